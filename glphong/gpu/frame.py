"""What a render returns: a `Frame` (linear float32 radiance, coverage, optional depth and normals) and
the `GBuffer` of per-pixel shader inputs that the twin shades.
"""
from dataclasses import dataclass, replace

import numpy as np

from glphong.core import validate as _validate
from glphong.core.imaging import encode_srgb8, png_bytes, save_npy, save_png

__all__ = ["Frame", "GBuffer"]


@dataclass(frozen=True)
class Frame:
    """A rendered image.

    Attributes
    ----------
    radiance : (H, W, 3) float32 ndarray or None
        Linear radiance [W/(m^2 sr)], row 0 at the top, never clamped (None where ``passes`` leaves it out).  With multisampling
        or supersampling, pixels on silhouettes hold the coverage-weighted average (the
        background counts as 0).  A writable view into the one RGBA readback (GL's bottom-up
        rows flipped by a negative stride; no copy is made): ``numpy.ascontiguousarray`` gives
        C order where a consumer needs it.
    mask : (H, W) bool ndarray
        Pixels covered by geometry (any sample; the pixel centre where the radiance is left out); with blended
        surfaces, where ``coverage > 0``.
    coverage : (H, W) float32 ndarray
        Fraction of the pixel's samples covered by geometry (0 or 1 with one sample, or without the radiance); with
        blended surfaces (`glphong.AlphaBlend`) the composite's alpha, ``1 - prod(1 - a_k)`` over the blended layers
        where no opaque surface lies behind them, 1 where one does.
    depth : (H, W) float32 ndarray or None
        With ``render(scene, depth=True)``: linear depth [m], the distance of the surface point at
        the pixel centre from the camera along its viewing axis (view-space ``-z``; not the distance
        to the eye), 0 where no geometry covers the centre.  One sample per pixel at the output size,
        whatever ``samples`` and ``supersample`` are.
    normal : (H, W, 3) float32 ndarray or None
        With ``render(scene, normals=True)``: the world-space unit shading normal at the pixel centre
        (interpolated, renormalised, flipped toward the viewer on the back faces of two-sided
        materials, as shaded), 0 where not covered or where the normal is zero or not finite.
    distance, normal_camera, uv, instance, category, object_coordinates, nocs, flow, backward_flow : ndarray or None
        The frame passes ``render(scene, passes=...)`` asks for (`glphong.gpu.passes`: each one's meaning, shape, unit
        and dtype); None where not asked for.
    matte_ids : (H, W, k) uint32 ndarray or None
        The 'matte' pass: per pixel the ``instance_id`` of the ``k`` objects with the largest share of its square, by
        share descending (ties by id ascending), 0 padding (`glphong.gpu.matte`).
    matte_fractions : (H, W, k) float32 ndarray or None
        Their shares of the pixel's area, descending, 0 padding; a pixel's sum is its covered share.
    blend_layers : int or None
        Where the scene has blended materials (`glphong.AlphaBlend`): the most blended layers any pixel composites
        (`glphong.gpu.peeling`); None without.
    blend_cut : (H, W) bool ndarray or None
        The pixels that had more blended layers than the renderer's ``blend_layers``: their farthest ones were left
        out (a `glphong.gpu.peeling.BlendCapWarning` says how many); None where no pixel was cut.
    passes : tuple of str
        The passes the frame holds, in `glphong.gpu.passes.PASSES` order.
    exposure : float
        The linear exposure a notebook shows the frame at (``_repr_png_``: Jupyter displays a `Frame`
        as a PNG of ``to_srgb8(exposure)``, the exact sRGB curve); 1 unless given (`with_exposure`).
    """

    radiance: np.ndarray
    mask: np.ndarray
    coverage: np.ndarray = None
    depth: np.ndarray = None
    normal: np.ndarray = None
    exposure: float = 1.0
    distance: np.ndarray = None
    normal_camera: np.ndarray = None
    uv: np.ndarray = None
    instance: np.ndarray = None
    category: np.ndarray = None
    object_coordinates: np.ndarray = None
    nocs: np.ndarray = None
    flow: np.ndarray = None
    backward_flow: np.ndarray = None
    matte_ids: np.ndarray = None
    matte_fractions: np.ndarray = None
    passes: tuple = ("radiance",)
    blend_layers: int = None
    blend_cut: np.ndarray = None

    def with_exposure(self, exposure):
        """The same frame (arrays shared, not copied) shown at ``exposure`` in a notebook."""
        return replace(self, exposure=_validate.scalar("exposure", exposure, low_inclusive=False))

    def _repr_png_(self):
        """PNG bytes of the frame at ``self.exposure`` (exact sRGB curve): how Jupyter shows a Frame (None without
        the radiance)."""
        return None if self.radiance is None else png_bytes(self.radiance, self.exposure)

    def _radiance(self):
        if self.radiance is None:
            raise ValueError("this frame holds no radiance: render with 'radiance' among the passes")
        return self.radiance

    def to_srgb8(self, exposure=1.0):
        """8-bit sRGB image, (H, W, 3) uint8 (see `glphong.imaging.encode_srgb8`)."""
        return encode_srgb8(self._radiance(), exposure)

    def save_png(self, path, exposure=1.0, compress_level=1):
        """Tone-map with ``exposure``, encode with the exact sRGB curve, write a PNG (`glphong.imaging.save_png`)."""
        save_png(path, self._radiance(), exposure, compress_level)

    def save_npy(self, path):
        """Write the raw float32 radiance ``(H, W, 3)`` as ``.npy``."""
        save_npy(path, self._radiance())


