"""Module paths of glphong 0.1.0 that moved into subpackages: they keep working for one release.

`install` registers the `PUBLIC` paths in ``sys.modules`` and puts a finder on ``sys.meta_path`` that answers an old path (``import glphong.stability``,
``from glphong.key import ProgramKey``) with the module at its new path (the very same module object,
so every name, private ones included, is there), warning once per path with a `DeprecationWarning`
that names the new one.  `PUBLIC` paths are documented API that now live in a subpackage
(``glphong.imaging`` is ``glphong.core.imaging``): they are registered in ``sys.modules`` when glphong is
imported and answer without a warning.  Registering them first also keeps ``glphong.verify`` the function:
an import that loads a submodule sets it as an attribute of its package, one found in ``sys.modules``
does not.  The changelog
lists every move.
"""
import importlib
import importlib.abc
import importlib.util
import sys
import warnings

from glphong.scene.scene import Scene
from glphong.shaders.binding import binding

__all__ = ["MOVED", "PUBLIC", "MOVED_METHODS", "install", "target_of"]

#: deprecated old path -> new path (removed in the release after next)
MOVED = {
    "glphong._validate": "glphong.core.validate",
    "glphong.timing": "glphong.core.timing",
    "glphong.tolerances": "glphong.checks.tolerances",
    "glphong.stability": "glphong.checks.stability",
    "glphong.probe": "glphong.testing.probe",
    "glphong.raycast": "glphong.checks.raycast",
    "glphong.key": "glphong.shaders.key",
    "glphong.programs": "glphong.gpu.programs",
    "glphong.camera": "glphong.scene.camera",
    "glphong.scene.lights": "glphong.lights",
    "glphong.geometry": "glphong.scene.geometry",
    "glphong.culling": "glphong.scene.culling",
    "glphong.contexts": "glphong.gpu.contexts",
    "glphong.textures": "glphong.gpu.textures",
    "glphong.renderer": "glphong.gpu.renderer",
    "glphong.describe": "glphong.gpu.describe",
    "glphong.comparisons": "glphong.bench",
    "glphong.plots": "glphong.analysis.plots",
    "glphong.gallery": "glphong.analysis.gallery",
    "glphong.figures": "glphong.analysis.figures",
    "glphong.loaders": "glphong.formats",
    "glphong.gltf_data": "glphong.formats.gltf_data",
    "glphong.gltf_validate": "glphong.formats.gltf_validate",
    "glphong.gltf_export": "glphong.formats.gltf_export",
    "glphong.obj_reader": "glphong.formats.obj",
    "glphong.cli": "glphong.tools.cli",
    "glphong.speed": "glphong.bench.speed",
    "glphong.expressions": "glphong.tools.expressions",
    "glphong.scene.numerics": "glphong.shaders.numerics",
    "glphong.checks.evaluate": "glphong.evaluation",
    "glphong.checks.probe": "glphong.testing.probe",
    "glphong.checks.glsl_builtins": "glphong.testing.glsl_builtins",
    "glphong.checks.glsl_compare": "glphong.testing.glsl_compare",
    "glphong.checks.glsl_function": "glphong.testing.glsl_runner",
    "glphong.checks.glsl_inputs": "glphong.testing.glsl_arguments",
    "glphong.checks.glsl_source": "glphong.testing.glsl_source",
    "glphong.checks.glsl_types": "glphong.testing.glsl_types",
    "glphong.tools.bench": "glphong.bench.work_precision",
    "glphong.tools.bench_continuous": "glphong.bench.continuous",
    "glphong.tools.speed": "glphong.bench.speed",
    "glphong.analysis.comparisons": "glphong.bench",
    "glphong.materials.params": "glphong.definitions.params",
    "glphong.materials.surface": "glphong.definitions.surface",
    "glphong.materials.table": "glphong.definitions.table",
    "glphong.materials.cases": "glphong.definitions.cases",
    "glphong.materials.registry": "glphong.definitions.registry",
    "glphong.materials.definition_checks": "glphong.definitions.material_checks",
    "glphong.materials.model": "glphong.definitions.material",
    "glphong.materials.fresnel": "glphong.definitions.fresnel",
    "glphong.materials.as_json": "glphong.definitions.as_json",
    "glphong.lights.model": "glphong.definitions.light",
}
#: documented old path -> new path, answered without a warning
PUBLIC = {
    "glphong.imaging": "glphong.core.imaging",
    "glphong.radiometry": "glphong.core.radiometry",
    "glphong.filesafety": "glphong.core.filesafety",
    "glphong.primitives": "glphong.scene.primitives",
    "glphong.reference": "glphong.checks.reference",
    "glphong.verify": "glphong.checks.verify",
}


#: deprecated ``Scene`` method -> its new place: the scene is data, and the program side reads it
#: (``scene.program_key(obj)`` is ``glphong.shaders.binding.binding(scene).program_key(obj)``)
MOVED_METHODS = {name: "glphong.shaders.binding.binding(scene)." + name for name in (
    "program_key", "gbuffer_needs", "light_keys", "shadow_setups", "light_uniform_values", "uniform_values",
    "frame_uniform_values", "object_uniform_values")}


def _moved_method(name):
    """A ``Scene`` method that warns once per call site and answers through the scene's binding."""

    def method(self, *args, **kwargs):
        warnings.warn(f"Scene.{name} moved to {MOVED_METHODS[name]}; the old method goes in the release after next "
                      "(see the changelog)", DeprecationWarning, stacklevel=2)
        return getattr(binding(self), name)(*args, **kwargs)

    method.__name__ = method.__qualname__ = name
    method.__doc__ = f"Deprecated: `{MOVED_METHODS[name]}`."
    return method


def target_of(name):
    """The new path of old module path ``name``, or None."""
    return MOVED.get(name) or PUBLIC.get(name)


class _Alias(importlib.abc.Loader):
    """Loads an old path as the module at its new path."""

    def __init__(self, target):
        self.target = target

    def create_module(self, spec):
        return importlib.import_module(self.target)

    def exec_module(self, module):
        """Nothing to run: the module at the new path is already executed."""


class _MovedFinder(importlib.abc.MetaPathFinder):
    """Finds the old module paths of `MOVED` and `PUBLIC`."""

    def find_spec(self, fullname, path=None, target=None):
        new = target_of(fullname)
        if new is None:
            return None
        if fullname in MOVED:
            warnings.warn(f"{fullname} moved to {new}; the old path goes in the release after next "
                          "(see the changelog)", DeprecationWarning, stacklevel=_caller_level())
        return importlib.util.spec_from_loader(fullname, _Alias(new))


def _caller_level():
    """The stack level of the import statement that asked (past importlib's frames)."""
    frame, level = sys._getframe(1), 1
    while frame is not None and frame.f_code.co_filename.startswith("<frozen importlib"):
        frame, level = frame.f_back, level + 1
    return level + 1


def install():
    """Register the `PUBLIC` paths, put the finder on ``sys.meta_path`` and give ``Scene`` its `MOVED_METHODS`,
    once (``import glphong`` does this, after importing the modules the public paths name)."""
    for name in MOVED_METHODS:
        if name not in vars(Scene):
            setattr(Scene, name, _moved_method(name))
    for old, new in PUBLIC.items():
        sys.modules.setdefault(old, importlib.import_module(new))
    if not any(isinstance(finder, _MovedFinder) for finder in sys.meta_path):
        sys.meta_path.insert(0, _MovedFinder())
