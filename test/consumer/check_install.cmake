# SPDX-License-Identifier: MIT
# Run by CTest: install the build tree into a scratch prefix, then build and
# run the consumer project against that prefix only.
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BSF_BINARY_DIR}" --prefix "${prefix}"
    RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "install failed (${rc})")
endif()
foreach(f include/bsf/bsf.h)
    if(NOT EXISTS "${prefix}/${f}")
        message(FATAL_ERROR "installed tree lacks ${f}")
    endif()
endforeach()
file(GLOB_RECURSE pc "${prefix}/*/pkgconfig/bsf.pc")
if(NOT pc)
    message(FATAL_ERROR "installed tree lacks pkgconfig/bsf.pc")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" -S "${CONSUMER_SOURCE_DIR}" -B "${WORK_DIR}/build"
        -G "${GENERATOR}" -DCMAKE_C_COMPILER=${C_COMPILER} -DCMAKE_PREFIX_PATH=${prefix}
        -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
    RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "consumer configure failed (${rc})")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${WORK_DIR}/build" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "consumer build failed (${rc})")
endif()
file(GLOB_RECURSE exe "${WORK_DIR}/build/consumer" "${WORK_DIR}/build/consumer.exe")
execute_process(COMMAND ${exe} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "consumer ran but returned ${rc}")
endif()
message(STATUS "consumer built against ${prefix} and ran OK")
