"""`make bench`: BuiltDR, the search, `cfmpa plan`, `check`, `dr`, `monitor` and `make prove`
timed; shapely side by side.

Writes OUT/results.json (default bench/results.json) and prints a table: the median of the runs
after a warm-up, with min and max, and each item's peak resident memory (its own process).
Items slower than their time budget get fewer runs; the table says how many. --quick is a smoke
run on a coarse grid (one run each, one process for all in-process items, so its memory column
is that process's high-water mark so far; no warm-up). Never imported by the package.

The table ends with the project's performance targets (``targets``: full checking's,
the monitor's throughput, `make prove`'s time), each met or missed, and an informational
section of former targets. ``builtdr_profile`` splits BuiltDR fast into its stages (the numbers
behind the 0.10 s target's note); the BuiltDR items report the cold call (the first in the
process, kernels loaded: ``cold_s``) apart from the warm ones (the median). `make prove` itself
(`cfmpa prove --audit DIR`, one run, a minute or two) is measured only with --prove, which `make
bench` passes; so is `cfmpa audit default --compare-n 0` (one run, ``audit_section``).

The campaign item (`cfmpa compare`, a fixed campaign with 1 and 2 local workers, and the
speed-up) runs in the full bench and alone with ``--only campaign`` (merged into an existing
results.json); --quick leaves it out (its cluster start alone is seconds). Likewise
``plan_scaling`` (``--only plan_scaling``): `cfmpa plan --contracts full` of the default
workcell at dt = 0.02, 0.01, 0.0075, 0.005 in fresh processes, with cells, seconds, peak resident
memory and bytes a cell (docs/model.md §3's cell budget rests on it). And ``certify_stream``
(``--only certify_stream``): `cfmpa certify` of a long slow trajectory of 10^6 and 10^7 rows
by default (and of 10^5, to show the peak does not grow with the rows), seconds and the child's
peak memory, against their targets. And
``tools`` (``--only tools``): BuiltDR fast of the bundled gripper and levels workcells, with
their ratio to the default workcell's. And ``first_run`` (``--only first_run``; --quick too):
`cfmpa plan default` with a fresh NUMBA_CACHE_DIR (the kernels compiled) against later runs
with that cache, the first at most 2x a later one. And ``dr_dask`` (``--only dr_dask``):
`cfmpa dr` at dt = 0.005 in one process and on 1 and 2 local Dask workers, and `cfmpa plan
--contracts full --store zarr` at dt = 0.0035 (1.11 G cells), with their targets.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
WORKER = Path(__file__).resolve().parent / "_worker.py"
DEFAULT_CELLS = {"start_cell": (40, 100), "goal_cell": (150, 60)}   # default.toml, dt = 0.02
VARIANTS = ("original", "modified", "tight")
GIB = 1024.0


@dataclass
class Config:
    quick: bool
    runs: int
    warmup: int = 1
    budget_s: float = 120.0                # per item: fewer runs when one run is slower
    dt: float = 0.02                       # the default scenario's own
    sample: int = 2000                     # per-cell shapely loop
    dwithin_stride: int = 8                # vectorised dwithin: every 8th layer, extrapolated
    scaling_dts: tuple[float, ...] = (0.04, 0.02, 0.01)
    #: `cfmpa plan --contracts full` of the default workcell per dt, fresh processes (seconds,
    #: peak MiB, bytes a cell); 0.005 (381 M cells) is left to a quiet machine.
    plan_scaling_dts: tuple[float, ...] = (0.02, 0.01, 0.0075, 0.005)
    one_degree: dict[str, Any] = field(default_factory=dict)
    prove: bool = False                    # time `make prove` (cfmpa prove --audit): one run
    monitor_samples: int = 1_000_000       # the monitor's log (10^6 samples)

    @classmethod
    def of(cls, quick: bool, runs: int | None, prove: bool = False) -> Config:
        if quick:
            return cls(quick=True, runs=runs or 1, warmup=0, budget_s=20.0, dt=0.16, sample=100,
                       dwithin_stride=1, scaling_dts=(0.32, 0.16, 0.08),
                       plan_scaling_dts=(0.16, 0.08),
                       one_degree=one_degree(10), prove=prove, monitor_samples=20_000)
        return cls(quick=False, runs=runs or 5, one_degree=one_degree(1), prove=prove)


def default_at(dt: float) -> dict[str, Any]:
    """The default scenario at time step dt, its start and goal cells scaled to the new grid."""
    scale = 0.02 / dt
    return {"path": "scenarios/default.toml",
            "overrides": {"dt": dt} | {f"right__{k}": [round(c * scale) for c in v]
                                       for k, v in DEFAULT_CELLS.items()}}


def one_degree(degrees: int) -> dict[str, Any]:
    """The default workcell on a grid of `degrees` degrees (361 x 361 at 1) with about 150 / degrees
    layers: dt = h / omega, the principal's move lengthened so that N = ceil(Tf / dt) hits it."""
    dt = math.radians(degrees)
    layers = 150 // degrees
    start = [0.3, 0.8]
    goal = [start[0] + (layers - 0.5) * dt, 2.2]   # omega = 1: Tf = (layers - 0.5) dt
    scale = 0.02 / dt
    return {"path": "scenarios/default.toml",
            "overrides": {"dt": dt, "left__start": start, "left__goal": goal}
            | {f"right__{k}": [round(c * scale) for c in v] for k, v in DEFAULT_CELLS.items()}}


# ------------------------------------------------------------------------------ running ----

def stats(times: list[float], **extra: Any) -> dict[str, Any]:
    return {"median_s": statistics.median(times), "min_s": min(times), "max_s": max(times),
            "runs": len(times), **extra}


