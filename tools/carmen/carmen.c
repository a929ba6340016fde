/* SPDX-License-Identifier: MIT */
/* popen/pclose for the gzip fallback */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include "carmen.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifdef BSF_HAVE_ZLIB
#include <zlib.h>
#else
/* Without zlib, a gzip file is read through the system's gzip (always
 * present on Debian: it is an essential package). */
#include <stdio.h>
#endif

#define CARMEN_PI 3.14159265358979323846
#define CARMEN_FLASER_MAX_RANGE 80.0f

struct carmen_reader {
#ifdef BSF_HAVE_ZLIB
    gzFile gz;
#else
    FILE *file;
    int piped; /* file is a gzip -dc pipe */
#endif
    FILE *err;
    char *path;
    char *line; /* current line, grown as needed */
    size_t line_cap;
    unsigned long line_no;
    unsigned long malformed;
    float ranges[CARMEN_MAX_BEAMS];
};

carmen_reader_t *carmen_open(const char *path, FILE *err)
{
    carmen_reader_t *r;
    if (path == NULL) {
        errno = EINVAL;
        return NULL;
    }
    r = calloc(1, sizeof *r);
    if (r == NULL) {
        return NULL;
    }
    r->err = err;
    r->path = malloc(strlen(path) + 1u);
    r->line_cap = 4096;
    r->line = malloc(r->line_cap);
    if (r->path == NULL || r->line == NULL) {
        carmen_close(r);
        return NULL;
    }
    strcpy(r->path, path);
#ifdef BSF_HAVE_ZLIB
    /* "-": standard input, plain or gzip (gzdopen reads both). */
    r->gz = strcmp(path, "-") == 0 ? gzdopen(dup(STDIN_FILENO), "rb") : gzopen(path, "rb");
    if (r->gz == NULL) {
        carmen_close(r);
        return NULL;
    }
#else
    if (strcmp(path, "-") == 0) {
        /* standard input through gzip -dcf, which passes plain text as is */
        r->file = popen("gzip -dcf", "r");
        r->piped = 1;
        if (r->file == NULL) {
            carmen_close(r);
            return NULL;
        }
        return r;
    }
    r->file = fopen(path, "rb");
    if (r->file == NULL) {
        carmen_close(r);
        return NULL;
    }
    if (fgetc(r->file) == 0x1f && fgetc(r->file) == 0x8b) {
        /* gzip magic: decompress through gzip, the path single-quoted */
        size_t i, n = 0;
        char *cmd = malloc(4u * strlen(path) + 32u);
        if (cmd == NULL) {
            carmen_close(r);
            return NULL;
        }
        fclose(r->file);
        r->file = NULL;
        n += (size_t)sprintf(cmd, "gzip -dc -- '");
        for (i = 0; path[i] != '\0'; ++i) {
            if (path[i] == '\'') {
                memcpy(cmd + n, "'\\''", 4u);
                n += 4u;
            } else {
                cmd[n++] = path[i];
            }
        }
        memcpy(cmd + n, "'", 2u);
        r->file = popen(cmd, "r");
        free(cmd);
        r->piped = 1;
        if (r->file == NULL) {
            carmen_close(r);
            return NULL;
        }
    } else {
        rewind(r->file);
    }
#endif
    return r;
}

void carmen_close(carmen_reader_t *reader)
{
    if (reader == NULL) {
        return;
    }
#ifdef BSF_HAVE_ZLIB
    if (reader->gz != NULL) {
        gzclose(reader->gz);
    }
#else
    if (reader->file != NULL) {
        if (reader->piped) {
            (void)pclose(reader->file);
        } else {
            fclose(reader->file);
        }
    }
#endif
    free(reader->line);
    free(reader->path);
    free(reader);
}

unsigned long carmen_malformed_count(const carmen_reader_t *reader)
{
    return reader->malformed;
}

/* Read one whole line (without its newline) into reader->line, growing the
 * buffer for long lines. Returns 1, 0 at end of file, -1 on error. */
