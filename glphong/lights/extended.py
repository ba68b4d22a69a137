"""Extended lights: kinds that integrate over a solid angle, the lecture's continuous version (docs/design.md
section 13).

The reflected radiance of an extended light is ``L_r(wo) = integral f_r(wi, wo) L_i(wi) (n.wi)^+ dwi``.  An extended
kind is an `ExtendedLight` subclass and gives it three ways, each a GLSL function and its numpy twin:

- ``vec3 <kind>_irradiance(vec3 x, vec3 n, int j)`` (twin ``irradiance(self, x, n, p)``): the irradiance ``E(n) =
  integral L_i(w) (n.w)^+ dw`` [W/m^2], which a term of `glphong.definitions.material.Integral` form 'irradiance'
  (Lambert) reflects as ``k E``;
- ``vec3 <kind>_lobe(vec3 x, vec3 n, vec3 r, float q, int j)`` (twin ``lobe(self, x, n, r, q, p)``), where the kind
  lists 'lobe' in `integrals`: ``integral max(r.w, 0)^q L_i(w) [n.w > 0] dw`` [W/(m^2 sr) sr] for an integer ``q``,
  which the lecture's Phong lobe (form 'lobe') reflects as ``k_s`` times it;
- ``bool <kind>_sample(vec3 x, vec3 n, int j, int k, out vec3 wi, out vec3 irradiance)`` (twin ``sample(self, x, n,
  k, p)``): weighted direction ``k`` of ``<KIND>_MAX_SAMPLES``, whose sum ``sum_k [n.wi_k > 0] response(wi_k) E_k``
  approximates the integral for every other term (valid false beyond the light's own `sample_count`).

A kind also gives its float64 exact integral (`exact`: an adaptive quadrature converged to a stated tolerance,
`glphong.twin.quadrature`), which `glphong.verify` compares the method with (the method error map), apart from the
float32 band of the GPU against the twin.
"""
from glphong.definitions.light import ContractFunction, LightModel, Param, sensitivity_band
from glphong.definitions.cases import Case
from glphong.materials.lambert import Lambert
from glphong.materials.phong import Phong, PhongLobe

__all__ = ["ExtendedLight", "IRRADIANCE", "LOBE", "SAMPLE", "SAMPLES", "CENTER", "RADIUS", "RADIANCE", "extended_cases"]

#: E(n) at x: what a Lambert term reflects, times its k_d
IRRADIANCE = ContractFunction("irradiance", "vec3 (irradiance (N, 3) [W/m^2])", ("vec3 x", "vec3 n", "int j"),
                              ("x", "n", "p"))
#: the Phong lobe's integral about r (integer q)
LOBE = ContractFunction("lobe", "vec3 (lobe integral (N, 3) [W/m^2])", ("vec3 x", "vec3 n", "vec3 r", "float q", "int j"),
                        ("x", "n", "r", "q", "p"))
#: weighted direction k, for the terms without a closed form
SAMPLE = ContractFunction("sample", "bool (valid (N,) bool, wi (N, 3) unit vectors, irradiance (N, 3) [W/m^2])",
                          ("vec3 x", "vec3 n", "int j", "int k", "out vec3 wi", "out vec3 irradiance"),
                          ("x", "n", "k", "p"))
#: the parameters the area kinds share
CENTER = Param("center", "vec3", low=-float("inf"), unit="m", doc="centre")
RADIUS = Param("radius", "scalar", low=0.0, low_inclusive=False, unit="m", doc="radius")
RADIANCE = Param("radiance", "rgb", low=0.0, unit="W/(m^2 sr)", doc="emitted radiance, uniform over the light")
#: the sampled method's knob, shared by the area kinds
SAMPLES = Param("samples", "scalar", low=1.0, high=64.0, default=4.0,
                doc="cells per side of the sampled method (an integer; the terms without a closed form)")


