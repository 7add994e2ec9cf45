"""Tests of bmc_functions.rigid_body.motion: angular velocity and finite helical axes."""

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from bmc_functions import (HelicalAxis, angular_velocity, compose, helical_axes, helical_axis,
                           rot_x, rot_z)
from bmc_functions.rigid_body.motion import MIN_HELICAL_ANGLE, consecutive_turns, matrix_rows

RNG_SEED = 20240515


def fixed_axis_motion(axis, speed, rate, frames):
    """Rotation about a fixed unit axis at a constant speed (rad/s), from scipy."""
    time = np.arange(frames) / rate
    return Rotation.from_rotvec(np.outer(speed * time, axis)).as_matrix()


def zxy_motion(rate, duration=2.0):
    """R = Rz(a) Rx(b) Ry(c) with smooth angles, and the analytic angular velocity in the
    lab: a' e_z + b' Rz(a) e_x + c' Rz(a) Rx(b) e_y (derived by hand)."""
    t = np.arange(int(round(duration * rate)) + 1) / rate
    a, da = 0.8 * np.sin(2 * t), 1.6 * np.cos(2 * t)
    b, db = 0.5 * np.cos(3 * t), -1.5 * np.sin(3 * t)
    c, dc = 0.4 * t + 0.3 * np.sin(5 * t), 0.4 + 1.5 * np.cos(5 * t)
    Rz = Rotation.from_euler("z", a[:, None]).as_matrix()
    Rx = Rotation.from_euler("x", b[:, None]).as_matrix()
    R = Rz @ Rx @ Rotation.from_euler("y", c[:, None]).as_matrix()
    omega = (da[:, None] * [0, 0, 1] + db[:, None] * Rz[:, :, 0]
             + dc[:, None] * (Rz @ Rx)[:, :, 1])
    return R, omega


# ---------------------------------------------------------------- angular_velocity


@pytest.mark.parametrize("seed", range(5))
def test_fixed_axis_constant_speed_is_sin_omega_h_over_h_in_every_frame(seed):
    rng = np.random.default_rng([RNG_SEED, seed])
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    speed, rate = rng.uniform(0.5, 20), rng.uniform(50, 500)
    R = fixed_axis_motion(axis, speed, rate, 40)
    expected = np.sin(speed / rate) * rate * axis   # central and one-sided alike
    np.testing.assert_allclose(angular_velocity(R, rate), np.tile(expected, (40, 1)),
                               rtol=0, atol=1e-9 * speed)
    # the axis is fixed in the segment too
    np.testing.assert_allclose(angular_velocity(R, rate, frame="local"),
                               np.tile(expected, (40, 1)), rtol=0, atol=1e-9 * speed)


def test_documented_relative_error_omega_h_squared_over_six():
    R = fixed_axis_motion([0, 0, 1], 10.0, 100.0, 5)
    error = 1 - angular_velocity(R, 100.0)[:, 2] / 10.0
    np.testing.assert_allclose(error, (10.0 / 100) ** 2 / 6, rtol=1e-3)


def test_general_motion_against_analytic_omega_and_second_order_convergence():
    errors = []
    for rate in (100.0, 200.0, 400.0):
        R, omega = zxy_motion(rate)
        est = angular_velocity(R, rate)
        errors.append(np.abs(est - omega)[1:-1].max())          # interior: central
        assert np.abs(est - omega).max() < 20 / rate             # ends: first order
    assert errors[0] < 2e-3
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    np.testing.assert_allclose(ratios, 4.0, rtol=0.05)          # O(h^2)


def test_local_is_lab_rotated_into_the_segment():
    R, _ = zxy_motion(150.0)
    lab = angular_velocity(R, 150.0)
    local = angular_velocity(R, 150.0, frame="local")
    np.testing.assert_allclose(local, np.einsum("fji,fj->fi", R, lab), atol=1e-12)


def test_against_scipy_rotation_vectors_of_consecutive_frames():
    rate = 200.0
    R, _ = zxy_motion(rate)
    rotvec = Rotation.from_matrix(np.swapaxes(R[:-1], 1, 2) @ R[1:]).as_rotvec() * rate
    oracle = 0.5 * (rotvec[:-1] + rotvec[1:])                    # local, frames 1..F-2
    local = angular_velocity(R, rate, frame="local")[1:-1]
    assert np.abs(local - oracle).max() < 1e-3
    # and the one-sided end equals the mid-interval rotation vector to first order
    assert np.abs(angular_velocity(R, rate, frame="local")[0] - rotvec[0]).max() < 1e-3


