"""Faults in long runs (issue 42, "Bad input and faults"): each gives a clear error, keeps what was done, leaves no
frame half-written and nothing running, and a rerun of the same batch resumes.

- a `Renderer` used after ``release()``: `RendererReleasedError` naming the call, for every public call;
- a bad scene file in a batch's list (an MTL ``Kd -0.5 0 0``, from a worker process): `FramesFailedError` naming
  the frame, its spec, the file and the line; every other frame written and journalled; the file fixed, a rerun
  renders that frame alone;
- a driver error mid-batch (``GLContext.check_error`` made to report ``GL_OUT_OF_MEMORY`` at the 3rd frame): the
  frame named, the worker's renderer made again, the frames after it rendered, a rerun completes;
- a full disk (the frame's write made to fail with ``ENOSPC`` half-way): the file, the free space and the bytes
  needed named, no partial file, the batch stopped, a rerun completes;
- SIGINT to the process group of a running batch (what Ctrl-C in a terminal sends): the batch exits within seconds,
  no process of the group is left, no partial file, the journal matches the frames, a rerun renders the rest;
- a worker that is SIGKILLed whenever it meets one frame (the OOM killer's signal): a warning naming the frames in
  flight and SIGKILL, that frame rendered alone on a new pool, killed again, failed by name; every other frame
  rendered; it does not hang;
- ``out_dir`` an existing file, or under one: `BatchError`, not FileExistsError;
- a texture beyond the context's ``GL_MAX_TEXTURE_SIZE`` (the limit lowered in the store) or beyond the memory
  available: a ValueError naming the texture and the limit before any upload.

Expected messages are the conditions themselves (the frame index, the file, the errno), not the code's output.
"""
import errno
import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import glphong
from glphong.batch import BatchError, FramesFailedError, render_many, turntable_scene
from glphong.batch.scenes import orbit_scene
from glphong.gpu.contexts import GLContext
from glphong.gpu.renderer import RendererReleasedError
from glphong.scene import primitives
from glphong.testing import InlineExecutor

W, H = 24, 16
TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"


def _journal(out):
    return {json.loads(line)["index"] for line in (out / "frames.jsonl").read_text().splitlines()}


def _partials(out):
    return [name for _, _, names in os.walk(out) for name in names if ".partial-" in name]


def test_a_released_renderer_names_the_call(glphong_backend):
    scene = turntable_scene(0)
    renderer = glphong.Renderer(8, 8, backend=glphong_backend)
    renderer.render(scene)
    renderer.release()
    renderer.release()  # idempotent
    calls = {"render()": lambda: renderer.render(scene), "render_srgb8()": lambda: renderer.render_srgb8(scene),
             "gbuffer()": lambda: renderer.gbuffer(scene), "silhouettes()": lambda: renderer.silhouettes(scene),
             "resize()": lambda: renderer.resize(4, 4), "backend": lambda: renderer.backend,
             "__enter__() (a `with` block)": lambda: renderer.__enter__()}
    for name, call in calls.items():
        with pytest.raises(RendererReleasedError) as info:
            call()
        assert str(info.value).startswith(f"Renderer.{name} called after release(): ")
    with pytest.raises(RendererReleasedError, match=r"Renderer\.render\(\)"):
        glphong.verify(scene, renderer)
    assert repr(renderer).endswith("released)") and renderer.gl_object_count() == 0


def _scene_files(folder, kd):
    (folder / "good.obj").write_text(TRIANGLE)
    (folder / "bad.mtl").write_text(f"newmtl m\nKd {kd}\n")
    (folder / "bad.obj").write_text("mtllib bad.mtl\nusemtl m\n" + TRIANGLE)
    return [(str(folder / name), angle) for name, angle in (("good.obj", 0), ("bad.obj", 0), ("good.obj", 40),
                                                            ("good.obj", 80))]


