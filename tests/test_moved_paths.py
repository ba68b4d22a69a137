"""The module paths of glphong 0.1.0 keep working for one release (`glphong._moved`): an old path imports the
module at its new path, the very same object (private names included), with one `DeprecationWarning` that names
the new path; the documented public paths answer without a warning.  Each runs in a fresh interpreter, since an
import happens once per process.
"""
import subprocess
import sys
import warnings

import numpy as np
import pytest

import glphong
from glphong import _moved
from glphong.shaders.binding import binding

CHECK = r"""
import importlib, sys, warnings
old, new = sys.argv[1], sys.argv[2]
import glphong
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    module = importlib.import_module(old)
assert module is importlib.import_module(new), (module, new)
deprecations = [str(w.message) for w in caught if issubclass(w.category, DeprecationWarning)]
print(len(deprecations), deprecations[0] if deprecations else "")
"""


def _import(old, new):
    result = subprocess.run([sys.executable, "-c", CHECK, old, new], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr[-2000:]
    count, _, message = result.stdout.strip().partition(" ")
    return int(count), message


@pytest.mark.parametrize("old", ["glphong.stability", "glphong.key", "glphong.loaders", "glphong.cli",
                                 "glphong.checks.glsl_function", "glphong.checks.evaluate", "glphong.checks.probe",
                                 "glphong.tools.bench", "glphong.tools.speed", "glphong.analysis.comparisons",
                                 "glphong.materials.model", "glphong.materials.params", "glphong.lights.model",
                                 "glphong.scene.numerics"])
def test_an_old_path_is_the_new_module_with_a_warning(old):
    count, message = _import(old, _moved.MOVED[old])
    assert count == 1 and f"{old} moved to {_moved.MOVED[old]}" in message


@pytest.mark.parametrize("old", sorted(_moved.PUBLIC))
def test_public_paths_answer_without_a_warning(old):
    assert _import(old, _moved.PUBLIC[old]) == (0, "")


def test_from_import_of_an_old_path_and_private_names():
    code = ("import warnings; warnings.simplefilter('error', DeprecationWarning)\n"
            "try:\n    from glphong.stability import _mirror_eye\nexcept DeprecationWarning as w:\n    print('warned', w)\n"
            "warnings.simplefilter('ignore')\nfrom glphong.stability import _mirror_eye, case_scene\n"
            "from glphong.tolerances import EPS, lobe_band\nimport glphong\nprint(callable(glphong.verify), EPS)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.splitlines()[0].startswith("warned glphong.stability moved to glphong.checks.stability")
    assert out.stdout.splitlines()[-1] == f"True {2.0 ** -24}"


def test_the_toolkit_and_the_benchmarks_keep_their_old_names():
    """``glphong.bench``, 0.1.0's work-precision module, is now the benchmarks' package: its old names answer there
    without a warning; the toolkit's and the comparisons' old module paths still give their names (warning once)."""
    code = ("import warnings\n"
            "warnings.simplefilter('error', DeprecationWarning)\n"
            "from glphong.bench import (BenchCase, BenchReport, Method, methods, quick_cases, run_bench, standard_cases,\n"
            "                           scaling_table, speed_targets, SPHERES, PLANE_Y, PLANE_SIZE)\n"
            "import glphong.testing\n"
            "warnings.simplefilter('ignore', DeprecationWarning)\n"
            "from glphong.checks.probe import evaluate, shade_points, signatures\n"
            "from glphong.checks.evaluate import direction_sets, evaluate, float32_units\n"
            "from glphong.checks.glsl_inputs import edge_inputs, glsl_inputs\n"
            "from glphong.analysis.comparisons import HandWrittenRenderer, PyrenderRenderer, import_pyrender, to_pyrender\n"
            "from glphong.tools.bench_continuous import sky_map\n"
            "import sys\n"
            "print(glphong.testing.evaluate is evaluate, sorted(m for m in sys.modules if m.split('.')[0] == 'pytest'))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip() == "True []"


def test_a_user_definition_through_the_old_paths():
    """A model and a light kind written against 0.1.0's mechanism modules still define, register and render."""
    code = ("import warnings; warnings.simplefilter('ignore', DeprecationWarning)\n"
            "from glphong.materials.model import MaterialModel, Param, Properties\n"
            "from glphong.lights.model import LightModel\n"
            "import glphong\n"
            "class Flat(MaterialModel):\n"
            "    name = 'old_path_flat'\n"
            "    params = (Param('k', 'rgb', low=0.0, high=1.0, default=0.5),)\n"
            "    glsl = 'vec3 old_path_flat_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l) "
            "{ return u_old_path_flat_k * n_dot_l; }'\n"
            "    def response(self, f, wi, wo, n_dot_l, p):\n"
            "        return p.k * n_dot_l[..., None]\n"
            "assert glphong.materials.model_named('old_path_flat') is Flat\n"
            "assert issubclass(glphong.PointLight, LightModel)\n"
            "print('ok')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr[-2000:]


def test_every_moved_target_exists():
    import importlib

    for new in list(_moved.MOVED.values()) + list(_moved.PUBLIC.values()):
        importlib.import_module(new)


def test_scene_binding_methods_answer_through_the_binding_with_a_warning():
    """The program-binding methods ``Scene`` had (``scene.program_key(obj)``, ``scene.uniform_values(...)``, ...)
    answer for one release through `glphong.shaders.binding`, each call warning with the new place."""
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)),
                          lights=[glphong.PointLight((2, 2, 2), 100.0)], ambient=glphong.AmbientLight(0.1))
    scene.add(glphong.primitives.sphere(1), glphong.Phong(0.2, 0.5, 10.0))
    bound, obj = binding(scene), scene.objects[0]
    assert binding(scene) is bound and bound.scene is scene
    key = bound.program_key(obj)
    calls = {"program_key": (obj,), "gbuffer_needs": (), "light_keys": (), "light_uniform_values": (key,),
             "uniform_values": (0, key, 1.0), "frame_uniform_values": (key, 1.0), "object_uniform_values": (0, key),
             "shadow_setups": (key.lights, 64)}
    assert set(calls) == set(_moved.MOVED_METHODS)
    for name, args in calls.items():
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            old = getattr(scene, name)(*args)
        new = getattr(bound, name)(*args)
        assert [str(w.message).split(";")[0] for w in caught] == \
            [f"Scene.{name} moved to glphong.shaders.binding.binding(scene).{name}"]
        assert caught[0].filename == __file__  # the warning points at the caller
        if isinstance(new, dict):
            assert new.keys() == old.keys() and all(np.array_equal(new[k], old[k]) for k in new)
        else:
            assert new == old
