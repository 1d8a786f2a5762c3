"""Resource limits of the prove's solver calls (proofs/_limits.py, docs/model.md §6.1): every Z3
check runs under a deterministic resource count, so a verdict does not depend on the machine's
load; a check that needs more than its limit is UNKNOWN, never proved, and fails the run."""

from __future__ import annotations

import json
import time

import pytest
import z3

from cfmpa.proofs import VC, Method, Obligation, Verdict, Z3Query, discharge, run_obligations
from cfmpa.proofs import _controls as C
from cfmpa.proofs import _limits as L
from cfmpa.proofs._depth import vc_depth
from cfmpa.proofs._obligation import Smoke, _smoke
from cfmpa.proofs._runner import FIXED_IDS, collect_obligations


def _ob(build, ident="T.limits", timeout_ms=5_000) -> Obligation:
    return Obligation(ident, "test", "none", "a test obligation", Method.Z3, Verdict.PROVED,
                      build, timeout_ms=timeout_ms)


def _square() -> Z3Query:
    x = z3.Real("x")
    return Z3Query((VC("square", (("x > 1", x > 1),), x * x > 1),))


def _fermat() -> Z3Query:
    # x^3 + y^3 = z^3 over positive integers: Z3 cannot refute it and searches on.
    x, y, z = z3.Ints("x y z")
    return Z3Query((VC("fermat3", (("positive", z3.And(x >= 1, y >= 1, z >= 1)),),
                       x * x * x + y * y * y != z * z * z),))


def test_every_fixed_z3_obligation_has_a_resource_limit_and_no_other_id_does():
    z3_ids = {o.id for o in collect_obligations() if o.method is Method.Z3}
    assert z3_ids and z3_ids <= set(FIXED_IDS)
    assert set(L.Z3_RLIMITS) == z3_ids
    assert all(v >= 100_000 for v in L.Z3_RLIMITS.values())


def test_a_check_runs_under_its_limit_and_records_its_counts(monkeypatch):
    monkeypatch.setitem(L.Z3_RLIMITS, "T.limits", 1_000_000)
    pr = discharge(_ob(_square))
    assert pr.verdict is Verdict.PROVED and pr.rlimit == 1_000_000
    vac, proof = pr.vcs[0].rlimit_count
    assert 0 < vac < 1_000_000 and 0 < proof < 1_000_000
    # The replayable query says which limits ran: the resource limit and the wall-clock net.
    assert "(set-option :rlimit 1000000)" in pr.smtlib
    assert f"(set-option :timeout {5_000 * L.WALL_NET_FACTOR})" in pr.smtlib
    # The count is a function of the statement: the same on another run.
    assert discharge(_ob(_square)).vcs[0].rlimit_count == (vac, proof)


def test_a_limit_too_small_makes_the_obligation_unknown_and_the_run_fail(monkeypatch, tmp_path):
    # Seeded fault: a resource limit of 1 leaves no check decided.
    monkeypatch.setitem(L.Z3_RLIMITS, "T.limits", 1)
    pr = discharge(_ob(_square))
    assert pr.verdict is Verdict.UNKNOWN and not pr.as_expected
    assert "resource limit" in (pr.reason_unknown or "")
    run = run_obligations([_ob(_square)], tmp_path, ["T.limits"])
    assert not run.ok


def test_the_resource_limit_not_the_wall_clock_stops_an_undecided_check(monkeypatch):
    # A wall clock of 60 s (a net of 300 s) would run on; the resource limit ends it.
    monkeypatch.setitem(L.Z3_RLIMITS, "T.limits", 300_000)
    t0 = time.perf_counter()
    pr = discharge(_ob(_fermat, timeout_ms=60_000))
    assert time.perf_counter() - t0 < 20
    assert pr.verdict is Verdict.UNKNOWN and "resource limit" in (pr.reason_unknown or "")


def test_without_an_entry_an_obligation_runs_on_the_wall_clock():
    pr = discharge(_ob(_square, ident="T.not_in_the_table"))
    assert pr.verdict is Verdict.PROVED and pr.rlimit is None
    assert "rlimit" not in pr.smtlib and "(set-option :timeout 5000)" in pr.smtlib


