"""What glphong holds in this process: live renderers, their GL objects, pooled contexts, pending orphans.

`gl_objects_alive` counts, at the moment it is called, every `glphong.Renderer` of this process that is not
released, the GL objects those renderers hold (`glphong.Renderer.gl_object_count`: programs, textures, buffers,
vertex arrays, framebuffers and their attachments), the contexts waiting in the pool for the next renderer
(`glphong.gpu.contexts.GLContext.recycle`, at most `glphong.gpu.contexts.POOL_SIZE` per backend) and the renderers
dropped without ``release()`` whose objects the next glphong call releases (`glphong.gpu.resources.ORPHANS`). A long
run that holds nothing more at its end than at its start shows the same counts (``benchmarks/soak.py``,
``tests/test_soak.py``). Contexts and objects made outside glphong (plain moderngl, another library) are not
seen: OpenGL has no query for the objects a context holds.

Renderers register themselves when made (`track`); the registry holds them weakly, so counting keeps nothing alive.
"""
import threading
import weakref
from typing import NamedTuple

from glphong.gpu import contexts as _contexts
from glphong.gpu.resources import ORPHANS, ORPHANS_LOCK

__all__ = ["GLCounts", "gl_objects_alive", "track"]

_RENDERERS = weakref.WeakSet()
_LOCK = threading.Lock()


class GLCounts(NamedTuple):
    """The counts of `gl_objects_alive`.

    Attributes
    ----------
    renderers : int
        Renderers of this process not released (nor yet collected).
    objects : int
        GL objects those renderers hold, summed (`glphong.Renderer.gl_object_count`).
    pooled_contexts : int
        Contexts waiting for reuse, all backends together.
    orphans : int
        Renderers dropped without ``release()`` whose GL objects wait for the next glphong call.
    """

    renderers: int
    objects: int
    pooled_contexts: int
    orphans: int


def track(renderer):
    """Register ``renderer`` (called by `glphong.Renderer` when it is made; held weakly)."""
    with _LOCK:
        _RENDERERS.add(renderer)


def gl_objects_alive():
    """Count what glphong holds in this process now.

    Returns
    -------
    GLCounts
        ``(renderers, objects, pooled_contexts, orphans)``; a renderer being released on another thread at the
        same moment is counted or not.

    Examples
    --------
    >>> from glphong.gpu.counters import gl_objects_alive
    >>> before = gl_objects_alive()
    >>> with glphong.Renderer(8, 8) as r:                 # doctest: +SKIP
    ...     r.render(scene)
    >>> gl_objects_alive().objects == before.objects       # doctest: +SKIP
    True
    """
    with _LOCK:
        live = [r for r in list(_RENDERERS) if getattr(r, "context", None) is not None]
    objects = 0
    for renderer in live:
        try:
            objects += renderer.gl_object_count()
        except (AttributeError, TypeError, RuntimeError):  # released or changed while counted
            pass
    with _contexts._POOL_LOCK:  # the pool is the contexts module's; read under its lock
        pooled = sum(len(waiting) for waiting in _contexts._POOL.values())
    with ORPHANS_LOCK:
        orphans = len(ORPHANS)
    return GLCounts(len(live), objects, pooled, orphans)
