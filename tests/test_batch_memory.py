"""What a batch's calling process holds while it runs (issue 42's soak: a parent that grew with the batch's length).

`glphong.batch.render_many` submits a bounded number of chunks and drops each chunk's future, and the result it
holds, once journalled: whatever the batch's length, the futures alive and done at its last frame are a few, not one
per chunk.  (Each Dask task's result stays on its worker while its future lives, so this bounds the workers' memory
too; benchmarks/soak.py measures both, docs/long_runs.md has the figures.)  The executor here is a one-thread
pool in this process, which reaches every future it made through a weak reference.
"""
import gc
import os
import weakref
from concurrent.futures import ThreadPoolExecutor
from fractions import Fraction

import pytest

from glphong.batch import render_many, turntable_scene
from glphong.batch import run as batch_run
from glphong.batch import workers as batch_workers


class _Watched(ThreadPoolExecutor):
    """A thread pool that keeps a weak reference to each future it returns."""

    def __init__(self):
        super().__init__(1)
        self.made = []

    def submit(self, fn, *args, **kwargs):
        future = super().submit(fn, *args, **kwargs)
        self.made.append(weakref.ref(future))
        return future


def _alive_done(executor):
    return sum(1 for ref in executor.made if ref() is not None and ref().done())


@pytest.fixture
def in_process():
    """Releases the renderer and writer thread a batch run on threads leaves in this process (`_WORKER`, `_WRITER`)."""
    yield
    for renderer in list(batch_workers._WORKER.values()):
        renderer.release()
    batch_workers._WORKER.clear()
    writer = batch_workers._WRITER.pop(os.getpid(), None)
    if writer is not None:
        writer.shutdown()


@pytest.mark.parametrize("backend", ["egl", "osmesa"])
def test_parent_holds_no_future_per_chunk(tmp_path, in_process, backend):
    """Batches of 12 and 24 one-frame chunks: at the last frame, the futures alive and done are at most the two the
    pool may have in flight (2 x its one thread) and the one being waited on, the same for both lengths (the code
    before this fix held all 11 and 23)."""
    from glphong.testing import require_backend

    require_backend(backend).release()
    seen = {}
    for n in (12, 24):
        executor = _Watched()

        def scene_fn(angle, n=n, executor=executor):
            if angle == n - 1:  # the last frame: what the parent still holds of the chunks before it
                seen[n] = _alive_done(executor)
            return turntable_scene(float(angle))

        with executor:
            paths = render_many(scene_fn, list(range(n)), 8, 8, tmp_path / f"frames{n}", executor=executor,
                                progress=False, backend=backend)
        assert len(paths) == n and all(os.path.exists(p) for p in paths)
        assert len(executor.made) == n  # one chunk a frame, each submitted once
    assert seen[12] <= 3 and seen[24] <= 3, seen


def test_local_dask_workers_keep_no_profile():
    """The local cluster of executor='dask' runs its workers without Dask's statistical profiler, whose one-second
    profiles of the task thread's stacks made each worker grow about 1.1 MiB per 10^3 frames (docs/long_runs.md)."""
    pytest.importorskip("distributed", reason="dask.distributed is not installed (pip install 'glphong[dask]')")
    cluster, executor = batch_workers._local_dask(1)
    client = executor._client
    try:
        # a lambda travels by value (a worker may not import this test module)
        assert list(client.run(lambda dask_worker: "profile" in dask_worker.periodic_callbacks).values()) == [False]
        assert executor._kwargs == {"pure": False}  # a task writes files: never one result for two
    finally:
        cluster.close()


def _spec_copies(specs):
    """The `Fraction` objects alive in this process but ``specs``' own: copies of the specs unpickled here."""
    own = {id(s) for s in specs}
    gc.collect()
    return sum(1 for o in gc.get_objects() if type(o) is Fraction and id(o) not in own)


def test_local_dask_parent_keeps_no_spec_per_task(tmp_path, monkeypatch):
    """At the end of a batch of 24 one-frame tasks on executor='dask' (a local cluster: its scheduler runs in this
    process), this process holds copies of at most the specs of the two tasks the batch may have in flight (2 x the
    one worker's thread), whatever the batch's length.  Dask's logs "for developers" kept, in the scheduler, the
    last 1000 messages sent to each worker, every task's arguments with them: a copy of each spec, 24 before this
    fix (docs/long_runs.md).  The specs are `Fraction` angles (`turntable_scene` takes any number), which the
    garbage collector tracks, unlike floats, so that copies can be counted.  The setting is this process's Dask
    configuration while the cluster runs (a worker that connects anew is logged by it too), and given back after."""
    pytest.importorskip("distributed", reason="dask.distributed is not installed (pip install 'glphong[dask]')")
    config = pytest.importorskip("dask").config
    log_length = config.get("distributed.admin.low-level-log-length")
    specs = [Fraction(15 * i) for i in range(24)]
    before = _spec_copies(specs)
    seen = {}

    class Probe:
        """What `_render_missing` closes at the batch's end: counted first, while the cluster is still up."""

        def __init__(self, cluster):
            self.cluster = cluster

        def close(self):
            seen["copies"] = _spec_copies(specs) - before
            seen["log length"] = config.get("distributed.admin.low-level-log-length")
            self.cluster.close()

    def local_dask(workers):
        cluster, executor = batch_workers._local_dask(workers)
        return Probe(cluster), executor

    monkeypatch.setattr(batch_run, "_local_dask", local_dask)
    paths = render_many(turntable_scene, specs, 8, 8, tmp_path / "frames", executor="dask", workers=1,
                        progress=False)
    assert len(paths) == 24 and all(os.path.exists(p) for p in paths)
    assert seen["copies"] <= 2, seen
    assert seen["log length"] == 0 and config.get("distributed.admin.low-level-log-length") == log_length != 0
