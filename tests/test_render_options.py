"""Rendering options: Gouraud shading, multisampling, supersampling, 8-bit GPU encoding, primitives."""

import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.imaging import encode_srgb8


@pytest.fixture(params=("egl", "osmesa"))
def backend(request):
    return request.param


def sphere_scene(material=None, subdivisions=4):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, lights=[glphong.PointLight((2.0, 2.0, 3.0), 150.0)], ambient=glphong.AmbientLight(0.02))
    scene.add(primitives.sphere(subdivisions), material or glphong.Phong(0.2, 0.6, 40.0))
    return scene


def test_primitives_have_exact_normals():
    s = primitives.sphere(3, radius=2.0)
    np.testing.assert_allclose(np.linalg.norm(s.positions, axis=1), 2.0, rtol=1e-6)
    np.testing.assert_allclose(s.normals, s.positions / 2.0, atol=1e-6)
    assert s.triangle_count == 20 * 4 ** 3 and primitives.sphere(3, radius=2.0) is s
    p = primitives.plane(2.0, 3)
    assert p.triangle_count == 18 and np.all(p.normals == (0, 0, 1)) and np.ptp(p.positions[:, 0]) == 2.0
    with pytest.raises(ValueError, match="subdivisions must be in \\[0, 8\\]"):
        primitives.sphere(9)


def test_gouraud_misses_narrow_highlights_and_is_exact_for_linear_radiance(backend, make_renderer):
    """Gouraud interpolates vertex radiance: too dim inside a highlight narrower than a triangle, exact
    where the radiance is linear across triangles; it runs shade_point() in the vertex stage."""
    scene = sphere_scene(glphong.Phong(0.2, 0.8, 500.0), subdivisions=2)
    pixel = make_renderer(96, 80, backend)
    vertex = make_renderer(96, 80, backend, shading="vertex")
    a, b = pixel.render(scene), vertex.render(scene)
    assert "shading='vertex'" in repr(vertex)
    np.testing.assert_array_equal(a.mask, b.mask)
    assert np.abs(b.radiance - a.radiance)[a.mask].max() > 0.1 * a.radiance.max()  # the highlight differs
    assert b.radiance.max() < 0.9 * a.radiance.max()  # q=500 peak missed between coarse vertices
    with pytest.raises(ValueError, match="shading='pixel'"):
        glphong.verify(scene, vertex)
    # where the radiance is linear in the triangle (an unlit ambient-only object) Gouraud is exact
    flat = glphong.Scene(scene.camera, ambient=glphong.AmbientLight(0.5))
    flat.add(primitives.sphere(2), glphong.Lambert(0.3))
    np.testing.assert_allclose(vertex.render(flat).radiance, pixel.render(flat).radiance, rtol=1e-5)  # interpolation ulps
    assert [k.shade_per_vertex for k in vertex.programs.keys() if k.output == "radiance"] == [True, True]


def test_msaa_changes_only_silhouettes(backend, make_renderer):
    scene = sphere_scene(subdivisions=2)  # triangles much larger than pixels
    single = make_renderer(96, 80, backend)
    multi = make_renderer(96, 80, backend, samples=4)
    a, b = single.render(scene), multi.render(scene)
    interior = a.mask & (b.coverage == 1.0)
    edge = b.mask & (b.coverage < 1.0)
    assert edge.sum() > 50 and interior.sum() > 1000
    assert set(np.unique(a.coverage)) <= {0.0, 1.0} and 0 < b.coverage[edge].min() < 1
    rel = np.max(np.abs(b.radiance - a.radiance)[interior] / np.maximum(a.radiance[interior], 1e-6), axis=-1)
    # one evaluation per pixel and triangle: identical except on pixels crossed by a triangle edge,
    # where the fragments of both triangles (evaluated at the pixel centre) are averaged
    assert np.mean(rel < 1e-5) > 0.75 and np.percentile(rel, 95) < 0.01
    with pytest.raises(ValueError, match="samples=1"):
        glphong.verify(scene, multi)


