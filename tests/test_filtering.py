"""Tests of bmc_functions.markers.filtering: the zero-lag low-pass filter and its cut-off
correction, the derivative, Winter's residual analysis, and their effect on angular
velocity. scipy.signal is the oracle for the filter; analytic signals for the
derivatives."""

import re
import warnings

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.signal import butter, sosfiltfilt, sosfreqz
from scipy.spatial.transform import Rotation

from bmc_functions import (angular_velocity, corrected_cutoff, derivative, lowpass, read_trc,
                           residual_analysis, svdt)
from bmc_functions.markers.filtering import MAX_ORDER, MAX_PASSES

from helpers import ROOT, SHARED_DATA


def combined_gain(cutoff, rate, order, passes, frequency):
    """|H(f)|^passes of the filter lowpass designs, from scipy's frequency response."""
    design = corrected_cutoff(cutoff, rate, order=order, passes=passes)
    sos = butter(order, design, fs=rate, output="sos")
    _, h = sosfreqz(sos, worN=np.atleast_1d(frequency), fs=rate)
    return np.abs(h) ** passes


# --------------------------------------------------------------------------- the cut-off


@pytest.mark.parametrize("order", [1, 2, 3, 4, 6])
@pytest.mark.parametrize("passes", [2, 4, 6, 10])
@pytest.mark.parametrize("rate, cutoff", [(100, 6), (150, 15), (1000, 10), (100, 45),
                                          (120, 0.5)])
def test_combined_filter_is_3_db_down_at_the_requested_cutoff(order, passes, rate, cutoff):
    gain = combined_gain(cutoff, rate, order, passes, cutoff)[0]
    assert gain == pytest.approx(1 / np.sqrt(2), abs=1e-9)


@settings(max_examples=200, deadline=None)
@given(order=st.integers(1, 8), pairs=st.integers(1, 5),
       rate=st.floats(20.0, 2000.0), fraction=st.floats(0.002, 0.49))
def test_any_order_passes_and_cutoff_give_minus_3_db_scipy_as_oracle(order, pairs, rate,
                                                                      fraction):
    cutoff = fraction * rate
    design = corrected_cutoff(cutoff, rate, order=order, passes=2 * pairs)
    assert cutoff < design < rate / 2
    gain = combined_gain(cutoff, rate, order, 2 * pairs, cutoff)[0]
    assert gain == pytest.approx(1 / np.sqrt(2), abs=1e-7)


def test_the_uncorrected_design_cuts_too_low_and_the_quoted_factor_holds_only_for_two_passes():
    rate, cutoff = 150.0, 6.0
    for passes in (2, 4, 6):
        sos = butter(2, cutoff, fs=rate, output="sos")
        _, h = sosfreqz(sos, worN=[cutoff], fs=rate)
        assert np.abs(h[0]) ** passes == pytest.approx(2 ** (-passes / 2))  # 3 dB per pass
    # Winter's 0.802 for a second-order filter run forwards and backwards ...
    c2 = np.tan(np.pi * cutoff / rate) / np.tan(np.pi * corrected_cutoff(cutoff, rate) / rate)
    assert c2 == pytest.approx((np.sqrt(2) - 1) ** 0.25) and round(c2, 3) == 0.802
    # ... is wrong for 4 passes: the design with 0.802 is no longer 3 dB down at 6 Hz
    design = rate / np.pi * np.arctan(np.tan(np.pi * cutoff / rate) / 0.802)
    _, h = sosfreqz(butter(2, design, fs=rate, output="sos"), worN=[cutoff], fs=rate)
    assert np.abs(h[0]) ** 4 < 0.6
    c4 = np.tan(np.pi * cutoff / rate) / np.tan(
        np.pi * corrected_cutoff(cutoff, rate, passes=4) / rate)
    assert c4 == pytest.approx((2 ** 0.25 - 1) ** 0.25)


def test_corrected_cutoff_stays_below_nyquist_near_it():
    design = corrected_cutoff(49.9, 100)
    assert 49.9 < design < 50
    assert combined_gain(49.9, 100, 2, 2, 49.9)[0] == pytest.approx(1 / np.sqrt(2), abs=1e-6)


# --------------------------------------------------------------------------- the filter


def test_lowpass_equals_scipy_sosfiltfilt_without_gaps():
    rng = np.random.default_rng(0)
    x = np.cumsum(rng.normal(size=(300, 4)), axis=0)
    sos = butter(2, corrected_cutoff(8, 100), fs=100, output="sos")
    once = sosfiltfilt(sos, x, axis=0, padtype="odd", padlen=25)    # 2 * 100 / 8
    np.testing.assert_allclose(lowpass(x, 8, rate=100), once, atol=1e-12)
    sos4 = butter(3, corrected_cutoff(8, 100, order=3, passes=4), fs=100, output="sos")
    twice = sosfiltfilt(sos4, sosfiltfilt(sos4, x, axis=0, padlen=25), axis=0, padlen=25)
    np.testing.assert_allclose(lowpass(x, 8, order=3, passes=4, rate=100), twice, atol=1e-12)


