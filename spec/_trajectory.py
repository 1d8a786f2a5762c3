"""Timed trajectories of both arms (docs/model.md §12): files, their certificate and tolerance tube.

A trajectory is waypoints (t_k, left1, left2, right1, right2): seconds and radians, theta1
absolute and theta2 relative, as in the scenario file. Between rows the motion is linear in joint
space; before the first row both arms rest at it, after the last row at that one. Files: CSV with
the header ``t,left1,left2,right1,right2`` (any column order), one row per waypoint, or JSON
``{"t": [...], "left1": [...], ...}``.

The tolerance tube. If the certificate proves clearance c > 0 over every instant, every motion
whose four joint angles stay within delta (max norm) of the trajectory at every instant is also
contact-free whenever c > 2 L delta, with L = ``tube_lipschitz(s)``, the largest R_base + R_elbow
over both arms' links: a deviation of at most delta per joint moves each point of a link by at
most delta (R_base + R_elbow) (integrate the point velocity along the straight joint-space segment
between the two configurations; docs/model.md §12), so each arm's rectangles lie within L delta of
the planned ones in Hausdorff distance and the distance between the arms drops by at most
2 L delta. The obligation ``Tolerance.tube`` proves the lemma; ``tolerance_rad`` is the largest
delta on a 1e-6 rad grid with 2 L delta <= c - EPS.

Between samples (docs/model.md §12). A measured log shows the robot at sampled instants only. If
a joint moves at most w_x rad/s (the robot's speed bound) and the trajectory's joint at most w_r
on [t_k, t_k+1] (its speed there), the deviation d(t) = |x(t) - r(t)| at any instant of the gap
is at most ``between_samples_bound(d_k, d_k+1, h, w_x, w_r)`` = max(d_k, d_k+1) + (w_x + w_r) h / 2
with h = t_k+1 - t_k: by the triangle inequality d(t) <= d_k + (w_x + w_r)(t - t_k) and
d(t) <= d_k+1 + (w_x + w_r)(t_k+1 - t), and one of t - t_k, t_k+1 - t is at most h / 2. The
obligation ``Monitor.between_samples`` proves it with Z3 on this very function's terms.
"""

from __future__ import annotations

import contextlib
import hashlib
import itertools
import json
import math
import os
import stat
import time
from array import array
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, cast

import numpy as np
import numpy.typing as npt

from ..errors import MISSING, InputError
from ..files import LIMITS, bounded_lines, echo, env_positive_int, read_bounded
from ._arith import max_of
from ._certificate import (
    DEFAULT_BOUND_RATIO,
    DEFAULT_MAX_DEPTH,
    DEFAULT_MAX_INTERVALS,
    Certificate,
    ContactDetail,
    Prover,
    link_rects,
    link_speeds,
    part_distances,
)
from ._grid import EPS, Grid, exact_tf, left_angles
from ._kinematics import parts, reach
from ._polygon import polygon_distances
from ._scenario import ANGLE_TOLERANCE, Scenario

__all__ = ["COLUMNS", "JOINTS", "Trajectory", "csv_column_order", "load_trajectory",
           "parse_trajectory_csv", "parse_trajectory_json", "certify_trajectory",
           "executed_trajectory", "trajectory_csv", "tube_lipschitz", "tolerance_rad",
           "TOLERANCE_STEP_RAD", "SPEED_TOLERANCE", "trajectory_distances", "validate",
           "between_samples_bound", "ReferenceSpeeds", "CHUNK_ROWS", "TrajectorySummary",
           "certify_trajectory_file", "log_end_bound", "RowLimit", "TRAJECTORY_ROWS",
           "certify_trajectory_rows", "check_trajectory_size", "WholeReference",
           "StreamedReference", "row_blocks", "trajectory_file_blocks", "rows_digest"]

#: The file columns, in the order of ``Trajectory.angles`` after t.
COLUMNS = ("t", "left1", "left2", "right1", "right2")
#: The same, under the public name it has in ``cfmpa.spec``.
TRAJECTORY_COLUMNS = COLUMNS
JOINTS = COLUMNS[1:]
#: tolerance_rad is rounded down to a multiple of this.
TOLERANCE_STEP_RAD = 1e-6
#: A joint speed is refused when above omega * (1 + SPEED_TOLERANCE) (float rounding only).
SPEED_TOLERANCE = 1e-9
#: Rows read, validated and certified at a time (docs/model.md §12): what certify holds of a
#: trajectory file, whatever its length. A trajectory of at most this many rows is certified
#: in one part, exactly as one piece list (spec._certificate.Prover).
CHUNK_ROWS = 65_536
#: Configurations per call of the polygon distance: its temporaries are about 7 KiB a
#: configuration, and at 1024 they stay small enough to be reused rather than mapped afresh
#: (4096 spent a fifth of certify's CPU time in the kernel, measured on 10^5 rows).
DISTANCE_BATCH = 1_024

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class RowLimit:
    """A row budget of a streamed reader (docs/model.md §12): ``default`` rows unless the
    environment variable ``env`` sets it (a positive integer). A streamed reader holds a part at
    a time, so the budget bounds the time a run takes, not its memory."""

    env: str
    default: int
    what: str

    def value(self) -> int:
        return env_positive_int(self.env, self.default, "rows")

    def refusal(self, cap: int, source: str | None, line: int | None,
                field: str = "trajectory") -> InputError:
        """The one-line refusal of the row after the ``cap``-th: the limit and how to raise it."""
        return InputError(field, MISSING, f"has more than {cap:,} rows, the limit for {self.what} "
                          f"(set the environment variable {self.env} higher to read a longer "
                          "one)", source=source, line=line)


#: The rows a streamed trajectory reader takes (`cfmpa certify`, `cfmpa monitor --traj`; CSV or
#: bag): 10^8 rows are a 6.6 GB CSV and about half an hour of certify on one core.
TRAJECTORY_ROWS = RowLimit("CFMPA_MAX_TRAJECTORY_ROWS", 100_000_000, "a streamed trajectory")


@dataclass(frozen=True)
class Trajectory:
    """Waypoints: ``t`` (R,) strictly increasing, ``angles`` (R, 4) as JOINTS; ``lines`` the file
    line of each row (None for JSON or a computed trajectory); ``source`` the file name."""

    t: FloatArray
    angles: FloatArray
    source: str | None = None
    lines: tuple[int, ...] | None = None

    @property
    def rows(self) -> int:
        return len(self.t)

    def line(self, k: int) -> int | None:
        return None if self.lines is None else self.lines[k]

    def at(self, t: npt.ArrayLike) -> FloatArray:
        """The four joint angles at times ``t`` (at rest before the first, after the last row)."""
        t = np.asarray(t, dtype=float)
        if self.rows == 1:
            return np.broadcast_to(self.angles[0], (*t.shape, 4)).copy()
        k = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, self.rows - 2)
        return self._interp(t, k)

    def _interp(self, t: FloatArray, k: npt.NDArray[np.int64]) -> FloatArray:
        t0, t1 = self.t[k], self.t[k + 1]
        u = np.clip((t - t0) / (t1 - t0), 0.0, 1.0)[..., None]
        a0, a1 = self.angles[k], self.angles[k + 1]
        return a0 + u * (a1 - a0)


