"""Lights as open definitions (glphong.lights.LightModel): the built-in kinds and a user's go through one mechanism.

- every built-in kind's GLSL agrees with its twin through the real shader (`glphong.testing.assert_light_matches`);
- the user-defined Phong luminaire of examples/custom_light.py renders, verifies, runs in the stability suite and in
  glphong.testing, and its closed form holds;
- a planted error in a light's twin or GLSL fails both the light check and `glphong.verify`;
- a definition is checked when its class is created, with a message saying what to write;
- the program key holds each kind's count generically, in registry order.
"""
import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.checks.stability import run_stability
from glphong.lights import LightDefinitionError, LightModel, light_cases, registered_lights
from glphong.materials import Param
from glphong.testing import TwinMismatch, assert_light_matches
from glphong.shaders.binding import binding

EXAMPLE = Path(__file__).resolve().parent.parent.parent / "examples" / "custom_light.py"


def _load_example():
    module = sys.modules.get("custom_light")
    if module is None or getattr(module, "__file__", None) != str(EXAMPLE):
        spec = importlib.util.spec_from_file_location("custom_light", EXAMPLE)
        module = importlib.util.module_from_spec(spec)
        sys.modules["custom_light"] = module
        spec.loader.exec_module(module)
    return module


example = _load_example()
PhongLuminaire = example.PhongLuminaire

BUILT_IN = [glphong.PointLight((0.3, 0.2, 1.0), 5.0), glphong.PointLight((0.3, 0.2, 1.0), 5.0, range=3.0),
            glphong.DirectionalLight((0.2, 0.1, -1.0), 2.0), glphong.UnattenuatedPointLight((1.0, 2.0, 3.0), 0.5),
            glphong.SpotLight((0.0, 0.0, 1.0), (0.1, 0.0, -1.0), 3.0, 0.2, 0.6),
            glphong.SpotLight((0.0, 0.0, 1.0), (0.1, 0.0, -1.0), 3.0, 0.0, np.pi / 2, range=10.0)]


def test_registry_order_is_the_loop_order():
    assert [k.name for k in registered_lights()][:4] == ["point", "unattenuated", "directional", "spot"]


@pytest.mark.parametrize("light", BUILT_IN, ids=lambda light: repr(light)[:40])
def test_built_in_kinds_match_their_twins(light, glphong_backend):
    figures = assert_light_matches(light, backend=glphong_backend)
    assert figures["lit"] > 100 and figures["max_relative_error"] < 1e-4


@pytest.mark.parametrize("n", [0.0, 1.0, 30.0, 1e4])
def test_user_light_matches_its_twin(n, glphong_backend):
    figures = assert_light_matches(PhongLuminaire((0.0, 0.0, 1.0), (0.0, 0.3, -1.0), 4.0, n=n), backend=glphong_backend)
    assert figures["lit"] > 0


def test_example_runs_end_to_end():
    """The script defines, renders, verifies and checks the closed form (its own asserted figures)."""
    report, worst = example.main(size=(96, 72))
    assert report.passed and report.covered_pixels > 3000 and worst < 1e-5
    out = subprocess.run([sys.executable, str(EXAMPLE)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0 and "'passed': True" in out.stdout, out.stderr


def test_user_light_in_the_stability_suite(glphong_backend):
    cases = PhongLuminaire.stability_cases()
    assert len(cases) == 3 and cases == light_cases(PhongLuminaire.example())
    report = run_stability(glphong_backend, cases=cases)
    assert report.passed_count == len(cases) and report.nan_count == 0, report.format_table()


def test_cli_stability_imports_a_light_kind():
    out = subprocess.run([sys.executable, "-m", "glphong", "stability", "--import", str(EXAMPLE), "--backend", "egl"],
                         capture_output=True, text=True, timeout=600)
    assert "luminaire light, normal" in out.stdout, out.stdout[-2000:] + out.stderr[-2000:]
    assert out.returncode == 0, out.stdout[-2000:]


class WrongTwin(PhongLuminaire):
    """The same GLSL, a twin 1% too bright."""

    name = "luminaire_wrong_twin"
    glsl = PhongLuminaire.glsl.replace("luminaire", "luminaire_wrong_twin")

    def incident(self, x, p):
        valid, wi, e = super().incident(x, p)
        return valid, wi, 1.01 * e


class WrongGlsl(PhongLuminaire):
    """The right twin, a GLSL whose cosine power is n / 2."""

    name = "luminaire_wrong_glsl"
    glsl = PhongLuminaire.glsl.replace("u_luminaire_n[j]", "0.5 * u_luminaire_n[j]").replace("luminaire", "luminaire_wrong_glsl")


class BrightGlsl(PhongLuminaire):
    """The right twin, a GLSL 1% too bright: the GPU lands above the band (WrongTwin puts it below)."""

    name = "luminaire_bright_glsl"
    glsl = PhongLuminaire.glsl.replace("irradiance = min((u_luminaire_peak[j]", "irradiance = min((1.01 * u_luminaire_peak[j]") \
        .replace("luminaire", "luminaire_bright_glsl")


@pytest.mark.parametrize("kind", [WrongTwin, WrongGlsl, BrightGlsl])
def test_planted_errors_fail(kind, glphong_backend, glphong_make_renderer):
    light = kind((0.0, 0.0, 1.0), (0.0, 0.3, -1.0), 4.0, n=5.0)
    with pytest.raises(TwinMismatch, match="left the tolerance band"):
        assert_light_matches(light, backend=glphong_backend)
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, -2.0, 2.0), (0.0, 0.0, 0.0)), [light])
    scene.add(primitives.plane(3.0), glphong.Lambert(0.5))
    report = glphong.verify(scene, glphong_make_renderer(64, 64, glphong_backend))
    assert not report.passed and report.outside_count > 100


