"""The spec's own numpy code run on Z3 terms, over every path of its branches (docs/model.md §6.2).

Some of what a verdict uses is chosen by index arithmetic in numpy code: which path segment's
speed the certificate takes for a time piece (``spec._certificate._Motion.lipschitz``), which
trajectory pieces the monitor takes the largest speed over for a gap
(``spec.ReferenceSpeeds.over``). The proofs read that code itself: its function object is run
with the module's ``np`` replaced by ``SymNumpy``, a stand-in that computes on Z3 terms, on
inputs whose sizes, indices and values are symbols. Nothing is re-written by hand: a changed
index, slice or branch in the code changes the terms the obligation is about.

- Arrays. ``ObjArray`` is a numpy object array of terms whose comparisons give arrays of Z3
  Booleans (numpy's would ask each for its truth) and which may be indexed by an integer term
  (an ``If`` over its rows). ``SymArray`` is an array whose length is a term (a trajectory of R
  rows, a path of n cells): row i is ``get(i)``, a term or an ``ObjArray`` of the inner shape.
  Both index, slice (bounds may be terms), broadcast and compute elementwise as numpy does.
- Facts. An operation whose result is a new symbol adds its definition to the running path:
  ``searchsorted`` (the insertion index on a sorted array, numpy's documented meaning, for each
  side), ``max`` (at least every element, stated at the indices the caller names: ledger A8).
  An index of a term adds a check that it is in range (numpy would raise otherwise), and so
  does ``max`` of an array that may be empty: the obligations prove these checks too.
- Branches. A Python ``if`` (or ``len``, ``flatnonzero``) on a term is a branch: ``Explorer``
  runs the function once per feasible path, Z3 deciding feasibility under the caller's
  hypotheses (an undecided branch is taken), so the paths cover every input; each path gives
  its conditions, definitions, checks and result.

Anything of numpy the stand-in does not know raises ``ExtractionError`` naming it: a change of
the code outside this subset fails its obligation, never passes it silently.
"""

from __future__ import annotations

import contextlib
import operator
import types
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import z3

__all__ = ["Explorer", "ExtractionError", "ObjArray", "Path", "SymArray", "SymNumpy",
           "obj", "rebind", "sym_len"]


class ExtractionError(ValueError):
    """The code does something the symbolic run does not model (names what)."""


# --- the running path -----------------------------------------------------------------------


@dataclass
class _Run:
    """One run of the function: the decisions taken so far and the facts its operations add."""

    explorer: Explorer
    prefix: tuple[bool, ...]
    taken: list[bool] = field(default_factory=list)
    conds: list[tuple[str, z3.BoolRef]] = field(default_factory=list)
    defs: list[tuple[str, z3.BoolRef]] = field(default_factory=list)
    checks: list[tuple[str, z3.BoolRef]] = field(default_factory=list)
    alternatives: list[tuple[bool, ...]] = field(default_factory=list)
    fresh: int = 0
    seen: dict[str, bool] = field(default_factory=dict)

    def new(self, tag: str, sort: str = "real") -> z3.ArithRef:
        self.fresh += 1
        name = f"{tag}#{self.fresh}"
        return z3.Int(name) if sort == "int" else z3.Real(name)

    def decide(self, cond: z3.BoolRef) -> bool:
        key = cond.sexpr()
        if key in self.seen:                     # the same test again: the same answer
            return self.seen[key]
        i = len(self.taken)
        if i < len(self.prefix):
            value = self.prefix[i]
        else:
            yes, no = self._feasible(cond), self._feasible(z3.Not(cond))
            if yes and no:
                value = True
                self.alternatives.append(tuple(self.taken) + (False,))
            elif yes or no:
                value = yes
            else:
                raise ExtractionError("a branch neither of whose sides is feasible: the path "
                                      "itself contradicts the hypotheses")
        self.taken.append(value)
        self.seen[key] = value
        text = " ".join(str(cond).split())
        self.conds.append((text if value else f"not ({text})", cond if value else z3.Not(cond)))
        return value

    def _feasible(self, cond: z3.BoolRef) -> bool:
        s = z3.Solver()
        s.set("timeout", self.explorer.timeout_ms)
        s.add([h for _, h in self.explorer.hypotheses])
        s.add([h for _, h in self.defs] + [c for _, c in self.conds] + [cond])
        with _paused():
            return bool(s.check() != z3.unsat)    # unknown: the branch is explored


