"""Tests of bmc_functions.files.opensim: OpenSim .mot/.sto files.

Expected values are the numbers written by hand in the small files below (or parsed by
hand with str.split from OpenSim's own output), never the reader's own output.
"""

import re
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from bmc_functions import (align_times, compose, opensim_coordinates, pelvis_angles, read_mot,
                           write_mot)
from bmc_functions.files.trc import write_trc

from helpers import SHARED_DATA, needs_shared, skip_without_shared

DATA = Path(__file__).resolve().parent / "data"
HEAD = "Coordinates\nversion=1\nnRows=2\nnColumns=3\ninDegrees=yes\nendheader\n"


def read_quietly(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return read_mot(path)


def write_text(tmp_path, text, name="bad.mot"):
    path = tmp_path / name
    path.write_bytes(text.encode())
    return path


def malformed(tmp_path, text, match):
    path = write_text(tmp_path, text)
    with pytest.raises(ValueError, match=match) as info:
        read_mot(path)
    assert "bad.mot" in str(info.value)


# --- reading ---------------------------------------------------------------------------

def test_small_opensim_file():
    # OpenSim's layout: CRLF, a blank line and description lines in the header, values
    # padded with spaces
    df = read_quietly(DATA / "opensim_ik_small.mot")
    assert list(df.columns) == ["pelvis_tilt", "knee_angle_r", "pelvis_tx"]
    assert df.index.name == "time"
    np.testing.assert_array_equal(df.index.to_numpy(), [0.0, 0.00666667, 0.01333333])
    np.testing.assert_array_equal(df["knee_angle_r"].to_numpy(), [12.5, 13.0, 13.75])
    np.testing.assert_array_equal(df["pelvis_tx"].to_numpy(), [0.00467157, 0.01, 0.015])
    assert df.attrs["name"] == "Coordinates"
    assert df.attrs["in_degrees"] is True
    assert df.attrs["header"] == {"version": "1", "nRows": "3", "nColumns": "4",
                                  "inDegrees": "yes"}
    assert df.attrs["description"] == ["Units are S.I. units (second, meters, Newtons, ...)",
                                       "Angles are in degrees."]


def test_real_opensim_ik_result():
    skip_without_shared("ik_output_run.mot")
    path = SHARED_DATA / "ik_output_run.mot"
    df = read_quietly(path)
    lines = path.read_text().splitlines()
    end = [line.strip() for line in lines].index("endheader")
    labels = lines[end + 1].split("\t")
    assert ["time", *df.columns] == [label.strip() for label in labels]
    assert df.shape == (122, 39)
    for k in (0, 60, 121):  # rows parsed by hand
        row = [float(v) for v in lines[end + 2 + k].split("\t")]
        assert df.index[k] == row[0]
        np.testing.assert_array_equal(df.iloc[k].to_numpy(), row[1:])
    assert df.attrs["in_degrees"] is True
    assert df["knee_angle_r"].between(-5, 140).all()  # degrees, flexion positive


def test_real_opensim_ik_result_round_trip(tmp_path):
    skip_without_shared("ik_output_run.mot")
    path = SHARED_DATA / "ik_output_run.mot"
    df = read_quietly(path)
    write_mot(df, tmp_path / "again.mot")
    back = read_quietly(tmp_path / "again.mot")
    pd.testing.assert_frame_equal(back, df, check_exact=True)
    assert back.attrs["in_degrees"] is True and back.attrs["name"] == "Coordinates"


def test_space_separated_old_file(tmp_path):
    text = ("name walk\ndatacolumns 3\ndatarows 2\nrange 0 0.01\nendheader\n"
            "time   knee_angle_r   hip_flexion_r\n"
            "  0.00   12.5   30.0\n  0.01   13.0   NaN\n")
    df = read_quietly(write_text(tmp_path, text, "old.mot"))
    np.testing.assert_array_equal(df.to_numpy(), [[12.5, 30.0], [13.0, np.nan]])
    assert df.attrs["in_degrees"] is None and df.attrs["name"] == "name walk"


def test_trailing_tabs_and_blank_lines(tmp_path):
    text = HEAD + "time\ta\tb\t\n0.0\t1.0\t2.0\t\n0.01\t3.0\t4.0\t\n\n"
    df = read_quietly(write_text(tmp_path, text, "tabs.mot"))
    np.testing.assert_array_equal(df.to_numpy(), [[1.0, 2.0], [3.0, 4.0]])


def test_no_rows(tmp_path):
    text = HEAD.replace("nRows=2", "nRows=0") + "time\ta\tb\n"
    df = read_quietly(write_text(tmp_path, text, "empty.mot"))
    assert df.shape == (0, 2) and list(df.columns) == ["a", "b"]


# --- bad files: ValueError naming the file and the line --------------------------------

def test_no_endheader(tmp_path):
    malformed(tmp_path, "Coordinates\nversion=1\ntime\ta\n0\t1\n",
              r"line 5: the file ends before the line 'endheader'")


def test_endless_header_is_refused(tmp_path):
    malformed(tmp_path, "x=1\n" * 20_000, r"line 10001: no line 'endheader' in the first "
                                          r"10000 lines")


def test_blank_lines_after_endheader_are_skipped(tmp_path):
    """OpenSim's own external-loads files (grf_run.mot) have a blank line there; a row's
    line number in an error counts it."""
    df = read_quietly(write_text(tmp_path, HEAD + "\n\n" + "time\ta\tb\n0\t1\t2\n0.1\t3\t4\n"))
    assert df["b"].tolist() == [2.0, 4.0]
    malformed(tmp_path, HEAD + "\n" + "time\ta\tb\n0\t1\t2\n0.1\t3\n",
              r"line 10: .*")


@needs_shared("grf_run.mot")
def test_opensims_external_loads_file_reads():
    df = read_quietly(SHARED_DATA / "grf_run.mot")
    assert df.shape == (246, 18) and df.index[-1] == pytest.approx(0.81666667)
    assert df["R_ground_force_vy"].max() == pytest.approx(1751.200188)


def test_no_labels(tmp_path):
    malformed(tmp_path, HEAD, r"line 7: expected the column labels")


def test_first_label_not_time(tmp_path):
    malformed(tmp_path, HEAD + "frame\ta\tb\n1\t2\t3\n",
              r"line 7: the first column label must be 'time'; got 'frame'")


def test_duplicate_labels(tmp_path):
    malformed(tmp_path, HEAD + "time\ta\ta\n0\t2\t3\n", r"line 7: duplicate column labels: a")


def test_empty_label(tmp_path):
    malformed(tmp_path, HEAD + "time\t\tb\n0\t2\t3\n", r"line 7: column 2 has no label")


def test_value_not_a_number(tmp_path):
    malformed(tmp_path, HEAD + "time\ta\tb\n0\t1\t2\n0.01\t1,5\t2\n",
              r"line 9: column 2 \('a'\) is not a number: '1,5'")


def test_row_longer_than_the_labels(tmp_path):
    malformed(tmp_path, HEAD + "time\ta\tb\n0\t1\t2\n0.01\t1\t2\t3\n",
              r"line 9: the row has 4 fields where the rows before have 3")


def test_first_row_longer_than_the_labels(tmp_path):
    malformed(tmp_path, HEAD + "time\ta\tb\n0\t1\t2\t9\n0.01\t1\t2\t\n",
              r"line 8: the row has more fields than the 3 column labels")


def test_row_shorter_than_the_labels(tmp_path):
    malformed(tmp_path, HEAD + "time\ta\tb\n0\t1\n0.01\t1\n",
              r"line 8: the row has 2 fields for the 3 column labels")


def test_infinite_value(tmp_path):
    malformed(tmp_path, HEAD + "time\ta\tb\n0\t1\tinf\n", r"line 8: infinite value")


def test_missing_time(tmp_path):
    malformed(tmp_path, HEAD + "time\ta\tb\n0\t1\t2\n\t1\t2\n", r"line 9: no time value")


def test_directory_is_refused(tmp_path):
    with pytest.raises(ValueError, match=r"is a directory; expected a .mot/.sto file"):
        read_mot(tmp_path)


# --- warnings -------------------------------------------------------------------------------

def test_nrows_mismatch_warns(tmp_path):
    path = write_text(tmp_path, HEAD.replace("nRows=2", "nRows=5") + "time\ta\tb\n0\t1\t2\n")
    with pytest.warns(UserWarning, match=r"the header says nRows = 5 but the table has 1"):
        read_mot(path)


def test_last_line_cut_warns_and_is_nan(tmp_path):
    path = write_text(tmp_path, HEAD + "time\ta\tb\n0\t1\t2\n0.01\t1\t31.25"[:-3])
    with pytest.warns(UserWarning, match=r"the last line does not end with a line break "
                                         r"\(is the file cut\?\): its last value may be "
                                         r"cut short, so these columns of that row were "
                                         r"set to NaN: b"):
        df = read_mot(path)
    np.testing.assert_array_equal(df.to_numpy(), [[1.0, 2.0], [1.0, np.nan]])


def test_time_not_increasing_warns(tmp_path):
    path = write_text(tmp_path, HEAD + "time\ta\tb\n0.01\t1\t2\n0.0\t1\t2\n")
    with pytest.warns(UserWarning, match=r"time does not increase at line 9"):
        read_mot(path)


# --- writing --------------------------------------------------------------------------------

def angles_frame(values, labels=("knee_angle_r", "hip_flexion_r"), times=None):
    values = np.array(values, dtype=float)
    times = np.arange(len(values)) / 100 if times is None else times
    return pd.DataFrame(values, columns=list(labels), index=pd.Index(times, name="time"))


def test_write_layout_is_opensims(tmp_path):
    df = angles_frame([[12.5, 30.0], [np.nan, 31.0]])
    write_mot(df, tmp_path / "a.mot", in_degrees=False, name="ik")
    lines = (tmp_path / "a.mot").read_text().split("\n")
    assert lines[:7] == ["ik", "version=1", "nRows=2", "nColumns=3", "inDegrees=no",
                         "endheader", "time\tknee_angle_r\thip_flexion_r"]
    assert lines[7].split("\t") == ["0.0", "12.5", "30.0"]
    assert lines[8].split("\t") == ["0.01", "NaN", "31.0"]


def test_write_read_round_trip_exact(tmp_path):
    rng = np.random.default_rng(4)
    values = rng.normal(0, 50, (200, 5))
    values[rng.random(values.shape) < 0.05] = np.nan
    df = angles_frame(values, [f"q{k}" for k in range(5)], np.arange(200) / 150)
    df.attrs = {"in_degrees": True, "name": "Coordinates"}
    write_mot(df, tmp_path / "r.mot")
    back = read_quietly(tmp_path / "r.mot")
    pd.testing.assert_frame_equal(back, df, check_exact=True)
    assert back.attrs["in_degrees"] is True and back.attrs["name"] == "Coordinates"


@settings(max_examples=30, deadline=None)
@given(arrays(np.float64, (6, 3), elements=st.floats(allow_infinity=False) | st.just(np.nan)))
def test_round_trip_property(tmp_path_factory, values):
    df = angles_frame(values, ["a", "b", "c"])
    path = tmp_path_factory.mktemp("mot") / "p.mot"
    write_mot(df, path, in_degrees=True)
    back = read_mot(path)
    np.testing.assert_array_equal(back.to_numpy(), values)  # bit for bit, NaN where NaN
    np.testing.assert_array_equal(back.index.to_numpy(), df.index.to_numpy())


def test_write_with_opensims_format_rounds(tmp_path):
    df = angles_frame([[12.123456789, 30.0]])
    write_mot(df, tmp_path / "f.mot", in_degrees=True, float_format="%.8f")
    back = read_quietly(tmp_path / "f.mot")
    assert back.iloc[0, 0] == 12.12345679


def test_write_needs_in_degrees(tmp_path):
    with pytest.raises(ValueError, match=r"in_degrees: df.attrs has no 'in_degrees' and no "
                                         r"'units' \('deg' or 'rad'\); pass in_degrees=True"):
        write_mot(angles_frame([[1.0, 2.0]]), tmp_path / "x.mot")


@pytest.mark.parametrize("flag", ["yes", 1, np.array(True)])
def test_write_in_degrees_must_be_a_bool(tmp_path, flag):
    with pytest.raises(TypeError, match=r"in_degrees must be True or False"):
        write_mot(angles_frame([[1.0, 2.0]]), tmp_path / "x.mot", in_degrees=flag)


def test_write_refuses_multilevel_columns(tmp_path):
    df = angles_frame([[1.0, 2.0]])
    df.columns = pd.MultiIndex.from_tuples([("knee", "flexion"), ("hip", "flexion")])
    with pytest.raises(ValueError, match=r"df has 2 column levels; .* flatten them"):
        write_mot(df, tmp_path / "x.mot", in_degrees=True)


@pytest.mark.parametrize("label", ["a\tb", "", " a", "time", 3])
def test_write_refuses_bad_labels(tmp_path, label):
    df = angles_frame([[1.0, 2.0]], [label, "z"])
    with pytest.raises(ValueError, match=r"column label .* must be a non-empty string"):
        write_mot(df, tmp_path / "x.mot", in_degrees=True)


def test_write_refuses_duplicate_labels(tmp_path):
    with pytest.raises(ValueError, match=r"duplicate column labels: a"):
        write_mot(angles_frame([[1.0, 2.0]], ["a", "a"]), tmp_path / "x.mot",
                  in_degrees=True)


def test_write_refuses_infinite_values(tmp_path):
    with pytest.raises(ValueError, match=r"df contains infinite values"):
        write_mot(angles_frame([[1.0, np.inf]]), tmp_path / "x.mot", in_degrees=True)


def test_write_refuses_booleans(tmp_path):
    df = angles_frame([[1.0, 2.0]]) > 1
    with pytest.raises(TypeError, match=r"df must hold numbers; got boolean columns"):
        write_mot(df, tmp_path / "x.mot", in_degrees=True)


def test_write_refuses_time_that_does_not_increase(tmp_path):
    df = angles_frame([[1.0, 2.0], [1.0, 2.0]], times=[0.01, 0.01])
    with pytest.raises(ValueError, match=r"df.index \(time\) must increase; got 0.01 then "
                                         r"0.01"):
        write_mot(df, tmp_path / "x.mot", in_degrees=True)


def test_write_refuses_a_line_break_in_the_name_or_path(tmp_path):
    df = angles_frame([[1.0, 2.0]])
    with pytest.raises(ValueError, match=r"name must be one line of text"):
        write_mot(df, tmp_path / "x.mot", in_degrees=True, name="a\nb")
    with pytest.raises(ValueError, match=r"path: the file name must not contain a line "
                                         r"break"):
        write_mot(df, tmp_path / "x\n.mot", in_degrees=True)


def test_write_refuses_a_bad_float_format(tmp_path):
    with pytest.raises(ValueError, match=r"float_format must format one number"):
        write_mot(angles_frame([[1.0, 2.0]]), tmp_path / "x.mot", in_degrees=True,
                  float_format="abc")


def test_write_refuses_a_non_dataframe(tmp_path):
    with pytest.raises(TypeError, match=re.escape("df must be a pandas DataFrame indexed "
                                                  "by time; got ndarray")):
        write_mot(np.ones((2, 2)), tmp_path / "x.mot", in_degrees=True)


def test_last_line_cut_inside_a_middle_column(tmp_path):
    # '13.75' cut to '13.7' with the last column absent: 13.7 must not be read
    path = write_text(tmp_path, HEAD + "time\ta\tb\n0\t1\t2\n0.01\t13.7")
    with pytest.warns(UserWarning, match=r"set to NaN: a$"):
        df = read_mot(path)
    np.testing.assert_array_equal(df.to_numpy(), [[1.0, 2.0], [np.nan, np.nan]])


def test_last_line_cut_in_its_time(tmp_path):
    path = write_text(tmp_path, HEAD + "time\ta\tb\n0\t1\t2\n0.0")
    with pytest.warns(UserWarning, match=r"stops in its time: the row was left out"):
        df = read_mot(path)
    np.testing.assert_array_equal(df.to_numpy(), [[1.0, 2.0]])


def test_fuzz_cut_at_every_byte(tmp_path):
    from read_worker import read_in_child

    raw = (DATA / "opensim_ik_small.mot").read_bytes()
    original = read_quietly(DATA / "opensim_ik_small.mot")
    paths = []
    for k in range(len(raw)):
        path = tmp_path / f"cut{k}.mot"
        path.write_bytes(raw[:k])
        paths.append(path)
    outcomes = read_in_child("read_mot", paths, folder=tmp_path, timeout=20.0)
    counts = {}
    for path, outcome in zip(paths, outcomes):
        counts[outcome[0]] = counts.get(outcome[0], 0) + 1
        assert outcome[0] in ("ok", "ValueError"), (path.name, outcome[:2])
        if outcome[0] == "ValueError":
            assert path.name in outcome[1]
            continue
        _, time_, _, values, columns, _ = outcome
        assert columns == list(original.columns)
        rows = original.index.get_indexer(time_)
        assert (rows >= 0).all()
        expected = original.to_numpy()[rows]
        present = ~np.isnan(values)
        np.testing.assert_array_equal(values[present], expected[present])
    assert counts["ok"] > 100 and counts["ValueError"] > 100


def test_file_cut_in_the_labels_line(tmp_path):
    malformed(tmp_path, HEAD + "time\tknee_an", r"line 7: the file ends in the column "
                                                 r"labels line \(is it cut\?\)")


# --- issue 21: a short row, a truncating format ------------------------------------------

def test_short_row_in_the_middle_is_an_error_not_a_shift(tmp_path):
    # a field left out of row 2: pandas would pad the row with NaN, shifting 2.5 into 'a'
    malformed(tmp_path, HEAD.replace("nRows=2", "nRows=3")
              + "time\ta\tb\n0\t1\t2\n0.01\t2.5\n0.02\t3\t4\n",
              r"line 9: the row has 2 fields for the 3 column labels \(a value left out\?")


def test_short_row_in_a_space_separated_file(tmp_path):
    malformed(tmp_path, HEAD + "time a b\n0 1 2\n0.01   2.5\n",
              r"line 9: the row has 2 fields for the 3 column labels")


def test_empty_field_is_nan_not_a_short_row(tmp_path):
    path = write_text(tmp_path, HEAD + "time\ta\tb\n0\t\t2\n0.01\t1\t\n")
    df = read_quietly(path)
    np.testing.assert_array_equal(df.to_numpy(), [[np.nan, 2.0], [1.0, np.nan]])


@pytest.mark.parametrize("fmt", ["%d", "%i", "%x", "%5d", "%c"])
def test_write_mot_refuses_an_integer_format(tmp_path, fmt):
    with pytest.raises(ValueError, match=r"float_format must be one floating-point "
                                         r"conversion .* truncates the values"):
        write_mot(angles_frame([[1.7, 2.2]]), tmp_path / "x.mot", in_degrees=True,
                  float_format=fmt)
    assert not (tmp_path / "x.mot").exists()


@pytest.mark.parametrize("fmt", ["%d", "%x"])
def test_write_trc_refuses_an_integer_format(tmp_path, fmt):
    columns = pd.MultiIndex.from_product([["M1"], ["x", "y", "z"]])
    df = pd.DataFrame([[1.7, 2.2, 3.9]], columns=columns, index=pd.Index([0.0], name="time"))
    with pytest.raises(ValueError, match=r"float_format must be one floating-point"):
        write_trc(df, tmp_path / "x.trc", rate=100.0, units="mm", float_format=fmt)


def test_write_mot_coarse_format_keeps_the_times(tmp_path):
    time = np.arange(5) / 200.0                    # '%.2f' would write 0.00, 0.01, 0.01
    df = pd.DataFrame({"a": [1.234, 2.345, 3.456, 4.567, 5.678]},
                      index=pd.Index(time, name="time"))
    write_mot(df, tmp_path / "x.mot", in_degrees=True, float_format="%.2f")
    back = read_quietly(tmp_path / "x.mot")
    np.testing.assert_array_equal(back.index.to_numpy(), time)
    np.testing.assert_array_equal(back["a"].to_numpy(), [1.23, 2.35, 3.46, 4.57, 5.68])


# --- the pipeline's angles straight to OpenSim (issue 22) --------------------------------

def pipeline_frame(values, columns, time):
    df = pd.DataFrame(values, columns=pd.MultiIndex.from_tuples(columns),
                      index=pd.Index(time, name="time"))
    df.attrs = {"units": "deg", "pelvis_sequence": "YXZ"}  # the ISB pipeline's
    return df


def test_write_pipeline_angles_as_they_come_round_trip(tmp_path):
    rng = np.random.default_rng(22)
    columns = [(j, s, a) for s in ("right", "left")
               for j, a in (("hip", "flexion"), ("hip", "adduction"), ("hip", "rotation"),
                            ("knee", "flexion"), ("knee", "adduction"), ("knee", "rotation"),
                            ("ankle", "dorsiflexion"), ("ankle", "inversion"),
                            ("ankle", "rotation"))]
    values = rng.normal(0, 30, (50, len(columns))) * np.pi   # full double precision
    values[3, 2] = np.nan
    time = np.arange(50) / 150
    angles = pipeline_frame(values, columns, time)
    write_mot(angles, tmp_path / "walk.mot")
    back = read_quietly(tmp_path / "walk.mot")
    assert back.attrs["in_degrees"] is True
    expected = ["hip_flexion_r", "hip_adduction_r", "hip_rotation_r", "knee_angle_r",
                "ankle_angle_r", "knee_adduction_r", "knee_rotation_r", "ankle_inversion_r",
                "ankle_rotation_r"]
    assert list(back.columns) == expected + [c[:-1] + "l" for c in expected]
    for name in back.columns:                        # exact: every bit of every value
        joint, side, angle = opensim_coordinates(angles).attrs["source_columns"][name]
        np.testing.assert_array_equal(back[name].to_numpy(),
                                      angles[joint, side, angle].to_numpy())
    np.testing.assert_array_equal(back.index.to_numpy(), time)


def test_write_radians_from_units(tmp_path):
    df = angles_frame([[0.1, 0.2]])
    df.attrs = {"units": "rad"}
    write_mot(df, tmp_path / "x.mot")
    assert read_quietly(tmp_path / "x.mot").attrs["in_degrees"] is False


def test_write_refuses_several_trials_in_one_table(tmp_path):
    df = angles_frame([[1.0, 2.0], [3.0, 4.0]])
    df.index = pd.MultiIndex.from_tuples([("walk1", 0.0), ("walk2", 0.0)],
                                         names=["trial", "time"])
    with pytest.raises(ValueError, match=r"df has 2 row index levels .* one file per "
                                         r"trial, e.g. df.loc\['walk1'\]"):
        write_mot(df, tmp_path / "x.mot", in_degrees=True)


@pytest.mark.parametrize("side", ["right", "left"])
def test_pelvis_is_converted_to_opensims_sequence(side):
    # oracle: scipy's intrinsic ZXY angles of the pelvis rotation itself
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(5)
    R = compose(rng.uniform(-25, 25, (40, 3)), "YXZ", degrees=True)
    ours = pelvis_angles(R, side, degrees=True)
    angles = pipeline_frame(ours, [("pelvis", side, a) for a in ("tilt", "obliquity",
                                                                  "rotation")],
                            np.arange(40) / 100)
    coordinates = opensim_coordinates(angles)
    truth = Rotation.from_matrix(R).as_euler("ZXY", degrees=True)
    np.testing.assert_allclose(coordinates[["pelvis_tilt", "pelvis_list",
                                            "pelvis_rotation"]].to_numpy(), truth,
                               atol=1e-9)
    # the signs stated: anterior tilt reads -, this side up reads as the right down/up
    one = opensim_coordinates(pipeline_frame(
        [[10.0, 0, 0], [0, 5.0, 0], [0, 0, 7.0]],
        [("pelvis", side, a) for a in ("tilt", "obliquity", "rotation")], [0.0, 0.1, 0.2]))
    sign = 1 if side == "right" else -1
    np.testing.assert_allclose(one.to_numpy(), [[-10.0, 0, 0], [0, -5.0 * sign, 0],
                                                [0, 0, 7.0 * sign]], atol=1e-12)


def test_pelvis_with_a_lab_frame_and_nan():
    from scipy.spatial.transform import Rotation

    R_lab = compose([180.0, 0, 0], "YXZ", degrees=True)   # walking towards -x
    angles = pipeline_frame([[10.0, 2.0, 3.0], [np.nan, np.nan, np.nan]],
                            [("pelvis", "right", a) for a in ("tilt", "obliquity",
                                                              "rotation")], [0.0, 0.01])
    angles.attrs["lab_frame"] = R_lab.tolist()
    out = opensim_coordinates(angles)
    assert np.isnan(out.iloc[1]).all()
    R = R_lab @ compose([3.0, -2.0, -10.0], "YXZ", degrees=True)   # in the lab, not progression
    np.testing.assert_allclose(out.iloc[0].to_numpy(),
                               Rotation.from_matrix(R).as_euler("ZXY", degrees=True),
                               atol=1e-9)


def test_opensim_coordinates_refuses_radians_and_flat_columns():
    angles = pipeline_frame([[1.0]], [("knee", "right", "flexion")], [0.0])
    angles.attrs["units"] = "rad"
    with pytest.raises(ValueError, match=r"units'\] is 'rad'"):
        opensim_coordinates(angles)
    with pytest.raises(ValueError, match=r"columns \(joint, side, angle\)"):
        opensim_coordinates(angles_frame([[1.0, 2.0]]))


def test_align_times_rounded_differently():
    ours = pd.DataFrame({"a": np.arange(150.0)},
                        index=pd.Index(np.round(np.arange(150) / 150, 3), name="time"))
    theirs_time = np.arange(150) / 150
    assert ours.index.intersection(pd.Index(theirs_time)).size < 60   # the failed join
    aligned = align_times(ours, theirs_time)
    np.testing.assert_array_equal(aligned["a"].to_numpy(), np.arange(150.0))
    np.testing.assert_array_equal(aligned.index.to_numpy(), theirs_time)


def test_align_times_warns_once_for_times_outside():
    ours = pd.DataFrame({"a": [1.0, 2.0, 3.0]}, index=[0.0, 0.01, 0.02])
    with pytest.warns(UserWarning, match=r"2 of 4 times have no row of df within "
                                         r"0.0025 s"):
        out = align_times(ours, [0.0, 0.011, 0.5, 0.6])
    np.testing.assert_array_equal(out["a"].to_numpy(), [1.0, 2.0, np.nan, np.nan])


@pytest.mark.parametrize("tolerance", [0, -1.0, np.nan, "1", True])
def test_align_times_refuses_a_bad_tolerance(tolerance):
    ours = pd.DataFrame({"a": [1.0, 2.0]}, index=[0.0, 0.01])
    with pytest.raises(ValueError, match=r"tolerance must be a positive number"):
        align_times(ours, [0.0], tolerance=tolerance)


@needs_shared("ik_output_run.mot", "static_run.trc", "motion_capture_run.trc")
def test_pipeline_angles_written_for_opensim_match_its_inverse_kinematics(tmp_path):
    from bmc_functions import calibrate_lower_limb

    markers = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI"}
    for p in "RL":
        markers.update({p + "THIGH": [p + "TH1", p + "TH2", p + "TH3"],
                        p + "SHANK": [p + "TB1", p + "TB2", p + "TB3"],
                        p + "KNEE_LAT": p + "LFC", p + "KNEE_MED": p + "MFC",
                        p + "ANKLE_LAT": p + "LMAL", p + "ANKLE_MED": p + "MMAL",
                        p + "HEEL": p + "CAL", p + "TOE": p + "TOE", p + "MT5": p + "MT5"})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")      # the trial's known RTOE/RMT5 swap
        model = calibrate_lower_limb(SHARED_DATA / "static_run.trc", markers)
        angles = model.angles(SHARED_DATA / "motion_capture_run.trc")
    write_mot(angles, tmp_path / "run.mot")
    ours = read_quietly(tmp_path / "run.mot")
    ik = read_quietly(SHARED_DATA / "ik_output_run.mot")
    assert ours.index.intersection(ik.index).size < len(ik) / 2   # 0.007 vs 0.0066667
    ours = align_times(ours, ik)
    assert not ours.isna().any().any()
    r = {name: np.corrcoef(ours[name], ik[name])[0, 1] for name in ours.columns
         if name in ik.columns}
    for name in ("hip_flexion_r", "hip_flexion_l", "knee_angle_r", "knee_angle_l",
                 "ankle_angle_l", "pelvis_rotation"):
        assert r[name] > 0.98, (name, r[name])
    for name in ("pelvis_tilt", "pelvis_list", "hip_adduction_r", "hip_adduction_l"):
        assert r[name] > 0.94, (name, r[name])
    offsets = (ours - ik)[["hip_flexion_r", "knee_angle_r", "ankle_angle_l"]].mean()
    assert (offsets.abs() < 8).all(), offsets


@pytest.mark.parametrize("columns, values, attrs, error, match", [
    ([("knee", "right", "flexion")], [["a"]], {}, TypeError,
     r"angles\[\('knee', 'right', 'flexion'\)\] must be a numeric array"),
    ([("knee", "right", "flexion")] * 2, [[1.0, 2.0]], {}, ValueError,
     r"angles has duplicate columns"),
    ([("pelvis", "right", "tilt"), ("pelvis", "right", "obliquity")], [[1.0, 2.0]], {},
     ValueError, r"the pelvis is converted .* of one side; got only"),
    ([("pelvis", "right", a) for a in ("tilt", "obliquity", "rotation")], [[1.0, 2, 3]],
     {"lab_frame": np.eye(3) * 2}, ValueError, r"angles.attrs\['lab_frame'\]"),
])
def test_opensim_coordinates_refuses_what_it_cannot_convert(columns, values, attrs, error,
                                                            match):
    angles = pd.DataFrame(values, columns=pd.MultiIndex.from_tuples(columns),
                          index=pd.Index([0.0], name="time"))
    angles.attrs = {"units": "deg", **attrs}
    with pytest.raises(error, match=match):
        opensim_coordinates(angles)


# --- adversarial pass, round 2 (tools/adversarial_pass_round2.py) ----------------------------

def test_write_mot_refuses_in_degrees_against_the_units_of_df(tmp_path):
    """in_degrees=False on angles in degrees wrote inDegrees=no: OpenSim would read 30 deg
    as 30 rad."""
    df = angles_frame([[12.5, 30.0], [13.0, 31.0]])
    df.attrs["units"] = "deg"
    with pytest.raises(ValueError, match=r"in_degrees=False contradicts df.attrs \(units "
                                         r"'deg': in degrees\)"):
        write_mot(df, tmp_path / "a.mot", in_degrees=False)
    write_mot(df, tmp_path / "a.mot", in_degrees=True)                   # agrees
    assert read_quietly(tmp_path / "a.mot").attrs["in_degrees"] is True


def test_write_mot_warns_of_a_time_index_in_ms(tmp_path):
    df = angles_frame([[12.5, 30.0], [13.0, 31.0], [13.5, 32.0]])
    df.index = df.index * 1000
    with pytest.warns(RuntimeWarning, match=r"df.index \(time\) steps by 10 .*ms or frame "
                                            r"numbers"):
        write_mot(df, tmp_path / "a.mot", in_degrees=True)


def test_align_times_says_when_the_times_look_like_ms():
    df = angles_frame([[12.5, 30.0], [13.0, 31.0], [13.5, 32.0]])
    with pytest.warns(UserWarning, match=r"are they in ms or frames, not seconds"):
        align_times(df, df.index.to_numpy() * 1000 + 1000)


def test_write_mot_names_an_unknown_conversion_as_such(tmp_path):
    """'%q' was said to truncate the values, as '%d' does."""
    df = angles_frame([[12.5, 30.0], [13.0, 31.0]])
    with pytest.raises(ValueError, match=r"got '%q', which is no conversion of a number"):
        write_mot(df, tmp_path / "a.mot", in_degrees=True, float_format="%q")
    with pytest.raises(ValueError, match=r"got '%d', which truncates the values"):
        write_mot(df, tmp_path / "a.mot", in_degrees=True, float_format="%d")
