"""Mutation check: does the test suite catch small deliberate bugs?

Each entry of `MUTATIONS` is one small bug of the kind a real one would be (a 1 % factor, a
swapped sign, a dropped transpose, a wrong constant), written as data: an exact text
substitution in one file of the repository.  The script copies the working tree (every file
``git ls-files --cached --others --exclude-standard`` lists, uncommitted changes included) into
a temporary folder, checks that the unmutated copy passes, then for each mutation makes a fresh
copy, plants that one mutation, runs the test suite on the copy and records whether it was
caught.  It ends with a markdown table of the bugs caught and missed.  It is not part of the
test suite.

The suite runs in the copy as ``python -m pytest -x -q -p no:cacheprovider -rfE`` (cwd = the
copy) with ``PYTHONPATH=<copy>`` prepended, ``GLPHONG_GLSL_DIR=<copy>/glsl`` (glphong reads its
GLSL chunks from there), ``GLPHONG_REQUIRE_BACKENDS=egl,osmesa`` and
``PYTHONDONTWRITEBYTECODE=1``.  glphong is usually installed in editable mode pointing at the
main checkout, so before any run the script checks, in the copy with that environment, that
both ``glphong.__file__`` and ``glphong.core.glsl_files.glsl_root()`` lie inside the copy, and stops
if not.  The temporary copies are removed at the end.

Examples
--------
List the mutations and check that each one still applies (runs nothing)::

    python benchmarks/mutation.py --list

Run everything (baseline first, then every mutation), and keep the table::

    python benchmarks/mutation.py --markdown mutation.md

Only the mutations whose name contains one of the substrings (case-insensitive), e.g. every
GLSL chunk, or everything about the Phong lobe, or one wiring bug::

    python benchmarks/mutation.py --only .glsl:
    python benchmarks/mutation.py --only phong model.py:u_ks

Extra pytest arguments go to every run, the baseline included (e.g. a subset of the tests)::

    python benchmarks/mutation.py --only lambert --pytest-args "tests/test_analytic.py"

Notes
-----
**Time.**  The baseline costs one full suite run: 600 s measured on 2 cores with both backends
(another test run sharing the machine).  A caught mutation stops at its first failing test
(``-x``): 8 to 32 s where tests/lights or tests/materials catch it, 200 s at tests/test_conformance.py,
364 to 455 s where the first catching test is as far down as tests/test_parameters_closed_form.py or
tests/test_pyrender_integration.py.  A missed mutation costs a full suite run (497 s measured).
The 33 light mutations took about 65 minutes in all; the whole list has not been timed since the
suite grew, so select with ``--only``.  ``--timeout`` (default 900 s) bounds each run.

**Verdicts.**  pytest's exit code decides:

- 1 (tests failed or errored): *caught*; the first ``FAILED``/``ERROR`` node id is reported;
- 2 (interrupted): *caught* where a test failed first (pytest-xdist ends a ``-x`` run that way
  after the first ``FAILED``), else a collection error such as an import that no longer works:
  counted as caught, shown as ``caught (collection error)``;
- 0 (all passed): *MISSED*;
- anything else (3 internal error, 4 usage error, 5 no tests collected, a timeout, a signal):
  *error*: the run said nothing about the mutation; the tail of its output is printed.

The script exits with 0 when every selected mutation is caught, 1 when any is missed or
errored, 2 when it cannot run at all (a mutation that no longer applies, a baseline that
fails, an import path outside the copy, an ``--only`` that selects nothing).

**The list cannot rot silently.**  Every mutation's ``old`` text must occur exactly once in its
file; if code changes so that it occurs 0 or more than once, ``--list`` and every run stop
with an error naming the mutation.  Fix its ``old``/``new`` to the new code (or delete it if
the code it mutated is gone).

**Adding mutations.**  New models add their mutations: when a model, a light kind, a uniform
or a GLSL chunk lands, append `Mutation` entries to its area of `MUTATIONS` (or open a new
area) -- at least one for the GLSL, one for its numpy twin (the library functions' in
``glphong/twin/functions.py``, a model's ``response`` or a light kind's ``incident`` in its module) and
one for each new uniform's wiring on the host (a light kind's ``uniform_value``, and its ``from_gltf`` /
``from_pyrender`` where it has them).  A mutation is
``Mutation(name, path, old, new, what)``: ``name`` ``"<file>:<short-slug>"`` and unique;
``path`` relative to the repository root; ``old`` an exact snippet (whitespace included; add
surrounding lines to make it unique); ``new`` its mutated text; ``what`` one line saying what
the bug is.  Run ``--list`` to validate, then ``--only <name>`` to see it caught.  Mutate only
code the tests can run: the ``NAIVE`` variants of the chunks are compared only with themselves (those that
``numerics='auto'`` compiles, ``NAIVE_<PIECE>`` and plain_normalize, are mutated: they are production code)
and glphong/checks/stability.py is a test tool, so neither is mutated here.
"""
import argparse
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class Mutation:
    """One deliberate bug: replace ``old`` (which must occur exactly once) by ``new`` in ``path``.

    Attributes
    ----------
    name : str
        Unique, ``"<file>:<slug>"``; what ``--only`` matches.
    path : str
        File relative to the repository root.
    old, new : str
        The exact text and its mutated replacement.
    what : str
        One line: the bug.
    also : tuple of (path, old, new)
        Further edits planted together with the first, for a bug written in two places at once
        (the same wrong formula in a GLSL chunk and in its numpy twin); each ``old`` must occur
        exactly once in its file too.
    """

    name: str
    path: str
    old: str
    new: str
    what: str
    also: tuple = ()

    def edits(self):
        """Every ``(path, old, new)`` edit of this mutation, the first one first."""
        return ((self.path, self.old, self.new),) + tuple(self.also)


