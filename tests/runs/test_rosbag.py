"""ROS 2 bags in `cfmpa monitor`, `cfmpa certify` and `cfmpa simulate` (docs/model.md §12): the
same samples as a bag (written here with rosbags itself, mcap and sqlite3) and as a CSV give the
same verdict and the same JSON; joints are matched by name; a bag that is not one, a missing
topic or joint, a wrong message type are exit 2 naming it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

import factory
from cfmpa.cli import main
from cfmpa.runs import BagOptions, Excursion, log_csv, monitor_json, monitor_log, simulate_log
from cfmpa.runs._rosbag import bag_rows
from cfmpa.runs._trajectory_runs import BLOCK_ROWS, MISSING_MESSAGES, monitor_rows
from cfmpa.spec import TRAJECTORY_COLUMNS, load_trajectory, tolerance_rad, trajectory_csv

DOC = factory.doc(right__start_cell=[2, 8], right__goal_cell=[13, 5])
STORE = get_typestore(Stores.ROS2_HUMBLE)
JS = STORE.types["sensor_msgs/msg/JointState"]
HEADER = STORE.types["std_msgs/msg/Header"]
TIME = STORE.types["builtin_interfaces/msg/Time"]
NS = 1_000_000_000


@pytest.fixture(scope="module")
def cell(tmp_path_factory):
    s, scen, folder, p = factory.planned(tmp_path_factory.mktemp("rosbag"), DOC)
    traj = load_trajectory(folder / "traj.csv", s)
    return s, scen, folder / "traj.csv", traj, tolerance_rad(s, p.certificate)


def write_bag(folder: Path, stamps_ns, positions, names, *, topic="/joint_states",
              storage=StoragePlugin.MCAP, msgtype="sensor_msgs/msg/JointState") -> Path:
    """A rosbag2 folder written by rosbags directly (not by cfmpa): one JointState per row of
    ``positions`` (in the order of ``names``), header.stamp from ``stamps_ns``."""
    with Writer(folder, version=9, storage_plugin=storage) as w:
        conn = w.add_connection(topic, msgtype, typestore=STORE)
        for ns, pos in zip(stamps_ns, positions):
            if msgtype == "std_msgs/msg/String":
                msg = STORE.types[msgtype](data="hello")
            else:
                sec, nanosec = divmod(int(ns), NS)
                msg = JS(header=HEADER(stamp=TIME(sec=sec, nanosec=nanosec), frame_id="base"),
                         name=list(names), position=np.asarray(pos, dtype=float),
                         velocity=np.zeros(0), effort=np.zeros(0))
            w.write(conn, int(ns), STORE.serialize_cdr(msg, msgtype))
    return folder


def samples(traj, tol, **kw):
    """A simulated log with times on the nanosecond grid (a bag's resolution): (ns, t, angles)."""
    t, a = simulate_log(traj, noise=tol / 4, seed=5, **kw)
    ns = np.round(t * 1e9).astype(np.int64)
    return ns, ns / 1e9, a


def monitor_doc(scen, traj_csv, log, out, *extra) -> tuple[int, dict]:
    code = main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(log), "--json",
                 str(out), *extra])
    doc = json.loads(out.read_text())
    doc.pop("timings_s")
    return code, doc


def same_but_log(a: dict, b: dict) -> None:
    assert a.pop("log") != b.pop("log")
    assert a == b




