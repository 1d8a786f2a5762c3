"""An append-only JSON-lines store of finished work: what makes a campaign resumable.

Line 1 is a header (``format``, ``version``, ``settings``); every further line is one record, a
JSON object on one line. ``append`` writes a whole line, flushes and fsyncs it before it returns,
so a record that was reported finished survives a crash of the client, the worker or the
machine. A crash can only tear the last line (a line without its newline, or one that does not
parse): ``open_store`` drops it (truncating the file to the last whole line) and says so. A bad
line before the last one is not a crash's work: it is an input error naming the file and line.
The file is locked while open, so two runs cannot append to one store at once.

Opening a store whose header records other settings is refused (InputError naming the setting
as ``--KEY``): records of two campaigns never mix.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO

from ..errors import InputError
from ..files import JsonStyle, dumps_json

try:  # POSIX; elsewhere the store is simply not locked
    import fcntl
except ImportError:  # pragma: no cover
    fcntl = None  # type: ignore[assignment]

__all__ = ["Store", "open_store", "read_store"]


@dataclass
class Store:
    """An open store: its path, the records read (file order) and whether a torn last line was
    dropped; ``append`` adds one record durably."""

    path: Path
    records: list[dict[str, Any]]
    torn: bool
    _fh: BinaryIO

    def append(self, record: dict[str, Any]) -> None:
        self._fh.write(_line(record))
        self._fh.flush()
        os.fsync(self._fh.fileno())
        self.records.append(record)

    def close(self) -> None:
        if not self._fh.closed:
            self._fh.close()

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _line(obj: dict[str, Any]) -> bytes:
    return dumps_json(obj, JsonStyle.LINE).encode("utf-8")


def open_store(path: str | os.PathLike[str], fmt: str, version: int,
               settings: dict[str, Any]) -> Store:
    """Open (or create) the store at ``path`` for a run with ``settings``; see the module
    docstring for torn lines, bad lines, locking and other settings."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    fh = open(p, "a+b")  # noqa: SIM115 -- kept open (and locked) until Store.close
    try:
        if fcntl is not None:
            try:
                fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                raise InputError("--out", str(p.parent), "is in use by another run (its "
                                 f"{p.name} is locked); wait for it or use another folder",
                                 source=str(p)) from None
        fh.seek(0)
        data = fh.read()
        header = {"format": fmt, "version": version, "settings": settings}
        _, records, good_end, torn = _parse(p, data, fmt, version, settings)
        if good_end < len(data):
            os.ftruncate(fh.fileno(), good_end)
            fh.seek(0, os.SEEK_END)
        if good_end == 0:
            fh.write(_line(header))
            fh.flush()
            os.fsync(fh.fileno())
        return Store(p, records, torn, fh)
    except BaseException:
        fh.close()
        raise


def read_store(path: str | os.PathLike[str], fmt: str, version: int
               ) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """(settings, records) of the store at ``path``, read only (nothing truncated or locked; a
    torn last line is left out); InputError if it is missing, empty or not such a store."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise InputError("store", str(p), f"cannot be read ({exc.strerror or exc})") from None
    head, records, _, _ = _parse(p, data, fmt, version, None)
    settings = head.get("settings")
    if not isinstance(settings, dict):
        raise InputError("store", str(p), "holds no header with the run's settings")
    return settings, records


def _parse(p: Path, data: bytes, fmt: str, version: int, settings: dict[str, Any] | None
           ) -> tuple[dict[str, Any], list[dict[str, Any]], int, bool]:
    """(header, {} if none; records; bytes of whole good lines; whether a torn last line was
    dropped)."""
    lines = data.split(b"\n")
    # split leaves b"" after a final newline; anything else there is a line without its newline.
    complete, rest = lines[:-1], lines[-1]
    parsed: list[dict[str, Any]] = []
    pos = 0
    for k, raw in enumerate(complete):
        try:
            obj = json.loads(raw.decode("utf-8"))
            if not isinstance(obj, dict):
                raise ValueError("not an object")
        except (UnicodeDecodeError, ValueError):
            if k == len(complete) - 1 and not rest:
                return (*_checked(p, parsed, fmt, version, settings), pos, True)
            raise InputError("line", raw[:60].decode("utf-8", "replace"), "is not a JSON "
                             "object; the store is damaged (remove it to start afresh)",
                             source=str(p), line=k + 1) from None
        parsed.append(obj)
        pos += len(raw) + 1
    return (*_checked(p, parsed, fmt, version, settings), pos, bool(rest))


def _checked(p: Path, lines: list[dict[str, Any]], fmt: str, version: int,
             settings: dict[str, Any] | None
             ) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """(header, records) of the parsed lines, the header checked (and its settings against
    ``settings`` unless None)."""
    if not lines:
        return {}, []
    head = lines[0]
    if head.get("format") != fmt or head.get("version") != version:
        raise InputError("format", head.get("format"), f"must be {fmt!r} version {version}: "
                         "this file is not such a store (remove it or use another folder)",
                         source=str(p), line=1)
    recorded = head.get("settings")
    if settings is not None and recorded != settings:
        recorded = recorded if isinstance(recorded, dict) else {}
        key = next((k for k in settings if recorded.get(k) != settings[k]), next(iter(settings)))
        said = ", ".join(f"{k} {recorded.get(k)!r}" for k in settings)
        raise InputError(f"--{key}", settings[key], f"differs from the run recorded in this "
                         f"folder ({said}); rerun with those settings to resume it, or write "
                         f"to another --out", source=str(p))
    return head, lines[1:]
