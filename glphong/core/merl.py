"""The MERL measured-BRDF binary format (Matusik et al. 2003; docs/design.md section 9): read, write, index, look up.

A file holds a header of three int32 ``(90, 90, 180)`` (the bins of ``theta_h``, ``theta_d``, ``phi_d``),
then 3 x 1,458,000 float64, channels planar (every red value, then green, then blue), each indexed
``[theta_h][theta_d][phi_d]`` in C order.  Values are scaled to ``f_r`` [1/sr] by 1/1500 (red),
1.15/1500 (green) and 1.66/1500 (blue); negative entries mark cells that were not measured.

Indices (the reference reader's, nearest lower bin, no interpolation):

- ``theta_h = acos(n.h)``: index ``floor(sqrt(theta_h / (pi/2)) * 90)`` (finer bins near the peak);
- ``theta_d = acos(h.l)``: index ``floor(theta_d / (pi/2) * 90)``;
- ``phi_d = atan2(l.(h x u), l.u)`` with ``u = -normalize(n - (n.h) h)`` (the reference code's two
  rotations; where ``h = n`` the reference's ``phi_h = 0`` gives ``u`` = the tangent ``t``), folded into
  [0, pi) by reciprocity (``+ pi`` when negative): index ``floor(phi_d / pi * 180)``;
- every index clamped to its range.

`glphong.analysis.tabulate.tabulate` fills a table from any analytic material at each bin's representative directions (the
lower edge of the ``theta_h`` bin, as the reference reader maps it, and the centres of the ``theta_d`` and
``phi_d`` bins), so `lookup` of the table reproduces the material exactly at those directions.
"""
import struct
from pathlib import Path

import numpy as np

from glphong.core.filesafety import Limits, SceneFileError, read_bytes

__all__ = ["SHAPE", "SCALE", "MerlFormatError", "read_merl", "write_merl", "half_diff", "merl_indices", "lookup",
           "bin_directions"]

#: the table's shape (theta_h, theta_d, phi_d)
SHAPE = (90, 90, 180)
#: f_r [1/sr] per stored unit, per channel
SCALE = np.array([1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0])
_HEADER = struct.Struct("<3i")
_CELLS = SHAPE[0] * SHAPE[1] * SHAPE[2]
_SIZE = _HEADER.size + 3 * _CELLS * 8


class MerlFormatError(ValueError):
    """A file is not a MERL BRDF table (wrong size, header or contents)."""


def read_merl(path):
    """The table of a MERL ``.binary`` file as ``f_r`` [1/sr].

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    (90, 90, 180, 3) float64 ndarray
        ``f_r`` per bin and channel, the stored values times `SCALE`; NaN where the file marks a cell
        as not measured (a negative entry).

    Raises
    ------
    MerlFormatError
        Naming what is wrong: not a regular file (a FIFO, a device), a file shorter or longer than
        34,992,012 bytes (truncated, or not a MERL table), a header other than (90, 90, 180), non-finite
        values.
    """
    path = Path(path)
    try:  # a regular file of at most a table's size: a FIFO or /dev/zero is refused before any read
        raw = read_bytes(path, Limits(file_bytes=_SIZE))
    except SceneFileError as exc:
        longer = "longer than a MERL table: " if "more than the limit" in exc.message else ""
        raise MerlFormatError(f"{exc}; {longer}a MERL table has {_SIZE} bytes (12-byte header and 3 x {_CELLS} "
                              "float64)") from None
    size = len(raw)
    if size < _HEADER.size:
        raise MerlFormatError(f"{path}: {size} bytes, too short for the MERL header (three int32 90, 90, 180)")
    dims = _HEADER.unpack_from(raw)
    if dims != SHAPE:
        raise MerlFormatError(f"{path}: header {dims}, expected {SHAPE} (theta_h, theta_d, phi_d bins): not a MERL "
                              "BRDF table, or one of another resolution")
    if size != _SIZE:
        raise MerlFormatError(f"{path}: {size} bytes, a MERL table has {_SIZE} (12-byte header and 3 x {_CELLS} "
                              "float64): truncated")
    data = np.frombuffer(raw, dtype="<f8", offset=_HEADER.size)
    if not np.all(np.isfinite(data)):
        raise MerlFormatError(f"{path}: {int(np.sum(~np.isfinite(data)))} values are NaN or infinite")
    table = data.reshape(3, *SHAPE).transpose(1, 2, 3, 0) * SCALE
    return np.where(table < 0, np.nan, table)


