"""Conformance: every built-in reflectance model passes the same checks, the way pbrt-v4 and Mitsuba test
every BSDF.

The tests are parametrised over the registry (`glphong.materials.registered_models`, the models glphong
itself defines; ids are the model names), so a model added to ``glphong/materials`` gets every check
below by being defined.  The per-model modules in ``tests/materials`` keep what is specific to their
model: closed forms, limits, albedos by quadrature, tight reciprocity figures, renders, the literal
declaration.

Parameter sets
--------------
`EXAMPLES` holds each model's parameter sets (grazing, high-exponent, zero-channel, tilted-frame,
Fresnel and form variants, the model in its sum), each with the figures its twin check asserts (the
bounds stand over figures measured on Mesa llvmpipe, the same through EGL and OSMesa).  A model
without an entry is tested at ``Model.example()``: its parameters' defaults (or a value inside their
range), or what its definition returns as its example; a model that cannot be built that way fails
every check here, with a message saying what to add.

What is checked, for every model
--------------------------------
- twin agreement (`test_twin_matches`, GPU, both backends through ``glphong_backend``): for every
  parameter set, `glphong.testing.assert_twin_matches` (seeded random and edge direction sets: no pair
  outside the tolerance band, never NaN, exactly 0 below the surface) and its figures: the number of
  pairs; ``max_relative_error`` under the set's bound where it gives one; a response that is not
  identically 0 (more non-zero pairs than the set's floor), or, for a set that vanishes, none and
  error 0; then the GPU response itself: finite, non-negative where the model declares it, exactly 0
  in the set's zero channels, and, where the set gives a bound, close to the twin wherever the twin
  is at least 2^-100 (away from float32 underflow, and from pairs that both graze below 1e-19);
- the definition (`test_definition`, no GPU): registered and exported under its name; the GLSL defines
  ``<name>_response`` with the signature; uniform names ``u_<model>_<param>``, their GLSL types and
  declarations; for each parameter set: one term, immutable, round-tripping through
  `parameter_values`; a missing required parameter is a TypeError naming it; NaN, Inf, a bad channel
  and values outside the range are a ValueError naming the parameter (and the range, where both ends
  are finite); a scalar broadcasts to rgb; each choice value is its index in the structural defines
  and the program; a bad choice is refused; the Fresnel slot (Schlick and dielectric defines and
  uniforms, none without a factor, a number refused) or its absence; exactly the ``vanishes_with``
  parameters at 0 make the term vanish (out of every key, no lights compiled, no uniforms, a response
  exactly 0), a zero channel or another parameter at 0 does not; the ambient answer (``ambient_scale
  k L_a``, reading only ``k``) or none; the lit program key: needs as the key's view, tangent (and its
  attribute) and uv, the library chunks, the uniforms bound (float32, rgb (3,), scalar ()) and
  declared, the response called (``wo`` only where the view is needed);
- declared properties (`test_declared_properties`, the float64 twin through `glphong.analysis.f_r`, no
  GPU): every property a model declares True holds at every parameter set inside its stated condition
  (`Example.outside` names the sets outside it): non-negative (to 1e-9 of the largest ``f_r``),
  reciprocal (``f_r(l, v) = f_r(v, l)`` where both cosines are at least 1e-3, to 1e-4), isotropic (the
  tangent frame turned about n by 0.3, 1.1, 2.5 and 4 rad, the directions by quarter turns, to 1e-9);
  energy conservation as a directional albedo at most 1 (at 0 and 85 degrees, within the quadrature's
  error estimate, `glphong.analysis.albedo`) at the model's first set inside the condition.  A property declared False must be shown by at least one set: otherwise the declaration,
  or the table, is wrong (energy conservation declared False shows at grazing incidence for extreme
  parameters: the per-model albedo tests measure it);
- stability (`test_stability_cases`, both backends through ``session_gl``): the model's own
  `stability_cases` (at least the generic geometry, unique names, each case's material holding the
  model) all pass against the mpmath oracle, with no NaN and no Inf;
- the built-in sums (`test_sums`, ids are the sums' names), built from each parameter set of each term
  (the others at their first): the arguments are the terms', in order; derived properties follow the
  terms'; the components are the terms, with their parameters and ``two_sided``; the key holds every
  term and binds their uniforms; only the terms that answer ``L_a`` answer it; the GPU response is the
  sum of the terms' (one float32 addition); a bad value is refused through the sum; a vanishing term
  leaves the key with what the others need (view, tangent, library chunks, uniforms) and nothing of its
  own.

The reciprocity verdict allows 1e-4 of the largest ``f_r``: the twin sees the float32-rounded unit
vectors `glphong.testing.evaluate` gives both sides, which are not exactly unit, so a half vector's
cosines with l and with v differ by about eps/|l + v| (a Fresnel factor of h.l at l, v grazing and
opposite: 4e-5), and Lafortune's chord form is accurate to 1.7e-8 in float64; a violated reciprocity
shows at 0.5 and more (Fresnel of n.l; the lecture's Phong: 2.2).
"""
import functools
import re
from dataclasses import dataclass

import numpy as np
import pytest

import glphong
import glphong.materials
from glphong import analysis
from glphong.shaders.key import program_key, response_key
from glphong.materials import (AshikhminShirley, BlinnLobe, CookTorrance, CookTorranceLobe, DielectricFresnel, Diffuse,
                               GltfPBR, Lafortune, LafortuneLobes, Lambert, MaterialModel, MaterialSum, MeasuredBRDF, MtlPhong,
                               NormalizedBlinnLobe, NormalizedBlinnPhong, NormalizedPhong, NormalizedPhongLobe,
                               OrenNayar, PhongLobe, SchlickFresnel, WardLobe, registered_models)
