# SPDX-License-Identifier: MIT
"""ROS bags to bsf streams (install the ``rosbag`` extra: rosbags).

Reads ``sensor_msgs/LaserScan`` messages of one topic from a ROS 1 ``.bag``
or a ROS 2 bag (its directory, or the ``.db3`` / ``.mcap`` file inside it)
with the pure-Python ``rosbags`` package, so no ROS installation is needed.
Each message's own geometry (angle_min, angle_increment) and range limits
(range_min, range_max) are used, and its header stamp becomes the frame time
(with format version 2: ms since the stream's time origin, the first
stamp, which the metadata frame carries in µs since the Unix epoch; with
version 1: ms since the Unix epoch). LaserScan carries no pose, so frames
have none.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator, List, Optional, Tuple, Union

import numpy as np

from . import BsfError

LASERSCAN = "sensor_msgs/msg/LaserScan"


class BagError(Exception):
    """The bag cannot be read, or the topic is missing or not a LaserScan."""


@dataclass(frozen=True, eq=False)
class BagScan:
    """One LaserScan message, or why it cannot be used (``error``)."""

    index: int  #: position of the message on its topic, from 0
    stamp_ns: int  #: header stamp, ns since the epoch
    ranges: np.ndarray  #: float32
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    error: Optional[str] = None


def _bag_paths(path: Union[str, Path]) -> List[Path]:
    p = Path(path)
    if not p.exists():
        raise BagError(f"{p}: no such file or directory")
    if p.is_file() and p.suffix in (".db3", ".mcap"):
        # rosbags opens a ROS 2 bag by its directory (metadata.yaml inside).
        if not (p.parent / "metadata.yaml").is_file():
            raise BagError(f"{p}: a ROS 2 bag file needs its directory with metadata.yaml beside it")
        return [p.parent]
    return [p]


def _stamp_ns(msg: object) -> int:
    stamp = msg.header.stamp  # type: ignore[attr-defined]
    sec = int(stamp.sec)
    nsec = int(getattr(stamp, "nanosec", getattr(stamp, "nsec", 0)))
    return sec * 1_000_000_000 + nsec


def _check_geometry(m: object) -> Optional[str]:
    vals = {k: float(getattr(m, k)) for k in ("angle_min", "angle_increment", "range_min", "range_max")}
    for k, v in vals.items():
        if not math.isfinite(v):
            return f"{k} is not finite ({v})"
    if vals["angle_increment"] == 0.0:
        return "angle_increment is 0"
    if vals["range_min"] < 0.0 or not vals["range_max"] > vals["range_min"]:
        return f"range limits [{vals['range_min']}, {vals['range_max']}) are not 0 <= min < max"
    return None


def scans(path: Union[str, Path], topic: str) -> Iterator[BagScan]:
    """LaserScan messages of ``topic`` in ``path``, in time order.

    Raises BagError for an unreadable bag, a missing topic or a topic of
    another type; a message that cannot be deserialised or has unusable
    geometry is yielded with ``error`` set (the caller reports it).
    """
    try:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise BagError("reading ROS bags needs rosbags: pip install './tools/python[rosbag]'") from None
    paths = _bag_paths(path)
    try:
        reader = AnyReader(paths, default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        reader.open()
    except Exception as e:  # rosbags raises several unrelated types for a bad file
        raise BagError(f"{path}: cannot read the bag: {e}") from None
    try:
        conns = [c for c in reader.connections if c.topic == topic]
        if not conns:
            have = ", ".join(sorted(f"{c.topic} ({c.msgtype})" for c in reader.connections)) or "none"
            raise BagError(f"{path}: no topic {topic}; topics: {have}")
        bad = [c.msgtype for c in conns if c.msgtype != LASERSCAN]
        if bad:
            raise BagError(f"{path}: topic {topic} has type {bad[0]}; only sensor_msgs/LaserScan is supported")
        index = 0
        try:
            for conn, _, raw in reader.messages(connections=conns):
                try:
                    m = reader.deserialize(raw, conn.msgtype)
                    err = _check_geometry(m)
                    stamp = _stamp_ns(m)
                    if err is None and stamp < 0:
                        err = f"header stamp is before 1970 ({stamp} ns)"
                    ranges = np.asarray(m.ranges)
                    if err is None and (ranges.ndim != 1 or ranges.dtype.kind != "f"):
                        err = f"ranges are not a float array (dtype {ranges.dtype}, shape {ranges.shape})"
                    yield BagScan(
                        index=index,
                        stamp_ns=stamp,
                        ranges=ranges.astype(np.float32, copy=False) if err is None else np.zeros(0, np.float32),
                        angle_min=float(m.angle_min),
                        angle_increment=float(m.angle_increment),
                        range_min=float(m.range_min),
                        range_max=float(m.range_max),
                        error=err,
                    )
                except (GeneratorExit, KeyboardInterrupt):
                    raise
                except Exception as e:  # a malformed message: report it, go on
                    yield BagScan(index, 0, np.zeros(0, np.float32), 0.0, 0.0, 0.0, 0.0, f"cannot decode the message: {e}")
                index += 1
        except BagError:
            raise
        except Exception as e:
            raise BagError(f"{path}: cannot read the bag after {index} messages on {topic}: {e}") from None
    finally:
        reader.close()


def stamp_ms(stamp_ns: int) -> int:
    """Header time to the frame time: ms since the epoch, nearest."""
    return (stamp_ns + 500_000) // 1_000_000


def extract_bag(
    path: Union[str, Path],
    topic: str,
    out: str,
    method: str = "lc-sved-pdm",
    *,
    quant_step: Optional[float] = None,
    range_max: Optional[float] = None,
    timing: bool = True,
    log=None,
    **params: Union[int, float],
) -> Tuple[int, int, int]:
    """Write the frames of every LaserScan on ``topic`` to ``out`` ("-": stdout).

    ``range_max`` lowers each message's own limit (never raises it). Returns
    (frames written, messages refused, bytes written); each refused message is
    reported to ``log`` (a text stream) with its index and reason.
    """
    import sys

    from . import QUANT_STEP_DEFAULT, Extractor

    from . import StreamWriter

    log = log or sys.stderr
    ex = Extractor(method, timing=timing, **params)
    written = failed = 0
    dst = sys.stdout.buffer if out == "-" else open(out, "wb")
    writer = StreamWriter(
        dst,
        method,
        params,
        quant_step if quant_step is not None else QUANT_STEP_DEFAULT,
        source=Path(path).name,
        v1_time_origin_us=0,
    )
    try:
        for s in scans(path, topic):
            where = f"{path}: {topic} message {s.index}"
            if s.error is not None:
                print(f"{where} skipped: {s.error}", file=log)
                failed += 1
                continue
            rmax = min(s.range_max, range_max) if range_max else s.range_max
            try:
                fr = ex.extract(s.ranges, s.angle_min, s.angle_increment, s.range_min, rmax, seq=s.index)
                writer.write(
                    fr,
                    (s.stamp_ns + 500) // 1000,
                    len(s.ranges),
                    s.angle_min,
                    s.angle_increment,
                    s.range_min,
                    rmax,
                    no_time=not timing,
                )
            except BsfError as e:
                print(f"{where} skipped: {e}", file=log)
                failed += 1
                continue
            written += 1
    finally:
        if dst is not sys.stdout.buffer:
            dst.close()
        else:
            dst.flush()
    nbytes = writer.bytes
    return written, failed, nbytes
