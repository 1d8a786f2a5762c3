"""The four findings about the paper, recomputed on concrete data for the report (no drawing here).

Each finding is shown on a bundled scenario, so the reader can rerun it: the naive hull on
``default``'s principal, the two-sided box (the inconsistency) and the literal Property 8 on
``original-fails``, the is_path flaw on ``early-arrival``. A finding whose data does not show
what the text claims says so (``reproduced`` False) instead of printing the claim.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt
import shapely

from ..impl import left_regions_fast, link_rectangles, naive_hull, right_regions_fast, swept_region
from ..spec import (
    EPS,
    Grid,
    Scenario,
    Variant,
    certify,
    is_path_paper,
    left_angles,
    left_box,
    path_violations,
    polygon_distance,
    trajectory_distances,
)

__all__ = [
    "Finding",
    "NaiveHullData",
    "InconsistencyData",
    "Prop8Data",
    "EarlyArrivalData",
    "PlanLike",
    "naive_hull_finding",
    "inconsistency_finding",
    "prop8_finding",
    "early_arrival_finding",
    "sample_clearance",
    "right_angles_at",
]

Polygon = npt.NDArray[np.float64]
Cell = tuple[int, int]

#: Size of the illustrative box of the naive-hull finding, per joint (rad): large enough that the
#: protrusion shows in a drawing; the scenario's own box size is measured as well.
NAIVE_BOX_RAD = 0.8
#: Configurations per joint sampled in a box when measuring how far the link leaves a region.
NAIVE_SAMPLES = 33


@dataclass(frozen=True)
class Finding:
    """A finding about the paper: a title, 2-3 sentences with the measured numbers, the ids of
    the related obligations (prefixes), JSON-safe data, and whether the data reproduced it."""

    id: str
    title: str
    text: str
    related: tuple[str, ...]
    reproduced: bool
    data: dict[str, Any]
    drawing: Any = field(default=None, compare=False, repr=False)


class PlanLike(Protocol):
    """What a finding needs of a plan (``PlanResult`` of cfmpa.proofs has it)."""

    grid: Grid
    dr: npt.NDArray[np.uint8]
    search: Any


PlanFn = Callable[[Scenario, Variant], PlanLike]


# --- naive hull ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class NaiveHullData:
    """The link over a box: naive hull, sound region, sampled rectangles, the worst protrusion."""

    arm: Any
    link: int
    box: tuple[tuple[float, float], tuple[float, float]]
    naive: Polygon
    sound: Polygon
    samples: npt.NDArray[np.float64]       # (S, 4, 2) rectangles at sampled configurations
    worst_rect: Polygon
    worst_point: tuple[float, float]
    protrusion_m: float


def naive_hull_finding(s: Scenario) -> Finding:
    """The hull of the link at the box's corner configurations misses the link in between."""
    arm, link = s.left, 1
    a = s.left.start
    box = ((a[0], a[0] + NAIVE_BOX_RAD), (a[1], a[1] + NAIVE_BOX_RAD))
    big = _protrusion(arm, link, box)
    own_box = left_box(s, Variant.ORIGINAL, 0)
    own = _protrusion(arm, link, own_box)
    # The sound construction on the same box: lattice anchored at the box's low corner.
    spacing = (NAIVE_BOX_RAD / 8, NAIVE_BOX_RAD / 8)
    sound = swept_region(arm, link, box, (box[0][0], box[1][0]), spacing)
    outside_sound = _outside(sound, big["samples"])
    reproduced = big["protrusion"] > 0 and own["protrusion"] > 0 and outside_sound <= 0.0
    text = (f"The paper's region is the convex hull of the link at the corners of the joint box; "
            f"a link turning about a joint bulges past that hull in between. For the principal of "
            f"{s.name}, link 2 over a {NAIVE_BOX_RAD} rad x {NAIVE_BOX_RAD} rad box leaves the "
            f"naive hull by {big['protrusion'] * 1000:.1f} mm, and even over the scenario's own "
            f"layer-0 box (±{s.left.omega[0] * s.dt:g} rad) by "
            f"{own['protrusion'] * 1e6:.2f} µm, so "
            f"a cell it calls free can collide. The project's sound region (lattice hull plus the "
            f"margin δ) contains every sampled pose"
            + ("." if outside_sound <= 0.0 else f" except one {outside_sound:.2e} m outside."))
    drawing = NaiveHullData(arm=arm, link=link, box=box, naive=naive_hull(arm, link, box),
                            sound=sound, samples=big["samples"], worst_rect=big["worst_rect"],
                            worst_point=big["worst_point"], protrusion_m=big["protrusion"])
    return Finding(
        id="naive_hull", title="The naive hull of the end configurations is unsound",
        text=text, related=("Margin.naive_hull", "Lemma.sweep_margin", "Margin.arc_chord"),
        reproduced=reproduced,
        data={"scenario": s.name, "link": link + 1, "box_rad": [list(b) for b in box],
              "protrusion_m": big["protrusion"], "own_box_rad": [list(b) for b in own_box],
              "own_box_protrusion_m": own["protrusion"], "sound_region_worst_outside_m":
              outside_sound, "samples_per_joint": NAIVE_SAMPLES},
        drawing=drawing)


