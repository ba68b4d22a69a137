"""What a scene is made of: cameras (`camera`), lights (`lights`), meshes (`geometry`, `primitives`),
bounding spheres and culling (`culling`), the `Scene` (`scene`), and scenes from trimesh with the
default view (`from_trimesh`).
"""
from glphong.scene.scene import Scene, SceneObject

__all__ = ["Scene", "SceneObject"]
