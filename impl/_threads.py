"""How many threads impl's compiled kernels use, and the one way to run them on that many.

``shared`` runs a kernel compiled with ``nogil=True`` once per thread, each call doing its own
share: plain Python threads, started and joined within the call. No kernel is ``parallel=True``,
so numba's threading layer is never started: its compile machinery cost seconds of the first
run (docs/model.md §7.5), and its OpenMP layer aborts a forked child that runs a parallel kernel
once the parent has (the prove run, the audit and the campaigns fork processes that build D_R).
Calls from several threads at once (a multi-threaded Dask worker) each run their own threads.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from typing import Any

__all__ = ["kernel_threads", "set_kernel_threads", "shared"]

#: Two where the machine has two cores or more; one in processes that run side by side (the
#: prove run's workers, the audit's second process, a local campaign's workers), which call
#: set_kernel_threads(1).
_THREADS = [min(2, os.cpu_count() or 1)]


def kernel_threads() -> int:
    """The threads the compiled kernels run on (see set_kernel_threads)."""
    return _THREADS[0]


def set_kernel_threads(k: int) -> None:
    """Run impl's parallel kernels on ``k`` threads (at most NUMBA_NUM_THREADS) from now on."""
    if isinstance(k, bool) or not isinstance(k, int) or k < 1:
        raise ValueError(f"k={k!r} must be an integer >= 1")
    _THREADS[0] = k


def shared(kernel: Callable[..., Any], *args: Any) -> None:
    """``kernel(t, k, *args)`` for t = 0 .. k - 1 at once, k = kernel_threads() (at most
    NUMBA_NUM_THREADS): ``kernel`` is compiled with nogil=True, does share t of k and writes
    nothing another share writes. Share 0 runs on the calling thread; an exception in any share
    is raised here once all have ended."""
    import numba  # here: kernel_threads alone (a run on the numpy kernels) needs none

    k = min(_THREADS[0], numba.config.NUMBA_NUM_THREADS)  # type: ignore[attr-defined]
    if k <= 1:
        kernel(0, 1, *args)
        return
    errors: list[BaseException] = []

    def run(t: int) -> None:
        try:
            kernel(t, k, *args)
        except BaseException as exc:  # noqa: BLE001 - re-raised below, on the calling thread
            errors.append(exc)

    threads = [threading.Thread(target=run, args=(t,), daemon=True) for t in range(1, k)]
    for th in threads:
        th.start()
    run(0)
    for th in threads:
        th.join()
    if errors:
        raise errors[0]
