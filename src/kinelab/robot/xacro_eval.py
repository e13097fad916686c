"""The expression evaluator for ``${...}`` in an untrusted xacro file: data in, data out, no object access.

xacro evaluates an expression with Python's ``eval`` over its symbol table, which hands every file ``python.type``,
``python.vars`` and the objects behind them: from there a file reaches the interpreter. This evaluator walks the
expression's syntax tree itself and knows only data — numbers, strings, booleans, ``None`` and lists, tuples and
dicts of them — and the names a file defines (properties, macro parameters, the properties of an included file's
namespace). It calls only a fixed list of functions (:data:`FUNCTIONS`: the math module's plain functions and a
few conversions), reads no attribute but ``math.NAME`` and a namespace's properties, and bounds what an expression
may build: integers of at most :data:`MAX_INT_BITS` bits, strings and containers of at most :data:`MAX_ITEMS`
items. A :class:`Budget` bounds the time and the number of elements of a whole expansion.
"""

from __future__ import annotations

import ast
import math
import operator
import re
import time
from collections.abc import Callable
from typing import Any

MAX_INT_BITS = 4096  # an integer result larger than this (about 1,233 digits) is refused
MAX_ITEMS = 1_000_000  # characters of a string, or items of a container counted through its nesting
_MATH = ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "asinh", "acosh", "atanh",
         "sqrt", "exp", "log", "log10", "log2", "pow", "fabs", "floor", "ceil", "trunc", "fmod", "hypot", "degrees",
         "radians", "copysign", "isclose", "isfinite", "isinf", "isnan")
FUNCTIONS: dict[str, Callable[..., Any]] = {
    **{name: getattr(math, name) for name in _MATH},
    "abs": abs, "min": min, "max": max, "round": round, "int": int, "float": float, "str": str, "bool": bool,
    "len": len, "list": list, "tuple": tuple, "sorted": sorted, "sum": sum, "all": all, "any": any,
}
"""The functions an untrusted expression may call, directly or as ``math.NAME``."""
CONSTANTS: dict[str, Any] = {"pi": math.pi, "e": math.e, "tau": math.tau, "inf": math.inf, "nan": math.nan,
                             "True": True, "False": False, "None": None}
_WIDE_FORMAT = re.compile(r"%[-+ #0]*(\*|\d{4,})|%[-+ #0]*\d*\.(\*|\d{4,})")
_BINARY: dict[type[ast.operator], Callable[[Any, Any], Any]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
    ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod, ast.Pow: operator.pow, ast.BitAnd: operator.and_,
    ast.BitOr: operator.or_, ast.BitXor: operator.xor,
}
_UNARY: dict[type[ast.unaryop], Callable[[Any], Any]] = {
    ast.USub: operator.neg, ast.UAdd: operator.pos, ast.Not: operator.not_, ast.Invert: operator.invert,
}
_COMPARE: dict[type[ast.cmpop], Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt,
    ast.GtE: operator.ge, ast.In: lambda a, b: a in b, ast.NotIn: lambda a, b: a not in b,
    ast.Is: operator.is_, ast.IsNot: operator.is_not,
}


class RefusedError(Exception):
    """An expression uses what an untrusted file may not (``construct`` names it)."""

    def __init__(self, construct: str, too_large: bool = False):
        super().__init__(construct)
        self.construct = construct
        self.too_large = too_large  # a size limit passed, not a forbidden construct


class LimitError(Exception):
    """An expansion went past its time or size limit (the message says which)."""


class Budget:
    """The time and element limits of one expansion.

    Args:
        seconds: wall time the whole expansion may take [s].
        elements: elements it may process (each macro body it instantiates counted again).
    """

    def __init__(self, seconds: float, elements: int):
        self.deadline = time.monotonic() + seconds
        self.seconds, self.elements, self.left = seconds, elements, elements

    def tick(self) -> None:
        """Count one element (or one expression); raise LimitError past either limit."""
        self.left -= 1
        if self.left < 0:
            raise LimitError(f"it expands to more than {self.elements} elements")
        if time.monotonic() > self.deadline:
            raise LimitError(f"its expansion took more than {self.seconds:g} s")


class Namespace:
    """A namespace of properties (an include's ``ns=``): ``ns.name`` reads its property ``name``."""

    def __init__(self, lookup: Callable[[str], Any]):
        self.lookup = lookup


def evaluate(expr: str, lookup: Callable[[str], Any]) -> Any:
    """The value of ``expr`` with names read through ``lookup`` (data, a :class:`Namespace`, or KeyError).

    Raises:
        RefusedError: a construct an untrusted file may not use.
        NameError: a name nothing defines. SyntaxError, ArithmeticError, ValueError, TypeError: as Python's.
    """
    tree = ast.parse(expr.strip(), mode="eval")
    _check_statically(tree)
    return _Evaluator(lookup).value(tree.body)


