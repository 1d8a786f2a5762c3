"""The command line: ``cfmpa`` -> ``main(argv)`` -> one ``cmd_*`` per subcommand.

The command line parses and prints only: each ``cmd_*`` turns the parsed options into one call
of a ``run_*`` of runs/, report/ or proofs/ (which computes, prints and returns the exit
code); ``cfmpa.errors.handled`` turns an exception into its exit code and
message, in one place. The options the subcommands share, and the checks of every output and
every number before any work, are ``cfmpa._arguments``'s. Exit codes: 0 success, 1 a check
failed (a violation, a failed proof), 2 bad input or usage.
"""

from __future__ import annotations

import argparse
import gc
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from . import __version__
from . import _arguments as opt
from .errors import MISSING, InputError, handled
from .scenarios import bundled_names
from .scenarios import resolve as _resolve

__all__ = ["main"]


# --- the commands: options -> one run_* call ---------------------------------------------------


def resolve(arg: str | Path) -> Path:
    """The scenario file of ``arg`` (``scenarios.resolve``: a bundled name or a path); a bare
    name that is neither a file nor a bundled scenario is refused here, pointing to
    `cfmpa scenarios`, rather than reported as a file that cannot be read."""
    p = _resolve(arg)
    if not p.exists() and p.suffix != ".toml" and len(p.parts) == 1:
        raise InputError("SCENARIO", str(arg), "is neither a file nor a bundled scenario (`cfmpa "
                         f"scenarios` lists them: {', '.join(bundled_names())})")
    return p


def model_doc() -> Path | None:
    """docs/model.md, the model the help cites: in an installed wheel the package's copy
    (cfmpa/docs/model.md, setup.py), in a checkout the checkout's; None when neither exists."""
    here = Path(__file__).resolve().parent
    for path in (here / "docs" / "model.md", here.parent / "docs" / "model.md"):
        if path.is_file():
            return path
    return None


def cmd_docs(args: argparse.Namespace) -> int:
    """Print where docs/model.md is (exit 2 when this installation has none)."""
    path = model_doc()
    if path is None:
        raise InputError("docs/model.md", MISSING, "is not installed with this package "
                         f"({Path(__file__).resolve().parent})")
    print(path)
    return 0


def cmd_dr(args: argparse.Namespace) -> int:
    """Build D_R for one scenario and variant; write DIR/dr.npy or DIR/dr.zarr (--store)."""
    from .runs import run_dr

    return run_dr(resolve(args.scenario), args.variant, args.out, kernel=args.kernel,
                  name=args.scenario, store=args.store, engine=_build_engine(args))


def cmd_plan(args: argparse.Namespace) -> int:
    """Plan: BuiltDR, searchoptpath, certificate; write DIR/dr.npy, DIR/plan.json and, for a
    found path, DIR/traj.csv (exit 1 on a violation, the files written all the same as the
    evidence)."""
    from .runs import run_plan

    return run_plan(resolve(args.scenario), args.variant, args.out, contracts=args.contracts,
                    seed=args.seed, sample=args.sample, kernel=args.kernel,
                    witness=args.witness, name=args.scenario, store=args.store,
                    engine=_build_engine(args))


def cmd_check(args: argparse.Namespace) -> int:
    """Check another planner's dr.npy and plan.json against the spec (0 all hold, 1 a check
    fails, 2 bad input). The old spelling ``check --batch DIR`` is cmd_check_batch."""
    if args.batch is not None:
        for flag, value in (("--dr", args.dr), ("--plan", args.plan),
                            ("--witness", args.witness)):
            if value is not None:
                raise InputError(flag, value, "cannot be combined with --batch (each plan "
                                 "folder's own dr.npy and plan.json are checked)")
        return _check_batch(args, args.batch, "--batch")
    from .runs import run_check

    for flag, value in (("SCENARIO", args.scenario), ("--dr", args.dr), ("--plan", args.plan)):
        if value is None:
            raise InputError(flag, MISSING, "is required (or check a folder of plans with "
                             "cfmpa check-batch DIR [SCENARIO])")
    for flag in ("--json", "--workers", "--scheduler"):
        if getattr(args, flag[2:]) is not None:
            raise InputError(flag, getattr(args, flag[2:]), "is an option of cfmpa check-batch")
    return run_check(resolve(args.scenario), args.dr, args.plan, args.witness)


