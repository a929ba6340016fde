# SPDX-License-Identifier: MIT
"""bsf for Python: B-spline features from 2D LIDAR scans.

The numerical work is the C library itself (``src/`` of the bsf repository,
compiled into ``bsf._core`` with host-sized caps, see :data:`caps`); this
package moves numpy arrays in and out of it and adds stream reading, ROS bag
conversion (``python -m bsf extract BAG --topic /scan -o out.bsf``) and
plotting.

>>> import numpy as np, bsf
>>> angles = np.linspace(-1.5, 1.5, 301)
>>> ranges = (2.0 / np.cos(angles)).astype(np.float32)     # a straight wall
>>> frame = bsf.extract(ranges, -1.5, 3.0 / 300, 0.05, 30.0)
>>> [f.kind for f in frame.features], frame.stats.n_valid
(['bleak'], 301)
>>> data = bsf.encode(frame)                                 # wire bytes
>>> bsf.decode(data)[0].features[0].ctrl.shape[1]
2

Everything is in the sensor frame (metres, radians, x ahead, y left) unless a
pose (x, y, theta of the laser in the world) is given.
"""
from __future__ import annotations

import io
import math
import operator
import os
import stat
import sys
import threading
from dataclasses import dataclass, field, fields, replace
from typing import IO, Any, Dict, Iterable, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _core
from ._core import BsfError

__all__ = [
    "__version__",
    "BsfError",
    "Feature",
    "ScanStats",
    "Frame",
    "Metadata",
    "MapFrame",
    "MapFeature",
    "Map",
    "read_map",
    "StreamWriter",
    "HAS_METADATA",
    "Extractor",
    "Decoder",
    "CarmenScan",
    "caps",
    "default_params",
    "extract",
    "encode",
    "decode",
    "read",
    "read_carmen",
    "extract_log",
    "plot",
    "METHODS",
]

#: Version of the compiled C library, "MAJOR.MINOR.PATCH"; the package's own
#: version is the same (setup.py reads it from include/bsf/bsf_version.h).
__version__: str = _core.version()

#: Compile-time caps of this build (beams per scan, keypoints, segments,
#: control points) and the wire format version it writes.
caps: Dict[str, int] = dict(_core.caps)

#: Extraction methods, as the C tool spells them, in bsf_method_t order (the
#: stream carries the index); the default is "lc-sved-pdm".
METHODS: Tuple[str, ...] = ("falko-sved-pdm", "bid-sved-pdm", "rpos-lsba", "lc-sved-pdm")

#: True when this build's wire format has the metadata frame (format version 2).
HAS_METADATA: bool = hasattr(_core, "encode_metadata")

#: Default quantisation step of control points on the wire, metres.
QUANT_STEP_DEFAULT: float = float(_core.QUANT_STEP_DEFAULT)

Pose = Tuple[float, float, float]

_KINDS = ("bleak", "auxiliary")


def default_params(method: str = "lc-sved-pdm") -> Dict[str, Union[int, float]]:
    """Every runtime parameter of ``method`` with its default value.

    The names are ``<stage>_<field>`` of the C ``bsf_params_t`` (for example
    ``pdm_target_rms``, ``sved_a``, ``falko_min_score_th``); pass any of them
    as keyword arguments to :func:`extract` or :class:`Extractor`.
    """
    return _readable_params(_core.default_params(method))


def _readable_params(params: Dict[str, Union[int, float]]) -> Dict[str, Union[int, float]]:
    """Parameters as the library holds them (float32), each float written as
    the shortest decimal that is the same float32: 0.2, not 0.20000000298023224.
    Passed back to :func:`extract`, each gives the same float32 again."""
    return {k: float(str(np.float32(v))) if isinstance(v, float) else v for k, v in params.items()}


# ---- data model -------------------------------------------------------------------


@dataclass(frozen=True)
class ScanStats:
    """Per-scan statistics (C ``bsf_stats_t``). Fields that a decoded frame does
    not carry are 0."""

    n_beams: int = 0  #: beams of the scan (index space)
    n_valid: int = 0  #: N, valid readings
    n_in_features: int = 0  #: points in kept features
    n_ctrl: int = 0  #: stored control points (a vertex counts twice)
    n_features: int = 0
    n_keypoints: int = 0
    n_unfitted: int = 0
    cut: int = 0  #: BSF_CUT_* bits: which cap cut the output
    n_cut_keypoints: int = 0
    n_cut_segments: int = 0
    n_cut_points: int = 0
    time_ns: int = 0  #: extraction time, ns (0 without a clock)
    n_fit_visits: int = 0  #: the fit's work: points (bins, with ``fit_bin_length``) visited by its footpoint passes (``fit_passes`` bounds it)
    stage_ns: Tuple[int, ...] = (0, 0, 0, 0)  #: points, corners, segments, fit

    @classmethod
    def _from_dict(cls, d: Dict[str, Any]) -> "ScanStats":
        names = {f.name for f in fields(cls)}
        return cls(**{k: (tuple(v) if k == "stage_ns" else int(v)) for k, v in d.items() if k in names})

    def _to_dict(self) -> Dict[str, int]:
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name != "stage_ns"}


def _transform(points: np.ndarray, pose: Optional[Pose]) -> np.ndarray:
    pts = np.asarray(points, dtype=np.float64)
    if pose is None:
        return pts
    x, y, th = (float(v) for v in pose)
    if not all(math.isfinite(v) for v in (x, y, th)):
        raise BsfError(f"pose must be three finite numbers, got {pose!r}")
    c, s = math.cos(th), math.sin(th)
    out = np.empty_like(pts)
    out[..., 0] = x + c * pts[..., 0] - s * pts[..., 1]
    out[..., 1] = y + s * pts[..., 0] + c * pts[..., 1]
    return out


