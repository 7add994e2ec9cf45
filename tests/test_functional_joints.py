"""Functional joint centre (SCoRE), axis (SARA) and the one-sided sphere fit, against the
ground truth of the seeded generator (data/generate_functional_data.py), scipy's nonlinear
least squares, and hand-built movements."""

import copy
import pickle
import time
import warnings

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from bmc_functions import (JointAxis, JointCentre, functional_axis, functional_joint_centre,
                           hip_joint_centre, rot_x, rot_y, rot_z, sphere_fit_centre, svdt)
from bmc_functions.models.functional_joints import MIN_RANGE_DEG, range_of_motion

from helpers import load_data_script

GEN = load_data_script("generate_functional_data")


def clusters(trial, *names):
    return [np.stack(list(trial[name].values()), axis=1) for name in names]


def rms_error(estimate, truth):
    return float(np.sqrt(np.nanmean(np.sum((np.asarray(estimate) - truth) ** 2, axis=1))))


def axis_angle_error(directions, truth):
    cos = np.abs(np.sum(directions * truth, axis=1))
    return float(np.degrees(np.arccos(np.clip(np.nanmean(cos), -1, 1))))


def line_distance(points, directions, truth_points):
    v = truth_points - points
    return np.linalg.norm(v - np.sum(v * directions, axis=1)[:, None] * directions, axis=1)


def quiet(function, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return function(*args, **kwargs)


@pytest.fixture(scope="module")
def exact_hip():
    return GEN.hip_trial(np.random.default_rng(1), noise_sd=0.0, sta_scale=0.0)


@pytest.fixture(scope="module")
def hip():
    return GEN.make_trials()["hip_star_arc"]


@pytest.fixture(scope="module")
def knee():
    return GEN.make_trials()["knee_flexion"]


# --- exact data: the true centre and axis are recovered --------------------------------

def test_score_recovers_the_true_centre_without_noise(exact_hip):
    pelvis, thigh = clusters(exact_hip, "pelvis", "thigh")
    centre = functional_joint_centre(pelvis, thigh)
    assert isinstance(centre, JointCentre) and centre.shape == (1501, 3)
    assert rms_error(centre, exact_hip["centre"]) < 1e-8
    assert centre.rms_distance < 1e-8 and np.nanmax(centre.distance) < 1e-8
    assert centre.frames_used == 1501 and centre.method == "SCoRE"
    # both segments moved (the pelvis sways): only their relative motion matters
    assert np.ptp(pelvis[:, 0, 0]) > 20


def test_sphere_fit_recovers_the_true_centre_without_noise(exact_hip):
    pelvis, thigh = clusters(exact_hip, "pelvis", "thigh")
    centre = sphere_fit_centre(pelvis, thigh)
    assert rms_error(centre, exact_hip["centre"]) < 1e-6
    assert centre.method == "sphere fit"


def test_local_centres_are_the_point_in_each_cluster_frame(exact_hip):
    pelvis, thigh = clusters(exact_hip, "pelvis", "thigh")
    centre = functional_joint_centre(pelvis, thigh)
    # carried into another trial (the static one) from each cluster separately
    static = GEN.static_trial(np.random.default_rng(5), noise_sd=0.0)
    markers = static["markers"]
    truth = static["truth"][["hip_x", "hip_y", "hip_z"]].to_numpy()
    p = markers[list(GEN.PELVIS_MARKERS)].to_numpy().reshape(-1, 4, 3)
    t = markers[list(GEN.THIGH_CLUSTER)].to_numpy().reshape(-1, 4, 3)
    np.testing.assert_allclose(centre.locate(p, segment=1), truth, atol=1e-8)
    np.testing.assert_allclose(centre.locate(t, segment=2), truth, atol=1e-8)
    np.testing.assert_allclose(centre.locate(p[0]), truth[0], atol=1e-8)   # one frame


def test_score_matches_scipy_nonlinear_least_squares(hip):
    # independent oracle: the same objective minimized by scipy from svdt's poses
    pelvis, thigh = clusters(hip, "pelvis", "thigh")
    centre = functional_joint_centre(pelvis, thigh)
    R1, t1, _ = svdt(centre.reference_1, pelvis, order="row")
    R2, t2, _ = svdt(centre.reference_2, thigh, order="row")

    def residuals(x):
        return (np.einsum("fij,j->fi", R1, x[:3]) + t1
                - np.einsum("fij,j->fi", R2, x[3:]) - t2).ravel()

    start = np.concatenate([centre.reference_1.mean(axis=0), centre.reference_2.mean(axis=0)])
    fit = least_squares(residuals, start, xtol=1e-14, ftol=1e-14, gtol=1e-14)
    np.testing.assert_allclose(centre.local_1, fit.x[:3], atol=1e-6)
    np.testing.assert_allclose(centre.local_2, fit.x[3:], atol=1e-6)
    distances = np.linalg.norm(residuals(fit.x).reshape(-1, 3), axis=1)
    assert centre.rms_distance == pytest.approx(np.sqrt(np.mean(distances**2)), rel=1e-9)


def test_score_is_symmetric(hip):
    pelvis, thigh = clusters(hip, "pelvis", "thigh")
    forward = functional_joint_centre(pelvis, thigh)
    backward = functional_joint_centre(thigh, pelvis)
    np.testing.assert_allclose(forward, backward, atol=1e-8)
    np.testing.assert_allclose(forward.local_1, backward.local_2, atol=1e-8)


def test_sara_recovers_the_true_axis_without_noise():
    trial = GEN.knee_trial(np.random.default_rng(2), noise_sd=0.0, sta_scale=0.0,
                           secondary=0.0)
    thigh, shank = clusters(trial, "thigh", "shank")
    result = functional_axis(thigh, shank)
    assert isinstance(result, JointAxis)
    points, directions = result
    assert points.shape == directions.shape == (1001, 3)
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0, atol=1e-12)
    # the sign rule: a knee given as (thigh, shank) points to the subject's right, which is
    # the true axis's sense (z of the thigh frame, turned by 5 deg)
    np.testing.assert_allclose(directions, trial["direction"], atol=1e-8)
    assert line_distance(points, directions, trial["point"]).max() < 1e-6
    assert result.rms_distance < 1e-6 and result.frames_used == 1001
    # the same axis in each segment's frame
    np.testing.assert_allclose(np.einsum("fij,j->fi", svdt(result.reference_1, thigh,
                                                           order="row")[0],
                                         result.direction_1), directions, atol=1e-8)


