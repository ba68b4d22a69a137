"""Program keys: the one source of truth for what a GLSL program contains (docs/design.md sections 5 and 8).

A `ProgramKey` is frozen and hashable.  It is the program-cache key, and it alone generates the ``#define`` lines
(`glphong.shaders.defines`), the chunks a program is assembled from (`glphong.shaders.stages`), the generated material
chunk (the sum of the material's terms), the vertex attributes and what `describe` lists as left out
(`glphong.shaders.prose`).  A material's terms enter as `TermKey` (model name, a hash of its GLSL, what it needs,
whether it is in the light loop and whether it answers ``L_a``), light kinds as `LightKey`: terms a material does not
have or whose parameters make them vanish, light kinds a scene lacks and vertex attributes nobody reads are left out
of the source.  Nothing here knows any model by name; the numpy twin reads the same key.  The keys are made by
`glphong.shaders.builders`.
"""
from dataclasses import dataclass

from glphong.core.glsl_files import library_chunks
from glphong.shaders.defines import program_defines
from glphong.shaders.generated import (LIGHTS_CHUNK, LOD_CHUNK, MATERIAL_CHUNK, lights_chunk, lod_chunk, material_chunk,
                                     transmits)
from glphong.shaders.options import FORMULATIONS, GBUFFER_PLANES, NUMERICS_PIECES, OUTPUTS, PASS_PLANES, SHADOW_PASSES
from glphong.shaders.prose import describe_key, left_out
from glphong.shaders.stages import shading_chunks, stage_chunks

__all__ = ["TermKey", "LightKey", "ProgramKey", "EncodeKey"]


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
    integral : glphong.definitions.material.Integral or None
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



@dataclass(frozen=True)
class ProgramKey:
    """What one program contains.

    Attributes
    ----------
    output : {'radiance', 'gbuffer', 'points', 'display', 'response', 'shadow', 'matte'}
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
    alpha_blend : int
        0: an opaque or alpha-masked surface; a blended one's layer programs (`glphong.gpu.peeling`, docs/design.md
        section 16): 1 shades the fragment at the layer's depth, premultiplied by the material's alpha (3: a textured
        alpha); 2 writes the window depth of the fragments behind the previous layer (the peel).  Set by the renderer,
        never by a scene.
    normal_map : bool
        The material's tangent-space normal map perturbs the shading normal in the fragment stage
        (glsl/normal_map.glsl); for a G-buffer program: the normal it writes is the mapped one.
    has_face : bool
        Whether the fragment stage computes the triangle's own (geometric) normal from the derivatives of the
        position (the shadow bias's slope; for a G-buffer program: whether it writes it, the 'face' plane).
    has_object : bool
        Whether the program interpolates the point in the object's own frame (the vertex position before the pose);
        a G-buffer program then writes it, the 'object' plane of the frame passes.
    has_unperturbed : bool
        A lit term reads the frame before the material's normal map (the need 'unperturbed': a coat normal over a
        normal-mapped `GltfPBR`): the radiance program keeps it in ``unperturbed_frame`` (glsl/normal_map.glsl); for
        a G-buffer program: whether it writes the interpolated normal before the map, the 'unperturbed' plane.
    pass_planes : tuple of str
        Radiance programs only: the planes (`glphong.shaders.options.PASS_PLANES`, in that order) it writes beside the
        radiance, at locations 1, 2, ...: the frame passes from the shading draw itself (multiple render targets).
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
    alpha_blend: int = 0
    has_face: bool = False
    has_object: bool = False
    has_unperturbed: bool = False
    pass_planes: tuple = ()
    shadow_size: int = 0
    shadow_filter: int = 0
    shadow_pass: str = None
    attribute_locations: tuple = ()

    def __post_init__(self):
        if self.output not in OUTPUTS or self.formulation not in FORMULATIONS or \
                not all(isinstance(t, TermKey) for t in self.terms) or not all(isinstance(k, LightKey) for k in self.lights) \
                or self.shadow_pass not in SHADOW_PASSES or \
                tuple(sorted(set(self.numerics))) != tuple(self.numerics) or \
                not set(self.numerics) <= set(NUMERICS_PIECES) or \
                tuple(n for n in PASS_PLANES if n in self.pass_planes) != tuple(self.pass_planes) or \
                (self.pass_planes and (self.output != "radiance" or self.pass_planes[0] != "position" or
                                       ("object" in self.pass_planes) != self.has_object or
                                       ("uv" in self.pass_planes and not self.has_uv))):
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
        """True when the program needs the eye position: a lit term reads v, per-vertex two-sided shading
        turns the normal toward the eye, or it draws what a transmissive surface lets through (`transmits`: its
        weight reads v with or without a light)."""
        return (self.num_lights > 0 and any("view" in t.needs for t in self.lit_terms)) or \
            (self.shade_per_vertex and self.two_sided and self.has_normal) or transmits(self)

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
        """The generated ``#define`` lines as (name, value) pairs (`glphong.shaders.defines`)."""
        return program_defines(self)

    def library_chunks(self):
        """Library chunks the terms use, in first-use order."""
        return tuple(dict.fromkeys(c for t in self.terms for c in t.uses))

    def light_library_chunks(self):
        """Library chunks the light kinds use and the terms do not, in first-use order."""
        return tuple(c for c in dict.fromkeys(c for k in self.lights for c in k.uses) if c not in self.library_chunks())

    def included_library(self):
        """Every library chunk the terms and light kinds use, in the library's one include order
        (`glphong.core.glsl_files.LIBRARY`: a chunk after those it calls, whichever term or kind asked first)."""
        used = set(self.library_chunks() + self.light_library_chunks())
        return tuple(c for c in library_chunks() if c in used)

    def shading_chunks(self):
        """Chunks that define ``shade_point()`` and what it calls: only those the key needs
        (`glphong.shaders.stages.SHADING`)."""
        return shading_chunks(self)

    def vertex_chunks(self):
        """Chunks of the vertex stage, in order (`glphong.shaders.stages.STAGES`)."""
        return stage_chunks(self, "vertex")

    def fragment_chunks(self):
        """Chunks of the fragment stage, in order (none for 'points' and 'response'; `glphong.shaders.stages.STAGES`)."""
        return stage_chunks(self, "fragment")

    def generated_chunks(self):
        """Text of the chunks generated from the key (label -> GLSL)."""
        if self.output == "gbuffer":
            return {LOD_CHUNK: lod_chunk(self)} if self.lod_textures else {}
        if self.output in ("shadow", "matte"):
            return {}
        out = {MATERIAL_CHUNK: material_chunk(self)}
        if self.lights and self.output != "response":
            out[LIGHTS_CHUNK] = lights_chunk(self)
        return out

    def varyings(self):
        """Transform-feedback outputs of a 'points' or 'response' program."""
        return {"points": ("out_radiance",), "response": ("out_response",)}.get(self.output, ())


    def left_out(self, absent_terms=()):
        """What this program does not contain, one readable line per item (`glphong.shaders.prose.left_out`).

        Parameters
        ----------
        absent_terms : sequence of (MaterialModel subclass, str)
            Terms of the drawn materials that the key leaves out, with the reason.
        """
        return left_out(self, absent_terms)

    def describe(self):
        """One line naming every field that is set, e.g. ``radiance terms=lambert[lit]+phong_lobe[lit] lights=point*2``
        (`glphong.shaders.prose.describe_key`)."""
        return describe_key(self)


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