def _fail(field: str, value: Any, message: str, source: str | None, line: int | None) -> InputError:
    return InputError(field, value, message, source=source, line=line)


def csv_column_order(header: str, source: str | None = None) -> list[int]:
    """The field index of each of COLUMNS in a CSV header line (any order, exactly those five);
    InputError at line 1 otherwise."""
    if not header.strip():
        raise _fail("header", MISSING, f"must be the first line: {','.join(COLUMNS)}", source, 1)
    names = [x.strip() for x in header.strip().split(",")]
    for name in COLUMNS:
        if name not in names:
            raise _fail("header", echo(header.strip()), f"is missing the column {name!r} (need "
                        f"{','.join(COLUMNS)})", source, 1)
    if len(names) != len(COLUMNS) or len(set(names)) != len(names):
        raise _fail("header", echo(header.strip()), f"must have exactly the columns "
                    f"{','.join(COLUMNS)}", source, 1)
    return [names.index(c) for c in COLUMNS]


def _csv_rows(lines: Iterator[str], source: str | None) -> Iterator[tuple[int, list[float]]]:
    """(line number, the five values in COLUMNS order) for each row after the header (read
    from ``lines``); a malformed row or a blank line that a row follows raises InputError."""
    order = csv_column_order(next(lines, ""), source)
    blank: int | None = None                        # the first of blank lines not yet followed
    no = 1
    for line in lines:
        no += 1
        if not line.strip():
            blank = no if blank is None else blank
            continue
        if blank is not None:                       # trailing blank lines are no rows; others
            raise _fail("row", "", "is blank (rows must follow one another)", source, blank)
        yield no, _csv_values(line, order, source, no)


def _csv_values(line: str, order: list[int], source: str | None, no: int) -> list[float]:
    """The five values of a CSV row (file line ``no``) in COLUMNS order; InputError naming the
    first that is missing, no number or not finite."""
    fields = line.rstrip("\r\n").split(",")
    if len(fields) != len(COLUMNS):
        raise _fail("row", echo(line.strip()), f"must have {len(COLUMNS)} values, has "
                    f"{len(fields)}", source, no)
    vals = []
    for name, i in zip(COLUMNS, order):
        try:
            v = float(fields[i])
        except ValueError:
            raise _fail(name, echo(fields[i].strip()), "must be a number", source,
                        no) from None
        if not math.isfinite(v):
            raise _fail(name, v, "must be finite", source, no)
        vals.append(v)
    return vals


#: CSV lines parsed at a time by ``_csv_row_blocks``.
PARSE_LINES = 1_024
#: A block of rows: their file lines and their values in COLUMNS order, (rows, 5).
RowBlock = tuple[Sequence[int], FloatArray]


def _csv_row_blocks(lines: Iterator[str], source: str | None, block: int = PARSE_LINES
                    ) -> Iterator[RowBlock]:
    """``_csv_rows``' rows, ``block`` lines at a time: (their file lines, their values (m, 5)).
    A block of rows alone (no blank line in it or pending) is parsed at once: one ``float``
    per field, the same conversion; any other block, or one whose parse fails, line by line as
    ``_csv_rows`` does, its good rows given before its error is raised, so that the same error
    comes out after the same rows (a row budget counts them first)."""
    order = csv_column_order(next(lines, ""), source)
    blank: int | None = None
    no = 1
    width = len(COLUMNS)
    while True:
        batch = list(itertools.islice(lines, block))
        if not batch:
            return
        if blank is None and all(map(str.strip, batch)):
            text = "".join(batch).replace("\n", ",")
            fields = text[:-1].split(",") if text.endswith(",") else text.split(",")
            if len(fields) == width * len(batch) and list(map(str.count, batch, itertools.repeat(
                    ","))).count(width - 1) == len(batch):
                try:
                    arr = np.array(list(map(float, fields)), dtype=float).reshape(-1, width)
                except ValueError:
                    arr = None
                if arr is not None and np.all(np.isfinite(arr)):
                    yield range(no + 1, no + 1 + len(batch)), arr[:, order]
                    no += len(batch)
                    continue
        rows: list[list[float]] = []
        nos: list[int] = []
        error: InputError | None = None
        for line in batch:
            no += 1
            if not line.strip():
                blank = no if blank is None else blank
                continue
            try:
                if blank is not None:
                    raise _fail("row", "", "is blank (rows must follow one another)", source,
                                blank)
                rows.append(_csv_values(line, order, source, no))
            except InputError as exc:
                error = exc
                break
            nos.append(no)
        if nos:
            yield nos, np.array(rows, dtype=float).reshape(-1, width)
        if error is not None:
            raise error


def parse_trajectory_csv(text: str | Iterable[str], s: Scenario, *, source: str | None = None,
                         allow_speed: bool = False,
                         name_row: Callable[[int], str] | None = None) -> Trajectory:
    """A CSV trajectory (its text, or its lines as ``files.bounded_lines`` streams them),
    validated (``validate``); errors name the file and line, echoing at most ECHO_CHARS of a
    value. Rows are kept as doubles only (8 bytes a value), not as text. ``name_row``: how a
    failed check names row k (1-based) instead of its line (a bag's "message k on TOPIC":
    the lines are then the CSV's the bag stands for, no line of the bag's own)."""
    lines = iter(text.splitlines() if isinstance(text, str) else text)
    vals: array[float] = array("d")
    where: list[int] = []
    for no, row in _csv_rows(lines, source):
        vals.extend(row)
        where.append(no)
    if not where:
        raise _fail("trajectory", MISSING, "must have at least one row", source, 1)
    arr = np.frombuffer(vals, dtype=float).reshape(-1, len(COLUMNS))
    traj = Trajectory(arr[:, 0].copy(), arr[:, 1:].copy(), source, tuple(where))
    validate(traj, s, allow_speed=allow_speed, name_row=name_row)
    return traj


def parse_trajectory_json(doc: Any, s: Scenario, *, source: str | None = None,
                          allow_speed: bool = False) -> Trajectory:
    """A JSON trajectory ``{"t": [...], "left1": [...], ...}``, validated (``validate``)."""
    if not isinstance(doc, dict):
        raise _fail("trajectory", type(doc).__name__, "must be a JSON object of columns", source,
                    None)
    cols = []
    for name in COLUMNS:
        if name not in doc:
            raise _fail(name, MISSING, "is a missing column", source, None)
        col = doc[name]
        if not isinstance(col, list):
            raise _fail(name, type(col).__name__, "must be a list of numbers", source, None)
        for k, v in enumerate(col):
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise _fail(f"{name}[{k}]", echo(v), "must be a number", source, None)
            if not math.isfinite(float(v)):
                raise _fail(f"{name}[{k}]", v, "must be finite", source, None)
        cols.append([float(v) for v in col])
    extra = sorted(set(doc) - set(COLUMNS))
    if extra:
        raise _fail("trajectory", echo(extra),
                    f"has unknown keys (columns are {', '.join(COLUMNS)})", source, None)
    counts = {len(c) for c in cols}
    if len(counts) != 1:
        raise _fail("trajectory", {n: len(c) for n, c in zip(COLUMNS, cols)},
                    "columns must have the same count", source, None)
    if not cols[0]:
        raise _fail("trajectory", 0, "must have at least one row", source, None)
    arr = np.asarray(cols, dtype=float).T
    traj = Trajectory(arr[:, 0].copy(), arr[:, 1:].copy(), source, None)
    validate(traj, s, allow_speed=allow_speed)
    return traj


