"""Layer 1 of docs/design.md section 7: each GLSL chunk function against its numpy twin of the same name.

Inputs are float32 (seeded random plus edge cases); the GPU evaluates the GLSL function
through transform feedback, the twin evaluates the same float32 inputs in float64, and
the two are compared under the tolerance model of `glphong.checks.tolerances`.
"""
import numpy as np
import pytest

from glphong.testing import probe
from glphong import reference as ref
from glphong.checks.tolerances import BAND, EPS, FLT_MIN, lobe_band

RNG_SEED = 20261122


def unit_vectors(rng, count):
    v = rng.normal(size=(count, 3))
    return (v / np.linalg.norm(v, axis=1, keepdims=True)).astype(np.float32)


def f64(a):
    return np.asarray(a, dtype=np.float32).astype(np.float64)


def test_every_chunk_function_has_a_twin():
    signatures = probe.signatures()
    for name in ("safe_normalize", "frame_from_tangent", "point_irradiance", "log_one_minus", "lobe_from_delta",
                 "lambert", "phong_delta", "phong_lobe", "blinn_delta", "blinn_lobe"):
        assert name in signatures, name  # found by parsing the chunks, not listed by hand
    for name, signature in signatures.items():
        if signature.twin_module.startswith("glphong."):  # glphong's chunks (not models other tests define)
            assert callable(probe.twin_of(name)), name


def test_probe_rejects_wrong_inputs(session_gl):
    with pytest.raises(TypeError, match="log_one_minus takes inputs"):
        probe.evaluate(session_gl, "log_one_minus", x=[0.1])


def test_safe_normalize(session_gl):
    rng = np.random.default_rng(RNG_SEED)
    scales = 10.0 ** rng.uniform(-37, 37, size=(400, 1))
    x = (rng.normal(size=(400, 3)) * scales).astype(np.float32)
    edge = np.array([[0, 0, 0], [1e-30, 0, 0], [3e38, 3e38, 1], [-2e38, 1, 1], [np.nan, 1, 1], [1, np.inf, 0],
                     [1, 1, -np.inf], [1.4e-45, 0, 0], [1e-25, 1e-25, 1e-25], [1e25, -1e25, 1e25]], np.float32)
    x = np.concatenate([x, edge])
    gpu = probe.evaluate(session_gl, "safe_normalize", x=x)
    valid, x_hat, length = ref.safe_normalize(f64(x))
    # a vector whose largest component is subnormal may be flushed to zero (GLSL 4.50, 4.7.1)
    flushable = np.max(np.abs(f64(x)), axis=1) < FLT_MIN
    np.testing.assert_array_equal(gpu["return"][~flushable], valid[~flushable])
    valid &= gpu["return"]
    edge_valid = valid[-len(edge):]
    assert not edge_valid[[0, 4, 5, 6, 7]].any() and edge_valid[[1, 2, 3, 8, 9]].all()
    np.testing.assert_allclose(gpu["x_hat"][valid], x_hat[valid], rtol=0, atol=4 * EPS)
    finite = valid & (length <= np.finfo(np.float32).max)
    np.testing.assert_allclose(gpu["len"][finite], length[finite], rtol=4 * EPS, atol=0)
    assert np.all(gpu["x_hat"][~valid] == 0) and np.all(gpu["len"][~valid] == 0)


def test_point_irradiance(session_gl):
    rng = np.random.default_rng(RNG_SEED + 1)
    intensity = (10.0 ** rng.uniform(-30, 30, size=(300, 3))).astype(np.float32)
    d = (10.0 ** rng.uniform(-15, 15, size=300)).astype(np.float32)
    gpu = probe.evaluate(session_gl, "point_irradiance", intensity=intensity, d=d)["return"]
    want = ref.point_irradiance(f64(intensity), f64(d))
    representable = (want >= FLT_MIN) & (want <= np.finfo(np.float32).max)
    assert representable.mean() > 0.5
    np.testing.assert_allclose(gpu[representable], want[representable], rtol=BAND.A * EPS, atol=0)
    # the stable order keeps d = 1e-19 and d = 1e19 finite where d*d would under/overflow
    gpu = probe.evaluate(session_gl, "point_irradiance", intensity=[[1e-20] * 3, [1e20] * 3], d=[1e-19, 1e19])["return"]
    np.testing.assert_allclose(gpu, [[1e18] * 3, [1e-18] * 3], rtol=BAND.A * EPS)


def test_lambert(session_gl):
    rng = np.random.default_rng(RNG_SEED + 2)
    kd = rng.uniform(0, 2, size=(200, 3)).astype(np.float32)
    cos = rng.uniform(0, 1, size=200).astype(np.float32)
    gpu = probe.evaluate(session_gl, "lambert", kd=kd, n_dot_l=cos)["return"]
    np.testing.assert_allclose(gpu, ref.lambert(f64(kd), f64(cos)), rtol=EPS, atol=0)


