"""EGL device listing and choice (glphong.gpu.devices, glphong.gpu.egl_devices) on the real drivers."""
import os
import subprocess
import sys

import pytest

import glphong.gpu
from glphong.gpu import egl_devices
from glphong.gpu.contexts import create_context


def _run(code, **env):
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                          env={**os.environ, **env})


def test_import_touches_no_egl():
    """Importing glphong, its GPU package and its command line loads no libEGL, libOSMesa or Mesa driver (a
    parent must be able to import glphong and then fork or spawn workers that make their own contexts)."""
    out = _run("import glphong, glphong.gpu, glphong.tools.cli, glphong.gpu.egl_devices\n"
               "maps = open('/proc/self/maps').read()\n"
               "print([n for n in ('libEGL', 'libOSMesa', '_dri.so') if n in maps])")
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["[]"]
    # the check can fail: listing the devices does load libEGL
    out = _run("import glphong.gpu; glphong.gpu.devices(); print('libEGL' in open('/proc/self/maps').read())")
    assert out.stdout.split() == ["True"], out.stderr[-2000:]


@pytest.fixture
def listed(make_context):
    make_context("egl")  # skips (or fails where required) without EGL
    found = glphong.gpu.devices()
    assert found, "EGL makes contexts but lists no devices"
    return found


def test_devices_are_numbered_and_described(listed):
    assert [d.index for d in listed] == list(range(len(listed)))
    assert sorted({d.egl_index for d in listed}) == [d.egl_index for d in listed]
    for device in listed:
        assert device.kind in ("gpu", "software")
        assert device.describe().startswith(f"{device.index}: {device.kind}")
        assert device.error is None or "unusable" in device.describe()


@pytest.mark.parametrize("kind", ["software", "gpu"])
def test_device_by_kind(listed, kind):
    """A context on ``device=kind`` has a renderer of that kind, judged from GL_RENDERER (not from how EGL
    classed the device); a kind this machine lacks is refused with the list of the devices it has."""
    if not any(d.kind == kind and d.error is None for d in listed):
        with pytest.raises(ValueError) as info:
            create_context("egl", device=kind)
        assert f"no EGL device '{kind}' here" in str(info.value)
        assert all(d.describe() in str(info.value) for d in listed)
        return
    ctx = create_context("auto", device=kind)
    try:
        software = any(n in ctx.renderer_name.lower() for n in ("llvmpipe", "softpipe", "swrast"))
        assert ctx.backend == "egl" and software == (kind == "software"), ctx.renderer_name
        assert listed[ctx.device].kind == kind
    finally:
        ctx.release()


def test_auto_prefers_a_gpu_device(listed):
    ctx = create_context("egl")
    try:
        gpus = [d.index for d in listed if d.kind == "gpu" and d.error is None]
        assert ctx.device == (gpus[0] if gpus else next(d.index for d in listed if d.kind == "software"))
    finally:
        ctx.release()


def test_bad_device_arguments_are_refused(listed):
    for bad in (len(listed), -1, "cuda", 1.0, True):
        with pytest.raises(ValueError, match="device") as info:
            create_context("egl", device=bad)
        if isinstance(bad, int) and not isinstance(bad, bool) and bad >= 0:
            assert "0: " in str(info.value)  # the devices that do exist


def test_environment_chooses_the_device(listed):
    out = _run("import glphong\n"
               "try:\n    glphong.create_context('egl')\nexcept ValueError as exc:\n    print('REFUSED', exc)",
               GLPHONG_EGL_DEVICE=str(len(listed)))
    assert out.stdout.startswith(f"REFUSED no EGL device {len(listed)} (from GLPHONG_EGL_DEVICE="), out.stderr[-2000:]
    out = _run("import glphong; c = glphong.create_context('egl'); print(c.device)", GLPHONG_EGL_DEVICE="software")
    assert out.stdout.split() == [str(next(d.index for d in listed if d.kind == "software"))], out.stderr[-2000:]


@pytest.mark.parametrize("egl_visible, cuda_visible, kind, egl_index, cuda, expected", [
    (None, None, "gpu", 3, 3, True),
    ("0,2", None, "gpu", 1, None, False),       # EGL_VISIBLE_DEVICES lists eglQueryDevicesEXT indices
    ("0, 2", None, "gpu", 2, None, True),
    ("0", None, "software", 1, None, True),     # the CPU is never hidden
    (None, "1", "gpu", 0, 0, False),            # CUDA_VISIBLE_DEVICES matches the CUDA number...
    (None, "1,3", "gpu", 0, 3, True),
    (None, "1", "gpu", 0, None, True),          # ...of devices that report one
    (None, "GPU-8a3b,1", "gpu", 0, 0, True),    # UUID lists are not interpreted
    (None, "", "gpu", 0, 0, False),             # an empty CUDA_VISIBLE_DEVICES hides every CUDA device
])
def test_visibility_variables(monkeypatch, egl_visible, cuda_visible, kind, egl_index, cuda, expected):
    for name, value in (("EGL_VISIBLE_DEVICES", egl_visible), ("CUDA_VISIBLE_DEVICES", cuda_visible)):
        if value is None:
            monkeypatch.delenv(name, raising=False)
        else:
            monkeypatch.setenv(name, value)
    assert egl_devices._visible(egl_index, cuda, kind) is expected


def test_bad_display_choice_is_named(listed):
    out = _run("import glphong\n"
               "try:\n    glphong.create_context('egl')\nexcept Exception as exc:\n    print(type(exc).__name__, exc)",
               GLPHONG_EGL_DISPLAY="private")
    assert "GLPHONG_EGL_DISPLAY must be 'own' or 'shared'" in out.stdout, out.stdout + out.stderr[-2000:]


def test_platforms_and_own_display(listed):
    assert "device" in egl_devices.egl_platforms()
    ctx = create_context("egl")
    try:
        assert ctx.display == listed[ctx.device].display
        if "EGL_MESA_device_software" in listed[ctx.device].extensions:  # Mesa: an own display is always possible
            assert ctx.display.startswith("own (")
    finally:
        ctx.release()


def test_probe_names_the_renderer(listed):
    """``devices(probe=True)`` reads each device's GL_RENDERER from a throwaway context: the same string a
    glphong context on that device reports, and a context entered around the call stays current."""
    probed = glphong.gpu.devices(probe=True)
    assert [d.index for d in probed] == [d.index for d in listed]
    for device in probed:
        if device.error is not None or listed[device.index].renderer is not None:  # the driver named it itself
            continue
        ctx = create_context("egl", device=device.index)
        try:
            with ctx:
                assert glphong.gpu.devices(probe=True)[device.index].renderer == ctx.renderer_name
                assert ctx.alive
        finally:
            ctx.release()
