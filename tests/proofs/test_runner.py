"""`make prove`'s driver: the expected-id check, replay hashes, results.json, the summary."""

from __future__ import annotations

import dataclasses
import hashlib
import io
import json
import shutil
import subprocess
from pathlib import Path

import pytest
import z3

from cfmpa.proofs import (
    ASSUMPTIONS,
    FIXED_IDS,
    Verdict,
    collect_obligations,
    expected_ids,
    render_report,
    run_obligations,
    run_prove,
    scenarios_note,
    selected,
)

REPO = Path(__file__).resolve().parents[2]
CHEAP = ["Def1", "Lemma1", "Prop2", "Margin.naive_hull"]


def _strip_times(doc: dict) -> dict:
    doc = dict(doc)
    doc.pop("seconds")
    doc["obligations"] = [{k: v for k, v in o.items()
                           if k not in ("seconds", "change", "cvc5_seconds")}
                          for o in doc["obligations"]]
    return doc


def test_fixed_ids_match_the_collected_obligations_exactly():
    # Compared as a mapping id -> verdict: EXPECTED_VERDICTS need not follow
    # the order the obligations are collected in, but every id and its verdict must match.
    from cfmpa.proofs import EXPECTED_VERDICTS

    obs = collect_obligations(scenarios_dir="/nonexistent")
    ids = [o.id for o in obs]
    assert len(ids) == len(set(ids))
    collected = {o.id: o.expected for o in obs}
    assert collected == EXPECTED_VERDICTS and set(FIXED_IDS) == set(ids)
    # The comparison is blind to order only: reordered it holds, a changed verdict fails it.
    assert dict(reversed(list(EXPECTED_VERDICTS.items()))) == collected
    flipped = dict(EXPECTED_VERDICTS, **{"Prop8.printed": Verdict.PROVED})
    assert flipped != collected


def test_scenario_ids_come_from_the_files_found(tmp_path: Path):
    for name in ("a", "b"):
        shutil.copy(REPO / "scenarios" / "default.toml", tmp_path / f"{name}.toml")
    ids = expected_ids(tmp_path)
    assert ids[: len(FIXED_IDS)] == FIXED_IDS
    assert ids[len(FIXED_IDS):] == tuple(f"Scenario.{s}.{c}" for s in ("a", "b")
                                         for c in ("time_grid", "cspace_grid", "margin_side",
                                                   "containment", "translation_original",
                                                   "translation_modified", "translation_tight"))
    assert [o.id for o in collect_obligations(tmp_path, ["Scenario"])] == list(ids[len(FIXED_IDS):])


def test_selection_by_id_prefix_and_glob():
    assert selected("Prop8.printed", ["Prop8"]) and selected("Prop8.printed", ["Prop8.printed"])
    assert not selected("Prop80.x", ["Prop8"])
    assert selected("Thm3.builtdr", ["Thm*"]) and not selected("Def1.segment", ["Thm*"])
    assert selected("anything", None)


def test_replay_reports_new_same_changed_and_writes_atomically(tmp_path: Path):
    obs = collect_obligations("/nonexistent", CHEAP)
    exp = [o.id for o in obs]
    first = run_obligations(obs, tmp_path, exp)
    assert first.ok and set(first.changes.values()) == {"new"}
    files = sorted(p.name for p in tmp_path.iterdir())
    assert not [f for f in files if f.startswith(".")]              # no temp files left over
    assert "Def1.segment.smt2" in files and "Margin.naive_hull.txt" in files
    doc1 = json.loads((tmp_path / "results.json").read_text())
    entry = next(o for o in doc1["obligations"] if o["id"] == "Def1.segment")
    text = (tmp_path / "Def1.segment.smt2").read_text()
    assert entry["sha256"] == hashlib.sha256(text.encode()).hexdigest()

    # The saved SMT-LIB replays to the same answers, check by check. Its `set-option`s
    # (:rlimit, :timeout) set Z3's global parameters for the whole process, as a script's
    # options do: put back afterwards, or every later solver in this process inherits them.
    try:
        for o in doc1["obligations"]:
            if o["method"] == "z3":
                ctx = z3.Context()
                out = z3.Z3_eval_smtlib2_string(ctx.ref(), (tmp_path / o["file"]).read_text())
                assert out.split() == [a for v in o["vcs"] for a in (v["vacuity"], v["answer"])]
    finally:
        z3.reset_params()

    second = run_obligations(obs, tmp_path, exp)
    assert set(second.changes.values()) == {"same"}
    doc2 = json.loads((tmp_path / "results.json").read_text())
    assert _strip_times(doc1) == _strip_times(doc2)

    edited = [dataclasses.replace(o, statement=o.statement + " (edited)")
              if o.id == "Prop2.endpoints" else o for o in obs]
    third = run_obligations(edited, tmp_path, exp)
    assert third.changes["Prop2.endpoints"] == "changed"
    assert {v for k, v in third.changes.items() if k != "Prop2.endpoints"} == {"same"}


