# SPDX-License-Identifier: MIT
# The consumer tests (registered by tests.cmake), one MODE per way a user
# adds bsf. Run by CTest as `cmake -D... -P consumer_test.cmake`. A test that
# lacks a tool it needs prints "SKIPPED: <why>" (CTest shows it as Skipped).
#
#   install_static  install this build tree (static libbsf) into WORK_DIR/static
#   install_shared  configure, build and install a shared libbsf from the
#                   source tree into WORK_DIR/shared (library only)
#   find_package    test/consumer/CMakeLists.txt against PREFIX
#   pkgconfig       test/consumer/Makefile with make + pkg-config against PREFIX
#   subdirectory    test/consumer/parent: add_subdirectory(bsf), strict warnings
#   copy_sources    src/ and include/ copied into a plain compiler command
#   caps_mismatch   a program compiled with other caps than PREFIX's library
#   exports         the shared library exports exactly the public API
cmake_minimum_required(VERSION 3.22)

function(run_checked what)
    execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
    endif()
    set(run_out "${out}" PARENT_SCOPE)
endfunction()

# Runs the consumer executable and checks it reports success.
function(run_consumer exe)
    run_checked("running ${exe}" ${exe})
    if(NOT run_out MATCHES "^bsf [0-9]+\\.[0-9]+\\.[0-9]+: [1-9][0-9]* feature")
        message(FATAL_ERROR "${exe} printed an unexpected line: ${run_out}")
    endif()
    message(STATUS "${exe}: ${run_out}")
endfunction()

function(require_prefix)
    if(NOT EXISTS "${PREFIX}/include/bsf/bsf.h")
        message(FATAL_ERROR "no installed bsf in ${PREFIX} (the install fixture failed?)")
    endif()
endfunction()

set(strict -std=c99 -Wall -Wextra -pedantic -Wconversion -Wshadow -Wstrict-prototypes -Werror)

# LIB_CAPS: the caps the library under test was built with (BSF_CAPS),
# comma-separated.
string(REPLACE "," ";" LIB_CAPS "${LIB_CAPS}")
set(lib_defs)
foreach(cap IN LISTS LIB_CAPS)
    list(APPEND lib_defs -D${cap})
endforeach()

# The symbol suffix (bsf_abi.h) for the default caps overridden by the
# NAME=VALUE pairs given.
function(caps_suffix out)
    set(BSF_MAX_POINTS 1081)
    set(BSF_MAX_KEYPOINTS 64)
    set(BSF_MAX_SEGMENTS 128)
    set(BSF_MAX_CTRL_PER_FEATURE 32)
    set(BSF_MAX_CTRL_POINTS 512)
    foreach(cap IN LISTS ARGN)
        string(REPLACE "=" ";" cap "${cap}")
        list(GET cap 0 name)
        list(GET cap 1 value)
        set(${name} ${value})
    endforeach()
    set(${out} "capsP${BSF_MAX_POINTS}K${BSF_MAX_KEYPOINTS}S${BSF_MAX_SEGMENTS}F${BSF_MAX_CTRL_PER_FEATURE}C${BSF_MAX_CTRL_POINTS}" PARENT_SCOPE)
endfunction()

if(MODE STREQUAL "install_static")
    file(REMOVE_RECURSE "${WORK_DIR}")
    run_checked("cmake --install" "${CMAKE_COMMAND}" --install "${BSF_BINARY_DIR}" --prefix "${WORK_DIR}")
    foreach(f include/bsf/bsf.h include/bsf/bsf_version.h include/bsf/port/bsf_port_clock.h
            ${LIBDIR}/pkgconfig/bsf.pc ${LIBDIR}/cmake/bsf/bsfConfig.cmake ${LIBDIR}/libbsf.a
            ${LIBDIR}/libbsf_port.a
            share/bsf/port/bsf_port_clock_posix.c share/bsf/port/bsf_port_clock_cortex_m.c)
        if(NOT EXISTS "${WORK_DIR}/${f}")
            message(FATAL_ERROR "installed tree lacks ${f}")
        endif()
    endforeach()
    message(STATUS "installed into ${WORK_DIR}")

elseif(MODE STREQUAL "install_shared")
    file(REMOVE_RECURSE "${WORK_DIR}")
    run_checked("configure shared bsf" "${CMAKE_COMMAND}" -S "${BSF_SOURCE_DIR}" -B "${WORK_DIR}/build"
        -G "${GENERATOR}" -DCMAKE_C_COMPILER=${C_COMPILER} -DCMAKE_BUILD_TYPE=Release
        -DBUILD_SHARED_LIBS=ON -DBSF_BUILD_TESTS=OFF -DBSF_BUILD_TOOLS=OFF
        -DCMAKE_INSTALL_LIBDIR=lib "-DBSF_CAPS=${LIB_CAPS}")
    run_checked("build shared bsf" "${CMAKE_COMMAND}" --build "${WORK_DIR}/build" -j 2)
    run_checked("install shared bsf" "${CMAKE_COMMAND}" --install "${WORK_DIR}/build" --prefix "${WORK_DIR}/prefix")
    foreach(f lib/libbsf.so lib/libbsf.so.${SOVERSION} lib/pkgconfig/bsf.pc)
        if(NOT EXISTS "${WORK_DIR}/prefix/${f}")
            message(FATAL_ERROR "shared install lacks ${f}")
        endif()
    endforeach()
    message(STATUS "shared libbsf installed into ${WORK_DIR}/prefix")

