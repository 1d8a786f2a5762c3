"""Mutation self-check: evidence that the contracts can fail. Each fault is seeded into BuiltDR,
the grid or searchoptpath, the planner runs under contracts, and we record what caught it.

Every fault must be caught in ``full`` mode (optimality there through a witness that the spec's
checker verifies: the forged witness fault hands it a false one); the table also records what
``sampled`` catches (with
a SAMPLE-cell sample, about 1% of the small grids used here; the default 4096 cells are 0.06% of
the default grid). Runs use ``stop=False``, so every postcondition that fails is listed, not
only the first. Each construction asserts its own defining property with direct computations
(not through the checker), so a fault that failed to take shape is an error, never a pass.

Workcells (built in, so ``cfmpa selftest`` needs no files): ``small``, the default workcell at
dt = 0.25 s (grid 7 x 27 x 27) with start and goal chosen so a path exists; ``early-arrival``,
the bundled scenarios/early-arrival.toml at dt = 0.11 s (grid 16 x 59 x 59; the bundled
dt = 0.04 s gives 1.06M cells, too slow for a unit test, and runs in a slow test instead).
"""

from __future__ import annotations

import copy
import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import Any, TextIO

import numpy as np
import numpy.typing as npt

from ..errors import CertificateViolation, CfmpaError, ContractViolation
from ..impl import build_dr, search_opt_path, search_opt_path_fast
from ..scenarios import SELFCHECK_WORKCELLS
from ..spec import (
    J1,
    J2,
    MOVES,
    Grid,
    Scenario,
    SearchResult,
    SearchStatus,
    Variant,
    Witness,
    exact_tf,
    is_path_paper,
    make_grid,
    opt_path,
    parse_scenario,
)
from ._contracts import Mode
from ._plan import plan

__all__ = ["FAULTS", "Fault", "FaultNotMade", "Mutant", "Outcome", "SAMPLE", "SelftestRow",
           "WORKCELLS", "run_fault", "run_selftest", "selftest_rows", "selftest_table", "workcell"]

#: Cells of the sampled mode's random sample in the self-check (the seed is 0).
SAMPLE = 64

#: The self-check's workcells, as scenario documents (docs/model.md §3); cfmpa prove's negative
#: controls use them too (cfmpa.scenarios).
WORKCELLS = SELFCHECK_WORKCELLS

DR = npt.NDArray[np.uint8]
Cell = tuple[int, int]


@dataclass(frozen=True)
class Mutant:
    """What a fault replaces in the planner: the grid, the builder, the search (None: keep)."""

    grid: Grid | None = None
    build: Callable[[Scenario, Variant, Grid], DR] | None = None
    search: Callable[[DR, Cell, Cell], SearchResult] | None = None
    detail: str = ""


@dataclass(frozen=True)
class Fault:
    """A seeded fault: its name, workcell, variant, and how it is made from the scenario."""

    name: str
    workcell: str
    variant: Variant
    make: Callable[[Scenario, Variant, Grid], Mutant]


@dataclass(frozen=True)
class Outcome:
    """One run of a faulty planner: the violations raised or recorded, as 'triple: condition'."""

    mode: Mode
    caught_by: tuple[str, ...]
    other_error: str | None = None

    @property
    def caught(self) -> bool:
        return bool(self.caught_by)


@dataclass(frozen=True)
class SelftestRow:
    """A fault, whether full and sampled mode caught it, by what, and the fault's size."""

    fault: str
    workcell: str
    caught_full: bool
    caught_sampled: bool
    caught_by: str
    caught_by_sampled: str
    detail: str


class FaultNotMade(AssertionError):
    """A fault's construction did not produce the fault it names (a bug in the self-check)."""


def _require(ok: bool, what: str) -> None:
    if not ok:
        raise FaultNotMade(what)


# --- the faults ---------------------------------------------------------------------------------