@dataclass(frozen=True, eq=False)
class Feature:
    """One B-spline feature: a clamped uniform quadratic B-spline.

    ``ctrl`` holds its control points (float32, shape (n, 2), sensor frame,
    metres); a vertex (corner) is stored twice in a row and both copies are
    flagged in ``vertex``. ``first_beam > last_beam`` means the feature wraps
    through the seam of a full-circle scan (see :meth:`beam_runs`).
    """

    kind: str  #: "bleak" (no corner) or "auxiliary" (has vertices)
    first_beam: int
    last_beam: int
    n_points: int  #: valid points the feature covers
    e_curve: float  #: RMS distance of its points to the curve, metres
    ctrl: np.ndarray
    vertex: np.ndarray
    n_beams: int = 0  #: beams of its scan (needed for a wrapping feature), 0 if unknown

    @property
    def wraps(self) -> bool:
        """True when the beam run goes through the seam of a full-circle scan."""
        return self.first_beam > self.last_beam

    def beam_runs(self) -> List[Tuple[int, int]]:
        """Inclusive beam index runs: one, or two for a wrapping feature."""
        if not self.wraps:
            return [(self.first_beam, self.last_beam)]
        if self.n_beams <= self.first_beam:
            raise BsfError("this wrapping feature's scan size is unknown (n_beams not carried)")
        return [(self.first_beam, self.n_beams - 1), (0, self.last_beam)]

    def beams(self) -> np.ndarray:
        """Every beam index in the feature's run(s), in scan order from first_beam."""
        return np.concatenate([np.arange(a, b + 1) for a, b in self.beam_runs()])

    @property
    def vertices(self) -> np.ndarray:
        """Distinct vertex (corner) positions, shape (k, 2), sensor frame."""
        flagged = np.flatnonzero(self.vertex)
        return self.ctrl[flagged[::2]]

    def sample(self, n: int = 32, pose: Optional[Pose] = None) -> np.ndarray:
        """``n`` points evenly spaced in the curve parameter, shape (n, 2), float64.

        In the sensor frame, or in the world frame when ``pose`` (laser x, y,
        theta in the world) is given. The first and last samples are the end
        control points (the curve is clamped).
        """
        if int(n) < 2:
            raise BsfError(f"sample needs n >= 2, got {n}")
        t = np.linspace(0.0, 1.0, int(n), dtype=np.float32)
        raw = _core.bspline_eval(np.ascontiguousarray(self.ctrl, dtype=np.float32), t)
        pts = np.frombuffer(raw, dtype=np.float32).reshape(-1, 2)
        return _transform(pts, pose)


@dataclass(frozen=True)
class Metadata:
    """A metadata frame (stream format version 2): what produced the stream.

    Frames after it are interpreted with it: ``timestamp_ms`` counts from
    ``time_origin_us`` (Unix time, microseconds), beams follow its geometry
    unless a frame carries its own.
    """

    lib_version: Tuple[int, int, int]
    method_id: int
    target_rms: float
    quant_step: float
    caps: Dict[str, int]  #: points, keypoints, segments, ctrl_per_feature, ctrl_points
    n_beams: int
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    time_origin_us: Optional[int] = None
    source: Optional[str] = None
    version: int = 2
    bytes: int = 0

    @property
    def method(self) -> Optional[str]:
        """The method's name, None for an id this version does not know."""
        return METHODS[self.method_id] if 0 <= self.method_id < len(METHODS) else None

    def _to_dict(self) -> Dict[str, Any]:
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name not in ("version", "bytes")}


@dataclass(frozen=True, eq=False)
class Frame:
    """One scan's features, as extracted or as decoded from a stream.

    ``quant_step`` is None for a fresh extraction (control points exact) and
    the wire step for a decoded frame (control points within half a step).
    """

    seq: int
    timestamp_ms: int
    pose: Optional[Pose]
    features: List[Feature]
    stats: ScanStats
    quant_step: Optional[float] = None
    time_us: int = 0  #: extraction time carried by the frame, microseconds
    version: int = 0  #: wire format version (0 for a fresh extraction)
    type: int = 1  #: frame type (1: features)
    bytes: int = 0  #: size on the wire (decoded frames; 0 otherwise)
    #: (angle_min, angle_increment) when the frame carries its own scan geometry
    geometry: Optional[Tuple[float, float]] = None
    #: the stream's metadata in force for this frame (decoded streams of version 2)
    metadata: Optional[Metadata] = None

    @property
    def unix_time_ms(self) -> Optional[float]:
        """Absolute scan time (ms since 1970) when the stream's metadata gives a time origin."""
        if self.metadata is None or self.metadata.time_origin_us is None:
            return None
        return self.metadata.time_origin_us / 1000.0 + self.timestamp_ms

    def sample(self, n: int = 32, world: bool = True) -> List[np.ndarray]:
        """Every feature sampled with :meth:`Feature.sample`; in the world frame
        when ``world`` and the frame has a pose, else in the sensor frame."""
        pose = self.pose if world else None
        return [f.sample(n, pose) for f in self.features]

    def vertices(self, world: bool = True) -> np.ndarray:
        """All distinct vertices of the frame, shape (k, 2)."""
        vs = [f.vertices for f in self.features]
        pts = np.concatenate(vs) if vs else np.zeros((0, 2), np.float32)
        return _transform(pts, self.pose if world else None)


