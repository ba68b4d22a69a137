"""Program keys: the one source of truth for what a GLSL program contains (docs/design.md sections 5 and 8).

A `ProgramKey` is frozen and hashable.  It is the program-cache key, and it alone generates
the ``#define`` lines, the list of chunks a program is assembled from, the generated material
chunk (the sum of the material's terms), the vertex attributes and what `describe` lists as left
out.  A material's terms enter as `TermKey` (model name, a hash of its GLSL, what it needs, whether
it is in the light loop and whether it answers ``L_a``): terms a material does not have or whose
parameters make them vanish, light kinds a scene lacks and vertex attributes nobody reads are
left out of the source.  Nothing here knows any model by name; the numpy twin reads the same key.
"""
from dataclasses import dataclass, fields, replace

from glphong.materials.model import registered_models, surface_define
from glphong.materials.params import LIBRARY_CHUNKS
from glphong.lights.model import light_for_key, registered_lights
from glphong.shaders.generated import (LIGHTS_CHUNK, LOD_CHUNK, MATERIAL_CHUNK, lights_chunk, lod_chunk, material_chunk,
                                       model_chunk_label)

__all__ = ["ProgramKey", "TermKey", "LightKey", "EncodeKey", "program_key", "gbuffer_key", "uber_key", "response_key",
           "light_keys", "shadow_key", "UBER_MAX_LIGHTS", "material_chunk"]

#: light-array size per kind in the uber-shader (its counts are runtime uniforms up to this)
UBER_MAX_LIGHTS = 8

OUTPUTS = ("radiance", "gbuffer", "points", "display", "response", "shadow")
SHADOW_PASSES = (None, "cube", "ortho")
FORMULATIONS = ("stable", "naive")
#: the pieces of arithmetic that Renderer(numerics='auto') specialises where the scene's ranges prove it (docs/design.md
#: section 3, "Stability where a scene needs it"), each with its define: the normal's, the view vector's and the
#: point-like lights' normalisation and the point light's falloff I / d^2 in their textbook form, and the cosine-power
#: lobes without the log branch of delta >= 1/2, where every exponent makes the lobe 0 there
NUMERICS_DEFINES = {"falloff": "NAIVE_FALLOFF", "light": "NAIVE_LIGHT", "lobe_tail": "LOBE_TAIL_ZERO",
                    "normal": "NAIVE_NORMAL", "view": "NAIVE_VIEW"}
NUMERICS_PIECES = tuple(NUMERICS_DEFINES)
#: the pieces whose specialised form is the textbook one (set by formulation='naive' too; lobe_tail is not: the naive
#: lobes are pow())
_TEXTBOOK_PIECES = ("falloff", "light", "normal", "view")
#: the G-buffer's planes beyond position and normal, in attachment order (a scene's present ones, packed)
GBUFFER_PLANES = ("tangent", "uv", "color", "lod", "face")
#: how a surface input is made (``<MODEL>_<PARAM>_INPUT`` is the mode's index plus 1)
INPUT_MODES = ("texture", "vertex", "texture*vertex")
#: textured parameters per material (one G-buffer plane of levels of detail)
MAX_TEXTURED_INPUTS = 4


@dataclass(frozen=True)
class TermKey:
    """One term of a program's material.

    Attributes
    ----------
    name : str
        The model's name (its GLSL prefix).
    source_hash : str
        Hash of the model's GLSL: an edited definition is a different program.
    needs : tuple of str
        What the model reads besides n and l ('view', 'tangent', 'uv').
    lit : bool
        Evaluated in the light loop.
    ambient : bool
        Answers the ambient light ``L_a`` (``k L_a``).
    uses : tuple of str
        Library chunks its GLSL calls.
    defines : tuple of (str, str)
        The instance's structural defines.
    ambient_param : str or None
        The rgb parameter of its ``k L_a`` answer.
    ambient_scale : float
        The answer is ``ambient_scale * k * L_a`` (``1/pi`` for an albedo ``rho``: ``rho/pi L_a``).
    inputs : tuple of (str, str)
        The parameters the program sets per fragment (surface inputs, glsl/surface.glsl) and how:
        ``(param, mode)`` with mode ``'texture'``, ``'vertex'`` or ``'texture*vertex'``, followed by ``':r'``,
        ``':g'`` or ``':b'`` where a scalar parameter reads one channel.
    integral : glphong.materials.model.Integral or None
        How the term reflects an extended light in closed form, where the program has one (else sampled).
    emission : str or None
        The rgb parameter the term emits (`glphong.materials.MaterialModel.emission`), where it is not zero.
    occlusion : str or None
        The scalar parameter that multiplies the term's answer to ``L_a`` and its reflection of the occludable lights
        (`glphong.materials.MaterialModel.occluded_by`), where the term answers ``L_a`` or the program has such a
        light.
    """

    name: str
    source_hash: str
    needs: tuple = ()
    lit: bool = True
    ambient: bool = False
    uses: tuple = ()
    defines: tuple = ()
    ambient_param: str = None
    ambient_scale: float = 1.0
    inputs: tuple = ()
    integral: object = None
    emission: str = None
    occlusion: str = None

    @property
    def chunk(self):
        """Chunk label of the model's GLSL, ``model:<name>@<source hash>``: the program is built from the
        very definition the material was made of."""
        return f"model:{self.name}@{self.source_hash}"

    def describe(self):
        flags = [f for f, on in (("lit", self.lit), ("ambient", self.ambient), ("emission", self.emission),
                                 ("occlusion", self.occlusion)) if on]
        flags += [f"{param}={mode}" for param, mode in self.inputs]
        return f"{self.name}[{','.join(flags)}]"


