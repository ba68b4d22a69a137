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
import importlib as _importlib
import pkgutil as _pkgutil

from .model import (Choice, GlslFile, Material, MaterialDefinitionError, MaterialModel, MaterialSum, Param, ParamValues,
                    Properties, ShadingFrame, model_named, registered_models)

__all__ = ["Material", "MaterialModel", "MaterialSum", "Param", "Choice", "ParamValues", "Properties", "ShadingFrame",
           "MaterialDefinitionError", "GlslFile", "registered_models", "model_named"]

# every module of this package but the mechanism is one model: importing it registers the model, and
# the material classes it exports are this package's, so a new model is one file here (with its GLSL
# and its tests); its twin functions stay in its module (and are found by glphong.reference)
for _info in sorted(_pkgutil.iter_modules(__path__), key=lambda info: info.name):
    if _info.name != "model":
        _module = _importlib.import_module(f"{__name__}.{_info.name}")
        for _name in _module.__all__:
            if isinstance(getattr(_module, _name), type):
                globals()[_name] = getattr(_module, _name)
                __all__.append(_name)
del _info, _module, _name
