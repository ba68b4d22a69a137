"""A pytest plugin that runs a test suite with glphong's pyrender embedding switched on everywhere
(`glphong.integrations.pyrender.enable_everywhere`)::

    pytest -p glphong.integrations.pyrender.everywhere      # someone else's suite, unchanged

Every ``pyrender.OffscreenRenderer`` the suite creates can then draw `GlphongMaterial` primitives; those without
glphong materials render as pyrender renders them (byte-identical frames, docs/pyrender.md).  Set
``PYOPENGL_PLATFORM`` before pytest starts: importing this plugin imports pyrender, which reads it once.
"""
from glphong.integrations.pyrender.renderer import enable_everywhere

__all__ = ["pytest_configure"]


def pytest_configure(config):
    """Switch the embedding on before any test module is collected (and so before any renderer exists)."""
    enable_everywhere()
