"""`glphong.datasets.exr` and `glphong.datasets.npz`: every pass of a real render written and read back bit-exact.

The render (64x48, both backends) holds every pass but 'uv': a sphere and a box that move between three frames, and
a next scene whose camera sits inside the sphere so that the flow of the points behind it is NaN.  Each round trip
must give the same bits (NaN payloads and signed zeros included), uint32 ids, and the EXR the documented channel
names and pixel types when OpenEXR reads it itself; truncated, foreign and hostile files give a SceneFileError.
"""
import io
import sys
import zipfile
from dataclasses import replace

import numpy as np
import OpenEXR
import pytest
import trimesh

import glphong
from glphong import primitives
from glphong.core.filesafety import Limits, SceneFileError
from glphong.datasets.exr import EXR_CHANNELS, load_exr, save_exr
from glphong.datasets.npz import load_npz, pass_arrays, save_npz
from glphong.gpu.passes import PASSES
from glphong.scene.geometry import MeshData

W, H = 64, 48
SPHERE = primitives.sphere(3, 0.5)
BOX = MeshData.from_trimesh(trimesh.creation.box((0.8, 0.6, 0.6)), smooth=False)
NAMES = ("radiance",) + tuple(n for n in PASSES[1:] if n != "uv")
ARRAYS = pass_arrays(NAMES)  # the 'matte' pass is two arrays, matte_ids and matte_fractions
#: the channels the module docstring promises, and their pixel types
DOCUMENTED = {
    "R": "FLOAT", "G": "FLOAT", "B": "FLOAT", "A": "FLOAT", "Z": "FLOAT", "distance.Z": "FLOAT",
    "normal.X": "FLOAT", "normal.Y": "FLOAT", "normal.Z": "FLOAT",
    "normal_camera.X": "FLOAT", "normal_camera.Y": "FLOAT", "normal_camera.Z": "FLOAT",
    "instance.id": "UINT", "category.id": "UINT",
    "object_coordinates.X": "FLOAT", "object_coordinates.Y": "FLOAT", "object_coordinates.Z": "FLOAT",
    "nocs.X": "FLOAT", "nocs.Y": "FLOAT", "nocs.Z": "FLOAT",
    "flow.X": "FLOAT", "flow.Y": "FLOAT", "backward_flow.X": "FLOAT", "backward_flow.Y": "FLOAT",
    **{f"matte.id{j}": "UINT" for j in range(4)}, **{f"matte.fraction{j}": "FLOAT" for j in range(4)},
}


def _pose(angle, shift):  # a turn of ``angle`` [rad] about +y, then ``shift`` [m]
    pose = trimesh.transformations.rotation_matrix(angle, (0.0, 1.0, 0.0))
    pose[:3, 3] = shift
    return pose


def _scene(angle, eye=(0.3, 0.25, 3.0), target=(0.0, 0.0, 0.0)):
    pose = glphong.PerspectiveCamera.look_at(eye, target).pose
    camera = glphong.IntrinsicsCamera(60.0, 58.0, 31.5, 23.5, W, H, pose=pose)
    scene = glphong.Scene(camera, [glphong.PointLight((2.0, 2.0, 3.0), 50.0)])
    scene.add(SPHERE, glphong.Phong(0.2, 0.4, 20.0), pose=_pose(angle, (0.3 * angle, 0.0, 0.5)),
              instance_id=7, category=3)
    scene.add(BOX, glphong.Lambert(0.5), pose=_pose(-angle, (-0.6, 0.2, -0.3)), instance_id=4_000_000_000,
              category=5)
    return scene


