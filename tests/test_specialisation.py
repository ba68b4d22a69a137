"""Per-scene program specialisation (docs/design.md section 5): what is left out, and that it changes nothing."""
import re
import subprocess
import sys

import numpy as np
import pytest
import trimesh

import glphong
from glphong import reference
from glphong.gpu.describe import describe, format_descriptions
from glphong.shaders.key import uber_key
from glphong.materials import registered_models
from glphong.shaders.binding import binding


@pytest.fixture(scope="module", params=("egl", "osmesa"))
def renderers(request, module_make_renderer):
    # the specialised renderer with the uber-shader's arithmetic (the stable formulation everywhere), so that the two
    # images differ by what specialisation leaves out alone
    return (module_make_renderer(96, 80, request.param, numerics="stable"),
            module_make_renderer(96, 80, request.param, specialise=False))


def scene_with(*materials, lights=None, ambient=0.05):
    camera = glphong.PerspectiveCamera.look_at((0.3, 0.8, 3.5), (0.0, 0.0, 0.0), yfov=0.9)
    if lights is None:
        lights = [glphong.PointLight((2.0, 2.5, 3.0), (80.0, 60.0, 40.0)), glphong.PointLight((-3.0, 1.0, 2.0), 30.0),
                  glphong.UnattenuatedPointLight((0.0, 4.0, 1.0), 0.3), glphong.DirectionalLight((-0.2, -0.3, -1.0), 0.7)]
    scene = glphong.Scene(camera, lights=lights, ambient=None if ambient is None else glphong.AmbientLight(ambient))
    for i, m in enumerate(materials):
        pose = np.eye(4)
        pose[:3, 3] = (1.2 * i - 0.6 * (len(materials) - 1), 0.0, 0.0)
        scene.add(trimesh.creation.icosphere(3), m, pose=pose, name=type(m).__name__ + str(i))
    return scene


MATERIALS = [glphong.Lambert(0.3), glphong.Lambert((0.1, 0.2, 0.3), ka=0.02), glphong.Phong(0.2, 0.5, 60.0),
             glphong.Phong(0.2, (0.5, 0.2, 0.0), 1e5, two_sided=False), glphong.BlinnPhong(0.1, 0.8, 400.0, ka=0.01),
             glphong.BlinnPhong(0.0, 1.0, 0.0)]


@pytest.mark.parametrize("material", MATERIALS, ids=lambda m: f"{type(m).__name__}-{m.q if hasattr(m, 'q') else ''}")
def test_specialised_image_equals_uber_image(renderers, material):
    specialised, uber = renderers
    scene = scene_with(material)
    a = specialised.render(scene)
    b = uber.render(scene)
    np.testing.assert_array_equal(a.mask, b.mask)
    report = glphong.verify(scene, uber)  # the uber image against the twin's band
    assert report.passed, str(report)
    assert report.covered_pixels > 1000
    np.testing.assert_allclose(b.radiance, a.radiance, rtol=2e-6, atol=1e-30)
    assert len(uber.programs) >= 1 and all(k.uber or k.output == "gbuffer" for k in uber.programs.keys())


def test_uber_renderer_compiles_one_radiance_program(renderers):
    _, uber = renderers
    scene = scene_with(*MATERIALS[:5])
    before = set(uber.programs.keys())
    uber.render(scene)
    new = [k for k in uber.programs.keys() if k.output == "radiance" and k not in before]
    drawn = {uber.program_key(scene, o) for o in scene.objects}
    assert drawn == {uber_key([o.material for o in scene.objects])} and len(new) <= 1
    # the models that declare in_uber (the lecture's three), plus the scene's own terms (here the same)
    assert sorted(m.name for m in registered_models() if m.in_uber) == ["blinn_lobe", "lambert", "phong_lobe"]
    assert [t.name for t in drawn.pop().terms] == ["blinn_lobe", "lambert", "phong_lobe"]


def test_mixed_scene_compiles_one_program_per_distinct_key(renderers):
    specialised, _ = renderers
    scene = scene_with(*MATERIALS)
    distinct = {binding(scene).program_key(o) for o in scene.objects}
    assert len(distinct) == 6  # Lambert ka/no-ka, Phong two-/one-sided, Blinn, Blinn without kd
    before = set(specialised.programs.keys())
    specialised.render(scene)
    new = {k for k in specialised.programs.keys() if k.output == "radiance"} - before
    assert new <= distinct and {k for k in specialised.programs.keys()} >= distinct
    assert len(describe(scene, specialised)) == 6
    # numerics='auto': the same six programs (the two lobes with exponents from 151, 1e5 and 400, were distinct
    # already), those two without the lobes' log branch
    auto = describe(scene)
    assert len(auto) == 6 and sum("lobe_tail" in d.key.numerics for d in auto) == 2