def test_a_missing_or_unexpected_id_fails_the_run(tmp_path: Path):
    obs = collect_obligations("/nonexistent", ["Def1"])
    run = run_obligations(obs, tmp_path, [o.id for o in obs] + ["Ghost.id"])
    assert not run.ok and run.missing_ids == ("Ghost.id",)
    assert "MISSING obligations" in render_report(run)
    run = run_obligations(obs, tmp_path, [obs[0].id])
    assert not run.ok and run.unexpected_ids == tuple(o.id for o in obs[1:])


def test_a_scenario_that_does_not_load_fails_instead_of_vanishing(tmp_path: Path):
    (tmp_path / "broken.toml").write_text('name = "broken"\n')
    out = io.StringIO()
    rc = run_prove(out_dir=tmp_path / "out", scenarios_dir=tmp_path, only=["Scenario"],
                   stream=out)
    assert rc == 1
    doc = json.loads((tmp_path / "out" / "results.json").read_text())
    verdicts = {o["id"]: o["verdict"] for o in doc["obligations"]}
    assert verdicts == {f"Scenario.broken.{c}": "failed"
                        for c in ("time_grid", "cspace_grid", "margin_side", "containment",
                                  "translation_original", "translation_modified",
                                  "translation_tight")}


# A whole run (about a minute): `make prove` is this run, and CI runs it again from the wheel
# (tests/test_wheel.py); kept behind the marker so that make test stays under ten minutes.
@pytest.mark.slow
def test_full_run_discharges_everything_as_expected(tmp_path: Path):
    out = io.StringIO()
    rc = run_prove(out_dir=tmp_path, scenarios_dir=REPO / "scenarios", stream=out)
    text = out.getvalue()
    assert rc == 0, text
    doc = json.loads((tmp_path / "results.json").read_text())
    assert doc["ok"] and not doc["missing_ids"] and not doc["unexpected_ids"]
    ids = [o["id"] for o in doc["obligations"]]
    assert ids == list(expected_ids(REPO / "scenarios"))
    assert all(o["verdict"] == o["expected"] for o in doc["obligations"])
    refuted = {o["id"] for o in doc["obligations"] if o["verdict"] == "refuted as expected"}
    assert refuted == {"Def1.segment_printed", "Margin.naive_hull", "Prop5.printed",
                       "Def4.is_path_printed", "Def4.is_path_printed_off_grid", "Prop8.printed"}
    assert all(o["counterexample"] for o in doc["obligations"] if o["id"] in refuted)
    assert [a["id"] for a in doc["assumptions"]] == [a.id for a in ASSUMPTIONS]
    assert "Summary of proof obligations" in text and "Assumptions (not proved)" in text
    assert doc["totals"]["unknown"] == 0 and doc["totals"]["failed"] == 0
    for o in doc["obligations"]:
        assert (tmp_path / o["file"]).is_file()
    assert Verdict(doc["obligations"][0]["verdict"]) is Verdict.PROVED


def test_verdicts_are_checked_against_the_pinned_map(tmp_path: Path):
    # An obligation claiming its own (wrong) expectation passes Obligation.expected, not the pin.
    from cfmpa.proofs import (
        EXPECTED_VERDICTS,
        CheckOutcome,
        CheckQuery,
        Method,
        Obligation,
        pinned_verdict,
    )
    assert EXPECTED_VERDICTS["Margin.cos_bound"] is Verdict.PROVED
    assert pinned_verdict("Scenario.x.time_grid") is Verdict.PROVED
    assert pinned_verdict("Ghost.id") is None
    liar = Obligation("Margin.cos_bound", "g", "ref", "s", Method.SYMPY,
                      Verdict.REFUTED_AS_EXPECTED,
                      lambda: CheckQuery(lambda: CheckOutcome(False, "no", "no"), "c"))
    run = run_obligations([liar], tmp_path, ["Margin.cos_bound"])
    assert run.proofs[0].as_expected and not run.ok
    assert run.verdict_mismatch == ("Margin.cos_bound",)
    assert "VERDICTS differing" in render_report(run)


