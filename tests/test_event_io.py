"""Events stored beside a trial: the C3D EVENT group and CSV files.

Oracles: C3D files written here with ezc3d holding known events (one a copy of the real
Plug-in Gait trial, whose first stored frame is 695, so that the time shift is tested);
round trips through the CSV writer.
"""

import sys
import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import (force_plate_events, normalize_by_side, read_c3d, read_events,
                           write_events)

from helpers import ROOT, SHARED_DATA

PIG = SHARED_DATA / "plug_in_gait" / "Movement_trial.c3d"
PIG_ROLES = {"RHEEL": "RHEE", "RTOE": "RTOE", "RANKLE_LAT": "RANK", "LTOE": "LTOE",
             "LANKLE_LAT": "LANK"}


def with_events(c3d, contexts, labels, seconds):
    c3d.add_parameter("EVENT", "USED", [len(labels)])
    c3d.add_parameter("EVENT", "CONTEXTS", list(contexts))
    c3d.add_parameter("EVENT", "LABELS", list(labels))
    c3d.add_parameter("EVENT", "TIMES", np.array([np.zeros(len(seconds)), seconds]))
    return c3d


def small_c3d(tmp_path, contexts, labels, seconds, name="events.c3d"):
    ezc3d = pytest.importorskip("ezc3d")
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [100.0]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = ("RHEE",)
    c3d["data"]["points"] = np.ones((4, 1, 300))
    if labels:
        with_events(c3d, contexts, labels, seconds)
    c3d.write(str(tmp_path / name))
    return tmp_path / name


def test_c3d_events_are_read_by_side_and_kind(tmp_path):
    path = small_c3d(tmp_path, ["Right", "Left", "Right", " right ", "General"],
                     ["Foot Strike", "Foot Off", "Foot Off", "foot strike", "Event"],
                     [1.0, 1.25, 1.7, 2.1, 0.3])
    with pytest.warns(UserWarning, match=r"1 of 5 events of the EVENT group are not a right "
                                         r"or left foot strike or foot off .*\(General/Event\)"):
        events = read_events(path)
    assert events["right"]["heel_strike"].tolist() == pytest.approx([1.0, 2.1])
    assert events["right"]["toe_off"].tolist() == pytest.approx([1.7])
    assert events["left"]["toe_off"].tolist() == pytest.approx([1.25])
    assert events["left"]["heel_strike"].shape == (0,)
    assert events.gait is None and events.source == str(path)
    assert "EVENT group" in events.method


def test_a_c3d_without_events_warns_and_gives_empty_arrays(tmp_path):
    path = small_c3d(tmp_path, [], [], [])
    with pytest.warns(UserWarning, match="no (EVENT group|foot event) in the file"):
        events = read_events(path)
    assert all(times.size == 0 for side in events.values() for times in side.values())


@pytest.mark.skipif(not PIG.exists(), reason="../shared/data absent")
def test_the_force_plate_events_written_into_the_real_file_come_back(tmp_path):
    # as Nexus stores them: times from the start of the capture; the file's first stored
    # frame is 695 at 120 Hz, so the stored times are 694/120 s later than read_c3d's
    ezc3d = pytest.importorskip("ezc3d")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plates = force_plate_events(PIG, PIG_ROLES)
        trial = read_c3d(PIG)
    contexts, labels, seconds = [], [], []
    for side, found in plates.items():
        for event, times in found.items():
            for t in times:
                contexts.append(side.capitalize())
                labels.append("Foot Strike" if event == "heel_strike" else "Foot Off")
                seconds.append(t + 694 / 120)
    c3d = with_events(ezc3d.c3d(str(PIG)), contexts, labels, seconds)
    c3d.write(str(tmp_path / "with_events.c3d"))
    stored = read_events(tmp_path / "with_events.c3d")
    for side in ("right", "left"):
        for event in ("heel_strike", "toe_off"):
            assert np.allclose(stored[side][event], plates[side][event], atol=1e-5)
    # and they cut cycles like detected events do
    angles = pd.DataFrame({("knee", "right", "flexion"): trial["RTOE"]["z"].to_numpy(),
                           ("knee", "left", "flexion"): trial["LTOE"]["z"].to_numpy()},
                          index=trial.index)
    cycles = normalize_by_side(angles, stored, n_points=11)
    assert cycles.attrs["cycles"]["right"] == [tuple(stored["right"]["heel_strike"])]


