"""The built-in model 'lafortune_lobes' (`glphong.materials.LafortuneLobes`) and the material
`glphong.materials.Lafortune` (Lafortune, Foo, Torrance and Greenberg 1997), tested the way a user tests
their own model.

What is specific to it (twin agreement for the lobes below, n = 0 to 1e6, four lobes with the diffuse term,
a tilted mirrored frame and every rho 0, the definition's mechanics, the sum of the terms, the declared
properties and the stable run of the stability cases are in tests/test_conformance.py), with the toolkit
of `glphong.testing` on both backends (fixture ``glphong_backend``); figures measured on Mesa llvmpipe,
the same through EGL and OSMesa:

- closed form: ``f_r = rho_d/pi + sum_i rho_i max(Cx l_x v_x + Cy l_y v_y + Cz l_z v_z, 0)^n_i``
  written here in float64 at the unit directions the GPU is given, against `evaluate` (GPU) and the
  twin, for Phong-type lobes (``C = (-1, -1, 1)``, n = 1, 50, 1e4, 1e6), an off-specular, a
  retro-reflective and an anisotropic lobe and four lobes, at normal, oblique (40, 75 deg) and grazing
  (n.l = 1e-2, 1e-4) incidence, at the lobe's peak ``v = (C o l)/|C o l|`` and where it has fallen to
  1/2 and 1e-3 (or 0.3, 0.7 rad off for n <= 1), for the +z normal and a tilted normal with a tangent.
  GPU: within the documented accuracy (the model docstring's estimate, computed here from the closed
  form's geometry; measured at most 0.19 of it, relative errors at most 4.1e-5 for the +z frame and
  1.5e-4 tilted); the peak of a Phong-type lobe is exact to 4 eps for the +z frame at every n up to
  1e6.  Twin, in float64 at the unit geometry: within 1e-12 plus the float64 closed form's own rounding
  ``n 1e-15 sum|C_i l_i v_i| / x`` (measured at most 0.44 of that); through `evaluate` (float32 inputs,
  +z frame) also the chord form's first-order dependence on ``|v| = 1 + e_v`` (``e_v (1 - cos)/cos``,
  asserted with a factor 2, which the measured difference meets to 1e-6 of it);
- with ``C = (-1, -1, 1)`` and ``rho = rho_s (n + 2)/(2 pi)`` the material equals the normalised Phong
  closed form ``rho_d/pi + rho_s (n + 2)/(2 pi) max(v.r, 0)^n``, ``r = 2 (n.l) n - l`` (world space, a
  tilted frame; n = 1, 60, 1e4): the twin to ``1e-12 + n 1e-15``, the GPU to 1e-5, 1e-5, 1e-4 (measured
  4.1e-7, 6.4e-7, 8.3e-6);
- reciprocity for four lobes (off-specular, retro-reflective, anisotropic) in a tilted frame: the twin
  in float64 on unit vectors to 1e-13 (measured 1.4e-15), the GPU to 5e-5 (measured 6.5e-6), against
  the lecture's Phong lobe (the same ``(v.r)^q`` in its response, so ``f_r = (v.r)^q/(n.l)``: not
  reciprocal);
- the retro-reflective lobe's maximum over v (a 1e-3 rad grid around l) is at v = l; an off-specular
  lobe's maximum in the plane of incidence lies past the mirror direction toward grazing, at
  ``tan(theta) = (Cx/Cz) tan(theta_l)``, and a Phong-type one at the mirror direction; rotating l and
  v together about n changes f_r by more than 10 % when Cx != Cy and by at most 1e-5 when Cx = Cy;
- directional albedo by quadrature of the closed form (Gauss-Legendre in cos(theta)): a normalised
  Phong-type lobe (n = 20) reflects rho_s at normal incidence (to 1e-9 of its float32 rho) and less at
  30, 60 and 80 degrees (about rho_s cos(theta_i)); an off-specular lobe (C = (-1.5, -1.5, 1), n = 10)
  scaled to reflect rho_s = 0.7 at normal incidence reflects 7.0 at 80 degrees (why energy
  conservation is not declared);
- a lobe saturating at e^88 (|C| = 2, n = 1e6) at l = v: finite on the GPU, e^88 (n.l) to 1e-4, its zero
  channel exactly 0;
- a render of `glphong.primitives.sphere` (analytic tangents) with an anisotropic two-lobe material
  under a point light through ``glphong_renderer``, passing `assert_render_matches`;
- the declaration: params and ranges, needs ('view', 'tangent'), no choices, declared properties; the
  constructors (lobes= or per-lobe keywords, 1 to 4 lobes; a bad lobe raises naming the lobe and the
  range), `parameter_values` and repr round trips; the structural define LAFORTUNE_LOBES_COUNT and the
  uniform names (only the used lobes' are bound, every lobe's is declared);
- the stability cases (`LafortuneLobes.stability_cases`, 25, all passing in the conformance test): the
  Phong-type lobe at n = 1e6 exact at its peak (1e-6) and to 1e-4 near it, the saturating lobe finite
  with its zero channel at the diffuse term; the float64 twin agrees with the mpmath oracle on every
  in-range case to 1e-7 (measured 3.5e-8; checked, for every registered case, by
  tests/test_stability.py::test_float64_twin_agrees_with_the_mpmath_oracle); the textbook formulation
  (``NAIVE``) fails the n = 1e6 case near the peak (1.7e-2 off) and the saturating lobe (``pow(2, 1e6)``
  is Inf).
"""
import numpy as np
import pytest

