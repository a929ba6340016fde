#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Release checks: what a user who never saw the repository gets.
#
#   tools/scripts/ci_release.sh [STEP...]      (default: every step, in this order)
#
#   gitignore  the files the README's commands write are ignored by git
#   archive    git archive of HEAD -> build-release/bsf-VERSION.tar.gz, then
#              configure, build and ctest from the extracted archive (not the
#              checkout), without the datasets (those tests must skip, visibly),
#              and cmake --install it (licence and docs included)
#   offline    the README's main command, in a fresh copy of the archive, with
#              no network (unshare -n when allowed, else a dead proxy and no
#              pip index): it must not need Unity or anything else
#   python     sdist of the archive's tools/python, a wheel built from that
#              sdist alone (copied out of any checkout), installed into a fresh
#              venv; the sdist's tests run against the installed wheel and
#              the archive build's tool
#   live       the live-link commands of docs/PORTING.md (the block with
#              mkfifo), twice in a row from the checkout: a second run must
#              work as the first; skipped, saying so, without build-m4's
#              uart_stream.elf (run it after the Cortex-M4F step)
#
# Environment: JOBS (2), BSF_SHARED_DIR (for the Python tests' datasets;
# default ../shared), BSF_UNITY_WHEEL (a local vyperling wheel for the archive
# build; default: build/_deps/unity/ of the checkout when present, else pip
# downloads it), BSF_MAIN_COMMAND (the offline step's command instead of the
# README's ci:main-command block).
# Needs git, cmake, a C compiler, python3 with venv and the C headers of
# Python, and PyPI (build==1.2.2.post1, setuptools==80.9.0 and the test
# requirements in tools/python/tests/requirements-ci.txt).
set -euo pipefail

here=$(cd "$(dirname "$0")/../.." && pwd)
cd "$here"
jobs=${JOBS:-2}
work="$here/build-release"
t0=$(date +%s)
step() { printf '\n==== [%4ss] release: %s\n' "$(( $(date +%s) - t0 ))" "$*"; }
fail() { echo "ci_release: $*" >&2; exit 1; }

version=$(sed -n 's/^#define BSF_VERSION_STRING "\([0-9.]*\)"$/\1/p' include/bsf/bsf_version.h)
[ -n "$version" ] || fail "no BSF_VERSION_STRING in include/bsf/bsf_version.h"
grep -Eq "^ +VERSION ${version//./\\.}$" CMakeLists.txt || fail "CMakeLists.txt's project(VERSION) is not $version"
name="bsf-$version"
src="$work/src/$name"           # the extracted archive
bld="$work/build"               # its build

readme_block() { # the fenced block after <!-- ci:$1 --> in README file $2
    awk -v mark="<!-- ci:$1 -->" '$0==mark{f=1;next} f&&/^```/{if(b){exit}b=1;next} f&&b{print}' "$2"
}

do_gitignore() {
    step "the README's outputs are ignored by git"
    if ! git rev-parse --is-inside-work-tree > /dev/null 2>&1; then
        echo "SKIPPED: not a git checkout"
        return
    fi
    for f in .venv/bin/python intel.png intel.bsf live.bsf run.bsf demo.svg demo.bsf build/x build-m4/x; do
        git check-ignore -q --no-index "$f" || fail "$f is not ignored (.gitignore)"
    done
    echo "ignored: .venv/ intel.png intel.bsf live.bsf run.bsf demo.svg demo.bsf build*/"
}

