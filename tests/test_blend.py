"""Blended surfaces (glphong.AlphaBlend; glTF's alphaMode BLEND) composited per pixel in depth order.

Independent checks: constant-radiance surfaces (``ka`` alone, no lights: ``L = k_a`` exactly) seen by an
orthographic camera looking down -z, so the surfaces covering a pixel centre and their order are known in closed form
(axis-aligned rectangles, planes ``z = +-x tan(theta)``, a sphere's disc); the expected colour is the glTF
specification's "over" applied back to front, written here (`_over`), never the renderer's front-to-back
accumulation.  Lit surfaces: ``L = k_d cos(theta) Phi / (4 pi d^2)`` of a point light, written here.
"""
import itertools
import json
import warnings

import numpy as np
import pytest
import trimesh

import glphong
from glphong import primitives
from glphong.checks import blend_twin
from glphong.gpu.peeling import BlendCapWarning
from glphong.scene.geometry import MeshData

SIZE = 40  # px; the orthographic view spans [-1, 1] m on both axes: 0.05 m a pixel
BACKGROUND = (0.0, 0.0, 1.0)
#: (centre x, centre y, z, side, colour, alpha) of the quads
QUADS = [(-0.25, 0.0, 0.3, 1.0, (1.0, 0.0, 0.0), 0.5), (0.25, 0.1, 0.2, 1.0, (0.0, 1.0, 0.0), 0.25),
         (0.0, -0.2, 0.1, 0.8, (0.2, 0.3, 0.9), 0.7)]


def _pose(x=0.0, y=0.0, z=0.0, turn=0.0):
    """Translation after a rotation of ``turn`` [rad] about +y."""
    pose = np.eye(4)
    c, s = np.cos(turn), np.sin(turn)
    pose[:3, :3] = [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
    pose[:3, 3] = (x, y, z)
    return pose


def _camera():
    return glphong.OrthographicCamera.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ymag=1.0)


def _centres():
    """Pixel centres (x, y) [m], each (SIZE, SIZE), row 0 at the top."""
    t = (np.arange(SIZE) + 0.5) / SIZE * 2.0 - 1.0
    return np.meshgrid(t, -t)


def _over(layers, background):
    """The glTF "over", back to front: ``C = a c + (1 - a) C_behind`` for the layers ``(z, colour, alpha)`` of one
    pixel, farthest first."""
    out = np.asarray(background, float)
    for _, colour, alpha in sorted(layers, key=lambda layer: layer[0]):
        out = alpha * np.asarray(colour, float) + (1.0 - alpha) * out
    return out


def _quad_scene(order, quads=QUADS, background=True):
    scene = glphong.Scene(_camera())
    for i in order:
        x, y, z, side, colour, alpha = quads[i]
        scene.add(primitives.plane(size=side), glphong.Lambert(0.0, ka=colour, alpha_blend=glphong.AlphaBlend(alpha)),
                  pose=_pose(x, y, z), name=f"quad{i}")
    if background:
        scene.add(primitives.plane(size=4.0), glphong.Lambert(0.0, ka=BACKGROUND), pose=_pose(z=-1.0), name="floor")
    return scene


def _quad_expectation(quads, cap=None):
    """Expected radiance (SIZE, SIZE, 3), the pixels at least 1.2 px from every edge, and the layer counts."""
    x, y = _centres()
    expected = np.zeros((SIZE, SIZE, 3))
    clear = np.ones((SIZE, SIZE), bool)
    count = np.zeros((SIZE, SIZE), int)
    for j, i in np.ndindex(SIZE, SIZE):
        inside = []
        for qx, qy, z, side, colour, alpha in quads:
            dx, dy = abs(x[j, i] - qx) - side / 2, abs(y[j, i] - qy) - side / 2
            clear[j, i] &= min(abs(dx), abs(dy)) > 0.06 or max(dx, dy) > 0.06
            if dx < 0 and dy < 0:
                inside.append((z, colour, alpha))
        count[j, i] = len(inside)
        kept = sorted(inside, key=lambda layer: -layer[0])[:cap]  # the cap keeps the nearest
        expected[j, i] = _over(kept, BACKGROUND)
    return expected, clear, count