@dataclass(frozen=True)
class LightKey:
    """The lights of one kind in a program.

    Attributes
    ----------
    name : str
        The kind's name (its GLSL prefix, `glphong.lights.LightModel.name`).
    source_hash : str
        Hash of the kind's GLSL and declarations: an edited definition is a different program.
    count : int
        How many lights of the kind the program loops over (the size of its uniform arrays).
    defines : tuple of (str, str)
        The kind's structural defines for the scene's lights of it (``RANGE`` where one has a range).
    uses : tuple of str
        Library chunks its GLSL calls.
    shadowed : tuple of int
        The lights of the kind (their numbers j) that cast shadows: their terms are multiplied by their shadow
        map's visibility (docs/design.md section 12).
    shadow_map : {'cube', 'ortho'} or None
        The kind's `glphong.lights.LightModel.shadow_map`.
    occludable : bool
        The kind is the surroundings, which a term's occlusion darkens (`glphong.lights.LightModel.occludable`).
    integrals : tuple of str or None
        None for a punctual kind; for an extended kind (docs/design.md section 13) the closed forms its GLSL
        offers ('irradiance', 'lobe'); other terms are summed over its weighted directions.
    """

    name: str
    source_hash: str
    count: int
    defines: tuple = ()
    uses: tuple = ()
    shadowed: tuple = ()
    shadow_map: str = None
    integrals: tuple = None
    occludable: bool = False

    @property
    def extended(self):
        """Whether the kind integrates over a solid angle (an area or environment light)."""
        return self.integrals is not None

    @property
    def chunk(self):
        """Chunk label of the kind's GLSL, ``light:<name>@<source hash>``."""
        return f"light:{self.name}@{self.source_hash}"

    def describe(self):
        shadowed = f"[shadows {','.join(map(str, self.shadowed))}]" if self.shadowed else ""
        return f"{self.name}*{self.count}" + "".join(f"[{name.lower()}]" for name, _ in self.defines) + shadowed


def light_keys(lights, casters=True):
    """The `LightKey` of each kind present in ``lights`` (a scene's light instances), in the registry's loop order;
    ``casters``: whether any object casts shadows (without, no light is shadowed)."""
    out = []
    for kind in registered_lights():
        mine = [light for light in lights if type(light) is kind]
        if mine:
            shadowed = tuple(j for j, light in enumerate(mine) if light.shadows) if casters else ()
            out.append(LightKey(kind.name, kind.source_hash(), len(mine), tuple(kind.structural_defines(mine)),
                                tuple(kind.uses), shadowed, kind.shadow_map, kind.key_integrals(mine), kind.occludable))
    return tuple(out)


def _as_light_keys(lights):
    """`light_keys` of light instances, or of a ``{kind name: count}`` dict (no structural defines), or the keys."""
    if isinstance(lights, dict):
        return tuple(LightKey(kind.name, kind.source_hash(), lights[kind.name], (), tuple(kind.uses),
                              integrals=kind.key_integrals(), occludable=kind.occludable)
                     for kind in registered_lights() if lights.get(kind.name, 0))
    lights = tuple(lights)
    if all(isinstance(light, LightKey) for light in lights):
        return lights
    return light_keys(lights)


