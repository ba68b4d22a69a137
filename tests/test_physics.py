"""Physics invariants of rendered images (docs/design.md section 7, layer 4), on every backend.

Each invariant is checked on the GPU images themselves, independently of
`glphong.verify` (which has its own test at the end): inverse-square falloff,
linearity in the source power, additivity over lights, no light from behind the
surface (diffuse and specular alike, one- and two-sided), view independence of
Lambert.  Figures measured on Mesa llvmpipe (EGL and OSMesa identical) are given
next to each bound.
"""
import numpy as np
import pytest
import trimesh

import glphong
from glphong import reference
from glphong.gpu.contexts import BACKENDS

N = 65  # odd: the centre pixel's ray is the optical axis
F32_EPS = float(np.finfo(np.float32).eps)  # 2^-23

#: centre-pixel ratios E(d)/E(2d) = 4 (measured exact), E(d)/E(3d) = 9 (measured <= 1.35e-7 relative)
FALLOFF_RTOL = 8 * F32_EPS
#: image(7 Phi) = 7 image(Phi) per pixel (measured <= 2.7e-7)
LINEARITY_RTOL = 1e-6
#: render(A + B) = render(A) + render(B) per pixel: one float32 rounding of the sum (measured 5.96e-8 = 2^-24)
ADDITIVITY_RTOL = 4 * F32_EPS
#: Lambert at the same plane point from two cameras, and against the eye-free closed form (measured <= 5.9e-7)
VIEW_RTOL = 2e-6


@pytest.fixture(params=BACKENDS)
def renderer(request, make_renderer):
    """A `glphong.Renderer` on each backend (skipped where unavailable); tests resize it."""
    return make_renderer(N, N, request.param)


def plane_mesh(half=4.0):
    """A planar quad at z = 0 facing +z (counter-clockwise seen from +z); its diagonal misses the origin."""
    vertices = np.array([(-half, -0.9 * half, 0.0), (1.1 * half, -half, 0.0), (0.9 * half, 1.05 * half, 0.0),
                         (-1.05 * half, 0.95 * half, 0.0)])
    mesh = trimesh.Trimesh(vertices, [[0, 1, 2], [0, 2, 3]], process=False)
    assert np.allclose(mesh.face_normals, (0.0, 0.0, 1.0))
    return mesh


def top_camera(x=0.0, y=0.0, height=3.0):
    """Camera at (x, y, height) looking straight down -z, image up = +y."""
    return glphong.PerspectiveCamera.look_at((x, y, height), (x, y, 0.0))


def sphere_on_plane(material, lights, camera=None, ambient=None):
    camera = camera or glphong.PerspectiveCamera.look_at((2.0, -2.5, 2.2), (0.0, 0.0, 0.3))
    scene = glphong.Scene(camera, lights=lights, ambient=ambient)
    scene.add(plane_mesh(), material)
    scene.add(trimesh.creation.icosphere(subdivisions=3), material, pose=trimesh.transformations.translation_matrix((0, 0, 0.8)))
    return scene


