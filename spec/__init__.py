"""The paper's definitions, triples and properties as executable predicates (imports no impl).

The same definitions as Z3 terms are the public module ``cfmpa.spec.z3defs``.
"""

from typing import TYPE_CHECKING

from ..lazy import lazy_exports

if TYPE_CHECKING:     # the names as the type checker sees them; at run time, _EXPORTS
    from ._counts import (MAX_EXTRA_POINTS, SPACING_ROUNDING, SPEED_READING, SpacingCondition,
                          Written, decimal, joint_grid, spacing_conditions, written)
    from ._arith import cases, ceil_of, floor_of, hypot_of, if_then, max_of, min_of, sqrt_of
    from ._grid import (DISTANCE_ERROR_M, EPS, MAX_COORD_M, UNIT_ROUNDOFF, Grid, Variant,
                        VariantRule, cell_box, exact_n, exact_tf, joint_points, left_angles,
                        left_box, make_grid, ptp_angles, ptp_fraction, rest_box, right_box,
                        rule_of)
    from ._certificate import (Certificate, ContactDetail, certificate_json, certify, closest_links,
                               contact_links_text, interval_bound, link_speeds, pair_lipschitz,
                               part_distances, pose_distance, require_clear)
    from ._certificate import contact_parts
    from ._certificate import _Motion as GridMotion
    from ._trajectory import _TrajectoryMotion as TrajectoryMotion
    from ._scope import SCOPE_CHECKED, theorem_scope
    from ._exact import ExactCell, ExactGaps, exact_path_gaps, gap_over_norm, projection_bounds
    from ._trajectory import (CHUNK_ROWS, ReferenceSpeeds, Trajectory, TrajectorySummary,
                              certify_trajectory_file, between_samples_bound, certify_trajectory,
                              log_end_bound,
                              csv_column_order, executed_trajectory,
                              load_trajectory, parse_trajectory_csv, parse_trajectory_json,
                              tolerance_rad, trajectory_csv, trajectory_distances, tube_lipschitz)
    from ._trajectory import COLUMNS as TRAJECTORY_COLUMNS
    from ._kinematics import (LINK_WORDS, TOOL, arm_corners, arm_parts, height_gap,
                              heights_overlap, joints, link_corners, link_name, pairs_to_test,
                              part_height, part_points, parts, reach)
    from ._paths import (J1, J2, MOVES, REASON_GOAL_BLOCKED, REASON_START_BLOCKED, REASON_UNREACHABLE,
                         Cell, PathViolation, SearchResult, SearchStatus, check_search_inputs,
                         is_opt_path, is_path, is_path_paper, opt_path, path_violations)
    from ._polygon import polygon_distance, polygon_distances
    from ._scenario import (ANGLE_TOLERANCE, DEFAULT_MAX_CELLS, Arm, LeftArm, RightArm, Scenario, Tool,
                            load_scenario, max_cells, parse_scenario)
    from ._triples import (TRIPLES, Failure, Triple, builtdr_triple, cells_failures, cost_failures,
                           dr_cell_failures, dr_shape_failures, grid_failures, path_cells,
                           search_failures, search_triple)
    from ._layers import (SPILL_BYTES, LayerSpill, Layers, npz_layers, npz_member, save_npz,
                          spill_wanted)
    from ._witness import (KEY_BASE, LABEL_LIMITS, WITNESS_FORMAT, Witness, check_witness,
                           closure_breaks, edge_bound, edge_holds, exclusion_breaks, goal_holds,
                           label_in_range, label_key, load_witness, start_breaks,
                           start_label_breaks, step_cost, stop_key)

