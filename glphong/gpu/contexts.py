"""Headless OpenGL contexts on Mesa's EGL or OSMesa drivers.

`create_context` opens an offscreen OpenGL core-profile context through EGL
(``moderngl``'s standalone EGL backend) or through OSMesa (``libOSMesa``
loaded with :mod:`ctypes`) and wraps it in a `GLContext`.  Rendering goes
into framebuffer objects created on ``GLContext.mgl``; neither backend has a
usable default framebuffer.

Several contexts, of either backend, may live in one process.  Make a context
current with ``with ctx:`` before issuing GL calls on it; ``with`` blocks nest,
and leaving an inner block makes the enclosing block's context current again.

EGL contexts live on a display of glphong's own where the driver allows it, so that another library's
``eglTerminate`` (pyrender, VTK/PyVista, Open3D) does not end them; `glphong.gpu.egl_devices` opens it and
chooses the device.

The two backends share one context pool (recycling), one fork guard and one notion of "current",
whose invariants hold only if a single module owns them: this one.  The drivers' C libraries
(:mod:`ctypes` bindings of libEGL and libOSMesa) are `glphong.gpu.drivers`'s, and contexts another
library made (`attach_current`, `release_offscreen`) are `glphong.gpu.foreign`'s; their names stay
importable from here.
"""

import atexit
import ctypes
import os
import threading

import moderngl

from glphong.gpu.egl_devices import create_egl_loader, resolve_device, terminating_libraries
from glphong.gpu.drivers import (  # noqa: F401 - egl_device_count stays importable from here
    _OSMESA_CONTEXT_MAJOR_VERSION, _OSMESA_CONTEXT_MINOR_VERSION, _OSMESA_CORE_PROFILE,
    _OSMESA_DEPTH_BITS, _OSMESA_FORMAT, _OSMESA_PROFILE, _OSMESA_RGBA, _OSMESA_VERSIONS,
    _osmesa_library, _OSMesaLoader, egl_device_count)
from glphong.gpu.foreign import attach_current, release_offscreen  # noqa: F401 - public names of this module

__all__ = [
    "BACKENDS",
    "SYSTEM_PACKAGES",
    "PACKAGES",
    "BackendUnavailableError",
    "EGLDisplayTerminatedError",
    "release_offscreen",
    "GLContext",
    "available_backends",
    "create_context",
    "egl_device_count",
]

BACKENDS = ("egl", "osmesa")
"""Backends in the order ``backend="auto"`` tries them."""

SYSTEM_PACKAGES = {
    "egl": "libegl1 libegl-mesa0 libgl1-mesa-dri",
    "osmesa": "libosmesa6",
}
"""Debian/Ubuntu packages providing each backend (``libosmesa6``: Debian 12 and 13, Ubuntu 22.04 to 26.04, where
Ubuntu's ``mesa-compat`` keeps Mesa 25.1's OSMesa; not Debian unstable, whose Mesa 25.1 and newer have none:
docs/install.md)."""

PACKAGES = {
    "egl": {"Debian/Ubuntu": "apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri",
            "Fedora": "dnf install libglvnd-egl mesa-libEGL mesa-dri-drivers",
            "conda-forge": "conda install -c conda-forge libegl (libglvnd's libEGL; Mesa's EGL vendor and drivers "
                           "come from the system packages above; not tried by this project)"},
    "osmesa": {"Debian/Ubuntu": "apt-get install libosmesa6 (Debian 12 and 13, Ubuntu 22.04 to 26.04; none in "
                                "Debian unstable, whose Mesa is 25.1 or newer)",
               "Fedora": "dnf install mesa-libOSMesa (Mesa before 25.1; with Mesa 25.1 and newer, Fedora 42's updates "
                         "and 43: dnf install mesa-compat-libOSMesa; not tried by this project)",
               "conda-forge": "conda install -c conda-forge mesalib (its builds of Mesa before 25.1; not tried by "
                              "this project)"},
}
"""The install command of each backend's libraries on each family of systems (`glphong doctor` prints them)."""

_ENV_BACKEND = "GLPHONG_BACKEND"

_entered = threading.local()


class BackendUnavailableError(RuntimeError):
    """No OpenGL context could be created on the requested backend(s)."""


class ForkedProcessError(RuntimeError):
    """OpenGL used in a process forked from one that had already used OpenGL (it would hang)."""


