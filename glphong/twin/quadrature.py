"""An independent float64 reference for area lights: the exact integral of a uniformly emitting polygon, sphere or
disk, at many surface points at once (docs/design.md section 13, the continuous version; section 11 for what a
light delivers).  It is the yardstick that closed forms and approximations of extended lights are measured against,
and it shares no code with them.

What is integrated
------------------
At a surface point ``x`` with unit normal ``n``, for a light of uniform radiance ``L`` [W/(m^2 sr)] (RGB)::

    I(x) = L * integral over Omega(x) of g(w) dw

``Omega(x)`` is the set of unit directions ``w`` from ``x`` that hit the light's emitting side and satisfy
``n.w >= 0`` and ``c.w >= 0`` for every extra clip plane ``c`` (planes through ``x``, e.g. the half-space of a
Phong lobe ``r.w >= 0``).  ``g`` is the caller's integrand (a BRDF response times the cosine, or just ``n.w`` for
the irradiance ``E``); ``dw`` is solid angle [sr].

The method
----------
1. *The region, clipped exactly.*  Every emitter is reduced to a convex planar region seen from ``x`` (coordinates
   relative to ``x``):

   - a polygon (emitting toward ``n_l = normalize((v1 - v0) x (v2 - v0))``, counter-clockwise seen from the front)
     is clipped by Sutherland-Hodgman against each plane ``{y : c.(y - x) >= 0}``; a point with
     ``n_l.(x - v0) <= 0`` (behind the light or on its plane) gets 0;
   - a disk (centre ``c``, unit normal ``m``, radius ``R``) is cut by the lines where each plane through ``x`` meets
     its plane: the rim crossings solve ``c.O + R (c.e1 cos(s) + c.e2 sin(s)) = 0`` (``O`` the centre relative to
     ``x``, angles ``s`` measured from the rim point nearest the foot of ``x``, and rim points computed as that
     point plus ``R ((cos(s) - 1) e1 + sin(s) e2)``, ``cos(s) - 1 = -2 sin^2(s/2)``, so that a rim passing a hair
     from ``x`` keeps its shape), the rim is split there into arcs each wholly inside or outside every half-space,
     and each plane's chord is clipped by the others (linear in the chord's parameter);
   - a sphere (centre ``c``, radius ``r``, at distance ``d > r``) is the cone of half angle ``alpha``, ``sin(alpha)
     = r/d``, about ``a = (c - x)/d``: exactly the cone over the *virtual disk* of centre ``x + cos(alpha) a``,
     radius ``sin(alpha)`` and normal ``-a`` (the circle where the cone touches the sphere, scaled to unit
     distance; ``cos(alpha) = sqrt((d - r)(d + r))/d``), so it is integrated as that disk.

   The horizon ``n.w >= 0`` is always the first plane; a plane given twice counts once, and two opposite planes
   leave nothing.  The integrand is then smooth over the region (kinks such as ``max(r.w, 0)`` belong in ``clip``).

2. *A fan in direction space.*  ``F`` is the direction to the region's point nearest ``x`` (the foot of the
   perpendicular when it lies inside).  For a convex set that point ``f`` satisfies ``(y - f).(f - x) >= 0`` for
   every ``y`` of the region, so every direction of the region lies within 90 degrees of ``F``.  The boundary is
   split into pieces (segments; arcs of at most 45 degrees of the rim) until each subtends at most 45 degrees at
   ``x`` (a segment at the point where the angle bisector meets it, ``t = |A| / (|A| + |B|)``; an arc at its
   middle, so a rim passing close to ``x`` is cut geometrically toward it), and segments are re-parametrised by
   their unit end directions.  Each piece ``P(s)``, ``s in [0, 1]``, with ``F`` spans one patch::

       w(s, t) = p / |p|,   p = F + t (B(s) - F),   B = P / |P|,   (s, t) in [0, 1]^2
       dw = t |det(F, P'(s), P(s))| / (|P(s)|^2 |p|^3) ds dt

   (``dw = p.(p_s x p_t) / |p|^3``).  ``|p| >= cos(45 deg)``, and nothing is divided by the distance to the light,
   so a light touching ``x`` (``x`` a hair in front of its plane or edge, where the area measure's ``cos_l / d^2``
   is singular) gives a smooth integrand all the same.

3. *Adaptive tensor Gauss-Legendre.*  Each patch is integrated with the 6 x 6 and the 9 x 9 tensor Gauss-Legendre
   rules on ``(s, t)``; the 9 x 9 value is kept and ``|Q9 - Q6|`` is its error estimate.  A point is done when the
   sum of its estimates is within ``tol = max(rtol |I|, 1e-300)`` (``|I|`` its largest channel), less what
   rounding takes (below); otherwise a patch whose estimate is within half that times its share of the point's
   solid angle is kept and the others are split 2 x 2 in ``(s, t)``, level by level, all ``(point, patch)`` pairs
   of a level as arrays, to ``max_depth`` levels.  Subdivision also stops at ``64 eps`` times the sum of
   ``|P'| |P| ... |g|`` (what the rounding of ``det`` is relative to: a region seen edge-on is known no better),
   and a guard holds the live patches to 400 000 (or 16 per first patch), refining the worst.

4. *The error estimate* is the sum over the final patches of ``|Q9 - Q6|`` (a generous bound on the 9 x 9 value's
   error: measured, it is 100 to 10 000 times the true error) plus a bound on rounding: every boundary point is
   computed within ``e = eps S`` of where it belongs (``S`` the size of the coordinates: ``|x| + max |v_i|``,
   ``|x| + |c| + R``, or for the sphere at unit distance ``(|x| + |c| + r)/d + sqrt(d/(d - r))``), which turns its
   direction by ``e/|P|``; so the region's measure is off by at most ``max |g|`` times ``e sum theta_k / dist_k``
   over the emitter's own boundary pieces (``theta_k`` the angle a piece subtends, ``dist_k`` its distance from
   ``x``) plus ``8 eps sum theta_k`` over the pieces cut by planes through ``x`` (they move across their plane only
   with its normal).  Near an edge at distance ``rho`` this grows like ``eps S / rho``, as the exact answer for
   inputs an ulp apart does.  ``converged`` is ``error <= tol``: False where the depth ran out or where rounding
   alone exceeds the tolerance.

The value is ``L`` times the integral: ``(N, 3)`` for an integrand of one channel (times the RGB radiance) or of
three (channel by channel).

The modules
-----------
This module checks the inputs and holds the three public functions; step 1 (the regions) is
`glphong.twin.quadrature_regions`, steps 2 to 4 (the fan, the adaptive quadrature and its error estimate) are
`glphong.twin.quadrature_fan`.
"""
import numpy as np

