"""The materials a caller gives `load_scene` in place of a file's (``materials=``)."""
from glphong.materials import Material

__all__ = ["chosen_material"]


def chosen_material(materials, name, entry):
    """The user's material for part ``name`` (``materials`` mapping or callable), or None."""
    material = None
    if callable(materials):
        material = materials(name, entry)
    elif materials and name in materials:
        material = materials[name]
    if material is not None and not isinstance(material, Material):
        raise TypeError(f"materials gave {type(material).__name__} for {name!r}: it must give a glphong material")
    return material


