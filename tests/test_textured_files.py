"""Textures and vertex colours from the files users have, and glphong materials round-tripping through glTF.

- OBJ + MTL: ``map_Kd`` becomes a texture that ``Kd`` multiplies (the MTL convention), on the part's UVs;
  the texels are the image's, sRGB-decoded, and the render verifies.
- glTF: ``baseColorTexture`` times ``baseColorFactor`` times ``COLOR_0`` (linear) varies the approximation's
  diffuse albedo; trimesh's v flip leaves uv (0, 0) at the image's bottom-left, checked with a marker
  image whose top row alone is red: a surface point at glTF v = 0 (the image's top) renders red.
- `glphong.save_gltf` then `load_scene`: every material equal to the original (class, parameters,
  textures by content), objects in order with their poses, lights and ambient as written; the reloaded
  render equals the original's within 3e-5 of the peak (measured 6.5e-6: glTF stores 1 - v in float32,
  so a round trip may move a uv by an ulp of 1 - v).
- What cannot be stored says so: a table (MeasuredBRDF) and a texture from a float image.
"""
import json

import numpy as np
import pytest
import trimesh
from PIL import Image

import glphong
from glphong import primitives
from glphong.scene.geometry import MeshData
from glphong.definitions.as_json import material_from_json, material_to_json
from glphong.definitions.surface import TextureImage

RNG = np.random.default_rng(11)
NOISE = RNG.integers(0, 256, (16, 24, 3), dtype=np.uint8)


def _decode(b):
    c = np.asarray(b, dtype=np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def _write_textured_obj(folder):
    Image.fromarray(NOISE).save(folder / "wood.png")
    (folder / "quad.mtl").write_text("newmtl wood\nKd 0.5 0.25 0.125\nKs 0.1 0.1 0.1\nNs 12\nillum 2\nmap_Kd wood.png\n")
    (folder / "quad.obj").write_text("mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                                     "vt 0 0\nvt 2 0\nvt 2 2\nvt 0 2\nvn 0 0 1\nusemtl wood\nf 1/1/1 2/2/1 3/3/1 4/4/1\n")
    return folder / "quad.obj"


def test_obj_map_kd_is_a_texture_kd_multiplies(tmp_path, glphong_backend, glphong_make_renderer):
    scene = glphong.load_scene(_write_textured_obj(tmp_path))
    material = scene.objects[0].material
    assert isinstance(material, glphong.MtlPhong) and material.ks == (0.1, 0.1, 0.1)
    assert material.kd.scale == (0.5, 0.25, 0.125)
    np.testing.assert_array_equal(material.kd.texture.levels[0], _decode(NOISE[::-1]).astype(np.float16))
    report = glphong.verify(scene, glphong_make_renderer(96, 80, glphong_backend))
    assert report.covered_pixels > 1500 and report.passed, report.summary()


def _marker_gltf(tmp_path, with_colors):
    """A unit quad facing +z whose glTF uv runs v = 0 at y = +1 (the image's top, which is red)."""
    marker = np.zeros((8, 8, 3), np.uint8)
    marker[0] = (255, 0, 0)
    quad = trimesh.Trimesh([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]], process=False)
    material = trimesh.visual.material.PBRMaterial(name="marker", baseColorTexture=Image.fromarray(marker),
                                                   baseColorFactor=[255, 255, 255, 255], metallicFactor=0.0)
    uv_opengl = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64)  # trimesh writes 1 - v to the file
    quad.visual = trimesh.visual.TextureVisuals(uv=uv_opengl, material=material)
    if with_colors:
        quad.visual.vertex_attributes["color"] = np.tile([128, 255, 255, 255], (4, 1)).astype(np.uint8)
    path = tmp_path / "marker.glb"
    trimesh.Scene(quad).export(path)
    return path


def test_gltf_base_colour_texture_and_vertex_colours(tmp_path, glphong_make_renderer):
    path = _marker_gltf(tmp_path, with_colors=False)
    assert "TEXCOORD_0" in glphong.formats.read_gltf_json(path)["meshes"][0]["primitives"][0]["attributes"]
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.load_scene(path, camera=camera, lights=[], ambient=glphong.AmbientLight(1.0))
    rho = scene.objects[0].material.base_color
    assert rho.texture is not None and not rho.vertex_colors
    frame = glphong_make_renderer(64, 64, "egl").render(scene)
    rows = frame.mask.any(axis=1).nonzero()[0]
    near_top, middle = (frame.radiance[rows[int(f * (len(rows) - 1))]].max(axis=0) for f in (0.05, 0.5))
    assert near_top[0] > 0.1 and near_top[1] == 0.0  # y near +1, the file's v near 0: the image's top row, red
    assert middle.max() == 0.0                       # the image's other rows are black
    coloured = glphong.load_scene(_marker_gltf(tmp_path, with_colors=True), camera=camera, lights=[],
                                  ambient=glphong.AmbientLight(1.0))
    obj = coloured.objects[0]
    assert obj.material.base_color.vertex_colors
    accessor = glphong.formats.read_gltf_json(tmp_path / "marker.glb")["accessors"]
    assert any(a.get("componentType") == 5121 for a in accessor)  # COLOR_0 as normalised bytes: linear, not sRGB
    np.testing.assert_array_equal(obj.mesh.colors, np.float32([[128 / 255, 1.0, 1.0]] * len(obj.mesh.colors)))
    assert glphong.verify(coloured, glphong_make_renderer(64, 64, "egl")).passed


