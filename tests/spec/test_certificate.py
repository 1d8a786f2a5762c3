"""The continuous-time certificate: sound against dense independent sampling, catches contacts
between samples, and says 'undecided' rather than 'clear' when its caps stop it."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.errors import CertificateViolation, InputError
from cfmpa.spec import (
    certificate_json,
    certify,
    left_angles,
    load_scenario,
    make_grid,
    parse_scenario,
    polygon_distance,
    require_clear,
)
from cfmpa.spec._certificate import _link_rects, _link_speeds
from cfmpa.spec._kinematics import link_corners
from cfmpa.spec._polygon import polygon_distances

DEFAULT = Path(__file__).resolve().parents[2] / "scenarios" / "default.toml"
TWO_PI = 6.283185307179586


def scenario(dt: float, left: dict, right: dict):
    arm = {"links": [0.35, 0.30], "width": 0.06, "omega": [1.0, 1.0]}
    doc = {"name": "hand-made", "purpose": "a certificate test", "dt": dt,
           "left": {**arm, "base": [0.0, 0.0], **left},
           "right": {**arm, "base": [0.6, 0.0], "limits": [[0.0, TWO_PI], [0.0, TWO_PI]],
                     **right}}
    return parse_scenario(doc, check_budget=False)


def cell_near(grid, q: int, angle: float) -> int:
    return int(round((angle - grid.lo[q]) / grid.h[q]))


def executed_distance(s, grid, path, t: float) -> float:
    """The arms' distance at time t, from the scalar spec routines and np.interp (not certify's
    own motion code): left PTP, right linear between cells one per dt, resting at the end."""
    thl = tuple(float(x) for x in left_angles(s, t))
    cells = np.asarray(path, dtype=float)
    x = np.arange(len(path))
    thr = tuple(float(np.interp(t / grid.dt, x, grid.lo[q] + cells[:, q] * grid.h[q]))
                for q in range(2))
    return min(polygon_distance(link_corners(s.left, thl, a), link_corners(s.right, thr, b))
               for a in range(2) for b in range(2))


def dense_min(s, grid, path, samples: int) -> float:
    """Least distance over `samples` evenly spaced instants plus every multiple of dt and Tf."""
    t_end = max((len(path) - 1) * grid.dt, grid.Tf)
    times = np.unique(np.concatenate([np.linspace(0.0, t_end, samples),
                                      np.arange(len(path)) * grid.dt, [grid.Tf]]))
    cells = np.asarray(path, dtype=float)
    x = np.arange(len(path))
    thr = np.stack([np.interp(times / grid.dt, x, grid.lo[q] + cells[:, q] * grid.h[q])
                    for q in range(2)], axis=1)
    thl = left_angles(s, times)
    left = np.array([[link_corners(s.left, tuple(th), a) for a in range(2)] for th in thl])
    right = np.array([[link_corners(s.right, tuple(th), b) for b in range(2)] for th in thr])
    return float(polygon_distances(left[:, :, None], right[:, None, :]).min())


# (a) arms far apart ---------------------------------------------------------------------------


def test_far_apart_is_clear_with_the_hand_computed_clearance():
    # Left stands still pointing along +x from (0, 0): its rectangle ends at x = l1 + l2 + w/2
    # = 0.68, |y| <= w/2. Right, based at (3, 0), straight, swings through pointing along -x.
    # Its nearest point is an end corner, at distance sqrt(0.68^2 + 0.03^2) from its base; that
    # corner reaches y = 0 when the arm is turned by atan(0.03 / 0.68) from -x. So the least
    # clearance over the motion is 3 - 0.68 - sqrt(0.68^2 + 0.03^2), between grid samples.
    s = scenario(0.05, {"start": [0.0, 0.0], "goal": [0.0, 0.0]},
                 {"base": [3.0, 0.0], "start": [math.pi, 0.0], "goal": [math.pi, 0.0]})
    g = make_grid(s)
    i0 = cell_near(g, 0, math.pi)
    path = [(i, 0) for i in range(i0 - 6, i0 + 7)]
    hand = 3.0 - 0.68 - math.hypot(0.68, 0.03)
    cert = certify(s, g, path)
    assert cert.clear
    assert cert.contact is None and cert.undecided == ()
    assert hand <= cert.min_clearance_m <= hand + 1e-4
    assert 0.9 * cert.min_clearance_m <= cert.lower_bound_m <= hand
    assert cert.lower_bound_m <= dense_min(s, g, path, 400)
    require_clear(cert)  # no exception


# (b) a path through the left arm ----------------------------------------------------------------


def test_path_through_the_left_arm_has_a_contact():
    # Right arm straight, swinging from pointing right (theta1 = 0) to pointing left (pi),
    # through the left arm standing at its base.
    s = scenario(0.02, {"start": [1.2, 0.3], "goal": [1.9, 0.0]},
                 {"start_cell": [0, 0], "goal_cell": [158, 0]})
    g = make_grid(s)
    path = [(i, 0) for i in range(159)]
    cert = certify(s, g, path)
    assert not cert.clear
    assert cert.contact is not None
    t, (a, b) = cert.contact
    assert 0.0 <= t <= (len(path) - 1) * g.dt
    assert (a, b) in {(1, 1), (1, 2), (2, 1), (2, 2)}          # link numbers, 1-based (§2)
    assert executed_distance(s, g, path, t) == 0.0
    assert cert.min_clearance_m == 0.0 and cert.lower_bound_m == 0.0
    with pytest.raises(CertificateViolation, match="touch"):
        require_clear(cert)


@pytest.mark.parametrize("left, path", [
    ({"start": [1.2, 0.3], "goal": [1.9, 0.0]}, [(i, 0) for i in range(159)]),
    ({"start": [1.9, 0.0], "goal": [1.2, 0.3]}, [(124, 0)] * 3)])
def test_a_contact_names_both_arms_angles_the_segment_and_the_cells(left, path):
    # Moving through the left arm, or resting (after a short list) where the left arm arrives.
    s = scenario(0.02, left, {"start_cell": [0, 0], "goal_cell": [158, 0]})
    g = make_grid(s)
    cert = certify(s, g, path)
    c = cert.contact_detail
    assert c is not None and (c.t_s, c.links) == cert.contact
    assert c.left_angles_rad == tuple(float(x) for x in left_angles(s, c.t_s))
    if c.step is None:                               # resting at the last cell
        assert c.t_s >= (len(path) - 1) * g.dt and c.cells == (path[-1], path[-1])
        assert c.right_angles_rad == g.angles(path[-1]) and c.segment == "resting at the last cell"
    else:
        assert c.step * g.dt <= c.t_s <= (c.step + 1) * g.dt
        assert c.cells == (path[c.step], path[c.step + 1])
        assert c.segment == f"step {c.step}->{c.step + 1}"
        lo, hi = sorted(g.angles(x)[0] for x in c.cells)
        assert lo <= c.right_angles_rad[0] <= hi
    assert (len(path) == 3) == (c.step is None)
    with pytest.raises(CertificateViolation) as info:
        require_clear(cert)
    v = info.value.values
    assert v["left angles_rad"] == list(c.left_angles_rad)
    assert v["right angles_rad"] == list(c.right_angles_rad)
    assert v["path segment"] == c.segment and v["cells"] == [list(x) for x in c.cells]
    out = certificate_json(cert)["contact"]
    assert out["step"] == c.step and out["cells"] == [list(x) for x in c.cells]
    assert json.loads(json.dumps(out)) == out


# (c) contact strictly between samples ---------------------------------------------------------


def thin_crossing():
    """A thin left link standing still on x = 0; the right arm, pointing at it, swings its end
    across it during one step: clear at t = 0 and t = dt, in contact at t = dt/2."""
    doc = {"name": "between-samples", "purpose": "contact only between samples", "dt": 0.2,
           "left": {"base": [0.0, 0.0], "links": [0.3, 0.3], "width": 0.002, "omega": [1.0, 1.0],
                    "start": [math.pi / 2, 0.0], "goal": [math.pi / 2, 0.0]},
           "right": {"base": [0.351, 0.3], "links": [0.17, 0.18], "width": 0.002,
                     "omega": [1.0, 1.0], "limits": [[math.pi - 0.3, math.pi + 0.3], [-0.2, 0.2]],
                     "start_cell": [1, 1], "goal_cell": [2, 1]}}
    s = parse_scenario(doc, check_budget=False)
    return s, make_grid(s), [(1, 1), (2, 1)]


def test_contact_between_samples_is_caught():
    s, g, path = thin_crossing()
    # The cells straddle theta1 = pi, where the right arm points straight at the left link.
    assert g.angles(path[0])[0] < math.pi < g.angles(path[1])[0]
    # A naive check at the multiples of dt sees only clearance.
    sampled = [executed_distance(s, g, path, k * g.dt) for k in range(len(path))]
    assert min(sampled) > 0.0
    cert = certify(s, g, path)
    assert not cert.clear
    assert cert.contact is not None
    t, _ = cert.contact
    assert 0.0 < t < g.dt
    assert executed_distance(s, g, path, t) == 0.0


def test_depth_cap_reports_undecided_not_clear():
    s, g, path = thin_crossing()
    cert = certify(s, g, path, max_depth=0)
    assert not cert.clear
    assert cert.contact is None
    assert cert.undecided == ((0.0, g.dt),)
    assert cert.lower_bound_m == 0.0
    with pytest.raises(CertificateViolation, match="neither proved clear"):
        require_clear(cert)


def test_interval_budget_reports_undecided_not_clear():
    s, g, path = thin_crossing()
    cert = certify(s, g, path, max_intervals=1)
    assert not cert.clear and cert.contact is None and cert.undecided


# soundness against dense independent sampling --------------------------------------------------


@settings(max_examples=25, deadline=None)
@given(st.integers(min_value=0, max_value=2**32 - 1))
def test_sound_against_dense_sampling_on_random_motions(seed):
    rng = np.random.default_rng(seed)
    dt = float(rng.choice([0.03, 0.05, 0.1]))
    left = {"start": rng.uniform(0, TWO_PI, 2).tolist(), "goal": rng.uniform(0, TWO_PI, 2).tolist(),
            "omega": rng.uniform(0.5, 2.0, 2).tolist()}
    right = {"base": [float(rng.uniform(0.3, 1.3)), float(rng.uniform(-0.3, 0.3))],
             "width": float(rng.uniform(0.01, 0.08)), "start_cell": [0, 0], "goal_cell": [0, 0]}
    s = scenario(dt, left, right)
    g = make_grid(s)
    cell = np.array([rng.integers(g.m), rng.integers(g.n)])
    path = [tuple(int(x) for x in cell)]
    for _ in range(int(rng.integers(0, 40))):
        # Steps up to 2 cells: the certificate does not assume neighbours (a jump moves faster).
        cell = np.clip(cell + rng.integers(-2, 3, 2), 0, [g.m - 1, g.n - 1])
        path.append(tuple(int(x) for x in cell))
    cert = certify(s, g, path)
    seen = dense_min(s, g, path, 1500)
    assert cert.lower_bound_m <= cert.min_clearance_m
    quick = certify(s, g, path, bound_ratio=0.0)
    assert quick.clear == cert.clear
    assert quick.lower_bound_m <= cert.lower_bound_m + 1e-12 or not cert.clear
    if cert.clear:
        assert quick.lower_bound_m > 0.0 and quick.lower_bound_m <= seen + 1e-12
        assert seen > 0.0
        assert cert.lower_bound_m <= seen + 1e-12
    if seen == 0.0:
        assert not cert.clear
    if cert.contact is not None:
        assert executed_distance(s, g, path, cert.contact[0]) <= 1e-12


def test_default_scenario_long_path_is_certified():
    # ~700 steps with the right arm wandering below and right of its base, away from the left
    # arm's sweep: the size the certificate must handle in about a second.
    s = load_scenario(DEFAULT)
    g = make_grid(s)
    rng = np.random.default_rng(1)
    lo_i, hi_i = cell_near(g, 0, 4.9), cell_near(g, 0, 6.2)
    hi_j = cell_near(g, 1, 1.2)
    cell = np.array([cell_near(g, 0, 5.5), cell_near(g, 1, 0.5)])
    path = [tuple(int(x) for x in cell)]
    for _ in range(699):
        cell = np.clip(cell + rng.integers(-1, 2, 2), [lo_i, 0], [hi_i, hi_j])
        path.append(tuple(int(x) for x in cell))
    cert = certify(s, g, path)
    assert cert.clear
    assert cert.intervals >= len(path) - 1
    assert 0.0 < cert.lower_bound_m <= dense_min(s, g, path, 3000)


# the pieces certify relies on -------------------------------------------------------------------


def test_batched_rectangles_match_link_corners():
    s = load_scenario(DEFAULT)
    theta = np.random.default_rng(3).uniform(-7.0, 7.0, size=(40, 2))
    for arm in (s.left, s.right):
        rects = _link_rects(arm, theta)
        for k, th in enumerate(theta):
            for link in range(2):
                expected = np.array(link_corners(arm, (float(th[0]), float(th[1])), link))
                np.testing.assert_allclose(rects[k, link], expected, rtol=0, atol=1e-14)


def test_speed_bound_holds_for_every_corner():
    # A rectangle's fastest point is a corner (speed is convex in the point), so checking the
    # corners' finite-difference speeds checks the bound for the whole link.
    s = load_scenario(DEFAULT)
    rng = np.random.default_rng(5)
    theta = rng.uniform(-7.0, 7.0, size=(200, 2))
    w = rng.uniform(-3.0, 3.0, size=(200, 2))
    tau = 1e-7
    moved = np.abs(_link_rects(s.right, theta + w * tau) - _link_rects(s.right, theta))
    speed = np.sqrt(np.sum(moved**2, axis=-1)).max(axis=-1) / tau       # (200, 2 links)
    bound = _link_speeds(s.right, w)
    assert np.all(speed <= bound * (1 + 1e-6))
    # ... and it is attained: exactly for link 1 (its far corners), nearly for link 2 when the
    # arm is almost straight and both joints turn the same way.
    np.testing.assert_allclose(speed[:, 0], bound[:, 0], rtol=1e-5)
    assert np.max(speed[:, 1] / bound[:, 1]) >= 0.95


# output and input ---------------------------------------------------------------------------------


def test_certificate_json_shape():
    s, g, path = thin_crossing()
    out = certificate_json(certify(s, g, path))
    assert out["min_m"] == 0.0
    assert out["t_s"] == out["contact"]["t_s"]
    assert out["clear"] is False
    assert len(out["contact"]["links"]) == 2
    assert json.loads(json.dumps(out)) == out
    clear = certificate_json(certify(s, g, [(0, 1), (0, 1)]))
    assert {"min_m", "t_s", "lower_bound_m"} <= set(clear)   # docs/model.md §9's keys, and the proof's
    assert clear["clear"] is True and clear["contact"] is None and clear["undecided"] == []
    assert clear["min_m"] > 0.0 and clear["lower_bound_m"] > 0.0


def test_single_cell_path_with_resting_left_arm():
    s, g, _ = thin_crossing()
    cert = certify(s, g, [(0, 1)])
    assert cert.clear
    # Nothing moves, so the one sampled distance is itself the proven bound.
    assert cert.lower_bound_m == cert.min_clearance_m == pytest.approx(
        executed_distance(s, g, [(0, 1)], 0.0), abs=0.0)


def facing(gap: float):
    """Both arms at rest for the whole motion, straight along the x axis and facing each other,
    ``gap`` metres apart (negative: overlapping): the left's end at x = 0.68, the right's at
    its base minus 0.68. The certificate's only intervals are atomic ones."""
    s = scenario(0.05, {"start": [0.0, 0.0], "goal": [0.0, 0.0]},
                 {"base": [1.36 + gap, 0.0], "start": [math.pi, 0.0], "goal": [math.pi, 0.0]})
    g = make_grid(s)
    cell = (cell_near(g, 0, math.pi), 0)
    assert g.angles(cell)[0] == math.pi
    return s, g, cell


