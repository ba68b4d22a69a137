r"""The measured BRDF: a table in the MERL layout, sampled from a 3D texture (issue 13; docs/design.md section 9).

Matusik, Pfister, Brand and McMillan 2003, "A data-driven reflectance model" (SIGGRAPH 2003), measured
100 isotropic materials and published each as a table of ``f_r`` over Rusinkiewicz's (1998) half and
difference angles (`glphong.merl` reads and writes the format).  ``MeasuredBRDF(path)`` renders one:

.. math::

    f_r(\omega_i, \omega_o) = T[i_h, i_d, i_p] \quad [1/\mathrm{sr}],\ \mathrm{rgb}

with the bin of ``theta_h = angle(n, h)``, ``theta_d = angle(h, l)`` and ``phi_d`` (the azimuth of l
about h, folded into [0, pi] by reciprocity), indexed as the reference reader does: ``x_h = 90
sqrt(theta_h / (pi/2))``, ``x_d = 90 theta_d / (pi/2)``, ``x_p = 180 phi_d / pi`` and the bin
``floor(x)``, clamped (``lookup="nearest"``, the default), or trilinear between the samples at
``x_h = i``, ``x_d = j + 1/2``, ``x_p = k + 1/2`` (``lookup="trilinear"``; periodic in ``phi_d``),
which is where `glphong.merl.tabulate` evaluates a model, so a tabulated model is reproduced exactly
at the samples and to second order between them.

=========  =====================  ==============================================================
argument   kind                   meaning
=========  =====================  ==============================================================
table      path, array or         a MERL ``.binary`` file, or ``f_r`` [1/sr] of shape (90, 90, 180, 3);
           TableData              read as float32; unmeasured cells (the file's negative markers,
                                  NaN in an array) become 0 and are counted in ``unmeasured``
lookup     'nearest' (0) or       the reference reader's bin, or trilinear between samples
           'trilinear' (1)
=========  =====================  ==============================================================

The table is a `glphong.materials.Table`: a float32 3D texture (17.5 MB) uploaded the first time a
drawn object's program reads it, once per content per context; the twin reads the same float32
values and makes exactly the GPU's lookup (``measured_brdf_coordinates``, ``measured_brdf_nearest``,
``measured_brdf_trilinear``).  Its band (`MeasuredBRDF.band`) is the range of the lookup over the
bin coordinates the GPU may compute (every angle within a few float32 ulp, the azimuth within
``ulp / sin(theta_h)`` and ``ulp / sin(theta_d)``), so a pixel on a bin boundary may take either bin.

Declared properties: reciprocal and isotropic by construction of the coordinates (swapping l and v
moves ``phi_d`` by pi, which the fold removes; ``phi_h`` is not a coordinate), non-negative (entries
>= 0); energy conservation depends on the data (`glphong.analysis.properties` measures it).

Where implementations differ: the reference reader (``BRDFRead.cpp``) converts with ``acos`` and
``atan2`` and keeps the unmeasured markers (negative values); renderers clamp them to 0, as glphong
does.  Some trilinear readers (and GPU hardware filtering, with 8-bit weights) place the samples at
the bins' lower corners in all three axes; glphong's samples are where `glphong.merl.tabulate` puts
them, and its weights are float32.
"""
import os
from pathlib import Path

import numpy as np

from glphong.core import merl
from glphong.twin.functions import atan2_first_quadrant, dot as _dot, frame_from_tangent, safe_normalize
from glphong.definitions.material import Choice, GlslFile, MaterialModel, Properties
from glphong.definitions.table import Table, TableData
from glphong.definitions.cases import Case, _mirror_eye, _unit, generic_cases
from glphong.twin.band import EPS

__all__ = ["MeasuredBRDF", "measured_brdf_coordinates", "measured_brdf_fetch", "measured_brdf_nearest",
           "measured_brdf_trilinear"]

#: the last bin of each axis (measured_brdf.glsl MEASURED_BRDF_LAST)
LAST = np.array(merl.SHAPE) - 1
_DEG = 180.0 / np.pi


