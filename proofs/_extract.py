"""Extraction: the while-language program of a loop-form Python function, read off its syntax tree.

The subset (what ``cfmpa.impl.builtdr_loop_nest`` is written in; anything else is refused with
an ``ExtractionError`` naming the line):

- the function's parameters are known names: sizes (``N``, ``m``, ``n`` -> ``Z3Dims``), arrays
  (``P``, ``SL``, ``SR``), helpers (``region_left`` -> ``regionL_<variant>``, ``region_right`` ->
  ``regionR``, ``region_rest`` -> ``regionRest_<variant>``, ``inter`` -> ``Inter``: the uninterpreted
  symbols of Theorems 1 and 3) and ``rule`` (the variant's ``spec.Variant.rule``); no
  decorators; a docstring may come first;
- the body is a sequence of *phases*, each a perfect nest ``for v in range(lo, hi):`` (two
  arguments, no ``else``, one statement per body) whose innermost statement stores one cell,
  ``A[idx] = e``, or ``if c: A[idx] = e1`` ``else: A[idx] = e2`` with the same cell in both;
- the store index holds every counter of the nest once, in nesting order; its other entries do
  not mention a counter (``P[N, i, j]``);
- expressions: integer literals, sizes, counters, ``+`` and ``-``, calls of the helpers, reads
  ``A[idx]`` of an array whose nest has finished (written by one phase, indexed by its counters),
  and ``x if rule.<field> else y``, a Boolean field of the variant's rule, decided at
  extraction (the code asks the rule, never the variant's name); loop bounds use no counter.

The loop invariants are generated, in the shape the hand-written ones had. For a phase with
counters v_1 .. v_d storing f (the stored value with every read of an earlier array replaced by
what its phase stored, so ``SL[N - 1]`` becomes ``regionL(N - 1)``), the invariant of loop t is:
the precondition, every earlier phase's complete fact, ``lo_s <= v_s < hi_s`` for the enclosing
loops s < t, and for u = 1 .. t: every iteration before v_u (outer counters at their current
values, inner counters over their full ranges) has stored f. Loops are labelled by phase letter
and counter (``A.k``, ``B.i``, ..., ``D.j``).
"""

from __future__ import annotations

import ast
import inspect
import textwrap
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import z3

from ..spec import Variant
from ..spec.z3defs import REGION, Z3Dims, inter
from ._while import Cmd, For, If, Seq, Store

__all__ = ["ExtractionError", "Extracted", "Phase", "extract"]

ARRAYS = ("P", "SL", "SR")


class ExtractionError(ValueError):
    """The source is outside the extractable subset; the message names the line."""


@dataclass(frozen=True)
class Phase:
    """One loop nest: its label letter, counters with bounds, and the cell it stores."""

    label: str
    counters: tuple[tuple[z3.ArithRef, z3.ArithRef, z3.ArithRef], ...]   # (v, lo, hi)
    array: z3.ArrayRef
    index: tuple[z3.ExprRef, ...]
    spec: z3.ExprRef                 # f: the stored value, reads of earlier arrays replaced

    def fact(self, u: int | None = None) -> z3.BoolRef:
        """Every iteration before counter u (0-based; None: all iterations) stored ``spec``."""
        start = 0 if u is None else u
        vs = [v for v, _, _ in self.counters[start:]]
        qs = [z3.Int(f"q.{self.label}.{v}") for v in vs]
        conds = []
        for s, ((v, lo, hi), q) in enumerate(zip(self.counters[start:], qs)):
            top = v if (u is not None and s == 0) else hi
            conds += [lo <= q, q < top]
        sub = list(zip(vs, qs))
        cell = z3.Select(self.array, *(z3.substitute(e, *sub) for e in self.index))
        body = cell == z3.substitute(self.spec, *sub)
        return z3.ForAll(qs, z3.Implies(z3.And(conds), body))


@dataclass(frozen=True)
class Extracted:
    program: Cmd
    phases: tuple[Phase, ...]
    labels: tuple[str, ...]


def _helpers(variant: str) -> dict[str, tuple[int, Callable[..., z3.ExprRef]]]:
    ints = z3.IntSort()
    region_l = z3.Function(f"regionL_{variant}", ints, REGION)
    region_r = z3.Function("regionR", ints, ints, REGION)
    rest = z3.Const(f"regionRest_{variant}", REGION)
    return {"region_left": (1, region_l), "region_right": (2, region_r),
            "region_rest": (0, lambda: rest), "inter": (2, inter)}


