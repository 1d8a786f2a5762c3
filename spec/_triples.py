"""The paper's Hoare triples {P} C {Q} as values, with executable pre- and postconditions.

Theorem 1/3 (BuiltDR) and Theorem 2/4 (searchoptpath) from Li et al., plus the same triples for
the ``tight`` variant (ours). Each condition is named; the predicates below return the
``Failure`` values of the conditions that do not hold (empty: all hold on the data checked).
They are the spec's: regions and distances from ``_builtdr_post``, paths from ``_paths``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum
from fractions import Fraction
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from ..errors import ContractViolation
from ._counts import SPAN_TOLERANCE, decimal, spacing_conditions
from ._grid import Grid, Variant, exact_tf
from ._layers import layered
from ._paths import J1, J2, SearchResult, SearchStatus, path_violations
from ._scenario import Scenario

if TYPE_CHECKING:     # shapely's geometry, for the postcondition only (docs/model.md §7.5)
    from ._builtdr_post import CellMismatch

__all__ = [
    "Command",
    "Condition",
    "Failure",
    "Triple",
    "THEOREM_1",
    "THEOREM_2",
    "THEOREM_3",
    "THEOREM_3_TIGHT",
    "THEOREM_4",
    "THEOREM_4_TIGHT",
    "TRIPLES",
    "SPAN_TOLERANCE",
    "builtdr_triple",
    "search_triple",
    "grid_failures",
    "cells_failures",
    "dr_shape_failures",
    "dr_cell_failures",
    "path_cells",
    "cost_failures",
    "search_failures",
]

#: SPAN_TOLERANCE (from spec/_counts.py): how far (rad) the last grid point lo + (m - 1) h may sit
#: from the upper joint limit; the construction (joint_grid) confirms it with the same tolerance.


class Command(str, Enum):
    """The program C of a triple."""

    BUILT_DR = "BuiltDR"
    SEARCH = "searchoptpath"

    def __str__(self) -> str:
        return self.value


@dataclass(frozen=True)
class Condition:
    """One conjunct of a pre- or postcondition: a short id (``post.cells``) and its statement."""

    id: str
    text: str


@dataclass(frozen=True)
class Failure:
    """A condition that does not hold: which, what was seen, and the values involved.

    ``count`` is how many instances failed (cells, steps); ``values`` describe the first.
    """

    condition: str
    message: str
    values: tuple[tuple[str, Any], ...] = ()
    count: int = 1


@dataclass(frozen=True)
class Triple:
    """A Hoare triple {P} C {Q} of the paper (or ours, for ``tight``), printable for the report."""

    name: str
    title: str
    reference: str
    command: Command
    variant: Variant
    program: str
    precondition: tuple[Condition, ...]
    postcondition: tuple[Condition, ...]
    note: str

    @property
    def label(self) -> str:
        """Name and title as violations name the triple: ``Theorem 3 [BuiltDR, modified]``."""
        return f"{self.name} [{self.title}]"

    def condition(self, cid: str) -> Condition:
        """The pre- or postcondition conjunct with this id."""
        for c in self.precondition + self.postcondition:
            if c.id == cid:
                return c
        raise KeyError(f"{self.name} has no condition {cid!r}")

    def violation(self, failure: Failure) -> ContractViolation:
        """The project's error for ``failure``: this triple, the condition, one line per value."""
        values = dict(failure.values)
        if failure.count > 1:
            values["instances failing"] = failure.count
        return ContractViolation(self.label,
                                 f"{failure.condition}: {failure.message}", values,
                                 condition_id=failure.condition, message=failure.message)

    def __str__(self) -> str:
        def block(conds: tuple[Condition, ...]) -> list[str]:
            lines = [f"  [{c.id}] {c.text}" for c in conds]
            return [("{ " + lines[0][2:]) if i == 0 else "    and " + line[2:]
                    for i, line in enumerate(lines)] if lines else ["{ T"]

        pre = block(self.precondition)
        post = block(self.postcondition)
        return "\n".join([f"{self.label} -- {self.reference}", *pre[:-1],
                          pre[-1] + " }", f"  {self.program}", *post[:-1], post[-1] + " }",
                          f"  note: {self.note}"])