def load_trajectory(path: str | Path, s: Scenario, *, allow_speed: bool = False) -> Trajectory:
    """A trajectory file, held whole: JSON if it ends in .json (or its first line starts with
    ``{``), else CSV. Bounded (docs/model.md §12): a regular file larger than
    LIMITS["trajectory"] is refused by its size before its first line is read; CSV is read line
    by line, each line within LIMITS["line"] (and, from a pipe or device, the bytes read within
    LIMITS["trajectory"]); JSON is read whole, within the latter. The streamed readers
    (``certify_trajectory_file``, ``certify_trajectory_rows``) have no byte limit."""
    p = Path(path)
    source = str(p)
    check_trajectory_size(p, source)
    with _csv_lines(p, source, whole=True) as csv:
        if csv is not None:
            return parse_trajectory_csv(csv.lines, s, source=source, allow_speed=allow_speed)
    data = read_bounded(p, LIMITS["trajectory"], source, lines=False, field="trajectory")
    return _parse_json_bytes(data, s, source, allow_speed)


def check_trajectory_size(p: Path, source: str) -> None:
    """Refuse a regular file larger than LIMITS["trajectory"] by its size, nothing read (what
    a reader holding the trajectory whole, or JSON, applies first); a pipe or a device has no
    size to check (its reader counts the bytes), and a file that cannot be read is left to the
    reader, which names why."""
    try:
        st = os.stat(p)
    except OSError:
        return
    lim = LIMITS["trajectory"]
    cap = lim.value()
    if stat.S_ISREG(st.st_mode) and st.st_size > cap:
        raise _fail("file", MISSING, f"is larger than {lim.words(cap)}, and a trajectory read "
                    "whole (JSON, or `cfmpa simulate`'s) is held in memory", source, None)


@dataclass(frozen=True)
class _CsvFile:
    """A trajectory file open as CSV: its bounded lines (the first included) and, when asked
    for, the reader that hashes the bytes the lines were read from."""

    lines: Iterator[str]
    hashing: _HashingReader | None


@contextlib.contextmanager
def _csv_lines(p: Path, source: str, *, hashing: bool = False,
               whole: bool = False) -> Iterator[_CsvFile | None]:
    """The trajectory file open as CSV, streamed line by line within LIMITS["line"] and, when
    read ``whole`` (held in memory), in all LIMITS["trajectory"]; None when it is JSON (it ends
    in .json, or its first line starts with ``{``), which the caller reads whole after the
    ``with`` (its size checked first: ``check_trajectory_size``). An unreadable file raises
    InputError naming it. Both readers (``load_trajectory``, ``certify_trajectory_file``) open
    and bound their file here, so they take a file for the same format and refuse it alike."""
    if p.suffix.lower() == ".json":
        yield None
        return
    try:
        fh = open(p, "rb")
    except OSError as exc:
        raise _fail("trajectory", MISSING, f"cannot be read ({exc.strerror or exc})", source,
                    None) from None
    with fh:
        reader = _HashingReader(fh) if hashing else None
        # cast: bounded_lines reads only readline(size) of a binary stream
        stream = cast(IO[bytes], reader) if reader is not None else fh
        lines = bounded_lines(stream, source, total=LIMITS["trajectory"] if whole else None)
        first = next(lines, "")
        yield (None if first.lstrip().startswith("{")
               else _CsvFile(itertools.chain([first], lines), reader))


def _parse_json_bytes(data: bytes, s: Scenario, source: str, allow_speed: bool) -> Trajectory:
    try:
        doc = json.loads(data.decode("utf-8"))
    except UnicodeDecodeError:
        raise _fail("trajectory", MISSING, "is not UTF-8 text", source, None) from None
    except json.JSONDecodeError as exc:
        raise _fail("JSON", echo(exc.msg), "is not valid JSON", source, exc.lineno) from None
    return parse_trajectory_json(doc, s, source=source, allow_speed=allow_speed)


def validate(traj: Trajectory, s: Scenario, *, allow_speed: bool = False,
             name_row: Callable[[int], str] | None = None) -> None:
    """Strictly increasing t; joint speeds within the scenario's omega (unless ``allow_speed``);
    the subordinate's angles within its limits. Raises InputError naming the sample once: its
    file line when it has one, else ``name_row(k)`` or "row k" (1-based)."""
    checks = _Checks(s, traj.source, allow_speed, name_row)
    checks.add(traj.t, traj.angles, traj.lines, 0)
    checks.raise_first()


class _Checks:
    """``validate`` over rows given in order, a block at a time: the first failure of each
    check is kept (the last row is carried into the next block's differences) and, at the end,
    the failure of the first check in validate's order wins (times, then right1's and right2's
    limits, then speeds), as if the rows had been validated at once."""

    def __init__(self, s: Scenario, source: str | None, allow_speed: bool,
                 name_row: Callable[[int], str] | None = None) -> None:
        self.s, self.source, self.allow_speed = s, source, allow_speed
        self.name_row = name_row
        self.failures: dict[int, InputError] = {}
        self.prev: tuple[float, FloatArray, int | None] | None = None
        self.omega = np.array([*s.left.omega, *s.right.omega])

    def _fail(self, field: str, row: int, line: int | None, value: Any,
              message: str) -> InputError:
        """A failure of row ``row`` (1-based), naming the sample once: by its file line when it
        has one (and no ``name_row``), else in the field ("right1 of message 3 on /topic",
        "right1 (row 3)")."""
        if self.name_row is not None:
            return _fail(f"{field} of {self.name_row(row)}", value, message, self.source, None)
        if line is not None:
            return _fail(field, value, message, self.source, line)
        return _fail(f"{field} (row {row})", value, message, self.source, None)

    def add(self, t: FloatArray, angles: FloatArray, lines: Iterable[int] | None,
            offset: int) -> None:
        """Rows ``offset`` .. ``offset + len(t) - 1`` (file lines ``lines``, or None)."""
        new_lines: list[int | None] = [None] * len(t) if lines is None else list(lines)
        fail = self.failures
        if self.prev is None:
            tt, aa, ll, base = t, angles, new_lines, offset
        else:
            tt = np.concatenate([[self.prev[0]], t])
            aa = np.concatenate([self.prev[1][None, :], angles])
            ll, base = [self.prev[2], *new_lines], offset - 1
        dt = np.diff(tt)
        bad = np.flatnonzero(dt <= 0)
        if 0 not in fail and len(bad):
            j = int(bad[0]) + 1
            fail[0] = self._fail("t", base + j + 1, ll[j], float(tt[j]), f"must be greater than "
                                 f"the previous time {float(tt[j - 1])!r} (times strictly "
                                 "increase)")
        for q in range(2):
            lo, hi = self.s.right.limits[q]
            col = angles[:, 2 + q]
            out = np.flatnonzero((col < lo - ANGLE_TOLERANCE) | (col > hi + ANGLE_TOLERANCE))
            if 1 + q not in fail and len(out):
                k = int(out[0])
                fail[1 + q] = self._fail(JOINTS[2 + q], offset + k + 1, new_lines[k],
                                         float(col[k]), "must lie within the subordinate's "
                                         f"limits [{lo!r}, {hi!r}]")
        # After a time failure (which wins) a speed is no number: dt <= 0.
        if 0 not in fail and 3 not in fail and not self.allow_speed and len(tt) > 1:
            omega = self.omega
            speed = np.abs(np.diff(aa, axis=0)) / dt[:, None]
            over = speed > omega[None, :] * (1.0 + SPEED_TOLERANCE)
            if np.any(over):
                j, q = (int(x) for x in np.argwhere(over)[0])
                unit = "message" if self.name_row is not None else "row"
                fail[3] = self._fail(
                    f"{JOINTS[q]} speed", base + j + 2, ll[j + 1], MISSING,
                    f"is {float(speed[j, q])!r} rad/s from the previous {unit}, above its omega "
                    f"of {float(omega[q])!r} rad/s (--allow-speed certifies it anyway)")
        if len(t):
            self.prev = (float(t[-1]), angles[-1].copy(), new_lines[-1])

    @property
    def failed(self) -> bool:
        return bool(self.failures)

    def raise_first(self) -> None:
        if self.failures:
            raise self.failures[min(self.failures)]


