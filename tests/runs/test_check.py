"""`run_check`: another planner's dr.npy and plan.json against the spec. Exit 0 when all holds,
1 with a listing of what failed, 2 with ``file: error: ...`` when an input cannot be read."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import factory
from cfmpa.errors import InputError, handled
from cfmpa.runs._check import check_outputs, read_plan, run_check
from cfmpa.runs._plan import plan, write_plan
from cfmpa.runs._selftest import FAULTS, WORKCELLS
from cfmpa.spec import load_scenario, make_grid
from cfmpa.spec._paths import J1, J2


def checked(*args, **kw) -> int:
    """run_check's exit code as the CLI gives it: bad input (InputError) is exit 2 there."""
    return handled(lambda: run_check(*args, **kw))


@pytest.fixture(scope="module")
def outputs(tmp_path_factory):
    """A scenario file and the reference planner's outputs for it (variant modified)."""
    d = tmp_path_factory.mktemp("check")
    (d / "small.toml").write_text(factory.toml(WORKCELLS["small"]))
    s = load_scenario(d / "small.toml")
    write_plan(plan(s, "modified", contracts="off"), d / "ref")
    return d


def _plan_doc(outputs: Path) -> dict:
    return json.loads((outputs / "ref" / "plan.json").read_text())


def _run(outputs: Path, tmp_path: Path, capsys, *, dr=None, doc=None, text=None):
    dr_path, plan_path = outputs / "ref" / "dr.npy", outputs / "ref" / "plan.json"
    if dr is not None:
        dr_path = tmp_path / "dr.npy"
        np.save(dr_path, dr)
    if doc is not None or text is not None:
        plan_path = tmp_path / "plan.json"
        plan_path.write_text(text if text is not None else json.dumps(doc))
    code = checked(outputs / "small.toml", dr_path, plan_path)
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def test_the_reference_outputs_pass_every_check(outputs, tmp_path, capsys):
    code, out, err = _run(outputs, tmp_path, capsys)
    assert code == 0 and err == ""
    for what in ("post.shape", "post.cells: all 5103 cells", "post.is_path", "post.costs",
                 "post.optimal", "continuous-time certificate: clear",
                 "scenario_sha256", "grid is the scenario's", "angles"):
        assert any(line.startswith("ok") and what in line for line in out.splitlines()), what
    assert "FAIL" not in out and out.rstrip().endswith("result: all checks hold")


def test_a_wrong_cell_fails_theorem_3_with_its_values(outputs, tmp_path, capsys):
    dr = np.load(outputs / "ref" / "dr.npy")
    k, i, j = (int(x) for x in np.argwhere(dr == 1)[0])
    dr[k, i, j] = 0
    code, out, _ = _run(outputs, tmp_path, capsys, dr=dr)
    assert code == 1
    lines = out.splitlines()
    at = lines.index(next(x for x in lines if x.startswith("FAIL  Theorem 3 post.cells")))
    assert f"layer was {k}" in lines[at + 1] and f"cell was {[i, j]}" in lines[at + 2]
    assert any(x.startswith("FAIL  Theorem 4 pre.dr.spec") for x in lines)
    assert any(x.startswith("FAIL  plan.json dr_sha256") for x in lines)   # not plan's D_R
    assert lines[-1].startswith("result: 3 of")


def test_the_wrong_dtype_fails_the_shape_check_and_skips_the_path(outputs, tmp_path, capsys):
    dr = np.load(outputs / "ref" / "dr.npy").astype(np.int64)
    code, out, _ = _run(outputs, tmp_path, capsys, dr=dr)
    assert code == 1
    assert "FAIL  Theorem 3 post.shape: D_R has the wrong shape or element type" in out
    assert "dtype was 'int64'" in out
    assert "skip  Theorem 3 post.cells" in out and "skip  the path" in out
    assert "ok    Theorem 4 post.costs: J1 and J2 recomputed" in out


