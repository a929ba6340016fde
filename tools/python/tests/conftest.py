# SPDX-License-Identifier: MIT
"""Shared fixtures: the C tool `bsf` and the datasets, each skipped visibly
when absent. CI sets BSF_PYTEST_REQUIRE_TOOL=1 so that a missing tool fails
instead of skipping."""
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[3]


def _shared_data():
    env = os.environ.get("BSF_SHARED_DIR")
    base = Path(env) if env else ROOT.parent / "shared"
    for d in (base / "data", base):
        if (d / "intel.log.gz").is_file():
            return d
    return None


@pytest.fixture(scope="session")
def bsf_tool():
    """Path of the C tool (BSF_TOOL, or build/tools/bsf of the checkout)."""
    tool = Path(os.environ.get("BSF_TOOL", ROOT / "build" / "tools" / "bsf"))
    if not (tool.is_file() and os.access(tool, os.X_OK)):
        msg = f"the C tool is not built at {tool} (cmake --build build, or set BSF_TOOL)"
        if os.environ.get("BSF_PYTEST_REQUIRE_TOOL") == "1":
            pytest.fail(msg)
        pytest.skip(msg)
    return tool


@pytest.fixture(scope="session")
def intel_log():
    d = _shared_data()
    if d is None:
        pytest.skip("dataset not found: ../shared/data/intel.log.gz (or $BSF_SHARED_DIR)")
    return d / "intel.log.gz"


def scan_frames(items):
    """The scan frames of a decoded stream (metadata frames left out)."""
    import bsf

    return [f for f in items if isinstance(f, bsf.Frame)]


def canonical(frames):
    """Scan frames as bytes without what depends on the stream around them or
    on the source: time, extraction time, pose, own geometry, metadata."""
    import dataclasses

    import bsf

    return [
        bsf.encode(dataclasses.replace(f, pose=None, geometry=None, metadata=None), no_time=True, timestamp_ms=0)
        for f in scan_frames(frames)
    ]


def run_tool(tool, *args, **kw):
    return subprocess.run([str(tool), *map(str, args)], check=True, capture_output=True, **kw)


def synthetic_scan(n=541, fov=np.radians(270.0), seed=0, hole=True):
    """A rectangular room (4 x 3 m, laser off-centre) with a round pillar,
    ray-cast with 5 mm Gaussian noise; a few readings are no-returns (NaN,
    inf, 0 and a 60 m code)."""
    rng = np.random.default_rng(seed)
    angle_min = -fov / 2.0
    inc = fov / (n - 1) if fov < 2 * np.pi else 2 * np.pi / n
    a = angle_min + inc * np.arange(n)
    d = np.stack([np.cos(a), np.sin(a)], axis=1)
    lx, ly = 0.7, -0.4
    best = np.full(n, np.inf)
    for axis, wall in ((0, 2.0 - lx), (0, -2.0 - lx), (1, 1.5 - ly), (1, -1.5 - ly)):
        with np.errstate(divide="ignore", invalid="ignore"):
            t = wall / d[:, axis]
        best = np.where((t > 0) & (t < best), t, best)
    c = np.array([1.0, 0.9])
    r = 0.35
    b = d @ c
    disc = b * b - (c @ c - r * r)
    t = b - np.sqrt(np.maximum(disc, 0.0))
    best = np.where((disc > 0) & (t > 0) & (t < best), t, best)
    ranges = (best + rng.normal(0.0, 0.005, n)).astype(np.float32)
    if hole:
        ranges[[3, 50, 51, 200]] = [np.nan, np.inf, 0.0, 60.0]
    return ranges, float(np.float32(angle_min)), float(np.float32(inc))


def write_robotlaser_log(path, scans, max_range):
    """A CARMEN log of ROBOTLASER1 lines: every scan's geometry written
    exactly (9 significant digits round-trip a float32)."""
    with open(path, "w") as f:
        for i, (ranges, amin, inc) in enumerate(scans):
            fov = inc * (len(ranges) - 1)
            vals = " ".join("%.9g" % v for v in ranges)
            f.write(
                f"ROBOTLASER1 0 {amin:.9g} {fov:.9g} {inc:.9g} {max_range:.9g} 0.01 0 {len(ranges)} {vals} 0 "
                f"{0.1 * i:.6f} 0 0 0 0 0 0 0 0 0 0 {100.0 + 0.1 * i:.6f} host {100.0 + 0.1 * i:.6f}\n"
            )