def executed_trajectory(s: Scenario, g: Grid, path: Any) -> Trajectory:
    """The certificate's executed motion of a grid path as waypoints: one row per step k dt,
    k = 0 .. max(len - 1, ceil(Tf / dt)), plus a row at Tf when it falls inside a step."""
    cells = np.asarray([tuple(c) for c in path], dtype=np.int64)
    if len(cells) == 0:
        raise InputError("path", [], "must have at least one cell")
    dt, tf = g.dt, float(exact_tf(s))
    last = len(cells) - 1
    steps = max(last, math.ceil(tf / dt))
    # cast: numpy's stubs type an int array times a float as floating[Any]
    times = cast(FloatArray, np.arange(steps + 1, dtype=np.int64) * dt)
    if tf > 0 and not np.any(times == tf) and tf < times[-1]:
        times = np.sort(np.append(times, tf))
    right = np.stack([g.lo[0] + cells[:, 0] * g.h[0], g.lo[1] + cells[:, 1] * g.h[1]], axis=1)
    k = np.minimum(np.floor(times / dt + 1e-9).astype(np.int64), max(last - 1, 0))
    # At step times use the cells' own angles; at Tf (inside step k) interpolate as the
    # certificate does.
    on_step = np.isclose(times / dt, np.round(times / dt), rtol=0, atol=1e-9)
    idx = np.minimum(np.round(times / dt).astype(np.int64), last)
    ang_r = right[idx].copy()
    if last > 0:
        inside = ~on_step
        u = np.clip((times[inside] - k[inside] * dt) / dt, 0.0, 1.0)[:, None]
        ang_r[inside] = right[k[inside]] + u * (right[k[inside] + 1] - right[k[inside]])
    ang_l = left_angles(s, times)
    return Trajectory(times, np.concatenate([ang_l, ang_r], axis=1), None, None)


def trajectory_csv(traj: Trajectory) -> str:
    """The CSV text of ``traj`` (repr floats: reading it back gives the same doubles)."""
    out = [",".join(COLUMNS)]
    for t, a in zip(traj.t.tolist(), traj.angles.tolist()):
        out.append(",".join(repr(float(x)) for x in (t, *a)))
    return "\n".join(out) + "\n"


def tube_lipschitz(s: Scenario) -> float:
    """L: the largest R_base + R_elbow over both arms' parts (m/rad; links and tools): a max-norm
    joint deviation delta moves any point of any part by at most L delta."""
    return max(sum(reach(arm, link)) for arm in (s.left, s.right) for link in parts(arm))


def tolerance_rad(s: Scenario, cert: Certificate) -> float:
    """The certified tube's radius: the largest multiple of TOLERANCE_STEP_RAD with
    2 L delta <= c - EPS (so c > 2 L delta), c the proved clearance; 0.0 when not clear."""
    if not cert.clear or cert.lower_bound_m <= EPS:
        return 0.0
    two_l = 2.0 * tube_lipschitz(s)
    per = round(1 / TOLERANCE_STEP_RAD)
    k = math.floor((cert.lower_bound_m - EPS) / two_l * per)
    while k > 0 and two_l * (k / per) > cert.lower_bound_m - EPS:
        k -= 1
    return k / per


def log_end_bound(d: Any, h: Any, w_robot: Any, w_ref: Any) -> Any:
    """The largest deviation |x(t) - r(t)| of one joint at an instant t at most h from one
    sample with deviation d, on the side where the log has no further sample (before its first
    or after its last, docs/model.md §12): d + (w_robot + w_ref) h, by the triangle inequality
    |x(t) - r(t)| <= |x(t) - x_k| + d + |r_k - r(t)| from that end alone (the first of the two
    that ``between_samples_bound`` takes). Floats or numpy arrays (elementwise)."""
    return d + (w_robot + w_ref) * h


def between_samples_bound(d0: Any, d1: Any, h: Any, w_robot: Any, w_ref: Any) -> Any:
    """The largest deviation |x(t) - r(t)| of one joint at any instant t of a gap of length h
    between two samples with deviations d0, d1, when the robot's joint moves at most w_robot
    rad/s and the trajectory's at most w_ref on the gap (module docstring; the obligation
    Monitor.between_samples). Floats, numpy arrays (elementwise) or Z3 terms."""
    return max_of(d0, d1) + (w_robot + w_ref) * h / 2