def test_costs_are_checked_even_when_dr_has_the_wrong_shape(outputs, tmp_path, capsys):
    dr = np.load(outputs / "ref" / "dr.npy")[:-1]           # the rest layer missing
    doc = _plan_doc(outputs)
    doc["J2"] += 3
    code, out, _ = _run(outputs, tmp_path, capsys, dr=dr, doc=doc)
    assert code == 1
    assert _fails(out) == ["FAIL  plan.json dr_sha256 is the dr file's (the two files are "
                           "from one run)", "FAIL  Theorem 3 post.shape",
                           "FAIL  Theorem 4 post.costs"]
    assert f"reported J1, J2 was {[doc['J1'], doc['J2']]}" in out
    assert f"recomputed J1, J2 was {[doc['J1'], doc['J2'] - 3]}" in out


def test_the_dr_of_another_variant_fails_the_stated_variant(outputs, tmp_path, capsys):
    s = load_scenario(outputs / "small.toml")
    from cfmpa.impl import build_dr

    code, out, _ = _run(outputs, tmp_path, capsys, dr=build_dr(s, "original", make_grid(s)))
    assert code == 1 and "FAIL  Theorem 3 post.cells: a cell is blocked in D_R" in out


def test_misreported_costs_and_a_jump_fail_their_checks(outputs, tmp_path, capsys):
    doc = _plan_doc(outputs)
    doc["J1"] += 1
    code, out, _ = _run(outputs, tmp_path, capsys, doc=doc)
    assert code == 1 and "FAIL  Theorem 4 post.costs" in out and "reported J1, J2 was" in out
    # the path itself is the optimum: optimality judges the path, not the misreported number
    assert _fails(out) == ["FAIL  Theorem 4 post.costs"]
    assert "ok    Theorem 4 post.optimal" in out
    doc = _plan_doc(outputs)
    del doc["path"][5], doc["angles"][5]
    doc["J1"], doc["J2"] = J1(doc["path"]), J2(doc["path"])
    code, out, _ = _run(outputs, tmp_path, capsys, doc=doc)
    assert code == 1 and "FAIL  Theorem 4 post.is_path: step 4->5" in out
    assert "FAIL  Theorem 4 post.costs" not in out


def _worse_path(outputs):
    """A valid path that is not optimal: the self-check's seeded fault, run on the good D_R."""
    s = load_scenario(outputs / "small.toml")
    fault = next(f for f in FAULTS if f.name == "non-optimal path")
    dr = np.load(outputs / "ref" / "dr.npy")
    return fault.make(s, fault.variant, make_grid(s)).search(dr, s.right.start_cell,
                                                             s.right.goal_cell)


def test_a_valid_but_worse_path_fails_optimality_only(outputs, tmp_path, capsys):
    worse = _worse_path(outputs)
    doc = _plan_doc(outputs)
    doc.update(path=[list(c) for c in worse.path], J1=worse.J1, J2=worse.J2)
    doc.pop("angles")
    code, out, _ = _run(outputs, tmp_path, capsys, doc=doc)
    assert code == 1
    assert [x.split(":")[0] for x in out.splitlines() if x.startswith("FAIL")] == [
        "FAIL  Theorem 4 post.optimal"]


def test_a_worse_path_reported_with_the_optimal_costs_fails_costs_and_optimality(
        outputs, tmp_path, capsys):
    # The numbers claimed are the optimum's: only recomputing the path's own costs shows that
    # the path is not the least.
    worse = _worse_path(outputs)
    doc = _plan_doc(outputs)
    best = [doc["J1"], doc["J2"]]
    doc.update(path=[list(c) for c in worse.path])
    doc.pop("angles")
    code, out, _ = _run(outputs, tmp_path, capsys, doc=doc)
    assert code == 1
    assert _fails(out) == ["FAIL  Theorem 4 post.costs", "FAIL  Theorem 4 post.optimal"]
    assert "the path's (J1, J2) is not the least" in out
    assert f"path's J1, J2 (recomputed) was {[worse.J1, worse.J2]}" in out
    assert f"least goal label + stop was {best}" in out            # the witness's labels


def _fails(out: str) -> list[str]:
    return [x.split(":")[0] for x in out.splitlines() if x.startswith("FAIL")]


def test_claiming_no_path_when_one_exists_fails(outputs, tmp_path, capsys):
    doc = _plan_doc(outputs)
    doc.update(status="no_path", reason="unreachable", path=[], J1=None, J2=None)
    code, out, _ = _run(outputs, tmp_path, capsys, doc=doc)
    assert code == 1 and "no path is reported but a valid path exists" in out


