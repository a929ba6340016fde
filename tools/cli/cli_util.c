/* SPDX-License-Identifier: MIT */
/*
 * cli_util.c - what every bsf command shares: messages, option parsing,
 * files and standard streams, progress on a terminal, opening a log.
 */
#include "tool.h"

#include <sys/stat.h>

const char *g_cmd = TOOL_NAME;

void fail_msg(const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "%s: ", g_cmd);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

/* The code point of the bidirectional formatting character UTF-8 encoded at
 * p, or 0. All of them are three bytes long but U+061C (two). */
static unsigned bidi_control_at(const unsigned char *p)
{
    if (p[0] == 0xD8u && p[1] == 0x9Cu) {
        return 0x061Cu;
    }
    if (p[0] == 0xE2u && p[1] == 0x80u &&
        ((p[2] >= 0x8Eu && p[2] <= 0x8Fu) || (p[2] >= 0xAAu && p[2] <= 0xAEu))) {
        return 0x2000u + (p[2] - 0x80u);
    }
    if (p[0] == 0xE2u && p[1] == 0x81u && p[2] >= 0xA6u && p[2] <= 0xA9u) {
        return 0x2040u + (p[2] - 0x80u);
    }
    return 0u;
}

void print_json_string(FILE *f, const char *s)
{
    const unsigned char *p = (const unsigned char *)s;
    fputc('"', f);
    while (*p != '\0') {
        const unsigned bidi = bidi_control_at(p);
        if (bidi != 0u) {
            fprintf(f, "\\u%04x", bidi);
            p += bidi == 0x061Cu ? 2 : 3;
            continue;
        }
        if (*p == '"' || *p == '\\') {
            fputc('\\', f);
            fputc(*p, f);
        } else if (*p < 0x20u || *p == 0x7Fu) {
            fprintf(f, "\\u%04x", (unsigned)*p);
        } else {
            fputc(*p, f);
        }
        ++p;
    }
    fputc('"', f);
}

int usage_error(const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "%s: ", g_cmd);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\nTry '%s --help'.\n", g_cmd);
    return EXIT_USAGE;
}

double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- argument helpers ----------------------------------------------------- */

int parse_long(const char *s, long lo, long hi, long *out)
{
    char *end = NULL;
    long v;
    errno = 0;
    v = strtol(s, &end, 10);
    if (errno != 0 || end == s || *end != '\0' || v < lo || v > hi) {
        return -1;
    }
    *out = v;
    return 0;
}

int parse_float(const char *s, double lo, double hi, double *out)
{
    char *end = NULL;
    double v;
    errno = 0;
    v = strtod(s, &end);
    if (errno != 0 || end == s || *end != '\0' || !isfinite(v) || v < lo || v > hi) {
        return -1;
    }
    *out = v;
    return 0;
}

/* Option value: "--opt=v" or "--opt v". Returns the value or NULL (and sets *err). */
const char *opt_value(int argc, char **argv, int *i, const char *name, int *err)
{
    const size_t n = strlen(name);
    if (strncmp(argv[*i], name, n) != 0) {
        return NULL;
    }
    if (argv[*i][n] == '=') {
        return argv[*i] + n + 1;
    }
    if (argv[*i][n] != '\0') {
        return NULL;
    }
    if (*i + 1 >= argc) {
        *err = usage_error("option %s needs a value", name);
        return NULL;
    }
    ++*i;
    return argv[*i];
}

int draw_option(int argc, char **argv, int *i, draw_opts_t *o, int *err)
{
    const char *v;
    if ((v = opt_value(argc, argv, i, "-o", err)) != NULL) {
        o->out_path = v;
    } else if ((v = opt_value(argc, argv, i, "--points", err)) != NULL) {
        o->points = v;
    } else if ((v = opt_value(argc, argv, i, "--prior", err)) != NULL) {
        o->prior = v;
    } else if ((v = opt_value(argc, argv, i, "--width", err)) != NULL) {
        if (parse_float(v, 100.0, 20000.0, &o->width) != 0) {
            *err = usage_error("--width needs pixels in [100, 20000], got '%s'", v);
        }
    } else {
        return *err != 0;
    }
    return 1;
}

int is_help(const char *a)
{
    return strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0;
}

/* ---- byte streams ------------------------------------------------------------ */

/* 1 (with a message) when path names a directory. */
static int is_directory(const char *path, const char *what)
{
    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
        fail_msg("%s is a directory, not %s", path, what);
        return 1;
    }
    return 0;
}

FILE *open_in(const char *path)
{
    FILE *f;
    if (strcmp(path, "-") == 0) {
        return stdin;
    }
    if (is_directory(path, "a bsf stream")) {
        return NULL;
    }
    f = fopen(path, "rb");
    if (f == NULL) {
        fail_msg("cannot open %s: %s", path, strerror(errno));
    }
    return f;
}

FILE *open_out(const char *path, int binary)
{
    FILE *f;
    if (strcmp(path, "-") == 0) {
        if (binary && isatty(fileno(stdout))) {
            fail_msg("refusing to write a binary stream to a terminal (use -o FILE or a pipe)");
            return NULL;
        }
        return stdout;
    }
    f = fopen(path, binary ? "wb" : "w");
    if (f == NULL) {
        fail_msg("cannot create %s: %s", path, strerror(errno));
    }
    return f;
}

int close_out(FILE *f, const char *path)
{
    int bad = ferror(f);
    if (f == stdout) {
        bad |= fflush(f) != 0;
    } else {
        bad |= fclose(f) != 0;
    }
    if (bad) {
        fail_msg("write error on %s", path);
        return -1;
    }
    return 0;
}

/* ---- progress ---------------------------------------------------------------- */

void progress_init(progress_t *p)
{
    p->enabled = isatty(fileno(stderr));
    p->t0 = p->last = now_s();
}

void progress_tick(progress_t *p, unsigned long done, const char *what)
{
    double t;
    if (!p->enabled) {
        return;
    }
    t = now_s();
    if (t - p->last < 0.25) {
        return;
    }
    p->last = t;
    fprintf(stderr, "\r%s: %lu scans, %.0f scans/s   ", what, done,
            (double)done / (t - p->t0 > 1e-9 ? t - p->t0 : 1e-9));
}

void progress_end(progress_t *p)
{
    if (p->enabled) {
        fputs("\r\033[K", stderr);
    }
}

carmen_reader_t *open_log(const char *path)
{
    carmen_reader_t *rd;
    if (strcmp(path, "-") != 0 && is_directory(path, "a CARMEN log")) {
        return NULL;
    }
    errno = 0;
    rd = carmen_open(path, stderr);
    if (rd == NULL) {
        fail_msg("cannot open log %s: %s", path, errno ? strerror(errno) : "unreadable");
    }
    return rd;
}
