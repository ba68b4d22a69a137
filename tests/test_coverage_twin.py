"""The exact per-pixel coverage (glphong.checks.coverage_twin) against closed forms computed here.

CPU only, no GL.  Every expected value is computed in this file from the geometry by hand: the image positions of
world points from the cameras' formulas (orthographic ``xp = (x / (ymag W / H) + 1) W / 2``, ``yp = (1 - y / ymag)
H / 2``; pinhole ``xp = (x / -z / (t W / H) + 1) W / 2``, ``yp = (1 - y / -z / t) H / 2``, ``t = tan(yfov / 2)``;
OpenCV intrinsics ``u = fx X / Z + cx``, ``xp = u + 0.5``), areas by the shoelace formula, and the share of a pixel
by clipping a convex polygon to the pixel's square with a clipper of this file.

- a screen-aligned rectangle with fractional borders (orthographic): each pixel's fraction is the product of the
  overlaps of its row and column with the rectangle;
- two overlapping triangles at different depths: the front one's share of each pixel, and the back one's minus
  their intersection;
- interpenetrating quads, orthographic (the split at a fractional column) and perspective (the projected halves);
- a sphere mesh: the total coverage is the area of the convex hull of its projected vertices (orthographic and
  perspective), 1e-9 relative; no pixel above 1;
- objects partly outside the image; a floor reaching behind a perspective camera (near-plane clipping) and cut by
  its far plane: the rows below the projected cut line;
- a PerspectiveCamera and an IntrinsicsCamera with its principal point off centre: a quad parallel to the image
  plane covers the rectangle of its projected corners;
- agreement with frame_twin's ray cast where a pixel is wholly one object's, and with the share a 16 x 16 grid of
  its rays per pixel estimates (a sphere and a box cut open by the near plane, before a tilted quad);
- layout: sorted, padded, sums at most 1, top_k; a constant alpha mask below its cutoff hides its object, a textured
  one is refused; coincident faces go to the lower object index; a triangle seen edge-on covers nothing.
"""
import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.checks import coverage_twin as ct
from glphong.checks import frame_twin as ft
from glphong.scene.geometry import MeshData

W, H = 8, 6
YMAG = 1.5  # orthographic: 0.5 m per pixel, xp = 2 x + 4, yp = 3 - 2 y


def _ortho(eye_z=5.0, **kw):
    pose = np.eye(4)
    pose[2, 3] = eye_z
    return glphong.OrthographicCamera(YMAG, pose=pose, **kw)


def _ortho_xy(x, y):
    """Image position of the world point (x, y, z) for `_ortho` at W x H, by hand."""
    return 2.0 * np.asarray(x) + 4.0, 3.0 - 2.0 * np.asarray(y)


def _mesh(points, faces):
    points = np.asarray(points, np.float32)
    return MeshData(points, np.tile([0.0, 0.0, 1.0], (len(points), 1)), np.asarray(faces, np.uint32))


def _rect(x0, x1, y0, y1, z=0.0):
    return _mesh([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], [[0, 1, 2], [0, 2, 3]])


def _scene(camera):
    return glphong.Scene(camera, [glphong.PointLight((0.0, 0.0, 3.0), 10.0)])


def _overlap(lo, hi, a, b):
    """Length of [lo, hi] (arrays) inside [a, b]."""
    return np.clip(np.minimum(hi, b) - np.maximum(lo, a), 0.0, None)


def _rect_fractions(xa, xb, ya, yb, width=W, height=H):
    """(height, width) share of each pixel inside the image rectangle [xa, xb] x [ya, yb]."""
    i, j = np.arange(width), np.arange(height)
    return _overlap(j, j + 1.0, ya, yb)[:, None] * _overlap(i, i + 1.0, xa, xb)[None, :]


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _shoelace(poly):
    poly = np.asarray(poly, float).reshape(-1, 2)
    if len(poly) < 3:
        return 0.0
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _clip(poly, n, c):
    """The part of a convex polygon (P, 2) where ``n . p + c >= 0``."""
    out = []
    for k in range(len(poly)):
        p, q = np.asarray(poly[k], float), np.asarray(poly[(k + 1) % len(poly)], float)
        fp, fq = np.dot(n, p) + c, np.dot(n, q) + c
        if fp >= 0:
            out.append(p)
        if (fp >= 0) != (fq >= 0):
            out.append(p + fp / (fp - fq) * (q - p))
    return out


