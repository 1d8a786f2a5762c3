"""Certificate.wiring, Certificate.pieces and Monitor.reference_speeds (proofs/_obl_wiring.py):
proved on the spec's own code run on terms, and refuted once the code takes the wrong segment,
row or pieces (the faults ``cfmpa selftest --code`` plants)."""

from __future__ import annotations

import inspect
import textwrap

import numpy as np
import pytest
import z3

from cfmpa import spec
from cfmpa.proofs import Verdict, collect_obligations
from cfmpa.proofs._obl_wiring import (
    KEY_GAP,
    KEY_ROW,
    KEY_SEGMENT,
    grid_motion_vcs,
    pieces_failures,
    reference_speed_vcs,
    trajectory_motion_vcs,
    wiring_obligations,
)
from z3answer import answer


def _holds(vc) -> z3.CheckSatResult:
    return answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal)])


def _mutated(cls, name: str, old: str, new: str):
    """A subclass of ``cls`` whose method ``name`` is its source with ``old`` made ``new``."""
    f = getattr(cls, name)
    f = getattr(f, "__func__", f)
    src = textwrap.dedent(inspect.getsource(f))
    assert src.count(old) == 1, old
    ns: dict = {}
    exec(src.replace(old, new), dict(f.__globals__), ns)   # noqa: S102 - the seeded fault
    g = ns[name]            # a static method's source carries its decorator
    return type(f"Mutated{cls.__name__}", (cls,), {name: g})


def test_registered_and_expected_proved():
    ids = {o.id: o for o in collect_obligations(scenarios_dir="/nonexistent")}
    for ob in wiring_obligations():
        assert ids[ob.id].expected is Verdict.PROVED


@pytest.mark.parametrize("build", [grid_motion_vcs, trajectory_motion_vcs, reference_speed_vcs],
                         ids=lambda f: f.__name__)
def test_every_path_is_proved_and_needs_its_key(build):
    vcs = build()
    assert len(vcs) >= 2
    for vc in vcs:
        assert _holds(vc) == z3.unsat, vc.name
        assert answer([h for n, h in vc.hypotheses if n != vc.key_premise]
                      + [z3.Not(vc.goal)]) == z3.sat, (vc.name, vc.key_premise)


def test_the_paths_cover_the_code_s_branches():
    names = [vc.name for vc in grid_motion_vcs()]
    # Tf > 0 or not, a one-cell path, two cells, more: six paths, rates apart where they move.
    assert {n.split(".")[0] for n in names} == {f"grid_path{i}" for i in range(1, 7)}
    assert sum(n.endswith(".motion") for n in names) == 6
    assert {vc.key_premise for vc in reference_speed_vcs()} == {KEY_GAP}
    assert {vc.key_premise for vc in trajectory_motion_vcs()} == {KEY_ROW}
    assert {vc.key_premise for vc in grid_motion_vcs() if vc.name.endswith(".motion")} == {
        KEY_SEGMENT}


def _refuted(vcs) -> list[str]:
    return [vc.name for vc in vcs if _holds(vc) == z3.sat]


def test_the_previous_segment_s_speed_is_refuted():
    bad = _mutated(spec.GridMotion, "lipschitz", "steps[np.maximum(seg, 0)]",
                   "steps[np.maximum(seg - 1, 0)]")
    assert any(n.endswith("right_rate") for n in _refuted(grid_motion_vcs(bad)))


def test_right_angles_on_the_next_segment_is_refuted():
    bad = _mutated(spec.GridMotion, "right_angles", "k = np.maximum(seg, 0)",
                   "k = np.maximum(seg + 1, 0)")
    assert _refuted(grid_motion_vcs(bad))


def test_the_principal_s_speed_on_a_resting_piece_is_refuted():
    # The principal's speed charged only where it rests: wrong on every moving piece.
    bad = _mutated(spec.GridMotion, "lipschitz", "np.where(moving[:, None], left_w[None, :], 0.0)",
                   "np.where(moving[:, None], 0.0, left_w[None, :])")
    assert any(n.endswith("left_rate") for n in _refuted(grid_motion_vcs(bad)))


def test_the_right_arm_s_speeds_for_the_left_arm_are_refuted():
    bad = _mutated(spec.GridMotion, "lipschitz", "vl = link_speeds(s.left, wl)",
                   "vl = link_speeds(s.left, wr)")
    assert _refuted(grid_motion_vcs(bad))


def test_a_trajectory_s_previous_row_is_refuted():
    bad = _mutated(spec.TrajectoryMotion, "lipschitz", "np.maximum(seg - self.offset, 0)",
                   "np.maximum(seg - self.offset - 1, 0)")
    assert _refuted(trajectory_motion_vcs(bad))


def test_a_gap_slice_without_its_last_piece_is_refuted():
    bad = _mutated(spec.ReferenceSpeeds, "over", "self.per_piece[lo[g]:hi[g] + 1]",
                   "self.per_piece[lo[g]:hi[g]]")
    assert _refuted(reference_speed_vcs(bad)) == ["gap_path1"]      # the path of a long gap


def test_speeds_per_piece_shifted_by_a_row_are_refuted():
    bad = _mutated(spec.ReferenceSpeeds, "of", "np.concatenate([zero, inner, zero])",
                   "np.concatenate([inner, zero, zero])")
    assert _refuted(reference_speed_vcs(bad))


def test_a_gap_searched_from_the_wrong_side_is_refuted():
    bad = _mutated(spec.ReferenceSpeeds, "over", 'np.searchsorted(self.t, a, side="right")',
                   'np.searchsorted(self.t, a, side="right") + 1')
    assert _refuted(reference_speed_vcs(bad))


def test_the_pieces_meet_what_the_wiring_assumes_and_a_shifted_segment_does_not():
    assert pieces_failures() == []
    bad = _mutated(spec.GridMotion, "pieces", "seg = np.where(ks < last, ks, -1)",
                   "seg = np.where(ks < last, ks - 1, -1)")
    assert pieces_failures(bad)
    uncut = _mutated(spec.GridMotion, "pieces", "cut = (t0 < tf) & (tf < t1)",
                     "cut = (t0 < tf) & (tf < t0)")
    assert any("straddles" in f for f in pieces_failures(uncut))


def test_the_code_s_own_functions_are_read():
    # A change of the code is a change of the terms: the pinned statement moves with it.
    vcs = grid_motion_vcs()
    other = grid_motion_vcs(_mutated(spec.GridMotion, "lipschitz", "/ self.dt", "/ (2 * self.dt)"))
    assert any(not a.goal.eq(b.goal) for a, b in zip(vcs, other))


def test_the_monitor_speed_is_the_real_one_on_numbers():
    # The statement's speed per piece is the trajectory's: checked against ReferenceSpeeds on
    # a concrete trajectory (rows, pieces and gaps as the VCs name them).
    traj = spec.Trajectory(np.array([0.0, 1.0, 1.5, 3.0]),
                           np.array([[0, 0, 0, 0], [1, 0, 0, 0], [1, 2, 0, 0], [1, 2, 3, 0.0]]))
    ref = spec.ReferenceSpeeds.of(traj)
    for a, b in ((0.2, 2.9), (-1.0, 0.5), (1.2, 1.4), (2.0, 4.0)):
        got = ref.over(np.array([a]), np.array([b]))[0]
        t = traj.t
        want = np.zeros(4)
        for j in range(1, len(t)):
            if t[j - 1] < b and t[j] > a:
                want = np.maximum(want, np.abs(traj.angles[j] - traj.angles[j - 1])
                                  / (t[j] - t[j - 1]))
        assert np.array_equal(got, want), (a, b)