M = Mutation
MUTATIONS = [
    # ------------------------------------------------------------------ GLSL chunks (glsl/)
    M("common.glsl:length-1.01", "glsl/common.glsl",
      "len = valid ? s * sqrt(yy) : 0.0;", "len = valid ? 1.01 * s * sqrt(yy) : 0.0;",
      "safe_normalize: |x| 1% long (every point-light distance)"),
    M("lights.glsl:falloff-1.01", "glsl/lights.glsl",
      "return min((intensity / d) / d, vec3(FLT_MAX));", "return min((intensity / d) / (1.01 * d), vec3(FLT_MAX));",
      "point_irradiance: I / (1.01 d^2)"),
    M("lambert.glsl:kd-1.01", "glsl/materials/lambert.glsl",
      "return kd * n_dot_l;", "return 1.01 * kd * n_dot_l;",
      "lambert: 1.01 kd (n.l)"),
    M("lobe.glsl:series-1/3", "glsl/lobe.glsl",
      "float series = 1.0 + t * (1.0 / 3.0 +", "float series = 1.0 + t * (1.0 / 3.03 +",
      "log_one_minus: artanh series coefficient 1/3 -> 1/3.03"),
    M("lobe.glsl:q0-rule", "glsl/lobe.glsl",
      "return q == 0.0 ? 1.0 : (delta < 1.0", "return q < 0.0 ? 1.0 : (delta < 1.0",
      "lobe_from_delta: the q == 0 rule (0^0 := 1) dropped"),
    M("lobe.glsl:clamp-80", "glsl/lobe.glsl",
      "log_one_minus(delta < 1.0 ? delta : 0.0), -104.0));", "log_one_minus(delta < 1.0 ? delta : 0.0), -80.0));",
      "lobe_from_delta: exponent clamp -104 -> -80 (tails stop at 1.8e-35 instead of flushing)"),
    M("lobe.glsl:phong-reflect-1.9", "glsl/lobe.glsl",
      "vec3 r = 2.0 * dot(n, wi) * n - wi;", "vec3 r = 1.9 * dot(n, wi) * n - wi;",
      "phong_delta: r = 1.9 (n.l) n - l"),
    M("lobe.glsl:blinn-half-vector", "glsl/lobe.glsl",
      "bool defined = safe_normalize(wi + wo, h, h_len);\n    bool valid",
      "bool defined = safe_normalize(wi + 1.01 * wo, h, h_len);\n    bool valid",
      "blinn_delta: h from l + 1.01 v"),
    M("lobe.glsl:blinn-floor-x10", "glsl/lobe.glsl",
      "const float BLINN_HALF_FLOOR = 9.5367431640625e-07;", "const float BLINN_HALF_FLOOR = 9.5367431640625e-06;",
      "BLINN_HALF_FLOOR 2^-20 -> 10 x 2^-20"),
    # the light loops are generated (glphong/shaders/generated.py, lights_chunk): the gate is a Python string there
    M("generated.py:light-gate-0.01", "glphong/shaders/generated.py",
      '"        radiance += (lit && valid && n_dot_l > 0.0) ? term : vec3(0.0);"',
      '"        radiance += (lit && valid && n_dot_l > 0.01) ? term : vec3(0.0);"',
      "generated light loops: gate n.l > 0.01 instead of n.l > 0 (every kind)"),
    # the material chunk is generated too (glphong/shaders/generated.py, material_chunk)
    M("generated.py:ka-1.01", "glphong/shaders/generated.py",
      '_switch(key, "u_use_ka", "radiance += u_ka;")', '_switch(key, "u_use_ka", "radiance += 1.01 * u_ka;")',
      "generated material_emission: 1.01 k_a"),
    M("generated.py:ambient-1.01", "glphong/shaders/generated.py",
      'answer = f"u_{t.name}_{t.ambient_param} * {scaled}"',
      'answer = f"1.01 * u_{t.name}_{t.ambient_param} * {scaled}"',
      "generated material_emission: every term's answer to L_a 1.01 k L_a (k_d L_a for Lambert)"),
    M("generated.py:response-1.01", "glphong/shaders/generated.py",
      'f"response += {t.name}_response(f, wi, {view}, n_dot_l);"',
      'f"response += 1.01 * {t.name}_response(f, wi, {view}, n_dot_l);"',
      "generated material_response: every term 1% high (GPU only)"),
    # each light kind's <kind>_incident (glsl/lights/<kind>.glsl)
    M("point.glsl:E-1.01", "glsl/lights/point.glsl",
      "irradiance = point_irradiance(u_point_intensity[j], d);",
      "irradiance = point_irradiance(1.01 * u_point_intensity[j], d);",
      "point_incident: irradiance of 1.01 I"),
    M("unattenuated.glsl:E-1.01", "glsl/lights/unattenuated.glsl",
      "irradiance = u_unattenuated_radiance[j];", "irradiance = 1.01 * u_unattenuated_radiance[j];",
      "unattenuated_incident: 1.01 L_i"),
    M("directional.glsl:E-1.01", "glsl/lights/directional.glsl",
      "irradiance = u_directional_irradiance[j];", "irradiance = 1.01 * u_directional_irradiance[j];",
      "directional_incident: 1.01 E"),
    M("spot.glsl:falloff-unsquared", "glsl/lights/spot.glsl",
      "float g_d = g / d;", "float g_d = sqrt(g) / d;",
      "spot_incident: the angular falloff g not squared (E = g I / d^2)"),
    M("spot.glsl:chord-sign", "glsl/lights/spot.glsl",
      "vec3 chord = -wi - u_spot_axis[j];", "vec3 chord = wi - u_spot_axis[j];",
      "spot_incident: theta measured from wi, not -wi (the cone points back at the light)"),
    M("point.glsl:range-ignored", "glsl/lights/point.glsl",
      "irradiance = u_point_range[j] > 0.0 ? irradiance * range_window(d, u_point_range[j]) : irradiance;",
      "irradiance = u_point_range[j] > 0.0 ? irradiance : irradiance;",
      "point_incident: a point light's range window never applied"),
    M("lights.glsl:range-window-squared", "glsl/lights.glsl",
      "return clamp(((range - d) / range) * (1.0 + t) * (1.0 + t * t), 0.0, 1.0);",
      "float w = clamp(((range - d) / range) * (1.0 + t) * (1.0 + t * t), 0.0, 1.0);\n    return w * w;",
      "range_window: the window squared (three.js's and Filament's), GPU only"),
    M("shade.glsl:view-sign", "glsl/shade.glsl",
      "safe_normalize(eye.xyz - position * eye.w, wo, view_distance)",
      "safe_normalize(position * eye.w - eye.xyz, wo, view_distance)",
      "view vector v points away from the eye"),
    M("srgb.glsl:gamma-2.42", "glsl/srgb.glsl",
      "pow(x, vec3(1.0 / 2.4))", "pow(x, vec3(1.0 / 2.42))",
      "srgb_encode: exponent 1/2.42 instead of 1/2.4"),
    M("encode.glsl:exposure-1.01", "glsl/encode.glsl",
      "srgb_encode(u_exposure * sum", "srgb_encode(1.01 * u_exposure * sum",
      "8-bit pass: exposure 1% high"),
    M("mesh_vertex.glsl:normal-transpose", "glsl/mesh_vertex.glsl",
      "v_normal = u_normal_matrix * in_normal;", "v_normal = transpose(u_normal_matrix) * in_normal;",
      "per-pixel normal transform by N^T instead of N"),
    M("mesh_fragment.glsl:two-sided-flip", "glsl/mesh_fragment.glsl",
      "(SWITCH(u_two_sided) && !gl_FrontFacing) ? -n_raw", "(SWITCH(u_two_sided) && gl_FrontFacing) ? -n_raw",
      "two-sided: normal flipped on front faces instead of back faces"),
    M("mesh_fragment.glsl:blend-straight-alpha", "glsl/mesh_fragment.glsl",
      "out_radiance = blend_alpha * vec4(shade_point(v_position, shading_frame(n, tangent, uv), n_valid, u_eye), 1.0);",
      "out_radiance = vec4(shade_point(v_position, shading_frame(n, tangent, uv), n_valid, u_eye), blend_alpha);",
      "a blended layer's radiance not premultiplied by its alpha"),
    M("mesh_fragment.glsl:blend-texture-ignored", "glsl/mesh_fragment.glsl",
      "blend_alpha *= surface_texture(u_alpha_blend_texture, uv).r;", "blend_alpha *= 1.0;",
      "a blended layer's alpha texture not read (its constant scale alone)"),
    M("mesh_fragment.glsl:peel-keeps-previous", "glsl/mesh_fragment.glsl",
      "if (gl_FragCoord.z <= layer_depth) {", "if (gl_FragCoord.z < layer_depth) {",
      "the peel keeps the previous layer's fragment: a layer composited again and again"),
    M("peeling.py:blend-over-not-under", "glphong/gpu/peeling.py",
      "mgl.blend_func = moderngl.ONE_MINUS_DST_ALPHA, moderngl.ONE  #",
      "mgl.blend_func = moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA  #",
      "the layers accumulated back-to-front's way while peeled front to back"),
    M("peeling.py:no-opaque-depth", "glphong/gpu/peeling.py",
      "mgl.copy_framebuffer(depth_copy, opaque_depth)  # the opaque depth", "pass  # the opaque depth",
      "the peel's depth buffer not given the opaque depth: blended surfaces seen through opaque ones"),
    M("blend_twin.py:no-culling", "glphong/checks/blend_twin.py",
      "keep = ~is_blend[obj] | front | two_sided[obj]", "keep = ~is_blend[obj] | front | ~two_sided[obj]",
      "the twin culls the back faces of two-sided blended materials, not of one-sided ones"),
    M("blend_twin.py:alpha-1.01", "glphong/checks/blend_twin.py",
      "scale = float(np.float32(blend.alpha.scale if blend.textured else blend.alpha))",
      "scale = 1.01 * float(np.float32(blend.alpha.scale if blend.textured else blend.alpha))",
      "the twin's alpha 1 % high"),
    M("scene.py:uber-light-count", "glphong/shaders/binding.py",
      'values[f"u_{light_key.name}_count"] = np.float32(len(mine))',
      'values[f"u_{light_key.name}_count"] = np.float32(max(len(mine) - 1, 0))',
      "uber-shader: the last light of each kind dropped"),
    M("common.glsl:frame-fallback", "glsl/common.glsl",
      "t = projected ? t : fallback;", "t = fallback;",
      "frame_from_tangent: the mesh's tangent ignored (always the basis around n)"),
    # ------------------------------------------------------------------ the numpy twin (glphong/twin/functions.py,
    # glphong/checks/reference.py, each kind's ``incident``)
    M("functions.py:point-irradiance-1.01", "glphong/twin/functions.py",
      "else np.minimum((intensity / d) / d, FLT_MAX)", "else np.minimum((intensity / d) / (1.01 * d), FLT_MAX)",
      "twin point_irradiance: I / (1.01 d^2)"),
    M("lambert.py:twin-1.01", "glphong/materials/lambert.py",
      "return kd * np.asarray(n_dot_l)[..., None]", "return 1.01 * kd * np.asarray(n_dot_l)[..., None]",
      "twin lambert: 1.01 kd (n.l)"),
    M("functions.py:lobe-clamp", "glphong/twin/functions.py",
      "dtype.type(-104)", "dtype.type(-80)",
      "twin lobe_from_delta: exponent clamp -104 -> -80"),
    M("functions.py:series-1/3", "glphong/twin/functions.py",
      "dtype.type(1.0) / dtype.type(2 * k + 1)", "dtype.type(1.0) / dtype.type(2 * k + 1.01)",
      "twin log_one_minus: artanh series coefficients 1/(2k + 1.01)"),
    M("functions.py:twin-phong-reflect-1.9", "glphong/twin/functions.py",
      "r = 2 * _dot(n, wi)[..., None] * n - wi", "r = 1.9 * _dot(n, wi)[..., None] * n - wi",
      "twin phong_delta: r = 1.9 (n.l) n - l"),
    M("functions.py:twin-blinn-half-vector", "glphong/twin/functions.py",
      "ok_h, h, h_len = safe_normalize(wi + wo)\n    valid", "ok_h, h, h_len = safe_normalize(wi + 1.01 * wo)\n    valid",
      "twin blinn_delta: h from l + 1.01 v"),
    M("reference.py:gate-0.01", "glphong/checks/reference.py",
      "gate = np.flatnonzero(lit & valid & (n_dot_l > 0))",
      "gate = np.flatnonzero(lit & valid & (n_dot_l > 0.01))",
      "twin shade_point: gate n.l > 0.01"),
    M("functions.py:frame-handedness", "glphong/twin/functions.py",
      "b = (np.where(tangent[..., 3] < 0, -1.0, 1.0)[..., None] * np.cross(n, t)).astype(n.dtype, copy=False)",
      "b = np.cross(n, t).astype(n.dtype, copy=False)",
      "twin frame_from_tangent: the handedness w ignored"),
    M("functions.py:range-window-squared", "glphong/twin/functions.py",
      "return np.clip(((range_ - d) / range_) * (1 + t) * (1 + t * t), 0, 1)",
      "return np.clip(((range_ - d) / range_) * (1 + t) * (1 + t * t), 0, 1) ** 2",
      "twin range_window: the window squared"),
    M("spot.py:twin-falloff-unsquared", "glphong/lights/spot.py",
      "g_d = (g / d)[..., None]", "g_d = (np.sqrt(g) / d)[..., None]",
      "twin SpotLight.incident: the angular falloff g not squared"),
    # ------------------------------------------------------------------ material uniforms (glphong/definitions/material.py)
    # every parameter is uploaded by one generic line: a bug in one parameter's wiring is planted there,
    # conditioned on the parameter's name
    M("model.py:u_ka-1.01", "glphong/definitions/material_base.py",
      'values["u_ka"] = _validate.float32_uniform(self.ka)',
      'values["u_ka"] = _validate.float32_uniform(self.ka) * np.float32(1.01)',
      "u_ka uploaded 1% high"),
    *[M(f"model.py:u_{param}-1.01", "glphong/definitions/material_base.py",
        "_validate.float32_uniform(term.uniform_value(p.name))\n",
        f"_validate.float32_uniform(term.uniform_value(p.name)) * np.float32(1.01 if p.name == {param!r} else 1.0)\n",
        f"u_<model>_{param} uploaded 1% high") for param in ("kd", "ks", "q")],
    M("testing.py:band-1.01", "glphong/testing/assertions.py",
      "ok = (gpu >= low) & (gpu <= high) & ~np.isnan(gpu)",
      "ok = (gpu >= low) & (gpu <= 1.01 * high) & ~np.isnan(gpu)",
      "_judge (assert_twin_matches and assert_light_matches) accepts values 1% above the band"),
    M("testing.py:light-band-1.01", "glphong/testing/assertions.py",
      "_judge(gpu, twin, low, high, True, worst)", "_judge(gpu, twin, low, 1.01 * high, True, worst)",
      "assert_light_matches alone accepts values 1% above the band"),
    M("geometry.py:tangent-handedness", "glphong/scene/geometry.py",
      "w = np.where(np.sum(np.cross(n_hat, t) * b_sum, axis=1) < 0.0, -1.0, 1.0)",
      "w = np.where(np.sum(np.cross(n_hat, t) * b_sum, axis=1) < 0.0, 1.0, -1.0)",
      "tangents from UVs: handedness w flipped"),
    M("model.py:generic-band-x100", "glphong/definitions/material.py",
      "angle = constants.D * EPS", "angle = 100 * constants.D * EPS",
      "the generic band of user models 100 times too wide in the directions"),
    # ------------------------------------------------------------------ light uniforms (glphong/lights/<kind>.py)
    # each kind's uniforms come from its `uniform_value(name)` (default: the parameter of that name); a bug there
    # reaches the GPU and the twin alike (the twin reads the uniforms), so only closed forms catch it
    M("point.py:intensity-1.01", "glphong/lights/point.py",
      "return point_intensity(np.asarray(self.power))", "return point_intensity(np.asarray(self.power)) * 1.01",
      "PointLight.intensity 1% high (Phi / (4 pi) * 1.01)"),
    M("point.py:range-uniform-1.01", "glphong/lights/point.py",
      "return 0.0 if self.range is None else self.range", "return 0.0 if self.range is None else 1.01 * self.range",
      "WithRange.uniform_value: point and spot lights upload their range 1% long"),
    M("unattenuated.py:radiance-1.01", "glphong/lights/unattenuated.py",
      "    numerics_bounds = {\"light\": \"position\"}\n\n    def incident(self, x, p):",
      "    numerics_bounds = {\"light\": \"position\"}\n\n    def uniform_value(self, name):\n"
      "        value = getattr(self, name)\n"
      "        return tuple(1.01 * c for c in value) if name == \"radiance\" else value\n\n"
      "    def incident(self, x, p):",
      "UnattenuatedPointLight uploads 1.01 L_i"),
    M("directional.py:towards-sign", "glphong/lights/directional.py",
      'return tuple(-c for c in self.direction) if name == "towards" else getattr(self, name)',
      'return tuple(c for c in self.direction) if name == "towards" else getattr(self, name)',
      "DirectionalLight uploads its travel direction, not the direction toward the light"),
    M("directional.py:E-1.01", "glphong/lights/directional.py",
      'return tuple(-c for c in self.direction) if name == "towards" else getattr(self, name)',
      'return tuple(-c for c in self.direction) if name == "towards" else tuple(1.01 * c for c in getattr(self, name))',
      "DirectionalLight uploads 1.01 E"),
    M("spot.py:versin-outer-1.01", "glphong/lights/spot.py",
      "return 2.0 * np.sin(0.5 * self.outer_cone_angle) ** 2",
      "return 2.02 * np.sin(0.5 * self.outer_cone_angle) ** 2",
      "SpotLight uploads 1 - cos(outer) 1% high (the cone's edge moves out)"),
    M("spot.py:scale-floor-0.01", "glphong/lights/spot.py",
      "return 1.0 / max(0.001, gap)", "return 1.0 / max(0.01, gap)",
      "SpotLight: s = 1 / max(0.01, cos(inner) - cos(outer)) instead of the specification's 0.001"),
    M("spot.py:axis-sign", "glphong/lights/spot.py",
      'if name == "axis":\n            return self.direction',
      'if name == "axis":\n            return tuple(-c for c in self.direction)',
      "SpotLight uploads its axis reversed (the cone points away from where it should)"),
    M("ambient.py:ambient-1.01", "glphong/lights/ambient.py",
      '    radiance: tuple\n\n    def __post_init__(self):\n'
      '        object.__setattr__(self, "radiance", _validate.rgb("radiance", self.radiance))',
      '    radiance: tuple\n\n    def __post_init__(self):\n'
      '        object.__setattr__(self, "radiance", tuple(1.01 * c for c in _validate.rgb("radiance", self.radiance)))',
      "AmbientLight stores 1.01 L_a"),
    # ------------------------------------------------------------------ scene uniforms (glphong/scene/scene.py)
    M("scene.py:u_ambient-1.01", "glphong/shaders/binding.py",
      'values["u_ambient"] = np.asarray(scene.ambient_radiance, dtype=np.float32)',
      'values["u_ambient"] = np.asarray(scene.ambient_radiance, dtype=np.float32) * np.float32(1.01)',
      "u_ambient uploaded 1% high"),
    M("scene.py:u_eye-1.01", "glphong/shaders/binding.py",  # u_eye is the homogeneous eye (e, w): scale e only
      'values["u_eye"] = camera.eye', 'values["u_eye"] = camera.eye * np.array([1.01, 1.01, 1.01, 1.0])',
      "u_eye 1% off the camera centre"),
    M("scene.py:u_model-x-1.01", "glphong/shaders/binding.py",
      'values = {"u_model": obj.pose}',
      'values = {"u_model": obj.pose @ np.diag([1.01, 1.0, 1.0, 1.0])}',
      "u_model stretches objects 1% along their x"),
    M("scene.py:normal-matrix-transpose", "glphong/scene/scene.py",
      "return np.linalg.inv(self.pose[:3, :3]).T", "return np.linalg.inv(self.pose[:3, :3])",
      "normal matrix: inverse without the transpose"),
    # ------------------------------------------------------------------ camera (glphong/scene/camera.py)
    M("camera.py:projection-x-1.01", "glphong/scene/camera.py",
      "return self._frustum(f / aspect, f, 0.0, 0.0)", "return self._frustum(1.01 * f / aspect, f, 0.0, 0.0)",
      "projection: x scale 1% high"),
    M("camera.py:yfov-half", "glphong/scene/camera.py",
      "f = 1.0 / np.tan(self.yfov / 2.0)", "f = 1.0 / np.tan(self.yfov / 2.02)",
      "projection: tan(yfov / 2.02)"),
    M("camera.py:view-translation", "glphong/scene/camera.py",
      "view[:3, 3] = -r.T @ t", "view[:3, 3] = -r @ t",
      "view matrix: translation -R t instead of -R^T t"),
    M("camera.py:znear-1.01", "glphong/scene/camera.py",
      "2.0 * far * n / (n - far)]", "2.0 * far * (1.01 * n) / (n - far)]",
      "projection: the near plane 1% off znear"),
    # ------------------------------------------------------------------ one bug written in two places
    M("lobe.glsl+functions.py:phong-reflect-1.9", "glsl/lobe.glsl",
      "vec3 r = 2.0 * dot(n, wi) * n - wi;", "vec3 r = 1.9 * dot(n, wi) * n - wi;",
      "Phong's 2 (n.l) -> 1.9 (n.l) in the GLSL and the twin alike",
      also=(("glphong/twin/functions.py", "r = 2 * _dot(n, wi)[..., None] * n - wi",
             "r = 1.9 * _dot(n, wi)[..., None] * n - wi"),)),
    M("lambert.glsl+lambert.py:kd-1.01", "glsl/materials/lambert.glsl",
      "return kd * n_dot_l;", "return 1.01 * kd * n_dot_l;",
      "Lambert 1.01 kd (n.l) in the GLSL and the twin alike",
      also=(("glphong/materials/lambert.py", "return kd * np.asarray(n_dot_l)[..., None]",
             "return 1.01 * kd * np.asarray(n_dot_l)[..., None]"),)),
    M("spot.glsl+spot.py:falloff-unsquared", "glsl/lights/spot.glsl",
      "float g_d = g / d;", "float g_d = sqrt(g) / d;",
      "spot light's falloff g not squared in the GLSL and the twin alike (only the closed form can tell)",
      also=(("glphong/lights/spot.py", "g_d = (g / d)[..., None]", "g_d = (np.sqrt(g) / d)[..., None]"),)),
    M("lights.glsl+functions.py:range-window-squared", "glsl/lights.glsl",
      "return clamp(((range - d) / range) * (1.0 + t) * (1.0 + t * t), 0.0, 1.0);",
      "float w = clamp(((range - d) / range) * (1.0 + t) * (1.0 + t * t), 0.0, 1.0);\n    return w * w;",
      "the range window squared (three.js's and Filament's) in the GLSL and the twin alike",
      also=(("glphong/twin/functions.py", "return np.clip(((range_ - d) / range_) * (1 + t) * (1 + t * t), 0, 1)",
             "return np.clip(((range_ - d) / range_) * (1 + t) * (1 + t * t), 0, 1) ** 2"),)),
    # ------------------------------------------------------------------ tolerance band (glphong/twin/band.py)
    M("band.py:A-x100", "glphong/twin/band.py",
      "    A: float = 16.0", "    A: float = 1600.0", "band constant A x 100"),
    M("band.py:B-x100", "glphong/twin/band.py",
      "    B: float = 4.0", "    B: float = 400.0", "band constant B x 100"),
    M("band.py:C-x100", "glphong/twin/band.py",
      "    C: float = 6.0", "    C: float = 600.0", "band constant C x 100"),
    M("band.py:D-x100", "glphong/twin/band.py",
      "    D: float = 8.0", "    D: float = 800.0", "band constant D x 100"),
    # ------------------------------------------------------------------ sRGB on the CPU (glphong/core/imaging.py)
    M("imaging.py:gamma-2.42", "glphong/core/imaging.py",
      "1.055 * np.power(x, 1.0 / 2.4) - 0.055", "1.055 * np.power(x, 1.0 / 2.42) - 0.055",
      "srgb_encode (numpy): exponent 1/2.42"),
    # ------------------------------------------------------------------ pyrender and glTF lights: each kind's
    # from_pyrender / from_gltf (glphong/lights/<kind>.py); the ambient light in glphong/integrations/pyrender/scenes.py
    M("point.py:pyrender-4pi-1.01", "glphong/lights/point.py",
      "return cls(pose[:3, 3], power_from_intensity(value))",
      "return cls(pose[:3, 3], 1.01 * power_from_intensity(value))",
      "pyrender PointLight: Phi = 4.04 pi I"),
    M("directional.py:pyrender-sign", "glphong/lights/directional.py",
      "return cls(-pose[:3, 2], value)", "return cls(pose[:3, 2], value)",
      "pyrender DirectionalLight: travels along +Z of its node"),
    M("spot.py:pyrender-axis-sign", "glphong/lights/spot.py",
      "cls(pose[:3, 3], -pose[:3, 2], value, light.innerConeAngle, light.outerConeAngle)",
      "cls(pose[:3, 3], pose[:3, 2], value, light.innerConeAngle, light.outerConeAngle)",
      "pyrender SpotLight: points along +Z of its node"),
    M("spot.py:pyrender-cones-swapped", "glphong/lights/spot.py",
      "cls(pose[:3, 3], -pose[:3, 2], value, light.innerConeAngle, light.outerConeAngle)",
      "cls(pose[:3, 3], -pose[:3, 2], value, light.innerConeAngle, light.innerConeAngle)",
      "pyrender SpotLight: the outer cone angle read as the inner one"),
    M("spot.py:gltf-axis-sign", "glphong/lights/spot.py",
      "return cls(tuple(pose[:3, 3]), tuple(-pose[:3, 2]), tuple(value),",
      "return cls(tuple(pose[:3, 3]), tuple(pose[:3, 2]), tuple(value),",
      "glTF spot light: points along +Z of its node"),
    # glphong.save_gltf's conformance (issue 41; glphong/formats/gltf_export.py): for tests/test_gltf_conformance.py
    M("gltf_export.py:tangent-w-unsigned", "glphong/formats/gltf_export.py",
      "np.where(tangents[:, 3:] < 0, -1.0, 1.0)", "tangents[:, 3:]",
      "save_gltf: a tangent's w written as given, not as +-1"),
    M("gltf_export.py:zero-tangent-kept", "glphong/formats/gltf_export.py",
      "xyz = np.where(valid[:, None], xyz, fallback)", "xyz = np.where(valid[:, None], xyz, 0.0 * fallback)",
      "save_gltf: a zero tangent (a sphere's pole) written as zero"),
    M("gltf_export.py:volume-double-sided", "glphong/formats/gltf_export.py",
      'and "KHR_materials_volume" not in out.get("extensions", {})', 'and "KHR_materials_volume" in out',
      "save_gltf: a volume's material written doubleSided"),
    M("pyrender.py:ambient-1.01", "glphong/integrations/pyrender/scenes.py",
      "ambient = np.asarray(scene.ambient_light, dtype=np.float64)",
      "ambient = 1.01 * np.asarray(scene.ambient_light, dtype=np.float64)",
      "pyrender scene.ambient_light mapped to 1.01 L_a"),
    # ---- Fresnel factors and the albedo diffuse term (issue 12)
    M("fresnel.glsl:schlick-power-4", "glsl/fresnel.glsl",
      "return f0 + (vec3(1.0) - f0) * (m2 * m2 * m);", "return f0 + (vec3(1.0) - f0) * (m2 * m2);",
      "Schlick's (1 - c)^5 as (1 - c)^4 on the GPU"),
    M("fresnel.glsl:dielectric-0.51", "glsl/fresnel.glsl",
      "float f = 0.5 * (ratio * ratio) * (1.0 + q * q);", "float f = 0.51 * (ratio * ratio) * (1.0 + q * q);",
      "dielectric Fresnel 2% high on the GPU"),
    M("functions.py:schlick-power-4", "glphong/twin/functions.py",
      "return f0 + (1 - f0) * (m2 * m2 * m)[..., None]", "return f0 + (1 - f0) * (m2 * m2)[..., None]",
      "twin Schlick (1 - c)^4"),
    M("model.py:fresnel-forms-swapped", "glphong/definitions/material.py",
      'f"    return fresnel_schlick(u_{name}_fresnel_f0, c);",',
      'f"    return vec3(fresnel_dielectric(u_{name}_fresnel_ior, c));",',
      "generated <model>_fresnel: SchlickFresnel evaluates the dielectric form"),
    M("diffuse.glsl:inv-pi", "glsl/materials/diffuse.glsl",
      "const float DIFFUSE_INV_PI = 0.3183098861837907;", "const float DIFFUSE_INV_PI = 0.3215;",
      "Diffuse's 1/pi 1% high"),
    M("generated.py:ambient-scale-dropped", "glphong/shaders/generated.py",
      'scaled = "u_ambient" if t.ambient_scale == 1.0 else', 'scaled = "u_ambient" if True else',
      "the albedo models answer L_a with rho L_a instead of rho/pi L_a"),
    # ---- shader unit tests for any GLSL function and the PNG writer (issues 28, 29)
    M("glsl_builtins.py:pow-domain", "glphong/testing/glsl_builtins.py",
      'return _undefined("pow", (x < 0) | ((x == 0) & (y <= 0)), np.power(np.abs(x), y))',
      'return _undefined("pow", (x < 0), np.power(np.abs(x), y))',
      "glsl.pow forgets that pow(0, y <= 0) is undefined"),
    M("glsl_inputs.py:no-negative-zero", "glphong/testing/glsl_arguments.py",
      "FLOAT_EDGES = np.array([0.0, -0.0,", "FLOAT_EDGES = np.array([0.0, 0.0,",
      "the float edge cases lose -0.0"),
    M("glsl_types.py:int-from-bits", "glphong/testing/glsl_types.py",
      'return f"int({names[0]})" if self.rows == 1 else f"i{vec}({names[0]})"',
      'return f"int(uintBitsToFloat({names[0]}))" if self.rows == 1 else f"i{vec}({names[0]})"',
      "an int parameter read as the float of its bits"),
    M("png.py:filter-byte", "glphong/core/png.py", "rows[:, 0] = 1\n", "rows[:, 0] = 0\n",
      "PNG rows filtered Sub but labelled None"),
    # ---- stability where a scene needs it (issue 29)
    M("numerics.py:near-plane-ignored", "glphong/shaders/numerics.py",
      "    nearest = max(nearest, camera.znear * (1 - POSITION_RESOLUTION))",
      "    nearest = max(nearest, camera.znear * (1 - POSITION_RESOLUTION), 1.0)",
      "the view piece assumes every fragment at least 1 m from the eye"),
    M("numerics.py:normals-may-cancel", "glphong/shaders/numerics.py",
      "((a, a), (b, b), (c, c), (a, b), (b, c), (a, c))", "((a, a), (b, b), (c, c))",
      "the normal bound forgets the pairwise dots: opposite normals on a triangle get the textbook normalize"),
    M("numerics.py:falloff-unbounded", "glphong/shaders/numerics.py",
      "if peak > FALLOFF_LIMIT", "if peak > FALLOFF_LIMIT * 1e6",
      "the textbook falloff allowed where I / d^2 overflows"),
    M("numerics.py:tail-q", "glphong/shaders/numerics.py", "LOBE_TAIL_Q = 151.0", "LOBE_TAIL_Q = 100.0",
      "the lobes' log branch left out from q = 100, where the lobe is not 0 at cos = 1/2"),
    M("lights.glsl:naive-falloff-1.01", "glsl/lights.glsl", "    return intensity / (d * d);",
      "    return intensity / (1.01 * d * d);", "the textbook falloff numerics='auto' compiles: I / (1.01 d^2)"),
    M("common.glsl:plain-length", "glsl/common.glsl", "    len = length(x);\n    return true;",
      "    len = 1.001 * length(x);\n    return true;", "plain_normalize's length 0.1% long"),
    M("lobe.glsl:tail-half", "glsl/lobe.glsl", "    return q == 0.0 ? 1.0 : (delta < 0.5 ? lobe : 0.0);",
      "    return q == 0.0 ? 1.0 : (delta < 0.4 ? lobe : 0.0);",
      "LOBE_TAIL_ZERO cuts the lobe at cos = 0.6 instead of 1/2"),
    # glTF's KHR_materials_specular and _clearcoat (glsl/materials/gltf_pbr.glsl, glphong/materials/gltf_extensions.py):
    # the GLSL alone, and the same wrong formula in the GLSL and its twin at once (only the transcription catches those)
    M("gltf_pbr.glsl:coat-f0-0.05", "glsl/materials/gltf_pbr.glsl", "return 0.04 + 0.96 * y;",
      "return 0.05 + 0.95 * y;", "KHR_materials_clearcoat: the coat's f0 0.05 instead of 0.04"),
    M("gltf_pbr.glsl:specular-f90-1", "glsl/materials/gltf_pbr.glsl",
      "return dielectric_f0 + (specular - dielectric_f0) * x;", "return dielectric_f0 + (1.0 - dielectric_f0) * x;",
      "KHR_materials_specular: f90 = 1 whatever the specular strength"),
    M("gltf_pbr.glsl+gltf_extensions.py:coat-on-v.h", "glsl/materials/gltf_pbr.glsl",
      "float coat_weight = u_gltf_pbr_clearcoat * gltf_clearcoat_fresnel(n_dot_v);",
      "float coat_weight = u_gltf_pbr_clearcoat * gltf_clearcoat_fresnel(v_dot_h);",
      "KHR_materials_clearcoat: the coat's Fresnel on v.h (GLSL and twin)",
      also=(("glphong/materials/gltf_extensions.py",
             "fresnel_cos = n_dot_v.astype(dtype)",
             "fresnel_cos = microfacet_geometry(f.n, wi, wo, n_dot_l)[3].astype(dtype)"),)),
    M("gltf_pbr.glsl+gltf_extensions.py:diffuse-mean-F", "glsl/materials/gltf_pbr.glsl",
      "float fd_max = max(fd.r, max(fd.g, fd.b));", "float fd_max = (fd.r + fd.g + fd.b) / 3.0;",
      "KHR_materials_specular: the diffuse weighted by 1 - mean(F_d), not 1 - max(F_d) (GLSL and twin)",
      also=(("glphong/materials/gltf_pbr.py", "fd_max = np.max(fd, axis=-1)", "fd_max = np.mean(fd, axis=-1)"),)),
    M("gltf_pbr.glsl+gltf_extensions.py:coat-alpha", "glsl/materials/gltf_pbr.glsl",
      "float alpha_c = u_gltf_pbr_clearcoat_roughness * u_gltf_pbr_clearcoat_roughness;",
      "float alpha_c = u_gltf_pbr_clearcoat_roughness;",
      "KHR_materials_clearcoat: alpha_c = clearcoat_roughness, not its square (GLSL and twin)",
      also=(("glphong/materials/gltf_extensions.py", "alpha_c = np.asarray(p.clearcoat_roughness).astype(dtype) ** 2",
             "alpha_c = np.asarray(p.clearcoat_roughness).astype(dtype)"),)),
    M("gltf_material_extensions.py:specular-alpha", "glphong/formats/gltf_material_extensions.py",
      'texture(specular["specularTexture"], False, True)', 'texture(specular["specularTexture"], False)',
      "KHR_materials_specular: specularTexture's red channel read instead of its alpha"),
    # KHR_materials_sheen (glsl/materials/gltf_pbr.glsl, glphong/materials/gltf_sheen.py): caught by
    # tests/materials/test_gltf_sheen.py (the GLSL alone by the twin's band, both at once by the transcription)
    M("gltf_pbr.glsl:sheen-visibility-no-1", "glsl/materials/gltf_pbr.glsl",
      "float sheen_v_cos = 1.0 / ((1.0 + gltf_sheen_lambda(n_dot_v, alpha_g)",
      "float sheen_v_cos = 1.0 / ((gltf_sheen_lambda(n_dot_v, alpha_g)",
      "KHR_materials_sheen: the visibility's 1 + dropped"),
    M("gltf_pbr.glsl+gltf_sheen.py:sheen-alpha", "glsl/materials/gltf_pbr.glsl",
      "float alpha_g = u_gltf_pbr_sheen_roughness * u_gltf_pbr_sheen_roughness;",
      "float alpha_g = u_gltf_pbr_sheen_roughness;",
      "KHR_materials_sheen: alpha_g = sheen_roughness, not its square (GLSL and twin)",
      also=(("glphong/materials/gltf_sheen.py", "alpha_g = (r * r).astype(dtype)", "alpha_g = r.astype(dtype)"),)),
    M("gltf_pbr.glsl+gltf_sheen.py:sheen-scaling-unclamped", "glsl/materials/gltf_pbr.glsl",
      "1.0 - sc_max * gltf_sheen_albedo(n_dot_l, u_gltf_pbr_sheen_roughness)), 0.0);",
      "1.0 - sc_max * gltf_sheen_albedo(n_dot_l, u_gltf_pbr_sheen_roughness)), -1e30);",
      "KHR_materials_sheen: the albedo scaling not clamped at 0 (GLSL and twin)",
      also=(("glphong/materials/gltf_sheen.py", "one - sc_max * gltf_sheen_albedo(n_dot_l, r)), dtype.type(0))",
             "one - sc_max * gltf_sheen_albedo(n_dot_l, r)), dtype.type(-1e30))"),)),
    M("gltf_pbr.glsl+gltf_sheen.py:sheen-scaling-view-only", "glsl/materials/gltf_pbr.glsl",
      "1.0 - sc_max * gltf_sheen_albedo(n_dot_l, u_gltf_pbr_sheen_roughness)), 0.0);",
      "1.0 - sc_max * gltf_sheen_albedo(n_dot_v, u_gltf_pbr_sheen_roughness)), 0.0);",
      "KHR_materials_sheen: the albedo scaling on E(n.v) alone (GLSL and twin)",
      also=(("glphong/materials/gltf_sheen.py", "one - sc_max * gltf_sheen_albedo(n_dot_l, r)), dtype.type(0))",
             "one - sc_max * gltf_sheen_albedo(n_dot_v, r)), dtype.type(0))"),)),
    M("gltf_sheen_table.py:entry", "glphong/materials/gltf_sheen_table.py", "0.3668602705001831", "0.367",
      "KHR_materials_sheen: one entry of the twin's E table differs from the GLSL's"),
    M("gltf_material_extensions.py:sheen-roughness-alpha", "glphong/formats/gltf_material_extensions.py",
      'texture(sheen["sheenRoughnessTexture"], False, True)', 'texture(sheen["sheenRoughnessTexture"], False)',
      "KHR_materials_sheen: sheenRoughnessTexture's red channel read instead of its alpha"),
    # KHR_materials_iridescence (glsl/materials/gltf_iridescence.glsl, glphong/materials/gltf_iridescence.py): for
    # tests/materials/test_gltf_iridescence.py
    M("gltf_iridescence.glsl:opd-cos1", "glsl/materials/gltf_iridescence.glsl",
      "float opd = 2.0 * film_ior * thickness * cos_theta2;", "float opd = 2.0 * film_ior * thickness * cos_theta1;",
      "KHR_materials_iridescence: the optical path on the outside angle (the README draft's)"),
    M("gltf_iridescence.glsl+gltf_iridescence.py:matrix-rows", "glsl/materials/gltf_iridescence.glsl",
      "return GLTF_IRIDESCENCE_XYZ_TO_REC709 * xyz;", "return xyz * GLTF_IRIDESCENCE_XYZ_TO_REC709;",
      "KHR_materials_iridescence: XYZ_TO_REC709 applied by rows (GLSL and twin)",
      also=(("glphong/materials/gltf_iridescence.py", "return (xyz @ XYZ_TO_REC709.T.astype(dtype)).astype(dtype)",
             "return (xyz @ XYZ_TO_REC709.astype(dtype)).astype(dtype)"),)),
    M("gltf_iridescence.glsl+gltf_iridescence.py:diffuse-mean-F", "glsl/materials/gltf_iridescence.glsl",
      "fd_max = max(fd_i.r, max(fd_i.g, fd_i.b));", "fd_max = (fd_i.r + fd_i.g + fd_i.b) / 3.0;",
      "KHR_materials_iridescence: the diffuse weighted by 1 - mean(F), not 1 - max3(F) (GLSL and twin)",
      also=(("glphong/materials/gltf_iridescence.py", "return np.max(fd_i, axis=-1).astype(dtype)",
             "return np.mean(fd_i, axis=-1).astype(dtype)"),)),
    M("gltf_material_extensions.py:iridescence-thickness-channel", "glphong/formats/gltf_material_extensions.py",
      'Texture(image, 1.0, channel="g") if image is not None else 1.0',
      'Texture(image, 1.0, channel="r") if image is not None else 1.0',
      "KHR_materials_iridescence: iridescenceThicknessTexture's red channel read instead of its green"),
    # KHR_materials_anisotropy (glsl/materials/gltf_pbr.glsl, glphong/materials/gltf_anisotropy.py): for
    # tests/materials/test_gltf_anisotropy.py (the GLSL alone by the twin's band, GLSL and twin at once by the
    # transcription of the specification)
    M("gltf_pbr.glsl:anisotropy-d-at-squared", "glsl/materials/gltf_pbr.glsl",
      "return GLTF_PBR_INV_PI / ((at * ab) * (s * s));", "return GLTF_PBR_INV_PI / ((at * at) * (s * s));",
      "KHR_materials_anisotropy: D's normalisation at^2 instead of at ab"),
    M("gltf_pbr.glsl+gltf_anisotropy.py:anisotropy-strength-unsquared", "glsl/materials/gltf_pbr.glsl",
      "float at = alpha * (1.0 - strength * strength) + strength * strength;",
      "float at = alpha * (1.0 - strength) + strength;",
      "KHR_materials_anisotropy: alpha_t = mix(alpha, 1, strength), not strength^2 (GLSL and twin)",
      also=(("glphong/materials/gltf_anisotropy.py",
             "at = (alpha * (dtype.type(1) - strength * strength) + strength * strength).astype(dtype)",
             "at = (alpha * (dtype.type(1) - strength) + strength).astype(dtype)"),)),
    M("gltf_pbr.glsl+gltf_anisotropy.py:anisotropy-rotation-sign", "glsl/materials/gltf_pbr.glsl",
      "float rx = c * dx - s * dy;\n    float ry = s * dx + c * dy;",
      "float rx = c * dx + s * dy;\n    float ry = -s * dx + c * dy;",
      "KHR_materials_anisotropy: the direction rotated the wrong way (GLSL and twin)",
      also=(("glphong/materials/gltf_anisotropy.py", "rx, ry = (c * dx - s * dy).astype(dtype), (s * dx + c * dy).astype(dtype)",
             "rx, ry = (c * dx + s * dy).astype(dtype), (-s * dx + c * dy).astype(dtype)"),)),
    # KHR_materials_diffuse_transmission (glsl/materials/gltf_pbr.glsl, glphong/materials/
    # gltf_diffuse_transmission.py): for tests/materials/test_gltf_diffuse_transmission.py
    M("gltf_pbr.glsl:diffuse-transmission-front-weight", "glsl/materials/gltf_pbr.glsl",
      "    diffuse *= 1.0 - u_gltf_pbr_diffuse_transmission;",
      "    diffuse *= 1.0 - 0.5 * u_gltf_pbr_diffuse_transmission;",
      "KHR_materials_diffuse_transmission: a light in front sees the diffuse times 1 - dt/2"),
    M("gltf_pbr.glsl+gltf_diffuse_transmission.py:diffuse-transmission-no-1-t", "glsl/materials/gltf_pbr.glsl",
      "float scale = (1.0 - u_gltf_pbr_metallic) * (1.0 - t) * u_gltf_pbr_diffuse_transmission;",
      "float scale = (1.0 - u_gltf_pbr_metallic) * u_gltf_pbr_diffuse_transmission;",
      "KHR_materials_diffuse_transmission: a light behind not weighted by 1 - transmission (GLSL and twin)",
      also=(("glphong/materials/gltf_diffuse_transmission.py",
             "scale = (1.0 - np.asarray(m, np.float64)) * (1.0 - np.asarray(t, np.float64)) * np.asarray(dt, np.float64)",
             "scale = (1.0 - np.asarray(m, np.float64)) * np.asarray(dt, np.float64)"),)),
    # transmission with blended surfaces (glphong/gpu/renderer.py, glphong/checks/transmission_blend.py): for
    # tests/test_transmission_blend.py
    M("renderer.py:transmission-background-without-layers", "glphong/gpu/renderer.py",
      "self._fullscreen, peel if blending else None)", "self._fullscreen, None)",
      "transmission with blended surfaces: the background the opaque image alone, without the blended layers"),
    M("transmission_blend.py:background-cut-left-out", "glphong/checks/transmission_blend.py",
      "cut=over.cut | (behind.cut if read else False),", "cut=over.cut,",
      "transmission with blended surfaces: the twin's cut without the background peel's"),
    M("renderer.py:transmission-background-peel-from-front", "glphong/gpu/renderer.py",
      "None if into is None else (lambda depth: layers(TRANSMIT_DEPTH, depth)))", "None)",
      "transmission with blended surfaces: the background's peel starts at the front again (not behind the glass): "
      "a layer in front of the glass transmitted through it a second time"),
    M("transmission_blend.py:background-twin-from-front", "glphong/checks/transmission_blend.py",
      "lambda gbuffer: shade(scene, in_scene(scene, gbuffer)), band, start)",
      "lambda gbuffer: shade(scene, in_scene(scene, gbuffer)), band, None)",
      "transmission with blended surfaces: the background's twin holds the layers in front of the glass too"),
    M("peeling.py:framebuffer-key-glo-alone", "glphong/gpu/peeling.py",
      "key = tuple(None if a is None else (type(a).__name__, a.glo) for a in (color, depth)) + (write,)",
      "key = tuple(None if a is None else a.glo for a in (color, depth)) + (write,)",
      "depth peeling: the framebuffer cache keyed by glo alone (a texture and a renderbuffer of one glo share one)"),
    # KHR_materials_dispersion (glsl/transmission_thin.glsl, glphong/checks/transmission_twin.py): for
    # tests/test_transmission.py
    M("transmission_thin.glsl:dispersion-spread", "glsl/transmission_thin.glsl",
      "float half_spread = (ior - 1.0) * 0.025 * gltf_pbr_dispersion();",
      "float half_spread = (ior - 1.0) * 0.05 * gltf_pbr_dispersion();",
      "KHR_materials_dispersion: the channels' ior spread twice the specification's"),
    # KHR_materials_volume, lights behind (glsl/transmission_thin.glsl, glphong/shaders/generated.py): for
    # tests/test_transmission_volume_lights.py
    M("transmission_thin.glsl:volume-light-attenuation-half-path", "glsl/transmission_thin.glsl",
      "return gltf_volume_attenuation(length(gltf_volume_exit(f, wo)), gltf_pbr_attenuation());",
      "return gltf_volume_attenuation(0.5 * length(gltf_volume_exit(f, wo)), gltf_pbr_attenuation());",
      "KHR_materials_volume: a light behind a volume attenuated over half the transmission ray"),
    M("transmission_thin.glsl:volume-light-diffuse-unattenuated", "glsl/transmission_thin.glsl",
      "return gltf_volume_attenuation(gltf_pbr_thickness() * scale, gltf_pbr_attenuation());",
      "return vec3(1.0);",
      "KHR_materials_volume with _diffuse_transmission: the diffusely transmitted light not attenuated"),
    M("generated.py:volume-light-not-moved", "glphong/shaders/generated.py",
      "{incident(f'position + {through}_exit', wi, e)}", "{incident('position', wi, e)}",
      "KHR_materials_volume: a light behind a volume seen from the surface, not from the exit point"),
    M("frame_twin.py:one-sided-glass-back-faces-kept", "glphong/checks/frame_twin.py",
      "    return cull[owner] & ((det > 0.0) == mirrored[owner])", "    return cull[owner] & False",
      "one-sided glass: the twins keep its back faces, which the GPU culls"),
    M("drawing.py:one-sided-glass-in-the-gbuffer", "glphong/gpu/drawing.py",
      'if blend or (output == "gbuffer" and one_sided_transmissive(scene.objects[entry.index].material)):',
      "if blend:",
      "one-sided glass: its back faces drawn in the G-buffer, which the transmission pass culls"),
    M("generated.py:volume-light-unshadowed", "glphong/shaders/generated.py",
      'lines += [f"{pad}{e} *= visibility;"] if shadowed else []', "",
      "KHR_materials_volume: a shadowed light behind a volume, seen from the exit point, without the visibility at "
      "the surface"),
    # KHR_materials_transmission, _volume, _dispersion (glsl/transmission_thin.glsl, glphong/materials/
    # gltf_transmission.py): for tests/test_transmission.py (planted in GLSL and twin at once: the closed forms)
    M("gltf_pbr.glsl+gltf_pbr.py:transmission-diffuse", "glsl/materials/gltf_pbr.glsl",
      "    diffuse *= 1.0 - u_gltf_pbr_transmission;", "    diffuse *= 1.0 - 0.5 * u_gltf_pbr_transmission;",
      "KHR_materials_transmission: the diffuse weighted by 1 - t/2 (GLSL and twin)",
      also=(("glphong/materials/gltf_pbr.py",
             "diffuse = diffuse * (dtype.type(1) - np.asarray(p.transmission).astype(dtype))[..., None]",
             "diffuse = diffuse * (dtype.type(1) - dtype.type(0.5) * np.asarray(p.transmission).astype(dtype))[..., None]"),)),
    M("transmission_thin.glsl+gltf_transmission.py:metallic", "glsl/transmission_thin.glsl",
      "return c * ((1.0 - m) * t * (1.0 - max(", "return c * (t * (1.0 - max(",
      "KHR_materials_transmission: the background's weight without 1 - metallic (GLSL and twin)",
      also=(("glphong/materials/gltf_transmission.py",
             "scale = ((one - np.asarray(m).astype(dtype)) * np.asarray(t).astype(dtype) * (one - fresnel))",
             "scale = (np.asarray(t).astype(dtype) * (one - fresnel))"),)),
    M("gltf_pbr.glsl+gltf_transmission.py:f0", "glsl/materials/gltf_pbr.glsl",
      "    float r = (ior - 1.0) / (ior + 1.0);\n#if defined(GLTF_PBR_SPECULAR)",
      "    float r = (ior - 1.0) / ior;\n#if defined(GLTF_PBR_SPECULAR)",
      "KHR_materials_transmission: f0 from (ior - 1)/ior (GLSL and twin)",
      also=(("glphong/materials/gltf_transmission.py", "r = ((ior - one) / (ior + one)).astype(dtype)",
             "r = ((ior - one) / ior).astype(dtype)"),)),
    M("transmission_thin.glsl+gltf_transmission.py:beer-lambert", "glsl/transmission_thin.glsl",
      "pow(attenuation.rgb, vec3(d / attenuation.w))", "pow(attenuation.rgb, vec3(d * attenuation.w))",
      "KHR_materials_volume: Beer-Lambert's exponent d times the distance (GLSL and twin)",
      also=(("glphong/materials/gltf_transmission.py", "** (d / float(distance))[..., None]",
             "** (d * float(distance))[..., None]"),)),
    M("gltf_transmission.py:thickness-channel", "glphong/formats/gltf_transmission.py",
      'texture, "g")', 'texture, "r")', "KHR_materials_volume: thicknessTexture's red channel read instead of its green"),
    # KHR_materials_specular, _sheen, _clearcoat over KHR_materials_transmission (glsl/transmission_thin.glsl,
    # glphong/materials/gltf_transmission.py): for tests/test_transmission_layers.py (GLSL and twin at once: the
    # closed forms)
    M("gltf_pbr.glsl+gltf_transmission.py:specular-ignored", "glsl/materials/gltf_pbr.glsl",
      "vec3 fresnel = u_gltf_pbr_specular * fresnel_schlick(min(r * r * u_gltf_pbr_specular_color, vec3(1.0)), c);",
      "vec3 fresnel = fresnel_schlick(vec3(r * r), c);",
      "KHR_materials_specular: the transmitted light weighted by the core's 1 - F, not 1 - max3(F_d) (GLSL and twin)",
      also=(("glphong/materials/gltf_transmission.py", "    if specular_color is None:\n        fresnel =",
             "    if True:\n        fresnel ="),)),
    M("gltf_pbr.glsl+gltf_transmission.py:sheen-scaling", "glsl/materials/gltf_pbr.glsl",
      "    keep = gltf_sheen_scaling(n_dot_v, n_dot_l);", "    keep = 1.0 + 0.0 * gltf_sheen_scaling(n_dot_v, n_dot_l);",
      "KHR_materials_sheen: the light let through not scaled by 1 - max3(sheen_color) E (GLSL and twin)",
      also=(("glphong/materials/gltf_transmission.py", "keep = gltf_sheen_scaling(n_dot_v,",
             "keep = 1.0 + 0.0 * gltf_sheen_scaling(n_dot_v,"),)),
    M("gltf_pbr.glsl+gltf_transmission.py:sheen-scaling-view-only", "glsl/materials/gltf_pbr.glsl",
      "    keep = gltf_sheen_scaling(n_dot_v, n_dot_l);", "    keep = gltf_sheen_scaling(n_dot_v, n_dot_v);",
      "KHR_materials_sheen: the light let through behind scaled on E(n.v) alone, not E(|n.l|) too (GLSL and twin)",
      also=(("glphong/materials/gltf_transmission.py",
             "keep = gltf_sheen_scaling(n_dot_v, np.asarray(n_dot_l, np.float64),",
             "keep = gltf_sheen_scaling(n_dot_v, n_dot_v,"),)),
    M("gltf_pbr.glsl+gltf_transmission.py:coat-on-v.h", "glsl/materials/gltf_pbr.glsl",
      "keep *= 1.0 - u_gltf_pbr_clearcoat * gltf_clearcoat_fresnel(n_dot_v);",
      "keep *= 1.0 - u_gltf_pbr_clearcoat * gltf_clearcoat_fresnel(n_dot_l);",
      "KHR_materials_clearcoat: the coat over the light let through weighted on the light's cosine, not n.v (GLSL "
      "and twin)",
      also=(("glphong/materials/gltf_transmission.py",
             "cosine = n_dot_v if coat_n_dot_v is None else np.asarray(coat_n_dot_v, np.float64)",
             "cosine = np.asarray(n_dot_l, np.float64) if coat_n_dot_v is None else np.asarray(coat_n_dot_v, "
             "np.float64)"),)),
    # the coat's own normal over KHR_materials_transmission (tests/test_transmission_layers.py: the closed form, and
    # verify over a normal map)
    M("gltf_pbr.glsl+gltf_transmission.py:coat-normal-ignored", "glsl/materials/gltf_pbr.glsl",
      "gltf_clearcoat_fresnel(max(dot(gltf_clearcoat_normal(f), wo), 0.0))",
      "gltf_clearcoat_fresnel(max(dot(f.n, wo), 0.0))",
      "KHR_materials_clearcoat: the coat over the light let through weighted by F_c(n.v), not its own normal's "
      "F_c(n_c.v) (GLSL and twin)",
      also=(("glphong/materials/gltf_transmission.py",
             "cosine = n_dot_v if coat_n_dot_v is None else np.asarray(coat_n_dot_v, np.float64)",
             "cosine = n_dot_v"),)),
    # KHR_materials_iridescence over KHR_materials_transmission (tests/test_transmission_layers.py: the closed forms)
    M("gltf_pbr.glsl+gltf_transmission.py:film-weight", "glsl/materials/gltf_pbr.glsl",
      "fresnel = mix(fresnel, film, u_gltf_pbr_iridescence);", "fresnel = mix(fresnel, film, 1.0);",
      "KHR_materials_iridescence: the transmitted light's F' the film's alone, its weight ignored (GLSL and twin)",
      also=(("glphong/materials/gltf_transmission.py", 'w = np.asarray(film["iridescence"]).astype(dtype)[..., None]',
             "w = np.ones(1, dtype)"),)),
    M("gltf_pbr.glsl+gltf_transmission.py:film-f0", "glsl/materials/gltf_pbr.glsl",
      "vec3 film_f0 = min(r * r * u_gltf_pbr_specular_color, vec3(1.0)) * u_gltf_pbr_specular;",
      "vec3 film_f0 = vec3(r * r);",
      "KHR_materials_iridescence over transmission: the film's base f0 the core's, not the specular's (GLSL and twin)",
      also=(("glphong/materials/gltf_transmission.py", "    if specular_color is None:\n        film_f0",
             "    if True:\n        film_f0"),)),
    M("gltf_pbr.glsl+gltf_transmission.py:film-cosine", "glsl/materials/gltf_pbr.glsl",
      "film_f0, thickness, clamp(c, 0.0, 1.0));", "film_f0, thickness, clamp(1.0 - c, 0.0, 1.0));",
      "KHR_materials_iridescence over transmission: the film on 1 - cos (GLSL and twin)",
      also=(("glphong/materials/gltf_transmission.py", "np.clip(c, 0, 1).astype(dtype))",
             "np.clip(1 - c, 0, 1).astype(dtype))"),)),
    M("transmission_lights.py:coat-normal-texel", "glphong/checks/transmission_lights.py",
      "SimpleNamespace(clearcoat_normal=texel,",
      "SimpleNamespace(clearcoat_normal=np.broadcast_to((0.5, 0.5, 1.0), texel.shape),",
      "KHR_materials_clearcoat over transmission: the twin's coat normal the unperturbed one, not the material's texel"),
    # area and environment lights behind a transmissive surface (glphong/shaders/generated.py _extended_loop, its twin
    # glphong/checks/transmission_extended.py): for tests/test_transmission_extended.py
    M("generated.py:extended-behind-gate", "glphong/shaders/generated.py",
      'f"{pad}{total} += ({gate}{valid} && {n_dot_l} < 0.0) ? {through} : vec3(0.0);"',
      'f"{pad}{total} += ({gate}{valid} && {n_dot_l} > 0.0) ? {through} : vec3(0.0);"',
      "lights behind a transmissive surface: the gate flipped to n.wi > 0, in the punctual loops and the extended "
      "kinds' samples (GPU only)"),
    M("transmission_extended.py:last-sample-dropped", "glphong/checks/transmission_extended.py",
      "            for k in range(count):", "            for k in range(count - 1):",
      "extended lights behind a transmissive surface: the twin leaves out each light's last weighted direction"),
    # transmissive surfaces under shadowing lights (glphong/checks/transmission_twin.py): for
    # tests/test_transmission_shadows.py
    M("transmission_twin.py:background-opaque-casters", "glphong/checks/transmission_twin.py",
      "shaded = shade(scene, in_scene(scene, opaque_gbuffer))", "shaded = shade(opaque, opaque_gbuffer)",
      "shadows through glass: the background twinned in the scene without its transmissive objects (their shadows "
      "and the maps' frusta left out), not in the GPU's whole-scene maps"),
    M("transmission_twin.py:behind-unshadowed", "glphong/checks/transmission_twin.py",
      "for i, v in enumerate(visibility or ()):", "for i, v in enumerate(()):",
      "shadows through glass: the lights behind the surface without their visibility at it"),
    M("transmission_blend.py:background-layers-opaque-casters", "glphong/checks/transmission_blend.py",
      "lambda gbuffer: shade(scene, in_scene(scene, gbuffer)), band, start)",
      "lambda gbuffer: shade(opaque, gbuffer), band, start)",
      "shadows through glass with blended surfaces: the background's layers twinned in the scene without its "
      "transmissive objects (the glass's shadow on a layer behind it left out), not in the GPU's whole-scene maps"),
]
del M

