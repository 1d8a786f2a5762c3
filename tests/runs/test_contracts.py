"""The triples as values and the contract wrappers: each condition holds on the reference's
outputs and fails, with the values that show why, on outputs made wrong on purpose."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import factory
from cfmpa.errors import ContractViolation, InputError
from cfmpa.files import jsonable
from cfmpa.impl import build_dr, search_opt_path
from cfmpa.runs._contracts import (
    DEFAULT_SAMPLE,
    Mode,
    Settings,
    builtdr_path_cells,
    builtdr_post,
    checked_build_dr,
    checked_search,
    sample_cells,
)
from cfmpa.spec import Variant, Witness, make_grid
from cfmpa.spec._paths import J1, J2, SearchResult
from cfmpa.spec._triples import (
    THEOREM_1,
    THEOREM_2,
    THEOREM_3,
    THEOREM_3_TIGHT,
    THEOREM_4,
    THEOREM_4_TIGHT,
    TRIPLES,
    Command,
    builtdr_triple,
    dr_shape_failures,
    grid_failures,
    path_cells,
    search_failures,
    search_triple,
)

START, GOAL = (2, 8), (13, 5)   # a pair with a path of 15 cells in the coarse workcell


@pytest.fixture(scope="module")
def small():
    s = factory.scenario(right__start_cell=list(START), right__goal_cell=list(GOAL))
    g = make_grid(s)
    dr = build_dr(s, Variant.MODIFIED, g)
    return s, g, dr, search_opt_path(dr, START, GOAL)


# --- the triples ----------------------------------------------------------------------------

def test_each_variant_has_its_pair_of_triples():
    assert [builtdr_triple(v).name for v in Variant] == ["Theorem 1", "Theorem 3",
                                                         "Theorem 3 (tight)"]
    assert [search_triple(v).name for v in Variant] == ["Theorem 2", "Theorem 4",
                                                        "Theorem 4 (tight)"]
    assert {t.command for t in (THEOREM_1, THEOREM_3, THEOREM_3_TIGHT)} == {Command.BUILT_DR}
    assert {t.command for t in (THEOREM_2, THEOREM_4, THEOREM_4_TIGHT)} == {Command.SEARCH}
    assert len({t.name for t in TRIPLES}) == 6


@pytest.mark.parametrize("triple", TRIPLES, ids=lambda t: t.name)
def test_a_triple_prints_as_pre_command_post(triple):
    text = str(triple)
    lines = text.splitlines()
    assert lines[0].startswith(triple.label) and triple.reference in lines[0]
    assert lines[1].startswith("{ ")
    program = next(i for i, line in enumerate(lines) if triple.program in line)
    # {P} closes right before the command, {Q} opens right after it
    assert lines[program - 1].endswith(" }") and lines[program + 1].startswith("{ ")
    for c in triple.precondition + triple.postcondition:
        assert f"[{c.id}] {c.text}" in text
    ids = [c.id for c in triple.precondition + triple.postcondition]
    assert len(ids) == len(set(ids))


def test_a_violation_names_the_triple_the_condition_and_each_value():
    from cfmpa.spec._triples import Failure

    err = THEOREM_3.violation(Failure("post.cells", "a cell is free", (("layer", 3),
                                                                        ("cell", [4, 5])), 7))
    assert isinstance(err, ContractViolation)
    assert str(err).splitlines() == ["Theorem 3 [BuiltDR, modified]: post.cells: a cell is free",
                                     "layer was 3", "cell was [4, 5]", "instances failing was 7"]
    assert (err.condition_id, err.message) == ("post.cells", "a cell is free")
    from cfmpa.runs._contracts import violation_json

    doc = violation_json(err)
    assert (doc["condition"], doc["condition_id"], doc["message"]) == (
        "post.cells: a cell is free", "post.cells", "a cell is free")
    # made by hand, without the parts: they are read off the joined text
    bare = ContractViolation("T", "pre.x: y: z")
    assert (bare.condition_id, bare.message) == ("pre.x", "y: z")


# --- preconditions ------------------------------------------------------------------------------

def test_the_scenarios_grid_meets_the_precondition(small):
    s, g, _, _ = small
    assert grid_failures(s, g) == []


@pytest.mark.parametrize("change, condition", [
    (dict(N=5), "pre.grid.N"),                                  # 5 * 0.25 s < Tf = 1.4 s
    (dict(m=14, h=(6.283185307179586 / 13, 6.283185307179586 / 26)), "pre.grid.h"),
    (dict(m=30), "pre.grid.h"),                                 # points run past the limit
    (dict(dt=0.3), "pre.grid.scenario"),                       # 6 * 0.3 s still covers Tf
])
def test_a_malformed_grid_fails_its_condition(small, change, condition):
    s, g, _, _ = small
    fails = grid_failures(s, replace(g, **change))
    assert [f.condition for f in fails] == [condition]


def test_a_failed_precondition_stops_before_the_build(small):
    s, g, _, _ = small
    calls = []

    def build(*args):
        calls.append(args)
        return build_dr(*args)

    with pytest.raises(ContractViolation) as info:
        checked_build_dr(s, Variant.MODIFIED, replace(g, N=5), Settings(Mode.SAMPLED),
                         build=build, stop=False)
    assert calls == []
    assert "pre.grid.N" in str(info.value) and "Tf_s was 1.4" in str(info.value)


def test_the_search_precondition_checks_shape_dtype_and_cells(small):
    s, g, dr, _ = small
    for bad in (dr.astype(np.int64), dr[:-1], np.where(dr == 1, 2, 0).astype(np.uint8)):
        assert [f.condition for f in dr_shape_failures(g, bad, "pre.dr.shape")] == ["pre.dr.shape"]
    s_out = replace(s, right=replace(s.right, goal_cell=(g.m, 0)))
    with pytest.raises(ContractViolation, match="pre.cells: the goal cell lies outside"):
        checked_search(s_out, Variant.MODIFIED, g, dr, Settings(Mode.SAMPLED))


# --- BuiltDR's postcondition ------------------------------------------------------------------

def test_the_reference_meets_theorem_3_at_every_cell(small):
    s, g, dr, _ = small
    run = builtdr_post(s, Variant.MODIFIED, g, dr, Settings(Mode.FULL))
    assert run.ok and run.checked == 1 + dr.size


def test_a_flipped_cell_is_reported_with_layer_cell_angles_and_distance(small):
    s, g, dr, _ = small
    k, i, j = (int(x) for x in np.argwhere(dr == 1)[len(np.argwhere(dr == 1)) // 2])

    def build(*args):
        out = build_dr(*args)
        out[k, i, j] = 0
        return out

    with pytest.raises(ContractViolation) as info:
        checked_build_dr(s, Variant.MODIFIED, g, Settings(Mode.FULL), build=build)
    lines = str(info.value).splitlines()
    assert lines[0] == ("Theorem 3 [BuiltDR, modified]: post.cells: a cell is free in D_R "
                        "against the spec's regions")
    assert f"layer was {k}" in lines and f"cell was {[i, j]}" in lines
    assert any(x.startswith("angles_rad was [") for x in lines)
    distance = next(x for x in lines if x.startswith("distance_m was "))
    assert float(distance.split()[-1]) <= 1e-9          # the regions touch: it must be blocked
    assert "D_R value was 0" in lines and "expected was 1" in lines


def test_sampled_cells_are_seeded_distinct_and_recorded(small):
    _, g, _, _ = small
    a = sample_cells(g.shape, 100, seed=1)
    assert a.shape == (100, 3) and len(np.unique(a, axis=0)) == 100
    assert np.all((a >= 0) & (a < np.array(g.shape)))
    assert np.array_equal(a, sample_cells(g.shape, 100, seed=1))
    assert not np.array_equal(a, sample_cells(g.shape, 100, seed=2))
    assert len(sample_cells(g.shape, 10 ** 9, seed=0)) == int(np.prod(g.shape))


def test_sampled_mode_catches_a_wrong_cell_exactly_when_it_draws_it(small):
    s, g, dr, _ = small
    cells = sample_cells(g.shape, 50, seed=3)
    bad = dr.copy()
    drawn = tuple(cells[7])
    bad[drawn] ^= 1
    run = builtdr_post(s, Variant.MODIFIED, g, bad, Settings(Mode.SAMPLED, seed=3, sample=50))
    assert not run.ok and dict(run.failures[0].values)["cell"] == list(drawn[1:])
    other = dr.copy()
    free = {tuple(c) for c in cells}
    missed = next(tuple(c) for c in np.argwhere(dr >= 0) if tuple(c) not in free)
    other[missed] ^= 1
    assert builtdr_post(s, Variant.MODIFIED, g, other,
                        Settings(Mode.SAMPLED, seed=3, sample=50)).ok


def test_path_cells_cover_every_step_then_the_rest_layer():
    path = [(0, 0), (1, 1)]
    cells = {tuple(c) for c in path_cells(path, N=4)}
    assert cells == {(0, 0, 0), (1, 1, 1), (2, 1, 1), (3, 1, 1), (4, 1, 1)}
    long = [(0, j) for j in range(7)]
    assert {tuple(c) for c in path_cells(long, N=3)} == (
        {(0, 0, 0), (1, 0, 1), (2, 0, 2)} | {(3, 0, j) for j in range(3, 7)})


def test_the_path_cells_check_finds_a_wrong_cell_under_the_path(small):
    s, g, dr, r = small
    assert builtdr_path_cells(s, Variant.MODIFIED, g, dr, r.path).ok
    bad = dr.copy()
    bad[4, r.path[4][0], r.path[4][1]] = 1          # free by the spec, blocked here
    run = builtdr_path_cells(s, Variant.MODIFIED, g, bad, r.path)
    assert [f.condition for f in run.failures] == ["post.cells"]
    assert dict(run.failures[0].values)["layer"] == 4


# --- searchoptpath's postcondition ---------------------------------------------------------------

def test_the_reference_search_meets_theorem_4_in_full(small):
    s, g, dr, r = small
    result, runs = checked_search(s, Variant.MODIFIED, g, dr, Settings(Mode.FULL))
    assert result == r and all(run.ok for run in runs)
    checks = {c.condition: c for run in runs for c in run.checks}
    assert checks["post.optimal"].ok is True and checks["post.is_path"].count == len(r.path) + 1


def test_full_mode_verifies_the_searchs_own_witness_and_rejects_a_forged_one(small):
    s, g, dr, r = small

    def certifying(*args):
        return search_opt_path(*args, with_witness=True)

    _, runs = checked_search(s, Variant.MODIFIED, g, dr, Settings(Mode.FULL), search=certifying)
    checks = {c.condition: c for run in runs for c in run.checks}
    assert checks["post.optimal"].ok and "the search's own witness" in checks["post.optimal"].scope

    def forging(*args):
        good = certifying(*args)
        j1, j2 = good.witness.j1.copy(), good.witness.j2.copy()
        j1[0, 4, START[0], START[1]] = 1                 # the start state's label is not 0
        return replace(good, witness=Witness.of_labels(j1, j2))

    with pytest.raises(ContractViolation, match="witness.start"):
        checked_search(s, Variant.MODIFIED, g, dr, Settings(Mode.FULL), search=forging)


def test_sampled_mode_says_optimality_was_not_checked(small):
    s, g, dr, _ = small
    _, runs = checked_search(s, Variant.MODIFIED, g, dr, Settings(Mode.SAMPLED))
    checks = {c.condition: c for run in runs for c in run.checks}
    assert checks["post.optimal"].ok is None and checks["post.optimal"].count == 0
    assert "not checked" in checks["post.optimal"].scope


def test_wrong_costs_a_jump_and_a_worse_path_each_fail_their_condition(small):
    _, _, dr, r = small
    p = list(r.path)
    assert [f.condition for f in search_failures(dr, START, GOAL, replace(r, J1=r.J1 + 1))] == [
        "post.costs"]
    jump = p[:2] + p[3:]
    fails = search_failures(dr, START, GOAL, SearchResult.found(jump, J1(jump), J2(jump)), r)
    assert [f.condition for f in fails] == ["post.is_path", "post.optimal"]
    assert dict(fails[0].values)["clause"] == "not_adjacent"
    # an understated cost on the optimal path is a costs failure only: optimality judges the
    # path's recomputed (J1, J2), which is the optimum
    cheap = search_failures(dr, START, GOAL, replace(r, J1=r.J1 - 1), r)
    assert [f.condition for f in cheap] == ["post.costs"]
    worse = p[:3] + [p[2]] + p[3:]                   # a wait mid-way: valid here, J2 + 2
    res = SearchResult.found(worse, J1(worse), J2(worse))
    assert search_failures(dr, START, GOAL, res) == []
    assert [f.condition for f in search_failures(dr, START, GOAL, res, r)] == ["post.optimal"]
    # against a (wrong) optimum above it, the optimal path's own costs are "below the least"
    below = search_failures(dr, START, GOAL, r, res)
    assert [f.condition for f in below] == ["post.optimal"]
    assert "below the least" in below[0].message
    assert dict(below[0].values)["path's J1, J2 (recomputed)"] == [r.J1, r.J2]
    nothing = SearchResult.no_path("unreachable")
    assert "a valid path exists" in search_failures(dr, START, GOAL, nothing, r)[0].message


def test_stop_false_records_postcondition_failures_and_goes_on(small):
    s, g, dr, r = small

    def lying(*args):
        return replace(search_opt_path(*args), J2=r.J2 + 3)

    with pytest.raises(ContractViolation, match="post.costs"):
        checked_search(s, Variant.MODIFIED, g, dr, Settings(Mode.SAMPLED), search=lying)
    result, runs = checked_search(s, Variant.MODIFIED, g, dr, Settings(Mode.SAMPLED),
                                  search=lying, stop=False)
    assert result.J2 == r.J2 + 3
    assert [f.condition for run in runs for f in run.failures] == ["post.costs"]


# --- settings and records ----------------------------------------------------------------------

@pytest.mark.parametrize("args, field", [
    (("sometimes",), "--contracts"), (("sampled", -1), "--seed"), (("sampled", 0, 0), "--sample"),
    (("sampled", 0, True), "--sample"),
])
def test_bad_settings_name_the_option(args, field):
    with pytest.raises(InputError) as info:
        Settings.of(*args)
    assert info.value.field == field


def test_default_settings_are_sampled_with_the_stated_sample():
    assert Settings.of() == Settings(Mode.SAMPLED, 0, DEFAULT_SAMPLE) and DEFAULT_SAMPLE == 4096


def test_values_become_json():
    assert jsonable({"a": (np.int64(3), np.float64(0.5)), "b": float("inf"), "c": None}) == {
        "a": [3, 0.5], "b": "inf", "c": None}
