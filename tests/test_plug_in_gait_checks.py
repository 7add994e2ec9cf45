"""Plug-in Gait's checks of markers and measurements (bmc_functions/models/plug_in_gait/
checks.py), each class of mistake injected into the shipped Plug-in Gait trial (static +
Movement, data/real/plug_in_gait) at the boundary its docstring states."""

import warnings

import numpy as np
import pytest

from bmc_functions import plug_in_gait, read_c3d
from bmc_functions.examples import example_file
from bmc_functions.models.plug_in_gait import checks, load_subject
from bmc_functions.rigid_body.rotations import rot_x

from helpers import SHARED_DATA, needs_shared, subject_without_static, swapped

STATIC = read_c3d(example_file("plug_in_gait/Static_trial.c3d"))
DYNAMIC = read_c3d(example_file("plug_in_gait/Movement_trial.c3d"))
VSK, _ = load_subject(example_file("plug_in_gait/Test.vsk"))
LOWER = ("pelvis", "hip", "knee", "ankle", "foot")
CHECK_WORDS = ("swapped", "jumped", "impossible", "doubtful", "disagree", "(0, 0, 0)",
               "elsewhere")


def moved(df, marker, shift, rows=slice(None)):
    out = df.copy()
    index = out.index[rows]
    out.loc[index, marker] = out.loc[index, marker].to_numpy() + shift
    return out


def subject(**values):
    return {**VSK, **values}


def lower(angles):
    return angles[[c for c in angles.columns if c[0] in LOWER]]


@pytest.fixture(scope="module")
def clean():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = plug_in_gait(STATIC, VSK)
        angles = model.angles(DYNAMIC)
    return model, angles, [str(w.message) for w in caught]


def test_no_false_alarm_on_the_shipped_trials(clean):
    _, angles, messages = clean
    assert not [m for m in messages if any(word in m for word in CHECK_WORDS)]
    assert not lower(angles).isna().any().any()


@needs_shared("walks_with_plates/sample14.c3d")
def test_no_false_alarm_on_sample14():
    df = read_c3d(SHARED_DATA / "walks_with_plates" / "sample14.c3d")
    measured = subject_without_static(df)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plug_in_gait(None, measured).angles(df)
    assert not [w for w in caught if any(word in str(w.message) for word in CHECK_WORDS)]


# -- measurements --

@pytest.mark.parametrize("name, value", [
    ("LeftKneeWidth", 14.4),          # cm
    ("LeftKneeWidth", 1440.0),        # x10
    ("RightAnkleWidth", 8.9),         # cm
    ("LeftLegLength", 0.877),         # m
    ("LeftLegLength", 8770.0),        # x10
    ("InterAsisDistance", 3070.0),    # x10
    ("LeftTibialTorsion", 20.0),      # degrees
    ("MarkerDiameter", 140.0),
])
def test_a_measurement_in_the_wrong_unit_is_an_error(name, value):
    with pytest.raises(ValueError, match=rf"{name} = {value:g} is impossible"):
        plug_in_gait(STATIC, subject(**{name: value}))


def test_measurement_range_boundaries():
    with pytest.warns(RuntimeWarning, match=r"doubtful measurement\(s\) LeftKneeWidth = 300"):
        checks.check_measurement_ranges({"LeftKneeWidth": 300.0}, "s")
    with pytest.raises(ValueError, match="LeftKneeWidth = 300.1 is impossible"):
        checks.check_measurement_ranges({"LeftKneeWidth": 300.1}, "s")
    with pytest.raises(ValueError, match="RightStaticRotOff = 3.15 is impossible"):
        checks.check_measurement_ranges({"RightStaticRotOff": 3.15}, "s")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        checks.check_measurement_ranges({"RightStaticRotOff": 1.0, "LeftKneeWidth": 180.0})


def test_static_offsets_in_degrees_without_a_static_trial():
    with pytest.raises(ValueError, match="LeftStaticPlantFlex = 14.5 is impossible"):
        plug_in_gait(None, subject(LeftStaticPlantFlex=14.5))


def test_asis_trochanter_distance_boundary():
    leg = VSK["LeftLegLength"]
    with pytest.raises(ValueError, match="LeftAsisTrocanterDistance = 644 mm is impossible"):
        plug_in_gait(STATIC, subject(LeftAsisTrocanterDistance=644.0))
    with pytest.warns(RuntimeWarning, match="LeftAsisTrocanterDistance"):
        checks.check_measurement_ranges({"LeftLegLength": leg,
                                         "LeftAsisTrocanterDistance": 0.3 * leg})


