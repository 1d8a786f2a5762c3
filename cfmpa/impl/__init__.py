"""The reference planner: kinematics, swept regions, BuiltDR, searchoptpath (clear first)."""

from ._builtdr import (ContainmentReport, LeftRegions, RightRegions, build_dr, check_containment,
                       left_regions, right_regions)
from ._fast_builtdr import build_dr_fast
from ._fast_search import search_opt_path_fast
from ._kinematics import link_reach, link_rectangles
from ._search import search_opt_path
from ._regions import convex_hull, lattice_range, naive_hull, sweep_margin, swept_region

__all__ = [
    "ContainmentReport", "LeftRegions", "RightRegions", "build_dr", "build_dr_fast",
    "check_containment",
    "convex_hull", "lattice_range", "left_regions", "link_reach", "link_rectangles", "naive_hull",
    "right_regions", "search_opt_path", "search_opt_path_fast", "sweep_margin", "swept_region",
]
