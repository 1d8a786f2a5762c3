"""The paper's definitions, triples and properties as executable predicates (imports no impl).

The same definitions as Z3 terms are the public module ``cfmpa.spec.z3defs``.
"""

from ._counts import MAX_EXTRA_POINTS, decimal, joint_grid
from ._arith import cases, ceil_of, floor_of, if_then, max_of, min_of
from ._grid import (DISTANCE_ERROR_M, EPS, MAX_COORD_M, UNIT_ROUNDOFF, Grid, Variant,
                    VariantRule, cell_box, exact_n, exact_tf, joint_points, left_angles,
                    left_box, make_grid, ptp_angles, rest_box, right_box, rule_of)
from ._certificate import (Certificate, ContactDetail, certificate_json, certify, closest_links,
                           contact_links_text, require_clear)
from ._exact import ExactCell, ExactGaps, exact_path_gaps
from ._trajectory import (CHUNK_ROWS, ReferenceSpeeds, Trajectory, TrajectorySummary,
                          between_samples_bound, certify_trajectory, certify_trajectory_file,
                          csv_column_order, executed_trajectory,
                          load_trajectory, parse_trajectory_csv, parse_trajectory_json,
                          tolerance_rad, trajectory_csv, trajectory_distances, tube_lipschitz)
from ._trajectory import COLUMNS as TRAJECTORY_COLUMNS
from ._kinematics import LINK_WORDS, arm_corners, joints, link_corners, link_name
from ._paths import (J1, J2, MOVES, REASON_GOAL_BLOCKED, REASON_START_BLOCKED, REASON_UNREACHABLE,
                     Cell, PathViolation, SearchResult, SearchStatus, check_search_inputs,
                     is_opt_path, is_path, is_path_paper, opt_path, path_violations)
from ._polygon import polygon_distance, polygon_distances
from ._scenario import (ANGLE_TOLERANCE, DEFAULT_MAX_CELLS, Arm, LeftArm, RightArm, Scenario,
                        load_scenario, max_cells, parse_scenario)
from ._triples import (TRIPLES, Failure, Triple, builtdr_triple, cells_failures, cost_failures,
                       dr_cell_failures, dr_shape_failures, grid_failures, path_cells,
                       search_failures, search_triple)
from ._layers import (SPILL_BYTES, LayerSpill, Layers, npz_layers, npz_member, save_npz,
                      spill_wanted)
from ._witness import (KEY_BASE, LABEL_LIMITS, WITNESS_FORMAT, Witness, check_witness,
                       closure_breaks, edge_bound, edge_holds, exclusion_breaks, goal_holds,
                       label_in_range, label_key, load_witness, start_breaks, step_cost,
                       stop_key)

__all__ = [
    # scenario, grids and motion (docs/model.md §2-§3)
    "ANGLE_TOLERANCE", "DEFAULT_MAX_CELLS", "DISTANCE_ERROR_M", "EPS", "MAX_COORD_M",
    "UNIT_ROUNDOFF", "Arm", "Grid", "LeftArm", "RightArm",
    "Scenario", "Variant", "exact_n", "exact_tf", "joint_points", "left_angles", "left_box",
    "MAX_EXTRA_POINTS", "decimal", "joint_grid",
    "load_scenario", "make_grid", "max_cells", "parse_scenario", "rest_box", "right_box",
    "VariantRule", "cell_box", "ptp_angles", "rule_of",
    # one definition on floats and on Z3 terms (the rules the proofs read)
    "cases", "ceil_of", "floor_of", "if_then", "max_of", "min_of",
    # geometry
    "arm_corners", "joints", "link_corners", "polygon_distance", "polygon_distances",
    # links named 1-based with words, as docs/model.md §2 names them
    "LINK_WORDS", "closest_links", "contact_links_text", "link_name",
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
    "label_in_range", "label_key", "start_breaks", "step_cost", "stop_key",
    # arrays read one layer at a time (the witness on large grids)
    "SPILL_BYTES", "LayerSpill", "Layers", "npz_layers", "npz_member", "save_npz",
    "spill_wanted",
    # the path's cells re-decided in ball arithmetic (docs/model.md §7)
    "ExactCell", "ExactGaps", "exact_path_gaps",
    # trajectories and the tolerance tube (docs/model.md §12)
    "TRAJECTORY_COLUMNS", "Trajectory", "certify_trajectory", "csv_column_order",
    "CHUNK_ROWS", "TrajectorySummary", "certify_trajectory_file",
    "executed_trajectory", "load_trajectory", "parse_trajectory_csv", "parse_trajectory_json",
    "tolerance_rad", "trajectory_csv", "trajectory_distances", "tube_lipschitz",
    # the monitor between samples (docs/model.md §12; proofs/_obl_monitor.py)
    "ReferenceSpeeds", "between_samples_bound",
]
