"""`cfmpa compare`: the paper's experimental claim (Section IV.B), measured on random workcells.

Each workcell i of a campaign is drawn from ``numpy.random.default_rng([seed, i])``, so a
campaign is reproducible from its seed and a smaller campaign is a prefix of a larger one.
A workcell: the principal's base at the origin; the subordinate's base at a distance of 0.35 to
0.85 times the sum of both reaches (so the reach disks always overlap), within 0.3 rad of the +x
axis; links 0.25-0.40 m, widths 0.04-0.07 m, joint speeds 0.8-1.5 rad/s; the principal turns
each joint by 0.4-1.8 rad either way; the subordinate's joint 1 spans [0, 2 pi], joint 2
[-2.6, 2.6]; dt = COMPARE_DT (a coarse grid, so a campaign of 100 takes seconds). The
subordinate's start (goal) cell is drawn uniformly among cells whose pose is apart from the
principal's start (goal) pose, as a real task would be; after MAX_DRAWS failed draws the last one
is kept (and counted). Every workcell is planned under the three variants; every found path gets
the continuous-time certificate.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..files import dumps_json, write_bytes_atomic
from ..errors import InputError
from ..spec import (EPS, Scenario, SearchStatus, Variant, arm_corners, certify, make_grid,
                    parse_scenario, polygon_distance)

__all__ = ["COMPARE_DT", "CONTACT_NOTE", "MAX_DRAWS", "Campaign", "CaseResult", "VariantOutcome",
           "random_workcell", "run_campaign", "campaign_json", "format_campaign", "run_compare"]

#: Time step of campaign workcells (s): grids of about 10-30 layers of 60-80 x 50-65 cells.
COMPARE_DT = 0.1
#: Draws of a start or goal cell before the campaign keeps a pose in contact (then counted).
MAX_DRAWS = 200
#: Appended to a workcell's purpose when a pose was kept in contact after MAX_DRAWS draws.
CONTACT_NOTE = "(a pose drawn in contact)"
_TWO_PI = 6.283185307179586


@dataclass(frozen=True)
class VariantOutcome:
    """One variant's plan of one workcell: status, costs, free fraction, certificate, times."""

    variant: Variant
    status: str
    reason: str | None
    J1: int | None
    J2: int | None
    free_fraction: float
    certified_clear: bool | None   # None: no path to certify
    min_clearance_m: float | None
    seconds: float
    path: tuple[tuple[int, int], ...] = ()


@dataclass(frozen=True)
class CaseResult:
    """One random workcell planned under all three variants."""

    index: int
    shape: tuple[int, int, int]
    poses_apart: bool              # start and goal poses drawn apart (not after MAX_DRAWS)
    outcomes: tuple[VariantOutcome, ...]

    def outcome(self, v: Variant) -> VariantOutcome:
        return next(o for o in self.outcomes if o.variant is v)

    def found(self, v: Variant) -> bool:
        return self.outcome(v).status == SearchStatus.FOUND.value


@dataclass(frozen=True)
class Campaign:
    """A seeded campaign: its cases and the kernel that built D_R."""

    n: int
    seed: int
    dt: float
    kernel: str
    cases: tuple[CaseResult, ...]


def random_workcell(seed: int, index: int) -> Scenario:
    """Workcell ``index`` of the campaign with ``seed`` (see the module docstring); its purpose
    ends with CONTACT_NOTE when a start or goal pose had to be kept in contact."""
    return _workcell(seed, index)[0]


def _workcell(seed: int, index: int) -> tuple[Scenario, bool]:
    """The workcell, and whether its start and goal poses were drawn apart from the principal."""
    rng = np.random.default_rng([seed, index])

    def arm() -> dict[str, Any]:
        return {"links": [_r(rng.uniform(0.25, 0.40)), _r(rng.uniform(0.25, 0.40))],
                "width": _r(rng.uniform(0.04, 0.07)),
                "omega": [_r(rng.uniform(0.8, 1.5)), _r(rng.uniform(0.8, 1.5))]}

    left, right = arm(), arm()
    start = [_r(rng.uniform(-math.pi, math.pi)), _r(rng.uniform(-2.4, 2.4))]
    goal = [_r(a + rng.choice([-1.0, 1.0]) * rng.uniform(0.4, 1.8)) for a in start]
    reach = sum(left["links"]) + sum(right["links"])
    d, phi = rng.uniform(0.35, 0.85) * reach, rng.uniform(-0.3, 0.3)
    doc: dict[str, Any] = {
        "name": f"random-{seed}-{index}",
        "purpose": f"cfmpa compare workcell {index} of seed {seed}",
        "dt": COMPARE_DT,
        "left": {"base": [0.0, 0.0], **left, "start": start, "goal": goal},
        "right": {"base": [_r(d * math.cos(phi)), _r(d * math.sin(phi))], **right,
                  "limits": [[0.0, _TWO_PI], [-2.6, 2.6]],
                  "start_cell": [0, 0], "goal_cell": [0, 0]},
    }
    s = parse_scenario(doc, check_budget=False)
    g = make_grid(s)
    apart = True
    for key, pose in (("start_cell", start), ("goal_cell", goal)):
        cell, ok = _draw_cell(rng, s, g, pose)
        apart &= ok
        doc["right"][key] = list(cell)
    if not apart:
        doc["purpose"] += f" {CONTACT_NOTE}"
    return parse_scenario(doc, check_budget=False), apart


