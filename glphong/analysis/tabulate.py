"""Analytic materials tabulated in the MERL layout (`glphong.core.merl`), for measured-BRDF tests."""
import numpy as np

from glphong.analysis.questions import f_r
from glphong.core.merl import SHAPE, bin_directions
from glphong.materials.measured import register_tabulator

__all__ = ["tabulate"]


def tabulate(material, chunk=200_000):
    """A MERL table of ``material``'s ``f_r`` (its float64 twin) at `bin_directions`; NaN where the light or
    the view is below the surface (MERL's unmeasured cells).

    Returns
    -------
    (90, 90, 180, 3) float64 ndarray
    """

    wi, wo = bin_directions()
    wi, wo = wi.reshape(-1, 3), wo.reshape(-1, 3)
    out = np.full(wi.shape, np.nan)
    above = (wi[:, 2] > 1e-6) & (wo[:, 2] > 1e-6)
    idx = np.flatnonzero(above)
    for start in range(0, len(idx), chunk):
        rows = idx[start:start + chunk]
        out[rows] = f_r(material, wi[rows], wo[rows])
    return out.reshape(SHAPE + (3,))


register_tabulator(tabulate)  # MeasuredBRDF.from_model tabulates through here
