"""Resource limits of the prove's solver calls (docs/model.md §6.1): deterministic counts, so that
a verdict does not depend on the machine's load.

A wall-clock timeout gives another answer on a loaded machine: a VC decided in 3 s when the
machine is quiet runs out of its 20 s at a load of 10, and a premise control that finds its
counter-model in 0.7 s ends ``unknown``. Z3's ``rlimit`` counts the solver's own work (the
``rlimit count`` statistic), the same on every run of the same text with the same Z3, however
busy the machine (measured: all 648 checks' counts equal over whole runs at loads 3 to 9, in
one process or two). So every Z3 check of an obligation (vacuity and proof, each in a context
of its own) runs under the obligation's resource limit of ``Z3_RLIMITS``, ``RLIMIT_MARGIN`` times the
largest count any of its checks used when calibrated; its wall-clock timeout stays, multiplied
by ``WALL_NET_FACTOR``, as a safety net only. A check that needs more than its limit ends
``unknown`` (never proved), as it would on any machine; ``results.json`` gives the limit that ran
(an obligation's ``rlimit``) and each VC's counts (``rlimit_count``: vacuity, proof).

The table is written from a run's results.json: ``python -m cfmpa.proofs._limits
build/proofs/results.json`` prints it (``calibrate``); re-calibrate when Z3 is upgraded or a
statement changes much (a check running into its limit is UNKNOWN and fails the run: that says
so). An obligation absent from the table runs on the wall clock alone (tests/proofs require
every fixed Z3 obligation to have an entry).
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

__all__ = ["RLIMIT_MARGIN", "WALL_NET_FACTOR", "Z3_RLIMITS", "calibrate", "wall_net_ms",
           "z3_rlimit"]

#: A limit is this many times the largest count measured (room for another Z3 build).
RLIMIT_MARGIN = 10
#: With a resource limit, the wall-clock timeout is only a safety net: this many times larger.
WALL_NET_FACTOR = 5
#: Never below this (the smallest checks' counts are noise).
_FLOOR = 100_000
#: The most of a results.json ``_main`` reads.
_MAX_BYTES = 64 * 1024 * 1024

#: Z3's resource limit per check of each Z3 obligation (``calibrate``; Z3 4.x's counts).
Z3_RLIMITS: dict[str, int] = {
    'Certificate.height_gap': 220_000,
    'Certificate.lipschitz': 29_000_000,
    'Certificate.wiring': 4_300_000,
    'Def1.segment': 100_000,
    'Def1.segment_printed': 100_000,
    'Def2.is_convex': 120_000,
    'Def3.convex_hull': 100_000,
    'Def4.is_path_fixed_safe': 950_000,
    'Def4.is_path_printed': 160_000,
    'Def4.is_path_printed_off_grid': 120_000,
    'Exact.gap_formula': 1_400_000,
    'Lemma.sweep_margin': 120_000_000,
    'Lemma1.convex_monotone': 100_000,
    'Lemma2.convex_union': 100_000,
    'Margin.arc_chord': 750_000,
    'Monitor.between_samples': 170_000,
    'Monitor.reference_speeds': 7_800_000,
    'Prop1.state_meaning': 100_000,
    'Prop2.endpoints': 100_000,
    'Prop3.layer_free': 670_000,
    'Prop4.rest_free': 110_000,
    'Prop5.optpath_is_path': 670_000,
    'Prop5.printed': 260_000,
    'Prop6.opt_layer_free': 370_000,
    'Prop7.opt_rest_free': 150_000,
    'Prop8.intersection_monotone': 100_000,
    'Prop8.optimal_cost': 430_000,
    'Prop8.path_exists': 19_000_000,
    'Prop8.prestrength_thm4': 8_900_000,
    'Prop8.printed': 570_000,
    'Prop8.subset_monotone': 100_000,
    'Prop8.valid_transfer': 6_000_000,
    'Safety.height_rule': 100_000,
    'Safety.modified.composition': 3_200_000,
    'Safety.modified.principal_in_layer_box': 2_600_000,
    'Safety.original.composition': 2_300_000,
    'Safety.original.principal_in_layer_box': 1_700_000,
    'Safety.region_soundness': 2_400_000,
    'Safety.region_statement': 1_400_000,
    'Safety.separation': 100_000,
    'Safety.subordinate_in_cell_box': 230_000,
    'Safety.tight.composition': 2_400_000,
    'Safety.tight.principal_in_layer_box': 2_100_000,
    'Safety.tool_region': 14_000_000,
    'Sep.distance_monotone': 100_000,
    'Sep.separating_axis': 910_000,
    'Thm1.builtdr': 200_000,
    'Thm1.termination': 100_000,
    'Thm2.searchoptpath': 1_100_000,
    'Thm3.box_nesting': 260_000,
    'Thm3.builtdr': 200_000,
    'Thm3.builtdr_tight': 200_000,
    'Thm3.termination': 100_000,
    'Thm3.termination_tight': 100_000,
    'Thm4.searchoptpath': 980_000,
    'Thm4.searchoptpath_tight': 820_000,
    'Tolerance.tube': 4_100_000,
    'Tolerance.tube_factor': 310_000,
    'Witness.labels_sound': 45_000_000,
    'Witness.reachable_sound': 25_000_000,
}


def z3_rlimit(ident: str) -> int | None:
    """The resource limit of each Z3 check of obligation ``ident`` (None: wall clock only)."""
    return Z3_RLIMITS.get(ident)


def wall_net_ms(timeout_ms: int, rlimit: int | None) -> int:
    """The wall-clock limit of a check: its timeout, or with a resource limit a safety net."""
    return timeout_ms if rlimit is None else timeout_ms * WALL_NET_FACTOR


def _round_up(n: float) -> int:
    """``n`` rounded up to two significant digits."""
    if n <= 0:
        return 0
    step = 10 ** max(int(math.floor(math.log10(n))) - 1, 0)
    return int(math.ceil(n / step) * step)


def calibrate(obligations: Iterable[Mapping[str, Any]], margin: int = RLIMIT_MARGIN
              ) -> dict[str, int]:
    """Per Z3 obligation of a run (results.json's ``obligations``), ``margin`` times the largest
    ``rlimit_count`` of its VCs, rounded up (at least ``_FLOOR``)."""
    out = {}
    for o in obligations:
        counts = [c for v in o.get("vcs", []) for c in v.get("rlimit_count", [])]
        if o.get("method") == "z3" and counts:
            out[str(o["id"])] = max(_FLOOR, _round_up(margin * max(counts)))
    return dict(sorted(out.items()))


def _main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: python -m cfmpa.proofs._limits RESULTS_JSON", file=sys.stderr)
        return 2
    try:
        with Path(argv[0]).open("rb") as f:
            raw = f.read(_MAX_BYTES + 1)
        if len(raw) > _MAX_BYTES:
            raise ValueError(f"larger than {_MAX_BYTES} bytes")
        doc = json.loads(raw.decode("utf-8"))
        table = calibrate(doc["obligations"])
    except (OSError, ValueError, KeyError, TypeError) as exc:
        print(f"{argv[0]}: cannot read a results.json ({type(exc).__name__}: {exc})",
              file=sys.stderr)
        return 2
    print("Z3_RLIMITS: dict[str, int] = {")
    for ident, limit in table.items():
        print(f"    {ident!r}: {limit:_},")
    print("}")
    return 0


if __name__ == "__main__":
    raise SystemExit(_main(sys.argv[1:]))
