"""Stability where a scene needs it (docs/design.md section 3): ``Renderer(numerics='auto')`` specialises a piece of
arithmetic only where the scene's ranges prove the bound, keeps the stable one elsewhere, and stays in the band."""
import math

import numpy as np
import pytest

import glphong
from glphong.testing.glsl_source import LIBRARY_DEFINES
from glphong.checks.stability import CASES, case_numerics, run_stability
from glphong.checks.tolerances import lobe_band
from glphong.core.glsl_files import chunk_source
from glphong.gpu.describe import describe, format_descriptions
from glphong.materials import registered_models
from glphong.scene import primitives
from glphong.scene.geometry import MeshData
from glphong.shaders.numerics import (FALLOFF_LIMIT, LOBE_TAIL_Q, NORMAL_LENGTHS, numerics_decisions, numerics_pieces,
                                    normal_range)
from glphong.shaders.key import NUMERICS_DEFINES, NUMERICS_PIECES, ProgramKey
from glphong.bench import speed_scenes

FLT_MAX = float(np.finfo(np.float32).max)


def _decisions(scene, obj=None):
    return {d.piece: d for d in numerics_decisions(scene, obj or scene.objects[0])}


def _models_scene():
    """A sphere of each built-in model's example under a point, a spot and a directional light, with ambient."""
    lights = [glphong.PointLight((2.0, 2.0, 3.0), 80.0), glphong.SpotLight((-2.0, 2.0, 3.0), (0.5, -0.5, -0.7), 60.0),
              glphong.DirectionalLight((0.3, -1.0, -0.5), 2.0)]
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, 0.0, 7.0), (0.0, 0.0, 0.0)), lights=lights,
                          ambient=glphong.AmbientLight(0.05))
    models = [m for m in registered_models() if m.__module__.startswith("glphong.")]
    for i, model in enumerate(models):
        pose = np.eye(4)
        pose[:3, 3] = ((i % 5) - 2.0, (i // 5) - 1.5, 0.0)
        scene.add(primitives.sphere(3, 0.45), model.example(), pose=pose)
    assert len(scene.objects) >= 14
    return scene


def _plane_scene(material, light, camera=None, size=2.0):
    scene = glphong.Scene(camera or glphong.PerspectiveCamera.look_at((0.0, 0.0, 1.5), (0.0, 0.0, 0.0)),
                          lights=[light])
    scene.add(primitives.plane(size, 8), material)
    return scene


def test_key_carries_each_piece_as_its_define():
    key = ProgramKey(terms=(), numerics=("falloff", "lobe_tail"))
    defines = dict(key.defines())
    assert defines["NAIVE_FALLOFF"] == "1" and defines["LOBE_TAIL_ZERO"] == "1"
    assert defines["NAIVE_NORMAL"] == defines["NAIVE_VIEW"] == defines["NAIVE_LIGHT"] == "0"
    textbook = dict(ProgramKey(formulation="naive").defines())  # the textbook formulation: every NAIVE_ piece
    assert all(textbook[d] == ("1" if d.startswith("NAIVE_") else "0") for d in NUMERICS_DEFINES.values())
    assert "numerics=('falloff', 'lobe_tail')" in key.describe()
    for bad in (("lobe_tail", "falloff"), ("pow",), ("view", "view")):
        with pytest.raises(ValueError, match="invalid ProgramKey"):
            ProgramKey(numerics=bad)
    assert set(dict(LIBRARY_DEFINES)) >= set(NUMERICS_DEFINES.values())  # a user's include sees them all at 0


def test_renderer_validates_numerics(make_renderer):
    with pytest.raises(ValueError, match="numerics"):
        make_renderer(8, 8, "egl", numerics="fast")


def test_family_scenes_decisions():
    scenes = speed_scenes(quick=True)
    for name, scene in scenes.items():
        pieces = numerics_pieces(scene, scene.objects[0])
        assert {"normal", "view", "light", "falloff"} <= set(pieces), name
    # Blinn q = 200 is past LOBE_TAIL_Q, Phong q = 60 is not
    assert "lobe_tail" in numerics_pieces(scenes["plane"], scenes["plane"].objects[0])
    decision = _decisions(scenes["8 lights"])["lobe_tail"]
    assert not decision.specialised and "q = 60 is below 151" in decision.reason


@pytest.mark.parametrize("backend", ["egl", "osmesa"])
def test_verify_passes_in_both_modes(make_renderer, backend):
    """Every scene of the speed family (small stand-ins), every built-in model under three light kinds, a Phong q = 1e4
    plane under a close light: in the band with numerics='auto' and 'stable'; the two differ by float32 roundings
    only."""
    scenes = dict(speed_scenes(quick=True))
    scenes["every model"] = _models_scene()
    scenes["phong q=1e4 close light"] = _plane_scene(glphong.Phong(0.2, 0.5, 1e4),
                                                      glphong.PointLight((0.1, 0.2, 0.05), 1.0))
    auto = make_renderer(64, 64, backend)
    stable = make_renderer(64, 64, backend, numerics="stable")
    for name, scene in scenes.items():
        a = glphong.verify(scene, auto)
        s = glphong.verify(scene, stable)
        assert a.passed and s.passed, (name, a.summary(), s.summary())
        ra, rs = auto.render(scene).radiance, stable.render(scene).radiance
        np.testing.assert_allclose(ra, rs, rtol=3e-5, atol=1e-9, err_msg=name)
        assert auto.program_key(scene, scene.objects[0]).numerics and not stable.program_key(scene, scene.objects[0]).numerics


def test_lobe_tail_gives_the_same_bits(glphong_glsl):
    """lobe_from_delta with LOBE_TAIL_ZERO equals the full form bit for bit for every q >= LOBE_TAIL_Q, over delta
    from 0 to past 1 (both sides of 1/2 densely)."""
    def source(tail):
        defines = "\n".join(f"#define {k} {('1' if tail and k == 'LOBE_TAIL_ZERO' else v)}" for k, v in LIBRARY_DEFINES)
        return "\n".join([defines, chunk_source("common"), chunk_source("lobe")])

    full, tail = (glphong_glsl(source(t), "lobe_from_delta") for t in (False, True))
    delta = np.concatenate([np.linspace(0.0, 1.1, 4001), np.nextafter(np.float32(0.5), np.float32(0)) + np.zeros(1),
                            0.5 + np.arange(-64, 64) * 2.0 ** -24, 10.0 ** -np.arange(1, 38)]).astype(np.float32)
    for q in (LOBE_TAIL_Q, 151.5, 200.0, 1e4, 1e7, FLT_MAX):
        a, b = full(delta=delta, q=q), tail(delta=delta, q=q)
        assert np.array_equal(a.view(np.uint32), b.view(np.uint32)), q
    # below LOBE_TAIL_Q the tail is not 0: the piece would change values there
    below = full(delta=np.float32([0.5]), q=100.0)
    assert below[0] > 0


def test_lobe_tail_decision_bounds():
    light = glphong.PointLight((0.3, 0.2, 1.0), 10.0)
    at, below = (_decisions(_plane_scene(glphong.BlinnPhong(0.2, 0.5, q), light))["lobe_tail"] for q in (151.0, 150.9))
    assert at.specialised and not below.specialised
    assert "no cosine-power lobe" in _decisions(_plane_scene(glphong.Lambert(0.2), light))["lobe_tail"].reason
    ashikhmin = _decisions(_plane_scene(glphong.AshikhminShirley(0.2, 0.3, 200.0, 200.0), light))["lobe_tail"]
    assert not ashikhmin.specialised and "exponents of its own" in ashikhmin.reason


def test_falloff_just_beyond_the_bound_is_stable_and_both_sides_verify(make_renderer):
    """A point light 1 mm above a plane whose irradiance at the nearest point is FLT_MAX / 16 times (1 -+ 1e-3): the
    side below the bound compiles I / (d d), the side above keeps (I / d) / d; both render inside the band."""
    renderer = make_renderer(48, 48, "egl")
    for factor, expected in ((0.999, True), (1.001, False)):
        d = 1e-3
        power = 4 * math.pi * FALLOFF_LIMIT * d * d * factor
        scene = _plane_scene(glphong.Lambert(0.3), glphong.PointLight((0.0, 0.0, d), power))
        decision = _decisions(scene)["falloff"]
        assert decision.specialised is expected, decision.reason
        assert renderer.program_key(scene, scene.objects[0]).numerics.count("falloff") == expected
        report = glphong.verify(scene, renderer)
        assert report.passed and report.summary()["nonfinite"] == 0, report.summary()


def test_lengths_beyond_the_bounds_keep_safe_normalize():
    plane = glphong.Lambert(0.3)
    near = 0.9 * NORMAL_LENGTHS[0]
    # a light inside the object's box, and one nearer than 2^-50 m to a tiny object
    inside = _decisions(_plane_scene(plane, glphong.PointLight((0.1, 0.1, 0.0), 1.0)))
    assert not inside["light"].specialised and not inside["falloff"].specialised
    tiny = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, 0.0, 5e-16), (0.0, 0.0, 0.0), znear=1e-16, zfar=1e-13),
                         lights=[glphong.PointLight((0.0, 0.0, near), 1e-30)])
    tiny.add(MeshData([[0, 0, 0], [1e-15, 0, 0], [0, 1e-15, 0]], [[0, 0, 1]] * 3, [[0, 1, 2]]), plane)
    found = _decisions(tiny)
    assert not found["light"].specialised and "below" in found["light"].reason
    assert not found["view"].specialised  # the eye 5e-16 m from the object, the near plane at 1e-16 m: below 2^-50 m
    far = _decisions(_plane_scene(plane, glphong.PointLight((0.0, 0.0, 1e19), 1.0)))
    assert not far["light"].specialised and "above 2^63" in far["light"].reason
    # the same tiny scene at 2^-50 m * 2 from a light: just inside
    tiny2 = glphong.Scene(tiny.camera, lights=[glphong.PointLight((0.0, 0.0, 2.0 * NORMAL_LENGTHS[0]), 1e-30)])
    tiny2.add(tiny.objects[0].mesh, plane)
    assert _decisions(tiny2)["light"].specialised
    ortho = _plane_scene(plane, glphong.PointLight((0.0, 0.0, 1.0), 1.0),
                         camera=glphong.OrthographicCamera.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0)))
    assert _decisions(ortho)["view"].specialised


