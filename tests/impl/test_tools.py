"""Tools and heights in BuiltDR (docs/model.md §2, "Tools and heights"; §4): the fast kernel gives
the reference's D_R bit for bit with random convex tools and height intervals, and sampled true
configurations of both arms (tools included, heights as prisms) in the free cells of D_R never
touch; three seeded faults are caught by that sampling: D_R built without the tool, a tool
vertex left out of its region, and heights compared with ``<`` where ``<=`` is meant."""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.impl import _kinematics as impl_kinematics
from cfmpa.impl import build_dr, right_regions
from cfmpa.impl._fast_builtdr import build_dr_fast
from cfmpa.spec import (
    Variant,
    _kinematics,
    left_box,
    load_scenario,
    make_grid,
    pairs_to_test,
    parse_scenario,
    right_box,
)
from cfmpa.spec._certificate import link_rects
from cfmpa.spec._polygon import polygon_distances
from dr_strategies import random_workcells

ROOT = Path(__file__).resolve().parents[2]
BUNDLED = ROOT / "tests" / "data" / "tools-heights.toml"


def coarse(dt: float = 0.08, **edits: object) -> dict:
    """The bundled tools-heights workcell as a document at a coarser time step (cells rescaled),
    with ``edits`` ("right.tool" -> None deletes it; "left.z" -> value sets it)."""
    doc = tomllib.loads(BUNDLED.read_text())
    doc["dt"] = dt
    scale = 0.02 / dt
    for key in ("start_cell", "goal_cell"):
        doc["right"][key] = [int(c * scale) for c in doc["right"][key]]
    for path, value in edits.items():
        side, key = path.split(".", 1)
        table = doc[side]
        *head, last = key.split(".")
        for h in head:
            table = table[h]
        if value is None:
            table.pop(last, None)
        else:
            table[last] = value
    return doc


def assert_same(s, variant):
    g = make_grid(s)
    rr = right_regions(s, g)
    ref = build_dr(s, variant, g, right=rr)
    fast = build_dr_fast(s, variant, g, right=rr, progress=False)
    diff = np.argwhere(fast != ref)
    assert diff.size == 0, f"{len(diff)} cells differ, first (k, i, j) = {diff[:5].tolist()}"
    return ref


def true_contacts(s, variant, dr, *, samples: int, seed: int = 0) -> int:
    """How many of ``samples`` configurations, drawn uniformly in random free cells of layers
    0..N-1 (the principal anywhere in the layer's box, the subordinate anywhere in the cell's),
    put two parts at overlapping heights within a hair of each other (3-D distance <= 1e-12 m,
    spec geometry: ``link_rects``, ``polygon_distances``, heights by their gap)."""
    g = make_grid(s)
    rng = np.random.default_rng(seed)
    free = np.argwhere(dr[:g.N] == 0)
    pick = free[rng.integers(len(free), size=samples)]
    la = np.empty((samples, 2))
    ra = np.empty((samples, 2))
    for n, (k, i, j) in enumerate(pick):
        lb, rb = left_box(s, variant, int(k)), right_box(g, (int(i), int(j)))
        la[n] = [rng.uniform(*lb[0]), rng.uniform(*lb[1])]
        ra[n] = [rng.uniform(*rb[0]), rng.uniform(*rb[1])]
    planar = polygon_distances(link_rects(s.left, la)[:, :, None], link_rects(s.right, ra)[:, None, :])
    gap = np.array([[_kinematics.height_gap(_kinematics.part_height(s.left, a),
                                            _kinematics.part_height(s.right, b))
                     for b in _kinematics.parts(s.right)] for a in _kinematics.parts(s.left)])
    d = np.where(gap > 0, np.hypot(planar, gap), planar)
    return int((d.reshape(samples, -1).min(axis=1) <= 1e-12).sum())


# --- the bundled workcell -------------------------------------------------------------------


def test_the_bundled_workcell_tests_three_pairs_of_parts():
    s = load_scenario(BUNDLED)
    assert s.left.tool is not None and s.right.tool is not None
    # docs/model.md §2's example: the left forearm and probe against the right upper arm, and
    # the two tools; every other pair is at disjoint heights.
    assert pairs_to_test(s.left, s.right) == ((1, 0), (2, 0), (2, 2))


@pytest.mark.parametrize("variant", list(Variant), ids=str)
def test_sampled_true_configurations_in_free_cells_do_not_touch(variant):
    s = load_scenario(BUNDLED)
    dr = build_dr_fast(s, variant, progress=False)
    assert 0 < dr.mean() < 1
    assert true_contacts(s, variant, dr, samples=20000) == 0


@pytest.mark.parametrize("variant", list(Variant), ids=str)
def test_fast_and_reference_agree_on_the_coarse_bundled_workcell(variant):
    ref = assert_same(parse_scenario(coarse(), check_budget=False), variant)
    assert 0 < ref.mean() < 1


# --- random tools and heights ---------------------------------------------------------------


