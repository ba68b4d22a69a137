"""Lights as open definitions (docs/design.md section 11): the built-in kinds, defined with `LightModel`.

A kind is one module here and one GLSL chunk (``glsl/lights/<name>.glsl``), defined with the mechanism a user's
kind uses (`glphong.definitions.light.LightModel`); the program key counts the lights of each kind generically, and
the shader's loop over each present kind is generated (`glphong.shaders.generated`), in the kinds' `loop_order`.
Every module of this package is discovered and imported, so a new kind is one file here (with its GLSL and its
tests: the conformance harness tests/lights/test_light_conformance.py holds every registered kind).
"""
from glphong.definitions.discovery import import_definitions
from glphong.definitions.light import (LightDefinitionError, LightModel, light_cases, light_for_key, light_named,
                                       pose_pointing, registered_lights)

__all__ = ["LightModel", "LightDefinitionError", "registered_lights", "light_named", "light_for_key", "light_cases",
           "pose_pointing"]

# every module of this package defines kinds (or a family's base, `ExtendedLight`, or the ambient light): importing
# it registers its kinds, and the light classes it exports are this package's
import_definitions(__name__, __path__, globals(), __all__)