def test_duplicate_ids_fail_the_run(tmp_path: Path):
    obs = collect_obligations("/nonexistent", ["Def1.segment"])
    run = run_obligations(list(obs) + list(obs[:1]), tmp_path, [o.id for o in obs])
    assert not run.ok and run.duplicate_ids == ("Def1.segment",) and not run.unexpected_ids
    assert "DUPLICATE" in render_report(run)


def test_only_that_selects_nothing_is_an_input_error(tmp_path: Path, capsys):
    from cfmpa.cli import main
    from cfmpa.errors import InputError
    with pytest.raises(InputError, match="selects no obligation") as exc:
        run_prove(out_dir=tmp_path, scenarios_dir=REPO / "scenarios", only=["Nonexistent"],
                  stream=io.StringIO())
    assert exc.value.value == "Nonexistent"
    rc = main(["prove", "--out", str(tmp_path), "--scenarios", str(REPO / "scenarios"),
               "--only", "Def1.segment", "--only", "Nonexistent"])
    assert rc == 2 and "'Nonexistent'" in capsys.readouterr().err
    assert not (tmp_path / "results.json").exists()


def test_an_empty_or_missing_scenarios_folder_is_an_input_error(tmp_path: Path):
    from cfmpa.errors import InputError
    for d in (tmp_path, tmp_path / "missing"):
        with pytest.raises(InputError, match="--scenarios"):
            run_prove(out_dir=tmp_path / "out", scenarios_dir=d, only=["Def1"],
                      stream=io.StringIO())


def test_a_deleted_bundled_scenario_is_a_missing_id(tmp_path: Path, monkeypatch):
    import cfmpa.proofs._runner as runner
    from cfmpa.proofs import BUNDLED_SCENARIOS
    copy = tmp_path / "scenarios"
    shutil.copytree(REPO / "scenarios", copy)
    assert sorted(f.stem for f in copy.glob("*.toml")) == sorted(BUNDLED_SCENARIOS)
    (copy / "narrow-gap.toml").unlink()
    monkeypatch.setattr(runner, "BUNDLED_DIR", copy)
    out = io.StringIO()
    rc = run_prove(out_dir=tmp_path / "out", scenarios_dir=copy,
                   only=["Scenario.narrow-gap", "Scenario.default.time_grid"], stream=out)
    assert rc == 1
    assert "MISSING obligations (expected, not produced): Scenario.narrow-gap.time_grid" in out.getvalue()


def test_another_scenarios_folder_says_what_it_expects(tmp_path: Path):
    shutil.copy(REPO / "scenarios" / "default.toml", tmp_path / "mine.toml")
    out = io.StringIO()
    rc = run_prove(out_dir=tmp_path / "out", scenarios_dir=tmp_path,
                   only=["Scenario.mine.time_grid"], stream=out)
    assert rc == 0
    line = out.getvalue().splitlines()[2]
    assert line == (f"scenarios: the 1 workcell(s) in {tmp_path}, expecting "
                    "Scenario.mine.{time_grid,cspace_grid,margin_side,containment,"
                    "translation_original,translation_modified,translation_tight}")
    assert "not the bundled" not in out.getvalue()


def test_the_bundled_folder_says_what_it_expects():
    from cfmpa.proofs import BUNDLED_DIR
    note = scenarios_note(BUNDLED_DIR)
    assert note.startswith("scenarios: the 7 bundled workcells, expecting "
                           "Scenario.default.{time_grid,cspace_grid,margin_side,containment,"
                           "translation_original,translation_modified,translation_tight}, ")
    assert "\n" not in note and "Scenario.original-fails.{" in note


