#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""CTest driver for `bsf extract --map --align`: a synthetic log whose
odometry drifts (the robot pose fields) fuses into a map that lies on the
true walls when aligned and off them when not; odometry from sequential
pose-graph edges; the prior path (--prior-path) drawn dashed beside the
corrected one by bsf map and bsf render; errors on bad option combinations.

Usage: test_align.py BSF_EXE SYNTH_LOG_EXE WORK_DIR
"""
import gzip
import json
import math
import os
import random
import shutil
import subprocess
import sys

BSF, SYNTH, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
failures = []


def check(cond, what):
    print(("ok      " if cond else "FAILED  ") + what, flush=True)
    if not cond:
        failures.append(what)


def run(args):
    return subprocess.run([BSF] + args, cwd=WORK, capture_output=True, text=True)


def compose(a, b):
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2])


def between(a, b):
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return (c * dx + s * dy, -s * dx + c * dy, math.remainder(b[2] - a[2], 2 * math.pi))


def dist_to_segments(x, y, segs):
    best = math.inf
    for sh in segs:
        if len(sh) == 3:
            best = min(best, abs(math.hypot(x - sh[0], y - sh[1]) - sh[2]))
            continue
        x0, y0, x1, y1 = sh
        dx, dy = x1 - x0, y1 - y0
        t = max(0.0, min(1.0, ((x - x0) * dx + (y - y0) * dy) / (dx * dx + dy * dy)))
        best = min(best, math.hypot(x0 + t * dx - x, y0 + t * dy - y))
    return best


def curve_points(ctrl):
    spans = len(ctrl) - 2
    out = []
    for s in range(spans):
        for j in range(5):
            u = j / 4
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


def share_far(stream, segs, far):
    res = run(["map", stream, "--json"])
    check(res.returncode == 0, "bsf map --json reads " + stream)
    pts = []
    for line in res.stdout.splitlines():
        pts += curve_points(json.loads(line)["ctrl"])
    if not pts:
        return 1.0
    return sum(1 for p in pts if dist_to_segments(p[0], p[1], segs) > far) / len(pts)


shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
room = os.path.join(WORK, "room.log")
exp = subprocess.run([SYNTH, room, "120", "walls"], capture_output=True, text=True)
check(exp.returncode == 0, "synth_log writes the log and its walls")
segs = []
for tok in exp.stdout.split():
    if tok.startswith("shape=segment,") or tok.startswith("shape=circle,"):
        segs.append(tuple(float(v) for v in tok.split(",")[1:]))
check(len(segs) >= 4, "the room has walls")
res = run(["extract", "room.log", "--map", "--reproducible", "-o", "true.bsf"])
check(res.returncode == 0, "extract --map on the true poses")

# Drifting odometry: the true motions with 3 % more distance and 2 degrees
# per metre more turn, plus seeded noise; the laser pose of the first scan
# stays true (it anchors the map), the rest carry the drifted poses in a
# second log for the prior-only map.
rng = random.Random(7)
lines = open(room).read().splitlines()
truth, odo, laser_fields = [], [], []
for ln in lines:
    t = ln.split()
    if t and t[0] == "ROBOTLASER1":
        n = int(t[8])
        m = int(t[9 + n])
        i = 10 + n + m
        truth.append(tuple(float(v) for v in t[i:i + 3]))
        laser_fields.append(i)
for k, p in enumerate(truth):
    if k == 0:
        odo.append(p)
        continue
    d = between(truth[k - 1], p)
    dist = math.hypot(d[0], d[1])
    noisy = (d[0] * 1.03 + rng.gauss(0, 0.005), d[1] * 1.03 + rng.gauss(0, 0.005),
             d[2] + math.radians(2.0) * dist + rng.gauss(0, 0.002))
    odo.append(compose(odo[-1], noisy))
drift = max(math.hypot(o[0] - p[0], o[1] - p[1]) for o, p in zip(odo, truth))
check(drift > 0.15, "the odometry drifts (%.2f m at most)" % drift)

aligned_log, prior_log = [], []
k = 0
for ln in lines:
    t = ln.split()
    if t and t[0] == "ROBOTLASER1":
        i = laser_fields[k]
        o = odo[k]
        a = list(t)
        a[i + 3:i + 6] = ["%.6f" % o[0], "%.6f" % o[1], "%.6f" % o[2]]
        b = list(a)
        b[i:i + 3] = ["%.6f" % o[0], "%.6f" % o[1], "%.6f" % o[2]]
        aligned_log.append(" ".join(a))
        prior_log.append(" ".join(b))
        k += 1
    else:
        aligned_log.append(ln)
        prior_log.append(ln)
open(os.path.join(WORK, "drift.log"), "w").write("\n".join(aligned_log) + "\n")
open(os.path.join(WORK, "prior.log"), "w").write("\n".join(prior_log) + "\n")

res = run(["extract", "prior.log", "--map", "--reproducible", "-o", "prior.bsf"])
check(res.returncode == 0, "extract --map on the drifted poses")
res = run(["extract", "drift.log", "--map", "--align", "--reproducible", "-o", "aligned.bsf"])
check(res.returncode == 0, "extract --map --align succeeds: " + res.stderr.strip()[-200:])
check("align: 119 scans aligned (odometry: the log's poses)" in res.stderr,
      "the summary counts the aligned scans")
far_prior = share_far("prior.bsf", segs, 0.05)
far_aligned = share_far("aligned.bsf", segs, 0.05)
far_true = share_far("true.bsf", segs, 0.05)
print("curve samples farther than 5 cm from a surface: true poses %.3f, prior %.3f, aligned %.3f"
      % (far_true, far_prior, far_aligned))
check(far_prior > 0.2, "the prior-only map is off the walls")
check(far_aligned < 0.05 and far_aligned < far_prior / 10, "the aligned map lies on the walls")
res2 = run(["extract", "drift.log", "--map", "--align", "--reproducible", "-o", "aligned2.bsf"])
check(res2.returncode == 0 and open(os.path.join(WORK, "aligned.bsf"), "rb").read() ==
      open(os.path.join(WORK, "aligned2.bsf"), "rb").read(), "--align is reproducible")

# Odometry from sequential edges: the same drifted motions as a pose graph.
edges = ["#SEQUENTIAL EDGES"]
for k in range(1, len(odo)):
    d = between(odo[k - 1], odo[k])
    edges.append("EDGE2 %d %d %.6f %.6f %.6f 100 0 100 500 0 0" % (k - 1, k, d[0], d[1], d[2]))
open(os.path.join(WORK, "edges.log"), "w").write("\n".join(lines + edges) + "\n")
res = run(["extract", "edges.log", "--map", "--align", "--odometry", "edges", "--reproducible",
           "-o", "edges.bsf"])
check(res.returncode == 0, "extract --align --odometry edges succeeds")
check("odometry: sequential edges" in res.stderr, "the summary names the edges")
check(share_far("edges.bsf", segs, 0.05) < 0.05, "the map aligned with edge odometry lies on the walls")
# The same log gzip-compressed (zlib, or the system's gzip in a build
# without zlib): the same map; a cut gzip file is a read error.
with open(os.path.join(WORK, "edges.log"), "rb") as f_in:
    packed = gzip.compress(f_in.read(), mtime=0)
with open(os.path.join(WORK, "edges.log.gz"), "wb") as f_out:
    f_out.write(packed)
with open(os.path.join(WORK, "cut.log.gz"), "wb") as f_out:
    f_out.write(packed[: len(packed) // 2])
res = run(["extract", "edges.log.gz", "--map", "--align", "--odometry", "edges", "--reproducible",
           "-o", "edges_gz.bsf"])
m1 = run(["map", "edges.bsf", "--json"])
m2 = run(["map", "edges_gz.bsf", "--json"])
check(res.returncode == 0 and m1.returncode == 0 and m2.returncode == 0 and m1.stdout == m2.stdout,
      "edges from a gzip log give the same map")
res = run(["extract", "cut.log.gz", "--map", "--align", "--odometry", "edges", "-o", "x.bsf"])
check(res.returncode == 1 and "cut.log.gz" in res.stderr, "a cut gzip log is refused with its name")

# The prior path beside the corrected one: --prior-path writes both per
# fused scan, bsf map --prior and bsf render --prior draw the prior dashed.
res = run(["extract", "drift.log", "--map", "--align", "--reproducible", "--prior-path", "prior.csv",
           "-o", "aligned3.bsf"])
check(res.returncode == 0, "extract --align --prior-path succeeds")
check(open(os.path.join(WORK, "aligned3.bsf"), "rb").read() ==
      open(os.path.join(WORK, "aligned.bsf"), "rb").read(), "--prior-path leaves the stream as it was")
rows = open(os.path.join(WORK, "prior.csv")).read().splitlines()
check(rows[0] == "scan,time_s,odometry_x,odometry_y,odometry_theta,prior_x,prior_y,prior_theta,"
      "aligned_x,aligned_y,aligned_theta",
      "the prior path CSV names its columns")
rows = [[float(v) for v in r.split(",")] for r in rows[1:]]
check(len(rows) == len(truth) and [int(r[0]) for r in rows] == list(range(len(truth))),
      "one row per fused scan, by scan index")
log_times = [float(ln.split()[-3]) for ln in lines if ln.startswith("ROBOTLASER1")]
check(all(abs(r[1] - t) < 1e-6 for r, t in zip(rows, log_times)), "the rows carry the log's times")
check(rows[0][2:5] == rows[0][5:8] == rows[0][8:11] and
      max(abs(a - b) for a, b in zip(rows[0][2:5], truth[0])) < 1e-5,
      "the first scan's odometry, prior and aligned poses are the log's")


def pose_gap(a, b):
    return max(math.hypot(a[0] - b[0], a[1] - b[1]), abs(math.remainder(a[2] - b[2], 2 * math.pi)))


# the odometry columns are the log's odometry alone (it starts at the true first pose)
worst_odo = max(pose_gap(r[2:5], o) for r, o in zip(rows, odo))
check(worst_odo < 1e-4, "the odometry columns chain the log's odometry (%.2g)" % worst_odo)
# each prior is the previous aligned pose moved by the odometry's motion
worst = max(pose_gap(rows[k][5:8], compose(tuple(rows[k - 1][8:11]), between(odo[k - 1], odo[k])))
            for k in range(1, len(rows)))
check(worst < 1e-4, "each prior is the previous aligned pose plus the odometry (%.2g)" % worst)
def rms(c):
    return math.sqrt(sum((r[c] - p[0]) ** 2 + (r[c + 1] - p[1]) ** 2 for r, p in zip(rows, truth)) / len(rows))


print("RMS position error against the truth: odometry %.3f m, aligned %.3f m" % (rms(2), rms(8)))
check(rms(2) > 0.08 and rms(8) < rms(2) / 2, "the aligned poses are nearer the truth than the odometry")
# the aligned columns are the stream's pose records (bsf listen, 1 mm)
res = run(["listen", "aligned3.bsf"])
recs = [tuple(float(v) for v in ln.split("pose=(")[1].split(")")[0].split(","))
        for ln in res.stdout.splitlines() if "pose=(" in ln]
check(len(recs) == len(rows) and all(abs(p[0] - r[8]) < 1.5e-3 and abs(p[1] - r[9]) < 1.5e-3
                                     for p, r in zip(recs, rows)),
      "the aligned columns are the stream's pose records")


def polylines(svg):
    """(attributes, points) of each <polyline> of an SVG."""
    out = []
    for chunk in svg.split("<polyline points=\"")[1:]:
        pts, rest = chunk.split("\"", 1)
        out.append((rest.split("/>")[0], [tuple(float(v) for v in p.split(",")) for p in pts.split()]))
    return out


def check_two_paths(svg_name, n_prior, what):
    svg = open(os.path.join(WORK, svg_name)).read()
    lines_ = polylines(svg)
    dashed = [pts for attrs, pts in lines_ if "stroke-dasharray" in attrs and "#ff7f0e" in attrs]
    solid = [pts for attrs, pts in lines_ if "stroke-dasharray" not in attrs and "#2ca02c" in attrs]
    check(len(dashed) == 1 and len(dashed[0]) == n_prior,
          "%s: the prior path is one dashed line through its %d poses" % (what, n_prior))
    check(len(solid) == 1 and len(solid[0]) == n_prior, "%s: the corrected path is a solid line" % what)
    if dashed and solid:
        # in pixels: the drift shows, the two lines part
        gap = max(math.hypot(a[0] - b[0], a[1] - b[1]) for a, b in zip(dashed[0], solid[0]))
        check(gap > 5.0, "%s: the two paths part by %.0f px" % (what, gap))
    check(">prior path (odometry)</text>" in svg and ">corrected path (aligned) and last pose</text>" in svg,
          "%s: the legend names both paths" % what)
    check("%d prior poses" % n_prior in svg, "%s: the caption counts the prior poses" % what)


res = run(["map", "aligned3.bsf", "-o", "prior_map.svg", "--prior", "prior.csv"])
check(res.returncode == 0, "bsf map --prior draws: " + res.stderr.strip()[-200:])
check_two_paths("prior_map.svg", len(rows), "bsf map")
res = run(["map", "aligned3.bsf", "-o", "plain_map.svg"])
plain = open(os.path.join(WORK, "plain_map.svg")).read()
check(res.returncode == 0 and "stroke-dasharray" not in plain.split("<g")[0] + "".join(
    a for a, _ in polylines(plain)) and "prior path" not in plain and ">robot path and last pose</text>" in plain,
      "without --prior, one path and the usual legend")
# bsf render: a per-scan stream of the same log (true laser poses) with the prior beside
res = run(["extract", "drift.log", "--reproducible", "-o", "scans.bsf"])
check(res.returncode == 0, "extract the per-scan stream")
res = run(["render", "scans.bsf", "-o", "prior_render.svg", "--prior", "prior.csv"])
check(res.returncode == 0, "bsf render --prior draws: " + res.stderr.strip()[-200:])
check_two_paths("prior_render.svg", len(rows), "bsf render")
res = run(["render", "scans.bsf", "-o", "prior_some.svg", "--prior", "prior.csv", "--scans", "10..29"])
check(res.returncode == 0, "bsf render --scans --prior draws")
check_two_paths("prior_some.svg", 20, "bsf render --scans 10..29")

# A bad prior file is refused with its line.
open(os.path.join(WORK, "bad_header.csv"), "w").write("x,y\n1,2\n")
csv_rows = open(os.path.join(WORK, "prior.csv")).read().splitlines()
open(os.path.join(WORK, "bad_row.csv"), "w").write("\n".join(csv_rows[:5] + ["5,1.0,nan,0,0,0,0,0,0,0,0"]) + "\n")
open(os.path.join(WORK, "short_row.csv"), "w").write("\n".join(csv_rows[:3] + ["3,1.0,2.0"]) + "\n")
open(os.path.join(WORK, "empty.csv"), "w").write("")
for name, needle in (("bad_header.csv", "bad_header.csv:1: not a prior path"),
                     ("bad_row.csv", "bad_row.csv:6: malformed row"),
                     ("short_row.csv", "short_row.csv:4: malformed row"),
                     ("empty.csv", "empty.csv is empty"),
                     ("missing.csv", "cannot open missing.csv")):
    for cmd in (["map", "aligned3.bsf", "-o", "x.svg"], ["render", "scans.bsf", "-o", "x.svg"]):
        res = run(cmd + ["--prior", name])
        check(res.returncode == 1 and needle in res.stderr, "bsf %s refuses %s: %s" % (cmd[0], name, needle))
res = run(["map", "aligned3.bsf", "--prior", "prior.csv"])
check(res.returncode == 2 and "--prior goes with -o" in res.stderr, "bsf map --prior needs -o")
res = run(["extract", "drift.log", "--map", "--prior-path", "p.csv", "-o", "x.bsf"])
check(res.returncode == 2 and "--prior-path goes with --align" in res.stderr, "--prior-path needs --align")
res = run(["extract", "drift.log", "--map", "--align", "--prior-path", "-", "-o", "x.bsf"])
check(res.returncode == 2 and "a file of its own" in res.stderr, "--prior-path needs a file of its own")
res = run(["extract", "drift.log", "--map", "--align", "--prior-path", "no_dir/p.csv", "-o", "untouched.bsf"])
check(res.returncode == 1 and "cannot create no_dir/p.csv" in res.stderr and
      not os.path.exists(os.path.join(WORK, "untouched.bsf")), "an unwritable --prior-path leaves no stream behind")
res = run(["extract", "drift.log", "--map", "--align", "--prior-path", "lone.csv", "-o", "no_dir/x.bsf"])
check(res.returncode == 1 and not os.path.exists(os.path.join(WORK, "lone.csv")),
      "an unwritable stream leaves no prior path behind")

# Errors.
res = run(["extract", "drift.log", "--align", "-o", "x.bsf"])
check(res.returncode == 2 and "--align goes with --map" in res.stderr, "--align needs --map")
res = run(["extract", "drift.log", "--map", "--odometry", "log", "-o", "x.bsf"])
check(res.returncode == 2 and "--odometry goes with --align" in res.stderr, "--odometry needs --align")
res = run(["extract", "drift.log", "--map", "--align", "--odometry", "wheels", "-o", "x.bsf"])
check(res.returncode == 2 and "'log' or 'edges'" in res.stderr, "an unknown odometry source is refused")
res = run(["extract", "drift.log", "--map", "--align", "--odometry", "edges", "-o", "x.bsf"])
check(res.returncode == 1 and "no sequential EDGE2" in res.stderr, "a log without edges is refused")

if failures:
    print("%d checks failed" % len(failures))
    sys.exit(1)
print("all checks passed")
