#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Every figure of docs/PERFORMANCE.md's speed and size table in one command.

x86-64: exact instruction counts under callgrind of tools/bench/bench_count
(fixed workloads, no clock hook) and of the whole `bsf extract` process.
Cortex-M4F: QEMU -icount runs of test/bench/bench_m4_icount (all Intel scans with
the default method and FALKO-SVED-PDM, the office scans, the adversarial
scans) and of bench_m4_icount_big (3200-beam office, 4000-beam long wall).
Size: the extract + encode firmware's link map (size_report.py), stack
(stack_report.py) and sizeof (mem_report.py).

  python3 tools/scripts/perf_table.py                 # about 4 minutes on 2 cores
  python3 tools/scripts/perf_table.py --skip-m4 --skip-size   # x86 rows only
  python3 tools/scripts/perf_table.py --markdown      # the table as in docs/PERFORMANCE.md

It configures and builds what it needs in build-perf/ (host Release),
build-m4-perf/ (M4F Release, every Intel scan, two methods) and
build-m4-size*/ (M4F MinSizeRel) unless --no-build. Needs valgrind,
arm-none-eabi-gcc and qemu-system-arm; ../shared/data/intel.log.gz
(--shared DIR, or BSF_SHARED_DIR).
"""
import argparse
import glob
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

# budget, FALKOLib, floor per row key (docs/PERFORMANCE.md); None: no such figure.
FALKOLIB_X86 = 114_000  # FALKOLib's FALKO extractor alone, x86 -O2, per Intel scan
FLOOR_X86 = 11_700  # points from a table plus one pass over them, per Intel scan
FLOOR_M4 = 8_000


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def run(cmd, cwd=ROOT, capture=True, check=True):
    log("  $ " + " ".join(cmd))
    t0 = time.time()
    r = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE if capture else None,
                       stderr=subprocess.STDOUT if capture else None, text=True)
    log(f"    ({time.time() - t0:.1f} s)")
    if check and r.returncode != 0:
        if capture:
            sys.stderr.write(r.stdout[-4000:])
        sys.exit(f"perf_table: command failed ({r.returncode}): {' '.join(cmd)}")
    return r.stdout if capture else ""


def need(tool):
    if shutil.which(tool) is None:
        sys.exit(f"perf_table: {tool} not found (install it or use the --skip options)")


def cmake_build(build, targets, args):
    if not os.path.isfile(os.path.join(build, "CMakeCache.txt")):
        run(["cmake", "-S", ROOT, "-B", build] + args)
    else:
        run(["cmake", "-S", ROOT, "-B", build] + args)  # keeps options in step with this script
    run(["cmake", "--build", build, "-j2", "--target"] + targets)


def symbol(binary, base):
    """The linked name of a library function (caps-carrying names, bsf_abi.h)."""
    out = run(["nm", binary])
    names = [l.split()[-1] for l in out.splitlines() if len(l.split()) == 3 and l.split()[1] in "Tt"]
    for n in names:
        if n == base or n.startswith(base + "_caps"):
            return n
    sys.exit(f"perf_table: {base} not found in {binary}")


def callgrind_total(outfile):
    with open(outfile) as f:
        for line in f:
            if line.startswith("totals:") or line.startswith("summary:"):
                return int(line.split()[1])
    sys.exit(f"perf_table: no totals in {outfile}")


def callgrind(cmd, workdir, name, extra=()):
    out = os.path.join(workdir, f"cg.{name}.out")
    for f in glob.glob(out + "*"):
        os.remove(f)
    stdout = run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}"] + list(extra) + cmd)
    return out, stdout


def inclusive(outfile, bases, binary):
    """Inclusive Ir of each function (by base name) in a callgrind profile."""
    text = run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", outfile])
    want = {symbol(binary, b): b for b in bases}
    got = {}
    for line in text.splitlines():
        m = re.match(r"^\s*([\d,]+)\s+\([^)]*\)\s+\S*:(\S+)", line)
        if m and m.group(2) in want and want[m.group(2)] not in got:
            got[want[m.group(2)]] = int(m.group(1).replace(",", ""))
    for b in bases:
        got.setdefault(b, 0)
    return got


def per_call(binary, args, workdir, name):
    """Instructions of each bsf_extract call (callgrind dumps after each call)."""
    fn = symbol(binary, "bsf_extract")
    out, _ = callgrind([binary] + args, workdir, name,
                       ["--collect-atstart=no", f"--toggle-collect={fn}", f"--dump-after={fn}"])
    files = sorted(glob.glob(out + ".*"), key=lambda p: int(p.rsplit(".", 1)[1]))
    counts = [callgrind_total(p) for p in files]
    if not counts:
        sys.exit(f"perf_table: no per-call dumps for {name}")
    return counts


def parse_scans(stdout):
    m = re.search(r"scans (\d+) frames (\d+)", stdout)
    if not m:
        sys.exit("perf_table: bench_count printed no summary:\n" + stdout[-2000:])
    return int(m.group(1)), int(m.group(2))


def x86_rows(args, rows, work):
    need("valgrind")
    need("callgrind_annotate")
    build = args.build
    if not args.no_build:
        cmake_build(build, ["bench_count", "bench_count_big", "bsf_tool"],
                    ["-DCMAKE_BUILD_TYPE=Release", "-DBSF_BUILD_TESTS=OFF", "-DBSF_BUILD_TOOLS=ON",
                     f"-DBSF_SHARED_DIR={args.shared}"])
    bc = os.path.join(build, "tools", "bench_count")
    bcb = os.path.join(build, "tools", "bench_count_big")
    log_path = args.intel
    # Intel, default method, with encoding.
    out, so = callgrind([bc, "intel", log_path, "--method", "lc-sved-pdm", "--encode"], work, "lc")
    n, frames = parse_scans(so)
    # Segmentation: the extractor finds the mixed pixels once
    # (bsf_sved_mixed_marks, shared with LC) and SVED reads them
    # (bsf_segment_sved_marked); bsf_segment_sved_labelled when it runs alone.
    # LC: the extractor calls bsf_lc_detect's body, bsf_lc_detect_memo, which
    # keeps the grazing joins' verdicts for SVED.
    inc = inclusive(out, ["bsf_extract", "bsf_scan_to_points", "bsf_frame_encode", "bsf_lc_detect_memo",
                          "bsf_segment_sved_labelled", "bsf_segment_sved_marked",
                          "bsf_sved_mixed_marks", "bsf_pdm_fit_anchored"], bc)
    rows["x86_lc"] = inc["bsf_extract"] / n
    rows["x86_points"] = inc["bsf_scan_to_points"] / n
    rows["x86_encode"] = inc["bsf_frame_encode"] / frames
    rows["x86_lc_stages"] = {"bsf_lc_detect": inc["bsf_lc_detect_memo"] / n,
                             "bsf_pdm_fit_anchored": inc["bsf_pdm_fit_anchored"] / n}
    rows["x86_lc_stages"]["sved"] = (inc["bsf_segment_sved_labelled"] + inc["bsf_segment_sved_marked"] +
                                     inc["bsf_sved_mixed_marks"]) / n
    rows["x86_scans"] = n
    # Intel, FALKO-SVED-PDM.
    out, so = callgrind([bc, "intel", log_path, "--method", "falko-sved-pdm"], work, "falko")
    n, _ = parse_scans(so)
    inc = inclusive(out, ["bsf_extract", "bsf_falko_detect"], bc)
    rows["x86_falko"] = inc["bsf_extract"] / n
    rows["x86_falko_stage"] = inc["bsf_falko_detect"] / n
    # Office scaling scene, per scan, both SVED-PDM methods.
    for method in ("lc-sved-pdm", "falko-sved-pdm"):
        for beams in (1000, 4000):
            rows[f"scale_{method}_{beams}"] = per_call(
                bcb, ["scaling", "--beams", str(beams), "--method", method], work,
                f"scale_{method}_{beams}")
    # Adversarial scans, default method.
    for kind in ("pillar", "clutter", "long-wall"):
        rows[f"adv_{kind}"] = per_call(bcb, ["adversarial", "--kind", kind], work, f"adv_{kind}")
    # The whole tool process.
    if not args.skip_process:
        tool = os.path.join(build, "tools", "bsf")
        out, _ = callgrind([tool, "extract", log_path, "-o", "/dev/null"], work, "process")
        rows["x86_process"] = callgrind_total(out)


M4_LINE = re.compile(r"^\s+(falko-sved-pdm|bid-sved-pdm|rpos-lsba|lc-sved-pdm(?:/f\d+(?:b\d+)?)?)\s+(\d+)\s+(\d+)\s+(\d+)\s+\|"
                     r"\s+(\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s+\|\s+(\d+)\s+\|\s+([\d.]+)\s+\|\s+(\d+)")


def knobs(suffix):
    """What a "fK" or "fKbC" row label of bench_m4_icount set, in words."""
    m = re.fullmatch(r"f(\d+)(?:b(\d+))?", suffix)
    if not m:
        return f"`{suffix}`"
    words = f"`fit_passes` {m.group(1)}"
    if m.group(2):
        words += f" and `fit_bin_length` {int(m.group(2)) / 100:g} m"
    return words


def parse_m4(text):
    """{tag: {method: dict}} from bench_m4_icount's output."""
    res = {}
    tag = None
    for line in text.splitlines():
        m = re.match(r"^\[([\w-]+)\]", line)
        if m:
            tag = m.group(1)
            res.setdefault(tag, {})
            continue
        m = M4_LINE.match(line)
        if m and tag:
            # median mean max points corners segment fit encode; encode again, features, stack
            v = [int(x) for x in m.groups()[1:9]] + [int(m.group(9)), float(m.group(10)), int(m.group(11))]
            res[tag][m.group(1)] = dict(median=v[0], mean=v[1], max=v[2], points=v[3], corners=v[4],
                                        segment=v[5], fit=v[6], encode=v[7], feat=v[9], stack=v[10])
    return res


