"""Trajectory files (docs/model.md §12): the loader's validation, the executed motion as waypoints,
the shared proof loop, and the tolerance formula."""

from __future__ import annotations

import json

import numpy as np
import pytest

import factory
from cfmpa.errors import InputError
from cfmpa.runs import plan
from cfmpa.spec import (
    Trajectory,
    certify,
    certify_trajectory,
    executed_trajectory,
    load_trajectory,
    parse_trajectory_csv,
    tolerance_rad,
    trajectory_csv,
    tube_lipschitz,
)
from cfmpa.spec._trajectory import parse_trajectory_json

START, GOAL = [2, 8], [13, 5]
HEADER = "t,left1,left2,right1,right2\n"


@pytest.fixture(scope="module")
def s():
    return factory.scenario(right__start_cell=START, right__goal_cell=GOAL)


@pytest.fixture(scope="module")
def planned(s):
    p = plan(s, "modified")
    assert p.certificate is not None and p.certificate.clear
    return p


def _err(text, s, **kw) -> InputError:
    with pytest.raises(InputError) as e:
        parse_trajectory_csv(text, s, source="traj.csv", **kw)
    return e.value


def test_a_valid_csv_in_any_column_order(s):
    t = parse_trajectory_csv("right2,t,left1,left2,right1\n1.0,0,0.3,0.8,0.5\n1.0,1,0.3,0.8,0.6\n",
                             s, source="x.csv")
    assert t.rows == 2 and t.lines == (2, 3)
    assert t.angles[1].tolist() == [0.3, 0.8, 0.6, 1.0]
    assert t.at([-1.0, 0.5, 9.0]).tolist() == [[0.3, 0.8, 0.5, 1.0], [0.3, 0.8, 0.55, 1.0],
                                               [0.3, 0.8, 0.6, 1.0]]


@pytest.mark.parametrize("text,line,words", [
    ("", 1, "header"),
    ("t,left1,left2,right1\n0,0,0,0\n", 1, "missing the column 'right2'"),
    ("t,left1,left2,right1,right2,x\n", 1, "exactly the columns"),
    (HEADER, 1, "at least one row"),
    (HEADER + "0,0.3,0.8,0.5,1\n1,0.3,nan,0.5,1\n", 3, "finite"),
    (HEADER + "0,0.3,0.8,0.5,1\n1,0.3,inf,0.5,1\n", 3, "finite"),
    (HEADER + "0,0.3,0.8,0.5,1\n1,0.3,x,0.5,1\n", 3, "number"),
    (HEADER + "0,0.3,0.8,0.5,1\n1,0.3,0.8,0.5\n", 3, "5 values"),
    (HEADER + "0,0.3,0.8,0.5,1\n0,0.3,0.8,0.5,1\n", 3, "strictly increase"),
    (HEADER + "1,0.3,0.8,0.5,1\n0.5,0.3,0.8,0.5,1\n", 3, "strictly increase"),
    (HEADER + "0,0.3,0.8,0.5,1\n\n1,0.3,0.8,0.5,1\n", 3, "blank"),
    (HEADER + "0,0.3,0.8,-0.5,1\n", 2, "limits"),
    (HEADER + "0,0.3,0.8,0.5,1\n1,0.3,0.8,0.5,7\n", 3, "limits"),
])
def test_bad_files_name_their_line(s, text, line, words):
    e = _err(text, s)
    assert e.line == line and words in e.render() and e.render().startswith(f"traj.csv:{line}:")
    assert e.exit_code == 2


def test_trailing_blank_lines_are_no_rows(s):
    assert parse_trajectory_csv(HEADER + "0,0.3,0.8,0.5,1\n\n\n", s).rows == 1


def test_a_joint_too_fast_is_refused_naming_row_joint_and_speed_unless_allowed(s):
    # The sample named once (its line, no row besides), the speed and its limit in one sentence.
    text = HEADER + "0,0.3,0.8,0.5,1\n1,0.3,0.8,0.5,1\n1.5,0.3,0.8,1.5,1\n"
    e = _err(text, s)
    assert e.line == 4 and e.render() == (
        "traj.csv:4: error: right1 speed is 2.0 rad/s from the previous row, above its omega "
        "of 1.0 rad/s (--allow-speed certifies it anyway)")
    assert "row 3" not in e.render() and e.render().count("2.0") == 1
    assert parse_trajectory_csv(text, s, allow_speed=True).rows == 3
    # Without lines (JSON) the row is named instead; a bag names its message (name_row).
    doc = {"t": [0, 1, 1.5], "left1": [0.3] * 3, "left2": [0.8] * 3, "right1": [0.5, 0.5, 1.5],
           "right2": [1, 1, 1]}
    with pytest.raises(InputError) as info:
        parse_trajectory_json(doc, s, source="t.json")
    assert info.value.render().startswith("t.json: error: right1 speed (row 3) is 2.0 rad/s")
    with pytest.raises(InputError) as info:
        parse_trajectory_csv(text, s, source="run.mcap", name_row=lambda k: f"message {k} on /js")
    assert info.value.line is None and info.value.render().startswith(
        "run.mcap: error: right1 speed of message 3 on /js is 2.0 rad/s from the previous "
        "message, above its omega of 1.0 rad/s")


