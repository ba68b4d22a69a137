"""The matte pass's error against run time (``glphong bench --matte``; docs/design.md section 15).

A family of scenes whose pixels hold edges of every kind (`matte_scenes`: two overlapping triangles, a sphere's edge,
interpenetrating meshes, an object partly outside the image, a camera from OpenCV intrinsics with its principal point
off centre) is drawn with ``matte_samples`` s = 4, 8, 16, 32, 64; each matte is compared with the exact coverage
(`glphong.checks.coverage_twin.exact_coverage`, float64) by `glphong.checks.verify_passes.matte_error`: the worst pixel
(the largest error of one object's share) and the RMS over the pixels whose exact coverage is partial (an edge
crosses them; elsewhere the matte is exact).  Each point's time is the median of the matte-only render, beside the
radiance-only render of the same scene, interleaved in one process.
"""
import numpy as np
import trimesh

from glphong.checks.coverage_twin import exact_coverage
from glphong.checks.verify_passes import matte_error
from glphong.core.timing import alternating_medians
from glphong.gpu.matte import MATTE_SAMPLES, matte_tolerance
from glphong.gpu.renderer import Renderer
from glphong.lights import PointLight
from glphong.materials.lambert import Lambert
from glphong.materials.phong import Phong
from glphong.scene import primitives
from glphong.scene.camera import IntrinsicsCamera, OrthographicCamera, PerspectiveCamera, opencv_pose
from glphong.scene.geometry import MeshData
from glphong.scene.scene import Scene

__all__ = ["MATTE_SAMPLE_VALUES", "matte_scenes", "matte_points", "format_matte"]

#: the samples per axis the row family measures
MATTE_SAMPLE_VALUES = (4, 8, 16, 32, 64)


def _flat(points):
    points = np.asarray(points, np.float32)
    faces = [[0, 1, 2]] if len(points) == 3 else [[0, 1, 2], [0, 2, 3]]
    return MeshData(points, np.tile([0.0, 0.0, 1.0], (len(points), 1)), np.asarray(faces, np.uint32))


def _box():
    return MeshData.from_trimesh(trimesh.creation.box((0.6, 0.5, 0.7)), smooth=False)


def _translated(x, y, z):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def _triangles():
    pose = np.eye(4)
    pose[2, 3] = 5.0
    scene = Scene(OrthographicCamera(1.5, pose=pose), [PointLight((0.0, 0.0, 3.0), 10.0)])
    scene.add(_flat([[-0.6, -1.4, 0.0], [1.9, 0.3, 0.0], [-1.2, 1.1, 0.0]]), Lambert(0.5), instance_id=4)
    scene.add(_flat([[-1.7, -1.3, 0.5], [1.45, -0.9, 0.5], [-0.2, 1.35, 0.5]]), Lambert(0.5), instance_id=2)
    return scene, (8, 6)


