"""Files from anyone, tried as a new user would (issue 42): MTL values beyond what they mean, an ``illum`` the
specification does not define, and one OBJ face line of a million corners.

- ``Kd -0.5 0 0``, ``Ns 1e40``, ``Ka nan 0 0``, ``Ks 1 2``, ``Kd spectral x.rfl``: a `SceneFileError` naming the
  MTL file and the line, and what was expected (a colour is 1 or 3 numbers from 0; Ns one number);
- ``illum 99``, ``illum -1``, ``illum 2.5``: an error naming the file and line: the MTL specification defines the
  illumination models 0 to 10 (its list, transcribed in the test below, not read from the code);
- ``illum 3`` to ``10``: rendered as ``illum 2`` with a warning naming what the model asks for, as the specification
  words it;
- one face of 10^6 corners (2 MB): read with a tracemalloc peak that grows by at most 128 bytes a corner from a
  face of 10^5 corners (measured: 90 bytes a corner, 106 MB in all; the triangles themselves, 10^6 of them, are
  the output).
"""
import tracemalloc
import warnings

import pytest

import glphong
from glphong.core.filesafety import SceneFileError
from glphong.formats.obj import read_obj

TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"

# the MTL specification's illumination models (Wavefront, "MTL material format", illum_#), as it words them
SPEC_ILLUM = {3: "reflection on and ray trace on", 4: "glass on", 5: "Fresnel on", 6: "refraction on",
              7: "refraction on", 8: "ray trace off", 9: "glass on", 10: "shadows onto invisible surfaces"}


def _load(folder, body):
    (folder / "m.mtl").write_text(f"# materials\nnewmtl m\n{body}\n")
    (folder / "m.obj").write_text("mtllib m.mtl\nusemtl m\n" + TRIANGLE)
    return glphong.load_scene(folder / "m.obj")


@pytest.mark.parametrize("body, expected", [
    ("Kd -0.5 0 0", "Kd needs finite numbers: 3, r g b (or 1 for all three), each from 0 to"),
    ("Ka nan 0 0", "Ka needs finite numbers: 3, r g b"),
    ("Ks 1 2", "Ks needs finite numbers: 3, r g b"),
    ("Kd spectral x.rfl", "Kd needs finite numbers: 3, r g b"),
    ("Ns 1e40", "Ns needs finite numbers: one, the specular exponent, from 0 to 3.40282e+38"),
    ("Ns -1", "Ns needs finite numbers: one"),
    ("illum 99", "illum needs one integer from 0 to 10, the MTL specification's illumination models"),
    ("illum -1", "illum needs one integer from 0 to 10"),
    ("illum 2.5", "illum needs one integer from 0 to 10"),
])
def test_mtl_values_beyond_their_meaning_name_the_file_and_line(tmp_path, body, expected):
    with pytest.raises(SceneFileError) as info:
        _load(tmp_path, body)
    message = str(info.value)
    assert message.startswith(f"{tmp_path / 'm.mtl'}: line 3: ") and expected in message, message
    assert repr(body.split(None, 1)[1]) in message  # what was found


@pytest.mark.parametrize("illum", sorted(SPEC_ILLUM))
def test_illum_3_to_10_render_as_2_with_a_warning_saying_what_the_model_asks(tmp_path, illum):
    with pytest.warns(UserWarning, match=rf"has illum {illum} \(.*{SPEC_ILLUM[illum]}.*\): glphong renders it as "
                                         "illum 2"):
        scene = _load(tmp_path, f"Kd 0.5 0.5 0.5\nKs 0.25 0.25 0.25\nNs 10\nillum {illum}")
    assert scene.objects[0].material.q == 10.0


def test_illum_0_to_2_and_values_in_range_load_without_a_warning(tmp_path):
    for illum in (0, 1, 2):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            _load(tmp_path, f"Kd 0.5\nKs 2 0 0\nKa 0 0 0\nNs 0\nillum {illum}")


def _peak_of_one_face(folder, corners):
    path = folder / f"face_{corners}.obj"
    nine = "".join(f"v {x} {y} 0\n" for x in range(3) for y in range(3))
    path.write_text(nine + "f " + " ".join(str(1 + k % 9) for k in range(corners)) + "\n")
    tracemalloc.start()
    try:
        [(_, mesh)] = read_obj(path)
        return tracemalloc.get_traced_memory()[1], mesh
    finally:
        tracemalloc.stop()


def test_one_face_of_a_million_corners_costs_memory_proportional_to_its_corners(tmp_path):
    small, _ = _peak_of_one_face(tmp_path, 10 ** 5)
    large, mesh = _peak_of_one_face(tmp_path, 10 ** 6)
    assert mesh.triangle_count == 10 ** 6 - 2  # fanned from the first corner
    per_corner = (large - small) / (10 ** 6 - 10 ** 5)
    assert per_corner <= 128 and large <= 128 * 2 ** 20, (per_corner, large)
