"""The paper's definitions as Z3 terms over symbolic data (sets, D_R arrays, paths).

Sets of points are predicates (Z3 arrays Real x Real -> Bool), as in the paper's HOL4 model;
D_R is an integer array indexed (k, i, j); a path is two integer arrays and a length. These
terms are what ``cfmpa.proofs`` hands to Z3: a proof about them is a proof about the paper's
definitions, read as written here (the docstrings say where we depart from the printed text).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import z3

__all__ = [
    "POINT_SET",
    "REGION",
    "Z3Dims",
    "Z3PathVar",
    "abs_int",
    "adjacent",
    "Blocked",
    "blocked_exact",
    "bound_path",
    "convex_instance",
    "costs",
    "free_sound",
    "is_optimal",
    "lex_le",
    "hull_instance",
    "hull_member",
    "in_grid",
    "inter",
    "inter_definition",
    "is_convex",
    "is_path_fixed",
    "is_path_paper",
    "layer_value",
    "member",
    "position",
    "segment_member",
    "segment_member_paper",
    "subset",
    "z3_path",
]

#: A set of points of the plane, as a predicate (Definition 1-3's ``Point set``).
POINT_SET = z3.ArraySort(z3.RealSort(), z3.RealSort(), z3.BoolSort())
#: A region (swept polygon) as the algorithm handles it: an opaque value with a membership test.
REGION = z3.DeclareSort("Region")

Vec = tuple[z3.ArithRef, z3.ArithRef]


# --- Definitions 1-3: segment, is_convex, convex hull ------------------------------------------

def segment_member(x: Vec, y: Vec, z: Vec, t: z3.ArithRef) -> z3.BoolRef:
    """z = t x + (1 - t) y with 0 <= t <= 1: z is on segment x y with the weight t as witness.

    Definition 1 as intended; the printed text has ``(t - 1) * y``, see ``segment_member_paper``.
    """
    return z3.And(0 <= t, t <= 1, z[0] == t * x[0] + (1 - t) * y[0],
                  z[1] == t * x[1] + (1 - t) * y[1])


def segment_member_paper(x: Vec, y: Vec, z: Vec, t: z3.ArithRef) -> z3.BoolRef:
    """Definition 1 exactly as printed: z = t x + (t - 1) y with 0 <= t <= 1."""
    return z3.And(0 <= t, t <= 1, z[0] == t * x[0] + (t - 1) * y[0],
                  z[1] == t * x[1] + (t - 1) * y[1])


def subset(a: z3.ArrayRef, b: z3.ArrayRef) -> z3.BoolRef:
    """a ⊆ b for two point sets."""
    p, q = z3.Reals("sub!x sub!y")
    return z3.ForAll([p, q], z3.Implies(a[p, q], b[p, q]))


def is_convex(z: z3.ArrayRef) -> z3.BoolRef:
    """Definition 2: for x, y in z, every point of segment x y is in z."""
    x0, x1, y0, y1, t = z3.Reals("cvx!x0 cvx!x1 cvx!y0 cvx!y1 cvx!t")
    return z3.ForAll([x0, x1, y0, y1, t], z3.Implies(
        z3.And(z[x0, x1], z[y0, y1], 0 <= t, t <= 1),
        z[t * x0 + (1 - t) * y0, t * x1 + (1 - t) * y1]))


def convex_instance(z: z3.ArrayRef, x: Vec, y: Vec, t: z3.ArithRef) -> z3.BoolRef:
    """Definition 2's universal instantiated at the named points x, y and weight t."""
    return z3.Implies(z3.And(z[x[0], x[1]], z[y[0], y[1]], 0 <= t, t <= 1),
                      z[t * x[0] + (1 - t) * y[0], t * x[1] + (1 - t) * y[1]])


