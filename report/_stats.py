"""The campaign's statistics: Wilson score intervals and the exact (McNemar) binomial test.

Plain ``math`` (no scipy): the Wilson interval of k successes in n trials at confidence 1 - a is

    (k + z^2/2) / (n + z^2)  -/+  z / (n + z^2) * sqrt(k (n - k) / n + z^2 / 4),   z = Phi^-1(1 - a/2)

(Wilson 1927; Newcombe 1998's method 3), and McNemar's exact test of paired outcomes with b and c
discordant pairs is the two-sided sign test: p = min(1, 2 P(X <= min(b, c))), X ~ Bin(b + c, 1/2),
summed in exact integers (p = 1 when b + c = 0).
"""

from __future__ import annotations

import math
from statistics import NormalDist

__all__ = ["Z95", "binomial_two_sided_p", "mcnemar_exact_p", "wilson_interval"]

#: The standard normal's 97.5 % quantile (a two-sided 95 % interval).
Z95 = NormalDist().inv_cdf(0.975)


def wilson_interval(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval (lo, hi) of ``k`` successes in ``n`` >= 1 trials."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ValueError(f"n must be an integer >= 1, got {n!r}")
    if isinstance(k, bool) or not isinstance(k, int) or not 0 <= k <= n:
        raise ValueError(f"k must be an integer in [0, n], got {k!r}")
    z2 = z * z
    centre = (k + z2 / 2) / (n + z2)
    half = z / (n + z2) * math.sqrt(k * (n - k) / n + z2 / 4)
    lo = 0.0 if k == 0 else max(0.0, centre - half)
    hi = 1.0 if k == n else min(1.0, centre + half)
    return lo, hi


def binomial_two_sided_p(k: int, n: int) -> float:
    """The exact two-sided p-value of ``k`` successes in ``n`` trials under p = 1/2."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 0:
        raise ValueError(f"n must be an integer >= 0, got {n!r}")
    if isinstance(k, bool) or not isinstance(k, int) or not 0 <= k <= n:
        raise ValueError(f"k must be an integer in [0, n], got {k!r}")
    if n == 0:
        return 1.0
    tail = sum(math.comb(n, i) for i in range(min(k, n - k) + 1))
    # 2 * tail / 2^n in exact integers, then one correctly rounded division.
    return min(1.0, tail / (1 << (n - 1)))


def mcnemar_exact_p(b: int, c: int) -> float:
    """McNemar's exact test: ``b`` pairs where only the first succeeds, ``c`` only the second."""
    return binomial_two_sided_p(min(b, c), b + c)
