"""Documented limits pinned on both sides, found by the mutation sample of issue 24
(tools/mutation_sample.py): each test fails if its comparison moves by one step, and its
numbers come from the docstring, not from the constant under test."""

import inspect
from pathlib import Path
import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import (force_plate_events, read_events, read_trc, time_normalize,
                           write_trc)
from bmc_functions.gait import force_plates
from bmc_functions.markers.roles import pelvis_roles


def one_marker(rate=100.0):
    columns = pd.MultiIndex.from_product([["A"], ["x", "y", "z"]])
    table = pd.DataFrame(np.arange(6.0).reshape(2, 3), columns=columns,
                         index=pd.Index([0.0, 1 / rate], name="time"))
    table.attrs.update(rate=rate, units="mm")
    return table


@pytest.mark.parametrize("rate", [0, 0.0, -1.0])
def test_write_trc_refuses_a_rate_that_is_not_positive(tmp_path, rate):
    # "rate : float ... a positive number (Hz)": 0 Hz is no DataRate
    with pytest.raises(ValueError, match=r"rate must be a positive number \(Hz\); got"):
        write_trc(one_marker(), tmp_path / "x.trc", rate=rate)


def test_write_trc_accepts_any_positive_rate(tmp_path):
    write_trc(one_marker(), tmp_path / "x.trc", rate=1e-3)
    assert read_trc(tmp_path / "x.trc").attrs["rate"] == pytest.approx(1e-3)


def events_csv(tmp_path, times):
    path = tmp_path / "events.csv"
    pd.DataFrame({"side": "right", "event": "heel_strike", "time": times}).to_csv(
        path, index=False)
    return path


def test_events_within_1_ms_are_one_event_stored_twice(tmp_path):
    # documented: "events stored twice (same side and kind, within 1 ms)" are kept once
    with pytest.warns(UserWarning, match="1 event"):
        events = read_events(events_csv(tmp_path, [0.5, 0.5009, 1.6]))
    np.testing.assert_allclose(events["right"]["heel_strike"], [0.5, 1.6])