def test_a_bad_scene_file_in_the_list_fails_its_frame_alone(tmp_path):
    specs = _scene_files(tmp_path, "-0.5 0 0")
    out = tmp_path / "frames"
    with pytest.raises(FramesFailedError) as info:
        render_many(orbit_scene, specs, W, H, out, workers=2, progress=False)
    message = str(info.value)
    assert "1 of 4 frame(s) failed" in message and "frame 1 " in message and "bad.obj" in message
    assert f"{tmp_path / 'bad.mtl'}: line 2: Kd needs finite numbers" in message and "The 3 frame(s) done" in message
    assert info.value.failures[0]["stage"] == "scene_fn" and "Traceback" in info.value.failures[0]["traceback"]
    assert _journal(out) == {0, 2, 3} and not (out / "frame_000001.npy").exists() and not _partials(out)
    stamps = {i: os.stat(out / f"frame_{i:06d}.npy").st_mtime_ns for i in (0, 2, 3)}
    (tmp_path / "bad.mtl").write_text("newmtl m\nKd 0.5 0 0\n")
    rendered = []
    paths = render_many(orbit_scene, specs, W, H, out, progress=False,
                        executor=InlineExecutor(lambda n: rendered.append(n)))
    assert len(rendered) == 1 and _journal(out) == {0, 1, 2, 3} and all(os.path.exists(p) for p in paths)
    assert {i: os.stat(out / f"frame_{i:06d}.npy").st_mtime_ns for i in (0, 2, 3)} == stamps


def test_a_driver_error_mid_batch_names_the_frame_and_the_batch_goes_on(tmp_path, monkeypatch):
    from glphong.batch import _WORKER

    for renderer in _WORKER.values():
        renderer.release()
    _WORKER.clear()
    calls, made = [], []
    check_error = GLContext.check_error

    def fails_at_the_third(self, where):
        calls.append(where)
        if len(calls) == 3:
            raise RuntimeError(f"GL error GL_OUT_OF_MEMORY after {where}")
        return check_error(self, where)

    monkeypatch.setattr(GLContext, "check_error", fails_at_the_third)
    angles = [0.0, 20.0, 40.0, 60.0, 80.0]
    out = tmp_path / "frames"
    with pytest.raises(FramesFailedError, match=r"1 of 5 frame\(s\) failed; the first, frame 2 \(spec 40.0\), "
                                                "rendering it: RuntimeError: GL error GL_OUT_OF_MEMORY") as info:
        render_many(turntable_scene, angles, W, H, out, progress=False,
                    executor=InlineExecutor(lambda n: made.append(id(next(iter(_WORKER.values()), None)))))
    assert made[3] != made[2]  # the renderer that reported the error was released and made again
    assert _journal(out) == {0, 1, 3, 4} and info.value.done == 4 and not _partials(out)
    monkeypatch.undo()
    paths = render_many(turntable_scene, angles, W, H, out, progress=False, executor=InlineExecutor())
    with glphong.Renderer(W, H) as renderer:
        assert np.array_equal(np.load(paths[2]), renderer.render(turntable_scene(40.0)).radiance)
    for renderer in _WORKER.values():
        renderer.release()
    _WORKER.clear()


def test_a_full_disk_names_the_file_and_the_space_and_leaves_no_partial_file(tmp_path, monkeypatch):
    import glphong.batch.workers as workers

    save, saved = np.save, []

    def disk_fills_at_the_third(path, array):
        saved.append(path)
        if len(saved) == 3:  # the worker saves into the open temporary file
            path.write(b"\x93NUMPY half")
            path.flush()
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return save(path, array)

    monkeypatch.setattr(workers.np, "save", disk_fills_at_the_third)
    out = tmp_path / "frames"
    needed = 128 + W * H * 3 * 4
    with pytest.raises(FramesFailedError) as info:
        render_many(turntable_scene, [0, 10, 20, 30, 40, 50], W, H, out, progress=False, executor=InlineExecutor(),
                    frames_per_task=6)  # one task: the worker stops at the failed write
    message = str(info.value)
    assert f"writing {out / 'frame_000002.npy'} failed: No space left on device" in message
    assert "MiB free on its file system" in message and f"the file needs {needed} bytes" in message
    assert "the batch stopped" in message and info.value.failures[0]["stage"] == "write"
    assert _journal(out) == {0, 1} and not _partials(out) and not (out / "frame_000002.npy").exists()
    assert len(saved) == 3  # nothing written after the disk filled (a pool's tasks not started are cancelled too)
    monkeypatch.undo()
    paths = render_many(turntable_scene, [0, 10, 20, 30, 40, 50], W, H, out, progress=False, executor=InlineExecutor())
    assert _journal(out) == set(range(6)) and all(np.load(p).shape == (H, W, 3) for p in paths)


def _helper_module(folder, name, body):
    (folder / f"{name}.py").write_text(textwrap.dedent(body))
    return name


