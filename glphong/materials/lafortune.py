"""The model 'lafortune_lobes' and the material `Lafortune` (docs/design.md section 9; GLSL:
``glsl/materials/lafortune_lobes.glsl``).

The generalised cosine lobes of Lafortune, Foo, Torrance and Greenberg (1997)::

    f_r = rho_d / pi + sum_{i=1..k} rho_i max(Cx_i l_x v_x + Cy_i l_y v_y + Cz_i l_z v_z, 0)^(n_i)   [1/sr]

with the components of ``l`` (toward the light) and ``v`` (toward the viewer) in the local frame
``(t, b, n)``: ``l_x = l.t``, ``l_y = l.b``, ``l_z = l.n``.  The model needs the view and a tangent
frame (``needs = ('view', 'tangent')``).  `Lafortune` is the `MaterialSum` of `Diffuse` (``rho_d / pi``)
and `LafortuneLobes` (the sum of the ``k`` lobes, 1 <= k <= `LAFORTUNE_MAX_LOBES` = 4).  The responses are
``f_r (n.l)`` [1/sr].

Each lobe is a tuple ``(rho, Cx, Cy, Cz, n)``.  ``C`` sets the lobe's shape and direction: the lobe of
a fixed ``l`` peaks at ``v = (C o l)/|C o l|`` (``o`` the componentwise product) with the value
``rho |C o l|^n``:

- ``C = (-1, -1, 1)``: ``x = v.r`` with ``r = 2 (n.l) n - l``, the Phong lobe ``(v.r)^n``; with
  ``rho = rho_s (n + 2)/(2 pi)`` it is the normalised Phong lobe of Lafortune and Willems 1994 (the
  lobe of `NormalizedPhong`: directional albedo ``rho_s`` at normal incidence, less elsewhere);
- ``-Cx = -Cy > Cz > 0``: off-specular reflection, the peak turned from the mirror direction toward
  grazing (``tan(theta_peak) = (Cx/Cz) tan(theta_l)``) and brighter there (``|C o l|`` grows);
- ``Cx = Cy = Cz > 0``: retro-reflection, ``rho Cx^n (l.v)^n``, peaking at ``v = l``;
- ``Cx != Cy``: anisotropic (the value changes under a rotation about ``n``); ``Cx = Cy`` isotropic;
- ``n = 0``: the constant lobe ``rho`` (the ``0^0 := 1`` convention of the Phong lobes).

``rho`` is the lobe's scale [1/sr]: the BRDF value of a unit lobe (``|C o l| = 1``) at its peak.

The lobe is symmetric in ``l`` and ``v`` (``C`` is diagonal), so the BRDF is reciprocal for every
parameter value.  It is isotropic only where ``Cx = Cy`` for every lobe (declared: not isotropic).
It conserves energy only for suitable parameters (declared: not in general): for lobes with
``C = (-1, -1, 1)`` and ``rho_i = rho_s,i (n_i + 2)/(2 pi)`` where ``rho_d + sum_i rho_s,i <= 1``; for
general ``C`` the lobe's scale ``|C o l|^n`` is unbounded.

==============  ======  ============  ======  ==============================================================
parameter       kind    range         unit    meaning
==============  ======  ============  ======  ==============================================================
rho_d           rgb     [0, 1]        1       diffuse albedo (the `Diffuse` term, ``f_r = rho_d / pi``)
lobes           --      1 to 4        --      tuples ``(rho, Cx, Cy, Cz, n)``, one per lobe (a key field: the
                                              program is compiled for their number, LAFORTUNE_LOBES_COUNT)
lobe<k>_rho     rgb     >= 0          1/sr    lobe k's scale rho_k (k = 1..4)
lobe<k>_c       rgb     finite        1       lobe k's (Cx, Cy, Cz) (an rgb param holding the three reals)
lobe<k>_n       scalar  [0, 1e6]      1       lobe k's exponent (0: a constant lobe)
==============  ======  ============  ======  ==============================================================

The per-lobe parameters are uniforms ``u_lafortune_lobes_lobe<k>_rho``, ``..._c``, ``..._n``; the constructors
take ``lobes=`` or the per-lobe keywords (``Lafortune(0.2, lobe1_rho=..., lobe1_c=..., lobe1_n=...)``, the
form `parameter_values` returns, so ``type(m)(**m.parameter_values())`` is ``m``).  The lobes above the
count keep placeholder values (``rho = 0``) that no program reads.  The term vanishes (leaves the program)
where every lobe's ``rho`` is 0.

Units: ``f_r``, ``rho_i`` and the responses in 1/sr; ``rho_d``, ``C`` and ``n`` dimensionless.

Paper: E. P. F. Lafortune, S.-C. Foo, K. E. Torrance and D. P. Greenberg, 1997, "Non-linear
approximation of reflectance functions", SIGGRAPH 97 Conference Proceedings, pp. 117-126.

Fresnel: the model takes no Fresnel factor (no ``fresnel=``): the paper fits the lobes, Fresnel
effects included, to measured or simulated data (off-specular lobes with ``|C o l|`` growing toward
grazing are how it represents them).

Stable evaluation (docs/design.md section 3): the textbook ``pow(x, n)`` with ``x`` formed by a dot product has
an absolute error ``~ eps |C|`` in ``x``, so a relative error ``~ n eps |C| / x`` (measured up to 17 % at
``n = 1e6`` near the peak) and no resolution of a narrow peak.  glphong uses a generalised chord form (see
the GLSL header): ``x = m |c^ o l| (w.v)`` with ``m = max|C_i|``, ``c^ = C/m``, ``w`` the unit peak
direction, ``w.v = 1 - |w - v|^2/2`` and ``|c^ o l|^2 = 1 - u``, ``u = sum (1 - c^_i^2) l_i^2`` formed
without cancellation, so ``x^n = exp(n (ln m + ln(1 - u)/2 + ln(1 - delta)))``.  For ``|Cx| = |Cy| = |Cz|``
(Phong-type and retro-reflective lobes) ``u = 0`` exactly and this is the chord form of `PhongLobe`:
exact at the peak and accurate to ``eps (A + 4 lambda + 6 sqrt(2 n lambda))`` near it for any ``n``
(``lambda = -ln(lobe/peak)``; measured within 4e-4 at ``n = 1e6``), plus ``4 eps n |ln m|`` for
``m != 1``.  For general ``C`` the lobe's magnitude depends on the direction of ``l``; an angle error
``D eps`` moves it by ``n D eps sqrt(u/(1 - u))`` relative (the function's own conditioning in float32,
not a formulation artefact), and the logarithms' rounding adds ``4 eps n (|ln m| + |ln(1 - u)|/2)``.
Valid range (relative error <~ 1e-3): any ``n`` up to 1e6 where ``|Cx| = |Cy| = |Cz|``; ``n sqrt(u) <~ 2e3``
otherwise, e.g. ``n <~ 5e3`` where the ``|C_i|`` differ by 10 % and ``n <~ 1.5e4`` where they differ by
1 %.  `LafortuneLobes.band` is this accuracy estimate (measured errors are 3 to 8 times smaller).  The
exponent is clamped to [-104, 88]: a lobe above ``e^88 ~ 1.65e38`` (``|C| > 1`` with a large ``n``)
saturates there, so the response is at most FLT_MAX or +Inf, never NaN.

Where the paper and common implementations differ (glphong follows the paper, docs/design.md section 9, with
the lobe's scale made explicit as the issue specifies):

- Scale: the paper folds each lobe's magnitude into ``C`` (``f_r = sum_i [C_i . (u o v)]^(n_i)``, e.g.
  the normalised Phong lobe as ``-Cx = -Cy = Cz = ((n + 2)/(2 pi))^(1/n)``); glphong writes an explicit
  ``rho_i`` in front (Cornell's MDL ``blLfrtn`` lobe does the same).  The paper's lobe is ``rho = 1`` with
  the paper's ``C``, exactly; ``rho`` with ``C`` equals the paper's ``C rho^(1/n)`` for ``n > 0``.
- Channels: the paper's fits (and pbrt's first-edition ``Lafortune`` BxDF, and LuxRender's) carry
  ``C`` and ``n`` per colour channel; glphong shares ``C`` and ``n`` across channels with an rgb ``rho``
  (a per-channel fit is one lobe per channel, ``rho`` masking the others).
- Clamp: glphong evaluates ``max(x, 0)^n``; pbrt's ``Lafortune::f`` raises the spectrum ``v`` to the
  exponent with no ``max(v, 0)`` in the BxDF itself.
- Normal-view gate: none (the paper's formula as written, as `PhongLobe`): the lobe is evaluated for a
  view below the surface too, which only one-sided materials seen from behind can reach.
"""
import numpy as np