def test_samples_beyond_the_context_limit_are_refused(make_renderer):
    with pytest.raises(ValueError, match="samples must be at most this context's GL_MAX_SAMPLES"):
        make_renderer(8, 8, "egl", samples=8)
    with pytest.raises(ValueError, match="samples must be one of"):
        glphong.Renderer(8, 8, samples=3)


def test_supersampling_is_the_box_filter_of_a_larger_render(backend, make_renderer):
    scene = sphere_scene()
    small = make_renderer(48, 40, backend, supersample=2)
    large = make_renderer(96, 80, backend)
    a, b = small.render(scene), large.render(scene)
    expected = b.radiance.reshape(40, 2, 48, 2, 3).mean(axis=(1, 3))
    np.testing.assert_allclose(a.radiance, expected, rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(a.coverage, b.coverage.reshape(40, 2, 48, 2).mean(axis=(1, 3)))
    assert a.radiance.shape == (40, 48, 3)


@pytest.mark.parametrize("options", [{}, {"samples": 4}, {"supersample": 2}])
def test_gpu_srgb8_matches_numpy_encoding(backend, options, make_renderer):
    scene = sphere_scene()
    r = make_renderer(96, 80, backend, **options)
    frame = r.render(scene)
    gpu = r.render_srgb8(scene, exposure=2.0, resolve="linear")
    cpu = encode_srgb8(frame.radiance, 2.0)
    assert gpu.dtype == np.uint8 and gpu.shape == (80, 96, 3)
    diff = np.abs(gpu.astype(int) - cpu.astype(int))
    assert diff.max() <= 1 and (diff == 0).mean() > 0.97
    assert gpu.max() == 255 and gpu[0, 0].tolist() == [0, 0, 0]
    with pytest.raises(ValueError, match="exposure must be"):
        r.render_srgb8(scene, exposure=0.0)


def test_options_survive_resize_without_leaks(backend, make_renderer):
    r = make_renderer(96, 80, backend, samples=4, supersample=2)
    scene = sphere_scene()
    r.render(scene)
    r.render_srgb8(scene)
    count = r.gl_object_count()
    r.resize(40, 30)
    assert r.render(scene).radiance.shape == (30, 40, 3) and r.render_srgb8(scene).shape == (30, 40, 3)
    r.resize(96, 80)
    r.render(scene)
    r.render_srgb8(scene)
    assert r.gl_object_count() == count
    r.context.check_error("resize")


@pytest.mark.parametrize("samples", [1, 4])
def test_srgb8_display_resolve(backend, samples, make_renderer):
    """'display' (default) encodes in the shading pass: with one sample the very bytes of the linear path;
    with 4x MSAA interior pixels within one step, silhouettes averaged as display values (darker than
    the encoded linear average where a lit surface meets the black background); vertex shading and
    supersampling take the linear path."""
    scene = sphere_scene()
    r = make_renderer(96, 80, backend, samples=samples)
    display, linear = r.render_srgb8(scene, 2.0), r.render_srgb8(scene, 2.0, resolve="linear")
    coverage = r.render(scene).coverage
    if samples == 1:
        assert np.array_equal(display, linear)
    else:
        diff = display.astype(int) - linear.astype(int)
        assert np.abs(diff[coverage == 1.0]).max() <= 1
        edge = (coverage > 0) & (coverage < 1) & (linear.max(axis=-1) > 20)
        # the mean of encoded values lies below the encoded mean: x^(1/2.4) is concave
        assert edge.sum() > 20 and (diff[edge].min(axis=-1) < -1).mean() > 0.5
    vertex = make_renderer(96, 80, backend, samples=samples, shading="vertex")
    assert np.array_equal(vertex.render_srgb8(scene), vertex.render_srgb8(scene, resolve="linear"))
    with pytest.raises(ValueError, match="resolve must be"):
        r.render_srgb8(scene, resolve="gamma")
