"""Surface inputs: values of a textureable parameter that vary over a mesh (textures, vertex colours).

A parameter declared ``Param(..., textureable=True)`` takes, besides a constant, a `SurfaceInput`,
whose value at a fragment is

    value = scale * T(uv) * C            (per channel; glsl/surface.glsl, `material_inputs`)

for an rgb parameter, and for a scalar parameter one channel ``c`` of each (``channel='b'``: glTF's
metallic is the blue channel of its metallic-roughness texture, roughness the green one):

    value = scale * T(uv).c * C.c        (scale a scalar)

    T(uv)  the texture's linear rgb filtered at the fragment's uv (GLSL ``texture()``: trilinear over
           glphong's own mip pyramid, or bilinear), 1 without a texture;
    C      the mesh's interpolated linear vertex colour (`glphong.scene.geometry.MeshData` ``colors``), 1
           unless ``vertex_colors=True``.

`Texture` and `VertexColors` make the two common cases.  Images are decoded on the CPU: 8- and
16-bit images are sRGB-decoded (``srgb=True``, the default for them) or scaled to [0, 1] (``srgb=False``,
for data such as roughness maps) in float64; float arrays are taken as linear.  The mip pyramid is
made here too (a box filter in linear float64, level ``k`` of size ``max(1, floor(size / 2^k))``), so
the GPU and the twin hold the same texels on every driver (``glGenerateMipmap``'s filter is the
driver's, and llvmpipe's sRGB texture decode is off by up to 2.5 % on dark texels: measured).
Texels are stored as float16 for 8-bit sources (every decoded 8-bit value to 2^-12 relative) and as
float32 otherwise; the twin reads those very values.

UV convention: ``(0, 0)`` is the image's bottom-left corner and v points up (OpenGL, OBJ); the glTF
loader flips glTF's v.  Alpha is ignored.  The twin's sampler is `surface_texture` (the GLSL
``texture()`` call of surface.glsl) and its band `surface_texture_band`.
"""
import hashlib
import threading
import weakref
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from glphong.core import validate as _validate
from glphong.core.filesafety import LIMITS, decode_image, read_bytes
from glphong.core.imaging import encode_srgb8, srgb_decode
from glphong.twin.band import EPS

__all__ = ["SurfaceInput", "Texture", "VertexColors", "TextureImage", "NormalMap", "AlphaMask", "AlphaBlend",
           "surface_texture", "surface_texture_band",
           "WRAPS", "FILTERS", "CHANNELS", "MAX_TEXTURE_SIZE"]

#: texture wrap modes: GL_REPEAT, GL_CLAMP_TO_EDGE (moderngl's textures offer no mirrored repeat)
WRAPS = ("repeat", "clamp")
#: filters: trilinear (GL_LINEAR_MIPMAP_LINEAR, mip pyramid) or bilinear (GL_LINEAR, level 0 only)
FILTERS = ("trilinear", "bilinear")
#: the channels a scalar parameter's surface input may read
CHANNELS = ("r", "g", "b")
#: the largest side glphong uploads (GL 4.5 guarantees 16384)
MAX_TEXTURE_SIZE = 16384


def _decode(array, srgb):
    """Linear float64 rgb (H, W, 3) of an image array (H, W), (H, W, 1..4)."""

    a = np.asarray(array)
    if a.ndim == 2:
        a = a[..., None]
    if a.ndim != 3 or a.shape[2] not in (1, 2, 3, 4):
        raise ValueError(f"a texture image must have shape (H, W) or (H, W, 1 to 4) (got {np.shape(array)})")
    a = a[..., :3] if a.shape[2] >= 3 else np.repeat(a[..., :1], 3, axis=2)  # grey (and alpha): grey rgb
    if a.dtype.kind in "ui" and a.dtype.itemsize <= 2 and a.dtype != bool:
        full = 255.0 if a.dtype.itemsize == 1 else 65535.0
        if a.min() < 0:
            raise ValueError("a texture image of integers must not be negative")
        x = a.astype(np.float64) / full
        return srgb_decode(x) if srgb else x
    if a.dtype.kind != "f":
        raise TypeError(f"a texture image must hold uint8, uint16 or float values (got {a.dtype})")
    if srgb:
        raise ValueError("srgb=True decodes 8- and 16-bit images; a float image is taken as linear: pass srgb=False")
    x = a.astype(np.float64)
    if not (np.all(np.isfinite(x)) and np.all(np.abs(x) <= _validate.FLT_MAX)):
        raise ValueError("a float texture image must be finite in float32")
    return x


