"""Scenes from files (`glphong.load_scene`, `glphong.Scene.from_trimesh`).

- An OBJ with an MTL written here: MTL's decimal values are kept exactly (0.123457 is no 8-bit colour);
  one object per ``usemtl`` part; a flat part seen straight down by an orthographic camera under a light
  straight above is ``Ka L_a + Kd + Ks`` for ``illum 2`` (v = r: the lobe is 1), ``Ka L_a + Kd`` for
  ``illum 1`` and ``Kd`` for ``illum 0``, to 1e-6; ``illum 5`` renders as ``illum 2`` with a warning.
- Without a camera or lights the default view frames the geometry (nothing touches the image border,
  more than 10% covered) and the render passes `verify`.
- ``Scene.from_trimesh`` keeps node transforms, names and a materials mapping; errors name the file.
"""
import numpy as np
import pytest
import trimesh

import glphong
from glphong.formats import parse_mtl

MTL = """# test materials
newmtl glossy
Kd 0.123457 0.234568 0.345679
Ks 0.25 0.125 0.0625
Ka 0.5 0.5 0.5
Ns 37.5
illum 2
newmtl matte
Kd 0.3 0.2 0.1
Ka 1 0 0
illum 1
newmtl flat
Kd 0.7 0.6 0.5
illum 0
newmtl mirror
Kd 0.1
Ks 0.2
Ns 10
illum 5
"""


def _quad(x0, material):
    """Two triangles of a unit square at z = 0 (normal +z), starting at x = x0, under ``usemtl material``."""
    return [f"usemtl {material}"], [(x0, 0.0), (x0 + 1.0, 0.0), (x0 + 1.0, 1.0), (x0, 1.0)]


def _write_obj(folder):
    lines, vertices = ["mtllib scene.mtl"], []
    faces = []
    for k, material in enumerate(("glossy", "matte", "flat", "mirror")):
        head, corners = _quad(1.5 * k, material)
        base = len(vertices)
        vertices += corners
        faces.append((head, base))
    lines += [f"v {x} {y} 0" for x, y in vertices] + ["vn 0 0 1"]
    for head, base in faces:
        lines += head + [f"f {base + 1}//1 {base + 2}//1 {base + 3}//1", f"f {base + 1}//1 {base + 3}//1 {base + 4}//1"]
    (folder / "scene.mtl").write_text(MTL)
    (folder / "scene.obj").write_text("\n".join(lines) + "\n")
    return folder / "scene.obj"


def test_mtl_values_are_read_exactly(tmp_path):
    entries = parse_mtl(_write_obj(tmp_path).with_suffix(".mtl"))
    assert entries["glossy"] == {"Kd": (0.123457, 0.234568, 0.345679), "Ks": (0.25, 0.125, 0.0625),
                                 "Ka": (0.5, 0.5, 0.5), "Ns": 37.5, "illum": 2}
    assert entries["mirror"]["Kd"] == (0.1, 0.1, 0.1)


def test_each_illum_renders_what_the_file_means(glphong_backend, glphong_make_renderer, tmp_path):
    path = _write_obj(tmp_path)
    camera = glphong.OrthographicCamera.look_at((2.75, 0.5, 3.0), (2.75, 0.5, 0.0), ymag=0.75)
    with pytest.warns(UserWarning, match="'mirror' has illum 5"):
        scene = glphong.load_scene(path, camera=camera, lights=[glphong.DirectionalLight((0.0, 0.0, -1.0), 1.0)],
                                   ambient=glphong.AmbientLight(0.1))
    assert len(scene.objects) == 4
    by_name = {o.material.kd: o for o in scene.objects if hasattr(o.material, "kd")}
    assert (0.123457, 0.234568, 0.345679) in by_name  # decimal values, not 8-bit colours
    renderer = glphong_make_renderer(120, 30, glphong_backend)
    frame = renderer.render(scene)
    index = renderer.gbuffer(scene).object_index
    expected = {"glossy": 0.05 + np.array([0.123457, 0.234568, 0.345679]) + np.array([0.25, 0.125, 0.0625]),
                "matte": np.array([0.1, 0.0, 0.0]) + np.array([0.3, 0.2, 0.1]),
                "flat": np.array([0.7, 0.6, 0.5]),
                "mirror": np.array([0.1, 0.1, 0.1]) + 0.2}
    names = {k: o.name for k, o in enumerate(scene.objects)}
    for k, name in names.items():
        material_name = next(m for m in expected if m in name)
        pixels = frame.radiance[index == k]
        assert len(pixels) > 50
        np.testing.assert_allclose(pixels, np.broadcast_to(expected[material_name], pixels.shape), rtol=1e-6)


