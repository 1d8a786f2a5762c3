"""What the bundled scenarios exist to show: the paper's is_path flaw, its Section IV.B claim,
and that the optimum never worsens from original to modified to tight."""

from __future__ import annotations

import dataclasses
import re
from functools import cache
from pathlib import Path

import pytest

from cfmpa import cli
from cfmpa.impl import build_dr_fast, search_opt_path
from cfmpa.spec import Variant, load_scenario, make_grid
from cfmpa.spec._certificate import certify
from cfmpa.spec._paths import J1, J2, SearchStatus, is_path, is_path_paper, path_violations

ROOT = Path(__file__).resolve().parents[1] / "scenarios"
SCENARIOS = sorted(p.stem for p in ROOT.glob("*.toml"))
ORDER = (Variant.ORIGINAL, Variant.MODIFIED, Variant.TIGHT)


@cache
def planned(name: str, variant: Variant):
    s = load_scenario(ROOT / f"{name}.toml")
    g = make_grid(s)
    # The fast kernel: bit-identical to the reference build_dr on every bundled workcell and
    # variant (tests/impl/test_fast_builtdr.py; the default workcell's under the slow marker),
    # and a tenth of its time on the tool workcells.
    dr = build_dr_fast(s, variant, g, progress=False)
    return s, g, dr, search_opt_path(dr, s.right.start_cell, s.right.goal_cell)


def test_early_arrival_path_passes_the_papers_is_path_but_collides():
    s, g, dr, best = planned("early-arrival", Variant.MODIFIED)
    start, goal = s.right.start_cell, s.right.goal_cell
    # The shortest list: straight along theta1 to the goal, arriving at step 4 of N = 41.
    early = [(start[0] + k, start[1]) for k in range(goal[0] - start[0] + 1)]
    assert len(early) < g.N
    assert is_path_paper(early, dr, start, goal)
    # Definition 4's clause at k = LENGTH - 1 involves L_{LENGTH}, unspecified in HOL4; where it
    # applies it checks the goal at the list's last step, free here: the early path passes
    # under every reading of that element that lets any list reach this goal.
    assert dr[len(early) - 1][goal] == 0
    assert not is_path(early, dr, start, goal)
    first = path_violations(early, dr, start, goal)[0]
    assert first.clause == "blocked" and first.cell == goal and first.step >= len(early)
    # Executed (waiting at the goal after the list ends), the arms really touch.
    cert = certify(s, g, early)
    assert not cert.clear and cert.contact is not None
    assert cert.contact[0] > (len(early) - 1) * g.dt  # after the list ended
    # The fixed search goes around and waits elsewhere; its motion is certified clear.
    assert best.status is SearchStatus.FOUND
    assert is_path(best.path, dr, start, goal)
    assert (best.J1, best.J2) > (J1(early), J2(early))
    assert certify(s, g, best.path).clear


def test_original_finds_no_path_where_modified_finds_one():
    _, _, _, orig = planned("original-fails", Variant.ORIGINAL)
    _, _, dr, mod = planned("original-fails", Variant.MODIFIED)
    assert orig.status is SearchStatus.NO_PATH
    assert orig.reason == "goal blocked in the rest layer"
    assert mod.status is SearchStatus.FOUND


@pytest.mark.parametrize("name", SCENARIOS)
def test_optimum_never_worsens_from_original_to_modified_to_tight(name):
    results = [planned(name, v) for v in ORDER]
    costs = [(r.J1, r.J2) for *_, r in results if r.status is SearchStatus.FOUND]
    found = [r.status is SearchStatus.FOUND for *_, r in results]
    # Once a variant finds a path, every less conservative one does too.
    assert found == sorted(found)
    assert costs == sorted(costs, reverse=True)
    # A path valid under a variant stays valid under every less conservative one: original's
    # under modified and tight, modified's under tight. Where a variant finds no path (original
    # on original-fails) there is no path to carry over and that part checks nothing; every
    # bundled scenario still carries at least one path over.
    s = results[0][0]
    carried = 0
    for k, (_, _, _, r) in enumerate(results):
        if r.status is SearchStatus.FOUND:
            for _, _, dr, _ in results[k + 1:]:
                assert is_path(r.path, dr, s.right.start_cell, s.right.goal_cell)
                carried += 1
    assert carried >= 1