#: Each public name -> "module:name", imported on first use (PEP 562, cfmpa.lazy): a
#: command loads only the modules it needs (docs/model.md §1.1).
_EXPORTS: dict[str, str] = {
    "CHUNK_ROWS": "._trajectory:CHUNK_ROWS",
    "TrajectorySummary": "._trajectory:TrajectorySummary",
    "certify_trajectory_file": "._trajectory:certify_trajectory_file",
    "MAX_EXTRA_POINTS": "._counts:MAX_EXTRA_POINTS",
    "SPACING_ROUNDING": "._counts:SPACING_ROUNDING",
    "SPEED_READING": "._counts:SPEED_READING",
    "SpacingCondition": "._counts:SpacingCondition",
    "Written": "._counts:Written",
    "decimal": "._counts:decimal",
    "joint_grid": "._counts:joint_grid",
    "spacing_conditions": "._counts:spacing_conditions",
    "written": "._counts:written",
    "cases": "._arith:cases",
    "ceil_of": "._arith:ceil_of",
    "floor_of": "._arith:floor_of",
    "hypot_of": "._arith:hypot_of",
    "if_then": "._arith:if_then",
    "max_of": "._arith:max_of",
    "min_of": "._arith:min_of",
    "sqrt_of": "._arith:sqrt_of",
    "DISTANCE_ERROR_M": "._grid:DISTANCE_ERROR_M",
    "EPS": "._grid:EPS",
    "MAX_COORD_M": "._grid:MAX_COORD_M",
    "UNIT_ROUNDOFF": "._grid:UNIT_ROUNDOFF",
    "Grid": "._grid:Grid",
    "Variant": "._grid:Variant",
    "VariantRule": "._grid:VariantRule",
    "cell_box": "._grid:cell_box",
    "exact_n": "._grid:exact_n",
    "exact_tf": "._grid:exact_tf",
    "joint_points": "._grid:joint_points",
    "left_angles": "._grid:left_angles",
    "left_box": "._grid:left_box",
    "make_grid": "._grid:make_grid",
    "ptp_angles": "._grid:ptp_angles",
    "ptp_fraction": "._grid:ptp_fraction",
    "rest_box": "._grid:rest_box",
    "right_box": "._grid:right_box",
    "rule_of": "._grid:rule_of",
    "Certificate": "._certificate:Certificate",
    "ContactDetail": "._certificate:ContactDetail",
    "certificate_json": "._certificate:certificate_json",
    "certify": "._certificate:certify",
    "closest_links": "._certificate:closest_links",
    "part_distances": "._certificate:part_distances",
    "pose_distance": "._certificate:pose_distance",
    "contact_links_text": "._certificate:contact_links_text",
    "contact_parts": "._certificate:contact_parts",
    "SCOPE_CHECKED": "._scope:SCOPE_CHECKED",
    "theorem_scope": "._scope:theorem_scope",
    "interval_bound": "._certificate:interval_bound",
    "link_speeds": "._certificate:link_speeds",
    "pair_lipschitz": "._certificate:pair_lipschitz",
    "require_clear": "._certificate:require_clear",
    "GridMotion": "._certificate:_Motion",
    "TrajectoryMotion": "._trajectory:_TrajectoryMotion",
    "ExactCell": "._exact:ExactCell",
    "ExactGaps": "._exact:ExactGaps",
    "exact_path_gaps": "._exact:exact_path_gaps",
    "gap_over_norm": "._exact:gap_over_norm",
    "projection_bounds": "._exact:projection_bounds",
    "ReferenceSpeeds": "._trajectory:ReferenceSpeeds",
    "Trajectory": "._trajectory:Trajectory",
    "between_samples_bound": "._trajectory:between_samples_bound",
    "log_end_bound": "._trajectory:log_end_bound",
    "certify_trajectory": "._trajectory:certify_trajectory",
    "csv_column_order": "._trajectory:csv_column_order",
    "executed_trajectory": "._trajectory:executed_trajectory",
    "load_trajectory": "._trajectory:load_trajectory",
    "parse_trajectory_csv": "._trajectory:parse_trajectory_csv",
    "parse_trajectory_json": "._trajectory:parse_trajectory_json",
    "tolerance_rad": "._trajectory:tolerance_rad",
    "trajectory_csv": "._trajectory:trajectory_csv",
    "trajectory_distances": "._trajectory:trajectory_distances",
    "tube_lipschitz": "._trajectory:tube_lipschitz",
    "TRAJECTORY_COLUMNS": "._trajectory:COLUMNS",
    "LINK_WORDS": "._kinematics:LINK_WORDS",
    "arm_corners": "._kinematics:arm_corners",
    "joints": "._kinematics:joints",
    "link_corners": "._kinematics:link_corners",
    "link_name": "._kinematics:link_name",
    "reach": "._kinematics:reach",
    "TOOL": "._kinematics:TOOL",
    "arm_parts": "._kinematics:arm_parts",
    "height_gap": "._kinematics:height_gap",
    "heights_overlap": "._kinematics:heights_overlap",
    "pairs_to_test": "._kinematics:pairs_to_test",
    "part_height": "._kinematics:part_height",
    "part_points": "._kinematics:part_points",
    "parts": "._kinematics:parts",
    "J1": "._paths:J1",
    "J2": "._paths:J2",
    "MOVES": "._paths:MOVES",
    "REASON_GOAL_BLOCKED": "._paths:REASON_GOAL_BLOCKED",
    "REASON_START_BLOCKED": "._paths:REASON_START_BLOCKED",
    "REASON_UNREACHABLE": "._paths:REASON_UNREACHABLE",
    "Cell": "._paths:Cell",
    "PathViolation": "._paths:PathViolation",
    "SearchResult": "._paths:SearchResult",
    "SearchStatus": "._paths:SearchStatus",
    "check_search_inputs": "._paths:check_search_inputs",
    "is_opt_path": "._paths:is_opt_path",
    "is_path": "._paths:is_path",
    "is_path_paper": "._paths:is_path_paper",
    "opt_path": "._paths:opt_path",
    "path_violations": "._paths:path_violations",
    "polygon_distance": "._polygon:polygon_distance",
    "polygon_distances": "._polygon:polygon_distances",
    "ANGLE_TOLERANCE": "._scenario:ANGLE_TOLERANCE",
    "DEFAULT_MAX_CELLS": "._scenario:DEFAULT_MAX_CELLS",
    "Arm": "._scenario:Arm",
    "LeftArm": "._scenario:LeftArm",
    "RightArm": "._scenario:RightArm",
    "Scenario": "._scenario:Scenario",
    "Tool": "._scenario:Tool",
    "load_scenario": "._scenario:load_scenario",
    "max_cells": "._scenario:max_cells",
    "parse_scenario": "._scenario:parse_scenario",
    "TRIPLES": "._triples:TRIPLES",
    "Failure": "._triples:Failure",
    "Triple": "._triples:Triple",
    "builtdr_triple": "._triples:builtdr_triple",
    "cells_failures": "._triples:cells_failures",
    "cost_failures": "._triples:cost_failures",
    "dr_cell_failures": "._triples:dr_cell_failures",
    "dr_shape_failures": "._triples:dr_shape_failures",
    "grid_failures": "._triples:grid_failures",
    "path_cells": "._triples:path_cells",
    "search_failures": "._triples:search_failures",
    "search_triple": "._triples:search_triple",
    "SPILL_BYTES": "._layers:SPILL_BYTES",
    "LayerSpill": "._layers:LayerSpill",
    "Layers": "._layers:Layers",
    "npz_layers": "._layers:npz_layers",
    "npz_member": "._layers:npz_member",
    "save_npz": "._layers:save_npz",
    "spill_wanted": "._layers:spill_wanted",
    "KEY_BASE": "._witness:KEY_BASE",
    "LABEL_LIMITS": "._witness:LABEL_LIMITS",
    "WITNESS_FORMAT": "._witness:WITNESS_FORMAT",
    "Witness": "._witness:Witness",
    "check_witness": "._witness:check_witness",
    "closure_breaks": "._witness:closure_breaks",
    "edge_bound": "._witness:edge_bound",
    "edge_holds": "._witness:edge_holds",
    "exclusion_breaks": "._witness:exclusion_breaks",
    "goal_holds": "._witness:goal_holds",
    "label_in_range": "._witness:label_in_range",
    "label_key": "._witness:label_key",
    "load_witness": "._witness:load_witness",
    "start_breaks": "._witness:start_breaks",
    "start_label_breaks": "._witness:start_label_breaks",
    "step_cost": "._witness:step_cost",
    "stop_key": "._witness:stop_key",
}