def test_events_2_ms_apart_are_two_events(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # no "stored twice" warning either
        events = read_events(events_csv(tmp_path, [0.5, 0.502, 1.6]))
    np.testing.assert_allclose(events["right"]["heel_strike"], [0.5, 0.502, 1.6])


@pytest.mark.parametrize("mapping, posterior", [
    ({"RPSIS": "RPSI", "LPSIS": "LPSI"}, ["RPSIS", "LPSIS"]),
    ({"RPSIS": "RPSI", "LPSIS": "LPSI", "SACRUM": "SACR"}, ["RPSIS", "LPSIS"]),
    ({"RPSIS": "RPSI", "SACRUM": "SACR"}, ["SACRUM"]),     # one PSIS is not both
    ({"LPSIS": "LPSI", "SACRUM": "SACR"}, ["SACRUM"]),
    ({"SACRUM": "SACR"}, ["SACRUM"]),
])
def test_the_pelvis_uses_both_psis_only_when_both_are_mapped(mapping, posterior):
    assert pelvis_roles(mapping) == ["RASIS", "LASIS"] + posterior


def test_a_cycle_that_ends_on_the_last_frame_is_kept():
    # heel strikes at 0, 1 and 2 s in a signal of 0 to 2 s: two whole cycles, the second
    # closed by the last frame itself
    time = np.linspace(0.0, 2.0, 201)
    signal = np.sin(2 * np.pi * time)
    cycles = time_normalize(signal, [0.0, 1.0, 2.0], time=time, n_points=11)
    assert cycles.shape[0] == 2
    np.testing.assert_allclose(cycles[1], np.sin(2 * np.pi * np.linspace(1, 2, 11)),
                               atol=1e-12)


def test_a_foot_is_on_a_plate_above_20_newtons():
    # documented: "Vertical force (N) above which a foot is on a plate (default 20 N)"
    assert inspect.signature(force_plate_events).parameters["threshold"].default == 20.0
    rate = 1000.0
    vertical = np.r_[np.zeros(10), np.linspace(0.0, 100.0, 101), np.zeros(10)]  # 1 N steps
    starts, stops = force_plates._loaded_runs(vertical, rate, 20.0, 0.05)
    first = starts[0]
    assert vertical[first - 1] <= 20.0 < vertical[first]       # 21 N: the first above
    assert vertical[first] == pytest.approx(21.0)


def test_a_closing_heel_strike_a_rounding_error_after_the_last_frame_closes_its_cycle():
    # 0.1 s summed twenty times is 2.0000000000000004 s: the same instant as the last
    # frame (2 s) for any event file or computation, so the cycle must be kept
    time = np.linspace(0.0, 2.0, 201)
    closing = sum([0.1] * 20)
    assert closing > time[-1]
    cycles = time_normalize(np.sin(2 * np.pi * time), [0.0, 1.0, closing], time=time,
                            n_points=11)
    assert cycles.shape[0] == 2


def test_an_opening_heel_strike_a_rounding_error_before_the_first_frame_keeps_gaps_seen():
    # the first frame at 0.3 s, the opening heel strike at 0.1 * 3 = 0.30000000000000004
    # s would be after it; at 0.3 - 5e-17 s it is before: the cycle is kept, and a long
    # gap at its start still makes it NaN (the frames it reads are found from the first)
    time = 0.3 + np.arange(201) / 100
    opening = np.nextafter(0.3, 0.0)
    assert opening < time[0]
    signal = np.sin(2 * np.pi * time)
    clean = time_normalize(signal, [opening, 1.3, 2.3], time=time, n_points=11)
    assert clean.shape[0] == 2 and np.isfinite(clean).all()
    signal[:10] = np.nan                                   # 0.1 s gap at the start
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        gapped = time_normalize(signal, [opening, 1.3, 2.3], time=time, n_points=11)
    assert np.isnan(gapped[0]).all() and np.isfinite(gapped[1]).all()


# --- the survivors of the blind sample (tools/mutation_sample.py, its second half) ------

def trc_stepping_at(tmp_path, step_rate, rate=100.0, frames=101):
    columns = pd.MultiIndex.from_product([["A"], ["x", "y", "z"]])
    table = pd.DataFrame(np.ones((frames, 3)), columns=columns,
                         index=pd.Index(np.arange(frames) / step_rate, name="time"))
    table.attrs.update(rate=rate, units="mm")
    path = tmp_path / "trial.trc"
    write_trc(table, path)
    return path


@pytest.mark.parametrize("step_rate", [98.1, 101.9])
def test_a_trc_time_column_within_2_percent_of_its_data_rate_is_quiet(tmp_path, step_rate):
    # documented: "Allowed: 2 % or 2 ms, whichever is larger" (1 s trial: 2 % = 20 ms)
    path = trc_stepping_at(tmp_path, step_rate)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read_trc(path)


@pytest.mark.parametrize("step_rate", [97.9, 102.1])
def test_a_trc_time_column_more_than_2_percent_off_its_data_rate_warns(tmp_path, step_rate):
    path = trc_stepping_at(tmp_path, step_rate)
    with pytest.warns(UserWarning, match="the header says DataRate = 100 Hz"):
        read_trc(path)


def test_a_time_index_with_a_dropped_row_is_refused_by_the_filter():
    # documented: "a step of more than 1.5 times the median: dropna()" is refused, since
    # the filter would join the data across the missing row
    from bmc_functions import lowpass
    time = np.arange(100) / 100.0
    signal = pd.Series(np.sin(2 * np.pi * time), index=pd.Index(time, name="time"))
    with pytest.raises(ValueError, match="skips rows"):
        lowpass(signal.drop(signal.index[50]), 6)
    jittered = signal.copy()
    jittered.index = pd.Index(time + np.r_[np.zeros(50), 0.004, np.zeros(49)], name="time")
    lowpass(jittered, 6)                     # steps of 1.4 and 0.6 times the usual: kept


def knee_model():
    from types import SimpleNamespace
    return SimpleNamespace(markers={"RKNEE_LAT": "RKNE", "RKNEE_MED": "RKNM"})


@pytest.mark.parametrize("tilt, offset, warns", [
    (30.0, 0.0, True),      # through mid-epicondyles, 30 degrees off the epicondylar line
    (0.0, 30.0, True),      # along the line, 30 mm from it
    (10.0, 10.0, False),    # within both (20 degrees, 20 mm)
])
def test_a_functional_knee_axis_warns_when_either_angle_or_distance_is_off(tilt, offset,
                                                                          warns):
    from bmc_functions.models.lower_limb import _check_knee_axis
    points = {"RKNE": np.array([0.0, 0.0, 50.0]), "RKNM": np.array([0.0, 0.0, -50.0])}
    a = np.radians(tilt)
    direction = np.array([np.sin(a), 0.0, np.cos(a)])
    point = np.array([0.0, offset, 0.0])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _check_knee_axis(knee_model(), points, "right", point, direction, "the knee trial")
    assert any("functional right knee axis" in str(w.message) for w in caught) == warns


def two_cluster_table(scales):
    from bmc_functions.files.trial import MarkerTable
    from types import SimpleNamespace
    local = np.array([[0.0, 0.0, 0.0], [60.0, 0.0, 0.0], [0.0, 60.0, 0.0], [0.0, 0.0, 60.0]])
    clusters, columns, values = {}, [], []
    for k, (name, scale) in enumerate(scales.items()):
        labels = [f"{name}{i}" for i in range(4)]
        clusters[name] = {"labels": labels, "local": local - local.mean(axis=0)}
        for label, xyz in zip(labels, local * scale + 500.0 * k):
            columns += [(label, c) for c in "xyz"]
            values += list(xyz)
    table = pd.DataFrame([values] * 5, columns=pd.MultiIndex.from_tuples(columns))
    return SimpleNamespace(clusters=clusters), MarkerTable(table, "the walk")


def test_one_odd_sized_cluster_is_not_taken_for_wrong_units():
    # documented: "Raise if every cluster is UNITS_RATIO times larger or smaller"
    from bmc_functions.models.lower_limb_checks import check_dynamic_units
    model, table = two_cluster_table({"RTHIGH": 2.5, "RSHANK": 1.0})
    check_dynamic_units(model, table, 1.0, "mm", "the walk")
    model, table = two_cluster_table({"RTHIGH": 10.0, "RSHANK": 10.0})
    with pytest.raises(ValueError, match="the file's units are wrong"):
        check_dynamic_units(model, table, 1.0, "mm", "the walk")


def test_a_foot_beside_the_short_edge_of_a_rectangular_plate_is_not_on_it():
    # a 600 x 400 mm plate (x along its 600 mm edge): over it within PLATE_MARGIN = 50 mm
    corners = np.array([[300.0, -300.0, -300.0, 300.0], [200.0, 200.0, -200.0, -200.0],
                        [0.0, 0.0, 0.0, 0.0]])
    normal = np.array([0.0, 0.0, 1.0])
    assert force_plates._over_plate(np.array([0.0, 240.0, 0.0]), corners, None, normal)
    assert not force_plates._over_plate(np.array([0.0, 300.0, 0.0]), corners, None, normal)
    assert force_plates._over_plate(np.array([340.0, 0.0, 0.0]), corners, None, normal)
    assert not force_plates._over_plate(np.array([360.0, 0.0, 0.0]), corners, None, normal)


def test_a_half_turn_decomposes_to_plus_pi():
    # documented ranges of the first and third angles: (-pi, pi]
    from bmc_functions import decompose, rot_z
    for R in (rot_z(np.pi), rot_z(-np.pi)):
        assert decompose(R, "ZXY")[0] == np.pi


def test_a_thin_cluster_is_not_refused_as_collinear():
    # singular values 141 and 0.014 mm (ratio 1e-4, far above COLLINEAR_RTOL = 1e-6)
    from bmc_functions import expected_orientation_error
    markers = np.array([[-100.0, 0, 0], [100.0, 0, 0], [0, 0.01, 0], [0, -0.01, 0]])
    error = expected_orientation_error(markers, 0.5)
    assert np.all(np.isfinite(error))
    with pytest.raises(ValueError, match="collinear"):
        expected_orientation_error(markers[:2].tolist() + [[0.0, 0, 0]], 0.5)


def test_frames_skipped_by_a_writer_do_not_contradict_the_rate():
    # documented: both the span and the median step must be more than 2 % off the rate
    from bmc_functions._checks import check_rate_attr
    time = np.delete(np.arange(100) / 100.0, [40, 41, 42])     # span says 97 Hz, step 100
    table = pd.DataFrame(index=time)
    table.attrs["rate"] = 100.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_rate_attr(table, time, "the trial")
    table.attrs["rate"] = 120.0                                 # both 17 % off
    with pytest.warns(RuntimeWarning, match="attrs\\['rate'\\] = 120 Hz"):
        check_rate_attr(table, time, "the trial")


def test_the_command_line_fails_when_a_pattern_matches_no_file(tmp_path, capsys):
    # documented: the exit status is 0 only when every trial succeeded
    from bmc_functions import write_mot
    from bmc_functions.cli import main
    angles = pd.DataFrame({"knee_angle_r": [1.0, 2.0, 3.0]},
                          index=pd.Index([0.0, 0.01, 0.02], name="time"))
    write_mot(angles, tmp_path / "walk.mot", in_degrees=True)
    status = main(["convert", str(tmp_path / "walk.mot"), str(tmp_path / "nomatch*.mot"),
                   "--to", "csv", "-o", str(tmp_path / "out"), "-q"])
    assert status == 1
    assert "no file matches" in capsys.readouterr().err
    assert (tmp_path / "out" / "walk.csv").exists()


# --- the survivors of the second blind sample -------------------------------------------

def test_a_cluster_role_needs_three_labels():
    # documented: "needs 3 or more labels (a rigid-body fit needs 3 non-collinear markers)"
    from bmc_functions.markers.roles import check_mapping
    base = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
            "RKNEE_LAT": "RKNE", "RKNEE_MED": "RKNM", "RANKLE_LAT": "RANK",
            "RANKLE_MED": "RMED", "RHEEL": "RHEE", "RTOE": "RTOE",
            "RSHANK": ["RS1", "RS2", "RS3"]}
    check_mapping({**base, "RTHIGH": ["T1", "T2", "T3"]}, ["right"], "harrington")
    with pytest.raises(ValueError, match=r"markers\['RTHIGH'\] needs 3 or more labels"):
        check_mapping({**base, "RTHIGH": ["T1", "T2"]}, ["right"], "harrington")