@pytest.mark.parametrize("label, normals, expected", [
    ("unit", [[0, 0, 1]] * 3, True),
    ("opposite on one triangle", [[0, 0, 1], [0, 0, -1], [0, 0, 1]], False),
    ("perpendicular", [[0, 0, 1], [1, 0, 0], [0, 0, 1]], False),
    ("zero", [[0, 0, 0]] * 3, False),
    ("tiny 1e-25", [[0, 3e-26, 1e-25]] * 3, False),
    ("huge 1e25", [[0, 3e24, 1e25]] * 3, False),
    ("NaN", [[np.nan, 0, 1]] * 3, False),
])
def test_normal_piece_follows_the_triangles_normals(label, normals, expected):
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, 0.0, 2.0), (0.0, 0.0, 0.0)),
                          lights=[glphong.PointLight((0.0, 1.0, 1.0), 1.0)])
    with np.errstate(invalid="ignore"):
        scene.add(MeshData([[0, 0, 0], [1, 0, 0], [0, 1, 0]], normals, [[0, 1, 2]]), glphong.Lambert(0.3))
    assert _decisions(scene)["normal"].specialised is expected, _decisions(scene)["normal"].reason


def test_normal_range_bound_is_a_lower_bound():
    """The pairwise-dot bound never exceeds the shortest interpolated normal (sampled barycentrics)."""
    rng = np.random.default_rng(29)
    normals = rng.normal(size=(60, 3)) * 0.2 + [0, 0, 1.0]
    mesh = MeshData(rng.normal(size=(60, 3)), normals, np.arange(60).reshape(20, 3))
    low, high = normal_range(mesh)
    tri = normals.reshape(20, 3, 3)
    w = rng.dirichlet((1, 1, 1), size=4000)
    shortest = min(np.min(np.linalg.norm(w @ t, axis=1)) for t in tri)
    assert 0 < low <= shortest ** 2 and high == pytest.approx(np.max(np.linalg.norm(normals, axis=1)))