def test_json_columns(s, tmp_path):
    doc = {"t": [0, 1], "left1": [0.3, 0.3], "left2": [0.8, 0.8], "right1": [0.5, 0.6],
           "right2": [1, 1]}
    f = tmp_path / "t.json"
    f.write_text(json.dumps(doc))
    assert load_trajectory(f, s).rows == 2
    for bad, words in [({**doc, "t": [0]}, "same count"), ({k: v for k, v in doc.items()
                                                             if k != "left2"}, "missing"),
                       ({**doc, "t": [0, None]}, "number"), ({**doc, "t": [1, 0]}, "increase"),
                       ({**doc, "x": [1, 2]}, "unknown")]:
        with pytest.raises(InputError, match=words):
            parse_trajectory_json(bad, s, source="t.json")
    f.write_text("{")
    with pytest.raises(InputError, match="JSON"):
        load_trajectory(f, s)


def test_the_executed_trajectory_certifies_as_the_grid_certificate(s, planned):
    g, path = planned.grid, planned.search.path
    traj = executed_trajectory(s, g, path)
    back = parse_trajectory_csv(trajectory_csv(traj), s)      # validated: speeds within omega
    assert np.array_equal(back.t, traj.t) and np.array_equal(back.angles, traj.angles)
    a, b = planned.certificate, certify_trajectory(s, back)
    assert b.clear and abs(a.lower_bound_m - b.lower_bound_m) <= 1e-15
    assert abs(a.min_clearance_m - b.min_clearance_m) <= 1e-15
    assert tolerance_rad(s, a) == tolerance_rad(s, b) > 0


def test_the_grid_certificate_is_unchanged_by_the_shared_loop(s, planned):
    # The loop is now prove_motion, shared with trajectories; the grid certificate still stops
    # at its first sampled contact and is deterministic. (Checked bit-identical against the
    # unshared loop on 300 random paths when it was shared: bound, minimum, intervals, contact.)
    c = certify(s, planned.grid, planned.search.path)
    assert c == planned.certificate
    rng = np.random.default_rng(7)
    g = planned.grid
    for _ in range(5):
        path = [[int(rng.integers(g.m)), int(rng.integers(g.n))] for _ in range(4)]
        c = certify(s, g, path)
        assert c.clear or c.contact is not None or c.undecided


def test_tolerance_formula(s, planned):
    c = planned.certificate
    tol = tolerance_rad(s, c)
    lip = tube_lipschitz(s)
    assert 2 * lip * tol < c.lower_bound_m - 1e-9 + 1e-18
    assert 2 * lip * (tol + 1e-6) > c.lower_bound_m - 1e-9
    assert round(tol * 1e6) == tol * 1e6
    # L for the tiny arms: link 2's R_base + R_elbow = l1 + 2 hypot(l2 + w/2, w/2).
    assert lip == pytest.approx(0.35 + 2 * np.hypot(0.33, 0.03))


def test_a_contact_is_the_first_one(s):
    # The right arm swings its first joint through the principal at rest: scan for the
    # configurations in contact, then check the certificate reports the earliest.
    left = [0.3, 0.8]
    traj = Trajectory(np.array([0.0, 10.0]), np.array([left + [3.3, 0.5], left + [1.2, 0.5]]))
    c = certify_trajectory(s, traj)
    assert not c.clear and c.contact is not None
    from cfmpa.spec import trajectory_distances
    t = np.linspace(0.0, 10.0, 200_001)
    d = trajectory_distances(s, traj.at(t)).min(axis=(1, 2))
    first = t[np.argmax(d == 0.0)]
    assert abs(c.contact[0] - first) <= 10.0 / 200_000 + 1e-6
    assert c.contact_detail is not None and c.contact_detail.step == 0


def test_a_single_row_is_one_instant(s):
    clear = Trajectory(np.array([1.0]), np.array([[0.3, 0.8, 3.3, 0.5]]))
    c = certify_trajectory(s, clear)
    assert c.clear and c.lower_bound_m == c.min_clearance_m > 0 and c.t_min_s == 1.0
    touching = Trajectory(np.array([0.0]), np.array([[0.3, 0.8, 2.0, 0.5]]))
    from cfmpa.spec import trajectory_distances
    if trajectory_distances(s, touching.angles).min() == 0.0:
        c = certify_trajectory(s, touching)
        assert not c.clear and c.contact is not None and c.contact_detail.step is None
