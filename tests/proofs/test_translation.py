"""Translation validation (Scenario.<stem>.translation_<variant>): the D_R and the answer that
cfmpa plan would use, judged at every cell by the spec. Each planted fault in the kernels the
check runs makes the obligation FAIL, naming the condition and the values."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import cfmpa.impl as impl
from cfmpa.proofs import Method, Verdict, discharge, scenario_obligations
from cfmpa.proofs._obl_scenario import EVERY_CELL, TRANSLATION_CHECKS
from cfmpa.spec import SearchStatus, Variant

ROOT = Path(__file__).resolve().parents[2]
SMALL = ROOT / "scenarios" / "narrow-gap.toml"     # the smallest bundled grid (44 x 141 x 126)


def _translation(path: Path, variant: str):
    ident = f"Scenario.{path.stem}.translation_{variant}"
    return next(o for o in scenario_obligations([path]) if o.id == ident)


def _planted(monkeypatch: pytest.MonkeyPatch, *, build=None, search=None) -> None:
    """cfmpa.impl.kernels("fast") gives the planted build or search in place of the real one."""
    real = impl.kernels

    def kernels(name: str = "fast", **kw):
        b, s = real(name, **kw)
        return (build(b) if build else b), (search(s) if search else s)
    monkeypatch.setattr(impl, "kernels", kernels)


def test_one_every_cell_check_per_variant_labelled_as_such():
    obs = [o for o in scenario_obligations([SMALL]) if o.id.split(".")[-1] in TRANSLATION_CHECKS]
    assert [o.id.split(".")[-1] for o in obs] == [f"translation_{v.value}" for v in Variant]
    assert all(o.method is Method.DATA and o.label == EVERY_CELL for o in obs)


@pytest.mark.parametrize("variant", [v.value for v in Variant])
def test_the_kernels_pass_on_a_bundled_workcell(variant: str):
    pr = discharge(_translation(SMALL, variant))
    assert pr.verdict is Verdict.PROVED, pr.reason
    assert "cells checked against the spec's regions" in pr.reason
    assert "optimal by its witness" in pr.reason


def test_a_rest_layer_left_free_fails(monkeypatch: pytest.MonkeyPatch):
    def rest_free(build):
        def b(*a, **k):
            dr = build(*a, **k)
            dr[-1] = 0
            return dr
        return b
    _planted(monkeypatch, build=rest_free)
    pr = discharge(_translation(SMALL, "original"))
    assert pr.verdict is Verdict.FAILED
    assert "post.cells" in pr.counterexample and "layer was 43" in pr.counterexample


def test_a_missing_layer_fails_on_the_shape(monkeypatch: pytest.MonkeyPatch):
    _planted(monkeypatch, build=lambda build: lambda *a, **k: build(*a, **k)[:-1])
    pr = discharge(_translation(SMALL, "modified"))
    assert pr.verdict is Verdict.FAILED and "post.shape" in pr.counterexample


def test_one_blocked_cell_turned_free_fails(monkeypatch: pytest.MonkeyPatch):
    def flip(build):
        def b(*a, **k):
            dr = build(*a, **k)
            k0, i, j = (int(x[0]) for x in np.nonzero(dr))
            dr[k0, i, j] = 0
            return dr
        return b
    _planted(monkeypatch, build=flip)
    pr = discharge(_translation(SMALL, "tight"))
    assert pr.verdict is Verdict.FAILED and "a cell is free in D_R" in pr.counterexample


def test_a_search_that_ignores_the_rest_layer_fails(monkeypatch: pytest.MonkeyPatch):
    # The search is given the D_R with its rest layer free: its path is judged on the real one.
    def blind(search):
        def s(dr, start, goal, **k):
            seen = dr.copy()
            seen[-1] = 0
            return search(seen, start, goal, **k)
        return s
    _planted(monkeypatch, search=blind)
    # On a workcell where the goal is blocked in the rest layer, a blind search reports a path.
    pr = discharge(_translation(ROOT / "scenarios" / "early-arrival.toml", "original"))
    assert pr.verdict is Verdict.FAILED, pr.reason
    assert "post." in pr.counterexample


def test_a_forged_optimum_fails_the_witness(monkeypatch: pytest.MonkeyPatch):
    # A found path reported with a lower J1 than it has: costs and witness disagree.
    def forged(search):
        def s(dr, start, goal, **k):
            r = search(dr, start, goal, **k)
            assert r.status is SearchStatus.FOUND
            return dataclasses.replace(r, J1=r.J1 - 1)
        return s
    _planted(monkeypatch, search=forged)
    pr = discharge(_translation(SMALL, "modified"))
    assert pr.verdict is Verdict.FAILED and "post.costs" in pr.counterexample


def test_a_forged_witness_fails_though_path_and_costs_are_right(monkeypatch: pytest.MonkeyPatch):
    # The search's true answer, but labels that claim every state costs nothing: only the
    # witness check can see it (the path is valid and its costs are its own).
    from cfmpa.spec import Witness

    def zero_labels(search):
        def s(dr, start, goal, **k):
            r = search(dr, start, goal, **k)
            assert r.status is SearchStatus.FOUND and r.witness.kind == "labels"
            w = Witness.of_labels(np.zeros_like(r.witness.j1), np.zeros_like(r.witness.j2))
            return dataclasses.replace(r, witness=w)
        return s
    _planted(monkeypatch, search=zero_labels)
    pr = discharge(_translation(SMALL, "modified"))
    assert pr.verdict is Verdict.FAILED, pr.reason
    assert pr.counterexample.startswith("witness."), pr.counterexample