def test_unlit_scene_neither_uploads_nor_binds_normals(renderers):
    specialised, _ = renderers
    scene = scene_with(glphong.Lambert(0.3, ka=0.2), lights=[], ambient=None)
    frame = specialised.render(scene)
    np.testing.assert_array_equal(frame.radiance[frame.mask], np.float32(0.2))
    key = binding(scene).program_key(scene.objects[0])
    assert not key.has_normal and key.attributes() == ("in_position",)
    with specialised.context:
        program = specialised.programs.get(key)
    assert "in_normal" not in program.gl_program and "u_normal_matrix" not in program.active
    buffers = specialised._mesh_buffers(scene.objects[0].mesh)
    assert set(buffers.buffers) == {"in_position"}


def test_no_program_binds_a_tangent(renderers):
    specialised, uber = renderers
    scene = scene_with(*MATERIALS)
    specialised.render(scene)
    specialised.gbuffer(scene)
    uber.render(scene)
    for r in (specialised, uber):
        for key in r.programs.keys():
            with r.context:
                assert "in_tangent" not in r.programs.get(key).gl_program
            assert "in_tangent" not in key.attributes()


def test_lambert_program_contains_no_lobe_and_describe_says_so():
    scene = scene_with(glphong.Lambert(0.3), glphong.Phong(0.3, 0.0, 10.0))  # ks = 0: a Lambert program
    (only,) = describe(scene)
    assert only.objects == ("Lambert0", "Phong1")
    assert any(item.startswith("term phong_lobe: materials/phong_lobe.glsl, u_phong_lobe_ks, u_phong_lobe_q "
                               "(ks = 0)") for item in only.left_out), only.left_out
    assert any("library chunk lobe.glsl" in item for item in only.left_out)
    src = only.effective_fragment_source
    assert "lobe" not in src and "pow(" not in src and "uniform vec4 u_eye" not in src and "u_phong" not in src
    text = format_descriptions(describe(scene, gbuffer=True), source=True)
    assert "2 distinct program(s)" in text and "effective fragment source:" in text


def test_twin_follows_the_key(monkeypatch):
    """The twin evaluates only the terms the key has: a Lambert key never calls a lobe."""
    def forbidden(*args, **kwargs):
        raise AssertionError("lobe evaluated for a key without specular")

    from glphong.materials import BlinnLobe, PhongLobe

    monkeypatch.setattr(PhongLobe, "response", forbidden)
    monkeypatch.setattr(BlinnLobe, "response", forbidden)
    material = glphong.Phong(0.3, 0.0, 10.0)  # ks = 0: the lobe term vanishes
    scene = scene_with(material)
    key = binding(scene).program_key(scene.objects[0])
    u = {k: v.astype(np.float64) for k, v in binding(scene).uniform_values(0, key, 1.0).items()}
    out = reference.shade_point(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.array([True]), None, key, u, material)
    assert out.shape == (1, 3) and out[0, 0] > 0


def test_uber_limit_is_enforced():
    lights = [glphong.PointLight((0, 0, 3 + i), 1.0) for i in range(9)]
    scene = scene_with(glphong.Lambert(0.3), lights=lights)
    with pytest.raises(ValueError, match="at most 8 lights of each kind"):
        binding(scene).uniform_values(0, uber_key([glphong.Lambert(0.3)]), 1.0)


def test_cli_describe_default_scene():
    out = subprocess.run([sys.executable, "-m", "glphong", "describe", "--gbuffer"], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    # Phong and Blinn-Phong, each with exponents below and from 151 (numerics='auto': the lobes' log branch left out
    # from 151 on), and the G-buffer
    assert "5 distinct program(s)" in out.stdout
    assert out.stdout.count("numerics=('falloff', 'light', 'lobe_tail', 'normal', 'view')") == 2
    assert "lobe_tail: stable (phong_lobe's exponent q = 5 is below 151" in out.stdout, out.stdout
    assert "terms=lambert[lit,ambient]+phong_lobe[lit]" in out.stdout, out.stdout
    assert "terms=lambert[lit,ambient]+blinn_lobe[lit]" in out.stdout and "gbuffer" in out.stdout
    assert re.search(r"fragment chunks: common lights lobe model:lambert@\w{12} model:phong_lobe@\w{12} "
                     r"generated:material light:point@\w{12} shade generated:lights", out.stdout), out.stdout