def test_log_one_minus_twin_is_accurate():
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.dps = 60
    delta = np.array([0.0, 1e-300, 1e-30, 1e-8, 1e-3, 0.1, 0.3, 0.49999, 0.5, 0.75, 0.999999, 1 - 2**-52])
    exact = np.array([float(mpmath.log1p(-mpmath.mpf(d))) for d in delta])
    np.testing.assert_allclose(ref.log_one_minus(delta), exact, rtol=4 * np.finfo(float).eps, atol=0)


def test_log_one_minus(session_gl):
    rng = np.random.default_rng(RNG_SEED + 3)
    delta = np.concatenate([10.0 ** rng.uniform(-38, 0, 400), rng.uniform(0, 1, 200),
                            [0.0, 1e-45, 0.5 - 2**-25, 0.5, 0.5 + 2**-24, 1 - 2**-24]]).astype(np.float32)
    delta = delta[delta < 1]
    gpu = probe.evaluate(session_gl, "log_one_minus", delta=delta)["return"]
    want = ref.log_one_minus(f64(delta))
    flushed = (delta < FLT_MIN) & (gpu == 0)  # subnormal inputs may be flushed to zero
    gpu, want = gpu[~flushed], want[~flushed]
    # the twin is exact to float64; the float32 series and log() are good to a few ulp
    np.testing.assert_allclose(gpu, want, rtol=8 * EPS, atol=FLT_MIN)


@pytest.mark.parametrize("q", [0.0, 0.5, 1.0, 50.0, 1e3, 1e4, 1e5, 1e6, 1e7])
def test_lobe_from_delta(session_gl, q):
    rng = np.random.default_rng(RNG_SEED + 4)
    peak_scale = 1.0 / max(q, 1.0)
    delta = np.concatenate([rng.uniform(0, 30 * peak_scale, 300), 10.0 ** rng.uniform(-40, 0, 200),
                            [0.0, 1e-30, 0.5, 0.999999, 1.0, 1.5, 2.0]]).astype(np.float32)
    gpu = probe.evaluate(session_gl, "lobe_from_delta", delta=delta, q=q)["return"]
    low, high = lobe_band(f64(delta), q, chord_scale=0.0)
    assert np.all(np.isfinite(gpu)) and np.all(gpu <= 1.0) and np.all(gpu >= 0.0)
    assert np.all((gpu >= low) & (gpu <= high)), np.c_[delta, gpu, low, high][(gpu < low) | (gpu > high)][:5]
    if q == 0:
        assert np.all(gpu == 1.0)


def _direction_sets(rng, count):
    """Random unit n, wi, wo plus peaks, grazing and opposite configurations."""
    n = unit_vectors(rng, count)
    wi = unit_vectors(rng, count)
    wo = unit_vectors(rng, count)
    # exact Phong peaks (v = r) and near-peaks
    k = count // 4
    r = 2 * np.sum(f64(n[:k]) * f64(wi[:k]), axis=1, keepdims=True) * f64(n[:k]) - f64(wi[:k])
    jitter = rng.normal(size=(k, 3)) * 10.0 ** rng.uniform(-7, -2, size=(k, 1))
    wo[:k] = (r + jitter) / np.linalg.norm(r + jitter, axis=1, keepdims=True)
    edge_n = np.array([[0, 0, 1]] * 6, np.float32)
    edge_wi = np.array([[0, 0, 1], [1, 0, 1e-7], [1, 0, 0], [0.6, 0, 0.8], [0.6, 0, 0.8], [0, 1, 0]], np.float32)
    edge_wo = np.array([[0, 0, 1], [-1, 0, 1e-7], [-1, 0, 0], [-0.6, 0, 0.8], [-0.6, 0, -0.8], [0, -1, 0]], np.float32)
    return np.concatenate([n, edge_n]), np.concatenate([wi, edge_wi]), np.concatenate([wo, edge_wo])


def _chord(delta):
    return np.sqrt(2 * np.maximum(delta, 0))


def test_phong_delta(session_gl):
    n, wi, wo = _direction_sets(np.random.default_rng(RNG_SEED + 5), 400)
    gpu = probe.evaluate(session_gl, "phong_delta", n=n, wi=wi, wo=wo)["return"]
    want = ref.phong_delta(f64(n), f64(wi), f64(wo))
    np.testing.assert_allclose(_chord(gpu), _chord(want), rtol=0, atol=BAND.C * EPS)


def test_blinn_delta(session_gl):
    n, wi, wo = _direction_sets(np.random.default_rng(RNG_SEED + 6), 400)
    gpu = probe.evaluate(session_gl, "blinn_delta", n=n, wi=wi, wo=wo)
    valid, want = ref.blinn_delta(f64(n), f64(wi), f64(wo))
    np.testing.assert_array_equal(gpu["return"], valid)
    _, _, h_len = ref.safe_normalize(f64(wi) + f64(wo))
    scale = np.maximum(1, 2 / np.maximum(h_len, ref.BLINN_HALF_FLOOR))
    assert np.all(np.abs(_chord(gpu["delta"]) - _chord(want))[valid] <= (BAND.C * EPS * scale)[valid])
    # edges: [n = l = v, near l = -v grazing, l = -v, mirror peak, n.v < 0, l = -v]
    assert valid[[-6, -3]].all() and not valid[[-4, -2, -1]].any()


