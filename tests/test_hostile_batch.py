"""Batches in folders that are not what they seem (`glphong.batch.render_many`): never mixed, never orphaned.

- two different batches started at the same instant in one fresh folder (two interpreters released by one
  marker file): exactly one renders, the other fails with `BatchError`, and every frame is the winner's;
- a batch started while another runs in its folder (the same batch or another) is refused;
- frame files without a manifest (a batch that crashed before manifests were written first, or foreign
  files) are refused, not adopted;
- a batch whose parent is killed (``SIGKILL``) mid-batch: within 15 s none of its workers and not its
  resource tracker is left; a different batch is then refused, and the same batch resumes, keeping the
  journalled frames and rendering the rest, identical to a serial render;
- a frame or the manifest replaced by a symbolic link: `BatchError` naming it;
- a frame corrupted (bytes changed), truncated, or without its journal record: rendered again.

Frames are 16x16 turntable frames; the tests that need no worker process run the tasks in this process
(`InlineExecutor`), the folder's bookkeeping being the same for every executor.
"""
import json
import os
import resource
import shutil
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import glphong
import glphong.batch
from glphong.testing import InlineExecutor
from glphong.batch import BatchError, render_many, turntable_scene

pytestmark = pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="POSIX processes and signals")

W = H = 16
ANGLES = [0.0, 30.0, 60.0, 90.0, 120.0, 150.0]
OTHER_ANGLES = [45.0, 135.0, 225.0, 315.0]
ORPHAN_LIMIT_S = 15.0


@pytest.fixture(scope="module", autouse=True)
def release_inline_renderers():
    """Release the renderers `InlineExecutor` tasks kept in this process (a worker keeps its own)."""
    yield
    while glphong.batch._WORKER:
        glphong.batch._WORKER.popitem()[1].release()


@pytest.fixture(scope="module")
def serial():
    """``{angle: radiance}``, rendered here, for every angle the tests use."""
    with glphong.Renderer(W, H) as renderer:
        return {a: renderer.render(turntable_scene(a)).radiance.copy() for a in ANGLES + OTHER_ANGLES}


def _inline_batch(out, angles=ANGLES, before=None):
    return render_many(turntable_scene, angles, W, H, out, executor=InlineExecutor(before), progress=False)


def _assert_frames(paths, angles, serial):
    assert len(paths) == len(angles)
    for path, angle in zip(paths, angles):
        assert np.array_equal(np.load(path), serial[angle]), path


def _popen(code, *args, cwd, stdout=subprocess.PIPE, pythonpath=None):
    """A fresh interpreter running ``code`` under a 3 GiB address-space limit (as ``run_isolated``)."""

    def limit():  # in the child, before exec: a runaway allocation fails instead of taking the machine
        resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))

    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", PYTHONUNBUFFERED="1")
    if pythonpath:
        env["PYTHONPATH"] = os.pathsep.join(p for p in (pythonpath, os.environ.get("PYTHONPATH")) if p)
    return subprocess.Popen([sys.executable, "-c", code, *args], stdout=stdout, stderr=subprocess.STDOUT, text=True,
                            preexec_fn=limit, cwd=cwd, env=env)


def _children(pid):
    """The `psutil.Process` descendants of ``pid`` (none where psutil is missing or ``pid`` is gone)."""
    try:
        import psutil

        return psutil.Process(pid).children(recursive=True)
    except Exception:  # noqa: BLE001 - ImportError, psutil.NoSuchProcess
        return []


def _end_all(processes):
    """SIGKILL each `psutil.Process` still running (psutil checks that the pid is still that process)."""
    import psutil

    for process in processes:
        try:
            process.kill()
        except psutil.NoSuchProcess:
            pass


def _end(popen):
    """SIGKILL the `subprocess.Popen` ``popen`` where it still runs, its descendants too, and reap it."""
    if popen.poll() is None:
        children = _children(popen.pid)
        popen.kill()
        popen.wait(timeout=30)
        if children:
            _end_all(children)


RACER = textwrap.dedent("""
    import os, sys, time
    from glphong.batch import BatchError, render_many, turntable_scene

    out, angles, go, ready = sys.argv[1], [float(a) for a in sys.argv[2].split(",")], sys.argv[3], sys.argv[4]
    open(ready, "w").close()
    while not os.path.exists(go):
        time.sleep(0.002)
    try:
        render_many(turntable_scene, angles, 16, 16, out, workers=1, progress=False)
    except BatchError as exc:
        print("BatchError:", exc)
        sys.exit(3)
    print("rendered")
""")


