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
    "one_line",
    "value_text",
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
        return one_line(f"{where}error: {self.field} {self.message}{got}")


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

    def one_line(self) -> str:
        """The violation in one line, as the command line prints it: the triple, the condition,
        then the values in parentheses (a length named ``*_m`` in mm)."""
        values = "; ".join(value_text(name, value) for name, value in self.values.items())
        return one_line(f"{self.triple}: {self.condition}" + (f" ({values})" if values else ""))


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


def one_line(text: str) -> str:
    """``text`` on one line: its line breaks (a library's multi-line cause) become "; "."""
    parts = [x.strip() for x in str(text).splitlines() if x.strip()]
    return "; ".join(parts)


def value_text(name: str, value: Any) -> str:
    """``name was value`` as a person reads it: a number whose name ends in ``_m`` (metres) in
    mm, one (or a list of them) whose name ends in ``_rad`` in rad with its degrees, under the
    name without the unit (docs/contributing.md, "Standards")."""
    import math

    def number(x: Any) -> bool:
        return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)

    if name.endswith("_m") and number(value):
        return f"{name[:-2]} was {value * 1000:.6g} mm"
    if name.endswith("_rad") and number(value):
        return f"{name[:-4]} was {value!r} rad ({math.degrees(value):.4g} deg)"
    if (name.endswith("_rad") and isinstance(value, (list, tuple)) and value
            and all(number(x) for x in value)):
        deg = ", ".join(f"{math.degrees(x):.4g}" for x in value)
        return f"{name[:-4]} was {list(value)!r} rad ([{deg}] deg)"
    return f"{name} was {value!r}"


def error_text(exc: BaseException) -> str:
    """The one line said on stderr for an exception that ``exit_code`` maps."""
    if isinstance(exc, InputError):
        return exc.render()
    if isinstance(exc, ContractViolation):
        return f"error: {exc.one_line()}"
    if isinstance(exc, CfmpaError):
        return one_line(f"error: {exc}")
    if isinstance(exc, OSError):
        name = exc.filename if exc.filename is not None else "file"
        return one_line(f"{name}: error: {exc.strerror or exc}")
    if isinstance(exc, KeyboardInterrupt):
        return "interrupted"
    return one_line(f"error: {exc}")


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
