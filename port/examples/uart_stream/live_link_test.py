#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Live link test: the uart_stream firmware under QEMU streams bsf frames
through its UART into the host tool's `bsf listen`.

--mode clean: QEMU's serial port writes into a named pipe that `bsf listen`
reads; the bytes received must equal the host encoder's bytes for the same
scans (uart_stream_expect), and every frame must be delivered.

--mode lossy: a relay between QEMU and `bsf listen -` drops and flips bytes
and injects line noise at chosen places; the frames not touched must still be
delivered, identical to the clean run, the damaged ones dropped, and the
counters must show the damage.
"""
import argparse
import os
import shutil
import subprocess
import sys
import threading

ap = argparse.ArgumentParser()
ap.add_argument("--mode", choices=["clean", "lossy"], required=True)
ap.add_argument("--qemu", required=True)
ap.add_argument("--firmware", required=True)
ap.add_argument("--bsf", required=True)
ap.add_argument("--expect", required=True)
ap.add_argument("--work", required=True)
args = ap.parse_args()

failures = []


def check(cond, what):
    print(("ok      " if cond else "FAILED  ") + what, flush=True)
    if not cond:
        failures.append(what)


shutil.rmtree(args.work, ignore_errors=True)
os.makedirs(args.work)
expected_path = os.path.join(args.work, "expected.bsf")
received_path = os.path.join(args.work, "received.bsf")
fifo = os.path.join(args.work, "uart.fifo")

subprocess.run([args.expect, expected_path], check=True)
with open(expected_path, "rb") as f:
    expected = f.read()

# Frames of the expected stream: (start offset, end offset incl. delimiter).
frames = []
start = 0
for i, b in enumerate(expected):
    if b == 0:
        if i > start:
            frames.append((start, i + 1))
        start = i + 1
n_frames = len(frames)
check(n_frames >= 50, "the host encoder wrote %d frames" % n_frames)


def frame_lines(text):
    """seq -> the scan's line without its running counters (metadata lines left out)."""
    out = {}
    for line in text.splitlines():
        if line.startswith("frame seq="):
            seq = int(line.split()[1].split("=")[1])
            out[seq] = line.split(" | ")[0]
    return out


def frame_kinds(text):
    """In stream order, one entry per delivered frame: its seq, or None for metadata."""
    kinds = []
    for line in text.splitlines():
        if line.startswith("frame seq="):
            kinds.append(int(line.split()[1].split("=")[1]))
        elif line.startswith("metadata "):
            kinds.append(None)
    return kinds


def summary(text):
    for line in text.splitlines():
        if line.startswith("counters: "):
            fields = {}
            for part in line[len("counters: "):].split(", "):
                name, _, value = part.rpartition(" ")
                fields[name] = int(value)
            return fields
    return {}


reference = subprocess.run([args.bsf, "listen", expected_path], capture_output=True, text=True)
check(reference.returncode == 0, "bsf listen on the expected file exits 0")
ref_lines = frame_lines(reference.stdout)
kinds = frame_kinds(reference.stdout)
n_scans = len(ref_lines)
check(len(kinds) == n_frames and n_scans >= 50, "bsf listen decodes every expected frame (%d scans)" % n_scans)

os.mkfifo(fifo)
qemu_cmd = [args.qemu, "-M", "mps2-an386", "-display", "none", "-monitor", "none",
            "-semihosting-config", "enable=on,target=native",
            "-serial", "file:" + fifo, "-kernel", args.firmware]

# Which input bytes the relay drops, flips or precedes with noise (lossy mode).
# (Frame indices count every frame of the stream, metadata included.)
drop, flip, noise_before = set(), set(), {}
damaged = set()
if args.mode == "lossy":
    def mid(k):
        return (frames[k][0] + frames[k][1]) // 2

    flip.add(mid(3)); damaged.add(3)                       # one corrupted byte
    drop.add(mid(10)); damaged.add(10)                     # one byte lost
    drop.add(frames[17][1] - 1); damaged.update({17, 18})  # a delimiter lost: two frames merge
    drop.update(range(frames[30][0], frames[30][0] + 20)); damaged.add(30)  # head of a frame lost
    drop.update(range(mid(40), mid(41))); damaged.update({40, 41})          # a burst over a boundary
    noise_before[frames[50][0]] = bytes([0x13, 0x37, 0x42, 0x00])  # a junk frame between two: none lost
