"""Program keys: the one source of truth for what a GLSL program contains (DESIGN section 5).

A `ProgramKey` is frozen and hashable.  It is the program-cache key, and it alone
generates the ``#define`` lines and the list of chunks a program is assembled from:
terms a material does not have, light kinds a scene lacks and vertex attributes
nobody reads are left out of the source.  The numpy twin reads the same key.
"""
from dataclasses import dataclass, fields

__all__ = ["ProgramKey", "EncodeKey", "program_key", "gbuffer_key", "uber_key", "UBER_MAX_LIGHTS"]

#: light-array size per kind in the uber-shader (its counts are runtime uniforms up to this)
UBER_MAX_LIGHTS = 8

OUTPUTS = ("radiance", "gbuffer", "points", "display")
LOBES = (None, "phong", "blinn")
FORMULATIONS = ("stable", "naive")


@dataclass(frozen=True)
class ProgramKey:
    """What one program contains.

    Attributes
    ----------
    output : {'radiance', 'gbuffer', 'points', 'display'}
        Shaded radiance, the G-buffer of shading inputs, radiance at arbitrary points
        (a vertex-only program whose ``shade_point()`` result is captured by transform feedback), or
        display values (exposure and sRGB applied after shading) for pyrender's 8-bit framebuffer.
    lobe : {None, 'phong', 'blinn'}
        Specular lobe, None when the program has no specular term.
    has_ka, has_kd_la, has_diffuse : bool
        Presence of the terms k_a, k_d L_a and k_d (n.l) E of DESIGN E6.
    num_point_lights, num_unattenuated_lights, num_directional_lights : int
        Compile-time light counts per kind.
    has_normal : bool
        Whether the program reads the normal attribute (not needed without lights).
    two_sided : bool
        Flip the normal on back faces.
    formulation : {'stable', 'naive'}
        The stable float32 formulation of DESIGN section 3, or the textbook one (``normalize``,
        ``d*d``, ``pow(dot(v, r), q)``) kept only to show why the stable one exists.
    uber : bool
        The uber-shader: every term, both lobes and `UBER_MAX_LIGHTS` lights of each kind
        compiled in and switched by uniforms.  Kept to measure what specialisation buys.
    shade_per_vertex : bool
        Gouraud shading: ``shade_point()`` runs in the vertex stage and its radiance is interpolated.
    """

    output: str = "radiance"
    lobe: str = None
    has_ka: bool = False
    has_kd_la: bool = False
    has_diffuse: bool = False
    num_point_lights: int = 0
    num_unattenuated_lights: int = 0
    num_directional_lights: int = 0
    has_normal: bool = True
    two_sided: bool = True
    formulation: str = "stable"
    uber: bool = False
    shade_per_vertex: bool = False

    def __post_init__(self):
        if self.output not in OUTPUTS or self.lobe not in LOBES or self.formulation not in FORMULATIONS:
            raise ValueError(f"invalid ProgramKey {self}")

    @property
    def has_specular(self):
        """True when the program evaluates a specular lobe."""
        return self.lobe is not None or self.uber

    @property
    def needs_view(self):
        """True when the program needs the eye position: a specular lobe reads v, and per-vertex
        two-sided shading turns the normal toward the eye."""
        return self.has_specular or (self.shade_per_vertex and self.two_sided and self.has_normal)

    @property
    def num_lights(self):
        """Total number of lights the program loops over."""
        return self.num_point_lights + self.num_unattenuated_lights + self.num_directional_lights

    def attributes(self):
        """Vertex attributes the program reads, in binding order."""
        return ("in_position", "in_normal") if self.has_normal else ("in_position",)

    def defines(self):
        """The generated ``#define`` lines as (name, value) pairs."""
        b = lambda flag: "1" if flag else "0"  # noqa: E731
        out = [
            ("OUTPUT_GBUFFER", b(self.output == "gbuffer")),
            ("OUTPUT_DISPLAY", b(self.output == "display")),
            ("HAS_NORMAL", b(self.has_normal)),
            ("TWO_SIDED", b(self.two_sided)),
            ("RUNTIME_SWITCHES", b(self.uber)),
            ("SHADE_PER_VERTEX", b(self.shade_per_vertex)),
            # SWITCH(u_flag): a float uniform flag in the uber-shader, the constant true otherwise
            ("SWITCH(flag)", "((flag) > 0.5)" if self.uber else "true"),
        ]
        if self.output != "gbuffer":
            out += [
                ("HAS_KA", b(self.has_ka)),
                ("HAS_KD_LA", b(self.has_kd_la)),
                ("HAS_DIFFUSE", b(self.has_diffuse)),
                ("HAS_SPECULAR", b(self.has_specular)),
                ("NEEDS_VIEW", b(self.needs_view)),
            ]
            for kind in ("POINT", "UNATTENUATED", "DIRECTIONAL"):
                size = getattr(self, f"num_{kind.lower()}_lights")
                out.append((f"NUM_{kind}_LIGHTS", str(size)))
                out.append((f"{kind}_LIGHT_COUNT", f"int(u_{kind.lower()}_count)" if self.uber else str(size)))
            if self.has_specular:
                out.append(("SPECULAR_LOBE", "uber_lobe" if self.uber else f"{self.lobe}_lobe"))
        return out

    def shading_chunks(self):
        """Chunk files that define ``shade_point()`` and what it calls: only those the key needs."""
        if self.formulation == "naive":
            return ("naive",) + (("lambert",) if self.has_diffuse else ()) + ("shade",)
        if self.uber:
            return ("common", "lights", "lambert", "lobe", "phong", "blinn", "uber", "shade")
        chunks = ["common"]
        if self.num_point_lights:
            chunks.append("lights")
        if self.has_diffuse:
            chunks.append("lambert")
        if self.has_specular:
            chunks += ["lobe", self.lobe]
        chunks.append("shade")
        return tuple(chunks)

    def vertex_chunks(self):
        """Chunk files of the vertex stage, in order."""
        if self.output == "points":
            return self.shading_chunks() + ("shade_points",)
        if self.shade_per_vertex:
            return self.shading_chunks() + ("mesh_vertex",)
        return ("mesh_vertex",)

    def fragment_chunks(self):
        """Chunk files of the fragment stage, in order (none for 'points')."""
        if self.output == "points":
            return ()
        if self.output == "gbuffer":
            return ("common", "mesh_fragment")
        if self.shade_per_vertex:
            return ("mesh_fragment",)
        if self.output == "display":
            return self.shading_chunks() + ("srgb", "mesh_fragment")
        return self.shading_chunks() + ("mesh_fragment",)

    def varyings(self):
        """Transform-feedback outputs of a 'points' program."""
        return ("out_radiance",) if self.output == "points" else ()

    def left_out(self):
        """What this program does not contain, one readable line per item (list of str)."""
        if self.output == "gbuffer":
            return ["all shading code and lights (the G-buffer program writes position and normal only)",
                    "radiance output"]
        if self.uber:
            return ["nothing: the uber-shader compiles every term and switches at run time"]
        out = []
        if self.lobe is None:
            out.append("specular lobe: lobe.glsl, phong.glsl, blinn.glsl, u_ks, u_q (no ks, or no light)")
        else:
            other = "blinn" if self.lobe == "phong" else "phong"
            out.append(f"the other lobe: {other}.glsl")
        if not self.needs_view:
            out.append("view vector v = normalize(eye - x) and u_eye (only a lobe reads it)")
        if not self.has_ka:
            out.append("ambient term k_a (ka = 0)")
        if not self.has_kd_la:
            out.append("ambient term k_d L_a (no AmbientLight, or kd = 0)")
        if not self.has_diffuse:
            out.append("Lambert term: lambert.glsl (kd = 0, or no light)")
        for kind, count in (("point", self.num_point_lights), ("unattenuated", self.num_unattenuated_lights),
                            ("directional", self.num_directional_lights)):
            if not count:
                extra = " and lights.glsl" if kind == "point" else ""
                out.append(f"{kind}-light loop, its uniform arrays{extra} (no {kind} light reaches this material)")
        if not self.has_normal:
            out.append("normal attribute, its upload and the normal matrix (nothing reads a normal)")
        if not self.two_sided:
            out.append("two-sided normal flip")
        out.append("tangent attribute (no anisotropic material)")
        out.append("G-buffer outputs (they exist only in the G-buffer program)")
        return out

    def describe(self):
        """One line naming every field that is set, e.g. ``radiance lobe=phong has_diffuse num_point_lights=2``."""
        if self.uber:
            return (f"{self.output} uber (every term, both lobes, {UBER_MAX_LIGHTS} lights per kind, switched by "
                    f"uniforms){'' if self.formulation == 'stable' else ' formulation=' + self.formulation}")
        parts = [self.output]
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name != "output" and v not in (False, 0, None, "stable"):
                parts.append(f.name if v is True else f"{f.name}={v}")
        return " ".join(parts)