@dataclass(frozen=True)
class ReferenceSpeeds:
    """The trajectory's joint speeds per piece of time: ``per_piece[j]`` (R + 1, 4) is the speed
    on the j-th piece, j = 0 before the first row (at rest, 0), j = k + 1 between rows k and
    k + 1 (|a_k+1 - a_k| / (t_k+1 - t_k)), j = R after the last row (at rest, 0)."""

    t: FloatArray
    per_piece: FloatArray

    @staticmethod
    def of(traj: Trajectory) -> ReferenceSpeeds:
        zero = np.zeros((1, 4))
        inner = (np.abs(np.diff(traj.angles, axis=0)) / np.diff(traj.t)[:, None]
                 if traj.rows > 1 else np.zeros((0, 4)))
        return ReferenceSpeeds(traj.t, np.concatenate([zero, inner, zero]))

    def top(self) -> FloatArray:
        """(4,): the largest speed of each joint over the whole trajectory."""
        return self.per_piece.max(axis=0)

    def over(self, a: FloatArray, b: FloatArray) -> FloatArray:
        """(G, 4): each joint's largest speed on [a_g, b_g] (a_g < b_g): over the pieces the
        interval meets. A gap within one or two pieces (the usual case) is one numpy step; a
        longer one is a slice each (gaps are disjoint, so the slices add up to R + 2 G)."""
        lo = np.searchsorted(self.t, a, side="right")         # the piece of a
        hi = np.searchsorted(self.t, b, side="left")          # the piece of the instant before b
        hi = np.maximum(hi, lo)
        out = np.maximum(self.per_piece[lo], self.per_piece[hi])
        for g in np.flatnonzero(hi - lo > 1):
            out[g] = self.per_piece[lo[g]:hi[g] + 1].max(axis=0)
        return out


