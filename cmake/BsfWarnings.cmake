# SPDX-License-Identifier: MIT
# The warning wall for bsf's own targets. It is PRIVATE to each target, so
# projects that consume bsf never inherit it.
set(BSF_WARNING_FLAGS
    -Wall -Wextra -pedantic -Wconversion -Wsign-conversion -Wdouble-promotion
    -Wshadow -Wcast-align -Wundef -Wvla -Wmissing-prototypes -Wstrict-prototypes
    -Wpointer-arith -Wwrite-strings -Wformat=2)

function(bsf_target_warnings target)
    if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
        target_compile_options(${target} PRIVATE ${BSF_WARNING_FLAGS})
        if(BSF_WERROR)
            target_compile_options(${target} PRIVATE -Werror)
        endif()
    endif()
    if(BSF_SANITIZERS)
        target_compile_options(${target} PRIVATE -fsanitize=${BSF_SANITIZERS} -fno-omit-frame-pointer -fno-sanitize-recover=all)
        target_link_options(${target} PRIVATE -fsanitize=${BSF_SANITIZERS})
    endif()
endfunction()
