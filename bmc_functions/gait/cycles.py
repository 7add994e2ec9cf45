r"""Gait cycles: time normalisation between heel strikes, ensembles, spatio-temporal parameters.

What follows the events of :mod:`~bmc_functions.gait.events` on the applied path
(files -> markers -> segments -> joints -> gait cycles):

- :func:`time_normalize` resamples any per-frame signal to a fixed number of points per
  cycle (default 101: 0, 1, ..., 100 % of the cycle) between consecutive heel strikes;
  :func:`normalize_by_side` does it for a DataFrame whose columns carry a side level
  (the angles of the lower-limb pipeline), right columns with right cycles, left with left;
- :func:`ensemble` gives the mean, SD and count per point over cycles;
- :func:`stride_table` and :func:`spatiotemporal_parameters` give stride time, cadence and
  stance/swing percentages.

The figure every gait paper shows (mean +- SD per joint and plane, right beside left) is
:func:`bmc_functions.plotting.plot_gait_cycles`.

References: Hollman JH et al. (2011) Gait & Posture 34:111-118 (stride times of adults'
walking, for ``MAX_MEDIAN_STRIDE``).
"""

import warnings
from collections import namedtuple
from collections.abc import Mapping

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

from .._checks import (as_float_array, check_choice, check_finite_or_nan, check_rate_attr,
                       check_scalar, warn)
from .events import EVENTS, MIN_STEP, SIDES, true_runs
from .strides import side_means, stride_distances, stride_phases

#: Most points per cycle that time_normalize accepts: 1,000 points per percent of the
#: cycle, far beyond any sampling rate's resolution; beyond it the request is a mistake
#: (and the result would not fit in memory).
MAX_POINTS = 100_000

#: Fewest frames of the signal a cycle must span (median over the cycles): a cycle that
#: spans fewer is sampled between too few frames to have a shape, and means that the
#: signal's index and the heel strikes are in different units (frame numbers or ms
#: against seconds).
MIN_CYCLE_FRAMES = 4

#: A median stride (heel strike to heel strike) longer than this (s) is not a gait
#: cycle: strides last about 0.45 s (sprinting) to 2-3 s (very slow walking; MIN_STRIDE
#: of gait.events, and Hollman et al. 2011, Gait Posture 34:111-118: 0.9-1.3 s in adults' walking);
#: the times are then in other units (ms, or frame numbers) than seconds.
MAX_MEDIAN_STRIDE = 10.0


Ensemble = namedtuple("Ensemble", ["mean", "sd", "count"])
Ensemble.__doc__ = "Mean, standard deviation (ddof=1) and count of non-NaN cycles per point."


# --- time normalisation -----------------------------------------------------------------------

def _check_events(times, name):
    times = as_float_array(times, name)
    if times.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array of times (s); got shape {times.shape}")
    check_finite_or_nan(times, name, allow_nan=False)
    if np.any(np.diff(times) <= 0):
        raise ValueError(f"{name} must be sorted in increasing order (times in s); got "
                         f"{np.round(times, 4).tolist()}")
    return times


def _gap_runs(missing, max_gap_samples):
    """Boolean (n, k): samples in NaN runs longer than `max_gap_samples` (or at the ends)."""
    long = np.zeros_like(missing)
    for column in range(missing.shape[1]):          # loop over columns, not frames
        starts, stops = true_runs(missing[:, column])
        for start, stop in zip(starts, stops):
            if stop - start > max_gap_samples or start == 0 or stop == len(missing):
                long[start:stop, column] = True
    return long


