r"""Force plates: the reference gait events of a C3D trial, and how marker events compare.

A foot is on a force plate while the plate's vertical force exceeds a small threshold;
its first and last instants above it are the foot strike and the foot off that gait
events from markers are judged against (:func:`force_plate_events`).
:func:`compare_events` matches detected events to reference events and gives, per side
and event, the share found and the median and largest timing error: the table a
validation reports.
"""

import os
import warnings
from collections.abc import Mapping

import numpy as np
import pandas as pd
from scipy.signal import butter

from .._checks import ArgumentTypeError, check_number, warn
from ..files._c3d_binary import read_checked
from ..files.c3d import read_c3d
from ..markers.filtering import filter_runs
from .events import SIDES, GaitEvents, checked_event_times, match_events

#: Vertical force (N) above which a foot is on a plate. Laboratories use 10-50 N; 20 N
#: lies six standard deviations above the noise of the unloaded plates here after the
#: low-pass filter (0.5-3.5 N; 0.4-9 N unfiltered) and far below a foot's load.
FORCE_THRESHOLD = 20.0

#: Shortest loaded interval (s) taken as a foot contact: a walking stance lasts 0.5 s or
#: more, a sprinter's about 0.1 s; a shorter crossing is noise, a bump or a swing-foot tap.
MIN_CONTACT = 0.08

#: Low-pass cut-off (Hz) of the plate forces before the threshold: the mains hum (50-60
#: Hz) and plate noise lie at or above it, while the load of a foot strike rises over
#: 10-30 ms (zero-lag: the crossings stay within 15 ms of the raw channel's, tested).
FORCE_CUTOFF = 50.0

#: A foot is on a plate when its markers lie over the plate's top within this margin (mm).
PLATE_MARGIN = 50.0

#: A foot that stands on a plate moves less than this (mm, horizontally) over the middle
#: half of the contact; the swing foot passing beside it moves half a stride or more.
MAX_TRAVEL = 150.0

#: Foot roles whose markers locate a foot over a plate (those present are used).
FOOT_ROLES = ("HEEL", "TOE", "MT5", "ANKLE_LAT")


def _extract_plates(source):
    """Forces, corners and rates read with ezc3d (plain NumPy objects)."""
    import ezc3d

    c3d = ezc3d.c3d(str(source), extract_forceplat_data=True)
    params = c3d["parameters"]
    plates = c3d["data"].get("platform", [])
    return {
        "forces": [np.asarray(p["force"], dtype=float) for p in plates],
        "corners": [np.asarray(p["corners"], dtype=float) for p in plates],
        "analog_rate": float(np.ravel(params["ANALOG"]["RATE"]["value"])[0]),
        "point_rate": float(np.ravel(params["POINT"]["RATE"]["value"])[0]),
    }


def _read_plates(path):
    """Forces (n_plates, 3, n_analog) in the lab frame, corners (n_plates, 3, 4), the
    analog and point rates, read with ezc3d in a child process after the structure
    checks of read_c3d."""
    info = read_checked(path, _extract_plates, "force_plate_events")
    if not info["forces"]:
        raise ValueError(f"{path}: no force plate in the file (FORCE_PLATFORM:USED is 0 or "
                         "missing)")
    return (np.array(info["forces"]), np.array(info["corners"]), info["analog_rate"],
            info["point_rate"])


def _loaded_runs(vertical, rate, threshold, min_contact):
    """Start and stop sample indices of the runs above `threshold` lasting `min_contact`."""
    above = np.concatenate(([False], vertical > threshold, [False]))
    edges = np.flatnonzero(np.diff(above.astype(np.int8)))
    starts, stops = edges[0::2], edges[1::2]
    keep = (stops - starts) >= min_contact * rate
    return starts[keep], stops[keep]