@pytest.mark.parametrize("storage", [StoragePlugin.MCAP, StoragePlugin.SQLITE3])
def test_monitor_gives_the_same_json_for_a_csv_log_and_its_bag(cell, tmp_path, storage):
    s, scen, traj_csv, traj, tol = cell
    ns, t, a = samples(traj, tol, excursions=[Excursion(1.5, "right2", 3 * tol, 0.1)], tail=0.5)
    log = tmp_path / "log.csv"
    log.write_bytes(log_csv(t, a))
    bag = write_bag(tmp_path / "bag", ns, a, TRAJECTORY_COLUMNS[1:], storage=storage)
    code_csv, doc_csv = monitor_doc(scen, traj_csv, log, tmp_path / "c.json")
    code_bag, doc_bag = monitor_doc(scen, traj_csv, bag, tmp_path / "b.json")
    assert code_csv == code_bag == 1
    assert doc_bag["status"] == "outside" and doc_bag["first_outside_joint"] == "right2"
    assert doc_bag["samples"] == len(t) and doc_bag["first_outside_line"] > 2
    same_but_log(doc_csv, doc_bag)
    # The storage file alone (no metadata.yaml) is a bag too.
    inner = next(bag.glob("*.mcap" if storage == StoragePlugin.MCAP else "*.db3"))
    if storage == StoragePlugin.MCAP:
        _, doc_file = monitor_doc(scen, traj_csv, inner, tmp_path / "f.json")
        doc_csv["log"] = "x"
        same_but_log(doc_csv, doc_file)


def test_blocks_of_a_bag_give_the_same_result_as_a_csv(cell, tmp_path):
    # Many blocks (97 rows each): the gaps across block ends are the CSV reader's.
    s, scen, traj_csv, traj, tol = cell
    ns, t, a = samples(traj, tol, period=0.003)
    ns[len(ns) // 2:] += 40_000_000                            # a 40 ms hole: unobserved
    t = ns / 1e9
    bag = write_bag(tmp_path / "bag", ns, a, TRAJECTORY_COLUMNS[1:])
    blocks = list(bag_rows(bag, BagOptions(), block_rows=97))
    assert len(blocks) > 5 and all(len(b) <= 97 for _, b in blocks)
    assert [first for first, _ in blocks] == [2 + 97 * k for k in range(len(blocks))]
    r_bag = monitor_rows(s, traj, tol, iter(blocks), source="b")
    text = log_csv(t, a).decode().splitlines(keepends=True)
    r_csv = monitor_log(s, traj, tol, text, source="b", block_rows=BLOCK_ROWS)
    assert r_bag.unobserved_count >= 1
    assert monitor_json(s, traj, tol, r_bag, "b") == monitor_json(s, traj, tol, r_csv, "b")


REORDERED = ["r_wrist", "gripper_finger", "l_shoulder", "r_shoulder", "l_elbow"]
JOINT_NAMES = "l_shoulder,l_elbow,r_shoulder,r_wrist"    # left1, left2, right1, right2


def reordered_bag(folder, ns, a):
    """The same samples under other names, in another order, with an extra joint."""
    extra = np.full((len(a), 1), 0.123)
    cols = np.column_stack([a[:, 3], extra[:, 0], a[:, 0], a[:, 2], a[:, 1]])
    return write_bag(folder, ns, cols, REORDERED)


def test_joints_are_matched_by_name_in_any_order_and_others_are_ignored(cell, tmp_path):
    s, scen, traj_csv, traj, tol = cell
    ns, t, a = samples(traj, tol, excursions=[Excursion(1.0, "left2", 3 * tol, 0.05)])
    log = tmp_path / "log.csv"
    log.write_bytes(log_csv(t, a))
    bag = reordered_bag(tmp_path / "bag", ns, a)
    _, doc_csv = monitor_doc(scen, traj_csv, log, tmp_path / "c.json")
    _, doc_bag = monitor_doc(scen, traj_csv, bag, tmp_path / "b.json", "--joints", JOINT_NAMES)
    assert doc_bag["first_outside_joint"] == "left2"
    same_but_log(doc_csv, doc_bag)


def test_seeded_fault_a_reader_taking_positions_fails_the_reordered_test(cell, tmp_path,
                                                                         monkeypatch):
    # The fault: the message's first four positions, whatever their names.
    monkeypatch.setattr("cfmpa.runs._rosbag._joint_indices", lambda *args: [0, 1, 2, 3])
    with pytest.raises(AssertionError):
        test_joints_are_matched_by_name_in_any_order_and_others_are_ignored(cell, tmp_path)


def test_a_missing_joint_is_exit_2_naming_it(cell, tmp_path, capsys):
    s, scen, traj_csv, traj, tol = cell
    ns, t, a = samples(traj, tol, samples=50)
    bag = reordered_bag(tmp_path / "bag", ns, a)
    out = tmp_path / "m.json"
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(bag), "--json",
                 str(out), "--joints", "l_shoulder,l_elbow,r_shoulder,r_elbow"]) == 2
    err = capsys.readouterr().err
    assert "--joints is not a joint name of message 1 on /joint_states" in err
    assert "got 'r_elbow'" in err and "Traceback" not in err and not out.exists()
    # The default names are none of this bag's: left1 is named.
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(bag)]) == 2
    assert "got 'left1'" in capsys.readouterr().err