@pytest.mark.parametrize("count", [2, 3])
def test_overlapping_quads_in_every_order_of_drawing(count, glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    expected, clear, layers = _quad_expectation(QUADS[:count])
    assert layers.max() == count and (layers[clear] == count).sum() > 20
    frames = [renderer.render(_quad_scene(order, QUADS[:count])) for order in itertools.permutations(range(count))]
    for frame in frames:  # the order of drawing changes nothing, not one bit
        np.testing.assert_array_equal(frame.radiance, frames[0].radiance)
        assert frame.blend_layers == count and frame.blend_cut is None
    np.testing.assert_allclose(frames[0].radiance[clear], expected[clear], rtol=1e-6, atol=1e-7)
    np.testing.assert_array_equal(frames[0].coverage, 1.0)  # the opaque floor behind everything
    report = glphong.verify(_quad_scene(range(count), QUADS[:count]), renderer)
    assert report.passed, report.summary()


def test_opaque_surfaces_hide_the_blended_ones_behind_them(glphong_backend, glphong_make_renderer):
    """A blended quad (green, 0.5) at z = 0 half hidden by an opaque one (red) at z = 0.3, another blended one behind
    the floor: the hidden parts add nothing."""
    scene = _quad_scene(range(0), background=True)
    for z, side, colour, blend in ((0.0, 1.2, (0.0, 1.0, 0.0), 0.5), (0.3, 0.6, (1.0, 0.0, 0.0), None),
                                   (-1.5, 1.6, (1.0, 1.0, 0.0), 0.9)):
        scene.add(primitives.plane(size=side), glphong.Lambert(0.0, ka=colour, alpha_blend=blend and
                                                               glphong.AlphaBlend(blend)), pose=_pose(z=z))
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    frame = renderer.render(scene)
    x, y = _centres()
    reach = np.maximum(abs(x), abs(y))
    hidden, ring, out = reach < 0.25, (reach > 0.35) & (reach < 0.55), reach > 0.65
    np.testing.assert_array_equal(frame.radiance[hidden], np.broadcast_to((1.0, 0.0, 0.0), (hidden.sum(), 3)))
    np.testing.assert_allclose(frame.radiance[ring], np.broadcast_to(_over([(0.0, (0.0, 1.0, 0.0), 0.5)], BACKGROUND),
                                                                     (ring.sum(), 3)), rtol=1e-6)
    np.testing.assert_array_equal(frame.radiance[out], np.broadcast_to(BACKGROUND, (out.sum(), 3)))
    assert frame.blend_layers == 1
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()


def test_coverage_is_the_composite_alpha_without_an_opaque_surface(glphong_make_renderer):
    renderer = glphong_make_renderer(SIZE, SIZE, "egl")
    frame = renderer.render(_quad_scene(range(3), background=False))
    _, clear, _ = _quad_expectation(QUADS)
    x, y = _centres()
    cover = np.zeros((SIZE, SIZE))
    for qx, qy, _, side, _, alpha in QUADS:
        inside = (abs(x - qx) < side / 2) & (abs(y - qy) < side / 2)
        cover = np.where(inside, alpha + (1.0 - alpha) * cover, cover)
    np.testing.assert_allclose(frame.coverage[clear], cover[clear], rtol=1e-6)
    np.testing.assert_array_equal(frame.mask[clear], cover[clear] > 0)


@pytest.mark.parametrize("two_sided", [True, False])
def test_a_transparent_sphere_shows_its_far_side_when_double_sided(two_sided, glphong_backend, glphong_make_renderer):
    """glTF doubleSided: a two-sided blended sphere is two layers inside its outline, a one-sided one (back faces
    culled) one."""
    colour, alpha, radius = (0.9, 0.6, 0.1), 0.35, 0.7
    scene = glphong.Scene(_camera())
    scene.add(primitives.sphere(3, radius), glphong.Lambert(0.0, ka=colour, two_sided=two_sided,
                                                            alpha_blend=glphong.AlphaBlend(alpha)))
    scene.add(primitives.plane(size=4.0), glphong.Lambert(0.0, ka=BACKGROUND), pose=_pose(z=-2.0))
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    frame = renderer.render(scene)
    x, y = _centres()
    inside = np.hypot(x, y) < radius * np.cos(np.pi / 5 / 8) - 0.1  # inside the polyhedron's outline, 2 px in
    layers = [(1.0, colour, alpha)] + ([(-1.0, colour, alpha)] if two_sided else [])
    np.testing.assert_allclose(frame.radiance[inside], np.broadcast_to(_over(layers, BACKGROUND), (inside.sum(), 3)),
                               rtol=1e-6)
    assert frame.blend_layers == (2 if two_sided else 1) and inside.sum() > 400
    report = glphong.verify(scene, renderer)  # the twin culls the one-sided sphere's back faces too
    assert report.passed and report.summary()["blend"]["layers"] == (2 if two_sided else 1), report.summary()


def test_a_lit_transparent_sphere_verifies(glphong_backend, glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.3, 0.2, 4.0), (0.0, 0.0, 0.0), yfov=0.7)
    scene = glphong.Scene(camera, [glphong.PointLight((1.0, 2.0, 3.0), 30.0)], ambient=glphong.AmbientLight(0.05))
    scene.add(primitives.sphere(3), glphong.Phong(0.5, 0.3, 20.0, alpha_blend=glphong.AlphaBlend(0.4)),
              pose=_pose(z=0.5))
    scene.add(primitives.plane(size=4.0), glphong.Lambert(0.6), pose=_pose(z=-1.0))
    report = glphong.verify(scene, glphong_make_renderer(64, 48, glphong_backend))
    blend = report.summary()["blend"]
    assert report.passed and blend["layers"] == 2 and blend["unchecked"] < 10, report.summary()


