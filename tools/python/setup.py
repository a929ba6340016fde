# SPDX-License-Identifier: MIT
"""Build of the bsf extension: the library's own C sources, compiled as they are.

In a checkout the sources are read from the repository around this package
(../../src, ../../include, ../../port, ../carmen and ../caps), never copied
into it: ``pip install ./tools/python``. An sdist (``python -m build``) must
build on its own, so the sdist command puts those files into the archive
under ``csrc/`` (same layout as the repository), and a build from the sdist
reads them there. The checkout never holds a copy.

The caps are the host caps of tools/caps/bsf_host_caps.h, the same as the
``bsf`` tool's (4096-beam scans); the library's default caps in
include/bsf/bsf_config.h stay as they are for firmware. A cap can still be
raised for one build with an environment variable of the same name prefixed
BSF_PY_, e.g. ``BSF_PY_MAX_POINTS=8192 pip install ./tools/python`` (a tool
built with other caps then refuses what exceeds its own).
"""
import os
import re
import shutil
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.sdist import sdist

HERE = Path(__file__).resolve().parent
BUNDLED = HERE / "csrc"


def _has_library(root):
    return (root / "src" / "bsf_extract.c").is_file() and (root / "include" / "bsf" / "bsf.h").is_file()


# An sdist carries the sources in csrc/; a checkout has them two levels up.
ROOT = BUNDLED if _has_library(BUNDLED) else HERE.parent.parent
if not _has_library(ROOT):
    sys.exit(
        f"bsf: the library sources are neither in {BUNDLED} (an sdist) nor in {HERE.parent.parent} (a checkout).\n"
        "Build this package from a bsf checkout (pip install ./tools/python) or from its sdist."
    )
SRC = ROOT / "src"
INCLUDE = ROOT / "include"
PORT = ROOT / "port"
TOOLS = ROOT / "tools"
HOST_CAPS = TOOLS / "caps" / "bsf_host_caps.h"

# What the extension compiles and includes, relative to ROOT (globs): the
# sdist copies exactly these.
LIBRARY_FILES = (
    "LICENSE",
    "src/*.c",
    "src/*.h",
    "include/bsf/*.h",
    "port/bsf_port_clock.h",
    "port/host/bsf_port_clock_posix.c",
    "tools/carmen/carmen.c",
    "tools/carmen/carmen.h",
    "tools/carmen/carmen_number.h",
    "tools/caps/bsf_host_caps.h",
)


def _version():
    text = (INCLUDE / "bsf" / "bsf_version.h").read_text(encoding="utf-8")
    m = re.search(r'^#define BSF_VERSION_STRING "([0-9]+\.[0-9]+\.[0-9]+)"', text, re.M)
    if not m:
        sys.exit(f"bsf: no BSF_VERSION_STRING in {INCLUDE / 'bsf' / 'bsf_version.h'}")
    return m.group(1)


def _host_caps():
    text = HOST_CAPS.read_text(encoding="utf-8")
    caps = {}
    for name in ("MAX_POINTS", "MAX_KEYPOINTS", "MAX_SEGMENTS", "MAX_CTRL_POINTS"):
        m = re.search(rf"^#define BSF_{name} ([1-9][0-9]*)$", text, re.M)
        if not m:
            sys.exit(f"bsf: {HOST_CAPS} defines no BSF_{name}")
        caps[name] = int(m.group(1))
    return caps


CAPS = _host_caps()
for name in list(CAPS):
    env = os.environ.get("BSF_PY_" + name)
    if env:
        if not re.fullmatch(r"[1-9][0-9]*", env):
            sys.exit(f"bsf: BSF_PY_{name}={env!r} is not a positive decimal number")
        CAPS[name] = int(env)


def _sources():
    # Relative to this directory, as setup() requires.
    files = sorted(SRC.glob("*.c")) + [
        PORT / "host" / "bsf_port_clock_posix.c",
        TOOLS / "carmen" / "carmen.c",
        HERE / "bsf" / "_core.c",
    ]
    return [os.path.relpath(p, HERE).replace(os.sep, "/") for p in files]


class BuildExt(build_ext):
    """Compile from absolute paths: setuptools names each object file after
    its source path under build/temp*, and "../../src/x.c" would put the
    objects outside it (into the source tree)."""

    def build_extension(self, ext):
        ext.sources = [str((HERE / s).resolve()) for s in ext.sources]
        super().build_extension(ext)


class SdistWithLibrary(sdist):
    """The sdist carries the library's sources in csrc/, so that it builds
    without the repository around it."""

    def make_release_tree(self, base_dir, files):
        # setuptools lists the extension's sources as they are named
        # (../../src/...), which would be copied outside the release tree:
        # they go into csrc/ below instead.
        files = [f for f in files if not os.path.normpath(f).startswith(os.pardir)]
        super().make_release_tree(base_dir, files)
        copied = 0
        for pattern in LIBRARY_FILES:
            matches = sorted(ROOT.glob(pattern))
            if not matches:
                raise SystemExit(f"bsf sdist: nothing matches {pattern} under {ROOT}")
            for path in matches:
                dest = Path(base_dir, "csrc", path.relative_to(ROOT))
                dest.parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(path, dest)
                copied += 1
        # The licence beside PKG-INFO too, where readers of an sdist look.
        shutil.copy2(ROOT / "LICENSE", Path(base_dir, "LICENSE"))
        print(f"bsf sdist: {copied} library files into csrc/", file=sys.stderr)


def _zlib_available():
    # The CARMEN reader uses zlib when present, else the system's gzip.
    import sysconfig

    dirs = [sysconfig.get_paths().get("include", ""), "/usr/include", "/usr/local/include"]
    return any(Path(d, "zlib.h").is_file() for d in dirs if d)


define_macros = [("BSF_" + k, str(v)) for k, v in CAPS.items()]
libraries = ["m"]
if _zlib_available():
    define_macros.append(("BSF_HAVE_ZLIB", "1"))
    libraries.append("z")

extra_compile_args = []
if os.name != "nt":
    # The same float semantics as the C build (src/CMakeLists.txt): no fused
    # multiply-add contraction, so results equal the bsf tool's bit for bit.
    extra_compile_args = ["-std=c99", "-ffp-contract=off", "-fno-fast-math"]

setup(
    version=_version(),
    cmdclass={"build_ext": BuildExt, "sdist": SdistWithLibrary},
    ext_modules=[
        Extension(
            "bsf._core",
            sources=_sources(),
            include_dirs=[str(INCLUDE), str(PORT), str(TOOLS / "carmen")],
            define_macros=define_macros,
            libraries=libraries,
            extra_compile_args=extra_compile_args,
        )
    ],
)
