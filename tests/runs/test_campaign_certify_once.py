"""A campaign workcell certifies each distinct path once (the variants often plan the same one),
and every variant's outcome is its own path's certificate."""

from __future__ import annotations

import pytest

import cfmpa.runs._campaign as C
from cfmpa.spec import certify, make_grid


@pytest.mark.parametrize("index", [7, 9], ids=["one-path", "two-paths"])
def test_each_distinct_path_is_certified_once_and_is_its_own(index, monkeypatch):
    calls = []

    def counted(s, g, path):
        calls.append(tuple(map(tuple, path)))
        return certify(s, g, path)
    monkeypatch.setattr(C, "certify", counted)
    case = C.plan_workcell(0, index)
    paths = [tuple(map(tuple, o.path)) for o in case.outcomes if o.status == "found"]
    assert len(paths) == 3 and len(calls) == len(set(paths)) == len(set(calls))
    s = C.random_workcell(0, index)
    g = make_grid(s)
    for o in case.outcomes:
        c = certify(s, g, o.path)
        assert (o.certified_clear, o.min_clearance_m) == (c.clear, c.min_clearance_m)


def test_the_check_sees_a_certificate_handed_to_another_path():
    # Seeded fault: a memo that hands the workcell's first certificate to every variant gives
    # workcell 9's tight path (50 cells) the 51-cell path's clearance, which the check above
    # compares with the tight path's own.
    s = C.random_workcell(0, 9)
    g = make_grid(s)
    case = C.plan_workcell(0, 9)
    first, tight = case.outcomes[0], case.outcomes[-1]
    assert first.path != tight.path
    own, handed = certify(s, g, tight.path), certify(s, g, first.path)
    assert (own.clear, own.min_clearance_m) != (handed.clear, handed.min_clearance_m)
    assert (tight.certified_clear, tight.min_clearance_m) == (own.clear, own.min_clearance_m)