def relative_difference(a, b):
    """``|a - b| / max(|a|, |b|)`` in float64, 0 where both are 0."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    scale = np.maximum(np.abs(a), np.abs(b))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(scale > 0, np.abs(a - b) / np.where(scale > 0, scale, 1.0), 0.0)


MATERIALS = {
    "lambert": glphong.Lambert(kd=(0.2, 0.25, 0.3)),
    "phong": glphong.Phong(kd=0.15, ks=(0.5, 0.4, 0.3), q=25.0),
    "blinn": glphong.BlinnPhong(kd=(0.1, 0.15, 0.2), ks=0.45, q=60.0),
}


# --------------------------------------------------------------------------- 1/d^2


@pytest.mark.parametrize("d", [0.7, 1.0, 1.3])
def test_inverse_square_falloff(renderer, d):
    """A point light moved along the plane normal from d to 2d and 3d: the centre pixel falls by 4 and 9."""
    renderer.resize(N, N)
    c = N // 2
    centre = {}
    for k in (1, 2, 3):
        scene = glphong.Scene(top_camera(height=4.0), lights=[glphong.PointLight((0.0, 0.0, k * d), power=(50.0, 80.0, 110.0))])
        scene.add(plane_mesh(), glphong.Lambert(kd=0.3))
        frame = renderer.render(scene)
        assert frame.mask[c, c]
        centre[k] = frame.radiance[c, c].astype(np.float64)
        # the value itself: E1 with cos = 1
        np.testing.assert_allclose(centre[k], 0.3 * np.array([50.0, 80.0, 110.0]) / (4 * np.pi * (k * d) ** 2), rtol=1e-6)
    ratio2, ratio3 = centre[1] / centre[2], centre[1] / centre[3]
    print(f"\n[{renderer.backend}] d={d}: E(d)/E(2d) - 4 = {ratio2 - 4}, E(d)/E(3d) - 9 = {ratio3 - 9}")
    np.testing.assert_allclose(ratio2, 4.0, rtol=FALLOFF_RTOL, atol=0)
    np.testing.assert_allclose(ratio3, 9.0, rtol=FALLOFF_RTOL, atol=0)


def test_unattenuated_light_has_no_falloff(renderer):
    """E2: an UnattenuatedPointLight gives the same centre pixel at every distance along the normal."""
    renderer.resize(N, N)
    c = N // 2
    values = []
    for height in (0.5, 1.0, 2.0, 3.0):
        scene = glphong.Scene(top_camera(height=4.0), lights=[glphong.UnattenuatedPointLight((0.0, 0.0, height), radiance=2.0)])
        scene.add(plane_mesh(), glphong.Lambert(kd=0.3))
        values.append(renderer.render(scene).radiance[c, c].astype(np.float64))
    np.testing.assert_allclose(values, np.full((4, 3), 0.3 * 2.0), rtol=4 * F32_EPS, atol=0)


# --------------------------------------------------------------------------- linearity in Phi


@pytest.mark.parametrize("name", ["lambert", "phong", "blinn"])
def test_linear_in_power(renderer, name):
    renderer.resize(N, N)
    material = MATERIALS[name]
    powers = (np.array([40.0, 55.0, 70.0]), np.array([25.0, 25.0, 25.0]))
    positions = ((1.5, -1.0, 2.5), (-2.0, 0.5, 1.5))
    frames = []
    for scale in (1.0, 7.0):
        lights = [glphong.PointLight(p, power=scale * phi) for p, phi in zip(positions, powers)]
        frames.append(renderer.render(sphere_on_plane(material, lights)))
    base, scaled = frames
    assert np.array_equal(base.mask, scaled.mask) and base.mask.sum() > 0.9 * N * N
    assert (base.radiance[base.mask] > 0).mean() > 0.9  # mostly lit, so the check has something to bite on
    rel = relative_difference(scaled.radiance, 7.0 * base.radiance.astype(np.float64))
    print(f"\n[{renderer.backend}] {name}: max rel |img(7 Phi) - 7 img(Phi)| = {rel.max():.2e}")
    assert rel.max() <= LINEARITY_RTOL


# --------------------------------------------------------------------------- additivity over lights


LIGHT_A = glphong.PointLight((1.5, -1.0, 2.5), power=(60.0, 45.0, 30.0))
LIGHT_B = glphong.PointLight((-2.0, 0.5, 1.5), power=35.0)
LIGHT_C = glphong.DirectionalLight((0.3, 0.8, -1.0), irradiance=(0.6, 0.7, 0.8))
LIGHT_D = glphong.UnattenuatedPointLight((0.5, 2.0, 1.0), radiance=0.9)


@pytest.mark.parametrize("name", ["phong", "blinn", "lambert"])
@pytest.mark.parametrize("pair", [(LIGHT_A, LIGHT_B), (LIGHT_A, LIGHT_C), (LIGHT_B, LIGHT_D)],
                         ids=["point+point", "point+directional", "point+unattenuated"])
def test_additive_over_lights(renderer, name, pair):
    renderer.resize(N, N)
    material = MATERIALS[name]
    both = renderer.render(sphere_on_plane(material, list(pair)))
    first = renderer.render(sphere_on_plane(material, [pair[0]]))
    second = renderer.render(sphere_on_plane(material, [pair[1]]))
    assert np.array_equal(both.mask, first.mask) and np.array_equal(both.mask, second.mask)
    total = first.radiance.astype(np.float64) + second.radiance.astype(np.float64)
    # both lights matter somewhere (otherwise the sum would be trivially right)
    for part in (first, second):
        assert (part.radiance > 0.05 * total.max()).any()
    rel = relative_difference(both.radiance, total)
    print(f"\n[{renderer.backend}] {name} {pair[0].kind}+{pair[1].kind}: max rel |img(A+B) - img(A) - img(B)| = {rel.max():.2e}")
    assert rel.max() <= ADDITIVITY_RTOL


# --------------------------------------------------------------------------- nothing from behind the surface

KA, KD, LA = 0.05, 0.3, 0.2


def _behind_scene(family, two_sided, camera_above, light_above):
    """Plane at z = 0 seen obliquely; a strong point light at grazing incidence on one side.

    The geometry is chosen so that without the ``n.l > 0`` gate the specular lobe of
    a light on the far side would be large (asserted in the test).
    """
    s = 1.0 if camera_above else -1.0
    camera = glphong.PerspectiveCamera.look_at((-3.0, 0.0, 1.5 * s), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), yfov=np.pi / 6)
    light_z = 0.3 if light_above else -0.3
    lights = [glphong.PointLight((4.0, 0.0, light_z), power=2000.0)]
    cls = glphong.Phong if family == "phong" else glphong.BlinnPhong
    material = cls(kd=KD, ks=0.8, q=5.0, ka=KA, two_sided=two_sided)
    scene = glphong.Scene(camera, lights=lights, ambient=glphong.AmbientLight(LA))
    scene.add(plane_mesh(8.0), material)
    return scene


@pytest.mark.parametrize("family", ["phong", "blinn"])
def test_no_light_from_behind_the_surface(renderer, family, record_property):
    """Radiance is exactly the ambient ``k_a + k_d L_a`` wherever the light is behind the shaded normal.

    One-sided: the normal is +z on both faces, so a light below (z < 0) never lights.
    Two-sided (default): a face seen from below is shaded with the normal flipped to -z,
    so the light must be on the camera's side.
    """
    renderer.resize(N, N)
    ambient = np.float32(KA) + np.float32(KD) * np.float32(LA)
    for two_sided in (False, True):
        for camera_above in (True, False):
            for light_above in (True, False):
                scene = _behind_scene(family, two_sided, camera_above, light_above)
                frame = renderer.render(scene)
                assert frame.mask.all()
                lit = (light_above == camera_above) if two_sided else light_above
                label = f"{family} two_sided={two_sided} camera_above={camera_above} light_above={light_above}"
                if lit:
                    assert (frame.radiance > ambient + 0.1).all(axis=-1).mean() > 0.9, label
                    report = glphong.verify(scene, renderer)
                    assert report.passed, f"{label}: {report}"
                    continue
                # exactly the ambient term, in every pixel and channel (no diffuse, no specular leak)
                assert np.all(frame.radiance == ambient), (label, np.abs(frame.radiance - ambient).max())
                # ... although the ungated specular lobe would be large here: the test can see a leak
                gbuffer = renderer.gbuffer(scene)
                n = gbuffer.normal.reshape(-1, 3).astype(np.float64)
                p = gbuffer.position.reshape(-1, 3).astype(np.float64)
                _, wi, _ = reference.safe_normalize(np.asarray(scene.lights[0].position) - p)
                _, wo, _ = reference.safe_normalize(scene.camera.position - p)
                assert np.all(np.sum(n * wi, axis=-1) < 0), label
                if family == "phong" and camera_above != light_above:
                    ungated = reference.phong_lobe(n, wi, wo, 5.0)
                    record_property(f"ungated_phong_lobe_max_{two_sided}_{camera_above}", float(ungated.max()))
                    assert ungated.max() > 0.5, label
                if family == "blinn" and camera_above != light_above:
                    # n.h > 0 although n.l < 0 (the lobe formula alone would light these pixels)
                    h = wi + wo
                    assert (np.sum(n * h, axis=-1) > 0).mean() > 0.5, label


# --------------------------------------------------------------------------- Lambert is view-independent


def test_lambert_is_view_independent(renderer):
    """Two cameras translated by whole pixel footprints see the same plane points from different directions.

    With both cameras looking straight down at height h, pixel (j, i) of the second
    camera, shifted by (k, m) footprints ``2 h tan(fov/2) / N``, sees the world point of
    pixel (j - m, i + k) of the first.  Lambert radiance must agree there; Phong must not
    (the control shows the comparison can see view dependence).
    """
    renderer.resize(N, N)
    h, k, m = 2.0, 20, 12
    footprint = 2.0 * h * np.tan(np.pi / 8) / N
    cameras = (top_camera(0.0, 0.0, h), top_camera(k * footprint, m * footprint, h))
    lights = [glphong.PointLight((0.4, -0.3, 1.2), power=40.0), glphong.DirectionalLight((0.5, 0.2, -1.0), irradiance=0.5)]

    def pair_views(material):
        out = []
        for camera in cameras:
            scene = glphong.Scene(camera, lights=lights)
            scene.add(plane_mesh(), material)
            out.append((renderer.render(scene), renderer.gbuffer(scene)))
        (f1, g1), (f2, g2) = out
        # overlapping pixels: second[j, i] <-> first[j - m, i + k]
        a = (slice(0, N - m), slice(k, N))
        b = (slice(m, N), slice(0, N - k))
        assert f1.mask[a].all() and f2.mask[b].all()
        gap = np.abs(g1.position[a].astype(np.float64) - g2.position[b]).max()
        assert gap < 1e-5, gap  # the same world points
        return f1.radiance[a], f2.radiance[b]

    first, second = pair_views(glphong.Lambert(kd=(0.2, 0.3, 0.4)))
    rel = relative_difference(first, second)
    print(f"\n[{renderer.backend}] Lambert, two views: max rel diff {rel.max():.2e} over {first.shape[0] * first.shape[1]} points")
    assert rel.max() <= VIEW_RTOL
    # control: a Phong highlight moves with the viewer
    first, second = pair_views(glphong.Phong(kd=0.2, ks=0.5, q=10.0))
    assert relative_difference(first, second).max() > 0.05


def test_lambert_matches_view_independent_closed_form_from_oblique_view(renderer):
    """From tilted cameras, each pixel's Lambert radiance is ``k_d (n.l) E`` at its G-buffer point, eye-free."""
    renderer.resize(N, N)
    light = (0.4, -0.3, 1.2)
    kd, power = 0.25, 40.0
    worst = 0.0
    for eye in ((0.0, 0.0, 3.0), (2.5, -1.0, 1.0), (-1.0, 2.5, 0.6)):
        camera = glphong.PerspectiveCamera.look_at(eye, (0.2, 0.1, 0.0), up=(0.0, 0.0, 1.0) if eye[2] < 3 else (0.0, 1.0, 0.0))
        scene = glphong.Scene(camera, lights=[glphong.PointLight(light, power=power)])
        scene.add(plane_mesh(8.0), glphong.Lambert(kd=kd))
        frame = renderer.render(scene)
        gbuffer = renderer.gbuffer(scene)
        m = frame.mask & gbuffer.mask
        assert m.sum() > 0.5 * N * N
        p = gbuffer.position[m].astype(np.float64)
        r = np.asarray(light) - p
        r2 = np.sum(r * r, axis=-1)
        expected = kd * power * (r[:, 2] / np.sqrt(r2)) / (4.0 * np.pi * r2)
        rel = relative_difference(frame.radiance[m], expected[:, None])
        worst = max(worst, float(rel.max()))
    print(f"\n[{renderer.backend}] Lambert from 3 views vs k_d (n.l) E at the G-buffer points: max rel err {worst:.2e}")
    assert worst <= VIEW_RTOL, worst


