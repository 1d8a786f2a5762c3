"""`cfmpa monitor --traj` streamed (docs/model.md §12): the trajectory is certified in one
streamed pass, then read again beside the log in a bounded window (spec.StreamedReference). Its
answers are the held-whole trajectory's bit for bit (the trajectory at the samples, the speeds
on the gaps), so the monitor's JSON is the same, for any window and block size, on a planned
trajectory and a generated one, with logs denser and sparser than the trajectory, cut short at
either end, and with a trajectory of one row. A trajectory changed between the two readings is
bad input. Seeded faults: the carried speed of a long gap dropped, the window trimmed a row too
far, the second reading's check skipped."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest

import factory
import mutant_module
from cfmpa.cli import main
from cfmpa.errors import InputError
from cfmpa.runs import Excursion, log_csv, monitor_json, monitor_log, simulate_log
from cfmpa.spec import _trajectory as tr
from cfmpa.spec import certify_trajectory_file, load_trajectory, tolerance_rad, trajectory_csv

H = "t,left1,left2,right1,right2\n"


@pytest.fixture(scope="module")
def cell(tmp_path_factory):
    folder = tmp_path_factory.mktemp("monstream")
    s, scen, plan_dir, _ = factory.planned(folder, factory.doc(right__start_cell=[2, 8],
                                                               right__goal_cell=[13, 5]))
    # A generated trajectory of 400 rows at uneven times, both arms wandering slowly apart.
    rng = np.random.default_rng(11)
    n = 400
    t = np.cumsum(rng.uniform(0.005, 0.03, n))
    a = np.column_stack([s.left.start[0] + 0.05 * np.sin(t * rng.uniform(0.5, 2)),
                         s.left.start[1] + 0.05 * np.sin(t * rng.uniform(0.5, 2)),
                         3.3 + 0.05 * np.sin(t * rng.uniform(0.5, 2)),
                         0.5 + 0.05 * np.sin(t * rng.uniform(0.5, 2))])
    gen = folder / "gen.csv"
    gen.write_text(trajectory_csv(tr.Trajectory(t, a)))
    one = folder / "one.csv"
    one.write_text(H + "1.5," + ",".join(repr(float(x)) for x in a[0]) + "\n")
    return s, scen, [plan_dir / "traj.csv", gen, one]


def _logs(traj) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Logs of ``traj`` (of a one-row trajectory: over a second after it, and before it)."""
    span = float(traj.t[-1] - traj.t[0]) or 1.0
    tail = 0.0 if traj.rows > 1 else 1.0
    out = {"dense": simulate_log(traj, samples=max(2 * traj.rows, 50), noise=1e-3, seed=1,
                                 tail=tail),
           "sparse": simulate_log(traj, samples=7, seed=2, tail=tail),
           "one": simulate_log(traj, samples=1, seed=3),
           "lag_tail": simulate_log(traj, samples=90, lag=span / 20, tail=span / 10, seed=4),
           "excursion": simulate_log(traj, samples=200, seed=5, tail=tail, excursions=[
               Excursion(float(traj.t[0]) + span / 2, "right1", 0.5, span / 50)])}
    t, a = simulate_log(traj, samples=300, noise=1e-3, seed=6, tail=tail)
    if traj.rows == 1:                           # and from before it
        t = t - span / 2
    keep = (t > traj.t[0] + span / 5) & (t < traj.t[0] + 4 * span / 5)
    out["cut"] = (t[keep], a[keep]) if keep.sum() > 1 else (t[:2], a[:2])
    keep = (t < traj.t[0] + span / 5) | (t > traj.t[0] + 4 * span / 5)
    out["hole"] = (t[keep], a[keep])
    return out


def _doc(s, ref, tol, log: bytes, block_rows: int) -> dict:
    res = monitor_log(s, ref, tol, log.decode().splitlines(keepends=True), source="log.csv",
                      block_rows=block_rows)
    return monitor_json(s, ref, tol, res, "log.csv")


def _streamed(s, path: Path, info, window: int, block: int) -> tr.StreamedReference:
    with tr.trajectory_file_blocks(path, s, block_rows=block) as blocks:
        # the blocks are read lazily: materialised here, as the file closes after the with
        return tr.StreamedReference(iter(list(blocks)), info, window_rows=window)