lost = {kinds[k] for k in damaged if kinds[k] is not None}  # scans lost

if args.mode == "clean":
    listen = subprocess.Popen([args.bsf, "listen", fifo, "-o", received_path],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    qemu = subprocess.Popen(qemu_cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    relay_stats = None
else:
    listen = subprocess.Popen([args.bsf, "listen", "-", "-o", received_path],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE)
    qemu = subprocess.Popen(qemu_cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    relay_stats = {"in": 0, "out": 0}

    def relay():
        fd = os.open(fifo, os.O_RDONLY)
        pos = 0
        try:
            while True:
                chunk = os.read(fd, 4096)
                if not chunk:
                    break
                out = bytearray()
                for b in chunk:
                    if pos in noise_before:
                        out += noise_before[pos]
                    if pos in flip:
                        out.append(b ^ 0x5A if b ^ 0x5A else 0xA5)
                    elif pos not in drop:
                        out.append(b)
                    pos += 1
                relay_stats["in"] = pos
                relay_stats["out"] += len(out)
                listen.stdin.write(bytes(out))
                listen.stdin.flush()
        except Exception:
            qemu.kill()  # a broken relay must not leave QEMU blocked on the pipe
            raise
        finally:
            os.close(fd)
            listen.stdin.close()

    relay_thread = threading.Thread(target=relay)
    relay_thread.start()

try:
    qemu_out, _ = qemu.communicate(timeout=90)
    if relay_stats is not None:
        relay_thread.join(timeout=30)
        listen.stdin = None  # the relay closed it
    listen_out, listen_err = (x.decode() for x in listen.communicate(timeout=30))
except subprocess.TimeoutExpired:
    qemu.kill()
    listen.kill()
    print("timed out", file=sys.stderr)
    sys.exit(1)

sys.stdout.write(listen_out)
sys.stderr.write(listen_err)
check(qemu.returncode == 0, "the firmware exits 0 under QEMU (%s; %s)"
      % (qemu.returncode, qemu_out.decode(errors="replace").strip()))
check(listen.returncode == 0, "bsf listen exits 0 at the end of the stream")
with open(received_path, "rb") as f:
    received = f.read()
got = frame_lines(listen_out)
counters = summary(listen_out)
print("counters:", counters)

if args.mode == "clean":
    check(received == expected,
          "bytes received from the UART equal the host encoder's (%d vs %d bytes)"
          % (len(received), len(expected)))
    check(got == ref_lines, "every frame delivered, decoded as from the expected file")
    check(counters.get("frames ok") == n_frames, "counters: %d frames ok" % n_frames)
    check(kinds == frame_kinds(listen_out), "the frames arrive in the order sent")
    dropped = sum(counters.get(k, -1) for k in ("bad crc", "malformed", "unsupported version",
                                                 "oversize"))
    check(dropped == 0 and counters.get("missing by sequence") == 0,
          "counters: nothing dropped, nothing missing")
else:
    print("relay: %d bytes in, %d bytes out" % (relay_stats["in"], relay_stats["out"]))
    check(relay_stats["in"] == len(expected), "the relay saw the whole stream from QEMU")
    want = {s: l for s, l in ref_lines.items() if s not in lost}
    check(set(got) == set(want),
          "exactly the undamaged scans delivered (%d of %d; lost %s)"
          % (len(got), n_scans, sorted(set(ref_lines) - set(got))))
    check(all(got.get(s) == l for s, l in want.items()),
          "each delivered scan decodes exactly as on the clean link")
    check(counters.get("frames ok") == n_frames - len(damaged), "counters: frames ok")
    dropped = sum(counters.get(k, 0) for k in ("bad crc", "malformed", "unsupported version",
                                                "oversize"))
    # 5 damaged places plus the junk frame: each is at least one dropped frame
    check(dropped >= 6, "counters: %d damaged frames dropped (>= 6)" % dropped)
    check(counters.get("missing by sequence") == len(lost),
          "counters: %d frames missing by sequence" % len(lost))
    check(counters.get("bytes skipped", 0) > 0, "counters: skipped bytes counted")

if failures:
    print("%d check(s) failed" % len(failures), file=sys.stderr)
    sys.exit(1)
print("all checks passed")
