"""The witness checker is sound (docs/model.md §11): its local conditions imply its answer.

``spec.check_witness`` accepts a found path when labels on the capped states pass
``witness.start``, ``witness.edge`` and ``witness.goal``, and a no-path answer when a set of
states passes ``witness.start``, ``witness.closure`` and ``witness.exclusion``. Here, for
arbitrary grids (N, m, n symbolic, D_R any integer array), those conditions are hypotheses and
the answers are proved by an inductive invariant over the prefixes of any valid path L (the
fixed ``is_path``): padded with the goal, L holds the cell ``c(k) = position(L, k)`` at step k,
arriving by the move ``p(k) = c(k) - c(k - 1)`` (``p(0) = (0, 0)``), for k = 0 .. T with
T = max(LENGTH L - 1, N); its state at step k is ``(min(k, N), c(k), p(k))``.

- ``Witness.labels_sound``: the invariant "the state at step k is labelled, at most the cost of
  the first k moves" holds at k = 0 (the start condition), is kept from k to k + 1 (the edge
  condition at the path's own edge), and at k = T bounds C, the least goal label, by L's cost.
- ``Witness.reachable_sound``: the invariant "the state at step k is in the set" holds at 0,
  is kept by closure, and at T contradicts the exclusion: no list is a valid path.

The checker's start, edge and goal conditions are not restated here: ``spec``'s own functions
(``start_label_breaks``, ``step_cost``, ``label_key``, ``edge_bound``, ``edge_holds``,
``label_in_range``, ``goal_holds``), which ``check_witness`` calls on numpy arrays, are called
on Z3 terms, so a loosened condition fails ``labels.base``, ``labels.step`` or
``labels.optimal``; the reachable set's conditions are
``start_breaks``, ``closure_breaks`` and ``exclusion_breaks``, likewise run on Z3 terms (a
loosened one fails ``reachable.base``, ``reachable.step`` or ``reachable.conclusion``). The goal
condition in ``labels.conclusion`` is the checker's comparison of keys (``label_key`` plus
``stop_key``'s |p|_1, the least key split back into (J1, J2)), with witness.form's range at the
goal states, which makes the key order the lexicographic one.
``labels.optimal`` closes the chain: the returned path's recomputed cost Q passes the checker's
goal comparison against C, and the conclusion's C <= (J1, J2)(L) gives Q <= (J1, J2)(L).

Each has four VCs (labels five, with ``optimal``): the induction's base, its step (split in
two: ``walk``, that is_path makes
L's edge k a free edge to its state at k + 1; and ``step``, that the edge or closure condition
at that edge keeps the invariant), and its conclusion; the induction principle over 0 .. T
(what the while rule is for a loop) joins them. The checker tests its edge condition at every
edge; the VCs use it at L's edge k, an instance named (ledger A8). L's costs are their prefix
sums over the padded moves, ``A1[k + 1] = A1[k] + |d_k|_1`` and
``A2[k + 1] = A2[k] + |d_k - d_{k-1}|_1`` with ``d_k = p(k + 1)``, and
``(J1, J2)(L) = (A1[T], A2[T] + |d_{T-1}|_1)``: the spec's J1 and J2 (padding with the goal adds
nothing; tests/proofs/test_obl_witness.py checks the two agree). Labels, sets and costs are
unconstrained integer (Boolean) arrays, so the proof covers any witness, not the search's alone.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import z3

from ..spec import (
    KEY_BASE,
    closure_breaks,
    edge_bound,
    edge_holds,
    exclusion_breaks,
    goal_holds,
    label_in_range,
    label_key,
    start_breaks,
    start_label_breaks,
    step_cost,
    stop_key,
)
from ..spec.z3defs import (
    Z3Dims,
    Z3PathVar,
    abs_int,
    in_grid,
    is_path_fixed,
    lex_le,
    position,
    z3_path,
)
from ._obligation import VC, Method, Obligation, Verdict, Z3Query

__all__ = ["GROUP", "witness_obligations", "witness_vcs"]

GROUP = "Witness checker (certifying search)"

Cell = tuple[z3.ArithRef, z3.ArithRef]
Hyp = tuple[str, z3.BoolRef]
State = tuple[z3.ArithRef, ...]


@dataclass(frozen=True)
class _World:
    """The symbolic grid, D_R, endpoints, a list L, and L's walk through the capped states."""

    d: Z3Dims
    P: z3.ArrayRef
    start: Cell
    goal: Cell
    L: Z3PathVar

    @property
    def T(self) -> z3.ArithRef:
        """The walk's last step: max(LENGTH L - 1, N)."""
        return z3.If(self.L.length - 1 > self.d.N, self.L.length - 1, self.d.N)

    def step(self, k: z3.ArithRef) -> z3.ArithRef:
        """The capped step min(k, N): the layer in force."""
        return z3.If(k < self.d.N, k, self.d.N)

    def cell(self, k: z3.ArithRef) -> Cell:
        return position(self.L, k)

    def prev(self, k: z3.ArithRef) -> Cell:
        """The move that arrived at step k: c(k) - c(k - 1), the rest move (0, 0) at k = 0."""
        c, b = self.cell(k), self.cell(k - 1)
        return (z3.If(k == 0, 0, c[0] - b[0]), z3.If(k == 0, 0, c[1] - b[1]))

    def state(self, k: z3.ArithRef) -> State:
        c, p = self.cell(k), self.prev(k)
        return (self.step(k), c[0], c[1], p[0], p[1])

    def base(self) -> tuple[Hyp, ...]:
        return (("N >= 1, m, n >= 1", self.d.sane()),
                ("start, goal in the grid", z3.And(in_grid(self.d, self.start),
                                                   in_grid(self.d, self.goal))),
                ("is_path L (the fixed definition)",
                 is_path_fixed(self.P, self.d, self.start, self.goal, self.L)))