def hull_member(x: z3.ArrayRef, p: Vec) -> z3.BoolRef:
    """Definition 3: p lies in every convex superset of x (the intersection of all of them)."""
    y = z3.Const("hull!Y", POINT_SET)
    return z3.ForAll([y], z3.Implies(z3.And(is_convex(y), subset(x, y)), y[p[0], p[1]]))


def hull_instance(x: z3.ArrayRef, y: z3.ArrayRef, p: Vec) -> z3.BoolRef:
    """Definition 3's universal instantiated at the named set y: the witness a proof supplies.

    ``hull_member(x, p)`` implies this for every y, so assuming it is sound, and proving a goal
    with it in a negative position proves the goal with ``hull_member``.
    """
    return z3.Implies(z3.And(is_convex(y), subset(x, y)), y[p[0], p[1]])


# --- Regions and the intersection test (Theorem 1's SLarm ∩ SRarm) -----------------------------

def member(region: z3.ExprRef, p: Vec) -> z3.BoolRef:
    """p is a point of the region (an uninterpreted membership relation)."""
    mem = z3.Function("mem", REGION, z3.RealSort(), z3.RealSort(), z3.BoolSort())
    return mem(region, p[0], p[1])


def inter(a: z3.ExprRef, b: z3.ExprRef) -> z3.BoolRef:
    """The algorithm's intersection test on two regions, uninterpreted: ``(a ∩ b) <> Φ``."""
    f = z3.Function("Inter", REGION, REGION, z3.BoolSort())
    return f(a, b)


def inter_definition() -> z3.BoolRef:
    """The test means what the paper says: Inter(a, b) iff some point lies in both regions."""
    a, b = z3.Consts("idef!a idef!b", REGION)
    x, y = z3.Reals("idef!x idef!y")
    return z3.ForAll([a, b], inter(a, b) == z3.Exists([x, y], z3.And(member(a, (x, y)),
                                                                     member(b, (x, y)))))


# --- D_R and paths (Definition 4, docs/model.md §5) ---------------------------------------------------

@dataclass(frozen=True)
class Z3Dims:
    """The symbolic sizes: N motion layers (D_R has N + 1 with the rest layer), m x n cells."""

    N: z3.ArithRef
    m: z3.ArithRef
    n: z3.ArithRef

    @classmethod
    def named(cls, prefix: str = "") -> Z3Dims:
        return cls(z3.Int(f"{prefix}N"), z3.Int(f"{prefix}m"), z3.Int(f"{prefix}n"))

    def sane(self) -> z3.BoolRef:
        """N >= 1 motion layers and a nonempty grid (what make_grid guarantees)."""
        return z3.And(self.N >= 1, self.m >= 1, self.n >= 1)


@dataclass(frozen=True)
class Z3PathVar:
    """A path as a list: cells (xs[k], ys[k]) for 0 <= k < length; entries past it unspecified."""

    xs: z3.ArrayRef
    ys: z3.ArrayRef
    length: z3.ArithRef

    def cell(self, k: z3.ArithRef | int) -> tuple[z3.ArithRef, z3.ArithRef]:
        """L_k, the list's k-th element (unspecified past the end, as HOL's EL)."""
        return self.xs[k], self.ys[k]

    def consts(self) -> list[z3.ExprRef]:
        return [self.xs, self.ys, self.length]


def z3_path(prefix: str) -> Z3PathVar:
    """A symbolic path named by ``prefix``."""
    ints = z3.IntSort()
    return Z3PathVar(z3.Array(f"{prefix}.x", ints, ints), z3.Array(f"{prefix}.y", ints, ints),
                     z3.Int(f"{prefix}.len"))


def abs_int(e: z3.ArithRef) -> z3.ArithRef:
    return z3.If(e >= 0, e, -e)


def adjacent(a: tuple[z3.ArithRef, z3.ArithRef], b: tuple[z3.ArithRef, z3.ArithRef]) -> z3.BoolRef:
    """b is one move from a: each coordinate differs by -1, 0 or +1 (standing still is a move)."""
    return z3.And(abs_int(b[0] - a[0]) <= 1, abs_int(b[1] - a[1]) <= 1)


