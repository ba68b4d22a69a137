"""Every public parameter against a closed form written here, from the constructor's arguments.

The other test modules take their expected values from ``scene.uniform_values()`` (the float32 numbers
the GPU is given), through the numpy twin, the tolerance band or the stability oracle.  A value that is
wrong on its way from a constructor argument to a shader uniform (``u_ks`` uploaded 1% too large, a
directional light's direction negated, ``yfov`` halved before the projection matrix) is then wrong on
both sides of the comparison and invisible.  These tests read no uniform, and use none of
glphong.reference, glphong.checks.tolerances, glphong.checks.stability, glphong.verify, glphong.imaging,
glphong.radiometry, ``uniform_row()``, ``light_uniform_values`` or the camera's ray and matrix methods:
every expected value is a closed form of the arguments the test passed (pinhole rays, ray-plane and
ray-triangle hits, E = Phi / (4 pi d^2), the Phong and Blinn lobes, the sRGB curve), evaluated in float64.
Every closed-form comparison also checks that the same closed form with the parameter perturbed (1% for
numbers, the other value for booleans) is *not* matched, so each test can fail.

parameter                                   -> test(s)
------------------------------------------------------------------------------------------------------
Lambert(kd)                                 -> test_lambert_kd_directional_direction_irradiance,
                                               test_point_light_position_power
Lambert(ka=), AmbientLight(radiance)        -> test_ka_ambient_light_radiance[Lambert]
Lambert(two_sided=)                         -> test_two_sided[Lambert]
Phong(kd, ks, q)                            -> test_phong_blinn_kd_ks_q_directional_straight_down[phong],
                                               test_phong_blinn_q_zero[phong]
Phong(...) with an oblique DirectionalLight -> test_phong_directional_direction_oblique
Phong(ka=), Phong(two_sided=)               -> test_ka_ambient_light_radiance[Phong], test_two_sided[Phong]
BlinnPhong(kd, ks, q)                       -> test_phong_blinn_kd_ks_q_directional_straight_down[blinn],
                                               test_phong_blinn_q_zero[blinn]
BlinnPhong(ka=), BlinnPhong(two_sided=)     -> test_ka_ambient_light_radiance[BlinnPhong],
                                               test_two_sided[BlinnPhong]
PointLight(position, power)                 -> test_point_light_position_power
UnattenuatedPointLight(position, radiance)  -> test_unattenuated_point_light_position_radiance
DirectionalLight(direction, irradiance)     -> test_lambert_kd_directional_direction_irradiance,
                                               test_phong_directional_direction_oblique
AmbientLight(radiance)                      -> test_ka_ambient_light_radiance,
                                               test_ka_ambient_light_with_directional_light
PerspectiveCamera(yfov)                     -> test_camera_yfov_mask_rows_and_columns,
                                               test_camera_yfov_pose_lit_plane
PerspectiveCamera(pose)                     -> test_camera_yfov_pose_lit_plane, test_camera_pose_markers
PerspectiveCamera(znear, zfar)              -> test_camera_znear_zfar[PerspectiveCamera]
PerspectiveCamera.look_at(eye, target, up,  -> test_look_at_eye_target_up_yfov_lit_plane,
    yfov)                                      test_look_at_markers_up_flips_image
PerspectiveCamera.look_at(znear, zfar)      -> test_camera_znear_zfar[look_at]
Scene.add(mesh, material)                   -> every test (each draws its meshes through Scene.add)
Scene.add(pose=)                            -> test_scene_add_pose_translation_rotation,
                                               test_scene_add_pose_shear_normal
Scene.add(smooth=)                          -> test_scene_add_smooth_and_flat_normals
Renderer.render_srgb8(scene, exposure)      -> test_render_srgb8_exposure
Frame.to_srgb8(exposure)                    -> test_frame_to_srgb8_exposure

Scenes: a quad at z = 0 facing +z seen from straight above (odd image sizes, so the centre pixel's
ray is the optical axis), oblique cameras over the same quad, a square pyramid for smooth vs flat
normals, and small camera-facing marker squares for the camera pose.  On a planar mesh the rasteriser's
perspective-correct interpolation at a pixel centre is the exact ray-plane hit, so the closed forms are
exact and only float32 rounding separates them from the GPU (measured below, per assertion).
Measured on Mesa llvmpipe; EGL and OSMesa gave the same errors.

Checked by mutation (monkeypatching a wiring error into the library, outside this module): multiplying
any of u_kd, u_ks, u_q, u_ka, u_ambient, a light's irradiance, power, radiance or position component,
u_eye, u_model's translation, the projection's yfov, aspect, znear or zfar, look_at's up or target, or
the exposure by 1.01 or 0.99 fails at least one test here; so does 1.001 for all of them, and 0.999 for
all but the exposure (8-bit output cannot resolve every 0.1% decrease).  So do swapping the Blinn and
Phong lobes, normals transformed by the pose instead of its inverse transpose, ignoring two_sided=False
or smooth=False, and q = 0 uploaded as 0.01.
"""
import numpy as np
import pytest
import trimesh

import glphong
from glphong.gpu.contexts import BACKENDS

#: image size of most tests: odd, so the centre pixel's ray is the optical axis
N = 33
#: the distinct-channel coefficients used throughout (a channel swap fails)
KD = (0.1, 0.2, 0.3)
#: the perturbation every closed form must be able to detect
PERTURB = 1.01


@pytest.fixture(scope="module", params=BACKENDS)
def renderer(request, module_make_renderer):
    """One `glphong.Renderer` per backend for the whole module; tests resize it."""
    return module_make_renderer(N, N, request.param)


# --------------------------------------------------------------------------- closed forms


def rotation(axis, angle):
    """Rodrigues: rotation by ``angle`` [rad] about ``axis``, (3, 3) float64."""
    k = np.asarray(axis, float)
    k = k / np.linalg.norm(k)
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * kx + (1.0 - np.cos(angle)) * kx @ kx


def rigid(r, t):
    """4x4 rigid transform from a rotation ``r`` and translation ``t``."""
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = r, t
    return m


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def look_at_rotation(eye, target, up):
    """Camera-to-world rotation of a camera at ``eye`` looking at ``target``: columns (x, y, z), z = backwards."""
    z = unit(np.subtract(eye, target))
    x = unit(np.cross(up, z))
    return np.stack([x, np.cross(z, x), z], axis=1)


def pinhole_rays(yfov, width, height, r):
    """Unit world ray directions through the pixel centres, (H, W, 3): row 0 at the top, camera looks down -Z."""
    t = np.tan(yfov / 2.0)
    i = np.arange(width)
    j = np.arange(height)
    x = ((i + 0.5) / width * 2.0 - 1.0) * t * (width / height)
    y = (1.0 - (j + 0.5) / height * 2.0) * t
    d = np.stack(np.broadcast_arrays(x[None, :], y[:, None], -1.0), axis=-1)
    return unit(d @ np.asarray(r, float).T)


