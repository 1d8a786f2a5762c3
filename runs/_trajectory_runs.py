"""`cfmpa certify`, `cfmpa monitor` and `cfmpa simulate`: any planner's trajectory (docs/model.md §12).

certify: the continuous-time certificate of a trajectory file and its tolerance tube.
monitor: a measured joint log streamed (in blocks, constant memory) against the certified tube,
at its samples and, by ``spec.between_samples_bound``, at every instant between them.
simulate: a measured log from a tracking model (lag, bounded noise, seeded; injected excursions).

JSON outputs are byte-identical for the same inputs apart from ``timings_s``.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import math
import sys
import time
import warnings
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, TextIO

import numpy as np
import numpy.typing as npt

from ..errors import MISSING, InputError
from ..files import angle_text, bounded_lines, dumps_json, echo, write_bytes_atomic
from ..spec import (
    TRAJECTORY_COLUMNS,
    Certificate,
    ReferenceSpeeds,
    Scenario,
    StreamedReference,
    Trajectory,
    TrajectorySummary,
    WholeReference,
    between_samples_bound,
    certify_trajectory_file,
    certify_trajectory_rows,
    closest_links,
    contact_links_text,
    contact_parts,
    csv_column_order,
    load_scenario,
    load_trajectory,
    log_end_bound,
    row_blocks,
    tolerance_rad,
    trajectory_distances,
    trajectory_file_blocks,
    tube_lipschitz,
)
from ._limits import MAX_LOG_SAMPLES
from ._rosbag import (
    BagOptions,
    BagReading,
    bag_row_name,
    bag_rows,
    bag_sha256,
    bag_trajectory_rows,
    is_bag,
    load_bag_trajectory,
    log_output_kind,
    write_bag,
)

__all__ = ["AFTER_LOG", "BEFORE_LOG", "BETWEEN_SAMPLES", "BLOCK_ROWS", "Excursion",
           "LISTED_UNOBSERVED", "MISSING_MESSAGES",
           "MonitorResult", "Unobserved",
           "certify_json", "log_csv", "monitor_json", "monitor_log", "monitor_rows",
           "parse_excursion", "parse_max_speed", "run_certify", "run_monitor", "run_simulate",
           "simulate_log"]


#: Log rows parsed per numpy block by the monitor ...
BLOCK_ROWS = 16_384
#: ... and at most this many characters of them (lines of up to 64 KiB each would otherwise
#: make a block of 1 GiB).
BLOCK_CHARS = 8 * 1024 * 1024
FloatArray = npt.NDArray[np.float64]
#: The trajectory as the monitor reads it: held whole, or streamed a second time.
Reference = WholeReference | StreamedReference


def _scenario(s: Scenario | str | Path) -> Scenario:
    return s if isinstance(s, Scenario) else load_scenario(s)


def _sha256(path: str | Path) -> str:
    if is_bag(path):
        return bag_sha256(path)
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _bag_options(bag: BagOptions | None, *paths: str | Path) -> BagOptions:
    """The options a bag among ``paths`` is read with; --topic, --joints or --t0 given
    (``bag`` not None) when none is a bag is refused: they would be ignored."""
    if bag is not None and not any(str(p) != "-" and is_bag(p) for p in paths):
        raise InputError("--topic/--joints/--t0", MISSING, "apply to a ROS 2 bag only (a "
                         "folder with metadata.yaml, or a .mcap or .db3 file), and none was "
                         f"given ({', '.join(str(p) for p in paths)})")
    return BagOptions() if bag is None else bag


def _trajectory(path: str | Path, s: Scenario, allow_speed: bool, bag: BagOptions) -> Trajectory:
    """A trajectory file (CSV or JSON, ``spec.load_trajectory``) or a ROS 2 bag."""
    if is_bag(path):
        return load_bag_trajectory(path, s, bag, allow_speed=allow_speed)
    return load_trajectory(path, s, allow_speed=allow_speed)


def certify_json(s: Scenario, traj: Trajectory | TrajectorySummary, cert: Certificate,
                 timings: dict[str, float] | None = None,
                 sha256: str | None = None) -> dict[str, Any]:
    """The JSON of `cfmpa certify` (keys stable: add, never rename), of a trajectory or of what
    the streaming reader kept of it (``spec.TrajectorySummary``)."""
    info = traj if isinstance(traj, TrajectorySummary) else TrajectorySummary.of(traj, cert)
    contact = None
    if cert.contact is not None and cert.contact_detail is not None:
        d = cert.contact_detail
        k = d.step
        rows = info.contact_rows
        contact = {"t_s": d.t_s, "links": list(d.links), "links_text": contact_links_text(d.links),
                   "parts": contact_parts(d.links),
                   "left_angles_rad": list(d.left_angles_rad),
                   "right_angles_rad": list(d.right_angles_rad),
                   "row": None if k is None else k,
                   "line": None if k is None or rows is None else rows[0][1],
                   "segment": ("at rest after the last row" if k is None or rows is None else
                               f"rows {k}->{k + 1} (t {rows[0][0]!r}..{rows[1][0]!r} s)")}
    return {
        "scenario": s.name,
        "scenario_sha256": s.sha256,
        "trajectory": {"file": info.source, "sha256": sha256, "rows": info.rows,
                       "t_start_s": info.t_start_s, "t_end_s": info.t_end_s},
        "clear": cert.clear,
        "lower_bound_m": cert.lower_bound_m,
        "min_m": cert.min_clearance_m,
        "t_s": cert.t_min_s,
        "tolerance_rad": tolerance_rad(s, cert),
        # The same in degrees, and what it allows in mm: the most a deviation of tolerance_rad
        # in every joint moves the farthest point of either arm (L tolerance_rad).
        "tolerance_deg": math.degrees(tolerance_rad(s, cert)),
        "tolerance_farthest_point_mm": 1000 * tube_lipschitz(s) * tolerance_rad(s, cert),
        "tube_lipschitz_m_per_rad": tube_lipschitz(s),
        "intervals": cert.intervals,
        "samples": cert.samples,
        "max_depth_used": cert.max_depth_used,
        "contact": contact,
        "undecided": [list(iv) for iv in cert.undecided],
        "timings_s": {k: round(v, 6) for k, v in sorted((timings or {}).items())},
    }


def run_certify(scenario: Scenario | str | Path, traj_path: str | Path, *,
                json_out: str | Path | None = None, allow_speed: bool = False,
                bag: BagOptions | None = None, stdout: TextIO | None = None,
                stderr: TextIO | None = None) -> int:
    """Certify the trajectory file or ROS 2 bag (read with ``bag``), read and certified in one
    pass, memory independent of its rows (``spec.certify_trajectory_file``,
    ``spec.certify_trajectory_rows``: at most TRAJECTORY_ROWS rows); print the summary, the
    verdict and its details on ``stdout`` (default sys.stdout at call time; ``stderr`` is
    for errors only, which are raised: InputError, exit 2, nothing written); 0 clear, 1 not
    clear."""
    so = sys.stdout if stdout is None else stdout
    s = _scenario(scenario)
    opts = _bag_options(bag, traj_path)
    timings: dict[str, float] = {}
    if is_bag(traj_path):
        info, cert = certify_trajectory_rows(
            bag_trajectory_rows(traj_path, opts), s, source=str(traj_path),
            allow_speed=allow_speed, name_row=bag_row_name(opts), timings=timings)
        rows, t_start, t_end = info.rows, info.t_start_s, info.t_end_s
        doc = certify_json(s, info, cert, timings, _sha256(traj_path))
    else:
        info, cert, sha = certify_trajectory_file(traj_path, s, allow_speed=allow_speed,
                                                  timings=timings)
        rows, t_start, t_end = info.rows, info.t_start_s, info.t_end_s
        doc = certify_json(s, info, cert, timings, sha)
    print(f"trajectory {traj_path}: {rows} rows, t {t_start:.6g}..{t_end:.6g} s "
          f"(scenario {s.name})", file=so)
    sampled = (f"sampled minimum {cert.min_clearance_m * 1000:.6g} mm at t={cert.t_min_s:.6g} s "
               f"({cert.intervals} intervals)")
    if cert.clear:
        print(f"clearance clear: proved >= {cert.lower_bound_m * 1000:.6g} mm at every instant; "
              f"{sampled}", file=so)
        print(f"tolerance {doc['tolerance_rad']:.6f} rad ({doc['tolerance_deg']:.4g} deg) in "
              f"every joint (max norm), moving the farthest point of either arm by at most "
              f"{doc['tolerance_farthest_point_mm']:.3g} mm (L = "
              f"{doc['tube_lipschitz_m_per_rad']:.6g} m/rad)", file=so)
    elif doc["contact"] is not None:
        c = doc["contact"]
        where = "" if c["line"] is None else f" (line {c['line']})"
        print(f"clearance NOT CLEAR: contact at t={c['t_s']:.9g} s, {c['links_text']}, "
              f"{c['segment']}{where}; left angles "
              f"{', '.join(angle_text(a) for a in c['left_angles_rad'])}; right angles "
              f"{', '.join(angle_text(a) for a in c['right_angles_rad'])}", file=so)
    else:
        print(f"clearance NOT CLEAR: {len(cert.undecided)} interval(s) neither proved clear nor "
              f"in contact, first {cert.undecided[0]} s; {sampled}", file=so)
    if json_out is not None:
        write_bytes_atomic(json_out, dumps_json(doc).encode())
        print(f"wrote     {json_out}", file=so)
    return 0 if cert.clear else 1


# --- monitor ----------------------------------------------------------------------------------

#: Unobserved intervals the JSON lists (all are counted and summed).
LISTED_UNOBSERVED = 20
#: Why an interval is unobserved, by where it lies.
BEFORE_LOG = "before the log's first sample"
BETWEEN_SAMPLES = "between samples, the bound exceeds the tolerance"
AFTER_LOG = "after the log's last sample"
#: ... and where a message the bag declares was not read (monitor --allow-gaps).
MISSING_MESSAGES = "a message the bag declares was not read"


@dataclass(frozen=True)
class Unobserved:
    """Time no sample vouches for: [t_s, t_s + length_s]. ``line``: the log line of the sample
    it starts at (None before the first sample); ``why``: BEFORE_LOG, BETWEEN_SAMPLES or
    AFTER_LOG, the reason at its start."""

    t_s: float
    length_s: float
    line: int | None
    why: str

    def json(self) -> dict[str, Any]:
        return {"t_s": self.t_s, "length_s": self.length_s, "line": self.line, "why": self.why}


@dataclass
class MonitorResult:
    """What the monitor saw: counts, the first sample outside the tube, and what the samples
    vouch for between them (docs/model.md §12): the unobserved intervals (merged; counted,
    summed, the first LISTED_UNOBSERVED kept and the longest), the covered fraction of the
    trajectory's time and the largest gap between samples."""

    samples: int = 0
    outside: int = 0
    contacts: int = 0
    first: dict[str, Any] | None = None
    t_first_s: float | None = None
    t_last_s: float | None = None
    max_deviation_rad: float = 0.0
    max_gap_s: float = 0.0
    covered_fraction: float = 0.0
    unobserved_count: int = 0
    unobserved_s: float = 0.0
    unobserved_in_span_s: float = 0.0
    unobserved: list[Unobserved] = field(default_factory=list)
    longest_unobserved: Unobserved | None = None
    max_speed_rad_s: tuple[float, ...] = ()
    missing_messages: int = 0
    timings_s: dict[str, float] = field(default_factory=dict)

    @property
    def status(self) -> str:
        """``outside`` (a sample outside the tube), else ``unobserved`` (some time no sample
        vouches for), else ``inside`` (the bound within the tube at every instant)."""
        if self.outside:
            return "outside"
        return "unobserved" if self.unobserved_count else "inside"

    def clear_unobserved(self) -> None:
        """Forget the unobserved intervals recorded (one covering everything replaces them)."""
        self.unobserved_count, self.unobserved_s, self.unobserved_in_span_s = 0, 0.0, 0.0
        self.unobserved, self.longest_unobserved = [], None

    def _record(self, u: Unobserved, span: tuple[float, float]) -> None:
        self.unobserved_count += 1
        self.unobserved_s += u.length_s
        self.unobserved_in_span_s += max(0.0, min(u.t_s + u.length_s, span[1]) -
                                         max(u.t_s, span[0]))
        if len(self.unobserved) < LISTED_UNOBSERVED:
            self.unobserved.append(u)
        if self.longest_unobserved is None or u.length_s > self.longest_unobserved.length_s:
            self.longest_unobserved = u


