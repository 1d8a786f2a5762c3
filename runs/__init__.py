"""Checked runs: a plan under the paper's contracts, `cfmpa check` of another planner's files,
the campaign of `cfmpa compare`, and the seeded-fault self-check (`cfmpa selftest`).

This layer uses both ``spec`` (the contracts and the certificate) and ``impl`` (the planner it
checks). The pipeline, stage by stage (docs/model.md §7, §9):

=============  ==========================================  ======================
stage          function                                    file
=============  ==========================================  ======================
scenario       ``spec.load_scenario`` / ``parse_scenario``  ``spec/_scenario.py``
grid           ``spec.make_grid``                           ``spec/_grid.py``
regions        ``impl.left_regions`` / ``right_regions``    ``impl/_builtdr.py``
D_R            ``impl.build_dr`` (fast: ``build_dr_fast``)  ``impl/_builtdr.py``
               under ``checked_build_dr``                   ``runs/_contracts.py``
path           ``impl.search_opt_path`` (fast variant)      ``impl/_search.py``
               under ``checked_search``                     ``runs/_contracts.py``
certificate    ``spec.certify``                             ``spec/_certificate.py``
plan.json      ``plan``, ``plan_json``, ``write_plan``      ``runs/_plan.py``
check          ``run_check`` (another planner's files)      ``runs/_check.py``
campaign       ``run_campaign`` (`cfmpa compare`'s work)    ``runs/_campaign.py``
report         ``report.run_audit``                         ``report/_audit.py``
=============  ==========================================  ======================

Each command of the CLI is one ``run_*`` here (``run_dr``, ``run_plan``, ``run_scenarios``,
``run_check``, ...): it takes the command's values and the streams to print on, prints, and
returns the exit code; bad input raises InputError, which ``cfmpa.errors.handled`` turns into
exit 2.
"""

from typing import TYPE_CHECKING

from ..lazy import lazy_exports

if TYPE_CHECKING:     # the names as the type checker sees them; at run time, _EXPORTS
    from ._campaign import (COMPARE_DT, CONTACT_NOTE, KERNEL, MAX_DRAWS,
                            STORE_NAME, Campaign,
                            CaseError, CaseResult, VariantOutcome, load_campaign, plan_workcell,
                            random_workcell, run_campaign, workcell_task)
    from ._limits import MAX_DT, MAX_LOG_SAMPLES, MAX_WORKCELLS, MIN_PERIOD_S
    from ._store import Store, open_store, read_store
    from ._batch import BATCH_JSON, batch_table, check_plan_folder, find_plan_folders, run_batch
    from ._check import CheckReport, check_outputs, read_dr, read_plan, run_check
    from ._drstore import (DR_FILES, DR_STORES, ZARR_ABOVE_CELLS, default_store, dr_sha256_of,
                           find_dr, load_dr, open_dr_layers, write_dr)
    from ._drdask import BuiltStore, EngineOptions, build_store
    from ._engine import (CONNECT_TIMEOUT_S, RETRIES, WORKER_TIMEOUT_S, Engine, ProgressBar,
                          TaskLost, check_scheduler_address, error_message)
    from ._contracts import (DEFAULT_SAMPLE, Mode, Settings, TripleRun, contracts_json,
                             optimality_failures, violation_json)
    from ._plan import (CERTIFICATE, PlanResult, clearance_line, plan, plan_json, run_dr, run_plan,
                        versions, write_plan)
    from ._bundled import run_scenarios
    from ._trajectory_runs import (AFTER_LOG, BEFORE_LOG, BETWEEN_SAMPLES, BLOCK_ROWS,
                                   LISTED_UNOBSERVED, MISSING_MESSAGES, Excursion,
                                   MonitorResult,
                                   Unobserved, certify_json, log_csv, monitor_json, monitor_log,
                                   monitor_rows, parse_excursion, parse_max_speed, run_certify, run_monitor,
                                   run_simulate, simulate_log)
    from ._rosbag import (DEFAULT_TOPIC, JOINT_STATE, LOG_KINDS, BagOptions, BagReading,
                          bag_rows, bag_sha256, is_bag, load_bag_trajectory, log_output_kind,
                          parse_joints, write_bag)
    from ._code_mutants import (CODE_CHECKS, CODE_MUTANTS, CodeMutant, CodeRow,
                                code_mutation_rows, code_mutation_table, imports_copy, mutated_copy,
                                run_code_selftest)
    from ._selftest import (FAULTS, SAMPLE, WORKCELLS, Fault, SelftestRow, run_fault, run_selftest,
                            selftest_rows, selftest_table, workcell)

