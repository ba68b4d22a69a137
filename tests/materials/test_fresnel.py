"""The Fresnel factors (`glphong.materials.SchlickFresnel`, `DielectricFresnel`, glsl/fresnel.glsl) and the
``fresnel=`` argument of the glossy built-ins, tested the way a user tests a model.

What is tested, on both backends where a GPU is involved (fixture ``glphong_backend``):

- ``fresnel_schlick`` and ``fresnel_dielectric`` on the GPU (`glphong.testing.probe`) and in the twin against
  independent float64 formulas written here: Schlick's polynomial, and for the dielectric the
  polarised Fresnel equations through Snell's law, ``F = (R_s + R_p) / 2``, ``R_s = ((cos i - n cos t) /
  (cos i + n cos t))^2``, ``R_p = ((n cos i - cos t) / (n cos i + cos t))^2`` (not the g-form the GLSL uses),
  at 400 cosines in [0, 1] (endpoints and cosines 1 - 2^-k included), for ior 1 + 2^-20, 1.33, 1.5, 2.5,
  1e4 and, with total internal reflection, 0.75; the twin agrees to 1e-12 and the GPU to 2e-6 absolute
  (measured at most 6e-7); a cosine that rounds above 1 gives f0 (Schlick) and the normal-incidence
  value (dielectric), never NaN;
- Phong's lobe with ``fresnel=`` (``F(n.l)``) and Blinn's (``F(h.l)``): the twin against ``k_s F q-lobe``
  written here (the GLSL response against the twin with Schlick and the dielectric form, ior above and
  below 1, is in tests/test_conformance.py);
- the definition: ``fresnel=`` is validated (a clear error for anything else), its form is a key define
  (``PHONG_LOBE_FRESNEL_SCHLICK``), ``fresnel=None`` compiles no Fresnel code and is bit-identical to the
  lecture's model, the uber-shader holds Phong with and without Fresnel in one program;
- the grazing brightening the lecture's slide asks about, in a rendered scene
  (``examples/fresnel_grazing.py``): the mirror highlight on a floor seen at 0, 60, 80 and 88 degrees from
  the normal; with ``SchlickFresnel(0.04)`` its peak radiance, relative to the same scene without
  Fresnel, equals ``F(h.l)`` at the highlight (to 2 %) and grows from 0.04 at normal view to above 0.5 at
  88 degrees, while without Fresnel the peak does not grow toward grazing.
"""
import numpy as np
import pytest

import glphong
from glphong import reference
from glphong.testing import probe
from glphong.shaders.key import program_key, uber_key
from glphong.materials import BlinnLobe, DielectricFresnel, PhongLobe, SchlickFresnel
from glphong.shaders.assembly import assemble
from glphong.testing import direction_sets, evaluate, float32_units

IORS = [1 + 2.0 ** -20, 1.33, 1.5, 2.5, 1e4, 0.75]


def snell_fresnel(ior, c):
    """Unpolarised reflectance from the polarised Fresnel equations and Snell's law (float64)."""
    c = np.asarray(c, dtype=np.float64)
    sin_t2 = (1 - c * c) / ior ** 2
    cos_t = np.sqrt(np.maximum(1 - sin_t2, 0))
    with np.errstate(divide="ignore", invalid="ignore"):
        rs = ((c - ior * cos_t) / (c + ior * cos_t)) ** 2
        rp = ((ior * c - cos_t) / (ior * c + cos_t)) ** 2
    f = 0.5 * (rs + rp)
    return np.where((sin_t2 >= 1) | (c == 0), 1.0, f)


def schlick(f0, c):
    return f0 + (1 - f0) * (1 - np.clip(c, 0, 1)) ** 5


def cosines():
    c = np.concatenate([np.linspace(0, 1, 360), 1 - 2.0 ** -np.arange(1, 25), [0.0, 1e-30, 1e-7, 1.0]])
    return np.asarray(c, np.float32)


@pytest.fixture(scope="module")
def gl():
    with glphong.create_context("egl") as context:
        yield context


# --------------------------------------------------------------------------- the factors
def test_schlick_against_the_polynomial(glphong_context):
    c = cosines()
    f0 = np.array([0.04, 0.5, 1.0], np.float32)
    expected = np.stack([schlick(float(x), c.astype(np.float64)) for x in f0], axis=-1)
    twin = reference.fresnel_schlick(f0.astype(np.float64), c.astype(np.float64))
    np.testing.assert_allclose(twin, expected, rtol=1e-12, atol=0)
    gpu = probe.evaluate(glphong_context, "fresnel_schlick", f0=np.tile(f0, (len(c), 1)), c=c)["return"]
    assert np.max(np.abs(gpu - expected)) < 2e-6
    above = probe.evaluate(glphong_context, "fresnel_schlick", f0=[f0], c=[1.0000001])["return"]
    np.testing.assert_array_equal(above[0], f0)  # a cosine rounded above 1 gives f0, no negative power