def _protrusion(arm: Any, link: int, box: Any) -> dict[str, Any]:
    t1 = np.linspace(box[0][0], box[0][1], NAIVE_SAMPLES)
    t2 = np.linspace(box[1][0], box[1][1], NAIVE_SAMPLES)
    T1, T2 = np.meshgrid(t1, t2, indexing="ij")
    rects = link_rectangles(arm, T1.ravel(), T2.ravel(), link)          # (S, 4, 2)
    hull = shapely.Polygon(naive_hull(arm, link, box))
    pts = shapely.points(rects.reshape(-1, 2))
    d = shapely.distance(hull, pts).reshape(len(rects), 4)
    k = int(np.argmax(d.max(axis=1)))
    c = int(np.argmax(d[k]))
    return {"samples": rects, "protrusion": float(d.max()), "worst_rect": rects[k],
            "worst_point": (float(rects[k, c, 0]), float(rects[k, c, 1]))}


def _outside(region: Polygon, rects: npt.NDArray[np.float64]) -> float:
    """Largest distance of a sampled rectangle corner from the region (0: all inside)."""
    poly = shapely.Polygon(region)
    return float(shapely.distance(poly, shapely.points(rects.reshape(-1, 2))).max())


# --- the inconsistency: two-sided vs one-sided box ----------------------------------------------

@dataclass(frozen=True)
class InconsistencyData:
    """The principal's boxes and regions at the last motion layer; the subordinate at its goal."""

    scenario: Scenario
    grid: Grid
    layer: int
    boxes: dict[Variant, Any]
    regions: dict[Variant, tuple[Polygon, ...]]     # link 1, link 2[, tool] (spec.parts)
    theta_now: tuple[float, float]
    theta_next: tuple[float, float]
    right_goal: tuple[float, float]
    right_region: tuple[Polygon, Polygon]
    distances_m: dict[Variant, float]
    goal_blocked: dict[Variant, bool]


