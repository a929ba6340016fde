# SPDX-License-Identifier: MIT
# Provides the target `unity` (ThrowTheSwitch Unity 2.6.1, MIT licence).
#
# Unity is never part of this repository. In order of preference:
#  1. UNITY_SOURCE_DIR: a directory holding unity.c, unity.h and
#     unity_internals.h (an upstream checkout's src/ or its top level).
#  2. BSF_UNITY_WHEEL: a local copy of the wheel below (offline builds).
#  3. The PyPI wheel vyperling==0.0.4, downloaded by pip with a pinned hash.
#     It carries Unity v2.6.1's three source files byte for byte; the wheel's
#     and every extracted file's SHA-256 are checked before use.

set(UNITY_SOURCE_DIR "" CACHE PATH "Directory with Unity's unity.c/unity.h/unity_internals.h (skips the download)")
set(BSF_UNITY_WHEEL "" CACHE FILEPATH "Local vyperling-0.0.4-py3-none-any.whl (skips the download)")

set(_unity_wheel_name "vyperling-0.0.4-py3-none-any.whl")
set(_unity_wheel_sha256 "028f4419cf4f49cfaed51256290718753a78cc035923fbf43acc8bcd62d205cb")
set(_unity_sha256_unity.c "b90e735a54cf3b3765ab6caa955d11a1488ee73d9c6152cdc98576c2d17cb871")
set(_unity_sha256_unity.h "9db174d3c2c6424fd35c0980c5941d124c5ebb0f48e8172f997a2aa9554b64ea")
set(_unity_sha256_unity_internals.h "fcd8b3f6b412ac0ab599547eb8a30b6d7f3f0af77aab31f7a1822a2a8fc9a2b2")

set(_unity_help "
Unity 2.6.1 (the unit-test framework) is fetched at configure time and could not be obtained.
Do one of these, then configure again:
  * let pip reach PyPI:  python3 -m pip --version  must work (Debian: apt-get install python3-pip);
  * or download it once and point the build at it:
      python3 -m pip download --no-deps vyperling==0.0.4 -d /some/dir
      cmake -DBSF_UNITY_WHEEL=/some/dir/${_unity_wheel_name} ...
  * or use a Unity v2.6.1 checkout:  cmake -DUNITY_SOURCE_DIR=/path/to/Unity/src ...
  * or build without tests:  cmake -DBSF_BUILD_TESTS=OFF ...")

function(_bsf_unity_check_file path expected)
    file(SHA256 "${path}" _actual)
    if(NOT _actual STREQUAL expected)
        message(FATAL_ERROR "Unity: SHA-256 mismatch for ${path}\n  expected ${expected}\n  got      ${_actual}${_unity_help}")
    endif()
endfunction()

if(UNITY_SOURCE_DIR)
    if(EXISTS "${UNITY_SOURCE_DIR}/src/unity.c")
        set(_unity_dir "${UNITY_SOURCE_DIR}/src")
    else()
        set(_unity_dir "${UNITY_SOURCE_DIR}")
    endif()
    foreach(f unity.c unity.h unity_internals.h)
        if(NOT EXISTS "${_unity_dir}/${f}")
            message(FATAL_ERROR "UNITY_SOURCE_DIR=${UNITY_SOURCE_DIR} has no ${f}.${_unity_help}")
        endif()
    endforeach()
    message(STATUS "Unity: using sources in ${_unity_dir}")
else()
    set(_unity_root "${PROJECT_BINARY_DIR}/_deps/unity")
    set(_unity_dir "${_unity_root}/vyperling/c")
    set(_have 1)
    foreach(f unity.c unity.h unity_internals.h)
        if(EXISTS "${_unity_dir}/${f}")
            file(SHA256 "${_unity_dir}/${f}" _h)
            if(NOT _h STREQUAL "${_unity_sha256_${f}}")
                set(_have 0)
            endif()
        else()
            set(_have 0)
        endif()
    endforeach()
    if(NOT _have)
        if(BSF_UNITY_WHEEL)
            set(_wheel "${BSF_UNITY_WHEEL}")
        else()
            set(_wheel "${_unity_root}/${_unity_wheel_name}")
            if(NOT EXISTS "${_wheel}")
                find_package(Python3 COMPONENTS Interpreter)
                if(NOT Python3_Interpreter_FOUND)
                    message(FATAL_ERROR "Unity: no python3 found to run pip.${_unity_help}")
                endif()
                file(WRITE "${_unity_root}/requirements.txt"
                    "vyperling==0.0.4 --hash=sha256:${_unity_wheel_sha256}\n")
                message(STATUS "Unity: downloading ${_unity_wheel_name} from PyPI (hash-pinned)")
                execute_process(
                    COMMAND ${Python3_EXECUTABLE} -m pip download --no-deps --require-hashes
                            --only-binary=:all: -r "${_unity_root}/requirements.txt" -d "${_unity_root}"
                    RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err)
                if(NOT _rc EQUAL 0 OR NOT EXISTS "${_wheel}")
                    message(FATAL_ERROR "Unity: pip download failed (${_rc}):\n${_err}${_unity_help}")
                endif()
            endif()
        endif()
        _bsf_unity_check_file("${_wheel}" "${_unity_wheel_sha256}")
        file(ARCHIVE_EXTRACT INPUT "${_wheel}" DESTINATION "${_unity_root}"
            PATTERNS vyperling/c/unity.c vyperling/c/unity.h vyperling/c/unity_internals.h)
    endif()
    foreach(f unity.c unity.h unity_internals.h)
        if(NOT EXISTS "${_unity_dir}/${f}")
            message(FATAL_ERROR "Unity: ${f} missing from the wheel.${_unity_help}")
        endif()
        _bsf_unity_check_file("${_unity_dir}/${f}" "${_unity_sha256_${f}}")
    endforeach()
    message(STATUS "Unity: 2.6.1 from PyPI wheel vyperling==0.0.4, hashes verified")
endif()

add_library(unity STATIC "${_unity_dir}/unity.c")
target_include_directories(unity SYSTEM PUBLIC "${_unity_dir}")
target_compile_definitions(unity PUBLIC UNITY_SUPPORT_64)
