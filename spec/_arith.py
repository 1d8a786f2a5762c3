"""The few operations a rule needs beyond + - * /, on floats (and numpy arrays) or on Z3 terms.

A rule the proofs read (the principal's box per layer, the subordinate's cell box, the PTP
motion, impl.lattice_range, the links' reach, the ball-arithmetic gap) is written once with
these and runs on either: on floats it performs the same IEEE operations as before (Python's
``min``/``max``, ``math.floor``/``ceil``/``hypot``/``sqrt``, numpy's ``minimum``/``maximum`` on
arrays, python-flint's ``arb.sqrt`` on balls), on Z3 terms it builds the term the proof is
about (``If``, ``ToInt``, ``Sqrt``: a square root the proofs replace by a real s >= 0 with
s^2 = its argument). So a changed rule changes the proved statement, and a wrong rule fails a
proof.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["ceil_of", "cases", "floor_of", "hypot_of", "if_then", "is_term", "max_of", "min_of",
           "sqrt_of"]


def is_term(*xs: Any) -> bool:
    """Whether any of ``xs`` is a Z3 expression (checked without importing z3)."""
    return any(type(x).__module__.startswith("z3") for x in xs)


def _z3() -> Any:
    import z3
    return z3


def _real(x: Any) -> Any:
    z3 = _z3()
    return x if isinstance(x, z3.ExprRef) else z3.RealVal(x)


def if_then(c: Any, x: Any, y: Any) -> Any:
    """x if c else y; on a Z3 condition, If(c, x, y)."""
    if is_term(c):
        z3 = _z3()
        if is_term(x, y) and any(isinstance(v, z3.ArithRef) and v.is_int() for v in (x, y)):
            return z3.If(c, x, y)
        return z3.If(c, _real(x), _real(y))
    return x if c else y


def cases(c: Any, then: Callable[[], Any], otherwise: Callable[[], Any]) -> Any:
    """``then()`` if c else ``otherwise()``, evaluating only the branch taken (a float division
    by zero stays out of reach); on a Z3 condition both, joined by If (per component of a
    tuple)."""
    if not is_term(c):
        return then() if c else otherwise()
    a, b = then(), otherwise()
    if isinstance(a, tuple):
        return tuple(if_then(c, x, y) for x, y in zip(a, b))
    return if_then(c, a, b)


def min_of(a: Any, b: Any) -> Any:
    """The lesser of a and b: Python's min (the first on a tie), numpy's minimum on arrays,
    If(a <= b, a, b) on terms."""
    if is_term(a, b):
        return _z3().If(a <= b, a, b)
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.minimum(a, b)
    return min(a, b)


def max_of(a: Any, b: Any) -> Any:
    """The greater of a and b: Python's max, numpy's maximum on arrays, If(a <= b, b, a)."""
    if is_term(a, b):
        return _z3().If(a <= b, b, a)
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.maximum(a, b)
    return max(a, b)


def floor_of(x: Any) -> Any:
    """floor(x) as an integer: math.floor, or Z3's ToInt (the floor of a real)."""
    if is_term(x):
        return _z3().ToInt(x)
    return math.floor(x)


def ceil_of(x: Any) -> Any:
    """ceil(x) as an integer: math.ceil, or -ToInt(-x)."""
    if is_term(x):
        return -_z3().ToInt(-x)
    return math.ceil(x)


def sqrt_of(x: Any) -> Any:
    """The square root of x: math.sqrt on a float, ``x.sqrt()`` on a ball (python-flint's arb:
    a ball containing the exact root), Z3's Sqrt (x ** (1/2)) on a term."""
    if is_term(x):
        return _z3().Sqrt(x)
    if hasattr(x, "sqrt"):
        return x.sqrt()
    return math.sqrt(x)


def hypot_of(x: Any, y: Any) -> Any:
    """The length of (x, y): math.hypot on floats, Sqrt(x^2 + y^2) on terms."""
    if is_term(x, y):
        return _z3().Sqrt(x * x + y * y)
    return math.hypot(x, y)
