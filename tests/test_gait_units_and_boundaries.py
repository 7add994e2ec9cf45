"""Issue 24, gait layer: one unit rule, one pelvis, validated arguments, pinned boundaries.

Oracles: the synthetic walk of data/gait/ (its events do not depend on how its units are
spelled, nor on a sacrum marker when both PSIS are mapped), the lower-limb pipeline's own
refusal of a trial without units, and signals whose gaps are placed frame by frame.
"""

import re
import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import (calibrate_lower_limb, derivative, force_plate_events, gait_events,
                           lowpass, read_c3d, read_trc, residual_analysis, time_normalize)

from helpers import ROOT

GAIT = ROOT / "data" / "gait"
ROLES = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
         "RHEEL": "RHEE", "RTOE": "RTOE", "RMT5": "RMT5",
         "LHEEL": "LHEE", "LTOE": "LTOE", "LMT5": "LMT5"}


def walk():
    return read_trc(GAIT / "walk.trc")


def quiet(function, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return function(*args, **kwargs)


def assert_same_events(got, expected):
    assert got.keys() == expected.keys()
    for side in expected:
        for event in expected[side]:
            np.testing.assert_array_equal(got[side][event], expected[side][event])


# --- finding 1: the units of the pipeline ----------------------------------------------------

@pytest.mark.parametrize("spelled", ["millimeters", "Millimetres", " MM "])
def test_spelled_out_millimetres_give_the_events_of_mm(spelled):
    trial = walk()
    assert trial.attrs["units"] == "mm"
    expected = quiet(gait_events, trial, ROLES)
    trial.attrs["units"] = spelled
    assert_same_events(quiet(gait_events, trial, ROLES), expected)


def test_spelled_out_metres_give_the_events_of_mm():
    trial = walk()
    expected = quiet(gait_events, trial, ROLES)
    metres = trial / 1000.0
    metres.attrs = dict(trial.attrs, units="metres")
    got = quiet(gait_events, metres, ROLES)
    for side in expected:
        for event in expected[side]:
            np.testing.assert_allclose(got[side][event], expected[side][event])


def test_a_trial_without_units_is_refused_as_by_the_pipeline():
    # the pipeline refuses it (a coordinate without a unit cannot meet the mm thresholds);
    # gait_events used to assume mm
    trial = walk()
    del trial.attrs["units"]
    message = r"has no units: set df.attrs\['units'\] to 'mm' or 'm'"
    with pytest.raises(ValueError, match="the dynamic trial " + message):
        gait_events(trial, ROLES)
    legs = read_trc(GAIT / "legs_static.trc")
    del legs.attrs["units"]
    roles = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI"}
    for p in "RL":
        roles.update({p + "THIGH": [p + "TH1", p + "TH2", p + "TH3", p + "TH4"],
                      p + "SHANK": [p + "TB1", p + "TB2", p + "TB3"],
                      p + "KNEE_LAT": p + "LFC", p + "KNEE_MED": p + "MFC",
                      p + "ANKLE_LAT": p + "LMAL", p + "ANKLE_MED": p + "MMAL"})
    with pytest.raises(ValueError, match="the static trial " + message), \
            warnings.catch_warnings():
        warnings.simplefilter("ignore")          # no foot frame: not what is tested
        calibrate_lower_limb(legs, roles)


# --- finding 2: one pelvis ----------------------------------------------------------------------

def with_sacrum(trial, offset):
    """`trial` with a SACR marker at the mid-PSIS moved by `offset` (mm), a sacrum marker
    placed off the midpoint (it sits on the skin over S2, not between the PSIS)."""
    mid = 0.5 * (trial["RPSI"].to_numpy() + trial["LPSI"].to_numpy()) + np.asarray(offset)
    sacrum = pd.DataFrame(mid, index=trial.index,
                          columns=pd.MultiIndex.from_product([["SACR"], ["x", "y", "z"]]))
    result = pd.concat([trial, sacrum], axis=1)
    result.attrs = dict(trial.attrs)
    return result


def test_a_mapping_with_sacrum_and_both_psis_uses_the_psis():
    trial = walk()
    expected = quiet(gait_events, trial, ROLES)
    # 80 mm to one side and a slow sway: a pelvis built on it would face another way
    # and move differently relative to the feet
    sway = 60 * np.sin(2 * np.pi * 0.7 * trial.index.to_numpy())[:, None] * [1, 0, 0]
    moved = with_sacrum(trial, sway + [0.0, 80.0, 0.0])
    got = quiet(gait_events, moved, dict(ROLES, SACRUM="SACR"))
    assert_same_events(got, expected)
    np.testing.assert_array_equal(got.progression, expected.progression)


def test_a_sacrum_alone_is_the_posterior_pelvis():
    trial = with_sacrum(walk(), [0.0, 0.0, 0.0])
    roles = {k: v for k, v in ROLES.items() if k not in ("RPSIS", "LPSIS")}
    got = quiet(gait_events, trial, dict(roles, SACRUM="SACR"))
    assert_same_events(got, quiet(gait_events, walk(), ROLES))


def test_one_psis_without_a_sacrum_names_the_posterior_roles():
    roles = {k: v for k, v in ROLES.items() if k != "LPSIS"}
    with pytest.raises(ValueError, match="the pelvis needs either the role 'SACRUM' or both "
                                         "'RPSIS' and 'LPSIS'"):
        gait_events(walk(), roles)


# --- finding 3: every argument through the validators of _checks -------------------------------

TIME = np.arange(0, 4.0, 0.01)
STRIKES = [0.5, 1.5, 2.5, 3.5]


@pytest.mark.parametrize("max_gap, error, shown", [
    ("a", TypeError, r"'a' \(str\)"), (None, TypeError, r"None \(NoneType\)"),
    (True, TypeError, r"True \(bool\)"), ([0.1], ValueError, r"\[0.1\] \(list\)"),
    (np.nan, ValueError, "nan"), (np.inf, ValueError, "inf"), (-1, ValueError, "-1"),
    (-1e-9, ValueError, "-1e-09")])
def test_max_gap_names_the_argument_the_value_and_what_is_expected(max_gap, error, shown):
    # max_gap='a' gave numpy's "ufunc 'isfinite' not supported"
    with pytest.raises(error, match=r"max_gap must be a time \(s\) >= 0; got " + shown):
        time_normalize(np.sin(TIME), STRIKES, time=TIME, max_gap=max_gap)


def test_max_gap_zero_is_a_time():
    out = time_normalize(np.sin(TIME), STRIKES, time=TIME, max_gap=0)
    assert np.isfinite(out).all()


@pytest.mark.parametrize("n_points, error, shown", [
    (True, TypeError, r"True \(bool\)"), (5.0, TypeError, r"5.0 \(float\)"),
    ("5", TypeError, r"'5' \(str\)"), (None, TypeError, "None"), (1, ValueError, "1"),
    (np.int64(1), ValueError, "1")])
def test_n_points_names_the_argument_the_value_and_what_is_expected(n_points, error, shown):
    with pytest.raises(error, match=r"n_points must be an integer >= 2; got " + shown):
        time_normalize(np.sin(TIME), STRIKES, time=TIME, n_points=n_points)


def test_n_points_of_numpy_integer_type_is_accepted():
    assert time_normalize(np.sin(TIME), STRIKES, time=TIME, n_points=np.int32(5)).shape == (3, 5)


@pytest.mark.parametrize("gait, error", [("jogging", ValueError), ("Walking", ValueError),
                                         (None, TypeError), (1, TypeError),
                                         (["walking"], TypeError)])
def test_gait_names_the_argument_the_value_and_what_is_expected(gait, error):
    with pytest.raises(error, match=r"gait must be 'auto' or 'walking' or 'running'; got "
                                    + re.escape(repr(gait))):
        gait_events(walk(), ROLES, gait=gait)


@pytest.mark.parametrize("cutoff, error, message", [
    (True, TypeError, r"cutoff must be a numeric array; got booleans"),
    ("6", TypeError, r"cutoff must be a numeric array; got '6'"),
    (-6, ValueError, r"cutoff must be a positive number; got -6"),
    (60, ValueError, r"cutoff must be between 0 and half the sampling rate \(50 Hz\); "
                     r"got 60")])
def test_cutoff_of_gait_events_names_the_argument(cutoff, error, message):
    with pytest.raises(error, match=message):
        gait_events(walk(), ROLES, cutoff=cutoff)


@pytest.mark.parametrize("markers", [None, ["RHEE"], "RHEE"])
def test_force_plate_events_refuses_markers_that_are_no_mapping(markers, tmp_path):
    with pytest.raises(TypeError, match=r"markers must be a dict mapping roles to labels .*"
                                        + type(markers).__name__):
        force_plate_events(tmp_path / "walk.c3d", markers)


@pytest.mark.parametrize("call, error, message", [
    (lambda x: lowpass(x, 6, rate=100, order=2.0), TypeError,
     r"order must be a whole number from 1 to 20 \(the Butterworth filter's order per "
     r"pass\); got 2.0 \(float\)"),
    (lambda x: lowpass(x, 6, rate=100, passes=np.float64(2)), TypeError,
     r"passes must be a whole number from 2 to 20 .*; got np.float64\(2.0\)|"
     r"passes must be a whole number from 2 to 20 .*; got 2.0"),
    (lambda x: derivative(x, 100, order="1"), TypeError,
     r"order must be 1 \(velocity\) or 2 \(acceleration\); got '1' \(str\)"),
    (lambda x: derivative(x, 100, order=0), ValueError,
     r"order must be 1 \(velocity\) or 2 \(acceleration\); got 0"),
    (lambda x: residual_analysis(x, rate=100, cutoffs=[3.0, 2.0, 1.0]), ValueError,
     r"cutoffs must be increasing, each value once; got \[3.0, 2.0, 1.0\]"),
])
def test_filtering_arguments_name_the_argument_the_value_and_what_is_expected(call, error,
                                                                              message):
    with pytest.raises(error, match=message):
        call(np.zeros((50, 3)))


# --- finding 4: the boundaries of time_normalize, frame by frame ------------------------------

def cycles_with_gap(gap, strikes=(50, 150, 250, 350), rate=100.0, **options):
    """time_normalize of a sine of 4 s at `rate` with frames `gap` (a range) NaN, between
    heel strikes at the frames (or fractional frames) `strikes`; which of the three
    cycles are NaN."""
    time = np.arange(int(round(4 * rate))) / rate
    signal = np.sin(2 * np.pi * time)
    signal[list(gap)] = np.nan
    out = time_normalize(signal, np.asarray(strikes) / rate, time=time, **options)
    assert (np.isnan(out).all(axis=1) | np.isfinite(out).all(axis=1)).all()
    return [int(k) for k in np.flatnonzero(np.isnan(out).all(axis=1))]


@pytest.mark.parametrize("gap, nan_cycles", [
    (range(150, 160), [0, 1]),     # starts at cycle 0's closing heel strike: both touched
    (range(151, 161), [1]),        # starts one frame after it: cycle 0 never reads it
    (range(140, 150), [0]),        # ends one frame before cycle 1's opening heel strike
    (range(141, 151), [0, 1]),     # ends at it
])
def test_a_long_gap_touching_a_heel_strike_frame_makes_its_cycles_nan(gap, nan_cycles):
    # 10 frames (0.1 s) against max_gap 0.05 s: a long gap
    assert cycles_with_gap(gap) == nan_cycles


@pytest.mark.parametrize("gap, nan_cycles", [
    (range(151, 161), [0, 1]),     # the heel strike at 150.5 reads frame 151
    (range(152, 162), [1]),
    (range(140, 150), [0]),        # cycle 1 opens after frame 150, which it reads
    (range(140, 151), [0, 1]),
])
def test_a_long_gap_next_to_a_heel_strike_between_frames(gap, nan_cycles):
    assert cycles_with_gap(gap, strikes=(50, 150.5, 250, 350)) == nan_cycles


@pytest.mark.parametrize("rate", [50.0, 100.0, 120.0, 150.0, 200.0, 250.0])
@pytest.mark.parametrize("frames", [1, 3, 6])
def test_a_gap_of_exactly_max_gap_is_bridged_and_one_frame_more_is_not(rate, frames):
    # documented: max_gap is the longest run of missing samples interpolated over; a run
    # of n missing frames lasts n / rate s
    middle = int(rate)                             # 1 s: inside cycle 0 (0.5 to 1.5 s)
    strikes = (0.5 * rate, 1.5 * rate, 2.5 * rate, 3.5 * rate)
    gap = range(middle, middle + frames)
    longer = range(middle, middle + frames + 1)
    assert cycles_with_gap(gap, strikes, rate, max_gap=frames / rate) == []
    assert cycles_with_gap(longer, strikes, rate, max_gap=frames / rate) == [0]
    # and in seconds: just below the gap's length, it is not bridged
    assert cycles_with_gap(gap, strikes, rate, max_gap=frames / rate - 1e-6) == [0]


# --- finding 7: Zeni's events alone through a documented argument ---------------------------

def leg_roles():
    roles = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
             "PELVIS": ["PEL1", "PEL2", "PEL3"]}
    for p in "RL":
        roles.update({p + "ANKLE_LAT": p + "LMAL", p + "HEEL": p + "HEEL",
                      p + "TOE": p + "TOE", p + "MT5": p + "MT5"})
    return roles


