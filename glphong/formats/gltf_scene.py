"""A glTF 2.0 file as a glphong scene: its camera and ``KHR_lights_punctual`` lights (`gltf_view`), its
materials (the glphong material stored in ``extras``, `material_from_extras`, else the metallic-roughness
approximation `gltf_material`) and its primitives (`glphong.formats.gltf_data`).
"""
import warnings

import numpy as np

from glphong.core.filesafety import SceneFileError
from glphong.core.radiometry import LUMENS_PER_WATT
from glphong.formats.gltf_choices import check_one_uv_set
from glphong.formats.gltf_data import GltfFile, read_gltf_image, read_gltf_primitives, texture_sampling
from glphong.formats.gltf_nodes import node_worlds
from glphong.materials import AlphaBlend, AlphaMask, NormalMap, Texture, TextureImage, VertexColors
from glphong.materials.cook_torrance import CookTorrance
from glphong.materials.gltf_pbr import GltfPBR
from glphong.formats.gltf_material_extensions import extension_arguments, extension_texture_infos, tangent_frame_error
from glphong.definitions.fresnel import SchlickFresnel
from glphong.formats.overrides import chosen_material
from glphong.definitions.as_json import material_from_json
from glphong.scene.geometry import MeshData
from glphong.scene.camera import OrthographicCamera, PerspectiveCamera
from glphong.scene.from_trimesh import _trimesh_material, default_view, empty_scene, with_default_view
from glphong.lights import AmbientLight, registered_lights
from glphong.scene.scene import Scene

__all__ = ["read_gltf_json", "gltf_view", "gltf_material", "gltf_pbr_material", "material_from_extras", "load_gltf",
           "texture_transform", "transformed_uvs"]


def read_gltf_json(path, limits=None):
    """The validated JSON document of a ``.gltf`` file, or of a ``.glb`` file's first chunk (dict;
    `glphong.formats.gltf_data.GltfFile`).

    Raises
    ------
    glphong.filesafety.SceneFileError
        Anything wrong with the file, with its JSON path.
    """

    return GltfFile(path, limits).document


def _glphong_extras(document):
    """What glphong stored in the asset's ``extras`` (`glphong.formats.gltf_export`), or {}."""
    extras = document.get("asset", {}).get("extras", {})
    stored = extras.get("glphong") if isinstance(extras, dict) else None
    return stored if isinstance(stored, dict) else {}


def material_from_extras(entry, gltf, where=""):
    """The glphong material stored in a glTF material's ``extras: {"glphong": ...}``
    (`glphong.definitions.as_json`), or None where there is none.

    Parameters
    ----------
    entry : dict
        The JSON ``materials`` entry.
    gltf : glphong.formats.gltf_data.GltfFile
    where : str
        The entry's JSON path (for errors).

    Raises
    ------
    glphong.filesafety.SceneFileError
        A stored material that cannot be made (an unknown class, a table, a value its class refuses).
    """
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


