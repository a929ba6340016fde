#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""CTest driver for cross builds: the target's `bsf` (run under the emulator,
for example s390x big-endian under qemu-user) writes the same
`bsf extract --reproducible` stream, byte for byte, as the host's `bsf` on the
same logs, for both methods, and reads the host's stream into the same
`bsf metrics` text. The same for the fused map's stream (`bsf extract --map`,
with and without `--align`, with snapshots), read back by `bsf map --json`,
on the synthetic log and the first scans of a corrected log (true poses)
when the shared data has one.

Usage: test_stream_match.py HOST_BSF TARGET_BSF TARGET_SYNTH_LOG WORK_DIR [SHARED_DIR]
"""
import os
import shutil
import subprocess
import sys

HOST, TARGET, SYNTH, WORK = (os.path.abspath(a) for a in sys.argv[1:5])
SHARED = sys.argv[5] if len(sys.argv) > 5 else os.environ.get("BSF_SHARED_DIR", "")
METHODS = ["lc-sved-pdm", "falko-sved-pdm"]
failures = []


def check(cond, what):
    """Record one check; the run fails if any check failed."""
    print(("ok      " if cond else "FAILED  ") + what)
    if not cond:
        failures.append(what)


def run(exe, args):
    return subprocess.run([exe] + args, cwd=WORK, capture_output=True, timeout=240)


def corrected_log():
    """alt/intel-corrected.log.gz from the shared data, when present."""
    for cand in (os.path.join(SHARED, "data", "alt", "intel-corrected.log.gz"),
                 os.path.join(SHARED, "alt", "intel-corrected.log.gz")):
        if SHARED and os.path.isfile(cand):
            return cand
    return None


def same_files(a, b):
    with open(a, "rb") as f:
        x = f.read()
    with open(b, "rb") as f:
        y = f.read()
    return x == y, len(x)


def intel_log():
    """intel.log.gz from the shared data, when present (SHARED names data/ or its parent)."""
    for cand in (os.path.join(SHARED, "data", "intel.log.gz"), os.path.join(SHARED, "intel.log.gz")):
        if SHARED and os.path.isfile(cand):
            return cand
    return None


def metrics_text(out):
    """`bsf metrics` output, line by line (blank lines aside). Every line must
    match, times included: a --reproducible stream carries zero times."""
    return [line for line in out.decode(errors="replace").splitlines() if line.strip()]


shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)

# Logs: a synthetic one (walls, corners, a circle), a cluttered one whose
# scans exceed the keypoint cap (cut scans in the stream), and the first
# Intel scans when the shared data is there (gzip: zlib on the host, and
# zlib or the system's gzip on the target).
logs = []
r = subprocess.run([SYNTH, os.path.join(WORK, "synth.log"), "40"], capture_output=True)
check(r.returncode == 0, "synth_log (target) writes synth.log")
logs.append(("synth.log", []))
r = subprocess.run([SYNTH, os.path.join(WORK, "clutter.log"), "12", "clutter"], capture_output=True)
check(r.returncode == 0, "synth_log (target) writes clutter.log")
logs.append(("clutter.log", []))
intel = intel_log()
if intel:
    logs.append((intel, ["--count", "300"]))
else:
    print("note    intel.log.gz not found: synthetic logs only")

for log, extra in logs:
    name = os.path.basename(log)
    for method in METHODS:
        outs = {}
        for side, exe in (("host", HOST), ("target", TARGET)):
            out = os.path.join(WORK, "%s.%s.%s.bsf" % (name, method, side))
            r = run(exe, ["extract", log, "--method", method, "--reproducible", "-o", out] + extra)
            ok = r.returncode == 0 and os.path.isfile(out) and os.path.getsize(out) > 0
            check(ok, "%s bsf extract %s --method %s exits 0 with a stream" % (side, name, method))
            if not ok:
                sys.stderr.write(r.stderr.decode(errors="replace"))
            outs[side] = out
        if all(os.path.isfile(p) for p in outs.values()):
            with open(outs["host"], "rb") as f:
                host_bytes = f.read()
            with open(outs["target"], "rb") as f:
                target_bytes = f.read()
            check(host_bytes == target_bytes,
                  "%s --method %s: target stream identical to the host's (%d bytes)" % (name, method, len(host_bytes)))
            # The target decodes the host's stream into the host's own reading.
            mh = run(HOST, ["metrics", outs["host"]])
            mt = run(TARGET, ["metrics", outs["host"]])
            check(mh.returncode == 0 and mt.returncode == 0 and metrics_text(mh.stdout) == metrics_text(mt.stdout),
                  "%s --method %s: target's bsf metrics of the host stream equal the host's" % (name, method))

# The fused map: extract --map (and --align) streams byte for byte, and the
# target's `bsf map --json` of the host's stream equal to the host's.
map_logs = [("synth.log", [])]
corrected = corrected_log()
if corrected:
    map_logs.append((corrected, ["--count", "400"]))
else:
    print("note    intel-corrected.log.gz not found: the map on the synthetic log only")
MAP_VARIANTS = [("map", ["--map"]), ("map-align", ["--map", "--align"]),
                ("map-snap", ["--map", "--align", "--snapshot-budget", "48"])]
for log, extra in map_logs:
    name = os.path.basename(log)
    for tag, opts in MAP_VARIANTS:
        outs = {}
        for side, exe in (("host", HOST), ("target", TARGET)):
            out = os.path.join(WORK, "%s.%s.%s.bsf" % (name, tag, side))
            r = run(exe, ["extract", log] + opts + ["--reproducible", "-o", out] + extra)
            ok = r.returncode == 0 and os.path.isfile(out) and os.path.getsize(out) > 0
            check(ok, "%s bsf extract %s %s exits 0 with a stream" % (side, name, " ".join(opts)))
            if not ok:
                sys.stderr.write(r.stderr.decode(errors="replace"))
            outs[side] = out
        if all(os.path.isfile(p) for p in outs.values()):
            same, size = same_files(outs["host"], outs["target"])
            check(same and size > 0, "%s %s: target map stream identical to the host's (%d bytes)"
                  % (name, " ".join(opts), size))
            jh = run(HOST, ["map", outs["host"], "--json"])
            jt = run(TARGET, ["map", outs["host"], "--json"])
            check(jh.returncode == 0 and jt.returncode == 0 and len(jh.stdout) > 0
                  and jh.stdout == jt.stdout,
                  "%s %s: target's bsf map --json of the host stream equals the host's"
                  % (name, " ".join(opts)))

if failures:
    print("%d check(s) failed" % len(failures))
    sys.exit(1)
print("all checks passed")
