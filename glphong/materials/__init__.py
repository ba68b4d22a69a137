"""Materials: the lecture's Material class as open definitions (docs/design.md section 8).

Every material is a sum of terms; each term is a `MaterialModel` (a reflectance model: its
parameters, GLSL response, numpy twin, band, properties and stability cases).  The built-ins use
the same public mechanism a user's model does:

The lecture's models (``kd``, ``ks`` are BRDF values [1/sr]):

- `Lambert` (model ``lambert``): ``k_d (n.l)``;
- `PhongLobe` (``phong_lobe``) and `Phong` = ``Lambert + PhongLobe``: ``k_d (n.l) + k_s (v.r)^q``;
- `BlinnLobe` (``blinn_lobe``) and `BlinnPhong` = ``Lambert + BlinnLobe``: ``k_d (n.l) + k_s (n.h)^q``.

The physically based models of docs/design.md section 9 (``rho_*`` are albedos, dimensionless in [0, 1]):

- `Diffuse` (``diffuse``): ``rho_d / pi``, the diffuse term of the sums below;
- `NormalizedPhong` = ``Diffuse + NormalizedPhongLobe`` (Lafortune and Willems 1994) and
  `NormalizedBlinnPhong` = ``Diffuse + NormalizedBlinnLobe`` (exact normalisation);
- `CookTorrance` = ``Diffuse + CookTorranceLobe`` (Beckmann, Torrance-Sparrow; microfacet or 1982 form);
- `Lafortune` = ``Diffuse + LafortuneLobes`` (1 to 4 generalised cosine lobes, Lafortune et al. 1997);
- `OrenNayar` (``oren_nayar``): rough diffuse, full (with inter-reflection) or qualitative (1994);
- `Ward` = ``Diffuse + WardLobe`` (anisotropic; Walter's, Duer's or the bounded normalisation);
- `AshikhminShirley` (``ashikhmin_shirley``): anisotropic Phong with Schlick Fresnel and coupled diffuse (2000).

Measured: `MeasuredBRDF` (``measured_brdf``): a MERL table (Matusik et al. 2003) sampled from a 3D texture,
nearest bin as the reference reader or trilinear; ``MeasuredBRDF.from_model`` tabulates any material.

Fresnel factors `SchlickFresnel(f0)` and `DielectricFresnel(ior)` are the ``fresnel=`` of the glossy
models (`Phong`, `BlinnPhong`, the normalised ones, `CookTorrance`); each model states its cosine.
``ka`` is a constant radiance [W/(m^2 sr)].  Define your own with `MaterialModel`, `Param`, `Table`, `Choice`
and `FresnelSlot` (see README, "Write your own material").
"""
from glphong.definitions.discovery import import_definitions
from glphong.definitions.material import Choice, GlslFile, Material, MaterialDefinitionError, MaterialModel, MaterialSum, Param, ParamValues, Properties, ShadingFrame, model_named, registered_models
from glphong.definitions.surface import AlphaBlend, AlphaMask, NormalMap, SurfaceInput, Texture, TextureImage, VertexColors
from glphong.definitions.table import Table, TableData
from glphong.definitions.cases import Case
from glphong.definitions.fresnel import DielectricFresnel, Fresnel, FresnelSlot, SchlickFresnel
from glphong.definitions.params import DefinitionError

__all__ = ["Material", "MaterialModel", "MaterialSum", "Param", "Choice", "Table", "TableData", "ParamValues",
           "Properties", "ShadingFrame", "MaterialDefinitionError", "GlslFile", "registered_models", "model_named",
           "SurfaceInput", "Texture", "TextureImage", "VertexColors", "NormalMap", "AlphaMask", "AlphaBlend", "Fresnel",
           "SchlickFresnel", "DielectricFresnel", "FresnelSlot", "Case", "DefinitionError"]

# every module of this package is one model (the mechanism is glphong.definitions): importing it registers the
# model, and the material classes it exports are this package's, so a new model is one file here (with its GLSL
# and its tests); its twin functions stay in its module (and are found by glphong.reference)
import_definitions(__name__, __path__, globals(), __all__)
