"""Issue 32, round 4 (files and events, the older open cases, the misleading errors):
each case that gave a wrong number without a word, or a misleading message, now raises a
ValueError naming the argument, warns once, or answers right. Expected values are set by
hand (or by an independent computation) in each test, never the function's own output.
"""

import struct
import warnings

import numpy as np
import pytest

from bmc_functions import read_c3d, read_trc
from bmc_functions.files.c3d_parameters import read_c3d_parameters, read_c3d_model_outputs
from helpers import ROOT, warning_messages, write_c3d_points

ezc3d = pytest.importorskip("ezc3d")


# ---- C3D: POINT:SCALE NaN, labels decoded by one rule ----------------------------------

def _c3d(tmp_path, labels=("ABCD", "WXYZ")):
    xyz = np.random.default_rng(3).normal(size=(5, len(labels), 3))
    return write_c3d_points(tmp_path / "trial.c3d", xyz, list(labels)), xyz


def _patch(path, old, new):
    """Replace every `old` by `new` (same length) in the file's bytes."""
    data = path.read_bytes()
    assert old in data and len(old) == len(new)
    path.write_bytes(data.replace(old, new))


def test_c3d_header_scale_nan_is_refused_naming_point_scale(tmp_path):
    path, _ = _c3d(tmp_path)
    data = bytearray(path.read_bytes())
    data[12:16] = struct.pack("<f", float("nan"))
    path.write_bytes(bytes(data))
    with pytest.raises(ValueError, match=r"header's POINT:SCALE .* is nan.*finite"):
        read_c3d(path)


def test_c3d_parameter_scale_nan_or_inf_is_refused(tmp_path):
    path, xyz = _c3d(tmp_path)
    scale = struct.unpack("<f", path.read_bytes()[12:16])[0]
    before = read_c3d(path)  # the boundary: a finite scale reads the points back
    np.testing.assert_allclose(before.to_numpy(), xyz.reshape(5, -1), atol=1e-5)
    data = path.read_bytes()
    section = data[512:]
    at = section.find(b"SCALE")
    assert at > 0
    # the value follows the name, the offset (2 bytes), the type and dims bytes (2)
    value_at = 512 + at + 5 + 2 + 2
    assert struct.unpack("<f", data[value_at:value_at + 4])[0] == pytest.approx(scale)
    for bad in (float("nan"), float("inf")):
        patched = bytearray(data)
        patched[value_at:value_at + 4] = struct.pack("<f", bad)
        path.write_bytes(bytes(patched))
        with pytest.raises(ValueError, match=r"parameter POINT:SCALE is (nan|inf)"):
            read_c3d(path)


def test_latin1_label_is_the_same_from_every_c3d_reader(tmp_path):
    path, _ = _c3d(tmp_path)
    _patch(path, b"ABCD", "Kné1".encode("latin-1"))
    assert list(read_c3d(path).columns.get_level_values(0).unique()) == ["Kné1", "WXYZ"]
    assert read_c3d_parameters(path)["POINT"]["LABELS"] == ["Kné1", "WXYZ"]


def test_utf8_label_is_the_same_from_every_c3d_reader(tmp_path):
    path, _ = _c3d(tmp_path, labels=("ABCDE", "WXYZ"))
    _patch(path, b"ABCDE", "Kné1".encode("utf-8"))  # 5 bytes, 4 characters
    assert list(read_c3d(path).columns.get_level_values(0).unique()) == ["Kné1", "WXYZ"]
    assert read_c3d_parameters(path)["POINT"]["LABELS"] == ["Kné1", "WXYZ"]


def test_latin1_model_output_label_is_found(tmp_path):
    path, xyz = _c3d(tmp_path, labels=("RKneeAngles", "WXYZ"))
    c3d = ezc3d.c3d(str(path))
    c3d.add_parameter("POINT", "ANGLES", ["RKneeAngles"])
    c3d.write(str(path))
    _patch(path, b"RKneeAngles", "RKnéeAngles".encode("latin-1"))
    outputs = read_c3d_model_outputs(path)
    assert "RKnéeAngles" in outputs.columns.get_level_values(0)