def test_a_wrong_topic_or_message_type_is_exit_2_naming_it(cell, tmp_path, capsys):
    s, scen, traj_csv, traj, tol = cell
    ns, t, a = samples(traj, tol, samples=20)
    bag = write_bag(tmp_path / "bag", ns, a, TRAJECTORY_COLUMNS[1:])
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(bag), "--topic",
                 "/robot/joint_states"]) == 2
    err = capsys.readouterr().err
    assert f"{bag}: error: --topic is not a topic of the bag (its topics: ['/joint_states'])" in err
    assert "got '/robot/joint_states'" in err
    other = write_bag(tmp_path / "str", ns, a, (), msgtype="std_msgs/msg/String")
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(other)]) == 2
    err = capsys.readouterr().err
    assert "--topic carries std_msgs/msg/String, not sensor_msgs/msg/JointState" in err


@pytest.mark.parametrize("make", ["junk.mcap", "junk.db3", "bad-metadata"])
def test_a_file_that_is_not_a_bag_is_exit_2_naming_it(cell, tmp_path, capsys, make):
    s, scen, traj_csv, traj, tol = cell
    path = tmp_path / make
    if make == "bad-metadata":
        path.mkdir()
        (path / "metadata.yaml").write_text("rosbag2_bagfile_information: [\n")
    else:
        path.write_bytes(b"t,left1,left2,right1,right2\n0,0,0,0,0\n")
    for argv in (["monitor", str(scen), "--traj", str(traj_csv), "--log", str(path)],
                 ["certify", str(scen), "--traj", str(path)]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert "is not a readable ROS 2 bag" in err and f"got '{path}'" in err
        assert "Traceback" not in err


def test_a_message_that_cannot_be_decoded_is_exit_2_naming_it(cell, tmp_path, capsys):
    s, scen, traj_csv, traj, tol = cell
    with Writer(tmp_path / "bag", version=9, storage_plugin=StoragePlugin.MCAP) as w:
        conn = w.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=STORE)
        w.write(conn, 1, b"\x00\x01\x00\x00\x07")                  # cut short
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log",
                 str(tmp_path / "bag")]) == 2
    err = capsys.readouterr().err
    assert "error: message 1 on /joint_states cannot be decoded as sensor_msgs/msg/JointState" in err
    assert "Traceback" not in err


def test_stamps_that_do_not_increase_are_exit_2_naming_the_message(cell, tmp_path, capsys):
    s, scen, traj_csv, traj, tol = cell
    ns, t, a = samples(traj, tol, samples=20)
    ns[7] = ns[6]
    bag = write_bag(tmp_path / "bag", ns, a, TRAJECTORY_COLUMNS[1:])
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(bag)]) == 2
    assert "header.stamp of message 8 on /joint_states must be later" in capsys.readouterr().err


def test_t0_shifts_epoch_stamps_to_the_trajectory_time(cell, tmp_path):
    s, scen, traj_csv, traj, tol = cell
    ns, t, a = samples(traj, tol, tail=0.2)
    epoch = 1_700_000_000 * NS
    log = tmp_path / "log.csv"
    log.write_bytes(log_csv(t, a))
    bag = write_bag(tmp_path / "bag", ns + epoch + 250_000_000, a, TRAJECTORY_COLUMNS[1:])
    _, doc_csv = monitor_doc(scen, traj_csv, log, tmp_path / "c.json")
    _, doc_bag = monitor_doc(scen, traj_csv, bag, tmp_path / "b.json", "--t0", "1700000000.25")
    same_but_log(doc_csv, doc_bag)
    # Without --t0 the first stamp is t = 0: the same here, the log starting at the trajectory's.
    assert t[0] == 0.0
    _, doc_first = monitor_doc(scen, traj_csv, bag, tmp_path / "d.json")
    doc_csv["log"] = "x"
    same_but_log(doc_csv, doc_first)