def force_plate_events(path, markers, *, threshold=FORCE_THRESHOLD, min_contact=MIN_CONTACT,
                       trial=None):
    r"""Foot strikes and foot offs of each side from the force plates of a C3D file.

    Parameters
    ----------
    path : str or path-like
        A ``.c3d`` file with a FORCE_PLATFORM group and its analog channels.
    markers : dict
        Role -> label, as for :func:`gait_events`; the foot roles ``'HEEL'``, ``'TOE'``,
        ``'MT5'`` and ``'ANKLE_LAT'`` (prefix ``R``/``L``) that are mapped say which foot
        is on a plate.
    threshold : float, optional
        Vertical force (N) above which a foot is on a plate (default 20 N).
    min_contact : float, optional
        Shortest contact (s) kept (default 0.08 s).
    trial : pandas.DataFrame, optional
        The markers of the file as returned by :func:`read_c3d` (read from `path` when
        not given).

    Returns
    -------
    GaitEvents
        ``events[side]["heel_strike"]`` (foot strikes) and ``["toe_off"]`` (foot offs),
        times in s on the time axis of :func:`read_c3d` (0 at the first frame). A contact
        loaded at the start (end) of the recording has no strike (off). ``method`` says
        how they were found; ``contacts`` lists every contact as (plate, side, start,
        end), side None when it could not be told.

    Raises
    ------
    ValueError
        If the file has no force plate, or `threshold` or `min_contact` is not a positive
        number, or `trial` has another rate than the file's markers.
    TypeError
        If `markers` is not a mapping, or `trial` is not a marker DataFrame.

    Warns
    -----
    RuntimeWarning
        When no plate is loaded at all (no events);
        Once, naming the contacts left out because no foot, or both feet, stood over the
        plate (the plate cannot say whose they are).

    Notes
    -----
    ezc3d [1]_ turns each plate's analog channels into the force in the lab frame. The
    component along the plate's normal (from its corners) is low-pass filtered (4th-order
    zero-lag Butterworth, ``FORCE_CUTOFF`` = 50 Hz), its offset removed (the median of the
    samples below the threshold, then recomputed once), and a contact is each run above
    the threshold lasting ``MIN_CONTACT`` or more. The foot on the plate is the side
    whose foot markers (mean of those mapped) lie over the plate, within
    ``PLATE_MARGIN`` (50 mm) of its edges, on average over the middle half of the
    contact, and move less than ``MAX_TRAVEL`` (150 mm) meanwhile (the swing foot passes
    over the plate too, half a stride or more in that time).

    References
    ----------
    .. [1] Michaud B, Begon M (2021). ezc3d: An easy C3D file I/O cross-platform solution
       for C++, Python and MATLAB. Journal of Open Source Software 6(58), 2911.
    """
    if not isinstance(markers, Mapping):
        raise ArgumentTypeError(f"markers must be a dict mapping roles to labels (as for "
                        f"gait_events); got {type(markers).__name__}")
    threshold = check_number(threshold, "threshold", positive=True)
    min_contact = check_number(min_contact, "min_contact", positive=True)
    forces, corners, analog_rate, point_rate = _read_plates(path)
    trial = _marker_trial(path, trial, point_rate)
    feet = _foot_centres(trial, markers)
    events = {side: {"heel_strike": [], "toe_off": []} for side in feet}
    contacts, unknown = [], []
    for plate in range(len(forces)):               # loop over plates (a few), not frames
        normal_force, normal = _normal_force(forces[plate], corners[plate], analog_rate,
                                             threshold)
        for start, stop in zip(*_loaded_runs(normal_force, analog_rate, threshold,
                                             min_contact)):
            side, over = _foot_on_plate(feet, corners[plate], normal, start, stop,
                                        (analog_rate, point_rate), len(trial))
            t_start, t_stop = start / analog_rate, (stop - 1) / analog_rate
            contacts.append((plate + 1, side, t_start, t_stop))
            if side is None:
                unknown.append(f"plate {plate + 1} at {t_start:.3f}-{t_stop:.3f} s "
                               f"({'both feet' if over else 'no foot'} over it)")
                continue
            if start > 0:
                events[side]["heel_strike"].append(t_start)
            if stop < len(normal_force):
                events[side]["toe_off"].append(t_stop)
    if not contacts:
        warn(f"{path}: no foot contact on any of the {len(forces)} force plates "
             f"(vertical force never above {threshold:g} N for "
             f"{1000 * min_contact:g} ms): no events", RuntimeWarning)
    if unknown:
        warn(f"{path}: {len(unknown)} force-plate contact(s) left out: "
             + "; ".join(unknown), RuntimeWarning)
    result = GaitEvents({side: {key: np.sort(np.asarray(times, dtype=float))
                                for key, times in found.items()}
                         for side, found in events.items()},
                        gait=None,
                        method=f"force plates: vertical force above {threshold:g} N "
                               f"for {1000 * min_contact:g} ms or more",
                        source=os.fspath(path))
    result.contacts = contacts
    return result