#: pytest's command line in the copy (``-rfE``: the short summary names failures and errors)
PYTEST = ["-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", "-rfE"]
#: result -> counts as caught
CAUGHT = {"caught": True, "caught (collection error)": True, "MISSED": False}


# ---------------------------------------------------------------------------- the list
def problems(mutations, root):
    """What is wrong with ``mutations`` against the files under ``root`` (empty list: all apply)."""
    out = []
    seen = set()
    for m in mutations:
        if m.name in seen:
            out.append(f"{m.name}: the name is used twice")
        seen.add(m.name)
        for path, old, new in m.edits():
            if old == new:
                out.append(f"{m.name}: old and new are the same text in {path}")
            file = root / path
            if not file.is_file():
                out.append(f"{m.name}: no file {path}")
                continue
            count = file.read_text(encoding="utf-8").count(old)
            if count != 1:
                out.append(f"{m.name}: its old text occurs {count} times in {path} (must be exactly once): {old!r}")
    return out


def validate(mutations, root):
    """Stop (exit 2) naming every mutation that no longer applies to the files under ``root``."""
    found = problems(mutations, root)
    if found:
        fail("mutations that no longer apply (fix their old/new text in benchmarks/mutation.py):\n  "
             + "\n  ".join(found))


def apply(mutation, root):
    """Plant ``mutation`` (all its edits) in the copy at ``root`` (each old text is known to occur once)."""
    for path, old, new in mutation.edits():
        file = root / path
        with open(file, encoding="utf-8", newline="") as f:
            text = f.read()
        if text.count(old) != 1:
            fail(f"{mutation.name}: old text does not occur exactly once in {path} of the copy")
        with open(file, "w", encoding="utf-8", newline="") as f:
            f.write(text.replace(old, new, 1))


