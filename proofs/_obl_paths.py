"""Properties 1-8, Definition 4's flaw, Theorems 2 and 4, over symbolic D_R and paths.

D_R is an integer array P[k, i, j] of unbounded size (N, m, n symbolic); a path is a pair of
integer arrays and a length, no bound; statements quantify over them. ``is_path`` is docs/model.md §5's
fixed definition unless the id says ``printed``. J1 and J2 are uninterpreted: what is proved
about optimal paths holds for any cost functions. searchoptpath's top level is a while-language
program that calls the search through its contract (null iff no valid path, else an optimal one).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import z3

from ..spec import Variant
from ..spec.z3defs import (
    REGION,
    Blocked,
    Z3Dims,
    Z3PathVar,
    blocked_exact,
    bound_path,
    costs,
    free_sound,
    in_grid,
    inter,
    inter_definition,
    is_optimal,
    is_path_fixed,
    is_path_paper,
    layer_value,
    lex_le,
    member,
    position,
    z3_path,
)
from ._obligation import VC, Method, Obligation, Smoke, Verdict, Z3Query
from ._while import Assign, Assume, Havoc, If, Seq, smoke_tests, verification_conditions

__all__ = ["path_obligations", "prop8_obligations", "search_top_level"]

GROUP_PROPS = "Paths (Props 1-7, Def 4)"
GROUP_THM = "searchoptpath (Theorems 2, 4)"
GROUP_P8 = "Property 8 (corrected chain)"

#: The label of the obligations about searchoptpath's top level: its inner search is assumed.
SEARCH_ASSUMED = "wrapper proved, search assumed"

Cell = tuple[z3.ArithRef, z3.ArithRef]


@dataclass(frozen=True)
class _Setting:
    d: Z3Dims
    P: z3.ArrayRef
    start: Cell
    goal: Cell

    def base(self) -> tuple[tuple[str, z3.BoolRef], ...]:
        return (("N >= 1, m, n >= 1", self.d.sane()),
                ("start, goal in the grid", z3.And(in_grid(self.d, self.start),
                                                   in_grid(self.d, self.goal))))

    def valid(self, path: Z3PathVar, P: z3.ArrayRef | None = None) -> z3.BoolRef:
        return is_path_fixed(self.P if P is None else P, self.d, self.start, self.goal, path)


def _setting(array: str = "P") -> _Setting:
    ints = z3.IntSort()
    return _Setting(Z3Dims.named(), z3.Array(array, ints, ints, ints, ints),
                    (z3.Int("start.i"), z3.Int("start.j")), (z3.Int("goal.i"), z3.Int("goal.j")))


#: The generic region family of Prop8.prestrength_thm4: not a variant, its rest layer an
#: independent region.
GENERIC = "X"


def _own_rest(variant: str) -> bool:
    """Whether the rest layer is an independent region (not layer N-1's): the generic family,
    or a variant whose rule puts the principal at rest at its goal (spec.Variant.rest_at_goal;
    the tight variant)."""
    return variant == GENERIC or Variant(variant).rest_at_goal


def rest_region(variant: str) -> z3.ExprRef:
    """The principal's region in the rest layer: ``regionRest_<variant>`` (the name
    Thm3.builtdr_tight's postcondition uses) when ``_own_rest``, else layer N-1's, as in the
    paper."""
    if _own_rest(variant):
        return z3.Const(f"regionRest_{variant}", REGION)
    region_l = z3.Function(f"regionL_{variant}", z3.IntSort(), REGION)
    return region_l(Z3Dims.named().N - 1)


def _regions(variant: str) -> tuple[Blocked, Blocked, Callable[[z3.ArithRef], z3.ExprRef]]:
    """The blocked predicates of Theorem 1/3's postcondition for a region family, and the
    principal's region at step k (the rest region from N on: ``rest_region(variant)``)."""
    ints = z3.IntSort()
    region_l = z3.Function(f"regionL_{variant}", ints, REGION)
    region_r = z3.Function("regionR", ints, ints, REGION)
    N = Z3Dims.named().N
    at_rest = rest_region(variant)

    def motion(k: z3.ArithRef, i: z3.ArithRef, j: z3.ArithRef) -> z3.BoolRef:
        return inter(region_l(k), region_r(i, j))

    def rest(_: z3.ArithRef, i: z3.ArithRef, j: z3.ArithRef) -> z3.BoolRef:
        return inter(at_rest, region_r(i, j))

    def at_step(k: z3.ArithRef) -> z3.ExprRef:
        return z3.If(k < N, region_l(k), at_rest)
    return motion, rest, at_step


def _BINARY(st: _Setting) -> tuple[str, z3.BoolRef]:
    """D_R holds 0 or 1, as BuiltDR writes it."""
    k, i, j = z3.Ints("bin!k bin!i bin!j")
    return ("P in {0, 1}", z3.ForAll([k, i, j], z3.Or(st.P[k, i, j] == 0, st.P[k, i, j] == 1)))


def _SMALL(st: _Setting) -> tuple[str, z3.BoolRef]:
    """A refutation may look in a small corner: its counterexample is one all the same."""
    return ("small: N <= 3, m, n <= 2", z3.And(st.d.N <= 3, st.d.m <= 2, st.d.n <= 2))


def _render_path(st: _Setting, path: Z3PathVar, steps: z3.ArithRef | None = None
                 ) -> Callable[[z3.ModelRef], str]:
    """A counterexample as a reader wants it: sizes, the list, and D_R where the path is."""
    def render(m: z3.ModelRef) -> str:
        ev = lambda e: m.eval(e, model_completion=True)  # noqa: E731
        N, length = ev(st.d.N).as_long(), ev(path.length).as_long()
        cells = [(ev(path.xs[k]), ev(path.ys[k])) for k in range(max(length, 0))]
        lines = [f"N = {N}, m = {ev(st.d.m)}, n = {ev(st.d.n)}, start = ({ev(st.start[0])}, "
                 f"{ev(st.start[1])}), goal = ({ev(st.goal[0])}, {ev(st.goal[1])})",
                 f"L = {[(int(str(a)), int(str(b))) for a, b in cells]} (LENGTH {length})"]
        for k in range(min(max(N, length) + 1, 12)):
            pos = position(path, k)
            layer = min(k, N)
            lines.append(f"step {k}: cell ({ev(pos[0])}, {ev(pos[1])}), "
                         f"P[{layer}] there = {ev(layer_value(st.P, st.d, k, pos))}"
                         + (" (rest layer)" if k >= N else ""))
        if steps is not None:
            lines.append(f"violated at step k = {ev(steps)}")
        return "\n".join(lines)
    return render


# --- Properties 1-7 and Definition 4 ---------------------------------------------------------

def _prop1() -> Z3Query:
    st = _setting()
    motion, _, _ = _regions("original")
    k, i, j = z3.Ints("k i j")
    x, y = z3.Reals("x y")
    region_l = z3.Function("regionL_original", z3.IntSort(), REGION)
    region_r = z3.Function("regionR", z3.IntSort(), z3.IntSort(), REGION)
    sl, sr = region_l(k), region_r(i, j)
    hyps = st.base() + (
        ("Inter means a common point", inter_definition()),
        ("Theorem 1's postcondition", blocked_exact(st.P, st.d, motion=motion)),
        ("0 <= k < N, (i, j) in the grid", z3.And(0 <= k, k < st.d.N, in_grid(st.d, (i, j)))))
    empty = z3.Not(z3.And(member(sl, (x, y)), member(sr, (x, y))))   # x, y free: for all points
    px, py = z3.Reals("px py")
    meets = z3.Exists([px, py], z3.And(member(sl, (px, py)), member(sr, (px, py))))
    goal = z3.And(z3.Implies(st.P[k, i, j] == 0, empty), z3.Implies(st.P[k, i, j] == 1, meets))
    return Z3Query((VC("state_meaning", hyps, goal, key_premise="Theorem 1's postcondition"),))


def _prop2() -> Z3Query:
    st = _setting()
    L = z3_path("L")
    goal = z3.And(L.xs[0] == st.start[0], L.ys[0] == st.start[1],
                  L.xs[L.length - 1] == st.goal[0], L.ys[L.length - 1] == st.goal[1])
    return Z3Query((VC("endpoints", st.base() + (("is_path L", st.valid(L)),), goal,
                       key_premise="is_path L"),))


def _prop34(rest: bool) -> Z3Query:
    st = _setting()
    L = z3_path("L")
    k, i, j = z3.Ints("k i j")
    pos = position(L, k)
    when = (z3.And(st.d.N <= k) if rest else z3.And(0 <= k, k < st.d.N))
    hyps = st.base() + (("is_path L", st.valid(L)),
                        ("k < N" if not rest else "k >= N", when),
                        ("the cell held at step k is (i, j)", z3.And(pos[0] == i, pos[1] == j)))
    if rest:
        copy = z3.ForAll([i, j], st.P[st.d.N, i, j] == st.P[st.d.N - 1, i, j])
        goal = z3.And(st.P[st.d.N, i, j] == 0,
                      z3.Implies(copy, st.P[st.d.N - 1, i, j] == 0))
    else:
        goal = st.P[k, i, j] == 0
    return Z3Query((VC("rest_free" if rest else "layer_free", hyps, goal,
                       key_premise="is_path L"),), render=_render_path(st, L, k))


def _optimal_hyps(st: _Setting, O: Z3PathVar) -> tuple[tuple[str, z3.BoolRef], ...]:
    """optpath(startp, goalp) = O with a path existing: Definition 5's predicate holds of O."""
    return (("O = optpath, a path existing (Prop 5)", is_optimal(st.P, st.d, st.start, st.goal, O)),)


def _prop5() -> Z3Query:
    st = _setting()
    O, W, Opt = z3_path("O"), z3_path("W"), z3_path("Opt")
    q = lambda p: is_optimal(st.P, st.d, st.start, st.goal, p)  # noqa: E731
    hyps = st.base() + (
        ("some path W exists", st.valid(W)),
        ("well-founded (J1, J2) at W: an optimum Opt exists", z3.Implies(st.valid(W), q(Opt))),
        ("Hilbert choice at Opt: (∃L. Q L) ⇒ Q(εQ), εQ = O", z3.Implies(q(Opt), q(O))))
    return Z3Query((VC("optpath_is_path", hyps, st.valid(O), key_premise="some path W exists"),))


def _prop5_printed() -> Z3Query:
    st = _setting()
    O, L = z3_path("O"), bound_path("eps!L")
    q = lambda p: is_optimal(st.P, st.d, st.start, st.goal, p)  # noqa: E731
    hyps = st.base() + (
        ("Hilbert choice: (∃L. Q L) ⇒ Q(O)", z3.ForAll(L.consts(), z3.Implies(q(L), q(O)))),
        ("a D_R whose start is blocked at step 0", st.P[0, st.start[0], st.start[1]] == 1),
        _SMALL(st))

    def render(m: z3.ModelRef) -> str:
        ev = lambda e: m.eval(e, model_completion=True)  # noqa: E731
        return (f"N = {ev(st.d.N)}, start = ({ev(st.start[0])}, {ev(st.start[1])}) with "
                f"P[0, start] = {ev(st.P[0, st.start[0], st.start[1]])}: no list is a path, so "
                f"the choice O = optpath (length {ev(O.length)}) is not one either; Property 5 "
                "holds only when some path exists (Theorem 2's 'optpath <> Null')")
    return Z3Query((VC("optpath_is_path", hyps, st.valid(O)),), render=render)


def _prop67(rest: bool) -> Z3Query:
    st = _setting()
    O = z3_path("O")
    k, i, j = z3.Ints("k i j")
    pos = position(O, k)
    when = (st.d.N <= k) if rest else z3.And(0 <= k, k < st.d.N)
    hyps = st.base() + _optimal_hyps(st, O) + (
        ("k >= N" if rest else "k < N", when),
        ("O holds (i, j) at step k", z3.And(pos[0] == i, pos[1] == j)))
    if rest:
        # Where R is layer N-1 (original, modified: BuiltDR copies it), layer N-1 is free too.
        copy = z3.ForAll([i, j], st.P[st.d.N, i, j] == st.P[st.d.N - 1, i, j])
        goal = z3.And(st.P[st.d.N, i, j] == 0, z3.Implies(copy, st.P[st.d.N - 1, i, j] == 0))
    else:
        goal = st.P[k, i, j] == 0
    return Z3Query((VC("opt_rest_free" if rest else "opt_layer_free", hyps, goal,
                       key_premise="O = optpath, a path existing (Prop 5)"),))


def _def4_printed() -> Z3Query:
    st = _setting()
    L = z3_path("L")
    k = z3.Int("k")
    kk = z3.Int("wf!k")
    well_formed = z3.And(
        L.length >= 1,
        z3.ForAll([kk], z3.Implies(z3.And(0 <= kk, kk < L.length), in_grid(st.d, L.cell(kk)))),
        z3.ForAll([kk], z3.Implies(z3.And(0 <= kk, kk < L.length),
                                   z3.If(kk < st.d.N, st.P[kk, L.xs[kk], L.ys[kk]],
                                         st.P[st.d.N - 1, L.xs[kk], L.ys[kk]]) == 0)))
    hyps = st.base() + (
        ("is_path L (Definition 4 as printed)", is_path_paper(st.P, st.d, st.start, st.goal, L)),
        ("L nonempty, in the grid, every listed step free", well_formed),
        ("LENGTH(L) <= k < N", z3.And(L.length <= k, k < st.d.N)),
        ("goal free in the rest layer", st.P[st.d.N, st.goal[0], st.goal[1]] == 0),
        _SMALL(st), _BINARY(st))
    goal = st.P[k, st.goal[0], st.goal[1]] == 0
    return Z3Query((VC("after_the_list", hyps, goal),), render=_render_path(st, L, k))


def _def4_off_grid() -> Z3Query:
    """Definition 4 as printed constrains a step only when both its cells are grid cells: a list
    that leaves the grid passes, even where every cell of D_R is blocked."""
    st = _setting()
    L = z3_path("L")
    kk = z3.Int("og!k")
    a, b, c = z3.Ints("og!a og!b og!c")
    listed = lambda f: z3.ForAll([kk], z3.Implies(z3.And(0 <= kk, kk < L.length), f))  # noqa: E731
    hyps = st.base() + (
        ("is_path L (Definition 4 as printed)", is_path_paper(st.P, st.d, st.start, st.goal, L)),
        ("L's cells are pairs of naturals (HOL's num)", listed(z3.And(L.xs[kk] >= 0,
                                                                      L.ys[kk] >= 0))),
        ("every cell of every layer blocked", z3.ForAll([a, b, c], st.P[a, b, c] == 1)),
        ("N = m = n = 3, start (0, 0), goal (2, 2)",
         z3.And(st.d.N == 3, st.d.m == 3, st.d.n == 3, st.start[0] == 0, st.start[1] == 0,
                st.goal[0] == 2, st.goal[1] == 2)),
        ("LENGTH(L) = 3", L.length == 3),
        # A small corner, so the counterexample reads well: it is one all the same.
        ("cells <= 9", listed(z3.And(L.xs[kk] <= 9, L.ys[kk] <= 9))))
    goal = listed(in_grid(st.d, L.cell(kk)))

    def render(m: z3.ModelRef) -> str:
        ev = lambda e: m.eval(e, model_completion=True)  # noqa: E731
        cells = [(int(str(ev(L.xs[q]))), int(str(ev(L.ys[q])))) for q in range(3)]
        return (f"N = m = n = 3, every cell of every layer blocked (P = 1), start (0, 0), goal "
                f"(2, 2): L = {cells} passes the printed is_path, since a step is constrained only "
                "when both its cells are grid cells; it leaves the grid (under the fixed is_path "
                "nothing passes: the start is blocked at step 0)")
    return Z3Query((VC("off_grid", hyps, goal),), render=render)


def _def4_fixed() -> Z3Query:
    st = _setting()
    L = z3_path("L")
    k = z3.Int("k")
    hyps = st.base() + (("is_path L", st.valid(L)), ("k >= 0", k >= 0))
    goal = z3.And(in_grid(st.d, position(L, k)),
                  layer_value(st.P, st.d, k, position(L, k)) == 0)
    return Z3Query((VC("every_step", hyps, goal, key_premise="is_path L"),),
                   render=_render_path(st, L, k))


def path_obligations() -> list[Obligation]:
    """Properties 1-7 and Definition 4 (printed: refuted; fixed: safe at every step)."""
    P, R, Z = Verdict.PROVED, Verdict.REFUTED_AS_EXPECTED, Method.Z3
    G = GROUP_PROPS
    return [
        Obligation("Prop1.state_meaning", G, "Property 1",
                   "Under Theorem 1's postcondition, P[k,i,j] = 0 implies SLarm_k ∩ SRarm_ij = Φ "
                   "(no common point) and P[k,i,j] = 1 implies a common point.", Z, P, _prop1,
                   summary=("Property 1: a cell marked 0 in D_R means the two arms share no point "
                            "there; a cell marked 1 means they do.")),
        Obligation("Prop2.endpoints", G, "Property 2",
                   "is_path(L) implies L_0 = startp and L_{LENGTH(L)-1} = goalp.", Z, P, _prop2,
                   definitional="a conjunct of is_path restated",
                   summary=("Property 2: a path starts at the subordinate arm's start cell and "
                            "ends at its goal cell.")),
        Obligation("Prop3.layer_free", G, "Property 3",
                   "is_path(L), k < N and the cell held at step k is (i, j) imply P[k,i,j] = 0 "
                   "(L_k read as the cell held at step k: the goal once the list has ended).",
                   Z, P, lambda: _prop34(False),
                   definitional="a conjunct of is_path restated",
                   summary=("Property 3: while the principal arm moves, every cell a path holds is "
                            "free in that time step's layer of D_R.")),
        Obligation("Prop4.rest_free", G, "Property 4",
                   "is_path(L), k >= N and the cell held at step k is (i, j) imply P[N,i,j] = 0 "
                   "(rest layer) and, where R is layer N-1 (original, modified), P[N-1,i,j] = 0; "
                   "for every k >= N, not only k < LENGTH(L).", Z, P, lambda: _prop34(True),
                   summary=("Property 4: once the principal arm has stopped, every cell a path "
                            "holds is free in the rest layer of D_R, however long it waits.")),
        Obligation("Prop5.optpath_is_path", G, "Property 5",
                   "If some path exists, optpath(startp, goalp) is a path: from Hilbert choice "
                   "(instance at the optimum named) and the well-foundedness of (J1, J2) on N x N "
                   "(an optimum exists once a path does; assumed, see the ledger).", Z, P, _prop5,
                   definitional="a choice instance: Hilbert choice at the named optimum",
                   summary=("Property 5: if any path exists, the least-cost path the planner "
                            "chooses is a path.")),
        Obligation("Prop5.printed", G, "Property 5 as printed",
                   "For all startp, goalp, optpath(startp, goalp) is a path: refuted when no path "
                   "exists (start blocked at step 0): Hilbert choice then picks a non-path. "
                   "is_path here is the fixed one (docs/model.md §5), on purpose, an exception to "
                   "'printed means the printed definitions': the flaw refuted is Property 5's "
                   "missing hypothesis that a path exists, which does not depend on Definition "
                   "4 (whose own flaws are Def4.is_path_printed and Def4.is_path_printed_off_grid).",
                   Z, R, _prop5_printed,
                   summary=("Property 5 as printed (the chosen path is always a path) is false "
                            "when no path exists, for example with the start cell blocked: the "
                            "hypothesis that one exists is missing.")),
        Obligation("Prop6.opt_layer_free", G, "Property 6",
                   "optpath = O (a path existing), k < N and O holds (i, j) at step k imply "
                   "P[k,i,j] = 0.", Z, P, lambda: _prop67(False),
                   definitional="a choice instance composed with a conjunct of is_path",
                   summary=("Property 6: the least-cost path holds only free cells while the "
                            "principal arm moves.")),
        Obligation("Prop7.opt_rest_free", G, "Property 7",
                   "optpath = O (a path existing), k >= N and O holds (i, j) at step k imply "
                   "P[N,i,j] = 0 (the rest layer) and, where R is layer N-1 (original, "
                   "modified: P[N] = P[N-1] on every cell), P[N-1,i,j] = 0.",
                   Z, P, lambda: _prop67(True),
                   summary=("Property 7: the least-cost path holds only cells free in the rest "
                            "layer once the principal arm has stopped.")),
        Obligation("Def4.is_path_printed", G, "Definition 4 as printed",
                   "Definition 4 as printed keeps the subordinate safe until the principal "
                   "arrives: refuted, a list that ends early and waits at a goal blocked in a "
                   "later layer passes it (LENGTH(L) <= k < N unchecked).", Z, R, _def4_printed,
                   summary=("Definition 4 as printed lets a path end early and wait at a goal cell "
                            "that the principal arm sweeps later: shown false, so it does not keep "
                            "the subordinate safe.")),
        Obligation("Def4.is_path_printed_off_grid", G, "Definition 4 as printed",
                   "Definition 4 as printed keeps the path in the grid: refuted, its step "
                   "condition applies only when L_k and L_k+1 are both grid cells (i < m, "
                   "j < n), so with N = m = n = 3 and every cell blocked a 3-cell list from "
                   "(0, 0) to (2, 2) through a cell outside the grid passes (cells are naturals, "
                   "as in HOL).", Z, R, _def4_off_grid,
                   summary=("Definition 4 as printed lets a path step through a cell outside the "
                            "grid: shown false on a 3 x 3 grid with every cell blocked.")),
        Obligation("Def4.is_path_fixed_safe", G, "Definition 4 fixed (docs/model.md §5)",
                   "The fixed is_path(L) implies that at every step k >= 0 the cell held is in "
                   "the grid and free in the layer in force (P[k] for k < N, the rest layer "
                   "after).", Z, P, _def4_fixed,
                   summary=("With Definition 4 fixed, a path holds at every step a cell of the "
                            "grid that is free in the layer in force (the rest layer once the "
                            "principal arm has stopped).")),
    ]


# --- searchoptpath's top level: Theorems 2 and 4 ----------------------------------------------

def search_top_level(st: _Setting, found: z3.BoolRef, R: Z3PathVar) -> tuple[If, z3.BoolRef]:
    """searchoptpath: report no path when the start is blocked at step 0 or the goal in the rest
    layer, else call the search, which returns null iff no path is valid, else an optimal one."""
    L = bound_path("none!L")
    no_path = z3.ForAll(L.consts(), z3.Not(st.valid(L)))
    contract = z3.And(z3.Implies(found, is_optimal(st.P, st.d, st.start, st.goal, R)),
                      z3.Implies(z3.Not(found), no_path))
    program = If(st.P[0, st.start[0], st.start[1]] == 1, Assign(found, z3.BoolVal(False)),
                 If(st.P[st.d.N, st.goal[0], st.goal[1]] == 1, Assign(found, z3.BoolVal(False)),
                    Seq((Havoc((found, R.xs, R.ys, R.length)), Assume(contract)))))
    return program, no_path


def _search_post(st: _Setting, found: z3.BoolRef, R: Z3PathVar, no_path: z3.BoolRef,
                 variant: str, printed: bool) -> z3.BoolRef:
    motion, rest, at_step = _regions(variant)
    region_r = z3.Function("regionR", z3.IntSort(), z3.IntSort(), REGION)
    k = z3.Int("post!k")
    pos = position(R, k)
    safe = z3.ForAll([k], z3.Implies(k >= 0, z3.Not(inter(at_step(k), region_r(pos[0], pos[1])))))
    parts = [z3.Implies(z3.Not(found), no_path),
             z3.Implies(found, is_optimal(st.P, st.d, st.start, st.goal, R)),
             z3.Implies(found, safe)]
    if printed:
        # The paper's postcondition: P[k] = 0 along the path for k < N, P[N-1] = 0 from N on.
        i, j = z3.Ints("post!i post!j")
        held = z3.And(pos[0] == i, pos[1] == j, in_grid(st.d, (i, j)))
        parts.append(z3.Implies(found, z3.ForAll([k, i, j], z3.Implies(
            z3.And(0 <= k, k < st.d.N, held), st.P[k, i, j] == 0))))
        if _own_rest(variant):
            # No layer N-1 reading here: the rest layer P[N] is free wherever the path waits.
            parts.append(z3.Implies(found, z3.ForAll([k, i, j], z3.Implies(
                z3.And(st.d.N <= k, held), st.P[st.d.N, i, j] == 0))))
        else:
            parts.append(z3.Implies(found, z3.ForAll([k, i, j], z3.Implies(
                z3.And(st.d.N <= k, k < R.length, held), st.P[st.d.N - 1, i, j] == 0))))
    return z3.And(parts)


def _search_vcs(variant: str, *, conservative: bool, printed: bool) -> tuple[VC, ...]:
    return _search(variant, conservative=conservative, printed=printed)[0]


def _search(variant: str, *, conservative: bool, printed: bool
            ) -> tuple[tuple[VC, ...], tuple[Smoke, ...]]:
    """The VCs of {pre} searchoptpath {post}, and the smoke tests of the program."""
    st = _setting()
    found = z3.Bool("found")
    R = z3_path("R")
    motion, rest, _ = _regions(variant)
    program, no_path = search_top_level(st, found, R)
    if conservative:
        pre_p = free_sound(st.P, st.d, motion, rest)
    else:
        pre_p = blocked_exact(st.P, st.d, motion=motion, rest=rest)
    pre = z3.And(st.d.sane(), in_grid(st.d, st.start), in_grid(st.d, st.goal), pre_p)
    post = _search_post(st, found, R, no_path, variant, printed)
    name = f"searchoptpath.{variant}"
    small = ((st.d.N, z3.IntVal(1)), (st.d.m, z3.IntVal(1)), (st.d.n, z3.IntVal(2)))
    return (verification_conditions(name, pre, program, post),
            smoke_tests(name, pre, program, witness=small, lemmas=(("no valid path", no_path),),
                        lemma_witness=_no_path_witness(st)))


def _no_path_witness(st: _Setting) -> tuple[tuple[z3.ExprRef, z3.ExprRef], ...]:
    """A D_R in which the search must report no path (for the smoke test of its contract's
    'not found' case): one cell, start = goal, N = 3, free at steps 0 and 2 and in the rest
    layer (layer N-1's copy), blocked at step 1, where every list is at that cell."""
    k, i, j = z3.Ints("nw!k nw!i nw!j")
    zero, three = z3.IntVal(0), z3.IntVal(3)
    return ((st.d.N, three), (st.d.m, z3.IntVal(1)), (st.d.n, z3.IntVal(1)),
            (st.start[0], zero), (st.start[1], zero), (st.goal[0], zero), (st.goal[1], zero),
            (st.P, z3.Lambda([k, i, j], z3.If(k == 1, z3.IntVal(1), zero))))


def _thm(variant: str) -> Z3Query:
    vcs, smoke = _search(variant, conservative=False, printed=True)
    return Z3Query(vcs, smoke=smoke)


def theorem_obligations() -> list[Obligation]:
    P, Z = Verdict.PROVED, Method.Z3
    text = ("{{P = Theorem {n}'s postcondition ({v} regions; rest layer = layer N-1)}} "
            "searchoptpath {{no path reported iff no valid path; else the result is an optimal "
            "valid path, collision-free at every step k >= 0 (no common point of SLarm and "
            "SRarm at the cell held), and the paper's postcondition: P[k] = 0 along it for k < N, "
            "P[N-1] = 0 for N <= k < LENGTH}}: WP of the top level, the search by its contract. "
            "Only the wrapper is proved: the search itself is assumed to meet its contract "
            "(ledger A6) until it is certified.")
    tight = ("{{P = {bid}'s postcondition ({v} regions regionL_{v}(k) for k < N; "
             "the rest layer P[N] from regionRest_{v}, the principal at rest at its goal, an "
             "opaque region independent of layer N-1)}} searchoptpath {{no path reported iff no "
             "valid path; else the result is an optimal valid path, collision-free at every "
             "step k >= 0 against regionL_{v}(k) for k < N and regionRest_{v} from N on, "
             "with P[k] = 0 along it for k < N and P[N] = 0 for every k >= N}}: WP of the top "
             "level, the search by its contract. The {v} variant's search safety. Only the "
             "wrapper is proved: the search itself is assumed to meet its contract (ledger A6).")
    out = []
    for v in Variant:
        r = v.rule
        bdr, thm = r.theorems
        ident = f"Thm{thm}.searchoptpath" + ("" if r.in_paper else f"_{v}")
        ref = f"Theorem {thm}" + ("" if r.in_paper else f", {v} variant ({r.source})")
        bid = f"Thm{bdr}.builtdr" + ("" if r.in_paper else f"_{v}")
        statement = (tight.format(v=v, bid=bid) if r.rest_at_goal
                     else text.format(n=bdr, v=v))
        out.append(Obligation(
            ident, GROUP_THM, ref, statement, Z, P, functools.partial(_thm, v.value),
            label=SEARCH_ASSUMED,
            summary=(f"Theorem {thm}{'' if r.in_paper else f', {v}'}: searchoptpath ({v}) "
                     "reports no path only when none exists, and otherwise returns a least-cost "
                     "path that is collision-free at every step; the search inside it is taken "
                     "at its contract unless its witness is checked.")))
    return out


# --- Property 8 and the corrected chain ---------------------------------------------------------

def _within(smaller: str, larger: str) -> z3.BoolRef:
    """SLarm'_k ⊆ SLarm_k at every layer k (as sets of points)."""
    ints = z3.IntSort()
    a = z3.Function(f"regionL_{smaller}", ints, REGION)
    b = z3.Function(f"regionL_{larger}", ints, REGION)
    k = z3.Int("w!k")
    x, y = z3.Reals("w!x w!y")
    return z3.ForAll([k, x, y], z3.Implies(member(a(k), (x, y)), member(b(k), (x, y))))


def _prop8_printed() -> Z3Query:
    st = _setting()
    m_o, _, _ = _regions("original")
    m_m, _, _ = _regions("modified")
    k, i, j = z3.Ints("k i j")
    hyps = st.base() + (("S'_k ⊆ S_k", _within("modified", "original")),
                        ("Inter means a common point", inter_definition()),
                        ("P per S (Theorem 1's postcondition)",
                         blocked_exact(st.P, st.d, motion=m_o)))
    goal = z3.Implies(z3.And(0 <= k, k < st.d.N, in_grid(st.d, (i, j))),
                      st.P[k, i, j] == z3.If(m_m(k, i, j), 1, 0))

    def render(m: z3.ModelRef) -> str:
        ev = lambda e: m.eval(e, model_completion=True)  # noqa: E731
        return (f"cell (k, i, j) = ({ev(k)}, {ev(i)}, {ev(j)}) of N = {ev(st.d.N)}, "
                f"m = {ev(st.d.m)}, n = {ev(st.d.n)}: SLarm_k meets SRarm_ij "
                f"({ev(m_o(k, i, j))}) so P = {ev(st.P[k, i, j])}, but SLarm'_k does not "
                f"({ev(m_m(k, i, j))}): the printed conclusion would need P = 0 there")
    return Z3Query((VC("conclusion", hyps, goal),), render=render)


def _prop8_intersection() -> Z3Query:
    ints = z3.IntSort()
    a = z3.Function("regionL_modified", ints, REGION)
    b = z3.Function("regionL_original", ints, REGION)
    k = z3.Int("k")
    r = z3.Const("SR", REGION)
    hyps = (("S'_k ⊆ S_k", _within("modified", "original")),
            ("Inter means a common point", inter_definition()))
    return Z3Query((VC("meets", hyps, z3.Implies(inter(a(k), r), inter(b(k), r)),
                       key_premise="S'_k ⊆ S_k"),))


def _meets_monotone() -> z3.BoolRef:
    """Prop8.intersection_monotone, for every layer k and region r."""
    ints = z3.IntSort()
    a = z3.Function("regionL_modified", ints, REGION)
    b = z3.Function("regionL_original", ints, REGION)
    k = z3.Int("mm!k")
    r = z3.Const("mm!r", REGION)
    return z3.ForAll([k, r], z3.Implies(inter(a(k), r), inter(b(k), r)))


def _prop8_monotone() -> Z3Query:
    st = _setting()
    P2 = _setting("P'").P
    m_o, r_o, _ = _regions("original")
    m_m, r_m, _ = _regions("modified")
    k, i, j = z3.Ints("k i j")
    hyps = st.base() + (("S'_k meets only what S_k meets (Prop8.intersection_monotone)",
                         _meets_monotone()),
                        ("P per S (Theorem 1)", blocked_exact(st.P, st.d, motion=m_o, rest=r_o)),
                        ("P' per S' (Theorem 3)", blocked_exact(P2, st.d, motion=m_m, rest=r_m)))
    goal = z3.Implies(z3.And(0 <= k, k <= st.d.N, in_grid(st.d, (i, j))), P2[k, i, j] <= st.P[k, i, j])
    return Z3Query((VC("pointwise", hyps, goal,
                       key_premise="S'_k meets only what S_k meets (Prop8.intersection_monotone)",
                       witness=((st.P, _all_blocked()), (P2, _all_blocked()))),))


def _below(st: _Setting, P2: z3.ArrayRef) -> z3.BoolRef:
    """0 <= P' <= P on every cell of every layer, the rest layer included."""
    k, i, j = z3.Ints("b!k b!i b!j")
    return z3.ForAll([k, i, j], z3.Implies(
        z3.And(0 <= k, k <= st.d.N, in_grid(st.d, (i, j))),
        z3.And(0 <= P2[k, i, j], P2[k, i, j] <= st.P[k, i, j])))


def _prop8_valid() -> Z3Query:
    st = _setting()
    P2 = _setting("P'").P
    L = z3_path("L")
    hyps = st.base() + (("0 <= P' <= P", _below(st, P2)), ("is_path under P", st.valid(L)))
    return Z3Query((VC("valid", hyps, st.valid(L, P2), key_premise="0 <= P' <= P"),))


def _prop8_exists() -> Z3Query:
    st = _setting()
    P2 = _setting("P'").P
    W = z3_path("W")
    L = bound_path("ex!L")
    hyps = st.base() + (("0 <= P' <= P", _below(st, P2)), ("a path W under P", st.valid(W)))
    goal = z3.Exists(L.consts(), st.valid(L, P2))
    # Z3's default solver took 1.9 M resource units, 0.4 s (0.02-0.55 s under other seeds);
    # its SMT core with the older simplex-based arithmetic solver (arith.solver 2) 19 k, under
    # 0.01 s, at most 0.04 s under every seed tried (docs/model.md §6.1).
    return Z3Query((VC("exists", hyps, goal, key_premise="0 <= P' <= P", z3_tactic="smt",
                       z3_tactic_params=(("arith.solver", 2),)),))


def _prop8_cost() -> Z3Query:
    st = _setting()
    P2 = _setting("P'").P
    O, O2 = z3_path("O"), z3_path("O'")
    # O' optimal under P': valid, and (Definition 5's universal, instantiated at O, named) no
    # worse than O if O is valid under P'. O optimal under P: only its validity is needed.
    hyps = st.base() + (("0 <= P' <= P", _below(st, P2)),
                        ("O valid under P (O optimal under P)", st.valid(O)),
                        ("O' optimal under P', instance at O",
                         z3.Implies(st.valid(O, P2), lex_le(costs(O2), costs(O)))))
    return Z3Query((VC("cost", hyps, lex_le(costs(O2), costs(O)), key_premise="0 <= P' <= P"),))


def _all_blocked() -> z3.ExprRef:
    """D_R with every cell blocked: a model for vacuity checks that need one."""
    k, i, j = z3.Ints("ab!k ab!i ab!j")
    return z3.Lambda([k, i, j], z3.IntVal(1))


def _prestrength() -> Z3Query:
    """Theorem 4 from Theorem 2 by precondition strengthening, with the right premise."""
    st = _setting()
    generic, generic_smoke = _search(GENERIC, conservative=True, printed=False)
    main_x = generic[0]
    m_m, r_m, _ = _regions("modified")
    exact = blocked_exact(st.P, st.d, motion=m_m, rest=r_m)
    strengthen = VC("strengthen", (("Theorem 4's precondition", exact),),
                    free_sound(st.P, st.d, m_m, r_m), key_premise="Theorem 4's precondition")
    # The rule itself, on the roles of the formulas: pre4 (Theorem 4's precondition), weak
    # (the conservative precondition at X := S'; 'strengthen' proves pre4 => weak) and wp (the
    # weakest precondition of searchoptpath for Q at S'; the generic VC proves weak => wp for
    # every region family X, so for S'). Abstracted to Booleans: pre4 is strong enough to give
    # wp directly (that is Thm4.searchoptpath), which would hide whether the rule is used.
    pre4, weak, wp = z3.Bools("pre4 weak_pre_at_S' wp_searchoptpath_Q")
    rule = VC("rule", (("Theorem 4's precondition holds", pre4),
                       ("strengthen: pre4 ⇒ weak", z3.Implies(pre4, weak)),
                       ("Theorem 2 (generic) at X := S': weak ⇒ wp", z3.Implies(weak, wp))),
              wp, key_premise="strengthen: pre4 ⇒ weak")
    return Z3Query((strengthen, main_x, *generic[1:], rule), smoke=generic_smoke)


def prop8_obligations() -> list[Obligation]:
    """Property 8 as printed (refuted) and the corrected chain."""
    P, R, Z = Verdict.PROVED, Verdict.REFUTED_AS_EXPECTED, Method.Z3
    G = GROUP_P8
    return [
        Obligation("Prop8.printed", G, "Property 8 as printed",
                   "S'_k ⊆ S_k and P per S (Theorem 1's postcondition) imply P per S' (Theorem "
                   "3's): refuted, a cell where S_k meets SRarm and S'_k does not.",
                   Z, R, _prop8_printed,
                   summary=("Property 8 as printed (a smaller swept region keeps Theorem 1's D_R "
                            "valid for Theorem 3) is false: a cell blocked for the larger region "
                            "may be free for the smaller one.")),
        Obligation("Prop8.intersection_monotone", G, "Property 8, corrected",
                   "S'_k ⊆ S_k implies: S'_k meets a region only if S_k does.",
                   Z, P, _prop8_intersection,
                   definitional="the definition of a subset, at a point",
                   summary=("A smaller swept region can meet the other arm only where the larger "
                            "one does.")),
        Obligation("Prop8.subset_monotone", G, "Property 8, corrected",
                   "S' ⊆ S (every layer; used through Prop8.intersection_monotone) with P per S "
                   "and P' per S' implies P' <= P on every cell of every layer, the rest layer "
                   "included.", Z, P, _prop8_monotone,
                   summary=("Smaller swept regions in every layer block no more cells of D_R, the "
                            "rest layer included.")),
        Obligation("Prop8.valid_transfer", G, "Property 8, corrected",
                   "0 <= P' <= P implies: a path valid under D is valid under D'.",
                   Z, P, _prop8_valid,
                   summary=("A path valid for the larger swept regions stays valid for the smaller "
                            "ones.")),
        Obligation("Prop8.path_exists", G, "Property 8, corrected",
                   "0 <= P' <= P implies: a path exists under D' whenever one exists under D.",
                   Z, P, _prop8_exists,
                   summary=("Whenever a path exists for the larger swept regions, one exists for "
                            "the smaller ones.")),
        Obligation("Prop8.optimal_cost", G, "Property 8, corrected",
                   "0 <= P' <= P implies: the optimal (J1, J2) under D' is lexicographically <= "
                   "the optimal under D (for any costs J1, J2; D''s optimality instantiated at "
                   "D's optimum, named).", Z, P, _prop8_cost,
                   summary=("The least cost of a path for the smaller swept regions is at most the "
                            "least cost for the larger ones.")),
        Obligation("Prop8.prestrength_thm4", G, "Pre-strength rule, Theorems 2 and 4",
                   "Theorem 2 holds for an arbitrary region family X (motion layers "
                   "regionL_X(k), and a rest region regionRest_X independent of them, so the "
                   "generic theorem covers a rest layer of layer N-1 and the tight one alike) "
                   "under the weaker precondition 'P = 0 implies no intersection' (all its "
                   "safety needs); Theorem "
                   "4's precondition implies that precondition at X := S'; by the rule "
                   "(P' ⇒ P, {P} C {Q} give {P'} C {Q}) Theorem 4's safety follows. (The paper "
                   "derives it from Property 8, which runs the other way and is not valid.)",
                   Z, P, _prestrength, label=SEARCH_ASSUMED,
                   summary=("Theorem 4's safety follows from Theorem 2 stated for any regions, by "
                            "strengthening its precondition; the paper's route through Property 8 "
                            "is not valid.")),
    ]
