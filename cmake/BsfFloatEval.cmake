# SPDX-License-Identifier: MIT
# bsf gives the same bytes on every target only when float arithmetic is
# evaluated in float (FLT_EVAL_METHOD 0); src/bsf_math.h refuses to compile
# otherwise. Some compilers evaluate float in double in ISO C mode (GCC on
# s390x with -std=c99 reports 1) but not with -fexcess-precision=fast: add
# that flag to every target of this build when it is what makes the
# difference. A target where no flag helps (x87 without SSE) stops here
# with the reason.
include(CheckCSourceCompiles)
include(CMakePushCheckState)

set(_bsf_flt_eval_src "#include <float.h>
#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD != 0
#error float is not evaluated in float
#endif
int main(void) { return 0; }
")
cmake_push_check_state(RESET)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
check_c_source_compiles("${_bsf_flt_eval_src}" BSF_FLT_EVAL_IS_FLOAT)
if(NOT BSF_FLT_EVAL_IS_FLOAT)
    set(CMAKE_REQUIRED_FLAGS "-fexcess-precision=fast")
    check_c_source_compiles("${_bsf_flt_eval_src}" BSF_FLT_EVAL_FLOAT_WITH_FAST_EXCESS)
    if(BSF_FLT_EVAL_FLOAT_WITH_FAST_EXCESS)
        message(STATUS "bsf: float evaluated in wider precision; adding -fexcess-precision=fast")
        add_compile_options(-fexcess-precision=fast)
    else()
        message(FATAL_ERROR "bsf needs float arithmetic evaluated in float (FLT_EVAL_METHOD 0) "
            "to give the same bytes on every target, and ${CMAKE_C_COMPILER} does not do that "
            "with these flags nor with -fexcess-precision=fast. On 32-bit x86 add "
            "-msse2 -mfpmath=sse to CMAKE_C_FLAGS.")
    endif()
endif()
cmake_pop_check_state()
