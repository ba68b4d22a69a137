"""
Tutorial: from a first render to a batch of frames
==================================================

A walk through glphong in the order a new user meets it: a first render, the cross-check against the
float64 twin, a material of your own, glphong inside pyrender, scene files, and many frames at once.
Every image on this page was rendered while the documentation was built, on Mesa's llvmpipe (no GPU),
at 128x96 pixels.

Run it as a script (``python examples/tutorial.py``; it needs matplotlib, in the ``[docs]``, ``[test]``
and ``[bench]`` extras), or cell by cell: each ``# %%`` line starts a cell in editors that know the format.
"""

# %%
# A first render
# --------------
#
# A scene is a camera, lights and objects, each object a mesh with a material.  Units are SI: a
# `PointLight` of power ``Phi`` [W] gives the irradiance ``E = Phi / (4 pi d^2)``, and the renderer returns
# linear radiance [W/(m^2 sr)] as float32, never clamped.  ``glphong.primitives.sphere`` is an icosphere
# with exact normals (and analytic tangents and UVs, which some models need).
import concurrent.futures
import shutil
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import glphong

camera = glphong.PerspectiveCamera.look_at(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), yfov=np.radians(45))
scene = glphong.Scene(camera,
                      lights=[glphong.PointLight(position=(2.0, 2.0, 2.0), power=100.0)],   # Phi [W]
                      ambient=glphong.AmbientLight(0.05))                                 # L_a
scene.add(glphong.primitives.sphere(4), glphong.Phong(kd=(0.2, 0.1, 0.05), ks=0.5, q=50))

renderer = glphong.Renderer(128, 96)          # offscreen: EGL or OSMesa, whichever works ("auto")
frame = renderer.render(scene, depth=True)
print(renderer)
print("radiance", frame.radiance.shape, frame.radiance.dtype, "peak", frame.radiance.max(), "W/(m^2 sr)")
print("covered pixels", frame.mask.sum(), "; depth from", frame.depth[frame.mask].min(), "m")


def show(images, titles, cmap=None):
    """Images side by side, at their own pixels."""
    fig, axes = plt.subplots(1, len(images), figsize=(2.6 * len(images), 2.2), squeeze=False)
    for ax, image, title in zip(axes[0], images, titles):
        shown = ax.imshow(image, cmap=cmap, interpolation="nearest")
        ax.set_title(title, fontsize=9)
        ax.set_axis_off()
        if cmap is not None:
            fig.colorbar(shown, ax=ax, fraction=0.046)
    fig.tight_layout()


# The 8-bit picture is the radiance times an exposure, through the exact sRGB curve.
show([frame.to_srgb8(exposure=1.0), frame.to_srgb8(exposure=4.0)], ["exposure 1", "exposure 4"])

# %%
# In a notebook a `Frame` shows itself (``Frame._repr_png_``, at ``frame.exposure``: see
# ``frame.with_exposure(4.0)``).  ``frame.save_png(path, exposure=...)`` writes the same picture and
# ``frame.save_npy(path)`` the raw float32 radiance.
#
# Verify: the GPU against the float64 twin
# ----------------------------------------
#
# `glphong.verify` renders the scene's G-buffer (the position, normal and material inputs each pixel was
# shaded with), evaluates the same equations in numpy float64 and checks every covered pixel against a
# float32 error band (docs/design.md section 4).  The report holds the error maps.
report = glphong.verify(scene, renderer)
print(report)
error = np.max(np.where(report.mask[..., None], report.relative_error, 0.0), axis=-1)   # NaN where uncovered
show([np.where(report.mask, np.log10(np.maximum(error, 1e-9)), np.nan)], ["log10 relative error"], cmap="viridis")

# %%
# A material of your own
# ----------------------
#
# A material model is one class: its parameters, its GLSL response ``f_r (n.l)`` and its numpy twin.  Here
# Minnaert's darkening law, ``f_r = k ((n.l)(n.v))^(m - 1)``, which the lunar limb follows.  glphong
# declares the uniforms ``u_minnaert_k`` and ``u_minnaert_m`` and checks the definition when the class is
# made (the page "Write your own material" has the whole contract).
from glphong.materials import MaterialModel, Param
from glphong.testing import assert_render_matches, assert_twin_matches


class Minnaert(MaterialModel):
    """Minnaert's darkening law: f_r = k ((n.l)(n.v))^(m - 1), 0 where the view is below the surface."""
    name = "minnaert"
    params = (Param("k", "rgb", low=0.0, unit="1/sr"),
              Param("m", "scalar", low=0.0, high=2.0, default=1.0))
    needs = ("view",)
    ambient = "k"
    vanishes_with = ("k",)
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


# its GLSL against its twin on seeded random and edge direction pairs, no scene needed
print(assert_twin_matches(Minnaert(k=0.25, m=0.6)))

moons = []
for material in (glphong.Lambert(kd=0.25), Minnaert(k=0.25, m=0.6)):
    moon = glphong.Scene(camera, lights=[glphong.DirectionalLight(direction=(-1.0, 0.0, -0.4), irradiance=2.0)])
    moon.add(glphong.primitives.sphere(4), material)
    print(assert_render_matches(moon, renderer))          # every pixel in the band of the float64 twin
    moons.append(renderer.render(moon).to_srgb8())
show(moons, ["Lambert", "Minnaert m = 0.6"])

