"""Wavefront MTL materials: read as written (`parse_mtl`) and made into the material the file means
(`material_from_mtl`).

An MTL file describes the fixed-function Phong its authors saw; each entry becomes `glphong.MtlPhong`:

- ``illum 0``: colour ``Kd`` with no lighting: a constant radiance ``ka = Kd`` and nothing lit;
- ``illum 1``: ``Kd (n.l) E + Ka L_a`` (no specular term);
- ``illum 2``: ``Kd (n.l) E + Ks max(v.r, 0)^Ns E + Ka L_a``;
- ``illum 3`` to ``10`` (reflections, refraction, ray tracing): rendered as ``illum 2``, with a warning;
- ``map_Kd`` / ``map_Ks``: textures (sRGB, trilinear, repeat) that ``Kd`` / ``Ks`` multiply, read only from
  inside the MTL file's folder (`glphong.filesafety`).
"""
import io
import math
import warnings
from pathlib import Path

from glphong.core.filesafety import SceneFileError, decode_image, read_bytes, read_text, resolve_reference
from glphong.materials import Texture
from glphong.materials.mtl import MtlPhong

__all__ = ["parse_mtl", "material_from_mtl", "MTL_IMAGE_FORMATS"]


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
        A keyword with values that are not finite numbers, or an image path leaving the folder, naming the
        file and line.
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
        try:
            if keyword in ("Kd", "Ks", "Ka"):
                numbers = [float(v) for v in values[:3]]
                current[keyword] = tuple(numbers * 3 if len(numbers) == 1 else numbers)
                if len(current[keyword]) != 3 or not all(math.isfinite(v) for v in current[keyword]):
                    raise ValueError
            elif keyword == "Ns":
                current["Ns"] = float(values[0])
                if not math.isfinite(current["Ns"]):
                    raise ValueError
            else:
                current["illum"] = int(values[0])
        except (ValueError, IndexError):
            raise SceneFileError(path, f"{keyword} needs finite numbers (got {' '.join(values)!r:.80})", where) from None
    return out


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
        warnings.warn(f"{source}: material {name!r} has illum {illum} (reflection, refraction or ray tracing): "
                      "glphong renders it as illum 2 (Kd, Ks, Ns and Ka)", stacklevel=3)
    return MtlPhong(kd, ks, q, ka)