from glphong.materials.diffuse import Diffuse
from glphong.definitions.material import GlslFile, MaterialModel, MaterialSum, Param, Properties
from glphong.definitions.cases import Case, _mirror_eye, _unit, generic_cases
from glphong.twin.band import EPS, FLT_MAX, lobe_band
from glphong.twin.functions import dot as _dot, log_one_minus, safe_normalize

__all__ = ["LafortuneLobes", "Lafortune", "lafortune_local", "lafortune_log", "lafortune_lobe",
           "LAFORTUNE_MAX_LOBES"]

#: the most lobes a Lafortune material takes (the GLSL evaluates lobes 1..LAFORTUNE_LOBES_COUNT <= 4)
LAFORTUNE_MAX_LOBES = 4
#: lafortune_lobes.glsl LAFORTUNE_EXP_MIN, LAFORTUNE_EXP_MAX: the clamp of the lobe's exponent
LAFORTUNE_EXP_MIN = -104.0
LAFORTUNE_EXP_MAX = 88.0


def _lobe_params(k):
    return (Param(f"lobe{k}_rho", "rgb", low=0.0, unit="1/sr",
                  doc=f"lobe {k}'s scale rho_{k}: its BRDF value at the peak where |C o l| = 1"),
            Param(f"lobe{k}_c", "rgb", low=-np.inf,
                  doc=f"lobe {k}'s (Cx, Cy, Cz), finite reals: (-1, -1, 1) is the Phong lobe (v.r)^n"),
            Param(f"lobe{k}_n", "scalar", low=0.0, high=1e6,
                  doc=f"lobe {k}'s exponent; 0 gives a constant lobe (0^0 := 1)"))


