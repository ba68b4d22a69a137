"""EGL devices: which ones this process may render on (`devices`), which one a ``device`` argument names
(`resolve_device`), and glphong's own EGL display and context on one (`create_egl_loader`).

Nothing here runs at import: libEGL is loaded, and the devices listed, on the first call.

Choosing a device
-----------------
``device`` (of `glphong.create_context`, `glphong.Renderer`, ``render_many``) is an index of `devices`'s list,
``"gpu"`` (the first GPU device), ``"software"`` (Mesa's software device, llvmpipe) or None: the
``GLPHONG_EGL_DEVICE`` environment variable (the same forms) where set, else the first GPU device, else the
software device.  Two variables hide devices, as cluster schedulers expect:

- ``EGL_VISIBLE_DEVICES``: comma-separated indices of ``eglQueryDevicesEXT``'s own list; the others are hidden.
- ``CUDA_VISIBLE_DEVICES`` (set by SLURM and the NVIDIA container runtime): a GPU device that reports its CUDA
  device number (``EGL_CUDA_DEVICE_NV``, NVIDIA's driver) is hidden unless that number is listed; entries that
  are not integers (``GPU-<uuid>``, ``MIG-...``) hide nothing, and a device that reports no CUDA number is kept.

Mesa's software device is never hidden by either (it is the CPU).  `devices` numbers the remaining devices from
0 in ``eglQueryDevicesEXT``'s order.

Living beside other EGL users
-----------------------------
pyrender, VTK (PyVista) and Open3D get the display of a device with ``eglGetPlatformDisplayEXT(
EGL_PLATFORM_DEVICE_EXT, device, NULL)`` and end it with ``eglTerminate``, which ends every context on that
display, whoever made it (EGL gives one display per platform, device and attribute list).  glphong
therefore opens a display of its own (`open_display`), the first of:

1. the device platform with ``EGL_TRACK_REFERENCES_KHR`` (client extension ``EGL_KHR_display_reference``:
   another attribute list, so another display);
2. for Mesa's software device, Mesa's surfaceless platform (``EGL_MESA_platform_surfaceless``), kept only where
   the display it gives is that device;
3. the device platform with no attributes: the display the libraries above share (``shared=True``), where
   another library's ``eglTerminate`` ends glphong's contexts too (`glphong.gpu.contexts.EGLDisplayTerminatedError`
   then names the libraries loaded in the process that do so).

``GLPHONG_EGL_DISPLAY=shared`` skips 1 and 2 (the display other libraries get, as glphong 0.1 used).  glphong
never calls ``eglTerminate``.
"""

import ctypes
import dataclasses
import os
import sys
import threading

from glphong.gpu.drivers import EGL_NONE, EGL_VENDOR, EGL_VERSION, _egl_library

__all__ = ["EGLDevice", "devices", "resolve_device", "open_display", "create_egl_loader", "egl_platforms",
           "terminating_libraries"]

_EGL_PLATFORM_DEVICE_EXT = 0x313F
_EGL_PLATFORM_SURFACELESS_MESA = 0x31DD
_EGL_TRACK_REFERENCES_KHR = 0x3352
_EGL_DEVICE_EXT = 0x322C
_EGL_DRM_DEVICE_FILE_EXT = 0x3233
_EGL_DRM_RENDER_NODE_FILE_EXT = 0x3377
_EGL_RENDERER_EXT = 0x335F
_EGL_CUDA_DEVICE_NV = 0x323A
_EGL_OPENGL_API = 0x30A2
_EGL_SURFACE_TYPE, _EGL_PBUFFER_BIT = 0x3033, 0x0001
_EGL_RENDERABLE_TYPE, _EGL_OPENGL_BIT = 0x3040, 0x0008
_EGL_CONTEXT_MAJOR_VERSION, _EGL_CONTEXT_MINOR_VERSION = 0x3098, 0x30FB
_EGL_CONTEXT_OPENGL_PROFILE_MASK, _EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT = 0x30FD, 0x1

ENV_DEVICE = "GLPHONG_EGL_DEVICE"
ENV_DISPLAY = "GLPHONG_EGL_DISPLAY"
ENV_VISIBLE = ("EGL_VISIBLE_DEVICES", "CUDA_VISIBLE_DEVICES")
_SOFTWARE_NAMES = ("llvmpipe", "softpipe", "swrast", "kms_swrast", "lavapipe", "swiftshader")