_ACTIVE: list[_Run] = []
_ORIGINAL_BOOL = z3.AstRef.__bool__


def _current() -> _Run:
    if not _ACTIVE:
        raise ExtractionError("a symbolic operation outside a symbolic run")
    return _ACTIVE[-1]


def _truth(self: z3.AstRef) -> bool:
    """``bool`` of a Z3 term during a symbolic run: a constant's value, else a branch."""
    if z3.is_true(self):
        return True
    if z3.is_false(self):
        return False
    if not _ACTIVE or not z3.is_bool(self):
        return bool(_ORIGINAL_BOOL(self))
    return _ACTIVE[-1].decide(self)


@contextlib.contextmanager
def _paused() -> Iterator[None]:
    """Z3's own truth of terms while the explorer asks the solver (no branching there)."""
    z3.AstRef.__bool__ = _ORIGINAL_BOOL
    try:
        yield
    finally:
        z3.AstRef.__bool__ = _truth


@contextlib.contextmanager
def _running(run: _Run) -> Iterator[None]:
    _ACTIVE.append(run)
    z3.AstRef.__bool__ = _truth
    try:
        yield
    finally:
        _ACTIVE.pop()
        if not _ACTIVE:
            z3.AstRef.__bool__ = _ORIGINAL_BOOL


@dataclass(frozen=True)
class Path:
    """One path of a symbolic run: the conditions of its branches (named by their text), the
    definitions of the symbols its operations made, the checks it must meet (indices in range,
    non-empty maxima) and what the function returned."""

    index: int
    conds: tuple[tuple[str, z3.BoolRef], ...]
    defs: tuple[tuple[str, z3.BoolRef], ...]
    checks: tuple[tuple[str, z3.BoolRef], ...]
    result: Any

    @property
    def condition(self) -> z3.BoolRef:
        return z3.And(*[c for _, c in self.conds])


@dataclass
class Explorer:
    """Runs a function on terms along every path its branches allow under ``hypotheses``.
    ``instances``: the indices at which a ``max`` is stated to bound the elements (A8)."""

    hypotheses: Sequence[tuple[str, z3.BoolRef]]
    instances: Sequence[z3.ArithRef] = ()
    timeout_ms: int = 5_000
    limit: int = 64

    def paths(self, f: Callable[[], Any]) -> list[Path]:
        out: list[Path] = []
        todo: list[tuple[bool, ...]] = [()]
        while todo:
            if len(out) >= self.limit:
                raise ExtractionError(f"more than {self.limit} paths")
            run = _Run(self, todo.pop(0))
            with _running(run):
                result = f()
            out.append(Path(len(out), tuple(run.conds), tuple(run.defs), tuple(run.checks),
                            result))
            todo.extend(run.alternatives)
        return out


def sym_len(x: Any) -> Any:
    """The length of an array as a term (or int): a ``SymArray``'s own, else ``len``."""
    return x.length if isinstance(x, SymArray) else len(x)


# --- scalars ------------------------------------------------------------------------------------


def _is_term(x: Any) -> bool:
    return isinstance(x, z3.ExprRef)


def _is_int(x: Any) -> bool:
    return (isinstance(x, (int, np.integer)) and not isinstance(x, bool)) or (
        isinstance(x, z3.ArithRef) and x.is_int())


def _val(x: Any, like_int: bool) -> Any:
    if _is_term(x):
        return x
    if isinstance(x, (bool, np.bool_)):
        return z3.BoolVal(bool(x))
    return z3.IntVal(int(x)) if like_int else z3.RealVal(float(x))


