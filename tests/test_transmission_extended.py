"""Transmissive surfaces under area and environment lights (issue 41): the extended kinds' weighted directions behind
the surface (glphong.shaders.generated._extended_loop, glphong.checks.transmission_twin._extended_behind,
docs/transmission.md).

Independent check: an orthographic camera looks down -z at a quad (normal +z) of KHR_materials_diffuse_transmission
(transmission 0, diffuse transmission 1, metallic 0) with KHR_materials_specular's ``specular = 0``, so ``F = 0``
exactly and the diffuse BTDF is ``c_dt / pi``; a RectLight below it shines on its back.  What the quad shows is then
``sum_k [n.wi_k < 0] (c_dt / pi) (-n.wi_k) E_k`` over the light's 4 x 4 cells, the midpoint rule ``E_k = L cos_l (A /
16) / d_k^2`` toward each cell's centre (written out here), and the exact integral is ``(c_dt / pi) E_back`` with
``E_back`` the irradiance of the rectangle at the normal ``-n`` by Lambert's polygon formula (written out here).
"""
import dataclasses

import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.definitions.material import Integral
from glphong.shaders import keys
from glphong.shaders.builders import _as_light_keys, _with_usage, program_key, term_keys
from glphong.shaders.generated import lights_chunk

SIZE = 24  # px; the view spans [-1, 1] m
C_DT = np.array([0.5, 0.7, 0.9])
L = np.array([2.0, 3.0, 4.0])  # W/(m^2 sr)
CENTER, U, V = np.array([0.1, -0.05, -0.8]), np.array([0.3, 0.0, 0.0]), np.array([0.0, 0.25, 0.0])  # emits toward +z
#: the midpoint rule's error against the exact integral at this geometry (4 x 4 cells of 0.075 x 0.0625 m, 0.8 m
#: away): 2.30e-3 relative at most over the quad (2000 random points; RMS 1.1e-3), the pixels' within it
#: (benchmarks/transmission_extended.py measures the method elsewhere)
METHOD_ERROR = 2.5e-3


def _quad_scene(light, material):
    camera = glphong.OrthographicCamera.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ymag=1.0)
    scene = glphong.Scene(camera, [light])
    scene.add(primitives.plane(1.0), material, name="glass")
    return scene


def _midpoint_sum(x, m=4):
    """``sum_k [n.wi_k < 0] (c_dt / pi) (-n.wi_k) E_k`` at points ``x`` (N, 3), n = +z (module docstring)."""
    front = np.cross(U, V)
    area = np.linalg.norm(front)
    out = np.zeros((len(x), 3))
    for a in range(m):
        for b in range(m):
            y = CENTER - x + U * ((a + 0.5) / m - 0.5) + V * ((b + 0.5) / m - 0.5)
            d = np.linalg.norm(y, axis=1)
            wi = y / d[:, None]
            cos_l = -(wi @ front) / area
            e = L * (cos_l * area / (m * m) / d ** 2)[:, None]
            behind = np.maximum(-wi[:, 2], 0.0) * (cos_l > 0)
            out += C_DT / np.pi * behind[:, None] * e
    return out


def _exact(x):
    """``(c_dt / pi) E_back``: Lambert's formula ``E = (L / 2) |sum_i theta_i g_i . n|`` over the edges, ``g_i`` the
    unit normal of the plane through x and edge i, ``theta_i`` the edge's angle seen from x (module docstring)."""
    corners = [CENTER - U / 2 - V / 2, CENTER + U / 2 - V / 2, CENTER + U / 2 + V / 2, CENTER - U / 2 + V / 2]
    total = np.zeros(len(x))
    for i in range(4):
        p, q = corners[i] - x, corners[(i + 1) % 4] - x
        p, q = p / np.linalg.norm(p, axis=1)[:, None], q / np.linalg.norm(q, axis=1)[:, None]
        g = np.cross(p, q)
        theta = np.arccos(np.clip(np.einsum("ij,ij->i", p, q), -1.0, 1.0))
        total += theta * (g @ np.array([0.0, 0.0, -1.0])) / np.linalg.norm(g, axis=1)
    return C_DT / np.pi * (L * np.abs(total)[:, None] / 2.0)


