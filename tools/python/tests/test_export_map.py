# SPDX-License-Identifier: MIT
"""python -m bsf export of a map stream (bsf extract --map): read back with
the mcap reader and with rosbags, /bsf/map holds the receiver's whole map at
the frames it was published after (its curves sampled per span, its vertices,
the feature ids, stale features in grey), /bsf/pose and /bsf/path the pose
records, every stamp the metadata's time origin plus the frame's sequence
number over the map frame rate."""
import math
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("rosbags", reason="rosbags (the 'rosbag' extra) is not installed")
pytest.importorskip("mcap_ros2", reason="mcap-ros2-support (the 'rosbag' extra) is not installed")

from mcap.reader import make_reader  # noqa: E402

import bsf  # noqa: E402
from bsf.export import ADD, COLORS, DELETEALL, LINE_STRIP, SPHERE_LIST, ExportError, Exporter  # noqa: E402
from conftest import run_tool  # noqa: E402
from test_export import _points, _read_bag, _read_mcap, _stamp  # noqa: E402
from test_map import _ranges  # noqa: E402

pytestmark = pytest.mark.skipif(not hasattr(bsf._core, "MapReceiver"), reason="this build has no map")

T0_S = 1_700_000_000.25  # the log's first scan, seconds since 1970
N_SCANS = 40
PER_SPAN = 4


def run_py(*args):
    return subprocess.run([sys.executable, "-m", "bsf", *map(str, args)], capture_output=True, text=True, timeout=300)


def _write_log(path):
    """The room of test_map, seen from a robot moving along a line, at 10 Hz from T0_S."""
    with open(path, "w") as f:
        for i in range(N_SCANS):
            x, y, th = 1.0 + 2.5 * i / N_SCANS, 1.5 + 0.5 * i / N_SCANS, 0.2 * np.sin(i / 7.0)
            ranges, amin, inc = _ranges(x, y, th, seed=i)
            fov = inc * (len(ranges) - 1)
            vals = " ".join("%.9g" % v for v in ranges)
            t = T0_S + 0.1 * i
            f.write(
                f"ROBOTLASER1 0 {amin:.9g} {fov:.9g} {inc:.9g} 30 0.01 0 {len(ranges)} {vals} 0 "
                f"{x:.6f} {y:.6f} {th:.6f} {x:.6f} {y:.6f} {th:.6f} 0 0 0 0 0 {t:.6f} host {t:.6f}\n"
            )


@pytest.fixture(scope="module")
def map_streams(bsf_tool, tmp_path_factory):
    d = tmp_path_factory.mktemp("mapexport")
    log = d / "room.log"
    _write_log(log)
    out = {}
    for every in (1, 3):
        out[every] = d / f"room-pose{every}.map"
        # a short range, so that the map grows as the robot moves: appends and moves follow its creation
        run_tool(bsf_tool, "extract", log, "--map", "--range-max", 2.5, "--pose-every", every, "--reproducible", "-o", out[every])
    return out


def _items(path):
    return list(bsf.read(path))


def _expected(items, rate, every, per_span=PER_SPAN):
    """What the export must hold, replayed here with the receiver: per map
    frame its stamp and pose (or None); the published maps as (stamp, lines,
    vertices, ids, stale flags)."""
    meta = next(i for i in items if isinstance(i, bsf.Metadata))
    origin = meta.time_origin_us * 1000
    maps = [i for i in items if isinstance(i, bsf.MapFrame)]
    m = bsf.Map()
    frames, published = [], []
    for k, fr in enumerate(maps):
        before = len(m.path)
        m.apply(fr)
        ns = origin + round((fr.seq - maps[0].seq) * 1e9 / rate)
        frames.append((ns, m.path[-1] if len(m.path) > before else None))
        if (k + 1) % every == 0 or k + 1 == len(maps):
            feats = m.features
            lines = [f.sample(per_span) if len(f.ctrl) >= 3 else f.ctrl.astype(np.float64) for f in feats]
            verts = np.concatenate([f.vertices for f in feats]) if feats else np.zeros((0, 2))
            published.append((ns, lines, verts, [f.id for f in feats], [f.stale for f in feats]))
    return frames, published, m


