"""`cfmpa check-batch DIR [SCENARIO]`: every plan folder under DIR checked, one task per plan.

A plan folder is any folder under DIR (DIR itself included) holding a plan.json; its D_R is
expected beside it: the store plan.json's ``dr_store`` names, else dr.npy, else dr.zarr
(docs/model.md §9). Each plan is checked as `cfmpa check` does (``check_outputs``: D_R in full,
the path, its costs, optimality, the certificate) against SCENARIO when given, else against the
bundled scenario named by the plan's ``scenario`` key (``cfmpa.scenarios``). The checks
run as tasks on ``Engine`` (in this process, a local Dask cluster, or a scheduler's); the
summary is one table and one JSON document (DIR/check-batch.json, or the --json path), written
atomically, with one row per plan sorted by folder: ``ok``, ``FAIL`` (a check failed: the
failed checks are listed) or ``error`` (the plan could not be checked: a file missing or
unreadable, no scenario of that name; the message says which). Exit 0 when every plan passes, 1
when any fails or errs; 2 when the batch itself is bad input (DIR missing or without a plan,
SCENARIO unreadable) -- before any task runs. A cluster without a worker for --worker-timeout
seconds stops the batch with exit 2 (``WorkersLost``) and the command that runs it again; the
summary is written only when every plan has its row, so a stopped batch writes nothing.
"""

from __future__ import annotations

import shlex
import sys
import time
from pathlib import Path
from typing import Any, TextIO

from ..errors import InputError, WorkersLost
from ..files import dumps_json, write_bytes_atomic
from ..scenarios import BUNDLED_DIR, bundled_names
from ..spec import load_scenario, make_grid
from ._check import check_outputs, read_plan
from ._drstore import find_dr, load_dr
from ._engine import (
    CONNECT_TIMEOUT_S,
    WORKER_TIMEOUT_S,
    Engine,
    ProgressBar,
    TaskLost,
    error_message,
)

__all__ = ["BATCH_JSON", "batch_table", "check_plan_folder", "find_plan_folders", "run_batch"]

#: The summary's default name in DIR.
BATCH_JSON = "check-batch.json"


def find_plan_folders(root: str | Path) -> list[Path]:
    """Every folder under ``root`` (itself included) that holds a plan.json, sorted."""
    top = Path(root)
    return sorted(p.parent for p in top.rglob("plan.json") if p.is_file())


def check_plan_folder(folder: str, scenario: str | None, rel: str) -> dict[str, Any]:
    """The task of one plan folder: its summary row (never raises: an input that cannot be read
    is an ``error`` row with the message)."""
    t0 = time.perf_counter()
    row: dict[str, Any] = {"folder": rel, "scenario": None, "variant": None, "status": "error",
                           "checks": 0, "failed": [], "message": None}
    try:
        plan_path = Path(folder) / "plan.json"
        doc = read_plan(plan_path)
        scenario_path = Path(scenario) if scenario is not None else _bundled(plan_path)
        s = load_scenario(scenario_path)
        row.update(scenario=s.name, variant=doc.variant.value)
        dr, dr_sha = load_dr(find_dr(folder, doc.dr_store), make_grid(s).shape)
        report = check_outputs(s, dr, doc, dr_sha256=dr_sha)
        row.update(status="ok" if report.ok else "FAIL",
                   checks=sum(line.status != "skip" for line in report.lines),
                   failed=[line.what for line in report.failed])
    except InputError as exc:
        row["message"] = exc.render()
    except Exception as exc:   # a bug or a resource limit: recorded with its message
        row["message"] = error_message(exc)
    row["seconds"] = time.perf_counter() - t0
    return row


def _bundled(plan_path: Path) -> Path:
    """The bundled scenario named by plan.json's ``scenario`` key."""
    import json

    name = json.loads(plan_path.read_text(encoding="utf-8")).get("scenario")
    if not isinstance(name, str) or name not in bundled_names():
        raise InputError("scenario", name, f"is not a bundled scenario ({', '.join(bundled_names())}"
                         f"); give the scenario file as SCENARIO", source=str(plan_path))
    return BUNDLED_DIR / f"{name}.toml"