def project(point, yfov, width, height, r, eye):
    """Continuous pixel coordinates ``(i, j)`` (column, row; pixel centres at integers) of a world point."""
    p = np.asarray(r, float).T @ (np.asarray(point, float) - eye)
    t = np.tan(yfov / 2.0)
    ndc_x = p[0] / -p[2] / (t * width / height)
    ndc_y = p[1] / -p[2] / t
    return (ndc_x + 1.0) / 2.0 * width - 0.5, (1.0 - ndc_y) / 2.0 * height - 0.5


def plane_hit(origin, dirs, p0, n):
    """Ray-plane hits ``origin + t dirs`` with the plane through ``p0`` of normal ``n``: (points, t)."""
    t = ((np.asarray(p0, float) - origin) @ n) / (dirs @ n)
    return origin + t[..., None] * dirs, t


def phong_lobe(n, l, v, q):
    """max(v.r, 0)^q, r = 2 (n.l) n - l, (q = 0 gives 1)."""
    r = 2.0 * np.sum(n * l, axis=-1, keepdims=True) * n - l
    c = np.maximum(np.sum(v * r, axis=-1), 0.0)
    return np.ones_like(c) if q == 0 else c ** q


def blinn_lobe(n, l, v, q):
    """max(n.h, 0)^q, h = (l + v)/|l + v|, (q = 0 gives 1)."""
    c = np.maximum(np.sum(n * unit(l + v), axis=-1), 0.0)
    return np.ones_like(c) if q == 0 else c ** q


def srgb(x):
    """The exact piecewise sRGB curve on [0, 1]."""
    x = np.clip(np.asarray(x, float), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1.0 / 2.4) - 0.055)


def rel_error(got, expected):
    """max |got - expected| / |expected| over all entries (expected > 0)."""
    got, expected = np.broadcast_arrays(np.asarray(got, float), np.asarray(expected, float))
    with np.errstate(divide="ignore", invalid="ignore"):  # expected 0 (an alternative that is unlit): inf
        return float(np.max(np.where(got == expected, 0.0, np.abs(got - expected) / np.abs(expected))))


def assert_matches_only(got, expected_fn, param, rtol, perturbed=None, margin=10.0):
    """``got`` matches ``expected_fn(param)`` to ``rtol`` and does not match ``expected_fn(p)`` for each
    ``p`` in ``perturbed`` (default ``[1.01 * param]``): there the error must exceed ``margin * rtol``.

    Returns the measured relative error against ``expected_fn(param)``.
    """
    err = rel_error(got, expected_fn(param))
    assert err <= rtol, f"relative error {err:.3e} > rtol {rtol:.1e} (param {param!r})"
    if perturbed is None:
        perturbed = [PERTURB * np.asarray(param, float)]
    for p in perturbed:
        other = rel_error(got, expected_fn(p))
        assert other > margin * rtol, (f"the closed form with the perturbed parameter {p!r} also matches "
                                       f"(error {other:.3e} <= {margin} x rtol {rtol:.1e}): the test cannot fail")
    return err


#: half-width of the lit plane: larger than every view below (their hits stay within 3.3 m of the
#: origin), and no larger, since float32 interpolation error grows with the triangle's size
PLANE_HALF = 4.0


def plane_mesh(half=PLANE_HALF, z=0.0, facing=+1):
    """A quad of about ``half`` half-width at height ``z``, front face and normals toward ``facing`` * z;
    slightly irregular, so that its diagonal misses the origin (the centre pixel)."""
    v = np.array([(-half, -0.9 * half, z), (1.1 * half, -half, z), (0.95 * half, 1.05 * half, z), (-1.05 * half, half, z)])
    faces = [[0, 1, 2], [0, 2, 3]] if facing > 0 else [[0, 2, 1], [0, 3, 2]]
    mesh = trimesh.Trimesh(v, faces, process=False)
    assert np.allclose(mesh.face_normals, (0.0, 0.0, facing))
    return mesh


def top_camera(height=2.0, yfov=2.0 * np.arctan(0.6), **kw):
    """A camera at (0, 0, height) looking straight down (identity rotation), built from a pose."""
    return glphong.PerspectiveCamera(yfov, pose=rigid(np.eye(3), (0.0, 0.0, height)), **kw)


def top_view(height=2.0, yfov=2.0 * np.arctan(0.6), width=N, rows=N):
    """Closed-form geometry of `top_camera` over the plane z = 0: (eye, view vectors v, hit points)."""
    eye = np.array([0.0, 0.0, height])
    d = pinhole_rays(yfov, width, rows, np.eye(3))
    hit, _ = plane_hit(eye, d, (0.0, 0.0, 0.0), np.array([0.0, 0.0, 1.0]))
    return eye, -d, hit


def render(renderer, scene, size=(N, N)):
    renderer.resize(*size)
    frame = renderer.render(scene)
    return frame, frame.radiance.astype(np.float64)


Z = np.array([0.0, 0.0, 1.0])


# --------------------------------------------------------------------------- Lambert, DirectionalLight


def test_lambert_kd_directional_direction_irradiance(renderer):
    """Lambert plane under an oblique directional light: ``kd E cos(theta)`` at every pixel."""
    direction = (0.6, -0.8, -1.0)      # travel direction: theta = 45 degrees from the normal
    irradiance = (2.0, 3.0, 5.0)
    scene = glphong.Scene(top_camera(), lights=[glphong.DirectionalLight(direction, irradiance)])
    scene.add(plane_mesh(), glphong.Lambert(KD))
    frame, got = render(renderer, scene)
    assert frame.mask.all()

    def expected(kd=KD, e=irradiance, dirn=direction):
        cos = max(-unit(dirn)[2], 0.0)
        return np.broadcast_to(np.multiply(kd, e) * cos, got.shape)

    # measured 4.6e-8 (a uniform image: kd, E, cos each rounded to float32); rtol 1e-6 is float32 with margin
    err = assert_matches_only(got, lambda kd: expected(kd=kd), KD, 1e-6)
    assert_matches_only(got, lambda e: expected(e=e), irradiance, 1e-6)
    # direction: 1% on its z component changes cos by 0.5%; the toward-light reading (negated) gives 0
    assert_matches_only(got, lambda d: expected(dirn=d), direction, 1e-6,
                        perturbed=[(0.6, -0.8, -1.01), (0.606, -0.8, -1.0), (-0.6, 0.8, 1.0)])
    print(f"\n[{renderer.backend}] lambert directional: rel err {err:.2e}")


