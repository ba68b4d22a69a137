"""Run in a subprocess by test_pyrender_flags.py: pyrender reads PYOPENGL_PLATFORM once per process.

What a pyrender user brings beyond materials: pyrender's example scene with its SpotLight and DirectionalLight,
its shadow flags, FLAT, orthographic and intrinsics cameras, a resized renderer, renderers created where the
user cannot reach them (`enable_everywhere`).  Usage: python pyrender_flags_check.py PLATFORM; prints one JSON
object of measured values.
"""
import json
import os
import sys
import warnings

os.environ["PYOPENGL_PLATFORM"] = sys.argv[1]

import numpy as np  # noqa: E402
import pyrender  # noqa: E402
import trimesh  # noqa: E402
from pyrender import RenderFlags  # noqa: E402

import glphong  # noqa: E402
from glphong.core.imaging import encode_srgb8  # noqa: E402
from glphong.integrations.pyrender import (GlphongMaterial, enable, enable_everywhere, release,  # noqa: E402
                                           scene_from_pyrender)

PLATFORM = sys.argv[1]
SAMPLES = 4 if PLATFORM == "egl" else 1  # pyrender multisamples on EGL only
SHADOWS = RenderFlags.SHADOWS_DIRECTIONAL | RenderFlags.SHADOWS_SPOT
#: pyrender's examples/example.py camera pose (its lights sit there too)
CAM_POSE = np.array([[0.0, -np.sqrt(2) / 2, np.sqrt(2) / 2, 0.5], [1.0, 0.0, 0.0, 0.0],
                     [0.0, np.sqrt(2) / 2, np.sqrt(2) / 2, 0.4], [0.0, 0.0, 0.0, 1.0]])


def translation(x, y, z):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def looking_at(eye, target):
    return glphong.PerspectiveCamera.look_at(eye, target, up=(0.0, 0.0, 1.0), yfov=1.0).pose


def example_scene(lights="example", pyrender_parts=False):
    """pyrender's examples/example.py scene made offscreen, with glphong materials on its meshes.  Its models (fuze,
    drill, water bottle, wood board) are not installed with pyrender: stand-ins of their size sit at their poses.
    ``lights``: 'example' (a DirectionalLight and a SpotLight at the camera, as the example has them) or 'side'
    (the same two lights from the side, so that shadows fall where the camera sees them).  ``pyrender_parts``: the
    example's face-coloured boxes (instanced, pyrender's material) and its point cloud as well."""
    scene = pyrender.Scene(ambient_light=np.array([0.02, 0.02, 0.02]))
    wood = trimesh.creation.box(extents=(0.6, 0.45, 0.02))
    fuze = trimesh.creation.cylinder(radius=0.035, height=0.12, sections=48)
    drill = trimesh.creation.capsule(height=0.12, radius=0.03, count=(24, 24))
    bottle = trimesh.creation.cylinder(radius=0.035, height=0.22, sections=48)
    box = trimesh.creation.box(extents=0.1 * np.ones(3))
    parts = [(wood, glphong.Lambert((0.25, 0.15, 0.08)), translation(0.0, 0.0, -0.01)),
             (fuze, glphong.Phong(0.15, 0.4, 60.0), translation(0.1, 0.15, 0.06)),
             (drill, glphong.BlinnPhong((0.2, 0.12, 0.02), 0.5, 200.0), translation(0.1, 0.0, 0.09)),
             (bottle, glphong.GltfPBR((0.1, 0.3, 0.6), 0.0, 0.4), translation(0.1, -0.16, 0.11)),
             (box, glphong.Lambert((0.1, 0.25, 0.1)), translation(-0.1, 0.10, 0.05))]
    for mesh, material, pose in parts:
        scene.add(pyrender.Mesh.from_trimesh(mesh, material=GlphongMaterial(material)), pose=pose)
    if pyrender_parts:
        boxf = trimesh.creation.box(extents=0.1 * np.ones(3))
        boxf.visual.face_colors = np.random.default_rng(1).uniform(size=boxf.faces.shape)
        poses = np.tile(np.eye(4), (2, 1, 1))
        poses[0, :3, 3], poses[1, :3, 3] = (-0.1, -0.10, 0.05), (-0.15, -0.10, 0.05)
        scene.add(pyrender.Mesh.from_trimesh(boxf, poses=poses, smooth=False))
        points = trimesh.creation.icosphere(radius=0.05).vertices
        scene.add(pyrender.Mesh.from_points(points, colors=np.random.default_rng(2).uniform(size=points.shape)))
    scene.add(pyrender.PerspectiveCamera(yfov=np.pi / 3.0), pose=CAM_POSE)
    light_pose = CAM_POSE if lights == "example" else looking_at((-0.2, 0.45, 0.5), (0.0, 0.0, 0.0))
    scene.add(pyrender.DirectionalLight(color=np.ones(3), intensity=1.0), pose=light_pose)
    scene.add(pyrender.SpotLight(color=np.ones(3), intensity=10.0 if lights == "example" else 2.0,
                                 innerConeAngle=np.pi / 16, outerConeAngle=np.pi / 6),
              pose=CAM_POSE if lights == "example" else looking_at((-0.3, -0.35, 0.55), (0.0, 0.0, 0.0)))
    return scene


