"""The environment light's exact reference made fast (issue 40): the irradiance's crossed texels found from the runs
(no normals x texels masks), in bounded chunks, bit-identical to the masks' order; the crossed texels in closed form
(Stokes) against the Gauss-Legendre rule; the exact image's Lambert irradiance in closed form against the quadrature."""
import numpy as np
import pytest

from glphong.lights.environment import EnvironmentLight
from glphong.twin import environment as env
from glphong.twin.environment_quadrature import environment_integral


def _normals(count, seed):
    rng = np.random.default_rng(seed)
    n = rng.normal(size=(count, 3))
    special = np.array([[0, 0, 1], [0, 0, -1], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [1e-9, 0, 1], [0.6, 0.8, 0.0],
                        [0.6, 0.8, 1e-7], [1, 0, 1e-3], [1e-3, 0, 1]], float)
    n = np.concatenate([n, special])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def _masks_crossed(above, below, W):  # what the runs' complement was before: (K, H, W) masks
    col = np.arange(W)[None, None, :]
    lit = np.mod(col - above[0][..., None], W) < above[1][..., None]
    dark = np.mod(col - below[0][..., None], W) < below[1][..., None]
    return np.nonzero(~(lit | dark))


def _cot(theta):
    """cot of the rows' edge angles, +-inf at the poles (as the irradiance's row runs take them)."""
    with np.errstate(divide="ignore"):
        cot = np.cos(theta) / np.sin(theta)
    cot[0], cot[-1] = np.inf, -np.inf
    return cot


@pytest.mark.parametrize("shape", [(2, 4), (3, 5), (8, 16), (31, 17), (32, 64)])
def test_crossed_texels_from_the_runs_equal_the_masks(shape):
    H, W = shape
    n = _normals(200, 1)
    theta, _ = env.texel_edges(H, W)
    above, below = env._row_runs(n, _cot(theta), W)
    for got, want in zip(env._crossed_texels(above, below, W), _masks_crossed(above, below, W)):
        assert np.array_equal(got, want)


def test_chunking_is_honoured_and_changes_nothing(monkeypatch):
    sky = np.random.default_rng(2).random((16, 32, 3))
    n = _normals(100, 3)
    whole = env.irradiance(sky, n)
    monkeypatch.setattr(env, "_ROW_BUDGET", 16)        # one normal a chunk
    monkeypatch.setattr(env, "_CROSSED_BUDGET", 7)     # seven crossed texels a batch
    calls = []
    original = env._crossed
    monkeypatch.setattr(env, "_crossed", lambda n, *a: calls.append(len(n)) or original(n, *a))
    chunked = env.irradiance(sky, n)
    assert max(calls) <= 7 and len(calls) > len(n)
    assert all(np.array_equal(a, b) for a, b in zip(whole, chunked))


@pytest.mark.parametrize("shape", [(2, 4), (3, 5), (8, 16), (31, 17), (64, 128)])
def test_crossed_texels_in_closed_form_against_the_rule(shape):
    H, W = shape
    n = _normals(150, 4)
    theta, phi = env.texel_edges(H, W)
    k, r, c = env._crossed_texels(*env._row_runs(n, _cot(theta), W), W)
    args = (n[k], theta[r], theta[r + 1], phi[c], phi[c + 1])
    rule, _ = env._crossed(*args, 12, 1e-12)
    closed, ok = env._crossed_closed(*args)
    assert ok.mean() > 0.9
    assert np.all(np.abs(closed - rule)[ok] <= env._closed_bound(*args)[ok] + 1e-15 * env._solid_angle(*args[1:])[ok])
    sky = np.random.default_rng(5).random((H, W, 3))
    a, _ = env.irradiance(sky, n)
    b, bound = env.irradiance(sky, n, crossed="closed")
    assert np.max(np.abs(a - b) / a) < 1e-11 and np.all(np.abs(a - b) <= bound + 1e-12 * a)


def test_exact_irradiance_against_the_quadrature():
    rotation = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    sky = np.random.default_rng(6).random((8, 16, 3))
    light = EnvironmentLight(sky, rotation=rotation)
    n = _normals(20, 7)
    exact = light.exact_twin().irradiance(None, n, None)
    value, _, converged = environment_integral(n, sky, lambda i, w: np.sum(n[i] * w, axis=1), rotation=rotation)
    assert converged.all() and np.max(np.abs(exact - value) / value) < 1e-9
    twin = light.exact_twin()
    assert twin.closed_form_is_exact("irradiance") and twin.closed_form_is_exact("lobe", 20)
    assert not twin.closed_form_is_exact("sampled")
