"""Per-scenario obligations: the grids' rounding in exact rationals, the margin lemma's side
conditions, and region containment.

For every scenario file: N dt >= Tf and h_q <= omega_q dt, each in two exact readings (below);
the lattice spacings within the margin lemma's 3.14 rad and its snap slack accounted for; and
tight ⊆ modified ⊆ original on the computed polygons of every layer and the rest layer (docs/model.md
§4, ``impl.check_containment``). Ids carry the file's stem, so they are derived from the files
found and unique.

The two readings of a number in the file. *Binary*: the IEEE double the code computes with,
as the exact rational it is (``Fraction(float)``), e.g. dt = 0.02 is
0.0200000000000000004163...; this is the reading the planner's safety rests on. *Decimal*: the
number as written, e.g. dt = 1/50. The decimal text is recovered by re-reading the TOML with
tomllib and taking ``repr`` of each float, the shortest decimal that rounds to the same double:
it equals the text as written whenever that text has at most 17 significant digits and no
superfluous ones (0.020 reads as 0.02, the same number).
"""

from __future__ import annotations

import tomllib
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from math import ceil
from pathlib import Path

from ..spec import Scenario, load_scenario, make_grid
from ._obligation import CheckOutcome, CheckQuery, Method, Obligation, Verdict, check_source

__all__ = ["CHECKS", "scenario_check_id", "scenario_files", "scenario_obligations"]

CHECKS = ("time_grid", "cspace_grid", "margin_side", "containment")

#: The margin lemma's bound on a lattice spacing (Margin.arc_chord, Lemma.sweep_margin: g <= 3.14).
G_MAX = Fraction(157, 50)


def scenario_files(scenarios_dir: str | Path) -> list[Path]:
    """The scenario files of a folder, sorted by name (so ids come out in a stable order)."""
    d = Path(scenarios_dir)
    return sorted(d.glob("*.toml")) if d.is_dir() else []


def scenario_check_id(stem: str, check: str) -> str:
    """The id of check ``check`` (one of CHECKS) of the scenario file ``stem``.toml."""
    return f"Scenario.{stem}.{check}"


@dataclass(frozen=True)
class _Decimal:
    """The numbers the checks need, in the decimal reading (the text of the file)."""

    dt: Fraction
    start: tuple[Fraction, Fraction]
    goal: tuple[Fraction, Fraction]
    omega_l: tuple[Fraction, Fraction]
    omega_r: tuple[Fraction, Fraction]
    limits: tuple[tuple[Fraction, Fraction], tuple[Fraction, Fraction]]


def _dec(x: float) -> Fraction:
    return Fraction(repr(float(x)))


def _decimal(path: Path) -> _Decimal:
    with path.open("rb") as fh:
        doc = tomllib.load(fh)
    left, right = doc["left"], doc["right"]
    pair = lambda v: (_dec(v[0]), _dec(v[1]))  # noqa: E731
    return _Decimal(dt=_dec(doc["dt"]), start=pair(left["start"]), goal=pair(left["goal"]),
                    omega_l=pair(left["omega"]), omega_r=pair(right["omega"]),
                    limits=(pair(right["limits"][0]), pair(right["limits"][1])))


def _fmt(x: Fraction) -> str:
    return f"{float(x):.17g}" if x.denominator > 10**6 else str(x)