def test_interpenetrating_meshes_change_order_inside_a_row(glphong_backend, glphong_make_renderer):
    """Planes z = -x tan(t) (red) and z = x tan(t) (green) cross at x = 0: red is in front left of it, green
    right."""
    turn, red, green = 0.4, ((1.0, 0.0, 0.0), 0.5), ((0.0, 1.0, 0.0), 0.6)
    scene = glphong.Scene(_camera())
    for (colour, alpha), angle in ((red, turn), (green, -turn)):
        scene.add(primitives.plane(size=1.6), glphong.Lambert(0.0, ka=colour, alpha_blend=glphong.AlphaBlend(alpha)),
                  pose=_pose(turn=angle))
    scene.add(primitives.plane(size=4.0), glphong.Lambert(0.0, ka=BACKGROUND), pose=_pose(z=-1.0))
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    frame = renderer.render(scene)
    x, y = _centres()
    half = 0.8 * np.cos(turn)
    checked = (abs(x) > 0.1) & (abs(x) < half - 0.1) & (abs(y) < 0.7)
    z_red, z_green = -x * np.tan(turn), x * np.tan(turn)
    expected = np.array([[_over([(z_red[j, i], *red), (z_green[j, i], *green)], BACKGROUND) for i in range(SIZE)]
                         for j in range(SIZE)])
    np.testing.assert_allclose(frame.radiance[checked], expected[checked], rtol=1e-6)
    row = SIZE // 2
    left, right = frame.radiance[row, 10], frame.radiance[row, SIZE - 11]
    assert left[0] > left[1] and right[1] > right[0]  # the order changed inside the row
    report = glphong.verify(scene, renderer)
    assert report.passed and report.summary()["blend"]["unchecked"] <= 2 * SIZE, report.summary()


def test_a_transparent_surface_over_an_opaque_one_under_a_point_light(glphong_backend, glphong_make_renderer):
    kd_glass, kd_floor, alpha, light, power = 0.2, 0.3, 0.6, np.array([0.3, 0.2, 2.0]), 50.0
    scene = glphong.Scene(_camera(), [glphong.PointLight(light, power)])
    scene.add(primitives.plane(size=1.5), glphong.Lambert(kd_glass, alpha_blend=glphong.AlphaBlend(alpha)),
              pose=_pose(z=0.5))
    scene.add(primitives.plane(size=4.0), glphong.Lambert(kd_floor), pose=_pose())
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    frame = renderer.render(scene)
    x, y = _centres()

    def lit(kd, z):  # k_d cos E, E = Phi / (4 pi d^2), the light above the plane z
        d = np.sqrt((light[0] - x) ** 2 + (light[1] - y) ** 2 + (light[2] - z) ** 2)
        return kd * (light[2] - z) / d * power / (4.0 * np.pi * d * d)

    expected = alpha * lit(kd_glass, 0.5) + (1.0 - alpha) * lit(kd_floor, 0.0)
    inside = (abs(x) < 0.7) & (abs(y) < 0.7)
    # measured: 2.4e-7 at most (float32 shading and blending)
    np.testing.assert_allclose(frame.radiance[inside], np.repeat(expected[inside][:, None], 3, axis=1), rtol=2e-6)
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()


