/* SPDX-License-Identifier: MIT */
/* popen/pclose for the gzip fallback */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include "carmen.h"
#include "carmen_number.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
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

/* Bytes read from the file (or the decompressor) per refill. Always this
 * many are asked for: zlib drops the data of a request that meets corrupt
 * input, so the same requests keep the same lines before a read error. */
#define CARMEN_BLOCK 65536u

#if CARMEN_MAX_BUFFER != CARMEN_MAX_LINE + CARMEN_BLOCK + 1u
#error "CARMEN_MAX_BUFFER must be the longest line, a block and a NUL"
#endif

/* No position yet (of a control byte in the line). */
#define CARMEN_NONE ((size_t)-1)

struct carmen_reader {
#ifdef BSF_HAVE_ZLIB
    gzFile gz;
#else
    FILE *file;
    int piped; /* file is a gzip -dc pipe */
#endif
    int want_gzip;    /* the name ends in .gz: the content must be gzip */
    int at_end;       /* the source reported end of data (and was checked) */
    int kind_checked; /* want_gzip was checked against the content */
    FILE *err;
    char *path;
    /* Data read and not yet consumed. Lines are parsed where they lie (the
     * newline becomes the NUL that ends the line's string); only the part
     * of a line that a refill cuts is moved, to the buffer's start. */
    char *buf;
    size_t buf_cap;  /* bytes allocated, grown for lines longer than a block */
    size_t buf_pos;  /* first byte of the next line */
    size_t buf_len;  /* bytes of data in buf */
    char *line;      /* current line (in buf), NUL-terminated */
    size_t line_len; /* bytes in line, without the newline */
    size_t bad_byte; /* 1 + column of the first control byte, 0: none */
    unsigned char bad_value;
    unsigned long line_no;
    unsigned long malformed;
    unsigned long overlong; /* lines longer than CARMEN_MAX_LINE */
    float ranges[CARMEN_MAX_BEAMS];
};

static int ends_with_gz(const char *path)
{
    const size_t n = strlen(path);
    return n >= 3u && strcmp(path + n - 3u, ".gz") == 0;
}

#ifndef BSF_HAVE_ZLIB
FILE *carmen_gzip_pipe(const char *path, const char *opts)
{
    size_t i, n = 0;
    FILE *f;
    char *cmd = malloc(4u * strlen(path) + strlen(opts) + 32u);
    if (cmd == NULL) {
        return NULL;
    }
    n += (size_t)sprintf(cmd, "gzip %s -- '", opts);
    for (i = 0; path[i] != '\0'; ++i) {
        if (path[i] == '\'') {
            memcpy(cmd + n, "'\\''", 4u);
            n += 4u;
        } else {
            cmd[n++] = path[i];
        }
    }
    memcpy(cmd + n, "' 2>/dev/null", 14u);
    f = popen(cmd, "r");
    free(cmd);
    return f;
}
#endif

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
    r->want_gzip = ends_with_gz(path);
    r->path = malloc(strlen(path) + 1u);
    /* room for a whole block after a cut line's first 4 KiB, and the final
     * NUL; longer lines grow the buffer */
    r->buf_cap = CARMEN_BLOCK + 4096u + 1u;
    r->buf = malloc(r->buf_cap);
    if (r->path == NULL || r->buf == NULL) {
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
    (void)gzbuffer(r->gz, CARMEN_BLOCK);
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
        /* gzip magic: decompress through gzip; its own complaints are
         * replaced by the reader's report. */
        fclose(r->file);
        r->file = carmen_gzip_pipe(path, "-dc");
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
    free(reader->buf);
    free(reader->path);
    free(reader);
}

unsigned long carmen_malformed_count(const carmen_reader_t *reader)
{
    return reader->malformed;
}

unsigned long carmen_overlong_count(const carmen_reader_t *reader)
{
    return reader->overlong;
}

size_t carmen_buffer_bytes(const carmen_reader_t *reader)
{
    return reader->buf_cap;
}

/* Reports a read error: where the data stopped and the last line that was
 * read whole (everything after it is lost). */
