"""Tools and heights under proof (docs/model.md §2 "Tools and heights", §10): the height rule,
the tool's swept region, the certificate's and the tube's constants with a tool.

``Safety.height_rule``: BuiltDR, the D_R postcondition, the exact re-decision and ``cfmpa check``
test a pair of parts (one of each arm) only when ``spec.pairs_to_test`` keeps it, i.e. when
``spec.heights_overlap`` says their closed height intervals overlap. In 3-D a part is the prism
over its planar outline and its height interval (every height when it has none), so a point
(x, y, z) of both prisms has z in both intervals. The obligation proves, for the code's own
interval test read off its syntax tree and run on Z3 reals (``run_on_terms``), that two parts
whose intervals the test calls disjoint share no point of 3-D space, whatever their planar
outlines (opaque sets): skipping the planar test for them is sound. Touching ends count as
overlapping: ``<`` where ``<=`` is meant is refuted (z at the common end). Two readings are
checked when the query is built (a failed one fails the obligation, as ``Safety.region_
soundness``'s lattice reading does): a part without a height interval is kept against every
part (``heights_overlap`` returns true for None, run on terms), and ``pairs_to_test`` keeps
exactly the pairs ``heights_overlap`` keeps, on sample arms with and without heights and tools.

``Safety.tool_region``: the region lemma for a tool (a convex polygon fixed to link 2), reading
impl's construction as impl builds it: ``impl.link_reach``, ``impl.sweep_margin`` and
``impl.link_rectangles`` for part 2, each module's own bytecode run on Z3 terms
(``module_on_terms``: numpy's cos and sin as the uninterpreted Cos, Sin of Safety.*, hypot as an
exact root, max as If), on a symbolic tool of V = 16 vertices, and checked against impl's floats
on sample tools (``check_tool_reading``). The margin argument is link 2's (Safety.region_
soundness's lemmas, by substitution) for a point of link 2's frame within the tool's reach.

``Certificate.lipschitz`` and ``Tolerance.tube_factor`` gain the tool's VCs here
(``tool_certificate_vcs``, ``tube_tool_vc``): spec.reach, spec.link_speeds and
spec.tube_lipschitz run on terms with a tool on the arm.
"""

from __future__ import annotations

import math
import types
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import z3

from .. import spec
from ._lemmas import Lemma, Substitution, dedupe, lemma
from ._obl_arc_chord import ArcChord
from ._obl_groups import GROUP_CERTIFICATE
from ._obl_safety_region import (
    Kit,
    _elbow,
    _pins,
    _point2,
    _snapped_to_corners,
    _weighted,
    _wvec,
    box_points,
    grown_coords,
    margin_parts,
    region_kit,
)
from ._obligation import VC, Method, Obligation, Verdict, Z3Query
from ._onterms import ExtractionError, module_on_terms, run_on_terms, sqrt_free
from ._onterms import as_bool as _bool
from ._onterms import is_sqrt as _is_sqrt
from ._onterms import term as _term
from ._z3vec import COS as _COS
from ._z3vec import G_MAX, N2, Hyp, Vec, a3_sum, a3_unit, concrete, e
from ._z3vec import SIN as _SIN
from ._z3vec import add as _add
from ._z3vec import comb as _comb
from ._z3vec import j as _j
from ._z3vec import occurs as _occurs
from ._z3vec import rot as _rot
from ._z3vec import scale as _scale2
from ._z3vec import sub as _sub
from ._z3vec import vec as _v
from ._z3vec import veq as _veq

__all__ = ["GROUP", "V", "ReachReading", "SymTool", "ToolKit", "ToolReading", "check_none_reading",
           "check_pairs_reading", "check_tool_reading", "height_gap_vcs", "height_rule_vcs",
           "module_on_terms",
           "read_spec_reach", "read_tool", "run_on_terms", "tool_certificate_vcs", "tool_kit",
           "tool_points_vc", "tool_region_query", "tools_obligations", "tube_tool_vc"]

GROUP = "End-to-end safety (docs/model.md §10)"

_R = z3.RealSort()


# --- the height rule ----------------------------------------------------------------------------

def _interval(prefix: str) -> tuple[z3.ArithRef, z3.ArithRef]:
    return z3.Real(f"{prefix}.lo"), z3.Real(f"{prefix}.hi")


def _in_prism(outline: z3.FuncDeclRef, height: tuple[z3.ArithRef, z3.ArithRef] | None,
              p: tuple[z3.ArithRef, z3.ArithRef, z3.ArithRef]) -> z3.BoolRef:
    """p = (x, y, z) lies in the prism over the planar ``outline`` (an opaque set) and the
    closed interval ``height`` (every height for None): (x, y) in the outline, lo <= z <= hi."""
    on = outline(p[0], p[1])
    if height is None:
        return on
    return z3.And(on, height[0] <= p[2], p[2] <= height[1])


def height_rule_vcs(overlap: Callable[..., Any] | None = None) -> tuple[VC, ...]:
    """The height rule's VC for ``overlap`` (default ``spec.heights_overlap``, read on terms)."""
    fn = overlap or spec.heights_overlap
    a, b = _interval("a"), _interval("b")
    x, y, zz = z3.Reals("x y z")
    p = (x, y, zz)
    outline_a = z3.Function("outlineA", _R, _R, z3.BoolSort())
    outline_b = z3.Function("outlineB", _R, _R, z3.BoolSort())
    said = _bool(run_on_terms(fn, a, b), 0)
    key = ("the height test calls the intervals disjoint: heights_overlap((a.lo, a.hi), "
           "(b.lo, b.hi)) is false, run on the reals (so pairs_to_test leaves the pair out)")
    goal = z3.Not(z3.And(_in_prism(outline_a, a, p), _in_prism(outline_b, b, p)))
    one, two, three = z3.RealVal(1), z3.RealVal(2), z3.RealVal(3)
    # Vacuity: [0, 1] and [2, 3]. Without the key: touching ends [0, 1] and [1, 2], z = 1.
    witness = ((a[0], z3.RealVal(0)), (a[1], one), (b[0], two), (b[1], three))
    counter = ((a[0], z3.RealVal(0)), (a[1], one), (b[0], one), (b[1], two), (zz, one))
    return (VC("disjoint_no_common_point", ((key, z3.Not(said)),), goal, key_premise=key,
               witness=witness, counter_witness=counter),)


def check_none_reading(overlap: Callable[..., Any] | None = None) -> None:
    """A part without a height interval (None: the prism over every height) is kept against
    every part: ``heights_overlap`` run on terms returns true for None on either side."""
    fn = overlap or spec.heights_overlap
    b = _interval("b")
    for args in ((None, b), (b, None), (None, None)):
        got = run_on_terms(fn, *args)
        val = got if isinstance(got, bool) else (z3.is_true(z3.simplify(got))
                                                 if isinstance(got, z3.BoolRef) else None)
        if val is not True:
            shown = tuple("None" if v is None else "(lo, hi)" for v in args)
            raise ValueError(f"heights_overlap{shown} is {got}, not true: a part at every "
                             "height would not be tested")


def _sample_arms() -> list[spec.Arm]:
    """Arms with and without link heights and tools, heights that overlap, touch or are apart."""
    tool = spec.Tool(polygon=((-0.02, -0.02), (0.08, -0.015), (0.08, 0.015)))
    out = []
    for z in (None, ((0.20, 0.26), (0.30, 0.36)), ((0.40, 0.46), (0.26, 0.30))):
        for t in (None, tool, spec.Tool(tool.polygon, (0.0, 0.20)),
                  spec.Tool(tool.polygon, (0.36, 0.50))):
            out.append(spec.Arm(base=(0.0, 0.0), links=(0.35, 0.3), width=0.06,
                                omega=(1.0, 1.0), z=z, tool=t))
    return out


def check_pairs_reading() -> None:
    """``pairs_to_test`` keeps exactly the pairs of parts (one of each arm) whose height
    intervals ``heights_overlap`` calls overlapping, on sample arms."""
    arms = _sample_arms()
    for left in arms:
        for right in arms:
            want = tuple((a, b) for a in spec.parts(left) for b in spec.parts(right)
                         if spec.heights_overlap(spec.part_height(left, a),
                                                 spec.part_height(right, b)))
            got = spec.pairs_to_test(left, right)
            if tuple(got) != want:
                raise ValueError(f"pairs_to_test gives {got}, the height test keeps {want} "
                                 f"(left z {left.z}, tool {left.tool}; right z {right.z}, "
                                 f"tool {right.tool})")


def height_rule_query() -> Z3Query:
    check_none_reading()
    check_pairs_reading()
    return Z3Query(height_rule_vcs())


# --- the certificate's 3-D distance between parts at disjoint heights ----------------------------

def height_gap_vcs(gap: Callable[..., Any] | None = None) -> tuple[VC, ...]:
    """Certificate.height_gap's VCs for ``gap`` (default spec.height_gap, read on terms)."""
    fn = gap or spec.height_gap
    a, b = _interval("a"), _interval("b")
    x1, y1, z1, x2, y2, z2, dp, n = z3.Reals("x1 y1 z1 x2 y2 z2 d_planar |P-Q|")
    g = z3.Real("gap")
    read = _term(run_on_terms(fn, a, b))
    key = "gap = height_gap((a.lo, a.hi), (b.lo, b.hi)), run on the reals"
    dz = z3.If(z1 >= z2, z1 - z2, z2 - z1)
    vertical = VC("gap_vertical", (
        ("z1 is a height of part A: a.lo <= z1 <= a.hi", z3.And(a[0] <= z1, z1 <= a[1])),
        ("z2 is a height of part B: b.lo <= z2 <= b.hi", z3.And(b[0] <= z2, z2 <= b[1])),
        (key, g == read)),
        z3.And(g >= 0, g <= dz), key_premise=key,
        witness=tuple((v, z3.RealVal(0)) for v in (*a, *b, z1, z2)),
        counter_witness=tuple((v, z3.RealVal(0)) for v in (*a, *b, z1, z2)))
    key1 = "0 <= gap <= |z1 - z2| (VC gap_vertical)"
    below = VC("gap_below_distance", (
        (key1, z3.And(g >= 0, g <= dz)),
        ("d_planar >= 0 is at most the planar distance of P = (x1, y1, z1) and Q = (x2, y2, z2) "
         "(the outlines' distance, which the certificate computes)",
         z3.And(dp >= 0, dp * dp <= (x1 - x2) * (x1 - x2) + (y1 - y2) * (y1 - y2))),
        ("|P - Q| is its length", z3.And(n >= 0, n * n == (x1 - x2) * (x1 - x2)
                                         + (y1 - y2) * (y1 - y2) + (z1 - z2) * (z1 - z2)))),
        dp * dp + g * g <= n * n, key_premise=key1,
        witness=tuple((v, z3.RealVal(0)) for v in (x1, y1, z1, x2, y2, z2, dp, n, g)),
        counter_witness=tuple((v, z3.RealVal(0)) for v in (x1, y1, z1, x2, y2, z2, dp, n))
        + ((g, z3.RealVal(1)),))
    p1, p2, h1, h2, gg = z3.Reals("p1 p2 h1 h2 g")
    key2 = "h1 = hypot(p1, g) (named)"
    lip = VC("gap_lipschitz", (
        ("p1, p2, g >= 0 (distances, a gap)", z3.And(p1 >= 0, p2 >= 0, gg >= 0)),
        (key2, z3.And(h1 >= 0, h1 * h1 == p1 * p1 + gg * gg)),
        ("h2 = hypot(p2, g) (named)", z3.And(h2 >= 0, h2 * h2 == p2 * p2 + gg * gg))),
        z3.And(h1 - h2 <= z3.If(p1 >= p2, p1 - p2, p2 - p1),
               h2 - h1 <= z3.If(p1 >= p2, p1 - p2, p2 - p1)),
        key_premise=key2,
        witness=tuple((v, z3.RealVal(0)) for v in (p1, p2, h1, h2, gg)),
        counter_witness=((p1, z3.RealVal(0)), (p2, z3.RealVal(0)), (gg, z3.RealVal(0)),
                         (h2, z3.RealVal(0))))
    return vertical, below, lip


