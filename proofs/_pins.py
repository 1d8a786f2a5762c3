"""Pinned statements: proofs/obligations.lock holds, per obligation id, the expected verdict and
the hash of every VC's statement, so that a changed premise, goal or constant fails the run
until it is re-pinned (``cfmpa prove --repin``), and the diff of the lock shows a reviewer what
changed.

- A Z3 obligation is pinned by each VC's hash: the sha256 of its proof check in standard
  SMT-LIB 2.6 (``_smtlib``; a function of the terms, not of Z3's printer), or of Z3's own text
  where there is no standard rendering. The words of the statement are not pinned (editing
  them changes no proof).
- A sympy or fixed data check is pinned by the hash of its canonical text (its source and
  inputs), ``source``.
- The per-scenario data checks (``Scenario.<stem>.<check>``) are pinned once per check, under
  ``Scenario.*.<check>``, by the hash of the check's source alone: the scenario data they read
  (the first line of their text: the file's name and sha256) is not a statement (it is recorded
  in results.json's run record instead), and a user's folder holds other files. Every
  scenario's check must match the one pin.

The lock is JSON, keys sorted, one obligation per entry; ``repin`` rewrites it and says which
ids were added, removed or changed, with the old and new hashes.

An entry also pins the obligation's kind (``kind``: ``theorem`` or ``definitional``, with
``kind_why``, the reason of proofs/_runner.py's DEFINITIONAL). ``repin`` writes the kind of an
obligation pinned for the first time and never changes a pinned one (it refreshes only the
reason of an unchanged kind): a theorem moved into the definitional list, or the reverse,
fails every run (``check_kinds``) until the lock is edited by hand, as an expected verdict
(pinned in the code) cannot be re-pinned either. An entry also records what cvc5
answered on each VC when it was pinned (``cvc5``; not part of the comparison): a run replays
in cvc5 only the statements cvc5 decided then (``cvc5_skips``: a decided one is a check, re-run
every time), since the same text gets the same answer; the others' answer is taken from the lock
and said so per VC; ``--repin`` and ``--recheck-undecided`` replay every one again. An entry
may name, per VC, the cvc5 strategy its replay runs under (``cvc5_strategy``, only where it is
not ``_cvc5.DEFAULT_STRATEGY``; not part of the comparison): the one measured quickest for that
statement (bench/tune_cvc5.py), found by the statement's hash (``cvc5_strategies``), so a changed
statement runs under the default until measured again; ``--repin`` keeps what each VC ran under.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from ..errors import InputError
from ..files import JsonStyle, write_json
from ._cvc5 import DEFAULT_STRATEGY, STRATEGIES
from ._obligation import Proof

__all__ = ["LOCK", "KindOf", "Mismatch", "check_kinds", "check_pins", "cvc5_skips",
           "cvc5_strategies", "load_lock", "pin_entry", "pin_key", "record_cvc5_strategies",
           "repin"]

#: The lock file shipped with the package (package data), next to this module.
LOCK = Path(__file__).with_name("obligations.lock")

_FORMAT = "cfmpa obligations lock 1"

Mismatch = tuple[str, str]     # (obligation id, what differs)
#: An obligation id -> (its kind, why): proofs/_runner.py's kind_of and DEFINITIONAL.
KindOf = Callable[[str], tuple[str, str]]
#: What an entry holds besides its statement (not part of the statement's comparison).
_NOT_STATEMENT = ("cvc5", "cvc5_strategy", "kind", "kind_why")


def pin_key(ident: str) -> str:
    """The lock's key for an obligation id: per-scenario checks share ``Scenario.*.<check>``."""
    parts = ident.split(".")
    if len(parts) >= 3 and parts[0] == "Scenario":
        return f"Scenario.*.{parts[-1]}"
    return ident


def pin_entry(p: Proof) -> dict[str, Any]:
    """What the lock holds for a proof: its expected verdict and its statement hashes."""
    entry: dict[str, Any] = {"expected": p.expected.value}
    if "source" in p.pins:
        entry["source"] = p.pins["source"]
    else:
        entry["vcs"] = dict(sorted(p.pins.items()))
        entry["cvc5"] = {v.name: v.cvc5 if v.cvc5 in ("sat", "unsat")
                         else f"undecided: {_reason_class(v.cvc5_reason)}" for v in p.vcs}
        chosen = {v.name: v.cvc5_strategy for v in p.vcs
                  if v.cvc5_strategy not in ("", DEFAULT_STRATEGY)}
        if chosen:
            entry["cvc5_strategy"] = chosen
    return entry


_KILLED = re.compile(r"killed after [0-9.]+ s (?:of CPU )?"
                     r"\(cvc5 overran its (\d+) ms limit('s wall-clock net)?\)")