def qemu(elf):
    need("qemu-system-arm")
    return run(["qemu-system-arm", "-M", "mps2-an386", "-icount", "shift=10,sleep=off", "-display", "none",
                "-serial", "null", "-monitor", "none", "-semihosting-config", "enable=on,target=native",
                "-kernel", elf])


def m4_rows(args, rows):
    build = args.build_m4
    if not args.no_build:
        need("arm-none-eabi-gcc")
        cmake_build(build, ["bench_m4_icount", "bench_m4_icount_big"],
                    ["-DCMAKE_TOOLCHAIN_FILE=" + os.path.join(ROOT, "port", "cortex-m4f.cmake"),
                     "-DCMAKE_BUILD_TYPE=Release", "-DBSF_BENCH_LOG_STRIDE=1",
                     "-DBSF_METHODS=lc-sved-pdm;falko-sved-pdm", f"-DBSF_SHARED_DIR={args.shared}"])
    t = qemu(os.path.join(build, "test", "bench_m4_icount.elf"))
    t += qemu(os.path.join(build, "test", "bench_m4_icount_big.elf"))
    rows["m4_text"] = t
    rows["m4"] = parse_m4(t)
    m = re.search(r"\[intel\] .*?: (\d+) scans", t)
    rows["m4_intel_scans"] = int(m.group(1)) if m else 0


