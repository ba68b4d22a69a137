"""The 'matte' pass (glphong.gpu.matte): each object's share of each pixel from s x s samples a pixel.

- `count_samples` against a count written here sample by sample (ties, padding, more objects than k);
- `tile_matrix` maps a tile's corners to its clip-space corners;
- a screen-aligned rectangle with fractional borders (orthographic): the GPU's shares are exactly the fraction of the
  s x s cell centres inside the rectangle, computed here by hand, on every tiling (tiles smaller than the image
  included); and within ``1 / (2 s)`` of the exact shares;
- against the exact coverage (glphong.checks.coverage_twin, itself tested against hand areas) on the scenes of
  ``glphong bench --matte`` (glphong.bench.matte.matte_scenes): two overlapping triangles, a sphere's edge,
  interpenetrating meshes, an object partly outside the image and a camera from OpenCV intrinsics off centre: the
  default (s = 32) within 1/64 in every pixel, s = 4, 8, 16 within ``1 / s``;
- `glphong.verify` passes the matte, and fails planted errors (a swapped id, a share off by 2 / s, a lost entry);
- bad input: a textured alpha mask, matte_samples and matte_k out of range; the matte alone gives a frame's mask.
"""
import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.bench.matte import matte_scenes
from glphong.checks.coverage_twin import exact_coverage
from glphong.checks.verify_passes import compare_matte, matte_error, verify_passes
from glphong.gpu.matte import MATTE_SAMPLES, count_samples, matte_tolerance, tile_matrix
from glphong.scene.geometry import MeshData

W, H = 8, 6
YMAG = 1.5  # orthographic: 0.5 m per pixel, xp = 2 x + 4, yp = 3 - 2 y


def _brute_count(samples, s, k):
    h, w = samples.shape[0] // s, samples.shape[1] // s
    values, counts = np.zeros((h, w, k), np.uint32), np.zeros((h, w, k), np.int64)
    for j in range(h):
        for i in range(w):
            block = samples[j * s:(j + 1) * s, i * s:(i + 1) * s].ravel().tolist()
            tally = sorted(((-block.count(v), v) for v in set(block) if v != 0))[:k]
            for r, (n, v) in enumerate(tally):
                values[j, i, r], counts[j, i, r] = v, -n
    return values, counts


@pytest.mark.parametrize("s, k", [(1, 1), (2, 2), (4, 3), (5, 4)])
def test_count_samples_is_a_count(s, k):
    rng = np.random.default_rng(s * 10 + k)
    samples = rng.integers(0, 5, (3 * s, 4 * s)).astype(np.uint32)
    samples[:s, :s] = 3  # a whole pixel
    samples[s:2 * s, :s] = 0  # a background pixel
    values, counts = count_samples(samples, s, k)
    expected = _brute_count(samples, s, k)
    assert np.array_equal(values, expected[0]) and np.array_equal(counts, expected[1])
    assert values[0, 0, 0] == 3 and counts[0, 0, 0] == s * s and not counts[1, 0].any()


def test_tile_matrix_maps_the_tile_to_the_whole_clip_square():
    size, tile = (10, 8), (3, 2, 4, 5)  # columns 3..7, rows 2..7 from the top: GL rows 1..6 from the bottom
    t = tile_matrix(size, tile)
    for x_image, y_image, corner in ((3, 2, (-1, 1)), (7, 7, (1, -1))):
        ndc = np.array([2.0 * x_image / size[0] - 1.0, 1.0 - 2.0 * y_image / size[1], 0.3, 1.0])
        assert np.allclose((t @ (2.0 * ndc))[:2] / 2.0, corner)  # w = 2: the w term is scaled along
    assert np.array_equal(tile_matrix(size, (0, 0, *size)), np.eye(4))


def _ortho_scene():
    pose = np.eye(4)
    pose[2, 3] = 5.0
    return glphong.Scene(glphong.OrthographicCamera(YMAG, pose=pose), [glphong.PointLight((0.0, 0.0, 3.0), 10.0)])


def _rect(x0, x1, y0, y1, z=0.0):
    points = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], np.float32)
    return MeshData(points, np.tile([0.0, 0.0, 1.0], (4, 1)), np.array([[0, 1, 2], [0, 2, 3]], np.uint32))


def _cells_inside(lo, hi, n, s):
    """(n,) share of each pixel's s cell centres, pixel p's at p + (c + 1/2) / s, inside [lo, hi] (no centre on a
    border)."""
    centres = np.arange(n)[:, None] + (np.arange(s)[None, :] + 0.5) / s
    return np.mean((centres > lo) & (centres < hi), axis=1)


