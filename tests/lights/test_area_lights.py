"""Area lights (glphong.RectLight, PolygonLight, SphereLight): the lecture's continuous version, checked against
closed forms that share nothing with glphong's GLSL or twin, on both backends.

- A horizontal rectangle over a horizontal Lambert plane: the textbook form factor of a rectangle with a corner
  above the point, ``F(A, B, h) = (1/2pi) [A/sqrt(A^2+h^2) atan(B/sqrt(A^2+h^2)) + B/sqrt(B^2+h^2)
  atan(A/sqrt(B^2+h^2))]``, superposed over the four corners: ``E = pi L sum +-F``.
- The Phong lobe seen along the normal under a rectangle that covers the sky: ``k_s 2 pi L / (q + 1)`` less the
  lobe's tail beyond the rectangle (below ``2 pi cos(theta_c)^(q+1) / (q + 1)``).
- A sphere above the horizon: ``pi L (R/d)^2 cos(theta)``, a `PointLight` of the same power; a rectangle shrinking at
  fixed intensity tends to a point of intensity ``L A cos(theta_l)``, its error falling like ``(size/d)^2``.
- `glphong.verify` passes and reports both error maps: the GPU against the twin (float32 band), and the twin's
  method against the exact integral (float64 quadrature): closed forms exact, the sampled terms' error measured.
"""
import runpy
from pathlib import Path

import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.checks.points import shade_points
from glphong.checks.stability import case_inputs
from glphong.checks.verify import exact_image, relative_error
from glphong.gpu.contexts import create_context
from glphong.gpu.programs import ProgramCache
from glphong.lights import LightDefinitionError
from glphong.definitions.cases import Case
from glphong.materials.phong import PhongLobe
from glphong.shaders.generated import lights_chunk
from glphong.shaders import assembly
from glphong.twin.quadrature import disk_integral
from glphong.shaders.key import uber_key
from glphong.shaders.binding import binding

ROOT = Path(__file__).resolve().parents[2]


def _corner_factor(a, b, h):
    """Form factor of the rectangle [0, a] x [0, b] at height h from a point below its corner (signed a, b)."""
    sa, sb = np.sign(a), np.sign(b)
    a, b = np.abs(a), np.abs(b)
    ra, rb = np.sqrt(a * a + h * h), np.sqrt(b * b + h * h)
    return sa * sb * (a / ra * np.arctan(b / ra) + b / rb * np.arctan(a / rb)) / (2 * np.pi)


def _rect_irradiance(points, x0, x1, y0, y1, h, radiance):
    px, py = points[:, 0], points[:, 1]
    f = (_corner_factor(x1 - px, y1 - py, h) - _corner_factor(x0 - px, y1 - py, h)
         - _corner_factor(x1 - px, y0 - py, h) + _corner_factor(x0 - px, y0 - py, h))
    return np.pi * radiance * f


def _points_gpu(backend, material, light, points, normals, eye=(0.0, 0.0, 5.0)):
    key, uniforms = case_inputs(Case("area", "area", material, eye=eye, lights=(light,)))
    gl = create_context(backend)
    programs = ProgramCache(gl.mgl)
    try:
        return shade_points(gl, programs, key, uniforms, points, normals, drop_unused=True).astype(np.float64)
    finally:
        with gl:
            programs.release()
        gl.release()


def _scene(light, sphere_material=None):
    camera = glphong.PerspectiveCamera.look_at((0.0, -2.0, 3.0), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), yfov=1.0)
    scene = glphong.Scene(camera, [light])
    scene.add(primitives.plane(4.0, segments=4), glphong.Phong(0.2, 0.3, 20.0))
    pose = np.eye(4)
    pose[:3, 3] = (-0.6, 0.0, 0.4)
    scene.add(primitives.sphere(2, 0.4), sphere_material or glphong.BlinnPhong(0.2, 0.3, 30.0), pose=pose)
    return scene


