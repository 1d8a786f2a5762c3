"""The project's exceptions: everything cfmpa raises on purpose derives from CfmpaError."""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping
from typing import Any, TextIO

__all__ = [
    "CfmpaError",
    "InputError",
    "MISSING",
    "ContractViolation",
    "CertificateViolation",
    "WorkersLost",
    "INTERRUPTED",
    "USAGE",
    "exit_code",
    "error_text",
    "handled",
]


class CfmpaError(Exception):
    """Root of the project's own errors; the CLI turns these into exit codes, never tracebacks."""

    exit_code = 1


class _Missing:
    def __repr__(self) -> str:
        return "<missing>"


MISSING = _Missing()


class InputError(CfmpaError):
    """Bad user input (a scenario, an array, a plan): names the field and the value it had.

    ``source`` is a file path when one is involved; ``line`` its line number when known.
    """

    exit_code = 2

    def __init__(self, field: str, value: Any, message: str, *, source: str | None = None,
                 line: int | None = None) -> None:
        self.field = field
        self.value = value
        self.message = message
        self.source = source
        self.line = line
        super().__init__(self.render())

    def render(self) -> str:
        where = ""
        if self.source is not None:
            where = f"{self.source}:{self.line}: " if self.line is not None else f"{self.source}: "
        got = "" if self.value is MISSING else f", got {self.value!r}"
        return f"{where}error: {self.field} {self.message}{got}"


class ContractViolation(CfmpaError):
    """A Hoare triple's pre- or postcondition failed at run time.

    The message names the triple, the condition, then one ``name was value`` line per value.
    ``condition`` is the id and the message joined (``post.costs: the reported ...``);
    ``condition_id`` and ``message`` are the two parts, apart.
    """

    exit_code = 1

    def __init__(self, triple: str, condition: str, values: Mapping[str, Any] | None = None, *,
                 condition_id: str | None = None, message: str | None = None) -> None:
        self.triple = triple
        self.condition = condition
        head, sep, tail = condition.partition(": ")
        self.condition_id = condition_id if condition_id is not None else (
            head if sep else condition)
        self.message = message if message is not None else (tail if sep else condition)
        self.values = dict(values or {})
        lines = [f"{triple}: {condition}"]
        lines += [f"{name} was {value!r}" for name, value in self.values.items()]
        super().__init__("\n".join(lines))


class CertificateViolation(ContractViolation):
    """The continuous-time certificate found the arms' link rectangles in contact."""


class WorkersLost(CfmpaError):
    """A run on a Dask cluster stopped because the cluster had no worker for ``--worker-timeout``
    seconds, or the client lost its scheduler: nothing was concluded about the work left, so
    exit 2 as for input the system refused. The message says what was recorded and the command
    that resumes."""

    exit_code = 2


#: Exit code of bad input or usage (argparse's own), and of an interrupted run (128 + SIGINT).
USAGE = 2
INTERRUPTED = 130


def exit_code(exc: BaseException) -> int | None:
    """The exit code an exception stands for, None for one that is a bug (a traceback).

    The one place exceptions become exit codes: the project's own errors carry theirs (a
    violation 1, bad input 2), an OSError is input the system refused (an unreadable file, a
    full disk: 2), an interrupt is 130.
    """
    if isinstance(exc, CfmpaError):
        return exc.exit_code
    if isinstance(exc, OSError):
        return USAGE
    if isinstance(exc, KeyboardInterrupt):
        return INTERRUPTED
    return None


def error_text(exc: BaseException) -> str:
    """The one line said on stderr for an exception that ``exit_code`` maps."""
    if isinstance(exc, InputError):
        return exc.render()
    if isinstance(exc, CfmpaError):
        return f"error: {exc}"
    if isinstance(exc, OSError):
        name = exc.filename if exc.filename is not None else "file"
        return f"{name}: error: {exc.strerror or exc}"
    if isinstance(exc, KeyboardInterrupt):
        return "interrupted"
    return f"error: {exc}"


def handled(run: Callable[[], int], stderr: TextIO | None = None) -> int:
    """``run()``'s exit code; an exception ``exit_code`` maps becomes its message on ``stderr``
    (default sys.stderr) and its exit code; any other propagates (a bug keeps its traceback)."""
    try:
        return int(run())
    except BaseException as exc:
        code = exit_code(exc)
        if code is None:
            raise
        print(error_text(exc), file=sys.stderr if stderr is None else stderr)
        return code
