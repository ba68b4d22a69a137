"""User-defined materials (docs/design.md section 8): what a definition is checked for, and that a user's
material works everywhere a built-in one does.

- A definition with a missing twin, a GLSL function of the wrong name or signature, a parameter
  without a range, a name that clashes or is reserved, uniforms that no parameter declares (or
  parameters the GLSL never reads) fails when the class is defined, with a message saying what
  is wrong; bad values fail at instantiation naming the parameter and its range.
- A compile error in a user's GLSL names the user's Python file (or .glsl file) and line and
  shows the offending line.
- A user model renders per pixel, per vertex, with MSAA and supersampling, through the G-buffer
  and `verify`, in the uber-shader, in `describe`, in `stability` with its own cases, and as a
  term of a user `MaterialSum`.
"""
import inspect
import re

import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.materials import (Choice, FresnelSlot, MaterialDefinitionError, MaterialModel, MaterialSum, Param, PhongLobe,
                               SchlickFresnel, model_named)
from glphong.gpu.programs import ShaderCompileError
from glphong.testing import assert_render_matches, assert_twin_matches


class Rim(MaterialModel):
    """A test model: a diffuse term brightened toward the silhouette, f_r = k (1 + a (1 - n.v)^2)."""

    name = "test_rim"
    params = (Param("k", "rgb", low=0.0, unit="1/sr"), Param("a", "scalar", low=0.0, high=10.0, default=1.0))
    needs = ("view",)
    ambient = "k"
    vanishes_with = ("k",)
    glsl = """
    vec3 test_rim_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
    {
        float rim = 1.0 - clamp(dot(f.n, wo), 0.0, 1.0);
        return u_test_rim_k * (n_dot_l * (1.0 + u_test_rim_a * rim * rim));
    }"""

    def response(self, f, wi, wo, n_dot_l, p):
        rim = 1.0 - np.clip(np.sum(f.n * wo, axis=-1), 0.0, 1.0)
        return p.k * (n_dot_l * (1.0 + p.a * rim * rim))[..., None]


class RimPhong(MaterialSum):
    """A user sum: the rim term plus glphong's Phong lobe."""

    terms = (Rim, PhongLobe)


def _definition(**attrs):
    """Define a MaterialModel subclass from ``attrs`` (a valid 'test_def' model unless overridden)."""
    name = attrs.get("name", "test_def")
    body = {"name": name, "params": (Param("k", "rgb", low=0.0),),
            "glsl": f"vec3 {name}_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)\n"
                    f"{{ return u_{name}_k * n_dot_l; }}",
            "response": lambda self, f, wi, wo, n_dot_l, p: p.k * n_dot_l[..., None]}
    body.update(attrs)
    body = {k: v for k, v in body.items() if v is not ...}
    return type("Defined", (MaterialModel,), body)


def _scene(*materials, lights=None, ambient=None, mesh=None):
    camera = glphong.PerspectiveCamera.look_at((0.4, 0.6, 3.0), (0.0, 0.0, 0.0))
    scene = glphong.Scene(camera, lights=lights if lights is not None else
                          [glphong.PointLight((2.0, 2.0, 3.0), 120.0), glphong.DirectionalLight((0.3, -1.0, -0.5), 0.5)],
                          ambient=ambient)
    for i, material in enumerate(materials):
        pose = np.eye(4)
        pose[0, 3] = 1.1 * (i - (len(materials) - 1) / 2)
        scene.add(mesh or primitives.sphere(3, radius=0.5), material, pose=pose)
    return scene


# --------------------------------------------------------------------------- definition-time checks
def test_a_valid_definition_registers_under_its_name():
    model = _definition()
    assert model_named("test_def") is model and model.source_hash() and model(0.5).k == (0.5, 0.5, 0.5)


