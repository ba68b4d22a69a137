"""An executor that runs a batch's tasks in the calling process, for testing batch pipelines
(`glphong.batch.render_many(..., executor=InlineExecutor())`): no worker processes, so a test can stop, break or
inspect a batch between its tasks, and the folder's bookkeeping is the same as for any other executor."""
from concurrent.futures import Executor, Future

__all__ = ["InlineExecutor"]


class InlineExecutor(Executor):
    """Runs each task in this process as it is submitted.

    Parameters
    ----------
    before : callable, optional
        ``before(n)`` is called before the n-th task (0, 1, ...): to interrupt a batch there (raise) or change what
        the next task finds.
    """

    def __init__(self, before=None):
        self.before, self.submitted = before, 0

    def submit(self, fn, /, *args, **kwargs):
        """Run ``fn`` with the given arguments now; a `concurrent.futures.Future` holding its result or its error."""
        future = Future()
        if self.before is not None:
            self.before(self.submitted)
        self.submitted += 1
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as exc:  # noqa: BLE001 - a task's error travels in its future
            future.set_exception(exc)
        return future