def _flip_blocked_cell(s: Scenario, v: Variant, g: Grid) -> Mutant:
    """A blocked cell on the border of free space (where an off-by-eps bug would bite) set free."""
    dr = build_dr(s, v, g)
    free = dr == 0
    near_free = np.zeros_like(free)
    near_free[:, 1:] |= free[:, :-1]
    near_free[:, :-1] |= free[:, 1:]
    near_free[:, :, 1:] |= free[:, :, :-1]
    near_free[:, :, :-1] |= free[:, :, 1:]
    border = np.argwhere((dr == 1) & near_free)
    _require(len(border) > 0, "D_R has no blocked cell next to a free one")
    k, i, j = (int(x) for x in border[np.random.default_rng(0).integers(len(border))])

    def build(s2: Scenario, v2: Variant, g2: Grid) -> DR:
        out = build_dr(s2, v2, g2)
        _require(out[k, i, j] == 1, "the chosen cell is not blocked")
        out[k, i, j] = 0
        return out

    return Mutant(build=build, detail=f"layer {k}, cell ({i}, {j}) set free (1 faulty cell)")


def _no_arc_margin(s: Scenario, v: Variant, g: Grid) -> Mutant:
    """impl's regions without the interpolation margin delta (hull of the lattice rectangles)."""
    def build(s2: Scenario, v2: Variant, g2: Grid) -> DR:
        return build_dr(s2, v2, g2, margin_scale=0.0)

    right = build_dr(s, v, g)
    wrong = build(s, v, g)
    flipped = int((right != wrong).sum())
    _require(flipped > 0 and bool(np.all(wrong <= right)),
             "dropping the margin freed no cell (or blocked one)")
    return Mutant(build=build, detail=f"margin 0 frees {flipped} of {right.size} cells")


def _n_rounded_down(s: Scenario, v: Variant, g: Grid) -> Mutant:
    """N = floor(Tf / dt): the layers end before the principal arrives."""
    n = math.floor(exact_tf(s) / Fraction(s.dt))
    _require(1 <= n < g.N, "Tf / dt is an integer here, so rounding down changes nothing")
    return Mutant(grid=replace(g, N=n), detail=f"N = {n} instead of {g.N} (N dt = "
                  f"{n * s.dt:.3f} s < Tf = {g.Tf:.3f} s)")


def _coarse_grid(s: Scenario, v: Variant, g: Grid) -> Mutant:
    """m_q and n from a spacing of 2 omega_q dt instead of omega_q dt."""
    R = s.right
    pts = [math.ceil((R.limits[q][1] - R.limits[q][0]) / (2 * R.omega[q] * s.dt)) + 1
           for q in range(2)]
    h = tuple((R.limits[q][1] - R.limits[q][0]) / (pts[q] - 1) for q in range(2))
    _require(all(h[q] > R.omega[q] * s.dt for q in range(2)), "the coarse grid is not coarse")
    bad = replace(g, m=pts[0], n=pts[1], h=(h[0], h[1]))
    return Mutant(grid=bad, detail=f"grid {pts[0]} x {pts[1]}, h = {h[0]:.4f} rad > omega dt "
                  f"= {R.omega[0] * s.dt:.4f} rad")


def _non_optimal(s: Scenario, v: Variant, g: Grid) -> Mutant:
    """A valid path with true costs that is not the least: the optimum with one cell blocked."""
    def search(dr: DR, start: Cell, goal: Cell) -> SearchResult:
        return _worse_path(dr.shape, dr.tobytes(), tuple(start), tuple(goal))

    return Mutant(search=search, detail="the optimum with one of its cells blocked; true costs "
                  "reported")


