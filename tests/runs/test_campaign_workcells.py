"""The campaign's workcells and runs (runs/_campaign.py): reproducible random workcells, poses
apart, found paths checked by the spec, a recorded campaign read back only when whole."""

from __future__ import annotations

import pytest

from cfmpa.errors import InputError
from cfmpa.impl import build_dr
from cfmpa.report import run_compare
from cfmpa.runs import load_campaign, run_campaign
from cfmpa.runs._campaign import CONTACT_NOTE, random_workcell
from cfmpa.spec import EPS, J1, J2, is_path, make_grid, polygon_distance
from cfmpa.spec._kinematics import arm_corners

SEED = 11


@pytest.fixture(scope="module")
def campaign():
    return run_campaign(6, SEED)


def test_workcells_are_reproducible_from_the_seed():
    a, b = random_workcell(SEED, 2), random_workcell(SEED, 2)
    assert a == b
    assert random_workcell(SEED, 3) != a and random_workcell(SEED + 1, 2) != a


def test_a_smaller_campaign_is_a_prefix_of_a_larger_one(campaign):
    small = run_campaign(2, SEED)
    def strip(c):
        return [(x.index, x.shape, [(o.status, o.J1, o.J2, o.free_fraction, o.path)
                                    for o in x.outcomes]) for x in c.cases]
    assert strip(small) == strip(campaign)[:2]


def test_start_and_goal_poses_are_apart_from_the_principal():
    for i in range(5):
        s = random_workcell(SEED, i)
        g = make_grid(s)
        for cell, pose in ((s.right.start_cell, s.left.start), (s.right.goal_cell, s.left.goal)):
            gap = min(polygon_distance(a, b) for a in arm_corners(s.left, pose)
                      for b in arm_corners(s.right, g.angles(cell)))
            assert gap > EPS or s.purpose.endswith(CONTACT_NOTE)


def test_found_paths_are_valid_on_the_reference_dr_with_their_costs(campaign):
    checked = 0
    for case in campaign.cases[:3]:
        s = random_workcell(SEED, case.index)
        g = make_grid(s)
        for o in case.outcomes:
            if o.status != "found":
                continue
            dr = build_dr(s, o.variant, g)
            assert is_path(o.path, dr, s.right.start_cell, s.right.goal_cell)
            assert (J1(o.path), J2(o.path)) == (o.J1, o.J2)
            assert o.certified_clear is True
            checked += 1
    assert checked > 0


@pytest.mark.parametrize("n", [0, -1, True, 2.5])
def test_campaign_size_must_be_a_positive_integer(n):
    with pytest.raises(InputError, match="--n"):
        run_campaign(n, 0)


def test_a_recorded_campaign_must_be_whole(tmp_path, capsys):
    with pytest.raises(InputError, match="cannot be read"):
        load_campaign(tmp_path / "nowhere")
    for text in ("", '{"format":'):         # empty, or only a torn header: no settings to read
        (tmp_path / "torn").mkdir(exist_ok=True)
        (tmp_path / "torn" / "compare.jsonl").write_text(text)
        with pytest.raises(InputError, match="holds no header"):
            load_campaign(tmp_path / "torn")
    assert run_compare(n=3, seed=SEED, out=str(tmp_path)) == 0
    capsys.readouterr()
    lines = (tmp_path / "compare.jsonl").read_text().splitlines(keepends=True)
    (tmp_path / "compare.jsonl").write_text("".join(lines[:-1]))      # one workcell missing
    with pytest.raises(InputError, match="holds 2 of 3 finished workcells") as exc:
        load_campaign(tmp_path)
    assert f"cfmpa compare --n 3 --seed {SEED}" in str(exc.value)
