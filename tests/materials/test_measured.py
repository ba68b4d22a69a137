"""MeasuredBRDF: a MERL table sampled from a 3D texture, its twin, its band, and tables made from models.

Nothing is downloaded: every measured material here is tabulated from an analytic one
(`MeasuredBRDF.from_model`, `glphong.merl.tabulate`) or built in closed form (`MeasuredBRDF.example`).

- The twin's bin coordinates equal the MERL reference code's angles (`glphong.merl.half_diff`,
  checked against a transcription of its rotations in test_merl.py) to 1e-9 bins on 20000 pairs, and
  its nearest bin is the reference reader's except where the two float64 formulations round across a
  boundary.
- Rendered images through `glphong.verify` on both backends, also in the uber-shader (the GPU against the
  twin at 4300 pairs for both lookups of this module's tabulated model, with the model's band, is in
  tests/test_conformance.py, with the definition's mechanics, the declared properties and the stability
  cases).
- The band fails a GPU that looks up the wrong bin (a shifted table).
- A round trip through a file returns the table bit for bit in float32; the render of a tabulated
  model matches the analytic render: trilinear median relative error below 5e-4, nearest below 2e-2,
  on pixels whose light and view are 25 degrees or more above the horizon.
- The texture is uploaded only when a drawn object reads it, once per content per context, and
  released when no material holds it any more.
- Unmeasured cells, bad shapes, negative entries and foreign files give clear errors or counts.
"""
import gc

import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong import merl
from glphong.materials import MeasuredBRDF
from glphong.materials.measured import measured_brdf_coordinates
from glphong.testing import TwinMismatch

ANALYTIC = glphong.NormalizedBlinnPhong(0.3, 0.5, 40.0)


@pytest.fixture(scope="module")
def tabulated():
    """The MERL table of `ANALYTIC` (1.5 s to make)."""
    return merl.tabulate(ANALYTIC)


def _random_pairs(count, seed=3):
    rng = np.random.default_rng(seed)
    a, b = rng.normal(size=(2, count, 3))
    a[:, 2], b[:, 2] = np.abs(a[:, 2]) + 1e-3, np.abs(b[:, 2]) + 1e-3
    return a / np.linalg.norm(a, axis=1, keepdims=True), b / np.linalg.norm(b, axis=1, keepdims=True)


def test_declaration():
    assert MeasuredBRDF.name == "measured_brdf" and glphong.MeasuredBRDF is MeasuredBRDF
    (table,) = MeasuredBRDF.tables
    assert (table.name, table.shape, table.channels, table.glsl_type) == ("table", merl.SHAPE, 3, "sampler3D")
    assert MeasuredBRDF.needs == ("view",) and MeasuredBRDF.uses == ("angle",)
    assert "uniform sampler3D u_measured_brdf_table;" in MeasuredBRDF.uniform_declarations()
    # the GLSL's bin constants are the declared table's
    assert "ivec3(89, 89, 179)" in MeasuredBRDF.source()
    p = MeasuredBRDF.properties
    assert (p.reciprocal, p.isotropic, p.non_negative, p.energy_conserving) == (True, True, True, None)


def test_coordinates_are_the_reference_angles():
    wi, wo = _random_pairs(20000)
    x = measured_brdf_coordinates(np.broadcast_to([0.0, 0.0, 1.0], wi.shape), wi, wo)
    theta_h, theta_d, phi_d = merl.half_diff(wi, wo)
    phi_d = np.where(phi_d < 0, phi_d + np.pi, phi_d)
    expected = np.stack([90 * np.sqrt(theta_h / (np.pi / 2)), theta_d * 180 / np.pi, phi_d * 180 / np.pi], axis=-1)
    np.testing.assert_allclose(x, expected, rtol=0, atol=1e-9)
    bins = np.clip(np.floor(x), 0, np.array(merl.SHAPE) - 1).astype(int)
    reference = np.stack(merl.merl_indices(*merl.half_diff(wi, wo)), axis=-1)
    differ = np.any(bins != reference, axis=1)
    # only where a coordinate lies within 1e-9 of a bin boundary may the formulations round apart
    near = np.any(np.abs(x - np.rint(x)) < 1e-9, axis=1)
    assert not np.any(differ & ~near)