@functools.lru_cache(maxsize=2)
def _worse_path(shape: tuple[int, ...], cells: bytes, start: Cell, goal: Cell) -> SearchResult:
    """_non_optimal's path on D_R (``shape``, ``cells``: its bytes): one search per table, as
    full and sampled mode, and the forged witness, ask for it on the same one."""
    dr = np.frombuffer(cells, dtype=np.uint8).reshape(shape)
    best = search_opt_path(dr, start, goal)
    _require(best.status is SearchStatus.FOUND, "no path to make worse")
    N = dr.shape[0] - 1
    for k in range(1, len(best.path) - 1):
        more = dr.copy()
        more[min(k, N), best.path[k][0], best.path[k][1]] = 1   # more blocked: still valid
        # Whether a blocked cell makes the optimum worse depends only on the least (J1, J2)
        # and whether a path exists, which every kernel computes alike (docs/model.md §5;
        # tests/impl/test_kernels.py): the fast kernel screens each cell in a fraction of a
        # millisecond, and the spec's search, whose path is the fault's, runs only on a cell
        # the screen finds worse. A screen that missed a worse cell would show as a different
        # path (tests/runs/test_selftest_screen.py).
        screen = search_opt_path_fast(more, start, goal)
        if screen.status is not SearchStatus.FOUND or (screen.J1, screen.J2) <= (best.J1,
                                                                                 best.J2):
            continue
        alt = opt_path(more, start, goal)
        if alt.status is SearchStatus.FOUND and (alt.J1, alt.J2) > (best.J1, best.J2):
            return SearchResult.found(alt.path, J1(alt.path), J2(alt.path))
    raise FaultNotMade("no single blocked cell makes the optimum worse")


def _opt_path_of(dr: DR, start: Cell, goal: Cell) -> SearchResult:
    """The spec's ``opt_path(dr, start, goal)``, searched once per table, start and goal
    (``_opt_path_cached``): a fault's search runs in full and in sampled mode on the same D_R
    (docs/model.md §7.3), and the spec's search is the slow one."""
    if dr.dtype != np.uint8:            # only D_R's own type is keyed by its bytes
        return opt_path(dr, start, goal)
    return _opt_path_cached(dr.shape, dr.tobytes(), (int(start[0]), int(start[1])),
                            (int(goal[0]), int(goal[1])))


@functools.lru_cache(maxsize=2)
def _opt_path_cached(shape: tuple[int, ...], cells: bytes, start: Cell, goal: Cell
                     ) -> SearchResult:
    """The spec's opt_path on the table ``cells`` (its bytes) of ``shape``: keyed by every cell,
    so a table that differs anywhere is searched anew."""
    return opt_path(np.frombuffer(cells, dtype=np.uint8).reshape(shape), start, goal)


def _forged_witness(s: Scenario, v: Variant, g: Grid) -> Mutant:
    """The non-optimal path with a forged witness: the optimum's labels, with every goal state's
    label raised so that the least goal label (plus the stop term) is the path's cost."""
    worse_search = _non_optimal(s, v, g).search
    assert worse_search is not None                # _non_optimal replaces the search

    def search(dr: DR, start: Cell, goal: Cell) -> SearchResult:
        worse = worse_search(dr, start, goal)
        best = search_opt_path(dr, start, goal, with_witness=True)
        labels = best.witness                      # with_witness: a found path's labels
        assert labels is not None and labels.j1 is not None and labels.j2 is not None
        j1, j2 = np.array(labels.j1), np.array(labels.j2)     # copies, held whole
        N, (gi, gj) = dr.shape[0] - 1, goal
        stop = np.abs(np.asarray(MOVES)).sum(axis=1)
        j1[N, :, gi, gj] = worse.J1
        j2[N, :, gi, gj] = np.maximum(worse.J2 - stop, 0)
        least = min((int(a), int(b) + int(c)) for a, b, c in zip(j1[N, :, gi, gj],
                                                                  j2[N, :, gi, gj], stop))
        _require(least == (worse.J1, worse.J2) and least > (best.J1, best.J2),
                 "the forged goal labels do not claim the worse path's cost")
        return replace(worse, witness=Witness.of_labels(j1, j2))

    return Mutant(search=search, detail="the non-optimal path, the optimum's labels raised at "
                  "the goal to its cost; true costs reported")