@dataclass(frozen=True)
class ProgramKey:
    """What one program contains.

    Attributes
    ----------
    output : {'radiance', 'gbuffer', 'points', 'display'}
        Shaded radiance, the G-buffer of shading inputs, radiance at arbitrary points
        (a vertex-only program whose ``shade_point()`` result is captured by transform feedback), or
        display values (exposure and sRGB applied after shading) for pyrender's 8-bit framebuffer,
        or the material's response at given direction pairs (transform feedback, `glphong.testing`).
    terms : tuple of TermKey
        The material's terms that the program evaluates (lit, or answering ``L_a``), in order.
    has_ka : bool
        The constant term ``k_a``.
    lights : tuple of LightKey
        The light kinds the program loops over, with their compile-time counts, in loop order.
    has_normal : bool
        Whether the program reads the normal attribute (not needed without lights).
    has_tangent, has_uv : bool
        Whether it reads the tangent (vec4, handedness in w) and uv attributes.  For a G-buffer
        program: whether it writes them.
    two_sided : bool
        Flip the normal on back faces.
    formulation : {'stable', 'naive'}
        The stable float32 formulation of docs/design.md section 3, or the textbook one (``normalize``,
        ``d*d``, ``pow(dot(v, r), q)``, through the ``NAIVE`` define every chunk may honour) kept
        only to show why the stable one exists.
    numerics : tuple of str
        With formulation 'stable': the pieces of `NUMERICS_PIECES` specialised because the scene's ranges prove
        the result stays inside the error band (``Renderer(numerics='auto')``, `glphong.shaders.numerics`), sorted;
        each sets its define of `NUMERICS_DEFINES`.
    uber : bool
        The uber-shader: its terms (every built-in one and the scene's own) and `UBER_MAX_LIGHTS`
        lights of each kind compiled in and switched by uniforms.  Kept to measure what
        specialisation buys.
    shade_per_vertex : bool
        Gouraud shading: ``shade_point()`` runs in the vertex stage and its radiance is interpolated.
    has_color : bool
        Whether it reads the vertex-colour attribute (a surface input with vertex colours; for a
        G-buffer program: whether it writes the interpolated colour).
    has_lod : bool
        G-buffer programs only: whether the G-buffer has the level-of-detail plane (the scene has a
        textured parameter).
    lod_textures : int
        G-buffer programs only: how many textures' levels of detail it writes there (``textureQueryLOD``,
        one per textured surface input of the object's material, at most 4; the rest are 0).
    alpha_mask : int
        0: no alpha test; 1: a constant alpha; 2: alpha from a texture (glsl/mesh_fragment.glsl discards the fragments
        below the cutoff, in the radiance and the G-buffer programs alike).
    normal_map : bool
        The material's tangent-space normal map perturbs the shading normal in the fragment stage
        (glsl/normal_map.glsl); for a G-buffer program: the normal it writes is the mapped one.
    has_face : bool
        Whether the fragment stage computes the triangle's own (geometric) normal from the derivatives of the
        position (the shadow bias's slope; for a G-buffer program: whether it writes it, the 'face' plane).
    shadow_size : int
        Texels along a side of each shadow map (the renderer's ``shadow_map_size``; 0 without shadowed lights).
    shadow_filter : int
        Radius of the percentage-closer filter in texels (0: the nearest texel alone).
    shadow_pass : {'cube', 'ortho'} or None
        For output 'shadow': the kind of map the pass draws.
    attribute_locations : tuple of (str, int)
        Where the tangent, uv and colour attributes are bound, where not at glphong's own locations
        (tangent 2, uv 3, colour 5): pyrender packs a primitive's attributes in order, so its uv is at 2
        when the primitive has no tangents (`glphong.integrations.pyrender`).
    """

    output: str = "radiance"
    terms: tuple = ()
    has_ka: bool = False
    lights: tuple = ()
    has_normal: bool = True
    has_tangent: bool = False
    has_uv: bool = False
    two_sided: bool = True
    formulation: str = "stable"
    numerics: tuple = ()
    uber: bool = False
    shade_per_vertex: bool = False
    has_color: bool = False
    has_lod: bool = False
    lod_textures: int = 0
    normal_map: bool = False
    alpha_mask: int = 0
    has_face: bool = False
    shadow_size: int = 0
    shadow_filter: int = 0
    shadow_pass: str = None
    attribute_locations: tuple = ()

    def __post_init__(self):
        if self.output not in OUTPUTS or self.formulation not in FORMULATIONS or \
                not all(isinstance(t, TermKey) for t in self.terms) or not all(isinstance(k, LightKey) for k in self.lights) \
                or self.shadow_pass not in SHADOW_PASSES or \
                tuple(sorted(set(self.numerics))) != tuple(self.numerics) or \
                not set(self.numerics) <= set(NUMERICS_PIECES):
            raise ValueError(f"invalid ProgramKey {self}")

    @property
    def lit_terms(self):
        """Terms in the light loop (tuple of TermKey)."""
        return tuple(t for t in self.terms if t.lit)

    @property
    def has_ambient(self):
        """True when a term answers ``L_a`` (the program reads ``u_ambient``)."""
        return any(t.ambient for t in self.terms)

    @property
    def needs_view(self):
        """True when the program needs the eye position: a lit term reads v, or per-vertex
        two-sided shading turns the normal toward the eye."""
        return (self.num_lights > 0 and any("view" in t.needs for t in self.lit_terms)) or \
            (self.shade_per_vertex and self.two_sided and self.has_normal)

    @property
    def inputs(self):
        """``(term, param, mode)`` of every surface input the program computes (tuple)."""
        return tuple((t.name, param, mode) for t in self.terms for param, mode in t.inputs)

    @property
    def textured_inputs(self):
        """``(term, param)`` of the surface inputs that sample a texture, in sampler order (tuple)."""
        return tuple((t, p) for t, p, mode in self.inputs if "texture" in mode)

    @property
    def num_lights(self):
        """Total number of lights the program loops over."""
        return sum(k.count for k in self.lights)

    @property
    def shadow_slots(self):
        """``(light key, j)`` of each shadowed light, in slot order (tuple)."""
        return tuple((k, j) for k in self.lights for j in k.shadowed)

    def light_count(self, kind):
        """How many lights of ``kind`` (a name) the program loops over."""
        return sum(k.count for k in self.lights if k.name == kind)

    def attributes(self):
        """Vertex attributes the program reads, in binding order."""
        names = ["in_position"]
        names += ["in_normal"] if self.has_normal else []
        names += ["in_tangent"] if self.has_tangent else []
        names += ["in_uv"] if self.has_uv else []
        names += ["in_color"] if self.has_color else []
        return tuple(names)

    def extensions(self):
        """``#extension`` lines of the program: ``textureQueryLOD`` for a G-buffer that writes levels of detail."""
        return ("GL_ARB_texture_query_lod : require",) if self.lod_textures else ()

    def gbuffer_planes(self):
        """The extra G-buffer planes a G-buffer program writes, in attachment order (tuple of str)."""
        return tuple(name for name in GBUFFER_PLANES if getattr(self, f"has_{name}"))

    def defines(self):
        """The generated ``#define`` lines as (name, value) pairs."""
        b = lambda flag: "1" if flag else "0"  # noqa: E731
        out = [
            ("OUTPUT_GBUFFER", b(self.output == "gbuffer")),
            ("OUTPUT_DISPLAY", b(self.output == "display")),
            ("HAS_NORMAL", b(self.has_normal)),
            ("HAS_TANGENT", b(self.has_tangent)),
            ("HAS_UV", b(self.has_uv)),
            ("HAS_COLOR", b(self.has_color)),
            ("HAS_INPUTS", b(bool(self.inputs))),
            ("HAS_LOD", b(self.has_lod)),
            ("HAS_FACE", b(self.has_face)),
            ("NORMAL_MAP", b(self.normal_map)),
            ("ALPHA_MASK", str(self.alpha_mask)),
            *((f"{name.upper()}_LOCATION", str(where)) for name, where in
              ({"tangent": 2, "uv": 3, "color": 5} | dict(self.attribute_locations)).items()),
            ("NUM_LOD_TEXTURES", str(self.lod_textures)),
            ("TWO_SIDED", b(self.two_sided)),
            ("RUNTIME_SWITCHES", b(self.uber)),
            ("SHADE_PER_VERTEX", b(self.shade_per_vertex)),
            ("NAIVE", b(self.formulation == "naive")),
            *((define, b(piece in self.numerics or (self.formulation == "naive" and piece in _TEXTBOOK_PIECES)))
              for piece, define in NUMERICS_DEFINES.items()),
            # SWITCH(u_flag): a float uniform flag in the uber-shader, the constant true otherwise
            ("SWITCH(flag)", "((flag) > 0.5)" if self.uber else "true"),
        ]
        if self.output == "shadow":
            out.append(("SHADOW_ORTHO", b(self.shadow_pass == "ortho")))
        if self.output == "gbuffer":  # extra planes follow position and normal, packed in this order
            out += [(f"GBUFFER_{name.upper()}_LOCATION", str(2 + i)) for i, name in enumerate(self.gbuffer_planes())]
        if self.output not in ("gbuffer", "shadow"):
            out.append(("NEEDS_VIEW", b(self.needs_view)))
            if self.shadow_slots:
                out += [("SHADOW_MAP_SIZE", str(self.shadow_size)), ("SHADOW_FILTER_RADIUS", str(self.shadow_filter))]
            out.append(("NUM_LIGHTS", str(self.num_lights)))
            for light in self.lights:  # array sizes, loop bounds and each kind's structural defines, prefixed
                upper = light.name.upper()
                out.append((f"NUM_{upper}_LIGHTS", str(light.count)))
                out.append((f"{upper}_LIGHT_COUNT", f"int(u_{light.name}_count)" if self.uber else str(light.count)))
                out += [(f"{upper}_{name}", value) for name, value in light.defines]
            for term in self.terms:  # a model's structural defines, prefixed with its name
                out += [(f"{term.name.upper()}_{name}", value) for name, value in term.defines]
                out += [(surface_define(term.name, param), str(INPUT_MODES.index(mode.split(":")[0]) + 1))
                        for param, mode in term.inputs]
        return out

    def library_chunks(self):
        """Library chunks the terms use, in first-use order."""
        return tuple(dict.fromkeys(c for t in self.terms for c in t.uses))

    def light_library_chunks(self):
        """Library chunks the light kinds use and the terms do not, in first-use order."""
        return tuple(c for c in dict.fromkeys(c for k in self.lights for c in k.uses) if c not in self.library_chunks())

    def shading_chunks(self):
        """Chunks that define ``shade_point()`` and what it calls: only those the key needs."""
        chunks = ["common"]
        chunks += self.light_library_chunks() + self.library_chunks()
        chunks += ["surface"] if self.textured_inputs or self.normal_map or self.alpha_mask == 2 else []
        chunks += ["normal_map"] if self.normal_map else []
        chunks += [t.chunk for t in self.terms]
        chunks += ["shadows"] if self.shadow_slots else []
        chunks += [MATERIAL_CHUNK] + [k.chunk for k in self.lights] + ["shade"]
        chunks += [LIGHTS_CHUNK] if self.lights else []
        return tuple(chunks)

    def vertex_chunks(self):
        """Chunks of the vertex stage, in order."""
        if self.output == "shadow":
            return ("mesh_vertex",)
        if self.output == "response":
            return ("common",) + self.library_chunks() + tuple(t.chunk for t in self.terms) + \
                (MATERIAL_CHUNK, "response_points")
        if self.output == "points":
            return self.shading_chunks() + ("shade_points",)
        if self.shade_per_vertex:
            return self.shading_chunks() + ("mesh_vertex",)
        return ("mesh_vertex",)

    def fragment_chunks(self):
        """Chunks of the fragment stage, in order (none for 'points' and 'response')."""
        if self.output in ("points", "response"):
            return ()
        if self.output == "shadow":
            return ("common", "shadow_fragment")
        if self.output == "gbuffer":
            return ("common",) + (("surface",) if self.lod_textures or self.normal_map or self.alpha_mask == 2 else ()) + \
                (("normal_map",) if self.normal_map else ()) + ((LOD_CHUNK,) if self.lod_textures else ()) + ("mesh_fragment",)
        if self.shade_per_vertex:
            return ("mesh_fragment",) if self.alpha_mask != 2 else ("surface", "mesh_fragment")
        if self.output == "display":
            return self.shading_chunks() + ("srgb", "mesh_fragment")
        return self.shading_chunks() + ("mesh_fragment",)

    def generated_chunks(self):
        """Text of the chunks generated from the key (label -> GLSL)."""
        if self.output == "gbuffer":
            return {LOD_CHUNK: lod_chunk(self)} if self.lod_textures else {}
        if self.output == "shadow":
            return {}
        out = {MATERIAL_CHUNK: material_chunk(self)}
        if self.lights and self.output != "response":
            out[LIGHTS_CHUNK] = lights_chunk(self)
        return out

    def varyings(self):
        """Transform-feedback outputs of a 'points' or 'response' program."""
        return {"points": ("out_radiance",), "response": ("out_response",)}.get(self.output, ())

    def left_out(self, absent_terms=()):
        """What this program does not contain, one readable line per item (list of str).

        Parameters
        ----------
        absent_terms : sequence of (MaterialModel subclass, str)
            Terms of the drawn materials that the key leaves out, with the reason.
        """
        if self.output == "gbuffer":
            return ["all shading code and lights (the G-buffer program writes the shading inputs only)",
                    "radiance output"] + [f"{name} output (no drawn term needs it)" for name in GBUFFER_PLANES
                                          if name not in self.gbuffer_planes()]
        if self.output == "shadow":
            return ["all shading code (the shadow pass writes each caster's distance from the light)"]
        if self.uber:
            return ["nothing: the uber-shader compiles every built-in term and the scene's own and switches at run time"]
        out = []
        for model, reason in absent_terms:
            params = ", ".join(model.uniform_name(p.name) for p in model.params + model.tables)
            out.append(f"term {model.name}: {model_chunk_label(model.name)}{', ' + params if params else ''} ({reason})")
        used = set(self.library_chunks() + self.light_library_chunks())

        for chunk in ("lights",) + LIBRARY_CHUNKS:
            if chunk not in used:
                out.append(f"library chunk {chunk}.glsl (no term or light kind of this program calls it)")
        if not self.needs_view:
            out.append("view vector v = normalize(eye - x) and u_eye (no lit term reads it)")
        if not self.has_ka:
            out.append("constant term k_a (ka = 0)")
        if not self.has_ambient:
            out.append("ambient light L_a and u_ambient (no AmbientLight, or no term answers it)")
        present = {k.name: k for k in self.lights}
        for kind in registered_lights():
            if kind.name not in present:
                out.append(f"{kind.name}-light loop, its chunk {kind.source_label()} and uniform arrays "
                           f"(no {kind.name} light reaches this material)")
            else:
                given = {name for name, _ in present[kind.name].defines}
                out += [f"{kind.name} lights' {what} (no {kind.name} light of the scene needs it)"
                        for name, what in kind.optional_code if name not in given]
        if not self.shadow_slots:
            out.append("shadow maps, their samplers and shadows.glsl (no light has shadows=True, or nothing casts)")
        if not self.has_normal:
            out.append("normal attribute, its upload and the normal matrix (nothing reads a normal)")
        if not self.two_sided:
            out.append("two-sided normal flip")
        if not self.has_tangent:
            out.append("tangent attribute and the tangent frame (no lit term needs 'tangent')")
        if not self.has_uv:
            out.append("uv attribute (no lit term needs 'uv', no parameter is textured)")
        if not self.has_color:
            out.append("vertex-colour attribute (no parameter takes vertex colours)")
        if not self.textured_inputs:
            out.append("surface.glsl, texture samplers and material_inputs() (no parameter is textured)")
        if not self.normal_map:
            out.append("normal_map.glsl and its sampler (the material has no normal map)")
        if not self.alpha_mask:
            out.append("the alpha test (the material has no alpha mask)")
        out.append("G-buffer outputs (they exist only in the G-buffer program)")
        return out

    def describe(self):
        """One line naming every field that is set, e.g. ``radiance terms=lambert[lit]+phong_lobe[lit] lights=point*2``."""
        if self.uber:
            return (f"{self.output} uber (terms {'+'.join(t.name for t in self.terms) or 'none'}, "
                    f"{UBER_MAX_LIGHTS} lights of each of {'+'.join(k.name for k in self.lights)}, switched by uniforms)"
                    f"{'' if self.formulation == 'stable' else ' formulation=' + self.formulation}")
        parts = [self.output]
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in ("terms", "lights"):
                if v:
                    parts.append(f"{f.name}=" + "+".join(t.describe() for t in v))
            elif f.name != "output" and v not in (False, 0, None, "stable", ()):
                parts.append(f.name if v is True else f"{f.name}={v}")
        return " ".join(parts)