def test_program_key_counts_kinds_generically():
    lights = [glphong.SpotLight((0, 0, 1), (0, 0, -1), 1.0), glphong.PointLight((0, 0, 1), 1.0),
              PhongLuminaire((0, 0, 1), (0, 0, -1), 1.0), glphong.PointLight((1, 0, 1), 1.0)]
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)), lights)
    scene.add(primitives.plane(2.0), glphong.Lambert(0.5))
    key = binding(scene).program_key(scene.objects[0])
    assert [(k.name, k.count) for k in key.lights] == [("point", 2), ("spot", 1), ("luminaire", 1)]
    assert key.num_lights == 4 and key.light_count("point") == 2
    assert "lights=point*2+spot*1+luminaire*1" in key.describe()
    defines = dict(key.defines())
    assert defines["NUM_LUMINAIRE_LIGHTS"] == "1" and defines["NUM_LIGHTS"] == "4"
    uniforms = binding(scene).light_uniform_values(key)
    assert uniforms["u_point_position"].shape == (2, 3) and uniforms["u_luminaire_n"].shape == (1,)
    dark = glphong.Scene(scene.camera, [])
    dark.add(primitives.plane(2.0), glphong.Lambert(0.5))
    assert binding(dark).program_key(dark.objects[0]).lights == ()


def _define(**attributes):
    """A light class made of the luminaire's parts, with ``attributes`` changed."""
    body = {"name": "probe_light", "params": PhongLuminaire.params, "incident": PhongLuminaire.incident,
            "glsl": PhongLuminaire.glsl.replace("luminaire", "probe_light")} | attributes
    return type("ProbeLight", (LightModel,), body)


@pytest.mark.parametrize("attributes, message", [
    ({"name": "Probe"}, "must be a lowercase GLSL identifier"),
    ({"name": "shade"}, "is reserved by glphong's shading code"),
    ({"name": "spot"}, "the light name 'spot' is taken by the built-in glphong.lights.spot.SpotLight"),
    ({"name": "lambert"}, "is the name of the material model"),
    ({"params": [Param("n", "scalar", low=0.0)]}, "params must be a tuple of glphong.materials.Param"),
    ({"incident": None}, r"defines no numpy twin: add `def incident\(self, x, p\)`"),
    ({"incident": lambda self, x: None}, r"incident must take \(self, x, p\)"),
    ({"glsl": None}, "has no glsl"),
    ({"glsl": "bool probe_light_incident(vec3 x, out vec3 wi, out vec3 irradiance) { return true; }"},
     r"must define `bool probe_light_incident\(vec3 x, int j, out vec3 wi, out vec3 irradiance\)`"),
    ({"glsl": PhongLuminaire.glsl.replace("luminaire", "probe_light").replace("u_probe_light_n[j]", "u_probe_light_q[j]")},
     "reads u_probe_light_q, which no uniform declares"),
    ({"glsl": PhongLuminaire.glsl.replace("luminaire", "probe_light").replace("u_probe_light_n[j]", "2.0")},
     "never reads u_probe_light_n"),
    ({"glsl": "uniform float u_probe_light_n[1];\n" + PhongLuminaire.glsl.replace("luminaire", "probe_light")},
     "declares its own u_probe_light_\\* uniforms"),
    ({"glsl": "float helper(float x) { return x; }\n" + PhongLuminaire.glsl.replace("luminaire", "probe_light")},
     "defines helper without the prefix probe_light_"),
    ({"glsl": "bool safe_normalize(vec3 x) { return true; }\n" + PhongLuminaire.glsl.replace("luminaire", "probe_light")},
     "defines safe_normalize, which glphong's library chunks define"),
    ({"uses": ("shadows",)}, "uses must be a tuple of library chunks"),
    ({"uniforms": (Param("n", "scalar", low=0.0),)}, "must define uniform_value"),
    ({"numerics_bounds": {"falloff": "peak"}}, "numerics_bounds must map 'light' to the kind's position uniform"),
    ({"numerics_bounds": {"light": "n"}}, "numerics_bounds must map 'light' to the kind's position uniform"),
    ({"numerics_bounds": {"lobe": "position"}}, "numerics_bounds must map"),
])
def test_definition_errors(attributes, message):
    with pytest.raises(LightDefinitionError, match=message):
        _define(**attributes)


def test_a_light_needs_its_arguments():
    with pytest.raises(TypeError, match="PhongLuminaire\\(\\) missing parameter 'peak'"):
        PhongLuminaire((0, 0, 1), (0, 0, -1))
    with pytest.raises(AttributeError, match="immutable"):
        PhongLuminaire((0, 0, 1), (0, 0, -1), 1.0).n = 2.0
    assert PhongLuminaire((0, 0, 1), (0, 0, -2), 1.0).axis == (0.0, 0.0, -1.0)