def test_missing_frames_give_nan_only_where_no_neighbour_is_left():
    R = fixed_axis_motion([1.0, 0, 0], 3.0, 100.0, 13)
    R[[0, 5, 8, 10]] = np.nan
    omega = angular_velocity(R, 100.0)
    expected = np.sin(0.03) * 100
    # missing frames (0, 5, 8, 10) and frame 9 (both neighbours missing) are NaN
    nan = np.isnan(omega).any(axis=1)
    assert nan.tolist() == [i in (0, 5, 8, 9, 10) for i in range(13)]
    # frame 1 (start of data), 4, 6, 7 and 11 (next to a gap) and 12 (end) use one-sided
    # differences: exact for this motion
    np.testing.assert_allclose(omega[~nan, 0], expected, rtol=1e-12)


def test_two_frames_use_one_sided_differences():
    R = rot_z([0.0, 0.1])
    np.testing.assert_allclose(angular_velocity(R, 10)[:, 2], [10 * np.sin(0.1)] * 2)


@pytest.mark.parametrize("R, message", [
    (np.zeros((10, 3)), r"R must have shape \(frames, 3, 3\).*got shape \(10, 3\)"),
    (np.eye(3), r"R must have shape \(frames, 3, 3\).*got shape \(3, 3\)"),
    (np.zeros((2, 4, 3, 3)), r"R must have shape \(frames, 3, 3\).*got shape \(2, 4, 3, 3\)"),
    (np.eye(3)[None], r"at least 2 frames.*got 1"),
    (np.stack([np.eye(3), 2 * np.eye(3)]), r"R is not a rotation matrix: R @ R.T differs"),
    (np.stack([np.eye(3), np.diag([1.0, 1, -1])]), r"R is not a rotation matrix: det\(R\)"),
    (np.full((2, 3, 3), np.inf), "R contains infinite values"),
])
def test_angular_velocity_bad_R(R, message):
    with pytest.raises(ValueError, match=message):
        angular_velocity(R, 100)


@pytest.mark.parametrize("rate", [0, -100, 0.0, np.nan, np.inf])
def test_angular_velocity_rate_not_positive(rate):
    with pytest.raises(ValueError, match=r"rate must be a positive, finite sampling rate in "
                                         r"Hz; got"):
        angular_velocity(rot_z([0, 0.1]), rate)


@pytest.mark.parametrize("rate", ["100", None, [100], True])
def test_angular_velocity_rate_not_a_number(rate):
    with pytest.raises(TypeError, match=r"rate must be a positive, finite sampling rate in "
                                        r"Hz; got"):
        angular_velocity(rot_z([0, 0.1]), rate)


def test_angular_velocity_unknown_frame():
    with pytest.raises(ValueError, match=r"frame must be 'lab' or 'local'; got 'global'"):
        angular_velocity(rot_z([0, 0.1]), 100, frame="global")


def test_angular_velocity_frame_not_a_string():
    with pytest.raises(TypeError, match=r"frame must be 'lab' or 'local'; got None"):
        angular_velocity(rot_z([0, 0.1]), 100, frame=None)


# ---------------------------------------------------------------- helical_axis