class WholeReference:
    """A trajectory held whole as the monitor reads it (``block``): the reference that
    ``StreamedReference`` must equal, bit for bit."""

    def __init__(self, traj: Trajectory) -> None:
        self.traj, self.speeds = traj, ReferenceSpeeds.of(traj)
        self.source = traj.source
        self.span = (float(traj.t[0]), float(traj.t[-1]))

    def top(self) -> FloatArray:
        return self.speeds.top()

    def block(self, lo: float, t: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(the trajectory at times ``t`` (K,), sorted, (K, 4); each joint's largest speed
        (K, 4) on the K intervals between consecutive points of ``lo``, t_0, ..., t_K-1), with
        ``lo`` <= t_0 (``Trajectory.at``, ``ReferenceSpeeds.over``). Successive calls ask
        from no earlier than the last point of the previous one."""
        pts = np.concatenate([[lo], t])
        return self.traj.at(t), self.speeds.over(pts[:-1], pts[1:])

    def finish(self) -> None:
        """Nothing to check: the rows are the ones certified."""


class StreamedReference:
    """``WholeReference``'s ``block`` over a trajectory read a second time, in order, in blocks
    (t (m,), angles (m, 4)), holding a window of about ``window_rows`` rows whatever the
    trajectory's length (docs/model.md §12): the rows from the one before the earliest time
    still asked for on. Where one interval between two points asked for spans more rows than
    the window, the largest speed over its rows read so far is carried (a maximum, so the same
    number) and those rows are dropped. ``summary``: the first pass's (``certify_trajectory_rows``):
    the span, the top speeds, and the rows' count and digest, which ``finish`` checks this pass
    read again (InputError otherwise: the file changed between the passes)."""

    def __init__(self, blocks: Iterable[tuple[FloatArray, FloatArray]],
                 summary: TrajectorySummary, window_rows: int = 2 * CHUNK_ROWS) -> None:
        if window_rows < 4:
            raise ValueError("window_rows must be at least 4")
        self.blocks = iter(blocks)
        self.summary, self.window = summary, window_rows
        self.source = summary.source
        self.span = (summary.t_start_s, summary.t_end_s)
        self.wt: FloatArray = np.zeros(0)
        self.wa: FloatArray = np.zeros((0, 4))
        self.base = 0                                   # the window's first row in the whole
        self.eof = False
        self.read = 0
        self.digest = hashlib.sha256()
        self.peak_rows = 0                              # the largest window held (tests)

    def top(self) -> FloatArray:
        return np.asarray(self.summary.top_speed_rad_s, dtype=float)

    def _load(self) -> None:
        got = next(self.blocks, None)
        if got is None:
            self.eof = True
            return
        t, a = got
        rows_digest(t, a, self.digest)
        self.read += len(t)
        self.wt = np.concatenate([self.wt, t])
        self.wa = np.concatenate([self.wa, a])
        self.peak_rows = max(self.peak_rows, len(self.wt))

    def _drop(self, r: int) -> None:
        """Drop the window's rows before its row ``r``."""
        if r > 0:
            self.wt, self.wa = self.wt[r:], self.wa[r:]
            self.base += r

    def _window(self) -> tuple[Trajectory, ReferenceSpeeds]:
        """The window as a trajectory of its own, and its speeds (``ReferenceSpeeds.of``: piece
        j between its rows j - 1 and j, the whole's piece base + j; its pieces 0 and n, at rest,
        are the whole's only when the window starts at row 0, or ends at the last row)."""
        window = Trajectory(self.wt, self.wa)
        return window, ReferenceSpeeds.of(window)

    def block(self, lo: float, t: FloatArray) -> tuple[FloatArray, FloatArray]:
        """As ``WholeReference.block``, the same numbers."""
        t = np.asarray(t, dtype=float)
        k_all = len(t)
        pts = np.concatenate([[lo], t])
        at = np.empty((k_all, 4))
        over = np.empty((k_all, 4))
        if not len(self.wt) and not self.eof:
            self._load()
        # The rows before the one at or before lo are asked for no more.
        n = len(self.wt)
        self._drop(max(min(int(np.searchsorted(self.wt, lo, side="right")) - 1, n - 2), 0))
        carry: FloatArray | None = None     # the largest speed on dropped pieces of the open gap
        i = 0                               # pts[i] answered (lo first); pts[i + 1:] pending
        while i < k_all:
            while not self.eof and len(self.wt) < self.window and (
                    len(self.wt) < 2 or self.wt[-1] <= pts[-1]):
                self._load()
            if not len(self.wt):            # the second reading gave no rows at all
                self.finish()
            if self.eof and self.base + len(self.wt) == 1:      # one row: at rest there
                at[i:] = self.wa[0]
                over[i:] = 0.0
                return at, over
            end = math.inf if self.eof else float(self.wt[-1])
            j = i + 1 + int(np.searchsorted(pts[i + 1:], end, side="left"))
            if j > i + 1:                   # pts[i + 1 .. j - 1] lie before the window's end
                self._answer(pts[i:j], carry, at[i:j - 1], over[i:j - 1])
                carry, i = None, j - 1
                continue
            carry = self._reduce(float(pts[i]), carry)
        return at, over

    def _answer(self, pts: FloatArray, carry: FloatArray | None, at: FloatArray,
                over: FloatArray) -> None:
        """The trajectory at ``pts[1:]`` and the speeds between consecutive ``pts``, all within
        the window, by the code that answers for the whole (``Trajectory.at``,
        ``ReferenceSpeeds.over``) run on the window: each point lies before the window's last
        row (or the window ends at the whole's), and after its first (or it starts at row 0),
        so the window's row and pieces are the whole's. ``carry``: the speeds of the dropped
        pieces of the first interval, whose pieces in the window start at its first row."""
        window, speeds = self._window()
        at[:] = window.at(pts[1:])
        a = pts[:-1].copy()
        if carry is not None:
            a[0] = self.wt[0]
        over[:] = speeds.over(a, pts[1:])
        if carry is not None:
            over[0] = np.maximum(over[0], carry)

    def _reduce(self, a: float, carry: FloatArray | None) -> FloatArray | None:
        """The window is full and the next point lies past it: keep its last two rows, and carry
        the largest speed of the pieces dropped from the interval starting at ``a``."""
        n = len(self.wt)
        keep = n - 2
        lo = 1 if carry is not None else int(np.searchsorted(self.wt, a, side="right"))
        if lo <= keep:
            seg = self._window()[1].per_piece[lo:keep + 1].max(axis=0)
            carry = seg if carry is None else np.maximum(carry, seg)
        self._drop(keep)            # else the interval starts on the last piece: nothing dropped
        return carry

    def finish(self) -> None:
        """Read the rest, and check the rows read again are the ones certified."""
        while not self.eof:
            self._drop(len(self.wt))
            self._load()
        if (self.read != self.summary.rows
                or self.digest.hexdigest() != self.summary.rows_sha256):
            raise _fail("trajectory", MISSING, f"changed while it was read: its second reading "
                        f"({self.read:,} rows) differs from the rows certified "
                        f"({self.summary.rows:,})", self.source, None)


def row_blocks(rows: Iterable[tuple[int, Iterable[float]]], block_rows: int = CHUNK_ROWS
               ) -> Iterator[tuple[FloatArray, FloatArray]]:
    """Rows given one at a time (as ``certify_trajectory_rows`` takes them) in blocks of
    ``block_rows``: (t (m,), angles (m, 4))."""
    vals: array[float] = array("d")
    n = 0
    for _, row in rows:
        vals.extend(row)
        n += 1
        if n >= block_rows:
            arr = np.frombuffer(vals, dtype=float).reshape(-1, len(COLUMNS))
            yield arr[:, 0].copy(), arr[:, 1:].copy()
            vals, n = array("d"), 0
    if n:
        arr = np.frombuffer(vals, dtype=float).reshape(-1, len(COLUMNS))
        yield arr[:, 0].copy(), arr[:, 1:].copy()


@contextlib.contextmanager
def trajectory_file_blocks(path: str | Path, s: Scenario, *, block_rows: int = CHUNK_ROWS
                           ) -> Iterator[Iterator[tuple[FloatArray, FloatArray]]]:
    """The rows of a trajectory file (``certify_trajectory_file``'s) read again, in blocks for
    ``StreamedReference``: a CSV streamed (no byte limit, each line bounded), a JSON read
    whole (its size within LIMITS["trajectory"]). Not validated again: ``finish`` checks they
    are the rows certified."""
    p = Path(path)
    source = str(p)
    with _csv_lines(p, source) as csv:
        if csv is not None:
            yield row_blocks(_csv_rows(csv.lines, source), block_rows)
            return
    check_trajectory_size(p, source)
    data = read_bounded(p, LIMITS["trajectory"], source, lines=False, field="trajectory")
    traj = _parse_json_bytes(data, s, source, allow_speed=True)
    yield iter([(traj.t, traj.angles)])


def trajectory_distances(s: Scenario, angles: FloatArray) -> FloatArray:
    """d[k, a, b]: distance (3-D, with the heights) between left part a and right part b at
    configurations (K, 4)
    (computed DISTANCE_BATCH configurations at a time: each is its own, so the batches change
    no value, only the temporaries' size)."""
    angles = np.asarray(angles, dtype=float).reshape(-1, 4)
    if len(angles) > DISTANCE_BATCH:
        return np.concatenate([trajectory_distances(s, angles[k:k + DISTANCE_BATCH])
                               for k in range(0, len(angles), DISTANCE_BATCH)])
    left = link_rects(s.left, angles[:, :2])
    right = link_rects(s.right, angles[:, 2:])
    return part_distances(s, polygon_distances(left[:, :, None], right[:, None, :]))


@dataclass(frozen=True)
class _TrajectoryMotion:
    """A part of a trajectory as the certificate's motion: its pieces between rows (``seg`` the
    row index in the whole trajectory; ``traj``'s first row is row ``offset``)."""

    scenario: Scenario
    traj: Trajectory
    offset: int = 0

    def pieces(self) -> tuple[FloatArray, FloatArray, npt.NDArray[np.int64], npt.NDArray[np.bool_]]:
        tr = self.traj
        if tr.rows == 1:
            z = np.full(1, tr.t[0])
            return z, z.copy(), np.full(1, -1, dtype=np.int64), np.zeros(1, dtype=bool)
        seg = np.arange(self.offset, self.offset + tr.rows - 1, dtype=np.int64)
        return tr.t[:-1].copy(), tr.t[1:].copy(), seg, np.ones(len(seg), dtype=bool)

    def lipschitz(self, seg: npt.NDArray[np.int64], moving: npt.NDArray[np.bool_]) -> FloatArray:
        tr = self.traj
        if tr.rows == 1:
            w = np.zeros((len(seg), 4))
        else:
            w = (np.abs(np.diff(tr.angles, axis=0)) / np.diff(tr.t)[:, None])[
                np.maximum(seg - self.offset, 0)]
            w = np.where(seg[:, None] >= 0, w, 0.0)
        vl = link_speeds(self.scenario.left, w[:, :2])
        vr = link_speeds(self.scenario.right, w[:, 2:])
        return vl[:, :, None] + vr[:, None, :]

    def angles(self, t: FloatArray, seg: npt.NDArray[np.int64]) -> FloatArray:
        tr = self.traj
        if tr.rows == 1:
            return np.broadcast_to(tr.angles[0], (len(t), 4))
        return np.where(seg[:, None] >= 0, tr._interp(t, np.maximum(seg - self.offset, 0)),
                        tr.angles[-1])

    def distances(self, t: FloatArray, seg: npt.NDArray[np.int64]) -> FloatArray:
        return trajectory_distances(self.scenario, self.angles(t, seg))

    def end_distances(self, t0: FloatArray, t1: FloatArray,
                      seg: npt.NDArray[np.int64]) -> tuple[FloatArray, FloatArray]:
        """``distances(t0, seg), distances(t1, seg)`` of consecutive pieces, each configuration
        computed once: where piece k's end (row k interpolated to u = 1) is bit for bit piece
        k + 1's start (row k + 1), its distances are the same numbers (trajectory_distances is
        one configuration's function), so they are copied instead of computed again."""
        a0, a1 = self.angles(t0, seg), self.angles(t1, seg)
        d0 = trajectory_distances(self.scenario, a0)
        d1 = np.empty_like(d0)
        same = np.zeros(len(a1), dtype=bool)
        if len(a1) > 1:
            bits0 = np.ascontiguousarray(a0).view(np.int64)
            bits1 = np.ascontiguousarray(a1).view(np.int64)
            same[:-1] = np.all(bits1[:-1] == bits0[1:], axis=1)
        d1[same] = d0[1:][same[:-1]]
        d1[~same] = trajectory_distances(self.scenario, a1[~same])
        return d0, d1

    def detail(self, contact: tuple[float, tuple[int, int]], seg: int) -> ContactDetail:
        t, links = contact
        a = self.angles(np.array([t]), np.array([seg], dtype=np.int64))[0]
        k = seg if seg >= 0 else None
        # No grid cells for a trajectory: ``cells`` holds the waypoint rows (k, k + 1). Only a
        # one-row trajectory has a piece at rest (seg -1), at its row 0.
        rows = (seg, seg + 1) if k is not None else (0, 0)
        return ContactDetail(t, links, (float(a[0]), float(a[1])), (float(a[2]), float(a[3])),
                             k, ((rows[0], rows[0]), (rows[1], rows[1])))


def _split(traj: Trajectory, chunk_rows: int) -> Iterator[tuple[Trajectory, int]]:
    """``traj`` in parts of ``chunk_rows`` rows (each after the first also has the previous
    part's last row, so that the pieces between parts are in one), with the row index of each
    part's first row: the parts the file reader gives (``_CsvParts``)."""
    if chunk_rows < 2:
        raise ValueError("chunk_rows must be at least 2")
    if traj.rows <= chunk_rows:
        yield traj, 0
        return
    for start in range(0, traj.rows, chunk_rows):
        lo = max(start - 1, 0)
        hi = min(start + chunk_rows, traj.rows)
        lines = None if traj.lines is None else traj.lines[lo:hi]
        yield Trajectory(traj.t[lo:hi], traj.angles[lo:hi], traj.source, lines), lo


#: A trajectory's motion under its public name (read on Z3 terms by the wiring obligations).
TrajectoryMotion = _TrajectoryMotion


@dataclass(frozen=True)
class TrajectorySummary:
    """What `cfmpa certify` reports of a trajectory it no longer holds: its file, row count and
    time span, and for a contact on the piece between rows k and k + 1 the (time, file line) of
    both rows (line None for JSON); and what `cfmpa monitor` needs before its second pass: each
    joint's top speed (``ReferenceSpeeds.top``, 0.0 for one row) and ``rows_sha256``, the
    SHA-256 of the rows' doubles in order (``rows_digest``), which that pass must read again."""

    source: str | None
    rows: int
    t_start_s: float
    t_end_s: float
    contact_rows: tuple[tuple[float, int | None], tuple[float, int | None]] | None = None
    top_speed_rad_s: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0)
    rows_sha256: str | None = None

    @staticmethod
    def of(traj: Trajectory, cert: Certificate) -> TrajectorySummary:
        d = cert.contact_detail
        k = None if d is None else d.step
        rows = None if k is None else ((float(traj.t[k]), traj.line(k)),
                                       (float(traj.t[k + 1]), traj.line(k + 1)))
        top = tuple(float(x) for x in ReferenceSpeeds.of(traj).top())
        return TrajectorySummary(traj.source, traj.rows, float(traj.t[0]), float(traj.t[-1]),
                                 rows, top, rows_digest(traj.t, traj.angles).hexdigest())


