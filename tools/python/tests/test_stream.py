# SPDX-License-Identifier: MIT
"""encode / decode / read, against the C tool's own decoder."""
import dataclasses
import io
import json
import math
import os
import signal
import subprocess
import sys
import threading
from itertools import islice

import numpy as np
import pytest

import bsf
from conftest import run_tool, synthetic_scan


def _frames(n=5):
    out = []
    for i in range(n):
        ranges, amin, inc = synthetic_scan(seed=i)
        out.append(bsf.extract(ranges, amin, inc, 0.05, 30.0, seq=i, timestamp_ms=100 * i, pose=(0.5 * i, 1.0, 0.1 * i)))
    return out


def test_round_trip_within_half_a_step():
    frames = _frames(3)
    data = b"".join(bsf.encode(f, 0.001) for f in frames)
    back = bsf.decode(data)
    assert [f.seq for f in back] == [0, 1, 2]
    for a, b in zip(frames, back):
        assert b.timestamp_ms == a.timestamp_ms and b.quant_step == pytest.approx(0.001)
        assert b.pose == pytest.approx(a.pose, abs=1e-3)
        assert b.stats.n_valid == a.stats.n_valid and len(b.features) == len(a.features)
        for fa, fb in zip(a.features, b.features):
            assert (fa.first_beam, fa.last_beam, fa.n_points, fa.kind) == (fb.first_beam, fb.last_beam, fb.n_points, fb.kind)
            assert np.array_equal(fa.vertex, fb.vertex)
            assert np.max(np.abs(fa.ctrl - fb.ctrl)) <= 0.0005 + 1e-6
            assert abs(fa.e_curve - fb.e_curve) <= 0.00025 + 1e-7
    # re-encoding a decoded frame gives its bytes back exactly
    assert b"".join(bsf.encode(f) for f in back) == data


def test_garbage_and_damage():
    with pytest.raises(bsf.BsfError, match="no valid bsf frame in 5000 bytes"):
        bsf.decode(np.random.default_rng(1).integers(1, 256, 5000, dtype=np.uint8).tobytes())
    with pytest.raises(bsf.BsfError, match="no valid bsf frame"):
        bsf.decode(b"FLASER 180 1.0 2.0\n")
    assert bsf.decode(b"") == []
    with pytest.raises(TypeError):
        bsf.decode("not bytes")
    data = [bsf.encode(f) for f in _frames(3)]
    broken = bytearray(data[1])
    broken[5] ^= 0x40  # one bit flipped inside frame 1
    dec = bsf.Decoder()
    got = dec.feed(data[0] + bytes(broken) + data[2])
    assert [f.seq for f in got] == [0, 2]
    assert dec.counters["frames_ok"] == 2 and dec.counters["bad_crc"] + dec.counters["malformed"] == 1
    # a stream cut in the middle of its last frame delivers the whole ones only
    assert [f.seq for f in bsf.decode(data[0] + data[1][:-7])] == [0]


def test_feed_byte_by_byte_equals_whole():
    data = b"".join(bsf.encode(f) for f in _frames(3))
    dec = bsf.Decoder()
    one = [fr for i in range(len(data)) for fr in dec.feed(data[i : i + 1])]
    assert [bsf.encode(f) for f in one] == [bsf.encode(f) for f in bsf.decode(data)]


def test_read_file_object_path_pipe_and_stdin(tmp_path):
    encoded = [bsf.encode(f) for f in _frames(4)]
    data = b"".join(encoded)
    p = tmp_path / "s.bsf"
    p.write_bytes(data)
    assert [f.seq for f in bsf.read(p)] == [0, 1, 2, 3]
    assert [f.seq for f in bsf.read(io.BytesIO(data))] == [0, 1, 2, 3]
    # a pipe: each frame must come out as soon as its bytes are in, before the writer is done
    r, w = os.pipe()
    src = os.fdopen(r, "rb", buffering=0)

    def _stuck(*_):
        raise TimeoutError("read() did not deliver a complete frame from the pipe")

    old = signal.signal(signal.SIGALRM, _stuck)
    signal.alarm(20)  # a regression fails here instead of hanging the suite
    it = bsf.read(src)
    os.write(w, encoded[0])
    assert next(it).seq == 0  # would block forever if read() waited for a full buffer
    os.write(w, b"".join(encoded[1:]))
    os.close(w)
    assert [f.seq for f in it] == [1, 2, 3]
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)
    src.close()
    code = "import bsf,sys; print([f.seq for f in bsf.read('-')])"
    out = subprocess.run([sys.executable, "-c", code], input=data, capture_output=True, check=True)
    assert out.stdout.strip() == b"[0, 1, 2, 3]"
    with pytest.raises(IsADirectoryError):
        list(bsf.read(tmp_path))
    with pytest.raises(OSError, match="cannot open"):
        list(bsf.read(tmp_path / "missing.bsf"))
    (tmp_path / "junk").write_bytes(b"\x01\x02garbage" * 50)
    with pytest.raises(bsf.BsfError, match="no valid bsf frame"):
        list(bsf.read(tmp_path / "junk"))


def test_read_serial_port_loopback():
    serial = pytest.importorskip("serial", reason="pyserial (the 'serial' extra) is not installed")
    port = serial.serial_for_url("loop://", timeout=0.05)
    frames = _frames(3)

    def send():
        for f in frames:
            port.write(bsf.encode(f))

    t = threading.Thread(target=send)
    t.start()
    got = list(islice(bsf.read(port), 3))  # a live link never ends: take what was sent
    t.join()
    port.close()
    assert [f.seq for f in got] == [0, 1, 2]


