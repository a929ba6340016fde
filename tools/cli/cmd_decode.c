/* SPDX-License-Identifier: MIT */
/*
 * cmd_decode.c - bsf decode: frames as text or JSON Lines, then decoder counters.
 */
#include "tool.h"

static const char decode_help[] =
    "Usage: bsf decode IN [--json]\n"
    "Decode a bsf stream ('-' for stdin): one line per frame, then the decoder's\n"
    "counters. With --json, one JSON object per line (JSON Lines): every frame with\n"
    "its features and control points, then {\"counters\": ...}.\n";

typedef struct {
    int json;
    FILE *out;
} decode_ctx_t;

static void print_json_float(FILE *f, float v)
{
    /* Shortest round-trip-ish form; never NaN (the decoder rejects them). */
    fprintf(f, "%.9g", (double)v);
}

static int print_frame(void *vctx, const bsf_frame_t *fr, size_t bytes)
{
    decode_ctx_t *ctx = (decode_ctx_t *)vctx;
    const bsf_result_t *r = &fr->result;
    const bsf_scan_counts_t c = counts_of_result(r);
    size_t i, k;
    if (!ctx->json) {
        fprintf(ctx->out, "seq=%lu t=%.3f pose=", (unsigned long)fr->seq,
                1e-3 * (double)fr->timestamp_ms);
        if (fr->has_pose) {
            fprintf(ctx->out, "(%.3f,%.3f,%.4f)", (double)fr->pose_x, (double)fr->pose_y,
                    (double)fr->pose_theta);
        } else {
            fputs("none", ctx->out);
        }
        fprintf(ctx->out,
                " N=%lu features=%u points=%lu ctrl=%lu time_us=%lu quant=%.4f bytes=%zu\n",
                (unsigned long)c.n_valid, (unsigned)r->n_features, (unsigned long)c.n_in_features,
                (unsigned long)c.n_ctrl, (unsigned long)fr->time_us, (double)fr->quant_step, bytes);
        return ferror(ctx->out) ? -1 : 0;
    }
    fprintf(ctx->out, "{\"seq\":%lu,\"timestamp_ms\":%llu,\"bytes\":%zu,\"version\":%u,",
            (unsigned long)fr->seq, (unsigned long long)fr->timestamp_ms, bytes,
            (unsigned)fr->version);
    if (fr->has_pose) {
        fputs("\"pose\":[", ctx->out);
        print_json_float(ctx->out, fr->pose_x);
        fputc(',', ctx->out);
        print_json_float(ctx->out, fr->pose_y);
        fputc(',', ctx->out);
        print_json_float(ctx->out, fr->pose_theta);
        fputs("],", ctx->out);
    } else {
        fputs("\"pose\":null,", ctx->out);
    }
    fprintf(ctx->out, "\"quant_step\":");
    print_json_float(ctx->out, fr->quant_step);
    fprintf(ctx->out, ",\"n_valid\":%lu,\"time_us\":%lu,\"features\":[",
            (unsigned long)r->stats.n_valid, (unsigned long)fr->time_us);
    for (i = 0; i < r->n_features; ++i) {
        const bsf_feature_t *f = &r->features[i];
        fprintf(ctx->out,
                "%s{\"kind\":\"%s\",\"first_beam\":%u,\"last_beam\":%u,\"n_points\":%u,"
                "\"e_curve\":",
                i ? "," : "", f->kind == BSF_FEATURE_AUXILIARY ? "auxiliary" : "bleak",
                (unsigned)f->first_beam, (unsigned)f->last_beam, (unsigned)f->n_points);
        print_json_float(ctx->out, f->e_curve);
        fputs(",\"ctrl\":[", ctx->out);
        for (k = 0; k < f->n_ctrl; ++k) {
            const size_t j = (size_t)f->ctrl_first + k;
            fputs(k ? ",[" : "[", ctx->out);
            print_json_float(ctx->out, r->ctrl[j].x);
            fputc(',', ctx->out);
            print_json_float(ctx->out, r->ctrl[j].y);
            fputc(']', ctx->out);
        }
        fputs("],\"vertex\":[", ctx->out);
        for (k = 0; k < f->n_ctrl; ++k) {
            fprintf(ctx->out, "%s%d", k ? "," : "",
                    r->ctrl_is_vertex[(size_t)f->ctrl_first + k] ? 1 : 0);
        }
        fputs("]}", ctx->out);
    }
    fputs("]}\n", ctx->out);
    return ferror(ctx->out) ? -1 : 0;
}

static void print_counters(FILE *f, int json, const bsf_decoder_stats_t *s, unsigned long gaps)
{
    if (json) {
        fprintf(f,
                "{\"counters\":{\"frames_ok\":%lu,\"bad_crc\":%lu,\"malformed\":%lu,"
                "\"unsupported_version\":%lu,\"unknown_type\":%lu,\"oversize\":%lu,"
                "\"bytes_skipped\":%lu,\"seq_gaps\":%lu}}\n",
                (unsigned long)s->frames_ok, (unsigned long)s->bad_crc, (unsigned long)s->malformed,
                (unsigned long)s->unsupported_version, (unsigned long)s->unknown_type,
                (unsigned long)s->oversize, (unsigned long)s->bytes_skipped, gaps);
    } else {
        fprintf(f,
                "frames ok %lu, bad crc %lu, malformed %lu, unsupported version %lu, unknown "
                "type %lu, oversize %lu, bytes skipped %lu, missing by sequence %lu\n",
                (unsigned long)s->frames_ok, (unsigned long)s->bad_crc, (unsigned long)s->malformed,
                (unsigned long)s->unsupported_version, (unsigned long)s->unknown_type,
                (unsigned long)s->oversize, (unsigned long)s->bytes_skipped, gaps);
    }
}

int cmd_decode(int argc, char **argv)
{
    const char *in_path = NULL;
    decode_ctx_t ctx;
    bsf_decoder_stats_t st;
    unsigned long gaps = 0;
    FILE *in;
    int i, rc;
    ctx.json = 0;
    ctx.out = stdout;
    for (i = 1; i < argc; ++i) {
        if (is_help(argv[i])) {
            fputs(decode_help, stdout);
            return 0;
        } else if (strcmp(argv[i], "--json") == 0) {
            ctx.json = 1;
        } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
            return usage_error("unknown option '%s'", argv[i]);
        } else if (in_path == NULL) {
            in_path = argv[i];
        } else {
            return usage_error("decode takes one input, got '%s' too", argv[i]);
        }
    }
    if (in_path == NULL) {
        return usage_error("decode needs an input stream (or '-')");
    }
    in = open_in(in_path);
    if (in == NULL) {
        return EXIT_FAIL;
    }
    rc = decode_stream(in, in_path, print_frame, &ctx, &st, &gaps);
    if (in != stdin) {
        fclose(in);
    }
    if (rc != 0) {
        return EXIT_FAIL;
    }
    print_counters(stdout, ctx.json, &st, gaps);
    return close_out(stdout, "stdout") == 0 ? 0 : EXIT_FAIL;
}
