# SPDX-License-Identifier: MIT
"""Planar transform trees: where a laser was when it took a scan.

A :class:`TransformTree` holds timed transforms parent -> child (as ROS
``/tf`` carries them) and static ones (``/tf_static``, valid at every time),
each projected to the plane: x, y and the yaw of the rotation. Looking up a
frame in another at a time composes the chain between them through their
common ancestor, interpolating each timed transform at that time (linear in
x and y, the shorter way round in yaw). A 3D transform is projected: its
translation's x and y, the heading of its rotation; one that turns its child
upside down (a mirrored scan) is refused (:meth:`TransformTree.add_3d`).

A lookup never extrapolates: a time before a transform's first sample, after
its last, or between two samples further apart than ``max_gap_ns`` raises
:class:`PoseError`, as do frames that are not connected, a loop, a chain of
more than :data:`MAX_CHAIN` transforms, a frame published with two parents,
and transforms so large that composing them overflows.
"""
from __future__ import annotations

import math
from typing import Dict, List, Optional, Set, Tuple

import numpy as np

Pose = Tuple[float, float, float]

#: Transforms at most in a chain from a frame up to its tree's root; a longer
#: chain is refused (a robot's tree is a handful deep; a bag is untrusted).
MAX_CHAIN = 64

#: Default largest gap between two samples of one timed transform that a
#: lookup interpolates across, ns (1 s: odometry and SLAM publish at 10 Hz or more).
MAX_GAP_NS_DEFAULT = 1_000_000_000

_IDENTITY: Pose = (0.0, 0.0, 0.0)

#: Stamps are held as signed 64-bit nanoseconds; a stamp outside is refused.
_STAMP_MIN, _STAMP_MAX = -(2**63), 2**63 - 1


class PoseError(Exception):
    """No pose at this time. ``reason`` is the message without per-lookup
    numbers, so that many lookups failing alike can be reported once."""

    def __init__(self, reason: str, detail: str = ""):
        super().__init__(reason + (f" ({detail})" if detail else ""))
        self.reason = reason