def test_csv_round_trip_and_the_synthetic_truth_files(tmp_path):
    events = read_events(ROOT / "data" / "gait" / "walk_events.csv")   # extra column in_gap
    table = pd.read_csv(ROOT / "data" / "gait" / "walk_events.csv")
    assert len(events["left"]["heel_strike"]) == np.count_nonzero(
        (table.side == "left") & (table.event == "heel_strike"))
    written = write_events(events, tmp_path / "out.csv")
    assert list(written.columns) == ["side", "event", "time"]
    assert np.all(np.diff(written["time"]) >= 0)
    back = read_events(tmp_path / "out.csv")
    for side in events:
        for event in events[side]:
            assert np.allclose(back[side][event], events[side][event], atol=1e-6)


@pytest.mark.parametrize("content, message", [
    ("side,time\nright,1.0\n", "needs the columns side, event, time; event missing"),
    ("side,event,time\nmiddle,heel_strike,1.0\n", r"side must be 'right' or 'left'.*middle"),
    ("side,event,time\nright,foot_flat,1.0\n", r"event 'heel_strike' or 'toe_off'.*foot_flat"),
    ("side,event,time\nright,heel_strike,n/a\n", r"column time must hold finite times"),
])
def test_bad_csv_events(tmp_path, content, message):
    (tmp_path / "bad.csv").write_text(content)
    with pytest.raises(ValueError, match=message):
        read_events(tmp_path / "bad.csv")


def test_bad_arguments(tmp_path):
    with pytest.raises(ValueError, match=r"path must be a .c3d or .csv file"):
        read_events(tmp_path / "events.xlsx")
    with pytest.raises(TypeError, match="path must be a file name"):
        read_events(3)
    with pytest.raises(TypeError, match="events must be a dict"):
        write_events([1.0, 2.0], tmp_path / "x.csv")
    with pytest.raises(ValueError, match="side must be 'right' or 'left'; got 'both'"):
        write_events({"both": {"heel_strike": [1.0]}}, tmp_path / "x.csv")
    with pytest.raises(ValueError, match=r"must hold finite times"):
        write_events({"right": {"heel_strike": [np.nan]}}, tmp_path / "x.csv")


def test_without_ezc3d_the_c3d_readers_name_the_extra(monkeypatch, tmp_path):
    path = small_c3d(tmp_path, [], [], [])
    monkeypatch.setitem(sys.modules, "ezc3d", None)    # makes `import ezc3d` fail
    with pytest.raises(ImportError, match=r"read_events needs the optional package ezc3d"):
        read_events(path)
    with pytest.raises(ImportError, match=r"force_plate_events needs the optional package"):
        force_plate_events(path, {"RHEEL": "RHEE"})


# --- adversarial pass, round 2 (tools/adversarial_pass_round2.py) ----------------------------

def test_c3d_labels_and_contexts_with_underscores_dashes_and_initials(tmp_path):
    path = small_c3d(tmp_path, ["R", "l", "RIGHT"], ["Foot_Strike", "foot-off", "Heel Strike"],
                     [0.5, 0.8, 1.6])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        events = read_events(path)
    assert events["right"]["heel_strike"].tolist() == pytest.approx([0.5, 1.6])
    assert events["left"]["toe_off"].tolist() == pytest.approx([0.8])


def test_c3d_events_outside_the_trial_or_stored_twice_are_left_out_with_a_warning(tmp_path):
    """The small file holds 300 frames at 100 Hz: 0 to 2.99 s."""
    path = small_c3d(tmp_path, ["Right", "Right", "Left", "Left"],
                     ["Foot Strike", "Foot Strike", "Foot Off", "Foot Off"],
                     [0.5, 12.0, 0.8, 0.8])
    with pytest.warns(UserWarning) as caught:
        events = read_events(path)
    texts = [str(w.message) for w in caught]
    assert any("1 event(s) lie outside the trial (0 to 2.99 s) and were left out: right "
               "heel_strike at 12 s" in t for t in texts), texts
    assert any("1 event(s) stored twice" in t for t in texts), texts
    assert events["right"]["heel_strike"].tolist() == pytest.approx([0.5])
    assert events["left"]["toe_off"].tolist() == pytest.approx([0.8])


