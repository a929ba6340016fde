/* SPDX-License-Identifier: MIT */
/*
 * cmd_decode.c - bsf decode: frames as text or JSON Lines, then decoder counters.
 */
#include "tool.h"

static const char decode_help[] =
    "Usage: bsf decode IN [--json]\n"
    "Decode a bsf stream ('-' for stdin): one line per frame (metadata frames\n"
    "included), then the decoder's counters. With --json, one JSON object per line\n"
    "(JSON Lines): {\"metadata\": ...} for a metadata frame, every scan's frame with\n"
    "its features and control points, {\"map\": ...} for a map-update frame (its\n"
    "sequence number and payload; bsf map rebuilds the map), then {\"counters\": ...}\n"
    "(docs/TOOL.md).\n"
    "Each line is written as soon as its frame's delimiter arrives (a live link on\n"
    "stdin works). Exits 1 when a non-empty input holds no valid frame.\n";

typedef struct {
    int json;
    FILE *out;
} decode_ctx_t;

static void print_json_float(FILE *f, float v)
{
    /* Shortest round-trip-ish form; never NaN (the decoder rejects them). */
    fprintf(f, "%.9g", (double)v);
}

/* Unix microseconds as UTC "YYYY-MM-DDTHH:MM:SS.uuuuuuZ". */
static void format_utc(char *out, size_t cap, int64_t us)
{
    const int64_t sec = us >= 0 ? us / 1000000 : -((-us + 999999) / 1000000);
    const long frac = (long)(us - sec * 1000000);
    const time_t t = (time_t)sec;
    struct tm tm;
    if (gmtime_r(&t, &tm) == NULL || strftime(out, cap, "%Y-%m-%dT%H:%M:%S", &tm) == 0u) {
        snprintf(out, cap, "%lld us", (long long)us);
        return;
    }
    snprintf(out + strlen(out), cap - strlen(out), ".%06ldZ", frac);
}

static int print_metadata(decode_ctx_t *ctx, const bsf_frame_t *fr, size_t bytes)
{
    const bsf_metadata_t *m = &fr->metadata;
    const char *method = bsf_method_name((bsf_method_t)m->method);
    if (!ctx->json) {
        fprintf(ctx->out,
                "metadata library=%u.%u.%u format=%u method=%s target_rms=%.9g quant=%.4f "
                "caps=points:%lu,keypoints:%lu,segments:%lu,ctrl_per_feature:%lu,ctrl:%lu "
                "beams=%lu angle_min=%.9g angle_increment=%.9g range_min=%.9g range_max=%.9g "
                "time_origin=",
                (unsigned)m->lib_version_major, (unsigned)m->lib_version_minor,
                (unsigned)m->lib_version_patch, (unsigned)fr->version,
                method != NULL ? method : "unknown", (double)m->target_rms, (double)m->quant_step,
                (unsigned long)m->max_points, (unsigned long)m->max_keypoints,
                (unsigned long)m->max_segments, (unsigned long)m->max_ctrl_per_feature,
                (unsigned long)m->max_ctrl_points, (unsigned long)m->n_beams, (double)m->angle_min,
                (double)m->angle_increment, (double)m->range_min, (double)m->range_max);
        if (m->has_time_origin) {
            char utc[64];
            format_utc(utc, sizeof utc, m->time_origin_us);
            fputs(utc, ctx->out);
        } else {
            fputs("unknown", ctx->out);
        }
        fputs(" source=", ctx->out);
        if (m->source_len > 0u) {
            print_json_string(ctx->out, m->source);
        } else {
            fputs("none", ctx->out);
        }
        fprintf(ctx->out, " bytes=%zu\n", bytes);
        return 0;
    }
    fprintf(ctx->out,
            "{\"metadata\":{\"bytes\":%zu,\"version\":%u,\"library\":\"%u.%u.%u\",\"method\":",
            bytes, (unsigned)fr->version, (unsigned)m->lib_version_major,
            (unsigned)m->lib_version_minor, (unsigned)m->lib_version_patch);
    if (method != NULL) {
        print_json_string(ctx->out, method);
    } else {
        fputs("null", ctx->out);
    }
    fprintf(ctx->out, ",\"method_id\":%u,\"target_rms\":", (unsigned)m->method);
    print_json_float(ctx->out, m->target_rms);
    fputs(",\"quant_step\":", ctx->out);
    print_json_float(ctx->out, m->quant_step);
    fprintf(ctx->out,
            ",\"caps\":{\"points\":%lu,\"keypoints\":%lu,\"segments\":%lu,"
            "\"ctrl_per_feature\":%lu,\"ctrl_points\":%lu},\"n_beams\":%lu,\"angle_min\":",
            (unsigned long)m->max_points, (unsigned long)m->max_keypoints,
            (unsigned long)m->max_segments, (unsigned long)m->max_ctrl_per_feature,
            (unsigned long)m->max_ctrl_points, (unsigned long)m->n_beams);
    print_json_float(ctx->out, m->angle_min);
    fputs(",\"angle_increment\":", ctx->out);
    print_json_float(ctx->out, m->angle_increment);
    fputs(",\"range_min\":", ctx->out);
    print_json_float(ctx->out, m->range_min);
    fputs(",\"range_max\":", ctx->out);
    print_json_float(ctx->out, m->range_max);
    fputs(",\"time_origin_us\":", ctx->out);
    if (m->has_time_origin) {
        fprintf(ctx->out, "%lld", (long long)m->time_origin_us);
    } else {
        fputs("null", ctx->out);
    }
    fputs(",\"source\":", ctx->out);
    if (m->source_len > 0u) {
        print_json_string(ctx->out, m->source);
    } else {
        fputs("null", ctx->out);
    }
    fputs("}}\n", ctx->out);
    return 0;
}

