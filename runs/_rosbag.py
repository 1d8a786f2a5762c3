"""ROS 2 bags as trajectories and measured logs (docs/model.md §12, "ROS 2 bags").

A bag is a rosbag2 folder (``metadata.yaml`` beside its storage files) or one storage file
(``.mcap`` or sqlite3 ``.db3``), read with the pure-Python ``rosbags`` library: no ROS
installation. Its samples are the ``sensor_msgs/msg/JointState`` messages of one topic, in the
bag's order: t = header.stamp - t0 (t0 the first message's stamp unless given), and the four
joints taken by name (``--joints``, the ROS names of left1, left2, right1, right2), in any order
among the message's names; other joints are ignored.

A bag is streamed: one message at a time, handed on in blocks of rows, so a log of any length
is read in bounded memory (a trajectory, which the certificate needs whole, is bounded like a
CSV one). A sample's ``line`` is the one it has in the CSV of the same samples (message k on the
topic, 1-based, is line k + 1 under the header), so the JSON of `cfmpa monitor` is the same for
a bag and for its CSV; messages to the user say "message k".
"""

from __future__ import annotations

import hashlib
import os
import shutil
import sqlite3
import struct
import tempfile
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import MISSING, InputError
from ..files import LIMITS, echo
from ..spec import TRAJECTORY_COLUMNS, Scenario, Trajectory, parse_trajectory_csv

__all__ = ["BagOptions", "DEFAULT_TOPIC", "JOINT_STATE", "bag_rows", "bag_sha256", "is_bag",
           "load_bag_trajectory", "parse_joints", "write_bag"]

#: The message type read and written.
JOINT_STATE = "sensor_msgs/msg/JointState"
#: The topic read and written unless --topic names another.
DEFAULT_TOPIC = "/joint_states"
#: Storage files that are a bag on their own (rosbags' Reader opens them without a folder).
BAG_SUFFIXES = (".mcap", ".db3")
JOINTS = TRAJECTORY_COLUMNS[1:]
FloatArray = npt.NDArray[np.float64]
NS = 1_000_000_000


@dataclass(frozen=True)
class BagOptions:
    """How a bag is read: the topic, the ROS names of JOINTS (left1, left2, right1, right2 in
    that order), and t0 in seconds (None: the first message's stamp)."""

    topic: str = DEFAULT_TOPIC
    joints: tuple[str, ...] = JOINTS
    t0: float | None = None


def is_bag(path: str | os.PathLike[str]) -> bool:
    """A bag by its path: a folder holding metadata.yaml, or a file ending in .mcap or .db3."""
    p = Path(path)
    if p.is_dir():
        return (p / "metadata.yaml").is_file()
    return p.suffix.lower() in BAG_SUFFIXES


def parse_joints(text: str | None) -> tuple[str, ...]:
    """--joints L1,L2,R1,R2: four distinct non-empty ROS joint names (default JOINTS)."""
    if text is None:
        return JOINTS
    names = tuple(x.strip() for x in str(text).split(","))
    if len(names) != len(JOINTS) or not all(names) or len(set(names)) != len(names):
        raise InputError("--joints", echo(text), "must be four distinct joint names, the ROS "
                         f"names of {','.join(JOINTS)} in that order")
    return names


def _stamp_ns(sec: int, nanosec: int) -> int:
    return int(sec) * NS + int(nanosec)


def _seconds_ns(t: float, up: bool = False) -> int:
    """Seconds as nanoseconds (the nearest, or with ``up`` the next at or above), from the
    decimal the float prints as (``--t0 1700000000.25`` is exact in ns, which a float product
    would not be)."""
    d = Decimal(repr(float(t))).scaleb(9)
    return int(d.to_integral_value(rounding="ROUND_CEILING")) if up else int(round(d))


def _joint_indices(names: Sequence[str], joints: Sequence[str], where: str,
                   source: str) -> list[int]:
    """The index in the message's ``names`` of each of ``joints``, by name; InputError naming a
    joint the message lacks."""
    index = {n: i for i, n in enumerate(names)}
    out = []
    for j in joints:
        if j not in index:
            raise InputError("--joints", j, f"is not a joint name of {where} (its names: "
                             f"{echo(list(names))})", source=source)
        out.append(index[j])
    return out


