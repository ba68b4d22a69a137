"""Alpha testing (glphong.AlphaMask; glTF's alphaMode MASK); BLEND's loading (its rendering: tests/test_blend.py).

Independent check: a plane whose alpha texture is two texels, opaque left and clear right, sampled bilinearly and
clamped: alpha falls linearly from 1 at u = 0.25 to 0 at u = 0.75, so with cutoff 0.5 exactly the fragments with
u < 0.5 are drawn.  The expected mask is computed here from the uv of an unmasked G-buffer; every pixel agrees but
those within 1e-3 of u = 0.5.
"""
import json

import numpy as np
import pytest
import trimesh
from PIL import Image

import glphong
from glphong import primitives
from glphong.definitions.surface import alpha_masked
from glphong.scene.geometry import MeshData

HALF = np.array([[255, 0]], np.uint8)  # one row: opaque, clear


def _plane_scene(material):
    plane = primitives.plane(size=2.0, segments=2)
    mesh = MeshData(plane.positions, plane.normals, plane.indices, uvs=plane.uvs)
    camera = glphong.PerspectiveCamera.look_at((0.2, -0.3, 2.4), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, [glphong.PointLight((0.5, 0.5, 1.5), 20.0)], ambient=glphong.AmbientLight(0.1))
    scene.add(mesh, material)
    return scene


@pytest.mark.parametrize("shading", ["pixel", "vertex"])
def test_the_mask_is_where_alpha_reaches_the_cutoff(shading, glphong_backend, glphong_make_renderer):
    alpha = glphong.Texture(HALF, 1.0, srgb=False, channel="r", wrap="clamp", filter="bilinear")
    masked = glphong.GltfPBR(0.6, 0.0, 0.5, alpha_mask=glphong.AlphaMask(0.5, alpha))
    renderer = glphong_make_renderer(96, 72, glphong_backend)
    plain = renderer.gbuffer(_plane_scene(glphong.GltfPBR(glphong.Texture(HALF), 0.0, 0.5)))  # a G-buffer with uv
    expected = plain.mask & (plain.uv[..., 0] < 0.5)
    clear_cut = np.abs(plain.uv[..., 0] - 0.5) > 1e-3
    vertex = glphong.Renderer(96, 72, backend=glphong_backend, shading="vertex") if shading == "vertex" else None
    frame = (vertex or renderer).render(_plane_scene(masked))
    assert expected.sum() > 1000 and (plain.mask & ~expected).sum() > 1000
    np.testing.assert_array_equal(frame.mask[clear_cut], expected[clear_cut])
    # the twin of the GLSL alpha test agrees with the formula written here, on the same G-buffer fragments
    uv = plain.uv[plain.mask].astype(np.float64)
    twin = ~alpha_masked(uv, np.zeros(len(uv)), masked.alpha_mask)
    np.testing.assert_array_equal(twin[clear_cut[plain.mask]], expected[plain.mask][clear_cut[plain.mask]])
    if vertex is not None:
        vertex.release()
        return
    report = glphong.verify(_plane_scene(masked), renderer)  # the G-buffer is masked alike: no mask mismatch
    assert report.passed and report.mask_mismatch == 0, report.summary()


def test_constant_alpha_draws_all_or_nothing(glphong_make_renderer):
    renderer = glphong_make_renderer(48, 36, "egl")
    below = renderer.render(_plane_scene(glphong.Lambert(0.2, alpha_mask=glphong.AlphaMask(0.5, 0.49))))
    above = renderer.render(_plane_scene(glphong.Lambert(0.2, alpha_mask=glphong.AlphaMask(0.5, 0.5))))
    opaque = renderer.render(_plane_scene(glphong.Lambert(0.2)))
    assert not below.mask.any()
    np.testing.assert_array_equal(above.mask, opaque.mask)
    np.testing.assert_array_equal(above.radiance, opaque.radiance)