def test_the_layer_cap_is_reported(glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend, blend_layers=2)
    with pytest.warns(BlendCapWarning, match="pixels have more than 2 blended layers"):
        frame = renderer.render(_quad_scene(range(3)))
    expected, clear, count = _quad_expectation(QUADS, cap=2)
    assert frame.blend_layers == 2
    np.testing.assert_array_equal(frame.blend_cut[clear], count[clear] > 2)
    assert (count[clear] > 2).sum() > 20
    np.testing.assert_allclose(frame.radiance[clear], expected[clear], rtol=1e-6, atol=1e-7)
    with pytest.warns(BlendCapWarning):
        report = glphong.verify(_quad_scene(range(3)), renderer)
    blend = report.summary()["blend"]
    assert report.passed and blend["cut"] == int(frame.blend_cut.sum()) and blend["cap_max_error"] > 0.01, blend


def test_the_geometry_passes_are_the_nearest_opaque_surface(glphong_make_renderer):
    scene = _quad_scene(range(3))
    renderer = glphong_make_renderer(SIZE, SIZE, "egl")
    frame = renderer.render(scene, passes=("radiance", "depth", "instance", "matte"))
    floor = scene.objects[3].instance_id
    assert (frame.instance == floor).all() and np.allclose(frame.depth, 6.0, rtol=1e-6)
    assert (frame.matte_ids[..., 0] == floor).all()
    assert renderer.gbuffer(scene).object_index.max() == 3  # the G-buffer holds the floor alone
    report = glphong.verify(scene, renderer, passes=("depth", "instance"))
    assert report.passed, report.summary()


def test_a_planted_error_in_the_composite_is_caught(monkeypatch, glphong_make_renderer):
    """The twin composited in the wrong order (farthest first) no longer matches: verify sees it."""
    renderer = glphong_make_renderer(SIZE, SIZE, "egl")
    assert glphong.verify(_quad_scene(range(3)), renderer).passed
    original = blend_twin.composite
    monkeypatch.setattr(blend_twin, "composite", lambda alphas, values, behind: original(alphas[::-1], values[::-1],
                                                                                        behind))
    report = glphong.verify(_quad_scene(range(3)), renderer)
    assert not report.passed and report.outside_count > 20


def test_refusals_name_the_option():
    with pytest.raises(ValueError, match=r"alpha must be in \[0, 1\]|alpha"):
        glphong.AlphaBlend(1.5)
    with pytest.raises(ValueError, match="alpha mask or alpha blending, not both"):
        glphong.Lambert(0.2, alpha_mask=glphong.AlphaMask(0.5, 1.0), alpha_blend=glphong.AlphaBlend(0.5))
    with pytest.raises(TypeError, match="alpha_blend must be a glphong.AlphaBlend"):
        glphong.Lambert(0.2, alpha_blend=0.5)
    scene = _quad_scene(range(2))
    for options, name in (({"shading": "vertex"}, "shading='vertex'"), ({"specialise": False}, "specialise=False"),
                          ({"samples": 2}, "samples=2")):
        with glphong.Renderer(16, 16, backend="egl", **options) as renderer:
            with pytest.raises(ValueError, match=name):
                renderer.render(scene)