@pytest.mark.parametrize("s, tile", [(32, None), (4, None), (4, 12), (3, 7)])
def test_rectangle_shares_are_the_cell_centres_inside(glphong_backend, glphong_make_renderer, s, tile):
    scene = _ortho_scene()
    # image x = 2 x + 4, y = 3 - 2 y: the rectangle covers x in [1.3, 6.55], y in [0.6, 4.2]
    scene.add(_rect(-1.35, 1.275, -0.6, 1.2), glphong.Lambert(0.5), instance_id=9)
    renderer = glphong_make_renderer(W, H, glphong_backend, matte_samples=s)
    if tile is not None:
        renderer._matte.tile = tile  # tiles of 4 and 2 pixels a side: partial tiles on both axes
    frame = renderer.render(scene, passes=("matte",))
    expected = _cells_inside(0.6, 4.2, H, s)[:, None] * _cells_inside(1.3, 6.55, W, s)[None, :]
    assert np.array_equal(frame.matte_fractions[..., 0], expected.astype(np.float32))
    assert np.array_equal(frame.matte_ids[..., 0], np.where(expected > 0, 9, 0))
    assert not frame.matte_ids[..., 1:].any() and not frame.matte_fractions[..., 1:].any()
    assert np.array_equal(frame.mask, expected > 0)
    exact = _cells_inside(0.6, 4.2, H, 4096)[:, None] * _cells_inside(1.3, 6.55, W, 4096)[None, :]
    assert np.abs(frame.matte_fractions[..., 0] - exact).max() <= 1.0 / s  # a corner: two edges of 1 / (2 s)


SCENES = matte_scenes()  # the row family of ``glphong bench --matte``


@pytest.mark.parametrize("name", SCENES)
def test_against_the_exact_coverage(glphong_backend, glphong_make_renderer, name):
    scene, (width, height) = SCENES[name]
    exact_ids, exact_fractions = exact_coverage(scene, width, height)
    assert (exact_fractions > 0).sum(axis=-1).max() >= (1 if "edge" in name or "outside" in name else 2)
    worst = {}
    for s in (4, 8, 16, MATTE_SAMPLES):
        frame = glphong_make_renderer(width, height, glphong_backend, matte_samples=s).render(
            scene, passes=("matte",))
        error = matte_error(frame.matte_ids, frame.matte_fractions, exact_ids, exact_fractions)
        worst[s] = error.max()
        assert worst[s] <= matte_tolerance(s), (s, worst[s])
        total = frame.matte_fractions.astype(np.float64).sum(axis=-1)
        assert np.all(total <= 1.0) and np.abs(total - exact_fractions.sum(axis=-1)).max() <= 2.0 / s
    assert worst[MATTE_SAMPLES] <= 1.0 / 64, worst


def test_verify_passes_the_matte_and_fails_planted_errors(glphong_make_renderer):
    scene, (width, height) = SCENES["interpenetrating meshes"]
    renderer = glphong_make_renderer(width, height, "egl", matte_samples=8)
    report = glphong.verify(scene, renderer, passes=("matte",))
    assert report.passed and report.passes["matte"].passed
    assert 0 < report.passes["matte"].max_error <= 1.0 / 8
    frame = renderer.render(scene, passes=("matte",))
    ids, fractions = frame.matte_ids.copy(), frame.matte_fractions.copy()
    mixed = np.argwhere((fractions[..., 0] - fractions[..., 1] > 0.4) & (fractions[..., 1] > 0.2))[0]
    swapped = ids.copy()
    swapped[tuple(mixed)] = swapped[tuple(mixed)][[1, 0, 2, 3]]
    assert not compare_matte(scene, swapped, fractions, 8).passed
    off = fractions.copy()
    whole = np.argwhere(fractions[..., 0] == 1.0)[0]
    off[tuple(whole) + (0,)] = 1.0 - 2.0 / 8
    assert compare_matte(scene, ids, off, 8).outside_count == 1
    lost = ids.copy(), fractions.copy()
    lost[0][tuple(mixed) + (1,)] = 0
    lost[1][tuple(mixed) + (1,)] = 0
    assert not compare_matte(scene, *lost, 8).passed


