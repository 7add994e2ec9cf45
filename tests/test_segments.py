"""Tests of bmc_functions.models.segments: ISB anatomical frames of pelvis, thigh and shank and
the Harrington hip joint centre, against hand-built landmarks moved by scipy rotations."""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from bmc_functions import hip_joint_centre, pelvis_frame, shank_frame, thigh_frame

# Landmarks of a right limb in each segment's own ISB frame (x anterior, y up, z right),
# so that each function must return exactly the rotation and origin that moved them.
PELVIS = {"rasis": [0, 0, 120], "lasis": [0, 0, -120], "rpsis": [-160, 0, 45],
          "lpsis": [-160, 0, -45]}
THIGH = {"hip_centre": [0, 0, 0], "lateral_epicondyle": [0, -415, 47],
         "medial_epicondyle": [0, -425, -47]}
SHANK = {"lateral_epicondyle": [0, 405, 47], "medial_epicondyle": [0, 395, -47],
         "lateral_malleolus": [0, -8, 35], "medial_malleolus": [0, 8, -35]}
MIRROR = np.diag([1.0, 1.0, -1.0])   # reflection across the sagittal plane: right <-> left


def moved(landmarks, R, L):
    """Landmarks (segment frame) -> lab coordinates for F poses R (F,3,3), L (F,3)."""
    return {k: np.einsum("fij,j->fi", R, np.asarray(v, float)) + L
            for k, v in landmarks.items()}


def random_poses(seed, frames=20):
    rng = np.random.default_rng(seed)
    return (Rotation.random(frames, random_state=rng).as_matrix(),
            rng.normal(scale=1000.0, size=(frames, 3)))


# --- frames recover the pose that placed the landmarks (scipy as the oracle) -------------
@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_frames_recover_random_poses(seed):
    R, L = random_poses(seed)
    Rp, op = pelvis_frame(**moved(PELVIS, R, L))
    Rt, ot = thigh_frame(**moved(THIGH, R, L))
    Rs, os_ = shank_frame(**moved(SHANK, R, L))
    for R_found in (Rp, Rt, Rs):
        np.testing.assert_allclose(R_found, R, atol=1e-9)
    np.testing.assert_allclose(op, L, atol=1e-7)        # mid-ASIS at the pelvis origin
    np.testing.assert_allclose(ot, L, atol=1e-7)        # hip centre
    np.testing.assert_allclose(os_, L, atol=1e-7)       # mid-malleoli


def test_single_frame_identity_and_shapes():
    R, origin = thigh_frame(**THIGH)
    assert R.shape == (3, 3) and origin.shape == (3,)
    np.testing.assert_allclose(R, np.eye(3), atol=1e-12)


def test_thigh_axes_follow_the_isb_definition_for_a_skewed_femur():
    # Epicondyles not perpendicular to the femur's long axis: z must be made perpendicular
    # to y (Gram-Schmidt) and stay in the plane of the hip centre and the epicondyles.
    hip, lat, med = np.array([10.0, 430, 5]), np.array([30.0, 20, 60]), np.array([-5.0, -5, -40])
    R, origin = thigh_frame(hip, lat, med)
    x, y, z = R.T
    knee = (lat + med) / 2
    np.testing.assert_allclose(y, (hip - knee) / np.linalg.norm(hip - knee))
    normal = np.cross(hip - med, lat - med)          # normal of the plane of the 3 points
    assert abs(z @ normal) < 1e-9 * np.linalg.norm(normal)
    assert z @ (lat - med) > 0                       # right limb: lateral is to the right
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0)
    np.testing.assert_allclose(x, np.cross(y, z))


def test_shank_axes_follow_the_definition():
    lat_ep, med_ep = np.array([0.0, 400, 50]), np.array([0.0, 390, -40])
    lat_mal, med_mal = np.array([-20.0, -10, 35]), np.array([10.0, 5, -30])
    R, origin = shank_frame(lat_ep, med_ep, lat_mal, med_mal)
    knee, ankle = (lat_ep + med_ep) / 2, (lat_mal + med_mal) / 2
    np.testing.assert_allclose(origin, ankle)
    np.testing.assert_allclose(R[:, 1], (knee - ankle) / np.linalg.norm(knee - ankle))
    normal = np.cross(lat_mal - knee, med_mal - knee)
    assert abs(R[:, 2] @ normal) < 1e-9 * np.linalg.norm(normal)
    assert R[:, 2] @ (lat_mal - med_mal) > 0


