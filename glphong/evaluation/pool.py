"""The toolkit's pooled OpenGL contexts: one context and program cache per backend, made on first use and kept
for the process, that `glphong.testing.evaluate` and `glphong.testing.glsl_function` run on when they are given
no context of their own.
"""
import atexit
import threading

from glphong.gpu.contexts import EGLDisplayTerminatedError, create_context
from glphong.gpu.programs import ProgramCache

__all__ = ["pooled"]

_POOL = {}
_POOL_LOCK = threading.Lock()


def pooled(backend):
    """The pooled context of ``backend``: made on first use, made anew where its EGL display was terminated
    (pyrender's ``OffscreenRenderer.delete`` on EGL does that), released at exit.

    Parameters
    ----------
    backend : {'auto', 'egl', 'osmesa'}

    Returns
    -------
    gl : glphong.gpu.contexts.GLContext
        Detached: enter it (``with lock, gl:``) for each use, from any thread.
    programs : glphong.gpu.programs.ProgramCache
        Its program cache.
    lock : threading.RLock
        Held for each use: one evaluation at a time on a pooled context.
    """
    with _POOL_LOCK:
        entry = _POOL.get(backend)
        if entry is not None:
            try:
                with entry[2], entry[0]:
                    pass
            except EGLDisplayTerminatedError:  # its display was terminated (pyrender on EGL): start anew
                entry[0]._released = True
                entry = None
        if entry is None or entry[0].mgl is None:
            gl = create_context(backend)
            gl.detach()  # entered per call, from any thread
            entry = _POOL[backend] = (gl, ProgramCache(gl.mgl), threading.RLock())
        return entry


@atexit.register
def _release_pool():
    for gl, programs, _ in _POOL.values():
        try:
            with gl:
                programs.release()
            gl.release()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass
    _POOL.clear()
