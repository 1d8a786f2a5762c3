"""Time and C-space grids (docs/model.md §2), computed in exact rationals so rounding is the safe way.

The counts come from ``spec._counts`` (one owner): N is derived from the numbers' exact values
in two readings (binary and decimal, ``Grid.READINGS``), so ``N * dt >= Tf`` holds exactly in
both; m is counted in the decimal reading, the numbers as written, so
``(hi_q - lo_q)/(m_q - 1) <= omega_q * dt`` holds exactly there, and the float spacing h the
planner uses is confirmed within rounding of omega_q * dt in both readings and <= 157/50
(``spacing_conditions``; a point is added only when that fails, docs/model.md §2). The loader,
``make_grid``, the contracts (``grid_failures``) and the obligations judge through the same
``spacing_conditions``, ``Grid.time_readings`` and ``Grid.spacing_readings``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from enum import Enum
from fractions import Fraction
from typing import Any, cast

import numpy as np
import numpy.typing as npt

from ._arith import cases, if_then, is_term, max_of, min_of
from ._counts import (
    READINGS,
    joint_grid,
    joint_points,
    spacing_readings,
    time_readings,
    time_steps,
    travel_time,
)
from ._scenario import Scenario

__all__ = [
    "Grid",
    "Variant",
    "make_grid",
    "joint_points",
    "exact_tf",
    "exact_n",
    "left_angles",
    "left_box",
    "right_box",
    "rest_box",
    "cell_box",
    "ptp_angles",
    "ptp_fraction",
    "rule_of",
    "VariantRule",
    "EPS",
    "DISTANCE_ERROR_M",
    "MAX_COORD_M",
    "UNIT_ROUNDOFF",
]

#: A cell is free only when the regions' Euclidean distance exceeds this (metres), docs/model.md §4.
EPS = 1e-9

#: The unit roundoff of IEEE doubles rounded to nearest: each +, -, *, /, sqrt is exact times
#: (1 + d) with |d| <= UNIT_ROUNDOFF.
UNIT_ROUNDOFF = 2.0 ** -53
#: A bound (metres) on every coordinate of every polygon BuiltDR compares, for any scenario the
#: reader accepts: a base within 1000 m in each coordinate (spec._scenario.MAX_BASE_M), two links
#: of at most 100 m with their half-widths, and a sweep margin below r g^2 / 8 with g <= 3.14
#: (together under 1400 m); 4000 m leaves room (docs/model.md §4.3).
MAX_COORD_M = 4000.0
#: What the float computation of a distance (or of a lower bound of it: a box gap, a
#: separating-axis gap) may be off from the exact value of the same formula on the same doubles:
#: 64 rounding units per metre of coordinate (ledger A12; the deepest formula, the vertex-edge
#: distance, rounds about 15 times). tests/spec/test_distance_error.py checks it against exact
#: rational arithmetic; Safety.separation proves that EPS above it makes "float distance > EPS"
#: imply "true distance > 0".
DISTANCE_ERROR_M = 64 * UNIT_ROUNDOFF * MAX_COORD_M

FloatArray = npt.NDArray[np.float64]


class Variant(str, Enum):
    """How the principal's box per layer is taken (docs/model.md §4). Each member's rules are
    its row of ``_RULES``: the box of one joint at layer k (``joint_box``), whether the rest
    layer is the principal at rest at its goal (``rest_at_goal``) or layer N-1's region, and
    the variant whose box holds its own (``within``, ``nesting``). Code asks these, never the
    member's name. They run on floats and on Z3 terms (``spec._arith``): spec, impl, the exact
    re-decision and the proofs all read them here, and a member without a row raises."""

    ORIGINAL = "original"  # Algorithm 1: [a - w dt, a + w dt]
    MODIFIED = "modified"  # Section IV.A: [a, a + s w dt]
    TIGHT = "tight"        # ours: [theta(k dt), theta((k+1) dt)]

    def __str__(self) -> str:
        return self.value

    @property
    def rule(self) -> VariantRule:
        """This member's row of the rule table; a member without one raises."""
        return rule_of(self)

    @property
    def rest_at_goal(self) -> bool:
        """True when the rest layer is the principal at rest at its goal, else layer N-1."""
        return self.rule.rest_at_goal

    @property
    def within(self) -> Variant | None:
        """The variant whose box holds this one's at every layer (None: the outermost)."""
        outer = self.rule.within
        return None if outer is None else Variant(outer)

    @classmethod
    def nesting(cls) -> tuple[tuple[Variant, Variant], ...]:
        """Every (inner, outer) pair of the rules' ``within``, innermost first (the deepest in
        the chain of ``within``, then the members' order): tight in modified, modified in
        original."""
        def depth(v: Variant) -> int:
            d, seen = 0, {v}
            while (w := v.within) is not None:
                if w in seen:
                    raise ValueError(f"variant rules: 'within' runs in a cycle through {w}")
                seen.add(w)
                v, d = w, d + 1
            return d
        inner = sorted((v for v in cls if v.within is not None), key=lambda v: -depth(v))
        return tuple((v, cast(Variant, v.within)) for v in inner)

    def joint_box(self, a: Any, b: Any, step: Any, up: Any) -> tuple[Any, Any]:
        """One joint's interval (lo, hi) at layer k: a = theta_q(k dt), b = theta_q((k+1) dt),
        step = omega_q dt, up = (goal_q > start_q). Floats or Z3 terms."""
        return self.rule.joint_box(a, b, step, up)

    def layer_box(self, start: Sequence[Any], goal: Sequence[Any], omega: Sequence[Any],
                  dt: Any, tf: Any, k: Any) -> tuple[tuple[Any, Any], tuple[Any, Any]]:
        """The principal's joint box at layer k, ((lo1, hi1), (lo2, hi2)), for the PTP motion
        from start to goal in time tf (``ptp_angles``). Floats or Z3 terms."""
        a = ptp_angles(start, goal, tf, k * dt)
        b = ptp_angles(start, goal, tf, (k + 1) * dt)
        out = [self.joint_box(a[q], b[q], omega[q] * dt, goal[q] > start[q]) for q in range(2)]
        return (out[0], out[1])

    def rest_box(self, start: Sequence[Any], goal: Sequence[Any], omega: Sequence[Any],
                 dt: Any, tf: Any, N: Any) -> tuple[tuple[Any, Any], tuple[Any, Any]]:
        """The rest layer's box (the principal from N dt on): the goal, a one-point box, when
        ``rest_at_goal``, else layer N-1's box."""
        if self.rest_at_goal:
            return ((goal[0], goal[0]), (goal[1], goal[1]))
        return self.layer_box(start, goal, omega, dt, tf, N - 1)