def test_axis_locate_in_another_trial():
    trial = GEN.knee_trial(np.random.default_rng(2), noise_sd=0.0, sta_scale=0.0,
                           secondary=0.0)
    thigh, shank = clusters(trial, "thigh", "shank")
    result = functional_axis(thigh[:500], shank[:500])
    for segment, markers in ((1, thigh[500:]), (2, shank[500:])):
        points, directions = result.locate(markers, segment=segment)
        np.testing.assert_allclose(directions, trial["direction"][500:], atol=1e-8)
        assert line_distance(points, directions, trial["point"][500:]).max() < 1e-6
    point, direction = result.locate(thigh[700])
    assert point.shape == direction.shape == (3,)


def test_sara_point_is_nearest_to_the_cluster_centroids():
    trial = GEN.knee_trial(np.random.default_rng(2), noise_sd=0.0, sta_scale=0.0,
                           secondary=0.0)
    thigh, shank = clusters(trial, "thigh", "shank")
    r = functional_axis(thigh, shank)
    o1, o2 = r.reference_1.mean(axis=0), r.reference_2.mean(axis=0)
    # moving along the axis (the same amount in both frames) only increases the sum of
    # squared distances to the centroids
    cost = lambda s: (np.sum((r.point_1 + s * r.direction_1 - o1) ** 2)  # noqa: E731
                      + np.sum((r.point_2 + s * r.direction_2 - o2) ** 2))
    assert cost(0.0) < cost(1.0) and cost(0.0) < cost(-1.0)


