# SPDX-License-Identifier: MIT
# CMake toolchain file: Arm Cortex-M4F (hard float), arm-none-eabi-gcc,
# newlib-nano with semihosting, tests run on QEMU's mps2-an386 board.
#
#   cmake -S . -B build-m4 -DCMAKE_TOOLCHAIN_FILE=port/cortex-m4f.cmake
#   cmake --build build-m4 && ctest --test-dir build-m4
#
# Firmware projects that only need the library can use this file too and
# ignore the QEMU parts.

set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

set(BSF_ARM_PREFIX "arm-none-eabi-" CACHE STRING "Prefix of the Arm bare-metal toolchain binaries")
set(CMAKE_C_COMPILER ${BSF_ARM_PREFIX}gcc)
set(CMAKE_ASM_COMPILER ${BSF_ARM_PREFIX}gcc)
set(CMAKE_AR ${BSF_ARM_PREFIX}ar CACHE FILEPATH "")
set(CMAKE_RANLIB ${BSF_ARM_PREFIX}ranlib CACHE FILEPATH "")
set(CMAKE_SIZE ${BSF_ARM_PREFIX}size CACHE FILEPATH "")

# Compiler checks cannot link a bare-metal program without our startup code.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(BSF_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
set(CMAKE_C_FLAGS_INIT "${BSF_CPU_FLAGS} -ffunction-sections -fdata-sections")
set(CMAKE_ASM_FLAGS_INIT "${BSF_CPU_FLAGS}")
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "${BSF_CPU_FLAGS} --specs=nano.specs --specs=rdimon.specs -u _printf_float -Wl,--gc-sections")

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# Every test executable runs in QEMU; printf/exit go through semihosting, so
# a failing Unity test (non-zero exit) fails CTest. -serial null and
# -monitor none keep QEMU off the terminal; never -nographic (it exits 1
# when stdin is closed, as under CI).
find_program(BSF_QEMU_ARM qemu-system-arm)
if(BSF_QEMU_ARM)
    set(CMAKE_CROSSCOMPILING_EMULATOR
        ${BSF_QEMU_ARM} -M mps2-an386 -display none -serial null -monitor none
        -semihosting-config enable=on,target=native -kernel)
endif()

set(BSF_PORT_CORTEX_M ON)
