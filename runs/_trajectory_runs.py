"""`cfmpa certify`, `cfmpa monitor` and `cfmpa simulate`: any planner's trajectory (docs/model.md §12).

certify: the continuous-time certificate of a trajectory file and its tolerance tube.
monitor: a measured joint log streamed (in blocks, constant memory) against the certified tube.
simulate: a measured log from a tracking model (lag, bounded noise, seeded; injected excursions).

JSON outputs are byte-identical for the same inputs apart from ``timings_s``.
"""

from __future__ import annotations

import hashlib
import io
import itertools
import math
import sys
import time
import warnings
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import numpy as np
import numpy.typing as npt

from ..errors import MISSING, InputError
from ..files import dumps_json, write_bytes_atomic
from ..spec import (TRAJECTORY_COLUMNS, Certificate, Scenario, Trajectory, certify_trajectory,
                    closest_links, contact_links_text, csv_column_order, load_scenario, load_trajectory, tolerance_rad,
                    trajectory_distances, tube_lipschitz)

__all__ = ["BLOCK_ROWS", "Excursion", "MonitorResult", "certify_json", "log_csv", "monitor_json",
           "monitor_log", "parse_excursion", "run_certify", "run_monitor", "run_simulate",
           "simulate_log"]

#: Log rows parsed per numpy block by the monitor.
BLOCK_ROWS = 16_384
FloatArray = npt.NDArray[np.float64]


def _scenario(s: Scenario | str | Path) -> Scenario:
    return s if isinstance(s, Scenario) else load_scenario(s)


