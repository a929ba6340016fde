# SPDX-License-Identifier: MIT
# Read by CTest before it runs the tests (TEST_INCLUDE_FILES): says in the
# normal ctest output why the pkg-config consumer tests will be skipped,
# since CTest itself prints only "Skipped".
find_program(_bsf_pkg_config NAMES pkg-config pkgconf)
find_program(_bsf_make NAMES make gmake)
if(NOT _bsf_pkg_config OR NOT _bsf_make)
    message("bsf: consumer_pkgconfig_static, consumer_pkgconfig_shared will be skipped: they need pkg-config and make on PATH")
endif()