def program_key(material, light_counts, ambient_radiance, output="radiance"):
    """The radiance-program key of one material in a scene.

    Parameters
    ----------
    material : glphong.materials.Material
    light_counts : dict of str to int
        Number of lights per kind ('point', 'unattenuated', 'directional').
    ambient_radiance : tuple of 3 float or None
        The scene's ``L_a``.
    output : {'radiance', 'gbuffer', 'points', 'display'}

    Returns
    -------
    ProgramKey
    """
    if output == "gbuffer":
        return gbuffer_key(material)
    has_kd = any(c > 0.0 for c in material.kd)
    # lights matter only to a material that reflects them
    lit = sum(light_counts.values()) > 0 and (has_kd or material.has_specular)
    count = lambda kind: light_counts.get(kind, 0) if lit else 0  # noqa: E731
    return ProgramKey(
        output=output,
        lobe=material.family if (lit and material.has_specular) else None,
        has_ka=any(c > 0.0 for c in material.ka),
        has_kd_la=has_kd and ambient_radiance is not None and any(c > 0.0 for c in ambient_radiance),
        has_diffuse=lit and has_kd,
        num_point_lights=count("point"),
        num_unattenuated_lights=count("unattenuated"),
        num_directional_lights=count("directional"),
        has_normal=lit,
        two_sided=material.two_sided and lit,
    )


