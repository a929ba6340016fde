/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_common.h"

const char *bsf_status_str(bsf_status_t status)
{
    switch (status) {
    case BSF_OK: return "ok";
    case BSF_OK_CUT: return "ok, output cut to fit the caps";
    case BSF_ERR_ARG: return "bad argument";
    case BSF_ERR_CAPACITY: return "capacity exceeded";
    case BSF_ERR_PARAM: return "parameter out of range";
    case BSF_ERR_NUMERIC: return "numerical failure";
    case BSF_ERR_DEGENERATE: return "degenerate input";
    case BSF_ERR_BUFFER: return "buffer too small";
    case BSF_ERR_FORMAT: return "malformed data";
    case BSF_ERR_CRC: return "checksum mismatch";
    case BSF_ERR_VERSION: return "unsupported version";
    case BSF_ERR_UNSUPPORTED: return "method or feature not compiled into this build";
    default: return "unknown status";
    }
}