static void print_json_features(decode_ctx_t *ctx, const bsf_frame_t *fr, size_t bytes);

static int print_frame(void *vctx, const bsf_frame_t *fr, size_t bytes)
{
    decode_ctx_t *ctx = (decode_ctx_t *)vctx;
    const bsf_result_t *r = &fr->result;
    const bsf_scan_counts_t c = counts_of_result(r);

    if (fr->type == BSF_FRAME_TYPE_METADATA) {
        print_metadata(ctx, fr, bytes);
    } else if (fr->type == BSF_FRAME_TYPE_MAP) {
        size_t k;
        if (ctx->json) {
            fprintf(ctx->out, "{\"map\":{\"seq\":%lu,\"bytes\":%zu,\"payload\":\"",
                    (unsigned long)fr->seq, bytes);
        } else {
            fprintf(ctx->out, "map seq=%lu bytes=%zu payload=", (unsigned long)fr->seq, bytes);
        }
        for (k = 0; k < fr->payload_len; ++k) {
            fprintf(ctx->out, "%02x", (unsigned)fr->payload[k]);
        }
        fputs(ctx->json ? "\"}}\n" : "\n", ctx->out);
    } else if (!ctx->json) {
        fprintf(ctx->out, "seq=%lu t=%.3f pose=", (unsigned long)fr->seq,
                1e-3 * (double)fr->timestamp_ms);
        if (fr->has_pose) {
            fprintf(ctx->out, "(%.3f,%.3f,%.4f)", (double)fr->pose.x, (double)fr->pose.y,
                    (double)fr->pose.theta);
        } else {
            fputs("none", ctx->out);
        }
        fprintf(ctx->out, " N=%lu features=%u points=%lu ctrl=%lu time_us=%lu quant=%.4f bytes=%zu",
                (unsigned long)c.n_valid, (unsigned)r->n_features, (unsigned long)c.n_in_features,
                (unsigned long)c.n_ctrl, (unsigned long)fr->time_us, (double)fr->quant_step, bytes);
        if (r->stats.n_beams != 0u) {
            fprintf(ctx->out, " beams=%lu", (unsigned long)r->stats.n_beams);
        }
        if (fr->has_geometry) {
            fprintf(ctx->out, " angle_min=%.9g angle_increment=%.9g", (double)fr->angle_min,
                    (double)fr->angle_increment);
        }
        if (r->stats.cut != 0u) {
            fprintf(ctx->out, " cut=%s%s%s(keypoints %lu, segments %lu, points %lu)",
                    (r->stats.cut & BSF_CUT_KEYPOINTS) ? "keypoints," : "",
                    (r->stats.cut & BSF_CUT_SEGMENTS) ? "segments," : "",
                    (r->stats.cut & BSF_CUT_CTRL) ? "ctrl," : "",
                    (unsigned long)r->stats.n_cut_keypoints, (unsigned long)r->stats.n_cut_segments,
                    (unsigned long)r->stats.n_cut_points);
        }
        fputc('\n', ctx->out);
    } else {
        print_json_features(ctx, fr, bytes);
    }
    /* One frame, one flush: a reader on a pipe sees each frame at once. */
    return fflush(ctx->out) != 0 || ferror(ctx->out) ? -1 : 0;
}