def _features_from(res: tuple, n_beams_hint: int = 0) -> Tuple[List[Feature], ScanStats]:
    feats, ctrl_b, vert_b, stats_d = res
    stats = ScanStats._from_dict(stats_d)
    ctrl = np.frombuffer(ctrl_b, dtype=np.float32).reshape(-1, 2).copy()
    vert = np.frombuffer(vert_b, dtype=np.uint8).astype(bool)
    n_beams = stats.n_beams or n_beams_hint
    out = []
    for first, last, npts, kind, e_curve, c0, nc in feats:
        out.append(
            Feature(
                kind=_KINDS[kind] if 0 <= kind < len(_KINDS) else str(kind),
                first_beam=first,
                last_beam=last,
                n_points=npts,
                e_curve=e_curve,
                ctrl=ctrl[c0 : c0 + nc],
                vertex=vert[c0 : c0 + nc],
                n_beams=n_beams,
            )
        )
    return out, stats


def _frame_from_tuple(
    t: tuple, nbytes: int = 0, meta: Optional[Metadata] = None
) -> Union[Frame, Metadata, "MapFrame", None]:
    """A decoder tuple to a Frame, a Metadata or a MapFrame; None for a frame type this version skips.

    The tag in t[0] says the frame type ("features", "metadata", "map", "other").
    """
    if t[0] == "map":
        return MapFrame(seq=t[3], payload=bytes(t[4]), version=t[1], type=t[2], bytes=nbytes)
    if t[0] == "metadata":
        d = dict(t[3])
        d["lib_version"] = tuple(d["lib_version"])
        return Metadata(**d, version=t[1], bytes=nbytes)
    if t[0] != "features":
        return None
    _, version, ftype, seq, ts, pose, quant, time_us, res, geometry = t
    hint = meta.n_beams if meta is not None else 0
    feats, stats = _features_from(res, hint)
    return Frame(
        seq=seq,
        timestamp_ms=ts,
        pose=None if pose is None else (float(pose[0]), float(pose[1]), float(pose[2])),
        features=feats,
        stats=stats,
        quant_step=quant,
        time_us=time_us,
        version=version,
        type=ftype,
        bytes=nbytes,
        geometry=None if geometry is None else (float(geometry[0]), float(geometry[1])),
        metadata=meta,
    )


# ---- the fused map --------------------------------------------------------------------


@dataclass(frozen=True)
class MapFrame:
    """A map-update frame (``bsf extract --map``): what changed in the robot's map.

    Apply it to a :class:`Map` (the library's receiver) to rebuild the map;
    ``payload`` is the frame's checked content.
    """

    seq: int  #: map frame sequence number (its own numbering)
    payload: bytes
    version: int = 2
    type: int = 3
    bytes: int = 0  #: size on the wire


def _bspline_points(ctrl: np.ndarray, per_span: int) -> np.ndarray:
    """A clamped uniform quadratic B-spline with any number (>= 3) of control
    points, ``per_span`` samples per span, shape (spans * per_span + 1, 2)."""
    c = np.asarray(ctrl, dtype=np.float64)
    spans = len(c) - 2
    u = np.arange(per_span, dtype=np.float64) / per_span
    a, b, q = (1 - u) ** 2, 2 * u * (1 - u), u * u
    out = []
    for s in range(spans):
        if spans == 1:
            w = (a, b, q)
        elif s == 0:
            w = (a, b + 0.5 * q, 0.5 * q)
        elif s == spans - 1:
            w = (0.5 * a, 0.5 * a + b, q)
        else:
            w = (0.5 * a, 0.5 * a + b + 0.5 * q, 0.5 * q)
        out.append(w[0][:, None] * c[s] + w[1][:, None] * c[s + 1] + w[2][:, None] * c[s + 2])
    out.append(c[-1][None, :])
    return np.concatenate(out)


@dataclass(frozen=True, eq=False)
class MapFeature:
    """One feature of the fused map: a clamped uniform quadratic B-spline in the
    world frame (metres). A vertex (corner) is a control point given twice in a
    row, both copies flagged in ``vertex``, as in a scan's :class:`Feature`.
    ``stale`` is True when the receiver cannot vouch for it: map frames were
    lost since it was last confirmed (by a snapshot, or a record whose update
    count shows it missed nothing), or a record of it could not apply, and no
    snapshot has repaired it yet."""

    id: int
    ctrl: np.ndarray  #: float32, shape (n, 2), world frame
    vertex: np.ndarray  #: uint8, shape (n,)
    stale: bool = False

    @property
    def vertices(self) -> np.ndarray:
        """Distinct vertex (corner) positions, shape (k, 2)."""
        flagged = np.flatnonzero(self.vertex)
        return self.ctrl[flagged[::2]]

    def sample(self, per_span: int = 16) -> np.ndarray:
        """Points along the curve, ``per_span`` per span, shape (m, 2), float64."""
        if int(per_span) < 1:
            raise BsfError(f"sample needs per_span >= 1, got {per_span}")
        return _bspline_points(self.ctrl, int(per_span))

    def length(self) -> float:
        """Curve length, metres (through 16 samples per span)."""
        p = self.sample(16)
        return float(np.hypot(*np.diff(p, axis=0).T).sum())


