"""The block CSV reader of `cfmpa certify` (spec/_trajectory.py ``_csv_row_blocks``,
docs/model.md §12) gives ``_csv_rows``' rows, bit for bit, and its errors after the same rows:
on random bodies with blank, whitespace-only, short, long, non-numeric and non-finite rows, in
blocks of any size; rows given one at a time (``_blocks_of``, a bag's) likewise. Seeded faults:
copies of the module with a check of the block path dropped disagree."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mutant_module
from cfmpa.errors import InputError
from cfmpa.spec import _trajectory as tr

HEADER = "t,left1,left2,right1,right2\n"
SHUFFLED = "right2, t,left1,right1 ,left2\n"

number = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False, width=64).map(repr),
    st.integers(-10**6, 10**6).map(str),
    st.sampled_from([" 1.5", "2 ", "1_000", "+3", "-0", "1e-310", "0x1", "", "abc", "inf",
                     "-inf", "nan", "1e999", "1,5"]))
good_row = st.lists(st.floats(-1e3, 1e3, allow_nan=False).map(repr), min_size=5, max_size=5)
any_row = st.lists(number, min_size=3, max_size=7)
line = st.one_of(good_row.map(",".join), good_row.map(",".join), good_row.map(",".join),
                 any_row.map(",".join), st.sampled_from(["", "  ", "\t", " , , , , "]))


def _outcome(items, error) -> tuple[list[tuple[int, tuple[int, ...]]], str | None]:
    rows = [(no, tuple(np.asarray(v, dtype=float).view(np.int64).tolist())) for no, v in items]
    return rows, None if error is None else error.render()


def _per_row(text: str):
    items, error = [], None
    try:
        for no, vals in tr._csv_rows(iter(text.splitlines(True)), "f.csv"):
            items.append((no, vals))
    except InputError as exc:
        error = exc
    return _outcome(items, error)


def _blocks(text: str, block: int, module=tr):
    items, error = [], None
    try:
        for nos, arr in module._csv_row_blocks(iter(text.splitlines(True)), "f.csv", block):
            assert arr.shape == (len(nos), 5)
            items.extend(zip(nos, arr))
    except InputError as exc:
        error = exc
    return _outcome(items, error)


@settings(max_examples=200, deadline=None)
@given(st.lists(line, max_size=14), st.sampled_from([HEADER, SHUFFLED]),
       st.integers(1, 9), st.booleans(), st.booleans())
def test_blocks_are_the_per_row_reader(body, header, block, newline_at_end, crlf):
    end = "\r\n" if crlf else "\n"
    text = header + end.join(body) + (end if newline_at_end and body else "")
    assert _blocks(text, block) == _per_row(text)


def test_rows_given_one_at_a_time_come_in_blocks_and_fail_after_them():
    def rows():
        for k in range(7):
            yield 10 + k, [float(k), 1.0, 2.0, 3.0, 4.0]
        raise InputError("row", "x", "is broken", source="bag", line=17)

    got, error = [], None
    try:
        for nos, arr in tr._blocks_of(rows(), 3):
            got.extend(zip(nos, arr.tolist()))
    except InputError as exc:
        error = exc
    assert [no for no, _ in got] == list(range(10, 17))
    assert [v[0] for _, v in got] == [float(k) for k in range(7)]
    assert error is not None and "is broken" in error.render()
    assert [len(n) for n, _ in tr._blocks_of(iter([(1, [0.0] * 5)] * 6), 3)] == [3, 3]


CASES = [HEADER + "0,1,2,3,4\n\n1,1,2,3,4\n",             # a row after a blank line
         HEADER + "0,1,2,3,4\n1,2,3,4\n2,1,2,3,4,5\n",     # four values, then six
         HEADER + "0,1,2,3,4\n1,inf,2,3,4\n",              # not finite
         HEADER + "0,1,2,3,4\n1,1,2,3,4\n\n\n",            # trailing blank lines: no rows
         SHUFFLED + "0,1,2,3,4\n1,5,6,7,8\n"]


def _agree(module) -> bool:
    return all(_blocks(text, block, module) == _per_row(text)
               for text in CASES for block in (1, 2, 3, 8))


@pytest.mark.parametrize("old,new", [
    ("if blank is None and all(map(str.strip, batch)):", "if all(map(str.strip, batch)):"),
    ('list(map(str.count, batch, itertools.repeat(\n                    ","))).count(width - 1) '
     '== len(batch)', "True"),
    ("if arr is not None and np.all(np.isfinite(arr)):", "if arr is not None:"),
    ("yield range(no + 1, no + 1 + len(batch)), arr[:, order]",
     "yield range(no + 1, no + 1 + len(batch)), arr"),
])
def test_seeded_fault_a_dropped_check_of_the_block_path_disagrees(old, new, monkeypatch):
    assert _agree(tr)
    mutant = mutant_module.mutated_module(
        "blocks", "spec/_trajectory.py", [(old, new)],
        lambda name, mod: monkeypatch.setitem(__import__("sys").modules, name, mod))
    assert not _agree(mutant)
