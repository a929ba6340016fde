# SPDX-License-Identifier: MIT
"""Extraction from Python gives the frames `bsf extract` writes, byte for byte
once the measured extraction time (the one field that differs from run to
run) is zeroed on both sides."""
import subprocess
import sys

import numpy as np

import bsf
from conftest import canonical, run_tool, scan_frames, synthetic_scan, write_robotlaser_log


def _compare(bsf_tool, log, tmp_path, *tool_args):
    cli = tmp_path / "cli.bsf"
    run_tool(bsf_tool, "extract", log, *tool_args, "-o", cli)
    cli_bytes = cli.read_bytes()
    decoded = bsf.decode(cli_bytes)
    # re-encoding reproduces the tool's bytes exactly (metadata frames too), so
    # comparing re-encoded frames with time zeroed is faithful
    assert b"".join(bsf.encode(f) for f in decoded) == cli_bytes
    cli_frames = scan_frames(decoded)
    py_frames = list(bsf.extract_log(log, timing=False))
    n = len(py_frames)
    assert n == len(cli_frames) > 0
    assert canonical(cli_frames) == canonical(py_frames)
    # the frames carry the same time and pose
    for a, b in zip(cli_frames, py_frames):
        assert a.pose == b.pose or max(abs(x - y) for x, y in zip(a.pose, b.pose)) < 1e-3
    ms = [f.timestamp_ms - cli_frames[0].timestamp_ms for f in cli_frames]
    assert all(abs(x - f.timestamp_ms) <= 1 for x, f in zip(ms, py_frames))
    # the command line of the package writes the same scan frames (its
    # metadata frames, with format version 2, name this build's larger caps)
    out = tmp_path / "py.bsf"
    subprocess.run([sys.executable, "-m", "bsf", "extract", str(log), "--no-time", "-o", str(out)], check=True, capture_output=True)
    mine = bsf.decode(out.read_bytes())
    assert canonical(mine) == canonical(cli_frames)
    assert [f.seq for f in scan_frames(mine)] == [f.seq for f in cli_frames]
    if bsf.HAS_METADATA:
        metas = [m for m in mine if isinstance(m, bsf.Metadata)]
        assert metas and metas[0].source == log.name and metas[0].method == "lc-sved-pdm"
        assert mine[0] is metas[0]  # the stream starts with it
        assert all(f.unix_time_ms is not None for f in scan_frames(mine))
    return n


def test_synthetic_log_same_frames_as_bsf_extract(bsf_tool, tmp_path):
    scans = [synthetic_scan(n=361 + 60 * i, seed=i) for i in range(6)]
    log = tmp_path / "room.log"
    write_robotlaser_log(log, scans, max_range=30.0)
    assert _compare(bsf_tool, log, tmp_path) == 6


def test_intel_same_frames_as_bsf_extract(bsf_tool, intel_log, tmp_path):
    n = _compare(bsf_tool, intel_log, tmp_path)
    assert n > 2000
