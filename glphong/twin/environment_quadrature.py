"""An independent float64 reference for environment lights: the integral of ``g(w) L(w)`` over an equirectangular
radiance map at many surface points (docs/design.md section 13), sharing no code with the methods it measures
(the irradiance map, the spherical harmonics, the texel samples of `glphong.lights.EnvironmentLight`).

What is integrated
------------------
At a surface point with unit normal ``n``: ``I = sum_k L_k integral over texel k of g(w) [n.w > 0] [c.w > 0] dw``,
each texel ``k`` a constant radiance ``L_k`` over its lat-long rectangle ``[theta0, theta1] x [phi0, phi1]`` (the
layout of `glphong.twin.environment`: theta from the map's +z, phi from its +x toward +y), ``g`` the caller's
integrand (a BRDF response times the cosine) and ``c`` optional clip planes through the point.  The map is turned
into the world by ``rotation`` (``w_world = R w_map``).

The method
----------
1. *The planes, clipped exactly.*  On the meridian at azimuth ``phi`` a plane ``m.w > 0`` holds for ``theta`` in
   ``(alpha - pi/2, alpha + pi/2)`` with ``alpha = atan2(m_x cos(phi) + m_y sin(phi), m_z)`` (one interval of the
   meridian): so each rectangle's ``theta`` nodes are placed on the part of ``[theta0, theta1]`` where every plane
   holds, at every ``phi`` node.  The rectangle is first cut in ``phi`` where a plane's boundary crosses its
   ``theta`` edges (``m_x cos(phi) + m_y sin(phi) = -m_z cot(theta_edge)``) and where two planes' boundaries cross
   (``+-(m_1 x m_2)``), so that over each piece the interval's ends are smooth in ``phi``, and so is the integral;
   so are the halves of every later subdivision (their new ``theta`` edges cut them again).
2. *Adaptive tensor Gauss-Legendre* of order 4 in ``phi`` and in ``theta`` (weight ``sin(theta)``) on each rectangle:
   its value is compared with the sum of its four halves'; a rectangle whose difference is within its share of the
   point's tolerance (``rtol |I|`` times its solid angle over the point's) keeps the halves' sum, the others are
   split, level by level, to ``max_depth`` levels.  Texels wholly below the horizon and texels of zero radiance are
   skipped; the others are first split until each side is at most ``extent`` [rad].
3. *The error estimate* is the sum of the kept differences (and of the last level's); ``converged`` is ``error <=
   rtol |I|``.  The rules only see what their nodes see: a feature of the integrand narrower than about
   ``extent / 8`` (a Phong lobe of ``q`` beyond about ``16 / extent^2``) can be missed at the first level, where
   nothing signals it; `glphong.lights.EnvironmentLight.exact` states the range it is used for.
"""
import numpy as np

__all__ = ["environment_integral"]

_ORDER = 4
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(_ORDER)
_NODES, _WEIGHTS = 0.5 * (_NODES + 1.0), 0.5 * _WEIGHTS
_CHUNK = 400_000              # integrand evaluations per call


