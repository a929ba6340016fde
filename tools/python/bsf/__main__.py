# SPDX-License-Identifier: MIT
"""Command line: ``python -m bsf extract|plot ...`` (``--help`` on each)."""
from __future__ import annotations

import argparse
import math
import os
import sys
from typing import List, Optional

from . import METHODS, QUANT_STEP_DEFAULT, BsfError, read

BAG_SUFFIXES = (".bag", ".db3", ".mcap")


def _is_bag(path: str) -> bool:
    return path.endswith(BAG_SUFFIXES) or (os.path.isdir(path) and os.path.isfile(os.path.join(path, "metadata.yaml")))


def _param(text: str) -> tuple:
    name, sep, value = text.partition("=")
    if not sep:
        raise argparse.ArgumentTypeError(f"--param needs NAME=VALUE, got {text!r}")
    try:
        v: object = int(value)
    except ValueError:
        try:
            v = float(value)
        except ValueError:
            raise argparse.ArgumentTypeError(f"--param {name}: {value!r} is not a number") from None
    return name, v


def cmd_extract(a: argparse.Namespace) -> int:
    params = dict(a.param or [])
    if _is_bag(a.input):
        if not a.topic:
            print("bsf: extract of a ROS bag needs --topic (e.g. --topic /scan)", file=sys.stderr)
            return 2
        from .rosbag import BagError, extract_bag
        from .tf import MAX_GAP_NS_DEFAULT

        if a.max_pose_gap is not None and not (a.max_pose_gap > 0 and a.max_pose_gap < 1e9):
            print(f"bsf: --max-pose-gap must be a positive number of seconds, got {a.max_pose_gap}", file=sys.stderr)
            return 2
        try:
            n, failed, nbytes, no_pose = extract_bag(
                a.input,
                a.topic,
                a.output,
                a.method,
                quant_step=a.quant,
                range_max=a.range_max,
                timing=not a.no_time,
                pose_from=a.pose_from,
                frame=a.frame,
                max_gap_ns=round((a.max_pose_gap if a.max_pose_gap is not None else MAX_GAP_NS_DEFAULT / 1e9) * 1e9),
                **params,
            )
        except (BagError, BsfError, TypeError, OSError) as e:
            print(f"bsf: {e}", file=sys.stderr)
            return 1
        print(
            f"{a.input}: {n} scans of {a.topic} extracted with {a.method}, {nbytes} bytes, {failed} refused"
            + (f", {no_pose} without a pose skipped" if a.pose_from else ""),
            file=sys.stderr,
        )
        if n == 0 and no_pose:
            print(f"bsf: {a.input}: no scan of {a.topic} has a pose from {a.pose_from}", file=sys.stderr)
            return 1
        if n == 0 and failed == 0:
            print(f"bsf: {a.input}: no message on {a.topic}", file=sys.stderr)
            return 1
        return 1 if failed else 0
    # Anything else is read as a CARMEN log, as `bsf extract` does.
    if a.pose_from or a.frame or a.max_pose_gap is not None:
        print("bsf: --pose-from, --frame and --max-pose-gap are for ROS bags (a CARMEN log carries its poses)", file=sys.stderr)
        return 2
    errors: List[str] = []
    n = nbytes = 0
    try:
        dst = sys.stdout.buffer if a.output == "-" else open(a.output, "wb")
    except OSError as e:
        print(f"bsf: {e}", file=sys.stderr)
        return 1
    from . import StreamWriter, _log_frames, _round_us

    writer = StreamWriter(dst, a.method, params, a.quant, source=os.path.basename(a.input))
    try:
        for scan, rmax, fr in _log_frames(a.input, a.method, a.first, a.count, a.range_max, not a.no_time, errors, params):
            writer.write(
                fr,
                _round_us(scan.timestamp),
                len(scan.ranges),
                scan.angle_min,
                scan.angle_increment,
                0.0,
                rmax,
                no_time=a.no_time,
            )
        n, nbytes = writer.frames, writer.bytes
    except (BsfError, TypeError, OSError) as e:
        print(f"bsf: {e}", file=sys.stderr)
        return 1
    finally:
        if dst is sys.stdout.buffer:
            dst.flush()
        else:
            dst.close()
    for e in errors:
        print(e, file=sys.stderr)
    print(f"{a.input}: {n} scans extracted with {a.method}, {nbytes} bytes, {len(errors)} failed", file=sys.stderr)
    if n == 0 and not errors and not a.first:
        # As `bsf extract`: a file without a laser line is not a log (a typo,
        # a script, a bag without its suffix), and an empty stream is no result.
        print(f"bsf: {a.input}: no laser line (FLASER or ROBOTLASER1) in the log", file=sys.stderr)
        return 1
    return 1 if errors else 0


