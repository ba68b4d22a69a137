"""What a pyrender scene holds, in glphong's terms: its lights (`glphong_lights_of`, with the shadows pyrender's
render flags ask for), its camera (`glphong_camera_of`) and its `GlphongMaterial` meshes (`scene_from_pyrender`).

Units (docs/design.md section 2): a pyrender light's ``color * intensity`` is read one to one as W/sr (point and
spot: ``Phi = 4 pi I`` for a point light) or W/m^2 (directional), as pyrender's shader uses it (no 683);
``scene.ambient_light`` is ``L_a``.
"""
import numpy as np
import pyrender
from pyrender.constants import RenderFlags

from glphong.lights import AmbientLight, registered_lights
from glphong.scene.camera import IntrinsicsCamera, OrthographicCamera, PerspectiveCamera
from glphong.scene.geometry import MeshData
from glphong.scene.scene import Scene

from glphong.integrations.pyrender.materials import GlphongMaterial

__all__ = ["glphong_lights_of", "glphong_camera_of", "scene_from_pyrender", "triangles", "SHADOW_FLAGS",
           "with_shadows"]

#: the render flag that asks for each pyrender light class's shadows
SHADOW_FLAGS = {"DirectionalLight": RenderFlags.SHADOWS_DIRECTIONAL, "SpotLight": RenderFlags.SHADOWS_SPOT,
                "PointLight": RenderFlags.SHADOWS_POINT}


def with_shadows(light):
    """The same glphong light with ``shadows=True``."""
    return type(light)(**{**light.parameter_values(), "shadows": True})


def glphong_lights_of(scene, flags=RenderFlags.NONE):
    """The glphong lights of a pyrender scene (SI units of docs/design.md section 2).

    Parameters
    ----------
    scene : pyrender.Scene
    flags : int
        pyrender's ``RenderFlags``: a light whose class ``SHADOWS_DIRECTIONAL``, ``SHADOWS_SPOT`` or
        ``SHADOWS_POINT`` names gets ``shadows=True`` (glphong's shadow maps, docs/design.md section 12).

    Returns
    -------
    lights : list of glphong lights
    ambient : glphong.AmbientLight or None
    """
    kinds = {kind.pyrender_type: kind for kind in registered_lights() if kind.pyrender_type}
    out = []
    for node in scene.light_nodes:
        light, pose = node.light, scene.get_pose(node)
        value = np.asarray(light.color, dtype=np.float64) * float(light.intensity)
        kind = kinds.get(type(light).__name__)
        if kind is None:
            raise ValueError(f"pyrender light {node.name or ''!r} is a {type(light).__name__}, which no glphong light "
                             f"kind maps (mapped: {', '.join(sorted(kinds))})")
        mapped = kind.from_pyrender(value, light, pose)
        if flags & SHADOW_FLAGS.get(type(light).__name__, 0):
            mapped = with_shadows(mapped)
        out.append(mapped)
    ambient = np.asarray(scene.ambient_light, dtype=np.float64)
    return out, (AmbientLight(ambient) if np.any(ambient > 0) else None)


def glphong_camera_of(scene, viewport=None):
    """The glphong camera of a pyrender scene's main camera.

    Parameters
    ----------
    scene : pyrender.Scene
    viewport : (int, int), optional
        ``(width, height)`` of the image [px]: needed for an ``IntrinsicsCamera`` (its intrinsics belong to an image
        size).

    Returns
    -------
    glphong.PerspectiveCamera, glphong.OrthographicCamera or glphong.IntrinsicsCamera
        ``PerspectiveCamera(yfov)``; ``OrthographicCamera(ymag)`` (glphong's half width is ``ymag width / height``,
        pyrender's ``xmag``); ``IntrinsicsCamera(fx, fy, cx - 1/2, cy - 1/2,
        width, height)`` (pyrender measures the principal point from the image's corner, glphong from the first
        pixel's centre, as OpenCV does).  The same pose, ``znear`` and ``zfar`` (pyrender's infinite far plane
        as 1e6 m).
    """
    node = scene.main_camera_node
    if node is None:
        raise ValueError("the pyrender scene has no camera (pyrender needs one too: scene.add(pyrender.PerspectiveCamera(...)))")
    camera, pose = node.camera, scene.get_pose(node)
    zfar = camera.zfar if camera.zfar is not None else 1e6
    if isinstance(camera, pyrender.IntrinsicsCamera):
        if viewport is None:
            raise ValueError("a pyrender.IntrinsicsCamera belongs to an image size: give viewport=(width, height)")
        return IntrinsicsCamera(camera.fx, camera.fy, camera.cx - 0.5, camera.cy - 0.5, *viewport, pose=pose,
                                znear=camera.znear, zfar=zfar)
    if isinstance(camera, pyrender.OrthographicCamera):
        return OrthographicCamera(camera.ymag, pose=pose, znear=camera.znear, zfar=zfar)
    if isinstance(camera, pyrender.PerspectiveCamera):
        return PerspectiveCamera(camera.yfov, pose=pose, znear=camera.znear, zfar=zfar)
    raise ValueError(f"glphong maps pyrender's PerspectiveCamera, OrthographicCamera and IntrinsicsCamera (got "
                     f"{type(camera).__name__})")


