"""`load_scene`: a scene file as a `glphong.Scene`, by its suffix.

- ``.obj``: `glphong.formats.obj.read_obj` (one object per material, ``usemtl``) with the MTL files it names
  (``mtllib``, `glphong.formats.mtl`; one name with spaces where that file exists, `_library_names`), read by
  glphong itself so that ``Kd``, ``Ks``, ``Ka`` and ``Ns`` keep their decimal values (trimesh keeps 8-bit colours,
  and drops every material of a file whose MTL it cannot parse).  An OBJ file has no camera and no light: it gets the default view
  (`glphong.scene.from_trimesh.default_view`; MTL's ``Ka`` multiplies its ambient light).
- ``.gltf``, ``.glb``: `glphong.formats.gltf_scene` (its own arrays, camera, lights and materials).

Every file, and every file it names, is untrusted (`glphong.filesafety`, docs/files.md).
"""
import re
import warnings
from pathlib import Path

from glphong.core.filesafety import SceneFileError, read_text, resolve_reference
from glphong.core.radiometry import LUMENS_PER_WATT
from glphong.formats.gltf_scene import (gltf_material, gltf_pbr_material, gltf_view, load_gltf, material_from_extras,
                                        read_gltf_json)
from glphong.formats.mtl import material_from_mtl, parse_mtl
from glphong.formats.obj import read_obj
from glphong.formats.overrides import chosen_material
from glphong.scene.from_trimesh import default_view, empty_scene, scene_bounds, with_default_view
from glphong.scene.scene import Scene

__all__ = ["load_scene", "FORMATS", "read_obj", "read_gltf_json", "gltf_view", "gltf_material", "gltf_pbr_material",
           "material_from_extras",
           "scene_from_trimesh", "parse_mtl", "material_from_mtl", "default_view", "scene_bounds", "LUMENS_PER_WATT"]

#: formats `load_scene` reads
FORMATS = (".obj", ".gltf", ".glb")


def scene_from_trimesh(trimesh_scene, camera=None, lights=None, ambient=None, materials=None, vertex_colors="srgb"):
    """`glphong.Scene.from_trimesh` (`glphong.scene.from_trimesh.build_from_trimesh`): a scene of a
    ``trimesh.Scene`` or ``Trimesh``, its nodes' transforms and parts."""
    return Scene.from_trimesh(trimesh_scene, camera, lights, ambient, materials, vertex_colors)


