"""examples/test_my_shader.py as a user runs it: copied with its GLSL file to a folder outside the checkout and run
by pytest there.  It passes as shipped; one operator changed in the GLSL, or in the twin, makes it fail with the
toolkit's report (the worst rows, GPU and twin values, the allowed band, a reproduction)."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _run(folder):
    env = {k: v for k, v in os.environ.items() if k != "PYTEST_ADDOPTS"}
    out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rs", "test_my_shader.py"],
                         cwd=folder, env=env, capture_output=True, text=True, timeout=300)
    return out.returncode, out.stdout + out.stderr


def _copy(tmp_path, name, glsl=None, twin=None):
    folder = tmp_path / name
    folder.mkdir()
    for file in ("test_my_shader.py", "my_shader.glsl"):
        shutil.copy(EXAMPLES / file, folder / file)
    for file, change in (("my_shader.glsl", glsl), ("test_my_shader.py", twin)):
        if change is not None:
            old, new = change
            text = (folder / file).read_text()
            assert text.count(old) == 1, old
            (folder / file).write_text(text.replace(old, new))
    return folder


def test_the_example_passes_outside_the_checkout(tmp_path):
    code, output = _run(_copy(tmp_path, "as_shipped"))
    assert code == 0, output[-3000:]
    summary = output.strip().splitlines()[-1]
    assert " passed" in summary and "failed" not in summary
    required = {name.strip() for name in os.environ.get("GLPHONG_REQUIRE_BACKENDS", "").split(",") if name.strip()}
    passed = int(summary.split(" passed")[0].split()[-1])
    assert passed >= 3 * len(required), summary  # 3 tests on each required backend (EGL only where OSMesa is gone)


def test_one_operator_in_the_glsl_fails_with_a_report(tmp_path):
    code, output = _run(_copy(tmp_path, "glsl", glsl=("(dot(n, l) + w)", "(dot(n, l) - w)")))
    assert code == 1
    assert "float wrap_diffuse(vec3 n, vec3 l, float w) disagrees with its twin wrap_diffuse" in output
    assert "worst rows of return (float):" in output and "GPU" in output and "allowed [" in output
    assert "reproduce (these rows):" in output and "my_shader.glsl" in output
    assert "test_tone_curve_within_8_ulps" not in output.split("short test summary")[-1]  # the other function passes


def test_one_operator_in_the_twin_fails_with_a_report(tmp_path):
    code, output = _run(_copy(tmp_path, "twin", twin=("radiance / (white * white)", "radiance / (white + white)")))
    assert code == 1
    assert "vec3 tone_reinhard(vec3 radiance, float white) disagrees with its twin tone_reinhard" in output
    assert "ulps" in output and "print(tone_reinhard(radiance=radiance, white=white))" in output
