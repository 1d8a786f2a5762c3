"""Code read on Z3 terms (docs/model.md §6): the engine with which an obligation's statement is
the code's own function run on symbols, never a hand-restated rule.

``run_on_terms`` evaluates a small pure function's body off its syntax tree (a subset: anything
else is refused, naming the line); ``module_on_terms`` gives a function's module globals where
numpy, ``float``, ``max`` and ``min`` work on terms, so the module's own bytecode runs on them;
``sqrt_free`` names the square roots such a run builds, with their meaning as hypotheses.
"""

from __future__ import annotations

import ast
import builtins
import functools
import inspect
import textwrap
import types
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import z3

from .. import spec
from ._z3vec import COS as _COS
from ._z3vec import SIN as _SIN
from ._z3vec import Hyp

__all__ = ["ExtractionError", "as_bool", "module_on_terms", "run_on_terms", "sqrt_free", "term"]


class ExtractionError(ValueError):
    """The code has a shape its reading on terms does not know (names the line)."""


def term(x: Any) -> z3.ArithRef:
    """x as a real term (a number made a numeral)."""
    return x if isinstance(x, z3.ExprRef) else z3.RealVal(x)


def is_sqrt(e: z3.ExprRef) -> bool:
    if not (z3.is_app_of(e, z3.Z3_OP_POWER) and e.num_args() == 2):
        return False
    k = e.arg(1)
    return z3.is_rational_value(k) and (k.numerator_as_long(), k.denominator_as_long()) == (1, 2)


def sqrt_free(terms: Sequence[z3.ExprRef]) -> tuple[list[z3.ExprRef], list[Hyp]]:
    """``terms`` with every square root x ** (1/2) (what ``hypot_of`` / ``sqrt_of`` build on
    terms) replaced by a real ``sqrt(x)``, and for each the hypothesis of its exact meaning,
    sqrt(x) >= 0 and sqrt(x)^2 = x (the code's square roots are of sums of squares, x >= 0)."""
    found: dict[int, tuple[z3.ExprRef, z3.ArithRef]] = {}
    order: list[int] = []

    def walk(e: z3.ExprRef) -> None:
        for k in range(e.num_args()):
            walk(e.arg(k))
        if is_sqrt(e) and e.get_id() not in found:
            found[e.get_id()] = (e, z3.Real("sqrt(" + " ".join(str(e.arg(0)).split()) + ")"))
            order.append(e.get_id())

    for t in terms:
        walk(t)
    pairs = [found[i] for i in order]
    # Innermost first (walk is post-order), so each root's own argument is already free of roots.
    hyps: list[Hyp] = []
    subst: list[tuple[z3.ExprRef, z3.ExprRef]] = []
    for e, s in pairs:
        arg = z3.substitute(e.arg(0), *subst) if subst else e.arg(0)
        hyps.append((f"{s} >= 0 and its square is its argument", z3.And(s >= 0, s * s == arg)))
        subst.append((e, s))
    out = [z3.substitute(t, *subst) if subst else t for t in terms]
    return out, hyps


# --- reading a small pure function off its syntax tree ------------------------------------------

class _Return(Exception):
    """A ``return`` reached on the path being read (carries the value)."""

    def __init__(self, value: Any) -> None:
        super().__init__()
        self.value = value


def _is_term(x: Any) -> bool:
    return isinstance(x, z3.ExprRef)


def as_bool(x: Any, line: int | str) -> z3.BoolRef:
    if isinstance(x, z3.BoolRef):
        return x
    if isinstance(x, bool):
        return z3.BoolVal(x)
    raise ExtractionError(f"line {line}: {x!r} is not a Boolean")


def _max_terms(*args: Any) -> Any:
    """Python's ``max`` of arguments (or of one iterable), folded with ``spec.max_of``: the
    same value on floats, an If on terms."""
    items = list(args[0]) if len(args) == 1 else list(args)
    return functools.reduce(spec.max_of, items)


def _min_terms(*args: Any) -> Any:
    items = list(args[0]) if len(args) == 1 else list(args)
    return functools.reduce(spec.min_of, items)


#: Builtins a read function may call, as they run on terms.
_BUILTINS = {"max": _max_terms, "min": _min_terms}