LIGHTS = {
    "rect": lambda: glphong.RectLight((0.0, 0.5, 1.0), (1.0, 0.0, 0.0), (0.0, -0.6, -0.3), 5.0, samples=3),
    "polygon": lambda: glphong.PolygonLight([(0.0, 0.5, 1.0), (0.5, 0.5, 1.0), (0.6, 0.5, 1.5), (0.2, 0.5, 1.8),
                                             (-0.3, 0.5, 1.4)], 5.0, samples=2),
    "sphere": lambda: glphong.SphereLight((0.3, 0.5, 0.5), 0.3, 5.0, samples=3),
    "disk": lambda: glphong.DiskLight((0.2, 0.6, 0.9), (-0.1, -0.6, -0.5), 0.45, 5.0, samples=3),
}


@pytest.mark.parametrize("kind", sorted(LIGHTS))
def test_verify_reports_both_error_maps(kind, glphong_backend, glphong_make_renderer):
    scene = _scene(LIGHTS[kind]())
    renderer = glphong_make_renderer(48, 36, glphong_backend)
    report = glphong.verify(scene, renderer)
    assert report.passed, str(report)
    assert report.exact is not None and report.method_error.shape == report.gpu.shape
    lit = report.mask[..., None] & (report.exact > 1e-3 * report.exact.max())  # slivers at the horizon apart
    plane = (renderer.gbuffer(scene).object_index == 0)[..., None]
    closed = report.method_error[plane & lit]  # Phong with an integer q: every term in closed form
    sampled = report.method_error[~plane & lit]  # Blinn-Phong: the light's weighted directions
    if kind not in ("sphere", "disk"):  # (under a sphere or a disk the Phong lobe is sampled too)
        assert closed.max() == 0  # every term's closed form is exact: verify's exact image takes it
        # ... and the quadrature, independent of the GLSL and the twin, says so: exact up to the float32 uniforms (a
        # polygon's edges, rounded apart from its vertices, close to ~1e-8 m)
        gbuffer = renderer.gbuffer(scene)
        quadrature, _ = exact_image(scene, gbuffer, renderer.shadow_settings, closed_forms=False)
        off = relative_error(report.exact, quadrature)[plane & lit]
        assert off.max() < 1e-5 and np.median(off) < 1e-6, (off.max(), np.median(off))
    assert np.median(sampled) > 1e-6  # the sampled method's own error shows
    mean, worst = report.method_error_figures()
    assert 0 < mean <= worst and "method against exact" in str(report)


def test_rect_over_a_plane_matches_the_form_factor(glphong_backend, glphong_make_renderer):
    h, radiance = 0.8, 3.0
    light = glphong.RectLight((0.2, -0.1, h), (0.0, 0.7, 0.0), (1.2, 0.0, 0.0), radiance)  # u x v = -z: emits down
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0), yfov=1.0)
    scene = glphong.Scene(camera, [light])
    scene.add(primitives.plane(4.0, segments=2), glphong.Lambert(1.0))
    renderer = glphong_make_renderer(96, 96, glphong_backend)
    gbuffer = renderer.gbuffer(scene)
    gpu = renderer.render(scene).radiance[gbuffer.mask].astype(np.float64)
    points = gbuffer.position[gbuffer.mask].astype(np.float64)
    c = np.asarray(light.center, np.float32).astype(np.float64)
    closed = _rect_irradiance(points, c[0] - 0.6, c[0] + 0.6, c[1] - 0.35, c[1] + 0.35, c[2] - points[:, 2],
                              float(np.float32(radiance)))
    assert closed.min() > 0.01 * closed.max()
    rel = np.abs(gpu[:, 0] - closed) / closed
    assert rel.max() < 2e-5, rel.max()