@dataclass
class _Open:
    """The unobserved interval being extended: from ``start`` to ``end`` so far."""

    start: float
    end: float
    line: int | None
    why: str

    def closed(self) -> Unobserved:
        return Unobserved(self.start, self.end - self.start, self.line, self.why)


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
            raise InputError("row", echo(line.strip()),
                             f"must have {len(TRAJECTORY_COLUMNS)} values, has {len(fields)}",
                             source=source, line=no)
        vals = []
        for name, i in zip(TRAJECTORY_COLUMNS, order):
            try:
                v = float(fields[i])
            except ValueError:
                raise InputError(name, echo(fields[i].strip()), "must be a number",
                                 source=source, line=no) from None
            if not math.isfinite(v):
                raise InputError(name, v, "must be finite", source=source, line=no)
            vals.append(v)
        rows.append(vals)
    return np.asarray(rows, dtype=float).reshape(-1, len(TRAJECTORY_COLUMNS)), blank


def _blocks(lines: Iterator[str], rows: int) -> Iterator[list[str]]:
    """``lines`` in lists of ``rows`` lines, fewer where they reach BLOCK_CHARS characters."""
    block: list[str] = []
    size = 0
    for line in lines:
        block.append(line)
        size += len(line)
        if len(block) >= rows or size >= BLOCK_CHARS:
            yield block
            block, size = [], 0
    if block:
        yield block


