# SPDX-License-Identifier: MIT
"""The package is as strict as the C tool: bounded memory on a gzip bomb, an
error for a log without scans or with a bad time, no silent wrap of an
integer, no byte read as a range, no re-initialisation during an extraction,
and every parameter value the library accepts."""
import math
import os
import subprocess
import sys
import threading
import zlib

import numpy as np
import pytest

import bsf
from conftest import run_tool, scan_frames, synthetic_scan

# ---- CARMEN logs ---------------------------------------------------------------------

BOMB_BYTES = 256 << 20  # inflated size: far beyond the bound below
RSS_LIMIT_KB = 160 * 1024  # Python, numpy and the reader's 1.1 MiB line buffer


def _write_bomb(path, head, fill):
    """A gzip file of `head` then `fill` repeated to BOMB_BYTES, without a newline."""
    chunk = (fill * ((1 << 20) // len(fill) + 1))[: 1 << 20]
    z = zlib.compressobj(9, zlib.DEFLATED, 16 + zlib.MAX_WBITS)
    with open(path, "wb") as f:
        f.write(z.compress(head))
        for _ in range(BOMB_BYTES // len(chunk)):
            f.write(z.compress(chunk))
        f.write(z.flush())


_READ_ALL = """
import sys, bsf
try:
    n = sum(1 for _ in bsf.read_carmen(sys.argv[1]))
    print("scans", n)
except bsf.BsfError as e:
    print("BsfError", e)
"""


@pytest.mark.parametrize(
    "head, fill",
    [(b"", b"\0"), (b"", b"a"), (b"ROBOTLASER1 ", bytes(c for c in range(1, 32) if c != 0x0A))],
    ids=["zeros", "letters", "robotlaser-control-bytes"],
)
def test_read_carmen_of_a_gzip_bomb_stays_in_bounded_memory_and_raises(tmp_path, head, fill):
    log = tmp_path / "bomb.log.gz"
    _write_bomb(log, head, fill)
    with open(tmp_path / "out.txt", "wb") as out, open(tmp_path / "err.txt", "wb") as err:
        p = subprocess.Popen([sys.executable, "-c", _READ_ALL, str(log)], stdout=out, stderr=err)
        _, status, usage = os.wait4(p.pid, 0)
        p.returncode = os.waitstatus_to_exitcode(status)
    out_text = (tmp_path / "out.txt").read_text()
    err_text = (tmp_path / "err.txt").read_text(errors="replace")
    assert p.returncode == 0, err_text[-2000:]
    assert usage.ru_maxrss < RSS_LIMIT_KB, f"peak RSS {usage.ru_maxrss} KiB"
    assert f"{log}:1: line longer than 1048576 bytes" in err_text
    assert out_text.startswith("BsfError") and "1 lines longer than 1048576 bytes" in out_text


def test_read_carmen_without_a_scan_raises(tmp_path):
    odom = tmp_path / "odom.log"
    odom.write_text("# comment\nODOM 0 0 0 0 0 0 1.0 host 1.0\n")
    with pytest.raises(bsf.BsfError, match="no laser line"):
        list(bsf.read_carmen(odom))
    bad = tmp_path / "bad.log"
    bad.write_text("FLASER 3 1 2\nFLASER x\n")
    with pytest.raises(bsf.BsfError, match="no laser line .* that could be read"):
        list(bsf.read_carmen(bad))
    # stopping early is not an error
    good = tmp_path / "good.log"
    good.write_text("FLASER 3 1 2 3 0 0 0 0 0 0 1.0 h 1.0\n" * 3)
    assert len(list(zip(range(2), bsf.read_carmen(good)))) == 2


def _flaser(t):
    ranges = " ".join("%.3f" % (2.0 + 0.01 * (i % 7)) for i in range(181))
    return f"FLASER 181 {ranges} 1 2 0.1 1 2 0.1 {t} host {t}\n"


def test_python_extract_skips_scans_with_a_bad_time_as_the_tool_does(bsf_tool, tmp_path):
    times = ["-5.0", "100.0", "nan", "inf", "-inf", "1e17", "100.5"]
    log = tmp_path / "times.log"
    log.write_text("".join(_flaser(t) for t in times))
    cli = subprocess.run(
        [str(bsf_tool), "extract", str(log), "--reproducible", "-o", str(tmp_path / "c.bsf")], capture_output=True, text=True
    )
    py = subprocess.run(
        [sys.executable, "-m", "bsf", "extract", str(log), "--no-time", "-o", str(tmp_path / "p.bsf")],
        capture_output=True,
        text=True,
    )
    assert cli.returncode == 1
    assert py.returncode == 1 and "Traceback" not in py.stderr, py.stderr
    for line, t in ((1, "-5"), (3, "nan"), (4, "inf"), (5, "-inf"), (6, "1e+17")):
        assert f"{log}:{line}: scan {line - 1} skipped: its time {t} s is not a time bsf can carry" in py.stderr
        assert f"{log}:{line}: scan {line - 1} skipped: its time" in cli.stderr
    c_frames = scan_frames(bsf.decode((tmp_path / "c.bsf").read_bytes()))
    p_items = bsf.decode((tmp_path / "p.bsf").read_bytes())
    p_frames = scan_frames(p_items)
    assert [f.seq for f in p_frames] == [f.seq for f in c_frames] == [1, 6]
    assert [f.timestamp_ms for f in p_frames] == [f.timestamp_ms for f in c_frames] == [0, 500]
    if bsf.HAS_METADATA:
        origin = [m.time_origin_us for m in p_items if isinstance(m, bsf.Metadata)]
        assert origin and all(o == 100_000_000 for o in origin)
    # the library call raises, or collects the message when asked
    with pytest.raises(bsf.BsfError, match="its time -5 s is not a time"):
        list(bsf.extract_log(log))
    errors = []
    assert len(list(bsf.extract_log(log, errors=errors))) == 2 and len(errors) == 5


# ---- encode: integers in range, never wrapped -------------------------------------------


def test_encode_refuses_seq_and_timestamp_out_of_range():
    ranges, amin, inc = synthetic_scan()
    fr = bsf.extract(ranges, amin, inc, 0.05, 30.0)
    for kw in ({"seq": 2**64}, {"seq": 2**32}, {"seq": -1}, {"timestamp_ms": 2**64}, {"timestamp_ms": -1}):
        with pytest.raises(OverflowError, match=next(iter(kw))):
            bsf.encode(fr, **kw)
    with pytest.raises(TypeError):
        bsf.encode(fr, seq=1.5)
    data = bsf.encode(fr, seq=2**32 - 1, timestamp_ms=2**64 - 1)
    back = scan_frames(bsf.decode(data))[0]
    assert back.seq == 2**32 - 1 and back.timestamp_ms == 2**64 - 1


# ---- ranges: numbers, never bytes ------------------------------------------------------


def test_extract_refuses_a_buffer_of_bytes_and_accepts_one_of_floats():
    ranges, amin, inc = synthetic_scan()
    want = bsf.encode(bsf.extract(ranges, amin, inc, 0.05, 30.0, timing=False))
    raw = ranges.tobytes()
    for bad in (memoryview(raw), raw, bytearray(raw), memoryview(raw).cast("b")):
        with pytest.raises(TypeError, match="float32 or float64"):
            bsf.extract(bad, amin, inc, 0.05, 30.0)
    for good in (memoryview(raw).cast("f"), memoryview(ranges.astype(np.float64)), memoryview(ranges)):
        assert bsf.encode(bsf.extract(good, amin, inc, 0.05, 30.0, timing=False)) == want
    with pytest.raises(TypeError):
        bsf._core.Extractor("lc-sved-pdm").extract(memoryview(raw), amin, inc, 0.05, 30.0)


# ---- one extractor, two threads ---------------------------------------------------------


def test_reinitialising_an_extractor_during_an_extraction_is_refused():
    ranges, amin, inc = synthetic_scan(n=4096, fov=2 * np.pi)
    ex = bsf._core.Extractor("falko-sved-pdm", None, False)
    want = ex.extract(ranges, amin, inc, 0.05, 30.0)
    stop = threading.Event()
    results = []

    def worker():
        while not stop.is_set():
            results.append(ex.extract(ranges, amin, inc, 0.05, 30.0))

    t = threading.Thread(target=worker)
    t.start()
    refused = 0
    try:
        for _ in range(200000):
            try:
                ex.__init__("falko-sved-pdm", None, False)
            except RuntimeError as e:
                assert "already running" in str(e)
                refused += 1
                if refused >= 3:
                    break
    finally:
        stop.set()
        t.join()
    assert refused >= 3
    assert results and all(r == want for r in results)


# ---- parameters: every value the library accepts ---------------------------------------


@pytest.mark.parametrize("method", bsf.METHODS)
def test_every_default_parameter_is_accepted_back(method):
    params = bsf.default_params(method)
    ex = bsf.Extractor(method, **params)
    assert ex.params == params


def test_float_parameters_accept_every_finite_float32():
    # Parameters read back in their shortest float32 form (3.4028235e38 for
    # FLT_MAX): the same float32, compared as one.
    assert np.float32(bsf.default_params()["lc_max_range"]) == np.finfo(np.float32).max
    for v in (float(np.finfo(np.float32).max), 3.4028235e38, 1e38):
        ex = bsf.Extractor("lc-sved-pdm", lc_max_range=v)
        assert np.float32(ex.params["lc_max_range"]) == np.float32(v)
    for v in (3.5e38, math.inf, math.nan, 1e300):
        with pytest.raises(bsf.BsfError, match="lc_max_range"):
            bsf.Extractor("lc-sved-pdm", lc_max_range=v)
