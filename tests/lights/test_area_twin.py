"""The area lights' twin (glphong.twin.area) computed as arrays (issue 40): the same values, to the bit, as the
vertex-by-vertex loop it replaced and as numpy's own cross product and norm, in float64 and float32."""
import numpy as np
import pytest

from glphong.twin import area
from glphong.twin.functions import dot


def _loop_clip(p, e, count, c):
    """area.glsl's Sutherland-Hodgman loop, vertex by vertex (the twin's former formulation)."""
    n, size = p.shape[:2]
    rows = np.arange(n)
    live = np.arange(size)[None, :] < count[:, None]
    d = np.where(live, dot(c[:, None, :], p), 0.0)
    q, f = np.zeros_like(p), np.zeros_like(e)
    m = np.zeros(n, int)
    open_ = np.full(n, -1)

    def put(where, point, edge=None):
        nonlocal m
        idx = m[where]
        q[rows[where], idx] = point[where]
        if edge is not None:
            f[rows[where], idx] = edge[where]
        m = np.where(where, np.minimum(m + 1, size - 1), m)
        return idx

    with np.errstate(divide="ignore", invalid="ignore"):
        for i in range(int(count.max()) if n else 0):
            active = i < count
            nxt = np.where(i + 1 < count, i + 1, 0)
            d_a, d_b = d[:, i], d[rows, nxt]
            a_in, b_in = d_a >= 0, d_b >= 0
            t = np.where(a_in == b_in, 0.0, d_a / (d_a - d_b)).astype(p.dtype)[:, None]
            put(active & a_in, p[:, i], np.where(b_in[:, None], e[:, i], e[:, i] * t))
            leaving = active & a_in & ~b_in
            open_[leaving] = put(leaving, p[:, i] + e[:, i] * t)
            put(active & ~a_in & b_in, p[:, i] + e[:, i] * t, e[:, i] * (1 - t))
    has = open_ >= 0
    if has.any():
        r, o = rows[has], open_[has]
        f[r, o] = q[r, np.where(o + 1 < m[has], o + 1, 0)] - q[r, o]
    live = np.arange(size)[None, :] < m[:, None]
    return np.where(live[..., None], q, 0.0), np.where(live[..., None], f, 0.0), m


def _polygons(rng, n, dtype, shuffled):
    """``n`` polygons of 0 to 10 vertices around random points (convex, or in random order: self-crossing, so a clip
    puts more vertices than the array holds), padded with zeros, and a plane through the origin for each."""
    count = rng.integers(0, area.AREA_MAX_VERTICES + 1 if shuffled else 9, n)
    p = np.zeros((n, area.AREA_MAX_VERTICES, 3))
    for k, c in enumerate(count):
        angle = rng.uniform(0, 2 * np.pi, c)
        angle = angle if shuffled else np.sort(angle)
        rotation = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        p[k, :c] = (np.stack([np.cos(angle), np.sin(angle), np.zeros(c)], 1) * rng.uniform(0.1, 2)) @ rotation.T \
            + rng.normal(size=3)
    p = p.astype(dtype)
    e = np.zeros_like(p)
    for k, c in enumerate(count):
        e[k, :c] = np.roll(p[k, :c], -1, axis=0) - p[k, :c]
    plane = rng.normal(size=(n, 3))
    plane[:20] = 0.0  # every vertex on the plane
    return p, e, count, (plane / np.maximum(np.linalg.norm(plane, axis=1, keepdims=True), 1e-300)).astype(dtype)


def _same(got, want):
    return got.dtype == want.dtype and got.shape == want.shape and np.array_equal(got, want, equal_nan=True)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("shuffled", [False, True])
def test_the_clip_as_arrays_is_the_loop_to_the_bit(dtype, shuffled):
    rng = np.random.default_rng(3 + shuffled)
    p, e, count, c = _polygons(rng, 3000, dtype, shuffled)
    with np.errstate(all="ignore"):
        got, want = area.area_clip(p, e, count, c), _loop_clip(p, e, count, c)
    assert all(_same(g, w) for g, w in zip(got, want))
    if shuffled:
        assert (want[2] == area.AREA_MAX_VERTICES - 1).any()  # the array bound was reached
    empty = np.zeros((0, area.AREA_MAX_VERTICES, 3), dtype)
    assert all(_same(g, w) for g, w in zip(area.area_clip(empty, empty, np.zeros(0, int), np.zeros((0, 3), dtype)),
                                           _loop_clip(empty, empty, np.zeros(0, int), np.zeros((0, 3), dtype))))


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_cross_and_norm_are_numpys_to_the_bit(dtype):
    rng = np.random.default_rng(5)
    a = (rng.normal(size=(4000, 6, 3)) * 10.0 ** rng.integers(-15, 15, size=(4000, 6, 3))).astype(dtype)
    b = (rng.normal(size=(4000, 1, 3)) * 10.0 ** rng.integers(-15, 15, size=(4000, 1, 3))).astype(dtype)
    with np.errstate(all="ignore"):
        for x, y in ((a, b), (a[:, 0], b[:, 0]), (a[:, :, :], np.float64(1.0) * b), (a[0, 0], b[:, 0])):
            assert _same(area._cross(x, y), np.cross(x, y))
            assert _same(area._norm(x), np.linalg.norm(x, axis=-1))


