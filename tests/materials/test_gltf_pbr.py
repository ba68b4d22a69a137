"""glTF 2.0's metallic-roughness material (glphong.GltfPBR) against an independent float64 implementation of the
specification's Appendix B, written here from its formulas and sharing nothing with glphong:

``D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)``, ``V = 1 / (2 (|n.v| sqrt(alpha^2 + (1 - alpha^2)(n.l)^2) +
|n.l| sqrt(alpha^2 + (1 - alpha^2)(n.v)^2)))``, ``metal = (c + (1 - c)(1 - |v.h|)^5) V D``, ``dielectric = mix(c/pi,
V D, 0.04 + 0.96 (1 - |v.h|)^5)``, ``f_r = mix(dielectric, metal, metallic)``, ``alpha = roughness^2``.
"""
import numpy as np
import pytest

import glphong
from glphong.materials import ShadingFrame
from glphong.testing import assert_twin_matches, evaluate
from glphong.shaders.binding import binding

Z = np.array([0.0, 0.0, 1.0])


def appendix_b(n, l, v, base_color, metallic, roughness, f0=0.04):
    """f_r (n.l) by the specification's formulas, float64, (N, 3); ``f0`` the dielectric's (KHR_materials_ior)."""
    h = l + v
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    nl, nv, nh, vh = (np.sum(a * b, -1) for a, b in ((n, l), (n, v), (n, h), (v, h)))
    alpha = roughness ** 2
    a2 = alpha ** 2
    d = a2 / (np.pi * (nh ** 2 * (a2 - 1) + 1) ** 2)
    vis = 1 / (2 * (np.abs(nv) * np.sqrt(a2 + (1 - a2) * nl ** 2) + np.abs(nl) * np.sqrt(a2 + (1 - a2) * nv ** 2)))
    x = (1 - np.abs(vh)) ** 5
    c = np.asarray(base_color, np.float64)[None, :]
    metal = (c + (1 - c) * x[:, None]) * (vis * d)[:, None]
    fd = (f0 + (1 - f0) * x)[:, None]
    dielectric = (c / np.pi) * (1 - fd) + (vis * d)[:, None] * fd
    return ((1 - metallic) * dielectric + metallic * metal) * nl[:, None]


def _pairs(count, seed, max_angle=1.45):
    rng = np.random.default_rng(seed)

    def direction():
        t, p = rng.uniform(0, max_angle, count), rng.uniform(0, 2 * np.pi, count)
        return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)

    return direction(), direction()


def _twin(material, l, v):
    n = np.broadcast_to(Z, l.shape).astype(np.float64)
    term = material.components[0]
    return term.response(ShadingFrame(n), l, v, np.sum(n * l, -1), term.values())


@pytest.mark.parametrize("metallic", [0.0, 0.4, 1.0])
@pytest.mark.parametrize("roughness", [0.05, 0.3, 0.7, 1.0])
def test_twin_equals_the_specification_in_float64(metallic, roughness):
    color = (0.9, 0.5, 0.1)
    material = glphong.GltfPBR(base_color=color, metallic=metallic, roughness=roughness)
    l, v = _pairs(500, seed=int(100 * roughness) + int(10 * metallic))
    expected = appendix_b(np.broadcast_to(Z, l.shape), l, v, np.float32(color).astype(float),
                          float(np.float32(metallic)), float(np.float32(roughness)))
    np.testing.assert_allclose(_twin(material, l, v), expected, rtol=1e-11, atol=1e-300)


@pytest.mark.parametrize("roughness", [0.05, 0.3, 1.0])
def test_gpu_equals_the_specification(roughness, glphong_backend):
    material = glphong.GltfPBR(base_color=(0.9, 0.5, 0.1), metallic=0.5, roughness=roughness)
    l, v = _pairs(400, seed=7, max_angle=1.3)
    l32, v32 = l.astype(np.float32).astype(float), v.astype(np.float32).astype(float)
    l32 /= np.linalg.norm(l32, axis=1, keepdims=True)
    v32 /= np.linalg.norm(v32, axis=1, keepdims=True)
    gpu = evaluate(material, l, v, backend=glphong_backend).astype(np.float64)
    expected = appendix_b(np.broadcast_to(Z, l.shape), l32, v32, np.float32((0.9, 0.5, 0.1)).astype(float), 0.5,
                          float(np.float32(roughness)))
    rel = np.abs(gpu - expected) / np.max(expected, axis=1, keepdims=True)
    assert np.all(np.isfinite(gpu)) and rel.max() < {0.05: 2e-3, 0.3: 2e-5, 1.0: 1e-5}[roughness], rel.max()
    assert_twin_matches(material, n=500, backend=glphong_backend)


