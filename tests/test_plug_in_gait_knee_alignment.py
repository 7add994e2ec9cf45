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
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from helpers import load_data_script

from bmc_functions.models.plug_in_gait import (chord_joint_centre, cgm_femur_frame,
                                               cgm_tibia_frame, knee_alignment, plug_in_gait)
from bmc_functions.models.plug_in_gait.knee_alignment import (kad_knee_marker, rotate_wand,
                                                              rotated_chord_joint_centre,
                                                              vicon_wand_offset,
                                                              wand_offset_from_vicon,
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


# --- Vicon's convention, and the model with the knee alignment device ---------------------

GEN = load_data_script("generate_plug_in_gait_data")
#: Known offsets (Vicon's names and signs, radians), both signs, thigh and shank.
OFFSETS = {"LeftThighRotation": 0.21, "RightThighRotation": -0.13,
           "LeftShankRotation": -0.09, "RightShankRotation": 0.17}
#: The subject without the static offsets: the static trial gives them.
NO_STATIC = {k: v for k, v in GEN.SUBJECT.items() if "Static" not in k}


def vicon_static_formula(wand, centre, R, side):
    """Vicon's number for a wand, by the static half's formula as pyCGM2 writes it
    (getThighOffset / getShankOffsets, compared in its tests with Nexus's stored value):
    w = wand - joint centre in the segment's axes (x anterior, y left);
    atan2(-w.x, w.y) on the left, atan2(-w.x, -w.y) on the right."""
    w = np.einsum("nij,ni->nj", R, wand - centre)
    return np.arctan2(-w[:, 0], w[:, 1] if side == "left" else -w[:, 1])


@pytest.fixture(scope="module")
def kad_trials():
    static, _, static_centres = GEN.make_trial(30, static=True, wand_offsets=OFFSETS,
                                               kad=True, straight_knees=True)
    walk, truth, centres = GEN.make_trial(110, wand_offsets=OFFSETS)
    return static, static_centres, walk, truth, centres


def test_wand_offset_sign_is_vicons_static_formula(kad_trials):
    """The generator's wands, turned by Vicon's numbers, give back those numbers by the
    source's formula (independent of this module's beta): the sign is Vicon's."""
    static, centres, _, _, _ = kad_trials
    for side, p, long in (("left", "L", "Left"), ("right", "R", "Right")):
        thi, tib = static[p + "THI"].to_numpy(), static[p + "TIB"].to_numpy()
        knee, ankle, hip = centres[p + "KJC"], centres[p + "AJC"], centres[p + "HJC"]
        lateral_k = kad_knee_marker(static[p + "KAX"].to_numpy(), static[p + "KD1"].to_numpy(),
                                    static[p + "KD2"].to_numpy(), side)
        R_femur = cgm_femur_frame(hip, knee, lateral_k, side)
        np.testing.assert_allclose(vicon_static_formula(thi, knee, R_femur, side),
                                   OFFSETS[long + "ThighRotation"], atol=1e-9, rtol=0)
        R_tibia = cgm_tibia_frame(knee, ankle, static[p + "ANK"].to_numpy(), side)[0]
        np.testing.assert_allclose(vicon_static_formula(tib, ankle, R_tibia, side),
                                   OFFSETS[long + "ShankRotation"], atol=1e-9, rtol=0)
        # and this module's beta is MIRROR * that number
        beta = wand_rotation_offset(thi, hip, lateral_k, knee)
        np.testing.assert_allclose(vicon_wand_offset(beta, side),
                                   OFFSETS[long + "ThighRotation"], atol=1e-9, rtol=0)


def test_vicon_offset_conversions():
    assert wand_offset_from_vicon(0.2, "left") == -0.2
    assert wand_offset_from_vicon(0.2, "right") == 0.2
    assert vicon_wand_offset(wand_offset_from_vicon(-0.3, "left"), "left") == -0.3
    with pytest.raises(ValueError, match="side must be 'left' or 'right'; got 'up'"):
        wand_offset_from_vicon(0.1, "up")


def test_kad_origin_is_the_apex_of_the_device():
    """Three orthogonal arms of known length from a known origin, any pose (scipy): the
    origin is recovered; the right device is the mirror image."""
    rng = np.random.default_rng(SEED)
    poses = Rotation.random(40, random_state=rng.integers(2**31))
    origin = rng.uniform(-500, 500, size=(40, 3))
    arms = 101.6 * np.eye(3)
    left = [origin + poses.apply(np.tile(a, (40, 1))) for a in arms]
    np.testing.assert_allclose(kad_knee_marker(*left, "left"), origin, atol=1e-9, rtol=0)
    mirror = np.diag([1.0, -1.0, 1.0])
    right = [origin + poses.apply(np.tile(mirror @ a, (40, 1))) for a in arms]
    np.testing.assert_allclose(kad_knee_marker(*right, "right"), origin, atol=1e-9, rtol=0)
    assert np.isnan(kad_knee_marker([np.nan, 0, 0], [0, 1, 0.], [0, 0, 1.], "left")).all()


def test_kad_static_recovers_the_known_offsets(kad_trials):
    static, _, _, _, _ = kad_trials
    model = plug_in_gait(static, NO_STATIC)
    for name, value in OFFSETS.items():
        assert model.subject[name] == pytest.approx(value, abs=1e-9)
        assert model.derived[name] == model.subject[name]
    for name in ("LeftStaticPlantFlex", "RightStaticPlantFlex", "LeftStaticRotOff",
                 "RightStaticRotOff"):
        assert model.static_offsets[name] == pytest.approx(GEN.SUBJECT[name], abs=1e-9)


def test_kad_static_then_walk_recovers_the_known_angles_and_centres(kad_trials):
    static, _, walk, truth, centres = kad_trials
    model = plug_in_gait(static, NO_STATIC)
    angles = model.angles(walk)
    np.testing.assert_allclose(angles[truth.columns].to_numpy(), truth.to_numpy(),
                               atol=1e-9, rtol=0)
    track = model.track(walk)
    for name in ("LKJC", "RKJC", "LAJC", "RAJC"):
        np.testing.assert_allclose(track.centres[name].to_numpy(), centres[name],
                                   atol=1e-9, rtol=0)


def test_subject_offsets_are_applied_with_vicons_sign(kad_trials):
    """Without a static trial, the offsets from the subject (a .vsk's) are applied: the
    known angles come back; the opposite sign would be tens of degrees off."""
    _, _, walk, truth, _ = kad_trials
    angles = plug_in_gait(None, dict(GEN.SUBJECT, **OFFSETS)).angles(walk)
    np.testing.assert_allclose(angles[truth.columns].to_numpy(), truth.to_numpy(),
                               atol=1e-9, rtol=0)
    wrong = plug_in_gait(None, dict(GEN.SUBJECT, **{k: -v for k, v in OFFSETS.items()}))
    error = np.abs(wrong.angles(walk)[truth.columns].to_numpy() - truth.to_numpy())
    assert np.nanmax(error) > 10.0


def test_the_kad_static_replaces_the_subjects_offsets(kad_trials):
    """With the device on, the static processing measures both offsets and they replace
    the subject's (Nexus's static processing; pyCGM2's Kad decorator zeroes them first)."""
    static, _, _, _, _ = kad_trials
    model = plug_in_gait(static, dict(NO_STATIC, LeftThighRotation=0.05))
    assert model.subject["LeftThighRotation"] == pytest.approx(0.21, abs=1e-9)
    assert model.derived["LeftThighRotation"] == model.subject["LeftThighRotation"]


def test_manual_thigh_offset_static_measures_the_shank_offset():
    """Without the device, a non-zero ThighRotation from the subject is applied in the
    static trial, and ShankRotation is measured there with KNE as the shank's wand turned
    by the tibial torsion (Vicon's "manual thigh offset" case, as pyCGM2's
    Cgm1ManualOffsets replicates it), replacing the subject's: the known value comes back
    (a straight knee, as the construction assumes), whatever the subject said."""
    static, _, _ = GEN.make_trial(30, static=True, wand_offsets=OFFSETS, straight_knees=True)
    given = dict(OFFSETS, LeftShankRotation=0.0, RightShankRotation=0.4)
    model = plug_in_gait(static, dict(NO_STATIC, **given))
    for name, value in OFFSETS.items():
        assert model.subject[name] == pytest.approx(value, abs=1e-9)
    assert "LeftThighRotation" not in model.derived        # the subject's, applied
    for name in ("LeftStaticPlantFlex", "RightStaticRotOff"):
        assert model.static_offsets[name] == pytest.approx(GEN.SUBJECT[name], abs=1e-9)


def test_static_without_device_or_thigh_offset_keeps_the_shank_offset():
    """ThighRotation 0 and no device: nothing is measured, the subject's ShankRotation is
    applied (its ankle centres, hence the static foot offsets)."""
    shank = {"LeftShankRotation": -0.09, "RightShankRotation": 0.17}
    static, _, _ = GEN.make_trial(30, static=True, wand_offsets=shank)
    model = plug_in_gait(static, dict(NO_STATIC, **shank))
    for name, value in shank.items():
        assert model.subject[name] == value
    for name in ("LeftStaticPlantFlex", "RightStaticRotOff"):
        assert model.static_offsets[name] == pytest.approx(GEN.SUBJECT[name], abs=1e-9)


def test_zero_offsets_leave_the_chord_function_untouched():
    """ThighRotation 0 (the shared subject's): the knee and ankle centres are the chord
    function's, bit for bit."""
    walk, _, _ = GEN.make_trial(20)
    plain = plug_in_gait(None, GEN.SUBJECT).track(walk).centres
    zero = plug_in_gait(None, dict(GEN.SUBJECT, LeftThighRotation=0.0,
                                   RightShankRotation=0.0)).track(walk).centres
    assert np.array_equal(plain.to_numpy(), zero.to_numpy(), equal_nan=True)


def test_kad_static_with_subject_prefixes_and_renames(kad_trials):
    """The device's labels are found as the other markers are: with a subject prefix
    ('Sub01:LKAX'), or renamed with markers= (then KNE is written under the renamed
    label)."""
    static, _, _, _, _ = kad_trials
    prefixed = static.rename(columns=lambda name: "Sub01:" + name, level=0)
    prefixed.attrs = dict(static.attrs)
    model = plug_in_gait(prefixed, NO_STATIC)
    assert model.subject["RightShankRotation"] == pytest.approx(0.17, abs=1e-9)
    renamed = static.rename(columns={"LKAX": "L_KAD_AX"}, level=0)
    renamed.attrs = dict(static.attrs)
    model = plug_in_gait(renamed, NO_STATIC, markers={"LKAX": "L_KAD_AX", "LKNE": "L_KNEE"})
    assert model.subject["LeftThighRotation"] == pytest.approx(0.21, abs=1e-9)


# --- the foot-flat option and SoleDelta ------------------------------------------------------

def _heel_raised(static, side, mm):
    """The static trial with that side's HEE raised by `mm` along the lab's z (up)."""
    out = static.copy()
    out[(side[0].upper() + "HEE", "z")] += mm
    out.attrs = dict(static.attrs)
    return out


@pytest.mark.parametrize("sole", [0.0, 12.0])
def test_foot_flat_puts_the_heel_at_the_toes_height_plus_the_sole(sole):
    """Oracle: the same static with the heel moved by hand to the toe's height + SoleDelta
    (lab z up, the generator's), processed without the option."""
    static, _, _ = GEN.make_trial(30, static=True)
    tilted = _heel_raised(static, "left", 25.0)            # a heel marker placed high
    by_hand = tilted.copy()
    by_hand[("LHEE", "z")] = tilted[("LTOE", "z")] + sole
    by_hand.attrs = dict(static.attrs)
    expected = plug_in_gait(by_hand, NO_STATIC).static_offsets
    model = plug_in_gait(tilted, dict(NO_STATIC, LeftSoleDelta=sole), foot_flat="left")
    for name in ("LeftStaticPlantFlex", "LeftStaticRotOff"):
        assert model.static_offsets[name] == pytest.approx(expected[name], abs=1e-12)
    # the right foot, not flat, keeps its recorded heel
    plain = plug_in_gait(tilted, NO_STATIC).static_offsets
    assert model.static_offsets["RightStaticPlantFlex"] == plain["RightStaticPlantFlex"]
    assert model.attrs["foot_flat"] == ["left"]
    if sole:
        assert model.static_offsets["LeftStaticPlantFlex"] != pytest.approx(
            plug_in_gait(tilted, NO_STATIC, foot_flat=True).static_offsets[
                "LeftStaticPlantFlex"], abs=1e-3)


def test_sole_delta_without_foot_flat_is_refused():
    static, _, _ = GEN.make_trial(10, static=True)
    with pytest.raises(ValueError, match="RightSoleDelta = 8.*foot_flat=True"):
        plug_in_gait(static, dict(NO_STATIC, RightSoleDelta=8.0), foot_flat="left")


@pytest.mark.parametrize("bad", ["both", 1, None, "False"])
def test_foot_flat_bad_values_name_the_argument(bad):
    with pytest.raises(ValueError, match="foot_flat must be True, False, 'left' or 'right'"):
        plug_in_gait(None, GEN.SUBJECT, foot_flat=bad)


def test_far_from_the_lab_origin_converges_like_near_it(monkeypatch):
    """A 10-minute walk is 780 m long: the iteration runs relative to the proximal
    centre, so it converges there in as few steps, to the same centre (translated)."""
    rng = np.random.default_rng(SEED)
    pts = limb(rng, 200, np.radians(9.0))
    offset = wand_rotation_offset(pts["W"], pts["P"], pts["M"], pts["J"])
    shift = np.array([780000.0, -3000.0, 0.0])
    calls = []
    original = knee_alignment.chord_joint_centre
    monkeypatch.setattr(knee_alignment, "chord_joint_centre",
                        lambda *a: calls.append(1) or original(*a))
    far = rotated_chord_joint_centre(pts["W"] + shift, pts["P"] + shift, pts["M"] + shift,
                                     DELTA, offset)
    assert len(calls) < 20
    np.testing.assert_allclose(far - shift, pts["J"], atol=1e-8, rtol=0)


# --- the KAD-med static: medial malleolus markers, AnkleAbAdd, tibial torsion -------------

#: Known ankle abductions (Vicon's names, radians; the same sign on both sides: the lateral
#: malleolus below the medial one) and the thigh/shank offsets above.
ABADD = {"LeftAnkleAbAdd": 0.20, "RightAnkleAbAdd": 0.152}
#: The subject without the values a KAD-med static measures (tibial torsion set to 0).
NO_KADMED = dict(NO_STATIC, LeftTibialTorsion=0.0, RightTibialTorsion=0.0)


@pytest.fixture(scope="module")
def kadmed_trials():
    static, _, static_centres = GEN.make_trial(30, static=True, wand_offsets=OFFSETS, kad=True,
                                               straight_knees=True, ankle_abadd=ABADD,
                                               medial_ankles=True)
    walk, truth, centres = GEN.make_trial(110, wand_offsets=OFFSETS, ankle_abadd=ABADD)
    return static, static_centres, walk, truth, centres


def test_abadd_rotation_against_scipy():
    """The dynamic half: the centre turned about the axis through ANK along
    (K - J) x (M - J) (pyCGM2's _rotateAjc frame's x), right-handed (scipy)."""
    rng = np.random.default_rng(SEED)
    J, K, M = (rng.normal(size=(30, 3)) * 200 for _ in range(3))
    theta = rng.uniform(-0.6, 0.6, 30)
    a = np.cross(K - J, M - J)
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    expected = M + Rotation.from_rotvec(theta[:, None] * a).apply(J - M)
    got = np.array([knee_alignment.abadd_rotated_ankle_centre(J[i], K[i], M[i], theta[i])
                    for i in range(30)])
    np.testing.assert_allclose(got, expected, atol=1e-9, rtol=0)
    same = knee_alignment.abadd_rotated_ankle_centre(J, K, M, 0.0)
    assert np.array_equal(same, J)


def test_abadd_static_formula_hand_derived_and_mirrored():
    """Hand-derived: ANK 40 mm lateral and 5 mm distal to the centre, the knee above:
    atan2(5, 40) on the left (lateral +y) and on the right (lateral -y) alike."""
    left = knee_alignment.ankle_abadd_offset([0, 0, 400.0], [0, 0, 0.0], [0, 40, -5.0])
    right = knee_alignment.ankle_abadd_offset([0, 0, 400.0], [0, 0, 0.0], [0, -40, -5.0])
    assert float(left) == pytest.approx(np.arctan2(5, 40), abs=1e-15)
    assert float(right) == float(left)
    up = knee_alignment.ankle_abadd_offset([0, 0, 400.0], [0, 0, 0.0], [0, 40, 5.0])
    assert float(up) == pytest.approx(-np.arctan2(5, 40), abs=1e-15)


def test_abadd_sign_is_pycgm2s_static_formula(kadmed_trials):
    """The generator's KAD-med static, by pyCGM2's getAbdAddAnkleJointOffset evaluated by
    hand in the tibia's axes (y left): atan2(-z.A, y.A) left, atan2(-z.A, -y.A) right,
    A = ANK - ankle centre: the known values; and tibial torsion by its
    getTibialTorsionOffset: atan2(k.y, k.x) - atan2(a.y, a.x) (left), negated (right)."""
    static, centres, _, _, _ = kadmed_trials
    for side, p, long in (("left", "L", "Left"), ("right", "R", "Right")):
        ank, med = static[p + "ANK"].to_numpy(), static[p + "MED"].to_numpy()
        ankle, knee, hip = (ank + med) / 2, centres[p + "KJC"], centres[p + "HJC"]
        np.testing.assert_allclose(ankle, centres[p + "AJC"], atol=1e-9, rtol=0)
        R = cgm_tibia_frame(knee, ankle, ank, side)[0]
        A = np.einsum("nij,ni->nj", R, ank - ankle)
        formula = np.arctan2(-A[:, 2], A[:, 1] if side == "left" else -A[:, 1])
        np.testing.assert_allclose(formula, ABADD[long + "AnkleAbAdd"], atol=1e-9, rtol=0)
        np.testing.assert_allclose(knee_alignment.ankle_abadd_offset(knee, ankle, ank),
                                   formula, atol=1e-12, rtol=0)
        lateral_k = kad_knee_marker(static[p + "KAX"].to_numpy(), static[p + "KD1"].to_numpy(),
                                    static[p + "KD2"].to_numpy(), side)
        R_femur = cgm_femur_frame(hip, knee, lateral_k, side)
        k = np.einsum("nij,ni->nj", R, R_femur[:, :, 1])
        torsion = np.arctan2(k[:, 1], k[:, 0]) - np.pi / 2
        torsion = torsion if side == "left" else -torsion
        np.testing.assert_allclose(torsion, GEN.SUBJECT[long + "TibialTorsion"], atol=1e-9,
                                   rtol=0)
        np.testing.assert_allclose(knee_alignment.tibial_torsion_offset(R_femur, R, side),
                                   torsion, atol=1e-12, rtol=0)


def test_external_tibial_torsion_is_negative_on_both_sides():
    """Hand-derived: the ankle axis turned 15 degrees externally from the knee axis
    (seen from above: clockwise on the right, counter-clockwise on the left)."""
    from bmc_functions.rigid_body.rotations import rot_z
    right = knee_alignment.tibial_torsion_offset(np.eye(3), rot_z(-np.radians(15)), "right")
    left = knee_alignment.tibial_torsion_offset(np.eye(3), rot_z(np.radians(15)), "left")
    assert float(np.degrees(right)) == pytest.approx(-15.0, abs=1e-12)
    assert float(np.degrees(left)) == pytest.approx(-15.0, abs=1e-12)


def test_kadmed_static_recovers_the_known_offsets(kadmed_trials):
    static, _, _, _, _ = kadmed_trials
    model = plug_in_gait(static, NO_KADMED)
    known = dict(OFFSETS, **ABADD, LeftTibialTorsion=GEN.SUBJECT["LeftTibialTorsion"],
                 RightTibialTorsion=GEN.SUBJECT["RightTibialTorsion"])
    for name, value in known.items():
        assert model.subject[name] == pytest.approx(value, abs=1e-9), name
        assert model.derived[name] == model.subject[name]
        assert model.attrs["measurements"][name] == model.subject[name]
    for name in ("LeftStaticPlantFlex", "RightStaticPlantFlex", "LeftStaticRotOff",
                 "RightStaticRotOff"):
        assert model.static_offsets[name] == pytest.approx(GEN.SUBJECT[name], abs=1e-9)


def test_walk_with_ankle_abadd_gives_the_known_angles_and_centres(kadmed_trials):
    """Without a static trial, AnkleAbAdd from the subject (a .vsk's) is applied by
    Vicon's rule: the generator's known angles and ankle centres come back; the opposite
    sign, or 0, is degrees off (the test can fail)."""
    _, _, walk, truth, centres = kadmed_trials
    model = plug_in_gait(None, dict(GEN.SUBJECT, **OFFSETS, **ABADD))
    np.testing.assert_allclose(model.angles(walk)[truth.columns].to_numpy(), truth.to_numpy(),
                               atol=1e-9, rtol=0)
    track = model.track(walk)
    for name in ("LAJC", "RAJC", "LKJC", "RKJC"):
        np.testing.assert_allclose(track.centres[name].to_numpy(), centres[name], atol=1e-9,
                                   rtol=0)
    for wrong in ({k: -v for k, v in ABADD.items()}, {k: 0.0 for k in ABADD}):
        angles = plug_in_gait(None, dict(GEN.SUBJECT, **OFFSETS, **wrong)).angles(walk)
        assert np.nanmax(np.abs(angles[truth.columns].to_numpy() - truth.to_numpy())) > 1.0


def test_kadmed_static_then_walk_recovers_the_known_angles(kadmed_trials):
    static, _, walk, truth, centres = kadmed_trials
    model = plug_in_gait(static, NO_KADMED)
    np.testing.assert_allclose(model.angles(walk)[truth.columns].to_numpy(), truth.to_numpy(),
                               atol=1e-9, rtol=0)


def test_vicons_two_halves_are_inverse_to_a_tenth_of_a_millimetre(kadmed_trials):
    """Vicon's static (centre midway between the malleoli) and dynamic (chord centre turned
    about ANK) halves are not exact inverses: on the static's own markers the dynamic rule
    finds the centre within 0.1 mm of the midpoint for ~10 degrees of abduction (recorded
    here so that a change of rule is seen)."""
    static, centres = GEN.make_trial(20, static=True, wand_offsets=OFFSETS, ankle_abadd=ABADD,
                                     medial_ankles=True, straight_knees=True)[::2]
    model = plug_in_gait(static, dict(NO_KADMED, **OFFSETS))
    assert model.subject["LeftAnkleAbAdd"] == pytest.approx(ABADD["LeftAnkleAbAdd"], abs=1e-9)
    track = model.track(static)
    for name in ("LAJC", "RAJC"):
        error = np.abs(track.centres[name].to_numpy() - centres[name]).max()
        assert 1e-3 < error < 0.1


def test_kadmed_static_with_mma_labels_prefixes_and_gaps(kadmed_trials):
    """LMMA is read as LMED; a subject prefix is found; a medial marker missing in some
    frames leaves those out of the means."""
    static, _, _, _, _ = kadmed_trials
    renamed = static.rename(columns={"LMED": "LMMA"}, level=0)
    renamed = renamed.rename(columns=lambda name: "Sub01:" + name, level=0)
    renamed.loc[renamed.index[3:9], ("Sub01:RMED", "x")] = np.nan
    renamed.attrs = dict(static.attrs)
    model = plug_in_gait(renamed, NO_KADMED)
    for name, value in ABADD.items():
        assert model.subject[name] == pytest.approx(value, abs=1e-9)
    assert np.isnan(renamed[("Sub01:RMED", "x")].iloc[3:9]).all()
    own = static.rename(columns={"RMED": "R_MALL_MED"}, level=0)
    own.attrs = dict(static.attrs)
    model = plug_in_gait(own, NO_KADMED, markers={"RMED": "R_MALL_MED"})
    assert model.subject["RightAnkleAbAdd"] == pytest.approx(ABADD["RightAnkleAbAdd"], abs=1e-9)


def _moved(static, **markers):
    """The static trial with the markers (name -> (frames, 3)) put elsewhere."""
    out = static.copy()
    for marker, xyz in markers.items():
        for k, coord in enumerate("xyz"):
            out[(marker, coord)] = xyz[:, k]
    out.attrs = dict(static.attrs)
    return out


def test_medial_marker_lateral_to_ank_is_refused(kadmed_trials):
    static, _, _, _, _ = kadmed_trials
    swapped = _moved(static, LMED=static["LANK"].to_numpy(), LANK=static["LMED"].to_numpy())
    with pytest.raises(ValueError, match="LMED lies .* mm lateral to LANK.*swapped"):
        plug_in_gait(swapped, NO_KADMED)


def test_medial_marker_far_from_ank_is_refused_or_warned(kadmed_trials):
    static, _, _, _, _ = kadmed_trials
    ank, med = static["RANK"].to_numpy(), static["RMED"].to_numpy()
    far = _moved(static, RMED=ank + 4.0 * (med - ank))      # 4 times the ankle's width
    with pytest.raises(ValueError, match="RMED is .* mm from RANK.*RightAnkleWidth.*times off"):
        plug_in_gait(far, NO_KADMED)
    wide = _moved(static, RMED=ank + 1.8 * (med - ank))
    with pytest.warns(RuntimeWarning, match="RMED is .* mm from RANK.*1.8 times off"):
        plug_in_gait(wide, NO_KADMED)


def test_medial_marker_in_no_frame_is_not_used(kadmed_trials):
    static, _, _, _, _ = kadmed_trials
    empty = _moved(static, LMED=np.full((len(static), 3), np.nan))
    with pytest.warns(RuntimeWarning, match="LMED .* is in no frame: LeftAnkleAbAdd"):
        model = plug_in_gait(empty, NO_KADMED)
    assert "LeftAnkleAbAdd" not in model.derived
    assert model.subject["RightAnkleAbAdd"] == pytest.approx(ABADD["RightAnkleAbAdd"], abs=1e-9)


def test_two_medial_markers_on_one_side_are_refused(kadmed_trials):
    static, _, _, _, _ = kadmed_trials
    both = pd.concat([static, static[["LMED"]].rename(columns={"LMED": "LMMA"}, level=0)],
                     axis=1)
    both.attrs = dict(static.attrs)
    with pytest.raises(ValueError, match="both LMED and LMMA found"):
        plug_in_gait(both, NO_KADMED)


def test_ankle_abadd_in_degrees_is_refused_and_a_large_one_warned():
    with pytest.raises(ValueError, match="LeftAnkleAbAdd = 11.5 is impossible"):
        plug_in_gait(None, dict(GEN.SUBJECT, LeftAnkleAbAdd=11.5))
    with pytest.warns(RuntimeWarning, match="RightAnkleAbAdd"):
        plug_in_gait(None, dict(GEN.SUBJECT, RightAnkleAbAdd=0.8))


def test_a_large_measured_abadd_is_warned(kadmed_trials):
    """Implausible geometry: a static whose malleoli line is 40 degrees off the shank's
    transverse plane (a medial marker placed too high) is measured and warned about."""
    static, _, _, _, _ = kadmed_trials
    tilted, _, _ = GEN.make_trial(10, static=True, straight_knees=True, medial_ankles=True,
                                  ankle_abadd={"LeftAnkleAbAdd": np.radians(40.0)})
    with pytest.warns(RuntimeWarning, match="LeftAnkleAbAdd"):
        model = plug_in_gait(tilted, NO_KADMED)
    assert model.subject["LeftAnkleAbAdd"] == pytest.approx(np.radians(40.0), abs=1e-9)


def test_a_static_without_medial_markers_gives_zero_abadd():
    """No medial markers: the static processing's AnkleAbAdd is 0 (Vicon's read-only
    output, pyCGM2's measurement on the chord centre), replacing the subject's, with a
    warning; the same static with the medial markers on one side measures that side."""
    static, _, _ = GEN.make_trial(30, static=True)
    with pytest.warns(RuntimeWarning, match="RightAnkleAbAdd = 0.152 and LeftAnkleAbAdd = "
                                            "0.2 replaced by 0"):
        model = plug_in_gait(static, dict(NO_STATIC, **ABADD))
    assert model.subject["LeftAnkleAbAdd"] == model.derived["LeftAnkleAbAdd"] == 0.0
    for name in ("LeftStaticPlantFlex", "RightStaticRotOff"):
        assert model.static_offsets[name] == pytest.approx(GEN.SUBJECT[name], abs=1e-9)
    one, _, _ = GEN.make_trial(30, static=True, medial_ankles=True, ankle_abadd=ABADD)
    one = one.drop(columns=["LMED"], level=0)
    one.attrs = dict(static.attrs)
    with pytest.warns(RuntimeWarning, match="LeftAnkleAbAdd = 0.2 replaced by 0"):
        model = plug_in_gait(one, dict(NO_STATIC, **ABADD))
    assert model.subject["RightAnkleAbAdd"] == pytest.approx(ABADD["RightAnkleAbAdd"],
                                                             abs=1e-9)


def test_zero_abadd_is_todays_model_bit_for_bit_on_the_vicon_trial():
    """AnkleAbAdd 0 (the shipped subject's .vsk holds 0): the angles are today's, bit for
    bit, on the Nexus-processed trial shipped with the package."""
    from bmc_functions.examples import example_file
    from bmc_functions.models.plug_in_gait.subject import load_subject
    vsk, _ = load_subject(example_file("plug_in_gait/Test.vsk"))
    assert vsk["LeftAnkleAbAdd"] == 0.0 and vsk["RightAnkleAbAdd"] == 0.0
    static = example_file("plug_in_gait/Static_trial.c3d")
    walk = example_file("plug_in_gait/Movement_trial.c3d")
    without = {k: v for k, v in vsk.items() if "AnkleAbAdd" not in k}
    a = plug_in_gait(static, vsk).angles(walk)
    b = plug_in_gait(static, without).angles(walk)
    assert np.array_equal(a.to_numpy(), b.to_numpy(), equal_nan=True)
