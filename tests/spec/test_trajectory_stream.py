"""Streaming certify (docs/model.md §12): `cfmpa certify` reads a CSV trajectory a part
of CHUNK_ROWS rows at a time and certifies each as it comes. Up to CHUNK_ROWS rows the result is
the one-piece-list certificate of the whole loaded trajectory, byte for byte (JSON, exit code,
messages); in smaller parts the verdict, the contact and every error stay the same; no part holds
more than its rows and the one carried over. Seeded faults: parts without the carried row, a row
offset off by one, a validation failure raised where it is found."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

import factory
from cfmpa.cli import main
from cfmpa.errors import InputError
from cfmpa.runs import certify_json
from cfmpa.scenarios import BUNDLED_DIR
from cfmpa.spec import (
    CHUNK_ROWS,
    Trajectory,
    certify_trajectory,
    certify_trajectory_file,
    load_scenario,
    load_trajectory,
    trajectory_csv,
)
from cfmpa.spec import _trajectory as tr
from cfmpa.spec._certificate import prove_motion

START, GOAL = [2, 8], [13, 5]
H = "t,left1,left2,right1,right2\n"


@pytest.fixture(scope="module")
def workcell(tmp_path_factory):
    return factory.planned(tmp_path_factory.mktemp("stream"), factory.doc(
        right__start_cell=START, right__goal_cell=GOAL))


def _whole(s, path: Path, allow_speed: bool = False) -> dict:
    """The certificate as before streaming: the whole trajectory loaded, one list of pieces."""
    traj = load_trajectory(path, s, allow_speed=allow_speed)
    cert = prove_motion(tr._TrajectoryMotion(s, traj), first_contact=True)
    doc = certify_json(s, traj, cert, None, None)
    doc["trajectory"].pop("sha256")
    doc.pop("timings_s")
    return doc


def _streamed(s, path: Path, chunk_rows: int = CHUNK_ROWS, allow_speed: bool = False) -> dict:
    info, cert, _ = certify_trajectory_file(path, s, chunk_rows=chunk_rows,
                                            allow_speed=allow_speed)
    doc = certify_json(s, info, cert, None, None)
    doc["trajectory"].pop("sha256")
    doc.pop("timings_s")
    return doc


def _cli(scen, path: Path, out: Path) -> tuple[int, str, str, dict | None]:
    o, e = io.StringIO(), io.StringIO()
    out.unlink(missing_ok=True)
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        rc = main(["certify", str(scen), "--traj", str(path), "--json", str(out)])
    doc = json.loads(out.read_text()) if out.exists() else None
    return rc, o.getvalue(), e.getvalue(), doc


def _random(s, n: int, seed: int, sweep: tuple[float, float]) -> Trajectory:
    """A slow random walk of both arms, the subordinate's first joint sweeping ``sweep``."""
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.3, 0.6, n))
    a = np.zeros((n, 4))
    a[:, 0] = s.left.start[0] + np.cumsum(rng.uniform(-0.05, 0.05, n))
    a[:, 1] = s.left.start[1] + np.cumsum(rng.uniform(-0.05, 0.05, n))
    a[:, 2] = np.linspace(*sweep, n) + rng.uniform(-0.05, 0.05, n)
    a[:, 3] = 1.0 + np.cumsum(rng.uniform(-0.05, 0.05, n))
    return Trajectory(t, a)


def _sweep(s, n: int) -> Trajectory:
    """At rest, then the subordinate sweeps into the principal (a contact) in ``n`` rows."""
    t = np.concatenate([[0.0], np.linspace(2.0, 12.0, n - 1)])
    a = np.tile([0.3, 0.8, 3.3, 0.5], (n, 1))
    a[1:, 2] = np.linspace(3.3, 1.2, n - 1)
    return Trajectory(t, a)


def _cases(s, folder: Path, plan_traj: Path) -> list[Path]:
    out = [plan_traj]
    for name, traj in (("random", _random(s, 300, 1, (2.5, 4.5))),
                       ("random2", _random(s, 60, 2, (0.5, 2.0))),
                       ("sweep", _sweep(s, 41))):
        p = folder / f"{name}.csv"
        p.write_text(trajectory_csv(traj))
        out.append(p)
    one = folder / "one.csv"
    one.write_text(H + "0,0.3,0.8,3.3,0.5\n")
    js = folder / "sweep.json"
    sw = _sweep(s, 9)
    js.write_text(json.dumps({"t": sw.t.tolist(), **{c: sw.angles[:, i].tolist()
                                                   for i, c in enumerate(tr.JOINTS)}}))
    return [*out, one, js]


def test_streamed_certify_is_the_whole_trajectory_certificate(workcell, tmp_path):
    s, scen, plan_dir, _ = workcell
    kinds = set()
    for path in _cases(s, tmp_path, plan_dir / "traj.csv"):
        whole = _whole(s, path)
        assert _streamed(s, path) == whole, path.name
        rc, out, err, doc = _cli(scen, path, tmp_path / "c.json")
        doc.pop("timings_s")
        doc["trajectory"].pop("sha256")
        assert doc == whole and rc == (0 if whole["clear"] else 1)
        assert f"{whole['trajectory']['rows']} rows" in out
        kinds.add("contact" if whole["contact"] else "clear" if whole["clear"] else "undecided")
    assert kinds == {"contact", "clear"}          # both verdicts are compared