def _default_max_speed(s: Scenario, top: FloatArray) -> FloatArray:
    """The scenario's omega, raised to the trajectory's top speed ``top`` where that is faster."""
    return np.maximum(np.array([*s.left.omega, *s.right.omega], dtype=float), top)


def parse_max_speed(text: str | None, s: Scenario,
                    traj: Trajectory | TrajectorySummary | Reference) -> FloatArray:
    """The robot's joint speed bound (4,) in JOINTS order, rad/s: ``--max-speed`` as one value
    for all joints or four comma-separated ones; without it the scenario's omega, raised to the
    trajectory's own top speed on a joint where that is faster (a robot tracking it is): of the
    trajectory held whole, or as its first reading found it (``TrajectorySummary``)."""
    if text is None:
        top = (ReferenceSpeeds.of(traj).top() if isinstance(traj, Trajectory) else
               np.asarray(traj.top_speed_rad_s, dtype=float)
               if isinstance(traj, TrajectorySummary) else traj.top())
        return _default_max_speed(s, top)
    parts = str(text).split(",")
    try:
        vals = [float(x) for x in parts]
    except ValueError:
        raise InputError("--max-speed", echo(text), "must be W or W1,W2,W3,W4 (rad/s, one per "
                         f"joint {','.join(TRAJECTORY_COLUMNS[1:])})") from None
    if len(vals) not in (1, 4) or not all(math.isfinite(v) and v >= 0 for v in vals):
        raise InputError("--max-speed", echo(text), "must be one or four finite speeds >= 0 "
                         f"(rad/s, joints {','.join(TRAJECTORY_COLUMNS[1:])})")
    return np.broadcast_to(np.array(vals, dtype=float), (4,)).copy()