#: the libraries known to call eglTerminate on the device display they share with glphong: module, description
TERMINATING_LIBRARIES = (
    ("pyrender", "pyrender (OffscreenRenderer.delete(), also when the garbage collector drops one; "
                 "glphong.integrations.pyrender.release(renderer) does not terminate)"),
    ("vtkmodules", "VTK / PyVista (a Plotter's or render window's close(), also when collected)"),
    ("open3d", "Open3D (its OffscreenRenderer's and visualizer's teardown)"),
)


@dataclasses.dataclass(frozen=True)
class EGLDevice:
    """One EGL device this process may render on.

    Attributes
    ----------
    index : int
        Its number in `devices`'s list (what ``device=`` takes).
    egl_index : int
        Its number in ``eglQueryDevicesEXT``'s list (what ``EGL_VISIBLE_DEVICES`` takes).
    kind : {'gpu', 'software'}
        ``'software'`` for Mesa's software device (``EGL_MESA_device_software``) or a driver named llvmpipe,
        softpipe or swrast.
    vendor, driver, renderer : str or None
        ``EGL_VENDOR`` of glphong's display on it, the driver (``EGL_MESA_query_driver``, Mesa only) and the
        renderer (``EGL_RENDERER_EXT`` where the driver gives it); None where not reported.
    drm_file : str or None
        Its DRM node (``EGL_EXT_device_drm``), e.g. ``/dev/dri/card0``.
    cuda_device : int or None
        Its CUDA device number (``EGL_NV_device_cuda``).
    display : str or None
        How glphong gets a display on it (see the module's docstring): ``'own (EGL_KHR_display_reference)'``,
        ``'own (surfaceless)'``, ``'shared'``; None where none could be initialised.
    error : str or None
        Why no display could be initialised (e.g. ``EGL_BAD_ACCESS`` where a scheduler's cgroup forbids the
        device); None where it can be used.
    extensions : tuple of str
        The device's extensions.
    """

    index: int
    egl_index: int
    kind: str
    vendor: str = None
    driver: str = None
    renderer: str = None
    drm_file: str = None
    cuda_device: int = None
    display: str = None
    error: str = None
    extensions: tuple = ()

    def describe(self):
        """One line: ``'0: software, Mesa Project, driver swrast, display own (surfaceless)'``."""
        parts = [self.kind, self.vendor, self.renderer, self.driver and f"driver {self.driver}",
                 self.drm_file, self.cuda_device is not None and f"CUDA device {self.cuda_device}",
                 self.display and f"display {self.display}", self.error and f"unusable: {self.error}"]
        return f"{self.index}: " + ", ".join(str(p) for p in parts if p)


_LOCK = threading.RLock()
_DISPLAYS = {}   # EGL device handle (or None: surfaceless without devices) -> (display, how, shared)


def _raw_devices(egl):
    """``eglQueryDevicesEXT``'s handles; () where the extension is missing."""
    if egl.eglQueryDevicesEXT is None:
        return ()
    count = ctypes.c_int(0)
    if not egl.eglQueryDevicesEXT(0, None, ctypes.byref(count)) or count.value <= 0:
        return ()
    handles = (ctypes.c_void_p * count.value)()
    egl.eglQueryDevicesEXT(count.value, handles, ctypes.byref(count))
    return tuple(handles[:count.value])


def _device_string(egl, handle, name):
    if egl.eglQueryDeviceStringEXT is None:
        return None
    value = egl.eglQueryDeviceStringEXT(handle, name)
    return value.decode(errors="replace") if value else None


def _initialise(egl, display):
    if not display:
        return False
    major, minor = ctypes.c_int(), ctypes.c_int()
    return bool(egl.eglInitialize(display, ctypes.byref(major), ctypes.byref(minor)))


def _display_device(egl, display):
    if egl.eglQueryDisplayAttribEXT is None:
        return None
    value = ctypes.c_ssize_t(0)
    return value.value if egl.eglQueryDisplayAttribEXT(display, _EGL_DEVICE_EXT, ctypes.byref(value)) else None