def test_roughness_zero_and_tiny_are_finite(glphong_backend):
    """Roughness 0: D is 0 off the mirror direction and at it (the delta, which a point light meets with zero
    measure); 1e-4: the peak D = 1/(pi alpha^2) = 3.2e15 is finite.  Never NaN."""
    l = np.array([[0.5, 0.0, np.sqrt(0.75)], [0.5, 0.0, np.sqrt(0.75)]])
    v = np.array([[-0.5, 0.0, np.sqrt(0.75)], [-0.45, 0.1, np.sqrt(1 - 0.45 ** 2 - 0.01)]])
    for roughness in (0.0, 1e-4):
        material = glphong.GltfPBR(base_color=0.5, metallic=1.0, roughness=roughness)
        twin = _twin(material, l, v)
        gpu = evaluate(material, l, v, backend=glphong_backend)
        assert np.all(np.isfinite(twin)) and np.all(np.isfinite(gpu))
        if roughness == 0.0:
            assert np.all(twin == 0) and np.all(gpu == 0)  # a metal reflects only its specular part
    # at the mirror direction h = n: D = 1/(pi alpha^2), V (n.l) = 1/(4 n.v), F = 1 for a white metal (the
    # specification's denominator (n.h)^2 (alpha^2 - 1) + 1 cancels to alpha^2 = 1e-16 there: float64 cannot form
    # it from a rounded n.h, the closed form can)
    a2 = float(np.float32(1e-4)) ** 4
    expected = 1 / (np.pi * a2) / (4 * np.sqrt(0.75))
    peak = _twin(glphong.GltfPBR(base_color=1.0, metallic=1.0, roughness=1e-4), l[:1], v[:1])
    np.testing.assert_allclose(peak, expected, rtol=1e-12)
    gpu = evaluate(glphong.GltfPBR(base_color=1.0, metallic=1.0, roughness=1e-4), l[:1], v[:1], backend=glphong_backend)
    np.testing.assert_allclose(gpu, expected, rtol=1e-5)


def test_declaration():
    material = glphong.GltfPBR(base_color=(0.2, 0.3, 0.4), metallic=0.25, roughness=0.5)
    assert material.components[0].name == "gltf_pbr"
    assert glphong.GltfPBR().metallic == 1.0 and glphong.GltfPBR().roughness == 1.0  # glTF's defaults
    with pytest.raises(ValueError, match="roughness"):
        glphong.GltfPBR(roughness=1.5)
    with pytest.raises(ValueError, match="base_color"):
        glphong.GltfPBR(base_color=(2.0, 0.0, 0.0))


# --------------------------------------------------------------------------- emission, occlusion, textures
def _front_scene(material, lights=(), ambient=None, size=(64, 48)):
    """A plane facing the camera, filling the view; returns (scene, renderer, covered pixels' radiance)."""
    from glphong import primitives
    from glphong.scene.geometry import MeshData

    plane = primitives.plane(size=4.0, segments=2)
    mesh = MeshData(plane.positions, plane.normals, plane.indices, uvs=plane.uvs)
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), yfov=0.6)
    scene = glphong.Scene(camera, list(lights), ambient=None if ambient is None else glphong.AmbientLight(ambient))
    scene.add(mesh, material)
    return scene


def test_emission_alone_is_the_emissive_radiance(glphong_backend, glphong_make_renderer):
    """No light, no ambient: every covered pixel is emissiveFactor times its strength, exactly (float32)."""
    emissive = (0.25, 1.5, 3.0)  # a strength above 1 (KHR_materials_emissive_strength)
    scene = _front_scene(glphong.GltfPBR(0.5, 0.0, 0.5, emissive=emissive))
    renderer = glphong_make_renderer(64, 48, glphong_backend)
    frame = renderer.render(scene)
    covered = frame.mask
    assert covered.sum() > 1000
    np.testing.assert_array_equal(frame.radiance[covered], np.broadcast_to(np.float32(emissive), (covered.sum(), 3)))
    key = renderer.program_key(scene, scene.objects[0])
    assert key.num_lights == 0 and key.terms[0].emission == "emissive" and not key.terms[0].lit


