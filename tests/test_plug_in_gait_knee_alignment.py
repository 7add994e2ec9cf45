"""plug_in_gait.knee_alignment: the wand-rotation offset measured in a static trial and
undone in a dynamic one (the knee alignment device's thigh and shank rotations).

Oracle: synthetic limbs built from the chord function's definition with a KNOWN flexion
axis and a wand turned off that axis' plane by a KNOWN angle (seeded); scipy's Rotation
for the wand's turn; the seeded Plug-in Gait generator (data/generate_plug_in_gait_data.py)
with the knee alignment device on, wands turned by known offsets and known angles; and,
for Vicon's sign, the static half's formula as pyCGM2 writes it (the one its tests compare
with Nexus's stored ThighRotation), evaluated here by hand in the segment's axes.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bmc_functions.models.plug_in_gait import (chord_joint_centre, cgm_femur_frame,
                                               plug_in_gait)
from bmc_functions.models.plug_in_gait.knee_alignment import (rotate_wand,
                                                              rotated_chord_joint_centre,
                                                              wand_rotation_offset)

SEED = 34
DELTA = 60.0     # knee width / 2 + marker radius (mm)


def limb(rng, n, misalignment):
    """n random poses of a thigh with a known knee centre J, its flexion axis through J
    and KNE, the hip centre P (P - J perpendicular to the axis, as the chord function
    assumes), a medial axis point A, and a wand THI turned by `misalignment` (radians,
    right-handed about the long axis J -> P) out of the axis' plane. Returns dict of (n, 3)."""
    # the thigh in its own frame: knee centre at the origin, axis along +y (lateral)
    local = {"J": np.zeros(3), "P": np.array([0.0, 0.0, 420.0]),
             "M": np.array([0.0, DELTA, 0.0])}
    e1 = (local["P"] - local["J"]) / np.linalg.norm(local["P"] - local["J"])
    in_plane = np.array([0.0, 95.0, 210.0])          # a wand in the axis' plane, lateral
    turn = Rotation.from_rotvec(misalignment * e1)
    local["W"] = local["P"] + turn.apply(in_plane - local["P"])
    poses = Rotation.random(n, random_state=rng.integers(2**31))
    shift = rng.uniform(-1000, 1000, size=(n, 3))
    return {k: poses.apply(np.tile(v, (n, 1))) + shift for k, v in local.items()}


@pytest.mark.parametrize("degrees", [-25.0, -3.0, 0.5, 12.0, 30.0])
def test_static_offset_recovers_the_known_misalignment(degrees):
    rng = np.random.default_rng(SEED)
    pts = limb(rng, 50, np.radians(degrees))
    offset = wand_rotation_offset(pts["W"], pts["P"], pts["M"], pts["J"])
    # the wand was turned by +a about the long axis; the offset (wand to KNE) is -a
    np.testing.assert_allclose(offset, -np.radians(degrees), atol=1e-9, rtol=0)


def test_offset_applied_to_a_dynamic_trial_recovers_the_true_knee_axis():
    rng = np.random.default_rng(SEED)
    misalignment = np.radians(14.0)
    static = limb(rng, 20, misalignment)
    offset = float(wand_rotation_offset(static["W"], static["P"], static["M"],
                                        static["J"]).mean())
    walk = limb(np.random.default_rng(SEED + 1), 300, misalignment)   # other poses
    knee = rotated_chord_joint_centre(walk["W"], walk["P"], walk["M"], DELTA, offset)
    np.testing.assert_allclose(knee, walk["J"], atol=1e-9, rtol=0)
    # the femur's y axis is then the true flexion axis (J to KNE), on every frame
    R = cgm_femur_frame(walk["P"], knee, walk["M"], "left")
    axis = (walk["M"] - walk["J"]) / DELTA
    np.testing.assert_allclose(R[:, :, 1], axis, atol=1e-9, rtol=0)
    # the plain chord function is off by the misalignment (the test can fail)
    plain = chord_joint_centre(walk["W"], walk["P"], walk["M"], DELTA)
    R_plain = cgm_femur_frame(walk["P"], plain, walk["M"], "left")
    error = np.degrees(np.arccos(np.clip(np.sum(R_plain[:, :, 1] * axis, axis=1), -1, 1)))
    assert np.all(error > 5.0)