def _csv_blocks(stream: Iterable[str], block_rows: int, source: str
                ) -> Iterator[tuple[int, FloatArray]]:
    """A CSV log's samples in blocks: (the first row's line, rows (K, 5) in COLUMNS order).
    InputError for an empty log, a bad header or row, a blank line that a sample follows, or a
    log with no samples."""
    it = iter(stream)
    header = next(it, None)
    if header is None or not header.strip():
        raise InputError("log", MISSING, "is empty (needs the header "
                         f"{','.join(TRAJECTORY_COLUMNS)} and at least one sample)",
                         source=source, line=1)
    order = csv_column_order(header, source)
    no = 1                                            # lines read so far
    blank: int | None = None
    samples = 0
    for block in _blocks(it, block_rows):
        start = no + 1
        no += len(block)
        arr, trailing = _parse_rows(block, start, order, source)
        if blank is not None and len(arr):
            raise InputError("row", "", "is blank (samples must follow one another)",
                             source=source, line=blank)
        if trailing is not None and blank is None:
            blank = trailing
        if len(arr):
            samples += len(arr)
            yield start, arr
    if samples == 0:
        raise InputError("log", MISSING, "has no samples (only a header)", source=source,
                         line=no)


def monitor_log(s: Scenario, traj: Trajectory | Reference, tol: float, stream: Iterable[str], *,
                source: str = "<log>", block_rows: int = BLOCK_ROWS,
                max_speed: npt.ArrayLike | None = None) -> MonitorResult:
    """``monitor_rows`` of a CSV log's lines (``stream``): its header, then ``block_rows``
    lines parsed at a time (constant memory); blank lines may only end the log."""
    return monitor_rows(s, traj, tol, _csv_blocks(stream, block_rows, source), source=source,
                        max_speed=max_speed)


