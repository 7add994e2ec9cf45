"""Tests of bmc_functions.markers.tracking (cluster calibration and landmark reconstruction) and of
the whole static + dynamic pipeline to knee angles: against scipy-moved clusters, the
ground truth of data/generate_marker_data.py, and, when present, real recordings."""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from bmc_functions import (calibrate_cluster, hip_joint_centre, knee_angles,
                           reconstruct_landmarks, shank_frame, svdt, thigh_frame)

from helpers import SHARED_DATA, load_data_script, needs_shared



GEN = load_data_script("generate_marker_data")
ANGLES = ["right_knee_flexion", "right_knee_adduction", "right_knee_rotation"]


def markers(df, names):
    """(frames, n, 3) array of the named markers of a (marker, coord) DataFrame."""
    return np.stack([df[name][["x", "y", "z"]].to_numpy() for name in names], axis=1)


def pipeline(static, dynamic, thigh, shank, pelvis=("RASI", "LASI", "RPSI", "LPSI"),
             knee=("RLFC", "RMFC"), ankle=("RLMAL", "RMMAL")):
    """Static + dynamic trial -> knee angles (deg) and the cluster fits' RMSE per frame."""
    hip = hip_joint_centre(*np.moveaxis(markers(static, pelvis), 1, 0))
    thigh_landmarks = np.concatenate([hip[:, None], markers(static, knee)], axis=1)
    thigh_local = calibrate_cluster(markers(static, thigh), thigh_landmarks)
    shank_local = calibrate_cluster(markers(static, shank), markers(static, knee + ankle))
    th, th_rmse = reconstruct_landmarks(*thigh_local, markers(dynamic, thigh))
    sh, sh_rmse = reconstruct_landmarks(*shank_local, markers(dynamic, shank))
    R_thigh, _ = thigh_frame(th[:, 0], th[:, 1], th[:, 2])
    R_shank, _ = shank_frame(sh[:, 0], sh[:, 1], sh[:, 2], sh[:, 3])
    return knee_angles(R_thigh, R_shank, degrees=True), th_rmse, sh_rmse


def synthetic(**options):
    trials = GEN.make_trials(**options)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)   # the gaps; tested separately
        angles, th_rmse, sh_rmse = pipeline(trials["static"], trials["walk"],
                                            list(GEN.THIGH_CLUSTER), list(GEN.SHANK_CLUSTER))
    return angles, trials["walk_truth"][ANGLES].to_numpy(), th_rmse, sh_rmse


def random_cluster(rng, n):
    return rng.normal(scale=60.0, size=(n, 3)) + rng.normal(scale=1000.0, size=3)


# --- calibration + reconstruction recover rigidly moved landmarks (scipy as the oracle) ---
@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(3, 6))
def test_landmarks_follow_a_rigid_cluster(seed, n):
    rng = np.random.default_rng(seed)
    cluster, landmarks = random_cluster(rng, n), random_cluster(rng, 4)
    R = Rotation.random(10, random_state=rng).as_matrix()
    L = rng.normal(scale=500.0, size=(10, 3))
    moved = np.einsum("fij,nj->fni", R, cluster) + L[:, None]
    expected = np.einsum("fij,mj->fmi", R, landmarks) + L[:, None]
    found, rmse = reconstruct_landmarks(*calibrate_cluster(cluster, landmarks), moved)
    np.testing.assert_allclose(found, expected, atol=1e-6)
    np.testing.assert_allclose(rmse, 0.0, atol=1e-6)