def cmd_plot(a: argparse.Namespace) -> int:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("bsf: plot needs matplotlib: pip install './tools/python[plot]'", file=sys.stderr)
        return 1
    from .plot import plot

    from . import Frame, Map, MapFrame

    try:
        items = list(read(a.input))
        frames = [f for f in items if isinstance(f, Frame)]  # metadata frames draw nothing
        m = None
        if not frames and any(isinstance(f, MapFrame) for f in items):
            m = Map()  # a map stream: draw the receiver's map
            for f in items:
                if isinstance(f, MapFrame):
                    m.apply(f)
    except (BsfError, OSError) as e:
        print(f"bsf: {e}", file=sys.stderr)
        return 1
    if m is not None:
        ax = plot(m)
        what = f"{len(m.features)} map features"
    else:
        ax = plot(frames, world=not a.sensor)
        what = f"{len(frames)} frames"
    ax.set_title(f"{os.path.basename(a.input)}: {what}")
    ax.figure.savefig(a.output, dpi=a.dpi, bbox_inches="tight")
    plt.close(ax.figure)
    print(f"{a.output}: {what} drawn", file=sys.stderr)
    return 0


def cmd_export(a: argparse.Namespace) -> int:
    from .export import ExportError, export

    if a.samples < 2:
        print(f"bsf: --samples must be at least 2, got {a.samples}", file=sys.stderr)
        return 2
    for bad, msg in (
        (not (math.isfinite(a.map_rate) and 0.001 <= a.map_rate <= 1e6), f"--map-rate must be 0.001 .. 1e6 Hz, got {a.map_rate}"),
        (a.map_every < 1, f"--map-every must be at least 1, got {a.map_every}"),
        (not 1 <= a.map_per_span <= 64, f"--map-per-span must be 1 .. 64, got {a.map_per_span}"),
    ):
        if bad:
            print(f"bsf: {msg}", file=sys.stderr)
            return 2
    try:
        res = export(
            a.input,
            a.output,
            a.format,
            frame_id=a.frame_id,
            laser_frame=a.laser_frame,
            samples=a.samples,
            prefix=a.prefix,
            map_rate=a.map_rate,
            map_every=a.map_every,
            map_per_span=a.map_per_span,
        )
    except (ExportError, BsfError, OSError) as e:
        print(f"bsf: {e}", file=sys.stderr)
        return 1
    counts = ", ".join(f"{n} on {t}" for t, n in sorted(res.messages.items()))
    what = f"{res.frames} frames" + (f", {res.map_frames} map frames" if res.map_frames else "")
    print(f"{a.output}: {what} exported ({counts})", file=sys.stderr)
    return 0