def test_one_section_is_scipys_filtfilt_bit_for_bit():
    """The filter of one second-order section (order=2) runs the extension's samples
    apart from the data, passing the filter's state on: scipy's filtfilt (odd
    extension, its initial conditions) to the last bit, for every padding from 1 frame
    to the run's length - 1, and through lowpass's whole-column path."""
    from scipy.signal import filtfilt

    from bmc_functions.markers.filtering import _filtfilt_rows
    rng = np.random.default_rng(29)
    for n in (2, 10, 11, 57, 1000):
        x = rng.normal(size=(3, n)) * [[1e-3], [1.0], [1e4]] + rng.normal(size=(3, 1)) * 50
        b, a = butter(2, rng.uniform(0.01, 0.9))
        for padlen in sorted({1, min(9, n - 1), n // 2, n - 1} - {0}):
            expected = filtfilt(b, a, x, axis=-1, padtype="odd", padlen=padlen)
            assert np.array_equal(_filtfilt_rows(b, a, x, padlen), expected), (n, padlen)
    x = np.cumsum(rng.normal(size=(300, 4)), axis=0)
    sos = butter(2, corrected_cutoff(8, 100), fs=100, output="sos")
    expected = filtfilt(sos[0, :3], sos[0, 3:], x.T, padtype="odd", padlen=25).T
    assert np.array_equal(lowpass(x, 8, rate=100), expected)


@pytest.mark.parametrize("values", [[1.0, np.inf], [-np.inf, 0.0], [1e101, 0.0],
                                    [np.nan, -1e101], [np.nan, np.inf], [np.nan, 2.0],
                                    [np.nan, np.nan], [0.0, 1e100], []])
def test_the_data_check_tells_nan_from_its_own_max_and_min(values):
    """check_finite_or_nan returns whether the data hold no NaN (read off the max and min
    it checks), which lowpass hands to _blocks so that it need not look again (the same
    runs); the errors: infinite values always, magnitudes beyond the limit unless
    max_abs=None, NaN where not allowed."""
    from bmc_functions._checks import MAX_MAGNITUDE, check_finite_or_nan
    from bmc_functions.markers.filtering import _blocks
    x = np.array(values, dtype=float).reshape(-1, 1)
    has_nan, infinite = bool(np.isnan(x).any()), bool(np.isinf(x).any())
    beyond = bool((np.abs(x[~np.isnan(x)]) > MAX_MAGNITUDE).any())
    for max_abs, refused in ((MAX_MAGNITUDE, infinite or beyond), (None, infinite)):
        if refused:
            match = "infinite values" if infinite else "magnitude up to"
            with pytest.raises(ValueError, match=match):
                check_finite_or_nan(x, "data", max_abs=max_abs)
            continue
        assert check_finite_or_nan(x, "data", max_abs=max_abs) is (not has_nan)
        if has_nan:
            with pytest.raises(ValueError, match="contains NaN values"):
                check_finite_or_nan(x, "data", allow_nan=False, max_abs=max_abs)
    if not (infinite or beyond):
        nan_free = check_finite_or_nan(x, "data")
        for got, expected in zip(_blocks(x, nan_free), _blocks(x)):
            assert np.array_equal(got, expected) and got.dtype == expected.dtype


def test_columns_without_a_gap_beside_columns_with_gaps_are_each_scipys():
    """Whole columns are filtered by slicing, the others run by run: both as scipy."""
    rng = np.random.default_rng(5)
    x = np.cumsum(rng.normal(size=(400, 5)), axis=0)
    x[100:110, 1] = np.nan
    x[:30, 3] = np.nan
    sos = butter(2, corrected_cutoff(8, 100), fs=100, output="sos")
    got = lowpass(x, 8, rate=100)
    for j in range(5):
        valid = np.flatnonzero(~np.isnan(x[:, j]))
        runs = np.split(valid, np.flatnonzero(np.diff(valid) > 1) + 1)
        for run in runs:
            expected = sosfiltfilt(sos, x[run, j], padtype="odd",
                                   padlen=min(25, len(run) - 1))
            np.testing.assert_allclose(got[run, j], expected, atol=1e-12)
    assert np.isnan(got).sum() == 40


@pytest.mark.parametrize("order, passes", [(2, 2), (4, 2), (2, 4)])
def test_sinusoids_come_out_with_the_gain_of_sosfreqz_and_no_lag(order, passes):
    rate, cutoff = 200.0, 10.0
    t = np.arange(4000) / rate
    middle = slice(1000, 3000)                       # far from the edges
    for f in (2.0, 6.0, 10.0, 14.0, 25.0):
        y = lowpass(np.cos(2 * np.pi * f * t), cutoff, order=order, passes=passes,
                    rate=rate)
        # least-squares amplitude and phase in the middle of the record
        basis = np.c_[np.cos(2 * np.pi * f * t), np.sin(2 * np.pi * f * t)][middle]
        (c, s), *_ = np.linalg.lstsq(basis, y[middle], rcond=None)
        assert np.hypot(c, s) == pytest.approx(
            combined_gain(cutoff, rate, order, passes, f)[0], abs=1e-6)
        assert abs(np.arctan2(s, c)) < 1e-6           # zero phase: no lag
    y = lowpass(np.cos(2 * np.pi * cutoff * t), cutoff, order=order, passes=passes, rate=rate)
    assert np.abs(y[middle]).max() == pytest.approx(1 / np.sqrt(2), abs=1e-3)


def test_gaps_stay_gaps_and_nothing_crosses_them():
    rng = np.random.default_rng(3)
    x = np.cumsum(rng.normal(size=(200, 3)), axis=0)
    x[60:75] = np.nan
    x[120:130, 1] = np.nan                              # a gap in one column only
    y = lowpass(x, 5, rate=100)
    np.testing.assert_array_equal(np.isnan(y), np.isnan(x))
    # each run is filtered as if it were alone
    np.testing.assert_allclose(y[:60], lowpass(x[:60], 5, rate=100), atol=1e-12)
    np.testing.assert_allclose(y[75:, 0], lowpass(x[75:, 0], 5, rate=100), atol=1e-12)
    np.testing.assert_allclose(y[130:, 1], lowpass(x[130:, 1], 5, rate=100), atol=1e-12)
    # changing the data after a gap leaves the run before it untouched
    x2 = x.copy()
    x2[75:] += 1000.0
    np.testing.assert_array_equal(lowpass(x2, 5, rate=100)[:60], y[:60])


def test_short_runs_are_left_unfiltered_with_one_warning():
    rng = np.random.default_rng(4)
    x = rng.normal(size=(100, 2))
    x[[10, 20, 30], :] = np.nan                          # runs of 9 frames (padding: 9)
    x[50, 0] = np.nan
    with pytest.warns(RuntimeWarning) as record:
        y = lowpass(x, 10, rate=100)
    assert len(record) == 1
    message = str(record[0].message)
    assert "4 run(s) of visible frames (36 values in all, in 2 of 2 columns)" in message
    assert "9 frames or shorter, too short for the filter (it needs more than 9): left " \
        "unfiltered" in message
    np.testing.assert_array_equal(y[11:20], x[11:20])
    assert not np.allclose(y[31:50], x[31:50])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lowpass(x[31:], 10, rate=100)                     # no short run: no warning


def test_a_line_and_a_constant_pass_unchanged_edges_included():
    t = np.arange(200) / 100
    x = np.c_[3.0 + 0 * t, 2.0 - 7.0 * t]
    np.testing.assert_allclose(lowpass(x, 4, rate=100), x, atol=1e-5)
    # with scipy's default padding (9 frames) the line's ends would be 0.014 off
    sos = butter(2, corrected_cutoff(4, 100), fs=100, output="sos")
    assert np.abs(sosfiltfilt(sos, x[:, 1]) - x[:, 1]).max() > 0.01
    # a run shorter than the wanted padding is padded with all it has: still close
    short = x[:30]
    np.testing.assert_allclose(lowpass(short, 4, rate=100), short, atol=2e-3)


def test_marker_dataframe_keeps_its_layout_and_attrs():
    walk = read_trc(ROOT / "data" / "markers" / "walk.trc")
    out = lowpass(walk, 6)
    assert isinstance(out, pd.DataFrame)
    assert out.index.equals(walk.index) and out.columns.equals(walk.columns)
    assert out.attrs == walk.attrs and out.attrs is not walk.attrs
    pd.testing.assert_frame_equal(out.isna(), walk.isna())
    expected = lowpass(walk.to_numpy(), 6, rate=walk.attrs["rate"])
    np.testing.assert_allclose(out.to_numpy(), expected)
    # the noise (0.5 mm) is reduced: differences from the filtered are about its size
    assert 0.2 < np.nanstd((walk - out).to_numpy()) < 1.0
    series = lowpass(walk["RTOE"]["x"], 6, rate=100)
    assert isinstance(series, pd.Series) and series.name == "x"
    np.testing.assert_allclose(series.to_numpy(), out["RTOE"]["x"].to_numpy())


# --------------------------------------------------------------------------- derivative


def test_derivative_is_exact_for_polynomials_it_should_be():
    t = np.arange(20) / 50
    x = 3 * t ** 2 - t + 2
    v = derivative(x, 50)
    np.testing.assert_allclose(v[1:-1], 6 * t[1:-1] - 1, atol=1e-9)   # central: exact
    np.testing.assert_allclose(v[[0, -1]], [(x[1] - x[0]) * 50, (x[-1] - x[-2]) * 50])
    np.testing.assert_allclose(derivative(x, 50, order=2), 6.0, atol=1e-8)


def test_derivative_respects_gaps_and_short_runs():
    t = np.arange(30) / 10.0
    x = np.c_[t ** 2, 2 * t]
    x[10] = np.nan
    x[12] = np.nan                                # frame 11 is a run of one frame
    v = derivative(x, 10)
    assert np.isnan(v[[10, 11, 12]]).all()
    np.testing.assert_allclose(v[:10, 1], 2.0)
    np.testing.assert_allclose(v[9, 0], (x[9, 0] - x[8, 0]) * 10)   # one-sided at the gap
    a = derivative(x, 10, order=2)
    assert np.isnan(a[10:13]).all()
    np.testing.assert_allclose(a[13:, 0], 2.0, atol=1e-9)
    walk = read_trc(ROOT / "data" / "markers" / "walk.trc")
    velocity = derivative(walk)
    pd.testing.assert_frame_equal(velocity.isna(), walk.isna())
    assert velocity.attrs["units"] == "mm/s" and walk.attrs["units"] == "mm"
    assert derivative(walk, order=2).attrs["units"] == "mm/s^2"


def test_known_derivatives_recovered_within_stated_error_after_filtering():
    """x(t) = 50 sin(2 pi 1.2 t) + 20 sin(2 pi 3 t + 0.5) mm at 100 Hz with white noise of
    0.5 mm: at the cut-off residual analysis suggests (7.0 Hz), the velocity is within 3 %
    and the acceleration within 7 % (RMS over the frames 0.2 s from the ends) of their
    RMS; unfiltered, the acceleration error is 220 %."""
    rate = 100.0
    t = np.arange(400) / rate
    w1, w2 = 2 * np.pi * 1.2, 2 * np.pi * 3
    x = 50 * np.sin(w1 * t) + 20 * np.sin(w2 * t + 0.5)
    v = 50 * w1 * np.cos(w1 * t) + 20 * w2 * np.cos(w2 * t + 0.5)
    a = -50 * w1 ** 2 * np.sin(w1 * t) - 20 * w2 ** 2 * np.sin(w2 * t + 0.5)
    noisy = x + np.random.default_rng(1977).normal(0, 0.5, t.size)

    def relative(estimate, truth):
        inner = slice(20, -20)
        return np.sqrt(np.mean((estimate - truth)[inner] ** 2) / np.mean(truth[inner] ** 2))

    cutoff = residual_analysis(noisy, rate=rate).cutoff
    assert 6.0 < cutoff < 8.0
    smooth = lowpass(noisy, cutoff, rate=rate)
    assert relative(derivative(smooth, rate), v) < 0.03
    assert relative(derivative(smooth, rate, order=2), a) < 0.07
    assert relative(derivative(noisy, rate, order=2), a) > 2.0
    assert relative(derivative(noisy, rate), v) > 3 * relative(derivative(smooth, rate), v)


def test_filtering_the_markers_improves_angular_velocity_and_acceleration():
    """A cluster of 4 markers swinging 0.8 rad at 1 Hz about z, noise 0.5 mm, 100 Hz.
    Measured (RMS error / RMS of the truth, frames 0.2 s from the ends): omega 19 % raw,
    about 3 % after a 6 Hz filter; angular acceleration about 250 % raw, 17 % at 6 Hz."""
    rate = 100.0
    t = np.arange(400) / rate
    cluster = np.array([[0.0, 0, 0], [100, 0, 0], [0, 80, 0], [30, 30, 60]])
    w0 = 2 * np.pi
    R = Rotation.from_rotvec(np.outer(0.8 * np.sin(w0 * t), [0, 0, 1.0])).as_matrix()
    omega = np.outer(0.8 * w0 * np.cos(w0 * t), [0, 0, 1.0])
    alpha = np.outer(-0.8 * w0 ** 2 * np.sin(w0 * t), [0, 0, 1.0])
    markers = np.einsum("fij,nj->fni", R, cluster) + [500, 900, 300]
    markers += np.random.default_rng(1977).normal(0, 0.5, markers.shape)

    def errors(points):
        R_fit, _, _ = svdt(cluster, points, order="row")
        w = angular_velocity(R_fit, rate)
        inner = slice(20, -20)
        rel = [np.sqrt(np.mean(np.sum((est - truth)[inner] ** 2, axis=1))
                       / np.mean(np.sum(truth[inner] ** 2, axis=1)))
               for est, truth in ((w, omega), (derivative(w, rate), alpha))]
        return rel

    raw_w, raw_a = errors(markers)
    filt_w, filt_a = errors(lowpass(markers, 6, rate=rate))
    assert 0.1 < raw_w < 0.3 and raw_a > 2.0
    assert filt_w < 0.04 and filt_a < 0.2


# --------------------------------------------------------------------------- residual analysis


def test_white_noise_intercept_matches_the_filters_frequency_response():
    """The noise line's intercept for white noise, predicted from sosfreqz (0.970 sigma
    with the defaults), against 20 records of 2000 samples."""
    rate = 100.0
    cutoffs = np.arange(1, 101) * 0.25
    predicted = []
    for fc in cutoffs:
        _, h = sosfreqz(butter(2, corrected_cutoff(fc, rate), fs=rate, output="sos"),
                        worN=20000, fs=rate)
        predicted.append(np.sqrt(np.mean((1 - np.abs(h) ** 2) ** 2)))
    upper = cutoffs >= 12.625
    slope, intercept = np.polyfit(cutoffs[upper], np.array(predicted)[upper], 1)
    assert intercept == pytest.approx(0.970, abs=0.001)
    noise = np.random.default_rng(5).normal(0, 2.0, (2000, 20))
    with pytest.warns(RuntimeWarning, match="no signal above the noise, 20 of them"):
        result = residual_analysis(noise, rate=rate)       # noise only: no cut-off
    assert np.isnan(result.cutoff).all()
    assert result.fit_from == pytest.approx(12.625)
    assert np.mean(result.noise) / 2.0 == pytest.approx(intercept, abs=0.02)
    np.testing.assert_allclose(np.mean(result.residuals, axis=1) / 2.0, predicted, atol=0.02)


def test_residual_curve_is_the_rms_difference_and_cutoff_meets_the_line():
    rate = 100.0
    t = np.arange(300) / rate
    x = np.c_[100 * np.sin(2 * np.pi * t), 40 * np.sin(2 * np.pi * 2.5 * t)]
    x = x + np.random.default_rng(2).normal(0, 1.0, x.shape)
    cutoffs = np.arange(1.0, 25.5, 0.5)
    result = residual_analysis(x, cutoffs, rate=rate, fit_from=12)
    np.testing.assert_array_equal(result.cutoffs, cutoffs)
    for i in (0, 10, 30):
        expected = np.sqrt(np.mean((x - lowpass(x, cutoffs[i], rate=rate)) ** 2, axis=0))
        np.testing.assert_allclose(result.residuals[i], expected)
    upper = cutoffs >= 12
    for j in range(2):
        slope, intercept = np.polyfit(cutoffs[upper], result.residuals[upper, j], 1)
        assert result.noise[j] == pytest.approx(intercept)
        assert result.slope[j] == pytest.approx(slope)
        fc = result.cutoff[j]
        k = np.searchsorted(cutoffs, fc)
        assert result.residuals[k - 1, j] > intercept >= result.residuals[k, j]
        crossing = np.interp(fc, cutoffs[k - 1:k + 1], result.residuals[k - 1:k + 1, j])
        assert crossing == pytest.approx(intercept)
    assert result.cutoff[1] > result.cutoff[0]      # the faster signal needs a higher one


def test_residual_analysis_of_a_trial_per_coordinate_and_per_marker():
    walk = read_trc(ROOT / "data" / "markers" / "walk.trc")[["RTOE", "RHEEL", "RTH3"]]
    walk.attrs = read_trc(ROOT / "data" / "markers" / "walk.trc").attrs
    by_coord = residual_analysis(walk)
    assert by_coord.residuals.columns.equals(walk.columns)
    assert by_coord.residuals.index[-1] == pytest.approx(25.0)
    assert list(by_coord.cutoff.index) == list(walk.columns)
    by_marker = residual_analysis(walk, by="marker")
    assert list(by_marker.residuals.columns) == ["RTOE", "RHEEL", "RTH3"]
    pooled = np.sqrt((by_coord.residuals["RTOE"] ** 2).mean(axis=1))
    np.testing.assert_allclose(by_marker.residuals["RTOE"], pooled)
    assert (by_marker.cutoff > 1).all() and (by_marker.cutoff < 25).all()
    array = residual_analysis(walk.to_numpy().reshape(len(walk), 3, 3), rate=100,
                              by="marker")
    np.testing.assert_allclose(array.cutoff, by_marker.cutoff.to_numpy())
    assert array.residuals.shape == (100, 3)


@pytest.mark.parametrize("name", ["plug_in_gait/Movement_trial.c3d",
                                  "force_plates/codamotion_gaitwands_20150204.c3d"])
def test_real_c3d_trials_with_gaps(name):
    """Real C3D files (shared data, skipped when absent): many gaps and short runs."""
    pytest.importorskip("ezc3d")
    path = SHARED_DATA / name
    if not path.exists():
        pytest.skip(f"{path} not found")
    from bmc_functions import read_c3d
    trial = read_c3d(path)
    with pytest.warns(RuntimeWarning, match=r"run\(s\) of visible frames .* left unfiltered"):
        smooth = lowpass(trial, 6)
    pd.testing.assert_frame_equal(smooth.isna(), trial.isna())
    assert smooth.attrs == trial.attrs
    with pytest.warns(RuntimeWarning, match=r"left out of the residuals"):
        result = residual_analysis(trial, by="marker")
    visible = [m for m in result.cutoff.index if trial[m].notna().to_numpy().sum() > 100]
    found = result.cutoff[visible]
    assert found.notna().all()
    # the noise lines of a modern system: a fraction of a millimetre
    assert (result.noise[visible] > 0).all() and result.noise[visible].median() < 1.0
    assert 5 < found.median() < 20


def test_residual_analysis_warns_when_no_cutoff_is_found():
    rate = 100.0
    x = np.c_[np.random.default_rng(0).normal(size=500), np.full(500, np.nan)]
    with pytest.warns(RuntimeWarning, match=r"no cut-off found for 1 of 2 columns"):
        result = residual_analysis(x, rate=rate, cutoffs=np.arange(20, 30.0))
    assert np.isnan(result.cutoff).all()


def test_plot_residual_analysis_draws_the_curves_and_the_cutoffs():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from bmc_functions.plotting import plot_residual_analysis

    walk = read_trc(ROOT / "data" / "markers" / "walk.trc")[["RTOE", "RHEEL"]]
    walk.attrs = {"rate": 100.0}
    result = residual_analysis(walk, by="marker")
    ax = plot_residual_analysis(result, ["RTOE"])
    x, y = ax.lines[0].get_data()
    np.testing.assert_allclose(y, result.residuals["RTOE"])
    assert ax.lines[3].get_xdata()[0] == pytest.approx(result.cutoff["RTOE"])
    with pytest.raises(ValueError, match=r"columns: \['LTOE'\] are not in the result"):
        plot_residual_analysis(result, ["LTOE"])
    plt.close("all")


# --------------------------------------------------------------------------- bad input


X = np.zeros((50, 3))


@pytest.mark.parametrize("call, error, message", [
    (lambda: lowpass(X, 50, rate=100), ValueError,
     r"cutoff must be below the Nyquist frequency, half the sampling rate \(50 Hz at 100 "
     r"Hz\); got 50 Hz"),
    (lambda: lowpass(X, 80, rate=100), ValueError, r"cutoff must be below the Nyquist"),
    (lambda: lowpass(X, 0, rate=100), ValueError, r"cutoff must be a positive number; got 0"),
    (lambda: lowpass(X, -5, rate=100), ValueError, r"cutoff must be a positive number"),
    (lambda: lowpass(X, np.nan, rate=100), ValueError, r"cutoff contains NaN"),
    (lambda: lowpass(X, [5, 6], rate=100), ValueError, r"cutoff must be a single number"),
    (lambda: lowpass(X, "6", rate=100), TypeError, r"cutoff must be a numeric array"),
    (lambda: lowpass(X, True, rate=100), TypeError, r"cutoff must be a numeric array; got "
     r"booleans"),
    (lambda: lowpass(X, 6, rate=100, order=0), ValueError,
     r"order must be a whole number from 1 to 20 .*; got 0"),
    (lambda: lowpass(X, 6, rate=100, order=-2), ValueError, r"order must be a whole number"),
    (lambda: lowpass(X, 6, rate=100, order=MAX_ORDER + 1), ValueError, r"from 1 to 20"),
    (lambda: lowpass(X, 6, rate=100, order=2.5), TypeError,
     r"order must be a whole number .*; got 2.5 \(float\)"),
    (lambda: lowpass(X, 6, rate=100, order=True), TypeError, r"order must be a whole number"),
    (lambda: lowpass(X, 6, rate=100, passes=3), ValueError,
     r"passes must be an even number \(2, 4, ...\): a zero-lag filter runs forwards and "
     r"backwards equally often; got 3"),
    (lambda: lowpass(X, 6, rate=100, passes=1), ValueError, r"passes must be a whole number "
     r"from 2 to 20"),
    (lambda: lowpass(X, 6, rate=100, passes=0), ValueError, r"passes must be a whole number"),
    (lambda: lowpass(X, 6, rate=100, passes=MAX_PASSES + 2), ValueError, r"from 2 to 20"),
    (lambda: lowpass(X, 6, rate=100, passes="2"), TypeError, r"passes must be a whole number"),
    (lambda: lowpass(X, 6), ValueError, r"rate: give the sampling rate in Hz"),
    (lambda: lowpass(X, 6, rate=0), ValueError, r"rate must be a positive number; got 0"),
    (lambda: lowpass(X, 6, rate=-100), ValueError, r"rate must be a positive number"),
    (lambda: lowpass(X, 6, rate=np.inf), ValueError, r"rate contains infinite values"),
    (lambda: lowpass(X, 6, rate="100"), TypeError, r"rate must be a numeric array"),
    (lambda: lowpass(X, 6, rate=True), TypeError, r"rate must be a numeric array; got booleans"),
    (lambda: lowpass(np.array([1.0, np.inf]), 6, rate=100), ValueError,
     r"data contains infinite values"),
    (lambda: lowpass(np.array(["a", "b"]), 6, rate=100), TypeError,
     r"data must be a numeric array"),
    (lambda: lowpass(3.0, 6, rate=100), ValueError, r"data must have frames on the first axis"),
    (lambda: lowpass(None, 6, rate=100), TypeError, r"data must be a numeric array"),
    (lambda: corrected_cutoff(6, 100, passes=5), ValueError, r"passes must be an even number"),
    (lambda: corrected_cutoff(60, 100), ValueError, r"cutoff must be below the Nyquist"),
    (lambda: derivative(X, 100, order=3), ValueError,
     r"order must be 1 \(velocity\) or 2 \(acceleration\); got 3"),
    (lambda: derivative(X, 100, order=True), ValueError, r"order must be 1"),
    (lambda: derivative(X), ValueError, r"rate: give the sampling rate"),
    (lambda: residual_analysis(X, rate=100, cutoffs=[1, 2]), ValueError,
     r"cutoffs must be a vector of at least 3 frequencies \(Hz\); got shape \(2,\)"),
    (lambda: residual_analysis(X, rate=100, cutoffs=[3, 2, 1]), ValueError,
     r"cutoffs must be increasing"),
    (lambda: residual_analysis(X, rate=100, cutoffs=[1, 2, 60]), ValueError,
     r"cutoffs must be below the Nyquist frequency"),
    (lambda: residual_analysis(X, rate=100, cutoffs=[0, 1, 2]), ValueError,
     r"cutoffs must be a positive number"),
    (lambda: residual_analysis(X, rate=100, cutoffs=[1, np.nan, 2]), ValueError,
     r"cutoffs contains NaN"),
    (lambda: residual_analysis(X, rate=100, cutoffs=np.linspace(1, 40, 1001)), ValueError,
     r"cutoffs: at most 1000 cut-offs; got 1001"),
    (lambda: residual_analysis(X, rate=100, fit_from=30), ValueError,
     r"fit_from must leave at least 2 tested cut-offs"),
    (lambda: residual_analysis(X, rate=100, by="axis"), ValueError,
     r"by must be 'coordinate' or 'marker'; got 'axis'"),
    (lambda: residual_analysis(np.zeros((50, 4)), rate=100, by="marker"), ValueError,
     r"by='marker' needs data of shape \(frames, ..., 3\)"),
    (lambda: residual_analysis(pd.DataFrame(X), rate=100, by="marker"), ValueError,
     r"by='marker' needs \(marker, coord\) columns"),
])
def test_bad_input_raises_a_clear_error(call, error, message):
    with pytest.raises(error, match=message):
        call()


def test_empty_data_give_empty_results():
    for shape in [(0, 3), (20, 0), (0, 4, 3)]:
        data = np.zeros(shape)
        assert lowpass(data, 6, rate=100).shape == shape
        assert derivative(data, 100).shape == shape
        assert np.shape(residual_analysis(data, rate=100).cutoff) == shape[1:]


def test_rate_given_twice_must_agree():
    walk = read_trc(ROOT / "data" / "markers" / "walk.trc")
    with pytest.raises(ValueError, match=r"rate: got rate=120 Hz but data.attrs\['rate'\] "
                                         r"is 100 Hz"):
        lowpass(walk, 6, rate=120)
    pd.testing.assert_frame_equal(lowpass(walk, 6, rate=100), lowpass(walk, 6))
    with pytest.raises(ValueError, match=r"cutoff must be below the Nyquist frequency, half "
                                         r"the sampling rate \(50 Hz at 100 Hz\)"):
        lowpass(walk, 55)


# --- adversarial pass, round 2 (tools/adversarial_pass_round2.py) ----------------------------

def test_many_runs_are_filtered_as_each_run_alone_and_fast():
    """Flickering markers (1 % random dropouts, each column its own gaps): the result is
    that of filtering each run with scipy alone, and 200,000 frames x 60 columns take
    seconds (one call per run length, not per run; it took minutes)."""
    import time
    rng = np.random.default_rng(11)
    small = rng.normal(size=(3000, 4))
    small[rng.random(small.shape) < 0.01] = np.nan
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        got = lowpass(small, 6, rate=200)
    sos = butter(2, corrected_cutoff(6, 200), fs=200, output="sos")
    for j in range(small.shape[1]):
        valid = np.r_[0, ~np.isnan(small[:, j]), 0]
        starts = np.flatnonzero(np.diff(valid) == 1)
        stops = np.flatnonzero(np.diff(valid) == -1)
        for a, b in zip(starts, stops):
            if b - a > 9:
                expected = sosfiltfilt(sos, small[a:b, j], padtype="odd",
                                       padlen=min(int(np.ceil(2 * 200 / 6)), b - a - 1))
                np.testing.assert_allclose(got[a:b, j], expected, atol=1e-12)
            else:
                np.testing.assert_array_equal(got[a:b, j], small[a:b, j])
    big = rng.normal(size=(200_000, 60))
    big[rng.random(big.shape) < 0.01] = np.nan
    start = time.perf_counter()
    with pytest.warns(RuntimeWarning, match="too short"):
        lowpass(big, 6, rate=200)
    assert time.perf_counter() - start < 15


def test_a_derivative_of_many_runs_is_each_run_alone():
    rng = np.random.default_rng(12)
    x = np.cumsum(rng.normal(size=(500, 3)), axis=0)
    x[rng.random(x.shape) < 0.05] = np.nan
    got = derivative(x, 100)
    for j in range(3):
        valid = np.r_[0, ~np.isnan(x[:, j]), 0]
        for a, b in zip(np.flatnonzero(np.diff(valid) == 1),
                        np.flatnonzero(np.diff(valid) == -1)):
            if b - a >= 2:
                np.testing.assert_allclose(got[a:b, j], np.gradient(x[a:b, j], 0.01))
            else:
                assert np.isnan(got[a:b, j]).all()


def test_a_trial_with_its_gap_rows_dropped_is_refused():
    """trial.dropna() joins the frames on either side of a gap: the filter and the
    derivative would run across it as if no time had passed."""
    t = np.arange(300) / 100
    df = pd.DataFrame({"x": np.sin(t)}, index=t)
    df.attrs["rate"] = 100.0
    dropped = df.drop(df.index[100:130])
    for function in (lambda d: lowpass(d, 6), derivative):
        with pytest.raises(ValueError, match=r"data.index \(time\) skips rows: 1 step.*"
                                             r"dropna"):
            function(dropped)


def test_a_rate_that_contradicts_the_time_index_is_refused():
    t = np.arange(300) / 100
    df = pd.DataFrame({"x": np.sin(t)}, index=t)
    df.attrs["rate"] = 50.0
    with pytest.raises(ValueError, match=r"rate: the sampling rate is 50 Hz but data.index "
                                         r"\(time\) steps by 0.01"):
        lowpass(df, 6)
    df.index = t * 1000                       # an index in ms agrees with 100 Hz
    df.attrs["rate"] = 100.0
    assert np.isfinite(lowpass(df, 6).to_numpy()).all()


def test_the_rate_of_a_time_indexed_dataframe_without_attrs_comes_from_its_index():
    """The angles of the pipeline carry their time, not attrs['rate']."""
    t = np.arange(200) / 100
    angles = pd.DataFrame({"knee": t ** 2}, index=t)
    np.testing.assert_allclose(derivative(angles)["knee"].to_numpy()[1:-1], 2 * t[1:-1])
    with pytest.raises(ValueError, match="rate: give the sampling rate"):
        derivative(pd.DataFrame({"knee": t ** 2}))          # frame numbers: no rate


def test_residual_analysis_finds_no_cutoff_without_signal():
    """A constant (residuals of rounding error only) and white noise have no cut-off that
    separates signal from noise: NaN, with the warning, not a number."""
    for data in (np.ones(500), np.random.default_rng(4).normal(size=2000)):
        with pytest.warns(RuntimeWarning, match=r"no cut-off found for 1 of 1 columns.*"
                                                r"no signal above the noise, 1 of them"):
            result = residual_analysis(data, rate=100)
        assert np.isnan(result.cutoff)


def test_plot_residual_analysis_refuses_another_result():
    from bmc_functions.plotting import plot_residual_analysis
    with pytest.raises(TypeError, match="result must be what residual_analysis returns"):
        plot_residual_analysis(pd.DataFrame({"x": [1.0, 2.0]}))


def test_a_time_column_rounded_to_milliseconds_agrees_with_its_rate():
    """A TRC's Time column at 150 Hz written with 3 decimals steps by 6 and 7 ms (median
    7 ms: 143 Hz); the mean step is the rate's. No false alarm."""
    t = np.round(np.arange(300) / 150, 3)
    df = pd.DataFrame({"x": np.sin(t)}, index=t)
    df.attrs["rate"] = 150.0
    assert np.isfinite(lowpass(df, 6).to_numpy()).all()
    real = ROOT.parent / "shared" / "data" / "walk.trc"
    if real.exists():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            trial = read_trc(real)
        assert lowpass(trial, 6).shape == trial.shape


def test_a_rate_from_an_index_in_ms_is_refused():
    t = np.arange(200) / 100
    angles = pd.DataFrame({"knee": t ** 2}, index=t * 1000)      # ms, no attrs['rate']
    with pytest.raises(ValueError, match=r"rate: data.attrs has no 'rate' and data.index "
                                         r"steps by 10 .*ms or frame numbers"):
        derivative(angles)


def test_residual_analysis_by_marker_names_the_columns_it_got():
    df = pd.DataFrame(np.zeros((50, 2)), columns=pd.MultiIndex.from_tuples(
        [("knee", "right", "flexion"), ("hip", "right", "flexion")]))
    with pytest.raises(ValueError, match=r"got 3-level columns, e.g. \('knee'"):
        residual_analysis(df, rate=100, by="marker")


def test_a_cutoff_whose_period_exceeds_every_run_warns():
    t = np.arange(110) / 100
    with pytest.warns(RuntimeWarning, match=r"every run of visible frames is shorter than "
                                            r"one period of the cut-off \(110 frames"):
        lowpass(np.sin(t), 0.01, rate=100)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lowpass(np.sin(t), 1.0, rate=100)                # one period: 100 frames, fine


def test_plot_residual_analysis_names_columns_an_array_result_lacks():
    """An array result's columns are numbers: 5 of 2, or a name, was a raw IndexError."""
    from bmc_functions.plotting import plot_residual_analysis
    t = np.arange(500) / 100
    x = np.c_[np.sin(t), np.cos(t)] + 0.01 * np.random.default_rng(0).normal(size=(500, 2))
    result = residual_analysis(x, rate=100)
    for columns in ([5], "a", [-1]):
        with pytest.raises(ValueError, match=r"columns: .* are not column numbers of the "
                                             r"result; it has 2 \(0 to 1\)"):
            plot_residual_analysis(result, columns)


@pytest.mark.parametrize("layout", ["C", "F"])
def test_derivative_has_numpy_gradients_numbers_bit_for_bit(layout):
    """derivative writes numpy.gradient's formulas (order 1, edge_order=1) and the second
    difference (order 2) in place: the same numbers, bit for bit (signs of zero too), on
    every run of a trial with gaps (runs of 2, 3 and more frames) and on a gapless one."""
    from bmc_functions import derivative
    rng = np.random.default_rng(11)
    x = np.asarray(rng.normal(size=(400, 4)) * [1e-3, 1.0, 1e3, 0.0], order=layout)
    gapped = x.copy()
    gapped[[2, 5, 9, 100, 101], 0] = np.nan                  # runs of 2 and 3 frames
    gapped[200:230, 2] = np.nan
    for data in (x, gapped):
        for order in (1, 2):
            got = derivative(data, 150.0, order=order)
            expected = np.full_like(data, np.nan)
            for column in range(data.shape[1]):
                seen = ~np.isnan(data[:, column])
                edges = np.flatnonzero(np.diff(np.r_[0, seen.astype(int), 0]))
                for a, b in zip(edges[::2], edges[1::2]):
                    run = data[a:b, column]
                    if b - a < order + 1:
                        continue
                    if order == 1:
                        expected[a:b, column] = np.gradient(run, 1 / 150.0, edge_order=1)
                    else:
                        second = (run[2:] - 2 * run[1:-1] + run[:-2]) * 150.0 ** 2
                        expected[a:b, column] = np.r_[second[0], second, second[-1]]
            assert np.array_equal(got, expected, equal_nan=True), order
            assert np.array_equal(np.signbit(got), np.signbit(expected)), order
