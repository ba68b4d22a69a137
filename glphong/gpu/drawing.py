"""A renderer's draw of a scene's objects: the per-object program, uniforms and vertex array, kept from frame to frame
(`draw_list`), and the draw with the winding and culling each object needs (`draw_objects`); of a large mesh that
reaches out of the view, only the triangles that may meet it (`glphong.gpu.view_cull`, kept per object and camera).

``blend`` selects what is drawn: 0 the opaque and alpha-masked objects (every object of a scene without a blended
material), 1 and 2 the blended objects with their layer and peel programs (`glphong.gpu.peeling.blend_key`), 4 the
transmissive ones (`glphong.gpu.transmission`, left out of 0 in a radiance draw).
"""
import moderngl
import numpy as np

from glphong.gpu.peeling import blend_key
from glphong.gpu.resources import ObjectEntry
from glphong.gpu.transmission import drawn_in, one_sided_transmissive
from glphong.gpu.view_cull import MIN_TRIANGLES, box_inside, visible_triangles
from glphong.scene.culling import closed_outward, view_allows_culling, world_sphere
from glphong.shaders.binding import binding
from glphong.shaders.numerics import allowed_pieces, view_decision

__all__ = ["draw_objects", "draw_list"]


def draw_objects(renderer, scene, output, frame_values=None, shadow_values=None, planes=frozenset(), blend=0):
    """Draw the objects ``blend`` selects into the bound framebuffer (depth test and blending as the caller set them).

    Opaque objects (``blend=0``): back faces culled where they cannot be seen (`glphong.scene.culling`).  Blended
    ones: back faces culled where the material is one-sided (glTF's ``doubleSided: false``), drawn where it is
    two-sided (a transparent closed mesh shows its far side through its near one).  Transmissive ones are drawn so
    in the radiance's transmission pass, and in the G-buffer too (what the radiance shaded: a one-sided glass seen
    from behind is not there, and the surface behind it is)."""
    mgl = renderer._mgl
    camera = scene.camera
    eye = tuple(camera.pose[:3, 3])
    forward = tuple(-camera.pose[:3, 2])
    near, far = camera.znear, camera.zfar
    aspect = renderer.width / renderer.height
    view_projection = None
    mirrored = culled = False
    for program, frame_pack, entry in draw_list(renderer, scene, output, aspect, frame_values, shadow_values, planes, blend):
        program.write(frame_pack)
        program.write(entry.pack)
        if entry.mirrored != mirrored:  # a mirroring pose (det < 0) reverses the winding
            mirrored = entry.mirrored
            mgl.front_face = "cw" if mirrored else "ccw"
        if blend or (output == "gbuffer" and one_sided_transmissive(scene.objects[entry.index].material)):
            cull = not scene.objects[entry.index].material.two_sided
        else:
            cull = entry.sphere is not None and view_allows_culling(*entry.sphere, eye, forward, near, far)
        if cull != culled:
            culled = cull
            (mgl.enable if cull else mgl.disable)(moderngl.CULL_FACE)
        vao = entry.vertex_array
        # a large mesh: what may meet the view (not for the uber-shader's entries, made anew each frame and never kept)
        if renderer.specialise and scene.objects[entry.index].mesh.indices.size >= 3 * MIN_TRIANGLES:
            if view_projection is None:
                view_projection = camera.projection_matrix(aspect) @ camera.view_matrix()
            vao = _view_vertex_array(renderer, scene.objects[entry.index], entry, camera, aspect, view_projection)
        if vao is not None:
            vao.render(moderngl.TRIANGLES)
    mgl.front_face = "ccw"
    mgl.disable(moderngl.CULL_FACE)


def _view_vertex_array(renderer, obj, entry, camera, aspect, view_projection):
    """The vertex array drawing what of ``obj``'s mesh may meet the view (`glphong.gpu.view_cull`): the entry's own
    where the mesh's bounding box lies inside the view or every triangle may meet it, else one of the kept triangles,
    made once per camera and aspect; None where no triangle may meet it."""
    buffers = renderer._mesh_buffers(obj.mesh)
    token = (entry.program.key, entry.index, id(obj))
    if entry.view is not None and entry.view[0] is camera and entry.view[1] == aspect:
        record = entry.view[2]
        if record is None or record == "whole" or buffers.subsets.get(token) is record:
            return entry.vertex_array if record == "whole" else record and record[0]
    if entry.bounds is None:
        centre, radius = world_sphere(obj.mesh, obj.pose)
        entry.bounds = (tuple(centre), radius)
    record = "whole"
    if not box_inside(*entry.bounds, view_projection):
        clip = view_projection @ np.asarray(obj.pose, np.float64)
        view = clip.tobytes()
        if view not in buffers.kept:  # once per pose and view, whichever programs draw the mesh
            if len(buffers.kept) >= 8:
                buffers.kept.clear()
            buffers.kept[view] = visible_triangles(obj.mesh.positions, obj.mesh.indices, clip)
        kept = buffers.kept[view]
        if kept is not None:
            record = buffers.subset(renderer._mgl, entry.program, token, kept) if len(kept) else None
    entry.view = (camera, aspect, record)
    return entry.vertex_array if record == "whole" else record and record[0]


