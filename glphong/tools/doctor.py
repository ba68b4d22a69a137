"""``glphong doctor``: why it does (not) render here.

Prints the versions of Python and the GL packages, which driver libraries load and from which file, the EGL
platforms and devices, then per backend the OpenGL version, renderer, ``GL_MAX_SAMPLES``, uniform budget and
whether subnormals flush, and one verified render (a tile of the default figure against the float64 twin);
for whatever is missing, the packages to install on Debian/Ubuntu, Fedora and conda-forge, and the environment
variables that matter.  Exit status 0 only where at least one backend renders and verifies.
"""
import ctypes.util
import glob
import importlib.metadata
import json
import os
import platform
import sys

from glphong.analysis.figures import phong_examples_scene
from glphong.checks.verify import verify
from glphong.gpu import drivers
from glphong.gpu.contexts import BACKENDS, PACKAGES, create_context
from glphong.gpu.egl_devices import devices, egl_platforms
from glphong.gpu.renderer import Renderer
from glphong.materials.phong import Phong
from glphong.testing import subnormal_flushing

__all__ = ["run_doctor", "ENVIRONMENT", "VENDOR_PACKAGES"]

#: the packages that give libEGL its Mesa vendor library (``libEGL_mesa.so.0``) and the DRI drivers
VENDOR_PACKAGES = {"Debian/Ubuntu": "apt-get install libegl-mesa0 libgl1-mesa-dri",
                   "Fedora": "dnf install mesa-libEGL mesa-dri-drivers",
                   "conda-forge": "conda install -c conda-forge libegl mesalib (or use the system's Mesa)"}

#: environment variables that change what glphong or the drivers do, and what each does
ENVIRONMENT = {
    "GLPHONG_BACKEND": "backend='auto' uses this backend (egl or osmesa) instead of trying EGL, then OSMesa",
    "GLPHONG_EGL_DEVICE": "the EGL device when none is given: an index of the list above, 'gpu' or 'software'",
    "GLPHONG_EGL_DISPLAY": "'shared': use the EGL display other libraries share (and may terminate) instead of "
                           "glphong's own",
    "EGL_VISIBLE_DEVICES": "comma-separated eglQueryDevicesEXT indices glphong may use (GPU devices only)",
    "CUDA_VISIBLE_DEVICES": "hides the GPU devices whose CUDA number (EGL_NV_device_cuda) is not listed",
    "GLPHONG_LIBEGL": "the libEGL file glphong loads (a name or a path) instead of the system's",
    "GLPHONG_LIBOSMESA": "the libOSMesa file glphong loads (a name or a path) instead of the system's",
    "__EGL_VENDOR_LIBRARY_FILENAMES": "libglvnd: the vendor JSON files libEGL loads (colon-separated); a wrong one "
                                      "leaves EGL with no devices",
    "EGL_PLATFORM": "read by eglGetDisplay only, which glphong does not call (it names its platforms itself)",
    "LIBGL_ALWAYS_SOFTWARE": "Mesa: llvmpipe even where a GPU is present",
    "LP_NUM_THREADS": "Mesa llvmpipe's rasterizer threads (0: none; forked children can then use OpenGL)",
    "DISPLAY": "not needed: glphong never opens a window or an X connection",
}

_VENDOR_DIRS = ("/etc/glvnd/egl_vendor.d", "/usr/share/glvnd/egl_vendor.d", "/usr/local/share/glvnd/egl_vendor.d")
_LIBRARY_PATTERNS = (("libEGL", "libEGL.so"), ("EGL vendor", "libEGL_"), ("libOSMesa", "libOSMesa"),
                     ("libGL", "libGL.so"), ("libglapi", "libglapi"), ("Mesa driver", "_dri.so"),
                     ("Mesa driver", "libgallium"))


def _version(package):
    try:
        return importlib.metadata.version(package)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


def _mapped_files():
    """The shared libraries mapped into this process (``/proc/self/maps``; [] where there is none)."""
    try:
        with open("/proc/self/maps") as maps:
            paths = [line.split(None, 5)[5].strip() for line in maps if len(line.split(None, 5)) == 6]
    except OSError:
        return []
    return list(dict.fromkeys(p for p in paths if ".so" in os.path.basename(p)))


def _vendor_files():
    """The EGL vendor JSON files libglvnd reads, with the library each names (or why it cannot be read)."""
    chosen = os.environ.get("__EGL_VENDOR_LIBRARY_FILENAMES")
    if chosen:
        files = [f for f in chosen.split(":") if f]
    else:
        directories = [d for d in os.environ.get("__EGL_VENDOR_LIBRARY_DIRS", "").split(":") if d] or _VENDOR_DIRS
        files = sorted(f for d in directories for f in glob.glob(os.path.join(d, "*.json")))
    found = []
    for path in files:
        try:
            with open(path, "rb") as handle:  # at most 64 KiB (a vendor file is some 100 bytes; a path from the
                text = handle.read(_VENDOR_FILE_BYTES + 1)  # environment may name /dev/zero or a huge file)
            if len(text) > _VENDOR_FILE_BYTES:
                raise ValueError(f"more than {_VENDOR_FILE_BYTES} bytes: not an EGL vendor file")
            library = json.loads(text)["ICD"]["library_path"]
            found.append((path, library, None))
        except (OSError, ValueError, KeyError, TypeError) as exc:
            found.append((path, None, f"unreadable ({type(exc).__name__}: {exc})"))
    return found


#: the largest EGL vendor JSON file the doctor reads [bytes]
_VENDOR_FILE_BYTES = 65536