def time_normalize(signal, heel_strikes, *, time=None, n_points=101, max_gap=0.05,
                   toe_offs=None, long_gaps="cycle"):
    r"""Resample a per-frame signal to `n_points` per cycle between consecutive heel strikes.

    Parameters
    ----------
    signal : pandas.DataFrame, pandas.Series or array_like
        Frames on the first axis. A DataFrame or Series is indexed by time (s); an array
        needs `time`.
    heel_strikes : array_like, shape (m,)
        Sorted times (s) of heel strikes of one side: cycle :math:`i` runs from
        ``heel_strikes[i]`` to ``heel_strikes[i + 1]``.
    time : array_like, shape (n,), optional
        Times (s) of the frames of an array `signal`, increasing.
    n_points : int, optional
        Points per cycle (default 101: 0, 1, ..., 100 %).
    max_gap : float, optional
        Longest run of missing samples (s) interpolated over (default 0.05 s): a run of
        :math:`n` missing frames lasts :math:`n / \text{rate}` (the rate from the median
        frame step), and one of exactly `max_gap` is interpolated. A cycle that reads a
        longer gap in a column (its frames run from the frame at or before its opening
        heel strike to the frame at or after its closing one) is NaN in that column, not
        interpolated across (see `long_gaps`).
    toe_offs : array_like, optional
        Sorted toe-off times (s) of the same side. When given, a "cycle" that holds more
        than one toe-off is left out (with a warning): a heel strike between them was not
        detected (a gap), and the interval is two strides, not one.
    long_gaps : {'cycle', 'points'}, optional
        What a gap longer than `max_gap` leaves NaN in the cycles that read it: the whole
        cycle in that column (``'cycle'``, the default: an angle curve with a hole is not
        a curve), or only the points nearer a frame of the gap than a measured frame
        (``'points'``: for joint moments and powers, missing by design in a stance no
        force plate measured, whose other points are measured values).

    Returns
    -------
    pandas.DataFrame or ndarray
        For a DataFrame/Series: a DataFrame indexed by ``(cycle, percent)`` with the
        columns of `signal` (``attrs['cycles']`` holds each cycle's start and end time).
        For an array of shape ``(n, ...)``: an array ``(cycles, n_points, ...)``. With
        fewer than two heel strikes there is no cycle: the result has 0 cycles (a
        documented empty result, with a warning).

    Raises
    ------
    ValueError
        If `heel_strikes` is not 1-D, finite and increasing; if the time is missing,
        not increasing or of the wrong length; if `n_points` < 2 or above
        ``MAX_POINTS = 100_000``, or `max_gap` is not a number >= 0, or `long_gaps` is not
        one of its values; if the signal is
        shorter than every cycle it is asked for; if the cycles span fewer than
        ``MIN_CYCLE_FRAMES = 4`` frames of the signal (median): an index in frame numbers
        or ms with events in s.

    Warns
    -----
    RuntimeWarning
        Once per call: cycles outside the signal's time range (left out), no cycle;
        cycles longer than ``MAX_MEDIAN_STRIDE = 10`` s (median: times in ms or frame
        numbers?); a signal whose ``attrs['rate']`` contradicts its index.

    Notes
    -----
    Cycle :math:`i` is sampled at :math:`t_{ik} = s_i + \tfrac{k}{N-1}(s_{i+1} - s_i)`,
    :math:`k = 0 \dots N-1`, by a cubic spline through the frames (short gaps first
    filled by a cubic spline through the valid frames of their column). Percent
    :math:`100\,k/(N-1)`.

    Examples
    --------
    A sine of period 1 s, normalised between heel strikes 1 s apart, is one period:

    >>> import numpy as np
    >>> from bmc_functions import time_normalize
    >>> t = np.arange(0, 3.01, 0.01)
    >>> cycles = time_normalize(np.sin(2 * np.pi * t), [0.5, 1.5, 2.5], time=t, n_points=5)
    >>> cycles.shape
    (2, 5)
    >>> print(np.round(cycles[0], 6) + 0.0)
    [ 0. -1.  0.  1.  0.]
    """
    strikes = _check_events(heel_strikes, "heel_strikes")
    n_points = check_scalar(n_points, "n_points", "an integer >= 2", minimum=2,
                            integer=True)
    if n_points > MAX_POINTS:
        raise ValueError(f"n_points must be at most {MAX_POINTS:,} (1,000 points per "
                         f"percent of the cycle); got {n_points:,}")
    max_gap = check_scalar(max_gap, "max_gap", "a time (s) >= 0", minimum=0.0)
    check_choice(long_gaps, "long_gaps", ("cycle", "points"))
    values, time, table, trailing = _signal_values(signal, time)
    starts, ends = _cycles_in(strikes, time, toe_offs)
    percent = np.linspace(0.0, 100.0, n_points)
    columns = values.shape[1]
    resampled = np.full((len(starts), n_points, columns), np.nan)
    if len(starts) and columns:
        resampled = _resample_cycles(values, time, starts, ends, percent, max_gap,
                                     long_gaps)
    if table is None:
        return resampled.reshape((len(starts), n_points) + trailing)
    index = pd.MultiIndex.from_product([range(len(starts)), percent],
                                       names=["cycle", "percent"])
    result = pd.DataFrame(resampled.reshape(-1, columns), index=index,
                          columns=table.columns)
    result.attrs = dict(table.attrs)
    result.attrs["cycles"] = list(zip(starts.tolist(), ends.tolist()))
    return result


def _signal_values(signal, time):
    """The signal as a float array (frames, columns), its time (s), the DataFrame it came
    from (None for an array) and the array's trailing shape; checked."""
    table = None
    if isinstance(signal, (pd.DataFrame, pd.Series)):
        table = signal.to_frame() if isinstance(signal, pd.Series) else signal
        if time is not None:
            raise ValueError("time must not be given with a DataFrame or Series signal: its "
                             "index is the time")
        time = as_float_array(table.index.to_numpy(), "signal.index (time)")
        if time.ndim == 1 and np.all(np.isfinite(time)):
            check_rate_attr(table, time, "signal")
        values = as_float_array(table.to_numpy(), "signal")
        trailing = ()
    else:
        if time is None:
            raise ValueError("time is required for an array signal (the time in s of each "
                             "frame); a DataFrame or Series carries it in its index")
        values = as_float_array(signal, "signal")
        if values.ndim == 0:
            raise ValueError("signal must have frames on the first axis; got a scalar")
        trailing = values.shape[1:]
        values = values.reshape(len(values), -1)
        time = as_float_array(time, "time")
    check_finite_or_nan(values, "signal")
    if time.ndim != 1 or len(time) != len(values):
        raise ValueError(f"time must be 1-D with one time per frame of signal "
                         f"({len(values)}); got shape {time.shape}")
    check_finite_or_nan(time, "time", allow_nan=False)
    if len(time) < 2 or np.any(np.diff(time) <= 0):
        raise ValueError("time must increase strictly, with at least 2 frames")
    return values, time, table, trailing