def open_display(handle, software):
    """glphong's initialised EGL display on the device ``handle`` (see the module's docstring), made once per
    device and process and never terminated.

    Parameters
    ----------
    handle : int or None
        An ``EGLDeviceEXT``; None where EGL lists no devices (then Mesa's surfaceless platform).
    software : bool
        Whether it is Mesa's software device (the surfaceless platform is tried for it).

    Returns
    -------
    display : int
        The ``EGLDisplay``.
    how : str
        ``'own (EGL_KHR_display_reference)'``, ``'own (surfaceless)'`` or ``'shared'``.
    shared : bool
        Whether other libraries get (and may terminate) the same display.

    Raises
    ------
    RuntimeError
        Where no display could be initialised; the message has the EGL error.
    """
    egl = _egl_library()
    with _LOCK:
        if handle in _DISPLAYS:  # initialised again: another library may have terminated a shared one since
            _initialise(egl, _DISPLAYS[handle][0])
            return _DISPLAYS[handle]
        get = egl.eglGetPlatformDisplayEXT
        if get is None:
            raise RuntimeError("libEGL has no eglGetPlatformDisplayEXT (EGL_EXT_platform_base)")
        choice = os.environ.get(ENV_DISPLAY, "").strip().lower() or "own"
        if choice not in ("own", "shared"):
            raise RuntimeError(f"{ENV_DISPLAY} must be 'own' or 'shared' (got {os.environ[ENV_DISPLAY]!r})")
        own = choice == "own" or handle is None
        tries = []
        if own and handle is not None and "EGL_KHR_display_reference" in egl.client_extensions:
            tries.append((_EGL_PLATFORM_DEVICE_EXT, handle, (_EGL_TRACK_REFERENCES_KHR, 1, EGL_NONE),
                          "own (EGL_KHR_display_reference)", False))
        if own and (software or handle is None) and "EGL_MESA_platform_surfaceless" in egl.client_extensions:
            tries.append((_EGL_PLATFORM_SURFACELESS_MESA, None, None, "own (surfaceless)", False))
        if handle is not None:
            tries.append((_EGL_PLATFORM_DEVICE_EXT, handle, None, "shared", True))
        failures = []
        for platform, native, attributes, how, shared in tries:
            array = None if attributes is None else (ctypes.c_int * len(attributes))(*attributes)
            display = get(platform, native, array)
            if not _initialise(egl, display):
                failures.append(egl.error(f"eglInitialize ({how})"))
                continue
            if how == "own (surfaceless)" and handle is not None and _display_device(egl, display) != handle:
                failures.append("the surfaceless display is another device")  # e.g. a GPU's render node
                continue
            _DISPLAYS[handle] = (display, how, shared)
            return _DISPLAYS[handle]
        raise RuntimeError("; ".join(failures) or "libEGL lists no EGL devices and offers no surfaceless platform: "
                           "no EGL vendor library (Mesa's libEGL_mesa.so.0, NVIDIA's libEGL_nvidia.so.0) answered")


def _visible(egl_index, cuda_device, kind):
    """Whether ``EGL_VISIBLE_DEVICES`` / ``CUDA_VISIBLE_DEVICES`` leave this device visible."""
    if kind == "software":
        return True
    listed = os.environ.get("EGL_VISIBLE_DEVICES")
    if listed is not None and listed.strip() != "":
        if str(egl_index) not in [p.strip() for p in listed.split(",")]:
            return False
    cuda = os.environ.get("CUDA_VISIBLE_DEVICES")
    if cuda is not None and cuda_device is not None:
        entries = [p.strip() for p in cuda.split(",") if p.strip()]
        numbers = [int(p) for p in entries if p.lstrip("-").isdigit()]
        if len(numbers) == len(entries):  # only integer lists select (UUIDs and MIG names are not matched)
            return cuda_device in numbers
    return True


def _describe_device(egl, egl_index, handle):
    extensions = tuple((_device_string(egl, handle, 0x3055) or "").split())
    cuda = None
    if "EGL_NV_device_cuda" in extensions and egl.eglQueryDeviceAttribEXT is not None:
        value = ctypes.c_ssize_t(0)
        if egl.eglQueryDeviceAttribEXT(handle, _EGL_CUDA_DEVICE_NV, ctypes.byref(value)):
            cuda = value.value
    fields = {"egl_index": egl_index, "extensions": extensions, "cuda_device": cuda,
              "drm_file": _device_string(egl, handle, _EGL_DRM_DEVICE_FILE_EXT) if "EGL_EXT_device_drm" in extensions else None,
              "renderer": _device_string(egl, handle, _EGL_RENDERER_EXT) if "EGL_EXT_device_query_name" in extensions else None}
    software = "EGL_MESA_device_software" in extensions
    try:
        display, how, _ = open_display(handle, software)
        fields.update(display=how, vendor=egl.string(display, EGL_VENDOR))
        if egl.eglGetDisplayDriverName is not None:
            name = egl.eglGetDisplayDriverName(display)
            fields["driver"] = name.decode() if name else None
    except RuntimeError as exc:
        fields["error"] = str(exc)
    names = " ".join(str(fields.get(k) or "") for k in ("driver", "renderer")).lower()
    fields["kind"] = "software" if software or any(n in names for n in _SOFTWARE_NAMES) else "gpu"
    return fields