def test_a_claimed_grid_or_hash_that_differs_fails(outputs, tmp_path, capsys):
    doc = _plan_doc(outputs)
    doc["grid"]["m"] += 1
    doc["scenario_sha256"] = "0" * 64
    code, out, _ = _run(outputs, tmp_path, capsys, doc=doc)
    assert code == 1
    assert "FAIL  plan.json grid is the scenario's" in out and "plan's m was 28" in out
    assert "FAIL  plan.json scenario_sha256" in out


def test_a_contact_fails_the_certificate(outputs, tmp_path, capsys):
    # The early-arrival fault's path waits at its goal while the principal sweeps through it.
    fault = next(f for f in FAULTS if "early" in f.name)
    (tmp_path / "early.toml").write_text(factory.toml(WORKCELLS[fault.workcell]))
    s = load_scenario(tmp_path / "early.toml")
    p = plan(s, fault.variant, contracts="off", stop=False,
             search=fault.make(s, fault.variant, make_grid(s)).search)
    write_plan(p, tmp_path / "out")
    code = checked(tmp_path / "early.toml", tmp_path / "out" / "dr.npy",
                     tmp_path / "out" / "plan.json")
    out = capsys.readouterr().out
    assert code == 1
    assert "FAIL  continuous-time certificate: the arms' link rectangles touch" in out
    assert "FAIL  Theorem 4 post.is_path" in out


@pytest.mark.parametrize("what, make, message", [
    ("missing dr", lambda d: ("dr", d / "none.npy"), "dr cannot be read"),
    ("dr not npy", lambda d: ("dr", d / "x.npy", "not an array"), "dr is not a .npy array"),
    ("missing plan", lambda d: ("plan", d / "none.json"), "plan cannot be read"),
    ("bad json", lambda d: ("plan", d / "p.json", '{\n  "variant": \n'),
     ":3: error: json is not valid"),
    ("not an object", lambda d: ("plan", d / "p.json", "[1, 2]"),
     "<document> must be a JSON object"),
])
def test_unreadable_input_exits_2_naming_the_file(outputs, tmp_path, capsys, what, make, message):
    spec = make(tmp_path)
    paths = {"dr": outputs / "ref" / "dr.npy", "plan": outputs / "ref" / "plan.json"}
    paths[spec[0]] = spec[1]
    if len(spec) == 3:
        spec[1].write_text(spec[2])
    code = checked(outputs / "small.toml", paths["dr"], paths["plan"])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and "Traceback" not in err
    assert err.startswith(f"{spec[1]}") and message in err


@pytest.mark.parametrize("change, field", [
    (lambda d: d.pop("status"), "status is required"),
    (lambda d: d.update(variant="sideways"), "variant must be one of"),
    (lambda d: d.update(status="maybe"), "status must be 'found' or 'no_path'"),
    (lambda d: d.update(path=[[0, 1.5]]), "path must be a list of [i, j] integer pairs"),
    (lambda d: d.update(J2="4"), "J2 must be an integer when status is 'found'"),
    (lambda d: d.update(angles=[[0.1]]), "angles must be a list of [t1, t2] number pairs"),
])
def test_wrong_keys_exit_2(outputs, tmp_path, capsys, change, field):
    doc = _plan_doc(outputs)
    change(doc)
    code, out, err = _run(outputs, tmp_path, capsys, doc=doc)
    assert code == 2 and f"error: {field}" in err


def test_a_bad_scenario_exits_2(outputs, tmp_path, capsys):
    code = checked(tmp_path / "none.toml", outputs / "ref" / "dr.npy",
                     outputs / "ref" / "plan.json")
    assert code == 2 and "cannot be read" in capsys.readouterr().err


def test_a_dr_file_from_another_run_fails_the_hash(outputs, tmp_path, capsys):
    # Same shape, one cell different: dr_sha256 in plan.json names the bytes written with it.
    code, out, _ = _run(outputs, tmp_path, capsys)
    assert "ok    plan.json dr_sha256 is the dr file's" in out
    dr = np.load(outputs / "ref" / "dr.npy")
    k, i, j = (int(x) for x in np.argwhere(dr == 1)[0])
    dr[k, i, j] = 0
    code, out, _ = _run(outputs, tmp_path, capsys, dr=dr)
    assert code == 1 and "FAIL  plan.json dr_sha256 is the dr file's" in out
    doc = _plan_doc(outputs)
    doc["dr_sha256"] = 7
    code, _, err = _run(outputs, tmp_path, capsys, doc=doc)
    assert code == 2 and "error: dr_sha256 must be a string" in err


