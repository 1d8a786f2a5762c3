"""`cfmpa compare` on the engine: the same compare.json whatever the workers, resumable after an
interruption (Ctrl-C, a torn last line, a killed client or worker), errors recorded, settings
guarded, bad scheduler addresses refused quickly; compare.json's intervals and paired tests
(the statistics themselves: tests/report/test_stats.py).

One local Dask cluster (2 worker processes) is shared by the module; tests that need their own
cluster (``--workers 1``) or a fresh process say so.
"""

from __future__ import annotations

import io
import json
import logging
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cfmpa.cli import main
from cfmpa.errors import InputError
from cfmpa.report import run_compare
from cfmpa.report._compare import campaign_json
from cfmpa.report._stats import mcnemar_exact_p, wilson_interval
from cfmpa.runs import Engine, run_campaign
from cfmpa.runs._campaign import STORE_NAME, random_workcell, workcell_task
from cfmpa.runs._engine import ProgressBar, check_scheduler_address
from cfmpa.runs._store import open_store

SEED, N, DT = 5, 6, 0.2


@pytest.fixture(scope="module")
def cluster():
    """One local cluster of two worker processes for the module (its start costs seconds)."""
    from dask.distributed import LocalCluster

    c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                     dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
    yield c.scheduler_address
    c.close()


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    """A clean serial run of the campaign: its folder and compare.json without timings_s."""
    out = tmp_path_factory.mktemp("clean")
    assert run_compare(N, SEED, str(out), dt=DT, workers=0) == 0
    return out, _without_timings(out / "compare.json")


def _without_timings(path: Path) -> bytes:
    """compare.json's raw bytes with only the top-level timings_s block cut out."""
    lines = path.read_bytes().splitlines(keepends=True)
    at = lines.index(b'  "timings_s": {\n')
    end = next(k for k in range(at, len(lines)) if lines[k].startswith(b"  }"))
    rest = lines[:at] + lines[end + 1:]
    assert b'"timings_s"' not in b"".join(rest)
    return b"".join(rest)


def _store_lines(out: Path) -> list[bytes]:
    return (out / STORE_NAME).read_bytes().splitlines(keepends=True)


# --- the same result whatever runs it ---------------------------------------------------------

def test_compare_json_is_the_same_serial_on_one_and_on_two_local_workers(clean, cluster,
                                                                          tmp_path, capsys):
    _, want = clean
    assert run_compare(N, SEED, str(tmp_path / "one"), dt=DT, workers=1) == 0
    printed = capsys.readouterr().out
    assert "local Dask cluster, 1 worker process(es)" in printed
    assert "dashboard http://127.0.0.1:" in printed
    assert run_compare(N, SEED, str(tmp_path / "two"), dt=DT, scheduler=cluster) == 0
    assert f"Dask scheduler {cluster}, 2 worker(s)" in capsys.readouterr().out
    assert _without_timings(tmp_path / "one" / "compare.json") == want
    assert _without_timings(tmp_path / "two" / "compare.json") == want
    doc = json.loads((tmp_path / "two" / "compare.json").read_text())
    assert doc["n"] == N and doc["dt"] == DT and doc["planned"] == N and doc["errors"] == []
    assert set(doc["timings_s"]) >= {"run", "engine_start", "tasks", "mean_per_variant"}


def test_a_workcell_is_a_function_of_seed_index_and_dt_alone():
    # Drawn from default_rng([seed, index]): another index or seed first, or another process,
    # changes nothing; dt changes the grid (and so the cells drawn), not the arms.
    first = random_workcell(SEED, 3, DT)
    for i in (0, 1, 2):
        random_workcell(SEED, i, DT)
        random_workcell(SEED + 1, i, DT)
    assert random_workcell(SEED, 3, DT) == first
    coarse = random_workcell(SEED, 3, 0.1)
    assert coarse.dt == 0.1 and first.dt == DT
    assert (coarse.left.links, coarse.right.base) == (first.left.links, first.right.base)
    a, b = workcell_task(SEED, 3, DT), workcell_task(SEED, 3, DT)
    for rec in (a, b):
        rec.pop("seconds")
        for o in rec["outcomes"].values():
            o.pop("seconds")
    assert a == b and a["status"] == "ok"


