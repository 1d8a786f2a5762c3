"""How many threads impl's compiled kernels use, and the one way to run them on that many.

A fork-safe threading layer (workqueue here; numba's OpenMP on Linux is GNU's, which aborts a
forked child that runs a parallel kernel once the parent has): the prove run, the audit and the
campaigns fork processes that build D_R. Workqueue is not thread-safe, so ``parallel`` holds a
lock: threads that run kernels at once (a multi-threaded Dask worker) take turns.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from typing import Any

import numba

__all__ = ["kernel_threads", "parallel", "set_kernel_threads"]

# numba.config's settings are set from the environment at import time: no static attributes.
if numba.config.THREADING_LAYER == "default":  # type: ignore[attr-defined]
    numba.config.THREADING_LAYER = "forksafe"  # type: ignore[attr-defined]
_LOCK = threading.Lock()

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


def parallel(kernel: Callable[..., Any], *args: Any) -> Any:
    """``kernel(*args)`` on kernel_threads() threads (numba's setting is per calling thread)."""
    with _LOCK:
        before = numba.get_num_threads()
        numba.set_num_threads(min(_THREADS[0],
                                  numba.config.NUMBA_NUM_THREADS))  # type: ignore[attr-defined]
        try:
            return kernel(*args)
        finally:
            numba.set_num_threads(before)
