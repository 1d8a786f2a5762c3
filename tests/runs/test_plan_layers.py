"""A plan whose witness is held in layers (spec.Layers over a spill file, as on large grids;
here the threshold is lowered to 0 on a small workcell): full contracts verify it, write_plan
streams it, and `cfmpa check --witness` verifies the file read in place."""

from __future__ import annotations

import hashlib
import json

import numpy as np
import pytest

import cfmpa.spec._layers as layers_module
import factory
from cfmpa.runs._check import check_outputs, read_plan
from cfmpa.runs._plan import plan, write_plan
from cfmpa.spec import Layers, load_witness


@pytest.fixture
def spill_everything(monkeypatch):
    monkeypatch.setattr(layers_module, "SPILL_BYTES", 0)


def test_a_layered_witness_is_checked_written_and_verified(spill_everything, tmp_path):
    s = factory.scenario(right__start_cell=[2, 8], right__goal_cell=[13, 5])
    p = plan(s, "modified", contracts="full", witness=True)
    assert isinstance(p.search.witness.j1, Layers) and not p.violations
    checks = [c for r in p.runs for c in r.checks if c.condition == "post.optimal"]
    assert [c.ok for c in checks] == [True]
    write_plan(p, tmp_path, witness=tmp_path / "w.npz")
    doc = json.loads((tmp_path / "plan.json").read_text())
    assert doc["witness_sha256"] == hashlib.sha256((tmp_path / "w.npz").read_bytes()).hexdigest()
    assert doc["dr_sha256"] == hashlib.sha256((tmp_path / "dr.npy").read_bytes()).hexdigest()
    w = load_witness(tmp_path / "w.npz")
    assert isinstance(w.j1, Layers)
    assert np.array_equal(np.asarray(w.j1), np.asarray(p.search.witness.j1))
    report = check_outputs(s, np.load(tmp_path / "dr.npy"), read_plan(tmp_path / "plan.json"),
                           witness=w)
    assert report.ok
    # The same file with one label raised (the start's): the check reads it and rejects it.
    j1 = np.asarray(w.j1).copy()
    j1[0, 4, 2, 8] += 1
    members = {"format": np.array("cfmpa-witness-1"), "kind": np.array("labels"),
               "j1": j1, "j2": np.asarray(w.j2)}
    with open(tmp_path / "bad.npz", "wb") as fh:
        layers_module.save_npz(fh, members)
    bad = check_outputs(s, np.load(tmp_path / "dr.npy"), read_plan(tmp_path / "plan.json"),
                        witness=load_witness(tmp_path / "bad.npz"))
    assert not bad.ok and "witness.start" in bad.failed[0].what
    p.search.witness.close()          # the spilled labels' temporary files, not left to the GC
    with pytest.raises(ValueError, match="closed file"):
        p.search.witness.j1.layer(1)
