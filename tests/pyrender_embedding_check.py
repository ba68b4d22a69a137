"""Run in a subprocess by test_pyrender_integration.py: pyrender reads PYOPENGL_PLATFORM once per process.

Usage: python pyrender_embedding_check.py PLATFORM; prints one JSON object of measured values.
"""
import json
import os
import sys

os.environ["PYOPENGL_PLATFORM"] = sys.argv[1]

import numpy as np  # noqa: E402
import pyrender  # noqa: E402
import trimesh  # noqa: E402

import glphong  # noqa: E402
from glphong.integrations.pyrender import GlphongMaterial, enable, glphong_lights_of, scene_from_pyrender  # noqa: E402
from glphong.shaders.binding import binding  # noqa: E402


def translation(x, y, z):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def build_scene():
    scene = pyrender.Scene(ambient_light=[0.03, 0.03, 0.03], bg_color=[0.0, 0.0, 0.0, 1.0])
    materials = [glphong.Lambert((0.3, 0.2, 0.1)), glphong.Phong(0.2, 0.6, 60.0), glphong.BlinnPhong((0.1, 0.2, 0.3), 0.5, 300.0)]
    for x, m in zip((-1.3, 0.0, 1.3), materials):
        mesh = pyrender.Mesh.from_trimesh(trimesh.creation.icosphere(4, radius=0.55), material=GlphongMaterial(m))
        scene.add(mesh, pose=translation(x, -0.2, 0.0), name=type(m).__name__)
    measured = GlphongMaterial(glphong.MeasuredBRDF.example(lookup="trilinear"))  # a table: a 3D texture
    scene.add(pyrender.Mesh.from_trimesh(trimesh.creation.icosphere(3, radius=0.3), material=measured),
              pose=translation(-1.3, 0.85, 0.0), name="measured")
    pbr = pyrender.MetallicRoughnessMaterial(baseColorFactor=[0.2, 0.8, 0.2, 1.0], metallicFactor=0.0, roughnessFactor=0.5)
    scene.add(pyrender.Mesh.from_trimesh(trimesh.creation.icosphere(3, radius=0.3), material=pbr),
              pose=translation(0.0, 0.85, 0.0), name="pbr")
    # a textured plane and a vertex-coloured sphere: samplers and the colour attribute inside pyrender
    plane = glphong.primitives.plane(1.0)
    checker = (np.indices((8, 8)).sum(axis=0) % 2 * 200 + 30).astype(np.uint8)
    textured = pyrender.Primitive(plane.positions, plane.normals, texcoord_0=plane.uvs * 2, indices=plane.indices,
                                  material=GlphongMaterial(glphong.Lambert(kd=glphong.Texture(checker, 0.3))))
    scene.add(pyrender.Mesh([textured]), pose=translation(1.3, 0.85, 0.0), name="textured")
    ball = trimesh.creation.icosphere(2, radius=0.25)
    colours = np.random.default_rng(3).random((len(ball.vertices), 4))
    coloured = pyrender.Primitive(ball.vertices, ball.vertex_normals, color_0=colours, indices=ball.faces,
                                  material=GlphongMaterial(glphong.Lambert(kd=glphong.VertexColors(0.3))))
    scene.add(pyrender.Mesh([coloured]), pose=translation(0.0, -1.0, 0.5), name="coloured")
    scene.add(pyrender.PerspectiveCamera(yfov=0.8, znear=0.05, zfar=100.0), pose=translation(0.0, 0.0, 4.0))
    scene.add(pyrender.PointLight(color=[1.0, 0.9, 0.8], intensity=25.0), pose=translation(2.0, 2.0, 3.0))
    light_pose = np.eye(4)
    light_pose[:3, :3] = trimesh.transformations.rotation_matrix(-0.6, [1, 0, 0])[:3, :3]
    scene.add(pyrender.DirectionalLight(color=[0.6, 0.7, 1.0], intensity=0.8), pose=light_pose)
    return scene, light_pose


