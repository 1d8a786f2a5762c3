"""The titles of the obligation groups more than one catalogue module declares obligations in
(docs/model.md §6): one spelling, imported by each."""

from __future__ import annotations

__all__ = ["GROUP_CERTIFICATE", "GROUP_EXACT", "GROUP_TUBE"]

GROUP_CERTIFICATE = "Continuous-time certificate (docs/model.md §7.2)"
GROUP_TUBE = "Trajectories (docs/model.md §12)"
GROUP_EXACT = "Exact re-decision (docs/model.md §7.2)"
