"""Measure which cvc5 strategy replays each pinned statement quickest, and (with --write) name
it in proofs/obligations.lock (docs/model.md §6.4). Never imported by the package.

For every Z3 obligation's VC with a standard SMT-LIB text: cvc5's answer and CPU under the
default strategy (``_cvc5.DEFAULT_STRATEGY``), then, where that took at least ``--floor``
seconds or did not decide, under each other strategy of ``_cvc5.STRATEGIES`` (one worker
process per strategy, the CPU its own process spent on the query). ``choose`` picks:

- a statement cvc5 decides by default keeps the default unless another strategy gives the same
  answer in at most ``RATIO`` of its CPU and at least ``MARGIN_S`` less (timing noise never
  flips a choice back and forth); the candidates are measured twice and the slower run kept;
- a statement cvc5 does not decide by default (its answer then comes from the lock, not re-run)
  gets the quickest strategy that decides it with the answer Z3 gives, if within
  ``NEW_DECIDED_S`` of CPU: from then on it is replayed, and so checked, in every run.

The strategies change cvc5's search only (``_cvc5.STRATEGIES``), so a choice never changes an
answer; a run still compares every answer with Z3's. Writes the measurements to ``--out``
(default build/cvc5_strategies.json); with --write, the choices (and cvc5's answer under each)
into the lock, and prints each change. Several minutes (the undecided statements each run to
cvc5's limit under every strategy).

    python bench/tune_cvc5.py [--write] [--lock PATH] [--out FILE] [--only PATTERN]
    python bench/tune_cvc5.py --apply FILE [--lock PATH]

--apply writes the choices of an earlier run's --out file into the lock without measuring
again, for the statements whose hash the lock still pins.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

#: A strategy other than the default must take at most this share of its CPU ...
RATIO = 0.7
#: ... and at least this much less (seconds): below it, a difference is noise.
MARGIN_S = 0.05
#: A statement the default does not decide is replayed from then on if a strategy decides it in
#: at most this much CPU (seconds): the cost every run pays for one more cvc5 check.
NEW_DECIDED_S = 1.0


def choose(default: tuple[str, float], others: Mapping[str, tuple[str, float]],
           want: str) -> str:
    """The strategy for one statement: ``default`` and ``others`` map to (answer, CPU seconds);
    ``want`` is Z3's answer (unsat for a proved VC). The rules are the module's."""
    from cfmpa.proofs._cvc5 import DEFAULT_STRATEGY

    answer, cpu = default
    good = sorted((c, name) for name, (a, c) in others.items() if a == want)
    if answer == want:
        if good and good[0][0] <= RATIO * cpu and cpu - good[0][0] >= MARGIN_S:
            return good[0][1]
        return DEFAULT_STRATEGY
    if answer in ("sat", "unsat"):
        raise ValueError(f"cvc5 answers {answer} where Z3 answers {want}: a disagreement, "
                         "which cfmpa prove reports; no strategy is chosen for it")
    if good and good[0][0] <= NEW_DECIDED_S:
        return good[0][1]
    return DEFAULT_STRATEGY


def statements(only: str | None) -> list[dict[str, Any]]:
    """Every Z3 VC with a standard text: its lock key, name, hash, text and Z3's answer."""
    from cfmpa.proofs import Method, collect_obligations
    from cfmpa.proofs._obligation import proof_answer, standard_smtlib, vc_keys
    from cfmpa.proofs._pins import pin_key

    out, seen = [], set()
    for ob in collect_obligations(only=None if only is None else [only]):
        if ob.method is not Method.Z3 or pin_key(ob.id) in seen:
            continue
        seen.add(pin_key(ob.id))
        want = proof_answer(ob)
        vcs = ob.build().vcs
        for vc, name in zip(vcs, vc_keys(vcs), strict=True):
            text, sha, _ = standard_smtlib(vc)
            if text is not None:
                out.append({"key": pin_key(ob.id), "vc": name, "sha256": sha, "text": text,
                            "want": want})
    return out


def _measure(workers: Mapping[str, Any], strategy: str, text: str) -> tuple[str, float]:
    a = workers[strategy].check(text, strategy=strategy)
    return a.answer, a.cpu_seconds