def in_grid(d: Z3Dims, c: tuple[z3.ArithRef, z3.ArithRef]) -> z3.BoolRef:
    return z3.And(0 <= c[0], c[0] < d.m, 0 <= c[1], c[1] < d.n)


def position(path: Z3PathVar, k: z3.ArithRef | int) -> tuple[z3.ArithRef, z3.ArithRef]:
    """Where the subordinate is at step k >= 0: L_k while the list lasts, then its last cell."""
    kk = z3.If(k < path.length, k, path.length - 1)
    return path.xs[kk], path.ys[kk]


def layer_value(P: z3.ArrayRef, d: Z3Dims, k: z3.ArithRef | int,
                c: tuple[z3.ArithRef, z3.ArithRef]) -> z3.ArithRef:
    """D_R's entry in force at step k: P[k] for k < N, the rest layer P[N] from then on."""
    return z3.If(k < d.N, P[k, c[0], c[1]], P[d.N, c[0], c[1]])


def is_path_fixed(P: z3.ArrayRef, d: Z3Dims, start: tuple[z3.ArithRef, z3.ArithRef],
                  goal: tuple[z3.ArithRef, z3.ArithRef], path: Z3PathVar) -> z3.BoolRef:
    """docs/model.md §5's is_path: a nonempty list inside the grid, one move per step, start to goal,
    free at every step k < max(len, N) (holding the goal after the list ends) and at goal in R."""
    k = z3.Int("isp!k")
    L = path.length
    return z3.And(
        L >= 1,
        path.xs[0] == start[0], path.ys[0] == start[1],
        path.xs[L - 1] == goal[0], path.ys[L - 1] == goal[1],
        z3.ForAll([k], z3.Implies(z3.And(0 <= k, k < L), in_grid(d, path.cell(k)))),
        z3.ForAll([k], z3.Implies(z3.And(0 <= k, k + 1 < L),
                                  adjacent(path.cell(k), path.cell(k + 1)))),
        z3.ForAll([k], z3.Implies(z3.And(0 <= k, z3.Or(k < L, k < d.N)),
                                  layer_value(P, d, k, position(path, k)) == 0)),
        P[d.N, goal[0], goal[1]] == 0)


def is_path_paper(P: z3.ArrayRef, d: Z3Dims, start: tuple[z3.ArithRef, z3.ArithRef],
                  goal: tuple[z3.ArithRef, z3.ArithRef], path: Z3PathVar) -> z3.BoolRef:
    """Definition 4 as printed: L_0 = startp, L_{LENGTH-1} = goalp, and for k < LENGTH(L), when
    L_k and L_{k+1} are grid cells they are one move apart and L_k is free in layer k (k < N) or
    in layer N - 1 (k >= N). LENGTH is a natural number; L_{LENGTH} is unspecified (HOL's EL)."""
    i, j, k, i2, j2 = z3.Ints("isp!i isp!j isp!k isp!i2 isp!j2")
    L = path.length
    last = z3.If(L >= 1, L - 1, 0)   # natural-number subtraction: LENGTH(L) - 1 is 0 for []
    return z3.And(
        L >= 0,
        path.xs[0] == start[0], path.ys[0] == start[1],
        path.xs[last] == goal[0], path.ys[last] == goal[1],
        z3.ForAll([i, j, k, i2, j2], z3.Implies(
            z3.And(0 <= i, i < d.m, 0 <= i2, i2 < d.m, 0 <= j, j < d.n, 0 <= j2, j2 < d.n,
                   0 <= k, k < L, path.xs[k] == i, path.ys[k] == j,
                   path.xs[k + 1] == i2, path.ys[k + 1] == j2),
            z3.And(adjacent((i, j), (i2, j2)),
                   z3.Implies(k < d.N, P[k, i, j] == 0),
                   z3.Implies(k >= d.N, P[d.N - 1, i, j] == 0)))))