def size_rows(args, rows):
    need("arm-none-eabi-gcc")
    tc = "-DCMAKE_TOOLCHAIN_FILE=" + os.path.join(ROOT, "port", "cortex-m4f.cmake")
    common = [tc, "-DCMAKE_BUILD_TYPE=MinSizeRel", "-DBSF_BUILD_TESTS=OFF", "-DBSF_STACK_USAGE=ON"]
    for key, build, extra in (("size_default", args.build_size + "-lc", ["-DBSF_METHODS=lc-sved-pdm", "-DBSF_FIT_BINS=OFF"]),
                              ("size_all", args.build_size, ["-DBSF_METHODS=all"])):
        if not args.no_build:
            cmake_build(build, ["bsf", "extract_encode"], common + extra)
        mapf = os.path.join(build, "port", "examples", "extract_encode", "extract_encode.elf.map")
        rep = run([sys.executable, os.path.join(HERE, "size_report.py"), mapf])
        m = re.search(r"libbsf\.a: (\d+) bytes", rep)
        rows[key] = int(m.group(1))
        rows[key + "_report"] = rep
        if key == "size_default":
            st = run([sys.executable, os.path.join(HERE, "stack_report.py"), "--root", "bsf_extract",
                      "--limit", "2048", build], check=False)
            rows["stack_report"] = st
            m = re.search(r"worst-case stack of \S+: (\d+) bytes", st)
            rows["stack"] = int(m.group(1)) if m else None
    mem = run([sys.executable, os.path.join(HERE, "mem_report.py")], check=False)
    rows["mem_report"] = mem
    # The last extractor_t line is the M4F's; its third figure is 1081 beams.
    lines = [l for l in mem.splitlines() if l.strip().startswith("extractor_t")]
    rows["mem_extractor_1081"] = int(re.findall(r"(\d+) \(", lines[-1])[2]) if lines else None


