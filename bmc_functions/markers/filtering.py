r"""Low-pass filtering and differentiation of marker trajectories, with gaps.

Marker coordinates carry measurement noise that differentiation amplifies: a velocity or
an angular velocity is only as good as the filter applied before it. This module holds the
zero-lag Butterworth low-pass filter biomechanics uses (:func:`lowpass`), with the cut-off
corrected for the number of passes so that the filter does what its cut-off says
(:func:`corrected_cutoff`); Winter's residual analysis to choose that cut-off
(:func:`residual_analysis`); and a NaN-aware finite-difference derivative
(:func:`derivative`).

All of them work on the DataFrames of :func:`~bmc_functions.read_trc` and
:func:`~bmc_functions.read_c3d` (the rate from ``df.attrs['rate']``) and on arrays with
frames on the first axis and a ``rate``. A gap (NaN) stays a gap: each run of visible
frames is filtered or differentiated on its own, so nothing is smeared across a gap.

Filtered angular velocity in one call (a recipe; :func:`~bmc_functions.angular_velocity`
itself differentiates what it is given)::

    smooth = lowpass(trial[cluster], 6)          # trial from read_trc, cluster: labels
    points = smooth.to_numpy().reshape(len(smooth), -1, 3)
    R, t, _ = svdt(reference, points, order="row")
    omega = angular_velocity(R, smooth.attrs["rate"])
    alpha = derivative(omega, smooth.attrs["rate"])   # angular acceleration

or, with the lower-limb pipeline, ``model.track(lowpass(trial, 6))``: every angle, frame
and landmark then comes from the filtered markers.
"""

import copy
from typing import NamedTuple

import numpy as np
import pandas as pd
from scipy.signal import butter, filtfilt, lfilter, lfilter_zi, sosfiltfilt

from .._checks import (as_float_array, check_choice, check_finite_or_nan, check_number,
                       check_scalar, warn)

#: Largest filter order accepted: beyond it scipy's design of the Butterworth filter
#: loses precision (its gain overflows near order 500), and no biomechanics protocol
#: uses more than a few (Winter: 2 per pass).
MAX_ORDER = 20

#: Largest number of passes accepted (each forwards-backwards pair counts 2).
MAX_PASSES = 20

#: A rate (Hz) taken from a DataFrame's time index must be at least this; a slower one
#: means an index in ms or frame numbers (100 Hz in ms steps by 10: 0.1 Hz).
MIN_INDEX_RATE = 10.0

#: Number of cut-offs tested by default in :func:`residual_analysis`.
N_CUTOFFS = 100

#: :func:`residual_analysis` finds no cut-off where the residual at the lowest tested
#: cut-off is at most this many times the noise estimate: the data hold no signal that
#: stands out of the noise (white noise gives about 1.03, since the noise line's intercept
#: is 0.97 sigma; a movement sampled for residual analysis gives tens to thousands).
MIN_SIGNAL = 1.2

#: Most cut-offs :func:`residual_analysis` accepts (each filters the whole trial once).
MAX_CUTOFFS = 1000


# --------------------------------------------------------------------------- checks


def _check_order(order):
    return check_scalar(order, "order", f"a whole number from 1 to {MAX_ORDER} (the "
                        f"Butterworth filter's order per pass)", minimum=1, maximum=MAX_ORDER,
                        integer=True)


def _check_passes(passes):
    passes = check_scalar(passes, "passes", f"a whole number from 2 to {MAX_PASSES} (an "
                          f"even number: the filter runs forwards and backwards equally "
                          f"often, so 2, 4, ...)", minimum=2, maximum=MAX_PASSES,
                          integer=True)
    if passes % 2:
        raise ValueError(f"passes must be an even number (2, 4, ...): a zero-lag filter "
                         f"runs forwards and backwards equally often; got {passes}")
    return passes


def _check_cutoff(cutoff, rate, name="cutoff"):
    cutoff = check_number(cutoff, name, positive=True)
    if cutoff >= 0.5 * rate:
        raise ValueError(f"{name} must be below the Nyquist frequency, half the sampling "
                         f"rate ({0.5 * rate:g} Hz at {rate:g} Hz); got {cutoff:g} Hz")
    return cutoff


def _index_step(data):
    """The mean step of a DataFrame's or Series's time index (a float index), checked
    for rows left out (a step of more than 1.5 times the median: ``dropna()``); None for
    an index of frame numbers, labels or fewer than 3 rows."""
    index = getattr(data, "index", None)
    if index is None or len(index) < 3 or not pd.api.types.is_float_dtype(index.dtype):
        return None
    steps = np.diff(index.to_numpy(dtype=float))
    median = float(np.median(steps))
    if not np.isfinite(median) or median <= 0:
        return None
    jumps = np.flatnonzero(steps > 1.5 * median)
    if jumps.size:
        raise ValueError(f"data.index (time) skips rows: {jumps.size} step(s) longer than "
                         f"1.5 times the usual {median:.4g} (the first after "
                         f"{index[jumps[0]]:.4g}); frames were left out (dropna?), so the "
                         f"filter would join data across them. Keep missing frames as NaN "
                         f"rows (e.g. data.reindex(...)).")
    # the mean step: a Time column rounded to 1 ms steps by 6 and 7 ms at 150 Hz
    return float(steps.mean())