from glphong.definitions.params import MATERIAL_KEYWORDS, NEEDS
from glphong.gpu.programs import assemble
from glphong.checks.stability import cases_for, run_stability
from glphong.testing import assert_twin_matches, direction_sets, evaluate

EPS = 2.0 ** -24
#: the labels of `direction_sets` where both directions graze below 1e-19: judged by the band alone
DOUBLY_GRAZING = "l and v grazing, (n.l)(n.v) below FLT_MIN"
TILTED = np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9])
#: a tangent of the tilted normal, and a raw tangent oblique to +z with a mirrored frame (w = -1)
TILTED_TANGENT = tuple(np.cross(TILTED, [0.0, 1.0, 0.0]) / np.linalg.norm(np.cross(TILTED, [0.0, 1.0, 0.0])))
OBLIQUE_MIRRORED = (0.3, 0.8, 0.5, -1.0)


@dataclass(frozen=True)
class Example:
    """One parameter set of a model and the figures its twin check asserts.

    Attributes
    ----------
    label : str
    make : callable
        Makes the material (a term of the model, alone or in one of its sums); called once.
    max_error : float or None
        ``max_relative_error`` must be below it, or exactly 0 for a bound 0 (None: the band alone).
    n, seed : int
        Random pairs and seed of `direction_sets`.
    normal : tuple
    tangent : tuple or 'random'
        The raw tangent, or one random raw tangent (handedness +-1) per pair.
    nonzero : int
        ``nonzero`` must exceed it.
    clear_error : float or None
        Bound on the relative error where the twin is at least 2^-100, outside the doubly grazing set.
    zero_channels : tuple of int
        Channels the GPU returns exactly 0 at every pair.
    outside : tuple of str
        Declared properties whose stated condition this set lies outside of (not checked here).
    """

    label: str
    make: object
    max_error: float = None
    n: int = 1000
    seed: int = 0
    normal: tuple = (0.0, 0.0, 1.0)
    tangent: object = (1.0, 0.0, 0.0)
    nonzero: int = 0
    clear_error: float = None
    zero_channels: tuple = ()
    outside: tuple = ()

    @functools.cached_property
    def material(self):
        return self.make()


def _lecture_lobe(lobe):
    """The lecture's lobes (`PhongLobe`, `BlinnLobe`): q = 0 to 1e7, ks 1 or with a zero channel, and Fresnel.

    ``max_relative_error`` measured exactly 0 at q = 0 (the lobe is exactly 1); 2.07e-4 (Phong) and 7.2e-5
    (Blinn) at q = 1, where v.r (n.h) is small and 1 - delta loses digits; at most 3.5e-5 (Phong) and
    2.9e-5 (Blinn) for q >= 50.  Away from underflow at most 2.43e-5 and 2.29e-5 for q >= 50 (from exp's
    (3 + 2|x|) ulp with |x| <= 70 there).  With Fresnel factors at most 5.2e-5.
    """
    out = []
    for q in (0.0, 1.0, 50.0, 1e4, 1e7):
        for label, ks, zero in (("ks=1", 1.0, ()), ("ks-zero-channel", (0.5, 0.0, 0.2), (1,))):
            out.append(Example(f"q={q:g} {label}", functools.partial(lobe, ks, q), n=2000,
                               max_error=0.0 if q == 0 else 1e-3 if q == 1 else 1e-4,
                               clear_error=1e-3 if q <= 1 else 1e-4, zero_channels=zero))
    for fresnel in (SchlickFresnel((0.04, 0.5, 0.95)), DielectricFresnel(1.5), DielectricFresnel(0.8)):
        out.append(Example(f"q=40 {fresnel!r}", functools.partial(lobe, ks=0.8, q=40.0, fresnel=fresnel), seed=1,
                           nonzero=500, max_error=1e-4))
    return out


def _normalized(lobe, total, fresnel_breaks_reciprocity):
    """The normalised lobes for q = 0 to 1e7, each with no Fresnel factor, Schlick and dielectric, and the sums.

    ``max_relative_error`` measured at most 6.4e-7 at q = 0, 5.7e-4 (Phong) and 6.0e-6 (Blinn) at q = 1,
    3.8e-5 for q >= 50, 1.4e-5 for the sums.  A Fresnel factor of n.l (Phong's) breaks reciprocity, as
    the condition says.
    """
    out = []
    for q in (0.0, 1.0, 50.0, 1e4, 1e6, 1e7):
        bound = 1e-6 if q == 0 else 1e-3 if q == 1 else 1e-4
        for fresnel in (None, SchlickFresnel(0.04), DielectricFresnel(1.5)):
            rho_s = (0.5, 0.0, 0.2) if fresnel is None else 1.0
            outside = ("reciprocal",) if fresnel and fresnel_breaks_reciprocity else ()
            out.append(Example(f"q={q:g} {fresnel!r}", functools.partial(lobe, rho_s, q, fresnel), max_error=bound,
                               outside=outside))
    out += [Example("with the diffuse term, q=80", functools.partial(total, 0.2, (0.5, 0.0, 0.2), 80.0), seed=1,
                    max_error=1e-4),
            Example("with the diffuse term, q=1e6, Schlick 0.5",
                    functools.partial(total, (0.3, 0.1, 0.0), 0.7, 1e6, SchlickFresnel(0.5)), seed=1, max_error=1e-4),
            Example("the diffuse term alone", functools.partial(total, 0.2, 0.0, 50.0), n=200, max_error=1e-6)]
    return out


PHONG_C, OFF_C, ANISO_C = (-1.0, -1.0, 1.0), (-1.1, -1.1, 0.9), (-1.0, -0.8, 1.0)
FOUR_LOBES = [((0.8, 0.0, 0.4), -1.0, -1.0, 1.0, 100.0), (0.2, -1.05, -1.05, 0.95, 20.0), (0.1, 0.9, 0.9, 0.9, 5.0),
              ((0.0, 0.3, 0.6), -0.6, -0.9, 1.0, 2.0)]
