"""The one definition mechanism: a named class with parameters, GLSL, a numpy twin, a band, an oracle and cases.

`MaterialModel` (a reflectance model, docs/design.md section 8) and `LightModel` (a light kind, section 11) are both
`Definition` subclasses, and the built-ins use exactly the mechanism a user's definition does: a subclass that sets
``name`` is checked when its class is created (`check_definition`, raising the sort's `definition_error` that says
what to write instead) and registered in its sort's `registry`; its GLSL is read, hashed and found again through the
registry (`source`, `source_hash`, `source_label`); its uniforms are ``u_<name>_<param>``.  A subclass without a
name of its own is an abstract intermediate or a pure-Python subclass (`check_unnamed` refuses one that redefines
what would make it another definition).
"""
from glphong.definitions.params import DefinitionError
from glphong.definitions.registry import is_builtin

__all__ = ["Definition"]


class Definition:
    """Base of material models and light kinds.

    Class attributes
    ----------------
    name : str
        Lowercase GLSL prefix, unique among all definitions.
    params : tuple of Param
        The constructor's parameters, in positional order.
    glsl : str, path or GlslFile
        The GLSL of the definition's functions.
    uses : tuple of str
        Library chunks its GLSL calls (`glphong.core.glsl_files.LIBRARY`).
    in_uber : bool
        Compiled into every uber-shader.
    registry : glphong.definitions.registry.Registry
        Where definitions of this sort are registered (set by the sort's base class).
    definition_error : type
        The exception a broken definition raises.
    definition_kind : str
        The sort in messages ('material', 'light').
    """

    name = None
    params = ()
    glsl = None
    uses = ()
    in_uber = False
    registry = None
    definition_error = DefinitionError
    definition_kind = "definition"

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "registry" in cls.__dict__:
            return  # a sort's base class (MaterialModel, LightModel), not a definition
        if "name" not in cls.__dict__:
            cls.check_unnamed()
            return
        taken = cls.registry.taken_by(cls)
        if taken is not None:
            raise cls.definition_error(
                f"{cls.__qualname__}: the {cls.definition_kind} name {cls.name!r} is taken by "
                f"{'the built-in ' if is_builtin(taken) else ''}{taken.__module__}.{taken.__qualname__}; "
                "choose another name")
        cls.check_definition()
        cls.registry.add(cls)  # a re-run of the same definition (a notebook cell) replaces it

    @classmethod
    def check_unnamed(cls):
        """Checks of a subclass that sets no name of its own (default none)."""

    @classmethod
    def check_definition(cls):
        """The definition-time checks of a named subclass; raise `definition_error` saying what to write."""
        raise NotImplementedError

    @classmethod
    def uniform_name(cls, param):
        """``u_<name>_<param>``."""
        return f"u_{cls.name}_{param}"

    @classmethod
    def source(cls):
        """The definition's GLSL text."""
        return cls.registry.source(cls)[0]

    @classmethod
    def source_hash(cls):
        """First 12 hex digits of the SHA-256 of the uniform declarations, uses and GLSL text (part of the program
        key: an edited definition is another program)."""
        return cls.registry.source(cls)[3]

    @classmethod
    def source_label(cls):
        """Where the GLSL comes from (a file, or the class), for compile errors."""
        return cls.registry.source(cls)[1]