def _world() -> _World:
    ints = z3.IntSort()
    return _World(Z3Dims.named(), z3.Array("P", ints, ints, ints, ints),
                  (z3.Int("start.i"), z3.Int("start.j")), (z3.Int("goal.i"), z3.Int("goal.j")),
                  z3_path("L"))


def _move(x: z3.ArithRef) -> z3.BoolRef:
    return z3.And(-1 <= x, x <= 1)


def _state_array(name: str, sort: z3.SortRef) -> z3.ArrayRef:
    """A value per state (s, i, j, pi, pj): a witness's labels or its set."""
    ints = z3.IntSort()
    return z3.Array(name, ints, ints, ints, ints, ints, sort)


def _edge_parts(w: _World, src: State, d: Cell) -> tuple[z3.BoolRef, z3.BoolRef, State]:
    """(an edge from a free state: 0 <= s <= N, the cell in the grid and free in layer s, p and
    d moves, cell + d in the grid; its target free in layer min(s + 1, N); the target state
    (min(s + 1, N), cell + d, d))."""
    s, i, j, pi, pj = src
    N = w.d.N
    t = z3.If(s + 1 < N, s + 1, N)
    target = (t, i + d[0], j + d[1], d[0], d[1])
    edge = z3.And(0 <= s, s <= N, in_grid(w.d, (i, j)), w.P[s, i, j] == 0,
                  _move(pi), _move(pj), _move(d[0]), _move(d[1]),
                  in_grid(w.d, (i + d[0], j + d[1])))
    return edge, w.P[t, i + d[0], j + d[1]] == 0, target


def _free_edge(w: _World, src: State, d: Cell) -> tuple[z3.BoolRef, State]:
    """(the move d from state ``src`` is a free edge: an edge from a free state to a free
    target, its target state)."""
    edge, target_free, target = _edge_parts(w, src, d)
    return z3.And(edge, target_free), target


def _edge_condition(w: _World, mark: z3.ArrayRef, then: Callable[[State, State, Cell], z3.BoolRef],
                    src: State, d: Cell) -> z3.BoolRef:
    """The checker's edge condition at one edge: if it is a free edge from a state marked in
    ``mark``, then ``then(source, target, d)``."""
    free, target = _free_edge(w, src, d)
    return z3.Implies(z3.And(free, mark[src]), then(src, target, d))


def _walk(w: _World, k: z3.ArithRef) -> z3.BoolRef:
    """L's edge k is a free edge, and its target is L's state at step k + 1."""
    free, target = _free_edge(w, w.state(k), w.prev(k + 1))
    return z3.And(free, *[a == b for a, b in zip(target, w.state(k + 1))])


