# SPDX-License-Identifier: MIT
"""Map streams in Python: MapFrame decoding, the receiver's Map, read_map,
plotting, against `bsf extract --map` and `bsf map --json`."""
import json

import numpy as np
import pytest

import bsf
from conftest import run_tool

pytestmark = pytest.mark.skipif(not hasattr(bsf._core, "MapReceiver"), reason="this build has no map")

# A 6 m x 4 m room (walls x = 0, 6 and y = 0, 4) with a pillar of radius 0.3 at (4, 2.5).
WALLS = [((0.0, 0.0), (6.0, 0.0)), ((6.0, 0.0), (6.0, 4.0)), ((6.0, 4.0), (0.0, 4.0)), ((0.0, 4.0), (0.0, 0.0))]
PILLAR = ((4.0, 2.5), 0.3)


def _ranges(x, y, theta, n=361, fov=np.radians(270.0), sigma=0.005, seed=0):
    """Ray-cast the room from the laser at (x, y, theta): ranges, angle_min, increment."""
    rng = np.random.default_rng(seed)
    amin = -fov / 2.0
    inc = fov / (n - 1)
    a = theta + amin + inc * np.arange(n)
    d = np.stack([np.cos(a), np.sin(a)], axis=1)
    best = np.full(n, np.inf)
    for (x0, y0), (x1, y1) in WALLS:
        ex, ey = x1 - x0, y1 - y0
        den = d[:, 0] * ey - d[:, 1] * ex
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((x0 - x) * ey - (y0 - y) * ex) / den
            u = ((x0 - x) * d[:, 1] - (y0 - y) * d[:, 0]) / den
        ok = (np.abs(den) > 1e-12) & (t > 0) & (u >= 0) & (u <= 1)
        best = np.where(ok & (t < best), t, best)
    (cx, cy), r = PILLAR
    c = np.array([cx - x, cy - y])
    b = d @ c
    disc = b * b - (c @ c - r * r)
    t = b - np.sqrt(np.maximum(disc, 0.0))
    best = np.where((disc > 0) & (t > 0) & (t < best), t, best)
    ranges = (best + rng.normal(0.0, sigma, n)).astype(np.float32)
    return ranges, float(np.float32(amin)), float(np.float32(inc))


def _write_log(path, n_scans=40):
    with open(path, "w") as f:
        for i in range(n_scans):
            x, y, th = 1.0 + 2.5 * i / n_scans, 1.5 + 0.5 * i / n_scans, 0.2 * np.sin(i / 7.0)
            ranges, amin, inc = _ranges(x, y, th, seed=i)
            fov = inc * (len(ranges) - 1)
            vals = " ".join("%.9g" % v for v in ranges)
            f.write(
                f"ROBOTLASER1 0 {amin:.9g} {fov:.9g} {inc:.9g} 30 0.01 0 {len(ranges)} {vals} 0 "
                f"{x:.6f} {y:.6f} {th:.6f} {x:.6f} {y:.6f} {th:.6f} 0 0 0 0 0 {100.0 + 0.1 * i:.6f} host {0.1 * i:.6f}\n"
            )


def _dist_to_room(p):
    best = np.full(len(p), np.inf)
    for (x0, y0), (x1, y1) in WALLS:
        e = np.array([x1 - x0, y1 - y0])
        t = np.clip(((p - [x0, y0]) @ e) / (e @ e), 0.0, 1.0)
        best = np.minimum(best, np.hypot(*(np.array([x0, y0]) + t[:, None] * e - p).T))
    (cx, cy), r = PILLAR
    return np.minimum(best, np.abs(np.hypot(p[:, 0] - cx, p[:, 1] - cy) - r))


@pytest.fixture(scope="module")
def map_stream(bsf_tool, tmp_path_factory):
    d = tmp_path_factory.mktemp("map")
    log = d / "room.log"
    _write_log(log)
    out = d / "room.map"
    run_tool(bsf_tool, "extract", log, "--map", "--reproducible", "-o", out)
    return log, out