def _check_uniform(data):
    """Refuse a DataFrame's or Series's time index (a float index of 3 rows or more) whose
    steps differ from their mean by more than the index's rounding: the differences of
    :func:`derivative` assume one step, 1 / rate.

    The rounding is the resolution the times are written with (1 ms for a Time column of
    3 decimals: its steps at 150 Hz are 6 and 7 ms), found as the fewest decimals (0 to
    7) that hold every time; times at full precision may deviate by 1e-6 of the step.
    """
    if not isinstance(data, (pd.DataFrame, pd.Series)) or len(data.index) < 3 or \
            not pd.api.types.is_float_dtype(data.index.dtype):
        return
    time = data.index.to_numpy(dtype=float)
    steps = np.diff(time)
    mean = float(steps.mean())
    resolution = next((10.0 ** -d for d in range(8)
                       if np.all(np.abs(time * 10.0 ** d - np.round(time * 10.0 ** d))
                                 <= 1e-6)), 0.0)
    deviation = np.abs(steps - mean)
    allowed = max(resolution, 1e-6 * mean) * (1 + 1e-6)
    if deviation.max() > allowed:
        k = int(np.argmax(deviation))
        raise ValueError(f"data.index (time) is not uniform: its steps range from "
                         f"{steps.min():.6g} to {steps.max():.6g} (mean {mean:.6g}; step "
                         f"{k + 1}, after {time[k]:.6g}, is {steps[k]:.6g}), beyond the "
                         f"{allowed:.3g} its rounding explains; the differences "
                         "assume one step, 1/rate. Resample the data to a "
                         "uniform time first (e.g. numpy.interp on a regular grid)")


def _rate_of(data, rate):
    """The sampling rate: `rate`, or a DataFrame's ``attrs['rate']`` (they must agree),
    or the rate of a DataFrame's time index; checked against that index."""
    stored = getattr(data, "attrs", {}).get("rate") if isinstance(
        data, (pd.DataFrame, pd.Series)) else None
    step = _index_step(data) if isinstance(data, (pd.DataFrame, pd.Series)) else None
    if rate is None:
        if stored is None:
            if step is not None:                   # a time index (s): its rate
                if 1.0 / step < MIN_INDEX_RATE:
                    raise ValueError(f"rate: data.attrs has no 'rate' and data.index "
                                     f"steps by {step:.4g} ({1 / step:.3g} Hz if in s): is "
                                     f"the index in ms or frame numbers? Give rate=... (Hz)")
                return check_number(1.0 / step, "rate", positive=True)
            raise ValueError("rate: give the sampling rate in Hz (rate=...); the data "
                             "carry none (a DataFrame from read_trc or read_c3d has it in "
                             "attrs['rate'])")
        rate = check_number(stored, "rate", positive=True)
    else:
        rate = check_number(rate, "rate", positive=True)
        if stored is not None and not np.isclose(float(stored), rate, rtol=1e-9, atol=0):
            raise ValueError(f"rate: got rate={rate:g} Hz but data.attrs['rate'] is "
                             f"{float(stored):g} Hz; give one or make them agree")
    if step is not None:
        ratio = step * rate              # 1 for an index in s, 1000 for one in ms
        if not (np.isclose(ratio, 1, rtol=0.02) or np.isclose(ratio, 1000, rtol=0.02)):
            raise ValueError(f"rate: the sampling rate is {rate:g} Hz but data.index "
                             f"(time) steps by {step:.4g} ({1 / step:.4g} Hz if in s): "
                             f"which is right? Correct attrs['rate'] or the index")
    return rate


def _as_columns(data):
    """(values as a float array (frames, columns), a function that rebuilds the input's
    type and shape from such an array, whether the values hold no NaN)."""
    if isinstance(data, (pd.DataFrame, pd.Series)):
        values = as_float_array(data, "data")
        nan_free = check_finite_or_nan(values, "data")

        def rebuild(array):
            if isinstance(data, pd.Series):
                out = pd.Series(array[:, 0], index=data.index, name=data.name)
            else:
                out = pd.DataFrame(array, index=data.index, columns=data.columns)
            out.attrs = copy.deepcopy(data.attrs)
            return out
        return (values.reshape(len(values), int(np.prod(values.shape[1:]))), rebuild,
                nan_free)
    values = as_float_array(data, "data")
    if values.ndim == 0:
        raise ValueError("data must have frames on the first axis (shape (frames, ...)); "
                         "got a single number")
    nan_free = check_finite_or_nan(values, "data")
    shape = values.shape
    return (values.reshape(shape[0], int(np.prod(shape[1:]))),
            lambda array: array.reshape(shape), nan_free)


class _Runs(NamedTuple):
    """Every run of visible frames of every column: (column, start, length) arrays."""

    column: np.ndarray
    start: np.ndarray
    length: np.ndarray


def _blocks(values, nan_free=None):
    """The runs of visible (not NaN) frames of each column of `values`, as :class:`_Runs`
    (vectorized: no loop over frames or columns); `nan_free` (from :func:`_as_columns`)
    if known."""
    if nan_free:
        gapless = True
    else:
        with np.errstate(over="ignore", invalid="ignore"):
            gapless = not values.size or np.isfinite(np.sum(values))   # NaN: a NaN sum
    if gapless:                                         # no gap: one run per column
        columns = values.shape[1]
        return _Runs(np.arange(columns), np.zeros(columns, dtype=np.intp),
                     np.full(columns, values.shape[0], dtype=np.intp))
    valid = ~np.isnan(values)
    padded = np.zeros((values.shape[0] + 2, values.shape[1]), dtype=np.int8)
    padded[1:-1] = valid
    edges = np.diff(padded, axis=0).T                   # (columns, frames + 1)
    column, start = np.nonzero(edges == 1)              # sorted by column, then frame
    _, stop = np.nonzero(edges == -1)
    return _Runs(column, start, stop - start)


def _same_length(runs, keep):
    """Yield (length, frame indices (n, length), column indices (n, 1)) for the runs
    selected by the boolean `keep`, grouped by length: one vectorized call per length
    instead of one per run (a trial with flickering markers has thousands of runs)."""
    for length in np.unique(runs.length[keep]):
        pick = keep & (runs.length == length)
        frames = runs.start[pick][:, None] + np.arange(length)
        yield int(length), frames, runs.column[pick][:, None]