import glphong
import glphong.primitives
from glphong.shaders.key import program_key, response_key
from glphong.materials import Diffuse, Lafortune, LafortuneLobes, PhongLobe
from glphong.materials.lafortune import LAFORTUNE_MAX_LOBES
from glphong.shaders.assembly import assemble, effective_source
from glphong.testing import assert_render_matches, evaluate, float32_units

EPS = 2.0 ** -24
FLT_MIN = 2.0 ** -126
PHONG = (-1.0, -1.0, 1.0)
OFF = (-1.1, -1.1, 0.9)
RETRO = (0.98, 0.98, 0.98)
ANISO = (-1.0, -0.8, 1.0)
FOUR = [((0.8, 0.0, 0.4), -1.0, -1.0, 1.0, 100.0), (0.2, -1.05, -1.05, 0.95, 20.0), (0.1, 0.9, 0.9, 0.9, 5.0),
        ((0.0, 0.3, 0.6), -0.6, -0.9, 1.0, 2.0)]
#: name -> (rho_d, lobes): the closed-form and twin parametrisations
LOBE_SETS = {
    "phong n=1": (0.0, [((0.7, 0.0, 0.3), *PHONG, 1.0)]),
    "phong n=50": (0.0, [((0.7, 0.0, 0.3), *PHONG, 50.0)]),
    "phong n=1e4": (0.0, [((0.7, 0.0, 0.3), *PHONG, 1e4)]),
    "phong n=1e6": (0.0, [((0.7, 0.0, 0.3), *PHONG, 1e6)]),
    "off-specular n=50": (0.0, [(0.5, *OFF, 50.0)]),
    "retro n=100": (0.0, [(0.5, *RETRO, 100.0)]),
    "anisotropic n=300": (0.0, [(0.5, *ANISO, 300.0)]),
    "four lobes": (0.2, FOUR),
}
TILTED = np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9])
FRAMES = {"normal+z": (np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])),
          "tilted": (TILTED, np.cross(TILTED, [0.0, 1.0, 0.0]) / np.linalg.norm(np.cross(TILTED, [0.0, 1.0, 0.0])))}


def f32(x):
    """The float32 value the GPU is given (the documented input precision), as float64."""
    return np.asarray(x, dtype=np.float32).astype(np.float64)


def unit(a):
    a = np.asarray(a, dtype=np.float64)
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def material_of(rho_d, lobes):
    return Lafortune(rho_d, lobes) if rho_d else LafortuneLobes(lobes)


def shader_frame(normal, tangent):
    """The orthonormal frame of the float32 normal and tangent the GPU is given (common.glsl's
    frame_from_tangent, exactly): ``(n, t, b)`` in float64, ``t = (T - (n.T) n)/|T - (n.T) n|``, ``b = n x t``."""
    n = unit(float32_units(normal))
    t32 = np.asarray(tangent, dtype=np.float32).astype(np.float64)
    t = unit(t32 - np.dot(n, t32) * n)
    return n, t, np.cross(n, t)


def local(frame, d):
    n, t, b = frame
    return np.stack([d @ t, d @ b, d @ n], axis=-1)


# --------------------------------------------------------------------------- the closed form
def closed_form(rho_d, lobes, frame, wi, wo):
    """``(f_r, parts)`` at the unit directions of ``wi``, ``wo``: ``f_r = rho_d/pi + sum rho_i max(x_i, 0)^n_i``
    with ``x_i = Cx l_x v_x + Cy l_y v_y + Cz l_z v_z`` in the frame; ``parts`` per lobe: (contribution (N, 3),
    x, |C o l|, n, C)."""
    l, v = local(frame, unit(wi)), local(frame, unit(wo))
    fr = np.zeros((len(l), 3)) + f32(rho_d) / np.pi
    parts = []
    for rho, cx, cy, cz, q in lobes:
        rho, c, q = f32(rho), f32([cx, cy, cz]), float(f32(q))
        x = np.sum(c * l * v, axis=1)
        lobe = np.ones_like(x) if q == 0 else np.where(x > 0, np.abs(x) ** q, 0.0)
        contribution = rho * lobe[:, None]
        fr = fr + contribution
        parts.append((contribution, x, np.linalg.norm(c * l, axis=1), q, c))
    return fr, parts