def _check(msgs, items, rate, every):
    frames, published, final = _expected(items, rate, every)
    by_topic = {}
    for topic, mtype, t, msg, _ in msgs:
        by_topic.setdefault(topic, []).append((mtype, t, msg))
    assert set(by_topic) == {"/bsf/map", "/bsf/pose", "/bsf/path"}
    got_maps = by_topic["/bsf/map"]
    assert len(got_maps) == len(published) == math.ceil(len(frames) / every)
    for (mtype, t, arr), (ns, lines, verts, ids, stale) in zip(got_maps, published):
        assert mtype == "visualization_msgs/msg/MarkerArray" and t == ns
        ms = list(arr.markers)
        assert ms[0].action == DELETEALL and all(mk.action == ADD for mk in ms[1:])
        strips = [mk for mk in ms if mk.type == LINE_STRIP]
        spheres = [mk for mk in ms if mk.type == SPHERE_LIST]
        assert len(strips) == len(lines) and len(strips) + len(spheres) + 1 == len(ms)
        assert [mk.id for mk in strips] == ids and all(mk.ns == "map" for mk in strips)
        for mk in ms:
            assert _stamp(mk.header) == ns and mk.header.frame_id == "map"
        for mk, want, st in zip(strips, lines, stale):
            got = _points(mk)
            assert got.shape == (len(want), 3) and np.array_equal(got[:, :2], want) and not got[:, 2].any()
            assert (mk.color.r, mk.color.g, mk.color.b) == pytest.approx(COLORS["stale" if st else "map"][:3])
        if len(verts):
            assert len(spheres) == 1 and np.array_equal(_points(spheres[0])[:, :2], verts)
        else:
            assert not spheres
    # the last message is the receiver's final map of the whole stream
    feats = final.features
    last = [mk for mk in got_maps[-1][2].markers if mk.type == LINE_STRIP]
    assert len(last) == len(feats) > 0
    for mk, f in zip(last, feats):
        want = f.sample(PER_SPAN) if len(f.ctrl) >= 3 else f.ctrl
        assert np.array_equal(_points(mk)[:, :2], want)
    posed = [(ns, p) for ns, p in frames if p is not None]
    assert posed and len(posed) == len(final.path)
    poses = by_topic["/bsf/pose"]
    assert [t for _, t, _ in poses] == [ns for ns, _ in posed]
    for (mtype, _, ps), (_, p) in zip(poses, posed):
        assert mtype == "geometry_msgs/msg/PoseStamped" and ps.header.frame_id == "map"
        q = ps.pose.orientation
        assert [ps.pose.position.x, ps.pose.position.y] == pytest.approx(p[:2], abs=1e-12)
        assert abs(math.remainder(math.atan2(2 * q.w * q.z, 1 - 2 * q.z * q.z) - p[2], 2 * math.pi)) < 1e-9
    ((mtype, t, path),) = by_topic["/bsf/path"]
    assert mtype == "nav_msgs/msg/Path" and t == posed[0][0]
    assert [_stamp(p.header) for p in path.poses] == [ns for ns, _ in posed]
    return frames, got_maps


def test_map_stream_mcap_export_reads_back(map_streams, tmp_path):
    stream = map_streams[1]
    items = _items(stream)
    n_map = sum(isinstance(i, bsf.MapFrame) for i in items)
    assert n_map >= N_SCANS and not any(isinstance(i, bsf.Frame) for i in items)
    out = tmp_path / "map.mcap"
    r = run_py("export", stream, "-o", out, "--map-every", 4, "--map-per-span", PER_SPAN)
    assert r.returncode == 0, r.stderr
    assert f"0 frames, {n_map} map frames exported" in r.stderr
    frames, _ = _check(_read_mcap(out), items, rate=10.0, every=4)
    # stamps: the log's first scan's time, then 0.1 s per map frame (one per scan here)
    assert frames[0][0] == round(T0_S * 1e6) * 1000
    assert frames[1][0] - frames[0][0] == 100_000_000
    with open(out, "rb") as f:
        summary = make_reader(f).get_summary()
        counts = {summary.channels[c].topic: n for c, n in summary.statistics.channel_message_counts.items()}
        assert counts["/bsf/map"] == math.ceil(n_map / 4) and counts["/bsf/path"] == 1


