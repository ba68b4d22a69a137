"""The drivers' C libraries through :mod:`ctypes`: libEGL's queries and libOSMesa's context calls.

`glphong.gpu.contexts` makes, pools and switches the contexts; this module only loads the libraries, declares the
signatures it calls and holds OSMesa's constants, so that nothing here keeps state beyond the loaded libraries.
"""

import ctypes
import ctypes.util
import functools
import os

# OSMesa constants, from GL/osmesa.h and GL/gl.h.
_OSMESA_FORMAT = 0x22
_OSMESA_RGBA = 0x1908
_OSMESA_DEPTH_BITS = 0x30
_OSMESA_PROFILE = 0x33
_OSMESA_CORE_PROFILE = 0x34
_OSMESA_CONTEXT_MAJOR_VERSION = 0x36
_OSMESA_CONTEXT_MINOR_VERSION = 0x37
_GL_UNSIGNED_BYTE = 0x1401
_OSMESA_VERSIONS = ((4, 5), (3, 3))


#: environment variables naming the library file (a name such as ``libEGL.so.1`` or a path) glphong loads instead
#: of the one ``ctypes.util.find_library`` finds; ``glphong doctor`` and the tests use them to point at another build
ENV_LIBRARIES = {"egl": "GLPHONG_LIBEGL", "osmesa": "GLPHONG_LIBOSMESA"}


def library_candidates(backend):
    """The library names glphong tries, in order, for ``backend`` (``'egl'`` or ``'osmesa'``): the file named by
    its `ENV_LIBRARIES` variable alone where that is set, else what ``find_library`` finds and the usual sonames."""
    override = os.environ.get(ENV_LIBRARIES[backend], "").strip()
    if override:
        return (override,)
    stem, sonames = ("EGL", ("libEGL.so.1", "libEGL.so")) if backend == "egl" else ("OSMesa", ("libOSMesa.so.8", "libOSMesa.so"))
    return tuple(dict.fromkeys(n for n in (ctypes.util.find_library(stem), *sonames) if n))


def _load(backend):
    """The first of `library_candidates` that loads, or OSError naming every one tried and why it failed."""
    errors = []
    for name in library_candidates(backend):
        try:
            return ctypes.CDLL(name)
        except OSError as exc:
            errors.append(str(exc))
    variable = ENV_LIBRARIES[backend]
    chosen = f" ({variable}={os.environ[variable]!r})" if os.environ.get(variable, "").strip() else ""
    raise OSError(f"lib{'EGL' if backend == 'egl' else 'OSMesa'} not found{chosen}: " + "; ".join(errors or ["no candidate"]))


class _EGL:
    """libEGL's entry points (core ones by symbol, extension ones through ``eglGetProcAddress``: None where
    missing) and the client extensions; one per process (`_egl_library`)."""

    _CORE = {  # name: (restype, argtypes)
        "eglGetError": (ctypes.c_int, []),
        "eglInitialize": (ctypes.c_uint, [ctypes.c_void_p, ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_int)]),
        "eglChooseConfig": (ctypes.c_uint, [ctypes.c_void_p, ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_void_p),
                                            ctypes.c_int, ctypes.POINTER(ctypes.c_int)]),
        "eglBindAPI": (ctypes.c_uint, [ctypes.c_uint]),
        "eglCreateContext": (ctypes.c_void_p, [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.POINTER(ctypes.c_int)]),
        "eglDestroyContext": (ctypes.c_uint, [ctypes.c_void_p, ctypes.c_void_p]),
        "eglMakeCurrent": (ctypes.c_uint, [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p]),
        "eglGetCurrentContext": (ctypes.c_void_p, []),
        "eglGetCurrentDisplay": (ctypes.c_void_p, []),
        "eglGetProcAddress": (ctypes.c_void_p, [ctypes.c_char_p]),
        "eglQueryString": (ctypes.c_char_p, [ctypes.c_void_p, ctypes.c_int]),
    }
    _EXTENSIONS = {  # name: (restype, argtypes)
        "eglQueryDevicesEXT": (ctypes.c_uint, [ctypes.c_int, ctypes.POINTER(ctypes.c_void_p), ctypes.POINTER(ctypes.c_int)]),
        "eglQueryDeviceStringEXT": (ctypes.c_char_p, [ctypes.c_void_p, ctypes.c_int]),
        "eglQueryDeviceAttribEXT": (ctypes.c_uint, [ctypes.c_void_p, ctypes.c_int, ctypes.POINTER(ctypes.c_ssize_t)]),
        "eglQueryDisplayAttribEXT": (ctypes.c_uint, [ctypes.c_void_p, ctypes.c_int, ctypes.POINTER(ctypes.c_ssize_t)]),
        "eglGetPlatformDisplayEXT": (ctypes.c_void_p, [ctypes.c_uint, ctypes.c_void_p, ctypes.POINTER(ctypes.c_int)]),
        "eglGetDisplayDriverName": (ctypes.c_char_p, [ctypes.c_void_p]),
    }

    def __init__(self, lib):
        self.lib = lib
        for name, (restype, argtypes) in self._CORE.items():
            function = getattr(lib, name)
            function.restype, function.argtypes = restype, argtypes
            setattr(self, name, function)
        for name, (restype, argtypes) in self._EXTENSIONS.items():
            address = self.eglGetProcAddress(name.encode())
            setattr(self, name, ctypes.CFUNCTYPE(restype, *argtypes)(address) if address else None)
        self.client_extensions = frozenset((self.eglQueryString(None, EGL_EXTENSIONS) or b"").decode().split())

    def string(self, display, name):
        """``eglQueryString(display, name)`` as str, or None."""
        value = self.eglQueryString(display, name)
        return value.decode(errors="replace") if value else None

    def error(self, what):
        """``'<what> failed (EGL error 0x3001 EGL_NOT_INITIALIZED)'`` for the thread's last EGL error."""
        code = self.eglGetError()
        return f"{what} failed (EGL error {code:#x}{' ' + EGL_ERRORS[code] if code in EGL_ERRORS else ''})"