def write_merl(path, table):
    """Write ``table`` (90, 90, 180, 3) of ``f_r`` [1/sr] as a MERL ``.binary`` file (NaN: not measured, -1)."""
    table = np.asarray(table, dtype=np.float64)
    if table.shape != SHAPE + (3,):
        raise ValueError(f"table must have shape {SHAPE + (3,)} (got {table.shape})")
    stored = np.where(np.isnan(table), -1.0, table / SCALE)
    with Path(path).open("wb") as f:
        f.write(_HEADER.pack(*SHAPE))
        f.write(np.ascontiguousarray(stored.transpose(3, 0, 1, 2), dtype="<f8").tobytes())


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def half_diff(wi, wo, n=(0.0, 0.0, 1.0), t=(1.0, 0.0, 0.0)):
    """``(theta_h, theta_d, phi_d)`` [rad] of direction pairs, ``phi_d`` in (-pi, pi] (not folded).

    Parameters
    ----------
    wi, wo : (..., 3) array_like
        Unit directions toward the light and the viewer.
    n, t : (3,) array_like
        Normal and tangent (the fallback of ``u`` where ``h = n``).
    """
    wi, wo = np.asarray(wi, dtype=np.float64), np.asarray(wo, dtype=np.float64)
    n, t = np.asarray(n, dtype=np.float64), np.asarray(t, dtype=np.float64)
    h = _unit(wi + wo)
    n_dot_h = np.clip(np.sum(h * n, axis=-1), -1.0, 1.0)
    theta_h = np.arccos(n_dot_h)
    theta_d = np.arccos(np.clip(np.sum(h * wi, axis=-1), -1.0, 1.0))
    away = -(n - n_dot_h[..., None] * h)
    length = np.linalg.norm(away, axis=-1, keepdims=True)
    u = np.where(length > 1e-12, away / np.maximum(length, 1e-300), t)
    phi_d = np.arctan2(np.sum(wi * np.cross(h, u), axis=-1), np.sum(wi * u, axis=-1))
    return theta_h, theta_d, phi_d


def merl_indices(theta_h, theta_d, phi_d):
    """The reference reader's bin indices (nearest lower bin, clamped), each an int ndarray."""
    phi_d = np.where(phi_d < 0, phi_d + np.pi, phi_d)
    i = np.floor(np.sqrt(np.maximum(theta_h, 0) / (np.pi / 2)) * SHAPE[0]).astype(int)
    j = np.floor(theta_d / (np.pi / 2) * SHAPE[1]).astype(int)
    k = np.floor(phi_d / np.pi * SHAPE[2]).astype(int)
    return np.clip(i, 0, SHAPE[0] - 1), np.clip(j, 0, SHAPE[1] - 1), np.clip(k, 0, SHAPE[2] - 1)


def lookup(table, wi, wo, n=(0.0, 0.0, 1.0), t=(1.0, 0.0, 0.0)):
    """``f_r`` (..., 3) [1/sr] of ``table`` at direction pairs, by the reference reader's nearest lower bin."""
    i, j, k = merl_indices(*half_diff(wi, wo, n, t))
    return np.asarray(table)[i, j, k]


def bin_directions():
    """``(wi, wo)``, each (90, 90, 180, 3): a direction pair in every bin (normal +z, tangent +x).

    ``theta_h`` at its bin's lower edge ``(i / 90)^2 pi/2`` (exactly where the reference reader's index
    is ``i``), nudged up by 1e-9 rad past the first (its pairs have ``h = n`` exactly, so an isotropic
    material's row 0 does not depend on ``phi_d``); ``theta_d`` and ``phi_d`` at their bins' centres;
    ``phi_h = 0``.
    """
    th = (np.arange(SHAPE[0]) / SHAPE[0]) ** 2 * (np.pi / 2) + np.where(np.arange(SHAPE[0]) > 0, 1e-9, 0.0)
    td = (np.arange(SHAPE[1]) + 0.5) / SHAPE[1] * (np.pi / 2)
    pd = (np.arange(SHAPE[2]) + 0.5) / SHAPE[2] * np.pi
    th, td, pd = np.meshgrid(th, td, pd, indexing="ij")
    # the "difference" vector in the frame of h, then rotated by theta_h about y (phi_h = 0)
    d = np.stack([np.sin(td) * np.cos(pd), np.sin(td) * np.sin(pd), np.cos(td)], axis=-1)
    c, s = np.cos(th)[..., None], np.sin(th)[..., None]
    def rot(v):  # rotation by theta_h about +y: takes +z to h
        return np.stack([c[..., 0] * v[..., 0] + s[..., 0] * v[..., 2], v[..., 1],
                         -s[..., 0] * v[..., 0] + c[..., 0] * v[..., 2]], axis=-1)
    h = rot(np.broadcast_to([0.0, 0.0, 1.0], d.shape))
    wi = rot(d)
    wo = 2 * np.sum(wi * h, axis=-1, keepdims=True) * h - wi
    return wi, wo
