"""Renderer, G-buffer, program cache and pixel parity with the float64 twin (docs/design.md section 7, layers 2 and 5)."""
import gc
import re

import numpy as np
import pytest
import trimesh

import glphong
from glphong.shaders.key import ProgramKey, program_key, uber_key
from glphong.gpu.programs import Program, ShaderCompileError, UniformError
from glphong.shaders.assembly import name_chunks as _name_chunks
from glphong.shaders.binding import binding

BACKENDS = ("egl", "osmesa")


@pytest.fixture(scope="module", params=BACKENDS)
def renderer(request, module_make_renderer):
    return module_make_renderer(96, 80, request.param)


def translation(x, y, z):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def mixed_lights():
    return [
        glphong.PointLight((2.0, 2.5, 3.0), (80.0, 60.0, 40.0)),
        glphong.PointLight((-3.0, -1.0, 2.0), 30.0),
        glphong.UnattenuatedPointLight((0.0, 4.0, 1.0), (0.3, 0.2, 0.1)),
        glphong.DirectionalLight((-0.2, -0.3, -1.0), 0.7),
    ]


def material_scene(material, smooth=True, lights=None):
    camera = glphong.PerspectiveCamera.look_at((0.3, 0.8, 3.2), (0.0, 0.0, 0.0), yfov=0.9)
    scene = glphong.Scene(camera, lights=mixed_lights() if lights is None else lights,
                          ambient=glphong.AmbientLight((0.05, 0.04, 0.03)))
    scene.add(trimesh.creation.icosphere(3), material, smooth=smooth)
    scene.add(trimesh.creation.box((4.0, 0.1, 4.0)), material, pose=translation(0, -1.1, 0), smooth=False)
    return scene


MATERIALS = {
    "lambert": glphong.Lambert(kd=(0.3, 0.2, 0.1), ka=0.01),
    "phong": glphong.Phong(kd=(0.2, 0.1, 0.05), ks=(0.5, 0.6, 0.7), q=60.0),
    "blinn": glphong.BlinnPhong(kd=0.1, ks=0.8, q=400.0, ka=(0.0, 0.01, 0.02)),
    "phong_one_sided": glphong.Phong(kd=0.2, ks=0.5, q=20.0, two_sided=False),
    "blinn_q0": glphong.BlinnPhong(kd=0.1, ks=0.05, q=0.0),
    "phong_huge_q": glphong.Phong(kd=0.1, ks=1.0, q=1e6),
}


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_gbuffer_parity_with_twin(renderer, name):
    scene = material_scene(MATERIALS[name])
    report = glphong.verify(scene, renderer)
    assert report.covered_pixels > 2000
    assert report.mask_mismatch == 0
    assert report.nonfinite_count == 0
    assert report.outside_count == 0, str(report)
    assert report.max_relative_error < 1e-4, str(report)
    assert report.passed
    # the twin really is the same function: the image is not trivially dark
    assert np.percentile(report.reference[report.mask], 90) > 1e-3


def test_flat_shading_parity(renderer):
    report = glphong.verify(material_scene(MATERIALS["phong"], smooth=False), renderer)
    assert report.passed, str(report)


def test_verify_detects_a_wrong_shader(renderer):
    """The cross-check can fail: a GPU image shaded with k_d 1e-4 relative off the twin's is caught.

    The GPU renders k_d = 0.3 (1 + 1e-4); the twin and its band shade the same fragments with k_d = 0.3.
    """
    from glphong import reference
    from glphong.checks.tolerances import radiance_band
    from glphong.verify import compare

    kd = 0.3
    wrong = material_scene(glphong.Lambert(kd=kd * (1 + 1e-4)))
    right = material_scene(glphong.Lambert(kd=kd))
    frame = renderer.render(wrong)
    gbuffer = renderer.gbuffer(wrong)
    assert np.array_equal(gbuffer.position, renderer.gbuffer(right).position)  # the same fragments
    low, high = radiance_band(right, gbuffer)
    ref = reference.shade(right, gbuffer)
    _, outside = compare(frame.radiance, ref, low, high, frame.mask)
    lit = (ref[frame.mask].max(axis=-1) > 0).sum()
    assert lit > 1000 and outside.sum() > 0.9 * lit
    # and the same GPU image against its own twin passes
    _, outside_own = compare(frame.radiance, reference.shade(wrong, gbuffer), *radiance_band(wrong, gbuffer), frame.mask)
    assert outside_own.sum() == 0


