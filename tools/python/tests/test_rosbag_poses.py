# SPDX-License-Identifier: MIT
"""python -m bsf extract BAG --topic /scan --pose-from /tf|/odom: each frame
carries its laser's pose in the fixed frame at the scan's stamp (ROS 1 and
ROS 2 bags of a known scene with a moving robot), the features land on the
scene's walls, scans outside the pose data are reported and skipped, and
hostile transform data gives a message, not a hang or a traceback."""
import math
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("rosbags", reason="rosbags (the 'rosbag' extra) is not installed")

import bsf  # noqa: E402
from bagscene import MOUNT, T0_NS, Bag, base_in_odom, laser_in, raycast, robot_bag, scan_times, wall_distance  # noqa: E402
from bsf.rosbag import BagError, load_poses, read_scans  # noqa: E402
from bsf.tf import MAX_CHAIN, PoseError, TransformTree, compose, inverse  # noqa: E402
from conftest import scan_frames  # noqa: E402

# the wire carries the pose to 1 mm and 2*pi/65536 rad
POS_TOL = 1.5e-3
YAW_TOL = 2e-4


def run_py(*args):
    return subprocess.run([sys.executable, "-m", "bsf", *map(str, args)], capture_output=True, text=True, timeout=300)


def _stamp_s(frame):
    return frame.unix_time_ms / 1000.0 - T0_NS / 1e9


def _bag_path(tmp_path, kind, name="run"):
    return tmp_path / (name + ".bag" if kind == "bag" else name)


def _assert_poses(frames, times, frame_name, with_map):
    assert len(frames) == len(times)
    for f, t in zip(frames, times):
        assert abs(_stamp_s(f) - t) < 1.5e-3
        want = laser_in(frame_name, t, with_map)
        assert f.pose is not None
        assert abs(f.pose[0] - want[0]) < POS_TOL and abs(f.pose[1] - want[1]) < POS_TOL, (t, f.pose, want)
        assert abs(math.remainder(f.pose[2] - want[2], 2 * math.pi)) < YAW_TOL, (t, f.pose, want)


def _assert_on_walls(frames):
    ctrl = np.concatenate([bsf._transform(ft.ctrl, f.pose) for f in frames for ft in f.features])
    verts = np.concatenate([f.vertices(world=True) for f in frames])
    assert len(ctrl) > 5 * len(frames) and len(verts) >= len(frames)
    d = wall_distance(ctrl)
    assert np.percentile(d, 95) < 0.02 and d.max() < 0.05, (np.percentile(d, 95), d.max())
    # corners (vertices) are the room's and the box's corners
    assert wall_distance(verts).max() < 0.05


@pytest.mark.parametrize("kind", ["bag", "db3", "mcap"])
def test_tf_poses_equal_the_true_laser_poses(kind, tmp_path):
    times = scan_times()
    bag = robot_bag(times).write(_bag_path(tmp_path, kind), kind)
    out = tmp_path / "map.bsf"
    r = run_py("extract", bag, "--topic", "/scan", "--pose-from", "/tf", "-o", out)
    assert r.returncode == 0, r.stderr
    assert f"{len(times)} scans of /scan" in r.stderr and "0 without a pose" in r.stderr
    frames = scan_frames(bsf.decode(out.read_bytes()))
    # the default fixed frame is map when the transforms have it
    _assert_poses(frames, times, "map", True)
    _assert_on_walls(frames)
    # --frame odom: the chain odom -> base_link -> laser only
    out2 = tmp_path / "odom.bsf"
    r = run_py("extract", bag, "--topic", "/scan", "--pose-from", "/tf", "--frame", "odom", "-o", out2)
    assert r.returncode == 0, r.stderr
    _assert_poses(scan_frames(bsf.decode(out2.read_bytes())), times, "odom", True)