def select(mutations, only):
    """The mutations whose name contains one of ``only`` (case-insensitive); all when ``only`` is empty."""
    if not only:
        return list(mutations)
    keys = [s.lower() for s in only]
    return [m for m in mutations if any(k in m.name.lower() for k in keys)]


# ---------------------------------------------------------------------------- copies and runs
def fail(message):
    """Print ``message`` and exit with status 2 (the check could not run)."""
    print(f"mutation.py: error: {message}", file=sys.stderr, flush=True)
    raise SystemExit(2)


def tracked_files(repo):
    """Relative paths of the working tree's files as git lists them (tracked and untracked-not-ignored)."""
    out = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=repo,
                         capture_output=True, check=True).stdout.decode("utf-8")
    # --cached also lists tracked files deleted from the working tree, and submodules (folders): skip both
    return sorted(p for p in set(out.split("\0")) if p and (repo / p).is_file())


def snapshot(repo, dest):
    """Copy the working tree's files into the new folder ``dest``."""
    for rel in tracked_files(repo):
        target = dest / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(repo / rel, target, follow_symlinks=False)


def environment(copy):
    """The environment the suite runs in, in the copy at ``copy``."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(copy)] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    env["GLPHONG_GLSL_DIR"] = str(copy / "glsl")
    env["GLPHONG_REQUIRE_BACKENDS"] = "egl,osmesa"
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    return env


def check_import_paths(copy):
    """Stop unless glphong's Python files and GLSL chunks both come from the copy at ``copy``."""
    code = "import glphong, glphong.core.glsl_files as p; print(glphong.__file__); print(p.glsl_root())"
    out = subprocess.run([sys.executable, "-c", code], cwd=copy, env=environment(copy), capture_output=True,
                         text=True, timeout=300)
    if out.returncode != 0:
        fail(f"importing glphong in the copy failed:\n{out.stderr[-3000:]}")
    lines = out.stdout.strip().splitlines()[-2:]
    root = copy.resolve()
    outside = [p for p in lines if not Path(p).resolve().is_relative_to(root)]
    if len(lines) != 2 or outside:
        fail(f"in the copy {copy}, glphong does not come from the copy (glphong.__file__ and glsl_root() "
             f"gave {lines}); the mutations would not be tested.  Is PYTHONPATH or GLPHONG_GLSL_DIR ignored?")
    return lines


