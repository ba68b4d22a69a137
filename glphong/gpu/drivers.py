"""The drivers' C libraries through :mod:`ctypes`: libEGL's queries and libOSMesa's context calls.

`glphong.gpu.contexts` makes, pools and switches the contexts; this module only loads the libraries, declares the
signatures it calls and holds OSMesa's constants, so that nothing here keeps state beyond the loaded libraries.
"""

import ctypes
import ctypes.util
import functools

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


@functools.lru_cache(maxsize=1)
def _egl_current_context():
    """libEGL's ``eglGetCurrentContext`` (ctypes), or None where libEGL cannot be loaded."""
    name = ctypes.util.find_library("EGL")
    if name is None:
        return None
    try:
        function = ctypes.CDLL(name).eglGetCurrentContext
    except (OSError, AttributeError):
        return None
    function.restype = ctypes.c_void_p
    return function


def egl_device_count():
    """The number of EGL devices (``eglQueryDevicesEXT``), or None where libEGL or the extension is missing."""
    name = ctypes.util.find_library("EGL")
    if name is None:
        return None
    try:
        egl = ctypes.CDLL(name)
        egl.eglGetProcAddress.restype = ctypes.c_void_p
        egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]
        address = egl.eglGetProcAddress(b"eglQueryDevicesEXT")
    except (OSError, AttributeError):
        return None
    if not address:
        return None
    query = ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_int, ctypes.POINTER(ctypes.c_void_p),
                             ctypes.POINTER(ctypes.c_int))(address)
    count = ctypes.c_int(0)
    return count.value if query(0, None, ctypes.byref(count)) else None


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
    """Load libOSMesa and declare the signatures used here."""
    errors = []
    for name in (ctypes.util.find_library("OSMesa"), "libOSMesa.so.8", "libOSMesa.so"):
        if name is None:
            continue
        try:
            lib = ctypes.CDLL(name)
            break
        except OSError as exc:
            errors.append(str(exc))
    else:
        raise OSError("libOSMesa not found: " + "; ".join(errors))
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
