"""Tests for glphong.gpu.contexts on the real EGL and OSMesa drivers."""

import moderngl
import numpy as np
import pytest

from glphong.gpu import contexts
from glphong.gpu.contexts import (
    BACKENDS,
    SYSTEM_PACKAGES,
    BackendUnavailableError,
    GLContext,
    available_backends,
    create_context,
)

RED = (0.25, 0.5, 0.75, 1.0)
BLUE = (0.125, 0.0, 1.0, 0.5)


def make_target(ctx, size=(4, 4)):
    """Return a float RGBA framebuffer of ``size`` on ``ctx`` (which must be current)."""
    return ctx.mgl.framebuffer(color_attachments=[ctx.mgl.renderbuffer(size, 4, dtype="f4")])


def read(fbo):
    width, height = fbo.size
    data = fbo.read(components=4, dtype="f4")
    return np.frombuffer(data, dtype="f4").reshape(height, width, 4)


def clear(fbo, colour):
    fbo.use()
    fbo.clear(*colour)


def assert_filled(fbo, colour):
    width, height = fbo.size
    np.testing.assert_array_equal(read(fbo), np.broadcast_to(np.float32(colour), (height, width, 4)))


@pytest.fixture
def both(make_context):
    """Live EGL and OSMesa contexts in this process."""
    return make_context("egl"), make_context("osmesa")


def test_context_properties(gl_backend):
    assert isinstance(gl_backend, GLContext)
    assert gl_backend.backend in BACKENDS
    assert isinstance(gl_backend.mgl, moderngl.Context)
    assert gl_backend.renderer_name.strip()
    assert gl_backend.renderer_name == gl_backend.mgl.info["GL_RENDERER"]
    assert gl_backend.version_code >= 330
    assert gl_backend.version_code == gl_backend.mgl.version_code
    text = repr(gl_backend)
    assert gl_backend.backend in text and gl_backend.renderer_name in text


def test_clear_and_read_back(gl_backend):
    fbo = make_target(gl_backend)
    clear(fbo, RED)
    assert_filled(fbo, RED)
    clear(fbo, BLUE)
    assert_filled(fbo, BLUE)


def test_reentering_same_context_keeps_it_current(gl_backend):
    fbo = make_target(gl_backend)
    clear(fbo, RED)
    with gl_backend:
        with gl_backend:
            assert_filled(fbo, RED)
        assert_filled(fbo, RED)
    assert_filled(fbo, RED)


def test_check_error(gl_backend):
    gl_backend.check_error("nothing")
    gl_backend.mgl.point_size = -1.0  # glPointSize(-1) sets GL_INVALID_VALUE
    with pytest.raises(RuntimeError, match="^GL error GL_INVALID_VALUE after point size$"):
        gl_backend.check_error("point size")
    gl_backend.check_error("reading the error, which clears it")


def test_require_newer_than_available(gl_backend):
    too_new = gl_backend.version_code + 10
    with pytest.raises(BackendUnavailableError, match=gl_backend.backend):
        create_context(gl_backend.backend, require=too_new)
    # The failed attempt must not take over the context entered by the fixture.
    fbo = make_target(gl_backend)
    clear(fbo, RED)
    assert_filled(fbo, RED)


def test_alternating_backends(both):
    egl, osmesa = both
    # Different sizes, so reading through the wrong context cannot pass.
    with egl:
        egl_fbo = make_target(egl, (4, 4))
    with osmesa:
        osmesa_fbo = make_target(osmesa, (8, 2))
    for egl_colour, osmesa_colour in [(RED, BLUE), (BLUE, RED), (RED, RED)]:
        with egl:
            clear(egl_fbo, egl_colour)
        with osmesa:
            clear(osmesa_fbo, osmesa_colour)
        with egl:
            assert_filled(egl_fbo, egl_colour)
            egl.check_error("egl read")
        with osmesa:
            assert_filled(osmesa_fbo, osmesa_colour)
            osmesa.check_error("osmesa read")


