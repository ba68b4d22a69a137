"""KHR_materials_iridescence's closed form against a float64 spectral integral (docs/gltf_extensions.md).

The README's ``F_iridescence`` (glphong's twin, `glphong.materials.gltf_iridescence.gltf_iridescence_fresnel`) is
``C0 + sum_{m=1,2} C_m 2 S(m OPD, m phi)``, ``S`` a fit by Gaussians of the CIE 1931 sensitivities' Fourier transforms
(its ``evalSensitivity``), in linear Rec. 709 through the README's ``XYZ_TO_REC709``.  The same quantity without the
approximations:

- ``S_exact(OPD, phi) = XYZ_TO_REC709 int cos(2 pi OPD / lambda + phi) cmf(lambda) dlambda / int y(lambda) dlambda``, the
  CIE 1931 2-degree colour matching functions (benchmarks/data/cie1931_xyz_5nm.csv, 360-830 nm, interpolated by a
  cubic spline to 0.05 nm, trapezoid rule); ``fit``: the README's sum to m = 2 with ``S_exact`` (the fit's error alone);
- ``spectral_fresnel``: the Airy sum to every order, ``C0 + XYZ_TO_REC709 int 2 sum_{m>=1} C_m cos(m (2 pi OPD/lambda +
  phi)) cmf / int y``, the series summed in closed form ``sum_{m>=1} r^m cos(m t) = (r cos t - r^2)/(1 - 2 r cos t +
  r^2)`` (the fit's and the truncation's error together: what the README's closed form is measured against).

The DC term ``C0`` is taken as the README takes it (white, not ``XYZ_TO_REC709`` of the equal-energy white); the phase
``phi`` is per channel in the README (a grey base's three are equal: only grey bases are measured here).
Run: ``python benchmarks/gltf_iridescence_spectral.py`` (a few seconds); prints the table docs/gltf_extensions.md
quotes.
"""
import pathlib

import numpy as np

from glphong.materials.gltf_iridescence import XYZ_TO_REC709, gltf_iridescence_fresnel

#: the largest error of the README's closed form against `spectral_fresnel` that docs/gltf_extensions.md states for
#: thickness 100 to 800 nm, film ior 1.3, base f0 0.04 (the test's bound)
STATED_ERROR = 0.01
_DATA = pathlib.Path(__file__).with_name("data") / "cie1931_xyz_5nm.csv"


def _cmfs(step=0.05):
    """``(lambda [nm], cmf (K, 3))`` on a fine grid: the CIE table by a cubic spline."""
    from scipy.interpolate import CubicSpline

    table = np.loadtxt(_DATA, delimiter=",", comments="#", skiprows=5)
    wavelengths = np.arange(table[0, 0], table[-1, 0] + step / 2, step)
    return wavelengths, np.clip(CubicSpline(table[:, 0], table[:, 1:])(wavelengths), 0.0, None)


_GRID = None


def _grid():
    global _GRID
    if _GRID is None:
        wavelengths, cmf = _cmfs()
        weights = np.full(len(wavelengths), wavelengths[1] - wavelengths[0])
        weights[[0, -1]] *= 0.5  # the trapezoid rule
        _GRID = wavelengths, cmf * (weights / np.sum(cmf[:, 1] * weights))[:, None]  # normalised: int y = 1
    return _GRID


