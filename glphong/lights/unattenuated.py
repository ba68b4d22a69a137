"""The kind 'unattenuated': the lecture's assignment light, a position and a value ``L_i`` used as the
irradiance at every distance (docs/design.md E2, section 11; GLSL: ``glsl/lights/unattenuated.glsl``).
No glTF or pyrender light has it (both always fall off as ``1/d^2``)."""
import numpy as np

from glphong.definitions.light import ExactIrradiance, GlslFile, LightModel, Param, mp32, mp_toward
from glphong.lights.point import POSITION
from glphong.twin.functions import safe_normalize

__all__ = ["UnattenuatedPointLight"]


class UnattenuatedPointLight(ExactIrradiance, LightModel):
    """A positional light of value ``L_i`` with no distance falloff (docs/design.md E2): ``E = L_i`` at every
    distance.

    Parameters
    ----------
    position : (3,) array_like
        World-space position [m].
    radiance : float or (3,) array_like
        The lecture's ``L_i``, used as the irradiance ``E`` [W/m^2] at every distance, >= 0.
    """

    name = "unattenuated"
    loop_order = 1
    params = (POSITION, Param("radiance", "rgb", low=0.0, unit="W/m^2", doc="the lecture's L_i, used as E"))
    glsl = GlslFile("lights/unattenuated.glsl")
    in_uber = True
    numerics_bounds = {"light": "position"}

    def incident(self, x, p):
        valid, wi, _ = safe_normalize(p.position - x)
        return valid, wi, np.broadcast_to(p.radiance, np.shape(x))

    def oracle(self, x):
        wi, _ = mp_toward(mp32(self.position), x)
        return None if wi is None else (wi, mp32(self.radiance))

    @classmethod
    def stability_cases(cls):
        """None of its own: the suite's group 'dynamic range' has it."""
        return ()