#: name -> (lobes, bound on max_relative_error); measured 0, 3.3e-5, 5.5e-4 (n = 1, near x = 0), 3.3e-5, 1.8e-4,
#: 5.9e-5, 1.2e-7, 1.8e-5, 1.8e-6
LAFORTUNE_SETS = {
    "phong n=0": ([(1.0, *PHONG_C, 0.0)], 0.0),
    "phong n=0.5": ([(1.0, -1.0, -0.5, 0.7, 0.5)], 1e-4),
    "phong n=1": ([((0.7, 0.0, 0.3), *PHONG_C, 1.0)], 2e-3),
    "phong n=50": ([(1.0, *PHONG_C, 50.0)], 1e-4),
    "phong n=1e6": ([(1.0, *PHONG_C, 1e6)], 1e-3),
    "off-specular n=1e3": ([(1.0, *OFF_C, 1e3)], 2e-4),
    "retro n=1e6": ([(1.0, 1.0, 1.0, 1.0, 1e6)], 1e-6),
    "anisotropic n=1e4": ([(1.0, *ANISO_C, 1e4)], 1e-4),
    "saturating |C|=2 n=1e6": ([((1.0, 0.0, 0.5), 2.0, 2.0, 2.0, 1e6)], 1e-5),
}


def _lafortune():
    """The lobes of `LAFORTUNE_SETS`, four lobes alone and with the diffuse term (measured 4.7e-7 with it,
    6.5e-4 alone), the tilted mirrored frame (at most 2.1e-4), and every rho 0 (vanishes)."""
    out = [Example(name, functools.partial(LafortuneLobes, lobes), max_error=bound, nonzero=1000)
           for name, (lobes, bound) in LAFORTUNE_SETS.items()]
    four = functools.partial(Lafortune, 0.2, FOUR_LOBES)
    out.append(Example("four lobes with the diffuse term", four, max_error=1e-5, nonzero=1000))
    tilted = {name: functools.partial(LafortuneLobes, LAFORTUNE_SETS[name][0]) for name in ("phong n=1e6",
                                                                                           "off-specular n=1e3")}
    for name, make in (tilted | {"four lobes": four}).items():
        out.append(Example(f"{name}, tilted mirrored frame", make, seed=1, normal=tuple(TILTED),
                           tangent=TILTED_TANGENT + (-1.0,), nonzero=800, max_error=1e-3))
    out.append(Example("four lobes alone", functools.partial(LafortuneLobes, FOUR_LOBES), max_error=1e-3))
    out.append(Example("every rho 0", functools.partial(LafortuneLobes, [(0.0, *PHONG_C, 50.0),
                                                                         (0.0, 0.98, 0.98, 0.98, 5.0)]), n=200))
    return out


def _ashikhmin_shirley():
    """(rho_d, rho_s, nu, nv) with the tangent along x, oblique and mirrored, and random per pair; measured at
    most 2.5e-4 (e = 1e6), 1.0e-4 (e = 1e4), 1.6e-5 (e <= 100), 2.2e-7 (nu = nv = 0)."""
    sets = [((0.3, 0.05, 100.0, 10.0), 1e-4), ((0.0, 0.9, 1e6, 1e6), 1e-3), ((0.0, 0.9, 1e6, 0.0), 1e-3),
            ((0.0, 1.0, 0.0, 0.0), 1e-6), ((0.5, 0.0, 1.0, 1.0), 1e-4),
            (((1.0, 0.5, 0.0), (0.0, 0.5, 1.0), 10.0, 1e4), 1e-3), ((1.0, 1.0, 0.5, 3.0), 1e-4)]
    return [Example(f"nu={p[2]:g},nv={p[3]:g},rho_s={p[1]} tangent {label}", functools.partial(AshikhminShirley, *p),
                    tangent=tangent, nonzero=1900, max_error=bound)
            for p, bound in sets
            for label, tangent in (("x", (1.0, 0.0, 0.0)), ("oblique-mirrored", OBLIQUE_MIRRORED),
                                   ("random", "random"))]


def _cook_torrance():
    """m = 1e-3 to 10, both forms, the Fresnel choices (measured at most 2.6e-5), with the diffuse term
    (3.8e-5); F = 1 at both ends of the m range, both forms, seed 9 (finite and non-negative).  The 1982
    form is 4 times the microfacet one: outside the energy condition."""
    sets = [(0.3, "microfacet", SchlickFresnel(0.04))] + [(m, "microfacet", SchlickFresnel(0.04))
                                                          for m in (1e-3, 0.05, 1.0, 10.0)] + [
        (1e-3, "1982", SchlickFresnel(0.04)), (0.3, "1982", SchlickFresnel(0.04)), (0.3, "microfacet", None),
        (0.05, "microfacet", DielectricFresnel(1.5))]
    out = [Example(f"m={m:g} {form} {fresnel!r}", functools.partial(CookTorranceLobe, m, fresnel, form=form),
                   nonzero=400 if m <= 1e-3 else 700, max_error=1e-4,
                   outside=("energy_conserving",) if form == "1982" else ())
           for m, form, fresnel in sets]
    out.append(Example("with the diffuse term", functools.partial(CookTorrance, (0.5, 0.0, 0.2), 0.2), seed=1,
                       nonzero=1500, max_error=1e-4))
    out += [Example(f"m={m:g} {form} F=1", functools.partial(CookTorranceLobe, m, SchlickFresnel(1.0), form=form),
                    seed=9, outside=("energy_conserving",) if form == "1982" else ())
            for m in (1e-3, 10.0) for form in ("microfacet", "1982")]
    return out


