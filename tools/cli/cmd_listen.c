/* SPDX-License-Identifier: MIT */
/*
 * cmd_listen.c - bsf listen: decode a live byte stream (a serial port, a pipe,
 * stdin) and print every frame the moment its delimiter arrives.
 *
 * Its own read loop: read(2) returns whatever the device has (never waits to
 * fill a buffer), every chunk goes through bsf_decoder_feed() and out to the
 * --save file at once, and stdout is flushed after each frame, so a reader at
 * the other end of a pipe sees frames as the sender produces them.
 */
#include "tool.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <termios.h>

static const char listen_help[] =
    "Usage: bsf listen DEVICE|- [--baud N] [-o FILE] [--features] [--count N]\n"
    "Decode a live bsf stream from a serial port, a named pipe or stdin ('-') and\n"
    "print one line per frame as soon as it arrives, with the decoder's counters;\n"
    "at the end (end of input, --count frames, or Ctrl-C) the final counters.\n"
    "\n"
    "  --baud N      on a terminal device: raw mode, 8N1, N baud (a standard rate:\n"
    "                9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600, ...);\n"
    "                default 115200. Ignored (with a note) on pipes and files.\n"
    "  -o, --save FILE  also write every byte received, unchanged, to FILE\n"
    "  --features    one more line per feature (kind, beams, E_curve, control points)\n"
    "  --count N     stop after N features or map frames delivered\n"
    "\n"
    "Frame line: seq, time stamp, pose, features, control points, vertices, bytes\n"
    "on the wire, then ok/dropped counters so far and frames missing by sequence.\n"
    "Map line (a map stream, bsf extract --map): the map frame's seq, how many map\n"
    "features it created, extended, moved, merged and removed in the receiver's\n"
    "map, snapshots, the pose it carried, records the receiver could not apply,\n"
    "bytes, then the receiver's totals: features, flagged (features it cannot\n"
    "vouch for since a lost frame, or whose record could not apply), absent (ids\n"
    "sent but never received) and map frames missing.\n";

typedef struct {
    long baud;
    speed_t code;
} baud_rate_t;

/* The standard rates termios knows on this system (B* constants). */
static const baud_rate_t baud_rates[] = {
    {1200, B1200},       {2400, B2400},   {4800, B4800},
    {9600, B9600},       {19200, B19200}, {38400, B38400},
#ifdef B57600
    {57600, B57600},
#endif
#ifdef B115200
    {115200, B115200},
#endif
#ifdef B230400
    {230400, B230400},
#endif
#ifdef B460800
    {460800, B460800},
#endif
#ifdef B500000
    {500000, B500000},
#endif
#ifdef B921600
    {921600, B921600},
#endif
#ifdef B1000000
    {1000000, B1000000},
#endif
#ifdef B1500000
    {1500000, B1500000},
#endif
#ifdef B2000000
    {2000000, B2000000},
#endif
#ifdef B3000000
    {3000000, B3000000},
#endif
#ifdef B4000000
    {4000000, B4000000},
#endif
};

static int baud_code(long baud, speed_t *code)
{
    size_t i;
    for (i = 0; i < sizeof baud_rates / sizeof baud_rates[0]; ++i) {
        if (baud_rates[i].baud == baud) {
            *code = baud_rates[i].code;
            return 0;
        }
    }
    return -1;
}

/* Raw 8N1 at the given speed: no echo, no line editing, no translation of
 * bytes (0x0D, 0x11, 0x13 and 0x00 are data here), reads return what is there. */
