"""The audit report's parts as data: a ``Section`` per part (docs/model.md §8).

A section names its report.json part(s), its title, how it is computed, the checks it adds to
the report's verdict and the template file that shows it. ``build_audit`` computes the sections
of one tuple (``report._audit.SECTIONS``), the page shows them in that tuple's order, and the
verdict ("What this run checked") is the sections' own checks, in the same order. So adding a
part is one Section, its template file and its test.

The order a section is *computed* in may differ from the order it is shown in: a section lists
the parts it ``needs`` (computed before it), and a ``deferred`` one (the proofs) is computed after
every other that does not need it, so that `cfmpa prove --audit` computes the plans, pictures and
campaign while the obligations are still being discharged.
"""

from __future__ import annotations

import html
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

__all__ = ["Check", "STATUSES", "Section", "compute_order", "numbers", "verdict_of"]

#: A check of the report's verdict: report.json (every part computed) -> one verdict item,
#: ``{"check": name, "ok": True | False | None (not available), "detail": text}``.
Check = Callable[[Mapping[str, Any]], dict[str, Any]]


@dataclass(frozen=True)
class Section:
    """A part of the audit report.

    ``key``: its report.json part (and the section's name); ``more``: further top-level parts it
    writes (the scenarios' ``triples``). ``compute(context)`` returns ``{key: part, **more}``;
    ``context`` is the build's (``report._audit._Context``) with the parts computed so far in
    ``context.doc``. ``needs``: the parts ``compute`` reads, computed first. ``deferred``: computed
    after every section that does not need it. ``finish(doc)``, when given, runs once every part
    is computed, for what a part shows of parts computed after it (a finding's related
    obligations). ``checks``: its items of the report's verdict. ``template``: the file (in this
    package) that shows it, included in the page in the order of the sections' tuple.
    ``contents``: its entries in the page's contents (``contents_entries``). ``headings``: how
    many numbered headings its template has (``number`` gives the first its number)."""

    key: str
    title: str
    compute: Callable[[Any], dict[str, Any]]
    template: str
    checks: tuple[Check, ...] = ()
    needs: tuple[str, ...] = ()
    more: tuple[str, ...] = ()
    deferred: bool = False
    finish: Callable[[dict[str, Any]], None] | None = None
    contents: tuple[str, ...] | None = None
    headings: int = 1

    def contents_entries(self) -> tuple[str, ...]:
        """Its entries in the page's list of contents, each a Jinja template (of report.json as
        ``doc``) of one entry's HTML: ``contents``, or a link to ``#key`` named by the title."""
        if self.contents is not None:
            return self.contents
        return (f'<a href="#{html.escape(self.key)}">{html.escape(self.title)}</a>',)

    @property
    def keys(self) -> tuple[str, ...]:
        """Every report.json part this section writes."""
        return (self.key, *self.more)


def compute_order(sections: Sequence[Section]) -> tuple[Section, ...]:
    """The sections in the order they are computed: the tuple's order, the deferred ones after the
    others, each after the sections writing the parts it needs. ValueError for two sections
    writing one part, or a need no section writes, or a cycle."""
    writer: dict[str, Section] = {}
    for s in sections:
        for k in s.keys:
            if k in writer:
                raise ValueError(f"sections {writer[k].key!r} and {s.key!r} both write {k!r}")
            writer[k] = s
    for s in sections:
        unknown = [n for n in s.needs if n not in writer]
        if unknown:
            raise ValueError(f"section {s.key!r} needs {unknown}, which no section writes")
    pending = sorted(sections, key=lambda s: s.deferred)      # stable: the tuple's order
    done: set[str] = set()
    order: list[Section] = []
    while pending:
        ready = next((s for s in pending if set(s.needs) <= done), None)
        if ready is None:
            raise ValueError(f"the sections {[s.key for s in pending]} need each other")
        order.append(ready)
        done.update(ready.keys)
        pending.remove(ready)
    return tuple(order)


#: The report's overall status (the pill of section 1 and of "What this run checked"), worst
#: first: a check failed; none failed but one is not available (not run here, or a verdict row
#: whose proofs did not all run), so the verdict rests on less than it needs; every check holds.
STATUSES = ("FAILED", "incomplete", "no failure")


def verdict_of(doc: Mapping[str, Any], sections: Sequence[Section]) -> dict[str, Any]:
    """The report's verdict: every section's checks in the sections' order; ``ok``, which is
    False when any item is False (None, not available, counts neither way: the exit code);
    ``status`` (STATUSES): "FAILED" when ``ok`` is False, else "incomplete" when any item is
    None, else "no failure"; ``not_available``: the checks that are None."""
    items = [check(doc) for s in sections for check in s.checks]
    ok = all(i["ok"] is not False for i in items)
    short = [i["check"] for i in items if i["ok"] is None]
    return {"ok": ok, "status": STATUSES[0] if not ok else STATUSES[1] if short else STATUSES[2],
            "not_available": short, "items": items}


def numbers(sections: Sequence[Section]) -> dict[str, int]:
    """Each section's number on the page (key -> the number of its first heading): 1, 2, ...
    in the tuple's order, a section with several headings taking as many numbers. The templates
    number their headings and cross-references from it, so a section added anywhere renumbers
    the rest."""
    out, n = {}, 1
    for s in sections:
        out[s.key] = n
        n += s.headings
    return out