class Map:
    """The receiver's map of a map stream: feed it :class:`MapFrame` objects
    (or a whole stream with :func:`read_map`); it holds every feature the robot
    ever sent, exactly the control point values the robot sent.

    ``path`` collects the robot's poses from the stream's pose records.
    """

    def __init__(self) -> None:
        if not hasattr(_core, "MapReceiver"):
            raise BsfError("this build of bsf has no map (bsf_map.h)")
        self._rx = _core.MapReceiver()
        self.path: List[Pose] = []  #: poses received, in order
        self.frames = 0  #: map frames applied
        self.bytes = 0  #: their bytes on the wire

    def apply(self, frame: MapFrame) -> int:
        """Apply one map frame; returns the number of records the receiver
        could not apply (a lost frame before them). Raises BsfError when the
        payload is refused (not a map frame, malformed)."""
        if not isinstance(frame, MapFrame):
            raise TypeError(f"Map.apply needs a MapFrame, got {type(frame).__name__}")
        poses = self._rx.counters["poses"]
        skipped = self._rx.apply(frame.payload)
        if self._rx.counters["poses"] != poses and self._rx.pose is not None:
            self.path.append(tuple(self._rx.pose))
        self.frames += 1
        self.bytes += frame.bytes
        return int(skipped)

    @property
    def features(self) -> List[MapFeature]:
        """Every feature the receiver holds, by increasing id."""
        out = []
        for fid, ctrl_b, vtx_b, stale in self._rx.features():
            ctrl = np.frombuffer(ctrl_b, dtype=np.float32).reshape(-1, 2).copy()
            vtx = np.frombuffer(vtx_b, dtype=np.uint8).copy()
            out.append(MapFeature(id=int(fid), ctrl=ctrl, vertex=vtx, stale=bool(stale)))
        return out

    @property
    def missing(self) -> List[int]:
        """Ids the robot sent that never arrived (a lost frame, a late join):
        the receiver holds no points for them. Ids are given in send order, so
        every id below the largest seen was sent."""
        return [int(i) for i in self._rx.missing()]

    @property
    def more_missing(self) -> bool:
        """True when, after a loss, features with ids above the largest seen may
        have been sent and never received (until a new feature, or the id-limit
        record that starts each snapshot round, arrives)."""
        return bool(self._rx.more_missing())

    def note_loss(self) -> None:
        """Tell the map that the link dropped a frame (a damaged one the
        decoder refused): every feature is unconfirmed (``stale``) until the
        next map frame's sequence number shows whether a map frame was lost."""
        self._rx.note_loss()

    @property
    def counters(self) -> Dict[str, int]:
        """frames, frames_missed, records, records_skipped, snapshots, poses."""
        return dict(self._rx.counters)

    @property
    def pose(self) -> Optional[Pose]:
        """The last pose record received, or None."""
        p = self._rx.pose
        return None if p is None else (float(p[0]), float(p[1]), float(p[2]))


def read_map(source: "Source", *, baudrate: int = 115200, chunk_size: int = 65536) -> Map:
    """The map of a whole map stream (a path, "-", a file object: as :func:`read`).

    Raises BsfError when the stream holds no map frame (a per-scan stream, or
    garbage) or the receiver refuses a frame.
    """
    m = Map()
    dec = Decoder()
    dropped_at_map = 0
    for fr in _read(source, dec, baudrate, chunk_size, by_frame=True):
        if isinstance(fr, MapFrame):
            m.apply(fr)
            dropped_at_map = _dropped(dec)
    if m.frames > 0 and _dropped(dec) != dropped_at_map:
        m.note_loss()  # a frame dropped after the last map frame may have been one
    if m.frames == 0:
        raise BsfError("no map frame in the stream (bsf extract --map writes one)")
    return m


# ---- extraction ----------------------------------------------------------------------


def _finite(name: str, v: Any) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a number, got {type(v).__name__}") from None
    if not math.isfinite(f):
        raise BsfError(f"{name} must be finite, got {f}")
    return f


# struct formats of float32 and float64 items, with or without a byte-order mark
_FLOAT_FORMATS = {p + c for p in ("", "@", "=", "<", ">", "!") for c in "fd"}


def _ranges_array(ranges: Any) -> np.ndarray:
    if not isinstance(ranges, np.ndarray):
        # A raw buffer (bytes, a memoryview of packed floats) would be read as
        # one number per byte: only buffers that say they hold floats are readings.
        try:
            view = memoryview(ranges)
        except TypeError:
            view = None
        if view is not None and view.format not in _FLOAT_FORMATS:
            raise TypeError(
                f"ranges as a buffer must hold float32 or float64 items (struct format 'f' or 'd'), "
                f"got format {view.format!r}: use np.frombuffer(data, dtype=np.float32) for packed floats"
            )
    arr = np.asarray(ranges)
    if arr.dtype.kind in "iub":
        # Integer readings are usually a driver's millimetres: read as metres,
        # every one would be out of range and the scan silently empty.
        raise TypeError(
            f"ranges must be floating-point metres, got an integer array (dtype {arr.dtype}); "
            "for millimetres pass ranges / 1000.0, for whole metres ranges.astype(float)"
        )
    if arr.dtype.kind != "f":
        raise TypeError(f"ranges must be real numbers (a float array), got dtype {arr.dtype}")
    if arr.ndim != 1:
        raise BsfError(f"ranges must be one-dimensional, got shape {arr.shape}")
    if arr.shape[0] > caps["BSF_MAX_POINTS"]:
        raise BsfError(
            f"{arr.shape[0]} beams is more than this build's BSF_MAX_POINTS "
            f"({caps['BSF_MAX_POINTS']}); rebuild with BSF_PY_MAX_POINTS=... pip install ./tools/python"
        )
    with np.errstate(over="ignore", invalid="ignore"):
        return np.ascontiguousarray(arr, dtype=np.float32)