@pytest.mark.parametrize("attrs, message", [
    ({"response": ...}, r"defines no numpy twin: add `def response\(self, f, wi, wo, n_dot_l, p\)`"),
    ({"response": lambda self, f, wi: wi}, r"response must take \(self, f, wi, wo, n_dot_l, p\)"),
    ({"glsl": "vec3 other_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l) { return u_test_def_k; }"},
     r"must define `vec3 test_def_response\(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l\)`.*"
     r"found no test_def_response \(functions defined: other_response\)"),
    ({"glsl": "vec3 test_def_response(vec3 n, vec3 wi, vec3 wo, float n_dot_l) { return u_test_def_k; }"},
     r"found `vec3 test_def_response\(vec3 n, vec3 wi, vec3 wo, float n_dot_l\)`"),
    ({"glsl": "vec3 test_def_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l) { return u_test_def_k * u_test_def_x; }"},
     r"reads u_test_def_x, which no Param or Table declares"),
    ({"glsl": "vec3 test_def_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l) { return vec3(n_dot_l); }"},
     r"never reads u_test_def_k"),
    ({"glsl": "uniform vec3 u_test_def_k;\nvec3 test_def_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l) "
              "{ return u_test_def_k; }"}, r"declares its own u_test_def_\* uniforms"),
    ({"name": "lambert"}, r"the material name 'lambert' is taken by the built-in glphong\.materials\.lambert\.Lambert"),
    ({"name": "material"}, r"name 'material' is reserved"),
    ({"name": "Minnaert"}, r"name must be a lowercase GLSL identifier"),
    ({"needs": ("normal",)}, r"needs must be a tuple of 'view', 'tangent', 'uv'"),
    ({"uses": ("srgb",)}, r"uses must be a tuple of library chunks 'lobe', 'fresnel', 'angle'"),
    ({"ambient": "q"}, r"ambient must be None or the name of an rgb Param \(k\)"),
    ({"vanishes_with": ("ks",)}, r"vanishes_with names \['ks'\]"),
    ({"glsl": ...}, r"has no glsl"),
    ({"glsl": "no_such_file.glsl"}, r"names the file .*no_such_file\.glsl', which does not exist"),
    ({"params": (Param("k", "rgb", low=0.0), Param("k", "scalar", low=0.0))}, r"params repeats a name"),
    ({"fresnel_slot": FresnelSlot("h.l")}, r"has a fresnel_slot, so its GLSL must call test_def_fresnel\(c\)"),
    ({"glsl": "vec3 test_def_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)\n"
              "{ return u_test_def_k * test_def_fresnel(n_dot_l) * n_dot_l; }"},
     r"calls test_def_fresnel, which glphong generates only for a model with fresnel_slot"),
    ({"fresnel_slot": 0.04}, r"fresnel_slot must be None or a glphong.materials.FresnelSlot"),
    ({"choices": (Param("k2", "rgb", low=0.0),)}, r"choices must be a tuple of glphong.materials.Choice"),
    ({"choices": (Choice("k", ("a", "b"), "a"),)}, r"params, choices and fresnel must have distinct names"),
    ({"ambient_scale": 0.0}, r"ambient_scale must be a positive finite float"),
])
def test_a_bad_definition_fails_when_the_class_is_defined(attrs, message):
    with pytest.raises(MaterialDefinitionError, match=message):
        _definition(**attrs)


@pytest.mark.parametrize("kwargs, message", [
    ({"name": "k", "kind": "rgb"}, r"Param 'k' has no range: give low= and/or high="),
    ({"name": "k", "kind": "vec4", "low": 0.0}, r"kind must be one of 'scalar', 'rgb', 'vec3', 'direction'"),
    ({"name": "Ks", "kind": "rgb", "low": 0.0}, r"lowercase identifier"),
    ({"name": "ka", "kind": "rgb", "low": 0.0}, r"keyword every material takes"),
    ({"name": "m", "kind": "scalar", "low": 2.0, "high": 1.0}, r"low must be below high"),
    ({"name": "m", "kind": "scalar", "low": 0.0, "high": 2.0, "default": 3.0}, r"default is not a valid value"),
])
def test_a_bad_param_fails_at_once(kwargs, message):
    with pytest.raises(MaterialDefinitionError, match=message):
        Param(**kwargs)