def _cycles_in(strikes, time, toe_offs):
    """Start and end times (s) of the cycles between consecutive heel strikes that lie
    within `time` and hold at most one of `toe_offs`; warns about those left out."""
    if len(strikes) < 2:
        warn(f"{len(strikes)} heel strike(s): no complete cycle to normalise",
             RuntimeWarning)
        return np.array([]), np.array([])
    starts, ends = strikes[:-1], strikes[1:]
    tol = 1e-9 * max(1.0, abs(time[-1]))
    inside = (starts >= time[0] - tol) & (ends <= time[-1] + tol)
    if not inside.any():
        raise ValueError(
            f"signal ({time[0]:.4g} to {time[-1]:.4g} s, {len(time)} frames) does not "
            f"cover any cycle between the heel strikes given "
            f"({strikes[0]:.4g} to {strikes[-1]:.4g} s): is the signal shorter than a "
            "cycle, are the events from another trial, or are the two in different "
            "units (ms or frame numbers against seconds)?")
    if not inside.all():
        warn(f"{np.count_nonzero(~inside)} of {len(inside)} cycles extend "
             "beyond the signal's time range and were left out",
             RuntimeWarning)
    starts, ends = starts[inside], ends[inside]
    _check_time_units(time, ends - starts)
    if toe_offs is not None:
        offs = _check_events(toe_offs, "toe_offs")
        count = (np.searchsorted(offs, ends, side="left")
                 - np.searchsorted(offs, starts, side="right"))
        double = count > 1
        if double.any():
            warn(f"{np.count_nonzero(double)} of {len(double)} cycles hold two "
                 "or more toe-offs (a heel strike between them was missed) and "
                 "were left out", RuntimeWarning)
            starts, ends = starts[~double], ends[~double]
    return starts, ends


def _resample_cycles(values, time, starts, ends, percent, max_gap, long_gaps="cycle"):
    """`values` (frames, columns) sampled at `percent` of each cycle (cycles, points,
    columns): gaps up to `max_gap` (s) filled by a cubic spline; a longer gap leaves NaN
    the cycles that read it in that column (`long_gaps` 'cycle') or the points nearer one
    of its frames than a measured frame ('points')."""
    columns = values.shape[1]
    missing = np.isnan(values)
    rate = 1.0 / np.median(np.diff(time))
    long_gap = _gap_runs(missing, int(np.floor(max_gap * rate + 1e-9)))
    filled = values.copy()
    for column in np.flatnonzero(missing.any(axis=0)):      # loop over columns, not frames
        seen = ~missing[:, column]
        if np.count_nonzero(seen) >= 4:
            filled[~seen, column] = CubicSpline(time[seen], values[seen, column])(time[~seen])
        else:                                               # the whole column is NaN below
            filled[:, column] = 0.0
            long_gap[:, column] = True
    targets = starts[:, None] + (ends - starts)[:, None] * (percent / 100.0)[None, :]
    targets = np.clip(targets, time[0], time[-1])
    resampled = CubicSpline(time, filled, axis=0)(targets)
    if long_gaps == "points":
        resampled[_nearer_a_gap(time, targets, long_gap)] = np.nan
        return resampled
    # a cycle reads the frames from the one at or before its start to the one at or after
    # its end: one that reads a long gap is NaN in that column
    # (clipped: a heel strike within the rounding tolerance outside the trial reads the
    # first or last frame, not past it)
    first = np.maximum(np.searchsorted(time, starts, side="right") - 1, 0)
    last = np.minimum(np.searchsorted(time, ends, side="left"), len(time) - 1)
    counts = np.vstack([np.zeros((1, columns), int), np.cumsum(long_gap, axis=0)])
    bad = (counts[last + 1] - counts[first]) > 0                  # (cycles, columns)
    resampled[np.broadcast_to(bad[:, None, :], resampled.shape)] = np.nan
    return resampled


def _nearer_a_gap(time, targets, long_gap):
    """Boolean (cycles, points, columns): the `targets` (cycles, points) nearer a frame of
    `long_gap` (frames, columns) than a frame outside it (a tie keeps the point)."""
    right = np.clip(np.searchsorted(time, targets), 1, len(time) - 1)
    left = right - 1
    to_left, to_right = (targets - time[left])[..., None], (time[right] - targets)[..., None]
    return np.where(to_left < to_right, long_gap[left],
                    np.where(to_right < to_left, long_gap[right],
                             long_gap[left] & long_gap[right]))


