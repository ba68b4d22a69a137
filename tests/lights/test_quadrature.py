"""The float64 reference for area lights (glphong.twin.quadrature, docs/design.md section 13) against
independent closed forms and brute-force grids: Lambert's edge formula for polygons (also clipped to the horizon
and to extra planes), the point limit, the sphere's cap (Snyder 1996; Lagarde & de Rousiers 2014), the disk's
configuration factor, the Phong lobe's 2 pi/(q + 1), and lights touching the surface.
"""
# Time of one 20 000-point evaluation, integrand n.w (C = 1), rtol 1e-8, points uniform in [-1, 2]^2 x [0, 1.9]
# with random normals, the light of size ~1 near z = 2 (2 cores, numpy 2.4, best of three while other work kept
# the load near 1.5; on a quieter machine about 1.2 s, 1.3 s and 2.2 s):
#
#     polygon (unit square)   2.1 s
#     sphere (r = 0.4)        1.8 s
#     disk (R = 0.6)          2.9 s
#
# All converged; against Lambert's formula the polygon's values were within 1e-12 relative, the error estimates
# at least 18 times (median 90 000 times) the true error.  test_twenty_thousand_points keeps a loose eye on it.
import time

import mpmath
import numpy as np
import pytest

from glphong.twin.quadrature import disk_integral, polygon_integral, sphere_integral

ONE = np.ones(3)


def _cosine(normals):
    return lambda index, w: np.einsum("md,md->m", normals[index], w)[:, None]


def _lambert(x, normals, vertices):
    """Lambert's edge formula, ``E/L = 1/2 sum_i Theta_i (n . g_i)``.  For a polygon counter-clockwise seen from its
    front (where ``x`` is), the edge normal pointing away from the polygon is ``(v_{i+1} - x) x (v_i - x)``: the
    opposite of ``(v_i - x) x (v_{i+1} - x)``."""
    total = np.zeros(len(x))
    for i in range(len(vertices)):
        a, b = vertices[i] - x, vertices[(i + 1) % len(vertices)] - x
        cross = np.cross(b, a)
        theta = np.arctan2(np.linalg.norm(cross, axis=1), np.sum(a * b, axis=1))
        total += theta * np.sum(normals * cross, axis=1) / np.linalg.norm(cross, axis=1)
    return 0.5 * total


def _lambert_mp(x, normal, vertices, planes=()):
    """The same in 40 digits, after clipping the polygon (also in 40 digits) to the horizon and the planes: the
    exact value for the float64 inputs, for points a hair from the polygon's edge or plane where float64 cancels."""
    with mpmath.workdps(40):
        n = [mpmath.mpf(float(c)) for c in normal]
        polygon = [[mpmath.mpf(float(v[k])) - mpmath.mpf(float(x[k])) for k in range(3)] for v in vertices]
        for c in [n] + [[mpmath.mpf(float(q)) for q in plane] for plane in planes]:
            clipped = []
            for i in range(len(polygon)):
                a, b = polygon[i], polygon[(i + 1) % len(polygon)]
                da, db = sum(c[k] * a[k] for k in range(3)), sum(c[k] * b[k] for k in range(3))
                if da >= 0:
                    clipped.append(a)
                if (da >= 0) != (db >= 0):
                    clipped.append([a[k] + da / (da - db) * (b[k] - a[k]) for k in range(3)])
            polygon = clipped
            if len(polygon) < 3:
                return 0.0
        total = mpmath.mpf(0)
        for i in range(len(polygon)):
            a, b = polygon[i], polygon[(i + 1) % len(polygon)]
            cross = [b[1] * a[2] - b[2] * a[1], b[2] * a[0] - b[0] * a[2], b[0] * a[1] - b[1] * a[0]]
            length = mpmath.sqrt(sum(c * c for c in cross))
            if length > 0:
                theta = mpmath.atan2(length, sum(a[k] * b[k] for k in range(3)))
                total += theta * sum(n[k] * cross[k] for k in range(3)) / length
        return float(total / 2)


