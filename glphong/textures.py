"""The textures of one GL context: each `TableData` a drawn program reads, uploaded once.

A `TextureStore` belongs to a `glphong.programs.ProgramCache` (one per context) and is released with
it.  A table is uploaded the first time a program that samples it is bound (`Program.bind`), never
before: a scene whose drawn objects read no table uploads nothing.  Entries are keyed by the table's
content hash and hold it weakly: a table no material holds any more is released at the next upload.
"""
import weakref

import moderngl
import numpy as np

__all__ = ["TextureStore"]


class TextureStore:
    """Textures of `glphong.materials.TableData` values in one context.

    Parameters
    ----------
    mgl : moderngl.Context

    Attributes
    ----------
    uploads : int
        Tables uploaded since creation.
    """

    def __init__(self, mgl):
        self._mgl = mgl
        self._entries = {}  # digest -> (weakref to the TableData, texture)
        self.uploads = 0

    def texture(self, table):
        """The texture holding ``table`` (uploaded on first use): texel ``(k, j, i)`` is ``array[i, j, k]``,
        nearest filtering, no mipmaps (the GLSL reads it with ``texelFetch``)."""
        entry = self._entries.get(table.digest)
        if entry is not None and entry[0]() is not None:
            return entry[1]
        self._purge()
        data = np.ascontiguousarray(table.array, dtype=np.float32)
        size = tuple(reversed(data.shape[:-1]))
        channels = data.shape[-1]
        if len(size) == 3:
            texture = self._mgl.texture3d(size, channels, data.tobytes(), dtype="f4")
        else:
            texture = self._mgl.texture(size, channels, data.tobytes(), dtype="f4")
        texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        texture.repeat_x = texture.repeat_y = False
        if len(size) == 3:
            texture.repeat_z = False
        self._entries[table.digest] = (weakref.ref(table), texture)
        self.uploads += 1
        return texture

    def bind(self, table, unit):
        """Bind ``table``'s texture to texture unit ``unit``."""
        self.texture(table).use(location=unit)

    def _purge(self):
        for digest in [d for d, (ref, _) in self._entries.items() if ref() is None]:
            self._entries.pop(digest)[1].release()

    def nbytes(self):
        """Bytes of the textures held (float32 data)."""
        return sum(t.width * t.height * getattr(t, "depth", 1) * t.components * 4 for _, t in self._entries.values())

    def __len__(self):
        return len(self._entries)

    def release(self):
        """Release every texture."""
        for _, texture in self._entries.values():
            texture.release()
        self._entries.clear()