def _ambient_present(ambient_radiance):
    return ambient_radiance is not None and any(c > 0.0 for c in ambient_radiance)


def _term_key(term, lit, ambient, uber=False, extended=False, emits=False, occludable=False):
    surface = term.surface_inputs()
    emission = term.emission if emits else None
    occlusion = term.occluded_by if ambient or (lit and occludable) else None
    read = ({p.name for p in term.params} - {term.emission, term.occluded_by} if lit else set()) \
        | {term.ambient if ambient else None, emission, occlusion}  # by the response, or by material_emission
    inputs = tuple((p.name, surface[p.name].mode) for p in term.params if p.name in surface and p.name in read)
    return TermKey(term.name, term.source_hash(), tuple(term.needs), lit=lit, ambient=ambient,
                   uses=term.library_uses(uber), defines=term.structural_defines(uber), ambient_param=term.ambient,
                   ambient_scale=float(term.ambient_scale), inputs=inputs,
                   integral=term.integral_form() if lit and extended else None, emission=emission, occlusion=occlusion)


def term_keys(material, lit, ambient_present, extended=False, emission=True, occludable=False):
    """The `TermKey` of each term of ``material`` that a program evaluates; ``extended``: the program has an
    extended light (each lit term's closed form, `TermKey.integral`, is part of the key); ``emission``: the program
    adds what the terms emit (not a response program); ``occludable``: it has a light its terms' occlusion darkens."""
    out = []
    for term in material.components:
        emits = emission and term.emits()
        if term.vanishes() and not emits:
            continue
        answers = ambient_present and term.answers_ambient() and not term.vanishes()
        reflects = lit and not term.vanishes()
        if reflects or answers or emits:
            out.append(_term_key(term, lit=reflects, ambient=answers, extended=extended, emits=emits,
                                 occludable=occludable))
    return tuple(out)