def measured_brdf_coordinates(n, wi, wo):
    """The continuous MERL bin coordinates ``(x_h, x_d, x_p)`` (measured_brdf.glsl), (..., 3) -> (..., 3).

    ``x_h = 90 sqrt(theta_h / (pi/2))``, ``x_d = 90 theta_d / (pi/2)``, ``x_p = 180 phi_d / pi`` with the
    angles from `atan2_first_quadrant`: ``theta_h`` of n's parts across and along h, ``theta_d`` of
    ``|l - v|`` and ``|l + v|`` (half the angle between them), the azimuth of ``d = l - v`` about h from
    ``u`` (the tangent of Duff et al.'s basis around h where ``n - (n.h) h`` vanishes).  Swapping l and v
    negates d exactly: the folded coordinates are bit-identical.
    """
    _, h, length = safe_normalize(wi + wo)
    cos_h = _dot(n, h)
    tilted, u, sin_h = safe_normalize(cos_h[..., None] * h - n)
    fallback, _ = frame_from_tangent(h, np.zeros(h.shape[:-1] + (4,), h.dtype))
    u = np.where(tilted[..., None], u, fallback)
    d = wi - wo  # 2 (l - (h.l) h): l's part across h, twice; -d for swapped l and v
    y = _dot(d, np.cross(h, u))
    x = _dot(d, u)
    theta_h = atan2_first_quadrant(np.minimum(sin_h, 1), np.maximum(cos_h, 0))
    theta_d = atan2_first_quadrant(np.sqrt(_dot(d, d)), length)
    flip = (y < 0) | ((y == 0) & (x < 0))  # folded into [0, pi): pi is 0
    ys, xs = np.where(flip, -y, y), np.where(flip, -x, x)
    a = atan2_first_quadrant(ys, np.abs(xs))
    phi_d = np.where(xs < 0, np.pi - a, a)
    return np.stack([90.0 * np.sqrt(theta_h * (2.0 / np.pi)), theta_d * _DEG, phi_d * _DEG], axis=-1)


def measured_brdf_fetch(i, table):
    """``table[i_h, i_d, i_p]`` (measured_brdf.glsl, texel ``i.zyx``) as float64: (N, 3) integer indices -> (N, 3)."""
    return table[i[..., 0], i[..., 1], i[..., 2]].astype(np.float64)


def measured_brdf_nearest(x, table):
    """The bin ``floor(x)``, clamped (measured_brdf.glsl): (N, 3) coordinates -> (N, 3) ``f_r``."""
    i = np.clip(np.floor(x), 0, LAST).astype(np.int64)
    return measured_brdf_fetch(i, table)


def measured_brdf_trilinear(x, table):
    """Trilinear between the samples at ``x_h = i``, ``x_d = j + 1/2``, ``x_p = k + 1/2`` (measured_brdf.glsl),
    clamped in theta, periodic in phi_d: (N, 3) coordinates -> (N, 3) ``f_r``."""
    a = x - np.array([0.0, 0.5, 0.5])
    base = np.floor(a)
    w = a - base
    i = base.astype(np.int64)
    lo = np.stack([np.clip(i[:, 0], 0, LAST[0]), np.clip(i[:, 1], 0, LAST[1]), (i[:, 2] + 180) % 180], axis=-1)
    hi = np.stack([np.clip(i[:, 0] + 1, 0, LAST[0]), np.clip(i[:, 1] + 1, 0, LAST[1]), (i[:, 2] + 181) % 180], axis=-1)

    def mix(p, q, t):
        return p * (1 - t[:, None]) + q * t[:, None]

    def corner(ih, jd):
        return mix(measured_brdf_fetch(np.stack([ih[:, 0], jd[:, 1], lo[:, 2]], -1), table),
                   measured_brdf_fetch(np.stack([ih[:, 0], jd[:, 1], hi[:, 2]], -1), table), w[:, 2])

    c00, c01, c10, c11 = corner(lo, lo), corner(lo, hi), corner(hi, lo), corner(hi, hi)
    return mix(mix(c00, c01, w[:, 1]), mix(c10, c11, w[:, 1]), w[:, 0])


_LOOKUPS = {"nearest": measured_brdf_nearest, "trilinear": measured_brdf_trilinear}


def _read_table(source):
    """``(TableData, unmeasured count)`` from a MERL file path or an array of f_r (NaN: unmeasured)."""
    if isinstance(source, TableData):
        return MeasuredBRDF.tables[0].validate(source), 0
    if isinstance(source, (str, os.PathLike)):
        values, where = merl.read_merl(source), str(Path(source))
    else:
        try:
            values = np.asarray(source, dtype=np.float64)
        except (TypeError, ValueError):
            raise TypeError(f"table must be the path of a MERL .binary file, an array of shape "
                            f"{merl.SHAPE + (3,)} or a TableData (got {type(source).__name__})") from None
        where = None
        if values.shape != merl.SHAPE + (3,):
            raise ValueError(f"table must have shape {merl.SHAPE + (3,)} (90 theta_h, 90 theta_d, 180 phi_d bins, "
                             f"rgb) (got {values.shape})")
    unmeasured = np.isnan(values)
    table = MeasuredBRDF.tables[0].validate(np.where(unmeasured, 0.0, values), where)
    return table, int(unmeasured.any(axis=-1).sum())


