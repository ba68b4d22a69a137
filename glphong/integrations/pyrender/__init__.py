"""glphong shading inside pyrender scenes.

A pyrender user keeps their scene, camera, lights, nodes and ``OffscreenRenderer``, gives the meshes
they choose a `GlphongMaterial`, and calls `enable` once on the renderer::

    import os
    os.environ["PYOPENGL_PLATFORM"] = "egl"          # or "osmesa"; before pyrender is imported
    import pyrender, trimesh, glphong
    from glphong.integrations.pyrender import GlphongMaterial, enable

    material = GlphongMaterial(glphong.Phong(kd=0.2, ks=0.5, q=80))
    scene.add(pyrender.Mesh.from_trimesh(tm, material=material))
    renderer = pyrender.OffscreenRenderer(640, 480)
    enable(renderer)                                   # once; or enable_everywhere() before creating it
    color, depth = renderer.render(scene)

Primitives with a `GlphongMaterial` are drawn by programs generated from glphong's own chunks and
`ProgramKey` (output ``'display'``: the same linear shading, then the exposure and the exact sRGB
curve, since pyrender's framebuffer is 8-bit), with glphong's strict uniform binding; every other
primitive keeps pyrender's shaders.  pyrender's render flags hold for glphong's surfaces too
(`glphong.integrations.pyrender.renderer`): its shadow flags with glphong's own shadow maps, ``FLAT`` unlit.

The package's modules: ``materials`` (`GlphongMaterial`, `gltf_pbr_of`), ``scenes`` (lights, cameras,
`scene_from_pyrender`), ``renderer`` (`enable`, `enable_everywhere`), ``shadows`` (glphong's maps in pyrender's frame).

Lights map with the units of docs/design.md section 2:

- ``pyrender.PointLight(color, intensity)``: intensity I [W/sr] per channel ``color * intensity``,
  so ``Phi = 4 pi I`` (`glphong.PointLight`);
- ``pyrender.DirectionalLight(color, intensity)``: irradiance ``E = color * intensity`` [W/m^2],
  travelling along the node's -Z axis (`glphong.DirectionalLight`);
- ``pyrender.SpotLight(color, intensity, innerConeAngle, outerConeAngle)``: a `glphong.SpotLight` of intensity
  ``I = color * intensity`` taken as W/sr along the axis (pyrender's shader uses the candela value as the
  intensity, and KHR_lights_punctual's falloff, as glphong does), pointing along the node's -Z axis;
- ``scene.ambient_light``: ``L_a`` (`glphong.AmbientLight`).

Each pyrender light class is read by the glphong light kind whose ``pyrender_type`` it is
(`glphong.lights.LightModel.from_pyrender`).  pyrender ignores a light's range; so does the mapping.

Importing this module imports pyrender, so set ``PYOPENGL_PLATFORM`` first (pyrender reads it once).
pyrender 0.1.45's OSMesa platform needs PyOpenGL >= 3.1.5 (``pip install --no-deps PyOpenGL==3.1.10``).
"""
from glphong.gpu.contexts import release_offscreen as release
from glphong.integrations.pyrender.materials import GlphongMaterial, gltf_pbr_of
from glphong.integrations.pyrender.renderer import GlphongRenderer, disable_everywhere, enable, enable_everywhere
from glphong.integrations.pyrender.scenes import glphong_camera_of, glphong_lights_of, scene_from_pyrender

__all__ = ["GlphongMaterial", "enable", "enable_everywhere", "disable_everywhere", "glphong_lights_of",
           "glphong_camera_of", "scene_from_pyrender", "gltf_pbr_of", "GlphongRenderer", "release"]