def _downsample_axis(a, axis):
    """Box filter halving ``axis`` (size n -> max(1, n // 2)): output texel i averages the source interval
    ``[i n/m, (i+1) n/m)`` with exact area weights (pairs for even n, three texels for odd n)."""
    n = a.shape[axis]
    if n == 1:
        return a
    m = n // 2
    a = np.moveaxis(a, axis, 0)
    if n % 2 == 0:
        out = 0.5 * (a[0::2] + a[1::2])
    else:
        edges = np.arange(m + 1) * (n / m)
        out = np.zeros((m,) + a.shape[1:])
        for j in range(n):  # source texel j covers [j, j + 1): its overlap with each output interval
            lo = np.clip(edges[:-1], j, j + 1)
            hi = np.clip(edges[1:], j, j + 1)
            w = (hi - lo) * (m / n)
            for i in np.nonzero(w > 0)[0]:
                out[i] += w[i] * a[j]
    return np.moveaxis(out, 0, axis)


class TextureImage:
    """An immutable texture: linear rgb mip levels and how they are sampled (what the GPU holds).

    Equal contents and sampling are one object (interned while anything holds it), so an image used
    by several materials is uploaded once per context.

    Parameters
    ----------
    image : (H, W) or (H, W, C) array_like, or str or pathlib.Path
        Pixels, top row first (as Pillow and image files store them), or an image file Pillow reads.
    srgb : bool or None
        Decode 8/16-bit values with the sRGB curve (None: True for 8/16-bit images, False for float).
    wrap : {'repeat', 'clamp'}
    filter : {'trilinear', 'bilinear'}

    Attributes
    ----------
    levels : tuple of (h_k, w_k, 3) ndarray
        Linear rgb, float16 (8-bit sources) or float32, row 0 at the bottom (v = 0); one level for
        'bilinear', the whole pyramid down to 1x1 for 'trilinear'.  Read-only.
    low, high : float
        Smallest and largest texel value (level 0 bounds every level).
    encoding : {'srgb8', 'linear8', 'srgb16', 'linear16', 'float'}
        What the source pixels were (8-bit sources re-encode exactly from the float16 texels:
        `pixels8`).
    digest : str
    source : str or None
    """

    _interned = weakref.WeakValueDictionary()
    _lock = threading.Lock()

    def __new__(cls, image, srgb=None, wrap="repeat", filter="trilinear"):
        source = None
        if isinstance(image, (str, Path)):
            source = str(image)

            # the caller chose this file: any format Pillow reads, sides checked from the header before decoding
            budget = LIMITS.replace(image_pixels=MAX_TEXTURE_SIZE * MAX_TEXTURE_SIZE)
            pixels = decode_image(read_bytes(image, budget), budget, source, "texture image", formats=None)
            if max(pixels.shape[:2]) > MAX_TEXTURE_SIZE:
                raise ValueError(f"{source}: a texture image must be from 1x1 to {MAX_TEXTURE_SIZE}x{MAX_TEXTURE_SIZE} "
                                 f"pixels (got {pixels.shape[1]}x{pixels.shape[0]})")
        else:
            pixels = np.asarray(image)
        if wrap not in WRAPS:
            raise ValueError(f"wrap must be one of {', '.join(map(repr, WRAPS))} (got {wrap!r})")
        if filter not in FILTERS:
            raise ValueError(f"filter must be one of {', '.join(map(repr, FILTERS))} (got {filter!r})")
        if srgb is None:
            srgb = pixels.dtype.kind in "ui"
        if not isinstance(srgb, (bool, np.bool_)):
            raise TypeError(f"srgb must be True, False or None (got {srgb!r})")
        if pixels.ndim < 2 or not 1 <= pixels.shape[0] <= MAX_TEXTURE_SIZE or not 1 <= pixels.shape[1] <= MAX_TEXTURE_SIZE:
            raise ValueError(f"a texture image must be from 1x1 to {MAX_TEXTURE_SIZE}x{MAX_TEXTURE_SIZE} pixels "
                             f"(got shape {pixels.shape})")
        linear = _decode(pixels, bool(srgb))[::-1]  # row 0 at the bottom: v = 0
        store = np.float16 if pixels.dtype.itemsize == 1 and pixels.dtype.kind in "ui" else np.float32
        encoding = "float" if pixels.dtype.kind == "f" else \
            f"{'srgb' if srgb else 'linear'}{8 * min(pixels.dtype.itemsize, 2)}"
        levels = [linear]
        if filter == "trilinear":
            while levels[-1].shape[0] > 1 or levels[-1].shape[1] > 1:
                levels.append(_downsample_axis(_downsample_axis(levels[-1], 0), 1))
        return cls._from_levels(tuple(np.ascontiguousarray(lv, dtype=store) for lv in levels), wrap, filter, source,
                                encoding)

    @classmethod
    def _from_levels(cls, levels, wrap, filter, source=None, encoding="float"):
        h = hashlib.sha256(f"{wrap} {filter}".encode())
        for lv in levels:
            h.update(repr((lv.shape, lv.dtype.str)).encode() + lv.tobytes())
        digest = h.hexdigest()[:16]
        with cls._lock:
            known = cls._interned.get(digest)
            if known is not None:
                return known
            self = object.__new__(cls)
            for lv in levels:
                lv.setflags(write=False)
            self.levels, self.wrap, self.filter, self.digest = tuple(levels), wrap, filter, digest
            self.source, self.encoding = source, encoding
            base = levels[0].astype(np.float64)
            self.low, self.high = float(base.min()), float(base.max())
            cls._interned[digest] = self
        return self

    @property
    def size(self):
        """``(width, height)`` of level 0 [texels]."""
        return self.levels[0].shape[1], self.levels[0].shape[0]

    @property
    def nbytes(self):
        """Bytes of every level."""
        return sum(lv.nbytes for lv in self.levels)

    def pixels8(self):
        """The 8-bit source pixels, top row first, (H, W, 3) uint8 (rgb), recovered exactly from the texels.

        Raises
        ------
        ValueError
            The source was not 8-bit (16-bit and float images cannot be re-encoded losslessly in 8 bits).
        """

        base = self.levels[0][::-1].astype(np.float64)
        if self.encoding == "srgb8":
            return encode_srgb8(base)
        if self.encoding == "linear8":
            return np.rint(np.clip(base, 0.0, 1.0) * 255.0).astype(np.uint8)
        raise ValueError(f"{self!r} was made from a {self.encoding} image, which 8-bit pixels cannot hold exactly")

    def __eq__(self, other):
        return isinstance(other, TextureImage) and other.digest == self.digest

    def __hash__(self):
        return hash(self.digest)

    def __repr__(self):
        name = repr(self.source) if self.source else self.digest[:8]
        return f"TextureImage({name}, {self.size[0]}x{self.size[1]}, {self.wrap}, {self.filter})"

    def __reduce__(self):  # by value: a spawn-started worker rebuilds (and interns) it
        return (TextureImage._from_levels, (tuple(np.asarray(lv) for lv in self.levels), self.wrap, self.filter,
                                            self.source, self.encoding))


