"""Materials as JSON: what glphong stores in a glTF material's ``extras`` (``{"glphong": ...}``).

A material is written by its class and its constructor's arguments (`MaterialModel.arguments`), so
every model, built-in or a user's, round-trips the same way::

    {"class": "Phong", "module": "glphong.materials.phong",
     "arguments": {"kd": [0.2, 0.2, 0.2], "ks": [0.3, 0.3, 0.3], "q": 20.0},
     "ka": [0, 0, 0], "two_sided": true}

Parameters are lists of 3 floats or floats (the validated values, which JSON keeps exactly: Python's
float repr round-trips), choices strings, a Fresnel factor ``{"class": "SchlickFresnel", "f0": [...]}``
and a surface input ``{"surface": {"scale": [...], "texture": <index>, "vertex_colors": false}}``, where
the index names a texture of the file (the writer's ``texture_index``, the reader's ``textures``).
Tables (`MeasuredBRDF`) are not stored: a file would hold megabytes of JSON.  On reading, the class is
found among the defined materials by module and name (a user's module must have been imported).
"""

from glphong.definitions.fresnel import Fresnel
from glphong.definitions.material import Choice, Material, Param
from glphong.definitions.surface import AlphaBlend, AlphaMask, NormalMap, SurfaceInput
from glphong.definitions.table import Table
__all__ = ["material_to_json", "material_from_json"]

#: the version of the layout above
VERSION = 1


def _plain(value):
    return [float(c) for c in value] if isinstance(value, tuple) else float(value)


def _alpha_to_json(owner, texture_index, cls, what):
    """An `AlphaMask`'s or `AlphaBlend`'s alpha as JSON: the number, or its texture (by ``texture_index``)."""
    if not owner.textured:
        return owner.alpha
    if texture_index is None:
        raise ValueError(f"{cls.__name__} has a textured {what}: give texture_index to store it")
    return {"texture": int(texture_index(owner.alpha.texture)), "wrap": owner.alpha.texture.wrap,
            "filter": owner.alpha.texture.filter, "scale": owner.alpha.scale, "channel": owner.alpha.channel}


def _alpha_from_json(entry, textures, cls, name, expected):
    """The alpha of a stored ``alpha_mask`` or ``alpha_blend`` object ``entry``: a number, or a `SurfaceInput` of
    one of ``textures``; ValueError naming ``name`` and what was ``expected``."""
    alpha = entry.get("alpha", 1.0) if isinstance(entry, dict) else None
    if isinstance(alpha, dict):
        if textures is None:
            raise ValueError(f"{cls.__name__}: its {name} is textured, but no textures were given")
        alpha = SurfaceInput(alpha.get("scale", 1.0), textures(alpha["texture"], alpha.get("wrap", "repeat"),
                                                               alpha.get("filter", "trilinear"), False),
                             channel=alpha.get("channel", "r"))
    if not isinstance(alpha, (int, float, SurfaceInput)) or isinstance(alpha, bool):
        raise ValueError(f"{cls.__name__}: '{name}' must be {expected}")
    return alpha


def material_to_json(material, texture_index=None):
    """The JSON-ready dict of ``material`` (see the module).

    Parameters
    ----------
    material : glphong.materials.Material
    texture_index : callable, optional
        ``texture_index(TextureImage) -> int``: the file's index of a texture (the glTF writer adds it to
        the file).  Without it a textured parameter raises ValueError.

    Raises
    ------
    ValueError
        A table argument, or a texture without ``texture_index``.
    """

    cls = type(material)
    arguments = {}
    for argument in cls.arguments():
        value = getattr(material, argument.name)
        if isinstance(argument, Table):
            raise ValueError(f"{cls.__name__}.{argument.name} is a table, which glphong does not store as JSON")
        if isinstance(value, SurfaceInput):
            surface = {"scale": _plain(value.scale), "vertex_colors": bool(value.vertex_colors)}
            surface.update({"channel": value.channel} if value.channel is not None else {})
            if value.texture is not None:
                if texture_index is None:
                    raise ValueError(f"{cls.__name__}.{argument.name} is textured: give texture_index to store it")
                surface.update(texture=int(texture_index(value.texture)), wrap=value.texture.wrap,
                               filter=value.texture.filter, srgb=value.texture.encoding.startswith("srgb"))
            arguments[argument.name] = {"surface": surface}
        elif isinstance(value, Fresnel):
            arguments[argument.name] = {"class": type(value).__name__, value.field: _plain(getattr(value, value.field))}
        elif isinstance(argument, (Param, Choice)) or value is None:
            arguments[argument.name] = value if isinstance(value, str) or value is None else _plain(value)
    out = {"version": VERSION, "class": cls.__name__, "module": cls.__module__, "arguments": arguments,
           "ka": _plain(material.ka), "two_sided": bool(material.two_sided)}
    if material.alpha_mask is not None:
        out["alpha_mask"] = {"cutoff": material.alpha_mask.cutoff,
                             "alpha": _alpha_to_json(material.alpha_mask, texture_index, cls, "alpha mask")}
    if material.alpha_blend is not None:
        out["alpha_blend"] = {"alpha": _alpha_to_json(material.alpha_blend, texture_index, cls, "alpha blend")}
    if material.normal_map is not None:
        if texture_index is None:
            raise ValueError(f"{cls.__name__} has a normal map: give texture_index to store it")
        texture = material.normal_map.texture
        out["normal_map"] = {"texture": int(texture_index(texture)), "wrap": texture.wrap, "filter": texture.filter,
                             "scale": material.normal_map.scale}
    return out


