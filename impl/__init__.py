"""The reference planner: kinematics, swept regions, BuiltDR, searchoptpath (clear first)."""

from typing import TYPE_CHECKING

from ..lazy import lazy_exports

if TYPE_CHECKING:     # the names as the type checker sees them; at run time, _EXPORTS
    from ._builtdr import (ContainmentReport, LeftRegions, RightRegions, build_dr, check_containment,
                           contained_exactly, containment_slack, left_regions, left_spacing,
                           right_regions)
    from ._builtdr_loops import build_dr_loops, builtdr_loop_nest
    from ._fast_builtdr import build_dr_fast
    from ._fast_search import search_opt_path_fast
    from ._kernel_cache import ensure_compiled, load_fast_kernels
    from ._kernels import KERNELS, kernel_name, kernels
    from ._kinematics import link_reach, link_rectangles
    from ._progress import Progress, progress_default, progress_silenced
    from ._search import search_opt_path
    from ._threads import kernel_threads, set_kernel_threads
    from ._regions import SNAP, convex_hull, lattice_range, naive_hull, sweep_margin, swept_region

#: Each public name -> "module:name", imported on first use (PEP 562, cfmpa.lazy): a
#: command loads only the modules it needs (docs/model.md §1.1).
_EXPORTS: dict[str, str] = {
    "ContainmentReport": "._builtdr:ContainmentReport",
    "LeftRegions": "._builtdr:LeftRegions",
    "RightRegions": "._builtdr:RightRegions",
    "build_dr": "._builtdr:build_dr",
    "check_containment": "._builtdr:check_containment",
    "contained_exactly": "._builtdr:contained_exactly",
    "containment_slack": "._builtdr:containment_slack",
    "left_regions": "._builtdr:left_regions",
    "left_spacing": "._builtdr:left_spacing",
    "right_regions": "._builtdr:right_regions",
    "build_dr_loops": "._builtdr_loops:build_dr_loops",
    "builtdr_loop_nest": "._builtdr_loops:builtdr_loop_nest",
    "build_dr_fast": "._fast_builtdr:build_dr_fast",
    "search_opt_path_fast": "._fast_search:search_opt_path_fast",
    "ensure_compiled": "._kernel_cache:ensure_compiled",
    "load_fast_kernels": "._kernel_cache:load_fast_kernels",
    "KERNELS": "._kernels:KERNELS",
    "kernel_name": "._kernels:kernel_name",
    "kernels": "._kernels:kernels",
    "link_reach": "._kinematics:link_reach",
    "link_rectangles": "._kinematics:link_rectangles",
    "Progress": "._progress:Progress",
    "progress_default": "._progress:progress_default",
    "progress_silenced": "._progress:progress_silenced",
    "search_opt_path": "._search:search_opt_path",
    "kernel_threads": "._threads:kernel_threads",
    "set_kernel_threads": "._threads:set_kernel_threads",
    "SNAP": "._regions:SNAP",
    "convex_hull": "._regions:convex_hull",
    "lattice_range": "._regions:lattice_range",
    "naive_hull": "._regions:naive_hull",
    "sweep_margin": "._regions:sweep_margin",
    "swept_region": "._regions:swept_region",
}

__all__ = [
    "KERNELS", "SNAP", "ContainmentReport", "LeftRegions", "Progress", "RightRegions", "build_dr",
    "build_dr_fast", "build_dr_loops", "builtdr_loop_nest", "check_containment", "contained_exactly",
    "containment_slack", "convex_hull", "ensure_compiled", "kernel_name", "kernel_threads",
    "kernels", "lattice_range", "left_regions", "left_spacing", "link_reach", "link_rectangles",
    "load_fast_kernels", "naive_hull", "progress_default",
    "progress_silenced", "right_regions", "search_opt_path", "search_opt_path_fast", "sweep_margin",
    "set_kernel_threads", "swept_region",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, __all__)
