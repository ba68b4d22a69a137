"""Back-face culling only where it cannot be seen (`glphong.scene.culling`, ``Renderer(culling='auto')``).

- `closed_outward`: closed, outward-wound meshes (glphong's sphere with its UV seam, trimesh's icosphere
  and box) pass; an open plane, an inside-out sphere, a sphere with a second inside-out part, a mesh with
  a doubled triangle and one with a degenerate triangle do not, each with its reason.
- Renders with culling against ``culling='off'``: the same coverage, and pixels differ only on silhouettes
  (where a back triangle tied in depth; at most 0.01% of the covered pixels); both pass `verify`.
- From inside a closed sphere, with the near plane cutting it, and with a mirroring pose, nothing is
  culled wrongly: the image equals ``culling='off'`` bit for bit.
"""
import numpy as np
import pytest
import trimesh

import glphong
from glphong import primitives
from glphong.scene.culling import closed_outward
from glphong.scene.geometry import MeshData


def test_closed_outward_meshes():
    assert closed_outward(primitives.sphere(3)) == (True, "closed, outward wound")
    assert closed_outward(MeshData.from_trimesh(trimesh.creation.icosphere(2)))[0]
    assert closed_outward(MeshData.from_trimesh(trimesh.creation.box()))[0]
    assert closed_outward(primitives.plane())[1].startswith("open")
    inverted = trimesh.creation.icosphere(2)
    inverted.invert()
    assert "winds inward" in closed_outward(MeshData.from_trimesh(inverted))[1]
    two = trimesh.util.concatenate([trimesh.creation.icosphere(2, radius=2.0), inverted])  # a big one holds volume
    assert "winds inward" in closed_outward(MeshData.from_trimesh(two))[1]
    box = MeshData.from_trimesh(trimesh.creation.box())
    doubled = MeshData(box.positions, box.normals, np.concatenate([box.indices, box.indices[:1]]))
    assert "used twice" in closed_outward(doubled)[1]
    degenerate = MeshData(box.positions, box.normals, np.concatenate([box.indices, [[0, 0, 1]]]))
    assert "degenerate" in closed_outward(degenerate)[1]


def _spheres(camera):
    scene = glphong.Scene(camera, [glphong.PointLight((2.0, 2.0, 2.0), 100.0)], ambient=glphong.AmbientLight(0.05))
    scene.add(primitives.sphere(4), glphong.Phong(0.2, 0.5, 30.0))
    rng = np.random.default_rng(0)
    for _ in range(30):
        pose = np.eye(4)
        pose[:3, 3] = rng.uniform(-1.5, 1.5, 3) - (0.0, 0.0, 1.0)
        scene.add(primitives.sphere(2, 0.15), glphong.BlinnPhong(0.1, 0.4, 60.0), pose=pose)
    return scene


def _pair(scene, backend, make_renderer, size=(96, 96)):
    auto = make_renderer(*size, backend)
    off = make_renderer(*size, backend, culling="off")
    return auto, off, auto.render(scene), off.render(scene)


def test_culled_render_is_the_same_image(glphong_backend, glphong_make_renderer):
    scene = _spheres(glphong.PerspectiveCamera.look_at((0.0, 0.4, 3.0), (0.0, 0.0, 0.0), yfov=0.8))
    auto, off, a, b = _pair(scene, glphong_backend, glphong_make_renderer, (160, 160))
    assert np.array_equal(a.mask, b.mask)
    differ = np.any(a.radiance != b.radiance, axis=-1)
    assert differ.sum() <= 1e-4 * a.mask.sum() + 1
    # only on silhouettes: within 2 pixels of an uncovered pixel or one of another object (the tie may
    # sit a pixel inside the silhouette, where the surface folds over)
    index = auto.gbuffer(scene).object_index
    padded = np.pad(index, 2, constant_values=-1)
    for r, c in zip(*np.nonzero(differ)):
        assert np.any(padded[r:r + 5, c:c + 5] != index[r, c])
    for renderer in (auto, off):
        assert glphong.verify(scene, renderer).passed


@pytest.mark.parametrize("where", ["inside", "near plane cuts", "mirrored"])
def test_no_culling_where_back_faces_show(glphong_backend, glphong_make_renderer, where):
    if where == "inside":
        camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 0.3), (0.0, 0.0, -1.0))
    elif where == "near plane cuts":
        camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 1.2), (0.0, 0.0, 0.0), znear=0.5)
    else:
        camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 4.0), (0.0, 0.0, 0.0))
    scene = glphong.Scene(camera, [glphong.PointLight((0.2, 0.3, 0.4), 5.0)], ambient=glphong.AmbientLight(0.05))
    pose = np.diag([-1.0, 1.0, 1.0, 1.0]) if where == "mirrored" else np.eye(4)
    scene.add(primitives.sphere(3), glphong.Lambert(0.3), pose=pose)
    _, _, a, b = _pair(scene, glphong_backend, glphong_make_renderer)
    assert a.mask.mean() > 0.2 and np.array_equal(a.radiance, b.radiance)


def test_describe_reports_each_objects_decision(glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0))
    scene = glphong.Scene(camera, [glphong.PointLight((1.0, 1.0, 2.0), 10.0)])
    scene.add(primitives.sphere(2, 0.5), glphong.Lambert(0.2), name="ball")
    scene.add(primitives.plane(), glphong.Lambert(0.2), name="floor")
    scene.add(primitives.sphere(2, 5.0), glphong.Lambert(0.2), name="dome")  # the camera is inside it
    lines = [line for d in glphong.describe(scene) for line in d.culling]
    assert lines == ["ball: culled: a closed, outward-wound mesh wholly between the near and far planes",
                     "floor: drawn: the mesh is not closed and outward wound (open: an edge has no opposite (a boundary))",
                     "dome: drawn: the camera is inside its bounding sphere, or a clip plane cuts it"]
    off = glphong_make_renderer(16, 16, "egl", culling="off")
    assert all(line.endswith("culling='off'") for d in glphong.describe(scene, off) for line in d.culling)
    assert "back faces:" in glphong.format_descriptions(glphong.describe(scene))
    # the renderer decides alike: what it draws with culling enabled
    auto = glphong_make_renderer(16, 16, "egl")
    auto.render(scene)
    from glphong.scene.culling import view_allows_culling

    eye, forward = tuple(camera.pose[:3, 3]), tuple(-camera.pose[:3, 2])
    culled = [e["radiance"].sphere is not None and view_allows_culling(*e["radiance"].sphere, eye, forward,
                                                                        camera.znear, camera.zfar)
              for e in (auto._entries[o] for o in scene.objects)]
    assert culled == [True, False, False]