EGL_EXTENSIONS, EGL_VENDOR, EGL_VERSION, EGL_NONE = 0x3055, 0x3053, 0x3054, 0x3038
EGL_ERRORS = {0x3001: "EGL_NOT_INITIALIZED", 0x3002: "EGL_BAD_ACCESS", 0x3003: "EGL_BAD_ALLOC",
              0x3004: "EGL_BAD_ATTRIBUTE", 0x3005: "EGL_BAD_CONFIG", 0x3006: "EGL_BAD_CONTEXT",
              0x3008: "EGL_BAD_DISPLAY", 0x3009: "EGL_BAD_MATCH", 0x300C: "EGL_BAD_PARAMETER"}


@functools.cache
def _egl_library():
    """libEGL (`library_candidates`) bound as an `_EGL`; OSError where it cannot be loaded."""
    lib = _load("egl")
    try:
        return _EGL(lib)
    except AttributeError as exc:
        raise OSError(f"{lib._name} is not a usable libEGL: {exc}") from None


def egl_device_count():
    """The number of EGL devices (``eglQueryDevicesEXT``, all of them, before `glphong.gpu.devices`'s visibility
    variables), or None where libEGL or the extension is missing."""
    try:
        egl = _egl_library()
    except OSError:
        return None
    if egl.eglQueryDevicesEXT is None:
        return None
    count = ctypes.c_int(0)
    return count.value if egl.eglQueryDevicesEXT(0, None, ctypes.byref(count)) else None


class _OSMesaLoader:
    """moderngl loader and make-current hooks for one OSMesa context."""

    def __init__(self, lib, handle):
        self._lib = lib
        self._handle = handle
        # OSMesa needs a colour buffer to make a context current; all
        # rendering goes to framebuffer objects, so one pixel suffices.
        self._buffer = (ctypes.c_ubyte * 4)()

    def make_current(self):
        """Make the context current; return whether OSMesa accepted it."""
        return bool(
            self._lib.OSMesaMakeCurrent(self._handle, self._buffer, _GL_UNSIGNED_BYTE, 1, 1)
        )

    def load_opengl_function(self, name):
        """Return the address of GL function ``name``, 0 if it is missing."""
        return self._lib.OSMesaGetProcAddress(name.encode()) or 0

    def destroy(self):
        """Destroy the OSMesa context."""
        self._lib.OSMesaDestroyContext(self._handle)

    def __enter__(self):
        self.make_current()

    def __exit__(self, *exc_info):
        pass

    def release(self):
        pass


@functools.cache
def _osmesa_library():
    """Load libOSMesa (`library_candidates`) and declare the signatures used here."""
    lib = _load("osmesa")
    lib.OSMesaCreateContextAttribs.restype = ctypes.c_void_p
    lib.OSMesaCreateContextAttribs.argtypes = [ctypes.POINTER(ctypes.c_int), ctypes.c_void_p]
    lib.OSMesaMakeCurrent.restype = ctypes.c_ubyte
    lib.OSMesaMakeCurrent.argtypes = [
        ctypes.c_void_p, ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_int
    ]
    lib.OSMesaGetProcAddress.restype = ctypes.c_void_p
    lib.OSMesaGetProcAddress.argtypes = [ctypes.c_char_p]
    lib.OSMesaDestroyContext.restype = None
    lib.OSMesaDestroyContext.argtypes = [ctypes.c_void_p]
    return lib