class ExtendedLight(LightModel):
    """Base of the extended kinds (area and environment lights; docs/design.md section 13).

    Every extended light takes ``method='auto'`` (the closed forms where a term has one) or ``'sampled'`` (every term
    over its weighted directions: the knob `glphong bench` compares the closed forms with).

    Class attributes a definition sets besides `LightModel`'s
    -----------------------------------------------------------
    integrals : tuple of str
        The closed forms its GLSL defines: 'irradiance' (always) and 'lobe' (optional).

    Methods a definition provides
    -----------------------------
    irradiance(self, x, n, p), lobe(self, x, n, r, q, p), sample(self, x, n, k, p)
        The twins of the GLSL functions (module docstring); ``x``, ``n``, ``r`` (N, 3), ``q`` a number, ``k`` an int.
    sample_count(self)
        How many weighted directions this light gives (``<KIND>_MAX_SAMPLES`` is the scene's largest).
    exact(self, x, n, p, integrand, clip=())
        The float64 integral ``integral integrand(index, w) L_i(w) [n.w > 0] dw`` over the light, with ``clip``
        planes through ``x``: ``(value (N, 3), error (N,), converged (N,))`` (`glphong.twin.quadrature`).
    irradiance_band, lobe_band, sample_band  (optional)
        Intervals of the float32 results; default: the generic sensitivity band (`sensitivity_band`) of the twin.
    """

    extent = "extended"
    integrals = ("irradiance",)
    #: the closed forms among `integrals` that are the exact integral when evaluated in float64 (a 'lobe' for whole
    #: exponents q only): `glphong.verify`'s exact image takes them in place of the quadrature (`closed_form_is_exact`)
    exact_integrals = ()
    exact_uniforms = ("samples",)
    abstract_contract = True

    @classmethod
    def contract(cls):
        return (IRRADIANCE,) + ((LOBE,) if "lobe" in cls.integrals else ()) + (SAMPLE,)

    def __init__(self, *args, method="auto", **kwargs):
        if method not in ("auto", "sampled"):
            raise ValueError(f"method must be 'auto' (the closed forms where a term has one) or 'sampled' (every term "
                             f"over the light's weighted directions) (got {method!r})")
        object.__setattr__(self, "method", method)
        super().__init__(*args, **kwargs)

    def parameter_values(self):
        return super().parameter_values() | {"method": self.method}

    #: methods a definition must give besides its contract's twins (checked when the class is made): its exact
    #: integral, which `glphong.verify` and the stability suite compare the methods with
    required_methods = ("exact",)

    def closed_form_is_exact(self, form, q=None):
        """Whether the closed form ``form`` ('irradiance', or 'lobe' of exponent ``q``) is the exact integral
        (`exact_integrals`; a lobe only for whole ``q``)."""
        return form in self.exact_integrals and (form != "lobe" or float(q).is_integer())

    @classmethod
    def key_integrals(cls, lights=()):
        """The kind's closed forms, or none where one of the scene's lights of the kind asks ``method='sampled'`` (the
        program then samples every term under every light of the kind)."""
        return () if any(light.method == "sampled" for light in lights) else tuple(cls.integrals)

    @classmethod
    def structural_defines(cls, lights):
        """``MAX_SAMPLES``: the largest `sample_count` of the scene's lights of the kind (the sampled loop's bound)."""
        return (("MAX_SAMPLES", str(max(light.sample_count() for light in lights))),)

    @classmethod
    def stability_cases(cls):
        """The kind's extreme cases (`extended_cases`); none by default.  The suite's expected value is the kind's
        `exact` integral of the terms' float64 twins (`glphong.checks.stability.oracle`)."""
        return ()

    def check(self):
        samples = getattr(self, "samples", 1.0)
        if not float(samples).is_integer():
            raise ValueError(f"samples must be a whole number of cells per side, 1 to 64 (got {samples!r})")

    def sample_count(self):
        """The number of weighted directions of this light (default ``samples^2``)."""
        return int(self.samples) ** 2

    # ---- the bands (generic: the twin's sensitivity to a few ulps of its inputs, the normal and the axis included)
    def irradiance_band(self, x, n, p, constants):
        """Interval of the float32 ``<kind>_irradiance``: ``(low, high)``, each (N, 3)."""
        return sensitivity_band(lambda x_, p_, n_: self.irradiance(x_, n_, p_), x, p, self.perturbed_uniforms(), constants,
                                (n,))

    def lobe_band(self, x, n, r, q, p, constants):
        """Interval of the float32 ``<kind>_lobe``: ``(low, high)``, each (N, 3)."""
        return sensitivity_band(lambda x_, p_, n_, r_: self.lobe(x_, n_, r_, q, p_), x, p,
                                self.perturbed_uniforms(), constants, (n, r))

    def sample_band(self, x, n, k, p, constants):
        """Interval of the float32 irradiance of ``<kind>_sample`` ``k``: ``(low, high)``, each (N, 3)."""
        return sensitivity_band(lambda x_, p_, n_: self.sample(x_, n_, k, p_)[2], x, p,
                                self.perturbed_uniforms(), constants, (n,))



def extended_cases(kind, cases):
    """Stability cases of an extended kind at the origin: ``cases`` are ``(label, light, normal)`` shaded by the
    lecture's Phong (k_d 0.3, k_s 0.4, q 20) where the kind has the lobe in closed form, else by Lambert (k_d 0.3),
    seen from (0.3, 0.2, 2), and ``(label, light, q)`` with ``q`` a number: the Phong lobe alone (k_s 0.5) seen along
    the normal (0, 0, 1), ``r_v = n``.  Every term is in closed form, so the expected value is the exact integral (a
    sampled term's own error is the method error map's, `glphong.verify`).  A fourth element overrides the material."""
    out = []
    for label, light, third, *given in cases:
        material = given[0] if given else Phong(0.3, 0.4, 20.0) if "lobe" in type(light).integrals else Lambert(0.3)
        if isinstance(third, (int, float)):
            out.append(Case(f"{kind} light, {label}", f"light {kind}", PhongLobe(0.5, float(third)), normal=(0.0, 0.0, 1.0),
                            eye=(0.0, 0.0, 2.0), lights=(light,)))
        else:
            out.append(Case(f"{kind} light, {label}", f"light {kind}", material,
                            normal=tuple(float(c) for c in third), eye=(0.3, 0.2, 2.0), lights=(light,)))
    return tuple(out)