#: The proof check's solver of the walk and step VCs (``VC.z3_tactic``): Z3's SMT core with
#: E-matching off, its quantifiers instantiated by MBQI alone. Measured: labels.walk and
#: reachable.walk (one statement) took Z3's default solver 2.5 M resource units, 0.5 s, each,
#: labels.step 2.2 M, 0.5 s; this solver 0.19 M and 0.32 M, 0.06 s and 0.11 s, and 0.05-0.18 s
#: under every seed tried, where the default's seeds ranged 0.2-0.7 s (docs/model.md §6.1).
_MBQI: tuple[str, tuple[tuple[str, bool | int], ...]] = ("smt", (("ematching", False),))


def _walk_vc(w: _World, name: str) -> VC:
    k = z3.Int("k")
    dims, cells, valid = w.base()
    return VC(name, (dims, cells, valid, ("0 <= k < T", z3.And(0 <= k, k < w.T))), _walk(w, k),
              key_premise=valid[0], z3_tactic=_MBQI[0], z3_tactic_params=_MBQI[1])


def labels_step_pins(k: z3.ArithRef, w: _World) -> tuple[tuple[z3.ExprRef, z3.ExprRef], ...]:
    """The constants ``labels.step``'s vacuity check pins (``VC.witness``): edge k = 0 of a
    list of one cell (LENGTH L = 1) on a 2 x 2 grid with one layer (N = 1)."""
    return ((k, z3.IntVal(0)), (w.d.N, z3.IntVal(1)), (w.L.length, z3.IntVal(1)),
            (w.d.m, z3.IntVal(2)), (w.d.n, z3.IntVal(2)))