def main(platform):
    scene, light_pose = build_scene()
    width, height = 200, 150
    renderer = pyrender.OffscreenRenderer(width, height)
    enable(renderer)
    color, depth = renderer.render(scene)
    color2, _ = renderer.render(scene)  # a second frame: programs cached, nothing recompiled
    programs = renderer._renderer._glphong_programs
    keys = [k for k in programs.keys()]
    glphong_scene = scene_from_pyrender(scene)
    samples = 4 if platform == "egl" else 1  # pyrender multisamples on EGL only
    with glphong.Renderer(width, height, backend=platform, samples=samples, numerics="stable") as g:
        ours = g.render_srgb8(glphong_scene)
        frame = g.render(glphong_scene)
        own_chunks = [g.programs.get(binding(glphong_scene).program_key(o)).key.fragment_chunks() for o in glphong_scene.objects]
    with glphong.Renderer(width, height, backend=platform, numerics="stable") as g:  # the frame passes of a pyrender scene
        passes = g.render(glphong_scene, passes=("depth", "instance"))
    interior = frame.coverage == 1.0
    for _ in range(2):  # erode by 2 px: silhouettes are compared apart
        interior[1:-1, 1:-1] &= interior[:-2, 1:-1] & interior[2:, 1:-1] & interior[1:-1, :-2] & interior[1:-1, 2:]
    diff = np.abs(ours.astype(int) - color.astype(int)).max(axis=-1)
    pbr_region = (depth > 0) & ~frame.mask
    lights, ambient = glphong_lights_of(scene)
    point = next(light for light in lights if isinstance(light, glphong.PointLight))
    directional = next(light for light in lights if isinstance(light, glphong.DirectionalLight))
    result = {
        "interior_pixels": int(interior.sum()),
        "interior_max_diff": int(diff[interior].max()),
        "interior_exact_fraction": float((diff[interior] == 0).mean()),
        "silhouette_pixels": int((frame.mask & ~interior).sum()),
        "pbr_pixels": int(pbr_region.sum()),
        "pbr_green": float(color[pbr_region][:, 1].mean()) if pbr_region.any() else 0.0,
        "second_frame_identical": bool(np.array_equal(color, color2)),
        "programs": len(programs), "compiled": programs.misses, "textures": len(programs.textures),
        "texture_uploads": programs.textures.uploads,
        "keys": sorted(k.describe() for k in keys),
        "pyrender_chunks": sorted(set(k.fragment_chunks() for k in keys)),
        "glphong_chunks": sorted(set(own_chunks)),
        "point_power": list(point.power),
        "directional": list(directional.direction), "directional_expected": list(light_pose[:3, 2]),
        "directional_irradiance": list(directional.irradiance),
        "ambient": list(ambient.radiance),
    }
    # pyrender's depth (view-axis z, multisampled on EGL) against the converted scene's depth pass, on the interior
    # pixels whose 5x5 neighbourhood sees one object (its edges over another object apart)
    ids = passes.instance
    same = np.zeros(ids.shape, bool)
    same[2:-2, 2:-2] = True
    for dy in range(-2, 3):
        for dx in range(-2, 3):
            same[2:-2, 2:-2] &= ids[2 + dy:ids.shape[0] - 2 + dy, 2 + dx:ids.shape[1] - 2 + dx] == ids[2:-2, 2:-2]
    inside = interior & same & (depth > 0)
    result["passes"] = {"instances": sorted(int(i) for i in np.unique(passes.instance)),
                        "objects": len(glphong_scene.objects),
                        "depth_max_relative": float(np.max(np.abs(passes.depth[inside] - depth[inside]) / depth[inside])),
                        "depth_pixels": int(inside.sum())}
    result["converted"] = _converted(platform, renderer, width, height)
    result["non_indexed"] = _non_indexed(platform, renderer, width, height)
    # refusals
    spot = pyrender.Scene()
    spot.add(pyrender.SpotLight(color=[1.0, 0.5, 0.25], intensity=2.0, innerConeAngle=0.2, outerConeAngle=0.7),
             pose=translation(1, 2, 3))
    (mapped,), _ = glphong_lights_of(spot)
    result["spot"] = {"kind": type(mapped).__name__, "position": list(mapped.position),
                      "direction": list(mapped.direction), "intensity": list(mapped.intensity),
                      "cones": [mapped.inner_cone_angle, mapped.outer_cone_angle]}
    poses = np.stack([translation(0, 0, 0), translation(1, 0, 0)])
    result["instanced"] = _refusal(renderer, pyrender.Mesh.from_trimesh(
        trimesh.creation.box(), material=GlphongMaterial(glphong.Lambert(0.5)), poses=poses))
    try:  # a blended material: pyrender's passes would draw it opaque
        GlphongMaterial(glphong.Lambert(0.5, alpha_blend=glphong.AlphaBlend(0.5)))
        result["blended"] = "accepted"
    except ValueError as exc:
        result["blended"] = str(exc)
    for name, keywords in (("transmissive", {"transmission": 0.5}), ("diffuse_transmissive", {"diffuse_transmission": 0.5})):
        try:  # lit through the surface: pyrender's passes have no image behind it nor lights behind it
            GlphongMaterial(glphong.GltfPBR(0.5, 0.0, 0.5, **keywords))
            result[name] = "accepted"
        except ValueError as exc:
            result[name] = str(exc)
    renderer.delete()
    # a GlphongMaterial drawn by a renderer glphong was not enabled on: an error, not a black image
    # (after the first renderer is deleted: on EGL deleting one OffscreenRenderer ends the shared display)
    plain = pyrender.OffscreenRenderer(32, 32)
    try:
        plain.render(_single(GlphongMaterial))
        result["not_enabled"] = "accepted"
    except RuntimeError as exc:
        result["not_enabled"] = str(exc)
    plain.delete()
    print(json.dumps(result))