def test_results_json_records_what_it_is_of(tmp_path: Path):
    # The commit and every scenario file's hash, so a report can refuse results of another tree.
    rc = run_prove(out_dir=tmp_path, scenarios_dir=REPO / "scenarios", only=["Def1"],
                   stream=io.StringIO())
    assert rc == 0
    run = json.loads((tmp_path / "results.json").read_text())["run"]
    head = subprocess.run(["git", "-C", str(REPO), "rev-parse", "HEAD"], capture_output=True,
                          text=True).stdout.strip()
    assert run["git"]["commit"] == (head or None)
    files = sorted((REPO / "scenarios").glob("*.toml"))
    assert run["scenarios"] == {f.name: hashlib.sha256(f.read_bytes()).hexdigest() for f in files}
    assert run["date_utc"].endswith("+00:00")


def test_workers_side_by_side_give_the_results_of_one(tmp_path: Path):
    obs = collect_obligations("/nonexistent", CHEAP + ["Prop8.printed"])
    exp = [o.id for o in obs]
    one = run_obligations(obs, tmp_path / "one", exp, workers=1)
    two = run_obligations(obs, tmp_path / "two", exp, workers=2)
    assert one.ok and two.ok
    assert [p.id for p in two.proofs] == exp                  # in the given order, not finishing order
    docs = [json.loads((tmp_path / d / "results.json").read_text()) for d in ("one", "two")]
    assert _strip_times(docs[0]) == _strip_times(docs[1])
    for p in one.proofs:                                      # the saved queries too
        saved = [sorted(f.read_text() for f in (tmp_path / d).glob(f"{p.id}.*"))
                 for d in ("one", "two")]
        assert saved[0] and saved[0] == saved[1]


def test_an_obligation_whose_worker_dies_is_failed_not_lost(tmp_path: Path):
    import os
    obs = collect_obligations("/nonexistent", ["Def1.segment"])

    def die():
        os._exit(3)
    dying = dataclasses.replace(obs[0], id="Def1.dies", build=die)
    run = run_obligations([dying, *obs], tmp_path, ["Def1.dies", "Def1.segment"], workers=2)
    got = {p.id: p for p in run.proofs}
    assert list(got) == ["Def1.dies", "Def1.segment"] and not run.ok
    assert got["Def1.dies"].verdict is Verdict.FAILED
    assert "worker process ended" in got["Def1.dies"].reason


def test_workers_below_one_is_an_input_error(tmp_path: Path, capsys):
    from cfmpa.cli import main
    rc = main(["prove", "--out", str(tmp_path), "--only", "Def1.segment", "--workers", "0"])
    assert rc == 2 and "--workers" in capsys.readouterr().err
    assert not (tmp_path / "results.json").exists()


# --- definitional obligations, counted apart ------------------------------------------------------

def test_definitional_ids_are_registered_obligations_with_reasons():
    from cfmpa.proofs import FIXED_IDS
    from cfmpa.proofs._runner import DEFINITIONAL, kind_of

    assert set(DEFINITIONAL) <= set(FIXED_IDS)
    assert all(why.strip() for why in DEFINITIONAL.values())
    assert kind_of("Thm1.termination") == "definitional"
    assert kind_of("Safety.modified.composition") == "theorem"


def test_the_summary_and_results_count_definitional_apart(tmp_path):
    import json

    from cfmpa.proofs import collect_obligations, render_report, run_obligations

    obs = collect_obligations("/nonexistent", ["Def1.segment", "Def2.is_convex"])
    run = run_obligations(obs, tmp_path, [o.id for o in obs])
    doc = json.loads((tmp_path / "results.json").read_text())
    assert doc["kinds"] == {"theorem": 1, "definitional": 1}
    kinds = {o["id"]: o["kind"] for o in doc["obligations"]}
    assert kinds == {"Def1.segment": "definitional", "Def2.is_convex": "theorem"}
    text = render_report(run)
    assert "(1 theorems, 1 definitional)" in text
    assert "Definitional (counted apart from the theorems): Def1.segment" in text


# --- a line per group as it ends (docs/model.md §6.1) --------------------------------------------

def _data_check(ident: str, group: str, run=None):
    from cfmpa.proofs import CheckOutcome, CheckQuery, Method, Obligation

    def check():
        return run() if run is not None else CheckOutcome(True, "holds")
    return Obligation(ident, group, "docs/model.md §6.1", f"{ident} holds", Method.DATA,
                      Verdict.PROVED, lambda: CheckQuery(check, f"check {ident}\n"))