def gltf_view(document, camera_name=None, light_units=None, source="", limits=None):
    """The camera and lights of a glTF document: ``(camera or None, [lights])``.

    The camera is the node camera named ``camera_name`` (by the camera's or its node's name) or the first
    one; ``yfov``, ``znear`` and ``zfar`` are read as written (an infinite ``zfar``: ``1e6 znear``),
    orthographic ``ymag`` too.  ``KHR_lights_punctual`` point and directional lights need ``light_units``:
    ``'photometric'`` (the glTF specification: point and spot intensity in candela, directional illuminance in
    lux; ``I = cd color / 683`` [W/sr], ``E = lux color / 683``) or ``'radiometric'`` (intensity taken as W/sr and
    W/m^2).  Each light type is read by the light kind whose ``gltf_type`` it is (`glphong.lights.LightModel.from_gltf`):
    point (with its ``range``), spot (cone angles and ``range``) and directional.  A node reached by several paths
    (`glphong.formats.gltf_nodes`) gives a light per path; a camera node, its first path's pose.  ``limits``
    (`glphong.filesafety.Limits`) bounds the paths walked.
    """

    nodes = document.get("nodes", [])
    worlds = node_worlds(document, limits)  # {node: [world per path]}
    cameras = document.get("cameras", [])
    camera = None
    for index, node in enumerate(nodes):
        if "camera" not in node or index not in worlds:
            continue
        spec = cameras[node["camera"]]
        if camera_name is not None and camera_name not in (spec.get("name"), node.get("name")):
            continue
        pose = worlds[index][0].copy()
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
        kind = _GLTF_KINDS.get(light.get("type"))
        if light_units is None:  # a file may declare them (glphong.formats.gltf_export writes radiometric lights)
            light_units = _glphong_extras(document).get("light_units")
        if light_units not in ("photometric", "radiometric"):
            raise ValueError(f"{source} has KHR_lights_punctual lights: say what their intensities are with "
                             "light_units='photometric' (candela and lux, as the glTF specification says) or "
                             "'radiometric' (W/sr and W/m^2)")
        scale = (1.0 / LUMENS_PER_WATT if light_units == "photometric" else 1.0) * light.get("intensity", 1.0)
        colour = np.asarray(light.get("color", (1.0, 1.0, 1.0)), dtype=np.float64) * scale
        if kind is None:
            raise ValueError(f"{source}: light type {light.get('type')!r} is not one glphong knows "
                             f"({', '.join(sorted(_GLTF_KINDS))})")
        for world in worlds[index]:
            pose = world.copy()
            pose[:3, :3] /= np.linalg.norm(pose[:3, :3], axis=0)  # a light node's scale does not apply
            try:
                lights.append(kind.from_gltf(colour, light, pose))
            except (TypeError, ValueError) as exc:
                raise ValueError(f"{source}: light {light.get('name', reference['light'])!r}: {exc}") from None
    return camera, lights


#: KHR_lights_punctual type -> the light kind that reads it
_GLTF_KINDS = {kind.gltf_type: kind for kind in registered_lights() if kind.gltf_type}


def gltf_material(entry, base_color_texture=None, vertex_colors=False):
    """The Cook-Torrance approximation of a glTF metallic-roughness material (JSON ``materials`` entry), which
    ``load_scene(..., materials='cook_torrance')`` still gives (the default is `gltf_pbr_material`, the
    specification's own BRDF): Cook-Torrance with Beckmann slope ``m = roughness^2`` (glTF's GGX ``alpha``, at least
    1e-3), diffuse albedo ``baseColor (1 - metallic)`` and Schlick's Fresnel with ``f0 = 0.04 (1 - metallic) +
    baseColorFactor metallic``.  The lobes differ (Beckmann against GGX, no coupling of diffuse and specular).

    ``baseColor`` is ``baseColorFactor`` times the base-colour texture (``base_color_texture``, an image
    array, sRGB, or a `glphong.materials.TextureImage`) times the mesh's ``COLOR_0`` (``vertex_colors``), as glTF defines it; the texture and the
    colours vary the diffuse albedo only (no other texture is read)."""

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