from glphong.twin.quadrature_fan import _run
from glphong.twin.quadrature_regions import _disk_region, _norm, _perpendiculars, _polygon_region, _unit

__all__ = ["polygon_integral", "sphere_integral", "disk_integral"]


# --------------------------------------------------------------------------------------------------------------
# Inputs
# --------------------------------------------------------------------------------------------------------------
def _points(x, normals):
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"x must be (N, 3), got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError("x has non-finite coordinates")
    normals = _unit(np.broadcast_to(np.asarray(normals, dtype=np.float64), x.shape), "normals")
    return x, np.ascontiguousarray(normals)


def _planes(normals, clip):
    """The horizon and the clip planes, each (N, 3), normalised (a zero vector stays zero: no constraint)."""
    if isinstance(clip, np.ndarray) and clip.ndim in (1, 2) and clip.shape[-1] == 3:
        clip = (clip,)
    planes = [normals]
    for c in clip:
        c = np.array(np.broadcast_to(np.asarray(c, dtype=np.float64), normals.shape))
        if not np.all(np.isfinite(c)):
            raise ValueError("a clip plane has non-finite components")
        length = _norm(c)
        c[length > 0] /= length[length > 0, None]
        planes.append(c)
    return planes


def _radiance(radiance):
    radiance = np.asarray(radiance, dtype=np.float64)
    if radiance.shape != (3,) or not np.all(np.isfinite(radiance)):
        raise ValueError(f"radiance must be three finite values (RGB), got shape {radiance.shape}")
    return radiance


def _round_emitter(x, normals, center, radius, radiance, clip, rtol, max_depth):
    """The checked arguments of a sphere or a disk: ``(x, center, radius, radiance, rtol, max_depth, planes)``."""
    x, normals = _points(x, normals)
    center = np.asarray(center, dtype=np.float64)
    radius = float(radius)
    if center.shape != (3,) or not np.all(np.isfinite(center)) or not (np.isfinite(radius) and radius > 0):
        raise ValueError("center must be (3,) and radius a positive number")
    rtol, max_depth = _check_budget(rtol, max_depth)
    return x, center, radius, _radiance(radiance), rtol, max_depth, _planes(normals, clip)