def test_stability_suite_in_auto_mode(session_gl, stability_expectations):
    """Every case passes with the pieces auto specialises for it; the cases beyond a bound take the stable path."""
    report = run_stability(context=session_gl, numerics="auto", expectations=stability_expectations)
    failed = [r.case for r in report.rows if not r.passed]
    assert failed == [] and report.nan_count == 0 and report.inf_count == 0, report.format_table()
    assert len(report.rows) == len(CASES) and any(r.numerics for r in report.rows)
    rows = {r.case: r for r in report.rows}
    for d in ("1e-30", "1e-19", "2e+19", "1e+30"):  # lengths outside [2^-50, 2^63]: safe_normalize, (I / d) / d
        assert not {"light", "falloff"} & set(rows[f"distance {d}, Phi=1 W"].numerics), d
    assert "falloff" not in rows["kd=(1,0,0) under saturating light"].numerics
    assert "falloff" not in rows["power 3e+38 W at 1 m"].numerics  # I / d^2 above FLT_MAX / 16
    assert "lobe_tail" in rows["phong q=1000 near"].numerics and "lobe_tail" not in rows["phong q=1 peak"].numerics


def test_case_numerics_leaves_out_the_normal():
    assert all("normal" not in case_numerics(c) for c in CASES[:40])