def test_a_subclass_with_its_own_glsl_must_have_its_own_name():
    """The issue's bug: a Phong subclass with its own GLSL silently rendered as plain Phong."""
    with pytest.raises(MaterialDefinitionError, match=r"redefines glsl but keeps the name 'phong_lobe'"):
        type("MyLobe", (PhongLobe,), {"glsl": PhongLobe.source()})
    with pytest.raises(MaterialDefinitionError, match=r"is a MaterialSum and defines glsl"):
        type("MyPhong", (glphong.Phong,), {"glsl": "vec3 x_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)"})
    plain = type("PlainSubclass", (PhongLobe,), {"__doc__": "a Python-only subclass: same model"})
    assert plain(0.5, 10.0).name == "phong_lobe"


def test_sums_check_their_terms():
    with pytest.raises(MaterialDefinitionError, match="repeats a model"):
        type("Twice", (MaterialSum,), {"terms": (Rim, Rim)})
    with pytest.raises(MaterialDefinitionError, match="parameter names must differ"):
        type("Clash", (MaterialSum,), {"terms": (glphong.Lambert, _definition(name="test_kd", params=(
            Param("kd", "rgb", low=0.0),), glsl="vec3 test_kd_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)"
                                                       " { return u_test_kd_kd; }"))})
    with pytest.raises(MaterialDefinitionError, match="non-empty tuple of MaterialModel"):
        type("Empty", (MaterialSum,), {"terms": ()})


def test_values_are_validated_at_instantiation_with_the_parameter_and_its_range():
    with pytest.raises(TypeError, match=r"Rim\(\) missing parameter 'k' \(rgb in \[0, inf\], 1/sr\)"):
        Rim()
    with pytest.raises(ValueError, match=r"a must be finite and in \[0, 10\]"):
        Rim(0.3, a=11.0)
    with pytest.raises(ValueError, match=r"k must be finite and in \[0, 3.40282e\+38\] per channel"):
        Rim(-0.1)
    with pytest.raises(TypeError, match=r"unexpected parameter 'q' \(parameters: k, a, ka, two_sided, normal_map, alpha_mask, "
                                          r"alpha_blend\)"):
        Rim(0.3, q=2.0)
    with pytest.raises(TypeError, match=r"at most 2 positional"):
        Rim(0.3, 1.0, 2.0)
    rim = Rim(0.3, ka=0.01, two_sided=False)
    assert (rim.k, rim.a, rim.ka, rim.two_sided) == ((0.3,) * 3, 1.0, (0.01,) * 3, False)
    with pytest.raises(AttributeError, match="immutable"):
        rim.k = 1.0
    assert rim == Rim(0.3, ka=0.01, two_sided=False) and hash(rim) == hash(Rim(0.3, ka=0.01, two_sided=False))
    assert rim != Rim(0.3, a=2.0) and repr(RimPhong(0.2, ks=0.5, q=10.0)) == "RimPhong(k=0.2, a=1, ks=0.5, q=10)"


def test_redefining_the_same_class_replaces_it_and_another_class_cannot_take_the_name():
    first = _definition(name="test_redefined")
    again = _definition(name="test_redefined")  # the same module and qualname: a re-run notebook cell
    assert model_named("test_redefined") is again is not first
    with pytest.raises(MaterialDefinitionError, match="the material name 'test_rim' is taken by"):
        type("Other", (MaterialModel,), {"name": "test_rim", "params": Rim.params, "glsl": Rim.glsl,
                                         "needs": ("view",), "response": Rim.response})


# --------------------------------------------------------------------------- compile errors
class _BrokenBody(MaterialModel):
    name = "test_broken_body"
    params = (Param("k", "rgb", low=0.0),)
    glsl = """
    vec3 test_broken_body_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
    {
        vec3 x = u_test_broken_body_k * n_dot_l;
        return x * not_declared_anywhere;
    }"""

    def response(self, f, wi, wo, n_dot_l, p):
        return p.k * n_dot_l[..., None]


def test_a_compile_error_names_the_users_file_and_line_and_shows_it(glphong_renderer):
    lines, start = inspect.getsourcelines(_BrokenBody)
    line = start + next(i for i, text in enumerate(lines) if "not_declared_anywhere" in text)
    with pytest.raises(ShaderCompileError) as caught:
        glphong_renderer.render(_scene(_BrokenBody(0.3)))
    message = str(caught.value)
    assert f"{__file__}:{line}:" in message, message
    assert f"{__file__}:{line} | return x * not_declared_anywhere;" in message, message
    assert "not_declared_anywhere" in message and "<generated header>" not in message


