"""Meshopt-compressed glTF files (``EXT_meshopt_compression``, ``KHR_meshopt_compression``;
`glphong.formats.gltf_compressed`), made here with the ``meshopt`` package's encoder.

- Exact modes: positions (ATTRIBUTES) and indices (INDICES) decode to the very arrays encoded; TRIANGLES to the
  same triangles with the same winding (the codec may start a triangle at another corner).
- Filters: OCTAHEDRAL normals and EXPONENTIAL uvs decode to what an independent float64 transcription of the
  extension's Appendix B formulas gives for the stored rows (octahedral within the 1 ULP the extension allows,
  exponential exactly), and the normals lie within the 8-bit octahedral quantization of the originals.
- Hostile streams: truncated, of another mode, a declared size the view does not hold, a filter on indices, a
  count beyond ``Limits.decoded_bytes`` (refused before the decoder runs), 60 randomly damaged streams: each is a
  `SceneFileError` naming the view, never another exception.  Without the package the error names the extra.
- ``save_gltf`` writes a loaded compressed file uncompressed, and it reads back equal.
"""
import json
import sys
import warnings

import numpy as np
import pytest
import trimesh

import glphong
from glphong.filesafety import Limits, SceneFileError

meshopt = pytest.importorskip("meshopt", reason="the [meshopt] extra (meshopt, Python >= 3.11) is not installed")


def _encode(mode, filter_="NONE", index_bytes=None):
    """A `GltfBuilder` compressor: rows (count, stride) uint8 -> (mode, filter, meshopt stream)."""

    def compress(rows):
        if index_bytes is not None:
            data = rows.reshape(-1).view("<u2" if index_bytes == 2 else "<u4").astype(np.uint32)
        else:
            data = rows
        return mode, filter_, meshopt.encode_gltf_buffer(data, mode)

    return compress


def _sphere():
    sphere = trimesh.creation.icosphere(1)
    positions = np.asarray(sphere.vertices, np.float32)
    normals = np.asarray(sphere.vertex_normals, np.float64)
    uvs = np.stack([np.arctan2(positions[:, 1], positions[:, 0]), positions[:, 2]], axis=1).astype(np.float32)
    return positions, normals, uvs, np.asarray(sphere.faces, np.uint16).reshape(-1)


def _octahedral_decode(rows):
    """Appendix B, filter 1, transcribed in float64: (n, 4) int8 rows -> (n, 3) decoded int8 values."""
    one = rows[:, 2].astype(np.float64)
    x, y = rows[:, 0] / one, rows[:, 1] / one
    z = 1.0 - np.abs(x) - np.abs(y)
    t = np.minimum(z, 0.0)
    x, y = x - np.copysign(t, x), y - np.copysign(t, y)
    length = np.sqrt(x * x + y * y + z * z)
    return np.round(np.stack([x, y, z], axis=1) / length[:, None] * 127.0)


def _exponential_decode(words):
    """Appendix B, filter 3: int32 words -> 2^e m (e: the top 8 bits, m: the low 24, both signed), in float64."""
    words = words.astype(np.int64)
    e = words >> 24
    m = ((words & 0xFFFFFF) ^ 0x800000) - 0x800000
    return np.ldexp(m.astype(np.float64), e)


def _compressed_sphere(builder, extension="EXT_meshopt_compression", index_mode="TRIANGLES"):
    positions, normals, uvs, indices = _sphere()
    oct_rows = meshopt.encode_filter_oct(np.c_[normals, np.zeros(len(normals))].astype(np.float32), 4, 8).view(np.int8)
    exp_rows = meshopt.encode_filter_exp(uvs, 20, "Separate")
    builder.attribute("POSITION", positions, compress=_encode("ATTRIBUTES"), extension=extension)
    builder.attribute("NORMAL", oct_rows[:, :3], normalized=True, stride=4,
                      compress=_encode("ATTRIBUTES", "OCTAHEDRAL"), extension=extension)
    builder.attribute("TEXCOORD_0", exp_rows.view(np.float32).reshape(-1, 2),
                      compress=_encode("ATTRIBUTES", "EXPONENTIAL"), extension=extension)
    builder.indices(indices, compress=_encode(index_mode, index_bytes=2), extension=extension)
    builder.document["extensionsUsed"] = builder.document["extensionsRequired"] = [extension]
    return positions, normals, oct_rows, exp_rows, indices