@functools.lru_cache(maxsize=256)
def _dedented_source(fn: Callable[..., Any]) -> str:
    """``fn``'s source, dedented, read once a process (each reading re-tokenises its file; the
    same few functions are read on terms hundreds of times in a prove)."""
    return textwrap.dedent(inspect.getsource(fn))


class _Reader:
    """Evaluates one function's body on the given arguments: the subset ``heights_overlap`` and
    ``height_gap`` are written in (a docstring, ``if``/``else`` whose branches return, ``return``;
    names, constants, tuples, constant subscripts, comparisons including ``is``/``is not``,
    ``and``/``or``/``not``, ``+``/``-``/``*``/``/``, calls of the module's names and ``max``/``min``).
    A condition on terms joins both branches by If; ``and``/``or`` on terms is And/Or; anything
    else is refused, naming the line."""

    def __init__(self, fn: Callable[..., Any], args: tuple[Any, ...]) -> None:
        src = _dedented_source(fn)
        tree = ast.parse(src)
        node = tree.body[0]
        if not isinstance(node, ast.FunctionDef) or node.decorator_list:
            raise ExtractionError(f"{fn.__name__} is not a plain function")
        params = [a.arg for a in node.args.args]
        if len(params) != len(args) or node.args.vararg or node.args.kwarg:
            raise ExtractionError(f"{fn.__name__} takes {params}, read with {len(args)} arguments")
        self.fn = fn
        self.node = node
        self.env: dict[str, Any] = dict(zip(params, args))

    def run(self) -> Any:
        try:
            self._block(self.node.body)
        except _Return as r:
            return r.value
        raise ExtractionError(f"{self.fn.__name__}: no return reached")

    # statements
    def _block(self, body: list[ast.stmt]) -> None:
        for i, st in enumerate(body):
            if i == 0 and isinstance(st, ast.Expr) and isinstance(st.value, ast.Constant) \
                    and isinstance(st.value.value, str):
                continue                                        # the docstring
            if isinstance(st, ast.Return):
                if st.value is None:
                    raise ExtractionError(f"line {st.lineno}: a bare return")
                raise _Return(self._expr(st.value))
            if isinstance(st, ast.If):
                cond = self._expr(st.test)
                if not _is_term(cond):
                    self._block(st.body if cond else st.orelse)
                    continue
                then = self._branch(st.body)
                rest = self._branch(st.orelse if st.orelse else body[i + 1:])
                raise _Return(spec.if_then(as_bool(cond, st.lineno), then, rest))
            raise ExtractionError(f"line {st.lineno}: {type(st).__name__} is outside the subset")

    def _branch(self, body: list[ast.stmt]) -> Any:
        try:
            self._block(body)
        except _Return as r:
            return r.value
        raise ExtractionError(f"line {self.node.lineno}: a branch on terms that does not return")

    # expressions
    def _name(self, node: ast.Name) -> Any:
        if node.id in self.env:
            return self.env[node.id]
        if node.id in self.fn.__globals__:
            return self.fn.__globals__[node.id]
        if node.id in _BUILTINS:
            return _BUILTINS[node.id]
        if node.id in ("None", "True", "False"):
            return getattr(builtins, node.id)
        raise ExtractionError(f"line {node.lineno}: the name {node.id!r} is outside the subset")

    def _expr(self, node: ast.expr) -> Any:
        line = getattr(node, "lineno", "?")
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.Name):
            return self._name(node)
        if isinstance(node, ast.Tuple):
            return tuple(self._expr(e) for e in node.elts)
        if isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant) \
                and isinstance(node.slice.value, int):
            return self._expr(node.value)[node.slice.value]
        if isinstance(node, ast.Compare):
            out = []
            left = self._expr(node.left)
            for op, right_node in zip(node.ops, node.comparators):
                right = self._expr(right_node)
                out.append(self._compare(op, left, right, line))
                left = right
            if len(out) == 1:
                return out[0]
            if any(_is_term(x) for x in out):
                return z3.And(*[as_bool(x, line) for x in out])
            return all(out)
        if isinstance(node, ast.BoolOp):
            return self._boolop(node, line)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
            x = self._expr(node.operand)
            return z3.Not(x) if _is_term(x) else not x
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            return -self._expr(node.operand)
        if isinstance(node, ast.BinOp) and type(node.op) in _ARITH:
            return _ARITH[type(node.op)](self._expr(node.left), self._expr(node.right))
        if isinstance(node, ast.Call) and not node.keywords:
            f = self._expr(node.func)
            return f(*[self._expr(a) for a in node.args])
        raise ExtractionError(f"line {line}: {ast.dump(node)[:80]} is outside the subset")

    @staticmethod
    def _compare(op: ast.cmpop, x: Any, y: Any, line: Any) -> Any:
        if isinstance(op, ast.Is):
            if _is_term(x) or _is_term(y):
                return False                   # a term is never None
            return x is y
        if isinstance(op, ast.IsNot):
            if _is_term(x) or _is_term(y):
                return True
            return x is not y
        ops: dict[type, Callable[[Any, Any], Any]] = {
            ast.Lt: lambda a, b: a < b, ast.LtE: lambda a, b: a <= b,
            ast.Gt: lambda a, b: a > b, ast.GtE: lambda a, b: a >= b,
            ast.Eq: lambda a, b: a == b, ast.NotEq: lambda a, b: a != b}
        if type(op) not in ops:
            raise ExtractionError(f"line {line}: the comparison {type(op).__name__} is outside "
                                  "the subset")
        return ops[type(op)](x, y)

    def _boolop(self, node: ast.BoolOp, line: Any) -> Any:
        """Python's short circuit while the values are concrete; And/Or of the rest once a
        term appears (the operands must then be Booleans)."""
        is_and = isinstance(node.op, ast.And)
        terms: list[z3.BoolRef] = []
        value: Any = None
        for v in node.values:
            value = self._expr(v)
            if _is_term(value):
                terms.append(as_bool(value, line))
                continue
            if terms:
                terms.append(as_bool(value, line))
                continue
            if (not value) if is_and else value:
                return value                  # the short circuit, before any term
        if not terms:
            return value
        return z3.And(*terms) if is_and else z3.Or(*terms)