def _rich_scene():
    camera = glphong.PerspectiveCamera.look_at((0.0, -3.0, 1.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), yfov=0.9)
    scene = glphong.Scene(camera, [glphong.PointLight((0.5, -1.0, 2.0), (100.0, 80.0, 60.0)),
                                   glphong.DirectionalLight((0.2, 0.3, -1.0), 0.5)], ambient=glphong.AmbientLight(0.2))
    plane = primitives.plane(3.0, 4)
    scene.add(MeshData(plane.positions, plane.normals, plane.indices, uvs=plane.uvs * 3),
              glphong.Phong(kd=glphong.Texture(NOISE, scale=0.3, wrap="clamp"), ks=0.2, q=20.0))
    sphere = primitives.sphere(3, 0.5)
    coloured = MeshData(sphere.positions, sphere.normals, sphere.indices, uvs=sphere.uvs,
                        colors=RNG.random((len(sphere.positions), 3)))
    lifted = np.eye(4)
    lifted[:3, 3] = (0.0, 0.0, 0.6)
    scene.add(coloured, glphong.Lambert(kd=glphong.Texture(NOISE, 0.25, vertex_colors=True)), pose=lifted)
    lifted = lifted.copy()
    lifted[0, 3] = -1.0
    scene.add(sphere, glphong.CookTorrance(0.3, 0.2, fresnel=glphong.DielectricFresnel(1.4), ka=0.01), pose=lifted)
    scene.add(sphere, glphong.Ward(rho_d=0.2, rho_s=0.1, alpha_x=0.2, alpha_y=0.4, two_sided=False), pose=np.diag([1, 1, -1, 1.0]))
    return scene


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_save_gltf_round_trips_materials_objects_and_lights(tmp_path, suffix, glphong_make_renderer):
    scene = _rich_scene()
    loaded = glphong.load_scene(glphong.save_gltf(scene, tmp_path / f"scene{suffix}"))
    assert [o.name for o in loaded.objects] == [o.name for o in scene.objects]
    for original, again in zip(scene.objects, loaded.objects):
        assert again.material == original.material
        np.testing.assert_allclose(again.pose, original.pose, atol=1e-12)
    assert loaded.lights == scene.lights and loaded.ambient == scene.ambient
    assert loaded.camera.yfov == scene.camera.yfov
    np.testing.assert_allclose(loaded.camera.pose, scene.camera.pose, atol=1e-12)
    renderer = glphong_make_renderer(120, 90, "egl")
    before, after = renderer.render(scene).radiance, renderer.render(loaded).radiance
    assert np.abs(after - before).max() <= 3e-5 * before.max()
    assert glphong.verify(loaded, renderer).passed


def test_materials_as_json_are_exact_and_refuse_what_they_cannot_hold():
    for material in (glphong.Phong(0.1234567891234, 0.3, 20.5), glphong.OrenNayar(rho=(0.1, 0.2, 0.3), sigma=0.4),
                     glphong.CookTorrance(0.3, 0.2, fresnel=None), glphong.Lambert(kd=glphong.VertexColors(0.5))):
        assert material_from_json(json.loads(json.dumps(material_to_json(material)))) == material
    with pytest.raises(ValueError, match="is textured: give texture_index"):
        material_to_json(glphong.Lambert(kd=glphong.Texture(NOISE)))
    table = glphong.MeasuredBRDF.example()
    with pytest.raises(ValueError, match="is a table"):
        material_to_json(table)
    with pytest.raises(ValueError, match="no material class nowhere.Imaginary"):
        material_from_json({"version": 1, "class": "Imaginary", "module": "nowhere", "arguments": {}})