@settings(max_examples=30, deadline=None)
@given(s=random_workcells(dts=(0.125, 0.2, 0.25), tools=True), variant=st.sampled_from(list(Variant)))
def test_bit_identical_with_random_tools_and_heights(s, variant):
    ref = assert_same(s, variant)
    if (ref[:-1] == 0).any():
        assert true_contacts(s, variant, ref, samples=300) == 0


# --- seeded faults the sampling catches -----------------------------------------------------


def test_fault_dr_without_the_tool_is_caught():
    s = parse_scenario(coarse(), check_budget=False)
    planar = dataclasses.replace(s, right=dataclasses.replace(s.right, tool=None))
    dr = build_dr_fast(planar, Variant.MODIFIED, progress=False)
    assert true_contacts(s, Variant.MODIFIED, dr, samples=20000) > 0
    assert true_contacts(s, Variant.MODIFIED, build_dr_fast(s, Variant.MODIFIED, progress=False),
                         samples=20000) == 0


def test_fault_a_tool_vertex_left_out_is_caught(monkeypatch):
    s = parse_scenario(coarse(), check_budget=False)
    real = impl_kinematics.part_polygons

    def drop_a_vertex(arm, t1, t2, elbow, grow):
        if arm.tool is None:
            return real(arm, t1, t2, elbow, grow)
        # The gripper's first vertex (its back right corner) left out of the region.
        shorter = dataclasses.replace(arm, tool=dataclasses.replace(arm.tool,
                                                                    polygon=arm.tool.polygon[1:]))
        return real(shorter, t1, t2, elbow, grow)

    monkeypatch.setattr(impl_kinematics, "part_polygons", drop_a_vertex)
    dr = build_dr(s, Variant.MODIFIED)
    assert true_contacts(s, Variant.MODIFIED, dr, samples=20000) > 0


def test_fault_heights_compared_with_less_than_is_caught(monkeypatch):
    # The only pair that can touch is the left tool (z 0.1-0.2) and the right links (z 0.2-0.3):
    # they share the height 0.2 exactly.
    doc = coarse(**{"left.z": [[0.5, 0.6], [0.5, 0.6]], "left.tool.z": [0.1, 0.2],
                    "right.z": [[0.2, 0.3], [0.2, 0.3]], "right.tool": None})
    s = parse_scenario(doc, check_budget=False)
    assert pairs_to_test(s.left, s.right) == ((2, 0), (2, 1))
    dr = build_dr_fast(s, Variant.MODIFIED, progress=False)
    assert true_contacts(s, Variant.MODIFIED, dr, samples=20000) == 0
    monkeypatch.setattr(_kinematics, "heights_overlap",
                        lambda a, b: a is None or b is None or (a[0] < b[1] and b[0] < a[1]))
    assert pairs_to_test(s.left, s.right) == ()
    dr = build_dr_fast(s, Variant.MODIFIED, progress=False)
    assert true_contacts(s, Variant.MODIFIED, dr, samples=20000) > 0


# --- the certificate with tools and heights, at random instants ----------------------------


def below_the_bound(s, g, path, bound: float, *, instants: int = 400) -> int:
    """How many random instants of the executed motion put two parts closer than ``bound``
    (true 3-D distance, ``pose_distance``). The motion is written out independently: the
    principal's PTP motion, the subordinate linear between its path's cells, one per dt, then
    at rest."""
    from cfmpa.spec import left_angles, pose_distance

    cells = np.array(path, dtype=float)
    angles = np.stack([g.lo[0] + cells[:, 0] * g.h[0], g.lo[1] + cells[:, 1] * g.h[1]], axis=1)
    times = np.arange(len(cells)) * s.dt
    rng = np.random.default_rng(3)
    below = 0
    for t in rng.uniform(0.0, max(times[-1], float(g.Tf)), instants):
        right = (float(np.interp(t, times, angles[:, 0])), float(np.interp(t, times, angles[:, 1])))
        below += pose_distance(s, tuple(left_angles(s, t)), right) < bound - 1e-12
    return below


def planned_modified(name: str):
    from cfmpa.impl import search_opt_path

    s = load_scenario(ROOT / "scenarios" / f"{name}.toml")
    g = make_grid(s)
    best = search_opt_path(build_dr_fast(s, Variant.MODIFIED, g, progress=False),
                           s.right.start_cell, s.right.goal_cell)
    return s, g, best.path


@pytest.mark.parametrize("name", ["gripper", "levels"])
def test_the_certified_lower_bound_holds_at_random_instants(name):
    from cfmpa.spec import certify

    s, g, path = planned_modified(name)
    cert = certify(s, g, path)
    assert cert.clear and cert.lower_bound_m > 0
    assert below_the_bound(s, g, path, cert.lower_bound_m) == 0


def test_fault_a_certificate_without_the_tools_is_caught():
    from cfmpa.spec import certify

    s, g, path = planned_modified("gripper")
    planar = dataclasses.replace(s, left=dataclasses.replace(s.left, tool=None),
                                 right=dataclasses.replace(s.right, tool=None))
    assert below_the_bound(s, g, path, certify(planar, g, path).lower_bound_m) > 0