def _converted(platform, renderer, width, height):
    """A pyrender MetallicRoughnessMaterial with every texture, converted (gltf_pbr_of): what each input became, and
    the converted sphere drawn inside pyrender (GlphongMaterial.from_pyrender) against glphong's renderer."""
    from glphong.integrations.pyrender import gltf_pbr_of

    rng = np.random.default_rng(2)
    mr = rng.integers(0, 256, (8, 8, 3), dtype=np.uint8)
    base = rng.integers(0, 256, (8, 8, 3), dtype=np.uint8)
    occlusion = rng.integers(0, 256, (8, 8, 3), dtype=np.uint8)
    material = pyrender.MetallicRoughnessMaterial(
        baseColorFactor=[0.5, 0.25, 1.0, 1.0], metallicFactor=0.75, roughnessFactor=0.5, baseColorTexture=base,
        metallicRoughnessTexture=mr, occlusionTexture=occlusion, emissiveFactor=[0.1, 0.2, 0.3], doubleSided=True)
    pbr = gltf_pbr_of(material)
    out = {"type": type(pbr).__name__, "two_sided": pbr.two_sided,
           "metallic": [pbr.metallic.channel, pbr.metallic.scale], "roughness": [pbr.roughness.channel, pbr.roughness.scale],
           "emissive": list(pbr.emissive), "base_scale": list(pbr.base_color.scale),
           # level 0 is stored bottom row first, as float16: compare with the source's channels
           "metallic_texels": bool(np.array_equal(pbr.metallic.texture.levels[0][::-1, :, 2],
                                                  (mr[..., 2] / 255.0).astype(np.float16))),
           "roughness_texels": bool(np.array_equal(pbr.roughness.texture.levels[0][::-1, :, 1],
                                                   (mr[..., 1] / 255.0).astype(np.float16))),
           "occlusion_texels": bool(np.array_equal(pbr.occlusion.texture.levels[0][::-1, :, 0],
                                                   (occlusion[..., 0] / 255.0).astype(np.float16))),
           "base_srgb": pbr.base_color.texture.encoding}
    scene = pyrender.Scene(ambient_light=[0.0, 0.0, 0.0])
    sphere = trimesh.creation.icosphere(3)
    uv = np.stack([0.5 + np.arctan2(sphere.vertices[:, 1], sphere.vertices[:, 0]) / (2 * np.pi),
                   0.5 + 0.5 * sphere.vertices[:, 2]], axis=1)
    sphere.visual = trimesh.visual.TextureVisuals(uv=uv)
    scene.add(pyrender.Mesh.from_trimesh(sphere, material=GlphongMaterial.from_pyrender(material)))
    scene.add(pyrender.PerspectiveCamera(yfov=0.8, aspectRatio=width / height), pose=translation(0, 0, 3))
    scene.add(pyrender.PointLight(intensity=3.0), pose=translation(1, 1, 3))
    color, _ = renderer.render(scene)  # the enabled renderer (a second one at once fails on EGL)
    with glphong.Renderer(width, height, backend=platform, samples=4 if platform == "egl" else 1, numerics="stable") as g:
        ours = g.render_srgb8(scene_from_pyrender(scene))
        interior = g.render(scene_from_pyrender(scene)).coverage == 1.0
    interior[1:-1, 1:-1] &= interior[:-2, 1:-1] & interior[2:, 1:-1] & interior[1:-1, :-2] & interior[1:-1, 2:]
    diff = np.abs(ours.astype(int) - color.astype(int)).max(axis=-1)[interior]
    out["embedded_pixels"], out["embedded_within_one"] = int(interior.sum()), float(np.mean(diff <= 1))
    return out