@dataclass(frozen=True, eq=True)
class SurfaceInput:
    """The value of a textureable parameter over a surface: ``scale * T(uv) * C`` (see the module).

    Parameters
    ----------
    scale : float or (3,) array_like
        Constant factor per channel (>= 0); the parameter's range applies to the product.  A float where
        ``channel`` is given.
    texture : TextureImage or None
    vertex_colors : bool
        Multiply by the mesh's vertex colours (the mesh must have ``colors``).
    channel : {None, 'r', 'g', 'b'}
        The one channel a scalar parameter reads (None: the rgb of an rgb parameter).
    """

    scale: tuple = (1.0, 1.0, 1.0)
    texture: TextureImage = None
    vertex_colors: bool = False
    channel: str = None

    def __post_init__(self):
        if self.channel is not None and self.channel not in CHANNELS:
            raise ValueError(f"channel must be one of {', '.join(map(repr, CHANNELS))} or None (got {self.channel!r})")
        if self.channel is None:
            object.__setattr__(self, "scale", _validate.rgb("scale", self.scale))
        else:
            object.__setattr__(self, "scale", _validate.scalar("scale", self.scale, low=0.0, high=_validate.FLT_MAX))
        if self.texture is not None and not isinstance(self.texture, TextureImage):
            raise TypeError(f"texture must be a glphong TextureImage or None (got {type(self.texture).__name__})")
        if not isinstance(self.vertex_colors, (bool, np.bool_)):
            raise TypeError(f"vertex_colors must be a bool (got {self.vertex_colors!r})")
        if self.texture is None and not self.vertex_colors:
            raise ValueError("a SurfaceInput needs a texture, vertex_colors=True or both (a constant is a plain value)")

    @property
    def mode(self):
        """``'texture'``, ``'vertex'`` or ``'texture*vertex'``, followed by ``':<channel>'`` for a scalar's input: what
        the program computes (part of its key)."""
        mode = "texture*vertex" if self.texture is not None and self.vertex_colors else \
            "texture" if self.texture is not None else "vertex"
        return mode if self.channel is None else f"{mode}:{self.channel}"

    def value_range(self):
        """``(low, high)``, each (3,) (floats for a channel): the bounds of the value over any surface (vertex colours
        in [0, 1])."""
        s = np.asarray(self.scale)
        if self.texture is None:
            lo, hi = 1.0, 1.0
        elif self.channel is None:
            lo, hi = self.texture.low, self.texture.high
        else:
            base = self.texture.levels[0][..., CHANNELS.index(self.channel)]
            lo, hi = float(base.min()), float(base.max())
        if self.vertex_colors:
            lo, hi = min(lo, 0.0), max(hi, 0.0)
        return s * lo, s * hi

    def __repr__(self):
        parts = [] if self.scale in ((1.0, 1.0, 1.0), 1.0) else [f"scale={self.scale}"]
        parts += [] if self.channel is None else [f"channel={self.channel!r}"]
        kind = "VertexColors" if self.texture is None else "Texture"
        if self.texture is not None:
            parts.insert(0, repr(self.texture))
            parts += ["vertex_colors=True"] if self.vertex_colors else []
        return f"{kind}({', '.join(parts)})"


