"""PyVista (VTK) and Open3D (Filament) as peers of the speed family (``benchmarks/peers.py``, docs/speed.md).

People who script offscreen renders also pick PyVista's ``Plotter(off_screen=True)`` (VTK, EGL or OSMesa) and
Open3D's ``OffscreenRenderer`` (Filament, EGL).  `PyVistaRenderer` and `Open3DRenderer` draw a glphong `Scene` with
settings matched to glphong's: the same triangles (vertex positions, normals and indices, posed), the same camera
(its pose and vertical field of view, near and far planes), the same size, one light per glphong point light at its
position, and the image read back to a numpy array; at the peer's defaults (PyVista's anti-aliasing as its theme
sets it: 4x MSAA on llvmpipe; Open3D's post-processing on) or single-sampled (``anti_aliasing=False``,
``post_processing=False``).  Materials become each peer's own lit material with the diffuse colour of their albedo
clipped to [0, 1], as for pyrender (the shading differs: these are speed peers, not reference images).

Both are optional (the extra ``bench``): imported only inside these classes, with an ImportError naming the extra;
each is meant to run in a process of its own with glphong (their GL contexts live beside glphong's there). Making a
PyVista plotter on EGL (VTK 9.7) terminates the device's shared EGL display, as pyrender's ``delete()`` does;
glphong's contexts live on a display of their own where the driver allows it (`glphong.gpu.egl_devices`), and
otherwise raise ``EGLDisplayTerminatedError``: there, prepare the peers first, then make glphong's renderers.
Open3D 0.20 renders through Vulkan only, which Mesa's llvmpipe lacks: use 0.19 (EGL) there.
"""
import numpy as np

from glphong.bench.pyrender_peer import pyrender_base_color
from glphong.lights import PointLight
from glphong.scene.camera import PerspectiveCamera

__all__ = ["PyVistaRenderer", "Open3DRenderer", "diffuse_colour", "posed_triangles"]


def _require(module, peer):
    try:
        return __import__(module)
    except ImportError as exc:
        raise ImportError(f"the {peer} peer needs {module} (pip install 'glphong[bench]'): {exc}") from None


def diffuse_colour(material):
    """The peer's diffuse colour of a glphong material: its albedo as its terms' definitions give it
    (`glphong.bench.pyrender_peer.pyrender_base_color`: Lambert ``pi k_d``), clipped to [0, 1], RGB floats."""
    return tuple(float(c) for c in np.clip(pyrender_base_color(material), 0.0, 1.0))


def posed_triangles(obj):
    """An object's mesh in world coordinates: ``(positions (N, 3) float64, normals (N, 3) float64, faces (F, 3)
    int64)``, the pose applied (normals by its normal matrix, renormalised)."""
    mesh, pose = obj.mesh, np.asarray(obj.pose, np.float64)
    positions = mesh.positions.astype(np.float64) @ pose[:3, :3].T + pose[:3, 3]
    normals = mesh.normals.astype(np.float64) @ np.asarray(obj.normal_matrix, np.float64).T
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    return positions, normals, mesh.indices.astype(np.int64).reshape(-1, 3)


def _camera(scene):
    camera = scene.camera
    if not isinstance(camera, PerspectiveCamera):
        raise ValueError(f"the peers take a PerspectiveCamera (got {type(camera).__name__})")
    eye = camera.pose[:3, 3]
    return eye, eye - camera.pose[:3, 2], camera.pose[:3, 1], float(np.degrees(camera.yfov))


def _point_lights(scene):
    lights = [light for light in scene.lights if isinstance(light, PointLight)]
    if len(lights) != len(scene.lights):
        raise ValueError("the peers take point lights only")
    return lights


