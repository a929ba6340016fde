#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""RAM cost of bsf's caller-owned objects for several beam caps.

    mem_report.py [--cc CC --nm NM [--cflags FLAGS]] ... [--points 180,361,1081]
                  [--define BSF_MAX_SEGMENTS=256 ...]

Compiles tools/scripts/mem_probe.c (the public headers only) once per
BSF_MAX_POINTS value with each given compiler and reads the sizes from the
object's symbol table (nm -S), so cross compilers work without running
anything. Default compilers: the host's cc, and arm-none-eabi-gcc for the
Cortex-M4F when it is on PATH. Prints a table in bytes and KiB.
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
PROBE = os.path.join(HERE, "mem_probe.c")
PREFIX = "bsf_sizeof_"
M4F_FLAGS = "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16"


def sizes(cc, nm, cflags, points, workdir, defines=()):
    obj = os.path.join(workdir, "probe_%d.o" % points)
    cmd = [cc] + cflags.split() + ["-std=c99", "-c", "-I", os.path.join(ROOT, "include"),
                                   "-DBSF_MAX_POINTS=%d" % points] + ["-D" + d for d in defines] + [PROBE, "-o", obj]
    subprocess.run(cmd, check=True)
    out = subprocess.run([nm, "-S", "-p", obj], check=True, capture_output=True, text=True).stdout
    result = {}
    for line in out.splitlines():
        f = line.split()
        if len(f) == 4 and f[3].startswith(PREFIX):
            result[f[3][len(PREFIX):]] = int(f[1], 16)
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cc", action="append", default=[])
    ap.add_argument("--nm", action="append", default=[])
    ap.add_argument("--cflags", action="append", default=[])
    ap.add_argument("--points", default="180,361,1081")
    ap.add_argument("--define", action="append", default=[],
                    help="another cap for every size, e.g. BSF_MAX_SEGMENTS=256 (repeatable)")
    a = ap.parse_args()
    targets = []
    if a.cc:
        if len(a.nm) != len(a.cc):
            sys.exit("mem_report.py: give one --nm per --cc")
        flags = a.cflags + [""] * (len(a.cc) - len(a.cflags))
        targets = [(os.path.basename(c), c, n, f) for c, n, f in zip(a.cc, a.nm, flags)]
    else:
        targets.append(("host", os.environ.get("CC", "cc"), "nm", ""))
        if shutil.which("arm-none-eabi-gcc"):
            targets.append(("cortex-m4f", "arm-none-eabi-gcc", "arm-none-eabi-nm", M4F_FLAGS))
    points = [int(p) for p in a.points.split(",")]
    with tempfile.TemporaryDirectory() as work:
        for label, cc, nm, cflags in targets:
            table = {p: sizes(cc, nm, cflags, p, work, a.define) for p in points}
            names = list(table[points[0]].keys())
            print("sizeof, bytes (%s, %s): BSF_MAX_POINTS = %s; %s"
                  % (label, cc, ", ".join(str(p) for p in points),
                     ", ".join(a.define) if a.define else "other caps default"))
            for n in names:
                cells = "".join("%9d (%5.1f KiB)" % (table[p][n], table[p][n] / 1024.0) for p in points)
                print("  %-20s%s" % (n, cells))
    return 0


if __name__ == "__main__":
    sys.exit(main())
