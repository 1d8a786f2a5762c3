"""Grid counts from a scenario's numbers, in exact rationals (docs/model.md §2).

Pure functions of the numbers a scenario holds, so that the loader (which sizes the grid and
places the subordinate's start and goal before building a Scenario), the grid, the contracts
and the obligations count and judge the same way. This module owns the counts.

Two readings of every number (``READINGS``). *Binary*: the IEEE double the code computes with,
as the exact rational it is (``Fraction(0.02)`` = 0.0200000000000000004163...). *Decimal*: the
number as written: for a number read from a scenario file, the TOML text itself, exactly
(``Written``: ``tomllib.loads(text, parse_float=written)``; an integer's digits likewise); for
a plain float (a document built in Python) ``Fraction(repr(x))``, the shortest decimal that
rounds to it.

``time_steps`` gives the least N >= 1 with N dt >= Tf in both readings (an extra layer only
extends the principal's rest). ``joint_grid`` gives m_q and the float spacing
h_q = (hi - lo) / (m_q - 1) the planner uses. m_q is counted in the decimal reading
(``SPEED_READING``), the one in which the file states the robot's speed limit: the least m with
(hi - lo) / (m - 1) <= omega dt there, exactly, so a span that is a whole number of omega dt
as written gives exactly that grid and round angles on it are grid points. The doubles can
round the other way (limits [-2, 2], omega 2.5, dt 0.02: the double 0.05 exceeds the product
of the doubles 2.5 and 0.02 by an ulp); the float h must then stay within ``SPACING_ROUNDING``
(relative) of omega dt in both readings, at most ``MAX_SPACING`` exactly (the margin lemma's
bound on the lattice spacing the subordinate's regions are built with) and span the limits
within ``SPAN_TOLERANCE``; only when one of these fails is a point added.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction

__all__ = ["READINGS", "SPEED_READING", "SPAN_TOLERANCE", "SPACING_ROUNDING", "MAX_SPACING",
           "MAX_EXTRA_POINTS", "GridRefused", "SpacingCondition", "Written", "ceil_fraction",
           "decimal", "joint_grid", "joint_points", "min_points", "spacing_conditions",
           "spacing_ok", "spacing_readings", "time_readings", "travel_time", "time_steps",
           "written"]

#: The two readings of a number in a scenario file (see the module docstring).
READINGS = ("binary", "decimal")
#: The reading in which a scenario states the robot's speed limit, and so the one that sizes
#: the C-space grid and in which (hi - lo) / (m - 1) <= omega dt holds exactly (pre.grid.h).
SPEED_READING = "decimal"
#: The grid's last point lo + (m - 1) h must lie this close to the upper limit (rad).
SPAN_TOLERANCE = 1e-9
#: The float h may exceed omega dt, in either reading, by this fraction of it: rounding only
#: (the doubles of lo, hi, omega and dt and the float subtraction and division are each within
#: 2^-53 of the decimals; 1e-10 holds for any span above 0.003 rad at the 1000 rad bound on
#: angles). A tenth of the trajectory reader's speed tolerance (1e-9, docs/model.md §12), so a
#: plan's steps of h per dt stay within what that reader accepts as the speed limit.
SPACING_ROUNDING = 1e-10
#: The margin lemma's bound on a lattice spacing (Lemma.sweep_margin: g <= 3.14 rad), exactly:
#: the subordinate's regions are built with the float h as their spacing (docs/model.md §4.2).
MAX_SPACING = Fraction(157, 50)
#: Points ``joint_grid`` may add beyond the exact count before it gives up (then the loader
#: refuses the joint with exit 2). One is all any workcell within the physical range needs.
MAX_EXTRA_POINTS = 4


class GridRefused(ValueError):
    """No grid of a joint could be confirmed safe (the loader turns this into an InputError)."""


class Written(float):
    """A double that keeps the decimal it was written as: ``Written("0.02")`` is the float 0.02
    whose ``decimal`` is exactly 1/50. Arithmetic gives plain floats, and repr, equality and JSON
    are the float's, so only ``decimal()`` tells it apart. The text must be a finite decimal
    (TOML's underscores allowed); ``written`` is the lenient entry point (docs/model.md §3)."""

    __slots__ = ("decimal", "text")
    decimal: Fraction
    text: str

    def __new__(cls, text: str) -> Written:
        plain = str(text).replace("_", "")
        x = super().__new__(cls, plain)
        x.decimal = Fraction(plain)      # a non-finite text raises ValueError: no decimal
        x.text = plain
        return x

    def __reduce__(self) -> tuple[type[Written], tuple[str]]:
        # Pickled as its text, so a campaign's workers get the same readings.
        return (Written, (self.text,))


def written(value: int | float | str) -> float:
    """``value`` as a float that keeps its decimal (tomllib's ``parse_float``, and the reader's
    numbers): a text or an int exactly as written; a plain float, or a text that is not a finite
    decimal (inf, nan: refused later by name), stays a plain float."""
    if isinstance(value, (Written, bool)):
        return value
    if isinstance(value, (int, str)):
        try:
            return Written(str(value))
        except (ValueError, OverflowError):
            return float(str(value).replace("_", "")) if isinstance(value, str) else float(value)
    return float(value)


def ceil_fraction(x: Fraction) -> int:
    """The least integer >= x."""
    return -((-x.numerator) // x.denominator)


def decimal(x: float) -> Fraction:
    """The decimal reading of a number: its text as written when it was read from a file
    (``Written``), else the shortest decimal that rounds to the double, exactly."""
    if isinstance(x, Written):
        return x.decimal
    return Fraction(repr(float(x)))


def _read(x: float, reading: str) -> Fraction:
    if reading == "binary":
        return Fraction(x)
    if reading == "decimal":
        return decimal(x)
    raise ValueError(f"unknown reading {reading!r} (known: {', '.join(READINGS)})")


def travel_time(start: Sequence[float], goal: Sequence[float], omega: Sequence[float],
                reading: str = "binary") -> Fraction:
    """Tf = max_q |goal_q - start_q| / omega_q, exactly, in ``reading``."""
    return max(abs(_read(goal[q], reading) - _read(start[q], reading)) / _read(omega[q], reading)
               for q in range(2))


def time_readings(start: Sequence[float], goal: Sequence[float], omega: Sequence[float],
                  dt: float) -> dict[str, tuple[Fraction, Fraction]]:
    """{reading: (dt, Tf)} for both readings, exactly."""
    return {r: (_read(dt, r), travel_time(start, goal, omega, r)) for r in READINGS}


def time_steps(start: Sequence[float], goal: Sequence[float], omega: Sequence[float],
               dt: float) -> int:
    """N: the least N >= 1 with N dt >= Tf in both readings (exactly)."""
    return max([1] + [ceil_fraction(tf / d)
                      for d, tf in time_readings(start, goal, omega, dt).values()])


def spacing_readings(lo: float, hi: float, omega: float, dt: float
                     ) -> dict[str, tuple[Fraction, Fraction]]:
    """{reading: (hi - lo, omega dt)} for both readings, exactly."""
    return {r: (_read(hi, r) - _read(lo, r), _read(omega, r) * _read(dt, r)) for r in READINGS}


@dataclass(frozen=True)
class SpacingCondition:
    """One condition a joint's grid must meet: ``value <= bound``, exactly. ``what`` names the
    quantity (the grid's exact spacing, or the float h), ``reading`` the reading of the scenario's
    numbers the bound is taken in (or "margin lemma"), ``bound_is`` the bound in words."""

    what: str
    reading: str
    value: Fraction
    bound: Fraction
    bound_is: str = ""

    @property
    def holds(self) -> bool:
        return self.value <= self.bound

    def words(self) -> str:
        named = f"{self.bound_is} = " if self.bound_is else ""
        return (f"{self.what} ({self.reading}) = {_fmt(self.value)} <= {named}"
                f"{_fmt(self.bound)}: {self.holds}")


def _fmt(x: Fraction) -> str:
    return f"{float(x):.17g}" if x.denominator > 10**6 else str(x)


def spacing_conditions(lo: float, hi: float, omega: float, dt: float, m: int, h: float
                       ) -> tuple[SpacingCondition, ...]:
    """What m points spaced by the float h must meet (docs/model.md §2): (hi - lo) / (m - 1) <=
    omega dt exactly in SPEED_READING (the speed limit as the file states it); the float h <=
    omega dt (1 + SPACING_ROUNDING) in every reading (rounding only); the float h <= MAX_SPACING
    (the margin lemma's bound, as the regions use h). m >= 2."""
    readings = spacing_readings(lo, hi, omega, dt)
    span, step = readings[SPEED_READING]
    out = [SpacingCondition("(hi - lo)/(m - 1)", SPEED_READING, span / (m - 1), step, "omega dt")]
    slack = 1 + Fraction(SPACING_ROUNDING)
    out += [SpacingCondition("float h", r, Fraction(h), st * slack,
                             f"omega dt (1 + {SPACING_ROUNDING:g})")
            for r, (_, st) in readings.items()]
    out.append(SpacingCondition("float h", "margin lemma", Fraction(h), MAX_SPACING, "3.14"))
    return tuple(out)


def spacing_ok(lo: float, hi: float, omega: float, dt: float, m: int, h: float) -> bool:
    """Whether m points spaced by the float h are a grid of the joint: m >= 2, every
    ``spacing_conditions`` holds, and the last point lies within SPAN_TOLERANCE of hi."""
    if m < 2:
        return False
    if not all(c.holds for c in spacing_conditions(lo, hi, omega, dt, m, h)):
        return False
    return abs(lo + (m - 1) * h - hi) <= SPAN_TOLERANCE


def joint_grid(lo: float, hi: float, omega: float, dt: float,
               extra: int | None = None) -> tuple[int, float]:
    """(m, h): the points of one joint and their float spacing, h = (hi - lo) / (m - 1).

    m starts at ``min_points`` (the count in SPEED_READING); a point is added while
    ``spacing_ok`` fails, at most ``extra`` (default MAX_EXTRA_POINTS) times, after which
    GridRefused is raised. On a round-number workcell no point is added (docs/model.md §2).
    """
    limit = MAX_EXTRA_POINTS if extra is None else extra
    m = min_points(lo, hi, omega, dt)
    for _ in range(limit + 1):
        h = (hi - lo) / (m - 1)
        if spacing_ok(lo, hi, omega, dt, m, h):
            return m, h
        m += 1
    raise GridRefused(f"no grid of [{lo!r}, {hi!r}] with spacing <= omega dt = {omega!r} * "
                      f"{dt!r} could be confirmed within {limit} extra point(s)")


def min_points(lo: float, hi: float, omega: float, dt: float) -> int:
    """The least m >= 2 with (hi - lo) / (m - 1) <= omega dt in SPEED_READING, in exact
    integers (no float is formed, so the loader can hold it to the budget first)."""
    span, step = spacing_readings(lo, hi, omega, dt)[SPEED_READING]
    return max(2, ceil_fraction(span / step) + 1)


def joint_points(lo: float, hi: float, omega: float, dt: float) -> int:
    """m_q, as ``joint_grid`` gives it."""
    return joint_grid(lo, hi, omega, dt)[0]
