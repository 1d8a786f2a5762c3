"""Each obligation in one plain sentence, for a reader who does not read the statements.

The audit report (docs/model.md §8) shows a summary on every obligation's card, with the full
statement folded out below it. A summary says what the obligation establishes in the paper's and
the robot's words: at most ``MAX_CHARS`` characters, no module, function or ledger names (the
statement has those). Each is declared with its obligation (``Obligation.summary``);
``SUMMARIES``, a view of the declarations, maps an obligation id, or a pattern whose ``*`` stands
for one dot-free part of the id (the workcell of a per-scenario check), to its sentence;
``{workcell}`` in a sentence is filled with that part. ``summary_problems`` is the check the
tests run over every registered obligation.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping

__all__ = ["FORBIDDEN", "MAX_CHARS", "SUMMARIES", "obligation_summary", "summary_problems"]

#: The longest summary allowed (a card's one line, two at most).
MAX_CHARS = 240

#: What a plain summary must not contain, each with what it would be: the names belong in the
#: statement, not in the sentence a reviewer reads first.
FORBIDDEN: tuple[tuple[str, re.Pattern[str]], ...] = (
    ("a module path", re.compile(r"\b(?:impl|spec|runs|proofs|report|cfmpa)\.")),
    ("a dotted code name", re.compile(r"\w+\.\w+_\w+")),
    ("an obligation id", re.compile(r"\b[A-Z][A-Za-z]*\d*\.[a-z]")),
    ("a code identifier", re.compile(r"\b[a-z]+_[a-z_]+\b|\w+\(\)")),
    ("a ledger id", re.compile(r"\bA\d+\b")),
    ("a code constant", re.compile(r"\b[A-Z]{4,}\b")),
    ("a file name", re.compile(r"\w\.(?:py|toml|md|json)\b")),
)


def _declared() -> dict[str, str]:
    """The summaries as declared (``Obligation.summary``): each fixed obligation's, then each
    per-scenario check's as a pattern, read off a declaration for a workcell named
    ``{workcell}`` (its text is then the pattern's sentence; the file is never read)."""
    from pathlib import Path

    from ._obl_scenario import scenario_obligations
    from ._runner import declared

    out = dict(declared().summaries)
    for o in scenario_obligations([Path("{workcell}.toml")]):
        if o.summary:
            out["Scenario.*." + o.id.rsplit(".", 1)[1]] = o.summary
    return out


#: Obligation id (or pattern) -> its plain summary: a view of the declarations.
SUMMARIES: dict[str, str] = _declared()


def obligation_summary(ident: str, summaries: Mapping[str, str] | None = None) -> str | None:
    """The plain summary of obligation ``ident``, or None when it has none: an exact key first,
    then a pattern (``*`` one dot-free part, filled in as ``{workcell}``), then the longest key
    that is a dotted prefix of ``ident``."""
    table = SUMMARIES if summaries is None else summaries
    if ident in table:
        return table[ident]
    parts = ident.split(".")
    for key, text in table.items():
        kp = key.split(".")
        if "*" in kp and len(kp) == len(parts) and all(k in ("*", p) for k, p in zip(kp, parts)):
            filled = [p for k, p in zip(kp, parts) if k == "*"]
            return text.format(workcell=filled[0])
    prefixes = [k for k in table if "*" not in k and ident.startswith(k + ".")]
    return table[max(prefixes, key=len)] if prefixes else None


def summary_problems(idents: Iterable[str], summaries: Mapping[str, str] | None = None
                     ) -> list[str]:
    """What is wrong with the summaries of ``idents``: a missing one, one longer than
    MAX_CHARS, or one holding a FORBIDDEN name (each named, with the id)."""
    out = []
    for ident in idents:
        text = obligation_summary(ident, summaries)
        if text is None:
            out.append(f"{ident}: no summary")
            continue
        if len(text) > MAX_CHARS:
            out.append(f"{ident}: {len(text)} characters, more than {MAX_CHARS}")
        for what, pattern in FORBIDDEN:
            hit = pattern.search(text)
            if hit:
                out.append(f"{ident}: {what} {hit.group(0)!r} in {text!r}")
    return out
