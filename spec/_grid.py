"""Time and C-space grids (docs/model.md §2), computed in exact rationals so rounding is the safe way.

The counts come from ``spec._counts`` (one owner): N and m are derived from the doubles' exact
values in two readings (binary and decimal, ``Grid.READINGS``), and the float spacing h the
planner uses is confirmed against the exact bound (a point is added when it fails), so
``N * dt >= Tf`` and ``h_q <= omega_q * dt`` hold exactly, not just up to rounding. The loader,
``make_grid``, the contracts (``grid_failures``) and the obligations judge through the same
``Grid.time_readings`` and ``Grid.spacing_readings``.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from fractions import Fraction

import numpy as np
import numpy.typing as npt

from ._counts import (READINGS, joint_grid, joint_points, spacing_readings, time_readings,
                      time_steps, travel_time)
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
    "rest_is_goal",
    "EPS",
]

#: A cell is free only when the regions' Euclidean distance exceeds this (metres), docs/model.md §4.
EPS = 1e-9

FloatArray = npt.NDArray[np.float64]


class Variant(str, Enum):
    """How the principal's box per layer is taken (docs/model.md §4)."""

    ORIGINAL = "original"  # Algorithm 1: [a - w dt, a + w dt]
    MODIFIED = "modified"  # Section IV.A: [a, a + s w dt]
    TIGHT = "tight"        # ours: [theta(k dt), theta((k+1) dt)]

    def __str__(self) -> str:
        return self.value


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
    #: rationals they are) and "decimal" (the numbers as written, Fraction(repr(x))).
    READINGS = READINGS

    @staticmethod
    def time_readings(s: Scenario) -> dict[str, tuple[Fraction, Fraction]]:
        """{reading: (dt, Tf)} of the scenario, exactly; N must satisfy N dt >= Tf in each."""
        L = s.left
        return time_readings(L.start, L.goal, L.omega, s.dt)

    @staticmethod
    def spacing_readings(s: Scenario, q: int) -> dict[str, tuple[Fraction, Fraction]]:
        """{reading: (hi_q - lo_q, omega_q dt)} of the subordinate's joint q, exactly; the grid
        must satisfy (hi - lo) / (m_q - 1) <= omega_q dt in each (and its float h in binary)."""
        R = s.right
        return spacing_readings(R.limits[q][0], R.limits[q][1], R.omega[q], s.dt)

    @property
    def shape(self) -> tuple[int, int, int]:
        """The shape of dr.npy: (N + 1, m, n), layers 0..N-1 then the rest layer."""
        return (self.N + 1, self.m, self.n)

    def angle(self, q: int, index: int | npt.NDArray[np.int64]) -> float | FloatArray:
        """theta = lo_q + index * h_q for joint q (0 or 1)."""
        return self.lo[q] + index * self.h[q]

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
    start = np.asarray(s.left.start)
    goal = np.asarray(s.left.goal)
    tf = float(exact_tf(s))
    frac = np.ones_like(t) if tf == 0 else np.clip(t / tf, 0.0, 1.0)
    return start + (goal - start) * frac[..., None]


def left_box(s: Scenario, variant: Variant | str, k: int) -> tuple[Pair2, Pair2]:
    """The principal's joint box at layer k (docs/model.md §4), ((lo1, hi1), (lo2, hi2))."""
    v = Variant(variant)
    dt = s.dt
    a = left_angles(s, k * dt)
    out = []
    for q in range(2):
        w = s.left.omega[q] * dt
        if v is Variant.ORIGINAL:
            out.append((float(a[q] - w), float(a[q] + w)))
        elif v is Variant.MODIFIED:
            sign = 1.0 if s.left.goal[q] > s.left.start[q] else -1.0
            ends = (a[q], a[q] + sign * w)
            out.append((float(min(ends)), float(max(ends))))
        else:
            b = left_angles(s, (k + 1) * dt)[q]
            out.append((float(min(a[q], b)), float(max(a[q], b))))
    return (out[0], out[1])


def rest_is_goal(variant: Variant | str) -> bool:
    """True when the rest layer is the principal at rest at its goal (tight), else layer N-1."""
    return Variant(variant) is Variant.TIGHT


def right_box(g: Grid, cell: tuple[int, int]) -> tuple[Pair2, Pair2]:
    """The subordinate's box at cell (i, j): [t_i - h1, t_i + h1] x [t_j - h2, t_j + h2]."""
    out = []
    for q in range(2):
        t = float(g.angle(q, cell[q]))
        out.append((t - g.h[q], t + g.h[q]))
    return (out[0], out[1])


Pair2 = tuple[float, float]
