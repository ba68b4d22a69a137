"""Pages written from the definitions: one per reflectance model and per light kind, and an index of them.

``docs/conf.py`` calls `write_pages` when the builder starts (``builder-inited``), into ``docs/definitions/``
(git-ignored: the pages are made from the code, never edited).  A page is read off its definition, the way
Mitsuba's plugin reference is:

- the class docstring, which states the formula (``autoclass``, so numpydoc renders it as on the API page);
- the parameter table, from the definition's `glphong.Param` objects (kind, default, range, unit, meaning) and, for a
  material model, its tables, ``fresnel=`` slot and structural choices; for a light kind also the uniforms its
  GLSL reads where they differ from the constructor's parameters;
- the uniform declarations glphong generates for its GLSL chunk;
- for a material model, the gallery tiles of the materials it is a term of (``glphong gallery``) and their answers
  to the lecture's four questions as recorded in ``docs/brdf_answers.md`` (``benchmarks/brdf_answers.py``); the
  records are read, nothing is rendered or measured here.

Only the built-in definitions get pages (a user's, registered while the gallery runs its examples, does not).
"""
import importlib.util
import inspect
import json
import re
from pathlib import Path

import numpy as np

import glphong
from glphong.analysis.gallery import GALLERY
from glphong.lights import registered_lights
from glphong.materials import MaterialSum, Param, registered_models

__all__ = ["FOLDER", "write_pages", "builder_inited"]

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
#: the generated pages' folder, under the documentation's source folder
FOLDER = "definitions"
#: the recorded answers to the four questions: the table and the records it was made from
ANSWERS = DOCS / "brdf_answers.md"
RECORDS = DOCS / "bench" / "brdf_answers.json"
#: the script that recorded them (its ``EXTRA`` entries are answered besides the gallery's tiles)
ANSWERS_SCRIPT = ROOT / "benchmarks" / "brdf_answers.py"


def builtin(definitions):
    """The definitions of glphong itself among ``definitions`` (a user's live in another module)."""
    return [cls for cls in definitions if cls.__module__.split(".")[0] == "glphong"]


def write_pages(out):
    """Write the pages of every built-in material model and light kind, and their index, into ``out``.

    Parameters
    ----------
    out : path-like
        The folder (made if missing); ``.rst`` files of definitions that no longer exist are removed, and a page
        whose text is unchanged is not rewritten (so Sphinx does not read it again).

    Returns
    -------
    dict
        ``'materials'`` and ``'lights'``: ``{name: path}`` of each definition's page; ``'index'``: the index's path.
    """
    out = Path(out)
    models, lights = builtin(registered_models()), builtin(registered_lights())
    answers, tiles = _answers(), _tile_models()
    pages = {f"materials/{cls.name}": _material_page(cls, answers, tiles) for cls in models}
    pages |= {f"lights/{cls.name}": _light_page(cls) for cls in lights}
    pages["index"] = _index_page(models, lights)
    written = {}
    for name, text in pages.items():
        path = written[name] = out / f"{name}.rst"
        path.parent.mkdir(parents=True, exist_ok=True)
        if not path.is_file() or path.read_text(encoding="utf-8") != text:
            path.write_text(text, encoding="utf-8")
    for stale in set(out.rglob("*.rst")) - set(written.values()):
        stale.unlink()
    return {"materials": {cls.name: written[f"materials/{cls.name}"] for cls in models},
            "lights": {cls.name: written[f"lights/{cls.name}"] for cls in lights}, "index": written["index"]}


def builder_inited(app):
    """The ``builder-inited`` handler: the pages into the source folder's `FOLDER`."""
    write_pages(Path(app.srcdir) / FOLDER)


# --------------------------------------------------------------------------- the pages
def _material_page(cls, answers, tiles):
    """A material model's page: heading and docstring, declared properties, parameters, uniforms, tiles, answers."""
    sums = [s for s in _sums() if cls in s.terms]
    lines = _heading(cls, "material", "reflectance model")
    if sums:
        lines += [f"A term of {', '.join(f'{_ref(s)} (``{_sum_formula(s)}``)' for s in sums)}.", ""]
    lines += [".. rubric:: Declared properties", ""]
    for flag in ("non_negative", "reciprocal", "isotropic", "energy_conserving"):
        value = getattr(cls.properties, flag)
        lines.append(f"- {flag.replace('_', '-')}: {'not declared' if value is None else 'yes' if value else 'no'}"
                     + (f" ({_text(cls.properties.condition)})" if flag == "energy_conserving"
                        and cls.properties.condition else ""))
    lines += ["", f"Needs: {', '.join(cls.needs) or 'the normal and the light direction only'}.", ""]
    lines += _parameters("Parameters", cls.arguments())
    lines += _declarations(cls)
    labels = [label for label, _ in GALLERY if cls.name in tiles.get(label, ())]
    rows = [row for label, row in answers["rows"].items() if cls.name in tiles.get(label, ())]
    lines += ["Gallery and the four answers", "----------------------------", ""]
    if labels:
        lines += ["Gallery tiles (``glphong gallery``, :doc:`/reflectance_models`) of the materials with this term: "
                  + ", ".join(f"*{_text(label)}*" for label in labels) + ".", ""]
    if rows:
        lines += ["The lecture's four questions answered for them (float64 twin, :doc:`/brdf`; "
                  "``benchmarks/brdf_answers.py``):", ""] + _table(answers["header"], rows)
    if not labels and not rows:
        lines += ["No gallery tile or recorded answers yet.", ""]
    return "\n".join(lines)


