"""Write meshes.json: the test meshes of tests/test_mikktspace.py (see README.md in this folder).

Run from the repository root: ``python tests/data/mikktspace/make_meshes.py``.  Each mesh is indexed; its arrays are
stored as base64 of little-endian float32 (positions, normals, uvs) and int32 (indices), so that glphong and the
node script read the very same float32 values.
"""
import base64
import json
from pathlib import Path

import numpy as np
import trimesh

HERE = Path(__file__).resolve().parent
RNG = np.random.default_rng(20261207)


def _unit(v):
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def quad():
    p = np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]], float)
    return p, np.tile([0, 0, 1.0], (4, 1)), np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float), [[0, 1, 2], [0, 2, 3]]


def uv_sphere(segments=12, rings=8):
    """A latitude-longitude sphere: a u seam (the column u = 0 and u = 1 twice) and one pole vertex per segment."""
    theta = np.linspace(0, np.pi, rings + 1)
    phi = np.linspace(0, 2 * np.pi, segments + 1)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    n = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1).reshape(-1, 3)
    uv = np.stack([ph / (2 * np.pi), 1 - th / np.pi], axis=-1).reshape(-1, 2)
    faces = []
    for r in range(rings):
        for s in range(segments):
            a, b = r * (segments + 1) + s, r * (segments + 1) + s + 1
            c, d = a + segments + 1, b + segments + 1
            if r > 0:
                faces.append([a, c, b])
            if r < rings - 1:
                faces.append([b, c, d])
    n = np.round(n, 12)
    return n * 1.5, n, uv, faces


def mirrored():
    """A bent grid whose uvs mirror about its middle column (shared vertices on the mirror line), a second island
    mirrored in v, and a uv seam between them (the seam's vertices duplicated with other uvs)."""
    nx, ny = 6, 4
    x, y = np.meshgrid(np.linspace(-1, 1, nx + 1), np.linspace(0, 1, ny + 1), indexing="xy")
    z = 0.3 * x * x + 0.1 * y
    p = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    n = _unit(np.stack([-0.6 * x, -0.1 * np.ones_like(x), np.ones_like(x)], axis=-1).reshape(-1, 3))
    uv = np.stack([np.abs(x) * 0.5, y * 0.5], axis=-1).reshape(-1, 2)
    faces = []
    for j in range(ny):
        for i in range(nx):
            a = j * (nx + 1) + i
            faces += [[a, a + 1, a + nx + 2], [a, a + nx + 2, a + nx + 1]]
    # second island: the top row again, going up, with v mirrored (1 - ...) and offset in u: a seam along y = 1
    top = np.arange(ny * (nx + 1), (ny + 1) * (nx + 1))
    p2 = p[top] + [0, 0.5, 0.2]
    start = len(p)
    ps, ns, uvs = [p, p[top], p2], [n, n[top], n[top]], [uv, np.c_[uv[top, 0] + 0.6, 1 - uv[top, 1]],
                                                     np.c_[uv[top, 0] + 0.6, 1 - uv[top, 1] - 0.25]]
    for i in range(nx):
        a, b = start + i, start + nx + 1 + i
        faces += [[a, a + 1, b + 1], [a, b + 1, b]]
    return np.concatenate(ps), np.concatenate(ns), np.concatenate(uvs), faces


def degenerate():
    """A strip with: a triangle with two corners at one position, one whose corner is used only by degenerate
    triangles, one of zero uv area and one of collinear uvs (group-with-any) between regions of either orientation,
    and one with collinear (distinct) positions."""
    p = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0], [0, 1, 0], [1, 1, 0.2], [2, 1, 0], [3, 1, 0.1],
                  [1, 0, 0], [5, 5, 0], [5, 5, 0], [1.5, 0.5, 0.1], [2.5, 0.5, 0.05]], float)
    n = _unit(np.array([[0, 0, 1.0]] * len(p)) + [[0.1 * k % 0.3, 0, 0] for k in range(len(p))])
    uv = np.array([[0, 0], [1, 0], [0.5, 0], [-0.5, 0], [0, 1], [1, 1], [0.5, 1], [-0.5, 1],
                   [1, 0], [0.3, 0.3], [0.6, 0.1], [0.7, 0.7], [0.7, 0.7]], float)
    faces = [[0, 1, 5], [0, 5, 4],           # healthy, orientation preserving
             [1, 2, 6], [1, 6, 5],           # u goes back: orientation reversing
             [2, 3, 7], [2, 7, 6],           # reversing again
             [1, 8, 5],                      # corners 1 and 8 at one position: degenerate (welded with 1)
             [9, 10, 4],                     # 9 and 10 at one position; 9, 10 used by no healthy triangle
             [5, 11, 6], [6, 12, 7],         # uv area 0 and one corner pair sharing uv: group with any
             [11, 12, 5],                    # collinear uvs (11 and 12 equal): group with any
             [0, 1, 2]]                      # collinear positions (distinct)
    return p, n, uv, faces