@pytest.mark.parametrize("ankle_width, refused", [(45.0, False), (125.0, False),
                                                   (135.0, True), (180.0, True),
                                                   (35.0, True)])
def test_the_malleolus_markers_are_40_to_130_mm_apart(ankle_width, refused):
    from types import SimpleNamespace

    from bmc_functions.models.lower_limb_checks import _check_joint_lines
    roles = {"RKNEE_LAT": (-50.0, 0.0, 500.0), "RKNEE_MED": (50.0, 0.0, 500.0),
             "RANKLE_LAT": (-ankle_width / 2, 0.0, 100.0),
             "RANKLE_MED": (ankle_width / 2, 0.0, 100.0)}
    model = SimpleNamespace(markers={role: role.lower() for role in roles})
    point = lambda role: np.array(roles[role])                       # noqa: E731
    hip = np.array([0.0, 0.0, 900.0])
    if refused:
        with pytest.raises(ValueError, match=f"right ankle: .* are {ankle_width:.0f} mm apart"):
            _check_joint_lines(model, point, "right", hip)
    else:
        _check_joint_lines(model, point, "right", hip)


@pytest.mark.parametrize("shift, warns", [(0.0, False), (60.0, True)])
def test_a_functional_hip_centre_far_from_harrington_s_warns(monkeypatch, shift, warns):
    # documented: a warning when the functional centre lies more than 50 mm from
    # Harrington's regression (data/functional: about 5 mm apart; 60 mm shift: ~56 mm)
    from bmc_functions import calibrate_lower_limb
    from bmc_functions.models import lower_limb
    from helpers import FUNCTIONAL_MARKERS as markers, ROOT
    folder = ROOT / "data" / "functional"
    regression = lower_limb.harrington_hip_centres

    def shifted(*args):
        centres, fits = regression(*args)
        return {side: centre + np.array([shift, 0.0, 0.0])
                for side, centre in centres.items()}, fits

    monkeypatch.setattr(lower_limb, "harrington_hip_centres", shifted)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        calibrate_lower_limb(folder / "static.trc", markers, hip_centre="functional",
                             functional_trial=folder / "hip_star_arc.trc")
    far = [str(w.message) for w in caught if "from Harrington's regression" in str(w.message)]
    assert bool(far) == warns, far


