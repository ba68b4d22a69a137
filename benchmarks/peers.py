"""glphong against PyVista (VTK) or Open3D (Filament) on the speed family (docs/speed.md, "Against PyVista and Open3D").

One peer a process (its GL context beside glphong's), the speed family of `glphong.bench.speed.speed_scenes` at each
size, and per scene interleaved rounds (each round renders once with every method, after two warm-up rounds) of:

- ``glphong float``: `Renderer.render`, one sample, linear float32 with coverage;
- ``glphong 8-bit``: `Renderer.render_srgb8`, one sample, 8-bit sRGB read back;
- ``glphong 4x 8-bit``: `Renderer(samples=4).render_srgb8`;
- the peer at its defaults (PyVista: its theme's anti-aliasing, 4x MSAA on llvmpipe; Open3D: post-processing on;
  pyrender: 4x MSAA, back faces culled) and single-sampled (PyVista ``disable_anti_aliasing()``; Open3D
  post-processing off; pyrender has no single-sampled setting on EGL: its second column is every material
  ``doubleSided``, nothing culled), each read back to numpy.

Printed: per scene, the medians [ms], their spread (the 25th to 75th percentile over the median), and the ratios
peer / glphong (above 1: glphong is faster).

Run:  python benchmarks/peers.py pyvista [--sizes 512] [--rounds 17] [--quick] [--scenes plane "fine plane"]
      python benchmarks/peers.py pyrender ...   (the pyrender2 fork, EGL)
      EGL_PLATFORM=surfaceless python benchmarks/peers.py open3d ...   (Open3D 0.19: 0.20 needs Vulkan)
"""
import argparse
import statistics

import numpy as np

import glphong
from glphong.bench.peers import Open3DRenderer, PyVistaRenderer
from glphong.bench.pyrender_peer import PyrenderRenderer
from glphong.bench.speed import speed_scenes
from glphong.core.timing import alternating_times

#: peer -> (its renderer at its defaults, its second renderer), each ``(width, height) -> renderer``
PEERS = {"pyvista": (PyVistaRenderer, lambda w, h: PyVistaRenderer(w, h, anti_aliasing=False)),
         "open3d": (Open3DRenderer, lambda w, h: Open3DRenderer(w, h, post_processing=False)),
         "pyrender": (lambda w, h: PyrenderRenderer(w, h, "egl"), lambda w, h: PyrenderRenderer(w, h, "egl", double_sided=True))}
#: the second renderer's column, where it is not the single-sampled one
SECOND = {"pyrender": "2-sided"}


def _spread(times):
    q1, _, q3 = np.percentile(times, [25, 50, 75])
    return (q3 - q1) / statistics.median(times)


def measure(peer, sizes, rounds, quick=False, names=None):
    """Rows ``{scene, size, ms: {method: median}, spread: {method: iqr / median}}`` (``names``: the family's scenes
    to run, default all)."""
    first, second = PEERS[peer]
    rows, peers, ours = [], [], []
    scenes = {k: v for k, v in speed_scenes(quick).items() if names is None or k in names}
    try:
        for size in sizes:
            # PyVista's plotters first: making a VTK plotter on EGL terminates the EGL display, and with it every
            # context made before on it (glphong's too); contexts made after it live on.  Open3D keeps one renderer
            # a size, loaded with one scene at a time: its scene is loaded just before it is timed
            make = lambda scene: (first(size, size).prepare(scene), second(size, size).prepare(scene))  # noqa: E731
            made = {name: make(scene) for name, scene in scenes.items()} if peer == "pyvista" else {}
            peers += [r for pair in made.values() for r in pair]
            plain = glphong.Renderer(size, size, backend="egl")
            msaa = glphong.Renderer(size, size, backend="egl", samples=4)
            ours += [plain, msaa]
            for name, scene in scenes.items():
                if name not in made:  # kept (and released at the end): pyrender's renderers, dropped, end the display
                    made[name] = make(scene)
                    peers += made[name]
                default, single = made[name]
                runs = {"glphong float": lambda s=scene: plain.render(s),
                        "glphong 8-bit": lambda s=scene: plain.render_srgb8(s),
                        "glphong 4x 8-bit": lambda s=scene: msaa.render_srgb8(s),
                        f"{peer} default": default.render, f"{peer} {SECOND.get(peer, '1 sample')}": single.render}
                times = alternating_times(runs, rounds, warmup=2)
                rows.append({"scene": name, "size": size,
                             "ms": {k: 1e3 * statistics.median(t) for k, t in times.items()},
                             "spread": {k: _spread(t) for k, t in times.items()}})
                print(_row(peer, rows[-1]), flush=True)
            for renderer in (plain, msaa):  # before the next size's plotters end the display
                renderer.release()
    finally:  # glphong's first: closing a VTK plotter on EGL terminates the display every context shares
        for renderer in ours:
            renderer.release()
        for made_peer in peers:
            made_peer.release()
    return rows


def _row(peer, row):
    ms = row["ms"]
    second = ms[f"{peer} {SECOND.get(peer, '1 sample')}"]
    return (f"| {row['scene']} | {row['size']} | " + " | ".join(f"{v:.1f} ({100 * row['spread'][k]:.0f} %)"
                                                             for k, v in ms.items())
            + f" | {ms[f'{peer} default'] / ms['glphong 4x 8-bit']:.2f}x | "
            f"{second / min(ms['glphong float'], ms['glphong 8-bit']):.2f}x |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("peer", choices=sorted(PEERS))
    parser.add_argument("--sizes", type=int, nargs="+", default=[512])
    parser.add_argument("--rounds", type=int, default=17)
    parser.add_argument("--quick", action="store_true", help="the family's small stand-ins")
    parser.add_argument("--scenes", nargs="+", help="the family's scenes to run (default all)")
    args = parser.parse_args()
    print(f"llvmpipe or whatever EGL gives, EGL; {args.peer}; {args.rounds} interleaved rounds, medians (spread)")
    second = SECOND.get(args.peer, "1 sample")
    print(f"| scene | size | glphong float | glphong 8-bit | glphong 4x 8-bit | {args.peer} default | {args.peer} {second} "
          f"| default / glphong 4x 8-bit | {second} / glphong's faster single-sampled |")
    measure(args.peer, args.sizes, args.rounds, args.quick, args.scenes)


if __name__ == "__main__":
    main()