def test_occlusion_scales_the_ambient_answer_only(glphong_backend, glphong_make_renderer):
    """Ambient only: L = occlusion base_color / pi L_a (pyrender's base_color ambient, glphong's irradiance
    convention); a point light's term is not occluded."""
    base, occlusion, la = np.array([0.8, 0.4, 0.2]), 0.25, 2.0
    renderer = glphong_make_renderer(64, 48, glphong_backend)
    ambient_only = renderer.render(_front_scene(glphong.GltfPBR(base, 0.0, 0.5, occlusion=occlusion), ambient=la))
    expected = occlusion * np.float32(base) / np.pi * la
    covered = ambient_only.mask
    np.testing.assert_allclose(ambient_only.radiance[covered], np.broadcast_to(expected, (covered.sum(), 3)), rtol=1e-6)
    light = glphong.PointLight((0.3, 0.2, 2.0), 50.0)
    occluded = renderer.render(_front_scene(glphong.GltfPBR(base, 0.0, 0.5, occlusion=occlusion), [light]))
    clear = renderer.render(_front_scene(glphong.GltfPBR(base, 0.0, 0.5), [light]))
    np.testing.assert_array_equal(occluded.radiance, clear.radiance)


def test_what_a_scene_does_not_need_is_left_out():
    """Emission only where it is not zero; occlusion only where the term answers an ambient light."""
    from glphong.shaders.key import program_key

    lights = [glphong.PointLight((0.0, 0.0, 2.0), 10.0)]
    plain = program_key(glphong.GltfPBR(0.5, 0.0, 0.5, occlusion=0.5), lights, None).terms[0]
    assert plain.emission is None and plain.occlusion is None and plain.lit
    both = program_key(glphong.GltfPBR(0.5, 0.0, 0.5, emissive=0.1, occlusion=0.5), lights, (0.1,) * 3).terms[0]
    assert both.emission == "emissive" and both.occlusion == "occlusion" and both.ambient
    texture = glphong.Texture(np.full((2, 2), 128, np.uint8), srgb=False, channel="r")
    unlit = program_key(glphong.GltfPBR(0.5, 0.0, 0.5, occlusion=texture), lights, None).terms[0]
    assert unlit.inputs == ()  # the occlusion texture is neither sampled nor bound without an ambient light


@pytest.mark.parametrize("inputs", ["metallic-roughness", "occlusion and emissive"])
def test_textured_gltf_material_verifies(inputs, glphong_backend, glphong_make_renderer):
    rng = np.random.default_rng(3)
    image = rng.integers(0, 256, (24, 24, 3), dtype=np.uint8)
    if inputs == "metallic-roughness":
        material = glphong.GltfPBR(glphong.Texture(image, 0.9), glphong.Texture(image, srgb=False, channel="b"),
                                   glphong.Texture(image, 0.9, srgb=False, channel="g"))
    else:
        material = glphong.GltfPBR(0.6, 0.3, 0.5, emissive=glphong.Texture(image, 0.2),
                                   occlusion=glphong.Texture(image[::-1], srgb=False, channel="r"))
    scene = _front_scene(material, [glphong.PointLight((0.5, 0.5, 1.5), 20.0)], ambient=0.5)
    report = glphong.verify(scene, glphong_make_renderer(96, 72, glphong_backend))
    assert report.covered_pixels > 3000 and report.passed, report.summary()


def test_every_gltf_texture_verifies_with_one_level_of_detail_per_size(glphong_backend, glphong_make_renderer):
    """Five textured inputs (base colour, metallic, roughness, emissive, occlusion) from four images of two sizes:
    the G-buffer records two levels of detail, and every pixel is inside the band."""
    from glphong.shaders.key import program_key

    rng = np.random.default_rng(4)
    big, small = (rng.integers(0, 256, (n, n, 3), dtype=np.uint8) for n in (32, 16))
    material = glphong.GltfPBR(glphong.Texture(big, 0.9), glphong.Texture(small, srgb=False, channel="b"),
                               glphong.Texture(small, 0.9, srgb=False, channel="g"),
                               emissive=glphong.Texture(big[::-1], 0.1), occlusion=glphong.Texture(small[::-1], srgb=False, channel="r"))
    scene = _front_scene(material, [glphong.PointLight((0.5, 0.5, 1.5), 20.0)], ambient=0.5)
    lights, ambient = binding(scene).light_keys(), scene.ambient_radiance
    assert len(program_key(material, lights, ambient).textured_inputs) == 5
    assert program_key(material, lights, ambient, output="gbuffer", gbuffer_needs={"uv", "lod"}).lod_textures == 2
    report = glphong.verify(scene, glphong_make_renderer(96, 72, glphong_backend))
    assert report.covered_pixels > 3000 and report.passed, report.summary()


