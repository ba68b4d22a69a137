"""pyrender as the peer glphong is measured against: a glphong `Scene` as a ``pyrender.Scene`` (`to_pyrender`),
drawn by pyrender's ``OffscreenRenderer`` (`PyrenderRenderer`), for speed and quality comparisons with a widely used
rasteriser.  pyrender is optional: it is imported only inside these functions (`import_pyrender`, which sets
``PYOPENGL_PLATFORM`` first), and ``import glphong`` never imports it (nor PyOpenGL).  A renderer is released by
`glphong.integrations.pyrender.release` (`glphong.gpu.contexts.release_offscreen`), which does not end the EGL display
the process shares.  The other way, pyrender's scenes drawn by glphong, is `glphong.integrations.pyrender`.

The pyrender conversion is approximate where the models differ (pyrender shades a
metallic-roughness microfacet BRDF, not Phong or Blinn):

- albedo: ``baseColorFactor = clip(pi kd, 0, 1)`` (a Lambertian BRDF ``kd`` is albedo / pi);
  ``metallicFactor = 0``.  pyrender's diffuse term is ``(1 - F) 0.96 rho / pi``, not ``kd``.
- glossiness: the exponent maps to pyrender's perceptual roughness by the Blinn-Beckmann
  correspondence ``alpha = sqrt(2 / (q_blinn + 2))`` and pyrender's ``alpha = roughness**2``,
  so ``roughness = (2 / (q_blinn + 2)) ** 0.25`` with ``q_blinn = q`` for `BlinnPhong` and
  ``q_blinn = 4 q`` for `Phong` (the usual Phong-to-Blinn exponent rule); see
  `pyrender_roughness`.  ``ks`` has no counterpart: pyrender's dielectric specular is
  fixed by ``F0 = 0.04``.  pyrender clamps roughness below at 0.04.
- ``ka`` (a radiance added to every pixel) becomes ``emissiveFactor = sqrt(ka)``: pyrender
  0.1.45's fragment shader multiplies the emissive factor in twice.
- point lights: ``I = Phi / (4 pi)`` (docs/design.md section 2) as ``color * intensity`` with
  ``color = Phi / max(Phi)`` and ``intensity = max(Phi) / (4 pi)``.
- directional lights: ``intensity = max(E)``, ``color = E / max(E)``, shining along the
  node's -Z axis, which the pose points along the light's direction.
- `UnattenuatedPointLight` has no pyrender equivalent (pyrender always divides by ``d^2``).
- ambient ``L_a`` becomes ``ambient_light = L_a / pi``: pyrender adds
  ``baseColor * ambient_light = pi kd * ambient_light``, glphong adds ``kd L_a``.
- ``doubleSided`` is False (pyrender's default: it culls back faces) unless ``double_sided=True``
  (every triangle drawn, as glphong's ``culling='off'``).

pyrender's output is not radiance: it is clamped to [0, 1], encoded with ``x ** (1/2.2)``
and quantised to 8 bits.  On EGL it draws into a 4x multisampled framebuffer object (the
sample count is hard-coded); on OSMesa it draws into the context's single-sampled default
framebuffer, so there is no antialiasing.
"""
import importlib
import importlib.util
import os
import sys

import numpy as np

from glphong.gpu.contexts import release_offscreen
from glphong.scene.camera import IntrinsicsCamera, OrthographicCamera
from glphong.scene.scene import Scene

__all__ = ["PyrenderRenderer", "to_pyrender", "pyrender_roughness", "pyrender_base_color", "import_pyrender",
           "pyrender_unavailable", "pyrender_encode", "pyrender_decode", "PYRENDER_PLATFORMS", "PYRENDER_SAMPLES",
           "PYRENDER_GAMMA"]

#: pyrender platforms `PyrenderRenderer` supports (values of ``PYOPENGL_PLATFORM``)
PYRENDER_PLATFORMS = ("egl", "osmesa")

#: MSAA sample count pyrender 0.1.45 hard-codes for its framebuffer-object path (EGL)
PYRENDER_SAMPLES = 4

#: the exponent of pyrender's output encoding: it writes ``clip(x, 0, 1) ** (1 / PYRENDER_GAMMA)`` in 8 bits
PYRENDER_GAMMA = 2.2


