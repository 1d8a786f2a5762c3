"""The project's exceptions: everything cfmpa raises on purpose derives from CfmpaError."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

__all__ = [
    "CfmpaError",
    "InputError",
    "MISSING",
    "ContractViolation",
    "CertificateViolation",
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