def test_sign_rule_points_to_the_subjects_right_for_a_left_knee_too(knee):
    # the committed right knee mirrored through the sagittal plane (z -> -z) is a left
    # knee; the rule needs no side: the axis still points to the subject's right (+z)
    thigh, shank = clusters(knee, "thigh", "shank")
    mirror = np.array([1.0, 1.0, -1.0])
    right = functional_axis(thigh, shank)[1]
    left = functional_axis(thigh * mirror, shank * mirror)[1]
    assert np.all(right[:, 2] > 0.9) and np.all(left[:, 2] > 0.9)
    # the same line, mirrored: its direction flips back to the right
    np.testing.assert_allclose(left, -right * mirror, atol=1e-9)


def test_reference_direction_chooses_the_sign(knee):
    thigh, shank = clusters(knee, "thigh", "shank")
    default = functional_axis(thigh, shank)
    flipped = functional_axis(thigh, shank, reference_direction=[0.0, 0.0, -1.0])
    np.testing.assert_allclose(flipped.directions, -default.directions)
    np.testing.assert_allclose(flipped.direction_1, -default.direction_1)
    per_frame = functional_axis(thigh, shank, reference_direction=knee["direction"])
    np.testing.assert_allclose(per_frame.directions, default.directions)


# --- missing data ------------------------------------------------------------------------

def test_frames_with_fewer_than_three_markers_are_left_out(hip):
    pelvis, thigh = clusters(hip, "pelvis", "thigh")
    thigh = thigh.copy()
    thigh[100:120, :2] = np.nan           # two of four thigh markers: 2 left, not tracked
    thigh[300:340, 3] = np.nan            # one marker: 3 left, still tracked
    pelvis = pelvis.copy()
    pelvis[500:505] = np.nan
    with pytest.warns(RuntimeWarning, match=r"^25 of 1501 frames have fewer than 3 visible"):
        centre = functional_joint_centre(pelvis, thigh)
    missing = np.isnan(centre).any(axis=1)
    expected = np.zeros(1501, bool)
    expected[100:120] = expected[500:505] = True
    assert np.array_equal(missing, expected)
    assert np.array_equal(np.isnan(centre.distance), expected)
    assert centre.frames_used == 1501 - 25
    assert not np.isnan(centre[300:340]).any()
    # the fit uses the other frames: close to the fit of the complete trial
    complete = functional_joint_centre(*clusters(hip, "pelvis", "thigh"))
    assert np.linalg.norm(centre.local_1 - complete.local_1) < 1.0
    with pytest.warns(RuntimeWarning, match=r"^20 of 1501 frames"), \
            pytest.warns(RuntimeWarning, match="not dominated by one axis"):
        points, directions = functional_axis(*clusters(hip, "pelvis", "thigh")[:1], thigh)
    assert np.array_equal(np.isnan(points).any(axis=1), np.isnan(directions).any(axis=1))
    assert np.isnan(points[100:120]).all()


def test_reference_is_the_first_complete_frame(hip):
    pelvis, thigh = clusters(hip, "pelvis", "thigh")
    thigh = thigh.copy()
    thigh[:10, 0] = np.nan
    centre = quiet(functional_joint_centre, pelvis, thigh)
    np.testing.assert_array_equal(centre.reference_2, thigh[10])


# --- the result type -----------------------------------------------------------------------

def test_result_behaves_as_a_plain_array(exact_hip):
    pelvis, thigh = clusters(exact_hip, "pelvis", "thigh")
    centre = functional_joint_centre(pelvis, thigh)
    assert isinstance(centre, np.ndarray)
    for derived in (centre[0], centre[:, 0], centre - exact_hip["centre"],
                    np.mean(centre, axis=0), np.nanmean(centre, axis=0), centre * 2):
        assert type(derived) is np.ndarray
    copy = centre.copy()
    assert copy.rms_distance == centre.rms_distance
    restored = pickle.loads(pickle.dumps(centre))
    assert type(restored) is JointCentre and np.array_equal(restored, centre)
    assert restored.rms_distance == centre.rms_distance
    np.testing.assert_array_equal(restored.local_1, centre.local_1)
    assert centre.range_of_motion.shape == (3,)