def _intersect(poly, convex):
    """``poly`` clipped to the convex polygon ``convex`` (either winding)."""
    convex = np.asarray(convex, float)
    sign = 1.0 if _cross(convex[1] - convex[0], convex[2] - convex[0]) > 0 else -1.0
    for k in range(len(convex)):
        a, b = convex[k], convex[(k + 1) % len(convex)]
        d = sign * (b - a)
        poly = _clip(poly, np.array([-d[1], d[0]]), d[1] * a[0] - d[0] * a[1])
        if not poly:
            return []
    return poly


def _pixel_shares(poly, width=W, height=H, minus=None):
    """(height, width) area of the convex polygon inside each pixel, less that of its intersection with ``minus``."""
    out = np.zeros((height, width))
    for j in range(height):
        for i in range(width):
            square = [[i, j], [i + 1, j], [i + 1, j + 1], [i, j + 1]]
            part = _intersect(list(np.asarray(poly, float)), square)
            out[j, i] = _shoelace(part)
            if minus is not None and part:
                out[j, i] -= _shoelace(_intersect(part, minus))
    return out


def _hull(points):
    """Andrew's monotone chain: the convex hull (P, 2) of points (N, 2), counter-clockwise."""
    pts = sorted(map(tuple, np.asarray(points, float)))

    def half(seq):
        chain = []
        for p in seq:
            while len(chain) >= 2 and _cross(np.subtract(chain[-1], chain[-2]), np.subtract(p, chain[-2])) <= 0:
                chain.pop()
            chain.append(p)
        return chain

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _share(ids, fractions, instance_id):
    """(H, W) fraction of one id."""
    return np.sum(np.where(ids == instance_id, fractions, 0.0), axis=-1)


def _check_layout(ids, fractions):
    assert ids.dtype == np.int64 and fractions.dtype == np.float64 and ids.shape == fractions.shape
    assert ids.shape[-1] >= 1
    assert np.all(np.diff(fractions, axis=-1) <= 0.0)
    assert np.all(fractions >= 0.0) and np.all(fractions.sum(-1) <= 1.0 + 1e-12)
    assert np.all((ids == 0) == (fractions == 0.0))
    live = ids != 0  # no id twice in a pixel
    for j, i in zip(*np.nonzero(live.sum(-1) > 1)):
        assert len(set(ids[j, i][live[j, i]])) == live[j, i].sum()


# --------------------------------------------------------------------------- 1. a screen-aligned rectangle
def test_rectangle_with_fractional_borders():
    scene = _scene(_ortho())
    x0, x1, y0, y1 = -1.296875, 0.90625, -0.796875, 1.09375  # binary fractions: exact in the float32 mesh
    scene.add(_rect(x0, x1, y0, y1), glphong.Lambert(0.5), instance_id=7)
    ids, fractions = ct.exact_coverage(scene, W, H)
    assert ids.shape == (H, W, 1)
    _check_layout(ids, fractions)
    (xa, xb), (yb, ya) = _ortho_xy([x0, x1], [y0, y1])  # xp in [1.40625, 5.8125], yp in [0.8125, 4.59375]
    expected = _rect_fractions(xa, xb, ya, yb)
    np.testing.assert_allclose(fractions[..., 0], expected, atol=1e-12)
    assert np.all(ids[..., 0] == np.where(expected > 0, 7, 0))
    assert fractions[0, 1, 0] == pytest.approx(0.59375 * 0.1875, abs=1e-12)  # the top-left corner pixel, by hand
    assert fractions[2, 3, 0] == 1.0


# --------------------------------------------------------------------------- 2. overlapping triangles
def test_front_triangle_hides_the_back_one():
    scene = _scene(_ortho())
    back = [[-1.6875, -1.1875], [1.3125, -0.875], [-0.1875, 1.375]]  # binary fractions: exact in float32
    front = [[-0.5625, 0.6875], [-1.0625, -0.5], [1.5625, 0.1875]]  # clockwise: both faces count
    scene.add(_mesh([p + [0.0] for p in back], [[0, 1, 2]]), glphong.Lambert(0.5), instance_id=3)
    scene.add(_mesh([p + [0.5] for p in front], [[0, 1, 2]]), glphong.Lambert(0.5), instance_id=9)
    ids, fractions = ct.exact_coverage(scene, W, H)
    _check_layout(ids, fractions)
    back_xy = np.stack(_ortho_xy(*np.array(back).T), axis=-1)
    front_xy = np.stack(_ortho_xy(*np.array(front).T), axis=-1)
    want_front = _pixel_shares(front_xy)
    want_back = _pixel_shares(back_xy, minus=front_xy)
    np.testing.assert_allclose(_share(ids, fractions, 9), want_front, atol=1e-12)
    np.testing.assert_allclose(_share(ids, fractions, 3), want_back, atol=1e-12)
    total = _shoelace(back_xy) + _shoelace(front_xy) - _shoelace(_intersect(list(back_xy), front_xy))
    assert fractions.sum() == pytest.approx(total, rel=1e-12)
    assert ids.shape[-1] == 2 and np.any(fractions[..., 1] > 0)