def test_a_diffuse_transmission_quad_under_a_rect_light_behind_is_the_midpoint_rule(glphong_backend,
                                                                                     glphong_make_renderer):
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    material = glphong.GltfPBR(0.5, 0.0, 0.5, specular=0.0, diffuse_transmission=1.0, diffuse_transmission_color=C_DT)
    scene = _quad_scene(glphong.RectLight(CENTER, U, V, radiance=L), material)
    frame = renderer.render(scene)
    gbuffer = renderer.gbuffer(scene)
    mask = gbuffer.mask
    assert mask.sum() == (SIZE // 2) ** 2
    x = gbuffer.position[mask].astype(np.float64)
    expected = _midpoint_sum(x)
    np.testing.assert_allclose(frame.radiance[mask], expected, rtol=2e-5)
    exact = _exact(x)
    assert np.max(np.abs(expected / exact - 1.0)) < METHOD_ERROR
    assert np.max(np.abs(frame.radiance[mask] / exact - 1.0)) < METHOD_ERROR + 2e-5
    report = glphong.verify(scene, renderer)
    assert report.passed and report.transmission.pixels.sum() == (SIZE // 2) ** 2, report.summary()


def _sphere_scene(light, **volume):
    camera = glphong.PerspectiveCamera.look_at((0.3, -0.4, 2.5), (0.0, 0.0, 0.0))
    scene = glphong.Scene(camera, [light])
    pose = np.eye(4)
    pose[2, 3] = -1.0
    scene.add(primitives.plane(4.0, segments=4), glphong.Lambert(0.4), pose=pose, name="floor")
    glass = glphong.GltfPBR((0.9, 0.8, 0.6), 0.1, 0.4, ior=1.4, transmission=0.6, diffuse_transmission=0.5,
                            diffuse_transmission_color=(0.6, 0.8, 0.9), **volume)
    scene.add(primitives.sphere(2, 0.6), glass, name="glass")
    return scene


#: each extended kind below the sphere (the environment all round it)
LIGHTS = {"rect": lambda: glphong.RectLight((0.1, 0.2, -0.7), (0.6, 0.0, 0.0), (0.0, 0.4, 0.0), radiance=3.0),
          "environment": lambda: glphong.EnvironmentLight.example(samples=2),
          "disk": lambda: glphong.DiskLight((0.0, 0.1, -0.8), (0.1, 0.0, 1.0), 0.3, 3.0),
          "sphere": lambda: glphong.SphereLight((0.2, 0.1, -0.9), 0.2, 5.0),
          "polygon": lambda: glphong.PolygonLight([(0.0, 0.0, -0.8), (0.5, 0.0, -0.8), (0.5, 0.4, -0.8),
                                                   (0.1, 0.5, -0.8)], 3.0, samples=2)}
VOLUME = {"thickness": 0.3, "attenuation_color": (0.9, 0.6, 0.4), "attenuation_distance": 0.5}


@pytest.mark.parametrize("light, volume", [(name, False) for name in sorted(LIGHTS)] + [("rect", True),
                                                                                      ("environment", True)])
def test_a_transmissive_sphere_under_an_extended_light_verifies(light, volume, glphong_backend,
                                                                glphong_make_renderer):
    """Both responses behind (the BTDF and the diffuse transmission) over the kind's samples, thin or a volume (the
    BTDF's directions seen from the exit point, both attenuated): verify's twin adds them
    (`glphong.checks.transmission_extended`), and they are there (the sphere's front shows light that only comes
    through it: no light in front of it but the environment's)."""
    renderer = glphong_make_renderer(40, 32, glphong_backend)
    scene = _sphere_scene(LIGHTS[light](), **(VOLUME if volume else {}))
    report = glphong.verify(scene, renderer)
    assert report.passed and report.transmission.pixels.sum() > 200, report.summary()
    assert report.transmission.transmitted[report.transmission.pixels].max() > 0.05


def test_a_light_behind_left_out_or_gated_the_wrong_way_fails_verify(monkeypatch, glphong_make_renderer):
    """The generated behind line planted wrong (the gate flipped to n.wi > 0) and the loop's behind part left out:
    verify fails under a RectLight."""
    original = keys.lights_chunk
    glass = _sphere_scene(LIGHTS["rect"]()).objects[1].material
    text = original(program_key(glass, [LIGHTS["rect"]()], (0.0, 0.0, 0.0)))
    for old, new in (("n_dot_l < 0.0) ? through", "n_dot_l > 0.0) ? through"),
                     ("reflected += (valid && n_dot_l < 0.0) ? diffuse_through",
                      "reflected += (false) ? diffuse_through")):
        assert text.count(old) == 1

        def planted(key, old=old, new=new):
            text = original(key)
            return text.replace(old, new) if "rect_sample" in text else text

        monkeypatch.setattr(keys, "lights_chunk", planted)
        report = glphong.verify(_sphere_scene(LIGHTS["rect"]()), glphong_make_renderer(40, 32, "egl"))
        assert not report.passed and report.outside_count > 0, (old, report.summary())
        monkeypatch.setattr(keys, "lights_chunk", original)


def test_programs_without_a_response_behind_keep_their_loop():
    """Without transmission the extended loop is what it was: the sampled terms alone (GltfPBR), no loop where every
    term is in closed form (Lambert); with it, the samples carry the responses behind, gated on n.wi < 0."""
    rect = glphong.RectLight((0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), radiance=1.0)
    loop = "\n".join(["    for (int j = 0; j < RECT_LIGHT_COUNT; ++j) {",
                      "        vec3 reflected = vec3(0.0);",
                      "        for (int k = 0; k < RECT_MAX_SAMPLES; ++k) {",
                      "            valid = rect_sample(position, f.n, j, k, wi, irradiance);",
                      "            n_dot_l = dot(f.n, wi);",
                      "            vec3 term = light_term(material_response_rect(f, wi, wo, n_dot_l), irradiance);",
                      "            reflected += (valid && n_dot_l > 0.0) ? term : vec3(0.0);",
                      "        }",
                      "        radiance += lit ? reflected : vec3(0.0);",
                      "    }",
                      "}"])
    opaque = lights_chunk(program_key(glphong.GltfPBR(0.8, 0.1, 0.4), [rect], (0.0, 0.0, 0.0)))
    assert opaque.endswith(loop + "\n") and "n_dot_l < 0.0" not in opaque
    lambert = lights_chunk(program_key(glphong.Lambert(0.5), [rect], (0.0, 0.0, 0.0)))
    assert "rect_sample" not in lambert and "n_dot_l < 0.0" not in lambert
    glass = lights_chunk(program_key(glphong.GltfPBR(0.8, 0.1, 0.4, transmission=1.0), [rect], (0.0, 0.0, 0.0)))
    assert "            reflected += (valid && n_dot_l < 0.0) ? through : vec3(0.0);" in glass
    assert glass.count("rect_sample(") == 1


def test_verify_refuses_the_exact_integrals_naming_the_extension(glphong_make_renderer):
    """exact=True stays refused (the exact image is not computed through a transmissive surface); the message names
    the object's extension; exact=None checks the method and computes no exact image."""
    renderer = glphong_make_renderer(SIZE, SIZE, "egl")
    material = glphong.GltfPBR(0.5, 0.0, 0.5, specular=0.0, diffuse_transmission=1.0, diffuse_transmission_color=C_DT)
    scene = _quad_scene(glphong.RectLight(CENTER, U, V, radiance=L), material)
    refused = r"'glass' is transmissive \(KHR_materials_diffuse_transmission\): .*exact=True"
    with pytest.raises(ValueError, match=refused):
        glphong.verify(scene, renderer, exact=True)
    report = glphong.verify(scene, renderer)
    assert report.passed and report.exact is None, report.summary()


def test_a_light_behind_declares_the_kind_s_samples_whatever_the_terms_closed_forms():
    """The extended loop samples the kind for the light behind the surface even where every lit term reflects it in
    closed form (a model of the open mechanism may declare ``behind_responses`` and an ``Integral``): the key then
    asks the kind for its samples' defines too, or the generated ``<kind>_sample`` call would not compile."""
    glass = glphong.GltfPBR(0.5, 0.0, 0.4, transmission=1.0)
    (light,) = _as_light_keys([glphong.EnvironmentLight(np.ones((4, 8)))])
    terms = term_keys(glass, True, False, extended=True, occludable=True)
    closed = tuple(dataclasses.replace(t, integral=Integral("irradiance", "base_color")) for t in terms)
    assert all(t.integral.form in light.integrals for t in closed if t.lit)  # every lit term closed, as planted
    without, with_behind = (dict(_with_usage(light, closed, behind).defines) for behind in (False, True))
    assert "USES_SAMPLE" not in without and with_behind["USES_SAMPLE"] == "1"