def test_numpy_functions_and_in_place_operations(exact_hip):
    centre = functional_joint_centre(*clusters(exact_hip, "pelvis", "thigh"))
    # NumPy functions see a plain array: a sorted or stacked array is not a fit
    for derived in (np.sort(centre, axis=0), np.concatenate([centre, centre]),
                    np.nan_to_num(centre), np.stack([centre, centre]), np.copy(centre),
                    np.where(centre > 0, centre, 0.0), np.diff(centre, axis=0)):
        assert type(derived) is np.ndarray
    np.testing.assert_array_equal(np.sort(centre, axis=0), np.sort(np.asarray(centre), axis=0))
    # in place: the same object, new values, the fit's details untouched
    moved = centre.copy()
    same = moved
    moved += 10.0
    assert moved is same and type(moved) is JointCentre
    np.testing.assert_allclose(moved - 10.0, centre)
    assert moved.rms_distance == centre.rms_distance
    # printing and pandas
    assert repr(centre).startswith("JointCentre([[") and "JointCentre" not in str(centre)
    table = pd.DataFrame(centre, columns=list("xyz"))
    assert type(table.to_numpy()) is np.ndarray
    np.testing.assert_array_equal(table.to_numpy(), np.asarray(centre))


def test_axis_result_pickles_and_copies(knee):
    result = functional_axis(*clusters(knee, "thigh", "shank"))
    for restored in (pickle.loads(pickle.dumps(result)), copy.copy(result),
                     copy.deepcopy(result)):
        assert type(restored) is JointAxis
        points, directions = restored
        np.testing.assert_array_equal(points, result.points)
        np.testing.assert_array_equal(directions, result.directions)
        np.testing.assert_array_equal(restored.direction_1, result.direction_1)
        assert restored.rms_distance == result.rms_distance
        assert restored.frames_used == result.frames_used
    thigh = clusters(knee, "thigh")[0]
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(result)).locate(thigh)[1],
                                  result.locate(thigh)[1])


def test_range_of_motion_of_hand_built_movements():
    eye = np.broadcast_to(np.eye(3), (61, 3, 3))
    hinge = rot_y(np.linspace(-20, 40, 61), degrees=True)
    np.testing.assert_allclose(range_of_motion(eye, hinge), [60, 0, 0], atol=1e-9)
    # the same hinge with both segments turned by a common rotation: unchanged
    common = rot_x(np.linspace(0, 90, 61), degrees=True)
    np.testing.assert_allclose(range_of_motion(common, common @ hinge), [60, 0, 0],
                               atol=1e-9)
    two = np.concatenate([rot_x(np.linspace(0, 30, 31), degrees=True),
                          rot_z(np.linspace(0, 10, 31), degrees=True)])
    ranges = range_of_motion(np.broadcast_to(np.eye(3), two.shape), two)
    assert ranges[0] > 30 and 9 < ranges[1] < 15 and ranges[2] < 1e-9


# --- validation: error against range of motion, noise and the Harrington regression -----

def mean_centre_errors(amplitude, noise_sd, sta_scale, seeds=range(4)):
    score, sphere = [], []
    for seed in seeds:
        trial = GEN.hip_trial(np.random.default_rng(seed), amplitude=amplitude,
                              noise_sd=noise_sd, sta_scale=sta_scale)
        pelvis, thigh = clusters(trial, "pelvis", "thigh")
        score.append(rms_error(quiet(functional_joint_centre, pelvis, thigh), trial["centre"]))
        sphere.append(rms_error(quiet(sphere_fit_centre, pelvis, thigh), trial["centre"]))
    return np.mean(score), np.mean(sphere)


def test_error_falls_as_the_range_grows_and_score_beats_the_sphere_fit():
    # Ehrig et al. (2006), with measurement noise only (0.5 mm)
    errors = {amp: mean_centre_errors(amp, 0.5, 0.0) for amp in (10, 20, 45)}
    score = [errors[a][0] for a in (10, 20, 45)]
    sphere = [errors[a][1] for a in (10, 20, 45)]
    assert score[0] > score[1] > score[2]
    assert sphere[0] > sphere[1] > sphere[2]
    for s, f in zip(score, sphere):
        assert s < f
    assert sphere[0] > 5 * score[0]               # the one-sided fit fails at small ranges
    assert score[1] < 3.0 and score[2] < 1.5      # mm


