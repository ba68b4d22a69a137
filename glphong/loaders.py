"""Scenes from the files users have: Wavefront OBJ with its MTL materials, glTF 2.0, and trimesh scenes.

`load_scene(path)` reads an ``.obj`` file (`read_obj`: one object per material, ``usemtl``) and the MTL
files it names (``mtllib``, `parse_mtl`) itself, so that ``Kd``, ``Ks``, ``Ka`` and ``Ns`` keep their
decimal values (trimesh keeps 8-bit colours, and drops every material of a file whose MTL it cannot
parse, e.g. one with a single-value ``Kd``).  Each part gets the material its MTL entry
means (`glphong.materials.MtlPhong`):

- ``illum 0``: colour ``Kd`` with no lighting: a constant radiance ``ka = Kd`` and nothing lit;
- ``illum 1``: ``Kd (n.l) E + Ka L_a`` (no specular term);
- ``illum 2``: ``Kd (n.l) E + Ks max(v.r, 0)^Ns E + Ka L_a``;
- ``illum 3`` to ``10`` (reflections, refraction, ray tracing): rendered as ``illum 2``, with a warning;
- ``map_Kd`` / ``map_Ks``: textures (sRGB, trilinear, repeat) that ``Kd`` / ``Ks`` multiply.

An OBJ file has no camera and no light.  Unless given, the camera looks at the centre of the geometry's
bounding sphere (radius ``r``) from ``3 r`` along ``(0.3, 0.4, 1)`` (it fills 87% of a 45-degree view), a
point light above and beside it delivers ``E = 1 W/m^2`` at the centre, and the ambient light is
``L_a = 0.1`` (MTL's ``Ka`` multiplies it).

A glTF file (``.gltf``, ``.glb``) is read from its own arrays (`glphong.gltf_data`: positions, normals,
uvs, tangents, ``COLOR_0``, indices, nodes in file order), its camera and ``KHR_lights_punctual`` lights
(`gltf_view`), and its materials: a glphong material stored in the material's ``extras``
(`material_from_extras`, written by `glphong.save_gltf`), else the metallic-roughness approximation
`gltf_material` (with ``baseColorTexture`` and ``COLOR_0``).

`scene_from_trimesh` (also `glphong.Scene.from_trimesh`) keeps a ``trimesh.Scene``'s node transforms and
parts; a part's material comes from ``materials`` (a mapping by part or material name, or a function of
the name and the trimesh geometry), else from its trimesh material: a ``SimpleMaterial`` (OBJ) as
`MtlPhong` from its 8-bit colours, a ``PBRMaterial`` (glTF) as ``Lambert(baseColor / pi)`` (each with its
image as a texture the colour multiplies, where the mesh has UVs), else ``Lambert(0.5 / pi)``; vertex colours are decoded as 8-bit sRGB unless ``vertex_colors='linear'``.
"""
import json
import math
import warnings
from pathlib import Path

import numpy as np

from .filesafety import SceneFileError, decode_image, read_bytes, read_text, resolve_reference
from .obj_reader import read_obj

__all__ = ["load_scene", "read_obj", "read_gltf_json", "gltf_view", "gltf_material", "material_from_extras",
           "scene_from_trimesh", "parse_mtl",
           "material_from_mtl", "default_view", "scene_bounds", "LUMENS_PER_WATT"]

#: formats `load_scene` reads
FORMATS = (".obj", ".gltf", ".glb")
#: luminous efficacy of 555 nm light [lm/W]: photometric glTF intensities to watts (docs/design.md section 2)
LUMENS_PER_WATT = 683.0