def test_glsl_from_a_file_beside_the_model(tmp_path, glphong_renderer):
    good = tmp_path / "test_file_model.glsl"
    good.write_text("// a model read from a file\nvec3 test_file_model_response(ShadingFrame f, vec3 wi, vec3 wo, "
                    "float n_dot_l)\n{\n    return u_test_file_model_k * n_dot_l;\n}\n")
    model = _definition(name="test_file_model", glsl=str(good))
    assert model.source() == good.read_text()
    glphong_renderer.resize(48, 48)
    assert_render_matches(_scene(model(0.2)), glphong_renderer)
    bad = tmp_path / "test_file_bad.glsl"
    bad.write_text("vec3 test_file_bad_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)\n{\n"
                   "    return u_test_file_bad_k * n_dot_l\n}\n")  # line 3: missing semicolon
    broken = _definition(name="test_file_bad", glsl=str(bad))
    with pytest.raises(ShaderCompileError, match=re.escape(str(bad)) + r":[34]:"):
        glphong_renderer.render(_scene(broken(0.2)))


# --------------------------------------------------------------------------- works everywhere
def test_the_toolkit_accepts_the_user_model(glphong_backend):
    figures = assert_twin_matches(Rim(0.3, a=3.0), backend=glphong_backend)
    assert figures["nonzero"] > 3000 and figures["max_relative_error"] < 1e-5
    figures = assert_twin_matches(RimPhong((0.2, 0.1, 0.0), ks=0.5, q=200.0), backend=glphong_backend)
    assert figures["max_relative_error"] < 1e-4


def test_per_pixel_render_and_verify(glphong_renderer):
    glphong_renderer.resize(96, 72)
    scene = _scene(Rim(0.25, a=4.0, ka=0.01), RimPhong(0.2, ks=0.6, q=80.0), glphong.Phong(0.2, 0.6, 80.0),
                   ambient=glphong.AmbientLight(0.05))
    report = assert_render_matches(scene, glphong_renderer)
    assert report.covered_pixels > 1500
    # the rim term is seen: the user sum is brighter than the plain Phong, by its rim brightening
    rim_sum, phong = (glphong_renderer.render(_scene(m)).radiance.sum()
                      for m in (RimPhong(0.2, a=2.0, ks=0.6, q=80.0), glphong.Phong(0.2, 0.6, 80.0)))
    assert rim_sum > 1.1 * phong, (rim_sum, phong)


def test_other_render_options_and_the_uber_shader(glphong_make_renderer, glphong_backend):
    scene = _scene(Rim(0.25, a=4.0), RimPhong(0.2, ks=0.6, q=30.0))
    pixel = glphong_make_renderer(64, 48, glphong_backend).render(scene)
    vertex = glphong_make_renderer(64, 48, glphong_backend, shading="vertex").render(scene)
    msaa = glphong_make_renderer(64, 48, glphong_backend, samples=4).render(scene)
    ssaa = glphong_make_renderer(64, 48, glphong_backend, supersample=2).render(scene)
    uber = glphong_make_renderer(64, 48, glphong_backend, specialise=False)
    for frame in (vertex, msaa, ssaa):
        assert np.isfinite(frame.radiance).all() and frame.mask.sum() > 400
        inside = pixel.mask & frame.mask & (frame.coverage == 1) & (pixel.coverage == 1)
        rel = np.abs(frame.radiance[inside].sum() - pixel.radiance[inside].sum()) / pixel.radiance[inside].sum()
        assert rel < 0.03, rel  # the same shading, sampled differently
    np.testing.assert_allclose(uber.render(scene).radiance, pixel.radiance, rtol=2e-6, atol=1e-30)
    assert_render_matches(scene, uber)


def test_describe_and_the_key_name_the_user_model():
    scene = _scene(Rim(0.25), RimPhong(0.0, ks=0.5, q=10.0))
    descriptions = glphong.describe(scene)
    first, second = descriptions
    assert f"model:test_rim@{Rim.source_hash()}" in first.fragment_chunks
    assert first.key.terms[0].source_hash == Rim.source_hash()
    assert [t.name for t in second.key.terms] == ["phong_lobe"]  # k = 0: the rim term is left out
    assert any(item.startswith("term test_rim: ") and "u_test_rim_k, u_test_rim_a (k = 0)" in item
               for item in second.left_out), second.left_out
    assert "test_rim_response" in first.effective_fragment_source


