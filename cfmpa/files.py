"""Files in and out: atomic output (a temporary name in the same folder, then a rename over the
target) and bounded input (docs/model.md §3, §12): a line reader with a per-line limit and an
optional total, a whole-file reader with a size limit, the limits overridable by environment
variables, and echoed values cut to ECHO_CHARS characters."""

from __future__ import annotations

import enum
import hashlib
import io
import json
import math
import os
import stat
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, BinaryIO

import numpy as np

from .errors import MISSING, InputError

__all__ = ["ECHO_CHARS", "LIMITS", "JsonStyle", "Limit", "angle_text", "bounded_lines",
           "cause_text", "check_file_size", "dumps_json", "echo", "env_positive_int", "jsonable",
           "mm_text", "npy_bytes", "read_bounded", "save_npy_atomic", "write_atomic_with",
           "write_bytes_atomic", "write_json"]

#: An echoed value (a row, a field) longer than this in a message is cut to it.
ECHO_CHARS = 80


def env_positive_int(env: str, default: int, unit: str) -> int:
    """The environment variable ``env`` read as a positive integer (``unit`` names what it
    counts in the refusal), or ``default`` where it is not set; anything else is exit 2."""
    raw = os.environ.get(env)
    if raw is None:
        return default
    try:
        v = int(raw)
    except ValueError:
        v = 0
    if v < 1:
        raise InputError(env, echo(raw), f"must be a positive integer ({unit})")
    return v


@dataclass(frozen=True)
class Limit:
    """A size limit on input, in bytes: ``default`` unless the environment variable ``env`` sets
    it (a positive integer)."""

    env: str
    default: int
    what: str

    def value(self) -> int:
        return env_positive_int(self.env, self.default, "bytes")

    def words(self, v: int) -> str:
        return f"the limit of {v:,} bytes for {self.what} (environment variable {self.env})"


#: The input limits (docs/model.md §3, §12).
LIMITS = {
    "line": Limit("CFMPA_MAX_LINE_BYTES", 64 * 1024,
                  "a line of a scenario, trajectory CSV or log, its newline included"),
    "scenario": Limit("CFMPA_MAX_SCENARIO_BYTES", 1024 * 1024, "a scenario file"),
    "trajectory": Limit("CFMPA_MAX_TRAJECTORY_BYTES", 32 * 1024 * 1024, "a trajectory file"),
    # A plan.json holds the path and its cells' details: a few MB at the cell budget.
    "plan": Limit("CFMPA_MAX_PLAN_BYTES", 64 * 1024 * 1024, "a plan.json"),
    # Read a layer at a time in place (spec._layers), so the limit is no memory bound: at 36
    # bytes a cell it covers 0.95 G cells; a larger witness needs the variable raised (the cell
    # budget is 2 G cells: docs/model.md §3, §11).
    "witness": Limit("CFMPA_MAX_WITNESS_BYTES", 32 * 1024 * 1024 * 1024,
                     "a witness file and its arrays unpacked"),
}


class _Cut:
    """A value whose repr is cut to ECHO_CHARS characters (what a message echoes)."""

    def __init__(self, text: str) -> None:
        self.text = text

    def __repr__(self) -> str:
        return self.text


def echo(value: Any) -> Any:
    """``value`` itself if its repr has at most ECHO_CHARS characters, else a stand-in whose
    repr is the first ECHO_CHARS of it, then ``...``: a 100 MB row is not echoed whole."""
    text = repr(value)
    return value if len(text) <= ECHO_CHARS else _Cut(text[:ECHO_CHARS] + "...")


def mm_text(metres: float, digits: int = 6) -> str:
    """A length as a person reads it (docs/contributing.md, "Standards"): in mm, ``digits``
    significant digits."""
    return f"{metres * 1000:.{digits}g} mm"


def angle_text(rad: float, digits: int = 6) -> str:
    """An angle as a person reads it: in rad, with its degrees."""
    return f"{rad:.{digits}g} rad ({math.degrees(rad):.{min(digits, 4)}g} deg)"


def cause_text(exc: BaseException, chars: int = ECHO_CHARS) -> str:
    """A library's exception as the cause in a one-line message: its type and the first line of
    its text, cut to ``chars`` characters (a YAML parser's five lines, a 200-digit integer)."""
    lines = str(exc).strip().splitlines()
    text = lines[0].strip() if lines else ""
    if len(text) > chars:
        text = text[:chars] + "..."
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _too_long(source: str | None, line: int) -> InputError:
    lim = LIMITS["line"]
    return InputError("line", MISSING, f"is longer than {lim.words(lim.value())}",
                      source=source, line=line)


def _too_large(limit: Limit, cap: int, source: str | None, line: int | None) -> InputError:
    return InputError("file", MISSING, f"is larger than {limit.words(cap)}", source=source,
                      line=line)


def bounded_lines(stream: IO[bytes] | IO[str], source: str | None, *,
                  total: Limit | None = None) -> Iterator[str]:
    """The lines of ``stream`` as text ending in ``\n`` (``\r\n`` read as ``\n``; the last
    may have none), reading at most the line limit + 1 bytes at a time: a line longer than
    LIMITS["line"], more than ``total`` bytes in all, or bytes that are not UTF-8 raise
    InputError naming the line and the limit, with no more than a line's worth in memory.
    A text stream (standard input) is read through its buffer when it has one."""
    cap_line = LIMITS["line"].value()
    cap = None if total is None else total.value()
    raw_stream: Any = getattr(stream, "buffer", stream)
    read = 0
    no = 0
    while True:
        raw = raw_stream.readline(cap_line + 1)
        if not raw:
            return
        no += 1
        size = len(raw.encode("utf-8")) if isinstance(raw, str) else len(raw)
        if size > cap_line:
            raise _too_long(source, no)
        read += size
        if cap is not None and total is not None and read > cap:
            raise _too_large(total, cap, source, no)
        if isinstance(raw, bytes):
            try:
                text = raw.decode("utf-8")
            except UnicodeDecodeError:
                raise InputError("line", MISSING, "is not UTF-8 text", source=source,
                                 line=no) from None
        else:
            text = raw
        if text.endswith("\r\n"):
            text = text[:-2] + "\n"
        yield text