@dataclass(frozen=True)
class VariantRule:
    """A variant's rules: ``joint_box(a, b, step, up) -> (lo, hi)`` (see Variant.joint_box),
    whether its rest layer is the goal, the rule in words (docs/model.md §4.1), and what the
    obligations read of it (docs/model.md §4, §6): ``within``, the variant whose box holds this
    one's at every layer (None for the outermost; Thm3.box_nesting proves each such pair and
    Scenario.*.containment checks it on the polygons); ``theorems``, the paper's theorems on
    BuiltDR and on searchoptpath under this variant's regions; ``in_paper``, whether the paper
    has the variant (its obligation ids then carry no variant suffix); ``source``, where the
    rule is defined."""

    joint_box: Callable[[Any, Any, Any, Any], tuple[Any, Any]]
    rest_at_goal: bool
    words: str
    rest_words: str
    within: str | None
    theorems: tuple[int, int]
    in_paper: bool
    source: str


def _original_box(a: Any, b: Any, step: Any, up: Any) -> tuple[Any, Any]:
    return (a - step, a + step)


def _modified_box(a: Any, b: Any, step: Any, up: Any) -> tuple[Any, Any]:
    end = a + if_then(up, 1.0, -1.0) * step
    return (min_of(a, end), max_of(a, end))