# --------------------------------------------------------------------------- 3. interpenetrating quads
def _tilted(x0, slope, half_y):
    """A quad over x in [-1, 1], |y| <= half_y, on the plane z = slope (x - x0): it crosses z = 0 along x = x0."""
    pts = [[x, y, slope * (x - x0)] for x, y in ((-1, -half_y), (1, -half_y), (1, half_y), (-1, half_y))]
    return _mesh(pts, [[0, 1, 2], [0, 2, 3]])


def test_interpenetrating_quads_orthographic():
    scene = _scene(_ortho())
    scene.add(_rect(-1.0, 1.0, -1.0, 1.0), glphong.Lambert(0.5), instance_id=1)
    scene.add(_tilted(0.125, 1.0, 0.625), glphong.Lambert(0.5), instance_id=2)
    ids, fractions = ct.exact_coverage(scene, W, H)
    _check_layout(ids, fractions)
    # the tilted quad is nearer (larger z) right of x = 0.125: xp = 4.25; its rows yp in [1.75, 4.25]
    tilted = _rect_fractions(4.25, 6.0, 1.75, 4.25)
    flat = _rect_fractions(2.0, 6.0, 1.0, 5.0) - tilted
    np.testing.assert_allclose(_share(ids, fractions, 2), tilted, atol=1e-12)
    np.testing.assert_allclose(_share(ids, fractions, 1), flat, atol=1e-12)
    assert fractions[2, 4, 0] == pytest.approx(0.75, abs=1e-12) and fractions[2, 4, 1] == pytest.approx(0.25, abs=1e-12)
    assert list(ids[2, 4, :2]) == [2, 1]


def test_interpenetrating_quads_perspective():
    w, h, yfov = 24, 18, 0.9
    t = np.tan(yfov / 2)
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), yfov=yfov)
    scene = _scene(camera)
    scene.add(_rect(-1.0, 1.0, -1.0, 1.0), glphong.Lambert(0.5), instance_id=1)
    scene.add(_tilted(0.125, 0.75, 0.625), glphong.Lambert(0.5), instance_id=2)
    ids, fractions = ct.exact_coverage(scene, w, h)
    _check_layout(ids, fractions)

    def project(p):  # world point -> image position, camera at z = 4 looking down -z
        x, y, z = p[0], p[1], p[2] - 4.0
        return [(x / -z / (t * w / h) + 1.0) * w / 2.0, (1.0 - y / -z / t) * h / 2.0]

    near_part = [project([x, y, 0.75 * (x - 0.125)])
                 for x, y in ((0.125, -0.625), (1, -0.625), (1, 0.625), (0.125, 0.625))]
    flat = [project([x, y, 0.0]) for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    np.testing.assert_allclose(_share(ids, fractions, 2), _pixel_shares(near_part, w, h), atol=1e-12)
    np.testing.assert_allclose(_share(ids, fractions, 1), _pixel_shares(flat, w, h, minus=near_part), atol=1e-12)


# --------------------------------------------------------------------------- 4. a sphere's silhouette
@pytest.mark.parametrize("kind", ["orthographic", "perspective"])
def test_sphere_total_is_its_silhouette(kind):
    w, h = 32, 24
    mesh = primitives.sphere(2, 0.9)
    pose = np.eye(4)
    pose[:3, 3] = [0.13, -0.07, 0.0]
    world = mesh.positions.astype(np.float64) + pose[:3, 3]
    if kind == "orthographic":
        camera = _ortho()
        xp = (world[:, 0] / (YMAG * w / h) + 1.0) * w / 2.0
        yp = (1.0 - world[:, 1] / YMAG) * h / 2.0
    else:
        yfov = 0.8
        t = np.tan(yfov / 2)
        camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.5), (0.0, 0.0, 0.0), yfov=yfov)
        z = 3.5 - world[:, 2]
        xp = (world[:, 0] / z / (t * w / h) + 1.0) * w / 2.0
        yp = (1.0 - world[:, 1] / z / t) * h / 2.0
    assert xp.min() > 0 and xp.max() < w and yp.min() > 0 and yp.max() < h  # wholly inside the image
    scene = _scene(camera)
    scene.add(mesh, glphong.Lambert(0.5), pose=pose, instance_id=5)
    ids, fractions = ct.exact_coverage(scene, w, h)
    _check_layout(ids, fractions)
    assert set(np.unique(ids)) == {0, 5}
    hull = _hull(np.stack([xp, yp], axis=-1))
    assert fractions.sum() == pytest.approx(_shoelace(hull), rel=1e-9)
    inner = _pixel_shares(hull, w, h)
    np.testing.assert_allclose(fractions[..., 0], inner, atol=1e-9)


