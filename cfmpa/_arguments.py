"""The command line's shared options and the checks of their values before any work.

Each helper adds one option the subcommands share (the scenario, ``--variant``, ``--kernel``
from ``impl.KERNELS``, ``--out``, ``--json``, the engine options, a trajectory's) and records
the check of its value: an output that cannot be written, a number over its ``Budget``.
``run_checks`` runs a command's recorded checks; `cfmpa` calls it before the command, so a bad
value is exit 2 (InputError) before anything is computed, allocated or written.
"""

from __future__ import annotations

import argparse
import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .errors import InputError

__all__ = ["FILE", "FOLDER", "Budget", "Formatter", "alias", "bag_arguments", "budgets",
           "check_log_output", "check_output", "checked", "cpus", "engine_arguments", "json_argument",
           "kernel_argument", "number", "out_argument", "output", "positive", "run_checks",
           "scenario_argument", "store_argument", "trajectory_arguments", "variant_argument",
           "visible_options"]


#: The attribute of an argparse action that holds its old spellings: accepted, hidden from the
#: help, listed in docs/model.md §7 ("old spellings").
ALIASES = "cfmpa_aliases"


def alias(action: argparse.Action, *old: str) -> argparse.Action:
    """Mark ``old`` (option strings of ``action``, after its own name) as old spellings: they
    still work, and the help shows the option's name only (``Formatter``)."""
    assert set(old) <= set(action.option_strings[1:]), (old, action.option_strings)
    setattr(action, ALIASES, frozenset(old))
    return action


def visible_options(action: argparse.Action) -> list[str]:
    """The option strings the help shows: none for a hidden option, else all but its old
    spellings."""
    if action.help == argparse.SUPPRESS:
        return []
    hidden: frozenset[str] = getattr(action, ALIASES, frozenset())
    return [o for o in action.option_strings if o not in hidden]


class Formatter(argparse.RawDescriptionHelpFormatter):
    """The help of every command: descriptions as written, and an option's old spellings
    (``alias``) left out."""

    def _format_action_invocation(self, action: argparse.Action) -> str:
        if getattr(action, ALIASES, None) and action.option_strings:
            import copy

            action = copy.copy(action)
            action.option_strings = visible_options(action)
        return super()._format_action_invocation(action)


def variant(value: str) -> str:
    """--variant's type: a member of spec.Variant by its value."""
    from .spec import Variant

    try:
        return Variant(value).value
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be one of "
                                         f"{', '.join(v.value for v in Variant)}, got {value!r}"
                                         ) from None


def scenario_argument(p: argparse.ArgumentParser,
                      text: str = "scenario: a bundled name (cfmpa scenarios) or a TOML file"
                      ) -> None:
    p.add_argument("scenario", help=text)


def variant_argument(p: argparse.ArgumentParser) -> None:
    """--variant, one of spec.Variant's members (default modified)."""
    from .spec import Variant

    names = [v.value for v in Variant]
    p.add_argument("--variant", type=variant, default="modified", choices=names,
                   metavar="{" + ",".join(names) + "}",
                   help=f"BuiltDR's sweep (docs/model.md §4): {', '.join(names[:-1])} or "
                        f"{names[-1]} (default: modified)")


def kernel_argument(p: argparse.ArgumentParser) -> None:
    """--kernel, one of impl.KERNELS (the first the default)."""
    from .impl import KERNELS

    p.add_argument("--kernel", choices=list(KERNELS), default=KERNELS[0],
                   help=f"{KERNELS[0]} (default; bit-identical to the reference) or "
                        f"{', '.join(KERNELS[1:])}")


def store_argument(p: argparse.ArgumentParser) -> None:
    """--store, how D_R is written (docs/model.md §9); default by the grid's cells."""
    from .runs import DR_STORES, ZARR_ABOVE_CELLS

    p.add_argument("--store", choices=list(DR_STORES), default=None,
                   help=f"D_R as DIR/dr.npy or DIR/dr.zarr, a chunked, compressed Zarr v3 "
                        f"store (default: zarr above {ZARR_ABOVE_CELLS:,} cells or "
                        f"CFMPA_ZARR_CELLS, else npy)")


#: What an output option names: a folder the command writes its files into, or one file.
FOLDER, FILE = "folder", "file"


def checked(p: argparse.ArgumentParser, dest: str, option: str,
            check: Callable[[str, Any], None]) -> None:
    """Record that option ``option`` (attribute ``dest``) is checked by ``check(option, value)``
    (which raises InputError); main runs every recorded check of the command before the command
    itself, so a bad value is exit 2 before anything is computed, allocated or written."""
    p.set_defaults(_checks=(*(p.get_default("_checks") or ()), (dest, option, check)))