def _time_grid(s: Scenario, d: _Decimal) -> CheckOutcome:
    g = make_grid(s)
    L = s.left
    # Binary: Tf from the doubles as exact rationals, independently of the grid code.
    tf = max(abs(Fraction(L.goal[q]) - Fraction(L.start[q])) / Fraction(L.omega[q])
             for q in range(2))
    dt = Fraction(s.dt)
    covers = g.N * dt >= tf
    least = g.N == 1 or (g.N - 1) * dt < tf
    # Decimal: the same motion as written; the code's N must cover it too.
    tf_d = max(abs(d.goal[q] - d.start[q]) / d.omega_l[q] for q in range(2))
    n_d = max(1, ceil(tf_d / d.dt))
    covers_d = g.N * d.dt >= tf_d
    boundary = " (exactly on the boundary: N dt = Tf)" if n_d * d.dt == tf_d else ""
    detail = (f"binary (the doubles): N = {g.N}, dt = {_fmt(dt)}, N dt = {_fmt(g.N * dt)} >= "
              f"Tf = {_fmt(tf)}: {covers}; N is the least such: {least}. decimal (as written): "
              f"dt = {d.dt}, Tf = {tf_d}, least N = {n_d}{boundary}; the code's N = {g.N} "
              f"covers it (N dt >= Tf): {covers_d}")
    ok = covers and least and covers_d
    return CheckOutcome(ok, detail, None if ok else detail)


def _cspace_grid(s: Scenario, d: _Decimal) -> CheckOutcome:
    g = make_grid(s)
    R = s.right
    dt = Fraction(s.dt)
    parts, ok = [], True
    for q, m in enumerate((g.m, g.n)):
        lo, hi = Fraction(R.limits[q][0]), Fraction(R.limits[q][1])
        step = Fraction(R.omega[q]) * dt
        exact_h = (hi - lo) / (m - 1)
        stored = Fraction(g.h[q])            # the float the planner computes angles with
        step_d = d.omega_r[q] * d.dt
        h_d = (d.limits[q][1] - d.limits[q][0]) / (m - 1)
        edge = " (on the boundary)" if h_d == step_d else ""
        good = exact_h <= step and stored <= step and h_d <= step_d
        ok = ok and good
        parts.append(f"joint {q + 1}: m = {m}; binary: h = {_fmt(exact_h)} (float {g.h[q]!r}) "
                     f"<= omega dt = {_fmt(step)}; decimal: h = {_fmt(h_d)} <= omega dt = "
                     f"{_fmt(step_d)}{edge}: {good}")
    detail = "; ".join(parts)
    return CheckOutcome(ok, detail, None if ok else detail)


def _margin_side(s: Scenario, d: _Decimal) -> CheckOutcome:
    """The margin lemma's side conditions on the spacings the regions use, and its snap slack."""
    # The impl's own margin, its snap slack and the spacing its left regions use.
    from ..impl import SNAP, left_spacing, link_reach, sweep_margin
    g = make_grid(s)
    left = left_spacing(s)
    right = g.h
    parts, ok = [], True
    for side, arm, sp in (("left", s.left, left), ("right", s.right, right)):
        for q in range(2):
            good = Fraction(sp[q]) <= G_MAX
            ok = ok and good
            parts.append(f"{side} spacing {q + 1} = {sp[q]!r} <= 3.14: {good}")
        for link in (0, 1):
            r = [Fraction(x) for x in link_reach(arm, link)]
            gg = [Fraction(x) for x in sp]
            # What sweep_margin must add with every joint moving: the lemma's delta, plus the
            # snap slack (a box end snapped inward by SNAP g leaves configurations within an
            # angle SNAP g of a covered one, i.e. within SNAP g R of it in the plane).
            need = sum(gg[q] ** 2 / 8 * r[q] + Fraction(SNAP) * gg[q] * r[q] for q in range(2))
            got = Fraction(sweep_margin(arm, link, sp))
            # Float sums may round down by a few ulps; eps = 1e-9 m covers that (ledger A2).
            good = got >= need * (1 - Fraction(1, 2**48))
            ok = ok and good
            parts.append(f"{side} link {link + 1}: sweep_margin = {float(got):.6e} m >= delta + "
                         f"SNAP slack = {float(need):.6e} m: {good}")
    parts.append(f"decimal spacings (omega dt as written): left "
                 f"{[_fmt(w * d.dt) for w in d.omega_l]}")
    detail = "; ".join(parts)
    return CheckOutcome(ok, detail, None if ok else detail)