def parse_mtl(path, limits=None, allow_outside=False):
    """The materials of an MTL file, keyword values as written.

    Parameters
    ----------
    path : path-like
    limits : glphong.filesafety.Limits, optional
        The file-size cap (a regular file is required).
    allow_outside : bool
        Let ``map_Kd`` / ``map_Ks`` name images outside the MTL file's folder.

    Returns
    -------
    dict of str to dict
        Per ``newmtl`` name: ``Kd``, ``Ks``, ``Ka`` (tuples of 3 float, a single value repeated), ``Ns``
        (float), ``illum`` (int), ``map_Kd`` and ``map_Ks`` (the image's path, resolved against the MTL
        file's folder and confined to it; options such as ``-s`` are ignored, with a warning), where the
        file gives them.

    Raises
    ------
    glphong.filesafety.SceneFileError
        A keyword with values that are not finite numbers, or an image path leaving the folder, naming the
        file and line.
    """
    out, current = {}, None
    for number, raw in enumerate(read_text(path, limits).splitlines(), start=1):
        words = raw.split("#", 1)[0].split()
        if not words:
            continue
        keyword, values = words[0], words[1:]
        if keyword == "newmtl":
            current = out.setdefault(" ".join(values), {})
            continue
        if current is None or keyword not in ("Kd", "Ks", "Ka", "Ns", "illum", "map_Kd", "map_Ks"):
            continue
        where = f"line {number}"
        if keyword.startswith("map_"):
            if not values:
                raise SceneFileError(path, f"{keyword} needs an image file", where)
            if values[0].startswith("-"):
                warnings.warn(f"{path}:{number}: {keyword} options {' '.join(values[:-1])!r:.80} are ignored",
                              stacklevel=2)
            current[keyword] = resolve_reference(path, values[-1], where, allow_outside, percent_encoded=False)
            continue
        try:
            if keyword in ("Kd", "Ks", "Ka"):
                numbers = [float(v) for v in values[:3]]
                current[keyword] = tuple(numbers * 3 if len(numbers) == 1 else numbers)
                if len(current[keyword]) != 3 or not all(math.isfinite(v) for v in current[keyword]):
                    raise ValueError
            elif keyword == "Ns":
                current["Ns"] = float(values[0])
                if not math.isfinite(current["Ns"]):
                    raise ValueError
            else:
                current["illum"] = int(values[0])
        except (ValueError, IndexError):
            raise SceneFileError(path, f"{keyword} needs finite numbers (got {' '.join(values)!r:.80})", where) from None
    return out


#: image formats an MTL map may be (Pillow plugins asked for; no EPS or PDF reaches Ghostscript)
MTL_IMAGE_FORMATS = ("PNG", "JPEG", "BMP", "TGA", "TIFF")


def material_from_mtl(entry, name="", source="", limits=None):
    """The glphong material an MTL entry (`parse_mtl`) means (see the module).  ``map_Kd`` and ``map_Ks``
    are textures that ``Kd`` and ``Ks`` multiply (1 where the entry omits them); a map whose image is
    missing is warned about and its constant used; an image beyond ``limits`` is an error."""
    from .materials import MtlPhong, Texture

    kd = entry.get("Kd", (1.0, 1.0, 1.0) if "map_Kd" in entry else (0.8, 0.8, 0.8))  # MTL's default diffuse colour
    ks = entry.get("Ks", (1.0, 1.0, 1.0) if "map_Ks" in entry else (0.0, 0.0, 0.0))
    specular = "map_Ks" in entry or any(ks)
    for keyword, value in (("map_Kd", kd), ("map_Ks", ks)):
        if keyword in entry:
            image = Path(entry[keyword])
            if not image.exists():
                warnings.warn(f"{source}: material {name!r}: {keyword} {image.name} not found; its constant is used",
                              stacklevel=3)
                continue
            payload = read_bytes(image, limits, source or image, f"material {name!r} {keyword}")
            pixels = decode_image(payload, limits, source or image, f"material {name!r} {keyword} {image.name}",
                                  formats=MTL_IMAGE_FORMATS)
            if pixels.ndim == 3 and pixels.shape[2] == 4:
                pixels = pixels[:, :, :3]
            try:
                texture = Texture(pixels, scale=value)
            except ValueError as exc:
                raise SceneFileError(source or image, f"material {name!r}: {keyword} {image.name}: {exc}") from None
            kd, ks = (texture, ks) if keyword == "map_Kd" else (kd, texture)
    ka = entry.get("Ka", (0.0, 0.0, 0.0))
    q = entry.get("Ns", 0.0)
    illum = entry.get("illum", 2 if specular else 1)
    if illum == 0:
        if not isinstance(kd, tuple):
            warnings.warn(f"{source}: material {name!r} has illum 0 and map_Kd: rendered with the constant Kd",
                          stacklevel=3)
            kd = entry.get("Kd", (1.0, 1.0, 1.0))
        return MtlPhong(0.0, 0.0, 0.0, 0.0, ka=kd)
    if illum == 1:
        return MtlPhong(kd, 0.0, q, ka)
    if illum != 2:
        warnings.warn(f"{source}: material {name!r} has illum {illum} (reflection, refraction or ray tracing): "
                      "glphong renders it as illum 2 (Kd, Ks, Ns and Ka)", stacklevel=3)
    return MtlPhong(kd, ks, q, ka)