def interior_of(coverage):
    interior = coverage == 1.0
    for _ in range(2):  # erode by 2 px: silhouettes are compared apart
        interior[1:-1, 1:-1] &= interior[:-2, 1:-1] & interior[2:, 1:-1] & interior[1:-1, :-2] & interior[1:-1, 2:]
    return interior


def agreement(color, scene, width, height, flags=RenderFlags.NONE, **renderer_options):
    """Where the embedded frame ``color`` and glphong's renderer of `scene_from_pyrender` differ, on the
    interior of glphong's coverage (8-bit steps)."""
    ours_scene = scene_from_pyrender(scene, flags=flags, viewport=(width, height))
    with glphong.Renderer(width, height, backend=PLATFORM, samples=SAMPLES, numerics="stable", **renderer_options) as g:
        ours = g.render_srgb8(ours_scene)
        interior = interior_of(g.render(ours_scene).coverage)
    diff = np.abs(ours.astype(int) - color[..., :3].astype(int)).max(axis=-1)[interior]
    return {"pixels": int(interior.sum()), "max_diff": int(diff.max()) if diff.size else -1,
            "exact": float(np.mean(diff == 0)) if diff.size else 0.0, "within_one": float(np.mean(diff <= 1))}, ours


def main():
    width, height = 160, 120
    result = {}
    renderer = pyrender.OffscreenRenderer(width, height)

    # 1. embedding switched on and no glphong material: pyrender's frames byte-identical, every flag
    plain_scene = pyrender.Scene(ambient_light=[0.05, 0.05, 0.05])
    tm = trimesh.creation.icosphere(3, radius=0.1)
    tm.visual.vertex_colors = np.random.default_rng(3).integers(0, 255, (len(tm.vertices), 4), dtype=np.uint8)
    sphere_node = plain_scene.add(pyrender.Mesh.from_trimesh(tm), pose=translation(0.0, 0.0, 0.1))
    plain_scene.add(pyrender.Mesh.from_trimesh(trimesh.creation.box(extents=(0.6, 0.45, 0.02))))
    plain_scene.add(pyrender.PerspectiveCamera(yfov=np.pi / 3.0), pose=CAM_POSE)
    plain_scene.add(pyrender.DirectionalLight(intensity=2.0), pose=looking_at((-0.2, 0.45, 0.5), (0, 0, 0)))
    plain_scene.add(pyrender.SpotLight(intensity=3.0, outerConeAngle=0.6), pose=looking_at((-0.3, -0.3, 0.5), (0, 0, 0)))
    flag_sets = {"NONE": RenderFlags.NONE, "RGBA": RenderFlags.RGBA, "DEPTH_ONLY": RenderFlags.DEPTH_ONLY,
                 "SEG": RenderFlags.SEG, "FLAT": RenderFlags.FLAT, "SHADOWS": SHADOWS,
                 "SKIP_CULL_FACES": RenderFlags.SKIP_CULL_FACES, "ALL_WIREFRAME": RenderFlags.ALL_WIREFRAME}

    def frames(r):
        out = {}
        for name, flags in flag_sets.items():
            got = r.render(plain_scene, flags=flags, seg_node_map={sphere_node: (255, 0, 0)} if name == "SEG" else None)
            out[name] = [np.array(a) for a in (got if isinstance(got, tuple) else (got,))]
        return out

    plain = frames(renderer)
    enable(renderer)
    enabled = frames(renderer)
    result["identical_enabled"] = {name: all(np.array_equal(a, b) for a, b in zip(plain[name], enabled[name]))
                                   for name in flag_sets}

    # 2. pyrender's example scene (SpotLight and DirectionalLight), glphong materials on its meshes, with and
    # without the shadow flags, against glphong's renderer of the same scene
    for lights in ("example", "side"):
        scene = example_scene(lights)
        colors = {}
        for name, flags in (("plain", RenderFlags.NONE), ("shadows", SHADOWS)):
            colors[name], _ = renderer.render(scene, flags=flags)
            measured, ours = agreement(colors[name], scene, width, height, flags)
            result[f"example_{lights}_{name}"] = measured
            result[f"example_{lights}_{name}_mean"] = float(ours.mean())
        result[f"example_{lights}_shadowed"] = float(np.mean(
            np.abs(colors["shadows"].astype(int) - colors["plain"].astype(int)).max(axis=-1) > 2))

    # the example's pyrender parts too (instanced face-coloured boxes, a point cloud): they draw beside glphong's
    # meshes; glphong's meshes cast onto pyrender's surfaces in pyrender's pass, and pyrender's onto glphong's
    mixed = example_scene("side", pyrender_parts=True)
    color_mixed, _ = renderer.render(mixed, flags=SHADOWS)
    unshadowed, _ = renderer.render(mixed)
    result["mixed_rendered"] = bool(color_mixed.any())
    result["mixed_shadowed"] = float(np.mean(np.abs(color_mixed.astype(int) - unshadowed.astype(int)).max(axis=-1) > 2))
    result["casts_onto_pyrender"] = _casts_onto_pyrender(renderer, width, height)

    # SHADOWS_POINT: glphong's surfaces get point-light shadows (cube maps); pyrender has none for its own
    # surfaces, and a warning says so when the frame has any
    point_scene = example_scene("side")
    for node in list(point_scene.light_nodes):
        point_scene.remove_node(node)
    point_scene.add(pyrender.PointLight(intensity=0.8), pose=translation(-0.25, 0.3, 0.45))
    point_scene.add(pyrender.Mesh.from_trimesh(trimesh.creation.icosphere(2, radius=0.04),
                                               material=GlphongMaterial(glphong.Lambert(0.3))), pose=translation(-0.1, -0.1, 0.1))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        color, _ = renderer.render(point_scene, flags=RenderFlags.SHADOWS_POINT)
    measured, _ = agreement(color, point_scene, width, height, RenderFlags.SHADOWS_POINT)
    plain_point, _ = renderer.render(point_scene)
    point_scene.add(pyrender.Mesh.from_trimesh(trimesh.creation.box(extents=(0.05, 0.05, 0.05))), pose=translation(0, 0.1, 0.1))
    with warnings.catch_warnings(record=True) as mixed_caught:
        warnings.simplefilter("always")
        renderer.render(point_scene, flags=RenderFlags.SHADOWS_POINT)
    result["point_shadows"] = measured | {
        "shadowed": float(np.mean(np.abs(color.astype(int) - plain_point.astype(int)).max(axis=-1) > 2)),
        "warning_glphong_only": " ".join(str(w.message) for w in caught),
        "warning_mixed": " ".join(str(w.message) for w in mixed_caught)}

    # 3. FLAT: glphong's surfaces drawn with their answer to an ambient light of radiance pi (Lambert: pi kd)
    flat = pyrender.Scene(ambient_light=[0.3, 0.3, 0.3])
    flat.add(pyrender.Mesh.from_trimesh(trimesh.creation.icosphere(3, radius=0.15),
                                        material=GlphongMaterial(glphong.Lambert((0.2, 0.1, 0.05)))))
    flat.add(pyrender.PerspectiveCamera(yfov=np.pi / 3.0), pose=translation(0, 0, 0.5))
    flat.add(pyrender.PointLight(intensity=1.0), pose=translation(0.2, 0.2, 0.5))
    color, _ = renderer.render(flat, flags=RenderFlags.FLAT)
    centre = color[height // 2 - 10:height // 2 + 10, width // 2 - 10:width // 2 + 10].reshape(-1, 3)
    expected = encode_srgb8((np.pi * np.array([0.2, 0.1, 0.05])).reshape(1, 1, 3))[0, 0]
    result["flat"] = {"expected": [int(v) for v in expected], "distinct": len(np.unique(centre, axis=0)),
                      "max_diff": int(np.abs(centre.astype(int) - expected.astype(int)).max())}

    # 4. orthographic and intrinsics cameras
    for name, camera in (("orthographic", pyrender.OrthographicCamera(xmag=0.3 * width / height, ymag=0.3)),
                         ("intrinsics", pyrender.IntrinsicsCamera(fx=150.0, fy=140.0, cx=width / 2 + 7.0,
                                                                  cy=height / 2 - 5.0))):
        scene = example_scene("side")
        scene.remove_node(scene.main_camera_node)
        scene.add(camera, pose=CAM_POSE)
        color, _ = renderer.render(scene)
        result[name], _ = agreement(color, scene, width, height)

    # 5. a resized renderer stays enabled (OSMesa re-creates pyrender's inner renderer on a new size)
    scene = example_scene("side")
    inner = renderer._renderer
    renderer.viewport_width, renderer.viewport_height = 96, 72
    color, _ = renderer.render(scene)
    result["resized"], _ = agreement(color, scene, 96, 72)
    result["resized"]["recreated"] = renderer._renderer is not inner
    release(renderer)  # glphong's release: the display the process shares is not ended

    # 6. renderers made where the user cannot reach them: enable_everywhere, as a context manager
    def third_party_render(scene, flags=RenderFlags.NONE):
        """A dataset generator's render: its own OffscreenRenderer, made and released inside."""
        r = pyrender.OffscreenRenderer(width, height)
        try:
            return r.render(scene, flags=flags)
        finally:
            release(r)

    with enable_everywhere():
        inside, _ = third_party_render(example_scene("side"))
        everywhere = {name: third_party_render(plain_scene, flags) for name, flags in (("NONE", 0), ("SHADOWS", SHADOWS))}
    result["everywhere"], _ = agreement(inside, example_scene("side"), width, height)
    result["everywhere_identical"] = {name: bool(np.array_equal(everywhere[name][0], plain[name][0])) for name in everywhere}
    try:
        third_party_render(example_scene("side"))
        result["after_everywhere"] = "accepted"
    except RuntimeError as exc:
        result["after_everywhere"] = str(exc)
    print(json.dumps(result))


def _casts_onto_pyrender(renderer, width, height):
    """A sphere over a pyrender-material board, lit from above with SHADOWS_DIRECTIONAL: the board's pixels that
    darken are the same whether the sphere has a glphong or a pyrender material (pyrender's shadow pass draws its
    geometry either way)."""
    out = {}
    for kind in ("glphong", "pyrender"):
        scene = pyrender.Scene(ambient_light=[0.02, 0.02, 0.02])
        board = scene.add(pyrender.Mesh.from_trimesh(trimesh.creation.box(extents=(0.6, 0.45, 0.02))))
        material = GlphongMaterial(glphong.Lambert(0.2)) if kind == "glphong" else None
        sphere = scene.add(pyrender.Mesh.from_trimesh(trimesh.creation.icosphere(3, radius=0.08), material=material),
                           pose=translation(0.0, 0.0, 0.15))
        scene.add(pyrender.PerspectiveCamera(yfov=np.pi / 3.0), pose=CAM_POSE)
        scene.add(pyrender.DirectionalLight(intensity=2.0), pose=looking_at((0.1, 0.1, 1.0), (0, 0, 0)))
        # the board's visible pixels (the sphere drawn in another colour: SEG leaves out the nodes it is not given)
        seg = renderer.render(scene, flags=RenderFlags.SEG,
                              seg_node_map={board: (255, 255, 255), sphere: (0, 0, 255)})[0][..., 0] > 0
        lit, _ = renderer.render(scene)
        shadowed, _ = renderer.render(scene, flags=RenderFlags.SHADOWS_DIRECTIONAL)
        out[kind] = seg & (np.abs(lit.astype(int) - shadowed.astype(int)).max(axis=-1) > 2)
    return {"board_pixels_darkened": int(out["glphong"].sum()), "pyrender_caster_darkened": int(out["pyrender"].sum()),
            "differing": int((out["glphong"] != out["pyrender"]).sum()),
            "same_as_pyrender_caster": float(np.mean(out["glphong"] == out["pyrender"]))}


if __name__ == "__main__":
    main()