def test_bag_options_without_a_bag_are_exit_2(cell, tmp_path, capsys):
    s, scen, traj_csv, traj, tol = cell
    assert main(["certify", str(scen), "--traj", str(traj_csv), "--topic", "/js"]) == 2
    assert "--topic/--joints/--t0 apply to a ROS 2 bag only" in capsys.readouterr().err
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(traj_csv),
                 "--joints", "a,b,c"]) == 2
    assert "--joints must be four distinct joint names" in capsys.readouterr().err


def test_certify_from_a_bag_equals_certify_from_the_csv(cell, tmp_path):
    s, scen, traj_csv, traj, tol = cell
    ns = np.round(traj.t * 1e9).astype(np.int64)
    csv = tmp_path / "traj.csv"                      # the same waypoints at ns times
    csv.write_text(trajectory_csv(type(traj)(ns / 1e9, traj.angles)))
    bag = reordered_bag(tmp_path / "bag", ns, traj.angles)
    docs = []
    for path, extra in ((csv, []), (bag, ["--joints", JOINT_NAMES])):
        out = tmp_path / f"{path.name}.json"
        assert main(["certify", str(scen), "--traj", str(path), "--json", str(out), *extra]) == 0
        doc = json.loads(out.read_text())
        doc.pop("timings_s")
        docs.append(doc)
    a, b = docs
    assert a["trajectory"].pop("file") != b["trajectory"].pop("file")
    assert a["trajectory"].pop("sha256") != b["trajectory"].pop("sha256") is not None
    assert a == b and a["clear"] is True and a["trajectory"]["rows"] == traj.rows
    # monitor's --traj may be the bag too: the same verdict and JSON as with its CSV.
    ns_log, t, angles = samples(traj, tol, samples=400)
    log = tmp_path / "log.csv"
    log.write_bytes(log_csv(t, angles))
    _, m_csv = monitor_doc(scen, csv, log, tmp_path / "mc.json")
    _, m_bag = monitor_doc(scen, bag, log, tmp_path / "mb.json", "--joints", JOINT_NAMES)
    assert m_csv.pop("trajectory") != m_bag.pop("trajectory")
    assert m_csv == m_bag


def test_simulate_out_mcap_round_trips(cell, tmp_path, capsys):
    s, scen, traj_csv, traj, tol = cell
    args = ["simulate", str(scen), "--traj", str(traj_csv), "--noise", str(tol / 4), "--seed",
            "2", "--tail", "0.3", "--excursion", f"0.8:right1:{3 * tol}:0.05"]
    csv, bag = tmp_path / "run.csv", tmp_path / "run.mcap"
    assert main([*args, "--out", str(csv)]) == 0
    assert main([*args, "--out", str(bag), "--joints", JOINT_NAMES]) == 0
    assert bag.is_file() and sorted(p.name for p in tmp_path.iterdir()) == ["run.csv", "run.mcap"]
    want = np.loadtxt(csv, delimiter=",", skiprows=1)
    got = np.concatenate([b for _, b in bag_rows(bag, BagOptions(joints=tuple(
        JOINT_NAMES.split(","))), block_rows=1000)])
    assert got.shape == want.shape
    assert np.array_equal(got[:, 1:], want[:, 1:])                 # angles: the same doubles
    assert np.max(np.abs(got[:, 0] - want[:, 0])) <= 1e-9           # t: to the nearest ns
    capsys.readouterr()
    c_csv, d_csv = monitor_doc(scen, traj_csv, csv, tmp_path / "c.json")
    c_bag, d_bag = monitor_doc(scen, traj_csv, bag, tmp_path / "b.json", "--joints", JOINT_NAMES)
    assert c_csv == c_bag == 1
    for key in ("status", "samples", "outside", "first_outside_line", "first_outside_joint",
                "unobserved"):
        assert d_csv[key] == d_bag[key], key
    assert "message " in capsys.readouterr().out                  # the user is told the message


