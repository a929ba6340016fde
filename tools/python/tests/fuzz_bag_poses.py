# SPDX-License-Identifier: MIT
"""A mutation fuzzer for the pose messages of ROS bags, as `bsf extract --bag`
and :func:`bsf.rosbag.load_poses` read them: serialized tf2_msgs/TFMessage and
nav_msgs/Odometry messages (ROS 2 CDR and ROS 1) are damaged (bit flips, bytes
overwritten, doubles replaced by NaN, infinities and huge values, lengths
changed, cut, grown), decoded with rosbags as a bag reader does, added to a
transform tree with :func:`bsf.rosbag.add_pose_message` and looked up between
random frames at random stamps.

What must hold for every input: decoding either succeeds or raises (a bad
message, counted as load_poses counts it); adding a decoded message takes
only finite transforms (the tree counts what it refuses); a lookup returns a
finite pose with its heading in [-pi, pi] or raises PoseError with a message,
never anything else, never hangs (chains are bounded); memory stays flat
(a fresh tree every ``TREE_LIFE`` messages, the peak RSS checked at the end).

Run it long from the command line (`python fuzz_bag_poses.py --runs 5000000`);
test_fuzz_bag_poses.py runs a short, fixed-seed pass in the test suite.
"""
import argparse
import math
import random
import resource
import struct
import sys
import time
from dataclasses import dataclass

from rosbags.typesys import Stores, get_typestore

from bsf.rosbag import add_pose_message
from bsf.tf import PoseError, TransformTree

TF = "tf2_msgs/msg/TFMessage"
ODOM = "nav_msgs/msg/Odometry"
FRAMES = ["map", "odom", "base_link", "laser", "/odom", "a", "b", ""]
SPECIAL = [math.nan, -math.nan, math.inf, -math.inf, 1e308, -1e308, 5e-324, -0.0, 0.0, 1e17, 2.0**63]
TREE_LIFE = 64  # messages per tree: a long run must not grow one tree forever


@dataclass
class Tally:
    runs: int = 0
    decoded: int = 0  # inputs the message decoder accepted
    undecodable: int = 0  # refused by the decoder: a bad message
    bad_fields: int = 0  # decoded, but a field could not be read as a pose
    added: int = 0  # transforms taken into the tree
    refused: int = 0  # transforms the tree refused (non-finite, names, tilted)
    poses: int = 0  # lookups that gave a pose
    pose_errors: int = 0  # lookups refused with PoseError


def _seeds(ts):
    """Serialized valid messages: a tf chain, a static mount, an odometry."""
    Header = ts.types["std_msgs/msg/Header"]
    Time = ts.types["builtin_interfaces/msg/Time"]
    Vec = ts.types["geometry_msgs/msg/Vector3"]
    Quat = ts.types["geometry_msgs/msg/Quaternion"]
    Tr = ts.types["geometry_msgs/msg/Transform"]
    TrS = ts.types["geometry_msgs/msg/TransformStamped"]
    Pt = ts.types["geometry_msgs/msg/Point"]
    Pose = ts.types["geometry_msgs/msg/Pose"]
    PoseC = ts.types["geometry_msgs/msg/PoseWithCovariance"]
    Twist = ts.types["geometry_msgs/msg/Twist"]
    TwistC = ts.types["geometry_msgs/msg/TwistWithCovariance"]
    Odom = ts.types[ODOM]
    TFM = ts.types[TF]
    import numpy as np

    def ts_(parent, child, sec, x, y, yaw):
        q = Quat(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))
        return TrS(header=Header(stamp=Time(sec=sec, nanosec=500), frame_id=parent), child_frame_id=child,
                   transform=Tr(translation=Vec(x=x, y=y, z=0.0), rotation=q))

    msgs = [
        (TF, TFM(transforms=[ts_("map", "odom", 10, 0.1, -0.2, 0.05), ts_("odom", "base_link", 10, 1.5, 0.5, 1.2)])),
        (TF, TFM(transforms=[ts_("odom", "base_link", 11, 1.6, 0.6, 1.3)])),
        (TF, TFM(transforms=[ts_("base_link", "laser", 0, 0.25, -0.1, 0.3)])),
        (ODOM, Odom(header=Header(stamp=Time(sec=10, nanosec=0), frame_id="odom"), child_frame_id="base_link",
                    pose=PoseC(pose=Pose(position=Pt(x=1.0, y=2.0, z=0.0), orientation=Quat(x=0.0, y=0.0, z=0.2, w=0.98)),
                               covariance=np.zeros(36)),
                    twist=TwistC(twist=Twist(linear=Vec(x=0.0, y=0.0, z=0.0), angular=Vec(x=0.0, y=0.0, z=0.0)),
                                 covariance=np.zeros(36)))),
    ]
    out = []
    for t, m in msgs:
        out.append((t, "cdr", bytes(ts.serialize_cdr(m, t))))
        out.append((t, "ros1", bytes(ts.serialize_ros1(m, t))))
    return out