def _rotated(triangles):
    """Each triangle rotated to start at its smallest index (the triangle codec keeps triangles and their winding,
    not which corner comes first)."""
    first = np.argmin(triangles, axis=1)[:, None]
    return np.take_along_axis(triangles.astype(np.int64), (first + np.arange(3)) % 3, axis=1)


def _load(path, **keywords):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # no lights: the default light's warning
        return glphong.load_scene(path, **keywords)


@pytest.mark.parametrize("extension, index_mode", [("EXT_meshopt_compression", "TRIANGLES"),
                                                   ("KHR_meshopt_compression", "INDICES")])
def test_meshopt_file_decodes_to_the_encoded_arrays(tmp_path, builder, extension, index_mode):
    positions, normals, oct_rows, exp_rows, indices = _compressed_sphere(builder, extension, index_mode)
    mesh = _load(builder.write(tmp_path)).objects[0].mesh
    assert np.array_equal(mesh.positions, positions.astype(np.float64))
    assert np.array_equal(_rotated(mesh.indices.reshape(-1, 3)), _rotated(indices.reshape(-1, 3)))
    expected = _octahedral_decode(oct_rows)
    assert np.abs(mesh.normals * 127.0 - expected).max() <= 1.0 + 1e-9  # the extension's 1 ULP
    assert np.abs(mesh.normals - normals).max() < 0.03  # 8-bit octahedral, then 8-bit components
    words = exp_rows.view(np.int32).reshape(-1, 2)
    assert np.array_equal(mesh.uvs[:, 0], _exponential_decode(words[:, 0]))
    assert np.array_equal(mesh.uvs[:, 1], 1.0 - _exponential_decode(words[:, 1]))


def test_a_planted_filter_error_is_caught(builder, tmp_path):
    """The transcription above is not the decoder's: with the wrong component order it disagrees."""
    _, _, oct_rows, _, _ = _compressed_sphere(builder)
    mesh = _load(builder.write(tmp_path)).objects[0].mesh
    assert np.abs(mesh.normals * 127.0 - _octahedral_decode(oct_rows[:, [1, 0, 2, 3]])).max() > 1.0


def test_save_gltf_writes_a_compressed_file_uncompressed(tmp_path, builder):
    positions, *_ = _compressed_sphere(builder)
    scene = _load(builder.write(tmp_path))
    out = tmp_path / "plain.gltf"
    glphong.save_gltf(scene, out)
    assert "meshopt" not in out.read_text()
    assert np.array_equal(_load(out).objects[0].mesh.positions, scene.objects[0].mesh.positions)


def _views(document):
    return [v["extensions"]["EXT_meshopt_compression"] for v in document["bufferViews"] if "extensions" in v]


@pytest.mark.parametrize("change, pattern", [
    (lambda d: _views(d)[0].update(byteLength=_views(d)[0]["byteLength"] - 9), r"bufferViews\[0\]\.extensions\."
     r"EXT_meshopt_compression: a ATTRIBUTES stream of \d+ bytes that does not decode"),
    (lambda d: _views(d)[3].update(mode="INDICES"), r"bufferViews\[3\].*INDICES stream .* does not decode"),
    (lambda d: _views(d)[0].update(count=_views(d)[0]["count"] + 1), "they must be equal"),
    (lambda d: _views(d)[3].update(filter="OCTAHEDRAL"), "applies to mode ATTRIBUTES only"),
    (lambda d: _views(d)[0].update(filter="QUATERNION"), "QUATERNION needs a byteStride of 8"),
    (lambda d: _views(d)[0].update(filter="COLOR"), r"filter: expected one of NONE, OCTAHEDRAL, QUATERNION"),
    (lambda d: _views(d)[0].update(mode="TRIANGLES"), "mode TRIANGLES with byteStride 12"),
    (lambda d: _views(d)[0].update(byteOffset=10 ** 9), "lie outside buffer 0"),
    (lambda d: _views(d)[0].pop("count"), r"count: expected an integer"),
])
def test_hostile_meshopt_views_are_clear_errors(tmp_path, builder, change, pattern):
    _compressed_sphere(builder)
    path = builder.write(tmp_path)
    document = json.loads(path.read_text())
    change(document)
    path.write_text(json.dumps(document))
    with pytest.raises(SceneFileError, match=pattern):
        _load(path)


