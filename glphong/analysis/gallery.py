"""The model gallery: one sphere per reflectance model under the same lights (``glphong gallery``).

A companion to the default figure: every built-in model of the lecture and docs/design.md section 9 at
representative parameters, the same albedo colour for the diffuse parts, one key light (a point light
up and to the left, 2.5 W/m^2 at the sphere), a rim light from behind-right grazing the silhouette (where
Fresnel factors brighten and Oren-Nayar flattens), and a faint ambient light.  The spheres carry analytic
tangents (``glphong.primitives.sphere``: the tangent runs along the azimuth about the vertical axis),
so the anisotropic models stretch their highlights around the sphere.

`GALLERY` lists ``(label, factory)`` pairs; a model that is not defined in this installation is
skipped.  `render_gallery` returns the mosaic and, with ``verify=True``, one cross-check report per tile.
"""
import functools
from dataclasses import dataclass

import numpy as np
from glphong import materials
from glphong.checks.verify import verify as verify_scene
from glphong.core.imaging import encode_srgb8
from glphong.analysis.tabulate import tabulate
from glphong.scene import primitives
from glphong.scene.camera import PerspectiveCamera
from glphong.lights import AmbientLight, DirectionalLight, PointLight
from glphong.scene.scene import Scene

__all__ = ["GALLERY", "Gallery", "gallery_scene", "render_gallery"]

#: the diffuse albedo every entry shares (a warm terracotta), and its Lambert/Phong kd
ALBEDO = (0.60, 0.28, 0.16)
KD = tuple(a / np.pi for a in ALBEDO)


def _m(name):
    return getattr(materials, name)


#: (label, factory) per tile, in reading order
GALLERY = (
    ("Lambert", lambda: _m("Lambert")(KD)),
    ("Phong q=60", lambda: _m("Phong")(KD, 0.25, 60.0)),
    ("Blinn-Phong q=240", lambda: _m("BlinnPhong")(KD, 0.25, 240.0)),
    ("Phong + Schlick 0.04", lambda: _m("Phong")(KD, 2.0, 60.0, fresnel=_m("SchlickFresnel")(0.04))),
    ("Normalized Phong", lambda: _m("NormalizedPhong")(ALBEDO, 0.3, 60.0)),
    ("Normalized Blinn-Phong", lambda: _m("NormalizedBlinnPhong")(ALBEDO, 0.3, 240.0)),
    ("Cook-Torrance m=0.25", lambda: _m("CookTorrance")(ALBEDO, 0.25)),
    ("Cook-Torrance 1982", lambda: _m("CookTorrance")(ALBEDO, 0.25, form="1982")),
    ("Cook-Torrance dielectric", lambda: _m("CookTorrance")(ALBEDO, 0.15, fresnel=_m("DielectricFresnel")(1.5))),
    ("glTF dielectric roughness 0.4", lambda: _m("GltfPBR")(ALBEDO, 0.0, 0.4)),
    ("glTF metal roughness 0.3", lambda: _m("GltfPBR")((0.95, 0.64, 0.54), 1.0, 0.3)),
    ("Lafortune off-specular", lambda: _m("Lafortune")(ALBEDO, [(2.5, -1.0, -1.0, 0.8, 30.0)])),
    ("Lafortune retro-reflective", lambda: _m("Lafortune")(ALBEDO, [(0.5, 1.0, 1.0, 1.0, 6.0)])),
    ("Oren-Nayar sigma=1", lambda: _m("OrenNayar")(ALBEDO, 1.0)),
    ("Oren-Nayar qualitative", lambda: _m("OrenNayar")(ALBEDO, 1.0, form="qualitative")),
    ("Ward 0.3 x 0.06", lambda: _m("Ward")(ALBEDO, 0.2, 0.3, 0.06)),
    ("Ward bounded", lambda: _m("Ward")(ALBEDO, 0.2, 0.3, 0.06, normalization="bounded")),
    ("Ashikhmin-Shirley 1000 x 20", lambda: _m("AshikhminShirley")(ALBEDO, 0.1, 1000.0, 20.0)),
    ("MTL Phong (OBJ files)", lambda: _m("MtlPhong")(KD, 0.25, 60.0, 0.05)),
    ("Measured Cook-Torrance, trilinear", lambda: _m("MeasuredBRDF")(_cook_torrance_table(), "trilinear")),
    ("Measured Cook-Torrance, nearest", lambda: _m("MeasuredBRDF")(_cook_torrance_table())),
)