def test_two_batches_started_together_never_mix(tmp_path, serial):
    out, go = tmp_path / "frames", tmp_path / "go"
    batches = {"six": ANGLES, "four": OTHER_ANGLES}
    racers = {}
    try:
        for name, angles in batches.items():
            racers[name] = _popen(RACER, str(out), ",".join(map(str, angles)), str(go), str(tmp_path / name),
                                  cwd=tmp_path)
        deadline = time.monotonic() + 60
        while not all((tmp_path / name).exists() for name in batches):
            assert time.monotonic() < deadline and all(r.poll() is None for r in racers.values()), "no start"
            time.sleep(0.01)
        go.touch()  # both interpreters are waiting: release them together
        results = {name: racer.communicate(timeout=90)[0] for name, racer in racers.items()}
        results = {name: (racers[name].returncode, text) for name, text in results.items()}
    finally:
        for racer in racers.values():
            _end(racer)
    winners = [name for name, (code, _) in results.items() if code == 0]
    losers = [name for name, (code, text) in results.items() if code == 3 and "BatchError" in text]
    assert len(winners) == 1 and len(losers) == 1, results
    loser_text = results[losers[0]][1]
    assert "another batch is running" in loser_text or "holds another batch" in loser_text, loser_text
    angles = batches[winners[0]]
    paths = [str(out / f"frame_{i:06d}.npy") for i in range(len(angles))]
    assert sorted(p for p in os.listdir(out) if p.startswith("frame_")) == [os.path.basename(p) for p in paths]
    _assert_frames(paths, angles, serial)
    assert json.loads((out / "manifest.json").read_text())["specs"] == [glphong.batch._spec_hash(a) for a in angles]


def test_a_batch_is_refused_while_another_runs_there(tmp_path):
    out = tmp_path / "frames"
    refused = []

    def start_another(task):
        if task == 0:
            for angles in (ANGLES, OTHER_ANGLES):  # the same batch, and another
                with pytest.raises(BatchError, match="another batch is running in") as info:
                    _inline_batch(out, angles)
                refused.append(str(info.value))

    _inline_batch(out, before=start_another)
    assert len(refused) == 2 and all(str(out) in message for message in refused)
    assert len(_inline_batch(out)) == len(ANGLES)  # the lock went with the batch


def test_frames_without_a_manifest_are_refused(tmp_path):
    out = tmp_path / "frames"
    out.mkdir()
    np.save(out / "frame_000000.npy", np.zeros((H, W, 3), np.float32))  # a batch that died before its manifest
    with pytest.raises(BatchError, match="frame_000000.npy but no manifest.json"):
        _inline_batch(out)
    assert sorted(os.listdir(out)) == [".lock", "frame_000000.npy"]  # nothing adopted, nothing written


BLOCKING_MODULE = """
import os
import time

from glphong.batch import turntable_scene

GO = {go!r}


def blocking_scene(angle):
    '''The turntable scene; from 60 degrees on, it waits until the file GO exists (a batch to kill).'''
    while angle >= 60.0 and not os.path.exists(GO):
        time.sleep(0.05)
    return turntable_scene(angle)
"""

KILLED_PARENT = textwrap.dedent("""
    import sys
    from glphong.batch import render_many
    from hostile_blocking import blocking_scene

    render_many(blocking_scene, [0.0, 30.0, 60.0, 90.0, 120.0, 150.0], 16, 16, sys.argv[1], workers=2,
                progress=False)
""")


def _journal_lines(out):
    try:
        return (out / "frames.jsonl").read_text().count("\n")
    except FileNotFoundError:
        return 0


def _alive(process):
    """Whether a `psutil.Process` still runs (a zombie waiting for its new parent to reap it does not)."""
    import psutil

    try:
        return process.is_running() and process.status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


def _wait_for_frames(parent, out, count, log, timeout=60):
    """Wait until the batch in ``out`` journalled ``count`` frames (the others block)."""
    deadline = time.monotonic() + timeout
    while _journal_lines(out) < count:
        if parent.poll() is not None or time.monotonic() > deadline:
            pytest.fail(f"the batch to kill did not get to {count} frames:\n{log.read_text()}")
        time.sleep(0.05)