@pytest.mark.parametrize("ior", IORS, ids=[f"ior={i:g}" for i in IORS])
def test_dielectric_against_snell(glphong_context, ior):
    c = cosines()
    ior32 = float(np.float32(ior))
    expected = snell_fresnel(ior32, c.astype(np.float64))
    twin = reference.fresnel_dielectric(np.float64(ior32), c.astype(np.float64))
    np.testing.assert_allclose(twin, expected, rtol=1e-9, atol=1e-12)
    gpu = probe.evaluate(glphong_context, "fresnel_dielectric", ior=np.full(len(c), ior32, np.float32), c=c)["return"]
    assert np.all(np.isfinite(gpu)) and np.all((gpu >= 0) & (gpu <= 1))
    assert np.max(np.abs(gpu - expected)) < 2e-6, np.max(np.abs(gpu - expected))
    if ior < 1:  # total internal reflection beyond the critical angle
        critical = np.sqrt(1 - ior32 ** 2)
        assert np.all(gpu[c.astype(np.float64) < critical - 1e-6] == 1.0)


def test_dielectric_at_normal_incidence_is_the_textbook_value(glphong_context):
    for ior in (1.33, 1.5, 2.5):
        gpu = probe.evaluate(glphong_context, "fresnel_dielectric", ior=[ior], c=[1.0])["return"][0]
        assert abs(gpu - ((ior - 1) / (ior + 1)) ** 2) < 1e-7
    assert probe.evaluate(glphong_context, "fresnel_dielectric", ior=[1.0], c=[0.0])["return"][0] == 1.0
    assert probe.evaluate(glphong_context, "fresnel_dielectric", ior=[1.0], c=[0.5])["return"][0] == 0.0


# --------------------------------------------------------------------------- the glossy built-ins with fresnel=
FRESNELS = [SchlickFresnel((0.04, 0.5, 0.95)), DielectricFresnel(1.5)]


@pytest.mark.parametrize("fresnel", FRESNELS, ids=repr)
def test_the_twin_is_ks_times_f_times_the_lobe(fresnel):
    wi, wo, _ = direction_sets(400, 3)
    l, v = float32_units(wi), float32_units(wo)
    n = np.array([0.0, 0.0, 1.0])
    lit = l[:, 2] > 0
    phong = evaluate(PhongLobe(0.8, 10.0, fresnel=fresnel), wi, wo, twin=True)
    blinn = evaluate(BlinnLobe(0.8, 10.0, fresnel=fresnel), wi, wo, twin=True)

    def factor(c):
        if isinstance(fresnel, SchlickFresnel):
            return np.stack([schlick(f, c) for f in fresnel.f0], axis=-1)
        return np.repeat(snell_fresnel(float(np.float32(fresnel.ior)), c)[:, None], 3, axis=1)

    r = 2 * l[:, 2:3] * n - l
    expected_phong = 0.8 * factor(l[:, 2]) * (np.maximum(np.sum(r * v, axis=1), 0) ** 10)[:, None]
    h = (l + v) / np.maximum(np.linalg.norm(l + v, axis=1, keepdims=True), 1e-300)
    ok = (v[:, 2] > 0) & (np.linalg.norm(l + v, axis=1) > 2.0 ** -20)
    expected_blinn = np.where(ok[:, None], 0.8 * factor(np.sum(h * l, axis=1))
                              * (np.maximum(h[:, 2], 0) ** 10)[:, None], 0)
    # float32 parameters (ks, f0) and the chord form against the direct dot product: measured 1.7e-6 relative at
    # most (lobes near 1e-5, where 10 ulps of v.r show), bound 1e-5; near 0 absolute 1e-12
    np.testing.assert_allclose(phong[lit], expected_phong[lit], rtol=1e-5, atol=1e-12)
    np.testing.assert_allclose(blinn[lit], expected_blinn[lit], rtol=1e-5, atol=1e-12)


