# SPDX-License-Identifier: MIT
"""extract(): numpy in, features out; bad input is a Python exception."""
import math

import numpy as np
import pytest

import bsf
from conftest import synthetic_scan


def test_features_carry_numpy_geometry_and_consistent_stats():
    ranges, amin, inc = synthetic_scan()
    fr = bsf.extract(ranges, amin, inc, 0.05, 30.0)
    assert fr.stats.n_beams == len(ranges)
    assert fr.stats.n_valid == len(ranges) - 4  # NaN, inf, 0 and the 60 m code are not points
    assert len(fr.features) == fr.stats.n_features >= 2
    assert sum(f.n_points for f in fr.features) == fr.stats.n_in_features
    assert sum(len(f.ctrl) for f in fr.features) == fr.stats.n_ctrl
    assert any(f.kind == "auxiliary" for f in fr.features)  # the room's corners
    for f in fr.features:
        assert f.ctrl.dtype == np.float32 and f.ctrl.shape == (len(f.vertex), 2)
        assert f.vertex.dtype == bool
        assert int(f.vertex.sum()) % 2 == 0  # a vertex is stored twice
        assert (f.kind == "auxiliary") == bool(f.vertex.any())
        assert 0.0 <= f.e_curve < 0.03
        runs = f.beam_runs()
        assert runs == [(f.first_beam, f.last_beam)]
        assert len(f.beams()) == f.last_beam - f.first_beam + 1 >= f.n_points


def test_sample_sensor_and_world_frame():
    ranges, amin, inc = synthetic_scan()
    f = bsf.extract(ranges, amin, inc, 0.05, 30.0).features[0]
    pts = f.sample(50)
    assert pts.shape == (50, 2)
    # clamped: the curve starts and ends on the end control points
    np.testing.assert_allclose(pts[0], f.ctrl[0], atol=1e-6)
    np.testing.assert_allclose(pts[-1], f.ctrl[-1], atol=1e-6)
    # and passes through every vertex
    for v in f.vertices:
        assert np.min(np.hypot(*(f.sample(2001) - v).T)) < 2e-3
    pose = (10.0, -2.0, math.pi / 2)
    w = f.sample(50, pose)
    np.testing.assert_allclose(w[:, 0], 10.0 - pts[:, 1], atol=1e-5)
    np.testing.assert_allclose(w[:, 1], -2.0 + pts[:, 0], atol=1e-5)
    fr = bsf.extract(ranges, amin, inc, 0.05, 30.0, pose=pose)
    np.testing.assert_allclose(fr.sample(50)[0], w, atol=1e-5)


def test_points_on_a_wall_lie_on_the_curve():
    # a straight wall 2 m ahead: every sample is within noise-free precision of x = 2
    a = np.linspace(-1.0, 1.0, 201)
    fr = bsf.extract(2.0 / np.cos(a), -1.0, 0.01, 0.05, 30.0)
    assert [f.kind for f in fr.features] == ["bleak"]
    assert np.max(np.abs(fr.features[0].sample(100)[:, 0] - 2.0)) < 1e-3


def test_4096_beam_full_circle_scan_and_one_beam_more():
    ranges, amin, inc = synthetic_scan(n=4096, fov=2 * np.pi)
    fr = bsf.extract(ranges, amin, inc, 0.05, 30.0)
    assert bsf.caps["BSF_MAX_POINTS"] >= 4096
    assert fr.stats.n_beams == 4096 and fr.stats.n_features >= 1
    assert fr.stats.cut == 0  # the host caps hold a 4096-beam scan
    with pytest.raises(bsf.BsfError, match="BSF_MAX_POINTS"):
        bsf.extract(np.ones(bsf.caps["BSF_MAX_POINTS"] + 1), 0.0, 0.001, 0.05, 30.0)


def test_methods_and_parameters():
    ranges, amin, inc = synthetic_scan()
    for m in bsf.METHODS:
        assert bsf.extract(ranges, amin, inc, 0.05, 30.0, method=m).stats.n_features >= 1
    loose = bsf.extract(ranges, amin, inc, 0.05, 30.0, pdm_target_rms=0.1)
    tight = bsf.extract(ranges, amin, inc, 0.05, 30.0, pdm_target_rms=0.004)
    assert loose.stats.n_ctrl < tight.stats.n_ctrl
    assert bsf.default_params()["pdm_target_rms"] == pytest.approx(0.03)
    assert bsf.default_params()["pdm_bias_window"] == 16
    assert bsf.default_params("falko-sved-pdm")["pdm_target_rms"] == pytest.approx(0.025)
    assert bsf.default_params("falko-sved-pdm")["pdm_bias_window"] == 0
    assert bsf.default_params()["sved_lookback"] == 4 and bsf.default_params()["no_return_min_run"] == 5
    assert bsf.Extractor(sved_min_segment_points=7).params["sved_min_segment_points"] == 7
    assert bsf.default_params()["split_dist"] == pytest.approx(0.25)
    assert bsf.Extractor(split_dist=0.0).params["split_dist"] == 0.0
    assert bsf.default_params()["trim_tails"] == 1
    assert bsf.Extractor(trim_tails=0).params["trim_tails"] == 0