def test_refine_false_gives_the_events_of_a_foot_that_never_rests_on_a_floor():
    # the two-leg trial has no floor: its events are Zeni's on both sides (warned)
    legs = read_trc(GAIT / "legs_walk.trc")
    with pytest.warns(RuntimeWarning, match="feet never rest on a floor"):
        floorless = gait_events(legs, leg_roles())
    with warnings.catch_warnings():
        warnings.simplefilter("error")               # nothing to warn about: asked for
        alone = gait_events(legs, leg_roles(), refine=False)
    assert_same_events(alone, floorless)
    assert alone.markers == floorless.markers
    assert alone.method == "Zeni et al. (2008) alone on the right and left side (refine=False)"


def test_refine_false_on_a_trial_with_a_floor_differs_from_the_refined_events():
    trial = walk()
    refined = quiet(gait_events, trial, ROLES)
    alone = quiet(gait_events, trial, ROLES, refine=False)
    assert "Zeni et al. (2008) alone" not in refined.method
    # Zeni's heel strike precedes contact (the heel's forward maximum): earlier here
    assert np.median(alone["right"]["heel_strike"][:4] - refined["right"]["heel_strike"][:4]) < 0


@pytest.mark.parametrize("refine", ["False", 0, None, np.array([True])])
def test_refine_must_be_a_flag(refine):
    with pytest.raises(TypeError, match="refine must be True or False; got"):
        gait_events(walk(), ROLES, refine=refine)


