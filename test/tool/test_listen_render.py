#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""CTest driver for `bsf listen` (live streams) and `bsf render` (map pictures).

Usage: test_listen_render.py BSF_EXE SYNTH_LOG_EXE WORK_DIR [SHARED_DIR]
"""
import os
import pty
import select
import shutil
import subprocess
import sys
import termios
import xml.etree.ElementTree as ET

BSF, SYNTH, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
SHARED = sys.argv[4] if len(sys.argv) > 4 else os.environ.get("BSF_SHARED_DIR", "")
SVG = "{http://www.w3.org/2000/svg}"
failures = []


def check(cond, what):
    print(("ok      " if cond else "FAILED  ") + what, flush=True)
    if not cond:
        failures.append(what)


def run(args, **kw):
    return subprocess.run([BSF] + args, cwd=WORK, capture_output=True, **kw)


def read_line(fd, timeout):
    """One line from a raw fd within timeout seconds (b'' if none came)."""
    data = b""
    while not data.endswith(b"\n"):
        ready, _, _ = select.select([fd], [], [], timeout)
        if not ready:
            break
        chunk = os.read(fd, 1)
        if not chunk:
            break
        data += chunk
    return data


shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
r = run(["demo", "--stream", "demo.bsf", "--svg", "demo.svg"])
check(r.returncode == 0, "bsf demo writes a stream and a map")
with open(os.path.join(WORK, "demo.bsf"), "rb") as f:
    stream = f.read()
# The stream's frames (a metadata frame may come first and now and then).
ends = [i + 1 for i, b in enumerate(stream) if b == 0]
n_frames = len(ends)
ref = run(["listen", "demo.bsf"], text=True).stdout.splitlines()[:-1]
check(len(ref) == n_frames and all(l.startswith(("frame seq=", "metadata ")) for l in ref),
      "listen prints one line per frame of a file (%d)" % n_frames)
n_scans = sum(1 for l in ref if l.startswith("frame seq="))


def counters_of(text):
    last = text.splitlines()[-1] if text.strip() else ""
    if not last.startswith("counters: "):
        return {}
    return dict((f.rpartition(" ")[0], int(f.rpartition(" ")[2]))
                for f in last[len("counters: "):].split(", "))


# ---- listen -------------------------------------------------------------------
# 1. On a pipe, a frame is printed as soon as its delimiter arrives, while the
#    pipe stays open (no block buffering on either side).
p = subprocess.Popen([BSF, "listen", "-", "-o", "saved.bsf"], cwd=WORK, stdin=subprocess.PIPE,
                     stdout=subprocess.PIPE, stderr=subprocess.PIPE)
p.stdin.write(stream[:ends[0]])
p.stdin.flush()
line = read_line(p.stdout.fileno(), 10.0)
check(line.decode().split(" | ")[0] == ref[0].split(" | ")[0],
      "listen prints the first frame before the pipe closes (%r)" % line[:60])
check(p.poll() is None, "listen still runs while the pipe is open")
p.stdin.write(stream[ends[0]:])
p.stdin.close()
rest = p.stdout.read().decode()
p.wait(timeout=10)
check(p.returncode == 0, "listen exits 0 at the end of the stream")
check(rest.count("frame seq=") + line.count(b"frame seq=") == n_scans, "listen prints every scan (%d)" % n_scans)
c = counters_of(rest)
check(c.get("frames ok") == n_frames and c.get("bad crc") == 0 and c.get("missing by sequence") == 0,
      "listen prints the final counters")
with open(os.path.join(WORK, "saved.bsf"), "rb") as f:
    check(f.read() == stream, "listen -o saves the bytes received unchanged")

# 2. A damaged scan is dropped and counted; the next frame is delivered.
k = next(i for i in range(5, n_frames - 1) if ref[i].startswith("frame seq=") and ref[i + 1].startswith("frame seq="))
bad = bytearray(stream)
pos = (ends[k - 1] + ends[k]) // 2
bad[pos] ^= 0x55 if bad[pos] != 0x55 else 0x0F
r = run(["listen", "-"], input=bytes(bad))
out = r.stdout.decode()
lost_seq = ref[k].split()[1]
next_seq = ref[k + 1].split()[1]
check(r.returncode == 0 and (lost_seq + " ") not in out and (next_seq + " ") in out,
      "listen drops a corrupted frame (%s) and resynchronises at the next one" % lost_seq)
c = counters_of(out)
check("dropped=1 missing=1" in out and c.get("frames ok") == n_frames - 1 and c.get("bad crc") == 1,
      "listen's counters show the dropped frame and the gap in sequence numbers")

# A frame cut short at the end of the input is counted, never delivered.
r = run(["listen", "-"], input=stream[:ends[0]] + stream[ends[0]:ends[1] - 9])
out = r.stdout.decode()
c = counters_of(out)
check(r.returncode == 0 and len(out.splitlines()) == 2 and c.get("frames ok") == 1
      and c.get("bad crc", 0) + c.get("malformed", 0) == 1,
      "listen counts a frame cut short by the end of input as dropped")

# 3. On a terminal (a pseudo-terminal here) listen sets raw mode and the baud rate.
try:
    master, slave = pty.openpty()
    slave_name = os.ttyname(slave)
except OSError as e:  # a container without /dev/pts
    master = None
    print("skipped  listen on a tty (%s)" % e)
if master is not None:
    p = subprocess.Popen([BSF, "listen", slave_name, "--baud", "57600", "--count", "3"], cwd=WORK,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    note = read_line(p.stderr.fileno(), 10.0)
    check(b"raw 8N1 at 57600 baud" in note, "listen on a tty reports raw mode at the baud rate (%r)" % note)
    attrs = termios.tcgetattr(slave)
    check(attrs[4] == termios.B57600 and attrs[5] == termios.B57600, "the tty's speed is 57600 baud")
    check(not (attrs[3] & (termios.ICANON | termios.ECHO)) and not (attrs[0] & termios.ICRNL),
          "the tty is in raw mode (no line editing, echo or CR translation)")
    os.write(master, stream[:ends[5]])
    try:
        out, err = p.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        p.kill()
        out, err = p.communicate()
    check(p.returncode == 0 and out.decode().count("frame seq=") == 3,
          "listen delivers the frames written into the tty and stops after --count 3")
    os.close(master)
    os.close(slave)

# 4. Bad options: clear message, non-zero exit.
for args, what in [(["listen", "-", "--baud", "12345"], "a non-standard baud rate"),
                   (["listen", "-", "--baud", "fast"], "a baud rate that is no number"),
                   (["listen", "-", "--count", "0"], "--count 0"),
                   (["listen"], "no device"),
                   (["listen", os.path.join(WORK, "no", "such", "tty")], "a missing device"),
                   (["listen", "-", "-o", os.path.join(WORK, "no", "dir", "x.bsf")], "an unwritable save file")]:
    r = run(args, input=b"")
    check(r.returncode != 0 and b"bsf listen:" in r.stderr, "listen refuses " + what)
r = run(["listen", "-", "--baud", "12345"], input=b"")
check(b"standard rate" in r.stderr, "the baud message names the standard rates")
r = run(["listen", "--help"])
check(r.returncode == 0 and b"Usage: bsf listen" in r.stdout, "listen --help")

# ---- render -------------------------------------------------------------------
def svg_parts(path):
    root = ET.parse(os.path.join(WORK, path)).getroot()
    ids = {g.get("id") for g in root.iter() if g.get("id")}
    paths = root.findall(".//%spath" % SVG)
    dots = sum(p.get("d", "").count("M") for p in paths if p.get("class") == "points")
    curves = sum(p.get("d", "").count("M") for p in paths if p.get("class") == "features")
    vertices = sum(1 for e in root.iter() if e.get("class") == "vertex")
    robot = sum(1 for e in root.iter() if e.get("class") == "robot")
    path_lines = [e for e in root.findall(".//%spolyline" % SVG) if e.get("stroke") == "#2ca02c"]
    return ids, dots, curves, vertices, robot, path_lines, root


ids, dots, curves, vertices, robot, path_lines, root = svg_parts("demo.svg")
check({"grid", "grid-labels", "scale-bar", "legend"} <= ids, "demo map has a grid, labels, a scale bar and a legend (%s)" % sorted(ids))
check(any(t.text and t.text.endswith(" m") for t in root.iter("%stext" % SVG)), "grid labels are in metres")
check(curves >= 100, "demo map draws the features as curves (%d)" % curves)
check(vertices > 0, "demo map marks vertices (%d)" % vertices)
check(robot == 1 and len(path_lines) == 1 and path_lines[0].get("points", "").count(",") == 60,
      "demo map draws the robot path through the 60 poses and the last pose")
legend = " ".join(t.text or "" for t in root.findall(".//%sg[@id='legend']/%stext" % (SVG, SVG)))
check("B-spline features" in legend and "vertices" in legend and "robot path" in legend and "true walls" in legend,
      "the legend names every layer (%s)" % legend)

# A dense log with points: thinned, so the picture stays small. One dot per
# point (the old rendering) would be about 20 MB for these 361 000 points.
subprocess.run([SYNTH, os.path.join(WORK, "dense.log"), "1000"], check=True, capture_output=True)
r = run(["extract", "dense.log", "-o", "dense.bsf"])
r = run(["render", "dense.bsf", "-o", "dense.svg", "--points", "dense.log"])
size = os.path.getsize(os.path.join(WORK, "dense.svg"))
ids, dots, curves, vertices, robot, path_lines, root = svg_parts("dense.svg")
check(r.returncode == 0 and size < 2_000_000, "1000 scans with points render under 2 MB (%d bytes)" % size)
check(dots > 5000, "the thinned points still draw the walls (%d dots)" % dots)

# One scan with its points: every valid beam of that scan is there (a few may
# share a pixel), and the robot.
r = run(["render", "dense.bsf", "-o", "one.svg", "--scans", "5..5", "--points", "dense.log"])
ids, dots, curves, vertices, robot, path_lines, root = svg_parts("one.svg")
n_valid = 0
for line in run(["decode", "dense.bsf"], text=True).stdout.splitlines():
    if line.startswith("seq=5 "):
        n_valid = int(line.split(" N=")[1].split()[0])
check(r.returncode == 0 and n_valid > 100 and dots >= 0.9 * n_valid and robot == 1,
      "a one-scan render shows its points (%d of %d valid beams) and the robot" % (dots, n_valid))
widths = [float(e.get("stroke-width", "0")) for e in root.iter() if e.get("class") == "points"]
check(widths and min(widths) >= 3.0, "a one-scan close-up draws its points as dots >= 3 px (%s)" % widths[:1])

intel = os.path.join(SHARED, "data", "intel.log.gz") if SHARED else ""
if intel and os.path.exists(intel):
    r = run(["extract", intel, "-o", "intel.bsf"])
    r = run(["render", "intel.bsf", "-o", "intel.svg", "--points", intel])
    size = os.path.getsize(os.path.join(WORK, "intel.svg"))
    check(r.returncode == 0 and size < 5_000_000, "Intel with points renders under 5 MB (%d bytes)" % size)
else:
    print("skipped  Intel size check (no %s)" % (intel or "shared dir"))

print("%d checks failed" % len(failures) if failures else "all listen/render checks passed")
sys.exit(1 if failures else 0)