def test_error_grows_with_the_noise():
    low = mean_centre_errors(20, 0.25, 0.0)[0]
    high = mean_centre_errors(20, 1.0, 0.0)[0]
    # at least proportional to the noise (more: the noisy cluster orientations add a bias
    # that grows with the noise squared)
    assert high / low > 3.5 and high < 6.0


def test_soft_tissue_artefact_gives_an_error_that_a_range_cannot_remove():
    small = mean_centre_errors(20, 0.5, 1.0)[0]
    large = mean_centre_errors(45, 0.5, 1.0)[0]
    # the artefact moves with the joint angles: a systematic shift of 8-10 mm remains
    assert 6 < small < 12 and 6 < large < 12


def test_functional_centre_beats_harrington_on_the_committed_trial(hip):
    pelvis, thigh = clusters(hip, "pelvis", "thigh")
    score = rms_error(functional_joint_centre(pelvis, thigh), hip["centre"])
    p = hip["pelvis"]
    harrington = rms_error(hip_joint_centre(p["RASI"], p["LASI"], p["RPSI"], p["LPSI"]),
                           hip["centre"])
    # per frame, the noise and artefact of the four pelvis markers add to the regression's
    # 15.7 mm (the generator's offset); from the averaged static trial, as labs use it:
    assert 14.0 < harrington < 25.0
    static = GEN.make_trials()["static"]["markers"].mean()
    averaged = hip_joint_centre(*(static[name].to_numpy() for name in
                                  ("RASI", "LASI", "RPSI", "LPSI")))
    truth = GEN.make_trials()["static"]["truth"][["hip_x", "hip_y", "hip_z"]].to_numpy()[0]
    assert np.linalg.norm(averaged - truth) == pytest.approx(15.7, abs=1.0)
    assert score < 12.0 and score < 0.6 * np.linalg.norm(averaged - truth)


def test_knee_axis_error_on_the_committed_trial(knee):
    thigh, shank = clusters(knee, "thigh", "shank")
    points, directions = functional_axis(thigh, shank)
    assert axis_angle_error(directions, knee["direction"]) < 8.0          # deg
    assert np.median(line_distance(points, directions, knee["point"])) < 10.0   # mm
    assert np.all(np.sum(directions * knee["direction"], axis=1) > 0)    # to the right


def test_axis_error_falls_as_the_range_grows():
    errors = []
    for amplitude in (20, 45, 90):
        angles = []
        for seed in range(3):
            trial = GEN.knee_trial(np.random.default_rng(seed), amplitude=amplitude,
                                   sta_scale=0.0, secondary=0.0)
            thigh, shank = clusters(trial, "thigh", "shank")
            angles.append(axis_angle_error(quiet(functional_axis, thigh, shank)[1],
                                           trial["direction"]))
        errors.append(np.mean(angles))
    assert errors[0] > errors[1] > errors[2]


def test_sixty_seconds_at_100_hz_is_fast():
    # measured under load on a shared machine; the bound only catches a loop over frames
    rng = np.random.default_rng(0)
    frames = 6000
    R = rot_x(rng.uniform(-30, 30, frames), degrees=True) @ rot_z(
        rng.uniform(-30, 30, frames), degrees=True)
    thigh = np.einsum("fij,nj->fni", R, rng.normal(0, 80, (4, 3)))
    pelvis = np.broadcast_to(rng.normal(0, 80, (4, 3)), (frames, 4, 3))
    start = time.perf_counter()
    functional_joint_centre(pelvis, thigh)
    quiet(functional_axis, pelvis, thigh)
    assert time.perf_counter() - start < 2.0


# --- bad input: each with its own message ------------------------------------------------

def hand_trial(R):
    pelvis = np.array([[0, 0, 0], [100, 0, 0], [0, 100, 0], [0, 0, 100]], float)
    thigh = np.array([[0, -100, 40], [30, -250, 50], [-20, -300, 60]], float)
    return (np.broadcast_to(pelvis, (len(R), 4, 3)),
            np.einsum("fij,nj->fni", R, thigh))


