"""The float64 integrals of an equirectangular radiance map (glphong.twin.environment), against closed forms and an
independent quadrature: the twin side of the environment light (the lecture's continuous version)."""
import numpy as np
import pytest

from glphong.twin.environment import irradiance, texel_directions, texel_moments, texel_solid_angles
from glphong.twin.environment_quadrature import environment_integral


def _quadrature(height, width, i, j, f, samples=400):
    """Midpoint quadrature of f(w) sin(theta) over texel (i, j), independent of the closed forms."""
    t = np.pi * (i + (np.arange(samples) + 0.5) / samples) / height
    p = 2 * np.pi * (j + (np.arange(samples) + 0.5) / samples) / width
    tt, pp = np.meshgrid(t, p, indexing="ij")
    w = np.stack([np.sin(tt) * np.cos(pp), np.sin(tt) * np.sin(pp), np.cos(tt)], axis=-1)
    weight = np.sin(tt) * (np.pi / height / samples) * (2 * np.pi / width / samples)
    value = f(w)
    return np.sum(value * weight[..., None], axis=(0, 1)) if value.ndim == 3 else np.sum(value * weight)


def test_solid_angles_and_moments_are_exact():
    omega = texel_solid_angles(16, 32)
    moments = texel_moments(16, 32)
    assert abs(omega.sum() - 4 * np.pi) < 1e-12
    np.testing.assert_allclose(moments.sum(axis=(0, 1)), 0.0, atol=1e-12)
    for i, j in ((0, 0), (3, 7), (8, 20), (15, 31)):
        assert abs(omega[i, j] - _quadrature(16, 32, i, j, lambda w: np.ones(w.shape[:-1]))) < 1e-6 * omega[i, j]
        np.testing.assert_allclose(moments[i, j], _quadrature(16, 32, i, j, lambda w: w), rtol=1e-5, atol=1e-9)
    assert np.allclose(np.linalg.norm(texel_directions(4, 8), axis=-1), 1.0)


NORMALS = np.concatenate([np.eye(3), -np.eye(3), np.random.default_rng(3).normal(size=(40, 3))])
NORMALS /= np.linalg.norm(NORMALS, axis=1, keepdims=True)


@pytest.mark.parametrize("shape", [(8, 16), (32, 64), (17, 9)])
def test_a_uniform_sky_gives_pi_L(shape):
    """A constant radiance L gives E = pi L at every normal, within the stated bound (and the bound is small)."""
    e, bound = irradiance(np.full(shape, 2.5), NORMALS)
    assert np.all(np.abs(e - np.pi * 2.5) <= bound + 1e-12)
    assert bound.max() < 1e-3 * np.pi * 2.5


def test_one_texel_above_the_horizon_is_its_moment():
    """A map zero but for one texel wholly above the surface: E = L (n . M) exactly (a directional light's limit)."""
    radiance = np.zeros((32, 64, 3))
    radiance[2, 10] = (1e6, 2e6, 0.0)
    n = np.array([[0.0, 0.0, 1.0], [0.3, 0.1, 0.95]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    e, bound = irradiance(radiance, n)
    np.testing.assert_allclose(e, (n @ texel_moments(32, 64)[2, 10])[:, None] * radiance[2, 10], rtol=1e-14)
    assert np.all(bound == 0)


def test_against_quadrature_where_the_horizon_cuts_texels():
    rng = np.random.default_rng(5)
    radiance = rng.uniform(0, 1, (6, 12))
    n = np.array([0.4, -0.3, 0.5])
    n /= np.linalg.norm(n)
    e, bound = irradiance(radiance, n[None])
    reference = sum(radiance[i, j] * _quadrature(6, 12, i, j, lambda w: np.maximum(w @ n, 0.0), samples=600)
                    for i in range(6) for j in range(12))
    assert abs(e[0] - reference) <= bound[0] + 1e-5 * reference
    assert bound[0] < 1e-3 * reference


@pytest.mark.parametrize("shape", [(2, 4), (7, 13), (16, 32)])
def test_row_runs_and_crossed_texels_against_the_quadrature(shape):
    """The lit runs summed from prefix sums and the crossed texels integrated apart give the independent quadrature's
    irradiance, at random normals and at the poles and the equator (where a row's classification is undecided)."""
    rng = np.random.default_rng(sum(shape))
    normals = rng.normal(size=(24, 3))
    normals = np.concatenate([normals / np.linalg.norm(normals, axis=1, keepdims=True),
                              [[0, 0, 1.0], [0, 0, -1.0], [1.0, 0, 0], [0, -1.0, 0], [0.6, 0, 0.8]]])
    radiance = rng.random(shape + (3,))
    e, bound = irradiance(radiance, normals)
    value, _, converged = environment_integral(normals, radiance, lambda i, w: np.sum(normals[i] * w, axis=1))
    assert converged.all() and np.max(np.abs(e - value) / value) < 1e-12
    assert np.all(bound < 1e-9 * value)
