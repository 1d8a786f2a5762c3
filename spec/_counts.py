"""Grid counts from a scenario's numbers, in exact rationals (docs/model.md §2).

Pure functions of the doubles a scenario holds, so that both the loader (which sizes the grid
before building a Scenario) and the grid itself count the same way.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction

__all__ = ["ceil_fraction", "joint_points", "travel_time", "time_steps"]


def ceil_fraction(x: Fraction) -> int:
    """The least integer >= x."""
    return -((-x.numerator) // x.denominator)


def joint_points(lo: float, hi: float, omega: float, dt: float) -> int:
    """m_q = ceil((hi - lo) / (omega dt)) + 1 grid points, in exact arithmetic."""
    return ceil_fraction((Fraction(hi) - Fraction(lo)) / (Fraction(omega) * Fraction(dt))) + 1


def travel_time(start: Sequence[float], goal: Sequence[float], omega: Sequence[float]) -> Fraction:
    """Tf = max_q |goal_q - start_q| / omega_q, exactly."""
    return max(abs(Fraction(goal[q]) - Fraction(start[q])) / Fraction(omega[q]) for q in range(2))


def time_steps(start: Sequence[float], goal: Sequence[float], omega: Sequence[float],
               dt: float) -> int:
    """N = max(1, ceil(Tf / dt)), exactly; hence N dt >= Tf."""
    return max(1, ceil_fraction(travel_time(start, goal, omega) / Fraction(dt)))