class Extractor:
    """A reusable extractor (one C ``bsf_extractor_t``) for one method and
    parameter set; cheaper than :func:`extract` for many scans.

    ``timing=False`` leaves the extraction time at 0, so encoded frames are
    byte-reproducible. Parameters: see :func:`default_params`.
    """

    def __init__(self, method: str = "lc-sved-pdm", *, timing: bool = True, **params: Union[int, float]):
        self.method = method
        self._ex = _core.Extractor(method, params, bool(timing))

    @property
    def params(self) -> Dict[str, Union[int, float]]:
        """The effective parameters (defaults and overrides)."""
        return _readable_params(self._ex.params)

    def extract(
        self,
        ranges: Any,
        angle_min: float,
        angle_increment: float,
        range_min: float,
        range_max: float,
        *,
        seq: int = 0,
        timestamp_ms: int = 0,
        pose: Optional[Pose] = None,
    ) -> Frame:
        """Extract one scan; see :func:`extract`."""
        arr = _ranges_array(ranges)
        amin = _finite("angle_min", angle_min)
        ainc = _finite("angle_increment", angle_increment)
        rmin = _finite("range_min", range_min)
        rmax = _finite("range_max", range_max)
        if ainc == 0.0:
            raise BsfError("angle_increment must be non-zero")
        if rmin < 0.0 or not rmax > rmin:
            raise BsfError(f"need 0 <= range_min < range_max, got {rmin} and {rmax}")
        if pose is not None:
            pose = tuple(_finite("pose", v) for v in pose)  # type: ignore[assignment]
            if len(pose) != 3:  # type: ignore[arg-type]
                raise BsfError("pose must be (x, y, theta)")
        res = self._ex.extract(arr, amin, ainc, rmin, rmax)
        feats, stats = _features_from(res, arr.shape[0])
        return Frame(
            seq=int(seq),
            timestamp_ms=int(timestamp_ms),
            pose=pose,
            features=feats,
            stats=stats,
            time_us=(stats.time_ns + 500) // 1000,
        )


_cache = threading.local()


def extract(
    ranges: Any,
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    method: str = "lc-sved-pdm",
    *,
    timing: bool = True,
    seq: int = 0,
    timestamp_ms: int = 0,
    pose: Optional[Pose] = None,
    **params: Union[int, float],
) -> Frame:
    """Extract the B-spline features of one scan.

    Args:
        ranges: 1-D float array of readings in metres (used as float32;
            an integer array, such as a driver's millimetres, is a TypeError). Beam i points at ``angle_min + i * angle_increment``.
            A reading is valid when finite and ``range_min <= r < range_max``;
            invalid ones keep their index but are never points.
        angle_min, angle_increment: radians, counter-clockwise.
        range_min, range_max: metres; set range_max below no-return codes.
        method: "lc-sved-pdm" (default: LC line corners, the library's default),
            "falko-sved-pdm" (the paper's, FALKOLib keypoints), "bid-sved-pdm" or "rpos-lsba".
        timing: measure the extraction time (False: 0, reproducible bytes).
        seq, timestamp_ms, pose: carried into the frame for :func:`encode`.
        **params: parameter overrides, see :func:`default_params`.

    Returns:
        A :class:`Frame` whose features hold numpy control points, vertex
        flags, beam runs and E_curve, and whose ``stats`` are the scan's.

    Raises:
        TypeError: ranges not floating-point numbers, unknown parameter name.
        BsfError (a ValueError): bad shape or geometry, more beams than
            :data:`caps`, a parameter out of range.
    """
    key = (method, bool(timing), tuple(sorted(params.items())))
    ex = getattr(_cache, "extractors", {}).get(key)
    if ex is None:
        ex = Extractor(method, timing=timing, **params)
        _cache.extractors = {key: ex}
    return ex.extract(
        ranges, angle_min, angle_increment, range_min, range_max, seq=seq, timestamp_ms=timestamp_ms, pose=pose
    )


# ---- wire format ------------------------------------------------------------------------


def encode(
    frame: Union[Frame, Metadata],
    quant_step: Optional[float] = None,
    *,
    no_time: bool = False,
    seq: Optional[int] = None,
    timestamp_ms: Optional[int] = None,
) -> bytes:
    """One frame on the wire (docs/FORMAT.md): COBS-framed, CRC-checked, 0x00-terminated.

    ``quant_step`` defaults to the frame's own (a decoded frame) or
    :data:`QUANT_STEP_DEFAULT`. ``no_time`` sends 0 as extraction time
    (reproducible bytes); ``seq`` and ``timestamp_ms`` override the frame's.
    Raises OverflowError when seq is outside 0..2**32-1 or timestamp_ms
    outside 0..2**64-1, TypeError when either is not an integer.
    A :class:`Metadata` is encoded as a metadata frame (format version 2).
    """
    if isinstance(frame, Metadata):
        if not HAS_METADATA:
            raise BsfError("this build's stream format has no metadata frame")
        return _core.encode_metadata(frame._to_dict())
    step = quant_step if quant_step is not None else (frame.quant_step or QUANT_STEP_DEFAULT)
    step = _finite("quant_step", step)
    pose = frame.pose
    if pose is not None:
        if len(pose) != 3 or not all(isinstance(v, (int, float, np.floating)) and math.isfinite(v) for v in pose):
            raise BsfError(f"pose must be three finite numbers (x, y, theta), got {pose!r}")
    feats = []
    ctrl = []
    vert = []
    c0 = 0
    for f in frame.features:
        c = np.ascontiguousarray(f.ctrl, dtype=np.float32).reshape(-1, 2)
        v = np.asarray(f.vertex, dtype=bool).reshape(-1)
        if c.shape[0] != v.shape[0]:
            raise BsfError("a feature's control points and vertex flags differ in length")
        kind = _KINDS.index(f.kind) if f.kind in _KINDS else -1
        if kind < 0:
            raise BsfError(f"unknown feature kind {f.kind!r}")
        feats.append((f.first_beam, f.last_beam, f.n_points, kind, float(f.e_curve), c0, c.shape[0]))
        ctrl.append(c)
        vert.append(v.astype(np.uint8))
        c0 += c.shape[0]
    ctrl_b = np.ascontiguousarray(np.concatenate(ctrl) if ctrl else np.zeros((0, 2), np.float32))
    vert_b = np.ascontiguousarray(np.concatenate(vert) if vert else np.zeros(0, np.uint8))
    stats = frame.stats._to_dict()
    stats["time_ns"] = 0 if no_time else (
        frame.stats.time_ns if frame.version == 0 else int(frame.time_us) * 1000
    )
    return _core.encode(
        # integers only (a float would be truncated); the range is checked in C
        operator.index(frame.seq if seq is None else seq),
        operator.index(frame.timestamp_ms if timestamp_ms is None else timestamp_ms),
        pose,
        step,
        (feats, ctrl_b, vert_b, stats),
        frame.geometry,
    )