def _terms(outside_ior, film_ior, base_f0, thickness, cos_theta1):
    """The README's interface terms in float64: ``(C0, Cm1 = Rs - T121, r = sqrt(R123), OPD, phi)``, each (N, 3) but
    OPD (N,)."""
    cos_theta1 = np.asarray(cos_theta1, np.float64)
    cos2 = np.sqrt(1 - (outside_ior / film_ior) ** 2 * (1 - cos_theta1 ** 2))
    r12 = (((film_ior - outside_ior) / (film_ior + outside_ior)) ** 2
           + (1 - ((film_ior - outside_ior) / (film_ior + outside_ior)) ** 2) * (1 - cos_theta1) ** 5)[:, None]
    t121 = 1 - r12
    s = np.sqrt(np.minimum(np.asarray(base_f0, np.float64) + 1e-4, 0.9999))
    base_ior = (1 + s) / (1 - s)
    r1 = ((base_ior - film_ior) / (base_ior + film_ior)) ** 2
    r23 = r1 + (1 - r1) * ((1 - cos2) ** 5)[:, None]
    phi = (np.pi - (np.pi if film_ior < outside_ior else 0.0)) + np.where(base_ior < film_ior, np.pi, 0.0)
    r123 = np.clip(r12 * r23, 1e-5, 0.9999)
    rs = t121 ** 2 * r23 / (1 - r123)
    return r12 + rs, rs - t121, np.sqrt(r123), 2 * film_ior * thickness * cos2, np.broadcast_to(phi, rs.shape)


def _to_rgb(xyz_per_channel):
    """(N, 3 channels, 3 xyz) -> (N, 3): channel k's own component of XYZ_TO_REC709 xyz_k."""
    return np.einsum("kj,nkj->nk", XYZ_TO_REC709, xyz_per_channel)


def spectral_fresnel(outside_ior, film_ior, base_f0, thickness, cos_theta1):
    """The Airy sum to every order, integrated over the spectrum in float64 (module docstring); (N, 3)."""
    wavelengths, cmf = _grid()
    c0, cm1, r, opd, phi = _terms(outside_ior, film_ior, base_f0, thickness, cos_theta1)
    t = 2 * np.pi * opd[:, None, None] / wavelengths[None, None, :] + phi[:, :, None]  # (N, 3, K)
    rr = r[:, :, None]
    series = (rr * np.cos(t) - rr * rr) / (1 - 2 * rr * np.cos(t) + rr * rr)  # sum_{m>=1} r^m cos(m t)
    xyz = np.einsum("nkl,lj->nkj", 2 * cm1[:, :, None] * series, cmf)
    return np.maximum(c0 + _to_rgb(xyz), 0.0)


def fit_alone(outside_ior, film_ior, base_f0, thickness, cos_theta1):
    """The README's sum to m = 2 with the exact sensitivity integral (the Gaussian fit's error alone); (N, 3)."""
    wavelengths, cmf = _grid()
    c0, cm1, r, opd, phi = _terms(outside_ior, film_ior, base_f0, thickness, cos_theta1)
    out = c0.copy()
    for m in (1, 2):
        t = m * (2 * np.pi * opd[:, None, None] / wavelengths[None, None, :] + phi[:, :, None])
        out += _to_rgb(np.einsum("nkl,lj->nkj", 2 * (cm1 * r ** m)[:, :, None] * np.cos(t), cmf))
    return np.maximum(out, 0.0)


def main():
    cos = np.linspace(0.02, 1.0, 50)
    near = cos >= 0.5  # within 60 degrees of the half vector's normal incidence
    print("film ior  base f0  thickness [nm]  |closed - spectral| max  (fit alone)  |closed| max  "
          "| at cos >= 0.5: error max, spectral value max")
    for film_ior, f0 in ((1.3, 0.04), (1.3, 0.5), (1.8, 0.04), (2.5, 0.04), (1.3, 0.9)):
        for thickness in (0.0, 50.0, 100.0, 250.0, 400.0, 800.0, 1200.0):
            base = np.full((len(cos), 3), f0)
            closed = gltf_iridescence_fresnel(1.0, film_ior, base, thickness, cos)
            exact = spectral_fresnel(1.0, film_ior, base[0], thickness, cos)
            fit = fit_alone(1.0, film_ior, base[0], thickness, cos)
            print(f"{film_ior:8.2f} {f0:8.2f} {thickness:15.0f} {np.abs(closed - exact).max():24.4f} "
                  f"{np.abs(closed - fit).max():12.4f} {np.abs(closed).max():12.3f} "
                  f"| {np.abs(closed - exact)[near].max():8.4f} {exact[near].max():8.4f}")


if __name__ == "__main__":
    main()