def _clip(vertices, c, x):
    """Sutherland-Hodgman against ``c.(y - x) >= 0`` (the test's own)."""
    out = []
    for i in range(len(vertices)):
        a, b = vertices[i], vertices[(i + 1) % len(vertices)]
        da, db = c @ (a - x), c @ (b - x)
        if da >= 0:
            out.append(a)
        if (da >= 0) != (db >= 0):
            out.append(a + da / (da - db) * (b - a))
    return np.array(out)


def _random_polygon(rng, sides):
    """A convex polygon (points of an ellipse in angle order) in a random plane, its front normal, its centre."""
    while True:
        angles = np.sort(rng.uniform(0.0, 2 * np.pi, sides))
        if np.min(np.diff(np.r_[angles, angles[0] + 2 * np.pi])) > 0.3:
            break
    a, b = rng.uniform(0.3, 1.5, 2)
    frame = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    u, v = frame[:, 0], frame[:, 1]
    front = np.cross(u, v)
    centre = rng.uniform(-2.0, 2.0, 3)
    vertices = centre + (a * np.cos(angles))[:, None] * u + (b * np.sin(angles))[:, None] * v
    return vertices, front, centre, (u, v)


def _grid_polygon(x, normal, corner, edge_u, edge_v, integrand, cells=2000):
    """Midpoint rule over the parallelogram ``corner + [0,1] edge_u + [0,1] edge_v`` in area measure:
    ``sum g(w) cos_l / d^2 dA`` with ``cos_l`` toward the emitting side (where ``x`` is)."""
    front = np.cross(edge_u, edge_v)
    area = np.linalg.norm(front) / cells ** 2
    front /= np.linalg.norm(front)
    if front @ (x - corner) < 0:
        front = -front
    centres = (np.arange(cells) + 0.5) / cells
    total = 0.0
    for rows in np.array_split(centres, 20):
        y = corner + rows[:, None, None] * edge_u + centres[None, :, None] * edge_v
        d = y.reshape(-1, 3) - x
        r = np.linalg.norm(d, axis=1)
        w = d / r[:, None]
        total += np.sum(integrand(w) * (-(w @ front)) / r ** 2) * area
    return total


# 1. Lambert's edge formula -----------------------------------------------------------------------------------
@pytest.mark.parametrize("sides", [3, 4, 5])
def test_lambert_edge_formula_above_the_horizon(sides):
    rng = np.random.default_rng(100 + sides)
    worst = 0.0
    for _ in range(35):
        vertices, front, centre, (u, v) = _random_polygon(rng, sides)
        while True:
            x = centre + rng.uniform(0.1, 3.0) * front + rng.uniform(-2, 2) * u + rng.uniform(-2, 2) * v
            n = (centre - x) / np.linalg.norm(centre - x) + 0.4 * rng.normal(size=3)
            n /= np.linalg.norm(n)
            if np.all((vertices - x) @ n > 0.0):
                break
        x, n = x[None, :], n[None, :]
        value, error, converged = polygon_integral(x, n, vertices, [1.0, 2.0, 0.5], _cosine(n))
        exact = _lambert(x, n, vertices)[0]
        assert converged.all()
        assert np.allclose(value[0], exact * np.array([1.0, 2.0, 0.5]), rtol=1e-9, atol=0)
        assert abs(value[0, 0] - exact) <= error[0] + 1e-14 * exact
        worst = max(worst, abs(value[0, 0] / exact - 1))
    assert worst < 1e-9


