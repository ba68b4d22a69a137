"""glphong's benchmarks as a library: what ``glphong bench`` runs, and the scripts in ``benchmarks/`` share.

- ``work_precision``: error against run time (``glphong bench``): a scene family rendered by every method at each
  setting of its accuracy knob, scored against a converged ray cast (`run_bench`, `BenchReport`);
- ``continuous``: its continuous version, the extended lights' methods against their exact integrals;
- ``speed``: frame times on a scene family against the naive floor and pyrender (``glphong bench --speed``,
  `run_speed`), with glphong's Python overhead per object, the cost of saving a PNG and fitted costs;
- the peers glphong is measured against: ``floor``, the hand-written moderngl floor (`HandWrittenRenderer`), and
  ``pyrender_peer``, a glphong scene drawn by pyrender (`to_pyrender`, `PyrenderRenderer`, `import_pyrender`).

pyrender and matplotlib are optional: they are imported where used, never by ``import glphong.bench``.
"""
from glphong.bench.continuous import continuous_cases, continuous_methods, continuous_points, sky_map
from glphong.bench.floor import SHADERS, HandWrittenRenderer
from glphong.bench.pyrender_peer import (PYRENDER_GAMMA, PYRENDER_PLATFORMS, PYRENDER_SAMPLES, PyrenderRenderer,
                                         import_pyrender, pyrender_base_color, pyrender_decode, pyrender_encode,
                                         pyrender_roughness, pyrender_unavailable, to_pyrender)
from glphong.bench.speed import (SCENES, SpeedReport, png_cost, python_per_object, run_speed, scaling_fits,
                                 speed_scenes)
from glphong.bench.work_precision import (PLANE_SIZE, PLANE_Y, SPHERES, BenchCase, BenchReport, Method, family_camera,
                                          family_scene, methods, quick_cases, run_bench, scaling_table, speed_targets,
                                          standard_cases)

__all__ = [
    # the work-precision report (the 0.1.0 module glphong.bench)
    "BenchCase", "standard_cases", "quick_cases", "Method", "methods", "run_bench", "BenchReport", "scaling_table",
    "speed_targets", "family_camera", "family_scene", "SPHERES", "PLANE_Y", "PLANE_SIZE",
    # its continuous version
    "continuous_cases", "continuous_methods", "continuous_points", "sky_map",
    # the speed family
    "SCENES", "speed_scenes", "SpeedReport", "run_speed", "python_per_object", "png_cost", "scaling_fits",
    # the peers
    "HandWrittenRenderer", "SHADERS", "PyrenderRenderer", "to_pyrender", "pyrender_roughness", "pyrender_base_color",
    "import_pyrender", "pyrender_unavailable", "pyrender_encode", "pyrender_decode", "PYRENDER_PLATFORMS",
    "PYRENDER_SAMPLES", "PYRENDER_GAMMA",
]
