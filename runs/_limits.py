"""The option budgets of the campaign and of `cfmpa simulate`, in a module of their own: every
command's parser reads them (cfmpa._arguments.budgets), and importing the campaign would load
the planner's compiled kernels into `cfmpa certify`, the trajectory runs the bag reader into
`cfmpa dr` (a command imports only what it needs: tests/test_startup.py)."""

from __future__ import annotations

__all__ = ["MAX_DT", "MAX_LOG_SAMPLES", "MAX_WORKCELLS", "MIN_PERIOD_S"]

#: The most workcells a campaign plans (--n): its bookkeeping is O(n) before the first task, and
#: a million is days of planning on a cluster; more is refused before the store is opened.
MAX_WORKCELLS = 1_000_000
#: The coarsest --dt accepted (s); the finest is what the cell budget allows (CFMPA_MAX_CELLS).
MAX_DT = 1.0
#: The most samples `cfmpa simulate` writes: the log is built in memory (about 0.5 KB a sample
#: at its peak, a 100 MB CSV), so a count beyond is refused before anything is allocated.
MAX_LOG_SAMPLES = 1_000_000
#: The shortest --period (s): a 1 MHz log; finer is no measured robot's.
MIN_PERIOD_S = 1e-6