def test_extra_keys_are_allowed_and_optional_claims_may_be_absent(outputs):
    s = load_scenario(outputs / "small.toml")
    doc = _plan_doc(outputs)
    for key in ("grid", "angles", "scenario_sha256", "clearance", "contracts", "dr_sha256",
                "kernel"):
        doc.pop(key)
    doc["my_planner"] = {"version": 3}
    p = outputs / "minimal.json"
    p.write_text(json.dumps(doc))
    report = check_outputs(s, np.load(outputs / "ref" / "dr.npy"), read_plan(p))
    assert report.ok and not any("plan.json" in line.what for line in report.lines)


# --- witnesses (docs/model.md §11) ----------------------------------------------------------


@pytest.fixture(scope="module")
def witnessed(outputs):
    """`cfmpa plan --witness`: the outputs with the search's witness file."""
    from cfmpa.cli import main

    out = outputs / "witnessed"
    assert main(["plan", str(outputs / "small.toml"), "--out", str(out), "--witness",
                 str(out / "witness.npz")]) == 0
    return out


def _run_witnessed(outputs, witnessed, capsys, witness=None):
    code = checked(outputs / "small.toml", witnessed / "dr.npy", witnessed / "plan.json",
                     witness if witness is not None else witnessed / "witness.npz")
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def test_plan_writes_the_witness_and_its_hash(witnessed):
    import hashlib

    doc = json.loads((witnessed / "plan.json").read_text())
    data = (witnessed / "witness.npz").read_bytes()
    assert doc["witness_sha256"] == hashlib.sha256(data).hexdigest()
    assert not list(witnessed.glob(".*tmp"))


def test_a_witness_file_is_verified_and_its_hash_checked(outputs, witnessed, capsys):
    code, out, _ = _run_witnessed(outputs, witnessed, capsys)
    assert code == 0, out
    assert "ok    plan.json witness_sha256 is the witness file's" in out
    assert "ok    Theorem 4 post.optimal: through the witness given" in out
    # without the file the fast search makes one
    code, out, _ = _run(outputs, None, capsys)
    assert code == 0 and "post.optimal: through a witness computed by the fast search" in out


def test_a_tampered_witness_is_rejected_with_the_first_failing_condition(
        outputs, witnessed, tmp_path, capsys):
    from cfmpa.spec import MOVES, Witness, load_witness

    w = load_witness(witnessed / "witness.npz")
    doc = json.loads((witnessed / "plan.json").read_text())
    a, b = doc["path"][2], doc["path"][3]
    d = MOVES.index((b[0] - a[0], b[1] - a[1]))
    j1, j2 = w.j1.copy(), w.j2.copy()
    j1[3, d, b[0], b[1]] += 1                        # one label raised on the path's walk
    forged = tmp_path / "forged.npz"
    forged.write_bytes(Witness.of_labels(j1, j2).npz_bytes())
    code, out, _ = _run_witnessed(outputs, witnessed, capsys, forged)
    assert code == 1
    assert _fails(out) == ["FAIL  plan.json witness_sha256 is the witness file's",
                           "FAIL  Theorem 4 post.optimal"]
    line = next(x for x in out.splitlines() if x.startswith("FAIL  Theorem 4 post.optimal"))
    assert "the witness fails witness.edge" in line
    assert f"'step': 3, 'cell': {b}" in out and "its label was" in out


def test_a_bad_witness_file_exits_2(outputs, witnessed, tmp_path, capsys):
    (tmp_path / "w.npz").write_bytes(b"not a zip")
    code, out, err = _run_witnessed(outputs, witnessed, capsys, tmp_path / "w.npz")
    assert code == 2 and out == "" and "witness is not an .npz witness file" in err


