/* SPDX-License-Identifier: MIT */
/*
 * main.c - the bsf command line: dispatch to one command per file (cmd_*.c).
 */
#include "tool.h"

static const char main_help[] =
    "Usage: bsf COMMAND [options]   (bsf COMMAND --help for details)\n"
    "B-spline map features from 2D LIDAR scans.\n"
    "\n"
    "  extract LOG|- [--method M] [--first K] [--count N] [--range-max M] [--reproducible]\n"
    "                [--meta-every K] [--map [--pose-every K]] [-o OUT|-]\n"
    "  decode IN [--json]          frames as text or JSON Lines, then decoder counters\n"
    "  metrics IN                  retrievability, compactness, accuracy, time, bytes\n"
    "  render IN -o MAP.svg [--scans K..L] [--points LOG] [--width PX]\n"
    "  table1 DATA_DIR             the paper's Table 1 on the four datasets\n"
    "  demo                        built-in synthetic scene, end to end\n"
    "  listen DEVICE|- [--baud N] [-o FILE]  live stream (serial port, pipe): frames as they come\n"
    "  map IN [--json] [-o MAP.svg] the fused map of a map stream (extract --map), rebuilt\n"
    "\n"
    "'-' means stdin/stdout:  bsf extract x.log -o - | bsf metrics -\n";

int main(int argc, char **argv)
{
    static const struct {
        const char *name;
        int (*fn)(int, char **);
    } cmds[] = {{"extract", cmd_extract}, {"decode", cmd_decode}, {"metrics", cmd_metrics},
                {"render", cmd_render},   {"table1", cmd_table1}, {"demo", cmd_demo},
                {"listen", cmd_listen},   {"map", cmd_map}};
    static char cmd_name[64];
    size_t i;
    if (argc < 2) {
        fputs(main_help, stderr);
        return EXIT_USAGE;
    }
    if (is_help(argv[1]) || strcmp(argv[1], "help") == 0) {
        fputs(main_help, stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("bsf %s (wire format version %u)\n", BSF_TOOL_VERSION, (unsigned)BSF_FORMAT_VERSION);
        /* A scan over these is cut (keypoints, segments, control points) or refused (beams). */
        printf("caps: BSF_MAX_POINTS=%d BSF_MAX_KEYPOINTS=%d BSF_MAX_SEGMENTS=%d "
               "BSF_MAX_CTRL_POINTS=%d\n",
               BSF_MAX_POINTS, BSF_MAX_KEYPOINTS, BSF_MAX_SEGMENTS, BSF_MAX_CTRL_POINTS);
        return 0;
    }
    for (i = 0; i < sizeof cmds / sizeof cmds[0]; ++i) {
        if (strcmp(argv[1], cmds[i].name) == 0) {
            snprintf(cmd_name, sizeof cmd_name, "bsf %s", cmds[i].name);
            g_cmd = cmd_name;
            return cmds[i].fn(argc - 1, argv + 1);
        }
    }
    return usage_error("unknown command '%s'", argv[1]);
}