@pytest.mark.parametrize("outer_index", [0, 1])
def test_nested_backends_restore_outer(both, outer_index):
    outer, inner = both[outer_index], both[1 - outer_index]
    with inner:
        inner_fbo = make_target(inner, (2, 2))
        clear(inner_fbo, BLUE)
    with outer:
        outer_fbo = make_target(outer, (4, 4))
        clear(outer_fbo, RED)
        with inner:
            assert_filled(inner_fbo, BLUE)
        assert_filled(outer_fbo, RED)
        outer.check_error("nested use")


def test_creating_context_keeps_entered_one_current(gl_backend, make_context):
    fbo = make_target(gl_backend)
    clear(fbo, RED)
    for name in BACKENDS:
        make_context(name)
        assert_filled(fbo, RED)


@pytest.mark.parametrize("name", BACKENDS)
def test_release_is_idempotent(make_context, name):
    ctx = make_context(name)
    ctx.release()
    ctx.release()
    assert isinstance(ctx.mgl.mglo, moderngl.InvalidObject)
    assert "released" in repr(ctx)
    fresh = make_context(name)
    with fresh:
        fbo = make_target(fresh)
        clear(fbo, BLUE)
        assert_filled(fbo, BLUE)


@pytest.mark.parametrize("name", BACKENDS)
def test_auto_honours_environment(monkeypatch, make_context, name):
    make_context(name).release()
    monkeypatch.setenv("GLPHONG_BACKEND", name)
    ctx = create_context()
    try:
        assert ctx.backend == name
    finally:
        ctx.release()


def test_auto_prefers_egl(monkeypatch, make_context):
    make_context("egl").release()
    monkeypatch.delenv("GLPHONG_BACKEND", raising=False)
    ctx = create_context("auto")
    try:
        assert ctx.backend == "egl"
    finally:
        ctx.release()


def test_auto_rejects_bad_environment(monkeypatch):
    monkeypatch.setenv("GLPHONG_BACKEND", "vulkan")
    with pytest.raises(ValueError, match="GLPHONG_BACKEND") as info:
        create_context()
    assert "vulkan" in str(info.value)


@pytest.mark.parametrize("bad", ["EGL", "glx", "", None])
def test_bad_backend_name(bad):
    with pytest.raises(ValueError, match="backend") as info:
        create_context(bad)
    assert all(name in str(info.value) for name in ("auto", *BACKENDS))


def test_available_backends(make_context):
    report = available_backends()
    assert tuple(report) == BACKENDS
    for name, reason in report.items():
        if reason is None:
            assert make_context(name).version_code >= 330
            continue
        assert isinstance(reason, str) and reason
        make_context(name)  # skips, or fails when the backend is required


@pytest.fixture
def broken(monkeypatch):
    """Make both backends fail without touching the drivers."""

    def no_osmesa():
        raise OSError("simulated: libOSMesa.so not found")

    def no_egl(*args):
        raise Exception("simulated: eglQueryDevicesEXT failed (0x3001)")

    monkeypatch.setattr(contexts, "_osmesa_library", no_osmesa)
    monkeypatch.setattr(contexts, "create_egl_loader", no_egl)
    # nor a context an earlier test's released Renderer recycled (it would be reused instead of created)
    monkeypatch.setattr(contexts, "_reuse", lambda *args: None)
    monkeypatch.delenv("GLPHONG_BACKEND", raising=False)


def test_all_backends_failing(broken):
    with pytest.raises(BackendUnavailableError) as info:
        create_context()
    message = str(info.value)
    for text in (
        "egl:",
        "osmesa:",
        "simulated: libOSMesa.so not found",
        "simulated: eglQueryDevicesEXT failed (0x3001)",
        f"apt-get install {SYSTEM_PACKAGES['egl']}",
        f"apt-get install {SYSTEM_PACKAGES['osmesa']}",
    ):
        assert text in message
    assert message.index("egl:") < message.index("osmesa:")


@pytest.mark.parametrize("name", BACKENDS)
def test_explicit_backend_failing(broken, name):
    with pytest.raises(BackendUnavailableError) as info:
        create_context(name)
    message = str(info.value)
    assert "simulated" in message
    assert f"apt-get install {SYSTEM_PACKAGES[name]}" in message
    other = next(b for b in BACKENDS if b != name)
    assert SYSTEM_PACKAGES[other] not in message


