"""Tangent-space normal maps (glphong.NormalMap, glsl/normal_map.glsl; glTF's normalTexture).

Independent checks:
- `surface_normal`, the GLSL function, against its twin on float32 inputs (the probe), and the twin against the
  formula ``normalize(t s m.x + b s m.y + n m.z)``, ``m = 2 texel - 1``, written here;
- a plane whose normal map holds one texel renders as the same plane whose vertex normals are that texel's normal,
  computed here in numpy from the 8-bit value (nothing of glphong's twin);
- the G-buffer's mapped normal against the twin of the geometric frame (a G-buffer without the map) and the
  texture sampled by the twin, to the filter's precision; a twin that reads v flipped is far off;
- a normal-mapped sphere verifies on every backend (the shading with the mapped normal is the twin's).
"""
import numpy as np
import pytest

import glphong
from glphong import primitives, reference
from glphong.testing import probe
from glphong.definitions.surface import TextureImage, surface_texture
from glphong.scene.geometry import MeshData

RNG = np.random.default_rng(26)
#: a noisy normal map, z at least 0.1 (texels near the surface's plane, not behind it)
NOISE = RNG.integers(0, 256, (24, 24, 3), dtype=np.uint8)
NOISE[..., 2] = np.maximum(NOISE[..., 2], 141)


def _formula(n, t, b, texel, scale):
    m = 2.0 * np.asarray(texel, np.float64) - 1.0
    p = t * (scale * m[:, :1]) + b * (scale * m[:, 1:2]) + n * m[:, 2:3]
    return p / np.linalg.norm(p, axis=1, keepdims=True)


def test_surface_normal_glsl_against_twin_and_formula(session_gl):
    n = np.tile([0.0, 0.0, 1.0], (200, 1))
    t = np.tile([1.0, 0.0, 0.0], (200, 1))
    b = np.tile([0.0, 1.0, 0.0], (200, 1))
    texel = RNG.random((200, 3)).astype(np.float32)
    scale = RNG.uniform(-2, 2, 200).astype(np.float32)
    gpu = probe.evaluate(session_gl, "surface_normal", n=n, t=t, b=b, texel=texel, scale=scale)["return"]
    twin = reference.surface_normal(n, t, b, texel.astype(np.float64), scale.astype(np.float64))
    np.testing.assert_allclose(twin, _formula(n, t, b, texel, scale[:, None]), rtol=0, atol=1e-14)
    np.testing.assert_allclose(gpu, twin, rtol=0, atol=4e-7)
    flat = reference.surface_normal(n[:1], t[:1], b[:1], np.array([[0.5, 0.5, 0.5]]), 0.0)  # p = 0: n kept
    np.testing.assert_array_equal(flat, n[:1])


def _plane(normals=None):
    plane = primitives.plane(size=2.0, segments=2)
    return MeshData(plane.positions, plane.normals if normals is None else normals, plane.indices, uvs=plane.uvs,
                    tangents=plane.tangents)


def _scene(material, mesh):
    camera = glphong.PerspectiveCamera.look_at((0.3, -0.4, 2.5), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), yfov=0.7)
    scene = glphong.Scene(camera, [glphong.PointLight((0.6, 0.4, 1.5), 30.0)])
    scene.add(mesh, material)
    return scene


def test_a_constant_normal_map_tilts_the_plane(glphong_backend, glphong_make_renderer):
    texel = np.array([200, 90, 220], np.uint8)
    plane = _plane()
    m = 2.0 * (texel / 255.0) - 1.0  # what the map holds, decoded here
    frame_t, frame_n = plane.tangents[0, :3], plane.normals[0]
    stored = (texel / 255.0).astype(np.float16).astype(np.float64)  # 8-bit texels are kept as float16 (surface.py)
    tilted = _formula(frame_n[None], frame_t[None], np.cross(frame_n, frame_t)[None] * plane.tangents[0, 3],
                      stored[None], 0.7)[0]
    material = glphong.GltfPBR(0.7, 0.0, 0.45)
    mapped = glphong.GltfPBR(0.7, 0.0, 0.45, normal_map=glphong.NormalMap(np.tile(texel, (4, 4, 1)), 0.7))
    renderer = glphong_make_renderer(64, 64, glphong_backend)
    ours = renderer.render(_scene(mapped, plane))
    expected = renderer.render(_scene(material, _plane(np.tile(tilted, (len(plane.positions), 1)))))
    assert ours.mask.sum() > 2000 and abs(m[0]) > 0.5
    np.testing.assert_allclose(ours.radiance[ours.mask], expected.radiance[ours.mask], rtol=2e-5, atol=1e-7)
    # and it differs from the unmapped plane
    assert np.abs(renderer.render(_scene(material, plane)).radiance - ours.radiance).max() > 0.05 * ours.radiance.max()


