"""Conformance: every registered light kind passes the same checks, the way tests/test_conformance.py holds every
material model (pbrt-v4's ``bsdfs_test``: listed by being defined).

The tests are parametrised over the registry (`glphong.lights.registered_lights`; ids are the kinds' names), so a
kind added to ``glphong/lights`` gets every check below by being defined, with nothing written here for it.  What is
specific to a kind (closed forms, falloffs, its methods' errors) stays in its own test module.

- the definition (no GPU): registered under its name and exported from `glphong.lights` under its class name; its
  GLSL defines each function of its contract with the signature and reads exactly its uniforms, declared by
  glphong (``u_<name>_<uniform>`` arrays of ``NUM_<NAME>_LIGHTS``); its source hash is 12 hex digits and stable;
  `example` builds an immutable light, equal (and of equal hash) to another example and to itself rebuilt from
  `parameter_values` (an environment light names its map by a digest there: not rebuilt), with a repr naming the
  class; a NaN or infinite scalar parameter is a ValueError naming the parameter; the loop order puts the
  built-ins first;
- agreement (GPU, both backends): a punctual kind's GLSL against its twin through the real shader
  (`glphong.testing.assert_light_matches`), and every kind's render of a Lambert plane against the float64 twin
  (`glphong.verify`);
- stability (GPU, both backends): the kind's own `stability_cases` and, for a punctual kind, the generic geometry
  (`light_cases`) all pass against the mpmath oracle, with no NaN and no Inf.
"""
import re

import numpy as np
import pytest

import glphong
import glphong.lights
from glphong import primitives
from glphong.checks.stability import run_stability
from glphong.core.glsl_files import library_chunks
from glphong.materials import registered_models
from glphong.shaders.builders import program_key
from glphong.lights import light_cases, registered_lights
from glphong.testing import assert_light_matches

KINDS = [kind for kind in registered_lights() if kind.__module__.startswith("glphong.")]
BUILT_IN_ORDER = ["point", "unattenuated", "directional", "spot", "rect", "polygon", "sphere", "disk", "environment"]


def _ids(kind):
    return kind.name


def test_every_built_in_kind_is_held():
    """The harness sees the kinds by being defined, in the shader's loop order."""
    assert [k.name for k in KINDS][:len(BUILT_IN_ORDER)] == BUILT_IN_ORDER
    assert [k.name for k in registered_lights()][:len(BUILT_IN_ORDER)] == BUILT_IN_ORDER


@pytest.mark.parametrize("kind", KINDS, ids=_ids)
def test_definition(kind):
    assert glphong.lights.light_named(kind.name) is kind
    assert getattr(glphong.lights, kind.__name__) is kind and kind.__name__ in glphong.lights.__all__
    code = kind.source()
    for function in kind.contract():
        assert re.search(function.pattern(kind.name), code), function.glsl(kind.name)
    declared = kind.uniform_declarations()
    for p in kind.uniform_params():
        assert re.search(rf"uniform {p.glsl_type} {kind.uniform_name(p.name)}\[NUM_{kind.name.upper()}_LIGHTS", declared)
    assert re.fullmatch(r"[0-9a-f]{12}", kind.source_hash()) and kind.source_hash() == kind.source_hash()

    light = kind.example()
    assert type(light) is kind and light.kind == kind.name
    with pytest.raises(AttributeError, match="immutable"):
        setattr(light, kind.params[0].name, 1.0)
    again = kind.example()
    assert again == light and hash(again) == hash(light) and repr(light).startswith(f"{kind.__name__}(")
    values = light.parameter_values()
    if any(isinstance(v, str) and "sha256:" in v for v in values.values()):
        return  # an environment light names its map by a digest: its values are not its arguments
    assert kind(**values) == light
    scalars = [p for p in kind.params if p.kind == "scalar" and not p.optional]
    for p in scalars[:2]:
        for bad in (np.nan, np.inf):
            with pytest.raises(ValueError, match=p.name):
                kind(**(values | {p.name: bad}))


@pytest.mark.parametrize("kind", [k for k in KINDS if k.extent == "punctual"], ids=_ids)
def test_punctual_glsl_matches_its_twin(kind, glphong_backend):
    figures = assert_light_matches(kind.example(), backend=glphong_backend)
    assert figures["lit"] > 100 and figures["max_relative_error"] < 1e-4


@pytest.mark.parametrize("kind", KINDS, ids=_ids)
def test_render_verifies(kind, glphong_backend, glphong_make_renderer):
    """The kind's example lights a Lambert plane seen from above; every pixel agrees with the float64 twin."""
    light = kind.example()
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, -1.5, 2.5), (0.0, 0.0, 0.0)), [light])
    scene.add(primitives.plane(3.0), glphong.Lambert(0.5))
    renderer = glphong_make_renderer(16, 16, glphong_backend)
    report = glphong.verify(scene, renderer)
    assert report.passed, report
    assert report.covered_pixels > 200 and np.any(report.gpu > 0)


@pytest.mark.parametrize("kind", KINDS, ids=_ids)
def test_stability_cases(kind, glphong_backend):
    """The kind's own extreme cases (the point-like built-ins have theirs in the suite's groups) and, for a punctual
    kind, the generic geometry every kind gets by default (`light_cases`: normal, oblique and grazing incidence over
    the lecture's Phong; an extended kind's sampled terms carry a method error beyond the float32 band, so its own
    cases light the terms it integrates exactly)."""
    own = kind.stability_cases()
    generic = light_cases(kind.example()) if kind.extent == "punctual" else ()
    cases = own + tuple(c for c in generic if c.name not in {o.name for o in own})  # the default is the generic
    names = [c.name for c in cases]
    assert len(cases) >= 3 and len(set(names)) == len(names)
    assert all(any(type(light) is kind for light in c.lights) for c in cases)
    report = run_stability(glphong_backend, cases=cases)
    assert report.passed_count == len(cases) and report.nan_count == 0 and report.inf_count == 0, report.format_table()


def test_every_model_under_every_kind_includes_the_library_in_its_order():
    """A program's library chunks follow `glphong.core.glsl_files.LIBRARY` whichever term or kind asked first (a
    term that calls angle.glsl under a kind that calls area.glsl, which calls angle.glsl, failed to compile when the
    kind's chunks came first)."""
    order = library_chunks()
    checked = 0
    for model in registered_models():
        material = model.example()
        for kind in KINDS:
            key = program_key(material, [kind.example()], (0.1, 0.1, 0.1))
            included = [c for c in key.fragment_chunks() if c in order and c != "common"]
            assert included == sorted(included, key=order.index), (model.name, kind.name, included)
            assert set(included) == {c for t in key.terms for c in t.uses} | {c for k in key.lights for c in k.uses}
            checked += 1
    assert checked >= 14 * 9


def test_a_term_and_a_kind_sharing_a_library_chunk_render(glphong_backend, glphong_make_renderer):
    """Oren-Nayar calls angle.glsl; the rect light calls angle.glsl and area.glsl, which calls it.  The GPU against
    the twin (Oren-Nayar under a rect light has no closed form, so the method's exact map, 207 s at 16x16, is left
    out: ``exact=False``)."""
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, -1.5, 2.5), (0.0, 0.0, 0.0)),
                          [glphong.RectLight.example()])
    scene.add(primitives.plane(3.0), glphong.OrenNayar(0.5, 0.3))
    report = glphong.verify(scene, glphong_make_renderer(16, 16, glphong_backend), exact=False)
    assert report.passed and np.any(report.gpu > 0), report
