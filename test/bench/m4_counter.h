/* SPDX-License-Identifier: MIT */
/*
 * m4_counter.h - instruction counts and stack high-water marks on the
 * Cortex-M4F under QEMU -icount, shared by the bench_m4_* programs.
 *
 * QEMU's -icount gives each instruction a fixed slice of virtual time, so
 * SysTick ticks count instructions (25.6 ticks each at shift=10 on
 * mps2-an386). The counter calibrates that ratio with two loops of known
 * length and counts the 24-bit wraps in an interrupt, so calls of any length
 * are counted exactly. Instructions, not cycles.
 */
#ifndef M4_COUNTER_H
#define M4_COUNTER_H

#include <stddef.h>
#include <stdint.h>

/* Start SysTick (through a vector table of our own in RAM) and calibrate.
 * Returns SysTick ticks per instruction; below 0.5 there is no usable
 * instruction clock (QEMU run without -icount). */
double m4_counter_start(void);

/* SysTick ticks since m4_counter_start(), wraps included. */
uint32_t m4_ticks(void);

/* Instructions in a number of ticks (rounded). */
uint32_t m4_instr(uint32_t ticks);

/* m4_ticks() in the form of the library's clock hook (bsf_params_t.clock). */
uint32_t m4_clock_hook(void *user);

/* Paint the free stack below the caller with a pattern; returns the lowest
 * painted word, for m4_stack_used(). */
uint32_t *m4_stack_paint(void);

/* Bytes of the painted area overwritten since m4_stack_paint(). */
uint32_t m4_stack_used(const uint32_t *base);

/* Median of v[0..n-1] (n >= 1), sorted in scratch (n words); *max_out, when
 * not NULL, gets the largest value. */
uint32_t m4_median(const uint32_t *v, size_t n, uint32_t *scratch, uint32_t *max_out);

#endif /* M4_COUNTER_H */