def _oren_nayar():
    """sigma = 0 to pi/2, both forms.  Measured 1.35e-7 at sigma = 0 (Lambert's rounding); at most 3.4e-7
    qualitative and full at sigma = 0.3; 4.9e-5 / 4.1e-5 full at sigma = 1 / pi/2, where it crosses 0; with
    the tilted normal 2.4e-5 (n.l down to 3e-4 is a float32 dot product there).  The full form at sigma = 1
    and a small albedo goes negative: what ``non_negative=False`` declares."""
    rho = (0.8, 0.0, 0.3)
    out = []
    for form in ("full", "qualitative"):
        for sigma in (0.0, 0.3, 1.0, np.pi / 2):
            bound = 3 * EPS if sigma == 0 else 1e-6 if form == "qualitative" or sigma <= 0.3 else 2e-4
            out.append(Example(f"{form} sigma={sigma:.4g}", functools.partial(OrenNayar, rho, sigma, form=form),
                               max_error=bound, zero_channels=(1,)))
    out += [Example(f"{form} sigma=0.5 tilted normal", functools.partial(OrenNayar, rho, 0.5, form=form), seed=1,
                    normal=tuple(TILTED), max_error=1e-4) for form in ("full", "qualitative")]
    out.append(Example("full sigma=1 rho=0.1", functools.partial(OrenNayar, 0.1, 1.0)))
    return out


def _ward():
    """Each normalisation at four alpha pairs with the tangent along x (measured at most 2.9e-5) and oblique
    and mirrored (2.1e-4 at alpha = 1e-3: the float32 Gram-Schmidt of the frame)."""
    out = []
    for norm in ("walter", "duer", "bounded"):
        for alphas in ((0.3, 0.1), (1e-3, 1e-3), (1.0, 1.0), (1e-3, 1.0)):
            for label, tangent, bound in (("x", (1.0, 0.0, 0.0), 1e-4), ("oblique-mirrored", OBLIQUE_MIRRORED, 5e-4)):
                out.append(Example(f"{norm} alpha={alphas[0]:g},{alphas[1]:g} tangent {label}",
                                   functools.partial(WardLobe, (0.5, 0.0, 1.0), *alphas, normalization=norm),
                                   tangent=tangent, nonzero=450 if min(alphas) < 0.01 else 1500, max_error=bound,
                                   zero_channels=(1,)))
    return out


@functools.lru_cache(maxsize=None)
def _tabulated():
    """The MERL table of a normalised Blinn-Phong (`glphong.merl.tabulate`: varies along every axis, with
    unmeasured cells), 1.5 s to make."""
    from glphong import merl

    return merl.tabulate(NormalizedBlinnPhong(0.3, 0.5, 40.0))


def _measured(lookup):
    return MeasuredBRDF(_tabulated(), lookup)


#: model name -> its parameter sets; a model without an entry is tested at ``Model.example()``
EXAMPLES = {
    # Lambert measured 5.85e-8 (< eps: with normal +z, n.l is exact; kd (n.l) is one rounded product),
    # Diffuse 1.4e-7 (n.l exact, two rounded products and the float32 1/pi)
    "lambert": [Example("kd=0.3", functools.partial(Lambert, 0.3), n=2000, max_error=2 * EPS),
                Example("kd-zero-channel", functools.partial(Lambert, (0.1, 0.0, 0.25)), n=2000, max_error=2 * EPS,
                        zero_channels=(1,)),
                Example("kd=1e-3", functools.partial(Lambert, 1e-3), n=2000, max_error=2 * EPS)],
    "diffuse": [Example("rho=0.6", functools.partial(Diffuse, 0.6), n=2000, nonzero=1000,
                        max_error=4 * EPS),
                Example("zero-channel", functools.partial(Diffuse, (0.5, 0.0, 1.0)), n=2000,
                        nonzero=1000, max_error=4 * EPS, zero_channels=(1,))],
    "phong_lobe": _lecture_lobe(PhongLobe),
    "blinn_lobe": _lecture_lobe(BlinnLobe),
    "mtl_phong": [Example("Kd, Ks, Ns, Ka", functools.partial(MtlPhong, (0.3, 0.2, 0.1),
                                                               (0.5, 0.4, 0.3), 40.0, (0.05, 0.1, 0.2)),
                          n=2000, nonzero=3000, max_error=1e-4)],
    "normalized_phong_lobe": _normalized(NormalizedPhongLobe, NormalizedPhong, fresnel_breaks_reciprocity=True),
    "normalized_blinn_lobe": _normalized(NormalizedBlinnLobe, NormalizedBlinnPhong, fresnel_breaks_reciprocity=False),
    "cook_torrance_lobe": _cook_torrance(),
    "lafortune_lobes": _lafortune(),
    "oren_nayar": _oren_nayar(),
    # a white dielectric (whose Fresnel mix exceeds albedo 1 at oblique incidence: 1.29 at 85 deg, roughness 0.3), a
    # coloured metal, and a half-metallic rough mix; the band alone (the twin check's figures in test_gltf_pbr.py)
    "gltf_pbr": [Example("white dielectric roughness=0.3", functools.partial(GltfPBR, 1.0, 0.0, 0.3)),
                 Example("copper metal roughness=0.2", functools.partial(GltfPBR, (0.95, 0.64, 0.54), 1.0, 0.2)),
                 Example("half metal roughness=0.8", functools.partial(GltfPBR, (0.5, 0.1, 0.0), 0.5, 0.8), seed=1,
                         normal=tuple(TILTED)),
                 Example("emissive, occluded", functools.partial(GltfPBR, 0.7, 0.2, 0.5, (0.2, 0.1, 0.0), 0.4), seed=2)],
    "ward_lobe": _ward(),
    "ashikhmin_shirley": _ashikhmin_shirley(),
    # nearest: the same bin on both sides (measured 6e-8); trilinear: float32 weights of steep neighbouring
    # samples near the lobe's peak (measured 1.3e-4)
    "measured_brdf": [Example(f"tabulated, {lookup}", functools.partial(_measured, lookup), n=2000, nonzero=3000,
                              max_error=1e-6 if lookup == "nearest" else 1e-3)
                      for lookup in ("nearest", "trilinear")],
}

