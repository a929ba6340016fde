# SPDX-License-Identifier: MIT
"""Build of the bsf extension: the library's own C sources, compiled in place.

The sources are read from the repository around this package (../../src,
../../include, ../../port and ../carmen/carmen.c), never copied, so the package
must be built from a checkout: ``pip install ./tools/python`` (pip >= 21.3
builds in the source tree). An sdist of this directory alone cannot build
and says so below.

The caps are raised for host use (4096-beam scans); the library's default
caps in include/bsf/bsf_config.h stay as they are for firmware. Override them
with environment variables of the same name prefixed BSF_PY_, e.g.
``BSF_PY_MAX_POINTS=8192 pip install ./tools/python``.
"""
import os
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
SRC = ROOT / "src"
INCLUDE = ROOT / "include"
PORT = ROOT / "port"
TOOLS = ROOT / "tools"

if not (SRC / "bsf_extract.c").is_file() or not (INCLUDE / "bsf" / "bsf.h").is_file():
    sys.exit(
        f"bsf: the library sources are not at {SRC} and {INCLUDE}.\n"
        "Build this package from a bsf checkout: pip install ./tools/python "
        "(pip >= 21.3 builds in place; an sdist or a copy of tools/python alone cannot build)."
    )

# Host caps: 4096 beams, and room for the keypoints, segments and control
# points such a scan can produce. BSF_MAX_CTRL_PER_FEATURE keeps the library
# default so that results are identical to the C tool's on the same scan.
CAPS = {
    "MAX_POINTS": 4096,
    "MAX_KEYPOINTS": 512,
    "MAX_SEGMENTS": 1024,
    "MAX_CTRL_POINTS": 8192,
}
for name in list(CAPS):
    env = os.environ.get("BSF_PY_" + name)
    if env:
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
    cmdclass={"build_ext": BuildExt},
    ext_modules=[
        Extension(
            "bsf._core",
            sources=_sources(),
            include_dirs=[str(INCLUDE), str(PORT), str(TOOLS / "carmen")],
            define_macros=define_macros,
            libraries=libraries,
            extra_compile_args=extra_compile_args,
        )
    ]
)