# --- the tool's region: impl's construction read on terms ---------------------------------------

#: The tool lemma's vertex count: the loader's most (spec's MAX_TOOL_VERTICES, tested equal). A
#: tool of fewer vertices is this one with its last vertex repeated: the same farthest vertex,
#: the same generating points (some twice), the same polygon.
V = 16


class _Positive:
    """The margin as impl receives it, a term known to be > 0 (the lemma's premise: the margin
    covers SNAP g1 R_base > 0): ``grow > 0`` is true, a product is the term's."""

    def __init__(self, term: z3.ArithRef) -> None:
        self.term = term

    def __gt__(self, other: object) -> bool:
        if other != 0:
            raise ExtractionError(f"the margin compared with {other!r}, not 0")
        return True

    def __mul__(self, other: Any) -> Any:
        return other * self.term

    __rmul__ = __mul__


def _name_ites(term: z3.ExprRef, prefix: str) -> tuple[z3.ExprRef, list[Hyp]]:
    """``term`` with each If subterm replaced by a fresh real named ``prefix.m<n>`` and its
    definition (the If of the names below it): the code's max, shared as the code shares it,
    stays linear in size (the standard printer has no sharing)."""
    (out,), defs = _name_ites_all([term], prefix)
    return out, defs


def _name_ites_all(terms: Sequence[z3.ExprRef], prefix: str
                   ) -> tuple[list[z3.ExprRef], list[Hyp]]:
    """``_name_ites`` over several terms, an If they share named once."""
    memo: dict[int, z3.ExprRef] = {}
    defs: list[Hyp] = []

    def walk(t: z3.ExprRef) -> z3.ExprRef:
        if t.get_id() in memo:
            return memo[t.get_id()]
        if z3.is_app(t) and t.num_args() > 0:
            kids = [walk(c) for c in t.children()]
            if z3.is_app_of(t, z3.Z3_OP_ITE) and z3.is_arith(t):
                name = z3.Real(f"{prefix}.m{len(defs) + 1}")
                defs.append((f"{name} = If(...), the code's max (named)",
                             name == z3.If(kids[0], kids[1], kids[2])))
                out: z3.ExprRef = name
            else:
                out = t.decl()(*kids)
        else:
            out = t
        memo[t.get_id()] = out
        return out
    return [walk(t) for t in terms], defs


@dataclass(frozen=True)
class SymTool:
    """A symbolic arm with a tool of V vertices (docs/model.md §2): base b, links l1, l2, vertices
    (x_k, y_k) in the forearm's frame (origin at the wrist, x along the forearm)."""

    b: Vec
    l1: z3.ArithRef
    l2: z3.ArithRef
    verts: tuple[Vec, ...]

    @classmethod
    def named(cls, tag: str, n: int = V) -> SymTool:
        return cls(_v(f"{tag}.b"), z3.Real(f"{tag}.l1"), z3.Real(f"{tag}.l2"),
                   tuple(_v(f"{tag}.v{k + 1}") for k in range(n)))

    def arm(self, arrays: bool = False) -> Any:
        """What impl reads of an Arm (its width is never read for the tool); ``arrays``: the
        lengths as 0-d object arrays, so that numpy broadcasts a length times an array."""
        wrap = (lambda t: np.asarray(t, dtype=object)) if arrays else (lambda t: t)
        tool = types.SimpleNamespace(polygon=self.verts, z=None)
        return types.SimpleNamespace(base=self.b, links=(wrap(self.l1), wrap(self.l2)),
                                     width=wrap(z3.RealVal(0)), tool=tool, z=None)


@dataclass(frozen=True)
class ToolReading:
    """impl's tool construction read on terms (``read_tool``): the farthest vertex's distance
    from the elbow (``far``, sqrt-free: the roots named, with ``roots`` their meaning, the code's
    max named by ``max_defs``), R_base (``base``), the margin per moving flags (in the margin
    lemma's names, ``far`` replaced by its R_elbow), and the generating points at a
    configuration."""

    tool: SymTool
    far: z3.ArithRef
    base: z3.ArithRef
    roots: tuple[Hyp, ...]
    max_defs: tuple[Hyp, ...]
    root_of: tuple[z3.ArithRef, ...]          # the roots the code takes (one per vertex)
    margin: Callable[[Vec, z3.ArithRef, tuple[bool, bool]], z3.ArithRef]
    points: Callable[[z3.ArithRef, z3.ArithRef, z3.ArithRef], list[Vec]]


def read_tool(tool: SymTool | None = None, *, reach: Callable[..., Any] | None = None,
              margin: Callable[..., Any] | None = None,
              rectangles: Callable[..., Any] | None = None) -> ToolReading:
    """Run impl.link_reach(arm, 2), impl.sweep_margin(arm, 2, g, moving) and
    impl.link_rectangles(arm, t1, t2, 2, grow) (or the functions given, for the tests' mutants)
    on a symbolic tool, each module's own bytecode on terms (``module_on_terms``)."""
    from .. import impl

    t = tool or SymTool.named("tool")
    reach_fn = reach or impl.link_reach
    kin = module_on_terms(reach_fn)
    rect_fn = rectangles or impl.link_rectangles
    kin_r = kin if rect_fn.__globals__ is reach_fn.__globals__ else module_on_terms(rect_fn)
    marg_fn = margin or impl.sweep_margin
    reg = module_on_terms(marg_fn, link_reach=kin[reach_fn.__name__])
    re_raw, base, far, roots, max_defs = _read_reach(kin[reach_fn.__name__], t, "link_reach")
    root_names = [h.arg(0).arg(0) for _, h in roots]

    def margin_term(g: Vec, re_sym: z3.ArithRef, flags: tuple[bool, bool]) -> z3.ArithRef:
        out = z3.substitute(_term(reg[marg_fn.__name__](t.arm(), 2, g, flags)),
                            (re_raw, re_sym))
        if _has_root(out):
            raise ExtractionError("sweep_margin reads the tool's reach other than through "
                                  "link_reach's far vertex")
        return out

    def points(alpha: z3.ArithRef, beta: z3.ArithRef, delta: z3.ArithRef) -> list[Vec]:
        pts = kin_r[rect_fn.__name__](t.arm(arrays=True), alpha, beta, 2,
                                      grow=_Positive(delta))
        flat = np.asarray(pts, dtype=object).reshape(-1, 2)
        return [(_term(p[0]), _term(p[1])) for p in flat]

    return ToolReading(t, far, base, tuple(roots), tuple(max_defs), tuple(root_names),
                       margin_term, points)


def _read_reach(reach_on_terms: Callable[..., Any], t: SymTool, what: str
                ) -> tuple[z3.ExprRef, z3.ArithRef, z3.ArithRef, list[Hyp], list[Hyp]]:
    """(R_elbow as the code builds it, R_base, R_elbow, the roots' meaning, the max's names) of
    the tool (part 2), the reach function run on terms: the code's max named first (its If
    chain shares each partial max twice: as a tree it is exponential), then the roots inside
    the small definitions."""
    rb_raw, re_raw = (_term(x) for x in reach_on_terms(t.arm(), 2))
    far_named, defs_raw = _name_ites(re_raw, "tool.far")
    rb_named = z3.substitute(rb_raw, (re_raw, far_named))
    free, roots = sqrt_free([rb_named, far_named] + [h for _, h in defs_raw])
    max_defs = [(n, h) for (n, _), h in zip(defs_raw, free[2:])]
    if len(roots) != len(t.verts):
        raise ExtractionError(f"{what} takes {len(roots)} roots for {len(t.verts)} vertices")
    return re_raw, free[0], free[1], roots, max_defs


def _has_root(term: z3.ExprRef) -> bool:
    """Whether a square root (x ** (1/2)) occurs in ``term`` (its DAG walked once)."""
    seen: set[int] = set()
    todo = [term]
    while todo:
        t = todo.pop()
        if t.get_id() in seen:
            continue
        seen.add(t.get_id())
        if _is_sqrt(t):
            return True
        todo += t.children()
    return False


# --- numbers, to check a reading against the code's floats --------------------------------------

_OPS: dict[int, Callable[..., Any]] = {
    z3.Z3_OP_ADD: lambda *a: sum(a), z3.Z3_OP_SUB: lambda a, *b: a - sum(b),
    z3.Z3_OP_MUL: lambda *a: math.prod(a), z3.Z3_OP_DIV: lambda a, b: a / b,
    z3.Z3_OP_UMINUS: lambda a: -a, z3.Z3_OP_LE: lambda a, b: a <= b,
    z3.Z3_OP_GE: lambda a, b: a >= b, z3.Z3_OP_LT: lambda a, b: a < b,
    z3.Z3_OP_GT: lambda a, b: a > b, z3.Z3_OP_ITE: lambda c, a, b: a if c else b,
    z3.Z3_OP_POWER: lambda a, b: a ** b, z3.Z3_OP_TO_REAL: float}


@dataclass(frozen=True)
class _Program:
    """Terms' values at many environments, their DAG walked once (``_compile``): steps in
    dependency order, each node once: ``(None, value)`` for a number or a truth value, ``(None,
    name)`` for a constant (``name`` a str, looked up in the environment), ``(op, child steps)``
    otherwise (every node is evaluated, an If's branches too); ``out`` the terms' steps."""

    steps: tuple[tuple[Callable[..., Any] | None, Any], ...]
    out: tuple[int, ...]


