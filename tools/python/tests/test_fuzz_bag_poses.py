# SPDX-License-Identifier: MIT
"""A short, fixed-seed pass of the bag pose-message fuzzer (fuzz_bag_poses.py;
run it long from the command line): damaged tf and odometry messages are
refused by the decoder or by the tree, or give finite poses; lookups give a
finite pose or a PoseError, nothing else."""
import pytest

pytest.importorskip("rosbags")

import fuzz_bag_poses  # noqa: E402


def test_damaged_pose_messages_give_finite_poses_or_clear_errors():
    tally, rss_kib = fuzz_bag_poses.run(20_000, seed=7)
    assert tally.runs == 20_000
    # every path was taken: the mutations reach the decoder's refusals, the
    # tree's refusals of hostile values, and lookups both ways
    assert tally.undecodable > 0 and tally.decoded > 0
    assert tally.added > 0 and tally.refused > 0
    assert tally.poses > 0 and tally.pose_errors > 0
    assert rss_kib < 512 * 1024
