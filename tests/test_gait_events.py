"""Gait events against force plates, and the trials whose events cannot be trusted.

Oracles: the force plates of the real trials in ../shared/data (the vertical force, read
here from the raw analog channels with ezc3d, independently of force_plate_events); the
exact events of the synthetic trials of data/gait; trials made from them whose defect is
known (reversed in time, feet swapped, both feet together, stairs).
"""

import io
import sys
import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import compare_events, force_plate_events, gait_events, read_c3d, read_trc

from helpers import ROOT, SHARED_DATA, skip_without_shared

# The synthetic walk of data/gait/ hides one left heel strike in a gap of its heel marker on
# purpose (data/README.md); gait_events says so ("events seem missing"). Tests of that
# warning use pytest.warns, which sees it whatever this filter says.
pytestmark = pytest.mark.filterwarnings(
    "ignore:events seem missing. left heel strikes:RuntimeWarning")

sys.path.insert(0, str(ROOT / "tools"))
import validate_gait_events as validation  # noqa: E402

CODA = SHARED_DATA / "force_plates" / "codamotion_gaitwands_20150204.c3d"
PIG = SHARED_DATA / "plug_in_gait" / "Movement_trial.c3d"
CODA_ROLES = validation.TRIALS["codamotion walk"][1]
PIG_ROLES = validation.TRIALS["PiG stair descent"][1]
ROLES = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
         "RHEEL": "RHEE", "RTOE": "RTOE", "RMT5": "RMT5",
         "LHEEL": "LHEE", "LTOE": "LTOE", "LMT5": "LMT5"}
needs_shared = pytest.mark.skipif(not CODA.exists(), reason="../shared/data absent")


def synthetic(name):
    return read_trc(ROOT / "data" / "gait" / f"{name}.trc")