# --------------------------------------------------------------------------- the filter


def corrected_cutoff(cutoff, rate, *, order=2, passes=2):
    r"""The cut-off to design a Butterworth filter with, so that `passes` passes of it
    attenuate `cutoff` by 3 dB.

    Parameters
    ----------
    cutoff : float
        The wanted cut-off (Hz): the frequency at which the whole filter (all passes
        together) passes :math:`1/\sqrt 2` of the amplitude (−3 dB). Below ``rate / 2``.
    rate : float
        Sampling rate (Hz).
    order : int, keyword-only
        Order of the Butterworth filter of one pass (1 to :data:`MAX_ORDER`), default 2.
    passes : int, keyword-only
        Number of passes through the data, an even number (a forwards-backwards filter
        makes 2), default 2.

    Returns
    -------
    float
        The design cut-off (Hz), above `cutoff` and below ``rate / 2``.

    Raises
    ------
    ValueError
        If `cutoff` is not positive or not below ``rate / 2``, if `rate` is not positive,
        if `order` or `passes` is not a whole number in its range, or `passes` is odd.

    Notes
    -----
    scipy's digital Butterworth filter of order :math:`N` and cut-off :math:`f_c` (made
    from the analogue one by the bilinear transform, with the cut-off pre-warped) has
    the gain

    .. math:: |H(f)|^2 = \frac{1}{1 + \left(\tan(\pi f/f_s) / \tan(\pi f_c/f_s)\right)^{2N}}

    at frequency :math:`f` for a sampling rate :math:`f_s`. :math:`n` passes multiply the
    amplitude by :math:`|H|^n`. The combined gain is :math:`1/\sqrt 2` at :math:`f_0` when
    :math:`(1 + r^{2N})^{n/2} = \sqrt 2`, with :math:`r = \tan(\pi f_0/f_s) / \tan(\pi
    f_c/f_s)`, that is :math:`r = C = (2^{1/n} - 1)^{1/(2N)}`, and

    .. math:: f_c = \frac{f_s}{\pi}\arctan\!\left(\frac{\tan(\pi f_0/f_s)}{C}\right).

    For :math:`N = 2, n = 2` (Winter's filter), :math:`C = (\sqrt 2 - 1)^{1/4} = 0.802`;
    for 4 passes :math:`C = 0.6`. The correction factor is Robertson & Dowling's (2003)
    :math:`C` with their :math:`n` (the number of passes) and the exponent
    :math:`1/(2N)` for an order-:math:`N` filter; it is applied to the pre-warped
    frequency, so the design cut-off stays below the Nyquist frequency for every
    `cutoff` below it (:math:`f_0 / C` need not).

    References
    ----------
    .. [1] Robertson DGE, Dowling JJ (2003) Design and responses of Butterworth and
       critically damped digital filters. Journal of Electromyography and Kinesiology
       13:569-573.
    .. [2] Winter DA (2009) Biomechanics and Motor Control of Human Movement, 4th ed.
       Wiley, ch. 2-3 (signal processing; data smoothing in kinematics).

    Examples
    --------
    >>> from bmc_functions import corrected_cutoff
    >>> print(round(corrected_cutoff(6, 150), 3))          # 6 Hz wanted, 150 Hz data
    7.457
    >>> print(round(corrected_cutoff(6, 150, passes=4), 3))
    9.036
    """
    rate = check_number(rate, "rate", positive=True)
    cutoff = _check_cutoff(cutoff, rate)
    order, passes = _check_order(order), _check_passes(passes)
    correction = (2.0 ** (1.0 / passes) - 1.0) ** (1.0 / (2 * order))     # C of the Notes
    return float(rate / np.pi * np.arctan(np.tan(np.pi * cutoff / rate) / correction))


def _design(cutoff, rate, order, passes):
    """Second-order sections of one pass, the shortest run that is filtered minus one
    (scipy's default padding), and the padding wanted (two periods of the cut-off)."""
    sos = butter(order, corrected_cutoff(cutoff, rate, order=order, passes=passes),
                 fs=rate, output="sos")
    shortest = default_padding(sos)
    return sos, shortest, max(shortest, int(np.ceil(2 * rate / cutoff)))


def default_padding(sos):
    """scipy's default padding of :func:`scipy.signal.sosfiltfilt` for the second-order
    sections `sos` (frames): 3 * (2 * sections + 1 - trailing zeros); 9 for a
    second-order Butterworth filter. A run of visible frames this long or shorter is not
    filtered."""
    zeros = min(int((sos[:, 2] == 0).sum()), int((sos[:, 5] == 0).sum()))
    return 3 * (2 * len(sos) + 1 - zeros)


def filter_runs(values, sos, *, padlen=None, passes=2):
    """Zero-lag filter of each run of visible frames of each column: the step of
    :func:`lowpass` after the design, for a caller that designs its own filter.

    Parameters
    ----------
    values : ndarray, shape (frames, columns)
        Floats, NaN for missing frames.
    sos : ndarray, shape (sections, 6)
        The second-order sections of one pass (:func:`scipy.signal.butter` with
        ``output='sos'``), used as given.
    padlen : int, optional
        Frames of odd extension at each end of a run (at most its length - 1); default
        and minimum :func:`default_padding` of `sos`.
    passes : int, optional
        Passes through the data, even (each pair one :func:`scipy.signal.sosfiltfilt`).

    Returns
    -------
    filtered : ndarray, shape (frames, columns)
        `values` with each run longer than :func:`default_padding` frames filtered;
        shorter runs keep their values, gaps stay NaN.
    done : ndarray of bool, shape (frames, columns)
        Where `filtered` was filtered.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import butter, filtfilt, sosfiltfilt
    >>> from bmc_functions.markers.filtering import filter_runs
    >>> x = np.sin(np.arange(40) / 3.0)[:, None]
    >>> x[20:22] = np.nan                        # two runs: frames 0-19 and 22-39
    >>> sos = butter(2, 10, fs=100, output='sos')
    >>> filtered, done = filter_runs(x, sos)
    >>> bool(np.allclose(filtered[:20, 0], sosfiltfilt(sos, x[:20, 0], padlen=9)))
    True
    >>> print(done[:, 0].sum(), np.isnan(filtered).sum())
    38 2
    """
    shortest = default_padding(sos)
    wanted = shortest if padlen is None else max(shortest, int(padlen))
    filtered, done, _ = _filter_values(values, _blocks(values), sos, shortest, wanted,
                                       passes)
    return filtered, done