def _check_time_units(time, durations):
    """Refuse cycles that span too few frames of the signal; warn about cycles too long
    for a stride (both mean that the index and the events are not both in seconds)."""
    step = float(np.median(np.diff(time)))
    median = float(np.median(durations))
    if median / step < MIN_CYCLE_FRAMES:
        raise ValueError(
            f"the cycles between heel_strikes last {median:.4g} (median) in the units of "
            f"the events, but the signal's frames are {step:.4g} apart in its time "
            f"({time[0]:.4g} to {time[-1]:.4g}): a cycle spans only {median / step:.2g} "
            f"frames. The signal's index (or time) and the events must both be in seconds: "
            f"is the index frame numbers (0, 1, 2, ...) or milliseconds?")
    if median > MAX_MEDIAN_STRIDE:
        warn(
            f"the cycles between heel_strikes last {median:.4g} s (median; the signal's "
            f"frames are {step:.4g} s apart), but a stride lasts 0.4-3 s: are the times "
            f"in milliseconds or frame numbers? (max_gap, in s, is compared with them "
            f"too)", RuntimeWarning)


def _side_level(columns):
    """Index of the column level that holds 'right'/'left'."""
    levels = range(columns.nlevels) if isinstance(columns, pd.MultiIndex) else [None]
    for level in levels:
        values = set(columns.get_level_values(level) if level is not None else columns)
        if values & set(SIDES):
            return level
    raise ValueError("signal must have a column level with the sides 'right' and/or "
                     f"'left' (as the angles of the lower-limb pipeline); got columns "
                     f"{list(columns[:4])}")


def normalize_by_side(signal, events, **options):
    """Time-normalise each side's columns between that side's heel strikes.

    Parameters
    ----------
    signal : pandas.DataFrame
        Indexed by time (s), with a column level holding ``'right'`` and ``'left'`` (e.g.
        ``(joint, side, angle)``). Columns of other sides (``'both'`` for the pelvis, say)
        are normalised with the right side's cycles when it has events, else the left's.
    events : dict
        As returned by :func:`gait_events`.
    **options
        Passed to :func:`time_normalize` (``n_points``, ``max_gap``, ``long_gaps``:
        ``'points'`` for kinetics, NaN only in the stances no plate measured). The toe-offs of
        `events`, when present, leave out the intervals that span a missed heel strike.

    Returns
    -------
    pandas.DataFrame
        Indexed by ``(cycle, percent)``, the columns of `signal`. Sides with fewer cycles
        than the other are NaN in the extra cycles. ``attrs['cycles']`` maps each side to
        its cycles' (start, end) times.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> from bmc_functions import normalize_by_side
    >>> t = np.arange(0, 3.01, 0.01)
    >>> cols = pd.MultiIndex.from_tuples([("knee", "right", "flexion"),
    ...                                   ("knee", "left", "flexion")])
    >>> angles = pd.DataFrame(np.c_[t, 2 * t], index=t, columns=cols)
    >>> events = {"right": {"heel_strike": np.array([0.0, 1.0, 2.0])},
    ...           "left": {"heel_strike": np.array([0.5, 1.5])}}
    >>> cycles = normalize_by_side(angles, events, n_points=3)
    >>> print(cycles.round(3))
                      knee
                     right  left
                   flexion flexion
    cycle percent
    0     0.0          0.0     1.0
          50.0         0.5     2.0
          100.0        1.0     3.0
    1     0.0          1.0     NaN
          50.0         1.5     NaN
          100.0        2.0     NaN
    """
    if not isinstance(signal, pd.DataFrame):
        raise TypeError(f"signal must be a DataFrame indexed by time with a side column "
                        f"level; got {type(signal).__name__}")
    if not isinstance(events, Mapping):
        raise TypeError(f"events must be the dict returned by gait_events; got "
                        f"{type(events).__name__}")
    for side, found in events.items():
        if not isinstance(found, Mapping) or "heel_strike" not in found:
            what = (f"a dict with keys {list(found)}" if isinstance(found, Mapping)
                    else f"{type(found).__name__}")
            raise ValueError(f"events[{side!r}] must be a dict with the 'heel_strike' times "
                             f"(s) of that side, and optionally 'toe_off', as gait_events "
                             f"returns; got {what}")
    level = _side_level(signal.columns)
    sides = (signal.columns.get_level_values(level) if level is not None
             else pd.Index(signal.columns))
    default = "right" if len(events.get("right", {}).get("heel_strike", [])) >= 2 else "left"
    parts, cycles = [], {}
    for side in dict.fromkeys(sides):
        use = side if side in SIDES else default
        if use not in events:
            raise ValueError(f"events has no side {use!r} for the columns of side {side!r}; "
                             f"it has {list(events)}")
        part = time_normalize(signal.loc[:, sides == side], events[use]["heel_strike"],
                              toe_offs=events[use].get("toe_off"), **options)
        cycles[side] = part.attrs.get("cycles", [])
        parts.append(part)
    result = pd.concat(parts, axis=1).reindex(columns=signal.columns)
    result.attrs = dict(signal.attrs)
    result.attrs["cycles"] = cycles
    return result


