# SPDX-License-Identifier: MIT
# CMake toolchain file: IBM Z (s390x) Linux, big-endian, cross-compiled with
# Debian's gcc-s390x-linux-gnu; tests run under qemu-user. It exists to check
# that bsf gives byte-identical frames on a big-endian target:
#
#   cmake -S . -B build-s390x -DCMAKE_TOOLCHAIN_FILE=port/s390x-linux.cmake
#   cmake --build build-s390x && ctest --test-dir build-s390x
#
# Every test that needs an operating system runs here too (the tool, the
# CARMEN reader, the fuzz corpus replays): BSF_BUILD_TOOLS is ON by default on
# a hosted target. Without an s390x zlib the reader reads .gz logs through the
# system's `gzip -dc` (qemu-user starts the host's gzip), so no more packages.
#
# Needs: gcc-s390x-linux-gnu libc6-dev-s390x-cross qemu-user (the first two
# conflict with gcc-multilib). GCC on s390x evaluates float in double in ISO C
# mode; cmake/BsfFloatEval.cmake adds -fexcess-precision=fast for that.

set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR s390x)

set(BSF_S390X_PREFIX "s390x-linux-gnu-" CACHE STRING "Prefix of the s390x cross toolchain binaries")
set(CMAKE_C_COMPILER ${BSF_S390X_PREFIX}gcc)
set(CMAKE_AR ${BSF_S390X_PREFIX}ar CACHE FILEPATH "")
set(CMAKE_RANLIB ${BSF_S390X_PREFIX}ranlib CACHE FILEPATH "")

set(BSF_S390X_SYSROOT "/usr/s390x-linux-gnu" CACHE PATH "Target libraries (libc6-dev-s390x-cross)")
set(CMAKE_FIND_ROOT_PATH ${BSF_S390X_SYSROOT})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

find_program(BSF_QEMU_S390X qemu-s390x)
if(BSF_QEMU_S390X)
    set(CMAKE_CROSSCOMPILING_EMULATOR ${BSF_QEMU_S390X} -L ${BSF_S390X_SYSROOT})
endif()
