"""``glphong doctor`` in a subprocess: on this machine, and with a driver library made unloadable."""
import os
import subprocess
import sys

import pytest


def _doctor(**env):
    out = subprocess.run([sys.executable, "-m", "glphong", "doctor", "--tile", "16"], capture_output=True, text=True,
                         timeout=300, env={**os.environ, **env})
    return out.returncode, out.stdout + out.stderr


def test_doctor_here(make_context):
    """Exit 0, each backend this machine has listed with its GL facts and a passed verification render."""
    backends = []
    for name in ("egl", "osmesa"):
        try:
            make_context(name)
            backends.append(name)
        except pytest.skip.Exception:
            pass
    if not backends:
        pytest.skip("no OpenGL backend here")
    status, text = _doctor()
    assert status == 0, text[-3000:]
    for name in backends:
        assert f"\n  {name}: OpenGL " in text
    assert text.count("passed, max relative error") == len(backends)
    assert text.count("GL_MAX_SAMPLES ") == len(backends)
    assert text.count("subnormal float32: operands ") == len(backends)
    for part in ("packages: glphong ", "moderngl ", "glcontext ", "numpy ", "EGL devices:", "environment:",
                 "GLPHONG_BACKEND", "__EGL_VENDOR_LIBRARY_FILENAMES", "DISPLAY"):
        assert part in text
    assert f"glphong renders and verifies here on: {', '.join(backends)}" in text
    if "egl" in backends:
        assert "libEGL: /" in text and "EGL vendor: /" in text  # where they were loaded from
    if "osmesa" in backends:
        assert "libOSMesa: /" in text


def test_doctor_without_any_backend(tmp_path, make_context):
    """No EGL vendor (libglvnd pointed at a bogus vendor file) and no libOSMesa (glphong's override pointed at a
    missing file): exit 1, and the report names each missing piece and the packages that provide it."""
    make_context("egl")  # the EGL part of this test needs libglvnd's libEGL
    bogus = tmp_path / "bogus.json"
    bogus.write_text('{"file_format_version": "1.0.0", "ICD": {"library_path": "libEGL_nowhere.so.0"}}')
    status, text = _doctor(__EGL_VENDOR_LIBRARY_FILENAMES=str(bogus), GLPHONG_LIBOSMESA="/nonexistent/libOSMesa.so.8")
    assert status == 1, text[-3000:]
    missing = text[text.index("missing or broken:"):]
    for part in ("libOSMesa not found (GLPHONG_LIBOSMESA='/nonexistent/libOSMesa.so.8')",
                 "apt-get install libosmesa6", "dnf install mesa-libOSMesa", "conda install -c conda-forge mesalib",
                 "no EGL vendor library (Mesa's libEGL_mesa.so.0) did", "apt-get install libegl-mesa0 libgl1-mesa-dri",
                 "dnf install mesa-libEGL mesa-dri-drivers", "Mesa 25.1 removed it"):
        assert part in missing, part
    assert f"{bogus}: libEGL_nowhere.so.0" in text
    assert "glphong cannot render here" in text


def test_doctor_without_libegl(make_context):
    """libEGL itself unloadable (GLPHONG_LIBEGL): the EGL packages are named; OSMesa, where present, still
    renders, so the exit status is 0 there."""
    try:
        make_context("osmesa")
        has_osmesa = True
    except pytest.skip.Exception:
        has_osmesa = False
    status, text = _doctor(GLPHONG_LIBEGL="libEGL_nowhere.so.1")
    assert status == (0 if has_osmesa else 1), text[-3000:]
    missing = text[text.index("missing or broken:"):]
    for part in ("libEGL not found (GLPHONG_LIBEGL='libEGL_nowhere.so.1')", "apt-get install libegl1 libegl-mesa0",
                 "dnf install libglvnd-egl mesa-libEGL", "conda install -c conda-forge libegl"):
        assert part in missing, part


def test_readme_driver_lines_survive_without_osmesa():
    """The README's and docs/install.md's driver blocks: the required line installs EGL only, and every line that
    installs libosmesa6 goes on where the package does not exist (Mesa 25.1 and newer); .ci/run still installs
    libosmesa6 and requires both backends."""
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    for page in (root / "README.md", root / "docs" / "install.md"):
        text = page.read_text(encoding="utf-8")
        lines = [line for line in text.splitlines() if line.startswith("sudo apt-get install")]
        assert lines, page
        assert "libosmesa6" not in lines[0] and "libegl1 libegl-mesa0 libgl1-mesa-dri" in lines[0]
        for line in lines:
            assert "libosmesa6" not in line or "|| " in line, (page, line)
    ci = (root / ".ci" / "run").read_text(encoding="utf-8")
    assert "libosmesa6" in ci and "GLPHONG_REQUIRE_BACKENDS=egl,osmesa" in ci


def test_vendor_files_named_by_the_environment_are_read_bounded(tmp_path, monkeypatch):
    """A vendor file the environment names is read up to 64 KiB: /dev/zero or a huge file is reported unreadable
    instead of read without end; a well-formed one names its library."""
    from glphong.tools import doctor

    good = tmp_path / "10_test.json"
    good.write_text('{"file_format_version": "1.0.0", "ICD": {"library_path": "libEGL_test.so.0"}}')
    big = tmp_path / "20_big.json"
    big.write_bytes(b" " * (doctor._VENDOR_FILE_BYTES + 1))
    monkeypatch.setenv("__EGL_VENDOR_LIBRARY_FILENAMES", f"{good}:{big}:/dev/zero")
    found = {path: (library, why) for path, library, why in doctor._vendor_files()}
    assert found[str(good)] == ("libEGL_test.so.0", None)
    for path in (str(big), "/dev/zero"):
        assert found[path][0] is None and "more than 65536 bytes" in found[path][1]


def test_osmesa_hints_agree_with_the_releases_tried():
    """Where ``libosmesa6`` exists, as docs/install.md's table records it from installs on each release (issue 42):
    Ubuntu 24.04, 25.10 and 26.04 keep it (Mesa 25.1.7, ``mesa-compat``) although their Mesa is 25.2 or newer;
    Debian unstable has none.  The hints glphong prints said "Ubuntu 22.04 to 25.04" and "Mesa 25.1 and newer have
    no OSMesa"; they now name the same releases as the table."""
    from pathlib import Path

    from glphong.gpu.contexts import PACKAGES, _install_hint

    table = (Path(__file__).resolve().parent.parent / "docs" / "install.md").read_text(encoding="utf-8")
    rows = {line.split("|")[1].strip(): line.split("|")[5] for line in table.splitlines()
            if line.startswith(("| Debian", "| Ubuntu"))}
    with_osmesa = [name for name, osmesa in rows.items() if "libosmesa6" in osmesa and "none" not in osmesa]
    without = [name for name, osmesa in rows.items() if name not in with_osmesa]
    assert [name.split(" (")[0] for name in with_osmesa] == [
        "Debian 12", "Debian 13", "Ubuntu 22.04", "Ubuntu 24.04", "Ubuntu 25.04", "Ubuntu 25.10", "Ubuntu 26.04"]
    assert [name.split(" (")[0] for name in without] == ["Debian unstable"]
    hint = PACKAGES["osmesa"]["Debian/Ubuntu"]
    assert "Debian 12 and 13, Ubuntu 22.04 to 26.04" in hint and "none in Debian unstable" in hint
    assert "none in Debian unstable" in _install_hint("osmesa")
    assert "Mesa 25.1 and newer have no OSMesa" not in _install_hint("osmesa")