def scene_bounds(scene):
    """``(centre (3,), radius)``: a world-space sphere about the centre of the scene's bounding box holding
    every vertex of every object (radius at least 1e-6 m)."""
    from .culling import points_sphere

    points = [(obj.pose[:3, :3] @ obj.mesh.positions.T).T + obj.pose[:3, 3] for obj in scene.objects]
    centre, radius = points_sphere(np.concatenate(points) if points else np.zeros((1, 3)))
    return centre, max(radius, 1e-6)


def default_view(scene):
    """A camera, a point light and an ambient light for a scene that has none (see the module):
    ``(camera, [light], ambient)``."""
    from .camera import PerspectiveCamera
    from .lights import AmbientLight, PointLight

    centre, radius = scene_bounds(scene)
    direction = np.array([0.3, 0.4, 1.0]) / np.linalg.norm([0.3, 0.4, 1.0])
    distance = 3.0 * radius  # the bounding sphere fills 87% of a 45-degree view
    camera = PerspectiveCamera.look_at(centre + distance * direction, centre, yfov=math.radians(45.0),
                                       znear=0.01 * radius, zfar=distance + 4 * radius)
    light = centre + distance * direction + radius * np.array([1.0, 1.5, 0.0])
    d = np.linalg.norm(light - centre)
    return camera, [PointLight(tuple(light), 4 * math.pi * d * d)], AmbientLight(0.1)


def _scene(camera, lights, ambient):
    """An empty scene with the given camera (a stand-in until `_with_view` places the default one)."""
    from .camera import PerspectiveCamera
    from .scene import Scene

    return Scene(camera if camera is not None else PerspectiveCamera(1.0), lights or (), ambient)


def _with_view(scene, camera, lights, ambient):
    """``scene`` with `default_view`'s camera where none was given, and its lights and ambient light where
    no lights were given either."""
    if camera is None:
        view_camera, view_lights, view_ambient = default_view(scene)
        scene.camera = view_camera
        if lights is None:
            for light in view_lights:
                scene.add_light(light)
            if ambient is None:
                scene.ambient = view_ambient
    return scene


def _trimesh_material(geometry):
    from .materials import Lambert, MtlPhong, Texture

    visual = getattr(geometry, "visual", None)
    material = getattr(visual, "material", None)
    kind = type(material).__name__
    has_uv = getattr(visual, "uv", None) is not None

    def textured(scale, image):  # the material's image times its colour, where the mesh has UVs
        return Texture(np.asarray(image.convert("RGB")), scale=scale) if image is not None and has_uv else scale

    if kind == "SimpleMaterial":
        rgb = lambda c: tuple(np.asarray(c, dtype=np.float64)[:3] / 255.0)  # noqa: E731
        return MtlPhong(textured(rgb(material.diffuse), getattr(material, "image", None)), rgb(material.specular),
                        float(material.glossiness or 0.0), rgb(material.ambient))
    if kind == "PBRMaterial":
        factor = material.baseColorFactor if material.baseColorFactor is not None else (255, 255, 255, 255)
        kd = tuple(np.asarray(factor, dtype=np.float64)[:3] / 255.0 / math.pi)
        return Lambert(textured(kd, material.baseColorTexture))
    return Lambert(0.5 / math.pi)