def test_the_validation_tool_patches_nothing_private():
    source = (ROOT / "tools" / "validate_gait_events.py").read_text()
    assert "mock" not in source and "gait_cycles._" not in source


# --- finding 6: one filter; gait_events designs its own, filtering runs it --------------------

def test_filter_runs_is_scipy_filtfilt_run_by_run_with_its_default_padding():
    # the filter gait_events was validated with: butter(2, 15 Hz) uncorrected, filtfilt's
    # default odd padding of 3 * max(len(a), len(b)) = 9 frames, runs of 9 frames or fewer
    # left out; scipy's transfer-function filtfilt is the independent oracle
    from scipy.signal import butter, filtfilt
    from bmc_functions.markers.filtering import filter_runs
    rng = np.random.default_rng(24)
    rate, cutoff = 100.0, 15.0
    values = np.cumsum(rng.normal(size=(300, 3)), axis=0)
    values[100:104, 0] = np.nan                 # runs 0-99 and 104-299
    values[10:291, 1] = np.nan                  # runs of 10 and 9 frames: the 9 is not filtered
    filtered, done = filter_runs(values, butter(2, cutoff, fs=rate, output="sos"))
    b, a = butter(2, cutoff / (0.5 * rate))
    for column, runs in ((0, [(0, 100), (104, 300)]), (1, [(0, 10)]), (2, [(0, 300)])):
        for start, stop in runs:
            np.testing.assert_allclose(filtered[start:stop, column],
                                       filtfilt(b, a, values[start:stop, column]),
                                       rtol=0, atol=1e-9)
            assert done[start:stop, column].all()
    assert not done[291:, 1].any()
    np.testing.assert_array_equal(filtered[291:, 1], values[291:, 1])   # kept as they were
    assert np.isnan(filtered[100:104, 0]).all() and not done[100:104, 0].any()


