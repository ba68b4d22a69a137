"""`glphong.checks.verify.twin_and_band` shades each object's pixels in chunks of `TWIN_CHUNK` (docs/speed.md,
"Verify against the render"): every pixel's arithmetic is its own, so the twin, its band and the shadow band are
those of shading the whole object at once, bit for bit (an environment light with its samples, a rect light, a
shadowing spot light; Phong, Blinn-Phong, Lambert and GltfPBR)."""
import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.checks import verify


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