def response_key(material):
    """The key of a program that evaluates ``material``'s response at direction pairs (`glphong.testing`):
    every term that does not vanish, in the light loop's place, no light, no emission."""
    terms = tuple(t for t in term_keys(material, True, False, emission=False))
    _refuse_surface_inputs(terms, "glphong.testing evaluates a material's response at given directions, with "
                                  "constant parameters")
    needs = {n for t in terms for n in t.needs}
    return ProgramKey(output="response", terms=terms, has_normal=True, has_tangent="tangent" in needs,
                      has_uv="uv" in needs, two_sided=False)


def program_key(material, lights, ambient_radiance, output="radiance", gbuffer_needs=None):
    """The program key of one material in a scene.

    Parameters
    ----------
    material : glphong.materials.Material
    lights : sequence of LightModel, or tuple of LightKey, or dict of str to int
        The scene's lights (`light_keys` of them), their keys, or a number of lights per kind name
        (``{'point': 1}``: no structural defines).
    ambient_radiance : tuple of 3 float or None
        The scene's ``L_a``.
    output : {'radiance', 'gbuffer', 'points', 'display'}
    gbuffer_needs : set of str, optional
        For 'gbuffer': the extra outputs ('tangent', 'uv') the scene's G-buffer carries.

    Returns
    -------
    ProgramKey
    """
    if output == "gbuffer":
        spec = program_key(material, lights, ambient_radiance)
        values = material.uniform_values(spec) if spec.textured_inputs else {}
        _, shown = lod_slots([values[f"u_{t}_{p}_texture"] for t, p in spec.textured_inputs])
        if len(shown) > MAX_TEXTURED_INPUTS:
            raise ValueError(f"a material's textures may have at most {MAX_TEXTURED_INPUTS} sizes (the G-buffer holds "
                             f"one level of detail per size); {type(material).__name__} has {len(shown)}")
        return replace(gbuffer_key(material, gbuffer_needs or (), len(shown)), normal_map=spec.normal_map,
                       alpha_mask=spec.alpha_mask)
    # lights matter only to a material with a term that reflects them
    lights = _as_light_keys(lights)
    lit = bool(lights) and any(not t.vanishes() for t in material.components)
    terms = term_keys(material, lit, _ambient_present(ambient_radiance), extended=any(k.extended for k in lights),
                      occludable=any(k.occludable for k in lights))
    lights = tuple(_with_usage(k, terms) if k.extended else k for k in lights)
    needs = {n for t in terms if t.lit for n in t.needs}
    modes = [mode for t in terms for _, mode in t.inputs]
    normal_map = lit and material.normal_map is not None
    mask = material.alpha_mask
    alpha_mask = 0 if mask is None else 2 if mask.textured else 1
    if output == "points":
        _refuse_surface_inputs(terms, "shading at given points has no texture coordinates or vertex colours")
        if normal_map:
            raise ValueError("the material has a normal map, but shading at given points has no texture coordinates: "
                             "give the points their normals and a material without normal_map")
    return ProgramKey(
        output=output,
        terms=terms,
        has_ka=any(c > 0.0 for c in material.ka),
        lights=lights if lit else (),
        has_face=lit and any(k.shadowed for k in lights),
        has_normal=lit,
        has_tangent="tangent" in needs or normal_map,
        has_uv="uv" in needs or any("texture" in m for m in modes) or normal_map or alpha_mask == 2,
        two_sided=material.two_sided and lit,
        has_color=any("vertex" in m for m in modes),
        normal_map=normal_map,
        alpha_mask=alpha_mask,
    )


