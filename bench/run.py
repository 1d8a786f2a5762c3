"""`make bench`: BuiltDR, the search, `cfmpa plan` and `make prove` timed; shapely side by side.

Writes OUT/results.json (default bench/results.json) and prints a table: the median of the runs
after a warm-up, with min and max, and each item's peak resident memory (its own process).
Items slower than their time budget get fewer runs; the table says how many. --quick is a smoke
run on a coarse grid (one run each, one process for all in-process items, so its memory column
is that process's high-water mark so far; no warm-up). Never imported by the package.

The campaign item (`cfmpa compare`, a fixed campaign with 1 and 2 local workers, and the
speed-up) runs in the full bench and alone with ``--only campaign`` (merged into an existing
results.json); --quick leaves it out (its cluster start alone is seconds).
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
    contracts_runs_full: int = 3           # full contracts on the default grid: minutes a run
    contracts_budget_full_s: float = 900.0
    one_degree: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def of(cls, quick: bool, runs: int | None) -> Config:
        if quick:
            return cls(quick=True, runs=runs or 1, warmup=0, budget_s=20.0, dt=0.16, sample=100,
                       dwithin_stride=1, scaling_dts=(0.32, 0.16, 0.08), contracts_runs_full=1,
                       one_degree=one_degree(10))
        return cls(quick=False, runs=runs or 5, one_degree=one_degree(1))


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
                             rss_before_mb=r["rss_before_mb"], info=r["info"]))
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


def cli_run(cfg: Config, argv: list[str], program: list[str] | None = None) -> dict[str, Any]:
    """Time a `cfmpa` command (or ``program``) in its own process; peak memory from that
    process's rusage."""
    exe = program or [str(cfmpa_exe())]
    times: list[float] = []
    peak = 0.0
    runs = cfg.runs
    for n in range(cfg.warmup + runs):
        with tempfile.TemporaryFile() as err:   # a file, not a pipe: a full pipe would block
            t0 = time.perf_counter()
            proc = subprocess.Popen([*exe, *argv], cwd=ROOT, stdout=subprocess.DEVNULL,
                                    stderr=err)
            _, status, usage = os.wait4(proc.pid, 0)
            seconds = time.perf_counter() - t0
            proc.returncode = os.waitstatus_to_exitcode(status)
            err.seek(0)
            message = err.read().decode(errors="replace").strip()[-500:]
        if proc.returncode != 0:
            return {"error": f"exit {proc.returncode}: {message}", "argv": argv}
        peak = max(peak, usage.ru_maxrss / 1024)
        if n < cfg.warmup:
            if seconds * runs > cfg.budget_s:
                runs = max(1, math.floor(cfg.budget_s / seconds))
            continue
        times.append(seconds)
        if len(times) >= runs:
            break
    return stats(times, peak_rss_mb=round(peak, 1), argv=argv)


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
    base = default_at(cfg.dt)
    res: dict[str, Any] = {"meta": meta(cfg, base)}

    items = [{"kind": "builtdr", "scenario": base, "variant": v, "impl": impl}
             for v in VARIANTS for impl in ("reference", "fast", "fast_regions_given")]
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
    # excluded, so the ratio is the checks' own cost); full gets fewer runs and no warm-up.
    items += [{"kind": "plan_fast", "scenario": base, "variant": "modified", "contracts": mode}
              for mode in ("off", "sampled")]
    items += [{"kind": "plan_fast", "scenario": base, "variant": "modified", "contracts": "full",
               "runs": cfg.contracts_runs_full, "warmup": 0,
               "budget_s": cfg.contracts_budget_full_s}]
    out = iter(in_workers(cfg, items))

    res["builtdr"] = {v: {impl: next(out) for impl in ("reference", "fast", "fast_regions_given")}
                      for v in VARIANTS}
    res["search"] = {v: {impl: next(out) for impl in ("reference", "fast")} for v in VARIANTS}
    loop, inter, dwithin = next(out), next(out), next(out)
    res["shapely"] = shapely_section(res, shp, loop, inter, dwithin)
    res["scaling"] = [{"dt": dt, "cells": (b := next(out))["info"]["cells"], "builtdr_fast": b,
                       "search_fast": next(out)} for dt in cfg.scaling_dts]
    plan_fast, one_fast = next(out), next(out)
    in_process = {mode: next(out) for mode in ("off", "sampled", "full")}

    have_cli = cli_has("plan")
    no_cli = skipped("no `cfmpa plan` in this checkout (.venv/bin/cfmpa missing or no plan)")
    default_toml = scenario_file(base, tmp)
    one_toml = scenario_file(cfg.one_degree, tmp)
    res["plan"] = {
        "cli_sampled": cli_run(cfg, ["plan", str(default_toml), "--variant", "modified", "--out",
                                     str(tmp / "plan"), "--contracts", "sampled"])
        if have_cli else no_cli,
        "fast_in_process_sampled": plan_fast,
        "note": "cli: `cfmpa plan` in a fresh process (fast kernels, imports and the kernels' "
                "cache load included); fast_in_process: plan() with the same kernels, files "
                "written, imports excluded",
    }
    res["prove"] = (cli_run(cfg, ["prove", "--out", str(tmp / "proofs")]) if cli_has("prove")
                    else skipped("no `cfmpa prove` in this checkout yet"))
    res["contracts"] = contracts_section(cfg, tmp, have_cli, base, in_process)
    res["one_degree"] = {
        "grid": one_fast["info"]["grid"], "cells": one_fast["info"]["cells"],
        "plan_fast_in_process_sampled": one_fast,
        "plan_cli_sampled": cli_run(cfg, ["plan", str(one_toml), "--variant", "modified",
                                          "--out", str(tmp / "one"), "--contracts", "sampled"])
        if have_cli else no_cli,
    }
    if not cfg.quick:   # the smoke run's key set stays as it was (see the module docstring)
        res["campaign"] = campaign_section(cfg, tmp)
    res["monitor"] = monitor_section(cfg, tmp, base, have_cli and cli_has("monitor"))
    res["targets"] = targets(res, cfg)
    return res


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
    big = 20_000 if cfg.quick else 1_000_000
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