def _reader(path: Path, option: str, source: str) -> Any:
    """An open rosbags Reader of the bag, or InputError naming the option and the path."""
    from rosbags.rosbag2 import Reader, ReaderError

    try:
        reader = Reader(path)
        reader.open()
    except FileNotFoundError as exc:
        raise InputError(option, str(path), f"is not a ROS 2 bag ({exc})", source=source) from None
    # rosbags 0.11.0 lets sqlite3's own error through for a .db3 that is no database.
    except (ReaderError, OSError, ValueError, KeyError, TypeError, EOFError, struct.error,
            sqlite3.Error) as exc:
        raise InputError(option, str(path), f"is not a readable ROS 2 bag ({exc})",
                         source=source) from None
    return reader


def _samples(path: str | os.PathLike[str], opts: BagOptions, option: str
             ) -> Iterator[tuple[int, FloatArray]]:
    """(message number, row (5,) in COLUMNS order) for each JointState on the topic, streamed;
    InputError for a topic the bag lacks or that carries another type, a message that cannot be
    decoded or lacks a joint, a non-finite value, or stamps that do not increase."""
    from rosbags.typesys import Stores, get_typestore

    p = Path(path)
    source = str(p)
    reader = _reader(p, option, source)
    try:
        conns = [c for c in reader.connections if c.topic == opts.topic]
        if not conns:
            topics = sorted({c.topic for c in reader.connections})
            raise InputError("--topic", opts.topic, f"is not a topic of the bag (its topics: "
                             f"{echo(topics)})", source=source)
        for c in conns:
            if c.msgtype != JOINT_STATE:
                raise InputError("--topic", opts.topic, f"carries {c.msgtype}, not "
                                 f"{JOINT_STATE}", source=source)
        store = get_typestore(Stores.ROS2_HUMBLE)
        t0 = None if opts.t0 is None else _seconds_ns(opts.t0)
        prev_ns: int | None = None
        names: Sequence[str] | None = None
        idx: list[int] = []
        k = 0
        try:
            messages = reader.messages(connections=conns)
            for conn, _, raw in messages:
                k += 1
                where = f"message {k} on {opts.topic}"
                try:
                    msg: Any = store.deserialize_cdr(raw, conn.msgtype)
                except Exception as exc:    # rosbags raises many kinds on a corrupt payload
                    raise InputError(where, MISSING, f"cannot be decoded as {JOINT_STATE} "
                                     f"({type(exc).__name__}: {exc})", source=source) from None
                ns = _stamp_ns(msg.header.stamp.sec, msg.header.stamp.nanosec)
                if t0 is None:
                    t0 = ns
                if prev_ns is not None and ns <= prev_ns:
                    raise InputError("header.stamp", ns / NS, f"of {where} must be later than "
                                     f"the previous message's {prev_ns / NS!r} s (times strictly "
                                     "increase)", source=source)
                prev_ns = ns
                if names is None or list(msg.name) != list(names):
                    names = list(msg.name)
                    idx = _joint_indices(names, opts.joints, where, source)
                pos = np.asarray(msg.position, dtype=float)
                if len(pos) != len(names):
                    raise InputError("position", len(pos), f"of {where} must have one value per "
                                     f"name ({len(names)})", source=source)
                row = np.empty(len(JOINTS) + 1)
                row[0] = (ns - t0) / NS                 # exact integers, then one rounding
                row[1:] = pos[idx]
                if not np.isfinite(row[1:]).all():
                    q = int(np.flatnonzero(~np.isfinite(row[1:]))[0])
                    raise InputError(f"position of {opts.joints[q]}", float(row[1 + q]),
                                     f"of {where} must be finite", source=source)
                yield k, row
        except InputError:
            raise
        except Exception as exc:            # a storage file cut short or corrupt mid-way
            raise InputError(option, source, f"cannot be read past message {k} on "
                             f"{opts.topic} ({type(exc).__name__}: {exc})",
                             source=source) from None
        if k == 0:
            raise InputError("--topic", opts.topic, "has no messages in the bag",
                             source=source)
    finally:
        reader.close()