# --- boundaries the mutation sample found unpinned ---------------------------------------------

def test_compare_events_finds_an_event_exactly_tolerance_away():
    # documented: found when a detected event lies within `tolerance` s (binary-exact times)
    from bmc_functions import compare_events
    reference = {"right": {"heel_strike": np.array([1.0]), "toe_off": np.array([2.0])}}
    detected = {"right": {"heel_strike": np.array([1.125]), "toe_off": np.array([1.875])}}
    found = compare_events(detected, reference, tolerance=0.125)
    assert found["found"].tolist() == [1, 1, 1, 1]
    missed = compare_events(detected, reference, tolerance=0.124)
    assert missed["found"].tolist() == [0, 0, 0, 0]


def feet_together(shift):
    """The synthetic walk with the left foot replaced by the right one `shift` frames
    later, mirrored about the pelvis's midline: heel strikes `shift` / 100 s apart."""
    trial = walk()
    centre = 0.5 * (trial["RASI"]["y"].to_numpy() + trial["LASI"]["y"].to_numpy())
    for right, left in (("RHEE", "LHEE"), ("RTOE", "LTOE")):
        for coord in "xyz":
            values = trial[right][coord].to_numpy()
            if coord == "y":
                values = 2 * centre - values
            trial[(left, coord)] = np.r_[np.full(shift, np.nan), values[:-shift]]
    return trial