def test_stability_runs_the_models_own_cases(session_gl):
    from glphong.checks.stability import cases_for, run_stability

    cases = cases_for(Rim)
    assert len(cases) >= 8 and all(c.material.name == "test_rim" for c in cases)
    report = run_stability(context=session_gl, cases=cases)
    assert report.passed_count == len(cases), report.format_table()
    assert report.nan_count == 0


# --------------------------------------------------------------------------- the generic band and the toolkit's edge
class _Linear(MaterialModel):
    """A test model whose generic band has a closed form: response k (n.l)."""

    name = "test_linear"
    params = (Param("k", "rgb", low=0.0),)
    glsl = """
    vec3 test_linear_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
    {
        return u_test_linear_k * n_dot_l;
    }"""

    def response(self, f, wi, wo, n_dot_l, p):
        return p.k * n_dot_l[..., None]


class _Linear1e4(_Linear):
    """The same twin, a GLSL 1e-4 relative high: the toolkit must see it."""

    name = "test_linear_high"
    glsl = _Linear.glsl.replace("test_linear", "test_linear_high").replace("* n_dot_l;", "* (1.0001 * n_dot_l);")
    response = _Linear.response


def test_the_generic_band_has_its_documented_closed_form():
    """Response k (n.l): the directions do not move it, n.l +- D eps moves it by k D eps, and the
    result widens by eps (A + B |ln r|) relative (the constants (16, 4, 6, 8) of docs/design.md section 4)."""
    from glphong.materials import ShadingFrame
    from glphong.checks.tolerances import BAND, EPS

    model = _Linear(0.5)
    n_dot_l = np.array([0.8, 0.1, 1e-3])
    wi = np.stack([np.sqrt(1 - n_dot_l ** 2), np.zeros(3), n_dot_l], axis=1)
    wo = np.tile([0.0, 0.6, 0.8], (3, 1))
    low, high = model.band(ShadingFrame(np.tile([0.0, 0.0, 1.0], (3, 1))), wi, wo, n_dot_l, model.values(), BAND)
    r = 0.5 * n_dot_l
    rel = EPS * (16.0 + 4.0 * np.abs(np.log(r)))
    np.testing.assert_allclose(low[:, 0], r - 0.5 * 8.0 * EPS - r * rel, rtol=1e-13)
    np.testing.assert_allclose(high[:, 0], r + 0.5 * 8.0 * EPS + r * rel, rtol=1e-13)


def test_the_toolkit_sees_a_1e4_relative_error(glphong_backend):
    assert_twin_matches(_Linear(0.5), backend=glphong_backend)
    with pytest.raises(AssertionError, match="TestLinearHigh|_Linear1e4"):
        assert_twin_matches(_Linear1e4(0.5), backend=glphong_backend)


class _Power(MaterialModel):
    """A test model with a structural define: response k (n.l)^N, N a compile-time integer from n."""

    name = "test_power"
    params = (Param("k", "rgb", low=0.0), Param("n", "scalar", low=1.0, high=4.0, default=2.0))
    glsl = """
    vec3 test_power_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
    {
        float value = n_dot_l;
        for (int i = 1; i < TEST_POWER_N; ++i) value *= n_dot_l;
        return u_test_power_k * value * step(1.0, u_test_power_n);
    }"""

    def defines(self):
        return (("N", str(int(self.n))),)

    def response(self, f, wi, wo, n_dot_l, p):
        return p.k * (n_dot_l ** int(self.n))[..., None]


def test_structural_defines_are_prefixed_and_part_of_the_key(glphong_renderer):
    squared, cubed = _Power(0.4, n=2.0), _Power(0.4, n=3.0)
    keys = [glphong.describe(_scene(m))[0].key for m in (squared, cubed)]
    assert keys[0] != keys[1] and ("TEST_POWER_N", "3") in keys[1].defines()
    glphong_renderer.resize(48, 48)
    frames = [assert_render_matches(_scene(m), glphong_renderer).gpu for m in (squared, cubed)]
    assert frames[1].sum() < frames[0].sum()  # (n.l)^3 < (n.l)^2