def test_pelvis_x_lies_in_the_plane_of_the_asis_and_mid_psis():
    rasis, lasis = np.array([5.0, 3, 118]), np.array([-4.0, 1, -121])
    rpsis, lpsis = np.array([-150.0, 40, 40]), np.array([-155.0, 35, -50])
    R, origin = pelvis_frame(rasis, lasis, rpsis, lpsis)
    mid_psis = (rpsis + lpsis) / 2
    normal = np.cross(rasis - mid_psis, lasis - mid_psis)
    assert abs(R[:, 0] @ normal) < 1e-9 * np.linalg.norm(normal)
    assert R[:, 0] @ (origin - mid_psis) > 0          # anterior
    np.testing.assert_allclose(R[:, 2], (rasis - lasis) / np.linalg.norm(rasis - lasis))


# --- left side: mirror images give frames with z still to the right ----------------------
def test_left_limb_frames_are_the_mirror_images():
    R, L = random_poses(1, frames=5)
    right_t = moved(THIGH, R, L)
    right_s = moved(SHANK, R, L)
    left_t = {k: v @ MIRROR for k, v in right_t.items()}
    left_s = {k: v @ MIRROR for k, v in right_s.items()}
    Rt_right, _ = thigh_frame(**right_t)
    Rt_left, _ = thigh_frame(**left_t, side="left")
    Rs_right, _ = shank_frame(**right_s)
    Rs_left, _ = shank_frame(**left_s, side="left")
    # Mirroring the landmarks mirrors the frame: M R M keeps z = right, x anterior, y up.
    np.testing.assert_allclose(Rt_left, MIRROR @ Rt_right @ MIRROR, atol=1e-12)
    np.testing.assert_allclose(Rs_left, MIRROR @ Rs_right @ MIRROR, atol=1e-12)
    assert np.all(np.linalg.det(Rt_left) > 0)


# --- hip joint centre ---------------------------------------------------------------------
def test_hip_joint_centre_hand_values():
    # PW = 240, PD = 160: x = -0.24*160 - 9.9, y = -0.30*240 - 10.9, z = 0.33*240 + 7.3
    right = hip_joint_centre(**PELVIS)
    left = hip_joint_centre(**PELVIS, side="left")
    np.testing.assert_allclose(right, [-48.3, -82.9, 86.5], atol=1e-9)
    np.testing.assert_allclose(left, [-48.3, -82.9, -86.5], atol=1e-9)


def test_hip_joint_centre_moves_with_the_pelvis():
    R, L = random_poses(2)
    centre = hip_joint_centre(**moved(PELVIS, R, L))
    np.testing.assert_allclose(centre, R @ np.array([-48.3, -82.9, 86.5]) + L, atol=1e-7)


# --- missing data --------------------------------------------------------------------------
def test_nan_landmark_gives_nan_only_in_its_frame():
    R, L = random_poses(3, frames=4)
    thigh = moved(THIGH, R, L)
    thigh["medial_epicondyle"][2] = np.nan
    Rt, origin = thigh_frame(**thigh)
    assert np.isnan(Rt[2]).all()
    assert np.isfinite(Rt[[0, 1, 3]]).all()
    np.testing.assert_allclose(Rt[[0, 1, 3]], R[[0, 1, 3]], atol=1e-9)
    pelvis = moved(PELVIS, R, L)
    pelvis["rasis"][0] = np.nan
    assert np.isnan(hip_joint_centre(**pelvis)[0]).all()
    assert np.isfinite(hip_joint_centre(**pelvis)[1:]).all()


# --- bad input: each with its own message -------------------------------------------------
def test_wrong_side():
    with pytest.raises(ValueError, match="side must be 'right' or 'left'; got 'up'"):
        thigh_frame(**THIGH, side="up")
    with pytest.raises(ValueError, match="side must be"):
        hip_joint_centre(**PELVIS, side="R")


