"""Batches of frames (`glphong.batch.render_many`): worker processes started with 'spawn', frames written
atomically with a manifest, resumed, never mixed, and a worker killed mid-batch costs no frame.

- 6 turntable frames from a 2-worker pool equal a serial render in this process, bit for bit;
- a rerun renders nothing (every frame on disk), one deleted frame is rendered again and is identical;
- another batch in the same folder is refused; a spec that cannot be pickled is refused;
- a scene function that kills its worker the first time it meets spec 3 (a marker file says so): every
  frame is present once, identical to the serial render, and no partial file is left (the folder holds
  the frames, the manifest, the journal ``frames.jsonl`` and the lock ``.lock``).

Hostile folders (racing batches, a killed parent, symbolic links, corrupted frames): test_hostile_batch.py.
"""
import os
import sys
import textwrap

import numpy as np
import pytest

import glphong
from glphong.batch import BatchError, render_many, turntable_scene

W, H = 48, 32
ANGLES = [0.0, 30.0, 60.0, 90.0, 120.0, 150.0]
BOOKKEEPING = ["manifest.json", "frames.jsonl", ".lock"]


@pytest.fixture(scope="module")
def serial():
    with glphong.Renderer(W, H) as renderer:
        return [renderer.render(turntable_scene(a)).radiance.copy() for a in ANGLES]


def _frames(paths):
    return [np.load(p) for p in paths]


def test_pool_frames_equal_serial_and_resume(tmp_path, serial):
    out = tmp_path / "frames"
    paths = render_many(turntable_scene, ANGLES, W, H, out, workers=2, frames_per_task=2, progress=False)
    assert [os.path.basename(p) for p in paths] == [f"frame_{i:06d}.npy" for i in range(6)]
    assert all(np.array_equal(a, b) for a, b in zip(_frames(paths), serial))
    manifest = (out / "manifest.json").read_text()
    assert "llvmpipe" in manifest and glphong.__version__ in manifest
    assert len((out / "frames.jsonl").read_text().splitlines()) == len(ANGLES)  # one record per frame
    stamp = {p: os.stat(p).st_mtime_ns for p in paths}
    os.remove(paths[4])
    again = render_many(turntable_scene, ANGLES, W, H, out, workers=1, progress=False)
    assert again == paths and np.array_equal(np.load(paths[4]), serial[4])
    assert all(os.stat(p).st_mtime_ns == stamp[p] for p in paths if p != paths[4])  # the others untouched
    with pytest.raises(BatchError, match="holds another batch .*specs"):
        render_many(turntable_scene, ANGLES[:3], W, H, out, workers=1, progress=False)
    with pytest.raises(BatchError, match="cannot be pickled"):
        render_many(turntable_scene, [lambda: 0], W, H, tmp_path / "other", workers=1, progress=False)


def test_frame_passes_in_a_batch(tmp_path, serial):
    """fmt='npz' writes each frame's passes (glphong.datasets.save_npz), equal to a serial render's; the passes are
    part of the batch (another set in the same folder is another batch); flow, which needs a second scene, and
    passes with a radiance-only format are refused by name."""
    from glphong.datasets import load_npz
    out = tmp_path / "passes"
    passes = ("radiance", "depth", "instance")
    paths = render_many(turntable_scene, ANGLES[:3], W, H, out, fmt="npz", passes=passes, workers=1, progress=False)
    with glphong.Renderer(W, H) as renderer:
        for angle, path, radiance in zip(ANGLES, paths, serial):
            arrays, frame = load_npz(path), renderer.render(turntable_scene(angle), passes=passes)
            assert np.array_equal(arrays["radiance"], radiance) and np.array_equal(arrays["depth"], frame.depth)
            assert arrays["instance"].dtype == np.uint32 and np.array_equal(arrays["instance"], frame.instance)
    with pytest.raises(BatchError, match="holds another batch"):
        render_many(turntable_scene, ANGLES[:3], W, H, out, fmt="npz", passes=("depth",), workers=1, progress=False)
    with pytest.raises(ValueError, match="flow need the next or previous scene"):
        render_many(turntable_scene, ANGLES, W, H, tmp_path / "flow", fmt="npz", passes=("flow",), progress=False)
    with pytest.raises(ValueError, match="holds the radiance alone"):
        render_many(turntable_scene, ANGLES, W, H, tmp_path / "png", fmt="png", passes=("depth",), progress=False)


