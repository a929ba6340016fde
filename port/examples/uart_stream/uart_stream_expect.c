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
    static bsf_encoder_t encoder;
    bsf_status_t st;
    uint32_t k;
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
    fputc(0, out); /* the firmware's leading delimiter */
    st = live_scene_start();
    for (k = 0; st == BSF_OK && k < LIVE_SCENE_SCANS; ++k) {
        bsf_frame_info_t info;
        const bsf_result_t *result = NULL;
        if (k % LIVE_SCENE_META_EVERY == 0u) {
            static bsf_metadata_t meta;
            live_scene_metadata(&meta);
            st = bsf_metadata_encode_sink(&encoder, &meta, file_sink, out, NULL);
            if (st != BSF_OK) {
                break;
            }
        }
        st = live_scene_scan(k, &info, &result);
        if (st == BSF_OK) {
            st = bsf_frame_encode_sink(&encoder, &info, result, file_sink, out, NULL);
        }
        if (st != BSF_OK) {
            fprintf(stderr, "uart_stream_expect: scan %lu: %s\n", (unsigned long)k,
                    bsf_status_str(st));
        }
    }
    if (fclose(out) != 0 && st == BSF_OK) {
        perror(argv[1]);
        return 1;
    }
    return st == BSF_OK ? 0 : 1;
}
