# SPDX-License-Identifier: MIT
"""plot(): features, vertices and the laser path on a matplotlib Axes."""
import subprocess
import sys

import numpy as np
import pytest

import bsf
from conftest import synthetic_scan

matplotlib = pytest.importorskip("matplotlib", reason="matplotlib (the 'plot' extra) is not installed")
matplotlib.use("Agg")


def _frames():
    out = []
    for i in range(3):
        r, a, inc = synthetic_scan(seed=i)
        out.append(bsf.extract(r, a, inc, 0.05, 30.0, seq=i, pose=(1.0 * i, 0.0, 0.0)))
    return out


def test_plot_draws_world_frame_curves_vertices_and_path(tmp_path):
    frames = _frames()
    ax = bsf.plot(frames, samples=10)
    lines = ax.collections[0].get_segments()
    assert len(lines) == sum(len(f.features) for f in frames)
    # second frame shifted by its pose (1 m along x)
    np.testing.assert_allclose(lines[len(frames[0].features)], frames[1].features[0].sample(10, frames[1].pose), atol=1e-6)
    labels = [ln.get_label() for ln in ax.get_lines()]
    assert labels == ["vertices", "laser path"]
    n_vertices = sum(len(f.vertices(world=True)) for f in frames)
    assert len(ax.get_lines()[0].get_xdata()) == n_vertices > 0
    ax.figure.savefig(tmp_path / "map.png")
    assert (tmp_path / "map.png").stat().st_size > 1000


def test_plot_command(tmp_path):
    p = tmp_path / "s.bsf"
    p.write_bytes(b"".join(bsf.encode(f) for f in _frames()))
    r = subprocess.run([sys.executable, "-m", "bsf", "plot", str(p), "-o", str(tmp_path / "m.png")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "m.png").read_bytes()[:4] == b"\x89PNG"
    (tmp_path / "bad.bsf").write_bytes(b"\x05garbage" * 10)
    r = subprocess.run([sys.executable, "-m", "bsf", "plot", str(tmp_path / "bad.bsf"), "-o", str(tmp_path / "x.png")], capture_output=True, text=True)
    assert r.returncode != 0 and "no valid bsf frame" in r.stderr and "Traceback" not in r.stderr
