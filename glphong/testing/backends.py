"""OpenGL backends in tests: `require_backend` opens a context or skips the test with the reason (fails where
``GLPHONG_REQUIRE_BACKENDS`` asks for the backend); `renderer_factory` opens renderers likewise.  pytest is imported
only where a backend is missing, so the toolkit runs without it.
"""
import os

from glphong.gpu.contexts import BackendUnavailableError, create_context
from glphong.gpu.renderer import Renderer

__all__ = ["require_backend", "renderer_factory"]


def _required_backends():
    names = os.environ.get("GLPHONG_REQUIRE_BACKENDS", "")
    return {name.strip() for name in names.split(",") if name.strip()}


def require_backend(name):
    """A new `GLContext` on backend ``name``; the test skips with the reason where it is unavailable,
    or fails when the comma-separated ``GLPHONG_REQUIRE_BACKENDS`` names it."""
    import pytest

    try:
        return create_context(name)
    except BackendUnavailableError as exc:
        if name in _required_backends():
            pytest.fail(f"GLPHONG_REQUIRE_BACKENDS names {name!r}, but: {exc}")
        pytest.skip(str(exc))


def renderer_factory():
    """``(make, made)``: ``make(width, height, backend, **options)`` opens a `glphong.Renderer` with the
    skip-or-fail semantics of `require_backend`; ``made`` lists what it opened (release them)."""

    made = []

    def make(width, height, backend, **options):
        try:
            renderer = Renderer(width, height, backend=backend, **options)
        except BackendUnavailableError:
            require_backend(backend).release()  # skips or fails; if it now works, report the original error
            raise
        made.append(renderer)
        return renderer

    return make, made