# --------------------------------------------------------------------------- Phong / Blinn lobes

PHONG_KD = (0.01, 0.02, 0.03)   # small kd: the lobe dominates, so q is well resolved
PHONG_KS = (0.5, 0.4, 0.3)
LIGHT_E = (2.0, 3.0, 4.0)


def lobe_scene(material, direction=(0.0, 0.0, -1.0), camera=None):
    scene = glphong.Scene(camera or top_camera(), lights=[glphong.DirectionalLight(direction, LIGHT_E)])
    scene.add(plane_mesh(), material)
    return scene


def glossy_closed_form(lobe, kd, ks, q, l, v, e=LIGHT_E):
    """``(kd (n.l) + ks lobe) E`` on the plane z = 0 (n = +z), (H, W, 3)."""
    cos = float(l @ Z)
    return (np.multiply.outer(np.ones(v.shape[:2]), np.multiply(kd, e)) * cos
            + np.multiply.outer(lobe(Z, l, v, q), np.multiply(ks, e)))


@pytest.mark.parametrize("family, q", [("phong", 20.0), ("blinn", 60.0)])
def test_phong_blinn_kd_ks_q_directional_straight_down(renderer, family, q):
    """Light straight down, camera straight above: the centre pixel is the mirror direction, exactly
    ``kd E + ks E``; every pixel is ``kd E + ks E lobe(v)`` with v = -(pixel ray)."""
    cls, lobe = (glphong.Phong, phong_lobe) if family == "phong" else (glphong.BlinnPhong, blinn_lobe)
    frame, got = render(renderer, lobe_scene(cls(PHONG_KD, PHONG_KS, q)))
    assert frame.mask.all()
    _, v, _ = top_view()
    l = Z
    c = N // 2
    centre = np.multiply(PHONG_KD, LIGHT_E) + np.multiply(PHONG_KS, LIGHT_E)
    # measured 7e-8 at the centre (lobe = 1 up to the float32 interpolated position); rtol 1e-6
    assert rel_error(got[c, c], centre) <= 1e-6
    assert rel_error(got[c, c], centre * 1.001) > 1e-4
    fn = lambda kd=PHONG_KD, ks=PHONG_KS, qq=q: glossy_closed_form(lobe, kd, ks, qq, l, v)  # noqa: E731
    # whole image, measured 1.16e-6 (Phong q=20) and 1.13e-6 (Blinn q=60): the float32 view vector from the
    # interpolated position enters the lobe with weight ~ q tan(theta); rtol 5e-6 is 4x that, and 200x below
    # the smallest effect of 1% on q checked below
    rtol = 5e-6
    err = assert_matches_only(got, lambda kd: fn(kd=kd), PHONG_KD, rtol)
    assert_matches_only(got, lambda ks: fn(ks=ks), PHONG_KS, rtol)
    assert_matches_only(got, lambda qq: fn(qq=float(qq)), q, rtol)
    # q is resolved where the lobe is between 0.05 and 0.9: there 1% on q changes every pixel by >= 9e-4
    lobe_values = lobe(Z, l, v, q)
    band = (lobe_values > 0.05) & (lobe_values < 0.9)
    assert band.sum() >= 100, band.sum()
    shift = np.abs(fn(qq=PERTURB * q)[band] / fn()[band] - 1.0)
    assert shift.min() > 50 * rtol, shift.min()
    assert rel_error(got[band], fn()[band]) <= rtol
    print(f"\n[{renderer.backend}] {family} q={q}: rel err {err:.2e}, {band.sum()} band pixels, "
          f"1% q shifts them by >= {shift.min():.1e}")


@pytest.mark.parametrize("family", ["phong", "blinn"])
def test_phong_blinn_q_zero(renderer, family):
    """q = 0: the lobe is 1 wherever the light is lit, ``(kd cos + ks) E`` (0^0 := 1)."""
    cls = glphong.Phong if family == "phong" else glphong.BlinnPhong
    direction = (0.3, -0.2, -1.0)
    frame, got = render(renderer, lobe_scene(cls(PHONG_KD, PHONG_KS, 0.0), direction=direction))
    assert frame.mask.all()
    _, v, _ = top_view()
    l = unit(np.negative(direction))
    lobe = phong_lobe if family == "phong" else blinn_lobe
    fn = lambda qq, ks=PHONG_KS: glossy_closed_form(lobe, PHONG_KD, ks, qq, l, v)  # noqa: E731
    # measured 7e-8 (uniform image: float32 products); rtol 1e-6.  q = 0.05 instead of 0 changes the image
    # by >= 1e-3 (the lobe would be cos^0.05 instead of 1)
    err = assert_matches_only(got, fn, 0.0, 1e-6, perturbed=[0.05])
    assert_matches_only(got, lambda ks: fn(0.0, ks), PHONG_KS, 1e-6)
    print(f"\n[{renderer.backend}] {family} q=0: rel err {err:.2e}")


def test_phong_directional_direction_oblique(renderer):
    """An oblique directional light moves the Phong highlight to the pixel whose v is the mirror of l;
    the whole image is ``(kd cos + ks (v.r)^q) E`` with r = 2 (n.l) n - l, l = -direction."""
    direction, q = (-0.3, 0.2, -1.0), 20.0
    frame, got = render(renderer, lobe_scene(glphong.Phong(PHONG_KD, PHONG_KS, q), direction=direction))
    assert frame.mask.all()
    _, v, _ = top_view()
    fn = lambda d: glossy_closed_form(phong_lobe, PHONG_KD, PHONG_KS, q, unit(np.negative(d)), v)  # noqa: E731
    # measured 1.06e-6, rtol 5e-6 (as the straight-down test); 1% on a component of the direction
    # moves the highlight and changes pixels by > 1e-3
    err = assert_matches_only(got, fn, direction, 5e-6,
                              perturbed=[(-0.303, 0.2, -1.0), (-0.3, 0.202, -1.0), (-0.3, 0.2, -1.01)])
    # the highlight peak is in the image, at the pixel whose ray is the reflection of the light's travel
    peak = np.unravel_index(np.argmax(got[..., 0]), got.shape[:2])
    expected_peak = np.unravel_index(np.argmax(fn(direction)[..., 0]), got.shape[:2])
    assert peak == expected_peak and 0 < peak[0] < N - 1 and 0 < peak[1] < N - 1
    print(f"\n[{renderer.backend}] phong oblique directional: rel err {err:.2e}, peak at {peak}")


# --------------------------------------------------------------------------- point lights


