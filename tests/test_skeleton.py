"""Tests of bmc_functions.models.skeleton: T-pose skeleton, pose_to_angles, angles_to_pose.

Oracles: poses built here by an independent forward-kinematics chain from rotations made
with scipy (limb rotations twist-free, i.e. rotation vectors perpendicular to the bone,
so that they are recoverable), SciPy's intrinsic 'ZXY' Euler angles, and hand-derived
single-joint poses.
"""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.spatial.transform import Rotation

from bmc_functions import PoseAngles, Skeleton, angles_to_pose, pose_to_angles, rot_y
from bmc_functions.models.skeleton import JOINTS, KEYPOINTS, PARENTS, ROTATING_JOINTS

LIMB_BONES = [("lefthip", "leftknee"), ("leftknee", "leftfoot"),
              ("righthip", "rightknee"), ("rightknee", "rightfoot"),
              ("leftshoulder", "leftelbow"), ("leftelbow", "leftwrist"),
              ("rightshoulder", "rightelbow"), ("rightelbow", "rightwrist")]


def unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def chain(offsets, root_position, root_rotation, rotations):
    """Independent forward kinematics, each joint written out (see the Skeleton Notes)."""
    j, R, R0 = offsets, rotations, root_rotation
    mv = lambda W, v: np.einsum("fij,j->fi", W, v)  # noqa: E731
    p = {"hips": root_position}
    p["lefthip"] = p["hips"] + mv(R0, j["lefthip"])
    p["righthip"] = p["hips"] + mv(R0, j["righthip"])
    W_trunk = R0 @ R["hips"]
    p["neck"] = p["hips"] + mv(W_trunk, j["neck"])
    for side in ("left", "right"):
        W_hip = R0 @ R[side + "hip"]
        p[side + "knee"] = p[side + "hip"] + mv(W_hip, j[side + "knee"])
        p[side + "foot"] = p[side + "knee"] + mv(W_hip @ R[side + "knee"], j[side + "foot"])
        W_neck = W_trunk @ R["neck"]
        p[side + "shoulder"] = p["neck"] + mv(W_neck, j[side + "shoulder"])
        W_sh = W_neck @ R[side + "shoulder"]
        p[side + "elbow"] = p[side + "shoulder"] + mv(W_sh, j[side + "elbow"])
        p[side + "wrist"] = p[side + "elbow"] + mv(W_sh @ R[side + "elbow"], j[side + "wrist"])
    return p


def swing(rng, bone_axis, frames, max_angle=np.deg2rad(170)):
    """Random twist-free rotations: rotation vectors perpendicular to the bone axis."""
    v = rng.normal(size=(frames, 3))
    v[:, bone_axis] = 0.0
    angle = rng.uniform(0, max_angle, size=(frames, 1))
    return Rotation.from_rotvec(unit(v) * angle).as_matrix()


def recoverable_pose(seed, frames=6):
    """A random pose whose rotations pose_to_angles can recover exactly, and its truth."""
    rng = np.random.default_rng(seed)
    sk = Skeleton.default({"thigh": rng.uniform(0.3, 0.5), "forearm": rng.uniform(0.2, 0.3)})
    R = {"hips": Rotation.from_euler("Z", rng.uniform(-1.2, 1.2, (frames, 1))).as_matrix(),
         "neck": Rotation.from_euler("YZ", np.column_stack(
             [rng.uniform(-3, 3, frames), rng.uniform(-1.3, 1.3, frames)])).as_matrix()}
    for joint in ("lefthip", "leftknee", "righthip", "rightknee"):
        R[joint] = swing(rng, 1, frames)       # leg offsets along y
    for joint in ("leftshoulder", "leftelbow", "rightshoulder", "rightelbow"):
        R[joint] = swing(rng, 0, frames)       # arm offsets along x
    R0 = Rotation.random(frames, random_state=rng.integers(2**31)).as_matrix()
    L = rng.normal(size=(frames, 3))
    return sk, chain(sk.offsets, L, R0, R), R0, R