static void print_json_features(decode_ctx_t *ctx, const bsf_frame_t *fr, size_t bytes)
{
    const bsf_result_t *r = &fr->result;
    size_t i, k;
    fprintf(ctx->out, "{\"seq\":%lu,\"timestamp_ms\":%llu,\"bytes\":%zu,\"version\":%u,",
            (unsigned long)fr->seq, (unsigned long long)fr->timestamp_ms, bytes,
            (unsigned)fr->version);
    if (fr->has_pose) {
        fputs("\"pose\":[", ctx->out);
        print_json_float(ctx->out, fr->pose.x);
        fputc(',', ctx->out);
        print_json_float(ctx->out, fr->pose.y);
        fputc(',', ctx->out);
        print_json_float(ctx->out, fr->pose.theta);
        fputs("],", ctx->out);
    } else {
        fputs("\"pose\":null,", ctx->out);
    }
    fprintf(ctx->out, "\"quant_step\":");
    print_json_float(ctx->out, fr->quant_step);
    fprintf(ctx->out,
            ",\"n_valid\":%lu,\"time_us\":%lu,\"n_beams\":", (unsigned long)r->stats.n_valid,
            (unsigned long)fr->time_us);
    if (r->stats.n_beams != 0u) {
        fprintf(ctx->out, "%lu", (unsigned long)r->stats.n_beams);
    } else {
        fputs("null", ctx->out);
    }
    fputs(",\"geometry\":", ctx->out);
    if (fr->has_geometry) {
        fputs("{\"angle_min\":", ctx->out);
        print_json_float(ctx->out, fr->angle_min);
        fputs(",\"angle_increment\":", ctx->out);
        print_json_float(ctx->out, fr->angle_increment);
        fputc('}', ctx->out);
    } else {
        fputs("null", ctx->out);
    }
    fprintf(ctx->out,
            ",\"cut\":%lu,\"n_cut_keypoints\":%lu,\"n_cut_segments\":%lu,\"n_cut_points\":%lu,"
            "\"features\":[",
            (unsigned long)r->stats.cut, (unsigned long)r->stats.n_cut_keypoints,
            (unsigned long)r->stats.n_cut_segments, (unsigned long)r->stats.n_cut_points);
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
}

static void print_counters(FILE *f, int json, const bsf_decoder_stats_t *s, unsigned long gaps)
{
    if (json) {
        fprintf(f,
                "{\"counters\":{\"frames_ok\":%lu,\"metadata\":%lu,\"bad_crc\":%lu,"
                "\"malformed\":%lu,\"unsupported_version\":%lu,\"unknown_type\":%lu,"
                "\"oversize\":%lu,\"bytes_skipped\":%lu,\"seq_gaps\":%lu}}\n",
                (unsigned long)s->frames_ok, (unsigned long)s->metadata, (unsigned long)s->bad_crc,
                (unsigned long)s->malformed, (unsigned long)s->unsupported_version,
                (unsigned long)s->unknown_type, (unsigned long)s->oversize,
                (unsigned long)s->bytes_skipped, gaps);
    } else {
        fprintf(f,
                "frames ok %lu (metadata %lu), bad crc %lu, malformed %lu, unsupported version "
                "%lu, unknown type %lu, oversize %lu, bytes skipped %lu, missing by sequence %lu\n",
                (unsigned long)s->frames_ok, (unsigned long)s->metadata, (unsigned long)s->bad_crc,
                (unsigned long)s->malformed, (unsigned long)s->unsupported_version,
                (unsigned long)s->unknown_type, (unsigned long)s->oversize,
                (unsigned long)s->bytes_skipped, gaps);
    }
}

int cmd_decode(int argc, char **argv)
{
    const char *in_path = NULL;
    decode_ctx_t ctx;
    stream_summary_t sum;
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
    rc = decode_stream(in, in_path, print_frame, &ctx, &sum);
    close_in(in);
    if (rc != 0) {
        return EXIT_FAIL;
    }
    print_counters(stdout, ctx.json, &sum.stats, sum.seq_gaps + sum.map_seq_gaps);
    return close_out(stdout, "stdout") == 0 ? 0 : EXIT_FAIL;
}
