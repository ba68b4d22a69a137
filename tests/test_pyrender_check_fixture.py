"""The suite's ``pyrender_check`` fixture where glphong lacks a backend (Debian unstable: Mesa 26.2, no libosmesa6).

There ``import pyrender`` under ``PYOPENGL_PLATFORM=osmesa`` dies inside PyOpenGL (``AttributeError: 'NoneType' object
has no attribute 'glGetError'``) before a check script can report ``BackendUnavailable``: the 18 OSMesa tests of
``test_pyrender_flags.py`` and ``test_pyrender_integration.py`` errored there instead of skipping (issue 42,
docs/install.md).  The fixture now asks glphong first: skip where the backend is absent, fail where
``GLPHONG_REQUIRE_BACKENDS`` names it.
"""
import pytest

from glphong.gpu import contexts

#: what the check scripts did on Debian unstable: died in `import pyrender`, with no word from glphong
PYOPENGL_WITHOUT_OSMESA = "raise AttributeError(\"'NoneType' object has no attribute 'glGetError'\")\n"


@pytest.fixture
def script_without_osmesa(monkeypatch, tmp_path):
    """A check script that fails as PyOpenGL does without libOSMesa, in a process where glphong has no OSMesa."""

    def missing():
        raise OSError("simulated: libOSMesa.so.8: cannot open shared object file")

    monkeypatch.setattr(contexts, "_osmesa_library", missing)
    monkeypatch.setattr(contexts, "_reuse", lambda *args: None)  # nor a pooled OSMesa context of an earlier test
    script = tmp_path / "check.py"
    script.write_text(PYOPENGL_WITHOUT_OSMESA)
    return script


def test_an_absent_backend_skips_the_pyrender_check(script_without_osmesa, pyrender_check, monkeypatch):
    monkeypatch.setenv("GLPHONG_REQUIRE_BACKENDS", "egl")
    with pytest.raises(pytest.skip.Exception, match="simulated: libOSMesa"):
        pyrender_check(script_without_osmesa, "osmesa")


def test_a_required_absent_backend_fails_the_pyrender_check_by_name(script_without_osmesa, pyrender_check,
                                                                     monkeypatch):
    monkeypatch.setenv("GLPHONG_REQUIRE_BACKENDS", "egl,osmesa")
    with pytest.raises(pytest.fail.Exception, match="GLPHONG_REQUIRE_BACKENDS names 'osmesa'"):
        pyrender_check(script_without_osmesa, "osmesa")