_STATIC_NAMES = ("python", "xacro", "__builtins__")  # xacro's namespaces of Python objects


def _check_statically(tree: ast.Expression) -> None:
    """Refuse object access anywhere in the expression, evaluated or not (a branch a condition skips included):
    xacro's Python namespaces, underscore attributes, and nodes the evaluator has no rule for."""
    for node in ast.walk(tree.body):
        if isinstance(node, ast.Name) and (node.id in _STATIC_NAMES or node.id.startswith("__")):
            raise RefusedError(f"the name {node.id!r}")
        if isinstance(node, ast.Attribute) and node.attr.startswith("_"):
            raise RefusedError(f"attribute access ('.{node.attr}')")
        if not isinstance(node, _ALLOWED_NODES):
            raise RefusedError(_described(node))


def size(value: object, limit: int = MAX_ITEMS) -> int:
    """Items in ``value``: a string's characters, a container's items through its nesting (1 for a scalar);
    stops counting past ``limit``."""
    if isinstance(value, str):
        return len(value)
    if isinstance(value, dict):
        value = [*value.keys(), *value.values()]
    if not isinstance(value, list | tuple):
        return 1
    total = len(value)
    for item in value:
        total += size(item, limit) - 1 if isinstance(item, str | list | tuple | dict) else 0
        if total > limit:
            break
    return total


def checked(value: object) -> Any:
    """``value`` when it is data within the bounds; RefusedError otherwise."""
    if value is None or isinstance(value, bool | float | str | Namespace):
        pass
    elif isinstance(value, int):
        if value.bit_length() > MAX_INT_BITS:
            raise RefusedError(f"an integer of more than {MAX_INT_BITS} bits", too_large=True)
    elif isinstance(value, list | tuple | dict):
        items = value.items() if isinstance(value, dict) else enumerate(value)
        for key, item in items:
            checked(key)
            checked(item)
    else:
        raise RefusedError(f"a value of type {type(value).__name__} (only numbers, strings and lists of them)")
    if size(value) > MAX_ITEMS:
        raise RefusedError(f"a string or list of more than {MAX_ITEMS} items", too_large=True)
    return value


class _Evaluator:
    def __init__(self, lookup: Callable[[str], Any]):
        self.lookup = lookup

    def value(self, node: ast.AST) -> Any:
        handler = getattr(self, f"_{type(node).__name__}", None)
        if handler is None:
            raise RefusedError(f"{_described(node)}")
        return checked(handler(node))

    def _Constant(self, node: ast.Constant) -> Any:
        if isinstance(node.value, complex | bytes) or node.value is Ellipsis:
            raise RefusedError(f"the literal {node.value!r}")
        return node.value

    def _Name(self, node: ast.Name) -> Any:
        try:
            return self.lookup(node.id)
        except KeyError:
            pass
        if node.id in CONSTANTS:
            return CONSTANTS[node.id]
        if node.id in FUNCTIONS or node.id == "math":
            raise RefusedError(f"{node.id!r} other than in a call")
        raise NameError(f"name {node.id!r} is not defined")

    def _Attribute(self, node: ast.Attribute) -> Any:
        if isinstance(node.value, ast.Name) and node.value.id == "math" and node.attr in CONSTANTS:
            return CONSTANTS[node.attr]
        base = self.value(node.value) if not node.attr.startswith("_") else None
        if isinstance(base, Namespace):
            return base.lookup(node.attr)
        raise RefusedError(f"attribute access ('.{node.attr}')")

    def _BinOp(self, node: ast.BinOp) -> Any:
        op = _BINARY.get(type(node.op))
        if op is None:
            raise RefusedError(f"the operator {type(node.op).__name__}")
        left, right = self.value(node.left), self.value(node.right)
        _check_operands(node.op, left, right)
        return op(left, right)

    def _UnaryOp(self, node: ast.UnaryOp) -> Any:
        return _UNARY[type(node.op)](self.value(node.operand))

    def _BoolOp(self, node: ast.BoolOp) -> Any:
        result = None
        for operand in node.values:
            result = self.value(operand)
            if bool(result) == isinstance(node.op, ast.Or):
                return result
        return result

    def _Compare(self, node: ast.Compare) -> Any:
        left = self.value(node.left)
        for op, right_node in zip(node.ops, node.comparators, strict=True):
            right = self.value(right_node)
            if not _COMPARE[type(op)](left, right):
                return False
            left = right
        return True

    def _IfExp(self, node: ast.IfExp) -> Any:
        return self.value(node.body) if self.value(node.test) else self.value(node.orelse)

    def _Call(self, node: ast.Call) -> Any:
        name = _function_name(node.func)
        if name is None and isinstance(node.func, ast.Attribute) and not isinstance(node.func.value, ast.Name):
            raise RefusedError(f"attribute access ('.{node.func.attr}')")  # a method of a value: 'a'.upper()
        if name is None:
            raise RefusedError(f"a call of {_described(node.func)}")
        if node.keywords or any(isinstance(a, ast.Starred) for a in node.args):
            raise RefusedError(f"keyword or starred arguments in a call of {name}")
        return FUNCTIONS[name](*(self.value(a) for a in node.args))

    def _Subscript(self, node: ast.Subscript) -> Any:
        container = self.value(node.value)
        if not isinstance(container, list | tuple | str | dict):
            raise RefusedError("an index into something other than a string, list or dict")
        key = self.value(node.slice)
        return container[key]

    def _Slice(self, node: ast.Slice) -> slice:
        parts = (None if p is None else self.value(p) for p in (node.lower, node.upper, node.step))
        return slice(*parts)

    def _List(self, node: ast.List) -> list[Any]:
        return [self.value(e) for e in node.elts]

    def _Tuple(self, node: ast.Tuple) -> tuple[Any, ...]:
        return tuple(self.value(e) for e in node.elts)

    def _Dict(self, node: ast.Dict) -> dict[Any, Any]:
        if any(k is None for k in node.keys):
            raise RefusedError("'**' in a dict")
        return {self.value(k): self.value(v) for k, v in zip(node.keys, node.values, strict=True) if k is not None}