def _compile(terms: Sequence[z3.ExprRef]) -> _Program:
    """The program of ``terms``: constants by name, Cos/Sin as math's, powers (roots) as floats,
    the arithmetic of ``_OPS`` (ValueError for any other operation)."""
    index: dict[int, int] = {}
    steps: list[tuple[Callable[..., Any] | None, Any]] = []

    def walk(t: z3.ExprRef) -> int:
        key = t.get_id()
        if key in index:
            return index[key]
        d = t.decl()
        kind = d.kind()
        step: tuple[Callable[..., Any] | None, Any]
        if kind == z3.Z3_OP_ANUM:                 # a rational numeral
            step = (None, float(t.as_fraction()))
        elif kind in (z3.Z3_OP_TRUE, z3.Z3_OP_FALSE):
            step = (None, kind == z3.Z3_OP_TRUE)
        elif t.num_args() == 0:
            step = (None, str(d.name()))
        else:
            kids = tuple(walk(c) for c in t.children())
            if kind == z3.Z3_OP_UNINTERPRETED and d.eq(_COS):
                op: Callable[..., Any] = math.cos
            elif kind == z3.Z3_OP_UNINTERPRETED and d.eq(_SIN):
                op = math.sin
            elif kind in _OPS:
                op = _OPS[kind]
            else:
                raise ValueError(f"no value for {d}")
            step = (op, kids)
        index[key] = len(steps)
        steps.append(step)
        return index[key]
    out = tuple(walk(t) for t in terms)
    return _Program(tuple(steps), out)


def _run(prog: _Program, env: dict[str, float]) -> list[Any]:
    """The values of the program's terms, constants from ``env`` (by name)."""
    vals: list[Any] = []
    for op, arg in prog.steps:
        if op is not None:
            vals.append(op(*[vals[i] for i in arg]))
        elif isinstance(arg, str):
            vals.append(env[arg])
        else:
            vals.append(arg)
    return [vals[i] for i in prog.out]


def _sample_tools() -> list[tuple[tuple[float, float], tuple[tuple[float, float], ...]]]:
    """(links, polygon padded to V vertices): the bundled gripper's tools and an odd one."""
    grip = ((-0.02, -0.04), (0.12, -0.025), (0.12, 0.025), (-0.02, 0.04))
    probe = ((-0.02, -0.02), (0.08, -0.015), (0.08, 0.015), (-0.02, 0.02))
    odd = tuple((0.05 * math.cos(2 * math.pi * k / V + 0.3) + 0.01 * k,
                 0.04 * math.sin(2 * math.pi * k / V + 0.3)) for k in range(V))
    pad = lambda p: p + (p[-1],) * (V - len(p))      # noqa: E731 - the padding the doc names
    return [((0.35, 0.30), pad(grip)), ((0.5, 0.25), pad(probe)), ((1.3, 0.7), odd)]


def check_tool_reading(reading: ToolReading, *, reach: Callable[..., Any] | None = None,
                       margin: Callable[..., Any] | None = None,
                       rectangles: Callable[..., Any] | None = None) -> None:
    """The reading gives the code's floats on sample tools (within 1e-9 relative): the reach,
    the margin for every moving flag, the generating points at sample configurations."""
    from .. import impl

    reach = reach or impl.link_reach
    margin = margin or impl.sweep_margin
    rectangles = rectangles or impl.link_rectangles
    t = reading.tool
    g1, g2, re_sym = z3.Reals("chk.g1 chk.g2 chk.Re")
    alpha, beta, delta = z3.Reals("chk.alpha chk.beta chk.delta")
    flagset = ((True, True), (True, False), (False, True), (False, False))
    margins = {f: reading.margin((g1, g2), re_sym, f) for f in flagset}
    sym_pts = reading.points(alpha, beta, delta)
    # Each term compiled once for the sample tools and values below; a name is set from a
    # term's value before a later term reads it, as the steps come.
    roots = [(_name(h.arg(0).arg(0)), _compile([h.arg(1).arg(1)])) for _, h in reading.roots]
    maxes = [(_name(h.arg(0)), _compile([h.arg(1)])) for _, h in reading.max_defs]
    reach_prog = _compile([reading.base, reading.far])
    margin_prog = _compile([margins[f] for f in flagset])
    pts_prog = _compile([c for p in sym_pts for c in p])
    for links, poly in _sample_tools():
        arm = spec.Arm(base=(0.25, -0.5), links=links, width=0.06, omega=(1.0, 1.0),
                       tool=spec.Tool(poly))
        env = {_name(t.b[0]): 0.25, _name(t.b[1]): -0.5, _name(t.l1): links[0],
               _name(t.l2): links[1]}
        for (vx, vy), (x, y) in zip(t.verts, poly):
            env[_name(vx)], env[_name(vy)] = x, y
        for name, prog in roots:                 # s >= 0 and s * s == arg: s = sqrt(arg)
            env[name] = math.sqrt(_run(prog, env)[0])
        for name, prog in maxes:
            env[name] = _run(prog, env)[0]
        got = tuple(_run(reach_prog, env))
        want = reach(arm, 2)
        _close(got, want, f"link_reach on {poly}")
        env[_name(re_sym)] = want[1]
        for gg in ((0.02, 0.02), (0.5, 0.01), (3.14, 1.0)):
            env[_name(g1)], env[_name(g2)] = gg
            for flags, value in zip(flagset, _run(margin_prog, env)):
                _close([value], [margin(arm, 2, gg, flags)], f"sweep_margin{gg, flags}")
        for a, b_, d in ((0.3, -1.1, 0.01), (2.0, 0.7, 0.2)):
            env[_name(alpha)], env[_name(beta)], env[_name(delta)] = a, b_, d
            want_pts = np.asarray(rectangles(arm, np.array(a), np.array(b_), 2, grow=d)
                                  ).reshape(-1, 2)
            _close(_run(pts_prog, env), list(want_pts.ravel()),
                   f"link_rectangles at {a, b_}, grow {d}")


def _name(t: z3.ExprRef) -> str:
    return str(t.decl().name())


def _close(got: Sequence[float], want: Sequence[float], what: str) -> None:
    if len(got) != len(want) or any(abs(x - y) > 1e-9 * max(1.0, abs(y))
                                    for x, y in zip(got, want)):
        raise ExtractionError(f"the reading of {what} gives {list(got)[:4]}..., the code "
                              f"{list(want)[:4]}...")


# --- the tool's region: lemmas ------------------------------------------------------------------

def _comb_id() -> Lemma:
    """|(1 - t) c + t w|^2 = (1 - t)|c|^2 + t |w|^2 - t (1 - t)|c - w|^2, and |c - w|^2 >= 0."""
    c, w, z = _v("cid.c"), _v("cid.w"), _v("cid.z")
    t = z3.Real("cid.t")
    key = "z = (1 - t) c + t w"
    goal = z3.And(N2(z) == (1 - t) * N2(c) + t * N2(w) - t * (1 - t) * N2(_sub(c, w)),
                  N2(_sub(c, w)) >= 0)
    return lemma("comb_id", ((key, _veq(z, _comb(c, w, t))),), goal, key,
                 names=dict(c=c, w=w, z=z, t=t))


def _hull_step(k: dict[str, Lemma]) -> Lemma:
    """A two-point convex combination of points within R of the origin is within R of it (the
    step of the induction over a chain of such combinations; from comb_id: (1 - t) |c|^2 +
    t |w|^2 <= R^2, less t (1 - t) |c - w|^2 >= 0)."""
    c, w, z = _v("hs.c"), _v("hs.w"), _v("hs.z")
    t, R = z3.Reals("hs.t hs.R")
    key = "|c| <= R"
    hyps: list[Hyp] = [("z = (1 - t) c + t w", _veq(z, _comb(c, w, t))), ("R >= 0", R >= 0),
                       (key, N2(c) <= R * R), ("|w| <= R", N2(w) <= R * R),
                       ("0 <= t <= 1", z3.And(0 <= t, t <= 1))]
    hyps += k["comb_id"].at("c, w, t", c=c, w=w, z=z, t=t)
    return lemma("hull_step", hyps, N2(z) <= R * R, key, abstract=True,
                 names=dict(c=c, w=w, z=z, t=t, R=R))


def _root_norm() -> Lemma:
    s, a, b = z3.Reals("rtn.s rtn.a rtn.b")
    key = "s >= 0 and s^2 = a^2 + b^2 (a root the code takes, named)"
    return lemma("root_norm", ((key, z3.And(s >= 0, s * s == a * a + b * b)),),
                 N2((a, b)) <= s * s, key, names=dict(s=s, a=a, b=b))


@dataclass(frozen=True)
class ToolPoint:
    """A point of the tool in link 2's frame (origin at the elbow, x along the forearm): (u, v) =
    (l2, 0) + a point of the polygon, as a chain of two-point convex combinations of its
    vertices (c_1 the first vertex, c_k = (1 - t_k) c_{k-1} + t_k (the k-th), (u, v) = c_V;
    every convex combination of the vertices is such a chain)."""

    reading: ToolReading | ReachReading   # its tool is all a point reads
    t: tuple[z3.ArithRef, ...]            # t_2 .. t_V
    c: tuple[Vec, ...]                    # c_2 .. c_V (named)
    u: z3.ArithRef
    v: z3.ArithRef

    @classmethod
    def named(cls, reading: ToolReading | ReachReading, prefix: str = "tp") -> ToolPoint:
        n = len(reading.tool.verts)
        return cls(reading, tuple(z3.Real(f"{prefix}.t{k}") for k in range(2, n + 1)),
                   tuple(_v(f"{prefix}.c{k}") for k in range(2, n + 1)),
                   z3.Real(f"{prefix}.u"), z3.Real(f"{prefix}.v"))

    def vertex(self, k: int) -> Vec:
        """The k-th vertex (0-based) in link 2's frame: (l2 + x_k, y_k)."""
        x, y = self.reading.tool.verts[k]
        return (self.reading.tool.l2 + x, y)

    def chain(self, k: int) -> Vec:
        """c_{k+1} (0-based k): the first vertex, then the named chain points."""
        return self.vertex(0) if k == 0 else self.c[k - 1]

    def hyps(self) -> list[Hyp]:
        out: list[Hyp] = []
        for k in range(1, len(self.reading.tool.verts)):
            t = self.t[k - 1]
            out.append((f"tool point: c{k + 1} = (1 - t{k + 1}) c{k} + t{k + 1} ((l2, 0) + "
                        f"vertex {k + 1}), 0 <= t{k + 1} <= 1 (named)",
                        z3.And(_veq(self.c[k - 1], _comb(self.chain(k - 1), self.vertex(k), t)),
                               0 <= t, t <= 1)))
        out.append(("(u, v) = c_V: (l2, 0) + a point of the tool's polygon",
                    _veq((self.u, self.v), self.chain(len(self.reading.tool.verts) - 1))))
        return out

    def names(self) -> dict[str, object]:
        out: dict[str, object] = dict(u=self.u, v=self.v)
        for k, (t, c) in enumerate(zip(self.t, self.c), start=2):
            out[f"t{k}"] = t
            out[f"c{k}"] = c
        return out


