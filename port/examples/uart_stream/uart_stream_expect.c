/* SPDX-License-Identifier: MIT */
/*
 * uart_stream_expect - the host's copy of what uart_stream sends: the same
 * scans (live_scene.c) through the same encoder, written to a file. The live
 * link test compares the bytes received from QEMU's UART with these.
 *
 *   uart_stream_expect OUT.bsf
 */
#include <stdio.h>

#include "live_scene.h"

static int file_sink(void *ctx, const uint8_t *data, size_t len)
{
    return fwrite(data, 1, len, (FILE *)ctx) == len ? 0 : 1;
}

int main(int argc, char **argv)
{
    uint32_t failed_scan = 0;
    bsf_status_t st;
    FILE *out;
    if (argc != 2) {
        fprintf(stderr, "usage: uart_stream_expect OUT.bsf\n");
        return 2;
    }
    out = fopen(argv[1], "wb");
    if (out == NULL) {
        perror(argv[1]);
        return 1;
    }
    st = live_scene_send(file_sink, out, &failed_scan);
    if (st != BSF_OK) {
        fprintf(stderr, "uart_stream_expect: scan %lu: %s\n", (unsigned long)failed_scan,
                bsf_status_str(st));
    }
    if (fclose(out) != 0 && st == BSF_OK) {
        perror(argv[1]);
        return 1;
    }
    return st == BSF_OK ? 0 : 1;
}
