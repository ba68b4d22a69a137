"""Fresnel factors a glossy term takes as ``fresnel=`` (docs/design.md section 9; GLSL: ``glsl/fresnel.glsl``).

A glossy model that declares a `FresnelSlot` multiplies its lobe by ``F(c)``, with the cosine ``c``
the model states (``n.l`` for Phong-type lobes, ``h.l`` for half-vector lobes and microfacets):

- ``fresnel=None``: ``F = 1`` (the lecture's models; nothing is compiled);
- `SchlickFresnel` ``(f0)``: ``F = f0 + (1 - f0)(1 - c)^5`` (Schlick 1994), ``f0`` the reflectance at
  normal incidence per channel, in [0, 1] (about 0.04 for glass and plastics, 0.5 to 1 for metals);
- `DielectricFresnel` ``(ior)``: the exact unpolarised reflectance of a dielectric of relative index
  ``ior`` (Cook and Torrance 1982), in (0, 1e6]; ``ior < 1`` (light leaving a denser medium) gives
  total internal reflection (``F = 1``) beyond the critical angle.

The choice is structural (a ``#define`` of the term's program: ``<MODEL>_FRESNEL_SCHLICK`` or
``<MODEL>_FRESNEL_DIELECTRIC``); ``f0`` and ``ior`` are uniforms ``u_<model>_fresnel_f0`` and
``u_<model>_fresnel_ior``.  The uber-shader, which holds one variant of each model for every
material of a scene, compiles both forms for a model where one of the scene's terms has a Fresnel
factor and selects by the uniform ``u_<model>_fresnel_form`` (``<MODEL>_FRESNEL_RUNTIME``); without
one it compiles none.  A user's model takes ``fresnel=`` by declaring ``fresnel_slot =
FresnelSlot(cosine='h.l')`` and calling ``<name>_fresnel(c)`` in its GLSL and `fresnel_factor` in its twin.
"""
from dataclasses import dataclass

import numpy as np

from glphong.definitions.params import Param
from glphong.twin.band import EPS
from glphong.twin.functions import fresnel_dielectric, fresnel_schlick

__all__ = ["Fresnel", "SchlickFresnel", "DielectricFresnel", "FresnelSlot", "fresnel_factor", "FRESNEL_PARAMS",
           "fresnel_oracle", "fresnel_band", "fresnel_uniform_values"]

#: the uniforms a Fresnel slot adds to its model (``u_<model>_fresnel_f0``, ``_ior`` and ``_form``)
FRESNEL_PARAMS = (Param("fresnel_f0", "rgb", low=0.0, high=1.0, default=0.0, doc="Schlick's f0 (fresnel=SchlickFresnel)"),
                  Param("fresnel_ior", "scalar", low=0.0, high=1e6, low_inclusive=False, default=1.5,
                        doc="relative index of refraction (fresnel=DielectricFresnel)"),
                  Param("fresnel_form", "scalar", low=0.0, high=2.0, default=0.0,
                        doc="the form by index, read only by the uber-shader (0 none, 1 Schlick, 2 dielectric)"))
#: forms by index (ParamValues.fresnel_form): 0 none (F = 1), 1 Schlick, 2 dielectric
FORMS = ("none", "schlick", "dielectric")


def fresnel_uniform_values(fresnel):
    """``{'fresnel_f0': (3,) tuple, 'fresnel_ior': float, 'fresnel_form': float}`` of a factor: its own value,
    its form's index and the neutral defaults of `FRESNEL_PARAMS` for the rest (all defaults for None)."""
    values = {p.name: p.default for p in FRESNEL_PARAMS}
    if fresnel is not None:
        values["fresnel_form"] = float(fresnel.index)
        values[fresnel.uniform] = getattr(fresnel, fresnel.field)
    return values


class Fresnel:
    """Base of the Fresnel factors (`SchlickFresnel`, `DielectricFresnel`): a frozen dataclass of one
    ``field`` held in the uniform ``u_<model>_<uniform>`` and validated by that uniform's `Param`."""

    form = None
    field = None
    uniform = None

    def __post_init__(self):
        param = {p.name: p for p in FRESNEL_PARAMS}[self.uniform]
        try:
            object.__setattr__(self, self.field, param.validate(getattr(self, self.field)))
        except (TypeError, ValueError) as exc:
            raise type(exc)(f"{type(self).__name__}: {str(exc).replace(self.uniform, self.field)}") from None

    def uniform_values(self):
        """This factor's uniforms (`fresnel_uniform_values`)."""
        return fresnel_uniform_values(self)

    @property
    def index(self):
        return FORMS.index(self.form)