# %%
# glphong inside pyrender
# -----------------------
#
# A pyrender user keeps their scene and ``OffscreenRenderer`` and gives the meshes they choose a
# ``GlphongMaterial``; ``enable(renderer)`` is the one glphong call.  pyrender picks its OpenGL platform
# once per process, when it is imported, so this page shows the code without running it (the page
# "glphong inside pyrender scenes" runs it in the test suite, and ``examples/pyrender_scene.py`` compares
# the two renderers)::
#
#     import os
#     os.environ["PYOPENGL_PLATFORM"] = "egl"            # or "osmesa"; before pyrender is imported
#     import numpy as np, pyrender, trimesh, glphong
#     from glphong.integrations.pyrender import GlphongMaterial, enable
#
#     scene = pyrender.Scene(ambient_light=[0.02, 0.02, 0.02])          # ambient_light is L_a
#     sphere = pyrender.Mesh.from_trimesh(trimesh.creation.icosphere(4),
#                                         material=GlphongMaterial(glphong.Phong(0.2, 0.5, 80)))
#     scene.add(sphere)
#     eye = np.eye(4)
#     eye[2, 3] = 3.0
#     scene.add(pyrender.PerspectiveCamera(yfov=np.radians(45)), pose=eye)
#     scene.add(pyrender.PointLight(color=[1.0, 1.0, 1.0], intensity=8.0), pose=eye)   # I [W/sr]: Phi = 4 pi I
#     renderer = pyrender.OffscreenRenderer(640, 480)
#     enable(renderer)
#     color, depth = renderer.render(scene)                             # (480, 640, 3) uint8, sRGB
#
# Install it with ``pip install "glphong[pyrender]"`` and, for pyrender's OSMesa platform,
# ``pip install --no-deps "PyOpenGL==3.1.10"``.
#
# Scene files
# -----------
#
# ``glphong.load_scene`` reads Wavefront OBJ with its MTL materials (glphong reads the MTL values itself,
# as written) and glTF 2.0; ``glphong.save_gltf`` writes a scene, glphong materials included, and
# ``load_scene`` reads it back.  Files are untrusted: a file may only name files in its own folder, sizes
# and image budgets are capped, and anything wrong is a ``glphong.filesafety.SceneFileError`` naming the
# file and where in it.  An OBJ file has no camera: glphong looks at its bounding sphere from 3 radii.
folder = Path(tempfile.mkdtemp(prefix="glphong-tutorial-"))
(folder / "pyramid.mtl").write_text("newmtl stone\nKd 0.6 0.5 0.4\nKs 0.3 0.3 0.3\nNs 40\nillum 2\n"
                                    "newmtl grass\nKd 0.1 0.4 0.1\nillum 1\n")
(folder / "pyramid.obj").write_text("mtllib pyramid.mtl\n"
                                    "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv 0 1.2 0\n"
                                    "v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\n"
                                    "usemtl stone\nf 1 5 2\nf 2 5 3\nf 3 5 4\nf 4 5 1\n"
                                    "usemtl grass\nf 6 9 8 7\n")
pyramid = glphong.load_scene(folder / "pyramid.obj", lights=[glphong.PointLight((2.0, 4.0, 3.0), 400.0)],
                             ambient=glphong.AmbientLight(0.1))
print([(obj.name, obj.material) for obj in pyramid.objects])

path = glphong.save_gltf(scene, folder / "sphere.glb")     # the first scene, as glTF with glphong extras
again = glphong.load_scene(path)
print(again.objects[0].material)
print("reloaded render differs by", np.abs(renderer.render(again).radiance - frame.radiance).max(), "W/(m^2 sr)")
show([renderer.render(pyramid).to_srgb8(), renderer.render(again).to_srgb8()], ["pyramid.obj", "sphere.glb"])

# %%
# Many frames: batches
# --------------------
#
# ``glphong.batch.render_many(scene_fn, specs, width, height, out_dir)`` renders one frame per spec
# (anything picklable: here camera angles) into ``out_dir``, as float32 ``.npy`` files (or PNG), each
# written atomically, with a manifest and a journal so that a rerun renders only what is missing and a
# different batch is never mixed in.  ``scene_fn`` is a picklable top-level function; ``turntable_scene``
# is a built-in one.  By default the frames are rendered by a pool of worker processes started with
# 'spawn' (call it under ``if __name__ == "__main__":`` in a script); any ``concurrent.futures``
# executor can be passed instead, and this page passes a thread pool, so that it builds in one process.
from glphong.batch import render_many, turntable_scene

angles = [0, 60, 120, 180]
with concurrent.futures.ThreadPoolExecutor(max_workers=1) as pool:
    paths = render_many(turntable_scene, angles, 128, 96, folder / "turntable", executor=pool, progress=False)
print([Path(p).name for p in paths])
frames = [np.load(p) for p in paths]
show([glphong.imaging.encode_srgb8(f) for f in frames], [f"{a} degrees" for a in angles])

# a second call with the same batch finds every frame and its journal record, and renders nothing
with concurrent.futures.ThreadPoolExecutor(max_workers=1) as pool:
    render_many(turntable_scene, angles, 128, 96, folder / "turntable", executor=pool, progress=False)

# %%
# A renderer holds a GL context: release it when done (or use ``with glphong.Renderer(...) as r:``).
renderer.release()
shutil.rmtree(folder)   # the files of this page
