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

from .._checks import ArgumentTypeError, check_number, warn
from ..files._c3d_binary import require_ezc3d
from ..files.c3d import read_c3d
from ..files.force_plates import (CONTACT_THRESHOLD, FORCE_CUTOFF, MAX_TRAVEL,  # noqa: F401
                                  MIN_CONTACT, PLATE_MARGIN, feet_on_plate, loaded_runs,
                                  over_plate, plate_contacts, plate_forces,
                                  read_force_plates)
from ..files.trial import mm_per_unit
from .events import SIDES, GaitEvents, checked_event_times, match_events

#: Vertical force (N) above which a foot is on a plate (see
#: :data:`bmc_functions.files.force_plates.CONTACT_THRESHOLD`).
FORCE_THRESHOLD = CONTACT_THRESHOLD

#: Foot roles whose markers locate a foot over a plate (those present are used).
FOOT_ROLES = ("HEEL", "TOE", "MT5", "ANKLE_LAT")

# the steps, under the names the tests of the documented boundaries use
_loaded_runs, _feet_on_plate, _over_plate = loaded_runs, feet_on_plate, over_plate


def _read_plates(path):
    """Forces (n_plates, 3, n_analog) in the lab frame, corners (n_plates, 3, 4) in mm,
    the analog and point rates, from :func:`read_force_plates` (which refuses damaged
    plate data, unknown plate types and missing corners)."""
    require_ezc3d("force_plate_events")
    with warnings.catch_warnings():       # an unzeroed plate: its offset is removed here
        warnings.simplefilter("ignore", RuntimeWarning)
        plates = read_force_plates(path, zero="none")
    forces = np.stack(plate_forces(plates))
    corners = np.stack([np.asarray(p["corners"]).T for p in plates.attrs["plates"]])
    return forces, corners, plates.attrs["rate"], plates.attrs["point_rate"]


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
        If the file has no force plate, a plate of a type other than 1-4, corners all
        zero or damaged analog data (:func:`read_force_plates`), or `threshold` or
        `min_contact` is not a positive number, or `trial` has another rate than the
        file's markers.
    TypeError
        If `markers` is not a mapping, or `trial` is not a marker DataFrame.

    Warns
    -----
    RuntimeWarning
        When no plate is loaded at all (no events);
        Once, naming the contacts left out because no foot, or both feet, stood over the
        plate, or the foot stood on two plates at once (the plate cannot say whose load
        it carries alone).

    Notes
    -----
    :func:`read_force_plates` gives each plate's force in the lab frame from its channels
    (read with ezc3d [1]_; positions in mm whatever the file's unit, and the trial's
    markers are converted from its ``attrs['units']``).
    The contacts and the foot on each are :func:`assign_plates`' rule: the component
    along the plate's normal (from its corners) is low-pass filtered (4th-order
    zero-lag Butterworth, ``FORCE_CUTOFF`` = 50 Hz), its offset removed (the median of
    the samples within the threshold of the level of the lowest or the highest
    samples, whichever is nearer zero, refined twice), and a
    contact is each run
    above the threshold lasting ``MIN_CONTACT`` or more. The foot on the plate is the
    side whose foot markers (mean of those mapped) lie over the plate, within
    ``PLATE_MARGIN`` (50 mm) of its edges, on average over the middle half of the
    contact, and move less than ``MAX_TRAVEL`` (150 mm) meanwhile (the swing foot passes
    over the plate too, half a stride or more in that time); a foot over two plates
    loaded at the same time is assigned to neither (one foot, one strike).

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
    found = plate_contacts(forces, corners, (analog_rate, point_rate), feet,
                           threshold=threshold, min_contact=min_contact)
    for plate, side, start, stop, reason in found:
        t_start, t_stop = start / analog_rate, (stop - 1) / analog_rate
        contacts.append((plate, side, t_start, t_stop))
        if side is None:
            unknown.append(f"plate {plate} at {t_start:.3f}-{t_stop:.3f} s ({reason})")
            continue
        if start > 0:
            events[side]["heel_strike"].append(t_start)
        if stop < forces.shape[2]:
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
    """Per side, the mean (frames, 3) of the foot markers mapped and in the trial, in mm
    (the plates' unit) whatever the trial's unit (mm when its attrs say none)."""
    scale = mm_per_unit(trial, "trial")[0] if "units" in trial.attrs else 1.0
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
                feet[side] = scale * np.nanmean(points, axis=0)
    if not feet:
        raise ValueError("markers: no foot role (HEEL, TOE, MT5 or ANKLE_LAT of R or L) "
                         "maps to a label of the file; the plates cannot tell whose foot "
                         "they carry")
    return feet


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
