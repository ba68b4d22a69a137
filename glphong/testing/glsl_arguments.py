"""Inputs that find bugs in GLSL functions (docs/design.md section 14): the edge cases of GLSL's float32 numerics,
and ``hypothesis`` strategies for each GLSL type.

`edge_values` gives a type's edge cases; `edge_inputs` crosses them for every input of a function, adding, for
two ``vec3`` inputs, the direction pairs that break shading code (equal, exactly opposite, at grazing angles,
rounded to float32).  `glsl_values` and `glsl_inputs` are ``hypothesis`` strategies (``pip install
hypothesis``; imported when called): arrays of ``rows`` values of a type, and a dict of them for every input of a
function, so that a property test is a few lines::

    @given(glsl_inputs(fn, rows=64, unit={"n", "l"}))
    def test_symmetric(values):
        out = fn(**values)
"""
import numpy as np

from glphong.testing.glsl_types import glsl_type

__all__ = ["edge_values", "edge_inputs", "glsl_values", "glsl_inputs", "FLOAT_EDGES", "unit_float32"]

_F32 = np.finfo(np.float32)
#: float32 edge cases: signed zeros, the smallest and largest subnormals, FLT_MIN, around 1, FLT_MAX
FLOAT_EDGES = np.array([0.0, -0.0, 2.0 ** -149, -(2.0 ** -149), 2.0 ** -126 - 2.0 ** -149, float(_F32.tiny),
                        -float(_F32.tiny), 1.0 - 2.0 ** -24, 1.0, -1.0, 1.0 + 2.0 ** -23, 0.5, 2.0, 1e-7, 1e7,
                        float(_F32.max), -float(_F32.max)], dtype=np.float32)
_NONFINITE = np.array([np.inf, -np.inf, np.nan], dtype=np.float32)
_INT_EDGES = {"int": np.array([0, 1, -1, 2, 2 ** 31 - 1, -(2 ** 31)], dtype=np.int64),
              "uint": np.array([0, 1, 2, 2 ** 31, 2 ** 32 - 1], dtype=np.int64)}


def unit_float32(v):
    """Unit vectors rounded to float32 (rows of ``v``), as a shader receives normalised data: their length is 1
    within float32's rounding, not exactly."""
    v = np.asarray(v, dtype=np.float64)
    return (v / np.linalg.norm(v, axis=-1, keepdims=True)).astype(np.float32)


def _directions():
    """Unit vec3 edge cases: the axes and their negatives, diagonals, a random unit vector rounded to float32."""
    axes = np.concatenate([np.eye(3), -np.eye(3)])
    diagonals = unit_float32([[1, 1, 1], [1, -1, 0], [-1, 2, 3], [1e-4, 0, 1]])
    return np.concatenate([axes.astype(np.float32), diagonals])


def edge_values(type_name, nonfinite=False, unit=False):
    """Edge cases of a GLSL type, one per row.

    Parameters
    ----------
    type_name : str
        A GLSL type (`glphong.testing.glsl_types.TYPE_NAMES`).
    nonfinite : bool
        Add inf, -inf and NaN (floats).
    unit : bool
        For a float vector: unit directions (`unit_float32`) instead of componentwise edges.

    Returns
    -------
    ndarray
        ``(M,) + row shape``.
    """
    t = glsl_type(type_name)
    if t is None:
        raise ValueError(f"no GLSL type {type_name!r}")
    if t.base == "bool":
        base = np.array([False, True])
    elif t.base == "float":
        if unit and t.rows == 3 and not t.is_matrix:
            return _directions()
        base = np.concatenate([FLOAT_EDGES, _NONFINITE]) if nonfinite else FLOAT_EDGES
    else:
        base = _INT_EDGES[t.base].astype(t.dtype)
    if t.components == 1:
        return base.copy()
    # each component walks the edge list at a different stride, so rows mix values (and include all-equal rows)
    count = len(base)
    index = (np.arange(count)[:, None] * np.arange(1, t.components + 1)[None, :]) % count
    return base[index].reshape((count,) + t.row_shape())