def _root_index(reading: Any, k: int) -> int | None:
    """Which of the code's roots is vertex k's distance from the elbow, if any."""
    x, y = ToolPoint.vertex(types.SimpleNamespace(reading=reading), k)  # type: ignore[arg-type]
    want = x * x + y * y
    for i, (_, h) in enumerate(reading.roots):
        if z3.eq(h.arg(1).arg(1), want):
            return i
    return None


_IMPL_REACH = "impl.link_reach(arm, tool)"


def _far_vertex(k: dict[str, Lemma], reading: Any, what: str = _IMPL_REACH,
                name: str = "far_vertex") -> Lemma:
    """Every vertex of the tool is within R_elbow = impl.link_reach(arm, tool)[1] (read on
    terms) of the elbow: the root the code takes of each vertex's distance is at most the code's
    max of them (root_norm, square_monotone)."""
    t = reading.tool
    P = ToolPoint.named(reading)
    re = z3.Real(f"{name}.Re")
    key = f"R_elbow = {what}[1], read on terms (the code's far vertex)"
    hyps: list[Hyp] = [*reading.roots, *reading.max_defs, (key, re == reading.far)]
    for i in range(len(t.verts)):
        r = _root_index(reading, i)
        if r is None:
            continue                         # the code takes no root of this vertex's distance
        s_k = reading.roots[r][1].arg(0).arg(0)
        vx, vy = P.vertex(i)
        hyps += k["root_norm"].at(f"vertex {i + 1}", s=s_k, a=vx, b=vy)
        hyps += k["square_monotone"].at(f"vertex {i + 1}", a=s_k, b=re, m=N2((vx, vy)))
    goal = z3.And(re >= 0, *[N2(P.vertex(i)) <= re * re for i in range(len(t.verts))])
    pins = [(c_, val) for c_, val in _tool_pins(reading, P) if not str(c_).startswith("tp.")]
    # Without the key: R_elbow below the vertices' 3/10.
    return lemma(name, hyps, goal, key, abstract=True,
                 witness=_pins(pins + [(re, z3.Q(3, 10))]),
                 counter_witness=_pins(pins + [(re, z3.Q(1, 10))]), names=dict(Re=re))


def _tool_reach(k: dict[str, Lemma], reading: Any, what: str = _IMPL_REACH,
                name: str = "tool_reach", far: str = "far_vertex") -> Lemma:
    """A point of the tool is within R_elbow of the elbow and l1 + R_elbow of the base, R_elbow
    = impl.link_reach(arm, tool)[1] read on terms: every vertex is (far_vertex), and by
    induction over the chain so is every point (hull_step)."""
    t = reading.tool
    P = ToolPoint.named(reading)
    beta, re = z3.Reals(f"{name}.beta {name}.Re")
    key = f"R_elbow = {what}[1], read on terms (the code's far vertex)"
    hyps: list[Hyp] = [a3_unit(beta, "theta2"), ("l1 > 0", t.l1 > 0), *P.hyps(),
                       *reading.roots, *reading.max_defs, (key, re == reading.far)]
    hyps += k[far].at("R_elbow", Re=re)
    for i in range(1, len(t.verts)):
        hyps += k["hull_step"].at(f"c{i + 1}", c=P.chain(i - 1), w=P.vertex(i), z=P.chain(i),
                                  t=P.t[i - 1], R=re)
    p = _rot(e(beta), (P.u, P.v))
    hyps += k["rot_norm"].at("R(theta2)", cs=e(beta), y=(P.u, P.v), z=p)
    hyps += k["reach_shift"].at("(l1, 0) + R(theta2) (u, v)", l1=t.l1, R=re, y=p)
    goal = z3.And(re >= 0, N2((P.u, P.v)) <= re * re,
                  N2(_wvec(t.l1, beta, P.u, P.v)) <= (t.l1 + re) * (t.l1 + re))
    pins = _tool_pins(reading, P)
    # Without the key: R_elbow below the vertices' 3/10.
    # Its proof check on qfnra-nlsat: Z3's default solver took 1.35 M resource units, 0.75 s;
    # the tactic 24 k, under 0.01 s, under every seed tried (docs/model.md §6.1).
    return lemma(name, hyps, goal, key, abstract=True,
                 witness=_pins(pins + [(re, z3.Q(3, 10))]),
                 counter_witness=_pins(pins + [(re, z3.Q(1, 10))]),
                 names=dict(beta=beta, Re=re, **P.names()), z3_tactic="qfnra-nlsat")


def tool_margin(reading: ToolReading, g: Vec, re: z3.ArithRef,
                moving: tuple[z3.BoolRef, z3.BoolRef]) -> z3.ArithRef:
    """The margin impl grows the tool by (sweep_margin read on terms, per moving flags), for a
    lattice whose joints move or not as ``moving`` says."""
    def at(f1: bool, f2: bool) -> z3.ArithRef:
        return reading.margin(g, re, (f1, f2))
    return z3.If(moving[0], z3.If(moving[1], at(True, True), at(True, False)),
                 z3.If(moving[1], at(False, True), at(False, False)))


def _margin_covers_tool(arc: ArcChord, reading: ToolReading) -> Lemma:
    """impl.sweep_margin for the tool, read on terms, covers the derived margin (the snap slack
    and Margin.arc_chord's bound per moving joint, at R_base = l1 + R_elbow, R_elbow), and is
    positive (impl grows the tool by it: its branch grow > 0)."""
    g1, g2, re, dl, G1, G2 = z3.Reals("mct.g1 mct.g2 mct.Re mct.Delta mct.G1 mct.G2")
    m1, m2 = z3.Bools("mct.moving1 mct.moving2")
    l1 = reading.tool.l1
    rb = l1 + re
    key = "Delta = impl.sweep_margin(arm, tool, g, moving), read on terms"

    term = tool_margin(reading, (g1, g2), re, (m1, m2))
    s1, s2, e1, e2 = margin_parts(arc, (g1, g2), (rb, re), (G1, G2))
    hyps = (("0 < g_q <= 3.14", z3.And(0 < g1, g1 <= G_MAX, 0 < g2, g2 <= G_MAX)),
            ("l1 > 0, R_elbow >= 0", z3.And(l1 > 0, re >= 0)),
            ("G1 = g1 if joint 1 moves, else 0", G1 == z3.If(m1, g1, z3.RealVal(0))),
            ("G2 = g2 if joint 2 moves, else 0", G2 == z3.If(m2, g2, z3.RealVal(0))),
            (key, dl == term))
    goal = z3.And(z3.And(s1 >= 0, s2 >= 0, e1 >= 0, e2 >= 0), s1 + s2 + e1 + e2 <= dl, dl > 0)
    return lemma("margin_covers_tool", hyps, goal, key,
                 names=dict(g1=g1, g2=g2, Re=re, Delta=dl, moving1=m1, moving2=m2, G1=G1, G2=G2))


def _offset(phi: z3.ArithRef, d: Vec) -> Vec:
    """d in the frame at angle phi: what grown_coords adds to (u, v)."""
    c, s_ = e(phi)
    return (c * d[0] + s_ * d[1], -s_ * d[0] + c * d[1])


def in_square(d: Vec, delta: z3.ArithRef) -> z3.BoolRef:
    return z3.And(-delta <= d[0], d[0] <= delta, -delta <= d[1], d[1] <= delta)


def _grow_square(k: dict[str, Lemma]) -> Lemma:
    """A point J + R(phi)(u, v) moved by d, |d| <= delta, is J + R(phi)(u', v') with (u', v') -
    (u, v) in the square [-delta, delta]^2 (the tool's points grown by delta: its sum with the
    square, whose hull impl's points span)."""
    phi, u, v, dl = z3.Reals("gsq.phi gsq.u gsq.v gsq.delta")
    J, d = _v("gsq.J"), _v("gsq.d")
    key = "|d| <= delta"
    c, s_ = e(phi)
    hyps: list[Hyp] = [a3_unit(phi, "phi"), ("delta >= 0", dl >= 0), (key, N2(d) <= dl * dl)]
    hyps += k["proj_id"].at("the frame at phi", cs=e(phi), d=d)
    hyps += k["proj_bound"].at("d in the frame", p=c * d[0] + s_ * d[1],
                               q=-s_ * d[0] + c * d[1], delta=dl)
    hyps += k["grow_id"].at("the frame at phi", cs=e(phi), u=u, v=v, J=J, d=d)
    uv2 = grown_coords(phi, u, v, d)
    goal = z3.And(_veq(_add(_add(J, _rot(e(phi), (u, v))), d), _add(J, _rot(e(phi), uv2))),
                  in_square(_offset(phi, d), dl))
    return lemma("grow_square", hyps, goal, key, abstract=True,
                 names=dict(phi=phi, u=u, v=v, delta=dl, J=J, d=d))


_SQUARE = ((-1, -1), (1, -1), (1, 1), (-1, 1))


def tool_points_vc(reading: ToolReading) -> VC:
    """impl's generating points of the tool grown by Delta at a configuration (alpha, beta),
    link_rectangles(arm, alpha, beta, part 3, grow=Delta) read on terms, include every vertex
    moved by each corner of the square [-Delta, Delta]^2 in the forearm's frame: their hull is
    the polygon's sum with the square (a point of the grown tool is in it)."""
    t = reading.tool
    alpha, beta, dl = z3.Reals("tpt.alpha tpt.beta tpt.Delta")
    G = reading.points(alpha, beta, dl)
    names = [_v(f"tpt.G{i + 1}") for i in range(len(G))]
    key = ("G = impl.link_rectangles(arm, alpha, beta, part 3, grow=Delta), read on terms "
           "(its points named G1, G2, ...)")
    want = []
    for k, (x, y) in enumerate(t.verts):
        for sx, sy in _SQUARE:
            want.append(((k, sx, sy), _point2(t.b, t.l1, alpha, alpha + beta,
                                              t.l2 + (x + sx * dl), y + sy * dl)))
    # Which of impl's points is each wanted one: compared at random values (a witness for the
    # statement only; the identities are Z3's to prove).
    rnd = np.random.default_rng(0)
    env: dict[str, float] = {}
    for sym in (*t.b, t.l1, t.l2, *[c for p in t.verts for c in p], alpha, beta, dl):
        env[_name(sym)] = float(rnd.uniform(0.1, 1.0))
    # impl's points, then the wanted ones, valued in one walk of their terms.
    values = _run(_compile([c for p in G for c in p] + [c for _, M in want for c in M]), env)
    points = list(zip(values[0::2], values[1::2]))
    got, at_want = points[:len(G)], points[len(G):]
    goal = []
    for ((k, _, _), M), m in zip(want, at_want):
        near = min(range(len(G)), key=lambda i: abs(got[i][0] - m[0]) + abs(got[i][1] - m[1]),
                   default=None)
        target = names[near] if near is not None else _v(f"tpt.none{k}")
        goal.append(_veq(M, target))
    hyps = (("Delta > 0 (margin_covers_tool)", dl > 0),
            (key, z3.And(*[_veq(n, g) for n, g in zip(names, G)])))
    return VC("tool_points", hyps, z3.And(*goal), key_premise=key)


