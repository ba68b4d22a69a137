"""glphong.testing as a user meets it: a project of their own with ``pytest_plugins = ["glphong.testing"]``.

A temporary project (a conftest that loads the plugin, a material module and a test module that uses
the fixtures and the toolkit) is run by pytest in a subprocess: the fixtures exist, are parametrised
per backend, and a wrong twin fails with the toolkit's message.
"""
import os
import subprocess
import sys
import textwrap

CONFTEST = 'pytest_plugins = ["glphong.testing"]\n'

MODEL = textwrap.dedent('''
    import numpy as np
    from glphong.materials import MaterialModel, Param

    class Wrap(MaterialModel):
        """Wrapped diffuse lighting, f_r (n.l) = k (n.l + w) / (1 + w) (n.l > 0 only)."""
        name = "plugin_wrap"
        params = (Param("k", "rgb", low=0.0), Param("w", "scalar", low=0.0, high=1.0, default=0.5))
        glsl = """
        vec3 plugin_wrap_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
        {
            return u_plugin_wrap_k * ((n_dot_l + u_plugin_wrap_w) / (1.0 + u_plugin_wrap_w));
        }"""

        def response(self, f, wi, wo, n_dot_l, p):
            return p.k * ((n_dot_l + p.w) / (1.0 + p.w))[..., None]

    class WrapWrongTwin(Wrap):
        name = "plugin_wrap_wrong"
        glsl = Wrap.glsl.replace("plugin_wrap", "plugin_wrap_wrong")

        def response(self, f, wi, wo, n_dot_l, p):
            return p.k * (n_dot_l / (1.0 + p.w))[..., None]
''')

TESTS = textwrap.dedent('''
    import numpy as np
    import pytest
    import glphong
    from glphong.testing import TwinMismatch, assert_render_matches, assert_twin_matches
    from wrap import Wrap, WrapWrongTwin

    def test_twin(glphong_backend):
        assert_twin_matches(Wrap(0.3, w=0.4), backend=glphong_backend, n=500)

    def test_wrong_twin_is_caught(glphong_backend):
        with pytest.raises(TwinMismatch, match="WrapWrongTwin"):
            assert_twin_matches(WrapWrongTwin(0.3), backend=glphong_backend, n=500)

    def test_render(glphong_renderer):
        scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)),
                              lights=[glphong.DirectionalLight((0.2, -0.5, -1.0), 1.0)])
        scene.add(glphong.primitives.sphere(3), Wrap(0.3))
        report = assert_render_matches(scene, glphong_renderer)
        assert report.covered_pixels > 500 and glphong_renderer.width == 64

    def test_context(glphong_context):
        assert glphong_context.backend in ("egl", "osmesa")
''')


def test_a_user_project_uses_the_plugin(tmp_path):
    (tmp_path / "conftest.py").write_text(CONFTEST)
    (tmp_path / "wrap.py").write_text(MODEL)
    (tmp_path / "test_wrap.py").write_text(TESTS)
    env = {k: v for k, v in os.environ.items() if k != "PYTEST_ADDOPTS"}
    env["PYTHONPATH"] = str(tmp_path) + os.pathsep + env.get("PYTHONPATH", "")
    out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rs", str(tmp_path)],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    summary = out.stdout.strip().splitlines()[-1]
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-2000:]
    passed = int(summary.split(" passed")[0].split()[-1])
    skipped = int(summary.split(" skipped")[0].split()[-1]) if " skipped" in summary else 0
    assert passed + skipped == 8 and passed >= 4, summary  # 4 tests x 2 backends; a missing backend skips
    if os.environ.get("GLPHONG_REQUIRE_BACKENDS"):
        assert skipped == 0, summary