def test_the_streamed_monitor_is_the_whole_trajectorys_json(cell):
    s, _, paths = cell
    seen, statuses = 0, set()
    for path in paths:
        info, cert, _ = certify_trajectory_file(path, s)
        tol = max(tolerance_rad(s, cert), 1e-3)
        traj = load_trajectory(path, s)
        for name, (t, a) in _logs(traj).items():
            log = log_csv(t, a)
            want = _doc(s, traj, tol, log, 4096)
            statuses.add(want["status"])
            for window, block, log_block in ((4, 2, 5), (9, 64, 4096)):
                ref = _streamed(s, path, info, window, block)
                got = _doc(s, ref, tol, log, log_block)
                ref.finish()
                assert got == want, (path.name, name, log_block, window, block)
                assert ref.peak_rows <= window + block, (ref.peak_rows, window, block)
                seen += 1
    assert seen == 3 * 7 * 2 and statuses == {"inside", "outside", "unobserved"}


def _queries(traj, rng) -> list[tuple[float, np.ndarray]]:
    """Monitor-like queries: increasing blocks of sample times, before, inside and past the
    trajectory, some many rows apart, each from the previous block's last time; then the end."""
    t0, t1 = float(traj.t[0]), float(traj.t[-1])
    span = t1 - t0
    times = np.unique(np.concatenate([
        rng.uniform(t0 - span / 10, t1 + span / 10, 40), traj.t[rng.integers(0, traj.rows, 10)],
        [t0, t1]]))
    out, prev = [], min(t0, float(times[0]))
    k = 0
    while k < len(times):
        m = int(rng.integers(1, 6))
        block = times[k:k + m]
        out.append((prev, block))
        prev, k = float(block[-1]), k + m
    if prev < t1:
        out.append((prev, np.array([t1])))
    return out


def _mismatches(s, path: Path, module=tr, seeds=range(4)) -> int:
    info, _, _ = certify_trajectory_file(path, s)
    traj = load_trajectory(path, s)
    bad = 0
    for seed in seeds:
        rng = np.random.default_rng(seed)
        queries = _queries(traj, rng)
        whole = module.WholeReference(traj)
        for window, block in ((4, 2), (6, 5), (50, 7)):
            with module.trajectory_file_blocks(path, s, block_rows=block) as blocks:
                ref = module.StreamedReference(blocks, info, window_rows=window)
                for lo, t in queries:
                    a_w, o_w = whole.block(lo, t)
                    a_s, o_s = ref.block(lo, t)
                    bad += not (np.array_equal(a_w.view(np.int64), a_s.view(np.int64))
                                and np.array_equal(o_w.view(np.int64), o_s.view(np.int64)))
    return bad


def test_streamed_answers_are_the_whole_trajectorys_bit_for_bit(cell):
    s, _, paths = cell
    for path in paths:
        assert _mismatches(s, path) == 0, path.name


def _mutant(monkeypatch, name: str, old: str, new: str):
    return mutant_module.mutated_module(name, "spec/_trajectory.py", [(old, new)],
                                        lambda n, m: monkeypatch.setitem(sys.modules, n, m))


def test_seeded_fault_a_long_gaps_carried_speed_dropped_is_caught(cell, monkeypatch):
    s, _, paths = cell
    mutant = _mutant(monkeypatch, "no_carry", "            over[0] = np.maximum(over[0], carry)",
                     "            pass")
    assert _mismatches(s, paths[1], mutant) > 0


def test_seeded_fault_the_window_trimmed_a_row_too_far_is_caught(cell, monkeypatch):
    s, _, paths = cell
    mutant = _mutant(monkeypatch, "trim", 'side="right")) - 1, n - 2), 0))',
                     'side="right")), n - 2), 0))')
    assert _mismatches(s, paths[1], mutant) > 0