def test_too_little_movement():
    R = rot_x(np.linspace(0, 3, 50), degrees=True) @ rot_z(np.linspace(0, 2, 50),
                                                            degrees=True)
    with pytest.raises(ValueError, match=r"too little movement to determine the joint "
                       r"centre: the joint turned through 3\.\d\d deg .* at least 5 deg"):
        functional_joint_centre(*hand_trial(R))
    with pytest.raises(ValueError, match=r"too little movement to determine the joint "
                       r"axis: the joint turned through 3\.\d\d deg .* at least 5 deg"):
        functional_axis(*hand_trial(R))
    with pytest.raises(ValueError, match=r"at least 5 deg is needed, and 30 deg or more for "
                       r"an accurate axis"):
        functional_axis(*hand_trial(R))
    with pytest.raises(ValueError, match="too little movement"):
        sphere_fit_centre(*hand_trial(R))


def test_pure_hinge_given_to_the_centre_method():
    R = rot_z(np.linspace(0, 60, 61), degrees=True)
    with pytest.raises(ValueError, match=r"a rotation about one axis \(a hinge\): 60\.0 deg "
                       r"about its main axis but only 0\.00 deg .*undetermined along the "
                       r"axis.*use functional_axis"):
        functional_joint_centre(*hand_trial(R))


def test_small_second_range_warns():
    R = np.concatenate([rot_z(np.linspace(0, 60, 61), degrees=True),
                        rot_x(np.linspace(0, 8, 20), degrees=True)])
    with pytest.warns(RuntimeWarning, match=r"functional_joint_centre: the joint turned "
                      r"through only \d+\.\d deg about its second axis"):
        functional_joint_centre(*hand_trial(R))


def test_small_flexion_range_warns_for_the_axis():
    R = rot_z(np.linspace(0, 20, 41), degrees=True)
    with pytest.warns(RuntimeWarning, match=r"^functional_axis: the joint turned through only "
                      r"20\.0 deg about its main axis; below 30 deg"):
        points, directions = functional_axis(*hand_trial(R))
    np.testing.assert_allclose(np.abs(directions[:, 2]), 1.0, atol=1e-9)   # still exact
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        functional_axis(*hand_trial(rot_z(np.linspace(0, 31, 41), degrees=True)))


def test_axis_of_a_ball_joint_movement_warns(hip):
    pelvis, thigh = clusters(hip, "pelvis", "thigh")
    with pytest.warns(RuntimeWarning, match="not dominated by one axis"):
        functional_axis(pelvis, thigh)


def test_fewer_than_three_markers():
    pelvis, thigh = hand_trial(rot_z(np.linspace(0, 60, 61), degrees=True))
    with pytest.raises(ValueError, match=r"markers_2 has 2 marker\(s\); a segment's pose "
                       r"needs at least 3"):
        functional_joint_centre(pelvis, thigh[:, :2])
    with pytest.raises(ValueError, match=r"markers_1 has 2 marker\(s\)"):
        functional_axis(pelvis[:, :2], thigh)


def test_different_frame_counts():
    pelvis, thigh = hand_trial(rot_z(np.linspace(0, 60, 61), degrees=True))
    with pytest.raises(ValueError, match=r"same number of frames \(the same trial\); got 61 "
                       r"and 60"):
        functional_joint_centre(pelvis, thigh[:60])
    with pytest.raises(ValueError, match="same number of frames"):
        functional_axis(pelvis, thigh[:60])


def test_wrong_shape():
    with pytest.raises(ValueError, match=r"markers_1 must have shape \(frames, n, 3\).*got "
                       r"shape \(4, 3\)"):
        functional_joint_centre(np.zeros((4, 3)), np.zeros((10, 4, 3)))
    with pytest.raises(ValueError, match=r"markers_2 must have shape \(\.\.\., 3\)"):
        functional_joint_centre(np.zeros((10, 4, 3)), np.zeros((10, 4, 2)))


