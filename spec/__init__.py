"""The paper's definitions, triples and properties as executable predicates (imports no impl).

The same definitions as Z3 terms are the public module ``cfmpa.spec.z3defs``. The public names
are listed once, below (``cfmpa.lazy``): each is imported on first use, so a command loads only
the modules it needs (docs/model.md §1.1).
"""

from typing import TYPE_CHECKING

from ..lazy import lazy_face

if TYPE_CHECKING:     # the public names, one list: the type checker's and __all__ (cfmpa.lazy)
    # scenario, grids and motion (docs/model.md §2-§3)
    from ._scenario import (Arm as Arm, Scenario as Scenario, Tool as Tool,
                            load_scenario as load_scenario, max_cells as max_cells,
                            parse_scenario as parse_scenario,
                            whole_max_cells as whole_max_cells)
    from ._grid import (DISTANCE_ERROR_M as DISTANCE_ERROR_M, EPS as EPS,
                        MAX_COORD_M as MAX_COORD_M, Grid as Grid, Variant as Variant,
                        cell_box as cell_box, exact_n as exact_n, exact_tf as exact_tf,
                        left_angles as left_angles, left_box as left_box, make_grid as make_grid,
                        ptp_angles as ptp_angles, ptp_fraction as ptp_fraction,
                        rest_box as rest_box, right_box as right_box)
    from ._counts import (MAX_SPACING as MAX_SPACING, Written as Written, decimal as decimal,
                          joint_grid as joint_grid,
                          joint_points as joint_points, spacing_conditions as spacing_conditions)
    # one definition on floats and on Z3 terms (the rules the proofs read)
    from ._arith import (cases as cases, ceil_of as ceil_of, floor_of as floor_of,
                         hypot_of as hypot_of, if_then as if_then, max_of as max_of,
                         min_of as min_of, sqrt_of as sqrt_of)
    # parts (links and tool), heights and their names (docs/model.md §2)
    from ._kinematics import (TOOL as TOOL, arm_parts as arm_parts, height_gap as height_gap,
                              heights_overlap as heights_overlap, link_name as link_name,
                              pairs_to_test as pairs_to_test, part_height as part_height,
                              part_points as part_points, parts as parts, reach as reach)
    from ._polygon import polygon_distance as polygon_distance
    # the certificate, the motions it samples and its constants (docs/model.md §7)
    from ._certificate import (Certificate as Certificate, GridMotion as GridMotion,
                               certificate_json as certificate_json, certify as certify,
                               closest_links as closest_links,
                               contact_links_text as contact_links_text,
                               contact_parts as contact_parts, interval_bound as interval_bound,
                               link_speeds as link_speeds, pair_lipschitz as pair_lipschitz,
                               part_distances as part_distances, pose_distance as pose_distance,
                               require_clear as require_clear)
    # what the safety theorem covers of a workcell (docs/model.md §10)
    from ._scope import theorem_scope as theorem_scope
    # paths (docs/model.md §5)
    from ._paths import (J1 as J1, J2 as J2, MOVES as MOVES,
                         REASON_GOAL_BLOCKED as REASON_GOAL_BLOCKED,
                         REASON_START_BLOCKED as REASON_START_BLOCKED,
                         REASON_UNREACHABLE as REASON_UNREACHABLE, Cell as Cell,
                         SearchResult as SearchResult, SearchStatus as SearchStatus,
                         check_search_inputs as check_search_inputs, is_opt_path as is_opt_path,
                         is_path as is_path, is_path_paper as is_path_paper, opt_path as opt_path,
                         path_violations as path_violations)
    # triples and their executable conditions (docs/model.md §7)
    from ._triples import (Failure as Failure, Triple as Triple, builtdr_triple as builtdr_triple,
                           cells_failures as cells_failures, cost_failures as cost_failures,
                           dr_cell_failures as dr_cell_failures,
                           dr_shape_failures as dr_shape_failures, grid_failures as grid_failures,
                           path_cells as path_cells, search_failures as search_failures,
                           search_triple as search_triple)
    # witnesses of the search's answer and their conditions (docs/model.md §11)
    from ._witness import (KEY_BASE as KEY_BASE, Witness as Witness, check_witness as check_witness,
                           closure_breaks as closure_breaks, edge_bound as edge_bound,
                           edge_holds as edge_holds, exclusion_breaks as exclusion_breaks,
                           goal_holds as goal_holds, label_in_range as label_in_range,
                           label_key as label_key, load_witness as load_witness,
                           start_breaks as start_breaks, start_label_breaks as start_label_breaks,
                           step_cost as step_cost, stop_key as stop_key)
    # arrays read one layer at a time (the witness on large grids)
    from ._layers import (SPILL_BYTES as SPILL_BYTES, LayerSpill as LayerSpill, Layers as Layers,
                          save_npz as save_npz, spill_wanted as spill_wanted)
    # the path's cells re-decided in ball arithmetic (docs/model.md §7)
    from ._exact import (ExactGaps as ExactGaps, exact_path_gaps as exact_path_gaps,
                         gap_over_norm as gap_over_norm, projection_bounds as projection_bounds)
    # trajectories, the tolerance tube and the monitor between samples (docs/model.md §12)
    from ._trajectory import (CHUNK_ROWS as CHUNK_ROWS, TRAJECTORY_COLUMNS as TRAJECTORY_COLUMNS,
                              ReferenceSpeeds as ReferenceSpeeds,
                              StreamedReference as StreamedReference, Trajectory as Trajectory,
                              TrajectoryMotion as TrajectoryMotion,
                              TrajectorySummary as TrajectorySummary,
                              WholeReference as WholeReference,
                              between_samples_bound as between_samples_bound,
                              certify_trajectory as certify_trajectory,
                              certify_trajectory_file as certify_trajectory_file,
                              certify_trajectory_rows as certify_trajectory_rows,
                              csv_column_order as csv_column_order,
                              executed_trajectory as executed_trajectory,
                              load_trajectory as load_trajectory, log_end_bound as log_end_bound,
                              parse_trajectory_csv as parse_trajectory_csv,
                              row_blocks as row_blocks, tolerance_rad as tolerance_rad,
                              trajectory_csv as trajectory_csv,
                              trajectory_distances as trajectory_distances,
                              trajectory_file_blocks as trajectory_file_blocks,
                              tube_lipschitz as tube_lipschitz)

__getattr__, __dir__, __all__ = lazy_face(__name__, __file__)
