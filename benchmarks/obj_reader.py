"""OBJ reading cost: glphong's reader (`glphong.formats.obj.read_obj`) against trimesh's (not a test).

Writes three files into a folder, then reads each with each reader in fresh Python processes
(``--repeat`` of them, the least time and memory kept) and prints a table of peak memory and wall time:

- ``triangles_v_vt_vn.obj``: about 16 MB, a 290 x 290 grid with a ``v``, ``vt`` and ``vn`` per vertex
  and two ``f a/a/a b/b/b c/c/c`` triangles per cell (167,042 triangles);
- ``one_face_1e6_corners.obj``: 10^6 vertices on a circle and a single face line naming all of them
  (fanned into 999,998 triangles);
- ``plain_1m_faces.obj``: a 708 x 708 grid of ``v`` lines and 999,698 ``f a b c`` triangles.

Peak memory is ``resource.getrusage(RUSAGE_SELF).ru_maxrss`` after the read minus its value before it,
after the imports (numpy, trimesh, glphong.formats.obj) and a first read of a tiny OBJ file (so lazy
imports are paid before).  On Linux a process starts with its parent's peak as its own, so the files
are written by a separate process and the parent stays small.  trimesh reads with
``trimesh.load(path, force="mesh")``, which parses the whole file; it computes no vertex normals where
the file has none, glphong does (trimesh's corner-angle weighting), and its figures include them.

Measured on this box (2 cores shared with other work, whose load moves the times by up to 2x;
23 GB; Linux, Python 3.11, numpy 2.4.6, trimesh 5.2.0), ``--repeat 3``::

    file                      reader   peak MB   time s  triangles
    triangles_v_vt_vn.obj     glphong      109      0.80     167042
    triangles_v_vt_vn.obj     trimesh      131      0.88     167042
    one_face_1e6_corners.obj  glphong      241      2.62     999998
    one_face_1e6_corners.obj  trimesh      210      3.91     999998
    plain_1m_faces.obj        glphong      285      2.54     999698
    plain_1m_faces.obj        trimesh      254      3.03     999698

The previous glphong reader (a Python tuple per corner; ``--extra glphong.formats:read_obj`` while
`glphong.formats.read_obj` was that reader) took 190 MB and 2.9 s, 725 MB and 12.2 s, 786 MB and
17.4 s on the same files, one run each.

Run:  python benchmarks/obj_reader.py [--folder DIR] [--repeat 3] [--extra glphong.formats:read_obj]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

FILES = ("triangles_v_vt_vn.obj", "one_face_1e6_corners.obj", "plain_1m_faces.obj")
TINY = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n"


def grid(n):
    """Vertices (n*n, 3) of a wavy n x n grid over [0, 1]^2 [m], and its (2 (n-1)^2, 3) triangles."""
    u, v = np.meshgrid(np.linspace(0.0, 1.0, n), np.linspace(0.0, 1.0, n), indexing="ij")
    positions = np.stack([u.ravel(), v.ravel(), 0.05 * np.sin(6.0 * u.ravel()) * np.cos(5.0 * v.ravel())], axis=1)
    k = np.arange(n * n).reshape(n, n)
    a, b, c, d = k[:-1, :-1].ravel(), k[1:, :-1].ravel(), k[1:, 1:].ravel(), k[:-1, 1:].ravel()
    faces = np.concatenate([np.stack([a, b, c], axis=1), np.stack([a, c, d], axis=1)])
    return positions, faces


def rows(keyword, values, fmt="%.6f"):
    """Lines ``keyword v1 v2 ...`` of the rows of ``values`` (N, k)."""
    line = keyword + (" " + fmt) * values.shape[1] + "\n"
    return "".join(line % tuple(row) for row in values.tolist())


def write_files(folder):
    """Write the three benchmark files (and ``tiny.obj``) into ``folder``; skip those already there."""
    os.makedirs(folder, exist_ok=True)
    paths = {name: os.path.join(folder, name) for name in FILES}
    with open(os.path.join(folder, "tiny.obj"), "w") as f:
        f.write(TINY)
    if not os.path.exists(paths[FILES[0]]):
        positions, faces = grid(290)
        uvs = positions[:, :2]
        normals = np.tile([0.0, 0.0, 1.0], (len(positions), 1))
        corners = faces + 1
        text = "".join("f %d/%d/%d %d/%d/%d %d/%d/%d\n" % (a, a, a, b, b, b, c, c, c) for a, b, c in corners.tolist())
        with open(paths[FILES[0]], "w") as f:
            f.write(rows("v", positions) + rows("vt", uvs) + rows("vn", normals) + text)
    if not os.path.exists(paths[FILES[1]]):
        angle = np.arange(10 ** 6) * (2.0 * np.pi / 10 ** 6)
        circle = np.stack([np.cos(angle), np.sin(angle), np.zeros_like(angle)], axis=1)
        with open(paths[FILES[1]], "w") as f:
            f.write(rows("v", circle))
            f.write("f " + " ".join(map(str, range(1, 10 ** 6 + 1))) + "\n")
    if not os.path.exists(paths[FILES[2]]):
        positions, faces = grid(708)
        with open(paths[FILES[2]], "w") as f:
            f.write(rows("v", positions) + rows("f", faces + 1, "%d"))
    return paths


def child(reader, path, tiny):
    """In a fresh process: read ``path`` with ``reader`` once and print JSON (peak MB, seconds, triangles)."""
    import importlib
    import resource
    import time

    import trimesh

    import glphong.formats.obj

    if reader == "glphong":
        def read(p):
            return sum(mesh.triangle_count for _, mesh in glphong.formats.obj.read_obj(p))
    elif reader == "trimesh":
        def read(p):
            return len(trimesh.load(p, force="mesh").faces)
    else:
        module, name = reader.split(":")
        function = getattr(importlib.import_module(module), name)

        def read(p):
            return sum(mesh.triangle_count for _, mesh in function(p))
    read(tiny)  # lazy imports
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    start = time.perf_counter()
    triangles = read(path)
    seconds = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    print(json.dumps({"peak_mb": peak / 1024.0, "seconds": seconds, "triangles": int(triangles)}))


def measure(reader, path, tiny):
    """Run `child` in a fresh interpreter; its JSON as a dict."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    done = subprocess.run([sys.executable, __file__, "--child", reader, path, tiny], capture_output=True, text=True,
                          env=env)
    if done.returncode != 0:
        return {"error": done.stderr.strip().splitlines()[-1] if done.stderr.strip() else f"exit {done.returncode}"}
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--folder", default=os.path.join(tempfile.gettempdir(), "glphong_obj_bench"))
    parser.add_argument("--extra", action="append", default=[], help="another reader, module:function(path)")
    parser.add_argument("--repeat", type=int, default=1, help="fresh processes per reading (the least of each)")
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    parser.add_argument("--write", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        return child(*args.child)
    if args.write:
        return write_files(args.folder)
    # written by another process: a child inherits its parent's peak RSS as its own starting ru_maxrss
    subprocess.run([sys.executable, __file__, "--write", "--folder", args.folder], check=True)
    paths = {name: os.path.join(args.folder, name) for name in FILES}
    tiny = os.path.join(args.folder, "tiny.obj")
    print(f"{'file':<26}{'reader':<30}{'peak MB':>9}{'time s':>9}{'triangles':>11}   ({args.folder})")
    for name in FILES:
        for reader in ["glphong", "trimesh", *args.extra]:
            runs = [measure(reader, paths[name], tiny) for _ in range(args.repeat)]
            result = next((run for run in runs if "error" in run), None) or {
                "peak_mb": min(run["peak_mb"] for run in runs), "seconds": min(run["seconds"] for run in runs),
                "triangles": runs[0]["triangles"]}
            if "error" in result:
                print(f"{name:<26}{reader:<30}  failed: {result['error']}")
            else:
                print(f"{name:<26}{reader:<30}{result['peak_mb']:>9.1f}{result['seconds']:>9.2f}"
                      f"{result['triangles']:>11}", flush=True)


if __name__ == "__main__":
    main()