def random_screws(rng, count, max_angle=np.pi):
    """Known screws: unit n, point s (nearest the origin: s . n = 0), angle, translation,
    and two poses related by them."""
    n = rng.normal(size=(count, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    s = rng.normal(size=(count, 3)) * 200
    s -= np.einsum("fi,fi->f", s, n)[:, None] * n
    angle = rng.uniform(0.2, max_angle, count)
    tau = rng.normal(size=count) * 50
    R1 = Rotation.random(count, rng=rng).as_matrix()
    t1 = rng.normal(size=(count, 3)) * 300
    Rs = Rotation.from_rotvec(angle[:, None] * n).as_matrix()
    # p2 = Rs (p1 - s) + s + tau n for every point p1 of the segment
    R2 = Rs @ R1
    t2 = np.einsum("fij,fj->fi", Rs, t1 - s) + s + tau[:, None] * n
    return (R1, t1, R2, t2), (n, s, angle, tau)


def test_recovers_known_screws():
    rng = np.random.default_rng(RNG_SEED)
    poses, (n, s, angle, tau) = random_screws(rng, 500)
    axis = helical_axis(*poses)
    assert isinstance(axis, HelicalAxis)
    np.testing.assert_allclose(axis.direction, n, atol=1e-13)
    np.testing.assert_allclose(axis.point, s, atol=1e-10)      # mm, points ~200 mm away
    np.testing.assert_allclose(axis.angle, angle, atol=1e-13)
    np.testing.assert_allclose(axis.translation, tau, atol=1e-10)


def test_close_to_180_degrees_stays_accurate():
    rng = np.random.default_rng(RNG_SEED + 1)
    (R1, t1, _, _), (n, s, _, tau) = random_screws(rng, 200)
    angle = np.pi - 10.0 ** rng.uniform(-9, -3, 200)
    Rs = Rotation.from_rotvec(angle[:, None] * n).as_matrix()
    R2 = Rs @ R1
    t2 = np.einsum("fij,fj->fi", Rs, t1 - s) + s + tau[:, None] * n
    axis = helical_axis(R1, t1, R2, t2)
    np.testing.assert_allclose(axis.direction, n, atol=1e-13)  # from the symmetric part
    np.testing.assert_allclose(axis.point, s, atol=1e-10)
    np.testing.assert_allclose(axis.angle, angle, atol=1e-12)


def test_direction_times_angle_is_scipy_rotation_vector():
    R1 = Rotation.random(300, rng=1).as_matrix()
    R2 = Rotation.random(300, rng=2).as_matrix()
    axis = helical_axis(R1, np.zeros(3), R2, np.zeros(3))
    rotvec = Rotation.from_matrix(R2 @ np.swapaxes(R1, 1, 2)).as_rotvec()
    np.testing.assert_allclose(axis.direction * axis.angle[:, None], rotvec, atol=1e-9)


quaternions = st.lists(st.floats(-1, 1), min_size=4, max_size=4).map(np.array)
translations = st.lists(st.floats(-1e3, 1e3), min_size=3, max_size=3).map(np.array)


@settings(max_examples=200, deadline=None)
@given(q1=quaternions, q2=quaternions, t1=translations, t2=translations)
def test_property_screw_reproduces_the_displacement_and_scipy_rotvec(q1, q2, t1, t2):
    assume(np.linalg.norm(q1) > 0.1 and np.linalg.norm(q2) > 0.1)
    R1 = Rotation.from_quat(q1).as_matrix()
    R2 = Rotation.from_quat(q2).as_matrix()
    rotvec = Rotation.from_matrix(R2 @ R1.T).as_rotvec()
    assume(np.linalg.norm(rotvec) > 1e-3)
    axis = helical_axis(R1, t1, R2, t2, min_angle=0)
    # scipy's rotation vector (the sign of n is free only at exactly 180 degrees)
    if axis.angle < np.pi - 1e-6:
        np.testing.assert_allclose(axis.angle * axis.direction, rotvec, atol=1e-9)
    # the screw moves every point of the segment as the two poses do
    p_local = np.array([[0.0, 0, 0], [100, 0, 0], [0, 100, 0], [0, 0, 100]])
    screw = Rotation.from_rotvec(axis.angle * axis.direction).as_matrix()
    p1, p2 = p_local @ R1.T + t1, p_local @ R2.T + t2
    moved = (p1 - axis.point) @ screw.T + axis.point + axis.translation * axis.direction
    scale = 1 + np.abs(t1).max() + np.abs(t2).max()
    np.testing.assert_allclose(moved, p2, atol=1e-8 * scale / min(axis.angle, 1.0))


def test_point_nearest_a_given_point():
    rng = np.random.default_rng(RNG_SEED + 2)
    poses, (n, s, angle, tau) = random_screws(rng, 50)
    p = rng.normal(size=(50, 3)) * 100
    axis = helical_axis(*poses, point=p)
    np.testing.assert_allclose(axis.point, s + np.einsum("fi,fi->f", p - s, n)[:, None] * n,
                               atol=1e-7)
    # the point is on the axis and p - point is perpendicular to it
    np.testing.assert_allclose(np.einsum("fi,fi->f", p - axis.point, n), 0, atol=1e-7)


def test_hand_derived_quarter_turn_about_a_vertical_line():
    # 90 deg about z through (100, 50, 0), 20 mm along z: p2 = Rz (p1 - c) + c + 20 e_z
    c = np.array([100.0, 50, 0])
    Rz = rot_z(np.pi / 2)
    t2 = c - Rz @ c + [0, 0, 20]
    axis = helical_axis(np.eye(3), np.zeros(3), Rz, t2)
    np.testing.assert_allclose(axis.direction, [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(axis.point, [100, 50, 0], atol=1e-12)
    assert axis.angle == pytest.approx(np.pi / 2)
    assert axis.translation == pytest.approx(20)


def test_below_min_angle_is_nan_with_one_warning():
    angles = np.radians([0.0, 1.0, 4.9, 5.1, 30.0])
    R2 = rot_x(angles)
    with pytest.warns(RuntimeWarning, match=r"^3 of 5 frames \(pairs of poses\) rotate less "
                                            r"than min_angle = 5 degrees"):
        axis = helical_axis(np.eye(3), np.zeros(3), R2, np.zeros(3))
    assert np.isnan(axis.direction[:3]).all() and np.isnan(axis.point[:3]).all()
    assert np.isnan(axis.translation[:3]).all()
    np.testing.assert_allclose(axis.angle, angles, atol=1e-15)   # the angle is known
    np.testing.assert_allclose(axis.direction[3:], [[1, 0, 0]] * 2, atol=1e-12)
    assert MIN_HELICAL_ANGLE == pytest.approx(np.radians(5))


def test_min_angle_zero_gives_the_axis_of_exact_small_rotations():
    axis = helical_axis(np.eye(3), np.zeros(3), rot_x(1e-6), np.zeros(3), min_angle=0)
    np.testing.assert_allclose(axis.direction, [1, 0, 0], atol=1e-9)
    no_rotation = helical_axis(np.eye(3), np.zeros(3), np.eye(3), [1.0, 0, 0], min_angle=0)
    assert np.isnan(no_rotation.direction).all()                # pure translation: no axis


def test_nan_pose_gives_nan_axis_and_broadcasting():
    R2 = rot_z(np.radians([10.0, 20, 30]))
    R2[1] = np.nan
    axis = helical_axis(np.eye(3), np.zeros(3), R2, np.zeros((3, 3)))
    assert axis.direction.shape == (3, 3) and axis.angle.shape == (3,)
    assert np.isnan(axis.direction[1]).all() and np.isnan(axis.angle[1])
    np.testing.assert_allclose(axis.direction[[0, 2]], [[0, 0, 1]] * 2, atol=1e-12)


@pytest.mark.parametrize("args, message", [
    ((np.eye(3), np.zeros(2), np.eye(3), np.zeros(3)), r"t1 must have shape \(\.\.\., 3\)"),
    ((np.eye(3), np.zeros(3), np.eye(2), np.zeros(3)), r"R2 must have shape \(\.\.\., 3, 3\)"),
    ((2 * np.eye(3), np.zeros(3), np.eye(3), np.zeros(3)), r"R1 is not a rotation matrix"),
    ((np.eye(3), np.zeros(3), rot_z([0.1, 0.2]), np.zeros((3, 3))),
     r"the leading axes of R1, t1, R2, t2 \(and point\) must broadcast; got shapes"),
])
def test_helical_axis_bad_input(args, message):
    with pytest.raises(ValueError, match=message):
        helical_axis(*args)


@pytest.mark.parametrize("min_angle", [-0.1, np.pi, np.nan])
def test_helical_axis_bad_min_angle(min_angle):
    with pytest.raises(ValueError, match=r"min_angle must be a number of radians in \[0, pi\); "
                                         r"got"):
        helical_axis(np.eye(3), np.zeros(3), rot_z(1.0), np.zeros(3), min_angle=min_angle)


@pytest.mark.parametrize("min_angle", ["5", None, True, [0.1]])
def test_helical_axis_min_angle_not_a_number(min_angle):
    with pytest.raises(TypeError, match=r"min_angle must be a number of radians in \[0, pi\); "
                                        r"got .*\("):
        helical_axis(np.eye(3), np.zeros(3), rot_z(1.0), np.zeros(3), min_angle=min_angle)


# ---------------------------------------------------------------- helical_axes


def knee_like_trial(frames=60):
    """Rotation about the x axis through (0, 0, -50) by 2 degrees per frame."""
    R = rot_x(np.radians(2.0 * np.arange(frames)))
    c = np.array([0.0, 0, -50])
    return R, c - R @ c


def test_step_pairs_every_frame_with_the_one_step_later():
    rng = np.random.default_rng(RNG_SEED + 3)
    R = compose(np.cumsum(rng.normal(0, 4, (50, 3)), axis=0), "ZXY", degrees=True)
    t = np.cumsum(rng.normal(0, 10, (50, 3)), axis=0)
    axes, frames = helical_axes(R, t, step=5, min_angle=0)
    assert frames.tolist() == [[k, k + 5] for k in range(45)]
    single = helical_axis(R[:-5], t[:-5], R[5:], t[5:], min_angle=0)
    for got, expected in zip(axes, single):
        np.testing.assert_array_equal(got, expected)


def test_angle_step_finds_increments_of_at_least_that_angle():
    R, t = knee_like_trial()
    axes, frames = helical_axes(R, t, angle_step=np.radians(9.9))
    assert frames.tolist() == [[5 * k, 5 * k + 5] for k in range(11)]
    np.testing.assert_allclose(axes.direction, [[1, 0, 0]] * 11, atol=1e-12)
    np.testing.assert_allclose(axes.point, [[0, 0, -50]] * 11, atol=1e-9)
    np.testing.assert_allclose(np.degrees(axes.angle), 10.0, atol=1e-9)


def test_angle_step_skips_missing_frames():
    R, t = knee_like_trial()
    R[4:7] = np.nan
    axes, frames = helical_axes(R, t, angle_step=np.radians(9.9))
    assert frames[0].tolist() == [0, 7]
    assert not np.isnan(axes.direction).any()


def test_angle_step_never_reached_gives_no_axes():
    R, t = knee_like_trial(5)                  # 8 degrees in all
    axes, frames = helical_axes(R, t, angle_step=np.radians(10))
    assert frames.shape == (0, 2) and axes.direction.shape == (0, 3) and axes.angle.shape == (0,)


def test_step_warns_for_small_rotations():
    R, t = knee_like_trial(10)
    with pytest.warns(RuntimeWarning, match=r"^9 of 9 frames \(pairs of poses\) rotate less"):
        axes, _ = helical_axes(R, t, step=1)
    assert np.isnan(axes.direction).all()


@pytest.mark.parametrize("kwargs, error, message", [
    ({}, ValueError, r"give exactly one of step .* and angle_step .*; got step=None"),
    ({"step": 2, "angle_step": 0.2}, ValueError, r"give exactly one of step"),
    ({"step": 0}, ValueError, r"step must be between 1 and frames - 1 = 59; got 0"),
    ({"step": 60}, ValueError, r"step must be between 1 and frames - 1 = 59; got 60"),
    ({"step": 2.0}, TypeError, r"step must be an integer number of frames; got 2.0 \(float\)"),
    ({"angle_step": 0.01}, ValueError, r"angle_step must be a number of radians in "
                                       r"\[min_angle, pi\) = \[0.08727, 3.142\); got 0.01"),
    ({"angle_step": "0.2"}, TypeError, r"angle_step must be a number of radians in "
                                       r"\[min_angle, pi\) = .*; got '0.2' \(str\)"),
    ({"step": 1, "min_angle": "0"}, TypeError, r"min_angle must be a number of radians"),
    ({"step": 1, "point": [np.nan, 0, 0]}, ValueError, r"point contains NaN values"),
    ({"step": 1, "point": [1.0, 2.0]}, ValueError, r"point must have shape \(\.\.\., 3\)"),
])
def test_helical_axes_bad_options(kwargs, error, message):
    R, t = knee_like_trial()
    with pytest.raises(error, match=message):
        helical_axes(R, t, **kwargs)


def test_helical_axes_bad_shapes():
    R, t = knee_like_trial()
    with pytest.raises(ValueError, match=r"t must have shape \(frames, 3\) with the frames "
                                         r"of R \(60\); got shape \(59, 3\)"):
        helical_axes(R, t[:-1], step=1)
    with pytest.raises(ValueError, match=r"at least 2 frames.*got 1"):
        helical_axes(R[:1], t[:1], step=1)


def test_step_with_point_and_missing_frames():
    R, t = knee_like_trial(20)
    R[7] = np.nan
    axes, frames = helical_axes(R, t, step=5, point=[30.0, 0, 0])
    missing = (frames == 7).any(axis=1)
    assert missing.sum() == 2 and np.isnan(axes.direction[missing]).all()
    # the point of the x axis through (0, 0, -50) nearest (30, 0, 0)
    np.testing.assert_allclose(axes.point[~missing], [[30.0, 0, -50]] * 13, atol=1e-9)
    np.testing.assert_allclose(np.degrees(axes.angle[~missing]), 10.0, atol=1e-9)


# --- issue 21: aliasing and the angle_step search -------------------------------------------

def test_angular_velocity_warns_when_a_frame_turns_too_far():
    R = rot_z(np.radians(150.0 * np.arange(6)))        # 262 rad/s at 100 Hz
    with pytest.warns(RuntimeWarning, match=r"5 of 5 frames \(pairs of consecutive frames\) "
                                            r"rotate by more than 30 degrees \(up to 150\).*"
                                            r"aliased"):
        omega = angular_velocity(R, 100)
    assert np.allclose(np.abs(omega[:, 2]), 50.0)        # the aliased value is still given


def test_angular_velocity_of_fast_but_sampled_motion_does_not_warn():
    import warnings
    R = rot_z(np.radians(29.0 * np.arange(6)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        angular_velocity(R, 100)


def _angle_step_brute_force(R, angle_step):
    """The original definition: from each start, the first later valid frame that has
    turned by angle_step (quadratic, for small trials)."""
    from bmc_functions import rotation_angle
    valid = np.flatnonzero(~np.isnan(R).any(axis=(1, 2)))
    pairs, i = [], valid[0]
    while True:
        later = valid[valid > i]
        reached = later[rotation_angle(R[later] @ R[i].T) >= angle_step]
        if not reached.size:
            return pairs
        pairs.append([i, reached[0]])
        i = reached[0]


@pytest.mark.parametrize("seed", range(5))
def test_angle_step_search_gives_the_pairs_of_the_definition(seed):
    rng = np.random.default_rng(seed)
    frames = int(rng.integers(50, 600))
    rotvec = np.cumsum(rng.normal(0, rng.uniform(0.01, 0.2), (frames, 3)), axis=0)
    R = Rotation.from_rotvec(rotvec).as_matrix()
    R[rng.random(frames) < 0.1] = np.nan
    R[0] = np.eye(3)
    step = rng.uniform(np.radians(5), 2.5)
    _, pairs = helical_axes(R, np.zeros((frames, 3)), angle_step=step)
    assert pairs.tolist() == _angle_step_brute_force(R, step)


def test_angle_step_is_linear_in_the_number_of_frames():
    import time
    R = rot_x(np.radians(np.arange(100_000) % 360.0))      # 16,666 axes
    start = time.process_time()
    _, pairs = helical_axes(R, np.zeros((len(R), 3)), angle_step=np.radians(5.5))
    assert len(pairs) == 16_666
    assert time.process_time() - start < 30                 # quadratic: many minutes


def test_consecutive_turns_match_scipys_angle_of_the_relative_rotation():
    """consecutive_turns (no product formed) against scipy's magnitude of R_{k+1} R_k^T,
    on random rotations, with a missing frame (NaN on both of its sides)."""
    R = Rotation.random(500, random_state=3).as_matrix()
    expected = (Rotation.from_matrix(R[1:]) * Rotation.from_matrix(R[:-1]).inv()).magnitude()
    R[7] = np.nan
    expected[6:8] = np.nan
    np.testing.assert_allclose(consecutive_turns(R), expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize("frames", [0, 1, 4095, 4096, 2 * 4096 + 5])
def test_matrix_rows_are_the_transposed_entries_across_its_blocks(frames):
    """matrix_rows copies in blocks of 4096 frames: every entry of every frame lands in
    its row (row-major entries), at the block edges too, NaN kept."""
    R = Rotation.random(frames, random_state=7).as_matrix() if frames else np.empty((0, 3, 3))
    if frames > 3:
        R[[0, frames // 2, -1]] = np.nan
    rows = matrix_rows(R)
    assert rows.shape == (9, frames) and rows.flags["C_CONTIGUOUS"]
    assert not np.shares_memory(rows, R)            # callers write NaN into it
    for i in range(3):
        for j in range(3):
            assert np.array_equal(rows[3 * i + j], R[:, i, j], equal_nan=True)


@pytest.mark.parametrize("frame", ["lab", "local"])
def test_angular_velocity_across_its_blocks_of_frames(frame, monkeypatch):
    """The differences and products run a block of frames at a time
    (motion._OMEGA_BLOCK): with gaps at, next to and away from the blocks' edges, every
    frame has the per-frame formula (central differences, one-sided at the ends and gap
    edges, the skew part of R_dot R^T or R^T R_dot), and bit for bit the numbers of the
    whole trial in one block."""
    from bmc_functions.rigid_body import motion
    block = motion._OMEGA_BLOCK
    frames, rate = 2 * block + 9, 100.0
    R = Rotation.from_rotvec(np.cumsum(np.random.default_rng(3).normal(0, 0.05, (frames, 3)),
                                       axis=0)).as_matrix()
    R[[block - 1, block + 1, block + 2, 2 * block, 2 * block + 3, frames - 1]] = np.nan
    omega = angular_velocity(R, rate, frame=frame)
    seen = ~np.isnan(R).any(axis=(1, 2))
    expected = np.full((frames, 3), np.nan)
    for k in np.flatnonzero(seen):
        before, after = k > 0 and seen[k - 1], k < frames - 1 and seen[k + 1]
        if before and after:
            R_dot = (R[k + 1] - R[k - 1]) * rate / 2
        elif after or before:
            R_dot = (R[k + 1] - R[k]) * rate if after else (R[k] - R[k - 1]) * rate
        else:
            continue
        W = R_dot @ R[k].T if frame == "lab" else R[k].T @ R_dot
        expected[k] = 0.5 * np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]])
    np.testing.assert_allclose(omega, expected, rtol=0, atol=1e-12)
    assert np.array_equal(np.isnan(omega), np.isnan(expected))
    monkeypatch.setattr(motion, "_OMEGA_BLOCK", 10 * frames)           # one block
    assert np.array_equal(angular_velocity(R, rate, frame=frame), omega, equal_nan=True)


def test_consecutive_turns_across_its_blocks_of_frames(monkeypatch):
    """consecutive_turns runs a block of pairs of frames at a time: every pair, at the
    blocks' edges too, turns by rotation_angle(R[k+1] R[k]^T) (NaN next to a gap), and
    bit for bit by the numbers of the whole trial in one block."""
    from bmc_functions import rotation_angle
    from bmc_functions.rigid_body import motion
    block = motion._OMEGA_BLOCK
    frames = 2 * block + 3
    R = Rotation.from_rotvec(np.cumsum(np.random.default_rng(4).normal(0, 0.3, (frames, 3)),
                                       axis=0)).as_matrix()
    R[[block - 1, 2 * block + 1]] = np.nan
    turn = consecutive_turns(R)
    expected = rotation_angle(R[1:] @ np.swapaxes(R[:-1], 1, 2))
    assert turn.shape == (frames - 1,)
    np.testing.assert_allclose(turn, expected, rtol=0, atol=1e-12)
    assert np.array_equal(np.isnan(turn), np.isnan(expected))
    monkeypatch.setattr(motion, "_OMEGA_BLOCK", 10 * frames)           # one block
    assert np.array_equal(consecutive_turns(R), turn, equal_nan=True)


def test_float32_rotations_keep_their_type_in_the_blocks():
    """consecutive_turns and the unchecked angular velocity compute float32 rotations in
    float32, as numpy's arithmetic on them does (the blocks' work arrays take the
    rotations' type): the numbers of the whole trial in one block, float32."""
    from bmc_functions.rigid_body import motion
    frames = motion._OMEGA_BLOCK + 2
    R = Rotation.from_rotvec(np.cumsum(np.random.default_rng(6).normal(0, 0.1, (frames, 3)),
                                       axis=0)).as_matrix().astype(np.float32)
    turn = consecutive_turns(R)
    omega = motion.unchecked_angular_velocity(matrix_rows(R), 100.0)
    assert turn.dtype == omega.dtype == np.float32
    np.testing.assert_allclose(turn, consecutive_turns(R.astype(float)), rtol=0, atol=1e-5)
    np.testing.assert_allclose(omega, angular_velocity(R.astype(float), 100.0), rtol=0,
                               atol=1e-3)