class _Extractor:
    def __init__(self, tree: ast.FunctionDef, lines: list[str], variant: str, pre: z3.BoolRef,
                 dims: Z3Dims, forget: frozenset[str]) -> None:
        self.tree, self.lines, self.variant = tree, lines, variant
        self.pre, self.forget = pre, forget
        self.sizes = {"N": dims.N, "m": dims.m, "n": dims.n}
        self.helpers = _helpers(variant)
        self.arrays: dict[str, z3.ArrayRef] = {}
        self.writers: dict[str, list[Phase]] = {}
        self.phases: list[Phase] = []
        self.labels: list[str] = []

    def fail(self, node: ast.AST, why: str) -> ExtractionError:
        line = getattr(node, "lineno", 0)
        text = self.lines[line - 1].strip() if 0 < line <= len(self.lines) else ""
        return ExtractionError(f"line {line}: {why}: {text!r}")

    # --- expressions ---------------------------------------------------------------------------
    def expr(self, e: ast.expr, counters: dict[str, z3.ArithRef]) -> tuple[z3.ExprRef, z3.ExprRef]:
        """(the term the program computes, the same with earlier arrays' reads replaced)."""
        try:
            return self._expr(e, counters)
        except z3.Z3Exception as exc:
            raise self.fail(e, f"ill-sorted expression ({exc})") from None

    def _expr(self, e: ast.expr, counters: dict[str, z3.ArithRef]
              ) -> tuple[z3.ExprRef, z3.ExprRef]:
        if isinstance(e, ast.Constant) and type(e.value) is int:
            v = z3.IntVal(e.value)
            return v, v
        if isinstance(e, ast.Name):
            if e.id in counters:
                return counters[e.id], counters[e.id]
            if e.id in self.sizes:
                return self.sizes[e.id], self.sizes[e.id]
            raise self.fail(e, f"unknown name {e.id!r} (not a size or a counter in scope)")
        if isinstance(e, ast.BinOp):
            if not isinstance(e.op, (ast.Add, ast.Sub)):
                raise self.fail(e, f"operator {type(e.op).__name__} (only + and -)")
            (a, sa), (b, sb) = self._expr(e.left, counters), self._expr(e.right, counters)
            for t in (a, b):
                if not z3.is_int(t):
                    raise self.fail(e, "+ and - of non-integers")
            if isinstance(e.op, ast.Add):
                return a + b, sa + sb
            return a - b, sa - sb
        if isinstance(e, ast.Call):
            if not isinstance(e.func, ast.Name) or e.func.id not in self.helpers:
                name = ast.unparse(e.func)
                raise self.fail(e, f"call of {name!r}, not a helper ({', '.join(self.helpers)})")
            if e.keywords:
                raise self.fail(e, "keyword arguments")
            arity, f = self.helpers[e.func.id]
            if len(e.args) != arity:
                raise self.fail(e, f"{e.func.id} takes {arity} argument(s)")
            args = [self._expr(a, counters) for a in e.args]
            return f(*[a for a, _ in args]), f(*[s for _, s in args])
        if isinstance(e, ast.Subscript):
            return self.read(e, counters)
        if isinstance(e, ast.IfExp):
            return self._expr(e.body if self.decide(e.test) else e.orelse, counters)
        raise self.fail(e, f"expression {type(e).__name__} outside the subset")

    def decide(self, test: ast.expr) -> bool:
        if (isinstance(test, ast.Attribute) and isinstance(test.value, ast.Name)
                and test.value.id == "rule"):
            try:
                value = getattr(Variant(self.variant).rule, test.attr)
            except (ValueError, AttributeError) as exc:
                raise self.fail(test, f"rule.{test.attr}: {exc}") from None
            if isinstance(value, bool):
                return value
            raise self.fail(test, f"rule.{test.attr} is not a Boolean field of the rule")
        raise self.fail(test, "a conditional expression needs the test rule.<field>, a "
                              "Boolean field of the variant's rule")

    def index_nodes(self, e: ast.Subscript) -> list[ast.expr]:
        sl = e.slice
        return list(sl.elts) if isinstance(sl, ast.Tuple) else [sl]

    def read(self, e: ast.Subscript, counters: dict[str, z3.ArithRef]
             ) -> tuple[z3.ExprRef, z3.ExprRef]:
        if not isinstance(e.value, ast.Name):
            raise self.fail(e, "subscript of something other than an array name")
        name = e.value.id
        writers = self.writers.get(name, [])
        if not writers:
            raise self.fail(e, f"reads {name} before a finished nest has written it")
        if len(writers) > 1:
            raise self.fail(e, f"reads {name}, written by more than one nest")
        (ph,) = writers
        vs = [v for v, _, _ in ph.counters]
        if len(ph.index) != len(vs) or any(not z3.eq(a, b) for a, b in zip(ph.index, vs)):
            raise self.fail(e, f"reads {name}, whose nest does not store at its counters")
        idx = [self._expr(x, counters) for x in self.index_nodes(e)]
        if len(idx) != len(vs):
            raise self.fail(e, f"{name} takes {len(vs)} index(es)")
        arr = self.arrays[name]
        raw = z3.Select(arr, *(a for a, _ in idx))
        return raw, z3.substitute(ph.spec, *zip(vs, [s for _, s in idx]))

    # --- statements ----------------------------------------------------------------------------
    def function(self) -> Extracted:
        fn = self.tree
        if fn.decorator_list:
            raise self.fail(fn, "decorators")
        known = set(self.sizes) | set(ARRAYS) | set(self.helpers) | {"rule"}
        for a in fn.args.posonlyargs + fn.args.args + fn.args.kwonlyargs:
            if a.arg not in known:
                raise self.fail(fn, f"parameter {a.arg!r} is not a known name")
        if fn.args.vararg or fn.args.kwarg:
            raise self.fail(fn, "*args or **kwargs")
        body = list(fn.body)
        if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
                and isinstance(body[0].value.value, str):
            body = body[1:]
        cmds: list[Cmd] = []
        for stmt in body:
            if not isinstance(stmt, ast.For):
                raise self.fail(stmt, f"statement {type(stmt).__name__} (only for-loop nests "
                                      "at the top level)")
            cmds.append(self.phase(stmt))
        return Extracted(Seq(tuple(cmds)), tuple(self.phases), tuple(self.labels))

    def loop_header(self, node: ast.For, counters: dict[str, z3.ArithRef]
                    ) -> tuple[str, z3.ArithRef, z3.ArithRef]:
        if node.orelse:
            raise self.fail(node, "for-else")
        if not isinstance(node.target, ast.Name):
            raise self.fail(node, "the loop target is not a name")
        name = node.target.id
        if name in counters or name in self.sizes or name in ARRAYS or name in self.helpers \
                or name == "rule":
            raise self.fail(node, f"counter {name!r} shadows a name in scope")
        it = node.iter
        if not (isinstance(it, ast.Call) and isinstance(it.func, ast.Name)
                and it.func.id == "range" and not it.keywords):
            raise self.fail(node, "a loop that is not over range(lo, hi)")
        if len(it.args) != 2:
            raise self.fail(node, f"range with {len(it.args)} argument(s) (write range(lo, hi))")
        for b in it.args:
            for sub in ast.walk(b):
                if isinstance(sub, ast.Name) and sub.id in counters:
                    raise self.fail(node, f"a loop bound uses the counter {sub.id!r}")
        lo, _ = self.expr(it.args[0], {})
        hi, _ = self.expr(it.args[1], {})
        return name, lo, hi

    def phase(self, top: ast.For) -> Cmd:
        letter = chr(ord("A") + len(self.phases))
        counters: dict[str, z3.ArithRef] = {}
        headers: list[tuple[str, z3.ArithRef, z3.ArithRef]] = []
        node: ast.stmt = top
        while isinstance(node, ast.For):
            name, lo, hi = self.loop_header(node, counters)
            counters[name] = z3.Int(name)
            headers.append((name, lo, hi))
            if len(node.body) != 1:
                raise self.fail(node.body[1] if len(node.body) > 1 else node,
                                "a loop body of more than one statement")
            node = node.body[0]
        array, idx, then_raw, then_spec, cond = self.store_stmt(node, counters)
        vs = [counters[h[0]] for h in headers]
        ph = Phase(letter, tuple((counters[h[0]], h[1], h[2]) for h in headers), array, idx,
                   then_spec)
        # The innermost command; reads are of finished arrays only, so SL's cells in C are known.
        inner: Cmd
        if cond is None:
            inner = Store(array, idx, then_raw[0])
        else:
            c_raw, else_raw = cond
            inner = If(c_raw, Store(array, idx, then_raw[0]), Store(array, idx, else_raw))
        # Invariants from the inside out.
        earlier = [p.fact() for p in self.phases]
        cmd: Cmd = inner
        for t in range(len(headers) - 1, -1, -1):
            name, lo, hi = headers[t]
            label = f"{letter}.{name}"
            bounds = [x for s in range(t) for x in (headers[s][1] <= vs[s], vs[s] < headers[s][2])]
            facts = [ph.fact(u) for u in range(t + 1)
                     if not (label in self.forget and u == 0 and t > 0)]
            inv = z3.And(self.pre, *earlier, *bounds, *facts)
            cmd = For(label, vs[t], lo, hi, inv, cmd)
        for h in headers:
            self.labels.append(f"{letter}.{h[0]}")
        self.phases.append(ph)
        self.writers.setdefault(str(array), []).append(ph)
        return cmd

    def target(self, node: ast.stmt, counters: dict[str, z3.ArithRef]
               ) -> tuple[str, tuple[z3.ExprRef, ...], ast.expr]:
        if not isinstance(node, ast.Assign):
            raise self.fail(node, f"statement {type(node).__name__} where a store belongs")
        if len(node.targets) != 1 or not isinstance(node.targets[0], ast.Subscript):
            raise self.fail(node, "an assignment that is not a store A[idx] = e")
        t = node.targets[0]
        if not isinstance(t.value, ast.Name) or t.value.id not in ARRAYS:
            raise self.fail(node, f"a store into {ast.unparse(t.value)!r}, not an array")
        order = list(counters)
        seen = []
        idx = []
        for x in self.index_nodes(t):
            if isinstance(x, ast.Name) and x.id in counters:
                seen.append(x.id)
            else:
                for sub in ast.walk(x):
                    if isinstance(sub, ast.Name) and sub.id in counters:
                        raise self.fail(node, f"a store index computed from the counter {sub.id!r}")
            idx.append(self.expr(x, counters)[0])
        if seen != order:
            raise self.fail(node, f"store index counters {seen} are not the loop counters "
                                  f"{order} once each in nesting order")
        return t.value.id, tuple(idx), node.value

    def store_stmt(self, node: ast.stmt, counters: dict[str, z3.ArithRef]) -> Any:
        if isinstance(node, ast.If):
            if len(node.body) != 1 or len(node.orelse) != 1:
                raise self.fail(node, "an if whose branches are not one store each "
                                      "(both branches must store the cell)")
            b, e = node.body[0], node.orelse[0]
            n1, idx1, v1 = self.target(b, counters)
            n2, idx2, v2 = self.target(e, counters)
            assert isinstance(b, ast.Assign) and isinstance(e, ast.Assign)   # target() said so
            if n1 != n2 or ast.dump(b.targets[0]) != ast.dump(e.targets[0]):
                raise self.fail(node, "the branches store different cells")
            c_raw, c_spec = self.expr(node.test, counters)
            if not z3.is_bool(c_raw):
                raise self.fail(node, "the condition is not a Boolean (a helper's answer)")
            a_raw, a_spec = self.expr(v1, counters)
            b_raw, b_spec = self.expr(v2, counters)
            if a_raw.sort() != b_raw.sort():
                raise self.fail(node, "the branches store values of different sorts")
            array = self.array(n1, len(idx1), a_raw.sort(), node)
            return array, idx1, (a_raw,), z3.If(c_spec, a_spec, b_spec), (c_raw, b_raw)
        name, idx, value = self.target(node, counters)
        raw, spec = self.expr(value, counters)
        return self.array(name, len(idx), raw.sort(), node), idx, (raw,), spec, None

    def array(self, name: str, arity: int, sort: z3.SortRef, node: ast.AST) -> z3.ArrayRef:
        if name not in self.arrays:
            self.arrays[name] = z3.Array(name, *([z3.IntSort()] * arity), sort)
        a = self.arrays[name]
        if a.sort() != z3.ArraySort(*([z3.IntSort()] * arity), sort):
            raise self.fail(node, f"{name} stored with another index count or value sort")
        return a


def extract(fn: Callable[..., Any] | None = None, variant: str = "original", *,
            pre: z3.BoolRef, dims: Z3Dims, source: str | None = None,
            forget: frozenset[str] | set[str] = frozenset()) -> Extracted:
    """The program of ``fn`` (or of ``source``, a function's text) for ``variant``, with generated
    invariants over ``pre``. ``forget`` names loops whose invariant omits the outermost loop's
    fact (a deliberately weak invariant, for the negative tests)."""
    if source is None:
        if fn is None:
            raise ExtractionError("line 1: neither a function nor its source to extract")
        source = inspect.getsource(fn)
    text = textwrap.dedent(source)
    lines = text.splitlines()
    try:
        module = ast.parse(text)
    except SyntaxError as exc:
        raise ExtractionError(f"line {exc.lineno}: not Python: {exc.msg}") from None
    defs = [s for s in module.body if isinstance(s, ast.FunctionDef)]
    if len(module.body) != 1 or len(defs) != 1:
        raise ExtractionError("line 1: the source is not one function definition")
    return _Extractor(defs[0], lines, variant, pre, dims, frozenset(forget)).function()
