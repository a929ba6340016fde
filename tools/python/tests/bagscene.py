# SPDX-License-Identifier: MIT
"""A known scene for the bag tests: a room with a box in it, a robot driving a
circle, its laser ray-cast at each scan time, and ROS 1 / ROS 2 bags of it
(LaserScan, /tf, /tf_static, nav_msgs/Odometry) written with rosbags."""
import math

import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin, Writer as Writer2
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from bsf.tf import compose

T0_NS = 1_700_000_000_000_000_000  # t = 0 of the scene: Nov 2023
SCAN = "sensor_msgs/msg/LaserScan"
TF = "tf2_msgs/msg/TFMessage"
ODOM = "nav_msgs/msg/Odometry"

ROOM = (-3.0, -2.0, 4.0, 3.0)  # x0, y0, x1, y1 in the world (map) frame
BOX = (1.8, 1.6, 2.4, 2.2)


def _rect(x0, y0, x1, y1):
    c = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    return [(c[i], c[(i + 1) % 4]) for i in range(4)]


WALLS = np.array(_rect(*ROOM) + _rect(*BOX), dtype=np.float64)  # (8, 2, 2) segments

MOUNT = (0.25, -0.10, 0.30)  # base_link -> laser: ahead, to the right, turned left


def base_in_odom(t):
    """The robot on a circle of 1 m around (0, 0.5), 0.25 rad/s, facing along it."""
    a = 0.25 * t
    return (math.cos(a), 0.5 + math.sin(a), math.remainder(a + math.pi / 2, 2 * math.pi))


def odom_in_map(t):
    """A slowly drifting map -> odom (linear in time: interpolation is exact)."""
    return (0.10 + 0.01 * t, -0.05 + 0.005 * t, 0.05 + 0.002 * t)


def laser_in(frame, t, with_map):
    p = compose(base_in_odom(t), MOUNT)
    return compose(odom_in_map(t), p) if (frame == "map" and with_map) else p