@dataclass(frozen=True, repr=False)
class SchlickFresnel(Fresnel):
    """Schlick's approximation ``F(c) = f0 + (1 - f0)(1 - c)^5``.

    Parameters
    ----------
    f0 : float or (3,) array_like
        Reflectance at normal incidence, per channel, in [0, 1] (dimensionless).
    """

    f0: tuple = 0.04
    form = "schlick"
    field = "f0"
    uniform = "fresnel_f0"

    def __repr__(self):
        f0 = f"{self.f0[0]:g}" if len(set(self.f0)) == 1 else "(" + ", ".join(f"{c:g}" for c in self.f0) + ")"
        return f"SchlickFresnel(f0={f0})"


@dataclass(frozen=True, repr=False)
class DielectricFresnel(Fresnel):
    """The exact unpolarised Fresnel reflectance of a dielectric (Cook and Torrance 1982).

    Parameters
    ----------
    ior : float
        Relative index of refraction, in (0, 1e6] (1.5 for glass, 1.33 for water; below 1: total
        internal reflection beyond the critical angle).
    """

    ior: float = 1.5
    form = "dielectric"
    field = "ior"
    uniform = "fresnel_ior"

    def __repr__(self):
        return f"DielectricFresnel(ior={self.ior:g})"


@dataclass(frozen=True)
class FresnelSlot:
    """A glossy model's ``fresnel=`` argument (a class attribute ``fresnel_slot = FresnelSlot(...)``).

    Attributes
    ----------
    cosine : str
        The cosine the model passes to ``F``, for documentation: ``'n.l'`` or ``'h.l'``.
    default : Fresnel or None
        The value when ``fresnel=`` is not given (None: ``F = 1``).
    """

    cosine: str = "h.l"
    default: Fresnel = None
    name = "fresnel"

    def validate(self, value):
        """``value`` if it is None or a `Fresnel`, else TypeError naming the valid values."""
        if value is None or isinstance(value, Fresnel):
            return value
        raise TypeError(f"fresnel must be None (F = 1), glphong.materials.SchlickFresnel(f0) or "
                        f"glphong.materials.DielectricFresnel(ior) (got {value!r})")

    @property
    def interval(self):
        return "None, SchlickFresnel(f0 in [0, 1]) or DielectricFresnel(ior in (0, 1e6])"


def fresnel_factor(p, c):
    """The twin of a model's generated ``<model>_fresnel(c)``: ``F(c)`` by ``p.fresnel_form``, (..., 3).

    Parameters
    ----------
    p : ParamValues
        With ``fresnel_form`` (0 none, 1 Schlick, 2 dielectric), ``fresnel_f0`` and ``fresnel_ior``.
    c : (...) ndarray
        The cosine the model states.
    """

    c = np.asarray(c)
    form = int(p.fresnel_form)
    if form == 1:
        return fresnel_schlick(p.fresnel_f0, c).astype(c.dtype)
    if form == 2:
        return np.repeat(fresnel_dielectric(p.fresnel_ior, c)[..., None], 3, axis=-1)
    return np.ones(c.shape + (3,), c.dtype)


def fresnel_oracle(p, c):
    """``F(c)`` in mpmath from the textbook formulas (no stabilisation): a list of 3."""
    import mpmath

    form = int(p.fresnel_form)
    c = min(max(c, mpmath.mpf(0)), mpmath.mpf(1))
    if form == 1:
        return [f + (1 - f) * (1 - c) ** 5 for f in p.fresnel_f0]
    if form == 2:
        n = p.fresnel_ior
        g2 = n * n + c * c - 1
        if g2 < 0 or (g2 == 0 and c == 0):
            return [mpmath.mpf(1)] * 3
        g = mpmath.sqrt(g2)
        f = (g - c) ** 2 / (2 * (g + c) ** 2) * (1 + (c * (g + c) - 1) ** 2 / (c * (g - c) + 1) ** 2)
        return [f] * 3
    return [mpmath.mpf(1)] * 3


def fresnel_band(p, c, tol):
    """Interval ``(low, high)``, each (..., 3), of float32 ``F`` for a cosine known to ``+- tol``.

    Both forms are non-increasing in ``c`` on [0, 1], so the ends are ``F(c + tol)`` and ``F(c - tol)``,
    widened by 16 eps relative (the power, the square root and the divisions).
    """

    c = np.asarray(c, dtype=np.float64)
    low = fresnel_factor(p, np.clip(c + tol, 0, 1))
    high = fresnel_factor(p, np.clip(c - tol, 0, 1))
    return low * (1 - 16 * EPS), np.minimum(high * (1 + 16 * EPS), 1.0)