@functools.lru_cache(maxsize=1)
def _cook_torrance_table():
    """The "Cook-Torrance m=0.25" tile's material tabulated in the MERL layout (1.6 s, once per process)."""

    return _m("MeasuredBRDF")(tabulate(_m("CookTorrance")(ALBEDO, 0.25))).table


def gallery_scene(material):
    """One tile: a unit sphere seen from +z, the key light, the rim light and ambient.

    Parameters
    ----------
    material : glphong.materials.Material

    Returns
    -------
    glphong.Scene
    """

    key = 10.0 * np.array([-0.45, 0.55, 0.70]) / np.linalg.norm([-0.45, 0.55, 0.70])
    camera = PerspectiveCamera.look_at((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0), yfov=np.radians(32.0))
    scene = Scene(camera, lights=[PointLight(tuple(key), 2.5 * 4.0 * np.pi * 100.0),
                                  DirectionalLight((-0.8, -0.1, 0.35), irradiance=1.5)],
                  ambient=AmbientLight(0.08))
    pose = np.eye(4)
    pose[:3, :3] = [[1, 0, 0], [0, 0, 1], [0, -1, 0]]  # the sphere's pole (+z) turned to +y: tangents run around it
    scene.add(primitives.sphere(5), material, pose=pose, name=type(material).__name__)
    return scene


@dataclass(frozen=True)
class Gallery:
    """The rendered gallery.

    Attributes
    ----------
    radiance : (H, W, 3) float32 ndarray
        Linear radiance mosaic [W/(m^2 sr)].
    labels : tuple of str
        Tile labels in reading order.
    columns, tile : int
    reports : list of glphong.verify.VerifyReport
        One per tile with ``verify=True``.
    """

    radiance: np.ndarray
    labels: tuple
    columns: int
    tile: int
    reports: list

    def save_png(self, path, exposure=1.0):
        """Encode (exposure, exact sRGB) and write the mosaic with a label under each tile."""
        from PIL import Image, ImageDraw

        label_height = 16
        rgb = encode_srgb8(self.radiance, exposure)
        rows = -(-len(self.labels) // self.columns)
        canvas = Image.new("RGB", (self.columns * self.tile, rows * (self.tile + label_height)), (255, 255, 255))
        draw = ImageDraw.Draw(canvas)
        for i, label in enumerate(self.labels):
            r, c = divmod(i, self.columns)
            tile = rgb[r * self.tile:(r + 1) * self.tile, c * self.tile:(c + 1) * self.tile]
            canvas.paste(Image.fromarray(np.ascontiguousarray(tile)), (c * self.tile, r * (self.tile + label_height)))
            draw.text((c * self.tile + 3, r * (self.tile + label_height) + self.tile + 2), label, fill=(0, 0, 0))
        canvas.save(path)


def render_gallery(renderer, tile=160, columns=4, verify=False, entries=GALLERY):
    """Render every available entry of ``entries`` as one tile.

    Parameters
    ----------
    renderer : glphong.Renderer
        Resized to ``tile x tile``.
    tile, columns : int
        Tile size [px] and tiles per row.
    verify : bool
        Cross-check every tile against the float64 twin (`glphong.verify`).
    entries : sequence of (str, callable)

    Returns
    -------
    Gallery
    """

    renderer.resize(tile, tile)
    labels, images, reports = [], [], []
    for label, factory in entries:
        try:
            material = factory()
        except AttributeError:  # a model this installation does not define
            continue
        scene = gallery_scene(material)
        images.append(renderer.render(scene).radiance)
        labels.append(label)
        if verify:
            reports.append(verify_scene(scene, renderer))
    rows = -(-len(images) // columns)
    mosaic = np.zeros((rows * tile, columns * tile, 3), np.float32)
    for i, image in enumerate(images):
        r, c = divmod(i, columns)
        mosaic[r * tile:(r + 1) * tile, c * tile:(c + 1) * tile] = image
    return Gallery(mosaic, tuple(labels), columns, tile, reports)