class EGLDisplayTerminatedError(RuntimeError):
    """An EGL context can no longer be made current: its display was terminated (``eglTerminate``)."""


def _terminated_message(how):
    """The message of `EGLDisplayTerminatedError` for a context on a display opened as ``how``."""
    suspects = terminating_libraries()
    named = ("; loaded in this process and known to terminate the display they share with glphong: " +
             "; ".join(suspects)) if suspects else ""
    if how == "shared":
        why = ("the one every library in the process gets for this device (GLPHONG_EGL_DISPLAY=shared, or a driver "
               "with neither EGL_KHR_display_reference nor, for Mesa's software device, the surfaceless platform), "
               "so another library's eglTerminate ends glphong's contexts too")
    else:
        why = "its own, which another library in the process got the same way and terminated"
    return ("this EGL context can no longer be made current: the EGL display it lives on was terminated "
            f"(eglTerminate). glphong's display here is {how}: {why}{named}. glphong drew nothing from then on. Make a new glphong.Renderer "
            "(a fresh context re-initialises the display), keep the other library's renderer alive while "
            "glphong's are in use, or (pyrender) release it with glphong.integrations.pyrender.release(renderer), "
            "which does not terminate it")


#: the process that first tried to make a context (llvmpipe starts its rasterizer threads then)
_GL_PID = None
#: recycled contexts per backend (`GLContext.recycle`), reused by `create_context`
_POOL = {}
_POOL_LOCK = threading.Lock()
POOL_SIZE = 4


@atexit.register
def _destroy_pool():
    with _POOL_LOCK:
        waiting = [ctx for contexts in _POOL.values() for ctx in contexts]
        _POOL.clear()
    for ctx in waiting:
        try:
            ctx.release()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass


def _reuse(backend, require, device=None):
    """A recycled context of ``backend`` (on the EGL device of index ``device``) at least as new as ``require``,
    or None."""
    with _POOL_LOCK:
        waiting = _POOL.get(backend, [])
        for i, ctx in enumerate(waiting):
            if ctx.version_code >= require and ctx.device == device:
                return waiting.pop(i)
    return None


_GL_THREADLESS = False


def _note_gl_use():
    """Record that this process has made a context (and whether llvmpipe runs without threads)."""
    global _GL_PID, _GL_THREADLESS
    if _GL_PID is None:
        _GL_PID = os.getpid()
        _GL_THREADLESS = os.environ.get("LP_NUM_THREADS") == "0"  # Mesa reads it at the first context


def check_not_forked():
    """Raise `ForkedProcessError` in a process forked after its parent used OpenGL.

    llvmpipe's rasterizer threads are not copied by ``fork``: a context made or used in such a child
    waits for them forever (in the first read-back).  ``LP_NUM_THREADS=0`` (no rasterizer threads)
    avoids it, and is honoured.
    """
    if _GL_PID is not None and _GL_PID != os.getpid() and not _GL_THREADLESS:
        raise ForkedProcessError(
            f"this process was forked from process {_GL_PID}, which had already made an OpenGL context: "
            "Mesa's llvmpipe rasterizer threads do not survive fork, and OpenGL here would hang. Start worker "
            "processes with multiprocessing's 'spawn' or 'forkserver' method "
            "(multiprocessing.get_context('spawn')), or make every context in the workers and none before "
            "forking; setting LP_NUM_THREADS=0 before the parent makes its first context also avoids the "
            "hang, at a speed cost")


def _entered_stack():
    """Return this thread's stack of entered `GLContext` objects."""
    if not hasattr(_entered, "stack"):
        _entered.stack = []
    return _entered.stack