def _reason_class(reason: str | None) -> str:
    """Why cvc5 did not decide a VC, without the seconds a kill took (they follow the load, not
    the statement): "overran its 5000 ms limit (killed)" for every such kill."""
    if not reason:
        return "not replayed"
    m = _KILLED.fullmatch(reason)
    return f"overran its {m.group(1)} ms limit{m.group(2) or ''} (killed)" if m else reason


def _statement(entry: dict[str, Any]) -> dict[str, Any]:
    """The part of an entry a run must match as its statement (cvc5's recorded answers are not;
    the kind is matched by ``check_kinds``, which --repin cannot silence)."""
    return {k: v for k, v in entry.items() if k not in _NOT_STATEMENT}


def cvc5_skips(lock: dict[str, dict[str, Any]]) -> dict[str, str]:
    """Statement hash -> why cvc5 did not decide it when pinned (a run takes that answer from
    the lock instead of replaying it, unless ``--recheck-undecided`` or ``--repin``)."""
    out: dict[str, str] = {}
    for entry in lock.values():
        answers = entry.get("cvc5") or {}
        for name, sha in (entry.get("vcs") or {}).items():
            a = answers.get(name, "")
            if isinstance(a, str) and a.startswith("undecided"):
                out[sha] = a.removeprefix("undecided: ")
    return out


def cvc5_strategies(lock: dict[str, dict[str, Any]], source: str | Path | None = None
                    ) -> dict[str, str]:
    """Statement hash -> the cvc5 strategy the lock names for it (``cvc5_strategy``; a
    statement not named runs under ``_cvc5.DEFAULT_STRATEGY``). InputError (naming ``source``,
    the lock) for a name that is not one of ``_cvc5.STRATEGIES`` or a VC the entry does not
    pin."""
    where = None if source is None else str(source)
    out: dict[str, str] = {}
    for key, entry in lock.items():
        chosen = entry.get("cvc5_strategy") if isinstance(entry, dict) else None
        if not chosen:
            continue
        vcs = entry.get("vcs")
        if not isinstance(chosen, dict) or not isinstance(vcs, dict):
            raise InputError(f"{key}.cvc5_strategy", _shown(chosen), "must map the names of "
                             "the VCs the entry pins (its vcs) to strategies", source=where)
        for name, strategy in chosen.items():
            if not isinstance(strategy, str) or strategy not in STRATEGIES:
                raise InputError(f"{key}.cvc5_strategy.{name}", _shown(strategy),
                                 f"is not one of {', '.join(sorted(STRATEGIES))}", source=where)
            if name not in vcs:
                raise InputError(f"{key}.cvc5_strategy.{name}", strategy,
                                 "names a VC the entry does not pin", source=where)
            out[vcs[name]] = strategy
    return out


def _shown(value: object) -> object:
    """``value`` as an error message shows it: a long one cut (a lock is read whole)."""
    text = repr(value)
    return value if len(text) <= 80 else text[:77] + "..."


def record_cvc5_strategies(choices: dict[tuple[str, str], tuple[str, str]],
                           path: str | Path | None = None) -> list[str]:
    """Write into the lock, per (entry key, VC name), the strategy its replay runs under and
    cvc5's answer under it (``sat``, ``unsat`` or ``undecided: why``), as measured
    (bench/tune_cvc5.py); the default strategy is written as no entry. Statements and kinds are
    untouched. Returns a line per change; KeyError for a VC the lock does not pin, ValueError
    for a strategy not in ``_cvc5.STRATEGIES`` (nothing written then)."""
    f = Path(path) if path is not None else LOCK
    doc = json.loads(f.read_text(encoding="utf-8"))
    obs = doc["obligations"]
    bad = sorted({st for st, _ in choices.values() if st not in STRATEGIES})
    if bad:
        raise ValueError(f"strategy={bad[0]!r} is not one of {sorted(STRATEGIES)}")
    lines = []
    for (key, name), (strategy, answer) in sorted(choices.items()):
        entry = obs[key]
        if name not in entry.get("vcs", {}):
            raise KeyError(f"{key} pins no VC {name!r}")
        chosen = dict(entry.get("cvc5_strategy") or {})
        before = (chosen.get(name, DEFAULT_STRATEGY), entry.get("cvc5", {}).get(name))
        if strategy == DEFAULT_STRATEGY:
            chosen.pop(name, None)
        else:
            chosen[name] = strategy
        if chosen:
            entry["cvc5_strategy"] = chosen
        else:
            entry.pop("cvc5_strategy", None)
        entry.setdefault("cvc5", {})[name] = answer
        if before != (strategy, answer):
            lines.append(f"{key} {name}: {before[0]} ({before[1]}) -> {strategy} ({answer})")
    write_json(f, doc, JsonStyle.LOCK, ascii_only=False, allow_nan=True)   # keys sorted
    return lines