_LOBE_PARAMS = tuple(p for k in range(1, LAFORTUNE_MAX_LOBES + 1) for p in _lobe_params(k))
_LOBE_NAMES = tuple(p.name for p in _LOBE_PARAMS)
#: the values an unused lobe's uniforms hold (no program reads them)
_UNUSED = {"rho": 0.0, "c": (-1.0, -1.0, 1.0), "n": 1.0}
#: the lobes of `LafortuneLobes.example`: an off-specular forward lobe and a retro-reflective one
EXAMPLE_LOBES = ((0.6, -1.05, -1.05, 0.95, 30.0), (0.15, 0.8, 0.8, 0.8, 4.0))


def _lobe_index(name):
    return int(name[4])


def _resolve_lobes(owner, lobes, per_lobe):
    """``(count, values)``: the number of lobes and every lobe param's validated value (unused: placeholders).

    ``lobes`` is a sequence of ``(rho, Cx, Cy, Cz, n)``; ``per_lobe`` the keywords ``lobe<k>_*`` (the
    count is then the highest ``k`` given, and lobes 1..count need all three)."""
    unknown = sorted(set(per_lobe) - set(_LOBE_NAMES))
    if unknown:
        raise TypeError(f"{owner}() got an unexpected parameter {unknown[0]!r} (parameters: lobes, or "
                        f"lobe<k>_rho, lobe<k>_c, lobe<k>_n for k = 1..{LAFORTUNE_MAX_LOBES}; ka, two_sided, normal_map, alpha_mask, "
                        "alpha_blend)")
    if lobes is not None and per_lobe:
        raise TypeError(f"{owner}() takes lobes= or the per-lobe parameters ({', '.join(sorted(per_lobe))}), not both")
    if lobes is None:
        if not per_lobe:
            raise TypeError(f"{owner}() missing parameter 'lobes' (1 to {LAFORTUNE_MAX_LOBES} tuples "
                            "(rho, Cx, Cy, Cz, n), or the per-lobe parameters lobe1_rho, lobe1_c, lobe1_n, ...)")
        count = max(_lobe_index(name) for name in per_lobe)
        for k in range(1, count + 1):
            missing = [f"lobe{k}_{part}" for part in ("rho", "c", "n") if f"lobe{k}_{part}" not in per_lobe]
            if missing:
                raise TypeError(f"{owner}() missing parameter {missing[0]!r}: with lobe{count}_* given, lobes 1 to "
                                f"{count} each need lobe<k>_rho, lobe<k>_c and lobe<k>_n")
        given, where = per_lobe, {}
    else:
        if isinstance(lobes, (str, bytes)) or not hasattr(lobes, "__iter__"):
            raise TypeError(f"{owner}(): lobes must be a sequence of tuples (rho, Cx, Cy, Cz, n) (got {lobes!r})")
        lobes = tuple(lobes)
        count = len(lobes)
        if not 1 <= count <= LAFORTUNE_MAX_LOBES:
            raise ValueError(f"{owner}(): lobes must hold 1 to {LAFORTUNE_MAX_LOBES} lobes (LAFORTUNE_MAX_LOBES = "
                             f"{LAFORTUNE_MAX_LOBES}; got {count})")
        given, where = {}, {}
        for k, lobe in enumerate(lobes, 1):
            if isinstance(lobe, (str, bytes)) or not hasattr(lobe, "__iter__") or len(tuple(lobe)) != 5:
                raise TypeError(f"{owner}(): lobes[{k - 1}] must be a tuple (rho, Cx, Cy, Cz, n) (got {lobe!r})")
            rho, cx, cy, cz, n = tuple(lobe)
            given.update({f"lobe{k}_rho": rho, f"lobe{k}_c": (cx, cy, cz), f"lobe{k}_n": n})
            where.update({f"lobe{k}_{part}": f"lobes[{k - 1}]" for part in ("rho", "c", "n")})
    values = {}
    for p in _LOBE_PARAMS:
        if _lobe_index(p.name) > count:
            values[p.name] = p.validate(_UNUSED[p.name.split("_", 1)[1]])
            continue
        try:
            values[p.name] = p.validate(given[p.name])
        except (TypeError, ValueError) as exc:
            if p.name not in where:
                raise
            part = {"rho": "rho", "c": "Cx, Cy, Cz", "n": "n"}[p.name.split("_", 1)[1]]
            raise type(exc)(f"{where[p.name]} ({part}): {exc}") from None
    return count, values