class GLContext:
    """An offscreen OpenGL context.

    Normally obtained from `create_context`.

    Parameters
    ----------
    backend : str
        Name of the backend that created the context, one of `BACKENDS`.
    mgl : moderngl.Context
        The wrapped context.  It must be current when the `GLContext` is
        constructed.
    on_release : callable, optional
        Called without arguments once, after ``mgl`` is released, to free
        native resources that moderngl does not own.
    device : int, optional
        The EGL device's index in `glphong.gpu.egl_devices.devices` (None for OSMesa, or a surfaceless display).
    loader : glphong.gpu.egl_devices.EGLLoader, optional
        The EGL context's loader (EGL only).

    Attributes
    ----------
    backend : str
        Name of the backend that created the context.
    mgl : moderngl.Context
        The wrapped moderngl context; create GL objects on it.
    renderer_name : str
        The ``GL_RENDERER`` string, e.g. ``"llvmpipe (LLVM 15.0.6, 256 bits)"``.
    version_code : int
        OpenGL version as reported by moderngl, e.g. ``450`` for 4.5.
    """

    def __init__(self, backend, mgl, on_release=None, device=None, loader=None):
        self.backend = backend
        self.device = device
        self.mgl = mgl
        self._loader = loader
        self.renderer_name = mgl.info["GL_RENDERER"]
        self.version_code = mgl.version_code
        self._on_release = on_release
        self._released = False
        self._idle_framebuffer = None

    def __enter__(self):
        """Make this context current on the calling thread."""
        check_not_forked()
        self._make_current()
        _entered_stack().append(self)
        return self

    def __exit__(self, *exc_info):
        """Leave the context, restoring the enclosing ``with`` block's one."""
        stack = _entered_stack()
        stack.pop()
        self.mgl.__exit__(*exc_info)
        if stack:
            stack[-1]._make_current()

    def _make_current(self):
        # EGL skips eglMakeCurrent for a context it already considers current,
        # although an OSMesa context may have taken over the GL dispatch that
        # both drivers share through libglapi since; leaving first forces a
        # real switch.  Leaving an OSMesa context does nothing.
        self.mgl.__exit__(None, None, None)
        self.mgl.__enter__()
        if self.backend == "egl" and self.alive is False:
            raise EGLDisplayTerminatedError(_terminated_message(self.display))

    @property
    def alive(self):
        """For an EGL context just made current: whether EGL made it current (False once its display was
        terminated, `EGLDisplayTerminatedError`); None for OSMesa, where that cannot be asked."""
        return self._loader.is_current() if self.backend == "egl" else None

    @property
    def display(self):
        """How the EGL display was opened (`glphong.gpu.egl_devices.open_display`): ``'own (...)'`` or ``'shared'``
        (other libraries' ``eglTerminate`` ends this context too); None for OSMesa."""
        return self._loader.how if self.backend == "egl" else None

    def detach(self):
        """Leave the context current on no thread, so that any thread may enter it next (EGL allows a
        context to be current on one thread only; an OSMesa context needs nothing)."""
        if self.backend == "egl" and not self._released:
            self.mgl.__enter__()
            self.mgl.__exit__(None, None, None)  # leaving moderngl's binding releases it from this thread

    def bind_idle_framebuffer(self):
        """Bind a 1x1 framebuffer owned by this context; call with the context entered.

        A complete framebuffer must be bound for any draw call, transform feedback
        included (standalone EGL contexts have none), and a framebuffer about to be
        released must not stay bound: moderngl rebinds the previously bound one when
        it creates the next, and binding a deleted name is GL_INVALID_OPERATION.
        """
        if self._idle_framebuffer is None:
            self._idle_framebuffer = self.mgl.framebuffer([self.mgl.renderbuffer((1, 1))])
        self._idle_framebuffer.use()

    def release_framebuffer(self, fbo):
        """Release a framebuffer and its attachments; call with the context entered.

        The idle framebuffer is bound first, so the released one does not stay bound (see
        `bind_idle_framebuffer`).
        """
        self.bind_idle_framebuffer()
        for attachment in (*fbo.color_attachments, fbo.depth_attachment):
            if attachment is not None:
                attachment.release()
        fbo.release()

    def release(self):
        """Destroy the context.  Calling it again does nothing."""
        if self._released:
            return
        self._released = True
        if self._idle_framebuffer is not None:
            with self:
                self.release_framebuffer(self._idle_framebuffer)
            self._idle_framebuffer = None
        self.mgl.release()
        if self._on_release is not None:
            self._on_release()

    def recycle(self):
        """Hand the context back for reuse by a later `create_context` of its backend instead of destroying
        it; the caller must have released every GL object it made on it.

        Making and destroying a context costs memory the driver never returns (measured with plain
        moderngl on Mesa's EGL: about 0.05 MB per context), so a loop that makes renderers would grow
        without bound; recycled contexts keep it flat.  At most `POOL_SIZE` contexts per backend wait
        for reuse; beyond that, and at exit, they are destroyed.
        """
        if self._released:
            return
        try:
            with self:
                _ = self.mgl.error  # reading the flag clears it: the next user starts clean
            self.detach()
        except Exception:  # noqa: BLE001 - a broken context is destroyed, not recycled
            self.release()
            return
        with _POOL_LOCK:
            waiting = _POOL.setdefault(self.backend, [])
            if len(waiting) < POOL_SIZE and os.getpid() == _GL_PID:
                waiting.append(self)
                return
        self.release()

    def check_error(self, where):
        """Raise if the GL error flag of the current context is set.

        Parameters
        ----------
        where : str
            Description of the preceding operation, used in the message.

        Raises
        ------
        RuntimeError
            If ``glGetError`` reports an error (which it also clears).
        """
        err = self.mgl.error
        if err != "GL_NO_ERROR":
            raise RuntimeError(f"GL error {err} after {where}")

    def __repr__(self):
        state = ", released" if self._released else ""
        return (
            f"GLContext(backend={self.backend!r}, renderer={self.renderer_name!r}, "
            f"version_code={self.version_code}{state})"
        )


