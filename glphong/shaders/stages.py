"""Each kind of program as one ordered list of chunks per stage, read top to bottom (docs/design.md section 5).

`STAGES` is the table: for each kind of program (`program_kind`) the chunks of its vertex and fragment stages, in
the order the source is assembled.  An entry is a chunk's name (always there), a ``(name, condition)`` pair (there
where the key asks for it) or a `Slot` (the key's own list at that place: the library chunks its terms and light
kinds call, its terms' and light kinds' GLSL).  `SHADING` is the part that defines ``shade_point()`` and what it
calls; it runs in the fragment stage of a per-pixel program and in the vertex stage of a per-vertex or points
program.
"""
from dataclasses import dataclass

from glphong.shaders.generated import LIGHTS_CHUNK, LOD_CHUNK, MATERIAL_CHUNK, transmits

__all__ = ["Slot", "SHADING", "STAGES", "program_kind", "shading_chunks", "stage_chunks"]


@dataclass(frozen=True)
class Slot:
    """A place in a stage filled by the key's own list of chunks.

    Attributes
    ----------
    name : str
        What fills it, as a reader would say it.
    chunks : callable
        ``chunks(key)`` -> sequence of chunk labels.
    """

    name: str
    chunks: object


def _reads_surface(key):
    """surface.glsl: a textured input, a normal map, a textured alpha mask or a blended layer's textured alpha."""
    return bool(key.textured_inputs) or key.normal_map or key.alpha_mask == 2 or key.alpha_blend == 3


def _normal_map(key):
    return key.normal_map


def _normal_map_after_library(key):
    """normal_map.glsl for the material's normal map, unless a term's ``uses`` put it in the library slot already."""
    return key.normal_map and "normal_map" not in key.included_library()


def _shadows(key):
    return bool(key.shadow_slots)


def _lights(key):
    return bool(key.lights)


def _gbuffer_reads_surface(key):
    """surface.glsl in the G-buffer: levels of detail, a normal map or a textured alpha mask."""
    return bool(key.lod_textures) or key.normal_map or key.alpha_mask == 2


def _writes_lod(key):
    return bool(key.lod_textures)


def _textured_alpha(key):
    return key.alpha_mask == 2


LIBRARY = Slot("library chunks the terms and light kinds call, in the library's include order",
               lambda key: key.included_library())
TERMS = Slot("each term's model GLSL", lambda key: [t.chunk for t in key.terms])
LIGHT_KINDS = Slot("each light kind's GLSL", lambda key: [k.chunk for k in key.lights])

#: the chunks that define shade_point() and what it calls
SHADING = (
    "common",
    LIBRARY,
    ("surface", _reads_surface),
    ("normal_map", _normal_map_after_library),
    TERMS,
    ("shadows", _shadows),
    MATERIAL_CHUNK,
    LIGHT_KINDS,
    "shade",
    (LIGHTS_CHUNK, _lights),
)

#: program kind -> {"vertex": entries, "fragment": entries}
STAGES = {
    "radiance": {"vertex": ("mesh_vertex",), "fragment": SHADING + (("transmission_thin", transmits), "mesh_fragment")},
    "display": {"vertex": ("mesh_vertex",), "fragment": SHADING + ("srgb", "mesh_fragment")},
    "per_vertex": {"vertex": SHADING + ("mesh_vertex",), "fragment": (("surface", _textured_alpha), "mesh_fragment")},
    "gbuffer": {"vertex": ("mesh_vertex",),
                "fragment": ("common", ("surface", _gbuffer_reads_surface), ("normal_map", _normal_map),
                             (LOD_CHUNK, _writes_lod), "mesh_fragment")},
    "points": {"vertex": SHADING + ("shade_points",), "fragment": ()},
    "response": {"vertex": ("common", LIBRARY, TERMS, MATERIAL_CHUNK, "response_points"), "fragment": ()},
    "shadow": {"vertex": ("mesh_vertex",), "fragment": ("common", "shadow_fragment")},
    "matte": {"vertex": ("mesh_vertex",), "fragment": ("matte_fragment",)},
}


def program_kind(key):
    """The `STAGES` entry of ``key``: its output, or 'per_vertex' for radiance or display shaded per vertex."""
    if key.shade_per_vertex and key.output in ("radiance", "display"):
        return "per_vertex"
    return key.output


def shading_chunks(key):
    """`SHADING` for ``key``: the chunks that define ``shade_point()`` and what it calls (tuple of str)."""
    return _expand(SHADING, key)


def stage_chunks(key, stage):
    """The chunks of ``stage`` ('vertex' or 'fragment') of the program of ``key``, in order (tuple of str)."""
    return _expand(STAGES[program_kind(key)][stage], key)


def _expand(entries, key):
    out = []
    for entry in entries:
        if isinstance(entry, Slot):
            out += entry.chunks(key)
        elif isinstance(entry, tuple):
            name, condition = entry
            if condition(key):
                out.append(name)
        else:
            out.append(entry)
    return tuple(out)
