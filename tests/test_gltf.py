"""glTF 2.0 scenes (`glphong.load_scene` on ``.gltf`` / ``.glb``): the file's camera, its KHR_lights_punctual
lights in an explicit unit mode, node transforms and a documented approximation of its PBR materials.

The files are made here: trimesh exports the geometry and material, and the test adds a camera, lights and
their nodes to the JSON (nothing is downloaded).

- The camera's ``yfov``, ``znear``, ``zfar`` are read as written and its node's transform is the pose;
  a camera is found by name, an unknown name is refused naming the cameras.
- Point light of 683 cd, colour (1, 0.5, 0.25): ``Phi = 4 pi colour`` photometric, ``4 pi 683 colour``
  radiometric; a directional light of 683 lux travels along its node's -Z with ``E = colour`` (photometric).
- Lights without ``light_units`` are refused with what to do; spot lights load as `glphong.SpotLight`.
- ``baseColorFactor`` 0.123457 (not an 8-bit colour) reaches the material exactly; the scene passes verify;
  a ``.glb``'s JSON chunk is read; ``glphong render FILE.gltf --light-units --camera`` renders it.
"""
import json
import math

import numpy as np
import pytest
import trimesh

import glphong
from glphong.formats import gltf_view, read_gltf_json

BASE = [0.123457, 0.5, 0.75, 1.0]


