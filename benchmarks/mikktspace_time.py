"""What MikkTSpace tangents cost (`glphong.scene.mikktspace`, the glTF loader's tangents where a file has none):
the time of `mikktspace_corners` and of `mikktspace_vertices` (the corners plus the vertex copies an indexed mesh needs)
on meshes of about 100 000 triangles, against Lengyel's per-vertex method (`glphong.scene.geometry.tangents_from_uvs`,
what glphong derives elsewhere), timed alternately in one process after a warm-up; reported: medians and ratios.

The meshes: a latitude-longitude sphere of 250 x 201 (100 000 triangles, smooth uvs: no group-with-any triangle), and
a lumpy icosphere of 81 920 triangles with uvs quantised to 1/64 (a third of its triangles have zero uv area: the
reference's sequential grouping of group-with-any triangles, which the module walks in Python, is its slow path).

Run:  python benchmarks/mikktspace_time.py [--repeats 5]
"""
import argparse
import statistics
import sys
from pathlib import Path

import numpy as np
import trimesh

from glphong.core.timing import alternating_times
from glphong.scene.geometry import tangents_from_uvs
from glphong.scene.mikktspace import mikktspace_corners, mikktspace_vertices

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "data" / "mikktspace"))
from make_meshes import uv_sphere  # noqa: E402  (the test meshes' sphere, larger)


def meshes():
    """``{name: (positions, normals, uvs, indices)}``."""
    p, n, uv, f = uv_sphere(250, 201)
    rng = np.random.default_rng(5)
    ico = trimesh.creation.icosphere(subdivisions=6)
    v = ico.vertices * (1 + 0.05 * rng.standard_normal((len(ico.vertices), 1)))
    lumpy = trimesh.Trimesh(v, ico.faces, process=False)
    uv_lumpy = np.c_[np.arctan2(v[:, 1], v[:, 0]), v[:, 2]] + 0.01 * rng.standard_normal((len(v), 2))
    uv_lumpy = np.round(uv_lumpy * 64) / 64
    return {"sphere 100000": (p, n, uv, np.asarray(f)),
            "lumpy 81920, quantised uvs": (v, np.asarray(lumpy.vertex_normals), uv_lumpy, np.asarray(ico.faces))}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    for name, (p, n, uv, f) in meshes().items():
        times = alternating_times({"lengyel": lambda: tangents_from_uvs(p, n, f, uv),
                                   "corners": lambda: mikktspace_corners(p, n, f, uv),
                                   "vertices": lambda: mikktspace_vertices(p, n, f, uv)},
                                  repeats=args.repeats, warmup=1)
        median = {k: statistics.median(t) for k, t in times.items()}
        print(f"{name} ({len(f)} triangles): " + ", ".join(f"{k} {median[k]:.3f} s" for k in median)
              + f"; corners / lengyel {median['corners'] / median['lengyel']:.1f}")


if __name__ == "__main__":
    main()