def folded():
    """A triangle folded back over its neighbour (a fin) with the uvs unfolded: one orientation, tangents exactly
    opposite in the plane of the shared normals, which the angular threshold's subgroups keep apart."""
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0.001], [-1, 0, 0], [0, -1, 0]], float)
    uv = np.array([[0.5, 0.5], [1, 0.5], [0.5, 1], [0, 0.5], [0, 0.5], [0.5, 0]], float)
    faces = [[0, 1, 2], [0, 2, 3], [0, 5, 1], [0, 4, 5]]
    return p, np.tile([0, 0, 1.0], (len(p), 1)), uv, faces


def random_shape():
    """A seeded lumpy icosphere with uvs from a noisy projection (some triangles flip orientation)."""
    mesh = trimesh.creation.icosphere(subdivisions=2)
    v = mesh.vertices * (1 + 0.15 * RNG.standard_normal((len(mesh.vertices), 1)))
    mesh = trimesh.Trimesh(v, mesh.faces, process=False)
    uv = np.c_[v[:, 0] + 0.3 * v[:, 2], v[:, 1] - 0.2 * v[:, 2]] + 0.05 * RNG.standard_normal((len(v), 2))
    return v, np.asarray(mesh.vertex_normals), uv, mesh.faces


def fuzz(seed, count=40):
    """Seeded small meshes (quantised positions and uvs: welds, degenerate and zero-uv-area triangles; random faces:
    edges of three or more triangles; grids with random u flips and shuffled faces); ``FUZZ`` keeps the few whose
    result depends on the reference's weld order and the last run of its edge sort (found by comparing against it)."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        vertices, faces = int(rng.integers(4, 40)), int(rng.integers(2, 80))
        p = rng.integers(0, 4, (vertices, 3)).astype(float) * 0.5
        if k % 3 == 0:
            p = rng.standard_normal((vertices, 3))
        n = _unit(rng.standard_normal((vertices, 3)))
        if k % 4 == 0:
            n[:] = [0, 0, 1]
        uv = rng.integers(0, 3, (vertices, 2)).astype(float) * 0.5
        if k % 5 == 0:
            uv = rng.random((vertices, 2))
        f = rng.integers(0, vertices, (faces, 3))
        if k % 2 == 0:
            g = int(rng.integers(2, 6))
            idx = np.arange((g + 1) ** 2).reshape(g + 1, g + 1)
            x, y = np.meshgrid(np.arange(g + 1), np.arange(g + 1))
            p = np.c_[x.ravel(), y.ravel(), rng.integers(0, 2, (g + 1) ** 2) * 0.3].astype(float)
            uv = np.c_[x.ravel() * rng.choice([-1, 1, 0], (g + 1) ** 2), y.ravel()].astype(float) * 0.25
            n = np.tile([0, 0, 1.0], ((g + 1) ** 2, 1))
            n[::3] = [0, 0.6, 0.8]
            f = np.array([[idx[j, i], idx[j, i + 1], idx[j + 1, i + 1]] for j in range(g) for i in range(g)]
                         + [[idx[j, i], idx[j + 1, i + 1], idx[j + 1, i]] for j in range(g) for i in range(g)])
            rng.shuffle(f)
        out.append((p, n, uv, f))
    return out


#: (seed, index) of the `fuzz` meshes kept
FUZZ = [(1, 19), (2, 15), (3, 23), (3, 26), (5, 17), (1, 14)]


def _b64(a, dtype):
    return base64.b64encode(np.ascontiguousarray(a, dtype=np.dtype(dtype).newbyteorder("<")).tobytes()).decode()


def main():
    meshes = {}
    for name, make in [("quad", quad), ("uv_sphere", uv_sphere), ("mirrored", mirrored), ("degenerate", degenerate),
                       ("folded", folded), ("random_shape", random_shape)]:
        p, n, uv, faces = make()
        meshes[name] = {"positions": _b64(p, "f4"), "normals": _b64(n, "f4"), "uvs": _b64(uv, "f4"),
                        "indices": _b64(np.asarray(faces).reshape(-1), "i4")}
    for seed, index in FUZZ:
        p, n, uv, faces = fuzz(seed)[index]
        meshes[f"fuzz_{seed}_{index}"] = {"positions": _b64(p, "f4"), "normals": _b64(n, "f4"), "uvs": _b64(uv, "f4"),
                                          "indices": _b64(np.asarray(faces).reshape(-1), "i4")}
    (HERE / "meshes.json").write_text(json.dumps(meshes, indent=1) + "\n")


if __name__ == "__main__":
    main()