def test_a_heel_and_toe_400_mm_apart_are_not_one_foot():
    # documented: "a foot is shorter than MAX_FOOT" (350 mm): a longer heel-toe distance
    # warns that the markers of the two feet are mixed
    from bmc_functions import gait_events, read_trc
    from helpers import ROOT
    gait = ROOT / "data" / "gait"
    walk = read_trc(gait / "walk.trc")
    mapping = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
               "RHEEL": "RHEE", "RTOE": "RTOE", "LHEEL": "LHEE", "LTOE": "LTOE"}
    heel, toe = mapping["RHEEL"], mapping["RTOE"]
    moved = walk.copy()
    direction = (walk[toe].to_numpy() - walk[heel].to_numpy())
    length = np.linalg.norm(direction, axis=1, keepdims=True)
    for coord, k in zip("xyz", range(3)):
        moved[(toe, coord)] = (walk[heel].to_numpy() + direction / length * 400.0)[:, k]
    with warnings.catch_warnings(record=True) as caught:   # the moved toe also spoils
        warnings.simplefilter("always")                    # the right foot's events
        gait_events(moved, mapping)
    assert any("foot markers too far apart for one foot" in str(w.message) for w in caught)


def test_a_foot_still_on_the_plate_at_the_end_of_the_recording_has_no_toe_off(monkeypatch):
    # a contact that lasts to the last sample has no measured end: a heel strike only
    rate, n = 1000.0, 2000
    forces = np.zeros((1, 3, n))
    forces[0, 2, 1400:] = 700.0                      # loaded from 1.4 s to the end
    corners = np.array([[[300.0, -300.0, -300.0, 300.0], [300.0, 300.0, -300.0, -300.0],
                         [0.0, 0.0, 0.0, 0.0]]])
    monkeypatch.setattr(force_plates, "_read_plates", lambda path: (forces, corners, rate,
                                                                    100.0))
    columns = pd.MultiIndex.from_product([["RHEE"], ["x", "y", "z"]])
    # RHEE still at the plate's centre: the right foot stands on it
    trial = pd.DataFrame(np.zeros((200, 3)), columns=columns,
                         index=pd.Index(np.arange(200) / 100.0, name="time"))
    trial.attrs["rate"] = 100.0
    events = force_plate_events("plates.c3d", {"RHEEL": "RHEE"}, trial=trial)
    # (1.394 s: the 50 Hz forwards-backwards filter spreads the step by a few ms)
    assert events["right"]["heel_strike"] == pytest.approx([1.4], abs=0.01)
    assert events["right"]["toe_off"].size == 0