class Decoder:
    """Incremental stream decoder: feed bytes in any chunks, get whole frames.

    Damaged frames are dropped and counted in :attr:`counters` (the stream
    resynchronises at the next 0x00), never half-used.
    """

    def __init__(self) -> None:
        self._dec = _core.Decoder()
        self.metadata: Optional[Metadata] = None  #: the last metadata frame delivered

    def _convert(self, items: list) -> List[Union[Frame, Metadata]]:
        out: List[Union[Frame, Metadata]] = []
        for t, n in items:
            fr = _frame_from_tuple(t, n, self.metadata)
            if isinstance(fr, Metadata):
                self.metadata = fr
            if fr is not None:
                out.append(fr)
        return out

    def feed(self, data: Union[bytes, bytearray, memoryview]) -> List[Union[Frame, Metadata]]:
        """Decode ``data``; returns the frames (and metadata frames) completed by it."""
        return self._convert(self._dec.feed(data))

    def finish(self) -> List[Union[Frame, Metadata]]:
        """End of stream: a last frame that lacks only its 0x00 is still delivered."""
        return self._convert(self._dec.finish())

    @property
    def counters(self) -> Dict[str, int]:
        """frames_ok, bad_crc, malformed, unsupported_version, unknown_type, oversize, bytes_skipped."""
        return dict(self._dec.counters)


def decode(data: Union[bytes, bytearray, memoryview]) -> List[Union[Frame, Metadata]]:
    """All frames of a complete stream held in memory, metadata frames included
    (``[f for f in decode(b) if isinstance(f, bsf.Frame)]`` keeps the scans).

    Raises BsfError when non-empty data holds no valid frame (garbage or the
    wrong file); damaged frames among good ones are dropped (see :class:`Decoder`).
    """
    dec = Decoder()
    frames = dec.feed(data) + dec.finish()
    if not frames and len(memoryview(data)) > 0:
        raise BsfError(f"no valid bsf frame in {len(memoryview(data))} bytes: {dec.counters}")
    return frames


Source = Union[str, "os.PathLike[str]", IO[bytes], Any]


def _open_source(source: Source, baudrate: int) -> Tuple[Any, bool, str]:
    """(object with read, close-when-done, name)."""
    if hasattr(source, "read"):
        return source, False, getattr(source, "name", "<stream>")
    path = os.fspath(source)
    if path == "-":
        return sys.stdin.buffer, False, "<stdin>"
    is_url = "://" in path
    is_tty = False
    if not is_url:
        try:
            st = os.stat(path)
        except OSError as e:
            raise OSError(e.errno, f"cannot open {path}: {e.strerror}") from None
        if stat.S_ISDIR(st.st_mode):
            raise IsADirectoryError(f"{path} is a directory, not a bsf stream")
        if stat.S_ISCHR(st.st_mode):
            fd = os.open(path, os.O_RDONLY | os.O_NOCTTY)
            try:
                is_tty = os.isatty(fd)
            finally:
                os.close(fd)
    if is_url or is_tty:
        try:
            import serial  # type: ignore[import-not-found]
        except ImportError:
            raise ImportError(
                f"{path} is a serial port: reading it needs pyserial (pip install './tools/python[serial]')"
            ) from None
        return serial.serial_for_url(path, baudrate=baudrate, timeout=0.1), True, path
    return open(path, "rb", buffering=0), True, path


def _chunks(f: Any, size: int) -> Iterator[bytes]:
    """Bytes as soon as they arrive: one read per chunk, never waiting to fill it."""
    if hasattr(f, "in_waiting"):  # pyserial: read what is there, or wait (timeout) for 1 byte
        while True:
            b = f.read(max(1, min(size, f.in_waiting)))
            if b:
                yield b
            elif not getattr(f, "is_open", True):
                return
        return
    reader = getattr(f, "read1", None) or f.read
    while True:
        b = reader(size)
        if not b:
            return
        if isinstance(b, str):
            raise TypeError("read() needs a binary stream (open the file with 'rb')")
        yield b


def read(source: Source, *, baudrate: int = 115200, chunk_size: int = 65536) -> Iterator[Union[Frame, Metadata]]:
    """Iterate over the frames of a stream as they arrive.

    ``source`` is a path (a file, a named pipe, a tty device), "-" for
    standard input, a pyserial URL such as "socket://host:port" or
    "rfc2217://...", or an open binary file object (a pipe, a socket's
    makefile('rb'), a ``serial.Serial``). Serial ports need the ``serial``
    extra (pyserial); ``baudrate`` is used when this function opens one.

    Frames are yielded as soon as their delimiter has been read (no block
    buffering), metadata frames (:class:`Metadata`, format version 2) in
    stream order among them; each Frame's ``metadata`` is the one in force. Damaged frames are skipped. Raises BsfError at the end when
    the source held bytes but no valid frame.
    """
    return _read(source, Decoder(), baudrate, chunk_size)