def test_scenes_without_blending_leave_the_peeling_out():
    renderer = glphong.Renderer(SIZE, SIZE, backend="egl")  # its own program cache
    opaque = glphong.Scene(_camera())
    opaque.add(primitives.plane(size=1.0), glphong.Lambert(0.0, ka=0.5))
    frame = renderer.render(opaque)
    assert frame.blend_layers is None and frame.blend_cut is None and ("peeling",) not in renderer._targets
    # the peel's code is compiled out: ALPHA_BLEND is not defined (glsl/mesh_fragment.glsl's #ifdef)
    assert all("#define ALPHA_BLEND" not in renderer.programs.get(k).fragment_source for k in renderer.programs.keys())
    renderer.render(_quad_scene(range(3)))
    kinds = sorted(getattr(k, "alpha_blend", 0) for k in renderer.programs.keys())
    assert kinds.count(1) and kinds.count(2) and ("peeling",) in renderer._targets
    floor = renderer.program_key(_quad_scene(range(3)), _quad_scene(range(3)).objects[3])
    assert floor.alpha_blend == 0 and "ALPHA_BLEND" not in dict(floor.defines())
    renderer.release()


def test_supersampled_blending_and_srgb8(glphong_make_renderer):
    scene = _quad_scene(range(3))
    plain = glphong_make_renderer(SIZE, SIZE, "egl").render(scene)
    double = glphong_make_renderer(SIZE, SIZE, "egl", supersample=2)
    frame = double.render(scene)
    _, clear, _ = _quad_expectation(QUADS)
    np.testing.assert_allclose(frame.radiance[clear], plain.radiance[clear], rtol=1e-6)
    encoded = glphong_make_renderer(SIZE, SIZE, "egl").render_srgb8(scene)
    np.testing.assert_array_equal(encoded, plain.to_srgb8())


def test_materials_keep_their_blending_in_json_and_files(tmp_path):
    material = glphong.Phong(0.5, 0.3, 20.0, alpha_blend=glphong.AlphaBlend(0.25))
    from glphong.definitions.as_json import material_from_json, material_to_json
    assert material_from_json(json.loads(json.dumps(material_to_json(material)))) == material
    assert "AlphaBlend(0.25)" in repr(material)
    scene = _quad_scene(range(1), background=False)
    glphong.save_gltf(scene, tmp_path / "blend.gltf")
    assert glphong.load_scene(tmp_path / "blend.gltf").objects[0].material == scene.objects[0].material
    entry = json.loads((tmp_path / "blend.gltf").read_text())["materials"][0]  # what other viewers read
    alpha = scene.objects[0].material.alpha_blend.alpha
    assert entry["alphaMode"] == "BLEND" and entry["pbrMetallicRoughness"]["baseColorFactor"][3] == alpha
    del entry["extras"]  # without glphong's own record, the file's glTF fields alone give the blend back
    assert glphong.formats.gltf_scene.gltf_pbr_material(entry).alpha_blend == glphong.AlphaBlend(alpha)


def test_gltf_blend_loads_and_renders(tmp_path, glphong_make_renderer):
    corners = [[-0.5, -0.5, 0.3], [0.5, -0.5, 0.3], [0.5, 0.5, 0.3], [-0.5, 0.5, 0.3]]
    quad = trimesh.Trimesh(corners, [[0, 1, 2], [0, 2, 3]], process=False)
    quad.visual = trimesh.visual.TextureVisuals(material=trimesh.visual.material.PBRMaterial(
        baseColorFactor=[255, 0, 0, 102], metallicFactor=0.0))
    files = trimesh.Scene(quad).export(file_type="gltf")
    for name, data in files.items():
        (tmp_path / name).write_bytes(data)
    document = json.loads(files["model.gltf"])
    document["materials"][0]["alphaMode"] = "BLEND"
    path = tmp_path / "blend.gltf"
    path.write_text(json.dumps(document))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = glphong.load_scene(path, lights=[], camera=_camera())
    material = scene.objects[0].material
    assert material.alpha_blend == glphong.AlphaBlend(float(np.float32(102 / 255))) or \
        material.alpha_blend.alpha == pytest.approx(102 / 255, abs=1e-6)
    scene.add(primitives.plane(size=4.0), glphong.Lambert(0.0, ka=BACKGROUND), pose=_pose(z=-1.0))
    report = glphong.verify(scene, glphong_make_renderer(SIZE, SIZE, "egl"))
    assert report.passed and report.summary()["blend"]["layers"] == 1, report.summary()


