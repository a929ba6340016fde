/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_version.h"

const char *bsf_version(void)
{
    return BSF_VERSION_STRING;
}
