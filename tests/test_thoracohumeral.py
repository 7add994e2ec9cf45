"""The ISB's thoracohumeral angles read from Plug-in Gait's thorax and humerus (issue 34).

Oracles: arms placed by hand (each frame's columns written from where the arm points),
scipy's ``Rotation.from_euler("YXY")`` composing the angles back into the matrix, the angle
between the long axes, a trial mirrored in the lab and rebuilt by the package's own frame
functions (for the left side), and the numbers notebook 16 printed before the function
existed (for the shipped trials).
"""

import importlib.util
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bmc_functions import plug_in_gait, read_c3d, rot_z
from bmc_functions.examples import example_file
from bmc_functions.models.plug_in_gait import thoracohumeral_angles
from bmc_functions.models.plug_in_gait.upper_body import (
    ISB_HUMERUS_AXES, ISB_THORAX_AXES, THORACOHUMERAL_ANGLES, cgm_humerus_frame,
    cgm_thorax_frame)

#: Plug-in Gait's humerus (columns x, y, z in the thorax's axes x forward, y left, z up):
#: x points away from the forearm, z from the elbow to the shoulder, y = z x x.
AT_SIDE = np.column_stack([[-1.0, 0, 0], [0, -1, 0], [0, 0, 1]])        # forearm forward
ABDUCTED = np.column_stack([[-1.0, 0, 0], [0, 0, 1], [0, 1, 0]])        # right arm, 90 deg
ABDUCTED_FOREARM_DOWN = np.column_stack([[0.0, 0, 1], [1, 0, 0], [0, 1, 0]])
FLEXED = np.column_stack([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]])          # forearm down
SAGITTAL_MIRROR = np.diag([1.0, -1.0, 1.0])


def random_rotations(rng, n):
    return Rotation.random(n, random_state=rng).as_matrix()


def test_hand_built_frames_are_rotations():
    for R in (AT_SIDE, ABDUCTED, ABDUCTED_FOREARM_DOWN, FLEXED, ISB_THORAX_AXES,
              ISB_HUMERUS_AXES):
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-15)
        assert np.linalg.det(R) == pytest.approx(1.0)


@pytest.mark.parametrize("turn", [-60.0, 0.0, 35.0])
def test_arm_at_the_side_has_zero_elevation_and_only_a_defined_sum(turn):
    # turned about the trunk's vertical axis: the plane of elevation and the axial rotation
    # are not defined apart at the lock (b = 0), only their sum, which is the turn; the
    # axial rotation is set to 0 there and the lock reported once
    humerus = rot_z(np.radians(turn)) @ AT_SIDE
    with pytest.warns(RuntimeWarning, match="1 of 1 frames are in gimbal lock"):
        plane, elevation, axial = thoracohumeral_angles(np.eye(3), humerus, "right")
    assert elevation == pytest.approx(0.0, abs=1e-6)
    assert axial == 0.0
    assert plane == pytest.approx(turn, abs=1e-6)


def test_arm_abducted_in_the_frontal_plane():
    plane, elevation, axial = thoracohumeral_angles(np.eye(3), ABDUCTED, "right")
    assert (plane, elevation, axial) == pytest.approx((0.0, -90.0, 0.0), abs=1e-9)


def test_arm_flexed_forward_has_a_plane_of_elevation_of_90():
    plane, elevation, axial = thoracohumeral_angles(np.eye(3), FLEXED, "right")
    assert (plane, elevation, axial) == pytest.approx((90.0, -90.0, 90.0), abs=1e-9)


def test_internal_rotation_is_positive():
    # the abducted arm with the forearm turned from forward to down: internal rotation,
    # positive in Wu et al. (2005)
    plane, elevation, axial = thoracohumeral_angles(np.eye(3), ABDUCTED_FOREARM_DOWN,
                                                    "right")
    assert (plane, elevation, axial) == pytest.approx((0.0, -90.0, 90.0), abs=1e-9)


def test_angles_compose_back_to_the_humerus_in_the_thorax():
    rng = np.random.default_rng(34)
    R_t, R_h = random_rotations(rng, 200), random_rotations(rng, 200)
    angles = thoracohumeral_angles(R_t, R_h, "right")
    composed = Rotation.from_euler("YXY", angles, degrees=True).as_matrix()
    relative = ISB_THORAX_AXES.T @ np.swapaxes(R_t, 1, 2) @ R_h @ ISB_HUMERUS_AXES
    np.testing.assert_allclose(composed, relative, atol=1e-9)
    assert np.all((angles[:, 1] <= 0) & (angles[:, 1] >= -180))
    assert np.all((angles[:, [0, 2]] >= -180) & (angles[:, [0, 2]] < 180))


def test_elevation_is_minus_the_angle_between_the_long_axes():
    rng = np.random.default_rng(5)
    R_t, R_h = random_rotations(rng, 100), random_rotations(rng, 100)
    between = np.degrees(np.arccos(np.clip(np.sum(R_t[:, :, 2] * R_h[:, :, 2], axis=1),
                                           -1, 1)))
    for side in ("right", "left"):
        elevation = thoracohumeral_angles(R_t, R_h, side)[:, 1]
        np.testing.assert_allclose(elevation, -between, atol=1e-6)