def _labels_vcs() -> tuple[VC, ...]:
    w = _world()
    has = _state_array("label.has", z3.BoolSort())
    lab1, lab2 = _state_array("label.J1", z3.IntSort()), _state_array("label.J2", z3.IntSort())
    ints = z3.IntSort()
    A1, A2 = z3.Array("A1", ints, ints), z3.Array("A2", ints, ints)
    C = (z3.Int("C.J1"), z3.Int("C.J2"))
    Q = (z3.Int("Q.J1"), z3.Int("Q.J2"))

    def label(x: State) -> tuple[z3.ArithRef, z3.ArithRef]:
        return lab1[x], lab2[x]

    def key(x: State) -> z3.ArithRef:
        return label_key(lab1[x], lab2[x])

    def edge_ok(src: State, dst: State, d: Cell) -> z3.BoolRef:
        # spec.check_witness's own condition, run on Z3 terms: keys, not pairs.
        cost = step_cost((d[0], d[1]), (src[3], src[4]))
        return z3.And(has[dst], edge_holds(key(dst), edge_bound(key(src), cost)))

    def in_range(x: State) -> z3.BoolRef:
        return z3.Implies(has[x], z3.And(0 <= lab1[x], 0 <= lab2[x],
                                         label_in_range(lab1[x], lab2[x])))

    k = z3.Int("k")
    kk = z3.Int("pre!k")
    d_k = w.prev(kk + 1)
    p_k = w.prev(kk)
    prefix = ("A1, A2: the costs of L's prefixes (J1, J2 summed over the padded moves)", z3.And(
        A1[0] == 0, A2[0] == 0,
        z3.ForAll([kk], z3.Implies(z3.And(0 <= kk, kk < w.T), z3.And(
            A1[kk + 1] == A1[kk] + abs_int(d_k[0]) + abs_int(d_k[1]),
            A2[kk + 1] == A2[kk] + abs_int(d_k[0] - p_k[0]) + abs_int(d_k[1] - p_k[1]))))))
    origin = (0, w.start[0], w.start[1], 0, 0)
    # spec.check_witness's own start test (start_label_breaks), run on Z3 terms; the checker
    # reads "no label" as the type's largest value in both arrays (witness.form), > 0.
    start = ("witness.start: the start state's label is (0, 0) (start_label_breaks false)",
             z3.Not(start_label_breaks(lab1[origin], lab2[origin])))
    none = z3.Int("none")
    unlabelled = ("witness.form at the start state: without a label it holds the no-label value "
                  "(the type's largest, > 0)",
                  z3.And(none > 0, z3.Implies(z3.Not(has[origin]), lab1[origin] == none)))
    edge = ("witness.edge at L's edge k: label[s'] <= label[s] + cost if it is a free edge from "
            "a labelled state", _edge_condition(w, has, edge_ok, w.state(k), w.prev(k + 1)))
    form = ("witness.form at L's states k, k + 1: labels unsigned, in range",
            z3.And(in_range(w.state(k)), in_range(w.state(k + 1))))
    qi, qj = z3.Ints("g!pi g!pj")
    at_goal = (w.d.N, w.goal[0], w.goal[1], qi, qj)
    # The checker's own comparison, run on Z3 terms: C is the least key (label_key plus
    # stop_key's |p|_1) over the labelled admissible goal states, split back into (J1, J2).
    goal = ("witness.goal: key(C) <= stop_key(key(label), p) at every labelled admissible goal "
            "state (C: the least such key, split)",
            z3.ForAll([qi, qj], z3.Implies(
                z3.And(_move(qi), _move(qj), has[at_goal], w.P[w.d.N, w.goal[0], w.goal[1]] == 0),
                label_key(C[0], C[1]) <= stop_key(key(at_goal), (qi, qj)))))
    split = ("C's J2 is the least key's low 32 bits: 0 <= C.J2 < KEY_BASE",
             z3.And(0 <= C[1], C[1] < KEY_BASE))
    goal_form = ("witness.form at the goal states: labels unsigned, in range",
                 z3.ForAll([qi, qj], in_range(at_goal)))

    def inv(x: z3.ArithRef) -> z3.BoolRef:
        return z3.And(has[w.state(x)], lex_le(label(w.state(x)), (A1[x], A2[x])))

    last = w.prev(w.T)
    cost_L = (A1[w.T], A2[w.T] + abs_int(last[0]) + abs_int(last[1]))
    dims = w.base()[0]
    return (
        VC("labels.base", w.base() + (prefix, start, unlabelled), inv(z3.IntVal(0)),
           key_premise=start[0]),
        _walk_vc(w, "labels.walk"),
        VC("labels.step", (dims, prefix, ("L's edge k is a free edge to its state at k + 1 "
                                           "(VC labels.walk)", _walk(w, k)),
                           edge, form, ("0 <= k < T", z3.And(0 <= k, k < w.T)),
                           ("invariant at k", inv(k))),
           inv(k + 1), key_premise=edge[0],
           # The vacuity check's model, pinned where it is smallest: the first edge of a
           # one-cell list on a 2 x 2 grid of one layer. Unpinned, Z3 spent 4.5 M of its
           # resource units (a second) to find such a model; pinned, 32 k.
           witness=labels_step_pins(k, w), z3_tactic=_MBQI[0], z3_tactic_params=_MBQI[1]),
        VC("labels.conclusion", w.base() + (prefix, goal, split, goal_form,
                                            ("invariant at T", inv(w.T))),
           lex_le(C, cost_L), key_premise=goal[0]),
        # The returned path's recomputed (J1, J2) = Q passes witness.goal (the checker's own
        # comparison, run on Z3 terms) and C <= (J1, J2)(L) for any valid L (the conclusion's
        # goal, verbatim): Q <= (J1, J2)(L), the returned path is optimal.
        VC("labels.optimal", (("witness.goal's comparison: Q equals C", goal_holds(Q, C)),
                              ("C <= (J1, J2)(L) (VC labels.conclusion)", lex_le(C, cost_L))),
           lex_le(Q, cost_L), key_premise="witness.goal's comparison: Q equals C"),
    )