def test_a_declared_size_beyond_the_limit_is_refused_before_decoding(tmp_path, builder, monkeypatch):
    _compressed_sphere(builder)
    path = builder.write(tmp_path)
    monkeypatch.setattr(meshopt, "decode_gltf_buffer", lambda *a, **k: pytest.fail("the decoder ran"))
    with pytest.raises(SceneFileError, match=r"bufferViews\[0\].*Limits\.decoded_bytes"):
        _load(path, limits=Limits(decoded_bytes=1200))  # the accessor's 1008 bytes pass


def test_damaged_streams_raise_nothing_but_scene_file_errors(tmp_path, builder):
    _compressed_sphere(builder)
    path = builder.write(tmp_path)
    blob = (tmp_path / "scene.bin").read_bytes()
    spans = [(v["byteOffset"], v["byteLength"]) for v in _views(json.loads(path.read_text()))]
    rng = np.random.default_rng(7)
    outcomes = set()
    for trial in range(60):
        damaged = bytearray(blob)
        start, length = spans[trial % len(spans)]
        for position in rng.integers(start, start + length, size=1 + trial % 4):
            damaged[position] = int(rng.integers(0, 256))
        (tmp_path / "scene.bin").write_bytes(bytes(damaged))
        try:  # a camera and no light: damaged positions may be finite but huge, beyond a default view's light
            _load(path, lights=[], camera=glphong.PerspectiveCamera(0.8))
            outcomes.add("loaded")
        except SceneFileError as error:
            assert "bufferViews[" in str(error) or "accessors[" in str(error) or "primitives[" in str(error), error
            outcomes.add("refused")
    assert outcomes == {"loaded", "refused"}  # both happen: damage inside deltas decodes, damage to a header not


def test_without_the_package_the_error_names_the_extra(tmp_path, builder, monkeypatch):
    _compressed_sphere(builder)
    path = builder.write(tmp_path)
    monkeypatch.setitem(sys.modules, "meshopt", None)
    with pytest.raises(SceneFileError, match=r"extensionsRequired: needs EXT_meshopt_compression.*glphong\[meshopt\]"):
        _load(path)
    document = json.loads(path.read_text())
    document.pop("extensionsRequired")
    path.write_text(json.dumps(document))
    with pytest.raises(SceneFileError, match=r"bufferViews\[0\]\.extensions.*pip install 'glphong\[meshopt\]'"):
        _load(path)


def test_without_the_package_a_parent_view_with_plain_data_is_read(tmp_path, builder, monkeypatch):
    """The extension's fallback: where the parent buffer is not marked ``fallback`` it holds the plain data, which a
    reader without the decoder reads (and a reader with it decodes to the same arrays)."""
    positions, _, _, _, indices = _compressed_sphere(builder)
    builder.document.pop("extensionsRequired")
    for view in builder.document["bufferViews"]:  # the plain rows, over the placeholder's data
        stream = view["extensions"]["EXT_meshopt_compression"]
        rows = meshopt.decode_gltf_buffer(bytes(builder.blob[stream["byteOffset"]:][:stream["byteLength"]]),
                                          stream["count"], stream["byteStride"], stream["mode"], stream["filter"])
        view.update(buffer=0, byteOffset=builder._append(np.ascontiguousarray(rows).tobytes()))
    del builder.document["buffers"][builder.placeholder]["extensions"]
    builder.document["buffers"].pop(builder.placeholder)
    path = builder.write(tmp_path)
    decoded = _load(path).objects[0].mesh
    monkeypatch.setitem(sys.modules, "meshopt", None)
    plain = _load(path).objects[0].mesh
    np.testing.assert_array_equal(plain.positions, decoded.positions)
    np.testing.assert_array_equal(plain.positions, positions)
    np.testing.assert_array_equal(plain.indices, decoded.indices)


def test_a_compressed_sphere_renders_and_verifies(tmp_path, builder, glphong_backend, glphong_make_renderer):
    _compressed_sphere(builder)
    scene = _load(builder.write(tmp_path))  # the default view: a camera and a point light
    assert glphong.verify(scene, glphong_make_renderer(40, 32, glphong_backend)).passed
