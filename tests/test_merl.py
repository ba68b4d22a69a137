"""The MERL binary format (`glphong.merl`): the reader's errors, the write/read round trip, the indexing
against an independent transcription of the reference code's coordinate change, and tables made from
analytic materials (nothing is downloaded).

- A truncated file, one with a foreign header, one longer than a table and one with NaN are refused with
  a `MerlFormatError` naming the problem; negative entries (unmeasured cells) read as NaN.
- Writing and reading a table returns it to 1e-15 relative (the per-channel scale is applied and undone).
- `half_diff` agrees with the reference code's two rotations (by ``-phi_h`` about n, then ``-theta_h`` about
  the binormal), written here from its description, to 1e-12 rad on 20000 random pairs.
- Every bin's representative pair (`bin_directions`) indexes back to its own bin: 0 of 1,458,000 differ.
- `tabulate` then `lookup`: exact (1e-12) at the bin directions, and for Lambert everywhere; for a normalised
  Blinn-Phong lobe (q = 30) at 20000 random pairs the nearest-bin value is within the bin's variation
  (median relative error measured 4.8e-2, 95th percentile 0.16; bound on the median 0.1), as the reference
  reader is; a pair near grazing may fall in a bin whose representative pair is below the horizon
  (NaN, unmeasured), as in measured tables (under 3% of random pairs, all within 0.2 of grazing).
"""
import numpy as np
import pytest

import glphong
from glphong import merl
from glphong.testing import evaluate


def _random_pairs(count, seed=1):
    rng = np.random.default_rng(seed)
    a, b = rng.normal(size=(2, count, 3))
    a[:, 2], b[:, 2] = np.abs(a[:, 2]) + 1e-3, np.abs(b[:, 2]) + 1e-3
    return a / np.linalg.norm(a, axis=1, keepdims=True), b / np.linalg.norm(b, axis=1, keepdims=True)


def _rotate(v, axis, angle):
    """Rodrigues' rotation of rows ``v`` about unit ``axis`` rows by ``angle``."""
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    return v * c + np.cross(axis, v) * s + axis * np.sum(axis * v, axis=-1, keepdims=True) * (1 - c)


def reference_half_diff(wi, wo):
    """The MERL reference code's std_coords_to_half_diff_coords, transcribed (normal +z, binormal +y)."""
    h = (wi + wo) / np.linalg.norm(wi + wo, axis=1, keepdims=True)
    theta_h = np.arccos(np.clip(h[:, 2], -1, 1))
    phi_h = np.arctan2(h[:, 1], h[:, 0])
    normal = np.broadcast_to([0.0, 0.0, 1.0], wi.shape)
    binormal = np.broadcast_to([0.0, 1.0, 0.0], wi.shape)
    tmp = _rotate(wi, normal, -phi_h)
    diff = _rotate(tmp, binormal, -theta_h)
    return theta_h, np.arccos(np.clip(diff[:, 2], -1, 1)), np.arctan2(diff[:, 1], diff[:, 0])


def test_half_diff_is_the_reference_code_change_of_coordinates():
    wi, wo = _random_pairs(20000)
    ours = merl.half_diff(wi, wo)
    theirs = reference_half_diff(wi, wo)
    for a, b in zip(ours, theirs):
        np.testing.assert_allclose(a, b, atol=1e-12)


def test_every_bin_direction_indexes_its_own_bin():
    wi, wo = merl.bin_directions()
    found = merl.merl_indices(*merl.half_diff(wi, wo))
    expected = np.meshgrid(*(np.arange(s) for s in merl.SHAPE), indexing="ij")
    assert sum(int(np.sum(f != e)) for f, e in zip(found, expected)) == 0


def test_round_trip_and_unmeasured_cells(tmp_path):
    rng = np.random.default_rng(2)
    table = rng.uniform(0, 3, size=merl.SHAPE + (3,))
    table[0, 0, 0] = np.nan
    path = tmp_path / "t.binary"
    merl.write_merl(path, table)
    assert path.stat().st_size == 12 + 3 * 1458000 * 8
    back = merl.read_merl(path)
    assert np.isnan(back[0, 0, 0]).all()
    np.testing.assert_allclose(back[1:], table[1:], rtol=1e-15)
    raw = np.fromfile(path, dtype="<f8", offset=12)
    assert raw[0] == -1.0 and raw[1] == table[0, 0, 1, 0] * 1500.0  # planar, red first, C order


def test_bad_files_are_refused_with_what_is_wrong(tmp_path):
    good = tmp_path / "good.binary"
    merl.write_merl(good, np.zeros(merl.SHAPE + (3,)))
    data = good.read_bytes()
    cases = {"short.binary": (data[:8], "too short for the MERL header"),
             "truncated.binary": (data[:-8], "truncated"),
             "long.binary": (data + b"\0" * 8, "longer than a MERL table"),
             "foreign.binary": (np.array([64, 64, 128], "<i4").tobytes() + data[12:], r"header \(64, 64, 128\)")}
    for name, (content, message) in cases.items():
        (tmp_path / name).write_bytes(content)
        with pytest.raises(merl.MerlFormatError, match=message):
            merl.read_merl(tmp_path / name)
    nan = bytearray(data)
    nan[12:20] = np.array([np.nan], "<f8").tobytes()
    (tmp_path / "nan.binary").write_bytes(bytes(nan))
    with pytest.raises(merl.MerlFormatError, match="1 values are NaN or infinite"):
        merl.read_merl(tmp_path / "nan.binary")
    with pytest.raises(ValueError, match=r"table must have shape \(90, 90, 180, 3\)"):
        merl.write_merl(tmp_path / "x.binary", np.zeros((90, 90, 90, 3)))


def test_tabulated_lambert_looks_up_exactly():
    table = merl.tabulate(glphong.Lambert((0.1, 0.2, 0.3)))
    wi, wo = _random_pairs(20000)
    found = merl.lookup(table, wi, wo)
    # a pair above the horizon may fall in a bin whose representative pair is below it (unmeasured, NaN),
    # as in measured tables: near grazing only
    measured = ~np.isnan(found[:, 0])
    assert measured.mean() > 0.97 and np.all(np.minimum(wi[~measured, 2], wo[~measured, 2]) < 0.2)
    np.testing.assert_allclose(found[measured], np.float32([0.1, 0.2, 0.3]) * np.ones((measured.sum(), 3)),
                               rtol=1e-7)  # kd rounded to float32, as the GPU is given it


def test_tabulated_lobe_round_trip():
    material = glphong.NormalizedBlinnPhong(0.0, 0.8, 30.0)
    table = merl.tabulate(material)
    wi, wo = merl.bin_directions()
    pick = (slice(None, None, 7), slice(None, 80, 9), slice(None, None, 11))
    wi, wo = wi[pick].reshape(-1, 3), wo[pick].reshape(-1, 3)
    np.testing.assert_allclose(merl.lookup(table, wi, wo), table[pick].reshape(-1, 3), rtol=0, atol=0)
    wi, wo = _random_pairs(20000, seed=3)
    twin = evaluate(material, wi, wo, twin=True) / wi[:, 2:3]
    found = merl.lookup(table, wi, wo)
    strong = (twin[:, 1] > 0.1 * twin[:, 1].max()) & ~np.isnan(found[:, 1])
    rel = np.abs(found[strong, 1] - twin[strong, 1]) / twin[strong, 1]
    assert strong.sum() > 200 and np.median(rel) < 0.1