def test_default_view_frames_the_geometry(glphong_backend, glphong_make_renderer):
    scene = glphong.load_scene("examples/data/torus.obj")
    assert scene.camera is not None and len(scene.lights) == 1 and scene.ambient is not None
    renderer = glphong_make_renderer(80, 80, glphong_backend)
    frame = renderer.render(scene)
    border = np.concatenate([frame.mask[0], frame.mask[-1], frame.mask[:, 0], frame.mask[:, -1]])
    assert not border.any() and frame.mask.mean() > 0.1
    assert glphong.verify(scene, renderer).passed


def test_from_trimesh_keeps_transforms_names_and_materials():
    box = trimesh.creation.box()
    tm = trimesh.Scene()
    shift = np.eye(4)
    shift[:3, 3] = (2.0, 0.0, 0.0)
    tm.add_geometry(box, node_name="left", geom_name="cube")
    tm.graph.update(frame_to="right", geometry="cube", matrix=shift)  # a second instance of the same part
    gold = glphong.Phong(0.3, 0.4, 20.0)
    scene = glphong.Scene.from_trimesh(tm, materials={"cube": gold})
    assert sorted(o.name for o in scene.objects) == ["left", "right"]
    right = next(o for o in scene.objects if o.name == "right")
    np.testing.assert_array_equal(right.pose, shift)
    assert all(o.material is gold for o in scene.objects)
    with pytest.raises(TypeError, match="must give a glphong material"):
        glphong.Scene.from_trimesh(tm, materials=lambda name, geometry: "gold")


def test_errors_name_the_file(tmp_path):
    with pytest.raises(ValueError, match=r"glphong reads \.obj, \.gltf, \.glb scene files \(got '\.stl'\)"):
        glphong.load_scene(tmp_path / "a.stl")
    with pytest.raises(ValueError, match="no such file"):
        glphong.load_scene(tmp_path / "missing.obj")
    (tmp_path / "bad.mtl").write_text("newmtl x\nKd 0.1 red 0.3\n")
    with pytest.raises(ValueError, match=r"bad.mtl: line 2: Kd needs finite numbers"):
        parse_mtl(tmp_path / "bad.mtl")


def test_cli_render_file(tmp_path, capsys):
    from PIL import Image

    from glphong.tools.cli import main

    path = _write_obj(tmp_path)
    out = tmp_path / "out.png"
    code = main(["render", str(path), "--width", "64", "--height", "48", "--verify", "--out", str(out)])
    captured = capsys.readouterr()
    text = captured.out
    assert code == 0 and "4 object(s), 64x48" in text and "PASS" in text
    warnings = [line for line in captured.err.splitlines() if "warning" in line]
    assert len(warnings) == 1 and warnings[0].startswith("glphong render: warning: ") and "illum 5" in warnings[0]
    assert Image.open(out).size == (64, 48)
    # the stable formulation everywhere on request: verified too, and the same picture to the 8-bit step
    stable = tmp_path / "stable.png"
    assert main(["render", str(path), "--width", "64", "--height", "48", "--verify", "--numerics", "stable",
                 "--out", str(stable)]) == 0 and "PASS" in capsys.readouterr().out
    difference = np.abs(np.asarray(Image.open(out), int) - np.asarray(Image.open(stable), int))
    assert difference.max() <= 1
    assert main(["render", str(tmp_path / "scene.stl")]) == 2
    assert "glphong reads .obj, .gltf, .glb scene files" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["render", str(path), "--width", "0"])


def test_cli_turntable_frames(tmp_path, capsys):
    from PIL import Image

    from glphong.tools.cli import main

    folder = tmp_path / "spin"
    assert main(["render", "examples/data/torus.obj", "--frames", "3", "--width", "40", "--height", "30",
                 "--out", str(folder)]) == 0
    frames = sorted(p.name for p in folder.glob("frame_*.png"))
    assert frames == ["frame_000000.png", "frame_000001.png", "frame_000002.png"]
    images = [np.asarray(Image.open(folder / f)) for f in frames]
    assert images[0].shape == (30, 40, 3) and not np.array_equal(images[0], images[1])  # the view turned
    with pytest.raises(SystemExit):
        main(["render", "--frames", "3"])
    assert "--frames needs a scene FILE" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["render", "examples/data/torus.obj", "--out", str(tmp_path / "x.jpg")])
    assert "--out must end in .png" in capsys.readouterr().err