def test_c3d_events_beyond_event_used_are_not_read(monkeypatch, tmp_path):
    # EVENT:USED counts the events; slots beyond it are stale (a C3D file keeps them)
    from bmc_functions.gait import event_files
    info = {"times": np.array([[0.0, 0.0, 0.0], [0.5, 1.0, 1.6]]),
            "contexts": ["Right", "Left", "Left"],
            "labels": ["Foot Strike", "Foot Strike", "Foot Strike"],
            "used": 2, "first_frame": 0, "last_frame": 199, "rate": 100.0,
            "has_group": True}
    monkeypatch.setattr(event_files, "read_checked", lambda path, extract, name: info)
    (tmp_path / "trial.c3d").write_bytes(b"")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        events = read_events(tmp_path / "trial.c3d")
    np.testing.assert_allclose(events["right"]["heel_strike"], [0.5])
    np.testing.assert_allclose(events["left"]["heel_strike"], [1.0])


@pytest.mark.parametrize("value", [1e300, -1e300])
def test_magnitudes_beyond_1e100_are_refused_whatever_their_sign(value):
    # documented (bmc_functions._checks): values beyond MAX_MAGNITUDE = 1e100 are refused
    from bmc_functions import svdt
    A = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    with pytest.raises(ValueError):
        svdt(A, A * value, order="row")


def test_events_before_the_curves_start_are_reported_too():
    from bmc_functions.plotting import _warn_events_outside
    time = np.linspace(0.0, 2.0, 201)
    for at in (-3.0, 5.0):
        with pytest.warns(RuntimeWarning, match="lie outside the curves' time"):
            _warn_events_outside([("right", "heel_strike", np.array([at, 1.0]))], time)


# --- the survivors of the third blind sample --------------------------------------------