static void report_read_error(carmen_reader_t *r, const char *what)
{
    if (r->err != NULL) {
        fprintf(r->err, "%s:%lu: read error: %s; the last complete line is %lu\n", r->path,
                r->line_no + 1u, what, r->line_no);
    }
}

/* Checks that the data ended where the file says it ends: a gzip stream
 * complete with its trailer, a gzip -dc that exited 0, no I/O error.
 * Returns 0 when the end is genuine, -1 (reported) when data was lost. */
static int check_end(carmen_reader_t *r)
{
#ifdef BSF_HAVE_ZLIB
    int zerr = Z_OK;
    const char *msg = gzerror(r->gz, &zerr);
    if (zerr == Z_BUF_ERROR) {
        /* zlib's "unexpected end of file": the stream was cut */
        report_read_error(r, "gzip data truncated (unexpected end of file)");
        return -1;
    }
    if (zerr != Z_OK) {
        report_read_error(r, msg);
        return -1;
    }
#else
    if (ferror(r->file)) {
        report_read_error(r, "I/O error");
        return -1;
    }
    if (r->piped) {
        const int status = pclose(r->file);
        r->file = NULL;
        if (status != 0) {
            report_read_error(r, "gzip -dc failed: the gzip data is truncated or corrupt");
            return -1;
        }
    }
#endif
    return 0;
}

/* Reads up to a block more after the buffer's data (make_room gave the
 * space). Returns the number of bytes read, 0 at a checked end of data, -1
 * on a (reported) read error. */
