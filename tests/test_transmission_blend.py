"""Transmissive and blended surfaces in one frame (issue 41; docs/transmission.md, "With blended surfaces").

Independent checks: an orthographic camera looks down -z (the view spans [-1.2, 1.2] x [-1, 1] m, pixels 0.05 m
square, row 0 at the top) at a Lambert floor (z = 0) lit by a point light, a thin transmissive quad (roughness 0,
transmission 1, metallic 0, ior 1.5; z = 0.5) and a blended Lambert quad of alpha ``A`` (z = 0.25 or 0.75) half under
the glass.  Every quad's edge lies on a pixel boundary.  ``n.v = 1`` everywhere, so the glass transmits
``(1 - m) t (1 - F) c B`` with ``F = f0 = ((ior - 1)/(ior + 1))^2`` and reflects nothing (its diffuse has weight
``1 - t = 0`` and its GGX lobe of roughness 0 is 0 off the mirror direction, which no pixel sees); a Lambert surface at
``x`` sends ``k_d (n.l) Phi / (4 pi d^2)``.  Written here in float64 from those formulas and the "over" operator
``a L + (1 - a) L_behind``:

(a) the blended quad between the floor and the glass: ``(1 - f0) c (A L_q + (1 - A) L_floor)``: the glass sees it in
    its background;
(b) the blended quad in front of the glass: ``A L_q + (1 - A) (1 - f0) c L_floor``: composited over the glass frame
    without it, whose background holds the floor alone (the decal seen once; the glTF Sample Viewer's transmission
    framebuffer would hold it too, and the glass transmit it a second time).
"""
import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.checks.blend_twin import blend_hits
from glphong.gpu.peeling import BlendCapWarning, Peeling
from glphong.gpu.transmission import TARGET_KEY, Transmission

WIDTH, HEIGHT = 48, 40
PIXEL = 0.05  # m
LIGHT = np.array([1.0, 0.9, 3.0])  # m (outside the glass's x and y: no pixel sees the lobe's mirror direction)
POWER = 40.0  # W
K_FLOOR = 0.6  # 1/sr
K_QUAD = np.array([0.2, 0.5, 0.9])  # 1/sr
ALPHA = 0.375  # exact in float32
GLASS_COLOR = np.array([0.8, 0.9, 1.0])
IOR = 1.5
GLASS = (-0.6, 0.6, -0.6, 0.6)  # x0, x1, y0, y1 [m]
QUAD = (0.0, 0.8, -0.4, 0.4)


def _pose(x, z):
    pose = np.eye(4)
    pose[0, 3], pose[2, 3] = x, z
    return pose


def _scene(quad_z, glass=None, quad_alpha=ALPHA):
    camera = glphong.OrthographicCamera.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ymag=1.0)
    scene = glphong.Scene(camera, [glphong.PointLight(LIGHT, POWER)])
    scene.add(primitives.plane(4.0), glphong.Lambert(K_FLOOR), name="floor")
    scene.add(primitives.plane(1.2), glass or glphong.GltfPBR(GLASS_COLOR, 0.0, 0.0, ior=IOR, transmission=1.0),
              pose=_pose(0.0, 0.5), name="glass")
    scene.add(primitives.plane(0.8), glphong.Lambert(K_QUAD, alpha_blend=glphong.AlphaBlend(quad_alpha)),
              pose=_pose(0.4, quad_z), name="decal")
    return scene


def _lambert(k, z):
    """A Lambert surface facing +z at height ``z`` under the light, at every pixel centre: (H, W, 3)."""
    x = -1.2 + (np.arange(WIDTH) + 0.5) * PIXEL
    y = 1.0 - (np.arange(HEIGHT) + 0.5) * PIXEL
    to_light = LIGHT - np.stack(np.broadcast_arrays(x[None, :], y[:, None], np.full((HEIGHT, WIDTH), z)), axis=-1)
    d = np.linalg.norm(to_light, axis=-1)
    irradiance = POWER / (4.0 * np.pi * d ** 2) * to_light[..., 2] / d
    return np.asarray(k, np.float64) * np.ones(3) * irradiance[..., None]


def _inside(box):
    x = -1.2 + (np.arange(WIDTH) + 0.5) * PIXEL
    y = 1.0 - (np.arange(HEIGHT) + 0.5) * PIXEL
    return ((x[None, :] > box[0]) & (x[None, :] < box[1]) & (y[:, None] > box[2]) & (y[:, None] < box[3]))[..., None]