def devices(probe=False):
    """The EGL devices this process may render on, in ``eglQueryDevicesEXT``'s order, less those the
    visibility variables hide (see the module's docstring).

    Parameters
    ----------
    probe : bool, optional
        Where the driver does not name a device's renderer (``EGL_RENDERER_EXT``), make a throwaway OpenGL
        context on it and read ``GL_RENDERER`` (a few milliseconds each; call it outside any ``with`` block of
        a glphong context).  ``glphong doctor`` does.

    Returns
    -------
    list of EGLDevice
        Empty where libEGL or its device enumeration (``EGL_EXT_device_enumeration``) is missing.
    """
    try:
        egl = _egl_library()
    except OSError:
        return []
    listed = []
    for egl_index, handle in enumerate(_raw_devices(egl)):
        fields = _describe_device(egl, egl_index, handle)
        if _visible(egl_index, fields["cuda_device"], fields["kind"]):
            device = EGLDevice(index=len(listed), **fields)
            if probe and device.renderer is None and device.error is None:
                renderer = _probe_renderer(device)
                software = device.kind == "software" or any(n in (renderer or "").lower() for n in _SOFTWARE_NAMES)
                device = dataclasses.replace(device, renderer=renderer, kind="software" if software else "gpu")
            listed.append(device)
    return listed


def _probe_renderer(device):
    """``GL_RENDERER`` of a throwaway context on ``device`` (None where none can be made); the calling thread's
    current EGL context is made current again."""
    egl = _egl_library()
    previous = (egl.eglGetCurrentDisplay(), egl.eglGetCurrentContext())
    try:
        loader = create_egl_loader(device)
    except RuntimeError:
        return None
    try:
        address = loader.load_opengl_function("glGetString")
        value = ctypes.CFUNCTYPE(ctypes.c_char_p, ctypes.c_uint)(address)(0x1F01) if address else None  # GL_RENDERER
    finally:
        loader.destroy()
        if previous[1]:
            egl.eglMakeCurrent(previous[0], None, None, previous[1])
    return value.decode(errors="replace") if value else None


def _handle(device):
    """The ``EGLDeviceEXT`` of an `EGLDevice` (None where EGL lists none)."""
    handles = _raw_devices(_egl_library())
    return handles[device.egl_index] if device is not None and device.egl_index < len(handles) else None


def resolve_device(device=None):
    """The `EGLDevice` a ``device`` argument names.

    Parameters
    ----------
    device : int, {'gpu', 'software'} or None
        An index of `devices`, the first device of a kind, or None: ``GLPHONG_EGL_DEVICE`` where set, else the
        first GPU device, else the software device, else the first device.

    Returns
    -------
    EGLDevice or None
        None only where EGL lists no devices at all and ``device`` is None (a surfaceless display is used).

    Raises
    ------
    ValueError
        If ``device`` is not one of the forms above, or names no device here; the message lists those there are.
    """
    origin = ""
    if device is None and os.environ.get(ENV_DEVICE, "").strip():
        text = os.environ[ENV_DEVICE].strip().lower()
        device, origin = (int(text) if text.isdigit() else text), f" (from {ENV_DEVICE}={os.environ[ENV_DEVICE]!r})"
    listed = devices()
    if device is None:
        usable = [d for d in listed if d.error is None]
        return next((d for d in usable if d.kind == "gpu"), None) or next(iter(usable or listed), None)
    if isinstance(device, str) and device in ("gpu", "software"):
        found = next((d for d in listed if d.kind == device and d.error is None), None)
    elif isinstance(device, int) and not isinstance(device, bool):
        found = listed[device] if 0 <= device < len(listed) else None
    else:
        raise ValueError(f"device must be an EGL device index, 'gpu' or 'software'{origin} (got {device!r})")
    if found is None:
        hidden = [f"{v}={os.environ[v]!r}" for v in ENV_VISIBLE if os.environ.get(v) is not None]
        have = "; ".join(d.describe() for d in listed) if listed else "none (libEGL or EGL_EXT_device_enumeration missing)"
        raise ValueError(f"no EGL device {device!r}{origin} here: the EGL devices this process may use are: {have}"
                         + (f" (after {', '.join(hidden)})" if hidden else ""))
    return found