def _containment(s: Scenario, d: _Decimal) -> CheckOutcome:
    from ..impl import check_containment   # only the data checks need impl
    rep = check_containment(s)
    # The digest of the polygons checked, so that a change in the regions shows as "changed".
    detail = (f"{rep.layers} layers (rest included): {rep.detail}; "
              f"worst slack {rep.worst_slack_m:.3e} m; polygons sha256 {rep.regions_sha256[:16]}")
    return CheckOutcome(rep.ok, detail, None if rep.ok else detail)


def _query(path: Path, check: Callable[[Scenario, _Decimal], CheckOutcome], what: str
           ) -> CheckQuery:
    s = load_scenario(path)
    dec = _decimal(path)
    src = check_source(check, _decimal, _dec)
    if check is _containment:
        from ..impl import check_containment, contained_exactly, containment_slack
        src += "\n" + check_source(check_containment, contained_exactly, containment_slack)
    content = f"scenario {path.name} sha256 {s.sha256}\ncheck {what}\n\n{src}\n"
    return CheckQuery(lambda: check(s, dec), content)


_READINGS = ("binary = the doubles the code computes with, as exact rationals; decimal = the "
             "numbers as written in the file (re-read with tomllib, repr of each float)")


def scenario_obligations(scenarios_dir: str | Path) -> list[Obligation]:
    """Four data checks per scenario file found."""
    out = []
    P, D = Verdict.PROVED, Method.DATA
    for f in scenario_files(scenarios_dir):
        group = f"Scenario {f.stem}"
        out += [
            Obligation(scenario_check_id(f.stem, "time_grid"), group, "docs/model.md §2 (time grid)",
                       f"{f.name}: in the binary reading N dt >= Tf and N is the least such; in "
                       f"the decimal reading the code's N also covers Tf ({_READINGS}). The "
                       "readings can differ on a boundary: default's Tf = 1.2 = 60 * 0.02 and "
                       "limited-joints' Tf = 1.625 = 65 * 0.025 are exact multiples of dt in "
                       "decimal.",
                       D, P, lambda f=f: _query(f, _time_grid, "time_grid")),
            Obligation(scenario_check_id(f.stem, "cspace_grid"), group, "docs/model.md §2 (C-space grid)",
                       f"{f.name}: h_q = (hi_q - lo_q)/(m_q - 1) <= omega_q dt for both joints, "
                       f"in the binary reading (exact, and for the float h the planner uses) and "
                       f"the decimal one ({_READINGS}).",
                       D, P, lambda f=f: _query(f, _cspace_grid, "cspace_grid")),
            Obligation(scenario_check_id(f.stem, "margin_side"), group, "docs/model.md §4 (margin lemma's "
                       "side conditions)",
                       f"{f.name}: every lattice spacing the regions use (left: omega_q dt as "
                       "the code computes it; right: the float h_q) is <= 3.14 rad, the bound "
                       "Margin.arc_chord and Lemma.sweep_margin assume; and impl.sweep_margin, "
                       "for every link of both arms at those spacings, is at least the lemma's "
                       "delta plus the snap slack SNAP g R per joint (ledger A10), exactly up "
                       "to 2^-48 relative float rounding (ledger A2).",
                       D, P, lambda f=f: _query(f, _margin_side, "margin_side")),
            Obligation(scenario_check_id(f.stem, "containment"), group, "docs/model.md §4 (containment chain)",
                       f"{f.name}: region_tight ⊆ region_modified ⊆ region_original on the computed "
                       "polygons, every layer and the rest layer, both links: every vertex of the "
                       "inner polygon on the inner side of every edge of the outer one, decided "
                       "exactly on the doubles (a filtered cross product, Fractions where the "
                       "float sign is not certain); the least float slack and a digest of the "
                       "polygons are reported.",
                       D, P, lambda f=f: _query(f, _containment, "containment")),
        ]
    return out