def _dropped(dec: "Decoder") -> int:
    c = dec.counters
    return c["bad_crc"] + c["malformed"] + c["unsupported_version"] + c["oversize"]


def _read(
    source: Source, dec: "Decoder", baudrate: int, chunk_size: int, by_frame: bool = False
) -> Iterator[Union[Frame, Metadata]]:
    """read() with a given decoder; by_frame feeds it one delimited piece at a
    time, so that its counters at each frame yielded are those of the stream
    up to that frame."""
    f, close, name = _open_source(source, baudrate)
    total = 0
    delivered = 0
    try:
        for chunk in _chunks(f, chunk_size):
            total += len(chunk)
            pieces = [chunk]
            if by_frame:
                pieces, at = [], 0
                while at < len(chunk):
                    end = chunk.find(b"\x00", at)
                    end = len(chunk) if end < 0 else end + 1
                    pieces.append(chunk[at:end])
                    at = end
            for piece in pieces:
                for fr in dec.feed(piece):
                    delivered += 1
                    yield fr
        for fr in dec.finish():
            delivered += 1
            yield fr
    finally:
        if close:
            f.close()
    if delivered == 0 and total > 0:
        raise BsfError(f"{name}: no valid bsf frame in {total} bytes: {dec.counters}")


# ---- CARMEN logs (the C tool's own reader) -------------------------------------------------


@dataclass(frozen=True, eq=False)
class CarmenScan:
    """One laser scan of a CARMEN log, read by the C tool's reader (tools/carmen.c)."""

    ranges: np.ndarray  #: float32, metres, as written
    angle_min: float
    angle_increment: float
    max_range: float  #: declared maximum range
    range_max: float  #: the range_max ``bsf extract`` uses (below the no-return codes)
    laser_pose: Pose
    robot_pose: Pose
    timestamp: float  #: seconds
    line: int  #: 1-based line in the log


def read_carmen(path: Union[str, "os.PathLike[str]"]) -> Iterator[CarmenScan]:
    """Laser scans (FLASER, ROBOTLASER1) of a CARMEN log, plain or gzip.

    Malformed lines are reported on stderr as FILE:LINE and skipped, as by
    ``bsf extract``. A line longer than 1 MiB (no CARMEN message is, but a
    gzip bomb is) is reported the same way and dropped in bounded memory.

    Raises:
        OSError: the log cannot be opened, or its data is cut or corrupt.
        BsfError: once the log is read to its end, when it held a line longer
            than 1 MiB, or no laser scan at all (``bsf extract`` exits 1 then too).
    """
    name = os.fspath(path)
    rd = _core.CarmenReader(name)
    scans = 0
    try:
        for d in rd:
            scans += 1
            yield CarmenScan(
                ranges=np.frombuffer(d["ranges"], dtype=np.float32).copy(),
                angle_min=d["angle_min"],
                angle_increment=d["angle_increment"],
                max_range=d["max_range"],
                range_max=d["valid_range_max"],
                laser_pose=tuple(d["laser_pose"]),  # type: ignore[arg-type]
                robot_pose=tuple(d["robot_pose"]),  # type: ignore[arg-type]
                timestamp=d["timestamp"],
                line=d["line"],
            )
        overlong, malformed = rd.overlong, rd.malformed
    finally:
        rd.close()
    if overlong:
        raise BsfError(f"{name}: {overlong} lines longer than 1048576 bytes (reported above): not a CARMEN log as written")
    if scans == 0:
        raise BsfError(
            f"{name}: no laser line (FLASER or ROBOTLASER1) in the log" + (" that could be read" if malformed else "")
        )


def _round_ms(seconds: float) -> int:
    """llround(seconds * 1000) for seconds >= 0, as the C tool computes it."""
    x = seconds * 1000.0
    i = math.floor(x)
    return int(i) + (1 if x - i >= 0.5 else 0)


#: Largest log time accepted, seconds since 1970, as ``bsf extract`` has it: a
#: larger one is a corrupt field, and its microseconds would not fit the stream.
_LOG_TIME_MAX_S = 1e11


def _log_frames(
    path: Union[str, "os.PathLike[str]"],
    method: str,
    first: int,
    count: Optional[int],
    range_max: Optional[float],
    timing: bool,
    errors: Optional[List[str]],
    params: Dict[str, Union[int, float]],
) -> Iterator[Tuple[CarmenScan, float, Frame]]:
    ex = Extractor(method, timing=timing, **params)
    t0: Optional[float] = None
    done = 0
    for index, s in enumerate(read_carmen(path)):
        if index < first:
            continue
        if count is not None and done >= count:
            break
        if not (math.isfinite(s.timestamp) and 0.0 <= s.timestamp <= _LOG_TIME_MAX_S):
            msg = (
                f"{os.fspath(path)}:{s.line}: scan {index} skipped: its time {s.timestamp:g} s is not a time "
                f"bsf can carry (finite, 0 .. {_LOG_TIME_MAX_S:g} s)"
            )
            if errors is None:
                raise BsfError(msg)
            errors.append(msg)
            continue
        rmax = float(np.float32(range_max)) if range_max else s.range_max
        try:
            fr = ex.extract(s.ranges, s.angle_min, s.angle_increment, 0.0, rmax)
        except BsfError as e:
            if errors is None:
                raise
            errors.append(f"{os.fspath(path)}:{s.line}: scan {index} skipped: {e}")
            continue
        if t0 is None:
            t0 = s.timestamp
        ts = _round_ms(s.timestamp - t0) if s.timestamp > t0 else 0
        pose = (s.laser_pose[0], s.laser_pose[1], math.remainder(s.laser_pose[2], 2.0 * math.pi))
        done += 1
        yield s, rmax, replace(fr, seq=index, timestamp_ms=ts, pose=pose)