def _loaded_pyopengl_platform():
    """The platform PyOpenGL was loaded with in this process ('egl', 'osmesa', other), or None."""
    module = sys.modules.get("OpenGL.platform")
    platform = getattr(module, "PLATFORM", None)
    if platform is None:
        return None
    name = type(platform).__name__.lower()
    for known in PYRENDER_PLATFORMS:
        if name.startswith(known):
            return known
    return name.removesuffix("platform")


def _platform_conflict(platform):
    """Why pyrender cannot run on ``platform`` in this process because PyOpenGL is loaded on another one, or None."""
    loaded = _loaded_pyopengl_platform()
    if loaded is not None and loaded != platform:
        return (f"PyOpenGL (and pyrender) already use the {loaded!r} platform in this process; PYOPENGL_PLATFORM "
                f"is read once, at the first import, so pyrender on {platform!r} needs a new process")
    return None


def pyrender_unavailable(platform="egl"):
    """Why `PyrenderRenderer` cannot run on ``platform`` in this process, or None; imports nothing (importing
    pyrender would fix PyOpenGL's platform).

    Parameters
    ----------
    platform : {'egl', 'osmesa'}

    Returns
    -------
    str or None
        The reason: pyrender is not installed (or is blocked in ``sys.modules``), or PyOpenGL already runs on
        another platform here.
    """
    if platform not in PYRENDER_PLATFORMS:
        return f"pyrender runs on {', '.join(map(repr, PYRENDER_PLATFORMS))} here, not {platform!r}"
    if "pyrender" in sys.modules and sys.modules["pyrender"] is None or importlib.util.find_spec("pyrender") is None:
        return "pyrender is not installed; pip install 'glphong[pyrender]'"
    return _platform_conflict(platform)


def pyrender_encode(radiance):
    """Radiance as pyrender writes its colour: clamped to [0, 1], ``x ** (1 / 2.2)``, rounded to 8 bits.

    Parameters
    ----------
    radiance : (..., 3) array_like

    Returns
    -------
    (..., 3) uint8 ndarray
    """
    encoded = np.clip(np.asarray(radiance, dtype=np.float64), 0.0, 1.0) ** (1.0 / PYRENDER_GAMMA)
    return np.rint(encoded * 255.0).astype(np.uint8)


def pyrender_decode(rgb8):
    """pyrender's 8-bit colour back to radiance, ``(c / 255) ** 2.2`` (exposure 1; what it clamped stays clamped).

    Parameters
    ----------
    rgb8 : (..., 3) uint8 array_like

    Returns
    -------
    (..., 3) float64 ndarray
    """
    return (np.asarray(rgb8, dtype=np.float64) / 255.0) ** PYRENDER_GAMMA


def import_pyrender(platform):
    """Import pyrender on ``platform`` ('egl' or 'osmesa') and return the module.

    PyOpenGL reads ``PYOPENGL_PLATFORM`` once, when it is first imported, so this sets the
    variable before the first import.

    Raises
    ------
    ValueError
        ``platform`` is not one of `PYRENDER_PLATFORMS`.
    RuntimeError
        PyOpenGL (hence pyrender) was already imported in this process on another platform.
    ImportError
        pyrender is not installed (``pip install glphong[pyrender]``, then
        ``pip install --no-deps PyOpenGL==3.1.10``).
    """
    if platform not in PYRENDER_PLATFORMS:
        raise ValueError(f"platform must be one of {', '.join(map(repr, PYRENDER_PLATFORMS))} (got {platform!r})")
    conflict = _platform_conflict(platform)
    if conflict is not None:
        raise RuntimeError(conflict)
    os.environ["PYOPENGL_PLATFORM"] = platform
    return importlib.import_module("pyrender")


def pyrender_base_color(material):
    """pyrender base colour (an albedo, RGB) for a glphong material: the sum of ``pbr_base_color()`` over
    its non-vanishing terms that define one (Lambert: ``pi k_d``), 0 where none does."""
    values = [np.asarray(term.pbr_base_color(), dtype=np.float64) for term in material.components
              if hasattr(term, "pbr_base_color") and not term.vanishes()]
    return np.sum(values, axis=0) if values else np.zeros(3)


