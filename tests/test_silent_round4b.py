"""Issue 32, round 4 (the cases outside Plug-in Gait's upper body): a body mass in tonnes or
contradicting the subject's, a segment in mm or of zero length, angles in radians given to
the Gait Profile Score, events outside the trial and a misspelt label given to the
spatiotemporal parameters, a toe marker behind the ankle marker and a thigh wand placed
medially (with or without a static trial). Each case raised nothing on the code before
this round; each test checks the error or warning and its boundary, with expected values
set by hand.
"""

import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import (calibrate_lower_limb, gait_events, gait_profile_score,
                           inverse_dynamics, normative_data, plug_in_gait, read_c3d,
                           segment_inertia, spatiotemporal_parameters)
from bmc_functions.dynamics.segment_parameters import (MAX_SEGMENT_LENGTH, MIN_BODY_MASS,
                                                       check_body_mass)
from bmc_functions.examples import example_file
from bmc_functions.models.plug_in_gait import checks, davis_hip_centre, load_subject
from bmc_functions.models.plug_in_gait.kinetics import body_mass_of
from helpers import SHARED_DATA, needs_shared, warning_messages, swapped

STATIC_PATH = example_file("plug_in_gait/Static_trial.c3d")
WALK_PATH = example_file("plug_in_gait/Movement_trial.c3d")
VSK, _ = load_subject(example_file("plug_in_gait/Test.vsk"))