def test_wrong_landmark_shape_names_the_argument():
    with pytest.raises(ValueError, match=r"lateral_malleolus must have shape \(\.\.\., 3\)"):
        shank_frame(SHANK["lateral_epicondyle"], SHANK["medial_epicondyle"], [1, 2],
                    SHANK["medial_malleolus"])


def test_landmark_shapes_that_do_not_match():
    with pytest.raises(ValueError, match="same shape"):
        thigh_frame(np.zeros((5, 3)), np.ones((4, 3)), np.ones((4, 3)) * 2)


def test_infinite_landmark():
    with pytest.raises(ValueError, match="rpsis contains infinite values"):
        pelvis_frame(PELVIS["rasis"], PELVIS["lasis"], [np.inf, 0, 0], PELVIS["lpsis"])


def test_coincident_epicondyles():
    with pytest.raises(ValueError, match="lateral_epicondyle and medial_epicondyle coincide "
                                         "in 1 of 1 frames"):
        thigh_frame([0, 400, 0], [0, 0, 40], [0, 0, 40])


def test_hip_centre_on_the_epicondylar_line():
    with pytest.raises(ValueError, match="hip_centre lies on the line through the epicondyles"):
        thigh_frame([0, 0, 400], [0, 0, 40], [0, 0, -40])


def test_coincident_asis_and_psis_on_the_asis_line():
    with pytest.raises(ValueError, match="rasis and lasis coincide"):
        pelvis_frame([0, 0, 1], [0, 0, 1], [-160, 0, 45], [-160, 0, -45])
    with pytest.raises(ValueError, match="mid-PSIS lies on the line through the ASISs"):
        pelvis_frame([0, 0, 120], [0, 0, -120], [0, 0, 200], [0, 0, 100])


def test_coincident_malleoli_and_knee_on_the_malleolar_line():
    with pytest.raises(ValueError, match="lateral_malleolus and medial_malleolus coincide"):
        shank_frame([0, 400, 45], [0, 400, -45], [0, 0, 35], [0, 0, 35])
    with pytest.raises(ValueError, match="knee centre lies on the line through the malleoli"):
        shank_frame([0, 0, 145], [0, 0, 55], [0, 0, 35], [0, 0, -35])


def test_coincident_mid_asis_and_mid_psis():
    with pytest.raises(ValueError, match="mid-ASIS and mid-PSIS coincide"):
        pelvis_frame([0, 0, 120], [0, 0, -120], [0, 0, 45], [0, 0, -45])