def test_fresnel_is_validated_and_named_in_the_key():
    with pytest.raises(TypeError, match=r"fresnel must be None \(F = 1\), glphong.materials.SchlickFresnel"):
        glphong.Phong(0.2, 0.5, 10.0, fresnel=0.04)
    with pytest.raises(ValueError, match=r"SchlickFresnel: f0 must be finite and in \[0, 1\]"):
        SchlickFresnel(1.5)
    with pytest.raises(ValueError, match=r"DielectricFresnel: ior must be finite and in \(0, 1e\+06\]"):
        DielectricFresnel(0.0)
    with pytest.raises(TypeError, match="unexpected parameter 'fresnel'"):
        glphong.Lambert(0.2, fresnel=SchlickFresnel(0.04))
    material = glphong.Phong(0.2, 0.5, 10.0, fresnel=SchlickFresnel(0.04))
    assert repr(material) == "Phong(kd=0.2, ks=0.5, q=10, fresnel=SchlickFresnel(f0=0.04))"
    assert repr(glphong.BlinnPhong(0.2, 0.5, 10.0)) == "BlinnPhong(kd=0.2, ks=0.5, q=10)"
    assert material == glphong.Phong(0.2, 0.5, 10.0, fresnel=SchlickFresnel(0.04)) != glphong.Phong(0.2, 0.5, 10.0)
    assert material.fresnel == SchlickFresnel(0.04) and material.components[1].fresnel == SchlickFresnel(0.04)
    key = program_key(material, {"point": 1}, None)
    lobe = [t for t in key.terms if t.name == "phong_lobe"][0]
    assert lobe.defines == (("FRESNEL_SCHLICK", "1"),) and "fresnel" in lobe.uses
    assert ("PHONG_LOBE_FRESNEL_SCHLICK", "1") in key.defines()
    uniforms = material.uniform_values(key)
    assert uniforms["u_phong_lobe_fresnel_f0"].tolist() == [np.float32(0.04)] * 3
    plain = program_key(glphong.Phong(0.2, 0.5, 10.0), {"point": 1}, None)
    source = assemble(plain.fragment_chunks(), plain.defines(), plain.generated_chunks())
    assert "fresnel_schlick(vec3 f0" not in source  # no Fresnel chunk without fresnel=
    assert "u_phong_lobe_fresnel_f0" not in glphong.Phong(0.2, 0.5, 10.0).uniform_values(plain)


def test_the_uber_shader_holds_phong_with_and_without_fresnel_in_one_program(glphong_make_renderer):
    from glphong import primitives

    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0.4, 3.0), (0, 0, 0)),
                          lights=[glphong.PointLight((2, 2, 2), power=100.0)])
    materials = [glphong.Phong(0.2, 0.5, 60), glphong.Phong(0.2, 0.5, 60, fresnel=SchlickFresnel(0.04)),
                 glphong.BlinnPhong(0.2, 0.5, 300, fresnel=DielectricFresnel(1.5))]
    for i, m in enumerate(materials):
        pose = np.eye(4)
        pose[:3, 3] = (-0.9 + 0.9 * i, 0, 0)
        scene.add(primitives.sphere(3, radius=0.4), m, pose=pose)
    uber = glphong_make_renderer(96, 64, "egl", specialise=False)
    specialised = glphong_make_renderer(96, 64, "egl", numerics="stable")  # the uber-shader's arithmetic
    # Fresnel is a run-time choice there, compiled for a model only where the scene has a Fresnel factor
    phong_terms = [t for t in uber_key(materials).terms if t.name == "phong_lobe"]
    assert len(phong_terms) == 1 and phong_terms[0].defines == (("FRESNEL_RUNTIME", "1"),)
    assert [t.defines for t in uber_key(materials[:1]).terms if t.name == "phong_lobe"] == [()]
    a, b = specialised.render(scene).radiance, uber.render(scene).radiance
    np.testing.assert_allclose(b, a, rtol=2e-6, atol=1e-30)
    assert glphong.verify(scene, uber).passed
    assert len([k for k in uber.programs.keys() if k.output == "radiance"]) == 1


# --------------------------------------------------------------------------- the grazing brightening
def test_a_fresnel_floor_brightens_toward_grazing(glphong_make_renderer, load_example):
    example = load_example("fresnel_grazing")
    renderer = glphong_make_renderer(*example.SIZE, "egl")
    rows = example.measure(renderer)
    assert [r["view_angle_deg"] for r in rows] == list(example.VIEW_ANGLES_DEG)
    for r in rows:  # the rendered ratio is F at the highlight's h.l
        assert abs(r["ratio"] - r["fresnel_at_peak"]) < 0.02 * r["fresnel_at_peak"], r
    assert rows[0]["ratio"] < 0.05 and rows[-1]["ratio"] > 0.5
    assert all(a["ratio"] < b["ratio"] for a, b in zip(rows, rows[1:]))  # grows monotonically toward grazing
    plain = [r["peak_without"] for r in rows]
    assert max(plain) <= 1.0001 * plain[0]  # without Fresnel the mirror peak does not grow toward grazing
