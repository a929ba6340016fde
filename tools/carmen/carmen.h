/* SPDX-License-Identifier: MIT */
/*
 * carmen.h - streaming reader of CARMEN log files (host only, not part of the
 * library). Reads plain or gzip-compressed logs (zlib's gzopen reads both)
 * one laser message at a time.
 *
 * Understood: FLASER and ROBOTLASER1. Skipped: every other message type
 * (ODOM, PARAM, VERTEX2, EDGE2, NEFF, ...), comment lines (starting with #)
 * and blank lines. A malformed FLASER/ROBOTLASER1 line is reported as
 * "file:line: message" to the error stream given at open, counted, and
 * skipped; reading goes on with the next line.
 *
 * Numbers are read as strtof/strtod/strtol read them in the C locale: the
 * forms logs write ("81.83", "-1.570796") through exact fast paths
 * (carmen_number.h), any other form through the C library itself.
 *
 * Damage is never read as a shorter or different log:
 *  - A line holding a control byte (NUL, any byte below 0x20 other than tab
 *    and a final CR, or DEL) is reported as malformed ("file:line: control
 *    byte 0xNN at column C") whatever its type, and skipped; the bytes up to
 *    the next newline belong to that line, so later line numbers stay right.
 *  - A gzip file cut short (or failing its CRC/length check), a `gzip -dc`
 *    that fails (the fallback without zlib), an I/O error, or a file named
 *    *.gz that holds no gzip data (e.g. cut before its header) is a read
 *    error: carmen_next returns -1 after "file:N: read error: WHAT; the last
 *    complete line is M". The partial line at the cut is never returned.
 *
 * Memory is bounded whatever the input: a line longer than CARMEN_MAX_LINE
 * (far more than the longest scan line needs) is reported as malformed the
 * moment it passes that length ("file:line: line longer than ..."), counted
 * apart (carmen_overlong_count), and the rest of it is read and dropped a
 * block at a time; the line buffer never holds more than CARMEN_MAX_BUFFER
 * bytes. A gzip bomb of one endless line costs its decompression time, not
 * its size in memory.
 */
#ifndef BSF_TOOLS_CARMEN_H
#define BSF_TOOLS_CARMEN_H

#include <stddef.h>
#include <stdio.h>

/** Largest beam count accepted on one line; more is reported as malformed. */
#define CARMEN_MAX_BEAMS 8192

/** Longest line read (bytes before its newline). A ROBOTLASER1 line of
 *  CARMEN_MAX_BEAMS readings and as many remissions, 24 characters each,
 *  is under 400 KiB. */
#define CARMEN_MAX_LINE 1048576u

/** Most bytes the reader's line buffer ever takes: the longest line, one
 *  read block (64 KiB) and the terminating NUL. */
#define CARMEN_MAX_BUFFER (CARMEN_MAX_LINE + 65536u + 1u)

/** Kind of laser message a record came from. */
typedef enum {
    CARMEN_FLASER = 1,     /**< old front-laser message, geometry by convention */
    CARMEN_ROBOTLASER1 = 2 /**< geometry given on the line */
} carmen_msg_t;

/** A planar pose in the world frame: metres, metres, radians. */
typedef struct {
    double x;
    double y;
    double theta;
} carmen_pose_t;

/**
 * One laser scan. `ranges` points into the reader's storage and stays valid
 * until the next carmen_next or carmen_close on the same reader.
 *
 * Geometry: beam i points at angle_min + i * angle_increment (radians, CCW).
 *  - ROBOTLASER1: angle_min = start, angle_increment = res from the line
 *    (the fov field is ignored); max_range = the line's maxrange. A line
 *    whose start or res is not a finite float, or whose res is 0 as a float,
 *    is malformed.
 *  - FLASER (CARMEN's readlog convention): angle_min = -pi/2; increment
 *    1 deg for 180 or 181 beams, 0.5 deg for 360 or 361 beams; any other
 *    count N >= 2 spreads the beams over exactly 180 deg (pi / (N - 1)), and
 *    a single beam gets increment pi. max_range = 80 m (CARMEN's assumption).
 *    laser_pose = the line's x y theta, robot_pose = its odometry pose.
 */
typedef struct {
    carmen_msg_t type;
    const float *ranges;      /**< count readings, metres, as written */
    size_t count;             /**< number of beams (may change from line to line) */
    float angle_min;          /**< radians */
    float angle_increment;    /**< radians */
    float max_range;          /**< declared maximum range, metres */
    carmen_pose_t laser_pose; /**< lx ly ltheta (FLASER: x y theta) */
    carmen_pose_t robot_pose; /**< rx ry rtheta (FLASER: odom_x odom_y odom_theta) */
    double timestamp;         /**< ipc_time, seconds */
    unsigned long line;       /**< 1-based line number in the file */
} carmen_scan_t;

typedef struct carmen_reader carmen_reader_t;

/**
 * Open a log ("-": standard input, plain or gzip). `err` receives the
 * reports of malformed lines (NULL: silent).
 * Returns NULL when the file cannot be opened (errno tells why) or memory
 * runs out.
 */
carmen_reader_t *carmen_open(const char *path, FILE *err);

#ifndef BSF_HAVE_ZLIB
/**
 * Without zlib: the output of `gzip OPTS -- PATH` read through popen (the
 * path quoted for the shell, gzip's complaints dropped): "-dc" decompresses,
 * "-dcf" passes plain text through as well. NULL when it cannot start or
 * memory runs out; pclose it.
 */
FILE *carmen_gzip_pipe(const char *path, const char *opts);
#endif

/**
 * Read the next laser message into *scan.
 * @return 1 when a scan was read, 0 at the (checked) end of the data, -1 on
 *         a read error or truncated data (reported to the error stream).
 */
int carmen_next(carmen_reader_t *reader, carmen_scan_t *scan);

/** Number of malformed laser lines skipped so far. */
unsigned long carmen_malformed_count(const carmen_reader_t *reader);

/** Number of those lines that were longer than CARMEN_MAX_LINE: not damage
 *  a real log shows, so a caller may treat any as a failure of the run. */
unsigned long carmen_overlong_count(const carmen_reader_t *reader);

/** Bytes the reader's line buffer holds now (at most CARMEN_MAX_BUFFER). */
size_t carmen_buffer_bytes(const carmen_reader_t *reader);

/** Readings at or above this are no-return codes in the CARMEN logs we know
 *  (81.83, 81.91); genuine outdoor returns reach about 81.8 m. */
#define CARMEN_NO_RETURN_FLOOR 81.8f

/**
 * The range_max to give bsf for this scan: the declared maximum range (80 m
 * for FLASER, per CARMEN), capped at CARMEN_NO_RETURN_FLOOR so that no-return
 * codes are never valid readings. Nothing else is filtered.
 */
float carmen_valid_range_max(const carmen_scan_t *scan);

/** Close the reader and free its storage; NULL is allowed. */
void carmen_close(carmen_reader_t *reader);

#endif /* BSF_TOOLS_CARMEN_H */
