"""cfmpa's one progress bar on stderr (``Progress``): long BuiltDR builds and searches, and the
campaign's and batch's tasks (``cfmpa.runs`` draws it through ``Progress.for_terminal``).

A build or search draws it only when stderr is a terminal and the grid is large
(``PROGRESS_MIN_CELLS``), so logs, pipes and tests stay clean; ``progress=True`` forces it,
``False`` silences it.
"""

from __future__ import annotations

import contextlib
import math
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
    """cfmpa's one progress bar: ``label done/total [####   ] rate/s, elapsed, ETA`` redrawn
    in place on a stream (None: silent); BuiltDR's rows, the search's layers, a campaign's or
    batch's tasks. The rate is of the units done in this run (``start`` counts those done before
    it, e.g. reused from a store), so the time left does not count reused work."""

    def __init__(self, label: str, total: int, start: int = 0, stream: TextIO | None = None
                 ) -> None:
        self.label, self.total = label, max(int(total), 1)
        self.start = self.done = min(int(start), self.total)
        self.stream = stream
        self._t0 = time.monotonic()
        self._last = -math.inf

    @classmethod
    def for_terminal(cls, label: str, total: int, start: int = 0,
                     progress: bool | None = None, stream: TextIO | None = None) -> Progress:
        """A bar on ``stream`` (default stderr) if ``progress`` is True, or None and the stream
        is a terminal (and no ``progress_silenced`` is in force); silent otherwise (logs, pipes
        and tests stay clean)."""
        out = sys.stderr if stream is None else stream
        if progress is None:
            progress = _DEFAULT[0]
        if progress is None:
            isatty = getattr(out, "isatty", None)
            progress = bool(isatty is not None and isatty())
        return cls(label, total, start, out if progress else None)

    @property
    def enabled(self) -> bool:
        return self.stream is not None

    def restart(self) -> None:
        """The clock of the rate and the elapsed time starts now (when the work starts)."""
        self._t0 = time.monotonic()

    def advance(self, units: int = 1) -> None:
        self.done = min(self.done + units, self.total)
        if self.stream is None:
            return
        now = time.monotonic()
        if now - self._last >= _REDRAW_S or self.done == self.total:
            self._last = now
            self._draw(now)

    def line(self, now: float | None = None) -> str:
        elapsed = (time.monotonic() if now is None else now) - self._t0
        computed = self.done - self.start
        rate = computed / elapsed if elapsed > 0 and computed > 0 else 0.0
        left = "-" if rate == 0 else _duration((self.total - self.done) / rate)
        filled = _WIDTH * self.done // self.total
        bar = "#" * filled + " " * (_WIDTH - filled)
        return (f"{self.label} {self.done}/{self.total} [{bar}] {rate:.2f}/s, "
                f"{_duration(elapsed)} elapsed, ETA {left}  ")

    def close(self) -> None:
        if self.stream is not None:
            self._draw(time.monotonic())
            self.stream.write("\n")
            self.stream.flush()
            self.stream = None

    def _draw(self, now: float) -> None:
        assert self.stream is not None
        self.stream.write("\r" + self.line(now))
        self.stream.flush()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


def _duration(seconds: float) -> str:
    s = int(round(seconds))
    h, rest = divmod(s, 3600)
    return f"{h}h{rest // 60:02d}m" if h else f"{rest // 60}m{rest % 60:02d}s"


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
    return Progress(label, total, stream=out if progress else None)
