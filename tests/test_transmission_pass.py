"""The transmission pass (glphong.gpu.transmission, docs/transmission.md): the background made on the GPU only as far
as a frame's programs read it, its pyramid the host's bit for bit, frames the path before's bit for bit; a
transmissive scene without a light; the uniforms of transmission in the programs that use it; a file's
diffuseTransmissionTexture saved and loaded back.

Independent checks: the host's pyramid (`background_levels`, numpy float32 with subnormals) and the path before
(``Transmission.method = "host"``: the image read back, that pyramid uploaded); a closed form without a light.
"""
import json
import re

import moderngl
import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.gpu.transmission import TARGET_KEY, PyramidKey, Transmission, background_need
from glphong.materials.gltf_transmission import background_levels
from glphong.scene.geometry import MeshData
from glphong.shaders import assembly
from glphong.shaders.assembly import assemble, effective_source

SIZE = 32  # px; the orthographic view spans [-1, 1] m
K_A = 0.4  # W/(m^2 sr): the floor's own radiance k_a, all there is to see without a light


def _bits(a):
    return np.ascontiguousarray(a, np.float32).view(np.uint32)


def _image(rng, width, height):
    """A float32 RGBA image over many magnitudes: lognormal values, zeros, some signed, blocks whose means are
    subnormal (below 2^-126) and blocks of subnormal texels, texels at 2^60 (the shader's two paths' boundary) and
    3e38 (their sums overflow), infinities, a corner of texels above 2^60 (the shader's plain sums)."""
    image = rng.lognormal(0.0, 4.0, (height, width, 4)).astype(np.float32)
    image[: height // 2, : width // 2] *= np.float32(2.0 ** -120)  # a corner of tiny texels: subnormal means
    image[height // 2:, width // 2:] *= np.float32(2.0 ** 70)  # and one of huge ones (the shader's plain sums)
    flat = image.reshape(-1)
    picks = rng.permutation(flat.size)
    parts = np.array_split(picks, 8)
    flat[parts[0]] = 0.0
    flat[parts[1]] = -flat[parts[1]]
    flat[parts[2]] = rng.uniform(1e-45, 3e-38, parts[2].size).astype(np.float32)  # subnormal and just normal
    flat[parts[3][:8]] = np.float32(2.0 ** 60)
    flat[parts[3][8:16]] = np.float32(3e38)
    flat[parts[3][16:20]] = np.inf
    return image


@pytest.mark.parametrize("width, height", [(37, 23), (64, 64), (1, 13), (100, 3), (6, 1)])
def test_the_gpu_pyramid_is_the_host_pyramid_bit_for_bit(width, height, glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(8, 8, glphong_backend)
    image = _image(np.random.default_rng(width * 1000 + height), width, height)
    with np.errstate(over="ignore", invalid="ignore"):  # the overflowing sums and Inf - Inf, as the GPU makes them
        host = background_levels(image, np.float32)
    subnormal = [np.count_nonzero((np.abs(level) < np.float32(2.0 ** -126)) & (level != 0)) for level in host[1:]]
    assert sum(subnormal) > 0 or min(width, height) == 1 and max(width, height) < 8  # the test reaches them
    with renderer.context:
        mgl = renderer._mgl
        texture = mgl.texture((width, height), 4, image.tobytes(), dtype="f4")
        target = mgl.framebuffer([texture])
        transmission = Transmission(mgl)
        try:
            target.use()
            transmission._gpu_levels(target, (width, height), True, renderer.programs.get(PyramidKey()),
                                     renderer._fullscreen)
            assert len(host) == int(np.log2(max(width, height))) + 1
            for k, level in enumerate(host):
                got = np.frombuffer(transmission._texture.read(level=k), np.float32).reshape(level.shape)
                assert np.array_equal(_bits(got), _bits(level)), (k, np.argwhere(_bits(got) != _bits(level))[:4])
        finally:
            transmission.release()
            renderer.context.release_framebuffer(target)  # and its texture, not left bound


def _scene(glass, light=True, ambient=None, second=None):
    camera = glphong.PerspectiveCamera.look_at((0.4, -2.0, 1.6), (0.0, 0.0, 0.2))
    scene = glphong.Scene(camera, [glphong.PointLight((1.0, -1.0, 2.0), 40.0)] if light else [], ambient=ambient)
    rng = np.random.default_rng(5)
    floor = primitives.plane(3.0, segments=8)
    scene.add(MeshData(floor.positions, floor.normals, floor.indices,
                               colors=rng.uniform(0.1, 1.0, (len(floor.positions), 3))),
              glphong.Lambert(glphong.VertexColors(0.5)), name="floor")
    pose = np.eye(4)
    pose[2, 3] = 0.4
    scene.add(primitives.sphere(3, 0.4), glass, pose=pose, name="glass")
    if second is not None:
        pose = np.eye(4)
        pose[:3, 3] = (0.6, 0.3, 0.3)
        scene.add(primitives.sphere(2, 0.3), second, pose=pose, name="second")
    return scene


def _ramp_texture(factor):
    """``factor`` times a texture's green channel (glTF's metallic-roughness texture's roughness), a ramp 0 to 1."""
    image = np.linspace(0.0, 1.0, 64).reshape(8, 8, 1) * np.ones((1, 1, 3))
    return glphong.Texture(image, factor, srgb=False, channel="g")


GLASS = dict(base_color=(0.9, 0.95, 1.0), metallic=0.0)
CASES = {  # name: (glass, second object, what the pass makes)
    "rough": (glphong.GltfPBR(**GLASS, roughness=0.3, transmission=1.0), None, "pyramid"),
    "smooth": (glphong.GltfPBR(**GLASS, roughness=0.0, transmission=0.9), None, "texel"),
    "rough, ior 1": (glphong.GltfPBR(**GLASS, roughness=0.6, ior=1.0, transmission=1.0), None, "texel"),
    "volume": (glphong.GltfPBR(**GLASS, roughness=0.0, transmission=1.0, thickness=0.3,
                               attenuation_color=(0.9, 0.6, 0.3), attenuation_distance=0.5, dispersion=0.5),
               None, "pyramid"),
    "diffuse transmission": (glphong.GltfPBR(**GLASS, roughness=0.4, diffuse_transmission=0.6), None, "none"),
    "diffuse beside smooth": (glphong.GltfPBR(**GLASS, roughness=0.4, diffuse_transmission=0.6),
                              glphong.GltfPBR(**GLASS, roughness=0.0, transmission=1.0), "texel"),
    "textured roughness": (glphong.GltfPBR(**GLASS, roughness=_ramp_texture(0.5), transmission=1.0), None, "pyramid"),
}


@pytest.mark.parametrize("case", CASES)
def test_frames_are_the_path_befores_bit_for_bit(case, glphong_backend, glphong_make_renderer):
    """Each frame made by the GPU path equals, bit for bit, the frame of the path before (the image read back, its
    pyramid made on the host and every level uploaded), and the pass made only what the frame's programs read."""
    glass, second, made = CASES[case]
    scene = _scene(glass, second=second)
    renderer = glphong_make_renderer(48, 40, glphong_backend)
    frames = {}
    for method in ("host", "gpu", "host", "gpu"):  # each after the other: nothing left from one reaches the next
        with renderer.context:
            renderer.release_targets()
        renderer.render(scene)  # makes the pass's Transmission
        transmission = renderer._targets[TARGET_KEY]
        transmission.method = method
        frames.setdefault(method, []).append(renderer.render(scene).radiance.copy())
        assert transmission.made == ("pyramid" if method == "host" else made)
    assert background_need(scene, 48) == made
    glass_pixels = renderer.render(scene, passes=("instance",)).instance == 2
    assert glass_pixels.sum() > 100
    for frame in frames["gpu"] + frames["host"][1:]:
        assert np.array_equal(_bits(frame), _bits(frames["host"][0])), np.argwhere(_bits(frame) != _bits(frames["host"][0]))[:4]
    if made == "texel":  # level 0 alone: the texture is not filtered through levels never written
        assert renderer._targets[TARGET_KEY]._texture.filter == (moderngl.LINEAR, moderngl.LINEAR)
    if made == "none":  # nothing read: no background at all
        assert renderer._targets[TARGET_KEY].gl_object_count() == 0


def test_a_wrong_pyramid_changes_rough_frames(glphong_make_renderer, monkeypatch):
    """The comparison above can fail: a pyramid of 2x2 means scaled by 0.26 (planted in the pyramid's GLSL, the path
    of every texel below 2^60) changes the rough frame, and not the smooth one (level 0 only)."""
    original = assembly.chunk_source
    old = "(pyramid_scaled(c) + pyramid_scaled(d))) * 0.25;"
    assert original("transmission_pyramid").count(old) == 1
    monkeypatch.setattr(assembly, "chunk_source", lambda name: original(name).replace(old, old.replace("0.25", "0.26"))
                        if name == "transmission_pyramid" else original(name))
    for case, changes in (("rough", True), ("smooth", False)):
        glass, second, _ = CASES[case]
        scene = _scene(glass, second=second)
        renderer = glphong_make_renderer(48, 40, "egl")
        renderer.render(scene)
        renderer._targets[TARGET_KEY].method = "host"
        before = renderer.render(scene).radiance.copy()
        renderer._targets[TARGET_KEY].method = "gpu"
        after = renderer.render(scene).radiance
        assert (not np.array_equal(_bits(before), _bits(after))) == changes, case


@pytest.mark.parametrize("roughness, ior, textured, volume, expected", [
    (0.0, 1.5, False, False, "texel"), (0.5, 1.0, False, False, "texel"), (0.0, 1.5, True, False, "texel"),
    (1e-30, 1.5, False, False, "pyramid"), (0.5, 1.5, True, False, "pyramid"), (0.0, 1.5, False, True, "pyramid")])
def test_what_a_frame_needs_of_the_background(roughness, ior, textured, volume, expected):
    """``lod = log2(W) r clamp(2 ior - 2, 0, 1)``: 0 for roughness 0 (a textured one's factor) or ior 1, above 0 for
    any roughness above 0 at ior 1.5 (float32 keeps 1e-30); a volume looks the background up elsewhere."""
    extra = dict(thickness=0.2) if volume else {}
    rough = _ramp_texture(roughness) if textured else roughness
    glass = glphong.GltfPBR(**GLASS, roughness=rough, ior=ior, transmission=1.0, **extra)
    assert background_need(_scene(glass), 48) == expected
    assert background_need(_scene(glphong.Lambert(0.5)), 48) == "none"


def _quad_over_a_glowing_floor(glass):
    """An orthographic view down -z at a transmissive quad (normal +z) over a Lambert floor that emits ``K_A``, no
    light and no ambient light: the floor is ``K_A`` and the quad lets ``(1 - m) t (1 - f0) c K_A`` through (n.v =
    1; nothing else: no light to reflect, no emission)."""
    camera = glphong.OrthographicCamera.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ymag=1.0)
    scene = glphong.Scene(camera, [])
    scene.add(primitives.plane(4.0), glphong.Lambert(0.6, ka=K_A), name="floor")
    pose = np.eye(4)
    pose[2, 3] = 0.5
    scene.add(primitives.plane(1.0), glass, pose=pose, name="glass")
    return scene


@pytest.mark.parametrize("c, m, t, ior, roughness", [((0.8, 0.9, 1.0), 0.0, 1.0, 1.5, 0.0),
                                                     ((0.3, 0.6, 0.9), 0.3, 0.6, 2.0, 0.0),
                                                     ((0.7, 0.8, 0.9), 0.0, 0.8, 1.5, 0.5)])
def test_a_transmissive_scene_without_a_light_renders_what_lies_behind(c, m, t, ior, roughness, glphong_backend,
                                                                      glphong_make_renderer):
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    scene = _quad_over_a_glowing_floor(glphong.GltfPBR(c, m, roughness, ior=ior, transmission=t))
    frame = renderer.render(scene)
    f0 = ((ior - 1.0) / (ior + 1.0)) ** 2
    inner = frame.radiance[SIZE // 2 - 6:SIZE // 2 + 6, SIZE // 2 - 6:SIZE // 2 + 6].reshape(-1, 3)
    expected = (1.0 - m) * t * (1.0 - f0) * np.asarray(c) * K_A  # a uniform background: any roughness's lookup
    np.testing.assert_allclose(inner, np.broadcast_to(expected, inner.shape), rtol=2e-6)
    np.testing.assert_allclose(frame.radiance[1, 1], K_A, rtol=1e-6)
    report = glphong.verify(scene, renderer)
    assert report.passed and report.transmission.pixels.sum() == (SIZE // 2) ** 2, report.summary()
    diffuse = _quad_over_a_glowing_floor(glphong.GltfPBR(c, m, roughness, diffuse_transmission=0.5))
    inner = renderer.render(diffuse).radiance[SIZE // 2 - 6:SIZE // 2 + 6, SIZE // 2 - 6:SIZE // 2 + 6]
    assert np.all(inner == 0.0)  # nothing of the background, no light to let through: black, as drawn opaque


def test_save_gltf_writes_the_diffuse_transmission_textures(tmp_path):
    """``diffuseTransmissionTexture`` (glTF reads its alpha) and ``diffuseTransmissionColorTexture`` written, so that
    a reader without glphong's ``extras`` (stripped here) loads the same weight and colour, texel for texel."""
    rng = np.random.default_rng(7)
    grey = rng.integers(0, 256, (8, 8), dtype=np.uint8)
    rgb = rng.integers(0, 256, (4, 4, 3), dtype=np.uint8)
    material = glphong.GltfPBR((0.8, 0.7, 0.6), 0.0, 0.5,
                               diffuse_transmission=glphong.Texture(np.stack([grey] * 3, axis=-1), 0.8, srgb=False,
                                                                    channel="r"),
                               diffuse_transmission_color=glphong.Texture(rgb, (0.9, 0.8, 0.7)))
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0)),
                          [glphong.PointLight((1.0, 1.0, 2.0), 10.0)])
    scene.add(primitives.plane(1.0), material, name="leaf")
    path = glphong.save_gltf(scene, tmp_path / "leaf.gltf")
    document = json.loads(path.read_text())
    entry = document["materials"][0]["extensions"]["KHR_materials_diffuse_transmission"]
    assert entry["diffuseTransmissionFactor"] == 0.8 and entry["diffuseTransmissionColorFactor"] == pytest.approx(
        [0.9, 0.8, 0.7])
    assert {"diffuseTransmissionTexture", "diffuseTransmissionColorTexture"} <= set(entry)
    for m in document["materials"]:
        m.pop("extras")
    bare = tmp_path / "bare.gltf"
    bare.write_text(json.dumps(document))
    loaded = glphong.load_scene(bare, light_units="radiometric", lights=[]).objects[0].material
    assert loaded.extensions() == ("diffuse_transmission",)
    weight, color = loaded.diffuse_transmission, loaded.diffuse_transmission_color
    assert weight.scale == pytest.approx(0.8) and weight.channel == "r"
    np.testing.assert_array_equal(weight.texture.levels[0], material.diffuse_transmission.texture.levels[0])
    np.testing.assert_allclose(color.scale, (0.9, 0.8, 0.7))
    np.testing.assert_array_equal(color.texture.levels[0], material.diffuse_transmission_color.texture.levels[0])
    again = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material  # with the extras
    assert again.diffuse_transmission.texture is material.diffuse_transmission.texture


TRANSMISSION_UNIFORMS = {"u_gltf_pbr_transmission", "u_gltf_pbr_thickness", "u_gltf_pbr_attenuation_color",
                         "u_gltf_pbr_attenuation_distance", "u_gltf_pbr_dispersion", "u_gltf_pbr_diffuse_transmission",
                         "u_gltf_pbr_diffuse_transmission_color", "u_transmission_background", "u_transmission_levels"}
VOLUME = dict(thickness=0.3, attenuation_color=(0.9, 0.6, 0.3), attenuation_distance=0.5, dispersion=0.5)


@pytest.mark.parametrize("extensions, declared", [
    ({}, set()),
    (dict(diffuse_transmission=0.5), {"u_gltf_pbr_diffuse_transmission", "u_gltf_pbr_diffuse_transmission_color"}),
    (dict(transmission=1.0), {"u_gltf_pbr_transmission", "u_transmission_background", "u_transmission_levels"}),
    (dict(transmission=1.0, **VOLUME), TRANSMISSION_UNIFORMS - {"u_gltf_pbr_diffuse_transmission",
                                                                 "u_gltf_pbr_diffuse_transmission_color"})])
def test_the_transmission_uniforms_are_declared_only_where_used(extensions, declared, glphong_make_renderer):
    """A program declares the uniforms of KHR_materials_transmission, _volume, _dispersion, _diffuse_transmission and
    the pass's background only where its material uses them (and it draws, and verifies, with them)."""
    scene = _scene(glphong.GltfPBR(**GLASS, roughness=0.2, **extensions))
    renderer = glphong_make_renderer(48, 40, "egl")
    key = renderer.program_key(scene, scene.objects[1])
    text = effective_source(assemble(key.fragment_chunks(), key.defines(), key.generated_chunks(), key.extensions()))
    names = set(re.findall(r"^\s*(?:uniform\s+)?\w+\s+(u_\w+)\s*;", text, re.M))
    assert names & TRANSMISSION_UNIFORMS == declared
    assert glphong.verify(scene, renderer).passed
