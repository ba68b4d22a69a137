"""Every public name has an entry in the API reference (``docs/api/*.rst``), read from the sources.

A name is public when a public module lists it in ``__all__``: ``glphong`` and ``glphong.testing`` (and the
modules the API reference has a page for, `MODULES`).  Its entry is an ``autosummary`` item that makes a page
(under ``:toctree:``) or an ``automodule`` / ``autoclass`` / ``autofunction`` / ``autodata`` / ... directive, naming
the object under this public name or under another one the same object has (``glphong.Phong`` documents
``glphong.materials.Phong``; ``glphong.testing.glsl_builtins`` documents ``glphong.testing.glsl``).  The
``.rst`` files are parsed here, without Sphinx: fast, and the test names the names that have no entry.
"""
import importlib
import inspect
import re
import sys
from pathlib import Path

import pytest

import glphong.testing  # noqa: F401  (the names resolve among the modules imported: glphong.testing.glsl)

ROOT = Path(__file__).resolve().parent.parent
API = ROOT / "docs" / "api"
#: the public modules whose ``__all__`` the API reference covers
MODULES = ("glphong", "glphong.testing", "glphong.materials", "glphong.lights")

_DIRECTIVE = re.compile(r"^\.\. (currentmodule|module|automodule|autosummary|auto\w+|py:\w+)::[ \t]*(\S*)")
_OPTION = re.compile(r"^\s+:[\w-]+:")


def documented(text):
    """The full names an API page's reST ``text`` documents (set of str).

    ``autosummary`` items count where the directive has ``:toctree:`` (a page of their own; a summary
    without one only links to a page made elsewhere), each relative to the ``currentmodule`` above it unless
    it names ``glphong...`` itself; ``auto*`` directives count with their argument, likewise.  A ``~``
    prefix (shown name only) is dropped.
    """
    names, module, lines = set(), "", text.splitlines()
    i = 0
    while i < len(lines):
        match = _DIRECTIVE.match(lines[i])
        i += 1
        if not match:
            continue
        directive, argument = match.groups()
        if directive in ("currentmodule", "module", "py:module", "py:currentmodule"):
            module = "" if argument == "None" else argument
            continue
        if directive == "automodule":
            names.add(argument)
            module = argument
            continue
        if directive == "autosummary":
            items, toctree = [], False
            while i < len(lines) and (not lines[i].strip() or lines[i].startswith((" ", "\t"))):
                if _OPTION.match(lines[i]):
                    toctree = toctree or lines[i].strip().startswith(":toctree:")
                elif lines[i].strip():
                    items.append(lines[i].strip().lstrip("~"))
                i += 1
            if toctree:
                names.update(_qualified(module, item) for item in items)
            continue
        names.add(_qualified(module, argument.lstrip("~")))
    return names


def _qualified(module, name):
    return name if not module or name == module or name.startswith(("glphong.", module + ".")) else f"{module}.{name}"


def resolve(dotted):
    """The object a dotted name stands for among the modules imported so far, or None.

    Attributes first (``glphong.describe`` is the function, not the module ``glphong.gpu.describe`` it was
    moved from), then ``sys.modules``; nothing is imported (``glphong.integrations.pyrender`` would import
    pyrender, which fixes PyOpenGL's platform for the whole process).
    """
    parts = dotted.split(".")
    obj = sys.modules.get(parts[0])
    for i in range(1, len(parts)):
        if obj is None:
            return None
        obj = getattr(obj, parts[i], None) if hasattr(obj, parts[i]) else sys.modules.get(".".join(parts[:i + 1]))
    return obj


def _is_named(obj):
    """An object identity may stand for: a module, class or function (not a number, string or instance)."""
    return inspect.ismodule(obj) or inspect.isclass(obj) or inspect.isroutine(obj)


def missing(public, entries):
    """The names of ``public`` (full names) that no entry of ``entries`` (full names) documents: neither under
    that name nor as the same module, class or function under another (sorted list)."""
    objects = {id(obj) for obj in map(resolve, entries) if obj is not None and _is_named(obj)}
    out = []
    for name in public:
        if name in entries:
            continue
        obj = resolve(name)
        if obj is None or not _is_named(obj) or id(obj) not in objects:
            out.append(name)
    return sorted(out)


def public_names(module):
    """``module.name`` for every name of the module's ``__all__`` (list; empty where it has none)."""
    return [f"{module}.{name}" for name in getattr(importlib.import_module(module), "__all__", ())]


ENTRIES = set().union(*(documented(page.read_text(encoding="utf-8")) for page in sorted(API.glob("*.rst"))))


def test_the_reference_has_its_entries():
    assert len(ENTRIES) > 150
    assert {"glphong.Phong", "glphong.SpotLight", "glphong.testing.evaluate", "glphong.imaging"} <= ENTRIES


@pytest.mark.parametrize("module", MODULES)
def test_every_public_name_has_an_entry(module):
    public = public_names(module)
    assert public or module != "glphong", "glphong has no __all__"
    absent = missing(public, ENTRIES)
    assert absent == [], f"public names of {module} with no entry in docs/api/*.rst: {absent}"


def test_the_check_names_what_is_missing():
    page = """
.. currentmodule:: glphong

.. autosummary::

   ~glphong.SpotLight

.. autosummary::
   :toctree: generated/

   Phong
   ~glphong.materials.PhongLobe

.. autoclass:: glphong.lights.RectLight

.. automodule:: glphong.testing.glsl_builtins
   :no-members:
"""
    entries = documented(page)
    assert entries == {"glphong.Phong", "glphong.materials.PhongLobe", "glphong.lights.RectLight",
                       "glphong.testing.glsl_builtins"}
    public = ["glphong.Phong", "glphong.materials.Phong", "glphong.RectLight", "glphong.SpotLight",
              "glphong.testing.glsl", "glphong.Lambert", "glphong.__version__", "glphong.NoSuchName"]
    # the same class under another public name counts; a summary without a page, an unknown name, a string don't
    assert missing(public, entries) == ["glphong.Lambert", "glphong.NoSuchName", "glphong.SpotLight",
                                        "glphong.__version__"]