@dataclass(frozen=True)
class GBuffer:
    """The per-pixel inputs the shader used.

    Attributes
    ----------
    position : (H, W, 3) float32 ndarray
        World-space surface point [m] (0 where not covered).
    normal : (H, W, 3) float32 ndarray
        World-space unit normal after renormalisation and the two-sided flip; 0 where
        the interpolated normal was zero or not finite (ambient-only pixels).
    object_index : (H, W) int ndarray
        Index into ``scene.objects``, -1 where not covered.
    mask : (H, W) bool ndarray
        Pixels covered by geometry.
    tangent : (H, W, 4) float32 ndarray or None
        The interpolated world-space tangent (handedness in w) the frame was built from, where a
        drawn term needs ``'tangent'``; else None.
    uv : (H, W, 2) float32 ndarray or None
        The interpolated texture coordinates, where a drawn term needs ``'uv'`` or a parameter is
        textured; else None.
    color : (H, W, 3) float32 ndarray or None
        The interpolated linear vertex colour, where a parameter takes vertex colours; else None.
    lod : (H, W, 4) float32 ndarray or None
        Per pixel, the level of detail the GPU used for the textures of the object's material, one per texture
        size in the order of `glphong.shaders.key.lod_slots` (0 beyond), where a parameter is textured.
    face : (H, W, 3) float32 ndarray or None
        The covered triangle's own unit normal (either orientation), where a light casts shadows (the shadow
        bias's slope, docs/design.md section 12).
    object_coordinates : (H, W, 3) float32 ndarray or None
        The covered point in its object's own frame [m] (the interpolated vertex position before the pose), where
        a frame pass asks for it (`glphong.gpu.passes`).
    unperturbed : (H, W, 3) float32 ndarray or None
        The unit normal before the material's normal map (``normal`` where the object's material has none), where a
        drawn term needs ``'unperturbed'``: a coat normal over a normal-mapped `glphong.GltfPBR`, whose coat
        KHR_materials_clearcoat takes on the unperturbed frame.
    """

    position: np.ndarray
    normal: np.ndarray
    object_index: np.ndarray
    mask: np.ndarray
    tangent: np.ndarray = None
    uv: np.ndarray = None
    color: np.ndarray = None
    lod: np.ndarray = None
    face: np.ndarray = None
    object_coordinates: np.ndarray = None
    unperturbed: np.ndarray = None

    @classmethod
    def from_planes(cls, position, normal, planes, copy=True):
        """The G-buffer of read-back RGBA planes: ``position`` (H, W, 4) (w: object index + 1, 0 where not covered),
        ``normal`` (H, W, 4) or None (then left None: a frame pass's draw that did not write it), ``planes`` dict of
        extra plane name (`glphong.shaders.options.GBUFFER_PLANES`) to (H, W, 4); ``copy=False``: the planes are
        views of the given ones (strided: the frame passes gather their covered pixels from them), not C-ordered
        copies."""
        mask = position[..., 3] > 0.0
        channels = {"tangent": 4, "uv": 2, "color": 3, "lod": 4, "face": 3, "object": 3, "unperturbed": 3}
        keep = np.ascontiguousarray if copy else (lambda a: a)
        extra = {("object_coordinates" if name == "object" else name): keep(plane[..., :channels[name]])
                 for name, plane in planes.items()}
        return cls(position=keep(position[..., :3]), normal=None if normal is None else keep(normal[..., :3]),
                   object_index=np.where(mask, np.rint(position[..., 3]).astype(np.int64) - 1, -1), mask=mask, **extra)