def _jump(s: Scenario, v: Variant, g: Grid) -> Mutant:
    """The optimal path with one cell dropped where that leaves a step of 2 in a coordinate."""
    def search(dr: DR, start: Cell, goal: Cell) -> SearchResult:
        best = search_opt_path(dr, start, goal)
        p = list(best.path)
        for k in range(1, len(p) - 1):
            if max(abs(p[k + 1][0] - p[k - 1][0]), abs(p[k + 1][1] - p[k - 1][1])) == 2:
                q = p[:k] + p[k + 1:]
                return SearchResult.found(q, J1(q), J2(q))
        raise FaultNotMade("the optimal path has no two steps in one direction")

    return Mutant(search=search, detail="one cell dropped from the optimum: a step of 2; "
                  "true costs reported")


def _early_arrival(s: Scenario, v: Variant, g: Grid) -> Mutant:
    """The paper's is_path: a path that arrives before the principal sweeps the goal and waits."""
    def search(dr: DR, start: Cell, goal: Cell) -> SearchResult:
        N = dr.shape[0] - 1
        # Waiting at the goal is not checked: the goal is taken as free at every step.
        blind = dr.copy()
        blind[:, goal[0], goal[1]] = 0
        r = _opt_path_of(blind, start, goal)
        _require(r.status is SearchStatus.FOUND, "no path even with the goal always free")
        p = list(r.path)
        later = [k for k in range(len(p), N + 1) if dr[k, goal[0], goal[1]]]
        _require(bool(later) and is_path_paper(p, dr, start, goal),
                 "the path does not arrive early at a goal swept later, or fails the paper's "
                 "is_path")
        return SearchResult.found(p, J1(p), J2(p))

    return Mutant(search=search, detail="passes the paper's is_path (steps < LENGTH only)")


def _rest_layer(s: Scenario, v: Variant, g: Grid) -> Mutant:
    """A path that, after step N, crosses a cell blocked in the rest layer R."""
    def search(dr: DR, start: Cell, goal: Cell) -> SearchResult:
        N = dr.shape[0] - 1
        blind = dr.copy()
        blind[N] = 0                        # the rest layer is ignored
        r = _opt_path_of(blind, start, goal)
        _require(r.status is SearchStatus.FOUND, "no path even with R ignored")
        p = list(r.path)
        in_r = [k for k in range(N, len(p)) if dr[N, p[k][0], p[k][1]]]
        early = [k for k in range(min(N, len(p))) if dr[k, p[k][0], p[k][1]]]
        _require(bool(in_r) and not early, "the path crosses no R-blocked cell after step N, or "
                 "is blocked before N")
        return SearchResult.found(p, J1(p), J2(p))

    return Mutant(search=search, detail="the optimum over D_R with R cleared")


FAULTS: tuple[Fault, ...] = (
    Fault("blocked cell flipped to free", "small", Variant.MODIFIED, _flip_blocked_cell),
    Fault("regions without the arc margin", "small", Variant.MODIFIED, _no_arc_margin),
    Fault("N rounded down", "small", Variant.MODIFIED, _n_rounded_down),
    Fault("cell grid coarser than omega dt", "small", Variant.MODIFIED, _coarse_grid),
    Fault("non-optimal path", "small", Variant.MODIFIED, _non_optimal),
    Fault("forged witness", "small", Variant.MODIFIED, _forged_witness),
    Fault("path with a jump", "small", Variant.MODIFIED, _jump),
    Fault("path ends early at a goal swept later", "early-arrival", Variant.MODIFIED,
          _early_arrival),
    Fault("path through a blocked cell in the rest layer", "small", Variant.MODIFIED,
          _rest_layer),
)


# --- running ------------------------------------------------------------------------------------


def workcell(name: str, **changes: Any) -> Scenario:
    """A built-in workcell as a validated Scenario; ``changes`` replace top-level keys."""
    doc = copy.deepcopy(WORKCELLS[name])
    doc.update(changes)
    return parse_scenario(doc, check_budget=False)


