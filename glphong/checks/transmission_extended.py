"""What the extended lights behind a transmissive surface send through it, in the float64 twin (issue 41;
`glphong.checks.transmission_twin`, docs/transmission.md "Lights").

The generated loop of an extended kind (`glphong.shaders.generated`, ``_extended_loop``) adds, over the kind's
weighted directions ``k`` of each light, for each response behind the surface (KHR_materials_transmission's BTDF,
KHR_materials_diffuse_transmission's)::

    (valid_k && n.wi_k < 0) ? light_term(<response>(f, wi_k, wo, -n.wi_k), E_k) : 0

The kinds' samples do not depend on the normal (the area kinds' points on the light, the environment's fixed
directions over the whole sphere), so those behind the surface are the back hemisphere's.  Each direction is twinned
as a punctual light behind the surface (`glphong.checks.transmission_lights._lights_behind`), its irradiance's interval the kind's
``sample_band``; a light's sum of ``m`` directions is widened by ``(1 +- m eps)``, as
`glphong.checks.tolerances.extended_band` widens the reflected part.
"""
import numpy as np

from glphong.checks.reference import extended_lights
from glphong.twin.band import EPS

__all__ = ["extended_behind"]


def extended_behind(behind, key, u, f, band):
    """``(value, low, high)``, each (N, 3): the sum over the key's extended lights of ``behind(incident)``.

    Parameters
    ----------
    behind : callable
        ``behind(incident)`` -> ``(value, low, high)``, each (N, 3) [W/(m^2 sr)]: what the lights ``incident(x)``
        (at points ``x`` (N, 3): an iterable of ``(valid (N,), wi (N, 3), E (N, 3) [W/m^2], (E_low, E_high))`` as
        `glphong.checks.reference.incident_light` yields them) send through the surface.
    key : glphong.shaders.key.ProgramKey
    u : dict of str to ndarray
        The program's uniforms, float64.
    f : ShadingFrame
        The fragments' frame (``f.n`` (N, 3) unit normals).
    band : glphong.checks.tolerances.BandConstants
    """
    value = low = high = 0.0
    for _, twin, q, _, _ in extended_lights(key, u, np.float64):
        count = int(q.defines["MAX_SAMPLES"])

        def samples(x, twin=twin, q=q, count=count):
            for k in range(count):
                with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                    sample = (*twin.sample(x, f.n, k, q), twin.sample_band(x, f.n, k, q, band))
                yield sample

        v, lo, hi = behind(samples)
        value, low, high = value + v, low + lo * (1.0 - count * EPS), high + hi * (1.0 + count * EPS)
    shape = (len(f.n), 3)
    return tuple(np.broadcast_to(a, shape).copy() for a in (value, low, high))
