"""What the safety theorem covers of a workcell, in one rule (docs/model.md §10).

The safety theorem (``Safety.*``, docs/model.md §10) is proved for planar arms of two link
rectangles each. A tool fixed to a forearm, or height intervals of the parts (docs/model.md §2),
are modelled by the geometry, D_R's cells and the continuous-time certificate (§4, §7.2), but not
yet by that theorem. Every place that gives a workcell's verdict (``cfmpa plan``'s summary and
plan.json, ``cfmpa prove``'s per-workcell obligations, the report's first table) asks this one
function, so none says a bare "proved" or "safe" of such a workcell.
"""

from __future__ import annotations

from ._scenario import Scenario

__all__ = ["SCOPE_CHECKED", "theorem_scope"]

#: What is said of a tool or of heights, after naming them.
SCOPE_CHECKED = "checked on samples and by the certificate, not yet by the safety theorem"


def theorem_scope(s: Scenario) -> str | None:
    """None where the safety theorem covers the workcell as written (no tool, no heights on
    either arm); else ``"tool: ..."``, ``"heights: ..."`` or ``"tool and heights: ..."``
    followed by SCOPE_CHECKED: what a verdict of that workcell rests on instead of the theorem
    (docs/model.md §10)."""
    arms = (s.left, s.right)
    tool = any(arm.tool is not None for arm in arms)
    heights = any(arm.z is not None or (arm.tool is not None and arm.tool.z is not None)
                  for arm in arms)
    what = " and ".join(w for w, has in (("tool", tool), ("heights", heights)) if has)
    return f"{what}: {SCOPE_CHECKED}" if what else None
