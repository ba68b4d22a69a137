"""Material expressions such as ``"Phong(kd=0.2, ks=0.5, q=20)"``, parsed without running any code.

The command line (``glphong brdf EXPR``, ``glphong plot KIND EXPR ...``) takes materials as text.  That
text may come from anyone, so `parse_material` never hands it to ``eval``: it parses it with `ast`,
accepts only calls of glphong's material classes and Fresnel factors with literal arguments, bounds
every size, and builds the material from the checked tree.
"""
import ast
import math

from glphong import materials
from glphong.materials import Material
from glphong.definitions.fresnel import Fresnel

__all__ = ["ExpressionError", "parse_material", "material_classes", "MAX_TEXT_LENGTH", "MAX_DEPTH", "MAX_ITEMS", "MAX_STRING_LENGTH",
           "MAX_NODES", "MAX_INT_DIGITS"]

#: longest expression text accepted, in characters
MAX_TEXT_LENGTH = 2000
#: deepest nesting of calls, lists and tuples (``Phong(...)`` is 1, ``CookTorrance(fresnel=SchlickFresnel((...)))`` 3)
MAX_DEPTH = 8
#: most items of one list or tuple
MAX_ITEMS = 64
#: longest string literal, in characters
MAX_STRING_LENGTH = 256
#: most nodes of the syntax tree
MAX_NODES = 400
#: most decimal digits of an integer literal
MAX_INT_DIGITS = 30

EXAMPLE = "Phong(kd=0.2, ks=0.5, q=20)"

_ACCEPTED = ("accepted: a call of a glphong.materials class with literal arguments (numbers, strings, True, "
             f"False, None, tuples and lists of those, Fresnel factors), e.g. \"{EXAMPLE}\"")

#: what each refused kind of node is, for the error message
_NODE_WORDS = {
    "Attribute": "attribute access", "Subscript": "subscript", "Lambda": "lambda", "ListComp": "list comprehension",
    "SetComp": "set comprehension", "DictComp": "dict comprehension", "GeneratorExp": "generator expression",
    "NamedExpr": "assignment expression (:=)", "BinOp": "binary operator", "BoolOp": "boolean operator",
    "Compare": "comparison", "IfExp": "conditional expression", "JoinedStr": "f-string", "Starred": "*unpacking",
    "Dict": "dict display", "Set": "set display", "Await": "await", "Yield": "yield", "YieldFrom": "yield from",
    "Slice": "slice", "FormattedValue": "f-string field", "Constant": "literal",
}
#: how a refused binary operator is written
_OPERATOR_SYMBOLS = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.FloorDiv: "//", ast.Mod: "%",
                     ast.Pow: "**", ast.LShift: "<<", ast.RShift: ">>", ast.BitOr: "|", ast.BitXor: "^",
                     ast.BitAnd: "&", ast.MatMult: "@"}


class ExpressionError(ValueError):
    """A material expression that `parse_material` refuses: what was found, where, and what is accepted."""


def material_classes():
    """The classes a material expression may call, by name.

    Returns
    -------
    dict of str to type
        The `glphong.materials.Material` subclasses and `glphong.definitions.fresnel.Fresnel` subclasses
        that ``glphong.materials.__all__`` exports, less the bases `Material`, `MaterialModel`,
        `MaterialSum` and `Fresnel` themselves.
    """

    bases = (materials.Material, materials.MaterialModel, materials.MaterialSum, Fresnel)
    classes = {}
    for name in materials.__all__:
        value = getattr(materials, name, None)
        if isinstance(value, type) and issubclass(value, (materials.Material, Fresnel)) and value not in bases:
            classes[name] = value
    return classes


def _where(node, text):
    """``'column C'`` (``'line L, column C'`` in a text of several lines) of a node, counted from 1 in characters."""
    lines = text.splitlines() or [""]
    line = lines[node.lineno - 1] if 0 < node.lineno <= len(lines) else ""
    column = len(line.encode("utf-8")[:node.col_offset].decode("utf-8", errors="ignore")) + 1
    return f"column {column}" if len(lines) == 1 else f"line {node.lineno}, column {column}"


def _refuse(node, text, what, accepted=_ACCEPTED):
    """An `ExpressionError` naming ``what`` was found at ``node``, and what is ``accepted``."""
    return ExpressionError(f"refused {what} at {_where(node, text)}; {accepted}")


