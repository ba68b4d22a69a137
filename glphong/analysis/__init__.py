"""Analysis: the lecture's four questions of a BRDF (`questions`), plots, the gallery and the lecture's figure
(`plots`, `gallery`, `figures`), and MERL tabulation of analytic models (`tabulate`).  Comparisons with peers
(a hand-written floor, pyrender) are `glphong.bench`'s.
"""
from glphong.analysis.questions import (DEFAULT_THETA_I, BrdfProperties, albedo, f_r, format_properties,
                                        hemisphere_directions, properties)

__all__ = ["f_r", "albedo", "properties", "format_properties", "BrdfProperties", "hemisphere_directions",
           "DEFAULT_THETA_I"]
