"""The exact Phong lobe under an environment map (issue 40, glphong.twin.environment_lobe) against the independent
adaptive quadrature (glphong.twin.environment_quadrature) and a uniform sky's closed form; the mixed-material split of
the exact image against the quadrature of every term; verify's random sample of pixels, said so."""
import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.checks.verify import exact_image
from glphong.lights.environment import EnvironmentLight
from glphong.twin import environment as env
from glphong.twin.environment_lobe import lobe_integral
from glphong.twin.environment_quadrature import environment_integral


def _sky(H, W, seed=0):
    d = env.texel_directions(H, W)
    s = 0.3 + np.maximum(d[..., 2], 0.0)[..., None] * np.array([0.4, 0.6, 1.2])
    s = s + 0.05 * np.random.default_rng(seed).random((H, W, 3))
    s[H // 4, W // 3] = (400.0, 380.0, 330.0)                         # a sun
    return s


def _geometry(count, seed):
    rng = np.random.default_rng(seed)
    n = rng.normal(size=(count, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = rng.normal(size=(count, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    v = np.where((np.sum(v * n, axis=1) < 0)[:, None], -v, v)
    r = 2 * np.sum(n * v, axis=1)[:, None] * n - v
    return n, r


@pytest.mark.parametrize("q, shape, count", [(2.5, (8, 16), 3), (20.0, (8, 16), 10), (100.0, (8, 16), 10),
                                             (20.0, (16, 32), 10), (100.0, (16, 32), 10)])
def test_lobe_against_the_adaptive_quadrature(q, shape, count):
    """q = 2.5 and the coarse map: kept texels that r.w = 0 crosses, integrated with the crossed ones."""
    sky = _sky(*shape)
    n, r = _geometry(count, 1)
    value, error, converged = lobe_integral(sky, r, n, q)
    want, _, ok = environment_integral(n, sky, lambda i, w: np.maximum(np.sum(r[i] * w, axis=1), 0.0) ** q, rtol=1e-11)
    assert ok.all() and converged.all()
    scale = np.max(want, axis=1)
    assert np.all(np.abs(value - want).max(axis=1) <= 1e-9 * scale)
    assert np.all(error <= 1e-9 * scale)


@pytest.mark.parametrize("q", [1.0, 20.0, 100.0, 1000.0])
def test_uniform_sky_lobe_along_the_normal_is_two_pi_over_q_plus_one(q):
    """Seen along the normal (r = n) the lobe's half-space is the horizon's: ``integral (n.w)^q = 2 pi / (q + 1)``."""
    n, _ = _geometry(8, 2)
    value, _, converged = lobe_integral(np.full((16, 32, 3), 1.5), n, n, q)
    assert converged.all()
    np.testing.assert_allclose(value, 1.5 * 2 * np.pi / (q + 1), rtol=1e-9, atol=0)


def test_the_lobe_sees_one_texel_changed():
    """A planted error: one texel near the lobe's axis changed by 1e-6 of its value moves the integral by more than the
    tolerance (the comparisons above can fail)."""
    sky = _sky(16, 32)
    d = env.texel_directions(16, 32)
    r = d[5, 7][None]
    n = r
    a, _, _ = lobe_integral(sky, r, n, 100.0)
    sky[5, 7] *= 1 + 1e-6
    b, _, _ = lobe_integral(sky, r, n, 100.0)
    assert np.all(np.abs(b - a) > 1e-8 * a)


def test_rotated_light_lobe_against_the_quadrature():
    rotation = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    sky = _sky(8, 16, 3)
    n, r = _geometry(6, 4)
    value, _, _ = EnvironmentLight(sky, rotation=rotation).exact_twin().exact_lobe(n, r, 20.0)
    want, _, _ = environment_integral(n, sky, lambda i, w: np.maximum(np.sum(r[i] * w, axis=1), 0.0) ** 20,
                                      rotation=rotation, rtol=1e-11)
    assert np.all(np.abs(value - want).max(axis=1) <= 1e-9 * want.max(axis=1))


def _scene(H, W):
    camera = glphong.PerspectiveCamera.look_at((0.0, -2.0, 2.5), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), yfov=0.8)
    scene = glphong.Scene(camera, [EnvironmentLight(_sky(H, W))])
    scene.add(primitives.sphere(3, 0.6), glphong.Phong(0.3, 0.5, 20.0))
    return scene


def test_mixed_split_against_the_quadrature_of_every_term(glphong_backend, glphong_make_renderer):
    scene = _scene(8, 16)
    gbuffer = glphong_make_renderer(12, 12, glphong_backend).gbuffer(scene)
    split, _ = exact_image(scene, gbuffer)
    whole, _ = exact_image(scene, gbuffer, closed_forms=False)
    m = gbuffer.mask
    assert m.sum() > 20 and np.all(np.abs(split - whole)[m] <= 1e-9 * np.abs(whole)[m].max(axis=1, keepdims=True))


def test_verify_on_a_random_sample_says_so(glphong_backend, glphong_make_renderer):
    scene = _scene(8, 16)
    renderer = glphong_make_renderer(16, 16, glphong_backend)
    report = glphong.verify(scene, renderer, exact_sample=12, seed=3)
    assert report.exact_sample.sum() == 12 and np.all(report.exact_sample <= report.mask)
    outside = report.mask & ~report.exact_sample
    assert np.isnan(report.exact[outside]).all() and np.isnan(report.method_error[outside]).all()
    figures = report.method_error_figures()
    assert figures.sample == 12 and figures.covered == report.covered_pixels
    assert figures.above_max95 == pytest.approx(1 - 0.05 ** (1 / 12)) and figures.mean_ci95 > 0
    summary = report.summary()
    assert summary["method_sample"] == 12 and "random sample of 12 px" in str(report)
    full = glphong.verify(scene, renderer)
    assert full.exact_sample is None and full.method_error_figures().sample is None
    picked = report.exact_sample
    np.testing.assert_array_equal(report.exact[picked], full.exact[picked])
    with pytest.raises(ValueError, match="exact_sample"):
        glphong.verify(scene, renderer, exact_sample=2.5)


def test_verify_samples_by_itself_where_the_exact_lobe_would_cost_too_much(glphong_make_renderer, monkeypatch):
    """The default rule, with its bounds lowered to this small scene (16 x 16 px, an 8 x 16 map): a Phong material is
    sampled and says so; the same scene with a Lambert material (the map's closed forms) and ``exact_sample=None``
    compute every covered pixel; under the bounds nothing is sampled."""
    import glphong.checks.method_sample as method_sample

    scene = _scene(8, 16)
    renderer = glphong_make_renderer(16, 16, "egl")
    assert glphong.verify(scene, renderer).exact_sample is None  # 8 x 16 texels x ~100 px: far under the bound
    covered = int(renderer.gbuffer(scene).mask.sum())
    monkeypatch.setattr(method_sample, "AUTO_PIXEL_TEXELS", covered * 8 * 16 - 1)
    monkeypatch.setattr(method_sample, "AUTO_SAMPLE", 10)
    report = glphong.verify(scene, renderer)
    assert report.exact_sample.sum() == 10 and "random sample of 10 px" in str(report) and report.passed
    assert glphong.verify(scene, renderer, exact_sample=None).exact_sample is None
    lambert = glphong.Scene(scene.camera, list(scene.lights))
    for obj in scene.objects:
        lambert.add(obj.mesh, glphong.Lambert(0.5), pose=obj.pose)
    assert glphong.verify(lambert, renderer).exact_sample is None
    monkeypatch.setattr(method_sample, "AUTO_PIXEL_TEXELS", covered * 8 * 16)
    assert glphong.verify(scene, renderer).exact_sample is None
    with pytest.raises(ValueError, match="exact_sample"):
        glphong.verify(scene, renderer, exact_sample="some")