@pytest.mark.parametrize("ior", [1.5, 1.33, 2.4])
def test_ior_sets_the_dielectric_f0(ior):
    """KHR_materials_ior: f0 = ((ior - 1)/(ior + 1))^2 in the Fresnel mix (1.5 is the core's 0.04)."""
    material = glphong.GltfPBR(base_color=(0.3, 0.6, 0.9), metallic=0.2, roughness=0.4, ior=ior)
    l, v = _pairs(300, seed=int(10 * ior))
    ior32 = float(np.float32(ior))
    expected = appendix_b(np.broadcast_to(Z, l.shape), l, v, np.float32((0.3, 0.6, 0.9)).astype(float),
                          float(np.float32(0.2)), float(np.float32(0.4)), f0=((ior32 - 1) / (ior32 + 1)) ** 2)
    np.testing.assert_allclose(_twin(material, l, v), expected, rtol=1e-11, atol=1e-300)



def test_occlusion_darkens_the_environment_light(glphong_backend, glphong_make_renderer):
    """The surroundings: an environment light's reflection is multiplied by the occlusion (a constant: the whole image
    scales by it, bit for bit up to one rounding), a textured occlusion verifies; an area light's is not."""
    from glphong.shaders.key import program_key

    sky = np.ones((8, 16, 3)) * np.array([0.3, 0.5, 0.9])
    sky[:2] = 3.0
    renderer = glphong_make_renderer(64, 48, glphong_backend)

    def frame(material, light):
        return renderer.render(_front_scene(material, [light])).radiance

    environment = glphong.EnvironmentLight(sky)
    clear, dark = (frame(glphong.GltfPBR(0.7, 0.2, 0.5, occlusion=o), environment) for o in (1.0, 0.25))
    np.testing.assert_allclose(dark, 0.25 * clear, rtol=2e-7, atol=0)
    assert clear.max() > 0.05
    rect = glphong.RectLight((0.0, 0.0, 2.0), (0.5, 0.0, 0.0), (0.0, -0.5, 0.0), radiance=20.0)
    np.testing.assert_array_equal(frame(glphong.GltfPBR(0.7, 0.2, 0.5, occlusion=0.25), rect),
                                  frame(glphong.GltfPBR(0.7, 0.2, 0.5), rect))
    texture = glphong.Texture(np.random.default_rng(8).integers(0, 256, (16, 16, 3), dtype=np.uint8), srgb=False,
                              channel="r")
    scene = _front_scene(glphong.GltfPBR(0.7, 0.2, 0.5, occlusion=texture), [environment])
    report = glphong.verify(scene, renderer, exact=False)  # the twin's band; the exact integral is not the point here
    assert report.covered_pixels > 2000 and report.passed, report.summary()
    assert program_key(glphong.GltfPBR(0.5, 0.0, 0.5, occlusion=0.5), [environment], None).terms[0].occlusion == "occlusion"
    assert program_key(glphong.GltfPBR(0.5, 0.0, 0.5, occlusion=0.5), [rect], None).terms[0].occlusion is None


# --------------------------------------------------------------------------- the derived band (gltf_pbr_band)
def _float32_twin(term, n, l, v):
    """The twin run in float32 on the directions rounded to float32 and normalised in float32: the GLSL's formula
    with a float32 rounding at every step, its inputs a few ulps off the float64 ones, as the GPU's are."""
    from glphong.definitions.params import ParamValues

    n32, l32, v32 = (np.asarray(a, np.float32) for a in (n, l, v))
    l32 = l32 / np.sqrt(np.sum(l32 * l32, -1, keepdims=True))
    v32 = v32 / np.sqrt(np.sum(v32 * v32, -1, keepdims=True))
    values = term.values()
    p32 = ParamValues({k: np.float32(x) if isinstance(x, (float, np.floating, np.ndarray)) else x
                       for k, x in values.__dict__.items()})
    return term.response(ShadingFrame(n32), l32, v32, np.sum(n32 * l32, -1), p32).astype(np.float64)