def _reachable_vcs() -> tuple[VC, ...]:
    w = _world()
    S = _state_array("reach", z3.BoolSort())
    origin = (0, w.start[0], w.start[1], 0, 0)
    # spec.check_witness's own conditions (start_breaks, closure_breaks, exclusion_breaks), run
    # on Z3 terms: the checker rejects where they hold, so the VCs assume they do not.
    start = ("witness.start: the start state in S when the start is free in layer 0",
             z3.Not(start_breaks(w.P[0, w.start[0], w.start[1]] == 0, S[origin])))
    k = z3.Int("k")
    edge_k, target_free, target = _edge_parts(w, w.state(k), w.prev(k + 1))
    closure = ("witness.closure at L's edge k: it ends in S if it is a free edge from S",
               z3.Implies(edge_k, z3.Not(closure_breaks(S[w.state(k)], target_free,
                                                         S[target]))))
    qi, qj = z3.Ints("x!pi x!pj")
    exclusion = ("witness.exclusion: no admissible goal state in S",
                 z3.ForAll([qi, qj], z3.Implies(z3.And(_move(qi), _move(qj)), z3.Not(
                     exclusion_breaks(w.P[w.d.N, w.goal[0], w.goal[1]] == 0,
                                      S[w.d.N, w.goal[0], w.goal[1], qi, qj])))))

    def inv(x: z3.ArithRef) -> z3.BoolRef:
        return S[w.state(x)]

    dims, cells, valid = w.base()
    return (
        VC("reachable.base", (dims, cells, valid, start), inv(z3.IntVal(0)),
           key_premise=start[0]),
        _walk_vc(w, "reachable.walk"),
        VC("reachable.step", (dims, ("L's edge k is a free edge to its state at k + 1 (VC "
                                     "reachable.walk)", _walk(w, k)), closure,
                              ("0 <= k < T", z3.And(0 <= k, k < w.T)), ("invariant at k", inv(k))),
           inv(k + 1), key_premise=closure[0]),
        # Not assuming is_path L here: the conclusion is that L is not a valid path.
        VC("reachable.conclusion", (dims, cells, exclusion,
                                    ("invariant at T (for a valid L)", inv(w.T))),
           z3.Not(valid[1]), key_premise=exclusion[0]),
    )


def witness_vcs(kind: str) -> tuple[VC, ...]:
    """The VCs of ``Witness.labels_sound`` (kind "labels") or ``Witness.reachable_sound``."""
    return _labels_vcs() if kind == "labels" else _reachable_vcs()


def witness_obligations() -> list[Obligation]:
    P, Z = Verdict.PROVED, Method.Z3
    return [
        Obligation(
            "Witness.labels_sound", GROUP, "ours: McConnell et al.'s certifying algorithms",
            "For every grid (N >= 1, m, n >= 1), D_R, start and goal, and any labels (J1, J2) "
            "on the capped states (step min(k, N), cell, previous move) and C: if the start "
            "state is labelled (0, 0) or less (witness.start), every free edge from a labelled "
            "state ends at a labelled state with label[s'] <= label[s] + (|d|_1, |d - p|_1) "
            "lexicographically (witness.edge), and C <= label + (0, |p|_1) at every labelled "
            "admissible goal state (N, goal, p) (witness.goal), then every valid path L (the "
            "fixed is_path) has (J1, J2)(L) >= C. By induction over L's prefixes, padded with "
            "the goal to T = max(LENGTH L - 1, N) moves: the state held at step k is labelled "
            "at most the first k moves' cost (VCs base; walk and step, with the edge condition "
            "at L's own edge, a named instance: ledger A8); the last is an admissible goal "
            "state (VC conclusion). The edge condition is spec's own (edge_holds on label keys, "
            "run on Z3 terms, with witness.form's range); VC optimal: a returned path whose "
            "cost passes spec's goal_holds against C is no worse than any valid L (Definition "
            "5): spec.check_witness's acceptance is sound (ledger A6).",
            Z, P, lambda: Z3Query(_labels_vcs()),
            summary=("When the cost labels the search hands over pass the witness checker, no "
                     "valid path costs less than the path returned: the path is optimal.")),
        Obligation(
            "Witness.reachable_sound", GROUP, "ours: McConnell et al.'s certifying algorithms",
            "For every grid, D_R, start and goal, and any set S of capped states: if S holds "
            "the start state when the start is free in layer 0 (witness.start), every free "
            "edge from a state of S ends in S (witness.closure), and S holds no admissible "
            "goal state when the goal is free in the rest layer (witness.exclusion), then no "
            "list L is a valid path: by induction over a valid L's prefixes its states stay in "
            "S (VCs base; walk and step, closure at L's own edge), and its last is an "
            "admissible goal state (VC conclusion). So spec.check_witness's acceptance of 'no "
            "path' is sound (ledger A6).",
            Z, P, lambda: Z3Query(_reachable_vcs()),
            summary=("When the search reports no path and the set of reachable states it hands "
                     "over passes the witness checker, no valid path exists.")),
    ]
