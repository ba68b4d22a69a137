"""Built-in default scenes.

`phong_examples` reproduces the lecture's "Phong Examples" slide: a grid of spheres
with the light direction varying down the rows and the shininess q along the
columns, Phong on the left next to Blinn-Torrance on the right.
"""
import functools
from dataclasses import dataclass

import numpy as np

from glphong.scene.camera import PerspectiveCamera
from glphong.scene.geometry import MeshData
from glphong.lights import AmbientLight, PointLight
from glphong.materials.blinn import BlinnPhong
from glphong.materials.phong import Phong
from glphong.scene.scene import Scene
from glphong.checks.verify import verify as verify_scene
from glphong.core.imaging import encode_srgb8

__all__ = ["PhongExamples", "phong_examples_scene", "phong_examples"]

#: shininess exponents along the columns
Q_VALUES = (5.0, 20.0, 100.0, 500.0, 5000.0)
#: angle [deg] between the light and the viewing direction, down the rows (light swings to upper right)
LIGHT_ANGLES = (10.0, 35.0, 60.0, 85.0)
#: distance of the light from the sphere centre [m] and the irradiance it delivers there [W/m^2]
LIGHT_DISTANCE = 20.0
IRRADIANCE = 3.0


@functools.lru_cache(maxsize=4)
def unit_sphere(subdivisions=5):
    """A unit icosphere as `MeshData` (cached: every tile shares one mesh and its GPU buffers)."""
    import trimesh

    return MeshData.from_trimesh(trimesh.creation.icosphere(subdivisions=subdivisions))


def phong_examples_scene(material_class, q, light_angle_deg, sphere_subdivisions=5):
    """One tile: a unit sphere seen from +z, lit by a point light ``light_angle_deg`` off the view axis.

    Parameters
    ----------
    material_class : type
        `Phong` or `BlinnPhong`.
    q : float
        Shininess exponent.
    light_angle_deg : float
        Angle between the light direction and the view direction [deg].
    sphere_subdivisions : int
        Icosphere subdivision level (5: 20480 triangles).

    Returns
    -------
    Scene
    """
    a = np.radians(light_angle_deg)
    direction = np.array([np.sin(a) * np.sqrt(0.5), np.sin(a) * np.sqrt(0.5), np.cos(a)])
    power = IRRADIANCE * 4.0 * np.pi * LIGHT_DISTANCE ** 2  # E = Phi / (4 pi d^2) at the centre
    camera = PerspectiveCamera.look_at((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), yfov=np.radians(32.0))
    scene = Scene(camera, lights=[PointLight(LIGHT_DISTANCE * direction, power)], ambient=AmbientLight(0.15))
    material = material_class(kd=(0.20, 0.05, 0.035), ks=0.5, q=q)
    scene.add(unit_sphere(sphere_subdivisions), material, name=f"{material_class.__name__} q={q:g} light {light_angle_deg:g} deg")
    return scene


@dataclass(frozen=True)
class PhongExamples:
    """The rendered figure.

    Attributes
    ----------
    radiance : (H, W, 3) float32 ndarray
        Linear radiance mosaic [W/(m^2 sr)], Phong panel left, Blinn-Torrance panel right.
    q_values, light_angles : tuple of float
        Column and row parameters.
    tile : int
        Tile size in pixels.
    reports : list of glphong.verify.VerifyReport
        One per tile when rendered with ``verify=True``, else empty.
    """

    radiance: np.ndarray
    q_values: tuple
    light_angles: tuple
    tile: int
    reports: list

    def save_png(self, path, exposure=0.6):
        """Encode (exposure, exact sRGB) and write the figure with row and column labels."""
        from PIL import Image, ImageDraw

        margin = 22
        rgb = encode_srgb8(self.radiance, exposure)
        height, width = rgb.shape[:2]
        canvas = Image.new("RGB", (width + margin, height + 2 * margin), (255, 255, 255))
        canvas.paste(Image.fromarray(rgb), (margin, margin))
        draw = ImageDraw.Draw(canvas)
        panel = len(self.q_values) * self.tile
        for p, title in enumerate(("Phong  (v.r)^q", "Blinn-Torrance  (n.h)^q")):
            draw.text((margin + p * panel + 4, 4), title, fill=(0, 0, 0))
            for c, q in enumerate(self.q_values):
                draw.text((margin + p * panel + c * self.tile + 4, height + margin + 4), f"q={q:g}", fill=(0, 0, 0))
        for r, angle in enumerate(self.light_angles):
            draw.text((2, margin + r * self.tile + self.tile // 2), f"{angle:g}", fill=(0, 0, 0))
        canvas.save(path)


def phong_examples(renderer, tile=128, q_values=Q_VALUES, light_angles=LIGHT_ANGLES, verify=False):
    """Render the "Phong Examples" figure.

    Parameters
    ----------
    renderer : glphong.Renderer
        Used at its current backend; resized to ``tile x tile``.
    tile : int
        Tile size in pixels.
    q_values, light_angles : sequence of float
        Columns (shininess) and rows (light angle off the view axis [deg]).
    verify : bool
        Also cross-check every tile against the float64 twin.

    Returns
    -------
    PhongExamples
    """

    renderer.resize(tile, tile)
    rows = []
    reports = []
    for angle in light_angles:
        row = []
        for material_class in (Phong, BlinnPhong):
            for q in q_values:
                scene = phong_examples_scene(material_class, q, angle)
                row.append(renderer.render(scene).radiance)
                if verify:
                    reports.append(verify_scene(scene, renderer))
        rows.append(np.concatenate(row, axis=1))
    return PhongExamples(np.concatenate(rows, axis=0), tuple(q_values), tuple(light_angles), tile, reports)