def _light_page(cls):
    """A light kind's page: heading and docstring, counterparts, parameters, uniforms."""
    facts = [f"glTF ``KHR_lights_punctual`` type ``{cls.gltf_type}``" if cls.gltf_type else "no glTF counterpart",
             f"pyrender ``{cls.pyrender_type}``" if cls.pyrender_type else "no pyrender counterpart",
             f"shadows: a {cls.shadow_map} shadow map" if cls.shadow_map else "casts no shadows"]
    lines = _heading(cls, "light", f"{cls.extent} light kind") + [f"Counterparts: {'; '.join(facts)}.", ""]
    lines += _parameters("Parameters", cls.params)
    if cls.uniforms is not None:
        lines += _parameters("Uniforms its GLSL reads", cls.uniforms)
    return "\n".join(lines + _declarations(cls))


def _index_page(models, lights):
    """The index: a table of the models, the materials made of them, a table of the light kinds, the toctree."""
    lines = ["Models and lights, from their definitions", "=" * 41, "",
             "One page per reflectance model and per kind of light glphong defines, written from the definition "
             "itself when the documentation is built (``docs/_definitions.py``): the class docstring with its "
             "formula, the parameter table from its `glphong.Param` objects, the uniforms its GLSL is given and, for "
             "the models, the gallery tiles and the four answers on record.  A definition of your own is made the "
             "same way (:doc:`/custom_material`, :doc:`/lights`).", "",
             "Reflectance models", "------------------", ""]
    lines += _table(["model", "class", "summary"], [[f":doc:`{cls.name} <materials/{cls.name}>`", _ref(cls),
                                                   _summary(cls)] for cls in models])
    lines += ["The materials made of several of them (each a `glphong.MaterialSum`):", ""]
    lines += [f"- {_ref(s)} = ``{_sum_formula(s)}``" for s in _sums()] + [""]
    lines += ["Light kinds", "-----------", ""]
    lines += _table(["kind", "class", "summary"], [[f":doc:`{cls.name} <lights/{cls.name}>`", _ref(cls), _summary(cls)]
                                                   for cls in lights])
    lines += [".. toctree::", "   :hidden:", ""] + [f"   materials/{cls.name}" for cls in models]
    lines += [f"   lights/{cls.name}" for cls in lights] + [""]
    return "\n".join(lines)


def _heading(cls, kind, what):
    """A page's label, title, source files, constructor and class docstring (``autoclass``, not indexed twice)."""
    title = f"``{cls.name}``: {cls.__name__}"
    source = Path(inspect.getsourcefile(cls)).resolve()
    glsl = f", GLSL ``glsl/{cls.glsl.path}``" if hasattr(cls.glsl, "path") else ""
    where = source.relative_to(ROOT) if source.is_relative_to(ROOT) else source.name
    return [f".. _definition-{kind}-{cls.name}:", "", title, "=" * len(title), "",
            f"The {what} ``{cls.name}``: {_ref(cls)} (``{where}``{glsl}).  Constructor::", "",
            f"    {cls.__name__}{_signature(cls)}", "",
            f".. autoclass:: {_public(cls)}", "   :no-index:", ""]


def _parameters(title, arguments):
    """A section ``title`` holding the table of ``arguments`` (name, kind, default, range, unit, meaning)."""
    rows = [[f"``{a.name}``", *_describe(a)] for a in arguments]
    return [title, "-" * len(title), ""] + (_table(["name", "kind", "default", "range", "unit", "meaning"], rows)
                                            if rows else ["None.", ""])


def _describe(argument):
    """``[kind, default, range, unit, meaning]`` of a `Param`, `glphong.materials.Table`, ``fresnel=`` slot or
    `glphong.materials.Choice`."""
    if isinstance(argument, Param):
        kind = argument.kind + (", textureable" if argument.textureable else "")
        extent = {"vec3": "any finite 3-vector", "direction": "any non-zero 3-vector (normalised)"}.get(
            argument.kind, argument.interval) + (", or None" if argument.optional else "")
        unit = argument.unit or ("--" if argument.kind == "direction" else "1")
        return [kind, "required" if _required(argument) else _value(argument.default), extent, _text(unit),
                _text(argument.doc)]
    if hasattr(argument, "shape"):  # a Table
        return [f"table {' x '.join(map(str, argument.shape))} x {argument.channels}", "required",
                f">= {argument.low:g}", _text(argument.unit or "1"), _text(argument.doc)]
    if hasattr(argument, "cosine"):  # the Fresnel slot
        return ["fresnel", _value(argument.default), _text(argument.interval), "--",
                f"the Fresnel factor ``F({argument.cosine})`` multiplying the term"]
    return ["choice", _value(argument.default), _text(argument.interval), "--", _text(argument.doc)]


