"""Benchmark peers (glphong.bench): the hand-written moderngl floor and the pyrender conversion.

pyrender is optional: its tests skip when it is not installed.  PyOpenGL reads
PYOPENGL_PLATFORM once per process, so pyrender runs on EGL in this process and on
OSMesa in a subprocess.
"""
import importlib.util
import json
import subprocess
import sys
import textwrap
import types

import numpy as np
import pytest
import trimesh

import glphong
from glphong.bench import HandWrittenRenderer, PyrenderRenderer, import_pyrender, pyrender_roughness, to_pyrender
from glphong.scene.geometry import MeshData

BACKENDS = ("egl", "osmesa")
WIDTH, HEIGHT = 96, 80

MATERIALS = {
    "phong": glphong.Phong(kd=(0.2, 0.1, 0.05), ks=(0.5, 0.6, 0.7), q=60.0, ka=0.01),
    "blinn": glphong.BlinnPhong(kd=0.1, ks=0.8, q=400.0, ka=(0.0, 0.01, 0.02)),
}


def sphere_scene(material, directional=False, power_scale=1.0):
    """An icosphere over a floor slab, two point lights (powers times ``power_scale``) and an ambient term."""
    camera = glphong.PerspectiveCamera.look_at((0.3, 0.8, 3.2), (0.0, 0.0, 0.0), yfov=0.9)
    lights = [glphong.PointLight((2.0, 2.5, 3.0), power_scale * np.array((80.0, 60.0, 40.0))),
              glphong.PointLight((-3.0, -1.0, 2.0), power_scale * 30.0)]
    if directional:
        lights.append(glphong.DirectionalLight((-0.2, -0.3, -1.0), (0.7, 0.6, 0.5)))
    scene = glphong.Scene(camera, lights=lights, ambient=glphong.AmbientLight((0.05, 0.04, 0.03)))
    scene.add(trimesh.creation.icosphere(3), material)
    floor = np.eye(4)
    floor[1, 3] = -1.1
    scene.add(trimesh.creation.box((4.0, 0.1, 4.0)), material, pose=floor, smooth=False)
    return scene


# --------------------------------------------------------------------------- hand-written floor