def _with_usage(light, terms):
    """An extended kind's `LightKey` with the defines its kind adds for what the program's lit ``terms`` use of it
    (`glphong.lights.LightModel.usage_defines`: its closed forms 'irradiance' and 'lobe', its samples 'sample')."""
    lit = [t for t in terms if t.lit]
    closed = {t.integral.form for t in lit if t.integral is not None and t.integral.form in light.integrals}
    uses = tuple(sorted(closed)) + (("sample",) if any(t.integral is None or t.integral.form not in light.integrals
                                                       for t in lit) else ())
    extra = tuple(light_for_key(light.name, light.source_hash).usage_defines(light.defines, uses))
    return replace(light, defines=light.defines + extra) if extra else light


def _refuse_surface_inputs(terms, why):
    inputs = [f"{t.name}.{param}" for t in terms for param, _ in t.inputs]
    if inputs:
        raise ValueError(f"{', '.join(inputs)} vary over the surface (a texture or vertex colours), but {why}: "
                         "give the material constant parameters")


_UBER_BUILTINS = {}


def _uber_builtins():
    """Example instances of the models the uber-shader always holds (those that declare ``in_uber = True``:
    the lecture's Lambert, Phong and Blinn lobes; they need no more than the view and have no structural
    defines), computed once per state of the registry.  Every other model joins it only where a scene has it:
    each term costs every fragment its switch (benchmarks/specialisation.py, a Lambert sphere and floor at
    1024x1024 on EGL: 2.34x the specialised program with the lecture's three terms, 4.2x with the normalised
    lobes, the albedo diffuse term and the Fresnel switch compiled in too)."""

    models = registered_models()
    cached = _UBER_BUILTINS.get(models)
    if cached is None:
        examples = [m.example() for m in models if m.in_uber and set(m.needs) <= {"view"}]
        cached = _UBER_BUILTINS[models] = [e for e in examples if not e.structural_defines()]
    return cached