def positional_lambert(hit, position, value, kd, falloff):
    """Lambert plane (normal +z) under a light at ``position``: ``kd value cos / (4 pi d^2)`` with the
    falloff (a `PointLight`, ``value`` = Phi), ``kd value cos`` without (``value`` = L_i), (H, W, 3)."""
    r = np.asarray(position, float) - hit
    d = np.linalg.norm(r, axis=-1)
    scale = r[..., 2] / d / (4.0 * np.pi * d * d if falloff else 1.0)
    return np.multiply.outer(scale, np.multiply(kd, value))


def test_point_light_position_power(renderer):
    """Lambert plane under a point light: ``kd Phi / (4 pi d^2) * (h / d)`` at each ray-plane hit."""
    position, power = (0.4, -0.3, 1.2), (30.0, 60.0, 90.0)
    scene = glphong.Scene(top_camera(), lights=[glphong.PointLight(position, power)])
    scene.add(plane_mesh(), glphong.Lambert(KD))
    frame, got = render(renderer, scene)
    assert frame.mask.all()
    _, _, hit = top_view()

    def expected(pos=position, phi=power, kd=KD):
        return positional_lambert(hit, pos, phi, kd, falloff=True)

    # measured 6.9e-7 (float32 interpolated position through 1/d^2 and the cosine); rtol 2e-6
    rtol = 2e-6
    err = assert_matches_only(got, lambda phi: expected(phi=phi), power, rtol)
    assert_matches_only(got, lambda kd: expected(kd=kd), KD, rtol)
    # each position component by 1%, and the whole position by 1%
    x, y, z = position
    assert_matches_only(got, lambda p: expected(pos=p), position, rtol,
                        perturbed=[(1.01 * x, y, z), (x, 1.01 * y, z), (x, y, 1.01 * z), tuple(1.01 * np.array(position))])
    print(f"\n[{renderer.backend}] point light: rel err {err:.2e}")


def test_unattenuated_point_light_position_radiance(renderer):
    """Lambert plane under an unattenuated point light: ``kd L_i (h / d)``, no distance falloff."""
    position, radiance = (0.4, -0.3, 1.2), (1.5, 2.5, 3.5)
    scene = glphong.Scene(top_camera(), lights=[glphong.UnattenuatedPointLight(position, radiance)])
    scene.add(plane_mesh(), glphong.Lambert(KD))
    frame, got = render(renderer, scene)
    assert frame.mask.all()
    _, _, hit = top_view()

    def expected(pos=position, li=radiance, falloff=False):
        return positional_lambert(hit, pos, li, KD, falloff)

    # measured 2.6e-7 (the cosine from the float32 position); rtol 1e-6
    rtol = 1e-6
    err = assert_matches_only(got, lambda li: expected(li=li), radiance, rtol)
    x, y, z = position
    assert_matches_only(got, lambda p: expected(pos=p), position, rtol,
                        perturbed=[(1.01 * x, y, z), (x, 1.01 * y, z), (x, y, 1.01 * z)])
    # no falloff: the E1 reading of the same value is not matched
    assert rel_error(got, expected(falloff=True)) > 0.5
    print(f"\n[{renderer.backend}] unattenuated point light: rel err {err:.2e}")


# --------------------------------------------------------------------------- ka, AmbientLight, two_sided

KA = (0.01, 0.02, 0.03)
LA = (0.5, 0.25, 0.125)
MATERIALS = {
    "Lambert": lambda **kw: glphong.Lambert(KD, **kw),
    "Phong": lambda **kw: glphong.Phong(KD, PHONG_KS, 20.0, **kw),
    "BlinnPhong": lambda **kw: glphong.BlinnPhong(KD, PHONG_KS, 60.0, **kw),
}


@pytest.mark.parametrize("name", list(MATERIALS))
def test_ka_ambient_light_radiance(renderer, name):
    """A plane lit only from behind (n.l < 0, diffuse and specular gated off): exactly ``ka + kd L_a``."""
    camera = top_camera()
    behind = glphong.DirectionalLight((0.2, 0.1, 1.0), LIGHT_E)  # travels upward: reaches only the back
    cases = [(KA, None), ((0.0, 0.0, 0.0), LA), (KA, LA)]
    for ka, la in cases:
        scene = glphong.Scene(camera, lights=[behind], ambient=None if la is None else glphong.AmbientLight(la))
        scene.add(plane_mesh(), MATERIALS[name](ka=ka))
        frame, got = render(renderer, scene)
        assert frame.mask.all()
        la0 = (0.0, 0.0, 0.0) if la is None else la

        def expected(k=ka, a=la0, kd=KD):
            return np.broadcast_to(np.add(k, np.multiply(kd, a)), got.shape)

        # measured 2e-8 to 4e-8 (float32 rounding of ka, kd, L_a, one product and sum); rtol 1e-6
        if any(ka):
            assert_matches_only(got, lambda k: expected(k=k), ka, 1e-6)
        if la is not None:
            assert_matches_only(got, lambda a: expected(a=a), la, 1e-6)
            assert_matches_only(got, lambda kd: expected(kd=kd), KD, 1e-6)


def test_ka_ambient_light_with_directional_light(renderer):
    """Ambient terms add to the lit term: ``ka + kd L_a + kd E cos``."""
    direction = (0.6, -0.8, -1.0)
    scene = glphong.Scene(top_camera(), lights=[glphong.DirectionalLight(direction, LIGHT_E)],
                          ambient=glphong.AmbientLight(LA))
    scene.add(plane_mesh(), glphong.Lambert(KD, ka=KA))
    frame, got = render(renderer, scene)
    cos = -unit(direction)[2]
    fn = lambda ka=KA, la=LA: np.broadcast_to(np.add(ka, np.multiply(KD, la)) + np.multiply(KD, LIGHT_E) * cos,  # noqa: E731
                                              got.shape)
    # measured 4.4e-8; rtol 1e-6
    assert_matches_only(got, lambda ka: fn(ka=ka), KA, 1e-6)
    assert_matches_only(got, lambda la: fn(la=la), LA, 1e-6)