#: the function `MeasuredBRDF.from_model` tabulates a material with (`glphong.analysis.tabulate.tabulate`,
#: which evaluates the material's twin through layers above the materials, registers itself here when
#: imported, and ``import glphong`` imports it): the materials never import upward
_TABULATOR = []


def register_tabulator(function):
    """Make ``function(material) -> (90, 90, 180, 3) table`` the tabulator of `MeasuredBRDF.from_model`."""
    _TABULATOR[:] = [function]


class MeasuredBRDF(MaterialModel):
    """A measured isotropic BRDF in the MERL layout: ``f_r(wi, wo) = T[i_h, i_d, i_p]`` [1/sr], per channel.

    The bin of the half and difference angles (Rusinkiewicz 1998) ``theta_h = angle(n, h)``, ``theta_d = angle(h,
    l)`` and ``phi_d`` (the azimuth of l about h, folded into [0, pi]), at ``x_h = 90 sqrt(theta_h / (pi/2))``,
    ``x_d = 90 theta_d / (pi/2)``, ``x_p = 180 phi_d / pi``: the bin ``floor(x)``, clamped, as the reference reader
    indexes it (``lookup='nearest'``), or trilinear between the samples at ``x_h = i``, ``x_d = j + 1/2``,
    ``x_p = k + 1/2`` (``lookup='trilinear'``).  The module docstring has the details.

    Parameters
    ----------
    table : str, path-like, (90, 90, 180, 3) array_like or TableData
        A MERL ``.binary`` file, or ``f_r`` [1/sr] per bin (NaN: unmeasured, rendered as 0).
    lookup : {'nearest', 'trilinear'}
    ka, two_sided
        As every material.

    Attributes
    ----------
    unmeasured : int
        Bins the file marked as not measured (0 in the texture).

    Examples
    --------
    >>> measured = MeasuredBRDF.from_model(glphong.NormalizedBlinnPhong(0.3, 0.5, 40.0), "blinn.binary")  # doctest: +SKIP
    >>> glphong.MeasuredBRDF("blinn.binary", lookup="trilinear")                                       # doctest: +SKIP
    """

    name = "measured_brdf"
    tables = (Table("table", merl.SHAPE, 3, low=0.0, unit="1/sr",
                    doc="f_r per (theta_h, theta_d, phi_d) bin, MERL layout"),)
    choices = (Choice("lookup", ("nearest", "trilinear"), "nearest",
                      doc="the reference reader's bin, or trilinear between the samples"),)
    needs = ("view",)
    uses = ("angle",)
    glsl = GlslFile("materials/measured_brdf.glsl")
    properties = Properties(reciprocal=True, isotropic=True, energy_conserving=None, non_negative=True,
                            condition="depends on the data (glphong.analysis measures it)")

    def __init__(self, table, lookup="nearest", *, ka=0.0, two_sided=True, normal_map=None, alpha_mask=None,
                 alpha_blend=None):
        data, unmeasured = _read_table(table)
        super().__init__(table=data, lookup=lookup, ka=ka, two_sided=two_sided, normal_map=normal_map, alpha_mask=alpha_mask,
                         alpha_blend=alpha_blend)
        object.__setattr__(self, "unmeasured", unmeasured)

    @classmethod
    def from_model(cls, material, path=None, lookup="nearest"):
        """Tabulate ``material`` (any material, by its float64 twin) in the MERL layout.

        Parameters
        ----------
        material : glphong.materials.Material
        path : str or path-like, optional
            Where to write the MERL ``.binary`` file; the returned material is read back from it.
        lookup : {'nearest', 'trilinear'}

        Returns
        -------
        MeasuredBRDF
            Bins whose representative pair has the light or the view below the horizon are unmeasured
            (`glphong.merl.tabulate`, registered by `glphong.analysis.tabulate`).
        """
        if not _TABULATOR:
            raise RuntimeError("MeasuredBRDF.from_model needs glphong.analysis.tabulate, which import glphong "
                               "loads: import glphong first")
        table = _TABULATOR[0](material)
        if path is None:
            return cls(table, lookup)
        merl.write_merl(path, table)
        return cls(path, lookup)

    @classmethod
    def example(cls, **overrides):
        """A normalised Blinn-Phong lobe with a diffuse term (``rho_d`` 0.3, ``rho_s`` 0.5, q 40) tabulated
        in closed form on the bins (fast; the same table each call)."""
        return cls(_example_table(), **overrides)

    def response(self, f, wi, wo, n_dot_l, p):
        """Twin of ``measured_brdf_response``: the GPU's lookup on the same float32 table; (N, 3)."""
        x = measured_brdf_coordinates(f.n, wi, wo)
        value = _LOOKUPS[p.lookup](x, p.table.array)
        return np.where((_dot(f.n, wo) > 0)[:, None], value * n_dot_l[:, None], 0.0)

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """The lookup's range over the coordinates the GPU may compute, times ``n.l +- D eps``.

        Every angle the GPU forms may differ from the twin's by ``e = 4 D eps`` rad (inputs rotated by
        ``D eps``, a 3-ulp atan, the normalisations); the azimuth by ``e (1 + 1/sin(theta_h) +
        1/sin(theta_d))`` (u and l's part across h lose direction as they shrink).  The coordinates'
        box per axis is mapped through the coordinate functions (and widened by 4 ulp of the product);
        the lookup's minimum and maximum over the box are taken at its corners and at the samples (or
        bin interiors) inside it, where a piecewise multilinear function has its extremes.  An azimuth
        box of one bin or more spans the whole period.  Trilinear sums are widened by ``A eps``.
        """

        e = 4 * constants.D * EPS
        x = measured_brdf_coordinates(f.n, wi, wo)
        theta_h = (np.pi / 2) * (x[:, 0] / 90.0) ** 2
        theta_d = x[:, 1] / _DEG
        with np.errstate(divide="ignore"):
            e_phi = e * (1 + 1 / np.sin(theta_h) + 1 / np.sin(theta_d))
        grow = 1 + 4 * EPS
        box = np.empty(x.shape + (2,))
        box[:, 0, 0] = 90 * np.sqrt(np.maximum(theta_h - e, 0) * (2 / np.pi)) / grow
        box[:, 0, 1] = 90 * np.sqrt(np.minimum(theta_h + e, np.pi / 2) * (2 / np.pi)) * grow + 4 * EPS
        box[:, 1, 0] = np.maximum(theta_d - e, 0) * _DEG / grow
        box[:, 1, 1] = (theta_d + e) * _DEG * grow + 4 * EPS
        with np.errstate(invalid="ignore"):
            box[:, 2, 0] = (x[:, 2] / _DEG - e_phi) * _DEG / grow - 4 * EPS
            box[:, 2, 1] = (x[:, 2] / _DEG + e_phi) * _DEG * grow + 4 * EPS
        wide = ~(box[:, 2, 1] - box[:, 2, 0] < 1.0)
        trilinear = p.lookup == "trilinear"
        offsets = np.array([0.0, 0.5, 0.5]) if trilinear else np.array([0.5, 0.5, 0.5])
        # per axis: the box's ends and the critical point (sample, or bin interior) just below its top
        inner = np.floor(box[:, :, 1] - offsets) + offsets
        middle = np.where(inner > box[:, :, 0], inner, box[:, :, 0])
        candidates = np.stack([box[:, :, 0], middle, box[:, :, 1]], axis=-1)  # (N, 3 axes, 3)
        lookup = _LOOKUPS[p.lookup]
        table = p.table.array
        low = np.full(x.shape, np.inf)
        high = np.full(x.shape, -np.inf)
        narrow = np.flatnonzero(~wide)
        phis = [candidates[narrow, 2, c] for c in range(3)]
        if len(narrow):
            for a in range(3):
                for b in range(3):
                    for c in range(3):
                        point = np.stack([candidates[narrow, 0, a], candidates[narrow, 1, b], phis[c] % 180.0], -1)
                        value = lookup(point, table)
                        low[narrow] = np.minimum(low[narrow], value)
                        high[narrow] = np.maximum(high[narrow], value)
        for row in np.flatnonzero(wide):  # the whole period of phi_d: every sample (bin centre) of the row
            points = np.array([[candidates[row, 0, a], candidates[row, 1, b], k + 0.5]
                               for a in range(3) for b in range(3) for k in range(180)])
            value = lookup(points, table)
            low[row], high[row] = value.min(axis=0), value.max(axis=0)
        if trilinear:
            low, high = low - constants.A * EPS * np.abs(low), high + constants.A * EPS * np.abs(high)
        tol = constants.D * EPS
        n_dot_v = _dot(f.n, wo)
        low = np.where((n_dot_v > tol)[:, None], low * (np.maximum(n_dot_l - tol, 0) * (1 - constants.A * EPS))[:, None],
                       0.0)
        high = np.where((n_dot_v > -tol)[:, None], high * ((n_dot_l + tol) * (1 + constants.A * EPS))[:, None], 0.0)
        return low, high

    def oracle(self, f, wi, wo, n_dot_l, p):
        """The lookup at the reference code's angles, in mpmath: ``acos`` of the dots and the azimuth by
        ``atan2`` in the frame (u, h x u) (`glphong.merl`'s formulas), then the same bin or samples."""
        import mpmath

        dot = lambda a, b: sum(x * y for x, y in zip(a, b))  # noqa: E731
        n, l, v = f.n, wi, wo
        if dot(n, v) <= 0:
            return [mpmath.mpf(0)] * 3
        s = [a + b for a, b in zip(l, v)]
        norm = mpmath.sqrt(dot(s, s))
        h = [c / norm for c in s]
        n_dot_h = dot(n, h)
        away = [n_dot_h * a - b for a, b in zip(h, n)]
        length = mpmath.sqrt(dot(away, away))
        if length == 0:  # h = n: Duff et al.'s tangent around h
            sign = 1 if h[2] >= 0 else -1
            k = -1 / (sign + h[2])
            u = [1 + sign * h[0] * h[0] * k, sign * h[0] * h[1] * k, -sign * h[0]]
        else:
            u = [c / length for c in away]
        hxu = [h[1] * u[2] - h[2] * u[1], h[2] * u[0] - h[0] * u[2], h[0] * u[1] - h[1] * u[0]]
        theta_h = mpmath.acos(min(max(n_dot_h, -1), 1))
        theta_d = mpmath.acos(min(max(dot(h, l), -1), 1))
        phi_d = mpmath.atan2(dot(l, hxu), dot(l, u))
        phi_d = phi_d + mpmath.pi if phi_d < 0 else phi_d
        x = np.array([[float(90 * mpmath.sqrt(theta_h / (mpmath.pi / 2))), float(theta_d * 180 / mpmath.pi),
                       float(phi_d * 180 / mpmath.pi)]])
        value = _LOOKUPS[p.lookup](x, p.table.array)[0]
        return [mpmath.mpf(float(c)) * n_dot_l for c in value]

    @classmethod
    def stability_cases(cls):
        """The generic geometry, and the peak of a sharp tabulated lobe (q = 1e4; ``theta_h`` from 0 to 5e-4
        rad, where ``acos`` of n.h resolves nothing below 3.5e-4 rad: x_h moves by up to 1.3 bins) with
        both lookups."""

        cases = generic_cases(cls.name, cls.example())
        light = _unit(30.0)
        for lookup in ("nearest", "trilinear"):
            material = cls(_example_table(1e4), lookup=lookup)
            for offset in (0.0, 1e-5, 1e-4, 3e-4, 4.2e-4, 1e-3):  # 4.2e-4: theta_h 2.1e-4, just inside bin 1
                cases.append(Case(f"{cls.name} {lookup} theta_h ~ {offset / 2:g} rad", "peak", material,
                                  eye=_mirror_eye(30.0, offset), lights=(("point", light, 4 * np.pi),),
                                  note="the finest theta_h bins: acos of n.h loses them"))
        return cases


_EXAMPLE = {}


def _example_table(q=40.0):
    """``(rho_d/pi + rho_s c(q) cos(theta_h)^q) (1, 0.8, 0.6)`` (normalised Blinn-Phong, 0.3, 0.5) on the
    bins, as `glphong.merl.tabulate` places them; made once per process and exponent."""
    if q not in _EXAMPLE:
        th = (np.arange(merl.SHAPE[0]) / merl.SHAPE[0]) ** 2 * (np.pi / 2)
        c = (q + 2) * (q + 4) / (8 * np.pi * (q + 2.0 ** (-q / 2)))
        lobe = 0.3 / np.pi + 0.5 * c * np.cos(th) ** q
        table = np.broadcast_to(lobe[:, None, None, None], merl.SHAPE + (3,)) * np.array([1.0, 0.8, 0.6])
        _EXAMPLE[q] = TableData(table)
    return _EXAMPLE[q]
