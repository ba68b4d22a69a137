"""The directions a response is evaluated at: `direction_sets` (seeded random pairs and the edge sets where
shaders break), and the closed-form tests' helpers (`frame_around`, `direction`, `rotate_toward`,
`float32_units`, `cosine_power_interval`).
"""
import numpy as np

from glphong.checks.tolerances import EPS

__all__ = ["direction_sets", "frame_around", "direction", "rotate_toward", "float32_units", "cosine_power_interval"]


def _rotate_toward(v, axis, angle):
    """Rotate unit rows ``v`` by ``angle`` [rad] toward the unit rows ``axis`` (perpendicular to v)."""
    return np.cos(angle)[..., None] * v + np.sin(angle)[..., None] * axis


def direction_sets(n=2000, seed=0):
    """Direction pairs that exercise a BRDF: seeded random, and the edges where shaders break.

    With the normal +z: random ``wi``, ``wo`` over the upper hemisphere (and some ``wo`` below it),
    and the edge sets: grazing light (``n.l`` from 1e-2 down to 1e-7, and 0), grazing view, the mirror
    direction (the peak of Phong and Blinn lobes) and small offsets from it, ``l = v`` (the
    retro-reflection peak), ``l = -v`` mirrored at grazing, ``n.l`` just above 0, and light and view
    both so grazing (cosines 1e-30 to 1e-19) that ``(n.l)(n.v)`` is below FLT_MIN.

    Parameters
    ----------
    n : int
        Number of random pairs (the edge sets come on top, about 40 % more).
    seed : int

    Returns
    -------
    wi, wo : (M, 3) float64 ndarray
        Unit vectors.
    labels : (M,) ndarray of str
        Which set each pair belongs to.
    """
    rng = np.random.default_rng(seed)

    def hemisphere(count, lower=False):
        v = rng.normal(size=(count, 3))
        v[:, 2] = np.abs(v[:, 2]) * (-1.0 if lower else 1.0)
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    def at(cos_theta, count):
        phi = rng.uniform(0, 2 * np.pi, count)
        s = np.sqrt(np.maximum(1.0 - cos_theta ** 2, 0.0))
        return np.stack([s * np.cos(phi), s * np.sin(phi), np.broadcast_to(cos_theta, (count,))], axis=1)

    def mirror(wi):
        return wi * np.array([-1.0, -1.0, 1.0])

    sets = []
    k = max(n // 20, 8)
    sets.append(("random", hemisphere(n), hemisphere(n)))
    sets.append(("view below the surface", hemisphere(k), hemisphere(k, lower=True)))
    for cosine in (1e-2, 1e-4, 1e-6, 1e-7, 0.0):
        sets.append((f"grazing light n.l={cosine:g}", at(np.full(k, cosine), k), hemisphere(k)))
    for cosine in (1e-2, 1e-4, 1e-6):
        sets.append((f"grazing view n.v={cosine:g}", hemisphere(k), at(np.full(k, cosine), k)))
    wi = hemisphere(4 * k)
    sets.append(("mirror direction (lobe peak)", wi, mirror(wi)))
    for offset in (1e-6, 1e-4, 1e-3, 1e-2, 1e-1):
        wi = hemisphere(k)
        peak = mirror(wi)
        axis = np.cross(peak, rng.normal(size=(k, 3)))
        axis /= np.linalg.norm(axis, axis=1, keepdims=True)
        sets.append((f"near the mirror direction, {offset:g} rad", wi, _rotate_toward(peak, axis, np.full(k, offset))))
    wi = hemisphere(2 * k)
    sets.append(("l = v (retro-reflection)", wi, wi.copy()))
    wi = at(np.full(k, 3e-6), k)
    sets.append(("l, v grazing and mirrored", wi, -wi * np.array([1.0, 1.0, -1.0])))
    wi = at(10.0 ** rng.uniform(-7, -3, k), k)
    sets.append(("n.l just above 0", wi, mirror(wi)))
    wi, wo = at(10.0 ** rng.uniform(-30, -19, k), k), at(10.0 ** rng.uniform(-30, -19, k), k)
    sets.append(("l and v grazing, (n.l)(n.v) below FLT_MIN", wi, wo))
    labels = np.concatenate([[label] * len(a) for label, a, _ in sets])
    return np.concatenate([a for _, a, _ in sets]), np.concatenate([b for _, _, b in sets]), labels


# --------------------------------------------------------------------------- closed-form helpers
def frame_around(n):
    """An orthonormal ``(t, b)`` completing the unit normal ``n`` (3,): ``(t, b, n)`` right-handed."""
    n = np.asarray(n, dtype=np.float64)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t = np.cross(n, helper)
    t /= np.linalg.norm(t)
    return t, np.cross(n, t)


def direction(n, theta, phi):
    """The unit vector at polar angle ``theta`` [rad] from the unit ``n`` and azimuth ``phi`` [rad] about it
    (measured from `frame_around`'s ``t``)."""
    t, b = frame_around(n)
    return np.sin(theta) * (np.cos(phi) * t + np.sin(phi) * b) + np.cos(theta) * np.asarray(n, dtype=np.float64)


def rotate_toward(a, target, angle):
    """Unit ``a`` (3,) rotated by ``angle`` [rad] toward ``target``, in their plane."""
    axis = target - np.dot(target, a) * a
    axis /= np.linalg.norm(axis)
    return np.cos(angle) * a + np.sin(angle) * axis


def float32_units(v):
    """Rows of ``v`` normalised in float64 and rounded to float32 (returned as float64): exactly the unit
    vectors `evaluate` hands to the GPU and to the twin."""
    v = np.asarray(v, dtype=np.float64)
    return np.asarray(v / np.linalg.norm(v, axis=-1, keepdims=True), dtype=np.float32).astype(np.float64)


def cosine_power_interval(cos_alpha, q, spread):
    """The interval of float32 values consistent with ``cos(alpha)^q``, for closed-form tests of lobes.

    ``alpha`` is the angle from the lobe's peak; float32 inputs and arithmetic leave it uncertain by
    ``+- spread`` [rad] (a few eps: the caller states it for its lobe); ``exp`` is good to
    ``(3 + 2|x|)`` ulp (GLSL 4.50, 4.7.1) and ``ln(1 - delta)`` to a few ulp relative, so the value is
    widened by ``eps (8 + 12 lambda)`` relative, ``lambda = -ln(value)``.  The caller accepts 0 below
    FLT_MIN (flush to zero).

    Returns
    -------
    low, high : ndarray
    """
    alpha = np.arccos(np.clip(cos_alpha, -1.0, 1.0))
    low = np.cos(np.minimum(alpha + spread, np.pi / 2)) ** q
    high = np.cos(np.maximum(alpha - spread, 0.0)) ** q
    lam = -np.log(np.maximum(low, 1e-300))
    return low * (1 - EPS * (8 + 12 * lam)), high * (1 + EPS * (8 + 12 * lam))