def _rule(rects, planes, integrand, radiance, rotation, order=_ORDER, zonal=None):
    """The tensor rule of ``order`` Gauss-Legendre points a side on rectangles ``rects`` = (owner, texel, t0, t1, p0,
    p1): (K, C) values (``C`` the radiance's channels).  ``zonal = (axes (N, 3), q)``: the integrand is
    ``max(a.w, 0)^q`` about each owner's axis ``a`` in the map's frame, evaluated at every node at once (``integrand``
    and ``rotation`` unused; `glphong.twin.environment_lobe`)."""
    owner, texel, t0, t1, p0, p1 = rects
    K = len(owner)
    out = np.zeros((K, radiance.shape[-1]))
    if K == 0:
        return out
    if order == _ORDER:
        nodes, weights = _NODES, _WEIGHTS
    else:
        nodes, weights = np.polynomial.legendre.leggauss(order)
        nodes, weights = 0.5 * (nodes + 1.0), 0.5 * weights
    step = max(1, _CHUNK // (order * order))
    for a in range(0, K, step):
        sl = slice(a, a + step)
        o = owner[sl]
        phi = p0[sl, None] + (p1 - p0)[sl, None] * nodes[None, :]                          # (k, G)
        lo = np.broadcast_to(t0[sl, None], phi.shape).copy()
        hi = np.broadcast_to(t1[sl, None], phi.shape).copy()
        cp, sp = np.cos(phi), np.sin(phi)
        for m in planes:
            mm = m[o]
            s = mm[:, 0, None] * cp + mm[:, 1, None] * sp
            alpha = np.arctan2(s, np.broadcast_to(mm[:, 2, None], s.shape))
            low, high = alpha - np.pi / 2, alpha + np.pi / 2
            wrap = high < 0.0
            low, high = np.where(wrap, low + 2 * np.pi, low), np.where(wrap, high + 2 * np.pi, high)
            none = (s == 0.0) & (mm[:, 2, None] == 0.0)           # the plane contains the meridian: measure zero
            lo = np.maximum(lo, np.where(none, np.inf, low))
            hi = np.minimum(hi, high)
        width = np.maximum(hi - lo, 0.0)                                                    # (k, G)
        theta = lo[:, :, None] + width[:, :, None] * nodes[None, None, :]                   # (k, G, G)
        st = np.sin(theta)
        weight = ((p1 - p0)[sl, None, None] * weights[None, :, None] * width[:, :, None] * weights[None, None, :]
                  * st)                                                                      # (k, G, G)
        if zonal is not None:  # the radiance is one texel's over each rectangle
            axis = zonal[0][o]
            dot = axis[:, 2, None, None] * np.cos(theta) + st * (axis[:, 0, None, None] * cp[:, :, None]
                                                                 + axis[:, 1, None, None] * sp[:, :, None])
            with np.errstate(divide="ignore"):
                g = np.where(dot > 0.0, np.exp(zonal[1] * np.log(np.where(dot > 0.0, dot, 1.0))), 0.0)
            out[sl] = np.sum(g * weight, axis=(1, 2))[:, None] * radiance[texel[sl]]
            continue
        w = np.stack([st * cp[:, :, None], st * sp[:, :, None], np.broadcast_to(np.cos(theta), st.shape)], axis=-1)
        live = weight > 0.0
        k_index = np.broadcast_to(np.arange(len(o))[:, None, None], live.shape)[live]
        values = np.zeros(live.shape + (radiance.shape[-1],))
        if k_index.size:
            g = np.asarray(integrand(o[k_index], w[live] @ rotation.T), dtype=np.float64)
            g = g if g.ndim == 2 else g[:, None]
            values[live] = g * radiance[texel[sl][k_index]]
        out[sl] = np.sum(values * weight[..., None], axis=(1, 2))
    return out


def _breakpoints(rects, planes):
    """Each rectangle cut in ``phi`` where a plane's boundary crosses its ``theta`` edges or two planes' boundaries
    cross inside it: the pieces, on which the clipped ``theta`` interval's ends are smooth in ``phi``."""
    owner, texel, t0, t1, p0, p1 = rects
    cuts = []
    for m in planes:
        mm = m[owner]
        rho = np.hypot(mm[:, 0], mm[:, 1])
        beta = np.arctan2(mm[:, 1], mm[:, 0])
        for edge in (t0, t1):
            sine = np.sin(edge)
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = -mm[:, 2] * np.cos(edge) / (sine * rho)
            ok = (sine > 1e-12) & (rho > 0.0) & (np.abs(ratio) < 1.0)
            delta = np.arccos(np.clip(np.nan_to_num(ratio), -1.0, 1.0))
            for sign in (1.0, -1.0):
                cuts.append(np.where(ok, np.mod(beta + sign * delta, 2 * np.pi), np.nan))
    for i in range(len(planes)):
        for j in range(i + 1, len(planes)):
            d = np.cross(planes[i][owner], planes[j][owner])
            length = np.linalg.norm(d, axis=1)
            for sign in (1.0, -1.0):
                theta = np.arccos(np.clip(sign * d[:, 2] / np.maximum(length, 1e-300), -1.0, 1.0))
                inside = (length > 1e-12) & (theta > t0) & (theta < t1)
                cuts.append(np.where(inside, np.mod(np.arctan2(sign * d[:, 1], sign * d[:, 0]), 2 * np.pi), np.nan))
    cuts = np.stack(cuts, axis=1)
    cuts = np.where((cuts > p0[:, None]) & (cuts < p1[:, None]), cuts, p1[:, None])
    edges = np.concatenate([p0[:, None], np.sort(cuts, axis=1), p1[:, None]], axis=1)
    a, b = edges[:, :-1], edges[:, 1:]
    k, c = np.nonzero(b > a)
    return (owner[k], texel[k], t0[k], t1[k], a[k, c], b[k, c]), k


def _split(rects):
    owner, texel, t0, t1, p0, p1 = rects
    tm, pm = 0.5 * (t0 + t1), 0.5 * (p0 + p1)
    return (np.tile(owner, 4), np.tile(texel, 4), np.concatenate([t0, t0, tm, tm]), np.concatenate([tm, tm, t1, t1]),
            np.concatenate([p0, pm, p0, pm]), np.concatenate([pm, p1, pm, p1]))


def _take(rects, sel):
    return tuple(a[sel] for a in rects)


def _solid_angle(rects):
    _, _, t0, t1, p0, p1 = rects
    return (p1 - p0) * (np.cos(t0) - np.cos(t1))


def environment_integral(normals, radiance, integrand, rotation=None, clip=(), rtol=1e-9, max_depth=10, extent=np.pi / 16):
    """``sum_k L_k integral_k g(w) [n.w > 0] [c.w > 0] dw`` at each point, float64 (module docstring).

    Parameters
    ----------
    normals : (N, 3) array_like
        Unit surface normals (world).
    radiance : (H, W) or (H, W, 3) array_like
        The map's radiance per texel [W/(m^2 sr)], row 0 at the map's +z.
    integrand : callable
        ``integrand(index, w) -> (M,) or (M, 1) or (M, 3)``: ``g`` at world directions ``w`` (M, 3) for the points
        ``index`` (M,) int.
    rotation : (3, 3) array_like, optional
        ``w_world = rotation @ w_map`` (default the identity).
    clip : tuple of (N, 3) or (3,) array_like
        Extra planes through each point (``c.w > 0`` counts); the horizon ``n.w > 0`` always applies.
    rtol : float
        Relative tolerance on each point's integral (its largest channel).
    max_depth : int
        Levels of 2 x 2 subdivision at most.
    extent : float
        Side [rad] the rectangles are first split to at most (module docstring: what it resolves).

    Returns
    -------
    value : (N, 3) float64 ndarray
    error : (N,) float64 ndarray
        The estimated absolute error (largest channel).
    converged : (N,) bool ndarray
    """
    radiance = np.asarray(radiance, dtype=np.float64)
    radiance = np.repeat(radiance[..., None], 3, axis=-1) if radiance.ndim == 2 else radiance
    H, W = radiance.shape[:2]
    flat = radiance.reshape(-1, 3)
    rotation = np.eye(3) if rotation is None else np.asarray(rotation, dtype=np.float64)
    normals = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    N = len(normals)
    planes = [normals @ rotation] + [np.broadcast_to(np.asarray(c, dtype=np.float64), (N, 3)) @ rotation for c in clip]
    theta, phi = np.linspace(0.0, np.pi, H + 1), np.linspace(0.0, 2 * np.pi, W + 1)
    t0, t1 = np.repeat(theta[:-1], W), np.repeat(theta[1:], W)
    p0, p1 = np.tile(phi[:-1], H), np.tile(phi[1:], H)
    tc, pc = 0.5 * (t0 + t1), 0.5 * (p0 + p1)
    centre = np.stack([np.sin(tc) * np.cos(pc), np.sin(tc) * np.sin(pc), np.cos(tc)], axis=-1)
    reach = 0.5 * (t1 - t0) + 0.5 * (p1 - p0)         # >= the angle from the centre to any point of the texel
    lit = np.any(flat != 0.0, axis=1)
    pairs = []
    for a in range(0, N, 512):
        angle = np.arccos(np.clip(planes[0][a:a + 512] @ centre.T, -1.0, 1.0))
        rows, texels = np.nonzero((angle < np.pi / 2 + reach[None, :]) & lit[None, :])
        pairs.append((a + rows, texels))
    owner = np.concatenate([p[0] for p in pairs]).astype(np.intp)
    texel = np.concatenate([p[1] for p in pairs]).astype(np.intp)
    rects = (owner, texel, t0[texel], t1[texel], p0[texel], p1[texel])
    levels = int(np.ceil(np.log2(max(np.pi / H, 2 * np.pi / W) / extent))) if extent > 0 else 0
    for _ in range(max(levels, 0)):
        rects = _split(rects)
    rects, _ = _breakpoints(rects, planes)
    value, error = np.zeros((N, 3)), np.zeros(N)
    estimate = _rule(rects, planes, integrand, flat, rotation)
    share = _solid_angle(rects)
    total_share = np.bincount(rects[0], share, minlength=N)
    for depth in range(max_depth + 1):
        if not len(rects[0]):
            break
        K = len(rects[0])
        children, parent = _breakpoints(_split(rects), planes)   # the halves' new theta edges cut them again
        parent = np.tile(np.arange(K), 4)[parent]
        fine = _rule(children, planes, integrand, flat, rotation)
        fine_sum = np.zeros((K, 3))
        np.add.at(fine_sum, parent, fine)
        diff = np.max(np.abs(fine_sum - estimate), axis=1)
        current = value.copy()
        np.add.at(current, rects[0], fine_sum)
        scale = np.max(np.abs(current), axis=1)
        allowed = np.maximum(rtol * scale, 1e-300)[rects[0]] * share / np.maximum(total_share[rects[0]], 1e-300)
        done = (diff <= allowed) | (depth == max_depth)
        np.add.at(value, rects[0][done], fine_sum[done])
        np.add.at(error, rects[0][done], diff[done])
        keep = ~done[parent]
        rects, estimate = _take(children, keep), fine[keep]
        share = _solid_angle(rects)
    converged = error <= np.maximum(rtol * np.max(np.abs(value), axis=1), 1e-300)
    return value, error, converged