def compose(a: Pose, b: Pose) -> Pose:
    """The pose b (given in frame A) in the frame that A is given in by a."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], math.remainder(a[2] + b[2], 2.0 * math.pi))


def inverse(a: Pose) -> Pose:
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-c * a[0] - s * a[1], s * a[0] - c * a[1], math.remainder(-a[2], 2.0 * math.pi))


def yaw_of_quaternion(x: float, y: float, z: float, w: float) -> Optional[float]:
    """Heading of a rotation (its x axis projected to the plane), radians; None
    for a quaternion that is not finite or too close to zero to mean a rotation."""
    n = x * x + y * y + z * z + w * w
    if not math.isfinite(n) or n < 1e-12:
        return None
    # scale-free: a quaternion that is not quite unit gives the same heading
    yaw = math.atan2(2.0 * (w * z + x * y), w * w + x * x - y * y - z * z)
    return yaw if math.isfinite(yaw) else None


def is_upright(x: float, y: float, z: float, w: float) -> bool:
    """True when the rotation keeps the child's z axis pointing up (less than
    90 degrees of roll and pitch combined). A laser mounted upside down sees a
    mirrored scan, which a plane pose (x, y, yaw) cannot express."""
    n = x * x + y * y + z * z + w * w
    return math.isfinite(n) and n >= 1e-12 and 1.0 - 2.0 * (x * x + y * y) / n > 1e-9


def strip_frame(name: str) -> str:
    """tf frame names as tf2 uses them: no leading '/' (ROS 1 tf wrote one)."""
    return name.lstrip("/")


class TransformTree:
    """Timed and static planar transforms between named frames."""

    def __init__(self, max_gap_ns: int = MAX_GAP_NS_DEFAULT):
        if not max_gap_ns > 0:
            raise ValueError(f"max_gap_ns must be positive, got {max_gap_ns}")
        self.max_gap_ns = int(max_gap_ns)
        self._samples: Dict[str, List[Tuple[int, float, float, float]]] = {}
        self._static: Dict[str, Pose] = {}
        self._parents: Dict[str, Set[str]] = {}
        self._arrays: Dict[str, Tuple[np.ndarray, np.ndarray]] = {}
        self.rejected = 0  #: transforms not added: non-finite values, a frame its own parent, an empty name
        self.tilted = 0  #: transforms not added: turned upside down (see :func:`is_upright`)

    def add(self, parent: str, child: str, stamp_ns: int, x: float, y: float, yaw: Optional[float], static: bool = False) -> bool:
        """Add parent -> child (the child's origin and heading in the parent).

        Returns False (and counts it in :attr:`rejected`) for values that are
        not finite, a missing yaw, empty names, a frame its own parent or a
        timed transform's stamp outside signed 64-bit nanoseconds.
        A later static transform of the same child replaces an earlier one.
        """
        parent, child = strip_frame(parent), strip_frame(child)
        if (
            not parent
            or not child
            or parent == child
            or yaw is None
            or not all(math.isfinite(v) for v in (x, y, yaw))
            or (not static and not _STAMP_MIN <= int(stamp_ns) <= _STAMP_MAX)
        ):
            self.rejected += 1
            return False
        self._parents.setdefault(child, set()).add(parent)
        if static:
            self._static[child] = (float(x), float(y), math.remainder(float(yaw), 2.0 * math.pi))
        else:
            # the heading reduced to [-pi, pi]: differences of huge headings overflow
            self._samples.setdefault(child, []).append((int(stamp_ns), float(x), float(y), math.remainder(float(yaw), 2.0 * math.pi)))
            self._arrays.pop(child, None)
        return True

    @property
    def frames(self) -> Set[str]:
        """Every frame named as a parent or a child."""
        out = set(self._parents)
        for ps in self._parents.values():
            out |= ps
        return out

    def _parent(self, child: str) -> Optional[str]:
        ps = self._parents.get(child)
        if not ps:
            return None
        if len(ps) > 1:
            raise PoseError(f"frame {child} has more than one parent in the data ({', '.join(sorted(ps))})")
        return next(iter(ps))

    def _up(self, frame: str) -> List[str]:
        """The frame, its parent, ... up to the root."""
        path = [frame]
        seen = {frame}
        while True:
            p = self._parent(path[-1])
            if p is None:
                return path
            if p in seen:
                loop = path[path.index(p) :] + [p]
                raise PoseError("the transforms form a loop: " + " -> ".join(reversed(loop)))
            if len(path) > MAX_CHAIN:
                raise PoseError(f"the chain above {frame} is longer than {MAX_CHAIN} transforms")
            path.append(p)
            seen.add(p)

    def _edge(self, child: str, stamp_ns: int) -> Pose:
        """The transform parent -> child at stamp_ns."""
        if child in self._samples:
            arr = self._arrays.get(child)
            if arr is None:
                data = sorted(self._samples[child], key=lambda s: s[0])
                t = np.array([s[0] for s in data], dtype=np.int64)
                v = np.array([s[1:] for s in data], dtype=np.float64)
                # several samples at one stamp: the last one published wins
                keep = np.append(t[1:] != t[:-1], True)
                arr = self._arrays[child] = (t[keep], v[keep])
            t, v = arr
            parent = next(iter(self._parents[child]))
            name = f"{parent} -> {child}"
            i = int(np.searchsorted(t, stamp_ns, side="left"))
            if i < len(t) and t[i] == stamp_ns:
                return (float(v[i, 0]), float(v[i, 1]), float(v[i, 2]))
            if i == 0:
                raise PoseError(f"before the first transform {name}", f"{_sec(t[0])} s")
            if i == len(t):
                if child in self._static:  # also latched: tf2 would use the static one
                    return self._static[child]
                raise PoseError(f"after the last transform {name}", f"{_sec(t[-1])} s")
            gap = int(t[i]) - int(t[i - 1])  # in Python ints: int64 would wrap
            if gap > self.max_gap_ns:
                raise PoseError(
                    f"in a gap of the transform {name} longer than {self.max_gap_ns / 1e9:g} s",
                    f"{_sec(t[i - 1])} s to {_sec(t[i])} s",
                )
            f = (stamp_ns - int(t[i - 1])) / gap
            a, b = [float(c) for c in v[i - 1]], [float(c) for c in v[i]]
            dyaw = math.remainder(b[2] - a[2], 2.0 * math.pi)
            return (
                a[0] + f * (b[0] - a[0]),
                a[1] + f * (b[1] - a[1]),
                math.remainder(a[2] + f * dyaw, 2.0 * math.pi),
            )
        return self._static[child]

    def add_3d(
        self, parent: str, child: str, stamp_ns: int, x: float, y: float, q: Tuple[float, float, float, float], static: bool = False
    ) -> bool:
        """:meth:`add` for a translation's x, y and a quaternion (x, y, z, w):
        the rotation's heading; refused (counted in :attr:`tilted`) when it
        turns the child upside down."""
        if all(math.isfinite(v) for v in q) and not is_upright(*q) and yaw_of_quaternion(*q) is not None:
            self.tilted += 1
            return False
        return self.add(parent, child, stamp_ns, x, y, yaw_of_quaternion(*q), static)

    def lookup(self, target: str, source: str, stamp_ns: int) -> Pose:
        """The origin and heading of frame ``source`` in frame ``target`` at ``stamp_ns``.

        Raises PoseError when there is none (see the module's description).
        """
        target, source = strip_frame(target), strip_frame(source)
        if not _STAMP_MIN <= int(stamp_ns) <= _STAMP_MAX:
            raise PoseError("a time outside signed 64-bit nanoseconds", f"{stamp_ns} ns")
        known = self.frames
        for name, what in ((source, "frame"), (target, "fixed frame")):
            if name not in known:
                raise PoseError(f"the {what} {name or '(empty)'} is not in the transforms")
        up_s = self._up(source)
        up_t = self._up(target)
        common = next((f for f in up_s if f in set(up_t)), None)
        if common is None:
            raise PoseError(
                f"frames {source} and {target} are not connected ({source} leads up to {up_s[-1]}, {target} to {up_t[-1]})"
            )

        def to_common(path: List[str]) -> Pose:
            pose = _IDENTITY
            for child in path[: path.index(common)]:
                pose = compose(self._edge(child, stamp_ns), pose)
            return pose

        pose = compose(inverse(to_common(up_t)), to_common(up_s))
        # finite transforms can still overflow when composed (1e308 + 1e308)
        if not all(math.isfinite(v) for v in pose):
            raise PoseError(f"the transforms from {target} to {source} give a pose that is not finite")
        return pose


def _sec(ns: int) -> str:
    return f"{int(ns) / 1e9:.3f}"