def test_refusals_and_program_keys():
    with pytest.raises(ValueError, match="one channel of a texture"):
        glphong.AlphaMask(0.5, glphong.Texture(HALF))
    with pytest.raises(ValueError, match="channel='g'"):  # the GLSL reads red: another channel would be ignored
        glphong.AlphaMask(0.5, glphong.Texture(HALF, srgb=False, channel="g"))
    with pytest.raises(ValueError, match="alpha"):
        glphong.AlphaMask(0.5, 1.5)
    with pytest.raises(TypeError, match="alpha_mask must be a glphong.AlphaMask"):
        glphong.Lambert(0.2, alpha_mask=0.5)
    scene = _plane_scene(glphong.Lambert(0.2, alpha_mask=glphong.AlphaMask(0.5, 0.7)))
    with pytest.raises(ValueError, match="alpha mask"):
        glphong.Renderer(16, 16, specialise=False).render(scene)
    from glphong.shaders.key import program_key

    assert program_key(glphong.Lambert(0.2), {"point": 1}, None).alpha_mask == 0
    textured = glphong.Lambert(0.2, alpha_mask=glphong.AlphaMask(0.5, glphong.Texture(HALF, srgb=False, channel="r")))
    key = program_key(textured, {"point": 1}, None)
    assert key.alpha_mask == 2 and key.has_uv and ("ALPHA_MASK", "2") in key.defines()


def _gltf(tmp_path, mode, cutoff=None):
    rgba = np.zeros((4, 4, 4), np.uint8)
    rgba[..., :3] = 200
    rgba[:, :2, 3] = 255  # the left half opaque
    quad = trimesh.Trimesh([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]], process=False)
    material = trimesh.visual.material.PBRMaterial(name="leaf", baseColorTexture=Image.fromarray(rgba, "RGBA"),
                                                   baseColorFactor=[255, 255, 255, 204], metallicFactor=0.0)
    quad.visual = trimesh.visual.TextureVisuals(uv=np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float), material=material)
    files = trimesh.Scene(quad).export(file_type="gltf")
    document = json.loads(files["model.gltf"])
    for name, data in files.items():
        if name != "model.gltf":
            (tmp_path / name).write_bytes(data)
    document["materials"][0]["alphaMode"] = mode
    if cutoff is not None:
        document["materials"][0]["alphaCutoff"] = cutoff
    path = tmp_path / f"{mode}.gltf"
    path.write_text(json.dumps(document))
    return path


def test_gltf_alpha_modes(tmp_path):
    material = glphong.load_scene(_gltf(tmp_path, "MASK", 0.3), lights=[]).objects[0].material
    mask = material.alpha_mask
    assert mask.cutoff == 0.3 and mask.alpha.channel == "r" and mask.alpha.scale == pytest.approx(204 / 255, abs=1e-6)
    np.testing.assert_array_equal(mask.alpha.texture.levels[0][..., 0][::-1][:, :2], 1.0)  # the texture's alpha
    np.testing.assert_array_equal(mask.alpha.texture.levels[0][..., 0][::-1][:, 2:], 0.0)
    assert glphong.load_scene(_gltf(tmp_path, "OPAQUE"), lights=[]).objects[0].material.alpha_mask is None
    blend = glphong.load_scene(_gltf(tmp_path, "BLEND"), lights=[]).objects[0].material.alpha_blend  # tests/test_blend.py
    assert blend.textured and blend.alpha.scale == pytest.approx(204 / 255, abs=1e-6)
    np.testing.assert_array_equal(blend.alpha.texture.levels[0][..., 0][::-1][:, 2:], 0.0)


def test_masked_and_normal_mapped_materials_survive_save_gltf(tmp_path):
    """The glphong material stored in the file's extras keeps its alpha mask and normal map (textures by index)."""
    alpha = glphong.Texture(np.array([[255, 0], [0, 255]], np.uint8), 0.8, srgb=False, channel="r")
    normals = np.full((4, 4, 3), (128, 160, 230), np.uint8)
    material = glphong.GltfPBR(0.5, 0.2, 0.6, alpha_mask=glphong.AlphaMask(0.4, alpha),
                               normal_map=glphong.NormalMap(normals, 0.5))
    scene = _plane_scene(material)
    with pytest.warns(UserWarning, match="textured alpha is written in glphong's extras only"):
        glphong.save_gltf(scene, tmp_path / "saved.glb")
    loaded = glphong.load_scene(tmp_path / "saved.glb").objects[0].material
    assert loaded == material