def _end_reach(d: FloatArray, h: float, w_robot: FloatArray, w_ref: FloatArray,
               tol: float) -> float:
    """How far (s, at most ``h``) from a sample with deviations ``d`` (4,), on the side where
    the log has no further sample, ``spec.log_end_bound`` stays within ``tol`` for every joint:
    ``h`` when it does over all of it, else the least (tol - d_q) / (w_robot_q + w_ref_q) (0 for
    a sample outside)."""
    if np.all(log_end_bound(d, h, w_robot, w_ref) <= tol):
        return h
    # The bound's inverse, then confirmed by the bound itself (a rounding step down at most).
    w = w_robot + w_ref
    room = np.maximum(tol - d, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        each = np.where(w > 0, room / np.where(w > 0, w, 1.0), np.where(d <= tol, np.inf, 0.0))
    reach = min(float(each.min()), h)
    for _ in range(4):
        if np.all(log_end_bound(d, reach, w_robot, w_ref) <= tol):
            return reach
        reach = float(np.nextafter(reach, 0.0))
    return 0.0


def monitor_rows(s: Scenario, traj: Trajectory | Reference, tol: float,
                 blocks: Iterable[tuple[int, FloatArray]], *, source: str = "<log>",
                 max_speed: npt.ArrayLike | None = None,
                 reading: BagReading | None = None) -> MonitorResult:
    """Check the log against the tube of radius ``tol`` around ``traj``, at every instant.

    At a sample: inside when each joint is within ``tol`` of the trajectory at its time (at
    rest before its first and after its last row). Between consecutive samples (docs/model.md
    §12): covered when ``between_samples_bound`` (from both ends' deviations, the gap, the
    robot's speed bound ``max_speed`` (4,), default ``parse_max_speed(None, ...)``, and the
    trajectory's speed on the gap) is within ``tol`` for every joint; a gap not covered is
    unobserved. The trajectory's time before the log's first sample and after its last is
    covered from that sample alone, as far as ``spec.log_end_bound`` (its deviation plus the
    two speeds times the distance to it) is within ``tol``, and unobserved beyond.
    ``blocks``: the samples as (the first one's line, rows (K, 5) in COLUMNS order), a CSV's
    (``monitor_log``) or a bag's (``bag_rows``); times must strictly increase. One block at a
    time (constant memory; the last sample is carried into the next block's first gap).
    ``reading``: a bag's, read with allow_gaps: where a declared message was not read, the
    time around it is unobserved, whatever the bounds (MISSING_MESSAGES). ``traj``: the
    trajectory held whole, or read a second time beside the log (``spec.StreamedReference``,
    the same numbers: `cfmpa monitor` holds neither file whole).
    """
    res = MonitorResult()
    ref = WholeReference(traj) if isinstance(traj, Trajectory) else traj
    w_robot = (_default_max_speed(s, ref.top()) if max_speed is None else
               np.broadcast_to(np.asarray(max_speed, dtype=float), (4,)).copy())
    res.max_speed_rad_s = tuple(float(x) for x in w_robot)
    span0, span1 = ref.span
    span_seen = False                                  # the instant span0 (a zero span)
    run: _Open | None = None

    def extend(a: float, b: float, line: int | None, why: str) -> None:
        nonlocal run
        if run is not None and run.end == a:           # contiguous with the open interval
            run.end = b
            return
        if run is not None:
            res._record(run.closed(), (span0, span1))
        run = _Open(a, b, line, why)

    prev_t = -math.inf
    prev_dev: FloatArray | None = None                # the last sample's deviation per joint
    prev_line = 0
    for start, arr in blocks:
        t = arr[:, 0]
        dtv = np.diff(np.concatenate([[prev_t], t]))
        bad = np.flatnonzero(~(dtv > 0))
        if len(bad):
            k = int(bad[0])
            before = prev_t if k == 0 else float(t[k - 1])
            raise InputError("t", float(t[k]), f"must be greater than the previous sample's time "
                             f"{before!r} (times strictly increase)", source=source,
                             line=start + k)
        res.t_last_s = float(t[-1])
        # The trajectory at the samples, and its speeds on the gaps from the previous sample
        # (from the trajectory's start, or the first sample, before the first block).
        first = prev_dev is None
        at, speeds = ref.block(min(span0, float(t[0])) if first else prev_t, t)
        dev = np.abs(arr[:, 1:] - at)
        if res.t_first_s is None:
            res.t_first_s = t1 = float(t[0])
            if reading is not None and reading.missing_first and t1 > span0:
                extend(span0, t1, None, MISSING_MESSAGES)
            elif t1 > span0:
                # Covered back from the first sample as far as the one-sided bound holds.
                reach = _end_reach(dev[0], t1 - span0, w_robot, speeds[0], tol)
                cut = t1 - reach
                if cut > span0:
                    extend(span0, cut, None, BEFORE_LOG)
                else:
                    span_seen = True
        worst = dev.max(axis=1)
        res.max_deviation_rad = max(res.max_deviation_rad, float(worst.max()))
        out = np.flatnonzero(worst > tol)
        span_seen = span_seen or bool(np.any((t == span0) & (worst <= tol)))
        # The gaps: from the previous block's last sample (if any) through this block's.
        if prev_dev is None:
            gt, gd, gl = t, dev, np.arange(start, start + len(t))
        else:
            gt = np.concatenate([[prev_t], t])
            gd = np.concatenate([prev_dev[None, :], dev])
            gl = np.concatenate([[prev_line], np.arange(start, start + len(t))])
        if len(gt) > 1:
            a, b = gt[:-1], gt[1:]
            h = b - a
            res.max_gap_s = max(res.max_gap_s, float(h.max()))
            bound = between_samples_bound(gd[:-1], gd[1:], h[:, None], w_robot[None, :],
                                          speeds[1:] if first else speeds)
            ok = np.all(bound <= tol, axis=1)
            # A gap a declared message was lost from (--allow-gaps) is not vouched for.
            lost = (np.isin(gl[1:], list(reading.gaps_before)) if reading is not None
                    and reading.gaps_before else np.zeros(len(ok), dtype=bool))
            ok &= ~lost
            span_seen = span_seen or bool(np.any(ok & (a <= span0) & (span0 <= b)))
            # Runs of uncovered gaps, each one interval (merged with the open one if they meet).
            nb = ~ok
            edges = np.diff(np.concatenate([[False], nb, [False]]).astype(np.int8))
            for r0, r1 in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
                extend(float(a[r0]), float(b[r1 - 1]), int(gl[r0]),
                       MISSING_MESSAGES if lost[r0] else BETWEEN_SAMPLES)
        prev_t, prev_dev, prev_line = float(t[-1]), dev[-1].copy(), start + len(t) - 1
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
                             "links": list(links), "links_text": contact_links_text(links),
                             "parts": contact_parts(links)}
            res.outside += len(out)
    if res.samples == 0:
        raise InputError("log", MISSING, "has no samples", source=source)
    if reading is not None and reading.missing_last and prev_t < span1:
        extend(prev_t, span1, prev_line, MISSING_MESSAGES)
    elif prev_t < span1 and prev_dev is not None:
        # Covered on from the last sample as far as the one-sided bound holds.
        reach = _end_reach(prev_dev, span1 - prev_t, w_robot,
                           ref.block(prev_t, np.array([span1]))[1][0], tol)
        cut = prev_t + reach
        if cut < span1:
            extend(max(cut, prev_t), span1, prev_line, AFTER_LOG)
        elif prev_t <= span0:
            span_seen = True
    if run is not None:
        res._record(run.closed(), (span0, span1))
    if reading is not None and reading.unplaced:
        # Declared messages not read, and no index says when: nothing is vouched for.
        res.clear_unobserved()
        res._record(Unobserved(span0, span1 - span0, None,
                               f"{reading.unplaced} message(s) the bag declares were not read, "
                               "and no message index says when"), (span0, span1))
        span_seen = False
    if reading is not None:
        res.missing_messages = reading.missing
    # The trajectory's time not unobserved is covered (by gaps whose bound is within the tube,
    # and sample instants); computed from the merged intervals, so blocks do not change it.
    res.covered_fraction = (max(0.0, 1.0 - res.unobserved_in_span_s / (span1 - span0))
                            if span1 > span0 else float(span_seen))
    return res