def run_campaign(n: int = 100, seed: int = 0) -> Campaign:
    """Plan ``n`` random workcells under original, modified and tight."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InputError("--n", n, "must be an integer >= 1")
    build, search, kernel = _kernels()
    cases = []
    for i in range(n):
        s, apart = _workcell(seed, i)
        g = make_grid(s)
        outcomes = []
        for v in Variant:
            t0 = time.perf_counter()
            dr = build(s, v, g)
            r = search(dr, s.right.start_cell, s.right.goal_cell)
            cert = certify(s, g, r.path) if r.status is SearchStatus.FOUND else None
            outcomes.append(VariantOutcome(
                variant=v, status=r.status.value, reason=r.reason, J1=r.J1, J2=r.J2,
                free_fraction=1.0 - float(dr.mean()),
                certified_clear=None if cert is None else cert.clear,
                min_clearance_m=None if cert is None else cert.min_clearance_m,
                seconds=time.perf_counter() - t0, path=r.path))
        cases.append(CaseResult(index=i, shape=g.shape, poses_apart=apart,
                                outcomes=tuple(outcomes)))
    return Campaign(n=n, seed=seed, dt=COMPARE_DT, kernel=kernel, cases=tuple(cases))


def campaign_json(c: Campaign) -> dict[str, Any]:
    """The campaign as JSON: the table per variant, the cross-variant counts and checks, the cases.

    Checks (each must count 0; the corrected Property 8 and the certificate predict it): modified
    fails where original succeeds; tight fails where modified succeeds; a variant's optimum
    (J1, J2) exceeds a looser variant's; a found path not certified clear.
    """
    O, M, T = Variant.ORIGINAL, Variant.MODIFIED, Variant.TIGHT
    all_found = [x for x in c.cases if all(x.found(v) for v in Variant)]
    rows = []
    for v in Variant:
        outs = [x.outcome(v) for x in c.cases]
        found = [o for o in outs if o.status == SearchStatus.FOUND.value]
        rows.append({
            "variant": v.value,
            "found": len(found),
            "success_rate": len(found) / c.n,
            "mean_free_fraction": _mean([o.free_fraction for o in outs]),
            "mean_J1_all_found": _mean([x.outcome(v).J1 for x in all_found]),
            "mean_J2_all_found": _mean([x.outcome(v).J2 for x in all_found]),
            "no_path_reasons": _count(o.reason for o in outs if o.reason is not None),
            "mean_seconds": _mean([o.seconds for o in outs]),
        })

    def worse(a: Variant, b: Variant) -> int:      # a's optimum worse than the looser b's
        return sum(1 for x in all_found
                   if (x.outcome(a).J1, x.outcome(a).J2) > (x.outcome(b).J1, x.outcome(b).J2))

    checks = {
        "modified_fails_original_succeeds": sum(1 for x in c.cases
                                                if x.found(O) and not x.found(M)),
        "tight_fails_modified_succeeds": sum(1 for x in c.cases if x.found(M) and not x.found(T)),
        "modified_optimum_worse_than_original": worse(M, O),
        "tight_optimum_worse_than_modified": worse(T, M),
        "found_path_not_certified_clear": sum(1 for x in c.cases for o in x.outcomes
                                              if o.certified_clear is False),
    }
    return {
        "n": c.n,
        "seed": c.seed,
        "dt": c.dt,
        "kernel": c.kernel,
        "table": rows,
        "all_found": len(all_found),
        "original_fails_modified_succeeds": sum(1 for x in c.cases
                                                if x.found(M) and not x.found(O)),
        "original_fails_tight_succeeds": sum(1 for x in c.cases if x.found(T) and not x.found(O)),
        "none_found": sum(1 for x in c.cases if not any(x.found(v) for v in Variant)),
        "poses_in_contact": sum(1 for x in c.cases if not x.poses_apart),
        "mean_cells": _mean([float(np.prod(x.shape)) for x in c.cases]),
        "checks": checks,
        "checks_ok": not any(checks.values()),
        "cases": [{"index": x.index, "shape": list(x.shape), "poses_apart": x.poses_apart,
                   "outcomes": {o.variant.value: {
                       "status": o.status, "reason": o.reason, "J1": o.J1, "J2": o.J2,
                       "free_fraction": o.free_fraction, "certified_clear": o.certified_clear,
                       "min_clearance_m": o.min_clearance_m} for o in x.outcomes}}
                  for x in c.cases],
    }


def format_campaign(doc: dict[str, Any]) -> str:
    """The campaign's table and counts as plain text (what `cfmpa compare` prints)."""
    lines = [f"campaign  {doc['n']} random workcells, seed {doc['seed']}, dt {doc['dt']} s, "
             f"kernels {doc['kernel']}; mean grid {doc['mean_cells']:.0f} cells",
             f"{'variant':<10}{'found':>7}{'success':>9}{'free':>9}{'mean J1':>10}{'mean J2':>10}"
             f"   (J1, J2: mean over the {doc['all_found']} workcells all variants solve)"]
    for r in doc["table"]:
        lines.append(f"{r['variant']:<10}{r['found']:>7}{r['success_rate']:>9.1%}"
                     f"{r['mean_free_fraction']:>9.1%}{_num(r['mean_J1_all_found']):>10}"
                     f"{_num(r['mean_J2_all_found']):>10}")
    lines.append(f"original fails, modified succeeds: {doc['original_fails_modified_succeeds']} "
                 f"of {doc['n']}  (tight succeeds: {doc['original_fails_tight_succeeds']}; "
                 f"no variant succeeds: {doc['none_found']})")
    bad = {k: v for k, v in doc["checks"].items() if v}
    lines.append("checks    " + ("all hold: " if not bad else "FAILED: ")
                 + ", ".join(f"{k} = {v}" for k, v in (bad or doc["checks"]).items()))
    return "\n".join(lines)