def in_workers(cfg: Config, items: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Run worker items: one process each (per-item memory), or all in one process if --quick."""
    for it in items:
        it.setdefault("runs", cfg.runs)
        it.setdefault("warmup", cfg.warmup)
        it.setdefault("budget_s", cfg.budget_s)
    groups = [items] if cfg.quick else [[it] for it in items]
    out: list[dict[str, Any]] = []
    for group in groups:
        proc = subprocess.run([sys.executable, str(WORKER), json.dumps(group)], cwd=ROOT,
                              capture_output=True, text=True)
        if proc.returncode != 0:
            raise SystemExit(f"bench worker failed on {group}:\n{proc.stderr}")
        for r in json.loads(proc.stdout.strip().splitlines()[-1]):
            out.append(stats(r["times_s"], peak_rss_mb=r["peak_rss_mb"],
                             rss_before_mb=r["rss_before_mb"], cold_s=r.get("cold_s"),
                             info=r["info"]))
    return out


def cfmpa_exe() -> Path | None:
    exe = ROOT / ".venv" / "bin" / "cfmpa"
    return exe if exe.exists() else (Path(p) if (p := shutil.which("cfmpa")) else None)


def cli_has(command: str) -> bool:
    exe = cfmpa_exe()
    if exe is None:
        return False
    help_text = subprocess.run([str(exe), "--help"], capture_output=True, text=True).stdout
    return f"{command}" in help_text.split("COMMAND", 1)[-1]


def cli_run(cfg: Config, argv: list[str], program: list[str] | None = None, *,
            runs: int | None = None, warmup: int | None = None,
            env: dict[str, str] | None = None, stderr_of_first: bool = False) -> dict[str, Any]:
    """Time a `cfmpa` command (or ``program``) in its own process; peak memory from that
    process's rusage (ru_maxrss: the largest of it and the children it waited for).
    ``runs`` and ``warmup`` override the configuration's; ``env`` is added to the environment;
    ``stderr_of_first``: the first run's stderr lines go into the result (``stderr_lines``)."""
    exe = program or [str(cfmpa_exe())]
    times: list[float] = []
    peak = 0.0
    first_err: list[str] | None = None
    runs = cfg.runs if runs is None else runs
    warmup = cfg.warmup if warmup is None else warmup
    for n in range(warmup + runs):
        with tempfile.TemporaryFile() as err:   # a file, not a pipe: a full pipe would block
            t0 = time.perf_counter()
            proc = subprocess.Popen([*exe, *argv], cwd=ROOT, stdout=subprocess.DEVNULL,
                                    stderr=err, env=None if env is None else os.environ | env)
            _, status, usage = os.wait4(proc.pid, 0)
            seconds = time.perf_counter() - t0
            proc.returncode = os.waitstatus_to_exitcode(status)
            err.seek(0)
            text = err.read().decode(errors="replace")
            message = text.strip()[-500:]
            if first_err is None:
                first_err = text.splitlines()[-20:]
        if proc.returncode != 0:
            return {"error": f"exit {proc.returncode}: {message}", "argv": argv,
                    "seconds": seconds, "peak_rss_mb": round(usage.ru_maxrss / 1024, 1),
                    "failure_lines": failure_lines(text)}
        peak = max(peak, usage.ru_maxrss / 1024)
        if n < warmup:
            if seconds * runs > cfg.budget_s:
                runs = max(1, math.floor(cfg.budget_s / seconds))
            continue
        times.append(seconds)
        if len(times) >= runs:
            break
    extra = {"stderr_lines": first_err} if stderr_of_first else {}
    return stats(times, peak_rss_mb=round(peak, 1), argv=argv, **extra)


#: What a failing run's stderr says about why (the tail alone lost the cause once: a long
#: report printed after the failing obligation).
_FAILURE_WORDS = ("FAIL", "fail", "unexpected", "not as expected", "error", "Error", "unknown",
                  "mismatch", "violation")


def failure_lines(text: str, most: int = 40) -> list[str]:
    """The lines of a failing run's stderr that name what failed (at most ``most``, each cut to
    300 characters), in order; the tail is in the result's ``error`` already."""
    hits = [ln[:300] for ln in text.splitlines() if any(w in ln for w in _FAILURE_WORDS)]
    return hits[:most]


def scenario_file(spec: dict[str, Any], folder: Path) -> Path:
    """A TOML file for the CLI: the bundled scenario with the spec's overrides."""
    import tomllib

    doc = tomllib.loads((ROOT / spec["path"]).read_text())
    for key, value in spec.get("overrides", {}).items():
        parts = key.split("__")
        target = doc
        for p in parts[:-1]:
            target = target[p]
        target[parts[-1]] = value
    path = folder / f"bench-{abs(hash(json.dumps(spec, sort_keys=True))):x}.toml"
    path.write_text(to_toml(doc))
    return path


def to_toml(doc: dict[str, Any]) -> str:
    def value(v: Any) -> str:
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return repr(v)
    top = [f"{k} = {value(v)}" for k, v in doc.items() if not isinstance(v, dict)]
    tables = [f"\n[{k}]\n" + "\n".join(f"{kk} = {value(vv)}" for kk, vv in v.items())
              for k, v in doc.items() if isinstance(v, dict)]
    return "\n".join(top) + "\n" + "\n".join(tables) + "\n"


def skipped(why: str) -> dict[str, Any]:
    return {"skipped": why}


# ------------------------------------------------------------------------------ the bench ----

def bench(cfg: Config, tmp: Path) -> dict[str, Any]:
    t_start = time.perf_counter()
    base = default_at(cfg.dt)
    res: dict[str, Any] = {"meta": meta(cfg, base)}

    items = [{"kind": "builtdr", "scenario": base, "variant": v, "impl": impl}
             for v in VARIANTS for impl in ("reference", "fast", "fast_regions_given")]
    items += [{"kind": "builtdr_profile", "scenario": base, "variant": v} for v in VARIANTS]
    items += [{"kind": "search", "scenario": base, "variant": v, "impl": impl}
              for v in VARIANTS for impl in ("reference", "fast")]
    shp = "modified"
    items += [{"kind": "shapely_loop", "scenario": base, "variant": shp, "sample": cfg.sample,
               "seed": 7},
              {"kind": "shapely_vector", "scenario": base, "variant": shp, "op": "intersects"},
              {"kind": "shapely_vector", "scenario": base, "variant": shp, "op": "dwithin",
               "layer_stride": cfg.dwithin_stride}]
    for dt in cfg.scaling_dts:
        items += [{"kind": "builtdr", "scenario": default_at(dt), "variant": "modified",
                   "impl": "fast"},
                  {"kind": "search", "scenario": default_at(dt), "variant": "modified",
                   "impl": "fast"}]
    items += [{"kind": "plan_fast", "scenario": base, "variant": "modified",
               "contracts": "sampled"},
              {"kind": "plan_fast", "scenario": cfg.one_degree, "variant": "modified",
               "contracts": "sampled"}]
    # Contract overhead on the default grid itself, in process (imports and interpreter start
    # excluded, so the ratio is the checks' own cost). Every mode gets the same warm-up and
    # runs: full checks through the witness in seconds now, and a first run without
    # warm-up would charge it the kernels' and the spec's first-call costs that off is spared.
    items += [{"kind": "plan_fast", "scenario": base, "variant": "modified", "contracts": mode}
              for mode in CONTRACT_MODES]
    out = iter(in_workers(cfg, items))

    res["builtdr"] = {v: {impl: next(out) for impl in ("reference", "fast", "fast_regions_given")}
                      for v in VARIANTS}
    res["builtdr_profile"] = builtdr_profile(res, {v: next(out) for v in VARIANTS})
    res["search"] = {v: {impl: next(out) for impl in ("reference", "fast")} for v in VARIANTS}
    loop, inter, dwithin = next(out), next(out), next(out)
    res["shapely"] = shapely_section(res, shp, loop, inter, dwithin)
    res["scaling"] = [{"dt": dt, "cells": (b := next(out))["info"]["cells"], "builtdr_fast": b,
                       "search_fast": next(out)} for dt in cfg.scaling_dts]
    plan_fast, one_fast = next(out), next(out)
    in_process = {mode: next(out) for mode in CONTRACT_MODES}

    have_cli = cli_has("plan")
    no_cli = skipped("no `cfmpa plan` in this checkout (.venv/bin/cfmpa missing or no plan)")
    default_toml = scenario_file(base, tmp)
    one_toml = scenario_file(cfg.one_degree, tmp)
    # `cfmpa plan` in every contract mode, fresh processes, each mode's folder kept (its last
    # run's plan.json gives the in-process stages; the default mode's is what `cfmpa check` reads).
    plan_cli = {mode: cli_run(cfg, ["plan", str(default_toml), "--variant", "modified", "--out",
                                    str(tmp / f"plan-{mode}"), "--contracts", mode])
                if have_cli else no_cli for mode in CONTRACT_MODES}
    for mode, d in plan_cli.items():
        if "median_s" in d:
            d["timings_s"] = plan_timings(tmp / f"plan-{mode}")
    default_mode = cli_default_contracts() if have_cli else None
    res["plan"] = {
        "cli_sampled": plan_cli["sampled"],
        "cli_full": plan_cli["full"],
        "cli_default_contracts": default_mode,
        "fast_in_process_sampled": plan_fast,
        "note": "cli: `cfmpa plan` in a fresh process (fast kernels, imports and the kernels' "
                "cache load included); fast_in_process: plan() with the same kernels, files "
                "written, imports excluded; cli_default_contracts: the --contracts default of "
                "`cfmpa plan` (read from its parser at run time); timings_s: the last run's "
                "plan.json",
    }
    res["dr_cli"] = (cli_run(cfg, ["dr", str(default_toml), "--variant", shp, "--out",
                                   str(tmp / "dr")]) | {"variant": shp}
                     if cli_has("dr") else skipped("no `cfmpa dr` in this checkout"))
    res["check"] = check_section(cfg, tmp, default_toml, default_mode, plan_cli)
    res["prove"] = prove_section(cfg, tmp)
    res["audit"] = audit_section(cfg, tmp)
    res["contracts"] = contracts_section(have_cli, base, in_process, plan_cli)
    res["one_degree"] = {
        "grid": one_fast["info"]["grid"], "cells": one_fast["info"]["cells"],
        "plan_fast_in_process_sampled": one_fast,
        "plan_cli_sampled": cli_run(cfg, ["plan", str(one_toml), "--variant", "modified",
                                          "--out", str(tmp / "one"), "--contracts", "sampled"])
        if have_cli else no_cli,
    }
    if not cfg.quick:   # the smoke run's key set stays as it was (see the module docstring)
        res["campaign"] = campaign_section(cfg, tmp)
        res["dr_dask"] = dr_dask_section(cfg, tmp)
    res["monitor"] = monitor_section(cfg, tmp, base, have_cli and cli_has("monitor"))
    res["plan_scaling"] = plan_scaling_section(cfg, tmp) if have_cli else no_cli
    res["certify_stream"] = certify_stream_section(cfg, tmp) if have_cli else no_cli
    res["tools"] = tools_section(cfg, tmp)
    res["first_run"] = first_run_section(cfg, tmp) if have_cli else no_cli
    res["targets"] = targets(res, cfg)
    res["informational"] = informational(res, cfg)
    res["meta"]["bench_wall_s"] = round(time.perf_counter() - t_start, 1)
    return res


CONTRACT_MODES = ("off", "sampled", "full")


def plan_scaling_section(cfg: Config, tmp: Path) -> dict[str, Any]:
    """Bytes a cell: `cfmpa plan --contracts full` of the default workcell (``default_at``) at
    each of ``plan_scaling_dts``, one run each in a fresh process, the kernels loaded by one
    unrecorded run at the coarsest dt first. Per dt: cells, seconds, the process's peak
    resident memory (ru_maxrss of the child) and that peak over the cells; and the exponent of
    a least-squares fit of log seconds against log cells."""
    rows = []
    for n, dt in enumerate(cfg.plan_scaling_dts):
        spec = default_at(dt)
        toml = scenario_file(spec, tmp)
        folder = tmp / f"plan-scaling-{n}"
        run = cli_run(cfg, ["plan", str(toml), "--variant", "modified", "--out", str(folder),
                            "--contracts", "full"], runs=1, warmup=1 if n == 0 else 0)
        doc = plan_json_of(folder)
        g = doc.get("grid") or {}
        cells = (g["N"] + 1) * g["m"] * g["n"] if g else None
        row: dict[str, Any] = {"dt": dt, "cells": cells,
                               "grid": [g["N"] + 1, g["m"], g["n"]] if g else None}
        if "median_s" in run and cells:
            peak_mib = run["peak_rss_mb"]
            row |= {"seconds": round(run["median_s"], 3), "peak_mib": peak_mib,
                    "bytes_per_cell": round(peak_mib * 2**20 / cells, 2),
                    "status": doc.get("status"), "timings_s": doc.get("timings_s")}
        else:
            row["error"] = run.get("error") or run.get("skipped") or "no plan.json"
        rows.append(row)
    ok = [r for r in rows if "seconds" in r]
    exponent = None
    if len(ok) >= 2:
        x = [math.log(r["cells"]) for r in ok]
        y = [math.log(r["seconds"]) for r in ok]
        mx, my = statistics.fmean(x), statistics.fmean(y)
        exponent = round(sum((a - mx) * (b - my) for a, b in zip(x, y))
                         / sum((a - mx) ** 2 for a in x), 3)
    return {"rows": rows, "time_exponent": exponent,
            "note": "`cfmpa plan --contracts full` of the default workcell (start and goal "
                    "scaled to the grid), one run per dt in a fresh process; peak_mib is its "
                    "ru_maxrss, bytes_per_cell that over (N + 1) m n; time_exponent: the slope "
                    "of log seconds against log cells (least squares)"}


def builtdr_only(cfg: Config, res: dict[str, Any]) -> None:
    """``--only builtdr``: BuiltDR fast (right regions computed and given) and its profile, per
    variant, into ``res`` (the reference's entries are kept from the last full run)."""
    base = default_at(cfg.dt)
    impls = ("fast", "fast_regions_given")
    items = [{"kind": "builtdr", "scenario": base, "variant": v, "impl": impl}
             for v in VARIANTS for impl in impls]
    items += [{"kind": "builtdr_profile", "scenario": base, "variant": v} for v in VARIANTS]
    out = iter(in_workers(cfg, items))
    for v in VARIANTS:
        for impl in impls:
            res.setdefault("builtdr", {}).setdefault(v, {})[impl] = next(out)
    res["builtdr_profile"] = builtdr_profile(res, {v: next(out) for v in VARIANTS})


def builtdr_lines(res: dict[str, Any]) -> list[str]:
    lines = ["", "BuiltDR fast in process, cold (first call, kernels loaded) and warm (median):"]
    for v in VARIANTS:
        d = res["builtdr"][v]["fast"]
        if "median_s" in d:
            lines.append(f"  {v:9s} cold {d.get('cold_s') or float('nan'):.3f} s, warm "
                         f"{d['median_s']:.3f} s (min {d['min_s']:.3f}, max {d['max_s']:.3f}, "
                         f"{d['runs']} runs)")
    return lines + profile_lines(res.get("builtdr_profile"))


#: The first run's target: a first `cfmpa plan default` at most this many times a later one.
FIRST_RUN_LIMIT = 2.0


def first_run_section(cfg: Config, tmp: Path) -> dict[str, Any]:
    """`cfmpa plan default` as on a new machine: one run in a fresh process with a fresh
    NUMBA_CACHE_DIR (the kernels compile, in parallel processes, docs/model.md §7.5), then
    ``min(runs, 3)`` later runs with that cache (loaded, not compiled): seconds, the ratio of the
    first to the later runs' median, and the first run's stderr lines (its compile line and
    seconds; a later run prints none)."""
    cache = tmp / "first-run-numba-cache"
    env = {"NUMBA_CACHE_DIR": str(cache)}
    argv = ["plan", "default", "--out", str(tmp / "first-run")]
    first = cli_run(cfg, argv, runs=1, warmup=0, env=env, stderr_of_first=True)
    # The first run starts the compile in the background and runs the numpy kernels; wait for
    # that compile (its stamps, polled by wait_compiled) so the later runs load the fast ones.
    t0 = time.perf_counter()
    waited = subprocess.run([sys.executable, "-c", "import sys; from cfmpa.impl._kernel_cache "
                             "import wait_compiled; sys.exit(0 if wait_compiled(1800) else 1)"],
                            cwd=ROOT, env=os.environ | env, check=False).returncode == 0
    wait_s = round(time.perf_counter() - t0, 1)
    later = cli_run(cfg, argv, runs=min(cfg.runs, 3), warmup=0, env=env, stderr_of_first=True)
    out: dict[str, Any] = {"argv": argv, "first": first, "later": later,
                           "limit_x": FIRST_RUN_LIMIT, "background_compile_wait_s": wait_s,
                           "background_compile_done": waited,
                           "note": "first: one fresh process, fresh NUMBA_CACHE_DIR (it starts "
                                   "the kernels' compile in the background and runs the numpy "
                                   "kernels); then the bench waits for that compile (its "
                                   "stamps) before the later runs: fresh processes with that "
                                   "cache, median; whole processes, wall seconds"}
    if "median_s" in first and "median_s" in later:
        out["ratio_first_over_later"] = round(first["median_s"] / later["median_s"], 2)
        out["compile_lines"] = [x for x in first.get("stderr_lines") or [] if "compil" in x]
        out["later_prints_compile"] = any("compil" in x for x in later.get("stderr_lines") or [])
    return out


def first_run_lines(sec: dict[str, Any]) -> list[str]:
    if "ratio_first_over_later" not in sec:
        return ["", f"first run: {failed(sec.get('first')) or failed(sec.get('later')) or sec}"]
    return ["", f"first `cfmpa plan default` (fresh numba cache) {sec['first']['median_s']:.1f} s, "
                f"later {sec['later']['median_s']:.1f} s (median of {sec['later']['runs']}): "
                f"{sec['ratio_first_over_later']:.2f}x (target <= {sec['limit_x']:g}x); "
                + "; ".join(sec.get("compile_lines", []))]


#: `cfmpa certify` of a long slow trajectory, by default (no limit raised): rows, and the
#: targets by rows (seconds, peak MiB of the child process).
CERTIFY_STREAM = {"rows": (100_000, 1_000_000, 10_000_000), "quick_rows": (2_000, 20_000),
                  "dt": 0.01, "target_s": 20.0, "target_mib": 300.0,
                  "targets": {1_000_000: (20.0, 300.0), 10_000_000: (200.0, 300.0)}}


def slow_trajectory_csv(path: Path, rows: int, dt: float) -> int:
    """A trajectory CSV of ``rows`` rows every ``dt`` s in the default workcell: both arms
    swaying slowly (at most 0.005 rad/s) well apart (about 0.38 m), so it is certified clear with
    every piece proved at once. Written a block at a time; returns its size in bytes."""
    import numpy as np

    with open(path, "w") as fh:
        fh.write("t,left1,left2,right1,right2\n")
        for start in range(0, rows, 100_000):
            t = np.arange(start, min(rows, start + 100_000)) * dt
            a = np.column_stack([t, 1.68 + 0.1 * np.sin(2 * np.pi * t / 200),
                                 -2.44 + 0.1 * np.sin(2 * np.pi * t / 150),
                                 0.35 + 0.2 * np.sin(2 * np.pi * t / 300),
                                 0.6 + 0.2 * np.sin(2 * np.pi * t / 250)])
            np.savetxt(fh, a, fmt="%.12g", delimiter=",")
    return path.stat().st_size


def certify_stream_section(cfg: Config, tmp: Path) -> dict[str, Any]:
    """`cfmpa certify` of ``slow_trajectory_csv`` at each row count, one run each in a fresh
    process with the default limits (a streamed trajectory has no byte limit, docs/model.md
    §12): seconds, the child's peak resident memory (ru_maxrss), bytes a row of that peak, and
    the command's own split into reading and certifying (timings_s); ``peak_growth_mib``: the
    largest minus the smallest."""
    rows_list = CERTIFY_STREAM["quick_rows"] if cfg.quick else CERTIFY_STREAM["rows"]
    out: dict[str, Any] = {"runs": [], "target_s": CERTIFY_STREAM["target_s"],
                           "target_mib": CERTIFY_STREAM["target_mib"],
                           "note": "one run each; the trajectory is default.toml's arms swaying "
                                   "slowly apart every 0.01 s (bench/run.py slow_trajectory_csv)"}
    for rows in rows_list:
        traj = tmp / f"slow-{rows}.csv"
        size = slow_trajectory_csv(traj, rows, CERTIFY_STREAM["dt"])
        report = tmp / f"certify-{rows}.json"
        run = cli_run(cfg, ["certify", "default", "--traj", str(traj), "--json", str(report)],
                      runs=1, warmup=0)
        entry: dict[str, Any] = {"rows": rows, "bytes": size}
        if "median_s" in run:
            doc = json.loads(report.read_text())
            entry |= {"seconds": round(run["median_s"], 3), "peak_mib": run["peak_rss_mb"],
                      "peak_bytes_per_row": round(run["peak_rss_mb"] * 2**20 / rows, 1),
                      "clear": doc["clear"], "intervals": doc["intervals"],
                      "timings_s": doc["timings_s"]}
        else:
            entry["error"] = run.get("error")
        out["runs"].append(entry)
        traj.unlink()
    ok = [r for r in out["runs"] if "peak_mib" in r]
    if len(ok) >= 2:
        out["peak_growth_mib"] = round(ok[-1]["peak_mib"] - ok[0]["peak_mib"], 1)
    return out


def certify_stream_lines(sec: dict[str, Any]) -> list[str]:
    lines = ["", "cfmpa certify, streamed (a long slow trajectory):",
             f"{'rows':>9s} {'seconds':>9s} {'peak MiB':>9s} {'B/row':>7s} {'read s':>7s} "
             f"{'cert s':>7s}"]
    for r in sec.get("runs", []):
        if "seconds" in r:
            t = r["timings_s"]
            lines.append(f"{r['rows']:9d} {r['seconds']:9.2f} {r['peak_mib']:9.1f} "
                         f"{r['peak_bytes_per_row']:7.1f} {t.get('load', 0):7.2f} "
                         f"{t.get('certificate', 0):7.2f}")
        else:
            lines.append(f"{r['rows']:9d} {r.get('error')}")
    if "peak_growth_mib" in sec:
        lines.append(f"peak growth over the rows: {sec['peak_growth_mib']} MiB (targets: "
                     + ", ".join(f"{n:,} rows in {lim[0]:g} s and {lim[1]:g} MiB" for n, lim in
                                 CERTIFY_STREAM["targets"].items()) + ")")
    return lines


TOOL_WORKCELLS = ("gripper", "levels")


def tools_section(cfg: Config, tmp: Path) -> dict[str, Any]:
    """BuiltDR fast (modified) of the bundled tool and height workcells against the default
    workcell they are built on (the same arms, motion and grid: ``default_at``'s overrides on
    each file), in worker processes: the medians and each one's ratio to the default's. A tool
    adds a region per arm and up to five pairs of parts; heights drop pairs (docs/model.md §2)."""
    base = default_at(cfg.dt)
    names = ("default",) + TOOL_WORKCELLS
    items = [{"kind": "builtdr", "impl": "fast", "variant": "modified",
              "scenario": base | {"path": f"scenarios/{name}.toml"}} for name in names]
    got = dict(zip(names, in_workers(cfg, items)))
    ref = med(got["default"])
    rows = {}
    for name in names:
        m = med(got[name])
        rows[name] = got[name] | {"ratio_to_default": (round(m / ref, 2) if m and ref else None)}
    return {"dt": cfg.dt, "variant": "modified", "rows": rows,
            "note": "build_dr_fast in its own process per workcell, after a warm-up; the ratio "
                    "is of medians from this one run"}


def tools_lines(sec: dict[str, Any]) -> list[str]:
    lines = ["", f"BuiltDR fast with tools and heights (modified, dt = {sec.get('dt')}):",
             f"{'workcell':>10s} {'median s':>9s} {'peak MiB':>9s} {'x default':>9s}"]
    for name, r in sec.get("rows", {}).items():
        if "median_s" in r:
            lines.append(f"{name:>10s} {r['median_s']:9.3f} {r.get('peak_rss_mb', 0):9.1f} "
                         f"{r['ratio_to_default'] or 0:9.2f}")
        else:
            lines.append(f"{name:>10s} {failed(r)}")
    return lines


def plan_json_of(folder: Path) -> dict[str, Any]:
    try:
        return json.loads((folder / "plan.json").read_text())
    except (OSError, ValueError):
        return {}


def plan_scaling_lines(sec: dict[str, Any]) -> list[str]:
    lines = ["", "cfmpa plan --contracts full, default workcell (bytes a cell):",
             f"{'dt':>8s} {'cells':>12s} {'seconds':>9s} {'peak MiB':>9s} {'B/cell':>7s}"]
    for r in sec.get("rows", []):
        if "seconds" in r:
            lines.append(f"{r['dt']:8g} {r['cells']:12d} {r['seconds']:9.2f} "
                         f"{r['peak_mib']:9.1f} {r['bytes_per_cell']:7.2f}")
        else:
            lines.append(f"{r['dt']:8g} {str(r.get('cells')):>12s} {r.get('error')}")
    if sec.get("time_exponent") is not None:
        lines.append(f"time ~ cells^{sec['time_exponent']}")
    return lines


def cli_default_contracts() -> str | None:
    """The --contracts default of `cfmpa plan`, read at run time: from the CLI's own parser, or
    failing that from `cfmpa plan --help` ("default: MODE")."""
    try:
        from cfmpa.cli import _parser

        subcommands = _parser()._subparsers._group_actions          # the COMMAND choice
        found = [str(a.default) for s in subcommands if "plan" in s.choices
                 for a in s.choices["plan"]._actions if "--contracts" in a.option_strings]
    except Exception:   # noqa: BLE001 - a parser shaped otherwise: fall back to --help
        found = []
    if found:
        return found[0]
    import re

    exe = cfmpa_exe()
    if exe is None:
        return None
    text = subprocess.run([str(exe), "plan", "--help"], capture_output=True, text=True,
                          check=False).stdout
    m = re.search(r"--contracts \{[^}]*\}\s+.*?\(default:\s*(\w+)", " ".join(text.split()))
    return m.group(1) if m else None


def plan_timings(folder: Path) -> dict[str, float] | None:
    """timings_s of the plan.json in ``folder`` (the last `cfmpa plan` run written there)."""
    try:
        return json.loads((folder / "plan.json").read_text()).get("timings_s")
    except (OSError, ValueError):
        return None


def check_section(cfg: Config, tmp: Path, toml: Path, default_mode: str | None,
                  plan_cli: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """`cfmpa check` of a good plan: the dr.npy and plan.json that `cfmpa plan` wrote in its
    default contract mode (the last run of that mode above), no witness given, so check
    computes one with the fast search and verifies it with the spec's checker, as for another
    planner's files. Fresh processes; exit 0 (every check holds) is required."""
    if not cli_has("check"):
        return skipped("no `cfmpa check` in this checkout")
    mode = default_mode if default_mode in plan_cli else "sampled"
    folder = tmp / f"plan-{mode}"
    if "median_s" not in plan_cli[mode] or not (folder / "plan.json").exists():
        return skipped(f"no good plan to check (`cfmpa plan --contracts {mode}` did not run)")
    run = cli_run(cfg, ["check", str(toml), "--dr", str(folder / "dr.npy"), "--plan",
                        str(folder / "plan.json")])
    return run | {"plan_contracts": mode, "witness": "none given (computed and verified)"}


def prove_section(cfg: Config, tmp: Path) -> dict[str, Any]:
    """`make prove` as a whole process: `cfmpa prove --audit DIR` (every obligation, then the
    audit report), one run, no warm-up (a minute or two); with --prove only. Also the
    obligations alone: results.json's `seconds` (the discharge loop, as the prove summary says)."""
    if not cfg.prove:
        return skipped("--prove not given (`make bench` passes it)")
    if not cli_has("prove"):
        return skipped("no `cfmpa prove` in this checkout")
    out, audit = tmp / "proofs", tmp / "audit"
    run = cli_run(cfg, ["prove", "--out", str(out), "--audit", str(audit)], runs=1, warmup=0)
    run["note"] = ("make prove is `cfmpa prove --audit build/audit`; here --out and --audit are "
                   "a temporary folder's, so build/ is left alone")
    try:
        doc = json.loads((out / "results.json").read_text())
        run.update(obligations_s=doc.get("seconds"), ok=doc.get("ok"),
                   obligations=len(doc.get("obligations", [])))
    except (OSError, ValueError) as e:
        run["obligations_error"] = f"no results.json: {e}"
    return run


def audit_section(cfg: Config, tmp: Path) -> dict[str, Any]:
    """`cfmpa audit default --compare-n 0` as a whole process (its own prove of the default
    workcell, then the report; no campaign): one run, no warm-up; with --prove only."""
    if not cfg.prove:
        return skipped("--prove not given (`make bench` passes it)")
    if not cli_has("audit"):
        return skipped("no `cfmpa audit` in this checkout")
    return cli_run(cfg, ["audit", "default", "--out", str(tmp / "audit-default"),
                         "--compare-n", "0"], runs=1, warmup=0)


def monitor_section(cfg: Config, tmp: Path, base: dict[str, Any], have_cli: bool
                    ) -> dict[str, Any]:
    """`cfmpa monitor` on a simulated log of 10^6 samples (--quick: 2 x 10^4) of the default
    plan's traj.csv, and on one a tenth as long: throughput (the stream alone, from the monitor's
    own timings_s, and the whole process) and each process's peak memory, which should not grow
    with the log (it is read a block at a time)."""
    if not have_cli:
        return skipped("no `cfmpa monitor` in this checkout")
    exe = str(cfmpa_exe())
    toml = scenario_file(base, tmp)
    folder = tmp / "monitor"
    proc = subprocess.run([exe, "plan", str(toml), "--out", str(folder), "--contracts", "off"],
                          cwd=ROOT, capture_output=True, text=True)
    traj = folder / "traj.csv"
    if not traj.exists():
        return {"error": f"no traj.csv from cfmpa plan (exit {proc.returncode}): "
                         f"{proc.stderr[-300:]}"}
    big = cfg.monitor_samples
    out: dict[str, Any] = {"scenario": base, "traj_rows": len(traj.read_text().splitlines()) - 1,
                           "note": "log: cfmpa simulate --samples N --noise 0.002 (17 significant "
                                   "digits a value, ~96 bytes a sample); stream: the monitor's "
                                   "own timings_s.monitor (reading, parsing, checking); cli: the "
                                   "whole process (imports and the certificate included)"}
    for key, n in (("log", big), ("log_tenth", big // 10)):
        log = tmp / f"monitor-{n}.csv"
        sim = subprocess.run([exe, "simulate", str(toml), "--traj", str(traj), "--out", str(log),
                              "--samples", str(n), "--noise", "0.002", "--seed", "0"],
                             cwd=ROOT, capture_output=True, text=True)
        if sim.returncode != 0:
            return {"error": f"cfmpa simulate failed: {sim.stderr[-300:]}"}
        report = tmp / f"monitor-{n}.json"
        run = cli_run(cfg, ["monitor", str(toml), "--traj", str(traj), "--log", str(log),
                            "--json", str(report)])
        entry: dict[str, Any] = {"samples": n, "bytes": log.stat().st_size, "cli": run}
        if "median_s" in run:
            doc = json.loads(report.read_text())
            stream = doc["timings_s"]["monitor"]
            entry.update(status=doc["status"], outside=doc["outside"], stream_s=stream,
                         samples_per_s=n / stream, cli_samples_per_s=n / run["median_s"],
                         peak_rss_mb=run["peak_rss_mb"])
            cpu = doc["timings_s"].get("monitor_cpu")
            if cpu:     # the stream's own CPU seconds: its rate on a machine shared by others
                entry.update(stream_cpu_s=cpu, cpu_samples_per_s=n / cpu)
        out[key] = entry
        log.unlink()
    if "peak_rss_mb" in out["log"] and "peak_rss_mb" in out["log_tenth"]:
        out["peak_growth_mb"] = round(out["log"]["peak_rss_mb"] - out["log_tenth"]["peak_rss_mb"], 1)
    return out


#: D_R on Dask (docs/model.md §9): `cfmpa dr --workers K` of the default workcell at
#: ``workers_dt`` in this process and on 1 and 2 local workers, and `cfmpa plan --contracts full
#: --store zarr` at ``store_dt`` (about 344 x 1796 x 1796 = 1.11 G cells); --quick: coarse grids.
DR_DASK = {"workers_dt": 0.005, "workers": (0, 1, 2), "store_dt": 0.0035,
           "store_max_cells": 2_000_000_000,
           "quick_dts": (0.04, 0.04)}


def dr_dask_section(cfg: Config, tmp: Path) -> dict[str, Any]:
    """`cfmpa dr --variant modified --store zarr` of the default workcell at
    DR_DASK["workers_dt"] in a fresh process per run with --workers 0 (the one-process build)
    and K local workers, and `cfmpa plan --contracts full --store zarr` at DR_DASK["store_dt"]
    (one run): seconds, the peak resident memory of the largest process waited for (ru_maxrss:
    the client, or a worker the client's cluster waited for), bytes a cell; every dr.zarr the
    same (dr_sha256 of each store, read back). Speed-up = 1 worker's median / 2 workers'."""
    if not cli_has("dr"):
        return skipped("no `cfmpa dr` in this checkout")
    from cfmpa.runs._drstore import open_zarr

    workers_dt, store_dt = DR_DASK["quick_dts"] if cfg.quick else (DR_DASK["workers_dt"],
                                                                     DR_DASK["store_dt"])
    runs = 1 if cfg.quick else min(cfg.runs, 3)
    toml = scenario_file(default_at(workers_dt), tmp)
    out: dict[str, Any] = {"workers_dt": workers_dt, "store_dt": store_dt}
    shas = set()
    for k in DR_DASK["workers"]:
        folder = tmp / f"dr-dask-{k}"
        r = cli_run(cfg, ["dr", str(toml), "--variant", "modified", "--out", str(folder),
                          "--store", "zarr", *(["--workers", str(k)] if k else [])],
                    runs=runs, warmup=0)
        if "median_s" in r:
            z = open_zarr(folder / "dr.zarr")
            r["cells"] = math.prod(z.shape)
            shas.add(z.sha256())
        out[f"workers_{k}"] = r
    one, two = out.get("workers_1", {}), out.get("workers_2", {})
    out["speedup_2_over_1"] = (one["median_s"] / two["median_s"]
                               if "median_s" in one and "median_s" in two else None)
    out["same_store"] = len(shas) == 1
    toml = scenario_file(default_at(store_dt), tmp)
    folder = tmp / "dr-dask-store"
    # Past the default cell budget (400 M) at dt = 0.0035 (1.11 G cells): raised for this row,
    # as docs/model.md §3 says a finer grid with the store needs.
    run = cli_run(cfg, ["plan", str(toml), "--variant", "modified", "--out", str(folder),
                        "--contracts", "full", "--store", "zarr"], runs=1, warmup=0,
                  env={"CFMPA_MAX_CELLS": str(DR_DASK["store_max_cells"])})
    doc = plan_json_of(folder)
    g = doc.get("grid") or {}
    cells = (g["N"] + 1) * g["m"] * g["n"] if g else None
    store: dict[str, Any] = {"dt": store_dt, "cells": cells,
                             "grid": [g["N"] + 1, g["m"], g["n"]] if g else None}
    if "median_s" in run and cells:
        store |= {"seconds": round(run["median_s"], 3), "peak_mib": run["peak_rss_mb"],
                  "bytes_per_cell": round(run["peak_rss_mb"] * 2**20 / cells, 2),
                  "status": doc.get("status"), "timings_s": doc.get("timings_s")}
    else:
        store["error"] = run.get("error") or "no plan.json"
    out["plan_store"] = store
    out["note"] = ("fresh processes on this machine's shared CPUs; workers_0 is the one-process "
                   "build, workers_K a local Dask cluster of K processes (cluster start and the "
                   "workers' kernel load included); peak_rss_mb is ru_maxrss, the largest single "
                   "process waited for, not the sum over the workers")
    return out


def dr_dask_lines(sec: dict[str, Any]) -> list[str]:
    """The D_R-on-Dask item's lines of the table."""
    if "skipped" in sec or "error" in sec:
        return [f"dr on dask: {sec.get('skipped') or sec.get('error')}"]
    lines = []
    for k in DR_DASK["workers"]:
        d = sec.get(f"workers_{k}", {})
        lines.append(f"cfmpa dr dt={sec['workers_dt']}, --workers {k}: "
                     + (f"{d['median_s']:.1f} s ({d['runs']} run(s)), peak "
                        f"{d['peak_rss_mb']:.0f} MiB" if "median_s" in d else failed(d)))
    sp = sec.get("speedup_2_over_1")
    lines.append("dr speed-up, 2 workers over 1: "
                 + (f"{sp:.2f}x" if sp is not None else "n/a")
                 + f"; the same dr.zarr: {sec.get('same_store')}")
    st = sec.get("plan_store", {})
    lines.append(f"cfmpa plan --contracts full --store zarr dt={st.get('dt')}: "
                 + (f"{st.get('cells', 0) / 1e9:.2f} G cells, {st['seconds']:.1f} s, "
                    f"{st['peak_mib']:.0f} MiB, {st['bytes_per_cell']} bytes a cell"
                    if "seconds" in st else str(st.get("error"))))
    return lines


def dr_dask_targets(res: dict[str, Any]) -> list[dict[str, Any]]:
    """D_R on Dask and the store at scale: 2 local workers faster than 1 at dt = 0.005; the
    1.11 G-cell workcell planned with full contracts in 300 s and 4 GiB; dt = 0.005 in 2 GiB
    (plan_scaling's row)."""
    sec = res.get("dr_dask") or {}
    why = str(sec.get("skipped") or sec.get("error") or "")
    sp = sec.get("speedup_2_over_1")
    one, two = sec.get("workers_1", {}), sec.get("workers_2", {})
    rows = [row("D_R on Dask: cfmpa dr dt=0.005, 1 worker / 2 workers (x)", sp, 1.0, False,
                note=why or ("not measured: " + (failed(one) or failed(two))
                             if sp is None else
                             f"fresh processes, local clusters: 1 worker {one['median_s']:.1f} "
                             f"s, 2 workers {two['median_s']:.1f} s (medians); one process "
                             f"{med(sec.get('workers_0')) or float('nan'):.1f} s; the same "
                             f"dr.zarr: {sec.get('same_store')}"))]
    st = sec.get("plan_store", {})
    what = (f"`cfmpa plan --contracts full --store zarr` of the default workcell at dt = "
            f"{st.get('dt')} ({st.get('cells') or 0:,} cells), one run, fresh process")
    note = why or (str(st.get("error")) if "error" in st else what)
    rows.append(row("store: plan dt=0.0035 (1.11 G cells), full contracts (s)",
                    st.get("seconds"), 300.0, note=note))
    rows.append(row("store: plan dt=0.0035 (1.11 G cells), full contracts (peak MiB)",
                    st.get("peak_mib"), 4 * GIB, note=note))
    ps = res.get("plan_scaling") or {}
    r5 = next((r for r in ps.get("rows", []) if r.get("dt") == 0.005), {})
    rows.append(row("store: plan dt=0.005 (381 M cells), full contracts (peak MiB)",
                    r5.get("peak_mib"), 2 * GIB,
                    note=(str(r5.get("error") or "not measured: no plan_scaling row at dt = "
                                                 "0.005") if "peak_mib" not in r5 else
                          "plan_scaling's row (`cfmpa plan --contracts full`, default store "
                          "zarr above 100 M cells), one run, fresh process")))
    return rows


#: The fixed campaign timed with 1 and 2 workers: `cfmpa compare --n 40 --dt 0.1 --seed 0`.
CAMPAIGN = {"n": 40, "dt": 0.1, "seed": 0, "workers": (1, 2)}


def campaign_section(cfg: Config, tmp: Path) -> dict[str, Any]:
    """`cfmpa compare` of CAMPAIGN in a fresh process per run (a fresh output folder each, so
    nothing is reused) with each number of local workers: the whole command (interpreter,
    cluster start, warm-up of the workers, tasks, report) and the tasks alone (compare.json's
    timings_s.tasks: first submit to last result). Speed-up = 1 worker's median / 2 workers'.
    compare.json must be the same apart from timings_s whatever the workers."""
    if not cli_has("compare"):
        return skipped("no `cfmpa compare` in this checkout")
    runs = min(cfg.runs, 3)
    out: dict[str, Any] = {k: v for k, v in CAMPAIGN.items() if k != "workers"}
    out["argv"] = ["compare", "--n", str(CAMPAIGN["n"]), "--dt", str(CAMPAIGN["dt"]),
                   "--seed", str(CAMPAIGN["seed"]), "--workers", "K", "--out", "DIR"]
    docs = []
    for k in CAMPAIGN["workers"]:
        wall, tasks, start = [], [], []
        for r in range(runs):
            folder = tmp / f"campaign-{k}-{r}"
            argv = [a.replace("K", str(k)).replace("DIR", str(folder)) if a in ("K", "DIR")
                    else a for a in out["argv"]]
            t0 = time.perf_counter()
            proc = subprocess.run([str(cfmpa_exe()), *argv], cwd=ROOT, capture_output=True,
                                  text=True)
            seconds = time.perf_counter() - t0
            if proc.returncode != 0:
                return {"error": f"exit {proc.returncode}: {proc.stderr.strip()[-500:]}",
                        "argv": argv}
            doc = json.loads((folder / "compare.json").read_text())
            timings = doc.pop("timings_s")
            docs.append(doc)
            wall.append(seconds)
            tasks.append(timings["tasks"])
            start.append(timings["engine_start"])
        out[f"workers_{k}"] = stats(wall, tasks_median_s=statistics.median(tasks),
                                    engine_start_median_s=statistics.median(start))
    one, two = out["workers_1"], out["workers_2"]
    out["speedup_2_over_1"] = {"end_to_end": one["median_s"] / two["median_s"],
                               "tasks": one["tasks_median_s"] / two["tasks_median_s"]}
    out["same_compare_json"] = all(d == docs[0] for d in docs)
    out["note"] = ("fresh `cfmpa compare` processes on this machine's CPUs (shared with other "
                   "users); end_to_end includes the interpreter, the cluster start and the "
                   "workers' warm-up (imports, kernel cache), tasks the planning alone")
    return out


def shapely_section(res: dict[str, Any], variant: str, loop: dict[str, Any],
                    inter: dict[str, Any], dwithin: dict[str, Any]) -> dict[str, Any]:
    cells = loop["info"]["cells"]
    rate = loop["info"]["sample"] / loop["median_s"]
    loop_full = cells / rate
    dw_full = dwithin["median_s"] * dwithin["info"]["layers"] / dwithin["info"]["layers_timed"]
    ours = res["builtdr"][variant]["fast_regions_given"]["median_s"]
    ours_all = res["builtdr"][variant]["fast"]["median_s"]
    return {
        "variant": variant,
        "per_cell_loop": {**loop, "rate_cells_per_s": rate, "extrapolated_full_grid_s": loop_full,
                          "note": f"measured on {loop['info']['sample']} seeded random cells; "
                                  "the full-grid time is extrapolated from that rate"},
        "vectorised_intersects": {**inter, "note": "shapely.intersects on prepared polygons, "
                                  "full grid, polygon creation included (intersects is distance "
                                  "<= 0, not <= eps)"},
        "vectorised_dwithin": {**dwithin, "extrapolated_full_grid_s": dw_full,
                               "note": "shapely.dwithin(a, b, eps), the project's own rule; "
                                       f"{dwithin['info']['layers_timed']} of "
                                       f"{dwithin['info']['layers']} layers timed, extrapolated"},
        "ratios": {"loop_over_ours": loop_full / ours,
                   "intersects_over_ours": inter["median_s"] / ours,
                   "dwithin_over_ours": dw_full / ours,
                   "loop_over_ours_with_right_regions": loop_full / ours_all,
                   "intersects_over_ours_with_right_regions": inter["median_s"] / ours_all,
                   "note": "their time / our fast BuiltDR time, same grid and variant. Like for "
                           "like: both are given the right arm's regions (ours still computes "
                           "the left arm's); *_with_right_regions: ours also computes them"},
    }


def contracts_section(have_cli: bool, base: dict[str, Any],
                      in_process: dict[str, dict[str, Any]],
                      plan_cli: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """`--contracts off|sampled|full` on the default grid: in process (the checks' own cost) and
    as `cfmpa plan` processes (what a user waits for; the same runs as the plan section's)."""
    out: dict[str, Any] = {"scenario": base, "variant": "modified",
                           "note": "in_process: plan() after a warm-up; cli: whole "
                                   "`cfmpa plan` processes",
                           "in_process": in_process}
    if all("median_s" in in_process[m] for m in CONTRACT_MODES):
        off = in_process["off"]["median_s"]
        out["ratios"] = {"sampled_over_off": in_process["sampled"]["median_s"] / off,
                         "full_over_off": in_process["full"]["median_s"] / off}
    if not have_cli:
        out["cli"] = skipped("no `cfmpa plan` in this checkout")
        return out
    out["cli"] = dict(plan_cli)
    cli = out["cli"]
    if all("median_s" in cli[m] for m in CONTRACT_MODES):
        off = cli["off"]["median_s"]
        out["cli_ratios"] = {"sampled_over_off": cli["sampled"]["median_s"] / off,
                             "full_over_off": cli["full"]["median_s"] / off}
    return out


#: BuiltDR fast, slowest variant, warm, in process: the target (seconds).
BUILTDR_LIMIT_S = 0.10

#: build_dr_fast's stages as the profile names them (impl's STAGES, in order).
PROFILE_STAGES = {
    "right_regions": "right regions (right_regions_fast: the subordinate's m + m n swept polygons)",
    "left_regions": "left regions (left_regions_fast: the principal's 2 polygons a layer)",
    "pack_right": "right packing (centre lines, link 1's polygons packed, every cell's box and "
                  "each row's union box on the kernel threads; cells packed later, on first use)",
    "pack_left": "left packing (_pack and centre lines of every layer's polygons, at once)",
    "layer_kernel": "numba kernel (_layers: each row in every computed layer, the rows shared "
                    "out among the kernel threads)",
    "settle_unsure": "settle of unsure cells (_settle_unsure: the reference's blocked_against)",
    "other": "rest layer copied",
}


def builtdr_profile(res: dict[str, Any], runs: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """BuiltDR fast on the default scenario split into build_dr_fast's stages, per variant: the
    median of each stage over the timed runs (its own process, after the warm-up), as
    build_dr_fast records them (its ``stages`` argument; bench/_worker.py item_builtdr_profile)."""
    out: dict[str, Any] = {
        "stages": PROFILE_STAGES,
        "note": "in process, per variant: median seconds of each stage over the timed runs "
                "(warm-up excluded); total: the whole staged build, to compare with "
                "builtdr.<variant>.fast (build_dr_fast itself, another process)",
    }
    for v, r in runs.items():
        info = r["info"]
        timed_runs = info["stages_s"][-r["runs"]:]
        mid = {k: statistics.median(st[k] for st in timed_runs) for k in timed_runs[0]}
        out[v] = {
            "stages_median_s": mid,
            "share": {k: mid[k] / mid["total"] for k in PROFILE_STAGES} if mid["total"] else {},
            "build_dr_fast_median_s": res["builtdr"][v]["fast"].get("median_s"),
            "runs": r["runs"], "peak_rss_mb": r["peak_rss_mb"],
            **{k: info[k] for k in ("cells", "grid", "kernel_threads", "unsure_pairs")
               if k in info},
        }
    return out


def profile_note(res: dict[str, Any], variant: str) -> str:
    """One line of the BuiltDR profile of ``variant`` for the target's note."""
    p = res.get("builtdr_profile", {}).get(variant)
    if not p:
        return ""
    s = p["stages_median_s"]
    short = {"right_regions": "right regions", "left_regions": "left regions",
             "pack_right": "right packing", "pack_left": "left packing",
             "layer_kernel": f"numba layer loop ({p.get('kernel_threads', '?')} thread)",
             "settle_unsure": f"settle {p.get('unsure_pairs', '?')} unsure pairs"}
    total = s["total"] or float("nan")
    parts = ", ".join(f"{name} {s[k]:.3f} s ({s[k] / total:.0%})" for k, name in short.items())
    floor = s["right_regions"] + s["left_regions"]
    return (f"profile of {variant} (builtdr_profile, in process): {parts}; staged total "
            f"{s['total']:.3f} s. The two region builders take {floor:.3f} s, "
            f"{floor / BUILTDR_LIMIT_S:.0%} of the {BUILTDR_LIMIT_S:g} s budget")


def row(name: str, measured: float | None, limit: float, at_most: bool = True,
        note: str = "", **extra: Any) -> dict[str, Any]:
    """A target: measured against limit (at most, or at least); met None when not measured."""
    met = None if measured is None else (measured <= limit if at_most else measured >= limit)
    return {"target": name, "limit": limit, "cmp": "<=" if at_most else ">=",
            "measured": measured, "met": met, "note": note, **extra}


def med(d: dict[str, Any] | None) -> float | None:
    return None if d is None else d.get("median_s")


def failed(d: dict[str, Any] | None) -> str:
    """Why an item has no median ('' if it has one): its error or skip reason."""
    if d is None:
        return "not measured"
    if "median_s" in d:
        return ""
    return "not measured: " + str(d.get("error") or d.get("skipped"))[:160]


def stage_note(timings: dict[str, float] | None, wall: float | None) -> str:
    """plan.json's in-process stages of a `cfmpa plan` run, and the rest of the process."""
    if not timings or wall is None:
        return ""
    # contracts_builtdr_overlapped: the part of contracts_builtdr spent beside the stages after
    # it (docs/model.md §7.5), so counted once
    inside = sum(v for v in timings.values() if isinstance(v, (int, float))) - 2 * float(
        timings.get("contracts_builtdr_overlapped", 0.0))
    stages = ", ".join(f"{k} {v:.2f}" for k, v in timings.items() if isinstance(v, (int, float)))
    return (f"; the last run's plan.json timings_s: {stages} (sum {inside:.2f} s); the rest of "
            f"the median process (interpreter, imports, files) {wall - inside:.2f} s")


def targets(res: dict[str, Any], cfg: Config) -> list[dict[str, Any]]:
    """The performance targets, against this run's medians (meaningful on the full run only):
    full checking's, start-up's (`cfmpa dr` whole, and against the shapely peer), the plan's
    end to end, the monitor's throughput and memory, `make prove`'s and `cfmpa audit`'s time,
    the streamed certify's, D_R on Dask's: every target of the run, met or not."""
    rows: list[dict[str, Any]] = []
    fresh = "fresh process"

    # full checking: cfmpa check of a good plan
    chk = res.get("check", {})
    what = (f"`cfmpa check` of a good plan (`cfmpa plan --contracts "
            f"{chk.get('plan_contracts', '?')}`'s dr.npy and plan.json, no witness: check "
            "computes one and verifies it), default scenario, " + fresh)
    rows.append(row("full checking: cfmpa check, good plan (s)", med(chk), 5.0,
                    note=failed(chk) or what))
    rows.append(row("full checking: cfmpa check, good plan (peak MiB)",
                    chk.get("peak_rss_mb") if "median_s" in chk else None, GIB,
                    note=failed(chk) or what + "; peak resident memory (ru_maxrss)"))

    # full checking: full / off in process
    c = res["contracts"]
    ip = c["in_process"]
    ratio = c.get("ratios", {}).get("full_over_off")
    rows.append(row("full checking: plan() contracts full / off, in process (x)", ratio, 5.0,
                    note=(f"plan() in process, default scenario, modified: full "
                          f"{med(ip['full']):.3f} s / off {med(ip['off']):.3f} s (medians)"
                          if ratio is not None else failed(ip["full"]) or failed(ip["off"]))))

    # full checking: BuiltDR fast, slowest variant, in process
    fast = {v: res["builtdr"][v]["fast"].get("median_s") for v in VARIANTS}
    cold = {v: res["builtdr"][v]["fast"].get("cold_s") for v in VARIANTS}
    slowest = max(fast, key=lambda v: fast[v] or -1.0)
    rows.append(row("full checking: BuiltDR fast, slowest variant, warm, in process (s)",
                    fast[slowest], BUILTDR_LIMIT_S,
                    note=f"build_dr_fast in process, right regions included, warm: the median of "
                         f"{res['builtdr'][slowest]['fast'].get('runs')} calls after a cold one "
                         f"(the first call in its process, kernels loaded); slowest {slowest} ("
                         + ", ".join(f"{v} {fast[v]:.3f}" for v in VARIANTS) + "); cold: "
                         + ", ".join(f"{v} {cold[v]:.3f}" for v in VARIANTS if cold[v])
                         + "; " + profile_note(res, slowest)))

    # the first run: a fresh numba cache against a later run
    fr = res.get("first_run") or {}
    ratio = fr.get("ratio_first_over_later")
    rows.append(row("first run: cfmpa plan default, fresh numba cache / later run (x)", ratio,
                    FIRST_RUN_LIMIT,
                    note=(f"whole processes: first {fr['first']['median_s']:.1f} s (one run, "
                          f"fresh NUMBA_CACHE_DIR), later {fr['later']['median_s']:.1f} s "
                          f"(median of {fr['later']['runs']}); "
                          + "; ".join(fr.get("compile_lines", []))
                          + ("" if not fr.get("later_prints_compile")
                             else "; a later run printed a compile line")
                          if ratio is not None else
                          "not measured: " + str(fr.get("skipped") or fr.get("error")
                                                 or "no first_run section"))))

    # full checking: cfmpa dr whole process vs the shapely-vectorised peer
    dr = res.get("dr_cli", {})
    nan = float("nan")
    sh = res["shapely"]
    peer = sh["vectorised_intersects"]["median_s"]
    dw = sh["vectorised_dwithin"]["extrapolated_full_grid_s"]
    speed = peer / dr["median_s"] if "median_s" in dr else None
    rows.append(row("start-up: cfmpa dr default, whole process (s)", med(dr), DR_LIMIT_S,
                    note=failed(dr) or
                    (f"`cfmpa dr --variant {dr.get('variant')}` of the default workcell, {fresh} "
                     f"(interpreter, imports, kernels' cache load, BuiltDR, dr.npy written): "
                     f"median of {dr.get('runs')}; in process BuiltDR fast "
                     f"{fast.get(dr.get('variant'), nan):.3f} s")))
    rows.append(row("start-up: shapely-vectorised peer / cfmpa dr (x)", speed, DR_PEER_X, False,
                    note=failed(dr) or
                    (f"`cfmpa dr --variant {dr.get('variant')}` {fresh} {dr['median_s']:.3f} s "
                     f"against the bench's shapely-vectorised peer (shapely.intersects on "
                     f"prepared polygons, full grid, same variant, right regions given, its own "
                     f"process) {peer:.3f} s, same run; the peer with dwithin(eps), the "
                     f"project's rule, extrapolated: {dw:.3f} s ({dw / dr['median_s']:.1f}x); "
                     f"in process BuiltDR fast {fast.get(dr.get('variant'), nan):.3f} s")))

    # full checking: cfmpa plan end to end in the CLI's default contract mode
    mode = res["plan"].get("cli_default_contracts")
    cli = res["contracts"].get("cli", {})
    plan_d = cli.get(mode) if isinstance(cli, dict) and mode in CONTRACT_MODES else None
    others = ", ".join(f"--contracts {m} {med(cli[m]):.3f} s" for m in ("sampled", "full")
                       if isinstance(cli, dict) and med(cli.get(m)) is not None)
    rows.append(row(f"full checking: cfmpa plan end to end, default --contracts {mode} (s)",
                    med(plan_d), 1.5,
                    note=failed(plan_d) or
                    (f"`cfmpa plan` {fresh}, default scenario, certificate included; "
                     f"--contracts {mode} is the CLI's default (read from its parser at run "
                     f"time); measured: {others}"
                     + stage_note(plan_d.get("timings_s"), med(plan_d)))))

    # monitoring: cfmpa monitor
    mon = res.get("monitor", {})
    big = mon.get("log", {}) if isinstance(mon.get("log"), dict) else {}
    tenth = mon.get("log_tenth", {}) if isinstance(mon.get("log_tenth"), dict) else {}
    n = big.get("samples", cfg.monitor_samples)
    why = failed(big.get("cli")) if big else str(mon.get("skipped") or mon.get("error") or "")
    wall = med(big.get("cli")) if big else None
    rows.append(row(f"monitoring: cfmpa monitor, {n:,}-sample log (samples/s)",
                    big.get("cli_samples_per_s"), 100_000.0, False,
                    wall_s=wall, peak_rss_mb=big.get("peak_rss_mb"),
                    note=why or (f"whole `cfmpa monitor` process: wall {wall:.3f} s, peak "
                                 f"{big['peak_rss_mb']:.1f} MiB; the stream alone "
                                 f"{big['samples_per_s']:,.0f} samples/s (its timings_s.monitor); "
                                 f"status {big.get('status')}")))
    growth = mon.get("peak_growth_mb")
    rows.append(row(f"monitoring: cfmpa monitor peak growth, {n // 10:,} -> {n:,} samples (MiB)",
                    growth, 16.0,
                    note=why or (f"bounded memory: peak {tenth.get('peak_rss_mb')} MiB on the "
                                 f"{n // 10:,}-sample log, {big.get('peak_rss_mb')} MiB on the "
                                 f"{n:,}-sample log ({big.get('bytes', 0) / 2**20:.0f} MiB of "
                                 "CSV); the requirement says bounded and names no number: the limit "
                                 "is the bench's (reading the log whole would add more than the "
                                 "log's size)")))

    # proving: make prove
    pv = res.get("prove", {})
    what = "`cfmpa prove --audit DIR` (make prove) as one " + fresh + ", one run"
    if "median_s" in pv:
        seconds = pv["median_s"]
        note = (f"{what}, peak {pv.get('peak_rss_mb')} MiB; {pv.get('obligations')} "
                f"obligations, ok {pv.get('ok')}")
    elif "seconds" in pv:       # it ran to the end but exited non-zero: timed, never met
        seconds = pv["seconds"]
        why = "; ".join(pv.get("failure_lines") or [str(pv.get("error"))])
        note = f"{what}; it FAILED, so the target is not met whatever its time ({why[:600]})"
    else:
        seconds, note = None, failed(pv)
    prove_row = row("proving: make prove, whole process (s)", seconds, PROVE_LIMIT_S, note=note)
    if "error" in pv and seconds is not None:
        prove_row["met"] = False
    rows.append(prove_row)
    alone = row("proving: make prove, obligations alone (s)", pv.get("obligations_s"), 60.0,
                note=(failed(pv) or pv.get("obligations_error", "")
                      if pv.get("obligations_s") is None else
                      "the same run's results.json `seconds`: the obligations' discharge as "
                      "the prove summary times it, without the interpreter's start and "
                      "imports or the audit report"
                      + ("; results.json says ok false: not met" if pv.get("ok") is False
                         else "")))
    if pv.get("ok") is False and alone["measured"] is not None:
        alone["met"] = False
    rows.append(alone)

    au = res.get("audit", {})
    rows.append(row("proving: cfmpa audit default --compare-n 0, whole process (s)", med(au),
                    AUDIT_LIMIT_S,
                    note=failed(au) or (f"`cfmpa audit default --compare-n 0` as one {fresh}, one "
                                        f"run (its prove of the default workcell and the report), "
                                        f"peak {au.get('peak_rss_mb')} MiB")))

    # certify: a long trajectory streamed, by default
    rows += certify_stream_targets(res.get("certify_stream") or {})
    rows += dr_dask_targets(res)
    if cfg.quick:
        for r in rows:
            r["note"] = ("quick run (the full bench's command, the same measurement); "
                         if r["target"].startswith(PROVE_ROWS) else
                         "quick run on a coarse grid: not the target's measurement; ") + r["note"]
    return rows


def certify_stream_targets(sec: dict[str, Any]) -> list[dict[str, Any]]:
    """The streamed certify's targets (CERTIFY_STREAM["targets"]): seconds and peak MiB of
    `cfmpa certify` of the slow trajectory at each of their row counts, default limits; unmet
    (None) when that run is missing or failed."""
    out = []
    by_rows = {r["rows"]: r for r in sec.get("runs", [])}
    for n, (limit_s, limit_mib) in CERTIFY_STREAM["targets"].items():
        r = by_rows.get(n, {})
        why = (r.get("error") and f"FAILED: {str(r['error'])[:160]}") or (
            "" if r else "not measured: " + str(sec.get("skipped") or sec.get("error")
                                                or f"no run of {n:,} rows"))
        note = why or (f"`cfmpa certify default --traj` of a {n:,}-row CSV "
                       f"({r['bytes'] / 2**20:.0f} MiB, bench/run.py slow_trajectory_csv), "
                       f"default limits, one run in a fresh process: read "
                       f"{r['timings_s'].get('load', 0):.1f} s, certify "
                       f"{r['timings_s'].get('certificate', 0):.1f} s; clear {r['clear']}")
        out.append(row(f"certify: {n:,}-row trajectory streamed, default limits (s)",
                       r.get("seconds"), limit_s, note=note))
        out.append(row(f"certify: {n:,}-row trajectory streamed, default limits (peak MiB)",
                       r.get("peak_mib"), limit_mib,
                       note=why or "peak resident memory of the child (ru_maxrss)"))
    return out


#: The rows of `make prove` and `cfmpa audit`, whose commands do not depend on the bench's grid.
PROVE_ROWS = ("proving: make prove", "proving: cfmpa audit")
#: The start-up targets of `cfmpa dr default`: its whole process at most DR_LIMIT_S, and the
#: shapely-vectorised peer at least DR_PEER_X times slower, measured in the same bench run.
DR_LIMIT_S = 0.6
DR_PEER_X = 4.0
#: `make prove` (cfmpa prove --audit) and `cfmpa audit default --compare-n 0`, whole processes
#: on two cores (s). `make test`'s time is no bench item (CI times it).
PROVE_LIMIT_S = 90.0
AUDIT_LIMIT_S = 45.0


def informational(res: dict[str, Any], cfg: Config) -> list[dict[str, Any]]:
    """Former targets, no longer required, kept as information (``limit``: the
    former limit; ``met`` against it)."""
    sh = res["shapely"]["ratios"]
    one = res["one_degree"]
    rows = [
        row("BuiltDR fast, slowest variant (s)",
            max(res["builtdr"][v]["fast"]["median_s"] for v in VARIANTS), 0.5,
            note="in process, right regions included; superseded by the 0.10 s target"),
        row("BuiltDR fast vs per-cell shapely loop (x)", sh["loop_over_ours"], 1000, False,
            note="in process, both given the same regions; extrapolated from the sample"),
        row("BuiltDR fast vs vectorised shapely intersects (x)", sh["intersects_over_ours"], 10,
            False, note="in process, both given the same regions"),
        row("search fast, slowest variant (s)",
            max(res["search"][v]["fast"]["median_s"] for v in VARIANTS), 1.0, note="in process"),
        row("cfmpa plan end to end, sampled (s)", med(res["plan"]["cli_sampled"]), 3.0,
            note="fresh process, certificate included"),
        row("1-degree cfmpa plan (s)", med(one["plan_cli_sampled"]), 5.0,
            note="fresh process, certificate included"),
        row("1-degree cfmpa plan (peak MiB)", one["plan_cli_sampled"].get("peak_rss_mb"), GIB,
            note="fresh process"),
    ]
    for r in rows:
        r["former_target"] = True
    if cfg.quick:
        for r in rows:
            r["note"] = ("quick run on a coarse grid: not the measurement; " + r["note"])
    return rows


#: The package's folders, whose bytecode the bench compiles before it times anything.
PACKAGE_DIRS = ("cfmpa", "spec", "impl", "proofs", "runs", "report", "scenarios")


def compile_bytecode() -> None:
    """Compile the checkout's modules to bytecode (``__pycache__``), as `pip install` of the
    wheel does: an editable install under PYTHONDONTWRITEBYTECODE=1 (set on some machines)
    otherwise compiles every module from source in every timed process, which a user's install
    never does. Python reads the files whatever that variable says."""
    import compileall

    for d in PACKAGE_DIRS:
        compileall.compile_dir(str(ROOT / d), quiet=1)


def compile_kernels() -> None:
    """Compile the fast kernels into the checkout's numba cache first (CFMPA_KERNEL_COMPILE=wait,
    docs/model.md §7.5): with a cold cache a command would otherwise run the numpy kernels while
    they compile in the background, and the bench would time those. ``first_run`` times the
    cold start itself, with a cache of its own."""
    code = ("from cfmpa.impl._kernel_cache import cold_groups, load_fast_kernels\n"
            "load_fast_kernels()\nassert not cold_groups(), cold_groups()")
    subprocess.run([sys.executable, "-c", code], check=True,
                   env=os.environ | {"CFMPA_KERNEL_COMPILE": "wait"})


def meta(cfg: Config, base: dict[str, Any]) -> dict[str, Any]:
    import numba
    import numpy
    import shapely

    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    return {"date": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "quick": cfg.quick, "runs": cfg.runs,
            "warmup": cfg.warmup, "budget_s_per_item": cfg.budget_s, "scenario": base,
            "python": platform.python_version(), "numpy": numpy.__version__,
            "numba": numba.__version__, "shapely": shapely.__version__, "commit": commit,
            "cpus": os.cpu_count(), "load_average": os.getloadavg(),
            "bytecode": "compiled before the runs (compile_bytecode), as pip install does",
            "note": "medians over the runs after the warm-up; other processes may share the CPUs"}


# ------------------------------------------------------------------------------ the table ----

def table(res: dict[str, Any]) -> str:
    lines = [f"{'item':58s} {'median s':>10s} {'min s':>9s} {'max s':>9s} {'runs':>4s} "
             f"{'peak MiB':>9s}"]

    def add(name: str, d: dict[str, Any]) -> None:
        if "median_s" in d:
            lines.append(f"{name:58s} {d['median_s']:10.4f} {d['min_s']:9.4f} {d['max_s']:9.4f} "
                         f"{d['runs']:4d} {d.get('peak_rss_mb', float('nan')):9.1f}")
        else:
            why = str(d.get("skipped") or d.get("error"))
            lines.append(f"{name:58s} {why.splitlines()[-1][:120] if why.strip() else why}")

    for v in VARIANTS:
        for impl, d in res["builtdr"][v].items():
            add(f"BuiltDR {v} {impl} ({d['info']['cells']} cells)", d)
    for v in VARIANTS:
        for impl, d in res["search"][v].items():
            add(f"search {v} {impl}", d)
    sh = res["shapely"]
    add(f"shapely per-cell loop, {sh['per_cell_loop']['info']['sample']} sampled cells",
        sh["per_cell_loop"])
    add("shapely vectorised intersects, full grid", sh["vectorised_intersects"])
    add(f"shapely vectorised dwithin, {sh['vectorised_dwithin']['info']['layers_timed']} layers",
        sh["vectorised_dwithin"])
    for s in res["scaling"]:
        add(f"scaling dt={s['dt']} BuiltDR fast ({s['cells']} cells)", s["builtdr_fast"])
        add(f"scaling dt={s['dt']} search fast", s["search_fast"])
    add("plan(), sampled (in process)", res["plan"]["fast_in_process_sampled"])
    c = res["contracts"]
    for mode in CONTRACT_MODES:
        add(f"plan(), contracts {mode} (in process)", c["in_process"][mode])
    default_mode = res["plan"].get("cli_default_contracts")
    for mode, d in c["cli"].items() if "skipped" not in c["cli"] else ():
        add(f"cfmpa plan --contracts {mode} (fresh process)"
            + (" [default]" if mode == default_mode else ""), d)
    add(f"cfmpa dr --variant {res['dr_cli'].get('variant', '')} (fresh process)", res["dr_cli"])
    add("cfmpa check, good plan (fresh process)", res["check"])
    add("make prove: cfmpa prove --audit (fresh process, 1 run)", res["prove"])
    one = res["one_degree"]
    grid = "x".join(str(x) for x in one["grid"])
    add(f"plan() {grid}, sampled (in process)", one["plan_fast_in_process_sampled"])
    add(f"cfmpa plan {grid}, sampled (fresh process)", one["plan_cli_sampled"])
    lines.append("")
    r = sh["ratios"]
    lines.append(f"per-cell shapely loop: {sh['per_cell_loop']['rate_cells_per_s']:.0f} cells/s, "
                 f"full grid {sh['per_cell_loop']['extrapolated_full_grid_s']:.1f} s "
                 "(extrapolated from the sample)")
    lines.append(f"ratios (theirs / ours, both given the right regions): per-cell loop "
                 f"{r['loop_over_ours']:.0f}x, vectorised intersects "
                 f"{r['intersects_over_ours']:.1f}x, vectorised dwithin "
                 f"{r['dwithin_over_ours']:.1f}x (extrapolated)")
    lines.append(f"ratios with our right regions computed too: per-cell loop "
                 f"{r['loop_over_ours_with_right_regions']:.0f}x, vectorised intersects "
                 f"{r['intersects_over_ours_with_right_regions']:.1f}x")
    if "ratios" in c:
        lines.append(f"contracts, in process: sampled/off {c['ratios']['sampled_over_off']:.2f}x, "
                     f"full/off {c['ratios']['full_over_off']:.1f}x")
    if "cli_ratios" in c:
        lines.append(f"contracts, fresh processes: sampled/off "
                     f"{c['cli_ratios']['sampled_over_off']:.2f}x")
    camp = res.get("campaign")
    if camp is not None:
        lines += campaign_lines(camp)
    if "rows" in (res.get("plan_scaling") or {}):
        lines += plan_scaling_lines(res["plan_scaling"])
    if "runs" in (res.get("certify_stream") or {}):
        lines += certify_stream_lines(res["certify_stream"])
    if "rows" in (res.get("tools") or {}):
        lines += tools_lines(res["tools"])
    if "plan_store" in (res.get("dr_dask") or {}):
        lines += dr_dask_lines(res["dr_dask"])
    if isinstance(res.get("first_run"), dict) and "skipped" not in res["first_run"]:
        lines += first_run_lines(res["first_run"])
    lines += profile_lines(res.get("builtdr_profile"))
    lines.append("")
    lines.append("targets (measured, limit, verdict, what was measured):")
    lines += target_lines(res["targets"])
    if res.get("informational"):
        lines.append("")
        lines.append("informational (former targets; former limit):")
        lines += target_lines(res["informational"])
    return "\n".join(lines)


def target_lines(rows: list[dict[str, Any]]) -> list[str]:
    out = []
    for t in rows:
        verdict = {True: "met", False: "MISSED", None: "n/a"}[t["met"]]
        measured = "-" if t["measured"] is None else f"{t['measured']:.4g}"
        cmp = t.get("cmp") or ("<=" if "vs" not in t["target"] else ">=")
        out.append(f"  {t['target']:64s} {measured:>10s} {cmp} {t['limit']:<7g} {verdict}"
                   + (f"\n      {t['note']}" if t["note"] else ""))
    return out


def profile_lines(prof: dict[str, Any] | None) -> list[str]:
    """BuiltDR fast's stages per variant (median seconds, in process)."""
    if not prof:
        return []
    lines = ["", "BuiltDR fast profile, in process (median s per stage):"]
    head = [k for k in PROFILE_STAGES if k != "other"] + ["total"]
    lines.append(f"  {'variant':9s}" + "".join(f"{k:>15s}" for k in head)
                 + f"{'build_dr_fast':>15s} {'unsure':>7s}")
    for v in VARIANTS:
        p = prof.get(v)
        if not p:
            continue
        s = p["stages_median_s"]
        lines.append(f"  {v:9s}" + "".join(f"{s[k]:15.4f}" for k in head)
                     + f"{p['build_dr_fast_median_s'] or float('nan'):15.4f} "
                       f"{p.get('unsure_pairs', 0):7d}")
    return lines


def campaign_lines(camp: dict[str, Any]) -> list[str]:
    """The campaign item's lines of the table: each number of workers, then the speed-up."""
    if "skipped" in camp or "error" in camp:
        return [f"campaign: {camp.get('skipped') or camp.get('error')}"]
    lines = []
    for k in CAMPAIGN["workers"]:
        d = camp[f"workers_{k}"]
        lines.append(f"campaign {camp['n']} workcells dt={camp['dt']}, {k} worker(s): "
                     f"{d['median_s']:.1f} s end to end ({d['runs']} run(s)), tasks "
                     f"{d['tasks_median_s']:.1f} s after {d['engine_start_median_s']:.1f} s "
                     f"of cluster start")
    sp = camp["speedup_2_over_1"]
    lines.append(f"campaign speed-up, 2 workers over 1: {sp['tasks']:.2f}x on the tasks, "
                 f"{sp['end_to_end']:.2f}x end to end; compare.json the same: "
                 f"{camp['same_compare_json']}")
    return lines


def merged(res: dict[str, Any], cfg: Config, section: str) -> None:
    """After ``--only SECTION``: meta.merged records the section's run (date, commit, load), and
    the targets are recomputed from the results as they now stand (if the file has a full run's
    sections; else they are left as they were)."""
    now = meta(cfg, {})
    res.setdefault("meta", {}).setdefault("merged", []).append(
        {"section": section, "date": now["date"], "commit": now["commit"],
         "load_average": now["load_average"], "runs": cfg.runs})
    try:
        res["targets"] = targets(res, cfg)
        res["informational"] = informational(res, cfg)
    except (KeyError, TypeError) as e:
        res["meta"]["merged"][-1]["targets_not_recomputed"] = f"{type(e).__name__}: {e}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smoke run on a coarse grid")
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent),
                    help="folder for results.json (default: bench/)")
    ap.add_argument("--runs", type=int, default=None, help="timed runs per item (default 5)")
    ap.add_argument("--only", choices=["campaign", "plan_scaling", "certify_stream", "tools",
                                        "first_run", "builtdr", "dr_dask"],
                    default=None,
                    help="run only this item and merge it into OUT/results.json (the targets "
                         "are recomputed; meta.merged says what came from which run)")
    ap.add_argument("--prove", action="store_true",
                    help="also time `make prove` (cfmpa prove --audit DIR), one run of a minute "
                         "or two; `make bench` passes it")
    args = ap.parse_args(argv)
    cfg = Config.of(args.quick, args.runs, prove=args.prove)
    compile_bytecode()
    compile_kernels()
    if args.only == "builtdr":
        out = Path(args.out) / "results.json"
        res = json.loads(out.read_text()) if out.exists() else {}
        builtdr_only(cfg, res)
        merged(res, cfg, "builtdr")
        out.write_text(json.dumps(res, indent=1, default=str) + "\n")
        print("\n".join(builtdr_lines(res)))
        print(f"\nwrote {out} (builtdr merged)")
        return 0
    if args.only is not None:
        section, lines = {"campaign": (campaign_section, campaign_lines),
                          "plan_scaling": (plan_scaling_section, plan_scaling_lines),
                          "certify_stream": (certify_stream_section,
                                             certify_stream_lines),
                          "tools": (tools_section, tools_lines),
                          "first_run": (first_run_section, first_run_lines),
                          "dr_dask": (dr_dask_section, dr_dask_lines)}[args.only]
        out = Path(args.out) / "results.json"
        res = json.loads(out.read_text()) if out.exists() else {}
        with tempfile.TemporaryDirectory(prefix="cfmpa-bench-") as tmp:
            res[args.only] = section(cfg, Path(tmp))
        merged(res, cfg, args.only)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(res, indent=1, default=str) + "\n")
        print("\n".join(lines(res[args.only])))
        print(f"\nwrote {out} ({args.only} merged)")
        return 0
    with tempfile.TemporaryDirectory(prefix="cfmpa-bench-") as tmp:
        res = bench(cfg, Path(tmp))
    out = Path(args.out) / "results.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(res, indent=1, default=str) + "\n")
    print(table(res))
    print(f"\nwrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
