"""Scene files: one reader per format (`obj`, `mtl`, `gltf_validate`, `gltf_data`, `gltf_scene`), the
glTF writer (`gltf_export`) and `load_scene`, which dispatches on the file's suffix (`load`).
"""
from glphong.formats.load import (LUMENS_PER_WATT, default_view, gltf_material, gltf_pbr_material, gltf_view, load_scene,
                                  material_from_extras, material_from_mtl, parse_mtl, read_gltf_json, read_obj,
                                  scene_bounds, scene_from_trimesh)

__all__ = ["load_scene", "read_obj", "read_gltf_json", "gltf_view", "gltf_material", "gltf_pbr_material",
           "material_from_extras",
           "scene_from_trimesh", "parse_mtl", "material_from_mtl", "default_view", "scene_bounds", "LUMENS_PER_WATT"]
