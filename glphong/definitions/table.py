"""Tables: float32 arrays a material model samples, as a texture on the GPU and as the same values in its twin.

A model declares a table the way it declares a parameter (docs/design.md section 8): ``tables = (Table(...),)``.
glphong then declares the sampler ``uniform sampler<N>D u_<model>_<name>;`` (generated, like a
parameter's uniform), validates the value a constructor is given (shape, channels, finite), and
uploads it as a texture the first time a drawn object's program reads it (`glphong.gpu.textures`), once
per content per context.  The twin receives the same `TableData` in its ``p`` (``p.<name>.array``,
the float32 values the texture holds), so both sides look up identical numbers.

The GLSL reads a table with ``texelFetch(u_<model>_<name>, ivec3(k, j, i), 0)`` for ``array[i, j, k]``:
the array's last axis (before the channels) is the texture's x.
"""
import functools
import hashlib
import threading
import weakref
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from glphong.definitions.params import MaterialDefinitionError, _check_argument_name

__all__ = ["Table", "TableData", "uniform_as"]

#: sampler types per number of table axes
SAMPLERS = {2: "sampler2D", 3: "sampler3D"}


class TableData:
    """An immutable float32 table: what a `Table` argument holds after validation.

    Equal contents are one object (interned by content hash while any material holds it), so a file
    read twice is uploaded once per context.

    Attributes
    ----------
    array : ``(*shape, channels)`` float32 ndarray
        Read-only.
    digest : str
        First 16 hex digits of the SHA-256 of the shape and bytes.
    source : str or None
        Where it came from (a file path), for messages and ``repr``.
    """

    _interned = weakref.WeakValueDictionary()
    _lock = threading.Lock()

    def __new__(cls, array, source=None):
        array = np.ascontiguousarray(array, dtype=np.float32)
        digest = hashlib.sha256(repr(array.shape).encode() + array.tobytes()).hexdigest()[:16]
        with cls._lock:
            known = cls._interned.get(digest)
            if known is not None:
                return known
            self = super().__new__(cls)
            array.setflags(write=False)
            self.array, self.digest = array, digest
            self.source = None if source is None else str(source)
            cls._interned[digest] = self
        return self

    @classmethod
    def zeros(cls, shape, channels):
        """A table of zeros (the uber-shader's value for a model an object does not have); made once per
        shape and kept, so a frame neither allocates nor hashes it again."""
        return _zeros(tuple(shape), channels)

    @property
    def shape(self):
        """The table's shape, channels last (tuple)."""
        return self.array.shape

    @property
    def nbytes(self):
        """Size of the float32 data [bytes] (what the texture holds)."""
        return self.array.nbytes

    def astype(self, dtype):
        """The table itself: its values stay the float32 the GPU samples (lookups convert what they pick)."""
        return self

    def __eq__(self, other):
        return isinstance(other, TableData) and other.digest == self.digest

    def __hash__(self):
        return hash(self.digest)

    def __repr__(self):
        where = repr(self.source) if self.source else f"<table {'x'.join(map(str, self.shape))} {self.digest[:8]}>"
        return where

    def __reduce__(self):  # pickled by value (a spawn-started worker rebuilds it, interned again there)
        return (TableData, (np.asarray(self.array), self.source))


@functools.lru_cache(maxsize=None)
def _zeros(shape, channels):
    return TableData(np.zeros(shape + (channels,), np.float32), source="zeros")


def uniform_as(value, dtype):
    """A uniform's value in ``dtype`` for the twin: arrays cast, tables and texture images passed through."""
    return value if isinstance(value, TableData) or hasattr(value, "levels") else np.asarray(value, dtype=dtype)


@dataclass(frozen=True)
class Table:
    """A table argument of a material model: a float32 array sampled as a 2D or 3D texture.

    Parameters
    ----------
    name : str
        Python keyword and GLSL suffix: the sampler is ``u_<model>_<name>``.
    shape : tuple of int
        The table's axes (2 or 3 of them), without the channels: ``(90, 90, 180)`` for a MERL
        BRDF.  The GLSL may rely on it (it is part of the model's source hash).
    channels : {1, 2, 3, 4}
    low : float
        Smallest valid entry (default ``-inf``); every entry must also be finite.
    unit : str
        Unit of the entries, for documentation.
    doc : str
        One line of documentation.
    """

    name: str
    shape: tuple
    channels: int = 3
    low: float = -np.inf
    unit: str = ""
    doc: str = ""

    def __post_init__(self):
        _check_argument_name("Table", self.name)
        shape = tuple(self.shape) if isinstance(self.shape, (tuple, list)) else None
        if shape is None or len(shape) not in SAMPLERS or not all(
                isinstance(s, (int, np.integer)) and not isinstance(s, bool) and 1 <= s <= 2048 for s in shape):
            raise MaterialDefinitionError(f"Table {self.name!r}: shape must be 2 or 3 sizes from 1 to 2048 "
                                          f"(got {self.shape!r})")
        object.__setattr__(self, "shape", tuple(int(s) for s in shape))
        if self.channels not in (1, 2, 3, 4) or isinstance(self.channels, bool):
            raise MaterialDefinitionError(f"Table {self.name!r}: channels must be 1, 2, 3 or 4 (got {self.channels!r})")

    #: a table has no default: it is always given
    default = None

    @property
    def kind(self):
        return "table"

    @property
    def glsl_type(self):
        """``'sampler2D'`` or ``'sampler3D'``."""
        return SAMPLERS[len(self.shape)]

    @property
    def interval(self):
        """What a valid value is, as text."""
        low = "" if self.low == -np.inf else f", entries >= {self.low:g}"
        return f"a float array of shape {self.shape + (self.channels,)}{low}"

    def validate(self, value, source=None):
        """``value`` as a `TableData`: a TableData, an array of the declared shape (a single channel may
        omit its axis), or the path of a ``.npy`` file holding one; ``source`` names where an array came
        from (for messages and ``repr``).

        Raises
        ------
        TypeError, ValueError
            Naming the table, the expected shape and what is wrong.
        """
        if isinstance(value, TableData):
            array, source = value.array, value.source
        else:
            if isinstance(value, (str, Path)):
                source = str(value)
                try:
                    value = np.load(value, allow_pickle=False)
                except (OSError, ValueError) as exc:
                    raise ValueError(f"{self.name}: cannot read a table from {source!r} ({exc})") from None
            try:
                array = np.asarray(value)
            except (TypeError, ValueError):
                raise TypeError(f"{self.name} must be {self.interval} (got {type(value).__name__})") from None
            if array.dtype.kind not in "fiu" or array.dtype == bool:
                raise TypeError(f"{self.name} must be {self.interval} (got an array of {array.dtype})")
        expected = self.shape + (self.channels,)
        if array.shape == self.shape and self.channels == 1:
            array = array[..., None]
        if array.shape != expected:
            raise ValueError(f"{self.name} must be {self.interval} (got shape {array.shape})")
        with np.errstate(over="ignore"):
            single = np.asarray(array, dtype=np.float32)
        bad = ~np.isfinite(single)
        if bad.any():
            raise ValueError(f"{self.name} has {int(bad.sum())} entries that are NaN or infinite in float32 "
                             f"(it must be {self.interval}, finite)")
        if self.low > -np.inf and single.min() < self.low:
            raise ValueError(f"{self.name} has {int((single < self.low).sum())} entries below {self.low:g} "
                             f"(smallest {float(single.min()):g}); it must be {self.interval}")
        return value if isinstance(value, TableData) else TableData(single, source)

    def example(self):
        """A valid value: zeros."""
        return TableData.zeros(self.shape, self.channels)