def _zero_lag(sos, rows, padlen):
    """:func:`scipy.signal.sosfiltfilt` of the rows of `rows` (odd extension); for one
    second-order section (``order=2``, the default) :func:`scipy.signal.filtfilt` with
    the section's own coefficients: the same filter, extension and initial conditions
    in fewer passes over memory (equal within 1e-13 of the data's scale)."""
    if len(sos) == 1:
        return _filtfilt_rows(sos[0, :3], sos[0, 3:], rows, padlen)
    return sosfiltfilt(sos, rows, axis=-1, padtype="odd", padlen=padlen)


def _filtfilt_rows(b, a, rows, padlen):
    """:func:`scipy.signal.filtfilt` (``padtype='odd'``) of the rows of `rows`, the
    same numbers bit for bit, without its extended copy of the data: the extension's
    samples are filtered apart, and the filter's state passed on (``zi``) from one
    piece to the next, which is what one call over the extended record computes.
    The backward pass starts from the end of the right extension; the left one's
    backward output is cut off by filtfilt, so it is not computed. `padlen` is below the
    rows' length (as filtfilt requires; :func:`_filter_values` clamps it)."""
    if padlen < 1:
        return filtfilt(b, a, rows, axis=-1, padtype="odd", padlen=padlen)
    steady = lfilter_zi(b, a)[None, :]               # filtfilt's initial conditions
    left = 2 * rows[:, :1] - rows[:, padlen:0:-1]     # scipy's odd_ext, piece by piece
    right = 2 * rows[:, -1:] - rows[:, -2:-(padlen + 2):-1]
    _, state = lfilter(b, a, left, zi=steady * left[:, :1])
    forward, state = lfilter(b, a, rows, zi=state)
    end, _ = lfilter(b, a, right, zi=state)
    _, state = lfilter(b, a, end[:, ::-1], zi=steady * end[:, -1:])
    return lfilter(b, a, forward[:, ::-1], zi=state)[0][:, ::-1]