class PyVistaRenderer:
    """A glphong scene drawn by PyVista's off-screen ``Plotter`` (VTK; EGL where VTK was built with it).

    Parameters
    ----------
    width, height : int
    anti_aliasing : bool
        True: the plotter's default (its theme asks for 8x MSAA; on llvmpipe the render window holds 4 samples,
        ``GetMultiSamples()``); False: ``disable_anti_aliasing()``, one sample a pixel.
    """

    def __init__(self, width, height, anti_aliasing=True):
        self.size = (int(width), int(height))
        self.anti_aliasing = bool(anti_aliasing)
        self.plotter = None

    def prepare(self, scene):
        """Build the plotter for ``scene`` (meshes, camera, lights); returns self."""
        pv = _require("pyvista", "PyVista")
        plotter = pv.Plotter(off_screen=True, window_size=self.size, lighting="none")
        if not self.anti_aliasing:
            plotter.disable_anti_aliasing()
        for obj in scene.objects:
            positions, normals, faces = posed_triangles(obj)
            cells = np.hstack([np.full((len(faces), 1), 3, np.int64), faces]).reshape(-1)
            mesh = pv.PolyData(positions, cells)
            mesh.point_data["Normals"] = normals
            mesh.point_data.active_normals_name = "Normals"
            plotter.add_mesh(mesh, color=diffuse_colour(obj.material), smooth_shading=True)
        eye, target, up, yfov = _camera(scene)
        plotter.camera.position, plotter.camera.focal_point, plotter.camera.up = tuple(eye), tuple(target), tuple(up)
        plotter.camera.view_angle = yfov
        plotter.camera.clipping_range = (scene.camera.znear, scene.camera.zfar)
        for light in _point_lights(scene):
            plotter.add_light(pv.Light(position=tuple(light.position), positional=True, cone_angle=180.0,
                                       light_type="scene light"))
        plotter.set_background("black")
        plotter.show(auto_close=False)  # sets the window up (off screen) and renders once
        self.plotter = plotter
        return self

    def render(self):
        """Draw (``Plotter.render``: VTK renders the window again) and read back: (H, W, 3) uint8."""
        self.plotter.render()
        return np.asarray(self.plotter.image)

    def release(self):
        if self.plotter is not None:
            self.plotter.close()
            self.plotter = None


#: Open3D's renderers, one per size for the process: a second ``OffscreenRenderer`` alive beside another aborts the
#: process when either is destroyed (Open3D 0.19: "Trying to destroy nonexistent resource"), so they are kept
_OPEN3D = {}
#: how many point lights the size's Open3D renderer holds (removed by the next `Open3DRenderer.prepare`)
_OPEN3D_LIGHTS = {}


class Open3DRenderer:
    """A glphong scene drawn by Open3D's ``OffscreenRenderer`` (Filament; EGL in 0.18 and 0.19).

    Open3D keeps one renderer per size in the process (`_OPEN3D`): `prepare` loads the scene into it (what the last
    `prepare` of that size loaded is what `render` draws), and `render` sets this instance's post-processing.

    Parameters
    ----------
    width, height : int
    post_processing : bool
        True: Open3D's default (Filament's post-processing: tone mapping, anti-aliasing); False:
        ``view.set_post_processing(False)``.
    """

    def __init__(self, width, height, post_processing=True):
        self.size = (int(width), int(height))
        self.post_processing = bool(post_processing)
        self.renderer = None

    def prepare(self, scene):
        """Load ``scene`` (meshes, camera, lights) into the size's renderer; returns self."""
        o3d = _require("open3d", "Open3D")
        rendering = o3d.visualization.rendering
        lights = _point_lights(scene)
        renderer = _OPEN3D.get(self.size)
        if renderer is None:
            renderer = _OPEN3D[self.size] = rendering.OffscreenRenderer(*self.size)
        renderer.scene.clear_geometry()
        renderer.scene.set_background([0.0, 0.0, 0.0, 1.0])
        for i, obj in enumerate(scene.objects):
            positions, normals, faces = posed_triangles(obj)
            mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(positions),
                                             o3d.utility.Vector3iVector(faces.astype(np.int32)))
            mesh.vertex_normals = o3d.utility.Vector3dVector(normals)
            material = rendering.MaterialRecord()
            material.shader = "defaultLit"
            material.base_color = [*diffuse_colour(obj.material), 1.0]
            renderer.scene.add_geometry(f"object{i}", mesh, material)
        renderer.scene.scene.enable_sun_light(False)
        for j in range(_OPEN3D_LIGHTS.get(self.size, 0)):
            renderer.scene.scene.remove_light(f"light{j}")
        for j, light in enumerate(lights):
            renderer.scene.scene.add_point_light(f"light{j}", [1.0, 1.0, 1.0], np.asarray(light.position, np.float32),
                                                 1e5, 1e3, False)
        _OPEN3D_LIGHTS[self.size] = len(lights)
        eye, target, up, yfov = _camera(scene)
        renderer.scene.camera.set_projection(yfov, self.size[0] / self.size[1], scene.camera.znear, scene.camera.zfar,
                                             rendering.Camera.FovType.Vertical)
        renderer.scene.camera.look_at(target, eye, up)
        self.renderer = renderer
        return self

    def render(self):
        """Draw (with this instance's post-processing) and read back: (H, W, 3) uint8."""
        self.renderer.scene.view.set_post_processing(self.post_processing)
        return np.asarray(self.renderer.render_to_image())

    def release(self):
        self.renderer = None  # the size's renderer lives on (`_OPEN3D`)
