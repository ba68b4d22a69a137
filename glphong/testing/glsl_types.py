"""The GLSL types a tested function's parameters and result may have, and their numpy form (docs/design.md
section 14).

Every value crosses to and from the GPU as its 32-bit patterns (``uint`` attributes and ``uint`` outputs:
``uintBitsToFloat`` on the way in, ``floatBitsToUint`` on the way out), so a float arrives and returns with its
bits: ``-0.0``, NaN payloads and subnormals survive the transfer, and whatever changes them is the function's
arithmetic (or the driver flushing a subnormal, which GLSL allows).

==================== ================================ ==========================================================
GLSL                 numpy, per row                   notes
==================== ================================ ==========================================================
float, int, uint     float32, int32, uint32: (N,)     Python scalars and 0-d arrays broadcast to every row
bool                 bool: (N,)                       passed as 0 or 1
vecK, ivecK, uvecK   (N, K) of float32/int32/uint32   K = 2, 3, 4; a (K,) array broadcasts
bvecK                (N, K) bool
matK, matCxR         (N, R, C) float32                as numpy writes a matrix: ``M[r, c]`` is GLSL's ``m[c][r]``
==================== ================================ ==========================================================

Arrays, structs, doubles and opaque types (samplers, images) are not parameter types; samplers are uniforms.
"""
from dataclasses import dataclass

import numpy as np

__all__ = ["GlslType", "glsl_type", "TYPE_NAMES", "encode", "decode"]


@dataclass(frozen=True)
class GlslType:
    """A GLSL scalar, vector or matrix type.

    Attributes
    ----------
    name : str
        As GLSL spells it (``'vec3'``, ``'mat3x2'``).
    base : {'float', 'int', 'uint', 'bool'}
    rows : int
        Components of a vector (1 for a scalar), rows of a matrix.
    columns : int
        Columns of a matrix; 1 otherwise.
    """

    name: str
    base: str
    rows: int
    columns: int = 1

    @property
    def components(self):
        """Scalars a value holds."""
        return self.rows * self.columns

    @property
    def is_matrix(self):
        return self.columns > 1

    @property
    def dtype(self):
        """numpy dtype of the values."""
        return {"float": np.float32, "int": np.int32, "uint": np.uint32, "bool": np.bool_}[self.base]

    def row_shape(self):
        """Shape of one row's value: ``()``, ``(K,)`` or ``(R, C)``."""
        if self.is_matrix:
            return (self.rows, self.columns)
        return () if self.rows == 1 else (self.rows,)

    def slots(self):
        """``(glsl type, components)`` of the uint attributes or outputs one value occupies: one per matrix column,
        one for a scalar or vector."""
        unsigned = "uint" if self.rows == 1 else f"uvec{self.rows}"
        return [(unsigned, self.rows)] * self.columns

    def from_bits(self, names):
        """GLSL expression of a value of this type from its uint slots ``names`` (list of str)."""
        vec = "" if self.rows == 1 else f"vec{self.rows}"
        if self.base == "float":
            parts = [f"uintBitsToFloat({n})" for n in names]
            return f"{self.name}({', '.join(parts)})" if self.is_matrix else parts[0]
        if self.base == "int":
            return f"int({names[0]})" if self.rows == 1 else f"i{vec}({names[0]})"
        if self.base == "uint":
            return names[0]
        zero = "0u" if self.rows == 1 else f"u{vec}(0u)"
        return f"({names[0]} != 0u)" if self.rows == 1 else f"notEqual({names[0]}, {zero})"

    def to_bits(self, expression):
        """GLSL expressions of the uint slots of ``expression`` (list of str, one per slot)."""
        vec = "" if self.rows == 1 else f"vec{self.rows}"
        if self.base == "float":
            if self.is_matrix:
                return [f"floatBitsToUint(({expression})[{c}])" for c in range(self.columns)]
            return [f"floatBitsToUint({expression})"]
        if self.base == "int":
            return [f"uint({expression})" if self.rows == 1 else f"u{vec}({expression})"]
        if self.base == "uint":
            return [expression]
        return [f"uint({expression})" if self.rows == 1 else f"u{vec}({expression})"]