def _group_processes(pgid):
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                if os.getpgid(int(entry)) == pgid:
                    found.append(int(entry))
            except OSError:
                pass
    return found


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc for the process group")
@pytest.mark.parametrize("to", ["group", "parent"])
def test_sigint_during_a_batch_exits_cleanly_and_the_rerun_resumes(tmp_path, to):
    """``to='group'``: Ctrl-C in a terminal (the whole foreground process group); 'parent': ``kill -INT`` to the
    batch's process alone (a scheduler, a supervising script)."""
    _helper_module(tmp_path, "slow_scenes", """
        import os, time
        from glphong.batch import turntable_scene

        def slow_scene(angle):
            time.sleep(float(os.environ.get("SLOW_SCENE_S", 0)))
            return turntable_scene(angle)
        """)
    angles = [float(a) for a in range(0, 360, 9)]  # 40 frames, 0.2 s each on 2 workers: about 4 s
    out = tmp_path / "frames"
    # the child is a user's script at a terminal, whose SIGINT is Python's default: a SIG_IGN inherited from the test
    # runner's process would stay ignored in it (Python keeps a SIGINT ignored at its start)
    script = (f"import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler)\n"
              f"sys.path.insert(0, {str(tmp_path)!r})\nfrom glphong.batch import render_many\n"
              f"from slow_scenes import slow_scene\nif __name__ == '__main__':\n"
              f"    render_many(slow_scene, {angles!r}, {W}, {H}, {str(out)!r}, workers=2, progress=False)\n")
    (tmp_path / "run_batch.py").write_text(script)
    env = dict(os.environ, SLOW_SCENE_S="0.2", PYTHONPATH=os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")]))
    child = subprocess.Popen([sys.executable, str(tmp_path / "run_batch.py")], start_new_session=True,
                             stderr=subprocess.PIPE, text=True, env=env)
    try:
        deadline = time.monotonic() + 120
        while not ((out / "frames.jsonl").exists() and len(_journal(out)) >= 3):
            assert child.poll() is None and time.monotonic() < deadline, "the batch ended before it was interrupted"
            time.sleep(0.05)
        (os.killpg if to == "group" else os.kill)(child.pid, signal.SIGINT)
        sent = time.monotonic()
        stderr = child.communicate(timeout=60)[1]
        took = time.monotonic() - sent
    finally:
        if child.poll() is None:
            os.killpg(child.pid, signal.SIGKILL)
    assert child.returncode == -signal.SIGINT and stderr.rstrip().endswith("KeyboardInterrupt"), stderr[-2000:]
    assert took < 20  # measured 0.8 s: the workers are ended, not waited for
    assert "Process SpawnProcess" not in stderr  # the workers ignore SIGINT: no traceback from each
    deadline = time.monotonic() + 10
    while _group_processes(child.pid) and time.monotonic() < deadline:  # the resource tracker ends last
        time.sleep(0.1)
    assert _group_processes(child.pid) == []
    done = _journal(out)
    assert 3 <= len(done) < len(angles) and not _partials(out)
    frames = {int(n[6:12]) for n in os.listdir(out) if n.startswith("frame_")}
    assert done <= frames  # a frame written but not journalled is checked and rendered again
    assert len(frames) <= len(done) + 4  # the workers were ended, not left to render the batch: at most the frames
    # in flight (2 workers, each with a frame and one queued) written after the last was journalled
    rendered = []
    paths = render_many(_slow(tmp_path), angles, W, H, out, progress=False,
                        executor=InlineExecutor(lambda n: rendered.append(n)))
    assert len(rendered) == len(angles) - len(done) and _journal(out) == set(range(len(angles)))
    with glphong.Renderer(W, H) as renderer:
        for k in sorted(done)[:2] + sorted(set(range(len(angles))) - done)[:2]:
            assert np.array_equal(np.load(paths[k]), renderer.render(turntable_scene(angles[k])).radiance)


def _slow(folder):
    """The batch's own scene function (the rerun must be the same batch: the manifest names the specs, not the
    function), imported from the helper module."""
    sys.path.insert(0, str(folder))
    try:
        return __import__("slow_scenes").slow_scene
    finally:
        sys.path.remove(str(folder))
        sys.modules.pop("slow_scenes", None)


def test_a_worker_killed_at_one_frame_fails_that_frame_alone(tmp_path):
    name = _helper_module(tmp_path, "oom_scenes", """
        import os, signal
        from glphong.batch import turntable_scene

        def killed_at_20(angle):
            if angle == 20.0:
                os.kill(os.getpid(), signal.SIGKILL)  # as the kernel's OOM killer does
            return turntable_scene(angle)
        """)
    sys.path.insert(0, str(tmp_path))
    try:
        module = __import__(name)
        out = tmp_path / "frames"
        with pytest.warns(RuntimeWarning, match=r"a worker died with frame\(s\) 2, [0-9, ]+ in flight; a worker was ended by "
                                                 "SIGKILL"):
            with pytest.raises(FramesFailedError, match=r"1 of 5 frame\(s\) failed; the first, frame 2 \(spec 20.0\), "
                                                        "rendering it: its worker process died rendering it, alone; a "
                                                        r"worker was ended by SIGKILL \(the kernel's OOM killer"):
                render_many(module.killed_at_20, [0.0, 10.0, 20.0, 30.0, 40.0], W, H, out, workers=1, progress=False)
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop(name, None)
    assert _journal(out) == {0, 1, 3, 4} and not _partials(out)


def test_out_dir_that_is_a_file(tmp_path):
    (tmp_path / "taken").write_text("x")
    with pytest.raises(BatchError, match=r"out_dir .*taken is a file, not a folder"):
        render_many(turntable_scene, [0], W, H, tmp_path / "taken", executor=InlineExecutor(), progress=False)
    with pytest.raises(BatchError, match=r"out_dir .*taken/sub cannot be made: Not a directory"):
        render_many(turntable_scene, [0], W, H, tmp_path / "taken" / "sub", executor=InlineExecutor(), progress=False)
    if os.geteuid() != 0:  # root writes anywhere
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        with pytest.raises(BatchError, match="cannot be written by this user"):
            render_many(turntable_scene, [0], W, H, locked, executor=InlineExecutor(), progress=False)


def _textured_scene(side):
    scene = turntable_scene(0)
    pixels = np.random.default_rng(1).random((side, side, 3)).astype(np.float32)
    scene.add(primitives.plane(1.0), glphong.Lambert(kd=glphong.Texture(pixels)))
    return scene


def test_a_texture_beyond_the_context_or_the_memory_is_refused_by_name(glphong_make_renderer, glphong_backend,
                                                                       monkeypatch):
    import glphong.gpu.textures as textures

    renderer = glphong_make_renderer(8, 8, glphong_backend)
    renderer.render(_textured_scene(4))
    store = renderer.programs.textures
    largest = store.limits[0]
    assert largest >= 1024  # what GL 3.3 guarantees
    store.limits = (32,) + store.limits[1:]  # a context whose largest texture is 32 texels a side
    uploads = store.uploads
    with pytest.raises(ValueError, match=r"texture image [0-9a-f]{8}: 64x64 texels, beyond this context's "
                                         r"GL_MAX_TEXTURE_SIZE = 32"):
        renderer.render(_textured_scene(64))
    assert store.uploads == uploads
    store.limits = (largest,) + store.limits[1:]
    monkeypatch.setattr(textures, "available_memory", lambda: 1 << 20)  # 1 MiB available
    levels = sum(12 * (256 >> k) ** 2 for k in range(9))  # float32 rgb, 256 x 256 and its mipmaps down to 1 x 1
    with pytest.raises(ValueError, match=rf"uploading it needs about 2 MiB \(its {levels} bytes copied, then the "
                                         r"driver's copy\); this machine has 1 MiB available"):
        renderer.render(_textured_scene(256))
    assert store.uploads == uploads
    monkeypatch.undo()
    assert renderer.render(_textured_scene(64)).radiance.shape == (8, 8, 3)  # the renderer still works


def test_leftovers_of_killed_writers_are_removed_by_the_rerun(tmp_path):
    out = tmp_path / "frames"
    render_many(turntable_scene, [0, 10], W, H, out, progress=False, executor=InlineExecutor())
    # a batch writer's temporary, and write_atomically's (save_npz and save_exr write through it) inside it
    for name in (".partial-k3j2h1.npz", "..partial-k3j2h1.npz.partial-0123456789ab", ".frame_000001.npy.partial-ab"):
        (out / name).write_bytes(b"half")
    (out / "notes.txt").write_text("the user's")
    render_many(turntable_scene, [0, 10], W, H, out, progress=False, executor=InlineExecutor())
    assert not _partials(out) and (out / "notes.txt").exists()