def cmd_check_batch(args: argparse.Namespace) -> int:
    """Check every plan folder under DIR, one task each (0 all pass, 1 any fails, 2 bad
    input)."""
    return _check_batch(args, args.folder, "DIR")


def _check_batch(args: argparse.Namespace, folder: str, label: str) -> int:
    """run_batch of ``folder`` (named ``label`` in a message: DIR, or the old --batch)."""
    from .runs import run_batch

    if args.json is None:          # the summary goes into DIR: it must be writable first
        opt.check_output(label, folder, opt.FOLDER)
    workers, scheduler = _engine(args)
    return run_batch(folder, None if args.scenario is None else resolve(args.scenario),
                     json_out=args.json, workers=workers, scheduler=scheduler,
                     connect_timeout=args.connect_timeout, worker_timeout=args.worker_timeout,
                     folder_option=label)


def cmd_selftest(args: argparse.Namespace) -> int:
    """Seed faults and show which contract check catches each. The old spelling ``selftest
    --code`` is cmd_mutants."""
    if args.code:
        return cmd_mutants(args)
    for flag in ("mutant", "checks", "json", "prove_only"):
        value = getattr(args, flag)
        if value:
            raise InputError("--" + flag.replace("_", "-"),
                             value[0] if isinstance(value, list) else value,
                             "is an option of cfmpa mutants (or its old spelling selftest "
                             "--code)")
    from .runs import run_selftest

    return run_selftest()


def cmd_mutants(args: argparse.Namespace) -> int:
    """Seeded mutations of a copy of the source, and which of prove, the contracts and the
    tests catch each."""
    from .runs import CODE_CHECKS, run_code_selftest

    checks = tuple(c.strip() for c in args.checks.split(",")) if args.checks else CODE_CHECKS
    return run_code_selftest(args.mutant or None, checks=checks,
                             prove_only=args.prove_only or (), json_out=args.json)


def cmd_prove(args: argparse.Namespace) -> int:
    """Discharge every obligation (--jobs processes, old spelling --workers); with --audit,
    also write the audit report (side by side)."""
    if args.audit is None:
        from .proofs import run_prove

        return run_prove(out_dir=args.out, scenarios_dir=args.scenarios, only=args.only,
                         repin=args.repin, workers=args.workers,
                         recheck_undecided=args.recheck_undecided)
    from .report import run_prove_audit

    return run_prove_audit(args.audit, out_dir=args.out, scenarios_dir=args.scenarios,
                           only=args.only, repin=args.repin, workers=args.workers,
                           recheck_undecided=args.recheck_undecided, argv=["cfmpa", *args.argv])


def cmd_audit(args: argparse.Namespace) -> int:
    """Write the audit report (HTML and its JSON twin)."""
    from .report import run_audit

    files = [str(resolve(a)) for a in args.scenarios] or None
    return run_audit(files, args.out, argv=["cfmpa", *args.argv],
                     proofs_json=args.proofs, compare_n=args.compare_n,
                     campaign=args.campaign, progress=sys.stderr)


def cmd_scenarios(args: argparse.Namespace) -> int:
    """List the bundled scenarios: name, grid size and purpose."""
    from .runs import run_scenarios

    return run_scenarios()


def cmd_compare(args: argparse.Namespace) -> int:
    """The paper's experimental claim, measured on seeded random workcells (one task each on a
    local Dask cluster, a running one, or in this process); resumable in --out."""
    from .report import run_compare

    workers, scheduler = _engine(args)
    return run_compare(n=args.n, seed=args.seed, out=args.out, dt=args.dt, workers=workers,
                       scheduler=scheduler, connect_timeout=args.connect_timeout,
                       worker_timeout=args.worker_timeout)


def cmd_certify(args: argparse.Namespace) -> int:
    """Certify any trajectory file: proved clearance, tolerance tube (0 clear, 1 not, 2 input)."""
    from .runs import run_certify

    return run_certify(resolve(args.scenario), args.traj, json_out=args.json,
                       allow_speed=args.allow_speed, bag=_bag(args))