def lafortune_local(f, d):
    """``(d.t, d.b, d.n)`` (lafortune_lobes.glsl): the local-frame components of directions ``d`` (N, 3)."""
    return np.stack([_dot(d, f.t), _dot(d, f.b), _dot(d, f.n)], axis=-1)


def lafortune_log(m):
    """``ln m`` for ``m > 0``, to a few ulp relative (lafortune_lobes.glsl): ``log_one_minus(1 - m)`` on
    [0.5, 1], ``-log_one_minus((m - 1)/m)`` on (1, 2], ``log(m)`` elsewhere."""

    m = np.asarray(m)
    dtype = m.dtype if m.dtype.kind == "f" else np.dtype(np.float64)
    m = m.astype(dtype)
    one = dtype.type(1.0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        below = log_one_minus(one - m)
        above = -log_one_minus((m - one) / m)
        direct = np.log(m)
    return np.where(m < 0.5, direct, np.where(m <= 1, below, np.where(m <= 2, above, direct))).astype(dtype)


def _lobe_parts(l, v, c):
    """The generalised chord form's pieces: ``(m, ok, u, delta)`` (see `lafortune_lobe`)."""

    dtype = np.result_type(l, v)
    c = np.asarray(c, dtype=dtype)
    m = np.max(np.abs(c))
    c_ok = bool(m > 0)
    m_safe = m if c_ok else dtype.type(1.0)
    c_hat = (c / m_safe).astype(dtype)
    a = np.abs(c_hat)
    k = ((1 - a) * (1 + a)).astype(dtype)
    l2 = (l * l).astype(dtype)
    u = (_dot(l2, k) / np.maximum(np.sum(l2, axis=-1), dtype.type(1e-30))).astype(dtype)
    w_ok, w, _ = safe_normalize((c_hat * l).astype(dtype))
    e = w - v
    delta = (0.5 * _dot(e, e)).astype(dtype)
    ok = c_ok & w_ok & (u < 1) & (delta < 1)
    return m_safe, ok, u, delta


def lafortune_lobe(l, v, c, q):
    """``max(Cx l_x v_x + Cy l_y v_y + Cz l_z v_z, 0)^q`` in the generalised chord form (lafortune_lobes.glsl).

    Parameters
    ----------
    l, v : (N, 3) ndarray
        Local-frame components of the unit directions (`lafortune_local`).
    c : (3,) array_like
        ``(Cx, Cy, Cz)``.
    q : float
        Exponent >= 0.

    Returns
    -------
    (N,) ndarray
        ``exp(clip(q (ln m + ln(1 - u)/2 + ln(1 - delta)), -104, 88))``; 1 for ``q = 0``; 0 where
        ``x <= 0`` or ``C o l = 0``.
    """

    m, ok, u, delta = _lobe_parts(l, v, c)
    dtype = delta.dtype
    q = dtype.type(q)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        log_x = (lafortune_log(m) + dtype.type(0.5) * log_one_minus(np.where(ok, u, 0).astype(dtype))) \
            + log_one_minus(np.where(ok, delta, 0).astype(dtype))
        value = np.exp(np.clip(q * log_x, dtype.type(LAFORTUNE_EXP_MIN), dtype.type(LAFORTUNE_EXP_MAX)))
    value = np.where(ok, value, 0)
    return np.where(q == 0, 1, value).astype(dtype)


def _lobe_band(l, v, c, q, constants):
    """Interval of float32 values of one lobe consistent with the float64 twin (see `LafortuneLobes.band`)."""

    if q == 0:
        one = np.ones(len(l))
        return one, one
    m, ok, u, delta = _lobe_parts(l, v, c)
    if not np.max(np.abs(np.asarray(c, dtype=np.float64))) > 0:
        zero = np.zeros(len(l))
        return zero, zero
    c_hat = np.asarray(c, dtype=np.float64) / m
    w_ok, _, _ = safe_normalize(c_hat * l)
    # the direction part, w.v = 1 - delta: the chord widened by C eps times the conditioning of w
    scale = 1.0 / np.sqrt(np.maximum(1.0 - u, np.finfo(np.float64).tiny))
    d_low, d_high = lobe_band(np.where(w_ok, delta, 2.0), q, scale, constants)
    # the magnitude part m^q (1 - u)^(q/2): u moved by an angle error D eps of l (|grad u| <= 2 sqrt(u (1 - u)))
    # and by its rounding (A eps relative), then the logarithms' rounding (B eps per unit of n |ln|)
    du = EPS * (2 * constants.D * np.sqrt(u * (1 - u)) + constants.A * u) + (constants.D * EPS) ** 2
    u_low, u_high = np.maximum(u - du, 0.0), np.minimum(u + du, 1.0)
    ln_m = float(np.log(m))
    with np.errstate(divide="ignore", invalid="ignore"):
        # (1 - u is at least eps where the GPU can still see a non-zero lobe)
        rel = EPS * constants.B * q * (abs(ln_m) + 0.5 * np.abs(np.log1p(-np.minimum(u, 1.0 - EPS))))
        e_low = np.log(d_low) + q * (ln_m + 0.5 * np.log1p(-u_high))
        e_high = np.log(d_high) + q * (ln_m + 0.5 * np.log1p(-u_low))
        low = np.exp(np.minimum(e_low, LAFORTUNE_EXP_MAX)) * np.maximum(1.0 - rel, 0.0)
        high = np.exp(np.clip(e_high, LAFORTUNE_EXP_MIN, LAFORTUNE_EXP_MAX)) * (1.0 + rel)
    low = np.nan_to_num(low, nan=0.0)
    high = np.nan_to_num(high, nan=np.exp(LAFORTUNE_EXP_MAX), posinf=np.inf)
    return low, high


class LafortuneLobes(MaterialModel):
    """The generalised cosine lobes alone: ``f_r = sum_i rho_i max(C_i . (l o v), 0)^(n_i)`` (local frame).

    Parameters
    ----------
    lobes : sequence of 1 to 4 tuples ``(rho, Cx, Cy, Cz, n)``
        ``rho`` rgb or scalar >= 0 [1/sr], the lobe's scale (with ``C = (-1, -1, 1)`` and
        ``rho = rho_s (n + 2)/(2 pi)`` the normalised Phong lobe); ``Cx, Cy, Cz`` finite reals; ``n`` in
        [0, 1e6].  Instead of ``lobes``, the per-lobe keywords ``lobe<k>_rho``, ``lobe<k>_c`` (the triple
        ``(Cx, Cy, Cz)``) and ``lobe<k>_n`` for k = 1..count (what `parameter_values` returns).
    ka : float or (3,) array_like, optional
        Constant term [W/(m^2 sr)], >= 0.
    two_sided : bool, optional

    Attributes
    ----------
    lobe_count : int
        The number of lobes (the key's ``LAFORTUNE_LOBES_COUNT``).
    lobes : tuple of tuples ``(rho, Cx, Cy, Cz, n)``
        The validated lobes (``rho`` a 3-tuple).
    """

    name = "lafortune_lobes"
    params = _LOBE_PARAMS
    needs = ("view", "tangent")
    glsl = GlslFile("materials/lafortune_lobes.glsl")
    uses = ("lobe",)
    vanishes_with = ()  # several lobes: the term vanishes where every used lobe's rho is 0 (`vanishes`)
    properties = Properties(reciprocal=True, isotropic=False, energy_conserving=False,
                            condition="not in general (|C o l|^n is unbounded); with C = (-1, -1, 1) and "
                                      "rho_i = rho_s,i (n_i + 2)/(2 pi): where rho_d + sum_i rho_s,i <= 1")

    def __init__(self, lobes=None, *, ka=0.0, two_sided=True, normal_map=None, alpha_mask=None, alpha_blend=None,
                 **per_lobe):
        count, values = _resolve_lobes(type(self).__name__, lobes, per_lobe)
        super().__init__(**values, ka=ka, two_sided=two_sided, normal_map=normal_map, alpha_mask=alpha_mask,
                         alpha_blend=alpha_blend)
        object.__setattr__(self, "lobe_count", count)

    @property
    def lobes(self):
        return tuple((getattr(self, f"lobe{k}_rho"), *getattr(self, f"lobe{k}_c"), getattr(self, f"lobe{k}_n"))
                     for k in range(1, self.lobe_count + 1))

    def _unused_names(self):
        return {name for name in _LOBE_NAMES if _lobe_index(name) > self.lobe_count}

    def defines(self):
        """``(('COUNT', k),)``: the key emits ``LAFORTUNE_LOBES_COUNT k``, the number of lobes the GLSL evaluates."""
        return (("COUNT", str(self.lobe_count)),)

    def active_params(self):
        """The used lobes' params (the unused lobes' uniforms are not read)."""
        unused = self._unused_names()
        return tuple(p for p in self.params if p.name not in unused)

    def vanishes(self):
        """True where every used lobe's ``rho`` is 0 in every channel."""
        return not any(np.any(getattr(self, f"lobe{k}_rho")) for k in range(1, self.lobe_count + 1))

    def parameter_values(self):
        unused = self._unused_names()
        return {k: v for k, v in super().parameter_values().items() if k not in unused}

    @classmethod
    def example(cls, **overrides):
        """An instance with `EXAMPLE_LOBES` (an off-specular forward lobe and a retro-reflective one), with
        ``overrides`` (``lobes=`` or per-lobe keywords)."""
        if "lobes" in overrides:
            return cls(**overrides)
        base = {}
        for k, (rho, cx, cy, cz, n) in enumerate(EXAMPLE_LOBES, 1):
            base.update({f"lobe{k}_rho": rho, f"lobe{k}_c": (cx, cy, cz), f"lobe{k}_n": n})
        return cls(**(base | overrides))

    def response(self, f, wi, wo, n_dot_l, p):
        l = lafortune_local(f, wi)
        v = lafortune_local(f, wo)
        fr = 0
        for k in range(1, self.lobe_count + 1):
            lobe = lafortune_lobe(l, v, getattr(p, f"lobe{k}_c"), getattr(p, f"lobe{k}_n"))
            fr = fr + getattr(p, f"lobe{k}_rho") * lobe[..., None]
        return fr * np.asarray(n_dot_l)[..., None]

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """The sum of the lobes' bands times ``n.l +- D eps``, widened by ``(k + 1) eps`` (k lobes).

        Each lobe: the direction part ``(w.v)^n`` is `glphong.checks.tolerances.lobe_band` of ``delta`` with the
        chord widening ``C eps`` scaled by the conditioning ``1/sqrt(1 - u)`` of the peak direction ``w``;
        the magnitude ``m^n (1 - u)^(n/2)`` takes ``u`` moved by ``eps (2 D sqrt(u (1 - u)) + A u)`` (an
        angle error ``D eps`` of ``l``, and the rounding of ``u``) and a relative ``B eps n (|ln m| +
        |ln(1 - u)|/2)`` (the logarithms); the clamp of the exponent at [-104, 88] is applied to both ends.
        Model-specific because the generic default does not perturb ``C`` and cannot see the rounding of
        ``ln m`` and ``ln(1 - u)`` where they cancel (an off-specular peak with ``|C o l| = 1``).  For
        ``|Cx| = |Cy| = |Cz|`` it is the Phong lobe band (``u = 0``)."""

        tol = constants.D * EPS
        l = lafortune_local(f, wi)
        v = lafortune_local(f, wo)
        low = np.zeros(np.shape(wi))
        high = np.zeros(np.shape(wi))
        for k in range(1, self.lobe_count + 1):
            rho = np.asarray(getattr(p, f"lobe{k}_rho"), dtype=np.float64)
            lo, hi = _lobe_band(l, v, np.asarray(getattr(p, f"lobe{k}_c"), dtype=np.float64),
                                float(getattr(p, f"lobe{k}_n")), constants)
            with np.errstate(invalid="ignore", over="ignore"):
                low = low + np.nan_to_num(rho * lo[..., None], nan=0.0)
                high = high + np.where(rho == 0, 0.0, rho * hi[..., None])
        rel = (self.lobe_count + 1) * EPS
        with np.errstate(invalid="ignore", over="ignore"):
            low = low * (np.maximum(n_dot_l - tol, 0.0)[..., None] * (1 - rel))
            high = high * (np.maximum(n_dot_l + tol, 0.0)[..., None] * (1 + rel))
        high = np.nan_to_num(high, nan=0.0)
        return low, np.where(high > FLT_MAX, np.inf, high)

    def oracle(self, f, wi, wo, n_dot_l, p):
        """The paper's formula in mpmath: ``sum_i rho_i max(x_i, 0)^(n_i) (n.l)``, ``x_i`` the dot product as
        written (no stabilisation), ``0^0 := 1``; the frame's ``t`` where the tangent is along ``n`` is Duff
        et al.'s basis vector, as common.glsl."""
        import mpmath

        n, t, b = f.n, f.t, f.b
        if t is None:  # the tangent was parallel to n: the shader's fallback basis (common.glsl)
            s = 1 if n[2] >= 0 else -1
            a = -1 / (s + n[2])
            t = [1 + s * n[0] * n[0] * a, s * n[0] * n[1] * a, -s * n[0]]
            b = [n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]]
        local = lambda d: [sum(x * y for x, y in zip(d, e)) for e in (t, b, n)]  # noqa: E731
        l, v = local(wi), local(wo)
        out = [mpmath.mpf(0)] * 3
        for k in range(1, self.lobe_count + 1):
            c, q = getattr(p, f"lobe{k}_c"), getattr(p, f"lobe{k}_n")
            x = sum(ci * li * vi for ci, li, vi in zip(c, l, v))
            lobe = mpmath.mpf(1) if q == 0 else (x ** q if x > 0 else mpmath.mpf(0))
            out = [o + r * lobe for o, r in zip(out, getattr(p, f"lobe{k}_rho"))]
        return [o * n_dot_l for o in out]

    @classmethod
    def stability_cases(cls):
        """Generic geometry; a Phong-type lobe (``C = (-1, -1, 1)``) at ``n = 1e3`` and ``1e6`` at, near and
        in the tail of its peak; off-specular, retro-reflective (at ``l = v``) and anisotropic lobes at
        their peaks; four lobes; ``n = 0`` where ``x < 0``; ``C = 0``; a saturating lobe (``|C| = 2``,
        ``n = 1e6``: outside the valid range, finite)."""
        return lafortune_cases("lafortune")


