/* SPDX-License-Identifier: MIT */
/*
 * shared_dir.h - where the tests find the shared datasets (host tests only).
 *
 * $BSF_SHARED_DIR (else the configured default) may name either the folder
 * that holds data/ and ref/, or the data folder itself; both give the former.
 */
#ifndef BSF_TEST_SHARED_DIR_H
#define BSF_TEST_SHARED_DIR_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Writes the folder holding data/ and ref/ to out (cap bytes). */
static void bsf_test_shared_dir(char *out, size_t cap)
{
    const char *env = getenv("BSF_SHARED_DIR");
    char probe[4096];
    size_t len;
    FILE *f;
    int is_data_dir;

    snprintf(out, cap, "%s", env != NULL && env[0] != '\0' ? env : BSF_SHARED_DIR_DEFAULT);
    len = strlen(out);
    while (len > 1u && out[len - 1u] == '/') {
        out[--len] = '\0';
    }
    /* The data folder itself: it holds the logs, or is called data. */
    snprintf(probe, sizeof probe, "%s/intel.log.gz", out);
    f = fopen(probe, "rb");
    is_data_dir = f != NULL || (len >= 4u && strcmp(out + len - 4u, "data") == 0 &&
                                (len == 4u || out[len - 5u] == '/'));
    if (f != NULL) {
        fclose(f);
    }
    if (is_data_dir && len + 3u < cap) {
        memcpy(out + len, "/..", 4u);
    }
}

#endif /* BSF_TEST_SHARED_DIR_H */