def Texture(image, scale=1.0, srgb=None, wrap="repeat", filter="trilinear", vertex_colors=False, channel=None):
    """A textureable parameter's value from an image: ``scale * T(uv)`` (times the vertex colours with
    ``vertex_colors=True``); for a scalar parameter, one channel of it: ``scale * T(uv).c``.

    Parameters
    ----------
    image : array_like, str, pathlib.Path or TextureImage
        Pixels (top row first), an image file, or a `TextureImage` (its srgb, wrap and filter kept).
    scale : float or (3,) array_like
        Factor per channel, >= 0 (glTF's baseColorFactor, MTL's Kd under map_Kd).
    srgb : bool or None
        sRGB-decode 8/16-bit pixels (None: yes for them; float images are linear).
    wrap : {'repeat', 'clamp'}
    filter : {'trilinear', 'bilinear'}
    vertex_colors : bool
    channel : {None, 'r', 'g', 'b'}
        The channel a scalar parameter reads (glTF: metallic 'b', roughness 'g' of the metallic-roughness
        texture, occlusion 'r'); None for an rgb parameter.

    Returns
    -------
    SurfaceInput

    Examples
    --------
    >>> import numpy as np, glphong
    >>> checker = (np.indices((8, 8)).sum(axis=0) % 2 * 255).astype(np.uint8)
    >>> material = glphong.Lambert(kd=glphong.Texture(checker, scale=1 / np.pi))
    """
    texture = image if isinstance(image, TextureImage) else TextureImage(image, srgb, wrap, filter)
    return SurfaceInput(scale=scale, texture=texture, vertex_colors=vertex_colors, channel=channel)


