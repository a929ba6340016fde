#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Check that the documentation agrees with itself and with the code.

Always (no build needed, well under a second):
  - every relative Markdown link in a tracked .md file names a file or folder that exists;
  - every pointer to a section of docs/DESIGN.md in the tree ('DESIGN.md, "Cut policy"' or
    'DESIGN.md ("Methods")') names a heading that exists;
  - no tracked text file cites a document outside the repository ("design brief",
    "(design 7)", "issue 15", ...);
  - every pip extras list in a .md file ('tools/python[plot,rosbag]') uses only the extras
    tools/python/pyproject.toml declares, and tools/python/README.md names all of them.

With a built tool, each figure the README and CHANGELOG quote is compared with what the named
command prints today:
  --bench-truth build/tools/bench_truth   corner recall and placement (about 2 s)
  --size-map MAP                          libbsf bytes of the default-method extract + encode
                                          firmware (size_report.py on its link map)
  --stack-build DIR                       worst-case stack of bsf_extract (stack_report.py on a
                                          -DBSF_STACK_USAGE=ON build of the default method)
  --mem                                   sizeof table (mem_report.py, needs arm-none-eabi-gcc)

Exit 0 when everything checked agrees, 1 with one line per disagreement otherwise.

  python3 tools/scripts/check_docs.py
  python3 tools/scripts/check_docs.py --bench-truth build/tools/bench_truth