def test_check_rejects_every_fault_the_selftest_seeds(tmp_path):
    # Each fault's outputs (and, for the forged witness, its witness file) fail `cfmpa check`.
    from cfmpa.runs._selftest import workcell
    from cfmpa.spec import load_witness

    for fault in FAULTS:
        s = workcell(fault.workcell)
        m = fault.make(s, fault.variant, make_grid(s))
        kwargs = {k: v for k, v in (("grid", m.grid), ("build", m.build), ("search", m.search))
                  if v is not None}
        p = plan(s, fault.variant, contracts="off", stop=False, witness=True, **kwargs)
        out = tmp_path / fault.name.replace(" ", "-")
        write_plan(p, out, witness=out / "witness.npz")
        report = check_outputs(s, np.load(out / "dr.npy"), read_plan(out / "plan.json"),
                               witness=load_witness(out / "witness.npz"))
        assert not report.ok, fault.name
        if fault.name in ("non-optimal path", "forged witness"):
            assert [x.what.split(":")[0] for x in report.failed] == [
                "Theorem 4 post.optimal"], fault.name
            want = "witness.edge" if fault.name == "forged witness" else "witness.goal"
            assert want in report.failed[0].what, (fault.name, report.failed[0].what)


def test_a_plan_file_is_read_within_its_limit(tmp_path, monkeypatch):
    # /dev/zero (or a plan.json cut short of nothing) is refused at the limit, naming it;
    # before, the whole device was read into memory (MemoryError).
    from cfmpa.runs._check import read_plan

    with pytest.raises(InputError) as e:
        read_plan("/dev/zero")
    assert "CFMPA_MAX_PLAN_BYTES" in e.value.render()
    big = tmp_path / "plan.json"
    big.write_text('{"path": [' + "[0, 0], " * 1000 + "[0, 0]]}")
    monkeypatch.setenv("CFMPA_MAX_PLAN_BYTES", "1000")
    with pytest.raises(InputError) as e:
        read_plan(big)
    assert "limit of 1,000 bytes" in e.value.render()


def test_a_dr_of_another_plan_says_which_failures_follow_from_the_first(outputs, tmp_path,
                                                                           capsys):
    # The original variant's D_R checked with the modified plan: D_R fails post.cells, and the
    # three FAILs after it (pre.dr.spec, the path blocked in that D_R, optimality judged on it)
    # say they follow from it; the lengths are in mm (docs/contributing.md, "Standards").
    s = load_scenario(outputs / "small.toml")
    write_plan(plan(s, "original", contracts="off"), tmp_path / "orig")
    code = checked(outputs / "small.toml", tmp_path / "orig" / "dr.npy",
                   outputs / "ref" / "plan.json")
    out = capsys.readouterr().out
    assert code == 1
    fails = [x for x in out.splitlines() if x.startswith("FAIL")]
    follows = [x for x in fails if "(follows from the failed " in x]
    assert [x.split(":")[0] for x in follows] == [
        "FAIL  Theorem 4 pre.dr.spec", "FAIL  Theorem 4 post.is_path",
        "FAIL  Theorem 4 post.optimal"]
    assert follows[0].endswith("(follows from the failed Theorem 3 post.cells above)")
    assert follows[2].endswith("(follows from the failed Theorem 4 post.is_path above)")
    assert any(x.startswith("FAIL  Theorem 3 post.cells") and "follows" not in x for x in fails)
    assert out.rstrip().splitlines()[-1] == (
        f"result: {len(fails)} of 13 checks failed, 3 of them following from an earlier failure")
    cert = next(x for x in out.splitlines() if "continuous-time certificate: clear" in x)
    assert " mm at every instant" in cert and " m at" not in cert.replace(" mm at", "")
    # A value in metres is shown in mm, an angle in rad with its degrees.
    assert any(x.strip().startswith("distance was ") and x.endswith(" mm")
               for x in out.splitlines())
    assert any(x.strip().startswith("angles was [") and "deg)" in x for x in out.splitlines())


def test_a_jump_in_the_path_is_its_own_failure_not_one_that_follows():
    from cfmpa.runs._check import CheckLine, _consequences

    lines = [CheckLine("FAIL", "Theorem 3 post.cells: a cell is blocked"),
             CheckLine("FAIL", "Theorem 4 post.is_path: step 3: a jump", (("clause", "jump"),)),
             CheckLine("FAIL", "Theorem 4 post.costs: J1 is not the path's")]
    got = _consequences(lines)
    assert [x.follows for x in got] == [None, None, None]
