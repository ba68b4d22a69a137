"""Check the files `glphong.save_gltf` writes with the Khronos glTF validator (issue 41; docs/scenes_from_files.md).

Writes, as ``.gltf`` and ``.glb``, scenes built here that cover what the writer saves (every ``KHR_materials_*``
extension glphong writes with and without its textures, normal and emissive textures, vertex colours, given
tangents, alpha MASK and BLEND, the non-glTF models' approximation, perspective, orthographic and intrinsics cameras,
point, spot and directional lights, several meshes and nodes sharing a mesh), and files written by hand in the forms
glphong reads (``KHR_texture_transform``, ``TEXCOORD_1``, ``KHR_materials_ior``, ``KHR_materials_variants``, 16-bit
indices, an external buffer and image) read by `glphong.load_scene` and written back; then runs the validator on each
and prints every message and the totals (exit status 1 where a file has an error or a warning).

The validator is the npm package ``gltf-validator`` (Node.js), which CI does not have: install it once outside the
repository (``mkdir -p /tmp/gv && cd /tmp/gv && npm install gltf-validator``) and run
``python benchmarks/gltf_validate.py --validator /tmp/gv [--keep FOLDER]``.  tests/test_gltf_conformance.py asserts the
rules whose breaking the validator reported, in Python, without it.
"""
import argparse
import base64
import io
import json
import pathlib
import shutil
import subprocess
import sys
import tempfile
import warnings

import numpy as np
from PIL import Image

import glphong
from glphong.scene.geometry import MeshData

_JS = r"""
const fs = require('fs'), path = require('path');
const validator = require(path.join(process.argv[2], 'node_modules', 'gltf-validator'));
(async () => {
  const out = [];
  for (const file of process.argv.slice(3)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: path.basename(file), maxIssues: 0,
      externalResourceFunction: (uri) => new Promise((resolve, reject) => fs.readFile(
        path.resolve(path.dirname(file), decodeURIComponent(uri)),
        (error, data) => error ? reject(String(error)) : resolve(new Uint8Array(data))))});
    out.push({file, version: report.validatorVersion, issues: report.issues.messages.map(m => ({
      code: m.code, severity: ['ERROR', 'WARNING', 'INFO', 'HINT'][m.severity], message: m.message,
      pointer: m.pointer}))});
  }
  console.log(JSON.stringify(out));
})();
"""


def _image(seed, channels=3, size=8):
    return np.random.default_rng(seed).integers(0, 256, (size, size, channels), dtype=np.uint8)


def _camera():
    return glphong.PerspectiveCamera.look_at((0.0, -4.0, 2.0), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0))