def inconsistency_finding(s: Scenario, plan: PlanFn) -> Finding:
    """Algorithm 1's two-sided box against the one-sided (modified) and planned (tight) ones."""
    plans = {v: plan(s, v) for v in Variant}
    g = plans[Variant.ORIGINAL].grid
    k = g.N - 1
    regs = {v: _left_links(s, v, g)[k] for v in Variant}
    goal = s.right.goal_cell
    rr = _right_regions(s, g)
    right = (rr.link1[goal[0]], rr.link2[goal[0], goal[1]])     # the goal cell's region
    dist = {v: _gap(regs[v], right) for v in Variant}
    blocked = {v: bool(plans[v].dr[g.N, goal[0], goal[1]]) for v in Variant}
    r_o, r_m = plans[Variant.ORIGINAL].search, plans[Variant.MODIFIED].search
    reproduced = (blocked[Variant.ORIGINAL] and not blocked[Variant.MODIFIED]
                  and r_o.J1 is None and r_m.J1 is not None)
    areas = {v: sum(shapely.Polygon(p).area for p in regs[v]) for v in Variant}
    w = s.left.omega
    text = (f"Algorithm 1 lets each principal joint turn either way by ω Δt in the next step "
            f"(box [θ − ωΔt, θ + ωΔt]), although the principal's motion is planned and its "
            f"direction known; the paper's modified box [θ, θ + sωΔt] is one quadrant of it, "
            f"and "
            f"the tight box is the planned interval itself. In {s.name}, at the last layer "
            f"(k = {k}, boxes {2 * w[0] * s.dt:g} x {2 * w[1] * s.dt:g} rad against "
            f"{w[0] * s.dt:g} x {w[1] * s.dt:g} rad) the two-sided region "
            + ("reaches the subordinate's region at its goal cell, so the goal is blocked in the "
               f"rest layer and original finds no path, while the one-sided region misses it by "
               f"{dist[Variant.MODIFIED] * 1000:.1f} mm and modified plans a path "
               f"(J1 = {r_m.J1}, J2 = {r_m.J2})." if reproduced else
               "does not show the expected difference on this data (see the numbers)."))
    drawing = InconsistencyData(
        scenario=s, grid=g, layer=k, boxes={v: left_box(s, v, k) for v in Variant}, regions=regs,
        theta_now=_pair(left_angles(s, k * s.dt)), theta_next=_pair(left_angles(s, (k + 1) * s.dt)),
        right_goal=g.angles(goal), right_region=right, distances_m=dist, goal_blocked=blocked)
    return Finding(
        id="inconsistency",
        title="The semantic inconsistency: a two-sided box for a known direction",
        text=text, reproduced=reproduced,
        related=("Thm1.builtdr", "Thm3.builtdr", "Prop8.subset_monotone", "Prop8.path_exists"),
        data={"scenario": s.name, "layer": k, "goal_cell": list(goal),
              "region_area_m2": {v.value: areas[v] for v in Variant},
              "goal_distance_m": {v.value: dist[v] for v in Variant},
              "goal_blocked_in_rest_layer": {v.value: blocked[v] for v in Variant},
              "status": {v.value: plans[v].search.status.value for v in Variant}},
        drawing=drawing)


# --- Property 8 as printed ----------------------------------------------------------------------

@dataclass(frozen=True)
class Prop8Data:
    """A cell blocked under S (original), free under S' (modified): both regions, the cell's."""

    scenario: Scenario
    grid: Grid
    layer: int
    cell: Cell
    region_s: tuple[Polygon, ...]           # link 1, link 2[, tool] (spec.parts)
    region_s_prime: tuple[Polygon, ...]
    right_region: tuple[Polygon, Polygon]
    theta_left: tuple[float, float]
    theta_right: tuple[float, float]
    gap_s_m: float
    gap_s_prime_m: float