def test_no_frame_with_every_marker():
    pelvis, thigh = hand_trial(rot_z(np.linspace(0, 60, 61), degrees=True))
    thigh = thigh.copy()
    thigh[::2, 0] = np.nan
    thigh[1::2, 1] = np.nan
    with pytest.raises(ValueError, match=r"markers_2: no frame has all 3 markers visible; "
                       r"one such frame is needed as the segment's reference$"):
        functional_axis(pelvis, thigh)


def test_marker_missing_in_every_frame_is_named():
    pelvis, thigh = hand_trial(rot_z(np.linspace(0, 60, 61), degrees=True))
    pelvis = pelvis.copy()
    pelvis[:, 2] = np.nan
    with pytest.raises(ValueError, match=r"markers_1: no frame has all 4 markers visible.*"
                       r"marker\(s\) 2 missing in every frame: leave them out of markers_1"):
        functional_joint_centre(pelvis, thigh)
    # left out, the other three markers track the pelvis
    with pytest.raises(ValueError, match="a rotation about one axis"):
        functional_joint_centre(pelvis[:, [0, 1, 3]], thigh)


def test_collinear_cluster():
    pelvis, thigh = hand_trial(rot_z(np.linspace(0, 60, 61), degrees=True))
    line = np.zeros_like(pelvis)
    line[:, :, 0] = [0, 1, 2, 3]
    with pytest.raises(ValueError, match=r"markers_1 \(reference frame 0\): .*collinear"):
        functional_axis(line, thigh)


def test_infinite_values():
    pelvis, thigh = hand_trial(rot_z(np.linspace(0, 60, 61), degrees=True))
    thigh = thigh.copy()
    thigh[3, 0, 0] = np.inf
    with pytest.raises(ValueError, match="markers_2 contains infinite values"):
        functional_axis(pelvis, thigh)


def test_too_few_tracked_frames():
    pelvis, thigh = hand_trial(rot_z(np.linspace(0, 60, 61), degrees=True))
    thigh = thigh.copy()
    thigh[1:, :2] = np.nan
    with pytest.raises(ValueError, match=r"only 1 of 61 frames have both clusters tracked"):
        quiet(functional_axis, pelvis, thigh)


def test_bad_reference_direction(knee):
    thigh, shank = clusters(knee, "thigh", "shank")
    with pytest.raises(ValueError, match=r"reference_direction must have shape \(3,\) or "
                       r"\(frames, 3\) = \(1001, 3\); got shape \(2, 3\)"):
        functional_axis(thigh, shank, reference_direction=np.ones((2, 3)))
    # perpendicular to the estimated axis in every frame
    perpendicular = np.cross(functional_axis(thigh, shank)[1], [0.0, 1.0, 0.0])
    with pytest.raises(ValueError, match="reference_direction is perpendicular to the axis"):
        functional_axis(thigh, shank, reference_direction=perpendicular)


def test_locate_bad_input(exact_hip):
    centre = functional_joint_centre(*clusters(exact_hip, "pelvis", "thigh"))
    with pytest.raises(ValueError, match="segment must be 1 or 2; got 3"):
        centre.locate(np.zeros((4, 3)), segment=3)
    with pytest.raises(ValueError, match=r"markers must have shape \(frames, 4, 3\) or "
                       r"\(4, 3\): the cluster of segment 1; got shape \(3, 3\)"):
        centre.locate(np.zeros((3, 3)))


# --- property test: any rigid motion about a fixed point, scipy as the oracle -------------

