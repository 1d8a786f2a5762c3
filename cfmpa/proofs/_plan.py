"""`cfmpa plan`: BuiltDR, searchoptpath and the certificate, written as DESIGN §9's files.

Output is deterministic: the same scenario bytes, variant and version give byte-identical JSON
apart from the ``timings_s`` object.
"""

from __future__ import annotations

import platform
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from .. import __version__
from .._io import dumps_json, save_npy_atomic, write_bytes_atomic
from ..impl import build_dr, search_opt_path
from ..spec import Grid, Scenario, Variant, make_grid
from ..spec._certificate import Certificate, certificate_json, certify
from ..spec._paths import SearchResult, SearchStatus

__all__ = ["PlanResult", "plan", "plan_json", "write_plan", "versions"]


@dataclass(frozen=True)
class PlanResult:
    """One planning run: the grid, D_R, the search's answer, the certificate and the timings."""

    scenario: Scenario
    variant: Variant
    grid: Grid
    dr: npt.NDArray[np.uint8]
    search: SearchResult
    certificate: Certificate | None
    contracts: dict[str, Any] | None
    timings_s: dict[str, float] = field(default_factory=dict)

    @property
    def free_fraction(self) -> float:
        return 1.0 - float(self.dr.mean())


def versions() -> dict[str, str]:
    """Versions that can change an answer: the tool, Python, numpy, shapely, Z3."""
    import shapely
    import z3

    return {"cfmpa": __version__, "python": platform.python_version(), "numpy": np.__version__,
            "shapely": shapely.__version__, "z3": z3.get_version_string()}


def plan(s: Scenario, variant: Variant | str, *, contracts: str = "off", seed: int = 0,
         sample: int | None = None) -> PlanResult:
    """Plan the subordinate's path for ``variant`` (no contracts: mode 'off')."""
    v = Variant(variant)
    g = make_grid(s)
    t: dict[str, float] = {}
    t0 = time.perf_counter()
    dr = build_dr(s, v, g)
    t["build_dr"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    result = search_opt_path(dr, s.right.start_cell, s.right.goal_cell)
    t["search"] = time.perf_counter() - t0
    cert = None
    if result.status is SearchStatus.FOUND:
        t0 = time.perf_counter()
        cert = certify(s, g, result.path)
        t["certificate"] = time.perf_counter() - t0
    return PlanResult(scenario=s, variant=v, grid=g, dr=dr, search=result, certificate=cert,
                      contracts=None, timings_s=t)


def plan_json(p: PlanResult) -> dict[str, Any]:
    """The plan.json document of DESIGN §9 (keys are stable: add, never rename)."""
    r = p.search
    found = r.status is SearchStatus.FOUND
    g = p.grid
    return {
        "scenario": p.scenario.name,
        "scenario_sha256": p.scenario.sha256,
        "variant": p.variant.value,
        "grid": {"N": g.N, "m": g.m, "n": g.n, "dt": g.dt, "Tf": g.Tf, "lo": list(g.lo),
                 "h": list(g.h)},
        "status": r.status.value,
        "reason": r.reason,
        "path": [list(c) for c in r.path],
        "angles": [list(g.angles(c)) for c in r.path],
        "J1": r.J1 if found else None,
        "J2": r.J2 if found else None,
        "path_length": len(r.path),
        "free_fraction": p.free_fraction,
        "clearance": certificate_json(p.certificate) if p.certificate is not None else None,
        "contracts": p.contracts,
        "timings_s": {k: round(v, 6) for k, v in sorted(p.timings_s.items())},
        "versions": versions(),
    }


def write_plan(p: PlanResult, out: str | Path) -> tuple[Path, Path]:
    """Write DIR/dr.npy and DIR/plan.json, each atomically (temporary name, then rename)."""
    out = Path(out)
    dr_path = save_npy_atomic(out / "dr.npy", p.dr)
    plan_path = write_bytes_atomic(out / "plan.json", dumps_json(plan_json(p)).encode())
    return dr_path, plan_path
