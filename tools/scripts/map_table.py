#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The fused map's figures against their targets, in one command: runs
bench_map (host: bytes, coverage, synthetic truth, RAM, the per-scan stream
and occupancy-grid baselines on the corrected logs and the synthetic scenes)
and bench_m4_map under QEMU (Cortex-M4F instructions per scan for fusing),
then prints the targets table followed by bench_map's full table.

    map_table.py [--build build] [--build-m4 build-m4] [--qemu qemu-system-arm]

Build first:
    cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build -j2 --target bench_map
    cmake -S . -B build-m4 -DCMAKE_TOOLCHAIN_FILE=port/cortex-m4f.cmake -DCMAKE_BUILD_TYPE=Release
    cmake --build build-m4 -j2 --target bench_m4_map
Without the M4F build (or QEMU) the instruction row says so; the rest prints.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def parse_table(text):
    """bench_map's Markdown table: {row label: {column: cell}}."""
    rows, cols = {}, None
    for line in text.splitlines():
        if not line.startswith("|") or line.startswith("|---"):
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cols is None:
            cols = cells[1:]
            continue
        rows[cells[0].replace("*", "")] = dict(zip(cols, cells[1:]))
    return rows, cols or []


def row(rows, prefix):
    for label, cells in rows.items():
        if label.startswith(prefix):
            return cells
    raise KeyError(prefix)


def num(cell, index=0):
    """The index-th number in a cell ("6321 (6928)" -> 6321, 6928)."""
    found = re.findall(r"-?\d+(?:\.\d+)?", cell)
    return float(found[index]) if len(found) > index else None


def run_m4(build_m4, qemu):
    elf = os.path.join(build_m4, "test", "bench_m4_map.elf")
    if not os.path.isfile(elf):
        return None, f"not built ({elf}; see --help)"
    if shutil.which(qemu) is None:
        return None, f"{qemu} not found"
    cmd = [qemu, "-M", "mps2-an386", "-icount", "shift=10,sleep=off", "-display", "none", "-serial", "null",
           "-monitor", "none", "-semihosting-config", "enable=on,target=native", "-kernel", elf]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        return None, f"bench_m4_map failed (exit {r.returncode}): {r.stdout[-300:]}{r.stderr[-300:]}"
    m = re.search(r"bsf_map_fuse\s+instructions per scan: median (\d+), max (\d+)", r.stdout)
    if m is None:
        return None, "bench_m4_map printed no fuse line"
    return (int(m.group(1)), int(m.group(2))), r.stdout


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--build-m4", default=os.path.join(ROOT, "build-m4"))
    ap.add_argument("--qemu", default="qemu-system-arm")
    a = ap.parse_args()
    bench = os.path.join(a.build, "tools", "bench_map")
    if not os.path.isfile(bench):
        sys.exit(f"map_table.py: {bench} is not built (see --help)")
    r = subprocess.run([bench], capture_output=True, text=True, timeout=1800)
    if r.returncode != 0:
        sys.exit(f"map_table.py: bench_map failed (exit {r.returncode}):\n{r.stderr}")
    rows, cols = parse_table(r.stdout)
    if "intel" not in cols:
        sys.exit("map_table.py: bench_map has no intel column (is ../shared/data/alt there?)")
    synth = [c for c in ("office", "angles", "curved") if c in cols]
    m4, m4_text = run_m4(a.build_m4, a.qemu)

    def worst(prefix, index, pick):
        vals = [num(row(rows, prefix)[c], index) for c in synth]
        vals = [v for v in vals if v is not None]
        return pick(vals) if vals else None

    once = row(rows, "map: bytes of the final map, sent once")["intel"]
    once_all = num(once, 1) if num(once, 1) is not None else num(once)
    ram = re.search(r"\): (\d+) bytes; receiver", r.stdout)
    lines = [
        ("bytes of the final map, sent once (in brackets: with the forgotten features)", "82 778 (per-scan stream)",
         "<= 6 000", once_all, lambda v: v <= 6000, once),
        ("bytes of the whole update stream, map only", "82 778", "<= 12 000",
         num(row(rows, "map: bytes of the whole update stream")["intel"]), lambda v: v <= 12000, None),
        ("median distance from valid raw points to the map, mm", "-", "<= 15",
         num(row(rows, "map: median point distance mm")["intel"]), lambda v: v <= 15.0, None),
        ("valid raw points within 5 cm of the map, %", row(rows, "per-scan features: points within 5 cm")["intel"]
         + " (per-scan)", ">= 93", num(row(rows, "map: points within 5 cm")["intel"]), lambda v: v >= 93.0, None),
        ("synthetic: curve to true surface p99, mm (worst scene)", "-", "<= 30",
         worst("map: curve to true surface", 0, max), lambda v: v <= 30.0, None),
        ("synthetic: curve to true surface max, mm (worst scene)", "-", "<= 80",
         worst("map: curve to true surface", 1, max), lambda v: v <= 80.0, None),
        ("synthetic: curve length per metre of surface seen (worst scene)", "-", "<= 1.05",
         worst("map: curve length per metre", 0, max), lambda v: v <= 1.05, None),
        ("synthetic: corners seen in >= 5 scans that are one map vertex, % (worst scene)", "-", ">= 90",
         worst("map: corners seen in >= 5 scans", 0, min), lambda v: v >= 90.0, None),
        ("RAM of the map at its default caps, bytes", "-", "<= 65 536",
         float(ram.group(1)) if ram else None, lambda v: v <= 65536, None),
        ("M4F instructions per Intel scan for fusing, median", "-", "<= 150 000",
         float(m4[0]) if m4 else None, lambda v: v <= 150000, None if m4 else m4_text),
        ("M4F instructions per Intel scan for fusing, max", "-", "<= 600 000",
         float(m4[1]) if m4 else None, lambda v: v <= 600000, None if m4 else m4_text),
    ]
    print("| figure (corrected Intel log unless said) | today | target | now | met |")
    print("|---|---|---|---|---|")
    for what, today, target, value, ok, note in lines:
        now = note if note else ("-" if value is None else f"{value:g}")
        met = "-" if value is None else ("yes" if ok(value) else "no")
        print(f"| {what} | {today} | {target} | {now} | {met} |")
    print()
    print(r.stdout.rstrip())
    if m4:
        print()
        print("Cortex-M4F (QEMU -icount, test/bench_m4_map.c):")
        print()
        print("```")
        print(m4_text.rstrip())
        print("```")
    return 0


if __name__ == "__main__":
    sys.exit(main())