# --- the ends of a log, declared counts, names twice, --t0, simulate's outputs (§12) ----------


def _shifted(traj, tmp_path):
    """The trajectory with its times shifted by an offset c for which the nanosecond grid falls
    short of its float end (round(t_end * 1e9) / 1e9 < t_end), as a bag's stamps do: (its CSV,
    the shifted trajectory)."""
    for c in np.arange(1, 200) * 0.1:                  # 0.1 steps as floats: 2.3000000000000003
        end = float(traj.t[-1] + c)
        if round(end * 1e9) / 1e9 < end:
            break
    else:
        raise AssertionError("no offset puts the end between two nanoseconds")
    moved = type(traj)(traj.t + c, traj.angles)
    csv = tmp_path / "moved.csv"
    csv.write_text(trajectory_csv(moved))
    return csv, moved


def test_a_bag_of_the_trajectorys_own_samples_with_nanosecond_stamps_is_inside_exit_0(
        cell, tmp_path, capsys):
    # docs/model.md §12: the ends are covered by the one-sided bound, so stamps rounded to the
    # nanosecond (every ROS bag's), which end 1e-16 s before the trajectory's float end, leave
    # nothing unobserved: the log of the trajectory's own samples is inside.
    s, scen, _, traj, tol = cell
    csv, moved = _shifted(traj, tmp_path)
    t, a = simulate_log(moved)                                  # its own samples, 1 ms apart
    ns = np.round(t * 1e9).astype(np.int64)
    assert 0 < moved.t[-1] - ns[-1] / 1e9 < 1e-12              # the case: the end falls short
    bag = write_bag(tmp_path / "own", ns, a, TRAJECTORY_COLUMNS[1:])
    code, doc = monitor_doc(scen, csv, bag, tmp_path / "m.json", "--t0", "0")
    assert code == 0 and doc["status"] == "inside" and doc["unobserved"] is None
    assert doc["covered_fraction"] == 1.0 and doc["t_last_s"] < moved.t[-1]
    assert "inside;" in capsys.readouterr().out


def _flip_message_opcode(mcap: Path, k: int) -> None:
    """Make message record k (0-based) of an uncompressed, chunked mcap file an unknown record,
    which a reader skips: the summary still counts it (one corrupt byte)."""
    data = bytearray(mcap.read_bytes())
    at, seen = 8, 0
    while at < len(data):
        op, length = data[at], int.from_bytes(data[at + 1:at + 9], "little")
        body = at + 9
        if op == 0x06:                                          # a chunk: walk its records
            size = int.from_bytes(data[body + 28:body + 32], "little")
            assert data[body + 32:body + 32 + size] == b""     # no compression
            rec = body + 32 + size + 8
            end = rec + int.from_bytes(data[body + 32 + size:rec], "little")
            while rec < end:
                if data[rec] == 0x05:
                    if seen == k:
                        data[rec] = 0x7F
                        mcap.write_bytes(bytes(data))
                        return
                    seen += 1
                rec += 9 + int.from_bytes(data[rec + 1:rec + 9], "little")
        at = body + length
    raise AssertionError(f"no message record {k}")