def _trc_bytes(line1, labels):
    header = [line1,
              "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\t"
              "OrigDataStartFrame\tOrigNumFrames",
              "100\t100\t2\t2\tmm\t100\t1\t2",
              "Frame#\tTime\t" + "\t\t\t".join(labels) + "\t\t",
              "\t\tX1\tY1\tZ1\tX2\tY2\tZ2", ""]
    rows = ["1\t0.00\t1\t2\t3\t4\t5\t6", "2\t0.01\t1\t2\t3\t4\t5\t6"]
    return header, rows


@pytest.mark.parametrize("encoding", ["latin-1", "utf-8"])
def test_trc_label_decoded_by_the_same_rule(tmp_path, encoding):
    header, rows = _trc_bytes("PathFileType\t4\t(X/Y/Z)\ttrial.trc", ["Kné1", "WXYZ"])
    path = tmp_path / "trial.trc"
    path.write_bytes("\n".join(header + rows).encode(encoding) + b"\n")
    assert list(read_trc(path).columns.get_level_values(0).unique()) == ["Kné1", "WXYZ"]


def test_trc_latin1_file_name_leaves_utf8_labels_utf8(tmp_path):
    header, rows = _trc_bytes("PathFileType\t4\t(X/Y/Z)\ttrial.trc", ["Kné1", "WXYZ"])
    path = tmp_path / "trial.trc"
    first = "PathFileType\t4\t(X/Y/Z)\tessai_é.trc".encode("latin-1")
    rest = "\n".join(header[1:] + rows).encode("utf-8")
    path.write_bytes(first + b"\n" + rest + b"\n")
    df = read_trc(path)
    assert list(df.columns.get_level_values(0).unique()) == ["Kné1", "WXYZ"]


# ---- events: the last frame, compare_events one-to-one and its spellings -------------