def _required(argument):
    """Whether a constructor's argument has no default: a `Param` without one (and not optional), a table."""
    if isinstance(argument, Param):
        return argument.default is None and not argument.optional
    return hasattr(argument, "shape")


def _declarations(cls):
    code = cls.uniform_declarations().splitlines()
    return ["Uniforms", "--------", "", "What glphong declares for its GLSL, generated from the parameters:", "",
            ".. code-block:: glsl", ""] + [f"   {line}".rstrip() for line in code] + [""]


def _signature(cls):
    """The constructor's signature: the definition's arguments in order (where it takes ``*args``), then its
    keywords."""
    signature = inspect.signature(cls)
    if not any(p.kind is p.VAR_POSITIONAL for p in signature.parameters.values()):
        return str(signature)
    arguments = cls.arguments() if hasattr(cls, "arguments") else cls.params
    shown = [a.name if _required(a) else f"{a.name}={_python(a.default)}" for a in arguments]
    shown += [str(p) for p in signature.parameters.values() if p.kind is p.KEYWORD_ONLY]
    return f"({', '.join(shown)})"


# --------------------------------------------------------------------------- the records
def _answers():
    """The table of ``docs/brdf_answers.md``: its header and ``{label: cells}`` of its rows."""
    if not ANSWERS.is_file():
        return {"header": [], "rows": {}}
    lines = [line for line in ANSWERS.read_text(encoding="utf-8").splitlines() if line.startswith("|")]
    cells = [[_text(cell.strip()).replace(r"\*\*", "**") for cell in line.strip("|").split("|")] for line in lines]
    return {"header": cells[0], "rows": {_unescape(row[0]): row for row in cells[2:]}}


def _tile_models():
    """``{label: names of its material's models}`` of every gallery tile and recorded answer: the material's class
    named by its record (``docs/bench/brdf_answers.json``), or for a label without one made by its factory
    (`glphong.analysis.gallery.GALLERY`, the answers script's ``EXTRA``: constructors, nothing rendered)."""
    records = json.loads(RECORDS.read_text(encoding="utf-8")) if RECORDS.is_file() else {}
    factories = dict(GALLERY)
    if ANSWERS_SCRIPT.is_file():
        spec = importlib.util.spec_from_file_location("_brdf_answers", ANSWERS_SCRIPT)
        script = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(script)
        factories |= dict(getattr(script, "EXTRA", ()))
    out = {}
    for label in set(factories) | set(records):
        if label in records:
            cls = getattr(glphong.materials, re.match(r"\w+", records[label]["material"]).group(0), None)
        else:
            cls = type(factories[label]())
        if cls is not None:
            out[label] = {t.name for t in (cls.terms if issubclass(cls, MaterialSum) else (cls,))}
    return out


# --------------------------------------------------------------------------- text
def _sums():
    """The built-in materials made of several terms (`glphong.MaterialSum` subclasses), by name."""
    found = {cls for cls in vars(glphong.materials).values()
             if isinstance(cls, type) and issubclass(cls, MaterialSum) and cls is not MaterialSum}
    return sorted(builtin(found), key=lambda cls: cls.__name__)


def _sum_formula(cls):
    """``'Lambert + PhongLobe'`` of a `glphong.MaterialSum`."""
    return " + ".join(t.__name__ for t in cls.terms)


def _public(cls):
    """The shortest public name of a class: ``glphong.X``, else ``glphong.materials.X`` or ``glphong.lights.X``."""
    for module in (glphong, glphong.materials, glphong.lights):
        if getattr(module, cls.__name__, None) is cls:
            return f"{module.__name__}.{cls.__name__}"
    return f"{cls.__module__}.{cls.__qualname__}"


def _ref(cls):
    """A cross-reference to a class's API page, under its public name."""
    return f":class:`~{_public(cls)}`"


def _summary(cls):
    """The docstring's first paragraph (reST, as the API page shows it)."""
    return " ".join(inspect.getdoc(cls).split("\n\n")[0].split())


def _python(value):
    """A default as Python would write it, floats to 6 digits, an rgb triple of equal values as one number."""
    if not isinstance(value, (int, float, tuple, list, np.ndarray)) or isinstance(value, bool):
        return repr(value)
    array = np.atleast_1d(np.asarray(value, dtype=np.float64))
    numbers = [f"{x:.6g}" for x in (array[:1] if np.all(array == array[0]) else array)]
    return numbers[0] if len(numbers) == 1 else f"({', '.join(numbers)})"


def _value(value):
    """`_python` of ``value`` as reST literal text."""
    return f"``{_python(value)}``"


def _text(text):
    """Plain text for reST: its markup characters escaped."""
    return re.sub(r"([\\*`|_])", r"\\\1", str(text))


def _unescape(text):
    """`_text` undone."""
    return re.sub(r"\\(.)", r"\1", text)


def _table(header, rows):
    """A reST ``list-table``."""
    lines = [".. list-table::", "   :header-rows: 1", ""]
    for row in [header] + rows:
        lines += [f"   * - {row[0]}"] + [f"     - {cell}" for cell in row[1:]]
    return lines + [""]