@pytest.mark.parametrize("q", [1, 2, 10, 101])
def test_phong_lobe_along_the_normal_under_a_covering_rect(q, glphong_backend):
    radiance, ks, size = 2.0, 0.5, 2.0e4  # half-side 1e4 at height 1: theta_c > 89.99 deg
    light = glphong.RectLight((0.0, 0.0, 1.0), (0.0, size, 0.0), (size, 0.0, 0.0), radiance)
    gpu = _points_gpu(glphong_backend, PhongLobe(ks, float(q)), light, np.zeros((1, 3)), [(0.0, 0.0, 1.0)])
    expected = ks * 2 * np.pi * radiance / (q + 1)
    tail = 2 * np.pi * (1.0 / np.hypot(1.0, size / 2)) ** (q + 1) / (q + 1) * ks * radiance
    assert abs(gpu[0, 0] - expected) <= tail + 3e-6 * expected, (gpu[0, 0], expected)


def test_lambert_under_a_covering_rect_is_pi_l(glphong_backend):
    radiance, size = 2.0, 2.0e4
    light = glphong.RectLight((0.0, 0.0, 1.0), (0.0, size, 0.0), (size, 0.0, 0.0), radiance)
    gpu = _points_gpu(glphong_backend, glphong.Lambert(1.0), light, np.zeros((1, 3)), [(0.0, 0.0, 1.0)])
    a = size / 2
    closed = 4 * radiance * a / np.hypot(a, 1.0) * np.arctan(a / np.hypot(a, 1.0))  # the form factor, 4 corners
    assert abs(gpu[0, 0] - closed) <= 3e-6 * closed and abs(closed - np.pi * radiance) < 1e-3


def test_disk_on_its_axis_and_across_the_horizon(glphong_backend):
    radius, d, radiance = 0.5, 1.5, 3.0
    light = glphong.DiskLight((0.0, 0.0, d), (0.0, 0.0, -1.0), radius, radiance)
    gpu = _points_gpu(glphong_backend, glphong.Lambert(1.0), light, np.zeros((1, 3)), [(0.0, 0.0, 1.0)])
    closed = np.pi * radiance * radius ** 2 / (radius ** 2 + d ** 2)  # the textbook on-axis disk
    assert abs(gpu[0, 0] - closed) <= 2e-6 * closed
    # across the horizon: against the independent quadrature (glphong.twin.quadrature), tilting the normal to 90 deg
    tilts = np.linspace(0.0, np.pi / 2, 12)
    normals = np.stack([np.sin(tilts), np.zeros(12), np.cos(tilts)], axis=1)
    gpu = _points_gpu(glphong_backend, glphong.Lambert(1.0), light, np.zeros((12, 3)), normals)[:, 0]
    p = light.values()
    exact = disk_integral(np.zeros((12, 3)), normals, p.center, p.normal, float(p.radius), p.radiance,
                          lambda i, w: np.sum(normals[i] * w, axis=-1))[0][:, 0]
    assert np.all(np.abs(gpu - exact) <= 3e-6 * exact.max()), np.abs(gpu - exact).max()
    assert exact[-1] < 0.1 * exact[0]  # at 90 deg most of the disk's light is below the horizon


def test_sphere_is_a_point_light_of_its_power(glphong_backend):
    power, d = 50.0, 2.0
    rng = np.random.default_rng(3)
    normals = rng.normal(size=(64, 3))
    normals[:, 2] = np.abs(normals[:, 2]) + 2.0  # the sphere wholly above every horizon
    point = _points_gpu(glphong_backend, glphong.Lambert(1.0), glphong.PointLight((0.0, 0.0, d), power),
                        np.zeros((64, 3)), normals)
    for radius in (1.0, 0.1, 1e-3):
        sphere = _points_gpu(glphong_backend, glphong.Lambert(1.0), glphong.SphereLight.from_power((0.0, 0.0, d),
                                                                                                   radius, power),
                             np.zeros((64, 3)), normals)
        assert np.allclose(sphere, point, rtol=2e-6, atol=0), (radius, np.abs(sphere / point - 1).max())


