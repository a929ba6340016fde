#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""CTest driver: `bsf extract` reads a gzip bomb in bounded memory.

A small .log.gz that inflates to hundreds of MiB of one endless line (zeros,
'a', or 'ROBOTLASER1 ' followed by control bytes) must cost the reader no
more than its line cap: the tool reports the line as FILE:LINE the moment it
passes 1 MiB, drops the rest a block at a time and exits non-zero. Each run's
peak resident memory is read from wait4() and must stay under
RSS_LIMIT_KB, for a file argument and for standard input. Good scans around
an overlong line are still extracted and later line numbers stay right.

Usage: test_log_bomb.py BSF_EXE WORK_DIR
"""
import gzip
import os
import shutil
import subprocess
import sys
import zlib

BSF, WORK = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
# Peak RSS allowed per run, KiB: the reader's cap is about 1.1 MiB; the
# rest is the tool and, in sanitizer builds, the sanitizer's own overhead.
RSS_LIMIT_KB = 64 * 1024
# Inflated size of each bomb: far beyond the limit, so an unbounded buffer fails.
BOMB_BYTES = 256 << 20
failures = []


def check(cond, what):
    print(("ok      " if cond else "FAILED  ") + what)
    if not cond:
        failures.append(what)


def write_bomb(name, head, fill):
    """A gzip file of `head` then `fill` repeated to BOMB_BYTES, no newline."""
    chunk = (fill * ((1 << 20) // len(fill) + 1))[: 1 << 20]
    z = zlib.compressobj(9, zlib.DEFLATED, 16 + zlib.MAX_WBITS)
    with open(os.path.join(WORK, name), "wb") as f:
        f.write(z.compress(head))
        for _ in range(BOMB_BYTES // len(chunk)):
            f.write(z.compress(chunk))
        f.write(z.flush())
    return os.path.getsize(os.path.join(WORK, name))


def run(args, stdin_path=None):
    """Runs the tool; returns (exit code, the first 64 KiB of its stderr, peak
    RSS in KiB of that child alone). The child's peak includes the moments
    between fork and exec, when it is a copy of this script: the script
    stays small (stderr goes to a file, never into memory whole)."""
    stdin = open(os.path.join(WORK, stdin_path), "rb") if stdin_path else subprocess.DEVNULL
    err_path = os.path.join(WORK, "stderr.txt")
    try:
        with open(err_path, "wb") as err_file:
            p = subprocess.Popen(args, cwd=WORK, stdin=stdin, stdout=subprocess.DEVNULL, stderr=err_file)
            _, status, usage = os.wait4(p.pid, 0)
            p.returncode = os.waitstatus_to_exitcode(status)
    finally:
        if stdin_path:
            stdin.close()
    with open(err_path, "rb") as f:
        err = f.read(65536).decode("utf-8", "replace")
    return p.returncode, err, usage.ru_maxrss


shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)

bombs = [
    ("zeros.log.gz", b"", b"\0"),
    ("letters.log.gz", b"", b"a"),
    ("robotlaser.log.gz", b"ROBOTLASER1 ", bytes(c for c in range(1, 32) if c != 0x0A)),
]
for name, head, fill in bombs:
    size = write_bomb(name, head, fill)
    for how in ("file", "stdin"):
        if how == "file":
            rc, err, rss = run([BSF, "extract", name, "-o", os.devnull])
            shown = name
        else:
            rc, err, rss = run([BSF, "extract", "-", "-o", os.devnull], stdin_path=name)
            shown = "-"
        check(rc == 1, "%s (%d bytes, %d MiB inflated) via %s: exit 1 (got %d)" % (name, size, BOMB_BYTES >> 20, how, rc))
        check(("%s:1: line longer than 1048576 bytes" % shown) in err,
              "%s via %s: reported as %s:1 (%r)" % (name, how, shown, err.strip()[:200]))
        check(rss < RSS_LIMIT_KB, "%s via %s: peak RSS %d KiB < %d KiB" % (name, how, rss, RSS_LIMIT_KB))

# Good scans before and after an overlong line: both extracted, the long
# line reported as line 2, the next bad line as line 4, and a non-zero exit.
flaser = "FLASER 180 " + " ".join(["2.50"] * 180) + " 0 0 0 0 0 0 %.1f nohost %.1f\n"
z = zlib.compressobj(9, zlib.DEFLATED, 16 + zlib.MAX_WBITS)
with open(os.path.join(WORK, "mixed.log.gz"), "wb") as f:
    f.write(z.compress((flaser % (1.0, 1.0)).encode()))
    f.write(z.compress(b"FLASER 180 "))
    for _ in range(64):
        f.write(z.compress(b"1.0 " * (1 << 18)))
    f.write(z.compress(b"\n" + (flaser % (2.0, 2.0)).encode() + b"FLASER x\n"))
    f.write(z.flush())
rc, err, rss = run([BSF, "extract", "mixed.log.gz", "-o", os.devnull])
check(rc == 1 and "2 scans extracted" in err and "2 malformed lines" in err,
      "mixed.log.gz: 2 scans extracted, 2 malformed lines, exit 1 (%d, %r)" % (rc, err.strip()))
check("mixed.log.gz:2: line longer than 1048576 bytes" in err and "mixed.log.gz:4: FLASER" in err,
      "mixed.log.gz: the long line is line 2, the bad one line 4")
check("1 lines longer than 1048576 bytes" in err, "mixed.log.gz: the summary names the overlong line")
check(rss < RSS_LIMIT_KB, "mixed.log.gz: peak RSS %d KiB < %d KiB" % (rss, RSS_LIMIT_KB))

# A line of exactly the cap is read (and is a malformed FLASER, not an overlong line).
with open(os.path.join(WORK, "at_cap.log.gz"), "wb") as f:
    line = b"FLASER 1 " + b"1" * (1048576 - 9)
    f.write(gzip.compress(line + b"\n" + (flaser % (3.0, 3.0)).encode(), mtime=0))
rc, err, rss = run([BSF, "extract", "at_cap.log.gz", "-o", os.devnull])
check(rc == 0 and "at_cap.log.gz:1: FLASER" in err and "longer than" not in err and "1 scans extracted" in err,
      "a line of exactly 1048576 bytes is parsed, not dropped (%d, %r)" % (rc, err.strip()[:300]))

if failures:
    print("%d check(s) failed" % len(failures))
    sys.exit(1)
print("all checks passed")
