"""The vocabulary of program keys: outputs, formulations, the numerics pieces and their defines, the G-buffer's
planes, how a surface input is made, and the limits (docs/design.md sections 3, 5 and 8)."""

__all__ = ["UBER_MAX_LIGHTS", "OUTPUTS", "SHADOW_PASSES", "FORMULATIONS", "NUMERICS_DEFINES", "NUMERICS_PIECES",
           "TEXTBOOK_PIECES", "GBUFFER_PLANES", "MAX_GBUFFER_TARGETS", "PASS_PLANES", "INPUT_MODES",
           "MAX_TEXTURED_INPUTS"]

#: light-array size per kind in the uber-shader (its counts are runtime uniforms up to this)
UBER_MAX_LIGHTS = 8

OUTPUTS = ("radiance", "gbuffer", "points", "display", "response", "shadow", "matte")
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
TEXTBOOK_PIECES = ("falloff", "light", "normal", "view")
#: the G-buffer's planes beyond position and normal, in attachment order (a scene's present ones, packed); 'object':
#: the point in the object's own frame (the frame passes' object coordinates, NOCS and flow); 'unperturbed': the
#: interpolated normal before the material's normal map, where a term reads that frame (a coat normal, `gltf_pbr`)
GBUFFER_PLANES = ("tangent", "uv", "color", "lod", "face", "object", "unperturbed")
#: the most planes one G-buffer draw writes, position and normal included (GL 3.3's least GL_MAX_DRAW_BUFFERS, and
#: llvmpipe's)
MAX_GBUFFER_TARGETS = 8
#: the planes a radiance program may write beside the radiance for the frame passes (multiple render targets, in this
#: order from location 1; a program writes the ones its key's ``pass_planes`` names): the world position with the object's
#: index + 1 in w, the shading normal, the point in the object's frame, the uv
PASS_PLANES = ("position", "normal", "object", "uv")
#: how a surface input is made (``<MODEL>_<PARAM>_INPUT`` is the mode's index plus 1)
INPUT_MODES = ("texture", "vertex", "texture*vertex")
#: textured parameters per material (one G-buffer plane of levels of detail)
MAX_TEXTURED_INPUTS = 4