def closed_form_rows(lobes, frame):
    """``(wi, wo, labels)``: the light at normal, oblique and grazing incidence; v at the first lobe's peak
    ``(C o l)/|C o l|`` and turned from it until the lobe has fallen to 1/2 and 1e-3 (n > 1), or by 0.3 and
    0.7 rad (n <= 1); plus views at grazing (n.v = 1e-3) for the light at 40 degrees."""
    n, t, b = frame
    _, cx, cy, cz, q = lobes[0]
    c = np.array([cx, cy, cz])
    if q > 1:
        offsets = {"peak": 0.0, "half maximum": np.arccos(0.5 ** (1 / q)),
                   "1e-3 of maximum": np.arccos(1e-3 ** (1 / q))}
    else:
        offsets = {"peak": 0.0, "0.3 rad off": 0.3, "0.7 rad off": 0.7}
    lights = {"normal incidence": 0.0, "40 deg": np.radians(40.0), "75 deg": np.radians(75.0),
              "grazing n.l=1e-2": np.arccos(1e-2), "grazing n.l=1e-4": np.arccos(1e-4)}
    to_world = np.stack([t, b, n])  # rows: local -> world by  d_local @ to_world
    wi, wo, labels = [], [], []
    for light, theta in lights.items():
        l_local = np.array([np.sin(theta) * np.cos(0.3), np.sin(theta) * np.sin(0.3), np.cos(theta)])
        w = unit(c * l_local)
        side = unit(np.cross(w, [0.0, 0.0, 1.0])) if abs(w[2]) < 0.999 else np.array([1.0, 0.0, 0.0])
        for where, alpha in offsets.items():
            v_local = np.cos(alpha) * w + np.sin(alpha) * side  # turned about an axis in the plane of w and n
            wi.append(l_local @ to_world)
            wo.append(v_local @ to_world)
            labels.append(f"{light}, {where}")
    for phi in (0.3, 0.3 + np.pi, 2.0):
        theta = np.radians(40.0)
        wi.append(np.array([np.sin(theta) * np.cos(0.3), np.sin(theta) * np.sin(0.3), np.cos(theta)]) @ to_world)
        s = np.sqrt(1 - 1e-6)
        wo.append(np.array([s * np.cos(phi), s * np.sin(phi), 1e-3]) @ to_world)
        labels.append(f"grazing view n.v=1e-3, azimuth {phi:.2f}")
    return np.array(wi), np.array(wo), labels


def documented_accuracy(parts, rho_d, n_dot_l):
    """The model's documented float32 accuracy (lafortune.py, the GLSL header), as an absolute tolerance
    (N, 3) on the response: per lobe ``eps (16 + 4 lambda + 6 s sqrt(2 n lambda)) + 4 eps n (|ln m| +
    |ln(1 - u)|/2) + 8 eps n sqrt(u/(1 - u))`` of its contribution, ``8 eps`` of the diffuse term, and the
    light gate's ``D eps / (n.l)`` (D = 8) of the whole."""
    tol = np.zeros_like(parts[0][0]) + f32(rho_d) / np.pi * 8 * EPS
    total = np.zeros_like(tol) + f32(rho_d) / np.pi
    for contribution, x, w_len, q, c in parts:
        m = np.max(np.abs(c))
        one_minus_u = np.minimum((w_len / m) ** 2, 1.0)
        u = 1 - one_minus_u
        cos_alpha = np.clip(x / w_len, 1e-300, 1.0)
        lam = -q * np.log(cos_alpha)
        s = 1 / np.sqrt(one_minus_u)
        rel = (EPS * (16 + 4 * lam + 6 * s * np.sqrt(2 * q * lam))
               + 4 * EPS * q * (abs(np.log(m)) - 0.5 * np.log(one_minus_u)) + 8 * EPS * q * np.sqrt(u / one_minus_u))
        tol = tol + contribution * rel[:, None]
        total = total + contribution
    return (tol + total * (8 * EPS / n_dot_l)[:, None]) * n_dot_l[:, None]


@pytest.mark.parametrize("frame_name", list(FRAMES))
@pytest.mark.parametrize("set_name", list(LOBE_SETS))
def test_closed_form(glphong_backend, set_name, frame_name):
    rho_d, lobes = LOBE_SETS[set_name]
    normal, tangent = FRAMES[frame_name]
    frame = shader_frame(normal, tangent)
    material = material_of(rho_d, lobes)
    wi, wo, labels = closed_form_rows(lobes, frame)
    l32, v32 = float32_units(wi), float32_units(wo)  # exactly what the GPU and the twin are given
    fr, parts = closed_form(rho_d, lobes, frame, l32, v32)
    n_dot_l = unit(l32) @ frame[0]
    expected = fr * n_dot_l[:, None]
    gpu = evaluate(material, wi, wo, normal=normal, tangent=tangent, backend=glphong_backend).astype(np.float64)
    zero = np.asarray(material.lobes[0][0]) == 0
    if rho_d == 0 and zero.any():
        assert np.all(gpu[:, zero] == 0.0)  # the zero channel
    # GPU: within the documented accuracy, measured at most 0.19 of it
    tol = documented_accuracy(parts, rho_d, n_dot_l)
    tol = np.maximum(tol, FLT_MIN)
    bad = np.abs(gpu - expected) > tol
    assert not bad.any(), "\n".join(f"{labels[i]}: gpu {gpu[i]}, closed form {expected[i]}, tolerance {tol[i]}"
                                    for i in np.nonzero(bad.any(axis=1))[0])
    assert np.max(np.abs(gpu - expected) / tol) < 0.5
    # the twin in float64 on the unit geometry (the directions and frame above, exactly): to 1e-12 plus the
    # float64 closed form's own rounding n 1e-15 sum|C l v| / x, and below e^-104 the twin's clamp
    l64, v64 = unit(l32), unit(v32)
    twin_fr = _twin_fr(material, frame, l64, v64)
    allowed = 1e-12 * np.abs(fr) + 1e-300
    for (rho, *_), (contribution, x, w_len, q, c) in zip(lobes, parts):
        l, v = local(frame, l64), local(frame, v64)
        with np.errstate(divide="ignore", invalid="ignore"):
            cancel = np.nan_to_num(q * 1e-15 * np.sum(np.abs(c * l * v), axis=1) / np.abs(x), posinf=0.0)
        allowed = allowed + contribution * cancel[:, None] + f32(rho) * np.exp(-104.0) * 1.01
    ratio = np.abs(twin_fr - fr) / allowed
    assert ratio.max() < 1.0, (labels[int(np.argmax(ratio.max(axis=1)))], ratio.max())
    # and through `evaluate` (the float32 inputs, frame built by the twin as the shader does): for the +z
    # frame the only difference is |v| = 1 + e_v, which the chord form reads as cos (1 - e_v (1 - cos)/cos)
    if frame_name == "normal+z":
        twin = evaluate(material, wi, wo, normal=normal, tangent=tangent, twin=True)
        twin_fr = twin / (l32 @ frame[0])[:, None]
        e_v = np.abs(np.linalg.norm(v32, axis=1) - 1.0)
        for contribution, x, w_len, q, c in parts:
            with np.errstate(divide="ignore", invalid="ignore"):
                cos = x / w_len
                allowed = allowed + contribution * np.nan_to_num(2 * q * e_v * np.abs(1 - cos) / np.abs(cos),
                                                                 posinf=0.0)[:, None]
        ratio = np.abs(twin_fr - fr) / allowed
        assert ratio.max() < 1.0, (labels[int(np.argmax(ratio.max(axis=1)))], ratio.max())
    # the peak of a Phong-type lobe in the +z frame: exact (the chord form) to 4 eps at every n
    if frame_name == "normal+z" and lobes[0][1:4] == PHONG and rho_d == 0:
        peak = [i for i, s in enumerate(labels) if s.endswith("peak") and "grazing" not in s]
        rho = np.asarray(np.float32(lobes[0][0]), dtype=np.float64)
        np.testing.assert_allclose(gpu[peak] / n_dot_l[peak, None], np.tile(rho, (len(peak), 1)), rtol=4 * EPS, atol=0)