def egl_platforms():
    """The EGL platforms libEGL offers (client extensions ``EGL_*_platform_*``), e.g. ``['device', 'surfaceless']``;
    [] where libEGL cannot be loaded."""
    try:
        extensions = _egl_library().client_extensions
    except OSError:
        return []
    return sorted({e.split("platform_", 1)[1] for e in extensions if "_platform_" in e and "base" not in e})


def terminating_libraries():
    """Descriptions of the libraries loaded in this process that terminate the EGL display they share with
    glphong (`TERMINATING_LIBRARIES`)."""
    return [text for module, text in TERMINATING_LIBRARIES if module in sys.modules]


class EGLLoader:
    """moderngl loader and make-current hooks for one EGL context on glphong's display of a device."""

    def __init__(self, egl, display, context, how, shared):
        self._egl, self.display, self.context, self.how, self.shared = egl, display, context, how, shared

    def make_current(self):
        """Make the context current on this thread (for OpenGL, ``eglBindAPI`` being per thread); return whether
        EGL accepted it."""
        self._egl.eglBindAPI(_EGL_OPENGL_API)
        return bool(self._egl.eglMakeCurrent(self.display, None, None, self.context))

    def is_current(self):
        """Whether EGL has this context current on the calling thread."""
        return self._egl.eglGetCurrentContext() == self.context

    def load_opengl_function(self, name):
        """The address of GL function ``name`` (``eglGetProcAddress``), 0 if it is missing."""
        return self._egl.eglGetProcAddress(name.encode()) or 0

    def destroy(self):
        """Destroy the context (not the display)."""
        if self.is_current():
            self._egl.eglMakeCurrent(self.display, None, None, None)
        self._egl.eglDestroyContext(self.display, self.context)

    def __enter__(self):
        self.make_current()

    def __exit__(self, *exc_info):
        self._egl.eglMakeCurrent(self.display, None, None, None)

    def release(self):
        pass


def create_egl_loader(device, require=330):
    """A new OpenGL core-profile context on ``device``'s display (`open_display`), made current.

    Parameters
    ----------
    device : EGLDevice or None
        From `resolve_device`; None for a surfaceless display where EGL lists no devices.
    require : int
        Minimum OpenGL version requested, ``major * 100 + minor * 10`` (drivers give the newest compatible one).

    Returns
    -------
    EGLLoader

    Raises
    ------
    RuntimeError
        Where the device has no usable display, no OpenGL config, or refuses the context.
    """
    egl = _egl_library()
    if device is not None and device.error is not None:
        raise RuntimeError(f"EGL device {device.index} is unusable: {device.error}")
    display, how, shared = open_display(_handle(device), device is None or device.kind == "software")
    if not egl.eglBindAPI(_EGL_OPENGL_API):
        raise RuntimeError(egl.error("eglBindAPI(EGL_OPENGL_API)"))
    attributes = (ctypes.c_int * 5)(_EGL_SURFACE_TYPE, _EGL_PBUFFER_BIT, _EGL_RENDERABLE_TYPE, _EGL_OPENGL_BIT, EGL_NONE)
    config, count = ctypes.c_void_p(), ctypes.c_int(0)
    if not egl.eglChooseConfig(display, attributes, ctypes.byref(config), 1, ctypes.byref(count)) or count.value < 1:
        attributes[1] = 0  # a surfaceless display may offer no pbuffer configs: any config will do
        if not egl.eglChooseConfig(display, attributes, ctypes.byref(config), 1, ctypes.byref(count)) or count.value < 1:
            raise RuntimeError(f"no OpenGL EGL config on {egl.string(display, EGL_VENDOR)} "
                               f"EGL {egl.string(display, EGL_VERSION)}")
    context_attributes = (ctypes.c_int * 7)(_EGL_CONTEXT_MAJOR_VERSION, require // 100, _EGL_CONTEXT_MINOR_VERSION,
                                            require // 10 % 10, _EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                            _EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE)
    context = egl.eglCreateContext(display, config, None, context_attributes)
    if not context:
        raise RuntimeError(egl.error(f"eglCreateContext (OpenGL {require // 100}.{require // 10 % 10} core)"))
    loader = EGLLoader(egl, display, context, how, shared)
    if not loader.make_current():
        message = egl.error("eglMakeCurrent")
        loader.destroy()
        raise RuntimeError(message)
    return loader
