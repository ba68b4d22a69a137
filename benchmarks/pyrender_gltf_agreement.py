"""glTF models drawn by pyrender and by glphong, lit by the same point light (issue 26): per model, the fraction of
covered pixels (both renderers cover them, one pixel in from every silhouette) where the two 8-bit images are within
one step in every channel.

Both sides draw the very same geometry and material: the file goes through trimesh into a ``pyrender.Scene``, and
glphong's scene is `glphong.integrations.pyrender.scene_from_pyrender(scene, convert=True)` of it (each
``MetallicRoughnessMaterial`` as `glphong.GltfPBR`, `gltf_pbr_of`).  glphong's radiance is encoded as pyrender encodes
its colour (``x^(1/2.2)``, clamped, rounded to 8 bits: `glphong.bench.pyrender_encode`), so the figures compare
shading only; ``--srgb`` compares glphong's own sRGB output instead.  pyrender runs on OSMesa (single-sampled: no
multisampled edges) by default.

Usage::

    python benchmarks/pyrender_gltf_agreement.py [FILE.gltf|FILE.glb ...] [--size 256] [--platform osmesa]

Without files it writes and measures a family of synthetic models (spheres of glTF materials: rough and smooth
dielectrics and metals, and a textured metallic-roughness sphere).
"""
import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import trimesh
from PIL import Image

from glphong.bench import import_pyrender, pyrender_encode