@pytest.mark.parametrize("q", [1.0, 60.0, 1e4])
def test_normalized_phong_closed_form(glphong_backend, q):
    """``C = (-1, -1, 1)``, ``rho = rho_s (n + 2)/(2 pi)``: the normalised Phong BRDF
    ``rho_d/pi + rho_s (n + 2)/(2 pi) max(v.r, 0)^n``, r = 2 (n.l) n - l, written in world space."""
    rho_d, rho_s = np.array([0.3, 0.2, 0.1]), np.array([0.5, 0.6, 0.0])
    material = Lafortune(rho_d, [(rho_s * (q + 2) / (2 * np.pi), -1.0, -1.0, 1.0, q)])
    rng = np.random.default_rng(7)
    normal = TILTED
    wi = unit(rng.normal(size=(300, 3)))
    wi = np.where((wi @ normal)[:, None] > 0.05, wi, wi - 2 * np.minimum(wi @ normal - 0.05, 0)[:, None] * normal)
    r = 2 * (unit(wi) @ normal)[:, None] * normal - unit(wi)
    wo = unit(r + rng.normal(size=(300, 3)) * (0.5 / np.sqrt(q)))  # around the mirror direction
    l32, v32 = unit(float32_units(wi)), unit(float32_units(wo))
    n = unit(float32_units(normal))
    r32 = 2 * (l32 @ n)[:, None] * n - l32
    cos_r = np.sum(v32 * r32, axis=1)
    fr = f32(rho_d) / np.pi + f32(rho_s * (q + 2) / (2 * np.pi)) * np.where(cos_r > 0, np.abs(cos_r) ** q, 0.0)[:, None]
    expected = fr * (l32 @ n)[:, None]
    tangent = FRAMES["tilted"][1]
    # the twin in float64 at the unit geometry: to the closed form's rounding (n 1e-15 relative)
    twin_fr = _twin_fr(material, shader_frame(normal, tangent), l32, v32)
    np.testing.assert_allclose(twin_fr, fr, rtol=1e-12 + q * 1e-15, atol=1e-300)
    # the GPU (float32 inputs, tilted frame): measured 4.1e-7, 6.4e-7 and 8.3e-6 relative for n = 1, 60, 1e4
    gpu = evaluate(material, wi, wo, normal=normal, tangent=tangent, backend=glphong_backend).astype(np.float64)
    np.testing.assert_allclose(gpu, expected, rtol={1.0: 1e-5, 60.0: 1e-5, 1e4: 1e-4}[q], atol=1e-37)


# --------------------------------------------------------------------------- physics
def _twin_fr(material, frame, wi, wo):
    """f_r from the twin in float64 at exactly unit inputs (no float32 rounding)."""
    from glphong.materials import ShadingFrame

    n, t, b = frame
    count = len(wi)
    f = ShadingFrame(np.tile(n, (count, 1)), np.tile(t, (count, 1)), np.tile(b, (count, 1)))
    n_dot_l = wi @ n
    total = sum(term.response(f, wi, wo, n_dot_l, term.values()) for term in material.components if not term.vanishes())
    return total / n_dot_l[:, None]


def _hemisphere(rng, count, normal):
    d = unit(rng.normal(size=(count, 3)))
    d = np.where((d @ normal)[:, None] < 0, d - 2 * (d @ normal)[:, None] * normal, d)
    return d[(d @ normal) > 1e-3]


