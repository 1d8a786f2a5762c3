"""A tiny progress bar on stderr for long BuiltDR builds and searches.

It draws only when stderr is a terminal and the grid is large (``PROGRESS_MIN_CELLS``), so logs,
pipes and tests stay clean; ``progress=True`` forces it, ``False`` silences it.
"""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Iterator
from types import TracebackType
from typing import TextIO

__all__ = ["PROGRESS_MIN_CELLS", "Progress", "progress_bar", "progress_default",
           "progress_silenced"]

#: Grids of at least this many cells ((N + 1) * m * n) get a bar when stderr is a terminal. The
#: default scenario (about 7.2 million cells) is just above it; small test grids stay silent.
PROGRESS_MIN_CELLS = 5_000_000

#: Redraw at most this often (seconds): a bar must not slow down what it reports on.
_REDRAW_S = 0.1
_WIDTH = 30


class Progress:
    """Counts finished units of work and redraws ``label [####   ] done/total`` in place."""

    def __init__(self, label: str, total: int, stream: TextIO | None) -> None:
        self.label = label
        self.total = max(int(total), 1)
        self.stream = stream  # None: silent
        self.done = 0
        self._last = -_REDRAW_S

    @property
    def enabled(self) -> bool:
        return self.stream is not None

    def advance(self, units: int = 1) -> None:
        self.done = min(self.done + units, self.total)
        if self.stream is None:
            return
        now = time.monotonic()
        if now - self._last >= _REDRAW_S or self.done == self.total:
            self._last = now
            self._draw()

    def close(self) -> None:
        if self.stream is not None:
            self._draw()
            self.stream.write("\n")
            self.stream.flush()
            self.stream = None

    def _draw(self) -> None:
        assert self.stream is not None
        filled = _WIDTH * self.done // self.total
        bar = "#" * filled + " " * (_WIDTH - filled)
        self.stream.write(f"\r{self.label} [{bar}] {self.done}/{self.total}")
        self.stream.flush()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


#: What ``progress=None`` means while ``progress_silenced`` is in force (False), else None.
_DEFAULT: list[bool | None] = [None]


def progress_default() -> bool | None:
    """False inside ``progress_silenced`` (every bar asked with progress=None stays silent)."""
    return _DEFAULT[0]


@contextlib.contextmanager
def progress_silenced() -> Iterator[None]:
    """No bar drawn unless asked for with progress=True, in every thread: for runs whose output
    a bar would cut up (`cfmpa prove --audit`, where the report is computed beside the proofs)."""
    before = _DEFAULT[0]
    _DEFAULT[0] = False
    try:
        yield
    finally:
        _DEFAULT[0] = before


def progress_bar(label: str, total: int, cells: int, progress: bool | None = None,
                 stream: TextIO | None = None) -> Progress:
    """A bar on ``stream`` (default stderr): drawn if ``progress`` is True, or if it is None and
    the stream is a terminal and ``cells >= PROGRESS_MIN_CELLS``; silent otherwise."""
    out = sys.stderr if stream is None else stream
    if progress is None:
        progress = _DEFAULT[0]
    if progress is None:
        isatty = getattr(out, "isatty", None)
        progress = bool(isatty is not None and isatty()) and cells >= PROGRESS_MIN_CELLS
    return Progress(label, total, out if progress else None)
