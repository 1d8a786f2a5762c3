"""dr_postcondition at every cell is checked a block of rows of a layer at a time (no D_R-sized
temporaries, nor all of a layer's link-2 regions at once): its report equals the per-cell
check's (the definition at each cell), mismatches in (k, i, j) order, also for cells only the
definition decides and for many wrong cells over the limit; and blocks of any size give the
same verdicts as one block."""

from __future__ import annotations

import numpy as np
import pytest

import factory
from cfmpa.impl import build_dr_fast
from cfmpa.spec import Variant, _builtdr_post, make_grid
from cfmpa.spec._builtdr_post import dr_postcondition


@pytest.fixture(params=[1 << 17, 7], ids=["one block", "blocks of one row"])
def blocks(request, monkeypatch):
    monkeypatch.setattr(_builtdr_post, "BLOCK_CELLS", request.param)
    return request.param


@pytest.fixture(scope="module")
def built():
    s = factory.scenario()
    g = make_grid(s)
    return s, g, build_dr_fast(s, Variant.MODIFIED, g)


def every_cell(g):
    return np.argwhere(np.ones(g.shape, dtype=bool))


def test_many_wrong_cells_over_the_limit_are_the_first_in_order(built, blocks):
    s, g, dr = built
    bad = dr.copy()
    rng = np.random.default_rng(3)
    flips = rng.choice(bad.size, size=60, replace=False)
    bad.reshape(-1)[flips] ^= 1
    each = dr_postcondition(s, "modified", g, bad, cells=every_cell(g), limit=100)
    assert len(each.mismatches) == 60
    for limit in (5, 20, 100):
        full = dr_postcondition(s, "modified", g, bad, limit=limit)
        assert not full.ok and (full.checked, full.indeterminate) == (each.checked,
                                                                      each.indeterminate)
        assert full.mismatches == each.mismatches[:limit]
        order = [(x.layer, *x.cell) for x in full.mismatches]
        assert order == sorted(order)


def test_cells_left_to_the_definition_are_checked_too(built, blocks, monkeypatch):
    # With a slack of 5 cm the bounds leave many cells to the definition (the batch at the
    # end); a wrong one among them must be reported just as the per-cell check reports it.
    s, g, dr = built
    monkeypatch.setattr(_builtdr_post, "SLACK", 0.05)
    undecided = [(k, i0 * g.n + c) for k, i0, _, meets, unsure in _builtdr_post._block_bounds(
        s, "modified", g, _builtdr_post.EPS, _builtdr_post.BAND) for c in np.flatnonzero(unsure)]
    assert len(undecided) > 20
    k, c = undecided[len(undecided) // 2]
    bad = dr.copy()
    bad[k, c // g.n, c % g.n] ^= 1
    assert dr_postcondition(s, "modified", g, dr).ok
    full = dr_postcondition(s, "modified", g, bad)
    each = dr_postcondition(s, "modified", g, bad, cells=every_cell(g))
    assert not full.ok and full == each
    assert (full.mismatches[0].layer, full.mismatches[0].cell) == (k, (c // g.n, c % g.n))


def test_a_value_other_than_0_or_1_is_a_mismatch(built):
    s, g, dr = built
    bad = dr.copy()
    k, i, j = (int(x) for x in np.argwhere(dr == 1)[0])
    bad[k, i, j] = 2
    full = dr_postcondition(s, "modified", g, bad)
    assert full == dr_postcondition(s, "modified", g, bad, cells=every_cell(g))
    assert not full.ok and full.mismatches[0].got == 2


def test_values_other_than_0_or_1_are_counted_layer_by_layer(built):
    from cfmpa.spec._triples import dr_shape_failures

    s, g, dr = built
    bad = dr.copy()
    rng = np.random.default_rng(5)
    bad.reshape(-1)[rng.choice(bad.size, size=17, replace=False)] = 7
    (f,) = dr_shape_failures(g, bad)
    first = tuple(int(x) for x in np.argwhere(bad > 1)[0])
    assert f.count == 17 and dict(f.values)["layer"] == first[0]
    assert dict(f.values)["cell"] == list(first[1:]) and dict(f.values)["value"] == 7
    assert dr_shape_failures(g, dr) == []


@pytest.mark.parametrize("variant", list(Variant), ids=str)
def test_blocks_of_rows_give_the_verdicts_of_one_block(monkeypatch, variant):
    s = factory.scenario()
    g = make_grid(s)
    whole = _builtdr_post.full_verdicts(s, variant, g)
    assert g.m > 3 and g.m * g.n <= _builtdr_post.BLOCK_CELLS      # one block by default
    for cells in (g.n, 3 * g.n + 1, 5):                         # 1 row, 3 rows, 1 row (< n)
        monkeypatch.setattr(_builtdr_post, "BLOCK_CELLS", cells)
        parts = _builtdr_post.full_verdicts(s, variant, g)
        assert all(np.array_equal(a, b) for a, b in zip(whole, parts))