def test_lambert_many_points_at_once_and_the_back_side():
    rng = np.random.default_rng(7)
    vertices = np.array([[0.0, 0.0, 2.0], [0.0, 1.0, 2.0], [1.0, 1.0, 2.0], [1.0, 0.0, 2.0]])  # faces -z
    x = np.column_stack([rng.uniform(-1, 2, 500), rng.uniform(-1, 2, 500), rng.uniform(-1, 3, 500)])
    n = np.tile([0.0, 0.0, 1.0], (500, 1))
    value, error, converged = polygon_integral(x, n, vertices, ONE, _cosine(n), rtol=1e-10)
    behind = x[:, 2] >= 2.0
    assert np.all(value[behind] == 0.0) and np.all(error[behind] == 0.0) and converged.all()
    exact = _lambert(x[~behind], n[~behind], vertices)
    assert np.allclose(value[~behind, 0], exact, rtol=1e-10, atol=1e-15)


# 2. The point limit --------------------------------------------------------------------------------------------
def test_far_polygon_tends_to_the_point_source():
    vertices = np.array([[0.0, 0.0, 0.0], [0.6, 0.0, 0.0], [0.6, 0.4, 0.0], [0.0, 0.4, 0.0]])  # faces +z
    area, size = 0.24, np.hypot(0.3, 0.2)
    centre = np.array([0.3, 0.2, 0.0])
    direction = np.array([0.3, -0.2, 1.0]) / np.linalg.norm([0.3, -0.2, 1.0])
    deviations = []
    for d in [10.0, 100.0, 1000.0]:
        x = (centre + d * direction)[None, :]
        n = np.array([[0.2, 0.1, -1.0]]) / np.linalg.norm([0.2, 0.1, -1.0])
        value, _, converged = polygon_integral(x, n, vertices, ONE, _cosine(n), rtol=1e-10)
        point = area * direction[2] * (n[0] @ -direction) / d ** 2
        deviation = abs(value[0, 0] / point - 1)
        assert converged.all() and deviation < 2 * (size / d) ** 2
        deviations.append(deviation)
    assert 50 < deviations[0] / deviations[1] < 200 and 50 < deviations[1] / deviations[2] < 200


# 3. A polygon across the horizon ------------------------------------------------------------------------------
def test_polygon_straddling_the_horizon():
    corner, edge_u, edge_v = np.array([-1.0, -0.5, 1.0]), np.array([2.0, 0.0, -1.5]), np.array([0.0, 1.5, 0.0])
    vertices = np.array([corner, corner + edge_u, corner + edge_u + edge_v, corner + edge_v])
    x = np.array([0.1, 0.2, 0.0])
    front = np.cross(vertices[1] - vertices[0], vertices[2] - vertices[0])
    if front @ (x - corner) < 0:                             # wind it counter-clockwise seen from x
        vertices = vertices[::-1]
    n = np.array([0.3, 0.0, 1.0]) / np.linalg.norm([0.3, 0.0, 1.0])
    heights = (vertices - x) @ n
    assert heights.min() < 0 < heights.max()
    value, error, converged = polygon_integral(x[None], n[None], vertices, ONE, _cosine(n[None]))
    grid = _grid_polygon(x, n, corner, edge_u, edge_v, lambda w: np.maximum(w @ n, 0.0))
    assert converged.all()
    assert abs(value[0, 0] / grid - 1) < 1e-5
    # exactly: Lambert's formula over the polygon clipped to the horizon
    exact = _lambert(x[None], n[None], _clip(vertices, n, x))[0]
    assert abs(value[0, 0] / exact - 1) < 1e-9


def test_extra_clip_planes_are_exact():
    rng = np.random.default_rng(11)
    for _ in range(30):
        vertices, front, centre, (u, v) = _random_polygon(rng, 5)
        x = centre + rng.uniform(0.2, 1.5) * front + rng.uniform(-1, 1) * u
        n = rng.normal(size=3) + 1.5 * front * -1.0
        n /= np.linalg.norm(n)
        c1, c2 = rng.normal(size=3), rng.normal(size=3)
        clipped = vertices
        for c in (n, c1, c2):
            clipped = _clip(clipped, c, x) if len(clipped) else clipped
        exact = _lambert(x[None], n[None], clipped)[0] if len(clipped) >= 3 else 0.0
        value, error, converged = polygon_integral(x[None], n[None], vertices, ONE, _cosine(n[None]), clip=(c1, c2))
        assert converged.all()
        assert abs(value[0, 0] - exact) <= 1e-9 * abs(exact) + 1e-14