@pytest.mark.parametrize("kind", ["bag", "mcap"])
def test_odometry_poses_with_the_static_mounting(kind, tmp_path):
    times = scan_times(n=20)
    bag = robot_bag(times, with_map=False, odometry=True, tf_rate=30.0).write(_bag_path(tmp_path, kind), kind)
    out = tmp_path / "odom.bsf"
    r = run_py("extract", bag, "--topic", "/scan", "--pose-from", "/odom", "-o", out)
    assert r.returncode == 0, r.stderr
    frames = scan_frames(bsf.decode(out.read_bytes()))
    _assert_poses(frames, times, "odom", False)
    _assert_on_walls(frames)


def test_read_scans_api(tmp_path):
    times = scan_times(n=6)
    bag = robot_bag(times).write(tmp_path / "api.bag", "bag")
    got = list(read_scans(bag, "/scan", pose_from="/tf", frame="odom"))
    assert [s.frame_id for s in got] == ["laser"] * 6
    for s, t in zip(got, times):
        want = compose(base_in_odom(t), MOUNT)
        assert s.pose_error is None and np.allclose(s.pose[:2], want[:2], atol=1e-5)
        assert abs(math.remainder(s.pose[2] - want[2], 2 * math.pi)) < 1e-6
    assert load_poses(bag, "/tf").fixed_frame == "map"
    with pytest.raises(BagError, match="fixed frame base is not in the pose data"):
        load_poses(bag, "/tf", frame="base")
    with pytest.raises(BagError, match="no topic /odom for the poses"):
        load_poses(bag, "/odom")
    with pytest.raises(BagError, match="--pose-from needs tf2_msgs/TFMessage"):
        load_poses(bag, "/scan")


def test_scans_outside_the_pose_data_are_reported_and_skipped(tmp_path):
    # tf from 1.0 s to 4.0 s with a 1.5 s hole in odom -> base_link from 2.0 to 3.5 s
    times = [0.5, 0.9, 1.2, 1.6, 2.5, 3.0, 3.7, 4.5, 5.0]
    b = Bag()
    for k in range(151):
        t = 1.0 + 0.02 * k
        if not (2.0 < t < 3.5):
            b.tf([("odom", "base_link", T0_NS + round(t * 1e9), base_in_odom(t))])
    b.tf([("base_link", "laser", T0_NS, MOUNT)], topic="/tf_static")
    for i, t in enumerate(times):
        b.scan(T0_NS + round(t * 1e9), "laser", *raycast(laser_in("odom", t, False), seed=i))
    bag = b.write(tmp_path / "holes.bag", "bag")
    out = tmp_path / "o.bsf"
    r = run_py("extract", bag, "--topic", "/scan", "--pose-from", "/tf", "-o", out)
    assert r.returncode == 0, r.stderr  # three scans have poses: written, the rest reported
    frames = scan_frames(bsf.decode(out.read_bytes()))
    _assert_poses(frames, [1.2, 1.6, 3.7], "odom", False)
    assert [f.seq for f in frames] == [2, 3, 6]
    err = r.stderr
    assert "2 scans of /scan skipped, no pose in odom: before the first transform odom -> base_link; stamps (s): 1700000000.500, 1700000000.900" in err
    assert "2 scans of /scan skipped, no pose in odom: after the last transform odom -> base_link" in err
    assert "2 scans of /scan skipped, no pose in odom: in a gap of the transform odom -> base_link longer than 1 s" in err
    assert "6 without a pose skipped" in err
    # a larger limit bridges the gap
    r = run_py("extract", bag, "--topic", "/scan", "--pose-from", "/tf", "--max-pose-gap", "2", "-o", out)
    assert r.returncode == 0 and "4 without a pose skipped" in r.stderr
    # none left: the exit status says so, and nothing is drawn at the origin
    late = Bag()
    late.tf([("odom", "laser", T0_NS + 10**10, (0.0, 0.0, 0.0))])
    late.scan(T0_NS, "laser", *raycast((0.0, 0.0, 0.0)))
    r = run_py("extract", late.write(tmp_path / "late.bag", "bag"), "--topic", "/scan", "--pose-from", "/tf", "-o", out)
    assert r.returncode == 1 and "no scan of /scan has a pose from /tf" in r.stderr and "Traceback" not in r.stderr
    assert scan_frames(bsf.decode(out.read_bytes()) if out.stat().st_size else []) == []