def ensemble(cycles):
    r"""Mean, standard deviation and count per point over cycles, NaN cycles left out.

    Parameters
    ----------
    cycles : pandas.DataFrame or array_like
        As returned by :func:`time_normalize` or :func:`normalize_by_side`: a DataFrame
        indexed by ``(cycle, percent)``, or an array ``(cycles, points, ...)``.

    Returns
    -------
    pandas.DataFrame or Ensemble
        For a DataFrame: indexed by percent, columns ``(statistic, *columns)`` with
        statistic ``'mean'``, ``'sd'`` (ddof=1) and ``'count'``. For an array: the
        namedtuple ``Ensemble(mean, sd, count)`` of arrays ``(points, ...)``. Points with
        no cycle are NaN (count 0); the SD of a single cycle is NaN.

    Raises
    ------
    ValueError
        Infinite values; cycles of different lengths (a list of arrays, or a DataFrame
        whose cycles have different percent points): un-normalised cycles, which cannot
        be averaged point by point; a DataFrame not indexed by ``(cycle, percent)``.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import ensemble
    >>> stats = ensemble(np.array([[0.0, 1.0], [2.0, np.nan], [4.0, 3.0]]))
    >>> print(stats.mean, stats.sd, stats.count)
    [2. 2.] [2.     1.4142] [3 2]
    """
    if isinstance(cycles, pd.DataFrame):
        if not isinstance(cycles.index, pd.MultiIndex) or "percent" not in cycles.index.names:
            raise ValueError("cycles must be indexed by (cycle, percent), as returned by "
                             f"time_normalize; got index names {list(cycles.index.names)}")
        numeric = as_float_array(cycles, "cycles")
        check_finite_or_nan(numeric, "cycles")
        if "cycle" in cycles.index.names:
            sizes = cycles.groupby(level="cycle").size()
            points = cycles.index.get_level_values("percent")
            per_cycle = pd.Series(points, index=cycles.index.get_level_values("cycle"))
            first = per_cycle.loc[sizes.index[0]].to_numpy() if len(sizes) else None
            if sizes.nunique() > 1 or any(
                    not np.array_equal(per_cycle.loc[c].to_numpy(), first)
                    for c in sizes.index[1:]):   # a loop over cycles, not frames
                raise ValueError(
                    f"cycles must all have the same points (percent of the cycle); got "
                    f"cycles of {sorted(set(sizes.tolist()))[:5]} points: un-normalised "
                    f"cycles cannot be averaged point by point. Time-normalise them first "
                    f"(time_normalize or normalize_by_side)")
        grouped = cycles.groupby(level="percent")
        result = pd.concat({"mean": grouped.mean(), "sd": grouped.std(ddof=1),
                            "count": grouped.count()}, axis=1, names=["statistic"])
        return result
    if isinstance(cycles, (list, tuple)) and len({np.shape(c)[:1] for c in cycles}) > 1:
        raise ValueError(
            f"cycles have different lengths ({', '.join(str(len(c)) for c in cycles[:6])}"
            f"{', ...' if len(cycles) > 6 else ''} points): un-normalised cycles cannot be "
            f"averaged point by point. Time-normalise them first (time_normalize)")
    values = as_float_array(cycles, "cycles")
    check_finite_or_nan(values, "cycles")
    if values.ndim < 2:
        raise ValueError(f"cycles must have shape (cycles, points, ...); got shape "
                         f"{values.shape}")
    count = np.count_nonzero(~np.isnan(values), axis=0)
    with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)      # all-NaN points: NaN by design
        mean = np.nanmean(values, axis=0)
        sd = np.nanstd(values, axis=0, ddof=1)
    sd[count < 2] = np.nan
    return Ensemble(mean, sd, count)


# --- spatio-temporal parameters --------------------------------------------------------------