def test_csv_events_in_any_case_and_column_order(tmp_path):
    path = tmp_path / "events.csv"
    path.write_text("Time,Side,Event\n0.5,Right,Heel_Strike\n0.7,L,toe off\n")
    events = read_events(path)
    assert events["right"]["heel_strike"].tolist() == [0.5]
    assert events["left"]["toe_off"].tolist() == [0.7]


def test_an_empty_csv_and_times_in_ms_are_reported(tmp_path):
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    with pytest.raises(ValueError, match=r"empty.csv: the events file is empty"):
        read_events(empty)
    ms = tmp_path / "ms.csv"
    ms.write_text("side,event,time\nright,heel_strike,500\nright,heel_strike,1600\n")
    with pytest.warns(UserWarning, match=r"1100 apart \(median\).*milliseconds"):
        read_events(ms)


def test_write_events_checks_its_path_and_times(tmp_path):
    events = {"right": {"heel_strike": [0.5]}}
    with pytest.raises(TypeError, match="path must be a file name"):
        write_events(events, None)            # pandas would return the text, writing nothing
    with pytest.raises(FileNotFoundError, match="path: the folder .*no.* does not exist"):
        write_events(events, tmp_path / "no" / "events.csv")
    with pytest.raises(ValueError, match=r"events\['right'\]\['heel_strike'\] must hold "
                                         r"times"):
        write_events({"right": {"heel_strike": ["a"]}}, tmp_path / "e.csv")


# --- issue 30: the other capture programs' ways of naming an event ---------------------------

def test_side_and_kind_in_one_text_of_the_context_or_the_label(tmp_path):
    """Motion Analysis Cortex: CONTEXTS 'LHS', 'RTO', LABELS empty; others put it in the
    label, or repeat the side in the context."""
    path = small_c3d(tmp_path, ["LHS", "RTO", "", "Right", "left", "R_FS", "General"],
                     ["", "", "Left Foot Off", "RHS", "Foot-Off", "", "RHS"],
                     [0.5, 0.7, 0.9, 1.1, 1.3, 2.2, 1.4])
    with pytest.warns(UserWarning, match=r"1 of 7 events .*\(General/RHS\)"):
        events = read_events(path)
    assert events["left"]["heel_strike"].tolist() == pytest.approx([0.5])
    assert events["right"]["toe_off"].tolist() == pytest.approx([0.7])
    assert events["left"]["toe_off"].tolist() == pytest.approx([0.9, 1.3])
    assert events["right"]["heel_strike"].tolist() == pytest.approx([1.1, 2.2])


@pytest.mark.parametrize("context, label, message", [
    ("Right", "LHS", r"'Right' and label 'LHS' names two sides \(left and right\)"),
    ("RHS", "Foot Off", r"'RHS' and label 'Foot Off' names two events \(heel_strike and "
                        r"toe_off\)"),
])
def test_a_context_and_label_that_contradict_are_refused(tmp_path, context, label, message):
    path = small_c3d(tmp_path, [context], [label], [0.5])
    with pytest.raises(ValueError, match=message + ".*ambiguous"):
        read_events(path)


def test_the_motion_analysis_walk_events_are_read():
    """Walk1.c3d (Motion Analysis, Helen Hayes markers) stores 8 events as contexts LHS,
    RHS, LTO, RTO with empty labels; the times are the file's own (first frame 1)."""
    path = SHARED_DATA / "walks_with_plates" / "Walk1.c3d"
    if not path.exists():
        pytest.skip(f"{path} not found")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        events = read_events(path)
    assert events["left"]["heel_strike"] == pytest.approx([0.56666666, 1.75])
    assert events["right"]["heel_strike"] == pytest.approx([1.14999998, 2.3166666])
    assert events["left"]["toe_off"] == pytest.approx([1.29999995, 2.4666667])
    assert events["right"]["toe_off"] == pytest.approx([0.73333335, 1.89999998])