@pytest.mark.parametrize("name", list(MATERIALS))
def test_two_sided(renderer, name):
    """A quad whose front face and normals point away from the camera, light and camera above it.

    two_sided=True: the back face is shaded with the normal flipped, as the front-facing plane would be
    (``ka + kd L_a + (kd + ks lobe) E``).  two_sided=False: the normal stays -z, n.l < 0, so the light
    adds nothing: exactly ``ka + kd L_a``, and the face is drawn, not culled (mask all True).
    """
    camera = top_camera()
    _, v, _ = top_view()
    lobe, q, ks = {"Lambert": (None, 0.0, (0.0, 0.0, 0.0)), "Phong": (phong_lobe, 20.0, PHONG_KS),
                   "BlinnPhong": (blinn_lobe, 60.0, PHONG_KS)}[name]
    ambient = np.add(KA, np.multiply(KD, LA))
    lit = np.multiply.outer(np.ones(v.shape[:2]), ambient + np.multiply(KD, LIGHT_E))
    if lobe is not None:
        lit = lit + np.multiply.outer(lobe(Z, Z, v, q), np.multiply(ks, LIGHT_E))
    unlit = np.broadcast_to(ambient, lit.shape)
    results = {}
    for two_sided in (True, False):
        scene = glphong.Scene(camera, lights=[glphong.DirectionalLight((0.0, 0.0, -1.0), LIGHT_E)],
                              ambient=glphong.AmbientLight(LA))
        scene.add(plane_mesh(facing=-1), MATERIALS[name](ka=KA, two_sided=two_sided))
        frame, got = render(renderer, scene)
        assert frame.mask.all()  # drawn either way: back faces are not culled
        results[two_sided] = got
    # two_sided=True, measured 3.7e-8 (Lambert), 3.6e-7 (Phong), 4.0e-7 (Blinn: the lobe from the float32
    # view vector, smaller here than in the lobe tests as ambient and diffuse dilute it); rtol 5e-6 as there
    assert_matches_only(results[True], lambda s: lit if s else unlit, True, 5e-6, perturbed=[False])
    # two_sided=False, measured 4.0e-8 (ambient only); rtol 1e-6
    assert_matches_only(results[False], lambda s: lit if s else unlit, False, 1e-6, perturbed=[True])


# --------------------------------------------------------------------------- camera


def test_camera_yfov_mask_rows_and_columns(renderer):
    """A rectangle of half-widths (ax, ay) at distance h: pixel centre (j, i) is covered iff its ray hits
    inside, ``|x_i| h < ax`` and ``|y_j| h < ay`` with the pinhole x_i, y_j; non-square image (aspect)."""
    w, hgt, h, yfov = 41, 33, 2.0, 0.9
    t = np.tan(yfov / 2.0)
    # edges 0.05 px beyond the 9th column / 7th row from the centre: a 1% larger yfov uncovers them
    ax = (2 * 9 + 0.1) / w * t * (w / hgt) * h
    ay = (2 * 7 + 0.1) / hgt * t * h
    v = np.array([(-ax, -ay, 0.0), (ax, -ay, 0.0), (ax, ay, 0.0), (-ax, ay, 0.0)])
    scene = glphong.Scene(top_camera(height=h, yfov=yfov))
    scene.add(trimesh.Trimesh(v, [[0, 1, 2], [0, 2, 3]], process=False), glphong.Lambert(KD, ka=KA))
    frame, _ = render(renderer, scene, size=(w, hgt))

    def covered(fov):
        tt = np.tan(fov / 2.0)
        x = ((np.arange(w) + 0.5) / w * 2.0 - 1.0) * tt * (w / hgt) * h
        y = (1.0 - (np.arange(hgt) + 0.5) / hgt * 2.0) * tt * h
        # no pixel centre within 1e-3 px of an edge (1 px = 2 tt h / hgt at the plane)
        px = 2.0 * tt * h / hgt
        assert np.min(np.abs(np.abs(x) - ax)) > 1e-3 * px and np.min(np.abs(np.abs(y) - ay)) > 1e-3 * px
        return np.abs(y)[:, None] < ay, np.abs(x)[None, :] < ax

    rows, cols = covered(yfov)
    assert rows.sum() == 15 and cols.sum() == 19
    np.testing.assert_array_equal(frame.mask, rows & cols)  # exact: every pixel centre
    rows_p, cols_p = covered(PERTURB * yfov)
    assert rows_p.sum() != rows.sum() and cols_p.sum() != cols.sum()
    assert frame.mask.sum() != (rows_p & cols_p).sum()


def lit_plane(camera, light=(0.5, 0.2, 1.0), power=(30.0, 60.0, 90.0)):
    scene = glphong.Scene(camera, lights=[glphong.PointLight(light, power)])
    scene.add(plane_mesh(), glphong.Lambert(KD))
    return scene


def lit_plane_closed_form(yfov, r, eye, width, height, light=(0.5, 0.2, 1.0), power=(30.0, 60.0, 90.0)):
    """``kd Phi cos / (4 pi d^2)`` at the hit of each pixel ray with z = 0, and the coverage mask."""
    d = pinhole_rays(yfov, width, height, r)
    hit, t = plane_hit(np.asarray(eye, float), d, (0.0, 0.0, 0.0), Z)
    mask = (t > 0) & np.all(np.abs(hit[..., :2]) < 0.9 * PLANE_HALF, axis=-1)
    rr = np.asarray(light, float) - hit
    dist = np.linalg.norm(rr, axis=-1)
    return np.multiply.outer(rr[..., 2] / dist / (4.0 * np.pi * dist * dist), np.multiply(KD, power)), mask


CAMERA_POSE_ANGLES = (0.35, 0.4)   # rotate about x by 0.35 rad, then about z by 0.4 rad
CAMERA_EYE = (0.3, -0.8, 2.2)


def camera_rotation(ax=CAMERA_POSE_ANGLES[0], az=CAMERA_POSE_ANGLES[1]):
    return rotation((0.0, 0.0, 1.0), az) @ rotation((1.0, 0.0, 0.0), ax)


def test_camera_yfov_pose_lit_plane(renderer):
    """An oblique camera (rotation and translation in ``pose``) over a point-lit plane: every pixel is the
    closed form at the hit of its own pinhole ray; non-square image."""
    w, hgt, yfov = 41, 33, 0.7
    camera = glphong.PerspectiveCamera(yfov, pose=rigid(camera_rotation(), CAMERA_EYE))
    frame, got = render(renderer, lit_plane(camera), size=(w, hgt))
    expected, mask = lit_plane_closed_form(yfov, camera_rotation(), CAMERA_EYE, w, hgt)
    assert mask.all() and frame.mask.all()
    # measured 7.5e-7 (float32 interpolated positions of an oblique plane); rtol 2e-6
    rtol = 2e-6
    err = assert_matches_only(got, lambda f: lit_plane_closed_form(f, camera_rotation(), CAMERA_EYE, w, hgt)[0],
                              yfov, rtol)
    assert_matches_only(got, lambda e: lit_plane_closed_form(yfov, camera_rotation(), e, w, hgt)[0],
                        CAMERA_EYE, rtol)
    assert_matches_only(got, lambda a: lit_plane_closed_form(yfov, camera_rotation(*a), CAMERA_EYE, w, hgt)[0],
                        CAMERA_POSE_ANGLES, rtol,
                        perturbed=[(0.35 * 1.01, 0.4), (0.35, 0.4 * 1.01)])
    # the transposed rotation (world-to-camera taken for camera-to-world) is not matched either
    assert rel_error(got, lit_plane_closed_form(yfov, camera_rotation().T, CAMERA_EYE, w, hgt)[0]) > 1e-2
    print(f"\n[{renderer.backend}] camera pose: rel err {err:.2e}")