def quiet(function, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return function(*args, **kwargs)


@pytest.fixture(scope="module")
def pig():
    static, walk = read_c3d(STATIC_PATH), read_c3d(WALK_PATH)
    model = quiet(plug_in_gait, static, VSK)
    no_static = quiet(plug_in_gait, None, {**VSK, **model.static_offsets})
    return model, no_static, static, walk


def shifted_inwards(df, wand, mm):
    """`wand` moved `mm` towards the other leg, along the line between the ASIS markers."""
    out = df.copy()
    other = "LASI" if wand[0] == "R" else "RASI"
    inward = df[other].to_numpy() - df[wand[0] + "ASI"].to_numpy()
    out[wand] = df[wand].to_numpy() + mm * inward / np.linalg.norm(inward, axis=1,
                                                                   keepdims=True)
    return out


# ---- body mass: 0.2 to 650 kg, and against the subject's Bodymass -----------------------

def test_body_mass_boundary_is_the_lightest_surviving_newborn():
    assert MIN_BODY_MASS == 0.2
    assert check_body_mass(0.2) == 0.2
    with pytest.raises(ValueError, match=r"body_mass must be a body mass in kg, from 0.2 "
                                         r"to 650 \(a mass in g, lb or tonnes\?\); got 0.199"):
        check_body_mass(0.199)


def test_body_mass_in_tonnes_is_refused_by_segment_inertia():
    with pytest.raises(ValueError, match=r"body_mass .* got 0.085"):
        segment_inertia([[0, 0.5, 0]], [[0, 0.1, 0]], 0.085, "shank")


def test_body_mass_in_tonnes_is_refused_by_plug_in_gait_kinetics(pig):
    with pytest.raises(ValueError, match=r"body_mass .*tonnes.* got 0.085"):
        pig[0].kinetics(WALK_PATH, plates={2: None, 3: None}, body_mass=0.085)


def test_body_mass_in_tonnes_is_refused_by_lower_limb_kinetics():
    from test_lower_limb_kinetics import MARKERS, loads, standing_trial, under
    model = quiet(calibrate_lower_limb, None, MARKERS)
    forces = loads(R_=((0, 350, 0), under("right"), (0, 0, 0)))
    with pytest.raises(ValueError, match=r"body_mass .* got 0.07"):
        model.kinetics(standing_trial(), forces, body_mass=0.07)


def test_a_body_mass_contradicting_bodymass_warns_at_10_percent():
    subject = {"Bodymass": 85.0}
    assert not warning_messages(body_mass_of, subject, 93.4)     # 9.9 % more: agrees
    assert not warning_messages(body_mass_of, subject, 76.6)     # 9.9 % less
    messages = warning_messages(body_mass_of, subject, 93.6)     # 10.1 %
    assert len(messages) == 1
    assert "body_mass=93.6 kg contradicts the subject's Bodymass=85 kg" in messages[0]
    assert "pounds" not in messages[0]
    assert body_mass_of(subject, None) == 85.0


def test_body_mass_in_pounds_names_both_and_the_pounds(pig):
    with pytest.warns(UserWarning, match=r"body_mass=187 kg contradicts the subject's "
                                         r"Bodymass=85 kg .*pounds: 84.8 kg"):
        result = quiet_but(UserWarning, pig[0].kinetics, WALK_PATH,
                           plates={2: None, 3: None}, body_mass=187)
    assert result.attrs["body_mass_kg"] == 187.0       # the given mass is used, and said


def quiet_but(category, function, *args, **kwargs):
    """Call `function` with every warning but `category` silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        warnings.simplefilter("always", category)
        return function(*args, **kwargs)


# ---- segments: zero length, mm where metres belong --------------------------------------

def test_segment_of_zero_length_in_every_frame_is_refused():
    with pytest.raises(ValueError, match=r"proximal and distal must be the two ends of the "
                                         r"shank .*the same point in all 2 frames"):
        segment_inertia([[0, 0.5, 0]] * 2, [[0, 0.5, 0]] * 2, 70, "shank")


def test_segment_of_zero_length_in_some_frames_is_nan_there():
    with pytest.warns(RuntimeWarning, match=r"2 of 5 frames give the shank a length of 0"):
        mass, com, inertia = segment_inertia([[0, 0.5, 0]] * 5,
                                             [[0, 0.5, 0]] * 2 + [[0, 0.1, 0]] * 3,
                                             70, "shank")
    assert np.isnan(inertia[:2]).all()
    # 70 kg x 0.0465 x 0.4² x 0.302², as the docstring's example
    np.testing.assert_allclose(inertia[2:, 0, 0], 70 * 0.0465 * 0.16 * 0.302 ** 2)


def test_segment_length_boundary_is_the_tallest_person():
    assert MAX_SEGMENT_LENGTH == 2.72
    assert not warning_messages(segment_inertia, [[0, 2.71, 0]], [[0, 0, 0]], 70, "thigh")
    messages = warning_messages(segment_inertia, [[0, 400.0, 0]], [[0, 0, 0]], 70, "shank")
    assert len(messages) == 1 and "the shank is 400 long" in messages[0]
    assert "in mm?" in messages[0]


def _at_rest(frames=5, **kw):
    R = np.repeat(np.eye(3)[None], frames, axis=0)
    args = dict(com=[np.tile([0.1, 0, 0], (frames, 1))], joint=[np.zeros((frames, 3))])
    args.update(kw)
    return inverse_dynamics([R], args.pop("com"), args.pop("joint"), [1.0],
                            [np.zeros((3, 3))], rate=100, **args)


def test_inverse_dynamics_refuses_a_centre_of_mass_in_mm():
    _at_rest(com=[np.tile([2.71, 0, 0], (5, 1))])                 # 2.71 m: accepted
    with pytest.raises(ValueError, match=r"com\[0\] must be within a segment's length of "
                                         r"joint\[0\], in metres .*got 100 apart"):
        _at_rest(com=[np.tile([100.0, 0, 0], (5, 1))])


def test_inverse_dynamics_refuses_a_centre_of_pressure_in_mm():
    force = np.tile([0, 700.0, 0], (5, 1))
    loads = _at_rest(force=force, cop=np.tile([0.1, 0, 0.05], (5, 1)))
    # the ground's 700 N at 0.1 m in front: 700 x 0.1 less the foot's 0.98 N m, about -z
    np.testing.assert_allclose(loads.moment[0, 2, 2], 0.980665 - 70.0)
    with pytest.raises(ValueError, match=r"cop must be within a segment's length of "
                                         r"joint\[0\]"):
        _at_rest(force=force, cop=np.tile([100.0, 0, 50.0], (5, 1)))
    # where the force is zero (swing), the point of application is not judged
    swing = force.copy()
    swing[:] = 0.0
    _at_rest(force=swing, cop=np.tile([100.0, 0, 50.0], (5, 1)))


# ---- Gait Profile Score: radians against degrees ----------------------------------------

PERCENT = np.linspace(0, 100, 51)
NORMAL = 30 * np.sin(np.pi * PERCENT / 100)             # peaks at 30 degrees
THREE = {"pelvic_tilt": ("pelvis", "tilt"), "hip_flexion": ("hip", "flexion"),
         "knee_flexion": ("knee", "flexion")}


def _cycles(*curves):
    columns = pd.MultiIndex.from_tuples([(joint, side, angle) for side in ("left", "right")
                                         for joint, angle in THREE.values()])
    index = pd.MultiIndex.from_product([range(len(curves)), PERCENT],
                                       names=["cycle", "percent"])
    return pd.DataFrame(np.concatenate([np.tile(c, (6, 1)).T for c in curves]),
                        index=index, columns=columns)


def test_gait_profile_score_refuses_cycles_in_radians():
    normative = normative_data(_cycles(NORMAL - 1, NORMAL + 1))     # up to 31 degrees
    with pytest.raises(ValueError, match=r"cycles and normative must be in the same unit, "
                                         r"degrees; got cycles' angles within 0.524 .*"
                                         r"radians\?"):
        gait_profile_score(_cycles(np.radians(NORMAL)), normative, variables=THREE)
    with pytest.raises(ValueError, match=r"normative and cycles must be in the same unit"):
        gait_profile_score(_cycles(NORMAL), normative_data(_cycles(np.radians(NORMAL))),
                           variables=THREE)


def test_gait_profile_score_unit_boundary_is_half_the_degree_to_radian_ratio():
    normative = normative_data(_cycles(NORMAL - 1, NORMAL + 1))     # largest: 31
    # a subject whose largest angle is 31 / 28.6 = 1.08 or less is taken for radians
    small = 1.2 * np.sin(np.pi * PERCENT / 100)                     # 31 / 1.2 = 25.8
    profile = gait_profile_score(_cycles(small), normative, variables=THREE)
    assert profile.gps["overall"] == pytest.approx(
        np.sqrt(np.mean((small - NORMAL) ** 2)))
    with pytest.raises(ValueError, match="radians"):
        gait_profile_score(_cycles(small / 1.2), normative, variables=THREE)   # 31 / 1


# ---- spatiotemporal parameters: a misspelt label, events outside the trial ---------------

@pytest.fixture(scope="module")
def walk_events(pig):
    model, _, _, walk = pig
    roles = model.event_markers()
    return walk, roles, quiet(gait_events, walk, roles)


def test_spatiotemporal_names_a_misspelt_foot_label(walk_events):
    walk, roles, events = walk_events
    with pytest.raises(ValueError, match=r"markers\['RHEEL'\] = 'RHEEX' .*no marker with "
                                         r"that label .*'RHEE'"):
        spatiotemporal_parameters(events, walk, dict(roles, RHEEL="RHEEX"))


def test_spatiotemporal_refuses_events_all_outside_the_trial(walk_events):
    walk, roles, events = walk_events
    later = walk.copy()
    later.index = later.index + 100.0
    with pytest.raises(ValueError, match=r"events must lie within the trial's time, 100 to "
                                         r"102.683 s; got every event outside it "
                                         r"\(0.34\d* to 2.53\d* s\)"):
        spatiotemporal_parameters(events, later, roles)


def test_spatiotemporal_names_the_events_outside_and_keeps_the_others(walk_events):
    walk, roles, events = walk_events
    plain = {side: dict(found) for side, found in events.items()}   # no progression kept
    clean = quiet(spatiotemporal_parameters, plain, walk, roles)
    late = {side: dict(found) for side, found in events.items()}
    last = walk.index[-1]
    late["right"]["heel_strike"] = np.r_[events["right"]["heel_strike"], last + 0.5]
    with pytest.warns(RuntimeWarning, match=rf"1 event\(s\) outside the trial's time "
                                            rf"\(0 to {last:g} s\): {last + 0.5:g} s"):
        result = quiet_but(RuntimeWarning, spatiotemporal_parameters, late, walk, roles)
    strides = result.attrs["strides"]
    assert np.isnan(strides.loc[strides["end"] == last + 0.5, "stride_length"]).all()
    np.testing.assert_allclose(result.loc["left", "stride_length"],
                               clean.loc["left", "stride_length"])
    # an event on the last frame (float32 times) is inside: half a frame of tolerance
    on_last = {side: dict(found) for side, found in events.items()}
    on_last["right"]["heel_strike"] = np.r_[events["right"]["heel_strike"],
                                            np.float32(last)]
    assert not [m for m in warning_messages(spatiotemporal_parameters, on_last, walk, roles)
                if "outside the trial" in m]


# ---- Plug-in Gait: TOE behind ANK, a thigh wand placed medially --------------------------

@pytest.mark.parametrize("side", ["L", "R"])
def test_toe_and_ankle_swapped_in_every_frame_is_an_error(pig, side):
    model, no_static, _, walk = pig
    trial = swapped(walk, side + "TOE", side + "ANK")
    for each in (model, no_static):
        with pytest.raises(ValueError, match=rf"{side}TOE lies 1\d\d mm behind {side}ANK "
                                             rf"along the pelvis's anterior axis"):
            quiet(each.angles, trial)


def test_toe_ahead_of_ankle_boundary_is_zero():
    body = {"LASI": [0, 120, 900], "RASI": [0, -120, 900], "SACRUM": [-150, 0, 900],
            "LANK": [0, 100, 80], "RANK": [0, -100, 80]}       # pelvis x: the lab's x
    for ahead, error in ((1.0, False), (-1.0, True)):
        points = {k: np.array([v], float) for k, v in body.items()}
        points["LTOE"] = np.array([[ahead, 80.0, 40.0]])
        points["RTOE"] = np.array([[150.0, -80.0, 40.0]])
        if error:
            with pytest.raises(ValueError, match=r"LTOE lies 1 mm behind LANK"):
                checks.check_toe_ahead_of_ankle(points)
        else:
            assert checks.check_toe_ahead_of_ankle(points) == {"L": 1.0, "R": 150.0}


@pytest.mark.parametrize("wand", ["LTHI", "RTHI"])
def test_a_thigh_wand_placed_medially_without_static_is_an_error(pig, wand):
    _, no_static, _, walk = pig
    with pytest.raises(ValueError, match=rf"{wand} lies \d+ mm medial to the line from the "
                                         rf"hip centre to {wand[0]}KNE"):
        quiet(no_static.angles, shifted_inwards(walk, wand, 120.0))


def test_a_thigh_wand_placed_medially_in_the_static_too_is_an_error(pig):
    static = pig[2]
    with pytest.raises(ValueError, match=r"the static trial: LTHI lies \d+ mm medial"):
        quiet(plug_in_gait, shifted_inwards(static, "LTHI", 120.0), VSK)


def test_thigh_wand_boundary_is_three_hundredths_of_the_leg_length():
    subject = {"LeftLegLength": 800.0, "RightLegLength": 800.0, "MarkerDiameter": 14.0,
               "LeftAsisTrocanterDistance": 55.0, "RightAsisTrocanterDistance": 55.0,
               "InterAsisDistance": 240.0}
    pelvis = {"LASI": [0, 120, 900], "RASI": [0, -120, 900], "SACRUM": [-150, 0, 900]}
    points = {k: np.array([v], float) for k, v in pelvis.items()}
    hips = {p: davis_hip_centre(np.eye(3), np.array([0, 0, 900.0]), mean_leg_length=800.0,
                                asis_trochanter=55.0, inter_asis_distance=240.0,
                                marker_radius=7.0, side=side)
            for p, side in (("L", "left"), ("R", "right"))}
    for p in "LR":
        points[p + "KNE"] = (hips[p] + [0, 0, -400.0])[None]   # the hip-KNE line vertical
    for medial, error in ((23.0, False), (25.0, True)):     # 0.03 x 800 = 24 mm
        # the wand halfway down, `medial` mm inside the hip-KNE line (along y, lateral
        # being +y on the left, -y on the right)
        for p, sign in (("L", 1.0), ("R", -1.0)):
            points[p + "THI"] = (hips[p] + [40.0, -sign * medial, -200.0])[None]
        if error:
            with pytest.raises(ValueError, match=r"LTHI lies 25 mm medial .*RTHI lies 25 mm"):
                checks.check_thigh_wands(points, subject)
        else:
            offsets = checks.check_thigh_wands(points, subject)
            assert offsets == pytest.approx({"L": -23.0, "R": -23.0})


def test_the_shipped_trials_put_the_toe_ahead_and_the_wands_lateral(pig):
    """The margins the docstrings quote (139 to 182 mm ahead, 54 to 64 mm lateral)."""
    model, _, static, walk = pig
    for trial in (static, walk):
        points = {label: trial[label].to_numpy(float) for label in
                  ("LASI", "RASI", "LPSI", "RPSI", "LTOE", "RTOE", "LANK", "RANK", "LKNE",
                   "RKNE", "LTHI", "RTHI")}
        points["SACRUM"] = (points["LPSI"] + points["RPSI"]) / 2.0
        assert min(checks.check_toe_ahead_of_ankle(points).values()) > 130.0
        assert min(checks.check_thigh_wands(points, model.subject).values()) > 50.0


@needs_shared("walks_with_plates/sample14.c3d")
def test_sample14_is_not_flagged():
    df = read_c3d(SHARED_DATA / "walks_with_plates" / "sample14.c3d")
    points = {label: df[label].to_numpy(float) for label in
              ("LASI", "RASI", "SACR", "LTOE", "RTOE", "LANK", "RANK", "LKNE", "RKNE",
               "LTHI", "RTHI")}
    points["SACRUM"] = points["SACR"]
    leg = {s: float(np.nanmedian(np.linalg.norm(points[s + "ASI"] - points[s + "ANK"],
                                                axis=1))) for s in "LR"}
    subject = {"LeftLegLength": leg["L"], "RightLegLength": leg["R"], "MarkerDiameter": 14.0,
               "LeftAsisTrocanterDistance": 0.1288 * leg["L"] - 48.56,
               "RightAsisTrocanterDistance": 0.1288 * leg["R"] - 48.56}
    assert min(checks.check_toe_ahead_of_ankle(points).values()) > 80.0
    assert min(checks.check_thigh_wands(points, subject).values()) > 60.0


# ---- assign_plates: a trial in metres declared in mm is named -----------------------------

def test_assign_plates_names_the_units_of_a_trial_in_metres_declared_mm(pig):
    from bmc_functions import assign_plates, read_force_plates
    walk = pig[3]
    plates = read_force_plates(WALK_PATH)
    feet = {"right": ["RHEE", "RTOE"], "left": ["LHEE", "LTOE"]}
    clean = warning_messages(assign_plates, plates, walk, feet)
    assert not [m for m in clean if "units" in m]          # the feet over the plates
    metres = walk / 1000.0
    metres.attrs = dict(walk.attrs)                         # still says 'mm'
    messages = warning_messages(assign_plates, plates, metres, feet)
    assert len(messages) == 1
    assert "not assigned to a foot" in messages[0]
    assert "the trial's units are not what its attrs['units'] says" in messages[0]


def test_gait_events_without_the_asis_roles_names_them(walk_events):
    walk, roles, _ = walk_events
    no_asis = {k: v for k, v in roles.items() if k not in ("RASIS", "LASIS")}
    with pytest.raises(ValueError, match=r"the pelvis needs the roles 'RASIS' and 'LASIS' "
                                         r".*got no RASIS or LASIS"):
        gait_events(walk, no_asis)
    with pytest.raises(ValueError, match=r"got no LASIS$"):
        gait_events(walk, {k: v for k, v in roles.items() if k != "LASIS"})
