"""Materials: the lecture's Material class as open definitions (DESIGN section 8).

Every material is a sum of terms; each term is a `MaterialModel` (a reflectance model: its
parameters, GLSL response, numpy twin, band, properties and stability cases).  The built-ins use
the same public mechanism a user's model does:

- `Lambert` (model ``lambert``): ``k_d (n.l)``;
- `PhongLobe` (``phong_lobe``) and `Phong` = ``Lambert + PhongLobe``: ``k_d (n.l) + k_s (v.r)^q``;
- `BlinnLobe` (``blinn_lobe``) and `BlinnPhong` = ``Lambert + BlinnLobe``: ``k_d (n.l) + k_s (n.h)^q``.

Units: ``kd`` and ``ks`` are BRDF values [1/sr] (an albedo rho gives kd = rho/pi); ``ka`` is a
constant radiance [W/(m^2 sr)]; ``q`` is dimensionless.  Define your own with `MaterialModel` and
`Param` (see README, "Write your own material").
"""
from .model import (GlslFile, Material, MaterialDefinitionError, MaterialModel, MaterialSum, Param, ParamValues,
                    Properties, ShadingFrame, model_named, registered_models)
from .lambert import Lambert
from .phong import Phong, PhongLobe
from .blinn import BlinnLobe, BlinnPhong

__all__ = ["Material", "MaterialModel", "MaterialSum", "Param", "ParamValues", "Properties", "ShadingFrame",
           "MaterialDefinitionError", "GlslFile", "registered_models", "model_named",
           "Lambert", "PhongLobe", "Phong", "BlinnLobe", "BlinnPhong"]
