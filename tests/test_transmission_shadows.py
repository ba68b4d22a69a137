"""Transmissive surfaces under lights with ``shadows=True`` (issue 41; docs/transmission.md, "Shadows").

The GPU draws every caster into the shadow maps, the glass included (`glphong.gpu.renderer.Renderer._shadow_values`:
``obj.casts_shadow``, True by default, as the glTF Sample Viewer and three.js do): the opaque scene the glass sees
through itself is shaded with those maps, so the floor behind clear glass lies in the glass's own full shadow; the
glass's own lights, in front and behind, take their visibility at the glass.  The twin mirrors it
(`glphong.checks.transmission_twin.transmission_check`): the background shaded in the whole scene (`in_scene`), the
lights behind with the visibility at the surface (`_visible`).

Independent checks, at pixels classified here by float64 segment tests against the box and the glass quad (no code of
glphong's): through clear glass (roughness 0, transmission 1, no ambient light) a floor point in the box's shadow
shows 0 (the glass reflects a point light only along its mirror direction), a lit one the thin wall's closed form
``(1 - m) t (1 - F(n.v)) c B``, Schlick's ``F`` with ``f0 = ((ior - 1)/(ior + 1))^2``, ``B = k_d (n.l) P / (4 pi
d^2)`` the Lambert floor under the point light; with a blended veil in front of the glass, ``a L_veil + (1 - a)`` times
that, ``L_veil`` the Lambert veil's own.  A casting veil in front of the glass and one behind it (in its shadow) pass
`verify`.  Planted errors (the background unshadowed, the glass casting nothing into the background's maps, the lights
behind unshadowed, the veil behind shaded without the glass's shadow) fail `verify`.
"""
import numpy as np
import pytest
import trimesh

import glphong
from glphong import primitives
from glphong.checks import transmission_blend, transmission_twin, verify as verify_module
from glphong.checks.tolerances import BAND

WIDTH, HEIGHT = 48, 40
EYE = np.array([0.0, -2.8, 1.5])
LIGHT = np.array([2.5, -1.6, 2.0])
POWER = 60.0  # W
K_D = 0.6  # the floor's k_d [1/sr]
FLOOR_SIDE = 6.0  # m
BOX_CENTRE, BOX_EXTENTS = np.array([0.3, 0.4, 0.35]), np.array([0.5, 0.5, 0.7])
GLASS_Y, GLASS_CENTRE_Z, GLASS_SIDE = -1.0, 0.65, 1.2  # a vertical quad facing the camera (normal -y)
C, IOR = np.array([0.9, 0.95, 1.0]), 1.5
FACING = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # the quad's +z to -y


def _pose(position, rotation=None):
    pose = np.eye(4)
    pose[:3, :3] = np.eye(3) if rotation is None else rotation
    pose[:3, 3] = position
    return pose


def _scene(glass_casts=True, shadows=True):
    """A Lambert floor (z = 0), an opaque box and a clear glass quad between them and the camera, one point light."""
    camera = glphong.PerspectiveCamera.look_at(EYE, (0.0, 0.4, 0.3), up=(0.0, 0.0, 1.0), yfov=0.9)
    scene = glphong.Scene(camera, [glphong.PointLight(LIGHT, POWER, shadows=shadows)])
    scene.add(primitives.plane(FLOOR_SIDE), glphong.Lambert(K_D), name="floor")
    scene.add(trimesh.creation.box(BOX_EXTENTS), glphong.Lambert(0.5), pose=_pose(BOX_CENTRE), smooth=False,
              name="box")
    scene.add(primitives.plane(GLASS_SIDE), glphong.GltfPBR(C, 0.0, 0.0, ior=IOR, transmission=1.0),
              pose=_pose((0.0, GLASS_Y, GLASS_CENTRE_Z), FACING), name="glass", casts_shadow=glass_casts)
    return scene