def _describe_node(node):
    """What a refused node is, in words, with its ast class name (``'attribute access (Attribute)'``)."""
    kind = type(node).__name__
    if isinstance(node, ast.BinOp):
        return f"binary operator {_OPERATOR_SYMBOLS.get(type(node.op), type(node.op).__name__)} (BinOp)"
    if isinstance(node, ast.Name):
        return f"name {node.id!r} (Name; not a glphong material class or Fresnel factor)"
    return f"{_NODE_WORDS.get(kind, kind)} ({kind})"


def _parse(text):
    """The expression's syntax tree (``ast.Expression``) and the stripped text it was parsed from, after the
    length and node-count bounds."""
    if not isinstance(text, str):
        raise TypeError(f"a material expression is a str (got {type(text).__name__})")
    if len(text) > MAX_TEXT_LENGTH:
        raise ExpressionError(f"refused an expression of {len(text)} characters (at most {MAX_TEXT_LENGTH}); "
                              f"{_ACCEPTED}")
    source = text.strip()
    try:
        tree = ast.parse(source, mode="eval")
    except SyntaxError as exc:
        where = f" at column {exc.offset}" if exc.offset else ""
        raise ExpressionError(f"refused text that is not a Python expression ({exc.msg}{where}); {_ACCEPTED}") from None
    except (ValueError, RecursionError, MemoryError) as exc:
        raise ExpressionError(f"refused text that cannot be parsed ({type(exc).__name__}); {_ACCEPTED}") from None
    count = sum(1 for node in ast.walk(tree) if not isinstance(node, ast.expr_context))
    if count > MAX_NODES:
        raise ExpressionError(f"refused an expression of {count} syntax nodes (at most {MAX_NODES}); {_ACCEPTED}")
    return tree, source


def _check_number(node, text, value):
    """Refuse a numeric literal that is out of bounds: an int of more than `MAX_INT_DIGITS` digits, a
    float that is not finite, a complex number."""
    if isinstance(value, bool):
        return
    if isinstance(value, int):
        if abs(value) >= 10 ** MAX_INT_DIGITS:
            raise _refuse(node, text, f"an integer of more than {MAX_INT_DIGITS} digits (Constant)")
    elif isinstance(value, float):
        if not math.isfinite(value):
            raise _refuse(node, text, f"a number that is not finite ({value!r}) (Constant)")
    else:
        raise _refuse(node, text, f"a {type(value).__name__} literal (Constant)")


def _check_constant(node, text):
    """Accept a number (bounded), a string (bounded), True, False or None."""
    value = node.value
    if value is None or isinstance(value, (bool, int, float, complex)):
        if value is not None:
            _check_number(node, text, value)
        return
    if isinstance(value, str):
        if len(value) > MAX_STRING_LENGTH:
            raise _refuse(node, text, f"a string of {len(value)} characters (at most {MAX_STRING_LENGTH}) (Constant)")
        return
    raise _refuse(node, text, f"a {type(value).__name__} literal (Constant)")


def _check_signed(node, text):
    """Accept ``-number`` and ``+number`` (one sign on an int or float literal)."""
    if not isinstance(node.op, (ast.USub, ast.UAdd)):
        raise _refuse(node, text, f"unary operator {type(node.op).__name__} (UnaryOp)")
    operand = node.operand
    if not (isinstance(operand, ast.Constant) and isinstance(operand.value, (int, float))
            and not isinstance(operand.value, bool)):
        raise _refuse(node, text, "a sign on something other than a number literal (UnaryOp)")
    _check_number(operand, text, operand.value)


def _check_call(node, text, depth, classes):
    """Accept ``Class(args, name=args)`` of a class in ``classes``: no ``*args``, no ``**kwargs``."""
    if not isinstance(node.func, ast.Name):
        raise _refuse(node.func, text, f"a call of {_describe_node(node.func)}")
    if node.func.id not in classes:
        raise _refuse(node.func, text, f"a call of {node.func.id!r} (Name)",
                      f"accepted: calls of {', '.join(sorted(classes))}, e.g. \"{EXAMPLE}\"")
    for argument in node.args:
        if isinstance(argument, ast.Starred):
            raise _refuse(argument, text, "*unpacking of arguments (Starred)")
        _check_value(argument, text, depth + 1, classes)
    for keyword in node.keywords:
        if keyword.arg is None:
            raise _refuse(keyword.value, text, "**unpacking of keyword arguments (keyword)")
        _check_value(keyword.value, text, depth + 1, classes)