_SUMMARY = re.compile(r"^(FAILED|ERROR) (.+)$")


def first_failure(output):
    """Node id of the first ``FAILED``/``ERROR`` line of pytest's short summary, or ''."""
    for line in output.splitlines():
        m = _SUMMARY.match(line.strip())
        if m:
            return m.group(2).split(" - ", 1)[0].strip()
    return ""


def run_suite(copy, timeout, extra):
    """Run the suite in ``copy``; returns ``(exit code or None on timeout, output, seconds)``."""
    start = time.monotonic()
    proc = subprocess.Popen([sys.executable, *PYTEST, *extra], cwd=copy, env=environment(copy),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace",
                            start_new_session=True)  # its own process group: a timeout ends its children too
    try:
        output, _ = proc.communicate(timeout=timeout)
        code = proc.returncode
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        output, _ = proc.communicate()
        code = None
    except BaseException:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        raise
    return code, output, time.monotonic() - start


def verdict(code, output=""):
    """Result text for a pytest exit code (None: timed out) and its ``-rfE`` output (a run that xdist stopped after a
    failed test under ``-x`` exits 2 too, with the test's ``FAILED`` line)."""
    if code == 1:
        return "caught"
    if code == 2:
        return "caught" if re.search(r"(?m)^FAILED ", output) else "caught (collection error)"
    if code == 0:
        return "MISSED"
    return "error (timeout)" if code is None else f"error (exit {code})"