_REACH = ("(u, v) within R_elbow of the elbow, and (l1, 0) + R(beta)(u, v) within l1 + R_elbow "
          "of the base at beta = theta2, theta2' (tool_reach's conclusion)")


def _grown_in_region(kit: Kit, k: dict[str, Lemma], reading: ToolReading) -> Lemma:
    """A point (u, v) of link 2's frame within the tool's reach, at any configuration of a box,
    lies in the hull of the grown tools at the lattice cell's corners: link 2's proof
    (link2_in_region) with the tool's margin (margin_covers_tool), each corner's grown point
    (u, v) moved by a point of the square [-Delta, Delta]^2 (grow_square)."""
    t = reading.tool
    b, l1 = t.b, t.l1
    P = ToolPoint.named(reading, "tir")
    u, v = P.u, P.v
    re, r1, r2, dl = z3.Reals("tir.Re tir.r1 tir.r2 tir.Delta")
    rb = l1 + re
    box = box_points("tir")
    (lo1, hi1, th1, A1, g1), (lo2, hi2, th2, A2, g2) = box.joint1, box.joint2
    L1, L2, alphas, phis, at, pts = box.L1, box.L2, box.alphas, box.phis, box.at, box.pts
    t2c, c1, G1, c2, G2 = L2.theta_c, L1.c, L1.G, L2.c, L2.G
    c1e = c1 + G1
    X0, X1, X2, A, B = box.named
    Ks = box.corners

    def Pt(alpha: z3.ArithRef, phi: z3.ArithRef) -> Vec:
        return _point2(b, l1, alpha, phi, u, v)
    key = "Delta = impl.sweep_margin(arm, tool, g, moving), read on terms"
    moving = (L1.moving, L2.moving)
    mct = k["margin_covers_tool"]
    hyps: list[Hyp] = [
        ("the arm (docs/model.md §2): l1 > 0", l1 > 0),
        ("theta in the box", z3.And(lo1 <= th1, th1 <= hi1, lo2 <= th2, th2 <= hi2)),
        ("lattice spacings 0 < g_q <= 3.14", z3.And(0 < g1, g1 <= G_MAX, 0 < g2, g2 <= G_MAX)),
        ("r1 = |w(theta2')|, r2 = |(u, v)| (square roots, named)",
         z3.And(r1 >= 0, r1 * r1 == N2(_wvec(l1, t2c, u, v)), r2 >= 0, r2 * r2 == N2((u, v)))),
        (key, dl == tool_margin(reading, (g1, g2), re, moving)),
    ]
    hyps += [(f"{n} = the tool's point (u, v) at {where} (named)", _veq(pts[n], Pt(a, ph)))
             for n, a, ph, where in at]
    hyps += box.lattice_hyps(k)
    hyps += mct.at("the box's lattice", g1=g1, g2=g2, Re=re, Delta=dl, moving1=L1.moving,
                   moving2=L2.moving, G1=G1, G2=G2)
    # (Where link2_in_region has reach_link2's instances.)
    hyps.append((_REACH, z3.And(re >= 0, N2((u, v)) <= re * re,
                                N2(_wvec(l1, th2, u, v)) <= (l1 + re) * (l1 + re),
                                N2(_wvec(l1, t2c, u, v)) <= (l1 + re) * (l1 + re))))
    chain = _snapped_to_corners(
        kit, k, "tir", (b, l1, u, v), (th1, th2, g1, g2), (L1, L2), (rb, re, r1, r2, dl),
        (X0, X1, X2, A, B, Ks), alphas, phis, "the tool's points", "the corners' grown tools",
        lambda i, alpha, phi, D: k["grow_square"].at(f"corner {i}", phi=phi, u=u, v=v, delta=dl,
                                                     J=_elbow(b, l1, alpha), d=D))
    hyps += chain.hyps
    ws, Qs, D = chain.ws, chain.Qs, chain.D
    goal = z3.And(
        L1.i_lo <= L1.j, L1.j + L1.step <= L1.i_hi, L2.i_lo <= L2.j, L2.j + L2.step <= L2.i_hi,
        c1e == A1 + z3.ToReal(L1.j + L1.step) * g1, c2 + G2 == A2 + z3.ToReal(L2.j + L2.step) * g2,
        *[w_ >= 0 for w_ in ws], z3.Sum(ws) == 1,
        *[in_square(_offset(ph, D), dl) for ph in phis],
        _veq(X0, _weighted(ws, Qs)))
    wit = _pins(_tool_pins(reading, P) + [
        (lo1, 0), (hi1, 0), (th1, 0), (A1, 0), (g1, z3.Q(1, 2)), (lo2, 0), (hi2, 0), (th2, 0),
        (A2, 0), (g2, z3.Q(1, 2)), (re, z3.Q(3, 10)), (r2, z3.Q(3, 10))])
    return lemma("grown_in_region", hyps, goal, key, abstract=True, witness=wit,
                 counter_witness=wit + [(dl, z3.RealVal(-1))])


def _tool_pins(reading: ToolReading | ReachReading, P: ToolPoint
               ) -> list[tuple[z3.ExprRef, int | z3.ArithRef]]:
    """A small arm, base at the origin, l1 = l2 = 1/10, every vertex at (1/5, 0) in the
    forearm's frame (each 3/10 from the elbow), the point at a vertex: for vacuity checks."""
    t, q = reading.tool, z3.Q
    out: list[tuple[z3.ExprRef, int | z3.ArithRef]] = [
        (t.b[0], 0), (t.b[1], 0), (t.l1, q(1, 10)), (t.l2, q(1, 10)), (P.u, q(3, 10)), (P.v, 0)]
    out += [(c_, q(1, 5) if n == 0 else 0) for vx in t.verts for n, c_ in enumerate(vx)]
    out += [(tk, 0) for tk in P.t]
    return out


def _tool_in_region(k: dict[str, Lemma], reading: ToolReading) -> Lemma:
    """The tool at any configuration of a box lies in the region built for it: a point of the
    tool (u, v) in link 2's frame is within the tool's reach (tool_reach at theta2 and at
    theta2' = theta2 clamped onto the lattice), so grown_in_region places it."""
    gir = k["grown_in_region"]
    P = ToolPoint.named(reading, "tir")
    re = z3.Real("tir.Re")
    th2, t2c = z3.Real("tir.theta2"), z3.Real("tir.joint2.theta_c")
    key = "R_elbow = impl.link_reach(arm, tool)[1], read on terms (the code's far vertex)"
    own = [(n, h) for n, h in gir.hyps if not n.startswith(("A3 ", "by ")) and n != _REACH]
    hyps: list[Hyp] = [*P.hyps(), *reading.roots, *reading.max_defs, (key, re == reading.far),
                       *own]
    for beta, where in ((th2, "theta2"), (t2c, "theta2'")):
        hyps += k["tool_reach"].at(where, beta=beta, Re=re, **P.names())
    hyps += gir.use((), "the tool's point")
    wit = [(c_, val) for c_, val in gir.vc.witness] + [
        (c_, z3.RealVal(val) if isinstance(val, int) else val) for c_, val in _tool_pins(reading, P)]
    # Without the key: a negative R_elbow, hence a negative margin.
    counter = [(c_, val) for c_, val in wit if not c_.eq(re)] + [(re, z3.RealVal(-1))]
    return lemma("tool_in_region", hyps, gir.goal, key, abstract=True, witness=wit,
                 counter_witness=counter)


@dataclass(frozen=True)
class ToolKit:
    """The tool's lemmas by name (with Safety.region_soundness's kit they use), for the tests."""

    reading: ToolReading
    kit: Kit
    lemmas: dict[str, Lemma]
    points: VC

    def __getitem__(self, name: str) -> Lemma:
        return self.lemmas[name]


def tool_kit(reading: ToolReading | None = None, kit: Kit | None = None) -> ToolKit:
    reading = reading or read_tool()
    kit = kit or region_kit()
    k = dict(kit.lemmas)
    for L in (_comb_id(), _root_norm()):
        k[L.vc.name] = L
    k["hull_step"] = _hull_step(k)
    k["far_vertex"] = _far_vertex(k, reading)
    k["tool_reach"] = _tool_reach(k, reading)
    k["margin_covers_tool"] = _margin_covers_tool(kit.arc, reading)
    k["grow_square"] = _grow_square(k)
    k["grown_in_region"] = _grown_in_region(kit, k, reading)
    k["tool_in_region"] = _tool_in_region(k, reading)
    own = ("comb_id", "hull_step", "root_norm", "far_vertex", "tool_reach", "margin_covers_tool",
           "grow_square", "grown_in_region", "tool_in_region")
    return ToolKit(reading, kit, {n: k[n] for n in own}, tool_points_vc(reading))


def tool_region_query(tk: ToolKit | None = None) -> Z3Query:
    """Safety.tool_region: the tool's lemmas (the reading checked against impl's floats first)
    and tool_points."""
    if tk is None:
        reading = read_tool()
        check_tool_reading(reading)
        tk = tool_kit(reading)
    vcs = [L.vc for L in tk.lemmas.values()]
    return Z3Query(tuple(vcs[:-1]) + (tk.points, vcs[-1])
                   + tuple(tool_statement_vc(tag, tk) for tag in ("L", "R")))


# --- the tool's statement: what the compositions read of Safety.tool_region ---------------------

def tool_statement(tag: str) -> tuple[list[z3.ExprRef], z3.BoolRef]:
    """The tool's region statement for arm ``tag`` (L, R), over its bound names: for every box,
    lattice anchor and spacing (0 < g_q <= G_MAX), configuration theta in the box and point p, a
    point of the arm's tool (part 3) at theta is a member of the region built for the tool, the
    box, the anchor and the spacing: Safety.region_statement's form for part 3."""
    from ._obl_safety import ArmModel, region_statement
    return region_statement(ArmModel.named(tag), 2)


def tool_statement_closed(tag: str) -> z3.BoolRef:
    bound, body = tool_statement(tag)
    return z3.ForAll(bound, body)