@pytest.mark.parametrize("waits", [1, 4])          # one cell (the instant [0, 0]), or waiting
@pytest.mark.parametrize("gap, verdict", [
    (1e-3, "clear"), (5e-10, "undecided"), (1e-15, "undecided"), (0.0, "undecided"),
    (-1e-3, "contact")])
def test_an_all_static_motion_is_decided_from_its_samples_without_splitting(gap, verdict, waits):
    # Nothing moves, so halving cannot tighten any bound: before, a clearance below EPS doubled
    # the intervals every round up to the caps (a million intervals, tens of seconds).
    s, g, cell = facing(gap)
    cert = certify(s, g, [cell] * waits)
    assert cert.intervals <= max(1, waits - 1) and cert.max_depth_used == 0
    seen = executed_distance(s, g, [cell], 0.0)
    assert cert.min_clearance_m == seen
    if verdict == "clear":
        assert cert.clear and cert.lower_bound_m == seen == pytest.approx(gap, abs=1e-12)
    elif verdict == "undecided":
        # Within EPS of a touch: neither provably apart nor a sampled contact.
        assert 0.0 < seen <= 1e-9
        assert not cert.clear and cert.contact is None and cert.lower_bound_m == 0.0
        assert cert.undecided == ((0.0, (waits - 1) * g.dt),)
        with pytest.raises(CertificateViolation, match="neither proved clear"):
            require_clear(cert)
    else:
        assert not cert.clear and cert.contact is not None and seen == 0.0


@pytest.mark.parametrize("path, field", [
    ([], "path"),
    ([(0, 0), (4, 0)], "path[1]"),
    ([(0, -1)], "path[0]"),
    ([(0, 0.5)], "path[0]"),
    ([(0, 0, 0)], "path[0]"),
    (3, "path"),
])
def test_refuses_malformed_paths(path, field):
    s, g, _ = thin_crossing()
    with pytest.raises(InputError) as info:
        certify(s, g, path)
    assert info.value.field == field


@pytest.mark.parametrize("options, field", [
    ({"max_depth": -1}, "max_depth"),
    ({"max_depth": 2.5}, "max_depth"),
    ({"bound_ratio": 1.0}, "bound_ratio"),
    ({"bound_ratio": -0.1}, "bound_ratio"),
])
def test_refuses_bad_options(options, field):
    s, g, path = thin_crossing()
    with pytest.raises(InputError) as info:
        certify(s, g, path, **options)
    assert info.value.field == field