def test_environment_backend_failing(broken, monkeypatch):
    monkeypatch.setenv("GLPHONG_BACKEND", "osmesa")
    with pytest.raises(BackendUnavailableError, match="GLPHONG_BACKEND") as info:
        create_context()
    assert "libosmesa6" in str(info.value)


def test_available_backends_reports_reasons(broken):
    assert available_backends() == {
        "egl": "simulated: eglQueryDevicesEXT failed (0x3001)",
        "osmesa": "simulated: libOSMesa.so not found",
    }


_TERMINATE_SCRIPT = """
import os, sys
os.environ["PYOPENGL_PLATFORM"] = "egl"
import numpy as np, glphong, pyrender
from glphong import primitives
from glphong.gpu.contexts import EGLDisplayTerminatedError
scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)), [glphong.PointLight((2, 2, 2), 100.0)])
scene.add(primitives.sphere(2), glphong.Lambert(0.3))
old = glphong.Renderer(32, 32, backend="egl")
before = old.render(scene).radiance.copy()
spare = glphong.Renderer(8, 8, backend="egl")
spare.release()                          # a recycled context waits in the pool
p = pyrender.OffscreenRenderer(16, 16)
p.delete()                               # eglTerminate on the display every EGL context shares
try:
    old.render(scene)
    print("RENDERED")
except EGLDisplayTerminatedError as exc:
    print("REFUSED", "pyrender" in str(exc) and "new glphong.Renderer" in str(exc))
old.release()                            # no error: the objects went with the display
with glphong.Renderer(32, 32, backend="egl") as fresh:   # the dead pooled context is dropped, not reused
    print("FRESH", np.array_equal(fresh.render(scene).radiance, before))
from glphong.testing import evaluate
first = evaluate(glphong.Lambert(0.3), [[0, 0, 1.0]], [[0, 0, 1.0]], backend="egl")
q = pyrender.OffscreenRenderer(16, 16)
q.delete()                               # again, under glphong.testing's pooled context
print("EVALUATE", np.array_equal(evaluate(glphong.Lambert(0.3), [[0, 0, 1.0]], [[0, 0, 1.0]], backend="egl"), first))
"""


def test_a_terminated_egl_display_is_named_not_rendered_through(make_context):
    """With the display every library shares (GLPHONG_EGL_DISPLAY=shared; glphong's own display is the default,
    tests/test_coexistence.py), pyrender's OffscreenRenderer.delete() on EGL terminates it: rendering with a
    glphong EGL context raises EGLDisplayTerminatedError naming what happened and the library (it returned NaN
    images before), releasing it does not raise, a new Renderer draws the same image as before, and
    glphong.testing's pooled context is replaced."""
    import importlib.util
    import subprocess
    import sys

    if importlib.util.find_spec("pyrender") is None:
        pytest.skip("pyrender is not installed (pip install 'glphong[pyrender]')")
    make_context("egl")  # skips (or fails where required) without EGL
    import os

    out = subprocess.run([sys.executable, "-c", _TERMINATE_SCRIPT], capture_output=True, text=True, timeout=120,
                         env=dict(os.environ, GLPHONG_EGL_DISPLAY="shared"))
    assert out.returncode == 0, out.stderr[-3000:]
    assert out.stdout.split() == ["REFUSED", "True", "FRESH", "True", "EVALUATE", "True"], out.stdout


def test_egl_device_selection(make_context):
    """``device`` selects an EGL device; an index this machine does not have is refused with the list of those
    it has (it suggested installing packages before), and a non-EGL backend with a device is refused."""
    import glphong
    from glphong.gpu.egl_devices import devices

    make_context("egl")  # skips (or fails where required) without EGL
    listed = devices()
    assert len(listed) >= 1
    with glphong.Renderer(8, 8, backend="egl", device=0) as renderer:
        assert renderer.context.device == 0
    with pytest.raises(ValueError, match=rf"no EGL device {len(listed)} here: the EGL devices this process may "
                                         rf"use are: 0: "):
        glphong.Renderer(8, 8, device=len(listed))
    with pytest.raises(ValueError, match="needs backend 'egl' or 'auto'"):
        glphong.Renderer(8, 8, backend="osmesa", device=0)