def test_fit_passes_bounds_the_fit_work():
    ranges, amin, inc = synthetic_scan()
    assert bsf.default_params()["fit_passes"] == 0
    assert bsf.default_params()["pdm_max_passes"] == 0
    free = bsf.extract(ranges, amin, inc, 0.05, 30.0, pdm_target_rms=0.004)
    bounded = bsf.extract(ranges, amin, inc, 0.05, 30.0, pdm_target_rms=0.004, fit_passes=1)
    assert free.stats.n_fit_visits > bounded.stats.n_fit_visits > 0
    assert bounded.stats.n_in_features == free.stats.n_in_features
    with pytest.raises((bsf.BsfError, OverflowError, ValueError)):
        bsf.extract(ranges, amin, inc, 0.05, 30.0, fit_passes=256)


def test_fit_bin_length_fits_bin_means_on_dense_scans():
    ranges, amin, inc = synthetic_scan(n=4096, fov=2 * np.pi)
    assert bsf.default_params()["fit_bin_length"] == 0.0
    every = bsf.extract(ranges, amin, inc, 0.05, 30.0)
    binned = bsf.extract(ranges, amin, inc, 0.05, 30.0, fit_bin_length=0.03)
    assert 0 < binned.stats.n_fit_visits < every.stats.n_fit_visits
    assert binned.stats.n_in_features == every.stats.n_in_features
    for bad in (-0.01, 1.5, float("nan")):
        with pytest.raises((bsf.BsfError, ValueError)):
            bsf.extract(ranges, amin, inc, 0.05, 30.0, fit_bin_length=bad)


def test_timing_off_gives_zero_time():
    ranges, amin, inc = synthetic_scan()
    assert bsf.extract(ranges, amin, inc, 0.05, 30.0, timing=False).stats.time_ns == 0


@pytest.mark.parametrize(
    "ranges, exc, match",
    [
        (np.array(["1", "2"]), TypeError, "real numbers"),
        (np.ones(10, dtype=complex), TypeError, "real numbers"),
        (np.array([object()] * 10), TypeError, "real numbers"),
        (np.ones((10, 2)), bsf.BsfError, "one-dimensional"),
    ],
)
def test_bad_ranges(ranges, exc, match):
    with pytest.raises(exc, match=match):
        bsf.extract(ranges, 0.0, 0.01, 0.05, 30.0)


@pytest.mark.parametrize(
    "geometry, match",
    [
        ((math.nan, 0.01, 0.05, 30.0), "angle_min must be finite"),
        ((0.0, math.inf, 0.05, 30.0), "angle_increment must be finite"),
        ((0.0, 0.0, 0.05, 30.0), "non-zero"),
        ((0.0, 0.01, -1.0, 30.0), "range_min"),
        ((0.0, 0.01, 1.0, 1.0), "range_max"),
        ((0.0, 0.01, 0.05, math.nan), "range_max must be finite"),
    ],
)
def test_bad_geometry(geometry, match):
    with pytest.raises(bsf.BsfError, match=match):
        bsf.extract(np.ones(100), *geometry)


def test_bad_method_and_parameters():
    r = np.ones(100)
    with pytest.raises(bsf.BsfError, match="unknown method"):
        bsf.extract(r, 0.0, 0.01, 0.05, 30.0, method="ransac")
    with pytest.raises(TypeError, match="unknown parameter"):
        bsf.extract(r, 0.0, 0.01, 0.05, 30.0, pdm_target=0.1)
    with pytest.raises(bsf.BsfError, match="pdm_target_rms"):
        bsf.extract(r, 0.0, 0.01, 0.05, 30.0, pdm_target_rms=-1.0)
    with pytest.raises(bsf.BsfError, match="pdm_max_ctrl"):
        bsf.extract(r, 0.0, 0.01, 0.05, 30.0, pdm_max_ctrl=1000)
    with pytest.raises(bsf.BsfError, match="finite"):
        bsf.extract(r, 0.0, 0.01, 0.05, 30.0, sved_a=math.nan)
    with pytest.raises(TypeError, match="integer"):
        bsf.extract(r, 0.0, 0.01, 0.05, 30.0, sved_min_segment_points=2.5)
    with pytest.raises(bsf.BsfError):
        bsf.extract(r, 0.0, 0.01, 0.05, 30.0, trim_tails=2)


def test_bsf_error_is_a_value_error_with_status():
    with pytest.raises(ValueError):
        bsf.extract(np.ones(10), 0.0, 0.0, 0.05, 30.0)
    with pytest.raises(bsf.BsfError, match="pose must be three finite numbers"):
        bsf.encode(bsf.Frame(0, 0, (math.nan, 0.0, 0.0), [], bsf.ScanStats()))
    with pytest.raises(bsf.BsfError) as e:
        bsf.encode(bsf.Frame(0, 0, (3e6, 0.0, 0.0), [], bsf.ScanStats()))  # beyond BSF_POSE_XY_MAX
    assert e.value.status == -1 and "BSF_ERR_ARG" in str(e.value)


def test_a_scan_over_a_cap_keeps_what_fits():
    # 1365 runs of 3 beams alternating between 2 m and 6 m: more segments than
    # the host cap under the paper's segmentation rule (the default look-back
    # joins every run at one range into one segment); the library returns
    # BSF_OK_CUT, which is a result, not an error
    r = np.where((np.arange(4096) // 3) % 2 == 0, 2.0, 6.0)
    fr = bsf.extract(r, -np.pi, 2 * np.pi / 4096, 0.05, 30.0, sved_min_segment_points=3,
                     sved_lookback=0)
    assert fr.stats.cut == 2 and fr.stats.n_cut_segments > 0  # BSF_CUT_SEGMENTS
    assert len(fr.features) == bsf.caps["BSF_MAX_SEGMENTS"]
    assert len(bsf.decode(bsf.encode(fr))[0].features) == len(fr.features)