def _segment_meets_box(p, q):
    """Whether the segment ``p`` -> ``q`` (3,) meets the box (slab test, float64)."""
    lo, hi = BOX_CENTRE - BOX_EXTENTS / 2, BOX_CENTRE + BOX_EXTENTS / 2
    d = q - p
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (lo - p) / d, (hi - p) / d
    near, far = np.nanmax(np.minimum(t0, t1)), np.nanmin(np.maximum(t0, t1))
    return near <= far and far > 0.0 and near < 1.0


def _square_at(p, q, centre, side):
    """Where the segment ``p`` -> ``q`` meets the plane y = ``centre[1]`` inside the square (facing y) of ``side``
    about ``centre`` (3,), None where it does not (float64)."""
    if (p[1] - centre[1]) * (q[1] - centre[1]) >= 0.0:
        return None
    x = p + (centre[1] - p[1]) / (q[1] - p[1]) * (q - p)
    return x if np.max(np.abs((x - centre)[[0, 2]])) < side / 2 else None


def _segment_meets_glass(p, q):
    return _square_at(p, q, np.array([0.0, GLASS_Y, GLASS_CENTRE_Z]), GLASS_SIDE) is not None


def _classes(glass_points):
    """Per glass pixel (its G-buffer point (3,)): 'box' (the view ray goes on to the box), 'nothing' (beyond the
    floor), 'box shadow', 'glass shadow' (the floor point behind, in that caster's shadow), 'both' or 'lit', with the
    floor point."""
    out = {}
    for pixel, x in glass_points.items():
        v = (x - EYE) / np.linalg.norm(x - EYE)
        if _segment_meets_box(x, x + 10.0 * v):
            out[pixel] = ("box", None)
            continue
        floor = x + v * (-x[2] / v[2])
        if np.max(np.abs(floor[:2])) > FLOOR_SIDE / 2:
            out[pixel] = ("nothing", None)  # beyond the floor: no background
            continue
        in_box, in_glass = _segment_meets_box(floor, LIGHT), _segment_meets_glass(floor, LIGHT)
        out[pixel] = ("box shadow" if in_box and not in_glass else "glass shadow" if in_glass and not in_box else
                      "lit" if not in_box else "both", floor)
    return out


def _thin_wall(x, floor):
    """``(1 - m) t (1 - F(n.v)) c B`` at the glass point ``x`` over the lit floor point ``floor`` (float64)."""
    n = np.array([0.0, -1.0, 0.0])
    v = (EYE - x) / np.linalg.norm(EYE - x)
    f0 = ((IOR - 1.0) / (IOR + 1.0)) ** 2
    fresnel = f0 + (1.0 - f0) * (1.0 - n @ v) ** 5
    to_light = LIGHT - floor
    d = np.linalg.norm(to_light)
    b = K_D * (to_light[2] / d) * POWER / (4.0 * np.pi * d * d)
    return (1.0 - 0.0) * 1.0 * (1.0 - fresnel) * C * b


def _inner(classes, name):
    """The pixels of class ``name`` whose 8 neighbours are of it too."""
    return [(i, j) for (i, j), (c, _) in classes.items() if c == name and all(
        classes.get((i + di, j + dj), ("",))[0] == name for di in (-1, 0, 1) for dj in (-1, 0, 1))]


