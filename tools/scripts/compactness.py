#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Bytes per scan: bsf frames against the raw scan and its per-scan compression.

For each CARMEN log (ROBOTLASER1 or FLASER lines) this prints, per scan:
  - the bsf frame as written by `bsf extract` (COBS, CRC and delimiter included),
  - the raw scan as uint16 little-endian millimetres (2 bytes per beam),
  - that raw scan compressed on its own with LZMA2 (xz preset 9e, raw stream
    without the .xz container) and with raw deflate (zlib level 9, no header),
as median and 95th percentile, in the Markdown table of docs/FORMAT.md.

Usage:
  tools/scripts/compactness.py --bsf build/tools/bsf --data ../shared/data
  tools/scripts/compactness.py --bsf build/tools/bsf --data DIR --quant 0.001 0.002 0.005 0.01 --only intel
"""
import argparse
import gzip
import lzma
import os
import statistics
import struct
import subprocess
import sys
import zlib

# name, file, scans used (None: all); Fr-Clinic: the first 1000, as in the paper.
DATASETS = [
    ("intel", "intel.log.gz", None),
    ("mit-csail", "mit-csail.log.gz", None),
    ("fr079", "fr079.log.gz", None),
    ("fr-clinic", "fr-clinic.log.gz", 1000),
]


def read_ranges(path, count):
    """Range lists (metres) of the laser lines of a CARMEN log, in order."""
    opener = gzip.open if path.endswith(".gz") else open
    scans = []
    with opener(path, "rt", errors="replace") as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            try:
                if parts[0] == "ROBOTLASER1":
                    n = int(parts[8])
                    ranges = [float(v) for v in parts[9:9 + n]]
                elif parts[0] == "FLASER":
                    n = int(parts[1])
                    ranges = [float(v) for v in parts[2:2 + n]]
                else:
                    continue
            except (ValueError, IndexError):
                continue
            scans.append(ranges)
            if count is not None and len(scans) >= count:
                break
    return scans


def raw_bytes(ranges):
    """The scan as uint16 millimetres, little-endian (65535 for anything longer)."""
    mm = [min(max(int(round(r * 1000.0)), 0), 65535) for r in ranges]
    return struct.pack("<%dH" % len(mm), *mm)


def xz_size(data):
    # A small dictionary gives the same output for one scan, without allocating 64 MiB a call.
    filters = [{"id": lzma.FILTER_LZMA2, "preset": 9 | lzma.PRESET_EXTREME, "dict_size": 1 << 16}]
    return len(lzma.compress(data, format=lzma.FORMAT_RAW, filters=filters))


def deflate_size(data):
    c = zlib.compressobj(9, zlib.DEFLATED, -15)
    return len(c.compress(data) + c.flush())


def bsf_frame_sizes(bsf, log, count, quant, metadata=None):
    """Sizes of the scan frames `bsf extract` writes (each up to and including
    its 0x00). Metadata frames (payload byte 0 of type 2, the byte after the
    first COBS code) are left out; their sizes go to the list `metadata`."""
    cmd = [bsf, "extract", log, "-o", "-"]
    if count is not None:
        cmd += ["--count", str(count)]
    if quant is not None:
        cmd += ["--quant", str(quant)]
    out = subprocess.run(cmd, check=True, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL).stdout
    sizes = []
    for f in out.split(b"\x00"):
        if not f:
            continue
        if len(f) > 1 and f[1] & 0x0F == 2:
            if metadata is not None:
                metadata.append(len(f) + 1)
            continue
        sizes.append(len(f) + 1)
    return sizes


def p95(values):
    s = sorted(values)
    return s[min(len(s) - 1, int(0.95 * len(s)))]


def med(values):
    return statistics.median(values)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bsf", required=True, help="path of the bsf host tool")
    ap.add_argument("--data", required=True, help="directory holding the four logs")
    ap.add_argument("--only", nargs="*", help="dataset names to measure (default: all four)")
    ap.add_argument("--quant", nargs="*", type=float,
                    help="also measure bsf frames at these steps (metres)")
    args = ap.parse_args()

    print("| dataset | scans | bsf frame median / p95 | metadata per scan | raw "
          "| xz per scan median / p95 | deflate per scan median / p95 |")
    print("|---|---|---|---|---|---|---|")
    for name, fname, count in DATASETS:
        if args.only and name not in args.only:
            continue
        log = os.path.join(args.data, fname)
        if not os.path.exists(log):
            print("SKIPPED: %s not found" % log, file=sys.stderr)
            continue
        raws = [raw_bytes(r) for r in read_ranges(log, count)]
        meta = []
        frames = bsf_frame_sizes(args.bsf, log, count, None, meta)
        if len(frames) != len(raws):
            print("note: %s: %d frames for %d scans" % (name, len(frames), len(raws)),
                  file=sys.stderr)
        raw_len = [len(r) for r in raws]
        xz = [xz_size(r) for r in raws]
        dfl = [deflate_size(r) for r in raws]
        print("| %s | %d | **%g** / %d | %.2f | %g | %g / %d | %g / %d |" %
              (name, len(frames), med(frames), p95(frames), sum(meta) / max(1, len(frames)),
               med(raw_len), med(xz), p95(xz), med(dfl), p95(dfl)))
        for q in args.quant or []:
            sizes = bsf_frame_sizes(args.bsf, log, count, q)
            print("|   %s at step %g mm | %d | %g / %d | | | | |" %
                  (name, q * 1000.0, len(sizes), med(sizes), p95(sizes)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
