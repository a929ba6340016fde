# SPDX-License-Identifier: MIT
"""Property-based tests of bsf.tf (hypothesis, no example database): random
transform trees (loops, missing frames, two parents, non-finite and huge
values, stamps at the ends of the integer range, chains deeper than
MAX_CHAIN) never make a lookup hang or raise anything but PoseError; a pose
it returns is finite, its heading within [-pi, pi]; what add() refuses it
counts."""
import math

from hypothesis import given, settings, strategies as st

from bsf.tf import MAX_CHAIN, PoseError, TransformTree

NAMES = ["map", "odom", "base_link", "laser", "/odom", "/laser", "a", "b", "c", ""]

# Values a hostile or broken bag can carry: ordinary, huge, tiny, non-finite.
coord = st.one_of(
    st.floats(min_value=-100.0, max_value=100.0),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([1e308, -1e308, 1.7e308, 1e-310, 0.0, -0.0]),
)
yaw = st.one_of(st.none(), coord)
stamp = st.one_of(
    st.integers(min_value=0, max_value=10_000_000_000),
    st.integers(min_value=-(2**64), max_value=2**65),
    st.sampled_from([0, 2**63 - 1, 2**63, 2**64 - 1, -1, -(2**63)]),
)
quat = st.tuples(coord, coord, coord, coord)
edge = st.tuples(
    st.sampled_from(NAMES), st.sampled_from(NAMES), stamp, coord, coord, yaw, st.booleans(), st.one_of(st.none(), quat)
)


def _check_lookup(tree, target, source, stamp_ns):
    try:
        pose = tree.lookup(target, source, stamp_ns)
    except PoseError as e:
        assert str(e)  # a message the user can read
        return None
    assert isinstance(pose, tuple) and len(pose) == 3
    assert all(isinstance(v, float) and math.isfinite(v) for v in pose), pose
    assert -math.pi - 1e-9 <= pose[2] <= math.pi + 1e-9
    return pose


def _build(edges, max_gap_ns=1_000_000_000):
    tree = TransformTree(max_gap_ns=max_gap_ns)
    added = 0
    for parent, child, t, x, y, w, static, q in edges:
        if q is None:
            ok = tree.add(parent, child, t, x, y, w, static)
        else:
            ok = tree.add_3d(parent, child, t, x, y, q, static)
        assert ok in (True, False)
        added += ok
    assert added + tree.rejected + tree.tilted == len(edges)
    return tree


@settings(max_examples=400, deadline=2000, database=None)
@given(
    edges=st.lists(edge, max_size=30),
    lookups=st.lists(st.tuples(st.sampled_from(NAMES + ["nowhere"]), st.sampled_from(NAMES + ["nowhere"]), stamp), min_size=1, max_size=10),
    max_gap=st.integers(min_value=1, max_value=10**12),
)
def test_random_trees_give_a_finite_pose_or_a_pose_error(edges, lookups, max_gap):
    tree = _build(edges, max_gap)
    for target, source, t in lookups:
        _check_lookup(tree, target, source, t)


@settings(max_examples=100, deadline=5000, database=None)
@given(
    depth=st.integers(min_value=1, max_value=3 * MAX_CHAIN),
    close_loop=st.booleans(),
    x=coord,
    t=stamp,
)
def test_deep_chains_and_loops_end_in_a_pose_or_a_pose_error(depth, close_loop, x, t):
    tree = TransformTree()
    names = [f"f{i}" for i in range(depth + 1)]
    for i in range(depth):
        assert tree.add(names[i], names[i + 1], 0, x, 0.5, 0.1, static=True) == math.isfinite(x)
    if close_loop:
        tree.add(names[-1], names[0], 0, 1.0, 0.0, 0.0, static=True)
    pose = _check_lookup(tree, names[0], names[-1], t)
    if math.isfinite(x) and abs(x) <= 100.0 and not close_loop and depth <= MAX_CHAIN and -(2**63) <= t < 2**63:
        assert pose is not None  # a sane chain within the limit is found
    if math.isfinite(x) and (depth > MAX_CHAIN + 1 or close_loop):
        assert pose is None  # too deep, or a loop: refused


@settings(max_examples=200, deadline=2000, database=None)
@given(
    samples=st.lists(st.tuples(stamp, coord, coord, coord), min_size=1, max_size=12),
    t=stamp,
)
def test_interpolation_between_hostile_samples_stays_finite(samples, t):
    tree = TransformTree(max_gap_ns=2**62)
    for s, x, y, w in samples:
        tree.add("odom", "base_link", s, x, y, w)
    if tree.frames:
        _check_lookup(tree, "odom", "base_link", t)
