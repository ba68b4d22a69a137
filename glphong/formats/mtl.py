"""Wavefront MTL materials: read as written (`parse_mtl`) and made into the material the file means
(`material_from_mtl`).

An MTL file describes the fixed-function Phong its authors saw; each entry becomes `glphong.MtlPhong`:

- ``illum 0``: colour ``Kd`` with no lighting: a constant radiance ``ka = Kd`` and nothing lit;
- ``illum 1``: ``Kd (n.l) E + Ka L_a`` (no specular term);
- ``illum 2``: ``Kd (n.l) E + Ks max(v.r, 0)^Ns E + Ka L_a``;
- ``illum 3`` to ``10`` (ray-traced reflection, glass, refraction, Fresnel, shadows onto invisible surfaces:
  `ILLUM_MODELS`): rendered as ``illum 2``, with a warning naming the model; any other ``illum`` (the
  specification defines 0 to 10) is an error naming the file and line, as are colours and ``Ns`` beyond what
  `glphong.MtlPhong` takes (negative, not finite, beyond float32);
- ``map_Kd`` / ``map_Ks``: textures (sRGB, trilinear, repeat) that ``Kd`` / ``Ks`` multiply, read only from
  inside the MTL file's folder (`glphong.filesafety`).
"""
import io
import warnings
from pathlib import Path

from glphong.core.filesafety import SceneFileError, decode_image, read_bytes, read_text, resolve_reference
from glphong.materials import Texture
from glphong.core.validate import FLT_MAX
from glphong.materials.mtl import MtlPhong

__all__ = ["parse_mtl", "material_from_mtl", "MTL_IMAGE_FORMATS", "ILLUM_MODELS"]


def parse_mtl(path, limits=None, allow_outside=False):
    """The materials of an MTL file, keyword values as written.

    Parameters
    ----------
    path : path-like
    limits : glphong.filesafety.Limits, optional
        The file-size cap (a regular file is required).
    allow_outside : bool
        Let ``map_Kd`` / ``map_Ks`` name images outside the MTL file's folder.

    Returns
    -------
    dict of str to dict
        Per ``newmtl`` name: ``Kd``, ``Ks``, ``Ka`` (tuples of 3 float, a single value repeated), ``Ns``
        (float), ``illum`` (int), ``map_Kd`` and ``map_Ks`` (the image's path, resolved against the MTL
        file's folder and confined to it; options such as ``-s`` are ignored, with a warning), where the
        file gives them.

    Raises
    ------
    glphong.filesafety.SceneFileError
        A ``Kd``/``Ks``/``Ka`` that is not 1 or 3 numbers from 0 to the float32 maximum, an ``Ns`` that is not
        one such number, an ``illum`` that is not an integer from 0 to 10, or an image path leaving the folder,
        naming the file and line and what was expected.
    """
    out, current = {}, None
    # line by line from a stream: a file of a billion empty lines is never a list of a billion strings
    for number, raw in enumerate(io.StringIO(read_text(path, limits), newline=None), start=1):
        words = raw.split("#", 1)[0].split()
        if not words:
            continue
        keyword, values = words[0], words[1:]
        if keyword == "newmtl":
            current = out.setdefault(" ".join(values), {})
            continue
        if current is None or keyword not in ("Kd", "Ks", "Ka", "Ns", "illum", "map_Kd", "map_Ks"):
            continue
        where = f"line {number}"
        if keyword.startswith("map_"):
            if not values:
                raise SceneFileError(path, f"{keyword} needs an image file", where)
            if values[0].startswith("-"):
                warnings.warn(f"{path}:{number}: {keyword} options {' '.join(values[:-1])!r:.80} are ignored",
                              stacklevel=2)
            current[keyword] = resolve_reference(path, values[-1], where, allow_outside, percent_encoded=False)
            continue
        current[keyword] = _value(path, keyword, values, where)
    return out


#: what each MTL illumination model asks for (the MTL specification's list, 0 to 10; glphong draws 0, 1 and 2)
ILLUM_MODELS = {0: "colour on, ambient off", 1: "colour on, ambient on", 2: "highlight on",
                3: "reflection on and ray trace on", 4: "transparency: glass on, reflection: ray trace on",
                5: "reflection: Fresnel on and ray trace on",
                6: "transparency: refraction on, reflection: Fresnel off and ray trace on",
                7: "transparency: refraction on, reflection: Fresnel on and ray trace on",
                8: "reflection on and ray trace off", 9: "transparency: glass on, reflection: ray trace off",
                10: "casts shadows onto invisible surfaces"}