def _materials():
    """``{name: material}``: each extension glphong writes, untextured and textured, and the other kinds."""
    grey, rgba = _image(1), _image(2, 4)
    lin = dict(srgb=False)
    pbr = glphong.GltfPBR
    return {
        "core": pbr((0.8, 0.4, 0.2), 0.3, 0.6),
        "core_textured": pbr(glphong.Texture(grey, (0.9, 0.8, 0.7)), glphong.Texture(grey, 0.8, channel="b", **lin),
                             glphong.Texture(grey, 0.7, channel="g", **lin),
                             normal_map=glphong.NormalMap(_image(3), 0.8)),
        "emissive": pbr(0.5, 0.0, 0.5, emissive=(0.5, 0.2, 0.1)),
        "emissive_strength_textured": pbr(0.5, 0.0, 0.5, emissive=glphong.Texture(_image(4), (4.0, 2.0, 1.0))),
        "specular": pbr(0.5, 0.0, 0.5, specular=0.6, specular_color=(1.0, 0.8, 0.6)),
        "specular_textured": pbr(0.5, 0.0, 0.5, specular=glphong.Texture(grey, 0.6, channel="r", **lin),
                                 specular_color=glphong.Texture(_image(5), (1.0, 0.9, 0.8))),
        "clearcoat": pbr(0.5, 0.0, 0.5, clearcoat=0.8, clearcoat_roughness=0.2),
        "clearcoat_textured": pbr(0.5, 0.0, 0.5, clearcoat=glphong.Texture(grey, 0.8, channel="r", **lin),
                                  clearcoat_roughness=glphong.Texture(grey, 0.3, channel="g", **lin),
                                  clearcoat_normal=glphong.Texture(_image(6), 1.0, **lin),
                                  clearcoat_normal_strength=0.5),
        "sheen": pbr(0.5, 0.0, 0.5, sheen_color=(0.6, 0.3, 0.2), sheen_roughness=0.4),
        "sheen_textured": pbr(0.5, 0.0, 0.5, sheen_color=glphong.Texture(_image(7), (1.0, 0.8, 0.9)),
                              sheen_roughness=glphong.Texture(grey, 0.6, channel="g", **lin)),
        "anisotropy": pbr(0.5, 0.0, 0.5, anisotropy_strength=0.6, anisotropy_rotation=0.4),
        "anisotropy_textured": pbr(0.5, 0.0, 0.5, anisotropy_strength=glphong.Texture(grey, 0.9, channel="b", **lin),
                                   anisotropy_direction=glphong.Texture(grey, 1.0, **lin), anisotropy_rotation=0.3),
        "iridescence": pbr(0.5, 0.0, 0.5, iridescence=0.8, iridescence_ior=1.4, iridescence_thickness_mix=0.5),
        "iridescence_textured": pbr(0.5, 0.0, 0.5, iridescence=glphong.Texture(grey, 0.9, channel="r", **lin),
                                    iridescence_thickness_mix=glphong.Texture(grey, 1.0, channel="g", **lin)),
        "transmission": pbr(0.9, 0.0, 0.1, transmission=0.9, ior=1.45),
        "transmission_textured": pbr(0.9, 0.0, 0.1, transmission=glphong.Texture(grey, 0.9, channel="r", **lin)),
        "volume_dispersion": pbr(0.9, 0.0, 0.1, transmission=1.0, thickness=0.3, attenuation_distance=0.7,
                                 attenuation_color=(0.9, 0.6, 0.3), dispersion=0.4),
        "volume_textured": pbr(0.9, 0.0, 0.1, transmission=1.0,
                               thickness=glphong.Texture(grey, 0.3, channel="g", **lin)),
        "diffuse_transmission": pbr(0.5, 0.0, 0.5, diffuse_transmission=0.6,
                                    diffuse_transmission_color=(0.9, 0.5, 0.2)),
        "diffuse_transmission_textured": pbr(0.5, 0.0, 0.5,
                                             diffuse_transmission=glphong.Texture(rgba, 0.6, channel="b", **lin),
                                             diffuse_transmission_color=glphong.Texture(_image(8), (0.9, 0.5, 0.2))),
        "every_layer": pbr(0.5, 0.2, 0.5, specular=0.7, clearcoat=0.5, sheen_color=0.3, iridescence=0.5,
                           transmission=0.5, thickness=0.2, emissive=2.0),
        "mask": pbr(glphong.Texture(rgba), 0.0, 0.5, alpha_mask=glphong.AlphaMask(0.4, 0.8)),
        "blend": pbr(0.5, 0.0, 0.5, alpha_blend=glphong.AlphaBlend(0.5)),
        "lambert_textured": glphong.Lambert(glphong.Texture(_image(9)), normal_map=glphong.NormalMap(_image(3))),
        "phong": glphong.Phong(0.3, 0.2, 20.0),
        "blinn_phong_blend": glphong.BlinnPhong(0.3, 0.2, 20.0, alpha_blend=glphong.AlphaBlend(0.7)),
        "vertex_colours": glphong.Lambert(glphong.VertexColors(0.8)),
    }


