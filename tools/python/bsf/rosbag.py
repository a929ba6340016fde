# SPDX-License-Identifier: MIT
"""ROS bags to bsf streams (install the ``rosbag`` extra: rosbags).

Reads ``sensor_msgs/LaserScan`` messages of one topic from a ROS 1 ``.bag``
or a ROS 2 bag (its directory, or the ``.db3`` / ``.mcap`` file inside it)
with the pure-Python ``rosbags`` package, so no ROS installation is needed.
Each message's own geometry (angle_min, angle_increment) and range limits
(range_min, range_max) are used, and its header stamp becomes the frame time
(with format version 2: ms since the stream's time origin, the first
stamp, which the metadata frame carries in µs since the Unix epoch; with
version 1: ms since the Unix epoch).

LaserScan carries no pose. With ``pose_from`` (:func:`read_scans`,
:func:`extract_bag`) each scan gets the pose of its laser frame (the
message's header.frame_id) in a fixed frame at its header stamp, from the
bag's ``/tf`` (with ``/tf_static``) or from a ``nav_msgs/Odometry`` topic
(with the mounting from ``/tf_static``); see :mod:`bsf.tf` for how the chain
is composed and interpolated, and which scans get no pose.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Dict, Iterator, List, NamedTuple, Optional, Union

import numpy as np

from . import BsfError
from .tf import MAX_GAP_NS_DEFAULT, Pose, PoseError, TransformTree

LASERSCAN = "sensor_msgs/msg/LaserScan"
ODOMETRY = "nav_msgs/msg/Odometry"
#: tf2's message and ROS 1 tf's older one: the same list of TransformStamped
TF_TYPES = ("tf2_msgs/msg/TFMessage", "tf/msg/tfMessage")
TF_STATIC = "/tf_static"


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
    frame_id: str = ""  #: header.frame_id: the laser frame
    #: the laser's (x, y, theta) in the fixed frame at the stamp (read_scans with pose_from)
    pose: Optional[Pose] = None
    #: why the scan has no pose (read_scans with pose_from)
    pose_error: Optional[str] = None


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


def _open_reader(path: Union[str, Path]):
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
    return reader


def scans(path: Union[str, Path], topic: str) -> Iterator[BagScan]:
    """LaserScan messages of ``topic`` in ``path``, in time order.

    Raises BagError for an unreadable bag, a missing topic or a topic of
    another type; a message that cannot be deserialised or has unusable
    geometry is yielded with ``error`` set (the caller reports it).
    """
    reader = _open_reader(path)
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
                        frame_id=str(m.header.frame_id),
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


@dataclass
class PoseSource:
    """The pose data of a bag: a transform tree and the fixed frame poses are given in."""

    tree: TransformTree
    fixed_frame: str
    kind: str  #: "tf" or "odometry"
    messages: int = 0  #: pose messages read
    bad_messages: int = 0  #: pose messages that could not be decoded

    def notes(self) -> List[str]:
        """What was left out of the pose data, for the user."""
        out = []
        if self.bad_messages:
            out.append(f"{self.bad_messages} pose messages could not be decoded and were ignored")
        if self.tree.tilted:
            out.append(
                f"{self.tree.tilted} transforms turn their child frame upside down and were ignored "
                "(a laser mounted upside down sees a mirrored scan, which a plane pose cannot express)"
            )
        if self.tree.rejected:
            out.append(f"{self.tree.rejected} transforms with non-finite values or bad frame names were ignored")
        return out


def _add_tf(tree: TransformTree, msg: object, static: bool) -> int:
    added = 0
    for ts in msg.transforms:  # type: ignore[attr-defined]
        tr, q = ts.transform.translation, ts.transform.rotation
        quat = (float(q.x), float(q.y), float(q.z), float(q.w))
        added += tree.add_3d(str(ts.header.frame_id), str(ts.child_frame_id), _stamp_ns(ts), float(tr.x), float(tr.y), quat, static)
    return added


def add_pose_message(tree: TransformTree, kind: str, msg: object, static: bool = False) -> int:
    """Add one decoded pose message to ``tree``: a ``tf2_msgs/TFMessage``
    (``kind`` "tf") or a ``nav_msgs/Odometry`` ("odometry"). Returns how many
    transforms were taken; the tree counts what it refused (non-finite values,
    bad frame names, a child turned upside down). Raises what reading a
    malformed message's fields raises; :func:`load_poses` counts those as bad
    messages."""
    if kind == "tf":
        return _add_tf(tree, msg, static)
    p, q = msg.pose.pose.position, msg.pose.pose.orientation  # type: ignore[attr-defined]
    quat = (float(q.x), float(q.y), float(q.z), float(q.w))
    frame = str(msg.header.frame_id)  # type: ignore[attr-defined]
    child = str(msg.child_frame_id)  # type: ignore[attr-defined]
    return int(tree.add_3d(frame, child, _stamp_ns(msg), float(p.x), float(p.y), quat, static))


def _names(frames: "set[str]", most: int = 20) -> str:
    """Frame names for a message, at most ``most`` of them (a bag may name thousands)."""
    names = sorted(frames)
    more = f", ... ({len(names)} frames)" if len(names) > most else ""
    return ", ".join(names[:most]) + more


def load_poses(
    path: Union[str, Path],
    pose_from: str,
    frame: Optional[str] = None,
    max_gap_ns: int = MAX_GAP_NS_DEFAULT,
) -> PoseSource:
    """Read the pose data of a bag: the topic ``pose_from`` (a tf topic such as
    ``/tf``, or a ``nav_msgs/Odometry`` topic) and ``/tf_static`` when present.

    The fixed frame is ``frame``; by default ``map`` when the transforms name
    it, else ``odom`` (tf), or the odometry's own frame (header.frame_id of
    its first message). Raises BagError when the topic is missing or of
    another type, holds no usable pose, or the fixed frame is not in the data.
    """
    reader = _open_reader(path)
    try:
        by_topic = {}
        for c in reader.connections:
            by_topic.setdefault(c.topic, []).append(c)
        conns = by_topic.get(pose_from)
        if not conns:
            have = ", ".join(sorted(f"{c.topic} ({c.msgtype})" for c in reader.connections)) or "none"
            raise BagError(f"{path}: no topic {pose_from} for the poses; topics: {have}")
        types = {c.msgtype for c in conns}
        if types <= set(TF_TYPES):
            kind = "tf"
        elif types == {ODOMETRY}:
            kind = "odometry"
        else:
            raise BagError(
                f"{path}: topic {pose_from} has type {', '.join(sorted(types))}; "
                "--pose-from needs tf2_msgs/TFMessage (/tf) or nav_msgs/Odometry"
            )
        tree = TransformTree(max_gap_ns)
        src = PoseSource(tree, "", kind)
        odom_frame = ""
        usable = 0  # transforms taken from the pose topic itself
        static = [c for c in by_topic.get(TF_STATIC, []) if c.msgtype in TF_TYPES and pose_from != TF_STATIC]
        try:
            for conn, _, raw in reader.messages(connections=conns + static):
                try:
                    m = reader.deserialize(raw, conn.msgtype)
                    if conn.topic == TF_STATIC and conn in static:
                        add_pose_message(tree, "tf", m, True)
                    else:
                        n = add_pose_message(tree, kind, m, pose_from == TF_STATIC)
                        if n and kind == "odometry":
                            odom_frame = odom_frame or str(m.header.frame_id).lstrip("/")
                        usable += n
                    src.messages += 1
                except (GeneratorExit, KeyboardInterrupt):
                    raise
                except Exception:  # a malformed pose message: counted, reported once
                    src.bad_messages += 1
        except BagError:
            raise
        except Exception as e:
            raise BagError(f"{path}: cannot read the bag's pose data: {e}") from None
    finally:
        reader.close()
    frames = tree.frames
    if not usable:
        raise BagError(f"{path}: {pose_from} holds no usable transform ({src.messages} messages; " + "; ".join(src.notes() or ["empty"]) + ")")
    if frame is not None:
        fixed = frame.lstrip("/")
        if fixed not in frames:
            raise BagError(f"{path}: the fixed frame {fixed} is not in the pose data; frames: {_names(frames)}")
    elif kind == "odometry":
        fixed = odom_frame
    elif "map" in frames:
        fixed = "map"
    elif "odom" in frames:
        fixed = "odom"
    else:
        raise BagError(f"{path}: neither map nor odom is in the pose data; choose the fixed frame with --frame ({_names(frames)})")
    src.fixed_frame = fixed
    return src


def read_scans(
    path: Union[str, Path],
    topic: str,
    pose_from: Optional[str] = None,
    frame: Optional[str] = None,
    max_gap_ns: int = MAX_GAP_NS_DEFAULT,
    poses: Optional[PoseSource] = None,
) -> Iterator[BagScan]:
    """LaserScan messages of ``topic`` as :func:`scans` gives them, each with
    the pose of its laser frame in the fixed frame at its stamp when
    ``pose_from`` is given (see :func:`load_poses`; ``poses`` reuses one
    already loaded). A scan without a pose has ``pose`` None and
    ``pose_error`` saying why; it is still yielded.
    """
    if poses is None and pose_from is not None:
        poses = load_poses(path, pose_from, frame, max_gap_ns)
    for s in scans(path, topic):
        if poses is None or s.error is not None:
            yield s
            continue
        try:
            pose = poses.tree.lookup(poses.fixed_frame, s.frame_id, s.stamp_ns)
            s = replace(s, pose=pose)
        except PoseError as e:
            s = replace(s, pose_error=e.reason)
        yield s


def stamp_ms(stamp_ns: int) -> int:
    """Header time to the frame time: ms since the epoch, nearest."""
    return (stamp_ns + 500_000) // 1_000_000


class BagResult(NamedTuple):
    """What :func:`extract_bag` did."""

    written: int  #: frames written
    refused: int  #: messages refused (undecodable, bad geometry, refused by the library)
    bytes: int  #: bytes written
    no_pose: int = 0  #: scans skipped for want of a pose (with pose_from)


#: How many skipped scans' stamps a report lists.
REPORT_STAMPS = 5


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
    pose_from: Optional[str] = None,
    frame: Optional[str] = None,
    max_gap_ns: int = MAX_GAP_NS_DEFAULT,
    **params: Union[int, float],
) -> BagResult:
    """Write the frames of every LaserScan on ``topic`` to ``out`` ("-": stdout).

    ``range_max`` lowers each message's own limit (never raises it). Each
    refused message is reported to ``log`` (a text stream) with its index and
    reason. With ``pose_from`` (see :func:`load_poses`) every frame carries
    its laser's pose in the fixed frame; scans without one are skipped and
    reported (how many, why, the first stamps), never written without a pose.
    """
    import sys

    from . import QUANT_STEP_DEFAULT, Extractor

    from . import StreamWriter

    log = log or sys.stderr
    poses = load_poses(path, pose_from, frame, max_gap_ns) if pose_from is not None else None
    if poses is not None:
        for note in poses.notes():
            print(f"{path}: {pose_from}: {note}", file=log)
    ex = Extractor(method, timing=timing, **params)
    written = failed = 0
    no_pose: Dict[str, List[int]] = {}
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
        for s in read_scans(path, topic, poses=poses):
            where = f"{path}: {topic} message {s.index}"
            if s.error is not None:
                print(f"{where} skipped: {s.error}", file=log)
                failed += 1
                continue
            if poses is not None and s.pose is None:
                no_pose.setdefault(s.pose_error or "no pose", []).append(s.stamp_ns)
                continue
            rmax = min(s.range_max, range_max) if range_max else s.range_max
            try:
                fr = ex.extract(s.ranges, s.angle_min, s.angle_increment, s.range_min, rmax, seq=s.index, pose=s.pose)
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
    for reason, stamps in no_pose.items():
        first = ", ".join(f"{t / 1e9:.3f}" for t in stamps[:REPORT_STAMPS])
        more = ", ..." if len(stamps) > REPORT_STAMPS else ""
        print(
            f"{path}: {len(stamps)} scans of {topic} skipped, no pose in {poses.fixed_frame if poses else '?'}: "
            f"{reason}; stamps (s): {first}{more}",
            file=log,
        )
    return BagResult(written, failed, writer.bytes, sum(len(v) for v in no_pose.values()))