def test_map_frames_decode_and_rebuild(map_stream):
    _, out = map_stream
    frames = bsf.decode(out.read_bytes())
    assert isinstance(frames[0], bsf.Metadata)
    maps = [f for f in frames if isinstance(f, bsf.MapFrame)]
    assert len(maps) >= 2
    assert [f.seq for f in maps] == list(range(maps[0].seq, maps[0].seq + len(maps)))
    assert not any(isinstance(f, bsf.Frame) for f in frames)  # map only, no per-scan features
    m = bsf.Map()
    skipped = sum(m.apply(f) for f in maps)
    assert skipped == 0 and m.frames == len(maps)
    assert m.bytes == sum(f.bytes for f in maps)
    feats = m.features
    assert len(feats) >= 3
    assert len(m.path) == 40  # a pose record per scan, the default
    assert m.pose == m.path[-1]


def test_map_equals_bsf_map_json(bsf_tool, map_stream):
    _, out = map_stream
    py = bsf.read_map(out).features
    lines = run_tool(bsf_tool, "map", out, "--json").stdout.decode().splitlines()
    cli = [json.loads(l) for l in lines]
    assert [f.id for f in py] == [c["id"] for c in cli]
    for f, c in zip(py, cli):
        assert np.allclose(f.ctrl, np.asarray(c["ctrl"]), atol=1e-4)
        assert f.vertex.tolist() == c["vertex"]
        assert f.stale is c["stale"]


def test_map_lies_on_the_walls(map_stream):
    _, out = map_stream
    feats = bsf.read_map(out).features
    # a straight wall between two vertices is one span: sample densely
    pts = np.concatenate([f.sample(256) for f in feats])
    d = _dist_to_room(pts)
    assert np.median(d) < 0.015
    assert np.quantile(d, 0.90) < 0.03
    assert d.max() < 0.15  # no curve strays from the room
    # the wall y = 0 is covered along most of its length
    xs = np.linspace(0.3, 5.7, 55)
    near = [np.min(np.hypot(pts[:, 0] - x, pts[:, 1])) < 0.05 for x in xs]
    assert np.mean(near) > 0.8
    assert sum(f.length() for f in feats) < 1.3 * 20.0  # no wall drawn twice over


def test_read_map_refuses_other_streams(bsf_tool, map_stream, tmp_path):
    log, _ = map_stream
    per_scan = tmp_path / "room.bsf"
    run_tool(bsf_tool, "extract", log, "-o", per_scan)
    with pytest.raises(bsf.BsfError, match="no map frame"):
        bsf.read_map(per_scan)
    garbage = tmp_path / "garbage.bin"
    garbage.write_bytes(bytes(range(1, 256)) * 8)
    with pytest.raises(bsf.BsfError):
        bsf.read_map(garbage)


def test_map_apply_checks_its_input():
    m = bsf.Map()
    with pytest.raises(TypeError):
        m.apply(b"\x13\x00")
    with pytest.raises(bsf.BsfError):
        m.apply(bsf.MapFrame(seq=0, payload=b"\x01\x02\x03"))
    assert m.frames == 0 and m.features == []


def test_map_feature_sample_is_the_curve():
    ctrl = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1.0, 1.0]], dtype=np.float32)
    f = bsf.MapFeature(id=0, ctrl=ctrl, vertex=np.array([0, 1, 1, 0], dtype=np.uint8))
    p = f.sample(8)
    assert np.allclose(p[0], ctrl[0]) and np.allclose(p[-1], ctrl[-1])
    assert np.allclose(f.vertices, [[1.0, 0.0]])
    assert any(np.allclose(q, [1.0, 0.0]) for q in p)  # the curve passes through the vertex
    assert abs(f.length() - 2.0) < 1e-9  # two straight spans of 1 m
    with pytest.raises(bsf.BsfError):
        f.sample(0)