elseif(MODE STREQUAL "find_package")
    require_prefix()
    file(REMOVE_RECURSE "${WORK_DIR}")
    run_checked("consumer configure" "${CMAKE_COMMAND}" -S "${CONSUMER_SOURCE_DIR}" -B "${WORK_DIR}"
        -G "${GENERATOR}" -DCMAKE_C_COMPILER=${C_COMPILER} -DCMAKE_PREFIX_PATH=${PREFIX}
        -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
    run_checked("consumer build" "${CMAKE_COMMAND}" --build "${WORK_DIR}")
    run_consumer("${WORK_DIR}/consumer")

elseif(MODE STREQUAL "pkgconfig")
    require_prefix()
    find_program(PKG_CONFIG NAMES pkg-config pkgconf)
    find_program(MAKE NAMES make gmake)
    if(NOT PKG_CONFIG OR NOT MAKE)
        message("SKIPPED: needs pkg-config and make on PATH (pkg-config: ${PKG_CONFIG}, make: ${MAKE})")
        return()
    endif()
    set(ENV{PKG_CONFIG_PATH} "${PREFIX}/${LIBDIR}/pkgconfig")
    unset(ENV{PKG_CONFIG_LIBDIR})
    # The .pc must lead to where it was installed, not to CMAKE_INSTALL_PREFIX.
    run_checked("pkg-config --variable=prefix" ${PKG_CONFIG} --variable=prefix bsf)
    string(STRIP "${run_out}" pc_prefix)
    get_filename_component(pc_prefix "${pc_prefix}" REALPATH)
    get_filename_component(real_prefix "${PREFIX}" REALPATH)
    if(NOT pc_prefix STREQUAL real_prefix)
        message(FATAL_ERROR "bsf.pc says prefix ${pc_prefix}, installed in ${real_prefix}")
    endif()
    file(REMOVE_RECURSE "${WORK_DIR}")
    file(MAKE_DIRECTORY "${WORK_DIR}")
    # As the README says: plain `pkg-config --cflags --libs bsf`.
    run_checked("make" ${MAKE} -C "${CONSUMER_SOURCE_DIR}" -f Makefile CC=${C_COMPILER}
        PKG_CONFIG=${PKG_CONFIG} OUT=${WORK_DIR}/consumer)
    if(SHARED)
        # Runs from the prefix without rpath: the loader finds the SONAME there.
        set(ENV{LD_LIBRARY_PATH} "${PREFIX}/${LIBDIR}")
        run_checked("readelf" ${READELF} -d "${WORK_DIR}/consumer")
        if(NOT run_out MATCHES "NEEDED[^\n]*libbsf\\.so\\.${SOVERSION}\\]")
            message(FATAL_ERROR "consumer does not need libbsf.so.${SOVERSION}:\n${run_out}")
        endif()
    endif()
    run_consumer("${WORK_DIR}/consumer")
    # And the --static route (what a static-only distribution uses).
    run_checked("make --static" ${MAKE} -C "${CONSUMER_SOURCE_DIR}" -f Makefile CC=${C_COMPILER}
        PKG_CONFIG=${PKG_CONFIG} PKG_CONFIG_FLAGS=--static OUT=${WORK_DIR}/consumer_static_flags)
    run_consumer("${WORK_DIR}/consumer_static_flags")

elseif(MODE STREQUAL "subdirectory")
    file(REMOVE_RECURSE "${WORK_DIR}")
    run_checked("parent configure" "${CMAKE_COMMAND}" -S "${CONSUMER_SOURCE_DIR}/parent" -B "${WORK_DIR}"
        -G "${GENERATOR}" -DCMAKE_C_COMPILER=${C_COMPILER} -DBSF_SOURCE_DIR=${BSF_SOURCE_DIR})
    file(READ "${WORK_DIR}/bsf/cmake_install.cmake" inst)
    if(inst MATCHES "libbsf|bsf\\.pc|bsfConfig")
        message(FATAL_ERROR "bsf added install rules to the parent (BSF_INSTALL should be OFF)")
    endif()
    run_checked("parent build" "${CMAKE_COMMAND}" --build "${WORK_DIR}" -j 2)
    run_consumer("${WORK_DIR}/parent_app")

elseif(MODE STREQUAL "copy_sources")
    # As the README's "Copy the sources" section: every flag it names.
    file(REMOVE_RECURSE "${WORK_DIR}")
    file(COPY "${BSF_SOURCE_DIR}/src" "${BSF_SOURCE_DIR}/include" DESTINATION "${WORK_DIR}")
    file(GLOB lib_sources "${WORK_DIR}/src/*.c")
    run_checked("plain compile" ${C_COMPILER} ${strict} -O2 -ffp-contract=off
        -I${WORK_DIR}/include ${lib_sources} ${CONSUMER_SOURCE_DIR}/main.c -lm
        -o ${WORK_DIR}/consumer)
    run_consumer("${WORK_DIR}/consumer")

elseif(MODE STREQUAL "caps_mismatch")
    require_prefix()
    file(REMOVE_RECURSE "${WORK_DIR}")
    file(MAKE_DIRECTORY "${WORK_DIR}")
    set(link -I${PREFIX}/include ${CONSUMER_SOURCE_DIR}/main.c -L${PREFIX}/${LIBDIR} -lbsf -lm
        -Wl,-rpath,${PREFIX}/${LIBDIR})
    # Control: the library's own caps link and run.
    run_checked("matching caps" ${C_COMPILER} ${strict} ${lib_defs} ${link} -o ${WORK_DIR}/same)
    run_consumer("${WORK_DIR}/same")
    # Other caps on the command line, then in a BSF_CONFIG_HEADER: the link
    # must refuse, naming the program's caps.
    if(LIB_CAPS)
        set(other_defs "")
        caps_suffix(other_expect)
    else()
        set(other_defs -DBSF_MAX_POINTS=361)
        caps_suffix(other_expect BSF_MAX_POINTS=361)
    endif()
    file(WRITE "${WORK_DIR}/my_bsf_config.h" "#define BSF_MAX_SEGMENTS 32\n")
    caps_suffix(header_expect ${LIB_CAPS} BSF_MAX_SEGMENTS=32)
    foreach(case other header)
        if(case STREQUAL "other")
            set(defs ${other_defs})
            set(expect ${other_expect})
            set(what "the default caps")
            if(other_defs)
                set(what "${other_defs}")
            endif()
        else()
            set(defs ${lib_defs} "-DBSF_CONFIG_HEADER=\"my_bsf_config.h\"")
            set(expect ${header_expect})
            set(what "a BSF_CONFIG_HEADER setting BSF_MAX_SEGMENTS 32")
        endif()
        execute_process(COMMAND ${C_COMPILER} ${strict} ${defs} -I${WORK_DIR} ${link}
                -o ${WORK_DIR}/mismatched
            RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
        if(rc EQUAL 0)
            message(FATAL_ERROR "a program built with ${what} linked against a library built "
                "with [${LIB_CAPS}] (empty: the defaults)")
        endif()
        if(NOT "${out}${err}" MATCHES "undefined reference to `bsf_[a-z_]+_${expect}'"
                AND NOT "${out}${err}" MATCHES "undefined symbol: _?bsf_[a-z_]+_${expect}")
            message(FATAL_ERROR "the link of a program built with ${what} failed, but not with "
                "the documented message (undefined reference to bsf_..._${expect}):\n${out}${err}")
        endif()
        message(STATUS "${what}: link refused as documented (bsf_..._${expect} undefined)")
    endforeach()

elseif(MODE STREQUAL "exports")
    require_prefix()
    # What the public headers declare, after preprocessing (so with the
    # symbol names the caps guard gives them).
    file(REMOVE_RECURSE "${WORK_DIR}")
    file(WRITE "${WORK_DIR}/api.c" "#include <bsf/bsf.h>\n")
    run_checked("preprocess" ${C_COMPILER} -E -P ${lib_defs} -I${PREFIX}/include "${WORK_DIR}/api.c")
    string(REGEX MATCHALL "bsf_[A-Za-z0-9_]+[ \t]*\\(" decl "${run_out}")
    list(TRANSFORM decl REPLACE "[ \t]*\\($" "")
    list(REMOVE_DUPLICATES decl)
    list(SORT decl)
    run_checked("nm -D" ${NM} -D --defined-only "${PREFIX}/${LIBDIR}/libbsf.so")
    string(REGEX MATCHALL "[ \t][TtWw][ \t]+[A-Za-z_][A-Za-z0-9_]*" exported "${run_out}")
    list(TRANSFORM exported REPLACE "^[ \t][TtWw][ \t]+" "")
    list(REMOVE_DUPLICATES exported)
    list(SORT exported)
    set(extra ${exported})
    list(REMOVE_ITEM extra ${decl})
    set(missing ${decl})
    list(REMOVE_ITEM missing ${exported})
    if(extra OR missing)
        message(FATAL_ERROR "libbsf.so exports what the headers do not declare: [${extra}]\n"
            "and lacks what they declare: [${missing}]")
    endif()
    list(LENGTH decl n)
    if(n LESS 40)
        message(FATAL_ERROR "only ${n} public functions found in the headers: parsing broke?")
    endif()
    run_checked("readelf -d" ${READELF} -d "${PREFIX}/${LIBDIR}/libbsf.so")
    if(NOT run_out MATCHES "SONAME[^\n]*\\[libbsf\\.so\\.${SOVERSION}\\]")
        message(FATAL_ERROR "libbsf.so has no versioned SONAME:\n${run_out}")
    endif()
    message(STATUS "libbsf.so (SONAME libbsf.so.${SOVERSION}) exports exactly the ${n} public functions")

else()
    message(FATAL_ERROR "unknown MODE '${MODE}'")
endif()