def test_depth_and_smoke_checks_run_under_a_resource_limit():
    x, y = z3.Reals("x y")
    f = z3.Function("f", z3.RealSort(), z3.RealSort())
    # Ground: proved with the quantified hypothesis abstracted away (a check Z3 runs).
    hyps, goal = [z3.ForAll([y], f(y) > 0), x > 1, x < 3], x > 0
    assert vc_depth(hyps, goal) == "ground"
    # Seeded fault: a limit of 1 decides no abstraction, so the level falls to full.
    assert vc_depth(hyps, goal, rlimit=1) == "full"
    sm = Smoke("reached", (("x > 1", x > 1),), x > 5)
    assert _smoke(sm, {}).answer == "sat"


def test_smoke_limit_applies(monkeypatch):
    from cfmpa.proofs import _obligation as O
    x, y = z3.Ints("x y")
    # A point reached only at a cube sum: found with room, not with a limit of 1.
    sm = Smoke("cubes", (("pos", z3.And(x >= 1, y >= 1)),), x * x * x + y * y * y != 9)
    assert _smoke(sm, {}).answer == "sat"
    monkeypatch.setattr(O, "SMOKE_RLIMIT", 1)
    assert _smoke(sm, {}).answer == "unknown"


def test_a_premise_control_is_decided_by_its_resource_limit(monkeypatch):
    # The postcondition's control is refuted within its limit (test_controls); seeded fault:
    # limits of 1 leave it undecided, said so (a resource limit, not a timeout).
    monkeypatch.setattr(C, "PREMISE_PINNED_RLIMIT", 1)
    monkeypatch.setattr(C, "PREMISE_FREE_RLIMIT", 1)
    outcome, detail = C._without("modified", 6)
    assert outcome == "unknown" and detail.count("resource limit") == 2, detail


def test_calibrate_takes_margin_times_the_largest_count():
    obs = [{"id": "A", "method": "z3", "vcs": [{"rlimit_count": [1_234_567, 50]},
                                              {"rlimit_count": [7, 2_000_001]}]},
           {"id": "B", "method": "z3", "vcs": [{"rlimit_count": [10, 20]}]},
           {"id": "C", "method": "sympy", "vcs": []}]
    assert L.calibrate(obs) == {"A": 21_000_000, "B": 100_000}
    assert L._round_up(1_234_567) == 1_300_000 and L._round_up(99) == 99


def test_calibrate_cli_prints_the_table_and_rejects_bad_input(tmp_path, capsys):
    good = tmp_path / "results.json"
    good.write_text(json.dumps({"obligations": [
        {"id": "A", "method": "z3", "vcs": [{"rlimit_count": [300_000, 10]}]}]}))
    assert L._main([str(good)]) == 0
    assert "'A': 3_000_000," in capsys.readouterr().out
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    assert L._main([str(bad)]) == 2
    err = capsys.readouterr().err
    assert str(bad) in err and len(err.strip().splitlines()) == 1
    assert L._main([]) == 2


@pytest.mark.parametrize("ident", ["Lemma.sweep_margin", "Witness.labels_sound"])
def test_the_table_leaves_room_for_the_heaviest_obligations(ident):
    # The two that ran out of a 20 s wall clock at a load of 10: their limits are at least
    # ten times what their checks use (the counts recorded when calibrated).
    assert L.Z3_RLIMITS[ident] >= 10 * 1_000_000


def test_an_undecided_premise_control_stops_at_its_resource_limit():
    # The tight composition without its first premise: shown unsat with the pins, not decided
    # without them, ending at the resource limit (on any machine), not at a wall clock.
    outcome, detail = C._without("tight", 1)
    assert outcome == "unknown", detail
    assert detail.startswith("unsat with the one-cell pins; unknown without pins")
    assert f"resource limit {C.PREMISE_FREE_RLIMIT} reached" in detail, detail