LOOK = dict(eye=(0.7, -0.9, 2.6), target=(0.1, 0.3, 0.0), up=(0.3, 1.0, 0.2), yfov=0.8)


def test_look_at_eye_target_up_yfov_lit_plane(renderer):
    """look_at: rotation columns x = up x z / |.|, y = z x x, z = (eye - target)/|.|; the point-lit
    plane is the closed form at every pixel."""
    w, hgt = 41, 33
    camera = glphong.PerspectiveCamera.look_at(LOOK["eye"], LOOK["target"], LOOK["up"], LOOK["yfov"])
    frame, got = render(renderer, lit_plane(camera), size=(w, hgt))

    def expected(eye=LOOK["eye"], target=LOOK["target"], up=LOOK["up"], yfov=LOOK["yfov"]):
        return lit_plane_closed_form(yfov, look_at_rotation(eye, target, up), eye, w, hgt)

    values, mask = expected()
    assert mask.all() and frame.mask.all()
    # measured 1.26e-6, at the far top row (hits 3 m away at a shallow angle; G-buffer positions there are
    # within 7.5e-7 m of the exact hits); rtol 3e-6.  The smallest perturbation effect is 1.9e-3 (target x)
    rtol = 3e-6
    err = assert_matches_only(got, lambda e: expected(eye=e)[0], LOOK["eye"], rtol)
    assert_matches_only(got, lambda t: expected(target=t)[0], LOOK["target"], rtol,
                        perturbed=[(0.101, 0.3, 0.0), (0.1, 0.303, 0.0)])
    # up: 1% on its x component rolls the image by 3 mrad
    assert_matches_only(got, lambda u: expected(up=u)[0], LOOK["up"], rtol, perturbed=[(0.303, 1.0, 0.2)])
    assert_matches_only(got, lambda f: expected(yfov=float(f))[0], LOOK["yfov"], rtol)
    print(f"\n[{renderer.backend}] look_at lit plane: rel err {err:.2e}")


def marker_mesh(points, r, eye, yfov, height, half_px=0.4):
    """Squares of half-width ``half_px`` pixels centred on ``points``, parallel to the image plane."""
    vertices, faces = [], []
    for p in points:
        p = np.asarray(p, float)
        depth = -(r.T @ (p - eye))[2]
        s = half_px * 2.0 * depth * np.tan(yfov / 2.0) / height
        x, y = r[:, 0] * s, r[:, 1] * s
        k = len(vertices)
        vertices += [p - x - y, p + x - y, p + x + y, p - x + y]
        faces += [[k, k + 1, k + 2], [k, k + 2, k + 3]]
    return trimesh.Trimesh(np.array(vertices), faces, process=False)


MARKERS = [(0.3, 0.5, 0.2), (-0.6, 0.1, -0.3), (0.2, -0.7, 0.4)]


def marker_pixels(points, yfov, width, height, r, eye):
    """The single pixel each marker covers: the pixel centre within 0.4 px of its projection."""
    out = set()
    for p in points:
        i, j = project(p, yfov, width, height, r, eye)
        # design check: the pixel centre nearest the projection is >= 0.05 px inside the marker's edge, the
        # next one >= 0.6 px outside it: exactly one centre is covered
        assert abs(i - round(i)) < 0.35 and abs(j - round(j)) < 0.35, (i, j)
        out.add((int(round(j)), int(round(i))))
    return out


def covered_pixels(mask):
    return {(int(j), int(i)) for j, i in zip(*np.nonzero(mask))}


def test_camera_pose_markers(renderer):
    """Markers at known world points appear at the pixels the test's own projection predicts (pose)."""
    w, hgt, yfov = 41, 33, 0.9
    r, eye = camera_rotation(), np.array([0.3, -1.5, 3.0])
    scene = glphong.Scene(glphong.PerspectiveCamera(yfov, pose=rigid(r, eye)))
    scene.add(marker_mesh(MARKERS, r, eye, yfov, hgt), glphong.Lambert(KD, ka=KA))
    frame, _ = render(renderer, scene, size=(w, hgt))
    expected = marker_pixels(MARKERS, yfov, w, hgt, r, eye)
    assert len(expected) == 3
    assert covered_pixels(frame.mask) == expected
    # a half-pixel marker resolves the pose to about 0.5 px (the 1% sensitivity is in the lit-plane test):
    # wrong readings of the pose (its rotation transposed, its translation negated in x or y, both angles
    # 5% off) put at least one marker elsewhere
    for r2, e2 in ((r.T, eye), (r, eye * (-1.0, 1.0, 1.0)), (r, eye * (1.0, -1.0, 1.0)),
                   (camera_rotation(0.35 * 1.05, 0.4 * 1.05), eye)):
        predicted = set()
        for p in MARKERS:
            i, j = project(p, yfov, w, hgt, r2, e2)
            predicted.add((int(round(j)), int(round(i))))
        assert predicted != expected


def test_look_at_markers_up_flips_image(renderer):
    """look_at with up = +y and up = -y: markers above the target are in the top half, then the bottom
    half, each at the pixel the test's own projection predicts (the two images are 180 degrees apart)."""
    w, hgt, yfov = 41, 33, 0.9
    eye, target = np.array([0.2, 0.1, 3.0]), np.array([0.0, 0.0, 0.0])
    above = [(0.4, 0.5, 0.2), (-0.6, 0.95, -0.3)]
    found = {}
    for up in ((0.0, 1.0, 0.0), (0.0, -1.0, 0.0)):
        r = look_at_rotation(eye, target, up)
        scene = glphong.Scene(glphong.PerspectiveCamera.look_at(eye, target, up, yfov))
        scene.add(marker_mesh(above, r, eye, yfov, hgt), glphong.Lambert(KD, ka=KA))
        frame, _ = render(renderer, scene, size=(w, hgt))
        expected = marker_pixels(above, yfov, w, hgt, r, eye)
        assert covered_pixels(frame.mask) == expected
        found[up[1]] = expected
    c_row, c_col = (hgt - 1) / 2, (w - 1) / 2
    assert all(j < c_row for j, _ in found[1.0]) and all(j > c_row for j, _ in found[-1.0])
    # 180 degrees about the optical axis: (j, i) -> (H-1-j, W-1-i) exactly (x and y both change sign)
    assert {(hgt - 1 - j, w - 1 - i) for j, i in found[1.0]} == found[-1.0]
    assert all(i != c_col for _, i in found[1.0])  # so the columns are mirrored too, not only the rows