def test_coordinates_at_the_peak_and_the_fold():
    n = np.array([[0.0, 0.0, 1.0]] * 3)
    wi = np.array([[0.0, 0.0, 1.0], [np.sin(0.3), 0, np.cos(0.3)], [0.6, 0.0, 0.8]])
    wo = np.array([[0.0, 0.0, 1.0], [-np.sin(0.3), 0, np.cos(0.3)], [0.0, 0.6, 0.8]])
    x = measured_brdf_coordinates(n, wi, wo)
    assert np.allclose(x[0], 0) and np.allclose(x[1, :2], [0, 0.3 * 180 / np.pi])
    # swapping l and v negates d = l - v, which the fold removes: bit-identical coordinates, also where
    # phi_d = pi (folded to 0, the same azimuth: the reference reader clamps it into bin 179)
    assert np.array_equal(measured_brdf_coordinates(n, wo, wi), x) and x[1, 2] == 0.0
    a, b = _random_pairs(20000)
    normals = np.broadcast_to([0.0, 0.0, 1.0], a.shape)
    assert np.array_equal(measured_brdf_coordinates(normals, b, a), measured_brdf_coordinates(normals, a, b))


def test_gpu_is_reciprocal(glphong_backend, tabulated):
    """On the GPU too, swapping l and v picks the same bin: f_r equal to float32 rounding of the response."""
    wi, wo = _random_pairs(20000)
    material = MeasuredBRDF(tabulated)
    forward = glphong.analysis.f_r(material, wi, wo, gpu=True, backend=glphong_backend)
    backward = glphong.analysis.f_r(material, wo, wi, gpu=True, backend=glphong_backend)
    live = forward > 0
    assert live.mean() > 0.9
    np.testing.assert_allclose(backward[live], forward[live], rtol=3e-7)


def test_the_band_catches_a_wrong_bin(glphong_backend, tabulated):
    """A GPU reading the neighbouring theta_h bin (the table shifted by one) leaves the band."""
    good = MeasuredBRDF(tabulated)
    shifted = MeasuredBRDF(np.roll(np.nan_to_num(tabulated), 1, axis=0))
    wi, wo = _random_pairs(500)
    gpu = glphong.testing.evaluate(shifted, wi, wo, backend=glphong_backend)
    with pytest.raises(TwinMismatch, match="left the tolerance band"):
        _assert_in_band(good, wi, wo, gpu)


def _assert_in_band(material, wi, wo, gpu):
    """`assert_twin_matches`' judgement on given GPU values (the tool's check, at these pairs)."""
    from glphong.shaders.builders import response_key
    from glphong.evaluation.response import response_inputs, twin_response
    from glphong.checks.tolerances import BAND, EPS

    wi, wo, normal, tangent, uv = response_inputs(material, wi, wo)
    key = response_key(material)
    twin, f, wi64, wo64, n_dot_l, u = twin_response(material, key, material.uniform_values(key), wi, wo, normal, tangent,
                                                    uv)
    low, high = material.band(f, wi64, wo64, n_dot_l, material.values(), BAND)
    bad = np.any((gpu < low) | (gpu > high), axis=1) & (n_dot_l > BAND.D * EPS)
    if bad.any():
        raise TwinMismatch(f"the GPU response left the tolerance band at {int(bad.sum())} pairs")


@pytest.mark.parametrize("lookup", ["nearest", "trilinear"])
def test_render_verifies_and_matches_the_analytic_material(glphong_backend, glphong_make_renderer, lookup, tabulated,
                                                          tmp_path):
    path = tmp_path / "blinn.binary"
    measured = MeasuredBRDF.from_model(ANALYTIC, path, lookup) if lookup == "nearest" else \
        MeasuredBRDF(tabulated, lookup)
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.4, 3.0), (0.0, 0.0, 0.0), yfov=0.7)
    light = glphong.PointLight((2.0, 2.0, 2.0), power=100.0)
    renderer = glphong_make_renderer(96, 96, glphong_backend)
    images = {}
    for name, material in (("analytic", ANALYTIC), ("measured", measured)):
        scene = glphong.Scene(camera, [light])
        scene.add(primitives.sphere(), material)
        images[name] = renderer.render(scene).radiance
        report = glphong.verify(scene, renderer)
        assert report.passed, report
    gbuffer = renderer.gbuffer(scene)
    to_eye = np.asarray(camera.position) - gbuffer.position
    to_light = np.asarray(light.position) - gbuffer.position
    cos = lambda d: np.sum(gbuffer.normal * d, -1) / np.linalg.norm(d, axis=-1)  # noqa: E731
    inner = gbuffer.mask & (cos(to_eye) > np.sin(np.radians(25))) & (cos(to_light) > np.sin(np.radians(25)))
    assert inner.sum() > 1500
    assert np.all(images["analytic"][inner] > 0)
    rel = (np.abs(images["measured"][inner] - images["analytic"][inner]) / images["analytic"][inner]).max(axis=-1)
    median = np.median(rel)
    # measured: trilinear 9e-5, nearest 6e-3 (its 1-degree bins in theta_d and phi_d)
    assert median < (5e-4 if lookup == "trilinear" else 2e-2), median
    assert median > 1e-7  # a real tabulation, not the analytic material again