def VertexColors(scale=1.0, channel=None):
    """A textureable parameter's value from the mesh's vertex colours: ``scale * C`` (``scale * C.c`` with a
    ``channel``, for a scalar parameter).

    Returns
    -------
    SurfaceInput
    """
    return SurfaceInput(scale=scale, vertex_colors=True, channel=channel)


class _Frozen:
    """An immutable value of a few fields (`NormalMap`, `AlphaMask`): equal, hashed and pickled by them."""

    __slots__ = ()

    def __setattr__(self, name, value):
        raise AttributeError(f"{type(self).__name__} is immutable")

    def _values(self):
        return tuple(getattr(self, name) for name in self.__slots__)

    def __eq__(self, other):
        return type(other) is type(self) and other._values() == self._values()

    def __hash__(self):
        return hash((type(self).__name__,) + self._values())

    def __reduce__(self):
        return type(self), self._values()


class NormalMap(_Frozen):
    """A tangent-space normal map: the shading normal at a fragment is ``normalize(t (s m.x) + b (s m.y) + n m.z)``,
    ``m = 2 T(uv) - 1`` (glTF 2.0's ``normalTexture``; glsl/normal_map.glsl, `glphong.reference.surface_normal`).

    Given to any material as ``normal_map=``; every term then shades with the mapped normal.  The mesh needs UVs and
    a tangent frame (tangents from the file, or derived from the UVs).

    Parameters
    ----------
    image : array_like, str, pathlib.Path or TextureImage
        The normal texture, linear (8-bit values scaled to [0, 1], never sRGB-decoded).
    scale : float
        glTF's ``normalTexture.scale``: multiplies ``m.x`` and ``m.y`` (finite; negative flips them).
    wrap : {'repeat', 'clamp'}
    filter : {'trilinear', 'bilinear'}
    """

    __slots__ = ("texture", "scale")  # the constructor's order: pickled by them

    def __init__(self, image, scale=1.0, wrap="repeat", filter="trilinear"):
        texture = image if isinstance(image, TextureImage) else TextureImage(image, srgb=False, wrap=wrap, filter=filter)
        if texture.encoding.startswith("srgb"):
            raise ValueError("a normal map is linear data: make its TextureImage with srgb=False")
        object.__setattr__(self, "texture", texture)
        object.__setattr__(self, "scale", _validate.scalar("scale", scale, low=-_validate.FLT_MAX))

    def __repr__(self):
        return f"NormalMap({self.texture!r}{'' if self.scale == 1.0 else f', scale={self.scale:g}'})"


class AlphaMask(_Frozen):
    """Alpha testing (glTF's ``alphaMode: MASK``): a fragment whose alpha is below ``cutoff`` is not drawn (in the
    radiance and in the G-buffer alike, so the twin shades exactly the fragments the GPU drew); the others are opaque.

    Given to any material as ``alpha_mask=``.  Alpha is a constant, or one channel of a texture times a constant
    (glTF: ``baseColorFactor.a`` times the base-colour texture's alpha, ``glphong.Texture(alpha, scale,
    srgb=False, channel='r')``).  Shadow maps are drawn without the mask (a masked surface casts its whole shadow).

    Parameters
    ----------
    cutoff : float
        glTF's ``alphaCutoff`` (default 0.5), >= 0.
    alpha : float or SurfaceInput
        In [0, 1]; a `SurfaceInput` reads its texture's red channel (``channel='r'``), without vertex colours.
    """

    __slots__ = ("cutoff", "alpha")  # the constructor's order: pickled by them

    def __init__(self, cutoff=0.5, alpha=1.0):
        object.__setattr__(self, "cutoff", _validate.scalar("cutoff", cutoff, low=0.0))
        object.__setattr__(self, "alpha", _alpha_value(alpha, "an alpha mask"))

    @property
    def textured(self):
        """Whether alpha varies over the surface."""
        return isinstance(self.alpha, SurfaceInput)

    def __repr__(self):
        return f"AlphaMask(cutoff={self.cutoff:g}, alpha={self.alpha!r})"


