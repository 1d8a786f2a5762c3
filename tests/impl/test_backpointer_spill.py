"""Back-pointers past their memory budget go to a temporary file (``BackPointers``,
docs/model.md §5): the searches give the same path, costs and witness whether the pointers are
held or spilled, and a pointer read wrongly from the file is caught by the walk back."""

from __future__ import annotations

import numpy as np
import pytest

from cfmpa.impl import _search, search_opt_path, search_opt_path_fast
from cfmpa.impl._search import BackPointers


def test_spilled_pointers_read_back_as_held_ones():
    rng = np.random.default_rng(0)
    held = BackPointers((2, 3), 6, 9)
    with BackPointers((2, 3), 6, 9, spill_bytes=0) as spilled:   # its file closed here
        for s in range(1, 7):
            values = rng.integers(-1, 9, size=held.new(s).shape).astype(np.int8)
            held.layers[s - 1][:] = values
            spilled.new(s)[:] = values
        assert spilled.spilled == 5 and held.spilled == 0      # the newest step stays in memory
        assert all(a is None for a in spilled.layers[:5])
        for s in range(1, 7):
            r0, r1, c0, c1 = held.box(s)
            for d in range(9):
                for i in range(r0, r1):
                    for j in range(c0, c1):
                        assert spilled.at(s, d, i, j) == held.at(s, d, i, j)


def test_pointers_under_the_budget_stay_in_memory():
    bp = BackPointers((0, 0), 5, 5, spill_bytes=10**6)
    for s in range(1, 6):
        bp.new(s)
    assert bp.spilled == 0 and all(a is not None for a in bp.layers)


@pytest.mark.parametrize("seed", range(6))
def test_the_searches_answer_the_same_with_spilled_pointers(monkeypatch, seed):
    rng = np.random.default_rng(seed)
    K, m, n = int(rng.integers(3, 12)), int(rng.integers(3, 10)), int(rng.integers(3, 10))
    dr = (rng.random((K, m, n)) < 0.2).astype(np.uint8)
    start, goal = (0, 0), (m - 1, n - 1)
    dr[0][start] = dr[-1][goal] = 0
    want = [search_opt_path(dr, start, goal, with_witness=True),
            search_opt_path_fast(dr, start, goal, progress=False, with_witness=True)]
    made: list[BackPointers] = []
    real_init = BackPointers.__init__

    def recording(self, *args, **kw):
        real_init(self, *args, **kw)
        made.append(self)

    monkeypatch.setattr(_search, "BACK_POINTER_BYTES", 0)
    monkeypatch.setattr(BackPointers, "__init__", recording)
    got = [search_opt_path(dr, start, goal, with_witness=True),
           search_opt_path_fast(dr, start, goal, progress=False, with_witness=True)]
    assert len(made) == 2 and all(bp.spilled == K - 2 for bp in made)
    for a, b in zip(want, got):
        assert (a.status, a.reason, a.path, a.J1, a.J2) == (b.status, b.reason, b.path, b.J1, b.J2)
        for name, x in a.witness.npz_members().items():
            assert np.array_equal(np.asarray(x), np.asarray(b.witness.npz_members()[name]))


def test_a_pointer_misread_from_the_file_is_caught(monkeypatch):
    """Seeded fault: every read from the file says "arrived by (-1, -1)"."""
    dr = np.zeros((8, 7, 7), dtype=np.uint8)
    assert search_opt_path_fast(dr, (0, 0), (6, 6), progress=False).path
    monkeypatch.setattr(_search, "BACK_POINTER_BYTES", 0)
    monkeypatch.setattr(_search.os, "pread", lambda fd, n, at: b"\x00")
    for search in (search_opt_path, search_opt_path_fast):
        with pytest.raises(AssertionError):
            search(dr, (0, 0), (6, 6))