def main(argv: Optional[List[str]] = None) -> int:
    p = argparse.ArgumentParser(prog="python -m bsf", description="bsf from Python: ROS bags and CARMEN logs to bsf streams, plots.")
    sub = p.add_subparsers(dest="command", required=True)
    e = sub.add_parser(
        "extract",
        help="extract features from a ROS bag (LaserScan topic) or a CARMEN log into a bsf stream",
        description="INPUT is a ROS 1 .bag, a ROS 2 bag (directory, .db3 or .mcap) or a CARMEN log (plain or .gz).",
    )
    e.add_argument("input", metavar="INPUT")
    e.add_argument("--topic", help="LaserScan topic of a bag, e.g. /scan")
    e.add_argument("-o", dest="output", default="-", help="output stream ('-': stdout, the default)")
    e.add_argument("--method", choices=METHODS, default="lc-sved-pdm")
    e.add_argument("--quant", type=float, default=QUANT_STEP_DEFAULT, help="control point step, metres (0.005)")
    e.add_argument("--range-max", type=float, default=None, help="readings >= M metres are invalid (bags: lowers each message's own limit)")
    e.add_argument("--first", type=int, default=0, help="CARMEN: skip the first K scans")
    e.add_argument("--count", type=int, default=None, help="CARMEN: at most N scans")
    e.add_argument("--no-time", action="store_true", help="send 0 as extraction time (byte-reproducible output)")
    e.add_argument("--param", action="append", type=_param, metavar="NAME=VALUE", help="parameter override, e.g. pdm_target_rms=0.02")
    e.add_argument("--pose-from", metavar="TOPIC", help="bags: poses from a tf topic (/tf, with /tf_static) or a nav_msgs/Odometry topic")
    e.add_argument("--frame", help="bags: fixed frame of the poses (default: map if the transforms have it, else odom; odometry: its own frame)")
    e.add_argument("--max-pose-gap", type=float, metavar="S", help="bags: longest gap between two pose samples to interpolate across, seconds (1)")
    e.set_defaults(func=cmd_extract)
    pl = sub.add_parser("plot", help="draw a bsf stream to an image (needs matplotlib)")
    pl.add_argument("input", metavar="IN", help="bsf stream ('-': stdin)")
    pl.add_argument("-o", dest="output", required=True, help="image file (.png, .svg, .pdf)")
    pl.add_argument("--sensor", action="store_true", help="sensor frame instead of the world frame")
    pl.add_argument("--dpi", type=int, default=150)
    pl.set_defaults(func=cmd_plot)
    x = sub.add_parser(
        "export",
        help="write a bsf stream as ROS 2 markers (MCAP for Foxglove, or a ROS 2 bag for RViz 2; needs the rosbag extra)",
        description="Features as visualization_msgs/MarkerArray (line strips, vertex spheres), the laser pose and path; "
        "a map stream (bsf extract --map) as the receiver's whole map on /bsf/map, with the pose records' path.",
    )
    x.add_argument("input", metavar="IN", help="bsf stream ('-': stdin)")
    x.add_argument("-o", dest="output", required=True, help="OUT.mcap, or a new directory with --format ros2bag")
    x.add_argument("--format", choices=("mcap", "ros2bag"), default=None, help="default: mcap for *.mcap")
    x.add_argument("--frame-id", default="map", help="fixed frame of frames with a pose (map)")
    x.add_argument("--laser-frame", default="laser", help="frame of frames without a pose (laser)")
    x.add_argument("--samples", type=int, default=32, help="points per feature's line strip (32)")
    x.add_argument("--prefix", default="/bsf", help="topic prefix (/bsf: /bsf/features, /bsf/pose, /bsf/path)")
    x.add_argument(
        "--map-rate",
        type=float,
        default=10.0,
        metavar="HZ",
        help="map streams: map frames per second, for their stamps (a map frame carries no time): "
        "the metadata's time origin + (seq - first seq) / HZ (10)",
    )
    x.add_argument("--map-every", type=int, default=10, metavar="N", help="map streams: the whole map every N map frames and after the last (10)")
    x.add_argument("--map-per-span", type=int, default=4, metavar="K", help="map streams: line strip points per curve span (4)")
    x.set_defaults(func=cmd_export)
    a = p.parse_args(argv)
    try:
        return int(a.func(a))
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        return 1


if __name__ == "__main__":
    sys.exit(main())