def _tight_box(a: Any, b: Any, step: Any, up: Any) -> tuple[Any, Any]:
    return (min_of(a, b), max_of(a, b))


_RULES: dict[str, VariantRule] = {
    "original": VariantRule(
        _original_box, False,
        "[a - omega_q dt, a + omega_q dt], a = theta_L(k dt) (Algorithm 1)", "layer N-1's box",
        within=None, theorems=(1, 2), in_paper=True, source="Algorithm 1"),
    "modified": VariantRule(
        _modified_box, False,
        "from a = theta_L(k dt) to a + s_q omega_q dt, s_q = +1 if goal_q > start_q else -1 "
        "(Section IV.A)", "layer N-1's box",
        within="original", theorems=(3, 4), in_paper=True, source="Section IV.A"),
    "tight": VariantRule(
        _tight_box, True, "from theta_L(k dt) to theta_L((k+1) dt)", "the goal, a one-point box",
        within="modified", theorems=(3, 4), in_paper=False, source="docs/model.md §4"),
}


def rule_of(variant: Variant | str) -> VariantRule:
    """The rule table's row of ``variant``; a value without a row raises ValueError."""
    key = variant.value if isinstance(variant, Variant) else str(variant)
    try:
        return _RULES[key]
    except KeyError:
        raise ValueError(f"variant {key!r} has no box rule; the rules are for "
                         f"{', '.join(_RULES)}") from None


def ptp_fraction(t: Any, tf: Any) -> Any:
    """How far along the PTP motion is at t: min(max(t / Tf, 0), 1), and 1 when Tf = 0 (the arm
    rests at its start, = goal). Floats, numpy arrays or Z3 terms."""
    return cases(tf <= 0, lambda: np.ones_like(np.asarray(t, dtype=float)) if not is_term(t)
                 else 1.0, lambda: min_of(max_of(t / tf, 0.0), 1.0))


def ptp_angles(start: Sequence[Any], goal: Sequence[Any], tf: Any, t: Any) -> tuple[Any, Any]:
    """theta(t) per joint: start_q + (goal_q - start_q) * ptp_fraction(t, Tf)."""
    f = ptp_fraction(t, tf)
    return (start[0] + (goal[0] - start[0]) * f, start[1] + (goal[1] - start[1]) * f)


def cell_box(lo: Sequence[Any], h: Sequence[Any], cell: Sequence[Any]
             ) -> tuple[tuple[Any, Any], tuple[Any, Any]]:
    """The subordinate's box at cell (i, j) of the grid lo_q + index h_q: [t_i - h1, t_i + h1] x
    [t_j - h2, t_j + h2]. Floats or Z3 terms."""
    out = []
    for q in range(2):
        t = lo[q] + cell[q] * h[q]
        out.append((t - h[q], t + h[q]))
    return (out[0], out[1])


def exact_tf(s: Scenario) -> Fraction:
    """Tf = max_q |goal_q - start_q| / omega_q, exactly (binary reading)."""
    return travel_time(s.left.start, s.left.goal, s.left.omega)


def exact_n(s: Scenario) -> int:
    """N: the least N >= 1 with N dt >= Tf in both readings, exactly."""
    return time_steps(s.left.start, s.left.goal, s.left.omega, s.dt)