do_archive() {
    step "source archive $name.tar.gz (git archive HEAD)"
    git diff --quiet HEAD -- || echo "note: uncommitted changes are not in the archive (it is HEAD)"
    rm -rf "$work"
    mkdir -p "$work/src"
    git archive --format=tar.gz --prefix="$name/" -o "$work/$name.tar.gz" HEAD
    tar -xzf "$work/$name.tar.gz" -C "$work/src"
    for f in LICENSE README.md CMakeLists.txt include/bsf/bsf.h tools/python/setup.py; do
        [ -f "$src/$f" ] || fail "the archive has no $f"
    done
    echo "$(du -k "$work/$name.tar.gz" | cut -f1) KiB, $(tar -tzf "$work/$name.tar.gz" | grep -vc '/$') files"

    step "configure, build and ctest from the extracted archive, datasets absent"
    local wheel=${BSF_UNITY_WHEEL:-}
    if [ -z "$wheel" ]; then
        wheel=$(ls "$here"/build/_deps/unity/vyperling-*.whl 2> /dev/null | head -n1 || true)
    fi
    # An empty directory as the shared data: tests needing the datasets skip.
    mkdir -p "$work/no-shared"
    cmake -S "$src" -B "$bld" -DCMAKE_BUILD_TYPE=Release -DBSF_BUILD_TESTS=ON \
        -DBSF_SHARED_DIR="$work/no-shared" ${wheel:+-DBSF_UNITY_WHEEL=$wheel} > "$work/configure.log" ||
        { cat "$work/configure.log"; fail "configure from the archive failed"; }
    cmake --build "$bld" -j"$jobs" > "$work/build.log" 2>&1 ||
        { tail -n 40 "$work/build.log"; fail "build from the archive failed"; }
    local rc=0
    (cd "$bld" && BSF_SHARED_DIR="$work/no-shared" ctest -j"$jobs" --no-tests=error --output-on-failure) > "$work/ctest.log" 2>&1 || rc=$?
    tail -n 25 "$work/ctest.log"
    [ "$rc" -eq 0 ] || fail "ctest from the archive failed"
    grep -q "Skipped" "$work/ctest.log" ||
        fail "no test skipped although the datasets are absent: do the dataset tests still look for them?"

    step "cmake --install of the archive build"
    cmake --install "$bld" --prefix "$work/prefix" > /dev/null
    for f in share/doc/bsf/LICENSE share/doc/bsf/README.md share/doc/bsf/docs/FORMAT.md include/bsf/bsf.h bin/bsf; do
        [ -e "$work/prefix/$f" ] || fail "cmake --install did not install $f"
    done
    ls "$work"/prefix/lib*/libbsf.* > /dev/null 2>&1 || fail "cmake --install did not install libbsf"
    "$work/prefix/bin/bsf" --version | grep -q "^bsf $version " || fail "the installed bsf is not version $version"
    echo "installed: bin/bsf $version, libbsf, headers, share/doc/bsf (LICENSE, README.md, docs/)"
}

have_archive() {
    [ -f "$src/CMakeLists.txt" ] || fail "run the archive step first (no $src)"
}

do_offline() {
    have_archive
    local copy="$work/offline/$name" cmd
    rm -rf "$work/offline"
    mkdir -p "$work/offline"
    tar -xzf "$work/$name.tar.gz" -C "$work/offline"
    cmd=${BSF_MAIN_COMMAND:-$(readme_block main-command "$copy/README.md")}
    [ -n "$cmd" ] || fail "README.md has no ci:main-command block"
    step "README main command with no network: $cmd"
    # Nothing to download from: a dead proxy, no pip index, no user pip config.
    local -a env_offline=(env http_proxy=http://127.0.0.1:9 https_proxy=http://127.0.0.1:9
        HTTP_PROXY=http://127.0.0.1:9 HTTPS_PROXY=http://127.0.0.1:9 no_proxy= NO_PROXY=
        PIP_NO_INDEX=1 PIP_CONFIG_FILE=/dev/null PIP_NO_CACHE_DIR=1)
    if unshare -n true 2> /dev/null; then
        echo "network: none (unshare -n)"
        env_offline=(unshare -n "${env_offline[@]}")
    else
        echo "network: dead proxy and no pip index (unshare -n not allowed here)"
    fi
    (cd "$copy" && "${env_offline[@]}" bash -euo pipefail -c "$cmd") > "$work/offline.log" 2>&1 ||
        { tail -n 30 "$work/offline.log"; fail "the main command needs the network"; }
    tail -n 3 "$work/offline.log"
    [ -s "$copy/demo.svg" ] || fail "the main command wrote no demo.svg"
    [ ! -e "$copy/build/_deps/unity" ] || fail "the main command fetched Unity"
}