def bag_rows(path: str | os.PathLike[str], opts: BagOptions, *, block_rows: int,
             option: str = "--log") -> Iterator[tuple[int, FloatArray]]:
    """The bag's samples in blocks: (the first sample's line, rows (K, 5) in COLUMNS order),
    at most ``block_rows`` rows each (message k stands at line k + 1, as in its CSV)."""
    block: list[FloatArray] = []
    first = 0
    for k, row in _samples(path, opts, option):
        if not block:
            first = k + 1
        block.append(row)
        if len(block) >= block_rows:
            yield first, np.stack(block)
            block = []
    if block:
        yield first, np.stack(block)


def load_bag_trajectory(path: str | os.PathLike[str], s: Scenario, opts: BagOptions, *,
                        allow_speed: bool = False) -> Trajectory:
    """A trajectory from a bag, read and validated as the CSV of the same samples is
    (``spec.parse_trajectory_csv``: message k is row k, at line k + 1); at most as many rows as
    a CSV within LIMITS["trajectory"] can hold (10 bytes a row at the least)."""
    cap = LIMITS["trajectory"].value() // 10

    def lines() -> Iterator[str]:
        yield ",".join(TRAJECTORY_COLUMNS)
        for k, row in _samples(path, opts, "--traj"):
            if k > cap:
                lim = LIMITS["trajectory"]
                raise InputError("--traj", str(path), f"has more than {cap:,} messages on "
                                 f"{opts.topic} (as many rows as a CSV within "
                                 f"{lim.words(lim.value())} can hold)", source=str(path))
            yield ",".join(repr(float(x)) for x in row)     # repr: the same doubles back

    return parse_trajectory_csv(lines(), s, source=str(path), allow_speed=allow_speed)


def bag_sha256(path: str | os.PathLike[str]) -> str:
    """SHA-256 of a bag file; of a folder, over its files in name order (each one's relative
    path, a NUL, its bytes), streamed."""
    p = Path(path)
    h = hashlib.sha256()
    files = sorted(x for x in p.rglob("*") if x.is_file()) if p.is_dir() else [p]
    for f in files:
        if p.is_dir():
            h.update(f.relative_to(p).as_posix().encode() + b"\0")
        with open(f, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 20), b""):
                h.update(chunk)
    return h.hexdigest()


def write_bag(path: str | os.PathLike[str], t: FloatArray, angles: FloatArray,
              opts: BagOptions = BagOptions()) -> Path:
    """Write samples (t (N,), angles (N, 4) in JOINTS order) as one .mcap file of JointState
    messages on ``opts.topic``, joints named ``opts.joints``, header.stamp = t to the nearest ns
    (the last one rounded up) and the same as the bag's receive time. Atomic: built in a
    temporary folder beside ``path``, then renamed onto it."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    target = Path(path)
    if target.suffix.lower() != ".mcap":
        raise InputError("--out", str(target), "must end in .mcap to be written as a bag")
    store = get_typestore(Stores.ROS2_HUMBLE)
    js = store.types[JOINT_STATE]
    header = store.types["std_msgs/msg/Header"]
    stamp = store.types["builtin_interfaces/msg/Time"]
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
    try:
        folder = tmp / "bag"
        empty = np.zeros(0)
        with Writer(folder, version=8, storage_plugin=StoragePlugin.MCAP) as w:
            conn = w.add_connection(opts.topic, JOINT_STATE, typestore=store)
            last = len(t) - 1
            for k, (tk, ak) in enumerate(zip(t.tolist(), np.asarray(angles, dtype=float))):
                # The last stamp rounded up: a log that reaches the trajectory's end still does
                # (one stopping short of it is unobserved there, docs/model.md §12).
                ns = _seconds_ns(tk, up=k == last)
                sec, nanosec = divmod(ns, NS)
                msg = js(header=header(stamp=stamp(sec=sec, nanosec=nanosec), frame_id=""),
                         name=list(opts.joints), position=np.array(ak, dtype=float),
                         velocity=empty, effort=empty)
                w.write(conn, max(ns, 0), store.serialize_cdr(msg, JOINT_STATE))
        inner = folder / "bag.mcap"            # rosbags names the file after its folder
        os.chmod(inner, 0o644)
        os.replace(inner, target)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return target