def contracts_section(cfg: Config, tmp: Path, have_cli: bool, base: dict[str, Any],
                      in_process: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """`--contracts off|sampled|full` on the default grid: in process (the checks' own cost) and,
    for off and sampled, as `cfmpa plan` processes (what a user waits for)."""
    out: dict[str, Any] = {"scenario": base, "variant": "modified",
                           "note": "in_process: plan() after a warm-up (full: no warm-up, fewer "
                                   "runs, minutes each); cli: whole `cfmpa plan` processes",
                           "in_process": in_process}
    modes = ("off", "sampled", "full")
    if all("median_s" in in_process[m] for m in modes):
        off = in_process["off"]["median_s"]
        out["ratios"] = {"sampled_over_off": in_process["sampled"]["median_s"] / off,
                         "full_over_off": in_process["full"]["median_s"] / off}
    if not have_cli:
        out["cli"] = skipped("no `cfmpa plan` in this checkout")
        return out
    toml = scenario_file(base, tmp)
    out["cli"] = {mode: cli_run(cfg, ["plan", str(toml), "--variant", "modified", "--out",
                                      str(tmp / f"contracts-{mode}"), "--contracts", mode])
                  for mode in ("off", "sampled")}
    cli = out["cli"]
    if all("median_s" in cli[m] for m in ("off", "sampled")):
        out["cli_ratios"] = {"sampled_over_off": cli["sampled"]["median_s"]
                             / cli["off"]["median_s"]}
    return out


def targets(res: dict[str, Any], cfg: Config) -> list[dict[str, Any]]:
    """The issue's targets against the medians (meaningful on the full run only)."""
    def row(name: str, measured: float | None, limit: float, at_most: bool = True,
            note: str = "") -> dict[str, Any]:
        met = None if measured is None else (measured <= limit if at_most else measured >= limit)
        return {"target": name, "limit": limit, "measured": measured, "met": met, "note": note}

    def med(d: dict[str, Any]) -> float | None:
        return d.get("median_s")

    sh = res["shapely"]["ratios"]
    cli = res["plan"]["cli_sampled"]
    one = res["one_degree"]
    rows = [
        row("BuiltDR fast, slowest variant (s)",
            max(res["builtdr"][v]["fast"]["median_s"] for v in VARIANTS), 0.5,
            note="right regions included"),
        row("BuiltDR fast vs per-cell shapely loop (x)", sh["loop_over_ours"], 1000, False,
            note="both given the same regions; extrapolated from the sample"),
        row("BuiltDR fast vs vectorised shapely intersects (x)", sh["intersects_over_ours"], 10,
            False, note="both given the same regions"),
        row("search fast, slowest variant (s)",
            max(res["search"][v]["fast"]["median_s"] for v in VARIANTS), 1.0),
        row("cfmpa plan end to end, sampled (s)", med(cli), 3.0,
            note="fresh process, certificate included"),
        row("1-degree cfmpa plan (s)", med(one["plan_cli_sampled"]), 5.0,
            note="fresh process, certificate included"),
        row("1-degree cfmpa plan (peak MiB)", one["plan_cli_sampled"].get("peak_rss_mb"), GIB,
            note="fresh process"),
    ]
    if cfg.quick:
        for r in rows:
            r["note"] = ("quick run on a coarse grid: not the target's measurement; " + r["note"])
    return rows


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
            lines.append(f"{name:58s} {d.get('skipped') or d.get('error')}")

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
    add("cfmpa plan, sampled (fresh process)", res["plan"]["cli_sampled"])
    add("plan(), sampled (in process)", res["plan"]["fast_in_process_sampled"])
    add("make prove (cfmpa prove)", res["prove"])
    c = res["contracts"]
    for mode in ("off", "sampled", "full"):
        add(f"plan(), contracts {mode} (in process)", c["in_process"][mode])
    for mode, d in c["cli"].items() if "skipped" not in c["cli"] else ():
        add(f"cfmpa plan --contracts {mode} (fresh process)", d)
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
    lines.append("")
    lines.append("targets:")
    for t in res["targets"]:
        verdict = {True: "met", False: "MISSED", None: "n/a"}[t["met"]]
        measured = "-" if t["measured"] is None else f"{t['measured']:.4g}"
        cmp = "<=" if "vs" not in t["target"] else ">="
        lines.append(f"  {t['target']:52s} {measured:>10s} {cmp} {t['limit']:<6g} {verdict}"
                     + (f"  ({t['note']})" if t["note"] else ""))
    return "\n".join(lines)


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


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smoke run on a coarse grid")
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent),
                    help="folder for results.json (default: bench/)")
    ap.add_argument("--runs", type=int, default=None, help="timed runs per item (default 5)")
    ap.add_argument("--only", choices=["campaign"], default=None,
                    help="run only this item and merge it into OUT/results.json")
    args = ap.parse_args(argv)
    cfg = Config.of(args.quick, args.runs)
    if args.only == "campaign":
        out = Path(args.out) / "results.json"
        res = json.loads(out.read_text()) if out.exists() else {}
        with tempfile.TemporaryDirectory(prefix="cfmpa-bench-") as tmp:
            res["campaign"] = campaign_section(cfg, Path(tmp))
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(res, indent=1, default=str) + "\n")
        print("\n".join(campaign_lines(res["campaign"])))
        print(f"\nwrote {out} (campaign merged)")
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
