#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""CTest driver for the host tool `bsf`: runs it the way a user does.

Usage: test_tool.py BSF_EXE SYNTH_LOG_EXE WORK_DIR
"""
import os
import random
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

BSF, SYNTH, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
failures = []


def run(args, **kw):
    return subprocess.run([BSF] + args, cwd=WORK, capture_output=True, **kw)


def check(cond, what):
    """Record one check; the run fails if any check failed."""
    print(("ok      " if cond else "FAILED  ") + what)
    if not cond:
        failures.append(what)


def metrics_of(text):
    out = {}
    for line in text.splitlines():
        parts = line.split()
        if len(parts) >= 2:
            out[parts[0]] = parts[1:]
    return out


shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)

# 1. demo: exits 0, writes a well-formed SVG with curves, and a stream.
r = run(["demo"])
check(r.returncode == 0, "bsf demo exits 0")
check(b"retrievability" in r.stdout, "bsf demo prints the metrics")
svg_path = os.path.join(WORK, "demo.svg")
try:
    root = ET.parse(svg_path).getroot()
    ok = root.tag.endswith("svg") and len(root.findall(".//{http://www.w3.org/2000/svg}polyline")) > 10
except (OSError, ET.ParseError) as e:
    print(e)
    ok = False
check(ok, "demo.svg is well-formed SVG with feature curves")

# 2. extract -> metrics on a small synthetic log reproduces the library's numbers.
log = os.path.join(WORK, "synth.log")
exp = subprocess.run([SYNTH, log, "40"], capture_output=True, text=True)
check(exp.returncode == 0, "synth_log writes the log")
expected = dict(l.split("=", 1) for l in exp.stdout.split())
r = run(["extract", "synth.log", "-o", "synth.bsf"])
check(r.returncode == 0, "bsf extract on the synthetic log exits 0")
r = run(["metrics", "synth.bsf"], text=True)
check(r.returncode == 0, "bsf metrics exits 0")
m = metrics_of(r.stdout)
try:
    check(int(m["scans"][0]) == int(expected["scans"]), "metrics: scan count")
    check(abs(float(m["retrievability"][0]) - float(expected["retrievability"])) < 0.01,
          "metrics: retrievability equals the library's (%s vs %s)" % (m["retrievability"][0], expected["retrievability"]))
    check(abs(float(m["compactness"][0]) - float(expected["compactness"])) < 1e-4,
          "metrics: compactness equals the library's (%s vs %s)" % (m["compactness"][0], expected["compactness"]))
    # E_curve travels in 0.5 mm steps: each value moves by <= 0.25 mm, the mean over 40 scans far less
    check(abs(float(m["accuracy"][0]) - float(expected["accuracy"])) < 1e-4,
          "metrics: accuracy equals the library's within the wire's E_curve step (%s vs %s)" % (m["accuracy"][0], expected["accuracy"]))
    check(abs(float(m["features/scan"][0]) - float(expected["features_per_scan"])) < 0.01,
          "metrics: features per scan")
except (KeyError, ValueError) as e:
    check(False, "metrics output parsable (%r)" % (e,))

# the same through pipes: extract -o - | metrics -
p1 = subprocess.Popen([BSF, "extract", "synth.log", "-o", "-"], cwd=WORK, stdout=subprocess.PIPE,
                      stderr=subprocess.DEVNULL)
p2 = subprocess.run([BSF, "metrics", "-"], cwd=WORK, stdin=p1.stdout, capture_output=True, text=True)
p1.stdout.close()
check(p1.wait() == 0 and p2.returncode == 0 and metrics_of(p2.stdout).get("compactness") == m.get("compactness"),
      "extract -o - | metrics - gives the same numbers")

# 3. decode of a corrupted stream reports the drops, and keeps the intact frames.
data = bytearray(open(os.path.join(WORK, "synth.bsf"), "rb").read())
rnd = random.Random(7)
n_frames = data.count(0)
for pos in rnd.sample(range(len(data)), 5):
    data[pos] ^= 0x5A if data[pos] != 0x5A else 0x11
open(os.path.join(WORK, "bad.bsf"), "wb").write(bytes(data))
r = run(["decode", "bad.bsf", "--json"], text=True)
check(r.returncode == 0, "decode of a corrupted stream exits 0")
lines = r.stdout.strip().splitlines()
import json
counters = json.loads(lines[-1])["counters"]
frames = [json.loads(l) for l in lines[:-1]]
dropped = counters["bad_crc"] + counters["malformed"] + counters["oversize"] + counters["unsupported_version"]
check(dropped >= 1, "decode reports dropped frames (%d)" % dropped)
check(len(frames) >= n_frames - 10 and len(frames) < n_frames + 1, "decode keeps the intact frames (%d of %d)" % (len(frames), n_frames))
r = run(["metrics", "bad.bsf"], text=True)
check(r.returncode == 0 and "frames dropped" in r.stdout and not r.stdout.count("frames dropped    0 "), "metrics reports dropped frames")

# 4. render writes an SVG with the features.
r = run(["render", "synth.bsf", "-o", "map.svg", "--scans", "0..9", "--points", "synth.log"])
try:
    root = ET.parse(os.path.join(WORK, "map.svg")).getroot()
    ok = r.returncode == 0 and len(root.findall(".//{http://www.w3.org/2000/svg}circle")) > 100
except (OSError, ET.ParseError):
    ok = False
check(ok, "render with --points writes a well-formed SVG with points and curves")

# 5. usage errors: non-zero exit and a message on stderr.
for args, what in [([], "no command"), (["frobnicate"], "unknown command"),
                   (["extract"], "extract without LOG"), (["extract", "synth.log", "--method", "nope"], "bad method"),
                   (["extract", "synth.log", "--count", "-3"], "negative count"),
                   (["extract", "missing.log", "-o", "x.bsf"], "missing log file"),
                   (["render", "synth.bsf"], "render without -o"), (["render", "synth.bsf", "-o", "m.svg", "--scans", "9..2"], "bad scan range"),
                   (["decode"], "decode without input"), (["table1"], "table1 without dir"),
                   (["demo", "--scans", "0"], "demo with zero scans")]:
    r = run(args, text=True)
    check(r.returncode != 0 and r.stderr.strip() != "", "usage error: " + what)
for cmd in ["extract", "decode", "metrics", "render", "table1", "demo"]:
    r = run([cmd, "--help"], text=True)
    check(r.returncode == 0 and "Usage: bsf " + cmd in r.stdout, "%s --help" % cmd)

# 6. a malformed log line is reported as file:line and skipped
with open(os.path.join(WORK, "synth.log")) as f:
    lines = f.readlines()
lines.insert(3, "ROBOTLASER1 0 -1.57 3.14 0.0174 50 0.01 0 5 1 2 x\n")
with open(os.path.join(WORK, "broken.log"), "w") as f:
    f.writelines(lines)
r = run(["extract", "broken.log", "-o", "broken.bsf"], text=True)
check(r.returncode == 0 and "broken.log:4" in r.stderr, "malformed line reported as broken.log:4 and skipped")

# 7. a scan that exceeds a cap is kept with what fits and reported as cut, not failed
exp = subprocess.run([SYNTH, os.path.join(WORK, "clutter.log"), "12", "clutter"], capture_output=True, text=True)
check(exp.returncode == 0, "synth_log writes the clutter log")
expected = dict(l.split("=", 1) for l in exp.stdout.split())
n_cut = int(expected["cut_scans"])
check(0 < n_cut < 12, "some clutter scans exceed the default keypoint cap (%d of 12)" % n_cut)
tool_caps = run(["--version"], text=True).stdout.split("caps: ")[-1].split()
same_caps = ",".join(tool_caps) == expected["caps"]
if not same_caps:  # a tool built with larger caps cuts fewer (or none) of these scans
    print("note: the tool's caps (%s) are not the library defaults (%s)" % (" ".join(tool_caps), expected["caps"]))
r = run(["extract", "clutter.log", "--method", "falko-sved-pdm", "-o", "clutter.bsf"], text=True)
check(r.returncode == 0 and "12 scans extracted" in r.stderr and " 0 failed" in r.stderr,
      "bsf extract keeps cut scans, none failed, and exits 0")
n_lines = r.stderr.count("cut by a cap:")
check(("%d cut by a cap" % n_lines) in r.stderr, "each cut scan is reported with file:line and counted apart from failures")
if same_caps:
    check(n_lines == n_cut and ("left out %s keypoints" % expected["cut_keypoints"]) in r.stderr,
          "bsf extract reports the %d cut scans and the keypoints the library left out" % n_cut)
r = run(["metrics", "clutter.bsf"], text=True)
check(r.returncode == 0 and metrics_of(r.stdout).get("scans", ["?"])[0] == "12",
      "bsf metrics reads every scan of the cut stream")

print("%d checks failed" % len(failures) if failures else "all tool checks passed")
sys.exit(1 if failures else 0)