@dataclass(frozen=True)
class ToolModel:
    """One arm's tool as the compositions read it: the arm's base, l1, l2 and V vertices (in
    the proofs' names for the arm, ``tag``), the opaque "p is a point of part 3 at theta"
    (linkL/linkR at 2) and its local quantities (the chain's weights and points, the point's
    coordinates in link 2's frame: functions of theta and p), and the region built for it."""

    tag: str
    tool: SymTool
    loc: dict[str, z3.FuncDeclRef]

    @classmethod
    def named(cls, tag: str) -> ToolModel:
        args = [z3.RealSort()] * 4
        loc = {n: z3.Function(f"{tag}.tl.{n}", *args, _R)
               for n in ["u", "v"] + [f"t{k}" for k in range(2, V + 1)]
               + [f"c{k}.{a}" for k in range(2, V + 1) for a in "xy"]}
        return cls(tag, SymTool.named(tag), loc)

    def at(self, name: str, theta: Vec, p: Vec) -> z3.ArithRef:
        return self.loc[name](theta[0], theta[1], p[0], p[1])

    def definition(self, theta: Vec, p: Vec) -> z3.BoolRef:
        """Definitional (docs/model.md §2): a point p of the tool at theta is the point of link
        2's frame (origin at the elbow, x along the forearm) at (u, v) = (l2, 0) + a point of
        the polygon, a chain of two-point convex combinations of its vertices (weights t_k in
        [0, 1], points c_k), all functions of theta and p."""
        from ._obl_safety_separation import link_l, link_r
        t = self.tool
        link = link_l if self.tag == "L" else link_r

        def vert(k: int) -> Vec:
            return (t.l2 + t.verts[k][0], t.verts[k][1])

        def chain(k: int) -> Vec:
            return vert(0) if k == 0 else (self.at(f"c{k + 1}.x", theta, p),
                                           self.at(f"c{k + 1}.y", theta, p))
        conds = []
        for k in range(1, V):
            tk = self.at(f"t{k + 1}", theta, p)
            conds += [0 <= tk, tk <= 1, _veq(chain(k), _comb(chain(k - 1), vert(k), tk))]
        uv = (self.at("u", theta, p), self.at("v", theta, p))
        conds += [_veq(uv, chain(V - 1)),
                  _veq(p, _point2(t.b, t.l1, theta[0], theta[0] + theta[1], uv[0], uv[1]))]
        return z3.Implies(link(2, theta, p), z3.And(conds))

    def hull_definition(self, reading: ToolReading, box: Any, anchor: Vec, g: Vec,
                        re: z3.ArithRef) -> tuple[list[z3.ExprRef], z3.BoolRef]:
        """Definitional (docs/model.md §4.2: the tool's region is the convex hull of the tool
        grown by impl.sweep_margin at the lattice configurations of impl.lattice_range): a
        convex combination of points of the grown tools at four lattice configurations, each
        (l2, 0) + a point of the polygon moved by a point of the square [-Delta, Delta]^2 in
        that configuration's frame (the grown tool: tool_points), is a member of the region.
        Stated at the corners the proof combines; returns its bound names and its body."""
        from ..impl import lattice_range
        from ..spec.z3defs import member
        from ._obl_safety import _SWEPT_L, _SWEPT_R, _swept
        t = self.tool
        pre = f"{self.tag}.td!"
        lat = [lattice_range(box[q][0], box[q][1], anchor[q], g[q]) for q in range(2)]
        moving = (lat[0][1] > lat[0][0], lat[1][1] > lat[1][0])
        delta = tool_margin(reading, g, re, moving)
        bound: list[z3.ExprRef] = []
        conds: list[z3.BoolRef] = []
        ts = [z3.Real(f"{pre}t{k}") for k in range(2, V + 1)]
        cs = [_v(f"{pre}c{k}") for k in range(2, V + 1)]
        u0, v0 = z3.Reals(f"{pre}u {pre}v")
        bound += ts + [x for c in cs for x in c] + [u0, v0]

        def vert(k: int) -> Vec:
            return (t.l2 + t.verts[k][0], t.verts[k][1])
        chain = [vert(0)] + cs
        for k in range(1, V):
            conds += [0 <= ts[k - 1], ts[k - 1] <= 1,
                      _veq(chain[k], _comb(chain[k - 1], vert(k), ts[k - 1]))]
        conds.append(_veq((u0, v0), chain[V - 1]))
        pts: list[Vec] = []
        ws: list[z3.ArithRef] = []
        for c in range(4):
            i, j = z3.Int(f"{pre}i{c}"), z3.Int(f"{pre}j{c}")
            al, be, ph, w = z3.Reals(f"{pre}alpha{c} {pre}beta{c} {pre}phi{c} {pre}w{c}")
            s = _v(f"{pre}s{c}")
            bound += [i, j, al, be, ph, w, s[0], s[1]]
            conds += [lat[0][0] <= i, i <= lat[0][1], al == anchor[0] + z3.ToReal(i) * g[0],
                      lat[1][0] <= j, j <= lat[1][1], be == anchor[1] + z3.ToReal(j) * g[1],
                      ph == al + be, w >= 0, in_square(s, delta)]
            pts.append(_point2(t.b, t.l1, al, ph, u0 + s[0], v0 + s[1]))
            ws.append(w)
        q = _v(f"{pre}q")
        conds += [z3.Sum(ws) == 1, _veq(q, _weighted(ws, pts))]
        swept = _SWEPT_L if self.tag == "L" else _SWEPT_R
        body = z3.Implies(z3.And(conds), member(_swept(swept, 2, box, anchor, g), q))
        return bound + [q[0], q[1]], body


#: tool_in_region's hypotheses the statement discharges itself: the arm (the statement's
#: premise), theta in the box and the spacings (its antecedent), the tool's point (the tool's
#: definition).
_TOOL_DERIVED = ("the arm (docs/model.md §2): l1 > 0", "theta in the box",
                 "lattice spacings 0 < g_q <= 3.14")


def tool_statement_vc(tag: str, tk: ToolKit, *, hull: Callable[..., Any] | None = None) -> VC:
    """The tool's statement for arm ``tag``: its body at its bound names (so its universal
    closure), from the tool's definition at (theta, p), the hull's definition at the corners
    tool_in_region exhibits, and tool_in_region (proved in Safety.tool_region) instantiated by
    substitution at the arm's tool, the box, theta and the point's local quantities. ``hull``
    replaces ToolModel.hull_definition (the tests' mutants)."""
    lem = tk["tool_in_region"]
    reading = tk.reading
    src, m = reading.tool, ToolModel.named(tag)
    dst = m.tool
    bound, goal = tool_statement(tag)
    lo1, hi1, lo2, hi2, a1, a2, g1, g2, t1, t2, p1, p2 = bound
    box, anchor, g, theta, p = ((lo1, hi1), (lo2, hi2)), (a1, a2), (g1, g2), (t1, t2), (p1, p2)
    R = z3.Real
    # The reading's tool and its named roots and maxes, renamed to the arm's.
    pairs: list[tuple[z3.ExprRef, z3.ExprRef]] = [
        (src.b[0], dst.b[0]), (src.b[1], dst.b[1]), (src.l1, dst.l1), (src.l2, dst.l2)]
    for a, b in zip(src.verts, dst.verts):
        pairs += [(a[0], b[0]), (a[1], b[1])]
    for r in reading.root_of:
        pairs.append((r, R(f"{tag}.{r}")))
    for n, _ in reading.max_defs:
        old = n.split(" ")[0]
        pairs.append((R(old), R(f"{tag}.{old}")))
    renamed = list(pairs)
    re = R(f"{tag}.tool.Re")
    pairs.append((R("tir.Re"), re))
    pairs += [(R("tir.lo1"), lo1), (R("tir.hi1"), hi1), (R("tir.theta1"), t1), (R("tir.A1"), a1),
              (R("tir.g1"), g1), (R("tir.lo2"), lo2), (R("tir.hi2"), hi2), (R("tir.theta2"), t2),
              (R("tir.A2"), a2), (R("tir.g2"), g2),
              (R("tir.u"), m.at("u", theta, p)), (R("tir.v"), m.at("v", theta, p))]
    for k in range(2, V + 1):
        pairs += [(R(f"tir.t{k}"), m.at(f"t{k}", theta, p)),
                  (R(f"tir.c{k}.x"), m.at(f"c{k}.x", theta, p)),
                  (R(f"tir.c{k}.y"), m.at(f"c{k}.y", theta, p))]
    names = {n for n, _ in lem.hyps}
    missing = [n for n in _TOOL_DERIVED if n not in names]
    if missing:
        raise KeyError(f"tool_in_region has no hypotheses {missing}: _TOOL_DERIVED is out of date")

    at_pairs = Substitution(pairs)

    def sub(f: z3.ExprRef) -> z3.ExprRef:
        return concrete(at_pairs(f))
    point = {n for n, _ in ToolPoint.named(reading, "tir").hyps()}
    defs = [(f"{n} [tool_in_region's named quantity]", sub(h)) for n, h in lem.hyps
            if n not in _TOOL_DERIVED and n not in point
            and not n.startswith(("A3 ", "by "))]
    # The corners, weights and offsets tool_in_region's conclusion names.
    c1, G1, c2, G2 = R("tir.joint1.c"), R("tir.joint1.G"), R("tir.joint2.c"), R("tir.joint2.G")
    j1, st1 = z3.Int("tir.joint1.j"), z3.If(z3.Bool("tir.joint1.moving"), 1, 0)
    j2, st2 = z3.Int("tir.joint2.j"), z3.If(z3.Bool("tir.joint2.moving"), 1, 0)
    lam, mu, nu = z3.Reals("tir.lam tir.mu tir.nu")
    D = _v("tir.D")
    c1e = c1 + G1
    alphas = (c1, c1, c1e, c1e)
    betas = (c2, c2 + G2, c2, c2 + G2)
    phis = (c1 + c2, (c1 + c2) + G2, c1e + c2, (c1e + c2) + G2)
    i_s = (j1, j1, j1 + st1, j1 + st1)
    j_s = (j2, j2 + st2, j2, j2 + st2)
    ws = ((1 - lam) * (1 - mu), (1 - lam) * mu, lam * (1 - nu), lam * nu)
    hull_bound, hull_body = (hull or m.hull_definition)(reading, box, anchor, g, re)
    hull_body = z3.substitute(hull_body, *renamed)
    vals: list[z3.ExprRef] = [m.at(f"t{k}", theta, p) for k in range(2, V + 1)]
    for k in range(2, V + 1):
        vals += [m.at(f"c{k}.x", theta, p), m.at(f"c{k}.y", theta, p)]
    vals += [m.at("u", theta, p), m.at("v", theta, p)]
    for c in range(4):
        off = _offset(phis[c], D)
        vals += [i_s[c], j_s[c], alphas[c], betas[c], phis[c], ws[c], off[0], off[1]]
    vals += [p1, p2]
    hull_inst = z3.substitute(hull_body, *zip(hull_bound, [sub(x) for x in vals]))
    key = f"{tag}: the tool's hull definition at tool_in_region's corners (docs/model.md §4.2)"
    hyps: list[Hyp] = [
        (f"{tag}: the arm (docs/model.md §2): l1 > 0", dst.l1 > 0),
        (f"{tag}: the tool's definition (docs/model.md §2) at (theta, p)",
         m.definition(theta, p)),
        (key, concrete(hull_inst)),
    ]
    hyps += defs
    hyps += [(n, concrete(h)) for n, h in lem.use(pairs, f"{tag}, the tool")]
    wit = tuple((sub(c), v) for c, v in lem.vc.witness)
    return VC(f"tool_statement_{tag}", dedupe(hyps), goal, key_premise=key, witness=wit,
              counter_witness=wit)