#: Each public name -> "module:name", imported on first use (PEP 562, cfmpa.lazy): a
#: command loads only the modules it needs (docs/model.md §1.1).
_EXPORTS: dict[str, str] = {
    "COMPARE_DT": "._campaign:COMPARE_DT",
    "CONTACT_NOTE": "._campaign:CONTACT_NOTE",
    "KERNEL": "._campaign:KERNEL",
    "MAX_DRAWS": "._campaign:MAX_DRAWS",
    "MAX_DT": "._limits:MAX_DT",
    "MAX_WORKCELLS": "._limits:MAX_WORKCELLS",
    "STORE_NAME": "._campaign:STORE_NAME",
    "Campaign": "._campaign:Campaign",
    "CaseError": "._campaign:CaseError",
    "CaseResult": "._campaign:CaseResult",
    "VariantOutcome": "._campaign:VariantOutcome",
    "load_campaign": "._campaign:load_campaign",
    "plan_workcell": "._campaign:plan_workcell",
    "random_workcell": "._campaign:random_workcell",
    "run_campaign": "._campaign:run_campaign",
    "workcell_task": "._campaign:workcell_task",
    "Store": "._store:Store",
    "open_store": "._store:open_store",
    "read_store": "._store:read_store",
    "BATCH_JSON": "._batch:BATCH_JSON",
    "batch_table": "._batch:batch_table",
    "check_plan_folder": "._batch:check_plan_folder",
    "find_plan_folders": "._batch:find_plan_folders",
    "run_batch": "._batch:run_batch",
    "CheckReport": "._check:CheckReport",
    "check_outputs": "._check:check_outputs",
    "read_dr": "._check:read_dr",
    "read_plan": "._check:read_plan",
    "run_check": "._check:run_check",
    "DR_FILES": "._drstore:DR_FILES",
    "DR_STORES": "._drstore:DR_STORES",
    "ZARR_ABOVE_CELLS": "._drstore:ZARR_ABOVE_CELLS",
    "default_store": "._drstore:default_store",
    "dr_sha256_of": "._drstore:dr_sha256_of",
    "find_dr": "._drstore:find_dr",
    "load_dr": "._drstore:load_dr",
    "open_dr_layers": "._drstore:open_dr_layers",
    "write_dr": "._drstore:write_dr",
    "BuiltStore": "._drdask:BuiltStore",
    "EngineOptions": "._drdask:EngineOptions",
    "build_store": "._drdask:build_store",
    "CONNECT_TIMEOUT_S": "._engine:CONNECT_TIMEOUT_S",
    "RETRIES": "._engine:RETRIES",
    "WORKER_TIMEOUT_S": "._engine:WORKER_TIMEOUT_S",
    "Engine": "._engine:Engine",
    "ProgressBar": "._engine:ProgressBar",
    "TaskLost": "._engine:TaskLost",
    "check_scheduler_address": "._engine:check_scheduler_address",
    "error_message": "._engine:error_message",
    "DEFAULT_SAMPLE": "._contracts:DEFAULT_SAMPLE",
    "Mode": "._contracts:Mode",
    "Settings": "._contracts:Settings",
    "TripleRun": "._contracts:TripleRun",
    "contracts_json": "._contracts:contracts_json",
    "optimality_failures": "._contracts:optimality_failures",
    "violation_json": "._contracts:violation_json",
    "CERTIFICATE": "._plan:CERTIFICATE",
    "PlanResult": "._plan:PlanResult",
    "clearance_line": "._plan:clearance_line",
    "plan": "._plan:plan",
    "plan_json": "._plan:plan_json",
    "run_dr": "._plan:run_dr",
    "run_plan": "._plan:run_plan",
    "versions": "._plan:versions",
    "write_plan": "._plan:write_plan",
    "run_scenarios": "._bundled:run_scenarios",
    "AFTER_LOG": "._trajectory_runs:AFTER_LOG",
    "BEFORE_LOG": "._trajectory_runs:BEFORE_LOG",
    "BETWEEN_SAMPLES": "._trajectory_runs:BETWEEN_SAMPLES",
    "BLOCK_ROWS": "._trajectory_runs:BLOCK_ROWS",
    "MAX_LOG_SAMPLES": "._limits:MAX_LOG_SAMPLES",
    "MIN_PERIOD_S": "._limits:MIN_PERIOD_S",
    "LISTED_UNOBSERVED": "._trajectory_runs:LISTED_UNOBSERVED",
    "MISSING_MESSAGES": "._trajectory_runs:MISSING_MESSAGES",
    "Excursion": "._trajectory_runs:Excursion",
    "MonitorResult": "._trajectory_runs:MonitorResult",
    "Unobserved": "._trajectory_runs:Unobserved",
    "certify_json": "._trajectory_runs:certify_json",
    "log_csv": "._trajectory_runs:log_csv",
    "monitor_json": "._trajectory_runs:monitor_json",
    "monitor_log": "._trajectory_runs:monitor_log",
    "monitor_rows": "._trajectory_runs:monitor_rows",
    "parse_excursion": "._trajectory_runs:parse_excursion",
    "parse_max_speed": "._trajectory_runs:parse_max_speed",
    "run_certify": "._trajectory_runs:run_certify",
    "run_monitor": "._trajectory_runs:run_monitor",
    "run_simulate": "._trajectory_runs:run_simulate",
    "simulate_log": "._trajectory_runs:simulate_log",
    "DEFAULT_TOPIC": "._rosbag:DEFAULT_TOPIC",
    "JOINT_STATE": "._rosbag:JOINT_STATE",
    "BagOptions": "._rosbag:BagOptions",
    "BagReading": "._rosbag:BagReading",
    "LOG_KINDS": "._rosbag:LOG_KINDS",
    "log_output_kind": "._rosbag:log_output_kind",
    "bag_rows": "._rosbag:bag_rows",
    "bag_sha256": "._rosbag:bag_sha256",
    "is_bag": "._rosbag:is_bag",
    "load_bag_trajectory": "._rosbag:load_bag_trajectory",
    "parse_joints": "._rosbag:parse_joints",
    "write_bag": "._rosbag:write_bag",
    "CODE_CHECKS": "._code_mutants:CODE_CHECKS",
    "CODE_MUTANTS": "._code_mutants:CODE_MUTANTS",
    "CodeMutant": "._code_mutants:CodeMutant",
    "CodeRow": "._code_mutants:CodeRow",
    "code_mutation_rows": "._code_mutants:code_mutation_rows",
    "code_mutation_table": "._code_mutants:code_mutation_table",
    "imports_copy": "._code_mutants:imports_copy",
    "mutated_copy": "._code_mutants:mutated_copy",
    "run_code_selftest": "._code_mutants:run_code_selftest",
    "FAULTS": "._selftest:FAULTS",
    "SAMPLE": "._selftest:SAMPLE",
    "WORKCELLS": "._selftest:WORKCELLS",
    "Fault": "._selftest:Fault",
    "SelftestRow": "._selftest:SelftestRow",
    "run_fault": "._selftest:run_fault",
    "run_selftest": "._selftest:run_selftest",
    "selftest_rows": "._selftest:selftest_rows",
    "selftest_table": "._selftest:selftest_table",
    "workcell": "._selftest:workcell",
}