class Lafortune(MaterialSum):
    """The Lafortune et al. (1997) model: ``f_r = rho_d / pi + sum_i rho_i max(C_i . (l o v), 0)^(n_i)``.

    Parameters
    ----------
    rho_d : float or (3,) array_like
        Diffuse albedo, dimensionless, in [0, 1].
    lobes : sequence of 1 to 4 tuples ``(rho, Cx, Cy, Cz, n)``
        As in `LafortuneLobes` (or the per-lobe keywords ``lobe<k>_rho``, ``lobe<k>_c``, ``lobe<k>_n``).
    ka : float or (3,) array_like, optional
        Constant term [W/(m^2 sr)], >= 0.
    two_sided : bool, optional
    """

    name = "lafortune"
    terms = (Diffuse, LafortuneLobes)
    properties = Properties(reciprocal=True, isotropic=False, energy_conserving=False,
                            condition="not in general; with C = (-1, -1, 1) and rho_i = rho_s,i (n_i + 2)/(2 pi) "
                                      "for every lobe: where rho_d + sum_i rho_s,i <= 1 per channel")

    def __init__(self, rho_d, lobes=None, *, ka=0.0, two_sided=True, normal_map=None, alpha_mask=None, alpha_blend=None,
                 **per_lobe):
        count, values = _resolve_lobes(type(self).__name__, lobes, per_lobe)
        used = {k: v for k, v in values.items() if _lobe_index(k) <= count}
        parts = (Diffuse(rho_d, two_sided=two_sided), LafortuneLobes(**used, two_sided=two_sided))
        object.__setattr__(self, "_parts", parts)
        self._set_common(ka, two_sided, normal_map, alpha_mask, alpha_blend)

    @property
    def lobe_count(self):
        return self._parts[1].lobe_count

    @property
    def lobes(self):
        return self._parts[1].lobes

    def parameter_values(self):
        unused = self._parts[1]._unused_names()
        return {k: v for k, v in super().parameter_values().items() if k not in unused}

    @classmethod
    def example(cls, **overrides):
        """``Lafortune(0.3, EXAMPLE_LOBES)`` with ``overrides``."""
        values = {"rho_d": 0.3} | overrides
        if "lobes" not in values and not set(values) & set(_LOBE_NAMES):
            values["lobes"] = EXAMPLE_LOBES
        return cls(**values)