def scene_from_pyrender(scene, convert=False, flags=RenderFlags.NONE, viewport=None):
    """The glphong `Scene` of a pyrender scene's `GlphongMaterial` meshes, camera and lights.

    For rendering the same scene with `glphong.Renderer` (comparison, verification).

    Parameters
    ----------
    scene : pyrender.Scene
    convert : bool
        Take the meshes with a ``pyrender.MetallicRoughnessMaterial`` too, as `gltf_pbr_of` converts them (a mesh
        from a glTF file or a trimesh with a PBR material).
    flags : int
        pyrender's ``RenderFlags``; its shadow flags give the lights they name ``shadows=True``
        (`glphong_lights_of`).
    viewport : (int, int), optional
        ``(width, height)``: for an ``IntrinsicsCamera`` (`glphong_camera_of`), and to check that an
        ``OrthographicCamera``'s ``xmag`` is ``ymag width / height``, as glphong's is.
    """
    lights, ambient = glphong_lights_of(scene, flags)
    camera = scene.main_camera_node.camera if scene.main_camera_node is not None else None
    if isinstance(camera, pyrender.OrthographicCamera) and viewport is not None and \
            not np.isclose(camera.xmag, camera.ymag * viewport[0] / viewport[1], rtol=1e-6):
        raise ValueError(f"glphong's OrthographicCamera has a half width of ymag width / height = "
                         f"{camera.ymag * viewport[0] / viewport[1]:.6g} at {viewport[0]}x{viewport[1]} (this pyrender "
                         f"camera has xmag {camera.xmag:.6g}, ymag {camera.ymag:.6g}): give it that xmag")
    out = Scene(glphong_camera_of(scene, viewport), lights=lights, ambient=ambient)
    for node in scene.mesh_nodes:
        if not node.mesh.is_visible:
            continue
        for primitive in node.mesh.primitives:
            material = primitive.material
            if convert and isinstance(material, pyrender.MetallicRoughnessMaterial) and primitive.normals is not None:
                material = GlphongMaterial.from_pyrender(material, vertex_colors=primitive.color_0 is not None)
            if isinstance(material, GlphongMaterial):
                colors = None if primitive.color_0 is None else np.asarray(primitive.color_0, dtype=np.float64)[:, :3]
                data = MeshData(primitive.positions, primitive.normals, triangles(primitive), uvs=primitive.texcoord_0,
                                tangents=primitive.tangents, colors=colors)
                out.add(data, material.glphong, pose=scene.get_pose(node), name=node.name)
    return out


def triangles(primitive):
    """A triangle primitive's (F, 3) vertex indices: its own (pyrender keeps them as float32, exact below 2^24
    vertices), or consecutive triples where it has none (``Mesh.from_trimesh(..., smooth=False)``: every triangle's
    own three vertices)."""
    if primitive.mode != pyrender.constants.GLTF.TRIANGLES:
        raise ValueError(f"glphong draws triangles; this primitive's mode is {primitive.mode} (points or lines: "
                         "pyrender.Mesh.from_points has no surface to shade)")
    if primitive.indices is None:
        count = len(primitive.positions)
        if count % 3:
            raise ValueError(f"a non-indexed triangle primitive needs a multiple of 3 vertices (got {count})")
        return np.arange(count, dtype=np.int64).reshape(-1, 3)
    return np.rint(np.asarray(primitive.indices, dtype=np.float64)).astype(np.int64).reshape(-1, 3)