# --- the triples ------------------------------------------------------------------------------

_GRID_PRE = (
    Condition("pre.grid.N", "N >= 1 and N * dt >= Tf in exact arithmetic, in both readings "
              "(binary: the doubles; decimal: the numbers as written): the layers cover the "
              "principal's whole motion"),
    Condition("pre.grid.h", "(hi_q - lo_q)/(m_q - 1) <= omega_q * dt for both joints exactly "
              "in the decimal reading (the speed limit as the file states it); the float h_q "
              "within rounding (1e-10 relative) of omega_q * dt in both readings and <= 157/50 "
              "rad (the margin lemma's bound); and the m x n grid points span the subordinate's "
              "joint limits"),
    Condition("pre.grid.scenario", "the grid's dt, Tf and lower limits are the scenario's"),
    Condition("pre.cells", "the start and goal cells lie inside the m x n grid"),
)

_REGION = {
    Variant.ORIGINAL: "S_LArm[k] swept over [theta_L(k dt) -+ omega dt] (two-sided, Algorithm 1)",
    Variant.MODIFIED: "S'_LArm[k] swept over [theta_L(k dt), theta_L(k dt) + s omega dt] "
                      "(one-sided, Section IV.A)",
    Variant.TIGHT: "S''_LArm[k] swept over [theta_L(k dt), theta_L((k+1) dt)] (the planned "
                   "interval)",
}


def _builtdr(name: str, variant: Variant, reference: str, note: str) -> Triple:
    region = _REGION[variant]
    rest = "the principal at rest at its goal" if variant.rest_at_goal else "layer N-1"
    return Triple(
        name=name, title=f"BuiltDR, {variant.value}", reference=reference,
        command=Command.BUILT_DR, variant=variant,
        program=f"D_R := BuiltDR(scenario, grid)   [{variant.value}: {region}]",
        precondition=_GRID_PRE,
        postcondition=(
            Condition("post.shape", "D_R is uint8 of shape (N + 1, m, n) holding only 0 and 1"),
            Condition("post.cells", "forall k <= N, i < m, j < n: P[k, i, j] = (dist(S_LArm[k], "
                      f"S_RArm[i][j]) > eps -> 0 | 1), eps = 1e-9 m; layer N is the rest layer "
                      f"R ({rest})"),
        ),
        note=note)


_DR_NAME = {Variant.ORIGINAL: "D_R", Variant.MODIFIED: "D'_R", Variant.TIGHT: "D''_R (tight)"}


def _search(name: str, variant: Variant, built: Triple, reference: str, note: str) -> Triple:
    return Triple(
        name=name, title=f"searchoptpath over {_DR_NAME[variant]}", reference=reference,
        command=Command.SEARCH, variant=variant,
        program="L := searchoptpath(D_R, startp, goalp)",
        precondition=(
            Condition("pre.dr.shape", "D_R is uint8 of shape (N + 1, m, n) holding only 0 and 1"),
            Condition("pre.cells", "startp and goalp lie inside the m x n grid"),
            Condition("pre.dr.spec", f"D_R satisfies {built.name}'s postcondition [post.cells]"),
        ),
        postcondition=(
            Condition("post.is_path", "L <> Null ==> is_path(L, startp, goalp): steps of -1, 0 or "
                      "+1 per coordinate, every step k < max(LENGTH L, N) free in its layer "
                      "(P[k] for k < N, R after) and the goal free in R (docs/model.md §5)"),
            Condition("post.costs", "L <> Null ==> the reported J1 and J2 are J1(L) and J2(L)"),
            Condition("post.optimal", "L <> Null ==> (J1, J2)(L) is the least over all valid "
                      "paths, lexicographically (Definition 5); L = Null ==> no valid path exists"),
        ),
        note=note)


