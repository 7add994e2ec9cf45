"""Tests of bmc_functions.files.trc and .c3d: TRC reading and writing, C3D reading.

Expected values are the numbers written by hand in the tiny files below (or parsed by
hand with str.split from the real recordings), never the reader's own output.
"""

import os
import re
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from bmc_functions import read_c3d, read_trc, write_trc

DATA = Path(__file__).resolve().parent / "data"
from helpers import SHARED_DATA as SHARED, skip_without_shared

KEYS = ("DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\t"
        "OrigDataStartFrame\tOrigNumFrames")
ROWS = ["1\t0.00\t1.0\t2.0\t3.0\t4.0\t5.0\t6.0",
        "2\t0.01\t1.5\t2.5\t3.5\t4.5\t5.5\t6.5"]
EXPECTED = np.array([[1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
                     [1.5, 2.5, 3.5, 4.5, 5.5, 6.5]])


def trc_lines(labels=("A", "B"), rows=ROWS, *, rate="100", units="mm", num_markers=None,
              num_frames=None):
    """Lines of a standard TRC file; the data start at line 7 (after a blank line 6)."""
    n_markers = len(labels) if num_markers is None else num_markers
    n_frames = len(rows) if num_frames is None else num_frames
    return ["PathFileType\t4\t(X/Y/Z)\ttest.trc",
            KEYS,
            f"{rate}\t{rate}\t{n_frames}\t{n_markers}\t{units}\t{rate}\t1\t{n_frames}",
            "Frame#\tTime\t" + "".join(f"{label}\t\t\t" for label in labels),
            "\t\t" + "".join(f"X{k}\tY{k}\tZ{k}\t" for k in range(1, len(labels) + 1)),
            "",
            *rows]


def write_lines(tmp_path, lines, newline="\n", name="test.trc"):
    path = tmp_path / name
    path.write_bytes((newline.join(lines) + newline).encode("utf-8"))
    return path


def markers(df):
    return list(df.columns.get_level_values("marker").unique())


def read_quietly(path):
    """read_trc, failing the test on any warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return read_trc(path)


# --- the standard file and the DataFrame shape -------------------------------------------

def test_standard_file(tmp_path):
    df = read_quietly(write_lines(tmp_path, trc_lines()))
    assert markers(df) == ["A", "B"]
    assert list(df.columns.get_level_values("coord")) == ["x", "y", "z"] * 2
    assert df.columns.names == ["marker", "coord"]
    assert df.index.name == "time"
    np.testing.assert_array_equal(df.index.to_numpy(), [0.0, 0.01])
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)
    np.testing.assert_array_equal(df["B"].to_numpy(), EXPECTED[:, 3:])
    assert df.attrs["rate"] == 100.0 and isinstance(df.attrs["rate"], float)
    assert df.attrs["units"] == "mm"
    assert df.attrs["frames"] == [1, 2]
    assert df.attrs["camera_rate"] == 100.0
    assert df.attrs["header"]["OrigDataStartFrame"] == "1"
    assert df.attrs["dropped_labels"] == []


def test_units_metres_and_rate_with_decimals(tmp_path):
    df = read_quietly(write_lines(tmp_path, trc_lines(rate="148.5", units="m")))
    assert df.attrs["units"] == "m"
    assert df.attrs["rate"] == 148.5


# --- quirks of real files -----------------------------------------------------------------

def test_fixture_cortex_quirks():
    # CRLF, header lines padded with tabs, NumFrames padded with spaces, a third label
    # beyond NumMarkers with empty columns, a marker empty in every row, a tab-only line
    # before the data, trailing tabs on every row.
    df = read_quietly(DATA / "trc_cortex_quirks.trc")
    assert markers(df) == ["RTH1", "RMFC"]
    assert df.attrs["dropped_labels"] == ["V_Knee_JC"]
    assert df.attrs["rate"] == 100.0 and df.attrs["units"] == "mm"
    assert df.attrs["frames"] == [1, 2, 3]
    np.testing.assert_array_equal(df.index.to_numpy(), [0.0, 0.01, 0.02])
    expected_rth1 = [[101.25, -20.5, 850.0], [102.5, -21.0, 851.125],
                     [np.nan, np.nan, np.nan]]
    np.testing.assert_array_equal(df["RTH1"].to_numpy(), expected_rth1)
    assert df["RMFC"].isna().all().all()  # kept: within NumMarkers


def test_fixture_opensim_small():
    # double tab in the keys line, values line padded with spaces, no blank line before
    # the data, the text NaN, a row that omits its trailing empty marker, frames from 10.
    df = read_quietly(DATA / "trc_opensim_small.trc")
    assert markers(df) == ["LASI", "RASI", "SACR"]
    assert df.attrs["rate"] == 60.0 and df.attrs["units"] == "m"
    assert df.attrs["frames"] == [10, 11, 12, 13]
    np.testing.assert_array_equal(df.index.to_numpy(), [0.0, 0.016667, 0.033333, 0.05])
    np.testing.assert_array_equal(df["LASI"].to_numpy()[:, 0], [0.125, 0.13, 0.135, 0.14])
    np.testing.assert_array_equal(df["RASI"].isna().all(axis=1).to_numpy(),
                                  [False, True, True, False])
    np.testing.assert_array_equal(df["SACR"].to_numpy()[3], [-0.035, 1.0, 0.0])
    assert df["SACR"].iloc[2].isna().all()


def test_trailing_tabs_everywhere(tmp_path):
    lines = [line + "\t\t\t" for line in trc_lines()]
    df = read_quietly(write_lines(tmp_path, lines))
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)


def test_crlf_line_ends(tmp_path):
    df = read_quietly(write_lines(tmp_path, trc_lines(), newline="\r\n"))
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)
    assert markers(df) == ["A", "B"]


def test_double_tabs_and_padding_in_header(tmp_path):
    lines = trc_lines()
    lines[0] = "PathFileType\t\t4\t(X/Y/Z)\t\ttest.trc"
    lines[1] = lines[1].replace("\t", "\t\t")
    lines[2] = "  100.00 \t100.00\t     2\t  2\t mm \t100\t1\t     2   "
    lines[3] = "Frame#\t\tTime\t\tA\t\t\t\tB\t\t"  # not the standard spacing: labels in order
    df = read_quietly(write_lines(tmp_path, lines))
    assert markers(df) == ["A", "B"]
    assert df.attrs["units"] == "mm" and df.attrs["rate"] == 100.0
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)


def test_padding_spaces_in_data_fields(tmp_path):
    rows = [" 1\t 0.00\t1.0 \t  2.0\t3.0\t4.0\t5.0\t6.0  ",
            "2\t0.01\t1.5\t2.5\t3.5\t   \t5.5\t6.5"]
    df = read_quietly(write_lines(tmp_path, trc_lines(rows=rows)))
    expected = EXPECTED.copy()
    expected[1, 3] = np.nan  # a field of spaces only is empty
    np.testing.assert_array_equal(df.to_numpy(), expected)


@pytest.mark.parametrize("gap", [[], ["", ""], ["\t\t\t", "  "]],
                         ids=["no-blank-line", "two-blank-lines", "whitespace-lines"])
def test_blank_lines_before_data(tmp_path, gap):
    lines = trc_lines()
    lines = lines[:5] + gap + lines[6:]
    df = read_quietly(write_lines(tmp_path, lines))
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)


def test_trailing_blank_lines_at_end(tmp_path):
    df = read_quietly(write_lines(tmp_path, trc_lines() + ["", "\t\t", ""]))
    assert df.shape == (2, 6)


def test_empty_fields_and_nan_text(tmp_path):
    rows = ["1\t0.00\t\t\t\t4.0\t5.0\t6.0",
            "2\t0.01\t1.5\tNaN\t3.5\tnan\t\t6.5"]
    df = read_quietly(write_lines(tmp_path, trc_lines(rows=rows)))
    nan = np.nan
    np.testing.assert_array_equal(df.to_numpy(), [[nan, nan, nan, 4.0, 5.0, 6.0],
                                                  [1.5, nan, 3.5, nan, nan, 6.5]])


def test_row_omitting_trailing_empty_markers(tmp_path):
    rows = ["1\t0.00\t1.0\t2.0\t3.0", "2\t0.01\t1.5\t2.5\t3.5\t4.5\t5.5\t6.5"]
    df = read_quietly(write_lines(tmp_path, trc_lines(rows=rows)))
    assert df["B"].iloc[0].isna().all()
    np.testing.assert_array_equal(df.to_numpy()[1], EXPECTED[1])


def test_empty_column_within_num_markers_is_kept(tmp_path):
    rows = ["1\t0.00\t\t\t\t4.0\t5.0\t6.0", "2\t0.01\t\t\t\t4.5\t5.5\t6.5"]
    df = read_quietly(write_lines(tmp_path, trc_lines(rows=rows)))
    assert markers(df) == ["A", "B"]
    assert df["A"].isna().all().all()
    assert df.attrs["dropped_labels"] == []


def test_empty_labels_beyond_num_markers_are_dropped(tmp_path):
    labels = ("A", "B", "V_C", "V_D")
    rows = [row + "\t" * 7 for row in ROWS]  # empty fields of V_C, V_D and a trailing tab
    path = write_lines(tmp_path, trc_lines(labels, rows, num_markers=2))
    df = read_quietly(path)
    assert markers(df) == ["A", "B"]
    assert df.attrs["dropped_labels"] == ["V_C", "V_D"]
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)


def test_labels_beyond_num_markers_with_data_are_kept_with_a_warning(tmp_path):
    labels = ("A", "B", "C")
    rows = [ROWS[0] + "\t7.0\t8.0\t9.0", ROWS[1] + "\t\t\t"]
    path = write_lines(tmp_path, trc_lines(labels, rows, num_markers=2))
    with pytest.warns(UserWarning, match=r"NumMarkers = 2 but 1 of the 1 labels beyond "
                                         r"it hold data and were kept: C"):
        df = read_trc(path)
    assert markers(df) == ["A", "B", "C"]
    np.testing.assert_array_equal(df["C"].to_numpy()[0], [7.0, 8.0, 9.0])
    assert df["C"].iloc[1].isna().all()


def test_num_markers_larger_than_labels_warns(tmp_path):
    path = write_lines(tmp_path, trc_lines(num_markers=3))
    with pytest.warns(UserWarning, match=r"NumMarkers = 3 but the labels line names 2"):
        df = read_trc(path)
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)


def test_num_frames_mismatch_warns_and_reads_all_rows(tmp_path):
    path = write_lines(tmp_path, trc_lines(num_frames=5))
    with pytest.warns(UserWarning, match=r"NumFrames = 5 but the file holds 2 data rows"):
        df = read_trc(path)
    assert df.shape == (2, 6)


def test_time_not_increasing_warns(tmp_path):
    rows = [ROWS[0], ROWS[1], "3\t0.01\t1\t2\t3\t4\t5\t6"]
    path = write_lines(tmp_path, trc_lines(rows=rows))
    with pytest.warns(UserWarning, match=r"time does not increase at line 9"):
        read_trc(path)


def test_latin1_file_name_in_header(tmp_path):
    lines = trc_lines()
    path = tmp_path / "latin.trc"
    text = "\n".join(lines).replace("test.trc", "essai_\xe9t\xe9.trc") + "\n"
    path.write_bytes(text.encode("latin-1"))
    df = read_quietly(path)
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)


def test_utf8_byte_order_mark(tmp_path):
    path = tmp_path / "bom.trc"
    path.write_bytes(b"\xef\xbb\xbf" + ("\n".join(trc_lines()) + "\n").encode())
    df = read_quietly(path)
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)



@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be"])
def test_utf16_file_saved_as_unicode_text(tmp_path, encoding):
    # what Notepad or Excel ("Unicode Text") write: a UTF-16 byte-order mark, 2 bytes per
    # character, Windows line ends; read as Latin-1 it failed at line 1 with 'ÿþP\x00a...'
    path = tmp_path / "unicode.trc"
    text = "\r\n".join(trc_lines(labels=("Épaule", "B"))) + "\r\n"
    data = text.encode(encoding)
    if encoding == "utf-16-be":
        data = b"\xfe\xff" + data
    path.write_bytes(data)
    df = read_quietly(path)
    assert markers(df) == ["Épaule", "B"]
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)

# --- malformed files: ValueError naming the file and the line ----------------------------

def malformed(tmp_path, lines, match):
    path = write_lines(tmp_path, lines, name="bad.trc")
    with pytest.raises(ValueError, match=match) as info:
        read_trc(path)
    assert "bad.trc" in str(info.value)


def test_missing_pathfiletype_line(tmp_path):
    malformed(tmp_path, trc_lines()[1:], r"line 1: expected the TRC header line 'PathFileType")


def test_missing_keys_line(tmp_path):
    lines = trc_lines()
    del lines[1]
    malformed(tmp_path, lines, r"line 2: the header keys line has no 'DataRate'")


def test_header_missing_units_key(tmp_path):
    lines = trc_lines()
    lines[1] = lines[1].replace("Units", "Unit")
    malformed(tmp_path, lines, r"line 2: the header keys line has no 'Units'")


def test_header_values_count_mismatch(tmp_path):
    lines = trc_lines()
    lines[2] = "100\t100\t2\t2\t100\t1\t2"  # Units missing
    malformed(tmp_path, lines, r"line 3: 7 header values for the 8 keys")


@pytest.mark.parametrize("key, position, value", [
    ("NumFrames", 2, "abc"), ("NumFrames", 2, "-2"), ("NumMarkers", 3, "2.5"),
    ("NumMarkers", 3, "two"), ("DataRate", 0, "fast"), ("DataRate", 0, "0"),
    ("CameraRate", 1, "n/a")])
def test_header_value_not_a_number(tmp_path, key, position, value):
    lines = trc_lines()
    values = lines[2].split("\t")
    values[position] = value
    lines[2] = "\t".join(values)
    malformed(tmp_path, lines, rf"line 3: {key} must be .*; got '{re.escape(value)}'")


def test_missing_labels_line(tmp_path):
    lines = trc_lines()
    del lines[3]
    malformed(tmp_path, lines, r"line 4: expected the labels line 'Frame#  Time")


def test_labels_line_without_markers(tmp_path):
    lines = trc_lines()
    lines[3] = "Frame#\tTime\t\t\t"
    malformed(tmp_path, lines, r"line 4: the labels line names no marker")


def test_missing_coordinate_line(tmp_path):
    lines = trc_lines()
    del lines[4]
    malformed(tmp_path, lines, r"line 5: expected the coordinate line 'X1  Y1  Z1")


def test_empty_label_slot(tmp_path):
    lines = trc_lines(("A", "B", "C"), [row + "\t7\t8\t9" for row in ROWS])
    lines[3] = "Frame#\tTime\tA\t\t\t\t\t\tC\t\t\t"
    malformed(tmp_path, lines, r"line 4: marker column 2 \(data fields 6-8\) has no label")


def test_duplicate_labels(tmp_path):
    malformed(tmp_path, trc_lines(("A", "A")), r"line 4: duplicate marker labels: A")


def test_file_too_short(tmp_path):
    malformed(tmp_path, trc_lines()[:3], r"line 4: the file ends after 4 line")


def test_row_with_too_many_fields(tmp_path):
    rows = [ROWS[0], ROWS[1] + "\t7.0"]
    malformed(tmp_path, trc_lines(rows=rows),
              r"line 8: the row has 9 fields but the labels line defines 8")


def test_row_truncated_inside_a_marker(tmp_path):
    rows = [ROWS[0], "2\t0.01\t1.5\t2.5\t3.5\t4.5"]
    malformed(tmp_path, trc_lines(rows=rows),
              r"line 8: the row stops after 6 fields, inside marker 'B'")


def test_row_with_a_lost_field(tmp_path):
    # the empty x of marker B was lost with its tab: 5.5 would be read as B's x
    rows = [ROWS[0], "2\t0.01\t1.5\t2.5\t3.5\t5.5\t6.5"]
    malformed(tmp_path, trc_lines(rows=rows),
              r"line 8: the row stops after 7 fields, inside marker 'B'")


def test_row_with_a_lost_field_in_a_file_with_trailing_tabs(tmp_path):
    # every row ends with a tab (9 fields) but line 8 has 8: its last marker is shifted
    rows = [ROWS[0] + "\t", "2\t0.01\t1.5\t2.5\t3.5\t5.5\t6.5\t7.5",
            "3\t0.02\t1\t2\t3\t4\t5\t6\t"]
    malformed(tmp_path, trc_lines(rows=rows),
              r"line 8: the row has 8 fields where most rows have 9: a lost or extra field")


def test_rows_omitting_whole_markers_in_a_file_with_trailing_tabs(tmp_path):
    rows = [ROWS[0] + "\t", "2\t0.01\t1.5\t2.5\t3.5\t", "3\t0.02\t1\t2\t3\t4\t5\t6\t"]
    df = read_quietly(write_lines(tmp_path, trc_lines(rows=rows)))
    assert df["B"].iloc[1].isna().all()
    np.testing.assert_array_equal(df["A"].iloc[1].to_numpy(), [1.5, 2.5, 3.5])
    np.testing.assert_array_equal(df.to_numpy()[2], [1, 2, 3, 4, 5, 6])


def test_non_numeric_value(tmp_path):
    rows = [ROWS[0], "2\t0.01\t1.5\t2.5\t3.5\t4.5\tabc\t6.5"]
    malformed(tmp_path, trc_lines(rows=rows),
              r"line 8: field 7 \('B' y\) is not a number: 'abc'")


def test_decimal_comma_is_not_a_number(tmp_path):
    rows = ["1\t0,00\t1.0\t2.0\t3.0\t4.0\t5.0\t6.0", ROWS[1]]
    malformed(tmp_path, trc_lines(rows=rows), r"line 7: field 2 \(Time\) is not a number")


def test_space_inside_a_field(tmp_path):
    rows = [ROWS[0], "2\t0.01\t1.5\t2 5\t3.5\t4.5\t5.5\t6.5"]
    malformed(tmp_path, trc_lines(rows=rows), r"line 8: a space inside a field: '2 5'")


def test_blank_line_inside_data(tmp_path):
    rows = [ROWS[0], "", ROWS[1]]
    malformed(tmp_path, trc_lines(rows=rows), r"line 8: no frame number")


def test_missing_time(tmp_path):
    rows = [ROWS[0], "2\t\t1.5\t2.5\t3.5\t4.5\t5.5\t6.5"]
    malformed(tmp_path, trc_lines(rows=rows), r"line 8: no time value")


def test_fractional_frame_number(tmp_path):
    rows = [ROWS[0], "2.5\t0.01\t1.5\t2.5\t3.5\t4.5\t5.5\t6.5"]
    malformed(tmp_path, trc_lines(rows=rows), r"line 8: the frame number 2.5 is not a whole")


def test_infinite_value(tmp_path):
    rows = ["1\t0.00\t1.0\tinf\t3.0\t4.0\t5.0\t6.0", ROWS[1]]
    malformed(tmp_path, trc_lines(rows=rows), r"line 7: infinite value")


def test_row_with_an_extra_field_in_a_file_with_trailing_tabs(tmp_path):
    # every row ends with a tab (9 fields) but line 8 has a stray tab after A's x: read
    # by position it would give A = (1.5, nan, 2.5), B = (3.5, 4.5, 5.5) without a word
    rows = [ROWS[0] + "\t", "2\t0.01\t1.5\t\t2.5\t3.5\t4.5\t5.5\t\t",
            "3\t0.02\t1\t2\t3\t4\t5\t6\t"]
    malformed(tmp_path, trc_lines(rows=rows),
              r"line 8: the row has 10 fields where most rows have 9: a lost or extra field")


def test_frame_number_too_large_for_an_integer(tmp_path):
    rows = [ROWS[0], "1e20\t0.01\t1.5\t2.5\t3.5\t4.5\t5.5\t6.5"]
    malformed(tmp_path, trc_lines(rows=rows), r"line 8: the frame number 1e\+20 is not a "
                                              r"whole number below 2\*\*53")


# --- writing -------------------------------------------------------------------------------

def marker_frame(values, labels, times, **attrs):
    columns = pd.MultiIndex.from_product([labels, ["x", "y", "z"]],
                                         names=["marker", "coord"])
    # a copy: before pandas 3 a DataFrame shares the array, and a test that edits its
    # frame would edit the module's EXPECTED for every later test
    df = pd.DataFrame(np.array(values, dtype=float), columns=columns,
                      index=pd.Index(times, name="time"))
    df.attrs.update(attrs)
    return df


def opensim_read(path):
    """Apply the reading rules of OpenSim 4's TRCFileAdapter; return (labels, array).

    OpenSim splits lines on tabs; a trailing tab adds no field, every other empty field
    counts; the keys must be the eight standard keys in order; the non-empty labels must
    be NumMarkers + 2; the coordinate labels X1 Y1 Z1 ...; every data row exactly
    2 + 3 NumMarkers fields; a marker with any empty coordinate is NaN.
    """
    lines = path.read_text().split("\n")

    def tokens(line):
        parts = line.split("\t")
        if parts[-1] == "":
            parts = parts[:-1]
        return [part.strip() for part in parts]

    assert tokens(lines[0])[0] == "PathFileType"
    assert [t for t in tokens(lines[1]) if t] == KEYS.split("\t")
    values = [t for t in tokens(lines[2]) if t]
    assert len(values) == 8
    n_markers = int(values[3])
    labels = [t for t in tokens(lines[3]) if t]
    assert labels[:2] == ["Frame#", "Time"] and len(labels) == n_markers + 2
    xyz = [t for t in tokens(lines[4]) if t]
    assert xyz == [f"{c}{k}" for k in range(1, n_markers + 1) for c in "XYZ"]
    assert lines[5] == ""
    data = []
    for line in lines[6:]:
        if not line:
            break
        row = tokens(line)
        assert len(row) == 2 + 3 * n_markers
        out = [float(row[1])]
        for k in range(n_markers):
            triplet = row[2 + 3 * k:5 + 3 * k]
            out += [np.nan] * 3 if "" in triplet else [float(v) for v in triplet]
        data.append(out)
    return labels[2:], np.array(data)


def test_write_layout_is_the_standard_one(tmp_path):
    nan = np.nan
    values = [[1.0, 2.0, 3.0, nan, nan, nan], [1.5, 2.5, 3.5, 4.0, 5.0, 6.0]]
    df = marker_frame(values, ["RTH1", "RTH2"], [0.0, 0.01], rate=100.0, units="mm",
                      frames=[5, 6])
    path = tmp_path / "out.trc"
    write_trc(df, path)
    lines = path.read_text().split("\n")
    assert lines[0] == "PathFileType\t4\t(X/Y/Z)\tout.trc"
    assert lines[1] == KEYS
    assert lines[2] == "100\t100\t2\t2\tmm\t100\t5\t2"
    assert lines[3] == "Frame#\tTime\tRTH1\t\t\tRTH2\t\t\t"
    assert lines[4] == "\t\tX1\tY1\tZ1\tX2\tY2\tZ2\t"
    assert lines[5] == ""
    assert lines[6] == "5\t0.000000\t1.000000\t2.000000\t3.000000\t\t\t\t"
    assert lines[7].split("\t")[:3] == ["6", "0.010000", "1.500000"]
    labels, data = opensim_read(path)
    assert labels == ["RTH1", "RTH2"]
    np.testing.assert_array_equal(data[:, 1:], values)


def test_round_trip_exact(tmp_path):
    rng = np.random.default_rng(5)
    values = np.round(rng.normal(0, 500, (50, 9)), 6)
    values[rng.random(values.shape) < 0.1] = np.nan
    values[10:14, 3:6] = np.nan  # a gap
    values[:, 6:] = np.nan       # a marker never seen
    df = marker_frame(values, ["PSIS", "ASIS", "RMFC"], np.round(np.arange(50) / 120, 6),
                      rate=120.0, units="m", frames=list(range(101, 151)), camera_rate=240.0)
    path = tmp_path / "round.trc"
    write_trc(df, path)
    back = read_quietly(path)
    pd.testing.assert_frame_equal(back, df, check_exact=True)
    for key in ("rate", "units", "frames", "camera_rate"):
        assert back.attrs[key] == df.attrs[key]
    labels, data = opensim_read(path)
    # OpenSim reads a marker with any missing coordinate as wholly missing
    triplets = values.reshape(50, 3, 3).copy()
    triplets[np.isnan(triplets).any(axis=2)] = np.nan
    np.testing.assert_array_equal(data[:, 1:], triplets.reshape(50, 9))


def test_round_trip_of_a_read_file(tmp_path):
    df = read_quietly(DATA / "trc_opensim_small.trc")
    write_trc(df, tmp_path / "again.trc")
    back = read_quietly(tmp_path / "again.trc")
    pd.testing.assert_frame_equal(back, df, check_exact=True)
    assert back.attrs["frames"] == [10, 11, 12, 13]


@settings(max_examples=40, deadline=None)
@given(arrays(np.float64, (7, 6), elements=st.floats(-1e4, 1e4) | st.just(np.nan)))
def test_round_trip_property(tmp_path_factory, values):
    values = np.round(values, 6)
    df = marker_frame(values, ["M1", "M2"], np.arange(7) / 100, rate=100.0, units="mm")
    path = tmp_path_factory.mktemp("prop") / "p.trc"
    with warnings.catch_warnings():    # values of 6 decimals are written exactly by '%.6f',
        warnings.filterwarnings(       # however few significant digits the smallest keep
            "ignore", message=r"write_trc: float_format '%\.6f' writes", category=UserWarning)
        write_trc(df, path)
    back = read_trc(path, zeros_as_gaps=False)     # a point exactly at (0, 0, 0) kept
    np.testing.assert_array_equal(back.to_numpy(), values)


def test_write_marker_order_and_coord_order(tmp_path):
    # columns given as z, x, y are written as x, y, z; marker order is kept
    columns = pd.MultiIndex.from_tuples([("B", "z"), ("B", "x"), ("B", "y"),
                                         ("A", "x"), ("A", "y"), ("A", "z")])
    df = pd.DataFrame([[3.0, 1.0, 2.0, 4.0, 5.0, 6.0]], columns=columns,
                      index=pd.Index([0.0], name="time"))
    write_trc(df, tmp_path / "o.trc", rate=50, units="mm")
    back = read_quietly(tmp_path / "o.trc")
    assert markers(back) == ["B", "A"]
    np.testing.assert_array_equal(back.to_numpy(), [[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]])


def test_write_renumbers_frames_after_slicing(tmp_path):
    df = read_quietly(DATA / "trc_opensim_small.trc").iloc[1:3]
    write_trc(df, tmp_path / "s.trc")
    back = read_quietly(tmp_path / "s.trc")
    assert back.attrs["frames"] == [1, 2]
    np.testing.assert_array_equal(back.index.to_numpy(), [0.016667, 0.033333])


def good_frame():
    return marker_frame(EXPECTED, ["A", "B"], [0.0, 0.01], rate=100.0, units="mm")


def test_write_renumbers_frame_numbers_too_large_for_an_integer(tmp_path):
    # not -9223372036854775808 (numpy's cast of 1e20 to int64) in every row
    df = good_frame()
    df.attrs["frames"] = [1e20, 1e20 + 2**17]
    with pytest.warns(UserWarning, match=r"numbered 1 to 2"):
        write_trc(df, tmp_path / "x.trc")
    assert read_quietly(tmp_path / "x.trc").attrs["frames"] == [1, 2]

def test_write_rejects_a_non_dataframe(tmp_path):
    with pytest.raises(ValueError, match=r"df must be a pandas DataFrame.*got ndarray"):
        write_trc(EXPECTED, tmp_path / "x.trc", rate=100, units="mm")


def test_write_rejects_flat_columns(tmp_path):
    df = pd.DataFrame(EXPECTED)
    with pytest.raises(ValueError, match=r"df must have two-level \(marker, coord\) columns"):
        write_trc(df, tmp_path / "x.trc", rate=100, units="mm")


def test_write_rejects_a_missing_coordinate(tmp_path):
    df = good_frame().drop(columns=[("B", "z")])
    with pytest.raises(ValueError, match=r"marker 'B' must have exactly the coords 'x', "
                                         r"'y', 'z'; got \['x', 'y'\]"):
        write_trc(df, tmp_path / "x.trc")


def test_write_rejects_a_label_with_a_tab(tmp_path):
    df = marker_frame(EXPECTED, ["A", "B\tC"], [0.0, 0.01], rate=100.0, units="mm")
    with pytest.raises(ValueError, match=r"marker label 'B\\tC' must be a non-empty string"):
        write_trc(df, tmp_path / "x.trc")


def test_write_rejects_infinite_values(tmp_path):
    df = good_frame()
    df.iloc[0, 0] = np.inf
    with pytest.raises(ValueError, match=r"df contains infinite values"):
        write_trc(df, tmp_path / "x.trc")


def test_write_needs_a_rate(tmp_path):
    df = good_frame()
    del df.attrs["rate"]
    with pytest.raises(ValueError, match=r"rate: df.attrs has no 'rate'; pass rate="):
        write_trc(df, tmp_path / "x.trc")


def test_write_rejects_a_bad_rate(tmp_path):
    with pytest.raises(ValueError, match=r"rate must be a positive number \(Hz\); got -5"):
        write_trc(good_frame(), tmp_path / "x.trc", rate=-5)


def test_write_needs_units(tmp_path):
    df = good_frame()
    del df.attrs["units"]
    with pytest.raises(ValueError, match=r"units: df.attrs has no 'units'"):
        write_trc(df, tmp_path / "x.trc")


def test_write_rejects_bad_units(tmp_path):
    with pytest.raises(ValueError, match=r"units must be a non-empty word"):
        write_trc(good_frame(), tmp_path / "x.trc", units="milli metres")


def test_write_rejects_time_that_does_not_increase(tmp_path):
    df = good_frame()
    df.index = pd.Index([0.01, 0.01], name="time")
    with pytest.raises(ValueError, match=r"df.index \(time\) must increase; got 0.01 then "
                                         r"0.01 at rows 0 and 1"):
        write_trc(df, tmp_path / "x.trc")


def test_write_rejects_nan_time(tmp_path):
    df = good_frame()
    df.index = pd.Index([0.0, np.nan], name="time")
    with pytest.raises(ValueError, match=r"df.index \(time\) must hold finite times"):
        write_trc(df, tmp_path / "x.trc")


@pytest.mark.parametrize("index", [pd.to_timedelta([0.0, 0.01], unit="s"),
                                   pd.date_range("2024-01-01 10:00", periods=2,
                                                 freq="10ms")],
                         ids=["timedelta", "datetime"])
def test_write_rejects_a_time_index_that_is_not_seconds(tmp_path, index):
    # numpy turns these into integer nanoseconds (or microseconds): 0.01 s became 1e7
    df = good_frame()
    df.index = index
    with pytest.raises(ValueError, match=r"df.index \(time\) must hold the time in seconds "
                                         r"as numbers; got dtype"):
        write_trc(df, tmp_path / "x.trc")


def test_write_keeps_the_time_when_the_coordinates_are_rounded(tmp_path):
    # 0.01 mm is plenty for coordinates in mm, but '%.2f' would write the times of a
    # 200 Hz trial as 0.00, 0.01, 0.01, 0.01, 0.02 (no longer increasing)
    times = np.arange(5) / 200.0
    values = np.tile(EXPECTED[:1], (5, 1)) + 0.123456
    df = marker_frame(values, ["A", "B"], times, rate=200.0, units="mm")
    with pytest.warns(UserWarning, match=r"float_format '%.2f' writes the coordinates to "
                                         r"0.01, but the largest is 6.12"):
        write_trc(df, tmp_path / "x.trc", float_format="%.2f")
    back = read_quietly(tmp_path / "x.trc")
    np.testing.assert_allclose(back.index.to_numpy(), times, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(back.to_numpy(), np.round(values, 2))


def test_write_rejects_labels_with_padding_spaces(tmp_path):
    # TRC readers strip the padding of fields: ' A' would come back as 'A'
    df = marker_frame(EXPECTED, [" A", "B"], [0.0, 0.01], rate=100.0, units="mm")
    with pytest.raises(ValueError, match=r"marker label ' A' must .*leading or trailing "
                                         r"spaces"):
        write_trc(df, tmp_path / "x.trc")


def test_write_rejects_a_bad_camera_rate_in_attrs(tmp_path):
    # it would be written as 'nan' and the file could not be read back
    df = good_frame()
    df.attrs["camera_rate"] = np.nan
    with pytest.raises(ValueError, match=r"df.attrs\['camera_rate'\] must be a positive "
                                         r"number \(Hz\); got nan"):
        write_trc(df, tmp_path / "x.trc")


# --- C3D -----------------------------------------------------------------------------------

def test_read_c3d_without_ezc3d_names_the_extra(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "ezc3d", None)  # makes `import ezc3d` fail
    with pytest.raises(ImportError, match=r"read_c3d needs the optional package ezc3d.*"
                                          r"pip install 'bmc_functions\[c3d\]'"):
        read_c3d(tmp_path / "any.c3d")


def test_read_c3d_small_file(tmp_path):
    ezc3d = pytest.importorskip("ezc3d")
    n = 4
    xyz = np.arange(3 * 3 * n, dtype=float).reshape(3, 3, n) * 1.5 + 100.0
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [200.0]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = ("RTH1", "RTH2", "LKneeAngles")
    c3d["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    points = np.ones((4, 3, n))
    points[:3] = xyz
    c3d["data"]["points"] = points
    residuals = np.zeros((1, 3, n))
    residuals[0, 1, 2] = -1.0  # RTH2 not seen in the third frame
    c3d["data"]["meta_points"]["residuals"] = residuals
    c3d.add_parameter("POINT", "ANGLES", ["LKneeAngles"])
    path = tmp_path / "small.c3d"
    c3d.write(str(path))

    df = read_c3d(path)
    assert markers(df) == ["RTH1", "RTH2"]
    assert df.attrs["dropped_labels"] == ["LKneeAngles"]
    assert df.attrs["rate"] == 200.0 and df.attrs["units"] == "mm"
    assert df.attrs["frames"] == [1, 2, 3, 4]
    np.testing.assert_allclose(df.index.to_numpy(), [0.0, 0.005, 0.01, 0.015])
    # xyz[c, marker, frame] -> df[marker][frame, c]
    np.testing.assert_allclose(df["RTH1"].to_numpy(), xyz[:, 0, :].T)
    expected = xyz[:, 1, :].T.copy()
    expected[2] = np.nan
    np.testing.assert_allclose(df["RTH2"].to_numpy(), expected)
    # and it writes to TRC like any marker DataFrame
    write_trc(df, tmp_path / "from_c3d.trc")
    pd.testing.assert_frame_equal(read_quietly(tmp_path / "from_c3d.trc"), df,
                                  check_exact=False, rtol=0, atol=1e-6)


def test_read_c3d_points_without_a_label(tmp_path):
    # not "duplicate marker labels: , " but which points have no label
    ezc3d = pytest.importorskip("ezc3d")
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [100.0]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = ("RTH1", "", "")
    c3d["data"]["points"] = np.ones((4, 3, 2))
    path = tmp_path / "blank.c3d"
    c3d.write(str(path))
    with pytest.raises(ValueError, match=r"blank.c3d: POINT:LABELS: points 2, 3 \(of 3\) "
                                         r"have an empty label"):
        read_c3d(path)

# --- the real recordings of ../shared/data (skipped without them) ------------------------

def shared(name):
    skip_without_shared(name)
    return SHARED / name


def hand_row(path, line_number):
    """Fields of one line (1-based), parsed by hand with str.split."""
    line = path.read_text().splitlines()[line_number - 1]
    return line.split("\t")


def hand_labels(path):
    fields = hand_row(path, 4)
    return [f.strip() for f in fields[2::3] if f.strip()]


CLUSTERS = ["RTH1", "RTH2", "RTH3", "RTB1", "RTB2", "RTB3", "LTH1", "LTH2", "LTH3",
            "LTB1", "LTB2", "LTB3", "RASI", "LASI", "RPSI", "LPSI"]
LANDMARKS = ["RLFC", "RMFC", "RLMAL", "RMMAL", "LLFC", "LMFC", "LLMAL", "LMMAL"]


def test_real_walk_more_labels_than_num_markers():
    path = shared("walk.trc")
    df = read_quietly(path)
    labels = hand_labels(path)
    assert len(labels) > 28  # the quirk this file is here for
    assert markers(df) == labels[:28]
    assert df.attrs["dropped_labels"] == labels[28:]
    assert df.shape == (184, 84)
    assert df.attrs["rate"] == 150.0 and df.attrs["units"] == "mm"
    assert df.attrs["frames"] == list(range(1, 185))
    assert np.isfinite(df.to_numpy()).all()  # the 28 markers are seen in every frame
    row = hand_row(path, 7)  # first data row (CRLF file: splitlines drops the \r)
    assert float(row[1]) == df.index[0]
    np.testing.assert_array_equal(df["R.ASIS"].iloc[0].to_numpy(),
                                  [float(v) for v in row[2:5]])
    row = hand_row(path, 190)  # last data row, last of the 28 markers
    np.testing.assert_array_equal(df["L.MT2"].iloc[-1].to_numpy(),
                                  [float(v) for v in row[2 + 3 * 27:5 + 3 * 27]])


def test_real_static_trial():
    path = shared("static_run.trc")
    df = read_quietly(path)
    assert len(markers(df)) == 78 and markers(df) == hand_labels(path)
    assert df.shape == (1500, 234)
    assert df.attrs["rate"] == 150.0 and df.attrs["units"] == "mm"
    assert df.attrs["dropped_labels"] == []
    assert np.isfinite(df[CLUSTERS + LANDMARKS].to_numpy()).all()
    row = hand_row(path, 1506)  # last line: frame 1500
    assert int(row[0]) == df.attrs["frames"][-1] == 1500
    k = markers(df).index("RTH2")
    np.testing.assert_array_equal(df["RTH2"].iloc[-1].to_numpy(),
                                  [float(v) for v in row[2 + 3 * k:5 + 3 * k]])


def test_real_running_trial():
    path = shared("motion_capture_run.trc")
    df = read_quietly(path)
    assert markers(df) == hand_labels(path) and len(markers(df)) == 78
    assert df.shape == (123, 234)
    assert df.attrs["rate"] == 150.0 and df.attrs["units"] == "mm"
    assert np.isfinite(df[CLUSTERS].to_numpy()).all()
    # the landmarks are empty in the running trial: kept as all-NaN columns
    assert df[LANDMARKS].isna().all().all()
    assert df.attrs["dropped_labels"] == []
    row = hand_row(path, 7 + 60)  # frame 61
    assert int(row[0]) == 61
    k = markers(df).index("LTB3")
    expected = [float(v) if v else np.nan for v in row[2 + 3 * k:5 + 3 * k]]
    np.testing.assert_array_equal(df["LTB3"].iloc[60].to_numpy(), expected)


def test_real_static_trial_reads_fast():
    path = shared("static_run.trc")
    read_trc(path)  # warm-up (imports, file cache)
    start = time.perf_counter()
    read_trc(path)
    assert time.perf_counter() - start < 1.0  # 1500 frames x 78 markers


def test_real_round_trip(tmp_path):
    df = read_quietly(shared("motion_capture_run.trc"))
    write_trc(df, tmp_path / "run.trc")
    back = read_quietly(tmp_path / "run.trc")
    pd.testing.assert_frame_equal(back, df, check_exact=True)
    labels, data = opensim_read(tmp_path / "run.trc")
    assert labels == markers(df)


# --- header layouts of other writers (issue 9: every TRC that OpenSim reads) -------------

@pytest.mark.parametrize("first_line", [
    "PathFileType 4 (X/Y/Z) test.trc",            # spaces only
    "PathFileType  4\t(X/Y/Z)\ttest.trc",         # OpenSim 3's writer: spaces then tabs
    "PathFileType\t4\t(X/Y/Z)",                   # no file name
    "PathFileType\t4\t(X/Y/Z)\tC:\\My Data\\walk 1.trc\tCortex 8 export",  # trailing text
    "PathFileType 4 (X/Y/Z)  ",
], ids=["spaces", "spaces-and-tabs", "no-name", "trailing-text", "padded"])
def test_first_line_layouts(tmp_path, first_line):
    lines = trc_lines()
    lines[0] = first_line
    df = read_quietly(write_lines(tmp_path, lines))
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)


def test_keys_and_values_separated_by_spaces(tmp_path):
    lines = trc_lines()
    lines[1] = " ".join(KEYS.split("\t"))
    lines[2] = "  100.00   100.00      2   2  mm  100.00  1      2   "
    df = read_quietly(write_lines(tmp_path, lines))
    assert df.attrs["rate"] == 100.0 and df.attrs["units"] == "mm"
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)


def test_first_line_with_another_first_word_is_still_refused(tmp_path):
    lines = trc_lines()
    lines[0] = "PathFile Type 4 (X/Y/Z) test.trc"
    malformed(tmp_path, lines, r"line 1: expected the TRC header line 'PathFileType")


@pytest.mark.parametrize("name", ["walk.trc", "static_run.trc", "motion_capture_run.trc"])
def test_every_shared_real_file_reads(name):
    df = read_trc(shared(name))
    assert df.shape[0] > 100 and df.shape[1] >= 84
    assert df.attrs["rate"] == 150.0


# --- paths that are not regular files (issue 10: no hang) --------------------------------

def test_read_trc_refuses_a_directory(tmp_path):
    with pytest.raises(ValueError, match=r"path: .* is a directory; expected a TRC file"):
        read_trc(tmp_path)


def test_read_trc_refuses_dev_zero():
    if not Path("/dev/zero").exists():
        pytest.skip("no /dev/zero here")
    start = time.perf_counter()
    with pytest.raises(ValueError, match=r"/dev/zero is not a regular file \(a device, "
                                         r"pipe or socket\); expected a TRC file"):
        read_trc("/dev/zero")
    assert time.perf_counter() - start < 1.0


def test_read_trc_refuses_a_named_pipe(tmp_path):
    if not hasattr(os, "mkfifo"):
        pytest.skip("no named pipes here")
    fifo = tmp_path / "pipe.trc"
    os.mkfifo(fifo)  # opening it for reading would block until a writer comes
    with pytest.raises(ValueError, match=r"pipe.trc is not a regular file"):
        read_trc(fifo)


def test_read_trc_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"no such file: .*absent.trc"):
        read_trc(tmp_path / "absent.trc")


def test_file_of_zero_bytes_without_line_breaks(tmp_path):
    # a binary blob saved as .trc: refused after reading a bounded first line
    path = tmp_path / "blob.trc"
    path.write_bytes(b"\0" * (17 * 2**20))
    start = time.perf_counter()
    with pytest.raises(ValueError, match=r"blob.trc, line 1: the line is longer than "
                                         r"16777216 bytes"):
        read_trc(path)
    assert time.perf_counter() - start < 5.0


# --- a cut last line (issue 10: never a shortened number) --------------------------------

def write_cut(tmp_path, text):
    path = tmp_path / "cut.trc"
    path.write_bytes(text.encode())
    return path


def full_text(rows=ROWS):
    return "\n".join(trc_lines(rows=rows)) + "\n"


def test_last_line_cut_inside_a_number(tmp_path):
    # '31.25' cut to '3' must not read as 3.0
    rows = [ROWS[0], "2\t0.01\t1.5\t2.5\t3.5\t4.5\t5.5\t31.25"]
    text = full_text(rows)
    path = write_cut(tmp_path, text[:text.rindex("31.25") + 1])
    with pytest.warns(UserWarning, match=r"line 8, the last line, does not end with a line "
                                         r"break \(is the file cut\?\).*set to NaN: B"):
        df = read_trc(path)
    np.testing.assert_array_equal(df["A"].to_numpy(), EXPECTED[:, :3])
    assert df["B"].iloc[1].isna().all()
    np.testing.assert_array_equal(df["B"].iloc[0].to_numpy(), EXPECTED[0, 3:])


def test_last_line_cut_inside_the_first_marker(tmp_path):
    text = full_text()
    path = write_cut(tmp_path, text[:text.rindex("2.5")])  # '2\t0.01\t1.5\t'
    with pytest.warns(UserWarning, match=r"markers of that row were set to NaN: A$"):
        df = read_trc(path)
    assert df.shape == (2, 6) and df.iloc[1].isna().all()
    assert df.attrs["frames"] == [1, 2]


def test_last_line_cut_in_the_time_drops_the_row(tmp_path):
    text = full_text()
    path = write_cut(tmp_path, text[:text.rindex("0.01") + 3])  # '2\t0.0'
    with pytest.warns(UserWarning, match=r"line 8, the last line, does not end with a line "
                                         r"break and stops before its first marker "
                                         r".*left out"):
        df = read_trc(path)
    assert df.attrs["frames"] == [1]
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED[:1])


def test_last_line_without_line_break_but_complete(tmp_path):
    # every row ends with a tab: a last line that ends with its tab is whole
    rows = [row + "\t" for row in ROWS]
    path = write_cut(tmp_path, full_text(rows).rstrip("\n"))
    df = read_quietly(path)
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)


def test_last_line_without_line_break_may_be_cut(tmp_path):
    # without a final tab the last number may be cut: its marker is NaN, with a warning
    path = write_cut(tmp_path, full_text().rstrip("\n"))
    with pytest.warns(UserWarning, match=r"markers of that row were set to NaN: B$"):
        df = read_trc(path)
    np.testing.assert_array_equal(df["A"].to_numpy(), EXPECTED[:, :3])
    assert df["B"].iloc[1].isna().all()


def test_cut_last_line_with_a_bad_field_is_an_error(tmp_path):
    text = full_text().replace("1.5\t2.5", "1.5\tx")
    path = write_cut(tmp_path, text.rstrip("\n"))
    with pytest.raises(ValueError, match=r"cut.trc, line 8: field 4 \('A' y\) is not a "
                                         r"number: 'x'"):
        read_trc(path)


def test_cut_file_of_a_crlf_file_between_cr_and_lf(tmp_path):
    path = tmp_path / "crlf.trc"
    path.write_bytes(("\r\n".join(trc_lines()) + "\r").encode())
    df = read_quietly(path)  # the line ends with its CR: whole
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)


def test_old_mac_line_ends(tmp_path):
    df = read_quietly(write_lines(tmp_path, trc_lines(), newline="\r"))
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)


# --- scale: work bounded by the header, linear header parse (issue 10, issue 16) ---------

def header_lines(labels, n_frames=1):
    n = len(labels)
    return ["PathFileType\t4\t(X/Y/Z)\tbig.trc", KEYS,
            f"100\t100\t{n_frames}\t{n}\tmm\t100\t1\t{n_frames}",
            "Frame#\tTime\t" + "".join(f"{label}\t\t\t" for label in labels),
            "\t\t" + "".join(f"X{k}\tY{k}\tZ{k}\t" for k in range(1, n + 1)), ""]


def test_100000_labels_read_in_a_bounded_time(tmp_path):
    n = 100_000
    labels = [f"M{k}" for k in range(n)]
    row = "1\t0.0\t" + "\t".join(f"{k % 1000}.5" for k in range(3 * n))
    path = write_lines(tmp_path, header_lines(labels) + [row])
    start = time.perf_counter()
    df = read_quietly(path)
    assert time.perf_counter() - start < 10.0  # 0.2 s here; more than 60 s before
    assert df.shape == (1, 3 * n)
    assert markers(df)[-1] == "M99999"
    np.testing.assert_array_equal(df.to_numpy()[0, :4], [0.5, 1.5, 2.5, 3.5])
    assert df.to_numpy()[0, -1] == (3 * n - 1) % 1000 + 0.5


def test_100000_labels_duplicate_found_in_a_bounded_time(tmp_path):
    labels = [f"M{k}" for k in range(100_000)]
    labels[-1] = "M7"
    path = write_lines(tmp_path, header_lines(labels) + ["1\t0.0"])
    start = time.perf_counter()
    with pytest.raises(ValueError, match=r"line 4: duplicate marker labels: M7"):
        read_trc(path)
    assert time.perf_counter() - start < 10.0


def test_a_million_tabs_in_a_row_is_refused_at_once(tmp_path):
    rows = [ROWS[0], "2\t0.01" + "\t1" * 1_000_000]
    path = write_lines(tmp_path, trc_lines(rows=rows))
    start = time.perf_counter()
    with pytest.raises(ValueError, match=r"line 8: the row has 1000002 fields but the "
                                         r"labels line defines 8"):
        read_trc(path)
    assert time.perf_counter() - start < 5.0  # 19 s and 1.45 GB before
    path = write_lines(tmp_path, trc_lines(rows=[ROWS[0], ROWS[1] + "\t" * 1_000_000]))
    with pytest.raises(ValueError, match=r"line 8: the row has 1000008 fields where most "
                                         r"rows have 8"):
        read_trc(path)
    assert time.perf_counter() - start < 10.0


def test_a_million_trailing_tabs_are_read_at_once(tmp_path):
    # (whole markers of empty fields: 999,999 tabs; one more would be a stray field)
    rows = [ROWS[0], ROWS[1] + "\t" * 999_999]
    path = write_lines(tmp_path, trc_lines(rows=rows))
    start = time.perf_counter()
    df = read_quietly(path)
    assert time.perf_counter() - start < 5.0
    np.testing.assert_array_equal(df.to_numpy(), EXPECTED)


def test_a_row_longer_than_the_header_allows_is_refused(tmp_path):
    rows = [ROWS[0], "2\t0.01\t" + "1" * (5 * 2**20)]
    path = write_lines(tmp_path, trc_lines(rows=rows))
    with pytest.raises(ValueError, match=r"line 8: the line is 5242887 bytes long; no row "
                                         r"of this file needs more than"):
        read_trc(path)


def test_big_file_equals_a_hand_parse(tmp_path):
    # more rows than one block of the scan (16 MB) would not be needed: check the
    # parse against numpy's own text parser on a file of 20,000 rows with gaps
    rng = np.random.default_rng(3)
    values = np.round(rng.uniform(-2000, 2000, (20_000, 30)), 5)
    values[rng.random(values.shape) < 0.01] = np.nan
    labels = [f"M{k}" for k in range(10)]
    df = marker_frame(values, labels, np.arange(20_000) / 100, rate=100.0, units="mm")
    write_trc(df, tmp_path / "big.trc", float_format="%.5f")
    back = read_quietly(tmp_path / "big.trc")
    hand = np.genfromtxt(tmp_path / "big.trc", delimiter="\t", skip_header=6,
                         usecols=range(2, 32))
    np.testing.assert_array_equal(back.to_numpy(), hand)
    np.testing.assert_array_equal(back.to_numpy(), values)


# --- write_trc: refuse what would not read back (issue 10) --------------------------------

@pytest.mark.parametrize("name", ["bad\nname.trc", "bad\rname.trc"])
def test_write_refuses_a_line_break_in_the_file_name(tmp_path, name):
    with pytest.raises(ValueError, match=r"path: the file name must not contain a line "
                                         r"break"):
        write_trc(good_frame(), tmp_path / name)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("fmt", ["abc", "%s %s", "%.2f\t", "", "%d%%x"])
def test_write_refuses_a_float_format_that_is_not_a_number(tmp_path, fmt):
    with pytest.raises(ValueError, match=r"float_format must format one number as a "
                                         r"number"):
        write_trc(good_frame(), tmp_path / "x.trc", float_format=fmt)


def test_write_refuses_a_float_format_that_is_not_a_string(tmp_path):
    with pytest.raises(TypeError, match=r"float_format must be a printf-style format "
                                        r"string .*got int"):
        write_trc(good_frame(), tmp_path / "x.trc", float_format=6)


@pytest.mark.parametrize("rate", [True, np.bool_(True)])
def test_write_refuses_a_boolean_rate(tmp_path, rate):
    with pytest.raises(TypeError, match=r"rate must be a positive number \(Hz\); got (np\.)?True"):
        write_trc(good_frame(), tmp_path / "x.trc", rate=rate)


def test_write_refuses_a_boolean_dataframe(tmp_path):
    df = good_frame() > 2
    with pytest.raises(TypeError, match=r"df must hold coordinates \(numbers\); got "
                                        r"boolean columns"):
        write_trc(df, tmp_path / "x.trc")


@pytest.mark.parametrize("frames", [[10**400, 10**400 + 1], ["a", "b"], [True, False],
                                    [1.5, 2.5], [np.nan, 2]],
                         ids=["huge-ints", "labels", "booleans", "fractions", "nan"])
def test_write_renumbers_frames_it_cannot_write_exactly(tmp_path, frames):
    df = good_frame()
    df.attrs["frames"] = frames
    with pytest.warns(UserWarning, match=r"df.attrs\['frames'\] does not hold whole numbers "
                                         r"below 2\*\*53 .*numbered 1 to 2"):
        write_trc(df, tmp_path / "x.trc")
    back = read_quietly(tmp_path / "x.trc")
    assert back.attrs["frames"] == [1, 2]
    np.testing.assert_array_equal(back.to_numpy(), EXPECTED)


def test_write_read_round_trip_of_many_markers_is_linear(tmp_path):
    n = 20_000
    values = np.arange(2 * 3 * n, dtype=float).reshape(2, 3 * n) / 4
    df = marker_frame(values, [f"M{k}" for k in range(n)], [0.0, 0.01], rate=100.0,
                      units="mm")
    start = time.perf_counter()
    write_trc(df, tmp_path / "wide.trc")
    back = read_quietly(tmp_path / "wide.trc")
    assert time.perf_counter() - start < 10.0  # quadratic before: minutes
    np.testing.assert_array_equal(back.to_numpy(), values)
    assert markers(back) == [f"M{k}" for k in range(n)]


# --- C3D: damaged files give a clear error, never a crash or a hang (issue 10) -----------

def c3d_file(path, n_frames=40, rate=100.0, analogs=True, seed=1):
    """Write a small valid C3D file with ezc3d (3 markers, one marker hidden in frame 5)."""
    ezc3d = pytest.importorskip("ezc3d")
    rng = np.random.default_rng(seed)
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [rate]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = ("RTH1", "RTH2", "RTH3")
    c3d["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    points = np.zeros((4, 3, n_frames))
    points[:3] = np.round(rng.normal(0, 300, (3, 3, n_frames)), 2)
    c3d["data"]["points"] = points
    residuals = np.zeros((1, 3, n_frames))
    residuals[0, 1, 4] = -1.0
    c3d["data"]["meta_points"]["residuals"] = residuals
    if analogs:
        c3d["parameters"]["ANALOG"]["RATE"]["value"] = [2 * rate]
        c3d["parameters"]["ANALOG"]["LABELS"]["value"] = ("EMG1",)
        c3d["data"]["analogs"] = rng.normal(size=(1, 1, 2 * n_frames))
    c3d.write(str(path))
    return path, points


def parameter_record(path, group, name):
    """(kind, dims, byte offset of the value) of a parameter, from the structure walk."""
    from bmc_functions.files._c3d_binary import walk_parameters

    raw = Path(path).read_bytes()
    start = (raw[0] - 1) * 512
    section = raw[start:start + raw[start + 2] * 512]
    kind, dims, at = walk_parameters(section, 0, len(section), raw[start + 3],
                                     pytest.fail)[(group, name)]
    return kind, dims, start + at


def test_read_c3d_refuses_a_directory(tmp_path):
    pytest.importorskip("ezc3d")
    with pytest.raises(ValueError, match=r"is a directory; expected a C3D file"):
        read_c3d(tmp_path)


def test_read_c3d_refuses_dev_zero():
    pytest.importorskip("ezc3d")
    if not Path("/dev/zero").exists():
        pytest.skip("no /dev/zero here")
    with pytest.raises(ValueError, match=r"/dev/zero is not a regular file"):
        read_c3d("/dev/zero")


def test_read_c3d_refuses_a_text_file(tmp_path):
    pytest.importorskip("ezc3d")
    path = write_lines(tmp_path, trc_lines() * 20, name="walk.c3d")
    with pytest.raises(ValueError, match=r"walk.c3d: not a readable C3D file: byte 2 is "
                                         r"97, not the C3D key 80"):
        read_c3d(path)


def test_read_c3d_file_cut_before_its_data(tmp_path):
    path, _ = c3d_file(tmp_path / "full.c3d")
    raw = path.read_bytes()
    data_block = int.from_bytes(raw[16:18], "little")
    cut = tmp_path / "cut.c3d"
    cut.write_bytes(raw[:(data_block - 1) * 512])
    with pytest.raises(ValueError, match=r"cut.c3d: not a readable C3D file: the file is "
                                         r"cut before its data"):
        read_c3d(cut)  # frames of 0.0 before


def test_read_c3d_file_cut_inside_its_data_warns_and_reads_whole_frames(tmp_path):
    path, points = c3d_file(tmp_path / "full.c3d")
    full = read_c3d(path)
    raw = path.read_bytes()
    frame_bytes = (4 * 3 + 2) * 4  # 3 points x (x, y, z, residual) + 2 analog samples
    data = (int.from_bytes(raw[16:18], "little") - 1) * 512
    cut = tmp_path / "cut.c3d"
    cut.write_bytes(raw[:data + 17 * frame_bytes + 9])  # 17 whole frames and a bit
    with pytest.warns(UserWarning, match=r"cut.c3d: the header announces 40 frames but the "
                                         r"file holds 17 whole frames \(is it cut\?\)"):
        df = read_c3d(cut)
    assert df.attrs["frames"] == list(range(1, 18))
    pd.testing.assert_frame_equal(df, full.iloc[:17], check_exact=True)
    np.testing.assert_allclose(df["RTH1"].to_numpy(), points[:3, 0, :17].T, rtol=1e-6)


@pytest.mark.parametrize("rate", [0.0, -100.0])
def test_read_c3d_refuses_a_rate_that_is_not_positive(tmp_path, rate):
    path, _ = c3d_file(tmp_path / "rate.c3d", analogs=False)
    kind, _, at = parameter_record(path, "POINT", "RATE")
    raw = bytearray(path.read_bytes())
    raw[at:at + 4] = np.float32(rate).tobytes()
    path.write_bytes(bytes(raw))
    with pytest.raises(ValueError, match=rf"rate.c3d: not a readable C3D file: POINT:RATE is "
                                         rf"{rate:g}; a frame rate must be a positive"):
        read_c3d(path)  # a time index of NaN/inf, or decreasing, before


def test_read_c3d_data_start_disagreeing_with_the_header(tmp_path):
    # a flipped bit in POINT:DATA_START made ezc3d crash the process
    path, _ = c3d_file(tmp_path / "start.c3d")
    _, _, at = parameter_record(path, "POINT", "DATA_START")
    raw = bytearray(path.read_bytes())
    raw[at + 1] ^= 0x80
    path.write_bytes(bytes(raw))
    with pytest.raises(ValueError, match=r"start.c3d: not a readable C3D file: "
                                         r"POINT:DATA_START \(\d+\) disagrees with the "
                                         r"header's first data block \(\d+\)"):
        read_c3d(path)


def test_read_c3d_survives_a_crash_inside_ezc3d(tmp_path):
    # ANALOG:LABELS with 0 dimensions passes the structure checks but made ezc3d crash
    # (SIGSEGV): the read runs in a child process, so this is an error, not a dead kernel
    path, _ = c3d_file(tmp_path / "labels.c3d")
    _, dims, at = parameter_record(path, "ANALOG", "LABELS")
    raw = bytearray(path.read_bytes())
    raw[at - len(dims) - 1] = 0  # the number of dimensions
    path.write_bytes(bytes(raw))
    with pytest.raises(ValueError, match=r"labels.c3d: not a readable C3D file: ezc3d "
                                         r"(crashed reading it|.*could not read it)"):
        read_c3d(path)


def test_a_crash_inside_ezc3d_prints_nothing(tmp_path):
    # the crashed child used to print ~70 lines of "Fatal Python error: Segmentation
    # fault" and stack dumps (an inherited faulthandler) into a green test run
    import subprocess
    import sys

    path, _ = c3d_file(tmp_path / "labels.c3d")
    _, dims, at = parameter_record(path, "ANALOG", "LABELS")
    raw = bytearray(path.read_bytes())
    raw[at - len(dims) - 1] = 0
    path.write_bytes(bytes(raw))
    code = ("import sys\nfrom bmc_functions import read_c3d\ntry:\n    read_c3d(sys.argv[1])\n"
            "except ValueError as err:\n    print(err)\n")
    run = subprocess.run([sys.executable, "-X", "faulthandler", "-c", code, str(path)],
                         capture_output=True, text=True, timeout=120)
    assert "labels.c3d: not a readable C3D file" in run.stdout
    assert run.stderr == ""


def fuzz_outcomes_are_clean(outcomes, names):
    """No crash, no hang, only ValueErrors that name the file and say nothing internal."""
    kinds = {}
    for name, outcome in zip(names, outcomes):
        kinds[outcome[0]] = kinds.get(outcome[0], 0) + 1
        assert outcome[0] in ("ok", "ValueError"), (name, outcome[:2], outcome[-1])
        if outcome[0] == "ValueError":
            assert name in outcome[1], outcome[1]
            assert not re.search(r"ignoreBadFormatting|_M_|std::|bad_alloc", outcome[1])
    return kinds


def assert_same_where_present(outcome, original):
    """A read of a cut file: its rows are rows of the original, values equal or NaN."""
    _, time_, frames, values, columns, _ = outcome
    assert columns == list(original.columns)
    if not frames:
        return
    rows = original.index.get_indexer(time_)
    assert (rows >= 0).all()
    assert frames == [original.attrs["frames"][r] for r in rows]
    expected = original.to_numpy()[rows]
    present = ~np.isnan(values)
    np.testing.assert_array_equal(values[present], expected[present])  # NaN never filled


def test_fuzz_trc_cut_at_every_byte_and_flipped(tmp_path):
    from read_worker import read_in_child

    values = EXPECTED.copy()
    values[0, 3:] = np.nan
    df = marker_frame(np.vstack([values, values + 31.25]), ["A", "B"],
                      [0.0, 0.01, 0.02, 0.03], rate=100.0, units="mm")
    write_trc(df, tmp_path / "orig.trc")
    tabs = (tmp_path / "orig.trc").read_bytes()
    no_tabs = b"\n".join(line.rstrip(b"\t") for line in tabs.split(b"\n"))
    original = read_quietly(tmp_path / "orig.trc")
    paths, kinds = [], []
    for variant, raw in (("tabs", tabs), ("notabs", no_tabs)):
        for k in range(len(raw)):  # every cut position
            path = tmp_path / f"{variant}_cut{k}.trc"
            path.write_bytes(raw[:k])
            paths.append(path)
            kinds.append("cut")
    rng = np.random.default_rng(10)
    for j in range(300):  # flipped bits
        raw = bytearray(tabs)
        raw[rng.integers(len(raw))] ^= 1 << int(rng.integers(8))
        path = tmp_path / f"flip{j}.trc"
        path.write_bytes(bytes(raw))
        paths.append(path)
        kinds.append("flip")
    start = time.perf_counter()
    outcomes = read_in_child("read_trc", paths, folder=tmp_path, timeout=20.0)
    assert time.perf_counter() - start < 60.0
    counts = fuzz_outcomes_are_clean(outcomes, [p.name for p in paths])
    for kind, outcome in zip(kinds, outcomes):
        if kind == "cut" and outcome[0] == "ok":
            assert_same_where_present(outcome, original)
    assert counts["ok"] > 400 and counts["ValueError"] > 100  # both paths exercised


def test_fuzz_c3d_cut_and_flipped(tmp_path):
    from read_worker import read_in_child

    path, _ = c3d_file(tmp_path / "valid.c3d")
    original = read_c3d(path)
    raw = path.read_bytes()
    rng = np.random.default_rng(11)
    cuts = sorted(set(rng.integers(0, len(raw), 150).tolist()) | {0, 511, 512, 4095})
    paths, kinds = [], []
    for k in cuts:
        cut = tmp_path / f"cut{k}.c3d"
        cut.write_bytes(raw[:k])
        paths.append(cut)
        kinds.append("cut")
    for j in range(100):  # flipped bits, mostly in the header and parameters
        flipped = bytearray(raw)
        flipped[rng.integers(min(len(raw), 3072))] ^= 1 << int(rng.integers(8))
        flip = tmp_path / f"flip{j}.c3d"
        flip.write_bytes(bytes(flipped))
        paths.append(flip)
        kinds.append("flip")
    start = time.perf_counter()
    outcomes = read_in_child("read_c3d", paths, folder=tmp_path, timeout=20.0)
    assert time.perf_counter() - start < 120.0
    counts = fuzz_outcomes_are_clean(outcomes, [p.name for p in paths])
    for kind, outcome in zip(kinds, outcomes):
        if kind == "cut" and outcome[0] == "ok":
            assert_same_where_present(outcome, original)
    assert counts["ok"] > 20 and counts["ValueError"] > 50


@pytest.mark.parametrize("reader", [read_trc, read_c3d], ids=["trc", "c3d"])
@pytest.mark.parametrize("path", [None, 3, b"x.trc"], ids=["none", "int", "bytes"])
def test_readers_refuse_a_path_that_is_not_a_file_name(reader, path):
    if reader is read_c3d:
        pytest.importorskip("ezc3d")
    with pytest.raises(TypeError, match=r"path must be a file name \(str or path-like\); "
                                        r"got (NoneType|int|bytes)"):
        reader(path)


def test_binary_junk_is_refused_at_line_1(tmp_path):
    path = tmp_path / "junk.trc"
    path.write_bytes(np.random.default_rng(0).integers(0, 256, 100_000, dtype=np.uint8)
                     .tobytes())
    with pytest.raises(ValueError, match=r"junk.trc, line 1: expected the TRC header line"):
        read_trc(path)


def test_unicode_in_a_bad_field_is_shown_readably(tmp_path):
    rows = [ROWS[0], "2\t0.01\t\u22121.5\t2.5\t3.5\t4.5\t5.5\t6.5"]
    malformed(tmp_path, trc_lines(rows=rows), r"line 8: field 3 \('A' x\) is not a number: "
                                              "'\u22121.5'")


# --- issue 20 (item 5): a DataRate that contradicts the Time column --------------------------

def _timed_rows(times):
    return [f"{k + 1}\t{t:.3f}\t1.0\t2.0\t3.0\t4.0\t5.0\t6.0" for k, t in enumerate(times)]


def test_datarate_contradicting_the_time_column_warns_naming_both(tmp_path):
    rows = _timed_rows(np.arange(100) * 0.02)             # 50 Hz times, DataRate 100
    with pytest.warns(UserWarning, match=r"DataRate = 100 Hz, but the Time column steps at "
                                         r"50 Hz \(99 frame steps over 1.98 s; at 100 Hz they "
                                         r"would span 0.99 s\)"):
        df = read_trc(write_lines(tmp_path, trc_lines(rows=rows)))
    assert df.attrs["rate"] == 100.0 and df.index[-1] == pytest.approx(1.98)


@pytest.mark.parametrize("rate, step", [(100, 0.01), (120, 1 / 120), (250, 0.004),
                                        (60, 1 / 60)])
def test_datarate_matching_a_rounded_time_column_does_not_warn(tmp_path, rate, step):
    rows = _timed_rows(np.arange(300) * step)             # times rounded to 1 ms
    read_quietly(write_lines(tmp_path, trc_lines(rows=rows, rate=str(rate))))


def test_skipped_frames_do_not_contradict_the_datarate(tmp_path):
    frames = np.r_[np.arange(50), np.arange(80, 130)]      # a writer skipped 30 frames
    rows = [f"{f + 1}\t{f / 100:.3f}\t1.0\t2.0\t3.0\t4.0\t5.0\t6.0" for f in frames]
    read_quietly(write_lines(tmp_path, trc_lines(rows=rows)))
