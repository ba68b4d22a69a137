"""glphong.testing: the shader unit-testing toolkit (docs/design.md sections 7 and 8).

- `evaluate`: run a material's GLSL response on the GPU for arrays of direction pairs, with no
  scene (a vertex program captured by transform feedback), or its numpy twin on the same inputs;
- `assert_twin_matches`: seeded random and edge direction sets, GPU against the twin under the
  tolerance band, with a failure message ready to paste into a regression test;
- `assert_light_matches`: a light kind's GLSL against its twin at seeded points (`light_points`), through the
  real shader, under the tolerance band;
- `assert_render_matches`: the image-level cross-check (`glphong.verify`) as an assertion;
- any GLSL function, not only materials (docs/shader_tests.md): `glsl_function` compiles a user's GLSL (a string
  or a ``.glsl`` file with ``#include`` s) and runs one function on numpy arrays, bit-exactly, in the vertex or the
  fragment stage; `assert_glsl_matches` compares it with a numpy twin in ULPs, absolute, relative or a band, leaving
  out the rows where GLSL is undefined (the twin written with `glsl`, GLSL's built-ins in numpy); `edge_inputs`
  and the ``hypothesis`` strategies `glsl_values` / `glsl_inputs` make the inputs;
- a pytest plugin: ``pytest_plugins = ["glphong.testing"]`` in a ``conftest.py`` gives the fixtures
  `glphong_backend` (each backend; a missing one skips with its reason unless
  ``GLPHONG_REQUIRE_BACKENDS=egl,osmesa`` asks for it, then it fails), `glphong_context`,
  `glphong_renderer` (64 x 64), `glphong_make_renderer` (a factory) and `glphong_glsl` (a factory of
  `glsl_function` on each backend's pooled context), all released at teardown.

The package's modules: ``assertions`` (the ``assert_*_matches``), ``backends`` (`require_backend`,
`renderer_factory`), the GLSL function toolkit ``glsl_runner`` (`glsl_function`), ``glsl_source`` (reading and
``#include``), ``glsl_types`` (values as 32-bit patterns), ``glsl_builtins`` (`glsl`), ``glsl_compare``
(`assert_glsl_matches`), ``glsl_arguments`` (`edge_inputs`, `glsl_inputs`), ``probe`` (glphong's own chunk functions
through `glsl_function`), ``executors`` (`InlineExecutor`: a batch's tasks run in the calling process, for
testing batch pipelines), and ``plugin`` (the fixtures; ``import glphong.testing`` does not import pytest).  It
stands on `glphong.evaluation` (`evaluate`, `direction_sets` and the closed-form helpers, re-exported here) and on
the render check (`glphong.checks`: the twin, the tolerance band, `glphong.verify`).

Example
-------
::

    from glphong.testing import assert_twin_matches, evaluate

    def test_minnaert_twin(glphong_backend):
        assert_twin_matches(Minnaert(k=0.3, m=0.7), backend=glphong_backend)
"""

from glphong.evaluation import (cosine_power_interval, direction, direction_sets, evaluate, float32_units, frame_around,
                                rotate_toward)
from glphong.testing import glsl_builtins as glsl
from glphong.testing.assertions import (TwinMismatch, assert_light_matches, assert_render_matches, assert_twin_matches,
                                        light_points)
from glphong.testing.backends import renderer_factory, require_backend
from glphong.testing.executors import InlineExecutor
from glphong.testing.glsl_arguments import edge_inputs, edge_values, glsl_inputs, glsl_values, unit_float32
from glphong.testing.glsl_compare import GlslMismatch, GlslUndefinedWarning, assert_glsl_matches, ulp32, ulps_between
from glphong.testing.glsl_runner import GlslFunction, glsl_function, subnormal_flushing
from glphong.testing.glsl_source import GlslSourceError

__all__ = ["InlineExecutor", "evaluate", "direction_sets", "assert_twin_matches", "assert_render_matches", "assert_light_matches",
           "light_points", "TwinMismatch",
           "frame_around", "direction", "rotate_toward", "float32_units", "cosine_power_interval",
           "require_backend", "renderer_factory",
           "glsl_function", "GlslFunction", "assert_glsl_matches", "GlslMismatch", "GlslUndefinedWarning",
           "GlslSourceError", "glsl", "edge_values", "edge_inputs", "glsl_values", "glsl_inputs", "unit_float32",
           "ulp32", "ulps_between", "subnormal_flushing"]

#: the fixtures: pytest loads this plugin with the package (``pytest_plugins = ["glphong.testing"]``)
pytest_plugins = ["glphong.testing.plugin"]
