"""What pyrender users bring beyond materials, on pyrender's EGL and OSMesa platforms: its example scene (SpotLight,
DirectionalLight), its render flags (shadows, FLAT, and every flag byte-identical where no glphong material is
drawn), its orthographic and intrinsics cameras, a resized renderer, and renderers made where the user cannot reach
them (`enable_everywhere`).

pyrender fixes its OpenGL platform once per process, so each platform runs `pyrender_flags_check.py` in a
subprocess that reports its measurements as JSON.  Agreement is measured on the interior of glphong's own
render of `scene_from_pyrender` (silhouettes eroded by 2 px; pyrender multisamples on EGL only).
"""
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

if importlib.util.find_spec("pyrender") is None:  # find_spec: importing pyrender here would fix its platform
    pytest.skip("pyrender is not installed (pip install 'glphong[pyrender]')", allow_module_level=True)

CHECK = Path(__file__).with_name("pyrender_flags_check.py")


@pytest.fixture(scope="module", params=("egl", "osmesa"))
def measured(request, pyrender_check):
    return request.param, pyrender_check(CHECK, request.param, timeout=600)


def _agrees(m, platform, exact=0.999):
    assert m["pixels"] > 1500, m
    assert m["within_one"] >= 0.999, m  # one 8-bit step after the same sRGB encoding
    assert m["exact"] >= exact, m


def test_no_glphong_material_leaves_every_flag_byte_identical(measured):
    """The embedding switched on, on one renderer and everywhere: pyrender's frames (colour and depth) are
    byte-identical under NONE, RGBA, DEPTH_ONLY, SEG, FLAT, the shadow flags, SKIP_CULL_FACES and ALL_WIREFRAME."""
    _, m = measured
    assert m["identical_enabled"] == {name: True for name in m["identical_enabled"]} and len(m["identical_enabled"]) == 8
    assert m["everywhere_identical"] == {"NONE": True, "SHADOWS": True}


def test_example_scene_with_spot_and_directional_light_equals_glphong(measured):
    """pyrender's example scene (a SpotLight and a DirectionalLight at the camera, ambient 0.02) with glphong
    materials on its meshes, and the same lights from the side: the frame equals glphong's render."""
    platform, m = measured
    for lights in ("example", "side"):
        _agrees(m[f"example_{lights}_plain"], platform)


def test_shadow_flags_are_honoured_on_glphong_surfaces(measured):
    """SHADOWS_DIRECTIONAL | SHADOWS_SPOT: glphong's surfaces read glphong's own maps of the two lights, and the frame
    equals glphong's render with those lights' shadows=True; the shadows are there (pixels change, the frame
    darkens)."""
    platform, m = measured
    for lights in ("example", "side"):
        _agrees(m[f"example_{lights}_shadows"], platform)
        assert m[f"example_{lights}_shadows_mean"] < m[f"example_{lights}_plain_mean"]
    assert m["example_side_shadowed"] > 0.05 and m["example_example_shadowed"] > 0.005
    assert m["mixed_rendered"] and m["mixed_shadowed"] > 0.05  # beside pyrender's instanced boxes and point cloud


def test_glphong_meshes_cast_onto_pyrender_surfaces(measured):
    """pyrender's shadow pass draws glphong's meshes: a pyrender board under a glphong sphere darkens on exactly the
    pixels it darkens under a pyrender sphere."""
    _, m = measured
    c = m["casts_onto_pyrender"]
    assert c["board_pixels_darkened"] > 200 and c["differing"] == 0, c


def test_point_light_shadows_on_glphong_surfaces_and_a_warning_for_pyrenders(measured):
    """SHADOWS_POINT, which pyrender refuses (NotImplementedError): glphong's surfaces get cube-map shadows equal to
    glphong's render; where pyrender's own surfaces are in the frame, a warning says they get none."""
    platform, m = measured
    p = m["point_shadows"]
    _agrees(p, platform)
    assert p["shadowed"] > 0.02
    assert p["warning_glphong_only"] == ""
    assert "SHADOWS_POINT" in p["warning_mixed"] and "pyrender's own surfaces get none" in p["warning_mixed"]


def test_flat_draws_the_albedo_unlit(measured):
    """RenderFlags.FLAT (pyrender's flat shader would not compile for a glphong material): the surface's answer to
    an ambient light of radiance pi, pi kd for Lambert, one colour whatever the lights."""
    _, m = measured
    assert m["flat"]["distinct"] == 1 and m["flat"]["max_diff"] == 0, m["flat"]


def test_orthographic_and_intrinsics_cameras(measured):
    """pyrender's OrthographicCamera and IntrinsicsCamera (cx, cy off centre) draw glphong materials, and
    scene_from_pyrender maps them (glphong_camera_of): the frames agree."""
    platform, m = measured
    _agrees(m["orthographic"], platform)
    _agrees(m["intrinsics"], platform, exact=0.995)


def test_resized_renderer_stays_enabled(measured):
    """A new viewport size after enable(): on OSMesa pyrender re-creates its inner renderer, which is enabled too."""
    platform, m = measured
    _agrees(m["resized"], platform)
    assert m["resized"]["recreated"] is (platform == "osmesa")


def test_enable_everywhere_reaches_renderers_made_inside_third_party_code(measured):
    """A function that makes, uses and releases its own OffscreenRenderer draws glphong materials inside
    `with enable_everywhere():`, agreeing with glphong's render; after the block, pyrender's own class is back
    and the material says how to enable it."""
    platform, m = measured
    _agrees(m["everywhere"], platform)
    assert "not enabled on" in m["after_everywhere"] and "enable_everywhere()" in m["after_everywhere"]


def test_a_suite_runs_with_the_embedding_everywhere(tmp_path):
    """``pytest -p glphong.integrations.pyrender.everywhere`` runs a suite that knows nothing of glphong with every
    renderer it makes enabled: its GlphongMaterial scene draws; without the plugin it refuses."""
    from glphong.testing import require_backend

    require_backend("osmesa").release()  # skips where OSMesa is missing (fails where it is required)
    (tmp_path / "test_theirs.py").write_text(
        "import os\nimport numpy as np, pyrender, trimesh, glphong\n"
        "from glphong.integrations.pyrender import GlphongMaterial, release\n"
        "def test_draws():\n"
        "    scene = pyrender.Scene()\n"
        "    scene.add(pyrender.Mesh.from_trimesh(trimesh.creation.icosphere(2), material=GlphongMaterial(glphong.Lambert(0.3))))\n"
        "    pose = np.eye(4); pose[2, 3] = 3.0\n"
        "    scene.add(pyrender.PerspectiveCamera(yfov=0.8), pose=pose)\n"
        "    scene.add(pyrender.PointLight(intensity=5.0), pose=pose)\n"
        "    r = pyrender.OffscreenRenderer(32, 32)\n"
        "    try:\n"
        "        color, _ = r.render(scene)\n"
        "    finally:\n"
        "        release(r)\n"
        "    assert color.max() > 0\n")
    env = {k: v for k, v in os.environ.items() if k != "PYTEST_ADDOPTS"}
    env["PYOPENGL_PLATFORM"] = "osmesa"
    results = {}
    for name, plugin in (("with", ["-p", "glphong.integrations.pyrender.everywhere"]), ("without", [])):
        out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *plugin, str(tmp_path)],
                             cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
        results[name] = (out.returncode, out.stdout[-2000:])
    assert results["with"][0] == 0, results["with"][1]
    assert results["without"][0] == 1 and "enable_everywhere()" in results["without"][1], results["without"][1]