def output(p: argparse.ArgumentParser, dest: str, option: str, kind: str) -> None:
    """Record that option ``option`` names an output ``kind`` (``check_output``)."""
    checked(p, dest, option, functools.partial(check_output, kind=kind))


def out_argument(p: argparse.ArgumentParser, help: str, *, required: bool = True,
                 default: str | None = None, metavar: str | None = None,
                 kind: str = FOLDER) -> None:
    """--out, the folder (or with ``kind=FILE`` the file) a command writes; checked before any
    work."""
    p.add_argument("--out", required=required, default=default, metavar=metavar, help=help)
    output(p, "out", "--out", kind)


def json_argument(p: argparse.ArgumentParser, help: str = "write the result as JSON") -> None:
    """--json OUT, a file a command writes its result to; checked before any work (``help``
    argparse.SUPPRESS: a hidden option of an old spelling)."""
    p.add_argument("--json", default=None, metavar="OUT", help=help)
    output(p, "json", "--json", FILE)


@dataclass(frozen=True)
class Budget:
    """The values a numeric option accepts, checked before the command allocates or writes
    anything: finite, at least ``lo`` and at most ``hi`` (None: that bound is the run's own, or
    none), and ``why`` the limit is what it is (said in the message)."""

    lo: float | None
    hi: float | None
    why: str

    def __call__(self, option: str, value: Any) -> None:
        if isinstance(value, (list, tuple)):      # nargs or append: each value on its own
            for v in value:
                self(option, v)
            return
        if isinstance(value, float) and not math.isfinite(value):
            raise InputError(option, value, "must be a finite number")
        if self.lo is not None and value < self.lo:
            raise InputError(option, value, f"must be at least {limit(self.lo)} ({self.why})")
        if self.hi is not None and value > self.hi:
            raise InputError(option, value, f"must be at most {limit(self.hi)} ({self.why})")


def limit(x: float) -> str:
    """A bound as the message says it: whole numbers in full, others as %g."""
    return str(int(x)) if float(x).is_integer() and abs(x) >= 1 else f"{x:g}"


def cpus() -> int:
    """The CPUs this process may run on."""
    import os

    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (
        os.cpu_count() or 1)


def budgets() -> dict[str, Budget]:
    """Every numeric option's budget, by name (the runs' own constants where they have one)."""
    from .runs import MAX_DT, MAX_LOG_SAMPLES, MAX_WORKCELLS, MIN_PERIOD_S

    workers = 4 * cpus()
    return {
        "seed": Budget(0, 2**63 - 1, "a seed of numpy's generator"),
        "sample": Budget(1, 2**53, "no grid has more cells; a sample of them all checks every "
                                   "cell"),
        "workers": Budget(0, workers, f"four processes per CPU; this machine has {cpus()}"),
        "prove_workers": Budget(None, workers, f"four processes per CPU; this machine has "
                                               f"{cpus()}"),
        "connect_timeout": Budget(0, 86_400, "a day"),
        "worker_timeout": Budget(0, 86_400, "a day"),
        "workcells": Budget(None, MAX_WORKCELLS, "the campaign's budget"),
        "dt": Budget(None, MAX_DT, "the coarsest campaign time step"),
        "lag": Budget(0, 3600, "an hour"),
        "noise": Budget(0, round(2 * math.pi, 6), "a full turn"),
        "tail": Budget(0, 3600, "an hour"),
        "period": Budget(MIN_PERIOD_S, 3600, "a 1 MHz log at the finest, a sample an hour at "
                                             "the coarsest"),
        "samples": Budget(1, MAX_LOG_SAMPLES, "the simulated log's budget"),
        # A joint speed in rad/s (a --max-speed of monitor's): 100 rad/s is ~950 rpm at a joint.
        "speed": Budget(0, 100, "a joint's speed in rad/s"),
        # --t0 of a ROS 2 bag: a builtin_interfaces/Time's seconds are an int32.
        "t0": Budget(-2**31, 2**31 - 1, "a ROS 2 stamp's seconds, an int32"),
    }


def number(p: argparse.ArgumentParser, option: str, budget: Budget, *, type: Callable[[str], Any],
           aliases: tuple[str, ...] = (), **kw: Any) -> None:
    """A numeric option: parsed by ``type``, its value checked against ``budget`` before the
    command runs; ``aliases``: its old spellings (``alias``)."""
    action = p.add_argument(option, *aliases, type=type, **kw)
    if aliases:
        alias(action, *aliases)
    checked(p, action.dest, option, budget)


def run_checks(args: argparse.Namespace) -> None:
    """Every recorded check of the command on the values given (InputError at the first)."""
    for dest, option, check in getattr(args, "_checks", ()):
        value = getattr(args, dest, None)
        if value is not None:
            check(option, value)