def test_inter_asis_distance_against_the_markers():
    points = {"LASI": np.array([[0.0, 150, 0]]), "RASI": np.array([[0.0, -150, 0]]),
              "LANK": np.array([[0.0, 150, -850]]), "RANK": np.array([[0.0, -150, -850]])}
    legs = {"LeftLegLength": 850.0, "RightLegLength": 850.0}
    with pytest.warns(RuntimeWarning, match=r"InterAsisDistance = 899 mm \(LASI-RASI"):
        checks.check_measurements_against_markers(points, {**legs, "InterAsisDistance": 899})
    with pytest.raises(ValueError, match="InterAsisDistance = 901 mm contradicts"):
        checks.check_measurements_against_markers(points, {**legs, "InterAsisDistance": 901})
    with pytest.warns(RuntimeWarning, match=r"InterAsisDistance = 150 mm \(LASI-RASI in the "
                                            r"static trial 307 mm\)"):
        plug_in_gait(STATIC, subject(InterAsisDistance=150.0))


def test_leg_length_against_the_markers():
    with pytest.warns(RuntimeWarning, match=r"doubtful measurement\(s\) LeftLegLength = 280 "
                                            r"\(usual 400 to 1200 mm\)"), \
            pytest.raises(ValueError, match=r"LeftLegLength = 280 mm contradicts the markers "
                                            r"\(LASI-LANK"):
        plug_in_gait(STATIC, subject(LeftLegLength=280.0))


# -- markers in the dynamic trial --

def test_zeros_for_missing_points_are_gaps(clean):
    model, angles, _ = clean
    df = DYNAMIC.copy()
    df.loc[df.index[10:20], "LKNE"] = 0.0
    with pytest.warns(RuntimeWarning, match=r"\(0, 0, 0\) .*LKNE in 10 frames"), \
            pytest.warns(RuntimeWarning, match=r"10 of 323 frames have undefined segments "
                                               r"\(LKNE missing in 10\)"):
        result = model.angles(df)
    assert result["knee", "left"].iloc[10:20].isna().all().all()
    keep = np.r_[0:10, 20:len(df)]
    np.testing.assert_allclose(lower(result).iloc[keep], lower(angles).iloc[keep])


def test_a_pair_swapped_between_sides_in_a_run_of_frames(clean):
    model, angles, _ = clean
    with pytest.warns(RuntimeWarning, match=r"50 of 323 frames .*RANK lies to the subject's "
                                            r"left of LANK"):
        result = model.angles(swapped(DYNAMIC, "LANK", "RANK", slice(100, 150)))
    assert result["ankle"].iloc[100:150].isna().all().all()
    keep = np.r_[0:100, 150:len(DYNAMIC)]
    np.testing.assert_allclose(lower(result).iloc[keep], lower(angles).iloc[keep])


@pytest.mark.parametrize("a, b", [("LKNE", "RKNE"), ("LTHI", "RTHI"), ("LTIB", "RTIB"),
                                  ("LANK", "RANK"), ("LTOE", "RTOE")])
def test_a_pair_swapped_between_sides_in_every_frame_is_an_error(clean, a, b):
    model = clean[0]
    with pytest.raises(ValueError, match=rf"every frame .*{b} lies to the subject's left "
                                         rf"of {a}"):
        model.angles(swapped(DYNAMIC, a, b))


@pytest.mark.parametrize("wand, joint, reference", [("LTHI", "LKNE", "LASI"),
                                                    ("RTIB", "RANK", "RKNE")])
def test_a_wand_swapped_with_its_joint_marker_is_an_error(clean, wand, joint, reference):
    with pytest.raises(ValueError, match=rf"every frame .*{wand} is farther from "
                                         rf"{reference} than {joint} is"):
        clean[0].angles(swapped(DYNAMIC, wand, joint))


def test_a_ghost_marker_jumping_for_a_few_frames(clean):
    model, angles, _ = clean
    with pytest.warns(RuntimeWarning, match=r"5 of 323 frames .*jumped.*LANK in 5"):
        result = model.angles(moved(DYNAMIC, "LANK", [300.0, 0, 0], slice(60, 65)))
    assert result["ankle", "left"].iloc[60:65].isna().all().all()
    keep = np.r_[0:60, 65:len(DYNAMIC)]
    np.testing.assert_allclose(lower(result).iloc[keep], lower(angles).iloc[keep])


def test_jump_boundary_is_a_tenth_of_the_leg_length():
    rng = np.random.default_rng(3)
    base = {"LASI": [0, 120, 900], "RASI": [0, -120, 900], "LTHI": [40, 150, 650],
            "LKNE": [0, 160, 480], "LTIB": [40, 140, 300], "LANK": [0, 140, 80],
            "LTOE": [180, 120, 30]}
    points = {k: np.tile(np.array(v, float), (20, 1)) + rng.normal(0, 1, (20, 3))
              for k, v in base.items()}
    for name in ("RTHI", "RKNE", "RTIB", "RANK", "RTOE"):
        points[name] = points["L" + name[1:]] * [1, -1, 1]
    legs = {"L": 800.0, "R": 800.0}
    ghost = {k: v.copy() for k, v in points.items()}
    along = points["LTOE"][0] - points["LANK"][0]
    along /= np.linalg.norm(along)
    ghost["LTOE"][5] += 75.0 * along      # distance to LANK changes by < 80 mm: kept
    assert not checks.check_leg_distances(ghost, legs).any()
    ghost["LTOE"][6] += 85.0 * along      # by more than 80 mm: flagged, NaN
    with pytest.warns(RuntimeWarning, match="LTOE in 1"):
        flagged = checks.check_leg_distances(ghost, legs)
    assert flagged.tolist() == [i == 6 for i in range(20)]
    assert np.isnan(ghost["LTOE"][6]).all() and np.isfinite(ghost["LANK"][6]).all()


