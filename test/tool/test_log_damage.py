#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""CTest driver: `bsf extract` on damaged logs never reads them as shorter logs.

Every prefix of a small gzip CARMEN log (and a dozen prefixes of the real
intel.log.gz when the shared data is present) must make `bsf extract` exit
non-zero with a message naming the file and the last complete line; control
bytes in a line make that line a reported malformed line and later line
numbers stay right.

Usage: test_log_damage.py BSF_EXE WORK_DIR [SHARED_DIR]
"""
import gzip
import os
import random
import re
import shutil
import subprocess
import sys
import zlib
from concurrent.futures import ThreadPoolExecutor

BSF, WORK = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
SHARED = sys.argv[3] if len(sys.argv) > 3 else ""
failures = []


def check(cond, what):
    print(("ok      " if cond else "FAILED  ") + what)
    if not cond:
        failures.append(what)


def extract(log):
    r = subprocess.run([BSF, "extract", log, "-o", os.devnull], cwd=WORK, capture_output=True, text=True)
    return r.returncode, r.stderr


def complete_lines(gz_prefix):
    """Newlines a gzip decompressor can produce from these bytes."""
    d = zlib.decompressobj(16 + zlib.MAX_WBITS)
    try:
        return d.decompress(gz_prefix).count(b"\n")
    except zlib.error:
        return None


def flaser(rng, t):
    ranges = " ".join("%.2f" % rng.uniform(0.5, 12.0) for _ in range(180))
    return "FLASER 180 %s 1.0 2.0 0.1 1.0 2.0 0.1 %.6f nohost %.6f\n" % (ranges, t, t)


shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)

# 1. Every cut point of a small gzip log.
rng = random.Random(17)
text = "# synthetic log for the truncation sweep\n"
for k in range(3):
    text += flaser(rng, 100.0 + k) + "ODOM 0 0 0 0 0 0 %.1f nohost %.1f\n" % (100.5 + k, 100.5 + k)
whole = gzip.compress(text.encode(), compresslevel=9, mtime=0)
with open(os.path.join(WORK, "whole.log.gz"), "wb") as f:
    f.write(whole)
rc, err = extract("whole.log.gz")
check(rc == 0 and "3 scans extracted" in err, "the whole gzip log extracts 3 scans (%d, %r)" % (rc, err.strip()))


def one_cut(cut):
    name = "cut%05d.log.gz" % cut
    with open(os.path.join(WORK, name), "wb") as f:
        f.write(whole[:cut])
    rc, err = extract(name)
    os.remove(os.path.join(WORK, name))
    good = complete_lines(whole[:cut])
    want = "%s:%d: read error:" % (name, good + 1)
    ok = rc != 0 and want in err and ("the last complete line is %d\n" % good) in err
    return cut, ok, rc, err


with ThreadPoolExecutor(max_workers=2) as pool:
    results = list(pool.map(one_cut, range(len(whole))))
bad = [(c, rc, e.strip()[-160:]) for c, ok, rc, e in results if not ok]
check(not bad, "all %d cuts of a %d-byte gzip log: non-zero exit, file and last complete line named%s" %
      (len(whole), len(whole), "" if not bad else " (first failures: %r)" % bad[:3]))

# 2. The real log, cut at a dozen places (header, body, trailer).
intel = os.path.join(SHARED, "data", "intel.log.gz") if SHARED else ""
if intel and os.path.isfile(intel):
    data = open(intel, "rb").read()
    n = len(data)
    cuts = [0, 1, 10, 4096, n // 2, n - 8, n - 1]
    ok_all = True
    for cut in cuts:
        name = "intel_cut.log.gz"
        with open(os.path.join(WORK, name), "wb") as f:
            f.write(data[:cut])
        rc, err = extract(name)
        good = complete_lines(data[:cut])
        m = re.search(r"the last complete line is (\d+)", err)
        ok = rc != 0 and ("%s:%d: read error:" % (name, good + 1)) in err and m and int(m.group(1)) == good
        if not ok:
            print("  cut %d: exit %d, %r (expected last complete line %d)" % (cut, rc, err.strip()[-200:], good))
        ok_all = ok_all and bool(ok)
    check(ok_all, "intel.log.gz cut at %d places: each a non-zero exit naming the last complete line" % len(cuts))
else:
    print("skipped: intel.log.gz not found under %r" % SHARED)

# 3. Control bytes: the damaged line is reported, the next line keeps its number.
lines = [flaser(rng, 200.0 + k) for k in range(5)]
lines[1] = lines[1][:40] + "\0" + lines[1][40:]
lines[3] = lines[3][:7] + "\x02" + lines[3][7:]
with open(os.path.join(WORK, "nul.log"), "wb") as f:
    f.write("".join(lines).encode())
rc, err = extract("nul.log")
check("nul.log:2: control byte 0x00 at column 41" in err, "NUL reported as nul.log:2 (%r)" % err.strip())
check("nul.log:4: control byte 0x02 at column 8" in err, "STX reported as nul.log:4")
check("3 scans extracted" in err and "2 malformed lines" in err, "lines 1, 3 and 5 extracted, 2 malformed")

if failures:
    print("%d check(s) failed" % len(failures))
    sys.exit(1)
print("all checks passed")
