"""`glphong.checks.verify.twin_and_band` shades each object's pixels in chunks of `TWIN_CHUNK` (docs/speed.md,
"Verify against the render"): every pixel's arithmetic is its own, so the twin, its band and the shadow band are
those of shading the whole object at once, bit for bit (an environment light with its samples, a rect light, a
shadowing spot light; Phong, Blinn-Phong, Lambert and GltfPBR)."""
import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.checks import reference, verify
from glphong.checks.tolerances import BAND


def _scene(light, materials):
    camera = glphong.PerspectiveCamera.look_at((0.0, -2.0, 3.0), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), yfov=1.0)
    scene = glphong.Scene(camera, [light])
    scene.add(primitives.plane(4.0, segments=2), materials[0])
    pose = np.eye(4)
    pose[:3, 3] = (-0.6, 0.0, 0.4)
    scene.add(primitives.sphere(3, 0.4), materials[1], pose=pose)
    return scene


LIGHTS = {"environment": lambda: glphong.EnvironmentLight.example(samples=2),
          "rect": lambda: glphong.RectLight((0.3, -0.5, 1.6), (0.0, 0.6, 0.3), (1.0, 0.0, 0.0), 5.0),
          "spot with shadows": lambda: glphong.SpotLight((0.8, -1.0, 2.0), (-0.8, 1.0, -1.5), 20.0, 0.3, 0.6,
                                                         shadows=True)}
MATERIALS = [(glphong.Phong(0.2, 0.3, 20.0), glphong.BlinnPhong(0.2, 0.3, 30.0)),
             (glphong.Lambert(0.5), glphong.GltfPBR((0.8, 0.5, 0.2), 0.3, 0.4))]


@pytest.mark.parametrize("materials", MATERIALS, ids=["phong", "pbr"])
@pytest.mark.parametrize("light", LIGHTS)
def test_the_twin_in_chunks_is_the_twin_whole(light, materials, monkeypatch, glphong_make_renderer):
    scene = _scene(LIGHTS[light](), materials)
    renderer = glphong_make_renderer(96, 72, "egl")
    gbuffer = renderer.gbuffer(scene)
    assert (gbuffer.object_index == 0).sum() > 1500 and (gbuffer.object_index == 1).sum() > 150
    monkeypatch.setattr(verify, "TWIN_CHUNK", 1 << 30)
    whole = verify.twin_and_band(scene, gbuffer, shadows=renderer.shadow_settings)
    monkeypatch.setattr(verify, "TWIN_CHUNK", 67)  # several chunks an object, the last one shorter
    chunked = verify.twin_and_band(scene, gbuffer, shadows=renderer.shadow_settings)
    for a, b in zip(whole, chunked):
        assert a.dtype == b.dtype and np.array_equal(a, b)


def test_each_objects_values_are_read_once_for_all_its_chunks(monkeypatch, glphong_make_renderer):
    """`twin_and_band` reads each term's parameter values from the uniforms once an object
    (`glphong.checks.uniform_values`), not once a chunk for the twin and again for the band, and the view directions
    once a chunk for both; the arrays stay those of reading them every time."""
    scene = _scene(glphong.SpotLight((0.8, -1.0, 2.0), (-0.8, 1.0, -1.5), 20.0, 0.3, 0.6), MATERIALS[1])
    renderer = glphong_make_renderer(96, 72, "egl")
    gbuffer = renderer.gbuffer(scene)
    monkeypatch.setattr(verify, "TWIN_CHUNK", 1 << 30)
    whole = verify.twin_and_band(scene, gbuffer)
    calls = []
    for kind in {type(term) for obj in scene.objects for term in obj.material.components}:
        read = kind.values_from_uniforms
        monkeypatch.setattr(kind, "values_from_uniforms",
                            lambda term, *a, _read=read, **k: calls.append(term) or _read(term, *a, **k))
    views, shaded = [], []
    for name, log in (("view_direction", views), ("shade_point", shaded)):
        monkeypatch.setattr(reference, name, lambda *a, _f=getattr(reference, name), _log=log, **k: _log.append(1) or
                            _f(*a, **k))
    monkeypatch.setattr(verify, "TWIN_CHUNK", 67)  # many chunks for the floor, a few for the sphere
    chunked = verify.twin_and_band(scene, gbuffer)
    terms = [term for obj in scene.objects for term in obj.material.components]
    assert sorted(map(id, calls)) == sorted(map(id, terms))  # once each
    assert len(shaded) > 10 and len(views) == len(shaded)  # the view once a chunk, for the twin and its band
    for a, b in zip(whole, chunked):
        assert a.dtype == b.dtype and np.array_equal(a, b)



@pytest.mark.parametrize("reach", [None, 2.5], ids=["exact irradiance", "range window"])
def test_a_lights_band_takes_the_irradiance_already_computed(reach, monkeypatch, glphong_make_renderer):
    """`reference.incident_light` hands a point light's band the irradiance it has just computed instead of computing
    it again (`ExactIrradiance`: the twin's value is the band; a range window's generic band: its value at the
    unmoved point, the moved ones computed); both bands equal the kind's band called on its own."""
    light = glphong.PointLight((0.8, -1.0, 2.0), 20.0, range=reach)
    scene = _scene(light, MATERIALS[0])
    gbuffer = glphong_make_renderer(96, 72, "egl").gbuffer(scene)
    calls = []
    incident = glphong.PointLight.incident
    monkeypatch.setattr(glphong.PointLight, "incident", lambda self, x, p: calls.append(x) or incident(self, x, p))
    for _, _, key, u, position, _, _ in reference.shade_inputs(scene, gbuffer):
        p = glphong.PointLight.values_from_uniforms(u, 0, dtype=np.float64, defines=key.lights[0].defines)
        del calls[:]
        expected = glphong.PointLight.twin().band(position, p, BAND)
        alone = len(calls)
        del calls[:]
        (valid, wi, irradiance, band), = reference.incident_light(position, key, u, band=BAND)
        assert np.array_equal(band[0], expected[0]) and np.array_equal(band[1], expected[1])
        # its own call, and the band's less the one at the unmoved point and values (the whole band of the first)
        assert len(calls) == alone
        if reach is None:
            assert alone == 1 and np.array_equal(band[0], irradiance)