def _ite(c: Any, x: Any, y: Any) -> Any:
    """x if c else y, a Python choice on a concrete c, else If(c, x, y) (Int when both are)."""
    if not _is_term(c):
        return x if bool(c) else y
    if z3.is_true(c):
        return x
    if z3.is_false(c):
        return y
    if _boolish(x) or _boolish(y):
        return z3.If(c, _val(x, False), _val(y, False))
    both_int = _is_int(x) and _is_int(y)
    a, b = _val(x, both_int), _val(y, both_int)
    if not both_int:
        a = z3.ToReal(a) if isinstance(a, z3.ArithRef) and a.is_int() else a
        b = z3.ToReal(b) if isinstance(b, z3.ArithRef) and b.is_int() else b
    return z3.If(c, a, b)


def _boolish(x: Any) -> bool:
    return isinstance(x, (bool, np.bool_)) or (_is_term(x) and z3.is_bool(x))


def _oa(x: Any) -> np.ndarray:
    """``x`` as a plain numpy object array (a scalar term as a 0-d one, never unpacked)."""
    if isinstance(x, np.ndarray):
        return np.asarray(x, dtype=object)
    out = np.empty((), dtype=object)
    out[()] = x
    return out


def _ge(x: Any, y: Any) -> Any:
    return x >= y


def _max2(x: Any, y: Any) -> Any:
    """numpy's maximum of two (non-NaN) numbers: x where x >= y, else y."""
    return _ite(_ge(x, y), x, y)


def _min2(x: Any, y: Any) -> Any:
    return _ite(_ge(y, x), x, y)


_ITE = np.frompyfunc(_ite, 3, 1)
_MAX = np.frompyfunc(_max2, 2, 1)
_MIN = np.frompyfunc(_min2, 2, 1)
_ABS = np.frompyfunc(abs, 1, 1)


# --- concrete arrays of terms -------------------------------------------------------------------


def obj(x: Any) -> Any:
    """``x`` as an ``ObjArray`` (a scalar stays a scalar)."""
    if isinstance(x, (SymArray, ObjArray)):
        return x
    if isinstance(x, (np.ndarray, list, tuple)):
        return np.asarray(x, dtype=object).view(ObjArray)
    return x


def _cmp(op: Callable[[Any, Any], Any]) -> Callable[[Any, Any], Any]:
    f = np.frompyfunc(op, 2, 1)

    def method(self: ObjArray, other: Any) -> Any:
        if isinstance(other, SymArray):
            return NotImplemented
        return obj(f(_oa(self), _oa(other)))
    return method


class ObjArray(np.ndarray):
    """A numpy object array of terms: comparisons elementwise to Z3 Booleans, and indexing by
    an integer term (or an array of them) along the first axis."""

    __array_priority__ = 1000.0

    __lt__ = _cmp(operator.lt)
    __le__ = _cmp(operator.le)
    __gt__ = _cmp(operator.gt)
    __ge__ = _cmp(operator.ge)
    __eq__ = _cmp(operator.eq)
    __ne__ = _cmp(operator.ne)
    __hash__ = None

    def __getitem__(self, key: Any) -> Any:
        if _is_term(key) or (isinstance(key, np.ndarray) and key.dtype == object):
            return _take(self, key, check=True)
        if isinstance(key, tuple) and any(
                _is_term(k) or isinstance(k, np.ndarray) and k.dtype == object for k in key):
            raise ExtractionError("a term inside a tuple index of an array")
        return np.ndarray.__getitem__(self, key)


def _row_select(a: np.ndarray, k: Any) -> Any:
    """Row k of ``a`` (first axis) for an integer term k: an If over the rows (the last row for
    any k out of range; the range is a check of its own)."""
    rows = [obj(np.ndarray.__getitem__(a, r)) if a.ndim > 1 else np.ndarray.__getitem__(a, r)
            for r in range(a.shape[0])]
    if not rows:
        raise ExtractionError("an index into an empty array")
    out = rows[-1]
    for r in range(len(rows) - 2, -1, -1):
        out = (obj(_ITE(_oa(k == r), _oa(rows[r]), _oa(out))) if isinstance(out, np.ndarray)
               else _ite(k == r, rows[r], out))
    return out


