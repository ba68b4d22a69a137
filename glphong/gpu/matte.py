"""The matte pass: each object's share of each pixel, estimated from a regular grid of samples (docs/design.md
section 15, "The matte pass").

The pass (`glphong.shaders.builders.matte_key`, glsl/matte_fragment.glsl) draws every object with the depth test into
an unsigned-integer target at ``samples`` (``s``) times the output size along each axis, writing the object's index
plus one (0 the background); the sample of cell ``(a, b)`` of pixel ``(i, j)`` (column, row; row 0 at the top) lies
at the cell's centre, image position ``(i + (a + 1/2)/s, j + (b + 1/2)/s)``.  The image is drawn in tiles of at most
``TILE`` samples a side (the projection composed with the tile's window, `tile_matrix`), so GPU and host memory stay
bounded whatever the size and ``s``.  Per pixel the host counts its ``s^2`` samples per object (only pixels whose
samples differ are sorted) and keeps the ``k`` largest:

- ``matte_ids`` (H, W, k) uint32: the objects' ``instance_id``, by fraction descending (ties by id ascending), 0
  padding;
- ``matte_fractions`` (H, W, k) float32: ``count / s^2``, descending, 0 padding; a pixel's sum is its covered share
  (of its samples) when it sees at most ``k`` objects.

Error: the estimate of an object's share counts the cells whose centre it covers; a cell that no boundary of the
object's visible region crosses is counted exactly, so the error is at most the crossed cells' area.  A straight
boundary across the pixel moves the estimate by at most ``1 / (2 s)`` (each row of cells counts the covered length
at its centre line to within half a cell), and `matte_tolerance` allows two of them (a corner): ``1 / s``.  The
measured error against the exact coverage (`glphong.checks.coverage_twin`) for ``s`` = 4 to 64 is in docs/speed.md
and ``glphong bench --matte``.  Objects whose constant alpha lies below their material's cutoff are not drawn (they
are not seen); a textured alpha mask is refused.
"""
import moderngl
import numpy as np

from glphong.definitions.surface import alpha_masked
from glphong.shaders.builders import matte_key

__all__ = ["MATTE_SAMPLES", "MATTE_K", "MAX_MATTE_K", "MAX_MATTE_SAMPLES", "TILE", "Matte", "matte_tolerance", "tile_matrix", "count_samples",
           "drawn_objects", "matte_objects"]

#: samples along each axis of a pixel (s), the default: the measured worst pixel is below 1/64 on the test scenes
MATTE_SAMPLES = 32
#: entries kept per pixel, the default (Cryptomatte's usual depth)
MATTE_K = 4
#: the most entries a pixel may keep (`glphong.Renderer`'s ``matte_k``; the frame files hold as many)
MAX_MATTE_K = 16
#: the most samples per axis (`glphong.Renderer`'s ``matte_samples``)
MAX_MATTE_SAMPLES = 64
#: the largest tile drawn at once [samples a side]: 16 MiB of uint32
TILE = 2048


def matte_tolerance(samples):
    """The largest error `Matte.draw` allows itself in one object's fraction of one pixel with ``samples`` per axis:
    ``1 / samples`` (two straight boundaries, each at most ``1 / (2 samples)``; module docstring)."""
    return 1.0 / samples


def drawn_objects(scene, refusal):
    """Indices of the opaque objects a pass draws: all but those whose constant alpha lies below their cutoff (they are
    not seen) and the blended ones (`glphong.AlphaBlend`: the geometry passes, the matte and the G-buffer are those of
    the nearest opaque or alpha-masked surface, docs/design.md section 16).

    Parameters
    ----------
    scene : glphong.Scene
    refusal : callable
        ``refusal(obj)``: the message of the ValueError raised for an object with a textured alpha mask (which the
        caller does not follow).

    Returns
    -------
    list of int
    """
    drawn = []
    for index, obj in enumerate(scene.objects):
        if obj.material.alpha_blend is not None:
            continue
        mask = obj.material.alpha_mask
        if mask is not None and mask.textured:
            raise ValueError(refusal(obj))
        if mask is None or not alpha_masked(np.zeros((1, 2)), np.zeros(1), mask)[0]:
            drawn.append(index)
    return drawn


def matte_objects(scene):
    """Indices of the objects the matte pass draws (`drawn_objects`); ValueError naming the pass for a textured alpha
    mask."""
    return drawn_objects(scene, lambda obj: f"the 'matte' pass does not follow textured alpha masks yet, and object "
                                            f"{obj.name!r} has one: leave 'matte' out, or give the material a constant "
                                            "alpha")