def tail(output, lines=25):
    return "\n".join("    " + line for line in output.rstrip().splitlines()[-lines:])


# ---------------------------------------------------------------------------- report
def _cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def markdown(rows):
    """The results table and the summary line."""
    out = ["| mutation | file | what | result | first failing test | s |",
           "|---|---|---|---|---|---|"]
    for m, result, test, seconds in rows:
        out.append("| " + " | ".join(_cell(c) for c in (m.name, m.path, m.what, result, test or "",
                                                          f"{seconds:.0f}")) + " |")
    caught = sum(CAUGHT.get(r, False) for _, r, _, _ in rows)
    missed = sum(r == "MISSED" for _, r, _, _ in rows)
    errors = len(rows) - caught - missed
    out += ["", f"caught {caught} of {len(rows)} ({missed} missed, {errors} errors)"]
    out += ["", "caught: a test failed (pytest exit 1, or 2 when xdist stopped the run after it); caught (collection "
                "error): pytest exit 2 with no failed test, counted as caught; MISSED: every test passed (exit 0); error: timeout or exit 3, 4 or 5, the run said "
                "nothing about the mutation."]
    return "\n".join(out) + "\n"


def list_mutations(mutations):
    width = max(len(m.name) for m in mutations)
    for m in mutations:
        print(f"{m.name:<{width}}  {m.path:<34}  {m.what}")
    print(f"{len(mutations)} mutations; each one's old text occurs exactly once in its file")


