#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Worst-case stack of a library entry point from GCC's call graphs.

    stack_report.py [--root FUNC ...] [--limit BYTES] DIR

Reads every *.ci file under DIR (written by GCC >= 12 with
-fcallgraph-info=su, e.g. a build configured with -DBSF_STACK_USAGE=ON) and,
for each root (default bsf_extract), finds the call chain whose frames sum to
the most bytes. The library has no recursion, so the call graph is acyclic;
a cycle is reported as an error. Frames GCC marks "dynamic" are flagged.

Not counted (printed as a list): functions without a frame size in the graph,
i.e. libc/libm (memset, sqrtf, ...) and indirect calls (the clock hook); their
stack comes on top of the printed total.
"""
import argparse
import os
import re
import sys

NODE_RE = re.compile(r'^node: \{ title: "([^"]*)" label: "([^"]*)"')
EDGE_RE = re.compile(r'^edge: \{ sourcename: "([^"]*)" targetname: "([^"]*)"')
SIZE_RE = re.compile(r'\\n(\d+) bytes \(([a-z,]+)\)')


def load(directory):
    size, qual, name, edges = {}, {}, {}, {}
    n_files = 0
    for top, _dirs, files in os.walk(directory):
        for fn in files:
            if not fn.endswith(".ci"):
                continue
            n_files += 1
            with open(os.path.join(top, fn), encoding="utf-8", errors="replace") as f:
                for line in f:
                    m = NODE_RE.match(line)
                    if m:
                        title, label = m.group(1), m.group(2)
                        s = SIZE_RE.search(label)
                        name.setdefault(title, label.split("\\n")[0])
                        if s:
                            size[title] = int(s.group(1))
                            qual[title] = s.group(2)
                            name[title] = label.split("\\n")[0]
                        continue
                    m = EDGE_RE.match(line)
                    if m:
                        edges.setdefault(m.group(1), set()).add(m.group(2))
    return n_files, size, qual, name, edges


def worst_chain(root, size, edges):
    """Longest path (by frame bytes) from root; returns (bytes, chain, unknown callees)."""
    best = {}
    unknown = set()
    state = {}

    # Iterative DFS (post-order) so deep graphs never hit Python's recursion limit.
    stack = [(root, False)]
    while stack:
        node, done = stack.pop()
        if done:
            total, chain = 0, []
            for callee in edges.get(node, ()):
                if callee not in size:
                    unknown.add(callee)
                    continue
                if best[callee][0] > total:
                    total, chain = best[callee]
            best[node] = (size.get(node, 0) + total, [node] + chain)
            state[node] = 2
            continue
        if state.get(node) == 2:
            continue
        if state.get(node) == 1:
            raise SystemExit("stack_report.py: recursion through %s" % node)
        state[node] = 1
        stack.append((node, True))
        for callee in edges.get(node, ()):
            if callee in size:
                if state.get(callee) == 1:
                    raise SystemExit("stack_report.py: recursion: %s -> %s" % (node, callee))
                if state.get(callee) != 2:
                    stack.append((callee, False))
    return best[root][0], best[root][1], unknown


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", action="append", help="entry function (repeatable)")
    ap.add_argument("--limit", type=int, default=2048, help="budget in bytes, printed for reference")
    ap.add_argument("dir")
    a = ap.parse_args()
    n_files, size, qual, name, edges = load(a.dir)
    if n_files == 0:
        sys.exit("stack_report.py: no .ci files under %s (configure with -DBSF_STACK_USAGE=ON, GCC >= 12)"
                 % a.dir)
    rc = 0
    for root in a.root or ["bsf_extract"]:
        if root not in size:
            # Functions that take caps-sized objects carry the caps in their
            # symbol (include/bsf/bsf_abi.h): bsf_extract_capsP1081K64...
            caps = [t for t in size if re.match(re.escape(root) + r"_capsP\d+K\d+S\d+F\d+C\d+$", t)]
            if len(caps) == 1:
                root = caps[0]
        if root not in size:
            print("stack_report.py: %s not found in the call graphs" % root)
            rc = 1
            continue
        total, chain, unknown = worst_chain(root, size, edges)
        print("worst-case stack of %s: %d bytes (budget %d: %s)"
              % (root, total, a.limit, "within" if total <= a.limit else "OVER"))
        for fn in chain:
            flag = "" if qual[fn] == "static" else "  [%s]" % qual[fn]
            print("  %6d  %s%s" % (size[fn], name[fn], flag))
        if unknown:
            print("  not counted (no frame size: libc/libm or indirect): %s"
                  % ", ".join(sorted(name.get(u, u) for u in unknown)))
        dyn = sorted(name[f] for f in chain if qual[f] != "static")
        if dyn:
            print("  WARNING: non-static frames on the chain: %s" % ", ".join(dyn))
    return rc


if __name__ == "__main__":
    sys.exit(main())
