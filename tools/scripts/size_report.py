#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""What a firmware links from libbsf: read a GNU ld link map (-Wl,-Map) and
sum, per archive member, the bytes of the .text and .rodata input sections
that survived --gc-sections. Library members are listed one by one; C
library, libm and libgcc members the firmware pulls in (partly on the
library's behalf: memset, sqrtf, ...) are summed per archive; the firmware's
own objects in one line.

  python3 tools/scripts/size_report.py build-m4-size/port/examples/extract_encode/extract_encode.elf.map
  python3 tools/scripts/size_report.py --budget 24576 MAP     # exit 1 when libbsf's bytes exceed it
"""
import argparse
import collections
import os
import re
import sys

# An input section line: " .text.name  0xADDR  0xSIZE  file" (name may sit
# alone on the previous line when long).
SECTION = re.compile(r"^ (\.(?:text|rodata)[^\s]*)?\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S.*)$")
MEMBER = re.compile(r"^(.*/)?([^/()]+\.a)\(([^()]+)\)$")


def parse(path):
    """{(archive, member): bytes} of .text*/.rodata* kept in the image."""
    sizes = collections.Counter()
    pending = None
    in_map = False
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            line = line.rstrip("\n")
            if line.startswith("Linker script and memory map"):
                in_map = True
                continue
            if not in_map:
                continue
            if line.startswith("/DISCARD/"):
                break
            m = SECTION.match(line)
            if m:
                name = m.group(1) or pending
                pending = None
                if name is None or int(m.group(2), 16) == 0 and int(m.group(3), 16) == 0:
                    continue
                size = int(m.group(3), 16)
                if size == 0:
                    continue
                where = m.group(4).strip()
                mm = MEMBER.match(where)
                key = (mm.group(2), mm.group(3)) if mm else ("", os.path.basename(where))
                sizes[key] += size
                continue
            s = line.strip()
            if re.match(r"^\.(text|rodata)\S*$", s) and line.startswith(" ."):
                pending = s
            else:
                pending = None
    return sizes


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("map", help="link map of the firmware (.map)")
    ap.add_argument("--library", default="libbsf.a", help="archive whose members are listed (default libbsf.a)")
    ap.add_argument("--budget", type=int, default=0, help="bytes allowed for the library; exit 1 when over")
    ap.add_argument("--quiet", action="store_true", help="print only the library total line")
    args = ap.parse_args()
    if not os.path.isfile(args.map):
        sys.exit(f"size_report: {args.map}: no such link map")
    sizes = parse(args.map)
    if not sizes:
        sys.exit(f"size_report: {args.map}: no .text/.rodata input sections found (not a GNU ld map?)")
    lib = {m: b for (a, m), b in sizes.items() if a == args.library}
    others = collections.Counter()
    for (a, m), b in sizes.items():
        if a != args.library:
            others[a or "(firmware objects)"] += b
    lib_total = sum(lib.values())
    if not args.quiet:
        print(f"{args.map}: .text + .rodata linked")
        for m, b in sorted(lib.items(), key=lambda kv: -kv[1]):
            print(f"  {args.library}({m}){'':<4} {b:7d}")
    line = f"{args.library}: {lib_total} bytes (.text + .rodata) linked into {os.path.basename(args.map)}"
    if args.budget:
        line += f" (budget {args.budget}: {'within' if lib_total <= args.budget else 'OVER'})"
    print(line)
    if not args.quiet:
        for a, b in sorted(others.items(), key=lambda kv: -kv[1]):
            print(f"  {a:<30} {b:7d}")
        print(f"whole image: {sum(sizes.values())} bytes .text + .rodata")
    if not lib:
        sys.exit(f"size_report: nothing from {args.library} in {args.map}")
    return 1 if args.budget and lib_total > args.budget else 0


if __name__ == "__main__":
    sys.exit(main())