def test_the_floor_through_glass_is_its_shadowed_closed_form(glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(WIDTH, HEIGHT, glphong_backend)
    scene = _scene()
    frame = renderer.render(scene)
    gbuffer = renderer.gbuffer(scene)
    glass = gbuffer.object_index == 2
    classes = _classes({(i, j): gbuffer.position[i, j].astype(np.float64) for i, j in zip(*np.nonzero(glass))})
    lit, shadowed, glass_shadow = (_inner(classes, c) for c in ("lit", "box shadow", "glass shadow"))
    assert len(lit) > 100 and len(shadowed) >= 4 and len(glass_shadow) >= 4, (len(lit), len(shadowed))
    for i, j in shadowed + glass_shadow:  # the floor gets nothing from the light; clear glass reflects nothing here
        np.testing.assert_array_equal(frame.radiance[i, j], 0.0)
    expected = np.array([_thin_wall(gbuffer.position[i, j].astype(np.float64), classes[i, j][1]) for i, j in lit])
    got = np.array([frame.radiance[i, j] for i, j in lit], np.float64)
    assert expected.min() > 1e-3
    np.testing.assert_allclose(got, expected, rtol=1e-5)
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()
    assert report.transmission.pixels.sum() == glass.sum()
    twin = report.transmission.transmitted
    assert all(np.all(twin[i, j] == 0.0) for i, j in shadowed + glass_shadow)  # the twin's visibility is 0 there
    np.testing.assert_allclose(np.array([twin[i, j] for i, j in lit]), expected, rtol=1e-6)


def _planted_background(monkeypatch, scene_for_background):
    """verify with the transmission check's background shaded in ``scene_for_background`` (same objects in order)."""
    check = verify_module.transmission_check

    def planted(scene, renderer, gbuffer, shade, *rest):
        shadows = renderer.shadow_settings
        return check(scene, renderer, gbuffer,
                     lambda s, g: verify_module.twin_and_band(scene_for_background, g, BAND, shadows), *rest)

    monkeypatch.setattr(verify_module, "transmission_check", planted)


@pytest.mark.parametrize("planted", ["visibility 1", "glass casts nothing"])
def test_a_background_without_the_whole_scene_s_shadows_fails(planted, monkeypatch, glphong_make_renderer):
    renderer = glphong_make_renderer(WIDTH, HEIGHT, "egl")
    scene = _scene()
    assert glphong.verify(scene, renderer).passed
    _planted_background(monkeypatch, _scene(shadows=False) if planted == "visibility 1" else _scene(glass_casts=False))
    report = glphong.verify(scene, renderer)
    assert not report.passed and (report.outside & report.transmission.pixels).sum() >= 4, report.summary()


def _behind_scene(thickness=0.0):
    """A glass quad (roughness 0.3) between the camera and a point light behind it, nearly on the line of sight, a small
    box between the light and the glass casting its shadow on the glass; a floor below.  ``thickness`` > 0: a volume
    (KHR_materials_volume), whose light behind is taken from the exit point, with the visibility at the glass."""
    camera = glphong.PerspectiveCamera.look_at((0.0, -3.0, 0.5), (0.0, 0.0, 0.5), up=(0.0, 0.0, 1.0), yfov=0.8)
    scene = glphong.Scene(camera, [glphong.PointLight((0.0, 1.5, 0.7), 20.0, shadows=True)])
    scene.add(primitives.plane(6.0), glphong.Lambert(K_D), name="floor")
    scene.add(trimesh.creation.box((0.2, 0.2, 0.2)), glphong.Lambert(0.5), pose=_pose((0.05, 0.3, 0.65)),
              smooth=False, name="blocker")
    volume = dict(thickness=thickness, attenuation_color=(0.9, 0.7, 0.5), attenuation_distance=0.5) if thickness else {}
    scene.add(primitives.plane(GLASS_SIDE), glphong.GltfPBR(C, 0.0, 0.3, ior=IOR, transmission=1.0, **volume),
              pose=_pose((0.0, GLASS_Y, 0.6), FACING), name="glass")
    return scene


@pytest.mark.parametrize("thickness", [0.0, 0.05], ids=["thin", "volume"])
def test_the_lights_behind_take_the_visibility_at_the_glass(thickness, glphong_backend, glphong_make_renderer,
                                                            monkeypatch):
    """The blocker's shadow on the glass darkens the light behind it (thin, and seen from a volume's exit point): the
    twin with the visibility passes, the twin without it fails where the shadow falls."""
    renderer = glphong_make_renderer(WIDTH, HEIGHT, glphong_backend)
    scene = _behind_scene(thickness)
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()
    visible = transmission_twin._visible
    monkeypatch.setattr(transmission_twin, "_visible", lambda key, u, band, visibility: visible(key, u, band, None))
    planted = glphong.verify(scene, renderer)
    assert not planted.passed and (planted.outside & planted.transmission.pixels).sum() >= 4, planted.summary()


VEIL_SIDE, VEIL_ALPHA, VEIL_K_D = 0.6, 0.5, 0.5
VEILS = {"in front": np.array([0.2, -1.4, 0.5]),  # between the camera and the glass, facing it (normal -y)
         "behind": np.array([-0.35, -0.8, 0.55])}  # between the glass and the box, in the glass's shadow


def _veil_scene(where):
    """`_scene` plus a blended Lambert veil (alpha 0.5, casting shadows) in front of the glass or behind it."""
    scene = _scene()
    scene.add(primitives.plane(VEIL_SIDE), glphong.Lambert(VEIL_K_D, alpha_blend=glphong.AlphaBlend(VEIL_ALPHA)),
              pose=_pose(VEILS[where], FACING), name="veil")
    return scene


@pytest.mark.parametrize("where", list(VEILS))
def test_verify_twins_a_casting_veil_with_the_glass(where, glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(WIDTH, HEIGHT, glphong_backend)
    scene = _veil_scene(where)
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()
    # the veil's layer seen over the glass (in front) or through it (behind), on >= 100 glass pixels
    gbuffer = renderer.gbuffer(scene)
    seen = [(i, j) for i, j in zip(*np.nonzero(gbuffer.object_index == 2)) if _square_at(
        EYE, EYE + 10.0 * (gbuffer.position[i, j] - EYE), VEILS[where], VEIL_SIDE) is not None]
    assert len(seen) >= 100, len(seen)


def test_a_veil_over_the_glass_is_its_closed_form(glphong_backend, glphong_make_renderer):
    """At glass pixels whose view ray meets the veil in front and then a lit floor point (neither the box, the glass
    nor the veil between it and the light): ``a L_veil + (1 - a) (1 - m) t (1 - F) c B``, the veil's ``L_veil = k_d
    (n.l) P / (4 pi d^2)`` (nothing between it and the light)."""
    renderer = glphong_make_renderer(WIDTH, HEIGHT, glphong_backend)
    scene = _veil_scene("in front")
    frame = renderer.render(scene)
    gbuffer = renderer.gbuffer(scene)
    glass = gbuffer.object_index == 2
    classes = _classes({(i, j): gbuffer.position[i, j].astype(np.float64) for i, j in zip(*np.nonzero(glass))})
    expected, got = [], []
    for i, j in _inner(classes, "lit"):
        x = gbuffer.position[i, j].astype(np.float64)
        veil = _square_at(EYE, EYE + 10.0 * (x - EYE), VEILS["in front"], 0.9 * VEIL_SIDE)  # off its edges
        floor = classes[i, j][1]
        if veil is None or _square_at(floor, LIGHT, VEILS["in front"], 1.1 * VEIL_SIDE) is not None:
            continue
        to_light = LIGHT - veil
        d = np.linalg.norm(to_light)
        lit_veil = VEIL_K_D * (-to_light[1] / d) * POWER / (4.0 * np.pi * d * d)  # its normal -y
        expected.append(VEIL_ALPHA * lit_veil + (1.0 - VEIL_ALPHA) * _thin_wall(x, floor))
        got.append(frame.radiance[i, j])
    assert len(expected) >= 50, len(expected)
    np.testing.assert_allclose(np.array(got, np.float64), np.array(expected), rtol=1e-5)


def test_a_veil_behind_shaded_without_the_glass_s_shadow_fails(monkeypatch, glphong_make_renderer):
    """The veil behind the glass lies in the glass's shadow: its layer in the background twinned in `opaque_scene`
    (the maps without the glass, as before) fails `verify` where the glass shows it."""
    renderer = glphong_make_renderer(WIDTH, HEIGHT, "egl")
    scene = _veil_scene("behind")
    behind = verify_module.layers_behind
    monkeypatch.setattr(transmission_blend, "in_scene", lambda whole, gbuffer: gbuffer)  # opaque_scene's indices
    monkeypatch.setattr(verify_module, "layers_behind", lambda whole, renderer, shade, band: behind(
        whole, renderer, lambda s, g: shade(transmission_twin.opaque_scene(s), g), band))
    report = glphong.verify(scene, renderer)
    assert not report.passed and (report.outside & report.transmission.pixels).sum() >= 50, report.summary()
