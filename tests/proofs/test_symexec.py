"""The symbolic run of numpy code (proofs/_symexec.py): its stand-ins mean what numpy computes,
every path of a branch is run, and code outside the subset is refused, not misread."""

from __future__ import annotations

import numpy as np
import pytest
import z3

from cfmpa.proofs._symexec import Explorer, ExtractionError, SymArray, SymNumpy, obj, rebind


@pytest.mark.parametrize("side", ["left", "right"])
def test_searchsorted_defines_the_index_numpy_returns(side):
    # On concrete sorted rows, the defined symbol can only be numpy's own answer.
    rng = np.random.default_rng(3)
    T = z3.Function("T", z3.IntSort(), z3.RealSort())
    R = z3.Int("R")
    for _ in range(20):
        rows = np.sort(rng.choice(np.arange(0, 10), size=rng.integers(1, 6), replace=False)) / 2
        v = float(rng.choice(np.concatenate([rows, rows + 0.25, [-1.0, 9.0]])))
        pins = [R == len(rows)] + [T(i) == float(x) for i, x in enumerate(rows)]
        for extra in (-1, len(rows)):
            pins.append(T(extra) == (-100.0 if extra < 0 else 100.0))
        paths = Explorer([(str(h), h) for h in pins]).paths(
            lambda v=v: SymNumpy.searchsorted(SymArray(R, T), obj([z3.RealVal(v)]), side=side))
        (p,) = paths
        r = p.result[0]
        s = z3.Solver()
        s.add(pins + [f for _, f in p.defs])
        s.add(r != int(np.searchsorted(rows, v, side=side)))
        assert s.check() == z3.unsat, (rows, v, side)


def test_a_branch_on_a_term_runs_both_ways_and_prunes_what_cannot_happen():
    x = z3.Int("x")

    def f() -> str:
        if x > 0:
            return "positive" if x > -5 else "never"
        return "not positive"
    paths = Explorer([("x is an integer", x == x)]).paths(f)
    assert sorted(p.result for p in paths) == ["not positive", "positive"]


def test_len_of_a_symbolic_array_is_a_branch():
    n = z3.Int("n")
    a = SymArray(n, lambda i: z3.Real("v"))
    paths = Explorer([("n >= 0", n >= 0)]).paths(lambda: len(a) == 1)
    assert sorted(p.result for p in paths) == [False, False, True]
    assert all(p.conds for p in paths)


def test_an_index_adds_its_range_check_and_a_slice_max_its_instances():
    n, j = z3.Ints("n j")
    W = z3.Function("W", z3.IntSort(), z3.RealSort())
    a = SymArray(n, W)
    (p,) = Explorer([("n >= 3", n >= 3)], instances=[j]).paths(lambda: a[1:n - 1].max(axis=0))
    m = p.result
    s = z3.Solver()
    s.add([f for _, f in p.defs] + [n >= 3, j >= 1, j < n - 1, W(j) > m])
    assert s.check() == z3.unsat                       # max >= every element of the slice
    s = z3.Solver()
    s.add([f for _, f in p.defs] + [n >= 3, j == 0, W(j) > m])
    assert s.check() == z3.sat                         # ... and says nothing outside it
    (q,) = Explorer([("n >= 3", n >= 3)]).paths(lambda: a[n])
    assert any("in range" in name for name, _ in q.checks)


def test_what_the_stand_in_does_not_model_is_refused():
    with pytest.raises(ExtractionError, match="numpy.linalg"):
        SymNumpy().linalg                               # noqa: B018 - the refusal is the test

    def uses_sort(np):
        return np.sort(obj([z3.Real("a")]))
    with pytest.raises(ExtractionError, match="numpy.sort"):
        Explorer([]).paths(lambda: rebind(uses_sort)(SymNumpy()))


def test_elementwise_operations_agree_with_numpy_on_numbers():
    a, b = np.array([1.5, -2.0, 0.0]), np.array([0.5, 3.0, 0.0])
    sym = SymNumpy()

    def run():
        return (sym.maximum(obj(a), obj(b)), sym.clip(obj(a), 0.0, 1.0),
                sym.where(obj(a) > 0, obj(a), obj(b)), sym.diff(obj(a)), sym.abs(obj(a)))
    (p,) = Explorer([]).paths(run)
    want = (np.maximum(a, b), np.clip(a, 0, 1), np.where(a > 0, a, b), np.diff(a), np.abs(a))
    for got, w in zip(p.result, want):
        vals = [float(z3.simplify(z3.ToReal(x) if isinstance(x, z3.ArithRef) and x.is_int()
                                  else (x if isinstance(x, z3.ExprRef) else z3.RealVal(x)))
                      .as_fraction()) for x in np.asarray(got, dtype=object).ravel()]
        assert vals == list(w)