def _create_egl(require, device=None):
    """A context on the `glphong.gpu.egl_devices.EGLDevice` ``device`` (None: a surfaceless display)."""
    loader = create_egl_loader(device, require)
    try:
        moderngl.init_context(loader)
        mgl = moderngl.get_context()
    except BaseException:
        loader.destroy()
        raise
    ctx = GLContext("egl", mgl, on_release=loader.destroy, device=None if device is None else device.index, loader=loader)
    if ctx.version_code < require:
        ctx.release()
        raise RuntimeError(f"got OpenGL {ctx.version_code}, need {require}")
    return ctx


def _create_osmesa(require):
    lib = _osmesa_library()
    for major, minor in _OSMESA_VERSIONS:
        attribs = (ctypes.c_int * 11)(
            _OSMESA_FORMAT, _OSMESA_RGBA,
            _OSMESA_DEPTH_BITS, 24,
            _OSMESA_PROFILE, _OSMESA_CORE_PROFILE,
            _OSMESA_CONTEXT_MAJOR_VERSION, major,
            _OSMESA_CONTEXT_MINOR_VERSION, minor,
            0,
        )
        handle = lib.OSMesaCreateContextAttribs(attribs, None)
        if handle:
            break
    else:
        raise RuntimeError("OSMesaCreateContextAttribs failed for OpenGL 4.5 and 3.3 core")
    loader = _OSMesaLoader(lib, handle)
    try:
        if not loader.make_current():
            raise RuntimeError("OSMesaMakeCurrent failed")
        moderngl.init_context(loader)
        mgl = moderngl.get_context()
    except BaseException:
        loader.destroy()
        raise
    ctx = GLContext("osmesa", mgl, on_release=loader.destroy)
    if ctx.version_code < require:
        ctx.release()
        raise RuntimeError(f"got OpenGL {ctx.version_code}, need {require}")
    return ctx


_CREATORS = {"egl": _create_egl, "osmesa": _create_osmesa}


def _try_create(backend, require, device=None):
    """Return ``(context, None)``, or ``(None, reason)`` if creation failed.

    ``device`` is, for EGL, a `glphong.gpu.egl_devices.EGLDevice` (None: a surfaceless display).  The context
    current before the call stays current if it was entered.
    """
    check_not_forked()
    stack = _entered_stack()
    if stack:  # the entered context's queued work completes before another context takes the GL dispatch, which
        stack[-1].mgl.finish()  # EGL and OSMesa share through libglapi (a clear was once lost: test_contexts)
    index = None if device is None else device.index
    reused = _reuse(backend, require, index)
    while reused is not None:
        try:
            reused._make_current()  # as a new context is: current (unless a with block restores another below)
            return reused, None
        except EGLDisplayTerminatedError:  # a recycled context whose display was terminated since: drop it
            reused._released = True
            reused = _reuse(backend, require, index)
    try:
        context = _create_egl(require, device) if backend == "egl" else _CREATORS[backend](require)
        _note_gl_use()
        return context, None
    except Exception as exc:
        return None, str(exc) or type(exc).__name__
    finally:
        stack = _entered_stack()
        if stack:
            stack[-1]._make_current()