def test_reciprocity(glphong_backend):
    """f_r(l, v) = f_r(v, l) for every lobe shape (the form is symmetric in l and v); the lecture's Phong lobe
    with the same (v.r)^q in its response is not reciprocal."""
    rng = np.random.default_rng(11)
    normal, tangent = FRAMES["tilted"]
    frame = shader_frame(normal, tangent)
    material = Lafortune(0.2, FOUR + [])
    wi, wo = _hemisphere(rng, 600, frame[0]), _hemisphere(rng, 600, frame[0])
    count = min(len(wi), len(wo))
    wi, wo = wi[:count], wo[:count]
    forward, backward = _twin_fr(material, frame, wi, wo), _twin_fr(material, frame, wo, wi)
    np.testing.assert_allclose(forward, backward, rtol=1e-13, atol=0)  # measured 1.4e-15
    gpu_f = evaluate(material, wi, wo, normal=normal, tangent=tangent, backend=glphong_backend).astype(np.float64)
    gpu_b = evaluate(material, wo, wi, normal=normal, tangent=tangent, backend=glphong_backend).astype(np.float64)
    l32, v32 = float32_units(wi), float32_units(wo)
    n32 = float32_units(normal)
    np.testing.assert_allclose(gpu_f / (l32 @ n32)[:, None], gpu_b / (v32 @ n32)[:, None], rtol=5e-5, atol=0)  # 6.5e-6
    # the same lobe as the lecture's response k_s (v.r)^q: its BRDF k_s (v.r)^q / (n.l) is not symmetric
    phong = PhongLobe(0.5, 20.0)
    lafortune = LafortuneLobes([(0.5, -1.0, -1.0, 1.0, 20.0)])
    with np.errstate(divide="ignore", invalid="ignore"):  # 0/0 where both lobes are 0 (v.r <= 0)
        ratio_phong = _twin_fr(phong, frame, wi, wo) / _twin_fr(phong, frame, wo, wi)
        ratio_lafortune = _twin_fr(lafortune, frame, wi, wo) / _twin_fr(lafortune, frame, wo, wi)
    finite = np.isfinite(ratio_phong[:, 0]) & (ratio_phong[:, 0] > 0)
    assert np.max(np.abs(ratio_phong[finite, 0] - 1)) > 0.5
    np.testing.assert_allclose(ratio_lafortune[finite], 1.0, rtol=1e-12)
    assert PhongLobe.properties.reciprocal is False and LafortuneLobes.properties.reciprocal is True


def _cone(center, radius, steps):
    """Unit directions on a square grid of half-width ``radius`` [rad] (``steps`` per side) around ``center``."""
    a = unit(np.cross(center, [0.3, 0.5, 0.7]))
    b = np.cross(center, a)
    s = np.linspace(-radius, radius, steps)
    x, y = np.meshgrid(s, s)
    return unit(center + x.ravel()[:, None] * a + y.ravel()[:, None] * b)


def test_retro_reflective_lobe_peaks_at_l_equals_v(glphong_backend):
    material = LafortuneLobes([(0.5, *RETRO, 100.0)])
    for theta in (0.0, 0.5, 1.2):
        light = np.array([np.sin(theta) * np.cos(1.0), np.sin(theta) * np.sin(1.0), np.cos(theta)])
        views = _cone(light, 0.05, 101)  # a 1e-3 rad grid, light at its centre
        views = np.vstack([views, light])
        gpu = evaluate(material, np.tile(light, (len(views), 1)), views, backend=glphong_backend)
        best = views[int(np.argmax(gpu[:, 0]))]
        assert np.degrees(np.arccos(min(1.0, float(best @ light)))) < 0.06, theta  # at v = l (grid 0.057 deg)
        # and its value there: rho Cx^n (l.l)^n (n.l)
        np.testing.assert_allclose(gpu[-1, 0], 0.5 * 0.98 ** 100 * light[2], rtol=2e-5)


def test_off_specular_peak_moves_toward_grazing(glphong_backend):
    theta_l = np.radians(50.0)
    light = np.array([np.sin(theta_l), 0.0, np.cos(theta_l)])
    theta_v = np.radians(np.linspace(0.05, 89.95, 1799))  # 0.05 deg steps on the mirror side
    views = np.stack([-np.sin(theta_v), np.zeros_like(theta_v), np.cos(theta_v)], axis=1)
    for c, expected in ((OFF, np.arctan(abs(OFF[0] / OFF[2]) * np.tan(theta_l))), (PHONG, theta_l)):
        material = LafortuneLobes([(0.5, *c, 50.0)])
        gpu = evaluate(material, np.tile(light, (len(views), 1)), views, backend=glphong_backend)
        peak = theta_v[int(np.argmax(gpu[:, 0]))]
        assert abs(peak - expected) <= np.radians(0.05), (c, np.degrees(peak), np.degrees(expected))
    assert np.arctan(abs(OFF[0] / OFF[2]) * np.tan(theta_l)) > theta_l + np.radians(5)  # 55.6 deg: past the mirror