def stride_table(events):
    """One row per complete stride (heel strike to the next of the same side).

    Parameters
    ----------
    events : dict
        As returned by :func:`gait_events`.

    Returns
    -------
    pandas.DataFrame
        Columns ``side``, ``start``, ``end`` (s), ``stride_time`` (s), ``toe_off`` (s,
        NaN when no toe-off was found inside the stride), ``stance`` and ``swing`` (% of
        the stride). An interval between heel strikes that holds two toe-offs spans a
        missed heel strike (two strides) and is left out. Empty (0 rows) when no side has
        two heel strikes.

    Warns
    -----
    RuntimeWarning
        When the median stride is longer than ``MAX_MEDIAN_STRIDE = 10`` s: the event
        times are in ms or frame numbers, not seconds.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import stride_table
    >>> events = {"right": {"heel_strike": np.array([0.1, 1.1, 2.2]),
    ...                     "toe_off": np.array([0.72, 1.76])}}
    >>> print(stride_table(events).round(3).to_string(index=False))
     side  start  end  stride_time  toe_off  stance  swing
    right    0.1  1.1          1.0     0.72    62.0   38.0
    right    1.1  2.2          1.1     1.76    60.0   40.0
    """
    if not isinstance(events, Mapping):
        raise TypeError(f"events must be the dict returned by gait_events; got "
                        f"{type(events).__name__}")
    rows = []
    for side, found in events.items():
        if not isinstance(found, Mapping) or "heel_strike" not in found:
            raise ValueError(f"events[{side!r}] must be a dict with 'heel_strike' and "
                             f"'toe_off' times; got {found!r}")
        strikes = _check_events(found["heel_strike"], f"events[{side!r}]['heel_strike']")
        offs = _check_events(found.get("toe_off", []), f"events[{side!r}]['toe_off']")
        if len(strikes) < 2:
            continue
        start, end = strikes[:-1], strikes[1:]
        # the first toe-off inside each stride
        index = np.searchsorted(offs, start, side="right")
        toe = np.where(index < len(offs), offs[np.minimum(index, len(offs) - 1)]
                       if len(offs) else np.nan, np.nan)
        toe = np.where(toe < end, toe, np.nan)
        spans_two = (np.searchsorted(offs, end, side="left")
                     - np.searchsorted(offs, start, side="right")) > 1
        start, end, toe = start[~spans_two], end[~spans_two], toe[~spans_two]  # a missed strike
        stride = end - start
        stance = 100.0 * (toe - start) / stride
        rows.append(pd.DataFrame({"side": side, "start": start, "end": end,
                                  "stride_time": stride, "toe_off": toe, "stance": stance,
                                  "swing": 100.0 - stance}))
    columns = ["side", "start", "end", "stride_time", "toe_off", "stance", "swing"]
    strides = np.concatenate([row["stride_time"].to_numpy() for row in rows] + [[]])
    if strides.size and np.median(strides) > MAX_MEDIAN_STRIDE:
        warn(f"the strides between the heel strikes of events last "
             f"{np.median(strides):.4g} s (median), but a stride lasts 0.4-3 s: "
             f"are the event times in milliseconds or frame numbers? They must be "
             f"in seconds", RuntimeWarning)
    if not rows:
        return pd.DataFrame({c: pd.Series(dtype=object if c == "side" else float)
                             for c in columns})
    return pd.concat(rows, ignore_index=True)[columns]


def _intervals(starts, ends):
    """Durations from each start to the first end after it that comes before the next start."""
    index = np.searchsorted(ends, starts, side="right")
    ok = index < len(ends)
    following = np.r_[starts[1:], np.inf]
    durations = ends[np.minimum(index, max(len(ends) - 1, 0))] - starts if len(ends) else \
        np.full(len(starts), np.nan)
    ok &= np.where(ok, starts + durations < following, False)
    return durations[ok]