def pyrender_roughness(material):
    """pyrender perceptual roughness for a glphong material (a rough, documented mapping).

    The smallest ``pbr_roughness()`` of the material's non-vanishing terms that define one, 1.0
    when none does.  The lobe models define ``(2 / (q_blinn + 2)) ** 0.25`` with ``q_blinn = q``
    for the Blinn lobe and ``4 q`` for the Phong lobe.  Derivation: a Blinn lobe of exponent q
    resembles a Beckmann/GGX lobe of ``alpha = sqrt(2 / (q + 2))``, and pyrender uses
    ``alpha = roughness**2``.
    """
    values = [term.pbr_roughness() for term in material.components
              if hasattr(term, "pbr_roughness") and not term.vanishes()]
    return min(values) if values else 1.0


def _pyrender_material(pyrender, material, double_sided=False):
    ka = np.asarray(material.ka, dtype=np.float64)
    return pyrender.MetallicRoughnessMaterial(
        baseColorFactor=np.append(np.clip(pyrender_base_color(material), 0.0, 1.0), 1.0),
        metallicFactor=0.0,
        roughnessFactor=pyrender_roughness(material),
        emissiveFactor=np.sqrt(ka),  # pyrender 0.1.45 squares the emissive factor
        doubleSided=bool(double_sided),
    )


def to_pyrender(scene, samples=PYRENDER_SAMPLES, aspect_ratio=None, platform=None, double_sided=False):
    """Convert a glphong `Scene` to a ``pyrender.Scene`` (see the module notes for the mapping).

    Parameters
    ----------
    scene : glphong.Scene
    samples : int
        MSAA samples; must be 4, the count pyrender 0.1.45 hard-codes (on EGL; its OSMesa
        path draws single-sampled).  Kept so callers state what they compare against.
    aspect_ratio : float, optional
        The camera's width / height; None (default) uses the viewport's at render time.
    platform : {'egl', 'osmesa'}, optional
        Import pyrender on this platform (see `import_pyrender`); None imports it as is
        (PyOpenGL then picks its platform from the environment, GLX by default).
    double_sided : bool
        pyrender's ``doubleSided`` on every material: False (pyrender's default) culls back faces.

    Returns
    -------
    pyrender.Scene
        Background (0, 0, 0, 0); one mesh node per object, one camera node, one light node
        per light.

    Raises
    ------
    ValueError
        The scene has a light whose kind has no pyrender counterpart (`UnattenuatedPointLight`), a range or
        shadows, or ``samples`` is not 4.
    """

    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a glphong.Scene (got {type(scene).__name__})")
    if samples != PYRENDER_SAMPLES:
        raise ValueError(f"pyrender 0.1.45 always renders with {PYRENDER_SAMPLES}x MSAA (EGL) "
                         f"or none (OSMesa); samples={samples!r} cannot be honoured")
    for light in scene.lights:
        if type(light).pyrender_type is None:  # the kind's own definition says (UnattenuatedPointLight: none)
            raise ValueError(f"{light!r} has no pyrender equivalent (its kind names no pyrender light; pyrender's "
                             "point lights always fall off as 1/d^2)")
        if getattr(light, "range", None) is not None:
            raise ValueError(f"{light!r} has a range, which pyrender ignores: the images would differ")
        if light.shadows:
            raise ValueError(f"{light!r} casts shadows, which this comparison does not ask pyrender for: the images "
                             "would differ (compare the scene with shadows=False)")
    pyrender = import_pyrender(platform) if platform is not None else importlib.import_module("pyrender")
    ambient = np.zeros(3) if scene.ambient is None else np.asarray(scene.ambient.radiance) / np.pi
    out = pyrender.Scene(bg_color=np.zeros(4), ambient_light=ambient)
    for obj in scene.objects:
        primitive = pyrender.Primitive(positions=obj.mesh.positions, normals=obj.mesh.normals,
                                       indices=obj.mesh.indices,
                                       material=_pyrender_material(pyrender, obj.material, double_sided))
        out.add(pyrender.Mesh([primitive], name=obj.name), pose=obj.pose, name=obj.name)
    camera = scene.camera

    if isinstance(camera, OrthographicCamera):
        if aspect_ratio is None:
            raise ValueError("an OrthographicCamera needs aspect_ratio (its xmag is ymag * width / height)")
        out.add(pyrender.OrthographicCamera(xmag=camera.ymag * aspect_ratio, ymag=camera.ymag, znear=camera.znear,
                                            zfar=camera.zfar), pose=camera.pose)
    elif isinstance(camera, IntrinsicsCamera):  # pyrender measures the principal point from the corner
        out.add(pyrender.IntrinsicsCamera(camera.fx, camera.fy, camera.cx + 0.5, camera.cy + 0.5, znear=camera.znear,
                                          zfar=camera.zfar), pose=camera.pose)
    else:
        out.add(pyrender.PerspectiveCamera(yfov=camera.yfov, znear=camera.znear, zfar=camera.zfar,
                                           aspectRatio=aspect_ratio), pose=camera.pose)
    for light in scene.lights:
        made = light.to_pyrender(pyrender)
        if made is None:
            raise ValueError(f"{type(light).__name__} has no pyrender equivalent")
        out.add(made[0], pose=made[1])
    return out


