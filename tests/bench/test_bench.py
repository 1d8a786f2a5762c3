"""`make bench` in smoke mode (--quick): every section is written with timings, and the
benchmark peers agree with our D_R. The structure is tested, never the speed; the targets'
list, limits and verdicts are tested on made-up results."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from cfmpa.spec import Variant

ROOT = Path(__file__).resolve().parents[2]
TIMING = {"median_s", "min_s", "max_s", "runs", "peak_rss_mb"}


def bench_module():
    """bench/run.py as a module (it is not part of the package)."""
    if "cfmpa_bench_run" not in sys.modules:
        spec = importlib.util.spec_from_file_location("cfmpa_bench_run", ROOT / "bench" / "run.py")
        mod = importlib.util.module_from_spec(spec)
        sys.modules["cfmpa_bench_run"] = mod      # dataclasses look their module up
        spec.loader.exec_module(mod)
    return sys.modules["cfmpa_bench_run"]


# Slow: the whole quick bench, cfmpa prove --audit included (minutes); make test-slow runs it.
@pytest.mark.slow
def test_bench_quick_writes_results_with_every_section(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "bench" / "run.py"), "--quick", "--prove",
                           "--out", str(tmp_path)], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    res = json.loads((tmp_path / "results.json").read_text())
    assert set(res) == {"meta", "builtdr", "builtdr_profile", "search", "shapely", "scaling",
                        "plan", "dr_cli", "check", "prove", "contracts", "one_degree", "monitor",
                        "plan_scaling", "certify_stream", "tools", "first_run", "targets",
                        "informational"}
    assert [r["dt"] for r in res["plan_scaling"]["rows"]] == [0.16, 0.08]
    assert all("error" not in r and r["bytes_per_cell"] > 0 for r in res["plan_scaling"]["rows"])
    for v in Variant:
        assert set(res["builtdr"][v.value]) == {"reference", "fast", "fast_regions_given"}
        assert set(res["search"][v.value]) == {"reference", "fast"}
        for d in (*res["builtdr"][v.value].values(), *res["search"][v.value].values()):
            assert TIMING <= set(d)
    assert {"per_cell_loop", "vectorised_intersects", "vectorised_dwithin", "ratios"} <= set(
        res["shapely"])
    # The peers decide every sampled cell as our kernel does, so the ratios compare like with like.
    assert res["shapely"]["per_cell_loop"]["info"]["disagree_with_ours"] == 0
    assert res["shapely"]["vectorised_dwithin"]["info"]["disagree_with_ours"] == 0
    assert [s["dt"] for s in res["scaling"]] == [0.32, 0.16, 0.08]
    assert res["scaling"][0]["cells"] < res["scaling"][1]["cells"] < res["scaling"][2]["cells"]
    for section in (res["plan"]["cli_sampled"], res["plan"]["cli_full"], res["prove"],
                    res["one_degree"]["plan_cli_sampled"], res["dr_cli"], res["check"]):
        assert "error" not in section, section
        assert "skipped" in section or TIMING <= set(section)
    # --prove: make prove timed once, and its obligations alone from its results.json.
    assert res["prove"]["runs"] == 1 and res["prove"]["obligations_s"] > 0
    assert res["plan"]["cli_default_contracts"] in ("off", "sampled", "full")
    assert res["check"]["plan_contracts"] == res["plan"]["cli_default_contracts"]
    c = res["contracts"]
    for mode in ("off", "sampled", "full"):
        assert TIMING <= set(c["in_process"][mode])
        assert c["in_process"][mode]["info"]["contracts"] == mode
        assert c["in_process"][mode]["info"]["violations"] == 0
    assert c["ratios"]["full_over_off"] > 0 and c["ratios"]["sampled_over_off"] > 0
    assert set(c["cli"]) == {"off", "sampled", "full"} and "error" not in str(c["cli"])
    # The profile is build_dr_fast's own split of its stages.
    prof = res["builtdr_profile"]
    for v in Variant:
        p = prof[v.value]
        stages = p["stages_median_s"]
        assert set(stages) == set(prof["stages"]) | {"total"}
        assert all(x >= 0 for x in stages.values())
        assert sum(x for k, x in stages.items() if k != "total") <= stages["total"] * 1.01
    assert TIMING <= set(res["one_degree"]["plan_fast_in_process_sampled"])
    m = res["monitor"]
    assert "error" not in m, m
    if "skipped" not in m:
        for key in ("log", "log_tenth"):
            assert {"samples", "samples_per_s", "peak_rss_mb", "status"} <= set(m[key])
    rows = res["targets"] + res["informational"]
    assert all({"target", "limit", "measured", "met", "note", "cmp"} <= set(t) for t in rows)
    assert [t["limit"] for t in res["targets"]] == LIMITS
    assert all(t["measured"] is not None for t in res["targets"]), res["targets"]
    assert all(t["former_target"] for t in res["informational"])
    assert "targets (" in proc.stdout and "informational (" in proc.stdout
    assert "BuiltDR fast profile" in proc.stdout and "results.json" in proc.stdout


#: The targets, in the table's order: full checking (check s, check MiB, full/off, BuiltDR s,
#: the first run / a later one), start-up (cfmpa dr s, peer/dr), plan s, monitoring
#: (samples/s, its peak growth), proving (make prove s, obligations alone s, audit s).
LIMITS = [5.0, 1024.0, 5.0, 0.10, 2.0, 0.6, 4.0, 1.5, 100_000.0, 16.0, 90.0, 60.0, 45.0,
          20.0, 300.0, 200.0, 300.0, 1.0, 300.0, 4096.0, 2048.0]


def made_up(default_mode: str = "full") -> dict[str, Any]:
    """Results with every field targets() and informational() read; numbers chosen so that some
    targets are met and some missed."""
    run = bench_module()

    def t(s: float, **kw: Any) -> dict[str, Any]:
        return {"median_s": s, "min_s": s, "max_s": s, "runs": 1, "peak_rss_mb": 300.0, **kw}
    stages = dict.fromkeys(run.PROFILE_STAGES, 0.01) | {"right_regions": 0.19, "total": 0.5}
    return {
        "builtdr": {v: {"fast": t(x, cold_s=x + 0.2)}
                    for v, x in zip(run.VARIANTS, (0.5, 0.55, 0.45))},
        "first_run": {"first": t(12.0), "later": t(4.0), "ratio_first_over_later": 3.0,
                      "compile_lines": ["cfmpa: compiling 3 groups ..."]},
        "builtdr_profile": {v: {"stages_median_s": stages, "kernel_threads": 1,
                                "unsure_pairs": 0,
                                "build_dr_fast_median_s": 0.5} for v in run.VARIANTS},
        "search": {v: {"fast": t(0.1)} for v in run.VARIANTS},
        "shapely": {"vectorised_intersects": t(4.0),
                    "vectorised_dwithin": {"extrapolated_full_grid_s": 2.0},
                    "ratios": {"loop_over_ours": 2000.0, "intersects_over_ours": 10.3}},
        "plan": {"cli_sampled": t(3.0), "cli_default_contracts": default_mode},
        "contracts": {"in_process": {"off": t(1.0), "sampled": t(1.5), "full": t(2.5)},
                      "ratios": {"full_over_off": 2.5},
                      "cli": {"off": t(1.7), "sampled": t(3.0),
                              "full": t(4.5, timings_s={"build_dr": 0.6, "search": 0.6})}},
        "dr_cli": t(2.0, variant="modified"),
        "check": t(3.3, peak_rss_mb=1500.0, plan_contracts=default_mode),
        "prove": t(90.0, obligations_s=70.0, ok=True, obligations=80),
        "audit": t(50.0),
        "one_degree": {"plan_cli_sampled": t(5.0)},
        "monitor": {"log": {"samples": 10**6, "bytes": 96 * 10**6, "cli": t(4.0),
                            "cli_samples_per_s": 250_000.0, "samples_per_s": 300_000.0,
                            "peak_rss_mb": 120.0, "status": "inside"},
                    "log_tenth": {"peak_rss_mb": 118.0}, "peak_growth_mb": 2.0},
        "certify_stream": {"runs": [
            {"rows": n, "bytes": 66 * n, "seconds": sec, "peak_mib": 70.0, "clear": True,
             "timings_s": {"load": sec / 2, "certificate": sec / 2}}
            for n, sec in ((10**6, 12.0), (10**7, 230.0))]},
        "dr_dask": {"speedup_2_over_1": 1.4, "workers_0": t(20.0), "workers_1": t(30.0),
                    "workers_2": t(21.0), "same_store": True,
                    "plan_store": {"dt": 0.0035, "cells": 1_110_000_000, "seconds": 320.0,
                                   "peak_mib": 3000.0}},
        "plan_scaling": {"rows": [{"dt": 0.005, "seconds": 50.0, "peak_mib": 2500.0}]},
    }


def test_targets_are_the_issues_with_their_limits_and_verdicts():
    run = bench_module()
    cfg = run.Config.of(False, None)
    rows = run.targets(made_up("full"), cfg)
    assert [r["limit"] for r in rows] == LIMITS
    assert [r["cmp"] for r in rows] == ["<=", "<=", "<=", "<=", "<=", "<=", ">=", "<=", ">=",
                                        "<=", "<=", "<=", "<=", "<=", "<=", "<=", "<=", ">=",
                                        "<=", "<=", "<="]
    assert [r["measured"] for r in rows] == [3.3, 1500.0, 2.5, 0.55, 3.0, 2.0, 2.0, 4.5,
                                             250_000.0, 2.0, 90.0, 70.0, 50.0, 12.0, 70.0,
                                             230.0, 70.0, 1.4, 320.0, 3000.0, 2500.0]
    assert [r["met"] for r in rows] == [True, False, True, False, False, False, False, False,
                                        True, True, True, False, False, True, True, False, True,
                                        True, False, True, False]
    # D_R on Dask: the note names both medians and that the stores agree.
    assert "1 worker 30.0 s, 2 workers 21.0 s" in rows[17]["note"]
    assert "1,110,000,000 cells" in rows[18]["note"]
    assert "10,000,000-row" in rows[15]["target"] and "default limits" in rows[15]["target"]
    assert "full checking" in rows[0]["target"] and "monitoring" in rows[8]["target"]
    assert "make prove" in rows[10]["target"] and "first run" in rows[4]["target"]
    # The issue's start-up targets: cfmpa dr default's whole process, and the peer against it.
    assert "start-up" in rows[5]["target"] and "whole process" in rows[5]["target"]
    assert "peer" in rows[6]["target"] and "audit default --compare-n 0" in rows[12]["target"]
    # BuiltDR: warm (the median) and cold (the first call) apart; the first run: both runs.
    assert "warm" in rows[3]["target"] and "cold: original 0.700" in rows[3]["note"]
    assert "first 12.0 s" in rows[4]["note"] and "later 4.0 s" in rows[4]["note"]
    # The BuiltDR miss is explained by the profile; the slowest variant is the one measured.
    assert "modified" in rows[3]["note"] and "right regions 0.190 s" in rows[3]["note"]
    # The monitor row reports wall time and peak memory of the whole process.
    assert rows[8]["wall_s"] == 4.0 and rows[8]["peak_rss_mb"] == 120.0
    assert all("quick run" not in r["note"] for r in rows)
    lines = run.target_lines(rows)
    assert sum(" MISSED" in line for line in lines) == 11


def test_plan_target_follows_the_cli_default_contract_mode():
    run = bench_module()
    cfg = run.Config.of(False, None)
    full = run.targets(made_up("full"), cfg)[7]
    sampled = run.targets(made_up("sampled"), cfg)[7]
    assert "--contracts full" in full["target"] and full["measured"] == 4.5
    assert "--contracts sampled" in sampled["target"] and sampled["measured"] == 3.0
    assert "build_dr 0.60" in full["note"]      # the miss with plan.json's stages


def test_unmeasured_targets_are_not_applicable():
    run = bench_module()
    res = made_up()
    res["prove"] = run.skipped("--prove not given (`make bench` passes it)")
    res["audit"] = run.skipped("--prove not given (`make bench` passes it)")
    res["dr_cli"] = {"error": "exit 2: boom", "argv": ["dr"]}
    rows = {r["target"]: r for r in run.targets(res, run.Config.of(False, None))}
    for name in ("proving: make prove, whole process (s)",
                 "proving: make prove, obligations alone (s)",
                 "proving: cfmpa audit default --compare-n 0, whole process (s)",
                 "start-up: cfmpa dr default, whole process (s)",
                 "start-up: shapely-vectorised peer / cfmpa dr (x)"):
        assert rows[name]["measured"] is None and rows[name]["met"] is None
        assert rows[name]["note"].startswith("not measured")


def test_cli_default_contracts_is_the_parsers():
    from cfmpa.cli import _parser

    default = _parser().parse_args(["plan", "default", "--out", "x"]).contracts
    assert bench_module().cli_default_contracts() == default


def test_informational_rows_are_former_targets_only():
    run = bench_module()
    rows = run.informational(made_up(), run.Config.of(False, None))
    names = {r["target"] for r in rows}
    assert all(r["former_target"] for r in rows)
    assert not names & {r["target"] for r in run.targets(made_up(), run.Config.of(False, None))}


def test_plan_scaling_reports_cells_peak_bytes_a_cell_and_the_exponent(tmp_path, monkeypatch):
    # cli_run and plan.json made up: two grids, the second 8x the cells and 8x the seconds.
    run = bench_module()
    cfg = run.Config.of(True, None)
    grids = iter([(2, 10, 10), (4, 20, 20)])
    seconds = iter([1.0, 8.0])

    def fake_cli_run(cfg, argv, *a, **k):
        N1, m, n = next(grids)
        out = Path(argv[argv.index("--out") + 1])
        out.mkdir(parents=True)
        (out / "plan.json").write_text(json.dumps({"grid": {"N": N1 - 1, "m": m, "n": n},
                                                   "status": "found", "timings_s": {}}))
        return {"median_s": next(seconds), "min_s": 0, "max_s": 0, "runs": 1,
                "peak_rss_mb": N1 * m * n / 2**20 * 15}

    monkeypatch.setattr(run, "cli_run", fake_cli_run)
    sec = run.plan_scaling_section(cfg, tmp_path)
    assert [r["cells"] for r in sec["rows"]] == [200, 1600]
    assert [r["bytes_per_cell"] for r in sec["rows"]] == [15.0, 15.0]
    assert sec["time_exponent"] == 1.0
    assert "time ~ cells^1.0" in run.plan_scaling_lines(sec)[-1]


def test_certify_stream_reports_seconds_peak_and_bytes_a_row(tmp_path, monkeypatch):
    # cli_run made up: the peak 100 MiB at 10^5 rows and 110 MiB at 10^6 (growth 10 MiB).
    run = bench_module()
    cfg = run.Config.of(False, None)
    monkeypatch.setattr(run, "CERTIFY_STREAM", run.CERTIFY_STREAM | {"rows": (100, 1000)})
    peaks = iter([100.0, 110.0])
    seen = []

    def fake_cli_run(cfg, argv, *a, env=None, **k):
        traj = Path(argv[argv.index("--traj") + 1])
        seen.append((len(traj.read_text().splitlines()) - 1, env))
        Path(argv[argv.index("--json") + 1]).write_text(json.dumps(
            {"clear": True, "intervals": 7, "timings_s": {"load": 1.0, "certificate": 2.0}}))
        return {"median_s": 3.0, "min_s": 3.0, "max_s": 3.0, "runs": 1,
                "peak_rss_mb": next(peaks)}

    monkeypatch.setattr(run, "cli_run", fake_cli_run)
    sec = run.certify_stream_section(cfg, tmp_path)
    assert [n for n, _ in seen] == [100, 1000]
    assert all(e is None for _, e in seen)          # by default: no limit raised
    assert [r["peak_bytes_per_row"] for r in sec["runs"]] == [
        round(100 * 2**20 / 100, 1), round(110 * 2**20 / 1000, 1)]
    assert sec["peak_growth_mib"] == 10.0
    assert "peak growth over the rows: 10.0 MiB" in run.certify_stream_lines(sec)[-1]
    # The targets, met or unmet by row count; unmeasured row counts are unmet (None).
    monkeypatch.setattr(run, "CERTIFY_STREAM", run.CERTIFY_STREAM | {
        "targets": {100: (3.0, 105.0), 1000: (3.0, 105.0), 10**7: (200.0, 300.0)}})
    got = {(t["target"], t["met"]) for t in run.certify_stream_targets(sec)}
    assert got == {("certify: 100-row trajectory streamed, default limits (s)", True),
                   ("certify: 100-row trajectory streamed, default limits (peak MiB)", True),
                   ("certify: 1,000-row trajectory streamed, default limits (s)", True),
                   ("certify: 1,000-row trajectory streamed, default limits (peak MiB)", False),
                   ("certify: 10,000,000-row trajectory streamed, default limits (s)", None),
                   ("certify: 10,000,000-row trajectory streamed, default limits (peak MiB)",
                    None)}


def test_the_slow_trajectory_is_valid_and_certified_clear(tmp_path):
    from cfmpa.scenarios import BUNDLED_DIR
    from cfmpa.spec import certify_trajectory_file, load_scenario
    run = bench_module()
    path = tmp_path / "slow.csv"
    run.slow_trajectory_csv(path, 500, 0.01)
    info, cert, _ = certify_trajectory_file(path, load_scenario(BUNDLED_DIR / "default.toml"))
    assert info.rows == 500 and cert.clear and cert.intervals == 499


def test_bench_only_tools_gives_each_workcells_ratio_to_the_default(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "bench" / "run.py"), "--quick", "--only",
                           "tools", "--out", str(tmp_path)], capture_output=True, text=True,
                          cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    sec = json.loads((tmp_path / "results.json").read_text())["tools"]
    assert list(sec["rows"]) == ["default", "gripper", "levels"]
    for name, r in sec["rows"].items():
        assert TIMING <= set(r), (name, r)
        assert r["ratio_to_default"] == round(r["median_s"] / sec["rows"]["default"]["median_s"], 2)
    assert sec["rows"]["default"]["ratio_to_default"] == 1.0
    assert "BuiltDR fast with tools and heights" in proc.stdout


def test_a_failed_make_prove_is_never_met_and_keeps_why():
    """A make prove that exits non-zero is timed but its targets are missed whatever the time,
    and the row says what failed (not only the output's tail)."""
    run = bench_module()
    res = made_up()
    text = ("prove: Safety.tool_region ... unexpected verdict: unknown (expected proved)\n"
            + "audit: a long report line\n" * 50)
    res["prove"] = {"error": "exit 1: audit: a long report line", "argv": ["prove"],
                    "seconds": 10.0, "peak_rss_mb": 1.0, "obligations_s": 5.0, "ok": False,
                    "failure_lines": run.failure_lines(text)}
    rows = {r["target"]: r for r in run.targets(res, run.Config.of(False, None))}
    whole = rows["proving: make prove, whole process (s)"]
    alone = rows["proving: make prove, obligations alone (s)"]
    assert whole["measured"] == 10.0 and whole["met"] is False
    assert "FAILED" in whole["note"] and "Safety.tool_region" in whole["note"]
    assert alone["measured"] == 5.0 and alone["met"] is False and "ok false" in alone["note"]
    # The same times from a run that passed are met: the failure alone made them missed.
    res["prove"] = {k: v for k, v in res["prove"].items()
                    if k not in ("error", "failure_lines")} | {"median_s": 10.0, "ok": True}
    rows = {r["target"]: r for r in run.targets(res, run.Config.of(False, None))}
    assert rows["proving: make prove, whole process (s)"]["met"] is True
    assert rows["proving: make prove, obligations alone (s)"]["met"] is True


def test_failure_lines_keep_what_failed_and_are_bounded():
    run = bench_module()
    text = "ok line\n" + "x FAILED y " * 100 + "\n" + "unexpected z\n" * 100
    got = run.failure_lines(text)
    assert len(got) == 40 and all(len(ln) <= 300 for ln in got)
    assert got[0].startswith("x FAILED") and got[1] == "unexpected z"
    assert run.failure_lines("all good\nstill good\n") == []
