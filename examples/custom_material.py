"""A material glphong does not ship, defined with the same public mechanism as the built-ins.

Minnaert's darkening law (Minnaert 1941, the lunar limb): ``f_r = k ((n.l)(n.v))^(m - 1)`` [1/sr],
so its response is ``f_r (n.l) = k (n.l)^m (n.v)^(m - 1)``, evaluated as those two powers (the product
``(n.l)(n.v)`` of two grazing cosines would underflow float32 before the power).  ``m = 1`` is Lambert with
``k_d = k``; ``m < 1`` brightens toward the limb (the Moon), ``m > 1`` darkens.  Where the viewer is
below the surface (``n.v <= 0``, a one-sided material seen from behind) nothing is reflected toward
it: the response is 0 there, by a select in GLSL and ``np.where`` in the twin (GLSL's
``pow(0, y)`` is undefined for ``y <= 0``, so the guard is part of the definition).

The script defines the model, checks its GLSL against its twin on seeded random and edge
directions, renders a scene with it next to glphong's Lambert, cross-checks every pixel against
the float64 twin, and (where pyrender is installed) draws it inside a pyrender scene.

Run:  python examples/custom_material.py [out.png]
      glphong stability --import examples/custom_material.py     (its extreme cases next to the built-ins')
Its tests (written with glphong.testing): tests/test_custom_material_example.py.
"""
import sys

import numpy as np

import glphong
from glphong import primitives
from glphong.materials import MaterialModel, Param, Properties


class Minnaert(MaterialModel):
    """Minnaert's darkening law: f_r = k ((n.l)(n.v))^(m - 1), 0 where n.v <= 0."""

    name = "minnaert"
    params = (Param("k", "rgb", low=0.0, unit="1/sr", doc="the BRDF value at m = 1 (a Lambert kd)"),
              Param("m", "scalar", low=0.0, high=2.0, default=1.0, doc="darkening exponent; 1 is Lambert"))
    needs = ("view",)
    ambient = "k"                        # answers the ambient light L_a with k L_a, as Lambert's kd L_a
    vanishes_with = ("k",)               # k = 0 compiles no Minnaert code
    properties = Properties(reciprocal=True, isotropic=True, energy_conserving=None,
                            condition="m = 1: pi k <= 1 (Lambert); not analysed for m != 1")
    glsl = """
    vec3 minnaert_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
    {
        float n_dot_v = dot(f.n, wo);
        vec3 value = u_minnaert_k * (pow(n_dot_l, u_minnaert_m) * pow(max(n_dot_v, 1e-30), u_minnaert_m - 1.0));
        return n_dot_v > 0.0 ? value : vec3(0.0);
    }"""

    def response(self, f, wi, wo, n_dot_l, p):
        n_dot_v = np.sum(f.n * wo, axis=-1)
        value = p.k * (n_dot_l ** p.m * np.maximum(n_dot_v, 1e-30) ** (p.m - 1.0))[..., None]
        return np.where((n_dot_v > 0)[..., None], value, 0.0)

    @classmethod
    def stability_cases(cls):
        """glphong's generic extreme geometry, at a limb-brightening and a darkening exponent."""
        from glphong.checks.stability import generic_cases

        return generic_cases("minnaert m=0.6", cls(k=0.25, m=0.6)) + generic_cases("minnaert m=1.5", cls(k=0.25, m=1.5))


def build_scene():
    """A Minnaert Moon (m = 0.6), a darkened Minnaert sphere (m = 1.5) and a Lambert one, on a Lambert floor."""
    camera = glphong.PerspectiveCamera.look_at((0.0, 1.2, 4.2), (0.0, 0.1, 0.0), yfov=np.radians(40))
    scene = glphong.Scene(camera, lights=[glphong.PointLight((-3.0, 2.5, 3.0), power=300.0),
                                          glphong.DirectionalLight((0.4, -1.0, -0.6), irradiance=0.4)],
                          ambient=glphong.AmbientLight(0.05))
    sphere = primitives.sphere(5, radius=0.55)
    for x, material in ((-1.25, Minnaert(k=0.25, m=0.6)), (0.0, Minnaert(k=0.25, m=1.5)), (1.25, glphong.Lambert(0.25))):
        pose = np.eye(4)
        pose[:3, 3] = (x, 0.1, 0.0)
        scene.add(sphere, material, pose=pose, name=f"{type(material).__name__} {x:+.2f}")
    floor = np.eye(4)
    floor[:3, :3] = [[1, 0, 0], [0, 0, 1], [0, -1, 0]]  # the plane's +z normal turned to +y
    floor[:3, 3] = (0.0, -0.45, 0.0)
    scene.add(primitives.plane(6.0), glphong.Lambert(0.12), pose=floor, name="floor")
    return scene


def main(out="custom_material.png"):
    from glphong.testing import assert_render_matches, assert_twin_matches

    for m in (0.6, 1.0, 1.5):
        figures = assert_twin_matches(Minnaert(k=0.25, m=m))
        print(f"Minnaert m={m}: GLSL against its twin on {figures['pairs']} direction pairs, "
              f"max rel err {figures['max_relative_error']:.2g}")
    scene = build_scene()
    with glphong.Renderer(480, 320) as renderer:
        report = assert_render_matches(scene, renderer)
        print(f"render cross-check: {report}")
        renderer.render(scene).save_png(out, exposure=1.0)
    print(f"wrote {out}")
    print(glphong.format_descriptions(glphong.describe(scene))[:600], "...")
    try:
        import pyrender  # noqa: F401
    except ImportError:
        print("pyrender not installed: skipping the embedding (pip install 'glphong[pyrender]')")
        return
    embed(scene)


def embed(scene, platform="egl"):
    """Draw the Minnaert spheres inside a pyrender scene with glphong's shading; returns the 8-bit image."""
    import os

    os.environ.setdefault("PYOPENGL_PLATFORM", platform)
    import pyrender
    import trimesh

    from glphong.integrations.pyrender import GlphongMaterial, enable

    pr = pyrender.Scene(ambient_light=[0.05, 0.05, 0.05], bg_color=[0, 0, 0, 1])
    for obj in scene.objects[:2]:
        mesh = trimesh.Trimesh(obj.mesh.positions, faces=obj.mesh.indices, vertex_normals=obj.mesh.normals, process=False)
        pr.add(pyrender.Mesh.from_trimesh(mesh, material=GlphongMaterial(obj.material, exposure=2.0)), pose=obj.pose)
    pr.add(pyrender.PerspectiveCamera(yfov=scene.camera.yfov), pose=scene.camera.pose)
    pr.add(pyrender.PointLight(color=[1, 1, 1], intensity=300.0 / (4 * np.pi)), pose=_translation(-3.0, 2.5, 3.0))
    renderer = pyrender.OffscreenRenderer(240, 160)
    try:
        enable(renderer)
        color, _ = renderer.render(pr)
    finally:
        renderer.delete()
    print(f"pyrender embedding: {int((color.sum(axis=2) > 0).sum())} lit pixels drawn by glphong's Minnaert")
    return color


def _translation(x, y, z):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


if __name__ == "__main__":
    main(*sys.argv[1:2])