@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), far=st.floats(0.0, 1e4))
def test_score_and_sara_recover_random_joints_exactly(seed, far):
    """Both segments move anywhere in the lab (scipy's random rotations, translations up to
    `far` mm); segment 2 turns about a point fixed in both (a ball joint) or about a line
    (a hinge). Without noise the point and the line come back exactly."""
    rng = np.random.default_rng(seed)
    frames = 60
    cluster_1 = rng.normal(0, 60, (4, 3))
    cluster_2 = rng.normal(0, 60, (3, 3))
    centre_1 = rng.normal(0, 150, 3)                       # the joint in segment 1's frame
    centre_2 = rng.normal(0, 150, 3)                       # ... and in segment 2's frame
    R1 = Rotation.random(frames, random_state=rng).as_matrix()
    t1 = rng.uniform(-far, far, (frames, 3))
    # ball joint: relative rotations spread over +-25 deg about random axes
    rel = Rotation.from_rotvec(rng.uniform(-25, 25, (frames, 3)), degrees=True).as_matrix()
    R2 = R1 @ rel
    t2 = (np.einsum("fij,j->fi", R1, centre_1) + t1) - np.einsum("fij,j->fi", R2, centre_2)
    m1 = np.einsum("fij,nj->fni", R1, cluster_1) + t1[:, None]
    m2 = np.einsum("fij,nj->fni", R2, cluster_2) + t2[:, None]
    centre = functional_joint_centre(m1, m2)
    truth = np.einsum("fij,j->fi", R1, centre_1) + t1
    scale = max(far, 1000.0)
    np.testing.assert_allclose(centre, truth, atol=1e-9 * scale)
    # hinge: relative rotations about one random axis (fixed in both frames), 0-90 deg
    axis = Rotation.random(random_state=rng).apply([0.0, 0.0, 1.0])
    rel = Rotation.from_rotvec(np.linspace(0, 90, frames)[:, None] * axis,
                               degrees=True).as_matrix()
    R2 = R1 @ rel
    t2 = (np.einsum("fij,j->fi", R1, centre_1) + t1) - np.einsum("fij,j->fi", R2, centre_1)
    m2 = np.einsum("fij,nj->fni", R2, cluster_2) + t2[:, None]
    points, directions = functional_axis(m1, m2)
    true_direction = np.einsum("fij,j->fi", R1, axis)
    np.testing.assert_allclose(np.abs(np.sum(directions * true_direction, axis=1)), 1.0,
                               atol=1e-9)
    assert line_distance(points, directions, truth).max() < 1e-8 * scale


# --- issue 21: the fits look at their own residual ------------------------------------------

def _trial_clusters(path, labels):
    from bmc_functions import read_trc
    df = read_trc(path)
    return np.stack([df[label].to_numpy() for label in labels], axis=1)


def test_score_leaves_out_frames_where_a_cluster_lost_its_shape():
    from helpers import ROOT
    folder = ROOT / "data" / "functional"
    pelvis = _trial_clusters(folder / "hip_star_arc.trc", ["RASI", "LASI", "RPSI", "LPSI"])
    thigh = _trial_clusters(folder / "hip_star_arc.trc", ["RTH1", "RTH2", "RTH3", "RTH4"])
    swapped = thigh.copy()
    swapped[750:, [0, 1]] = thigh[750:, [1, 0]]
    clean = functional_joint_centre(pelvis, thigh)
    with pytest.warns(RuntimeWarning, match=r"751 of 1501 frames of markers_2 do not have "
                                            r"the cluster's shape"):
        fit = functional_joint_centre(pelvis, swapped)
    assert fit.frames_used == 750
    assert np.linalg.norm(fit.local_1 - clean.local_1) < 3.0


@pytest.mark.parametrize("change", ["order", "size", "metres"])
def test_locate_with_another_reference_warns_and_gives_nan(change):
    from helpers import ROOT
    folder = ROOT / "data" / "functional"
    pelvis = _trial_clusters(folder / "hip_star_arc.trc", ["RASI", "LASI", "RPSI", "LPSI"])
    thigh = _trial_clusters(folder / "hip_star_arc.trc", ["RTH1", "RTH2", "RTH3", "RTH4"])
    static = _trial_clusters(folder / "static.trc", ["RASI", "LASI", "RPSI", "LPSI"])
    fit = functional_joint_centre(pelvis, thigh)
    moved = {"order": static[:, [1, 0, 2, 3]], "size": static * 1.4,
             "metres": static / 1000}[change]
    assert np.isfinite(fit.locate(static)).all()
    with pytest.warns(RuntimeWarning, match=r"frames of markers do not have the cluster's "
                                            r"shape.*the centre is NaN there"):
        located = fit.locate(moved)
    assert np.isnan(located).all()
