"""`cfmpa monitor` between samples (docs/model.md §12): a hole in the log, a late start and an early
end are `unobserved` (exit 1) with the interval's start and length; a dense log stays inside; the
bound is the spec's (a copy without its h term lets the hole through, and the test sees it)."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest

import factory
from cfmpa.cli import main
from cfmpa.errors import InputError
from cfmpa.runs import _trajectory_runs, log_csv, monitor_log, parse_max_speed, simulate_log
from cfmpa.runs._trajectory_runs import AFTER_LOG, BEFORE_LOG, BETWEEN_SAMPLES, LISTED_UNOBSERVED
from cfmpa.spec import ReferenceSpeeds, Trajectory, load_trajectory, max_of, tolerance_rad

DOC = factory.doc(right__start_cell=[2, 8], right__goal_cell=[13, 5])


@pytest.fixture(scope="module")
def cell(tmp_path_factory):
    s, scen, folder, p = factory.planned(tmp_path_factory.mktemp("between"), DOC)
    traj = load_trajectory(folder / "traj.csv", s)
    tol = tolerance_rad(s, p.certificate)
    # A 1 kHz tracking log from the first row to the last (3.5 s here), well inside the tube.
    t, a = simulate_log(traj, noise=tol / 4, seed=5, lag=0.001)
    assert t[0] == traj.t[0] and t[-1] == traj.t[-1] and len(t) == 3501
    return s, scen, folder / "traj.csv", traj, tol, t, a


def _monitor(cell, keep, **kw):
    s, _, _, traj, tol, t, a = cell
    return monitor_log(s, traj, tol, io.StringIO(log_csv(t[keep], a[keep]).decode()), **kw)


def _write(cell, path, keep):
    t, a = cell[5], cell[6]
    path.write_bytes(log_csv(t[keep], a[keep]))
    return path


def _hole(cell):
    keep = np.ones(len(cell[5]), dtype=bool)
    keep[1000:1500] = False                       # 500 samples dropped: t = 1.000 .. 1.499 s
    return keep


def test_a_dense_log_is_inside_at_every_instant(cell, tmp_path):
    _, scen, traj_csv, _, tol, t, _ = cell
    log = _write(cell, tmp_path / "log.csv", slice(None))
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(log), "--json",
                 str(tmp_path / "m.json")]) == 0
    doc = json.loads((tmp_path / "m.json").read_text())
    assert doc["status"] == "inside" and doc["unobserved"] is None
    assert doc["covered_fraction"] == pytest.approx(1.0, abs=1e-12)
    assert doc["max_gap_s"] == pytest.approx(0.001, rel=1e-9)
    # The scenario's omega (the trajectory's own top speed where rounding puts it above).
    assert doc["max_speed_rad_s"] == pytest.approx([1.0] * 4, rel=1e-12)
    assert all(w >= 1.0 for w in doc["max_speed_rad_s"])


def test_a_half_second_hole_is_unobserved_exit_1(cell, tmp_path, capsys):
    _, scen, traj_csv, _, _, t, _ = cell
    log = _write(cell, tmp_path / "hole.csv", _hole(cell))
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(log), "--json",
                 str(tmp_path / "m.json")]) == 1
    doc = json.loads((tmp_path / "m.json").read_text())
    assert doc["status"] == "unobserved" and doc["outside"] == 0
    u = doc["unobserved"]
    assert u["count"] == 1 and u["first"] == u["longest"] == u["listed"][0]
    # From the last sample before the hole (t[999], line 1001) to the first after (t[1500]).
    assert u["first"]["t_s"] == t[999] and u["first"]["line"] == 1001
    assert u["first"]["length_s"] == pytest.approx(t[1500] - t[999]) == pytest.approx(0.501)
    assert u["first"]["why"] == BETWEEN_SAMPLES
    assert doc["max_gap_s"] == pytest.approx(0.501)
    assert doc["covered_fraction"] == pytest.approx(1 - 0.501 / 3.5)
    # The verdict and its details on one stream (stdout), the status word once in the summary.
    got = capsys.readouterr()
    assert got.err == ""
    summary, detail = got.out.splitlines()[:2]
    assert summary.count("unobserved") == 1 and "unobserved (1 interval(s), 0.501 s in all)" in summary
    assert detail.startswith(f"first     unobserved from t={float(t[999])!r} s for 0.501 s "
                             "(line 1001)")


def _reach(cell, k, a_s, b_s):
    """How far from sample k the one-sided bound (spec.log_end_bound) vouches, over [a_s, b_s]."""
    s, _, _, traj, tol, t, a = cell
    d = np.abs(a[k] - traj.at(t[k]))
    w = parse_max_speed(None, s, traj) + ReferenceSpeeds.of(traj).over(
        np.array([a_s]), np.array([b_s]))[0]
    return float(np.min((tol - d) / w))


def test_a_late_start_and_an_early_end_are_unobserved_beyond_the_one_sided_bound(cell):
    # docs/model.md §12: the time before the first sample (after the last) is covered from that
    # sample alone as far as its deviation + (w_x + w_r) x the distance stays within the tube.
    t = cell[5]
    late = _monitor(cell, slice(300, None))
    assert late.status == "unobserved" and late.unobserved_count == 1
    u = late.unobserved[0]
    assert (u.t_s, u.line, u.why) == (0.0, None, BEFORE_LOG)
    reach = _reach(cell, 300, 0.0, t[300])
    assert 0.001 < reach < 0.05                        # a few ms, not the 0.3 s before
    assert u.length_s == pytest.approx(t[300] - reach, rel=1e-12)
    assert late.covered_fraction == pytest.approx(1 - (t[300] - reach) / 3.5)
    early = _monitor(cell, slice(None, -300))
    assert early.status == "unobserved" and early.unobserved_count == 1
    u = early.unobserved[0]
    reach = _reach(cell, -301, t[-301], 3.5)
    assert (u.why, u.line) == (AFTER_LOG, len(t) - 300 + 1)
    assert u.t_s == pytest.approx(t[-301] + reach, rel=1e-12)
    assert u.t_s + u.length_s == pytest.approx(3.5)
    both = _monitor(cell, slice(300, -300))
    assert [x.why for x in both.unobserved] == [BEFORE_LOG, AFTER_LOG]
    # A log a few samples short at either end is covered all the same.
    for keep in (slice(2, None), slice(None, -2), slice(2, -2)):
        assert _monitor(cell, keep).status == "inside", keep


def test_the_ends_are_decided_by_the_specs_one_sided_bound(cell, monkeypatch):
    # Seeded faults in spec.log_end_bound as the monitor calls it: without its h term a 0.3 s
    # late start goes through; a bound that never holds leaves even a short log's ends unobserved.
    assert _monitor(cell, slice(300, None)).status == "unobserved"
    monkeypatch.setattr(_trajectory_runs, "log_end_bound", lambda d, h, w_robot, w_ref: d)
    assert _monitor(cell, slice(300, None)).status == "inside"
    monkeypatch.setattr(_trajectory_runs, "log_end_bound",
                        lambda d, h, w_robot, w_ref: d + np.inf)
    r = _monitor(cell, slice(2, -2))
    assert r.status == "unobserved" and [u.why for u in r.unobserved] == [BEFORE_LOG, AFTER_LOG]


def test_intervals_merge_across_blocks_and_blocks_agree(cell):
    keep = _hole(cell)
    keep[2000:2200:2] = False                     # every other sample: gaps of 2 ms stay covered
    keep[3000:3100] = False
    ref = _monitor(cell, keep)
    assert ref.unobserved_count == 2 and ref.status == "unobserved"
    for block in (1, 7, 1000, 1001):             # 1001: a block boundary inside the first hole
        got = _monitor(cell, keep, block_rows=block)
        assert (got.unobserved, got.covered_fraction, got.max_gap_s, got.unobserved_s) == (
            ref.unobserved, ref.covered_fraction, ref.max_gap_s, ref.unobserved_s)


def test_many_intervals_are_counted_and_the_first_ones_listed(cell):
    s, _, _, traj, tol, t, a = cell
    keep = np.zeros(len(t), dtype=bool)
    keep[::200] = True                            # 0.2 s apart: no gap covered
    keep[-1] = True
    r = _monitor(cell, keep)
    assert r.unobserved_count == 1 and r.unobserved[0].length_s == pytest.approx(3.5)
    # Alternate covered and uncovered gaps: each uncovered one is its own interval.
    keep = np.zeros(len(t), dtype=bool)
    for k in range(0, 3400, 100):
        keep[k:k + 3] = True                      # 3 samples 1 ms apart, then a 98 ms gap
    keep[-1] = True
    r = _monitor(cell, keep)
    # 34 groups, each followed by a gap no bound covers (the last one's runs to the end).
    assert r.unobserved_count == 34 and len(r.unobserved) == LISTED_UNOBSERVED
    assert r.unobserved_s == pytest.approx(3.5 - 34 * 0.002, rel=1e-9)
    assert r.covered_fraction == pytest.approx(34 * 0.002 / 3.5)


def test_the_seeded_fault_without_the_h_term_lets_the_hole_through(cell, monkeypatch):
    # The hole is caught by the bound's h term: a copy of the monitor whose bound leaves it out
    # sees both ends of the hole inside and vouches for the half second nobody saw.
    assert _monitor(cell, _hole(cell)).status == "unobserved"
    monkeypatch.setattr(_trajectory_runs, "between_samples_bound",
                        lambda d0, d1, h, w_robot, w_ref: max_of(d0, d1))
    faulty = _monitor(cell, _hole(cell))
    assert faulty.status == "inside" and faulty.unobserved_count == 0


def test_the_robot_speed_bound_comes_from_max_speed(cell, tmp_path, capsys):
    s, scen, traj_csv, traj, tol, _, _ = cell
    assert list(parse_max_speed("2", s, traj)) == [2.0] * 4
    assert list(parse_max_speed("1,2,3,4", s, traj)) == [1.0, 2.0, 3.0, 4.0]
    for bad in ("fast", "1,2", "-1", "nan", "inf", "1,2,3,4," + "9" * 200):
        with pytest.raises(InputError) as e:
            parse_max_speed(bad, s, traj)
        assert "--max-speed" in e.value.render() and len(repr(e.value.value)) <= 90
    # A robot that could turn 200 rad/s: 1 ms gaps are no longer covered.
    assert _monitor(cell, slice(None), max_speed=np.full(4, 200.0)).status == "unobserved"
    log = _write(cell, tmp_path / "log.csv", slice(None))
    base = ["monitor", str(scen), "--traj", str(traj_csv), "--log", str(log)]
    assert main(base + ["--max-speed", "200"]) == 1
    assert main(base + ["--max-speed", "1,1,1,1"]) == 0
    capsys.readouterr()
    assert main(base + ["--max-speed", "1,x"]) == 2
    assert "--max-speed" in capsys.readouterr().err


def test_a_single_row_trajectory_is_one_instant(cell):
    s, _, _, _, tol, _, _ = cell
    rest = Trajectory(np.array([1.0]), np.array([[0.3, 0.8, 1.0, 1.0]]))
    t = np.array([0.999, 0.9995, 1.0, 1.0005, 1.001])
    a = np.repeat(rest.angles, len(t), axis=0)
    r = monitor_log(s, rest, tol, io.StringIO(log_csv(t, a).decode()))
    assert r.status == "inside" and r.covered_fraction == 1.0
    # Half a millisecond after the instant: the one-sided bound from the first sample covers it.
    r = monitor_log(s, rest, tol, io.StringIO(log_csv(t[3:], a[3:]).decode()))
    assert r.status == "inside" and r.covered_fraction == 1.0
    # Half a second after: too far for it (tol / omega is about tol seconds here).
    late = t[3:] + 0.5
    r = monitor_log(s, rest, tol, io.StringIO(log_csv(late, a[3:]).decode()))
    assert r.status == "unobserved" and r.covered_fraction == 0.0
    assert (r.unobserved[0].why, r.unobserved[0].t_s) == (BEFORE_LOG, 1.0)
    assert r.unobserved[0].length_s == pytest.approx(late[0] - 1.0 - tol / 1.0, rel=1e-9)
    # A gap before the trajectory's first row is monitored too: the arms rest there.
    t2 = np.array([0.0, 0.999, 1.0])
    r = monitor_log(s, rest, tol, io.StringIO(log_csv(t2, a[:3]).decode()))
    assert r.status == "unobserved" and r.covered_fraction == 1.0
    assert (r.unobserved[0].t_s, r.unobserved[0].why) == (0.0, BETWEEN_SAMPLES)


def test_reference_speeds_over_an_interval_are_the_pieces_it_meets():
    traj = Trajectory(np.array([0.0, 1.0, 2.0, 4.0]),
                      np.array([[0, 0, 0, 0], [1, 0, 0, 0], [1, 3, 0, 0], [1, 3, 0, 1.0]]))
    ref = ReferenceSpeeds.of(traj)
    a = np.array([-1.0, 0.5, 0.5, 1.0, 1.5, 3.0, -5.0, 4.0, 0.0])
    b = np.array([-0.5, 0.9, 1.5, 2.0, 3.0, 5.0, 5.0, 6.0, 1.0])
    got = ref.over(a, b)
    want = [[0, 0, 0, 0], [1, 0, 0, 0], [1, 3, 0, 0], [0, 3, 0, 0], [0, 3, 0, 0.5],
            [0, 0, 0, 0.5], [1, 3, 0, 0.5], [0, 0, 0, 0], [1, 0, 0, 0]]
    assert got.tolist() == want
    assert ref.top().tolist() == [1, 3, 0, 0.5]


def test_blocks_are_bounded_in_characters_too(cell, monkeypatch):
    # Long lines (valid numbers padded with zeros) make smaller blocks; the result is the same.
    keep = _hole(cell)
    ref = _monitor(cell, keep)
    monkeypatch.setattr(_trajectory_runs, "BLOCK_CHARS", 500)
    got = _monitor(cell, keep)
    assert (got.samples, got.unobserved, got.covered_fraction) == (
        ref.samples, ref.unobserved, ref.covered_fraction)
    sizes = [len(b) for b in _trajectory_runs._blocks(iter(["x" * 100 + "\n"] * 50), 16_384)]
    assert sizes == [5] * 10