# 4. and 5. The sphere --------------------------------------------------------------------------------------------
def _frostbite(cos_theta, sin2_sigma):
    """``E/L`` of a sphere across the horizon (Snyder 1996; Lagarde & de Rousiers 2014, "Moving Frostbite to
    PBR"), in 40 digits."""
    with mpmath.workdps(40):
        c, s2 = mpmath.mpf(float(cos_theta)), mpmath.mpf(float(sin2_sigma))
        if c * c > s2:
            return float(mpmath.pi * s2 * max(c, 0))
        sin_theta = mpmath.sqrt(1 - c * c)
        x = mpmath.sqrt(1 / s2 - 1)
        y = -x * c / sin_theta
        s = sin_theta * mpmath.sqrt(1 - y * y)
        return float((c * mpmath.acos(y) - x * s) * s2 + mpmath.atan(s / x))


def test_sphere_above_the_horizon():
    rng = np.random.default_rng(3)
    N = 200
    x = rng.normal(size=(N, 3))
    centre, radius = np.array([0.2, -0.1, 0.3]), 0.4
    to_centre = centre - x
    d = np.linalg.norm(to_centre, axis=1)
    keep = d > 1.2 * radius
    x, to_centre, d = x[keep], to_centre[keep], d[keep]
    sin_alpha = radius / d
    a = to_centre / d[:, None]
    # a normal within (90 deg - alpha) of the direction to the centre: the whole cap above the horizon
    tilt = rng.uniform(0, 1, len(x)) * (np.arccos(sin_alpha) - 1e-3)
    side = np.cross(a, rng.normal(size=(len(x), 3)))
    side /= np.linalg.norm(side, axis=1)[:, None]
    n = np.cos(tilt)[:, None] * a + np.sin(tilt)[:, None] * side
    value, error, converged = sphere_integral(x, n, centre, radius, [0.5, 1.0, 2.0], _cosine(n))
    exact = np.pi * sin_alpha ** 2 * np.cos(tilt)
    assert converged.all()
    assert np.allclose(value, exact[:, None] * [0.5, 1.0, 2.0], rtol=1e-9, atol=0)
    solid, _, _ = sphere_integral(x, n, centre, radius, ONE, lambda index, w: np.ones((len(index), 1)))
    cos_alpha = np.sqrt(1 - sin_alpha ** 2)
    assert np.allclose(solid[:, 0], 2 * np.pi * (1 - cos_alpha), rtol=1e-9, atol=0)


def test_sphere_across_the_horizon_matches_the_cap_formula():
    rng = np.random.default_rng(5)
    N = 300
    h = np.exp(rng.uniform(np.log(1.0 + 1e-9), np.log(30.0), N))    # d / r
    theta = rng.uniform(0.0, np.pi, N)
    theta[:20] = np.pi / 2                                           # the centre on the horizon
    radius = 0.7
    x = rng.normal(size=(N, 3))
    n = np.tile([0.0, 0.0, 1.0], (N, 1))
    direction = np.column_stack([np.sin(theta), np.zeros(N), np.cos(theta)])
    values, errors = np.zeros(N), np.zeros(N)
    for i in range(N):                                                # the sphere moves with each point
        centre = x[i] + h[i] * radius * direction[i]
        value, error, converged = sphere_integral(x[i:i + 1], n[i:i + 1], centre, radius, ONE, _cosine(n[i:i + 1]),
                                                  rtol=1e-11)
        assert converged.all()
        d = np.linalg.norm(centre - x[i])                             # the distance the quadrature sees
        values[i], errors[i] = value[0, 0], error[0]
        exact = _frostbite(np.cos(theta[i]), (radius / d) ** 2)
        assert abs(values[i] - exact) <= 1e-8 * exact + 1e-14, (h[i], theta[i])
    straddling = np.cos(theta) ** 2 <= 1 / h ** 2
    assert straddling.sum() > 50 and (~straddling).sum() > 50