@pytest.mark.parametrize("metallic", [0.0, 0.5, 1.0])
@pytest.mark.parametrize("roughness", [1e-3, 0.05, 0.3, 1.0])
def test_the_derived_band_holds_the_formula_in_float32(metallic, roughness):
    """`gltf_pbr_band` holds every value of the float32 formula (`_float32_twin`), grazing light and view included,
    and is narrow: a relative 1e-4 off the twin lies outside it at nearly every pair off the lobe's sharpest part."""
    from glphong.materials.gltf_pbr import gltf_pbr_band
    from glphong.twin.band import BAND, EPS

    term = glphong.GltfPBR((0.9, 0.5, 0.1), metallic, roughness, ior=1.4).components[0]
    l, v = _pairs(20000, seed=int(1000 * roughness) + int(10 * metallic), max_angle=1.5707)
    n = np.broadcast_to(Z, l.shape).astype(np.float64)
    p = term.values()
    n_dot_l = np.sum(n * l, -1)
    low, high = gltf_pbr_band(n, l, v, n_dot_l, p, BAND)
    gpu_like = _float32_twin(term, n, l, v)
    decided = (n_dot_l > BAND.D * EPS)[:, None] & (gpu_like > 0)
    assert decided.sum() > 30000
    assert np.all((low <= gpu_like)[decided]) and np.all((gpu_like <= high)[decided])
    twin = term.response(ShadingFrame(n), l, v, n_dot_l, p)
    caught = ((twin * (1 + 1e-4) > high) & (twin * (1 - 1e-4) < low))[decided]
    assert caught.mean() > (0.97 if roughness >= 0.05 else 0.5), caught.mean()


def _spot_scene(material):
    from glphong import primitives

    camera = glphong.PerspectiveCamera.look_at((0.0, -1.2, 1.5), (0.0, 0.0, 0.45), up=(0.0, 0.0, 1.0))
    pose = np.eye(4)
    pose[2, 3] = 0.5
    scene = glphong.Scene(camera, [glphong.SpotLight((1.2, -0.2, 1.2), (-1.2, 0.2, -0.7), 20.0, 0.5, 0.9)])
    scene.add(primitives.sphere(4, radius=0.5), material, pose=pose)
    return scene


PLANTED = {  # (chunk, text, planted text): each a relative 1e-4 or a wrong power, in the GLSL only
    "GGX D 1e-4 too large": ("microfacet", "(min(r, FLT_MAX) * MICROFACET_INV_PI)",
                             "(min(r, FLT_MAX) * (1.0001 * MICROFACET_INV_PI))"),
    "V (n.l) 1e-4 too large": ("model", "return n_dot_l / (2.0", "return 1.0001 * n_dot_l / (2.0"),
    "Schlick's x to the fourth": ("model", "float x = (x1 * x1) * (x1 * x1) * x1;", "float x = (x1 * x1) * (x1 * x1);"),
    "the diffuse part 1e-4 too large": ("model", "(c * (GLTF_PBR_INV_PI * n_dot_l))",
                                        "(c * (1.0001 * GLTF_PBR_INV_PI * n_dot_l))"),
}


@pytest.mark.parametrize("planted", sorted(PLANTED))
def test_planted_errors_fail(planted, monkeypatch, glphong_make_renderer):
    """A GltfPBR sphere under a spot light (the scene passes unplanted on both backends:
    test_the_spot_lit_sphere_verifies)."""
    from glphong.shaders import assembly

    chunk, old, new = PLANTED[planted]
    if chunk == "model":
        original = assembly.model_source
        source = original(glphong.materials.gltf_pbr.GltfPBR)
        assert old in source[0]
        monkeypatch.setattr(assembly, "model_source", lambda cls: (source[0].replace(old, new),) + tuple(source[1:])
                            if cls is glphong.materials.gltf_pbr.GltfPBR else original(cls))
    else:
        original = assembly.chunk_source
        source = original(chunk)
        assert old in source
        monkeypatch.setattr(assembly, "chunk_source", lambda name: source.replace(old, new) if name == chunk
                            else original(name))
    report = glphong.verify(_spot_scene(glphong.GltfPBR((0.8, 0.5, 0.2), 0.5, 0.4)),
                            glphong_make_renderer(64, 64, "egl"))
    assert not report.passed and report.outside_count > 0, report.summary()


@pytest.mark.parametrize("roughness", [0.02, 0.4, 1.0])
def test_the_spot_lit_sphere_verifies(roughness, glphong_backend, glphong_make_renderer):
    report = glphong.verify(_spot_scene(glphong.GltfPBR((0.8, 0.5, 0.2), 0.5, roughness)),
                            glphong_make_renderer(64, 64, glphong_backend))
    assert report.covered_pixels > 900 and report.passed, report.summary()
