"""`plan` under contracts: what plan.json's ``contracts`` records per mode, that it is
deterministic, and that violations stop the run or are recorded, as asked."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

import factory
from cfmpa.errors import CertificateViolation, ContractViolation
from cfmpa.files import dumps_json
from cfmpa.impl import build_dr, search_opt_path
from cfmpa.runs._plan import CERTIFICATE, EXACT, plan, plan_json, write_plan
from cfmpa.runs._selftest import FAULTS, workcell
from cfmpa.spec import make_grid

START, GOAL = [2, 8], [13, 5]


@pytest.fixture(scope="module")
def s():
    return factory.scenario(right__start_cell=START, right__goal_cell=GOAL)


def _checks(record):
    return {(t["name"], c["condition"], c["scope"]): c for t in record["triples"]
            for c in t["checks"]}


def test_off_records_the_mode_and_checks_nothing(s):
    p = plan(s, "modified", contracts="off")
    rec = plan_json(p)["contracts"]
    assert rec == {"mode": "off", "seed": None, "sample": None, "checked": 0, "violations": [],
                   "triples": [], "certificate_enforced": True}
    assert not any(k.startswith("contracts_") for k in p.timings_s)


def test_sampled_records_seed_sample_and_what_was_checked(s):
    p = plan(s, "modified", contracts="sampled", seed=5, sample=300)
    rec = plan_json(p)["contracts"]
    assert (rec["mode"], rec["seed"], rec["sample"], rec["violations"]) == ("sampled", 5, 300, [])
    assert [t["name"] for t in rec["triples"]] == ["Theorem 3", "Theorem 4"]
    checks = _checks(rec)
    sampled = [c for (name, cond, scope), c in checks.items()
               if cond == "post.cells" and "random" in scope]
    assert len(sampled) == 1 and sampled[0]["count"] == 300 and "seed 5" in sampled[0]["scope"]
    on_path = [c for (name, cond, scope), c in checks.items()
               if cond == "post.cells" and "path occupies" in scope]
    path, N = p.search.path, p.grid.N
    assert len(path) > N          # so every step has its own entry; R's is the last step's
    occupied = {(min(k, N), c) for k, c in enumerate(path)} | {(N, path[-1])}
    assert on_path[0]["count"] == len(occupied) == len(path)
    optimal = [c for (_, cond, _), c in checks.items() if cond == "post.optimal"]
    assert optimal[0]["ok"] is None and optimal[0]["coverage"] == "none"
    # a sample is recorded as one: pre.dr.spec does not claim more than the cells drawn
    spec = [c for (_, cond, _), c in checks.items() if cond == "pre.dr.spec"]
    assert spec[0]["coverage"] == "sample" and spec[0]["scope"].startswith("on a sample only")
    assert "300 random cells" in spec[0]["scope"] and "not checked" in spec[0]["scope"]
    assert sampled[0]["coverage"] == on_path[0]["coverage"] == "sample"
    assert rec["checked"] == sum(c["count"] for c in checks.values())
    assert rec["certificate_enforced"] is True and {"contracts_builtdr",
                                                     "contracts_search"} <= set(p.timings_s)


def test_full_checks_every_cell_and_optimality(s):
    p = plan(s, "modified", contracts="full")
    checks = _checks(plan_json(p)["contracts"])
    cells = [c for (_, cond, _), c in checks.items() if cond == "post.cells"]
    assert [c["count"] for c in cells] == [p.dr.size]
    assert all(c["ok"] is True and c["coverage"] == "all" for c in checks.values())
    assert any(cond == "post.optimal" and c["count"] == 1 for (_, cond, _), c in checks.items())
    # optimality through the fast search's own witness, verified by the spec's checker
    assert any(cond == "post.optimal" and "through the search's own witness" in scope
               for (_, cond, scope) in checks)
    assert p.search.witness is None                 # checked, then dropped: it is large
    kept = plan(s, "modified", contracts="full", witness=True)
    assert kept.search.witness is not None and kept.search.witness.kind == "labels"


def test_a_witness_is_made_on_request_and_hashed_only_when_written(s, tmp_path):
    import hashlib

    off = plan(s, "modified", contracts="off")
    assert off.search.witness is None and "witness_sha256" not in plan_json(off)
    with pytest.raises(ValueError, match="witness=True"):
        write_plan(off, tmp_path / "a", witness=tmp_path / "a" / "w.npz")
    p = plan(s, "modified", contracts="off", witness=True)
    assert p.search == off.search and p.search.path == off.search.path
    write_plan(p, tmp_path / "b", witness=tmp_path / "b" / "w.npz")
    doc = json.loads((tmp_path / "b" / "plan.json").read_text())
    assert doc["witness_sha256"] == hashlib.sha256(
        (tmp_path / "b" / "w.npz").read_bytes()).hexdigest()
    # a search that makes no witness gets the fast search's
    ref = plan(s, "modified", contracts="off", search=lambda *a: search_opt_path(*a),
               witness=True)
    assert ref.search.witness is not None


@pytest.mark.parametrize("variant, names", [
    ("original", ["Theorem 1", "Theorem 2"]),
    ("tight", ["Theorem 3 (tight)", "Theorem 4 (tight)"]),
])
def test_each_variant_records_its_own_triples(s, variant, names):
    rec = plan_json(plan(s, variant, contracts="sampled", sample=50))["contracts"]
    assert [t["name"] for t in rec["triples"]] == names
    assert all(t["statement"].startswith(t["name"]) for t in rec["triples"])


def test_the_record_is_byte_identical_across_runs(s, tmp_path):
    docs = []
    for out in ("a", "b"):
        write_plan(plan(s, "modified", contracts="sampled", sample=200, seed=1), tmp_path / out)
        doc = json.loads((tmp_path / out / "plan.json").read_text())
        doc.pop("timings_s")
        docs.append(dumps_json(doc))
    assert docs[0] == docs[1]


def test_a_postcondition_violation_stops_the_run_unless_recording(s):
    def lying(dr, start, goal):
        r = search_opt_path(dr, start, goal)
        return replace(r, J1=r.J1 - 1)

    with pytest.raises(ContractViolation, match="post.costs"):
        plan(s, "modified", contracts="sampled", search=lying)
    p = plan(s, "modified", contracts="sampled", search=lying, stop=False)
    rec = plan_json(p)["contracts"]
    assert [v["condition"].split(":")[0] for v in rec["violations"]] == ["post.costs"]
    v = rec["violations"][0]                        # the id and the message, also apart
    assert v["condition_id"] == "post.costs"
    assert v["message"] == "the reported costs are not the path's"
    assert v["condition"] == f"{v['condition_id']}: {v['message']}"
    assert rec["violations"][0]["triple"] == "Theorem 4 [searchoptpath over D'_R]"
    assert rec["violations"][0]["values"]["reported J1, J2"] == [p.search.J1, p.search.J2]
    dumps_json(plan_json(p))                        # the record is valid, deterministic JSON
    # mode off checks nothing, so the same lie passes silently: that is what off means
    assert plan_json(plan(s, "modified", contracts="off", search=lying))["contracts"][
        "violations"] == []


@pytest.mark.parametrize("mode", ["off", "sampled"])
def test_a_contact_is_a_violation_in_every_mode(mode):
    # The certificate is the safety result, not a contract: --contracts off does not waive it.
    fault = next(f for f in FAULTS if "early" in f.name)
    s = workcell(fault.workcell)
    m = fault.make(s, fault.variant, make_grid(s))
    p = plan(s, fault.variant, contracts=mode, search=m.search, stop=False)
    assert not p.certificate.clear and p.certificate.contact is not None
    assert CertificateViolation in [type(v) for v in p.violations]
    rec = plan_json(p)["contracts"]
    assert rec["violations"][-1]["triple"] == CERTIFICATE
    assert rec["violations"][-1]["condition_id"] == "certificate.contact"
    values = rec["violations"][-1]["values"]
    assert values["distance_m"] == 0.0 and values["path segment"] == "resting at the last cell"
    assert values["cells"] == [list(p.search.path[-1])] * 2
    assert len(values["left angles_rad"]) == len(values["right angles_rad"]) == 2
    if mode == "off":   # off checks no triple: only the exact re-decision and the certificate
        assert [v["triple"] for v in rec["violations"]] == [EXACT, CERTIFICATE]
    # stop=True: off raises the contact itself; sampled stops earlier, at post.is_path
    with pytest.raises(CertificateViolation if mode == "off" else ContractViolation,
                       match="touch" if mode == "off" else "post.is_path"):
        plan(s, fault.variant, contracts=mode, search=m.search)


def test_plan_json_names_the_kernel_and_hashes_the_dr_bytes_written(s, tmp_path):
    import hashlib

    from cfmpa.impl import build_dr_fast, search_opt_path_fast

    fast = plan(s, "modified")
    ref = plan(s, "modified", build=build_dr, search=search_opt_path)
    custom = plan(s, "modified", build=lambda *a: build_dr(*a))
    assert (fast.kernel, ref.kernel, custom.kernel) == ("fast", "reference", "custom")
    assert plan(s, "modified", build=lambda *a: build_dr_fast(*a), search=search_opt_path_fast,
                kernel="fast").kernel == "fast"
    # the load is timed apart (once per process, then 0.0); the reference loads nothing
    assert "kernel_load" in fast.timings_s and "kernel_load" not in ref.timings_s
    dr_path, plan_path = write_plan(fast, tmp_path)
    doc = json.loads(plan_path.read_text())
    assert doc["kernel"] == "fast"
    assert doc["dr_sha256"] == hashlib.sha256(dr_path.read_bytes()).hexdigest()
    assert plan_json(ref)["dr_sha256"] == doc["dr_sha256"]      # bit-identical D_R
    assert plan_json(ref)["kernel"] == "reference"


def test_another_builder_can_be_run_under_the_contracts(s):
    seen = []

    def mine(s2, v, g):
        seen.append(v)
        return np.ascontiguousarray(build_dr(s2, v, g))

    p = plan(s, "tight", contracts="full", build=mine)
    assert seen == ["tight"] and p.violations == []


@pytest.mark.slow
def test_the_default_scenario_meets_every_triple_in_full_mode():
    from pathlib import Path

    from cfmpa.impl import build_dr_fast
    from cfmpa.spec import load_scenario

    s = load_scenario(Path(__file__).resolve().parents[2] / "scenarios" / "default.toml")
    p = plan(s, "modified", contracts="full", build=build_dr_fast, stop=False)
    assert p.violations == [] and p.certificate.clear
    assert plan_json(p)["contracts"]["checked"] > p.dr.size