def _document(tmp_path, spot=False):
    sphere = trimesh.creation.icosphere(3)
    sphere.visual = trimesh.visual.TextureVisuals(material=trimesh.visual.material.PBRMaterial(
        name="paint", baseColorFactor=BASE, metallicFactor=0.0, roughnessFactor=0.5))
    scene = trimesh.Scene()
    scene.add_geometry(sphere, node_name="ball", geom_name="ball")
    files = scene.export(file_type="gltf")
    document = json.loads(files["model.gltf"])
    for name, data in files.items():
        if name != "model.gltf":
            (tmp_path / name).write_bytes(data)
    document["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = BASE  # floats as written
    document["cameras"] = [{"name": "main", "type": "perspective",
                            "perspective": {"yfov": 0.7, "znear": 0.125, "zfar": 37.5, "aspectRatio": 1.5}}]
    lights = [{"type": "point", "color": [1.0, 0.5, 0.25], "intensity": 683.0, "name": "bulb"},
              {"type": "directional", "color": [0.5, 0.5, 0.5], "intensity": 683.0, "name": "sun"}]
    if spot:
        lights.append({"type": "spot", "name": "torch", "color": [1.0, 1.0, 0.5], "intensity": 1366.0, "range": 7.5,
                       "spot": {"innerConeAngle": 0.25, "outerConeAngle": 0.5}})
    document["extensions"] = {"KHR_lights_punctual": {"lights": lights}}
    document["extensionsUsed"] = ["KHR_lights_punctual"]
    half = math.sqrt(0.5)
    new_nodes = [{"name": "cam", "camera": 0, "translation": [0.0, 0.0, 5.0]},
                 {"name": "bulb", "translation": [2.0, 3.0, 4.0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
                 {"name": "sun", "rotation": [-half, 0.0, 0.0, half], "extensions": {"KHR_lights_punctual": {"light": 1}}}]
    if spot:
        new_nodes.append({"name": "torch", "translation": [0.0, 1.0, 2.0], "rotation": [-half, 0.0, 0.0, half],
                          "extensions": {"KHR_lights_punctual": {"light": 2}}})
    first = len(document["nodes"])
    document["nodes"] += new_nodes
    document["scenes"][document.get("scene", 0)]["nodes"] += list(range(first, first + len(new_nodes)))
    path = tmp_path / "scene.gltf"
    path.write_text(json.dumps(document))
    return path


def test_camera_lights_and_material(tmp_path, glphong_backend, glphong_make_renderer):
    path = _document(tmp_path)
    scene = glphong.load_scene(path, light_units="photometric")
    camera = scene.camera
    assert (camera.yfov, camera.znear, camera.zfar) == (0.7, 0.125, 37.5)
    np.testing.assert_allclose(camera.pose[:3, 3], [0.0, 0.0, 5.0])
    point, sun = sorted(scene.lights, key=lambda light: type(light).__name__ != "PointLight")
    np.testing.assert_allclose(point.position, [2.0, 3.0, 4.0])
    np.testing.assert_allclose(point.power, 4 * math.pi * np.array([1.0, 0.5, 0.25]), rtol=1e-15)
    np.testing.assert_allclose(sun.irradiance, [0.5, 0.5, 0.5], rtol=1e-15)
    np.testing.assert_allclose(sun.direction, [0.0, -1.0, 0.0], atol=1e-12)  # -Z turned by -90 degrees about x
    (ball,) = scene.objects
    assert isinstance(ball.material, glphong.GltfPBR)  # the specification's BRDF, by default
    assert ball.material.base_color == tuple(BASE[:3]) and ball.material.metallic == 0.0
    assert ball.material.roughness == 0.5 and ball.material.emissive == (0.0, 0.0, 0.0)
    approximation = glphong.load_scene(path, light_units="photometric", materials="cook_torrance").objects[0].material
    assert approximation.rho_d == tuple(BASE[:3]) and approximation.m == 0.25
    with pytest.raises(ValueError, match="the one name load_scene takes is 'cook_torrance'"):
        glphong.load_scene(path, light_units="photometric", materials="ggx")
    radiometric = glphong.load_scene(path, light_units="radiometric")
    power = next(light.power for light in radiometric.lights if hasattr(light, "power"))
    np.testing.assert_allclose(power, 4 * math.pi * 683.0 * np.array([1.0, 0.5, 0.25]), rtol=1e-15)
    assert glphong.verify(scene, glphong_make_renderer(48, 32, glphong_backend)).passed


def test_glb_and_named_camera(tmp_path):
    path = _document(tmp_path)
    loaded = trimesh.load(str(path), force="scene")
    glb = tmp_path / "scene.glb"
    glb.write_bytes(trimesh.exchange.gltf.export_glb(loaded))
    assert read_gltf_json(glb)["asset"]["version"] == "2.0"
    camera, lights = gltf_view(read_gltf_json(path), camera_name="main", light_units="photometric")
    assert camera.yfov == 0.7 and len(lights) == 2
    with pytest.raises(ValueError, match=r"no camera named 'side' \(cameras: \['main'\]\)"):
        gltf_view(read_gltf_json(path), camera_name="side", light_units="photometric")


def test_refusals(tmp_path):
    with pytest.raises(ValueError, match="light_units='photometric'"):
        glphong.load_scene(_document(tmp_path))
    (tmp_path / "bad.glb").write_bytes(b"glTF\x02\x00\x00\x00")
    with pytest.raises(ValueError, match="truncated glTF binary"):
        glphong.load_scene(tmp_path / "bad.glb")


def test_spot_light_loads_in_both_unit_modes(tmp_path, glphong_backend, glphong_make_renderer):
    """A KHR_lights_punctual spot light: position and -Z of its node, cone angles and range as written, intensity in
    candela / 683 (photometric) or as W/sr (radiometric)."""
    path = _document(tmp_path, spot=True)
    for units, scale in (("photometric", 1.0 / 683.0), ("radiometric", 1.0)):
        scene = glphong.load_scene(path, light_units=units)
        (spot,) = [light for light in scene.lights if isinstance(light, glphong.SpotLight)]
        np.testing.assert_allclose(spot.position, [0.0, 1.0, 2.0], atol=1e-12)
        np.testing.assert_allclose(spot.direction, [0.0, -1.0, 0.0], atol=1e-12)
        np.testing.assert_allclose(spot.intensity, 1366.0 * scale * np.array([1.0, 1.0, 0.5]), rtol=1e-15)
        assert (spot.inner_cone_angle, spot.outer_cone_angle, spot.range) == (0.25, 0.5, 7.5)
    assert glphong.verify(scene, glphong_make_renderer(48, 32, glphong_backend)).passed


def test_cli_render_gltf(tmp_path, capsys):
    from glphong.tools.cli import main

    path = _document(tmp_path)
    assert main(["render", str(path), "--light-units", "photometric", "--camera", "main", "--width", "32",
                 "--height", "24", "--verify", "--out", str(tmp_path / "g.png")]) == 0
    assert "PASS" in capsys.readouterr().out
    assert main(["render", str(path), "--out", str(tmp_path / "h.png")]) == 2
    assert "light_units" in capsys.readouterr().err


def test_material_extensions_ior_and_emissive_strength(tmp_path):
    """KHR_materials_ior becomes GltfPBR's ior; KHR_materials_emissive_strength multiplies emissiveFactor (photometric
    files: divided by 683, as their lights are); both validated with their JSON paths."""
    path = _document(tmp_path)
    document = json.loads(path.read_text())
    material = document["materials"][0]
    material["emissiveFactor"] = [0.5, 0.25, 1.0]
    material["extensions"] = {"KHR_materials_ior": {"ior": 1.33},
                              "KHR_materials_emissive_strength": {"emissiveStrength": 6.83}}
    path.write_text(json.dumps(document))
    loaded = glphong.load_scene(path, light_units="radiometric").objects[0].material
    assert loaded.ior == 1.33
    np.testing.assert_allclose(loaded.emissive, np.array([0.5, 0.25, 1.0]) * 6.83, rtol=1e-12)
    photometric = glphong.load_scene(path, light_units="photometric").objects[0].material
    np.testing.assert_allclose(photometric.emissive, np.array([0.5, 0.25, 1.0]) * 6.83 / 683.0, rtol=1e-12)
    material["extensions"]["KHR_materials_ior"]["ior"] = "glass"
    path.write_text(json.dumps(document))
    with pytest.raises(glphong.filesafety.SceneFileError, match=r"materials\[0\]\.extensions\.KHR_materials_ior\.ior"):
        glphong.load_scene(path, light_units="radiometric")


def test_gltf_pbr_material_reads_every_texture():
    """gltf_pbr_material with a texture reader: base colour sRGB times COLOR_0; metallic blue, roughness green of one
    linear image; emissive sRGB times factor and strength; occlusion 1 + strength (R - 1), baked linearly; the
    normal texture linear with its scale."""
    from glphong.formats import gltf_pbr_material
    from glphong.materials import TextureImage

    rng = np.random.default_rng(6)
    images = {k: rng.integers(0, 256, (4, 4, 4), dtype=np.uint8) for k in range(5)}

    def texture(info, srgb, alpha=False):
        pixels = images[info["index"]]
        return TextureImage(pixels[..., 3] if alpha else pixels, srgb=srgb)

    entry = {"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 1.0, 1.0], "baseColorTexture": {"index": 0},
                                      "metallicFactor": 0.5, "roughnessFactor": 0.8,
                                      "metallicRoughnessTexture": {"index": 1}},
             "emissiveFactor": [1.0, 0.5, 0.25], "emissiveTexture": {"index": 2},
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}},
             "occlusionTexture": {"index": 3, "strength": 0.5}, "normalTexture": {"index": 4, "scale": 0.7},
             "doubleSided": True}
    m = gltf_pbr_material(entry, texture, vertex_colors=True)
    assert m.base_color.scale == (0.5, 0.5, 1.0) and m.base_color.vertex_colors
    assert m.base_color.texture.encoding == "srgb8"
    assert (m.metallic.channel, m.metallic.scale, m.roughness.channel, m.roughness.scale) == ("b", 0.5, "g", 0.8)
    assert m.metallic.texture.encoding == "linear8" and m.metallic.texture is m.roughness.texture
    assert m.emissive.scale == (4.0, 2.0, 1.0) and m.emissive.texture.encoding == "srgb8"
    red = (images[3][..., 0] / 255.0).astype(np.float16).astype(np.float64)  # 8-bit texels are kept as float16
    np.testing.assert_allclose(m.occlusion.texture.levels[0][::-1, :, 0], 0.5 + 0.5 * red, rtol=1e-7)
    assert m.occlusion.channel == "r" and m.two_sided
    assert m.normal_map.scale == 0.7 and m.normal_map.texture.encoding == "linear8"
    assert gltf_pbr_material({"emissiveFactor": [0, 0, 0], "emissiveTexture": {"index": 2}}, texture).emissive == (0.0,) * 3
