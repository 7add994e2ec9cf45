"""Tests of bmc_functions.files.trial's MarkerTable: the stacked points (np.stack's values and
memory layout, which set the order of svdt's sums where a marker is missing), points_of
and has_data."""

import numpy as np
import pytest

from bmc_functions import read_trc
from bmc_functions.files.trial import MarkerTable

from helpers import ROOT


@pytest.fixture(scope="module")
def walk():
    """The generated walk with gaps: a column-major table, as read_trc gives it."""
    df = read_trc(ROOT / "data" / "markers" / "walk.trc")
    df.loc[df.index[20:24], "RTH1"] = np.nan
    df.loc[df.index[30], ("RTH3", "y")] = np.nan
    return df


def _np_stack(table, labels, scale):
    return np.stack([table.points(label, scale) for label in labels], axis=1)


@pytest.mark.parametrize("scale", [1.0, 10.0])
@pytest.mark.parametrize("labels", [["RTH1", "RTH2", "RTH3", "RTH4"], ["LTOE"],
                                    ["RTH3", "LTOE", "RTH1"]])
def test_stacked_has_np_stack_values_and_layout(walk, labels, scale):
    table = MarkerTable(walk)
    assert table.values.flags.f_contiguous and not table.values.flags.c_contiguous
    expected = _np_stack(table, labels, scale)
    stacked = table.stacked(labels, scale)
    assert np.array_equal(stacked, expected, equal_nan=True)
    assert stacked.strides == expected.strides           # the same memory layout
    contiguous = table.stacked(labels, scale, contiguous=True)
    assert contiguous.flags.c_contiguous
    assert np.array_equal(contiguous, expected, equal_nan=True)


@pytest.mark.parametrize("frames", [slice(0, 1), slice(None)])
def test_stacked_of_a_row_major_or_one_frame_table_is_np_stack(walk, frames):
    table = MarkerTable(walk.iloc[frames])
    table.values = np.ascontiguousarray(table.values)     # a row-major table too
    labels = ["RTH2", "RTH1", "RTH4"]
    expected = _np_stack(table, labels, 1000.0)
    stacked = table.stacked(labels, 1000.0)
    assert np.array_equal(stacked, expected, equal_nan=True)
    assert stacked.strides == expected.strides


@pytest.mark.parametrize("row_major", [False, True])
@pytest.mark.parametrize("scale", [1.0, 10.0])
def test_points_of_is_points_per_name_each_a_copy_of_its_own(walk, scale, row_major):
    """points_of gives, per name, points()'s values and memory layout (column-major from
    a column-major table, the fast path; row-major from a row-major one), a label asked
    twice included, and each array is written to without changing another or the table."""
    table = MarkerTable(walk)
    if row_major:
        table.values = np.ascontiguousarray(table.values)
    original = table.values.copy()
    labels = {"A": "RTH3", "B": "LTOE", "C": "RTH1", "D": "RTH3"}
    points = table.points_of(labels, scale)
    assert list(points) == list(labels)
    for name, label in labels.items():
        expected = table.points(label, scale)
        assert np.array_equal(points[name], expected, equal_nan=True)
        assert points[name].strides == expected.strides
    points["A"][3] = -1.0
    assert np.array_equal(points["D"], table.points("RTH3", scale), equal_nan=True)
    assert np.array_equal(points["C"], table.points("RTH1", scale), equal_nan=True)
    assert np.array_equal(table.values, original, equal_nan=True)


def test_has_data_reads_any_coordinate_of_the_label(walk):
    df = walk.copy()
    df["RTH1"] = np.nan                                   # never seen
    df["RTH2"] = np.nan
    df.loc[df.index[7], ("RTH2", "z")] = 12.0             # one coordinate in one frame
    table = MarkerTable(df)
    assert not table.has_data("RTH1")
    assert table.has_data("RTH2")
    assert table.has_data("RTH3")
    assert not table.has_data("NOT_A_LABEL")


@pytest.mark.parametrize("column", [0, 8, 29, -1])
def test_an_infinite_coordinate_in_any_column_is_refused_naming_its_marker(walk, column):
    """MarkerTable refuses an infinite coordinate in any column (the first, the 9th, a
    middle or the last one), and the error names its marker, its first frame and the
    frames that hold one."""
    df = walk.copy()
    df.iloc[[5, 9], column] = [np.inf, -np.inf]
    label = df.columns[column][0]
    match = (rf"the walk: marker '{label}' has an infinite coordinate \(first at frame 5; "
             r"2 frames in all\)")
    with pytest.raises(ValueError, match=match):
        MarkerTable(df, "the walk")