def _mutate(rng, data):
    b = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        op = rng.randrange(7)
        if op == 0 and b:  # bit flips
            for _ in range(rng.randint(1, 8)):
                i = rng.randrange(len(b))
                b[i] ^= 1 << rng.randrange(8)
        elif op == 1 and len(b) >= 8:  # a double replaced by a hostile value
            i = rng.randrange(len(b) - 7)
            b[i : i + 8] = struct.pack("<d", rng.choice(SPECIAL))
        elif op == 2 and len(b) >= 4:  # a length or count field changed
            i = rng.randrange(len(b) - 3)
            b[i : i + 4] = struct.pack("<I", rng.choice([0, 1, 2, 3, 7, 255, 65536, 2**31 - 1, 2**32 - 1]))
        elif op == 3 and b:  # cut
            del b[rng.randrange(len(b)) :]
        elif op == 4:  # grown
            at = rng.randrange(len(b) + 1)
            b[at:at] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
        elif op == 5 and b:  # random bytes
            for _ in range(rng.randint(1, 4)):
                b[rng.randrange(len(b))] = rng.randrange(256)
        elif op == 6 and len(b) >= 4:  # a frame name's bytes replaced
            name = rng.choice(FRAMES).encode() or b"\x00"
            i = rng.randrange(len(b))
            b[i : i + len(name)] = name
    return bytes(b)


def _check_lookup(tree, target, source, stamp_ns, tally):
    try:
        pose = tree.lookup(target, source, stamp_ns)
    except PoseError as e:
        assert str(e), "a PoseError without a message"
        tally.pose_errors += 1
        return
    assert isinstance(pose, tuple) and len(pose) == 3, pose
    assert all(isinstance(v, float) and math.isfinite(v) for v in pose), pose
    assert -math.pi - 1e-9 <= pose[2] <= math.pi + 1e-9, pose
    tally.poses += 1


def run(runs, seed=1, report_every=0):
    """Fuzz ``runs`` messages; returns the Tally and the peak RSS in KiB."""
    ts = get_typestore(Stores.ROS2_HUMBLE)
    seeds = _seeds(ts)
    rng = random.Random(seed)
    tally = Tally()
    tree = TransformTree()
    frames = list(FRAMES) + ["nowhere"]
    start = time.monotonic()
    for k in range(runs):
        if k % TREE_LIFE == 0:
            tree = TransformTree(max_gap_ns=rng.choice([1, 10**9, 2**62]))
        msgtype, enc, data = rng.choice(seeds)
        raw = _mutate(rng, data) if rng.random() < 0.95 else data
        tally.runs += 1
        try:
            msg = ts.deserialize_cdr(raw, msgtype) if enc == "cdr" else ts.deserialize_ros1(raw, msgtype)
        except (KeyboardInterrupt, SystemExit):
            raise
        except Exception:  # what load_poses counts as a message it could not decode
            tally.undecodable += 1
            msg = None
        if msg is not None:
            tally.decoded += 1
            before = tree.rejected + tree.tilted
            try:
                tally.added += add_pose_message(tree, "tf" if msgtype == TF else "odometry", msg, rng.random() < 0.1)
            except (KeyboardInterrupt, SystemExit):
                raise
            except Exception:  # a field that is not a number or a name: a bad message
                tally.bad_fields += 1
            tally.refused += tree.rejected + tree.tilted - before
        stamp = rng.choice([10 * 10**9 + 500, 10 * 10**9 + rng.randrange(2 * 10**9), rng.randrange(-(2**64), 2**65), 0])
        _check_lookup(tree, rng.choice(frames), rng.choice(frames), stamp, tally)
        if report_every and (k + 1) % report_every == 0:
            rate = (k + 1) / (time.monotonic() - start)
            print(f"{k + 1} runs, {rate:.0f}/s, {tally}", flush=True)
    return tally, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=100_000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--report-every", type=int, default=100_000)
    a = ap.parse_args(argv)
    t0 = time.monotonic()
    tally, rss = run(a.runs, a.seed, a.report_every)
    print(f"done: {tally.runs} executions in {time.monotonic() - t0:.0f} s, peak RSS {rss} KiB; {tally}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