def _direction_pairs():
    """``(a, b)`` unit vec3 pairs: equal, exactly opposite, 1e-7 rad and 1e-3 rad apart, perpendicular, grazing."""
    a = _directions().astype(np.float64)
    helper = np.where(np.abs(a[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
    side = np.cross(a, helper)
    side /= np.linalg.norm(side, axis=1, keepdims=True)
    pairs = [(a, a), (a, -a), (a, side)]
    for angle in (1e-7, 1e-3, np.pi / 2 - 1e-7, np.pi / 2 + 1e-7):
        pairs.append((a, np.cos(angle) * a + np.sin(angle) * side))
    first = np.concatenate([p[0] for p in pairs]).astype(np.float32)
    second = np.concatenate([unit_float32(p[1]) for p in pairs])
    return first, second


def edge_inputs(fn, nonfinite=False, unit=(), limit=20000, seed=0):
    """Edge cases for every input of GLSL function ``fn``, crossed: a dict of arrays with one row per case.

    Parameters
    ----------
    fn : glphong.testing.GlslFunction
    nonfinite : bool
        Include inf, -inf and NaN among the floats.
    unit : collection of str
        ``vec3`` inputs that are directions: they take unit edge cases; the first two of them are crossed as the
        direction pairs shading code meets (equal, exactly opposite, perpendicular, 1e-7 rad apart, at grazing).
    limit : int
        Most rows: the full cross product where it is smaller, else ``limit`` rows drawn from it (seeded).
    seed : int

    Returns
    -------
    dict of str to ndarray
    """
    params = fn.signature.inputs
    unit = set(unit)
    paired = [p.name for p in params if p.name in unit and p.type == "vec3"][:2]
    groups = []  # (names, arrays) crossed with one another
    if len(paired) == 2:
        groups.append((paired, _direction_pairs()))
    for p in params:
        if p.name in paired and len(paired) == 2:
            continue
        groups.append(([p.name], (edge_values(p.type, nonfinite, unit=p.name in unit),)))
    sizes = [len(arrays[0]) for _, arrays in groups]
    total = int(np.prod(sizes, dtype=np.float64))
    if total <= limit:
        index = np.indices(sizes).reshape(len(sizes), -1)
    else:
        rng = np.random.default_rng(seed)
        index = np.stack([rng.integers(0, size, limit) for size in sizes])
    out = {}
    for (names, arrays), pick in zip(groups, index):
        for name, array in zip(names, arrays):
            out[name] = array[pick]
    return {p.name: out[p.name] for p in params}


def _hypothesis():
    try:
        from hypothesis import strategies as st
        from hypothesis.extra import numpy as hnp
    except ImportError:
        raise ImportError("glphong's hypothesis strategies need hypothesis: pip install hypothesis "
                          "(it comes with glphong's [test] extra)") from None
    return st, hnp


def _float32_inward(bound, up):
    """A bound as the nearest float32 inside it (hypothesis's width=32 floats take float32 bounds)."""
    if bound is None:
        return None
    value = np.float32(bound)
    if (up and float(value) < bound) or (not up and float(value) > bound):
        value = np.nextafter(value, np.float32(np.inf if up else -np.inf))
    return float(value)


def glsl_values(type_name, rows=32, min_value=None, max_value=None, allow_nan=False, allow_infinity=False,
                allow_subnormal=None, unit=False):
    """A ``hypothesis`` strategy of ``rows`` values of a GLSL type: an array ``(rows,) + row shape``.

    Floats are float32 (``width=32``: every value a float32, subnormals included where the range holds them,
    unless ``allow_subnormal=False``), within ``[min_value, max_value]`` where given (rounded inward to float32); ``unit=True`` draws unit vectors
    (float vectors) rounded to float32.  Integers span their type unless bounded; booleans both values.
    """
    st, hnp = _hypothesis()
    t = glsl_type(type_name)
    if t is None:
        raise ValueError(f"no GLSL type {type_name!r}")
    shape = (rows,) + t.row_shape()
    if t.base == "bool":
        return hnp.arrays(np.bool_, shape)
    if t.base in ("int", "uint"):
        info = np.iinfo(t.dtype)
        low = info.min if min_value is None else max(int(min_value), int(info.min))
        high = info.max if max_value is None else min(int(max_value), int(info.max))
        return hnp.arrays(t.dtype, shape, elements=st.integers(low, high))
    if unit:
        if t.is_matrix or t.rows == 1:
            raise ValueError(f"unit=True draws unit vectors, not {type_name}")
        component = st.floats(-1.0, 1.0, width=32)
        return hnp.arrays(np.float32, shape, elements=component).filter(
            lambda a: np.all(np.linalg.norm(a.astype(np.float64), axis=-1) > 1e-3)).map(unit_float32)
    elements = st.floats(min_value=_float32_inward(min_value, up=True), max_value=_float32_inward(max_value, up=False),
                         allow_nan=allow_nan, allow_infinity=allow_infinity, allow_subnormal=allow_subnormal, width=32)
    return hnp.arrays(np.float32, shape, elements=elements)


def glsl_inputs(fn, rows=32, unit=(), **options):
    """A ``hypothesis`` strategy of a dict with ``rows`` values for every input of GLSL function ``fn``.

    Parameters
    ----------
    fn : glphong.testing.GlslFunction
    rows : int
    unit : collection of str
        Inputs drawn as unit vectors.
    **options
        Per input name: a dict of `glsl_values` options (``x={"min_value": 0.0}``) or a strategy of its own.
    """
    st, _ = _hypothesis()
    strategies = {}
    for p in fn.signature.inputs:
        given = options.pop(p.name, {})
        if not isinstance(given, dict):
            strategies[p.name] = given
            continue
        strategies[p.name] = glsl_values(p.type, rows, unit=p.name in set(unit), **given)
    if options:
        raise TypeError(f"{fn.signature} has no inputs {sorted(options)}")
    return st.fixed_dictionaries(strategies)