# --------------------------------------------------------------------------- review regressions
class _Stripe(MaterialModel):
    """A test model that reads the tangent: k (n.l) (1 + (wi.t)^2)."""

    name = "test_stripe"
    params = (Param("k", "rgb", low=0.0),)
    needs = ("tangent",)
    glsl = """
    vec3 test_stripe_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
    {
        float a = dot(wi, f.t);
        return u_test_stripe_k * (n_dot_l * (1.0 + a * a));
    }"""

    def response(self, f, wi, wo, n_dot_l, p):
        a = np.sum(wi * f.t, axis=-1)
        return p.k * (n_dot_l * (1.0 + a * a))[..., None]


def test_a_tangent_model_beside_a_mesh_without_tangents(glphong_make_renderer, glphong_backend):
    """The G-buffer carries the tangent plane for the whole scene and the uber-shader reads it for every
    object: a mesh without tangents gets a constant one, where no term of its own needs it."""
    import trimesh

    scene = _scene(_Stripe(0.3), mesh=primitives.sphere(3, radius=0.5))
    scene.add(trimesh.creation.icosphere(2, radius=0.4), glphong.Lambert(0.2), pose=np.diag([1.0, 1.0, 1.0, 1.0]))
    for options in ({}, {"specialise": False}):
        renderer = glphong_make_renderer(64, 48, glphong_backend, **options)
        report = assert_render_matches(scene, renderer)
        assert report.covered_pixels > 200
    assert renderer.gbuffer(scene).tangent is not None


def test_the_uber_shader_refuses_two_variants_of_one_model():
    from glphong.shaders.key import uber_key

    with pytest.raises(ValueError, match=r"one variant of each model.*'test_power'.*specialise=True"):
        uber_key([_Power(0.3, n=1.0), _Power(0.3, n=4.0)])


def test_a_redefined_model_keeps_its_old_instances_right(glphong_renderer):
    """A notebook cell re-run with other GLSL: the old instance still renders with its own definition."""
    glphong_renderer.resize(40, 40)
    first = _definition(name="test_cell")
    old = first(0.3)
    doubled = _definition(name="test_cell", glsl="vec3 test_cell_response(ShadingFrame f, vec3 wi, vec3 wo, "
                          "float n_dot_l)\n{ return 2.0 * u_test_cell_k * n_dot_l; }",
                          response=lambda self, f, wi, wo, n_dot_l, p: 2.0 * p.k * n_dot_l[..., None])
    new = doubled(0.3)
    assert old.source_hash() != new.source_hash()
    a = assert_render_matches(_scene(old), glphong_renderer).gpu
    b = assert_render_matches(_scene(new), glphong_renderer).gpu
    np.testing.assert_allclose(b, 2.0 * a, rtol=1e-6)
    rgb_again = _definition(name="test_cell", params=(Param("k", "scalar", low=0.0),),  # k now a float
                            glsl="vec3 test_cell_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)\n"
                                 "{ return vec3(u_test_cell_k * n_dot_l); }",
                            response=lambda self, f, wi, wo, n_dot_l, p: np.repeat((p.k * n_dot_l)[..., None], 3, -1))
    assert rgb_again.source_hash() != first.source_hash()
    assert_render_matches(_scene(rgb_again(0.3)), glphong_renderer)


def test_a_parameter_a_structural_define_leaves_unread_is_not_an_error(glphong_backend, glphong_renderer):
    class _Second(MaterialModel):
        name = "test_second"
        params = (Param("k", "rgb", low=0.0), Param("k2", "rgb", low=0.0, default=0.0))
        glsl = """
        vec3 test_second_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
        {
            vec3 r = u_test_second_k * n_dot_l;
        #if TEST_SECOND_ON
            r += u_test_second_k2 * (n_dot_l * n_dot_l);
        #endif
            return r;
        }"""

        def defines(self):
            return (("ON", "1" if any(self.k2) else "0"),)

        def response(self, f, wi, wo, n_dot_l, p):
            return p.k * n_dot_l[..., None] + p.k2 * (n_dot_l * n_dot_l)[..., None]

    for material in (_Second(0.3), _Second(0.3, k2=0.2)):
        assert_twin_matches(material, backend=glphong_backend, n=300)
        assert_render_matches(_scene(material), glphong_renderer)