def test_landmarks_are_each_contiguous_and_their_pose_applied_as_one_product():
    # Each landmark's (frames, 3) positions contiguous (the segment frames read them),
    # with the numbers of R_f p + L_f as one (3 frames, 3) @ (3, m) product plus L, bit
    # for bit (the tracking's results must not change with the layout); NaN frames too.
    rng = np.random.default_rng(7)
    cluster, landmarks = random_cluster(rng, 4), random_cluster(rng, 3)
    c_local, l_local = calibrate_cluster(cluster, landmarks)
    R = Rotation.random(500, random_state=rng).as_matrix()
    moved = np.einsum("fij,nj->fni", R, cluster) + rng.normal(scale=500.0, size=(500, 1, 3))
    moved += rng.normal(scale=2.0, size=moved.shape)           # not rigid: an RMSE
    moved[[3, 40], :2] = np.nan                                # two frames not fitted
    with pytest.warns(RuntimeWarning, match="2 of 500 frames"):
        found, _ = reconstruct_landmarks(c_local, l_local, moved)
        R_fit, L_fit, _ = svdt(c_local, moved, order="row")
    product = (R_fit.reshape(-1, 3) @ l_local.T).reshape(500, 3, 3)
    assert np.array_equal(found, np.swapaxes(product, 1, 2) + L_fit[:, None], equal_nan=True)
    assert all(found[:, k].flags.c_contiguous for k in range(3))
    assert np.isnan(found[[3, 40]]).all() and np.isfinite(np.delete(found, [3, 40], 0)).all()


def test_technical_frame_keeps_distances_and_is_centred():
    rng = np.random.default_rng(0)
    cluster, landmarks = random_cluster(rng, 4), random_cluster(rng, 3)
    c_local, l_local = calibrate_cluster(cluster, landmarks)
    np.testing.assert_allclose(c_local.mean(axis=0), 0.0, atol=1e-9)
    both, both_local = np.vstack([cluster, landmarks]), np.vstack([c_local, l_local])
    d = np.linalg.norm(both[:, None] - both[None], axis=2)
    d_local = np.linalg.norm(both_local[:, None] - both_local[None], axis=2)
    np.testing.assert_allclose(d_local, d, atol=1e-9)


def test_static_trial_is_averaged_over_visible_frames():
    cluster = np.array([[0.0, 0, 0], [100, 0, 0], [0, 80, 0], [50, 50, 40]])
    offsets = np.array([[-1.0, 0, 0], [1.0, 0, 0], [7.0, 7, 7]])[:, None, :]
    static = cluster + offsets          # 3 frames; the third is spoiled and then occluded
    static[2, 1] = np.nan
    c_local, _ = calibrate_cluster(static, cluster[:1])
    # marker 1 is the mean of frames 0 and 1 only; the others average all three
    expected, _ = calibrate_cluster(np.vstack([cluster[:1] + 7 / 3, cluster[1:2],
                                               cluster[2:] + 7 / 3]), cluster[:1])
    np.testing.assert_allclose(c_local, expected, atol=1e-9)


def test_a_four_marker_cluster_survives_one_occlusion_and_three_do_not():
    rng = np.random.default_rng(1)
    cluster, landmarks = random_cluster(rng, 4), random_cluster(rng, 2)
    R = Rotation.random(5, random_state=rng).as_matrix()
    moved = np.einsum("fij,nj->fni", R, cluster)
    moved[2, 3] = np.nan
    found, rmse = reconstruct_landmarks(*calibrate_cluster(cluster, landmarks), moved)
    np.testing.assert_allclose(found, np.einsum("fij,mj->fmi", R, landmarks), atol=1e-6)
    three = moved[:, :3].copy()
    three[2, 0] = np.nan
    with pytest.warns(RuntimeWarning, match="1 of 5 frames have fewer than 3"):
        found3, rmse3 = reconstruct_landmarks(*calibrate_cluster(cluster[:3], landmarks),
                                              three)
    assert np.isnan(found3[2]).all() and np.isnan(rmse3[2])
    assert np.isfinite(found3[[0, 1, 3, 4]]).all()


# --- the pipeline against the generator's ground truth --------------------------------------
def test_pipeline_is_exact_without_artefact_and_noise():
    angles, truth, th_rmse, sh_rmse = synthetic(noise_sd=0.0, sta_scale=0.0, gaps=False)
    np.testing.assert_allclose(angles, truth, atol=1e-8)
    np.testing.assert_allclose(th_rmse, 0.0, atol=1e-9)


