/* SPDX-License-Identifier: MIT */
/*
 * uart_stream - firmware example for the Cortex-M4F (QEMU mps2-an386): extract
 * the features of every scan of a built-in scene (live_scene.c) and send each
 * scan as one bsf frame over UART0, the way a LIDAR node would stream to a
 * host. The encoder hands the frame over in blocks of at most 256 bytes
 * (bsf_frame_encode_sink), so no frame-sized buffer is needed.
 *
 * On the host: `bsf listen DEVICE|-` (see README, "Live link").
 *
 *   qemu-system-arm -M mps2-an386 -display none -monitor none \
 *       -semihosting-config enable=on,target=native \
 *       -serial file:/tmp/bsf.fifo -kernel uart_stream.elf
 *
 * Exit status 0 after the last scan (semihosting), 1 when an extraction or
 * encoding fails (with a message on the semihosting console).
 */
#include <stdio.h>

#include "live_scene.h"

/* CMSDK APB UART0 of the MPS2 boards (ARM DDI0479C, "APB UART"). */
#define UART0_BASE 0x40004000u
#define UART_DATA (*(volatile uint32_t *)(UART0_BASE + 0x00u))
#define UART_STATE (*(volatile uint32_t *)(UART0_BASE + 0x04u))
#define UART_CTRL (*(volatile uint32_t *)(UART0_BASE + 0x08u))
#define UART_BAUDDIV (*(volatile uint32_t *)(UART0_BASE + 0x10u))
#define UART_STATE_TX_FULL 0x1u
#define UART_CTRL_TX_ENABLE 0x1u

/* The APB clock of mps2-an386 is 25 MHz; the divider must be at least 16. */
#define BOARD_PCLK_HZ 25000000u
#define LINK_BAUD 115200u

static void uart_init(void)
{
    UART_BAUDDIV = BOARD_PCLK_HZ / LINK_BAUD;
    UART_CTRL = UART_CTRL_TX_ENABLE;
}

/* Polled transmit: wait while the one-byte TX buffer is full. The host side
 * (QEMU's chardev, or a real wire) drains it at the link's pace. */
static void uart_put(uint8_t byte)
{
    while ((UART_STATE & UART_STATE_TX_FULL) != 0u) {
    }
    UART_DATA = byte;
}

static int uart_sink(void *ctx, const uint8_t *data, size_t len)
{
    size_t i;
    (void)ctx;
    for (i = 0; i < len; ++i) {
        uart_put(data[i]);
    }
    return 0;
}

int main(void)
{
    uint32_t failed_scan = 0;
    bsf_status_t st;

    uart_init();
    st = live_scene_send(uart_sink, NULL, &failed_scan);
    if (st != BSF_OK) {
        printf("uart_stream: scan %lu: %s\n", (unsigned long)failed_scan, bsf_status_str(st));
        return 1;
    }
    return 0;
}
