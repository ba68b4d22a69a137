"""The error band of single functions: the constants and the band of a cosine-power lobe
(docs/design.md section 4).

A GPU value agrees with the float64 twin when it lies in an interval built from eps = 2^-24 and the
constants `BAND` (A, B, C, D, T), which held on a 101k-pixel stress set (q up to 1e7, grazing lights,
d in [1e-3, 1e3]) on llvmpipe.  They live here and nowhere else; the band of a whole image is
`glphong.checks.tolerances`.
"""
from dataclasses import dataclass

import numpy as np

from glphong.twin import functions as ref

__all__ = ["EPS", "FLT_MIN", "FLT_MAX", "BandConstants", "BAND", "lobe_band"]

EPS = 2.0 ** -24
FLT_MIN = float(np.finfo(np.float32).tiny)
FLT_MAX = float(np.finfo(np.float32).max)


@dataclass(frozen=True)
class BandConstants:
    """Multipliers of eps in the band (docs/design.md section 4).

    Attributes
    ----------
    A : float
        Relative error of products, quotients and sums of a term.
    B : float
        Relative error of the lobe per unit of ``lambda = -ln(lobe)`` (exp's ``2|x|`` ulp).
    C : float
        Error of the unit vectors' chord ``c = |r - v|`` (or ``|h - n|``): ``C eps (1 + c)``, an absolute part from the
        vectors and one relative to the chord from forming it (`lobe_band`).
    D : float
        Absolute error of ``n.l`` and ``n.v``.
    T : float
        Error of a filtered texture value as a fraction of the spread of the texels it weights
        (`glphong.definitions.surface.surface_texture_band`).  GL does not bound filter-weight precision;
        2^-7 covers 8-bit weights (Direct3D's minimum).  llvmpipe measured 5.6e-5 (256x256 renders of
        64- and 1024-texel textures, float16 and float32 texels, trilinear, lod 0 to 8); the test
        (tests/test_surface_inputs.py) holds it below 2^-12 beyond 16 ulps of the texels' magnitude.
    """

    A: float = 16.0
    B: float = 4.0
    C: float = 6.0
    D: float = 8.0
    T: float = 2.0 ** -7


BAND = BandConstants()


def lobe_band(delta, q, chord_scale=1.0, band=BAND):
    """Interval of float32 lobe values consistent with a float64 ``delta``.

    Parameters
    ----------
    delta : (...) float64 ndarray
        Distance from the lobe peak, ``1 - cos``.
    q : float
        Exponent.
    chord_scale : float or (...) ndarray
        Factor on the chord widening ``C eps (1 + c)`` (the Blinn half-vector conditioning).
    band : BandConstants

    Returns
    -------
    low, high : (...) float64 ndarray
    """
    delta = np.asarray(delta, dtype=np.float64)
    chord = np.sqrt(2.0 * np.maximum(delta, 0.0))
    # C eps absolute from the vectors' own errors, and as much again per unit of chord from forming it (e = r - v
    # and 0.5 e.e round relative to |e|): measured 7.8 eps at c = 1.38 (v.r = 0.048, q = 3.16), beyond a flat 6
    width = band.C * EPS * chord_scale * (1.0 + chord)
    high = ref.lobe_from_delta(0.5 * np.maximum(chord - width, 0.0) ** 2, q)
    low = ref.lobe_from_delta(0.5 * (chord + width) ** 2, q)

    def widen(value, sign):
        with np.errstate(divide="ignore"):
            lam = -np.log(np.maximum(value, np.finfo(np.float64).tiny))
        return value * (1.0 + sign * EPS * (band.A + band.B * lam))

    low = widen(low, -1.0)
    return np.where(low < FLT_MIN, 0.0, low), widen(high, +1.0)
