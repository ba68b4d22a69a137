"""Shared fixtures: OpenGL contexts on each backend, skipped where unavailable."""
import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import glphong
from glphong.gpu.contexts import BACKENDS

# glphong's own pytest plugin (fixtures glphong_backend, glphong_context, glphong_renderer,
# glphong_make_renderer): the suite uses it the way a user's conftest.py would
pytest_plugins = ["glphong.testing"]


def require_backend(name):
    """`glphong.testing.require_backend` (imported at use: the plugin module loads first)."""
    from glphong.testing import require_backend as require

    return require(name)


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


@pytest.fixture
def make_renderer(glphong_make_renderer):
    """Factory ``make_renderer(width, height, backend, **options)``: the plugin's `glphong_make_renderer`."""
    return glphong_make_renderer


@pytest.fixture(scope="module")
def module_make_renderer():
    """`make_renderer` whose renderers live for the whole test module."""
    from glphong.testing import renderer_factory

    make, made = renderer_factory()
    yield make
    for renderer in made:
        renderer.release()


@pytest.fixture(scope="session", params=BACKENDS)
def session_gl(request):
    """One `GLContext` per backend for the whole session (not entered), released at the end."""
    ctx = require_backend(request.param)
    yield ctx
    ctx.release()


@pytest.fixture(scope="session")
def stability_expectations():
    """One `glphong.checks.stability.CaseExpectations` per test process: the suite's twins, bands and oracles,
    computed once for every run that passes it (both backends, the stable, naive and auto formulations)."""
    from glphong.checks.stability import CaseExpectations

    return CaseExpectations()


def _isolated_runner(code, timeout=120, memory_bytes=3 << 30, cwd=None, args=()):
    """Run Python ``code`` in a fresh interpreter with an address-space limit and a timeout (see
    `run_isolated`); returns the ``subprocess.CompletedProcess`` (``returncode`` -9 after the timeout)."""
    import os
    import resource
    import subprocess
    import sys

    def limit():  # in the child, before exec: a runaway allocation fails instead of taking the machine
        resource.setrlimit(resource.RLIMIT_AS, (memory_bytes, memory_bytes))

    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", PYTHONUNBUFFERED="1")
    try:
        return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, timeout=timeout,
                              preexec_fn=limit, cwd=cwd, env=env)
    except subprocess.TimeoutExpired as exc:
        return subprocess.CompletedProcess(exc.cmd, -9, exc.stdout or "", (exc.stderr or "") +
                                           f"\n[killed after the {timeout} s timeout]")


@pytest.fixture
def run_isolated():
    """``run_isolated(code, timeout=120, memory_bytes=3 GiB, cwd=None, args=())``: Python ``code`` in a
    subprocess under an address-space limit (``RLIMIT_AS``) and a timeout, so that a hostile input that
    regresses into a hang or a memory blow-up fails its test instead of taking the machine down.  Returns
    the ``subprocess.CompletedProcess`` (text output; ``returncode`` -9 on timeout)."""
    return _isolated_runner


@pytest.fixture(scope="session")
def pyrender_check():
    """``run(script, platform)``: run a pyrender check script in a subprocess (pyrender reads PYOPENGL_PLATFORM once
    per process) and return the JSON object its last line prints; an unavailable platform skips, unless
    ``GLPHONG_REQUIRE_BACKENDS`` names it."""

    def run(script, platform, timeout=600):
        # glphong's verdict first: without the backend (no libOSMesa: Debian's Mesa 25.1 and newer), `import pyrender`
        # itself fails inside PyOpenGL, before the script can report BackendUnavailable
        require_backend(platform).release()
        env = {k: v for k, v in os.environ.items() if k != "PYOPENGL_PLATFORM"}
        out = subprocess.run([sys.executable, str(script), platform], capture_output=True, text=True, timeout=timeout,
                             env=env)
        if out.returncode != 0 and "BackendUnavailable" in out.stderr and platform not in os.environ.get(
                "GLPHONG_REQUIRE_BACKENDS", ""):
            pytest.skip(f"{platform} unavailable: {out.stderr.strip().splitlines()[-1]}")
        assert out.returncode == 0, out.stderr[-3000:]
        return json.loads(out.stdout.strip().splitlines()[-1])

    return run


#: tests that each take 10 s or more (CI's --durations), run first: a long test started last keeps one worker busy
#: alone at the end of the run (longest first is the classic schedule for parallel workers); the rest keep their order
LONG_FIRST = (
    "tests/test_docs.py::test_the_site_builds",
    "tests/test_soak.py::test_frames_with_a_new_scene_each_grow_nothing",
    "tests/test_docs.py::test_docs_python_block_runs[measured_brdfs.md",
    "tests/test_custom_material_example.py::test_its_stability_cases_run_from_the_command_line",
    "tests/lights/test_light_mechanism.py::test_cli_stability_imports_a_light_kind",
    "tests/lights/test_area_lights.py::test_the_continuous_version_example_runs",
    "tests/test_stability.py::test_naive_formulation_fails_where_the_design_says",
    "tests/test_numerics.py::test_stability_suite_in_auto_mode",
    "tests/materials/test_measured.py::test_cli_brdf_and_plots_of_a_measured_file",
    "tests/test_stability.py::test_cli_stability_json",
)


def pytest_collection_modifyitems(config, items):
    """Move the `LONG_FIRST` tests to the front of the run, in that order."""
    def rank(item):
        return next((i for i, prefix in enumerate(LONG_FIRST) if item.nodeid.startswith(prefix)), len(LONG_FIRST))
    items.sort(key=rank)  # stable: the others keep their collection order


@pytest.fixture
def load_example():
    """``load_example(name)``: the module of ``examples/<name>.py``, executed afresh (its ``main`` not run)."""
    def load(name):
        spec = importlib.util.spec_from_file_location(name, Path(__file__).resolve().parent.parent / "examples" /
                                                      f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module
    return load


@pytest.fixture
def lights_behind_scene():
    """``build(glass, material, name='glass')``: a transmissive mesh ``glass`` drawn with ``material`` at the origin
    over a Lambert floor 1 m below it, seen from above, lit from behind it (a point, a spot and a directional light
    below or through it) and from in front (a point light): the transmission tests' scene for lights on both
    sides."""
    def build(glass, material, name="glass"):
        camera = glphong.PerspectiveCamera.look_at((0.3, -0.4, 2.5), (0.0, 0.0, 0.0))
        scene = glphong.Scene(camera, [glphong.PointLight((0.2, 0.1, -0.6), 5.0),
                                       glphong.SpotLight((-0.3, 0.0, -0.8), (0.2, 0.0, 1.0), 2.0,
                                                         outer_cone_angle=1.2),
                                       glphong.DirectionalLight((0.1, 0.2, 1.0), 1.5),
                                       glphong.PointLight((1.0, -1.0, 2.0), 20.0)])
        pose = np.eye(4)
        pose[2, 3] = -1.0
        scene.add(glphong.primitives.plane(4.0, segments=4), glphong.Lambert(0.4), pose=pose, name="floor")
        scene.add(glass, material, name=name)
        return scene
    return build
