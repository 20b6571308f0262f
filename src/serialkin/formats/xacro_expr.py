"""The expressions of xacro files, evaluated as data: a small evaluator over Python's ``ast``.

xacro's ``${...}`` and ``$(eval ...)`` are Python expressions, and the ROS processor
evaluates them with Python's ``eval`` behind a filter of names: a crafted file can still
reach Python's builtins (a ``lambda`` or a walk over subclasses), run code or read any
file. A robot file is data. :func:`evaluate` accepts only what robot descriptions use:

* literals: numbers, strings, ``True``/``False``/``None``, lists and tuples of them;
* names: the file's properties and arguments (looked up by the caller), then the
  constants of :data:`CONSTANTS` (``pi``, ``e``, ``tau``, ``inf``, lower-case
  ``true``/``false``);
* arithmetic ``+ - * / // % **``, comparisons (also ``in``), ``and``/``or``/``not``,
  conditional expressions ``a if c else b``;
* calls of the functions of :data:`FUNCTIONS` only (``sin``, ``cos``, ``radians``,
  ``sqrt``, ``abs``, ``min``, ``max``, ...), also written ``math.NAME``, with
  positional arguments;
* items of a property's lists and mappings (``${p['key']}``, ``${p[0]}``, and
  ``${p.key}`` for a mapping loaded from YAML), never attributes of Python objects.

Everything else (attribute access, calls of anything else, ``lambda``, comprehensions,
f-strings, walrus, starred arguments, keyword arguments) raises
:class:`XacroExpressionError` naming the expression and what is refused. The work is
bounded: an expression of at most :data:`MAX_LENGTH` characters and :data:`MAX_NODES`
syntax nodes, integers of at most :data:`MAX_INT_BITS` bits, strings and lists of at
most :data:`MAX_ITEMS` items; beyond that :class:`~serialkin.errors.BudgetError`.
"""

from __future__ import annotations

import ast
import math
import operator
import warnings
from collections.abc import Callable, Mapping

from serialkin._checks import short_repr
from serialkin.errors import BudgetError, RobotDefinitionError

__all__ = ["CONSTANTS", "FUNCTIONS", "XacroExpressionError", "evaluate"]

#: Longest expression evaluated [characters].
MAX_LENGTH = 10_000
#: Most syntax nodes in one expression.
MAX_NODES = 2_000
#: Largest integer an expression may produce [bits] (``9**9**9**9`` would not end).
MAX_INT_BITS = 4_096
#: Longest string, list or tuple an expression may produce [items].
MAX_ITEMS = 1_000_000


class XacroExpressionError(RobotDefinitionError):
    """A xacro expression uses something other than data and arithmetic, or is malformed."""


def _pow(base, exp):
    """``base ** exp``, refusing an integer power beyond :data:`MAX_INT_BITS` before computing."""
    if isinstance(base, int) and isinstance(exp, int) and exp > 0 and abs(base) > 1:
        bits = exp * math.log2(abs(base))
        if bits > MAX_INT_BITS:
            raise BudgetError(f"the integer power {short_repr(base)} ** {short_repr(exp)} "
                              f"would have about {bits:.3g} bits, more than the "
                              f"{MAX_INT_BITS} an expression may produce")
    return base ** exp


#: The functions an expression may call (also as ``math.NAME``).
FUNCTIONS: dict[str, Callable] = {
    **{name: getattr(math, name) for name in (
        "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh",
        "asinh", "acosh", "atanh", "sqrt", "exp", "log", "log10", "log2", "radians",
        "degrees", "floor", "ceil", "fabs", "hypot", "copysign", "fmod", "trunc",
        "isclose", "isfinite", "isinf", "isnan")},
    "pow": _pow, "abs": abs, "min": min, "max": max, "round": round, "int": int,
    "float": float, "str": str, "bool": bool, "len": len,
}
#: The names an expression may use besides the file's properties and arguments.
CONSTANTS: dict[str, object] = {
    "pi": math.pi, "e": math.e, "tau": math.tau, "inf": math.inf,
    "true": True, "false": False, "True": True, "False": False, "None": None,
}

_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
           ast.Div: operator.truediv, ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod,
           ast.Pow: _pow}
_COMPARE = {ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt,
            ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge,
            ast.In: lambda a, b: a in b, ast.NotIn: lambda a, b: a not in b}
_UNARY = {ast.UAdd: operator.pos, ast.USub: operator.neg, ast.Not: operator.not_}
#: The namespaces xacro files write functions under (``math.pi``, ``python.min``).
_NAMESPACES = ("math", "python")


def _is_data(value: object, depth: int = 0) -> bool:
    """Whether ``value`` is plain data: numbers, strings, None, lists/tuples/mappings of them."""
    if value is None or isinstance(value, bool | int | float | str):
        return True
    if depth > 20:
        return False
    if isinstance(value, list | tuple):
        return all(_is_data(v, depth + 1) for v in value)
    if isinstance(value, Mapping):
        return all(isinstance(k, str | int) and _is_data(v, depth + 1)
                   for k, v in value.items())
    return False