def test_sphere_with_points_inside_is_refused():
    x = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.5], [3.0, 0.0, 0.0], [0.9, 0.0, 0.0]])
    with pytest.raises(ValueError, match="3 of 4 points"):
        sphere_integral(x, [0.0, 0.0, 1.0], [0.0, 0.0, 0.0], 1.0, ONE, _cosine(np.tile([0.0, 0.0, 1.0], (4, 1))))


# 6. The disk --------------------------------------------------------------------------------------------------
def _disk_parallel(z, rho, radius):
    """``E/L`` at height ``z`` under a disk facing it, ``rho`` off its axis, the surface parallel to it (the
    configuration factor of a parallel disk), in 40 digits."""
    with mpmath.workdps(40):
        z, rho, radius = (mpmath.mpf(float(v)) for v in (z, rho, radius))
        return float(mpmath.pi / 2 * (1 - (z * z + rho * rho - radius * radius)
                                      / mpmath.sqrt((z * z + rho * rho + radius * radius) ** 2
                                                    - 4 * radius * radius * rho * rho)))


def test_disk_on_and_off_its_axis():
    radius = 0.8
    d = np.array([0.1, 1.0, 5.0])
    x = np.column_stack([np.zeros(3), np.zeros(3), 2.0 - d])
    n = np.tile([0.0, 0.0, 1.0], (3, 1))
    value, _, converged = disk_integral(x, n, [0, 0, 2.0], [0, 0, -1.0], radius, [1.0, 2.0, 3.0], _cosine(n))
    assert converged.all()
    assert np.allclose(value, (np.pi * radius ** 2 / (radius ** 2 + d ** 2))[:, None] * [1.0, 2.0, 3.0],
                       rtol=1e-10, atol=0)
    rng = np.random.default_rng(9)
    rho, z = rng.uniform(0.0, 3.0, 40), np.exp(rng.uniform(np.log(1e-3), np.log(3.0), 40))
    phi = rng.uniform(0, 2 * np.pi, 40)
    x = np.column_stack([rho * np.cos(phi), rho * np.sin(phi), 2.0 - z])
    n = np.tile([0.0, 0.0, 1.0], (40, 1))
    value, _, converged = disk_integral(x, n, [0, 0, 2.0], [0, 0, -1.0], radius, ONE, _cosine(n))
    assert converged.all()
    exact = np.array([_disk_parallel(z[i], rho[i], radius) for i in range(40)])
    assert np.allclose(value[:, 0], exact, rtol=1e-9, atol=1e-15)


def _grid_disk(x, centre, normal, radius, integrand, cells=2000):
    """Midpoint rule over the disk in polar coordinates: ``sum g(w) cos_l / d^2 rho drho dphi``."""
    e1 = np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.6 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    rho = (np.arange(cells) + 0.5) / cells * radius
    phi = (np.arange(cells) + 0.5) / cells * 2 * np.pi
    cell = (radius / cells) * (2 * np.pi / cells)
    total = 0.0
    for rows in np.array_split(np.arange(cells), 20):
        y = centre + rho[rows, None, None] * (np.cos(phi)[None, :, None] * e1 + np.sin(phi)[None, :, None] * e2)
        d = y.reshape(-1, 3) - x
        r = np.linalg.norm(d, axis=1)
        w = d / r[:, None]
        total += np.sum(integrand(w) * np.maximum(-(w @ normal), 0.0) / r ** 2 * np.repeat(rho[rows], cells)) * cell
    return total