def scene_from_trimesh(trimesh_scene, camera=None, lights=None, ambient=None, materials=None, vertex_colors="srgb"):
    """A `glphong.Scene` of a ``trimesh.Scene`` (or ``Trimesh``): every node's geometry with its world
    transform, named after the node; materials as in the module notes.

    Parameters
    ----------
    trimesh_scene : trimesh.Scene or trimesh.Trimesh
    camera : glphong camera, optional
        Default: `default_view`'s (also its light and ambient light when ``lights`` is None).
    lights : sequence of lights, optional
    ambient : glphong.AmbientLight, optional
    materials : dict of str to Material, or callable, optional
        By geometry name or material name; a callable gets ``(name, geometry)`` and returns a Material
        (or None for the default).
    vertex_colors : {'srgb', 'linear'}
        The encoding of the meshes' vertex colours (`glphong.geometry.MeshData.from_trimesh`).
    """
    import trimesh

    from .geometry import MeshData
    from .materials import Material

    if isinstance(trimesh_scene, trimesh.Trimesh):
        trimesh_scene = trimesh.Scene(trimesh_scene)
    if not isinstance(trimesh_scene, trimesh.Scene):
        raise TypeError(f"trimesh_scene must be a trimesh.Scene or trimesh.Trimesh (got {type(trimesh_scene).__name__})")
    parts = []
    for node in trimesh_scene.graph.nodes_geometry:
        transform, geometry_name = trimesh_scene.graph[node]
        geometry = trimesh_scene.geometry[geometry_name]
        if not isinstance(geometry, trimesh.Trimesh) or len(geometry.faces) == 0:
            continue  # point clouds and paths have no surface to shade
        material = None
        if callable(materials):
            material = materials(geometry_name, geometry)
        elif materials:
            material_name = getattr(getattr(geometry.visual, "material", None), "name", None)
            material = materials.get(geometry_name, materials.get(material_name))
        if material is None:
            material = _trimesh_material(geometry)
        if not isinstance(material, Material):
            raise TypeError(f"materials gave {type(material).__name__} for {geometry_name!r}: it must give a "
                            "glphong material")
        parts.append((geometry, material, np.asarray(transform, dtype=np.float64), str(node)))
    scene = _scene(camera, lights, ambient)
    for geometry, material, transform, name in parts:
        scene.add(MeshData.from_trimesh(geometry, colors=vertex_colors), material, pose=transform, name=name)
    return _with_view(scene, camera, lights, ambient)


def read_gltf_json(path, limits=None):
    """The validated JSON document of a ``.gltf`` file, or of a ``.glb`` file's first chunk (dict;
    `glphong.gltf_data.GltfFile`).

    Raises
    ------
    glphong.filesafety.SceneFileError
        Anything wrong with the file, with its JSON path.
    """
    from .gltf_data import GltfFile

    return GltfFile(path, limits).document


def _glphong_extras(document):
    """What glphong stored in the asset's ``extras`` (`glphong.gltf_export`), or {}."""
    extras = document.get("asset", {}).get("extras", {})
    stored = extras.get("glphong") if isinstance(extras, dict) else None
    return stored if isinstance(stored, dict) else {}


def material_from_extras(entry, gltf, where=""):
    """The glphong material stored in a glTF material's ``extras: {"glphong": ...}``
    (`glphong.materials.as_json`), or None where there is none.

    Parameters
    ----------
    entry : dict
        The JSON ``materials`` entry.
    gltf : glphong.gltf_data.GltfFile
    where : str
        The entry's JSON path (for errors).

    Raises
    ------
    glphong.filesafety.SceneFileError
        A stored material that cannot be made (an unknown class, a table, a value its class refuses).
    """
    from .gltf_data import read_gltf_image
    from .materials.as_json import material_from_json
    from .materials.surface import TextureImage

    extras = entry.get("extras", {})
    stored = extras.get("glphong") if isinstance(extras, dict) else None
    if stored is None:
        return None

    def textures(index, wrap, filter, srgb):
        textures_count = len(gltf.document.get("textures", []))
        if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < textures_count:
            raise ValueError(f"texture index {index!r:.20} is not one of the file's {textures_count} textures")
        pixels = read_gltf_image(gltf, index)
        if pixels is None:
            raise ValueError(f"texture {index} has no image glphong decodes")
        return TextureImage(pixels, srgb=srgb, wrap=wrap, filter=filter)

    try:
        return material_from_json(stored, textures)
    except SceneFileError:
        raise
    except (TypeError, ValueError, KeyError, AttributeError) as exc:
        raise SceneFileError(gltf.path, f"stores a glphong material that cannot be made: {exc}"[:400],
                             f"{where}.extras.glphong") from None