def _check_budget(rtol, max_depth):
    if not (np.isfinite(rtol) and rtol > 0):
        raise ValueError("rtol must be a positive number")
    if int(max_depth) != max_depth or max_depth < 0:
        raise ValueError("max_depth must be a non-negative integer")
    return float(rtol), int(max_depth)


def _check_polygon(vertices):
    vertices = np.asarray(vertices, dtype=np.float64)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or len(vertices) < 3:
        raise ValueError(f"vertices must be (V, 3) with V >= 3, got {vertices.shape}")
    if not np.all(np.isfinite(vertices)):
        raise ValueError("vertices have non-finite coordinates")
    # the front normal normalize((v1 - v0) x (v2 - v0)), taken from the area vector (the same for a convex polygon,
    # and accurate when those three are nearly collinear)
    centred = vertices - vertices.mean(axis=0)
    front = np.sum(np.cross(centred, np.roll(centred, -1, axis=0)), axis=0)
    if _norm(front) == 0.0:
        raise ValueError("the polygon has no area: its front normal is undefined")
    front /= _norm(front)
    if np.cross(vertices[1] - vertices[0], vertices[2] - vertices[0]) @ front < 0:
        raise ValueError("the polygon is not convex and counter-clockwise seen from its front "
                         "(normalize((v1 - v0) x (v2 - v0)))")
    size = np.max(_norm(centred))
    if np.max(np.abs((vertices - vertices[0]) @ front)) > 1e-9 * size:
        raise ValueError("the polygon is not planar")
    edges = np.roll(vertices, -1, axis=0) - vertices
    turns = np.cross(edges, np.roll(edges, -1, axis=0)) @ front
    turning = np.sum(np.arctan2(turns, np.sum(edges * np.roll(edges, -1, axis=0), axis=1)))
    if np.min(turns) < -1e-12 * size ** 2 or abs(turning - 2.0 * np.pi) > 1e-6:
        raise ValueError("the polygon is not convex and counter-clockwise seen from its front "
                         "(normalize((v1 - v0) x (v2 - v0)))")
    return vertices, front


def polygon_integral(x, normals, vertices, radiance, integrand, clip=(), rtol=1e-9, max_depth=12):
    """The integral of ``g(w) L`` over the directions from each point to a uniformly emitting convex polygon.

    Parameters
    ----------
    x : (N, 3) array_like
        Surface points [m].
    normals : (N, 3) or (3,) array_like
        Unit surface normals (normalised here).
    vertices : (V, 3) array_like
        A planar convex polygon, ``V >= 3`` [m].  It emits only toward the side from which its vertices appear
        counter-clockwise: the front normal ``normalize((v1 - v0) x (v2 - v0))``.  A point behind the polygon's
        plane or on it gets 0.
    radiance : (3,) array_like
        The light's uniform radiance ``L`` [W/(m^2 sr)], RGB.
    integrand : callable
        ``integrand(index, w) -> (M, C)`` float64, ``C`` 1 or 3 (or ``(M,)``): ``index`` (M,) int, the point each
        direction belongs to; ``w`` (M, 3), unit directions from ``x[index]``.  It must be smooth over the clipped
        region (put a kink such as ``max(r.w, 0)`` into ``clip``).  ``M`` is a few hundred thousand at most.
    clip : tuple of (N, 3) or (3,) array_like
        Extra planes through each ``x``: only directions with ``c.w >= 0`` count.  The horizon ``n.w >= 0`` is
        always applied.
    rtol : float
        Relative tolerance on each point's integral (its largest channel).
    max_depth : int
        Levels of 2 x 2 subdivision of a patch at most.

    Returns
    -------
    value : (N, 3) float64 ndarray
        ``L`` times the integral: an integrand of one channel times the RGB radiance, one of three channel by
        channel [W/m^2 for ``g = n.w``; W/m^2 times the unit of ``g/(n.w)`` in general].
    error : (N,) float64 ndarray
        Estimated absolute error of ``value`` (its largest channel), same unit: the quadrature's estimate plus a
        bound on what rounding the geometry (``eps`` times the coordinates' size) moves the region's boundary by,
        which grows like ``1/distance`` as ``x`` nears the polygon's edge (module docstring).
    converged : (N,) bool ndarray
        Whether the error is within ``rtol`` times the integral (its largest channel): False where the depth ran
        out or where rounding alone exceeds that (a point a hair from an edge).
    """
    x, normals = _points(x, normals)
    vertices, front = _check_polygon(vertices)
    radiance = _radiance(radiance)
    rtol, max_depth = _check_budget(rtol, max_depth)
    planes = _planes(normals, clip)
    pieces, foot, inside = _polygon_region(x, planes, vertices, front)
    scale = _norm(x) + np.max(_norm(vertices))
    return _run(pieces, foot, inside, integrand, radiance, len(x), rtol, max_depth, scale)