def tile_matrix(size, tile):
    """The matrix that maps the whole image's clip space to one tile's, (4, 4) float64.

    Parameters
    ----------
    size : (int, int)
        The image ``(W, H)`` [px].
    tile : (int, int, int, int)
        ``(column, row, width, height)`` of the tile [px], row 0 at the top.

    Returns
    -------
    (4, 4) ndarray
        ``T`` with ``T @ clip`` the tile's clip coordinates: ``x' = (W / w) x + ((W - 2 c - w) / w) w_clip`` and the
        same for y with the tile's rows counted from the bottom (GL's window); z and w unchanged.
    """
    width, height = size
    column, row, w, h = tile
    bottom = height - row - h
    out = np.eye(4)
    out[0, 0], out[0, 3] = width / w, (width - 2.0 * column - w) / w
    out[1, 1], out[1, 3] = height / h, (height - 2.0 * bottom - h) / h
    return out


def count_samples(samples, s, k):
    """Each pixel's ``k`` most frequent nonzero values among its ``s x s`` samples.

    Parameters
    ----------
    samples : (h s, w s) uint32 ndarray
        The tile's samples (object index plus one; 0 background), row 0 at the top.
    s : int
        Samples per pixel along each axis.
    k : int
        Entries kept per pixel.

    Returns
    -------
    values : (h, w, k) uint32 ndarray
        The values by count descending, ties by value ascending; 0 padding.
    counts : (h, w, k) int64 ndarray
        Their counts, 0 padding.
    """
    h, w = samples.shape[0] // s, samples.shape[1] // s
    blocks = samples.reshape(h, s, w, s)
    low, high = blocks.min(axis=(1, 3)), blocks.max(axis=(1, 3))
    values = np.zeros((h, w, k), np.uint32)
    counts = np.zeros((h, w, k), np.int64)
    whole = (low == high) & (low != 0)
    values[whole, 0] = low[whole]
    counts[whole, 0] = s * s
    rows, cols = np.nonzero(low != high)
    if rows.size == 0:
        return values, counts
    mixed = np.sort(blocks[rows, :, cols, :].reshape(rows.size, s * s), axis=1)
    flat = mixed.reshape(-1)
    start = np.ones(flat.size, bool)
    start[1:] = flat[1:] != flat[:-1]
    start[::s * s] = True  # every pixel's first sample starts a run
    first = np.flatnonzero(start)
    length = np.diff(np.append(first, flat.size))
    pixel = first // (s * s)
    value = flat[first]
    keep = value != 0
    pixel, value, length = pixel[keep], value[keep], length[keep]
    order = np.lexsort((value, -length, pixel))
    pixel, value, length = pixel[order], value[order], length[order]
    begins = np.flatnonzero(np.r_[True, pixel[1:] != pixel[:-1]])
    rank = np.arange(pixel.size) - np.repeat(begins, np.diff(np.append(begins, pixel.size)))
    keep = rank < k
    values[rows[pixel[keep]], cols[pixel[keep]], rank[keep]] = value[keep]
    counts[rows[pixel[keep]], cols[pixel[keep]], rank[keep]] = length[keep]
    return values, counts