# --------------------------------------------------------------------------- 5. partly outside; near and far planes
def test_partly_outside_the_image():
    scene = _scene(_ortho())
    scene.add(_rect(-2.6875, -0.4375, 0.34375, 1.90625), glphong.Lambert(0.5), instance_id=4)  # xp [-1.375, 3.125],
    # yp [-0.8125, 2.3125]
    ids, fractions = ct.exact_coverage(scene, W, H)
    _check_layout(ids, fractions)
    expected = _rect_fractions(0.0, 3.125, 0.0, 2.3125)
    np.testing.assert_allclose(fractions[..., 0], expected, atol=1e-12)
    assert fractions.sum() == pytest.approx(3.125 * 2.3125, rel=1e-12)


@pytest.mark.parametrize("zfar", [100.0, 20.0])
def test_floor_behind_the_camera_and_the_far_plane(zfar):
    w, h, yfov = 16, 12, 0.8
    t = np.tan(yfov / 2)
    camera = glphong.PerspectiveCamera(yfov, znear=0.05, zfar=zfar)  # at the origin, looking down -z
    scene = _scene(camera)
    # the floor y = -1, |x| <= 50, |z| <= 50: it reaches behind the camera (and crosses its near plane)
    floor = _mesh([[-50, -1, -50], [50, -1, -50], [50, -1, 50], [-50, -1, 50]], [[0, 1, 2], [0, 2, 3]])
    scene.add(floor, glphong.Lambert(0.5), instance_id=8)
    ids, fractions = ct.exact_coverage(scene, w, h)
    _check_layout(ids, fractions)
    # a floor point at depth Z lies at y = -1 / Z on the plane z = -1; it is seen up to Z = min(50, zfar) (its far
    # side, or the far plane), and |x| <= 50 / Z reaches beyond the image's sides; the near plane lies below it
    top = (1.0 + (1.0 / min(50.0, zfar)) / t) * h / 2.0
    expected = _rect_fractions(0.0, w, top, h, w, h)
    np.testing.assert_allclose(fractions[..., 0], expected, atol=1e-12)


# --------------------------------------------------------------------------- 6. pinhole and intrinsics cameras
def test_perspective_quad_parallel_to_the_image():
    w, h, yfov = 20, 15, 0.7
    t = np.tan(yfov / 2)
    camera = glphong.PerspectiveCamera.look_at((0.2, -0.1, 3.0), (0.2, -0.1, 0.0), yfov=yfov)
    scene = _scene(camera)
    scene.add(_rect(-0.375, 0.40625, -0.515625, 0.28125, z=0.40625), glphong.Lambert(0.5), instance_id=6)
    ids, fractions = ct.exact_coverage(scene, w, h)
    _check_layout(ids, fractions)
    z = 3.0 - 0.40625
    xa, xb = ((np.array([-0.375, 0.40625]) - 0.2) / z / (t * w / h) + 1.0) * w / 2.0
    yb, ya = (1.0 - (np.array([-0.515625, 0.28125]) + 0.1) / z / t) * h / 2.0
    np.testing.assert_allclose(fractions[..., 0], _rect_fractions(xa, xb, ya, yb, w, h), atol=1e-12)