"""
import argparse
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

# Citations of documents a reader of the repository does not have.
OUTSIDE = re.compile(r"design brief|\(design [0-9]+\)|design section [0-9]|\bissue[- ][0-9]+|"
                     r"\bissues [0-9]+ and [0-9]+|the brief\b", re.IGNORECASE)
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
DESIGN_POINTER = re.compile(r'DESIGN\.md,?\s+\(?"([^"]+)"')
EXTRAS = re.compile(r"tools/python\[([a-z0-9_,-]+)\]")
TEXT_EXT = (".md", ".c", ".h", ".py", ".txt", ".cmake", ".cff", ".toml", ".cfg", ".in", ".pyi")


def tracked_files():
    out = subprocess.run(["git", "-C", ROOT, "ls-files"], capture_output=True, text=True, check=True)
    return [f for f in out.stdout.splitlines() if f]


def read(rel):
    with open(os.path.join(ROOT, rel), encoding="utf-8", errors="replace") as f:
        return f.read()


def headings(rel):
    return {m.group(1).strip() for m in re.finditer(r"^#+\s+(.*)$", read(rel), re.MULTILINE)}


def check_links(files, errors):
    for rel in files:
        if not rel.endswith(".md"):
            continue
        text = read(rel)
        for m in LINK.finditer(text):
            target = m.group(1)
            if re.match(r"^[a-z]+:", target) or target.startswith("#"):
                continue
            path = target.split("#", 1)[0]
            full = os.path.normpath(os.path.join(ROOT, os.path.dirname(rel), path))
            if not os.path.exists(full):
                line = text.count("\n", 0, m.start()) + 1
                errors.append(f"{rel}:{line}: link to {target}: no such file")


def check_design_pointers(files, errors):
    design = "docs/DESIGN.md"
    if not os.path.exists(os.path.join(ROOT, design)):
        errors.append(f"{design}: missing")
        return
    names = headings(design)
    for rel in files:
        if not rel.endswith(TEXT_EXT) and os.path.basename(rel) != "run":
            continue
        text = re.sub(r"\s*\n\s*(?:\*|#|//)?\s*", " ", read(rel))  # join wrapped comment lines
        for m in DESIGN_POINTER.finditer(text):
            if m.group(1) not in names:
                errors.append(f'{rel}: points to DESIGN.md section "{m.group(1)}", which does not exist')


def check_outside_references(files, errors):
    for rel in files:
        if not rel.endswith(TEXT_EXT) and os.path.basename(rel) not in ("run", "CMakeLists.txt"):
            continue
        if rel == "tools/scripts/check_docs.py":
            continue
        for n, line in enumerate(read(rel).splitlines(), 1):
            m = OUTSIDE.search(line)
            if m:
                errors.append(f"{rel}:{n}: cites a document outside the repository: {m.group(0)!r}")


def check_extras(files, errors):
    toml = read("tools/python/pyproject.toml")
    block = re.search(r"^\[project\.optional-dependencies\]\n(.*?)(?:^\[|\Z)", toml, re.MULTILINE | re.DOTALL)
    declared = set(re.findall(r"^([a-z0-9_-]+)\s*=", block.group(1), re.MULTILINE)) if block else set()
    if not declared:
        errors.append("tools/python/pyproject.toml: no [project.optional-dependencies]")
        return
    for rel in files:
        if not rel.endswith(".md"):
            continue
        for m in EXTRAS.finditer(read(rel)):
            unknown = set(m.group(1).split(",")) - declared
            if unknown:
                errors.append(f"{rel}: pip extras {sorted(unknown)} are not in pyproject.toml {sorted(declared)}")
    readme = re.sub(r"\s+", " ", read("tools/python/README.md"))
    named = set(re.findall(r"`([a-z0-9_-]+)` \(", readme))
    if not declared <= named:
        errors.append(f"tools/python/README.md: extras {sorted(declared - named)} of pyproject.toml not described")


def number(s):
    return float(s.replace(" ", "").replace("\u202f", ""))


def expect_range(rel, pattern, lo, hi, what, errors, tol=0.005):
    text = re.sub(r"\s+", " ", read(rel))
    m = re.search(pattern, text)
    if not m:
        errors.append(f"{rel}: no {what} figure found (pattern {pattern!r})")
        return
    got = (number(m.group(1)), number(m.group(2)))
    if abs(got[0] - lo) > tol or abs(got[1] - hi) > tol:
        errors.append(f"{rel}: {what} {got[0]:g}-{got[1]:g}, the command prints {lo:g}-{hi:g}")


def expect_value(rel, pattern, value, what, errors):
    text = re.sub(r"\s+", " ", read(rel))
    found = re.findall(pattern, text)
    if not found:
        errors.append(f"{rel}: no {what} figure found (pattern {pattern!r})")
    for g in found:
        if number(g) != value:
            errors.append(f"{rel}: {what} {g.strip()}, the command prints {value:g}")


def bench_rows(exe, extra):
    cmd = [exe, "--poses", "40", "--noise", "10"] + extra
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    rows = []
    for line in out.splitlines():
        c = [x.strip() for x in line.split("|")]
        if len(c) > 17 and c[3] == "1cm":
            rows.append({"scene": c[1], "beams": int(c[2].split("/")[0]), "recall": float(c[5].rstrip("%")),
                         "verr_median": float(c[10].split("/")[0])})
    if not rows:
        raise SystemExit(f"check_docs: {' '.join(cmd)} printed no 1 cm rows")
    return rows


# The scenes the README's "synthetic offices" sentence covers; the corridor and
# the cluttered room have a sentence of their own.
OFFICE_SCENES = ("office", "angles", "curved")


def check_truth(exe, errors):
    all_rows = bench_rows(exe, [])
    rows = [r for r in all_rows if r["scene"] in OFFICE_SCENES]
    recall = (min(r["recall"] for r in rows), max(r["recall"] for r in rows))
    verr = (min(r["verr_median"] for r in rows), max(r["verr_median"] for r in rows))
    paper = bench_rows(exe, ["--paper"])
    sparse = [r["recall"] for r in paper if r["beams"] <= 541 and r["scene"] in OFFICE_SCENES]
    for scene, lead in (("corridor", "a long corridor with door recesses"),
                        ("clutter", "a cluttered room of shelves, posts and boxes")):
        got = [r["recall"] for r in all_rows if r["scene"] == scene]
        if not got:
            errors.append(f"bench_truth printed no 1 cm rows for the {scene} scene")
            continue
        expect_range("README.md", re.escape(lead) + r"[^%]*? ([\d.]+)–([\d.]+) %", min(got), max(got),
                     f"{scene} recall", errors)
    paper_range = (round(min(sparse)), round(max(sparse)))
    for rel in ("README.md", "CHANGELOG.md"):
        expect_range(rel, r"finds ([\d.]+)–([\d.]+) % of the visible corners", *recall, "corner recall", errors)
        expect_range(rel, r"([\d.]+)–([\d.]+) cm from the true corner \(median\)", *verr,
                     "corner placement (median)", errors)
        expect_range(rel, r"finds (\d+)–(\d+) % at 181–541 beams", *paper_range,
                     "paper-faithful recall at 181-541 beams", errors)


def check_size(map_path, errors):
    out = subprocess.run([sys.executable, os.path.join(HERE, "size_report.py"), map_path, "--quiet"],
                         capture_output=True, text=True, check=True).stdout
    m = re.search(r"libbsf\.a: (\d+) bytes", out)
    if not m:
        raise SystemExit(f"check_docs: size_report.py printed no total for {map_path}")
    value = int(m.group(1))
    # The README states today's figure; CHANGELOG's are history.
    expect_value("README.md", r"links ([\d ]+) bytes of libbsf", value, "firmware libbsf bytes", errors)


def check_stack(build_dir, errors):
    out = subprocess.run([sys.executable, os.path.join(HERE, "stack_report.py"), "--root", "bsf_extract", build_dir],
                         capture_output=True, text=True, check=True).stdout
    m = re.search(r"worst-case stack of \S+: (\d+) bytes", out)
    if not m:
        raise SystemExit(f"check_docs: stack_report.py printed no worst case for {build_dir}")
    expect_value("README.md", r"worst-case stack of `bsf_extract` is ([\d ]+) bytes", int(m.group(1)),
                 "bsf_extract stack", errors)


def check_mem(errors):
    out = subprocess.run([sys.executable, os.path.join(HERE, "mem_report.py")], capture_output=True, text=True,
                         check=True).stdout
    m4 = out.split("cortex-m4f", 1)
    if len(m4) < 2:
        raise SystemExit("check_docs: mem_report.py printed no Cortex-M4F sizes (arm-none-eabi-gcc missing?)")
    text = re.sub(r"\s+", " ", read("README.md"))
    for name in ("extractor_t", "result_t"):
        m = re.search(r"^\s*" + name + r"\s+(\d+) \(.*?\)\s+(\d+) \(.*?\)\s+(\d+) \(", m4[1], re.MULTILINE)
        want = [int(v) for v in m.groups()] if m else None
        r = re.search(r"\| `sizeof\(bsf_" + name + r"\)` \| ([\d ]+) \| ([\d ]+) \| ([\d ]+) \|", text)
        if not (m and r):
            errors.append(f"README.md: sizeof(bsf_{name}) row or mem_report.py line not found")
            continue
        got = [int(number(v)) for v in r.groups()]
        if got != want:
            errors.append(f"README.md: sizeof(bsf_{name}) {got}, mem_report.py prints {want}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bench-truth", metavar="EXE", help="bench_truth executable (Release build)")
    ap.add_argument("--size-map", metavar="MAP", help="link map of the default-method extract_encode firmware")
    ap.add_argument("--stack-build", metavar="DIR", help="M4F -Os build with BSF_STACK_USAGE=ON (default method)")
    ap.add_argument("--mem", action="store_true", help="compare the README's sizeof table with mem_report.py")
    args = ap.parse_args()
    files = tracked_files()
    errors = []
    check_links(files, errors)
    check_design_pointers(files, errors)
    check_outside_references(files, errors)
    check_extras(files, errors)
    if args.bench_truth:
        check_truth(args.bench_truth, errors)
    if args.size_map:
        check_size(args.size_map, errors)
    if args.stack_build:
        check_stack(args.stack_build, errors)
    if args.mem:
        check_mem(errors)
    for e in errors:
        print(e)
    checked = ["links", "DESIGN.md pointers", "outside references", "pip extras"]
    checked += [n for n, on in (("truth figures", args.bench_truth), ("code size", args.size_map),
                                ("stack", args.stack_build), ("sizeof", args.mem)) if on]
    print(f"check_docs: {', '.join(checked)}: {'OK' if not errors else f'{len(errors)} problem(s)'}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