def test_disk_tilted_and_across_the_horizon_against_a_grid():
    centre, radius = np.array([0.3, -0.2, 1.2]), 0.9
    normal = np.array([0.4, 0.2, -1.0]) / np.linalg.norm([0.4, 0.2, -1.0])
    x = np.array([0.5, 0.4, 0.1])
    for n in (np.array([0.0, 0.3, 1.0]), np.array([1.0, 0.2, 0.4])):   # wholly above, across the horizon
        n = n / np.linalg.norm(n)
        value, _, converged = disk_integral(x[None], n[None], centre, normal, radius, ONE, _cosine(n[None]))
        grid = _grid_disk(x, centre, normal, radius, lambda w: np.maximum(w @ n, 0.0))
        assert converged.all()
        assert abs(value[0, 0] / grid - 1) < 1e-5


def test_disk_cut_by_planes_against_a_many_sided_polygon():
    """The disk's own clipping (rim arcs and chords) against the polygon's (Sutherland-Hodgman), on a regular
    4096-gon of the disk's area (the two regions differ by O(M^-2) of the rim's share only)."""
    rng = np.random.default_rng(13)
    sides = 4096
    angles = np.arange(sides) * 2 * np.pi / sides
    compared = 0
    while compared < 6:
        centre, normal, radius = rng.normal(size=3), rng.normal(size=3), rng.uniform(0.3, 1.5)
        normal /= np.linalg.norm(normal)
        x = centre + normal * rng.uniform(0.05, 1.5) + 0.8 * rng.normal(size=3)
        if (x - centre) @ normal <= 0:
            continue
        n, planes = rng.normal(size=3), (rng.normal(size=3), rng.normal(size=3))
        n /= np.linalg.norm(n)
        e1 = np.cross(normal, [1.0, 0.0, 0.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(normal, e1)
        scaled = radius * np.sqrt(2 * np.pi / (sides * np.sin(2 * np.pi / sides)))
        polygon = centre + scaled * (np.cos(angles)[:, None] * e1 + np.sin(angles)[:, None] * e2)
        disk, _, converged = disk_integral(x[None], n, centre, normal, radius, ONE, _cosine(n[None]), clip=planes)
        reference, _, _ = polygon_integral(x[None], n, polygon, ONE, _cosine(n[None]), clip=planes)
        assert converged.all()
        assert abs(disk[0, 0] - reference[0, 0]) <= 1e-8 * reference[0, 0] + 1e-11
        compared += disk[0, 0] > 0


# 7. The Phong lobe ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("q", [1, 2, 10, 100])
def test_phong_lobe_inside_a_huge_polygon(q):
    size = 1e7
    vertices = np.array([[-size, -size, 1.0], [-size, size, 1.0], [size, size, 1.0], [size, -size, 1.0]])
    x = np.array([[0.0, 0.0, 0.0], [5.0, -3.0, 0.9]])
    n = np.tile([0.0, 0.0, 1.0], (2, 1))
    value, error, converged = polygon_integral(x, n, vertices, ONE, lambda index, w: np.maximum(w[:, 2:], 0.0) ** q,
                                               clip=(n,))
    assert converged.all()
    assert np.allclose(value, 2 * np.pi / (q + 1), rtol=1e-9, atol=0)


@pytest.mark.parametrize("q", [1, 2, 10])
def test_phong_lobe_against_a_grid(q):
    corner, edge_u, edge_v = np.array([-1.5, -1.0, 1.0]), np.array([3.0, 0.0, 0.0]), np.array([0.0, 2.0, 0.5])
    vertices = np.array([corner, corner + edge_u, corner + edge_u + edge_v, corner + edge_v])
    x = np.array([0.0, 0.0, 0.0])
    if np.cross(vertices[1] - vertices[0], vertices[2] - vertices[0]) @ (x - corner) < 0:
        vertices = vertices[::-1]
    n = np.array([0.5, 0.0, 1.0]) / np.linalg.norm([0.5, 0.0, 1.0])
    r = np.array([-0.6, 0.3, 0.5]) / np.linalg.norm([-0.6, 0.3, 0.5])   # the lobe's edge and the horizon both cut

    def lobe(w):
        return np.maximum(w @ r, 0.0) ** q * np.maximum(w @ n, 0.0)

    value, error, converged = polygon_integral(x[None], n[None], vertices, ONE, lambda index, w: lobe(w)[:, None],
                                               clip=(r[None],))
    grid = _grid_polygon(x, n, corner, edge_u, edge_v, lobe)
    assert converged.all()
    assert abs(value[0, 0] / grid - 1) < 1e-5


# 8. Lights touching the surface -----------------------------------------------------------------------------------
# Within a distance rho of an edge the answer moves by about eps |coordinates| / rho when the float64 inputs move by
# an ulp: the error estimate includes that bound, and `converged` is False where it exceeds rtol |value|.
def test_points_on_and_a_hair_from_the_polygon():
    vertices = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 0.0, 1.0]])  # faces -z
    feet = [(0.5, 0.5), (0.5, 0.0), (0.0, 0.0), (0.5, -1e-6), (0.3, 1e-9), (2.0, 0.5)]
    heights = [1e-3, 1e-6, 1e-9, 1e-12]
    x = np.array([(a, b, 1.0 - h) for h in heights for a, b in feet])
    n = np.array([0.0, 0.3, 1.0]) / np.linalg.norm([0.0, 0.3, 1.0])
    normals = np.tile(n, (len(x), 1))
    value, error, converged = polygon_integral(x, normals, vertices, ONE, _cosine(normals))
    assert np.all(np.isfinite(value)) and np.all(np.isfinite(error))
    exact = np.array([_lambert_mp(x[i], n, vertices) for i in range(len(x))])
    assert np.all(np.abs(value[:, 0] - exact) <= error)
    assert converged[:6].all() and converged.sum() >= 10      # h = 1e-3 all; nearer, rounding limits some
    assert np.all(np.abs(value[converged, 0] - exact[converged]) <= 1e-9 * exact[converged])
    # on the plane, on an edge or a vertex of it, or behind: nothing
    on = np.array([[0.5, 0.5, 1.0], [0.5, 0.0, 1.0], [0.0, 0.0, 1.0], [2.0, 2.0, 1.0], [0.5, 0.5, 1.5]])
    value, error, converged = polygon_integral(on, n, vertices, ONE, _cosine(np.tile(n, (5, 1))))
    assert np.all(value == 0.0) and np.all(error == 0.0) and converged.all()