def _sized(value: object) -> object:
    """``value``, or BudgetError when it is an integer, string or sequence too large."""
    if isinstance(value, int) and not isinstance(value, bool) \
            and value.bit_length() > MAX_INT_BITS:
        raise BudgetError(f"an integer of {value.bit_length()} bits, more than the "
                          f"{MAX_INT_BITS} an expression may produce")
    if isinstance(value, str | list | tuple) and len(value) > MAX_ITEMS:
        raise BudgetError(f"a {type(value).__name__} of {len(value)} items, more than the "
                          f"{MAX_ITEMS} an expression may produce")
    return value


def _binary(op: ast.operator, a: object, b: object) -> object:
    """``a op b`` with the sizes of a repetition and of a power checked before computing."""
    if isinstance(op, ast.Mult):
        for seq, k in ((a, b), (b, a)):
            if isinstance(seq, str | list | tuple) and isinstance(k, int) \
                    and len(seq) * max(k, 0) > MAX_ITEMS:
                raise BudgetError(f"repeating a {type(seq).__name__} of {len(seq)} items "
                                  f"{k} times, more than the {MAX_ITEMS} items an "
                                  "expression may produce")
    return _sized(_BINARY[type(op)](a, b))


class _Evaluator:
    """Evaluates one parsed expression; ``lookup(name)`` gives properties (KeyError: none)."""

    def __init__(self, lookup: Callable[[str], object],
                 functions: Mapping[str, Callable]) -> None:
        self.lookup = lookup
        self.functions = functions

    def refuse(self, node: ast.AST, what: str) -> XacroExpressionError:
        return XacroExpressionError(f"{what} is not allowed in a xacro expression "
                                    f"(at {short_repr(ast.unparse(node), 80)})")

    def value(self, node: ast.AST) -> object:  # noqa: C901, PLR0911, PLR0912 (one case per node type)
        if isinstance(node, ast.Constant):
            if not _is_data(node.value):
                raise self.refuse(node, f"a constant of type {type(node.value).__name__}")
            return node.value
        if isinstance(node, ast.Name):
            return self.name(node)
        if isinstance(node, ast.BinOp):
            if type(node.op) not in _BINARY:
                raise self.refuse(node, f"the operator {type(node.op).__name__}")
            return _binary(node.op, self.value(node.left), self.value(node.right))
        if isinstance(node, ast.UnaryOp):
            if type(node.op) not in _UNARY:
                raise self.refuse(node, f"the operator {type(node.op).__name__}")
            return _UNARY[type(node.op)](self.value(node.operand))
        if isinstance(node, ast.BoolOp):
            result = None
            for item in node.values:  # short-circuit, as Python
                result = self.value(item)
                if isinstance(node.op, ast.And) and not result:
                    return result
                if isinstance(node.op, ast.Or) and result:
                    return result
            return result
        if isinstance(node, ast.Compare):
            left = self.value(node.left)
            for op, right_node in zip(node.ops, node.comparators, strict=True):
                if type(op) not in _COMPARE:
                    raise self.refuse(node, f"the comparison {type(op).__name__}")
                right = self.value(right_node)
                if not _COMPARE[type(op)](left, right):
                    return False
                left = right
            return True
        if isinstance(node, ast.IfExp):
            return self.value(node.body if self.value(node.test) else node.orelse)
        if isinstance(node, ast.List | ast.Tuple):
            items = [self.value(e) for e in node.elts]
            return _sized(items if isinstance(node, ast.List) else tuple(items))
        if isinstance(node, ast.Subscript):
            return self.item(node)
        if isinstance(node, ast.Attribute):
            return self.attribute(node)
        if isinstance(node, ast.Call):
            return self.call(node)
        raise self.refuse(node, {
            ast.Lambda: "lambda", ast.ListComp: "a comprehension", ast.SetComp: "a comprehension",
            ast.DictComp: "a comprehension", ast.GeneratorExp: "a generator",
            ast.JoinedStr: "an f-string", ast.NamedExpr: "an assignment expression",
            ast.Starred: "unpacking", ast.Dict: "a dict display", ast.Set: "a set display",
        }.get(type(node), f"{type(node).__name__}"))

    def name(self, node: ast.Name) -> object:
        try:
            value = self.lookup(node.id)
        except KeyError:
            if node.id in CONSTANTS:
                return CONSTANTS[node.id]
            if node.id in self.functions:
                raise self.refuse(node, f"the function {node.id!r} used as a value") from None
            raise XacroExpressionError(f"unknown name {short_repr(node.id, 60)} (not a "
                                       "property, argument or constant of xacro)") from None
        if not _is_data(value):
            if node.id in CONSTANTS:  # a xacro global (True, pi) rather than a property
                return CONSTANTS[node.id]
            raise self.refuse(node, f"the name {node.id!r} (a {type(value).__name__}, not "
                                    "data)")
        return value

    def item(self, node: ast.Subscript) -> object:
        if isinstance(node.slice, ast.Slice):
            container = self.value(node.value)
            lo, hi, step = (None if s is None else self.value(s)
                            for s in (node.slice.lower, node.slice.upper, node.slice.step))
            if not isinstance(container, str | list | tuple):
                raise self.refuse(node, "slicing something other than a string or list")
            return container[lo:hi:step]
        container = self.value(node.value)
        key = self.value(node.slice)
        if not isinstance(container, str | list | tuple | Mapping):
            raise self.refuse(node, f"an item of a {type(container).__name__}")
        try:
            return container[key]
        except (KeyError, IndexError, TypeError) as exc:
            raise XacroExpressionError(f"no item {short_repr(key, 60)} in "
                                       f"{short_repr(ast.unparse(node.value), 60)}: "
                                       f"{type(exc).__name__}") from None

    def attribute(self, node: ast.Attribute) -> object:
        if isinstance(node.value, ast.Name) and node.value.id in _NAMESPACES:
            if node.attr in CONSTANTS:
                return CONSTANTS[node.attr]
            raise self.refuse(node, f"{node.value.id}.{node.attr} used as a value")
        container = self.value(node.value)
        if isinstance(container, Mapping) and node.attr in container:  # YAML: ${cfg.key}
            return container[node.attr]
        raise self.refuse(node, "attribute access")

    def call(self, node: ast.Call) -> object:
        func = node.func
        if isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name) \
                and func.value.id in (*_NAMESPACES, "xacro"):
            name = func.attr
        elif isinstance(func, ast.Name):
            name = func.id
        elif isinstance(func, ast.Lambda):
            raise self.refuse(node, "lambda")
        else:
            raise self.refuse(node, "calling anything but a function of the table")
        if name not in self.functions:
            raise self.refuse(node, f"calling {short_repr(name, 40)} (allowed: "
                                    f"{', '.join(sorted(self.functions))})")
        if node.keywords or any(isinstance(a, ast.Starred) for a in node.args):
            raise self.refuse(node, "a keyword or unpacked argument")
        args = [self.value(a) for a in node.args]
        try:
            result = self.functions[name](*args)
        except (BudgetError, XacroExpressionError):
            raise
        except Exception as exc:  # a math domain error, a bad argument type
            raise XacroExpressionError(f"{name}({', '.join(short_repr(a, 30) for a in args)})"
                                       f" failed: {exc}") from None
        if not _is_data(result):
            raise self.refuse(node, f"{name}() returning a {type(result).__name__}")
        return _sized(result)