def test_save_gltf_refuses_textures_it_cannot_store(tmp_path):
    scene = _rich_scene()
    scene.add(primitives.plane(1.0), glphong.Lambert(kd=glphong.Texture(RNG.random((4, 4)).astype(np.float32))))
    with pytest.raises(ValueError, match="float image, which 8-bit pixels cannot hold exactly"):
        glphong.save_gltf(scene, tmp_path / "scene.glb")
    with pytest.raises(ValueError, match="writes .glb or .gltf"):
        glphong.save_gltf(_rich_scene(), tmp_path / "scene.obj")
    assert TextureImage(NOISE).pixels8().tolist() == NOISE.tolist()


def test_example_textured_scene(tmp_path, load_example):
    module = load_example("textured_scene")
    report, difference = module.main(tmp_path)
    assert report.passed and report.covered_pixels > 50000
    assert difference < 3e-5
    assert (tmp_path / "textured.png").stat().st_size > 10000 and (tmp_path / "textured.glb").is_file()


def test_from_trimesh_keeps_material_images_as_textures():
    box = trimesh.creation.box()
    image = Image.fromarray(NOISE)
    box.visual = trimesh.visual.TextureVisuals(uv=RNG.random((len(box.vertices), 2)), material=
                                               trimesh.visual.material.PBRMaterial(baseColorTexture=image,
                                                                                  baseColorFactor=[255, 128, 64, 255]))
    kd = glphong.Scene.from_trimesh(trimesh.Scene(box)).objects[0].material.kd
    assert kd.texture == TextureImage(NOISE)
    np.testing.assert_allclose(kd.scale, np.array([255, 128, 64]) / 255 / np.pi)
    box.visual = trimesh.visual.TextureVisuals(material=trimesh.visual.material.PBRMaterial(baseColorTexture=image))
    assert isinstance(glphong.Scene.from_trimesh(trimesh.Scene(box)).objects[0].material.kd, tuple)  # no UVs: the colour


def test_gltf_texture_transform_moves_the_uvs(tmp_path):
    """KHR_texture_transform (offset, rotation, scale) applied to the mesh's uvs, in glTF's uv space, written here
    from the extension's definition: u' = sx cos(r) u + sy sin(r) v + ox, v' = -sx sin(r) u + sy cos(r) v + oy."""
    import json

    path = _marker_gltf(tmp_path, with_colors=False)
    gltf = tmp_path / "moved.gltf"
    document, binary = _glb_parts(path)
    (tmp_path / "moved.bin").write_bytes(binary)
    document["buffers"][0]["uri"] = "moved.bin"
    plain = tmp_path / "plain.gltf"
    plain.write_text(json.dumps(document))
    ox, oy, sx, sy, r = 0.25, -0.5, 2.0, 3.0, 0.3
    info = document["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]
    info["extensions"] = {"KHR_texture_transform": {"offset": [ox, oy], "scale": [sx, sy], "rotation": r}}
    document["extensionsUsed"] = ["KHR_texture_transform"]
    gltf.write_text(json.dumps(document))
    before = glphong.load_scene(plain, lights=[]).objects[0].mesh.uvs.astype(np.float64)
    after = glphong.load_scene(gltf, lights=[]).objects[0].mesh.uvs.astype(np.float64)
    u, v = before[:, 0], 1.0 - before[:, 1]  # glTF's v points down
    expected_u = sx * np.cos(r) * u + sy * np.sin(r) * v + ox
    expected_v = -sx * np.sin(r) * u + sy * np.cos(r) * v + oy
    np.testing.assert_allclose(after[:, 0], expected_u, atol=1e-6)
    np.testing.assert_allclose(1.0 - after[:, 1], expected_v, atol=1e-6)
    # the earlier approximation reads the same texture through the same transform; a material of the user's is theirs
    approximated = glphong.load_scene(gltf, lights=[], materials="cook_torrance").objects[0].mesh.uvs
    np.testing.assert_array_equal(approximated, after.astype(np.float32))
    own = glphong.load_scene(gltf, lights=[], materials=lambda name, entry: glphong.Lambert(0.3)).objects[0].mesh.uvs
    np.testing.assert_array_equal(own, before.astype(np.float32))
    for hostile in ({"rotation": "a lot"}, [1, 2], {"offset": {"a": 1, "b": 2}}):
        info["extensions"]["KHR_texture_transform"] = hostile
        gltf.write_text(json.dumps(document))
        with pytest.raises(glphong.filesafety.SceneFileError, match="KHR_texture_transform"):
            glphong.load_scene(gltf, lights=[])


def _glb_parts(path):
    """The JSON document and the binary chunk of a .glb file (written by trimesh)."""
    import json
    import struct

    data = path.read_bytes()
    length = struct.unpack_from("<I", data, 12)[0]
    document = json.loads(data[20:20 + length])
    binary = data[20 + length + 8:]
    return document, binary