def test_the_error_estimate_is_honest_near_edges():
    rng = np.random.default_rng(21)
    flagged = 0
    for _ in range(60):
        vertices, front, _, _ = _random_polygon(rng, int(rng.integers(3, 6)))
        i = rng.integers(len(vertices))
        a, b = vertices[i], vertices[(i + 1) % len(vertices)]
        h = 10.0 ** rng.uniform(-14, -1)
        side = np.cross(front, b - a) / np.linalg.norm(b - a)
        x = a + rng.uniform(-0.2, 1.2) * (b - a) + h * front + rng.uniform(-2, 2) * h * side
        n = front + 0.5 * rng.normal(size=3)
        n /= np.linalg.norm(n)
        value, error, converged = polygon_integral(x[None], n[None], vertices, ONE, _cosine(n[None]))
        exact = _lambert_mp(x, n, vertices)
        assert abs(value[0, 0] - exact) <= error[0]
        assert not converged[0] or error[0] <= 1e-9 * abs(value[0, 0])
        flagged += not converged[0]
    assert 10 < flagged < 50


def test_wall_meeting_the_floor():
    """An emitter standing on the floor: points on the floor in front of its base edge."""
    vertices = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 0.0, 0.0]])  # faces +y
    y = np.array([1.0, 1e-3, 1e-7, 1e-11, 1e-15])
    x = np.column_stack([np.full(5, 0.5), y, np.zeros(5)])
    normals = np.tile([0.0, 0.0, 1.0], (5, 1))
    value, error, converged = polygon_integral(x, normals, vertices, ONE, _cosine(normals))
    assert np.all(np.isfinite(value)) and converged[:2].all()
    for i in range(5):
        exact = _lambert_mp(x[i], normals[i], vertices)
        assert abs(value[i, 0] - exact) <= min(error[i], 1e-9 * exact)
    assert abs(value[-1, 0] - np.pi / 2) < 1e-6                       # the quarter sphere's limit, pi/2