def _sphere_edge():
    camera = PerspectiveCamera.look_at((0.0, 0.3, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = Scene(camera, [PointLight((2.0, 2.0, 3.0), 50.0)])
    scene.add(primitives.sphere(3, 0.8), Phong(0.2, 0.4, 20.0))
    return scene, (48, 36)


def _interpenetrating():
    scene, size = _sphere_edge()
    scene.add(primitives.sphere(2, 0.4), Phong(0.2, 0.4, 20.0), pose=_translated(0.5, 0.1, 0.45))
    scene.add(_box(), Lambert(0.3), pose=_translated(-0.7, -0.4, 0.3))
    return scene, size


def _partly_outside():
    camera = PerspectiveCamera.look_at((0.9, 0.2, 2.2), (0.9, 0.2, 0.0), yfov=0.8)
    scene = Scene(camera, [PointLight((2.0, 2.0, 3.0), 50.0)])
    scene.add(primitives.sphere(3, 0.8), Phong(0.2, 0.4, 20.0))
    return scene, (48, 36)


def _opencv_off_centre():
    camera = IntrinsicsCamera(40.0, 38.0, 19.3, 11.8, 44, 30, pose=opencv_pose(np.eye(3), np.array([0.1, -0.05, 3.0])))
    scene = Scene(camera, [PointLight((2.0, 2.0, -3.0), 50.0)])
    scene.add(primitives.sphere(3, 0.7), Phong(0.2, 0.4, 20.0))
    scene.add(_box(), Lambert(0.3), pose=_translated(0.5, 0.3, -0.4))
    return scene, (44, 30)


def matte_scenes():
    """The row family's scenes: dict of name to ``(scene, (width, height))``."""
    return {"two overlapping triangles": _triangles(), "a sphere's edge": _sphere_edge(),
            "interpenetrating meshes": _interpenetrating(), "partly outside the image": _partly_outside(),
            "OpenCV intrinsics off centre": _opencv_off_centre()}


def matte_points(samples=MATTE_SAMPLE_VALUES, repeats=5, backend="egl", scenes=None):
    """Every (scene, s) point: the matte's error against the exact coverage and its frame time.

    Parameters
    ----------
    samples : sequence of int
        ``matte_samples`` values.
    repeats : int
        Timed repeats (median, interleaved with the radiance-only render).
    backend : str
    scenes : dict, optional
        Default `matte_scenes`.

    Returns
    -------
    list of dict
        ``case``, ``matte_samples``, ``worst`` (the largest error of a share), ``rms`` (over the pixels of partial
        exact coverage), ``tolerance`` (`glphong.gpu.matte.matte_tolerance`), ``seconds`` (the matte-only render),
        ``radiance_seconds``, ``pixels``.
    """
    rows = []
    for case, (scene, (width, height)) in (scenes or matte_scenes()).items():
        exact_ids, exact_fractions = exact_coverage(scene, width, height)
        total = exact_fractions.sum(axis=-1)
        partial = (exact_fractions > 0).sum(axis=-1) > 1
        partial |= (total > 0) & (total < 1)
        for s in samples:
            with Renderer(width, height, backend=backend, matte_samples=s) as renderer:
                times = alternating_medians({"matte": lambda: renderer.render(scene, passes=("matte",)),
                                             "radiance": lambda: renderer.render(scene)}, repeats)
                frame = renderer.render(scene, passes=("matte",))
            error = matte_error(frame.matte_ids, frame.matte_fractions, exact_ids, exact_fractions)
            rows.append({"case": case, "matte_samples": s, "worst": float(error.max()),
                         "rms": float(np.sqrt(np.mean(error[partial] ** 2))) if partial.any() else 0.0,
                         "tolerance": matte_tolerance(s), "seconds": times["matte"],
                         "radiance_seconds": times["radiance"], "pixels": width * height})
    return rows


def format_matte(rows):
    """The row family as a text table: per s, the worst pixel and RMS over the family, the time per megapixel."""
    lines = ["matte: error against the exact coverage, against run time (worst over the scenes; the default s = "
             f"{MATTE_SAMPLES}):",
             f"{'s':>4s} {'worst':>10s} {'1/worst':>8s} {'RMS':>10s} {'tolerance':>10s} {'ms/Mpx':>9s} {'x radiance':>11s}"]
    for s in sorted({r["matte_samples"] for r in rows}):
        pts = [r for r in rows if r["matte_samples"] == s]
        worst = max(r["worst"] for r in pts)
        rms = float(np.sqrt(np.mean([r["rms"] ** 2 for r in pts])))
        per_mpx = 1e9 * sum(r["seconds"] for r in pts) / sum(r["pixels"] for r in pts)
        ratio = sum(r["seconds"] for r in pts) / sum(r["radiance_seconds"] for r in pts)
        lines.append(f"{s:4d} {worst:10.3g} {1 / worst if worst else float('inf'):8.1f} {rms:10.3g} "
                     f"{pts[0]['tolerance']:10.3g} {per_mpx:9.1f} {ratio:10.1f}x")
    return "\n".join(lines)