def test_intrinsics_camera_off_centre():
    w, h = 40, 30
    fx, fy, cx, cy = 61.0, 57.5, 23.3, 12.6
    camera = glphong.IntrinsicsCamera(fx, fy, cx, cy, w, h)  # at the origin: OpenCV X = x, Y = -y, Z = -z
    scene = _scene(camera)
    x0, x1, y0, y1, z = -0.40625, 0.234375, -0.3125, 0.359375, -2.0
    scene.add(_rect(x0, x1, y0, y1, z=z), glphong.Lambert(0.5), instance_id=11)
    ids, fractions = ct.exact_coverage(scene, w, h)
    _check_layout(ids, fractions)
    u = fx * np.array([x0, x1]) / -z + cx
    v = fy * -np.array([y1, y0]) / -z + cy
    expected = _rect_fractions(u[0] + 0.5, u[1] + 0.5, v[0] + 0.5, v[1] + 0.5, w, h)  # pixel centres at integers
    np.testing.assert_allclose(fractions[..., 0], expected, atol=1e-12)
    # rendered at twice the size, the same camera scales its intrinsics
    ids2, fractions2 = ct.exact_coverage(scene, 2 * w, 2 * h)
    expected2 = _rect_fractions(2 * (u[0] + 0.5), 2 * (u[1] + 0.5), 2 * (v[0] + 0.5), 2 * (v[1] + 0.5), 2 * w, 2 * h)
    np.testing.assert_allclose(fractions2[..., 0], expected2, atol=1e-12)