def test_noise_only_residual_matches_its_expected_size():
    # With isotropic noise sd s on n markers, the least-squares fit absorbs 6 of the 3n
    # degrees of freedom: E[RMSE^2] = s^2 (3n - 6) / (3n) (s = 0.5 mm; n = 4 and 3).
    _, _, th_rmse, sh_rmse = synthetic(sta_scale=0.0, gaps=False)
    s = GEN.NOISE_SD
    assert np.mean(th_rmse**2) == pytest.approx(s**2 * 6 / 12, rel=0.2)
    assert np.mean(sh_rmse**2) == pytest.approx(s**2 * 3 / 9, rel=0.25)


def test_pipeline_error_with_noise_and_artefact_is_bounded_by_their_size():
    angles, truth, th_rmse, sh_rmse = synthetic()
    error = np.abs(angles - truth)
    # Noise (0.5 mm) on clusters ~100 mm across: about 0.3 deg per segment. The artefact
    # moves thigh markers by up to ~12 mm and shank markers by ~6 mm. About the long axes
    # the markers sit only 50-90 mm from the axis, so 12/90 + 6/55 rad ~ 14 deg is the
    # scale of the rotation error; about the transverse axes the lever arm is the cluster
    # length (~200 mm on the thigh, ~120 mm on the shank): 12/200 + 6/120 rad ~ 6 deg.
    assert np.nanmax(error[:, 0]) < 6.0
    assert np.nanmax(error[:, 1]) < 6.0
    assert np.nanmax(error[:, 2]) < 20.0
    assert np.nanmax(error[:, 2]) > 2.0         # the artefact must be visible
    # The deforming part of the artefact raises the thigh residual well above noise only.
    assert np.nanmean(th_rmse) > 2 * GEN.NOISE_SD * np.sqrt(6 / 12)


def test_gaps_give_nan_exactly_where_a_cluster_has_fewer_than_three_markers():
    angles, truth, th_rmse, sh_rmse = synthetic(noise_sd=0.0, sta_scale=0.0)
    undetermined = np.zeros(len(truth), bool)
    (_, first, last), = [g for g in GEN.GAPS if g[0] in GEN.SHANK_CLUSTER]
    undetermined[first:last + 1] = True
    assert np.array_equal(np.isnan(angles).any(axis=1), undetermined)
    np.testing.assert_allclose(angles[~undetermined], truth[~undetermined], atol=1e-8)
    assert np.isfinite(th_rmse).all()         # the thigh (4 markers) survives its gap


def test_gaps_warn_once_per_call():
    trials = GEN.make_trials()
    shank = list(GEN.SHANK_CLUSTER)
    local = calibrate_cluster(markers(trials["static"], shank),
                              markers(trials["static"], ["RLMAL", "RMMAL"]))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        reconstruct_landmarks(*local, markers(trials["walk"], shank))
    assert [str(w.message)[:16] for w in caught] == ["8 of 111 frames "]


# --- bad input --------------------------------------------------------------------------------
def test_calibrate_cluster_with_fewer_than_three_markers():
    with pytest.raises(ValueError, match="a cluster needs at least 3 markers; "
                                         "cluster_static has 2"):
        calibrate_cluster([[0, 0, 0], [1, 0, 0]], [[0, 0, 1]])


def test_calibrate_cluster_collinear():
    with pytest.raises(ValueError, match="markers of cluster_static are collinear"):
        calibrate_cluster([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 0, 1]])


def test_calibrate_cluster_marker_missing_in_every_static_frame():
    static = np.ones((5, 3, 3)) * np.arange(3)[:, None] + np.eye(3)
    static[:, 1] = np.nan
    with pytest.raises(ValueError, match=r"cluster_static: marker\(s\) \[1\] are missing"):
        calibrate_cluster(static, [[0, 0, 1]])
    with pytest.raises(ValueError, match=r"landmarks_static: marker\(s\) \[0\] are missing"):
        calibrate_cluster(np.eye(3), [[np.nan, 0, 1]])


def test_calibrate_cluster_wrong_shapes():
    with pytest.raises(ValueError, match=r"cluster_static must have shape \(n, 3\) or "
                                         r"\(frames, n, 3\); got shape \(3,\)"):
        calibrate_cluster([1, 2, 3], [[0, 0, 1]])
    with pytest.raises(ValueError, match=r"landmarks_static must have shape \(\.\.\., 3\)"):
        calibrate_cluster(np.eye(3), [[0, 1]])