def _non_indexed(platform, renderer, width, height):
    """Mesh.from_trimesh(..., smooth=False) keeps no indices: scene_from_pyrender takes consecutive triples, and the
    embedded frame agrees with glphong's renderer; a vertex-colour material without color_0 names the fix."""
    scene = pyrender.Scene(ambient_light=[0.0, 0.0, 0.0])
    scene.add(pyrender.Mesh.from_trimesh(trimesh.creation.icosphere(2), smooth=False,
                                         material=GlphongMaterial(glphong.Lambert(0.2))))
    scene.add(pyrender.PerspectiveCamera(yfov=0.8, aspectRatio=width / height), pose=translation(0, 0, 3))
    scene.add(pyrender.PointLight(intensity=3.0), pose=translation(1, 1, 3))
    primitive = next(iter(scene.meshes)).primitives[0]
    color, _ = renderer.render(scene)
    ours_scene = scene_from_pyrender(scene)
    with glphong.Renderer(width, height, backend=platform, samples=4 if platform == "egl" else 1, numerics="stable") as g:
        ours = g.render_srgb8(ours_scene)
        interior = g.render(ours_scene).coverage == 1.0
    interior[1:-1, 1:-1] &= interior[:-2, 1:-1] & interior[2:, 1:-1] & interior[1:-1, :-2] & interior[1:-1, 2:]
    diff = np.abs(ours.astype(int) - color.astype(int)).max(axis=-1)[interior]
    out = {"indices": primitive.indices is None, "triangles": len(ours_scene.objects[0].mesh.indices),
           "pixels": int(interior.sum()), "within_one": float(np.mean(diff <= 1))}
    out["vertex_colours"] = _refusal(renderer, pyrender.Mesh.from_trimesh(
        trimesh.creation.icosphere(1), material=GlphongMaterial(glphong.Lambert(glphong.VertexColors(0.2)))))
    return out


def _refusal(renderer, mesh):
    """What drawing ``mesh`` (seen from 4 m, lit beside the camera) says: its ValueError's message, or 'accepted'."""
    scene = pyrender.Scene()
    scene.add(mesh)
    scene.add(pyrender.PerspectiveCamera(yfov=0.8), pose=translation(0, 0, 4))
    scene.add(pyrender.PointLight(intensity=1.0), pose=translation(0, 0, 4))
    try:
        renderer.render(scene)
        return "accepted"
    except ValueError as exc:
        return str(exc)


def _single(material_class):
    scene = pyrender.Scene()
    scene.add(pyrender.Mesh.from_trimesh(trimesh.creation.icosphere(1), material=material_class(glphong.Lambert(0.5))))
    scene.add(pyrender.PerspectiveCamera(yfov=0.8), pose=translation(0, 0, 4))
    scene.add(pyrender.PointLight(intensity=1.0), pose=translation(0, 0, 4))
    return scene


if __name__ == "__main__":
    main(sys.argv[1])