def _subclasses(base):
    """Every subclass of ``base`` defined so far (depth first)."""
    out, stack = [], [base]
    while stack:
        for sub in stack.pop().__subclasses__():
            out.append(sub)
            stack.append(sub)
    return out


def _material_classes():
    out = {}
    for sub in _subclasses(Material):
        out.setdefault((sub.__module__, sub.__name__), sub)
    return out


def material_from_json(data, textures=None):
    """The material a `material_to_json` dict describes.

    Parameters
    ----------
    data : dict
    textures : callable, optional
        ``textures(index, wrap, filter, srgb) -> TextureImage`` for textured parameters.

    Raises
    ------
    ValueError
        An unknown class (naming it and where it should come from), a newer layout, or a value the
        class refuses (its own message).
    """

    if not isinstance(data, dict) or data.get("version", 0) > VERSION or "class" not in data:
        raise ValueError(f"not a glphong material (layout version {VERSION}): {data!r}"[:300])
    classes = _material_classes()
    cls = classes.get((data.get("module"), data["class"]))
    if cls is None:
        named = [c for (module, name), c in classes.items() if name == data["class"]]
        if len(named) != 1:
            raise ValueError(f"no material class {data.get('module')}.{data['class']} is defined: import the module "
                             "that defines it before loading")
        cls = named[0]
    declared = {argument.name: argument for argument in cls.arguments()}
    factors = {factor.__name__: factor for factor in _subclasses(Fresnel)}
    arguments = {}
    stored = data.get("arguments", {})
    if not isinstance(stored, dict):
        raise ValueError(f"{cls.__name__}: 'arguments' must be an object")
    for name, value in stored.items():
        if name not in declared:
            raise ValueError(f"{cls.__name__} has no argument {name!r:.40} (it has {', '.join(declared)})")
        if isinstance(declared[name], Table):
            raise ValueError(f"{cls.__name__}.{name} is a table: glphong never reads a table (or its path) from a "
                             "scene file; give the material with load_scene(..., materials=...)")
        if isinstance(value, dict) and "surface" in value:
            s = value["surface"]
            texture = None
            if "texture" in s:
                if textures is None:
                    raise ValueError(f"{cls.__name__}.{name} is textured, but no textures were given")
                texture = textures(s["texture"], s.get("wrap", "repeat"), s.get("filter", "trilinear"), s.get("srgb", True))
            scale = tuple(s["scale"]) if isinstance(s["scale"], list) else s["scale"]
            value = SurfaceInput(scale, texture, bool(s.get("vertex_colors", False)), s.get("channel"))
        elif isinstance(value, dict) and "class" in value:
            factor = factors.get(value["class"]) if isinstance(value["class"], str) else None
            if factor is None:
                raise ValueError(f"{cls.__name__}.{name}: unknown Fresnel factor {value['class']!r:.40} (known: "
                                 f"{', '.join(sorted(factors))})")
            value = factor(**{k: tuple(v) if isinstance(v, list) else v for k, v in value.items() if k != "class"})
        elif isinstance(value, list):
            value = tuple(value)
        arguments[name] = value
    ka = data.get("ka", 0.0)
    normal_map = None
    if data.get("normal_map") is not None:
        n = data["normal_map"]
        if not isinstance(n, dict) or textures is None:
            raise ValueError(f"{cls.__name__}: 'normal_map' must be an object naming a texture, and textures must be given")
        normal_map = NormalMap(textures(n["texture"], n.get("wrap", "repeat"), n.get("filter", "trilinear"), False),
                               n.get("scale", 1.0))
    alpha_mask = alpha_blend = None
    if data.get("alpha_mask") is not None:
        a = data["alpha_mask"]
        alpha = _alpha_from_json(a, textures, cls, "alpha_mask", "an object with a cutoff and an alpha")
        alpha_mask = AlphaMask(a.get("cutoff", 0.5), alpha)
    if data.get("alpha_blend") is not None:
        alpha_blend = AlphaBlend(_alpha_from_json(data["alpha_blend"], textures, cls, "alpha_blend",
                                                  "an object with an alpha: a number in [0, 1] or a texture"))
    return cls(**arguments, ka=tuple(ka) if isinstance(ka, list) else float(ka), two_sided=bool(data.get("two_sided", True)),
               normal_map=normal_map, alpha_mask=alpha_mask, alpha_blend=alpha_blend)
