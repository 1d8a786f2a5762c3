"""Per-scenario obligations: the grids' rounding in exact rationals, and region containment.

For every bundled ``scenarios/*.toml``: N dt >= Tf and h_q <= omega_q dt with the scenario's
floats read as the exact rationals they are (DESIGN §2), and tight ⊆ modified ⊆ original on
the computed polygons of every layer and the rest layer (DESIGN §4, ``impl.check_containment``).
Ids carry the file's stem, so they are derived from the files found and unique.
"""

from __future__ import annotations

from collections.abc import Callable
from fractions import Fraction
from pathlib import Path

from ..spec import Scenario, load_scenario, make_grid
from ._obligation import CheckOutcome, CheckQuery, Method, Obligation, Verdict

__all__ = ["scenario_files", "scenario_ids", "scenario_obligations"]

CHECKS = ("time_grid", "cspace_grid", "containment")


def scenario_files(scenarios_dir: str | Path) -> list[Path]:
    """The bundled scenario files, sorted by name (so ids come out in a stable order)."""
    d = Path(scenarios_dir)
    return sorted(d.glob("*.toml")) if d.is_dir() else []


def scenario_ids(files: list[Path]) -> list[str]:
    """The obligation ids the scenario files call for."""
    return [f"Scenario.{f.stem}.{c}" for f in files for c in CHECKS]


def _fmt(x: Fraction) -> str:
    return f"{float(x):.17g}" if x.denominator > 10**6 else str(x)


def _time_grid(s: Scenario) -> CheckOutcome:
    g = make_grid(s)
    L = s.left
    # Tf from the scenario's floats as exact rationals, independently of the grid code.
    tf = max(abs(Fraction(L.goal[q]) - Fraction(L.start[q])) / Fraction(L.omega[q])
             for q in range(2))
    dt = Fraction(s.dt)
    covers = g.N * dt >= tf
    least = g.N == 1 or (g.N - 1) * dt < tf
    detail = (f"N = {g.N}, dt = {_fmt(dt)}, N dt = {_fmt(g.N * dt)} >= Tf = {_fmt(tf)}: {covers}; "
              f"N is the least such: {least}")
    if covers and least:
        return CheckOutcome(True, detail)
    return CheckOutcome(False, detail, detail)


def _cspace_grid(s: Scenario) -> CheckOutcome:
    g = make_grid(s)
    R = s.right
    dt = Fraction(s.dt)
    parts, ok = [], True
    for q, m in enumerate((g.m, g.n)):
        lo, hi = Fraction(R.limits[q][0]), Fraction(R.limits[q][1])
        step = Fraction(R.omega[q]) * dt
        exact_h = (hi - lo) / (m - 1)
        stored = Fraction(g.h[q])            # the float the planner computes angles with
        good = exact_h <= step and stored <= step
        ok = ok and good
        parts.append(f"joint {q + 1}: m = {m}, h = {_fmt(exact_h)} (float {g.h[q]!r}) "
                     f"<= omega dt = {_fmt(step)}: {good}")
    detail = "; ".join(parts)
    return CheckOutcome(ok, detail, None if ok else detail)


def _containment(s: Scenario) -> CheckOutcome:
    from ..impl import check_containment   # the impl is only needed by this data check
    rep = check_containment(s)
    detail = (f"{rep.layers} layers (rest included): {rep.detail}; "
              f"worst slack {rep.worst_slack_m:.3e} m")
    return CheckOutcome(rep.ok, detail, None if rep.ok else detail)


def _query(path: Path, check: Callable[[Scenario], CheckOutcome], what: str) -> CheckQuery:
    s = load_scenario(path)
    content = f"scenario {path.name} sha256 {s.sha256}\ncheck {what}\n"
    return CheckQuery(lambda: check(s), content)


def scenario_obligations(scenarios_dir: str | Path) -> list[Obligation]:
    """Three data checks per scenario file found."""
    out = []
    P, D = Verdict.PROVED, Method.DATA
    for f in scenario_files(scenarios_dir):
        group = f"Scenario {f.stem}"
        out += [
            Obligation(f"Scenario.{f.stem}.time_grid", group, "DESIGN §2 (time grid)",
                       f"{f.name}: N dt >= Tf in exact rationals (and N is the least such).",
                       D, P, lambda f=f: _query(f, _time_grid, "time_grid")),
            Obligation(f"Scenario.{f.stem}.cspace_grid", group, "DESIGN §2 (C-space grid)",
                       f"{f.name}: h_q = (hi_q - lo_q)/(m_q - 1) <= omega_q dt for both joints, "
                       "exactly and for the float h the planner uses.",
                       D, P, lambda f=f: _query(f, _cspace_grid, "cspace_grid")),
            Obligation(f"Scenario.{f.stem}.containment", group, "DESIGN §4 (containment chain)",
                       f"{f.name}: region_tight ⊆ region_modified ⊆ region_original on the computed "
                       "polygons, every layer and the rest layer, both links (vertices inside "
                       "the outer polygon's edges up to 1e-12 m of float slack; the worst slack "
                       "is reported).",
                       D, P, lambda f=f: _query(f, _containment, "containment")),
        ]
    return out
