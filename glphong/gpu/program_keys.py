"""The program key a renderer draws an object with: the scene binding's key (`glphong.shaders.binding`) adjusted to
the renderer's settings (formulation, specialisation, per-vertex or per-pixel shading, shadow-map size and filter, the
frame passes' planes, numerics), with the errors for combinations it cannot draw."""
from dataclasses import replace

from glphong.shaders.binding import binding
from glphong.shaders.builders import uber_key
from glphong.shaders.numerics import with_numerics

__all__ = ["renderer_program_key"]


def renderer_program_key(renderer, scene, obj, output="radiance", planes=frozenset()):
    """The key ``renderer`` (a `glphong.Renderer`: its ``shading``, ``specialise``, ``formulation``, ``numerics``,
    ``shadow_map_size``, ``shadow_filter_radius``) draws ``obj`` of ``scene`` with; ``planes``: a G-buffer's planes
    beyond the scene's, or the frame passes' planes beside the radiance.

    Raises
    ------
    ValueError
        Shadows with the uber-shader or with per-vertex shading; textures or a normal map with per-vertex shading.
    """
    per_vertex = output == "radiance" and renderer.shading == "vertex"
    if output == "radiance" and not renderer.specialise:
        if any(k.shadowed for k in binding(scene).light_keys()):
            raise ValueError("the uber-shader holds no shadow maps, and the scene has lights with shadows=True: "
                             "render it with specialise=True")
        return uber_key([o.material for o in scene.objects], output, renderer.formulation, per_vertex, scene.lights)
    key = binding(scene).program_key(obj, output)
    if planes and output == "radiance":  # the frame passes' planes beside the radiance (`_render_with_planes`)
        key = replace(key, pass_planes=tuple(planes), has_object="object" in planes,
                      has_uv=key.has_uv or "uv" in planes)
    elif planes:
        key = replace(key, **{f"has_{name}": True for name in planes})
    if key.shadow_slots:
        if per_vertex:
            raise ValueError("shadows are looked up per pixel: a scene with lights with shadows=True needs "
                             "Renderer(shading='pixel')")
        key = replace(key, shadow_size=renderer.shadow_map_size, shadow_filter=renderer.shadow_filter_radius)
    if per_vertex and key.textured_inputs:
        raise ValueError(f"object {obj.name!r}: {', '.join(f'{t}.{p}' for t, p in key.textured_inputs)} "
                         "are textured, which needs per-pixel shading (a vertex has no texture footprint): "
                         "use Renderer(shading='pixel')")
    if per_vertex and key.normal_map:
        raise ValueError(f"object {obj.name!r}: its material has a normal map, which needs per-pixel shading (a "
                         "vertex has no texture footprint): use Renderer(shading='pixel')")
    if key.formulation != renderer.formulation or key.shade_per_vertex != per_vertex:
        key = replace(key, formulation=renderer.formulation, shade_per_vertex=per_vertex)
    return with_numerics(key, scene, obj) if renderer.numerics == "auto" else key