# --------------------------------------------------------------------------- glphong.verify


def all_kinds_scene(material):
    lights = [
        glphong.PointLight((1.5, -1.0, 2.5), power=(60.0, 45.0, 30.0)),
        glphong.PointLight((-2.0, 0.5, 1.5), power=35.0),
        glphong.UnattenuatedPointLight((0.5, 2.0, 1.0), radiance=0.9),
        glphong.UnattenuatedPointLight((-1.0, -2.0, 0.4), radiance=(0.2, 0.4, 0.3)),
        glphong.DirectionalLight((0.3, 0.8, -1.0), irradiance=(0.6, 0.7, 0.8)),
        glphong.DirectionalLight((-1.0, 0.1, -0.2), irradiance=0.4),
    ]
    return sphere_on_plane(material, lights, ambient=glphong.AmbientLight((0.1, 0.12, 0.15)))


VERIFY_MATERIALS = {
    "lambert": glphong.Lambert(kd=(0.2, 0.25, 0.3), ka=0.01),
    "phong": glphong.Phong(kd=0.15, ks=(0.5, 0.4, 0.3), q=25.0, ka=(0.02, 0.0, 0.01)),
    "blinn": glphong.BlinnPhong(kd=(0.1, 0.15, 0.2), ks=0.45, q=60.0, ka=0.02),
}


@pytest.mark.parametrize("name", list(VERIFY_MATERIALS))
def test_verify_passes_with_every_light_kind(renderer, name, record_property):
    renderer.resize(96, 96)
    report = glphong.verify(all_kinds_scene(VERIFY_MATERIALS[name]), renderer)
    summary = report.summary()
    print(f"\n[{renderer.backend}] verify {name}: {report}")
    record_property(f"verify_{renderer.backend}_{name}", summary)
    assert summary["covered_pixels"] > 0.9 * 96 * 96
    assert summary["nonfinite"] == 0
    assert summary["mask_mismatch"] == 0
    assert summary["outside_band"] == 0
    assert report.passed is True
    assert summary["max_relative_error"] < 1e-5
