"""`cfmpa compare` as the user sees it: the campaign (``cfmpa.runs.run_campaign``) as
compare.json (``campaign_json``: the table per variant with Wilson intervals, the paired counts
with McNemar's exact test, the checks) and as the printed table (``format_campaign``).

The workcells, their tasks on the engine and the store are ``runs/_campaign.py``'s
(docs/model.md §13); this module computes only statistics of the recorded results and imports
no dask.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from ..files import write_json
from ..runs import COMPARE_DT, CONNECT_TIMEOUT_S, WORKER_TIMEOUT_S, Campaign, run_campaign
from ..spec import SearchStatus, Variant
from ._stats import mcnemar_exact_p, wilson_interval

__all__ = ["PAIRS", "campaign_json", "format_campaign", "run_compare"]

#: The paired comparisons (a, b): b's region is inside a's, so b should succeed where a does.
PAIRS = ((Variant.ORIGINAL, Variant.MODIFIED), (Variant.MODIFIED, Variant.TIGHT),
         (Variant.ORIGINAL, Variant.TIGHT))


def campaign_json(c: Campaign) -> dict[str, Any]:
    """The campaign as JSON: the table per variant with Wilson 95 % intervals, the paired
    counts with McNemar's exact test, the cross-variant counts and checks, the errors, the cases.

    Rates are over the ``planned`` workcells (``n`` less those whose task raised, listed in
    ``errors``). Checks (each must count 0; the corrected Property 8 and the certificate predict
    it): modified fails where original succeeds; tight fails where modified succeeds; a variant's
    optimum (J1, J2) exceeds a looser variant's; a found path not certified clear. Everything but
    ``timings_s`` is a function of (n, seed, dt) and the code.
    """
    O, M, T = Variant.ORIGINAL, Variant.MODIFIED, Variant.TIGHT
    planned = len(c.cases)
    all_found = [x for x in c.cases if all(x.found(v) for v in Variant)]
    rows = []
    for v in Variant:
        outs = [x.outcome(v) for x in c.cases]
        found = [o for o in outs if o.status == SearchStatus.FOUND.value]
        rows.append({
            "variant": v.value,
            "found": len(found),
            "success_rate": len(found) / planned if planned else None,
            "success_rate_ci95": list(wilson_interval(len(found), planned)) if planned else None,
            "mean_free_fraction": _mean([o.free_fraction for o in outs]),
            "mean_J1_all_found": _mean([x.outcome(v).J1 for x in all_found]),
            "mean_J2_all_found": _mean([x.outcome(v).J2 for x in all_found]),
            "no_path_reasons": _count(o.reason for o in outs if o.reason is not None),
        })

    def worse(a: Variant, b: Variant) -> int:      # a's optimum worse than the looser b's
        return sum(1 for x in all_found
                   if (x.outcome(a).J1, x.outcome(a).J2) > (x.outcome(b).J1, x.outcome(b).J2))

    paired = []
    for a, b in PAIRS:
        only_b = sum(1 for x in c.cases if x.found(b) and not x.found(a))
        only_a = sum(1 for x in c.cases if x.found(a) and not x.found(b))
        both = sum(1 for x in c.cases if x.found(a) and x.found(b))
        paired.append({"a": a.value, "b": b.value, "a_fails_b_succeeds": only_b,
                       "a_succeeds_b_fails": only_a, "both_succeed": both,
                       "both_fail": planned - only_a - only_b - both,
                       "mcnemar_exact_p": mcnemar_exact_p(only_b, only_a)})
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
        "planned": planned,
        "errors": [{"index": e.index, "message": e.message} for e in c.errors],
        "table": rows,
        "paired": paired,
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
        # The only part that depends on the machine and the run: times, never results.
        "timings_s": {"mean_per_variant": {v.value: _mean([x.outcome(v).seconds
                                                           for x in c.cases]) for v in Variant},
                      **c.timings_s},
    }


def format_campaign(doc: dict[str, Any]) -> str:
    """The campaign's table, paired counts and checks as plain text (what `cfmpa compare`
    prints)."""
    lines = [f"campaign  {doc['n']} random workcells, seed {doc['seed']}, dt {doc['dt']} s, "
             f"kernels {doc['kernel']}; mean grid {_num(doc['mean_cells'], 0)} cells",
             f"{'variant':<10}{'found':>7}{'success':>9}  {'95% CI (Wilson)':<18}{'free':>8}"
             f"{'mean J1':>9}{'mean J2':>9}   (J1, J2: mean over the {doc['all_found']} "
             f"workcells all variants solve)"]
    for r in doc["table"]:
        ci = r["success_rate_ci95"]
        lines.append(f"{r['variant']:<10}{r['found']:>7}{_pct(r['success_rate']):>9}  "
                     f"{'-' if ci is None else f'[{ci[0]:.1%}, {ci[1]:.1%}]':<18}"
                     f"{_pct(r['mean_free_fraction'], 1):>8}{_num(r['mean_J1_all_found']):>9}"
                     f"{_num(r['mean_J2_all_found']):>9}")
    lines.append(f"{'paired (a vs b)':<22}{'a fails, b succeeds':>21}{'a succeeds, b fails':>21}"
                 f"{'McNemar exact p':>17}")
    for p in doc["paired"]:
        lines.append(f"{p['a'] + ' vs ' + p['b']:<22}{p['a_fails_b_succeeds']:>21}"
                     f"{p['a_succeeds_b_fails']:>21}{p['mcnemar_exact_p']:>17.3g}")
    lines.append(f"original fails, modified succeeds: {doc['original_fails_modified_succeeds']} "
                 f"of {doc['planned']}  (tight succeeds: {doc['original_fails_tight_succeeds']}; "
                 f"no variant succeeds: {doc['none_found']})")
    errs = doc["errors"]
    if errs:
        lines.append(f"errors    {len(errs)} workcell(s) raised (not counted above): "
                     + "; ".join(f"{e['index']}: {e['message']}" for e in errs[:5])
                     + (" ..." if len(errs) > 5 else ""))
    bad = {k: v for k, v in doc["checks"].items() if v}
    lines.append("checks    " + ("all hold: " if not bad else "FAILED: ")
                 + ", ".join(f"{k} = {v}" for k, v in (bad or doc["checks"]).items()))
    return "\n".join(lines)


def run_compare(n: int = 100, seed: int = 0, out: str | None = None, *, dt: float = COMPARE_DT,
                workers: int = 0, scheduler: str | None = None,
                connect_timeout: float = CONNECT_TIMEOUT_S,
                worker_timeout: float = WORKER_TIMEOUT_S, progress: bool | None = None,
                stdout: TextIO | None = None, _faults: Mapping[int, str] | None = None,
                _after_record: Callable[[int], None] | None = None) -> int:
    """Run a campaign (see ``run_campaign``), print its table on ``stdout`` (default
    sys.stdout); write ``out``/compare.json (atomically) when ``out`` is given, with the store
    ``out``/compare.jsonl beside it.

    Exit code 0 when every check of ``campaign_json`` counts 0 and no workcell raised, else 1.
    """
    so = sys.stdout if stdout is None else stdout
    c = run_campaign(n, seed, dt, workers=workers, scheduler=scheduler, out=out,
                     connect_timeout=connect_timeout, worker_timeout=worker_timeout,
                     progress=progress, stream=so,
                     _faults=_faults, _after_record=_after_record)
    doc = campaign_json(c)
    print(format_campaign(doc), file=so)
    if out is not None:
        path = write_json(Path(out) / "compare.json", doc)
        print(f"wrote     {path}", file=so)
    t = c.timings_s
    print(f"time      {t.get('run', 0.0):.1f} s: {c.n - c.reused} workcell(s) planned in "
          f"{t.get('tasks', 0.0):.1f} s after {t.get('engine_start', 0.0):.1f} s of engine start",
          file=so)
    return 0 if doc["checks_ok"] and not doc["errors"] else 1



def _mean(xs: Any) -> float | None:
    xs = [float(x) for x in xs]
    return sum(xs) / len(xs) if xs else None


def _count(xs: Any) -> dict[str, int]:
    out: dict[str, int] = {}
    for x in xs:
        out[x] = out.get(x, 0) + 1
    return dict(sorted(out.items()))


def _num(x: float | None, digits: int = 1) -> str:
    return "-" if x is None else f"{x:.{digits}f}"


def _pct(x: float | None, digits: int = 1) -> str:
    return "-" if x is None else f"{x:.{digits}%}"