def blocked_exact(P: z3.ArrayRef, d: Z3Dims, motion: Blocked | None = None,
                  rest: Blocked | None = None) -> z3.BoolRef:
    """Theorem 1's postcondition: P[k, i, j] = (blocked(k, i, j) -> 1 | 0) on every cell of the
    motion layers k < N (``motion``) and of the rest layer k = N (``rest``), where given."""
    k, i, j = z3.Ints("bex!k bex!i bex!j")
    parts = []
    if motion is not None:
        parts.append(z3.ForAll([k, i, j], z3.Implies(
            z3.And(0 <= k, k < d.N, 0 <= i, i < d.m, 0 <= j, j < d.n),
            P[k, i, j] == z3.If(motion(k, i, j), 1, 0))))
    if rest is not None:
        parts.append(z3.ForAll([i, j], z3.Implies(
            z3.And(0 <= i, i < d.m, 0 <= j, j < d.n),
            P[d.N, i, j] == z3.If(rest(d.N, i, j), 1, 0))))
    return z3.And(parts)


def free_sound(P: z3.ArrayRef, d: Z3Dims, motion: Blocked, rest: Blocked) -> z3.BoolRef:
    """The conservative half of Theorem 1's postcondition (all the search relies on): a cell
    marked free (0) is not blocked, on the motion layers and on the rest layer."""
    k, i, j = z3.Ints("fs!k fs!i fs!j")
    return z3.And(
        z3.ForAll([k, i, j], z3.Implies(
            z3.And(0 <= k, k < d.N, 0 <= i, i < d.m, 0 <= j, j < d.n, P[k, i, j] == 0),
            z3.Not(motion(k, i, j)))),
        z3.ForAll([i, j], z3.Implies(
            z3.And(0 <= i, i < d.m, 0 <= j, j < d.n, P[d.N, i, j] == 0),
            z3.Not(rest(d.N, i, j)))))


# --- Definition 5: the optimal path ------------------------------------------------------------

def costs(path: Z3PathVar) -> tuple[z3.ArithRef, z3.ArithRef]:
    """(J1, J2) of a path as uninterpreted functions: what is proved holds for any costs."""
    ints, arr = z3.IntSort(), z3.ArraySort(z3.IntSort(), z3.IntSort())
    j1 = z3.Function("J1", arr, arr, ints, ints)
    j2 = z3.Function("J2", arr, arr, ints, ints)
    return j1(path.xs, path.ys, path.length), j2(path.xs, path.ys, path.length)


def lex_le(a: tuple[z3.ArithRef, z3.ArithRef], b: tuple[z3.ArithRef, z3.ArithRef]) -> z3.BoolRef:
    """(J1, J2) of a is no worse than of b: J1(a) <= J1(b) and (J1 equal => J2(a) <= J2(b))."""
    return z3.And(a[0] <= b[0], z3.Implies(a[0] == b[0], a[1] <= b[1]))


def is_optimal(P: z3.ArrayRef, d: Z3Dims, start: tuple[z3.ArithRef, z3.ArithRef],
               goal: tuple[z3.ArithRef, z3.ArithRef], path: Z3PathVar,
               valid: Callable[..., z3.BoolRef] | None = None) -> z3.BoolRef:
    """Definition 5's predicate: path is valid and no valid path has lower (J1, J2)."""
    ok = valid or is_path_fixed
    other = bound_path("opt!L")
    return z3.And(ok(P, d, start, goal, path), z3.ForAll(
        other.consts(), z3.Implies(ok(P, d, start, goal, other),
                                   lex_le(costs(path), costs(other)))))


def bound_path(prefix: str) -> Z3PathVar:
    """A path whose constants are meant to be bound by a quantifier (same shape as z3_path)."""
    return z3_path(prefix)


Blocked = Callable[[z3.ArithRef, z3.ArithRef, z3.ArithRef], z3.BoolRef]