def synthetic_models(folder):
    """A family of .glb files: one sphere each, glTF materials from rough dielectric to smooth metal, one textured."""
    rng = np.random.default_rng(5)
    cases = {"dielectric rough": dict(baseColorFactor=[0.8, 0.3, 0.2, 1.0], metallicFactor=0.0, roughnessFactor=0.9),
             "dielectric glossy": dict(baseColorFactor=[0.2, 0.5, 0.8, 1.0], metallicFactor=0.0, roughnessFactor=0.3),
             "metal rough": dict(baseColorFactor=[0.95, 0.64, 0.54, 1.0], metallicFactor=1.0, roughnessFactor=0.6),
             "metal glossy": dict(baseColorFactor=[0.9, 0.9, 0.9, 1.0], metallicFactor=1.0, roughnessFactor=0.25),
             "half metal": dict(baseColorFactor=[0.5, 0.7, 0.3, 1.0], metallicFactor=0.5, roughnessFactor=0.5)}
    u, v = np.meshgrid(np.linspace(0, 1, 64), np.linspace(0, 1, 64))
    smooth = np.stack([0.2 + 0.7 * u, 0.3 + 0.5 * v, 0.9 - 0.6 * u * v], axis=-1)
    texture = Image.fromarray(np.rint(255 * smooth).astype(np.uint8))
    metal_rough = np.zeros((64, 64, 3), np.uint8)
    metal_rough[..., 1] = np.linspace(40, 255, 64, dtype=np.uint8)[None, :]  # roughness grows along u
    metal_rough[..., 2] = (np.indices((64, 64)).sum(0) // 16 % 2 * 255).astype(np.uint8)  # metal checks
    cases["textured"] = dict(baseColorTexture=texture, metallicRoughnessTexture=Image.fromarray(metal_rough),
                             metallicFactor=1.0, roughnessFactor=1.0)
    noise = Image.fromarray(rng.integers(0, 256, (64, 64, 3), dtype=np.uint8))  # where filtering order matters most
    cases["noise texture"] = dict(baseColorTexture=noise, metallicFactor=0.0, roughnessFactor=0.7)
    paths = []
    for name, material in cases.items():
        sphere = trimesh.creation.uv_sphere(radius=1.0, count=[48, 48])
        uv = np.stack([np.arctan2(sphere.vertices[:, 1], sphere.vertices[:, 0]) / (2 * np.pi) + 0.5,
                       np.arccos(np.clip(sphere.vertices[:, 2], -1, 1)) / np.pi], axis=1)
        sphere.visual = trimesh.visual.TextureVisuals(uv=uv, material=trimesh.visual.material.PBRMaterial(**material))
        path = Path(folder) / f"{name.replace(' ', '_')}.glb"
        trimesh.Scene(sphere).export(path)
        paths.append(path)
    return paths


def pyrender_model():
    """pyrender 0.1.45's own metallic-roughness BRDF (its mesh.frag, ``compute_brdf``) as a glphong `MaterialModel`,
    defined here with the public mechanism: what glphong draws when it shades as pyrender does.  It differs from
    Appendix B in five places (docs/pyrender.md): roughness clamped below at 0.04; the diffuse colour
    ``0.96 (1 - metallic) c`` weighted by ``1 - F`` with the specular ``F``; Schlick-Smith ``G`` with ``k = (r + 1)^2 /
    8`` instead of the height-correlated ``V``; ``+ 0.001`` in the specular denominator; ``n.l`` and ``n.v`` clamped
    below at 0.001."""
    from glphong.materials import MaterialModel, Param  # noqa: PLC0415

    class PyrenderPBR(MaterialModel):
        name = "pyrender_pbr"
        params = (Param("base_color", "rgb", low=0.0, high=1.0, textureable=True),
                  Param("metallic", "scalar", low=0.0, high=1.0, textureable=True),
                  Param("roughness", "scalar", low=0.0, high=1.0, textureable=True))
        needs = ("view",)
        glsl = """
        vec3 pyrender_pbr_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
        {
            float r = clamp(u_pyrender_pbr_roughness, 0.04, 1.0);
            float m = clamp(u_pyrender_pbr_metallic, 0.0, 1.0);
            vec3 c = u_pyrender_pbr_base_color;
            vec3 c_diff = c * 0.96 * (1.0 - m);
            vec3 f0 = mix(vec3(0.04), c, m);
            vec3 h = normalize(wi + wo);
            float nl = clamp(n_dot_l, 0.001, 1.0);
            float nv = clamp(abs(dot(f.n, wo)), 0.001, 1.0);
            float nh = clamp(dot(f.n, h), 0.0, 1.0);
            float vh = clamp(dot(wo, h), 0.0, 1.0);
            vec3 F = f0 + (1.0 - f0) * pow(clamp(1.0 - vh, 0.0, 1.0), 5.0);
            float k = (r + 1.0) * (r + 1.0) / 8.0;
            float G = nv / (nv * (1.0 - k) + k) * (nl / (nl * (1.0 - k) + k));
            float a2 = r * r * r * r;
            float d = nh * nh * (a2 - 1.0) + 1.0;
            float D = a2 / (3.141592653589793 * d * d);
            return nl * ((1.0 - F) * c_diff / 3.141592653589793 + F * G * D / (4.0 * nl * nv + 0.001));
        }"""

        def response(self, f, wi, wo, n_dot_l, p):
            def dot(a, b):
                return np.sum(a * b, axis=-1)

            r = np.clip(np.asarray(p.roughness, np.float64), 0.04, 1.0)[..., None]
            m = np.clip(np.asarray(p.metallic, np.float64), 0.0, 1.0)[..., None]
            c = np.asarray(p.base_color, np.float64)
            h = (wi + wo) / np.linalg.norm(wi + wo, axis=-1, keepdims=True)
            nl = np.clip(n_dot_l, 0.001, 1.0)[..., None]
            nv = np.clip(np.abs(dot(f.n, wo)), 0.001, 1.0)[..., None]
            nh = np.clip(dot(f.n, h), 0.0, 1.0)[..., None]
            vh = np.clip(dot(wo, h), 0.0, 1.0)[..., None]
            f0 = 0.04 * (1 - m) + c * m
            fresnel = f0 + (1 - f0) * (1 - vh) ** 5
            k = (r + 1) ** 2 / 8
            g = nv / (nv * (1 - k) + k) * (nl / (nl * (1 - k) + k))
            a2 = r ** 4
            d = a2 / (np.pi * (nh * nh * (a2 - 1) + 1) ** 2)
            return nl * ((1 - fresnel) * c * 0.96 * (1 - m) / np.pi + fresnel * g * d / (4 * nl * nv + 0.001))

    return PyrenderPBR


def _as_pyrender_model(scene, model):
    """``scene`` with each `GltfPBR` replaced by ``model`` of the same base colour, metallic and roughness."""
    import glphong  # noqa: PLC0415

    out = glphong.Scene(scene.camera, lights=list(scene.lights), ambient=scene.ambient)
    for obj in scene.objects:
        m = obj.material
        out.add(obj.mesh, model(m.base_color, m.metallic, m.roughness, two_sided=m.two_sided), pose=obj.pose,
                name=obj.name)
    return out


def _view(pyrender, tm_scene, width, height):
    """A pyrender scene of the file with a camera on +z of its bounds and a point light beside the camera."""
    scene = pyrender.Scene.from_trimesh_scene(tm_scene, ambient_light=[0.0, 0.0, 0.0], bg_color=[0.0, 0.0, 0.0, 0.0])
    low, high = tm_scene.bounds
    centre, radius = (low + high) / 2, max(float(np.linalg.norm(high - low)) / 2, 1e-6)
    distance = 2.6 * radius
    pose = np.eye(4)
    pose[:3, 3] = centre + (0.0, 0.0, distance)
    scene.add(pyrender.PerspectiveCamera(yfov=0.8, aspectRatio=width / height, znear=0.05 * radius,
                                         zfar=10 * distance), pose=pose)
    light = np.eye(4)
    light[:3, 3] = centre + np.array([0.6, 0.8, 1.0]) * distance
    scene.add(pyrender.PointLight(color=np.ones(3), intensity=1.2 * distance ** 2), pose=light)  # E ~ 1 at the centre
    return scene


def measure(path, size, platform, srgb=False):
    """``dict`` of the figures for one file."""
    pyrender = import_pyrender(platform)
    import glphong  # noqa: PLC0415 - after pyrender chose its platform
    from glphong.integrations.pyrender import release, scene_from_pyrender  # noqa: PLC0415

    width, height = size, size
    scene = _view(pyrender, trimesh.load(str(path), force="scene"), width, height)
    offscreen = pyrender.OffscreenRenderer(width, height)
    try:
        theirs, _ = offscreen.render(scene)
    finally:
        release(offscreen)  # on EGL without eglTerminate, which would end glphong's contexts too
    ours_scene = scene_from_pyrender(scene, convert=True)
    renderer = glphong.Renderer(width, height)
    out = {"file": Path(path).name, "materials": sorted({type(o.material).__name__ for o in ours_scene.objects})}
    variants = {"gltf": ours_scene}
    if all(isinstance(o.material, glphong.GltfPBR) for o in ours_scene.objects):
        if _PYRENDER_MODEL[0] is None:
            _PYRENDER_MODEL[0] = pyrender_model()
        variants["pyrender_brdf"] = _as_pyrender_model(ours_scene, _PYRENDER_MODEL[0])
    gbuffer = renderer.gbuffer(ours_scene)
    light = next(iter(ours_scene.lights)).position
    to_light = light - gbuffer.position
    facing = np.sum(gbuffer.normal * to_light, axis=-1) > 0  # n.l > 0: glphong's gate (pyrender lights n.l <= 0 too)
    for name, variant in variants.items():
        frame = renderer.render(variant)
        ours = renderer.render_srgb8(variant) if srgb else pyrender_encode(frame.radiance)
        covered = frame.mask & (theirs.max(axis=-1) > 0) | frame.mask & (ours.max(axis=-1) > 0)
        inner = covered.copy()
        for axis in (0, 1):
            for shift in (1, -1):
                inner &= np.roll(covered, shift, axis=axis)
        lit = facing[inner]
        difference = np.abs(theirs[..., :3].astype(int) - ours.astype(int)).max(axis=-1)[inner]
        out[name] = {"pixels": int(inner.sum()), "facing": float(np.mean(lit)) if inner.any() else float("nan"),
                     "within_one_facing": float(np.mean(difference[lit] <= 1)) if lit.any() else float("nan"),
                     "within_one": float(np.mean(difference <= 1)) if inner.any() else float("nan"),
                     "median": float(np.median(difference)) if inner.any() else float("nan"),
                     "p99": float(np.percentile(difference, 99)) if inner.any() else float("nan"),
                     "max": int(difference.max()) if inner.any() else 0}
    return out


#: the pyrender-BRDF model class, defined once per process
_PYRENDER_MODEL = [None]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="*")
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--platform", default="osmesa", choices=("osmesa", "egl"))
    parser.add_argument("--srgb", action="store_true", help="glphong's sRGB output instead of pyrender's encoding")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        files = args.files or synthetic_models(folder)
        print("within 1: the fraction of covered pixels within one 8-bit step (facing: of those with n.l > 0)")
        print(f"{'file':24s} {'pixels':>6s} {'n.l>0':>5s} | GltfPBR: {'within 1':>8s} {'facing':>6s} {'p99':>4s} "
              f"{'max':>4s} | pyrender's BRDF: {'within 1':>8s} {'facing':>6s} {'p99':>4s} {'max':>4s}")
        for path in files:
            try:
                r = measure(path, args.size, args.platform, args.srgb)
            except Exception as exc:  # noqa: BLE001 - a report over many files names what failed
                print(f"{Path(path).name:30s} failed: {type(exc).__name__}: {exc}"[:160])
                continue
            line = f"{r['file'][:24]:24s} {r['gltf']['pixels']:6d} {r['gltf']['facing']:5.2f}"
            for name in ("gltf", "pyrender_brdf"):
                if name in r:
                    f = r[name]
                    line += f" | {'':9s}{f['within_one']:8.3f} {f['within_one_facing']:6.3f} {f['p99']:4.0f} {f['max']:4d}"
                    line += " " * 7 if name == "gltf" else ""
            print(line + f"   {','.join(r['materials'])}")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
