"""glphong materials inside an ordinary pyrender scene, with pyrender's shadows.

A pyrender scene with a pyrender PBR mesh (green, pyrender's own shader) beside a Phong and a
Blinn-Torrance mesh shaded by glphong, on a glphong Lambert floor, lit by a pyrender SpotLight (axis intensity
I [W/sr]), a PointLight (glphong uses Phi = 4 pi I) and a DirectionalLight, with the scene's ambient light as L_a,
drawn with pyrender's SHADOWS_DIRECTIONAL | SHADOWS_SPOT flags: glphong's surfaces read glphong's own shadow maps,
pyrender's its own.  The same OffscreenRenderer draws everything; `enable` is the one glphong call it needs.  The
scene is then rendered by glphong's own Renderer (the PBR mesh converted to glTF's material, so that it casts the
same shadows) and the two images compared on the glphong meshes.

Run:  python examples/pyrender_scene.py [egl|osmesa] [out.png]
"""
import os
import sys

PLATFORM = sys.argv[1] if len(sys.argv) > 1 else "egl"
os.environ["PYOPENGL_PLATFORM"] = PLATFORM  # before pyrender is imported: it is read once

import numpy as np  # noqa: E402
import pyrender  # noqa: E402
import trimesh  # noqa: E402
from PIL import Image  # noqa: E402

import glphong  # noqa: E402
from glphong.integrations.pyrender import GlphongMaterial, enable, release, scene_from_pyrender  # noqa: E402

FLAGS = pyrender.RenderFlags.SHADOWS_DIRECTIONAL | pyrender.RenderFlags.SHADOWS_SPOT


def translation(x, y, z):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def build_scene():
    scene = pyrender.Scene(ambient_light=[0.05, 0.05, 0.05], bg_color=[0.0, 0.0, 0.0, 1.0])
    sphere = trimesh.creation.icosphere(subdivisions=4, radius=0.6)
    phong = GlphongMaterial(glphong.Phong(kd=(0.25, 0.06, 0.04), ks=0.6, q=80), exposure=1.0)
    blinn = GlphongMaterial(glphong.BlinnPhong(kd=(0.04, 0.08, 0.25), ks=0.6, q=320), exposure=1.0)
    pbr = pyrender.MetallicRoughnessMaterial(baseColorFactor=[0.2, 0.7, 0.2, 1.0], metallicFactor=0.0, roughnessFactor=0.4)
    scene.add(pyrender.Mesh.from_trimesh(sphere, material=phong), pose=translation(-1.4, 0.0, 0.0), name="phong")
    scene.add(pyrender.Mesh.from_trimesh(sphere, material=pbr), pose=translation(0.0, 0.0, 0.0), name="pyrender pbr")
    scene.add(pyrender.Mesh.from_trimesh(sphere, material=blinn), pose=translation(1.4, 0.0, 0.0), name="blinn")
    floor = GlphongMaterial(glphong.Lambert(0.15))
    scene.add(pyrender.Mesh.from_trimesh(trimesh.creation.box(extents=(6.0, 0.1, 4.0)), material=floor),
              pose=translation(0.0, -0.65, 0.0), name="floor")
    spot = glphong.PerspectiveCamera.look_at((-2.0, 3.0, 1.5), (0.0, -0.6, 0.0), yfov=1.0).pose
    scene.add(pyrender.SpotLight(color=[1.0, 0.9, 0.7], intensity=25.0, innerConeAngle=0.3, outerConeAngle=0.6),
              pose=spot)
    scene.add(pyrender.PerspectiveCamera(yfov=np.radians(40), znear=0.05, zfar=50.0), pose=translation(0.0, 0.3, 4.5))
    scene.add(pyrender.PointLight(color=[1.0, 0.95, 0.9], intensity=40.0), pose=translation(2.0, 2.5, 3.0))
    tilt = trimesh.transformations.rotation_matrix(-0.7, [1.0, 0.0, 0.0])
    scene.add(pyrender.DirectionalLight(color=[0.7, 0.8, 1.0], intensity=0.6), pose=tilt)
    return scene


def main(out="pyrender_scene.png"):
    scene = build_scene()
    width, height = 640, 300
    renderer = pyrender.OffscreenRenderer(width, height)
    enable(renderer)
    color, _ = renderer.render(scene, flags=FLAGS)
    Image.fromarray(color).save(out)
    # the scene rendered by glphong itself at pyrender's sample count, its lights with shadows=True as the flags ask;
    # compared on the glphong meshes (the PBR sphere converted, so that it casts into glphong's maps too)
    converted = scene_from_pyrender(scene, convert=True, flags=FLAGS)
    pbr = [i for i, obj in enumerate(converted.objects) if obj.name == "pyrender pbr"]
    with glphong.Renderer(width, height, backend=PLATFORM, samples=4 if PLATFORM == "egl" else 1, numerics="stable") as own:
        ours = own.render_srgb8(converted)
        interior = (own.render(converted).coverage == 1.0) & ~np.isin(own.gbuffer(converted).object_index, pbr)
    for _ in range(2):  # 2 px away from silhouettes, which multisampling treats differently
        interior[1:-1, 1:-1] &= interior[:-2, 1:-1] & interior[2:, 1:-1] & interior[1:-1, :-2] & interior[1:-1, 2:]
    diff = np.abs(ours.astype(int) - color.astype(int)).max(axis=-1)[interior]
    release(renderer)  # frees pyrender's renderer without ending the EGL display the process shares
    print(f"wrote {out} ({PLATFORM}); glphong interior pixels: {interior.sum()}, "
          f"max 8-bit difference to glphong's own renderer {diff.max()}, identical {100 * (diff == 0).mean():.1f}%")


if __name__ == "__main__":
    main(*sys.argv[2:])