def gltf_pbr_material(entry, texture=None, vertex_colors=False, emissive_scale=1.0):
    """A glTF metallic-roughness material (JSON ``materials`` entry) as `glphong.GltfPBR`, the specification's
    Appendix B, with its textures (docs/scenes_from_files.md):

    - ``base_color = baseColorFactor.rgb * baseColorTexture (sRGB) * COLOR_0``;
    - ``metallic = metallicFactor * metallicRoughnessTexture.b``, ``roughness = roughnessFactor *
      metallicRoughnessTexture.g`` (linear; factors above 1 clamped to 1);
    - ``emissive = emissiveFactor * KHR_materials_emissive_strength * emissiveTexture (sRGB) * emissive_scale``;
    - ``occlusion = 1 + strength (occlusionTexture.r - 1)`` (linear), on the ambient and environment answers only;
    - ``normalTexture`` (linear) as a `glphong.NormalMap` with its ``scale`` (the mesh's ``TANGENT``, or tangents
      derived from its UVs);
    - ``doubleSided`` as ``two_sided``;
    - ``KHR_materials_ior``'s ``ior`` (the dielectric's ``f0``);
    - ``alphaMode``: OPAQUE; MASK as a `glphong.AlphaMask` of ``alphaCutoff`` and ``baseColorFactor.a`` times the
      base-colour texture's alpha (COLOR_0's alpha is not read: a warning says so); BLEND as a `glphong.AlphaBlend` of
      the same alpha (composited per pixel in depth order, docs/design.md section 16).

    Parameters
    ----------
    entry : dict
        The validated JSON entry.
    texture : callable, optional
        ``texture(info, srgb, alpha=False)``: the `glphong.materials.TextureImage` of a ``textureInfo`` object (of its
        alpha channel with ``alpha``), or None where it cannot be read (the texture is then left out); default: no
        texture is read.
    vertex_colors : bool
        The mesh has ``COLOR_0``.
    emissive_scale : float
        Converts the file's emissive values to radiance [W/(m^2 sr)]: 1/683 where the file's lights are read as
        photometric (glphong's luminous efficacy, as for the lights), 1 otherwise.

    Returns
    -------
    glphong.GltfPBR
    """
    texture = texture or (lambda info, srgb, alpha=False: None)
    pbr = entry.get("pbrMetallicRoughness", {})

    def image(info_key, srgb, holder=None):
        holder = entry if holder is None else holder
        return texture(holder[info_key], srgb) if info_key in holder else None

    base = tuple(np.clip(np.asarray(pbr.get("baseColorFactor", (1.0, 1.0, 1.0, 1.0))[:3], np.float64), 0.0, 1.0))
    base_image = image("baseColorTexture", True, pbr)
    base_color = Texture(base_image, scale=base, vertex_colors=vertex_colors) if base_image is not None else \
        VertexColors(scale=base) if vertex_colors else base
    metallic = min(float(pbr.get("metallicFactor", 1.0)), 1.0)
    roughness = min(float(pbr.get("roughnessFactor", 1.0)), 1.0)
    mr_image = image("metallicRoughnessTexture", False, pbr)
    if mr_image is not None:
        metallic = Texture(mr_image, scale=metallic, channel="b")
        roughness = Texture(mr_image, scale=roughness, channel="g")
    strength = entry.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
    emissive = tuple(np.asarray(entry.get("emissiveFactor", (0.0, 0.0, 0.0)), np.float64) * strength * emissive_scale)
    emissive_image = image("emissiveTexture", True) if any(emissive) else None
    emissive = Texture(emissive_image, scale=emissive) if emissive_image is not None else emissive
    occlusion = 1.0
    occlusion_image = image("occlusionTexture", False)
    if occlusion_image is not None:
        weight = float(entry["occlusionTexture"].get("strength", 1.0))
        if weight != 1.0:  # 1 + s (R - 1), filtered linearly as R is: a float texture of its values
            red = occlusion_image.levels[0][::-1, :, 0].astype(np.float64)
            occlusion_image = TextureImage(np.repeat((1.0 - weight + weight * red)[..., None], 3, axis=2),
                                           wrap=occlusion_image.wrap, filter=occlusion_image.filter)
        occlusion = Texture(occlusion_image, channel="r")
    alpha_mask = alpha_blend = None
    mode = entry.get("alphaMode", "OPAQUE")
    if mode in ("MASK", "BLEND"):
        factor = float(np.clip(pbr.get("baseColorFactor", (1.0, 1.0, 1.0, 1.0))[3], 0.0, 1.0))
        info = pbr.get("baseColorTexture")
        alpha = texture(info, False, True) if info is not None else None
        alpha = Texture(alpha, factor, channel="r") if alpha is not None else factor
        if mode == "MASK":
            alpha_mask = AlphaMask(float(entry.get("alphaCutoff", 0.5)), alpha)
        else:
            alpha_blend = AlphaBlend(alpha)
        if vertex_colors:
            warnings.warn(f"COLOR_0's alpha is not read: the alpha {'mask' if mode == 'MASK' else 'blend'} is the base "
                          "colour's", stacklevel=3)
    normal_image = image("normalTexture", False)
    normal_map = NormalMap(normal_image, float(entry["normalTexture"].get("scale", 1.0))) \
        if normal_image is not None else None
    ior = entry.get("extensions", {}).get("KHR_materials_ior", {}).get("ior", 1.5)
    if not 1.0 <= ior <= 1e4:  # validated >= 0; 0 (a "perfect reflector" in some exporters) is not a dielectric
        warnings.warn(f"KHR_materials_ior {ior!r}: glphong takes an ior in [1, 1e4]; 1.5 is used", stacklevel=3)
        ior = 1.5
    extensions = extension_arguments(entry, texture, lambda message: warnings.warn(message, stacklevel=4))
    return GltfPBR(base_color, metallic, roughness, emissive=emissive, occlusion=occlusion, ior=float(ior), **extensions,
                   two_sided=bool(entry.get("doubleSided", False)), normal_map=normal_map, alpha_mask=alpha_mask,
                   alpha_blend=alpha_blend)