def test_calibrate_cluster_infinite():
    with pytest.raises(ValueError, match="cluster_static contains infinite values"):
        calibrate_cluster([[0, 0, 0], [1, 0, 0], [0, np.inf, 0]], [[0, 0, 1]])


def test_reconstruct_landmarks_wrong_number_of_markers():
    c_local, l_local = calibrate_cluster(np.eye(3), [[0, 0, 0]])
    with pytest.raises(ValueError, match="cluster_dynamic has 4 markers per frame but "
                                         "cluster_local has 3"):
        reconstruct_landmarks(c_local, l_local, np.zeros((2, 4, 3)))


def test_reconstruct_landmarks_wrong_shapes():
    c_local, l_local = calibrate_cluster(np.eye(3), [[0, 0, 0]])
    with pytest.raises(ValueError, match=r"cluster_dynamic must have shape \(frames, n, 3\)"):
        reconstruct_landmarks(c_local, l_local, np.eye(3))
    with pytest.raises(ValueError, match=r"cluster_local must have shape \(n, 3\)"):
        reconstruct_landmarks(c_local[None], l_local, np.eye(3)[None])
    with pytest.raises(ValueError, match=r"landmarks_local must have shape \(m, 3\)"):
        reconstruct_landmarks(c_local, l_local[0], np.eye(3)[None])


def test_reconstruct_landmarks_nan_in_calibration():
    c_local, l_local = calibrate_cluster(np.eye(3), [[0, 0, 0]])
    with pytest.raises(ValueError, match="landmarks_local contains NaN"):
        reconstruct_landmarks(c_local, l_local * np.nan, np.eye(3)[None])


# --- real recordings (../shared/data), skipped when absent -----------------------------------
needs_shared = needs_shared()


@pytest.fixture(scope="module")
def running():
    from bmc_functions import read_trc
    static = read_trc(SHARED_DATA / "static_run.trc")
    dynamic = read_trc(SHARED_DATA / "motion_capture_run.trc")
    return static, dynamic


@needs_shared
@pytest.mark.parametrize("cluster", [["RTH1", "RTH2", "RTH3"], ["RTB1", "RTB2", "RTB3"],
                                     ["RASI", "LASI", "RPSI", "LPSI"]])
def test_real_running_cluster_fit_matches_the_readme(running, cluster):
    # The README of ../shared/data: SVD fit from the mean static cluster to every running
    # frame: mean RMSE about 1 to 3.5 mm, max about 4 mm, det(R) = +1 in every frame.
    # (Measured here: thigh 1.76 / 2.47 mm, shank 0.90 / 1.87 mm, pelvis 1.96 / 3.15 mm,
    # mean / max; hence the lower bound of 0.5 mm for "about 1".)
    static, dynamic = running
    reference = np.nanmean(markers(static, cluster), axis=0)
    R, L, rmse = svdt(reference, markers(dynamic, cluster), order="row")
    assert np.isfinite(rmse).all()
    assert 0.5 < rmse.mean() < 3.5 and rmse.max() < 4.5
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-9)


@needs_shared
def test_real_running_knee_angles_are_finite_and_plausible(running):
    static, dynamic = running
    # The anatomical landmarks are in the static trial only.
    assert np.isnan(markers(dynamic, ["RLFC", "RMFC", "RLMAL", "RMMAL"])).all()
    angles, th_rmse, sh_rmse = pipeline(static, dynamic, ["RTH1", "RTH2", "RTH3"],
                                        ["RTB1", "RTB2", "RTB3"])
    assert np.isfinite(angles).all()
    flexion, adduction, rotation = angles.T
    # Running: the knee stays flexed in stance and flexes far in swing (peak 80-130 deg in
    # the literature); adduction and rotation stay within a few tens of degrees.
    assert -10 < flexion.min() < 30 and 60 < flexion.max() < 140
    assert np.abs(adduction).max() < 25 and np.abs(rotation).max() < 45