def uber_key(output="radiance", formulation="stable", shade_per_vertex=False):
    """The uber-shader's key: everything compiled in, switched at run time by uniforms."""
    return ProgramKey(output=output, lobe=None, has_ka=True, has_kd_la=True, has_diffuse=True,
                      num_point_lights=UBER_MAX_LIGHTS, num_unattenuated_lights=UBER_MAX_LIGHTS,
                      num_directional_lights=UBER_MAX_LIGHTS, has_normal=True, two_sided=True,
                      formulation=formulation, uber=True, shade_per_vertex=shade_per_vertex)


@dataclass(frozen=True)
class EncodeKey:
    """Key of the 8-bit output pass (encode.glsl): box filter of ``supersample``^2 texels,
    exposure, exact sRGB curve."""

    supersample: int = 1

    def defines(self):
        """The generated ``#define`` lines."""
        return [("SUPERSAMPLE", str(self.supersample))]

    def vertex_chunks(self):
        return ("fullscreen_vertex",)

    def fragment_chunks(self):
        return ("srgb", "encode")

    def varyings(self):
        return ()

    def attributes(self):
        return ()

    def describe(self):
        return f"encode srgb8 supersample={self.supersample}"


def gbuffer_key(material):
    """The G-buffer-program key of one material (only the two-sided flag matters)."""
    return ProgramKey(output="gbuffer", has_normal=True, two_sided=material.two_sided)