def _take(a: np.ndarray, key: Any, *, check: bool) -> Any:
    n = a.shape[0]
    if isinstance(key, np.ndarray):
        items = [_take(a, k, check=check) for k in key.flat]
        return _stack(items, key.shape)
    if not _is_term(key):
        return np.ndarray.__getitem__(a, int(key))
    if check:
        _current().checks.append((f"index {_text(key)} in range [0, {n})",
                                  z3.And(key >= 0, key < n)))
    return _row_select(a, key)


def _stack(items: Sequence[Any], shape: tuple[int, ...]) -> Any:
    inner = np.shape(items[0]) if items else ()
    out = np.empty(tuple(shape) + tuple(inner), dtype=object)
    flat = out.reshape((-1,) + tuple(inner))
    for i, x in enumerate(items):
        flat[i] = x
    return obj(out)


def _text(t: Any) -> str:
    return " ".join(str(t).split())


# --- arrays of symbolic length ------------------------------------------------------------------

#: What ``len`` returns for a SymArray of length >= 2: only its comparisons with 0 and 1 mean
#: anything (the code under proof uses len for those alone; arithmetic on it would be absurd).
_LONG = 1 << 62


class SymArray:
    """An array whose length is a term: row i is ``get(i)`` (a term, or an ObjArray of the inner
    shape); ``offset`` is where row 0 sits in the array it was sliced from."""

    __array_ufunc__ = None

    def __init__(self, length: Any, get: Callable[[Any], Any], inner_ndim: int = 0,
                 offset: Any = 0) -> None:
        self.length, self._get, self.inner_ndim, self.offset = length, get, inner_ndim, offset

    @property
    def ndim(self) -> int:
        return 1 + self.inner_ndim

    def get(self, i: Any) -> Any:
        return self._get(i)

    def __len__(self) -> int:
        n = self.length
        if not _is_term(n):
            return int(n)
        if n == 0:                                   # a branch (bool of a term)
            return 0
        if n == 1:
            return 1
        return _LONG

    def _index(self, key: Any) -> Any:
        """An integer index (term or int) as the row it selects, with its range check."""
        run = _current()
        if isinstance(key, (int, np.integer)) and not isinstance(key, bool):
            k = self.length + int(key) if key < 0 else z3.IntVal(int(key))
            run.checks.append((f"index {int(key)} in range (length {_text(self.length)})",
                               z3.And(k >= 0, k < self.length)))
            return k
        if _is_term(key):
            run.checks.append((f"index {_text(key)} in range [0, {_text(self.length)})",
                               z3.And(key >= 0, key < self.length)))
            return key
        raise ExtractionError(f"an index {key!r} the symbolic run does not model")

    def __getitem__(self, key: Any) -> Any:
        if isinstance(key, tuple):
            first, rest = key[0], key[1:]
            if not (isinstance(first, slice) and first == slice(None)):
                raise ExtractionError(f"the index {key!r} of a symbolic array")
            extra = sum(1 for r in rest if r is None) - sum(1 for r in rest if r is not None
                                                           and not isinstance(r, slice))
            return SymArray(self.length, lambda i: _apply(self.get(i), rest),
                            self.inner_ndim + extra, self.offset)
        if isinstance(key, slice):
            if key.step is not None:
                raise ExtractionError("a slice with a step of a symbolic array")
            n = self.length
            start = _clamp(key.start, n, 0)
            stop = _clamp(key.stop, n, n)
            length = _max2(stop - start, 0)
            return SymArray(length, lambda i: self.get(start + i), self.inner_ndim,
                            self.offset + start)
        if isinstance(key, np.ndarray):
            return _stack([self.get(self._index(k)) for k in key.flat], key.shape)
        if isinstance(key, SymArray):
            return SymArray(key.length, lambda i: self.get(self._index(key.get(i))),
                            self.inner_ndim + key.inner_ndim, 0)
        return self.get(self._index(key))

    def max(self, axis: int = 0) -> Any:
        """numpy's max along the first axis: a new symbol per element, at least the element at
        each named instance (``Explorer.instances``, indices of the array it was sliced from);
        numpy raises on an empty array, so its length >= 1 is a check."""
        if axis != 0:
            raise ExtractionError("max along an axis other than the first")
        run = _current()
        run.checks.append((f"max of a non-empty array (length {_text(self.length)})",
                           self.length >= 1))
        probe = self.get(z3.IntVal(0))
        shape = np.shape(probe)
        out = np.empty(shape, dtype=object)
        for e in np.ndindex(*shape) if shape else [()]:
            out[e] = run.new("max")
        for j in run.explorer.instances:
            local = j - self.offset
            row = self.get(local)
            for e in np.ndindex(*shape) if shape else [()]:
                el = row[e] if shape else row
                run.defs.append((f"{out[e]} is the max over the slice: at least its element "
                                 f"{_text(j)} when that lies in it",
                                 z3.Implies(z3.And(local >= 0, local < self.length),
                                            el <= out[e])))
        return obj(out) if shape else out[()]

    # elementwise arithmetic and comparisons
    def _bin(self, other: Any, op: Callable[[Any, Any], Any], swap: bool = False) -> SymArray:
        return _lift([other, self] if swap else [self, other],
                     lambda a, b: op(a, b))

    def __add__(self, o: Any) -> SymArray: return self._bin(o, operator.add)
    def __radd__(self, o: Any) -> SymArray: return self._bin(o, operator.add, True)
    def __sub__(self, o: Any) -> SymArray: return self._bin(o, operator.sub)
    def __rsub__(self, o: Any) -> SymArray: return self._bin(o, operator.sub, True)
    def __mul__(self, o: Any) -> SymArray: return self._bin(o, operator.mul)
    def __rmul__(self, o: Any) -> SymArray: return self._bin(o, operator.mul, True)
    def __truediv__(self, o: Any) -> SymArray: return self._bin(o, operator.truediv)
    def __rtruediv__(self, o: Any) -> SymArray: return self._bin(o, operator.truediv, True)
    def __lt__(self, o: Any) -> SymArray: return self._bin(o, _elem(operator.lt))
    def __le__(self, o: Any) -> SymArray: return self._bin(o, _elem(operator.le))
    def __gt__(self, o: Any) -> SymArray: return self._bin(o, _elem(operator.gt))
    def __ge__(self, o: Any) -> SymArray: return self._bin(o, _elem(operator.ge))

    def __neg__(self) -> SymArray:
        return SymArray(self.length, lambda i: -self.get(i), self.inner_ndim)

    def __abs__(self) -> SymArray:
        return SymArray(self.length, lambda i: _abs(self.get(i)), self.inner_ndim)


