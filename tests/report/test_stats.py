"""The campaign's statistics (report._stats): Wilson intervals against published values, the exact
binomial and McNemar tests against hand-counted ones."""

from __future__ import annotations

import pytest

from cfmpa.report._stats import Z95, binomial_two_sided_p, mcnemar_exact_p, wilson_interval


@pytest.mark.parametrize("k, n, lo, hi", [
    # Newcombe (1998), Statistics in Medicine 17:857, Table I, method 3 (Wilson score).
    (81, 263, 0.2553, 0.3662), (15, 148, 0.0624, 0.1605), (0, 20, 0.0, 0.1611),
    (1, 29, 0.0061, 0.1718),
    # symmetric and degenerate cases
    (5, 10, 0.2366, 0.7634), (10, 10, 0.7225, 1.0), (0, 1, 0.0, 0.7935)])
def test_wilson_interval_matches_published_values(k, n, lo, hi):
    a, b = wilson_interval(k, n)
    assert a == pytest.approx(lo, abs=5e-5) and b == pytest.approx(hi, abs=5e-5)
    c, d = wilson_interval(n - k, n)                 # the interval of failures mirrors it
    assert (c, d) == pytest.approx((1 - b, 1 - a), abs=1e-12)


def test_z95_is_the_normal_quantile():
    assert Z95 == pytest.approx(1.959963984540054, abs=1e-12)


@pytest.mark.parametrize("k, n, p", [
    (7, 10, 0.34375),                # 2 * 176 / 1024
    (0, 10, 2 / 1024), (10, 10, 2 / 1024), (1, 10, 22 / 1024), (5, 10, 1.0), (0, 0, 1.0),
    (3, 3, 0.25), (2, 12, 2 * 79 / 4096), (60, 60, 2 / 2 ** 60)])
def test_exact_binomial_two_sided_p(k, n, p):
    assert binomial_two_sided_p(k, n) == pytest.approx(p, rel=1e-12)


def test_mcnemar_exact_uses_only_the_discordant_pairs():
    assert mcnemar_exact_p(3, 0) == mcnemar_exact_p(0, 3) == 0.25
    assert mcnemar_exact_p(0, 0) == 1.0
    # a large campaign: exact integers, no underflow to 0 before the float division
    assert 0 < mcnemar_exact_p(0, 1000) < 1e-290
    with pytest.raises(ValueError, match=r"k must be an integer in \[0, n\], got 3"):
        wilson_interval(3, 2)
