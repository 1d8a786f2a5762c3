"""The reference planner: kinematics, swept regions, BuiltDR, searchoptpath (clear first)."""

from ._builtdr import (ContainmentReport, LeftRegions, RightRegions, build_dr, check_containment,
                       contained_exactly, containment_slack, left_regions, left_spacing,
                       right_regions)
from ._builtdr_loops import build_dr_loops, builtdr_loop_nest
from ._fast_builtdr import build_dr_fast
from ._fast_search import search_opt_path_fast
from ._kernels import KERNELS, kernel_name, kernels
from ._kinematics import link_reach, link_rectangles
from ._progress import progress_default, progress_silenced
from ._search import search_opt_path
from ._threads import kernel_threads, set_kernel_threads
from ._regions import SNAP, convex_hull, lattice_range, naive_hull, sweep_margin, swept_region

__all__ = [
    "KERNELS", "SNAP", "ContainmentReport", "LeftRegions", "RightRegions", "build_dr",
    "build_dr_fast", "build_dr_loops", "builtdr_loop_nest", "check_containment", "contained_exactly",
    "containment_slack", "convex_hull", "kernel_name", "kernel_threads", "kernels", "lattice_range",
    "left_regions", "left_spacing", "link_reach", "link_rectangles", "naive_hull", "progress_default",
    "progress_silenced", "right_regions", "search_opt_path", "search_opt_path_fast", "sweep_margin",
    "set_kernel_threads", "swept_region",
]