def _dying_module(tmp_path, name):
    """Write and import module ``name`` in ``tmp_path``: its ``dying_scene`` kills its process (``os._exit``)
    the first time it meets the angle 90 (a marker file remembers), else builds the turntable scene."""
    (tmp_path / f"{name}.py").write_text(textwrap.dedent(f"""
        import os
        from glphong.batch import turntable_scene

        MARKER = {str(tmp_path / "died")!r}

        def dying_scene(angle):
            if angle == 90.0 and not os.path.exists(MARKER):
                open(MARKER, "w").close()
                os._exit(9)  # the worker dies mid-batch, without cleaning up
            return turntable_scene(angle)
    """))
    sys.path.insert(0, str(tmp_path))
    return __import__(name)


def test_a_killed_worker_costs_no_frame(tmp_path, serial):
    try:
        module = _dying_module(tmp_path, "batch_helper_kill")
        out = tmp_path / "frames"
        paths = render_many(module.dying_scene, ANGLES, W, H, out, workers=2, progress=False)
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("batch_helper_kill", None)
    assert (tmp_path / "died").exists()  # it did die
    assert all(np.array_equal(a, b) for a, b in zip(_frames(paths), serial))
    assert sorted(os.listdir(out)) == sorted([os.path.basename(p) for p in paths] + BOOKKEEPING)


def test_example_batch_turntable(tmp_path, load_example):
    example = load_example("batch_turntable")
    paths = example.main(frames=4, out_dir=str(tmp_path / "t"), size=24)
    assert len(paths) == 4 and all(np.load(p).shape == (24, 24, 3) for p in paths)


def test_dask_cluster_with_a_killed_worker(tmp_path, serial):
    """The same batch on a two-worker Dask LocalCluster (executor='dask'), one worker killed the first time
    it meets spec 3: Dask reschedules it, every frame is present once and equal to the serial render."""
    pytest.importorskip("distributed", reason="dask.distributed is not installed (pip install 'glphong[dask]')")
    os.environ["PYTHONPATH"] = os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])
    try:
        module = _dying_module(tmp_path, "batch_helper_dask")

        paths = render_many(module.dying_scene, ANGLES, W, H, tmp_path / "frames", executor="dask",
                            workers=2, progress=False)
    finally:
        sys.path.remove(str(tmp_path))
        os.environ["PYTHONPATH"] = os.environ["PYTHONPATH"].split(os.pathsep, 1)[1]
        if not os.environ["PYTHONPATH"]:
            del os.environ["PYTHONPATH"]
        sys.modules.pop("batch_helper_dask", None)
    assert (tmp_path / "died").exists()
    assert all(np.array_equal(a, b) for a, b in zip(_frames(paths), serial))
    assert sorted(os.listdir(tmp_path / "frames")) == sorted([os.path.basename(p) for p in paths] + BOOKKEEPING)


def test_a_scene_function_that_kills_every_worker_stops_the_batch(tmp_path):
    """A pool broken three times in a row without a frame written is a batch that cannot finish: it stops with
    the reason instead of making pools forever."""
    (tmp_path / "batch_helper_always_dies.py").write_text("import os\n\ndef always_dies(angle):\n    os._exit(7)\n")
    sys.path.insert(0, str(tmp_path))
    try:
        module = __import__("batch_helper_always_dies")
        with pytest.raises(BatchError, match="died 3 times in a row without writing a frame"):
            render_many(module.always_dies, ANGLES[:2], W, H, tmp_path / "frames", workers=1, progress=False)
    finally:
        sys.path.remove(str(tmp_path))