def test_map_stream_ros2bag_export_reads_back(map_streams, tmp_path):
    stream = map_streams[3]  # a pose record every 3 scans
    items = _items(stream)
    out = tmp_path / "map_bag"
    r = run_py("export", stream, "-o", out, "--format", "ros2bag", "--map-every", 1, "--map-rate", 5, "--map-per-span", PER_SPAN)
    assert r.returncode == 0, r.stderr
    frames, _ = _check(_read_bag(out), items, rate=5.0, every=1)
    n_posed = sum(p is not None for _, p in frames)
    assert 0 < n_posed < len(frames)  # only the frames with a pose record give a pose
    assert "durability: 1" in (out / "metadata.yaml").read_text()  # the map and path are offered transient-local


def _split_frames(data):
    """The stream's frames, each with its delimiter."""
    return [p + b"\x00" for p in data.split(b"\x00")[:-1] if p]


def test_a_lost_map_frame_keeps_the_stamps_and_greys_stale_features(map_streams, tmp_path):
    raw = _split_frames(map_streams[1].read_bytes())
    kinds = [type(bsf.decode(f)[0]).__name__ for f in raw]
    maps = [i for i, k in enumerate(kinds) if k == "MapFrame"]
    # lose the first map frame that changes a feature already held (a record,
    # not only a pose), so that the receiver marks features stale
    m = bsf.Map()
    lost = None
    for i in maps:
        before = {f.id: f.ctrl.tobytes() for f in m.features}
        m.apply(bsf.decode(raw[i])[0])
        after = {f.id: f.ctrl.tobytes() for f in m.features}
        if any(fid in after and after[fid] != b for fid, b in before.items()):
            lost = i
            break
    assert lost is not None
    damaged = tmp_path / "lossy.map"
    damaged.write_bytes(b"".join(f for i, f in enumerate(raw) if i != lost))
    items = _items(damaged)
    out = tmp_path / "lossy.mcap"
    r = run_py("export", damaged, "-o", out, "--map-every", 1)
    assert r.returncode == 0, r.stderr
    frames, got_maps = _check(_read_mcap(out), items, rate=10.0, every=1)
    k = maps.index(lost)
    # the frame after the lost one is two periods after the one before it
    assert frames[k][0] - frames[k - 1][0] == 200_000_000
    assert any(
        (mk.color.r, mk.color.g, mk.color.b) == pytest.approx(COLORS["stale"][:3]) for _, _, arr in got_maps for mk in arr.markers
    )


def test_map_export_options_are_checked(map_streams, tmp_path):
    stream = map_streams[1]
    for args, needle in (
        (("--map-rate", "0"), "--map-rate must be"),
        (("--map-rate", "nan"), "--map-rate must be"),
        (("--map-every", "0"), "--map-every must be at least 1"),
        (("--map-per-span", "0"), "--map-per-span must be 1 .. 64"),
    ):
        r = run_py("export", stream, "-o", tmp_path / "x.mcap", *args)
        assert r.returncode == 2 and needle in r.stderr and "Traceback" not in r.stderr, r.stderr
        assert not (tmp_path / "x.mcap").exists()
    for kw in ({"map_rate": 0.0}, {"map_every": 0}, {"map_per_span": 65}):
        with pytest.raises(ExportError):
            Exporter(tmp_path / "y.mcap", "mcap", **kw)
    with Exporter(tmp_path / "z.mcap", "mcap") as ex:
        with pytest.raises(ExportError, match="no map frame"):
            ex.publish_map()
        with pytest.raises(TypeError, match="needs a MapFrame"):
            ex.add_map_frame(next(i for i in _items(stream) if isinstance(i, bsf.Metadata)))