def test_event_on_the_last_stored_frame_is_kept(tmp_path):
    from test_event_io import small_c3d
    from bmc_functions import read_events

    # 300 frames at 100 Hz: 0 to 2.99 s; 2.99 in float32 is 2.9900000095 s
    last = float(np.float32(2.99))
    assert last > 2.99
    path = small_c3d(tmp_path, ["Right", "Right", "Left"],
                     ["Foot Strike", "Foot Off", "Foot Strike"], [0.0, last, 1.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        events = read_events(path)
    assert events["right"]["toe_off"].tolist() == [2.99]  # on the last frame
    assert events["right"]["heel_strike"].tolist() == [0.0]


def test_event_more_than_half_a_frame_outside_is_still_left_out(tmp_path):
    from test_event_io import small_c3d
    from bmc_functions import read_events

    path = small_c3d(tmp_path, ["Right", "Right"], ["Foot Strike", "Foot Off"],
                     [1.0, 2.99 + 0.0051])  # half a frame is 0.005 s
    with pytest.warns(UserWarning, match=r"1 event\(s\) lie outside the trial"):
        events = read_events(path)
    assert events["right"]["toe_off"].size == 0


def test_compare_events_matches_one_to_one():
    from bmc_functions import compare_events

    # one detected strike between two reference strikes 60 ms apart: it can be found once
    reference = {"right": {"heel_strike": [1.00, 1.06]}}
    detected = {"right": {"heel_strike": [1.03]}}
    row = compare_events(detected, reference).iloc[0]
    assert (row["reference"], row["found"], row["found_%"]) == (2, 1, 50.0)
    assert row["max_ms"] == pytest.approx(30.0)
    # two detected for two references: the pairing of least total error (20 + 20 ms),
    # not each reference's nearest (both would take 1.04)
    detected = {"right": {"heel_strike": [1.04, 1.08]}}
    row = compare_events(detected, reference).iloc[0]
    assert (row["found"], row["median_ms"], row["max_ms"]) == (2, 30.0, 40.0)
    assert row["bias_ms"] == pytest.approx(30.0)


def test_compare_events_maximises_the_pairs_within_tolerance():
    from bmc_functions import compare_events

    # nearest-first would pair 1.09 with 1.10 and leave 1.00 alone (1.09 - 1.00 < 0.1)
    reference = {"right": {"heel_strike": [1.00, 1.10]}}
    detected = {"right": {"heel_strike": [1.09, 1.19]}}
    row = compare_events(detected, reference).iloc[0]
    assert row["found"] == 2
    assert row["max_ms"] == pytest.approx(90.0)


@pytest.mark.parametrize("side, event", [("Right", "heel strike"), ("RIGHT", "Heel_Strike"),
                                         ("r", "Foot Strike"), (" right ", "heel-strike")])
def test_compare_events_accepts_the_spellings_of_side_and_event(side, event):
    from bmc_functions import compare_events

    reference = {side: {event: [1.0, 2.0]}}
    detected = {"right": {"heel_strike": [1.01, 2.02]}}
    table = compare_events(detected, reference)
    row = table[(table["side"] == "right") & (table["event"] == "heel_strike")].iloc[0]
    assert row["found_%"] == 100.0
    assert compare_events(reference, detected).iloc[0]["found_%"] == 100.0


def test_compare_events_refuses_an_unknown_side_or_event_naming_it():
    from bmc_functions import compare_events

    good = {"right": {"heel_strike": [1.0]}}
    with pytest.raises(ValueError, match=r"reference: side must be 'right' or 'left'; "
                                         r"got 'centre'"):
        compare_events(good, {"centre": {"heel_strike": [1.0]}})
    with pytest.raises(ValueError, match=r"detected\['right'\]: event must be 'heel_strike' "
                                         r"or 'toe_off'; got 'midstance'"):
        compare_events({"right": {"midstance": [1.0]}}, good)
    with pytest.raises(ValueError, match=r"the side 'right' is given twice"):
        compare_events({"right": {"heel_strike": [1.0]}, "Right": {"toe_off": [1.5]}}, good)


def test_write_events_with_a_list_where_a_dict_belongs_says_which():
    from bmc_functions import write_events

    with pytest.raises(TypeError, match=r"events\['right'\] must be a dict event -> times.*"
                                        r"got a list"):
        write_events({"right": [1.0, 2.0]}, "unused.csv")


# ---- gait_events: heel and toe swapped, a cut-off at Nyquist, a rate contradicting ----

def _walk():
    from bmc_functions.examples import example_file

    trial = read_trc(example_file("gait/walk.trc"))
    roles = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
             "RHEEL": "RHEE", "RTOE": "RTOE", "LHEEL": "LHEE", "LTOE": "LTOE"}
    return trial, roles


def _events(trial, roles, **options):
    from bmc_functions import gait_events

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the walk's left strike in a gap (documented)
        return gait_events(trial, roles, **options)


def test_gait_events_refuses_heel_and_toe_swapped():
    trial, roles = _walk()
    assert _events(trial, roles)["right"]["heel_strike"].size == 5  # the boundary: right
    swapped = dict(roles, RHEEL="RTOE", RTOE="RHEE")
    with pytest.raises(ValueError, match=r"RHEE \(given as the right toe.*\) lies 1[0-9]{2} "
                                         r"mm behind RTOE \(given as the right heel.*swapped"):
        _events(trial, swapped)


def test_gait_events_heel_without_toe_is_a_clear_error():
    trial, roles = _walk()
    del roles["LTOE"]
    with pytest.raises(ValueError, match=r"side 'left' has LHEEL but not LTOE \(nor LMT5\)"):
        _events(trial, roles)


@pytest.mark.parametrize("factor", [1 - 1e-12, 1 + 1e-12])
def test_gait_events_refuses_a_cutoff_at_nyquist_of_a_rounded_rate(factor):
    trial, roles = _walk()
    trial.index = np.arange(len(trial)) / 100.0 * factor  # 100 Hz with rounding errors
    with pytest.raises(ValueError, match=r"cutoff must be between 0 and half the sampling "
                                         r"rate \(50 Hz\); got 50.0 \(it must lie at least "
                                         r"1 % below"):
        _events(trial, roles, cutoff=50.0)
    assert _events(trial, roles, cutoff=49.0)["right"]["heel_strike"].size == 5


def test_gait_events_refuses_a_cutoff_at_nyquist_of_a_time_index_rounded_to_ms():
    trial, roles = _walk()
    trial.index = np.round(np.arange(len(trial)) / 120.0, 3)  # median step 8 ms: 125 Hz
    trial.attrs["rate"] = 120.0
    with pytest.raises(ValueError, match=r"half the sampling rate \(60.00.. Hz"):
        _events(trial, roles, cutoff=60.0)


def test_gait_events_warns_of_a_declared_rate_contradicting_the_index():
    from bmc_functions import gait_events

    trial, roles = _walk()
    trial.attrs["rate"] = 200.0  # the index steps at 100 Hz
    with pytest.warns(RuntimeWarning, match=r"dynamic: attrs\['rate'\] = 200 Hz, but its "
                                            r"time index steps at 100 Hz.*index is used"), \
            pytest.warns(RuntimeWarning, match=r"events seem missing: left heel strikes"):
        events = gait_events(trial, roles)     # the walk's left strike in a gap (documented)
    assert events["right"]["heel_strike"].tolist() == [0.34, 1.44, 2.57, 3.66, 4.78]
    trial.attrs["rate"] = 101.0  # within 2 %: no word
    assert not [m for m in warning_messages(gait_events, trial, roles) if "attrs" in m]


def test_step_time_of_feet_striking_at_the_same_instants_is_nan_with_a_warning():
    from bmc_functions import spatiotemporal_parameters

    strikes, offs = np.array([0.1, 1.1, 2.1]), np.array([0.7, 1.7])
    both = {"right": {"heel_strike": strikes, "toe_off": offs},
            "left": {"heel_strike": strikes + 0.001, "toe_off": offs}}
    with pytest.warns(RuntimeWarning, match=r"3 heel strike\(s\) of the two feet lie within "
                                            r"80 ms of each other"):
        table = spatiotemporal_parameters(both)
    assert table["step_time"].isna().all()
    assert table["stride_time"].tolist() == [1.0, 1.0]
    # the boundary: half a stride apart, steps of 0.5 s and no warning
    apart = {"right": both["right"], "left": {"heel_strike": strikes + 0.5,
                                              "toe_off": offs + 0.5}}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        table = spatiotemporal_parameters(apart)
    assert table["step_time"].tolist() == pytest.approx([0.5, 0.5])


# ---- derivative on a non-uniform time index ----------------------------------------

def _series(time):
    import pandas as pd

    return pd.Series(time ** 2, index=pd.Index(time, name="time"))


def test_derivative_refuses_a_non_uniform_time_index():
    from bmc_functions import derivative

    # 50 frames at 100 Hz then 50 at 200 Hz: no step is 1.5 times the median
    time = np.r_[np.arange(50) * 0.01, 0.5 + np.arange(50) * 0.005]
    with pytest.raises(ValueError, match=r"data.index \(time\) is not uniform: its steps "
                                         r"range from 0.005 to 0.01"):
        derivative(_series(time))
    jitter = np.cumsum(0.01 + np.random.default_rng(1).uniform(-0.002, 0.002, 100))
    with pytest.raises(ValueError, match="not uniform"):
        derivative(_series(jitter), 100)


def test_derivative_accepts_a_time_column_rounded_to_the_millisecond():
    from bmc_functions import derivative

    # 150 Hz written with 3 decimals (steps of 6 and 7 ms): the boundary, accepted
    time = np.round(np.arange(300) / 150, 3)
    velocity = derivative(_series(time), 150).to_numpy()
    exact = 2 * np.arange(300) / 150   # d(t^2)/dt on the true, unrounded times
    assert np.max(np.abs(velocity[1:-1] - exact[1:-1])) < 0.2
    # a full-precision index at 100 Hz (float rounding only) is uniform too
    assert np.isfinite(derivative(_series(np.arange(100) * 0.01)).to_numpy()).all()


# ---- write_mot and convert of Plug-in Gait angles whose attrs were lost ---------------

def _pig_like_angles(with_foot=True):
    """Pelvis and hip angles as Plug-in Gait gives them (tilt-obliquity-rotation), two
    halves concatenated with different attrs (pd.concat then drops them all)."""
    import pandas as pd

    rng = np.random.default_rng(32)
    columns = [("pelvis", "right", a) for a in ("tilt", "obliquity", "rotation")]
    columns += [("hip", "right", "flexion")]
    columns += [("foot", "right", "progression")] if with_foot else []
    halves = []
    for k in range(2):
        half = pd.DataFrame(rng.uniform(-15, 15, (5, len(columns))),
                            columns=pd.MultiIndex.from_tuples(columns),
                            index=pd.Index((np.arange(5) + 5 * k) / 100, name="time"))
        half.attrs = {"units": "deg", "model": "Plug-in Gait (Vicon)", "trial": k}
        halves.append(half)
    joined = pd.concat(halves)
    assert joined.attrs == {}  # what the user has after pd.concat
    return joined


def test_write_mot_of_plug_in_gait_angles_without_attrs_renames_the_pelvis(tmp_path):
    from bmc_functions import read_mot, write_mot

    angles = _pig_like_angles()
    angles.attrs = {"units": "deg"}
    write_mot(angles, tmp_path / "pig.mot")
    mot = read_mot(tmp_path / "pig.mot")
    # Plug-in Gait's order is OpenSim's: renamed with OpenSim's signs, not converted
    np.testing.assert_array_equal(mot["pelvis_tilt"], -angles["pelvis", "right", "tilt"])
    np.testing.assert_array_equal(mot["pelvis_list"], -angles["pelvis", "right", "obliquity"])
    np.testing.assert_array_equal(mot["pelvis_rotation"],
                                  angles["pelvis", "right", "rotation"])


def test_write_mot_refuses_pelvis_angles_of_an_unknown_sequence(tmp_path):
    from bmc_functions import write_mot

    angles = _pig_like_angles(with_foot=False)
    angles.attrs = {"units": "deg"}
    with pytest.raises(ValueError, match=r"pelvis angles' sequence is unknown.*"
                                         r"attrs\['model'\] = 'Plug-in Gait' or .*"
                                         r"attrs\['pelvis_sequence'\] = 'YXZ'"):
        write_mot(angles, tmp_path / "x.mot")
    angles.attrs["model"] = "Plug-in Gait"  # said: renamed
    write_mot(angles, tmp_path / "pig.mot")
    angles.attrs = {"units": "deg", "pelvis_sequence": "YXZ"}  # said: converted
    write_mot(angles, tmp_path / "isb.mot")


def test_convert_of_a_plug_in_gait_csv_renames_the_pelvis(tmp_path):
    from bmc_functions import read_mot
    from bmc_functions.cli import main

    angles = _pig_like_angles()
    table = angles.copy()
    table.columns = [".".join(c) for c in angles.columns]
    table.to_csv(tmp_path / "pig_angles.csv")
    assert main(["convert", str(tmp_path / "pig_angles.csv"), "-o", str(tmp_path / "o"),
                 "-q"]) == 0
    mot = read_mot(tmp_path / "o" / "pig_angles.mot")
    np.testing.assert_allclose(mot["pelvis_tilt"], -angles["pelvis", "right", "tilt"],
                               atol=1e-12)
    np.testing.assert_allclose(mot["pelvis_list"], -angles["pelvis", "right", "obliquity"],
                               atol=1e-12)
    # --model isb on a file with a foot progression angle contradicts it
    assert main(["convert", str(tmp_path / "pig_angles.csv"), "--model", "isb", "-o",
                 str(tmp_path / "p"), "-q"]) == 1


# ---- map_trials: a function workers cannot import, items that are no iterable --------

def test_map_trials_refuses_an_unpicklable_function_before_starting_workers():
    import time
    from bmc_functions.batch import map_trials

    def nested(item):
        return item

    for function in (lambda item: item, nested):
        start = time.perf_counter()
        with pytest.raises(ValueError, match=r"cannot be sent to worker processes.*module "
                                             r"level.*or run with workers=None"):
            map_trials(function, [1, 2], workers=2)
        assert time.perf_counter() - start < 0.5  # refused before a worker started
    assert map_trials(lambda item: item + 1, [1, 2]) == [2, 3]  # in this process: fine


def test_map_trials_refuses_a_function_of_an_interactive_session(monkeypatch):
    import sys
    import types
    from bmc_functions.batch import map_trials

    session = types.ModuleType("__main__")  # a notebook's __main__ has no file
    monkeypatch.setitem(sys.modules, "__main__", session)

    def cell(item):
        return item
    cell.__module__ = "__main__"
    with pytest.raises(ValueError, match=r"'.*cell' cannot be sent to worker processes "
                                         r"\(it is defined in an interactive session"):
        map_trials(cell, [1], workers=1)


@pytest.mark.parametrize("items", [None, "walk.trc", 3])
def test_map_trials_names_items_that_are_no_iterable_of_trials(items):
    from bmc_functions.batch import map_trials

    with pytest.raises(TypeError, match=r"items must be an iterable of trials .*got "):
        map_trials(abs, items)


# ---- write_trc's default format: values too small for it, times closer than 1 us -------

def _table(values, time):
    import pandas as pd

    columns = pd.MultiIndex.from_product([["A"], ["x", "y", "z"]])
    return pd.DataFrame(values, columns=columns, index=pd.Index(time, name="time"))


def test_write_trc_warns_when_the_default_format_zeroes_the_data(tmp_path):
    from bmc_functions import write_trc

    tiny = _table([[1e-7, 2e-7, 3e-7], [1e-7, 2e-8, 0.0]], [0.0, 0.01])
    with pytest.warns(UserWarning, match=r"'%.6f' writes the coordinates to 1e-06, but the "
                                         r"largest is 3e-07.*5 nonzero value\(s\) written "
                                         r"as 0"):
        write_trc(tiny, tmp_path / "tiny.trc", rate=100, units="km")
    write_trc(tiny, tmp_path / "kept.trc", rate=100, units="km", float_format="%.10g")
    np.testing.assert_allclose(read_trc(tmp_path / "kept.trc").to_numpy(), tiny.to_numpy(),
                               rtol=1e-9)
    # the boundary: a largest value of 1e-3 keeps 4 digits (silent); 1e-16 beside 1000 mm
    # (a rotation's rounding) is written as 0 without a word
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        write_trc(_table([[1e-3, 0, 0], [0, 0, 0]], [0.0, 0.01]), tmp_path / "a.trc",
                  rate=100, units="m")
        write_trc(_table([[1000.0, 1e-16, 0], [0, 0, 0]], [0.0, 0.01]), tmp_path / "b.trc",
                  rate=100, units="mm")
    with pytest.warns(UserWarning, match="fewer than 4 significant digits"):
        write_trc(_table([[9.9e-4, 0, 0], [0, 0, 0]], [0.0, 0.01]), tmp_path / "c.trc",
                  rate=100, units="m")


def test_write_trc_keeps_times_less_than_a_microsecond_apart_distinct(tmp_path):
    from bmc_functions import write_trc

    time = 1.0 + np.arange(4) * 4e-7  # 2.5 MHz
    df = _table(np.ones((4, 3)), time)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the DataRate against the Time column: its own
        write_trc(df, tmp_path / "fast.trc", rate=2.5e6, units="mm")
        back = read_trc(tmp_path / "fast.trc")
    assert (np.diff(back.index.to_numpy()) > 0).all()
    np.testing.assert_allclose(back.index.to_numpy(), time, atol=1e-12)
    # the boundary: 1 us apart keeps the 6 decimals of the default
    write_trc(_table(np.ones((3, 3)), np.arange(3) * 1e-6), tmp_path / "us.trc", rate=1e6,
              units="mm")
    assert (tmp_path / "us.trc").read_text().splitlines()[7].split("\t")[1] == "0.000001"


# ---- a pose in mm on a skeleton in metres --------------------------------------------

@pytest.mark.parametrize("scale", [1000.0, 100.0, 0.001])
def test_pose_in_other_units_than_the_skeleton_is_refused(scale):
    from bmc_functions import Skeleton, pose_to_angles

    skeleton = Skeleton.default()
    pose = {name: point * scale for name, point in skeleton.tpose().items()}
    with pytest.raises(ValueError, match=rf"positions: the bones are {scale:g} times the "
                                         r"skeleton's .*different units"):
        pose_to_angles(pose, skeleton)


@pytest.mark.parametrize("scale", [0.25, 4.0])
def test_pose_of_another_size_in_the_same_units_is_accepted(scale):
    from bmc_functions import Skeleton, pose_to_angles

    skeleton = Skeleton.default()
    pose = {name: point * scale for name, point in skeleton.tpose().items()}
    result = pose_to_angles(pose, skeleton)
    assert np.allclose(result.angles["leftknee"], 0.0, atol=1e-12)


# ---- fill_gaps_rigid: a marker that slipped during its gap, another subject's reference --

def _cluster_trial(slip=0.0):
    """A rigid 4-marker thigh-like cluster (radius about 70 mm) on a smooth path, marker 3
    lost in frames 60-99 and, from frame 80 on, moved by `slip` mm on the cluster."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(11)
    cluster = np.array([[60.0, 0, 0], [-30, 50, 0], [-30, -50, 10], [0, 10, 70]])
    t = np.linspace(0, 2 * np.pi, 160)[:, None]
    R = Rotation.from_rotvec(0.6 * np.sin(t * rng.uniform(0.5, 2, 3))).as_matrix()
    L = 400 * np.sin(t * rng.uniform(0.5, 2, 3)) + [1000, 800, 600]
    moved = np.repeat(cluster[None], len(t), axis=0)
    moved[80:, 3] += [slip, 0, 0]
    truth = np.einsum("fij,fnj->fni", R, moved) + L[:, None, :]
    markers = truth + rng.normal(0, 0.5, truth.shape)  # 0.5 mm of noise
    markers[60:100, 3] = np.nan
    return markers, truth, cluster


def test_fill_gaps_rigid_leaves_a_gap_across_which_the_marker_slipped_unfilled():
    from bmc_functions import fill_gaps_rigid

    markers, _, _ = _cluster_trial(slip=40.0)
    with pytest.warns(RuntimeWarning, match=r"1 gap\(s\) left unfilled: the marker lies "
                                            r"elsewhere on the cluster after the gap.*"
                                            r"marker 3 in frames 60-99 \(moved (39|40|41)\."):
        filled, mask = fill_gaps_rigid(markers, return_mask=True)
    assert np.isnan(filled[60:100, 3]).all() and not mask[60:100, 3].any()


def test_fill_gaps_rigid_fills_a_gap_without_slip_silently():
    from bmc_functions import fill_gaps_rigid

    markers, truth, _ = _cluster_trial(slip=5.0)  # 5 mm: within the skin's motion
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        filled = fill_gaps_rigid(markers)
    assert np.nanmax(np.abs(filled[60:80, 3] - truth[60:80, 3])) < 10


def test_fill_gaps_rigid_refuses_to_fill_from_a_reference_25_percent_larger():
    from bmc_functions import fill_gaps_rigid

    markers, truth, cluster = _cluster_trial()
    with pytest.warns(RuntimeWarning, match=r"reference: its markers lie 1.25 times as far "
                                            r"apart as in markers.*No gap is filled"):
        filled = fill_gaps_rigid(markers, cluster * 1.25)
    assert np.isnan(filled[60:100, 3]).all()
    with warnings.catch_warnings():   # the boundary: 10 % larger is still filled
        warnings.simplefilter("error")
        filled = fill_gaps_rigid(markers, cluster * 1.10)
    assert np.isfinite(filled[60:100, 3]).all()
    np.testing.assert_allclose(fill_gaps_rigid(markers, cluster)[60:100, 3],
                               truth[60:100, 3], atol=3)


# ---- a functional trial with the pelvis cluster mirrored in half its frames -----------

def test_functional_centre_leaves_out_frames_with_the_pelvis_mirrored():
    from helpers import load_data_script
    from bmc_functions import functional_joint_centre

    trial = load_data_script("generate_functional_data").make_trials()["hip_star_arc"]
    pelvis = np.stack([trial["pelvis"][k] for k in ("RASI", "LASI", "RPSI", "LPSI")], axis=1)
    thigh = np.stack(list(trial["thigh"].values()), axis=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        clean = functional_joint_centre(pelvis, thigh)
    n = len(pelvis)
    mirrored = pelvis.copy()
    mirrored[n // 2:] = pelvis[n // 2:][:, [1, 0, 3, 2]]   # RASI<->LASI, RPSI<->LPSI
    with pytest.warns(RuntimeWarning, match=rf"75[01] of {n} frames of markers_1 turn the "
                                            r"cluster by more than 90 degrees"):
        centre = np.asarray(functional_joint_centre(mirrored, thigh))
    # one half is left out (either: each half alone is one rigid cluster); the other gives
    # the whole clean trial's centre within a few mm
    left_out = np.isnan(centre).any(axis=1)
    assert left_out.sum() in (750, 751)
    assert left_out[:n // 2].all() or left_out[n // 2 + 1:].all()
    error = np.linalg.norm(centre[~left_out] - np.asarray(clean)[~left_out], axis=1)
    assert np.max(error) < 10


# ---- misleading errors, now named ------------------------------------------------------

def test_gait_events_names_two_roles_mapped_to_one_label():
    trial, roles = _walk()
    with pytest.raises(ValueError, match=r"markers maps the label 'RHEE' to 2 roles: RHEEL "
                                         r".*RTOE"):
        _events(trial, dict(roles, RTOE="RHEE"))
    with pytest.raises(ValueError, match=r"markers maps the label 'RASI' to 2 roles"):
        _events(trial, dict(roles, LASIS="RASI"))


@pytest.mark.parametrize("wrong, right", [("RHEAL", "RHEEL"), ("RTOES", "RTOE"),
                                          ("rtoe", "RTOE")])
def test_gait_events_names_a_misspelt_foot_role(wrong, right):
    trial, roles = _walk()
    roles[wrong] = roles.pop(right)
    with pytest.raises(ValueError, match=rf"markers: unknown role '{wrong}'; did you mean "
                                         rf"'{right}'"):
        _events(trial, roles)


def test_gait_events_names_a_misspelt_foot_label():
    trial, roles = _walk()
    with pytest.raises(ValueError, match=r"markers\['RTOE'\] = 'RTEO' .*no marker with "
                                         r"that label.*'RTOE'"):
        _events(trial, dict(roles, RTOE="RTEO"))


def test_boolean_coordinates_are_named_not_blamed_on_units():
    from bmc_functions import calibrate_lower_limb
    from helpers import synthetic_markers

    trial, roles = _walk()
    flags = trial.astype(bool)
    flags.attrs = dict(trial.attrs)
    with pytest.raises(TypeError, match=r"dynamic must hold coordinates \(numbers\); got "
                                        r"boolean columns \(True/False\) in column \('"):
        _events(flags, roles)
    static = read_trc(ROOT / "data" / "markers" / "static.trc")
    flags = static.astype(bool)
    flags.attrs = dict(static.attrs)
    with pytest.raises(TypeError, match=r"the static trial: marker 'PEL1', coordinate 'x' "
                                        r"holds booleans \(True/False\), not coordinates"):
        calibrate_lower_limb(flags, synthetic_markers())


def test_a_non_numeric_marker_column_is_named():
    trial, roles = _walk()
    text = trial.copy()
    text[("RTOE", "x")] = text[("RTOE", "x")].astype(object)
    text.loc[text.index[3], ("RTOE", "x")] = "abc"
    with pytest.raises(TypeError, match=r"dynamic must hold coordinates \(numbers\); got "
                                        r"text \('abc' at time 0.03 is not a number; 1 such "
                                        r"value\(s\)\) in column \('RTOE', 'x'\)"):
        _events(text, roles)


def test_plotting_options_of_the_wrong_type_are_named():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pandas as pd
    from bmc_functions import normalize_by_side, residual_analysis
    from bmc_functions.plotting import (plot_angles, plot_gait_cycles,
                                        plot_residual_analysis, plot_trial_3d)

    columns = pd.MultiIndex.from_tuples([("knee", side, "flexion") for side in ("right",
                                                                                "left")])
    t = np.arange(400) / 100
    angles = pd.DataFrame(np.c_[np.sin(2 * np.pi * t), np.cos(2 * np.pi * t)],
                          columns=columns, index=pd.Index(t, name="time"))
    events = {"right": {"heel_strike": [0.5, 1.5, 2.5], "toe_off": [1.1, 2.1]},
              "left": {"heel_strike": [1.0, 2.0, 3.0], "toe_off": [1.6, 2.6]}}
    cycles = normalize_by_side(angles, events)
    result = residual_analysis(np.random.default_rng(0).normal(size=(200, 2)).cumsum(0),
                               rate=100)
    try:
        with pytest.raises(TypeError, match=r"toe_off\['right'\] must be a number .*got "
                                            r"'60' \(str\)"):
            plot_gait_cycles(cycles, toe_off={"right": "60"})
        with pytest.raises(TypeError, match=r"figsize must be \(width, height\) in inches"):
            plot_angles(angles, figsize="10x5")
        with pytest.raises(TypeError, match=r"colors must be a list of matplotlib colours "
                                            r".*got 3 \(int\)"):
            plot_residual_analysis(result, colors=3)
        with pytest.raises(ValueError, match=r"got 'notacolour' in it"):
            plot_residual_analysis(result, colors=["red", "notacolour"])
        with pytest.raises(TypeError, match=r"ax must be a matplotlib Axes or None; got "
                                            r"'ax' \(str\)"):
            plot_residual_analysis(result, ax="ax")
        with pytest.raises(TypeError, match=r"ax must be a 3D matplotlib Axes"):
            plot_trial_3d(read_trc(ROOT / "data" / "markers" / "walk.trc"),
                          ax=plt.figure().add_subplot())
        # the boundary: one colour for every curve, NaN toe-off, a pair of sizes: drawn
        plot_residual_analysis(result, colors="red")
        plot_gait_cycles(cycles, toe_off={"right": 60.0, "left": np.nan}, figsize=(6, 4))
    finally:
        plt.close("all")