def test_round_trip_through_a_file_is_exact(tmp_path, tabulated):
    path = tmp_path / "t.binary"
    measured = MeasuredBRDF.from_model(ANALYTIC, path)
    assert measured.table.source == str(path)
    assert measured.unmeasured == int(np.isnan(tabulated).any(axis=-1).sum()) > 0
    expected = np.where(np.isnan(tabulated), 0.0, tabulated).astype(np.float32)
    assert np.array_equal(measured.table.array, expected)
    assert MeasuredBRDF(path) == measured and hash(MeasuredBRDF(path)) == hash(measured)
    assert MeasuredBRDF(path) != MeasuredBRDF(path, "trilinear")
    assert repr(measured) == f"MeasuredBRDF(table={str(path)!r})"
    assert eval(repr(measured), {"MeasuredBRDF": MeasuredBRDF}) == measured  # noqa: S307


def test_texture_uploaded_only_when_drawn_and_once(glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(32, 32, glphong_backend)
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0))
    scene = glphong.Scene(camera, [glphong.PointLight((1.0, 1.0, 2.0), power=50.0)])
    scene.add(primitives.sphere(2), glphong.Lambert(0.3))
    renderer.render(scene)
    assert renderer.programs.textures.uploads == 0
    table = np.full(merl.SHAPE + (3,), 0.1)
    table[0, 0, 0] = 0.2  # a table of its own (tables are interned by content)
    first, second = MeasuredBRDF(table), MeasuredBRDF(table.copy(), "trilinear")
    assert first.table is second.table
    scene.add(primitives.sphere(2), first, pose=np.diag([0.5, 0.5, 0.5, 1.0]))
    scene.add(primitives.sphere(2), second, pose=np.diag([0.3, 0.3, 0.3, 1.0]))
    renderer.render(scene)
    objects = renderer.gl_object_count()
    renderer.render(scene)
    assert renderer.programs.textures.uploads == 1 and len(renderer.programs.textures) == 1
    assert renderer.gl_object_count() == objects  # nothing made again
    del scene, first, second
    gc.collect()
    other = glphong.Scene(camera, [glphong.PointLight((1.0, 1.0, 2.0), power=50.0)])
    other.add(primitives.sphere(2), MeasuredBRDF(np.full(merl.SHAPE + (3,), 0.3)))
    renderer.render(other)
    assert renderer.programs.textures.uploads == 2 and len(renderer.programs.textures) == 1  # the first one released


def test_uber_shader_with_a_measured_material(glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(48, 48, glphong_backend, specialise=False)
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 4.0), (0.0, 0.0, 0.0))
    scene = glphong.Scene(camera, [glphong.PointLight((1.0, 1.0, 2.0), power=50.0)])
    scene.add(primitives.sphere(2), MeasuredBRDF.example(), pose=np.diag([0.6, 0.6, 0.6, 1.0]))
    scene.add(primitives.sphere(2), glphong.Phong(0.2, 0.5, 30.0), pose=_translate(1.2, 0.0, 0.0) @ np.diag([0.5, 0.5, 0.5, 1]))
    report = glphong.verify(scene, renderer)
    assert report.passed and report.mask.sum() > 300, str(report)