def test_import_glphong_never_imports_pyrender():
    code = ("import sys, glphong, glphong.bench; "
            "print(sorted(m for m in ('pyrender', 'OpenGL') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_floor_equals_glphong_renderer(make_renderer, backend, name):
    scene = sphere_scene(MATERIALS[name])
    frame = make_renderer(WIDTH, HEIGHT, backend).render(scene)
    with HandWrittenRenderer(WIDTH, HEIGHT, backend) as floor:
        image = floor.prepare(scene).render()
        again = floor.render()
        prepared_twice = floor.prepare(scene).render()
        floor.context.check_error("HandWrittenRenderer")
    assert image.shape == (HEIGHT, WIDTH, 3) and image.dtype == np.float32
    assert frame.mask.sum() > 2000 and np.percentile(frame.radiance[frame.mask], 90) > 1e-3
    # the same generated GLSL on the same inputs: equal up to float32 rounding (in practice bit-identical)
    np.testing.assert_allclose(image, frame.radiance, rtol=1e-6, atol=1e-7 * float(frame.radiance.max()))
    np.testing.assert_array_equal(again, image)
    np.testing.assert_array_equal(prepared_twice, image)


@pytest.mark.parametrize("backend", BACKENDS)
def test_textbook_floor_equals_naive_renderer(make_context, backend):
    make_context(backend)  # skips where the backend is unavailable
    scene = sphere_scene(MATERIALS["blinn"])
    with glphong.Renderer(WIDTH, HEIGHT, backend=backend, formulation="naive") as renderer:
        reference = renderer.render(scene).radiance
    with HandWrittenRenderer(WIDTH, HEIGHT, backend, shader="textbook") as floor:
        image = floor.prepare(scene).render()
        assert {floor.key(scene, obj).formulation for obj in scene.objects} == {"naive"}
    np.testing.assert_allclose(image, reference, rtol=1e-6, atol=1e-7 * float(reference.max()))


def test_floor_rejects_unknown_shader_and_unprepared_render(make_context):
    with pytest.raises(ValueError, match="shader must be one of"):
        HandWrittenRenderer(8, 8, "egl", shader="fast")
    make_context("egl")  # skips where EGL is unavailable
    floor = HandWrittenRenderer(8, 8, "egl")
    with pytest.raises(RuntimeError, match="prepare"):
        floor.render()
    floor.release()
    floor.release()


# --------------------------------------------------------------------------- pyrender, no pyrender needed


def test_to_pyrender_rejects_unattenuated_light_and_other_sample_counts():
    scene = sphere_scene(MATERIALS["phong"])
    scene.add_light(glphong.UnattenuatedPointLight((0.0, 3.0, 0.0), 0.5))
    with pytest.raises(ValueError, match="UnattenuatedPointLight"):
        to_pyrender(scene)
    with pytest.raises(ValueError, match="4x MSAA"):
        to_pyrender(sphere_scene(MATERIALS["phong"]), samples=8)


def test_pyrender_roughness_mapping():
    assert pyrender_roughness(glphong.Lambert(kd=0.2)) == 1.0
    assert pyrender_roughness(glphong.Phong(kd=0.2, ks=0.0, q=100.0)) == 1.0
    assert pyrender_roughness(glphong.BlinnPhong(kd=0.2, ks=0.5, q=0.0)) == 1.0
    assert pyrender_roughness(glphong.BlinnPhong(kd=0.2, ks=0.5, q=98.0)) == pytest.approx(0.02 ** 0.25)
    # Phong exponent q ~ Blinn exponent 4 q
    assert pyrender_roughness(glphong.Phong(kd=0.2, ks=0.5, q=25.0)) == pyrender_roughness(
        glphong.BlinnPhong(kd=0.2, ks=0.5, q=100.0))
    rough = [pyrender_roughness(glphong.BlinnPhong(kd=0.2, ks=0.5, q=q)) for q in (1, 10, 100, 1000)]
    assert rough == sorted(rough, reverse=True)


def test_import_pyrender_refuses_a_second_platform(monkeypatch):
    fake = types.ModuleType("OpenGL.platform")
    fake.PLATFORM = type("EGLPlatform", (), {})()
    monkeypatch.setitem(sys.modules, "OpenGL.platform", fake)
    with pytest.raises(RuntimeError, match="already use the 'egl' platform"):
        import_pyrender("osmesa")
    with pytest.raises(ValueError, match="platform must be one of"):
        import_pyrender("glx")


# --------------------------------------------------------------------------- pyrender (optional)


@pytest.fixture(scope="module")
def pyrender_egl():
    """pyrender imported on EGL; skips where pyrender is not installed."""
    if importlib.util.find_spec("pyrender") is None:
        pytest.skip("pyrender is not installed (optional: pip install glphong[pyrender])")
    # sets PYOPENGL_PLATFORM before the first import; a RuntimeError (pyrender already bound to
    # another platform in this process) is a bug in the suite and fails the test
    return import_pyrender("egl")


def coverage_agreement(covered, mask):
    """Fraction of pixels where ``covered`` equals ``mask``, and whether all differences lie on the silhouette."""
    from scipy import ndimage

    band = ndimage.binary_dilation(mask) & ~ndimage.binary_erosion(mask)
    differ = covered != mask
    return 1.0 - differ.mean(), bool(np.all(band[differ]))


def test_pyrender_light_and_material_mapping(pyrender_egl):
    pyrender = pyrender_egl
    scene = sphere_scene(MATERIALS["phong"], directional=True)
    doubled = sphere_scene(MATERIALS["phong"], directional=True, power_scale=2.0)
    converted, converted2 = to_pyrender(scene), to_pyrender(doubled)
    points = [n.light for n in sorted(converted.point_light_nodes, key=lambda n: n.translation[0])]
    points2 = [n.light for n in sorted(converted2.point_light_nodes, key=lambda n: n.translation[0])]
    glph = sorted((light for light in scene.lights if isinstance(light, glphong.PointLight)), key=lambda l: l.position[0])
    for light, p, p2 in zip(glph, points, points2):
        assert isinstance(p, pyrender.PointLight)
        assert p2.intensity == 2.0 * p.intensity                      # exactly
        np.testing.assert_array_equal(p2.color, p.color)
        np.testing.assert_allclose(p.color * p.intensity, light.intensity, rtol=1e-6)  # I = Phi / (4 pi)
    (directional,) = converted.directional_light_nodes
    np.testing.assert_allclose(-directional.matrix[:3, 2], scene.lights[2].direction, atol=1e-12)
    np.testing.assert_allclose(directional.light.color * directional.light.intensity, (0.7, 0.6, 0.5), rtol=1e-6)
    np.testing.assert_allclose(converted.ambient_light, np.array((0.05, 0.04, 0.03)) / np.pi)
    mesh_nodes = sorted(converted.mesh_nodes, key=lambda n: n.name)
    assert [n.name for n in mesh_nodes] == ["object0", "object1"]
    material = mesh_nodes[0].mesh.primitives[0].material
    np.testing.assert_allclose(material.baseColorFactor, [0.2 * np.pi, 0.1 * np.pi, 0.05 * np.pi, 1.0], rtol=1e-6)
    assert material.metallicFactor == 0.0 and not material.doubleSided  # pyrender's default: back faces culled
    two_sided = to_pyrender(scene, double_sided=True)
    assert all(p.material.doubleSided for n in two_sided.mesh_nodes for p in n.mesh.primitives)
    np.testing.assert_allclose(mesh_nodes[1].matrix, scene.objects[1].pose, atol=1e-12)
    np.testing.assert_allclose(converted.main_camera_node.matrix, scene.camera.pose, atol=1e-12)


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_pyrender_coverage_matches_glphong_egl(pyrender_egl, make_renderer, name):
    scene = sphere_scene(MATERIALS[name], directional=True)
    renderer = make_renderer(WIDTH, HEIGHT, "egl")
    frame = renderer.render(scene)
    with PyrenderRenderer(WIDTH, HEIGHT, "egl") as pyr:
        assert pyr.samples == 4
        colour = pyr.prepare(scene).render()
    assert colour.shape == (HEIGHT, WIDTH, 3) and colour.dtype == np.uint8
    assert colour.max() > 50
    agreement, on_silhouette = coverage_agreement(np.any(colour > 0, axis=-1), frame.mask)
    assert agreement > 0.98 and on_silhouette, agreement
    # glphong's EGL contexts still render the same after pyrender's came and went
    np.testing.assert_array_equal(renderer.render(scene).radiance, frame.radiance)


def test_pyrender_segmentation_gives_the_ids_glphong_does(pyrender_egl, make_renderer):
    """The benchmark's pyrender peer for frame passes (`PyrenderRenderer.render_segmentation`: a colour render and a
    SEG render): its ids are the objects' index + 1, those of glphong's instance pass on every pixel but silhouettes,
    its depth glphong's depth pass inside, up to the slope across the half pixel its multisampled depth is off the
    centre (the floor is seen at a grazing angle)."""
    scene = sphere_scene(glphong.Lambert(0.5), directional=True)
    scene.add(trimesh.creation.box((0.6, 0.6, 0.6)), glphong.Lambert(0.3),
              pose=trimesh.transformations.translation_matrix((0.9, 0.2, 0.6)))
    frame = make_renderer(WIDTH, HEIGHT, "egl").render(scene, passes=("instance", "depth"))
    with PyrenderRenderer(WIDTH, HEIGHT, "egl") as pyr:
        colour, depth, instance = pyr.prepare(scene).render_segmentation()
    assert colour.shape == (HEIGHT, WIDTH, 3) and set(np.unique(instance)) == set(range(len(scene.objects) + 1))
    assert np.mean(instance == frame.instance) > 0.98
    inside = (instance == frame.instance) & (instance > 0)
    relative = np.abs(depth[inside] - frame.depth[inside]) / frame.depth[inside]
    assert inside.sum() > 500 and np.median(relative) < 2e-2  # pyrender's depth is one of its 4 samples, off centre


def test_pyrender_renderer_refuses_second_platform(pyrender_egl):
    with pytest.raises(RuntimeError, match="new process"):
        PyrenderRenderer(8, 8, "osmesa")


_OSMESA_SCRIPT = textwrap.dedent("""
    import json, sys
    import numpy as np, trimesh, glphong
    from glphong.bench import PyrenderRenderer
    material = glphong.Phong(kd=(0.2, 0.1, 0.05), ks=0.5, q=60.0)
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0.3, 0.8, 3.2), (0, 0, 0), yfov=0.9),
                          lights=[glphong.PointLight((2.0, 2.5, 3.0), 80.0)], ambient=glphong.AmbientLight(0.05))
    scene.add(trimesh.creation.icosphere(3), material)
    with glphong.Renderer(96, 80, backend="osmesa") as r:
        mask = r.render(scene).mask
    with PyrenderRenderer(96, 80, "osmesa") as pyr:
        colour = pyr.prepare(scene).render()
        samples = pyr.samples
    covered = np.any(colour > 0, axis=-1)
    print(json.dumps({"max": int(colour.max()), "mismatch": int((covered != mask).sum()), "covered": int(mask.sum()),
                      "samples": samples, "pyrender_loaded": "pyrender" in sys.modules}))
""")


def test_pyrender_osmesa_in_subprocess(pyrender_egl, make_context):
    make_context("osmesa")  # skips where glphong has no OSMesa
    out = subprocess.run([sys.executable, "-c", _OSMESA_SCRIPT], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert result["max"] > 50 and result["covered"] > 1000 and result["samples"] == 1
    assert result["mismatch"] <= 0.02 * WIDTH * HEIGHT, result


@pytest.mark.parametrize("backend", BACKENDS)
def test_floor_with_shared_mesh_every_light_kind_and_unlit_objects(make_renderer, backend):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.6, 4.0), (0.0, 0.0, 0.0), yfov=0.9)
    lights = [glphong.PointLight((2.0, 2.0, 2.0), 60.0), glphong.UnattenuatedPointLight((-2.0, 1.0, 1.0), 0.4),
              glphong.DirectionalLight((0.3, -1.0, -0.2), (0.5, 0.4, 0.3))]
    scene = glphong.Scene(camera, lights=lights, ambient=glphong.AmbientLight(0.1))
    sphere = MeshData.from_trimesh(trimesh.creation.icosphere(2))
    for x, material in ((-1.2, MATERIALS["phong"]), (0.0, glphong.Lambert(kd=0.0, ka=0.2)), (1.2, MATERIALS["blinn"])):
        pose = np.eye(4)
        pose[0, 3] = x
        scene.add(sphere, material, pose=pose)  # one MeshData, three programs (one without normals)
    frame = make_renderer(WIDTH, HEIGHT, backend).render(scene)
    with HandWrittenRenderer(WIDTH, HEIGHT, backend) as floor:
        image = floor.prepare(scene).render()
    assert frame.mask.sum() > 1000
    np.testing.assert_allclose(image, frame.radiance, rtol=1e-6, atol=1e-7 * float(frame.radiance.max()))