def _elem(op: Callable[[Any, Any], Any]) -> Callable[[Any, Any], Any]:
    """A comparison elementwise (an ObjArray's own, or on scalars)."""
    def f(a: Any, b: Any) -> Any:
        if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
            return obj(np.frompyfunc(op, 2, 1)(_oa(a), _oa(b)))
        return op(a, b)
    return f


def _abs(x: Any) -> Any:
    return obj(_ABS(np.asarray(x, dtype=object))) if isinstance(x, np.ndarray) else abs(x)


def _apply(x: Any, rest: tuple[Any, ...]) -> Any:
    """An inner row indexed by the rest of a key (``None`` adds an axis)."""
    return obj(np.asarray(x, dtype=object).view(ObjArray)[rest] if isinstance(x, np.ndarray)
               else np.asarray(x, dtype=object)[rest])


def _clamp(v: Any, n: Any, default: Any) -> Any:
    """A slice bound as numpy reads it: negative from the end, clamped to [0, n]."""
    if v is None:
        return default
    if isinstance(v, (int, np.integer)) and v < 0:
        v = n + int(v)
    return _min2(_max2(v, 0), n)


def _row(x: Any, i: Any, ndim: int) -> Any:
    """Row i of an operand broadcast against an array of ``ndim`` dimensions whose first axis
    is symbolic: a SymArray's row, an array of fewer dimensions whole, one of length 1 its row."""
    if isinstance(x, SymArray):
        return x.get(i)
    if isinstance(x, np.ndarray):
        if x.ndim < ndim:
            return obj(x)
        if x.shape[0] == 1:
            return obj(x)[0]
        raise ExtractionError(f"an array of length {x.shape[0]} broadcast against a symbolic "
                              "length")
    return x


