"""Lights as open definitions (docs/design.md section 11): `LightModel` and the built-in kinds, defined with it.

A kind is one module and one GLSL chunk (``glsl/lights/<name>.glsl``); the program key counts the lights of
each kind generically, and the shader's loop over each present kind is generated (`glphong.shaders.generated`).
"""
from glphong.lights.model import (LightDefinitionError, LightModel, light_cases, light_for_key, light_named,
                                  pose_pointing, registered_lights)
from glphong.lights.point import PointLight
from glphong.lights.unattenuated import UnattenuatedPointLight
from glphong.lights.directional import DirectionalLight
from glphong.lights.spot import SpotLight
from glphong.lights.ambient import AmbientLight
from glphong.lights.extended import ExtendedLight
from glphong.lights.area import PolygonLight, RectLight
from glphong.lights.sphere import SphereLight
from glphong.lights.disk import DiskLight
from glphong.lights.environment import EnvironmentLight

__all__ = ["LightModel", "LightDefinitionError", "registered_lights", "light_named", "light_for_key", "light_cases",
           "pose_pointing", "PointLight", "UnattenuatedPointLight", "DirectionalLight", "SpotLight", "AmbientLight",
           "ExtendedLight", "RectLight", "PolygonLight", "SphereLight", "DiskLight",
           "EnvironmentLight"]