def test_a_sum_over_the_live_vertices_is_the_whole_widths():
    rng = np.random.default_rng(9)
    terms = rng.normal(size=(1000, area.AREA_MAX_VERTICES)) * 10.0 ** rng.integers(-8, 8, size=(1000, 1))
    for width in range(area.AREA_MAX_VERTICES + 1):
        padded = np.where(np.arange(area.AREA_MAX_VERTICES) < width, terms, 0.0)
        assert _same(area._vertex_sum(terms[:, :width], area.AREA_MAX_VERTICES), padded.sum(axis=1))


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_the_cosine_of_one_polygon_for_many_normals_is_the_clipped_cosine_to_the_bit(dtype):
    """`area_clipped_cosine_of` reuses the polygon's edges where no vertex is below the horizon: the same bits as the
    clip and the formula run anew, for normals that keep every vertex, that cut the polygon, and that clip it all."""
    rng = np.random.default_rng(11)
    p, e, count, c = _polygons(rng, 3000, dtype, False)
    cosine = area.area_clipped_cosine_of(p, e, count)
    centre = np.sum(p, axis=1) / np.maximum(count, 1)[:, None]
    toward = -centre / np.maximum(np.linalg.norm(centre, axis=1, keepdims=True), 1e-300)  # most keep every vertex
    whole = 0
    with np.errstate(all="ignore"):
        for n in (c, toward.astype(dtype), -toward.astype(dtype), (toward + 0.3 * c).astype(dtype)):
            got, want = cosine(n), area.area_clipped_cosine(p, e, count, n)
            assert _same(got, want)
            active = np.arange(area.AREA_MAX_VERTICES)[None, :] < count[:, None]
            whole += np.all(~active | (np.sum(n[:, None, :] * p, -1) >= 0), axis=1).sum()
    assert whole > 3000  # the shortcut was taken


@pytest.mark.parametrize("integral", ["irradiance", "lobe"])
def test_the_area_bands_shortcuts_hold_the_generic_band(integral):
    """The rect's band takes `sensitivity_band`'s shortcuts (the radiance a factor, the centre moved with x, each move
    one way): it holds the generic band (every move both ways, each uniform's own) to 1e-3 of each deviation (its
    second order) and 1e-12 of the largest value, at points around the light, below its plane and in it beside it
    (seen edge-on: held at 0 on one side), with normals that cut the polygon and that clip it all."""
    import glphong
    from glphong.definitions.light import sensitivity_band
    from glphong.twin.band import BAND

    light = glphong.RectLight((0.3, -0.5, 1.6), (0.0, 0.6, 0.3), (1.0, 0.0, 0.0), (5.0, 2.0, 0.5))
    p = light.values()
    rng = np.random.default_rng(13)
    x = rng.normal(size=(4000, 3)) * (1.5, 1.5, 1.0)
    a, b = rng.uniform(0.6, 2.0, (2, 400)) * rng.choice([-1.0, 1.0], (2, 400))
    x[:400] = p.center + a[:, None] * p.u + b[:, None] * p.v  # in the light's plane, off the light (there E jumps)
    n, r = rng.normal(size=(2, 4000, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    r /= np.linalg.norm(r, axis=1, keepdims=True)
    if integral == "irradiance":
        evaluate, directions = (lambda x_, p_, n_: light.irradiance(x_, n_, p_)), (n,)
    else:
        evaluate, directions = (lambda x_, p_, n_, r_: light.lobe(x_, n_, r_, 20, p_)), (n, r)
    base = evaluate(x, p, *directions)
    low, high = sensitivity_band(evaluate, x, p, light.perturbed_uniforms(), BAND, directions, factors=("radiance",),
                                 offset="center", one_sided=True)
    g_low, g_high = sensitivity_band(evaluate, x, p, light.perturbed_uniforms(), BAND, directions)
    floor = 1e-12 * base.max()
    assert (base > 0).mean() > 0.2 and (base == 0).mean() > 0.2 and (g_high[:400] > 0).mean() > 0.3
    assert np.all(high >= g_high - 1e-3 * (g_high - base) - floor)
    assert np.all(low <= g_low + 1e-3 * (base - g_low) + floor)