def run_batch(root: str | Path, scenario: str | Path | None = None, *,
              json_out: str | Path | None = None, workers: int = 0,
              scheduler: str | None = None, connect_timeout: float = CONNECT_TIMEOUT_S,
              worker_timeout: float = WORKER_TIMEOUT_S, progress: bool | None = None,
              stdout: TextIO | None = None, stderr: TextIO | None = None,
              folder_option: str = "DIR") -> int:
    """`cfmpa check-batch`: check every plan folder under ``root``; print the table and the
    engine's notes on ``stdout`` (default sys.stdout at call time; errors are raised), write
    the JSON summary; return the exit code (0 all pass, 1 any fails or errs; InputError for a
    bad batch; WorkersLost, naming the command to run again, when the cluster had no worker
    for ``worker_timeout`` s). ``folder_option``: how a message names ``root`` (DIR, or the old
    spelling's --batch)."""
    out = sys.stdout if stdout is None else stdout
    top = Path(root)
    if not top.is_dir():
        raise InputError(folder_option, str(root), "must be a folder of plan folders")
    engine = Engine(workers, scheduler, connect_timeout=connect_timeout,
                    worker_timeout=worker_timeout, stream=out)
    scen = None
    if scenario is not None:
        scen = str(Path(scenario).resolve())
        load_scenario(scen)              # unreadable: exit 2 before any task
    folders = find_plan_folders(top)
    if not folders:
        raise InputError(folder_option, str(root), "holds no plan folder (a folder with "
                         "plan.json)")
    rels = [_rel(f, top) for f in folders]
    rows: list[dict[str, Any] | None] = [None] * len(folders)

    def on_done(i: int, result: Any) -> None:
        if isinstance(result, TaskLost):
            result = {"folder": rels[i], "scenario": None, "variant": None, "status": "error",
                      "checks": 0, "failed": [], "message": f"task lost: {result.message}",
                      "seconds": 0.0}
        rows[i] = result

    t0 = time.perf_counter()
    bar = ProgressBar.for_terminal("check", len(folders), progress=progress)
    try:
        with engine:
            engine.run(check_plan_folder,
                       [(str(f.resolve()), scen, r) for f, r in zip(folders, rels)],
                       on_done, name="check-plan", progress=bar)
    except WorkersLost as exc:
        checked = sum(r is not None for r in rows)
        command = ["cfmpa", "check-batch", str(root), *([scen] if scen is not None else []),
                   *(["--json", str(json_out)] if json_out is not None else []),
                   *engine.options()]
        raise WorkersLost(f"{exc}. {checked} of {len(rows)} plans were checked; no summary is "
                          f"written (a batch keeps no partial results); run it again with: "
                          f"{shlex.join(command)}") from None
    done = [r for r in rows if r is not None]
    assert len(done) == len(rows), "the engine reports every task"
    doc = batch_json(top, scen, done, {"run": time.perf_counter() - t0, **engine.timings_s})
    print(batch_table(doc), file=out)
    path = write_bytes_atomic(Path(json_out) if json_out is not None else top / BATCH_JSON,
                              dumps_json(doc).encode())
    print(f"wrote     {path}", file=out)
    return 0 if doc["ok"] else 1


def batch_json(root: Path, scenario: str | None, rows: list[dict[str, Any]],
               timings: dict[str, float]) -> dict[str, Any]:
    """The summary document: counts, one row per plan (sorted by folder), the times apart."""
    rows = sorted(rows, key=lambda r: r["folder"])
    counts = {k: sum(1 for r in rows if r["status"] == k) for k in ("ok", "FAIL", "error")}
    return {
        "root": str(root),
        "scenario": scenario,
        "plans": len(rows),
        "passed": counts["ok"],
        "failed": counts["FAIL"],
        "errors": counts["error"],
        "ok": counts["ok"] == len(rows),
        "rows": [{k: v for k, v in r.items() if k != "seconds"} for r in rows],
        "timings_s": {"per_plan": {r["folder"]: r.get("seconds", 0.0) for r in rows}, **timings},
    }


def batch_table(doc: dict[str, Any]) -> str:
    """The summary as plain text: one line per plan, then the counts."""
    width = max([len("folder")] + [len(r["folder"]) for r in doc["rows"]]) + 2
    lines = [f"{'folder':<{width}}{'scenario':<18}{'variant':<10}{'result':<7}detail"]
    for r in doc["rows"]:
        if r["status"] == "ok":
            detail = f"{r['checks']} checks hold"
        elif r["status"] == "FAIL":
            detail = (f"{len(r['failed'])} of {r['checks']} checks failed: "
                      + "; ".join(r["failed"][:3]) + (" ..." if len(r["failed"]) > 3 else ""))
        else:
            detail = r["message"] or ""
        lines.append(f"{r['folder']:<{width}}{r['scenario'] or '-':<18}{r['variant'] or '-':<10}"
                     f"{r['status']:<7}{detail}")
    lines.append(f"result: {doc['passed']} of {doc['plans']} plans pass"
                 + (f", {doc['failed']} fail" if doc["failed"] else "")
                 + (f", {doc['errors']} could not be checked" if doc["errors"] else ""))
    return "\n".join(lines)


def _rel(folder: Path, root: Path) -> str:
    rel = folder.relative_to(root).as_posix()
    return rel if rel else "."