def rows_digest(t: FloatArray, angles: FloatArray, h: Any = None) -> Any:
    """``h`` (a new SHA-256 when None) updated with rows (t, angles) as doubles, row by row in
    COLUMNS order: the same digest however the rows are split into blocks."""
    h = hashlib.sha256() if h is None else h
    h.update(np.ascontiguousarray(np.column_stack([t, angles]), dtype=np.float64).tobytes())
    return h


class _Certifier:
    """Trajectory parts (in time order) certified as they come, keeping only the prover's
    aggregates, the row count, the time span and the contact's rows."""

    def __init__(self, s: Scenario, source: str | None, **caps: Any) -> None:
        self.s, self.source = s, source
        self.prover = Prover(first_contact=True, **caps)
        self.rows, self.t_start, self.t_end = 0, math.nan, math.nan
        self.contact_rows: tuple[tuple[float, int | None], tuple[float, int | None]] | None = None
        self.top = np.zeros(4)
        self.digest = hashlib.sha256()

    def add(self, part: Trajectory, offset: int) -> None:
        if part.rows > 1:           # ReferenceSpeeds.of's speeds, the same numbers
            self.top = np.maximum(self.top, (np.abs(np.diff(part.angles, axis=0))
                                             / np.diff(part.t)[:, None]).max(axis=0))
        if self.prover.add(_TrajectoryMotion(self.s, part, offset)):
            d = self.prover.detail
            k = None if d is None else d.step
            if k is not None:
                j = k - offset
                self.contact_rows = ((float(part.t[j]), part.line(j)),
                                     (float(part.t[j + 1]), part.line(j + 1)))

    def summary(self) -> TrajectorySummary:
        return TrajectorySummary(self.source, self.rows, self.t_start, self.t_end,
                                 self.contact_rows, tuple(float(x) for x in self.top),
                                 self.digest.hexdigest())


def certify_trajectory(s: Scenario, traj: Trajectory, *, max_depth: int = DEFAULT_MAX_DEPTH,
                       bound_ratio: float = DEFAULT_BOUND_RATIO,
                       max_intervals: int = DEFAULT_MAX_INTERVALS,
                       chunk_rows: int = CHUNK_ROWS) -> Certificate:
    """The continuous-time certificate (docs/model.md §7) of a trajectory, both arms from it.

    The pieces are the rows' intervals; a contact reported is the first one (to within a
    piece's length / 2^max_depth). ``contact_detail.step`` is the row index k of the piece
    [t_k, t_{k+1}] (None at rest after the last row). The pieces are decided ``chunk_rows``
    rows at a time (spec._certificate.Prover: one part, hence exactly one piece list, up to
    CHUNK_ROWS rows), as ``certify_trajectory_file`` does.
    """
    c = _Certifier(s, traj.source, max_depth=max_depth, bound_ratio=bound_ratio,
                   max_intervals=max_intervals)
    for part, offset in _split(traj, chunk_rows):
        c.add(part, offset)
    return c.prover.certificate()


class _HashingReader:
    """A binary file whose bytes, as ``readline`` returns them, go into a SHA-256 as well."""

    def __init__(self, fh: Any) -> None:
        self.fh, self.hash = fh, hashlib.sha256()

    def readline(self, size: int = -1) -> bytes:
        raw: bytes = self.fh.readline(size)
        self.hash.update(raw)
        return raw


def _blocks_of(rows: Iterable[tuple[int, Iterable[float]]], block: int = PARSE_LINES
               ) -> Iterator[RowBlock]:
    """Rows given one at a time as (file line, the five values in COLUMNS order) in blocks of
    ``block`` rows; a failure of ``rows`` is raised after the block of the rows before it."""
    it = iter(rows)
    while True:
        vals: array[float] = array("d")
        nos: list[int] = []
        error: Exception | None = None
        try:
            for no, row in itertools.islice(it, block):
                vals.extend(row)
                nos.append(no)
        except Exception as exc:        # the reader's own failure, raised below in its turn
            error = exc
        if nos:
            yield nos, np.frombuffer(vals, dtype=float).reshape(-1, len(COLUMNS))
        if error is not None:
            raise error
        if len(nos) < block:
            return