# --- resumable, nothing lost ------------------------------------------------------------------

class Stop(KeyboardInterrupt):
    pass


def _stop_after(k: int):
    def hook(written: int) -> None:
        if written >= k:
            raise Stop
    return hook


def test_an_interrupted_serial_campaign_resumes_to_the_clean_result(clean, tmp_path, capsys):
    _, want = clean
    out = tmp_path / "c"
    with pytest.raises(KeyboardInterrupt):
        run_compare(N, SEED, str(out), dt=DT, workers=0, _after_record=_stop_after(2))
    assert "2 of 6 workcells are recorded" in capsys.readouterr().err
    assert not (out / "compare.json").exists()
    assert len(_store_lines(out)) == 1 + 2          # the header and two workcells
    assert run_compare(N, SEED, str(out), dt=DT, workers=0) == 0
    assert "reused 2 finished workcell(s), computing 4" in capsys.readouterr().out
    assert _without_timings(out / "compare.json") == want


def test_an_interrupted_dask_campaign_resumes_on_another_engine(clean, cluster, tmp_path, capsys):
    _, want = clean
    out = tmp_path / "c"
    with pytest.raises(KeyboardInterrupt):
        run_compare(N, SEED, str(out), dt=DT, scheduler=cluster, _after_record=_stop_after(3))
    recorded = len(_store_lines(out)) - 1
    assert recorded == 3
    assert run_compare(N, SEED, str(out), dt=DT, workers=0) == 0
    assert f"reused {recorded} finished workcell(s)" in capsys.readouterr().out
    assert _without_timings(out / "compare.json") == want
    # The store holds each workcell once: nothing was planned twice.
    indices = [json.loads(x)["index"] for x in _store_lines(out)[1:]]
    assert sorted(indices) == list(range(N))