def test_anisotropy_iff_cx_differs_from_cy(glphong_backend):
    """Rotating l and v together about n (the tangent fixed) leaves f_r unchanged iff Cx = Cy."""
    rng = np.random.default_rng(5)
    wi, wo = _hemisphere(rng, 200, np.array([0.0, 0.0, 1.0])), _hemisphere(rng, 200, np.array([0.0, 0.0, 1.0]))
    count = min(len(wi), len(wo))
    wi, wo = wi[:count], wo[:count]
    psi = 0.7
    rot = np.array([[np.cos(psi), -np.sin(psi), 0.0], [np.sin(psi), np.cos(psi), 0.0], [0.0, 0.0, 1.0]])
    for c, isotropic in ((OFF, True), (RETRO, True), (ANISO, False), ((-1.0, -0.5, 0.8), False)):
        material = LafortuneLobes([(0.5, *c, 10.0)])
        before = evaluate(material, wi, wo, backend=glphong_backend).astype(np.float64)
        after = evaluate(material, wi @ rot.T, wo @ rot.T, backend=glphong_backend).astype(np.float64)
        big = before[:, 0] > 1e-6 * before[:, 0].max()
        change = np.abs(after[big, 0] - before[big, 0]) / before[big, 0]
        if isotropic:
            assert change.max() < 1e-5, (c, change.max())
        else:
            assert change.max() > 0.1, (c, change.max())


def _albedo(fr_of_v, light, normal, steps=160):
    """``int f_r(l, v) (n.v) d omega`` over the upper hemisphere (normal +z): Gauss-Legendre in cos(theta)
    (exact for the polynomial integrand at normal incidence), the midpoint rule in phi (periodic)."""
    x, w = np.polynomial.legendre.leggauss(steps)
    mu, w_mu = 0.5 * (x + 1), 0.5 * w
    phi = (np.arange(2 * steps) + 0.5) * np.pi / steps
    m, p = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1 - m * m)
    views = np.stack([s * np.cos(p), s * np.sin(p), m], axis=-1).reshape(-1, 3)
    weights = (w_mu[:, None] * np.full(len(phi), np.pi / steps)[None, :]).ravel()
    return float(np.sum(fr_of_v(light, views) * views[:, 2] * weights))