def spatiotemporal_parameters(events, trial=None, markers=None, *, cycles=None):
    r"""Cadence, stride time and stance/swing percentages per side; with the trial, Vicon's
    stride and step lengths, speed, supports and opposite-foot events.

    Parameters
    ----------
    events : dict
        As returned by :func:`gait_events` or :func:`read_events`.
    trial : pandas.DataFrame or path, optional
        The marker trial the events belong to (a .trc or .c3d path, or the DataFrame of
        :func:`read_trc` / :func:`read_c3d`). With `markers`, adds the columns below.
    markers : dict, optional
        Role -> label, as :func:`gait_events` takes it (``PlugInGait.event_markers()``
        gives one): per side the foot marker measured (``'RTOE'``, else ``'RHEEL'``,
        else ``'RANKLE_LAT'``, whichever the trial has: Vicon Nexus's default is the toe)
        and the pelvis markers (``'RASIS'``, ``'LASIS'``, ...) that give the vertical.
    cycles : {'first', 'mean'}, optional
        Which strides a side's values come from. ``'first'``: the first stride of the
        side in which every event is found (this foot's toe-off, the other foot's toe-off
        and heel strike), else its first stride: Vicon Nexus's rule for the ANALYSIS group
        ("the parameters are based on the first cycle for each side where all the
        necessary events are found" [1]_). ``'mean'``: the mean over the side's strides
        (Polygon's "Use Average of Nominated Cycles"). Default: ``'first'`` when `trial`
        is given (the table is then Vicon's gait cycle parameters, value for value),
        ``'mean'`` without it (the table as before the trial could be given).

    Returns
    -------
    pandas.DataFrame
        One row per side with any event, columns:

        - ``strides``: complete strides (heel strike to heel strike);
        - ``stride_time``, ``stride_time_sd`` (s) and ``stride_from``: the mean of the
          complete strides (``'strides'``); without one, stance time + swing time
          (``'stance+swing'``), else twice the mean step time of the trial (both
          sides; ``'steps'``, which assumes symmetric steps); NaN if none is available;
        - ``cadence``: steps per minute, :math:`120 / T_{stride}`;
        - ``stance_time``, ``swing_time``, ``step_time`` (s): heel strike to the next
          toe-off of the same side, toe-off to the next heel strike, and the other
          side's heel strike to this side's next one;
        - ``stance`` and ``swing`` (% of the stride): :math:`100\,t_{stance}/T_{stride}`,
          or :math:`100 - 100\,t_{swing}/T_{stride}` without a stance.

        With `trial` and `markers`, Vicon Nexus's gait cycle parameters [1]_, each from the
        strides `cycles` chooses (heel strike to heel strike):

        - ``stride_length`` (m): the foot marker's displacement from the stride's heel
          strike to the next, along the direction of progression;
        - ``step_length`` (m): from the other foot's marker at its heel strike inside the
          stride to this foot's marker at the stride's end (the step that ends the stride,
          as ``step_time``), along the direction of progression;
        - ``speed`` (m/s): stride length / stride time;
        - ``foot_off``, ``opposite_foot_off``, ``opposite_foot_contact`` (% of the
          stride): this foot's toe-off, the other foot's toe-off and heel strike;
        - ``single_support`` (s): opposite foot off to opposite foot contact (this foot
          alone on the ground);
        - ``double_support`` (s): heel strike to opposite foot off plus opposite foot
          contact to foot off (both feet on the ground); both supports NaN in a stride
          whose events are not in walking's order (opposite foot off, opposite foot
          contact, foot off), as in running.

        The direction of progression is the horizontal part of `events`' ``progression``
        (:func:`gait_events` finds it from the pelvis) or else of the mean stride; the
        vertical is `events`' ``vertical`` or else the lab axis nearest the direction from
        the feet to the pelvis markers. ``attrs['strides']`` holds every stride's values,
        ``attrs['markers']`` the marker measured on each side.

        With ``cycles='first'`` the stride's own times replace the means: ``stride_time``
        (``stride_from`` is ``'first cycle'``), ``cadence``, ``stance_time`` (heel strike
        to foot off), ``swing_time``, ``step_time`` (opposite foot contact to the
        stride's end), ``stance`` and ``swing``; ``strides`` and ``stride_time_sd`` still
        count and spread every stride, and ``attrs['cycle']`` gives each side's (start,
        end) times (s).

    Raises
    ------
    ValueError
        If only one of `trial` and `markers` is given, or the pelvis or foot markers are
        missing from `markers` or mapped to a label the trial lacks, or every event lies
        outside the trial's time, or `cycles` is not one of its values; as
        :func:`read_c3d` / :func:`read_trc` for the trial.

    Warns
    -----
    RuntimeWarning
        When some events lie outside the trial's time (their strides get no length), and
        when heel strikes of the two feet lie within ``MIN_STEP`` (80 ms, as
        :func:`gait_events`) of each other (both feet striking at once): no step time
        is measured there (NaN when no other step is left).

    References
    ----------
    .. [1] Vicon Motion Systems, "How does Nexus (Plug-in Gait) and Polygon calculate Gait
       Cycle Parameters (Spatial and Temporal)?" (support FAQ), and the Vicon glossary's
       "Step length" and "Stride length".

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import spatiotemporal_parameters
    >>> events = {"right": {"heel_strike": np.array([0.1, 1.1, 2.2]),
    ...                     "toe_off": np.array([0.72, 1.76])}}
    >>> print(spatiotemporal_parameters(events).round(3).T)
                  right
    strides           2
    stride_time    1.05
    stride_time_sd 0.071
    stride_from   strides
    cadence      114.286
    stance_time    0.64
    swing_time     0.41
    step_time       NaN
    stance       60.952
    swing        39.048
    """
    if cycles is None:
        cycles = "mean" if trial is None else "first"
    if cycles not in ("first", "mean"):
        raise ValueError(f"cycles must be 'first' (Vicon Nexus's first complete cycle) or "
                         f"'mean' (the mean over the strides); got {cycles!r}")
    table = stride_table(events)
    columns = ["strides", "stride_time", "stride_time_sd", "stride_from", "cadence",
               "stance_time", "swing_time", "step_time", "stance", "swing"]
    checked = {side: {key: _check_events(found.get(key, []), f"events[{side!r}][{key!r}]")
                      for key in EVENTS} for side, found in events.items()}
    rows, all_steps, coincident = {}, [], 0
    for side, found in checked.items():
        strikes, offs = found["heel_strike"], found["toe_off"]
        if not strikes.size and not offs.size:
            continue
        others = np.concatenate([f["heel_strike"] for s, f in checked.items() if s != side]
                                + [np.array([])])
        merged = np.concatenate([strikes, others])
        order = np.argsort(merged, kind="stable")
        mine = np.r_[np.ones(len(strikes), bool), np.zeros(len(others), bool)][order]
        merged = merged[order]
        steps = np.diff(merged)[mine[1:] & ~mine[:-1]]
        together = np.abs(strikes[:, None] - others[None, :]).min(axis=1, initial=np.inf) \
            < MIN_STEP                                  # (strikes, others): a few dozen each
        coincident += int(together.sum())
        ends = merged[1:][mine[1:] & ~mine[:-1]]
        steps = steps[(steps >= MIN_STEP) & ~np.isin(ends, strikes[together])]
        stride = table.loc[table["side"] == side, "stride_time"].to_numpy()
        stance_time = _mean(_intervals(strikes, offs))
        swing_time = _mean(_intervals(offs, strikes))
        step_time = _mean(steps)
        all_steps.append(steps)
        if stride.size:
            stride_time, source = np.mean(stride), "strides"
        elif np.isfinite(stance_time) and np.isfinite(swing_time):
            stride_time, source = stance_time + swing_time, "stance+swing"
        else:
            stride_time, source = np.nan, "steps"
        rows[side] = {"strides": len(stride), "stride_time": stride_time,
                      "stride_time_sd": np.std(stride, ddof=1) if len(stride) > 1 else np.nan,
                      "stride_from": source, "stance_time": stance_time,
                      "swing_time": swing_time, "step_time": step_time}
    if coincident:
        warn(f"{coincident // 2 if len(rows) == 2 else coincident} heel strike(s) of the "
             f"two feet lie within {1000 * MIN_STEP:g} ms of each other (both feet striking "
             "at once: a jump, or one side's events given for both?); no step time is "
             "measured there", RuntimeWarning)
    steps = _mean(np.concatenate(all_steps)) if all_steps else np.nan
    for row in rows.values():
        if row["stride_from"] == "steps":
            row["stride_time"] = 2 * steps
            if not np.isfinite(steps):
                row["stride_from"] = ""
        stride_time = row["stride_time"]
        row["cadence"] = 120.0 / stride_time
        row["stance"] = (100 * row["stance_time"] / stride_time
                         if np.isfinite(row["stance_time"])
                         else 100 - 100 * row["swing_time"] / stride_time)
        row["swing"] = 100 - row["stance"]
    result = pd.DataFrame.from_dict(rows, orient="index", columns=columns)
    if trial is None and markers is None:
        return result if cycles == "mean" else _first_cycle(result, stride_phases(
            checked, table), [])
    return _with_stride_measures(result, checked, table, trial, markers, events, cycles)