def wrapped(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def tpose(sk=None):
    return (sk or Skeleton.default()).tpose()


def limb_pose(frames=3):
    pose = tpose()
    return {k: np.repeat(pose[k], frames, axis=0) for k in KEYPOINTS}


# --------------------------------------------------------------------------- recovery


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_recovers_twist_free_rotations_and_scipy_angles(seed):
    sk, pose, R0, R = recoverable_pose(seed)
    result = pose_to_angles({k: pose[k] for k in KEYPOINTS}, sk)
    np.testing.assert_allclose(result.root_rotation, R0, atol=1e-9)
    np.testing.assert_allclose(result.root_position, pose["hips"], atol=1e-12)
    for joint in ROTATING_JOINTS:
        np.testing.assert_allclose(result.rotations[joint], R[joint], atol=1e-9,
                                   err_msg=joint)
        expected = Rotation.from_matrix(R[joint]).as_euler("ZXY")  # intrinsic in SciPy
        ok = np.abs(np.cos(expected[:, 1])) > 1e-3                 # away from gimbal lock
        np.testing.assert_allclose(wrapped(result.angles[joint] - expected)[ok], 0,
                                   atol=1e-7, err_msg=joint)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_round_trip_reproduces_every_bone_direction_on_any_pose(seed):
    rng = np.random.default_rng(seed)
    P = {k: rng.normal(size=(5, 3)) for k in KEYPOINTS}
    sk = Skeleton.from_positions(P)
    Q = angles_to_pose(pose_to_angles(P, sk), sk)
    P["hips"] = 0.5 * (P["lefthip"] + P["righthip"])
    P["neck"] = 0.5 * (P["leftshoulder"] + P["rightshoulder"])
    for joint in JOINTS[1:]:  # limbs, and also the hip line, trunk and shoulder line
        parent = PARENTS[joint]
        np.testing.assert_allclose(unit(Q[joint] - Q[parent]), unit(P[joint] - P[parent]),
                                   atol=1e-9, err_msg=f"{parent}->{joint}")
    np.testing.assert_allclose(Q["hips"], P["hips"], atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_retargeting_keeps_directions_and_uses_the_skeleton_lengths(seed):
    rng = np.random.default_rng(seed)
    P = {k: rng.normal(size=(4, 3)) for k in KEYPOINTS}
    target = Skeleton.default({"thigh": 0.55, "upperarm": 0.2})
    Q = angles_to_pose(pose_to_angles(P, Skeleton.from_positions(P)), target)
    for parent, child in LIMB_BONES:
        np.testing.assert_allclose(unit(Q[child] - Q[parent]), unit(P[child] - P[parent]),
                                   atol=1e-9)
        np.testing.assert_allclose(np.linalg.norm(Q[child] - Q[parent], axis=-1),
                                   np.linalg.norm(target.offsets[child]), rtol=1e-12)


def test_given_hips_and_neck_off_the_mid_points_keep_every_limb_direction():
    # hips and neck given explicitly, not mid-points: the limb bones and the trunk are
    # still exact; the right hip and right shoulder lines cannot be (the skeleton's hip
    # and shoulder lines are straight), as the module docstring says.
    rng = np.random.default_rng(2)
    P = {k: rng.normal(size=(4, 3)) for k in KEYPOINTS + ("hips", "neck")}
    sk = Skeleton.from_positions(P)
    Q = angles_to_pose(pose_to_angles(P, sk), sk)
    for parent, child in LIMB_BONES + [("hips", "neck"), ("hips", "lefthip"),
                                       ("neck", "leftshoulder")]:
        np.testing.assert_allclose(unit(Q[child] - Q[parent]), unit(P[child] - P[parent]),
                                   atol=1e-9, err_msg=f"{parent}->{child}")
    np.testing.assert_allclose(unit(Q["righthip"] - Q["hips"]),
                               -unit(P["lefthip"] - P["hips"]), atol=1e-12)


def test_true_positions_on_the_true_skeleton_are_reproduced_exactly():
    sk, pose, _, _ = recoverable_pose(7)
    Q = angles_to_pose(pose_to_angles({k: pose[k] for k in KEYPOINTS}, sk), sk)
    for joint in JOINTS:
        np.testing.assert_allclose(Q[joint], pose[joint], atol=1e-12, err_msg=joint)


def test_angles_alone_give_the_same_pose_as_rotations():
    sk, pose, _, _ = recoverable_pose(3)
    result = pose_to_angles({k: pose[k] for k in KEYPOINTS}, sk)
    from_angles = PoseAngles(result.root_position, result.root_rotation, rotations=None,
                             angles=result.angles, sequence=result.sequence)
    Q1, Q2 = angles_to_pose(result, sk), angles_to_pose(from_angles, sk)
    for joint in JOINTS:
        np.testing.assert_allclose(Q2[joint], Q1[joint], atol=1e-12)


def test_other_sequence_angles_match_scipy():
    sk, pose, _, R = recoverable_pose(11)
    result = pose_to_angles({k: pose[k] for k in KEYPOINTS}, sk, sequence="xyz")
    assert result.sequence == "XYZ"
    expected = Rotation.from_matrix(R["leftknee"]).as_euler("XYZ")
    np.testing.assert_allclose(wrapped(result.angles["leftknee"] - expected), 0, atol=1e-9)


# ----------------------------------------------------------- frames and hand-derived


def test_root_frame_is_orthonormal_with_x_on_the_hip_line():
    # A trunk leaning 30 degrees towards the left hip: not perpendicular to the hip line.
    # The seed's frame [u, t, u x t] would have u . t = sin(30 deg) = 0.5.
    pose = limb_pose(1)
    lean = np.array([np.sin(np.pi / 6), np.cos(np.pi / 6), 0.0])
    for k in ("leftshoulder", "leftelbow", "leftwrist", "rightshoulder", "rightelbow",
              "rightwrist"):
        pose[k] = pose[k] + (0.5 * lean - [0, 0.5, 0])
    R = pose_to_angles(pose, Skeleton.default()).root_rotation[0]
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert np.isclose(np.linalg.det(R), 1.0)
    np.testing.assert_allclose(R[:, 0], [1, 0, 0], atol=1e-12)  # hip line is exact
    # the lean is taken by the trunk rotation: 30 degrees about z, towards +x (negative)
    Rh = pose_to_angles(pose, Skeleton.default()).angles["hips"][0]
    np.testing.assert_allclose(Rh, [-np.pi / 6, 0, 0], atol=1e-12)


def test_tpose_gives_identity_rotations_and_zero_angles():
    result = pose_to_angles(tpose(), Skeleton.default())
    np.testing.assert_allclose(result.root_rotation[0], np.eye(3), atol=1e-15)
    for joint in ROTATING_JOINTS:
        np.testing.assert_allclose(result.rotations[joint][0], np.eye(3), atol=1e-15)
        np.testing.assert_allclose(result.angles[joint][0], 0, atol=1e-15)


def test_tpose_positions_by_hand():
    p = Skeleton.default().tpose(root_position=(1, 2, 3))
    np.testing.assert_allclose(p["leftfoot"][0], [1.1, 2 - 0.84, 3])
    np.testing.assert_allclose(p["rightwrist"][0], [1 - 0.74, 2.5, 3])


def test_elbow_flexion_forward_is_a_negative_rotation_about_y():
    # Forearm from +x to (cos a, 0, sin a): the axis x cross (cos a, 0, sin a) is -y.
    a = np.deg2rad(40)
    pose = tpose()
    pose["leftwrist"] = pose["leftelbow"] + 0.26 * np.array([[np.cos(a), 0, np.sin(a)]])
    result = pose_to_angles(pose, Skeleton.default())
    np.testing.assert_allclose(result.rotations["leftelbow"][0], rot_y(-a), atol=1e-12)
    np.testing.assert_allclose(result.angles["leftelbow"][0], [0, 0, -a], atol=1e-12)


def test_hip_abduction_is_a_rotation_about_z():
    # Left foot and knee moved towards +x: rot_z(a) @ (0, -1, 0) = (sin a, -cos a, 0).
    a = np.deg2rad(25)
    pose = tpose()
    d = np.array([[np.sin(a), -np.cos(a), 0]])
    pose["leftknee"] = pose["lefthip"] + 0.42 * d
    pose["leftfoot"] = pose["leftknee"] + 0.42 * d
    result = pose_to_angles(pose, Skeleton.default())
    np.testing.assert_allclose(result.angles["lefthip"][0], [a, 0, 0], atol=1e-12)
    np.testing.assert_allclose(result.angles["leftknee"][0], 0, atol=1e-12)


def test_parallel_and_antiparallel_bones_are_exact_without_nan():
    sk = Skeleton.default()
    pose = tpose()
    # forearm folded back along the upper arm, thigh pointing straight up
    pose["leftwrist"] = pose["leftelbow"] - [[0.26, 0, 0]]
    pose["rightknee"] = pose["righthip"] + [[0, 0.42, 0]]
    pose["rightfoot"] = pose["rightknee"] + [[0, 0.42, 0]]
    result = pose_to_angles(pose, sk)
    for joint in ROTATING_JOINTS:
        assert np.isfinite(result.angles[joint]).all(), joint
    R = result.rotations["leftelbow"][0]
    np.testing.assert_allclose(R @ [1, 0, 0], [-1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-15)
    np.testing.assert_allclose(result.rotations["rightknee"][0], np.eye(3), atol=1e-15)
    Q = angles_to_pose(result, sk)
    for joint in KEYPOINTS:
        np.testing.assert_allclose(Q[joint], pose[joint], atol=1e-12, err_msg=joint)


def test_from_positions_takes_medians_and_averages_left_and_right():
    pose = limb_pose(3)
    pose["leftfoot"] = pose["leftknee"] - np.array([[0, 0.40, 0], [0, 0.40, 0], [0, 0.5, 0]])
    pose["rightfoot"] = pose["rightknee"] - np.array([[0, 0.44, 0], [0, 0.30, 0], [0, 0.44, 0]])
    pose["leftfoot"][2] = np.nan   # NaN frames are ignored by the median
    sk = Skeleton.from_positions(pose)
    assert sk.lengths["shank"] == pytest.approx(0.42)   # (0.40 + 0.44) / 2
    assert sk.lengths["thigh"] == pytest.approx(0.42)
    np.testing.assert_allclose(sk.offsets["rightfoot"], [0, -0.42, 0])


def test_given_hips_and_neck_are_used_instead_of_mid_points():
    pose = tpose()
    pose["neck"] = pose["neck"] + [[0, 0.1, 0]]
    sk = Skeleton.from_positions(pose)
    assert sk.lengths["trunk"] == pytest.approx(0.6)


# ------------------------------------------------------------------------- unwrapping


def test_root_angle_is_unwrapped_through_a_full_turn():
    yaw = np.linspace(0, 2 * np.pi, 41)  # turning on the spot about the vertical
    sk = Skeleton.default()
    base = tpose(sk)
    R = rot_y(yaw)
    pose = {k: np.einsum("fij,j->fi", R, base[k][0]) for k in KEYPOINTS}
    result = pose_to_angles(pose, sk)
    np.testing.assert_allclose(result.root_angles[:, 2], yaw, atol=1e-9)  # Y is third


def test_joint_angle_is_unwrapped_past_180_degrees_even_across_lost_frames():
    # The left leg sweeps about z from 150 to 210 degrees. The minimal rotation for 210
    # is -150 about z, so wrapped angles jump; unwrapped ones continue past 180.
    a = np.deg2rad(np.linspace(150, 210, 25))
    pose = limb_pose(len(a))
    d = np.column_stack([np.sin(a), -np.cos(a), 0 * a])
    pose["leftknee"] = pose["lefthip"] + 0.42 * d
    pose["leftfoot"] = pose["leftknee"] + 0.42 * d
    pose["leftknee"][10:14] = np.nan
    z = pose_to_angles(pose, Skeleton.default()).angles["lefthip"][:, 0]
    ok = np.ones(len(a), bool)
    ok[10:14] = False
    np.testing.assert_allclose(z[ok], a[ok], atol=1e-9)
    assert np.isnan(z[~ok]).all()


# ------------------------------------------------------------------------ missing data


@pytest.mark.parametrize("lost, affected", [
    ("leftwrist", {"leftelbow"}),
    ("leftknee", {"lefthip", "leftknee"}),
    ("rightfoot", {"rightknee"}),
    ("rightelbow", {"rightshoulder", "rightelbow"}),
    # a shoulder sets the neck (mid-point), so the trunk, root frame and everything below
    ("leftshoulder", set(ROTATING_JOINTS) | {"root"}),
    ("righthip", set(ROTATING_JOINTS) | {"root", "root_position"}),
])
def test_lost_keypoint_gives_nan_only_for_the_joints_that_depend_on_it(lost, affected):
    sk, pose, _, _ = recoverable_pose(5, frames=6)
    pose = {k: pose[k].copy() for k in KEYPOINTS}
    pose[lost][[1, 4]] = np.nan
    result = pose_to_angles(pose, sk)
    series = dict(result.angles, root=result.root_angles,
                  root_position=result.root_position)
    for name, values in series.items():
        nan_frames = np.flatnonzero(np.isnan(values).any(axis=1))
        if name in affected:
            assert nan_frames.tolist() == [1, 4], name
            assert np.isnan(values[[1, 4]]).all(), name
        else:
            assert nan_frames.size == 0, name


def test_lost_wrist_gives_nan_only_at_that_wrist_after_forward_kinematics():
    sk, pose, _, _ = recoverable_pose(9, frames=4)
    pose = {k: pose[k].copy() for k in KEYPOINTS}
    pose["rightwrist"][2] = np.nan
    Q = angles_to_pose(pose_to_angles(pose, sk), sk)
    for joint in JOINTS:
        assert np.isnan(Q[joint][2]).any() == (joint == "rightwrist"), joint


# ----------------------------------------------------------------------------- warnings


def test_gimbal_lock_warns_once_naming_the_joint():
    pose = limb_pose(4)
    # thigh straight backwards: rot_x(90) takes (0, -1, 0) to (0, 0, -1); ZXY middle = 90
    pose["leftknee"][1] = pose["lefthip"][1] + [0, 0, -0.42]
    pose["leftfoot"][1] = pose["leftknee"][1] + [0, 0, -0.42]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = pose_to_angles(pose, Skeleton.default())
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1, messages
    assert "1 of 4 frames" in messages[0] and "lefthip" in messages[0]
    np.testing.assert_allclose(result.angles["lefthip"][1], [0, np.pi / 2, 0], atol=1e-12)


def test_no_warning_for_an_ordinary_pose():
    sk, pose, _, _ = recoverable_pose(1, frames=3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pose_to_angles({k: pose[k] for k in KEYPOINTS}, Skeleton.default(), "ZXY")


# --------------------------------------------------------------------------- bad input


def test_unknown_joint_name_is_named():
    pose = limb_pose()
    pose["leftankle"] = pose.pop("leftfoot")
    with pytest.raises(ValueError, match="unknown joint 'leftankle' in positions"):
        pose_to_angles(pose, Skeleton.default())


def test_missing_joint_is_named():
    pose = limb_pose()
    del pose["rightelbow"]
    with pytest.raises(ValueError, match="positions is missing joint 'rightelbow'"):
        pose_to_angles(pose, Skeleton.default())


@pytest.mark.parametrize("shape", [(3, 2), (3,), (3, 3, 1)])
def test_wrong_shape_is_named(shape):
    pose = limb_pose()
    pose["leftknee"] = np.zeros(shape)
    with pytest.raises(ValueError, match=r"positions\['leftknee'\] must have shape \(F, 3\)"):
        pose_to_angles(pose, Skeleton.default())


def test_different_frame_counts_are_named():
    pose = limb_pose(3)
    pose["rightfoot"] = pose["rightfoot"][:2]
    with pytest.raises(ValueError, match=r"positions\['rightfoot'\] has 2 frames"):
        pose_to_angles(pose, Skeleton.default())


def test_infinite_position_is_named():
    pose = limb_pose()
    pose["neck"] = np.full((3, 3), np.inf)
    with pytest.raises(ValueError, match=r"positions\['neck'\] contains infinite"):
        pose_to_angles(pose, Skeleton.default())


def test_positions_not_a_dict():
    with pytest.raises(ValueError, match="positions must be a dict"):
        pose_to_angles(np.zeros((3, 12, 3)), Skeleton.default())


def test_skeleton_of_wrong_type():
    with pytest.raises(ValueError, match="skeleton must be a Skeleton"):
        pose_to_angles(limb_pose(), {"lefthip": [1, 0, 0]})


def test_unknown_sequence():
    with pytest.raises(ValueError, match="unknown rotation sequence 'ZZY'"):
        pose_to_angles(limb_pose(), Skeleton.default(), sequence="ZZY")


def test_zero_length_bone_is_named():
    pose = limb_pose()
    pose["leftwrist"] = pose["leftelbow"].copy()
    with pytest.raises(ValueError, match="leftelbow->leftwrist.*zero length"):
        pose_to_angles(pose, Skeleton.default())


def test_collinear_root_points_are_named():
    pose = limb_pose(1)
    for k in ("leftshoulder", "rightshoulder"):  # neck on the hip line
        pose[k] = pose[k] - [[0, 0.5, 0]] + [[0.3, 0, 0]]
    with pytest.raises(ValueError, match="root frame from hips, lefthip and neck"):
        pose_to_angles(pose, Skeleton.default())


def test_skeleton_missing_offset_is_named():
    offsets = dict(Skeleton.default().offsets)
    del offsets["leftwrist"]
    with pytest.raises(ValueError, match="offsets is missing joint 'leftwrist'"):
        Skeleton(offsets)


def test_skeleton_unknown_offset_is_named():
    offsets = dict(Skeleton.default().offsets, lefttoe=[0, 0, 0.1])
    with pytest.raises(ValueError, match="unknown joint 'lefttoe' in offsets"):
        Skeleton(offsets)


def test_skeleton_zero_offset_is_named():
    offsets = dict(Skeleton.default().offsets, leftknee=[0, 0, 0])
    with pytest.raises(ValueError, match=r"offsets\['leftknee'\] has zero length"):
        Skeleton(offsets)


def test_skeleton_offset_of_wrong_shape_is_named():
    offsets = dict(Skeleton.default().offsets, neck=[0, 0.5])
    with pytest.raises(ValueError, match=r"offsets\['neck'\] must be 3 finite numbers"):
        Skeleton(offsets)


def test_skeleton_parallel_frame_offsets_are_named():
    offsets = dict(Skeleton.default().offsets, neck=[0.5, 0, 0])
    with pytest.raises(ValueError, match=r"offsets\['lefthip'\] and offsets\['neck'\] are "
                                         "parallel"):
        Skeleton(offsets)


def test_skeleton_unknown_length_name():
    with pytest.raises(ValueError, match="unknown bone length 'femur'"):
        Skeleton.default({"femur": 0.4})


def test_from_positions_bone_never_seen_is_named():
    pose = limb_pose(2)
    pose["leftwrist"] = np.full((2, 3), np.nan)
    with pytest.raises(ValueError, match="leftelbow->leftwrist has NaN in every frame"):
        Skeleton.from_positions(pose)


def test_angles_to_pose_missing_rotation_is_named():
    result = pose_to_angles(limb_pose(), Skeleton.default())
    del result.rotations["leftknee"]
    with pytest.raises(ValueError, match="result.rotations is missing joint 'leftknee'"):
        angles_to_pose(result, Skeleton.default())


def test_angles_to_pose_wrong_rotation_shape_is_named():
    result = pose_to_angles(limb_pose(3), Skeleton.default())
    result.rotations["neck"] = result.rotations["neck"][:2]
    with pytest.raises(ValueError, match=r"result.rotations\['neck'\] must have shape "
                                         r"\(3, 3, 3\)"):
        angles_to_pose(result, Skeleton.default())


def test_angles_to_pose_wrong_angle_shape_is_named():
    result = pose_to_angles(limb_pose(3), Skeleton.default())
    result.rotations = None
    result.angles["rightelbow"] = np.zeros((3, 2))
    with pytest.raises(ValueError, match=r"result.angles\['rightelbow'\] must have shape"):
        angles_to_pose(result, Skeleton.default())


def test_angles_to_pose_wrong_result_type():
    with pytest.raises(ValueError, match="result must be a PoseAngles"):
        angles_to_pose({"hips": np.zeros((1, 3))}, Skeleton.default())


def test_skeleton_negative_or_non_numeric_length_is_named():
    # a negative length used to turn the bone round silently (legs pointing up)
    for value, match in [(-0.42, r"lengths\['thigh'\] must be a positive number"),
                         (0.0, r"lengths\['thigh'\] must be a positive number"),
                         (np.nan, r"lengths\['thigh'\] must be a positive number"),
                         ("long", r"lengths\['thigh'\] must be a numeric array"),
                         ([0.4, 0.4], r"lengths\['thigh'\] must be a positive number")]:
        with pytest.raises(ValueError, match=match):
            Skeleton.default({"thigh": value})


def test_tpose_root_position_of_wrong_shape_is_named():
    with pytest.raises(ValueError, match="root_position must be 3 finite numbers"):
        Skeleton.default().tpose(root_position=(1.0, 2.0))


@pytest.mark.parametrize("name, matrix, match", [
    ("leftknee", 2 * np.eye(3), r"result.rotations\['leftknee'\] is not a rotation"),
    ("leftknee", np.diag([1.0, 1.0, -1.0]), r"result.rotations\['leftknee'\].*reflection"),
    ("root", np.diag([1.0, 1.0, -1.0]), r"result.root_rotation.*reflection"),
])
def test_angles_to_pose_matrix_that_is_not_a_rotation_is_named(name, matrix, match):
    # used to be accepted and to stretch or mirror the bones silently
    result = pose_to_angles(limb_pose(2), Skeleton.default())
    if name == "root":
        result.root_rotation = np.repeat(matrix[None], 2, axis=0)
    else:
        result.rotations[name] = np.repeat(matrix[None], 2, axis=0)
    with pytest.raises(ValueError, match=match):
        angles_to_pose(result, Skeleton.default())


def test_angles_to_pose_accepts_nan_rotations_of_lost_frames():
    result = pose_to_angles(limb_pose(3), Skeleton.default())
    result.rotations["leftelbow"][1] = np.nan
    Q = angles_to_pose(result, Skeleton.default())
    assert np.isnan(Q["leftwrist"][1]).all() and np.isfinite(Q["leftwrist"][[0, 2]]).all()
    assert np.isfinite(Q["leftelbow"]).all()


# --- issue 21: keypoints swapped for a few frames --------------------------------------------

def _turning_pose(frames=120):
    sk = Skeleton.default()
    turn = rot_y(np.linspace(0, 90, frames), degrees=True)
    pose = {k: np.einsum("fij,j->fi", turn, v[0]) + [0, 1.0, 0]
            for k, v in sk.tpose().items() if k in KEYPOINTS}
    return sk, pose


@pytest.mark.parametrize("a, b, start, stop, pair", [
    ("lefthip", "righthip", 40, 45, "lefthip and righthip"),
    ("leftshoulder", "rightshoulder", 70, 72, "leftshoulder and rightshoulder")])
def test_keypoints_swapped_for_a_few_frames_are_nan_not_180_degree_jumps(a, b, start, stop,
                                                                           pair):
    sk, pose = _turning_pose()
    clean = pose_to_angles(pose, sk)
    swapped = {k: v.copy() for k, v in pose.items()}
    swapped[a][start:stop], swapped[b][start:stop] = pose[b][start:stop], pose[a][start:stop]
    with pytest.warns(RuntimeWarning, match=rf"^{stop - start} of 120 frames turn by more "
                                            rf"than 90 degrees .*{pair} swapped"):
        result = pose_to_angles(swapped, sk)
    joint = "hips" if a == "lefthip" else "neck"
    assert np.isnan(result.angles[joint][start:stop]).all()
    keep = np.r_[0:start, stop:120]
    np.testing.assert_allclose(result.angles[joint][keep], clean.angles[joint][keep],
                               atol=1e-9)
    if a == "lefthip":
        assert np.isnan(result.root_angles[start:stop]).all()
        jumps = np.abs(np.diff(np.degrees(result.root_angles), axis=0))
        assert np.nanmax(jumps) < 5


def test_unrelated_poses_are_not_judged_for_jumps():
    # poses without continuity (a different random pose each frame) turn far between
    # frames by design: no warning
    sk, pose = _turning_pose(frames=6)
    R = Rotation.random(6, random_state=5).as_matrix()
    moved = {k: np.einsum("fij,fj->fi", R, v) for k, v in pose.items()}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pose_to_angles(moved, sk)