def test_left_arm_that_mirrors_a_right_arm_has_its_angles():
    # mirror the lab (y -> -y): a frame's x and z are mirrored, its y = z x x flips again
    rng = np.random.default_rng(11)
    R_t, R_h = random_rotations(rng, 50), random_rotations(rng, 50)
    mirrored_t = SAGITTAL_MIRROR @ R_t @ SAGITTAL_MIRROR
    mirrored_h = SAGITTAL_MIRROR @ R_h @ SAGITTAL_MIRROR
    np.testing.assert_allclose(thoracohumeral_angles(mirrored_t, mirrored_h, "left"),
                               thoracohumeral_angles(R_t, R_h, "right"), atol=1e-9)


def test_left_arm_abducted_and_flexed():
    # the right arm's hand-built frames mirrored onto the left side
    for right, expected in [(ABDUCTED, (0.0, -90.0, 0.0)), (FLEXED, (90.0, -90.0, 90.0))]:
        left = SAGITTAL_MIRROR @ right @ SAGITTAL_MIRROR
        assert tuple(thoracohumeral_angles(np.eye(3), left, "left")) == pytest.approx(
            expected, abs=1e-9)


def test_missing_frames_are_nan_and_others_kept():
    rng = np.random.default_rng(2)
    R_t, R_h = random_rotations(rng, 4), random_rotations(rng, 4)
    expected = thoracohumeral_angles(R_t, R_h, "right")
    R_h[1] = np.nan
    R_t[3, 0, 0] = np.nan
    angles = thoracohumeral_angles(R_t, R_h, "right")
    assert np.isnan(angles[[1, 3]]).all()
    np.testing.assert_allclose(angles[[0, 2]], expected[[0, 2]])


def test_bad_inputs_are_refused_naming_the_argument():
    with pytest.raises(ValueError, match="side must be 'right' or 'left'; got 'up'"):
        thoracohumeral_angles(np.eye(3), np.eye(3), "up")
    with pytest.raises(ValueError, match=r"R_humerus must have shape \(\.\.\., 3, 3\)"):
        thoracohumeral_angles(np.eye(3), np.eye(3)[:2], "right")
    with pytest.raises(ValueError, match="R_thorax is not a rotation matrix"):
        thoracohumeral_angles(np.diag([1.0, 1, -1]), np.eye(3), "right")


# --- the shipped trials --------------------------------------------------------------

STATIC = example_file("plug_in_gait/Static_trial.c3d")
STAIRS = example_file("plug_in_gait/Movement_trial.c3d")


@pytest.fixture(scope="module")
def model():
    if importlib.util.find_spec("ezc3d") is None:
        pytest.skip("ezc3d absent")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return plug_in_gait(STATIC, example_file("plug_in_gait/Test.vsk"))


def quiet(call, *args):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return call(*args)


@pytest.mark.parametrize("trial, summary", [
    # notebook 16, section 6, as stored before the package had the function: the right
    # arm's mean, min and max of plane of elevation, elevation, axial rotation (deg)
    (STATIC, [[-15.2, -79.8, 7.6], [-15.6, -80.2, 7.0], [-14.7, -79.2, 8.0]]),
    (STAIRS, [[-45.0, -30.2, 48.0], [-53.8, -34.0, 36.2], [-27.4, -25.7, 55.9]])])
def test_shipped_trials_give_notebook_16s_numbers(model, trial, summary):
    table = quiet(model.thoracohumeral_angles, trial)
    right = table["right"][list(THORACOHUMERAL_ANGLES)]
    got = right.agg(["mean", "min", "max"]).round(1).to_numpy()
    np.testing.assert_array_equal(got, np.array(summary))


def test_table_is_indexed_like_the_angles(model):
    table = quiet(model.thoracohumeral_angles, STAIRS)
    angles = quiet(model.angles, STAIRS)
    assert table.index.equals(angles.index)
    assert list(table.columns) == [(side, name) for side in ("right", "left")
                                   for name in THORACOHUMERAL_ANGLES]
    assert table.columns.names == ["side", "angle"]
    assert table.attrs["rate"] == angles.attrs["rate"]
    assert not table.isna().any().any()


def test_left_side_of_the_trial_equals_the_mirrored_trial_rebuilt(model):
    # mirror the markers and joint centres in the lab, rebuild the thorax and the (now
    # right) humerus with the package's frame functions, read them as a right arm
    markers = read_c3d(STAIRS)
    track = quiet(model.track, STAIRS)
    mirror = np.array([1.0, -1.0, 1.0])
    thorax, _ = cgm_thorax_frame(*(markers[m].to_numpy() * mirror
                                   for m in ("CLAV", "C7", "STRN", "T10")), 7.0)
    humerus = cgm_humerus_frame(*(track.centres[name].to_numpy() * mirror
                                  for name in ("LSJC", "LEJC", "LWJC")))
    expected = thoracohumeral_angles(thorax, humerus, "right")
    table = quiet(model.thoracohumeral_angles, STAIRS)
    np.testing.assert_allclose(table["left"].to_numpy(), expected, atol=1e-9)
    # and the left arm is not the right one
    assert np.abs(table["left"].to_numpy() - table["right"].to_numpy()).max() > 5


def test_a_trial_without_a_thorax_is_refused(model):
    markers = read_c3d(STAIRS).drop(columns="C7", level=0)
    with pytest.raises(ValueError, match="thoracohumeral angles need the thorax markers.*"
                                         "the trial has no thorax"):
        quiet(model.thoracohumeral_angles, markers)
