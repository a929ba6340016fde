#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Quality gates of a speed change: a run before it against a run after it.

A change that makes extraction faster must not make it worse anywhere. This
compares two saved outputs of the same benchmark, row by row, and exits 1
when any gated figure of any row got worse (exactly: no tolerance, as the
gates are stated):

  truth:  `bench_truth` Markdown tables (e.g. `bench_truth --poses 40 --noise 10`):
          recall and precision no lower; vertex error median / p90 / max and
          curve p99 / max no higher; eta no higher.
  table1: `bsf table1 DATA_DIR` Markdown tables: for every row of the
          default method (lc-sved-pdm) in the run after, Gamma no lower,
          eta and accuracy no higher than the paper's figures in parentheses,
          and eta no higher than in the run before.

Rows are matched by their leading key columns (scene, sensor, noise; data set
and method); a row missing from either run is an error. Every worse figure is
printed with both values. Exit status: 0 all gates hold, 1 some figure is
worse, 2 unreadable input.

Usage:
  tools/scripts/quality_gate.py truth BEFORE.md AFTER.md
  tools/scripts/quality_gate.py table1 BEFORE.md AFTER.md
"""
import argparse
import re
import sys

DEFAULT_METHOD = "lc-sved-pdm"


class InputError(Exception):
    pass


def read_table(path):
    """(header cells, rows of cells) of the first Markdown table in `path`."""
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{path}: {e}") from e
    header = None
    rows = []
    for line in lines:
        s = line.strip()
        if not s.startswith("|"):
            if header is not None and rows:
                break  # the table ended
            continue
        cells = [c.strip() for c in s.strip("|").split("|")]
        if header is None:
            header = cells
        elif all(re.fullmatch(r":?-+:?", c) for c in cells if c):
            continue
        else:
            if len(cells) != len(header):
                raise InputError(f"{path}: a row has {len(cells)} cells, the header {len(header)}")
            rows.append(cells)
    if header is None or not rows:
        raise InputError(f"{path}: no Markdown table")
    return header, rows


def column(header, path, *prefixes):
    """Index of the first header cell that starts with one of `prefixes`."""
    for i, h in enumerate(header):
        if any(h.lower().startswith(p) for p in prefixes):
            return i
    raise InputError(f"{path}: no column {prefixes[0]!r}")


def number(cell, path):
    """A figure as float; '93.9%' and '0.0140 (0.0158)' read their first number."""
    m = re.match(r"\s*(-?[0-9]+(?:\.[0-9]+)?)", cell)
    if not m:
        raise InputError(f"{path}: {cell!r} is not a number")
    return float(m.group(1))


def triple(cell, path):
    parts = cell.split("/")
    if len(parts) != 3:
        raise InputError(f"{path}: {cell!r} is not 'a / b / c'")
    return [number(p, path) for p in parts]


def truth_rows(path):
    header, rows = read_table(path)
    c_recall = column(header, path, "recall")
    c_prec = column(header, path, "precision")
    c_verr = column(header, path, "verr")
    c_curve = column(header, path, "curve")
    c_eta = column(header, path, "eta", "η")
    out = {}
    for r in rows:
        key = " ".join(r[:3])
        if key in out:
            raise InputError(f"{path}: row {key!r} twice")
        verr = triple(r[c_verr], path)
        curve = triple(r[c_curve], path)
        out[key] = [
            ("recall %", number(r[c_recall], path), +1),
            ("precision %", number(r[c_prec], path), +1),
            ("vertex error median cm", verr[0], -1),
            ("vertex error p90 cm", verr[1], -1),
            ("vertex error max cm", verr[2], -1),
            ("curve p99 cm", curve[1], -1),
            ("curve max cm", curve[2], -1),
            ("eta", number(r[c_eta], path), -1),
        ]
    return out


def paper(cell, path):
    m = re.search(r"\(\s*(-?[0-9]+(?:\.[0-9]+)?)\s*\)", cell)
    if not m:
        raise InputError(f"{path}: {cell!r} carries no paper figure in parentheses")
    return float(m.group(1))


def table1_rows(path):
    header, rows = read_table(path)
    c_gamma = column(header, path, "γ", "gamma")
    c_eta = column(header, path, "η", "eta")
    c_acc = column(header, path, "accuracy")
    out = {}
    for r in rows:
        if r[1] != DEFAULT_METHOD:
            continue
        key = " ".join(r[:2])
        out[key] = {
            "gamma": (number(r[c_gamma], path), paper(r[c_gamma], path)),
            "eta": (number(r[c_eta], path), paper(r[c_eta], path)),
            "accuracy": (number(r[c_acc], path), paper(r[c_acc], path)),
        }
    if not out:
        raise InputError(f"{path}: no {DEFAULT_METHOD} row")
    return out


def same_keys(before, after, b_path, a_path):
    missing = sorted(set(before) ^ set(after))
    if missing:
        raise InputError(f"rows not in both {b_path} and {a_path}: {', '.join(missing)}")


def gate_truth(b_path, a_path):
    before, after = truth_rows(b_path), truth_rows(a_path)
    same_keys(before, after, b_path, a_path)
    worse = []
    for key in before:
        for (name, x, sense), (_, y, _) in zip(before[key], after[key]):
            if (y - x) * sense < 0:
                worse.append(f"{key}: {name} {x:g} -> {y:g}")
    return worse, len(before)


def gate_table1(b_path, a_path):
    before, after = table1_rows(b_path), table1_rows(a_path)
    same_keys(before, after, b_path, a_path)
    worse = []
    for key, a in after.items():
        gamma, gamma_paper = a["gamma"]
        if gamma < gamma_paper:
            worse.append(f"{key}: Gamma {gamma:g} below the paper's {gamma_paper:g}")
        for name in ("eta", "accuracy"):
            value, value_paper = a[name]
            if value > value_paper:
                worse.append(f"{key}: {name} {value:g} above the paper's {value_paper:g}")
        eta_before = before[key]["eta"][0]
        if a["eta"][0] > eta_before:
            worse.append(f"{key}: eta {eta_before:g} -> {a['eta'][0]:g}")
    return worse, len(after)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("kind", choices=("truth", "table1"), help="which benchmark's output")
    ap.add_argument("before", help="saved output of the run before the change")
    ap.add_argument("after", help="saved output of the run after it")
    args = ap.parse_args(argv)
    try:
        if args.kind == "truth":
            worse, n = gate_truth(args.before, args.after)
        else:
            worse, n = gate_table1(args.before, args.after)
    except InputError as e:
        print(f"quality_gate: {e}", file=sys.stderr)
        return 2
    for w in worse:
        print("worse   " + w)
    print(f"quality_gate {args.kind}: {n} rows, {len(worse)} figures worse")
    return 1 if worse else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