def _lift(args: Sequence[Any], f: Callable[..., Any]) -> SymArray:
    """f elementwise over operands, at least one a SymArray (their lengths must agree)."""
    syms = [a for a in args if isinstance(a, SymArray)]
    length = syms[0].length
    for s in syms[1:]:
        if not (s.length is length or (_is_term(s.length) and _is_term(length)
                                       and s.length.eq(length)) or (
                not _is_term(s.length) and not _is_term(length) and s.length == length)):
            _current().checks.append(("broadcast lengths agree",
                                      _val(s.length, True) == _val(length, True)))
    ndim = max(a.ndim if isinstance(a, (SymArray, np.ndarray)) else 0 for a in args)
    inner = ndim - 1
    return SymArray(length, lambda i: f(*[_row(a, i, ndim) for a in args]), inner)


# --- the stand-in for numpy ---------------------------------------------------------------------


class SymNumpy(types.SimpleNamespace):
    """The numpy functions the code under proof calls, on terms; anything else raises."""

    def __init__(self) -> None:
        super().__init__()

    def __getattr__(self, name: str) -> Any:
        raise ExtractionError(f"numpy.{name} is outside what the symbolic run models")

    @staticmethod
    def zeros(shape: Any, dtype: Any = None) -> Any:
        shape = (shape,) if not isinstance(shape, tuple) else shape
        if any(_is_term(s) for s in shape[1:]):
            raise ExtractionError("zeros with a symbolic inner size")
        if _is_term(shape[0]):
            inner = shape[1:]
            return SymArray(shape[0], lambda i: obj(np.full(inner, 0.0, dtype=object))
                            if inner else 0.0, len(inner))
        return obj(np.full(shape, 0.0, dtype=object))

    @staticmethod
    def abs(x: Any) -> Any:
        return abs(x) if isinstance(x, SymArray) else _abs(obj(x))

    @staticmethod
    def subtract(a: Any, b: Any) -> Any:
        return obj(a) - obj(b)

    @staticmethod
    def asarray(x: Any, dtype: Any = None) -> Any:
        return obj(x)

    @staticmethod
    def where(c: Any, x: Any, y: Any) -> Any:
        if any(isinstance(a, SymArray) for a in (c, x, y)):
            return _lift([c, x, y], lambda a, b, d: SymNumpy.where(a, b, d))
        if not any(isinstance(a, np.ndarray) for a in (c, x, y)):
            return _ite(c, x, y)
        return obj(_ITE(_oa(c), _oa(x), _oa(y)))

    @staticmethod
    def maximum(a: Any, b: Any) -> Any:
        if isinstance(a, SymArray) or isinstance(b, SymArray):
            return _lift([a, b], SymNumpy.maximum)
        if not isinstance(a, np.ndarray) and not isinstance(b, np.ndarray):
            return _max2(a, b)
        return obj(_MAX(_oa(a), _oa(b)))

    @staticmethod
    def minimum(a: Any, b: Any) -> Any:
        if isinstance(a, SymArray) or isinstance(b, SymArray):
            return _lift([a, b], SymNumpy.minimum)
        if not isinstance(a, np.ndarray) and not isinstance(b, np.ndarray):
            return _min2(a, b)
        return obj(_MIN(_oa(a), _oa(b)))

    @staticmethod
    def clip(x: Any, lo: Any, hi: Any) -> Any:
        """numpy's clip: minimum(maximum(x, lo), hi)."""
        return SymNumpy.minimum(SymNumpy.maximum(x, lo), hi)

    @staticmethod
    def diff(x: Any, axis: int = -1) -> Any:
        if isinstance(x, SymArray):
            if axis not in (0, -1) or (axis == -1 and x.inner_ndim):
                raise ExtractionError("diff along an inner axis of a symbolic array")
            n = x.length
            return SymArray(_max2(n - 1, 0), lambda i: x.get(i + 1) - x.get(i), x.inner_ndim)
        a = obj(x)
        if axis not in (0, -1) or (axis == -1 and a.ndim > 1):
            raise ExtractionError("diff along an inner axis")
        return obj(np.ndarray.__getitem__(a, slice(1, None))
                   - np.ndarray.__getitem__(a, slice(None, -1)))

    @staticmethod
    def searchsorted(a: Any, v: Any, side: str = "left") -> Any:
        """numpy's searchsorted on a sorted 1-D array: for each v, a new integer r in [0, n]
        with a[r - 1] <= v < a[r] (side "right") or a[r - 1] < v <= a[r] (side "left"), the
        missing neighbour of an end left out (numpy's documented meaning)."""
        if side not in ("left", "right"):
            raise ExtractionError(f"searchsorted side {side!r}")
        if not (isinstance(a, SymArray) and a.inner_ndim == 0):
            raise ExtractionError("searchsorted on other than a 1-D symbolic array")
        run = _current()
        n = a.length
        vals = obj(v)
        scalar = not isinstance(vals, np.ndarray)
        flat = [vals] if scalar else list(np.asarray(vals, dtype=object).flat)
        out = []
        for x in flat:
            r = run.new(f"searchsorted_{side}", "int")
            below = a.get(r - 1) <= x if side == "right" else a.get(r - 1) < x
            above = x < a.get(r) if side == "right" else x <= a.get(r)
            run.defs.append((f"{r} = searchsorted(..., {_text(x)}, side={side!r})",
                             z3.And(r >= 0, r <= n, z3.Or(r == 0, below), z3.Or(r == n, above))))
            out.append(r)
        return out[0] if scalar else _stack(out, np.shape(vals))

    @staticmethod
    def flatnonzero(c: Any) -> Any:
        """The indices where c holds: each element's truth a branch."""
        if isinstance(c, SymArray):
            raise ExtractionError("flatnonzero of a symbolic-length array")
        flat = list(np.asarray(c, dtype=object).flat)
        return np.array([i for i, x in enumerate(flat) if bool(x)], dtype=np.int64)

    @staticmethod
    def concatenate(parts: Sequence[Any], axis: int = 0) -> Any:
        if axis != 0:
            raise ExtractionError("concatenate along an inner axis")
        if not any(isinstance(p, SymArray) for p in parts):
            return obj(np.concatenate([np.asarray(p, dtype=object) for p in parts]))
        lengths = [p.length if isinstance(p, SymArray) else np.shape(p)[0] for p in parts]
        starts = [z3.IntVal(0)]
        for n in lengths:
            starts.append(starts[-1] + n)
        total = starts[-1]
        inner = max(p.inner_ndim if isinstance(p, SymArray) else np.ndim(p) - 1 for p in parts)

        def at(p: Any, k: Any) -> Any:
            return p.get(k) if isinstance(p, SymArray) else _row_select(obj(p), k)

        def get(i: Any) -> Any:
            out = at(parts[-1], i - starts[-2])
            for p in range(len(parts) - 2, -1, -1):
                if isinstance(lengths[p], int) and lengths[p] == 0:
                    continue
                here = at(parts[p], i - starts[p])
                out = (obj(_ITE(_oa(i < starts[p + 1]), _oa(here), _oa(out)))
                       if isinstance(here, np.ndarray) else _ite(i < starts[p + 1], here, out))
            return out
        return SymArray(z3.simplify(total), get, inner)

    @staticmethod
    def broadcast_to(x: Any, shape: Any) -> Any:
        if any(_is_term(s) for s in (shape if isinstance(shape, tuple) else (shape,))):
            raise ExtractionError("broadcast_to a symbolic shape")
        return obj(np.broadcast_to(np.asarray(x, dtype=object), shape))


def rebind(f: Callable[..., Any], **names: Any) -> Callable[..., Any]:
    """``f``'s own code with some of its module's names replaced (``np`` by ``SymNumpy()``,
    a callee by a recorder): what runs is the code as written, on terms."""
    g = dict(f.__globals__)
    g.update(names)
    return types.FunctionType(f.__code__, g, f.__name__, f.__defaults__, f.__closure__)