def draw_list(renderer, scene, output, aspect, frame_values=None, shadow_values=None, planes=frozenset(), blend=0):
    """``(program, frame pack, object entry)`` per object ``blend`` selects, in order.

    Per frame, the uniforms every object shares (camera, lights) are packed once per program key;
    per object, its key, program, vertex array and packed uniforms (pose, normal matrix, material)
    are made once and kept (`ObjectEntry`) while the scene's lights, ambient light and the object's
    index are what they were: objects, materials and poses are immutable.  The uber-shader's key is
    the scene's, the same for every object (made once per frame).  ``frame_values`` are uniforms the
    call adds to every program's frame pack (the display programs' ``u_exposure``, a blended layer's
    ``u_blend_depth``), ``shadow_values`` the shadow maps, added to the programs that read them; ``planes`` a
    G-buffer's planes beyond the scene's (kept apart from the plain G-buffer's entries)."""
    drop = renderer.formulation == "naive"
    bound = binding(scene)
    state = (output, bound.light_keys(), scene.ambient_radiance, renderer.formulation,
             renderer.shading, renderer.specialise, renderer.culling, renderer.numerics, planes)
    camera = scene.camera
    shared = renderer.program_key(scene, None, output) if output == "radiance" and not renderer.specialise else None
    frame_packs = {}
    entries = renderer._entries
    slot = (output, planes, blend) if planes or blend else output
    for index, obj in enumerate(scene.objects):
        if not drawn_in(obj, blend, output):  # blended layers, transmissive surfaces (glphong.gpu.transmission)
            continue
        per_object = entries.get(obj)
        if per_object is None:
            per_object = entries[obj] = {}
        entry = per_object.get(slot)
        if entry is not None and entry.camera is not camera and not _same_view_piece(renderer, entry, obj, camera):
            entry = None
        if shared is not None or entry is None or entry.state != state or entry.index != index:
            key = shared or renderer.program_key(scene, obj, output, planes)
            kind = blend & 3  # a blended layer's (1) or peel's (2) program; TRANSMIT_DEPTH: the peel's of a glass
            key = blend_key(key, kind, kind == 1 and obj.material.alpha_blend.textured) if kind else key
            program = renderer.programs.get(key)
            values = bound.uniform_values(index, key, aspect) if shared is not None else \
                bound.object_uniform_values(index, key)
            vao = renderer._vertex_array(obj.mesh, program)
            sphere = world_sphere(obj.mesh, obj.pose) if renderer.culling == "auto" and closed_outward(obj.mesh)[0] \
                else None
            entry = ObjectEntry(state, index, key, program, program.pack(values, drop), vao, obj.mirrored,
                                None if sphere is None else (tuple(sphere[0]), sphere[1]), camera=camera)
            if shared is None:
                per_object[slot] = entry
        frame = frame_packs.get(entry.program)
        if frame is None:
            values = {} if shared is not None else bound.frame_uniform_values(entry.key, aspect)
            shadows = (shadow_values or {}) if entry.key.shadow_slots else {}
            pack = entry.program.pack(values | (frame_values or {}) | shadows, drop)
            frame = frame_packs[entry.program] = (pack, tuple(name for name, _, _ in pack))
        if entry.checked != frame[1]:  # strict: every active uniform set, checked once per entry
            entry.program.check_complete(frame[0], entry.pack)
            entry.checked = frame[1]
        yield entry.program, frame[0], entry


def _same_view_piece(renderer, entry, obj, camera):
    """True where ``entry``'s key needs no change for ``camera``: its 'view' piece (the only piece that depends on
    the camera, `glphong.shaders.numerics`) is decided the same way; the entry then remembers ``camera``."""
    key = entry.key
    if renderer.numerics == "auto" and "view" in allowed_pieces(key) \
            and view_decision(obj, camera)[0] != ("view" in key.numerics):
        return False
    entry.camera = camera
    return True