def tune(rows: Sequence[dict[str, Any]], floor: float, log: Any = sys.stderr
         ) -> list[dict[str, Any]]:
    """Each row measured (``_measure``) and its strategy chosen (``choose``)."""
    from cfmpa.proofs._cvc5 import DEFAULT_STRATEGY, STRATEGIES, Cvc5Worker

    workers = {name: Cvc5Worker() for name in STRATEGIES}
    out = []
    try:
        for k, r in enumerate(rows):
            default = (("unknown", 0.0) if r.get("undecided")
                       else _measure(workers, DEFAULT_STRATEGY, r["text"]))
            others: dict[str, tuple[str, float]] = {}
            if default[0] != r["want"] or default[1] >= floor:
                for name in STRATEGIES:
                    if name != DEFAULT_STRATEGY:
                        others[name] = _measure(workers, name, r["text"])
                best = min((c for a, c in others.values() if a == r["want"]), default=None)
                if default[0] == r["want"] and best is not None and best < default[1]:
                    # A switch is measured again, each side keeping its slower run.
                    again = _measure(workers, DEFAULT_STRATEGY, r["text"])
                    default = (default[0], max(default[1], again[1]))
                    for name, (a, c) in list(others.items()):
                        if a == r["want"]:
                            others[name] = (a, max(c, _measure(workers, name, r["text"])[1]))
            chosen = choose(default, others, r["want"])
            answer = others[chosen][0] if chosen in others else default[0]
            out.append({"key": r["key"], "vc": r["vc"], "sha256": r["sha256"], "want": r["want"],
                        "default": list(default), "others": {n: list(v) for n, v in
                                                             others.items()},
                        "chosen": chosen, "answer": answer})
            print(f"[{k + 1}/{len(rows)}] {r['key']} {r['vc']}: {default[0]} {default[1]:.2f} s"
                  + "".join(f", {n} {a} {c:.2f} s" for n, (a, c) in others.items())
                  + f" -> {chosen}", file=log, flush=True)
    finally:
        for w in workers.values():
            w.close()
    return out


def lock_answer(row: Mapping[str, Any]) -> str:
    """What the lock records as cvc5's answer under the chosen strategy."""
    a = row["answer"]
    if a in ("sat", "unsat"):
        return str(a)
    return "undecided: " + ("not decided under any strategy" if row["others"]
                            else "not decided")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--write", action="store_true", help="name the choices in the lock")
    ap.add_argument("--lock", default=None, help="the lock (default proofs/obligations.lock)")
    ap.add_argument("--out", default="build/cvc5_strategies.json")
    ap.add_argument("--only", default=None, help="obligation ids (cfmpa prove --only's patterns)")
    ap.add_argument("--floor", type=float, default=0.15,
                    help="try other strategies on a statement whose default takes this long")
    ap.add_argument("--apply", default=None, metavar="FILE",
                    help="write the choices of an earlier run's --out FILE into the lock")
    args = ap.parse_args(argv)
    from cfmpa.files import write_json
    from cfmpa.proofs._pins import LOCK, cvc5_skips, cvc5_strategies, load_lock

    t0 = time.perf_counter()
    lock_path = Path(args.lock) if args.lock else LOCK
    pinned = load_lock(lock_path)
    if args.apply:
        import json

        got = [r for r in json.loads(Path(args.apply).read_text())["statements"]
               if pinned.get(r["key"], {}).get("vcs", {}).get(r["vc"]) == r["sha256"]]
        _write(got, pinned, lock_path)
        return 0
    rows = [r for r in statements(args.only)
            if pinned.get(r["key"], {}).get("vcs", {}).get(r["vc"]) == r["sha256"]]
    skips, chosen = cvc5_skips(pinned), cvc5_strategies(pinned, lock_path)
    for r in rows:    # undecided under the default when pinned: not run again under it
        r["undecided"] = r["sha256"] in skips and r["sha256"] not in chosen
    got = tune(rows, args.floor)
    write_json(args.out, {"seconds": round(time.perf_counter() - t0, 1), "floor_s": args.floor,
                          "ratio": RATIO, "margin_s": MARGIN_S, "new_decided_s": NEW_DECIDED_S,
                          "statements": got})
    print(f"wrote {args.out}: {len(got)} statements (only those the lock pins as they are now)")
    if args.write:
        _write(got, pinned, lock_path)
    return 0


def _write(got: Sequence[Mapping[str, Any]], pinned: Mapping[str, Any], lock_path: Path) -> None:
    """The choices into the lock, a line per change; a statement on the default strategy that
    the lock names none for is left as it is (its pinned answer too)."""
    from cfmpa.proofs._cvc5 import DEFAULT_STRATEGY
    from cfmpa.proofs._pins import record_cvc5_strategies

    choices = {(r["key"], r["vc"]): (r["chosen"], lock_answer(r)) for r in got
               if r["chosen"] != DEFAULT_STRATEGY
               or pinned[r["key"]].get("cvc5_strategy", {}).get(r["vc"])}
    for line in record_cvc5_strategies(choices, lock_path):
        print(line)


if __name__ == "__main__":
    raise SystemExit(main())