def _closed_form(quad_z):
    """The frame of `_scene` (module docstring), (H, W, 3) float64."""
    f0 = ((IOR - 1.0) / (IOR + 1.0)) ** 2
    weight = (1.0 - 0.0) * 1.0 * (1.0 - f0) * GLASS_COLOR
    floor, quad = _lambert(K_FLOOR, 0.0), _lambert(K_QUAD, quad_z)
    glass, decal = _inside(GLASS), _inside(QUAD)
    over = lambda a, front, behind: a * front + (1.0 - a) * behind  # noqa: E731 - the "over" operator
    if quad_z < 0.5:  # (a): the decal in the glass's background
        background = np.where(decal, over(ALPHA, quad, floor), floor)
        return np.where(glass, weight * background, background)
    frame = np.where(glass, weight * floor, floor)  # (b): the glass frame without the decal, the decal over it
    return np.where(decal, over(ALPHA, quad, frame), frame)


@pytest.mark.parametrize("quad_z", [0.25, 0.75], ids=["behind-glass", "in-front"])
def test_blended_and_transmissive_quads_are_the_closed_form(quad_z, glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(WIDTH, HEIGHT, glphong_backend)
    scene = _scene(quad_z)
    frame = renderer.render(scene)
    expected = _closed_form(quad_z)
    np.testing.assert_allclose(frame.radiance, expected, rtol=1e-5, atol=1e-8)
    assert frame.blend_layers == 1 and frame.blend_cut is None
    # the regions differ: the test sees where the decal went
    behind = (_inside(GLASS) & _inside(QUAD))[..., 0]
    other = _closed_form(0.75 if quad_z < 0.5 else 0.25)
    assert np.all(np.abs(frame.radiance[behind] - other[behind]).max(axis=-1) > 1e-2 * other[behind].max(axis=-1))
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()
    assert report.blend is not None and report.transmission is not None
    assert report.transmission.background_blend is not None and not report.blend.unchecked.any()
    assert report.transmission.pixels.sum() == 24 * 24


def test_a_scene_with_either_alone_draws_as_before(glphong_make_renderer):
    """Where only one of the two covers a pixel, the frame of both is that one's own frame, bit for bit: outside the
    glass the scene without the glass (the peel's composite alone), outside the decal the scene without the decal
    (drawn without a background peel: nothing blended in it)."""
    renderer = glphong_make_renderer(WIDTH, HEIGHT, "egl")
    scene = _scene(0.25)
    without_decal = glphong.Scene(scene.camera, scene.lights)
    without_glass = glphong.Scene(scene.camera, scene.lights)
    for obj in scene.objects:
        for out, drop in ((without_decal, "decal"), (without_glass, "glass")):
            if obj.name != drop:
                out.add(obj.mesh, obj.material, obj.pose, name=obj.name)
    glass_only = renderer.render(without_decal).radiance
    decal_only = renderer.render(without_glass).radiance
    assert renderer._targets[TARGET_KEY].blend is None
    both = renderer.render(scene).radiance
    outside = ~_inside(GLASS)[..., 0]
    np.testing.assert_array_equal(both[outside], decal_only[outside])  # no glass there: the peel's composite alone
    np.testing.assert_array_equal(both[~_inside(QUAD)[..., 0]], glass_only[~_inside(QUAD)[..., 0]])


def test_the_host_path_composites_the_same_background(glphong_make_renderer):
    """A rough glass reads the background's pyramid: the GPU's and the host's (Transmission.method) agree bit for bit
    with the decal composited into level 0."""
    renderer = glphong_make_renderer(WIDTH, HEIGHT, "egl")
    scene = _scene(0.25, glass=glphong.GltfPBR(GLASS_COLOR, 0.0, 0.4, ior=IOR, transmission=1.0))
    frames = {}
    for method in ("gpu", "host"):
        renderer.render(scene)
        renderer._targets[TARGET_KEY].method = method
        frames[method] = renderer.render(scene).radiance.copy()
        assert renderer._targets[TARGET_KEY].blend[0] == 1
    np.testing.assert_array_equal(frames["gpu"], frames["host"])
    report = glphong.verify(scene, renderer)
    assert report.passed and report.transmission.rough.any(), report.summary()


def test_diffuse_transmission_alone_peels_no_background(glphong_make_renderer):
    """KHR_materials_diffuse_transmission reads no background: nothing of it is made, its peel included."""
    renderer = glphong_make_renderer(WIDTH, HEIGHT, "egl")
    scene = _scene(0.25, glass=glphong.GltfPBR(GLASS_COLOR, 0.0, 0.3, diffuse_transmission=0.7))
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()
    transmission = renderer._targets[TARGET_KEY]
    assert transmission.made == "none" and transmission.blend is None


def test_a_blended_quad_crossing_a_glass_sphere_verifies(glphong_backend, glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.4, -2.0, 1.6), (0.0, 0.0, 0.3))
    scene = glphong.Scene(camera, [glphong.PointLight((1.0, -1.0, 2.0), 40.0)])
    scene.add(primitives.plane(3.0, segments=4), glphong.Lambert(0.5), name="floor")
    scene.add(primitives.sphere(3, 0.4), glphong.GltfPBR((0.9, 0.95, 1.0), 0.0, 0.0, transmission=1.0),
              pose=_pose(0.0, 0.4), name="glass")
    pose = np.eye(4)  # upright, turned 60 degrees about z, through the sphere's axis and out of it toward the camera
    c, s = np.cos(np.pi / 3), np.sin(np.pi / 3)
    pose[:3, :3] = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ [[1, 0, 0], [0, 0, -1], [0, 1, 0]]
    pose[:3, 3] = (0.0, 0.0, 0.65)
    scene.add(primitives.plane(1.2), glphong.Lambert((0.9, 0.3, 0.2), alpha_blend=glphong.AlphaBlend(0.5)), pose=pose,
              name="pane")
    renderer = glphong_make_renderer(WIDTH, HEIGHT, glphong_backend)
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()
    behind = report.transmission.background_blend.layers > 0
    over = blend_hits(scene, WIDTH, HEIGHT).count[0] > 0  # the layers in front of the glass and the floor
    # the pane is seen both ways: through the glass (in the background only) and over it
    glass = report.transmission.pixels
    assert (glass & behind & ~over).sum() > 20 and (glass & over).sum() > 20
    assert report.blend.unchecked.sum() < 0.05 * report.mask.sum()


