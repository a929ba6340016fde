/* SPDX-License-Identifier: MIT */
/*
 * m4_counter.c - SysTick instruction counter and stack painting for the
 * bench_m4_* programs (m4_counter.h).
 */
#include "m4_counter.h"

#include <stdlib.h>
#include <string.h>

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define SYST_MASK 0x00FFFFFFu
#define SCB_ICSR (*(volatile uint32_t *)0xE000ED04u)
#define SCB_VTOR (*(volatile uint32_t *)0xE000ED08u)
#define ICSR_PENDSTSET (1u << 26)
#define N_VECTORS 16u

/* Room painted below the caller's frame; the deepest call measured uses
 * about 5 KiB. */
#define PAINT_BYTES 16384u
#define PAINT_WORD 0xDEADBEEFu

typedef void (*vector_t)(void);
static vector_t g_vectors[N_VECTORS] __attribute__((aligned(128)));
static volatile uint32_t g_wraps;
static double g_ticks_per_instr;

static void systick_isr(void)
{
    ++g_wraps;
}

uint32_t m4_ticks(void)
{
    uint32_t w, v, pend;
    do {
        w = g_wraps;
        v = SYST_CVR & SYST_MASK;
        pend = SCB_ICSR & ICSR_PENDSTSET;
    } while (w != g_wraps);
    /* A wrap whose interrupt has not run yet: the counter reloaded already. */
    if (pend != 0u && v > SYST_MASK / 2u) {
        ++w;
    }
    return (w << 24) + (SYST_MASK - v);
}

uint32_t m4_clock_hook(void *user)
{
    (void)user;
    return m4_ticks();
}

/* Exactly 2 instructions per iteration (subs, bne). */
static void spin(uint32_t n)
{
    __asm volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n) : : "cc");
}

static uint32_t ticks_of_spin(uint32_t n)
{
    const uint32_t t0 = m4_ticks();
    spin(n);
    return m4_ticks() - t0;
}

double m4_counter_start(void)
{
    const vector_t *boot = (const vector_t *)(uintptr_t)SCB_VTOR;
    uint32_t i;
    for (i = 0; i < N_VECTORS; ++i) {
        g_vectors[i] = boot[i];
    }
    g_vectors[15] = systick_isr;
    SCB_VTOR = (uint32_t)(uintptr_t)g_vectors;
    __asm volatile("dsb\n\tisb" ::: "memory");
    g_wraps = 0u;
    SYST_RVR = SYST_MASK;
    SYST_CVR = 0u;
    SYST_CSR = 7u;
    {
        /* Two loops differing by 2 * 200000 instructions: the call and
         * reading overhead cancels. */
        const uint32_t a = ticks_of_spin(100000u);
        const uint32_t b = ticks_of_spin(300000u);
        g_ticks_per_instr = (double)(b - a) / 400000.0;
    }
    return g_ticks_per_instr;
}

uint32_t m4_instr(uint32_t ticks)
{
    return (uint32_t)((double)ticks / g_ticks_per_instr + 0.5);
}

uint32_t *__attribute__((noinline)) m4_stack_paint(void)
{
    uint32_t sp;
    volatile uint32_t *p;
    uint32_t i;
    __asm volatile("mov %0, sp" : "=r"(sp));
    p = (volatile uint32_t *)(uintptr_t)((sp - PAINT_BYTES - 256u) & ~7u);
    for (i = 0; i < PAINT_BYTES / 4u; ++i) {
        p[i] = PAINT_WORD;
    }
    return (uint32_t *)(uintptr_t)p;
}

uint32_t __attribute__((noinline)) m4_stack_used(const uint32_t *base)
{
    const volatile uint32_t *p = base;
    uint32_t i = 0;
    while (i < PAINT_BYTES / 4u && p[i] == PAINT_WORD) {
        ++i;
    }
    return PAINT_BYTES - 4u * i;
}

static int cmp_u32(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a;
    const uint32_t y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

uint32_t m4_median(const uint32_t *v, size_t n, uint32_t *scratch, uint32_t *max_out)
{
    memcpy(scratch, v, n * sizeof *v);
    qsort(scratch, n, sizeof *scratch, cmp_u32);
    if (max_out != NULL) {
        *max_out = scratch[n - 1u];
    }
    return scratch[n / 2u];
}