_ARITH: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b, ast.Div: lambda a, b: a / b}


def run_on_terms(fn: Callable[..., Any], *args: Any) -> Any:
    """``fn``'s own body, read off its syntax tree, evaluated on ``args`` (Z3 terms or Python
    values): what it returns, a term where the arguments are terms (``_Reader``'s subset)."""
    return _Reader(fn, args).run()



# --- a module's own code, run on terms ----------------------------------------------------------

def _ident(x: Any) -> Any:
    return x


def _each(f: Callable[[Any], Any]) -> Callable[[Any], Any]:
    return lambda a: np.vectorize(f, otypes=[object])(np.asarray(a, dtype=object))


class _Numpy:
    """numpy, for code run on terms: cos and sin are the proofs' uninterpreted Cos and Sin
    (ledger A3), elementwise on object arrays; ``asarray(..., dtype=float)`` keeps the terms (an
    object array); ``hypot`` is spec.hypot_of (an exact root); the rest is numpy's own."""

    cos = staticmethod(_each(lambda t: _COS(t)))
    sin = staticmethod(_each(lambda t: _SIN(t)))
    hypot = staticmethod(spec.hypot_of)

    @staticmethod
    def asarray(a: Any, dtype: Any = None) -> Any:
        return np.asarray(a, dtype=object if dtype in (float, _ident) else dtype)

    def __getattr__(self, name: str) -> Any:
        return getattr(np, name)


def module_on_terms(fn: Callable[..., Any], **names: Any) -> dict[str, Any]:
    """The globals of ``fn``'s module, copied, where numpy is ``_Numpy``, ``float`` the identity,
    ``max``/``min`` fold with spec.max_of/min_of, ``names`` replace what they name (another
    module's functions read so), and every function of the module is rebound to the copy: the
    module's own bytecode, calling itself, on terms."""
    g = dict(fn.__globals__)
    mod = g["__name__"]
    g.update(np=_Numpy(), float=_ident, max=_max_terms, min=_min_terms, **names)
    for key, val in list(g.items()):
        if isinstance(val, types.FunctionType) and val.__module__ == mod and key not in names:
            g[key] = types.FunctionType(val.__code__, g, val.__name__, val.__defaults__,
                                        val.__closure__)
    return g