def sphere_integral(x, normals, center, radius, radiance, integrand, clip=(), rtol=1e-9, max_depth=12):
    """The integral of ``g(w) L`` over the cone of directions from each point to a uniformly emitting sphere.

    The cone has half angle ``alpha = asin(r/d)`` about the direction to the centre (``d`` the distance to it);
    it is integrated as the disk it passes through at unit distance (module docstring).

    Parameters
    ----------
    x : (N, 3) array_like
        Surface points [m], all outside the sphere (``ValueError`` otherwise, saying how many are not).
    normals : (N, 3) or (3,) array_like
        Unit surface normals (normalised here).
    center : (3,) array_like
        The sphere's centre [m].
    radius : float
        The sphere's radius [m], positive.
    radiance : (3,) array_like
        The sphere's uniform radiance ``L`` [W/(m^2 sr)], RGB.
    integrand : callable
        ``integrand(index, w) -> (M, C)``, as for `polygon_integral`.
    clip : tuple of (N, 3) or (3,) array_like
        Extra planes through each ``x`` (``c.w >= 0`` counts); the horizon ``n.w >= 0`` is always applied.
    rtol : float
        Relative tolerance on each point's integral (its largest channel).
    max_depth : int
        Levels of 2 x 2 subdivision of a patch at most.

    Returns
    -------
    value : (N, 3) float64 ndarray
        ``L`` times the integral (as for `polygon_integral`).
    error : (N,) float64 ndarray
        Estimated absolute error of ``value`` (its largest channel).
    converged : (N,) bool ndarray
        Whether the error is within ``rtol`` times the integral (as for `polygon_integral`).
    """
    x, center, radius, radiance, rtol, max_depth, planes = _round_emitter(x, normals, center, radius, radiance, clip,
                                                                           rtol, max_depth)
    offset = center - x
    d = _norm(offset)
    outside = d > radius
    if not outside.all():
        raise ValueError(f"{int(np.count_nonzero(~outside))} of {len(x)} points are inside the sphere or on it "
                         f"(distance to the centre <= radius)")
    a = offset / d[:, None]
    sin_a = radius / d
    cos_a = np.sqrt((d - radius) * (d + radius)) / d
    e1, e2 = _perpendiculars(a)
    pieces, foot, inside = _disk_region(cos_a[:, None] * a, -a, sin_a, e1, e2, planes, np.ones(len(x), bool))
    # at unit distance: the direction to the centre is known to eps (|x| + |c|)/d, the cone's edge to about
    # eps sqrt(d/(d - r)) (cos(alpha) from d - r)
    scale = (_norm(x) + _norm(center) + radius) / d + np.sqrt(d / (d - radius))
    return _run(pieces, foot, inside, integrand, radiance, len(x), rtol, max_depth, scale)


def disk_integral(x, normals, center, normal, radius, radiance, integrand, clip=(), rtol=1e-9, max_depth=12):
    """The integral of ``g(w) L`` over the directions from each point to a one-sided uniformly emitting disk.

    Parameters
    ----------
    x, normals, center, radius, radiance, integrand, clip, rtol, max_depth
        As for `sphere_integral` (the disk's centre, radius and radiance).
    normal : (3,) array_like
        The side the disk emits toward (normalised here).  A point behind the disk's plane or on it gets 0.

    Returns
    -------
    value, error, converged
        As for `sphere_integral`; the error grows like ``1/distance`` as ``x`` nears the rim (`polygon_integral`).
    """
    x, center, radius, radiance, rtol, max_depth, planes = _round_emitter(x, normals, center, radius, radiance, clip,
                                                                           rtol, max_depth)
    normal = _unit(normal, "normal")
    if normal.shape != (3,):
        raise ValueError("normal must be (3,)")
    N = len(x)
    O = center - x
    seen = -(O @ normal) > 0.0
    e1, e2 = _perpendiculars(normal)
    pieces, foot, inside = _disk_region(O, np.broadcast_to(normal, (N, 3)), np.full(N, radius),
                                        np.broadcast_to(e1, (N, 3)), np.broadcast_to(e2, (N, 3)), planes, seen)
    scale = _norm(x) + _norm(center) + radius
    return _run(pieces, foot, inside, integrand, radiance, N, rtol, max_depth, scale)
