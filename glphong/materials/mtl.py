"""The model 'mtl_phong': a Wavefront MTL material as the files mean it (GLSL: ``glsl/materials/mtl_phong.glsl``).

An MTL file's ``illum 2`` material is the fixed-function Phong its authors saw: ``colour = Ka L_a +
Kd (n.l) E + Ks max(v.r, 0)^Ns E``.  That is the lecture's model with MTL's numbers taken as they are:
``Kd`` and ``Ks`` are the lecture's ``k_d`` and ``k_s`` (BRDF values per unit irradiance; a white light of
``E = 1 W/m^2`` gives ``Kd (n.l)``), ``Ns`` is ``q``, and ``Ka`` multiplies the ambient light: glphong's
`Lambert` answers ``L_a`` with ``k_d L_a`` and its ``ka`` adds a constant, so this model answers with
``Ka L_a`` instead (its parameter ``kamb``).  `glphong.load_scene` maps ``illum 0`` (colour ``Kd``, no
lighting) to a constant ``ka = Kd`` with no lit terms, ``illum 1`` to ``ks = 0``, ``illum 2`` to this model
as read, and the ray-traced ``illum 3`` to ``10`` to ``illum 2`` with a warning.

=========  ======  ==========  ======  ===================================================
parameter  kind    range       unit    meaning (MTL keyword)
=========  ======  ==========  ======  ===================================================
kd         rgb     >= 0        1/sr    diffuse coefficient ``Kd``
ks         rgb     >= 0        1/sr    specular coefficient ``Ks``
q          scalar  >= 0                specular exponent ``Ns`` (MTL: 0 to 1000)
kamb       rgb     >= 0                ambient coefficient ``Ka``: the answer ``Ka L_a``
=========  ======  ==========  ======  ===================================================

Not reciprocal, not energy-conserving, isotropic (the lecture's Phong; `glphong.analysis` measures it).
"""
from glphong.twin.functions import phong_lobe
from glphong.definitions.material import GlslFile, MaterialModel, Param, Properties

__all__ = ["MtlPhong"]


class MtlPhong(MaterialModel):
    """An MTL material: ``Kd (n.l) + Ks max(v.r, 0)^Ns`` lit, ``Ka L_a`` ambient (see the module).

    Parameters
    ----------
    kd, ks : float or (3,) array_like
        MTL's ``Kd`` and ``Ks`` [1/sr], >= 0.
    q : float
        MTL's ``Ns``, >= 0.
    kamb : float or (3,) array_like
        MTL's ``Ka``, >= 0 (default 0).
    """

    name = "mtl_phong"
    params = (Param("kd", "rgb", low=0.0, unit="1/sr", textureable=True, doc="MTL Kd: Phong's diffuse k_d"),
              Param("ks", "rgb", low=0.0, default=0.0, unit="1/sr", textureable=True, doc="MTL Ks: Phong's specular k_s"),
              Param("q", "scalar", low=0.0, default=1.0, doc="MTL Ns, the Phong exponent"),
              Param("kamb", "rgb", low=0.0, default=0.0, doc="MTL Ka: the ambient answer Ka L_a"))
    needs = ("view",)
    uses = ("lobe",)
    glsl = GlslFile("materials/mtl_phong.glsl")
    ambient = "kamb"
    properties = Properties(reciprocal=False, isotropic=True, energy_conserving=False)

    def response(self, f, wi, wo, n_dot_l, p):
        """Twin of ``mtl_phong_response``: ``kd (n.l) + ks phong_lobe`` (lobe.glsl's twin); (N, 3)."""
        return p.kd * n_dot_l[:, None] + p.ks * phong_lobe(f.n, wi, wo, p.q)[:, None]

    def oracle(self, f, wi, wo, n_dot_l, p):
        """The textbook formula in mpmath: ``kd (n.l) + ks max(v.r, 0)^q`` (``0^0 = 1``)."""
        import mpmath

        r = [2 * n_dot_l * n - l for n, l in zip(f.n, wi)]
        v_dot_r = max(sum(a * b for a, b in zip(wo, r)), mpmath.mpf(0))
        lobe = mpmath.mpf(1) if p.q == 0 else v_dot_r ** p.q
        return [kd * n_dot_l + ks * lobe for kd, ks in zip(p.kd, p.ks)]

    @classmethod
    def example(cls, **overrides):
        return cls(**({"kd": (0.64, 0.2, 0.1), "ks": 0.5, "q": 40.0, "kamb": 0.1} | overrides))