def extract_log(
    path: Union[str, "os.PathLike[str]"],
    method: str = "lc-sved-pdm",
    *,
    first: int = 0,
    count: Optional[int] = None,
    range_max: Optional[float] = None,
    timing: bool = True,
    errors: Optional[List[str]] = None,
    **params: Union[int, float],
) -> Iterator[Frame]:
    """The scan frames ``bsf extract LOG`` writes, extracted here: sequence
    number = scan index, time in ms since the first extracted scan, the laser
    pose. (``python -m bsf extract LOG`` also writes the metadata frames.)

    A scan the library refuses, or whose time is not finite, negative or
    beyond 1e11 s, is skipped (its message is appended to ``errors`` when
    given, else raised), as by ``bsf extract``.
    """
    for _, _, fr in _log_frames(path, method, first, count, range_max, timing, errors, params):
        yield fr


class StreamWriter:
    """Writes frames to a binary stream as ``bsf extract`` does.

    With format version 2 (:data:`HAS_METADATA`): a metadata frame first (this
    build's caps, the method, target RMS, step, the scan geometry, the time
    origin, the source name), again when the range limits change, when time
    goes back before the origin, and every ``meta_every`` frames; a scan whose
    beams differ from the metadata carries its own geometry; frame times are
    ms since the origin. With version 1: frames only, times in ms since
    ``v1_time_origin_us`` (0: Unix time; None: the frame's own timestamp_ms).
    """

    def __init__(
        self,
        out: IO[bytes],
        method: str = "lc-sved-pdm",
        params: Optional[Dict[str, Union[int, float]]] = None,
        quant_step: float = QUANT_STEP_DEFAULT,
        source: Optional[str] = None,
        meta_every: int = 64,
        v1_time_origin_us: Optional[int] = None,
    ):
        self.out = out
        self._first_us: Optional[int] = v1_time_origin_us
        self.quant_step = quant_step
        self.meta_every = int(meta_every)
        self.frames = self.metadata_frames = self.bytes = 0
        self._since = 0
        self._meta: Optional[Metadata] = None
        full = dict(_core.default_params(method))
        full.update(params or {})
        self._method_id = METHODS.index(method)
        self._target = float(np.float32(full["pdm_target_rms"])) if method != "rpos-lsba" else 0.0
        if source is not None:
            raw = source.encode("utf-8")[:64]
            source = raw.decode("utf-8", "ignore") or None
        self._source = source

    def _emit(self, data: bytes) -> None:
        self.out.write(data)
        self.bytes += len(data)

    def write(
        self,
        frame: Frame,
        time_us: int,
        n_beams: int,
        angle_min: float,
        angle_increment: float,
        range_min: float,
        range_max: float,
        no_time: bool = False,
    ) -> None:
        """Write one scan's frame; ``time_us`` is its absolute time (Unix µs)."""
        f32 = lambda v: float(np.float32(v))  # noqa: E731
        if not HAS_METADATA:
            # the frame's own time, or ms since the given origin
            ts = frame.timestamp_ms if self._first_us is None else max(0, (time_us - self._first_us + 500) // 1000)
            self._emit(encode(frame, self.quant_step, no_time=no_time, timestamp_ms=ts))
            self.frames += 1
            return
        m = self._meta
        ranges = (f32(range_min), f32(range_max))
        if m is None or (m.range_min, m.range_max) != ranges or time_us < (m.time_origin_us or 0) or self._since >= self.meta_every:
            origin = time_us if m is None or time_us < (m.time_origin_us or 0) else m.time_origin_us
            d = dict(_core.default_metadata())
            d.update(
                method_id=self._method_id,
                target_rms=self._target,
                quant_step=f32(self.quant_step),
                n_beams=int(n_beams),
                angle_min=f32(angle_min),
                angle_increment=f32(angle_increment),
                range_min=ranges[0],
                range_max=ranges[1],
                time_origin_us=origin,
                source=self._source,
            )
            d["lib_version"] = tuple(d["lib_version"])
            m = self._meta = Metadata(**d)
            self._emit(encode(m))
            self.metadata_frames += 1
            self._since = 0
        same = m.n_beams == n_beams and m.angle_min == f32(angle_min) and m.angle_increment == f32(angle_increment)
        geometry = None if same else (f32(angle_min), f32(angle_increment))
        ts = (time_us - (m.time_origin_us or 0) + 500) // 1000
        self._emit(encode(replace(frame, geometry=geometry), self.quant_step, no_time=no_time, timestamp_ms=ts))
        self.frames += 1
        self._since += 1


def _round_us(seconds: float) -> int:
    """llround(seconds * 1e6) for seconds >= 0."""
    x = seconds * 1e6
    i = math.floor(x)
    return int(i) + (1 if x - i >= 0.5 else 0)


# The submodule is imported here, before the function of the same name is
# defined: importing it later (inside the function) would rebind bsf.plot to
# the module and break every call after the first. It needs matplotlib only
# when drawing.
from . import plot as _plot_module  # noqa: E402


def plot(frames: Union[Frame, Iterable[Frame], Map], ax: Any = None, **kwargs: Any) -> Any:
    """Draw frames or a :class:`Map` with matplotlib (the ``plot`` extra); see :func:`bsf.plot.plot`."""
    return _plot_module.plot(frames, ax=ax, **kwargs)