def monitor_json(s: Scenario, traj: Trajectory | Reference, tol: float, res: MonitorResult,
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
            "links_text": f["links_text"], "parts": f["parts"],
            "angles_rad": f["angles_rad"],
            "meaning": ("the sampled configuration is in contact" if f["in_contact"] else
                        "not in contact, but outside what the certificate covers")},
        "max_gap_s": res.max_gap_s,
        "covered_fraction": res.covered_fraction,
        "max_speed_rad_s": list(res.max_speed_rad_s),
        "missing_messages": res.missing_messages,
        "unobserved": None if not res.unobserved_count else {
            "count": res.unobserved_count, "total_s": res.unobserved_s,
            "first": res.unobserved[0].json(),
            "longest": None if res.longest_unobserved is None else res.longest_unobserved.json(),
            "listed": [u.json() for u in res.unobserved]},
        "timings_s": {k: round(v, 6) for k, v in sorted(res.timings_s.items())},
    }


def run_monitor(scenario: Scenario | str | Path, traj_path: str | Path, log: str | Path, *,
                json_out: str | Path | None = None, allow_speed: bool = False,
                stdin: IO[str] | None = None, max_speed: str | None = None,
                bag: BagOptions | None = None, allow_gaps: bool = False,
                stdout: TextIO | None = None, stderr: TextIO | None = None) -> int:
    """Monitor a measured log (a file, or ``-`` for standard input) against the certified tube
    at every instant: 0 inside, 1 some sample outside or some time unobserved (or the trajectory
    is not certified clear: no JSON then), 2 bad input (InputError). ``max_speed``: the
    robot's joint speed bound as ``--max-speed`` gives it (``parse_max_speed``). The log (and
    the trajectory) may be a ROS 2 bag, read with ``bag`` (``runs._rosbag``); a log bag with
    fewer messages than it declares is bad input unless ``allow_gaps`` (their time is then
    unobserved). The verdict and its details are printed on ``stdout`` (default sys.stdout at
    call time), one line each; ``stderr`` is for errors only, which are raised (InputError)."""
    so = sys.stdout if stdout is None else stdout
    s = _scenario(scenario)
    opts = _bag_options(bag, traj_path, log)
    in_bag = str(log) != "-" and is_bag(log)
    if allow_gaps and not in_bag:
        raise InputError("--allow-gaps", MISSING, f"applies to a ROS 2 bag log only, and --log "
                         f"{log} is none")
    t0 = time.perf_counter()
    # The trajectory is read twice, streamed (docs/model.md §12): certified first (its tube),
    # then beside the log; neither reading holds it whole. A pipe cannot be read twice.
    traj_p = Path(traj_path)
    if traj_p.exists() and not (traj_p.is_file() or is_bag(traj_p)):
        raise InputError("--traj", str(traj_path), "must be a regular file or a ROS 2 bag: the "
                         "monitor reads the trajectory twice (a pipe or a device can be read "
                         "once)")
    if is_bag(traj_path):
        info, cert = certify_trajectory_rows(
            bag_trajectory_rows(traj_path, opts), s, source=str(traj_path),
            allow_speed=allow_speed, name_row=bag_row_name(opts))
    else:
        info, cert, _ = certify_trajectory_file(traj_path, s, allow_speed=allow_speed)
    w_robot = parse_max_speed(max_speed, s, info)
    t1 = time.perf_counter()
    c1 = time.process_time()
    if not cert.clear:
        print(f"monitor   {traj_path} is not certified clear (run cfmpa certify): there is no "
              "tube to monitor", file=so)
        return 1
    tol = tolerance_rad(s, cert)
    with contextlib.ExitStack() as stack:
        blocks = (row_blocks(bag_trajectory_rows(traj_path, opts)) if is_bag(traj_path) else
                  stack.enter_context(trajectory_file_blocks(traj_path, s)))
        ref = StreamedReference(blocks, info)
        res, reading = _monitor_stream(s, ref, tol, log, opts, in_bag, w_robot, stdin,
                                       allow_gaps)
        ref.finish()
    source = "<stdin>" if str(log) == "-" else str(log)
    t2 = time.perf_counter()
    # monitor: wall-clock seconds of the stream; monitor_cpu: this process's CPU seconds in it.
    res.timings_s = {"certificate": t1 - t0, "monitor": t2 - t1,
                     "monitor_cpu": time.process_time() - c1}
    rate = res.samples / (t2 - t1) if t2 > t1 else float("inf")
    intervals = (f"{res.unobserved_count} interval(s), {res.unobserved_s:.6g} s in all")
    verdict = {"inside": "inside",
               "outside": f"outside ({res.outside} of {res.samples} samples)",
               "unobserved": f"unobserved ({intervals})"}[res.status]
    print(f"monitor   {res.samples} samples of {source} against {traj_path} "
          f"(tolerance {angle_text(tol)}): {verdict}; largest gap {res.max_gap_s:.6g} s, "
          f"{100 * res.covered_fraction:.4g}% of the trajectory's time covered "
          f"({rate:,.0f} samples/s)", file=so)
    _report(res, ref, tol, in_bag, opts, reading, log=source, out=so)
    doc = monitor_json(s, ref, tol, res, source)
    if json_out is not None:
        write_bytes_atomic(json_out, dumps_json(doc).encode())
        print(f"wrote     {json_out}", file=so)
    return 0 if res.status == "inside" else 1