def test_gbuffer_contents(renderer):
    scene = material_scene(MATERIALS["phong"])
    g = renderer.gbuffer(scene)
    assert g.position.shape == (80, 96, 3) and g.normal.shape == (80, 96, 3) and g.position.dtype == np.float32
    sphere = g.object_index == 0
    floor = g.object_index == 1
    assert sphere.sum() > 500 and floor.sum() > 500 and np.array_equal(g.mask, sphere | floor)
    # positions lie on the geometry; normals are unit and face the camera
    radius = np.linalg.norm(g.position[sphere], axis=-1)
    assert np.all(np.abs(radius - 1.0) < 0.03)
    np.testing.assert_allclose(np.linalg.norm(g.normal[g.mask], axis=-1), 1.0, atol=1e-6)
    np.testing.assert_allclose(g.position[floor][:, 1], -1.05, atol=1e-5)
    facing = np.sum(g.normal * (scene.camera.position - g.position), axis=-1)
    assert np.all(facing[floor] > 0)
    assert np.mean(facing[sphere] > 0) > 0.98  # interpolated normals may turn away at the silhouette
    assert np.all(g.position[~g.mask] == 0) and np.all(g.object_index[~g.mask] == -1)


def test_image_orientation_row0_is_top(renderer):
    camera = glphong.PerspectiveCamera.look_at((0, 0, 5), (0, 0, 0), yfov=0.8)
    scene = glphong.Scene(camera, ambient=None)
    scene.add(trimesh.creation.box((0.5, 0.5, 0.5)), glphong.Lambert(kd=0.0, ka=1.0), pose=translation(0, 1.0, 0))
    frame = renderer.render(scene)
    rows = np.nonzero(frame.mask.any(axis=1))[0]
    assert rows.max() < 80 // 2  # the box above the centre is in the top half
    np.testing.assert_array_equal(frame.radiance[frame.mask], 1.0)