def test_pyrender_intrinsics_camera_is_the_same_projection(pyrender_egl, make_renderer):
    """An `IntrinsicsCamera` becomes pyrender's IntrinsicsCamera with the principal point moved by half a
    pixel (pyrender measures it from the corner): the same projection matrix, and the same coverage."""
    scene = sphere_scene(MATERIALS[sorted(MATERIALS)[0]], directional=True)
    camera = glphong.IntrinsicsCamera(0.9 * WIDTH, 0.8 * WIDTH, WIDTH / 2 + 3.3, HEIGHT / 2 - 2.1, WIDTH, HEIGHT,
                                      pose=scene.camera.pose)
    scene.camera = camera
    converted = to_pyrender(scene)
    np.testing.assert_allclose(converted.main_camera_node.camera.get_projection_matrix(WIDTH, HEIGHT),
                               camera.projection_matrix(WIDTH / HEIGHT), rtol=1e-12, atol=1e-12)
    frame = make_renderer(WIDTH, HEIGHT, "egl").render(scene)
    with PyrenderRenderer(WIDTH, HEIGHT, "egl") as pyr:
        colour = pyr.prepare(scene).render()
    agreement, on_silhouette = coverage_agreement(np.any(colour > 0, axis=-1), frame.mask)
    assert agreement > 0.98 and on_silhouette, agreement


def test_pyrender_orthographic_camera_is_the_same_projection(pyrender_egl, make_renderer):
    scene = sphere_scene(MATERIALS[sorted(MATERIALS)[0]], directional=True)
    scene.camera = glphong.OrthographicCamera(1.3, pose=scene.camera.pose)
    with pytest.raises(ValueError, match="needs aspect_ratio"):
        to_pyrender(scene)
    converted = to_pyrender(scene, aspect_ratio=WIDTH / HEIGHT)
    np.testing.assert_allclose(converted.main_camera_node.camera.get_projection_matrix(WIDTH, HEIGHT),
                               scene.camera.projection_matrix(WIDTH / HEIGHT), rtol=1e-12, atol=1e-12)
    frame = make_renderer(WIDTH, HEIGHT, "egl").render(scene)
    with PyrenderRenderer(WIDTH, HEIGHT, "egl") as pyr:
        colour = pyr.prepare(scene).render()
    agreement, on_silhouette = coverage_agreement(np.any(colour > 0, axis=-1), frame.mask)
    assert agreement > 0.98 and on_silhouette, agreement
