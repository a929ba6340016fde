#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""CTest driver for the fused map in the host tool: `bsf extract --map`,
`bsf map` (JSON and SVG), `bsf metrics` and `bsf listen` on a map stream,
and their errors on bad input.

Usage: test_map.py BSF_EXE SYNTH_LOG_EXE WORK_DIR
"""
import json
import math
import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

BSF, SYNTH, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
SVG = "{http://www.w3.org/2000/svg}"
failures = []


def check(cond, what):
    print(("ok      " if cond else "FAILED  ") + what, flush=True)
    if not cond:
        failures.append(what)


def run(args, **kw):
    return subprocess.run([BSF] + args, cwd=WORK, capture_output=True, **kw)


def dist_to_shapes(x, y, shapes):
    best = math.inf
    for s in shapes:
        if s[0] == "circle":
            cx, cy, r = s[1:]
            d = abs(math.hypot(x - cx, y - cy) - r)
        else:
            x0, y0, x1, y1 = s[1:]
            dx, dy = x1 - x0, y1 - y0
            t = max(0.0, min(1.0, ((x - x0) * dx + (y - y0) * dy) / (dx * dx + dy * dy)))
            d = math.hypot(x0 + t * dx - x, y0 + t * dy - y)
        best = min(best, d)
    return best


def curve_samples(ctrl, per_span=8):
    """The clamped uniform quadratic B-spline through ctrl (closed forms)."""
    spans = len(ctrl) - 2
    out = []
    for s in range(spans):
        for j in range(per_span + 1):
            u = j / per_span
            a, b, q = (1 - u) ** 2, 2 * u * (1 - u), u * u
            if spans == 1:
                w = (a, b, q)
            elif s == 0:
                w = (a, b + 0.5 * q, 0.5 * q)
            elif s == spans - 1:
                w = (0.5 * a, 0.5 * a + b, q)
            else:
                w = (0.5 * a, 0.5 * a + b + 0.5 * q, 0.5 * q)
            out.append(tuple(w[0] * ctrl[s][k] + w[1] * ctrl[s + 1][k] + w[2] * ctrl[s + 2][k] for k in range(2)))
    return out


shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)

# A synthetic log of a known L-shaped room with a pillar, and its true surfaces.
exp = subprocess.run([SYNTH, os.path.join(WORK, "room.log"), "80", "walls"], capture_output=True, text=True)
check(exp.returncode == 0, "synth_log writes the log and its walls")
shapes = []
for line in exp.stdout.split():
    if line.startswith("shape="):
        parts = line[len("shape="):].split(",")
        shapes.append((parts[0],) + tuple(float(v) for v in parts[1:]))
check(len(shapes) == 7, "the room has six walls and a pillar")
corners = []
segs = [s for s in shapes if s[0] == "segment"]
for a in segs:
    for b in segs:
        if a is not b and math.hypot(a[3] - b[1], a[4] - b[2]) < 1e-9:
            corners.append((a[3], a[4]))

# 1. extract --map writes a map stream: metadata first, then map frames only.
r = run(["extract", "room.log", "--map", "--reproducible", "-o", "room.map"])
check(r.returncode == 0, "bsf extract --map exits 0")
m = re.search(rb"map: (\d+) frames, (\d+) bytes of map records and headers, (\d+) of pose records", r.stderr)
encoder_bytes = (int(m.group(2)), int(m.group(3))) if m else None
check(b"map:" in r.stderr and b"bytes of RAM" in r.stderr, "extract --map reports the map (bytes, RAM)")
r2 = run(["extract", "room.log", "--reproducible", "-o", "room.bsf"])
check(r2.returncode == 0, "bsf extract (per-scan) exits 0")
map_size = os.path.getsize(os.path.join(WORK, "room.map"))
scan_size = os.path.getsize(os.path.join(WORK, "room.bsf"))
check(0 < map_size < scan_size, f"the map stream ({map_size} B) is smaller than the per-scan stream ({scan_size} B)")
r = run(["decode", "room.map", "--json"])
lines = [json.loads(l) for l in r.stdout.decode().splitlines() if l.startswith("{")]
check(r.returncode == 0 and len(lines) > 1, "bsf decode reads the map stream")
check(bool(lines) and "metadata" in json.dumps(lines[0]), "the metadata frame comes first")
maps = [l["map"] for l in lines if "map" in l]
check(len(maps) == 80 and [m["seq"] for m in maps] == list(range(80)), "decode --json: one map frame per scan, in sequence")
check(all(m["payload"].startswith("23") for m in maps), "decode --json: payloads of version 2, type 3")
r = run(["render", "room.map", "-o", "render.svg"])
check(r.returncode == 1 and b"bsf map" in r.stderr, "bsf render on a map stream: exit 1, points to bsf map")
r3 = run(["extract", "room.log", "--map", "--reproducible", "-o", "room2.map"])
with open(os.path.join(WORK, "room.map"), "rb") as f1, open(os.path.join(WORK, "room2.map"), "rb") as f2:
    check(f1.read() == f2.read(), "extract --map --reproducible gives the same bytes twice")

# 2. bsf map --json: one object per feature; known walls land where they are.
r = run(["map", "room.map", "--json"])
check(r.returncode == 0, "bsf map --json exits 0")
feats = [json.loads(l) for l in r.stdout.decode().splitlines()]
check(len(feats) >= 2, f"the map has features ({len(feats)})")
ok_form = True
for f in feats:
    ok_form &= isinstance(f["id"], int) and len(f["ctrl"]) >= 3 and len(f["ctrl"]) == len(f["vertex"])
    ok_form &= all(v in (0, 1) for v in f["vertex"]) and f["stale"] is False
    flagged = [i for i, v in enumerate(f["vertex"]) if v]
    ok_form &= len(flagged) % 2 == 0 and all(
        flagged[i + 1] == flagged[i] + 1 and f["ctrl"][flagged[i]] == f["ctrl"][flagged[i + 1]] for i in range(0, len(flagged), 2)
    )
check(ok_form, "every feature: id, >= 3 control points, vertex flags in equal pairs")
check(len({f["id"] for f in feats}) == len(feats), "feature ids are unique")
samples = [p for f in feats for p in curve_samples(f["ctrl"])]
# a straight wall between two vertices is one span: dense samples for coverage
dense = [p for f in feats for p in curve_samples(f["ctrl"], 128)]
d = sorted(dist_to_shapes(x, y, shapes) for x, y in samples)
p90 = d[int(0.90 * (len(d) - 1))] if d else math.inf
check(bool(d) and p90 < 0.03, f"map curves lie on the true walls (p90 {1000 * p90:.1f} mm < 30 mm)")
check(bool(d) and d[len(d) // 2] < 0.015, "median curve distance to the walls < 15 mm")
check(bool(d) and d[-1] < 0.15, f"no map curve strays from the walls (max {1000 * d[-1]:.1f} mm < 150 mm)")
# the walls the robot saw are covered: points every 5 cm along the two long walls in view
def covered(x0, y0, x1, y1):
    n = int(math.hypot(x1 - x0, y1 - y0) / 0.05)
    pts = [(x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n) for k in range(1, n)]
    near = sum(1 for px, py in pts if min(math.hypot(px - sx, py - sy) for sx, sy in dense) < 0.05)
    return near / max(1, len(pts))


# the robot (y = 1.2, heading 0.3 rad, 180 degrees) faces the far wall and the notch
check(covered(0.5, 0.0, 7.5, 0.0) > 0.8, "the wall y = 0 is in the map")
check(covered(4.5, 6.0, 0.5, 6.0) > 0.8, "the far wall y = 6 is in the map")
check(covered(7.5, 3.5, 5.5, 3.5) > 0.8, "the notch wall y = 3.5 is in the map")
vertices = [tuple(f["ctrl"][i]) for f in feats for i, v in enumerate(f["vertex"]) if v]
found = [c for c in corners if any(math.hypot(c[0] - vx, c[1] - vy) < 0.05 for vx, vy in vertices)]
check(len(found) >= 2, f"true corners are map vertices within 5 cm ({len(found)} of {len(corners)})")

# 3. the text summary and the SVG.
r = run(["map", "room.map"])
check(r.returncode == 0 and b"features" in r.stdout and b"map frames" in r.stdout, "bsf map prints a summary")
# 2b. A lost map frame: every feature that differs from the lossless map is
# flagged (stale in --json) or missing (counted in the summary), never wrong
# without a word; a damaged last frame leaves every feature flagged.
with open(os.path.join(WORK, "room.map"), "rb") as f:
    pieces = f.read().split(b"\x00")
frames_idx = [i for i, p in enumerate(pieces) if p]
# the longest map frame (COBS keeps the version/type byte 0x23 second): it carries map records
lost = max((i for i in frames_idx if len(pieces[i]) > 1 and pieces[i][1] == 0x23), key=lambda i: len(pieces[i]))
lossy = [p for i, p in enumerate(pieces) if i != lost]
with open(os.path.join(WORK, "lossy.map"), "wb") as f:
    f.write(b"\x00".join(lossy))
r = run(["map", "lossy.map", "--json"])
lossy_feats = {f["id"]: f for f in (json.loads(l) for l in r.stdout.decode().splitlines())}
summary = re.search(rb"(\d+) features, .* (\d+) stale, (\d+) missing;", r.stderr)
check(r.returncode == 0 and summary is not None, "bsf map --json of a stream with a lost frame: exit 0, summary")
unflagged = [fid for fid, f in ((f["id"], f) for f in feats)
             if fid in lossy_feats and not lossy_feats[fid]["stale"]
             and (lossy_feats[fid]["ctrl"] != f["ctrl"] or lossy_feats[fid]["vertex"] != f["vertex"])]
absent = [f["id"] for f in feats if f["id"] not in lossy_feats]
check(not unflagged, f"a lost frame: every feature that differs is flagged stale (unflagged: {unflagged})")
check(summary is not None and len(absent) <= int(summary.group(3)),
      f"a lost frame: features never received are counted missing ({len(absent)} absent)")
check(any(f["stale"] for f in lossy_feats.values()) or (summary is not None and int(summary.group(3)) > 0),
      "losing the longest map frame leaves features flagged or missing")
damaged = list(pieces)
last = bytearray(damaged[frames_idx[-1]])
last[len(last) // 2] ^= 0x01
damaged[frames_idx[-1]] = bytes(last) if 0 not in last else damaged[frames_idx[-1]]
with open(os.path.join(WORK, "damaged_last.map"), "wb") as f:
    f.write(b"\x00".join(damaged))
r = run(["map", "damaged_last.map"])
summary = re.search(rb"(\d+) features, .* (\d+) stale, (\d+) missing;", r.stdout)
check(r.returncode == 0 and summary is not None and int(summary.group(1)) > 0
      and summary.group(1) == summary.group(2),
      "a damaged last frame: the receiver cannot vouch for any feature (all stale)")

r = run(["map", "room.map", "-o", "room.svg"])
check(r.returncode == 0, "bsf map -o room.svg exits 0")
try:
    root = ET.parse(os.path.join(WORK, "room.svg")).getroot()
    text = ET.tostring(root).decode()
    ok = root.tag.endswith("svg") and 'class="features"' in text and "robot path" in text and "vertices" in text
except (OSError, ET.ParseError) as e:
    print(e)
    ok = False
check(ok, "room.svg: curves, robot path and legend as bsf render draws them")

r = run(["map", "room.map", "-o", "points.svg", "--points", "room.log"])
try:
    text = ET.tostring(ET.parse(os.path.join(WORK, "points.svg")).getroot()).decode()
    ok = r.returncode == 0 and 'class="points"' in text and "raw LIDAR points" in text
except (OSError, ET.ParseError) as e:
    print(e)
    ok = False
check(ok, "bsf map --points draws the log's raw points under the map")
r = run(["map", "room.map", "--points", "room.log"])
check(r.returncode == 2, "--points without -o: usage error")

# 4. metrics and listen on the map stream.
r = run(["metrics", "room.map"])
check(r.returncode == 0 and b"map frames" in r.stdout and b"pose-only" in r.stdout, "bsf metrics reports the map's bytes")
m = re.search(rb"map frames +\d+, \d+ bytes: map (\d+), pose (\d+)", r.stdout)
check(m is not None and encoder_bytes == (int(m.group(1)), int(m.group(2))),
      f"metrics splits map and pose bytes as the encoder counted them {encoder_bytes}")
with open(os.path.join(WORK, "room.map"), "rb") as f:
    data = f.read()
r = run(["listen", "-"], input=data)
map_lines = [l for l in r.stdout.decode().splitlines() if l.startswith("map seq=")]
check(r.returncode == 0 and len(map_lines) > 1, "bsf listen prints one line per map frame")
check(any("created=" in l and "created=0 " not in l for l in map_lines), "listen shows features created")
def field(line, name):
    m = re.search(r"\b" + name + r"=(\d+)", line)
    return int(m.group(1)) if m else 0


net = sum(field(l, "created") - field(l, "merged") - field(l, "removed") for l in map_lines)
check(net == len(feats), f"listen: created - merged - removed over all frames = the map's features ({net}, {len(feats)})")
check(map_lines and field(map_lines[-1], "features") == len(feats), "listen's last line counts the map's features")
check(map_lines and all(re.search(r"\bflagged=0 absent=0\b", l) for l in map_lines),
      "listen: a lossless map stream never flags a feature")
with open(os.path.join(WORK, "lossy.map"), "rb") as f:
    r = run(["listen", "-"], input=f.read())
lossy_lines = [l for l in r.stdout.decode().splitlines() if l.startswith("map seq=")]
check(r.returncode == 0 and lossy_lines and field(lossy_lines[-1], "missing") == 1
      and field(lossy_lines[-1], "flagged") + field(lossy_lines[-1], "absent") > 0,
      "listen: after a lost map frame the receiver's flagged and absent features show on the line")
check(re.search(r"features \(\d+ flagged: unconfirmed or stale\), \d+ ids never received", r.stdout.decode()) is not None,
      "listen's summary counts flagged features and ids never received")

# 5. loss: a damaged frame in the middle costs only what it carried.
mid = len(data) // 2
damaged = bytearray(data)
damaged[mid] ^= 0x55
with open(os.path.join(WORK, "damaged.map"), "wb") as f:
    f.write(damaged)
r = run(["map", "damaged.map", "--json"])
check(r.returncode == 0, "bsf map on a stream with a damaged frame exits 0")
check(len(r.stdout.splitlines()) >= len(feats) // 2, "most of the map survives one damaged frame")

# 6. pipes: extract --map -o - | bsf map - and | bsf metrics -
p1 = subprocess.Popen([BSF, "extract", "room.log", "--map", "--reproducible", "-o", "-"], cwd=WORK,
                      stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
r = subprocess.run([BSF, "map", "-", "--json"], cwd=WORK, stdin=p1.stdout, capture_output=True)
p1.stdout.close()
check(p1.wait() == 0 and r.returncode == 0 and len(r.stdout.splitlines()) == len(feats),
      "extract --map -o - | bsf map - --json gives the same features")
r = run(["metrics", "-"], input=data)
check(r.returncode == 0 and b"map frames" in r.stdout, "bsf metrics - reads a map stream from a pipe")

# 7. errors: clear messages, non-zero exits.
with open(os.path.join(WORK, "garbage.bin"), "wb") as f:
    f.write(bytes(range(1, 256)) * 40)
r = run(["map", "garbage.bin"])
check(r.returncode == 1 and b"no valid bsf frame" in r.stderr, "bsf map on garbage: exit 1 with a message")
r = run(["map", "room.bsf"])
check(r.returncode == 1 and b"no map frame" in r.stderr, "bsf map on a per-scan stream: exit 1, says why")
r = run(["map"])
check(r.returncode == 2, "bsf map without input: usage error")
r = run(["map", "room.map", "--bogus"])
check(r.returncode == 2, "bsf map with an unknown option: usage error")
r = run(["map", "missing.map"])
check(r.returncode == 1, "bsf map on a missing file: exit 1")
r = run(["map", "--help"])
check(r.returncode == 0 and b"--json" in r.stdout, "bsf map --help")
r = run(["extract", "room.log", "--pose-every", "2", "-o", "x.bsf"])
check(r.returncode == 2, "--pose-every without --map: usage error")
r = run(["extract", "room.log", "--snapshot-budget", "64", "-o", "x.bsf"])
check(r.returncode == 2, "--snapshot-budget without --map: usage error")
r = run(["extract", "room.log", "--map", "--snapshot-budget", "99999", "-o", "x.bsf"])
check(r.returncode == 2, "--snapshot-budget out of range: usage error")
r = run(["extract", "room.log", "--map", "--snapshot-budget", "64", "--reproducible", "-o", "snap.map"])
check(r.returncode == 0 and os.path.getsize(os.path.join(WORK, "snap.map")) > map_size,
      "--snapshot-budget adds snapshot bytes")
r = run(["extract", "room.log", "--map", "--pose-every", "x", "-o", "x.bsf"])
check(r.returncode == 2, "--pose-every with a bad count: usage error")
r = run(["extract", "room.log", "--map", "--pose-every", "0", "-o", "nopose.map"])
check(r.returncode == 0 and os.path.getsize(os.path.join(WORK, "nopose.map")) < map_size, "--pose-every 0: no pose bytes")
r = run(["help"])
check(b"map IN" in r.stdout, "bsf help lists the map command")

print(f"{len(failures)} failed" if failures else "all passed")
sys.exit(1 if failures else 0)