@pytest.mark.parametrize("kind", ["PerspectiveCamera", "look_at"])
def test_camera_znear_zfar(renderer, kind):
    """A plane perpendicular to the axis at distance 2: fully visible iff znear < 2 < zfar, else fully
    clipped.  The clip distances are 0.05% either side of 2, so a clip distance wired 1% or 0.1% too large
    or too small flips one of the cases (checked on the closed form below).  The clip-space margin at
    0.05% is ~1e-3 relative, far above float32 rounding."""
    cases = [(1.999, 100.0, True), (2.001, 100.0, False), (0.05, 2.001, True), (0.05, 1.999, False)]
    visible_if = lambda n, f: n < 2.0 < f  # noqa: E731  (the closed form)
    for scale in (1.01, 0.99, 1.001, 0.999):
        assert any(visible_if(scale * n, f) != v for n, f, v in cases)
        assert any(visible_if(n, scale * f) != v for n, f, v in cases)
    for znear, zfar, visible in cases:
        if kind == "look_at":
            camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 2.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), 0.9,
                                                       znear=znear, zfar=zfar)
        else:
            camera = top_camera(height=2.0, yfov=0.9, znear=znear, zfar=zfar)
        scene = glphong.Scene(camera)
        scene.add(plane_mesh(), glphong.Lambert(KD, ka=KA))
        frame, got = render(renderer, scene)
        assert visible_if(znear, zfar) == visible
        assert frame.mask.all() if visible else not frame.mask.any(), (znear, zfar)
        if visible:
            np.testing.assert_array_equal(got, np.broadcast_to(np.float32(KA), got.shape))


# --------------------------------------------------------------------------- Scene.add pose and smooth


def posed_plane_closed_form(pose, light, power, camera_eye=(0.0, 0.0, 2.0), yfov=2.0 * np.arctan(0.6),
                            normal=None):
    """Point-lit Lambert plane z = 0 transformed by ``pose``: its world normal is the cross product of the
    transformed tangents (M e_x) x (M e_y) (or ``normal`` for the shading only), its point M (0, 0, 0)."""
    m = np.asarray(pose, float)
    n_geo = unit(np.cross(m[:3, 0], m[:3, 1]))
    n = n_geo if normal is None else unit(normal)
    eye = np.asarray(camera_eye, float)
    d = pinhole_rays(yfov, N, N, np.eye(3))
    hit, _ = plane_hit(eye, d, m[:3, 3], n_geo)
    rr = np.asarray(light, float) - hit
    dist = np.linalg.norm(rr, axis=-1)
    cos = (rr @ n) / dist
    return np.multiply.outer(np.maximum(cos, 0.0) / (4.0 * np.pi * dist * dist), np.multiply(KD, power))


def test_scene_add_pose_translation_rotation(renderer):
    """The plane lifted by dz toward the light and tilted by an angle about x: d and the normal change."""
    light, power = (0.3, -0.2, 1.4), (30.0, 60.0, 90.0)

    def pose(dz=0.35, angle=0.3):
        return rigid(rotation((1.0, 0.0, 0.0), angle), (0.0, 0.0, dz))

    scene = glphong.Scene(top_camera(), lights=[glphong.PointLight(light, power)])
    scene.add(plane_mesh(), glphong.Lambert(KD), pose=pose())
    frame, got = render(renderer, scene)
    assert frame.mask.all()
    # measured 6.4e-7 (float32 positions through the model matrix); rtol 2e-6
    rtol = 2e-6
    err = assert_matches_only(got, lambda dz: posed_plane_closed_form(pose(dz=float(dz)), light, power), 0.35, rtol)
    assert_matches_only(got, lambda a: posed_plane_closed_form(pose(angle=float(a)), light, power), 0.3, rtol)
    # and the identity pose (the pose ignored) is far off
    assert rel_error(got, posed_plane_closed_form(np.eye(4), light, power)) > 0.1
    print(f"\n[{renderer.backend}] Scene.add pose rigid: rel err {err:.2e}")


def test_scene_add_pose_shear_normal(renderer):
    """A shear pose z' = z + s x tilts the plane; its normal is (-s, 0, 1)/|.| (the inverse transpose of
    the pose, not the pose itself, transforms normals)."""
    light, power = (0.3, -0.2, 1.4), (30.0, 60.0, 90.0)

    def pose(s=0.4):
        m = np.eye(4)
        m[2, 0] = s
        m[2, 3] = 0.1
        return m

    scene = glphong.Scene(top_camera(), lights=[glphong.PointLight(light, power)])
    scene.add(plane_mesh(), glphong.Lambert(KD), pose=pose())
    frame, got = render(renderer, scene)
    assert frame.mask.all()
    # measured 1.1e-6 (the sheared plane is steeper: larger position error along the rays); rtol 3e-6
    err = assert_matches_only(got, lambda s: posed_plane_closed_form(pose(float(s)), light, power), 0.4, 3e-6)
    # the normal transformed by the pose's own 3x3 block, M (0, 0, 1) = (0, 0, 1), is not matched
    wrong = posed_plane_closed_form(pose(), light, power, normal=Z)
    assert rel_error(got, wrong) > 1e-2
    print(f"\n[{renderer.backend}] Scene.add pose shear: rel err {err:.2e}")


PYRAMID_H = 0.8


def pyramid():
    """Square pyramid, base half-width 1 at z = 0, apex (0, 0, PYRAMID_H), four side faces, no base."""
    v = np.array([(-1.0, -1.0, 0.0), (1.0, -1.0, 0.0), (1.0, 1.0, 0.0), (-1.0, 1.0, 0.0), (0.0, 0.0, PYRAMID_H)])
    faces = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    return v, faces


def ray_triangles(origin, dirs, v, faces):
    """First hits of rays with triangles (Moller-Trumbore): face index (-1 none) and barycentrics (H, W, 3)."""
    shape = dirs.shape[:-1]
    d = dirs.reshape(-1, 3)
    best_t = np.full(len(d), np.inf)
    face = np.full(len(d), -1)
    bary = np.zeros((len(d), 3))
    for f, (a, b, c) in enumerate(faces):
        e1, e2 = v[b] - v[a], v[c] - v[a]
        p = np.cross(d, e2)
        det = p @ e1
        s = origin - v[a]
        u = (p @ s) / det
        qv = np.cross(s, e1)
        w = (d @ qv) / det
        t = (qv @ e2) / det
        ok = (u >= 0) & (w >= 0) & (u + w <= 1) & (t > 0) & (t < best_t)
        best_t[ok], face[ok] = t[ok], f
        bary[ok] = np.stack([1 - u - w, u, w], axis=-1)[ok]
    return face.reshape(shape), bary.reshape(*shape, 3)


