# SPDX-License-Identifier: MIT
"""What a user of the released package meets first: its version, the caps it
shares with the C tool, and the traps of a first try (integer ranges, a file
that is no log, parameters printed as float32 noise)."""
import re
import struct
import subprocess
import sys
from importlib import metadata

import numpy as np
import pytest

import bsf
from conftest import run_tool


def test_version_is_the_c_librarys():
    assert re.fullmatch(r"[0-9]+\.[0-9]+\.[0-9]+", bsf.__version__)
    assert bsf.__version__ == bsf._core.version()
    # the installed distribution carries the same version (setup.py reads it
    # from include/bsf/bsf_version.h)
    assert metadata.version("bsf") == bsf.__version__
    # and so does every metadata frame the package writes
    if bsf.HAS_METADATA:
        out = bsf.decode(_stream_of_one_scan())
        metas = [f for f in out if isinstance(f, bsf.Metadata)]
        assert metas and ".".join(map(str, metas[0].lib_version)) == bsf.__version__


def _stream_of_one_scan():
    import io

    angles = np.linspace(-1.5, 1.5, 301)
    ranges = (2.0 / np.cos(angles)).astype(np.float32)
    buf = io.BytesIO()
    w = bsf.StreamWriter(buf, "lc-sved-pdm")
    fr = bsf.extract(ranges, -1.5, 3.0 / 300, 0.05, 30.0, timing=False)
    w.write(fr, 1_700_000_000_000_000, len(ranges), -1.5, 3.0 / 300, 0.05, 30.0, no_time=True)
    return buf.getvalue()


def test_tool_reports_the_same_version_and_caps(bsf_tool):
    out = run_tool(bsf_tool, "--version").stdout.decode()
    assert out.startswith(f"bsf {bsf.__version__} ")
    tool_caps = {k: int(v) for k, v in re.findall(r"(BSF_MAX_[A-Z_]+)=([0-9]+)", out)}
    assert len(tool_caps) == 4
    assert tool_caps == {k: bsf.caps[k] for k in tool_caps}


def _scan_at_the_caps():
    # 1365 runs of 3 beams alternating between 2 m and 6 m over 4096 beams:
    # with the paper's segmentation (no look-back) more segments than the caps
    # hold, so the frame is as large as this build makes one.
    r = np.where((np.arange(bsf.caps["BSF_MAX_POINTS"]) // 3) % 2 == 0, 2.0, 6.0)
    return bsf.extract(
        r, -np.pi, 2 * np.pi / len(r), 0.05, 30.0, timing=False, sved_min_segment_points=3, sved_lookback=0
    )


def test_a_frame_python_writes_at_its_caps_the_tool_decodes(bsf_tool, tmp_path):
    fr = _scan_at_the_caps()
    assert fr.stats.cut != 0  # at the caps: the largest frame this build writes
    n_ctrl = sum(len(f.ctrl) for f in fr.features)
    assert len(fr.features) > 128 and n_ctrl > 512  # beyond the library's default caps
    path = tmp_path / "big.bsf"
    path.write_bytes(bsf.encode(fr, no_time=True))
    out = run_tool(bsf_tool, "decode", path).stdout.decode()
    m = re.search(r"features=([0-9]+)", out) or re.search(r"([0-9]+) features", out)
    assert m, out[:400]
    assert int(m.group(1)) == len(fr.features)


def test_integer_ranges_are_refused_with_a_word():
    mm = np.full(361, 2000, dtype=np.uint16)  # a driver's millimetres
    for ranges in (mm, mm.astype(np.int32), [2, 2, 2, 2, 2, 2]):
        with pytest.raises(TypeError, match="floating-point metres"):
            bsf.extract(ranges, -1.5, 3.0 / 360, 0.05, 30.0)
        with pytest.raises(TypeError, match="ranges / 1000.0"):
            bsf.Extractor().extract(ranges, -1.5, 3.0 / 360, 0.05, 30.0)
    # the same readings in metres give features
    assert bsf.extract(mm / 1000.0, -1.5, 3.0 / 360, 0.05, 30.0).features


@pytest.mark.parametrize("method", bsf.METHODS)
def test_default_params_read_as_written_and_round_trip(method):
    params = bsf.default_params(method)
    floats = {k: v for k, v in params.items() if isinstance(v, float)}
    assert floats
    for k, v in floats.items():
        f32 = struct.unpack("<f", struct.pack("<f", v))[0]
        # the shortest decimal that is this float32 ...
        assert repr(v) == str(np.float32(f32)) or repr(v) == repr(float(str(np.float32(f32)))), k
        # ... and never longer than float32's 9 significant digits
        assert len(re.sub(r"[^0-9]", "", repr(v).split("e")[0]).lstrip("0")) <= 9, (k, v)
    if method == "lc-sved-pdm":
        assert params["pdm_target_rms"] == 0.03 and params["sved_a"] == 0.2
    # passed back, they give the same float32 parameters and the same features
    ex = bsf.Extractor(method, timing=False, **params)
    assert ex.params == params
    r = (2.0 / np.cos(np.linspace(-1.5, 1.5, 301))).astype(np.float32)
    a = bsf.extract(r, -1.5, 3.0 / 300, 0.05, 30.0, method=method, timing=False)
    b = ex.extract(r, -1.5, 3.0 / 300, 0.05, 30.0)
    assert bsf.encode(a, no_time=True) == bsf.encode(b, no_time=True)


def test_extract_of_a_file_without_scans_fails(tmp_path):
    script = tmp_path / "some_script.py"
    script.write_text("print('not a log')\n")
    out = tmp_path / "out.bsf"
    r = subprocess.run(
        [sys.executable, "-m", "bsf", "extract", str(script), "-o", str(out)], capture_output=True, text=True
    )
    assert r.returncode == 1
    assert "no laser line" in r.stderr
    assert out.stat().st_size == 0


def test_extract_of_a_file_without_scans_fails_as_the_tool_does(bsf_tool, tmp_path):
    script = tmp_path / "some_script.py"
    script.write_text("print('not a log')\n")
    r = subprocess.run([str(bsf_tool), "extract", str(script), "-o", str(tmp_path / "c.bsf")], capture_output=True)
    p = subprocess.run([sys.executable, "-m", "bsf", "extract", str(script), "-o", str(tmp_path / "p.bsf")], capture_output=True)
    assert r.returncode == p.returncode == 1
