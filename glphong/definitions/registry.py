"""The registries of definitions: material models and light kinds, each registered by name when its class is made.

One `Registry` class serves both (docs/design.md sections 8 and 11): a definition registers itself when its class is
created (`glphong.definitions.definition.Definition`), program assembly finds a definition's GLSL through its
registry (`Registry.for_key`, `Registry.source`), never the reverse.  A definition's source hash covers its uniform
declarations, the library chunks it uses and its text, so an edited definition is another program.  `MATERIALS` lists
models by name; `LIGHTS` lists kinds in the shader's loop order (the built-ins' `loop_order`, then a user's kinds in
the order they were defined).
"""
import hashlib
import itertools

from glphong.definitions.source import resolve_source

__all__ = ["Registry", "MATERIALS", "LIGHTS", "registered_models", "model_named", "model_source", "model_for_key",
           "register", "registered_lights", "light_named", "light_for_key", "light_source"]


class Registry:
    """Definitions of one sort by name, with their GLSL sources cached per class and by source hash.

    Parameters
    ----------
    sort : str
        What a definition is, in messages ('material model', 'light kind').
    loop_ordered : bool
        `all` lists the definitions in loop order (each class's ``loop_order``, then definition order) instead of
        by name.
    """

    def __init__(self, sort, loop_ordered=False):
        self.sort = sort
        self.loop_ordered = loop_ordered
        self._classes = {}  # name -> (class, sequence number of its first definition)
        self._sources = {}  # class -> (text, label, first line, hash)
        self._by_hash = {}  # (name, hash) -> class
        self._sequence = itertools.count()

    def add(self, cls):
        """Register ``cls`` under its name; a re-run of the same definition (a notebook cell) replaces it in place."""
        existing = self._classes.get(cls.name)
        if existing is not None:
            self._sources.pop(existing[0], None)
        self._classes[cls.name] = (cls, existing[1] if existing else next(self._sequence))

    def taken_by(self, cls):
        """The registered class whose name ``cls`` may not take, or None: a built-in's name, or a different
        definition's (a re-run of the same module and class name replaces it)."""
        found = self._classes.get(cls.name) if isinstance(cls.name, str) else None
        if found is None or found[0] is cls:
            return None
        existing = found[0]
        same = (existing.__module__, existing.__qualname__) == (cls.__module__, cls.__qualname__)
        return existing if is_builtin(existing) or not same else None

    def all(self):
        """Every registered definition (tuple): by name, or in loop order."""
        if not self.loop_ordered:
            return tuple(self._classes[name][0] for name in sorted(self._classes))

        def order(entry):
            cls, sequence = entry
            return (0, cls.loop_order, sequence) if cls.loop_order is not None else (1, 0, sequence)
        return tuple(cls for cls, _ in sorted(self._classes.values(), key=order))

    def named(self, name):
        """The definition registered as ``name`` (KeyError naming the defined ones)."""
        try:
            return self._classes[name][0]
        except KeyError:
            names = ", ".join(c.name for c in self.all())
            raise KeyError(f"no {self.sort} is named {name!r} (defined: {names})") from None

    def source(self, cls):
        """``(text, label, first_line, source_hash)`` of ``cls``'s GLSL, cached per class (`resolve_source`).

        The hash covers everything the definition's chunk is made of: its uniform declarations, the library chunks
        it uses and its text."""
        cached = self._sources.get(cls)
        if cached is None:
            text, label, first = resolve_source(cls)
            whole = "\n".join([cls.uniform_declarations(), " ".join(cls.uses), text])
            digest = hashlib.sha256(whole.encode("utf-8")).hexdigest()[:12]
            cached = self._sources[cls] = (text, label, first, digest)
            self._by_hash[(cls.name, digest)] = cls
        return cached

    def for_key(self, name, source_hash):
        """The definition a program key's entry was made from (by name and source hash): a class redefined since
        (a re-run notebook cell) still builds its own programs."""
        cls = self._by_hash.get((name, source_hash))
        if cls is None:
            cls = self.named(name)
            if cls.source_hash() != source_hash:
                raise KeyError(f"no definition of the {self.sort} {name!r} has source hash {source_hash}")
        return cls


def is_builtin(cls):
    """True for a definition glphong ships (its module is glphong's)."""
    return cls.__module__.startswith("glphong.")


#: the material models, by name
MATERIALS = Registry("material model")
#: the light kinds, in the shader's loop order
LIGHTS = Registry("light kind", loop_ordered=True)


def registered_models():
    """Every defined `MaterialModel` subclass, built-in and user, sorted by name (tuple)."""
    return MATERIALS.all()


def model_named(name):
    """The `MaterialModel` subclass registered as ``name``.

    Raises
    ------
    KeyError
        No model has that name.
    """
    return MATERIALS.named(name)


def model_source(cls):
    """``(text, label, first_line, source_hash)`` of a model's GLSL (cached per class)."""
    return MATERIALS.source(cls)


def model_for_key(name, source_hash):
    """The model class a program key's term was made from (by name and source hash)."""
    return MATERIALS.for_key(name, source_hash)


def register(cls):
    """Register model class ``cls`` under its name (a re-run of the same definition replaces it)."""
    MATERIALS.add(cls)


def registered_lights():
    """Every defined light kind, built-in and user, in the order the shader loops over them (tuple): the built-ins
    (point, unattenuated, directional, spot, then the extended kinds), then a user's kinds in definition order."""
    return LIGHTS.all()


def light_named(name):
    """The `LightModel` subclass registered as ``name`` (KeyError naming the defined kinds)."""
    return LIGHTS.named(name)


def light_for_key(name, source_hash):
    """The light kind a program key's entry was made from (by name and source hash)."""
    return LIGHTS.for_key(name, source_hash)


def light_source(cls):
    """``(text, label, first_line, source_hash)`` of a light kind's GLSL (cached per class)."""
    return LIGHTS.source(cls)
