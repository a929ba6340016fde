# SPDX-License-Identifier: MIT
"""python -m bsf extract BAG --topic /scan: ROS 1 .bag and ROS 2 .db3 / .mcap
bags written here with rosbags give the frames `bsf extract` gives on the
same scans; bad bags and messages give a message and a non-zero exit."""
import subprocess
import sys

import numpy as np
import pytest

rosbags = pytest.importorskip("rosbags", reason="rosbags (the 'rosbag' extra) is not installed")
from rosbags.rosbag1 import Writer as Writer1  # noqa: E402
from rosbags.rosbag2 import StoragePlugin, Writer as Writer2  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

import bsf  # noqa: E402
from conftest import canonical, run_tool, scan_frames, synthetic_scan, write_robotlaser_log  # noqa: E402

SCAN = "sensor_msgs/msg/LaserScan"
T0_NS = 1_700_000_000_123_456_789  # header stamps: Nov 2023, sub-ms part to round


def _msg(store, i, ranges, amin, inc, rmin, rmax, stamp_ns):
    T = store.types
    header = dict(stamp=T["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9), frame_id="laser")
    if "seq" in T["std_msgs/msg/Header"].__dataclass_fields__:
        header["seq"] = i
    return T[SCAN](
        header=T["std_msgs/msg/Header"](**header),
        angle_min=amin,
        angle_max=amin + inc * (len(ranges) - 1),
        angle_increment=inc,
        time_increment=0.0,
        scan_time=0.1,
        range_min=rmin,
        range_max=rmax,
        ranges=np.asarray(ranges, dtype=np.float32),
        intensities=np.zeros(0, dtype=np.float32),
    )


def write_bag(path, kind, scans, topic="/scan", msgtype=SCAN, raw=None):
    """scans: (ranges, angle_min, inc, range_min, range_max, stamp_ns[, record_ns]): the
    header stamp, and the bag's record time (default: the stamp). kind: bag, db3, mcap.
    raw: list of raw message bytes to write instead (malformed-message tests)."""
    if kind == "bag":
        store = get_typestore(Stores.ROS1_NOETIC)
        with Writer1(path) as w:
            conn = w.add_connection(topic, msgtype, typestore=store)
            for i, s in enumerate(scans):
                w.write(conn, s[-1], store.serialize_ros1(_msg(store, i, *s[:6]), SCAN))
            for i, data in enumerate(raw or []):
                w.write(conn, T0_NS + 10**10 + i, data)
        return path
    store = get_typestore(Stores.ROS2_HUMBLE)
    plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
    with Writer2(path, version=8, storage_plugin=plugin) as w:
        conn = w.add_connection(topic, msgtype, typestore=store)
        for i, s in enumerate(scans):
            w.write(conn, s[-1], store.serialize_cdr(_msg(store, i, *s[:6]), SCAN))
        for i, data in enumerate(raw or []):
            w.write(conn, T0_NS + 10**10 + i, data)
    return path


def _unix_ms(frame):
    """A frame's absolute time, ms: through the metadata's origin (format 2) or as sent."""
    if frame.metadata is not None:
        return round(frame.unix_time_ms)
    return frame.timestamp_ms


def _assert_times(frames, scans):
    """Each frame's time is its message's header stamp (within the 1 ms the
    origin's sub-millisecond part can add when times are relative to it)."""
    want = [(s[5] + 500_000) // 1_000_000 for s in scans]
    got = [_unix_ms(f) for f in frames]
    assert len(got) == len(want)
    slack = 1 if frames and frames[0].metadata is not None else 0
    assert all(abs(g - w) <= slack for g, w in zip(got, want)), (got[:5], want[:5])


def run_py(*args):
    return subprocess.run([sys.executable, "-m", "bsf", *map(str, args)], capture_output=True, text=True)


def synthetic_bag_scans():
    out = []
    for i in range(5):
        ranges, amin, inc = synthetic_scan(n=541 + 40 * i, seed=10 + i)
        out.append((ranges, amin, inc, 0.0, 30.0, T0_NS + i * 100_000_000))
    return out


@pytest.mark.parametrize("kind", ["bag", "db3", "mcap"])
def test_bag_frames_equal_cli_frames(kind, bsf_tool, tmp_path):
    scans = synthetic_bag_scans()
    bag = write_bag(tmp_path / ("scans.bag" if kind == "bag" else "scans"), kind, scans)
    if kind != "bag":  # the .db3 / .mcap file inside the bag directory works too
        bag = next(bag.glob("*." + kind))
    out = tmp_path / "bag.bsf"
    r = run_py("extract", bag, "--topic", "/scan", "-o", out)
    assert r.returncode == 0, r.stderr
    assert "5 scans of /scan" in r.stderr
    got = scan_frames(bsf.decode(out.read_bytes()))
    # frame time = header stamp (ms since the epoch, or since the metadata's origin); no pose
    _assert_times(got, scans)
    assert all(f.pose is None for f in got) and [f.seq for f in got] == list(range(5))
    log = tmp_path / "same.log"
    write_robotlaser_log(log, [s[:3] for s in scans], max_range=30.0)
    cli = tmp_path / "cli.bsf"
    run_tool(bsf_tool, "extract", log, "-o", cli)
    assert canonical(got) == canonical(bsf.decode(cli.read_bytes()))


def test_message_geometry_and_range_limits_are_honoured(tmp_path):
    ranges, amin, inc = synthetic_scan(n=541, seed=3)
    near = (ranges, amin, inc, 0.0, 2.0, T0_NS)  # range_max 2 m drops the far walls
    mirrored = (ranges[::-1].copy(), -amin, -inc, 0.0, 30.0, T0_NS + 1)  # clockwise beams: same scan
    raised_min = (ranges, amin, inc, 1.5, 30.0, T0_NS + 2)
    bag = write_bag(tmp_path / "g.bag", "bag", [(ranges, amin, inc, 0.0, 30.0, T0_NS), near, mirrored, raised_min])
    out = tmp_path / "g.bsf"
    assert run_py("extract", bag, "--topic", "/scan", "-o", out).returncode == 0
    full, cut, mirror, high = scan_frames(bsf.decode(out.read_bytes()))
    valid = np.isfinite(ranges) & (ranges > 0)
    assert full.stats.n_valid == int(np.sum(valid & (ranges < 30.0)))
    assert cut.stats.n_valid == int(np.sum(valid & (ranges < 2.0))) < full.stats.n_valid
    assert high.stats.n_valid == int(np.sum(valid & (ranges >= np.float32(1.5)) & (ranges < 30.0)))
    assert mirror.stats.n_valid == full.stats.n_valid
    # the mirrored scan's curves cover the same places (sensor frame)
    a = np.concatenate(full.sample(20))
    b = np.concatenate(mirror.sample(20))
    d = np.min(np.hypot(a[:, None, 0] - b[None, :, 0], a[:, None, 1] - b[None, :, 1]), axis=1)
    assert np.median(d) < 0.02


def test_intel_slice_in_a_bag_equals_cli(bsf_tool, intel_log, tmp_path):
    carmen = list(zip(range(60), bsf.read_carmen(intel_log)))
    scans = [
        # Intel's log times step back now and then: the bag's record time keeps
        # the log's order, the header keeps the log's time
        (s.ranges, s.angle_min, s.angle_increment, 0.0, s.range_max, int(round(s.timestamp * 1e9)), T0_NS + i * 10**8)
        for i, s in carmen
    ]
    bag = write_bag(tmp_path / "intel", "mcap", scans)
    out = tmp_path / "intel_bag.bsf"
    r = run_py("extract", bag, "--topic", "/scan", "-o", out)
    assert r.returncode == 0, r.stderr
    cli = tmp_path / "cli.bsf"
    run_tool(bsf_tool, "extract", intel_log, "--count", 60, "-o", cli)
    got = scan_frames(bsf.decode(out.read_bytes()))
    assert len(got) == 60
    _assert_times(got, scans)
    assert canonical(got) == canonical(bsf.decode(cli.read_bytes()))


def _assert_clean_failure(r, *needles):
    assert r.returncode != 0
    assert "Traceback" not in r.stderr, r.stderr
    for n in needles:
        assert n in r.stderr, r.stderr


def test_bad_bags_and_messages(tmp_path):
    good = synthetic_bag_scans()[:2]
    bag = write_bag(tmp_path / "ok.bag", "bag", good)
    _assert_clean_failure(run_py("extract", bag, "--topic", "/laser", "-o", tmp_path / "o"), "no topic /laser", "/scan")
    _assert_clean_failure(run_py("extract", bag, "-o", tmp_path / "o"), "needs --topic")
    store = get_typestore(Stores.ROS1_NOETIC)
    wrong = tmp_path / "wrong.bag"
    with Writer1(wrong) as w:
        conn = w.add_connection("/scan", "std_msgs/msg/String", typestore=store)
        w.write(conn, T0_NS, store.serialize_ros1(store.types["std_msgs/msg/String"](data="hi"), "std_msgs/msg/String"))
    _assert_clean_failure(run_py("extract", wrong, "--topic", "/scan", "-o", tmp_path / "o"), "std_msgs/msg/String", "only sensor_msgs/LaserScan")
    junk = tmp_path / "junk.bag"
    junk.write_bytes(b"#ROSBAG V2.0\n" + bytes(range(256)) * 8)
    _assert_clean_failure(run_py("extract", junk, "--topic", "/scan", "-o", tmp_path / "o"), "cannot read the bag")
    _assert_clean_failure(run_py("extract", tmp_path / "missing.bag", "--topic", "/scan", "-o", tmp_path / "o"), "no such file")
    # bad geometry and a truncated message: reported by index, the good scans still written
    r0, a0, i0 = good[0][:3]
    bad = [good[0], (r0, a0, 0.0, 0.0, 30.0, T0_NS + 5), (r0, a0, i0, 0.0, float("nan"), T0_NS + 6), good[1]]
    for kind in ("bag", "db3"):
        path = tmp_path / ("bad.bag" if kind == "bag" else "bad_" + kind)
        write_bag(path, kind, bad, raw=[b"\x01\x02\x03"])
        out = tmp_path / (kind + ".bsf")
        r = run_py("extract", path, "--topic", "/scan", "-o", out)
        _assert_clean_failure(r, "message 1 skipped: angle_increment is 0", "message 2 skipped: range_max is not finite", "message 4 skipped: cannot decode")
        assert [f.seq for f in scan_frames(bsf.decode(out.read_bytes()))] == [0, 3]
    # more beams than this build's cap
    big = [(np.ones(bsf.caps["BSF_MAX_POINTS"] + 1, np.float32), 0.0, 0.001, 0.0, 30.0, T0_NS)]
    r = run_py("extract", write_bag(tmp_path / "big.bag", "bag", big), "--topic", "/scan", "-o", tmp_path / "o")
    _assert_clean_failure(r, "message 0 skipped", "BSF_MAX_POINTS")