THEOREM_1 = _builtdr("Theorem 1", Variant.ORIGINAL, "Li et al., Section III.B, Theorem 1",
                     "the paper's precondition is T; ours states the grid the proof takes for "
                     "granted (docs/model.md §2)")
THEOREM_3 = _builtdr("Theorem 3", Variant.MODIFIED, "Li et al., Section IV.B, Theorem 3",
                     "the paper's precondition is T; ours states the grid the proof takes for "
                     "granted (docs/model.md §2)")
THEOREM_3_TIGHT = _builtdr("Theorem 3 (tight)", Variant.TIGHT,
                           "ours: Theorem 3 with the tight box of docs/model.md §4",
                           "the rest layer is the principal at its goal, not layer N-1")
_PAPER_PATH = ("the paper's postcondition checks steps k < LENGTH(L) only, against P[N-1] after N; "
               "ours uses the fixed is_path and adds costs and optimality (Definition 5)")
THEOREM_2 = _search("Theorem 2", Variant.ORIGINAL, THEOREM_1,
                    "Li et al., Section III.B, Theorem 2", _PAPER_PATH)
THEOREM_4 = _search("Theorem 4", Variant.MODIFIED, THEOREM_3,
                    "Li et al., Section IV.B, Theorem 4", _PAPER_PATH)
THEOREM_4_TIGHT = _search("Theorem 4 (tight)", Variant.TIGHT, THEOREM_3_TIGHT,
                          "ours: Theorem 4 over the tight D_R", _PAPER_PATH)

TRIPLES: tuple[Triple, ...] = (THEOREM_1, THEOREM_2, THEOREM_3, THEOREM_4, THEOREM_3_TIGHT,
                               THEOREM_4_TIGHT)


def builtdr_triple(variant: Variant | str) -> Triple:
    """Theorem 1 (original), Theorem 3 (modified) or Theorem 3 (tight)."""
    v = Variant(variant)
    return {Variant.ORIGINAL: THEOREM_1, Variant.MODIFIED: THEOREM_3,
            Variant.TIGHT: THEOREM_3_TIGHT}[v]


def search_triple(variant: Variant | str) -> Triple:
    """Theorem 2 (over D_R), Theorem 4 (over D'_R) or Theorem 4 (tight)."""
    v = Variant(variant)
    return {Variant.ORIGINAL: THEOREM_2, Variant.MODIFIED: THEOREM_4,
            Variant.TIGHT: THEOREM_4_TIGHT}[v]


# --- executable conditions --------------------------------------------------------------------


def grid_failures(s: Scenario, grid: Grid) -> list[Failure]:
    """pre.grid.*: the grid is well formed for the scenario (exact rationals where it matters)."""
    out: list[Failure] = []
    tf = exact_tf(s)
    times = Grid.time_readings(s)
    grid_dt = {"binary": Fraction(grid.dt), "decimal": decimal(grid.dt)}
    n_ok = isinstance(grid.N, int) and grid.N >= 1
    short = [r for r in Grid.READINGS if n_ok and not grid.N * grid_dt[r] >= times[r][1]]
    if not n_ok or short:
        r = short[0] if short else "binary"
        dt_r, tf_r = grid_dt[r], times[r][1]
        out.append(Failure("pre.grid.N", "the time grid ends before the principal arrives",
                           (("N", grid.N), ("dt_s", grid.dt), ("reading", r),
                            ("N * dt_s", float(grid.N * dt_r) if n_ok else None),
                            ("Tf_s", float(tf_r)))))
    R = s.right
    bad_h: list[tuple[int, str, Fraction, Fraction]] = []
    for q, points in enumerate((grid.m, grid.n)):
        if not (isinstance(points, int) and points >= 2):
            continue  # reported below, as points that do not span the limits
        # The conditions joint_grid builds the grid to meet (spec/_counts.py, docs/model.md §2).
        conds = spacing_conditions(R.limits[q][0], R.limits[q][1], R.omega[q], s.dt, points,
                                   grid.h[q])
        bad = [(q, f"{c.what}, {c.reading}", c.value, c.bound) for c in conds if not c.holds]
        bad_h += bad[:1]
    if bad_h:
        q, r, h, step = bad_h[0]
        out.append(Failure("pre.grid.h", f"joint {q + 1}'s grid spacing exceeds omega * dt",
                           (("joint", q + 1), ("reading", r), ("h_rad", float(h)),
                            ("omega * dt_rad", float(step)),
                            ("points", grid.m if q == 0 else grid.n)), count=len(bad_h)))
    for q, points in enumerate((grid.m, grid.n)):
        lo, hi = R.limits[q]
        last = grid.lo[q] + (points - 1) * grid.h[q]
        if points < 2 or abs(last - hi) > SPAN_TOLERANCE:
            out.append(Failure("pre.grid.h", f"joint {q + 1}'s grid points do not span its limits",
                               (("joint", q + 1), ("points", points), ("last point_rad", last),
                                ("limits_rad", [lo, hi]))))
    same = (grid.dt == s.dt and grid.Tf == float(tf)
            and tuple(grid.lo) == (R.limits[0][0], R.limits[1][0]))
    if not same:
        out.append(Failure("pre.grid.scenario", "the grid is not the scenario's",
                           (("grid dt, Tf, lo", [grid.dt, grid.Tf, list(grid.lo)]),
                            ("scenario dt, Tf, lo", [s.dt, float(tf),
                                                     [R.limits[0][0], R.limits[1][0]]]))))
    return out