class Matte:
    """The matte pass's target (an R32UI texture and a depth buffer of ``tile`` squared, at most `TILE` and the
    context's largest target, made on first use and kept among the renderer's render targets, ``targets``)."""

    def __init__(self, mgl, targets, tile=TILE):
        self._mgl = mgl
        self._targets = targets
        self.tile = int(tile)

    def draw(self, scene, size, samples, k, programs, vertex_array):
        """Draw the matte of ``scene``.

        Parameters
        ----------
        scene : glphong.Scene
        size : (int, int)
            The output ``(W, H)`` [px].
        samples : int
            Samples per pixel along each axis (s).
        k : int
            Entries kept per pixel.
        programs : glphong.gpu.programs.ProgramCache
        vertex_array : callable
            ``vertex_array(mesh, program)``: the mesh's vertex array for a program (the renderer's buffers).

        Returns
        -------
        ids : (H, W, k) uint32 ndarray
            ``instance_id`` by fraction descending (ties by id ascending), 0 padding.
        fractions : (H, W, k) float32 ndarray
            Share of the pixel's samples, descending, 0 padding.
        """
        width, height = size
        drawn = matte_objects(scene)
        table = np.zeros(len(scene.objects) + 1, np.uint32)
        table[1:] = [obj.instance_id for obj in scene.objects]
        program = programs.get(matte_key())
        camera = scene.camera
        view_projection = camera.projection_matrix(width / height) @ camera.view_matrix()
        fbo = self._target()
        per_tile = max(1, self.tile // samples)
        ids = np.zeros((height, width, k), np.uint32)
        counts = np.zeros((height, width, k), np.int64)
        mgl = self._mgl
        mgl.enable(moderngl.DEPTH_TEST)
        mgl.disable(moderngl.CULL_FACE | moderngl.BLEND)
        fbo.use()
        for row in range(0, height, per_tile):
            for column in range(0, width, per_tile):
                w, h = min(per_tile, width - column), min(per_tile, height - row)
                viewport = (0, 0, w * samples, h * samples)
                fbo.viewport = viewport
                fbo.clear(0, 0, 0, 0, depth=1.0, viewport=viewport)
                matrix = tile_matrix(size, (column, row, w, h)) @ view_projection
                for index in drawn:
                    obj = scene.objects[index]
                    program.bind({"u_model": obj.pose, "u_view_projection": matrix, "u_object_id": float(index)})
                    vertex_array(obj.mesh, program).render(moderngl.TRIANGLES)
                data = np.empty((h * samples, w * samples), np.uint32)
                fbo.read_into(data, viewport=viewport, components=1, dtype="u4")
                values, n = count_samples(data[::-1], samples, k)
                ids[row:row + h, column:column + w] = table[values]
                counts[row:row + h, column:column + w] = n
        return ids, (counts / float(samples * samples)).astype(np.float32)

    def silhouettes(self, scene, size, indices, programs, vertex_array, culled):
        """Where each object ``indices`` of ``scene`` covers the image when drawn alone (its whole silhouette).

        Each object is drawn by itself into the cleared target, one sample per pixel at the pixel centre, no depth
        test, by the matte program: its vertex stage computes the same ``invariant gl_Position`` from the same
        uniforms as every program's, and the cull state is the one the renderer draws the object with, so the
        pixels are those a render of the object alone covers (its alpha mask apart: `matte_objects` refuses a
        textured one, and a constant alpha below its cutoff hides the object).

        Parameters
        ----------
        scene : glphong.Scene
        size : (int, int)
            ``(W, H)`` [px], at most the tile.
        indices : sequence of int
        programs, vertex_array
            As `draw`.
        culled : callable
            ``culled(obj)``: ``(cull, mirrored)``, whether the renderer culls the object's back faces and whether
            its pose mirrors (clockwise front faces).

        Returns
        -------
        list of (H, W) bool ndarray
        """
        width, height = size
        if max(size) > self.tile:
            raise ValueError(f"silhouettes are drawn at most {self.tile} px a side (got {width}x{height})")
        drawn = set(matte_objects(scene))
        program = programs.get(matte_key())
        camera = scene.camera
        view_projection = camera.projection_matrix(width / height) @ camera.view_matrix()
        fbo = self._target()
        mgl = self._mgl
        mgl.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
        fbo.use()
        viewport = (0, 0, width, height)
        fbo.viewport = viewport
        out = []
        try:
            for index in indices:
                fbo.clear(0, 0, 0, 0, viewport=viewport)
                obj = scene.objects[index]
                if index in drawn:
                    cull, mirrored = culled(obj)
                    (mgl.enable if cull else mgl.disable)(moderngl.CULL_FACE)
                    mgl.front_face = "cw" if mirrored else "ccw"
                    program.bind({"u_model": obj.pose, "u_view_projection": view_projection,
                                  "u_object_id": float(index)})
                    vertex_array(obj.mesh, program).render(moderngl.TRIANGLES)
                data = np.empty((height, width), np.uint32)
                fbo.read_into(data, viewport=viewport, components=1, dtype="u4")
                out.append(data[::-1] != 0)
        finally:
            mgl.front_face = "ccw"
            mgl.disable(moderngl.CULL_FACE)
        return out

    def _target(self):
        fbo = self._targets.get("matte")
        if fbo is None:
            size = (self.tile, self.tile)
            texture = self._mgl.texture(size, 1, dtype="u4")
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            fbo = self._targets["matte"] = self._mgl.framebuffer([texture], self._mgl.depth_renderbuffer(size))
        return fbo
