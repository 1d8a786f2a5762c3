"""The campaign's option budgets, in a module of their own: every command's parser reads them
(cfmpa._arguments.budgets), and importing the campaign itself would load the planner's compiled
kernels into `cfmpa certify` (a command imports only what it needs: tests/test_startup.py)."""

from __future__ import annotations

__all__ = ["MAX_DT", "MAX_WORKCELLS"]

#: The most workcells a campaign plans (--n): its bookkeeping is O(n) before the first task, and
#: a million is days of planning on a cluster; more is refused before the store is opened.
MAX_WORKCELLS = 1_000_000
#: The coarsest --dt accepted (s); the finest is what the cell budget allows (CFMPA_MAX_CELLS).
MAX_DT = 1.0