def test_a_shrinking_rect_tends_to_a_point_light(glphong_backend):
    intensity, d = 4.0, 3.0  # W/sr toward the point below, held fixed
    normals = np.array([(0.0, 0.0, 1.0), (0.3, 0.0, 1.0), (0.0, -0.5, 1.0)])
    limit = intensity / d ** 2 * (normals[:, 2] / np.linalg.norm(normals, axis=1))
    errors = []
    for size in (1.0, 0.1, 0.01):
        light = glphong.RectLight((0.0, 0.0, d), (0.0, size, 0.0), (size, 0.0, 0.0), intensity / size ** 2)
        gpu = _points_gpu(glphong_backend, glphong.Lambert(1.0), light, np.zeros((3, 3)), normals)[:, 0]
        errors.append(np.abs(gpu / limit - 1).max())
    assert errors[0] > 1e-3 and errors[1] < errors[0] / 50 and errors[2] < 1e-4, errors


def test_polygon_light_checks_its_vertices():
    with pytest.raises(ValueError, match="planar"):
        glphong.PolygonLight([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0.5)], 1.0)
    with pytest.raises(ValueError, match="convex"):
        glphong.PolygonLight([(0, 0, 0), (1, 0, 0), (0.2, 0.2, 0), (0, 1, 0)], 1.0)
    with pytest.raises(ValueError, match="3 to 8"):
        glphong.PolygonLight([(np.cos(t), np.sin(t), 0) for t in np.linspace(0, 6, 9)], 1.0)
    with pytest.raises(ValueError, match="whole number"):
        glphong.RectLight((0, 0, 0), (1, 0, 0), (0, 1, 0), 1.0, samples=2.5)
    with pytest.raises(ValueError, match="parallelogram"):
        glphong.RectLight((0, 0, 0), (1, 0, 0), (2, 0, 0), 1.0)


def test_the_polygon_and_rect_agree():
    rect = glphong.RectLight((0.1, 0.2, 1.0), (0.0, 0.7, 0.1), (0.5, 0.0, 0.0), 2.0)
    polygon = glphong.PolygonLight(rect.corners(), 2.0)
    rng = np.random.default_rng(0)
    x = rng.uniform(-1, 1, (200, 3)) * (1, 1, 0.3)
    n = rng.normal(size=(200, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    e_rect = rect.irradiance(x, n, rect.values())
    e_polygon = polygon.irradiance(x, n, polygon.values())
    # the same light rounded to float32 two ways: near the horizon a tiny E moves with its vertices' last bits
    assert np.allclose(e_rect, e_polygon, rtol=1e-5, atol=1e-6 * e_rect.max())


def test_left_out_where_no_scene_needs_it():
    point_only = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)), [glphong.PointLight((0, 0, 2), 10)])
    point_only.add(primitives.plane(), glphong.Phong(0.2, 0.3, 20.0))
    key = binding(point_only).program_key(point_only.objects[0])
    assert "area" not in key.light_library_chunks() and all(t.integral is None for t in key.terms)
    closed = _scene(LIGHTS["rect"]())
    key = binding(closed).program_key(closed.objects[0])  # Phong, integer q: no sample loop, no sampled response
    text = lights_chunk(key)
    assert "rect_irradiance" in text and "rect_lobe" in text and "rect_sample" not in text
    key = binding(closed).program_key(closed.objects[1])  # Blinn-Phong: Lambert in closed form, the lobe sampled
    text = lights_chunk(key)
    assert "rect_irradiance" in text and "rect_sample" in text and "rect_lobe" not in text


def test_the_uber_shader_refuses_extended_lights():
    with pytest.raises(ValueError, match="specialise=True"):
        uber_key([glphong.Lambert(0.5)], lights=[LIGHTS["rect"]()])


def test_an_extended_kind_must_give_its_exact_integral():
    with pytest.raises(LightDefinitionError, match=r"defines no `exact`"):
        class Flat(glphong.ExtendedLight):  # noqa: F841 - defined to be refused
            name = "glowpanel"
            params = (glphong.Param("radiance", "rgb", low=0.0),)
            glsl = ("vec3 glowpanel_irradiance(vec3 x, vec3 n, int j) { return u_glowpanel_radiance[j]; }\n"
                    "bool glowpanel_sample(vec3 x, vec3 n, int j, int k, out vec3 wi, out vec3 irradiance)"
                    " { wi = n; irradiance = vec3(0.0); return false; }")

            def irradiance(self, x, n, p):
                return np.broadcast_to(p.radiance, x.shape)

            def sample(self, x, n, k, p):
                return np.zeros(len(x), bool), n, np.zeros_like(x)