def raycast(pose, n=541, fov=math.radians(270.0), noise=0.005, seed=0):
    """Ranges from a laser at pose (in the walls' frame), beams counter-clockwise."""
    rng = np.random.default_rng(seed)
    amin = -fov / 2
    inc = fov / (n - 1)
    a = pose[2] + amin + inc * np.arange(n)
    d = np.stack([np.cos(a), np.sin(a)], axis=1)
    o = np.array(pose[:2])
    p, q = WALLS[:, 0], WALLS[:, 1]
    e = q - p  # (m, 2)
    w = p - o  # (m, 2)
    den = d[:, None, 0] * e[None, :, 1] - d[:, None, 1] * e[None, :, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (w[None, :, 0] * e[None, :, 1] - w[None, :, 1] * e[None, :, 0]) / den
        u = (w[None, :, 0] * d[:, None, 1] - w[None, :, 1] * d[:, None, 0]) / den
    hit = (np.abs(den) > 1e-12) & (t > 0) & (u >= 0) & (u <= 1)
    r = np.where(hit, t, np.inf).min(axis=1)
    return (r + rng.normal(0, noise, n)).astype(np.float32), float(np.float32(amin)), float(np.float32(inc))


def wall_distance(points):
    """Distance of each world point (k, 2) to the nearest wall segment."""
    pts = np.asarray(points, dtype=np.float64)
    p, q = WALLS[:, 0], WALLS[:, 1]
    e = q - p
    rel = pts[:, None, :] - p[None, :, :]
    u = np.clip(np.sum(rel * e[None], axis=2) / np.sum(e * e, axis=1)[None], 0.0, 1.0)
    near = p[None] + u[..., None] * e[None]
    return np.min(np.linalg.norm(pts[:, None, :] - near, axis=2), axis=1)


def quat(yaw):
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


class Bag:
    """Messages to write: (topic, msgtype, stamp/record ns, builder(store) -> msg)."""

    def __init__(self):
        self.items = []

    def _header(self, store, stamp_ns, frame_id):
        T = store.types
        h = dict(stamp=T["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9), frame_id=frame_id)
        if "seq" in T["std_msgs/msg/Header"].__dataclass_fields__:
            h["seq"] = 0
        return T["std_msgs/msg/Header"](**h)

    def _tfs(self, store, transforms):
        T = store.types
        out = []
        for parent, child, stamp_ns, pose in transforms:
            qx, qy, qz, qw = quat(pose[2]) if len(pose) == 3 else pose[3:]
            out.append(
                T["geometry_msgs/msg/TransformStamped"](
                    header=self._header(store, stamp_ns, parent),
                    child_frame_id=child,
                    transform=T["geometry_msgs/msg/Transform"](
                        translation=T["geometry_msgs/msg/Vector3"](x=pose[0], y=pose[1], z=0.3),
                        rotation=T["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
                    ),
                )
            )
        return T[TF](transforms=out)

    def tf(self, transforms, topic="/tf", record_ns=None):
        """transforms: (parent, child, stamp_ns, (x, y, yaw) or (x, y, yaw, qx, qy, qz, qw))."""
        rec = record_ns if record_ns is not None else max(t[2] for t in transforms)
        self.items.append((topic, TF, rec, lambda s, tr=list(transforms): self._tfs(s, tr)))

    def odometry(self, stamp_ns, frame, child, pose, topic="/odom"):
        def build(store):
            T = store.types
            cov = np.zeros(36, dtype=np.float64)
            qx, qy, qz, qw = quat(pose[2])
            return T[ODOM](
                header=self._header(store, stamp_ns, frame),
                child_frame_id=child,
                pose=T["geometry_msgs/msg/PoseWithCovariance"](
                    pose=T["geometry_msgs/msg/Pose"](
                        position=T["geometry_msgs/msg/Point"](x=pose[0], y=pose[1], z=0.0),
                        orientation=T["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
                    ),
                    covariance=cov,
                ),
                twist=T["geometry_msgs/msg/TwistWithCovariance"](
                    twist=T["geometry_msgs/msg/Twist"](
                        linear=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
                        angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
                    ),
                    covariance=cov,
                ),
            )

        self.items.append((topic, ODOM, stamp_ns, build))

    def scan(self, stamp_ns, frame_id, ranges, amin, inc, topic="/scan", rmax=30.0):
        def build(store):
            T = store.types
            return T[SCAN](
                header=self._header(store, stamp_ns, frame_id),
                angle_min=amin,
                angle_max=amin + inc * (len(ranges) - 1),
                angle_increment=inc,
                time_increment=0.0,
                scan_time=0.1,
                range_min=0.05,
                range_max=rmax,
                ranges=np.asarray(ranges, dtype=np.float32),
                intensities=np.zeros(0, dtype=np.float32),
            )

        self.items.append((topic, SCAN, stamp_ns, build))

    def write(self, path, kind):
        """kind: bag (ROS 1), db3 or mcap (ROS 2 bag directory)."""
        items = sorted(self.items, key=lambda it: it[2])
        if kind == "bag":
            store = get_typestore(Stores.ROS1_NOETIC)
            if TF not in store.types:  # tf2_msgs is not among rosbags' Noetic types
                store.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", TF))
            with Writer1(path) as w:
                conns = {}
                for topic, mt, rec, build in items:
                    if topic not in conns:
                        conns[topic] = w.add_connection(topic, mt, typestore=store)
                    w.write(conns[topic], rec, store.serialize_ros1(build(store), mt))
            return path
        store = get_typestore(Stores.ROS2_HUMBLE)
        plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
        with Writer2(path, version=8, storage_plugin=plugin) as w:
            conns = {}
            for topic, mt, rec, build in items:
                if topic not in conns:
                    conns[topic] = w.add_connection(topic, mt, typestore=store)
                w.write(conns[topic], rec, store.serialize_cdr(build(store), mt))
        return path


def scan_times(n=30, dt=0.2, start=0.113):
    return [start + dt * k for k in range(n)]


def robot_bag(scan_t, *, with_map=True, odometry=False, tf_span=(-0.5, 7.0), tf_rate=50.0, laser="laser", noise_seed=0):
    """A Bag of the scene: scans at scan_t (s), ray-cast from the true laser pose
    in the map; /tf odom -> base_link (or /odom Odometry), map -> odom at 5 Hz
    when with_map, /tf_static base_link -> laser."""
    b = Bag()
    t = tf_span[0]
    k = 0
    while t <= tf_span[1] + 1e-9:
        ns = T0_NS + round(t * 1e9)
        if odometry:
            b.odometry(ns, "odom", "base_link", base_in_odom(t))
        else:
            b.tf([("odom", "base_link", ns, base_in_odom(t))])
        if with_map and k % round(tf_rate / 5) == 0:
            b.tf([("map", "odom", ns, odom_in_map(t))])
        k += 1
        t = tf_span[0] + k / tf_rate
    b.tf([("base_link", laser, T0_NS, MOUNT)], topic="/tf_static", record_ns=T0_NS + round(tf_span[0] * 1e9))
    for i, ts in enumerate(scan_t):
        truth = laser_in("map", ts, with_map)
        ranges, amin, inc = raycast(truth, seed=noise_seed + i)
        b.scan(T0_NS + round(ts * 1e9), laser, ranges, amin, inc)
    return b