def cells_failures(grid: Grid, start: Sequence[int], goal: Sequence[int]) -> list[Failure]:
    """pre.cells: start and goal are (i, j) inside the grid."""
    bad = [(name, c) for name, c in (("start", start), ("goal", goal))
           if not (len(c) == 2 and 0 <= c[0] < grid.m and 0 <= c[1] < grid.n)]
    return [Failure("pre.cells", f"the {name} cell lies outside the grid",
                    ((name, list(c)), ("grid m x n", [grid.m, grid.n])), count=len(bad))
            for name, c in bad[:1]]


def dr_shape_failures(grid: Grid, dr: Any, condition: str = "post.shape") -> list[Failure]:
    """D_R is a uint8 array of the grid's shape (N + 1, m, n) with values 0 and 1 only."""
    shape = tuple(getattr(dr, "shape", ()))
    dtype = getattr(dr, "dtype", type(dr).__name__)
    if shape != grid.shape or dtype != np.uint8:
        return [Failure(condition, "D_R has the wrong shape or element type",
                        (("shape", list(shape)), ("expected shape", list(grid.shape)),
                         ("dtype", str(dtype)), ("expected dtype", "uint8")))]
    a = layered(dr)                          # a Layers (a store) stays one (§9, §11)
    count = 0
    first: tuple[int, ...] | None = None
    for layer in range(a.shape[0]):          # a layer at a time: no D_R-sized temporary
        bad = np.flatnonzero(a[layer].ravel() > 1)
        count += bad.size
        if bad.size and first is None:
            first = (layer, *np.unravel_index(int(bad[0]), a.shape[1:]))
    if first is not None:
        k, i, j = (int(x) for x in first)
        return [Failure(condition, "D_R holds values other than 0 and 1",
                        (("layer", k), ("cell", [i, j]), ("value", int(dr[k, i, j]))),
                        count=count)]
    return []


def dr_cell_failures(s: Scenario, variant: Variant | str, grid: Grid,
                     dr: npt.NDArray[np.uint8], cells: npt.NDArray[np.int64] | None = None, *,
                     limit: int = 1000) -> tuple[int, list[Failure]]:
    """post.cells at ``cells`` ((C, 3) of k, i, j) or at every cell: (cells checked, failures).

    The count of failing cells is exact up to ``limit``, then a lower bound ("at least").
    """
    from ._builtdr_post import dr_postcondition  # shapely: loaded by the check alone

    rep = dr_postcondition(s, variant, grid, dr, cells=cells, limit=limit)
    if rep.ok:
        return rep.checked, []
    first: CellMismatch = rep.mismatches[0]
    n = len(rep.mismatches)
    word = "free" if first.got == 0 else "blocked"
    values = (("layer", first.layer), ("cell", list(first.cell)),
              ("angles_rad", list(first.angles)), ("distance_m", first.distance_m),
              ("D_R value", first.got), ("expected", first.expected))
    if n >= limit:
        values += (("cells failing", f"at least {n}"),)
    return rep.checked, [Failure("post.cells", f"a cell is {word} in D_R against the spec's "
                                 "regions", values, count=n)]