def test_disk_and_sphere_touching():
    radius = 1.0
    rim = [1.0 - 1e-6, 1.0, 1.0 + 1e-6]
    x = np.array([(rho, 0.0, 2.0 - h) for h in (1e-4, 1e-8, 1e-12) for rho in rim])
    n = np.tile([0.0, 0.0, 1.0], (len(x), 1))
    value, error, converged = disk_integral(x, n, [0, 0, 2.0], [0, 0, -1.0], radius, ONE, _cosine(n))
    assert np.all(np.isfinite(value)) and converged[:3].all()
    for i in range(len(x)):
        exact = _disk_parallel(2.0 - x[i, 2], x[i, 0], radius)
        assert abs(value[i, 0] - exact) <= error[i], x[i]
        assert not converged[i] or abs(value[i, 0] - exact) <= 1e-9 * exact
    # a sphere a hair away, its cap across the horizon
    theta = 0.3
    for gap in (1e-6, 1e-12):
        centre = np.array([np.sin(theta), 0.0, np.cos(theta)]) * (1.0 + gap)
        value, error, converged = sphere_integral(np.zeros((1, 3)), [0.0, 0.0, 1.0], centre, 1.0, ONE,
                                                  _cosine(n[:1]))
        exact = _frostbite(np.cos(theta), 1.0 / np.linalg.norm(centre) ** 2)
        assert converged.all() and abs(value[0, 0] / exact - 1) < 1e-9


def test_the_error_estimate_is_honest_when_the_budget_runs_out():
    vertices = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 0.0, 1.0]])
    rng = np.random.default_rng(4)
    x = np.column_stack([rng.uniform(-0.5, 1.5, 60), rng.uniform(-0.5, 1.5, 60), 1.0 - 10.0 ** rng.uniform(-9, 0, 60)])
    n = rng.normal(size=(60, 3)) + [0.0, 0.0, 2.0]
    n /= np.linalg.norm(n, axis=1)[:, None]
    exact, _, _ = polygon_integral(x, n, vertices, ONE, _cosine(n), rtol=1e-13)
    value, error, converged = polygon_integral(x, n, vertices, ONE, _cosine(n), rtol=1e-13, max_depth=0)
    assert not converged.all()
    assert np.all(np.abs(value[:, 0] - exact[:, 0]) <= error + 1e-15)


def test_inputs_are_checked():
    n = np.array([[0.0, 0.0, 1.0]])
    x = np.zeros((1, 3))
    star = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [0.2, 0.2, 1.0], [1.0, 0.0, 1.0]])
    with pytest.raises(ValueError, match="convex"):
        polygon_integral(x, n, star, ONE, _cosine(n))
    with pytest.raises(ValueError, match="V >= 3"):
        polygon_integral(x, n, star[:2], ONE, _cosine(n))
    with pytest.raises(ValueError, match=r"\(M, 1\) or \(M, 3\)"):
        polygon_integral(x, n, star[[0, 1, 3]], ONE, lambda index, w: np.ones((len(index), 2)))


def test_twenty_thousand_points():
    rng = np.random.default_rng(1)
    N = 20_000
    x = np.column_stack([rng.uniform(-1, 2, N), rng.uniform(-1, 2, N), rng.uniform(0, 1.9, N)])
    n = rng.normal(size=(N, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    vertices = np.array([[0.0, 0.0, 2.0], [0.0, 1.0, 2.0], [1.0, 1.0, 2.0], [1.0, 0.0, 2.0]])
    start = time.perf_counter()
    value, error, converged = polygon_integral(x, n, vertices, ONE, _cosine(n), rtol=1e-8)
    elapsed = time.perf_counter() - start
    assert converged.all()
    assert np.all(error <= 1e-8 * np.abs(value[:, 0]) + 1e-300)
    assert elapsed < 15.0