class PyrenderRenderer:
    """pyrender's ``OffscreenRenderer`` drawing a converted glphong scene.

    Parameters
    ----------
    width, height : int
        Image size in pixels.
    platform : {'egl', 'osmesa'}
        ``PYOPENGL_PLATFORM``; set before pyrender is first imported.  Only one platform can
        be used per process.
    double_sided : bool
        Draw every triangle (pyrender's ``doubleSided``); False (default) is pyrender's default,
        which culls back faces.

    Attributes
    ----------
    samples : int
        MSAA samples pyrender actually uses: 4 on EGL, 1 on OSMesa (no framebuffer objects).

    Raises
    ------
    RuntimeError
        pyrender (PyOpenGL) was already imported with another platform.
    ImportError
        pyrender is not installed.
    """

    def __init__(self, width, height, platform="egl", double_sided=False):
        self._pyrender = import_pyrender(platform)
        self.double_sided = bool(double_sided)
        self.width = int(width)
        self.height = int(height)
        self.platform = platform
        self.samples = PYRENDER_SAMPLES if platform == "egl" else 1
        self.scene = None
        self._names = []
        os.environ["PYOPENGL_PLATFORM"] = platform  # pyrender picks its context class from it at construction
        self._renderer = self._pyrender.OffscreenRenderer(self.width, self.height)

    def prepare(self, scene):
        """Convert ``scene`` once (`to_pyrender`); returns self."""
        self.scene = to_pyrender(scene, aspect_ratio=self.width / self.height, platform=self.platform,
                                 double_sided=self.double_sided)
        self._names = [obj.name for obj in scene.objects]
        return self

    def render(self):
        """Render the prepared scene: (H, W, 3) uint8, gamma 1/2.2 encoded (`pyrender_decode` undoes it), row 0 at
        the top."""
        if self._renderer is None:
            raise RuntimeError("this PyrenderRenderer has been released")
        colour, _depth = self._renderer.render(self.scene)
        return colour

    def render_segmentation(self):
        """pyrender's way to the colour, the depth and which object each pixel sees: a colour render (its depth
        buffer read back with it) and a ``RenderFlags.SEG`` render with a colour per mesh node (pyrender issue 15's
        answer), the ids read back from the colours.

        Returns
        -------
        colour : (H, W, 3) uint8
        depth : (H, W) float32
            pyrender's depth [m] (view-axis z, 0 on the background).
        instance : (H, W) uint32
            The prepared scene's object index + 1 of the node seen, 0 the background (objects' names must be unique).
        """
        if self._renderer is None:
            raise RuntimeError("this PyrenderRenderer has been released")
        nodes = {node.name: node for node in self.scene.mesh_nodes}
        if len(nodes) != len(self._names) or set(nodes) != set(self._names):
            raise ValueError("render_segmentation needs the scene's objects to have unique names")
        colours = {nodes[name]: (index + 1, 0, 0) for index, name in enumerate(self._names)}  # ids below 256
        if len(colours) > 255:
            raise ValueError("render_segmentation encodes ids in one 8-bit channel: 255 objects at most")
        colour, depth = self._renderer.render(self.scene)
        segmentation, _ = self._renderer.render(self.scene, flags=self._pyrender.RenderFlags.SEG, seg_node_map=colours)
        return colour, depth, segmentation[..., 0].astype(np.uint32)

    def release(self):
        """Delete pyrender's renderer and its context, as `glphong.integrations.pyrender.release` does (on EGL
        without ``OffscreenRenderer.delete``, whose ``eglTerminate`` would end every EGL context of the process);
        idempotent."""
        offscreen, self._renderer = self._renderer, None
        if offscreen is not None:
            release_offscreen(offscreen)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()

    def __repr__(self):
        state = "released" if self._renderer is None else self.platform
        return f"PyrenderRenderer({self.width}x{self.height}, {state})"