@pytest.mark.slow
def test_streamed_certify_of_the_bundled_plans(tmp_path):
    from cfmpa.runs import plan, write_plan
    for name in ("default", "narrow-gap"):
        s = load_scenario(BUNDLED_DIR / f"{name}.toml")
        res = plan(s, "modified", contracts="off")
        write_plan(res, tmp_path / name)
        path = tmp_path / name / "traj.csv"
        assert _streamed(s, path) == _whole(s, path), name


def test_the_file_hash_is_of_its_bytes(workcell):
    import hashlib
    s, _, plan_dir, _ = workcell
    path = plan_dir / "traj.csv"
    _, _, sha = certify_trajectory_file(path, s)
    assert sha == hashlib.sha256(path.read_bytes()).hexdigest()


def _invariants(s, path: Path, chunks=(2, 3, 7, 64)) -> list[str]:
    """What must not depend on the part size: the verdict, the rows and span, the contact
    (instant, links, row, line, angles) and the proved bound never above the sampled minimum."""
    ref = _streamed(s, path)
    bad = []
    for c in chunks:
        got = _streamed(s, path, chunk_rows=c)
        for key in ("clear", "contact", "trajectory"):
            if got[key] != ref[key]:
                bad.append(f"chunk {c}: {key} {got[key]} != {ref[key]}")
        if got["lower_bound_m"] > got["min_m"]:
            bad.append(f"chunk {c}: lower bound above the sampled minimum")
    return bad


def test_small_parts_give_the_same_verdict_and_contact(workcell, tmp_path):
    s, _, plan_dir, _ = workcell
    for path in _cases(s, tmp_path, plan_dir / "traj.csv"):
        assert _invariants(s, path) == [], path.name
    # in memory as from the file
    traj = load_trajectory(tmp_path / "sweep.csv", s)
    assert certify_trajectory(s, traj, chunk_rows=3) == certify_trajectory_file(
        tmp_path / "sweep.csv", s, chunk_rows=3)[1]


def test_a_contact_on_the_piece_between_two_parts(workcell, tmp_path):
    """Rows 0-3 at rest far off, then one long sweep into the principal between rows 3 and 4:
    with parts of 4 rows that piece is the carried row's."""
    s, _, _, _ = workcell
    p = tmp_path / "edge.csv"
    p.write_text(H + "0,0.3,0.8,3.3,0.5\n1,0.3,0.8,3.3,0.5\n2,0.3,0.8,3.3,0.5\n"
                 "3,0.3,0.8,3.3,0.5\n13,0.3,0.8,1.2,0.5\n14,0.3,0.8,1.2,0.5\n")
    got = _streamed(s, p, chunk_rows=4)
    assert got["contact"] is not None and got["contact"]["row"] == 3
    assert got["contact"]["line"] == 5 and _invariants(s, p, chunks=(2, 3, 4, 5)) == []


def test_seeded_fault_parts_without_the_carried_row_are_caught(workcell, tmp_path, monkeypatch):
    s, _, _, _ = workcell
    p = tmp_path / "edge.csv"
    p.write_text(H + "0,0.3,0.8,3.3,0.5\n1,0.3,0.8,3.3,0.5\n2,0.3,0.8,3.3,0.5\n"
                 "3,0.3,0.8,3.3,0.5\n13,0.3,0.8,1.2,0.5\n14,0.3,0.8,1.2,0.5\n")
    real = tr._row_parts

    def dropped(*args, **kw):
        for n, (part, offset) in enumerate(real(*args, **kw)):
            yield (part, offset) if n == 0 else (Trajectory(part.t[1:], part.angles[1:],
                                                            part.source, part.lines[1:]),
                                                 offset + 1)
    monkeypatch.setattr(tr, "_row_parts", dropped)
    assert _invariants(s, p, chunks=(4,)) != []


def test_seeded_fault_a_row_offset_off_by_one_is_caught(workcell, tmp_path, monkeypatch):
    s, _, _, _ = workcell
    p = tmp_path / "sweep.csv"
    p.write_text(trajectory_csv(_sweep(s, 41)))
    real = tr._row_parts
    monkeypatch.setattr(tr, "_row_parts", lambda *a, **k: ((part, offset + (offset > 0))
                                                           for part, offset in real(*a, **k)))
    assert _invariants(s, p) != []


def _error(s, path: Path, chunk_rows: int) -> str:
    with pytest.raises(InputError) as exc:
        certify_trajectory_file(path, s, chunk_rows=chunk_rows)
    return str(exc.value)


