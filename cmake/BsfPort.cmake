# SPDX-License-Identifier: MIT
# Per-platform pieces for bsf's own executables (tests, benchmarks).

# Turn an executable into a bare-metal image for QEMU's mps2-an386: our
# startup code, vector table and linker script.
function(bsf_target_cortex_m_executable target)
    target_sources(${target} PRIVATE ${PROJECT_SOURCE_DIR}/port/cortex-m/startup_mps2_an386.c)
    target_link_options(${target} PRIVATE
        -T${PROJECT_SOURCE_DIR}/port/cortex-m/mps2_an386.ld
        -Wl,-Map=$<TARGET_FILE:${target}>.map)
    set_target_properties(${target} PROPERTIES SUFFIX ".elf"
        LINK_DEPENDS ${PROJECT_SOURCE_DIR}/port/cortex-m/mps2_an386.ld)
endfunction()
