"""Per-scenario obligations: the grids' rounding in exact rationals, the margin lemma's side
conditions, and region containment.

For every scenario file: N dt >= Tf and h_q <= omega_q dt, each in two exact readings (below);
the lattice spacings within the margin lemma's 3.14 rad and its snap slack accounted for; and
tight ⊆ modified ⊆ original on the computed polygons of every layer and the rest layer (docs/model.md
§4, ``impl.check_containment``). Ids carry the file's stem, so they are derived from the files
found and unique.

The two readings of a number in the file. *Binary*: the IEEE double the code computes with,
as the exact rational it is (``Fraction(float)``), e.g. dt = 0.02 is
0.0200000000000000004163.... *Decimal*: the number as written, e.g. dt = 1/50: the TOML text
itself, exactly (the reader keeps it, ``spec.Written``; 0.020 reads as 0.02, the same number);
the C-space grid is counted in it, the reading in which the file states the speed limit, and
the float h is held within rounding of omega dt in both (docs/model.md §2). Both readings are
the spec's own (``Grid.READINGS``, ``Grid.time_readings``, ``Grid.spacing_readings``,
``spec.spacing_conditions``, spec/_counts.py), the ones the loader builds the grid with and the
contracts check.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import replace
from fractions import Fraction
from pathlib import Path

from ..errors import CfmpaError
from ..spec import (
    MAX_SPACING,
    Grid,
    Scenario,
    Variant,
    decimal,
    link_name,
    load_scenario,
    make_grid,
    spacing_conditions,
    theorem_scope,
)
from ..spec import parts as part_indices
from ._obligation import (
    CheckOutcome,
    CheckQuery,
    Method,
    Obligation,
    Verdict,
    check_source,
    spec_closure_source,
)

__all__ = ["CHECKS", "scenario_check_id", "scenario_files", "scenario_obligations"]

#: Translation validation, one per variant: the bytes cfmpa plan would use, checked at every cell.
TRANSLATION_CHECKS = tuple(f"translation_{v.value}" for v in Variant)
CHECKS = ("time_grid", "cspace_grid", "margin_side", "containment") + TRANSLATION_CHECKS

#: Translation validation builds and checks a whole D_R: a larger wall-clock limit than the
#: other data checks (a default-sized grid takes about 3 s; a user's grid may be much larger).
TRANSLATION_TIMEOUT_MS = 600_000

#: The margin lemma's bound on a lattice spacing (Margin.arc_chord, Lemma.sweep_margin: g <= 3.14):
#: the loader's own (spec.MAX_SPACING, read).
G_MAX = MAX_SPACING


def scenario_files(scenarios_dir: str | Path) -> list[Path]:
    """The scenario files of a folder, sorted by name (so ids come out in a stable order)."""
    d = Path(scenarios_dir)
    return sorted(d.glob("*.toml")) if d.is_dir() else []


def scenario_check_id(stem: str, check: str) -> str:
    """The id of check ``check`` (one of CHECKS) of the scenario file ``stem``.toml."""
    return f"Scenario.{stem}.{check}"


def _fmt(x: Fraction) -> str:
    return f"{float(x):.17g}" if x.denominator > 10**6 else str(x)


def _time_grid(s: Scenario) -> CheckOutcome:
    g = make_grid(s)
    parts, covers_all, least_somewhere = [], True, g.N == 1
    for r, (dt, tf) in Grid.time_readings(s).items():
        covers = g.N * dt >= tf
        short = (g.N - 1) * dt < tf        # N - 1 would not cover Tf in this reading
        covers_all = covers_all and covers
        least_somewhere = least_somewhere or short
        edge = " (exactly on the boundary: N dt = Tf)" if g.N * dt == tf else ""
        parts.append(f"{r}: dt = {_fmt(dt)}, Tf = {_fmt(tf)}, N dt = {_fmt(g.N * dt)} >= Tf: "
                     f"{covers}{edge}; (N - 1) dt < Tf: {short}")
    ok = covers_all and least_somewhere
    detail = (f"N = {g.N}; " + "; ".join(parts) + f"; N is the least N >= 1 covering Tf in both "
              f"readings: {ok}")
    return CheckOutcome(ok, detail, None if ok else detail)


def _cspace_grid(s: Scenario) -> CheckOutcome:
    g = make_grid(s)
    parts, ok = [], True
    for q, m in enumerate((g.m, g.n)):
        lo, hi = s.right.limits[q]
        # The conditions the grid is built to meet (spec.spacing_conditions, docs/model.md §2):
        # exact in the decimal reading, the float h within rounding in both, <= 3.14.
        conds = spacing_conditions(lo, hi, s.right.omega[q], s.dt, m, g.h[q])
        good = all(c.holds for c in conds)
        words = [c.words() for c in conds]
        # Stated, not required: the exact spacing of the doubles against their product
        # (it may exceed it by rounding; the regions use the float h, docs/model.md §2).
        span, step = Grid.spacing_readings(s, q)["binary"]
        edge = "on the boundary" if span / (m - 1) == step else (
            "below" if span / (m - 1) < step else "above, by rounding")
        words.append(f"binary (hi - lo)/(m - 1) = {_fmt(span / (m - 1))} vs omega dt = "
                     f"{_fmt(step)}: {edge}")
        ok = ok and good
        parts.append(f"joint {q + 1}: m = {m}; " + "; ".join(words))
    detail = "; ".join(parts)
    return CheckOutcome(ok, detail, None if ok else detail)


def _margin_side(s: Scenario) -> CheckOutcome:
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
        for link in part_indices(arm):
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
            parts.append(f"{link_name(side, link + 1)}: sweep_margin = {float(got):.6e} m >= delta + "
                         f"SNAP slack = {float(need):.6e} m: {good}")
    dec = [_fmt(decimal(w) * decimal(s.dt)) for w in s.left.omega]
    parts.append(f"decimal spacings (omega dt as written): left {dec}")
    detail = "; ".join(parts)
    return CheckOutcome(ok, detail, None if ok else detail)


def _containment(s: Scenario) -> CheckOutcome:
    from ..impl import check_containment   # only the data checks need impl
    rep = check_containment(s)
    # The digest of the polygons checked, so that a change in the regions shows as "changed".
    detail = (f"{rep.layers} layers (rest included): {rep.detail}; "
              f"worst slack {rep.worst_slack_m:.3e} m; polygons sha256 {rep.regions_sha256[:16]}")
    return CheckOutcome(rep.ok, detail, None if rep.ok else detail)


def _chains() -> list[list[Variant]]:
    """The variants' containment chains by their rules' ``within`` (``Variant.nesting``), each
    from its innermost variant out: [[tight, modified, original]]."""
    pairs = Variant.nesting()
    outers = {o for _, o in pairs}
    chains = []
    for v in (i for i, _ in pairs if i not in outers):
        chain = [v]
        while (w := chain[-1].within) is not None:
            chain.append(w)
        chains.append(chain)
    return chains


def _translation(s: Scenario, variant: Variant) -> CheckOutcome:
    """The fast kernels' D_R and answer, as cfmpa plan computes them, against Theorems 1-4's
    postconditions, decided by the spec alone: every cell, the path, and the search's witness;
    and a found path's exact re-decision (``spec.exact_path_gaps``, its own loop, the geometry
    replaced: ``_obl_wiring.exact_cells``) visits every (layer, cell) the fixed is_path reads,
    the rest layer included (docs/model.md §7.4)."""
    import hashlib

    from ..impl import kernels
    from ..spec import check_witness, dr_cell_failures, dr_shape_failures, search_failures

    build, search = kernels("fast", wait=True)   # the fast kernels themselves, never numpy's
    g = make_grid(s)
    start, goal = s.right.start_cell, s.right.goal_cell
    dr = build(s, variant, g, progress=False)
    fails = dr_shape_failures(g, dr)
    checked = 0
    if not fails:
        checked, fails = dr_cell_failures(s, variant, g, dr)
    answer = None
    if not fails:
        answer = search(dr, start, goal, with_witness=True, progress=False)
        fails = (search_failures(dr, start, goal, answer)
                 or check_witness(dr, start, goal, answer, answer.witness))
    covered = ""
    if answer is not None and answer.path and not fails:
        from types import SimpleNamespace

        from ._obl_wiring import exact_coverage_failures, is_path_reads
        gaps = exact_coverage_failures(s, variant, g, answer.path)
        fails = [SimpleNamespace(condition="exact.coverage", message=f"{gaps[0]} ({len(gaps)} "
                                 "in all)", values=())] if gaps else []
        covered = (f"; the exact re-decision visits the {len(is_path_reads(answer.path, g.N))} "
                   "(layer, cell) pairs is_path reads, rest layer included")
    digest = hashlib.sha256(dr.tobytes()).hexdigest()[:16]
    if answer is None:
        said = "not searched"
    elif answer.path:
        said = f"path found, J1 = {answer.J1}, J2 = {answer.J2}, optimal by its witness"
    else:
        said = f"no path ({answer.reason}), shown by the reachable set"
    detail = (f"{variant.value}: D_R {list(dr.shape)} sha256 {digest}; {checked} cells checked "
              f"against the spec's regions; {said}{covered}")
    if fails:
        f = fails[0]
        lines = [f"{f.condition}: {f.message}"] + [f"{k} was {v!r}" for k, v in f.values]
        return CheckOutcome(False, detail + "; FAILS " + lines[0], "\n".join(lines))
    return CheckOutcome(True, detail)


def _query(path: Path, check: Callable[[Scenario], CheckOutcome], what: str
           ) -> CheckQuery:
    s = load_scenario(path)
    if what.startswith("translation_"):
        from ..impl import kernels

        # The checkers' sources (hashed: editing them is a change); the kernels' output is
        # judged by them, and its digest is in the detail.
        from ..spec import (
            check_witness,
            dr_cell_failures,
            dr_shape_failures,
            exact_path_gaps,
            path_violations,
            search_failures,
        )
        from ._obl_wiring import exact_cells, exact_coverage_failures, is_path_reads
        src = check_source(_translation, make_grid, kernels, dr_shape_failures, dr_cell_failures,
                           search_failures, check_witness, exact_path_gaps,
                           exact_path_gaps.__globals__["path_layer_cells"], path_violations,
                           exact_cells, exact_coverage_failures, is_path_reads)
        # And the spec's modules they rest on, whole: the every-cell postcondition, the
        # regions, the witness checker's helpers are called, not named, above.
        src += "\n" + spec_closure_source(dr_shape_failures, dr_cell_failures, search_failures,
                                          check_witness, exact_path_gaps, path_violations)
    else:
        src = check_source(check, Grid.time_readings, Grid.spacing_readings, decimal, make_grid,
                           spacing_conditions)
    if check is _containment:
        from ..impl import check_containment, contained_exactly, containment_slack
        src += "\n" + check_source(check_containment, contained_exactly, containment_slack,
                                  Variant.nesting)
    content = f"scenario {path.name} sha256 {s.sha256}\ncheck {what}\n\n{src}\n"
    return CheckQuery(lambda: check(s), content)


def _scope(path: Path) -> str:
    """``spec.theorem_scope`` of the workcell in ``path`` ("" for none, and for a file that does
    not load: its checks then fail with the loader's message)."""
    try:
        return theorem_scope(load_scenario(path)) or ""
    except CfmpaError:
        return ""


#: How the translation validations are labelled in the summary and the report.
EVERY_CELL = "every cell"

_READINGS = ("binary = the doubles the code computes with, as exact rationals; decimal = the "
             "numbers as written in the file (each TOML number's text, exactly)")


def scenario_obligations(scenarios: str | Path | Sequence[str | Path]) -> list[Obligation]:
    """The data checks (CHECKS) per scenario file: those of a folder (sorted), or the files
    given (the workcells a report is about, in the order given)."""
    files = (scenario_files(scenarios) if isinstance(scenarios, (str, Path))
             else [Path(f) for f in scenarios])
    out: list[Obligation] = []
    P, D = Verdict.PROVED, Method.DATA
    for f in files:
        first = len(out)
        group = f"Scenario {f.stem}"
        out += [
            Obligation(scenario_check_id(f.stem, "time_grid"), group, "docs/model.md §2 (time grid)",
                       f"{f.name}: N dt >= Tf in both readings, and N is the least N >= 1 that "
                       f"covers Tf in both ({_READINGS}). The "
                       "readings can differ on a boundary: default's Tf = 1.2 = 60 * 0.02 and "
                       "limited-joints' Tf = 1.625 = 65 * 0.025 are exact multiples of dt in "
                       "decimal.",
                       D, P, functools.partial(_query, f, _time_grid, "time_grid"),
                       summary=(f"{f.stem}: the time steps cover the whole of the principal arm's "
                                "motion, for the numbers as written in the file and as the computer "
                                "stores them.")),
            Obligation(scenario_check_id(f.stem, "cspace_grid"), group, "docs/model.md §2 (C-space grid)",
                       f"{f.name}: h_q = (hi_q - lo_q)/(m_q - 1) <= omega_q dt for both joints "
                       f"exactly in the decimal reading (the speed limit as the file states it), "
                       f"and the float h the planner uses within rounding (1e-10 relative) of "
                       f"omega_q dt in both readings and <= 3.14 rad ({_READINGS}).",
                       D, P, functools.partial(_query, f, _cspace_grid, "cspace_grid"),
                       summary=(f"{f.stem}: the subordinate arm's grid of joint angles is no coarser "
                                "than the angle its joints turn in one time step, as written and as "
                                "stored.")),
            Obligation(scenario_check_id(f.stem, "margin_side"), group, "docs/model.md §4 (margin lemma's "
                       "side conditions)",
                       f"{f.name}: every lattice spacing the regions use (left: omega_q dt as "
                       "the code computes it; right: the float h_q) is <= 3.14 rad, the bound "
                       "Margin.arc_chord and Lemma.sweep_margin assume; and impl.sweep_margin, "
                       "for every link of both arms at those spacings, is at least the lemma's "
                       "delta plus the snap slack SNAP g R per joint (ledger A10), exactly up "
                       "to 2^-48 relative float rounding (ledger A2).",
                       D, P, functools.partial(_query, f, _margin_side, "margin_side"),
                       summary=(f"{f.stem}: every angle step the swept regions use is at most 3.14 "
                                "rad, and the margin the planner adds to each link is at least the "
                                "margin lemma's bound.")),
            Obligation(scenario_check_id(f.stem, "containment"), group,
                       "docs/model.md §4 (containment chain)",
                       f"{f.name}: "
                       + "; ".join(" ⊆ ".join(f"region_{v}" for v in c) for c in _chains())
                       + " on the computed polygons, "
                       "every layer and the rest layer, both links: every vertex of the "
                       "inner polygon on the inner side of every edge of the outer one, decided "
                       "exactly on the doubles (a filtered cross product, Fractions where the "
                       "float sign is not certain); the least float slack and a digest of the "
                       "polygons are reported.",
                       D, P, functools.partial(_query, f, _containment, "containment"),
                       summary=(f"{f.stem}: " + "; ".join(
                                    f"the {c[0]} swept region lies inside the {c[1]} one"
                                    + "".join(f", which lies inside the {x} one" for x in c[2:])
                                    for c in _chains())
                                + ", in every layer and for both "
                                "links, decided exactly.")),
        ]
        for v in Variant:
            what = f"translation_{v.value}"
            out.append(Obligation(
                scenario_check_id(f.stem, what), group,
                "docs/model.md §7 (translation validation)",
                f"{f.name}, {v.value}: the D_R that cfmpa plan uses (impl's fast BuiltDR) meets "
                f"Theorem {v.rule.theorems[0]}'s postcondition at every cell "
                "(its shape, and each cell's value against the spec's own regions and "
                "distances), and the fast searchoptpath's answer on it meets Theorem "
                f"{v.rule.theorems[1]}'s (a found path valid under the fixed "
                "is_path, its costs its own) with a witness that spec.check_witness accepts "
                "(the path optimal, or no valid path at all); a found path's exact re-decision "
                "(spec.exact_path_gaps, its loop run with the geometry replaced) visits every "
                "(layer, cell) the fixed is_path reads, the rest layer included, and no other. A "
                "check of the code that runs, on this workcell's data: not a proof for other "
                "workcells.",
                D, P, functools.partial(_query, f, functools.partial(_translation, variant=v),
                                        what),
                summary=(f"{f.stem}, {v.value}: the fast code's D_R and path meet Theorem "
                         f"{v.rule.theorems[0]}'s and Theorem "
                         f"{v.rule.theorems[1]}'s postconditions at every cell; "
                         "the search's answer is checked by its witness; the exact re-decision "
                         "visits every cell of the path."),
                label=EVERY_CELL, timeout_ms=TRANSLATION_TIMEOUT_MS))
        # A tool or heights: each of the workcell's lines says what the safety theorem does
        # not yet cover (docs/model.md §10), beside its verdict.
        scope = _scope(f)
        if scope:
            out[first:] = [replace(o, label="; ".join(x for x in (o.label, scope) if x))
                           for o in out[first:]]
    return out
