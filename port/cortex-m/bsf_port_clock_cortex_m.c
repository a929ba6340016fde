/* SPDX-License-Identifier: MIT */
/* Cortex-M clock hooks: DWT cycle counter, and SysTick as a free-running
 * counter (the one QEMU emulates). Register addresses are architectural
 * (ARMv7-M), the same on every M3/M4/M7. */
#include "bsf_port_clock.h"

#define DEMCR (*(volatile uint32_t *)0xE000EDFCu)
#define DWT_CTRL (*(volatile uint32_t *)0xE0001000u)
#define DWT_CYCCNT (*(volatile uint32_t *)0xE0001004u)
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

#define DEMCR_TRCENA (1u << 24)
#define DWT_CTRL_NOCYCCNT (1u << 25)
#define DWT_CTRL_CYCCNTENA 1u

int bsf_port_clock_dwt_enable(void)
{
    DEMCR |= DEMCR_TRCENA;
    if ((DWT_CTRL & DWT_CTRL_NOCYCCNT) != 0u) {
        return 0;
    }
    DWT_CYCCNT = 0u;
    DWT_CTRL |= DWT_CTRL_CYCCNTENA;
    return 1;
}

uint32_t bsf_port_clock_dwt_cycles(void *user)
{
    (void)user;
    return DWT_CYCCNT;
}

static uint32_t systick_last;
static uint32_t systick_high;

void bsf_port_clock_systick_enable(void)
{
    SYST_RVR = 0x00FFFFFFu;
    SYST_CVR = 0u;
    SYST_CSR = 5u; /* enable, core clock, no interrupt */
    systick_last = 0u;
    systick_high = 0u;
}

uint32_t bsf_port_clock_systick_ticks(void *user)
{
    /* SysTick counts down from 0xFFFFFF; turn it into an up-counter and add
     * 2^24 each time it wrapped since the previous call. */
    const uint32_t now = 0x00FFFFFFu - (SYST_CVR & 0x00FFFFFFu);
    (void)user;
    if (now < systick_last) {
        systick_high += 0x01000000u;
    }
    systick_last = now;
    return systick_high + now;
}