static int set_raw_tty(int fd, const char *name, speed_t code)
{
    struct termios t;
    if (tcgetattr(fd, &t) != 0) {
        fail_msg("%s: cannot read the terminal settings: %s", name, strerror(errno));
        return -1;
    }
    t.c_iflag &= ~(tcflag_t)(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON |
                             IXOFF | INPCK);
    t.c_oflag &= ~(tcflag_t)OPOST;
    t.c_lflag &= ~(tcflag_t)(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
    t.c_cflag &= ~(tcflag_t)(CSIZE | PARENB | CSTOPB);
    t.c_cflag |= (tcflag_t)(CS8 | CREAD | CLOCAL);
    t.c_cc[VMIN] = 1;
    t.c_cc[VTIME] = 0;
    if (cfsetispeed(&t, code) != 0 || cfsetospeed(&t, code) != 0 ||
        tcsetattr(fd, TCSANOW, &t) != 0) {
        fail_msg("%s: cannot set raw mode at that baud rate: %s", name, strerror(errno));
        return -1;
    }
    return 0;
}

static volatile sig_atomic_t g_stop;

static void on_signal(int sig)
{
    (void)sig;
    g_stop = 1;
}

typedef struct {
    int features;
    unsigned long frames; /* scans and map frames delivered */
    unsigned long seq_gaps;
    int have_seq;
    uint32_t last_seq;
    map_view_t map; /* the receiver's map, from the first map frame on */
    int have_map;
    unsigned long map_features; /* features the receiver holds */
    unsigned long map_seq_gaps;
    int have_map_seq;
    uint32_t last_map_seq;
} listen_state_t;

static unsigned long dropped(const bsf_decoder_stats_t *s)
{
    return (unsigned long)s->bad_crc + (unsigned long)s->malformed +
           (unsigned long)s->unsupported_version + (unsigned long)s->oversize;
}

static void print_frame_line(listen_state_t *ls, const bsf_frame_t *fr, size_t bytes,
                             const bsf_decoder_stats_t *s)
{
    const bsf_result_t *r = &fr->result;
    size_t i, k, vertices = 0;
    for (k = 0; k + 1u < r->n_ctrl; ++k) {
        if (r->ctrl_is_vertex[k] && r->ctrl_is_vertex[k + 1u]) {
            ++vertices;
            ++k;
        }
    }
    printf("frame seq=%lu t=%.3f pose=", (unsigned long)fr->seq, 1e-3 * (double)fr->timestamp_ms);
    if (fr->has_pose) {
        printf("(%.3f,%.3f,%.4f)", (double)fr->pose.x, (double)fr->pose.y, (double)fr->pose.theta);
    } else {
        fputs("none", stdout);
    }
    printf(" features=%u ctrl=%lu vertices=%zu bytes=%zu | ok=%lu dropped=%lu missing=%lu\n",
           (unsigned)r->n_features, (unsigned long)r->n_ctrl, vertices, bytes,
           (unsigned long)s->frames_ok, dropped(s), ls->seq_gaps);
    if (!ls->features) {
        return;
    }
    for (i = 0; i < r->n_features; ++i) {
        const bsf_feature_t *f = &r->features[i];
        printf("  feature %zu %s beams=%u..%u points=%u e_curve=%.4f ctrl=", i,
               f->kind == BSF_FEATURE_AUXILIARY ? "auxiliary" : "bleak", (unsigned)f->first_beam,
               (unsigned)f->last_beam, (unsigned)f->n_points, (double)f->e_curve);
        for (k = 0; k < f->n_ctrl; ++k) {
            const size_t j = (size_t)f->ctrl_first + k;
            printf("%s(%.4f,%.4f)%s", k ? " " : "", (double)r->ctrl[j].x, (double)r->ctrl[j].y,
                   r->ctrl_is_vertex[j] ? "v" : "");
        }
        putchar('\n');
    }
}

/* What produced the stream: a sender repeats it, so a receiver that joins a
 * live link late learns it within a few frames. */
static void print_metadata_line(const bsf_frame_t *fr, size_t bytes, const bsf_decoder_stats_t *s)
{
    const bsf_metadata_t *m = &fr->metadata;
    const char *method = bsf_method_name((bsf_method_t)m->method);
    printf("metadata library=%u.%u.%u method=%s beams=%lu angle_min=%.6f angle_increment=%.6f "
           "range=%.3f..%.3f quant=%.4f source=",
           (unsigned)m->lib_version_major, (unsigned)m->lib_version_minor,
           (unsigned)m->lib_version_patch, method != NULL ? method : "unknown",
           (unsigned long)m->n_beams, (double)m->angle_min, (double)m->angle_increment,
           (double)m->range_min, (double)m->range_max, (double)m->quant_step);
    /* the sender's text, escaped as decode --json writes it */
    if (m->source_len > 0u) {
        print_json_string(stdout, m->source);
    } else {
        fputs("none", stdout);
    }
    printf(" bytes=%zu | ok=%lu dropped=%lu\n", bytes, (unsigned long)s->frames_ok, dropped(s));
}

static void note_seq(listen_state_t *ls, uint32_t seq)
{
    if (ls->have_seq && seq != ls->last_seq + 1u) {
        const uint32_t gap = seq - ls->last_seq - 1u;
        if (gap < 0x80000000u) { /* a restarted sender is not a loss */
            ls->seq_gaps += gap;
        }
    }
    ls->have_seq = 1;
    ls->last_seq = seq;
}

/* Features the receiver cannot vouch for (unconfirmed after a loss, or
 * stale) and ids it knows were sent but never got (missing). */
static void map_flags(const bsf_map_rx_t *rx, unsigned long *flagged, unsigned long *absent)
{
    const uint32_t limit = bsf_map_rx_id_limit(rx);
    uint32_t id;
    *flagged = 0u;
    *absent = 0u;
    for (id = 0; id < limit; ++id) {
        const int st = bsf_map_rx_feature_state(rx, id);
        *flagged += st == BSF_MAP_RX_UNCONFIRMED || st == BSF_MAP_RX_STALE;
        *absent += st == BSF_MAP_RX_MISSING;
    }
}

/* A map frame into the receiver's map, and its line. -1 out of memory. */
static int map_frame(listen_state_t *ls, const bsf_frame_t *fr, size_t bytes,
                     const bsf_decoder_stats_t *s)
{
    map_change_t c;
    unsigned long flagged;
    unsigned long absent;
    const unsigned long poses_before = ls->have_map ? ls->map.n_path : 0u;
    if (!ls->have_map) {
        if (map_view_init(&ls->map, 1) != 0) {
            return -1;
        }
        ls->have_map = 1;
    }
    if (ls->have_map_seq && fr->seq != ls->last_map_seq + 1u) {
        const uint32_t gap = fr->seq - ls->last_map_seq - 1u;
        if (gap < 0x80000000u) {
            ls->map_seq_gaps += gap;
        }
    }
    ls->have_map_seq = 1;
    ls->last_map_seq = fr->seq;
    if (map_view_apply(&ls->map, fr, bytes, &c) != 0) {
        printf("map seq=%lu refused by the receiver bytes=%zu | ok=%lu dropped=%lu missing=%lu\n",
               (unsigned long)fr->seq, bytes, (unsigned long)s->frames_ok, dropped(s),
               ls->map_seq_gaps);
        return 0;
    }
    ls->map_features = ls->map.n_features;
    printf("map seq=%lu created=%lu extended=%lu moved=%lu merged=%lu removed=%lu snapshots=%lu "
           "pose=",
           (unsigned long)fr->seq, c.created, c.extended, c.moved, c.merged, c.removed,
           c.snapshots);
    if (ls->map.n_path > poses_before) {
        const double *p = &ls->map.path[3u * (ls->map.n_path - 1u)];
        printf("(%.3f,%.3f,%.4f)", p[0], p[1], p[2]);
    } else {
        fputs("none", stdout);
    }
    map_flags(ls->map.rx, &flagged, &absent);
    printf(" skipped=%lu bytes=%zu | features=%lu flagged=%lu absent=%lu ok=%lu dropped=%lu "
           "missing=%lu\n",
           c.skipped, bytes, ls->map_features, flagged, absent, (unsigned long)s->frames_ok,
           dropped(s), ls->map_seq_gaps);
    return 0;
}

/* One delivered frame: its line, and sequence accounting for scans (a
 * metadata frame has no place in the sequence of scans; map frames have
 * their own). -1 out of memory. */
static int deliver(listen_state_t *ls, const bsf_frame_t *fr, size_t bytes,
                   const bsf_decoder_stats_t *s)
{
    if (fr->type == BSF_FRAME_TYPE_METADATA) {
        print_metadata_line(fr, bytes, s);
        return 0;
    }
    if (fr->type == BSF_FRAME_TYPE_MAP) {
        ++ls->frames;
        return map_frame(ls, fr, bytes, s);
    }
    ++ls->frames;
    note_seq(ls, fr->seq);
    print_frame_line(ls, fr, bytes, s);
    return 0;
}

static void print_summary(const bsf_decoder_stats_t *s, unsigned long gaps)
{
    printf("counters: frames ok %lu, bad crc %lu, malformed %lu, unsupported version %lu, "
           "unknown type %lu, oversize %lu, bytes skipped %lu, missing by sequence %lu\n",
           (unsigned long)s->frames_ok, (unsigned long)s->bad_crc, (unsigned long)s->malformed,
           (unsigned long)s->unsupported_version, (unsigned long)s->unknown_type,
           (unsigned long)s->oversize, (unsigned long)s->bytes_skipped, gaps);
}

static int write_all(int fd, const uint8_t *p, size_t n)
{
    while (n > 0) {
        const ssize_t w = write(fd, p, n);
        if (w < 0) {
            if (errno == EINTR) {
                continue;
            }
            return -1;
        }
        p += (size_t)w;
        n -= (size_t)w;
    }
    return 0;
}

int cmd_listen(int argc, char **argv)
{
    static bsf_decoder_t dec;
    static bsf_frame_t frame;
    static uint8_t buf[4096];
    const char *dev = NULL, *save_path = NULL;
    long baud = 115200, count = 0;
    int baud_given = 0;
    speed_t code = B9600;
    listen_state_t ls;
    struct sigaction sa;
    int i, err = 0, fd, save_fd = -1, rc = 0;
    size_t frame_bytes = 0, since_delim = 0, k;

    memset(&ls, 0, sizeof ls);
    for (i = 1; i < argc; ++i) {
        const char *v;
        if (is_help(argv[i])) {
            fputs(listen_help, stdout);
            return 0;
        } else if ((v = opt_value(argc, argv, &i, "--baud", &err)) != NULL) {
            if (parse_long(v, 1, 100000000L, &baud) != 0 || baud_code(baud, &code) != 0) {
                return usage_error("--baud needs a standard rate (9600, 19200, 38400, 57600, "
                                   "115200, 230400, 460800, 921600, ...), got '%s'",
                                   v);
            }
            baud_given = 1;
        } else if ((v = opt_value(argc, argv, &i, "-o", &err)) != NULL ||
                   (v = opt_value(argc, argv, &i, "--save", &err)) != NULL) {
            save_path = v;
        } else if ((v = opt_value(argc, argv, &i, "--count", &err)) != NULL) {
            if (parse_long(v, 1, 2000000000L, &count) != 0) {
                return usage_error("--count needs a whole number >= 1, got '%s'", v);
            }
        } else if (strcmp(argv[i], "--features") == 0) {
            ls.features = 1;
        } else if (err) {
            return err;
        } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
            return usage_error("unknown option '%s'", argv[i]);
        } else if (dev == NULL) {
            dev = argv[i];
        } else {
            return usage_error("listen takes one device, got '%s' too", argv[i]);
        }
        if (err) {
            return err;
        }
    }
    if (dev == NULL) {
        return usage_error("listen needs a device, a named pipe or '-' (stdin)");
    }
    if (!baud_given && baud_code(baud, &code) != 0) {
        code = B9600;
    }

    if (strcmp(dev, "-") == 0) {
        fd = STDIN_FILENO;
    } else {
        fd = open(dev, O_RDONLY | O_NOCTTY);
        if (fd < 0) {
            fail_msg("cannot open %s: %s", dev, strerror(errno));
            return EXIT_FAIL;
        }
    }
    if (isatty(fd)) {
        if (set_raw_tty(fd, dev, code) != 0) {
            if (fd != STDIN_FILENO) {
                close(fd);
            }
            return EXIT_FAIL;
        }
        fprintf(stderr, "%s: %s: raw 8N1 at %ld baud\n", g_cmd, dev, baud);
    } else if (baud_given) {
        fprintf(stderr, "%s: %s is not a terminal: --baud ignored\n", g_cmd, dev);
    }
    if (save_path != NULL) {
        save_fd = strcmp(save_path, "-") == 0
                      ? -2
                      : open(save_path, O_WRONLY | O_CREAT | O_TRUNC, (mode_t)0644);
        if (save_fd == -2) {
            fail_msg("--save needs a file (stdout carries the frame lines)");
            rc = EXIT_USAGE;
            goto done;
        }
        if (save_fd < 0) {
            fail_msg("cannot create %s: %s", save_path, strerror(errno));
            rc = EXIT_FAIL;
            goto done;
        }
    }

    /* Ctrl-C (or a kill) ends the loop: read(2) returns EINTR, the summary is
     * printed and the saved file is complete up to the last byte received. */
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0; /* no SA_RESTART: a blocked read must return */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    bsf_decoder_init(&dec);
    while (!g_stop && (count == 0 || (long)ls.frames < count)) {
        const ssize_t got = read(fd, buf, sizeof buf);
        size_t off = 0;
        if (got < 0) {
            if (errno == EINTR) {
                continue;
            }
            fail_msg("%s: read error: %s", dev, strerror(errno));
            rc = EXIT_FAIL;
            break;
        }
        if (got == 0) {
            /* End of input: the sender closed the pipe. A frame cut short
             * is counted as dropped (never used); one complete but for its
             * delimiter is intact and delivered, as `bsf decode` does. */
            static const uint8_t delimiter = 0u;
            size_t used = 0;
            if (bsf_decoder_feed(&dec, &delimiter, 1u, &used, &frame) > 0) {
                deliver(&ls, &frame, since_delim + 1u, &dec.stats);
            }
            break;
        }
        if (save_fd >= 0 && write_all(save_fd, buf, (size_t)got) != 0) {
            fail_msg("write error on %s: %s", save_path, strerror(errno));
            rc = EXIT_FAIL;
            break;
        }
        while (off < (size_t)got && (count == 0 || (long)ls.frames < count)) {
            size_t used = 0;
            const int r = bsf_decoder_feed(&dec, buf + off, (size_t)got - off, &used, &frame);
            if (r < 0) {
                fail_msg("%s: decoder error (%s)", dev, bsf_status_str((bsf_status_t)r));
                rc = EXIT_FAIL;
                goto done;
            }
            for (k = off; k < off + used; ++k) {
                ++since_delim;
                if (buf[k] == 0u) { /* a delivered frame ends at its delimiter */
                    frame_bytes = since_delim;
                    since_delim = 0;
                }
            }
            off += used;
            if (r > 0) {
                if (deliver(&ls, &frame, frame_bytes, &dec.stats) != 0) {
                    rc = EXIT_FAIL;
                    goto done;
                }
                if (fflush(stdout) != 0) {
                    fail_msg("write error on stdout");
                    rc = EXIT_FAIL;
                    goto done;
                }
            } else if (used == 0) {
                break;
            }
        }
    }
    print_summary(&dec.stats, ls.seq_gaps);
    if (ls.have_map) {
        unsigned long flagged;
        unsigned long absent;
        map_flags(ls.map.rx, &flagged, &absent);
        printf("map: %lu frames, %llu bytes, %lu features (%lu flagged: unconfirmed or stale), "
               "%lu ids never received, %lu map frames missing by sequence, %lu records skipped\n",
               ls.map.frames, ls.map.bytes, ls.map_features, flagged, absent, ls.map_seq_gaps,
               (unsigned long)ls.map.rx->stats.records_skipped);
    }
    if (fflush(stdout) != 0) {
        rc = EXIT_FAIL;
    }
done:
    if (ls.have_map) {
        map_view_free(&ls.map);
    }
    if (save_fd >= 0 && close(save_fd) != 0) {
        fail_msg("write error on %s: %s", save_path, strerror(errno));
        rc = EXIT_FAIL;
    }
    if (fd != STDIN_FILENO) {
        close(fd);
    }
    return rc;
}