@pytest.mark.parametrize("marker, shift, match", [
    ("LKNE", "shank", r"LKNE \(LTHI-LKNE"),
    ("LKNE", "wand", r"LKNE \(LTHI-LKNE"),
    ("LTOE", "heel", r"LTOE \(LANK-LTOE"),
    ("LTHI", "medial", r"the thigh wands \d+ mm apart here, 414 in the static trial"),
])
def test_a_marker_placed_elsewhere_than_in_the_static_trial(clean, marker, shift, match):
    df = DYNAMIC
    if shift == "shank":       # 100 mm down the line to the ankle marker
        down = df["LANK"].to_numpy() - df["LKNE"].to_numpy()
        offset = 100.0 * down / np.linalg.norm(down, axis=1, keepdims=True)
    elif shift == "wand":
        offset = df["LTHI"].to_numpy() - df["LKNE"].to_numpy() + [0, 0, -20.0]
    elif shift == "heel":
        offset = df["LHEE"].to_numpy() - df["LTOE"].to_numpy() + [0, 0, 5.0]
    else:                      # 120 mm medially (towards RASI)
        right = df["RASI"].to_numpy() - df["LASI"].to_numpy()
        offset = 120.0 * right / np.linalg.norm(right, axis=1, keepdims=True)
    with pytest.raises(ValueError, match=rf"placed elsewhere than in the static trial: "
                                         rf".*{match}"):
        clean[0].angles(moved(df, marker, offset))


# -- the static trial --

@pytest.mark.parametrize("a, b, match", [
    ("LHEE", "LTOE", "LHEE is farther from LANK than LTOE is"),
    ("LHEE", "RHEE", "RHEE lies to the subject's left of LHEE"),
    ("LKNE", "RKNE", "RKNE lies to the subject's left of LKNE"),
])
def test_static_trial_swaps_are_errors(a, b, match):
    with pytest.raises(ValueError, match=rf"every frame of the static trial .*{match}"):
        plug_in_gait(swapped(STATIC, a, b), VSK)


# -- the lab's vertical --

def tilted(df, degrees):
    out = df.copy()
    xyz = df.to_numpy().reshape(len(df), -1, 3) @ rot_x(np.radians(degrees)).T
    out[:] = xyz.reshape(len(df), -1)
    return out


def test_lab_vertical_boundary_is_30_degrees():
    body = {"LASI": [0, 120, 900], "RASI": [0, -120, 900], "LANK": [0, 100, 80],
            "RANK": [0, -100, 80]}
    for degrees, warns in ((29.9, False), (30.1, True)):
        R = rot_x(np.radians(degrees))
        points = {k: (R @ np.array(v, float))[None] for k, v in body.items()}
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            angle = checks.check_lab_vertical(points)
        assert angle == pytest.approx(degrees)
        assert bool(caught) == warns


def test_a_tilted_lab_warns_and_changes_only_the_lab_relative_angles(clean):
    _, angles, _ = clean
    with pytest.warns(RuntimeWarning, match=r"the lab's vertical is not where the trial "
                                            r"says"), \
            pytest.warns(RuntimeWarning, match=r"the pelvis in the dynamic trial travels 26 "
                                               r"degrees from the lab axis"):
        result = plug_in_gait(tilted(STATIC, 40.0), VSK).angles(tilted(DYNAMIC, 40.0))
    joints = [c for c in angles.columns if c[0] in ("hip", "knee", "ankle")]
    np.testing.assert_allclose(result[joints], angles[joints], atol=1e-9)
    assert (result["pelvis"] - angles["pelvis"]).abs().max().max() > 30.0


def test_zero_points_as_missing_takes_only_points_with_all_three_coordinates_zero():
    """(0, 0, 0), any zero negative, is missing; a point with one or two zero coordinates
    or a NaN is kept as it is; the count and the warning name the marker."""
    rng = np.random.default_rng(5)
    values = rng.choice([0.0, -0.0, 1.5, np.nan], size=(400, 3), p=[0.5, 0.2, 0.2, 0.1])
    expected = values.copy()
    zero = (values == 0.0).all(axis=-1)
    expected[zero] = np.nan
    points = {"LKNE": np.asfortranarray(values), "RKNE": np.ones((400, 3))}
    with pytest.warns(RuntimeWarning, match=rf"LKNE in {zero.sum()} frames$"):
        assert checks.zero_points_as_missing(points, "the trial") == zero.sum() > 0
    assert np.array_equal(points["LKNE"], expected, equal_nan=True)
    assert np.array_equal(points["RKNE"], np.ones((400, 3)))
