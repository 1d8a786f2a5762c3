"""The reference planner: kinematics, swept regions, BuiltDR, searchoptpath (clear first).

The public names are listed once, below (``cfmpa.lazy``): each is imported on first use, so a
command loads only the modules it needs (docs/model.md §1.1).
"""

from typing import TYPE_CHECKING

from ..lazy import lazy_face

if TYPE_CHECKING:     # the public names, one list: the type checker's and __all__ (cfmpa.lazy)
    # swept regions and BuiltDR (docs/model.md §4)
    from ._kinematics import link_reach as link_reach, link_rectangles as link_rectangles
    from ._regions import (SNAP as SNAP, convex_hull as convex_hull, lattice_range as lattice_range,
                           naive_hull as naive_hull, sweep_margin as sweep_margin,
                           swept_region as swept_region)
    from ._builtdr import (LeftRegions as LeftRegions, RightRegions as RightRegions,
                           build_dr as build_dr, check_containment as check_containment,
                           contained_exactly as contained_exactly,
                           containment_slack as containment_slack, left_regions as left_regions,
                           left_spacing as left_spacing, right_regions as right_regions)
    from ._builtdr_loops import (build_dr_loops as build_dr_loops,
                                 builtdr_loop_nest as builtdr_loop_nest)
    # searchoptpath (docs/model.md §5)
    from ._search import search_opt_path as search_opt_path
    # the kernels a run picks by name, the fast ones and their compile cache, threads, progress
    from ._kernels import (KERNELS as KERNELS, kernel_name as kernel_name, kernels as kernels,
                           resolved as resolved)
    from ._fast_regions import (left_regions_fast as left_regions_fast,
                                right_regions_fast as right_regions_fast)
    from ._fast_builtdr import (build_dr_fast as build_dr_fast,
                                build_from_regions as build_from_regions)
    from ._fast_search import search_opt_path_fast as search_opt_path_fast
    from ._kernel_cache import (ensure_compiled as ensure_compiled,
                                load_fast_kernels as load_fast_kernels)
    from ._threads import kernel_threads as kernel_threads, set_kernel_threads as set_kernel_threads
    from ._progress import Progress as Progress, progress_silenced as progress_silenced

__getattr__, __dir__, __all__ = lazy_face(__name__, __file__)