def prop8_finding(s: Scenario, plan: PlanFn) -> Finding:
    """A counterexample to Property 8 as printed, taken from the computed tables of a scenario."""
    po, pm = plan(s, Variant.ORIGINAL), plan(s, Variant.MODIFIED)
    g = po.grid
    diff = (po.dr[: g.N] == 1) & (pm.dr[: g.N] == 0)        # Property 8 quantifies k < N
    total = int(diff.sum())
    worse = int(((pm.dr == 1) & (po.dr == 0)).sum())    # P' > P anywhere would refute P' <= P
    if total == 0:
        return Finding(id="prop8_literal", title="Property 8 as printed does not hold",
                       text=(f"On {s.name} no cell is blocked under S and free under S'; the "
                             f"counterexample is not reproduced on this data."),
                       related=("Prop8.",), reproduced=False,
                       data={"scenario": s.name, "cells_free_only_under_s_prime": 0,
                             "cells_blocked_only_under_s_prime": worse})
    per_layer = diff.reshape(g.N, -1).sum(axis=1)
    k = int(np.argmax(per_layer))
    cells = np.argwhere(diff[k])
    step = max(1, len(cells) // 400)                         # a deterministic subsample
    cand = cells[::step]
    rr = _right_regions(s, g)
    lo = _left_links(s, Variant.ORIGINAL, g)[k]
    lm = _left_links(s, Variant.MODIFIED, g)[k]
    # The candidate farthest from S' (the first of equals): shapely's distances, batched, pick
    # the few within GAP_SLACK_M of the farthest, whose exact distances (_gap) decide as before.
    near = _gaps(lm, rr.link1[cand[:, 0]], rr.link2[cand[:, 0], cand[:, 1]])
    picked = np.flatnonzero(near >= near.max() - GAP_SLACK_M)
    gaps = [_gap(lm, (rr.link1[i], rr.link2[i, j])) for i, j in cand[picked]]
    best = int(picked[int(np.argmax(gaps))])
    i, j = (int(x) for x in cand[best])
    right = (rr.link1[i], rr.link2[i, j])
    gap_s, gap_sp = _gap(lo, right), _gap(lm, right)
    reproduced = gap_s <= EPS < gap_sp and worse == 0
    text = (f"Property 8 as printed says that if P is the table of S (P = 0 iff S ∩ S_R = ∅) "
            f"then P is also the table of the smaller S'. In {s.name} at layer k = {k}, "
            f"cell ({i}, {j}), "
            f"S meets the subordinate's region (P = 1) but S' stays {gap_sp * 1000:.1f} mm away, "
            f"so the table of S' has 0 there and P is not it; {total} cells of layers 0..{g.N - 1} "
            f"are like this one. What S' ⊆ S does give is P' ≤ P cell by cell, which the "
            f"corrected chain proves (no cell here has P' > P: {worse}).")
    drawing = Prop8Data(scenario=s, grid=g, layer=k, cell=(i, j), region_s=lo, region_s_prime=lm,
                        right_region=right, theta_left=_pair(left_angles(s, k * s.dt)),
                        theta_right=g.angles((i, j)), gap_s_m=gap_s, gap_s_prime_m=gap_sp)
    return Finding(
        id="prop8_literal", title="Property 8 as printed does not hold", text=text,
        related=("Prop8.",), reproduced=reproduced,
        data={"scenario": s.name, "layer": k, "cell": [i, j], "gap_s_m": gap_s,
              "gap_s_prime_m": gap_sp, "cells_free_only_under_s_prime": total,
              "cells_blocked_only_under_s_prime": worse},
        drawing=drawing)


def _gap(left: tuple[Polygon, ...], right: tuple[Polygon, Polygon]) -> float:
    return min(polygon_distance(a, b) for a in left for b in right)


#: How far below the largest batched distance a candidate's may be and still have its exact
#: distance compared (m): shapely's and polygon_distance's agree to far better than this.
GAP_SLACK_M = 1e-9


def _gaps(left: tuple[Polygon, ...], link1: npt.NDArray[np.float64],
          link2: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """``_gap(left, (link1[c], link2[c]))`` for every candidate c, as shapely computes it."""
    rights = [shapely.polygons(np.asarray(r, dtype=float)) for r in (link1, link2)]
    return np.min([shapely.distance(shapely.Polygon(np.asarray(a, dtype=float)), r)
                   for a in left for r in rights], axis=0)


@functools.lru_cache(maxsize=4)
def _left_links(s: Scenario, v: Variant, g: Grid) -> tuple[tuple[Polygon, ...], ...]:
    """The principal's regions per layer (impl's compiled left_regions, the same polygons),
    computed once for the two findings on one scenario."""
    return left_regions_fast(s, v, g).links


@functools.lru_cache(maxsize=1)
def _right_regions(s: Scenario, g: Grid) -> Any:
    """The subordinate's regions per cell (impl's compiled right_regions, the same arrays),
    computed once for the two findings on one scenario."""
    return right_regions_fast(s, g)


# --- is_path: the early arrival ---------------------------------------------------------------

@dataclass(frozen=True)
class EarlyArrivalData:
    """The early path, the instant of contact while waiting, and the fixed optimum."""

    scenario: Scenario
    grid: Grid
    path: tuple[Cell, ...]
    contact_t_s: float | None
    optimal_path: tuple[Cell, ...]
    times_s: npt.NDArray[np.float64]
    clearance_m: npt.NDArray[np.float64]
    optimal_times_s: npt.NDArray[np.float64]
    optimal_clearance_m: npt.NDArray[np.float64]


def early_arrival_finding(s: Scenario, plan: PlanFn) -> Finding:
    """The shortest list passes the paper's is_path, then collides while waiting at its goal."""
    p = plan(s, Variant.MODIFIED)
    g, dr = p.grid, p.dr
    path = _straight(s.right.start_cell, s.right.goal_cell)
    paper_ok = is_path_paper(path, dr, s.right.start_cell, s.right.goal_cell)
    bad = path_violations(path, dr, s.right.start_cell, s.right.goal_cell)
    cert = certify(s, g, path)
    t, d = sample_clearance(s, g, path)
    contact = cert.contact[0] if cert.contact is not None else None
    opt = p.search
    reproduced = paper_ok and bool(bad) and contact is not None and opt.J1 is not None
    first = bad[0] if bad else None
    text = (f"The paper's is_path checks the cells of the list only, for steps k < LENGTH(L); "
            f"after the list ends the subordinate holds its goal while the principal still moves. "
            f"In {s.name} the {len(path)}-cell straight path reaches the goal at "
            f"t = {(len(path) - 1) * s.dt:g} s and passes the printed is_path"
            + (f", but the principal sweeps through the waiting arm (in contact at t = "
               f"{contact:.3f} s); the fixed is_path rejects it ({first}; {len(bad)} blocked steps "
               f"in all). The optimal path under the fixed "
               f"definition goes around: J1 = {opt.J1}, J2 = {opt.J2}." if reproduced else
               f": is_path (printed) = {paper_ok}, violations of the fixed one = {len(bad)}, "
               f"contact = {contact}; the flaw is not reproduced on this data."))
    ot, od = sample_clearance(s, g, opt.path) if opt.path else (np.zeros(0), np.zeros(0))
    drawing = EarlyArrivalData(scenario=s, grid=g, path=tuple(path), contact_t_s=contact,
                               optimal_path=tuple(opt.path), times_s=t, clearance_m=d,
                               optimal_times_s=ot, optimal_clearance_m=od)
    return Finding(
        id="is_path_flaw", title="The printed is_path admits a path that collides after it ends",
        text=text, related=("Def4.", "Prop4.rest_free"), reproduced=reproduced,
        data={"scenario": s.name, "path": [list(c) for c in path],
              "is_path_printed": paper_ok, "fixed_violations": len(bad),
              "first_violation": None if first is None else str(first),
              "contact_t_s": contact, "optimal_J1": opt.J1, "optimal_J2": opt.J2},
        drawing=drawing)


def _straight(a: Cell, b: Cell) -> list[Cell]:
    """The shortest list of one-step moves from a to b (diagonal first, then straight)."""
    out = [tuple(a)]
    i, j = a
    while (i, j) != tuple(b):
        i += int(np.sign(b[0] - i))
        j += int(np.sign(b[1] - j))
        out.append((i, j))
    return out  # type: ignore[return-value]


# --- the executed motion, sampled ---------------------------------------------------------------

def sample_clearance(s: Scenario, g: Grid, path: Any, per_step: int = 16
                     ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Times and the arms' distance (m) along the executed motion (docs/model.md §7), ``per_step``
    per dt: the least over every pair of parts, tools and heights included
    (``spec.trajectory_distances``, the certificate's own distances).

    A picture, not a proof: the certificate bounds the distance between samples.
    """
    cells = np.asarray(path, dtype=np.int64).reshape(-1, 2)
    t_end = max((len(cells) - 1) * s.dt, g.Tf)
    steps = max(1, math.ceil(t_end / s.dt - 1e-12))
    t = np.linspace(0.0, steps * s.dt, steps * per_step + 1)
    t = t[t <= t_end + 1e-12]
    angles = np.concatenate([left_angles(s, t), right_angles_at(g, cells, t)], axis=1)
    return t, trajectory_distances(s, angles).min(axis=(1, 2))


def _pair(a: Any) -> tuple[float, float]:
    return (float(a[0]), float(a[1]))


# --- pure numpy -----------------------------------------------------------------------------


def right_angles_at(g: Grid, cells: npt.NDArray[np.int64], t: npt.NDArray[np.float64]
                  ) -> npt.NDArray[np.float64]:
    """The subordinate's joint angles at times t: linear between cells, one per dt, then held."""
    ang = np.stack([g.lo[0] + cells[:, 0] * g.h[0], g.lo[1] + cells[:, 1] * g.h[1]], axis=1)
    u = t / g.dt
    k = np.minimum(np.floor(u).astype(np.int64), len(ang) - 1)
    nxt = np.minimum(k + 1, len(ang) - 1)
    frac = np.clip(u - k, 0.0, 1.0)[:, None]
    return ang[k] + frac * (ang[nxt] - ang[k])