def _marker_trial(path, trial, point_rate):
    """The markers of the file: `trial` checked against its rate, or read from `path`."""
    if trial is None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return read_c3d(path)
    if not isinstance(trial, pd.DataFrame) or not isinstance(trial.columns, pd.MultiIndex):
        raise TypeError(f"trial must be the marker DataFrame read_c3d returns for {path}; "
                        f"got {type(trial).__name__}")
    rate = trial.attrs.get("rate")
    if rate is None or not np.isclose(float(rate), point_rate, rtol=1e-6):
        raise ValueError(f"trial: its rate ({rate} Hz) is not the marker rate of {path} "
                         f"({point_rate:g} Hz); give read_c3d of that file (or nothing)")
    return trial


def _foot_centres(trial, markers):
    """Per side, the mean (frames, 3) of the foot markers mapped and in the trial."""
    labels = set(trial.columns.get_level_values(0))
    feet = {}
    for side, prefix in SIDES.items():
        points = [trial[markers[prefix + role]][["x", "y", "z"]].to_numpy(float)
                  for role in FOOT_ROLES
                  if isinstance(markers.get(prefix + role), str)
                  and markers[prefix + role] in labels]
        if points:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                feet[side] = np.nanmean(points, axis=0)
    if not feet:
        raise ValueError("markers: no foot role (HEEL, TOE, MT5 or ANKLE_LAT of R or L) "
                         "maps to a label of the file; the plates cannot tell whose foot "
                         "they carry")
    return feet


def _normal_force(force, corners, analog_rate, threshold):
    """The magnitude of a plate's force (3, samples) along its normal, low-pass filtered
    (FORCE_CUTOFF) and with the unloaded plate's offset removed; and the unit normal."""
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.linalg.norm(normal)
    design = butter(2, min(FORCE_CUTOFF, 0.4 * analog_rate), fs=analog_rate, output="sos")
    along = filter_runs((normal @ force)[:, None], design)[0][:, 0]
    offset = np.median(along)                       # the plate's zero: unloaded samples
    offset = np.median(along[np.abs(along - offset) < threshold])
    return np.abs(along - offset), normal


def _foot_on_plate(feet, corners, normal, start, stop, rates, n_frames):
    """The side whose foot stands over the plate during the contact of analog samples
    [start, stop) (None unless exactly one), and the sides found over it; `rates` are
    the analog and the marker rates (Hz)."""
    analog_rate, point_rate = rates
    # the middle half of the contact, in marker frames
    first, last = np.clip(np.round(np.array([0.75 * start + 0.25 * stop,
                                             0.25 * start + 0.75 * stop])
                                   / analog_rate * point_rate).astype(int), 0, n_frames - 1)
    centre = corners.mean(axis=1)
    over = []
    for side, foot in feet.items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            where = np.nanmean(foot[first:last + 1], axis=0) - centre
        travel = foot[last] - foot[first]
        travel = np.linalg.norm(travel - (travel @ normal) * normal)
        horizontal = where - (where @ normal) * normal
        if (np.all(np.isfinite(horizontal)) and not travel > MAX_TRAVEL
                and _over_plate(horizontal, corners, centre, normal)):
            over.append(side)
    return (over[0] if len(over) == 1 else None), over


def _over_plate(horizontal, corners, centre, normal):
    """Whether a point (relative to the plate centre, in the plate's plane) lies over the
    plate's rectangle, within PLATE_MARGIN."""
    edge_u = corners[:, 0] - corners[:, 1]
    edge_v = corners[:, 1] - corners[:, 2]
    half_u, half_v = 0.5 * np.linalg.norm(edge_u), 0.5 * np.linalg.norm(edge_v)
    return (abs(horizontal @ (edge_u / (2 * half_u))) <= half_u + PLATE_MARGIN
            and abs(horizontal @ (edge_v / (2 * half_v))) <= half_v + PLATE_MARGIN)


