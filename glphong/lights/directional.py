"""The kind 'directional': a light at infinity, constant direction and irradiance (docs/design.md section 11;
GLSL: ``glsl/lights/directional.glsl``).  glTF's and pyrender's directional lights."""
import numpy as np

from glphong.definitions.light import ExactIrradiance, GlslFile, LightModel, Param, gltf_entry, mp, mp32, mp_dot, pose_pointing

__all__ = ["DirectionalLight"]

_DIRECTION = Param("direction", "direction", low=-1.0, high=1.0, doc="direction the light travels in (any length)")
_IRRADIANCE = Param("irradiance", "rgb", low=0.0, unit="W/m^2", doc="E on a surface facing the light")


class DirectionalLight(ExactIrradiance, LightModel):
    """A light at infinity: constant direction and irradiance, ``E = irradiance`` at every point.

    Parameters
    ----------
    direction : (3,) array_like
        Direction the light travels in (from the light toward the scene), any non-zero length; stored
        normalised.
    irradiance : float or (3,) array_like
        Irradiance ``E`` [W/m^2] on a surface facing the light, >= 0.
    shadows : bool
        Cast shadows (an orthographic shadow map over the scene; default False).
    """

    name = "directional"
    loop_order = 2
    params = (_DIRECTION, _IRRADIANCE)
    uniforms = (Param("towards", "direction", low=-1.0, high=1.0, doc="unit vector toward the light"), _IRRADIANCE)
    glsl = GlslFile("lights/directional.glsl")
    shadow_map = "ortho"
    in_uber = True
    gltf_type = "directional"
    pyrender_type = "DirectionalLight"

    def uniform_value(self, name):
        return tuple(-c for c in self.direction) if name == "towards" else getattr(self, name)

    def incident(self, x, p):
        shape = np.shape(x)
        return np.ones(shape[:-1], bool), np.broadcast_to(p.towards, shape), np.broadcast_to(p.irradiance, shape)

    def oracle(self, x):
        towards = [-mp().mpf(c) for c in self.direction]
        length = mp().sqrt(mp_dot(towards, towards))
        return [c / length for c in towards], mp32(self.irradiance)

    @classmethod
    def stability_cases(cls):
        """None of its own: the suite's group 'dynamic range' has it."""
        return ()

    @classmethod
    def from_gltf(cls, value, entry, pose):
        return cls(tuple(-pose[:3, 2]), tuple(value))

    def to_gltf(self):
        return gltf_entry("directional", self.irradiance), pose_pointing(self.direction)

    @classmethod
    def from_pyrender(cls, value, light, pose):
        return cls(-pose[:3, 2], value)

    def to_pyrender(self, pyrender):
        entry, pose = self.to_gltf()
        return pyrender.DirectionalLight(color=entry["color"], intensity=entry["intensity"]), pose