def _hostile(tmp_path, name, transforms, laser="laser", static=()):
    b = Bag()
    for k in range(20):
        ns = T0_NS + k * 50_000_000
        b.tf([(p, c, ns, pose) for p, c, pose in transforms])
    if static:
        b.tf([(p, c, T0_NS, pose) for p, c, pose in static], topic="/tf_static")
    for i in range(3):
        b.scan(T0_NS + 200_000_000 + i * 100_000_000, laser, *raycast((0.0, 0.0, 0.0), seed=i))
    path = b.write(tmp_path / (name + ".bag"), "bag")
    return run_py("extract", path, "--topic", "/scan", "--pose-from", "/tf", "--frame", "odom", "-o", tmp_path / (name + ".bsf"))


def _assert_clean(r, *needles):
    assert r.returncode != 0, r.stderr
    assert "Traceback" not in r.stderr, r.stderr
    for n in needles:
        assert n in r.stderr, r.stderr


def test_hostile_transforms_give_clear_messages(tmp_path):
    z = (0.0, 0.0, 0.0)
    # a loop: odom -> base -> laser -> odom
    _assert_clean(_hostile(tmp_path, "loop", [("odom", "base", z), ("base", "laser", z), ("laser", "odom", z)]), "loop")
    # the scan's frame is not in the transforms
    _assert_clean(_hostile(tmp_path, "missing", [("odom", "base", z)]), "the frame laser is not in the transforms")
    # two trees: odom and laser are not connected
    _assert_clean(_hostile(tmp_path, "apart", [("odom", "base", z), ("world", "laser", z)]), "frames laser and odom are not connected")
    # a chain longer than the limit
    chain = [("odom", "f0", z)] + [(f"f{i}", f"f{i + 1}", (0.01, 0.0, 0.0)) for i in range(MAX_CHAIN + 5)]
    chain.append((f"f{MAX_CHAIN + 5}", "laser", z))
    _assert_clean(_hostile(tmp_path, "long", chain), f"longer than {MAX_CHAIN} transforms")
    # every transform non-finite: nothing usable
    nan = (float("nan"), 0.0, 0.0)
    _assert_clean(_hostile(tmp_path, "nan", [("odom", "laser", nan)]), "holds no usable transform", "non-finite")
    # a zero quaternion is no rotation
    zq = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    _assert_clean(_hostile(tmp_path, "zeroq", [("odom", "laser", zq)]), "no usable transform")
    # a frame with two parents
    _assert_clean(_hostile(tmp_path, "twoparents", [("odom", "laser", z), ("base", "laser", z)]), "more than one parent")


def test_non_finite_samples_are_dropped_and_counted(tmp_path):
    b = Bag()
    for k in range(40):
        t = 0.05 * k
        pose = base_in_odom(t) if k % 7 else (float("inf"), 0.0, 0.0)
        b.tf([("odom", "base_link", T0_NS + round(t * 1e9), pose)])
    b.tf([("base_link", "laser", T0_NS, MOUNT)], topic="/tf_static")
    times = [0.33, 0.71, 1.42]
    for i, t in enumerate(times):
        b.scan(T0_NS + round(t * 1e9), "laser", *raycast(laser_in("odom", t, False), seed=i))
    out = tmp_path / "nf.bsf"
    r = run_py("extract", b.write(tmp_path / "nf.bag", "bag"), "--topic", "/scan", "--pose-from", "/tf", "-o", out)
    assert r.returncode == 0, r.stderr
    assert "6 transforms with non-finite values or bad frame names were ignored" in r.stderr
    _assert_poses(scan_frames(bsf.decode(out.read_bytes())), times, "odom", False)


