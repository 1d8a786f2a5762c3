"""`make bench` in smoke mode (--quick): every section is written with timings, and the
benchmark peers agree with our D_R. The structure is tested, never the speed."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from cfmpa.spec import Variant

ROOT = Path(__file__).resolve().parents[2]
TIMING = {"median_s", "min_s", "max_s", "runs", "peak_rss_mb"}


# Slow: the whole quick bench, cfmpa prove included (minutes); make test-slow runs it.
@pytest.mark.slow
def test_bench_quick_writes_results_with_every_section(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "bench" / "run.py"), "--quick", "--out",
                           str(tmp_path)], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    res = json.loads((tmp_path / "results.json").read_text())
    assert set(res) == {"meta", "builtdr", "search", "shapely", "scaling", "plan", "prove",
                        "contracts", "one_degree", "monitor", "targets"}
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
    for section in (res["plan"]["cli_sampled"], res["prove"],
                    res["one_degree"]["plan_cli_sampled"]):
        assert "error" not in section, section
        assert "skipped" in section or TIMING <= set(section)
    c = res["contracts"]
    for mode in ("off", "sampled", "full"):
        assert TIMING <= set(c["in_process"][mode])
        assert c["in_process"][mode]["info"]["contracts"] == mode
        assert c["in_process"][mode]["info"]["violations"] == 0
    assert c["ratios"]["full_over_off"] > 0 and c["ratios"]["sampled_over_off"] > 0
    assert set(c["cli"]) == {"off", "sampled"} and "error" not in str(c["cli"])
    assert TIMING <= set(res["one_degree"]["plan_fast_in_process_sampled"])
    m = res["monitor"]
    assert "error" not in m, m
    if "skipped" not in m:
        for key in ("log", "log_tenth"):
            assert {"samples", "samples_per_s", "peak_rss_mb", "status"} <= set(m[key])
    assert all({"target", "limit", "measured", "met"} <= set(t) for t in res["targets"])
    assert "targets:" in proc.stdout and "results.json" in proc.stdout
