# SPDX-License-Identifier: MIT
"""Extraction from Python gives the frames `bsf extract` writes, byte for byte
once the measured extraction time (the one field that differs from run to
run) is zeroed on both sides."""
import subprocess
import sys

import numpy as np

import bsf
from conftest import run_tool, synthetic_scan, write_robotlaser_log


def _zero_time(frames):
    return [bsf.encode(f, no_time=True) for f in frames]


def _compare(bsf_tool, log, tmp_path, *tool_args):
    cli = tmp_path / "cli.bsf"
    run_tool(bsf_tool, "extract", log, *tool_args, "-o", cli)
    cli_bytes = cli.read_bytes()
    cli_frames = bsf.decode(cli_bytes)
    # re-encoding reproduces the tool's bytes exactly, so zeroing time this way is faithful
    assert b"".join(bsf.encode(f) for f in cli_frames) == cli_bytes
    py_frames = list(bsf.extract_log(log, timing=False))
    n = len(py_frames)
    assert n == len(cli_frames) > 0
    assert _zero_time(cli_frames) == [bsf.encode(f) for f in py_frames]
    # the command line of the package writes the same file
    out = tmp_path / "py.bsf"
    subprocess.run([sys.executable, "-m", "bsf", "extract", str(log), "--no-time", "-o", str(out)], check=True, capture_output=True)
    assert out.read_bytes() == b"".join(_zero_time(cli_frames))
    return n


def test_synthetic_log_same_frames_as_bsf_extract(bsf_tool, tmp_path):
    scans = [synthetic_scan(n=361 + 60 * i, seed=i) for i in range(6)]
    log = tmp_path / "room.log"
    write_robotlaser_log(log, scans, max_range=30.0)
    assert _compare(bsf_tool, log, tmp_path) == 6


def test_intel_same_frames_as_bsf_extract(bsf_tool, intel_log, tmp_path):
    n = _compare(bsf_tool, intel_log, tmp_path)
    assert n > 2000