def uber_key(materials, output="radiance", formulation="stable", shade_per_vertex=False, lights=()):
    """The uber-shader's key: every built-in model that needs no more than the view vector, every
    term of ``materials``, and `UBER_MAX_LIGHTS` lights of each built-in kind (``in_uber``) and of each kind of
    ``lights``, with every optional part of their code, switched at run time by uniforms.

    Parameters
    ----------
    materials : sequence of glphong.materials.Material
        The materials drawn with it (a scene's); their terms are all compiled in.
    lights : sequence of LightModel
        The scene's lights: their kinds join the built-in ones.
    """
    extended = sorted({type(light).name for light in lights if type(light).extent == "extended"})
    if extended:
        raise ValueError(f"the uber-shader holds punctual lights only, but the scene has {', '.join(extended)} lights, "
                         "which integrate over a solid angle (docs/design.md section 13): render it with specialise=True")
    terms = {}
    drawn = [term for material in materials for term in material.components]
    textured = [f"{t.name}.{name}" for t in drawn for name in t.surface_inputs()]
    textured += [f"{type(m).__name__}'s normal map" for m in materials if m.normal_map is not None]
    textured += [f"{type(m).__name__}'s alpha mask" for m in materials if m.alpha_mask is not None]
    if textured:
        raise ValueError(f"the uber-shader holds constant parameters only, but {', '.join(textured)} vary over the "
                         "surface (a texture or vertex colours): render it with specialise=True")
    # a model's Fresnel form is a run-time switch, compiled only where one of the scene's terms has one
    # (computing F for every fragment and light would cost the lecture's models whatever the scene)
    with_fresnel = {t.name for t in drawn if getattr(t, "fresnel", None) is not None}
    for term in _uber_builtins() + drawn:
        key = _term_key(term, lit=True, ambient=term.ambient is not None, uber=term.name in with_fresnel,
                        emits=term.emission is not None)
        known = terms.setdefault(term.name, key)
        if known != key:
            raise ValueError(f"the uber-shader holds one variant of each model, but the scene has two of "
                             f"{term.name!r} (defines {known.defines} and {key.defines}, or two definitions): "
                             "render it with specialise=True")
    needs = {n for t in terms.values() for n in t.needs}
    kinds = {type(light).name for light in lights}
    uber_lights = tuple(LightKey(k.name, k.source_hash(), UBER_MAX_LIGHTS, tuple((name, "1") for name, _ in k.optional_code),
                                 tuple(k.uses)) for k in registered_lights() if k.in_uber or k.name in kinds)
    return ProgramKey(output=output, terms=tuple(terms[name] for name in sorted(terms)), has_ka=True,
                      lights=uber_lights, has_normal=True, has_tangent="tangent" in needs,
                      has_uv="uv" in needs, two_sided=True, formulation=formulation, uber=True,
                      shade_per_vertex=shade_per_vertex)


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

    def generated_chunks(self):
        return {}

    def varyings(self):
        return ()

    def attributes(self):
        return ()

    def describe(self):
        return f"encode srgb8 supersample={self.supersample}"

    def extensions(self):
        return ()