def _scenes():
    """``{name: Scene}``: one object per material, and scenes of several objects, cameras and lights."""
    sphere, quad = glphong.primitives.sphere(2), glphong.primitives.plane()
    rng = np.random.default_rng(0)
    coloured = MeshData(sphere.positions, sphere.normals, sphere.indices, uvs=sphere.uvs,
                        colors=rng.uniform(0, 1, (len(sphere.positions), 3)))
    scenes = {}
    for name, material in _materials().items():
        scene = glphong.Scene(_camera(), [glphong.PointLight((1.0, -2.0, 3.0), 20.0)])
        scene.add(coloured if name == "vertex_colours" else sphere, material, name=name)
        scenes[name] = scene
    many = glphong.Scene(glphong.OrthographicCamera(2.0, pose=_camera().pose),
                         [glphong.PointLight((1.0, -2.0, 3.0), 20.0, range=10.0),
                          glphong.SpotLight((0, 0, 3), (0, 0, -1), 3.0, 0.2, 0.5, range=8.0),
                          glphong.DirectionalLight((0.3, 0.2, -1.0), 2.0)],
                         ambient=glphong.AmbientLight((0.1, 0.1, 0.1)))
    shared = glphong.GltfPBR(0.5, 0.0, 0.5)
    for k in range(3):  # one mesh, three nodes
        many.add(sphere, shared, pose=np.diag([1.0, 1.0, 1.0, 1.0]) + np.eye(4, k=3) * k, name=f"sphere{k}")
    many.add(quad, glphong.Lambert(0.5), name="floor")
    scenes["several_objects_lights_orthographic"] = many
    bare = MeshData(quad.positions, quad.normals * 3.0, quad.indices)  # no uvs nor tangents; normals of length 3
    skew = MeshData(quad.positions, quad.normals, quad.indices, uvs=quad.uvs,
                    tangents=[[2.0, 0.0, 0.0, -5.0], [0, 0, 0, 1], [1, 1, 0, 1], [0.5, 0, 0, 0]])  # lengths, w, zero
    odd = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0)),
                        [glphong.UnattenuatedPointLight((0.0, 0.0, 2.0), 1.0)])  # a light glTF has no kind for
    odd.add(bare, glphong.Lambert(0.5), pose=np.eye(4), name="bare")
    odd.add(skew, glphong.GltfPBR(0.5, 0.0, 0.5, normal_map=glphong.NormalMap(_image(3), wrap="clamp",
                                                                              filter="bilinear")), name="skew")
    odd.add(skew, glphong.Phong(glphong.Texture(_image(12, 4), wrap="clamp", filter="bilinear"), 0.2, 8.0,
                                alpha_mask=glphong.AlphaMask(0.5)), name="skew_again")  # one mesh, two materials
    odd.add(quad, glphong.CookTorrance(0.3, 0.2, glphong.SchlickFresnel(0.04)), name="cook_torrance")
    scenes["bare_mesh_odd_tangents_sum"] = odd
    scenes["empty"] = glphong.Scene(_camera(), [])
    intrinsics = glphong.IntrinsicsCamera(500.0, 500.0, 330.0, 230.0, 640, 480, pose=_camera().pose)
    scenes["intrinsics_camera"] = glphong.Scene(intrinsics, [])
    scenes["intrinsics_camera"].add(quad, glphong.Lambert(0.5), name="quad")
    return scenes


