"""The work-precision report's plumbing on a tiny configuration (the full sweep is a benchmark)."""
import csv
import subprocess
import sys
import json

import numpy as np
import pytest

from glphong.bench import BenchCase, Method, continuous_methods, methods, quick_cases, run_bench


@pytest.fixture(scope="module")
def tiny_report():
    cases = [BenchCase("phong", 100.0, 1)]
    chosen = [m for m in methods(quick=True) if m.kind in ("glphong", "twin", "floor")]
    chosen = [Method(m.name, m.knob, m.values, m.kind, m.options) for m in chosen]
    return run_bench(64, 48, cases=cases, method_list=chosen, repeats=1, reference_samples=2,
                     scaling=True, targets=True, progress=False)


def test_every_method_and_knob_produces_a_point(tiny_report):
    got = {(p["method"], p["knob_value"]) for p in tiny_report.points}
    want = {(m.name, v) for m in methods(quick=True) if m.kind != "pyrender" for v in m.values}
    want |= {(name, v) for name, _, values, _, _ in continuous_methods(quick=True) for v in values}
    assert got == want
    for p in tiny_report.points:
        assert p["seconds"] > 0 and np.isfinite(p["relative_rms"]) and p["interior_pixels"] > 100


def test_area_lights_against_their_exact_integrals(tiny_report):
    err = {(p["method"], p["knob_value"], p["case"]): p["relative_rms"] for p in tiny_report.points}
    closed = [e for (m, _, _), e in err.items() if m.startswith("area light, closed")]
    sampled = {k: e for (m, k, _), e in err.items() if m.startswith("area light, sampled")}
    assert closed and max(closed) < 1e-5  # Lambert's edge formula and Arvo's recurrence: float32 rounding only
    assert sampled[2] < sampled[1] and sampled[1] > 1e-3  # the midpoint rule converges from a visible error


def test_errors_behave_as_the_methods_promise(tiny_report):
    err = {(p["method"], p["knob_value"]): p["relative_rms"] for p in tiny_report.points}
    pixel = "per-pixel GLSL, EGL"
    assert err[(pixel, 4)] < err[(pixel, 2)]  # finer tessellation converges
    assert err[("Gouraud GLSL, EGL", 2)] > err[(pixel, 2)]  # per-vertex shading is less accurate
    # the twins shade the same G-buffer: the same error as the GPU up to float32 rounding
    for dtype in ("float32", "float64"):
        twin = err[(f"numpy twin {dtype} (on the GPU G-buffer)", 4)]
        assert twin == pytest.approx(err[(pixel, 4)], rel=1e-3)
    assert err[("hand-written moderngl floor, EGL", 4)] == pytest.approx(err[(pixel, 4)], rel=1e-6)
    assert err[("per-pixel GLSL, OSMesa", 4)] == pytest.approx(err[(pixel, 4)], rel=1e-6)


def test_tables_and_files(tiny_report, tmp_path):
    axes = {row["axis"] for row in tiny_report.scaling}
    assert axes == {"pixels", "triangles", "lights"}
    names = " ".join(t["name"] for t in tiny_report.targets)
    assert "hand-written moderngl floor" in names and "throughput" in names
    text = tiny_report.format_tables()
    assert "work-precision points" in text and "scaling" in text
    paths = tiny_report.write(str(tmp_path / "b"))
    rows = list(csv.DictReader(open(paths[0])))
    assert len(rows) == len(tiny_report.points)
    data = json.load(open(paths[1]))
    assert {"points", "curves", "scaling", "targets", "matte"} <= set(data)
    from PIL import Image

    assert Image.open(paths[2]).size[0] > 400  # the work-precision diagram


def test_quick_cases_and_pyrender_reported_when_missing(monkeypatch):
    assert len(quick_cases()) == 2
    only_pyrender = [m for m in methods(quick=True) if m.kind == "pyrender"]
    monkeypatch.setitem(__import__("sys").modules, "pyrender", None)  # import pyrender -> ImportError
    report = run_bench(32, 24, cases=quick_cases()[:1], method_list=only_pyrender, repeats=1, reference_samples=1,
                       scaling=False, targets=False, progress=False, continuous=False, matte=False)
    assert report.points == [] and "pyrender is not installed" in report.skipped[0]


def test_speed_report_in_process(tmp_path):
    """The speed family's machinery on small stand-ins (no pyrender in this process: it fixes PyOpenGL's
    platform): a row per scene with positive times and spreads, Python overhead, PNG cost and fits."""
    import json

    from glphong.bench import SCENES, run_speed

    report = run_speed(sizes=(32,), repeats=3, quick=True, pyrender=False, progress=False)
    assert [r["scene"] for r in report.rows] == list(SCENES)
    for row in report.rows:
        assert set(row["ms"]) == {"glphong float", "glphong stable", "naive floor", "glphong 4x 8-bit"}
        assert all(v > 0 for v in row["ms"].values()) and all(v >= 0 for v in row["spread"].values())
    assert report.rows[SCENES.index("1000 objects")]["objects"] == 100  # the quick stand-in
    assert report.python_per_object["objects"] == 100 and report.png["save_ms"] > 0 and report.png["encode_ms"] > 0  # positive: no timing compared in a test
    assert set(report.fits) == {"per object", "per pixel and light", "per triangle"}
    text = report.format()
    assert all(name in text for name in SCENES) and "Python per object" in text
    assert json.loads(report.to_json())["rows"][0]["size"] == 32


def test_cli_bench_speed_quick(tmp_path):
    """``glphong bench --speed --quick`` in its own process (pyrender on EGL where installed)."""
    out = subprocess.run([sys.executable, "-m", "glphong", "bench", "--speed", "--quick", "--no-progress",
                          "--out", str(tmp_path / "s")], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    assert "float/floor" in out.stdout and (tmp_path / "s_speed.json").exists()


def test_matte_rows_error_against_time(tiny_report, tmp_path, capsys):
    """The matte pass's row family (glphong.bench.matte): every scene at s = 4 and 32 within its tolerance, the
    default within 1/64; ``glphong bench --matte --quick`` prints the table and writes the rows."""
    from glphong.bench.matte import matte_scenes
    from glphong.tools.cli import main

    rows = tiny_report.matte
    assert {(r["case"], r["matte_samples"]) for r in rows} == {(c, s) for c in matte_scenes() for s in (4, 32)}
    for r in rows:
        assert r["seconds"] > 0 and r["radiance_seconds"] > 0 and 0 < r["worst"] <= r["tolerance"]
        assert r["rms"] <= r["worst"]
    assert max(r["worst"] for r in rows if r["matte_samples"] == 32) <= 1 / 64
    assert "matte: error against the exact coverage" in tiny_report.format_tables()
    assert main(["bench", "--matte", "--quick", "--repeats", "1", "--out", str(tmp_path / "b")]) == 0
    assert "1/worst" in capsys.readouterr().out
    assert len(json.load(open(tmp_path / "b_matte.json"))) == len(rows)
