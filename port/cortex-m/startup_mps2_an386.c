/* SPDX-License-Identifier: MIT */
/*
 * Minimal startup for QEMU's mps2-an386 (Cortex-M4F): vector table, FPU
 * enable, .data copy, .bss zeroing, newlib semihosting init, then main().
 * Used for the unit tests and benchmarks that run under emulation; firmware
 * brings its own startup.
 */
#include <stdint.h>
#include <stdlib.h>

extern uint32_t __StackTop;
extern uint32_t __data_load;
extern uint32_t __data_start;
extern uint32_t __data_end;
extern uint32_t __bss_start__;
extern uint32_t __bss_end__;

extern int main(void);
extern void initialise_monitor_handles(void);
extern void __libc_init_array(void);

void Reset_Handler(void);
void Default_Handler(void);

#define CPACR (*(volatile uint32_t *)0xE000ED88u)

void Reset_Handler(void)
{
    uint32_t *src;
    uint32_t *dst;

    /* Full access to CP10 and CP11 (the FPU) before any float instruction. */
    CPACR |= 0xFu << 20;
    __asm volatile("dsb\n\tisb" ::: "memory");

    src = &__data_load;
    for (dst = &__data_start; dst < &__data_end;) {
        *dst++ = *src++;
    }
    for (dst = &__bss_start__; dst < &__bss_end__;) {
        *dst++ = 0u;
    }

    initialise_monitor_handles();
    __libc_init_array();
    exit(main());
}

/* Any fault or unexpected interrupt ends the run with a distinctive status,
 * so CTest reports a failure instead of hanging. */
void Default_Handler(void)
{
    exit(99);
}

typedef void (*bsf_vector_t)(void);

/* Initial SP, then the 15 system exceptions; external IRQs are unused. */
__attribute__((section(".vectors"), used)) static const bsf_vector_t vector_table[16] = {
    (bsf_vector_t)(uintptr_t)&__StackTop,
    Reset_Handler,
    Default_Handler, /* NMI */
    Default_Handler, /* HardFault */
    Default_Handler, /* MemManage */
    Default_Handler, /* BusFault */
    Default_Handler, /* UsageFault */
    0,
    0,
    0,
    0,
    Default_Handler, /* SVCall */
    Default_Handler, /* DebugMon */
    0,
    Default_Handler, /* PendSV */
    Default_Handler, /* SysTick */
};