def shadow_key(shadow_pass):
    """The key of a shadow pass (a caster's distance from the light, glsl/shadow_fragment.glsl): 'cube' or 'ortho'."""
    return ProgramKey(output="shadow", has_normal=False, two_sided=False, shadow_pass=shadow_pass)


def lod_slots(images):
    """Where the G-buffer keeps the level of detail of each of a program's textures: ``(slots, shown)``, ``slots[i]``
    the slot of ``images[i]`` (the `TextureImage` of ``ProgramKey.textured_inputs[i]``) and ``shown[k]`` the index of
    the image the G-buffer program samples for slot ``k``.  ``textureQueryLOD`` depends on the uv derivatives and the
    texture's size and number of levels only, so textures alike in those share a slot (glTF's textures mostly are:
    base colour, metallic-roughness, occlusion and emissive at one size take one slot)."""
    slots, shown, seen = [], [], {}
    for i, image in enumerate(images):
        shape = (image.size, len(image.levels))
        if shape not in seen:
            seen[shape] = len(shown)
            shown.append(i)
        slots.append(seen[shape])
    return tuple(slots), tuple(shown)


def gbuffer_key(material, needs=(), lod_textures=0):
    """The G-buffer-program key of one material: its two-sided flag, the scene's extra G-buffer outputs
    ``needs`` ('tangent', 'uv', 'color', 'lod') and the number of its textures whose level of detail it
    writes."""
    return ProgramKey(output="gbuffer", has_normal=True, two_sided=material.two_sided,
                      has_tangent="tangent" in needs, has_uv="uv" in needs, has_color="color" in needs,
                      has_lod="lod" in needs, lod_textures=lod_textures, has_face="face" in needs)