def test_shank_offset_same_construction():
    """The shank rotation: TIB, the knee centre and ANK take the places of THI, the hip
    centre and KNE; the same two functions measure and undo it."""
    rng = np.random.default_rng(SEED + 2)
    pts = limb(rng, 40, np.radians(-8.0))   # read as knee centre, ankle centre, ANK, TIB
    offset = wand_rotation_offset(pts["W"], pts["P"], pts["M"], pts["J"])
    ankle = rotated_chord_joint_centre(pts["W"], pts["P"], pts["M"], DELTA, offset.mean())
    np.testing.assert_allclose(ankle, pts["J"], atol=1e-9, rtol=0)


def test_zero_offset_is_the_chord_function_bit_for_bit():
    pts = limb(np.random.default_rng(SEED), 30, 0.3)
    plain = chord_joint_centre(pts["W"], pts["P"], pts["M"], DELTA)
    same = rotated_chord_joint_centre(pts["W"], pts["P"], pts["M"], DELTA, 0.0)
    assert np.array_equal(plain, same)


def test_rotate_wand_against_scipy():
    rng = np.random.default_rng(SEED)
    W, O, A = (rng.normal(size=(25, 3)) * 300 for _ in range(3))
    theta = rng.uniform(-np.pi, np.pi, 25)
    axis = (A - O) / np.linalg.norm(A - O, axis=1, keepdims=True)
    expected = O + Rotation.from_rotvec(theta[:, None] * axis).apply(W - O)
    np.testing.assert_allclose(rotate_wand(W, O, A, theta), expected, atol=1e-9, rtol=0)


def test_offset_sign_convention_hand_derived():
    """Hand-derived: knee centre at the origin, hip straight above (long axis +z), KNE
    along +y; the wand turned from +y towards +x by 10 deg is -10 deg about +z, so the
    angle from the wand to KNE about +z is +10 deg. Mirrored wand (towards -x): -10."""
    a = np.radians(10.0)
    for sign in (1.0, -1.0):
        thi = [sign * 100 * np.sin(a), 100 * np.cos(a), 200.0]
        offset = wand_rotation_offset(thi, [0, 0, 400.0], [0, 60, 0.0], [0, 0, 0.0])
        assert float(np.degrees(offset)) == pytest.approx(sign * 10.0, abs=1e-12)


def test_missing_frames_give_nan_per_frame():
    pts = limb(np.random.default_rng(SEED), 10, 0.2)
    pts["W"][3] = np.nan
    pts["J"][5] = np.nan
    offset = wand_rotation_offset(pts["W"], pts["P"], pts["M"], pts["J"])
    assert np.isnan(offset[[3, 5]]).all() and np.isfinite(np.delete(offset, [3, 5])).all()
    knee = rotated_chord_joint_centre(pts["W"], pts["P"], pts["M"], DELTA, 0.2)
    assert np.isnan(knee[3]).all() and np.isfinite(np.delete(knee, 3, axis=0)).all()


@pytest.mark.parametrize("name", ["wand", "proximal_centre", "lateral_marker",
                                  "joint_centre"])
def test_bad_shape_names_the_argument(name):
    args = {"wand": np.zeros((4, 3)), "proximal_centre": np.ones((4, 3)),
            "lateral_marker": np.full((4, 3), 2.0), "joint_centre": np.full((4, 3), 3.0)}
    args[name] = np.zeros((4, 2))
    with pytest.raises(ValueError, match=name):
        wand_rotation_offset(**args)
