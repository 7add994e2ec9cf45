"""Documented limits pinned on both sides, found by the mutation sample of issue 24
(tools/mutation_sample.py): each test fails if its comparison moves by one step, and its
numbers come from the docstring, not from the constant under test."""

import inspect
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
