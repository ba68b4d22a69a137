"""The built-in model 'diffuse' (`glphong.materials.Diffuse`): Lambert's law by its albedo, the diffuse
term of the physically based models, tested the way a user tests their own model.

What is specific to it (twin agreement at rho_d = 0.6 and with a zero channel to 4 eps, the definition's
mechanics, vanishing at rho_d = 0, the declared properties and the stability cases are in
tests/test_conformance.py; GPU parts on both backends, fixture ``glphong_backend``):

- the closed form ``rho_d (n.l) / pi`` written here against `evaluate` (GPU, 4 eps relative) and the twin
  (1e-15) at normal, oblique and grazing incidence;
- the directional albedo by quadrature (midpoint rule in theta and phi, 400 x 200 cells) is rho_d at
  incident angles 0, 30, 60 and 85 degrees to 1e-5, so ``rho_d <= 1`` conserves energy, as declared;
- reciprocity: ``f_r(wi, wo) = f_r(wo, wi)`` exactly in the twin;
- the declaration (range [0, 1], declared properties), the ambient answer ``(rho_d / pi) L_a`` in the
  generated GLSL (the constant is float32(1/pi)), equal to `Lambert` with ``kd = rho_d/pi`` in a
  rendered scene to 4 eps relative;
- a sphere rendered with `assert_render_matches` (relative error below 1e-5).
"""
import numpy as np
import pytest

import glphong
import glphong.primitives
from glphong.shaders.key import program_key
from glphong.materials import Diffuse, Lambert
from glphong.testing import assert_render_matches, direction, evaluate

EPS = 2.0 ** -24


def test_closed_form(glphong_backend):
    n = np.array([0.0, 0.0, 1.0])
    thetas = [0.0, np.radians(30), np.radians(60), np.arccos(1e-2), np.arccos(1e-4)]
    wi = np.array([direction(n, t, 0.4) for t in thetas])
    wo = np.array([direction(n, 0.7, 2.0)] * len(thetas))
    material = Diffuse((0.25, 0.5, 1.0))
    l32 = (wi / np.linalg.norm(wi, axis=1, keepdims=True)).astype(np.float32).astype(np.float64)
    rho = np.float32([0.25, 0.5, 1.0]).astype(np.float64)
    expected = rho * (l32[:, 2:3] / np.pi)
    np.testing.assert_allclose(evaluate(material, wi, wo, twin=True), expected, rtol=1e-15)
    gpu = evaluate(material, wi, wo, backend=glphong_backend).astype(np.float64)
    np.testing.assert_allclose(gpu, expected, rtol=4 * EPS)


def _albedo(material, theta_i, cells=(400, 200)):
    n_theta, n_phi = cells
    theta = (np.arange(n_theta) + 0.5) * (np.pi / 2) / n_theta
    phi = (np.arange(n_phi) + 0.5) * 2 * np.pi / n_phi
    t, p = np.meshgrid(theta, phi, indexing="ij")
    wo = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(-1, 3)
    wi = np.repeat([[np.sin(theta_i), 0.0, np.cos(theta_i)]], len(wo), axis=0)
    f_r = evaluate(material, wi, wo, twin=True) / np.cos(theta_i)
    weight = (np.cos(t) * np.sin(t)).reshape(-1) * (np.pi / 2 / n_theta) * (2 * np.pi / n_phi)
    return np.sum(f_r * weight[:, None], axis=0)


@pytest.mark.parametrize("degrees", [0.0, 30.0, 60.0, 85.0])
def test_albedo_is_rho_d(degrees):
    albedo = _albedo(Diffuse((0.2, 0.6, 1.0)), np.radians(degrees))
    np.testing.assert_allclose(albedo, np.float32([0.2, 0.6, 1.0]), rtol=1e-5)


def test_reciprocal():
    rng = np.random.default_rng(4)
    wi, wo = rng.normal(size=(2, 200, 3))
    wi[:, 2], wo[:, 2] = np.abs(wi[:, 2]), np.abs(wo[:, 2])
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    m = Diffuse(0.7)
    forward = evaluate(m, wi, wo, twin=True) / wi[:, 2:3].astype(np.float32).astype(np.float64)
    backward = evaluate(m, wo, wi, twin=True) / wo[:, 2:3].astype(np.float32).astype(np.float64)
    np.testing.assert_allclose(forward, backward, rtol=1e-15)


def test_declaration_and_ambient():
    (rho,) = Diffuse.params
    assert (rho.name, rho.kind, rho.interval) == ("rho_d", "rgb", "[0, 1]")
    assert Diffuse.properties.reciprocal and Diffuse.properties.energy_conserving
    assert Diffuse.ambient == "rho_d" and Diffuse.ambient_scale == 1 / np.pi and Diffuse.vanishes_with == ("rho_d",)
    key = program_key(Diffuse(0.6), {"point": 1}, (0.1, 0.1, 0.1))
    assert "u_diffuse_rho_d * (0.31830987334251404 * u_ambient)" in key.generated_chunks()["generated:material"]


def _scene(material):
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)),
                          lights=[glphong.PointLight((2, 2, 2), power=80.0)], ambient=glphong.AmbientLight(0.2))
    scene.add(glphong.primitives.sphere(4), material)
    return scene


def test_render_matches_and_equals_lambert(glphong_renderer):
    report = assert_render_matches(_scene(Diffuse(0.6)), glphong_renderer)
    assert report.max_relative_error < 1e-5
    a = glphong_renderer.render(_scene(Diffuse(0.6))).radiance.astype(np.float64)
    b = glphong_renderer.render(_scene(Lambert(0.6 / np.pi))).radiance.astype(np.float64)
    lit = b > 0
    assert lit.sum() > 1000
    np.testing.assert_allclose(a[lit], b[lit], rtol=4 * EPS)
