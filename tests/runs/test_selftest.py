"""The mutation self-check: every seeded fault is caught in full mode, by the condition that
names it; the table records what sampled mode catches; `cfmpa selftest` fails when one is missed."""

from __future__ import annotations

from pathlib import Path

import pytest

import cfmpa.runs._selftest as st
from cfmpa.runs._contracts import Mode
from cfmpa.runs._selftest import (
    FAULTS,
    SAMPLE,
    WORKCELLS,
    FaultNotMade,
    run_fault,
    run_selftest,
    selftest_rows,
    selftest_table,
    workcell,
)
from cfmpa.spec import load_scenario, make_grid

ROOT = Path(__file__).resolve().parents[2]

#: The condition that must catch each fault first in full mode (stop=False lists the rest too).
FIRST_CATCH = {
    "blocked cell flipped to free": "Theorem 3 post.cells",
    "regions without the arc margin": "Theorem 3 post.cells",
    "N rounded down": "Theorem 3 pre.grid.N",
    "cell grid coarser than omega dt": "Theorem 3 pre.grid.h",
    "non-optimal path": "Theorem 4 post.optimal",
    "forged witness": "Theorem 4 post.optimal",
    "path with a jump": "Theorem 4 post.is_path",
    "path ends early at a goal swept later": "Theorem 4 post.is_path",
    "path through a blocked cell in the rest layer": "Theorem 4 post.is_path",
}


@pytest.fixture(scope="module")
def rows():
    return selftest_rows()


def test_the_list_is_the_issues_list():
    assert [f.name for f in FAULTS] == list(FIRST_CATCH)


def test_every_fault_is_caught_in_full_mode_by_its_condition(rows):
    for r in rows:
        assert r.caught_full, r.fault
        assert r.caught_by.split("; ")[0] == FIRST_CATCH[r.fault], r


def test_sampled_mode_catches_what_it_checks_for_certain(rows):
    by = {r.fault: r for r in rows}
    # preconditions and is_path are checked whole in every mode but off
    for name in ("N rounded down", "cell grid coarser than omega dt", "path with a jump",
                 "path ends early at a goal swept later",
                 "path through a blocked cell in the rest layer"):
        assert by[name].caught_sampled and by[name].caught_by_sampled.split("; ")[0] == (
            FIRST_CATCH[name]), name
    # optimality is full mode's alone: stated, and so recorded
    assert not by["non-optimal path"].caught_sampled
    assert not by["forged witness"].caught_sampled


def test_the_waiting_path_is_also_a_real_contact(rows):
    early = next(r for r in rows if "early" in r.fault)
    assert "certificate: contact" in early.caught_by.split("; ")


def test_sampled_mode_catches_a_cell_fault_once_its_sample_covers_the_grid():
    flip = FAULTS[0]
    outcome, _ = run_fault(flip, Mode.SAMPLED, sample=10 ** 6)
    assert outcome.caught_by[0] == "Theorem 3 post.cells"


def test_mode_off_checks_no_triple_but_still_the_certificate():
    # Off waives the contracts, never the safety results: a real contact, or a path cell not
    # proved free in ball arithmetic, is still a violation.
    for f in FAULTS:
        outcome, _ = run_fault(f, Mode.OFF)
        assert outcome.other_error is None, f.name
        assert all(by.startswith(("certificate: ", "exact re-decision of the path's cells "))
                   for by in outcome.caught_by), (f.name, outcome)
        if "early" in f.name:
            assert "certificate: contact" in outcome.caught_by


def test_a_fault_that_cannot_be_made_is_an_error_not_a_pass():
    # Tf = 1 s exactly is 4 whole layers of 0.25 s: rounding down changes nothing.
    s = workcell("small", left={**WORKCELLS["small"]["left"], "start": [0.5, 0.5],
                                "goal": [1.5, 1.0]})
    fault = next(f for f in FAULTS if f.name == "N rounded down")
    with pytest.raises(FaultNotMade):
        fault.make(s, fault.variant, make_grid(s))


def test_the_table_and_the_exit_code(rows, monkeypatch, capsys):
    text = selftest_table(rows)
    for r in rows:
        assert f"{r.fault}" in text and r.detail in text
    assert f"{SAMPLE} random cells (seed 0)" in text
    monkeypatch.setattr(st, "selftest_rows", lambda: rows)
    assert run_selftest() == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0].split() == ["fault", "mode", "caught", "by"]
    assert f"all {len(rows)} faults caught in full mode" in out
    missed = (rows[0].__class__(**{**rows[0].__dict__, "caught_full": False,
                                   "caught_by": "not caught"}),) + rows[1:]
    monkeypatch.setattr(st, "selftest_rows", lambda: missed)
    assert run_selftest() == 1
    assert f"NOT CAUGHT in full mode: {rows[0].fault}" in capsys.readouterr().out


@pytest.mark.slow
def test_the_bundled_early_arrival_scenario_is_caught_in_full_mode():
    s = load_scenario(ROOT / "scenarios" / "early-arrival.toml")
    fault = next(f for f in FAULTS if "early" in f.name)
    outcome, _ = run_fault(fault, Mode.FULL, scenario=s)
    assert outcome.caught_by[0] == "Theorem 4 post.is_path"
    assert "certificate: contact" in outcome.caught_by
