/* SPDX-License-Identifier: MIT */
/* POSIX clock hook (host builds): CLOCK_MONOTONIC, nanoseconds, 32-bit wrap. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 199309L
#endif
#include <time.h>

#include "bsf_port_clock.h"

uint32_t bsf_port_clock_monotonic_ns(void *user)
{
    struct timespec ts;
    (void)user;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) != 0) {
        return 0u;
    }
    return (uint32_t)((uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec);
}