#: Bad files whose first failure in file order is not the one reported: validate's order (times,
#: then right1's and right2's limits, then speeds) and parse failures before any of them.
BAD = {
    "speed_then_parse": H + "0,0.3,0.8,3.3,0.5\n1,0.3,0.8,1.2,0.5\n2,0.3,0.8,1.2,0.5\n"
                        "3,0.3,0.8,1.2,x\n",
    "limit_then_t": H + "0,0.3,0.8,7.3,0.5\n1,0.3,0.8,3.2,0.5\n2,0.3,0.8,3.2,0.5\n"
                    "1.5,0.3,0.8,3.2,0.5\n",
    "limit2_then_limit1": H + "0,0.3,0.8,3.3,-0.5\n1,0.3,0.8,3.3,0.5\n2,0.3,0.8,3.3,0.5\n"
                          "3,0.3,0.8,-1,0.5\n",
    "speed_across_parts": H + "0,0.3,0.8,3.3,0.5\n1,0.3,0.8,3.3,0.5\n2,0.3,0.8,3.3,0.5\n"
                          "3,0.3,0.8,3.3,2.5\n",
    "t_across_parts": H + "0,0.3,0.8,3.3,0.5\n1,0.3,0.8,3.3,0.5\n2,0.3,0.8,3.3,0.5\n"
                      "2,0.3,0.8,3.3,0.5\n",
    "blank_inside": H + "0,0.3,0.8,3.3,0.5\n1,0.3,0.8,3.3,0.5\n\n2,0.3,0.8,3.3,0.5\n",
    "header_only": H,
}


def test_errors_are_the_loaders_in_any_part_size(workcell, tmp_path):
    s, scen, _, _ = workcell
    for name, text in BAD.items():
        p = tmp_path / f"{name}.csv"
        p.write_text(text)
        with pytest.raises(InputError) as exc:
            load_trajectory(p, s)
        want = str(exc.value)
        assert {_error(s, p, c) for c in (2, 3, CHUNK_ROWS)} == {want}, name
        rc, out, err, doc = _cli(scen, p, tmp_path / "c.json")
        assert rc == 2 and doc is None and want in err, name


def test_seeded_fault_a_failure_raised_where_found_is_caught(workcell, tmp_path, monkeypatch):
    s, _, _, _ = workcell
    p = tmp_path / "limit_then_t.csv"
    p.write_text(BAD["limit_then_t"])
    want = _error(s, p, 2)
    real = tr._Checks.add

    def eager(self, *a, **k):
        real(self, *a, **k)
        self.raise_first()
    monkeypatch.setattr(tr._Checks, "add", eager)
    assert _error(s, p, 2) != want


def test_no_part_holds_more_than_its_rows_and_the_carried_one(workcell, tmp_path, monkeypatch):
    s, _, _, _ = workcell
    p = tmp_path / "random.csv"
    p.write_text(trajectory_csv(_random(s, 300, 1, (2.5, 4.5))))
    seen: list[tuple[int, int]] = []
    real = tr._Certifier.add

    def spy(self, part, offset):
        seen.append((offset, part.rows))
        real(self, part, offset)
    monkeypatch.setattr(tr._Certifier, "add", spy)
    certify_trajectory_file(p, s, chunk_rows=16)
    assert max(n for _, n in seen) <= 17 and seen[0] == (0, 16)
    # contiguous: each part starts at the previous one's last row, and the last ends at row 299
    assert all(o == po + pn - 1 for (po, pn), (o, _) in zip(seen, seen[1:]))
    assert seen[-1][0] + seen[-1][1] == 300


def _ends_mismatch(motion) -> bool:
    t0, t1, seg, _ = motion.pieces()
    d0, d1 = motion.end_distances(t0, t1, seg)
    want0, want1 = motion.distances(t0, seg), motion.distances(t1, seg)
    return not (np.array_equal(d0.view(np.int64), want0.view(np.int64))
                and np.array_equal(d1.view(np.int64), want1.view(np.int64)))


def test_end_distances_are_the_two_distance_calls_bit_for_bit(workcell):
    s, _, _, _ = workcell
    rng = np.random.default_rng(3)      # angles of very different sizes: a0 + (a1 - a0) != a1
    a = rng.uniform(0, 6, (400, 4)) * 10.0 ** rng.uniform(-6, 0, (400, 4))
    traj = Trajectory(np.arange(400.0), a)
    m = tr._TrajectoryMotion(s, traj)
    t0, t1, seg, _ = m.pieces()
    a0, a1 = m.angles(t0, seg), m.angles(t1, seg)
    shared = np.all(a1[:-1] == a0[1:], axis=1)
    assert shared.any() and not shared.all()      # both branches: copied and computed
    assert not _ends_mismatch(m)
    assert not _ends_mismatch(tr._TrajectoryMotion(s, Trajectory(traj.t[:1], traj.angles[:1])))


def test_seeded_fault_end_distances_copied_from_the_wrong_piece_is_caught(workcell):
    s, _, _, _ = workcell

    class Shifted(tr._TrajectoryMotion):
        def end_distances(self, t0, t1, seg):
            d0, d1 = super().end_distances(t0, t1, seg)
            return d0, np.concatenate([d0[:1], d1[:-1]])
    assert _ends_mismatch(Shifted(s, _random(s, 50, 3, (2.5, 4.5))))