def _hints(what, packages):
    return [f"  to get {what}:"] + [f"    {family}: {command}" for family, command in packages.items()]


def _backend_report(name, tile, out):
    """Print one backend's context facts and verified render; return (verified, problem or None)."""
    try:
        context = create_context(name)
    except Exception as exc:  # noqa: BLE001 - the reason is the report
        out(f"  {name}: no context: {' '.join(str(exc).split())}")
        return False, str(exc)
    try:
        info = context.mgl.info
        with context:
            flushing = subnormal_flushing(context=context)
        out(f"  {name}: OpenGL {info['GL_VERSION']}, renderer {context.renderer_name!r}"
            + (f", EGL device {context.device}, display {context.display}" if name == "egl" else ""))
        out(f"    GL_MAX_SAMPLES {info['GL_MAX_SAMPLES']}; uniform budget: "
            f"{info['GL_MAX_VERTEX_UNIFORM_COMPONENTS']} vertex and {info['GL_MAX_FRAGMENT_UNIFORM_COMPONENTS']} "
            f"fragment components, blocks of {info['GL_MAX_UNIFORM_BLOCK_SIZE']} bytes")
        out(f"    subnormal float32: operands {'flushed to 0' if flushing['inputs'] else 'kept'}, results "
            f"{'flushed to 0' if flushing['results'] else 'kept'}")
    finally:
        context.release()
    scene = phong_examples_scene(Phong, 20.0, 35.0, sphere_subdivisions=3)
    try:
        with Renderer(tile, tile, backend=name) as renderer:
            report = verify(scene, renderer)
    except Exception as exc:  # noqa: BLE001
        out(f"    verification render: failed: {' '.join(str(exc).split())}")
        return False, str(exc)
    out(f"    verification render ({tile}x{tile} tile of the default figure, Phong q=20, light at 35 deg): "
        f"{'passed' if report.passed else 'FAILED'}, max relative error {report.max_relative_error:.3g} "
        "against the float64 twin")
    return report.passed, None if report.passed else "the verification render left the tolerance band"


def run_doctor(tile=32, out=print):
    """Print the report; return the exit status (0 where a backend renders and verifies, else 1).

    Parameters
    ----------
    tile : int
        Side of the verification render [px].
    out : callable
        Called with each line.

    Returns
    -------
    int
    """
    out(f"Python {platform.python_version()} ({sys.executable}) on {platform.platform()}")
    out("packages: " + ", ".join(f"{p} {_version(p)}" for p in ("glphong", "moderngl", "glcontext", "numpy")))
    problems = {}
    for name in BACKENDS:
        try:
            (drivers._egl_library if name == "egl" else drivers._osmesa_library)()
        except OSError as exc:
            problems[name] = str(exc)
    out("EGL vendor files (libglvnd):")
    vendors = _vendor_files()
    for path, library, error in vendors:
        out(f"  {path}: {library or error}")
    if not vendors:
        out("  none found")
    out(f"EGL platforms: {', '.join(egl_platforms()) or ('none (libEGL not loaded)' if 'egl' in problems else 'none (no EGL vendor library answered)')}")
    listed = devices(probe=True)
    out("EGL devices:" + ("" if listed else " none"))
    for device in listed:
        out(f"  {device.describe()}")
    out("OpenGL backends:")
    verified = []
    for name in BACKENDS:
        ok, problem = _backend_report(name, tile, out)
        if ok:
            verified.append(name)
        elif problem is not None:
            problems.setdefault(name, problem)
    out("libraries loaded in this process:")
    mapped = _mapped_files()
    for label, pattern in _LIBRARY_PATTERNS:
        for path in (p for p in mapped if pattern in os.path.basename(p)):
            out(f"  {label}: {path}")
    if not any(pattern in os.path.basename(p) for p in mapped for _, pattern in _LIBRARY_PATTERNS[:3]):
        out("  none of libEGL, an EGL vendor, libOSMesa")
    if not any("libGL.so" in os.path.basename(p) for p in mapped):
        libgl = ctypes.util.find_library("GL")
        out(f"  libGL: {'installed as ' + libgl if libgl else 'not installed'}, not loaded (glphong does not need "
            "it; pyrender and VTK do)")
    out("environment:")
    for variable, meaning in ENVIRONMENT.items():
        value = os.environ.get(variable)
        out(f"  {variable}={value!r}: {meaning}" if value is not None else f"  {variable} (unset): {meaning}")
    if problems:
        out("missing or broken:")
        for name, problem in problems.items():
            out(f"  {name}: {' '.join(problem.split())}")
            if name == "egl" and "libEGL not found" not in problem:
                vendor_loaded = any("libEGL_" in os.path.basename(p) for p in mapped)
                out("    libEGL loads" + ("" if vendor_loaded else ", but no EGL vendor library (Mesa's "
                                         "libEGL_mesa.so.0) did: check __EGL_VENDOR_LIBRARY_FILENAMES and the files above"))
                for line in _hints("Mesa's EGL vendor and drivers", VENDOR_PACKAGES):
                    out(line)
            else:
                for line in _hints(f"the {name} backend", PACKAGES[name]):
                    out(line)
        if "osmesa" in problems:
            out("  (OSMesa is optional: Mesa 25.1 removed it; glphong renders through EGL's software device there)")
    if verified:
        out(f"glphong renders and verifies here on: {', '.join(verified)}")
        return 0
    out("glphong cannot render here: no backend rendered and verified (see 'missing or broken' above)")
    return 1
