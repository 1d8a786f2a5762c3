"""searchoptpath without a compile: the reference's own search, with the fast search's
signature (docs/model.md §7.5).

The "numpy" kernel's search (``_kernels``): a run uses it while the fast kernels are compiled
in the background. It is ``search_opt_path`` itself (so bit-identical to it), and it makes the
witness unless told not to: a run under full contracts then verifies that witness instead of
asking the fast search for one (which would compile it in the foreground).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..spec import Cell, SearchResult
from ._search import search_opt_path

__all__ = ["search_opt_path_numpy"]


def search_opt_path_numpy(dr: npt.NDArray[np.integer], start: Cell, goal: Cell, *,
                          progress: bool | None = None, with_witness: bool = True
                          ) -> SearchResult:
    """``search_opt_path(dr, start, goal, with_witness=with_witness)``; ``progress`` is
    accepted for the fast search's signature and ignored."""
    del progress
    return search_opt_path(dr, start, goal, with_witness=with_witness)