#: The columns spatiotemporal_parameters adds from the trial's markers.
STRIDE_MEASURES = ["stride_length", "step_length", "speed", "foot_off", "opposite_foot_off",
                   "opposite_foot_contact", "single_support", "double_support"]


def _with_stride_measures(result, checked, table, trial, markers, events, cycles):
    """`result` with STRIDE_MEASURES per side (`cycles`: the first cycle's or the means),
    every stride in attrs."""
    if trial is None or markers is None:
        raise ValueError("trial and markers go together: the stride and step lengths need "
                         "the marker trial and the role mapping (as gait_events takes it; "
                         f"got trial={'None' if trial is None else '...'}, markers="
                         f"{'None' if markers is None else '...'})")
    phases = stride_phases(checked, table)
    strides, used = stride_distances(phases, trial, markers,
                                     vertical=getattr(events, "vertical", None),
                                     progression=getattr(events, "progression", None))
    means = side_means(strides, STRIDE_MEASURES).reindex(result.index)
    result = pd.concat([result, means], axis=1)
    if cycles == "first":
        result = _first_cycle(result, strides, STRIDE_MEASURES)
    result.attrs["strides"] = strides.reset_index(drop=True)
    result.attrs["markers"] = used
    return result


#: The events a cycle needs for Vicon Nexus to report its parameters (Vicon's FAQ [1]_
#: of :func:`spatiotemporal_parameters`): this foot's off, the other foot's off and contact.
CYCLE_EVENTS = ["foot_off_time", "opposite_foot_off_time", "opposite_foot_contact_time"]


def _first_cycle(result, phases, measures):
    """`result` with each side's times, and `measures`, from its first stride with every
    CYCLE_EVENTS (else its first stride): Vicon Nexus's rule."""
    result = result.copy()
    result.attrs["cycle"] = {}
    complete = phases[CYCLE_EVENTS].notna().all(axis=1)
    for side in result.index:                                  # a loop over the sides
        own = phases[phases["side"] == side].sort_values("start")
        if own.empty:
            continue
        chosen = own[complete[own.index]]
        cycle = (chosen if len(chosen) else own).iloc[0]
        stride = cycle["end"] - cycle["start"]
        stance = cycle["foot_off_time"] - cycle["start"]
        values = {"stride_time": stride, "stride_from": "first cycle",
                  "cadence": 120.0 / stride, "stance_time": stance,
                  "swing_time": cycle["end"] - cycle["foot_off_time"],
                  "step_time": cycle["end"] - cycle["opposite_foot_contact_time"],
                  "stance": 100.0 * stance / stride, "swing": 100.0 - 100.0 * stance / stride}
        values.update({name: cycle[name] for name in measures})
        for name, value in values.items():
            result.loc[side, name] = value
        result.attrs["cycle"][side] = (float(cycle["start"]), float(cycle["end"]))
    return result


def _mean(values):
    """Mean of an array, NaN (without a warning) when it is empty."""
    return float(np.mean(values)) if len(values) else np.nan