do_python() {
    have_archive
    local py="$work/py" sdist wheel
    rm -rf "$py"
    mkdir -p "$py"
    step "Python: sdist of the archive's tools/python, wheel from the sdist alone"
    python3 -m venv "$py/tools"
    "$py/tools/bin/pip" install -q --disable-pip-version-check build==1.2.2.post1
    "$py/tools/bin/python" -m build --sdist --outdir "$py/sdist" "$src/tools/python" > "$py/sdist.log" 2>&1 ||
        { tail -n 30 "$py/sdist.log"; fail "python -m build --sdist failed"; }
    sdist=$(ls "$py"/sdist/bsf-*.tar.gz)
    # The sdist, alone in an empty directory: it must carry the C library.
    mkdir -p "$py/alone"
    tar -xzf "$sdist" -C "$py/alone"
    [ -f "$py/alone/$name/csrc/src/bsf_extract.c" ] || fail "the sdist carries no csrc/src"
    [ -f "$py/alone/$name/LICENSE" ] || fail "the sdist carries no LICENSE"
    "$py/tools/bin/python" -m build --wheel --outdir "$py/wheel" "$py/alone/$name" > "$py/wheel.log" 2>&1 ||
        { tail -n 30 "$py/wheel.log"; fail "python -m build --wheel from the sdist failed"; }
    wheel=$(ls "$py"/wheel/bsf-"$version"-*.whl) || fail "no bsf-$version wheel"
    echo "$(basename "$sdist") ($(tar -tzf "$sdist" | grep -c '/csrc/.*[^/]$') library files in csrc/) -> $(basename "$wheel")"

    step "Python: the wheel in a fresh venv, the package's tests against it"
    python3 -m venv "$py/venv"
    "$py/venv/bin/pip" install -q --disable-pip-version-check \
        -c "$src/tools/python/tests/requirements-ci.txt" "$wheel[plot,rosbag,serial,test]"
    # The sdist's own tests, away from any source of the package: only the
    # installed wheel can be imported.
    [ -f "$py/alone/$name/tests/conftest.py" ] || fail "the sdist carries no tests/conftest.py"
    cp -r "$py/alone/$name/tests" "$py/tests"
    (cd "$py" && "$py/venv/bin/python" - "$version" "$py/venv" << 'EOF'
import sys
import bsf
version, venv = sys.argv[1], sys.argv[2]
assert bsf.__file__.startswith(venv), f"bsf imported from {bsf.__file__}, not the venv"
assert bsf.__version__ == version, f"bsf.__version__ {bsf.__version__} != {version}"
print(f"import bsf: {bsf.__version__} from {bsf.__file__}")
EOF
    )
    local shared="${BSF_SHARED_DIR:-$here/../shared}"
    (cd "$py/tests" && BSF_SHARED_DIR="$shared" BSF_TOOL="$bld/tools/bsf" BSF_PYTEST_REQUIRE_TOOL=1 \
        timeout 900 "$py/venv/bin/pytest" -q -rs -p no:cacheprovider .)
}

live_block() { # the indented command block of $1 that makes the FIFO, unindented
    awk '/^    /{b=b substr($0,5) "\n"; next} {if(b ~ /mkfifo/){printf "%s", b; done=1; exit} b=""}
         END{if(!done && b ~ /mkfifo/) printf "%s", b}' "$1"
}

do_live() {
    local elf="$here/build-m4/port/examples/uart_stream/uart_stream.elf" cmd run out="$work/live"
    step "live link as docs/PORTING.md runs it, twice in a row"
    if [ ! -f "$elf" ] || ! command -v qemu-system-arm > /dev/null; then
        echo "SKIPPED: needs $elf (the Cortex-M4F build) and qemu-system-arm"
        return
    fi
    cmd=$(live_block docs/PORTING.md)
    [ -n "$cmd" ] || fail "docs/PORTING.md has no command block with mkfifo"
    printf '%s\n' "$cmd" | sed 's/^/    /'
    mkdir -p "$out"
    # From the checkout (the block names build/ and build-m4/); its live.bsf is ignored by git.
    for run in 1 2; do
        bash -euo pipefail -c "$cmd" > "$out/listen$run.txt" 2> "$out/listen$run.err" ||
            { cat "$out/listen$run.err"; fail "live link run $run failed"; }
        grep -q "^counters: frames ok 63, bad crc 0" "$out/listen$run.txt" ||
            { cat "$out/listen$run.txt"; fail "live link run $run: not 63 clean frames"; }
    done
    grep -E "^(metadata|frame|counters)" "$out/listen1.txt" > "$out/lines1.txt"
    grep -E "^(metadata|frame|counters)" "$out/listen2.txt" > "$out/lines2.txt"
    cmp "$out/lines1.txt" "$out/lines2.txt" || fail "the two live runs printed different frames"
    sed -n 1,2p "$out/lines1.txt"
    tail -n 1 "$out/lines1.txt"
    echo "two runs in a row, 63 clean frames each, the same lines"
}

steps=("$@")
[ ${#steps[@]} -gt 0 ] || steps=(gitignore archive offline python live)
for s in "${steps[@]}"; do
    case $s in
    gitignore | archive | offline | python | live) "do_$s" ;;
    *) fail "unknown step $s (gitignore archive offline python live)" ;;
    esac
done
step "done: ${steps[*]}"
