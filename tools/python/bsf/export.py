# SPDX-License-Identifier: MIT
"""bsf streams to the viewers robotics people use (the ``rosbag`` extra).

``python -m bsf export IN.bsf -o OUT.mcap`` writes an MCAP file (Foxglove
opens it; ``ros2 bag play`` plays it where the MCAP storage plugin is
installed) and ``-o OUTDIR --format ros2bag`` a ROS 2 bag directory (SQLite
storage, for ``ros2 bag play`` and RViz 2). Both hold ROS 2 messages,
stamped at each scan's time from the stream:

- ``/bsf/features``: ``visualization_msgs/msg/MarkerArray`` per scan: a
  DELETEALL (the previous scan's markers go), a LINE_STRIP per feature
  (namespace ``features``, id = the feature's index, the curve sampled
  evenly in its parameter) and one SPHERE_LIST of the scan's vertices
  (namespace ``vertices``);
- ``/bsf/pose``: ``geometry_msgs/msg/PoseStamped``, the laser's pose, per scan
  that has one;
- ``/bsf/path``: ``nav_msgs/msg/Path`` of every pose, once, at the first
  posed scan's time (offered transient-local, so a late subscriber gets it).

A map stream (``bsf extract --map``) gives, from the receiver's map
(:class:`bsf.Map`) rebuilt frame by frame:

- ``/bsf/map``: ``visualization_msgs/msg/MarkerArray`` of the whole map every
  ``map_every`` map frames and after the last one: a DELETEALL, a LINE_STRIP
  per map feature (namespace ``map``, id = the feature's id; the curve through
  ``map_per_span`` samples per span of its world-frame control points, a
  feature of two control points as their segment; stale features in grey)
  and one SPHERE_LIST of the map's vertices (namespace ``vertices``),
  offered transient-local;
- ``/bsf/pose`` at each map frame that carries a pose record, and ``/bsf/path``
  of those poses, as for scans.

A map frame carries no time (docs/FORMAT.md section 11), so its stamp is
derived: the time origin of the stream's metadata plus its sequence number
(counted from the first map frame's) divided by ``map_rate`` (Hz; 10 by
default, one frame per scan for a 10 Hz scanner with ``--pose-every 1``). A
lost frame (a gap in the sequence numbers) keeps the later stamps in place.

Frames with a pose are drawn in the fixed frame (``frame_id``), frames
without one in the laser frame (``laser_frame``). Anything else that is a
set of curves and points in the fixed frame (the fused map) goes through
:meth:`Exporter.add_markers` on a topic of its own.

Messages are built and serialised (CDR) with rosbags' ROS 2 Humble types,
whose definitions also go into the MCAP schemas; the MCAP container is
written with the ``mcap`` package.
"""
from __future__ import annotations

import math
import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import Frame, Map, MapFeature, MapFrame, Metadata, read

FORMATS = ("mcap", "ros2bag")
MARKER_ARRAY = "visualization_msgs/msg/MarkerArray"
POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
PATH = "nav_msgs/msg/Path"

# visualization_msgs/Marker constants
LINE_STRIP = 4
SPHERE_LIST = 7
ADD = 0
DELETEALL = 3

#: RGBA of each thing drawn
COLORS = {
    "bleak": (0.12, 0.47, 0.71, 1.0),
    "auxiliary": (1.0, 0.5, 0.05, 1.0),
    "vertices": (0.84, 0.15, 0.16, 1.0),
    "map": (0.17, 0.63, 0.17, 1.0),
    "stale": (0.6, 0.6, 0.6, 1.0),
}
LINE_WIDTH = 0.02  #: metres
SPHERE_SIZE = 0.06  #: metres


class ExportError(Exception):
    """The export cannot be written (missing packages, an existing bag directory, ...)."""


def frame_stamp_ns(frame: Frame) -> int:
    """A frame's absolute time, ns since the epoch: the metadata's time origin
    plus the frame's ms (format 2), or the frame's ms as sent (format 1)."""
    if frame.metadata is not None and frame.metadata.time_origin_us is not None:
        return int(frame.metadata.time_origin_us) * 1000 + int(frame.timestamp_ms) * 1_000_000
    return int(frame.timestamp_ms) * 1_000_000


