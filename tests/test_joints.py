"""Tests of bmc_functions.models.joints.knee_angles: scipy as the oracle for the Cardan sequence,
hand-built shank orientations for the clinical signs, Grood & Suntay's axes."""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from bmc_functions import knee_angles

MIRROR = np.diag([1.0, 1.0, -1.0])   # reflection across the sagittal plane: right <-> left


def frame(x, y):
    """Rotation matrix with columns x, y, z = x cross y (x, y orthonormal)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    return np.column_stack([x, y, np.cross(x, y)])


def c(deg):
    return np.cos(np.deg2rad(deg))


def s(deg):
    return np.sin(np.deg2rad(deg))


# --- scipy as the oracle: R_shank = R_thigh Rz(-flexion) Rx(adduction) Ry(internal) ------
@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_recovers_angles_composed_with_scipy(seed):
    rng = np.random.default_rng(seed)
    n = 30
    truth = np.column_stack([rng.uniform(-20, 150, n), rng.uniform(-30, 30, n),
                             rng.uniform(-60, 60, n)])
    R_thigh = Rotation.random(n, random_state=rng).as_matrix()
    # scipy's upper-case 'ZXY' is intrinsic: Rz @ Rx @ Ry.
    R_knee = Rotation.from_euler("ZXY", truth * [-1, 1, 1], degrees=True).as_matrix()
    found = knee_angles(R_thigh, R_thigh @ R_knee, degrees=True)
    np.testing.assert_allclose(found, truth, atol=1e-7)
    np.testing.assert_allclose(knee_angles(R_thigh, R_thigh @ R_knee),
                               np.deg2rad(truth), atol=1e-9)


# --- clinical signs from hand-built shank orientations (thigh = lab frame) -----------------
def test_flexion_is_positive_when_the_ankle_goes_backwards():
    # 30 degrees of flexion: the shank's long axis (ankle -> knee) leans forwards at the top,
    # i.e. the ankle is behind the knee.
    y = [s(30), c(30), 0]
    R_shank = frame([c(30), -s(30), 0], y)
    np.testing.assert_allclose(knee_angles(np.eye(3), R_shank, degrees=True), [30, 0, 0],
                               atol=1e-12)


def test_adduction_is_positive_when_the_right_ankle_goes_medially():
    # Right knee, 10 degrees of varus: the ankle is to the left (medial) of the knee, so the
    # ankle -> knee axis points to the right (+z).
    R_shank = frame([1, 0, 0], [0, c(10), s(10)])
    np.testing.assert_allclose(knee_angles(np.eye(3), R_shank, degrees=True), [0, 10, 0],
                               atol=1e-12)


def test_internal_rotation_is_positive_when_the_right_shank_faces_medially():
    # The shank's anterior axis turned 20 degrees towards the left (-z, medial on the right).
    R_shank = frame([c(20), 0, -s(20)], [0, 1, 0])
    np.testing.assert_allclose(knee_angles(np.eye(3), R_shank, degrees=True), [0, 0, 20],
                               atol=1e-12)


def test_left_knee_mirror_image_reads_the_same():
    rng = np.random.default_rng(7)
    truth = np.column_stack([rng.uniform(0, 90, 10), rng.uniform(-10, 10, 10),
                             rng.uniform(-20, 20, 10)])
    R_thigh = Rotation.random(10, random_state=rng).as_matrix()
    R_shank = R_thigh @ Rotation.from_euler("ZXY", truth * [-1, 1, 1],
                                            degrees=True).as_matrix()
    # Mirroring a right leg across the sagittal plane gives a left leg whose ISB frames are
    # M R M (z still to the right); its clinical angles are the same.
    left = knee_angles(MIRROR @ R_thigh @ MIRROR, MIRROR @ R_shank @ MIRROR, "left",
                       degrees=True)
    np.testing.assert_allclose(left, truth, atol=1e-7)
    # Read as a right knee, the mirror image has adduction and rotation reversed.
    as_right = knee_angles(MIRROR @ R_thigh @ MIRROR, MIRROR @ R_shank @ MIRROR,
                           degrees=True)
    np.testing.assert_allclose(as_right, truth * [1, -1, -1], atol=1e-7)


# --- equivalence with Grood & Suntay's joint coordinate system ----------------------------
def test_axes_are_those_of_the_joint_coordinate_system():
    rng = np.random.default_rng(11)
    truth = np.array([40.0, 8.0, -15.0])
    R_thigh = Rotation.random(random_state=rng).as_matrix()
    R_shank = R_thigh @ Rotation.from_euler("ZXY", truth * [-1, 1, 1],
                                            degrees=True).as_matrix()
    flexion, adduction, rotation = knee_angles(R_thigh, R_shank, degrees=True)
    e1 = R_thigh[:, 2]                          # femoral medio-lateral (flexion) axis
    e3 = R_shank[:, 1]                          # tibial long (rotation) axis
    e2 = np.cross(e3, e1) / np.linalg.norm(np.cross(e3, e1))  # floating axis
    # Grood & Suntay: adduction from the angle between e1 and e3 (90 deg at zero)
    assert np.rad2deg(np.arcsin(e1 @ e3)) == pytest.approx(adduction)
    # flexion: angle from the femoral anterior axis to e2, about e1 (extension positive)
    x_thigh = R_thigh[:, 0]
    alpha = np.arctan2(np.cross(x_thigh, e2) @ e1, x_thigh @ e2)
    assert -np.rad2deg(alpha) == pytest.approx(flexion)
    # rotation: angle from e2 to the tibial anterior axis, about e3
    assert np.rad2deg(np.arctan2(np.cross(e2, R_shank[:, 0]) @ e3,
                                 e2 @ R_shank[:, 0])) == pytest.approx(rotation)


# --- missing data and warnings -------------------------------------------------------------
def test_nan_frame_gives_nan_angles_only_there():
    R_shank = Rotation.from_euler("ZXY", [[-30, 2, 5]] * 3, degrees=True).as_matrix()
    R_shank[1] = np.nan
    angles = knee_angles(np.eye(3)[None].repeat(3, 0), R_shank, degrees=True)
    assert np.isnan(angles[1]).all()
    np.testing.assert_allclose(angles[[0, 2]], [[30, 2, 5], [30, 2, 5]], atol=1e-9)


def test_gimbal_lock_warns_once():
    R_shank = np.stack([Rotation.from_euler("ZXY", [0, 90, 0], degrees=True).as_matrix()] * 4)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        knee_angles(np.eye(3)[None].repeat(4, 0), R_shank)
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1 and "4 of 4 frames" in messages[0]


# --- bad input -----------------------------------------------------------------------------
def test_wrong_side():
    with pytest.raises(ValueError, match="side must be 'right' or 'left'; got 'both'"):
        knee_angles(np.eye(3), np.eye(3), "both")


def test_wrong_shape_names_the_argument():
    with pytest.raises(ValueError, match=r"R_shank must have shape \(\.\.\., 3, 3\)"):
        knee_angles(np.eye(3), np.eye(2))


def test_not_a_rotation_matrix():
    with pytest.raises(ValueError, match="R_thigh is not a rotation matrix"):
        knee_angles(np.eye(3) * 2, np.eye(3))


def test_reflection():
    with pytest.raises(ValueError, match=r"R_shank is not a rotation matrix: det\(R\) = -1"):
        knee_angles(np.eye(3), MIRROR)


def test_shapes_that_do_not_match():
    with pytest.raises(ValueError, match="R_thigh and R_shank must have the same shape"):
        knee_angles(np.eye(3)[None].repeat(3, 0), np.eye(3)[None].repeat(2, 0))


# --- hip, ankle and pelvis angles: scipy as the oracle ----------------------------------------
from bmc_functions import ankle_angles, hip_angles, pelvis_angles  # noqa: E402


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_hip_and_ankle_recover_angles_composed_with_scipy(seed):
    rng = np.random.default_rng(seed)
    n = 20
    truth = np.column_stack([rng.uniform(-60, 60, n), rng.uniform(-30, 30, n),
                             rng.uniform(-45, 45, n)])
    R_prox = Rotation.random(n, random_state=rng).as_matrix()
    R_rel = Rotation.from_euler("ZXY", truth, degrees=True).as_matrix()
    for function in (hip_angles, ankle_angles):
        np.testing.assert_allclose(function(R_prox, R_prox @ R_rel, degrees=True), truth,
                                   atol=1e-7)
        # the mirror image on the left side reads the same
        left = MIRROR @ (R_prox @ R_rel) @ MIRROR
        np.testing.assert_allclose(function(MIRROR @ R_prox @ MIRROR, left, "left",
                                            degrees=True), truth, atol=1e-7)


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_pelvis_angles_are_baker_yxz_with_clinical_signs(seed):
    rng = np.random.default_rng(seed)
    n = 20
    rotation, obliquity, about_z = (rng.uniform(-40, 40, n), rng.uniform(-20, 20, n),
                                    rng.uniform(-40, 40, n))
    R = Rotation.from_euler("YXZ", np.column_stack([rotation, obliquity, about_z]),
                            degrees=True).as_matrix()
    right = pelvis_angles(R, degrees=True)
    left = pelvis_angles(R, "left", degrees=True)
    np.testing.assert_allclose(right, np.column_stack([-about_z, -obliquity, rotation]),
                               atol=1e-7)
    np.testing.assert_allclose(left, right * [1, -1, -1], atol=1e-7)
    # relative to a lab whose axes are turned: the same pelvis in that lab's frame
    R_lab = Rotation.random(random_state=rng).as_matrix()
    np.testing.assert_allclose(pelvis_angles(R_lab @ R, R_lab=R_lab, degrees=True), right,
                               atol=1e-7)


def test_clinical_signs_of_hip_ankle_and_pelvis_by_hand():
    # hip: the knee moves forwards (thigh's long axis tilts back at the top) -> flexion
    R_thigh = frame([c(20), s(20), 0], [-s(20), c(20), 0])
    np.testing.assert_allclose(hip_angles(np.eye(3), R_thigh, degrees=True), [20, 0, 0],
                               atol=1e-12)
    # ankle: toes up (foot's x tilts up) -> dorsiflexion; sole facing medially (right foot's
    # y tilts to +z, lateral) -> inversion
    R_foot = frame([c(10), s(10), 0], [-s(10), c(10), 0])
    np.testing.assert_allclose(ankle_angles(np.eye(3), R_foot, degrees=True), [10, 0, 0],
                               atol=1e-12)
    R_foot = frame([1, 0, 0], [0, c(8), s(8)])
    np.testing.assert_allclose(ankle_angles(np.eye(3), R_foot, degrees=True), [0, 8, 0],
                               atol=1e-12)
    # pelvis: anterior axis pointing down -> anterior tilt; right side down -> the right
    # side's obliquity negative, the left side's positive
    R = frame([c(10), -s(10), 0], [s(10), c(10), 0])
    np.testing.assert_allclose(pelvis_angles(R, degrees=True), [10, 0, 0], atol=1e-12)
    R = frame([1, 0, 0], [0, c(5), s(5)])                  # y tilts right: right side down
    np.testing.assert_allclose(pelvis_angles(R, degrees=True), [0, -5, 0], atol=1e-12)
    np.testing.assert_allclose(pelvis_angles(R, "left", degrees=True), [0, 5, 0],
                               atol=1e-12)


def test_new_joint_functions_reject_bad_input():
    with pytest.raises(ValueError, match="side must be 'right' or 'left'; got 'both'"):
        hip_angles(np.eye(3), np.eye(3), "both")
    with pytest.raises(ValueError, match=r"R_pelvis and R_thigh must have the same shape"):
        hip_angles(np.eye(3), np.stack([np.eye(3)] * 2))
    with pytest.raises(ValueError, match=r"R_foot must have shape \(\.\.\., 3, 3\)"):
        ankle_angles(np.eye(3), np.eye(2))
    with pytest.raises(ValueError, match=r"R_lab must have shape \(3, 3\)"):
        pelvis_angles(np.eye(3), R_lab=np.stack([np.eye(3)] * 2))
    with pytest.raises(ValueError, match="side must be 'right' or 'left'"):
        pelvis_angles(np.eye(3), "up")