def _alpha_value(alpha, what):
    """An alpha in [0, 1]: a float, or a `SurfaceInput` reading a texture's red channel (mesh_fragment.glsl reads .r)
    without vertex colours, in [0, 1] everywhere; ValueError naming ``what`` otherwise."""
    if not isinstance(alpha, SurfaceInput):
        return _validate.scalar("alpha", alpha, low=0.0, high=1.0)
    if alpha.channel != "r" or alpha.vertex_colors or alpha.texture is None:
        raise ValueError(f"{what}'s alpha is one channel of a texture, its red (channel='r', no vertex "
                         f"colours; got channel={alpha.channel!r}): move the alpha into the red channel")
    low, high = alpha.value_range()
    if low < 0.0 or high > 1.0:
        raise ValueError(f"alpha must be in [0, 1] everywhere; {alpha!r} spans [{low:g}, {high:g}]")
    return alpha


class AlphaBlend(_Frozen):
    """Alpha blending (glTF's ``alphaMode: BLEND``): the surface covers a fraction ``alpha`` of what lies behind it.
    Every blended surface is composited over what lies behind it in depth order per pixel, premultiplied, in linear
    float: ``C = alpha L + (1 - alpha) C_behind`` (the Porter-Duff "over" the glTF specification names), by depth
    peeling (`glphong.gpu.peeling`, docs/design.md section 16).

    Given to any material as ``alpha_blend=``; not together with ``alpha_mask``.  Alpha is a constant, or one channel
    of a texture times a constant (glTF: ``baseColorFactor.a`` times the base-colour texture's alpha,
    ``glphong.Texture(alpha, scale, srgb=False, channel='r')``; the mesh needs uvs).  Shadow maps are drawn without it
    (a blended surface that casts shadows casts its whole shadow); give the object ``casts_shadow=False`` for none.

    Parameters
    ----------
    alpha : float or SurfaceInput
        The coverage, in [0, 1] (0: the surface is not seen, 1: it hides what lies behind it, still drawn as a
        blended layer); a `SurfaceInput` reads its texture's red channel (``channel='r'``), without vertex colours.
    """

    __slots__ = ("alpha",)  # the constructor's order: pickled by them

    def __init__(self, alpha=1.0):
        object.__setattr__(self, "alpha", _alpha_value(alpha, "a blended material"))

    @property
    def textured(self):
        """Whether alpha varies over the surface."""
        return isinstance(self.alpha, SurfaceInput)

    def __repr__(self):
        return f"AlphaBlend({self.alpha!r})" if self.textured else f"AlphaBlend({self.alpha:g})"


# --------------------------------------------------------------------------- the twin of surface.glsl
def _wrap_index(i, n, wrap):
    """Texel index ``i`` wrapped into ``[0, n)`` (GL 4.6 table 8.20)."""
    return np.mod(i, n) if wrap == "repeat" else np.clip(i, 0, n - 1)


def _bilinear(level, uv, wrap):
    """``(value, texels)`` of GL_LINEAR at ``uv`` on one level: value (N, 3); texels (4, N, 3) the four
    texels it weights."""
    h, w = level.shape[:2]
    x = uv[:, 0] * w - 0.5
    y = uv[:, 1] * h - 0.5
    i0, j0 = np.floor(x), np.floor(y)
    a, b = (x - i0)[:, None], (y - j0)[:, None]
    i0, j0 = i0.astype(np.int64), j0.astype(np.int64)
    i1, j1 = _wrap_index(i0 + 1, w, wrap), _wrap_index(j0 + 1, h, wrap)
    i0, j0 = _wrap_index(i0, w, wrap), _wrap_index(j0, h, wrap)
    texels = np.stack([level[j0, i0], level[j0, i1], level[j1, i0], level[j1, i1]]).astype(np.float64)
    value = (1 - a) * (1 - b) * texels[0] + a * (1 - b) * texels[1] + (1 - a) * b * texels[2] + a * b * texels[3]
    return value, texels