BUILTIN = tuple(model for model in registered_models() if model.__module__.startswith("glphong."))
SUMS = tuple(cls for cls in map(functools.partial(getattr, glphong.materials), glphong.materials.__all__)
             if isinstance(cls, type) and issubclass(cls, MaterialSum) and cls is not MaterialSum)


def examples(model):
    """The parameter sets of ``model``: its `EXAMPLES`, else one at ``model.example()``."""
    if model.name in EXAMPLES:
        return EXAMPLES[model.name]
    return [Example("example()", model.example)]


def _built(model, example):
    """The set's material; a model that cannot be built fails with what its author should add."""
    try:
        return example.material
    except (TypeError, ValueError) as exc:
        error = f"{type(exc).__name__}: {exc}"
    pytest.fail(f"{model.__qualname__} ({model.name!r}) cannot be built for its conformance checks ({error}).  Give "
                "every Param and Table a default (or define the classmethod example() returning a representative "
                f"instance), or add its parameter sets to EXAMPLES in {__file__}", pytrace=False)


def own_instances(model):
    """The materials of ``model``'s parameter sets that are instances of the model itself, with their sets."""
    out = []
    for example in examples(model):
        material = _built(model, example)
        if type(material) is model or (isinstance(material, MaterialModel) and material.name == model.name):
            out.append((example, material))
    if not out:
        out.append((Example("example()", model.example), _built(model, Example("example()", model.example))))
    return out


def _vanishes(material):
    return all(term.vanishes() for term in material.components)


def _values(material):
    return {k: v for k, v in material.parameter_values().items() if k not in MATERIAL_KEYWORDS}


def _tangent(example, count):
    if example.tangent != "random":
        return example.tangent
    rng = np.random.default_rng(7)
    return np.concatenate([rng.normal(size=(count, 3)), rng.choice([-1.0, 1.0], size=(count, 1))], axis=1)


# --------------------------------------------------------------------------- twin agreement
@pytest.mark.parametrize("model", BUILTIN, ids=[m.name for m in BUILTIN])
def test_twin_matches(model, glphong_backend):
    failures = []
    for example in examples(model):
        material = _built(model, example)
        try:
            _check_twin(model, example, material, glphong_backend)
        except AssertionError as exc:
            failures.append(f"[{example.label}] {material!r}:\n{exc}")
    assert not failures, f"{model.name}: {len(failures)} of {len(examples(model))} parameter sets fail\n" + \
        "\n".join(failures)


def _check_twin(model, example, material, backend):
    wi, wo, labels = direction_sets(example.n, example.seed)
    tangent = _tangent(example, len(wi))
    figures = assert_twin_matches(material, n=example.n, seed=example.seed, backend=backend, normal=example.normal,
                                  tangent=tangent)
    assert figures["pairs"] == len(wi), figures
    if _vanishes(material):
        assert figures["nonzero"] == 0 and figures["max_relative_error"] == 0.0, figures
        return
    assert figures["nonzero"] > example.nonzero, (
        f"the response is non-zero at {figures['nonzero']} pairs only (at least {example.nonzero + 1} wanted): a "
        f"parameter set must reflect light (define {model.__qualname__}.example() or add sets to EXAMPLES)")
    if example.max_error is not None:  # below the bound; exactly 0 where the bound is 0
        error = figures["max_relative_error"]
        assert error < example.max_error or error == example.max_error == 0.0, \
            f"max_relative_error {error:.3g} is not below {example.max_error:.3g}"
    gpu = evaluate(material, wi, wo, normal=example.normal, tangent=tangent, backend=backend).astype(np.float64)
    assert np.all(np.isfinite(gpu)), "the GPU response is not finite"
    if material.properties.non_negative and "non_negative" not in example.outside:
        assert np.all(gpu >= 0), f"a negative GPU response: {gpu.min():.3g}"
    for channel in example.zero_channels:
        assert np.all(gpu[:, channel] == 0), f"channel {channel} is not exactly 0"
    if example.clear_error is not None:
        twin = evaluate(material, wi, wo, normal=example.normal, tangent=tangent, twin=True)
        clear = (twin >= 2.0 ** -100) & (labels != DOUBLY_GRAZING)[:, None]
        rel = np.abs(gpu - twin)[clear] / twin[clear]
        assert rel.max() < example.clear_error, \
            f"relative error {rel.max():.3g} >= {example.clear_error:.3g} away from underflow"


# --------------------------------------------------------------------------- the definition
@pytest.mark.parametrize("model", BUILTIN, ids=[m.name for m in BUILTIN])
def test_definition(model):
    assert glphong.materials.model_named(model.name) is model
    assert getattr(glphong.materials, model.__name__, None) is model, \
        f"{model.__name__} is not exported by glphong.materials (list it in its module's __all__)"
    assert set(model.needs) <= set(NEEDS)
    source = model.source()
    assert re.search(rf"\bvec3\s+{model.name}_response\s*\(\s*ShadingFrame\s+\w+\s*,\s*vec3\s+\w+\s*,\s*vec3\s+\w+\s*,"
                     rf"\s*float\s+\w+\s*\)", source), f"{model.name}_response is not defined with the signature"
    assert re.fullmatch(r"[0-9a-f]{12}", model.source_hash())
    declarations = model.uniform_declarations()
    for p in model.uniform_params():
        assert model.uniform_name(p.name) == f"u_{model.name}_{p.name}"
        assert p.glsl_type == {"scalar": "float", "rgb": "vec3"}[p.kind]
        assert f"{p.glsl_type} u_{model.name}_{p.name};" in declarations, p.name
        if p in model.params:
            p.validate(p.example())
    for t in model.tables:
        assert f"uniform {t.glsl_type} u_{model.name}_{t.name};" in declarations, t.name
    for _, material in own_instances(model):
        if not material.vanishes():  # what vanishing means is checked on the others
            _check_instance(model, material)


