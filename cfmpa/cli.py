"""The command line: ``cfmpa`` -> ``main(argv)`` -> one function per subcommand returning the exit code.

Exit codes: 0 success, 1 a check failed (a violation, a failed proof), 2 bad input or usage.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from . import __version__
from .errors import CfmpaError, InputError
from .scenarios import resolve

if TYPE_CHECKING:
    from .spec import Certificate

__all__ = ["main"]


def _variant(value: str) -> str:
    from .spec import Variant

    try:
        return Variant(value).value
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"--variant must be one of {', '.join(v.value for v in Variant)}, got {value!r}") from None


def cmd_dr(args: argparse.Namespace) -> int:
    """Build D_R for one scenario and variant; write DIR/dr.npy."""
    from .files import save_npy_atomic
    from .impl import kernels
    from .spec import load_scenario, make_grid

    s = load_scenario(resolve(args.scenario))
    g = make_grid(s)
    build, _ = kernels(args.kernel)
    t0 = time.perf_counter()
    dr = build(s, args.variant, g)
    seconds = time.perf_counter() - t0
    out = save_npy_atomic(Path(args.out) / "dr.npy", dr)
    free = 1.0 - float(dr.mean())
    print(f"scenario  {s.name} ({args.scenario})")
    print(f"variant   {args.variant} ({args.kernel} kernel)")
    print(f"grid      N={g.N} m={g.m} n={g.n} dt={g.dt} h=({g.h[0]:.6g}, {g.h[1]:.6g}) rad"
          f"  shape={tuple(dr.shape)}")
    print(f"free      {free:.4%} of cells")
    print(f"time      {seconds:.3f} s")
    print(f"wrote     {out}")
    return 0


def cmd_plan(args: argparse.Namespace) -> int:
    """Plan: BuiltDR, searchoptpath, certificate; write DIR/dr.npy and DIR/plan.json.

    Exit 0 when nothing was violated; 1 when a contract failed or the certificate is not clear
    (a contact or an undecided interval is a violation in every --contracts mode, off included);
    the files are written all the same, as the evidence, and the summary says so.
    """
    from .impl import kernels
    from .runs import plan, write_plan
    from .spec import load_scenario

    s = load_scenario(resolve(args.scenario))
    build, search = kernels(args.kernel)
    p = plan(s, args.variant, contracts=args.contracts, seed=args.seed, sample=args.sample,
             stop=False, build=build, search=search, kernel=args.kernel,
             witness=args.witness is not None)
    dr_path, plan_path = write_plan(p, args.out, witness=args.witness)
    violations = p.violations
    g, r, t = p.grid, p.search, p.timings_s
    print(f"scenario  {s.name} ({args.scenario})")
    print(f"variant   {p.variant}")
    print(f"grid      N={g.N} m={g.m} n={g.n} dt={g.dt} h=({g.h[0]:.6g}, {g.h[1]:.6g}) rad")
    print(f"free      {p.free_fraction:.4%} of cells")
    if r.reason is None:
        print(f"status    {r.status}: J1={r.J1} J2={r.J2} length={len(r.path)} cells")
    else:
        print(f"status    {r.status}: {r.reason}")
    if p.certificate is not None:
        print(_clearance_line(p.certificate))
    print(f"contracts {p.settings.mode.value}: {p.checked} checks, {len(violations)} violations")
    print("time      " + "  ".join(f"{k} {v:.3f} s" for k, v in t.items()))
    print(f"wrote     {dr_path}, {plan_path}" + (f", {args.witness}" if args.witness else ""))
    for v in violations:
        print(f"violation {v}", file=sys.stderr)
    if violations:
        print(f"result    {len(violations)} violation(s): exit 1; the files above are written as "
              f"the evidence", file=sys.stderr)
    return 1 if violations else 0


def _clearance_line(c: Certificate) -> str:
    """The certificate in one line: the PROVED lower bound first, then the least sampled distance
    (an upper bound on the true minimum) and its instant."""
    sampled = (f"sampled minimum {c.min_clearance_m * 1000:.6g} mm at t={c.t_min_s:.4f} s "
               f"({c.intervals} intervals)")
    if c.clear:
        return (f"clearance clear: proved >= {c.lower_bound_m * 1000:.6g} mm at every instant; "
                f"{sampled}")
    if c.contact_detail is not None:
        d = c.contact_detail
        return (f"clearance NOT CLEAR: contact at t={d.t_s:.4f} s, left link {d.links[0]} and "
                f"right link {d.links[1]}, {d.segment}; {sampled}")
    return (f"clearance NOT CLEAR: {len(c.undecided)} interval(s) neither proved clear nor in "
            f"contact, first {c.undecided[0]} s; {sampled}")


def cmd_check(args: argparse.Namespace) -> int:
    """Check another planner's dr.npy and plan.json against the spec; with --batch DIR, every
    plan folder under DIR, one task each (0 all pass, 1 any fails, 2 bad input)."""
    from .errors import MISSING

    if args.batch is not None:
        from .runs import run_batch

        for flag, value in (("--dr", args.dr), ("--plan", args.plan),
                            ("--witness", args.witness)):
            if value is not None:
                raise InputError(flag, value, "cannot be combined with --batch (each plan "
                                 "folder's own dr.npy and plan.json are checked)")
        workers, scheduler = _engine(args)
        return run_batch(args.batch, None if args.scenario is None else resolve(args.scenario),
                         json_out=args.json, workers=workers, scheduler=scheduler,
                         connect_timeout=args.connect_timeout)
    from .runs import run_check

    for flag, value in (("SCENARIO", args.scenario), ("--dr", args.dr), ("--plan", args.plan)):
        if value is None:
            raise InputError(flag, MISSING, "is required (or check a folder of plans with "
                             "--batch DIR [SCENARIO])")
    for flag in ("--json", "--workers", "--scheduler"):
        if getattr(args, flag[2:]) is not None:
            raise InputError(flag, getattr(args, flag[2:]), "is an option of --batch")
    return run_check(resolve(args.scenario), args.dr, args.plan, args.witness)


def cmd_selftest(args: argparse.Namespace) -> int:
    """Seed faults and show which contract check catches each; with --code, seeded mutations
    of a copy of the source, and which of prove, the contracts and the tests catch each."""
    if not args.code:
        for flag in ("mutant", "checks", "json", "prove_only"):
            value = getattr(args, flag)
            if value:
                raise InputError("--" + flag.replace("_", "-"),
                                 value[0] if isinstance(value, list) else value,
                                 "is an option of --code")
        from .runs import run_selftest

        return run_selftest()
    from .runs import CODE_CHECKS, run_code_selftest

    checks = tuple(c.strip() for c in args.checks.split(",")) if args.checks else CODE_CHECKS
    return run_code_selftest(args.mutant or None, checks=checks,
                             prove_only=args.prove_only or (), json_out=args.json)


def cmd_prove(args: argparse.Namespace) -> int:
    """Discharge every obligation; with --audit, also write the audit report."""
    from .proofs import run_prove

    if args.only and args.audit is not None:
        # A report a reviewer trusts is of a whole run: a selection would show the rest missing.
        raise InputError("--audit", args.audit, "needs every obligation; run it without --only")
    if args.audit is None:
        return run_prove(out_dir=args.out, scenarios_dir=args.scenarios, only=args.only,
                         repin=args.repin, workers=args.workers)
    import multiprocessing

    from .impl import progress_silenced
    from .report import run_audit

    # The report's plans, pictures and campaign need no proof: a second process (forked, so it
    # starts at once with everything imported) computes them while this one discharges the
    # obligations, and reads results.json only once the gate opens. If the prove run stops with
    # an error, the gate opens with `stopped` set and the report process ends writing nothing.
    results = str(Path(args.out) / "results.json")
    mp = multiprocessing.get_context("fork")
    gate, stopped = mp.Event(), mp.Event()

    def proofs_ready() -> str:
        gate.wait()
        if stopped.is_set():
            raise InputError("--audit", args.audit, "not written: the prove run stopped")
        return results

    def audit() -> None:
        from .impl import set_kernel_threads

        set_kernel_threads(1)          # beside the prove run's processes
        try:
            code = run_audit(None, args.audit, argv=["cfmpa", *args.argv],
                             proofs_json=proofs_ready, scenarios_dir=args.scenarios)
        except BaseException as exc:   # said after the proofs, or not at all if they stopped
            gate.wait()
            if stopped.is_set():
                os._exit(1)

            def again(exc: BaseException = exc) -> int:  # bound now: `except ... as` unbinds it
                raise exc
            code = _handled(again)
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)

    with progress_silenced():          # two processes' bars would cut up the summary
        worker = mp.Process(target=audit, name="cfmpa-audit", daemon=True)
        worker.start()
        try:
            code = run_prove(out_dir=args.out, scenarios_dir=args.scenarios, only=args.only,
                             repin=args.repin, workers=args.workers)
        except BaseException:
            stopped.set()
            gate.set()
            worker.join(timeout=5)
            raise
        print(flush=True)
        gate.set()
        worker.join()
    return code or worker.exitcode or 0


def cmd_audit(args: argparse.Namespace) -> int:
    """Write the audit report (HTML and its JSON twin)."""
    from .report import run_audit

    files = [str(resolve(a)) for a in args.scenarios] or None
    return run_audit(files, args.out, argv=["cfmpa", *args.argv],
                     proofs_json=args.proofs, compare_n=args.compare_n,
                     campaign=args.campaign)


def cmd_scenarios(args: argparse.Namespace) -> int:
    """List the bundled scenarios: name, grid size and purpose."""
    from .scenarios import BUNDLED_DIR, bundled_names
    from .spec import load_scenario, make_grid

    print(f"bundled scenarios in {BUNDLED_DIR} (give the name or a path to any command)")
    for name in bundled_names():
        s = load_scenario(BUNDLED_DIR / f"{name}.toml")
        g = make_grid(s)
        print(f"{name:<16} dt={s.dt:g} s  grid N={g.N} m={g.m} n={g.n}")
        print(f"{'':<16} {s.purpose}")
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    """The paper's experimental claim, measured on seeded random workcells (one task each on a
    local Dask cluster, a running one, or in this process); resumable in --out."""
    from .report import run_compare

    workers, scheduler = _engine(args)
    return run_compare(n=args.n, seed=args.seed, out=args.out, dt=args.dt, workers=workers,
                       scheduler=scheduler, connect_timeout=args.connect_timeout)


def cmd_certify(args: argparse.Namespace) -> int:
    """Certify any trajectory file: proved clearance, tolerance tube (0 clear, 1 not, 2 input)."""
    from .runs import run_certify

    return run_certify(resolve(args.scenario), args.traj, json_out=args.json,
                       allow_speed=args.allow_speed)


def cmd_monitor(args: argparse.Namespace) -> int:
    """Stream a measured joint log against the certified tube (0 inside, 1 outside, 2 input)."""
    from .runs import run_monitor

    return run_monitor(resolve(args.scenario), args.traj, args.log, json_out=args.json,
                       allow_speed=args.allow_speed)


def cmd_simulate(args: argparse.Namespace) -> int:
    """Write a simulated measured log of a trajectory (lag, noise, seed, excursions)."""
    from .runs import parse_excursion, run_simulate

    return run_simulate(resolve(args.scenario), args.traj, args.out, lag=args.lag,
                        noise=args.noise, seed=args.seed,
                        excursions=[parse_excursion(e) for e in args.excursion],
                        period=args.period, samples=args.samples, tail=args.tail,
                        allow_speed=args.allow_speed)


def _engine(args: argparse.Namespace) -> tuple[int, str | None]:
    """(workers, scheduler) of --workers and --scheduler: a local cluster of one worker per CPU
    unless either is given; both at once is refused."""
    import os

    if args.scheduler is not None and args.workers is not None:
        raise InputError("--workers", args.workers, "cannot be combined with --scheduler (the "
                         "cluster's own workers run the tasks)")
    if args.scheduler is not None:
        return 0, args.scheduler
    if args.workers is not None:
        return args.workers, None
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (
        os.cpu_count() or 1), None


def _engine_arguments(p: argparse.ArgumentParser) -> None:
    """--workers, --scheduler, --connect-timeout (cfmpa compare, cfmpa check --batch)."""
    p.add_argument("--workers", type=_positive, default=None, metavar="K",
                   help="worker processes of a local Dask cluster (default: one per CPU; 0: "
                        "run in this process, no cluster)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on a running Dask cluster instead (tcp://HOST:PORT of `dask "
                        "scheduler`; its workers need cfmpa installed)")
    p.add_argument("--connect-timeout", type=float, default=10.0, metavar="S",
                   help="seconds to wait for the scheduler and its first worker (default 10)")


def _positive(value: str) -> int:
    try:
        n = int(value)
    except ValueError:
        n = -1
    if n < 0:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 0, got {value!r}")
    return n


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="cfmpa", description=__doc__.splitlines()[0])
    p.add_argument("--version", action="version", version=f"cfmpa {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    d = sub.add_parser("dr", help="build the collision-state database D_R (BuiltDR)")
    d.add_argument("scenario", help="scenario: a bundled name (cfmpa scenarios) or a TOML file")
    d.add_argument("--variant", type=_variant, default="modified",
                   help="original | modified | tight (default: modified)")
    d.add_argument("--out", required=True, help="output folder (dr.npy is written there)")
    d.add_argument("--kernel", choices=["fast", "reference"], default="fast",
                   help="fast (default; bit-identical to the reference) or reference")
    d.set_defaults(func=cmd_dr)

    pl = sub.add_parser("plan", help="plan the subordinate's path; write dr.npy and plan.json")
    pl.add_argument("scenario", help="scenario: a bundled name (cfmpa scenarios) or a TOML file")
    pl.add_argument("--variant", type=_variant, default="modified",
                    help="original | modified | tight (default: modified)")
    pl.add_argument("--out", required=True, help="output folder")
    pl.add_argument("--contracts", choices=["off", "sampled", "full"], default="full",
                    help="contract checking of BuiltDR and searchoptpath (default: full, every "
                         "cell and optimality through the witness)")
    pl.add_argument("--seed", type=int, default=0, help="seed of the sampled contracts")
    pl.add_argument("--sample", type=int, default=None,
                    help="cells checked by sampled contracts (default: the mode's own)")
    pl.add_argument("--kernel", choices=["fast", "reference"], default="fast",
                    help="fast (default; bit-identical to the reference) or reference")
    pl.add_argument("--witness", default=None, metavar="FILE",
                    help="also write the search's witness of its answer (npz, docs/model.md "
                         "§11); plan.json gets its witness_sha256")
    pl.set_defaults(func=cmd_plan)

    c = sub.add_parser("check", help="check another planner's dr.npy and plan.json (or a "
                                     "folder of plan folders with --batch)")
    c.add_argument("scenario", nargs="?", default=None,
                   help="scenario the outputs are for: a bundled name or a TOML file (with "
                        "--batch: optional, else each plan's bundled scenario by its name)")
    c.add_argument("--dr", default=None, help="dr.npy (uint8, shape (N + 1, m, n))")
    c.add_argument("--plan", default=None, help="plan.json (docs/model.md §9)")
    c.add_argument("--witness", default=None, metavar="FILE",
                   help="a witness file (cfmpa plan --witness) to verify for optimality; "
                        "without it the fast search computes one")
    c.add_argument("--batch", default=None, metavar="DIR",
                   help="check every folder under DIR holding plan.json and dr.npy, one task "
                        "per plan; summary in DIR/check-batch.json")
    c.add_argument("--json", default=None, metavar="OUT",
                   help="with --batch: write the summary here instead")
    _engine_arguments(c)
    c.set_defaults(func=cmd_check)

    st = sub.add_parser("selftest", help="seed faults; show which check catches each")
    st.add_argument("--code", action="store_true",
                    help="mutate a copy of the source instead (minutes): which of cfmpa prove, "
                         "the contracts and the tests catch each mutant; exit 1 unless prove "
                         "catches every one")
    st.add_argument("--mutant", action="append", metavar="NAME",
                    help="with --code: only this mutant (repeatable)")
    st.add_argument("--checks", metavar="LIST",
                    help="with --code: comma-separated, of prove,contracts,tests (default all)")
    st.add_argument("--prove-only", action="append", metavar="ID",
                    help="with --code: cfmpa prove on these obligations only (as its --only)")
    st.add_argument("--json", metavar="OUT", help="with --code: the table as JSON")
    st.set_defaults(func=cmd_selftest)

    pr = sub.add_parser("prove", help="discharge every obligation (make prove)")
    pr.add_argument("--out", default="build/proofs", help="results folder (default build/proofs)")
    pr.add_argument("--scenarios", default=None,
                    help="a folder of your workcells (*.toml) to prove: seven checks per file, "
                         "ids from the file names (default: the bundled workcells)")
    pr.add_argument("--only", action="append", default=None,
                    help="an obligation id, prefix or glob (repeatable)")
    pr.add_argument("--audit", metavar="DIR", default=None,
                    help="then write the audit report to DIR")
    pr.add_argument("--repin", action="store_true",
                    help="rewrite proofs/obligations.lock with the statements run and print "
                         "what changed (review the diff), instead of failing on a change")
    pr.add_argument("--workers", type=int, default=None, metavar="K",
                    help="processes discharging obligations side by side (default 2 on a "
                         "machine with two cores or more, else 1); the results do not depend on K")
    pr.set_defaults(func=cmd_prove)

    au = sub.add_parser("audit", help="write report.html and report.json")
    au.add_argument("scenarios", nargs="*",
                    help="scenario names or files (default: all bundled); the report shows the "
                         "per-scenario obligations of exactly these workcells")
    au.add_argument("--out", required=True, help="output folder")
    au.add_argument("--proofs", default=None,
                    help="results.json of a prove run to report (default: prove afresh); it "
                         "must cover the given workcells' checks, others' rows are left out")
    au.add_argument("--compare-n", type=_positive, default=100,
                    help="workcells in the campaign (0 skips it; default 100)")
    au.add_argument("--campaign", metavar="DIR", default=None,
                    help="show the campaign `cfmpa compare --out DIR` recorded there (read "
                         "from its records, not run again) instead of running one")
    au.set_defaults(func=cmd_audit)

    sc = sub.add_parser("scenarios", help="list the bundled scenarios and their purposes")
    sc.set_defaults(func=cmd_scenarios)

    co = sub.add_parser("compare", help="original vs modified vs tight on random workcells")
    co.add_argument("--n", type=_positive, default=100, help="workcells (default 100)")
    co.add_argument("--seed", type=int, default=0, help="campaign seed (default 0)")
    co.add_argument("--dt", type=float, default=0.1,
                    help="time step of the workcells in s (default 0.1; the bundled default "
                         "scenario's is 0.02)")
    co.add_argument("--out", default=None,
                    help="folder for compare.json and the store compare.jsonl (a rerun of the "
                         "same settings resumes from it)")
    _engine_arguments(co)
    co.set_defaults(func=cmd_compare)

    ce = sub.add_parser("certify", help="certify any trajectory file: proved clearance and "
                                        "tolerance tube")
    _trajectory_arguments(ce, "trajectory: CSV t,left1,left2,right1,right2 or the same columns "
                              "as JSON (docs/model.md §12)",
                          "certify even when a joint speed exceeds the scenario's omega")
    ce.add_argument("--json", default=None, metavar="OUT", help="write the result as JSON")
    ce.set_defaults(func=cmd_certify)

    mo = sub.add_parser("monitor", help="check a measured joint log against the certified tube")
    _trajectory_arguments(mo)
    mo.add_argument("--log", required=True, metavar="LOG",
                    help="measured samples, CSV t,left1,left2,right1,right2 (- for stdin)")
    mo.add_argument("--json", default=None, metavar="OUT", help="write the result as JSON")
    mo.set_defaults(func=cmd_monitor)

    si = sub.add_parser("simulate", help="write a simulated measured log of a trajectory")
    _trajectory_arguments(si)
    si.add_argument("--out", required=True, metavar="LOG", help="the log file to write (CSV)")
    si.add_argument("--lag", type=float, default=0.0, help="tracking lag in s (default 0)")
    si.add_argument("--noise", type=float, default=0.0,
                    help="bounded uniform noise per joint in rad (default 0)")
    si.add_argument("--seed", type=int, default=0, help="noise seed (default 0)")
    si.add_argument("--excursion", action="append", default=[], metavar="T:JOINT:RAD[:DURATION]",
                    help="add RAD to JOINT from T for DURATION s (default 0.05; repeatable)")
    si.add_argument("--period", type=float, default=None,
                    help="sample period in s (default 0.001)")
    si.add_argument("--samples", type=int, default=None,
                    help="this many evenly spaced samples instead of --period")
    si.add_argument("--tail", type=float, default=0.0,
                    help="keep sampling this many s after the trajectory ends (default 0)")
    si.set_defaults(func=cmd_simulate)
    return p


def _trajectory_arguments(p: argparse.ArgumentParser, traj: str = "the planned trajectory",
                          speed: str = "accept a trajectory whose joint speeds exceed omega"
                          ) -> None:
    """What certify, monitor and simulate share: the scenario, --traj and --allow-speed."""
    p.add_argument("scenario", help="scenario (the geometry): a bundled name or a TOML file")
    p.add_argument("--traj", required=True, metavar="FILE", help=traj)
    p.add_argument("--allow-speed", action="store_true", help=speed)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit code (errors become messages, never tracebacks)."""
    parser = _parser()
    args = parser.parse_args(argv)
    # The provenance records what this call was given, not the process's sys.argv.
    args.argv = list(sys.argv[1:] if argv is None else argv)
    return _handled(lambda: args.func(args))


def _handled(run: Callable[[], int]) -> int:
    """``run()``'s exit code; an error becomes its message on stderr and its exit code."""
    try:
        return int(run())
    except InputError as exc:
        print(exc.render(), file=sys.stderr)
        return exc.exit_code
    except CfmpaError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return exc.exit_code
    except OSError as exc:
        name = exc.filename if exc.filename is not None else "file"
        print(f"{name}: error: {exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