def _monitor_stream(s: Scenario, ref: Reference, tol: float, log: str | Path, opts: BagOptions,
                    in_bag: bool, w_robot: FloatArray, stdin: IO[str] | None,
                    allow_gaps: bool) -> tuple[MonitorResult, BagReading]:
    """``monitor_rows`` of the log (a bag, standard input or a CSV file) against ``ref``."""
    source = "<stdin>" if str(log) == "-" else str(log)
    # Lines within LIMITS["line"] (docs/model.md §12): /dev/zero ends at its first line's limit.
    reading = BagReading()
    if in_bag:
        res = monitor_rows(s, ref, tol, bag_rows(log, opts, block_rows=BLOCK_ROWS,
                                                  reading=reading, allow_gaps=allow_gaps),
                           source=source, max_speed=w_robot, reading=reading)
    elif str(log) == "-":
        res = monitor_log(s, ref, tol, bounded_lines(stdin if stdin is not None else sys.stdin,
                                                      source), source=source, max_speed=w_robot)
    else:
        try:
            fh = open(log, "rb")
        except OSError as exc:
            raise InputError("log", MISSING, f"cannot be read ({exc.strerror or exc})",
                             source=source) from None
        with fh:
            res = monitor_log(s, ref, tol, bounded_lines(fh, source), source=source,
                              max_speed=w_robot)
    return res, reading


def _report(res: MonitorResult, ref: Reference, tol: float, in_bag: bool, opts: BagOptions,
            reading: BagReading, log: str, out: TextIO) -> None:
    """The monitor's detail lines, after its verdict: the first sample outside, the first time
    no sample vouches for, what a bag lacked, the --t0 hint."""
    intervals = (f"{res.unobserved_count} interval(s), {res.unobserved_s:.6g} s in all")

    # A bag's sample k stands at line k + 1 (its CSV's line); the user is told its message.
    def at(line: int) -> str:
        return f"message {line - 1} on {opts.topic}" if in_bag else f"line {line}"

    # The details, on the verdict's stream: the first sample outside, the first time no sample
    # vouches for, what a bag lacked.
    if res.first is not None:
        f = res.first
        kind = (f"IN CONTACT ({f['links_text']})" if f["in_contact"] else
                "not in contact, outside the certified tube")
        print(f"first     outside at t={f['t_s']!r} s ({at(f['line'])}): {f['joint']} off by "
              f"{angle_text(f['deviation_rad'])}; {kind}", file=out)
    if res.unobserved_count:
        u = res.unobserved[0]
        where = "" if u.line is None else f" ({at(u.line)})"
        print(f"first     unobserved from t={u.t_s!r} s for {u.length_s:.6g} s{where}: {u.why}"
              + ("" if res.status == "unobserved" else f" ({intervals})"), file=out)
    if in_bag and res.missing_messages:
        print(f"missing   {res.missing_messages} message(s) the bag declares on {opts.topic} "
              f"were not read (--allow-gaps): their time is unobserved", file=out)
    hint = _t0_hint(res, reading, ref.span[0]) if in_bag else None
    if hint is not None:
        print(f"hint      {hint}", file=out)