@pytest.mark.parametrize("slide, on_plate", [(100.0, True), (200.0, False)])
def test_a_foot_that_slides_more_than_150_mm_is_not_standing_on_the_plate(slide, on_plate):
    # documented: the foot must "move less than MAX_TRAVEL (150 mm)" during the middle
    # half of the contact (the swing foot passes over a plate, it does not stand on it)
    corners = np.array([[300.0, -300.0, -300.0, 300.0], [300.0, 300.0, -300.0, -300.0],
                        [0.0, 0.0, 0.0, 0.0]])
    normal = np.array([0.0, 0.0, 1.0])
    frames = 100                                     # 1 s of markers at 100 Hz
    x = np.interp(np.arange(frames), [25, 75], [-slide / 2, slide / 2])
    foot = np.stack([x, np.zeros(frames), np.full(frames, 50.0)], axis=1)
    [(side, over)] = force_plates._feet_on_plate({"right": foot}, corners, normal, [0], [1000],
                                                 (1000.0, 100.0), frames)
    assert (side == "right") == on_plate and (over == ["right"]) == on_plate


@pytest.mark.parametrize("times, warns", [([0.0, 1.1, 2.2], False), ([0.0, 50.0, 100.0], True)])
def test_an_events_file_whose_strides_last_over_10_s_is_taken_for_ms(tmp_path, times, warns):
    # documented: heel strikes more than MAX_MEDIAN_STRIDE (10 s) apart: ms or frames?
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        read_events(events_csv(tmp_path, times))
    assert any("milliseconds or frames" in str(w.message) for w in caught) == warns


def test_a_cycle_spans_at_least_4_frames_of_the_signal():
    # documented: cycles spanning fewer than MIN_CYCLE_FRAMES = 4 frames (median) mean an
    # index in frame numbers or ms against events in s
    signal = np.sin(np.arange(20.0))
    with pytest.raises(ValueError, match="spans only"):
        time_normalize(signal, [0, 3, 6, 9, 12], time=np.arange(20.0))
    cycles = time_normalize(signal, [0, 4, 8, 12, 16], time=np.arange(20.0))
    assert cycles.shape == (4, 101)


def test_axes_a_microradian_apart_still_make_a_frame():
    # documented: parallel below PARALLEL_RTOL = 1e-8 (the angle between them)
    from bmc_functions import frame_from_axes
    frame = frame_from_axes([1.0, 0.0, 0.0], [1.0, 1e-6, 0.0])
    np.testing.assert_allclose(frame, np.eye(3), atol=1e-12)
    with pytest.raises(ValueError, match="parallel"):
        frame_from_axes([1.0, 0.0, 0.0], [1.0, 1e-9, 0.0])


@pytest.mark.parametrize("error, refused", [(1e-7, False), (1e-4, True)])
def test_a_rotation_matrix_is_orthonormal_within_1e_6(error, refused):
    from bmc_functions import rotation_angle
    R = np.eye(3)
    R[0, 0] += error
    if refused:
        with pytest.raises(ValueError, match="1e-06"):
            rotation_angle(R)
    else:
        assert rotation_angle(R) == pytest.approx(0.0, abs=1e-6)


def test_plot_residuals_draws_them_scale_times_as_long():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from bmc_functions.plotting import plot_residuals
    ax = plt.figure().add_subplot(projection="3d")
    plot_residuals(ax, [[0.0, 0.0, 1.0]], [[0.0, 0.0, 0.0]], scale=10)
    z = np.concatenate([line.get_data_3d()[2] for line in ax.lines])
    assert np.nanmax(z) == pytest.approx(10.0)
    plt.close("all")


# --- the survivors of the fourth blind sample -------------------------------------------

PIG = Path(__file__).resolve().parents[1] / "data" / "real" / "plug_in_gait"


def vsk_with(tmp_path, duplicate_value):
    text = (PIG / "Test.vsk").read_text()
    line = next(line for line in text.splitlines() if 'NAME="LeftLegLength"' in line)
    twice = line.replace('VALUE="877"', f'VALUE="{duplicate_value}"')
    path = tmp_path / "twice.vsk"
    path.write_text(text.replace(line, line + "\n" + twice))
    return path


def test_a_vsk_parameter_given_twice_with_two_values_is_refused(tmp_path):
    from bmc_functions import read_vsk
    assert read_vsk(vsk_with(tmp_path, 877))["LeftLegLength"] == 877.0   # same value: fine
    with pytest.raises(ValueError, match="LeftLegLength appears twice with different"):
        read_vsk(vsk_with(tmp_path, 950))