# --- the certificate's and the tube's constants with a tool (docs/model.md §7.2, §12) ---------

@dataclass(frozen=True)
class ReachReading:
    """spec.reach(arm, TOOL) read on terms (``read_spec_reach``): the fields a tool's reach
    lemmas read (as ToolReading's)."""

    tool: SymTool
    far: z3.ArithRef
    base: z3.ArithRef
    roots: tuple[Hyp, ...]
    max_defs: tuple[Hyp, ...]
    raw: z3.ExprRef                       # R_elbow as the code builds it (roots, max unnamed)
    on_terms: Callable[..., Any]          # spec.reach on terms


_SPEC_REACH = "spec.reach(arm, TOOL)"


def read_spec_reach(tool: SymTool | None = None, reach: Callable[..., Any] | None = None
                    ) -> ReachReading:
    """spec.reach (or ``reach``, a test's mutant) run on a symbolic tool, its module's bytecode
    on terms (Python's max as an If, hypot as an exact root)."""
    t = tool or SymTool.named("tool")
    fn = reach or spec.reach
    on = module_on_terms(fn)[fn.__name__]
    raw, base, far, roots, max_defs = _read_reach(on, t, "spec.reach")
    return ReachReading(t, far, base, tuple(roots), tuple(max_defs), raw, on)


def _sqrt_le() -> Lemma:
    n, R = z3.Reals("sql.n sql.R")
    key = "n^2 <= R^2"
    return lemma("sqrt_le", (("n, R >= 0", z3.And(n >= 0, R >= 0)), (key, n * n <= R * R)),
                 n <= R, key, names=dict(n=n, R=R))


def tool_certificate_lemmas(reading: ReachReading | None = None,
                            kit: Kit | None = None) -> dict[str, Lemma]:
    """Certificate.lipschitz's lemmas for the tool, reading spec.reach (with Safety.region_
    soundness's and Safety.tool_region's lemmas they use by substitution)."""
    reading = reading or read_spec_reach()
    kit = kit or region_kit()
    k = dict(kit.lemmas)
    for L in (_comb_id(), _root_norm(), _sqrt_le()):
        k[L.vc.name] = L
    k["hull_step"] = _hull_step(k)
    k["tool_far_vertex"] = _far_vertex(k, reading, _SPEC_REACH, "tool_far_vertex")
    k["tool_reach_frame"] = _tool_reach(k, reading, _SPEC_REACH, "tool_reach_frame",
                                        "tool_far_vertex")
    k["reach_point"] = _reach_point(k, reading)
    k["reach_tool"] = _reach_tool(k, reading)
    k["speed_term"] = _speed_term()
    k["speed_tool"] = speed_tool_lemma(k, reading)
    return k


_FRAME_REACH = ("(u, v) within R_elbow of the elbow, (l1, 0) + R(theta2)(u, v) within l1 + "
                "R_elbow of the base (tool_reach_frame's conclusion)")


def _reach_point(k: dict[str, Lemma], reading: ReachReading) -> Lemma:
    """A point p of link 2's frame at (u, v), (u, v) within the tool's reach (as tool_reach_frame
    concludes), is within R_elbow of the elbow and R_base of the base, R_base as spec.reach
    gives it."""
    t = reading.tool
    P = ToolPoint.named(reading)
    b, l1 = t.b, t.l1
    al, be, re, rb, ne, nb = z3.Reals("rt.theta1 rt.theta2 rt.Re rt.Rb |p-elbow| |p-base|")
    phi = al + be
    p = _point2(b, l1, al, phi, P.u, P.v)
    elbow = _elbow(b, l1, al)
    w = _wvec(l1, be, P.u, P.v)
    key = f"R_base = {_SPEC_REACH}[0], read on terms"
    hyps: list[Hyp] = [
        ("l1 > 0", l1 > 0),
        (_FRAME_REACH, z3.And(re >= 0, N2((P.u, P.v)) <= re * re,
                              N2(w) <= (l1 + re) * (l1 + re))),
        (f"R_elbow = {_SPEC_REACH}[1], read on terms (the code's far vertex)",
         re == reading.far),
        (key, rb == reading.base),
        ("|p - elbow| is its length", z3.And(ne >= 0, ne * ne == N2(_sub(p, elbow)))),
        ("|p - base| is its length", z3.And(nb >= 0, nb * nb == N2(_sub(p, b)))),
        a3_unit(al, "theta1"), a3_unit(phi, "theta1 + theta2"),
        a3_sum(phi, al, be, "theta1 + theta2")]
    hyps += k["rot_norm"].at("R(theta1 + theta2): p - elbow", cs=e(phi), y=(P.u, P.v),
                             z=_sub(p, elbow))
    hyps += k["kin"].at("theta", A=e(al), B=e(be), AB=e(phi), l1=l1, u=P.u, v=P.v, b=b)
    hyps += k["rot_norm"].at("R(theta1): p - base", cs=e(al), y=w, z=_sub(p, b))
    hyps += k["sqrt_le"].at("|p - elbow|", n=ne, R=re)
    hyps += k["square_monotone"].at("l1 + R_elbow <= R_base", a=l1 + re, b=rb, m=N2(w))
    hyps += k["sqrt_le"].at("|p - base|", n=nb, R=rb)
    q = z3.Q
    wit = _pins([(b[0], 0), (b[1], 0), (l1, q(1, 10)), (P.u, q(3, 10)), (P.v, 0),
                 (re, q(3, 10)), (al, 0), (be, 0)])
    return lemma("reach_point", hyps, z3.And(ne <= re, nb <= rb), key, abstract=True,
                 witness=wit, counter_witness=wit + _pins([(rb, q(1, 10))]))


def _reach_tool(k: dict[str, Lemma], reading: ReachReading) -> Lemma:
    """Every point p of the tool at (theta1, theta2) is within R_elbow of the elbow and R_base
    of the base, (R_base, R_elbow) = spec.reach(arm, TOOL) on terms: tool_reach_frame at theta2
    and reach_point, chained by their instances."""
    P = ToolPoint.named(reading)
    rp = k["reach_point"]
    re, be = z3.Real("rt.Re"), z3.Real("rt.theta2")
    key = f"R_elbow = {_SPEC_REACH}[1], read on terms (the code's far vertex)"
    own = [(n, h) for n, h in rp.hyps if not n.startswith(("A3 ", "by ")) and n != _FRAME_REACH]
    hyps: list[Hyp] = [*P.hyps(), *reading.roots, *reading.max_defs, *own]
    hyps += k["tool_reach_frame"].at("theta2", beta=be, Re=re, **P.names())
    hyps += rp.use((), "the tool's point")
    pins = _tool_pins(reading, P)
    wit = list(rp.vc.witness) + _pins(pins)
    counter = [(c_, v_) for c_, v_ in wit if not c_.eq(re)] + [(re, z3.RealVal(-1))]
    return lemma("reach_tool", hyps, rp.goal, key, abstract=True, witness=wit,
                 counter_witness=counter)


def _speed_term() -> Lemma:
    """A joint's share of a point's velocity: z = c J(y) with |y| = n <= R gives |z| <= |c| R."""
    c, n, R = z3.Reals("st.c st.n st.R")
    y, z = _v("st.y"), _v("st.z")
    key = "n <= R"
    hyps = (("z = c J(y)", _veq(z, _scale2(c, _j(y)))),
            ("n = |y| (named)", z3.And(n >= 0, n * n == N2(y))), (key, n <= R))
    ac = z3.If(c >= 0, c, -c)
    return lemma("speed_term", hyps, z3.And(ac * R >= 0, N2(z) <= (ac * R) * (ac * R)), key,
                 names=dict(c=c, n=n, R=R, y=y, z=z))


def speed_tool_lemma(k: dict[str, Lemma], reading: ReachReading,
                     speeds: Callable[..., Any] | None = None) -> Lemma:
    """A point fixed to the tool moves at most spec.link_speeds(arm, w)[0, TOOL] (run on terms,
    with spec.reach on terms): its velocity is w1 J(p - base) + w2 J(p - elbow) (the VC
    velocity: the tool is fixed to link 2), |p - base| <= R_base, |p - elbow| <= R_elbow (VC
    reach_tool); each joint's share is at most |w_q| R_q (speed_term), their sum at most the sum
    (triangle)."""
    fn = speeds or spec.link_speeds
    t = reading.tool
    w1, w2, width = z3.Reals("w1 w2 w")
    arm = t.arm()
    arm.width = width
    g = module_on_terms(fn, reach=reading.on_terms)
    bound = _term(g[fn.__name__](arm, np.array([[w1, w2]], dtype=object))[0, spec.TOOL])
    bound = z3.substitute(bound, (reading.raw, reading.far))
    (bound,), bound_roots = sqrt_free([bound])
    if any(_occurs(h.arg(0).arg(0), bound) for _, h in reading.roots):
        raise ExtractionError("link_speeds reads the tool's reach other than through reach's "
                              "far vertex")
    p, elbow = _v("p"), _v("elbow")
    base = t.b
    nb, ne, nv = z3.Reals("|p-base| |p-elbow| |v|")
    re, rb = z3.Reals("R_elbow R_base")
    x, y = _scale2(w1, _j(_sub(p, base))), _scale2(w2, _j(_sub(p, elbow)))
    v = _add(x, y)
    a1, a2 = z3.If(w1 >= 0, w1, -w1) * rb, z3.If(w2 >= 0, w2, -w2) * re
    key = "|p - base| <= R_base (VC reach_tool)"
    # R_base and R_elbow as the names reach_tool bounds (the max and the roots behind them are
    # reach_tool's business; here only that link_speeds takes its bound from them).
    hyps: list[Hyp] = [
        *bound_roots,
        (f"(R_base, R_elbow) = {_SPEC_REACH}, read on terms (its far vertex named)",
         z3.And(re == reading.far, rb == reading.base)),
        ("|p - base| is its length", z3.And(nb >= 0, nb * nb == N2(_sub(p, base)))),
        (key, nb <= rb),
        ("|p - elbow| is its length", z3.And(ne >= 0, ne * ne == N2(_sub(p, elbow)))),
        ("|p - elbow| <= R_elbow (VC reach_tool)", ne <= re),
        ("|v| is the length of the velocity, v = w1 J(p - base) + w2 J(p - elbow): both "
         "joints move the tool (VC velocity)", z3.And(nv >= 0, nv * nv == N2(v)))]
    hyps += k["speed_term"].at("joint 1", c=w1, n=nb, R=rb, y=_sub(p, base), z=x)
    hyps += k["speed_term"].at("joint 2", c=w2, n=ne, R=re, y=_sub(p, elbow), z=y)
    hyps += k["triangle"].at("the two joints' shares", x=x, y=y, z=v, a=a1, b=a2)
    hyps += k["sqrt_le"].at("|v|", n=nv, R=a1 + a2)
    zero = z3.RealVal(0)
    return lemma("speed_tool", hyps, nv <= bound, key, abstract=True,
                 witness=tuple((q, zero) for q in (w1, w2, *p, *elbow, *base)))