static long refill(carmen_reader_t *r)
{
    long got;
    if (r->at_end) {
        return 0;
    }
    if (!r->kind_checked) {
        /* A .gz name promises gzip: plain text there is a file cut before
         * (or never given) its gzip header, not a log. */
        r->kind_checked = 1;
#ifdef BSF_HAVE_ZLIB
        if (r->want_gzip && gzdirect(r->gz)) {
#else
        if (r->want_gzip && !r->piped) {
#endif
            report_read_error(r, "not gzip data (empty or cut before the gzip header)");
            return -1;
        }
    }
#ifdef BSF_HAVE_ZLIB
    {
        const int n = gzread(r->gz, r->buf + r->buf_len, CARMEN_BLOCK);
        int zerr = Z_OK;
        (void)gzerror(r->gz, &zerr);
        if (n < 0 || (zerr != Z_OK && zerr != Z_BUF_ERROR)) {
            report_read_error(r, gzerror(r->gz, &zerr));
            return -1;
        }
        got = n;
    }
#else
    if (r->file == NULL) {
        return 0;
    }
    got = (long)fread(r->buf + r->buf_len, 1, CARMEN_BLOCK, r->file);
#endif
    if (got == 0) {
        /* Only a genuine end gives 0; a cut or failed source is an error,
         * never a shorter log. */
        if (check_end(r) != 0) {
            return -1;
        }
        r->at_end = 1;
        return 0;
    }
    r->buf_len += (size_t)got;
    return got;
}

/* Moves the unconsumed data (the start of a line) to the buffer's start and
 * makes room after it for a whole block and a NUL, growing the buffer for
 * a line longer than a block. Returns 0 or -1 (reported). */
static int make_room(carmen_reader_t *r)
{
    if (r->buf_pos > 0u) {
        memmove(r->buf, r->buf + r->buf_pos, r->buf_len - r->buf_pos);
        r->buf_len -= r->buf_pos;
        r->buf_pos = 0;
    }
    if (r->buf_cap - r->buf_len < CARMEN_BLOCK + 1u) {
        /* never beyond the longest line's room: read_line drops a longer
         * line before asking for more */
        const size_t cap =
            r->buf_cap < CARMEN_MAX_BUFFER / 2u ? 2u * r->buf_cap : (size_t)CARMEN_MAX_BUFFER;
        char *bigger = cap > r->buf_cap ? realloc(r->buf, cap) : NULL;
        if (bigger == NULL) {
            if (r->err != NULL) {
                fprintf(r->err, "%s:%lu: out of memory\n", r->path, r->line_no + 1u);
            }
            return -1;
        }
        r->buf = bigger;
        r->buf_cap = cap;
    }
    return 0;
}

/* Eight bytes at a time: does any of them need a closer look (a byte below
 * 0x20: newline, tab, CR or a control byte; or DEL)? Exact as a whole-word
 * test (the classic "has a byte less than n" and "has a zero byte"). */
static int word_needs_look(const unsigned char *p)
{
    const uint64_t ones = 0x0101010101010101u;
    const uint64_t highs = 0x8080808080808080u;
    uint64_t w, del;
    memcpy(&w, p, sizeof w);
    del = w ^ (ones * 0x7fu);
    return (((w - ones * 0x20u) & ~w) | ((del - ones) & ~del)) & highs ? 1 : 0;
}

/* The first newline in buf[i, n), or n. Notes on the way, as offsets from
 * the line's start `from`, the first control byte other than tab and CR
 * (and its value) and the first CR. */
static size_t find_line_end(const carmen_reader_t *r, size_t i, size_t from, size_t *first_ctrl,
                            unsigned char *ctrl_value, size_t *first_cr)
{
    const unsigned char *b = (const unsigned char *)r->buf;
    const size_t n = r->buf_len;
    while (i < n) {
        size_t stop;
        if (n - i >= 8u) {
            if (!word_needs_look(b + i)) {
                i += 8u;
                continue;
            }
            stop = i + 8u;
        } else {
            stop = n;
        }
        for (; i < stop; ++i) {
            const unsigned char c = b[i];
            if (c >= 0x20u && c != 0x7fu) {
                continue;
            }
            if (c == '\n') {
                return i;
            }
            if (c == '\r') {
                if (*first_cr == CARMEN_NONE) {
                    *first_cr = i - from;
                }
            } else if (c != '\t' && *first_ctrl == CARMEN_NONE) {
                *first_ctrl = i - from;
                *ctrl_value = c;
            }
        }
    }
    return n;
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

/* Reads and drops the rest of an overlong line (its first bytes are
 * already dropped), a block at a time in the buffer's fixed room, up to and
 * including its newline. Returns 1 (the next line starts at buf_pos), 0 at
 * the end of the data (the overlong line was the last), -1 on a (reported)
 * read error. */
static int skip_rest_of_line(carmen_reader_t *r)
{
    for (;;) {
        const char *nl;
        long got;
        r->buf_pos = r->buf_len = 0;
        got = refill(r);
        if (got <= 0) {
            if (got == 0) {
                ++r->line_no; /* the last line, ended by the end of the data */
            }
            return (int)got;
        }
        nl = memchr(r->buf, '\n', r->buf_len);
        if (nl != NULL) {
            r->buf_pos = (size_t)(nl - r->buf) + 1u;
            ++r->line_no;
            return 1;
        }
    }
}

/* Reports the line being read as longer than CARMEN_MAX_LINE (it is line
 * line_no + 1: line_no counts the lines read whole). */
static void report_overlong(carmen_reader_t *r)
{
    ++r->line_no;
    report(r, "line longer than %lu bytes (no CARMEN message is): skipped",
           (unsigned long)CARMEN_MAX_LINE);
    --r->line_no;
    ++r->overlong;
}

/* Finds the next whole line (without its newline) in the buffer, reading
 * more as needed: reader->line, NUL-terminated. Every byte up to the
 * newline belongs to the line, NUL included. A line longer than
 * CARMEN_MAX_LINE is reported and skipped without keeping more than that
 * much of it. Returns 1, 0 at end of file, -1 on error (the partial last
 * line of a cut file is lost and reported, never returned). */
static int read_line(carmen_reader_t *r)
{
    size_t seen = 0; /* bytes of the line looked at so far */
    size_t first_ctrl = CARMEN_NONE, first_cr = CARMEN_NONE;
    unsigned char ctrl_value = 0;
    size_t end, next;
    for (;;) {
        end = find_line_end(r, r->buf_pos + seen, r->buf_pos, &first_ctrl, &ctrl_value, &first_cr);
        if (end < r->buf_len) {
            if (end - r->buf_pos > CARMEN_MAX_LINE) {
                report_overlong(r);
                ++r->line_no;
                r->buf_pos = end + 1u;
                seen = 0;
                first_ctrl = first_cr = CARMEN_NONE;
                continue;
            }
            next = end + 1u;
            break;
        }
        seen = r->buf_len - r->buf_pos;
        if (seen > CARMEN_MAX_LINE) {
            /* Condemned before its newline: never buffered further. */
            int rc;
            report_overlong(r);
            rc = skip_rest_of_line(r);
            if (rc <= 0) {
                return rc;
            }
            seen = 0;
            first_ctrl = first_cr = CARMEN_NONE;
            continue;
        }
        {
            long got;
            if (make_room(r) != 0) {
                return -1;
            }
            got = refill(r);
            if (got < 0) {
                return -1;
            }
            if (got == 0) {
                if (r->buf_len == r->buf_pos) {
                    return 0;
                }
                end = next = r->buf_len; /* last line without a newline, end checked */
                if (end - r->buf_pos > CARMEN_MAX_LINE) {
                    report_overlong(r);
                    ++r->line_no;
                    return 0;
                }
                break;
            }
        }
    }
    r->line = r->buf + r->buf_pos;
    r->line_len = end - r->buf_pos;
    r->buf_pos = next;
    if (r->line_len > 0 && r->line[r->line_len - 1u] == '\r') {
        --r->line_len;
    }
    r->line[r->line_len] = '\0';
    /* A control byte makes the line malformed; a CR anywhere but at the end
     * is one too, reported when there is no other. */
    r->bad_byte = 0;
    if (first_ctrl != CARMEN_NONE) {
        r->bad_byte = first_ctrl + 1u;
        r->bad_value = ctrl_value;
    } else if (first_cr != CARMEN_NONE && first_cr < r->line_len) {
        r->bad_byte = first_cr + 1u;
        r->bad_value = '\r';
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

/* Moves the cursor to the next field's first byte (or the end). */
static const char *skip_blanks(fields_t *f)
{
    while (*f->p == ' ' || *f->p == '\t') {
        ++f->p;
    }
    return f->p;
}

static double get_double(fields_t *f, const char *name)
{
    size_t len;
    char *end;
    const char *t;
    const char *fast_end;
    double v;
    if (f->what != NULL) {
        return 0.0;
    }
    if (carmen_parse_double(skip_blanks(f), &fast_end, &v)) {
        f->p = fast_end;
        return v;
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
    const char *fast_end;
    float v;
    if (f->what != NULL) {
        return 0.0f;
    }
    if (carmen_parse_float(skip_blanks(f), &fast_end, &v)) {
        f->p = fast_end;
        return v;
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
    const char *fast_end;
    long v;
    if (f->what != NULL) {
        return 0;
    }
    if (carmen_parse_count(skip_blanks(f), &fast_end, &v)) {
        f->p = fast_end;
        return v;
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
    {
        /* The readings are most of the log: the fast path inline, with the
         * cursor in a local; anything it leaves goes through get_float. */
        const char *p = f->p;
        float *out = r->ranges;
        for (i = 0; i < n; ++i) {
            const char *end;
            while (*p == ' ' || *p == '\t') {
                ++p;
            }
            if (carmen_parse_short_float(p, &end, &out[i]) ||
                carmen_parse_float(p, &end, &out[i])) {
                p = end;
                continue;
            }
            f->p = p;
            out[i] = get_float(f, "range reading");
            if (f->what != NULL) {
                return 0;
            }
            p = f->p;
        }
        f->p = p;
    }
    return 1;
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
        if (reader->bad_byte != 0u) {
            /* Binary damage: whatever the line says, it cannot be trusted. */
            report(reader, "control byte 0x%02x at column %lu", (unsigned)reader->bad_value,
                   (unsigned long)reader->bad_byte);
            continue;
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