def _check_instance(model, m):
    values = _values(m)
    assert m.components == (m,) and m.ka == (0.0, 0.0, 0.0) and m.two_sided is True
    again = type(m)(**values)
    assert again == m and hash(again) == hash(m), "an instance does not round-trip through parameter_values()"
    with pytest.raises(AttributeError, match="immutable"):
        setattr(m, next(iter(values)), None)
    # a missing required parameter names it; a bad value names the parameter (and its range, where finite)
    for p in model.tables + model.params:
        if p.default is None and p.name in values:
            with pytest.raises(TypeError, match=p.name):
                type(m)(**{k: v for k, v in values.items() if k != p.name})
    for p in model.params:
        if p.name not in values:
            continue
        bad = [np.nan, np.inf] + ([p.low - max(1.0, abs(p.low))] if np.isfinite(p.low) else []) + \
            ([p.high + max(1.0, abs(p.high))] if np.isfinite(p.high) else [])
        finite = np.isfinite(p.low) and np.isfinite(p.high)
        pattern = re.escape(p.name) + (r".*" + re.escape(p.interval) if finite else "")
        for value in bad:
            with pytest.raises(ValueError, match=pattern):
                type(m)(**(values | {p.name: value}))
        if p.kind == "rgb":  # one bad channel is enough; a scalar broadcasts to the three channels
            with pytest.raises(ValueError, match=re.escape(p.name)):
                type(m)(**(values | {p.name: (p.example()[0], np.nan, p.example()[2])}))
            assert getattr(type(m)(**(values | {p.name: p.example()[0]})), p.name) == (p.example()[0],) * 3
    _check_choices_and_fresnel(model, m, values)
    _check_vanishing_and_ambient(model, m, values)
    _check_key(model, m)


def _check_choices_and_fresnel(model, m, values):
    upper = model.name.upper()
    for choice in model.choices:
        for index, value in enumerate(choice.values):
            variant = type(m)(**(values | {choice.name: value}))
            assert (choice.name.upper(), str(index)) in variant.structural_defines()
            key = response_key(variant)
            assert (f"{upper}_{choice.name.upper()}", str(index)) in key.defines()
            assert f"#define {upper}_{choice.name.upper()} {index}" in assemble(key.fragment_chunks(), key.defines(),
                                                                                 key.generated_chunks())
        with pytest.raises(ValueError, match=re.escape(choice.name)):
            type(m)(**(values | {choice.name: "no such " + choice.name}))
    if model.fresnel_slot is None:
        with pytest.raises(TypeError, match="fresnel"):
            type(m)(**values, fresnel=SchlickFresnel(0.04))
        return
    with pytest.raises(TypeError, match="fresnel"):
        type(m)(**(values | {"fresnel": 0.04}))
    for fresnel, form, uniform, value in ((SchlickFresnel(0.3), "SCHLICK", "fresnel_f0", [0.3] * 3),
                                          (DielectricFresnel(1.33), "DIELECTRIC", "fresnel_ior", 1.33)):
        variant = type(m)(**(values | {"fresnel": fresnel}))
        key = response_key(variant)
        assert (f"{upper}_FRESNEL_{form}", "1") in key.defines()
        source = assemble(key.fragment_chunks(), key.defines(), key.generated_chunks())
        assert f"#define {upper}_FRESNEL_{form} 1" in source
        np.testing.assert_array_equal(variant.uniform_values(key)[model.uniform_name(uniform)], np.float32(value))
    plain = type(m)(**(values | {"fresnel": None}))
    key = response_key(plain)
    assert not any("FRESNEL" in name for name, _ in key.defines())
    assert not any("fresnel" in name for name in plain.uniform_values(key))


def _check_vanishing_and_ambient(model, m, values):
    assert not m.vanishes(), f"{m!r} vanishes: a parameter set must not (the checks would test nothing)"
    assert [t.name for t in response_key(m).terms] == [model.name]
    for p in model.params:
        if p.name not in values or not (p.low <= 0.0 <= p.high) or (p.low == 0.0 and not p.low_inclusive):
            continue
        zero = type(m)(**(values | {p.name: 0.0}))
        if p.name in model.vanishes_with:  # the term leaves every program, and its response is exactly 0
            assert zero.vanishes() and response_key(zero).terms == ()
            for key in (program_key(zero, {"point": 1}, (0.1, 0.1, 0.1)), program_key(zero, {"point": 1}, None)):
                assert key.terms == () and key.num_lights == 0 and zero.uniform_values(key) == {}
            figures = assert_twin_matches(zero, n=200)  # no term: neither side needs the GPU
            assert figures["nonzero"] == 0 and figures["max_relative_error"] == 0.0
            if p.kind == "rgb":  # a zero channel does not vanish
                assert not type(m)(**(values | {p.name: (0.5, 0.0, 0.5)})).vanishes()
        elif not zero.vanishes():
            assert [t.name for t in response_key(zero).terms] == [model.name]
    answers = model.ambient is not None and bool(np.any(getattr(m, model.ambient)))
    assert m.answers_ambient() == answers
    ambient = program_key(m, {}, (0.1, 0.1, 0.1))
    if answers:
        assert [(t.name, t.lit, t.ambient, t.ambient_param, t.ambient_scale) for t in ambient.terms] == [
            (model.name, False, True, model.ambient, model.ambient_scale)]
        occluded = {model.uniform_name(model.occluded_by)} if model.occluded_by else set()
        occluded |= {model.uniform_name(model.emission)} if m.emits() else set()
        assert m.uniform_values(ambient).keys() == {model.uniform_name(model.ambient)} | occluded
        assert ambient.terms[0].occlusion == model.occluded_by
    elif not m.emits():
        assert ambient.terms == ()
    # what a term emits: in every program where it is not zero (lights or none), nowhere where it is zero
    emits = model.emission is not None and bool(np.any(getattr(m, model.emission)))
    assert m.emits() == emits
    dark = program_key(m, {}, None)
    assert [t.emission for t in dark.terms] == ([model.emission] if emits else [])
    if emits:
        assert m.uniform_values(dark).keys() == {model.uniform_name(model.emission)}
    assert all(t.emission is None for t in response_key(m).terms)  # a response program emits nothing