def _peak_eye(c, light):
    """The lobe's peak direction ``(C o l)/|C o l|`` for the light direction ``light`` (local = world frame)."""
    w = np.asarray(c, dtype=np.float64) * np.asarray(light, dtype=np.float64)
    return tuple(float(x) for x in w / np.linalg.norm(w))


def lafortune_cases(label):
    """The stability cases of the Lafortune lobes (list of `glphong.checks.stability.Case`); normal +z, tangent +x."""

    e_one = 4 * np.pi  # a point light at 1 m: E = 1 W/m^2
    light = _unit(30.0)
    point = (("point", light, e_one),)
    cases = generic_cases(label, Lafortune(0.2, EXAMPLE_LOBES))
    for n in (1e3, 1e6):
        width = 1.0 / np.sqrt(n)
        material = Lafortune(0.1, [(1.0, -1.0, -1.0, 1.0, n)])
        for where, offset in (("peak", 0.0), ("near", 0.7 * width), ("tail", 3.0 * width)):
            cases.append(Case(f"{label} phong-type C=(-1,-1,1) n={n:g} {where}", "lobe", material,
                              eye=_mirror_eye(30.0, offset), lights=point,
                              note="the chord form: exact at the peak" if where == "peak" else ""))
    off = (-1.1, -1.1, 0.9)
    light60 = _unit(60.0)
    material = Lafortune(0.1, [(0.5, *off, 50.0)])
    cases.append(Case(f"{label} off-specular C={off} n=50 peak", "lobe", material, eye=_peak_eye(off, light60),
                      lights=(("point", light60, e_one),), note="peak toward grazing from the mirror direction"))
    cases.append(Case(f"{label} off-specular C={off} n=50 mirror", "lobe", material, eye=_mirror_eye(60.0, 0.0),
                      lights=(("point", light60, e_one),)))
    retro = Lafortune(0.1, [(0.5, 0.98, 0.98, 0.98, 100.0)])
    cases.append(Case(f"{label} retro-reflective C=0.98 n=100 at l = v", "lobe", retro, eye=light, lights=point,
                      note="the peak 0.98^100 = 0.13: the magnitude m^n by lafortune_log"))
    cases.append(Case(f"{label} retro-reflective C=0.98 n=100 0.1 rad from l = v", "lobe", retro,
                      eye=_unit(30.0 + np.degrees(0.1)), lights=point))
    aniso = (-1.0, -0.8, 1.0)
    material = Lafortune(0.1, [(0.5, *aniso, 100.0)])
    cases.append(Case(f"{label} anisotropic C={aniso} n=100 peak", "lobe", material, eye=_peak_eye(aniso, light),
                      lights=point))
    turned = _unit(30.0, 40.0)
    cases.append(Case(f"{label} anisotropic C={aniso} n=100 peak, light at azimuth 40", "lobe", material,
                      eye=_peak_eye(aniso, turned), lights=(("point", turned, e_one),),
                      note="|C o l| < 1 off the tangent: the lobe's magnitude depends on the azimuth"))
    four = Lafortune(0.1, [(0.8, -1.0, -1.0, 1.0, 100.0), (0.2, -1.05, -1.05, 0.95, 20.0),
                           (0.1, 0.9, 0.9, 0.9, 5.0), ((0.0, 0.3, 0.6), -0.6, -0.9, 1.0, 2.0)])
    cases.append(Case(f"{label} four lobes near the mirror direction", "lobe", four, eye=_mirror_eye(30.0, 0.05),
                      lights=point))
    cases.append(Case(f"{label} n=0 where x < 0", "lobe", Lafortune(0.1, [(0.5, -1.0, -1.0, 1.0, 0.0)]),
                      eye=_unit(60.0, 90.0), lights=(("point", _unit(80.0), e_one),),
                      note="0^0 := 1: the constant lobe, no pow(0, 0)"))
    cases.append(Case(f"{label} C=(0,0,0) n=2", "lobe", Lafortune(0.1, [(0.5, 0.0, 0.0, 0.0, 2.0)]),
                      eye=_unit(20.0, 90.0), lights=point, note="x = 0 everywhere: the lobe is 0"))
    cases.append(Case(f"{label} saturating C=2 n=1e6 at l = v", "lobe",
                      Lafortune(0.1, [((1.0, 0.0, 0.5), 2.0, 2.0, 2.0, 1e6)]), eye=light, lights=point, in_range=False,
                      note="2^1e6 beyond float32: the lobe saturates at e^88, a zero channel stays 0"))
    return cases