def gltf_view(document, camera_name=None, light_units=None, source=""):
    """The camera and lights of a glTF document: ``(camera or None, [lights])``.

    The camera is the node camera named ``camera_name`` (by the camera's or its node's name) or the first
    one; ``yfov``, ``znear`` and ``zfar`` are read as written (an infinite ``zfar``: ``1e6 znear``),
    orthographic ``ymag`` too.  ``KHR_lights_punctual`` point and directional lights need ``light_units``:
    ``'photometric'`` (the glTF specification: point intensity in candela, directional illuminance in lux;
    ``Phi = 4 pi I color / 683``, ``E = lux color / 683``) or ``'radiometric'`` (intensity taken as W/sr and
    W/m^2).  Spot lights are refused (glphong has point and directional lights).
    """
    from .camera import OrthographicCamera, PerspectiveCamera
    from .gltf_data import node_matrices
    from .lights import DirectionalLight, PointLight
    from .radiometry import power_from_intensity

    nodes = document.get("nodes", [])
    worlds = node_matrices(document)
    cameras = document.get("cameras", [])
    camera = None
    for index, node in enumerate(nodes):
        if "camera" not in node or index not in worlds:
            continue
        spec = cameras[node["camera"]]
        if camera_name is not None and camera_name not in (spec.get("name"), node.get("name")):
            continue
        pose = worlds[index].copy()
        pose[:3, :3] /= np.linalg.norm(pose[:3, :3], axis=0)  # a camera node's scale does not apply
        if spec.get("type") == "orthographic":
            o = spec["orthographic"]
            camera = OrthographicCamera(o["ymag"], pose=pose, znear=max(o.get("znear", 0.0), 1e-6), zfar=o["zfar"])
        else:
            p = spec["perspective"]
            camera = PerspectiveCamera(p["yfov"], pose=pose, znear=p["znear"], zfar=p.get("zfar", 1e6 * p["znear"]))
        break
    if camera_name is not None and camera is None:
        names = [c.get("name") for c in cameras]
        raise ValueError(f"{source}: no camera named {camera_name!r} (cameras: {names})")
    definitions = document.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    lights = []
    for index, node in enumerate(nodes):
        reference = node.get("extensions", {}).get("KHR_lights_punctual")
        if reference is None or index not in worlds:
            continue
        light = definitions[reference["light"]]
        kind = light.get("type")
        if kind == "spot":
            raise ValueError(f"{source}: light {light.get('name', reference['light'])!r} is a spot light: glphong has "
                             "point and directional lights only")
        if light_units is None:  # a file may declare them (glphong.gltf_export writes radiometric lights)
            light_units = _glphong_extras(document).get("light_units")
        if light_units not in ("photometric", "radiometric"):
            raise ValueError(f"{source} has KHR_lights_punctual lights: say what their intensities are with "
                             "light_units='photometric' (candela and lux, as the glTF specification says) or "
                             "'radiometric' (W/sr and W/m^2)")
        scale = (1.0 / LUMENS_PER_WATT if light_units == "photometric" else 1.0) * light.get("intensity", 1.0)
        colour = np.asarray(light.get("color", (1.0, 1.0, 1.0)), dtype=np.float64) * scale
        world = worlds[index]
        if kind == "point":
            lights.append(PointLight(tuple(world[:3, 3]), tuple(power_from_intensity(colour))))
        elif kind == "directional":
            lights.append(DirectionalLight(tuple(-world[:3, 2]), tuple(colour)))
        else:
            raise ValueError(f"{source}: light type {kind!r} is not one glphong knows")
    return camera, lights


