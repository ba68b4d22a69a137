"""The soak in the suite (issue 42; docs/long_runs.md): ``benchmarks/soak.py`` at reduced counts, in a fresh process.

- 10^4 frames on EGL and 2 x 10^3 on OSMesa, one renderer, a new scene every frame (materials, lights, poses, the
  camera, a new mesh; the image size changed every 1000 frames, depth and normals every 7th frame), 16 x 16 pixels:
  after the warm-up (2000 frames; 1000 on OSMesa) resident memory within `BAND_MIB`, descriptors, threads, live
  renderers and GL objects unchanged at every sample, every sampled frame's cross-check passed, and scene 0 rendered
  again (at every sample at the first size, at the end, and by a new renderer) bit-identical to its first render;
- 100 renderers made and released (every tenth dropped) and 100 contexts made and destroyed, both backends in turn:
  descriptors and threads unchanged, nothing left alive but the pooled contexts;
- a planted leak (every scene kept alive) is caught by the same measures;
- `glphong.gpu.counters.gl_objects_alive` counts a renderer and its objects while it lives, nothing after
  ``release()``, and a dropped renderer as an orphan until the next glphong call.
"""
import json
import subprocess
import sys
from pathlib import Path

import pytest

SOAK = Path(__file__).resolve().parent.parent / "benchmarks" / "soak.py"
#: resident memory may move by this much after warm-up [MiB]: a leak of 0.5 KiB a frame over the 8000 frames after
#: EGL's warm-up would exceed it (the 10^5-frame soak: a band of 2.2 MiB, a trend of 7 bytes a frame; docs/long_runs.md)
BAND_MIB = 4.0
NO_BATCHES = ("--workers", "0", "--dask", "0")


def _soak(tmp_path, *args):
    """Run ``benchmarks/soak.py`` with ``args`` in a fresh process: its JSON report."""
    out = tmp_path / "soak.json"
    run = subprocess.run([sys.executable, str(SOAK), *args, "--json", str(out), "--quiet"], capture_output=True,
                         text=True, timeout=900, cwd=tmp_path)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-3000:]
    return json.loads(out.read_text())


@pytest.mark.parametrize("backend, frames, warmup", [("egl", 10_000, 2000), ("osmesa", 2000, 1000)])
def test_frames_with_a_new_scene_each_grow_nothing(backend, frames, warmup, make_context, tmp_path):
    make_context(backend).release()
    report = _soak(tmp_path, "--frames", str(frames), "--size", "16", "16", "--backend", backend, "--sample-every",
                   "500", "--resize-every", "1000", "--warmup", str(warmup), "--renderers", "0", "--contexts", "0",
                   *NO_BATCHES)["frames"]
    assert report["backend"] == backend and report["frames"] == frames
    assert report["cross_checks"] == frames // 500 and report["cross_checks_failed"] == 0
    after = [s for s in report["samples"] if s["frame"] >= warmup]
    assert len(after) >= 3 and len({tuple(s["size"]) for s in after}) >= 2  # the size did change
    for key in ("fds", "threads", "renderers", "gl_objects", "pooled_contexts", "orphans"):
        assert {s[key] for s in after} == {after[0][key]}, (key, [s[key] for s in after])
    rss = [s["rss_mib"] for s in after]
    assert max(rss) - min(rss) < BAND_MIB, rss
    assert report["first_frame_compared_at_samples"] >= 2 and report["first_frame_differed_at_samples"] == 0
    assert report["first_frame_identical"] and report["first_frame_identical_new_renderer"]


def test_renderers_and_contexts_made_and_released_leave_nothing(make_context, tmp_path):
    make_context("egl").release()
    make_context("osmesa").release()
    report = _soak(tmp_path, "--frames", "0", "--renderers", "100", "--contexts", "100", "--size", "16", "16",
                   "--backends", "egl,osmesa", *NO_BATCHES)
    for phase in ("renderers", "contexts"):
        samples = report[phase]["samples"]
        for key in ("fds", "threads"):
            assert {s[key] for s in samples} == {samples[0][key]}, (phase, key, [s[key] for s in samples])
        end = samples[-1]
        assert end["renderers"] == 0 and end["gl_objects"] == 0 and end["orphans"] == 0, (phase, end)
        assert end["pooled_contexts"] <= 8  # at most glphong.gpu.contexts.POOL_SIZE per backend
    # a destroyed context keeps some driver memory (about 0.05 MiB with plain moderngl, docs/threads.md): bounded
    assert report["contexts"]["mib_per_context"] < 0.2, report["contexts"]["whole"]


_LEAK = r'''
import importlib.util, json, sys
spec = importlib.util.spec_from_file_location("soak", sys.argv[1])
soak = importlib.util.module_from_spec(spec)
spec.loader.exec_module(soak)
kept, made = [], soak.scene
soak.scene = lambda i: kept.append(made(i)) or kept[-1]         # every scene kept alive: its meshes stay uploaded
with soak.glphong.Renderer(16, 16) as r:
    first = r.render(soak.scene(0), depth=True, normals=True)
report = soak.frames_phase(600, 16, 16, "auto", 100, 1000, 100, lambda m: None, first)
print(json.dumps(report["after_warmup"]))
'''


def test_a_planted_leak_is_caught(make_context):
    make_context("egl").release()
    out = subprocess.run([sys.executable, "-c", _LEAK, str(SOAK)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    grown = json.loads(out.stdout.strip().splitlines()[-1])
    assert grown["gl_objects_change"] >= 500, grown  # a new mesh each of the 500 frames after warm-up, kept


def test_gl_objects_alive_counts_renderers_objects_and_orphans(glphong_backend):
    import gc
    import warnings

    import glphong
    from glphong import primitives
    from glphong.gpu.counters import gl_objects_alive

    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)),
                          lights=[glphong.PointLight((1, 1, 2), 50.0)])
    scene.add(primitives.sphere(2), glphong.Phong(0.2, 0.5, 20.0))
    before = gl_objects_alive()
    renderer = glphong.Renderer(8, 8, backend=glphong_backend)
    renderer.render(scene)
    during = gl_objects_alive()
    assert during.renderers == before.renderers + 1
    assert during.objects >= before.objects + 4  # a program, a target and its attachment, the mesh's buffers
    renderer.release()
    assert gl_objects_alive()[:2] == before[:2]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResourceWarning)
        dropped = glphong.Renderer(8, 8, backend=glphong_backend)
        dropped.render(scene)
        del dropped
        gc.collect()
    assert gl_objects_alive().orphans == before.orphans + 1
    glphong.Renderer(1, 1, backend=glphong_backend).release()  # any glphong call releases the orphans
    assert gl_objects_alive().orphans == 0 and gl_objects_alive()[:2] == before[:2]
