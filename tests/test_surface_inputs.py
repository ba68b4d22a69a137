"""Textures and vertex colours as inputs of textureable parameters (glphong/definitions/surface.py).

Independent checks, not the code under test:
- texel decoding against the sRGB formula written here, the pyramid's sizes and means from the
  definition of a box filter, the image's v axis from a one-row marker;
- GPU renders of textured and vertex-coloured meshes under `verify`: every pixel inside the band of
  the twin that samples the same texels at the GPU's level of detail; the band catches a twin that
  samples half a texel off, a level too far or with v flipped (most pixels outside);
- the filtered texture value itself, isolated by an ambient-only Lambert (radiance = scale T L_a):
  its error over the spread of the texels it weights, measured against the band constant T;
- a texture of one colour and vertex colours all equal render as the constant parameter does.
"""
import pickle

import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.scene.geometry import MeshData
from glphong.definitions import surface as surface_module
from glphong.definitions.surface import TextureImage, surface_texture
from glphong.checks.tolerances import BAND, BandConstants


def _srgb_decode(b):
    c = np.asarray(b, dtype=np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


RNG = np.random.default_rng(7)
NOISE = RNG.integers(0, 256, (40, 56, 3), dtype=np.uint8)


def _pose(x=0.0, y=0.0, z=0.0):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def _plane(uv_scale=4.0, colors=None):
    plane = primitives.plane(size=3.0, segments=4)
    return MeshData(plane.positions, plane.normals, plane.indices, uvs=plane.uvs * uv_scale, colors=colors)


def _sphere(colors=None):
    sphere = primitives.sphere(3, 0.5)
    return MeshData(sphere.positions, sphere.normals, sphere.indices, uvs=sphere.uvs,
                    colors=RNG.random((len(sphere.positions), 3)) if colors is None else colors)


def _oblique_scene(material, mesh=None, lights=True, ambient=0.2):
    camera = glphong.PerspectiveCamera.look_at((0.0, -3.0, 1.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), yfov=0.9)
    scene = glphong.Scene(camera, [glphong.PointLight((0.5, -1.0, 2.0), 100.0)] if lights else [],
                          ambient=glphong.AmbientLight(ambient) if ambient else None)
    scene.add(mesh if mesh is not None else _plane(), material)
    return scene


# --------------------------------------------------------------------------- the texture's texels
def test_texels_are_the_decoded_image_bottom_row_first():
    image = TextureImage(NOISE)
    level = image.levels[0]
    assert level.dtype == np.float16 and level.shape == (40, 56, 3)
    np.testing.assert_array_equal(level, _srgb_decode(NOISE[::-1]).astype(np.float16))
    linear = TextureImage(NOISE, srgb=False).levels[0]
    np.testing.assert_array_equal(linear, (NOISE[::-1] / 255.0).astype(np.float16))
    marker = np.zeros((4, 4), np.uint8)
    marker[0] = 255  # the image's top row: v near 1
    top = surface_texture(TextureImage(marker, filter="bilinear", wrap="clamp"), np.array([[0.5, 0.99], [0.5, 0.01]]), [0, 0])
    assert top[0, 0] == 1.0 and top[1, 0] == 0.0


def test_pyramid_sizes_and_means_follow_the_box_filter():
    image = TextureImage(RNG.random((5, 12, 3)).astype(np.float32))
    assert [lv.shape[:2] for lv in image.levels] == [(5, 12), (2, 6), (1, 3), (1, 1)]
    for finer, coarser in zip(image.levels, image.levels[1:]):
        # exact area weights: every level has the mean of the one above (float32 storage)
        np.testing.assert_allclose(coarser.astype(np.float64).mean(axis=(0, 1)),
                                   finer.astype(np.float64).mean(axis=(0, 1)), rtol=1e-6)
    even = TextureImage(np.arange(16, dtype=np.float32).reshape(4, 4), srgb=False)
    np.testing.assert_array_equal(even.levels[1][..., 0], [[10.5, 12.5], [2.5, 4.5]])  # rows bottom first


def test_images_are_interned_pickled_by_value_and_validated(tmp_path):
    from PIL import Image

    assert TextureImage(NOISE) is TextureImage(NOISE.copy())
    assert TextureImage(NOISE) is not TextureImage(NOISE, wrap="clamp")
    again = pickle.loads(pickle.dumps(glphong.Texture(NOISE, scale=0.5)))
    assert again == glphong.Texture(NOISE, scale=0.5)
    path = tmp_path / "noise.png"
    Image.fromarray(NOISE).save(path)
    assert TextureImage(path) == TextureImage(NOISE)
    with pytest.raises(ValueError, match="float image is taken as linear"):
        TextureImage(np.zeros((2, 2), np.float32), srgb=True)
    with pytest.raises(ValueError, match="wrap must be one of 'repeat', 'clamp'"):
        TextureImage(NOISE, wrap="mirror")
    with pytest.raises(ValueError, match="missing.png: no such file"):
        TextureImage(tmp_path / "missing.png")


def test_parameters_check_textures_and_vertex_colours():
    with pytest.raises(TypeError, match="q takes a constant .* does not declare it textureable"):
        glphong.Phong(0.2, 0.3, q=glphong.Texture(NOISE))
    with pytest.raises(ValueError, match=r"rho_d must be in \[0, 1\] everywhere"):
        glphong.Diffuse(rho_d=glphong.Texture(NOISE, scale=2.0))
    with pytest.raises(ValueError, match="scale"):
        glphong.Lambert(kd=glphong.VertexColors(scale=-1.0))
    with pytest.raises(glphong.materials.MaterialDefinitionError, match="only rgb and scalar parameters can be"):
        glphong.Param("d", "direction", low=-np.inf, textureable=True)
    assert glphong.Diffuse(rho_d=glphong.Texture(NOISE)).rho_d.texture == TextureImage(NOISE)
    # a scalar parameter reads one channel, an rgb one all three
    with pytest.raises(ValueError, match="roughness is a scalar: .* need the channel"):
        glphong.GltfPBR(0.5, 0.0, glphong.Texture(NOISE, srgb=False))
    with pytest.raises(ValueError, match="base_color is rgb"):
        glphong.GltfPBR(glphong.Texture(NOISE, channel="g"), 0.0, 0.5)
    with pytest.raises(ValueError, match="channel must be one of"):
        glphong.Texture(NOISE, channel="a")
    with pytest.raises(ValueError, match=r"roughness must be in \[0, 1\] everywhere"):
        glphong.GltfPBR(0.5, 0.0, glphong.Texture(NOISE, scale=1.5, srgb=False, channel="g"))
    one_channel = np.zeros((2, 2, 3), np.uint8)
    one_channel[..., 1] = 255  # green full, the others 0: its range is the green channel's
    assert glphong.Texture(one_channel, srgb=False, channel="g").value_range() == (1.0, 1.0)
    assert glphong.Texture(one_channel, srgb=False, channel="b").value_range() == (0.0, 0.0)


# --------------------------------------------------------------------------- GPU against the twin
CASES = {
    "phong kd texture": lambda: (glphong.Phong(kd=glphong.Texture(NOISE, scale=0.3), ks=0.2, q=20.0), _plane()),
    "phong ks texture, clamp, bilinear": lambda: (
        glphong.Phong(kd=0.05, ks=glphong.Texture(NOISE, scale=0.5, wrap="clamp", filter="bilinear"), q=8.0),
        _plane(uv_scale=1.5)),
    "lambert vertex colours": lambda: (glphong.Lambert(kd=glphong.VertexColors(0.3)), _sphere()),
    "texture times vertex colours": lambda: (glphong.Lambert(kd=glphong.Texture(NOISE, 0.25, vertex_colors=True)), _sphere()),
    "oren-nayar rho, float texture": lambda: (
        glphong.OrenNayar(rho=glphong.Texture(RNG.random((33, 17)).astype(np.float32)), sigma=0.3), _plane()),
    "mtl kd and ks, 16-bit": lambda: (
        glphong.MtlPhong(kd=glphong.Texture((NOISE.astype(np.uint16) * 257), scale=0.3),
                         ks=glphong.Texture(NOISE[::-1], scale=0.2), q=30.0, kamb=0.1), _plane()),
    # scalar parameters read one channel: glTF's metallic-roughness texture (metallic blue, roughness green)
    "gltf metallic-roughness texture": lambda: (
        glphong.GltfPBR(glphong.Texture(NOISE, 0.9), glphong.Texture(NOISE[::-1], srgb=False, channel="b"),
                        glphong.Texture(NOISE[::-1], 0.8, srgb=False, channel="g")), _sphere()),
    "gltf roughness times vertex colours": lambda: (
        glphong.GltfPBR(0.7, 0.2, glphong.Texture(NOISE, 0.9, srgb=False, channel="r", vertex_colors=True)), _sphere()),
}


@pytest.mark.parametrize("case", list(CASES))
def test_textured_renders_verify_on_every_backend(case, glphong_backend, glphong_make_renderer):
    material, mesh = CASES[case]()
    scene = _oblique_scene(material, mesh)
    report = glphong.verify(scene, glphong_make_renderer(160, 120, glphong_backend))
    assert report.covered_pixels > 1000
    assert report.passed, report.summary()


def test_ambient_only_texture_verifies(glphong_backend, glphong_make_renderer):
    scene = _oblique_scene(glphong.Lambert(kd=glphong.Texture(NOISE, scale=0.3)), lights=False, ambient=1.0)
    renderer = glphong_make_renderer(160, 120, glphong_backend)
    key = renderer.program_key(scene, scene.objects[0])
    assert key.num_lights == 0 and key.inputs == (("lambert", "kd", "texture"),)
    assert glphong.verify(scene, renderer).passed


def test_the_band_catches_a_twin_that_reads_the_wrong_channel(monkeypatch, glphong_make_renderer):
    """A twin that reads the red channel where the program reads green is outside the band on most pixels."""
    from glphong.checks import reference

    scene = _oblique_scene(glphong.GltfPBR(0.8, glphong.Texture(NOISE, srgb=False, channel="g"), 0.5), _sphere())
    renderer = glphong_make_renderer(160, 120, "egl")
    assert glphong.verify(scene, renderer).passed
    monkeypatch.setattr(reference, "_channel_of", lambda mode: lambda rgb: rgb[..., 0] if ":" in mode else rgb)
    report = glphong.verify(scene, renderer)
    assert report.outside_count > 0.3 * report.covered_pixels, report.summary()


@pytest.mark.parametrize("mutation", ["half a texel off", "a level too far", "v flipped"])
def test_the_band_catches_a_twin_that_samples_wrong(mutation, monkeypatch, glphong_make_renderer):
    scene = _oblique_scene(glphong.Phong(kd=glphong.Texture(NOISE, scale=0.3), ks=0.2, q=20.0))
    renderer = glphong_make_renderer(160, 120, "egl")
    sample = surface_module._sample
    wrong = {"half a texel off": lambda im, uv, lod: sample(im, uv + 0.5 / np.array(im.size), lod),
             "a level too far": lambda im, uv, lod: sample(im, uv, np.asarray(lod) + 1.0),
             "v flipped": lambda im, uv, lod: sample(im, np.stack([uv[:, 0], 1.0 - uv[:, 1]], axis=1), lod)}
    monkeypatch.setattr(surface_module, "_sample", wrong[mutation])
    report = glphong.verify(scene, renderer)
    assert report.outside_count > 0.5 * report.covered_pixels, report.summary()


def test_filtered_values_against_the_filter_precision_constant(glphong_backend, glphong_make_renderer):
    """Ambient only, L_a = 1: the radiance is scale * T(uv) per pixel, T blending levels 0 to 5."""
    image = TextureImage(NOISE)
    scene = _oblique_scene(glphong.Lambert(kd=glphong.Texture(image)), _plane(uv_scale=12.0), lights=False, ambient=1.0)
    renderer = glphong_make_renderer(200, 150, glphong_backend)
    frame, gbuffer = renderer.render(scene), renderer.gbuffer(scene)
    mask = gbuffer.mask
    uv, lod = gbuffer.uv[mask].astype(np.float64), gbuffer.lod[mask][:, 0].astype(np.float64)
    assert lod.max() > 2.0  # minified over several levels, not just magnified
    value, low, high = surface_module._sample(image, uv, lod)
    error = np.abs(frame.radiance[mask] - value)
    spread = high - low
    ratio = np.max(error - BAND.A * 2.0 ** -24 * high, initial=0.0) / max(float(spread.max()), 1e-30)
    worst = np.max(np.where(spread > 0, (error - BAND.A * 2.0 ** -24 * high) / np.where(spread > 0, spread, 1), 0))
    assert worst <= BAND.T, f"filter error {worst:.3g} of the texel spread exceeds T = {BAND.T}"
    assert ratio <= BAND.T
    # llvmpipe filters float16/float32 texels with float weights: 5.6e-5 measured, far inside 2^-7
    if "llvmpipe" in renderer.context.renderer_name:
        assert worst < 2.0 ** -12


def test_a_tight_band_without_filter_slack_fails(glphong_make_renderer):
    """T = 0 (no allowance for filter weights) rejects some pixels: T is not vacuous."""
    scene = _oblique_scene(glphong.Phong(kd=glphong.Texture(NOISE, scale=0.3), ks=0.2, q=20.0))
    scene.add(_sphere(), glphong.Lambert(kd=glphong.Texture(NOISE, 0.25, vertex_colors=True)), _pose(1.0, 0.0, 0.6))
    renderer = glphong_make_renderer(320, 240, "egl")
    assert glphong.verify(scene, renderer).passed
    assert glphong.verify(scene, renderer, band=BandConstants(T=0.0)).outside_count > 0


def test_uniform_inputs_render_as_the_constant(glphong_backend, glphong_make_renderer):
    grey = np.full((8, 8, 3), 0.6, np.float32)
    constant = _oblique_scene(glphong.Phong(kd=np.float32(0.6) * np.float32(0.3), ks=0.2, q=20.0))
    textured = _oblique_scene(glphong.Phong(kd=glphong.Texture(grey, scale=0.3), ks=0.2, q=20.0))
    colours = np.full((len(_plane().positions), 3), 0.6)
    coloured = _oblique_scene(glphong.Phong(kd=glphong.VertexColors(0.3), ks=0.2, q=20.0), _plane(colors=colours))
    renderer = glphong_make_renderer(120, 90, glphong_backend)
    reference = renderer.render(constant).radiance
    for scene in (textured, coloured):
        np.testing.assert_allclose(renderer.render(scene).radiance, reference, rtol=2e-6, atol=1e-9)


def test_vertex_colours_shade_per_vertex_too(glphong_make_renderer):
    colours = np.full((len(_plane().positions), 3), 0.5)
    coloured = _oblique_scene(glphong.Lambert(kd=glphong.VertexColors(0.2)), _plane(colors=colours))
    constant = _oblique_scene(glphong.Lambert(kd=0.1))
    renderer = glphong_make_renderer(80, 60, "egl", shading="vertex")
    np.testing.assert_allclose(renderer.render(coloured).radiance, renderer.render(constant).radiance, rtol=1e-6)


# --------------------------------------------------------------------------- what is refused, and why
def test_refusals_name_the_parameter_and_the_way_out(glphong_make_renderer):
    textured = glphong.Lambert(kd=glphong.Texture(NOISE))
    scene = _oblique_scene(textured)
    with pytest.raises(ValueError, match="lambert.kd are textured, which needs per-pixel shading"):
        glphong_make_renderer(40, 30, "egl", shading="vertex").render(scene)
    with pytest.raises(ValueError, match="uber-shader holds constant parameters only.*specialise=True"):
        glphong_make_renderer(40, 30, "egl", specialise=False).render(scene)
    bare = MeshData(_plane().positions, _plane().normals, _plane().indices)
    with pytest.raises(ValueError, match="lambert.kd is textured, but the mesh has no UVs"):
        _oblique_scene(textured, bare)
    with pytest.raises(ValueError, match="lambert.kd takes vertex colours, but the mesh has none"):
        _oblique_scene(glphong.Lambert(kd=glphong.VertexColors()), bare)
    with pytest.raises(ValueError, match="vary over the surface"):
        from glphong.shaders.key import response_key

        response_key(textured)
    with pytest.raises(ValueError, match=r"colors must be linear values in \[0, 1\]"):
        MeshData(bare.positions, bare.normals, bare.indices, colors=np.full((len(bare.positions), 3), 2.0))


def test_programs_leave_out_what_no_input_needs(glphong_make_renderer):
    renderer = glphong_make_renderer(40, 30, "egl")
    plain = _oblique_scene(glphong.Lambert(kd=0.2))
    key = renderer.program_key(plain, plain.objects[0])
    assert not key.has_uv and not key.has_color and not key.inputs
    assert any("surface.glsl" in line for line in key.left_out())
    coloured = _oblique_scene(glphong.Lambert(kd=glphong.VertexColors()), _sphere())
    key = renderer.program_key(coloured, coloured.objects[0])
    assert key.has_color and not key.has_uv and "surface" not in key.shading_chunks()
    assert "in_color" in key.attributes()
    gbuffer = renderer.gbuffer(coloured)
    assert gbuffer.color is not None and gbuffer.lod is None and gbuffer.uv is None


def test_trimesh_vertex_colours_are_decoded_from_srgb():
    import trimesh

    box = trimesh.creation.box()
    box.visual.vertex_colors = np.tile([255, 128, 0, 255], (len(box.vertices), 1)).astype(np.uint8)
    data = MeshData.from_trimesh(box)
    np.testing.assert_allclose(data.colors[0], _srgb_decode([255, 128, 0]).astype(np.float32))
    flat = MeshData.from_trimesh(box, smooth=False)
    assert flat.colors.shape == (len(flat.positions), 3)


class FiveInputs(glphong.MaterialModel):
    """A user's model with five textureable parameters: the mechanism the built-ins use, nothing else."""

    name = "five_inputs"
    params = tuple(glphong.Param(f"c{i}", "rgb", low=0.0, default=0.05, textureable=True) for i in range(5))
    glsl = """
vec3 five_inputs_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    return (u_five_inputs_c0 + u_five_inputs_c1 + u_five_inputs_c2 + u_five_inputs_c3 + u_five_inputs_c4) * n_dot_l;
}
"""

    def response(self, f, wi, wo, n_dot_l, p):
        return (p.c0 + p.c1 + p.c2 + p.c3 + p.c4) * n_dot_l[:, None]


def test_a_users_model_textures_four_sizes_and_is_refused_a_fifth(glphong_make_renderer):
    images = [RNG.integers(0, 256, (8 + i, 12, 3), dtype=np.uint8) for i in range(5)]
    four = FiveInputs(**{f"c{i}": glphong.Texture(images[i], 0.05) for i in range(4)}, c4=glphong.VertexColors(0.05))
    scene = _oblique_scene(four, _plane(colors=RNG.random((len(_plane().positions), 3))))
    renderer = glphong_make_renderer(120, 90, "egl")
    report = glphong.verify(scene, renderer)
    assert report.passed and report.covered_pixels > 3000
    assert renderer.gbuffer(scene).lod.shape == (90, 120, 4)
    five = FiveInputs(**{f"c{i}": glphong.Texture(images[i], 0.05) for i in range(5)})
    with pytest.raises(ValueError, match="at most 4 sizes .* has 5"):
        renderer.gbuffer(_oblique_scene(five))
    # five textures of one size share one level of detail (textureQueryLOD depends on the size, not the texels)
    alike = FiveInputs(**{f"c{i}": glphong.Texture(images[0][::1 if i % 2 else -1, ::1 if i < 3 else -1], 0.05)
                          for i in range(5)})
    scene = _oblique_scene(alike)
    assert renderer.program_key(scene, scene.objects[0], "gbuffer").lod_textures == 1
    report = glphong.verify(scene, renderer)
    assert report.passed and report.covered_pixels > 3000, report.summary()


@pytest.mark.parametrize("scale", [1e-8, 1e8])
def test_sixty_decades_of_texels_verify(scale, glphong_make_renderer):
    """A float texture with texels from 1e-30 to 1e30 (times 1e-8 or 1e8: products down to 1e-38, up to 1e38)."""
    hdr = (10.0 ** RNG.uniform(-30, 30, (32, 32, 3))).astype(np.float32)
    scene = _oblique_scene(glphong.Lambert(kd=glphong.Texture(hdr, scale=scale)))
    report = glphong.verify(scene, glphong_make_renderer(120, 90, "egl"))
    assert report.passed and report.nonfinite_count == 0, report.summary()