def test_the_integers_of_a_dec_c3d_file_are_little_endian(tmp_path):
    # C3D processor types: 84 Intel and 85 DEC store integers little-endian, 86 MIPS
    # big-endian (the C3D user guide); POINT:USED of the Nexus trial is 239
    from bmc_functions import read_c3d_parameters
    path = tmp_path / "dec.c3d"
    path.write_bytes((PIG / "Movement_trial.c3d").read_bytes())
    with open(path, "r+b") as file:
        start = (file.read(1)[0] - 1) * 512
        file.seek(start + 3)
        assert file.read(1)[0] == 84
        file.seek(start + 3)
        file.write(bytes([85]))
    assert read_c3d_parameters(path)["POINT"]["USED"] == 239


@pytest.mark.parametrize("step, warns", [(0.01, False), (1.0, True), (1.5, True)])
def test_write_mot_asks_whether_a_time_step_of_1_or_more_is_in_seconds(tmp_path, step, warns):
    from bmc_functions import write_mot
    angles = pd.DataFrame({"knee_angle_r": [1.0, 2.0, 3.0, 4.0]},
                          index=pd.Index(np.arange(4) * step, name="time"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        write_mot(angles, tmp_path / "a.mot", in_degrees=True)
    assert any("is it in ms or frame numbers" in str(w.message) for w in caught) == warns


def test_stance_from_the_swing_and_step_time_per_side_when_no_stride_is_complete():
    # right: toe-off 0.6 s, heel strike 1.0 s; left heel strike 0.5 s. No complete stride:
    # the stride is twice the step time (0.5 s, left strike to right strike), the right
    # swing 0.4 s, so its stance is 100 - 100 * 0.4 / 1.0 = 60 %
    from bmc_functions import spatiotemporal_parameters
    from bmc_functions.gait.events import GaitEvents
    events = GaitEvents({"right": {"heel_strike": np.array([1.0]),
                                   "toe_off": np.array([0.6])},
                         "left": {"heel_strike": np.array([0.5]),
                                  "toe_off": np.array([])}},
                        gait=None, method="by hand", source="by hand")
    table = spatiotemporal_parameters(events)
    assert table.loc["right", "step_time"] == pytest.approx(0.5)
    assert np.isnan(table.loc["left", "step_time"])          # no right strike before it
    assert table.loc["right", "stance"] == pytest.approx(60.0)
    assert table.loc["right", "swing"] == pytest.approx(40.0)


def feet_tilted(degrees):
    a = np.radians(degrees)
    pelvis = np.tile([0.0, 0.0, 0.0], (50, 1))
    below = -900.0 * np.array([np.sin(a), 0.0, np.cos(a)])         # feet below the pelvis
    return pelvis, {"right": {"HEEL": np.tile(below, (50, 1))}}


def test_a_lab_axis_within_30_degrees_of_the_feet_to_pelvis_direction_is_the_vertical():
    from bmc_functions.gait import events
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_array_equal(events._vertical(*feet_tilted(25.0)), [0, 0, 1])
    with pytest.warns(RuntimeWarning, match="no lab axis lies within 30 degrees"):
        events._vertical(*feet_tilted(35.0))


@pytest.mark.parametrize("turn, warns", [(40.0, False), (50.0, True)])
def test_a_pelvis_heading_more_than_45_degrees_from_its_mean_is_a_turn(turn, warns):
    from bmc_functions.gait import events
    a = np.radians(turn)
    forward = np.tile([1.0, 0.0, 0.0], (100, 1))
    forward[:10] = [np.cos(a), np.sin(a), 0.0]                   # 10 frames turned
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        events._heading(forward, np.array([0.0, 0.0, 1.0]), 100)
    assert any("45 degrees away from its mean" in str(w.message) for w in caught) == warns


def test_a_documented_maximum_is_included():
    from bmc_functions._checks import check_scalar
    assert check_scalar(20, "passes", "an integer in 1..20", minimum=1, maximum=20,
                        integer=True) == 20
    with pytest.raises(ValueError, match="passes must be an integer in 1..20; got 21"):
        check_scalar(21, "passes", "an integer in 1..20", minimum=1, maximum=20,
                     integer=True)


def test_the_command_line_fails_when_no_pattern_matches_a_file(tmp_path, capsys):
    from bmc_functions.cli import main
    assert main(["convert", str(tmp_path / "none*.mot"), "-o", str(tmp_path / "o"),
                 "-q"]) == 1
    assert "no trial to run" in capsys.readouterr().err