def test_all_missing_landmarks_give_nan_without_warnings():
    missing = np.full((2, 3), np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        R, origin = thigh_frame(missing, missing, missing)
        centre = hip_joint_centre(missing, missing, missing, missing)
    assert np.isnan(R).all() and np.isnan(origin).all() and np.isnan(centre).all()


# --- units of the hip regression; the shank frame against Wu et al.'s tibia frame ----
@pytest.mark.parametrize("scale, unit", [(1e-3, "m"), (1e-1, "cm")])
def test_hip_joint_centre_rejects_landmarks_not_in_mm(scale, unit):
    # The regression's constants are in mm: with landmarks in m the old code put the
    # centre ~10 m away (x = -0.24 PD - 9.9 with PD = 0.16) and said nothing.
    pelvis = {k: np.asarray(v, float) * scale for k, v in PELVIS.items()}
    with pytest.raises(ValueError, match=r"pelvis width .* is [\d.]+ \(median\).*the "
                                         r"landmarks must be in mm"):
        hip_joint_centre(**pelvis)


def test_hip_joint_centre_accepts_a_small_child_pelvis():
    # A 150 mm pelvis (young child) is within the plausible range; hand values as above.
    pelvis = {k: np.asarray(v, float) * 150 / 240 for k, v in PELVIS.items()}
    expected = [-0.24 * 100 - 9.9, -0.30 * 150 - 10.9, 0.33 * 150 + 7.3]
    np.testing.assert_allclose(hip_joint_centre(**pelvis), expected, atol=1e-9)


def test_shank_frame_is_wu_torsional_frame_turned_about_x():
    # Wu et al. (2002) tibia/fibula XYZ: Z along the malleoli (MM -> LM, right), X normal
    # to the torsional plane (knee centre, malleoli) pointing anteriorly, Y = Z x X. The
    # package keeps y on the long axis instead: same x, and the two frames differ by a
    # rotation about x by the tilt of the malleolar line (here atan(16/70) = 12.9 deg).
    lat_ep, med_ep = np.array([0.0, 405, 47]), np.array([0.0, 395, -47])
    lat_mal, med_mal = np.array([0.0, -8, 35]), np.array([0.0, 8, -35])
    knee = (lat_ep + med_ep) / 2
    Z = (lat_mal - med_mal) / np.linalg.norm(lat_mal - med_mal)
    X = np.cross(lat_mal - knee, med_mal - knee)      # anterior for a right leg
    X /= np.linalg.norm(X)
    assert X @ [1, 0, 0] > 0
    wu = np.column_stack([X, np.cross(Z, X), Z])
    R, _ = shank_frame(lat_ep, med_ep, lat_mal, med_mal)
    np.testing.assert_allclose(R[:, 0], X, atol=1e-12)
    # R = wu @ Rx(angle): the malleolar line descends laterally (towards -y), so the
    # package's z is Wu's Z turned up towards +y, a negative rotation about x.
    turn = Rotation.from_matrix(wu.T @ R).as_rotvec(degrees=True)
    np.testing.assert_allclose(turn, [-np.degrees(np.arctan2(16, 70)), 0, 0], atol=1e-9)


# --- foot frame ---------------------------------------------------------------------------------
from bmc_functions import foot_frame  # noqa: E402


def test_foot_frame_with_mt5_is_the_sole_plane():
    rng = np.random.default_rng(5)
    R_true = Rotation.random(10, random_state=rng).as_matrix()
    origin = rng.normal(0, 500, (10, 3))
    local = {"heel": (-55, -45, 0), "toe": (150, -45, 0), "mt5": (115, -45, 35),
             "lat": (0, -8, 35), "med": (0, 8, -35)}
    lab = {k: np.einsum("fij,j->fi", R_true, v) + origin for k, v in local.items()}
    R, o = foot_frame(lab["heel"], lab["toe"], lab["lat"], lab["med"], mt5=lab["mt5"])
    np.testing.assert_allclose(R, R_true, atol=1e-12)
    np.testing.assert_allclose(o, origin, atol=1e-9)
    # the left foot: mirrored points, side='left', z still to the right
    M = np.diag([1.0, 1.0, -1.0])
    left = {k: v @ M for k, v in lab.items()}
    R_left, _ = foot_frame(left["heel"], left["toe"], left["lat"], left["med"],
                           mt5=left["mt5"], side="left")
    np.testing.assert_allclose(R_left, M @ R_true @ M, atol=1e-12)


def test_foot_frame_without_mt5_takes_z_from_the_malleoli():
    R, _ = foot_frame([-50, -40, 0], [150, -40, 0], [0, -8, 35], [0, 8, -35])
    np.testing.assert_allclose(R[:, 0], [1, 0, 0], atol=1e-12)
    tilt = np.degrees(np.arctan2(-16, 70))                   # the malleolar line's slope
    np.testing.assert_allclose(R[:, 2], [0, np.sin(np.radians(tilt)),
                                         np.cos(np.radians(tilt))], atol=1e-12)


def test_foot_frame_errors():
    with pytest.raises(ValueError, match="heel and toe coincide"):
        foot_frame([0, 0, 0], [0, 0, 0], [0, 0, 35], [0, 0, -35])
    with pytest.raises(ValueError, match="mt5 lies on the line through heel and toe"):
        foot_frame([0, 0, 0], [100, 0, 0], [0, 0, 35], [0, 0, -35], mt5=[50, 0, 0])
    with pytest.raises(ValueError, match="the malleolar line is parallel to heel-toe"):
        foot_frame([0, 0, 0], [100, 0, 0], [35, 0, 0], [-35, 0, 0])
    with pytest.raises(ValueError, match="side must be 'right' or 'left'"):
        foot_frame([0, 0, 0], [100, 0, 0], [0, 0, 35], [0, 0, -35], side="r")
    with pytest.raises(ValueError, match=r"landmark arrays must have the same shape"):
        foot_frame(np.zeros((2, 3)), np.ones((3, 3)), [0, 0, 35], [0, 0, -35])