def map_lines(features: Sequence[MapFeature], per_span: int) -> List[np.ndarray]:
    """The polylines the export draws for map features: ``per_span`` samples per
    span of each curve (:meth:`MapFeature.sample`), the segment itself for a
    feature of two control points (no quadratic span yet)."""
    return [f.sample(per_span) if len(f.ctrl) >= 3 else np.asarray(f.ctrl, dtype=np.float64) for f in features]


def map_vertices(features: Sequence[MapFeature]) -> np.ndarray:
    """Every vertex of the map features, shape (k, 2), float64."""
    if not features:
        return np.zeros((0, 2))
    return np.concatenate([np.asarray(f.vertices, dtype=np.float64).reshape(-1, 2) for f in features])


def _typestore():
    try:
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise ExportError("export needs rosbags and mcap: pip install './tools/python[rosbag]'") from None
    return get_typestore(Stores.ROS2_HUMBLE)


@dataclass
class ExportResult:
    frames: int = 0  #: scan frames exported
    map_frames: int = 0  #: map frames applied to the exported map
    messages: Dict[str, int] = field(default_factory=dict)  #: messages per topic


class Exporter:
    """Writes ROS 2 messages to an MCAP file or a ROS 2 bag directory.

    Use as a context manager; :meth:`add_frame` per scan, :meth:`add_markers`
    for any other curves (the fused map), :meth:`close` (or leaving the
    ``with``) writes the path and finishes the file.
    """

    def __init__(
        self,
        out: Union[str, "os.PathLike[str]"],
        fmt: str = "mcap",
        *,
        frame_id: str = "map",
        laser_frame: str = "laser",
        samples: int = 32,
        prefix: str = "/bsf",
        map_rate: float = 10.0,
        map_every: int = 10,
        map_per_span: int = 4,
    ):
        if fmt not in FORMATS:
            raise ExportError(f"unknown format {fmt!r}; one of {', '.join(FORMATS)}")
        if int(samples) < 2:
            raise ExportError(f"samples must be at least 2, got {samples}")
        if not frame_id or not laser_frame:
            raise ExportError("frame names must not be empty")
        if not prefix.startswith("/") or any(c.isspace() for c in prefix):
            raise ExportError(f"the topic prefix must start with '/' and hold no spaces, got {prefix!r}")
        if not (isinstance(map_rate, (int, float)) and math.isfinite(map_rate) and 0.001 <= map_rate <= 1e6):
            raise ExportError(f"the map frame rate must be 0.001 .. 1e6 Hz, got {map_rate}")
        if int(map_every) < 1:
            raise ExportError(f"map_every must be at least 1, got {map_every}")
        if not 1 <= int(map_per_span) <= 64:
            raise ExportError(f"map_per_span must be 1 .. 64, got {map_per_span}")
        self.map_rate = float(map_rate)
        self.map_every = int(map_every)
        self.map_per_span = int(map_per_span)
        self._map: Optional[Map] = None
        self._map_seq = 0  # sequence number of the last map frame applied
        self._map_tick = 0  # frame periods since the first map frame
        self._map_origin_ns = 0
        self._map_stamp_ns = 0  # stamp of the last map frame applied
        self._map_published = True  # the map as it is now was published
        self.fmt = fmt
        self.frame_id = frame_id
        self.laser_frame = laser_frame
        self.samples = int(samples)
        self.prefix = prefix.rstrip("/")
        self.result = ExportResult()
        self._store = _typestore()
        self._T = self._store.types
        self._path: List[Tuple[int, Tuple[float, float, float]]] = []
        self._channels: Dict[str, Any] = {}
        self._closed = False
        out = Path(out)
        if fmt == "mcap":
            try:
                from mcap.writer import Writer as McapWriter
            except ImportError:
                raise ExportError("MCAP export needs mcap: pip install './tools/python[rosbag]'") from None
            self._file = open(out, "wb")
            self._mcap = McapWriter(self._file)
            self._mcap.start(profile="ros2", library="bsf")
            self._schemas: Dict[str, int] = {}
        else:
            from rosbags.rosbag2 import StoragePlugin, Writer as BagWriter

            if out.exists():
                raise ExportError(f"{out} exists; a ROS 2 bag is written into a new directory")
            self._bag = BagWriter(out, version=8, storage_plugin=StoragePlugin.SQLITE3)
            try:
                self._bag.open()
            except Exception as e:  # rosbags raises its own error types
                raise ExportError(f"{out}: cannot create the bag: {e}") from None

    # ---- messages ------------------------------------------------------------

    def _time(self, ns: int):
        return self._T["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)

    def _header(self, ns: int, frame_id: str):
        return self._T["std_msgs/msg/Header"](stamp=self._time(ns), frame_id=frame_id)

    def _pose(self, x: float = 0.0, y: float = 0.0, yaw: float = 0.0):
        T = self._T
        return T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=0.0),
            orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2.0), w=math.cos(yaw / 2.0)),
        )

    def _marker(self, ns: int, frame_id: str, name: str, mid: int, mtype: int, action: int, points: np.ndarray, color, size: float):
        T = self._T
        P = T["geometry_msgs/msg/Point"]
        return T["visualization_msgs/msg/Marker"](
            header=self._header(ns, frame_id),
            ns=name,
            id=int(mid),
            type=int(mtype),
            action=int(action),
            pose=self._pose(),
            scale=T["geometry_msgs/msg/Vector3"](x=size, y=size, z=size),
            color=T["std_msgs/msg/ColorRGBA"](r=color[0], g=color[1], b=color[2], a=color[3]),
            lifetime=T["builtin_interfaces/msg/Duration"](sec=0, nanosec=0),
            frame_locked=False,
            points=[P(x=float(p[0]), y=float(p[1]), z=0.0) for p in points],
            colors=[],
            texture_resource="",
            texture=T["sensor_msgs/msg/CompressedImage"](header=self._header(0, ""), format="", data=np.zeros(0, np.uint8)),
            uv_coordinates=[],
            text="",
            mesh_resource="",
            mesh_file=T["visualization_msgs/msg/MeshFile"](filename="", data=np.zeros(0, np.uint8)),
            mesh_use_embedded_materials=False,
        )

    # ---- writing -------------------------------------------------------------

    def _write(self, topic: str, msgtype: str, ns: int, msg: Any, latched: bool = False) -> None:
        data = bytes(self._store.serialize_cdr(msg, msgtype))
        ch = self._channels.get(topic)
        if self.fmt == "mcap":
            if ch is None:
                sid = self._schemas.get(msgtype)
                if sid is None:
                    text = self._store.generate_msgdef(msgtype, ros_version=2)[0]
                    sid = self._schemas[msgtype] = self._mcap.register_schema(msgtype, "ros2msg", text.encode())
                from rosbags.rosbag2.metadata import dump_qos_v8

                meta = {"offered_qos_profiles": dump_qos_v8(_qos(latched))}
                ch = self._channels[topic] = self._mcap.register_channel(topic, "cdr", sid, meta)
            self._mcap.add_message(ch, log_time=ns, data=data, publish_time=ns)
        else:
            if ch is None:
                ch = self._channels[topic] = self._bag.add_connection(
                    topic, msgtype, typestore=self._store, offered_qos_profiles=_qos(latched)
                )
            self._bag.write(ch, ns, data)
        self.result.messages[topic] = self.result.messages.get(topic, 0) + 1

    def add_markers(
        self,
        topic: str,
        stamp_ns: int,
        lines: Sequence[np.ndarray],
        points: Optional[np.ndarray] = None,
        *,
        frame_id: Optional[str] = None,
        ns: str = "curves",
        colors: Optional[Sequence[Tuple[float, float, float, float]]] = None,
        ids: Optional[Sequence[int]] = None,
        replace: bool = True,
        latched: bool = False,
    ) -> None:
        """One MarkerArray on ``topic``: a LINE_STRIP per polyline in ``lines``
        (each (k, 2), k >= 2, namespace ``ns``, id = its index) and the
        ``points`` ((m, 2)) as one SPHERE_LIST (namespace ``vertices``), in
        ``frame_id`` (default: the fixed frame). ``ids`` replaces the indices
        as marker ids (int32). ``replace`` first deletes every marker this
        topic drew before; ``latched`` offers the topic transient-local."""
        if stamp_ns < 0:
            raise ExportError(f"a stamp before 1970 cannot be written ({stamp_ns} ns)")
        fid = frame_id or self.frame_id
        ms = []
        if replace:
            ms.append(self._marker(stamp_ns, fid, "", 0, 0, DELETEALL, np.zeros((0, 2)), (0, 0, 0, 0), 0.0))
        for i, pts in enumerate(lines):
            pts = np.asarray(pts, dtype=np.float64)
            if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] < 2 or not np.all(np.isfinite(pts)):
                raise ExportError(f"{topic}: line {i} is not two or more finite (x, y) points")
            color = colors[i] if colors is not None else COLORS["map"]
            mid = i if ids is None else int(ids[i])
            if not -(2**31) <= mid < 2**31:
                raise ExportError(f"{topic}: marker id {mid} does not fit a ROS marker id (int32)")
            ms.append(self._marker(stamp_ns, fid, ns, mid, LINE_STRIP, ADD, pts, color, LINE_WIDTH))
        if points is not None and len(points):
            pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
            if not np.all(np.isfinite(pts)):
                raise ExportError(f"{topic}: points are not finite")
            ms.append(self._marker(stamp_ns, fid, "vertices", 0, SPHERE_LIST, ADD, pts, COLORS["vertices"], SPHERE_SIZE))
        self._write(topic, MARKER_ARRAY, stamp_ns, self._T[MARKER_ARRAY](markers=ms), latched=latched)

    def add_frame(self, frame: Frame) -> None:
        """One scan: its features and vertices on ``<prefix>/features``, its pose on ``<prefix>/pose``."""
        ns = frame_stamp_ns(frame)
        fid = self.frame_id if frame.pose is not None else self.laser_frame
        lines = [f.sample(self.samples, frame.pose) for f in frame.features]
        colors = [COLORS.get(f.kind, COLORS["bleak"]) for f in frame.features]
        self.add_markers(
            self.prefix + "/features", ns, lines, frame.vertices(world=True), frame_id=fid, ns="features", colors=colors
        )
        if frame.pose is not None:
            self._pose_message(ns, frame.pose)
        self.result.frames += 1

    def _pose_message(self, ns: int, pose: Tuple[float, float, float]) -> None:
        self._write(
            self.prefix + "/pose",
            POSE_STAMPED,
            ns,
            self._T[POSE_STAMPED](header=self._header(ns, self.frame_id), pose=self._pose(*pose)),
        )
        self._path.append((ns, pose))

    def _map_tick_of(self, frame: MapFrame) -> int:
        """Frame periods from the first map frame to this one: the sequence
        number's step, a step back (a new stream) counting as one."""
        if self._map is None:
            return 0
        step = (int(frame.seq) - self._map_seq) % 2**32
        return self._map_tick + (step if 0 < step < 2**31 else 1)

    def add_map_frame(self, frame: MapFrame, metadata: Optional[Metadata] = None) -> None:
        """One map frame: applied to the export's receiver map (BsfError when
        the receiver refuses it), its pose record on ``<prefix>/pose``, and
        the whole map on ``<prefix>/map`` every ``map_every`` map frames.
        Its stamp is the time origin of ``metadata`` (the one in force at the
        first map frame; 0 without one) plus the frame periods since the
        first map frame (see the module's description)."""
        if not isinstance(frame, MapFrame):
            raise TypeError(f"add_map_frame needs a MapFrame, got {type(frame).__name__}")
        tick = self._map_tick_of(frame)
        if self._map is None:
            if metadata is not None and metadata.time_origin_us is not None:
                self._map_origin_ns = int(metadata.time_origin_us) * 1000
            self._map = Map()
        ns = self._map_origin_ns + round(tick * 1e9 / self.map_rate)
        poses = len(self._map.path)
        self._map.apply(frame)
        self._map_seq, self._map_tick, self._map_stamp_ns = int(frame.seq), tick, ns
        self._map_published = False
        self.result.map_frames += 1
        if len(self._map.path) > poses:
            self._pose_message(ns, self._map.path[-1])
        if self.result.map_frames % self.map_every == 0:
            self.publish_map()

    def publish_map(self) -> None:
        """The receiver's whole map on ``<prefix>/map`` at the last map frame's stamp."""
        if self._map is None:
            raise ExportError("no map frame was added")
        feats = self._map.features
        self.add_markers(
            self.prefix + "/map",
            self._map_stamp_ns,
            map_lines(feats, self.map_per_span),
            map_vertices(feats),
            ns="map",
            ids=[f.id for f in feats],
            colors=[COLORS["stale"] if f.stale else COLORS["map"] for f in feats],
            latched=True,
        )
        self._map_published = True

    @property
    def map(self) -> Optional[Map]:
        """The receiver's map of the map frames added so far (None before the first)."""
        return self._map

    def close(self) -> ExportResult:
        """Publish the final map, write the path and finish the file (idempotent)."""
        if self._closed:
            return self.result
        self._closed = True
        try:
            if self._map is not None and not self._map_published:
                self.publish_map()
            if self._path:
                first = min(ns for ns, _ in self._path)
                poses = [self._T[POSE_STAMPED](header=self._header(ns, self.frame_id), pose=self._pose(*p)) for ns, p in self._path]
                self._write(self.prefix + "/path", PATH, first, self._T[PATH](header=self._header(first, self.frame_id), poses=poses), latched=True)
        finally:
            if self.fmt == "mcap":
                self._mcap.finish()
                self._file.close()
            else:
                self._bag.close()
        return self.result

    def __enter__(self) -> "Exporter":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def _qos(latched: bool) -> list:
    """The offered QoS stored with a topic: reliable, keep-last, transient-local
    when latched (a late subscriber still gets the message), deadline,
    lifespan and lease 0 (the middleware's default, no limit)."""
    from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime

    zero = QosTime(0, 0)
    return [
        Qos(
            QosHistory.KEEP_LAST,
            1 if latched else 10,
            QosReliability.RELIABLE,
            QosDurability.TRANSIENT_LOCAL if latched else QosDurability.VOLATILE,
            zero,
            zero,
            QosLiveliness.AUTOMATIC,
            zero,
            False,
        )
    ]


