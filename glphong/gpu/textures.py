"""The textures of one GL context: each `TableData` a drawn program reads, uploaded once.

A `TextureStore` belongs to a `glphong.gpu.programs.ProgramCache` (one per context) and is released with
it.  A table is uploaded the first time a program that samples it is bound (`Program.bind`), never
before: a scene whose drawn objects read no table uploads nothing.  Entries are keyed by the table's
content hash and hold it weakly: a table no material holds any more is released at the next upload.
"""
import weakref

import moderngl
import numpy as np

from glphong.gpu.resources import available_memory

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
        self.limits = None  # (GL_MAX_TEXTURE_SIZE, GL_MAX_3D_TEXTURE_SIZE, GL_RENDERER), read at the first upload

    def texture(self, table):
        """The texture holding ``table`` (uploaded on first use).  A `TableData`: texel ``(k, j, i)`` is
        ``array[i, j, k]``, nearest filtering, no mipmaps (the GLSL reads it with ``texelFetch``).  A
        `glphong.definitions.surface.TextureImage`: its levels as float16 or float32 rgb, its filter and wrap."""
        entry = self._entries.get(table.digest)
        if entry is not None and entry[0]() is not None:
            return entry[1]
        self._purge()
        self._check_fits(table)
        texture = self._upload_image(table) if hasattr(table, "levels") else self._upload_table(table)
        self._entries[table.digest] = (weakref.ref(table), texture)
        self.uploads += 1
        return texture

    def _check_fits(self, table):
        """ValueError naming ``table`` (a texture image or a table) where a side is beyond this context's largest
        texture, or its upload (a copy of its bytes, then the driver's: twice `nbytes`) beyond 80% of the memory
        available (`glphong.gpu.resources.available_memory`), before anything is copied or allocated."""
        if self.limits is None:  # inside a draw: the context is current
            info = self._mgl.info
            self.limits = (info["GL_MAX_TEXTURE_SIZE"], info["GL_MAX_3D_TEXTURE_SIZE"], info["GL_RENDERER"])
        image = hasattr(table, "levels")
        sides = table.size if image else tuple(reversed(table.array.shape[:-1]))
        name = f"texture image {table.source or table.digest[:8]}" if image else \
            f"table {table.source or table.digest[:8]} of shape {table.array.shape}"
        limit, which = (self.limits[1], "GL_MAX_3D_TEXTURE_SIZE") if len(sides) == 3 else \
            (self.limits[0], "GL_MAX_TEXTURE_SIZE")
        if max(sides) > limit:
            raise ValueError(f"{name}: {'x'.join(map(str, sides))} texels, beyond this context's {which} = {limit} "
                             f"({self.limits[2]}): use a smaller texture")
        needed = 2 * table.nbytes
        available = available_memory()
        if available is not None and needed > 0.8 * available:
            raise ValueError(f"{name}: uploading it needs about {needed / 2**20:.0f} MiB (its {table.nbytes} bytes "
                             f"copied, then the driver's copy); this machine has {available / 2**20:.0f} MiB "
                             "available (at most 80% of it may be used): use a smaller texture")

    def _upload_image(self, image):
        levels = image.levels
        dtype = "f2" if levels[0].dtype == np.float16 else "f4"
        texture = self._mgl.texture(image.size, 3, levels[0].tobytes(), dtype=dtype, alignment=1)
        if len(levels) > 1:
            texture.build_mipmaps(0, len(levels) - 1)  # allocates the levels; glphong's own texels replace GL's
            for k, level in enumerate(levels[1:], start=1):
                texture.write(level.tobytes(), level=k, alignment=1)
            texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        else:
            texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
        texture.repeat_x = texture.repeat_y = image.wrap == "repeat"  # else GL_CLAMP_TO_EDGE
        texture.anisotropy = 1.0
        return texture

    def _upload_table(self, table):
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
        return texture

    def bind(self, table, unit):
        """Bind ``table``'s texture to texture unit ``unit``."""
        self.texture(table).use(location=unit)

    def _purge(self):
        for digest in [d for d, (ref, _) in self._entries.items() if ref() is None]:
            self._entries.pop(digest)[1].release()

    def nbytes(self):
        """Bytes of the data of the textures held."""
        return sum(ref().nbytes for ref, _ in self._entries.values() if ref() is not None)

    def __len__(self):
        return len(self._entries)

    def release(self):
        """Release every texture."""
        for _, texture in self._entries.values():
            texture.release()
        self._entries.clear()