def test_a_textured_alpha_blends_as_its_bilinear_filter_reads(glphong_backend, glphong_make_renderer):
    """Two texels, opaque then clear, bilinear and clamped: alpha = 0.8 clip((0.75 - u) / 0.5, 0, 1), u = x + 1/2."""
    texels = np.array([[255, 0]], np.uint8)
    alpha = glphong.Texture(texels, 0.8, srgb=False, channel="r", wrap="clamp", filter="bilinear")
    colour = (1.0, 0.5, 0.0)
    scene = glphong.Scene(_camera())
    scene.add(primitives.plane(size=1.0), glphong.Lambert(0.0, ka=colour, alpha_blend=glphong.AlphaBlend(alpha)), pose=_pose(z=0.2))
    scene.add(primitives.plane(size=4.0), glphong.Lambert(0.0, ka=BACKGROUND), pose=_pose(z=-1.0))
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    frame = renderer.render(scene)
    x, y = _centres()
    a = 0.8 * np.clip((0.75 - (x + 0.5)) / 0.5, 0.0, 1.0)
    expected = a[..., None] * np.array(colour) + (1.0 - a[..., None]) * np.array(BACKGROUND)
    inside = (abs(x) < 0.45) & (abs(y) < 0.45)
    # GL leaves the filter weights' precision to the implementation: 2^-7 of the texels' spread (the band's T)
    np.testing.assert_allclose(frame.radiance[inside], expected[inside], atol=0.8 * 2.0 ** -7 + 1e-6)
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()
    with pytest.raises(ValueError, match="has no uvs"):
        bare = glphong.Scene(_camera())
        sphere = primitives.sphere(1)
        bare.add(MeshData(sphere.positions, sphere.normals, sphere.indices),
                 glphong.Lambert(0.2, alpha_blend=glphong.AlphaBlend(alpha)))
        renderer.render(bare)


def test_example_transparency(tmp_path, load_example):
    report = load_example("transparency").main(tmp_path / "transparency.png", 160, 120)
    assert report.passed and report.summary()["blend"]["layers"] == 2 and (tmp_path / "transparency.png").is_file()


def test_blended_frames_hold_no_growing_gl_objects_across_renders_and_sizes(glphong_make_renderer):
    """The peel's targets are made once a size and target and dropped with the renderer's targets on resize: many
    blended frames, float and 8-bit, in both drawing orders and across two sizes, leave the renderer's GL object count
    where the first round put it (programs included), and a frame after resizing back is bit for bit the first."""
    renderer = glphong_make_renderer(SIZE, SIZE, "egl")
    scenes = [_quad_scene(order) for order in ((0, 1, 2), (2, 1, 0))]

    def one_round():
        for scene in scenes:
            renderer.render(scene)
            renderer.render_srgb8(scene)

    first = renderer.render(scenes[0]).radiance.copy()
    one_round()
    baseline = renderer.gl_object_count()
    for _ in range(6):
        one_round()
    assert renderer.gl_object_count() == baseline
    renderer.resize(SIZE + 8, SIZE)
    assert renderer.render(scenes[0]).radiance.shape == (SIZE, SIZE + 8, 3)
    renderer.resize(SIZE, SIZE)
    np.testing.assert_array_equal(renderer.render(scenes[0]).radiance, first)
    one_round()
    assert renderer.gl_object_count() == baseline


def test_a_textured_alpha_saved_for_other_viewers_is_warned_about(tmp_path):
    """glTF's alpha is baseColorFactor.a times the base-colour texture's alpha; glphong writes its own alpha texture
    in its extras only, so other viewers would see alpha 1: the save says so, and glphong reads it back exactly."""
    alpha = glphong.Texture(np.array([[255, 0]], np.uint8), 0.8, srgb=False, channel="r")
    scene = glphong.Scene(_camera())
    scene.add(primitives.plane(size=1.0), glphong.Lambert(0.5, alpha_blend=glphong.AlphaBlend(alpha)))
    with pytest.warns(UserWarning, match="textured alpha is written in glphong's extras only"):
        glphong.save_gltf(scene, tmp_path / "textured.gltf")
    assert json.loads((tmp_path / "textured.gltf").read_text())["materials"][0]["alphaMode"] == "BLEND"
    assert glphong.load_scene(tmp_path / "textured.gltf").objects[0].material == scene.objects[0].material