# ---------------------------------------------------------------------------- main
def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                     epilog="Exit status: 0 all caught, 1 some missed or errored, 2 could not run.")
    parser.add_argument("--list", action="store_true", help="list the mutations, check they apply, run nothing")
    parser.add_argument("--only", nargs="+", metavar="SUBSTRING", default=[],
                        help="only mutations whose name contains one of these (case-insensitive)")
    parser.add_argument("--timeout", type=float, default=900.0, metavar="S",
                        help="seconds per suite run, the baseline included (default 900)")
    parser.add_argument("--pytest-args", default="", metavar='"..."',
                        help="extra arguments for every pytest run, e.g. a subset of the tests")
    parser.add_argument("--markdown", metavar="PATH", help="also write the table to PATH")
    args = parser.parse_args(argv)

    validate(MUTATIONS, REPO)
    chosen = select(MUTATIONS, args.only)
    if not chosen:
        fail(f"--only {' '.join(args.only)} selects none of the {len(MUTATIONS)} mutations (see --list)")
    if args.list:
        list_mutations(chosen)
        return 0
    extra = shlex.split(args.pytest_args)

    work = Path(tempfile.mkdtemp(prefix="glphong-mutation-"))
    try:
        pristine = work / "pristine"  # the working tree as it is now: later edits there do not leak in
        pristine.mkdir()
        snapshot(REPO, pristine)
        validate(chosen, pristine)

        copy = work / "baseline"
        shutil.copytree(pristine, copy, symlinks=True)
        module, glsl = check_import_paths(copy)
        print(f"copy of the working tree: {copy}\n  glphong from {module}\n  GLSL from {glsl}", flush=True)
        print(f"baseline: python {' '.join(PYTEST + extra)} ...", flush=True)
        code, output, seconds = run_suite(copy, args.timeout, extra)
        shutil.rmtree(copy, ignore_errors=True)
        if code != 0:
            how = "timed out" if code is None else f"pytest exit {code}"
            fail(f"the unmutated copy does not pass ({how}, {seconds:.0f} s); fix the suite first:\n{tail(output)}")
        print(f"baseline: passes ({seconds:.0f} s)\n", flush=True)

        rows = []
        width = max(len(m.name) for m in chosen)
        for i, m in enumerate(chosen, start=1):
            copy = work / f"run{i:03d}"
            shutil.copytree(pristine, copy, symlinks=True)
            try:
                apply(m, copy)
                code, output, seconds = run_suite(copy, args.timeout, extra)
            finally:
                shutil.rmtree(copy, ignore_errors=True)
            result = verdict(code, output)
            test = first_failure(output) if code in (1, 2) else ""
            rows.append((m, result, test, seconds))
            print(f"[{i}/{len(chosen)}] {m.name:<{width}}  {result:<9}  {test or '-'}  ({seconds:.0f} s)", flush=True)
            if result.startswith("error"):
                print(tail(output), flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)

    table = markdown(rows)
    print("\n" + table, end="", flush=True)
    if args.markdown:
        Path(args.markdown).write_text(table, encoding="utf-8")
        print(f"wrote {args.markdown}")
    return 0 if all(CAUGHT.get(r, False) for _, r, _, _ in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