def _filter_values(values, runs, sos, shortest, wanted, passes, mask=True):
    """Filter each run of visible frames (`runs`, from :func:`_blocks`) longer than
    `shortest`, padded by `wanted` frames (at most the run's length - 1); return
    (filtered, filtered mask (None unless `mask`: a caller that does not read it is
    spared a boolean array the size of the data), lengths of the runs left unfiltered,
    their columns)."""
    long = runs.length > shortest
    whole = long & (runs.length == len(values))    # columns without a gap: by slicing
    every = whole.size > 0 and whole.all() and whole.size == values.shape[1]
    out = None if every else values.copy()
    done = np.zeros(values.shape, dtype=bool) if mask else None
    if whole.any():
        columns = runs.column[whole]
        # one signal per row, its frames contiguous (no copy for a column-major array)
        rows = np.ascontiguousarray((values if every else values[:, columns]).T)
        for _ in range(passes // 2):
            rows = _zero_lag(sos, rows, min(wanted, len(values) - 1))
        block = rows.T
        if every:
            out = block
        else:
            out[:, columns] = block
        if mask:
            done[:, columns] = True
    for length, frames, columns in _same_length(runs, long & ~whole):
        block = values[frames, columns].T                # (length, runs of that length)
        padlen = min(wanted, length - 1)
        for _ in range(passes // 2):
            block = sosfiltfilt(sos, block, axis=0, padtype="odd", padlen=padlen)
        out[frames, columns] = block.T
        if mask:
            done[frames, columns] = True
    return out, done, (runs.length[~long], runs.column[~long])


def _warn_short(short, shortest, total, what="left unfiltered"):
    """One warning for the runs of visible frames too short to filter (`shortest` frames
    or fewer), out of `total` columns."""
    lengths, columns = short
    lengths, columns = lengths[lengths > 0], columns[lengths > 0]   # empty data: no run
    if lengths.size:
        warn(f"{lengths.size} run(s) of visible frames ({int(lengths.sum())} values "
             f"in all, in {np.unique(columns).size} of {total} columns) are "
             f"{shortest} frames or shorter, too short for the filter (it needs "
             f"more than {shortest}): {what}", RuntimeWarning)


def lowpass(data, cutoff, *, order=2, passes=2, rate=None):
    r"""Zero-lag Butterworth low-pass filter of marker trajectories (or any signals).

    Parameters
    ----------
    data : pandas.DataFrame, pandas.Series or array_like, shape (frames, ...)
        A trial from :func:`~bmc_functions.read_trc` or :func:`~bmc_functions.read_c3d`
        (its rate in ``attrs['rate']``), any DataFrame of numbers with a rate, or an
        array with frames on the first axis. NaN is a missing value.
    cutoff : float
        Cut-off frequency (Hz) of the whole filter: the frequency it attenuates by 3 dB
        (amplitude :math:`\times 1/\sqrt 2`), all passes together. Below ``rate / 2``.
    order : int, keyword-only
        Order of the Butterworth filter of one pass, 1 to :data:`MAX_ORDER`; default 2.
        The amplitude falls at ``20 * order * passes`` dB per decade above the cut-off.
    passes : int, keyword-only
        Number of passes through the data, even: 2 (default) is one forwards and one
        backwards pass (Winter's "fourth-order zero-lag" filter with ``order=2``); 4
        runs that pair twice.
    rate : float, keyword-only
        Sampling rate (Hz). Default: ``data.attrs['rate']``; required for arrays.

    Returns
    -------
    Same type and shape as `data`
        The filtered data (a DataFrame keeps its index, columns and a copy of its
        ``attrs``). NaN where `data` is NaN; a run of visible frames too short to be
        filtered (see Notes) keeps its values.

    Raises
    ------
    ValueError
        If `cutoff` is not positive or not below the Nyquist frequency ``rate / 2``; if
        `order` is not a whole number from 1 to :data:`MAX_ORDER`; if `passes` is not an
        even whole number from 2 to :data:`MAX_PASSES`; if no rate is given or it
        disagrees with ``data.attrs['rate']``; if `data` is not numeric or has infinite
        values. Type errors (:class:`~bmc_functions._checks.ArgumentTypeError`) are also
        ValueErrors.

    Warns
    -----
    RuntimeWarning
        Once per call, if some runs of visible frames were too short to filter, with
        their number; once if every run is shorter than one period of `cutoff` (a
        cut-off too low for the data's length).

    Notes
    -----
    *Zero lag.* One pass of a Butterworth filter delays each frequency by a different
    amount (its phase). Running the same filter backwards over the output undoes the
    delay exactly (the phases cancel) and squares the gain; scipy's
    :func:`scipy.signal.sosfiltfilt` does both passes.

    *Cut-off.* Each pass attenuates the cut-off of its design by 3 dB, so two passes
    attenuate it by 6 dB: the filter would cut lower than asked. The design cut-off is
    raised by :func:`corrected_cutoff` (derived there for any order and number of
    passes) so that the combined gain at `cutoff` is exactly :math:`1/\sqrt 2`.

    *Gaps.* Each run of visible frames of each column is filtered on its own (columns
    that share their gaps together): a gap stays a gap and nothing is smeared across it.

    *Edges.* Before each pass pair the run is extended at both ends by an odd
    reflection about its end values (``padtype='odd'``: :math:`2x_0 - x_k` before the
    first frame), so that the filter starts and ends without a jump: a constant passes
    unchanged, and so does a straight line once the extension is long enough for the
    filter's start-up transient to die out. The extension is two periods of the
    cut-off, :math:`\lceil 2\,\text{rate}/\text{cutoff}\rceil` frames (50 at 100 Hz
    and 4 Hz), at least scipy's default :math:`3(2s + 1)` for a filter of :math:`s`
    second-order sections (9 frames for ``order=2``), at most the run's length minus 1.
    A run of :math:`3(2s + 1)` frames or fewer is left unfiltered (warning). The first
    and last frames of a run remain the least reliable: the extension only guesses what
    came before.

    References
    ----------
    .. [1] Winter DA (2009) Biomechanics and Motor Control of Human Movement, 4th ed.
       Wiley, ch. 2-3 (signal processing; data smoothing in kinematics).
    .. [2] Robertson DGE, Dowling JJ (2003) Design and responses of Butterworth and
       critically damped digital filters. Journal of Electromyography and Kinesiology
       13:569-573.

    Examples
    --------
    A 2 Hz movement with a 25 Hz tremor, sampled at 100 Hz, with a gap:

    >>> import numpy as np
    >>> from bmc_functions import lowpass
    >>> t = np.arange(200) / 100
    >>> x = np.sin(2 * np.pi * 2 * t) + 0.2 * np.sin(2 * np.pi * 25 * t)
    >>> x[90:100] = np.nan
    >>> y = lowpass(x, 6, rate=100)
    >>> print(np.isnan(y[90:100]).all(), np.isnan(y).sum())
    True 10
    >>> print(f"{np.nanmax(np.abs(y - np.sin(2 * np.pi * 2 * t))[20:80]):.3f}")
    0.007

    A marker trial from a file: ``lowpass(read_trc(path), 6)``.
    """
    rate = _rate_of(data, rate)
    cutoff = _check_cutoff(cutoff, rate)
    order, passes = _check_order(order), _check_passes(passes)
    values, rebuild, nan_free = _as_columns(data)
    sos, shortest, wanted = _design(cutoff, rate, order, passes)
    runs = _blocks(values, nan_free)
    out, _, short = _filter_values(values, runs, sos, shortest, wanted, passes, mask=False)
    _warn_short(short, shortest, values.shape[1])
    longest = int(runs.length.max()) if runs.length.size else 0
    if longest > shortest and longest < rate / cutoff:
        warn(f"every run of visible frames is shorter than one period of the "
             f"cut-off ({longest} frames, {longest / rate:.3g} s, against "
             f"{1 / cutoff:.3g} s at {cutoff:g} Hz): the result is mostly the "
             f"filter's edge padding, not the data; use a higher cut-off",
             RuntimeWarning)
    return rebuild(out)


# --------------------------------------------------------------------------- derivative


def _differences(block, rate, order):
    """First (central, one-sided at the ends) or second differences of the columns of
    `block` (frames, columns), each a run of at least order + 1 visible frames."""
    if order == 1:
        return np.gradient(block, 1.0 / rate, axis=0, edge_order=1)
    out = np.empty_like(block)                  # the layout of `block` (C or Fortran)
    out[1:-1] = (block[2:] - 2 * block[1:-1] + block[:-2]) * rate ** 2
    out[:1], out[-1:] = out[1:2], out[-2:-1]     # the neighbouring frame's
    return out


def derivative(data, rate=None, *, order=1):
    r"""First or second time derivative by central differences, gap by gap.

    Parameters
    ----------
    data : pandas.DataFrame, pandas.Series or array_like, shape (frames, ...)
        As for :func:`lowpass`: a trial (rate in ``attrs['rate']``) or an array.
    rate : float, optional
        Sampling rate (Hz). Default: ``data.attrs['rate']``; required for arrays.
    order : {1, 2}, keyword-only
        1: velocity (default); 2: acceleration.

    Returns
    -------
    Same type and shape as `data`
        The derivative, in the data's units per second (per second squared; a
        DataFrame's ``attrs['units']``, e.g. ``'mm'``, becomes ``'mm/s'`` or
        ``'mm/s^2'``). NaN where `data` is NaN, and in runs of visible frames too short
        for the difference (1 frame for ``order=1``, 2 or fewer for ``order=2``).

    Raises
    ------
    ValueError
        If `order` is not 1 or 2, if no rate is given or it disagrees with
        ``data.attrs['rate']``, if `data` is not numeric or has infinite values, if
        `data`'s time index is not uniform (steps that differ by more than the rounding
        of the times: the differences assume one step, 1/rate).

    Notes
    -----
    With :math:`h = 1/\text{rate}`, inside each run of visible frames

    .. math:: \dot x_k \approx \frac{x_{k+1} - x_{k-1}}{2h}, \qquad
              \ddot x_k \approx \frac{x_{k+1} - 2x_k + x_{k-1}}{h^2},

    both with an error of order :math:`h^2` (Winter 2009, ch. 3). At a run's first and
    last frame the velocity is the one-sided difference :math:`(x_1 - x_0)/h` (error of
    order :math:`h`) and the acceleration that of the neighbouring frame. Noise is
    amplified: white noise of SD :math:`\sigma` gives a velocity noise of SD
    :math:`\sigma/(\sqrt 2 h)` and an acceleration noise of SD :math:`\sqrt 6\,\sigma/h^2`;
    filter first (:func:`lowpass`).

    References
    ----------
    .. [1] Winter DA (2009) Biomechanics and Motor Control of Human Movement, 4th ed.
       Wiley, ch. 3 (kinematics: finite differences).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import derivative
    >>> t = np.arange(6) / 10
    >>> print(derivative(t ** 2, 10) + 0.0)
    [0.1 0.2 0.4 0.6 0.8 0.9]
    >>> print(derivative(t ** 2, 10, order=2))
    [2. 2. 2. 2. 2. 2.]
    """
    rate = _rate_of(data, rate)
    _check_uniform(data)
    order = check_scalar(order, "order", "1 (velocity) or 2 (acceleration)", minimum=1,
                         maximum=2, integer=True)
    values, rebuild, nan_free = _as_columns(data)
    runs = _blocks(values, nan_free)
    long = runs.length >= order + 1
    whole = long & (runs.length == len(values))    # columns without a gap: by slicing
    every = whole.size > 0 and whole.all() and whole.size == values.shape[1]
    out = _differences(values, rate, order) if every else np.full_like(values, np.nan)
    if whole.any() and not every:
        columns = runs.column[whole]
        out[:, columns] = _differences(values[:, columns], rate, order)
    for length, frames, columns in _same_length(runs, long & ~whole):
        block = values[frames, columns].T                   # (length, runs of that length)
        out[frames, columns] = _differences(block, rate, order).T
    result = rebuild(out)
    units = getattr(result, "attrs", {}).get("units")
    if isinstance(units, str):                 # a trial's 'mm' becomes 'mm/s' or 'mm/s^2'
        result.attrs["units"] = units + ("/s" if order == 1 else "/s^2")
    return result


# --------------------------------------------------------------------------- residual analysis


class ResidualAnalysis(NamedTuple):
    """The result of :func:`residual_analysis`."""

    residuals: object
    """RMS residual (data units) per tested cut-off (rows) and column or marker."""
    cutoff: object
    """The suggested cut-off (Hz) per column or marker; NaN where none is found."""
    noise: object
    """Intercept of the noise line at 0 Hz: the estimated RMS of the noise."""
    slope: object
    """Slope of the noise line (data units per Hz)."""
    fit_from: float
    """Lowest cut-off (Hz) of the cut-offs the noise line was fitted to."""
    cutoffs: np.ndarray
    """The tested cut-offs (Hz), the rows of `residuals`."""


def residual_analysis(data, cutoffs=None, *, order=2, passes=2, rate=None,
                      by="coordinate", fit_from=None):
    r"""Winter's residual analysis: the cut-off that leaves as much noise as it removes
    signal, per coordinate or per marker.

    Parameters
    ----------
    data : pandas.DataFrame or array_like, shape (frames, ...)
        As for :func:`lowpass`.
    cutoffs : array_like, optional
        The cut-offs to test (Hz), increasing, each below ``rate / 2``. Default:
        :data:`N_CUTOFFS` = 100 equally spaced values up to ``rate / 4`` (half the
        Nyquist frequency; 0.375 to 37.5 Hz at 150 Hz). At most :data:`MAX_CUTOFFS`.
    order, passes, rate
        As for :func:`lowpass`.
    by : {'coordinate', 'marker'}, keyword-only
        One curve and cut-off per column (default) or per marker: the residuals of a
        marker's x, y and z pooled (root mean square), for a trial with (marker, coord)
        columns or an array of shape (frames, markers, 3).
    fit_from : float, keyword-only
        The noise line is fitted to the residuals at the cut-offs from `fit_from` up to
        the highest tested. Default: the middle of the tested range.

    Returns
    -------
    ResidualAnalysis
        ``(residuals, cutoff, noise, slope, fit_from, cutoffs)``. For a DataFrame, `residuals` is
        a DataFrame indexed by the tested cut-offs with a column per column (or
        marker) of `data`, and `cutoff`, `noise`, `slope` are Series; for an array they
        are arrays, of shape ``(len(cutoffs), ...)`` and ``data.shape[1:]`` (without the
        last axis for ``by='marker'``).

    Raises
    ------
    ValueError
        As for :func:`lowpass` (for every cut-off); if `cutoffs` is not an increasing vector
        of 3 to :data:`MAX_CUTOFFS` positive values; if fewer than 2 tested cut-offs are at
        or above `fit_from`; if ``by='marker'`` and the data have no x, y, z per marker.

    Warns
    -----
    RuntimeWarning
        Once per call: where no cut-off is found (the residual never comes down to the
        noise line in the tested range, or is below it from the lowest cut-off), and
        where runs were too short to filter (left out of the residuals).

    Notes
    -----
    For each cut-off :math:`f_c` the data are filtered (:func:`lowpass`) and the residual

    .. math:: R(f_c) = \sqrt{\frac{1}{N}\sum_{k=1}^{N} \left(x_k - \hat x_k(f_c)\right)^2}

    is taken over the :math:`N` filtered frames. White noise of SD :math:`\sigma` has a
    flat spectrum up to the Nyquist frequency :math:`f_N`: an ideal filter at
    :math:`f_c` leaves out the fraction :math:`1 - f_c/f_N` of its power, so once
    :math:`f_c` is above the signal's band, :math:`R(f_c) \approx \sigma\sqrt{1 -
    f_c/f_N} \approx \sigma(1 - f_c/(2f_N))`: nearly a straight line that meets
    :math:`f_c = 0` at :math:`\sigma` (Winter 2009).

    *The line*: fitted by least squares to :math:`R(f_c)` at the tested cut-offs from
    `fit_from` up; its intercept :math:`a` at 0 Hz estimates :math:`\sigma` (`noise`).
    The filter is not ideal, so the line is an approximation: with the defaults (the
    fit from :math:`f_N/4` to :math:`f_N/2`, ``order=2``, ``passes=2``) the residual of
    white noise computed from the filter's frequency response gives an intercept of
    :math:`0.970\,\sigma` (the tests check it, and 50 noise records give
    :math:`0.968 \pm 0.020\,\sigma`).

    *The cut-off*: Winter draws a horizontal line at :math:`a` and takes the cut-off where
    it meets the residual curve: there the noise the filter lets through is about as
    large as the signal it removes. Here: the lowest tested cut-off at which
    :math:`R \le a`, refined by linear interpolation between it and the cut-off below.
    NaN (with a warning) if :math:`R > a` at every tested cut-off, or already
    :math:`R \le a` at the lowest one (no signal left above it: test lower cut-offs).

    References
    ----------
    .. [1] Winter DA (2009) Biomechanics and Motor Control of Human Movement, 4th ed.
       Wiley, ch. 3 (kinematics: the optimal cutoff frequency by residual analysis).
    .. [2] Winter DA, Sidwall HG, Hobson DA (1974) Measurement and reduction of noise in
       kinematics of locomotion. Journal of Biomechanics 7:157-159.

    Examples
    --------
    A 1 Hz movement with 2 mm of white noise, 500 frames at 100 Hz:

    >>> import numpy as np
    >>> from bmc_functions import residual_analysis
    >>> rng = np.random.default_rng(1)
    >>> t = np.arange(500) / 100
    >>> x = 100 * np.sin(2 * np.pi * t) + rng.normal(0, 2, t.size)
    >>> result = residual_analysis(x, rate=100)
    >>> print(f"noise {result.noise:.2f} mm, cut-off {result.cutoff:.1f} Hz")
    noise 1.89 mm, cut-off 2.6 Hz
    """
    rate = _rate_of(data, rate)
    order, passes = _check_order(order), _check_passes(passes)
    check_choice(by, "by", ("coordinate", "marker"))
    if cutoffs is None:
        cutoffs = np.arange(1, N_CUTOFFS + 1) * (0.25 * rate / N_CUTOFFS)
    cutoffs = as_float_array(cutoffs, "cutoffs")
    if cutoffs.ndim != 1 or cutoffs.size < 3:
        raise ValueError(f"cutoffs must be a vector of at least 3 frequencies (Hz); got "
                         f"shape {cutoffs.shape}")
    if cutoffs.size > MAX_CUTOFFS:                      # each one filters the whole trial
        raise ValueError(f"cutoffs: at most {MAX_CUTOFFS} cut-offs; got {cutoffs.size}")
    check_finite_or_nan(cutoffs, "cutoffs", allow_nan=False)
    if not (np.diff(cutoffs) > 0).all():
        raise ValueError(f"cutoffs must be increasing, each value once; got "
                         f"{np.round(cutoffs[:8], 6).tolist()}"
                         f"{' ...' if cutoffs.size > 8 else ''}")
    for value in (cutoffs[0], cutoffs[-1]):             # increasing: the ends suffice
        _check_cutoff(value, rate, "cutoffs")
    if fit_from is None:
        fit_from = 0.5 * (cutoffs[0] + cutoffs[-1])
    fit_from = check_number(fit_from, "fit_from")
    fitted = cutoffs >= fit_from
    if fitted.sum() < 2:
        raise ValueError(f"fit_from must leave at least 2 tested cut-offs at or above it "
                         f"for the noise line; got {fit_from:g} Hz with the highest tested "
                         f"{cutoffs[-1]:g} Hz")

    values, _, nan_free = _as_columns(data)
    names, groups = _groups(data, values, by)
    squared = np.empty((cutoffs.size, values.shape[1]))
    blocks = _blocks(values, nan_free)                    # the same for every cut-off
    for i, fc in enumerate(cutoffs):                      # a loop over cut-offs
        sos, shortest, wanted = _design(fc, rate, order, passes)
        filtered, done, short = _filter_values(values, blocks, sos, shortest, wanted,
                                               passes)
        diff = np.where(done, values - np.where(done, filtered, 0.0), np.nan)
        squared[i] = _nanmean0(diff ** 2)
    residual = np.sqrt(np.stack([_nanmean1(squared[:, g]) for g in groups], axis=1)
                       if groups else np.empty((cutoffs.size, 0)))
    _warn_short(short, shortest, values.shape[1], "left out of the residuals")

    slope, noise = _noise_line(cutoffs[fitted], residual[fitted])
    with np.errstate(invalid="ignore"):
        below = residual <= noise
    chosen = np.full(residual.shape[1], np.nan)
    first = np.argmax(below, axis=0) if below.size else np.zeros(0, dtype=int)
    # no signal to separate from the noise: the residual at the lowest cut-off is within
    # MIN_SIGNAL of the noise line (white noise, or a constant: rounding error only)
    with np.errstate(invalid="ignore"):
        no_signal = residual[0] <= MIN_SIGNAL * noise
    scale = np.array([np.nanmax(np.abs(values[:, g]), initial=0.0) for g in groups])
    no_signal |= residual[0] <= 1e-9 * scale              # a constant: rounding error only
    found = below.any(axis=0) & (first > 0) & ~no_signal
    crossing = first[found]                 # the first tested cut-off at or below the line
    columns = np.flatnonzero(found)
    above, under = residual[crossing - 1, columns], residual[crossing, columns]
    fraction = (above - noise[columns]) / (above - under)
    chosen[columns] = cutoffs[crossing - 1] + fraction * (cutoffs[crossing]
                                                          - cutoffs[crossing - 1])
    missing = ~found & ~np.isnan(residual).all(axis=0)
    if missing.any():
        quiet = int((missing & no_signal).sum())
        warn(f"no cut-off found for {missing.sum()} of {len(names)} "
             f"{'markers' if by == 'marker' else 'columns'}: the residual is "
             f"above the noise line at every tested cut-off, or below it (or "
             f"within {MIN_SIGNAL:g} times it: no signal above the noise, "
             f"{quiet} of them) from the lowest ({cutoffs[0]:g} Hz); test other "
             f"cut-offs", RuntimeWarning)
    return _package(data, values, names, cutoffs, residual, chosen, noise, slope,
                    float(fit_from), by)


def _noise_line(cutoffs, residual):
    """Slope and intercept at 0 Hz (the noise) of the least-squares line through the
    residuals (cut-offs, curves) at `cutoffs`, per curve."""
    centred = cutoffs - cutoffs.mean()
    with np.errstate(invalid="ignore"):
        slope = (centred[:, None] * (residual - residual.mean(axis=0))).sum(axis=0) / \
            (centred ** 2).sum()
        noise = residual.mean(axis=0) - slope * cutoffs.mean()
    return slope, noise


def _nanmean0(array):
    """Mean over the first axis ignoring NaN; NaN (no warning) where all are NaN."""
    count = (~np.isnan(array)).sum(axis=0)
    total = np.nansum(array, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def _nanmean1(array):
    return _nanmean0(array.T)


def _groups(data, values, by):
    """(names, column indices of each curve) for 'coordinate' or 'marker'."""
    n = values.shape[1]
    if by == "coordinate":
        names = list(data.columns) if isinstance(data, pd.DataFrame) else list(range(n))
        return names, [np.array([j]) for j in range(n)]
    if isinstance(data, pd.DataFrame):
        columns = data.columns
        if not isinstance(columns, pd.MultiIndex) or columns.nlevels != 2:
            raise ValueError(f"by='marker' needs (marker, coord) columns, as read_trc "
                             f"returns them; got {columns.nlevels}-level columns, e.g. "
                             f"{columns[0]!r}")
        markers = list(dict.fromkeys(columns.get_level_values(0)))
        codes = columns.get_level_values(0)
        return markers, [np.flatnonzero(codes == m) for m in markers]
    shape = np.shape(as_float_array(data, "data"))
    if len(shape) < 2 or shape[-1] != 3:
        raise ValueError(f"by='marker' needs data of shape (frames, ..., 3), x, y, z on "
                         f"the last axis; got shape {shape}")
    return list(range(n // 3)), [np.arange(3 * m, 3 * m + 3) for m in range(n // 3)]


def _package(data, values, names, cutoffs, residual, chosen, noise, slope, fit_from, by):
    if isinstance(data, pd.DataFrame):
        columns = (pd.Index(names, name=data.columns.names[0]) if by == "marker"
                   else data.columns)
        index = pd.Index(cutoffs, name="cutoff (Hz)")
        return ResidualAnalysis(pd.DataFrame(residual, index=index, columns=columns),
                                pd.Series(chosen, index=columns, name="cutoff (Hz)"),
                                pd.Series(noise, index=columns, name="noise"),
                                pd.Series(slope, index=columns, name="slope"), fit_from,
                                cutoffs)
    shape = np.shape(as_float_array(data, "data"))[1:]
    if by == "marker":
        shape = shape[:-1]
    if isinstance(data, pd.Series):
        shape = ()

    def shaped(array):
        out = array.reshape(array.shape[:-1] + shape)
        return float(out) if out.ndim == 0 else out
    return ResidualAnalysis(residual.reshape((len(cutoffs),) + shape), shaped(chosen),
                            shaped(noise), shaped(slope), fit_from, cutoffs)