def _texture_reader(gltf, where):
    """``texture(info, srgb, alpha=False)`` for `gltf_pbr_material`: the `TextureImage` of a ``textureInfo`` of ``gltf``
    (of its alpha channel alone, as grey, with ``alpha``), or None
    (with a warning once per file) where it names no image glphong decodes.  The mesh carries the texture coordinate
    set the material's textures read (`glphong.formats.gltf_choices.material_uv_set`)."""

    def texture(info, srgb, alpha=False):
        pixels = read_gltf_image(gltf, info["index"])
        if pixels is None:
            return None
        wrap, filter_ = texture_sampling(gltf.document, info["index"])
        return TextureImage(pixels[..., 3] if alpha else pixels, srgb=srgb, wrap=wrap, filter=filter_)

    return texture


def texture_transform(entry, gltf=None, where=""):
    """The ``KHR_texture_transform`` of a glTF material's textures as one 3x3 matrix in glTF's uv space (``T R S``:
    offset, rotation by ``-rotation`` about the origin, scale, as the extension defines it), or None.

    glphong's textures share the mesh's coordinates, so the transform is applied to them (`transformed_uvs`): where
    the material's textures carry different transforms, none is applied and a
    warning says so (``gltf``: the file that warns once).

    Raises
    ------
    glphong.filesafety.SceneFileError
        A transform whose offset, rotation or scale is not finite numbers (with ``gltf``).
    """
    pbr = entry.get("pbrMetallicRoughness", {})
    infos = [holder[key] for holder, key in ((pbr, "baseColorTexture"), (pbr, "metallicRoughnessTexture"),
                                             (entry, "normalTexture"), (entry, "occlusionTexture"),
                                             (entry, "emissiveTexture")) if isinstance(holder.get(key), dict)]
    infos += extension_texture_infos(entry)  # KHR_materials_specular's and _clearcoat's (gltf_material_extensions)
    transforms = [info.get("extensions", {}).get("KHR_texture_transform") for info in infos]
    if not any(t is not None for t in transforms):
        return None
    matrices = []
    for t in transforms:
        t = {} if t is None else t
        try:
            if not isinstance(t, dict):
                raise TypeError
            ox, oy = (float(x) for x in t.get("offset", (0.0, 0.0)))
            sx, sy = (float(x) for x in t.get("scale", (1.0, 1.0)))
            r = float(t.get("rotation", 0.0))
            values = np.array([ox, oy, sx, sy, r])
            if not np.all(np.isfinite(values)) or isinstance(t.get("texCoord", 0), bool):
                raise ValueError
        except (TypeError, ValueError):
            if gltf is None:
                raise ValueError(f"{where}: KHR_texture_transform needs finite numbers") from None
            raise SceneFileError(gltf.path, "KHR_texture_transform needs a finite offset [2], scale [2] and rotation",
                                 f"{where}.extensions.KHR_texture_transform") from None
        c, s = np.cos(r), np.sin(r)
        matrices.append(np.array([[1, 0, ox], [0, 1, oy], [0, 0, 1.0]]) @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1.0]])
                        @ np.diag([sx, sy, 1.0]))
    if matrices is None or any(not np.array_equal(m, matrices[0]) for m in matrices[1:]):
        if gltf is not None:
            gltf.warn_once(("KHR_texture_transform", where), f"{where}: its textures carry different "
                           "KHR_texture_transforms: none is applied")
        return None
    return matrices[0]