def test_describe_shows_each_decision_with_its_reason(make_renderer):
    scene = speed_scenes(quick=True)["8 lights"]
    text = format_descriptions(describe(scene))
    assert "numerics (auto):" in text
    assert "lobe_tail: stable (phong_lobe's exponent q = 60 is below 151" in text
    assert "falloff: specialised (point-light irradiance at most" in text
    stable = make_renderer(8, 8, "egl", numerics="stable")
    text = format_descriptions(describe(scene, stable))
    assert "numerics (auto)" not in text and "numerics=" not in text


def test_a_camera_change_revisits_the_view_piece(make_renderer):
    scene = _plane_scene(glphong.Phong(0.2, 0.5, 30.0), glphong.PointLight((0.3, 0.2, 1.0), 10.0))
    renderer = make_renderer(32, 32, "egl")
    renderer.render(scene)
    obj = scene.objects[0]
    assert "view" in renderer._entries[obj]["radiance"].key.numerics
    # a camera 1e-16 m above the plane with its near plane below 2^-50 m: the view vector may be too short
    scene.camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 1e-16), (0.0, 0.0, -1.0), znear=1e-17, zfar=10.0)
    renderer.render(scene)
    assert "view" not in renderer._entries[obj]["radiance"].key.numerics
    assert "view" not in renderer.program_key(scene, obj).numerics


def test_pieces_are_documented():
    assert set(NUMERICS_PIECES) == {"normal", "view", "light", "falloff", "lobe_tail"}
    assert LOBE_TAIL_Q * (math.log(0.5) + 2.0 ** -21) < -104.0  # the tail's bound, as the design document writes it


def test_plain_normalize_and_the_series_against_their_twins(session_gl):
    """The new chunk functions against their numpy twins: plain_normalize on lengths across [2^-50, 2^63] (within
    4 eps of safe_normalize's twin there), log_one_minus_series on delta from 1e-30 to 1/2 (a few ulp)."""
    from glphong.testing import probe
    from glphong import reference as ref

    rng = np.random.default_rng(2029)
    lengths = 2.0 ** rng.uniform(-50, 63, size=(500, 1))
    x = (rng.normal(size=(500, 3)) * lengths).astype(np.float32)
    norm = np.linalg.norm(x.astype(np.float64), axis=1)
    x = x[(norm >= NORMAL_LENGTHS[0]) & (norm <= NORMAL_LENGTHS[1])]
    assert len(x) > 400
    gpu = probe.evaluate(session_gl, "plain_normalize", x=x)
    valid, x_hat, length = ref.plain_normalize(x.astype(np.float64))
    assert gpu["return"].all() and valid.all()
    np.testing.assert_allclose(gpu["x_hat"], x_hat, rtol=0, atol=4 * 2.0 ** -24)
    np.testing.assert_allclose(gpu["len"], length, rtol=4 * 2.0 ** -24, atol=0)
    _, safe_hat, _ = ref.safe_normalize(x.astype(np.float64))
    np.testing.assert_allclose(x_hat, safe_hat, rtol=0, atol=1e-15)
    delta = np.concatenate([10.0 ** -np.arange(1, 31), rng.uniform(0, 0.5, 400)]).astype(np.float32)
    gpu = probe.evaluate(session_gl, "log_one_minus_series", delta=delta)["return"]
    want = np.log1p(-delta.astype(np.float64))
    np.testing.assert_allclose(gpu, want, rtol=8 * 2.0 ** -24, atol=0)
    np.testing.assert_allclose(ref.log_one_minus_series(delta.astype(np.float64)), want, rtol=1e-15, atol=0)
    # beyond the bound the textbook form fails where the stable one does not: |x| = 2^65 overflows x.x
    beyond = probe.evaluate(session_gl, "plain_normalize", x=np.float32([[2.0 ** 65, 0, 0]]))
    assert beyond["x_hat"][0, 0] != 1.0 and probe.evaluate(session_gl, "safe_normalize", x=np.float32([[2.0 ** 65, 0, 0]]))["x_hat"][0, 0] == 1.0


