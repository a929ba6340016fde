/* SPDX-License-Identifier: MIT */
/*
 * bsf_port_clock.h - ready-made clock hooks for bsf's timing (bsf_params_t
 * clock / clock_user / clock_hz). A hook returns a free-running 32-bit tick
 * count; bsf only uses differences, so wrap-around is harmless as long as one
 * extraction takes less than 2^32 ticks.
 */
#ifndef BSF_PORT_CLOCK_H
#define BSF_PORT_CLOCK_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Host (POSIX): CLOCK_MONOTONIC in nanoseconds; use clock_hz = 1000000000. */
uint32_t bsf_port_clock_monotonic_ns(void *user);

/**
 * Cortex-M3/M4/M7: the DWT cycle counter (CYCCNT); use clock_hz = the core
 * clock. Call bsf_port_clock_dwt_enable() once at start-up. Returns 0 when the
 * core has no DWT cycle counter (then timing reads 0, it never fails).
 */
int bsf_port_clock_dwt_enable(void);
uint32_t bsf_port_clock_dwt_cycles(void *user);

/**
 * Cortex-M SysTick as a 24-bit down-counter run free at the core clock
 * (reload 0xFFFFFF, no interrupt), returned as an up-counting 24-bit value
 * widened to 32 bits by counting wraps between calls (call at least once
 * per 2^24 ticks). Works under QEMU, where DWT is absent; with QEMU's
 * -icount shift=10 on mps2-an386 one instruction is 25.6 ticks.
 */
void bsf_port_clock_systick_enable(void);
uint32_t bsf_port_clock_systick_ticks(void *user);

#ifdef __cplusplus
}
#endif

#endif /* BSF_PORT_CLOCK_H */