def test_two_sided_and_one_sided_back_faces(renderer):
    """A plane seen from behind: two-sided flips the normal to the viewer, one-sided does not."""
    camera = glphong.PerspectiveCamera.look_at((0, 0, -3), (0, 0, 0), yfov=0.8)
    quad = trimesh.Trimesh(vertices=[[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], faces=[[0, 1, 2], [0, 2, 3]])
    light = [glphong.PointLight((0, 0, -3), 4 * np.pi * 9)]  # E = 1 W/m^2 at the centre, behind the front face
    values = {}
    for two_sided in (True, False):
        scene = glphong.Scene(camera, lights=light)
        scene.add(quad, glphong.Lambert(kd=0.5, two_sided=two_sided))
        g = renderer.gbuffer(scene)
        assert np.all(g.normal[g.mask][:, 2] == (-1.0 if two_sided else 1.0))
        frame = renderer.render(scene)
        values[two_sided] = frame.radiance[40, 48]
    np.testing.assert_allclose(values[True], 0.5, rtol=1e-3)  # kd * n.l * E with n.l ~ 1
    np.testing.assert_array_equal(values[False], 0.0)  # the light is behind the one-sided surface


def test_program_cache_counts_and_no_recompilation(renderer):
    camera = glphong.PerspectiveCamera.look_at((0, 0, 4), (0, 0, 0))
    lights = [glphong.PointLight((1, 1, 3), 50.0)]
    scene = glphong.Scene(camera, lights=lights)
    sphere = trimesh.creation.icosphere(2)
    for x, m in zip((-1.5, 0.0, 1.5, 3.0), (glphong.Lambert(0.2), glphong.Phong(0.2, 0.3, 10),
                                            glphong.BlinnPhong(0.2, 0.3, 10), glphong.Phong(0.5, 0.1, 99))):
        scene.add(sphere, m, pose=translation(x, 0, 0))
    before = len(renderer.programs)
    renderer.render(scene)
    keys = {binding(scene).program_key(o) for o in scene.objects}
    assert len(keys) == 3  # the two Phong materials share one program
    assert len(renderer.programs) - before <= 3
    misses = renderer.programs.misses
    renderer.render(scene)
    # value changes only: other colours, light moved and brightened, other q
    scene2 = glphong.Scene(camera, lights=[glphong.PointLight((-2, 0, 3), (1.0, 2.0, 3.0))])
    # (q stays below 151, where numerics='auto' would leave out the lobes' log branch: another program)
    for x, m in zip((-1.5, 0.0, 1.5), (glphong.Lambert(0.9), glphong.Phong(0.1, 0.9, 150), glphong.BlinnPhong(0.3, 0.3, 2))):
        scene2.add(sphere, m, pose=translation(x, 0, 0))
    renderer.render(scene2)
    assert renderer.programs.misses == misses
    # a second light changes the key: one more compile per material family
    scene2.add_light(glphong.PointLight((0, 3, 3), 10.0))
    renderer.render(scene2)
    assert renderer.programs.misses == misses + 3


def test_no_leak_across_renders_and_sizes(renderer):
    camera = glphong.PerspectiveCamera.look_at((0, 0, 4), (0, 0, 0))

    def render_fresh(i):
        scene = glphong.Scene(camera, lights=[glphong.PointLight((1, 2, 3), 10.0 + i)])
        scene.add(trimesh.creation.icosphere(1 + i % 2), glphong.Phong(0.2, 0.4, 5.0 + i))
        renderer.render(scene)
        renderer.gbuffer(scene)

    render_fresh(0)
    render_fresh(1)
    gc.collect()
    render_fresh(2)
    baseline = renderer.gl_object_count()
    for i in range(3, 15):
        render_fresh(i)
        gc.collect()
    render_fresh(15)
    assert renderer.gl_object_count() == baseline
    renderer.resize(40, 30)
    scene = material_scene(MATERIALS["lambert"])
    frame = renderer.render(scene)
    assert frame.radiance.shape == (30, 40, 3) and frame.mask.shape == (30, 40)
    assert glphong.verify(scene, renderer).passed
    renderer.resize(96, 80)
    assert renderer.render(scene).radiance.shape == (80, 96, 3)
    renderer.context.check_error("leak test")


def test_renderer_release_is_idempotent_and_context_manager():
    with glphong.Renderer(8, 8) as r:
        assert "Renderer(8x8" in repr(r)
    r.release()
    assert "released" in repr(r)


def test_uniform_binding_is_strict(renderer):
    key = ProgramKey(output="radiance", has_ka=True)
    with renderer.context:
        program = renderer.programs.get(key)
        good = {"u_model": np.eye(4), "u_view_projection": np.eye(4), "u_ka": np.ones(3)}
        program.bind(good)
        with pytest.raises(UniformError, match=r"missing uniforms \['u_ka'\]"):
            program.bind({k: v for k, v in good.items() if k != "u_ka"})
        with pytest.raises(UniformError, match=r"unknown uniforms \['u_eye', 'u_lambert_kd'\]"):
            program.bind({**good, "u_lambert_kd": np.ones(3), "u_eye": np.zeros(3)})  # u_eye: no lights, not used
        with pytest.raises(UniformError, match="u_ka .* takes 3 floats"):
            program.bind({**good, "u_ka": np.ones(4)})


def test_compile_error_names_chunk_file_and_line(renderer, monkeypatch):
    from glphong.shaders import assembly

    original = assembly.chunk_source

    def broken(name):
        text = original(name)
        return text.replace("vec3 radiance = material_emission();", "vec3 radiance = material_emission()  // no ;") \
            if name == "shade" else text

    monkeypatch.setattr(assembly, "chunk_source", broken)
    key = program_key(glphong.Lambert(0.3), {"directional": 1}, None)
    with renderer.context, pytest.raises(ShaderCompileError) as caught:
        Program(renderer.context.mgl, key)
    message = str(caught.value)
    line = next(i for i, text in enumerate(broken("shade").splitlines(), 1) if "// no ;" in text)
    # the error names the chunk file and a line at or just after the broken one, and shows that line
    assert re.search(rf"shade\.glsl:({line}|{line + 1}|{line + 2})\b", message), message
    assert re.search(r"shade\.glsl:\d+ \| ", message), message


def test_name_chunks_rewrites_both_log_formats():
    # Mesa: source:line(column); NVIDIA: source(line); string 0 is the generated #version/#define header
    from glphong.core.glsl_files import chunk_source

    line12 = chunk_source("lights").splitlines()[11].strip()
    assert _name_chunks("0:3(7): error: x", ["common"]) == "<generated header>:3:7: error: x"
    assert _name_chunks("2:12(5): error: y", ["common", "lights"]) == f"lights.glsl:12:5: error: y\n    lights.glsl:12 | {line12}"
    assert _name_chunks("1(12) : error C0000: z", ["lights"]) == f"lights.glsl:12 : error C0000: z\n    lights.glsl:12 | {line12}"
    assert _name_chunks("0:5: error", ["common"]) == "<generated header>:5: error"
    assert _name_chunks("7:2(1): error", ["common"]) == "7:2(1): error"  # no such source string: left as it is


def test_specialised_sources_leave_out_unused_code():
    lambert = program_key(glphong.Lambert(0.3), {"point": 2}, None)
    from glphong.shaders.assembly import assemble, effective_source
    fragment = effective_source(assemble(lambert.fragment_chunks(), lambert.defines(), lambert.generated_chunks()))
    for absent in ("lobe_from_delta", "log_one_minus", "pow(", "phong", "blinn", "uber", "in_tangent",
                   "safe_normalize(eye"):
        assert absent not in fragment, absent
    import re
    declared = set(re.findall(r"uniform \w+ (\w+)", fragment))
    assert declared == {"u_lambert_kd", "u_point_position", "u_point_intensity"}, declared
    assert "#define NUM_POINT_LIGHTS 2" in fragment and "#line 100001 1" in fragment
    assert lambert.attributes() == ("in_position", "in_normal")
    unlit = ProgramKey(output="radiance", has_ka=True, has_normal=False, two_sided=False)
    assert unlit.attributes() == ("in_position",)
    unlit_fragment = effective_source(assemble(unlit.fragment_chunks(), unlit.defines(), unlit.generated_chunks()))
    assert "for (int j" not in unlit_fragment and "safe_normalize(eye" not in unlit_fragment
    assert "u_ka" in unlit_fragment
    both = uber_key([glphong.Phong(0.2, 0.5, 10.0), glphong.BlinnPhong(0.2, 0.5, 10.0)])
    uber = effective_source(assemble(both.fragment_chunks(), both.defines(), both.generated_chunks()))
    for present in ("phong_lobe_response", "blinn_lobe_response", "lambert_response", "u_use_ka", "u_use_phong_lobe",
                    "u_use_lambert_ambient", "u_point_count", "u_eye"):
        assert present in uber, present


def test_effective_source_evaluates_conditions():
    from glphong.shaders.assembly import effective_source

    src = "#define A 1\n#define B 0\n#if A && !B\nyes1 // c\n#elif A\nno1\n#else\nno2\n#endif\n" \
          "#if B\nno3\n#if A\nno4\n#endif\n#elif A > 0 || B\nyes2\n#endif\n#if B\nno5\n#else\nyes3\n#endif\n"
    lines = effective_source(src).split()
    assert [w for w in lines if w.startswith(("yes", "no"))] == ["yes1", "yes2", "yes3"]
