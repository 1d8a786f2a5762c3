"""ROS 2 bags as trajectories and measured logs (docs/model.md §12, "ROS 2 bags").

A bag is a rosbag2 folder (``metadata.yaml`` beside its storage files) or one storage file
(``.mcap`` or sqlite3 ``.db3``), read with the pure-Python ``rosbags`` library: no ROS
installation. Its samples are the ``sensor_msgs/msg/JointState`` messages of one topic, in the
bag's order: t = header.stamp - t0 (t0 the first message's stamp unless given), and the four
joints taken by name (``--joints``, the ROS names of left1, left2, right1, right2), in any order
among the message's names; other joints are ignored.

A bag is streamed: one message at a time, handed on in blocks of rows, so a log of any length
is read in bounded memory, and so is a trajectory `cfmpa certify` and `cfmpa monitor` read
(``bag_trajectory_rows``: at most TRAJECTORY_ROWS messages); one held whole
(``load_bag_trajectory``, `cfmpa simulate`) is bounded like a CSV one. A sample's ``line`` is
the one it has in the CSV of the same samples (message k on the topic, 1-based, is line k + 1
under the header), so the JSON of `cfmpa monitor` is the same for a bag and for its CSV;
messages to the user say "message k".

The count read is checked against the count the bag declares on the topic (its metadata.yaml,
or a bare file's mcap summary): a storage file can lose a message silently (rosbags skips a
record whose opcode or time a corrupt byte changed). A shortfall is bad input naming both counts;
with ``allow_gaps`` (monitor --allow-gaps) the log is monitored all the same and the time of
each missing message is unobserved (``BagReading``), placed by the mcap's message index.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import struct
import tempfile
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from decimal import Decimal
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import MISSING, InputError
from ..files import LIMITS, cause_text, echo
from ..spec import TRAJECTORY_COLUMNS, Scenario, Trajectory, parse_trajectory_csv

__all__ = ["BagOptions", "BagReading", "DEFAULT_TOPIC", "JOINT_STATE", "LOG_KINDS", "bag_rows",
           "bag_row_name", "bag_sha256", "bag_trajectory_rows", "is_bag", "load_bag_trajectory",
           "log_output_kind", "parse_joints", "write_bag"]

#: The message type read and written.
JOINT_STATE = "sensor_msgs/msg/JointState"
#: The topic read and written unless --topic names another.
DEFAULT_TOPIC = "/joint_states"
#: Storage files that are a bag on their own (rosbags' Reader opens them without a folder).
BAG_SUFFIXES = (".mcap", ".db3")
JOINTS = TRAJECTORY_COLUMNS[1:]
FloatArray = npt.NDArray[np.float64]
NS = 1_000_000_000


@dataclass
class BagReading:
    """What reading a bag's topic found, filled in as it is read: the count it declares and
    the count read, the first message's stamp and t0 (ns; ``t0_given``: from --t0) and, with
    ``allow_gaps``, where declared messages were not read: ``gaps_before`` the lines (k + 1) of
    the samples a missing message precedes, ``missing_first`` one before the first sample,
    ``missing_last`` after the last, ``unplaced`` those whose place is unknown (no message
    index: sqlite3 storage)."""

    topic: str = ""
    declared: int = 0
    read: int = 0
    first_ns: int | None = None
    t0_ns: int | None = None
    t0_given: bool = False
    gaps_before: set[int] = field(default_factory=set)
    missing_first: bool = False
    missing_last: bool = False
    unplaced: int = 0

    @property
    def missing(self) -> int:
        """Declared messages not read."""
        return max(0, self.declared - self.read)


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


def _seconds_ns(t: float) -> int:
    """Seconds as the nearest nanoseconds, from the decimal the float prints as
    (``--t0 1700000000.25`` is exact in ns, which a float product would not be)."""
    return int(round(Decimal(repr(float(t))).scaleb(9)))


def _joint_indices(names: Sequence[str], joints: Sequence[str], where: str,
                   source: str) -> list[int]:
    """The index in the message's ``names`` of each of ``joints``, by name; InputError naming a
    joint the message lacks or names twice (which position would be its?)."""
    index = {n: i for i, n in enumerate(names)}
    out = []
    for j in joints:
        if j not in index:
            raise InputError("--joints", j, f"is not a joint name of {where} (its names: "
                             f"{echo(list(names))})", source=source)
        twice = [i for i, n in enumerate(names) if n == j]
        if len(twice) > 1:
            raise InputError(f"joint {j!r}", MISSING, f"is named twice in {where} (at positions "
                             f"{twice[0]} and {twice[1]} of its {len(names)} names)",
                             source=source)
        out.append(index[j])
    return out


def _reader(path: Path, option: str, source: str) -> Any:
    """An open rosbags Reader of the bag, or InputError naming the option and the path."""
    import sqlite3  # here, not at the top: a CSV run loads no bag machinery

    from rosbags.rosbag2 import Reader, ReaderError

    try:
        reader = Reader(path)
        reader.open()
    except FileNotFoundError as exc:
        raise InputError(option, str(path), f"is not a ROS 2 bag ({cause_text(exc)})",
                         source=source) from None
    # rosbags 0.11.0 lets sqlite3's own error through for a .db3 that is no database; a YAML
    # error of a corrupt metadata.yaml is several lines (cause_text keeps its first).
    except (ReaderError, OSError, ValueError, KeyError, TypeError, EOFError, struct.error,
            OverflowError, sqlite3.Error) as exc:
        raise InputError(option, str(path), f"is not a readable ROS 2 bag ({cause_text(exc)})",
                         source=source) from None
    return reader


def _samples(path: str | os.PathLike[str], opts: BagOptions, option: str,
             reading: BagReading | None = None, *, allow_gaps: bool = False
             ) -> Iterator[tuple[int, FloatArray]]:
    """(message number, row (5,) in COLUMNS order) for each JointState on the topic, streamed;
    InputError for a topic the bag lacks or that carries another type, a message that cannot be
    decoded, lacks a joint or names one twice, a non-finite value, stamps that do not increase,
    or (after the last message) fewer messages read than the bag declares on the topic, unless
    ``allow_gaps``: then ``reading`` records where they are missing (``BagReading``)."""
    from rosbags.typesys import Stores, get_typestore

    p = Path(path)
    source = str(p)
    info = BagReading(topic=opts.topic) if reading is None else reading
    info.topic = opts.topic
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
        info.declared = sum(int(c.msgcount) for c in conns)
        # Where declared messages are missing, by their receive times in the mcap's message
        # index (only with allow_gaps: 8 bytes a message).
        declared_times = _declared_log_times(p, opts.topic) if allow_gaps else None
        at = 0                                  # declared_times[:at] are accounted for
        placed = 0
        store = get_typestore(Stores.ROS2_HUMBLE)
        t0 = None if opts.t0 is None else _seconds_ns(opts.t0)
        info.t0_given = t0 is not None
        prev_ns: int | None = None
        names: Sequence[str] | None = None
        idx: list[int] = []
        k = 0
        try:
            messages = reader.messages(connections=conns)
            for conn, log_time, raw in messages:
                k += 1
                info.read = k
                where = f"message {k} on {opts.topic}"
                if declared_times is not None:
                    before = int(np.searchsorted(declared_times, log_time, side="left")) - at
                    if before > 0:                  # declared earlier, never read
                        if k == 1:
                            info.missing_first = True
                        else:
                            info.gaps_before.add(k + 1)
                        placed += before
                        at += before
                    if at < len(declared_times) and declared_times[at] == log_time:
                        at += 1
                try:
                    msg: Any = store.deserialize_cdr(raw, conn.msgtype)
                except Exception as exc:    # rosbags raises many kinds on a corrupt payload
                    raise InputError(where, MISSING, f"cannot be decoded as {JOINT_STATE} "
                                     f"({cause_text(exc)})", source=source) from None
                ns = _stamp_ns(msg.header.stamp.sec, msg.header.stamp.nanosec)
                if t0 is None:
                    t0 = ns
                if info.first_ns is None:
                    info.first_ns, info.t0_ns = ns, t0
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
            where = f"past message {k}" if k else "at its first message"
            raise InputError(option, MISSING, f"cannot be read {where} on {opts.topic} "
                             f"({cause_text(exc)})", source=source) from None
        if k == 0:
            raise InputError("--topic", opts.topic, "has no messages in the bag" + (
                f" that can be read (it declares {info.declared:,})" if info.declared else ""),
                source=source)
        if info.missing:
            if not allow_gaps:
                hint = (" (--allow-gaps monitors the rest, the time of the missing ones "
                        "unobserved)" if option == "--log" else "")
                raise InputError(option, MISSING, f"has {k:,} messages on {opts.topic} that can "
                                 f"be read, of the {info.declared:,} the bag declares "
                                 f"({_declared_where(p)}): {info.missing:,} skipped or lost"
                                 + hint, source=source)
            if declared_times is not None and at < len(declared_times):
                info.missing_last = True
                placed += len(declared_times) - at
            info.unplaced = max(0, info.missing - placed)
    finally:
        reader.close()


def _declared_where(p: Path) -> str:
    """Where a bag declares its counts, as the message says it."""
    return "its metadata.yaml" if p.is_dir() else (
        "its mcap summary" if p.suffix.lower() == ".mcap" else "its messages table")


#: mcap's magic, and the opcodes of the records the message index is read from (mcap spec).
MCAP_MAGIC = b"\x89MCAP0\r\n"
OP_FOOTER, OP_CHANNEL, OP_MESSAGE_INDEX, OP_CHUNK_INDEX = 0x02, 0x04, 0x07, 0x08


def _declared_log_times(p: Path, topic: str) -> npt.NDArray[np.int64] | None:
    """The receive times (ns) of every message the bag's mcap message indexes declare on
    ``topic``, sorted; None when there is no such index (sqlite3 storage, an unchunked or
    unindexed mcap, or one whose index cannot be read)."""
    files = sorted(p.glob("*.mcap")) if p.is_dir() else [p]
    if not files or any(f.suffix.lower() != ".mcap" for f in files):
        return None
    times: list[int] = []
    try:
        for f in files:
            got = _mcap_log_times(f, topic)
            if got is None:
                return None
            times += got
    except (OSError, struct.error, ValueError, IndexError):
        return None
    return np.sort(np.asarray(times, dtype=np.int64))


def _mcap_log_times(f: Path, topic: str) -> list[int] | None:
    """The log times of ``topic``'s messages by one mcap file's summary (its channels and chunk
    indexes) and the message index records they point to; None without them."""
    def record(fh: Any) -> tuple[int, bytes]:
        op, length = struct.unpack("<BQ", fh.read(9))
        # A record's length is the file's word: never read more than the file still holds (a
        # forged length of 2^62 would otherwise ask for that much memory).
        if length > file_bytes - fh.tell():
            raise ValueError(f"an mcap record of {length} bytes runs past the file's end")
        return op, fh.read(length)

    def string(buf: bytes, at: int) -> tuple[str, int]:
        (n,) = struct.unpack_from("<I", buf, at)
        return buf[at + 4:at + 4 + n].decode("utf-8", "replace"), at + 4 + n

    with open(f, "rb") as fh:
        file_bytes = os.fstat(fh.fileno()).st_size
        fh.seek(-(len(MCAP_MAGIC) + 29), os.SEEK_END)
        op, body = record(fh)
        if op != OP_FOOTER or fh.read(len(MCAP_MAGIC)) != MCAP_MAGIC:
            return None
        summary_start, _, _ = struct.unpack("<QQI", body)
        if not summary_start:
            return None
        fh.seek(summary_start)
        channels: set[int] = set()
        index_offsets: list[tuple[int, int]] = []
        indexed = False
        while True:
            op, body = record(fh)
            if op == OP_FOOTER:
                break
            if op == OP_CHANNEL:
                cid, _ = struct.unpack_from("<HH", body, 0)
                name, _ = string(body, 4)
                if name == topic:
                    channels.add(cid)
            elif op == OP_CHUNK_INDEX:
                indexed = True
                (size,) = struct.unpack_from("<I", body, 32)
                for at in range(36, 36 + size, 10):
                    cid, offset = struct.unpack_from("<HQ", body, at)
                    index_offsets.append((cid, offset))
        if not indexed:
            return None
        times: list[int] = []
        for cid, offset in index_offsets:
            if cid not in channels:
                continue
            fh.seek(offset)
            op, body = record(fh)
            if op != OP_MESSAGE_INDEX:
                return None
            (size,) = struct.unpack_from("<I", body, 2)
            times += [x[0] for x in struct.iter_unpack("<QQ", body[6:6 + size])]
        return times


def bag_rows(path: str | os.PathLike[str], opts: BagOptions, *, block_rows: int,
             option: str = "--log", reading: BagReading | None = None,
             allow_gaps: bool = False) -> Iterator[tuple[int, FloatArray]]:
    """The bag's samples in blocks: (the first sample's line, rows (K, 5) in COLUMNS order),
    at most ``block_rows`` rows each (message k stands at line k + 1, as in its CSV).
    ``reading`` is filled in as they are read (a block's gaps before it is handed on)."""
    block: list[FloatArray] = []
    first = 0
    for k, row in _samples(path, opts, option, reading, allow_gaps=allow_gaps):
        if not block:
            first = k + 1
        block.append(row)
        if len(block) >= block_rows:
            yield first, np.stack(block)
            block = []
    if block:
        yield first, np.stack(block)


def bag_trajectory_rows(path: str | os.PathLike[str], opts: BagOptions
                        ) -> Iterator[tuple[int, FloatArray]]:
    """A trajectory bag's rows one at a time, streamed, as ``spec.certify_trajectory_rows``
    takes them: (line, row (5,) in COLUMNS order), message k standing at line k + 1 of the CSV
    of the same samples; every message the bag declares must be read (``_samples``)."""
    for k, row in _samples(path, opts, "--traj"):
        yield k + 1, row


def bag_row_name(opts: BagOptions) -> Callable[[int], str]:
    """How a failed check names a trajectory bag's row k (1-based): its message."""
    return lambda k: f"message {k} on {opts.topic}"


def load_bag_trajectory(path: str | os.PathLike[str], s: Scenario, opts: BagOptions, *,
                        allow_speed: bool = False) -> Trajectory:
    """A trajectory from a bag, read and validated as the CSV of the same samples is
    (``spec.parse_trajectory_csv``: message k is row k, named "message k on TOPIC", no line
    of the binary bag); at most as many rows as a CSV within LIMITS["trajectory"] can hold
    (10 bytes a row at the least); every message the bag declares must be read."""
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

    return parse_trajectory_csv(lines(), s, source=str(path), allow_speed=allow_speed,
                                name_row=bag_row_name(opts))


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


#: How `cfmpa simulate --out` writes its log, by ``log_output_kind``.
LOG_KINDS = ("csv", "mcap", "db3", "folder")


def log_output_kind(path: str | os.PathLike[str]) -> str:
    """How a log is written to ``path`` (one of LOG_KINDS): a bag for a name ending in .mcap or
    .db3 (that storage file alone) or for a folder (the rosbag2 layout, metadata.yaml beside an
    mcap file): a bag folder (replaced), or a path ending in / that is new or an empty folder;
    CSV otherwise. InputError for any other folder, and for a path ending in / that is a file
    (a log never replaces those)."""
    text = os.fspath(path)
    p = Path(text)
    slash = text.endswith(("/", os.sep))
    if p.suffix.lower() in BAG_SUFFIXES and not slash:
        return p.suffix.lower()[1:]
    if p.is_dir():
        if (p / "metadata.yaml").is_file() or (slash and not any(p.iterdir())):
            return "folder"
        if slash:
            raise InputError("--out", text, "is a folder that is not a ROS 2 bag (no "
                             "metadata.yaml, and not empty): give a new folder for a bag, or a "
                             "file (.mcap or .db3 for a bag, any other name for CSV)")
        raise InputError("--out", text, "is a folder, not a file (and no ROS 2 bag: end a new "
                         "or empty folder's name in / to write a bag folder there)")
    if slash:
        if p.exists():
            raise InputError("--out", text, "ends in / but is a file, not a folder")
        return "folder"
    return "csv"


def write_bag(path: str | os.PathLike[str], t: FloatArray, angles: FloatArray,
              opts: BagOptions = BagOptions(), kind: str | None = None) -> Path:
    """Write samples (t (N,), angles (N, 4) in JOINTS order) as JointState messages on
    ``opts.topic``, joints named ``opts.joints``, header.stamp = t to the nearest ns (and the
    same as the bag's receive time): one .mcap or .db3 file, or a rosbag2 folder, by ``kind``
    (``log_output_kind`` of ``path`` when None). Atomic: built in a temporary folder beside
    ``path``, then renamed onto it (a bag folder it replaces is moved aside first, then
    deleted)."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    target = Path(path)
    kind = log_output_kind(path) if kind is None else kind
    if kind not in LOG_KINDS[1:]:
        raise InputError("--out", str(target), "must end in .mcap or .db3, or name a folder, to "
                         "be written as a bag")
    store = get_typestore(Stores.ROS2_HUMBLE)
    js = store.types[JOINT_STATE]
    header = store.types["std_msgs/msg/Header"]
    stamp = store.types["builtin_interfaces/msg/Time"]
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
    try:
        folder = tmp / (target.name if kind == "folder" else "bag")
        empty = np.zeros(0)
        plugin = StoragePlugin.SQLITE3 if kind == "db3" else StoragePlugin.MCAP
        with Writer(folder, version=8, storage_plugin=plugin) as w:
            conn = w.add_connection(opts.topic, JOINT_STATE, typestore=store)
            for tk, ak in zip(t.tolist(), np.asarray(angles, dtype=float)):
                # To the nearest ns: a log whose last stamp falls short of the trajectory's end
                # is covered there by the bound from its last sample (docs/model.md §12).
                ns = _seconds_ns(tk)
                sec, nanosec = divmod(ns, NS)
                msg = js(header=header(stamp=stamp(sec=sec, nanosec=nanosec), frame_id=""),
                         name=list(opts.joints), position=np.array(ak, dtype=float),
                         velocity=empty, effort=empty)
                w.write(conn, max(ns, 0), store.serialize_cdr(msg, JOINT_STATE))
        for f in [folder, *folder.rglob("*")]:
            os.chmod(f, 0o755 if f.is_dir() else 0o644)
        if kind == "folder":
            old = tmp / "replaced"
            if target.exists():
                os.replace(target, old)
            os.replace(folder, target)
        else:
            # rosbags names the storage file after its folder
            os.replace(folder / f"bag.{kind}", target)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return target