def run_compare(n: int = 100, seed: int = 0, out: str | None = None) -> int:
    """Run a campaign, print its table; write ``out``/compare.json when ``out`` is given.

    Exit code 0 when every check of ``campaign_json`` counts 0, else 1.
    """
    doc = campaign_json(run_campaign(n, seed))
    print(format_campaign(doc))
    if out is not None:
        from pathlib import Path
        path = write_bytes_atomic(Path(out) / "compare.json", dumps_json(doc).encode())
        print(f"wrote     {path}")
    return 0 if doc["checks_ok"] else 1


def _kernels() -> tuple[Any, Any, str]:
    """(build, search, label): the fast kernels, quiet (their output is the reference's, which
    their own tests check)."""
    from ..impl import kernels
    build, search = kernels("fast")
    return (lambda s, v, g: build(s, v, g, progress=False),
            lambda dr, a, b: search(dr, a, b, progress=False),
            "build_dr_fast + search_opt_path_fast")


def _draw_cell(rng: np.random.Generator, s: Scenario, g: Any, left_pose: list[float]
               ) -> tuple[tuple[int, int], bool]:
    """A uniformly drawn cell whose pose is apart from the principal at ``left_pose``."""
    left = arm_corners(s.left, (left_pose[0], left_pose[1]))
    cell = (0, 0)
    for _ in range(MAX_DRAWS):
        cell = (int(rng.integers(g.m)), int(rng.integers(g.n)))
        right = arm_corners(s.right, g.angles(cell))
        if min(polygon_distance(a, b) for a in left for b in right) > EPS:
            return cell, True
    return cell, False


def _r(x: float) -> float:
    # Four decimals: readable workcells; the validated scenario is what is planned either way.
    return round(float(x), 4)


def _mean(xs: Any) -> float | None:
    xs = [float(x) for x in xs]
    return sum(xs) / len(xs) if xs else None


def _count(xs: Any) -> dict[str, int]:
    out: dict[str, int] = {}
    for x in xs:
        out[x] = out.get(x, 0) + 1
    return dict(sorted(out.items()))


def _num(x: float | None) -> str:
    return "-" if x is None else f"{x:.1f}"