def _sha256(path: str | Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def certify_json(s: Scenario, traj: Trajectory, cert: Certificate,
                 timings: dict[str, float] | None = None,
                 sha256: str | None = None) -> dict[str, Any]:
    """The JSON of `cfmpa certify` (keys stable: add, never rename)."""
    contact = None
    if cert.contact is not None and cert.contact_detail is not None:
        d = cert.contact_detail
        k = d.step
        contact = {"t_s": d.t_s, "links": list(d.links), "links_text": contact_links_text(d.links),
                   "left_angles_rad": list(d.left_angles_rad),
                   "right_angles_rad": list(d.right_angles_rad),
                   "row": None if k is None else k,
                   "line": None if k is None else traj.line(k),
                   "segment": ("at rest after the last row" if k is None else
                               f"rows {k}->{k + 1} (t {float(traj.t[k])!r}.."
                               f"{float(traj.t[k + 1])!r} s)")}
    return {
        "scenario": s.name,
        "scenario_sha256": s.sha256,
        "trajectory": {"file": traj.source, "sha256": sha256, "rows": traj.rows,
                       "t_start_s": float(traj.t[0]), "t_end_s": float(traj.t[-1])},
        "clear": cert.clear,
        "lower_bound_m": cert.lower_bound_m,
        "min_m": cert.min_clearance_m,
        "t_s": cert.t_min_s,
        "tolerance_rad": tolerance_rad(s, cert),
        "tube_lipschitz_m_per_rad": tube_lipschitz(s),
        "intervals": cert.intervals,
        "samples": cert.samples,
        "max_depth_used": cert.max_depth_used,
        "contact": contact,
        "undecided": [list(iv) for iv in cert.undecided],
        "timings_s": {k: round(v, 6) for k, v in sorted((timings or {}).items())},
    }


def run_certify(scenario: Scenario | str | Path, traj_path: str | Path, *,
                json_out: str | Path | None = None, allow_speed: bool = False) -> int:
    """Certify the trajectory file; print the summary; 0 clear, 1 not clear (bad input raises
    InputError, exit 2, nothing written)."""
    s = _scenario(scenario)
    t0 = time.perf_counter()
    traj = load_trajectory(traj_path, s, allow_speed=allow_speed)
    t1 = time.perf_counter()
    cert = certify_trajectory(s, traj)
    t2 = time.perf_counter()
    doc = certify_json(s, traj, cert, {"load": t1 - t0, "certificate": t2 - t1},
                       _sha256(traj_path))
    print(f"trajectory {traj_path}: {traj.rows} rows, t {traj.t[0]:.6g}..{traj.t[-1]:.6g} s "
          f"(scenario {s.name})")
    sampled = (f"sampled minimum {cert.min_clearance_m * 1000:.6g} mm at t={cert.t_min_s:.6g} s "
               f"({cert.intervals} intervals)")
    if cert.clear:
        print(f"clearance clear: proved >= {cert.lower_bound_m * 1000:.6g} mm at every instant; "
              f"{sampled}")
        print(f"tolerance {doc['tolerance_rad']:.6f} rad (max norm over the four joints; "
              f"L = {doc['tube_lipschitz_m_per_rad']:.6g} m/rad)")
    elif doc["contact"] is not None:
        c = doc["contact"]
        where = "" if c["line"] is None else f" (line {c['line']})"
        print(f"clearance NOT CLEAR: contact at t={c['t_s']:.9g} s, {c['links_text']}, "
              f"{c['segment']}{where}; left angles "
              f"{c['left_angles_rad']}, right angles {c['right_angles_rad']}", file=sys.stderr)
    else:
        print(f"clearance NOT CLEAR: {len(cert.undecided)} interval(s) neither proved clear nor "
              f"in contact, first {cert.undecided[0]} s; {sampled}", file=sys.stderr)
    if json_out is not None:
        write_bytes_atomic(json_out, dumps_json(doc).encode())
        print(f"wrote     {json_out}")
    return 0 if cert.clear else 1


# --- monitor ----------------------------------------------------------------------------------


@dataclass
class MonitorResult:
    """What the monitor saw: counts and the first sample outside the tube."""

    samples: int = 0
    outside: int = 0
    contacts: int = 0
    first: dict[str, Any] | None = None
    t_first_s: float | None = None
    t_last_s: float | None = None
    max_deviation_rad: float = 0.0
    timings_s: dict[str, float] = field(default_factory=dict)

    @property
    def status(self) -> str:
        return "inside" if self.outside == 0 else "outside"


def _log_lines(stream: IO[str]) -> Iterator[tuple[int, str]]:
    return enumerate(stream, start=1)


def _fast_rows(lines: Sequence[str]) -> FloatArray | None:
    """The block parsed in one numpy call, or None when anything is unusual (a row numpy cannot
    read, a blank line, which numpy would skip, a non-finite value): then the line-by-line
    reader decides, and names the line."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)        # "input contained no data"
            arr = np.loadtxt(io.StringIO("".join(lines)), delimiter=",", dtype=float,
                             ndmin=2, comments=None)
    except ValueError:
        return None
    if arr.shape != (len(lines), len(TRAJECTORY_COLUMNS)) or not np.isfinite(arr).all():
        return None
    return arr


def _parse_rows(lines: Sequence[str], first_line: int, order: list[int],
                source: str) -> tuple[FloatArray, int | None]:
    """(rows (K, 5) in COLUMNS order, the line of a first trailing blank line or None).

    A malformed line raises InputError with its number; so does a blank line that a sample
    follows in the block. Blank lines may only trail the block's samples."""
    arr = _fast_rows(lines)
    if arr is not None:
        return arr[:, order], None
    rows: list[list[float]] = []
    blank: int | None = None
    for k, line in enumerate(lines):                 # line by line: find the culprit
        no = first_line + k
        if not line.strip():
            if blank is None:
                blank = no
            continue
        if blank is not None:
            raise InputError("row", "", "is blank (samples must follow one another)",
                             source=source, line=blank)
        fields = line.strip().split(",")
        if len(fields) != len(TRAJECTORY_COLUMNS):
            raise InputError("row", line.strip(), f"must have {len(TRAJECTORY_COLUMNS)} values, "
                             f"has {len(fields)}", source=source, line=no)
        vals = []
        for name, i in zip(TRAJECTORY_COLUMNS, order):
            try:
                v = float(fields[i])
            except ValueError:
                raise InputError(name, fields[i].strip(), "must be a number", source=source,
                                 line=no) from None
            if not math.isfinite(v):
                raise InputError(name, v, "must be finite", source=source, line=no)
            vals.append(v)
        rows.append(vals)
    return np.asarray(rows, dtype=float).reshape(-1, len(TRAJECTORY_COLUMNS)), blank


def monitor_log(s: Scenario, traj: Trajectory, tol: float, stream: Iterable[str], *,
                source: str = "<log>", block_rows: int = BLOCK_ROWS) -> MonitorResult:
    """Check every sample of the log against the tube of radius ``tol`` around ``traj``.

    Times must strictly increase; a sample is inside when each joint is within ``tol`` of the
    trajectory at its time (at rest before its first and after its last row). Reads
    ``block_rows`` lines at a time (constant memory); blank lines may only end the log.
    """
    res = MonitorResult()
    it = iter(stream)
    header = next(it, None)
    if header is None or not header.strip():
        raise InputError("log", MISSING, "is empty (needs the header "
                         f"{','.join(TRAJECTORY_COLUMNS)} and at least one sample)",
                         source=source, line=1)
    order = csv_column_order(header, source)
    no = 1                                            # lines read so far
    prev_t = -math.inf
    blank: int | None = None
    while True:
        block = list(itertools.islice(it, block_rows))
        if not block:
            break
        start = no + 1
        no += len(block)
        arr, trailing = _parse_rows(block, start, order, source)
        if blank is not None and len(arr):
            raise InputError("row", "", "is blank (samples must follow one another)",
                             source=source, line=blank)
        if trailing is not None and blank is None:
            blank = trailing
        if not len(arr):
            continue
        t = arr[:, 0]
        dtv = np.diff(np.concatenate([[prev_t], t]))
        bad = np.flatnonzero(~(dtv > 0))
        if len(bad):
            k = int(bad[0])
            before = prev_t if k == 0 else float(t[k - 1])
            raise InputError("t", float(t[k]), f"must be greater than the previous sample's time "
                             f"{before!r} (times strictly increase)", source=source,
                             line=start + k)
        prev_t = float(t[-1])
        if res.t_first_s is None:
            res.t_first_s = float(t[0])
        res.t_last_s = prev_t
        dev = np.abs(arr[:, 1:] - traj.at(t))
        worst = dev.max(axis=1)
        res.max_deviation_rad = max(res.max_deviation_rad, float(worst.max()))
        out = np.flatnonzero(worst > tol)
        res.samples += len(t)
        if len(out):
            d = trajectory_distances(s, arr[out, 1:])            # (K, 2, 2)
            touching = d.min(axis=(1, 2)) == 0.0
            res.contacts += int(touching.sum())
            if res.first is None:
                k = int(out[0])
                q = int(np.argmax(dev[k]))
                links = closest_links(d[0])
                res.first = {"t_s": float(t[k]), "line": start + k,
                             "joint": TRAJECTORY_COLUMNS[1 + q],
                             "deviation_rad": float(dev[k, q]),
                             "angles_rad": [float(x) for x in arr[k, 1:]],
                             "in_contact": bool(touching[0]),
                             "distance_m": float(d[0].min()),
                             "links": list(links), "links_text": contact_links_text(links)}
            res.outside += len(out)
    if res.samples == 0:
        raise InputError("log", MISSING, "has no samples (only a header)", source=source,
                         line=no)
    return res


def monitor_json(s: Scenario, traj: Trajectory, tol: float, res: MonitorResult,
                 log: str) -> dict[str, Any]:
    f = res.first
    return {
        "scenario": s.name, "scenario_sha256": s.sha256, "trajectory": traj.source, "log": log,
        "tolerance_rad": tol,
        "status": res.status,
        "samples": res.samples,
        "outside": res.outside,
        "outside_in_contact": res.contacts,
        "max_deviation_rad": res.max_deviation_rad,
        "t_first_s": res.t_first_s, "t_last_s": res.t_last_s,
        "first_outside_t": None if f is None else f["t_s"],
        "first_outside_line": None if f is None else f["line"],
        "first_outside_joint": None if f is None else f["joint"],
        "first_outside_deviation_rad": None if f is None else f["deviation_rad"],
        "contact": None if f is None else {
            "in_contact": f["in_contact"], "distance_m": f["distance_m"], "links": f["links"],
            "links_text": f["links_text"],
            "angles_rad": f["angles_rad"],
            "meaning": ("the sampled configuration is in contact" if f["in_contact"] else
                        "not in contact, but outside what the certificate covers")},
        "timings_s": {k: round(v, 6) for k, v in sorted(res.timings_s.items())},
    }


def run_monitor(scenario: Scenario | str | Path, traj_path: str | Path, log: str | Path, *,
                json_out: str | Path | None = None, allow_speed: bool = False,
                stdin: IO[str] | None = None) -> int:
    """Monitor a measured log (a file, or ``-`` for standard input) against the certified tube:
    0 every sample inside, 1 some outside (or the trajectory is not certified clear: no JSON
    then), 2 bad input (InputError)."""
    s = _scenario(scenario)
    t0 = time.perf_counter()
    traj = load_trajectory(traj_path, s, allow_speed=allow_speed)
    cert = certify_trajectory(s, traj)
    t1 = time.perf_counter()
    c1 = time.process_time()
    if not cert.clear:
        print(f"monitor   {traj_path} is not certified clear (run cfmpa certify): there is no "
              "tube to monitor", file=sys.stderr)
        return 1
    tol = tolerance_rad(s, cert)
    source = "<stdin>" if str(log) == "-" else str(log)
    if str(log) == "-":
        res = monitor_log(s, traj, tol, stdin if stdin is not None else sys.stdin, source=source)
    else:
        with open(log, encoding="utf-8", newline=None) as fh:
            res = monitor_log(s, traj, tol, fh, source=source)
    t2 = time.perf_counter()
    # monitor: wall-clock seconds of the stream; monitor_cpu: this process's CPU seconds in it.
    res.timings_s = {"certificate": t1 - t0, "monitor": t2 - t1,
                     "monitor_cpu": time.process_time() - c1}
    rate = res.samples / (t2 - t1) if t2 > t1 else float("inf")
    print(f"monitor   {res.samples} samples of {source} against {traj_path} "
          f"(tolerance {tol:.6f} rad): {res.status}, {res.outside} outside "
          f"({rate:,.0f} samples/s)")
    if res.first is not None:
        f = res.first
        kind = (f"IN CONTACT ({f['links_text']})" if f["in_contact"] else
                "not in contact, outside the certified tube")
        print(f"first     outside at t={f['t_s']!r} s (line {f['line']}): {f['joint']} off by "
              f"{f['deviation_rad']:.6g} rad; {kind}", file=sys.stderr)
    doc = monitor_json(s, traj, tol, res, source)
    if json_out is not None:
        write_bytes_atomic(json_out, dumps_json(doc).encode())
        print(f"wrote     {json_out}")
    return 0 if res.outside == 0 else 1


# --- simulate ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Excursion:
    """Add ``rad`` to ``joint`` during [t_s, t_s + duration_s]."""

    t_s: float
    joint: str
    rad: float
    duration_s: float = 0.05


def parse_excursion(text: str) -> Excursion:
    """T:JOINT:RAD[:DURATION] (seconds, a column name, radians, seconds)."""
    parts = text.split(":")
    if len(parts) not in (3, 4):
        raise InputError("--excursion", text, "must be T:JOINT:RAD[:DURATION]")
    joint = parts[1]
    if joint not in TRAJECTORY_COLUMNS[1:]:
        raise InputError("--excursion", text,
                         f"names no joint ({', '.join(TRAJECTORY_COLUMNS[1:])})")
    try:
        nums = [float(x) for x in (parts[0], parts[2], *parts[3:])]
    except ValueError:
        raise InputError("--excursion", text,
                         "must be T:JOINT:RAD[:DURATION] with numbers") from None
    if not all(math.isfinite(x) for x in nums) or (len(nums) == 3 and nums[2] < 0):
        raise InputError("--excursion", text, "needs finite numbers and DURATION >= 0")
    return Excursion(nums[0], joint, nums[1], *(nums[2:]))


def simulate_log(traj: Trajectory, *, lag: float = 0.0, noise: float = 0.0, seed: int = 0,
                 excursions: Sequence[Excursion] = (), period: float | None = None,
                 samples: int | None = None, tail: float = 0.0) -> tuple[FloatArray, FloatArray]:
    """(t, angles): samples from t_0 to t_end + tail, every ``period`` s (default 1 ms) or
    ``samples`` of them evenly; measured = trajectory(t - lag) + uniform noise in
    [-noise, noise] per joint (seeded), plus the excursions."""
    if lag < 0 or noise < 0 or tail < 0:
        raise InputError("--lag/--noise/--tail", (lag, noise, tail), "must be >= 0")
    t0, t1 = float(traj.t[0]), float(traj.t[-1]) + tail
    if samples is not None:
        if samples < 1:
            raise InputError("--samples", samples, "must be >= 1")
        t = t0 + (t1 - t0) * np.arange(samples) / max(samples - 1, 1) if samples > 1 else (
            np.array([t0]))
    else:
        p = 0.001 if period is None else period
        if not p > 0:
            raise InputError("--period", p, "must be > 0")
        t = t0 + p * np.arange(int(math.floor((t1 - t0) / p + 1e-9)) + 1)
    if len(t) > 1 and not np.all(np.diff(t) > 0):
        raise InputError("--samples", samples, "gives times that do not increase")
    rng = np.random.default_rng(seed)
    a = traj.at(t - lag)
    if noise > 0:
        a = a + rng.uniform(-noise, noise, size=a.shape)
    for e in excursions:
        q = TRAJECTORY_COLUMNS.index(e.joint) - 1
        on = (t >= e.t_s) & (t <= e.t_s + e.duration_s)
        a[on, q] += e.rad
    return t, a


def log_csv(t: FloatArray, a: FloatArray) -> bytes:
    buf = io.StringIO()
    buf.write(",".join(TRAJECTORY_COLUMNS) + "\n")
    np.savetxt(buf, np.column_stack([t, a]), fmt="%.17g", delimiter=",")
    return buf.getvalue().encode()


def run_simulate(scenario: Scenario | str | Path, traj_path: str | Path, out: str | Path, *,
                 lag: float = 0.0, noise: float = 0.0, seed: int = 0,
                 excursions: Sequence[Excursion] = (), period: float | None = None,
                 samples: int | None = None, tail: float = 0.0,
                 allow_speed: bool = False) -> int:
    """Write a simulated measured log of the trajectory to ``out`` (atomically); 0 on success."""
    s = _scenario(scenario)
    traj = load_trajectory(traj_path, s, allow_speed=allow_speed)
    t, a = simulate_log(traj, lag=lag, noise=noise, seed=seed, excursions=excursions,
                        period=period, samples=samples, tail=tail)
    write_bytes_atomic(out, log_csv(t, a))
    print(f"simulate  {len(t)} samples of {traj_path} (lag {lag:g} s, noise {noise:g} rad, seed "
          f"{seed}, {len(excursions)} excursion(s)) -> {out}")
    return 0