def _json_of(frame):
    """The object `bsf decode --json` prints for one frame, from the Python frame."""
    f32 = lambda v: float(np.float32(v))  # noqa: E731
    if isinstance(frame, bsf.Metadata):
        return {
            "metadata": {
                "bytes": frame.bytes,
                "version": frame.version,
                "library": "%d.%d.%d" % frame.lib_version,
                "method": frame.method,
                "method_id": frame.method_id,
                "target_rms": f32(frame.target_rms),
                "quant_step": f32(frame.quant_step),
                "caps": dict(frame.caps),
                "n_beams": frame.n_beams,
                "angle_min": f32(frame.angle_min),
                "angle_increment": f32(frame.angle_increment),
                "range_min": f32(frame.range_min),
                "range_max": f32(frame.range_max),
                "time_origin_us": frame.time_origin_us,
                "source": frame.source,
            }
        }
    v2 = {}
    if bsf.HAS_METADATA:  # the tool of a version-2 build prints these for every frame
        s = frame.stats
        v2 = {
            "n_beams": s.n_beams or None,
            "geometry": None if frame.geometry is None else {"angle_min": f32(frame.geometry[0]), "angle_increment": f32(frame.geometry[1])},
            "cut": s.cut,
            "n_cut_keypoints": s.n_cut_keypoints,
            "n_cut_segments": s.n_cut_segments,
            "n_cut_points": s.n_cut_points,
        }
    return {
        **v2,
        "seq": frame.seq,
        "timestamp_ms": frame.timestamp_ms,
        "bytes": frame.bytes,
        "version": frame.version,
        "pose": None if frame.pose is None else [f32(v) for v in frame.pose],
        "quant_step": f32(frame.quant_step),
        "n_valid": frame.stats.n_valid,
        "time_us": frame.time_us,
        "features": [
            {
                "kind": f.kind,
                "first_beam": f.first_beam,
                "last_beam": f.last_beam,
                "n_points": f.n_points,
                "e_curve": f32(f.e_curve),
                "ctrl": [[float(x), float(y)] for x, y in f.ctrl],
                "vertex": [int(v) for v in f.vertex],
            }
            for f in frame.features
        ],
    }


def _as_f32(obj):
    """JSON numbers printed with %.9g identify a float32 exactly: compare as float32."""
    if isinstance(obj, float):
        return float(np.float32(obj))
    if isinstance(obj, list):
        return [_as_f32(v) for v in obj]
    if isinstance(obj, dict):
        return {k: _as_f32(v) for k, v in obj.items()}
    return obj


def _check_decode_matches_tool(bsf_tool, path):
    out = run_tool(bsf_tool, "decode", path, "--json").stdout.decode().splitlines()
    tool = [json.loads(line) for line in out]
    counters = tool.pop()["counters"]
    mine = list(bsf.read(path))
    assert counters["frames_ok"] == len(mine) == len(tool) > 0
    for t, m in zip(tool, mine):
        # every key the tool prints must be one we reproduce (a new key fails here)
        assert _as_f32(t) == _as_f32(_json_of(m))
    return len(mine)


def test_decode_matches_bsf_decode_json_synthetic(bsf_tool, tmp_path):
    p = tmp_path / "s.bsf"
    p.write_bytes(b"".join(bsf.encode(f) for f in _frames(5)))
    assert _check_decode_matches_tool(bsf_tool, p) == 5


def test_decode_intel_matches_bsf_decode_json(bsf_tool, intel_log, tmp_path):
    p = tmp_path / "intel.bsf"
    run_tool(bsf_tool, "extract", intel_log, "-o", p)
    assert _check_decode_matches_tool(bsf_tool, p) > 1000


def test_metadata_frames_in_stream_order(tmp_path):
    if not bsf.HAS_METADATA:
        pytest.skip("this build's stream format (version 1) has no metadata frame")
    out = io.BytesIO()
    w = bsf.StreamWriter(out, "falko-sved-pdm", {"pdm_target_rms": 0.02}, 0.002, source="rüm.log", meta_every=2)
    scans = [synthetic_scan(n=361, seed=i) for i in range(3)] + [synthetic_scan(n=401, seed=3)]
    for i, (r, a, inc) in enumerate(scans):
        fr = bsf.extract(r, a, inc, 0.0, 30.0, seq=i, pdm_target_rms=0.02)
        w.write(fr, 1_700_000_000_000_000 + 250_000 * i, len(r), a, inc, 0.0, 30.0)
    items = list(bsf.read(io.BytesIO(out.getvalue())))
    kinds = ["M" if isinstance(x, bsf.Metadata) else "F" for x in items]
    assert kinds == ["M", "F", "F", "M", "F", "F"]  # first, then every 2 frames
    m = items[0]
    assert (m.method, m.source, m.n_beams, m.time_origin_us) == ("falko-sved-pdm", "rüm.log", 361, 1_700_000_000_000_000)
    assert m.target_rms == pytest.approx(0.02) and m.quant_step == pytest.approx(0.002)
    assert m.caps["points"] == bsf.caps["BSF_MAX_POINTS"] and m.range_max == 30.0
    frames = [x for x in items if isinstance(x, bsf.Frame)]
    assert [f.timestamp_ms for f in frames] == [0, 250, 500, 750]
    assert frames[2].metadata is items[3] and frames[2].unix_time_ms == 1_700_000_000_500
    # the 401-beam scan differs from the metadata's 361 beams: it carries its own geometry
    assert [f.geometry is not None for f in frames] == [False, False, False, True]
    assert frames[3].stats.n_beams == 401
    # re-encoding gives the bytes back, metadata included
    assert b"".join(bsf.encode(x) for x in items) == out.getvalue()
    with pytest.raises(bsf.BsfError, match="source"):
        bsf.encode(dataclasses.replace(m, source="x" * 65))
