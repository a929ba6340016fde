#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""CTest driver: tools/scripts/quality_gate.py on small saved tables.

Equal runs and better runs pass (exit 0); one figure worse in any gated
column fails (exit 1) and is named; a missing row, a non-number or a file
without a table is unreadable input (exit 2), never a pass.

Usage: test_quality_gate.py SCRIPT WORK_DIR
"""
import os
import shutil
import subprocess
import sys

SCRIPT, WORK = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
failures = []

TRUTH_HEAD = (
    "bench_truth: default configuration, 40 poses per row\n"
    "| scene | sensor | noise | visible | recall | precision | verr med/p90/max cm "
    "| curve rms/p99/max cm | eta |\n"
    "|---|---|---|---:|---:|---:|---|---|---:|\n"
)
TRUTH_ROWS = [
    ["office", "361/0.75/270", "1cm", "51", "100.0%", "96.5%", "0.48 / 0.88 / 1.97",
     "1.06 / 4.03 / 25.08", "0.066"],
    ["angles", "3200/0.1125/360", "1cm", "216", "93.5%", "100.0%", "0.26 / 0.64 / 1.32",
     "0.43 / 1.31 / 12.31", "0.023"],
]
TABLE1_HEAD = (
    "| Data set | Method | Γ % (paper) | η (paper) | accuracy m (paper) | scans |\n"
    "|---|---|---|---|---|---|\n"
)
TABLE1_ROWS = [
    ["Intel", "falko-sved-pdm", "87.2 (86.4)", "0.159 (0.192)", "0.0140 (0.0158)", "2672"],
    ["Intel", "lc-sved-pdm", "87.2 (86.4)", "0.161 (0.192)", "0.0130 (0.0158)", "2672"],
    ["Fr-079", "lc-sved-pdm", "92.1 (91.9)", "0.164 (0.169)", "0.0167 (0.0214)", "1464"],
]


def check(cond, what):
    print(("ok      " if cond else "FAILED  ") + what)
    if not cond:
        failures.append(what)


def write(name, head, rows):
    path = os.path.join(WORK, name)
    with open(path, "w", encoding="utf-8") as f:
        f.write(head)
        for r in rows:
            f.write("| " + " | ".join(r) + " |\n")
    return path


def gate(kind, before, after):
    p = subprocess.run([sys.executable, SCRIPT, kind, before, after], capture_output=True,
                       text=True, timeout=60)
    return p.returncode, p.stdout + p.stderr


def changed(rows, i, col, value):
    out = [list(r) for r in rows]
    out[i][col] = value
    return out


shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)

# bench_truth tables.
base = write("truth_base.md", TRUTH_HEAD, TRUTH_ROWS)
rc, out = gate("truth", base, base)
check(rc == 0 and "0 figures worse" in out, f"truth: a run against itself passes ({rc})")
better = write("truth_better.md", TRUTH_HEAD,
               changed(changed(TRUTH_ROWS, 0, 6, "0.40 / 0.80 / 1.50"), 1, 4, "95.0%"))
rc, out = gate("truth", base, better)
check(rc == 0, f"truth: lower vertex error and higher recall pass ({rc})")
for col, value, name in ((4, "99.9%", "recall"), (5, "96.4%", "precision"),
                         (6, "0.48 / 0.89 / 1.97", "vertex error p90"),
                         (6, "0.48 / 0.88 / 1.98", "vertex error max"),
                         (7, "0.90 / 4.04 / 25.08", "curve p99"),
                         (7, "1.06 / 4.03 / 25.09", "curve max"), (8, "0.067", "eta")):
    worse = write("truth_worse.md", TRUTH_HEAD, changed(TRUTH_ROWS, 0, col, value))
    rc, out = gate("truth", base, worse)
    check(rc == 1 and name in out and "office 361/0.75/270 1cm" in out,
          f"truth: a worse {name} fails and is named ({rc})")
# curve RMS is not gated (a fit may trade it for the tail).
rms = write("truth_rms.md", TRUTH_HEAD, changed(TRUTH_ROWS, 0, 7, "1.20 / 4.03 / 25.08"))
check(gate("truth", base, rms)[0] == 0, "truth: curve RMS alone is not a gate")
short = write("truth_short.md", TRUTH_HEAD, TRUTH_ROWS[:1])
rc, out = gate("truth", base, short)
check(rc == 2 and "angles" in out, f"truth: a missing row is bad input ({rc})")
bad = write("truth_bad.md", TRUTH_HEAD, changed(TRUTH_ROWS, 1, 4, "n/a"))
check(gate("truth", base, bad)[0] == 2, "truth: a non-number is bad input")
empty = write("empty.md", "no table here\n", [])
check(gate("truth", base, empty)[0] == 2, "truth: a file without a table is bad input")
check(gate("truth", base, os.path.join(WORK, "absent.md"))[0] == 2,
      "truth: a missing file is bad input")

# bsf table1 tables: the default method's rows only.
t1 = write("t1_base.md", TABLE1_HEAD, TABLE1_ROWS)
rc, out = gate("table1", t1, t1)
check(rc == 0 and "2 rows" in out, f"table1: a run against itself passes, 2 default rows ({rc})")
falko_worse = write("t1_falko.md", TABLE1_HEAD, changed(TABLE1_ROWS, 0, 3, "0.170 (0.192)"))
check(gate("table1", t1, falko_worse)[0] == 0, "table1: other methods' rows are not gated")
eta_up = write("t1_eta.md", TABLE1_HEAD, changed(TABLE1_ROWS, 2, 3, "0.165 (0.169)"))
rc, out = gate("table1", t1, eta_up)
check(rc == 1 and "Fr-079" in out and "eta" in out, f"table1: a higher eta fails ({rc})")
acc_paper = write("t1_acc.md", TABLE1_HEAD, changed(TABLE1_ROWS, 1, 4, "0.0160 (0.0158)"))
rc, out = gate("table1", t1, acc_paper)
check(rc == 1 and "paper" in out, f"table1: accuracy above the paper's fails ({rc})")
gamma_paper = write("t1_gamma.md", TABLE1_HEAD, changed(TABLE1_ROWS, 1, 2, "86.0 (86.4)"))
check(gate("table1", t1, gamma_paper)[0] == 1, "table1: Gamma below the paper's fails")
no_paper = write("t1_nopaper.md", TABLE1_HEAD, changed(TABLE1_ROWS, 1, 3, "0.161"))
check(gate("table1", t1, no_paper)[0] == 2, "table1: a figure without the paper's is bad input")

if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
print("all checks passed")