def test_transform_tree_interpolation_and_limits():
    tr = TransformTree(max_gap_ns=10**9)
    # yaw across the +-pi seam: the short way round
    tr.add("odom", "base", 0, 0.0, 0.0, math.pi - 0.1)
    tr.add("odom", "base", 10**8, 1.0, 2.0, -math.pi + 0.1)
    tr.add("/base", "/laser", 5, 0.5, 0.0, 0.0, static=True)
    x, y, th = tr.lookup("odom", "laser", 5 * 10**7)
    assert abs(abs(th) - math.pi) < 1e-9
    assert abs(x - (0.5 - 0.5)) < 1e-9 and abs(y - 1.0) < 1e-9  # base at (0.5, 1), laser 0.5 m behind it
    # the inverse direction: the odom origin seen from the laser
    back = tr.lookup("laser", "odom", 5 * 10**7)
    assert np.allclose(compose((x, y, th), back), (0.0, 0.0, 0.0), atol=1e-9)
    assert np.allclose(compose(inverse((x, y, th)), (x, y, th)), (0.0, 0.0, 0.0), atol=1e-9)
    with pytest.raises(PoseError, match="before the first transform odom -> base"):
        tr.lookup("odom", "laser", -1)
    with pytest.raises(PoseError, match="after the last transform"):
        tr.lookup("odom", "laser", 10**8 + 1)
    assert not tr.add("a", "a", 0, 0.0, 0.0, 0.0) and not tr.add("a", "b", 0, 0.0, math.nan, 0.0) and tr.rejected == 2


def test_ros1_style_frame_names_and_the_default_fixed_frame(tmp_path):
    # tf1 wrote frame names with a leading '/'; neither map nor odom here
    b = Bag()
    for k in range(30):
        t = 0.05 * k
        b.tf([("/world", "/base_link", T0_NS + round(t * 1e9), base_in_odom(t))])
    b.tf([("/base_link", "/laser", T0_NS, MOUNT)], topic="/tf_static")
    b.scan(T0_NS + 500_000_000, "/laser", *raycast(laser_in("odom", 0.5, False)))
    bag = b.write(tmp_path / "world.bag", "bag")
    r = run_py("extract", bag, "--topic", "/scan", "--pose-from", "/tf", "-o", tmp_path / "w.bsf")
    assert r.returncode == 1 and "neither map nor odom is in the pose data" in r.stderr and "world" in r.stderr
    r = run_py("extract", bag, "--topic", "/scan", "--pose-from", "/tf", "--frame", "world", "-o", tmp_path / "w.bsf")
    assert r.returncode == 0, r.stderr
    _assert_poses(scan_frames(bsf.decode((tmp_path / "w.bsf").read_bytes())), [0.5], "odom", False)
    # pose options on a CARMEN log are refused, not ignored
    log = tmp_path / "x.log"
    log.write_text("")
    r = run_py("extract", log, "--pose-from", "/tf", "-o", tmp_path / "x.bsf")
    assert r.returncode == 2 and "for ROS bags" in r.stderr


def test_tilted_mountings_project_to_the_plane_and_upside_down_is_refused(tmp_path):
    yaw, pitch = MOUNT[2], 0.3
    cz, sz, cp, sp = math.cos(yaw / 2), math.sin(yaw / 2), math.cos(pitch / 2), math.sin(pitch / 2)
    pitched = MOUNT + (-sz * sp, cz * sp, sz * cp, cz * cp)  # yaw, then pitched 17 degrees down: heading is yaw
    upside_down = MOUNT + (cz, sz, 0.0, 0.0)  # yaw, then rolled 180 degrees
    times = [0.4, 0.8]
    for name, mount, ok in (("pitched", pitched, True), ("flipped", upside_down, False)):
        b = Bag()
        for k in range(60):
            t = 0.02 * k
            b.tf([("odom", "base_link", T0_NS + round(t * 1e9), base_in_odom(t))])
        b.tf([("base_link", "laser", T0_NS, mount)], topic="/tf_static")
        for i, t in enumerate(times):
            b.scan(T0_NS + round(t * 1e9), "laser", *raycast(laser_in("odom", t, False), seed=i))
        out = tmp_path / (name + ".bsf")
        r = run_py("extract", b.write(tmp_path / (name + ".bag"), "bag"), "--topic", "/scan", "--pose-from", "/tf", "-o", out)
        if ok:
            assert r.returncode == 0, r.stderr
            _assert_poses(scan_frames(bsf.decode(out.read_bytes())), times, "odom", False)
        else:
            _assert_clean(r, "1 transforms turn their child frame upside down", "the frame laser is not in the transforms")