def evaluate(expression: str, lookup: Callable[[str], object], *,
             functions: Mapping[str, Callable] | None = None) -> object:
    """The value of one xacro expression (the text inside ``${...}`` or ``$(eval ...)``).

    Args:
        expression: the expression's text.
        lookup: ``lookup(name)`` returns the value of a property or argument, or raises
            KeyError when there is none (then :data:`CONSTANTS` is asked).
        functions: the callable functions (default :data:`FUNCTIONS`; the xacro reader adds
            ``find``, ``arg`` and ``load_yaml`` bound to the folders the user allowed).

    Returns:
        a number, string, bool, None, or a list / tuple / mapping of those.

    Raises:
        XacroExpressionError: a syntax error or anything not listed in the module
            docstring (the message names the refused part).
        BudgetError: an expression, an integer, string or list beyond the limits above.
    """
    if not isinstance(expression, str):
        raise XacroExpressionError(f"a xacro expression must be text, got "
                                   f"{type(expression).__name__}")
    text = expression.strip()
    if len(text) > MAX_LENGTH:
        raise BudgetError(f"a xacro expression of {len(text)} characters, more than the "
                          f"{MAX_LENGTH} allowed")
    try:
        with warnings.catch_warnings():  # "invalid escape sequence": the text is data
            warnings.simplefilter("ignore")
            tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        raise XacroExpressionError(f"not a valid expression: {short_repr(text, 80)} "
                                   f"({exc.msg})") from None
    nodes = sum(1 for _ in ast.walk(tree))
    if nodes > MAX_NODES:
        raise BudgetError(f"a xacro expression of {nodes} syntax nodes, more than the "
                          f"{MAX_NODES} allowed")
    try:
        return _Evaluator(lookup, FUNCTIONS if functions is None else functions).value(
            tree.body)
    except (XacroExpressionError, BudgetError):
        raise
    except RecursionError:
        raise BudgetError("a xacro expression nested too deeply") from None
    except (ArithmeticError, TypeError, ValueError) as exc:  # 1/0, 'a' - 1, ...
        raise XacroExpressionError(f"{short_repr(text, 80)}: {type(exc).__name__}: "
                                   f"{exc}") from None