def test_save_gltf_writes_the_gltf_material_for_other_viewers(tmp_path):
    """A GltfPBR is written as glTF's own material (not only in extras): factors, the shared metallic-roughness
    texture, emissive with its strength, the normal texture and the alpha mode; read without the extras, the file
    gives the same factors."""
    mr = np.zeros((4, 4, 3), np.uint8)
    mr[..., 1], mr[..., 2] = 200, 100
    image = glphong.materials.TextureImage(mr, srgb=False)
    material = glphong.GltfPBR(0.5, glphong.Texture(image, 0.75, channel="b"), glphong.Texture(image, 0.5, channel="g"),
                               emissive=(2.0, 1.0, 0.0), alpha_mask=glphong.AlphaMask(0.4, 0.9),
                               normal_map=glphong.NormalMap(np.full((2, 2, 3), (128, 128, 255), np.uint8), 0.5))
    glphong.save_gltf(_plane_scene(material), tmp_path / "out.gltf")
    document = json.loads((tmp_path / "out.gltf").read_text())
    (entry,) = document["materials"]
    pbr = entry["pbrMetallicRoughness"]
    assert (pbr["metallicFactor"], pbr["roughnessFactor"], pbr["baseColorFactor"][3]) == (0.75, 0.5, 0.9)
    assert "metallicRoughnessTexture" in pbr and entry["normalTexture"]["scale"] == 0.5
    assert entry["emissiveFactor"] == [1.0, 0.5, 0.0]
    assert entry["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] == 2.0
    assert (entry["alphaMode"], entry["alphaCutoff"]) == ("MASK", 0.4)
    del entry["extras"]  # what another viewer (and glphong without the stored material) reads
    (tmp_path / "bare.gltf").write_text(json.dumps(document))
    bare = glphong.load_scene(tmp_path / "bare.gltf", lights=[]).objects[0].material
    assert (bare.metallic.scale, bare.roughness.scale, bare.emissive) == (0.75, 0.5, (2.0, 1.0, 0.0))
    assert bare.alpha_mask.cutoff == pytest.approx(0.4) and bare.normal_map.scale == 0.5


def test_save_gltf_asks_the_model_for_its_gltf_fields(tmp_path, monkeypatch):
    """The writer takes glTF's material from the model's own `gltf_fields` (no branch on a model's name): a model
    without it is approximated by its base colour (Lambert: pi kd), and a model that answers is written as it says."""
    glphong.save_gltf(_plane_scene(glphong.Lambert(0.2)), tmp_path / "phong.gltf")
    (entry,) = json.loads((tmp_path / "phong.gltf").read_text())["materials"]
    assert entry["pbrMetallicRoughness"]["baseColorFactor"][:3] == pytest.approx([0.2 * np.pi] * 3)
    assert (entry["pbrMetallicRoughness"]["metallicFactor"], "emissiveFactor" in entry) == (0.0, False)
    monkeypatch.setattr(glphong.Lambert, "gltf_fields", lambda self, texture_index: (
        {"baseColorFactor": [0.1, 0.2, 0.3, 1.0], "roughnessFactor": 0.25}, {"emissiveFactor": [0.0, 0.5, 0.0]}),
        raising=False)
    glphong.save_gltf(_plane_scene(glphong.Lambert(0.2)), tmp_path / "asked.gltf")
    (entry,) = json.loads((tmp_path / "asked.gltf").read_text())["materials"]
    assert entry["pbrMetallicRoughness"] == {"baseColorFactor": [0.1, 0.2, 0.3, 1.0], "roughnessFactor": 0.25}
    assert entry["emissiveFactor"] == [0.0, 0.5, 0.0]