def _translate(x, y, z):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def test_unmeasured_cells_and_bad_input(tmp_path):
    table = np.full(merl.SHAPE + (3,), 0.25)
    table[3, 4, 5] = np.nan
    table[6, 7, 8, 1] = np.nan
    measured = MeasuredBRDF(table)
    assert measured.unmeasured == 2 and measured.table.array[3, 4, 5].tolist() == [0, 0, 0]
    path = tmp_path / "m.binary"
    merl.write_merl(path, table)
    assert MeasuredBRDF(path).unmeasured == 2  # the file's negative markers
    with pytest.raises(ValueError, match=r"table must have shape \(90, 90, 180, 3\).*\(got \(90, 90, 3\)\)"):
        MeasuredBRDF(np.zeros((90, 90, 3)))
    negative = table.copy()
    negative[0, 0, 0, 0] = -1.0
    with pytest.raises(ValueError, match=r"table has 1 entries below 0"):
        MeasuredBRDF(negative)
    with pytest.raises(TypeError, match="table must be the path of a MERL .binary file"):
        MeasuredBRDF(object())
    (tmp_path / "short.binary").write_bytes(np.array(merl.SHAPE, "<i4").tobytes() + b"\x00" * 10)
    with pytest.raises(merl.MerlFormatError, match="truncated"):
        MeasuredBRDF(tmp_path / "short.binary")
    with pytest.raises(ValueError, match="lookup must be 'nearest' or 'trilinear'"):
        MeasuredBRDF(table, "cubic")
    with pytest.raises(TypeError, match="missing parameter 'table'|required positional argument"):
        MeasuredBRDF()


def test_analysis_of_a_measured_material(tabulated):
    """The four questions, asked of a tabulated normalised Blinn-Phong: reciprocal and isotropic by
    construction (to rounding), non-negative; the albedo of the trilinear table follows the model's."""
    from glphong import analysis

    for lookup in ("nearest", "trilinear"):
        record = analysis.properties(MeasuredBRDF(tabulated, lookup), theta_i=np.radians([0.0, 40.0, 80.0]))
        assert record.non_negative and record.reciprocal and record.isotropic and not record.disagreements
        # swapping l and v negates d = l - v exactly (bit-identical coordinates); row 0 of the table holds
        # h = n exactly, so a rotation about n changes nothing there either
        assert record.reciprocity_error < 1e-15 and record.isotropy_error == 0.0
    measured = MeasuredBRDF(tabulated, "trilinear")
    model = analysis.albedo(ANALYTIC, np.radians([0.0, 40.0, 80.0]))
    table = analysis.albedo(measured, np.radians([0.0, 40.0, 80.0]))
    np.testing.assert_allclose(table, model, rtol=5e-4)  # measured: 2.5e-4, 2.7e-4, 1.2e-4


def test_twin_of_table_entries_is_exact_at_the_samples(tabulated):
    """At the bin directions `tabulate` used (float64: the theta_h nudge of 1e-9 rad is below float32's
    resolution), the nearest lookup returns the bin's entry exactly and trilinear to 1e-6."""
    from glphong.materials import ShadingFrame

    wi, wo = merl.bin_directions()
    pick = (slice(0, 90, 7), slice(0, 90, 11), slice(0, 180, 13))
    wi, wo, want = wi[pick].reshape(-1, 3), wo[pick].reshape(-1, 3), tabulated[pick].reshape(-1, 3)
    keep = ~np.isnan(want[:, 0])
    wi, wo, want = wi[keep], wo[keep], want[keep].astype(np.float32).astype(np.float64)
    frame = ShadingFrame(np.broadcast_to([0.0, 0.0, 1.0], wi.shape))
    n_dot_l = wi[:, 2]
    for lookup, rtol in (("nearest", 0.0), ("trilinear", 1e-6)):
        material = MeasuredBRDF(tabulated, lookup)
        got = material.response(frame, wi, wo, n_dot_l, material.values()) / n_dot_l[:, None]
        np.testing.assert_allclose(got, want, rtol=rtol + 1e-15)


def test_cli_brdf_and_plots_of_a_measured_file(tmp_path, capsys):
    """``glphong brdf`` and ``glphong plot`` take a measured material by its file, like any other."""
    import json

    from glphong.tools.cli import main

    path = tmp_path / "lambert.binary"
    merl.write_merl(path, np.full(merl.SHAPE + (3,), 0.2))
    assert main(["brdf", f"MeasuredBRDF({str(path)!r})", "--json", "--directions", "60"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["non_negative"] and record["reciprocal"] and record["isotropic"]
    assert abs(record["max_albedo"] - 0.2 * np.pi) < 1e-6  # a constant table is Lambert: albedo pi f_r
    assert main(["plot", "lobe", f"MeasuredBRDF({str(path)!r})", "Lambert(0.2)", "--out", str(tmp_path / "l.png")]) == 0
    assert main(["plot", "lobe3d", f"MeasuredBRDF({str(path)!r}, 'trilinear')", "--out", str(tmp_path / "s.png")]) == 0
    assert (tmp_path / "l.png").exists() and (tmp_path / "s.png").exists()