def fmt(v, unit=""):
    if v is None:
        return "-"
    if isinstance(v, str):
        return v
    if v >= 1_000_000_000:
        return f"{v / 1e6:,.0f} M{unit}".replace(",", " ")
    if v >= 10_000_000:
        return f"{v / 1e6:.1f} M{unit}"
    if v >= 1_000_000:
        return f"{v / 1e6:.2f} M{unit}"
    if v >= 100_000:
        return f"{v / 1e3:.0f} k{unit}"
    if v >= 10_000:
        return f"{v / 1e3:.1f} k{unit}"
    if v >= 1000:
        return f"{v / 1e3:.1f} k{unit}"
    return f"{v:.3g}{unit}"


def nbytes(v):
    return f"{v:,} B".replace(",", " ")


def status(ok):
    return "met" if ok else "**not met**"


def table(rows):
    """[(figure, today, budget, falkolib, floor, status, command)]"""
    t = []
    P = "perf_table.py"  # every row comes from it; the column says which of its runs
    if "x86_lc" in rows:
        t.append(("x86 instructions per Intel scan, `bsf_extract`, lc-sved-pdm (default)",
                  fmt(rows["x86_lc"]), "<= 110 k", fmt(FALKOLIB_X86), fmt(FLOOR_X86),
                  status(rows["x86_lc"] <= 110_000), "callgrind `bench_count intel` (mean over the log's scans)"))
        t.append(("x86 instructions per Intel scan, `bsf_extract`, falko-sved-pdm",
                  fmt(rows["x86_falko"]), "<= 110 k", fmt(FALKOLIB_X86), fmt(FLOOR_X86),
                  status(rows["x86_falko"] <= 110_000), "callgrind `bench_count intel --method falko-sved-pdm`"))
        t.append(("FALKO stage alone (`bsf_falko_detect`), per Intel scan, x86",
                  fmt(rows["x86_falko_stage"]), "<= 28 k", fmt(FALKOLIB_X86), "-",
                  status(rows["x86_falko_stage"] <= 28_000), "same run, inclusive"))
        t.append(("range -> points (`bsf_scan_to_points`), per Intel scan, x86",
                  fmt(rows["x86_points"]), "<= 12 k", "-", "-",
                  status(rows["x86_points"] <= 12_000), "callgrind `bench_count intel`"))
        t.append(("`bsf_frame_encode` per frame, x86 (Intel, default method)",
                  fmt(rows["x86_encode"]), "<= 5 k", "-", "-",
                  status(rows["x86_encode"] <= 5_000), "callgrind `bench_count intel --encode`"))
        for method in ("lc-sved-pdm", "falko-sved-pdm"):
            a = rows[f"scale_{method}_1000"]
            b = rows[f"scale_{method}_4000"]
            r = statistics.median(b) / statistics.median(a)
            worst = max(max(a) / statistics.median(a), max(b) / statistics.median(b))
            t.append((f"office scene 1000 -> 4000 beams, median instructions, {method} (x86)",
                      f"{r:.1f}x ({fmt(statistics.median(a))} -> {fmt(statistics.median(b))})", "<= 4.3x", "-", "-",
                      status(r <= 4.3), "callgrind per call, `bench_count_big scaling --beams N`"))
            t.append((f"office scene, worst scan / median (1000 and 4000 beams), {method} (x86)",
                      f"{worst:.1f}x", "<= 10x", "-", "-", status(worst <= 10.0), "same runs"))
        med = {1000: statistics.median(rows["scale_lc-sved-pdm_1000"]),
               4000: statistics.median(rows["scale_lc-sved-pdm_4000"])}
        for kind, beams in (("pillar", 1000), ("clutter", 1000), ("long-wall", 4000)):
            c = rows[f"adv_{kind}"]
            t.append((f"adversarial: {kind} ({beams} beams), worst scan / office median at {beams} beams, default method (x86)",
                      f"{max(c) / med[beams]:.1f}x ({fmt(max(c))})", "<= 10x", "-", "-",
                      status(max(c) / med[beams] <= 10.0),
                      f"callgrind per call, `bench_count_big adversarial --kind {kind}`"))
        if "x86_process" in rows:
            t.append(("whole `bsf extract intel.log.gz -o /dev/null` process, x86",
                      fmt(rows["x86_process"]), "<= 600 M", "-", "-", status(rows["x86_process"] <= 600e6),
                      "callgrind of the tool"))
    if "m4" in rows:
        m4 = rows["m4"]
        intel = m4.get("intel", {})
        n = rows.get("m4_intel_scans", 0)
        if "lc-sved-pdm" in intel:
            d = intel["lc-sved-pdm"]
            t.append((f"M4F, Intel ({n} scans), extraction median, default method", fmt(d["median"]), "<= 150 k",
                      "-", fmt(FLOOR_M4), status(d["median"] <= 150_000), "QEMU icount `bench_m4_icount`"))
            t.append((f"M4F, Intel ({n} scans), extraction max, default method",
                      f"{fmt(d['max'])} ({d['max'] / d['median']:.1f}x median)", "<= 4x median", "-", "-",
                      status(d["max"] <= 4 * d["median"]), "same run"))
            t.append(("M4F, Intel, extraction + encoding median, default method",
                      fmt(d["median"] + d["encode"]), "<= 165 k", "-", "-",
                      status(d["median"] + d["encode"] <= 165_000), "same run (median + median encode)"))
            t.append(("M4F, `bsf_frame_encode` median per frame, Intel, default method", fmt(d["encode"]), "<= 8 k",
                      "-", "-", status(d["encode"] <= 8000), "same run"))
            t.append(("M4F, range -> points median per Intel scan", fmt(d["points"]), "-", "-", "-", "-",
                      "same run (points stage)"))
        if "falko-sved-pdm" in intel:
            d = intel["falko-sved-pdm"]
            t.append((f"M4F, Intel ({n} scans), extraction median / max, falko-sved-pdm",
                      f"{fmt(d['median'])} / {fmt(d['max'])}", "<= 150 k / 4x", "-", fmt(FLOOR_M4),
                      status(d["median"] <= 150_000 and d["max"] <= 4 * d["median"]), "same run"))
        for tag, label, budget in (("office-1081", "1081-beam 270 deg office scan, M4F median", 1_000_000),
                                   ("office-3200", "3200-beam 360 deg office scan, M4F median", 3_200_000)):
            d = m4.get(tag, {}).get("lc-sved-pdm")
            if d:
                t.append((label + " (default method)", fmt(d["median"]), f"<= {fmt(budget)}", "-", "-",
                          status(d["median"] <= budget), f"QEMU icount `bench_m4_icount{'_big' if '3200' in tag else ''}`"))
        # The default method with the fit's work bounded (bsf_params_t.fit_passes,
        # the "lc-sved-pdm/fK" rows): the worst scans a firmware must keep up with.
        for tag, label, budget in (("office-1081", "1081-beam 270 deg office scan, M4F worst pose", 2_100_000),
                                   ("office-3200", "3200-beam 360 deg office scan, M4F worst pose", 8_400_000)):
            for name, d in sorted(m4.get(tag, {}).items()):
                if name.startswith("lc-sved-pdm/f"):
                    t.append((f"{label}, default method, {knobs(name[12:])} (median / max)",
                              f"{fmt(d['median'])} / {fmt(d['max'])}", f"max <= {fmt(budget)}", "-", "-",
                              status(d["max"] <= budget),
                              f"QEMU icount `bench_m4_icount{'_big' if '3200' in tag else ''}`"))
        for name, d in sorted(intel.items()):
            if name.startswith("lc-sved-pdm/f"):
                t.append((f"M4F, Intel ({n} scans), extraction median / max, default method, {knobs(name[12:])}",
                          f"{fmt(d['median'])} / {fmt(d['max'])} ({d['max'] / d['median']:.1f}x median)",
                          "max <= 4x median", "-", "-", status(d["max"] <= 4 * d["median"]), "same run"))
        stacks = [d["stack"] for methods in m4.values() for d in methods.values()]
        if stacks:
            t.append(("painted stack of `bsf_extract` (M4F -O3, libm included), max over every source and method",
                      nbytes(max(stacks)), "<= 2 048 B", "-", "-", status(max(stacks) <= 2048),
                      "QEMU `bench_m4_icount{,_big}` (stack column)"))
        for tag in ("adv-pillar", "adv-clutter", "adv-long-wall"):
            d = m4.get(tag, {}).get("lc-sved-pdm")
            if d:
                t.append((f"M4F adversarial {tag[4:]}, median / max (default method)",
                          f"{fmt(d['median'])} / {fmt(d['max'])}", "(bounds the worst case)", "-", "-", "-",
                          "QEMU icount"))
            for name, d in sorted(m4.get(tag, {}).items()):
                if name.startswith("lc-sved-pdm/f"):
                    t.append((f"M4F adversarial {tag[4:]}, median / max (default method, {knobs(name[12:])})",
                              f"{fmt(d['median'])} / {fmt(d['max'])}", "(bounds the worst case)", "-", "-", "-",
                              "QEMU icount"))
    if "size_default" in rows:
        t.append(("`.text`+`.rodata` of libbsf linked by an extract + encode firmware, -Os, default method only",
                  nbytes(rows['size_default']), "<= 32 768 B", "-", "-", status(rows["size_default"] <= 32768),
                  "size_report.py on extract_encode.elf.map, `-DBSF_METHODS=lc-sved-pdm -DBSF_FIT_BINS=OFF`"))
        if rows.get("mem_extractor_1081") is not None:
            t.append(("`sizeof(bsf_extractor_t)`, 1081 beams, M4F", nbytes(rows['mem_extractor_1081']), "<= 49 152 B",
                      "-", "-", status(rows["mem_extractor_1081"] <= 49152), "mem_report.py"))
        if rows.get("stack") is not None:
            t.append(("worst-case stack of `bsf_extract` (call graph, M4F -Os)", nbytes(rows['stack']), "<= 2 048 B",
                      "-", "-", status(rows["stack"] <= 2048), "stack_report.py --root bsf_extract"))
        t.append(("libbsf linked by the same firmware with every method compiled in (the default build)",
                  nbytes(rows["size_all"]), "-", "-", "-", "-", "size_report.py, `-DBSF_METHODS=all`"))
    return t


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    shared_default = os.environ.get("BSF_SHARED_DIR", os.path.join(os.path.dirname(ROOT), "shared"))
    ap.add_argument("--shared", default=shared_default, help="directory holding data/ (default ../shared)")
    ap.add_argument("--build", default=os.path.join(ROOT, "build-perf"))
    ap.add_argument("--build-m4", default=os.path.join(ROOT, "build-m4-perf"))
    ap.add_argument("--build-size", default=os.path.join(ROOT, "build-m4-size"))
    ap.add_argument("--no-build", action="store_true", help="use the builds as they are")
    ap.add_argument("--skip-x86", action="store_true")
    ap.add_argument("--skip-m4", action="store_true")
    ap.add_argument("--skip-size", action="store_true")
    ap.add_argument("--skip-process", action="store_true", help="skip the whole-process callgrind run")
    ap.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    ap.add_argument("--keep", action="store_true", help="keep the callgrind files (printed path)")
    args = ap.parse_args()
    args.shared = os.path.abspath(args.shared)
    data = args.shared if os.path.isfile(os.path.join(args.shared, "intel.log.gz")) else os.path.join(args.shared, "data")
    args.intel = os.path.join(data, "intel.log.gz")
    if not os.path.isfile(args.intel) and not args.skip_x86:
        sys.exit(f"perf_table: {args.intel} not found (--shared DIR)")
    t0 = time.time()
    rows = {}
    work = tempfile.mkdtemp(prefix="bsf-perf-")
    try:
        if not args.skip_x86:
            x86_rows(args, rows, work)
        if not args.skip_m4:
            m4_rows(args, rows)
        if not args.skip_size:
            size_rows(args, rows)
    finally:
        if args.keep:
            log(f"callgrind files kept in {work}")
        else:
            shutil.rmtree(work, ignore_errors=True)
    commit = run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], check=False).strip()
    t = table(rows)
    print(f"performance figures, commit {commit}, {time.time() - t0:.0f} s")
    if args.markdown:
        print("\n| figure | today | budget | FALKOLib | floor | status | command |")
        print("|---|---|---|---|---|---|---|")
        for r in t:
            print("| " + " | ".join(r) + " |")
    else:
        w = max(len(r[0]) for r in t) if t else 10
        for r in t:
            print(f"{r[0]:<{w}}  {r[1]:>22}  budget {r[2]:<14} {r[5]}")
    if "x86_lc_stages" in rows:
        s = rows["x86_lc_stages"]
        print(f"\nx86 per Intel scan ({rows['x86_scans']} scans), default method: LC corners "
              f"{fmt(s['bsf_lc_detect'])}, SVED with its mixed pixels {fmt(s['sved'])}, "
              f"PDM {fmt(s['bsf_pdm_fit_anchored'])}, points {fmt(rows['x86_points'])}")
        for method in ("lc-sved-pdm", "falko-sved-pdm"):
            for beams in (1000, 4000):
                c = rows[f"scale_{method}_{beams}"]
                print(f"office scaling {method} {beams} beams, per scan: median {fmt(statistics.median(c))}, "
                      f"max {fmt(max(c))}, min {fmt(min(c))}")
        for kind in ("pillar", "clutter", "long-wall"):
            c = rows[f"adv_{kind}"]
            print(f"adversarial {kind}, per scan: " + ", ".join(fmt(x) for x in c))
    if "m4" in rows:
        print("\nM4F (QEMU icount), medians per scan:")
        for tag, methods in rows["m4"].items():
            for m, d in methods.items():
                print(f"  {tag:<14} {m:<15} median {fmt(d['median']):>8}  max {fmt(d['max']):>8}  points "
                      f"{fmt(d['points']):>7}  corners {fmt(d['corners']):>7}  segment {fmt(d['segment']):>7}  "
                      f"fit {fmt(d['fit']):>8}  encode {fmt(d['encode']):>7}  stack {d['stack']} B")
    if "size_default" in rows:
        print("\n" + rows["size_default_report"].strip())
        print(rows["stack_report"].strip())
        print(rows["mem_report"].strip())
    return 0


if __name__ == "__main__":
    sys.exit(main())
