"""spec.check_witness: good witnesses pass, and every corruption is rejected with the first
failing condition named (docs/model.md §11).

Witnesses come from the searches (their exact labels, or reachable sets). Corruptions, each one
that the soundness argument says cannot pass: a label lowered on the returned path's walk (its
successor on the walk was tight), a label raised anywhere (every labelled state but the start
has a tight predecessor), the labels of a search that never took the edges into one reachable
cell, a state removed from a reachable set, and a set that never took those edges either.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from cfmpa.errors import InputError
from cfmpa.impl import build_dr_fast, search_opt_path, search_opt_path_fast
from cfmpa.spec import (
    J1,
    J2,
    MOVES,
    SearchResult,
    SearchStatus,
    Variant,
    Witness,
    check_witness,
    load_scenario,
    load_witness,
    make_grid,
)
from dr_strategies import random_dr

SCENARIOS = sorted(Path(__file__).resolve().parents[2].joinpath("scenarios").glob("*.toml"))
WAIT = MOVES.index((0, 0))


def cases(free_ends=True):
    return random_dr(max_n=5, max_side=7, density=st.sampled_from([0.0, 0.15, 0.3, 0.45]),
                     free_ends=free_ends)


def certified(dr, start, goal):
    r = search_opt_path_fast(dr, start, goal, with_witness=True)
    assert check_witness(dr, start, goal, r, r.witness) == []
    return r


def walk(path, N):
    """The capped states (s, p, i, j) the padded path holds, step 0 .. max(len - 1, N)."""
    T = max(len(path) - 1, N)
    cells = [path[min(k, len(path) - 1)] for k in range(T + 1)]
    out = [(0, WAIT, *cells[0])]
    for k in range(1, T + 1):
        d = (cells[k][0] - cells[k - 1][0], cells[k][1] - cells[k - 1][1])
        out.append((min(k, N), MOVES.index(d), *cells[k]))
    return out


def labels(w: Witness):
    return w.j1.copy(), w.j2.copy()


def found_labels(dr, start, goal):
    """The fast search's answer on a case where it finds a path (others are discarded), with
    copies of its labels to corrupt."""
    r = search_opt_path_fast(dr, start, goal, with_witness=True)
    assume(r.status is SearchStatus.FOUND)
    return (r, *labels(r.witness))


def conditions(fails):
    return [f.condition for f in fails]


# --- good witnesses -------------------------------------------------------------------------


@settings(max_examples=200, deadline=None)
@given(case=cases(free_ends=None))
def test_the_searches_witnesses_pass(case):
    dr, start, goal = case
    for search in (search_opt_path, search_opt_path_fast):
        r = search(dr, start, goal, with_witness=True)
        assert check_witness(dr, start, goal, r, r.witness) == []
        assert r.witness.kind == ("labels" if r.status is SearchStatus.FOUND else "reachable")


@pytest.mark.parametrize("variant", list(Variant), ids=str)
@pytest.mark.parametrize("path", [p for p in SCENARIOS if p.stem != "default"],
                         ids=lambda p: p.stem)
def test_good_witnesses_pass_on_the_bundled_scenarios(path, variant):
    s = load_scenario(path)
    dr = build_dr_fast(s, variant, make_grid(s))
    goal = s.right.goal_cell
    r = certified(dr, s.right.start_cell, goal)
    with r.witness:                # in layers on these grids: its spill files closed here
        assert (r.status is SearchStatus.FOUND
                or not r.witness.reachable[-1, :, goal[0], goal[1]].any())


@pytest.mark.slow
@pytest.mark.parametrize("variant", list(Variant), ids=str)
def test_good_witnesses_pass_on_the_default_scenario(variant):
    s = load_scenario(next(p for p in SCENARIOS if p.stem == "default"))
    r = certified(build_dr_fast(s, variant, make_grid(s)), s.right.start_cell, s.right.goal_cell)
    r.witness.close()


def test_another_optimal_path_passes_with_the_same_labels():
    # Labels certify the optimum, not one path: every optimal list passes.
    dr = np.zeros((3, 4, 4), dtype=np.uint8)
    r = certified(dr, (0, 0), (2, 2))
    other = ((0, 0), (1, 0), (2, 1), (2, 2))
    assert other != r.path and (J1(other), J2(other)) == (r.J1, r.J2) == (4, 4)
    alt = SearchResult.found(other, 4, 4)
    assert check_witness(dr, (0, 0), (2, 2), alt, r.witness) == []


# --- corruptions of labels -----------------------------------------------------------------


@settings(max_examples=150, deadline=None)
@given(case=cases(), data=st.data())
def test_a_label_lowered_on_the_walk_is_rejected(case, data):
    dr, start, goal = case
    r, j1, j2 = found_labels(dr, start, goal)
    states = [x for x in walk(r.path, dr.shape[0] - 1)[1:] if j1[x] > 0 or j2[x] > 0]
    assume(states)
    x = data.draw(st.sampled_from(states))
    if j1[x] > 0 and (j2[x] == 0 or data.draw(st.booleans())):
        j1[x] -= 1
    else:
        j2[x] -= 1
    fails = check_witness(dr, start, goal, r, Witness.of_labels(j1, j2))
    assert conditions(fails) in (["witness.edge"], ["witness.goal"])


@settings(max_examples=150, deadline=None)
@given(case=cases(), data=st.data())
def test_a_label_raised_anywhere_is_rejected(case, data):
    dr, start, goal = case
    r, j1, j2 = found_labels(dr, start, goal)
    none = np.iinfo(j1.dtype).max
    states = [tuple(int(v) for v in x) for x in np.argwhere(j1 != none)]
    x = data.draw(st.sampled_from(states))
    how = data.draw(st.sampled_from(["J1", "J2", "no label"]))
    if how == "J1":
        j1[x] += 1
    elif how == "J2":
        j2[x] += 1
    else:
        j1[x] = j2[x] = none
    fails = check_witness(dr, start, goal, r, Witness.of_labels(j1, j2))
    want = ["witness.start"] if x == (0, WAIT, *start) else ["witness.edge"]
    assert conditions(fails) == want


@settings(max_examples=150, deadline=None)
@given(case=cases(free_ends=None), data=st.data())
def test_a_witness_that_drops_the_edges_into_a_cell_is_rejected(case, data):
    # The search is run on D_R with one more blocked cell (every edge into it dropped) and its
    # witness is checked against the real D_R and the real answer.
    dr, start, goal = case
    r = search_opt_path_fast(dr, start, goal, with_witness=True)
    reached = (r.witness.j1 != np.iinfo(r.witness.j1.dtype).max
               if r.status is SearchStatus.FOUND else r.witness.reachable)
    cells = sorted({(int(s), int(i), int(j)) for s, _, i, j in np.argwhere(reached)
                    if (s, i, j) != (0, *start)})
    assume(cells)
    s, i, j = data.draw(st.sampled_from(cells))
    fewer = dr.copy()
    fewer[s, i, j] = 1
    w = search_opt_path_fast(fewer, start, goal, with_witness=True).witness
    fails = check_witness(dr, start, goal, r, w)
    assert len(fails) == 1
    assert fails[0].condition in ("witness.form", "witness.edge", "witness.goal",
                                  "witness.closure")


def test_an_edge_failure_names_the_state_the_edge_and_the_labels():
    dr = np.zeros((3, 3, 3), dtype=np.uint8)
    r = certified(dr, (0, 0), (2, 2))
    j1, j2 = labels(r.witness)
    j1[1, MOVES.index((1, 1)), 1, 1] += 5                  # the state after one diagonal move
    (f,) = check_witness(dr, (0, 0), (2, 2), r, Witness.of_labels(j1, j2))
    v = dict(f.values)
    assert f.condition == "witness.edge" and "label[s'] <= label[s] + cost" in f.message
    assert v["state"] == {"step": 0, "cell": [0, 0], "previous move": [0, 0]}
    assert v["label"] == [0, 0] and v["move"] == [1, 1] and v["edge cost"] == [2, 2]
    assert v["to state"] == {"step": 1, "cell": [1, 1], "previous move": [1, 1]}
    assert v["its label"] == [7, 2] and v["bound"] == [2, 2]


def test_a_worse_path_fails_the_goal_condition_with_both_costs():
    dr = np.zeros((3, 3, 3), dtype=np.uint8)
    r = certified(dr, (0, 0), (2, 2))
    path = ((0, 0), (1, 1), (1, 2), (2, 1), (2, 2))          # a step back: J1 = 6
    worse = SearchResult.found(path, J1(path), J2(path))
    (f,) = check_witness(dr, (0, 0), (2, 2), worse, r.witness)
    assert f.condition == "witness.goal"
    assert dict(f.values)["path's J1, J2 (recomputed)"] == [J1(path), J2(path)]
    assert dict(f.values)["least goal label + stop"] == [r.J1, r.J2]


def test_malformed_witnesses_fail_the_form_condition():
    dr = np.zeros((3, 3, 3), dtype=np.uint8)
    r = certified(dr, (0, 0), (2, 2))
    j1, j2 = labels(r.witness)
    for w in (None, Witness.of_reachable(np.ones(j1.shape, dtype=bool)),
              Witness.of_labels(j1[:-1], j2[:-1]), Witness.of_labels(j1.astype(np.int32), j2),
              Witness.of_labels(j1, j2.astype(np.uint32))):
        assert conditions(check_witness(dr, (0, 0), (2, 2), r, w)) == ["witness.form"]
    half = j2.copy()
    half[0, 0, 1, 1] = 7                                    # a label in j2 only
    assert conditions(check_witness(dr, (0, 0), (2, 2), r, Witness.of_labels(j1, half))) == [
        "witness.form"]
    big1, big2 = j1.astype(np.uint32), j2.astype(np.uint32)
    big1[0, WAIT, 0, 0] = 1 << 30
    assert "out of range" in check_witness(dr, (0, 0), (2, 2), r,
                                           Witness.of_labels(big1, big2))[0].message


def test_an_invalid_path_fails_even_with_good_labels():
    dr = np.zeros((3, 3, 3), dtype=np.uint8)
    r = certified(dr, (0, 0), (2, 2))
    jump = SearchResult.found(((0, 0), (2, 2)), 4, 4)
    assert conditions(check_witness(dr, (0, 0), (2, 2), jump, r.witness)) == ["witness.path"]


# --- corruptions of reachable sets ---------------------------------------------------------


@st.composite
def no_path_cases(draw):
    dr, start, goal = draw(cases())
    dr = dr.copy()
    N = dr.shape[0] - 1
    wall = draw(st.sampled_from(["row", "column", "goal at rest"]))
    if wall == "goal at rest":
        dr[N][goal] = 1
    elif wall == "row" and start[0] != goal[0]:
        dr[:, (start[0] + goal[0]) // 2 + (start[0] < goal[0]), :] = 1
    elif start[1] != goal[1]:
        dr[:, :, (start[1] + goal[1]) // 2 + (start[1] < goal[1])] = 1
    dr[0][start] = 0
    return dr, start, goal


@settings(max_examples=150, deadline=None)
@given(case=no_path_cases(), data=st.data())
def test_a_state_removed_from_the_reachable_set_is_rejected(case, data):
    dr, start, goal = case
    r = search_opt_path_fast(dr, start, goal, with_witness=True)
    assume(r.status is SearchStatus.NO_PATH)
    reach = r.witness.reachable.copy()
    states = [tuple(int(v) for v in x) for x in np.argwhere(reach)]
    x = data.draw(st.sampled_from(states))
    reach[x] = False
    fails = check_witness(dr, start, goal, r, Witness.of_reachable(reach))
    want = ["witness.start"] if x == (0, WAIT, *start) else ["witness.closure"]
    assert conditions(fails) == want


def test_a_set_holding_a_goal_state_fails_exclusion_and_a_path_fails_the_kind():
    dr = np.zeros((3, 3, 3), dtype=np.uint8)
    dr[:, 1, :] = 1                                        # a wall: no path
    r = certified(dr, (0, 0), (2, 2))
    assert r.status is SearchStatus.NO_PATH
    reach = r.witness.reachable.copy()
    reach[2, :, 2, :] = True               # the far row at the capped step: closed, goal in it
    (f,) = check_witness(dr, (0, 0), (2, 2), r, Witness.of_reachable(reach))
    assert f.condition == "witness.exclusion"
    assert dict(f.values)["state"] == {"step": 2, "cell": [2, 2], "previous move": [-1, -1]}
    open_ = np.zeros_like(dr)
    good = certified(open_, (0, 0), (2, 2))
    assert conditions(check_witness(open_, (0, 0), (2, 2), r, good.witness)) == ["witness.form"]
    # a claimed "no path" with the reachable set of the wall's D_R, on the open D_R: closure
    assert conditions(check_witness(open_, (0, 0), (2, 2), r, r.witness)) == ["witness.closure"]


def test_a_blocked_start_or_goal_needs_no_more_than_its_set():
    dr = np.zeros((3, 3, 3), dtype=np.uint8)
    dr[0, 0, 0] = 1
    r = certified(dr, (0, 0), (2, 2))
    assert not r.witness.reachable.any()
    dr = np.zeros((3, 3, 3), dtype=np.uint8)
    dr[2, 2, 2] = 1
    r = certified(dr, (0, 0), (2, 2))
    assert r.witness.reachable.any()                       # all it reaches, none at the goal


# --- the file -------------------------------------------------------------------------------


def test_the_file_round_trips_and_bad_files_are_input_errors(tmp_path):
    dr = np.zeros((3, 3, 3), dtype=np.uint8)
    for d in (dr, np.pad(np.ones((3, 1, 3), dtype=np.uint8), ((0, 0), (1, 1), (0, 0)))):
        r = certified(d, (0, 0), (2, 2))
        f = tmp_path / "w.npz"
        f.write_bytes(r.witness.npz_bytes())
        back = load_witness(f)
        assert back.kind == r.witness.kind
        assert all(np.array_equal(back.arrays[k], v) and back.arrays[k].dtype == v.dtype
                   for k, v in r.witness.arrays.items())
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    np.save(tmp_path / "one.npy", np.zeros(3))
    np.savez(tmp_path / "other.npz", format=np.array("something-else"), j1=np.zeros(3))
    np.savez(tmp_path / "kind.npz", format=np.array("cfmpa-witness-1"), kind=np.array("labels"))
    for name, field in (("junk.npz", "witness"), ("one.npy", "witness"),
                        ("other.npz", "format"), ("kind.npz", "kind"), ("absent.npz", "witness")):
        with pytest.raises(InputError) as err:
            load_witness(tmp_path / name)
        assert err.value.field == field and str(tmp_path / name) in err.value.render()


def test_the_witness_takes_no_part_in_comparing_results():
    dr = np.zeros((3, 3, 3), dtype=np.uint8)
    r = certified(dr, (0, 0), (2, 2))
    assert r == replace(r, witness=None) and "witness" not in repr(r)