def check_file_size(path: str | os.PathLike[str], limit: Limit, source: str | None, *,
                    field: str = "file") -> None:
    """Refuse a regular file larger than ``limit`` (by its size, nothing read), and anything but
    a regular file (a device, a pipe: its size says nothing), with InputError."""
    try:
        st = os.stat(path)
    except OSError as exc:
        raise InputError(field, MISSING, f"cannot be read ({exc.strerror or exc})",
                         source=source) from None
    if not stat.S_ISREG(st.st_mode):
        raise InputError(field, MISSING, "must be a regular file", source=source)
    cap = limit.value()
    if st.st_size > cap:
        raise _too_large(limit, cap, source, None)


def read_bounded(path: str | os.PathLike[str], limit: Limit, source: str | None, *,
                 lines: bool = True, field: str = "file") -> bytes:
    """The whole file, read with at most ``limit`` + 1 bytes in memory: larger (a device such
    as /dev/zero, a file cut short of nothing) raises InputError naming the limit; with
    ``lines``, so does a line longer than LIMITS["line"] (the first, by its number), and a
    too-large file names the line the limit fell in."""
    cap = limit.value()
    try:
        with open(path, "rb") as fh:
            data = fh.read(cap + 1)
    except OSError as exc:
        raise InputError(field, MISSING, f"cannot be read ({exc.strerror or exc})",
                         source=source) from None
    if lines:
        cap_line = LIMITS["line"].value()
        start, no = 0, 1
        while True:
            end = data.find(b"\n", start)
            stop = len(data) if end < 0 else end + 1
            if stop - start > cap_line:
                raise _too_long(source, no)
            if end < 0:
                break
            start, no = end + 1, no + 1
    if len(data) > cap:
        raise _too_large(limit, cap, source, data.count(b"\n") + 1 if lines else None)
    return data


def write_atomic_with(path: str | os.PathLike[str], write: Callable[[BinaryIO], object], *,
                      digest: bool = False) -> tuple[Path, str | None]:
    """``write(fh)`` into a temporary file beside ``path``, flushed to disk, then renamed over
    it: ``path`` is either absent/old or complete, never half-written. With ``digest``, also the
    sha256 of the file as written, read back in chunks (a streamed file is never held whole)."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    sha = None
    try:
        # mkstemp makes the file private (0600); outputs are meant to be shared like any file.
        os.chmod(tmp, 0o644)
        with os.fdopen(fd, "w+b") as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
            if digest:
                fh.seek(0)
                h = hashlib.sha256()
                for chunk in iter(lambda: fh.read(1 << 20), b""):
                    h.update(chunk)
                sha = h.hexdigest()
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return target, sha


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` so that ``path`` is either absent/old or complete, never half-written."""
    return write_atomic_with(path, lambda fh: fh.write(data))[0]


class JsonStyle(enum.Enum):
    """The layouts of the JSON cfmpa writes; every one sorts its keys and ends in a newline, so
    the same data gives the same bytes. The value is json.dumps's indent (None: compact)."""

    #: A document (report.json, plan.json, results.json, compare.json): two-space indent.
    DOCUMENT = 2
    #: A pinned file reviewed as a diff (obligations.lock): one-space indent.
    LOCK = 1
    #: One record a line (a campaign's or batch's store): no spaces at all.
    LINE = None


def dumps_json(obj: Any, style: JsonStyle = JsonStyle.DOCUMENT, *, ascii_only: bool = True,
               allow_nan: bool = False) -> str:
    """The one JSON writer: ``obj`` in ``style``, keys sorted, a trailing newline.
    ``ascii_only``: non-ASCII characters as \\u escapes; ``allow_nan``: NaN and infinities
    written as JavaScript's names (not JSON) instead of refused with ValueError."""
    if style is JsonStyle.LINE:
        text = json.dumps(obj, sort_keys=True, separators=(",", ":"), ensure_ascii=ascii_only,
                          allow_nan=allow_nan)
    else:
        text = json.dumps(obj, indent=style.value, sort_keys=True, ensure_ascii=ascii_only,
                          allow_nan=allow_nan)
    return text + "\n"


def write_json(path: str | os.PathLike[str], obj: Any, style: JsonStyle = JsonStyle.DOCUMENT,
               *, ascii_only: bool = True, allow_nan: bool = False) -> Path:
    """``dumps_json``'s text written atomically (UTF-8) to ``path``."""
    return write_bytes_atomic(path, dumps_json(obj, style, ascii_only=ascii_only,
                                               allow_nan=allow_nan).encode("utf-8"))


def npy_bytes(array: np.ndarray) -> bytes:
    """The .npy file's bytes for ``array`` (what save_npy_atomic writes)."""
    buf = io.BytesIO()
    np.save(buf, array, allow_pickle=False)
    return buf.getvalue()


def save_npy_atomic(path: str | os.PathLike[str], array: np.ndarray) -> Path:
    return write_bytes_atomic(path, npy_bytes(array))


def jsonable(x: Any) -> Any:
    """``x`` as plain JSON values: tuples to lists, numpy scalars to Python numbers, keys to
    strings, a non-finite float to its repr, anything else to its str."""
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return repr(x)
    if x is None or isinstance(x, (bool, int, float, str)):
        return x
    return str(x)