def cmd_monitor(args: argparse.Namespace) -> int:
    """Stream a measured joint log against the certified tube (0 inside, 1 outside, 2 input)."""
    from .runs import run_monitor

    return run_monitor(resolve(args.scenario), args.traj, args.log, json_out=args.json,
                       allow_speed=args.allow_speed, max_speed=args.max_speed, bag=_bag(args),
                       allow_gaps=args.allow_gaps)


def cmd_simulate(args: argparse.Namespace) -> int:
    """Write a simulated measured log of a trajectory (lag, noise, seed, excursions)."""
    from .runs import parse_excursion, run_simulate

    return run_simulate(resolve(args.scenario), args.traj, args.out, lag=args.lag,
                        noise=args.noise, seed=args.seed,
                        excursions=[parse_excursion(e) for e in args.excursion],
                        period=args.period, samples=args.samples, tail=args.tail,
                        allow_speed=args.allow_speed, bag=_bag(args))


def _bag(args: argparse.Namespace) -> Any:
    """runs.BagOptions of --topic, --joints and --t0; None when none of them is given."""
    from .runs import DEFAULT_TOPIC, BagOptions, parse_joints

    t0 = getattr(args, "t0", None)
    if args.topic is None and args.joints is None and t0 is None:
        return None
    return BagOptions(DEFAULT_TOPIC if args.topic is None else args.topic,
                      parse_joints(args.joints), t0)


def _engine(args: argparse.Namespace) -> tuple[int, str | None]:
    """(workers, scheduler) of --workers and --scheduler: a local cluster of one worker per CPU
    unless either is given; both at once is refused."""
    if args.scheduler is not None and args.workers is not None:
        raise InputError("--workers", args.workers, "cannot be combined with --scheduler (the "
                         "cluster's own workers run the tasks)")
    if args.scheduler is not None:
        return 0, args.scheduler
    if args.workers is not None:
        return args.workers, None
    return opt.cpus(), None


def _build_engine(args: argparse.Namespace) -> Any:
    """runs.EngineOptions of dr's and plan's --workers, --scheduler and time-outs: D_R built in
    this process unless --workers K >= 1 or --scheduler is given (both at once refused)."""
    from .runs import EngineOptions

    workers, scheduler = (0, None) if args.workers is None and args.scheduler is None \
        else _engine(args)
    return EngineOptions(workers, scheduler, args.connect_timeout, args.worker_timeout)


# --- the parser --------------------------------------------------------------------------------


#: What `cfmpa --help` opens with: what the tool does, for a user.
ABOUT = ("cfmpa plans the subordinate arm's collision-free motion in a dual-arm SCARA workcell "
         "(BuiltDR and searchoptpath of Li et al.), checks each run against the paper's "
         "contracts, certifies a motion's clearance at every instant, monitors measured joint "
         "logs against the certified tube, and discharges the paper's proof obligations with "
         "Z3.")

#: What `cfmpa --help` closes with: a first command and the exit codes (errors.exit_code).
FIRST_STEPS = """\
a first command:
  cfmpa plan default --out plan    plan the bundled default workcell into the folder plan/
  cfmpa scenarios                  list the bundled workcells (or give a TOML file instead)
  cfmpa COMMAND --help             a command's options and an example
  cfmpa docs                       print where docs/model.md, which the help cites, is

exit codes:
  0    success (a plan that finds no path is an answer: exit 0)
  1    a check failed: a contract violation, a clearance not proved, a log outside its
       tube, an obligation not proved, a seeded fault not caught
  2    bad input or usage (or a file the system refused), in one line naming the
       option or the file and line, without a traceback
  130  interrupted
"""


def _command(sub: Any, name: str, summary: str, example: str,
             func: Callable[[argparse.Namespace], int]) -> argparse.ArgumentParser:
    """The subparser of command ``name``: ``summary`` is its one line (in `cfmpa --help` and
    atop its own help), ``example`` a command line shown under its options."""
    p: argparse.ArgumentParser = sub.add_parser(
        name, help=summary, description=summary[0].upper() + summary[1:] + ".",
        epilog=f"example:\n  {example}", formatter_class=opt.Formatter)
    p.set_defaults(func=func)
    return p