def _sample(image, uv, lod):
    """``(value, low, high)``: the filtered value and the extremes of the texels it weights, each (N, 3)."""
    uv = np.asarray(uv, dtype=np.float64)
    if image.filter == "bilinear" or len(image.levels) == 1:
        value, texels = _bilinear(image.levels[0], uv, image.wrap)
        return value, texels.min(axis=0), texels.max(axis=0)
    top = len(image.levels) - 1
    lam = np.clip(np.asarray(lod, dtype=np.float64), 0.0, top)
    d1 = np.minimum(np.floor(lam).astype(np.int64), top)
    frac = (lam - d1)[:, None]
    value, low, high = (np.zeros((len(uv), 3)) for _ in range(3))
    for d in np.unique(d1):
        sel = d1 == d
        v1, t1 = _bilinear(image.levels[d], uv[sel], image.wrap)
        if d < top:
            v2, t2 = _bilinear(image.levels[d + 1], uv[sel], image.wrap)
            t = np.concatenate([t1, t2])
            value[sel] = (1 - frac[sel]) * v1 + frac[sel] * v2
        else:
            t = t1
            value[sel] = v1
        low[sel], high[sel] = t.min(axis=0), t.max(axis=0)
    return value, low, high


def surface_texture(image, uv, lod):
    """The twin of surface.glsl's ``surface_texture(s, uv)`` (GLSL ``texture(s, uv).rgb``), (N, 3) float64.

    Parameters
    ----------
    image : TextureImage
    uv : (N, 2) array_like
        Texture coordinates (the G-buffer's).
    lod : (N,) array_like
        The level of detail the GPU used (the G-buffer's ``textureQueryLOD(s, uv).x``): trilinear
        filtering blends levels ``floor(lod)`` and ``floor(lod) + 1`` by its fraction, as GL 4.6 section
        8.14 defines; ignored for 'bilinear'.
    """
    return _sample(image, uv, lod)[0]


def alpha_masked(uv, lod, mask):
    """The twin of mesh_fragment.glsl's ``alpha_masked(uv)``: whether a fragment is discarded, (N,) bool.

    ``alpha = scale`` (times the red channel of `surface_texture` where the alpha is textured) ``< cutoff``, with the
    float32 uniforms the GPU reads; ``uv`` (N, 2) and ``lod`` (N,) as `surface_texture` takes them; ``mask`` the
    `AlphaMask`."""
    uv = np.asarray(uv, dtype=np.float64)
    scale = float(np.float32(mask.alpha.scale if mask.textured else mask.alpha))
    alpha = np.full(len(uv), scale)
    if mask.textured:
        alpha = alpha * surface_texture(mask.alpha.texture, uv, lod)[:, 0]
    return alpha < float(np.float32(mask.cutoff))


def surface_texture_band(image, uv, lod, constants):
    """``(value, low, high)``, each (N, 3): `surface_texture`'s value and the interval of the GPU's filtered
    texture value around it, from one sampling.

    GL leaves the precision of filter weights to the implementation (Direct3D requires 8 fractional
    bits): the value may be off by ``T`` times the spread of the texels it weights, plus a few ulps of
    their magnitude, and a filter's weights are non-negative and sum to 1, so it also lies between
    the smallest and the largest of them.  ``T = constants.T``.
    """

    value, low, high = _sample(image, uv, lod)
    ulps = constants.A * EPS * np.maximum(np.abs(low), np.abs(high))
    width = constants.T * (high - low) + ulps
    return value, np.maximum(value - width, low - ulps), np.minimum(value + width, high + ulps)