def _check_key(model, m):
    key = program_key(m, {"point": 1}, None)
    assert [t.name for t in key.terms] == [model.name] and key.terms[0].lit
    assert key.needs_view == ("view" in model.needs)
    assert key.has_tangent == ("tangent" in model.needs) and key.has_uv == ("uv" in model.needs)
    assert ("in_tangent" in key.attributes()) == ("tangent" in model.needs)
    assert set(key.library_chunks()) == set(m.library_uses()) >= set(model.uses)
    uniforms = m.uniform_values(key)
    # the emission and the occlusion are read by generated code, only where the key has them
    generated = {model.emission if not key.terms[0].emission else None, model.occluded_by} - {None}
    read = [p for p in m.active_params() if p.name not in generated]
    assert uniforms.keys() == {model.uniform_name(p.name) for p in read} | \
        {model.uniform_name(t.name) for t in model.tables}
    for p in read:
        value = uniforms[model.uniform_name(p.name)]
        assert value.dtype == np.float32 and value.shape == ((3,) if p.kind == "rgb" else ())
        if not p.name.startswith("fresnel_"):
            np.testing.assert_array_equal(value, np.float32(getattr(m, p.name)))
    source = assemble(key.fragment_chunks(), key.defines(), key.generated_chunks())
    for p in model.uniform_params():
        assert f"uniform {p.glsl_type} {model.uniform_name(p.name)};" in source, p.name
    view = "wo" if "view" in model.needs else "vec3(0.0)"  # a model that does not need the view is not given it
    assert f"response += {model.name}_response(f, wi, {view}, n_dot_l);" in source


# --------------------------------------------------------------------------- declared properties
#: verdict tolerances, relative to the largest f_r: rounding passes, a violation does not
TOLERANCE = {"non_negative": 1e-9, "reciprocal": 1e-4, "isotropic": 1e-9}
#: incident angles of the energy check: normal and grazing incidence
ALBEDO_ANGLES = np.radians([0.0, 85.0])


@functools.lru_cache(maxsize=1)
def _property_pairs():
    """Fibonacci pairs over the upper hemispheres and `direction_sets`' upper pairs, as float32 units."""
    from glphong.testing import float32_units

    d = analysis.hemisphere_directions(24)
    i, j = np.meshgrid(np.arange(len(d)), np.arange(len(d)), indexing="ij")
    ewi, ewo, _ = direction_sets(300, 5)
    up = (ewi[:, 2] > 0) & (ewo[:, 2] > 0)
    wi, wo = np.concatenate([d[i.ravel()], ewi[up]]), np.concatenate([d[j.ravel()], ewo[up]])
    return float32_units(wi), float32_units(wo)


def measured_properties(material):
    """``{property: (holds, error, where)}`` of the twin for non_negative, reciprocal, isotropic."""
    wi, wo = _property_pairs()
    value = analysis.f_r(material, wi, wo)
    ok = (wi[:, 2] >= 1e-3) & (wo[:, 2] >= 1e-3)
    scale = float(np.max(np.abs(value[ok]))) or 1.0
    out = {}
    k = int(np.argmin(value.min(axis=1)))
    low = float(value[k].min() / scale)
    out["non_negative"] = (low >= -TOLERANCE["non_negative"], low, (wi[k], wo[k]))
    diff = np.max(np.abs(analysis.f_r(material, wo[ok], wi[ok]) - value[ok]), axis=1) / scale
    r = int(np.argmax(diff))
    out["reciprocal"] = (diff[r] <= TOLERANCE["reciprocal"], float(diff[r]), (wi[ok][r], wo[ok][r]))
    worst = (0.0, None)
    for angle in (0.3, 1.1, 2.5, 4.0):
        turned = analysis.f_r(material, wi[ok], wo[ok], tangent=(np.cos(angle), -np.sin(angle), 0.0))
        d = np.max(np.abs(turned - value[ok]), axis=1) / scale
        j = int(np.argmax(d))
        worst = max(worst, (float(d[j]), (wi[ok][j], wo[ok][j], f"tangent turned {angle} rad")), key=lambda w: w[0])
    for quarter in (1, 2, 3):
        def rot(x, q=quarter):
            for _ in range(q):
                x = np.stack([-x[:, 1], x[:, 0], x[:, 2]], axis=1)
            return x

        d = np.max(np.abs(analysis.f_r(material, rot(wi[ok]), rot(wo[ok])) - value[ok]), axis=1) / scale
        j = int(np.argmax(d))
        worst = max(worst, (float(d[j]), (wi[ok][j], wo[ok][j], f"{quarter} quarter turns")), key=lambda w: w[0])
    out["isotropic"] = (worst[0] <= TOLERANCE["isotropic"], worst[0], worst[1])
    return out