def test_half_cosine(session_gl):
    _, wi, wo = _direction_sets(np.random.default_rng(RNG_SEED + 8), 400)
    gpu = probe.evaluate(session_gl, "half_cosine", wi=wi, wo=wo)["return"]
    want = ref.half_cosine(f64(wi), f64(wo))
    _, _, h_len = ref.safe_normalize(f64(wi) + f64(wo))
    # h is known to the half vector's conditioning max(1, 2/|l + v|) (measured at most 2.3 eps times it)
    scale = np.maximum(1, 2 / np.maximum(h_len, ref.BLINN_HALF_FLOOR))
    assert np.all(np.abs(gpu - want) <= 4 * EPS * scale)
    # edges [-4], [-2], [-1]: l = -v gives 0 (h undefined); [-3], the mirror peak: h = n, h.l = n.l = 0.8
    assert np.all(gpu[[-4, -2, -1]] == 0) and abs(gpu[-3] - 0.8) <= 4 * EPS


@pytest.mark.parametrize("name", ["phong_lobe", "blinn_lobe"])
@pytest.mark.parametrize("q", [0.0, 1.0, 1e3, 1e5, 1e7])
def test_lobes(session_gl, name, q):
    n, wi, wo = _direction_sets(np.random.default_rng(RNG_SEED + 7), 400)
    gpu = probe.evaluate(session_gl, name, n=n, wi=wi, wo=wo, q=q)["return"]
    want = getattr(ref, name)(f64(n), f64(wi), f64(wo), q)
    if name == "phong_lobe":
        low, high = lobe_band(ref.phong_delta(f64(n), f64(wi), f64(wo)), q)
    else:
        valid, delta = ref.blinn_delta(f64(n), f64(wi), f64(wo))
        _, _, h_len = ref.safe_normalize(f64(wi) + f64(wo))
        low, high = lobe_band(delta, q, np.maximum(1, 2 / np.maximum(h_len, ref.BLINN_HALF_FLOOR)))
        low, high = np.where(valid, low, 0), np.where(valid, high, 0)
    assert np.all(np.isfinite(gpu)) and np.all(gpu <= 1.0)
    bad = (gpu < low) | (gpu > high)
    assert not bad.any(), np.c_[gpu, want, low, high][bad][:5]
    # the lobe is really exercised: some values near the peak, some far below it
    assert (want > 0.5).sum() >= 20 and (want < 0.5).sum() >= 20 or q == 0


def test_atan2_first_quadrant(session_gl):
    """angle.glsl's Cephes atan against numpy's arctan2: within 4 ulp of pi/2 absolute over the quadrant,
    relative 4 ulp of the result, and 0 at (0, 0) (no NaN)."""
    rng = np.random.default_rng(RNG_SEED + 7)
    angle = rng.uniform(0, np.pi / 2, size=2000)
    scale = 10.0 ** rng.uniform(-20, 20, size=2000)
    y = np.concatenate([np.sin(angle) * scale, [0, 0, 1, 1e-30, 1, 3e38]]).astype(np.float32)
    x = np.concatenate([np.cos(angle) * scale, [0, 1, 0, 1, 1e-30, 3e38]]).astype(np.float32)
    gpu = probe.evaluate(session_gl, "atan2_first_quadrant", y=y, x=x)["return"].astype(np.float64)
    want = ref.atan2_first_quadrant(f64(y), f64(x))
    assert not np.isnan(gpu).any() and gpu[-6] == 0.0
    err = np.abs(gpu - want)
    assert np.all(err <= 4 * EPS * np.maximum(want, 2 ** -20)), float(np.max(err / np.maximum(want, 2 ** -20)) / EPS)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_the_twins_dot_is_numpys_sum_to_the_bit(dtype):
    """`glphong.twin.functions.dot` replaced ``np.sum(a * b, axis=-1)`` in every twin for speed: the same values to the
    bit (the sum's order ``(a_0 b_0 + a_1 b_1) + a_2 b_2``), broadcasting and other lengths included."""
    from glphong.twin.functions import dot

    rng = np.random.default_rng(7)
    a = (rng.normal(size=(5000, 4, 3)) * 10.0 ** rng.integers(-12, 12, size=(5000, 4, 3))).astype(dtype)
    b = (rng.normal(size=(5000, 1, 3)) * 10.0 ** rng.integers(-12, 12, size=(5000, 1, 3))).astype(dtype)
    for x, y in ((a, b), (a[:, 0], b[:, 0]), (a[0, 0], b[:, 0]), (a[..., :2], b[..., :2])):
        got, want = dot(x, y), np.sum(x * y, axis=-1)
        assert got.dtype == want.dtype and got.shape == want.shape
        assert np.array_equal(got.view(np.uint8), want.view(np.uint8))
