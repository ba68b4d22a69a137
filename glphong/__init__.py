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
from . import imaging, materials, primitives, radiometry, reference
from .camera import Camera, IntrinsicsCamera, OrthographicCamera, PerspectiveCamera, opencv_pose
from .contexts import BackendUnavailableError, available_backends, create_context
from .describe import describe, format_descriptions
from .lights import AmbientLight, DirectionalLight, PointLight, UnattenuatedPointLight
from .gltf_export import save_gltf
from .loaders import load_scene
from .materials import (AshikhminShirley, BlinnPhong, CookTorrance, DielectricFresnel, Diffuse, Lafortune, Lambert,
                        Material, MaterialModel, MaterialSum, MeasuredBRDF, MtlPhong, NormalizedBlinnPhong,
                        NormalizedPhong, OrenNayar, Param, Phong, SchlickFresnel, Texture, VertexColors, Ward)
from .renderer import Frame, GBuffer, Renderer
from .scene import Scene, SceneObject
from .verify import VerifyReport, verify

__version__ = "0.1.0"

__all__ = [
    "Camera", "PerspectiveCamera", "IntrinsicsCamera", "OrthographicCamera", "opencv_pose", "PointLight", "UnattenuatedPointLight", "DirectionalLight", "AmbientLight",
    "Material", "MaterialModel", "MaterialSum", "Param", "Lambert", "Phong", "BlinnPhong", "Diffuse", "NormalizedPhong",
    "NormalizedBlinnPhong", "CookTorrance", "Lafortune", "OrenNayar", "Ward", "AshikhminShirley", "MeasuredBRDF", "MtlPhong", "SchlickFresnel",
    "DielectricFresnel", "Texture", "VertexColors", "Scene", "SceneObject", "load_scene", "save_gltf", "Renderer", "Frame", "GBuffer",
    "verify", "VerifyReport", "describe", "format_descriptions", "create_context", "available_backends", "BackendUnavailableError",
    "imaging", "materials", "primitives", "radiometry", "reference",
]