def _parser() -> argparse.ArgumentParser:
    import textwrap

    p = argparse.ArgumentParser(prog="cfmpa", description=textwrap.fill(ABOUT, 79),
                                epilog=FIRST_STEPS, formatter_class=opt.Formatter)
    p.add_argument("--version", action="version", version=f"cfmpa {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    b = opt.budgets()

    d = _command(sub, "dr", "build the collision-state database D_R (BuiltDR)",
                 "cfmpa dr default --variant tight --out build/dr", cmd_dr)
    opt.scenario_argument(d)
    opt.variant_argument(d)
    opt.out_argument(d, "output folder (dr.npy or dr.zarr is written there)")
    opt.kernel_argument(d)
    opt.store_argument(d)
    opt.engine_arguments(d, default="0, the build in this process; K >= 1 or --scheduler: "
                                    "blocks of layers as Dask tasks into dr.zarr")

    pl = _command(sub, "plan", "plan the subordinate's path; write dr.npy, plan.json and "
                               "traj.csv",
                  "cfmpa plan default --out plan", cmd_plan)
    opt.scenario_argument(pl)
    opt.variant_argument(pl)
    opt.out_argument(pl, "output folder")
    pl.add_argument("--contracts", choices=["off", "sampled", "full"], default="full",
                    help="contract checking of BuiltDR and searchoptpath (default: full, every "
                         "cell and optimality through the witness)")
    opt.number(pl, "--seed", b["seed"], type=int, default=0, help="seed of the sampled contracts")
    opt.number(pl, "--sample", b["sample"], type=int, default=None,
               help="cells checked by sampled contracts (default: the mode's own)")
    opt.kernel_argument(pl)
    opt.store_argument(pl)
    opt.engine_arguments(pl, default="0, the build in this process; K >= 1 or --scheduler: "
                                     "blocks of layers as Dask tasks into dr.zarr")
    opt.alias(pl.add_argument("--witness-out", "--witness", dest="witness", default=None,
                              metavar="FILE",
                              help="also write the search's witness of its answer to FILE "
                                   "(npz, docs/model.md §11); plan.json gets its "
                                   "witness_sha256"), "--witness")
    opt.output(pl, "witness", "--witness-out", opt.FILE)

    c = _command(sub, "check", "check another planner's dr.npy and plan.json",
                 "cfmpa check default --dr plan/dr.npy --plan plan/plan.json", cmd_check)
    c.add_argument("scenario", nargs="?", default=None,
                   help="scenario the outputs are for: a bundled name or a TOML file")
    c.add_argument("--dr", default=None, help="dr.npy or dr.zarr (uint8, shape (N + 1, m, n))")
    c.add_argument("--plan", default=None, help="plan.json (docs/model.md §9)")
    c.add_argument("--witness", default=None, metavar="FILE",
                   help="a witness file (cfmpa plan --witness-out) to verify for optimality; "
                        "without it the fast search computes one")
    # The old spelling of cfmpa check-batch (docs/model.md §7.3): accepted, not in the help.
    c.add_argument("--batch", default=None, metavar="DIR", help=argparse.SUPPRESS)
    opt.json_argument(c, argparse.SUPPRESS)
    opt.engine_arguments(c, hidden=True)

    cb = _command(sub, "check-batch", "check every plan folder under DIR, one task per plan",
                  "cfmpa check-batch plans --workers 2", cmd_check_batch)
    cb.add_argument("folder", metavar="DIR",
                    help="a folder of plan folders: each folder under it holding plan.json and "
                         "dr.npy (or dr.zarr) is checked; summary in DIR/check-batch.json")
    cb.add_argument("scenario", nargs="?", default=None,
                    help="the scenario of every plan (default: each plan's bundled scenario by "
                         "its name)")
    opt.json_argument(cb, "write the summary here instead of DIR/check-batch.json")
    opt.engine_arguments(cb)

    st = _command(sub, "selftest", "seed faults; show which check catches each",
                  "cfmpa selftest", cmd_selftest)
    # The old spelling of cfmpa mutants (docs/model.md §7.3): accepted, not in the help.
    st.add_argument("--code", action="store_true", help=argparse.SUPPRESS)
    _mutant_arguments(st, hidden=True)

    mu = _command(sub, "mutants", "mutate a copy of the source (minutes); show which of "
                                  "prove, the contracts and the tests catch each",
                  "cfmpa mutants --mutant margin_halved --checks prove", cmd_mutants)
    _mutant_arguments(mu)

    pr = _command(sub, "prove", "discharge every obligation (make prove)",
                  "cfmpa prove --only Prop8 --out build/proofs", cmd_prove)
    opt.out_argument(pr, "results folder (default build/proofs)", required=False,
                     default="build/proofs")
    pr.add_argument("--scenarios", default=None,
                    help="a folder of your workcells (*.toml) to prove: seven checks per file, "
                         "ids from the file names (default: the bundled workcells)")
    pr.add_argument("--only", action="append", default=None,
                    help="an obligation id, prefix or glob (repeatable)")
    pr.add_argument("--audit", metavar="DIR", default=None,
                    help="then write the audit report to DIR")
    opt.output(pr, "audit", "--audit", opt.FOLDER)
    pr.add_argument("--repin", action="store_true",
                    help="rewrite proofs/obligations.lock with the statements run and print "
                         "what changed (review the diff), instead of failing on a change")
    pr.add_argument("--recheck-undecided", action="store_true",
                    help="replay in cvc5 the VCs it did not decide when pinned too (by default "
                         "their answer is taken from proofs/obligations.lock, and said so)")
    opt.number(pr, "--jobs", b["prove_workers"], type=int, default=None, metavar="K",
               aliases=("--workers",), dest="workers",
               help="processes discharging obligations side by side (default 2 on a machine with "
                 "two cores or more, else 1); the results do not depend on K")

    au = _command(sub, "audit", "write report.html and report.json",
                  "cfmpa audit default --out build/audit --compare-n 0", cmd_audit)
    au.add_argument("scenarios", nargs="*",
                    help="scenario names or files (default: all bundled); the report shows the "
                         "per-scenario obligations of exactly these workcells")
    opt.out_argument(au, "output folder")
    au.add_argument("--proofs", default=None,
                    help="results.json of a prove run to report (default: prove afresh); it "
                         "must cover the given workcells' checks, others' rows are left out")
    opt.number(au, "--compare-n", b["workcells"], type=opt.positive, default=100,
               help="workcells in the campaign (0 skips it; default 100)")
    au.add_argument("--campaign", metavar="DIR", default=None,
                    help="show the campaign `cfmpa compare --out DIR` recorded there (read "
                         "from its records, not run again) instead of running one")

    _command(sub, "scenarios", "list the bundled scenarios and their purposes",
                  "cfmpa scenarios", cmd_scenarios)
    _command(sub, "docs", "print where docs/model.md (the model the help cites) is installed",
             "cfmpa docs", cmd_docs)

    co = _command(sub, "compare", "original vs modified vs tight on random workcells",
                  "cfmpa compare --n 20 --workers 0 --out build/compare", cmd_compare)
    opt.number(co, "--n", b["workcells"], type=opt.positive, default=100,
               help="workcells (default 100)")
    opt.number(co, "--seed", b["seed"], type=int, default=0, help="campaign seed (default 0)")
    opt.number(co, "--dt", b["dt"], type=float, default=0.1,
               help="time step of the workcells in s (default 0.1; the bundled default scenario's "
                 "is 0.02)")
    opt.out_argument(co, "folder for compare.json and the store compare.jsonl (a rerun of the "
                      "same settings resumes from it)", required=False)
    opt.engine_arguments(co)

    ce = _command(sub, "certify", "certify any trajectory file: proved clearance and "
                                  "tolerance tube",
                  "cfmpa certify default --traj plan/traj.csv --json certify.json", cmd_certify)
    opt.trajectory_arguments(ce, "trajectory: CSV t,left1,left2,right1,right2 or the same columns "
                              "as JSON, or a ROS 2 bag (docs/model.md §12)",
                          "certify even when a joint speed exceeds the scenario's omega")
    opt.json_argument(ce)
    opt.bag_arguments(ce)

    mo = _command(sub, "monitor", "check a measured joint log against the certified tube",
                  "cfmpa monitor default --traj plan/traj.csv --log log.csv", cmd_monitor)
    opt.trajectory_arguments(mo)
    mo.add_argument("--log", required=True, metavar="LOG",
                    help="measured samples: CSV t,left1,left2,right1,right2 (- for stdin), or "
                         "a ROS 2 bag (a folder with metadata.yaml, a .mcap or .db3 file)")
    mo.add_argument("--max-speed", default=None, metavar="W[,W2,W3,W4]",
                    help="the robot's joint speed bound in rad/s, one for all joints or one per "
                         "joint (default: the scenario's omega; docs/model.md §12)")
    opt.json_argument(mo)
    opt.bag_arguments(mo)
    mo.add_argument("--allow-gaps", action="store_true",
                    help="a --log bag with fewer messages than it declares: monitor the rest, "
                         "the time of the missing ones unobserved (default: exit 2)")

    si = _command(sub, "simulate", "write a simulated measured log of a trajectory",
                  "cfmpa simulate default --traj plan/traj.csv --log-out log.csv --noise 0.001",
                  cmd_simulate)
    opt.trajectory_arguments(si)
    opt.alias(si.add_argument("--log-out", "--out", dest="out", required=True, metavar="LOG",
                              help="the log to write: a ROS 2 bag for a name ending in .mcap "
                                   "or .db3 (that storage file) or for a folder (a new one "
                                   "ending in /, or a bag folder, replaced: metadata.yaml and "
                                   "an mcap file), else CSV"), "--out")
    opt.checked(si, "out", "--log-out", opt.check_log_output)
    opt.number(si, "--lag", b["lag"], type=float, default=0.0,
               help="tracking lag in s (default 0)")
    opt.number(si, "--noise", b["noise"], type=float, default=0.0,
               help="bounded uniform noise per joint in rad (default 0)")
    opt.number(si, "--seed", b["seed"], type=int, default=0, help="noise seed (default 0)")
    si.add_argument("--excursion", action="append", default=[], metavar="T:JOINT:RAD[:DURATION]",
                    help="add RAD to JOINT from T for DURATION s (default 0.05; repeatable)")
    opt.number(si, "--period", b["period"], type=float, default=None,
               help="sample period in s (default 0.001)")
    opt.number(si, "--samples", b["samples"], type=int, default=None,
               help="this many evenly spaced samples instead of --period")
    opt.number(si, "--tail", b["tail"], type=float, default=0.0,
               help="keep sampling this many s after the trajectory ends (default 0)")
    opt.bag_arguments(si, read=False)
    return p


def _mutant_arguments(p: argparse.ArgumentParser, *, hidden: bool = False) -> None:
    """cfmpa mutants' options (``hidden``: those of its old spelling, selftest --code)."""
    def text(t: str) -> str:
        return argparse.SUPPRESS if hidden else t
    p.add_argument("--mutant", action="append", metavar="NAME",
                   help=text("only this mutant (repeatable; default every one)"))
    p.add_argument("--checks", metavar="LIST",
                   help=text("comma-separated, of prove,contracts,tests (default all); exit 1 "
                             "unless prove catches every mutant"))
    p.add_argument("--prove-only", action="append", metavar="ID",
                   help=text("cfmpa prove on these obligations only (as its --only)"))
    opt.json_argument(p, text("the table as JSON"))


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit code (errors become messages, never tracebacks).

    ``argv`` None: the process's own command line (the ``cfmpa`` script, ``python -m cfmpa``),
    which exits with the code returned; the objects made so far are then frozen for the
    collector (``gc.freeze``), so that the interpreter's exit does not sweep numba's and
    numpy's modules (0.07 s CPU of `cfmpa dr`'s start-up, docs/model.md §7.5). What lies in
    a reference cycle then is not finalised at the exit, so nothing may be left to it: a
    command closes what it writes before it returns."""
    parser = _parser()
    args = parser.parse_args(argv)
    # The provenance records what this call was given, not the process's sys.argv.
    args.argv = list(sys.argv[1:] if argv is None else argv)
    func: Any = args.func

    def run() -> int:
        opt.run_checks(args)           # before any work: a bad value is exit 2 at once
        return int(func(args))
    code = handled(run)
    if argv is None:
        gc.freeze()
    return code


if __name__ == "__main__":
    sys.exit(main())