def _table():
    out = {}
    for base, prefix in (("float", ""), ("int", "i"), ("uint", "u"), ("bool", "b")):
        out[base] = GlslType(base, base, 1)
        for k in (2, 3, 4):
            out[f"{prefix}vec{k}"] = GlslType(f"{prefix}vec{k}", base, k)
    for c in (2, 3, 4):
        out[f"mat{c}"] = GlslType(f"mat{c}", "float", c, c)
        for r in (2, 3, 4):
            out[f"mat{c}x{r}"] = GlslType(f"mat{c}x{r}", "float", r, c)
    return out


_TYPES = _table()
#: every type name a parameter or result may have
TYPE_NAMES = tuple(_TYPES)


def glsl_type(name):
    """The `GlslType` of a GLSL type name, or None where glphong cannot pass it."""
    return _TYPES.get(name)


def encode(glsl, value, count, where):
    """``value`` as the uint32 words of ``count`` rows, one (count, components) array per slot of `GlslType.slots`.

    Parameters
    ----------
    glsl : GlslType
    value : array_like
        ``(count,) + row_shape``, or one row's shape (broadcast), or a scalar where a row is a scalar.
    count : int
    where : str
        The parameter, for messages.

    Raises
    ------
    ValueError
        A shape that does not match the type, an integer out of range or not whole.
    """
    shape = glsl.row_shape()
    array = np.asarray(value)
    if array.dtype == object or array.dtype.kind not in "biuf":
        raise TypeError(f"{where}: expected numbers for a {glsl.name} (got dtype {array.dtype})")
    if array.shape == shape:
        array = np.broadcast_to(array, (count,) + shape)
    elif array.shape == (1,) + shape:
        array = np.broadcast_to(array, (count,) + shape)
    if array.shape != (count,) + shape:
        expected = ", ".join(map(str, ("N",) + shape))
        raise ValueError(f"{where}: a {glsl.name} takes an array of shape ({expected}) or {shape or '()'} "
                         f"(got shape {np.shape(value)}, with N = {count} rows)")
    if glsl.base == "float":
        words = np.ascontiguousarray(array, dtype=np.float32).view(np.uint32)
    elif glsl.base == "bool":
        words = (array != 0).astype(np.uint32)
    else:
        info = np.iinfo(np.int32 if glsl.base == "int" else np.uint32)
        if array.dtype.kind == "f" and not np.all(np.isfinite(array) & (array == np.round(array))):
            raise ValueError(f"{where}: a {glsl.name} takes whole numbers (got non-integer values)")
        if array.size and (np.min(array) < info.min or np.max(array) > info.max):
            raise ValueError(f"{where}: a {glsl.name} takes values in [{info.min}, {info.max}]")
        words = np.ascontiguousarray(array.astype(np.int64).astype(np.int32 if glsl.base == "int" else np.uint32))
        words = words.view(np.uint32)
    if glsl.is_matrix:  # (N, R, C) -> one slot per column: (N, R) each
        return [np.ascontiguousarray(words[:, :, c]) for c in range(glsl.columns)]
    return [np.ascontiguousarray(words.reshape(count, glsl.rows))]


def decode(glsl, slots):
    """The numpy value of ``slots`` (one (N, components) uint32 array per slot), as the table above gives it."""
    count = len(slots[0])
    words = np.stack(slots, axis=2) if glsl.is_matrix else slots[0].reshape((count,) + glsl.row_shape())
    if glsl.base == "float":
        return np.ascontiguousarray(words).view(np.float32)
    if glsl.base == "int":
        return np.ascontiguousarray(words).view(np.int32)
    if glsl.base == "uint":
        return np.ascontiguousarray(words)
    return words != 0