@pytest.mark.parametrize("model", BUILTIN, ids=[m.name for m in BUILTIN])
def test_declared_properties(model):
    declared = model.properties
    shown = {name: [] for name in ("non_negative", "reciprocal", "isotropic")}
    broken = []
    measured = {}  # by material: sets that differ only in the frame they are evaluated in are measured once
    for example, material in own_instances(model):
        if material.vanishes():
            continue
        if material not in measured:
            measured[material] = measured_properties(material)
        for name, (holds, error, where) in measured[material].items():
            if not holds:
                shown[name].append(example.label)
            if getattr(declared, name) and not holds and name not in example.outside:
                broken.append(f"{name} declared, but [{example.label}] {material!r} is off by {error:.3g} of the "
                              f"largest f_r at {where}")
    for name, labels in shown.items():
        if getattr(declared, name) is False and not labels:
            broken.append(f"{name}=False is declared, but no parameter set shows it: add one to EXAMPLES that does, "
                          "or declare None (not known)")
    if declared.energy_conserving:
        example, material = next((e, m) for e, m in own_instances(model) if "energy_conserving" not in e.outside)
        albedo, error = analysis.albedo(material, ALBEDO_ANGLES, nodes=2, return_error=True)
        if np.max(albedo) > 1 + max(np.max(error), 1e-9):
            broken.append(f"energy_conserving declared, but [{example.label}] {material!r} reflects "
                          f"{np.max(albedo, axis=-1)} at {np.degrees(ALBEDO_ANGLES)} degrees")
    assert not broken, f"{model.name} ({declared}):\n" + "\n".join(broken)


# --------------------------------------------------------------------------- stability
@pytest.mark.parametrize("model", BUILTIN, ids=[m.name for m in BUILTIN])
def test_stability_cases(model, session_gl):
    cases = cases_for(model)
    assert len(cases) >= 9, "stability_cases() must hold at least the generic geometry (stability.generic_cases)"
    assert len({c.name for c in cases}) == len(cases), "case names must be unique"
    for case in cases:
        assert model.name in [t.name for t in case.material.components], f"{case.name}: {case.material!r}"
    report = run_stability(context=session_gl, cases=cases)
    assert report.passed_count == len(cases), report.format_table()
    assert report.nan_count == 0 and report.inf_count == 0, report.format_table()


# --------------------------------------------------------------------------- the built-in sums
def _sum_instances(total):
    """``total`` built from each parameter set of each of its terms (the other terms at their first set)."""
    firsts = {term: own_instances(term)[0][1] for term in total.terms}
    out = []
    for term in total.terms:
        for example, material in own_instances(term):
            if material.vanishes():
                continue
            parts = {t: (material if t is term else firsts[t]) for t in total.terms}
            values = {}
            for part in parts.values():
                values.update(_values(part))
            out.append((f"{term.name}: {example.label}", parts, total(**values)))
    return out


@pytest.mark.parametrize("total", SUMS, ids=[s.name for s in SUMS])
def test_sums(total, glphong_backend):
    names = [a.name for t in total.terms for a in t.arguments() if a.name != "fresnel"]
    assert [a.name for a in total.arguments() if a.name != "fresnel"] == names
    if "properties" not in total.__dict__:  # derived: a property holds when every term declares it
        for name in ("reciprocal", "isotropic", "non_negative"):
            said = [getattr(t.properties, name) for t in total.terms]
            assert getattr(total.properties, name) == (None if None in said else all(said)), name
        assert total.properties.energy_conserving is None
    wi, wo, _ = direction_sets(200, 2)
    for label, parts, material in _sum_instances(total):
        assert [type(c) for c in material.components] == list(total.terms), label
        for component, part in zip(material.components, parts.values()):
            assert _values(component) == _values(part), label
        assert not any(c.two_sided for c in total(**_values(material), two_sided=False).components)
        key = program_key(material, {"point": 1}, None)
        assert [t.name for t in key.terms] == [t.name for t in total.terms]
        assert material.uniform_values(key).keys() == {c.uniform_name(p.name) for c in material.components
                                                       for p in c.active_params()} | \
            {c.uniform_name(t.name) for c in material.components for t in c.tables}
        ambient = program_key(material, {}, (0.1, 0.1, 0.1))
        assert [t.name for t in ambient.terms] == [c.name for c in material.components if c.answers_ambient()]
        gpu = evaluate(material, wi, wo, backend=glphong_backend).astype(np.float64)
        separate = sum(evaluate(part, wi, wo, backend=glphong_backend).astype(np.float64) for part in parts.values())
        np.testing.assert_allclose(gpu, separate, rtol=2 * EPS, atol=0, err_msg=label)  # one float32 addition
    # a bad value is refused through the sum, naming the parameter
    _, parts, material = _sum_instances(total)[0]
    for name, value in _values(material).items():
        if name in names and isinstance(value, (float, tuple)):
            with pytest.raises(ValueError, match=re.escape(name)):
                total(**(_values(material) | {name: np.nan}))
    if any(t.fresnel_slot is not None for t in total.terms):
        with pytest.raises(TypeError, match="fresnel"):
            total(**(_values(material) | {"fresnel": 0.04}))
    # a vanishing term leaves the key with what the others need
    for term in total.terms:
        if not term.vanishes_with:
            continue
        values = _values(material) | {name: 0.0 for name in term.vanishes_with}
        key = program_key(total(**values), {"point": 1}, None)
        others = [t for t in total.terms if t is not term]
        assert [t.name for t in key.terms] == [t.name for t in others]
        assert key.needs_view == any("view" in t.needs for t in others)
        assert key.has_tangent == any("tangent" in t.needs for t in others)
        assert set(key.library_chunks()) >= {u for t in others for u in t.uses}
        assert not set(key.library_chunks()) & (set(term.uses) - {u for t in others for u in t.uses})
        source = assemble(key.fragment_chunks(), key.defines(), key.generated_chunks())
        assert f"{term.name}_response(" not in source and f"u_{term.name}_" not in source
        left = [c for c in total(**values).components if type(c) is not term]
        assert total(**values).uniform_values(key).keys() == {c.uniform_name(p.name) for c in left
                                                              for p in c.active_params()}