def test_plot_map(map_stream):
    mpl = pytest.importorskip("matplotlib")
    mpl.use("Agg")
    _, out = map_stream
    m = bsf.read_map(out)
    ax = bsf.plot(m)
    assert len(ax.collections) == 1 and len(ax.collections[0].get_segments()) == len(m.features)
    labels = [l.get_label() for l in ax.get_lines()]
    assert "vertices" in labels or all(len(f.vertices) == 0 for f in m.features)
    assert "robot path" in labels


def test_python_m_bsf_plot_draws_a_map_stream(map_stream, tmp_path):
    pytest.importorskip("matplotlib")
    import subprocess
    import sys

    _, out = map_stream
    png = tmp_path / "map.png"
    r = subprocess.run([sys.executable, "-m", "bsf", "plot", str(out), "-o", str(png)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "map features drawn" in r.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_snapshots_repair_a_lost_frame(bsf_tool, map_stream, tmp_path):
    log, _ = map_stream
    out = tmp_path / "snap.map"
    run_tool(bsf_tool, "extract", log, "--map", "--snapshot-budget", "200", "--reproducible", "-o", out)
    frames = [f for f in bsf.decode(out.read_bytes()) if isinstance(f, bsf.MapFrame)]
    full = bsf.Map()
    for f in frames:
        full.apply(f)
    # lose the first frame that carries more than a pose: the one that made the map
    lost = [i for i, f in enumerate(frames) if len(f.payload) > 16][0]
    lossy = bsf.Map()
    for i, f in enumerate(frames):
        if i != lost:
            lossy.apply(f)
    assert lossy.counters["frames_missed"] == 1
    assert lossy.counters["snapshots"] > 0
    # the snapshot rounds after the loss restore every feature exactly (without
    # snapshots the whole map of this room would be missing)
    got = {f.id: f for f in lossy.features}
    want = {f.id: f for f in full.features}
    assert set(got) == set(want)
    for fid, f in want.items():
        assert np.array_equal(got[fid].ctrl, f.ctrl) and np.array_equal(got[fid].vertex, f.vertex)
        assert not got[fid].stale


def test_a_lost_frame_leaves_nothing_wrong_without_a_word(map_stream):
    """Without snapshots, a lost frame: every feature either equals the
    lossless map's or is stale, and ids never received are listed missing."""
    _, out = map_stream
    frames = [f for f in bsf.decode(out.read_bytes()) if isinstance(f, bsf.MapFrame)]
    full = bsf.Map()
    for f in frames:
        full.apply(f)
    assert full.missing == [] and not any(f.stale for f in full.features)
    lost = [i for i, f in enumerate(frames) if len(f.payload) > 16][0]
    lossy = bsf.Map()
    for i, f in enumerate(frames):
        if i != lost:
            lossy.apply(f)
    got = {f.id: f for f in lossy.features}
    want = {f.id: f for f in full.features}
    flagged = 0
    for fid, f in want.items():
        if fid not in got:
            # below the largest id seen: listed; above it: maybe more are missing
            assert fid in lossy.missing or lossy.more_missing
            flagged += 1
        elif not (np.array_equal(got[fid].ctrl, f.ctrl) and np.array_equal(got[fid].vertex, f.vertex)):
            assert got[fid].stale
            flagged += 1
    assert flagged > 0  # the frame that made the map was lost


def test_a_damaged_last_frame_flags_every_feature(map_stream, tmp_path):
    _, out = map_stream
    data = bytearray(out.read_bytes())
    assert data[-1] == 0
    # a byte in the middle of the last frame (after the last delimiter but one)
    start = data.rindex(0, 0, len(data) - 1) + 1
    at = (start + len(data) - 1) // 2
    data[at] = data[at] ^ 0x01 or 0x01
    bad = tmp_path / "bad_last.map"
    bad.write_bytes(bytes(data))
    m = bsf.read_map(bad)
    assert m.features and all(f.stale for f in m.features)
    m2 = bsf.Map()
    for f in bsf.decode(bytes(data)):
        if isinstance(f, bsf.MapFrame):
            m2.apply(f)
    assert not any(f.stale for f in m2.features)  # what the receiver cannot know alone
    m2.note_loss()
    assert all(f.stale for f in m2.features)