def test_a_message_the_bag_declares_but_cannot_give_is_exit_2_naming_both_counts(
        cell, tmp_path, capsys):
    s, scen, traj_csv, traj, tol = cell
    ns, t, a = samples(traj, tol, samples=200)
    folder = write_bag(tmp_path / "bag", ns, a, TRAJECTORY_COLUMNS[1:])
    inner = next(folder.glob("*.mcap"))
    lone = tmp_path / "lone.mcap"
    lone.write_bytes(inner.read_bytes())
    _flip_message_opcode(lone, 120)
    out = tmp_path / "m.json"
    argv = ["monitor", str(scen), "--traj", str(traj_csv), "--log", str(lone), "--json", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert ("--log has 199 messages on /joint_states that can be read, of the 200 the bag "
            "declares (its mcap summary): 1 skipped or lost") in err
    assert "--allow-gaps" in err and len(err.strip().splitlines()) == 1 and not out.exists()
    # --allow-gaps: monitored all the same, the time around the lost message unobserved.
    assert main([*argv, "--allow-gaps"]) == 1
    doc = json.loads(out.read_text())
    assert doc["status"] == "unobserved" and doc["missing_messages"] == 1
    (u,) = doc["unobserved"]["listed"]
    assert u["why"] == MISSING_MESSAGES and u["line"] == 121       # message 120, then the lost
    assert u["t_s"] == pytest.approx(t[119]) and u["length_s"] == pytest.approx(t[121] - t[119])
    said = capsys.readouterr().out
    assert "1 message(s) the bag declares on /joint_states were not read" in said
    # A certify --traj bag has no --allow-gaps: a trajectory missing a waypoint is another one.
    assert main(["certify", str(scen), "--traj", str(lone)]) == 2
    assert "199 messages" in capsys.readouterr().err


def test_a_folder_whose_metadata_declares_more_is_exit_2_or_wholly_unobserved(
        cell, tmp_path, capsys):
    s, scen, traj_csv, traj, tol = cell
    ns, t, a = samples(traj, tol, samples=50)
    folder = write_bag(tmp_path / "bag", ns, a, TRAJECTORY_COLUMNS[1:],
                       storage=StoragePlugin.SQLITE3)
    meta = folder / "metadata.yaml"
    meta.write_text(meta.read_text().replace("message_count: 50", "message_count: 52"))
    argv = ["monitor", str(scen), "--traj", str(traj_csv), "--log", str(folder)]
    assert main(argv) == 2
    assert "of the 52 the bag declares (its metadata.yaml): 2 skipped" in capsys.readouterr().err
    # No message index says when they were lost (sqlite3): no time is vouched for.
    assert main([*argv, "--allow-gaps", "--json", str(tmp_path / "m.json")]) == 1
    doc = json.loads((tmp_path / "m.json").read_text())
    assert doc["status"] == "unobserved" and doc["covered_fraction"] == 0.0
    assert "2 message(s) the bag declares were not read" in doc["unobserved"]["first"]["why"]
    # --allow-gaps is for a bag log only.
    log = tmp_path / "log.csv"
    log.write_bytes(log_csv(t, a))
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(log),
                 "--allow-gaps"]) == 2
    assert "--allow-gaps applies to a ROS 2 bag log only" in capsys.readouterr().err


def test_a_joint_named_twice_in_a_message_is_exit_2(cell, tmp_path, capsys):
    s, scen, traj_csv, traj, tol = cell
    ns, t, a = samples(traj, tol, samples=20)
    twice = np.column_stack([a, a[:, 2]])                       # right1's name again, last
    bag = write_bag(tmp_path / "bag", ns, twice, [*TRAJECTORY_COLUMNS[1:], "right1"])
    out = tmp_path / "m.json"
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(bag), "--json",
                 str(out)]) == 2
    err = capsys.readouterr().err
    assert ("error: joint 'right1' is named twice in message 1 on /joint_states (at positions 2 "
            "and 4 of its 5 names)") in err
    assert not out.exists() and "Traceback" not in err