def test_a_torn_last_line_is_dropped_and_its_workcell_planned_again(clean, tmp_path, capsys):
    src, want = clean
    out = tmp_path / "c"
    out.mkdir()
    lines = _store_lines(src)
    torn = lines[4][: len(lines[4]) // 2]           # a crash in the middle of a write
    (out / STORE_NAME).write_bytes(b"".join(lines[:4]) + torn)
    assert run_compare(N, SEED, str(out), dt=DT, workers=0) == 0
    printed = capsys.readouterr().out
    assert "reused 3 finished workcell(s), computing 3" in printed
    assert "dropped a torn last line" in printed
    assert _without_timings(out / "compare.json") == want
    after = _store_lines(out)
    assert len(after) == 1 + N and all(json.loads(x) for x in after)


def test_a_torn_header_starts_the_store_afresh(clean, tmp_path):
    _, want = clean
    out = tmp_path / "c"
    out.mkdir()
    (out / STORE_NAME).write_bytes(b'{"format":"cfmpa-compare-st')
    assert run_compare(N, SEED, str(out), dt=DT, workers=0) == 0
    assert _without_timings(out / "compare.json") == want


@pytest.mark.parametrize("workers", ["0", pytest.param("1", marks=pytest.mark.slow)])
def test_a_killed_client_loses_nothing_recorded(clean, tmp_path, workers):
    """`cfmpa compare` killed with SIGKILL mid-campaign (a fresh process, in process or with its
    own local cluster, about 30 s; each task slowed by the test-only fault hook), then rerun:
    every workcell recorded is reused and the result is the clean one."""
    _, want = clean
    out = tmp_path / "c"
    argv = [sys.executable, "-m", "cfmpa", "compare", "--n", str(N), "--seed", str(SEED),
            "--dt", str(DT), "--workers", workers, "--out", str(out)]
    env = os.environ | {"CFMPA_TEST_FAULTS": json.dumps({str(i): "sleep:0.5" for i in range(N)})}
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    deadline = time.monotonic() + 60
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            if (out / STORE_NAME).exists() and len(_store_lines(out)) >= 1 + 2:
                break
            time.sleep(0.02)
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    recorded = [x for x in _store_lines(out)[1:] if x.endswith(b"\n")]
    assert 2 <= len(recorded) < N, "the client was not killed mid-campaign"
    code = main(["compare", "--n", str(N), "--seed", str(SEED), "--dt", str(DT),
                 "--workers", "0", "--out", str(out)])
    assert code == 0
    assert _without_timings(out / "compare.json") == want


def test_a_worker_that_dies_mid_task_has_the_task_run_again(clean, cluster, tmp_path):
    _, want = clean
    mark = tmp_path / "killed"
    out = tmp_path / "c"
    assert run_compare(N, SEED, str(out), dt=DT, scheduler=cluster,
                       _faults={2: f"exit-once:{mark}"}) == 0
    assert mark.exists(), "the fault did not kill the worker"
    assert _without_timings(out / "compare.json") == want


# --- errors are recorded, settings guarded ----------------------------------------------------

@pytest.mark.parametrize("engine", ["serial", "dask"])
def test_a_task_that_raises_is_recorded_then_planned_again(clean, cluster, tmp_path, capsys,
                                                           engine):
    _, want = clean
    out = tmp_path / "c"
    where = {"workers": 0} if engine == "serial" else {"scheduler": cluster}
    assert run_compare(N, SEED, str(out), dt=DT, _faults={1: "raise", 4: "raise"}, **where) == 1
    printed = capsys.readouterr().out
    assert "errors    2 workcell(s) raised" in printed
    doc = json.loads((out / "compare.json").read_text())
    assert doc["planned"] == N - 2 and [e["index"] for e in doc["errors"]] == [1, 4]
    assert doc["errors"][0]["message"] == "RuntimeError: fault injected into workcell 1"
    assert sum(r["found"] <= N - 2 for r in doc["table"]) == 3
    recs = [json.loads(x) for x in _store_lines(out)[1:]]
    assert sorted(r["index"] for r in recs if r["status"] == "error") == [1, 4]
    # A rerun plans the two again (and only those) and ends with the clean result.
    assert run_compare(N, SEED, str(out), dt=DT, workers=0) == 0
    assert "reused 4 finished workcell(s), computing 2 (2 that raised before)" in (
        capsys.readouterr().out)
    assert _without_timings(out / "compare.json") == want


@pytest.mark.parametrize("flag, value", [("--n", str(N + 1)), ("--seed", str(SEED + 1)),
                                         ("--dt", "0.25")])
def test_a_rerun_with_other_settings_into_the_same_folder_is_refused(clean, tmp_path, capsys,
                                                                     flag, value):
    src, _ = clean
    out = tmp_path / "c"
    out.mkdir()
    (out / STORE_NAME).write_bytes((src / STORE_NAME).read_bytes())
    before = (out / STORE_NAME).read_bytes()
    args = {"--n": str(N), "--seed": str(SEED), "--dt": str(DT)} | {flag: value}
    code = main(["compare", *[x for kv in args.items() for x in kv], "--workers", "0",
                 "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert f"error: {flag} differs from the run recorded in this folder" in err
    assert f"n {N}, seed {SEED}, dt {DT}" in err and "Traceback" not in err
    assert (out / STORE_NAME).read_bytes() == before and not (out / "compare.json").exists()


def test_a_damaged_line_before_the_last_is_an_input_error(clean, tmp_path):
    src, _ = clean
    out = tmp_path / "c"
    out.mkdir()
    lines = _store_lines(src)
    (out / STORE_NAME).write_bytes(b"".join(lines[:2]) + b"garbage\n" + b"".join(lines[3:]))
    with pytest.raises(InputError, match=r"compare.jsonl:3: error: line .*damaged"):
        run_campaign(N, SEED, DT, out=out)


def test_a_record_of_another_campaign_size_is_an_input_error(clean, tmp_path):
    src, _ = clean
    out = tmp_path / "c"
    out.mkdir()
    lines = _store_lines(src)
    rec = json.loads(lines[1]) | {"index": N + 3}
    (out / STORE_NAME).write_bytes(lines[0] + json.dumps(rec).encode() + b"\n")
    with pytest.raises(InputError, match=rf"compare.jsonl:2: error: index must be a workcell "
                                         rf"index in \[0, {N}\), got {N + 3}"):
        run_campaign(N, SEED, DT, out=out)


def test_a_store_is_used_by_one_run_at_a_time(tmp_path):
    settings = {"n": 1, "seed": 0, "dt": 0.1}
    with open_store(tmp_path / STORE_NAME, "f", 1, settings) as first:
        with pytest.raises(InputError, match="in use by another run"):
            open_store(tmp_path / STORE_NAME, "f", 1, settings)
        first.append({"index": 0})
    with open_store(tmp_path / STORE_NAME, "f", 1, settings) as again:
        assert again.records == [{"index": 0}] and not again.torn


@pytest.mark.parametrize("kw, field", [({"n": 0}, "--n"), ({"seed": -1}, "--seed"),
                                       ({"dt": 0.0}, "--dt"), ({"dt": 1.5}, "--dt"),
                                       ({"dt": float("nan")}, "--dt"), ({"workers": -1}, "--workers")])
def test_campaign_settings_are_validated_before_any_work(tmp_path, kw, field):
    args = {"n": 2, "seed": 0, "dt": 0.1} | kw
    with pytest.raises(InputError, match=field):
        run_campaign(args.pop("n"), args.pop("seed"), args.pop("dt"), out=tmp_path, **args)
    assert not (tmp_path / STORE_NAME).exists()


# --- scheduler addresses ----------------------------------------------------------------------

@pytest.mark.parametrize("address", ["", "not an address", "tcp://", "tcp://127.0.0.1",
                                     "tcp://127.0.0.1:port", "tcp://127.0.0.1:99999",
                                     "http://127.0.0.1:8786", "tcp://127.0.0.1:8786/path",
                                     " tcp://127.0.0.1:8786"])
def test_a_malformed_scheduler_address_is_refused_at_once(address, tmp_path, capsys):
    t0 = time.monotonic()
    code = main(["compare", "--n", "2", "--scheduler", address, "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and time.monotonic() - t0 < 5
    assert "error: --scheduler must be a Dask scheduler address" in err and "Traceback" not in err
    assert not (tmp_path / STORE_NAME).exists()


def test_well_formed_scheduler_addresses_are_normalised():
    assert check_scheduler_address("127.0.0.1:8786") == "tcp://127.0.0.1:8786"
    assert check_scheduler_address("tls://sched.example:8786") == "tls://sched.example:8786"
    assert check_scheduler_address("tcp://[::1]:8786") == "tcp://[::1]:8786"


def test_a_scheduler_that_does_not_answer_is_an_input_error_not_a_hang(tmp_path, capsys):
    t0 = time.monotonic()
    code = main(["compare", "--n", "2", "--scheduler", "tcp://127.0.0.1:9",
                 "--connect-timeout", "1", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and time.monotonic() - t0 < 15
    assert "error: --scheduler did not answer within 1 s" in err and "Traceback" not in err


def test_a_server_that_is_not_a_scheduler_is_an_input_error_not_a_hang(cluster, tmp_path,
                                                                        capsys):
    """A port that accepts and never answers (as the dashboard's HTTP port does: dask's own
    handshake would wait forever) and a worker's address, each exit 2 within the timeout."""
    import socket

    from dask.distributed import Client

    with Client(cluster, set_as_default=False) as client:
        worker = next(iter(client.scheduler_info()["workers"]))
    with socket.socket() as silent:
        silent.bind(("127.0.0.1", 0))
        silent.listen()
        mute = f"tcp://127.0.0.1:{silent.getsockname()[1]}"
        for address, said in [(mute, "did not answer within 1 s"),
                              (worker, "is not a Dask scheduler (it answered as Worker)")]:
            t0 = time.monotonic()
            code = main(["compare", "--n", "2", "--scheduler", address, "--connect-timeout", "1",
                         "--out", str(tmp_path)])
            err = capsys.readouterr().err
            assert code == 2 and time.monotonic() - t0 < 15
            assert f"error: --scheduler {said}" in err and "Traceback" not in err


def test_a_scheduler_without_workers_is_an_input_error_not_a_hang():
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=0, processes=True, host="127.0.0.1",
                      dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL) as empty:
        t0 = time.monotonic()
        with pytest.raises(InputError, match="has no worker after 1 s"):
            run_campaign(2, 0, 0.5, scheduler=empty.scheduler_address, connect_timeout=1)
        assert time.monotonic() - t0 < 15


# --- statistics a reviewer can quote ----------------------------------------------------------

def test_campaign_json_states_intervals_and_paired_tests(clean):
    src, _ = clean
    doc = json.loads((src / "compare.json").read_text())
    c = run_campaign(N, SEED, DT, out=src)            # every workcell reused from the store
    assert c.reused == N and campaign_json(c)["table"] == doc["table"]
    for row in doc["table"]:
        lo, hi = row["success_rate_ci95"]
        assert (lo, hi) == pytest.approx(wilson_interval(row["found"], doc["planned"]))
        assert lo <= row["success_rate"] <= hi
    pairs = {(p["a"], p["b"]): p for p in doc["paired"]}
    assert set(pairs) == {("original", "modified"), ("modified", "tight"), ("original", "tight")}
    om = pairs[("original", "modified")]
    assert om["a_fails_b_succeeds"] == doc["original_fails_modified_succeeds"]
    assert om["a_succeeds_b_fails"] == doc["checks"]["modified_fails_original_succeeds"]
    assert sum(om[k] for k in ("a_fails_b_succeeds", "a_succeeds_b_fails", "both_succeed",
                               "both_fail")) == doc["planned"]
    assert om["mcnemar_exact_p"] == mcnemar_exact_p(om["a_fails_b_succeeds"],
                                                    om["a_succeeds_b_fails"])


# --- progress ---------------------------------------------------------------------------------

def test_progress_bar_shows_count_rate_and_time_left_only_on_a_terminal():
    quiet = ProgressBar.for_terminal("compare", 10, stream=io.StringIO())
    assert quiet.stream is None                      # not a terminal: silent
    buf = io.StringIO()
    bar = ProgressBar.for_terminal("compare", 10, start=4, progress=True, stream=buf)
    bar._t0 -= 2.0                                   # two seconds ago
    bar.advance(2)
    line = buf.getvalue()
    assert line.startswith("\rcompare 6/10 [") and "1.00/s" in line and "ETA 0m04s" in line
    bar.close()
    assert buf.getvalue().endswith("\n")


def test_the_serial_engine_reports_every_task_even_one_that_raises():
    got = {}
    with Engine(0) as e:
        e.run(_half, [(1,), (0,), (4,)], got.__setitem__)
    assert got[0] == 0.5 and got[2] == 0.125
    assert got[1].message == "ZeroDivisionError: division by zero"


def _half(x: int) -> float:
    return 1 / (2 * x)


def test_compare_without_out_writes_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["compare", "--n", "2", "--dt", "0.5", "--workers", "0"]) == 0
    assert "checks    all hold" in capsys.readouterr().out
    assert os.listdir(tmp_path) == []