def _hand_file(folder, name, material, extra=None, uv_set=0, external=False):
    """A quad written by hand (16-bit indices, uvs in ``TEXCOORD_<uv_set>``) with ``material`` and two images; the
    buffer and the images in files beside it where ``external``."""
    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    normals = np.tile(np.array([0, 0, 1], np.float32), (4, 1))
    uvs = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
    indices = np.array([0, 1, 2, 0, 2, 3], np.uint16)
    blob = positions.tobytes() + normals.tobytes() + uvs.tobytes() + indices.tobytes() + bytes(4)
    attributes = {"POSITION": 0, "NORMAL": 1, **{f"TEXCOORD_{k}": 2 for k in range(uv_set + 1)}}
    document = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": 3, "material": 0}]}],
        "materials": [material],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0],
                       "max": [1, 1, 0]}, {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
                      {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}],
        "bufferViews": [{"buffer": 0, "byteOffset": offset, "byteLength": length, "target": target}
                        for offset, length, target in ((0, 48, 34962), (48, 48, 34962), (96, 32, 34962),
                                                       (128, 12, 34963))],
        "buffers": [{"byteLength": len(blob)}], "images": [], "textures": [], "samplers": [{}]}
    for k, pixels in enumerate((_image(10), _image(11, 4))):
        png = io.BytesIO()
        Image.fromarray(pixels).save(png, format="PNG")
        if external:
            (folder / f"{name}_{k}.png").write_bytes(png.getvalue())
            document["images"].append({"uri": f"{name}_{k}.png"})
        else:
            document["images"].append({"uri": "data:image/png;base64," + base64.b64encode(png.getvalue()).decode()})
        document["textures"].append({"source": k, "sampler": 0})
    if external:
        (folder / f"{name}.bin").write_bytes(blob)
        document["buffers"][0]["uri"] = f"{name}.bin"
    else:
        document["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode()
    document.update(extra or {})
    used = {key for m in document["materials"] for key in m.get("extensions", {})}
    used |= {"KHR_texture_transform"} if "KHR_texture_transform" in json.dumps(material) else set()
    used |= set(document.get("extensions", {}))
    if used:
        document["extensionsUsed"] = sorted(used)
    path = folder / f"{name}.gltf"
    path.write_text(json.dumps(document))
    return path


def _hand_files(folder):
    """Files in forms glphong reads but does not write itself."""
    shift = {"extensions": {"KHR_texture_transform": {"offset": [0.25, 0.0], "rotation": 0.3, "scale": [2.0, 1.0]}}}
    base = {"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.4, 0.3, 1.0], "metallicFactor": 0.0,
                                     "roughnessFactor": 0.5, "baseColorTexture": {"index": 0, **shift}},
            "normalTexture": {"index": 0, "scale": 0.7, **shift}, "occlusionTexture": {"index": 0, **shift},
            "emissiveTexture": {"index": 0, **shift}, "emissiveFactor": [1.0, 0.5, 0.2]}
    second = {"pbrMetallicRoughness": {"baseColorTexture": {"index": 1, "texCoord": 1}}, "alphaMode": "MASK"}
    ior = {"pbrMetallicRoughness": {"metallicFactor": 0.0},
           "extensions": {"KHR_materials_ior": {"ior": 1.33}, "KHR_materials_transmission": {"transmissionFactor": 1.0},
                          "KHR_materials_specular": {"specularTexture": {"index": 1},
                                                     "specularColorTexture": {"index": 0}},
                          "KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatNormalTexture": {"index": 0}}}}
    variants = {"extensions": {"KHR_materials_variants": {"variants": [{"name": "red"}, {"name": "blue"}]}}}
    paths = [_hand_file(folder, "hand_texture_transform", base),
             _hand_file(folder, "hand_texcoord_1", second, uv_set=1),
             _hand_file(folder, "hand_ior_transmission", ior, external=True),
             _hand_file(folder, "hand_variants", base, extra=variants)]
    document = json.loads(paths[-1].read_text())  # the variants' mappings, and their second material
    document["materials"].append({"pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.9, 1.0]}})
    document["meshes"][0]["primitives"][0]["extensions"] = {"KHR_materials_variants": {"mappings": [
        {"material": 0, "variants": [0]}, {"material": 1, "variants": [1]}]}}
    paths[-1].write_text(json.dumps(document))
    return paths


def write_files(folder):
    """Write every scene of `_scenes` as ``.gltf`` and ``.glb``, and every file of `_hand_files` read and written
    back (both suffixes; the blue variant too); the list of the written paths (the hand-written inputs are not in
    it)."""
    folder = pathlib.Path(folder)
    written = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the writer's own (an intrinsics camera, a textured alpha): expected here
        for name, scene in _scenes().items():
            written += [glphong.save_gltf(scene, folder / f"{name}{suffix}") for suffix in (".gltf", ".glb")]
        for path in _hand_files(folder):
            variants = ("", "blue") if "variants" in path.name else ("",)
            for variant in variants:
                scene = glphong.load_scene(path, light_units="radiometric", variant=variant or None)
                stem = f"saved_{path.stem}" + (f"_{variant}" if variant else "")
                written += [glphong.save_gltf(scene, folder / f"{stem}{suffix}") for suffix in (".gltf", ".glb")]
    return written


def validate(paths, validator):
    """The validator's reports of ``paths`` (list of dict: ``file``, ``version``, ``issues``)."""
    with tempfile.NamedTemporaryFile("w", suffix=".js", delete=False) as script:
        script.write(_JS)
    result = subprocess.run(["node", script.name, str(pathlib.Path(validator).resolve()), *map(str, paths)],
                            capture_output=True, text=True, check=True)
    pathlib.Path(script.name).unlink()
    return json.loads(result.stdout)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--validator", default="/tmp/gv", help="the folder where `npm install gltf-validator` ran")
    parser.add_argument("--keep", help="write the files here (kept) instead of a temporary folder")
    args = parser.parse_args()
    if shutil.which("node") is None or not (pathlib.Path(args.validator) / "node_modules" / "gltf-validator").is_dir():
        print(f"needs node and `npm install gltf-validator` run in {args.validator} (--validator)", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory() as scratch:
        folder = pathlib.Path(args.keep or scratch)
        folder.mkdir(parents=True, exist_ok=True)
        reports = validate(write_files(folder), args.validator)
    counts = {"ERROR": 0, "WARNING": 0, "INFO": 0, "HINT": 0}
    for report in reports:
        for issue in report["issues"]:
            counts[issue["severity"]] += 1
            where = issue.get("pointer", "")
            print(f"{pathlib.Path(report['file']).name}: {issue['severity']} {issue['code']} {where}: {issue['message']}")
    version = reports[0]["version"] if reports else "?"
    print(f"gltf-validator {version}: {len(reports)} files, {counts['ERROR']} errors, {counts['WARNING']} warnings, "
          f"{counts['INFO']} infos, {counts['HINT']} hints")
    return 1 if counts["ERROR"] or counts["WARNING"] else 0


if __name__ == "__main__":
    sys.exit(main())