def compare_events(detected, reference, *, tolerance=0.1, trial=None):
    r"""Match detected gait events to reference events; the found share and the errors.

    Parameters
    ----------
    detected, reference : dict
        Events as returned by :func:`gait_events` / :func:`force_plate_events`:
        ``events[side][event]`` arrays of times (s). Sides and events may be spelled
        as in a C3D file ('Right', 'Foot Strike', 'heel strike'): case, spaces, '_' and
        '-' are ignored.
    tolerance : float, optional
        A reference event is found when a detected event of the same side and kind lies
        within this many seconds (default 0.1 s; 0.06 s suits running). Events are
        paired one-to-one (a detected event counts for one reference event at most).
    trial : str, optional
        A name put in a first column ``'trial'`` (for tables of several trials).

    Returns
    -------
    pandas.DataFrame
        One row per side and event of `reference` that has events, and one row per
        event over both sides (side ``'both'``), with columns ``reference`` (count),
        ``found`` (count), ``found_%``, ``median_ms`` and ``max_ms`` (of the absolute
        errors of the found events, ms) and ``bias_ms`` (median signed error, detected
        minus reference: negative = early).

    Raises
    ------
    TypeError
        If `detected` or `reference` is not a dict of dicts.
    ValueError
        If a time is not a finite number, or `tolerance` not a positive number.

    Warns
    -----
    RuntimeWarning
        When the two sets' median times differ by a factor of 100 or more (one in ms).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import compare_events
    >>> ref = {"right": {"heel_strike": np.array([1.0, 2.0]), "toe_off": np.array([1.6])}}
    >>> det = {"right": {"heel_strike": np.array([0.98, 2.03]), "toe_off": np.array([1.9])}}
    >>> table = compare_events(det, ref)
    >>> print(table[["side", "event", "found_%", "median_ms", "max_ms"]].to_string(index=False))
     side       event  found_%  median_ms  max_ms
    right heel_strike    100.0       25.0    30.0
    right     toe_off      0.0        NaN     NaN
     both heel_strike    100.0       25.0    30.0
     both     toe_off      0.0        NaN     NaN
    """
    tolerance = check_number(tolerance, "tolerance", positive=True)
    detected, reference = checked_event_times(detected, "detected"), checked_event_times(reference,
                                                                           "reference")
    _check_same_units(detected, reference)
    rows, errors = [], {}
    for side, found in reference.items():
        for event, times in found.items():
            times = np.asarray(times, dtype=float)
            mine = np.asarray(detected.get(side, {}).get(event, []), dtype=float)
            if times.size == 0:
                continue
            error = match_events(mine, times, tolerance)  # one-to-one
            hit = np.abs(error) <= tolerance
            errors.setdefault(event, []).append(error[hit])
            errors.setdefault(("n", event), []).append(times.size)
            rows.append(_row(side, event, times.size, error[hit]))
    for event in ("heel_strike", "toe_off"):
        if event in errors:
            rows.append(_row("both", event, sum(errors[("n", event)]),
                             np.concatenate(errors[event])))
    table = pd.DataFrame(rows, columns=["side", "event", "reference", "found", "found_%",
                                        "median_ms", "max_ms", "bias_ms"])
    if trial is not None:
        table.insert(0, "trial", trial)
    return table


def _check_same_units(detected, reference):
    """Warn when one set of times is about 1000 times the other (ms against s)."""
    def median(events):
        times = [t for found in events.values() for t in found.values()]
        times = np.concatenate(times) if times else np.zeros(0)
        return float(np.median(times)) if times.size else np.nan
    found, expected = median(detected), median(reference)
    if found > 0 and expected > 0 and not 0.01 < found / expected < 100:
        warn(f"the detected events (median {found:.4g}) and the reference events "
             f"(median {expected:.4g}) differ by a factor of "
             f"{max(found / expected, expected / found):.3g}: are both in seconds (one in "
             f"ms or frames?)", RuntimeWarning)


def _row(side, event, n_reference, hit_errors):
    ms = 1000.0 * hit_errors
    return {"side": side, "event": event, "reference": n_reference, "found": ms.size,
            "found_%": round(100.0 * ms.size / n_reference, 1),
            "median_ms": round(float(np.median(np.abs(ms))), 1) if ms.size else np.nan,
            "max_ms": round(float(np.max(np.abs(ms))), 1) if ms.size else np.nan,
            "bias_ms": round(float(np.median(ms)), 1) if ms.size else np.nan}