def test_a_trajectory_changed_between_the_readings_is_bad_input(cell, tmp_path, monkeypatch):
    s, _, paths = cell
    path = tmp_path / "t.csv"
    text = paths[1].read_text()
    path.write_text(text)
    info, _, _ = certify_trajectory_file(path, s)
    lines = text.splitlines(keepends=True)
    changed = "".join(lines[:5] + [lines[5].replace(",", ",1", 1)] + lines[6:])

    def finish(new_text: str) -> str | None:
        path.write_text(new_text)
        ref = _streamed(s, path, info, 8, 4)
        ref.block(float(ref.span[0]), np.array([float(ref.span[0]) + 1e-3]))
        try:
            ref.finish()
        except InputError as exc:
            return exc.render()
        return None

    assert finish(text) is None
    assert "changed while it was read" in (finish(changed) or "")
    assert "changed while it was read" in (finish("".join(lines[:-1])) or "")
    # Seeded fault: a finish that reads the rest but checks nothing lets the change through.
    monkeypatch.setattr(tr.StreamedReference, "finish", lambda self: None)
    assert finish(changed) is None


def test_monitor_has_no_byte_limit_and_a_row_budget(cell, tmp_path, capsys, monkeypatch):
    s, scen, paths = cell
    path = paths[1]
    traj = load_trajectory(path, s)
    log = tmp_path / "log.csv"
    log.write_bytes(log_csv(*simulate_log(traj, samples=500, noise=1e-4, seed=9)))
    out = tmp_path / "m.json"
    args = ["monitor", str(scen), "--traj", str(path), "--log", str(log), "--json", str(out)]
    rc = main(args)
    want = json.loads(out.read_text())
    monkeypatch.setenv("CFMPA_MAX_TRAJECTORY_BYTES", "100")         # far below the file
    out.unlink()
    assert main(args) == rc and rc in (0, 1)
    got = json.loads(out.read_text())
    assert {k: v for k, v in got.items() if k != "timings_s"} == {
        k: v for k, v in want.items() if k != "timings_s"}
    capsys.readouterr()
    monkeypatch.setenv("CFMPA_MAX_TRAJECTORY_ROWS", str(traj.rows - 1))
    out.unlink()
    assert main(args) == 2 and not out.exists()
    err = capsys.readouterr().err
    assert err.startswith(f"{path}:{traj.rows + 1}: error: trajectory has more than "
                          f"{traj.rows - 1:,} rows") and err.count("\n") == 1


def test_a_trajectory_that_cannot_be_read_twice_is_refused(cell, tmp_path, capsys):
    s, scen, paths = cell
    fifo = tmp_path / "traj.csv"
    os.mkfifo(fifo)                  # never opened: refused by what it is, before any read
    log = tmp_path / "log.csv"
    log.write_text(H + "0,0.3,0.8,3.3,0.5\n")
    assert main(["monitor", str(scen), "--traj", str(fifo), "--log", str(log)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--traj" in err and "reads the trajectory twice" in err
    # A second reading that gives no rows at all is the file changed, not an IndexError.
    info, _, _ = certify_trajectory_file(paths[1], s)
    ref = tr.StreamedReference(iter([]), info, window_rows=8)
    with pytest.raises(InputError) as e:
        ref.block(0.0, np.array([1.0]))
    assert "changed while it was read" in e.value.render()


def test_a_json_trajectory_is_monitored_as_its_csv(cell, tmp_path):
    s, scen, paths = cell
    traj = load_trajectory(paths[1], s)
    js = tmp_path / "gen.json"
    js.write_text(json.dumps({"t": traj.t.tolist(), **{c: traj.angles[:, i].tolist()
                                                     for i, c in enumerate(tr.JOINTS)}}))
    log = tmp_path / "log.csv"
    log.write_bytes(log_csv(*simulate_log(traj, samples=120, noise=1e-3, seed=4)))
    docs = []
    for path in (paths[1], js):
        out = tmp_path / f"{path.name}.out.json"
        rc = main(["monitor", str(scen), "--traj", str(path), "--log", str(log), "--json",
                   str(out)])
        doc = json.loads(out.read_text())
        doc.pop("timings_s")
        docs.append((rc, doc))
    (rc_a, a), (rc_b, b) = docs
    assert a.pop("trajectory") != b.pop("trajectory")
    assert rc_a == rc_b and a == b and a["samples"] == 120