def run_fault(fault: Fault, mode: Mode | str, *, scenario: Scenario | None = None,
              sample: int = SAMPLE, seed: int = 0, mutant: Mutant | None = None
              ) -> tuple[Outcome, str]:
    """Plan with the fault seeded, contracts in ``mode``: (what caught it, the fault's size).
    ``mutant``: the fault as made already from ``scenario`` (None: made here)."""
    s = scenario or workcell(fault.workcell)
    g = make_grid(s)
    m = mutant or fault.make(s, fault.variant, g)
    kwargs: dict[str, Any] = {k: v for k, v in (("grid", m.grid), ("build", m.build),
                                                ("search", m.search)) if v is not None}
    try:
        p = plan(s, fault.variant, contracts=mode, seed=seed, sample=sample, stop=False, **kwargs)
    except ContractViolation as exc:        # a failed precondition always stops the run
        return Outcome(Mode(mode), (_name(exc),)), m.detail
    except CfmpaError as exc:               # stopped, but not by a contract: not "caught"
        return Outcome(Mode(mode), (), f"{type(exc).__name__}: {exc}"), m.detail
    return Outcome(Mode(mode), tuple(dict.fromkeys(_name(v) for v in p.violations))), m.detail


def _name(v: ContractViolation) -> str:
    if isinstance(v, CertificateViolation):
        return "certificate: " + ("contact" if "distance_m" in v.values else "undecided")
    return f"{v.triple.split(' [')[0]} {v.condition.split(':')[0]}"


def selftest_rows(*, sample: int = SAMPLE, seed: int = 0) -> tuple[SelftestRow, ...]:
    """Every fault run in full and in sampled mode."""
    rows = []
    for f in FAULTS:
        # One workcell and one fault for both modes (making a fault builds D_R, some twice).
        s = workcell(f.workcell)
        m = f.make(s, f.variant, make_grid(s))
        full, detail = run_fault(f, Mode.FULL, scenario=s, sample=sample, seed=seed, mutant=m)
        sampled, _ = run_fault(f, Mode.SAMPLED, scenario=s, sample=sample, seed=seed, mutant=m)
        rows.append(SelftestRow(
            fault=f.name, workcell=f.workcell, caught_full=full.caught,
            caught_sampled=sampled.caught, caught_by=_by(full), caught_by_sampled=_by(sampled),
            detail=detail))
    return tuple(rows)


def _by(o: Outcome) -> str:
    if o.caught:
        return "; ".join(o.caught_by)
    return f"not caught ({o.other_error})" if o.other_error else "not caught"


def selftest_table(rows: tuple[SelftestRow, ...], *, sample: int = SAMPLE, seed: int = 0) -> str:
    """The table ``cfmpa selftest`` prints: fault, caught by, mode."""
    head = ("fault", "mode", "caught by")
    lines = [(r.fault, mode, by) for r in rows
             for mode, by in (("full", r.caught_by), ("sampled", r.caught_by_sampled))]
    w = [max(len(x[c]) for x in [head, *lines]) for c in range(2)]
    out = [f"{head[0]:<{w[0]}}  {head[1]:<{w[1]}}  {head[2]}",
           f"{'-' * w[0]}  {'-' * w[1]}  {'-' * 9}"]
    out += [f"{a:<{w[0]}}  {b:<{w[1]}}  {c}" for a, b, c in lines]
    out.append("")
    out += [f"{r.fault}: {r.detail} [{r.workcell}]" for r in rows]
    out.append(f"sampled: {sample} random cells (seed {seed}) plus the cells the path occupies; "
               "full: every cell, and optimality through a witness verified by the spec")
    return "\n".join(out)


def run_selftest(*, stdout: TextIO | None = None, stderr: TextIO | None = None) -> int:
    """`cfmpa selftest`: seed every fault, print the table and the verdict on ``stdout``
    (default sys.stdout at call time; ``stderr`` is for errors only, which are raised); 0 iff
    full mode caught every one."""
    import sys

    so = sys.stdout if stdout is None else stdout
    rows = selftest_rows()
    print(selftest_table(rows), file=so)
    missed = [r.fault for r in rows if not r.caught_full]
    if missed:
        print(f"NOT CAUGHT in full mode: {', '.join(missed)}", file=so)
        return 1
    print(f"all {len(rows)} faults caught in full mode; "
          f"{sum(r.caught_sampled for r in rows)} of {len(rows)} in sampled mode", file=so)
    return 0
