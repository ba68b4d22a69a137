"""The toolkit's pytest plugin: its fixtures, each released at teardown.

``pytest_plugins = ["glphong.testing"]`` in a ``conftest.py`` (or ``pytest -p glphong.testing``) loads it: the
package names this module in its own ``pytest_plugins``, so that ``import glphong.testing`` never imports pytest.

- `glphong_backend`: each backend name ('egl', 'osmesa'); a missing one skips with its reason, or fails where
  ``GLPHONG_REQUIRE_BACKENDS=egl,osmesa`` asks for it (`glphong.testing.require_backend`);
- `glphong_context`: a `glphong.gpu.contexts.GLContext` on each backend;
- `glphong_make_renderer`: a factory of `glphong.Renderer` s (`glphong.testing.renderer_factory`), and
  `glphong_renderer`: a 64 x 64 one on each backend;
- `glphong_glsl`: a factory of `glphong.testing.glsl_function` s on each backend's pooled context.
"""
import pytest

from glphong.gpu.contexts import BACKENDS, create_context
from glphong.testing.backends import renderer_factory, require_backend
from glphong.testing.glsl_runner import glsl_function

__all__ = ["glphong_backend", "glphong_context", "glphong_make_renderer", "glphong_renderer", "glphong_glsl"]


@pytest.fixture(params=BACKENDS)
def glphong_backend(request):
    """Each OpenGL backend name ('egl', 'osmesa') that works here (else skip, or fail if required)."""
    require_backend(request.param).release()
    return request.param


@pytest.fixture
def glphong_context(glphong_backend):
    """A `glphong.gpu.contexts.GLContext` on each backend, released at teardown."""
    gl = create_context(glphong_backend)
    yield gl
    gl.release()


@pytest.fixture
def glphong_make_renderer():
    """Factory ``make(width, height, backend, **options)`` of `glphong.Renderer` s, released at teardown;
    an unavailable backend skips (or fails where required)."""
    make, made = renderer_factory()
    yield make
    for renderer in made:
        renderer.release()


@pytest.fixture
def glphong_renderer(glphong_backend, glphong_make_renderer):
    """A 64 x 64 `glphong.Renderer` on each backend (resize it as needed), released at teardown."""
    return glphong_make_renderer(64, 64, glphong_backend)


@pytest.fixture
def glphong_glsl(glphong_backend):
    """Factory ``glphong_glsl(source, name, **options)`` of `glsl_function` s on each backend (that backend's
    pooled context: compiled per test, the context made once per process), released at teardown; a missing
    backend skips with its reason (or fails where required)."""
    made = []

    def make(source, name, **options):
        fn = glsl_function(source, name, backend=glphong_backend, **options)
        made.append(fn)
        return fn

    yield make
    for fn in made:
        fn.release()
