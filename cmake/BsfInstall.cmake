# SPDX-License-Identifier: MIT
# Install rules (BSF_INSTALL): the library, its headers, the port clock hooks
# (bsf::port, plus their sources for firmware builds), the CMake package
# (find_package(bsf CONFIG)), a relocatable pkg-config file, the licence and
# the documentation.
include(CMakePackageConfigHelpers)

install(TARGETS bsf bsf_port EXPORT bsfTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY include/bsf DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# Clock hooks: the header beside the library's, every platform's source for
# builds that compile their own (firmware), and bsf::port for this platform.
install(FILES port/bsf_port_clock.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bsf/port)
install(FILES port/host/bsf_port_clock_posix.c port/cortex-m/bsf_port_clock_cortex_m.c
    DESTINATION ${CMAKE_INSTALL_DATADIR}/bsf/port)
install(EXPORT bsfTargets NAMESPACE bsf:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bsf)
configure_package_config_file(cmake/bsfConfig.cmake.in
    ${PROJECT_BINARY_DIR}/bsfConfig.cmake
    INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bsf)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/bsfConfigVersion.cmake
    COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/bsfConfig.cmake ${PROJECT_BINARY_DIR}/bsfConfigVersion.cmake
    DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bsf)

# bsf.pc. prefix is found from the file's own place (${pcfiledir}), so the
# file stays right after `cmake --install --prefix ANY` or moving the tree.
# libm: a static libbsf needs it on every link (plain `pkg-config --libs`
# too), a shared one carries it itself (Libs.private, for --static).
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
    set(BSF_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
    set(BSF_PC_LIBDIR "${CMAKE_INSTALL_LIBDIR}")
else()
    string(REGEX REPLACE "[^/]+" ".." _up "${CMAKE_INSTALL_LIBDIR}")
    set(BSF_PC_PREFIX "\${pcfiledir}/../${_up}")
    set(BSF_PC_LIBDIR "\${prefix}/${CMAKE_INSTALL_LIBDIR}")
endif()
if(IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
    set(BSF_PC_INCLUDEDIR "${CMAKE_INSTALL_INCLUDEDIR}")
else()
    set(BSF_PC_INCLUDEDIR "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
endif()
get_target_property(_bsf_type bsf TYPE)
if(MSVC)
    set(BSF_PC_LIBM "")
else()
    set(BSF_PC_LIBM "-lm")
endif()
if(_bsf_type STREQUAL "STATIC_LIBRARY")
    set(BSF_PC_LIBS "-L\${libdir} -lbsf ${BSF_PC_LIBM}")
    set(BSF_PC_LIBS_PRIVATE "")
else()
    set(BSF_PC_LIBS "-L\${libdir} -lbsf")
    set(BSF_PC_LIBS_PRIVATE "${BSF_PC_LIBM}")
endif()
set(BSF_PC_CFLAGS "-I\${includedir}")
foreach(_cap IN LISTS BSF_CAPS)
    string(APPEND BSF_PC_CFLAGS " -D${_cap}")
endforeach()
configure_file(cmake/bsf.pc.in ${PROJECT_BINARY_DIR}/bsf.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/bsf.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# The licence and the documentation, where packagers and users look for them
# (share/doc/bsf): README.md links docs/ relatively, so docs/ keeps its name.
install(FILES LICENSE README.md CHANGELOG.md CITATION.cff DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs)