def _groups_told(obligations, tmp_path: Path, workers: int, seen: list[str]) -> str:
    """Obligations A.1, A.2 (group A) then B.1 (group B), whose check records what the progress
    stream held when it ran; the stream's text afterwards."""
    from cfmpa.proofs import CheckOutcome

    stream = io.StringIO()

    def b_check():
        seen.append(stream.getvalue())
        return CheckOutcome(True, "holds")
    obs = [_data_check("A.1", "Group A"), _data_check("A.2", "Group A"),
           _data_check("B.1", "Group B", b_check), *obligations]
    run = run_obligations(obs, tmp_path, [o.id for o in obs], workers=workers, progress=stream)
    assert [(p.id, p.verdict) for p in run.proofs] == [(o.id, Verdict.PROVED) for o in obs]
    return stream.getvalue()


def test_a_group_is_told_as_it_ends_not_at_the_end(tmp_path: Path, monkeypatch):
    import cfmpa.proofs._runner as runner

    seen: list[str] = []
    text = _groups_told([], tmp_path / "one", 1, seen)
    lines = text.splitlines()
    assert [ln.split(":")[1].strip() for ln in lines] == ["Group A", "Group B"]
    assert lines[0].startswith("prove: Group A: 2 done, ") and " s of work, at " in lines[0]
    assert lines[1].startswith("prove: Group B: 1 done, ")
    # Group A was told before B's check ran: during the run, not with the summary.
    assert seen == [lines[0] + "\n"]

    # Seeded fault: every obligation settled only once all are discharged (the lines at the end).
    def at_the_end(obligations, skip, told, recheck=False, strategies=None):
        from cfmpa.proofs._cvc5 import Cvc5Pool
        from cfmpa.proofs._obligation import discharge_pending
        with Cvc5Pool() as pool:
            pending = [discharge_pending(o, pool, skip, strategies=strategies)
                       for o in obligations]
        proofs = tuple(p.settle() for p in pending)
        for o, p in zip(obligations, proofs):
            told.done(o, p)
        return proofs
    monkeypatch.setattr(runner, "_discharge_in_turn", at_the_end)
    late: list[str] = []
    assert len(_groups_told([], tmp_path / "late", 1, late).splitlines()) == 2
    assert late == [""] != seen                   # B's check saw nothing: the check above fails


def test_side_by_side_each_group_is_told_once_and_the_results_do_not_change(tmp_path: Path):
    from cfmpa.proofs import collect_controls

    obs = collect_obligations("/nonexistent", ["Def1", "Margin.naive_hull"])
    exp = [o.id for o in obs]
    stream = io.StringIO()
    told = run_obligations(obs, tmp_path / "told", exp, workers=2, progress=stream,
                           controls=collect_controls(["Control.witness.forged"]))
    quiet = run_obligations(obs, tmp_path / "quiet", exp, workers=2,
                            controls=collect_controls(["Control.witness.forged"]))
    assert told.ok and quiet.ok
    lines = sorted(stream.getvalue().splitlines())
    assert len(lines) == 3 and lines == sorted(set(lines))
    assert lines[0].startswith("prove: Definitions 1-3, Lemmas 1-2: 2 done, ")
    assert lines[1].startswith("prove: Swept regions (docs/model.md §4): 1 done, ")
    assert lines[2].startswith("prove: negative controls: 1 done, ")
    docs = [json.loads((tmp_path / d / "results.json").read_text()) for d in ("told", "quiet")]
    strip = [{k: v for k, v in c.items() if k != "seconds"} for d in docs for c in d.pop("controls")]
    assert strip[0] == strip[1] and strip[0]["outcome"] == "rejected"
    assert _strip_times(docs[0]) == _strip_times(docs[1])


def test_prove_tells_the_groups_on_stderr_and_keeps_stdout_as_it_was(tmp_path: Path, capsys):
    from cfmpa.cli import main

    rc = main(["prove", "--out", str(tmp_path), "--only", "Def1.segment", "--workers", "1"])
    out, err = capsys.readouterr()
    assert rc == 0
    assert err.startswith("prove: Definitions 1-3, Lemmas 1-2: 1 done, ")
    assert "prove: " not in out and out.startswith("Summary of proof obligations")