def test_the_background_peel_cut_is_the_frames(glphong_make_renderer):
    """blend_layers=1 and two decals behind the glass (overlapping on 8 x 8 pixels): the background's peel cuts those
    pixels (the frame's peel sees no layer there), the frame says so, and verify's twin cuts the same."""
    scene = _scene(0.25)
    scene.add(primitives.plane(0.4), glphong.Lambert(0.3, alpha_blend=glphong.AlphaBlend(0.5)), pose=_pose(0.2, 0.1))
    renderer = glphong_make_renderer(WIDTH, HEIGHT, "egl", blend_layers=1)
    with pytest.warns(BlendCapWarning, match="64 pixels"):
        frame = renderer.render(scene)
    expected = _inside((0.0, 0.4, -0.2, 0.2))[..., 0]
    np.testing.assert_array_equal(frame.blend_cut, expected)
    with pytest.warns(BlendCapWarning):
        report = glphong.verify(scene, renderer)
    assert report.passed and report.blend_cut_mismatch == 0 and report.blend.cut.sum() == 64, report.summary()


def test_a_background_without_its_layers_fails_verify(monkeypatch, glphong_make_renderer):
    """Planted: the background the opaque image alone (the layers not composited into it): verify fails where the
    glass shows the decal."""
    composite = Transmission._composite
    monkeypatch.setattr(Transmission, "_composite", lambda self, target, size, mipmaps, peel: composite(
        self, target, size, mipmaps, lambda *arguments: None))
    report = glphong.verify(_scene(0.25), glphong_make_renderer(WIDTH, HEIGHT, "egl"))
    assert not report.passed and report.outside.sum() == 12 * 16, report.summary()


def test_a_surface_both_transmissive_and_blended_is_refused(glphong_make_renderer):
    glass = glphong.GltfPBR(GLASS_COLOR, 0.0, 0.0, transmission=1.0, alpha_blend=glphong.AlphaBlend(0.5))
    with pytest.raises(ValueError, match="'glass' is transmissive and blended"):
        glphong_make_renderer(WIDTH, HEIGHT, "egl").render(_scene(0.25, glass=glass))


def test_a_texture_and_a_renderbuffer_of_one_glo_get_their_own_framebuffers():
    """GL names textures and renderbuffers apart, so a peel texture and the blit's scratch renderbuffer may share a
    glo; one framebuffer for both made the blit copy the scratch colour over the cleared peel target, which then peeled
    the first layer twice (seen after other renderers had come and gone: the background's blend_layers 2 for one
    decal)."""
    made = []

    class Context:
        def framebuffer(self, colors, depth):
            made.append((tuple(colors), depth))
            return type("Framebuffer", (), {})()

    texture = type("Texture", (), {"glo": 9})()
    renderbuffer = type("Renderbuffer", (), {"glo": 9})()
    depth = type("Renderbuffer", (), {"glo": 3})()
    peeling = Peeling(Context())
    assert peeling._framebuffer(texture, depth, write=True) is not peeling._framebuffer(renderbuffer, depth, write=True)
    assert peeling._framebuffer(texture, depth, write=True) is peeling._framebuffer(texture, depth, write=True)
    assert [colors[0] for colors, _ in made] == [texture, renderbuffer]