def _check_value(node, text, depth, classes):
    """Check one node of the tree, ``depth`` levels of calls, lists and tuples deep (the top call is 1)."""
    if depth > MAX_DEPTH:
        raise _refuse(node, text, f"nesting deeper than {MAX_DEPTH} levels of calls, lists and tuples")
    if isinstance(node, ast.Constant):
        _check_constant(node, text)
    elif isinstance(node, ast.UnaryOp):
        _check_signed(node, text)
    elif isinstance(node, (ast.List, ast.Tuple)):
        if len(node.elts) > MAX_ITEMS:
            kind = type(node).__name__.lower()
            raise _refuse(node, text, f"a {kind} of {len(node.elts)} items (at most {MAX_ITEMS})")
        for item in node.elts:
            if isinstance(item, ast.Starred):
                raise _refuse(item, text, "*unpacking (Starred)")
            _check_value(item, text, depth + 1, classes)
    elif isinstance(node, ast.Call):
        _check_call(node, text, depth, classes)
    else:
        raise _refuse(node, text, _describe_node(node))


def _build(node, classes):
    """The value of a checked node: literals as themselves, calls as instances of their class."""
    if isinstance(node, ast.Constant):
        return node.value
    if isinstance(node, ast.UnaryOp):
        value = node.operand.value
        return -value if isinstance(node.op, ast.USub) else +value
    if isinstance(node, ast.List):
        return [_build(item, classes) for item in node.elts]
    if isinstance(node, ast.Tuple):
        return tuple(_build(item, classes) for item in node.elts)
    cls = classes[node.func.id]
    args = [_build(argument, classes) for argument in node.args]
    kwargs = {keyword.arg: _build(keyword.value, classes) for keyword in node.keywords}
    try:
        return cls(*args, **kwargs)
    except (TypeError, ValueError, ArithmeticError, OSError) as exc:
        raise ExpressionError(f"{node.func.id}(...) refused its arguments: {exc}") from None


def _check_top_level(body, text, classes):
    """Check the whole tree, and that its top is a call of a material class (not of a Fresnel factor)."""

    if not isinstance(body, ast.Call):
        raise _refuse(body, text, f"{_describe_node(body)} at the top level (a material is a call of its class)")
    _check_value(body, text, 1, classes)
    name = body.func.id
    if not issubclass(classes[name], Material):
        raise ExpressionError(f"refused a bare Fresnel factor {name}(...), which is not a material: give it as the "
                              f"fresnel= of a glossy model, e.g. \"CookTorrance(0.1, 0.3, fresnel={name}(...))\"")


def parse_material(text):
    """The material an expression such as ``"Phong(kd=0.2, ks=0.5, q=20)"`` describes, built without ``eval``.

    Accepted: one call of a glphong material class (a `glphong.materials.Material` subclass that
    ``glphong.materials.__all__`` exports: ``Phong``, ``BlinnPhong``, ``CookTorrance``, ``Lafortune``, ...)
    with positional and keyword arguments that are

    - int and float literals (finite; an int of at most `MAX_INT_DIGITS` digits), with at most one
      ``-`` or ``+`` sign; ``True``, ``False``, ``None``;
    - string literals of at most `MAX_STRING_LENGTH` characters (``form='1982'``);
    - tuples and lists of accepted values, of at most `MAX_ITEMS` items;
    - calls of Fresnel factors (``SchlickFresnel(f0)``, ``DielectricFresnel(ior)``, any exported
      `glphong.definitions.fresnel.Fresnel` subclass) and of material classes, with such arguments.

    Nothing else: no other names, attributes, subscripts, operators other than a sign, comprehensions,
    lambdas, assignment expressions, f-strings, ``*args`` or ``**kwargs``.  The text is at most
    `MAX_TEXT_LENGTH` characters, with at most `MAX_NODES` syntax nodes and `MAX_DEPTH` levels of
    calls, lists and tuples.

    Parameters
    ----------
    text : str
        The expression, e.g. ``"CookTorrance(0.1, 0.3, fresnel=SchlickFresnel((0.9, 0.6, 0.3)))"``.

    Returns
    -------
    glphong.materials.Material
        The material, built by calling the classes with the literal arguments.

    Raises
    ------
    ExpressionError
        (a ValueError) where the text is not such an expression, is out of bounds, is a bare Fresnel
        factor or any non-material, or where a class refuses its arguments (the class's own message).
    TypeError
        Where ``text`` is not a str.

    Examples
    --------
    >>> parse_material("Phong(kd=0.2, ks=0.5, q=20)")
    Phong(kd=0.2, ks=0.5, q=20)
    """

    tree, text = _parse(text)
    classes = material_classes()
    body = tree.body
    _check_top_level(body, text, classes)
    material = _build(body, classes)
    if not isinstance(material, Material):  # a class may build something else; refuse it all the same
        raise ExpressionError(f"refused {body.func.id}(...): it built a {type(material).__name__}, not a material; "
                              f"{_ACCEPTED}")
    return material