def test_scene_add_smooth_and_flat_normals(renderer):
    """smooth=False: each face shows ``kd E (n_f . l)`` with its own face normal; smooth=True: the
    barycentric interpolation of the vertex normals, renormalised.  Vertex normals by symmetry: the apex
    (0, 0, 1), a base corner the normalised sum of its two faces' normals."""
    v, faces = pyramid()
    direction, e = (-0.5, -0.3, -1.0), (2.0, 3.0, 4.0)
    l = unit(np.negative(direction))
    face_n = unit(np.cross(v[faces[:, 1]] - v[faces[:, 0]], v[faces[:, 2]] - v[faces[:, 0]]))
    vertex_n = np.zeros((5, 3))
    for f, tri in enumerate(faces):
        vertex_n[tri] += face_n[f]
    vertex_n = unit(vertex_n)
    assert np.allclose(vertex_n[4], Z)
    eye = np.array([0.0, 0.0, 3.0])
    yfov = 0.9
    d = pinhole_rays(yfov, N, N, np.eye(3))
    face, bary = ray_triangles(eye, d, v, faces)
    # away from the face edges: the smallest barycentric above 0.02 (about 0.1 px on these faces)
    interior = (face >= 0) & (bary.min(axis=-1) > 0.02)
    assert interior.sum() > 200

    def expected(smooth):
        n = face_n[face[interior]]
        if smooth:
            n = unit(np.einsum("pk,pkc->pc", bary[interior], vertex_n[faces[face[interior]]]))
        return np.multiply.outer(np.maximum(n @ l, 0.0), np.multiply(KD, e))

    for smooth in (False, True):
        mesh = trimesh.Trimesh(v, faces, process=False)
        assert np.allclose(mesh.vertex_normals, vertex_n)  # the input data agrees with the symmetry argument
        scene = glphong.Scene(glphong.PerspectiveCamera(yfov, pose=rigid(np.eye(3), eye)),
                              lights=[glphong.DirectionalLight(direction, e)])
        scene.add(mesh, glphong.Lambert(KD), smooth=smooth)
        frame, got = render(renderer, scene)
        # coverage: the exact ray cast, except within 0.02 barycentric of an edge
        near_edge = (face >= 0) & ~interior
        np.testing.assert_array_equal(frame.mask[~near_edge], (face >= 0)[~near_edge])
        # measured 2.5e-7 (flat) and 2.2e-7 (smooth, float32 interpolated normals); rtol 1e-6
        err = assert_matches_only(got[interior], expected, smooth, 1e-6,
                                  perturbed=[not smooth])
        print(f"\n[{renderer.backend}] smooth={smooth}: rel err {err:.2e} over {interior.sum()} px")


# --------------------------------------------------------------------------- sRGB encoding

#: exposure-scaled linear targets, one per channel, 255 srgb(x) =
#:   6.495  (linear branch, rounds down; 0.1% more exposure gives 6.5015 and rounds up),
#:   235.70 (high branch, rounds up: truncation would give 235; 1% more exposure gives ~236.74),
#:   200.45 (high branch, rounds down; 0.1% more exposure gives ~200.54).
#: The GPU's float32 error is ~1e-4 code values (pow), well inside the 0.005 .. 0.2 margins.
SRGB_CODES = (6.495, 235.70, 200.45)
EXPOSURE = 2.5


def srgb_inverse(code):
    """The linear value whose 255 srgb(x) is ``code`` (test set-up only; expected values use `srgb`)."""
    y = code / 255.0
    return y / 12.92 if y <= 0.04045 else ((y + 0.055) / 1.055) ** 2.4


def srgb_scene():
    """Lambert plane, light straight down with E = 1: L = kd exactly; kd chosen so exposure * L hits SRGB_CODES."""
    kd = tuple(srgb_inverse(c) / EXPOSURE for c in SRGB_CODES)
    scene = glphong.Scene(top_camera(), lights=[glphong.DirectionalLight((0.0, 0.0, -1.0), 1.0)])
    scene.add(plane_mesh(), glphong.Lambert(kd))
    return scene, np.array(kd)


def srgb8_closed_form(radiance, exposure):
    return np.rint(255.0 * srgb(exposure * radiance)).astype(np.uint8)


def check_srgb8(got, kd):
    assert got.dtype == np.uint8 and got.shape == (N, N, 3)
    expected = srgb8_closed_form(kd, EXPOSURE)
    assert tuple(expected) == (6, 236, 200)
    assert kd[0] * EXPOSURE < 0.0031308 < kd[1] * EXPOSURE  # both branches of the curve
    np.testing.assert_array_equal(got, np.broadcast_to(expected, got.shape))  # exact, every pixel
    # 1% more exposure changes every channel; exposure applied after the curve, or no rounding (truncation)
    for wrong in (srgb8_closed_form(kd, PERTURB * EXPOSURE),
                  np.rint(255.0 * np.clip(EXPOSURE * srgb(kd), 0, 1)).astype(np.uint8),
                  np.floor(255.0 * srgb(EXPOSURE * kd)).astype(np.uint8)):
        assert np.any(got[0, 0] != wrong), wrong
    assert np.all(srgb8_closed_form(kd, PERTURB * EXPOSURE) != expected)
    # even 0.1% more exposure changes the red (linear branch) and blue channels
    assert np.any(got[0, 0] != srgb8_closed_form(kd, 1.001 * EXPOSURE))
    assert np.all((srgb8_closed_form(kd, 1.001 * EXPOSURE) != expected) == (True, False, True))


def test_render_srgb8_exposure(renderer):
    """GPU encode: ``round(255 srgb(exposure L))`` exactly, on both branches of the curve."""
    scene, kd = srgb_scene()
    renderer.resize(N, N)
    check_srgb8(renderer.render_srgb8(scene, exposure=EXPOSURE), kd)
    # saturation: exposure large enough that every channel is above 1 gives 255
    np.testing.assert_array_equal(renderer.render_srgb8(scene, exposure=1e4), 255)


def test_frame_to_srgb8_exposure(renderer):
    """Host encode of the rendered radiance: the same closed form, exactly."""
    scene, kd = srgb_scene()
    frame, got = render(renderer, scene)
    # the radiance itself is kd (E = 1, cos = 1), measured 0 to 3e-8 relative (float32 rounding of kd)
    assert rel_error(got, kd) <= 1e-6
    check_srgb8(frame.to_srgb8(exposure=EXPOSURE), kd)
    np.testing.assert_array_equal(frame.to_srgb8(exposure=1e4), 255)