def export(
    source: Union[str, "os.PathLike[str]", Iterable[Union[Frame, Metadata]]],
    out: Union[str, "os.PathLike[str]"],
    fmt: Optional[str] = None,
    **options: Any,
) -> ExportResult:
    """Export a bsf stream (a path, or frames) to ``out``: see the module's
    description. ``fmt`` defaults to "mcap" for a name ending in .mcap;
    ``options`` go to :class:`Exporter` (frame_id, laser_frame, samples, prefix,
    map_rate, map_every, map_per_span).
    Raises ExportError, BsfError (a bad stream) or OSError."""
    if fmt is None:
        if not os.fspath(out).endswith(".mcap"):
            raise ExportError(f"{os.fspath(out)}: name an MCAP file *.mcap, or give the format (ros2bag for a bag directory)")
        fmt = "mcap"
    frames = read(source) if isinstance(source, (str, os.PathLike)) else source
    ex = Exporter(out, fmt, **options)
    try:
        with ex:
            meta: Optional[Metadata] = None
            for f in frames:
                if isinstance(f, Metadata):
                    meta = f
                elif isinstance(f, Frame):
                    ex.add_frame(f)
                elif isinstance(f, MapFrame):
                    ex.add_map_frame(f, meta)
        if ex.result.frames == 0 and ex.result.map_frames == 0:
            raise ExportError(f"{os.fspath(source) if isinstance(source, (str, os.PathLike)) else 'the stream'} holds no scan frame and no map frame")
    except BaseException:
        # no half-written output is left behind for a viewer to open
        target = Path(out)
        if fmt == "mcap":
            target.unlink(missing_ok=True)
        else:
            shutil.rmtree(target, ignore_errors=True)
        raise
    return ex.result