@dataclass(frozen=True)
class Grid:
    """The discretisation of a scenario: N motion layers, an m x n C-space grid of points."""

    N: int
    m: int
    n: int
    dt: float
    Tf: float
    lo: tuple[float, float]
    h: tuple[float, float]

    #: The two exact readings every grid condition is judged in: "binary" (the doubles as the
    #: rationals they are) and "decimal" (the numbers as written: a file's text, exactly).
    READINGS = READINGS

    @staticmethod
    def time_readings(s: Scenario) -> dict[str, tuple[Fraction, Fraction]]:
        """{reading: (dt, Tf)} of the scenario, exactly; N must satisfy N dt >= Tf in each."""
        L = s.left
        return time_readings(L.start, L.goal, L.omega, s.dt)

    @staticmethod
    def spacing_readings(s: Scenario, q: int) -> dict[str, tuple[Fraction, Fraction]]:
        """{reading: (hi_q - lo_q, omega_q dt)} of the subordinate's joint q, exactly; the grid
        must satisfy (hi - lo) / (m_q - 1) <= omega_q dt exactly in the decimal reading, and its
        float h within rounding of omega_q dt in each (``spacing_conditions``)."""
        R = s.right
        return spacing_readings(R.limits[q][0], R.limits[q][1], R.omega[q], s.dt)

    @property
    def shape(self) -> tuple[int, int, int]:
        """The shape of dr.npy: (N + 1, m, n), layers 0..N-1 then the rest layer."""
        return (self.N + 1, self.m, self.n)

    def angle(self, q: int, index: int | npt.NDArray[np.int64]) -> float | FloatArray:
        """theta = lo_q + index * h_q for joint q (0 or 1)."""
        # cast: numpy's stubs type an int array times a float as floating[Any]
        return cast("float | FloatArray", self.lo[q] + index * self.h[q])

    def angles(self, cell: tuple[int, int]) -> tuple[float, float]:
        return (float(self.angle(0, cell[0])), float(self.angle(1, cell[1])))

    def as_json(self) -> dict[str, object]:
        return {"N": self.N, "m": self.m, "n": self.n, "dt": self.dt, "Tf": self.Tf,
                "lo": list(self.lo), "h": list(self.h)}


def make_grid(s: Scenario) -> Grid:
    """The grid of docs/model.md §2 for a validated scenario."""
    R = s.right
    (m, h1), (n, h2) = (joint_grid(R.limits[q][0], R.limits[q][1], R.omega[q], s.dt)
                        for q in range(2))
    return Grid(N=exact_n(s), m=m, n=n, dt=s.dt, Tf=float(exact_tf(s)),
                lo=(R.limits[0][0], R.limits[1][0]), h=(h1, h2))


def left_angles(s: Scenario, t: float | FloatArray) -> FloatArray:
    """The principal's PTP motion: theta(t) = start + (goal - start) * min(t / Tf, 1).

    Returns shape (..., 2). With Tf = 0 the arm rests at its start (= goal).
    """
    t = np.asarray(t, dtype=float)
    th = ptp_angles(s.left.start, s.left.goal, float(exact_tf(s)), t)
    return np.stack([np.asarray(th[0], dtype=float), np.asarray(th[1], dtype=float)], axis=-1)


def left_box(s: Scenario, variant: Variant | str, k: int) -> tuple[Pair2, Pair2]:
    """The principal's joint box at layer k (docs/model.md §4), ((lo1, hi1), (lo2, hi2)):
    ``Variant.layer_box`` on the scenario's floats."""
    L = s.left
    box = Variant(variant).layer_box(L.start, L.goal, L.omega, s.dt, float(exact_tf(s)), k)
    return _float_box(box)


def rest_box(s: Scenario, variant: Variant | str, N: int) -> tuple[Pair2, Pair2]:
    """The principal's box in the rest layer (from N dt on): ``Variant.rest_box``."""
    L = s.left
    box = Variant(variant).rest_box(L.start, L.goal, L.omega, s.dt, float(exact_tf(s)), N)
    return _float_box(box)


def right_box(g: Grid, cell: tuple[int, int]) -> tuple[Pair2, Pair2]:
    """The subordinate's box at cell (i, j): ``cell_box`` on the grid's floats."""
    box = cell_box(g.lo, g.h, cell)
    return _float_box(box)


Pair2 = tuple[float, float]


def _float_box(box: Any) -> tuple[Pair2, Pair2]:
    """A rule's box ((lo1, hi1), (lo2, hi2)) as Python floats."""
    return ((float(box[0][0]), float(box[0][1])), (float(box[1][0]), float(box[1][1])))