def quiet(function, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return function(*args, **kwargs)


# --- force-plate events ---------------------------------------------------------------------

def raw_vertical_onsets(path, threshold):
    """Per plate, the first and last analog sample (s) above `threshold` of the raw FZ
    channel minus its median: no filter, no frame change (the plates here are level)."""
    import ezc3d
    c3d = ezc3d.c3d(str(path))
    rate = float(c3d["parameters"]["ANALOG"]["RATE"]["value"][0])
    channels = np.asarray(c3d["parameters"]["FORCE_PLATFORM"]["CHANNEL"]["value"])
    analogs = c3d["data"]["analogs"][0]
    out = []
    for plate in range(channels.shape[1]):
        fz = analogs[channels[2, plate] - 1]
        fz = np.abs(fz - np.median(fz))
        # the longest run above the threshold
        above = np.flatnonzero(fz > threshold)
        runs = np.split(above, np.flatnonzero(np.diff(above) > 0.02 * rate) + 1)
        run = max(runs, key=len)
        out.append((run[0] / rate, run[-1] / rate))
    return out


@needs_shared
@pytest.mark.parametrize("path, roles, sides", [
    (CODA, CODA_ROLES, ["right", "left", "right", "left"]),
    (PIG, PIG_ROLES, ["left", "right", "left", "right"])])
def test_force_plate_events_against_the_raw_channels(path, roles, sides):
    events = quiet(force_plate_events, path, roles)
    raw = raw_vertical_onsets(path, 50.0)       # well above the noise of the raw channels
    assert [side for _, side, _, _ in events.contacts] == sides
    for (plate, side, start, end), (raw_start, raw_end) in zip(events.contacts, raw):
        # 20 N on the filtered force and 50 N on the raw one: within a few ms
        assert abs(raw_start - start) < 0.015 and abs(end - raw_end) < 0.015, plate
    assert events.gait is None and "force plates" in events.method


@needs_shared
def test_a_contact_cut_by_the_end_of_the_recording_has_no_foot_off():
    events = quiet(force_plate_events, PIG, PIG_ROLES)
    # plate 1 is still loaded in the last frame (2.69 s): a foot strike, no foot off
    assert events["left"]["heel_strike"].size == 2 and events["left"]["toe_off"].size == 1
    assert events["right"]["heel_strike"].size == 2 and events["right"]["toe_off"].size == 2


def test_force_plate_events_bad_input(tmp_path):
    ezc3d = pytest.importorskip("ezc3d")
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [100.0]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = ("RHEE",)
    c3d["data"]["points"] = np.ones((4, 1, 10))
    c3d.write(str(tmp_path / "no_plates.c3d"))
    with pytest.raises(ValueError, match="no force plate in the file"):
        force_plate_events(tmp_path / "no_plates.c3d", {"RHEEL": "RHEE"})
    if CODA.exists():
        with pytest.raises(ValueError, match="threshold must be a positive"):
            force_plate_events(CODA, CODA_ROLES, threshold=-5)
        with pytest.raises(ValueError, match="no foot role"):
            force_plate_events(CODA, {"RASIS": "R.ASIS"})


def test_compare_events_by_hand():
    reference = {"right": {"heel_strike": np.array([1.0, 2.0, 3.0]),
                           "toe_off": np.array([1.6])},
                 "left": {"heel_strike": np.array([1.5]), "toe_off": np.array([])}}
    detected = {"right": {"heel_strike": np.array([0.99, 2.04, 3.5]),
                          "toe_off": np.array([1.62])}}
    table = compare_events(detected, reference, tolerance=0.05, trial="t")
    rows = {(r["side"], r["event"]): r for _, r in table.iterrows()}
    assert rows["right", "heel_strike"]["found"] == 2
    assert rows["right", "heel_strike"]["median_ms"] == pytest.approx(25.0)
    assert rows["right", "heel_strike"]["max_ms"] == pytest.approx(40.0)
    assert rows["right", "heel_strike"]["bias_ms"] == pytest.approx(15.0)
    assert rows["left", "heel_strike"]["found"] == 0       # no left side detected
    assert rows["both", "heel_strike"]["reference"] == 4
    assert rows["both", "heel_strike"]["found_%"] == 50.0
    assert ("left", "toe_off") not in rows                   # nothing to find
    assert (table.trial == "t").all()
    with pytest.raises(ValueError, match="tolerance must be a positive"):
        compare_events(detected, reference, tolerance=0)


# --- the target: events within 30 ms (median) and 45 ms (max) of the force plates --------

@needs_shared
def test_marker_events_match_the_force_plates_at_every_rate_with_and_without_heel():
    table = validation.event_table(steps=(1, 2, 4), heel=(True, False))
    walk = table[(table.trial == "codamotion walk") & (table.side == "both")]
    assert sorted(set(walk.rate)) == [50, 100, 200] and len(walk) == 12
    assert (walk["found_%"] >= 85).all(), walk
    assert (walk["median_ms"] <= 30).all() and (walk["max_ms"] <= 45).all(), walk
    # no warning, except the true one where the lateral malleolus times the heel strikes
    # (no heel marker): a 3-frame gap of R.Ankle at 3.85 s drops the right heel strike
    # between the plates' (round-2 adversarial pass: it was dropped without a word)
    warned = walk["warning"] != ""
    assert (walk.loc[warned, "heel"] == "no").all(), walk
    assert walk.loc[warned, "warning"].str.startswith(
        "events seem missing: right heel strikes").all(), walk
    # the stair descent gets its events (within 20 ms median) and a warning that says
    # the ground is not level
    stairs = table[(table.trial == "PiG stair descent") & (table.side == "both")]
    assert stairs["warning"].str.contains("the feet land at heights").all()
    assert (stairs["median_ms"] <= 20).all()


def test_the_stored_force_plate_table_equals_a_fresh_one():
    # data/real/gait_events_vs_force_plates.csv (notebook 10) is derived from a file that may
    # not be copied into the repository; recomputed from ../shared, it must be the same
    skip_without_shared("force_plates/codamotion_gaitwands_20150204.c3d")
    fresh = pd.read_csv(io.StringIO(validation.stored_table().to_csv(index=False)))
    pd.testing.assert_frame_equal(fresh, pd.read_csv(validation.STORED))


def test_the_stored_force_plate_table_shows_the_refinement():
    # what notebook 10 reads from it: every event found; gait_events within the target,
    # Zeni's heel strikes alone 50 ms or more early at every rate
    table = pd.read_csv(validation.STORED)
    both = table[table.side == "both"]
    assert len(table) == 72 and (table["found_percent"] == 100).all()
    ours = both[both.method == "gait_events"]
    assert (ours["median_ms"] <= 30).all() and (ours["max_ms"] <= 45).all()
    zeni = both[(both.method == "Zeni alone") & (both.event == "heel_strike")]
    assert len(zeni) == 6 and (zeni["bias_ms"] <= -50).all()


def test_synthetic_events_at_rates_from_50_to_250_hz():
    table = validation.synthetic_table(rates=(50, 60, 100, 250), heel=(True,))
    both = table[table.side == "both"]
    # within 30 ms or two frames (issue 31's target: 3 frames or 45 ms); the running
    # toe-off at 50 Hz is 31 ms early (23 ms before the cut-off took lowpass's meaning)
    two_frames = 2000.0 / both["rate"]
    assert (both["found_%"] >= 85).all(), both
    assert (both["median_ms"] <= two_frames.clip(lower=30)).all(), both
    assert (both["max_ms"] <= 45).all(), both
    # the walk's one warning is true: its gap hides a left heel strike (walk_events.csv,
    # in_gap), which the detector drops; the run has none
    warned = both["warning"] != ""
    assert (both.loc[warned, "trial"] == "synthetic walk").all(), both
    assert both.loc[warned, "warning"].str.startswith(
        "events seem missing: left heel strikes (3 against 5 toe offs").all(), both


def test_without_heel_the_lateral_malleolus_times_the_heel_strike():
    if not CODA.exists():
        pytest.skip("../shared/data absent")
    roles = {k: v for k, v in CODA_ROLES.items() if not k.endswith("HEEL")}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        events = gait_events(quiet(read_c3d, CODA), roles)
    assert events.markers["right"] == {"heel_strike": ["R.Ankle"], "toe_off": ["R.Toe"]}
    assert "Hreljac & Marshall (2000)" in events.method


def test_without_heel_or_ankle_the_forefoot_times_the_heel_strike_with_a_warning():
    roles = {k: v for k, v in ROLES.items() if not k.endswith("HEEL")}
    with pytest.warns(RuntimeWarning, match="no heel or lateral malleolus marker on the right "
                                            "and left side"):
        events = gait_events(synthetic("walk"), roles)
    assert set(events.markers["right"]["heel_strike"]) <= {"RTOE", "RMT5"}


def test_an_mt5_serves_as_the_toe():
    roles = {k: v for k, v in ROLES.items() if k not in ("RTOE", "LTOE")}
    events = quiet(gait_events, synthetic("walk"), roles)
    assert events.markers["left"]["toe_off"] == ["LMT5"]
    assert len(events["left"]["toe_off"]) == 5


# --- trials whose events would be wrong: refused or warned --------------------------------

def reversed_in_time(markers):
    out = pd.DataFrame(markers.to_numpy()[::-1], index=markers.index, columns=markers.columns)
    out.attrs = dict(markers.attrs)
    return out


@pytest.mark.parametrize("name", ["walk", "run"])
def test_a_trial_reversed_in_time_is_refused(name):
    # overground walk and treadmill run: played backwards, the body travels against the
    # way it faces, and foot offs would come out as foot strikes
    with pytest.raises(ValueError, match=r"travels backwards relative to the supporting "
                                         r"foot \(median \d+ mm/s .* walking backwards, a "
                                         r"trial reversed in time"):
        gait_events(reversed_in_time(synthetic(name)), ROLES)


@needs_shared
def test_a_real_trial_reversed_in_time_is_refused():
    with pytest.raises(ValueError, match="travels backwards"):
        gait_events(reversed_in_time(quiet(read_c3d, CODA)), CODA_ROLES)


def _mirrored(markers, axis):
    out = markers.copy()
    for label in out.columns.get_level_values(0).unique():
        out[(label, "xyz"[axis])] = -out[(label, "xyz"[axis])]
    out.attrs = dict(markers.attrs)
    return out


def _labels_swapped(markers):
    swap = {label: {"R": "L", "L": "R"}.get(label[0], "") + label[1:]
            for label in markers.columns.get_level_values(0).unique()}
    out = markers.rename(columns=swap, level=0)
    out.attrs = dict(markers.attrs)
    return out


@pytest.mark.parametrize("name", ["walk", "run"])
@pytest.mark.parametrize("mistake", ["lateral axis reversed", "every R/L label swapped"])
def test_a_mirror_image_of_a_body_is_refused(name, mistake):
    # the walk's lateral axis is y, the run's z: reversing it (or swapping every label) is a
    # reflection; the feet stay on the pelvis's sides, so only the handedness can tell, and
    # each foot's events would be given to the other side
    trial = synthetic(name)
    bad = (_mirrored(trial, 1 if name == "walk" else 2) if mistake.startswith("lateral")
           else _labels_swapped(trial))
    with pytest.raises(ValueError, match=r"the body is a mirror image: .* points towards the "
                                         r"feet in 100% of the frames.* Every right and left "
                                         r"label is swapped, or one lab axis is reversed"):
        quiet(gait_events, bad, ROLES)
    # the same trial as recorded is a body (no error)
    assert quiet(gait_events, trial, ROLES).gait in ("walking", "running")


@needs_shared
def test_a_real_mirrored_trial_is_refused():
    with pytest.raises(ValueError, match="the body is a mirror image"):
        gait_events(_mirrored(quiet(read_c3d, CODA), 0), CODA_ROLES)


@pytest.mark.parametrize("swap", [("HEEL", "TOE", "MT5"), ("HEEL",)])
def test_foot_markers_swapped_between_sides_are_refused(swap):
    roles = dict(ROLES)
    for role in swap:
        roles["R" + role], roles["L" + role] = ROLES["L" + role], ROLES["R" + role]
    with pytest.raises(ValueError, match=r"foot markers on the wrong side of the pelvis: "
                                         r"LHEE \(right heel .*\) lies \d+ mm to the "
                                         r"subject's left.* swapped"):
        quiet(gait_events, synthetic("walk"), roles)   # the heel-only swap also warns


def test_both_feet_landing_together_warn():
    # a two-footed hop made from the walk: the left foot follows the right one, 160 mm to
    # its side
    markers = synthetic("walk").copy()
    for label in ("HEE", "TOE", "MT5"):
        moved = markers["R" + label].to_numpy().copy()
        moved[:, 1] += 160.0 * np.sign(markers["LHEE"]["y"].mean() - markers["RHEE"]["y"].mean())
        markers["L" + label] = moved
    with pytest.warns(RuntimeWarning, match=r"\d+ of \d+ right heel strikes come within 80 ms "
                                            r"of a left one: both feet land together"):
        gait_events(markers, ROLES, gait="walking")


@needs_shared
def test_a_stair_descent_warns():
    with pytest.warns(RuntimeWarning, match=r"the feet land at heights \d+ mm apart .* "
                                            r"stairs, a slope or a step"):
        events = gait_events(quiet(read_c3d, PIG), PIG_ROLES)
    assert events.markers["left"]["toe_off"] == ["LTOE"]


# --- adversarial pass, round 2 (tools/adversarial_pass_round2.py) ----------------------------

def _with_index(df, index):
    out = df.copy()
    out.index = index
    out.attrs = dict(df.attrs)
    return out


@pytest.mark.parametrize("index, shown", [(lambda t: t * 1000, "steps by 10"),
                                          (lambda t: np.arange(1, len(t) + 1), "steps by 1:")])
def test_a_time_index_in_ms_or_frames_is_refused(index, shown):
    """An index in ms read as s made every stride 1000 times too slow: no events and a
    'standing trial' warning that blamed the subject."""
    walk = synthetic("walk")
    with pytest.raises(ValueError, match=rf"dynamic.index \(time\) {shown}.*ms or frame "
                                         r"numbers"):
        gait_events(_with_index(walk, index(walk.index.to_numpy())), ROLES)


@pytest.mark.parametrize("factor, units", [(0.001, "mm"), (1.0, "m"), (10.0, "mm")])
def test_coordinates_in_other_units_than_stated_are_refused(factor, units):
    walk = synthetic("walk") * factor
    walk.attrs = dict(synthetic("walk").attrs, units=units)
    with pytest.raises(ValueError, match=rf"the pelvis lies .* mm above the feet .* "
                                         rf"'{units}' .*are the units right"):
        gait_events(walk, ROLES)


def test_stated_units_other_than_mm_give_the_same_events():
    walk = synthetic("walk")
    expected = quiet(gait_events, walk, ROLES)
    for factor, units in ((0.1, "cm"), (0.001, "m")):
        scaled = walk * factor
        scaled.attrs = dict(walk.attrs, units=units)
        got = quiet(gait_events, scaled, ROLES)
        for side in expected:
            for event in expected[side]:
                np.testing.assert_allclose(got[side][event], expected[side][event])


@pytest.mark.parametrize("cutoff", ["high", [6], None])
def test_a_cutoff_that_is_no_number_names_cutoff(cutoff):
    if cutoff is None:
        quiet(gait_events, synthetic("walk"), ROLES, cutoff=None)      # the default
        return
    with pytest.raises(ValueError, match="cutoff"):
        gait_events(synthetic("walk"), ROLES, cutoff=cutoff)


def test_a_rate_below_the_validated_range_warns():
    walk = synthetic("walk").iloc[::3].copy()                           # 33 Hz
    walk.attrs["rate"] = 100 / 3                        # (else: a warning that it is stale)
    with pytest.warns(RuntimeWarning, match=r"sampled at 33.3 Hz, below the 45 Hz"):
        gait_events(walk, ROLES)


def test_events_dropped_by_gaps_are_reported():
    """Gaps over every right heel strike drop them (never interpolated): the user is told
    instead of getting a side with fewer events."""
    walk = synthetic("walk")
    truth = pd.read_csv(ROOT / "data" / "gait" / "walk_events.csv")
    for time in truth[(truth.side == "right") & (truth.event == "heel_strike")].time:
        walk.loc[time - 0.03:time + 0.03, "RHEE"] = np.nan
    with pytest.warns(RuntimeWarning, match=r"events seem missing: right heel strikes "
                                            r"\(0 against 4 toe offs\)"):
        events = gait_events(walk, ROLES)
    assert events["right"]["heel_strike"].size == 0


@needs_shared
def test_a_gap_of_the_lateral_malleolus_does_not_drop_a_heel_strike_the_heel_times():
    """R.Ankle has 3 missing frames at 3.85 s in the real walk: the heel strike there
    (timed by the heel, which lands first) was dropped without a word."""
    trial = quiet(read_c3d, CODA)
    assert trial.loc[3.80:3.90, "R.Ankle"].isna().any(axis=1).sum() > 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        events = gait_events(trial, CODA_ROLES)
    strikes = events["right"]["heel_strike"]
    assert np.any((strikes > 3.8) & (strikes < 4.0)), strikes
    assert np.all(np.diff(strikes) < 1.4), strikes       # one stride apart, none missing


def test_a_gait_given_against_the_pelvis_motion_warns():
    with pytest.warns(RuntimeWarning, match=r"gait='running' was given, but the pelvis's "
                                            r"vertical motion says walking"):
        gait_events(synthetic("walk"), ROLES, gait="running")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gait_events(synthetic("run"), ROLES, gait="running")       # agrees: no warning


def test_compare_events_checks_its_inputs():
    reference = {"right": {"heel_strike": np.array([1.0, 2.1]), "toe_off": np.array([])}}
    with pytest.raises(TypeError, match="detected must be a dict side"):
        compare_events([1.0, 2.1], reference)
    with pytest.raises(ValueError, match=r"detected\['right'\]\['heel_strike'\] must hold "
                                         r"finite times"):
        compare_events({"right": {"heel_strike": [np.nan, 1.0]}}, reference)
    with pytest.warns(RuntimeWarning, match=r"differ by a factor of 1e\+03.*ms"):
        compare_events({"right": {"heel_strike": [1000.0, 2100.0]}}, reference)


@needs_shared
def test_force_plate_events_refuses_a_trial_of_another_file_and_warns_when_unloaded():
    with pytest.raises(ValueError, match=r"trial: its rate \(100.0 Hz\) is not the marker "
                                         r"rate"):
        force_plate_events(CODA, CODA_ROLES, trial=synthetic("walk"))
    static = SHARED_DATA / "plug_in_gait" / "Static_trial.c3d"
    with pytest.warns(RuntimeWarning, match="no foot contact on any of the 4 force plates"):
        events = force_plate_events(static, {"RHEEL": "RHEE", "RTOE": "RTOE"})
    assert events["right"]["heel_strike"].size == 0


def test_a_foot_marker_never_seen_is_left_out_with_a_warning():
    """RTOE mapped but NaN in every frame dropped every right event in silence (its gap
    touched every window)."""
    walk = synthetic("walk")
    walk["RTOE"] = np.nan
    with pytest.warns(RuntimeWarning, match=r"RTOE never seen \(every frame NaN\): left out"):
        events = gait_events(walk, ROLES)
    assert events.markers["right"]["toe_off"] == ["RMT5"]         # the MT5 takes its place
    assert events["right"]["heel_strike"].size >= 4
    walk["RMT5"] = np.nan
    with pytest.warns(RuntimeWarning, match=r"the right side has no forefoot marker left"):
        events = gait_events(walk, ROLES)
    assert "right" not in events


def test_a_trial_without_any_data_is_refused():
    walk = synthetic("walk")
    walk.iloc[:] = np.nan
    with pytest.raises(ValueError, match=r"dynamic: every coordinate of .* is NaN"):
        gait_events(walk, ROLES)


def test_a_label_twice_in_the_trial_is_refused_by_name():
    walk = synthetic("walk")
    with pytest.raises(ValueError, match=r"dynamic: the label\(s\) RHEE appear more than once"):
        gait_events(pd.concat([walk, walk[["RHEE"]]], axis=1), ROLES)
