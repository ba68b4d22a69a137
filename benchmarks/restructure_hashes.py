"""Hashes of what a restructure must leave bit-identical: the default figure, the gallery and the stability rows.

Run it before and after a change that should move code without changing a result, on every backend the machine
has, and compare the printed JSON (``python benchmarks/restructure_hashes.py > before.json``; the same after;
``diff before.json after.json``).  Each hash is SHA-256 over the float32 bytes of the linear radiance (the figure,
the gallery mosaic) or over the GPU values and pass flags of every stability row, in both numerics modes.
"""
import hashlib
import json
import sys

import numpy as np

import glphong
from glphong.analysis.figures import phong_examples
from glphong.analysis.gallery import render_gallery
from glphong.checks.stability import run_stability


def _digest(array):
    return hashlib.sha256(np.ascontiguousarray(array, dtype=np.float32).tobytes()).hexdigest()


def hashes(backend):
    """``{name: sha256}`` of the default figure, the gallery and the stability rows on ``backend``."""
    out = {}
    with glphong.Renderer(128, 128, backend=backend) as renderer:
        out["default_figure"] = _digest(phong_examples(renderer).radiance)
        out["gallery"] = _digest(render_gallery(renderer).radiance)
    for numerics in ("stable", "auto"):
        report = run_stability(backend, "stable", numerics=numerics)
        rows = [(r.case, r.gpu, r.passed, list(r.numerics)) for r in report.rows]
        out[f"stability_{numerics}"] = hashlib.sha256(json.dumps(rows).encode()).hexdigest()
        out[f"stability_{numerics}_rows"] = len(rows)
    return out


if __name__ == "__main__":
    backends = sys.argv[1:] or glphong.available_backends()
    print(json.dumps({b: hashes(b) for b in backends}, indent=1, sort_keys=True))