def test_definitions_declare_what_the_decisions_read():
    """A model names the exponent of its lobes (`MaterialModel.lobe_exponent`), a light kind the uniforms its pieces
    are bounded by (`LightModel.numerics_bounds`); the decisions read those, not the names, and a definition that
    names something else is refused."""
    from glphong.materials import MaterialDefinitionError, MaterialModel, Param

    assert {m.name for m in registered_models() if m.lobe_exponent} == {
        "phong_lobe", "blinn_lobe", "normalized_phong_lobe", "normalized_blinn_lobe"}
    assert glphong.PointLight.numerics_bounds == {"light": "position", "falloff": "intensity"}
    assert glphong.SpotLight.numerics_bounds == {"light": "position"} == glphong.UnattenuatedPointLight.numerics_bounds
    assert glphong.DirectionalLight.numerics_bounds == {}
    glsl = ("vec3 {n}_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)\n"
            "{{ return u_{n}_k * lobe_from_delta(phong_delta(f.n, wi, wo), u_{n}_e); }}")

    def twin(self, f, wi, wo, n_dot_l, p):
        from glphong import reference as ref
        return p.k * ref.lobe_from_delta(ref.phong_delta(f.n, wi, wo), p.e)[..., None]

    params = (Param("k", "rgb", low=0.0), Param("e", "scalar", low=0.0, high=1e7, textureable=True))
    with pytest.raises(MaterialDefinitionError, match="lobe_exponent must be None or the name of a scalar Param"):
        type("Bad", (MaterialModel,), {"name": "test_numerics_bad", "params": params, "uses": ("lobe",), "needs": ("view",),
                                       "lobe_exponent": "k", "glsl": glsl.format(n="test_numerics_bad"),
                                       "response": twin})
    model = type("Textured", (MaterialModel,), {"name": "test_numerics_lobe", "params": params, "uses": ("lobe",), "needs": ("view",),
                                                "lobe_exponent": "e", "glsl": glsl.format(n="test_numerics_lobe"),
                                                "response": twin})
    light = glphong.PointLight((0.3, 0.2, 1.0), 10.0)
    assert _decisions(_plane_scene(model(0.5, 200.0), light))["lobe_tail"].specialised
    assert not _decisions(_plane_scene(model(0.5, 150.0), light))["lobe_tail"].specialised
    textured = model(0.5, glphong.Texture(np.full((4, 4, 3), 0.9, np.float32), scale=300.0, channel="r"))
    assert "exponent e varies over the surface" in _decisions(_plane_scene(textured, light))["lobe_tail"].reason


def test_textbook_falloff_and_the_tail_against_their_twins(glphong_glsl):
    """point_irradiance under NAIVE_FALLOFF against the twin's textbook form, lobe_from_delta under LOBE_TAIL_ZERO
    against the twin's tail_zero form (GLSL and twin alike, function by function)."""
    from glphong import reference as ref

    def source(define):
        defines = "\n".join(f"#define {k} {('1' if k == define else v)}" for k, v in LIBRARY_DEFINES)
        return "\n".join([defines, chunk_source("common"), chunk_source("lights"), chunk_source("lobe")])

    rng = np.random.default_rng(7)
    intensity = (10.0 ** rng.uniform(-10, 10, size=(300, 3))).astype(np.float32)
    d = (10.0 ** rng.uniform(-6, 6, size=300)).astype(np.float32)
    gpu = glphong_glsl(source("NAIVE_FALLOFF"), "point_irradiance")(intensity=intensity, d=d)
    want = ref.point_irradiance(intensity.astype(np.float64), d.astype(np.float64), textbook=True)
    np.testing.assert_allclose(gpu, want, rtol=16 * 2.0 ** -24, atol=0)
    delta = np.linspace(0.0, 1.0, 2001, dtype=np.float32)
    gpu = glphong_glsl(source("LOBE_TAIL_ZERO"), "lobe_from_delta")(delta=delta, q=200.0)
    want = ref.lobe_from_delta(delta.astype(np.float64), 200.0, tail_zero=True)
    assert np.all(gpu[delta >= 0.5] == 0) and np.all(want[delta >= 0.5] == 0)
    low, high = lobe_band(delta.astype(np.float64), 200.0)
    assert np.all((gpu >= low) & (gpu <= high))