@pytest.fixture
def frame(glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(W, H, glphong_backend)
    following = _scene(0.1, eye=(0.0, 0.0, 0.8), target=(0.0, 0.0, -1.0))  # inside the sphere: NaN behind it
    frame = renderer.render(_scene(0.0), passes=NAMES, next_scene=following, previous_scene=_scene(-0.1))
    assert frame.passes == NAMES
    flow = frame.flow[frame.mask]
    assert np.isnan(flow).any() and np.isfinite(flow).any()  # a real NaN flow, and real values
    assert frame.instance.max() == 4_000_000_000  # beyond float32's exact integers
    return frame


def _same_bits(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a.view(np.uint32), b.view(np.uint32))


def _check_round_trip(frame, loaded):
    assert list(loaded) == list(ARRAYS) + ["coverage"]
    assert ARRAYS[-2:] == ("matte_ids", "matte_fractions") and loaded["matte_ids"].shape == (H, W, 4)
    for name in ARRAYS:
        assert _same_bits(loaded[name], getattr(frame, name)), name
    assert _same_bits(loaded["coverage"], frame.coverage)
    assert loaded["instance"].dtype == loaded["category"].dtype == np.uint32
    assert np.array_equal(loaded["coverage"] > 0, frame.mask)


def test_npz_round_trip_is_bit_exact(tmp_path, frame):
    path = tmp_path / "frame.npz"
    assert save_npz(path, frame) == path
    assert [p.name for p in tmp_path.iterdir()] == ["frame.npz"]  # no temporary file left
    _check_round_trip(frame, load_npz(path))
    with np.load(path, allow_pickle=False) as plain:  # NumPy reads it unaided
        assert sorted(plain.files) == sorted(list(ARRAYS) + ["coverage"])


def test_exr_round_trip_is_bit_exact_with_documented_channels(tmp_path, frame):
    path = tmp_path / "frame.exr"
    assert save_exr(path, frame) == path
    assert [p.name for p in tmp_path.iterdir()] == ["frame.exr"]
    _check_round_trip(frame, load_exr(path))
    with OpenEXR.File(str(path), separate_channels=True) as exr:
        channels = exr.channels()
        assert {name: channel.type().name for name, channel in channels.items()} == DOCUMENTED
        assert exr.header()["compression"] == OpenEXR.ZIP_COMPRESSION
        assert _same_bits(channels["Z"].pixels, frame.depth)
        assert _same_bits(channels["flow.Y"].pixels, np.ascontiguousarray(frame.flow[..., 1]))
        assert _same_bits(channels["instance.id"].pixels, frame.instance)
        assert _same_bits(channels["A"].pixels, frame.coverage)
    assert {c for group in EXR_CHANNELS.values() for c in group} == {
        c for c in DOCUMENTED if not c.startswith("matte.")} | {"uv.U", "uv.V"}


def test_uv_round_trip(tmp_path, glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.2, -0.3, 2.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, [glphong.PointLight((0.0, 0.0, 2.0), 10.0)])
    scene.add(primitives.plane(1.2), glphong.Lambert(0.5))
    frame = glphong_make_renderer(W, H, "egl").render(scene, passes=("uv",))
    assert frame.uv[frame.mask].max() > 0.5
    save_exr(tmp_path / "uv.exr", frame)
    save_npz(tmp_path / "uv.npz", frame)
    with OpenEXR.File(str(tmp_path / "uv.exr"), separate_channels=True) as exr:
        assert {n: c.type().name for n, c in exr.channels().items()} == {"uv.U": "FLOAT", "uv.V": "FLOAT", "A": "FLOAT"}
    for loaded in (load_exr(tmp_path / "uv.exr"), load_npz(tmp_path / "uv.npz")):
        assert list(loaded) == ["uv", "coverage"] and _same_bits(loaded["uv"], frame.uv)


def test_nan_payloads_and_signed_zeros_survive(tmp_path, glphong_make_renderer):
    frame = glphong_make_renderer(W, H, "egl").render(_scene(0.0), passes=("depth", "flow"), next_scene=_scene(0.1))
    flow = frame.flow.copy()
    flow[0, 0] = np.array([0x7FC00001, 0xFFC00000], np.uint32).view(np.float32)  # two NaNs of other bits
    flow[0, 1] = (-0.0, np.inf)
    planted = replace(frame, flow=flow)
    for save, load, name in ((save_npz, load_npz, "f.npz"), (save_exr, load_exr, "f.exr")):
        save(tmp_path / name, planted)
        loaded = load(tmp_path / name)
        assert list(loaded) == ["depth", "flow", "coverage"] and _same_bits(loaded["flow"], flow), name


def _small_frame(glphong_make_renderer, passes=("radiance", "depth", "instance")):
    return glphong_make_renderer(W, H, "egl").render(_scene(0.0), passes=passes)


def test_requested_pass_missing(tmp_path, glphong_make_renderer):
    frame = _small_frame(glphong_make_renderer)
    save_exr(tmp_path / "f.exr", frame)
    save_npz(tmp_path / "f.npz", frame)
    with pytest.raises(SceneFileError, match=r"f\.exr: no 'normal': expected the channels \['normal\.X'"):
        load_exr(tmp_path / "f.exr", passes=["depth", "normal"])
    with pytest.raises(SceneFileError, match=r"f\.npz: holds no \['flow'\]"):
        load_npz(tmp_path / "f.npz", passes=["flow"])
    for load, name in ((load_exr, "f.exr"), (load_npz, "f.npz")):
        with pytest.raises(ValueError, match="unknown name 'albedo'"):
            load(tmp_path / name, passes=["albedo"])


@pytest.mark.parametrize("cut", ["half", "end", "header"])
def test_truncated_files(tmp_path, glphong_make_renderer, cut):
    frame = _small_frame(glphong_make_renderer)
    for name, save, load in (("f.exr", save_exr, load_exr), ("f.npz", save_npz, load_npz)):
        save(tmp_path / name, frame)
        data = (tmp_path / name).read_bytes()
        keep = {"half": len(data) // 2, "end": len(data) - 10, "header": 40}[cut]
        (tmp_path / name).write_bytes(data[:keep])
        with pytest.raises(SceneFileError, match=rf"{name}: "):
            load(tmp_path / name)


def _flipped_fails(path, data, offset, load, frame):
    """Write ``data`` with the byte at ``offset`` flipped to ``path`` and ``load`` it: 1 where that is a clear error
    naming the file, 0 where the flip changed nothing read (the same bits back); never other data."""
    corrupt = data.copy()
    corrupt[offset] ^= 0x5A
    path.write_bytes(bytes(corrupt))
    try:
        loaded = load(path)
    except SceneFileError as exc:
        assert str(exc).startswith(f"{path}: "), exc
        return 1
    assert all(_same_bits(loaded[name], getattr(frame, name)) for name in frame.passes), offset
    return 0


def test_corrupt_npz_is_an_error_never_wrong_data(tmp_path, glphong_make_renderer):
    path = tmp_path / "f.npz"
    frame = _small_frame(glphong_make_renderer)
    save_npz(path, frame)
    data = bytearray(path.read_bytes())
    with zipfile.ZipFile(path) as archive:
        infos = archive.infolist()
    failed = 0
    for info in infos:  # bytes inside each member's deflate stream, which follows the local header
        name_length, extra_length = np.frombuffer(bytes(data[info.header_offset + 26:info.header_offset + 30]), "<u2")
        start = info.header_offset + 30 + int(name_length) + int(extra_length)
        for offset in np.linspace(start, start + info.compress_size - 1, 7).astype(int):
            failed += _flipped_fails(path, data, offset, load_npz, frame)
    assert failed >= 3 * len(infos)


def test_corrupt_exr_is_an_error_never_wrong_data(tmp_path, glphong_make_renderer):
    path = tmp_path / "f.exr"
    frame = _small_frame(glphong_make_renderer)
    save_exr(path, frame)
    data = bytearray(path.read_bytes())
    failed = 0
    for offset in np.linspace(len(data) // 2, len(data) - 1, 24).astype(int):  # in the compressed pixel chunks
        failed += _flipped_fails(path, data, offset, load_exr, frame)
    assert failed >= 20


def test_a_lying_exr_data_window_is_refused_before_decoding(tmp_path, glphong_make_renderer):
    path = tmp_path / "f.exr"
    save_exr(path, _small_frame(glphong_make_renderer))
    data = bytearray(path.read_bytes())
    at = data.index(b"dataWindow\0box2i\0") + len(b"dataWindow\0box2i\0") + 4  # after the attribute's size
    data[at + 8:at + 16] = np.array([1 << 20, 1 << 20], "<i4").tobytes()  # xMax, yMax
    path.write_bytes(bytes(data))
    with pytest.raises(SceneFileError, match=r"f\.exr: header: a data window of 1048577 x 1048577 pixels"):
        load_exr(path)


def test_foreign_files(tmp_path):
    text = tmp_path / "notes.exr"
    text.write_text("not an image " * 20)
    with pytest.raises(SceneFileError, match=r"notes\.exr: not an OpenEXR file"):
        load_exr(text)
    with pytest.raises(SceneFileError, match=r"notes\.exr: not a \.npz \(zip\) archive"):
        load_npz(text)
    with pytest.raises(SceneFileError, match="no such file"):
        load_exr(tmp_path / "missing.exr")
    with pytest.raises(SceneFileError, match="not a regular file"):
        load_npz(tmp_path)
    zero = np.zeros((H, W), np.float32)
    OpenEXR.File({}, {"Y": zero}).write(str(tmp_path / "luminance.exr"))
    with pytest.raises(SceneFileError, match=r"no channel glphong knows; the file has \['Y'\]"):
        load_exr(tmp_path / "luminance.exr")


@pytest.mark.parametrize("channels, message", [
    ({"Z": np.zeros((H, W), np.uint32)}, r"channel 'Z': pixel type UINT; expected FLOAT or HALF"),
    ({"instance.id": np.zeros((H, W), np.float32)}, r"channel 'instance.id': pixel type FLOAT; expected UINT"),
    ({"normal.X": np.zeros((H, W), np.float32), "normal.Y": np.zeros((H, W), np.float32)},
     r"channels \['normal.X', 'normal.Y'\] of 'normal' without \['normal.Z'\]"),
])
def test_exr_channel_types_and_layers_are_checked(tmp_path, channels, message):
    path = tmp_path / "odd.exr"
    OpenEXR.File({}, channels).write(str(path))
    with pytest.raises(SceneFileError, match=message):
        load_exr(path)


def test_half_float_channels_widen_exactly(tmp_path):
    depth = np.linspace(0.0, 4.0, H * W, dtype=np.float16).reshape(H, W)
    OpenEXR.File({}, {"Z": depth}).write(str(tmp_path / "half.exr"))
    loaded = load_exr(tmp_path / "half.exr")
    assert loaded["depth"].dtype == np.float32 and np.array_equal(loaded["depth"], depth.astype(np.float32))


def test_limits_are_checked_before_decoding(tmp_path, glphong_make_renderer):
    frame = _small_frame(glphong_make_renderer)
    save_exr(tmp_path / "f.exr", frame)
    save_npz(tmp_path / "f.npz", frame)
    small = Limits(image_pixels=W * H - 1)
    with pytest.raises(SceneFileError, match=r"f\.exr: header: a data window of 64 x 48 pixels"):
        load_exr(tmp_path / "f.exr", limits=small)
    with pytest.raises(SceneFileError, match=r"f\.npz: .*\.npy: 48 x 64 pixels; expected 1 to 3071"):
        load_npz(tmp_path / "f.npz", limits=small)
    with pytest.raises(SceneFileError, match="more than the limit of 100"):
        load_exr(tmp_path / "f.exr", limits=Limits(file_bytes=100))
    with pytest.raises(SceneFileError, match=r"Limits\.decoded_bytes"):
        load_npz(tmp_path / "f.npz", limits=Limits(decoded_bytes=W * H * 8))


def _npz(path, **members):
    """An archive holding ``members`` as written (arrays through np.save; bytes as they are)."""
    with zipfile.ZipFile(path, "w") as archive:
        for name, value in members.items():
            if isinstance(value, np.ndarray):
                stream = io.BytesIO()
                np.save(stream, value, allow_pickle=True)
                value = stream.getvalue()
            archive.writestr(f"{name}.npy", value)


@pytest.mark.parametrize("members, message", [
    ({"depth": np.zeros((H, W), np.float64)}, r"depth\.npy: float64 \(48, 64\); expected float32 \(H, W\)"),
    ({"instance": np.zeros((H, W), np.int32)}, r"instance\.npy: int32 .*expected uint32"),
    ({"normal": np.zeros((H, W, 2), np.float32)}, r"normal\.npy: .*expected float32 \(H, W, 3\)"),
    ({"depth": np.array([{"a": 1}] * 4, dtype=object).reshape(2, 2)}, r"depth\.npy: object"),
    ({"evil": np.zeros((H, W), np.float32)}, r"unexpected members \['evil\.npy'\]"),
    ({"depth": np.zeros((H, W), np.float32), "radiance": np.zeros((H, W + 1, 3), np.float32)},
     r"radiance\.npy: 48 x 65 pixels \(H x W\), the archive's other arrays 48 x 64"),
    ({}, "holds no arrays"),
    ({"depth": np.zeros((0, W), np.float32)}, r"depth\.npy: shape \(0, 64\); expected every dimension >= 1"),
])
def test_hostile_npz(tmp_path, members, message):
    path = tmp_path / "hostile.npz"
    _npz(path, **members)
    with pytest.raises(SceneFileError, match=message):
        load_npz(path)


def test_a_lying_npz_header_is_refused_before_allocating(tmp_path):
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f4", "fortran_order": False, "shape": (100000, 100000)})
    _npz(tmp_path / "big.npz", depth=header.getvalue() + b"\0" * 16)
    with pytest.raises(SceneFileError, match=r"depth\.npy: 100000 x 100000 pixels; expected 1 to"):
        load_npz(tmp_path / "big.npz")


def test_writes_are_atomic_and_frames_checked(tmp_path, glphong_make_renderer, monkeypatch):
    frame = _small_frame(glphong_make_renderer)
    for name, save in (("f.exr", save_exr), ("f.npz", save_npz)):
        path = tmp_path / name
        path.write_bytes(b"earlier")
        with pytest.raises(ValueError, match=r"frame\.depth is float64 \(48, 64\); expected float32 \(H, W\)"):
            save(path, replace(frame, depth=frame.depth.astype(np.float64)))
        with pytest.raises(ValueError, match="frame.passes lists 'normal' but frame.normal is None"):
            save(path, replace(frame, passes=frame.passes + ("normal",)))
        with pytest.raises(FileNotFoundError, match="does not exist"):
            save(tmp_path / "missing" / name, frame)
        assert path.read_bytes() == b"earlier"
    monkeypatch.setattr(np, "savez_compressed", lambda *a, **k: (_ for _ in ()).throw(OSError("disk full")))
    with pytest.raises(OSError, match="disk full"):  # a failure half-way through leaves the old file, no temporary
        save_npz(tmp_path / "f.npz", frame)
    assert (tmp_path / "f.npz").read_bytes() == b"earlier"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.exr", "f.npz"]


def test_missing_extra_is_named(tmp_path, glphong_make_renderer, monkeypatch):
    frame = _small_frame(glphong_make_renderer)
    monkeypatch.setitem(sys.modules, "OpenEXR", None)
    with pytest.raises(ImportError, match=r"optional extra 'exr' \(pip install 'glphong\[exr\]'"):
        save_exr(tmp_path / "f.exr", frame)
    assert list(tmp_path.iterdir()) == []


def test_matte_arrays_come_in_pairs_of_one_k(tmp_path, frame):
    from dataclasses import replace
    with pytest.raises(ValueError, match="matte_ids is .*matte_fractions"):
        save_npz(tmp_path / "bad.npz", replace(frame, matte_fractions=frame.matte_fractions[..., :3].copy()))
    with pytest.raises(ValueError, match=r"frame.matte_ids is uint32 \(48, 64, 17\)"):
        save_npz(tmp_path / "bad.npz", replace(frame, matte_ids=np.zeros((H, W, 17), np.uint32)))
    np.savez(tmp_path / "half.npz", matte_ids=frame.matte_ids)
    with pytest.raises(SceneFileError, match="matte_ids and matte_fractions: expected both"):
        load_npz(tmp_path / "half.npz")
    k2 = replace(frame, matte_ids=frame.matte_ids[..., :2].copy(), matte_fractions=frame.matte_fractions[..., :2].copy())
    save_exr(tmp_path / "k2.exr", k2)
    loaded = load_exr(tmp_path / "k2.exr", passes=("matte_ids",))
    assert _same_bits(loaded["matte_ids"], k2.matte_ids) and _same_bits(loaded["matte_fractions"], k2.matte_fractions)
    assert not list(tmp_path.glob("bad*"))