@pytest.mark.parametrize("shift, warned", [(3, True), (7, True), (9, False), (12, False)])
def test_heel_strikes_within_min_step_of_the_other_side_are_warned(shift, warned):
    # documented: right and left heel strikes closer than 80 ms land together (a jump)
    roles = {k: v for k, v in ROLES.items() if not k.endswith("MT5")}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        events = gait_events(feet_together(shift), roles)
    gap = np.abs(events["left"]["heel_strike"] - events["right"]["heel_strike"])
    assert np.abs(gap - shift / 100).max() <= 0.0101      # a frame at the trial's end
    assert (gap.min() < 0.08) == warned
    together = [w for w in caught if "come within 80 ms of a left one" in str(w.message)]
    assert bool(together) == warned
    if warned:
        assert str(together[0].message).startswith("5 of 5 right heel strikes")


CODA = ROOT.parent / "shared" / "data" / "force_plates" / "codamotion_gaitwands_20150204.c3d"


@pytest.mark.skipif(not CODA.exists(), reason="../shared/data absent")
def test_a_contact_of_exactly_min_contact_is_kept():
    # documented: contacts of min_contact s or longer are kept; the shortest contact of
    # the walk decides, within half an analog sample either side
    import ezc3d
    import sys
    sys.path.insert(0, str(ROOT / "tools"))
    import validate_gait_events as validation
    roles = validation.TRIALS["codamotion walk"][1]
    rate = float(ezc3d.c3d(str(CODA), extract_forceplat_data=False)
                 ["parameters"]["ANALOG"]["RATE"]["value"][0])
    contacts = quiet(force_plate_events, CODA, roles).contacts
    samples = min(int(round((end - start) * rate)) + 1 for _, _, start, end in contacts)
    kept = quiet(force_plate_events, CODA, roles, min_contact=(samples - 0.5) / rate)
    assert len(kept.contacts) == len(contacts)
    dropped = quiet(force_plate_events, CODA, roles, min_contact=(samples + 0.5) / rate)
    assert len(dropped.contacts) == len(contacts) - 1


@pytest.mark.skipif(not CODA.exists(), reason="../shared/data absent")
@pytest.mark.parametrize("outside, whose", [(30.0, "right"), (70.0, None)])
def test_a_foot_within_plate_margin_of_the_plate_edge_is_on_it(outside, whose):
    # documented: the foot is on a plate when its markers' mean lies over the plate within
    # PLATE_MARGIN (50 mm) of its edges. Plate 1 of the walk spans y = -2 to 461 mm; the
    # right foot stands on it from 0.388 to 1.091 s at y = 150 mm: moved sideways to lie
    # 30 mm beyond the edge it is still on the plate, 70 mm beyond it is on no plate
    import sys
    sys.path.insert(0, str(ROOT / "tools"))
    import validate_gait_events as validation
    roles = validation.TRIALS["codamotion walk"][1]
    trial = quiet(read_c3d, CODA)
    labels = [roles[role] for role in ("RHEEL", "RTOE", "RANKLE_LAT")]
    time = trial.index.to_numpy()
    middle = (time >= 0.388 + 0.25 * 0.703) & (time <= 0.388 + 0.75 * 0.703)
    lateral = np.nanmean(np.mean([trial[label]["y"].to_numpy() for label in labels],
                                 axis=0)[middle])
    for label in labels:
        trial[(label, "y")] = trial[label]["y"] + (-2.0 - outside - lateral)
    contacts = quiet(force_plate_events, CODA, roles, trial=trial).contacts
    assert contacts[0][:2] == (1, whose)