def transformed_uvs(mesh, matrix):
    """``mesh`` with its uvs moved by a `texture_transform` matrix (glTF's uv space, v down: glphong's v is ``1 - v``);
    the tangents derived from the new uvs where the mesh has none of its own."""
    if matrix is None or mesh.uvs is None:
        return mesh
    uv = np.stack([mesh.uvs[:, 0], 1.0 - mesh.uvs[:, 1], np.ones(len(mesh.uvs))], axis=1).astype(np.float64)
    moved = uv @ matrix.T
    uvs = np.stack([moved[:, 0], 1.0 - moved[:, 1]], axis=1)
    return MeshData(mesh.positions, mesh.normals, mesh.indices, uvs=uvs, tangents=mesh.given_tangents, colors=mesh.colors)


def _gltf_object_material(gltf, entries, materials, made, name, mesh, index, emissive_scale):
    """``(material, uv transform)`` of one glTF primitive: the user's, the stored glphong one, or `gltf_pbr_material`
    (`gltf_material` where ``materials='cook_torrance'``); the transform (`texture_transform`, read once per
    material) is that of a material made from the file's own entry, whose textures it moves, else None."""

    entry = entries[index] if index is not None else None
    material_name = entry.get("name") if entry is not None else None
    approximate = isinstance(materials, str)
    if approximate and materials != "cook_torrance":
        raise ValueError(f"materials={materials!r}: the one name load_scene takes is 'cook_torrance' (glTF's "
                         "metallic-roughness read as the earlier Cook-Torrance approximation)")
    if approximate:
        chosen = None
    elif callable(materials):
        chosen = chosen_material(materials, material_name or name, entry)
    else:
        chosen = next((chosen_material(materials, k, entry) for k in (material_name, name)
                       if k is not None and materials and k in materials), None)
    if chosen is not None:
        return chosen, None
    if entry is None:
        return _trimesh_material(None), None
    key = (index, mesh.uvs is not None, mesh.colors is not None)
    if key not in made:
        stored, transform = material_from_extras(entry, gltf, f"materials[{index}]"), None
        if stored is None:
            where = f"materials[{index}]"
            check_one_uv_set(gltf.path, entry, where)
            texture = _texture_reader(gltf, where) if mesh.uvs is not None else None
            if approximate:
                info = entry.get("pbrMetallicRoughness", {}).get("baseColorTexture")
                stored = gltf_material(entry, texture(info, True) if texture and info else None, mesh.colors is not None)
            else:
                stored = gltf_pbr_material(entry, texture, mesh.colors is not None, emissive_scale)
            transform = texture_transform(entry, gltf, where)
        made[key] = stored, transform
    return made[key]


def load_gltf(path, camera, lights, ambient, materials, light_units, camera_name, allow_outside, limits, variant=None):
    """A glTF file's scene: its own arrays (`glphong.formats.gltf_data`), nodes in file order, materials from the
    user's ``materials``, else the stored glphong material (``extras``), else `gltf_pbr_material` (`gltf_material`
    with ``materials='cook_torrance'``)."""

    gltf = GltfFile(path, limits, allow_outside)
    document = gltf.document
    file_camera, file_lights = gltf_view(document, camera_name, light_units, str(path), limits)
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
    scene = empty_scene(Scene, chosen_camera, lights, ambient)
    entries, made = document.get("materials", []), {}
    emissive_scale = 1.0 / LUMENS_PER_WATT if light_units == "photometric" else 1.0
    for name, mesh, world, index in read_gltf_primitives(gltf, variant):
        material, transform = _gltf_object_material(gltf, entries, materials, made, name, mesh, index, emissive_scale)
        try:
            scene.add(transformed_uvs(mesh, transform), material, pose=world, name=name)
        except ValueError as exc:  # the scene's check of what the mesh serves: an extension's tangent frame, named
            raise tangent_frame_error(gltf.path, exc, material, mesh, name, index) from None
    if lights is None:  # a file without lights is not drawn black by accident
        _, view_lights, view_ambient = default_view(scene, path)
        warnings.warn(f"{path} has no lights: glphong adds its default point light and ambient light (give "
                      "lights=[] to keep the scene dark)", stacklevel=3)
        for light in view_lights:
            scene.add_light(light)
        if ambient is None:
            scene.ambient = view_ambient
        lights = list(view_lights)
    return with_default_view(scene, chosen_camera, lights, ambient, path)
