"""Shared fixtures: OpenGL contexts on each backend, skipped where unavailable."""

import os

import pytest

from glphong.contexts import BACKENDS, BackendUnavailableError, create_context


def _required_backends():
    names = os.environ.get("GLPHONG_REQUIRE_BACKENDS", "")
    return {name.strip() for name in names.split(",") if name.strip()}


def require_backend(name):
    """Return a new `GLContext` on backend ``name``, or skip the test.

    The test fails instead of skipping when the comma-separated environment
    variable ``GLPHONG_REQUIRE_BACKENDS`` names the backend.
    """
    try:
        return create_context(name)
    except BackendUnavailableError as exc:
        if name in _required_backends():
            pytest.fail(f"GLPHONG_REQUIRE_BACKENDS names {name!r}, but: {exc}")
        pytest.skip(str(exc))


@pytest.fixture(params=BACKENDS)
def gl_backend(request):
    """A current `GLContext` on each backend, checked for GL errors and released."""
    ctx = require_backend(request.param)
    try:
        with ctx:
            yield ctx
            ctx.check_error(f"test on {ctx.backend}")
    finally:
        ctx.release()


@pytest.fixture
def make_context():
    """Factory ``make_context(name)``: `require_backend`, released at teardown.

    Tests run with ``--import-mode=importlib`` and cannot import this module,
    so they reach `require_backend` through this fixture.
    """
    made = []

    def make(name):
        ctx = require_backend(name)
        made.append(ctx)
        return ctx

    yield make
    for ctx in made:
        ctx.release()


def _renderer_factory():
    """``(make, made)``: ``make(width, height, backend, **options)`` opens a `glphong.Renderer` with the
    skip-or-fail semantics of `require_backend`; ``made`` lists what it opened."""
    from glphong import Renderer

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


@pytest.fixture
def make_renderer():
    """Factory ``make_renderer(width, height, backend, **options)``: a `glphong.Renderer`, released at
    teardown; an unavailable backend skips the test, or fails it when ``GLPHONG_REQUIRE_BACKENDS`` names it."""
    make, made = _renderer_factory()
    yield make
    for renderer in made:
        renderer.release()


@pytest.fixture(scope="module")
def module_make_renderer():
    """`make_renderer` whose renderers live for the whole test module."""
    make, made = _renderer_factory()
    yield make
    for renderer in made:
        renderer.release()


@pytest.fixture(scope="session", params=BACKENDS)
def session_gl(request):
    """One `GLContext` per backend for the whole session (not entered), released at the end."""
    ctx = require_backend(request.param)
    yield ctx
    ctx.release()