# --------------------------------------------------------------------------- 7. agreement with the ray cast
def test_interior_pixels_agree_with_the_ray_cast():
    w, h = 40, 30
    camera = glphong.PerspectiveCamera.look_at((0.3, 0.4, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = _scene(camera)
    scene.add(primitives.sphere(2, 0.7), glphong.Lambert(0.5), instance_id=21)
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.0, -0.5]
    scene.add(primitives.plane(2.5), glphong.Lambert(0.5), pose=pose, instance_id=22)
    ids, fractions = ct.exact_coverage(scene, w, h)
    _check_layout(ids, fractions)
    hits = ft.cast_pixels(scene, w, h, offsets=[[0.5, 0.5]])
    index = hits.object_index[0]
    cast_ids = np.where(index >= 0, np.array([o.instance_id for o in scene.objects])[index], 0)
    interior = fractions[..., 0] >= 1.0 - 1e-12
    assert interior.sum() > 200 and np.any(ids[..., 0][interior] == 21) and np.any(ids[..., 0][interior] == 22)
    assert np.all(cast_ids[interior] == ids[..., 0][interior])
    assert np.all(cast_ids[fractions.sum(-1) == 0.0] == 0)  # an uncovered pixel's centre hits nothing


# --------------------------------------------------------------------------- 8. layout, top_k and alpha masks
def test_layout_top_k_and_alpha_masks():
    scene = _scene(_ortho())
    scene.add(_rect(-1.0, 1.0, -1.0, 1.0), glphong.Lambert(0.5), instance_id=1)
    scene.add(_tilted(0.125, 1.0, 0.625), glphong.Lambert(0.5), instance_id=2)
    scene.add(_rect(-0.3125, 0.1875, -0.1875, 0.34375, z=0.875), glphong.Lambert(0.5), instance_id=3)
    hidden = glphong.Lambert(0.5, alpha_mask=glphong.AlphaMask(0.5, 0.49))
    scene.add(_rect(-2.0, 2.0, -2.0, 2.0, z=2.0), hidden, instance_id=4)  # below its cutoff: not drawn
    ids, fractions = ct.exact_coverage(scene, W, H)
    _check_layout(ids, fractions)
    assert not np.any(ids == 4) and ids.shape[-1] == 3
    # the pixel (2, 4) [xp 4..5, yp 2..3]: the small quad (xp 3.375..4.375, yp 2.3125..3.375) covers 0.375 x 0.6875,
    # the tilted one the rest right of xp 4.25 (0.75 x 1 less 0.125 x 0.6875), the flat one 0.25 x (1 - 0.6875)
    assert list(ids[2, 4]) == [2, 3, 1]
    np.testing.assert_allclose(fractions[2, 4], [0.75 - 0.125 * 0.6875, 0.375 * 0.6875, 0.25 * 0.3125], atol=1e-12)
    assert fractions[0, 0].tolist() == [0.0, 0.0, 0.0] and ids[0, 0].tolist() == [0, 0, 0]
    i1, f1 = ct.top_k(ids, fractions, 1)
    assert i1.shape == (H, W, 1) and np.all(i1[..., 0] == ids[..., 0]) and np.all(f1[..., 0] == fractions[..., 0])
    i5, f5 = ct.top_k(ids, fractions, 5)
    assert i5.shape == (H, W, 5) and np.all(i5[..., 3:] == 0) and np.all(f5[..., 3:] == 0.0)
    with pytest.raises(ValueError, match="at least 1"):
        ct.top_k(ids, fractions, 0)
    empty = _scene(_ortho())
    ids, fractions = ct.exact_coverage(empty, W, H)
    assert ids.shape == (H, W, 1) and not np.any(ids) and not np.any(fractions)
    texture = glphong.Texture(np.array([[255, 0]], np.uint8), 1.0, srgb=False, channel="r")
    lace = MeshData(_rect(-1, 1, -1, 1).positions, _rect(-1, 1, -1, 1).normals, [[0, 1, 2], [0, 2, 3]],
                    uvs=[[0, 0], [1, 0], [1, 1], [0, 1]])
    scene.add(lace, glphong.Lambert(0.5, alpha_mask=glphong.AlphaMask(0.5, texture)), name="lace")
    with pytest.raises(ValueError, match="'lace'.*textured alpha mask"):
        ct.exact_coverage(scene, W, H)


def test_ties_go_to_the_lower_index_and_edge_on_is_skipped():
    scene = _scene(_ortho())
    scene.add(_rect(-1.0, 1.0, -1.0, 1.0), glphong.Lambert(0.5), instance_id=30)
    scene.add(_rect(-1.0, 1.0, -1.0, 1.0), glphong.Lambert(0.5), instance_id=20)  # the same face again
    edge_on = _mesh([[-1.0, 0.3, -1.0], [1.0, 0.3, -1.0], [0.0, 0.3, 1.0]], [[0, 1, 2]])  # in a viewing plane
    scene.add(edge_on, glphong.Lambert(0.5), instance_id=40)
    ids, fractions = ct.exact_coverage(scene, W, H)
    _check_layout(ids, fractions)
    assert set(np.unique(ids)) == {0, 30}
    np.testing.assert_allclose(fractions[..., 0], _rect_fractions(2.0, 6.0, 1.0, 5.0), atol=1e-12)


def test_a_dense_ray_cast_agrees_near_plane_cutting():
    """A 16 x 16 grid of rays per pixel (frame_twin's cast) estimates each object's share: a sphere and a tilted box,
    both cut open by the near plane (their inner faces show), in front of a tilted quad."""
    w, h, n = 24, 18, 16
    camera = glphong.PerspectiveCamera.look_at((0.4, 0.5, 2.5), (0.0, 0.0, 0.0), yfov=0.9, znear=1.9)
    scene = _scene(camera)
    scene.add(primitives.sphere(2, 0.6), glphong.Lambert(0.5), instance_id=1)
    c, s = np.cos(0.8), np.sin(0.8)
    box = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]])
    faces = [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [2, 3, 7], [2, 7, 6], [1, 2, 6],
             [1, 6, 5], [0, 4, 7], [0, 7, 3]]
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = [[c, 0, s], [0, 1, 0], [-s, 0, c]], (0.2, 0.1, 0.1)
    scene.add(_mesh(0.45 * box, faces), glphong.Lambert(0.5), pose=pose, instance_id=2)
    pose = np.eye(4)
    pose[1:3, 1:3], pose[:3, 3] = [[np.cos(-1.2), -np.sin(-1.2)], [np.sin(-1.2), np.cos(-1.2)]], (0.0, -0.3, 0.0)
    scene.add(primitives.plane(3.0), glphong.Lambert(0.5), pose=pose, instance_id=3)
    ids, fractions = ct.exact_coverage(scene, w, h)
    _check_layout(ids, fractions)
    grid = (np.arange(n) + 0.5) / n
    hits = ft.cast_pixels(scene, w, h, offsets=np.stack(np.meshgrid(grid, grid), -1).reshape(-1, 2))
    for index, instance_id in enumerate((1, 2, 3)):
        estimate = (hits.object_index == index).mean(axis=0)
        exact = _share(ids, fractions, instance_id)
        assert np.abs(estimate - exact).max() < 0.06
        assert exact.sum() == pytest.approx(estimate.sum(), rel=3e-3)
