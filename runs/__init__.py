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
exit 2. The public names are listed once, below (``cfmpa.lazy``), each imported on first use;
a name only the tests use stays in its private module, and the tests import it from there.
"""

from typing import TYPE_CHECKING

from ..lazy import lazy_face

if TYPE_CHECKING:     # the public names, one list: the type checker's and __all__ (cfmpa.lazy)
    # a plan under contracts and the commands' runs (docs/model.md §7, §9): each run_* prints
    # on the streams it is given and returns the exit code
    from ._contracts import Mode as Mode
    from ._plan import (PlanResult as PlanResult, plan as plan, plan_json as plan_json,
                        run_dr as run_dr, run_plan as run_plan, versions as versions,
                        write_plan as write_plan)
    from ._bundled import run_scenarios as run_scenarios
    # another planner's files, one folder or a batch
    from ._check import run_check as run_check
    from ._batch import run_batch as run_batch
    # D_R on disk: dr.npy or the chunked dr.zarr, built on Dask (docs/model.md §9)
    from ._drstore import (DR_STORES as DR_STORES, ZARR_ABOVE_CELLS as ZARR_ABOVE_CELLS,
                           load_dr as load_dr, open_dr_layers as open_dr_layers)
    from ._drdask import EngineOptions as EngineOptions
    from ._engine import (CONNECT_TIMEOUT_S as CONNECT_TIMEOUT_S, Engine as Engine,
                          WORKER_TIMEOUT_S as WORKER_TIMEOUT_S)
    # the campaign of `cfmpa compare` (docs/model.md §13) and the commands' limits
    from ._campaign import (COMPARE_DT as COMPARE_DT, Campaign as Campaign,
                            load_campaign as load_campaign, run_campaign as run_campaign)
    from ._limits import (MAX_DT as MAX_DT, MAX_LOG_SAMPLES as MAX_LOG_SAMPLES,
                          MAX_WORKCELLS as MAX_WORKCELLS, MIN_PERIOD_S as MIN_PERIOD_S)
    # any planner's trajectory (docs/model.md §12), and ROS 2 bags as trajectories and logs
    from ._trajectory_runs import (Excursion as Excursion, MonitorResult as MonitorResult,
                                   certify_json as certify_json, log_csv as log_csv,
                                   monitor_json as monitor_json, monitor_log as monitor_log,
                                   parse_excursion as parse_excursion,
                                   parse_max_speed as parse_max_speed, run_certify as run_certify,
                                   run_monitor as run_monitor, run_simulate as run_simulate,
                                   simulate_log as simulate_log)
    from ._rosbag import (DEFAULT_TOPIC as DEFAULT_TOPIC, BagOptions as BagOptions,
                          log_output_kind as log_output_kind, parse_joints as parse_joints)
    # seeded faults (cfmpa selftest) and seeded mutations of the source (--code)
    from ._selftest import (SAMPLE as SAMPLE, run_selftest as run_selftest,
                            selftest_rows as selftest_rows)
    from ._code_mutants import CODE_CHECKS as CODE_CHECKS, run_code_selftest as run_code_selftest

__getattr__, __dir__, __all__ = lazy_face(__name__, __file__)