def tool_certificate_vcs() -> tuple[VC, ...]:
    """What Certificate.lipschitz adds for a tool: its reach (tool_far_vertex, tool_reach_frame,
    reach_tool; comb_id, hull_step, root_norm and sqrt_le with them) and its speed bound."""
    reading = read_spec_reach()
    k = tool_certificate_lemmas(reading)
    names = ("comb_id", "hull_step", "root_norm", "sqrt_le", "tool_far_vertex",
             "tool_reach_frame", "reach_point", "reach_tool", "speed_term", "speed_tool")
    return tuple(k[n].vc for n in names)


@dataclass(frozen=True)
class _SymArmTool:
    """What tube_lipschitz reads of an arm with a tool: links, width, tool."""

    links: tuple[z3.ArithRef, z3.ArithRef]
    width: z3.ArithRef
    tool: Any
    z: Any = None


def tube_tool_vc(tube: Callable[..., Any] | None = None,
                 reach: Callable[..., Any] | None = None) -> VC:
    """L = spec.tube_lipschitz (run on terms, spec.reach on terms) is at least R_base + R_elbow
    of every part of either arm, each arm with a tool of V vertices: the links' and the tools'."""
    fn = tube or spec.tube_lipschitz
    reach_fn = reach or spec.reach
    on_reach = module_on_terms(reach_fn)[reach_fn.__name__]
    g = module_on_terms(fn, reach=on_reach)
    arms: dict[str, Any] = {}             # _SymArmTool: what spec.parts and reach read
    hyps: list[Hyp] = []
    for side in ("left", "right"):
        t = SymTool.named(f"{side}.tool")
        width = z3.Real(f"{side}.w")
        arms[side] = _SymArmTool((t.l1, t.l2), width, types.SimpleNamespace(polygon=t.verts,
                                                                           z=None))
        hyps.append((f"the {side} arm's links and width are positive",
                     z3.And(t.l1 > 0, t.l2 > 0, width > 0)))
    s = types.SimpleNamespace(left=arms["left"], right=arms["right"])
    lip = z3.Real("L")
    terms = [_term(g[fn.__name__](s))]
    labels = []
    for side in ("left", "right"):
        for part in spec.parts(arms[side]):
            terms += [_term(x) for x in on_reach(arms[side], part)]
            labels.append(f"{side} part {part + 1}")
    named, defs = _name_ites_all(terms, "tube")
    free, _ = sqrt_free(named + [h for _, h in defs])
    # The roots' meaning is not needed: L bounds every sum whatever the roots are (as in the VC
    # lipschitz), and the maxima are the code's, named.
    defs_free = [(n, h) for (n, _), h in zip(defs, free[len(named):])]
    key = "L = tube_lipschitz(s), read on terms"
    goal = z3.And(*[free[1 + 2 * i] + free[2 + 2 * i] <= lip for i in range(len(labels))])
    one = z3.RealVal(1)
    wit = [(x, one) for a in arms.values() for x in a.links] + [
        (a.width, z3.RealVal("1/10")) for a in arms.values()]
    return VC("lipschitz_tool", tuple(hyps + defs_free + [(key, lip == free[0])]), goal,
              key_premise=key, witness=tuple(wit))


# --- the obligations ----------------------------------------------------------------------------

def tools_obligations() -> list[Obligation]:
    """Safety.height_rule, Safety.tool_region and Certificate.height_gap (docs/model.md §2,
    §7.2, §10)."""
    return [
        Obligation(
            "Safety.height_rule", GROUP, "docs/model.md §2 (tools and heights), §4.3, §10",
            "The height rule is sound: in 3-D a part is the prism over its planar outline and "
            "its closed height interval [lo, hi] (every height when it has none), so a point "
            "(x, y, z) of two prisms has z in both intervals. For the code's own interval test, "
            "spec.heights_overlap read off its syntax tree and run on real terms (a, b "
            "symbolic: a.lo, a.hi, b.lo, b.hi), whenever it calls two intervals disjoint no "
            "point (x, y, z) lies in both prisms, whatever the planar outlines (opaque sets): "
            "BuiltDR, the postcondition, the exact re-decision and cfmpa check may skip the "
            "planar test for such a pair. Touching ends count as overlapping: a test with < "
            "where <= is meant is refuted at the common end. Checked when built (a failure "
            "fails the obligation): heights_overlap, run on terms, keeps a part without an "
            "interval against every part, and spec.pairs_to_test keeps exactly the pairs "
            "heights_overlap keeps (sample arms with and without heights and tools).",
            Method.Z3, Verdict.PROVED, height_rule_query,
            summary=("Two parts whose height ranges the planner calls apart share no point in "
                     "space, whatever their outlines, so their planar test may be skipped; ranges "
                     "that only touch count as overlapping.")),
        Obligation(
            "Safety.tool_region", GROUP, "docs/model.md §2 (tools and heights), §4.2, §10 (c)",
            "A point of a tool (a convex polygon fixed in the forearm's frame: origin at the "
            "wrist, x along the forearm) at any configuration theta of a box [lo1, hi1] x [lo2, "
            "hi2] lies in the region impl builds for the tool and the box, as impl builds it: "
            "the lattice of impl.lattice_range (run on the symbols), the tool's generating points "
            "impl.link_rectangles(arm, t1, t2, part 3, grow) at the lattice configurations, grown "
            "by impl.sweep_margin(arm, part 3, g, moving), the reach of impl.link_reach(arm, part "
            "3) -- each impl's own bytecode run on Z3 terms (numpy's cos and sin as the "
            "uninterpreted Cos, Sin; hypot as an exact root; max as If), for a symbolic tool of 16 "
            "vertices (the loader's most; a tool of fewer is it with a vertex repeated) and checked "
            "against impl's floats on sample tools. The tool's point is a chain of two-point convex "
            "combinations of its vertices (every convex combination is one). far_vertex: each "
            "vertex's root the code takes is at most its max (root_norm, square_monotone), so each "
            "vertex is within R_elbow = link_reach's far vertex of the elbow; tool_reach: by "
            "induction over the chain every point is (hull_step, from comb_id), and within l1 + "
            "R_elbow of the base. margin_covers_tool: sweep_margin read for the tool is at least "
            "the snap slack and Margin.arc_chord's bound at those radii, and positive (impl's "
            "branch grow > 0). "
            "grown_in_region: link2_in_region's argument (Safety.region_soundness's lemmas by "
            "substitution: lattice, kin, chord, arc_in_place at the base arc and both elbow arcs, "
            "transport, transport_chord, combine2_norm, combine2_weights, shift_eq, sum_subst4) "
            "for a point of link 2's frame within the tool's reach, each corner's grown point the "
            "point moved by a point of the square [-Delta, Delta]^2 in the corner's frame "
            "(grow_square); tool_in_region: the tool's point is such a point. tool_points: at any "
            "configuration impl's generating points include every vertex moved by each corner of "
            "that square, so each corner's grown point, a point of the polygon plus a point of the "
            "square, lies in the hull of impl's points there (the sum of two convex polygons is "
            "the hull of their vertices' sums: stated, not proved here), and the tool's point in "
            "the hull of impl's points over the box's lattice. tool_statement_L/R: what the "
            "compositions read, for each arm: a point of the tool at a configuration of a box is "
            "a member of the region built for the tool and the box, derived from the tool's "
            "definition (link 2's frame at (l2, 0) plus a chain of convex combinations of the "
            "vertices), the hull's definition (the grown tool at four lattice configurations, "
            "each a point of the polygon moved by a point of the square) and tool_in_region by "
            "substitution. Faults refuted: a vertex left out "
            "of the points (tool_points), the margin from the nearest vertex (far_vertex), the "
            "polygon turned with link 1 (tool_points).",
            Method.Z3, Verdict.PROVED, tool_region_query, label="hull of sums stated",
            summary=("Every point of a tool on the wrist, at any joint angles inside a box, lies "
                     "inside the swept region the planner builds for the tool: its margin, taken "
                     "from the farthest vertex, covers the motion between the sample angles.")),
        Obligation(
            "Certificate.height_gap", GROUP_CERTIFICATE,
            "docs/model.md §2 (tools and heights), §7.2",
            "The certificate's 3-D distance between two parts at disjoint heights, hypot(planar "
            "distance, gap) (spec.part_distances), rests on the height rule: (gap_vertical) for "
            "spec.height_gap, read off its syntax tree and run on real terms (Python's max as an "
            "If), 0 <= gap <= |z1 - z2| for every height z1 of one part's closed interval and z2 "
            "of the other's; (gap_below_distance) so for points P, Q of the two prisms and any "
            "planar distance d <= |(P - Q) in the plane|, d^2 + gap^2 <= |P - Q|^2: the "
            "certificate's value bounds the true 3-D distance from below; (gap_lipschitz) "
            "hypot(p, g) with g fixed changes by at most |p1 - p2|, so the 3-D distance between "
            "moving parts at fixed heights has the planar distance's Lipschitz constant (the "
            "certificate's L, Certificate.lipschitz). Restated, not read: part_distances' "
            "hypot(planar, gap) where gap > 0 (tested against it).",
            Method.Z3, Verdict.PROVED, lambda: Z3Query(height_gap_vcs()),
            label="hypot restated",
            summary=("Between two parts at disjoint heights the motion check's distance, made of "
                     "the planar distance and the height gap, never exceeds their true distance in "
                     "space, and changes no faster than the planar one.")),
    ]