@pytest.fixture(scope="module")
def killed_batch(tmp_path_factory):
    """A batch of `ANGLES` whose parent was killed (``SIGKILL``) with frames 0 and 1 done and its two workers
    blocked on frames 2 and 3; ``(folder, module folder, {process: its command line}, seconds until none
    was left, the processes left after ORPHAN_LIMIT_S)``.  Every process left is killed at the end."""
    psutil = pytest.importorskip("psutil", reason="psutil lists a process's children")
    root = tmp_path_factory.mktemp("killed")
    (root / "hostile_blocking.py").write_text(BLOCKING_MODULE.format(go=str(root / "go")))
    out, log = root / "frames", root / "parent.log"
    processes = []
    with open(log, "w") as stream:
        parent = _popen(KILLED_PARENT, str(out), cwd=root, stdout=stream, pythonpath=str(root))
    try:
        _wait_for_frames(parent, out, 2, log)
        time.sleep(0.3)  # both workers are in blocking_scene now
        processes = psutil.Process(parent.pid).children(recursive=True)
        commands = {p: " ".join(p.cmdline()) for p in processes}
        parent.send_signal(signal.SIGKILL)
        parent.wait(timeout=30)
        killed = time.monotonic()
        while any(_alive(p) for p in processes) and time.monotonic() - killed < ORPHAN_LIMIT_S:
            time.sleep(0.05)
        seconds = time.monotonic() - killed
        left = [p for p in processes if _alive(p)]
        (root / "go").touch()  # from now on blocking_scene does not block
        yield out, root, commands, seconds, left
    finally:
        _end(parent)  # its descendants too, where the test failed before it was killed
        _end_all(processes)


def test_killed_parent_leaves_no_worker_and_no_resource_tracker(killed_batch):
    _, _, commands, seconds, left = killed_batch
    assert sum("spawn_main" in c for c in commands.values()) == 2, commands  # the two workers
    assert sum("resource_tracker" in c for c in commands.values()) == 1, commands
    assert not left, f"left {ORPHAN_LIMIT_S} s after the parent was killed: {[commands[p] for p in left]}"
    print(f"none of the {len(commands)} processes of the batch left {seconds:.2f} s after SIGKILL of its parent")


def test_killed_batch_is_refused_to_another_and_resumed_by_itself(killed_batch, tmp_path, serial):
    killed, root, *_ = killed_batch
    with pytest.raises(BatchError, match="holds another batch .*specs"):
        _inline_batch(killed, ANGLES[:3])
    out = tmp_path / "frames"
    shutil.copytree(killed, out)
    done = sorted(p for p in os.listdir(out) if p.startswith("frame_"))
    assert _journal_lines(out) == 2 and done == ["frame_000000.npy", "frame_000001.npy"]
    stamps = {name: os.stat(out / name).st_mtime_ns for name in done}
    sys.path.insert(0, str(root))
    try:
        from hostile_blocking import blocking_scene

        paths = render_many(blocking_scene, ANGLES, W, H, out, workers=1, progress=False)
    finally:
        sys.path.remove(str(root))
        sys.modules.pop("hostile_blocking", None)
    _assert_frames(paths, ANGLES, serial)
    assert {name: os.stat(out / name).st_mtime_ns for name in stamps} == stamps  # the journalled frames kept
    assert not [p for p in os.listdir(out) if p.startswith(".partial-")]
    assert json.loads((out / "manifest.json").read_text())["renderer"]  # named by the first frame back


def test_a_symbolic_link_for_a_frame_or_the_manifest_is_refused(tmp_path):
    out = tmp_path / "frames"
    paths = _inline_batch(out)
    elsewhere = tmp_path / "elsewhere.npy"
    shutil.copy(paths[2], elsewhere)
    os.remove(paths[2])
    os.symlink(elsewhere, paths[2])
    with pytest.raises(BatchError, match=r"frame_000002\.npy \(a frame\) is a symbolic link"):
        _inline_batch(out)
    os.replace(elsewhere, paths[2])
    manifest = out / "manifest.json"
    os.replace(manifest, tmp_path / "manifest.json")
    os.symlink(tmp_path / "manifest.json", manifest)
    with pytest.raises(BatchError, match=r"manifest\.json \(the batch manifest\) is a symbolic link"):
        _inline_batch(out)


def test_corrupted_truncated_or_unrecorded_frames_are_rendered_again(tmp_path, serial):
    out = tmp_path / "frames"
    paths = _inline_batch(out)
    data = bytearray(open(paths[1], "rb").read())
    data[-5] ^= 0x40  # one bit of the last pixel, the size unchanged
    with open(paths[1], "r+b") as stream:
        stream.write(data)
    with open(paths[3], "r+b") as stream:
        stream.truncate(100)
    journal = (out / "frames.jsonl").read_text().splitlines(keepends=True)
    (out / "frames.jsonl").write_text("".join(line for line in journal if json.loads(line)["index"] != 4) +
                                      '{"index": 0, "size": 1')  # and a record cut short by a crash
    stamps = [os.stat(p).st_mtime_ns for p in paths]
    time.sleep(0.01)
    again = _inline_batch(out)
    assert again == paths
    _assert_frames(paths, ANGLES, serial)
    changed = [i for i, p in enumerate(paths) if os.stat(p).st_mtime_ns != stamps[i]]
    assert changed == [1, 3, 4]
    records = [json.loads(line) for line in (out / "frames.jsonl").read_text().splitlines()]
    assert sorted(r["index"] for r in records) == list(range(len(ANGLES)))