__all__ = [
    # a plan under contracts (docs/model.md §7, §9)
    "CERTIFICATE", "DEFAULT_SAMPLE", "Mode", "PlanResult", "Settings", "TripleRun",
    "contracts_json", "optimality_failures", "plan", "plan_json", "versions", "violation_json",
    "write_plan",
    # the commands' runs: each prints on the streams it is given and returns the exit code
    "clearance_line", "run_dr", "run_plan", "run_scenarios",
    # another planner's files
    "CheckReport", "check_outputs", "read_dr", "read_plan", "run_check",
    # D_R on disk: dr.npy or the chunked dr.zarr (docs/model.md §9)
    "DR_FILES", "DR_STORES", "ZARR_ABOVE_CELLS", "default_store", "dr_sha256_of", "find_dr",
    "load_dr", "open_dr_layers", "write_dr",
    # D_R built on Dask, blocks of layers into dr.zarr (docs/model.md §9)
    "BuiltStore", "EngineOptions", "build_store",
    "BATCH_JSON", "batch_table", "check_plan_folder", "find_plan_folders", "run_batch",
    "CONNECT_TIMEOUT_S", "Engine", "ProgressBar", "RETRIES", "TaskLost", "WORKER_TIMEOUT_S",
    "check_scheduler_address", "error_message",
    # the campaign of `cfmpa compare` and its resumable store (docs/model.md §13)
    "COMPARE_DT", "CONTACT_NOTE", "Campaign", "CaseError", "CaseResult", "KERNEL", "MAX_DRAWS",
    "MAX_DT", "MAX_WORKCELLS", "STORE_NAME", "Store", "VariantOutcome", "load_campaign",
    "open_store",
    "plan_workcell", "random_workcell", "read_store", "run_campaign", "workcell_task",
    # any planner's trajectory (docs/model.md §12)
    "AFTER_LOG", "BEFORE_LOG", "BETWEEN_SAMPLES", "LISTED_UNOBSERVED", "MISSING_MESSAGES",
    "Unobserved",
    "parse_max_speed",
    "BLOCK_ROWS", "Excursion", "MAX_LOG_SAMPLES", "MIN_PERIOD_S", "MonitorResult",
    "certify_json", "log_csv", "monitor_json",
    "monitor_log", "parse_excursion", "run_certify", "run_monitor", "run_simulate",
    "simulate_log", "monitor_rows",
    # ROS 2 bags as trajectories and logs (docs/model.md §12)
    "BagOptions", "DEFAULT_TOPIC", "JOINT_STATE", "bag_rows", "bag_sha256", "is_bag",
    "load_bag_trajectory", "parse_joints", "write_bag", "BagReading", "LOG_KINDS",
    "log_output_kind",
    # seeded faults
    "FAULTS", "Fault", "SAMPLE", "SelftestRow", "WORKCELLS", "run_fault", "run_selftest",
    "selftest_rows", "selftest_table", "workcell",
    # seeded mutations of the source (cfmpa selftest --code)
    "CODE_CHECKS", "CODE_MUTANTS", "CodeMutant", "CodeRow", "code_mutation_rows",
    "code_mutation_table", "imports_copy", "mutated_copy", "run_code_selftest",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, __all__)
