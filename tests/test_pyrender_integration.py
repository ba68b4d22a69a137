"""glphong materials inside pyrender scenes, on pyrender's EGL and OSMesa platforms.

pyrender fixes its OpenGL platform once per process, so each platform runs
`pyrender_embedding_check.py` in a subprocess that reports its measurements as JSON.
"""
import importlib.util
from pathlib import Path

import numpy as np
import pytest

if importlib.util.find_spec("pyrender") is None:  # find_spec: importing pyrender here would fix its platform
    pytest.skip("pyrender is not installed (pip install 'glphong[pyrender]')", allow_module_level=True)

CHECK = Path(__file__).with_name("pyrender_embedding_check.py")


@pytest.fixture(scope="module", params=("egl", "osmesa"))
def measured(request, pyrender_check):
    return request.param, pyrender_check(CHECK, request.param, timeout=300)


def test_image_agrees_with_glphong_renderer(measured):
    platform, m = measured
    assert m["interior_pixels"] > 3000
    assert m["interior_max_diff"] <= 1  # one 8-bit step after the same sRGB encoding
    assert m["interior_exact_fraction"] > (0.9 if platform == "egl" else 0.999)
    assert m["silhouette_pixels"] > 100  # compared apart, not hidden in the interior
    assert m["second_frame_identical"]


def test_pyrender_materials_render_beside_glphong_ones(measured):
    _, m = measured
    assert m["pbr_pixels"] > 200 and m["pbr_green"] > 60  # pyrender's own PBR sphere, in green


def test_same_chunks_and_keys_as_glphong(measured):
    _, m = measured
    # Lambert, Phong, Blinn, the measured table, the textured plane (a texture, its uv at pyrender's location 2:
    # the primitive has no tangents) and the vertex-coloured sphere; the second frame compiled and uploaded nothing
    assert m["programs"] == 6 and m["compiled"] == 6 and m["textures"] == 2 and m["texture_uploads"] == 2
    assert all(k.startswith("display") for k in m["keys"])
    # identical shading chunks; the display output only appends the sRGB chunk before the stage file
    expected = sorted(tuple(c[:-1]) + ("srgb", c[-1]) for c in map(tuple, m["glphong_chunks"]))
    assert [tuple(c) for c in m["pyrender_chunks"]] == expected


def test_light_units(measured):
    _, m = measured
    # pyrender stores colours as float32
    np.testing.assert_allclose(m["point_power"], 4 * np.pi * 25.0 * np.array([1.0, 0.9, 0.8]), rtol=1e-7)
    np.testing.assert_allclose(m["directional"], -np.array(m["directional_expected"]), atol=1e-12)
    np.testing.assert_allclose(m["directional_irradiance"], 0.8 * np.array([0.6, 0.7, 1.0]), rtol=1e-7)
    np.testing.assert_allclose(m["ambient"], 0.03, rtol=1e-7)


def test_spot_light_maps(measured):
    """pyrender's SpotLight: cd taken as W/sr along the node's -Z axis, its cone angles as given."""
    _, m = measured
    spot = m["spot"]
    assert spot["kind"] == "SpotLight"
    np.testing.assert_allclose(spot["position"], [1.0, 2.0, 3.0])
    np.testing.assert_allclose(spot["direction"], [0.0, 0.0, -1.0], atol=1e-12)
    np.testing.assert_allclose(spot["intensity"], 2.0 * np.array([1.0, 0.5, 0.25]), rtol=1e-7)
    np.testing.assert_allclose(spot["cones"], [0.2, 0.7], rtol=1e-7)


def test_refusals_name_the_problem(measured):
    _, m = measured
    assert "cannot be instanced" in m["instanced"]
    assert "not enabled on" in m["not_enabled"] and "enable(renderer)" in m["not_enabled"]
    assert "blends (alpha_blend)" in m["blended"] and "glphong.Renderer" in m["blended"]
    assert "transmits (KHR_materials_transmission)" in m["transmissive"]
    assert "transmits (KHR_materials_diffuse_transmission)" in m["diffuse_transmissive"]


def test_metallic_roughness_material_converts_to_gltf_pbr(measured):
    """gltf_pbr_of: the factors as given; metallic and roughness read the blue and green channels pyrender keeps
    (its 'GB' texture), occlusion the red; the base colour sRGB; drawn inside pyrender as a GlphongMaterial, it
    agrees with glphong's renderer on the interior."""
    _, m = measured
    c = m["converted"]
    assert c["type"] == "GltfPBR" and c["two_sided"] is True
    assert c["metallic"] == ["b", 0.75] and c["roughness"] == ["g", 0.5]
    assert c["metallic_texels"] and c["roughness_texels"] and c["occlusion_texels"]
    np.testing.assert_allclose(c["emissive"], [0.1, 0.2, 0.3], rtol=1e-7)
    np.testing.assert_allclose(c["base_scale"], [0.5, 0.25, 1.0])
    assert c["base_srgb"] == "srgb8"
    assert c["embedded_pixels"] > 2000 and c["embedded_within_one"] > 0.9, c


def test_non_indexed_primitives_and_the_vertex_colour_message(measured):
    """Mesh.from_trimesh(..., smooth=False) has no indices: scene_from_pyrender draws consecutive triples (80
    triangles of an icosphere), and the embedded frame agrees with glphong's renderer; a material that takes vertex
    colours on a primitive pyrender built without them names the fix."""
    _, m = measured
    n = m["non_indexed"]
    assert n["indices"] and n["triangles"] == 320
    assert n["pixels"] > 2000 and n["within_one"] > 0.9, n
    assert "color_0" in n["vertex_colours"] and "pyrender.Primitive(" in n["vertex_colours"]



def test_the_frame_passes_of_a_pyrender_scene(measured):
    """A pyrender scene gives the frame passes through scene_from_pyrender (docs/data_for_training.md): an id for each
    node's primitive, and a depth pass that is pyrender's own depth on the pixels inside one object: without
    multisampling (OSMesa) to its 24-bit depth buffer's resolution (measured 1.4e-5 relative); on EGL pyrender draws
    with 4 samples and its depth is one of them, off the pixel centre by up to half a pixel (measured 4.4e-3 where a
    sphere slopes away)."""
    platform, m = measured
    passes = m["passes"]
    assert passes["instances"] == list(range(passes["objects"] + 1))
    assert passes["depth_pixels"] > 5000 and passes["depth_max_relative"] < (1e-2 if platform == "egl" else 1e-4)