def _lobe_fr(rho, c, q):
    frame = (np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    return lambda light, views: closed_form(0.0, [(rho, *c, q)], frame, np.tile(light, (len(views), 1)), views)[0][:, 0]


def test_directional_albedo():
    q, rho_s = 20.0, 0.7
    fr = _lobe_fr(rho_s * (q + 2) / (2 * np.pi), PHONG, q)
    normal = np.array([0.0, 0.0, 1.0])
    albedo = {deg: _albedo(fr, np.array([np.sin(np.radians(deg)), 0.0, np.cos(np.radians(deg))]), normal)
              for deg in (0.0, 30.0, 60.0, 80.0)}
    # normal incidence: (n + 2)/(2 pi) int cos^n cos d omega = 1, so rho_s (Gauss-Legendre is exact here)
    rho = float(np.float32(rho_s * (q + 2) / (2 * np.pi)))  # the float32 uniform
    assert albedo[0.0] == pytest.approx(rho * 2 * np.pi / (q + 2), rel=1e-9)
    assert albedo[0.0] == pytest.approx(rho_s, rel=1e-7)  # the float32 rounding of rho
    assert albedo[0.0] > albedo[30.0] > albedo[60.0] > albedo[80.0] > 0.0  # the lobe is cut by the horizon
    # with rho_d = 0.3: rho_d + rho_s = 1, energy conserved at every incident angle tested
    assert all(0.3 + a <= 1.0 + 1e-6 for a in albedo.values())
    # an off-specular lobe (|C o l| grows toward grazing), scaled to reflect rho_s at normal incidence, reflects
    # more toward grazing: increasing reflectance, and beyond 1 at 80 degrees (measured 7.0)
    off = _lobe_fr(rho_s * (10.0 + 2) / (2 * np.pi), (-1.5, -1.5, 1.0), 10.0)
    assert _albedo(off, np.array([0.0, 0.0, 1.0]), normal) == pytest.approx(rho_s, rel=1e-7)
    grazing = _albedo(off, np.array([np.sin(np.radians(80.0)), 0.0, np.cos(np.radians(80.0))]), normal)
    assert grazing > 1.0
    assert LafortuneLobes.properties.energy_conserving is False and Lafortune.properties.energy_conserving is False


# --------------------------------------------------------------------------- saturation
def test_a_saturating_lobe_is_finite_at_e88(glphong_backend):
    """|C| = 2, n = 1e6 at l = v: the exponent is clamped at 88 (the twin check of the conformance test covers
    the other pairs); the zero channel stays 0, no 0 * Inf."""
    material = LafortuneLobes([((1.0, 0.0, 0.5), 2.0, 2.0, 2.0, 1e6)])
    wi = np.array([[0.3, 0.1, 0.9]])
    gpu = evaluate(material, wi, wi, backend=glphong_backend)
    assert np.isfinite(gpu).all() and gpu[0, 1] == 0.0
    np.testing.assert_allclose(gpu[0, 0], np.exp(88.0) * float(unit(float32_units(wi))[0, 2]), rtol=1e-4)


# --------------------------------------------------------------------------- a render
def test_render_matches(glphong_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, lights=[glphong.PointLight((1.5, 1.0, 3.0), (400.0, 300.0, 200.0))])
    material = Lafortune((0.3, 0.2, 0.1), [((0.8, 0.6, 0.4), -1.0, -0.6, 1.0, 60.0), (0.2, 0.9, 0.9, 0.9, 8.0)])
    scene.add(glphong.primitives.sphere(3), material)
    report = assert_render_matches(scene, glphong_renderer)
    assert report.covered_pixels > 1000 and report.nonfinite_count == 0
    assert report.gpu[..., 0].max() > 0.5  # the highlight is in the picture
    covered = report.mask[..., None] & (report.reference >= 2.0 ** -100)
    assert report.relative_error[covered].max() < 1e-3
    key = glphong_renderer.program_key(scene, scene.objects[0])
    assert key.has_tangent and ("LAFORTUNE_LOBES_COUNT", "2") in key.defines()


# --------------------------------------------------------------------------- the declaration
def test_declaration():
    assert LafortuneLobes.name == "lafortune_lobes"
    assert Lafortune.name == "lafortune" and Lafortune.terms == (Diffuse, LafortuneLobes)
    assert LAFORTUNE_MAX_LOBES == 4
    names = [p.name for p in LafortuneLobes.params]
    assert names == [f"lobe{k}_{part}" for k in range(1, 5) for part in ("rho", "c", "n")]
    rho, c, n = LafortuneLobes.params[:3]
    assert (rho.kind, rho.glsl_type, rho.interval, rho.unit) == ("rgb", "vec3", "[0, inf]", "1/sr")
    assert (c.kind, c.interval, c.low) == ("rgb", "[-inf, inf]", -np.inf)
    assert (n.kind, n.glsl_type, n.interval) == ("scalar", "float", "[0, 1e+06]")
    assert LafortuneLobes.needs == ("view", "tangent") and LafortuneLobes.uses == ("lobe",)
    assert LafortuneLobes.choices == () and LafortuneLobes.fresnel_slot is None and LafortuneLobes.ambient is None
    p = LafortuneLobes.properties
    assert (p.reciprocal, p.isotropic, p.energy_conserving, p.non_negative) == (True, False, False, True)
    assert (Lafortune.properties.reciprocal, Lafortune.properties.isotropic) == (True, False)
    assert [q.name for q in Lafortune.all_params()] == ["rho_d"] + names


def test_constructors_and_round_trips():
    m = Lafortune(0.2, [((0.5, 0.4, 0.3), -1.0, -1.0, 1.0, 30.0), (0.1, 0.9, 0.9, 0.9, 4.0)], ka=0.01)
    assert m.lobe_count == 2
    assert m.lobes == (((0.5, 0.4, 0.3), -1.0, -1.0, 1.0, 30.0), ((0.1, 0.1, 0.1), 0.9, 0.9, 0.9, 4.0))
    assert m.rho_d == (0.2,) * 3 and m.lobe1_c == (-1.0, -1.0, 1.0) and m.lobe2_n == 4.0 and m.ka == (0.01,) * 3
    diffuse, lobes = m.components
    assert type(diffuse) is Diffuse and type(lobes) is LafortuneLobes and lobes.defines() == (("COUNT", "2"),)
    values = m.parameter_values()
    assert set(values) == {"rho_d", "ka", "two_sided", "normal_map", "alpha_mask", "alpha_blend"} | {f"lobe{k}_{p}" for k in (1, 2) for p in ("rho", "c", "n")}
    assert type(m)(**values) == m and hash(type(m)(**values)) == hash(m)
    assert eval(repr(m), {"Lafortune": Lafortune}) == m
    assert Lafortune(0.2, m.lobes, ka=0.01) == m
    assert Lafortune(0.2, m.lobes) != m and Lafortune(0.2, m.lobes[:1], ka=0.01) != m
    from glphong.checks.stability import _with_ka

    assert _with_ka(m, 0.5).ka == (0.5,) * 3 and _with_ka(m, 0.5).lobes == m.lobes
    single = LafortuneLobes([(0.3, 0.5, 0.5, 0.5, 2.0)], two_sided=False)
    assert type(single)(**single.parameter_values()) == single and not single.two_sided
    assert LafortuneLobes.example().lobe_count == 2 and Lafortune.example().lobe_count == 2
    assert LafortuneLobes(lobe1_rho=0.2, lobe1_c=(-1, -1, 1), lobe1_n=5).lobes == (((0.2,) * 3, -1.0, -1.0, 1.0, 5.0),)
    four = Lafortune(0.1, FOUR)
    assert four.lobe_count == 4 and type(four)(**four.parameter_values()) == four


@pytest.mark.parametrize("lobes, error, match", [
    ([], ValueError, r"1 to 4 lobes \(LAFORTUNE_MAX_LOBES = 4; got 0\)"),
    ([(0.5, -1, -1, 1, 2.0)] * 5, ValueError, r"1 to 4 lobes \(LAFORTUNE_MAX_LOBES = 4; got 5\)"),
    ([(0.5, -1, -1, 1)], TypeError, r"lobes\[0\] must be a tuple \(rho, Cx, Cy, Cz, n\)"),
    ("abc", TypeError, "lobes must be a sequence"),
    ([(-0.1, -1, -1, 1, 2.0)], ValueError, r"lobes\[0\] \(rho\): lobe1_rho must be finite and in \[0, 3.40282e\+38\]"),
    ([(0.5, -1, -1, 1, 2.0), (0.5, -1, np.nan, 1, 2.0)], ValueError,
     r"lobes\[1\] \(Cx, Cy, Cz\): lobe2_c must be finite"),
    ([(0.5, -1, -1, 1, 2e6)], ValueError, r"lobes\[0\] \(n\): lobe1_n must be finite and in \[0, 1e\+06\]"),
    ([(0.5, -1, -1, 1, -1.0)], ValueError, r"lobe1_n must be finite and in \[0, 1e\+06\]"),
    ([(0.5, -1, -1, 1e39, 2.0)], ValueError, "lobe1_c"),
])
def test_bad_lobes_are_refused(lobes, error, match):
    with pytest.raises(error, match=match):
        Lafortune(0.2, lobes)
    with pytest.raises(error, match=match):
        LafortuneLobes(lobes)


def test_bad_constructor_calls_are_refused():
    with pytest.raises(TypeError, match="missing parameter 'lobes'"):
        LafortuneLobes()
    with pytest.raises(TypeError, match="missing parameter 'lobes'"):
        Lafortune(0.2)
    with pytest.raises(TypeError, match="not both"):
        Lafortune(0.2, [(0.5, -1, -1, 1, 2.0)], lobe1_rho=0.5)
    with pytest.raises(TypeError, match="missing parameter 'lobe1_c'"):
        Lafortune(0.2, lobe1_rho=0.5, lobe1_n=2.0)
    with pytest.raises(TypeError, match="missing parameter 'lobe1_rho'"):
        Lafortune(0.2, lobe2_rho=0.5, lobe2_c=1.0, lobe2_n=2.0)
    with pytest.raises(TypeError, match="unexpected parameter 'lobe5_rho'"):
        Lafortune(0.2, lobe5_rho=0.5)
    with pytest.raises(ValueError, match=r"rho_d must be finite and in \[0, 1\]"):
        Lafortune(1.5, [(0.5, -1, -1, 1, 2.0)])
    with pytest.raises(TypeError, match="two_sided must be a bool"):
        Lafortune(0.2, [(0.5, -1, -1, 1, 2.0)], two_sided=1)


def test_program_key_defines_and_uniform_names():
    terms = lambda m: [t.name for t in program_key(m, {"point": 1}, None).terms]  # noqa: E731
    lobes2 = [(0.5, -1, -1, 1, 20.0), ((0.0, 0.1, 0.2), 0.9, 0.9, 0.9, 3.0)]
    assert terms(Lafortune(0.2, [(0.0, -1, -1, 1, 20.0), (0.0, 0.9, 0.9, 0.9, 3.0)])) == ["diffuse"]  # every rho 0
    assert LafortuneLobes([(0.0, -1, -1, 1, 20.0)]).vanishes() and not LafortuneLobes(lobes2[1:]).vanishes()
    assert response_key(LafortuneLobes([(0.0, -1, -1, 1, 20.0)])).terms == ()
    for count in range(1, 5):
        material = Lafortune(0.2, FOUR[:count])
        key = program_key(material, {"point": 1}, None)
        assert key.has_tangent and key.needs_view
        assert ("LAFORTUNE_LOBES_COUNT", str(count)) in key.defines()
        uniforms = material.uniform_values(key)
        expected = {"u_diffuse_rho_d"} | {f"u_lafortune_lobes_lobe{k}_{p}" for k in range(1, count + 1)
                                          for p in ("rho", "c", "n")}
        assert set(uniforms) == expected
        assert uniforms["u_lafortune_lobes_lobe1_c"].shape == (3,) and uniforms["u_lafortune_lobes_lobe1_n"].shape == ()
        source = effective_source(assemble(key.fragment_chunks(), key.defines(), key.generated_chunks()))
        for k in range(1, 5):  # the unused lobes' uniforms are declared but not read
            assert "uniform vec3 u_lafortune_lobes_lobe%d_rho;" % k in source
            assert (f"u_lafortune_lobes_lobe{k}_rho * lafortune_lobe(" in source) == (k <= count)
        assert "response += lafortune_lobes_response(f, wi, wo, n_dot_l);" in source
    four = Lafortune(0.2, FOUR)
    uniforms = four.uniform_values(program_key(four, {"point": 1}, None))
    np.testing.assert_array_equal(uniforms["u_lafortune_lobes_lobe4_c"], np.float32([-0.6, -0.9, 1.0]))


# --------------------------------------------------------------------------- stability
def test_stability_cases(glphong_backend):
    from glphong.checks.stability import cases_for, run_stability

    cases = cases_for(LafortuneLobes)
    assert len(cases) == 25
    names = " | ".join(c.name for c in cases)
    for needle in ("grazing light", "off-specular", "retro-reflective C=0.98 n=100 at l = v", "anisotropic",
                   "n=1e+06 peak", "four lobes", "saturating"):
        assert needle in names, needle
    chosen = [c for c in cases if "n=1e+06 peak" in c.name or "n=1e+06 near" in c.name or "saturating" in c.name]
    rows = {r.case: r for r in run_stability(backend=glphong_backend, cases=chosen).rows}
    assert rows["lafortune phong-type C=(-1,-1,1) n=1e+06 peak"].relative_error < 1e-6  # exact at the peak
    assert rows["lafortune phong-type C=(-1,-1,1) n=1e+06 near"].relative_error < 1e-4  # measured 2e-5
    saturated = rows["lafortune saturating C=2 n=1e6 at l = v"]
    # the lobe's zero channel stays at the diffuse term (no 0 * Inf), the others saturate finite
    assert np.isfinite(saturated.gpu).all() and saturated.gpu[1] == pytest.approx(saturated.expected[1], rel=1e-6)
    naive = {r.case: r for r in run_stability(backend=glphong_backend, formulation="naive", cases=[
        c for c in cases if "n=1e+06 near" in c.name or "saturating" in c.name]).rows}
    assert not any(r.passed for r in naive.values())  # pow(dot, 1e6): 1.7e-2 off near the peak; 2^1e6 = Inf
