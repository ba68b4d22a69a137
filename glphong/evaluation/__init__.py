"""Evaluating a material off-screen, without a scene: its GLSL response on direction pairs by transform feedback,
or its float64 twin on the same float32 inputs (`evaluate`, module ``response``), at the direction sets that
exercise a BRDF and with the closed-form tests' helpers (module ``directions``), on pooled contexts (module
``pool``).

It stands on the render check's twin (`glphong.checks`) and is shared by the users' test toolkit
(`glphong.testing`, which re-exports these names and adds the assertions) and by the BRDF analysis
(`glphong.analysis`); ``import glphong`` loads it, not the toolkit.
"""
from glphong.evaluation.directions import (cosine_power_interval, direction, direction_sets, float32_units,
                                           frame_around, rotate_toward)
from glphong.evaluation.response import evaluate

__all__ = ["evaluate", "direction_sets", "frame_around", "direction", "rotate_toward", "float32_units",
           "cosine_power_interval"]