def test_an_extended_kind_is_checked_like_any_light():
    with pytest.raises(LightDefinitionError, match=r"must define `bool glow_sample\(vec3 x, vec3 n, int j, int k"):
        class Glow(glphong.ExtendedLight):  # noqa: F841 - defined to be refused
            name = "glow"
            params = (glphong.Param("radiance", "rgb", low=0.0),)
            glsl = "vec3 glow_irradiance(vec3 x, vec3 n, int j) { return u_glow_radiance[j]; }"

            def irradiance(self, x, n, p):
                return np.broadcast_to(p.radiance, x.shape)

            def sample(self, x, n, k, p):
                return np.zeros(len(x), bool), n, np.zeros_like(x)


def test_the_continuous_version_example_runs():
    example = runpy.run_path(str(ROOT / "examples" / "continuous_version.py"))
    strip = example["main"](width=48, height=36)  # asserts each render passes verify
    assert strip.shape == (36, 192, 3) and strip.max() > 0


PLANTED = {  # (chunk, text, planted text, light)
    "Lambert's edge sum 1e-4 too large": ("area", "max(-0.5 * sum, 0.0)", "max(-0.50005 * sum, 0.0)", "rect"),
    "Arvo's recurrence a step short": ("area", "for (int k = even ? 1 : 0; k < qi; k += 2)",
                                       "for (int k = even ? 1 : 0; k < qi - 2; k += 2)", "rect"),
    # a slide along the edge moves the integral to second order where the integrand vanishes on the cut (Lambert's
    # cosine on the horizon): measured on this scene, 1e-3 moved no pixel by more than 2.5e-7, inside the band; 1e-2
    # moves one by 5.2e-5 against a half-width of 1.5e-6
    "a clip point 1 % off along its edge": ("area", "d[i] / (d[i] - d[next])", "1.01 * d[i] / (d[i] - d[next])",
                                            "rect+phong"),
    # the first draft's bug, found by the quadrature: this term set to 0 on the disk's axis, where it is -w
    "the disk's arc without its log term": ("light:disk", "float L = -w * disk_log1p_over(rho * w);",
                                            "float L = 0.0 * w;", "disk"),
    "the sphere's horizon branch 1e-4 off": ("light:sphere", "+ atan2_first_quadrant(s, X)",
                                             "+ 1.0001 * atan2_first_quadrant(s, X)", "sphere"),
}


@pytest.mark.parametrize("planted", sorted(PLANTED))
def test_planted_errors_fail(planted, monkeypatch, glphong_make_renderer):
    """The same scenes pass unplanted (test_verify_reports_both_error_maps)."""
    chunk, old, new, kind = PLANTED[planted]
    kind, _, phong = kind.partition("+")  # '+phong': the sphere in Phong, whose lobe the horizon cuts
    light = LIGHTS[kind]()
    if chunk == "area":
        original = assembly.chunk_source
        source = original("area")
        monkeypatch.setattr(assembly, "chunk_source", lambda name: source.replace(old, new) if name == "area"
                            else original(name))
    else:  # a kind's own chunk
        original = assembly.light_source
        source = original(type(light))
        monkeypatch.setattr(assembly, "light_source", lambda k: (source[0].replace(old, new),) + tuple(source[1:])
                            if k is type(light) else original(k))
    assert old in source if chunk == "area" else old in source[0]
    scene = _scene(light, glphong.Phong(0.2, 0.3, 30.0) if phong else None)
    report = glphong.verify(scene, glphong_make_renderer(48, 36, "egl"), exact=False)
    assert not report.passed and report.outside_count > 0, report.summary()
