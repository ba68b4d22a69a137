"""glphong: the local-illumination lecture's shading equations in GLSL, rendered offscreen
(EGL or OSMesa) and cross-checked pixel by pixel against a numpy float64 twin.

Typical use::

    import glphong, trimesh
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)),
                          lights=[glphong.PointLight((2, 2, 2), power=100.0)])
    scene.add(trimesh.creation.icosphere(4), glphong.Phong(kd=0.2, ks=0.5, q=50))
    with glphong.Renderer(256, 256) as r:
        frame = r.render(scene)          # frame.radiance: (256, 256, 3) float32, W/(m^2 sr)
        report = glphong.verify(scene, r)
"""
from glphong import _moved, datasets, materials
from glphong.analysis import tabulate as _tabulate  # noqa: F401 - registers MeasuredBRDF.from_model's tabulator
from glphong.checks import reference
from glphong.core import filesafety, imaging, radiometry
from glphong.core.version import __version__
from glphong.scene import primitives
from glphong.scene.camera import Camera, IntrinsicsCamera, OrthographicCamera, PerspectiveCamera, opencv_pose
from glphong.gpu.contexts import BackendUnavailableError, available_backends, create_context
from glphong.gpu.describe import describe, format_descriptions
from glphong.lights import (AmbientLight, DirectionalLight, ExtendedLight, LightModel, PointLight, PolygonLight, RectLight,
                            SphereLight, DiskLight, EnvironmentLight,                             SpotLight, UnattenuatedPointLight)
from glphong.formats.gltf_export import save_gltf
from glphong.formats.load import load_scene
from glphong.materials import AlphaBlend, AlphaMask, Material, MaterialModel, MaterialSum, NormalMap, Param, Texture, VertexColors
from glphong.materials.ashikhmin_shirley import AshikhminShirley
from glphong.materials.blinn import BlinnPhong
from glphong.materials.cook_torrance import CookTorrance
from glphong.definitions.fresnel import DielectricFresnel, SchlickFresnel
from glphong.materials.diffuse import Diffuse
from glphong.materials.gltf_pbr import GltfPBR
from glphong.materials.lafortune import Lafortune
from glphong.materials.lambert import Lambert
from glphong.materials.measured import MeasuredBRDF
from glphong.materials.mtl import MtlPhong
from glphong.materials.normalized import NormalizedBlinnPhong, NormalizedPhong
from glphong.materials.oren_nayar import OrenNayar
from glphong.materials.phong import Phong
from glphong.materials.ward import Ward
from glphong.gpu.renderer import Frame, GBuffer, Renderer, RendererReleasedError
from glphong.scene.scene import Scene, SceneObject
from glphong.checks.verify import VerifyReport, verify

_moved.install()  # the module paths of 0.1.0 keep working (glphong._moved)

__all__ = [
    "Camera", "PerspectiveCamera", "IntrinsicsCamera", "OrthographicCamera", "opencv_pose", "PointLight", "UnattenuatedPointLight", "DirectionalLight", "SpotLight", "AmbientLight", "LightModel",
    "ExtendedLight", "RectLight", "PolygonLight", "SphereLight", "DiskLight", "EnvironmentLight",
    "Material", "MaterialModel", "MaterialSum", "Param", "Lambert", "Phong", "BlinnPhong", "Diffuse", "NormalizedPhong",
    "NormalizedBlinnPhong", "CookTorrance", "GltfPBR", "Lafortune", "OrenNayar", "Ward", "AshikhminShirley", "MeasuredBRDF", "MtlPhong", "SchlickFresnel",
    "DielectricFresnel", "Texture", "VertexColors", "NormalMap", "AlphaMask", "AlphaBlend", "Scene", "SceneObject", "load_scene", "save_gltf", "Renderer", "RendererReleasedError", "Frame", "GBuffer",
    "verify", "VerifyReport", "describe", "format_descriptions", "create_context", "available_backends", "BackendUnavailableError",
    "datasets", "imaging", "lights", "materials", "primitives", "radiometry", "reference", "filesafety", "__version__",
]
