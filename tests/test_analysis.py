"""glphong.analysis: closed-form albedos, the four properties of the lecture's and the physical models,
the ``glphong brdf`` command and the GPU path against the twin."""
import json

import numpy as np
import pytest

from glphong.analysis import questions as analysis
from glphong.analysis import albedo, format_properties, properties
from glphong.tools.cli import main
from glphong.materials import (CookTorrance, Diffuse, Lambert, NormalizedBlinnPhong, NormalizedPhong, OrenNayar, Phong,
                               SchlickFresnel, Ward)

F32 = lambda x: float(np.float32(x))  # noqa: E731 - the parameter value the twin is given
ANGLES = [0.0, 0.7, 1.4]


def quick(material, **kw):
    return properties(material, directions=50, theta_i=kw.pop("theta_i", [0.0]), **kw)


# --------------------------------------------------------------------------- closed forms
def test_lambert_and_diffuse_albedo_exact_at_every_angle():
    rho, err = albedo(Lambert(0.2), ANGLES, return_error=True)
    assert rho.shape == (3, 3) and rho.dtype == np.float64
    np.testing.assert_allclose(rho, np.pi * F32(0.2), rtol=0, atol=1e-12)
    assert err.max() < 1e-12
    np.testing.assert_allclose(albedo(Diffuse(0.6), ANGLES), F32(0.6), rtol=0, atol=1e-12)


@pytest.mark.parametrize("q", [1.0, 100.0, 1e4])
def test_normalized_phong_normal_incidence_is_rho_s(q):
    rho, err = albedo(NormalizedPhong(0.0, 0.5, q), 0.0, return_error=True)
    assert abs(rho[0] - 0.5) < 1e-6 and err[0] < 1e-6


@pytest.mark.parametrize("q", [1.0, 100.0, 1e4])
def test_normalized_blinn_normal_incidence_is_rho_s(q):
    rho, err = albedo(NormalizedBlinnPhong(0.0, 0.5, q), 0.0, return_error=True)
    assert abs(rho[0] - 0.5) < 1e-6 and err[0] < 1e-6


@pytest.mark.parametrize("q", [20.0, 1e4])
def test_lecture_phong_lobe_at_normal_incidence(q):
    # at theta_i = 0: r = n, f_r cos(theta_o) = ks cos^q(theta_o) cos(theta_o) / 1, so
    # rho = ks 2 pi int_0^1 c^(q+1) dc = ks 2 pi / (q + 2)
    rho = albedo(Phong(0.0, 0.5, q), 0.0)
    assert abs(rho[0] - 0.5 * 2 * np.pi / (q + 2)) < 1e-6


def test_lecture_phong_albedo_grows_without_bound_at_grazing():
    rho = albedo(Phong(0.0, 0.5, 20.0), np.arccos([0.5, 1e-1, 1e-2, 1e-3]))[:, 0]
    assert np.all(np.diff(rho) > 0)
    assert rho[2] > 1 and rho[3] > 5 * rho[2] / 2  # ~ 1/cos(theta_i)


def test_cook_torrance_sharp_furnace():
    rho, err = albedo(CookTorrance(0.0, 0.01, fresnel=SchlickFresnel(1.0)), 0.0, return_error=True)
    assert 0.99 < rho[0] <= 1 + 1e-6 and err[0] < 1e-6


def test_albedo_rejects_bad_angles():
    with pytest.raises(ValueError):
        albedo(Lambert(0.2), np.pi / 2)


# --------------------------------------------------------------------------- properties
def test_lecture_phong_not_reciprocal_not_energy_conserving():
    r = quick(Phong(0.0, 0.5, 20.0), theta_i=[0.0, np.arccos(1e-2)])
    assert r.reciprocity_error > 0.1 and not r.reciprocal
    assert r.max_albedo > 1 and not r.energy_conserving
    assert r.non_negative and r.min_value >= 0
    assert r.isotropic and r.isotropy_error < 1e-12
    assert r.disagreements == []  # the declaration is honest
    text = format_properties(r)
    assert "reciprocal:" in text and "no" in text


def test_normalized_phong_reciprocal_and_conserving():
    r = quick(NormalizedPhong(0.2, 0.5, 50.0), theta_i=[0.0, 1.0])
    assert r.reciprocal and r.reciprocity_error < 1e-12
    assert r.energy_conserving and abs(r.max_albedo - (F32(0.2) + 0.5)) < 1e-6
    assert r.isotropic and r.non_negative and r.disagreements == []


def test_ward_isotropy():
    aniso = quick(Ward(0.1, 0.5, 0.1, 0.3))
    iso = quick(Ward(0.1, 0.5, 0.2, 0.2))
    assert aniso.isotropy_error > 0.1 and not aniso.isotropic
    assert iso.isotropy_error < 1e-12 and iso.isotropic
    assert "isotropic" in iso.disagreements  # the model declares isotropic=False for every alpha


def test_oren_nayar_full_goes_negative_qualitative_does_not():
    full = quick(OrenNayar(0.1, 1.0))
    assert full.min_value < 0 and not full.non_negative
    wi, wo = full.min_at
    assert wi[2] > 0 and wo[2] > 0
    qual = quick(OrenNayar(0.1, 1.0, form="qualitative"))
    assert qual.non_negative and qual.min_value > 0


def test_record_fields_and_json():
    r = quick(Lambert(0.2))
    d = json.loads(r.to_json())
    for name in ("non_negative", "min_value", "energy_conserving", "max_albedo", "reciprocal", "reciprocity_error",
                 "isotropic", "isotropy_error", "declared", "quadrature_error", "pairs"):
        assert name in d
    assert d["max_albedo"] == pytest.approx(np.pi * F32(0.2), abs=1e-12)


# --------------------------------------------------------------------------- CLI
def test_cli_brdf_text_and_json(capsys, monkeypatch):
    monkeypatch.setattr(analysis, "DEFAULT_THETA_I", np.array([0.0, np.arccos(1e-2)]))
    assert main(["brdf", "Phong(kd=0.2, ks=0.5, q=20)", "--directions", "40"]) == 0
    out = capsys.readouterr().out
    for word in ("non-negative", "energy-conserving", "reciprocal", "isotropic", "max albedo"):
        assert word in out
    assert main(["brdf", "Phong(kd=0.2, ks=0.5, q=20)", "--json", "--directions", "40"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["reciprocal"] is False and d["energy_conserving"] is False and d["max_albedo"] > 1


@pytest.mark.parametrize("expression", ["__import__('os')", "open('x')", "1 + 1", "Phong(kd=", "Nope(1)"])
def test_cli_brdf_rejects_other_expressions(capsys, expression):
    assert main(["brdf", expression]) == 2
    assert "glphong brdf" in capsys.readouterr().err


# --------------------------------------------------------------------------- GPU
def test_gpu_agrees_with_twin(glphong_backend):
    material = Phong(0.2, 0.5, 20.0)
    gpu = albedo(material, [0.0, 1.0], gpu=True, backend=glphong_backend)
    twin = albedo(material, [0.0, 1.0])
    np.testing.assert_allclose(gpu, twin, rtol=1e-4)
    r = properties(material, gpu=True, backend=glphong_backend, directions=30, theta_i=[0.0])
    assert r.evaluated_by.startswith("gpu") and not r.reciprocal and r.reciprocity_error > 0.1