def _value(path, keyword, values, where):
    """The value of an MTL ``Kd``/``Ks``/``Ka`` (3 numbers, or 1 repeated), ``Ns`` or ``illum`` line, checked
    against what glphong's `glphong.MtlPhong` takes; `SceneFileError` naming the file, the line and what was
    expected."""
    got = f"(got {' '.join(values)!r:.80})"
    if keyword == "illum":
        if len(values) != 1 or not values[0].lstrip("+-").isdigit() or int(values[0]) not in ILLUM_MODELS:
            raise SceneFileError(path, "illum needs one integer from 0 to 10, the MTL specification's illumination "
                                 f"models {got}", where)
        return int(values[0])
    try:
        numbers = [float(v) for v in values]
    except ValueError:
        numbers = []
    if keyword == "Ns":
        if len(numbers) != 1 or not 0.0 <= numbers[0] <= FLT_MAX:  # NaN fails too
            raise SceneFileError(path, f"Ns needs finite numbers: one, the specular exponent, from 0 to {FLT_MAX:.6g} "
                                 f"(a float32; the MTL specification's range is 0 to 1000) {got}", where)
        return numbers[0]
    if len(numbers) not in (1, 3) or not all(0.0 <= v <= FLT_MAX for v in numbers):  # spectral and xyz forms fail
        raise SceneFileError(path, f"{keyword} needs finite numbers: 3, r g b (or 1 for all three), each from 0 to "
                             f"{FLT_MAX:.6g} (a float32; reflectances, 0 to 1 in the MTL specification) {got}", where)
    return tuple(numbers * 3 if len(numbers) == 1 else numbers)


#: image formats an MTL map may be (Pillow plugins asked for; no EPS or PDF reaches Ghostscript)
MTL_IMAGE_FORMATS = ("PNG", "JPEG", "BMP", "TGA", "TIFF")


def material_from_mtl(entry, name="", source="", limits=None):
    """The glphong material an MTL entry (`parse_mtl`) means (see the module).  ``map_Kd`` and ``map_Ks``
    are textures that ``Kd`` and ``Ks`` multiply (1 where the entry omits them); a map whose image is
    missing is warned about and its constant used; an image beyond ``limits`` is an error."""

    kd = entry.get("Kd", (1.0, 1.0, 1.0) if "map_Kd" in entry else (0.8, 0.8, 0.8))  # MTL's default diffuse colour
    ks = entry.get("Ks", (1.0, 1.0, 1.0) if "map_Ks" in entry else (0.0, 0.0, 0.0))
    specular = "map_Ks" in entry or any(ks)
    for keyword, value in (("map_Kd", kd), ("map_Ks", ks)):
        if keyword in entry:
            image = Path(entry[keyword])
            if not image.exists():
                warnings.warn(f"{source}: material {name!r}: {keyword} {image.name} not found; its constant is used",
                              stacklevel=3)
                continue
            payload = read_bytes(image, limits, source or image, f"material {name!r} {keyword}")
            pixels = decode_image(payload, limits, source or image, f"material {name!r} {keyword} {image.name}",
                                  formats=MTL_IMAGE_FORMATS)
            if pixels.ndim == 3 and pixels.shape[2] == 4:
                pixels = pixels[:, :, :3]
            try:
                texture = Texture(pixels, scale=value)
            except ValueError as exc:
                raise SceneFileError(source or image, f"material {name!r}: {keyword} {image.name}: {exc}") from None
            kd, ks = (texture, ks) if keyword == "map_Kd" else (kd, texture)
    ka = entry.get("Ka", (0.0, 0.0, 0.0))
    q = entry.get("Ns", 0.0)
    illum = entry.get("illum", 2 if specular else 1)
    if illum == 0:
        if not isinstance(kd, tuple):
            warnings.warn(f"{source}: material {name!r} has illum 0 and map_Kd: rendered with the constant Kd",
                          stacklevel=3)
            kd = entry.get("Kd", (1.0, 1.0, 1.0))
        return MtlPhong(0.0, 0.0, 0.0, 0.0, ka=kd)
    if illum == 1:
        return MtlPhong(kd, 0.0, q, ka)
    if illum != 2:
        warnings.warn(f"{source}: material {name!r} has illum {illum} ({ILLUM_MODELS[illum]}): glphong renders it as "
                      "illum 2 (Kd, Ks, Ns and Ka, highlight on)", stacklevel=3)
    return MtlPhong(kd, ks, q, ka)


