# SPDX-License-Identifier: MIT
# Consumer tests: a downstream program (main.c) built and run each way a
# user adds bsf, plus the caps guard and the shared library's exports. Each
# is quick (a few seconds); see consumer_test.cmake for what each MODE does.
# Included from test/CMakeLists.txt on host builds.
#
#   consumer_find_package         find_package(bsf CONFIG), static install
#   consumer_find_package_shared  find_package(bsf CONFIG), shared install with other caps
#   consumer_pkgconfig_static     Makefile + pkg-config, static install
#   consumer_pkgconfig_shared     Makefile + pkg-config, shared install with other caps
#   consumer_subdirectory         add_subdirectory(bsf) from a strict parent
#   consumer_copy_sources         src/ + include/ in a plain compiler command
#   consumer_caps_mismatch        other caps than the installed library: link refused
#   consumer_shared_exports       libbsf.so: versioned SONAME, only the public API
set(_bsf_consumer_dir ${CMAKE_CURRENT_LIST_DIR})
set(_bsf_consumer_work ${CMAKE_CURRENT_BINARY_DIR}/consumer)
if(PROJECT_VERSION_MAJOR EQUAL 0)
    set(_bsf_soversion ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
else()
    set(_bsf_soversion ${PROJECT_VERSION_MAJOR})
endif()
set(_bsf_consumer_args
    -DBSF_SOURCE_DIR=${PROJECT_SOURCE_DIR}
    -DBSF_BINARY_DIR=${PROJECT_BINARY_DIR}
    -DCONSUMER_SOURCE_DIR=${_bsf_consumer_dir}
    -DC_COMPILER=${CMAKE_C_COMPILER}
    -DGENERATOR=${CMAKE_GENERATOR}
    -DNM=${CMAKE_NM}
    -DREADELF=${CMAKE_READELF}
    -DSOVERSION=${_bsf_soversion})
# The shared library is built with other caps than the default, so the
# shared consumers also prove that the caps travel with the package.
set(_bsf_shared_caps BSF_MAX_POINTS=361)
string(REPLACE ";" "," _bsf_shared_caps_arg "${_bsf_shared_caps}")
set(_bsf_static_prefix ${_bsf_consumer_work}/static)
set(_bsf_shared_prefix ${_bsf_consumer_work}/shared/prefix)

# bsf_consumer_test(NAME MODE [PREFIX dir LIBDIR dir] [SHARED] [FIXTURES f...])
function(bsf_consumer_test name mode)
    cmake_parse_arguments(C "SHARED" "PREFIX;LIBDIR" "FIXTURES" ${ARGN})
    set(extra)
    if(C_SHARED)
        list(APPEND extra -DSHARED=1 -DLIB_CAPS=${_bsf_shared_caps_arg})
    endif()
    add_test(NAME ${name}
        COMMAND ${CMAKE_COMMAND} ${_bsf_consumer_args} -DMODE=${mode}
            -DWORK_DIR=${_bsf_consumer_work}/${name} -DPREFIX=${C_PREFIX} -DLIBDIR=${C_LIBDIR}
            ${extra} -P ${_bsf_consumer_dir}/consumer_test.cmake)
    set_tests_properties(${name} PROPERTIES TIMEOUT 120 SKIP_REGULAR_EXPRESSION "SKIPPED:"
        LABELS consumer)
    if(C_FIXTURES)
        set_tests_properties(${name} PROPERTIES FIXTURES_REQUIRED "${C_FIXTURES}")
    endif()
endfunction()

# The static install (a fixture: CTest runs it before the tests that need it).
add_test(NAME consumer_install_static
    COMMAND ${CMAKE_COMMAND} ${_bsf_consumer_args} -DMODE=install_static
        -DWORK_DIR=${_bsf_static_prefix} -DLIBDIR=${CMAKE_INSTALL_LIBDIR}
        -P ${_bsf_consumer_dir}/consumer_test.cmake)
set_tests_properties(consumer_install_static PROPERTIES TIMEOUT 120 FIXTURES_SETUP bsf_static
    LABELS consumer)
set(_st PREFIX ${_bsf_static_prefix} LIBDIR ${CMAKE_INSTALL_LIBDIR} FIXTURES bsf_static)
set(_sh PREFIX ${_bsf_shared_prefix} LIBDIR lib SHARED FIXTURES bsf_shared)
bsf_consumer_test(consumer_find_package find_package ${_st})
bsf_consumer_test(consumer_pkgconfig_static pkgconfig ${_st})
bsf_consumer_test(consumer_subdirectory subdirectory)
bsf_consumer_test(consumer_copy_sources copy_sources)
bsf_consumer_test(consumer_caps_mismatch caps_mismatch ${_st})

# The shared-library routes: ELF (Linux) only, where the checks read the
# SONAME and the dynamic symbol table.
if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
    add_test(NAME consumer_install_shared
        COMMAND ${CMAKE_COMMAND} ${_bsf_consumer_args} -DMODE=install_shared
            -DWORK_DIR=${_bsf_consumer_work}/shared -DLIB_CAPS=${_bsf_shared_caps_arg}
            -P ${_bsf_consumer_dir}/consumer_test.cmake)
    set_tests_properties(consumer_install_shared PROPERTIES TIMEOUT 180 FIXTURES_SETUP bsf_shared
        LABELS consumer)
    bsf_consumer_test(consumer_find_package_shared find_package ${_sh})
    bsf_consumer_test(consumer_pkgconfig_shared pkgconfig ${_sh})
    bsf_consumer_test(consumer_caps_mismatch_shared caps_mismatch ${_sh})
    bsf_consumer_test(consumer_shared_exports exports ${_sh})
endif()
set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${_bsf_consumer_dir}/tool_notice.cmake)