__all__ = [
    # scenario, grids and motion (docs/model.md §2-§3)
    "ANGLE_TOLERANCE", "DEFAULT_MAX_CELLS", "DISTANCE_ERROR_M", "EPS", "MAX_COORD_M",
    "UNIT_ROUNDOFF", "Arm", "Grid", "LeftArm", "RightArm", "Tool",
    "Scenario", "Variant", "exact_n", "exact_tf", "joint_points", "left_angles", "left_box",
    "MAX_EXTRA_POINTS", "SPACING_ROUNDING", "SPEED_READING", "SpacingCondition", "Written",
    "decimal", "joint_grid", "spacing_conditions", "written",
    "load_scenario", "make_grid", "max_cells", "parse_scenario", "rest_box", "right_box",
    "VariantRule", "cell_box", "ptp_angles", "ptp_fraction", "rule_of",
    # one definition on floats and on Z3 terms (the rules the proofs read)
    "cases", "ceil_of", "floor_of", "hypot_of", "if_then", "max_of", "min_of", "sqrt_of",
    # geometry
    "arm_corners", "joints", "link_corners", "polygon_distance", "polygon_distances",
    # parts (links and tool) and heights (docs/model.md §2, "Tools and heights")
    "TOOL", "arm_parts", "height_gap", "heights_overlap", "pairs_to_test", "part_height",
    "part_points", "parts", "part_distances", "pose_distance",
    # links named 1-based with words, as docs/model.md §2 names them
    "LINK_WORDS", "closest_links", "contact_links_text", "link_name",
    "contact_parts",
    # what the safety theorem covers of a workcell (docs/model.md §10)
    "SCOPE_CHECKED", "theorem_scope",
    # paths (docs/model.md §5)
    "Cell", "J1", "J2", "MOVES", "PathViolation", "REASON_GOAL_BLOCKED", "REASON_START_BLOCKED",
    "REASON_UNREACHABLE", "SearchResult", "SearchStatus", "check_search_inputs", "is_opt_path",
    "is_path", "is_path_paper", "opt_path", "path_violations",
    # triples and the certificate (docs/model.md §7)
    "TRIPLES", "Failure", "Triple", "builtdr_triple", "cells_failures", "cost_failures",
    "dr_cell_failures", "dr_shape_failures", "grid_failures", "path_cells", "search_failures",
    "search_triple",
    "Certificate", "ContactDetail", "certificate_json", "certify", "require_clear",
    # witnesses of the search's answer (docs/model.md §11)
    "LABEL_LIMITS", "WITNESS_FORMAT", "Witness", "check_witness", "load_witness",
    # its conditions, on numpy arrays and on Z3 terms (proofs/_obl_witness.py)
    "KEY_BASE", "closure_breaks", "edge_bound", "edge_holds", "exclusion_breaks", "goal_holds",
    "label_in_range", "label_key", "start_breaks", "start_label_breaks", "step_cost", "stop_key",
    # arrays read one layer at a time (the witness on large grids)
    "SPILL_BYTES", "LayerSpill", "Layers", "npz_layers", "npz_member", "save_npz",
    "spill_wanted",
    # the motions the certificate samples, read on terms by proofs/_obl_wiring.py
    "GridMotion", "TrajectoryMotion",
    # the path's cells re-decided in ball arithmetic (docs/model.md §7)
    "ExactCell", "ExactGaps", "exact_path_gaps",
    # trajectories and the tolerance tube (docs/model.md §12)
    "TRAJECTORY_COLUMNS", "Trajectory", "certify_trajectory", "csv_column_order",
    "executed_trajectory", "load_trajectory", "parse_trajectory_csv", "parse_trajectory_json",
    "tolerance_rad", "trajectory_csv", "trajectory_distances", "tube_lipschitz",
    # the monitor between samples (docs/model.md §12; proofs/_obl_monitor.py)
    "ReferenceSpeeds", "between_samples_bound", "log_end_bound",
    # certify in one pass (docs/model.md §12)
    "CHUNK_ROWS", "TrajectorySummary", "certify_trajectory_file",
    # the constants the certificate, the tube and the ball gaps rest on (proofs/_obl_constants.py)
    "gap_over_norm", "interval_bound", "link_speeds", "pair_lipschitz", "projection_bounds",
    "reach",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, __all__)
