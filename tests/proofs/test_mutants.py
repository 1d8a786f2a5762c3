"""Proof mutants: seeded mutations of a copy of the proof code must make the run fail.

Each mutant is the source of a module of cfmpa.proofs with one edit, executed as a fresh module
(the original is untouched); the prove run is pointed at the mutant's obligations and must exit
1 with the affected obligations FAILED, for the mutation's own reason (a refutation, a vacuous
program), not only because the statement is no longer the pinned one.
"""

from __future__ import annotations

import importlib
import inspect
import io
import json
import sys
import types
from pathlib import Path

import pytest

import cfmpa.proofs._runner as runner
from cfmpa.proofs import Verdict, discharge, run_prove


def mutant(monkeypatch: pytest.MonkeyPatch, modname: str, old: str, new: str, *,
           within: str | None = None) -> types.ModuleType:
    """A copy of module ``cfmpa.proofs.<modname>`` with ``old`` replaced by ``new`` (every
    occurrence, inside the function ``within`` if given; there must be one at least)."""
    src = inspect.getsource(importlib.import_module(f"cfmpa.proofs.{modname}"))
    lo, hi = 0, len(src)
    if within is not None:
        lo = src.index(f"\ndef {within}(")
        hi = src.find("\ndef ", lo + 1)
        hi = len(src) if hi < 0 else hi
    part = src[lo:hi]
    assert old in part, f"mutation of {modname}: {old!r} not found"
    src = src[:lo] + part.replace(old, new) + src[hi:]
    mod = types.ModuleType(f"cfmpa.proofs.{modname}_mutant")
    mod.__package__ = "cfmpa.proofs"
    monkeypatch.setitem(sys.modules, mod.__name__, mod)
    exec(compile(src, f"<mutant of {modname}>", "exec"), mod.__dict__)
    return mod


def use_collectors(monkeypatch: pytest.MonkeyPatch, mod: types.ModuleType, *names: str) -> None:
    """The run collects the mutant module's collectors ``names`` in place of the originals
    (runner.COLLECTORS holds the functions, so each is swapped there by its name)."""
    swapped = tuple(getattr(mod, c.__name__) if c.__name__ in names else c
                    for c in runner.COLLECTORS)
    assert sum(a is not b for a, b in zip(swapped, runner.COLLECTORS)) == len(names)
    monkeypatch.setattr(runner, "COLLECTORS", swapped)


def _prove(only: list[str], out: Path) -> tuple[int, dict[str, dict]]:
    rc = run_prove(out_dir=out, only=only, stream=io.StringIO())
    doc = json.loads((out / "results.json").read_text())
    return rc, {o["id"]: o for o in doc["obligations"]}


# Slow: the default run keeps the same mutant through cfmpa prove's exit code.
@pytest.mark.slow
def test_a_smaller_margin_constant_fails_the_margin_lemma(monkeypatch, tmp_path):
    # r g^2/8 -> r g^2/16 in Lemma.sweep_margin: the lemma's margins R g^2/16.
    m = mutant(monkeypatch, "_obl_margin", "/ 8", "/ 16", within="_sweep_margin")
    use_collectors(monkeypatch, m, "margin_obligations")
    rc, obs = _prove(["Lemma.sweep_margin"], tmp_path)
    assert rc == 1
    assert obs["Lemma.sweep_margin"]["verdict"] == "failed"
    assert obs["Lemma.sweep_margin"]["reason"] == "refuted: counterexample to compose"


def test_cfmpa_prove_exits_1_on_the_margin_mutant(monkeypatch, tmp_path, capsys):
    from cfmpa.cli import main
    m = mutant(monkeypatch, "_obl_margin", "/ 8", "/ 16", within="_sweep_margin")
    use_collectors(monkeypatch, m, "margin_obligations")
    assert main(["prove", "--out", str(tmp_path), "--only", "Lemma.sweep_margin"]) == 1
    assert "counterexample to compose" in capsys.readouterr().out


def test_a_smaller_arc_constant_fails_the_arc_lemma(monkeypatch):
    m = mutant(monkeypatch, "_obl_margin", "delta = r * g * g / 8", "delta = r * g * g / 16",
               within="_arc")
    ob = next(o for o in m.margin_obligations() if o.id == "Margin.arc_chord")
    pr = discharge(ob)
    assert pr.verdict is Verdict.FAILED and pr.counterexample


def test_assuming_found_in_the_search_wrapper_fails(monkeypatch, tmp_path):
    # On a copy of the source: "the search always finds a path".
    m = mutant(monkeypatch, "_obl_paths", "Assume(contract)", "Assume(z3.And(contract, found))",
               within="search_top_level")
    use_collectors(monkeypatch, m, "theorem_obligations", "prop8_obligations")
    only = ["Thm2.searchoptpath", "Thm4.searchoptpath", "Prop8.prestrength_thm4"]
    rc, obs = _prove(only, tmp_path)
    assert rc == 1
    for ident in only:
        assert obs[ident]["verdict"] == "failed", ident
        assert "vacuous program" in obs[ident]["reason"] and "Not(found)" in obs[ident]["reason"]


def test_a_flipped_box_rule_fails_the_box_nesting(monkeypatch, tmp_path):
    # The modified box pointing away from the goal (s_q's sign flipped), in a copy of the rule
    # table's row: Thm3.box_nesting runs the code's rule, so it is the proof that fails.
    import dataclasses

    from cfmpa.spec import _grid as grid
    from cfmpa.spec import if_then, max_of, min_of

    def flipped(a, b, step, up):
        end = a + if_then(up, -1.0, 1.0) * step
        return (min_of(a, end), max_of(a, end))
    monkeypatch.setitem(grid._RULES, "modified",
                        dataclasses.replace(grid._RULES["modified"], joint_box=flipped))
    rc, obs = _prove(["Thm3.box_nesting"], tmp_path)
    assert rc == 1 and obs["Thm3.box_nesting"]["verdict"] == "failed"
    assert "refuted" in obs["Thm3.box_nesting"]["reason"]


@pytest.mark.slow
def test_an_assume_contradicting_its_branch_is_vacuous(monkeypatch):
    # The search called only where the start is blocked: the else-branch says it is not.
    m = mutant(monkeypatch, "_obl_paths", "Assume(contract)",
               "Assume(z3.And(contract, st.P[0, st.start[0], st.start[1]] == 1))",
               within="search_top_level")
    ob = next(o for o in m.theorem_obligations() if o.id == "Thm2.searchoptpath")
    pr = discharge(ob)
    assert pr.verdict is Verdict.FAILED and "vacuous program" in pr.reason


@pytest.mark.slow
def test_dropping_builtdrs_postcondition_from_the_search_premise_fails(monkeypatch):
    m = mutant(monkeypatch, "_obl_paths",
               "pre = z3.And(st.d.sane(), in_grid(st.d, st.start), in_grid(st.d, st.goal), pre_p)",
               "pre = z3.And(st.d.sane(), in_grid(st.d, st.start), in_grid(st.d, st.goal))",
               within="_search")
    ob = next(o for o in m.theorem_obligations() if o.id == "Thm2.searchoptpath")
    pr = discharge(ob)
    assert pr.verdict is not Verdict.PROVED