def path_cells(path: Sequence[Sequence[int]], N: int) -> npt.NDArray[np.int64]:
    """(k, i, j) of every cell the path occupies: step k < max(len, N) in its layer, and R.

    These are the D_R entries a path's safety rests on (the subordinate holds its last cell).
    """
    cells = np.asarray([tuple(c) for c in path], dtype=np.int64).reshape(-1, 2)
    if len(cells) == 0:
        return np.zeros((0, 3), dtype=np.int64)
    steps = np.arange(max(len(cells), N))
    at = cells[np.minimum(steps, len(cells) - 1)]
    layer = np.minimum(steps, N)
    out = np.concatenate([np.column_stack([layer, at]), [[N, *cells[-1]]]])
    return np.unique(out, axis=0)


def cost_failures(result: SearchResult) -> list[Failure]:
    """post.costs: a found path's reported J1 and J2 are J1(L) and J2(L) (needs no D_R)."""
    if result.status is not SearchStatus.FOUND:
        return []
    path = list(result.path)
    costs = [J1(path), J2(path)]
    if [result.J1, result.J2] == costs:
        return []
    return [Failure("post.costs", "the reported costs are not the path's",
                    (("reported J1, J2", [result.J1, result.J2]), ("recomputed J1, J2", costs)))]


def search_failures(dr: npt.NDArray[np.integer], start: Sequence[int], goal: Sequence[int],
                    result: SearchResult, optimum: SearchResult | None = None) -> list[Failure]:
    """post.is_path, post.costs and (when ``optimum`` is given) post.optimal.

    ``optimum`` is an independent search's answer over the same D_R. post.optimal judges the
    path's own (J1, J2), recomputed, never the reported numbers: a misreported cost is
    post.costs's failure alone. Reasons for "no path" are not compared (only that no path
    exists): another planner may word them differently.
    """
    out: list[Failure] = []
    found = result.status is SearchStatus.FOUND
    costs: tuple[int, int] | None = None
    if found:
        path = list(result.path)
        bad = path_violations(path, dr, tuple(start), tuple(goal))
        if bad:
            v = bad[0]
            values = tuple((name, value) for name, value in (
                ("clause", v.clause), ("step", v.step),
                ("cell", None if v.cell is None else list(v.cell)), ("layer", v.layer))
                if value is not None)
            out.append(Failure("post.is_path", v.message, values, count=len(bad)))
        costs = (J1(path), J2(path))
        out += cost_failures(result)
    if optimum is None:
        return out
    if optimum.status is not result.status:
        if costs is not None:
            msg = "a path is reported where no valid path exists"
            values = (("path's J1, J2", list(costs)),
                      ("independent search", f"no path ({optimum.reason})"))
        else:
            msg = "no path is reported but a valid path exists"
            values = (("reported", f"no path ({result.reason})"),
                      ("optimal J1, J2", [optimum.J1, optimum.J2]),
                      ("optimal path starts", [list(c) for c in optimum.path[:5]]))
        out.append(Failure("post.optimal", msg, values))
    elif costs is not None and costs != (optimum.J1, optimum.J2):
        below = costs < (optimum.J1, optimum.J2)
        out.append(Failure("post.optimal", "the path's (J1, J2) is below the least over valid "
                           "paths (so the path is not valid)" if below else
                           "the path's (J1, J2) is not the least",
                           (("path's J1, J2 (recomputed)", list(costs)),
                            ("optimal J1, J2", [optimum.J1, optimum.J2]),
                            ("optimal path length", len(optimum.path)))))
    return out
