"""What the safety theorem covers of a workcell, in one rule (docs/model.md §10).

The safety theorem (``Safety.*``, docs/model.md §10) covers every part of both arms: the link
rectangles, a tool fixed to a forearm and the parts' height intervals (docs/model.md §2; the
compositions range over every pair of parts the height rule keeps, §10 (e)). A feature a workcell
may have that the theorem does not cover would be listed in ``NOT_COVERED``; every place that
gives a workcell's verdict (``cfmpa plan``'s summary and plan.json, ``cfmpa prove``'s
per-workcell obligations, the report's first table) asks this one function, so none would say a
bare "proved" or "safe" of such a workcell. None is listed today.
"""

from __future__ import annotations

from collections.abc import Callable

from ._scenario import Scenario

__all__ = ["SCOPE_CHECKED", "theorem_scope"]

#: What is said of a feature the theorem does not cover, after naming it.
SCOPE_CHECKED = "checked on samples and by the certificate, not yet by the safety theorem"

#: The features of a workcell the safety theorem does not cover (a name and whether the workcell
#: has it), in the order they are named. Empty: tools and heights are covered (docs/model.md §10
#: (e)); what they still assume is the ledger's A13.
NOT_COVERED: tuple[tuple[str, Callable[[Scenario], bool]], ...] = ()


def theorem_scope(s: Scenario) -> str | None:
    """None where the safety theorem covers the workcell as written (every workcell the loader
    accepts, tools and heights included); else the NOT_COVERED features it has, joined by
    "and", followed by SCOPE_CHECKED: what a verdict of that workcell rests on instead of the
    theorem (docs/model.md §10)."""
    what = " and ".join(w for w, has in NOT_COVERED if has(s))
    return f"{what}: {SCOPE_CHECKED}" if what else None