def gltf_material(entry, base_color_texture=None, vertex_colors=False):
    """glphong's approximation of a glTF metallic-roughness material (JSON ``materials`` entry): Cook-Torrance
    with Beckmann slope ``m = roughness^2`` (glTF's GGX ``alpha``, at least 1e-3), diffuse albedo
    ``baseColor (1 - metallic)`` and Schlick's Fresnel with ``f0 = 0.04 (1 - metallic) + baseColorFactor metallic``.
    The lobes differ (Beckmann against GGX, no coupling of diffuse and specular): an approximation.

    ``baseColor`` is ``baseColorFactor`` times the base-colour texture (``base_color_texture``, an image
    array, sRGB, or a `glphong.materials.TextureImage`) times the mesh's ``COLOR_0`` (``vertex_colors``), as glTF defines it; the texture and the
    colours vary the diffuse albedo only (the metallic-roughness texture is not read)."""
    from .materials import CookTorrance, SchlickFresnel, Texture, VertexColors

    pbr = entry.get("pbrMetallicRoughness", {})
    base = np.clip(np.asarray(pbr.get("baseColorFactor", (1.0, 1.0, 1.0, 1.0))[:3], dtype=np.float64), 0.0, 1.0)
    metallic = min(float(pbr.get("metallicFactor", 1.0)), 1.0)  # factors above 1 (validated >= 0) are clamped
    roughness = min(float(pbr.get("roughnessFactor", 1.0)), 1.0)
    f0 = 0.04 * (1 - metallic) + base * metallic
    rho_d = tuple(base * (1 - metallic))
    if base_color_texture is not None:
        rho_d = Texture(base_color_texture, scale=rho_d, srgb=True, vertex_colors=vertex_colors)
    elif vertex_colors:
        rho_d = VertexColors(scale=rho_d)
    return CookTorrance(rho_d, max(roughness * roughness, 1e-3), fresnel=SchlickFresnel(tuple(np.clip(f0, 0.0, 1.0))))


