"""The MERL measured-BRDF format (`glphong.core.merl`: read, write, index, look up) and `tabulate`
(`glphong.analysis.tabulate`), under the path of glphong 0.1.0."""
from glphong.analysis.tabulate import tabulate
from glphong.core.merl import (SCALE, SHAPE, MerlFormatError, bin_directions, half_diff, lookup, merl_indices,
                               read_merl, write_merl)

__all__ = ["SHAPE", "SCALE", "MerlFormatError", "read_merl", "write_merl", "half_diff", "merl_indices", "lookup",
           "bin_directions", "tabulate"]