_ALLOWED_NODES = (ast.Constant, ast.Name, ast.Attribute, ast.BinOp, ast.UnaryOp, ast.BoolOp, ast.Compare, ast.IfExp,
                  ast.Call, ast.Subscript, ast.Slice, ast.List, ast.Tuple, ast.Dict, ast.Load, ast.operator,
                  ast.unaryop, ast.boolop, ast.cmpop, ast.Starred, ast.keyword)  # the last two refused by _Call


def _function_name(func: ast.expr) -> str | None:
    """The FUNCTIONS entry a call names (``f`` or ``math.f``), or None."""
    if isinstance(func, ast.Name) and func.id in FUNCTIONS:
        return func.id
    if (isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name) and func.value.id == "math"
            and func.attr in _MATH):
        return func.attr
    return None


def _check_operands(op: ast.operator, left: Any, right: Any) -> None:
    """Refuse an operation whose result would outgrow the bounds before Python builds it."""
    check = _OPERAND_CHECKS.get(type(op))
    if check is not None:
        check(left, right)


def _check_power(left: Any, right: Any) -> None:
    if _is_int(left) and _is_int(right) and right > 0 and abs(left) > 1 and left.bit_length() * right > MAX_INT_BITS:
        raise RefusedError(f"a power of more than {MAX_INT_BITS} bits", too_large=True)


def _check_repetition(left: Any, right: Any) -> None:
    for seq, count in ((left, right), (right, left)):
        if isinstance(seq, str | list | tuple) and _is_int(count) and size(seq) * max(count, 0) > MAX_ITEMS:
            raise RefusedError(f"a repetition of more than {MAX_ITEMS} items", too_large=True)


def _check_format(left: Any, _right: Any) -> None:
    if isinstance(left, str) and _WIDE_FORMAT.search(left):
        raise RefusedError("a '%' format wider than 999 characters", too_large=True)


def _check_concatenation(left: Any, right: Any) -> None:
    if isinstance(left, str | list | tuple) and size(left) + size(right) > MAX_ITEMS:
        raise RefusedError(f"a string or list of more than {MAX_ITEMS} items", too_large=True)


_OPERAND_CHECKS: dict[type[ast.operator], Callable[[Any, Any], None]] = {
    ast.Pow: _check_power, ast.Mult: _check_repetition, ast.Mod: _check_format, ast.Add: _check_concatenation,
}


def _is_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _described(node: ast.AST) -> str:
    """How a refusal names a construct: its source text where it is short."""
    kinds = {"Lambda": "a lambda", "ListComp": "a comprehension", "SetComp": "a comprehension",
             "DictComp": "a comprehension", "GeneratorExp": "a generator", "JoinedStr": "an f-string",
             "NamedExpr": "':='", "Set": "a set", "Starred": "'*'", "Await": "await", "Yield": "yield"}
    kind = kinds.get(type(node).__name__)
    if kind is not None:
        return kind
    text = ast.unparse(node)
    return repr(text) if len(text) <= 40 else type(node).__name__