def load_lock(path: str | Path | None = None) -> dict[str, dict[str, Any]]:
    """The pinned entries by key ({} for a missing or unreadable lock: nothing is pinned)."""
    f = Path(path) if path is not None else LOCK
    try:
        doc = json.loads(f.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    obs = doc.get("obligations") if isinstance(doc, dict) else None
    # An entry that is not an object pins nothing (its id is then "not pinned").
    return ({k: v for k, v in obs.items() if isinstance(v, dict)} if isinstance(obs, dict)
            else {})


def _short(h: object) -> str:
    return str(h)[:12] if h else "absent"


def _diff(old: dict[str, Any], new: dict[str, Any]) -> str:
    parts = []
    if old.get("expected") != new.get("expected"):
        parts.append(f"expected {old.get('expected')} -> {new.get('expected')}")
    if old.get("source") != new.get("source"):
        parts.append(f"source {_short(old.get('source'))} -> {_short(new.get('source'))}")
    ov, nv = old.get("vcs") or {}, new.get("vcs") or {}
    for name in sorted(set(ov) | set(nv)):
        if ov.get(name) != nv.get(name):
            parts.append(f"VC {name}: {_short(ov.get(name))} -> {_short(nv.get(name))}")
    return "; ".join(parts)


def check_pins(proofs: Iterable[Proof], lock: dict[str, dict[str, Any]]) -> list[Mismatch]:
    """Every proof whose statement is not the pinned one: not pinned at all, or changed."""
    out: list[Mismatch] = []
    for p in proofs:
        entry = pin_entry(p)
        old = lock.get(pin_key(p.id))
        if old is None:
            out.append((p.id, "not pinned (a new obligation)"))
        elif _statement(old) != _statement(entry):
            out.append((p.id, "statement changed, not re-pinned: " + _diff(old, entry)))
    return out


def check_kinds(proofs: Iterable[Proof], lock: dict[str, dict[str, Any]],
                kind_of: KindOf) -> list[Mismatch]:
    """Every proof whose kind in the code (``kind_of``) is not the kind the lock pins, or whose
    entry pins none (a lock from before kinds were pinned: ``--repin`` adds them)."""
    out: list[Mismatch] = []
    for p in proofs:
        old = lock.get(pin_key(p.id))
        if old is None:
            continue                    # not pinned at all: check_pins says so
        kind, _ = kind_of(p.id)
        if "kind" not in old:
            out.append((p.id, f"its kind ({kind}) is not pinned (cfmpa prove --repin pins it)"))
        elif old["kind"] != kind:
            out.append((p.id, f"kind {kind} in the code, {old['kind']} pinned: --repin never "
                              "changes a kind (edit proofs/obligations.lock by hand, with the "
                              "reason, if the change is meant)"))
    return out


def repin(proofs: Iterable[Proof], path: str | Path | None = None, *,
          complete: bool = True, kind_of: KindOf | None = None) -> list[str]:
    """Rewrite the lock with the proofs' statements; return the changes, one line each.

    ``complete``: the proofs are a whole run, so a pinned id not among them is removed (with
    ``--only`` the others are kept as they are). ``kind_of``: the kind of an id not pinned yet
    (or pinned without one) is written; a pinned kind is kept whatever the code says."""
    f = Path(path) if path is not None else LOCK
    old = load_lock(f)
    new: dict[str, dict[str, Any]] = {} if complete else dict(old)
    produced: dict[str, dict[str, Any]] = {}
    conflicts = []
    for p in proofs:
        key, entry = pin_key(p.id), pin_entry(p)
        before = old.get(key, {})
        if "kind" in before:
            entry["kind"] = before["kind"]
            entry["kind_why"] = before.get("kind_why", "")
            if kind_of is not None and kind_of(p.id)[0] == before["kind"]:
                entry["kind_why"] = kind_of(p.id)[1]
        elif kind_of is not None:
            entry["kind"], entry["kind_why"] = kind_of(p.id)
        if key in produced and _statement(produced[key]) != _statement(entry):
            conflicts.append(f"conflict: {p.id} is not {key} as pinned by another scenario")
        produced.setdefault(key, entry)
    new.update(produced)
    lines = []
    for key in sorted(set(old) | set(new)):
        if key not in old:
            lines.append(f"added   {key}")
        elif key not in new:
            lines.append(f"removed {key}")
        elif _statement(old[key]) != _statement(new[key]):
            lines.append(f"changed {key}: {_diff(old[key], new[key])}")
    doc = {"format": _FORMAT,
           "note": "Written by `cfmpa prove --repin`: review the diff. Per obligation, the "
                   "expected verdict and the sha256 of each VC's statement in standard SMT-LIB "
                   "2.6 (or of a check's source); per-scenario checks once, as Scenario.*.",
           "obligations": {k: new[k] for k in sorted(new)}}
    write_json(f, doc, JsonStyle.LOCK, ascii_only=False, allow_nan=True)
    return conflicts + lines