def test_needs_are_checked_against_the_response():
    with pytest.raises(MaterialDefinitionError, match=r"needs must include 'view' \(it reads wo\)"):
        _definition(name="test_noview", glsl="vec3 test_noview_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)"
                    "\n{ return u_test_noview_k * max(dot(f.n, wo), 0.0); }")
    with pytest.raises(MaterialDefinitionError, match=r"'tangent' \(it reads g.t or g.b\)"):
        _definition(name="test_notangent", glsl="vec3 test_notangent_response(ShadingFrame g, vec3 l, vec3 v, "
                    "float c)\n{ return u_test_notangent_k * abs(dot(l, g.t)); }")
    with pytest.raises(MaterialDefinitionError, match=r"'uv' \(it reads f.uv\)"):
        _definition(name="test_nouv", glsl="vec3 test_nouv_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)"
                    "\n{ return u_test_nouv_k * f.uv.x; }")


def test_a_declared_need_the_glsl_never_reads_still_renders(glphong_renderer):
    model = _definition(name="test_overneedy", needs=("view", "tangent", "uv"))
    for shading in ("pixel",):
        glphong_renderer.resize(40, 40)
        assert_render_matches(_scene(model(0.3)), glphong_renderer)


def test_models_that_would_share_a_program_cannot_collide():
    helper = "float {p}sq(float x) {{ return x * x; }}\nvec3 {n}_response(ShadingFrame f, vec3 wi, vec3 wo, " \
             "float n_dot_l)\n{{ return u_{n}_k * {p}sq(n_dot_l); }}"
    _definition(name="test_sq_a", glsl=helper.format(n="test_sq_a", p=""))
    with pytest.raises(MaterialDefinitionError, match=r"defines sq, which the model 'test_sq_a' also defines"):
        _definition(name="test_sq_b", glsl=helper.format(n="test_sq_b", p=""))
    _definition(name="test_sq_b", glsl=helper.format(n="test_sq_b", p="test_sq_b_"))  # prefixed: fine
    with pytest.raises(MaterialDefinitionError, match=r"defines safe_normalize, which glphong's library chunks define"):
        _definition(name="test_lib", glsl="bool safe_normalize(vec3 x) { return true; }\n"
                    "vec3 test_lib_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l) { return u_test_lib_k; }")
    with pytest.raises(MaterialDefinitionError, match=r"generated uniforms u_phong_lobe_q collide"):
        _definition(name="phong", params=(Param("lobe_q", "rgb", low=0.0),),
                    glsl="vec3 phong_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l) { return u_phong_lobe_q; }")


def test_parameter_names_cannot_shadow_the_class():
    for shadowed in ("ambient", "name", "values"):
        with pytest.raises(MaterialDefinitionError, match=rf"{shadowed} would shadow a MaterialModel attribute"):
            _definition(name="test_shadow", params=(Param(shadowed, "rgb", low=0.0),),
                        glsl=f"vec3 test_shadow_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l) "
                             f"{{ return u_test_shadow_{shadowed}; }}")


def test_a_mirroring_pose_keeps_two_sided_shading_facing_the_viewer(glphong_renderer):
    """det(pose) < 0 reverses the winding; the faces toward the camera must still count as front faces."""
    glphong_renderer.resize(32, 32)
    scene = _scene(lights=[glphong.DirectionalLight((0.0, 0.0, -1.0), 1.0)])
    scene.camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0))
    scene.add(primitives.plane(2.0), glphong.Lambert(0.3), pose=np.diag([-1.0, 1.0, 1.0, 1.0]))
    frame = glphong_renderer.render(scene)
    np.testing.assert_allclose(frame.radiance[16, 16], 0.3, rtol=1e-6)  # k_d E, lit from the front
    np.testing.assert_allclose(glphong_renderer.gbuffer(scene).normal[16, 16], (0.0, 0.0, 1.0), atol=1e-7)
    assert_render_matches(scene, glphong_renderer)