@pytest.mark.parametrize("flipped", [False, True])
def test_gbuffer_normal_is_the_twins_mapped_normal(flipped, glphong_make_renderer):
    """bilinear (one level: the level of detail does not matter); the geometric frame from a G-buffer without the map."""
    image = TextureImage(NOISE, srgb=False, filter="bilinear")
    sphere = primitives.sphere(3, 0.6)
    renderer = glphong_make_renderer(96, 96, "egl")
    mapped = renderer.gbuffer(_scene(glphong.Lambert(0.2, normal_map=glphong.NormalMap(image, 0.9)), sphere))
    plain = renderer.gbuffer(_scene(glphong.Lambert(0.2, normal_map=glphong.NormalMap(np.full((2, 2, 3), 128, np.uint8), 0.0)),
                                    sphere))
    mask = mapped.mask
    n, tangent, uv = (a[mask].astype(np.float64) for a in (plain.normal, plain.tangent, plain.uv))
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    t, b = reference.frame_from_tangent(n, tangent)
    at = np.stack([uv[:, 0], 1.0 - uv[:, 1]], 1) if flipped else uv
    twin = reference.surface_normal(n, t, b, surface_texture(image, at, np.zeros(len(uv))), 0.9)
    angle = np.arccos(np.clip(np.sum(twin * mapped.normal[mask], axis=1), -1.0, 1.0))
    if flipped:  # a twin that samples the map upside down is far off almost everywhere
        assert np.mean(angle > 0.05) > 0.5
    else:  # the filter's weight precision on texels that differ by up to 1 (llvmpipe: 4.9e-4 rad measured)
        assert mask.sum() > 2000 and angle.max() < 5e-3, angle.max()


def test_normal_mapped_sphere_verifies(glphong_backend, glphong_make_renderer):
    material = glphong.GltfPBR(0.8, 0.2, 0.35, normal_map=glphong.NormalMap(NOISE, 1.0))
    scene = _scene(material, primitives.sphere(3, 0.6))
    report = glphong.verify(scene, glphong_make_renderer(96, 96, glphong_backend))
    assert report.covered_pixels > 2000 and report.passed, report.summary()


def test_refusals_name_the_problem(glphong_make_renderer):
    normal_map = glphong.NormalMap(NOISE)
    with pytest.raises(ValueError, match="normal map is linear"):
        glphong.NormalMap(TextureImage(NOISE, srgb=True))
    with pytest.raises(TypeError, match="normal_map must be a glphong.NormalMap"):
        glphong.Lambert(0.2, normal_map=NOISE)
    bare = MeshData(_plane().positions, _plane().normals, _plane().indices)
    with pytest.raises(ValueError, match="normal map, which needs the mesh's UVs"):
        _scene(glphong.Lambert(0.2, normal_map=normal_map), bare)
    scene = _scene(glphong.Lambert(0.2, normal_map=normal_map), _plane())
    with pytest.raises(ValueError, match="normal map, which needs per-pixel shading"):
        glphong.Renderer(32, 32, shading="vertex").render(scene)
    with pytest.raises(ValueError, match="normal map"):
        glphong.Renderer(32, 32, specialise=False).render(scene)
    assert glphong.Lambert(0.2, normal_map=normal_map) == glphong.Lambert(0.2, normal_map=glphong.NormalMap(NOISE))
    assert glphong.Lambert(0.2, normal_map=normal_map) != glphong.Lambert(0.2)


def test_the_program_leaves_the_map_out_where_nothing_is_lit():
    from glphong.shaders.key import program_key

    material = glphong.Lambert(0.2, normal_map=glphong.NormalMap(NOISE))
    lit = program_key(material, {"point": 1}, None)
    assert lit.normal_map and lit.has_tangent and lit.has_uv and "normal_map" in lit.shading_chunks()
    dark = program_key(material, {}, (0.1, 0.1, 0.1))  # ambient only: the normal is not read
    assert not dark.normal_map and not dark.has_tangent and "normal_map" not in dark.shading_chunks()