def load_scene(path, camera=None, lights=None, ambient=None, materials=None, light_units=None, camera_name=None,
               allow_outside=False, limits=None):
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
    materials : dict of str to Material, or callable, optional
        Overrides the file's materials by material name; a callable gets ``(name, MTL or glTF entry or
        None)`` and returns a Material (or None for the file's).
    light_units : {'photometric', 'radiometric'}, optional
        Required where a glTF file has lights (`gltf_view`).
    camera_name : str, optional
        The glTF camera to look through (default the first).
    allow_outside : bool
        Let the file name files outside its own folder (absolute paths, ``..``): for files you trust.
    limits : glphong.filesafety.Limits, optional
        File-size cap, image pixel budget, entry counts (default `glphong.filesafety.LIMITS`).

    Raises
    ------
    ValueError
        A format glphong does not read (naming those it does), a missing file.
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
        return _load_gltf(path, camera, lights, ambient, materials, light_units, camera_name, allow_outside, limits)
    return _load_obj(path, camera, lights, ambient, materials, allow_outside, limits)


def _mtl_libraries(path, text, allow_outside, limits):
    """The materials of every ``mtllib`` an OBJ file's ``text`` names (each confined to its folder)."""
    mtl = {}
    for number, line in enumerate(text.splitlines(), start=1):
        words = line.split("#", 1)[0].split()
        if not words or words[0] != "mtllib":
            continue
        for name in words[1:]:
            library = resolve_reference(path, name, f"line {number}", allow_outside, percent_encoded=False)
            if library.exists():
                mtl.update(parse_mtl(library, limits, allow_outside))
            else:
                warnings.warn(f"{path}: mtllib {name!r:.80} not found next to it; its materials get defaults",
                              stacklevel=3)
    return mtl


def _chosen_material(materials, name, entry):
    """The user's material for part ``name`` (``materials`` mapping or callable), or None."""
    from .materials import Material

    material = None
    if callable(materials):
        material = materials(name, entry)
    elif materials and name in materials:
        material = materials[name]
    if material is not None and not isinstance(material, Material):
        raise TypeError(f"materials gave {type(material).__name__} for {name!r}: it must give a glphong material")
    return material


def _load_obj(path, camera, lights, ambient, materials, allow_outside, limits):
    """An OBJ file's scene: one object per material (`read_obj`), its MTL materials."""
    mtl = _mtl_libraries(path, read_text(path, limits), allow_outside, limits)
    scene = _scene(camera, lights, ambient)
    made = {}
    for name, mesh in read_obj(path, limits):
        material = _chosen_material(materials, name, mtl.get(name))
        if material is None:
            if name not in made:
                made[name] = material_from_mtl(mtl.get(name, {}), name, str(path), limits)
            material = made[name]
        scene.add(mesh, material, name=name or path.stem)
    return _with_view(scene, camera, lights, ambient)


def _gltf_object_material(gltf, entries, materials, made, name, mesh, index):
    """The material of one glTF primitive: the user's, the stored glphong one, or `gltf_material`."""
    from .gltf_data import read_gltf_image, texture_sampling
    from .materials import TextureImage

    entry = entries[index] if index is not None else None
    material_name = entry.get("name") if entry is not None else None
    if callable(materials):
        chosen = _chosen_material(materials, material_name or name, entry)
    else:
        chosen = next((_chosen_material(materials, k, entry) for k in (material_name, name)
                       if k is not None and materials and k in materials), None)
    if chosen is not None:
        return chosen
    if entry is None:
        return _trimesh_material(None)
    textured = "baseColorTexture" in entry.get("pbrMetallicRoughness", {}) and mesh.uvs is not None
    key = (index, textured, mesh.colors is not None)
    if key not in made:
        stored = material_from_extras(entry, gltf, f"materials[{index}]")
        if stored is None:
            texture = None
            if textured:
                reference = entry["pbrMetallicRoughness"]["baseColorTexture"]["index"]
                pixels = read_gltf_image(gltf, reference)
                if pixels is not None:
                    wrap, filter_ = texture_sampling(gltf.document, reference)
                    texture = TextureImage(pixels, srgb=True, wrap=wrap, filter=filter_)
            stored = gltf_material(entry, texture, mesh.colors is not None)
        made[key] = stored
    return made[key]


def _load_gltf(path, camera, lights, ambient, materials, light_units, camera_name, allow_outside, limits):
    """A glTF file's scene: its own arrays (`glphong.gltf_data`), nodes in file order, materials from the
    user's ``materials``, else the stored glphong material (``extras``), else `gltf_material`."""
    from .gltf_data import GltfFile, read_gltf_primitives
    from .lights import AmbientLight

    gltf = GltfFile(path, limits, allow_outside)
    document = gltf.document
    file_camera, file_lights = gltf_view(document, camera_name, light_units, str(path))
    written = _glphong_extras(document)
    if lights is None and (file_lights or written):
        lights = file_lights
    if ambient is None and isinstance(written.get("ambient"), (int, float, list)):
        try:
            ambient = AmbientLight(tuple(written["ambient"]) if isinstance(written["ambient"], list) else written["ambient"])
        except (TypeError, ValueError) as exc:
            raise SceneFileError(path, f"the stored ambient light cannot be made: {exc}", "asset.extras.glphong.ambient") \
                from None
    chosen_camera = camera if camera is not None else file_camera
    scene = _scene(chosen_camera, lights, ambient)
    entries, made = document.get("materials", []), {}
    for name, mesh, world, index in read_gltf_primitives(gltf):
        scene.add(mesh, _gltf_object_material(gltf, entries, materials, made, name, mesh, index), pose=world, name=name)
    if lights is None:  # a file without lights is not drawn black by accident
        _, view_lights, view_ambient = default_view(scene)
        warnings.warn(f"{path} has no lights: glphong adds its default point light and ambient light (give "
                      "lights=[] to keep the scene dark)", stacklevel=3)
        for light in view_lights:
            scene.add_light(light)
        if ambient is None:
            scene.ambient = view_ambient
        lights = list(view_lights)
    return _with_view(scene, chosen_camera, lights, ambient)