def test_errors_and_a_matte_alone(glphong_make_renderer):
    for bad in (0, 65, 2.5):
        with pytest.raises((ValueError, TypeError), match="matte_samples"):
            glphong.Renderer(4, 4, matte_samples=bad)
    with pytest.raises((ValueError, TypeError), match="matte_k"):
        glphong.Renderer(4, 4, matte_k=17)
    scene, size = matte_scenes()["a sphere's edge"]  # its own: a textured object is added below
    renderer = glphong_make_renderer(*size, "egl", matte_k=2)
    frame = renderer.render(scene, passes=("matte", "instance"))
    assert frame.matte_ids.shape == size[::-1] + (2,) and frame.passes == ("instance", "matte")
    assert np.array_equal(frame.instance != 0, frame.mask)  # the mask of the G-buffer's centre sample
    alone = renderer.render(scene, passes=("matte",))
    assert np.array_equal(alone.mask, alone.matte_fractions[..., 0] > 0) and alone.radiance is None
    assert np.array_equal(alone.matte_fractions, frame.matte_fractions)
    texture = glphong.Texture(np.array([[255, 0]], np.uint8), 1.0, srgb=False, channel="r")
    rect = _rect(-1, 1, -1, 1)
    lace = MeshData(rect.positions, rect.normals, [[0, 1, 2], [0, 2, 3]], uvs=[[0, 0], [1, 0], [1, 1], [0, 1]])
    scene.add(lace, glphong.Lambert(0.5, alpha_mask=glphong.AlphaMask(0.5, texture)), name="lace")
    with pytest.raises(ValueError, match="'matte' pass .* object 'lace' has one"):
        renderer.render(scene, passes=("matte",))


def test_silhouettes_are_the_instance_pass_of_each_object_alone(glphong_backend, glphong_make_renderer):
    """Renderer.silhouettes (one small draw per object, the matte program) gives, pixel for pixel, what the instance
    pass of each object rendered alone covers, itself checked against the float64 ray cast (`verify_passes`): a closed mesh (back faces culled), a mirrored pose, a flat plane seen
    from behind, an object cut by the near plane, an object hidden by its constant alpha; a textured alpha mask is
    refused by name."""
    camera = glphong.PerspectiveCamera.look_at((0.3, 0.2, 2.5), (0.0, 0.0, 0.0), yfov=0.9, znear=0.5)
    scene = glphong.Scene(camera, [glphong.PointLight((2.0, 2.0, 3.0), 50.0)])
    sphere = primitives.sphere(2, 0.5)
    mirrored = np.diag([-1.0, 1.0, 1.0, 1.0])
    mirrored[:3, 3] = (0.6, 0.1, 0.0)
    behind = np.eye(4)
    behind[:3, 3] = (-0.4, -0.3, -0.8)
    near = np.eye(4)
    near[:3, 3] = (0.1, 0.0, 1.9)  # its front reaches the near plane (2.5 - 0.5 from the eye)
    scene.add(sphere, glphong.Lambert(0.5), instance_id=3)
    scene.add(sphere, glphong.Lambert(0.5), pose=mirrored, instance_id=5)
    scene.add(primitives.plane(0.8), glphong.Lambert(0.5), pose=behind @ np.diag([1.0, 1.0, -1.0, 1.0]), instance_id=6)
    scene.add(sphere, glphong.Lambert(0.5), pose=near, instance_id=8)
    scene.add(sphere, glphong.Lambert(0.5, alpha_mask=glphong.AlphaMask(0.5, 0.2)), instance_id=9)
    renderer = glphong_make_renderer(40, 30, glphong_backend)
    masks = renderer.silhouettes(scene)
    for obj, mask in zip(scene.objects, masks):
        alone = glphong.Scene(camera, scene.lights)
        alone.add(obj.mesh, obj.material, pose=obj.pose, instance_id=obj.instance_id)
        frame = renderer.render(alone, passes=("instance",))
        assert verify_passes(alone, frame, ("instance",))["instance"].passed  # that pass against the float64 ray cast
        assert np.array_equal(mask, frame.instance == obj.instance_id), obj.instance_id
    assert all(m.any() for m in masks[:4]) and not masks[4].any()
    assert [m.sum() for m in renderer.silhouettes(scene, [1, 0])] == [masks[1].sum(), masks[0].sum()]
    texture = glphong.Texture(np.array([[255, 0]], np.uint8), 1.0, srgb=False, channel="r")
    rect = _rect(-1, 1, -1, 1)
    lace = MeshData(rect.positions, rect.normals, [[0, 1, 2], [0, 2, 3]], uvs=[[0, 0], [1, 0], [1, 1], [0, 1]])
    scene.add(lace, glphong.Lambert(0.5, alpha_mask=glphong.AlphaMask(0.5, texture)), name="lace", instance_id=11)
    with pytest.raises(ValueError, match="object 'lace' has one"):
        renderer.silhouettes(scene)