static int read_line(carmen_reader_t *r)
{
    size_t len = 0;
    for (;;) {
        size_t got;
#ifdef BSF_HAVE_ZLIB
        if (gzgets(r->gz, r->line + len, (int)(r->line_cap - len)) == NULL) {
            int zerr = 0;
            const char *msg = gzerror(r->gz, &zerr);
            if (zerr != Z_OK && zerr != Z_BUF_ERROR) {
#else
        if (fgets(r->line + len, (int)(r->line_cap - len), r->file) == NULL) {
            const char *msg = "I/O error";
            if (ferror(r->file)) {
#endif
                if (r->err != NULL) {
                    fprintf(r->err, "%s:%lu: read error: %s\n", r->path, r->line_no + 1u, msg);
                }
                return -1;
            }
            if (len == 0) {
                return 0;
            }
            break; /* last line without a newline */
        }
        got = strlen(r->line + len);
        len += got;
        if (len > 0 && r->line[len - 1u] == '\n') {
            r->line[--len] = '\0';
            break;
        }
        if (len + 1u < r->line_cap) {
#ifdef BSF_HAVE_ZLIB
            if (gzeof(r->gz)) {
                break;
            }
#else
            if (feof(r->file)) {
                break;
            }
#endif
            continue;
        }
        {
            char *bigger = realloc(r->line, r->line_cap * 2u);
            if (bigger == NULL) {
                if (r->err != NULL) {
                    fprintf(r->err, "%s:%lu: out of memory\n", r->path, r->line_no + 1u);
                }
                return -1;
            }
            r->line = bigger;
            r->line_cap *= 2u;
        }
    }
    if (len > 0 && r->line[len - 1u] == '\r') {
        r->line[--len] = '\0';
    }
    ++r->line_no;
    return 1;
}

/* A cursor over the blank-separated fields of one line. */
typedef struct {
    const char *p;
    const char *what; /* first problem met, NULL while all is well */
} fields_t;

static const char *next_token(fields_t *f, size_t *len)
{
    const char *s = f->p;
    while (*s == ' ' || *s == '\t') {
        ++s;
    }
    if (*s == '\0') {
        return NULL;
    }
    f->p = s;
    while (*f->p != '\0' && *f->p != ' ' && *f->p != '\t') {
        ++f->p;
    }
    *len = (size_t)(f->p - s);
    return s;
}

static double get_double(fields_t *f, const char *name)
{
    size_t len;
    char *end;
    const char *t;
    double v;
    if (f->what != NULL) {
        return 0.0;
    }
    t = next_token(f, &len);
    if (t == NULL) {
        f->what = name;
        return 0.0;
    }
    v = strtod(t, &end);
    if (end != t + len) {
        f->what = name;
        return 0.0;
    }
    return v;
}

static float get_float(fields_t *f, const char *name)
{
    size_t len;
    char *end;
    const char *t;
    float v;
    if (f->what != NULL) {
        return 0.0f;
    }
    t = next_token(f, &len);
    if (t == NULL) {
        f->what = name;
        return 0.0f;
    }
    v = strtof(t, &end);
    if (end != t + len) {
        f->what = name;
        return 0.0f;
    }
    return v;
}

/* A count: a non-negative integer written without fraction. */
static long get_count(fields_t *f, const char *name)
{
    size_t len;
    char *end;
    const char *t;
    long v;
    if (f->what != NULL) {
        return 0;
    }
    t = next_token(f, &len);
    if (t == NULL) {
        f->what = name;
        return 0;
    }
    v = strtol(t, &end, 10);
    if (end != t + len || v < 0) {
        f->what = name;
        return 0;
    }
    return v;
}

static void skip_field(fields_t *f, const char *name)
{
    size_t len;
    if (f->what == NULL && next_token(f, &len) == NULL) {
        f->what = name;
    }
}

#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 2, 3)))
#endif
static void
report(carmen_reader_t *r, const char *fmt, ...)
{
    va_list ap;
    ++r->malformed;
    if (r->err != NULL) {
        fprintf(r->err, "%s:%lu: ", r->path, r->line_no);
        va_start(ap, fmt);
        vfprintf(r->err, fmt, ap);
        va_end(ap);
        fputc('\n', r->err);
    }
}

/* Ranges: count readings into r->ranges. Returns 0 when the line is bad. */
static int get_ranges(carmen_reader_t *r, fields_t *f, long n, const char *type)
{
    long i;
    if (f->what != NULL) {
        return 0;
    }
    if (n < 1 || n > CARMEN_MAX_BEAMS) {
        report(r, "%s: beam count %ld outside 1..8192", type, n);
        return 0;
    }
    for (i = 0; i < n; ++i) {
        r->ranges[i] = get_float(f, "range reading");
    }
    return f->what == NULL;
}

static int parse_flaser(carmen_reader_t *r, fields_t *f, carmen_scan_t *s)
{
    const long n = get_count(f, "beam count");
    if (!get_ranges(r, f, n, "FLASER")) {
        return f->what != NULL ? -1 : 0;
    }
    s->type = CARMEN_FLASER;
    s->count = (size_t)n;
    s->angle_min = (float)(-CARMEN_PI / 2.0);
    if (n == 180 || n == 181) {
        s->angle_increment = (float)(CARMEN_PI / 180.0);
    } else if (n == 360 || n == 361) {
        s->angle_increment = (float)(CARMEN_PI / 360.0);
    } else if (n >= 2) {
        s->angle_increment = (float)(CARMEN_PI / (double)(n - 1));
    } else {
        s->angle_increment = (float)CARMEN_PI;
    }
    s->max_range = CARMEN_FLASER_MAX_RANGE;
    s->laser_pose.x = get_double(f, "x");
    s->laser_pose.y = get_double(f, "y");
    s->laser_pose.theta = get_double(f, "theta");
    s->robot_pose.x = get_double(f, "odom_x");
    s->robot_pose.y = get_double(f, "odom_y");
    s->robot_pose.theta = get_double(f, "odom_theta");
    s->timestamp = get_double(f, "ipc_time");
    return f->what != NULL ? -1 : 1;
}

static int parse_robotlaser1(carmen_reader_t *r, fields_t *f, carmen_scan_t *s)
{
    long n, m, i;
    double start, res, maxr;
    skip_field(f, "laser type");
    start = get_double(f, "start angle");
    skip_field(f, "fov");
    res = get_double(f, "angular resolution");
    maxr = get_double(f, "max range");
    skip_field(f, "accuracy");
    skip_field(f, "remission mode");
    n = get_count(f, "beam count");
    /* Checked as the float the scan carries: 1e-50 is non-zero but becomes 0,
     * and a finite double beyond FLT_MAX would not convert at all. */
    if (f->what == NULL && !(isfinite(start) && fabs(start) <= (double)FLT_MAX && isfinite(res) &&
                             fabs(res) <= (double)FLT_MAX && (float)res != 0.0f)) {
        report(r, "ROBOTLASER1: angular resolution or start angle is zero or not finite");
        return 0;
    }
    if (isfinite(maxr) && fabs(maxr) > (double)FLT_MAX) {
        maxr = maxr > 0.0 ? HUGE_VAL : -HUGE_VAL;
    }
    if (!get_ranges(r, f, n, "ROBOTLASER1")) {
        return f->what != NULL ? -1 : 0;
    }
    m = get_count(f, "remission count");
    for (i = 0; i < m && f->what == NULL; ++i) {
        skip_field(f, "remission value");
    }
    s->type = CARMEN_ROBOTLASER1;
    s->count = (size_t)n;
    s->angle_min = (float)start;
    s->angle_increment = (float)res;
    s->max_range = (float)maxr;
    s->laser_pose.x = get_double(f, "laser x");
    s->laser_pose.y = get_double(f, "laser y");
    s->laser_pose.theta = get_double(f, "laser theta");
    s->robot_pose.x = get_double(f, "robot x");
    s->robot_pose.y = get_double(f, "robot y");
    s->robot_pose.theta = get_double(f, "robot theta");
    skip_field(f, "tv");
    skip_field(f, "rv");
    skip_field(f, "forward safety distance");
    skip_field(f, "side safety distance");
    skip_field(f, "turn axis");
    s->timestamp = get_double(f, "ipc_time");
    return f->what != NULL ? -1 : 1;
}

int carmen_next(carmen_reader_t *reader, carmen_scan_t *scan)
{
    for (;;) {
        fields_t f;
        size_t len;
        const char *type;
        int got;
        int rc = read_line(reader);
        if (rc <= 0) {
            return rc;
        }
        f.p = reader->line;
        f.what = NULL;
        type = next_token(&f, &len);
        if (type == NULL || type[0] == '#') {
            continue;
        }
        if (len == 6 && strncmp(type, "FLASER", 6) == 0) {
            got = parse_flaser(reader, &f, scan);
        } else if (len == 11 && strncmp(type, "ROBOTLASER1", 11) == 0) {
            got = parse_robotlaser1(reader, &f, scan);
        } else {
            continue;
        }
        if (got == 1) {
            scan->ranges = reader->ranges;
            scan->line = reader->line_no;
            return 1;
        }
        if (got < 0) {
            /* A field was missing or not a number. */
            report(reader, "%s: missing or bad field: %s", len == 6 ? "FLASER" : "ROBOTLASER1",
                   f.what);
        }
    }
}

float carmen_valid_range_max(const carmen_scan_t *scan)
{
    const float declared = scan->max_range;
    if (!(declared > 0.0f) || !(declared < CARMEN_NO_RETURN_FLOOR)) {
        return CARMEN_NO_RETURN_FLOOR; /* also for NaN and infinity */
    }
    return declared;
}