def _row_parts(blocks: Iterable[RowBlock], s: Scenario, source: str,
               allow_speed: bool, chunk_rows: int, c: _Certifier,
               name_row: Callable[[int], str] | None = None,
               ) -> Iterator[tuple[Trajectory, int]]:
    """The trajectory's validated parts as ``_split`` makes them, from its rows given in blocks
    of (file lines, the five values in COLUMNS order), ``chunk_rows`` rows at a time. A
    failure of the reader (a CSV row's parse, a blank line; a bag's message) raises at once, as
    the whole-file loader would; a validation failure stops the parts and is raised once every
    row is read (a later row's parse failure, or an earlier check, would win in ``validate``'s
    order); a row past the budget (TRAJECTORY_ROWS) raises at once, naming its line (or, with
    ``name_row``, how a failure names the row: a bag's "message k on TOPIC"). Counts rows and
    the time span into ``c``."""
    checks = _Checks(s, source, allow_speed, name_row)
    cap = TRAJECTORY_ROWS.value()
    prev: tuple[float, FloatArray, int] | None = None
    vals: array[float] = array("d")
    where: list[int] = []

    def flush() -> Iterator[tuple[Trajectory, int]]:
        nonlocal prev, vals, where
        arr = np.frombuffer(vals, dtype=float).reshape(-1, len(COLUMNS))
        c.digest.update(arr.tobytes())
        t, a = arr[:, 0].copy(), arr[:, 1:].copy()
        offset, lines_here = c.rows, where
        vals, where = array("d"), []
        if not c.rows:
            c.t_start = float(t[0])
        c.rows += len(t)
        c.t_end = float(t[-1])
        was_ok = not checks.failed
        checks.add(t, a, lines_here, offset)
        last = (float(t[-1]), a[-1].copy(), lines_here[-1])
        if was_ok and not checks.failed:
            if prev is None:
                yield Trajectory(t, a, source, tuple(lines_here)), offset
            else:
                yield (Trajectory(np.concatenate([[prev[0]], t]),
                                  np.concatenate([prev[1][None, :], a]), source,
                                  (prev[2], *lines_here)), offset - 1)
        prev = last

    for nos, block in blocks:
        i, m = 0, len(nos)
        while i < m:                                # row nos[i] is the next
            if c.rows + len(where) >= cap:
                raise TRAJECTORY_ROWS.refusal(cap, source,
                                              None if name_row is not None else nos[i])
            # the rows up to the budget (at least the one just admitted) and the part's end
            take = max(1, min(m - i, chunk_rows - len(where), cap - c.rows - len(where)))
            vals.frombytes(np.ascontiguousarray(block[i:i + take], dtype=float).tobytes())
            where.extend(nos[i:i + take])
            i += take
            if len(where) >= chunk_rows:
                yield from flush()
    if where:
        yield from flush()
    if not c.rows:
        raise _fail("trajectory", MISSING, "must have at least one row", source, 1)
    checks.raise_first()


def certify_trajectory_rows(rows: Iterable[tuple[int, Iterable[float]]], s: Scenario, *,
                            source: str, allow_speed: bool = False,
                            chunk_rows: int = CHUNK_ROWS,
                            name_row: Callable[[int], str] | None = None,
                            timings: dict[str, float] | None = None,
                            ) -> tuple[TrajectorySummary, Certificate]:
    """(summary, certificate) of a trajectory given row by row as (line, the five values in
    COLUMNS order), read, validated and certified ``chunk_rows`` rows at a time in one pass
    (docs/model.md §12): what is held does not grow with the rows; at most TRAJECTORY_ROWS of
    them. The certificate is ``certify_trajectory``'s of the same rows loaded whole, and the
    errors are the whole loader's, in the same order (``name_row`` as in
    ``parse_trajectory_csv``). ``timings`` gets the seconds spent reading (``load``, the rows'
    source included) and certifying (``certificate``)."""
    return _certify_blocks(_blocks_of(rows), s, source=source, allow_speed=allow_speed,
                           chunk_rows=chunk_rows, name_row=name_row, timings=timings)


def _certify_blocks(blocks: Iterable[RowBlock], s: Scenario, *, source: str,
                    allow_speed: bool = False, chunk_rows: int = CHUNK_ROWS,
                    name_row: Callable[[int], str] | None = None,
                    timings: dict[str, float] | None = None,
                    ) -> tuple[TrajectorySummary, Certificate]:
    """``certify_trajectory_rows`` of rows given in blocks (``_blocks_of``,
    ``_csv_row_blocks``)."""
    if chunk_rows < 2:
        raise ValueError("chunk_rows must be at least 2")
    tim = {"load": 0.0, "certificate": 0.0}
    c = _Certifier(s, source)
    parts = _row_parts(blocks, s, source, allow_speed, chunk_rows, c, name_row)
    t0 = time.perf_counter()
    while True:
        part = next(parts, None)
        t1 = time.perf_counter()
        tim["load"] += t1 - t0
        if part is None:
            break
        c.add(*part)
        t0 = time.perf_counter()
        tim["certificate"] += t0 - t1
    if timings is not None:
        timings.update(tim)
    return c.summary(), c.prover.certificate()


def certify_trajectory_file(path: str | Path, s: Scenario, *, allow_speed: bool = False,
                            chunk_rows: int = CHUNK_ROWS,
                            timings: dict[str, float] | None = None,
                            ) -> tuple[TrajectorySummary, Certificate, str]:
    """(summary, certificate, SHA-256 of the file's bytes) of a trajectory file, read and
    certified in one pass: a CSV ``chunk_rows`` rows at a time (``certify_trajectory_rows``),
    so what is held does not grow with the file, with no byte limit: each line within
    LIMITS["line"], at most TRAJECTORY_ROWS rows (docs/model.md §12); a JSON file is read whole
    (its size within LIMITS["trajectory"], checked before it is read) and certified in the same
    parts. Errors are those of ``load_trajectory``, in the same order (but for the limits); the
    certificate is ``certify_trajectory``'s of the loaded trajectory. ``timings`` gets the
    seconds spent reading (``load``) and certifying (``certificate``)."""
    if chunk_rows < 2:
        raise ValueError("chunk_rows must be at least 2")
    p = Path(path)
    source = str(p)
    t0 = time.perf_counter()
    with _csv_lines(p, source, hashing=True) as csv:
        if csv is not None and csv.hashing is not None:
            summary, cert = _certify_blocks(
                _csv_row_blocks(csv.lines, source), s, source=source, allow_speed=allow_speed,
                chunk_rows=chunk_rows, timings=timings)
            return summary, cert, csv.hashing.hash.hexdigest()
    check_trajectory_size(p, source)
    data = read_bounded(p, LIMITS["trajectory"], source, lines=False, field="trajectory")
    traj = _parse_json_bytes(data, s, source, allow_speed)
    t1 = time.perf_counter()
    cert = certify_trajectory(s, traj, chunk_rows=chunk_rows)
    if timings is not None:
        timings.update(load=t1 - t0, certificate=time.perf_counter() - t1)
    return TrajectorySummary.of(traj, cert), cert, hashlib.sha256(data).hexdigest()