def check_output(option: str, value: Any, kind: str) -> None:
    """InputError for an output that cannot be written: a folder that is a file, a file that is
    a folder, a dangling symbolic link, or a place under a file or in a folder this user cannot
    write."""
    import os
    from pathlib import Path

    value = str(value)
    path = Path(value)

    def refuse(why: str) -> InputError:
        return InputError(option, value, why)

    if path.is_symlink() and not path.exists():
        raise refuse(f"is a dangling symbolic link (to {os.readlink(path)!r}); remove it or "
                     f"give another {kind}")
    if path.exists():
        if kind == FOLDER and not path.is_dir():
            raise refuse("is a file, not a folder (the command writes its files into it)")
        if kind == FILE and path.is_dir():
            raise refuse("is a folder, not a file")
    # The nearest folder that exists is where the files (or the folders leading to them) and
    # the atomic writer's temporary names are made.
    here = path if kind == FOLDER else path.parent
    while not here.exists() and not here.is_symlink() and here != here.parent:
        here = here.parent
    if here.is_symlink() and not here.exists():
        raise refuse(f"cannot be written: {str(here)!r} is a dangling symbolic link")
    if not here.is_dir():
        raise refuse(f"cannot be written: {str(here)!r} is a file, not a folder")
    if not os.access(here, os.W_OK | os.X_OK):
        raise refuse(f"cannot be written: this user may not write in the folder {str(here)!r}")


def check_log_output(option: str, value: Any) -> None:
    """InputError for simulate's --out that cannot be written: the kind of log its name asks for
    (``runs.log_output_kind``: a bag file, a bag folder, CSV), then ``check_output`` as a folder
    or a file."""
    from .runs import log_output_kind

    try:
        kind = log_output_kind(str(value))
    except InputError as exc:          # runs._rosbag names the option by its old spelling
        raise InputError(option, exc.value, exc.message, source=exc.source,
                         line=exc.line) from None
    check_output(option, value, FOLDER if kind == "folder" else FILE)


def engine_arguments(p: argparse.ArgumentParser, *,
                     default: str = "one per CPU; 0: run in this process, no cluster",
                     hidden: bool = False) -> None:
    """--workers, --scheduler, --connect-timeout, --worker-timeout (cfmpa compare, cfmpa
    check-batch; cfmpa dr and plan, whose ``default`` is the build in this process). --workers
    is always Dask workers (prove's processes are its --jobs). ``hidden``: options of an old
    spelling (cfmpa check --batch), accepted and left out of the help."""
    b = budgets()

    def text(t: str) -> str:
        return argparse.SUPPRESS if hidden else t
    number(p, "--workers", b["workers"], type=positive, default=None, metavar="K",
           help=text(f"worker processes of a local Dask cluster (default: {default})"))
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help=text("run on a running Dask cluster instead (tcp://HOST:PORT of `dask "
                             "scheduler`; its workers need cfmpa installed)"))
    number(p, "--connect-timeout", b["connect_timeout"], type=float, default=10.0, metavar="S",
           help=text("seconds to wait for the scheduler and its first worker (default 10)"))
    number(p, "--worker-timeout", b["worker_timeout"], type=float, default=60.0, metavar="S",
           help=text("seconds a run waits while the cluster has no worker, then stops with "
                     "exit 2 and the command that resumes (default 60)"))


def trajectory_arguments(p: argparse.ArgumentParser, traj: str = "the planned trajectory",
                         speed: str = "accept a trajectory whose joint speeds exceed omega"
                         ) -> None:
    """What certify, monitor and simulate share: the scenario, --traj and --allow-speed."""
    scenario_argument(p, "scenario (the geometry): a bundled name or a TOML file")
    p.add_argument("--traj", required=True, metavar="FILE", help=traj)
    p.add_argument("--allow-speed", action="store_true", help=speed)


def bag_arguments(p: argparse.ArgumentParser, *, read: bool = True) -> None:
    """--topic and --joints of a ROS 2 bag (runs.BagOptions), and with ``read`` --t0 (the
    stamp that is t = 0; numeric, budgeted)."""
    p.add_argument("--topic", default=None, metavar="TOPIC",
                   help="a ROS 2 bag's topic of sensor_msgs/msg/JointState (default "
                        "/joint_states)")
    p.add_argument("--joints", default=None, metavar="L1,L2,R1,R2",
                   help="the ROS joint names of left1,left2,right1,right2, matched by name "
                        "(default left1,left2,right1,right2)")
    if read:
        number(p, "--t0", budgets()["t0"], type=float, default=None, metavar="SECONDS",
               help="the stamp that is t = 0: t = header.stamp - t0 (default: the first "
                    "message's stamp)")


def positive(value: str) -> int:
    """The type of a count that may be 0 (its upper bound is its Budget)."""
    try:
        n = int(value)
    except ValueError:
        n = -1
    if n < 0:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 0, got {value!r}")
    return n