def _install_hint(backend):
    hint = f"Debian/Ubuntu: apt-get install {SYSTEM_PACKAGES[backend]}"
    if backend == "osmesa":
        hint += " (none in Debian unstable, whose Mesa 25.1 and newer has no OSMesa: use EGL there)"
    return hint + "; other systems and what is missing here: glphong doctor"


def create_context(backend="auto", require=330, device=None):
    """Create an offscreen OpenGL core-profile context.

    A context a released `glphong.Renderer` recycled (`GLContext.recycle`) is reused when one of the
    backend is waiting.  The new context is current unless called inside another context's ``with``
    block, which then stays current; `GLContext.detach` leaves it current on no thread (for use
    from other threads, as `glphong.Renderer` does).  In a process forked after its parent made a
    context, `ForkedProcessError` is raised instead of hanging (see `check_not_forked`).

    Parameters
    ----------
    backend : {"auto", "egl", "osmesa"}, optional
        Driver interface to use.  ``"auto"`` uses the backend named by the
        ``GLPHONG_BACKEND`` environment variable if that is set and not
        empty, otherwise the first of `BACKENDS` that works.
    require : int, optional
        Minimum OpenGL version, as ``major * 100 + minor * 10``.
    device : int or {"gpu", "software"}, optional
        The EGL device: an index of `glphong.gpu.egl_devices.devices`'s list, or the first device of a kind; EGL
        only.  None: ``GLPHONG_EGL_DEVICE`` where set, else the first GPU device, else Mesa's software device
        (`glphong.gpu.egl_devices.resolve_device`; ``EGL_VISIBLE_DEVICES`` and ``CUDA_VISIBLE_DEVICES`` hide
        devices).

    Returns
    -------
    GLContext
        The new context.  Call its `GLContext.release` when done.

    Raises
    ------
    ValueError
        If ``backend`` or ``GLPHONG_BACKEND`` names no known backend, or ``device`` (or
        ``GLPHONG_EGL_DEVICE``) names no EGL device here (the message lists those there are).
    BackendUnavailableError
        If no context could be created; the message gives the reason for
        each backend tried and the system packages that provide it.
    """
    if backend not in ("auto", *BACKENDS):
        raise ValueError(
            f"backend must be one of 'auto', {', '.join(map(repr, BACKENDS))}; got {backend!r}"
        )
    origin = ""
    if backend == "auto" and os.environ.get(_ENV_BACKEND):
        backend = os.environ[_ENV_BACKEND].strip().lower()
        if backend not in BACKENDS:
            raise ValueError(
                f"environment variable {_ENV_BACKEND} must be one of "
                f"{', '.join(map(repr, BACKENDS))}; got {os.environ[_ENV_BACKEND]!r}"
            )
        origin = f" (chosen by {_ENV_BACKEND})"
    if device is not None:
        if backend == "auto":
            backend = "egl"
        if backend != "egl":
            raise ValueError(f"device selects an EGL device: it needs backend 'egl' or 'auto' (got {backend!r})")
    if backend != "auto":
        egl_device = resolve_device(device) if backend == "egl" else None
        ctx, reason = _try_create(backend, require, egl_device)
        if ctx is None:
            raise BackendUnavailableError(
                f"OpenGL backend {backend!r}{origin} is unavailable: {reason}. "
                f"{_install_hint(backend)}"
            )
        return ctx
    failures = []
    for name in BACKENDS:
        ctx, reason = _try_create(name, require, resolve_device() if name == "egl" else None)
        if ctx is not None:
            return ctx
        failures.append(f"  {name}: {reason} ({_install_hint(name)})")
    raise BackendUnavailableError(
        f"no OpenGL {require} backend is available; tried:\n" + "\n".join(failures)
    )


def available_backends():
    """Report which backends can create an OpenGL 3.3 context.

    Each backend is probed by creating and releasing a context.

    Returns
    -------
    dict of str to str or None
        For each name in `BACKENDS`, None if it works, else the reason it
        does not.
    """
    report = {}
    for name in BACKENDS:
        try:
            device = resolve_device() if name == "egl" else None
        except ValueError as exc:  # GLPHONG_EGL_DEVICE names no device here
            report[name] = str(exc)
            continue
        ctx, report[name] = _try_create(name, 330, device)
        if ctx is not None:
            ctx.release()
    return report