#: How far past the trajectory's start (s) a bag's first stamp must be, beyond the largest gap
#: between samples, for a log whose every sample is outside to suggest --t0.
T0_HINT_S = 1e-3


def _t0_hint(res: MonitorResult, reading: BagReading, start: float) -> str | None:
    """When every sample of a bag is outside and t counted from its first stamp (no --t0),
    which is well past the trajectory's start: the suggestion of --t0; else None."""
    if (res.samples == 0 or res.outside < res.samples or reading.t0_given
            or reading.first_ns is None):
        return None
    first = reading.first_ns / 1e9
    past = first - start
    if past <= T0_HINT_S + res.max_gap_s:
        return None
    return (f"every sample is outside, and t counts from the bag's first stamp, {first:.9g} s, "
            f"{past:.6g} s past the trajectory's start at {start:.6g} s: if the log "
            "began after the trajectory did, give --t0 the stamp at its start (--t0 0 when "
            "the stamps are on the trajectory's clock)")


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
    """(t, angles): samples from t_0 to t_end + tail (both included), every ``period`` s
    (default 1 ms; the last gap shorter when the span is not a multiple) or ``samples`` of them
    evenly; measured = trajectory(t - lag) + uniform noise in
    [-noise, noise] per joint (seeded), plus the excursions."""
    if lag < 0 or noise < 0 or tail < 0:
        raise InputError("--lag/--noise/--tail", (lag, noise, tail), "must be >= 0")
    t0, t1 = float(traj.t[0]), float(traj.t[-1]) + tail
    if samples is not None:
        if samples < 1:
            raise InputError("--samples", samples, "must be >= 1")
        if samples > MAX_LOG_SAMPLES:
            raise InputError("--samples", samples, f"must be at most {MAX_LOG_SAMPLES} (the "
                             f"simulated log's budget)")
        t = t0 + (t1 - t0) * np.arange(samples) / max(samples - 1, 1) if samples > 1 else (
            np.array([t0]))
    else:
        p = 0.001 if period is None else period
        if not p > 0:
            raise InputError("--period", p, "must be > 0")
        # Counted before np.arange allocates them: --period 1e-12 is 1e13 samples a second.
        count = math.floor((t1 - t0) / p + 1e-9) + 1 if math.isfinite(t1 - t0) else math.inf
        if count > MAX_LOG_SAMPLES:
            raise InputError("--period", p, f"gives {count:.4g} samples over {t1 - t0:g} s, more "
                             f"than the simulated log's budget of {MAX_LOG_SAMPLES}")
        t = np.minimum(t0 + p * np.arange(int(math.floor((t1 - t0) / p + 1e-9)) + 1), t1)
        # The last sample at t_end + tail exactly (the grid's last point may fall short of it,
        # by rounding or by a fraction of a period): a log that stops short is unobserved (§12).
        if t[-1] < t1:
            if t1 - t[-1] <= 1e-9 * (t1 - t0):
                t[-1] = t1
            else:
                t = np.append(t, t1)
    if len(t) > 1:
        t[-1] = t1
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
                 allow_speed: bool = False, bag: BagOptions | None = None,
                 stdout: TextIO | None = None, stderr: TextIO | None = None) -> int:
    """Write a simulated measured log of the trajectory to ``out`` (atomically): a ROS 2 bag
    (JointState on ``bag``'s topic and joint names, header.stamp = t to the nearest ns) when
    ``out`` ends in .mcap or .db3 (that storage file) or names a folder (``runs._rosbag.
    log_output_kind``: the rosbag2 layout), CSV otherwise; what was written on ``stdout``
    (default sys.stdout at call time; errors are raised, InputError); 0 on success."""
    so = sys.stdout if stdout is None else stdout
    s = _scenario(scenario)
    kind = log_output_kind(out)
    if bag is not None and kind == "csv":
        raise InputError("--topic/--joints", MISSING, f"apply to a bag only: --log-out {out} is "
                         "written as CSV (a bag is a name ending in .mcap or .db3, or a folder "
                         "ending in /)")
    traj = _trajectory(traj_path, s, allow_speed, BagOptions() if bag is None else bag)
    t, a = simulate_log(traj, lag=lag, noise=noise, seed=seed, excursions=excursions,
                        period=period, samples=samples, tail=tail)
    if kind == "csv":
        write_bytes_atomic(out, log_csv(t, a))
    else:
        write_bag(out, t, a, BagOptions() if bag is None else bag, kind=kind)
    what = {"csv": "CSV", "mcap": "ROS 2 bag, mcap", "db3": "ROS 2 bag, sqlite3",
            "folder": "ROS 2 bag folder, mcap"}[kind]
    print(f"simulate  {len(t)} samples of {traj_path} (lag {lag:g} s, noise {noise:g} rad, seed "
          f"{seed}, {len(excursions)} excursion(s))", file=so)
    print(f"wrote     {out} ({what})", file=so)
    return 0