def load_scene(path, camera=None, lights=None, ambient=None, materials=None, light_units=None, camera_name=None,
               allow_outside=False, limits=None, variant=None):
    """Load a scene file as a `glphong.Scene` (see the module for what each format keeps).

    Files are untrusted (`glphong.filesafety`): the file and every file it names must be regular files
    within ``limits``, named files must lie inside the scene file's folder, and whatever is wrong with
    the content is a `glphong.filesafety.SceneFileError` naming the file and where in it.

    Parameters
    ----------
    path : str or path-like
        A Wavefront ``.obj`` (with its ``.mtl`` files), or a glTF 2.0 ``.gltf`` / ``.glb``.
    camera, lights, ambient
        As in `scene_from_trimesh`; default: the file's (glTF: `gltf_view`), else `default_view`'s.  A
        file with no light gets `default_view`'s light and ambient light, with a warning (``lights=[]``
        keeps it dark on purpose).
    materials : dict of str to Material, callable, or 'cook_torrance', optional
        Overrides the file's materials by material name; a callable gets ``(name, MTL or glTF entry or
        None)`` and returns a Material (or None for the file's).  glTF: ``'cook_torrance'`` reads every
        metallic-roughness material as the earlier Cook-Torrance approximation (`gltf_material`) instead of
        the specification's BRDF (`gltf_pbr_material`, the default).
    light_units : {'photometric', 'radiometric'}, optional
        Required where a glTF file has lights (`gltf_view`).
    camera_name : str, optional
        The glTF camera to look through (default the first).
    allow_outside : bool
        Let the file name files outside its own folder (absolute paths, ``..``): for files you trust.
    limits : glphong.filesafety.Limits, optional
        File-size cap, image pixel budget, entry counts (default `glphong.filesafety.LIMITS`).
    variant : str, optional
        glTF: the ``KHR_materials_variants`` variant to draw, by name (default: each primitive's own material).

    Raises
    ------
    ValueError
        A format glphong does not read (naming those it does), a missing file; a ``variant`` the file does not have
        (naming those it has), or one given for an OBJ file.
    glphong.filesafety.SceneFileError
        (a ValueError) Anything wrong with the file's content, naming the file and the line or JSON path.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise ValueError(f"{path}: glphong reads {', '.join(FORMATS)} scene files (got {suffix or 'no suffix'!r})")
    if not path.exists():
        raise SceneFileError(path, "no such file")
    if suffix in (".gltf", ".glb"):
        return load_gltf(path, camera, lights, ambient, materials, light_units, camera_name, allow_outside, limits,
                         variant)
    if variant is not None:
        raise ValueError(f"{path}: variant={variant!r}: an OBJ file has no material variants (glTF's "
                         "KHR_materials_variants)")
    return _load_obj(path, camera, lights, ambient, materials, allow_outside, limits)


#: an OBJ ``mtllib`` statement: its library names, up to a comment or the line's end
_MTLLIB = re.compile(r"^[ \t]*mtllib[ \t]+([^\r\n#]*)", re.M)


def _mtl_libraries(path, text, allow_outside, limits):
    """The materials of every ``mtllib`` an OBJ file's ``text`` names (each confined to its folder, each read
    once).  The text is searched, not split into lines: memory stays that of the text itself."""
    mtl, read, line, position = {}, set(), 1, 0
    for match in _MTLLIB.finditer(text):
        line += text.count("\n", position, match.start())
        position = match.start()
        for name in _library_names(path, match.group(1), f"line {line}", allow_outside):
            library = resolve_reference(path, name, f"line {line}", allow_outside, percent_encoded=False)
            if library in read:
                continue
            read.add(library)
            if library.exists():
                mtl.update(parse_mtl(library, limits, allow_outside))
            else:
                warnings.warn(f"{path}: mtllib {name!r:.80} not found next to it; its materials get defaults",
                              stacklevel=3)
    return mtl


def _library_names(path, names, where, allow_outside):
    """The MTL file names of one ``mtllib`` line (``names``: the rest of the line): the whole of it as one name where
    it has spaces and a file of that name exists inside the folder (three.js's MTLLoader reads the rest of the line as
    one name, Blender tries it first: obj2gltf's ``box mtllib.obj`` names ``box mtllib.mtl``), else each word (the
    OBJ specification's list of files).  Each name is still confined by `resolve_reference`."""
    whole = names.strip()
    if len(whole.split()) > 1:
        try:
            target = resolve_reference(path, whole, where, allow_outside, percent_encoded=False)
        except SceneFileError:  # the words are resolved, and refused, one by one
            target = None
        if target is not None and target.is_file() and (path.resolve().parent / whole.replace("\\", "/")).is_file():
            return [whole]  # the second test: as named, not as resolve() folded a ".." after a missing folder
    return whole.split()


def _load_obj(path, camera, lights, ambient, materials, allow_outside, limits):
    """An OBJ file's scene: one object per material (`read_obj`), its MTL materials."""
    mtl = _mtl_libraries(path, read_text(path, limits), allow_outside, limits)
    scene = empty_scene(Scene, camera, lights, ambient)
    made = {}
    for name, mesh in read_obj(path, limits):
        material = chosen_material(materials, name, mtl.get(name))
        if material is None:
            if name not in made:
                made[name] = material_from_mtl(mtl.get(name, {}), name, str(path), limits)
            material = made[name]
        scene.add(mesh, material, name=name or path.stem)
    return with_default_view(scene, camera, lights, ambient, path)


