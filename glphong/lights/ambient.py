"""The ambient light ``L_a`` of the lecture's term ``k_d L_a`` (docs/design.md E6).  Not a light kind: no
direction reaches a point from it; the materials that answer it add ``k L_a`` (their ``ambient`` parameter)."""
from dataclasses import dataclass

from glphong.core import validate as _validate

__all__ = ["AmbientLight"]


@dataclass(frozen=True)
class AmbientLight:
    """Ambient illumination ``L_a`` [W/m^2] of the term ``k_d L_a`` (docs/design.md E6).

    Parameters
    ----------
    radiance : float or (3,) array_like
        ``L_a`` per RGB channel, >= 0.
    """

    radiance: tuple

    def __post_init__(self):
        object.__setattr__(self, "radiance", _validate.rgb("radiance", self.radiance))