def test_every_sample_outside_well_past_the_start_suggests_t0(cell, tmp_path, capsys):
    # A bag recorded from t = 0.3 s on the trajectory's clock: by default t counts from its
    # first stamp, so every sample is compared 0.3 s early.
    s, scen, traj_csv, traj, tol = cell
    t, a = simulate_log(traj)
    keep = t >= 0.3
    ns = np.round(t[keep] * 1e9).astype(np.int64)
    bag = write_bag(tmp_path / "late", ns, a[keep], TRAJECTORY_COLUMNS[1:])
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(bag)]) == 1
    out = capsys.readouterr().out
    n = int(keep.sum())
    assert f"outside ({n} of {n} samples)" in out
    hint = next(x for x in out.splitlines() if x.startswith("hint"))
    assert "t counts from the bag's first stamp, 0.3 s" in hint and "--t0 0" in hint
    # Given --t0 0, it is the trajectory's time: no sample outside (its first 0.3 s are
    # unobserved: the log began late), and no hint.
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(bag),
                 "--t0", "0"]) == 1
    out = capsys.readouterr().out
    assert ": unobserved (1 interval(s)" in out and "hint" not in out and "outside (" not in out


def test_simulate_writes_a_bag_for_mcap_db3_or_a_folder_and_csv_otherwise(cell, tmp_path, capsys):
    s, scen, traj_csv, traj, tol = cell
    base = ["simulate", str(scen), "--traj", str(traj_csv), "--samples", "30", "--out"]
    for name in ("run.mcap", "run.db3", "rundir/", "run.csv", "run"):
        assert main([*base, f"{tmp_path}/{name}"]) == 0, name
    assert (tmp_path / "run.db3").read_bytes().startswith(b"SQLite format 3\0")
    assert (tmp_path / "run.mcap").read_bytes().startswith(b"\x89MCAP0\r\n")
    assert sorted(p.name for p in (tmp_path / "rundir").iterdir()) == ["metadata.yaml",
                                                                       "rundir.mcap"]
    for name in ("run.csv", "run"):
        assert (tmp_path / name).read_text().startswith("t,left1,left2,right1,right2\n")
    said = capsys.readouterr().out
    assert "wrote     " + str(tmp_path / "run.db3") + " (ROS 2 bag, sqlite3)" in said
    csv = np.loadtxt(tmp_path / "run.csv", delimiter=",", skiprows=1)
    for name in ("run.mcap", "run.db3", "rundir"):
        got = np.concatenate([b for _, b in bag_rows(tmp_path / name, BagOptions(),
                                                     block_rows=1000)])
        assert np.array_equal(got[:, 1:], csv[:, 1:]), name
    # A bag folder is replaced whole; a path ending in / that is a file or another folder is
    # refused before anything is written.
    assert main([*base, str(tmp_path / "rundir")]) == 0
    other = tmp_path / "other"
    other.mkdir()
    (other / "keep.txt").write_text("mine")
    for bad, words in ((f"{other}/", "is a folder that is not a ROS 2 bag"),
                       (f"{tmp_path / 'run.csv'}/", "ends in / but is a file")):
        assert main([*base, bad]) == 2
        err = capsys.readouterr().err
        assert words in err and len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in other.iterdir()) == ["keep.txt"]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]   # no temporary left


def test_a_corrupt_metadata_yaml_is_one_line(cell, tmp_path, capsys):
    s, scen, traj_csv, traj, tol = cell
    bag = tmp_path / "bag"
    bag.mkdir()
    (bag / "metadata.yaml").write_text("rosbag2_bagfile_information:\n  version: [\n  - a: :\n")
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(bag)]) == 2
    err = capsys.readouterr().err
    assert "is not a readable ROS 2 bag" in err and len(err.strip().splitlines()) == 1


def test_a_forged_mcap_record_length_is_not_read_into_memory(tmp_path):
    # Seeded fault in the bag: the summary's first record claims 2^62 bytes. The index reader
    # gives up on the index (None: no declared times) instead of asking for that memory.
    import struct

    from cfmpa.runs._rosbag import MCAP_MAGIC, OP_FOOTER, _declared_log_times

    summary_start = len(MCAP_MAGIC) + 8
    body = MCAP_MAGIC + b"\x00" * 8 + struct.pack("<BQ", 0x04, 2**62)
    footer = struct.pack("<BQ", OP_FOOTER, 20) + struct.pack("<QQI", summary_start, 0, 0)
    bag = tmp_path / "forged.mcap"
    bag.write_bytes(body + footer + MCAP_MAGIC)
    assert _declared_log_times(bag, "/joint_states") is None