@pytest.mark.parametrize("name", SCENARIOS)
def test_found_paths_are_valid_and_certified(name):
    for v in ORDER:
        s, g, dr, r = planned(name, v)
        if r.status is SearchStatus.FOUND:
            assert is_path(r.path, dr, s.right.start_cell, s.right.goal_cell)
            assert (J1(r.path), J2(r.path)) == (r.J1, r.J2)
            assert certify(s, g, r.path).clear


# --- tools and heights (docs/model.md §2, "Tools and heights") --------------------------------


def _without(s, key):
    """The workcell ``s`` with ``key`` ("tool" or "z") left out of both arms: what a user who
    could not write it would have planned."""
    return dataclasses.replace(s, left=dataclasses.replace(s.left, **{key: None}),
                               right=dataclasses.replace(s.right, **{key: None}))


@pytest.mark.parametrize("variant", ORDER, ids=str)
def test_gripper_a_plan_made_without_the_tools_collides_through_them(variant):
    s, g, _, best = planned("gripper", variant)
    assert best.status is SearchStatus.FOUND and certify(s, g, best.path).clear
    planar = _without(s, "tool")
    # The fast kernel (bit-identical to the reference: tests/impl/test_fast_builtdr.py).
    blind = search_opt_path(build_dr_fast(planar, variant, g, progress=False), s.right.start_cell,
                            s.right.goal_cell)
    assert blind.status is SearchStatus.FOUND
    assert certify(planar, g, blind.path).clear          # safe for arms that carry nothing
    cert = certify(s, g, blind.path)                      # but the real arms carry tools
    assert not cert.clear and cert.contact is not None
    assert 3 in cert.contact[1]                           # part 3: a tool is in the contact


def test_gripper_cfmpa_certify_with_the_tools_finds_the_contact_of_a_plan_without(tmp_path, capsys):
    text = (ROOT / "gripper.toml").read_text()
    blind = tmp_path / "blind.toml"
    blind.write_text(re.sub(r"\n\[(left|right)\.tool\][^\n]*\npolygon = [^\n]*\n", "\n", text))
    planar = load_scenario(blind)
    assert planar.left.tool is None and planar.right.tool is None
    assert cli.main(["plan", str(blind), "--out", str(tmp_path / "plan")]) == 0
    capsys.readouterr()
    code = cli.main(["certify", "gripper", "--traj", str(tmp_path / "plan" / "traj.csv"),
                     "--json", str(tmp_path / "cert.json")])
    got = capsys.readouterr()
    out = got.out + got.err
    assert code == 1
    assert "NOT CLEAR: contact at" in out and "left tool and right tool" in out
    # The contact's angles as a person reads them: rad with degrees (docs/contributing.md).
    line = next(x for x in out.splitlines() if "NOT CLEAR" in x)
    assert re.search(r"left angles -?[\d.]+ rad \(-?[\d.]+ deg\), -?[\d.]+ rad \(-?[\d.]+ deg\); "
                     r"right angles -?[\d.]+ rad \(", line), line


def test_levels_heights_shorten_the_plan():
    for variant in ORDER:
        s, g, dr, best = planned("levels", variant)
        flat = _without(s, "z")
        flat_dr = build_dr_fast(flat, variant, g, progress=False)   # = the reference's
        flat_best = search_opt_path(flat_dr, s.right.start_cell, s.right.goal_cell)
        assert best.status is SearchStatus.FOUND and flat_best.status is SearchStatus.FOUND
        # The subordinate no longer waits for the principal's forearm: J1 drops to the
        # Manhattan distance, and fewer cells are blocked.
        assert (best.J1, best.J2) < (flat_best.J1, flat_best.J2)
        assert best.J1 == abs(s.right.goal_cell[0] - s.right.start_cell[0]) + abs(
            s.right.goal_cell[1] - s.right.start_cell[1])
        assert 0 < dr.sum() < flat_dr.sum()
        assert certify(s, g, best.path).clear
        # Planned with the heights, the motion touches in the plane (the forearms cross above
        # one another): without the heights it would not be clear.
        assert not certify(flat, g, best.path).clear


@pytest.mark.parametrize("name", ["gripper", "levels"])
def test_tool_and_height_workcells_plan_in_every_variant_with_full_contracts(name):
    from cfmpa.runs._plan import plan

    s = load_scenario(ROOT / f"{name}.toml")
    for v in ORDER:
        r = plan(s, v, contracts="full")       # raises on any violation
        assert r.search.status is SearchStatus.FOUND
        assert r.certificate is not None and r.certificate.clear
        assert r.exact is not None and r.exact.ok
        assert r.contracts["violations"] == [] and r.checked > 6_000_000
