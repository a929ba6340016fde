# SPDX-License-Identifier: MIT
"""python -m bsf export IN.bsf -o OUT.mcap | -o DIR --format ros2bag: read
back with the mcap reader (mcap-ros2-support's decoder) and with rosbags, the
messages are the stream's: one MarkerArray per scan at its time, a line strip
per feature through the decoded curve's samples, the vertices, the poses and
the path."""
import math
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("rosbags", reason="rosbags (the 'rosbag' extra) is not installed")
pytest.importorskip("mcap_ros2", reason="mcap-ros2-support (the 'rosbag' extra) is not installed")

from mcap.reader import make_reader  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402
from rosbags.highlevel import AnyReader  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

import bsf  # noqa: E402
from bagscene import T0_NS, Bag, raycast, robot_bag, scan_times  # noqa: E402
from bsf.export import ADD, DELETEALL, LINE_STRIP, SPHERE_LIST, Exporter, frame_stamp_ns  # noqa: E402
from conftest import scan_frames  # noqa: E402

SAMPLES = 32


def run_py(*args):
    return subprocess.run([sys.executable, "-m", "bsf", *map(str, args)], capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def posed_stream(tmp_path_factory):
    d = tmp_path_factory.mktemp("posed")
    times = scan_times(n=12)
    bag = robot_bag(times).write(d / "run.bag", "bag")
    out = d / "run.bsf"
    r = run_py("extract", bag, "--topic", "/scan", "--pose-from", "/tf", "-o", out)
    assert r.returncode == 0, r.stderr
    return out, times


def _read_mcap(path):
    """(topic, schema name, log_time, decoded message, raw bytes) of every message."""
    out = []
    with open(path, "rb") as f:
        for schema, channel, message, decoded in make_reader(f, decoder_factories=[DecoderFactory()]).iter_decoded_messages():
            assert channel.message_encoding == "cdr" and schema.encoding == "ros2msg"
            out.append((channel.topic, schema.name, message.log_time, decoded, message.data))
    return out


def _read_bag(path):
    out = []
    with AnyReader([path]) as rd:
        for conn, t, raw in rd.messages():
            out.append((conn.topic, conn.msgtype, t, rd.deserialize(raw, conn.msgtype), raw))
    return out


def _stamp(header):
    return header.stamp.sec * 10**9 + header.stamp.nanosec


def _points(marker):
    return np.array([[p.x, p.y, p.z] for p in marker.points], dtype=np.float64).reshape(-1, 3)


def _check_messages(msgs, frames, frame_id="map", posed=True):
    by_topic = {}
    for topic, mtype, t, m, _ in msgs:
        by_topic.setdefault(topic, []).append((mtype, t, m))
    want_topics = {"/bsf/features", "/bsf/pose", "/bsf/path"} if posed else {"/bsf/features"}
    assert set(by_topic) == want_topics
    feats = by_topic["/bsf/features"]
    assert len(feats) == len(frames)
    for (mtype, t, arr), fr in zip(feats, frames):
        assert mtype == "visualization_msgs/msg/MarkerArray"
        ns = frame_stamp_ns(fr)
        assert t == ns
        ms = list(arr.markers)
        assert ms[0].action == DELETEALL and all(m.action == ADD for m in ms[1:])
        lines = [m for m in ms if m.type == LINE_STRIP]
        spheres = [m for m in ms if m.type == SPHERE_LIST]
        assert len(lines) == len(fr.features) and len(lines) + len(spheres) + 1 == len(ms)
        for m in ms:
            assert _stamp(m.header) == ns and m.header.frame_id == frame_id
        for m, feat in zip(lines, fr.features):
            assert m.ns == "features" and m.scale.x > 0 and m.color.a == 1.0
            got = _points(m)
            want = feat.sample(SAMPLES, fr.pose)
            assert got.shape == (SAMPLES, 3) and np.array_equal(got[:, :2], want) and not got[:, 2].any()
        verts = fr.vertices(world=True)
        if len(verts):
            assert len(spheres) == 1 and np.array_equal(_points(spheres[0])[:, :2], verts)
        else:
            assert not spheres
    if not posed:
        return
    poses = by_topic["/bsf/pose"]
    assert [t for _, t, _ in poses] == [frame_stamp_ns(f) for f in frames]
    for (mtype, _, ps), fr in zip(poses, frames):
        assert mtype == "geometry_msgs/msg/PoseStamped" and ps.header.frame_id == frame_id
        q = ps.pose.orientation
        yaw = math.atan2(2 * q.w * q.z, 1 - 2 * q.z * q.z)
        assert np.allclose([ps.pose.position.x, ps.pose.position.y], fr.pose[:2], atol=1e-12)
        assert abs(math.remainder(yaw - fr.pose[2], 2 * math.pi)) < 1e-9
    (mtype, t, path), = by_topic["/bsf/path"]
    assert mtype == "nav_msgs/msg/Path" and t == frame_stamp_ns(frames[0])
    assert [_stamp(p.header) for p in path.poses] == [frame_stamp_ns(f) for f in frames]
    assert np.allclose([[p.pose.position.x, p.pose.position.y] for p in path.poses], [f.pose[:2] for f in frames], atol=1e-12)


def test_mcap_export_reads_back(posed_stream, tmp_path):
    stream, times = posed_stream
    frames = scan_frames(bsf.decode(stream.read_bytes()))
    # the scans' own header stamps (ms) are the messages' stamps
    assert [frame_stamp_ns(f) for f in frames] == [T0_NS + round(t * 1000) * 10**6 for t in times]
    out = tmp_path / "run.mcap"
    r = run_py("export", stream, "-o", out)
    assert r.returncode == 0, r.stderr
    assert f"{len(frames)} frames exported" in r.stderr
    msgs = _read_mcap(out)
    _check_messages(msgs, frames)
    # the summary and index a viewer seeks with: the ros2 profile, per-channel counts
    with open(out, "rb") as f:
        rd = make_reader(f)
        assert rd.get_header().profile == "ros2"
        summary = rd.get_summary()
        counts = {summary.channels[c].topic: n for c, n in summary.statistics.channel_message_counts.items()}
        assert counts == {"/bsf/features": len(frames), "/bsf/pose": len(frames), "/bsf/path": 1}
        assert summary.chunk_indexes and summary.statistics.message_start_time == frame_stamp_ns(frames[0])
    # the CDR bytes are what rosbags' ROS 2 Humble definitions read too
    store = get_typestore(Stores.ROS2_HUMBLE)
    for topic, mtype, _, m, raw in msgs:
        back = store.deserialize_cdr(raw, mtype)
        if topic == "/bsf/features":
            assert [mk.type for mk in back.markers] == [mk.type for mk in m.markers]
            assert len(back.markers[1].points) == SAMPLES


def test_ros2_bag_export_reads_back(posed_stream, tmp_path):
    stream, _ = posed_stream
    frames = scan_frames(bsf.decode(stream.read_bytes()))
    out = tmp_path / "viewer_bag"
    r = run_py("export", stream, "-o", out, "--format", "ros2bag")
    assert r.returncode == 0, r.stderr
    assert (out / "metadata.yaml").is_file()
    _check_messages(_read_bag(out), frames)
    meta = (out / "metadata.yaml").read_text()
    assert "durability: 1" in meta  # the path is offered transient-local
    # an existing directory is never written into
    r = run_py("export", stream, "-o", out, "--format", "ros2bag")
    assert r.returncode == 1 and "exists" in r.stderr and "Traceback" not in r.stderr


def test_export_of_frames_without_pose_uses_the_laser_frame(tmp_path):
    b = Bag()
    for i in range(3):
        b.scan(T0_NS + i * 100_000_000, "laser", *raycast((0.2, 0.1, 0.3 * i), seed=i))
    bag = b.write(tmp_path / "plain.bag", "bag")
    stream = tmp_path / "plain.bsf"
    assert run_py("extract", bag, "--topic", "/scan", "-o", stream).returncode == 0
    frames = scan_frames(bsf.decode(stream.read_bytes()))
    assert all(f.pose is None for f in frames)
    out = tmp_path / "plain.mcap"
    r = run_py("export", stream, "-o", out, "--laser-frame", "base_scan", "--samples", str(SAMPLES))
    assert r.returncode == 0, r.stderr
    _check_messages(_read_mcap(out), frames, frame_id="base_scan", posed=False)


def test_map_hook_writes_markers_on_its_own_topic(posed_stream, tmp_path):
    stream, _ = posed_stream
    frames = scan_frames(bsf.decode(stream.read_bytes()))
    out = tmp_path / "hook.mcap"
    curves = [np.array([[0.0, 0.0], [1.0, 0.5], [2.0, 0.0]]), np.array([[3.0, 3.0], [3.0, -1.0]])]
    with Exporter(out, "mcap", samples=SAMPLES) as ex:
        for f in frames:
            ex.add_frame(f)
        ex.add_markers("/bsf/map", frame_stamp_ns(frames[-1]), curves, np.array([[1.0, 0.5]]), ns="map")
        with pytest.raises(Exception, match="line 0 is not two or more finite"):
            ex.add_markers("/bsf/map", 0, [np.array([[np.nan, 0.0], [1.0, 1.0]])])
    msgs = [m for m in _read_mcap(out) if m[0] == "/bsf/map"]
    assert len(msgs) == 1
    ms = msgs[0][3].markers
    assert [m.action for m in ms] == [DELETEALL, ADD, ADD, ADD]
    assert [m.type for m in ms[1:]] == [LINE_STRIP, LINE_STRIP, SPHERE_LIST]
    assert np.array_equal(_points(ms[1])[:, :2], curves[0]) and np.array_equal(_points(ms[2])[:, :2], curves[1])
    _check_messages([m for m in _read_mcap(out) if m[0] != "/bsf/map"], frames)


def test_export_errors_are_clear(posed_stream, tmp_path):
    stream, _ = posed_stream
    for args, needle in (
        ((stream, "-o", tmp_path / "x.bin"), "name an MCAP file"),
        ((tmp_path / "missing.bsf", "-o", tmp_path / "x.mcap"), "missing.bsf"),
        ((stream, "-o", tmp_path / "x.mcap", "--samples", "1"), "--samples must be at least 2"),
        ((stream, "-o", tmp_path / "x.mcap", "--prefix", "bsf"), "must start with '/'"),
    ):
        r = run_py("export", *args)
        assert r.returncode != 0 and needle in r.stderr and "Traceback" not in r.stderr, r.stderr
    junk = tmp_path / "junk.bsf"
    junk.write_bytes(bytes(range(1, 200)) + b"\x00")
    r = run_py("export", junk, "-o", tmp_path / "j.mcap")
    assert r.returncode == 1 and "no valid bsf frame" in r.stderr and "Traceback" not in r.stderr
    # a stream of metadata only holds no scan
    meta_only = tmp_path / "meta.bsf"
    meta_only.write_bytes(bsf.encode(next(f for f in bsf.decode(stream.read_bytes()) if isinstance(f, bsf.Metadata))))
    r = run_py("export", meta_only, "-o", tmp_path / "m.mcap")
    assert r.returncode == 1 and "holds no scan frame" in r.stderr
    assert not (tmp_path / "m.mcap").exists() and not (tmp_path / "j.mcap").exists()  # nothing half-written left
    r = run_py("export", meta_only, "-o", tmp_path / "m_bag", "--format", "ros2bag")
    assert r.returncode == 1 and not (tmp_path / "m_bag").exists()