def test_stability_cases_of_a_tangent_model(session_gl):
    """The oracle builds the frame in mpmath (t from the case's tangent by Gram-Schmidt, b = n x t)."""
    from glphong.checks.stability import cases_for, run_stability

    report = run_stability(context=session_gl, cases=cases_for(_Stripe))
    assert report.passed_count == len(report.rows) >= 8, report.format_table()


# --------------------------------------------------------------------------- choices, Fresnel, ambient scale
class Sheen(MaterialModel):
    """A test glossy model with a structural choice and a Fresnel slot: f_r = k F(h.l) (n.v)^e, e = 1 or 2."""

    name = "test_sheen"
    params = (Param("k", "rgb", low=0.0, unit="1/sr"),)
    needs = ("view",)
    ambient = "k"
    ambient_scale = 0.5
    fresnel_slot = FresnelSlot(cosine="h.l", default=SchlickFresnel(0.1))
    choices = (Choice("power", ("one", "two"), default="one", doc="the exponent of n.v"),)
    glsl = """
    vec3 test_sheen_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
    {
        vec3 h;
        float h_len;
        float c = safe_normalize(wi + wo, h, h_len) ? dot(h, wi) : 0.0;
        float n_dot_v = max(dot(f.n, wo), 0.0);
    #if TEST_SHEEN_POWER == 1
        n_dot_v = n_dot_v * n_dot_v;
    #endif
        return u_test_sheen_k * test_sheen_fresnel(c) * (n_dot_v * n_dot_l);
    }"""

    def response(self, f, wi, wo, n_dot_l, p):
        from glphong.materials.blinn import half_cosine
        from glphong.definitions.fresnel import fresnel_factor

        n_dot_v = np.maximum(np.sum(f.n * wo, axis=-1), 0.0)
        if p.power == "two":
            n_dot_v = n_dot_v * n_dot_v
        return p.k * fresnel_factor(p, half_cosine(wi, wo)) * (n_dot_v * n_dot_l)[..., None]


def test_a_user_model_takes_choices_and_fresnel_like_the_built_ins(glphong_backend):
    from glphong.shaders.key import program_key
    from glphong.materials import DielectricFresnel

    default = Sheen(0.5)
    assert default.fresnel == SchlickFresnel(0.1) and default.power == "one"
    assert repr(Sheen(0.5, None, "two")) == "Sheen(k=0.5, fresnel=None, power='two')"
    assert repr(default) == "Sheen(k=0.5)"  # arguments at their defaults are not shown
    with pytest.raises(ValueError, match=r"power must be 'one' or 'two' \(got 'three'\)"):
        Sheen(0.5, power="three")
    for material in (default, Sheen(0.5, fresnel=DielectricFresnel(1.4), power="two"), Sheen(0.5, fresnel=None)):
        figures = assert_twin_matches(material, n=500, backend=glphong_backend)
        assert figures["nonzero"] > 200 and figures["max_relative_error"] < 1e-5
    key = program_key(Sheen(0.5, fresnel=DielectricFresnel(1.4), power="two"), {"point": 1}, (0.1, 0.1, 0.1))
    assert ("TEST_SHEEN_POWER", "1") in key.defines() and ("TEST_SHEEN_FRESNEL_DIELECTRIC", "1") in key.defines()
    assert "u_test_sheen_k * (0.5 * u_ambient)" in key.generated_chunks()["generated:material"]
    scene = _scene(Sheen(0.5, power="two"), Sheen(0.4, fresnel=DielectricFresnel(1.4)), ambient=glphong.AmbientLight(0.1))
    with glphong.Renderer(96, 64, backend=glphong_backend) as renderer:
        report = assert_render_matches(scene, renderer)
    assert report.max_relative_error < 1e-5
    with glphong.Renderer(96, 64, backend=glphong_backend, specialise=False) as uber:
        with pytest.raises(ValueError, match="holds one variant of each model, but the scene has two of 'test_sheen'"):
            uber.render(scene)  # a choice is structural: two of them need two programs (specialise=True)
        one_choice = _scene(Sheen(0.5), Sheen(0.4, fresnel=DielectricFresnel(1.4)))  # Fresnel is a runtime switch there
        assert glphong.verify(one_choice, uber).passed
