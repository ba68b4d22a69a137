"""OpenGL contexts that another library made and owns (pyrender's): glphong draws into them without owning
them (`attach_current`), and ends them without ending the EGL display the process shares (`release_offscreen`).

glphong's own contexts are `glphong.gpu.contexts`'s.
"""

import moderngl

from glphong.gpu.drivers import _egl_library, _osmesa_library


class _CurrentContextLoader:
    """moderngl loader for a context some other library created and made current.

    Entering and leaving do nothing: the owner keeps the context current.
    """

    def __init__(self, get_proc_address):
        self._get_proc_address = get_proc_address

    def load_opengl_function(self, name):
        return self._get_proc_address(name.encode()) or 0

    def __enter__(self):
        pass

    def __exit__(self, *exc_info):
        pass

    def release(self):
        pass


def attach_current(platform):
    """Wrap the OpenGL context another library made current (e.g. pyrender's), without owning it.

    Parameters
    ----------
    platform : {'egl', 'osmesa'}
        How the current context was created; GL functions are loaded with
        ``eglGetProcAddress`` or ``OSMesaGetProcAddress``.

    Returns
    -------
    moderngl.Context
        Valid while the owner keeps that context current; releasing it is the owner's job.
    """
    if platform == "egl":
        get_proc_address = _egl_library().eglGetProcAddress
    elif platform == "osmesa":
        get_proc_address = _osmesa_library().OSMesaGetProcAddress
    else:
        raise ValueError(f"platform must be 'egl' or 'osmesa' (got {platform!r})")
    moderngl.init_context(_CurrentContextLoader(get_proc_address))
    return moderngl.get_context()


def release_offscreen(offscreen):
    """Delete a ``pyrender.OffscreenRenderer``'s GL objects and its context without ending the EGL display the
    process shares; idempotent.

    pyrender's own ``OffscreenRenderer.delete()`` (also when the garbage collector drops one) calls
    ``eglTerminate`` on the device's display, which Mesa shares with every other EGL context on that device in the
    process (glphong's, moderngl's, other pyrender renderers'), and so ends them all.  Here, on EGL, pyrender's
    scene renderer deletes its GL objects and only its own context is destroyed (this reaches into pyrender
    0.1.45's private attributes, the same in its forks ``pyrender2`` and ``pyrender-maintained``); on OSMesa
    ``delete()`` is called, which ends nothing else.

    Parameters
    ----------
    offscreen : pyrender.OffscreenRenderer
    """
    platform = getattr(offscreen, "_platform", None)
    if platform is None:
        return
    if not hasattr(platform, "_egl_display"):
        offscreen.delete()
        return
    from OpenGL.EGL import EGL_NO_CONTEXT, EGL_NO_SURFACE, eglDestroyContext, eglMakeCurrent

    platform.make_current()
    offscreen._renderer.delete()
    eglMakeCurrent(platform._egl_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT)
    eglDestroyContext(platform._egl_display, platform._egl_context)
    platform._egl_context = platform._egl_display = None
    offscreen._renderer = offscreen._platform = None
