r"""Force plates first: the plates' events of a trial, and the marker events calibrated on them.

Two steps that :func:`~bmc_functions.gait.events.gait_events` takes when it is given force
plates (``force_plates=``):

- :func:`plate_reference_events`: where a foot stands on a plate alone, its heel strike and
  toe-off are the first and last loaded analog samples (the contacts of
  :func:`~bmc_functions.files.force_plates.assign_plates`);
- :func:`calibrate_events`: those plate events replace the marker events they match, and
  the marker detector's systematic offset on this trial (the median of marker minus plate
  over the matched events, per kind of event) is removed from the marker events the plates
  do not see.

Arrays and dicts in, dicts out: :func:`~bmc_functions.gait.events.gait_events` wraps the
result in its :class:`~bmc_functions.gait.events.GaitEvents`.
"""

import os
import warnings

import numpy as np
import pandas as pd

from .._checks import ArgumentTypeError, check_number
from ..files.force_plates import assign_plates, read_force_plates

EVENTS = ("heel_strike", "toe_off")

#: Largest time (s) between a marker event and the plate event it is matched to: half the
#: shortest stride accepted (``events.MIN_STRIDE`` = 0.3 s), so that no two events of one
#: kind and side can match the same plate event.
MATCH_TOLERANCE = 0.15


def plates_of(force_plates, dynamic):
    """The plates' DataFrame (:func:`~bmc_functions.files.force_plates.read_force_plates`)
    that `force_plates` names, None for None.

    ``True`` or ``'file'``: the plates of `dynamic`, which must then be a ``.c3d`` path; a
    path: that C3D file's plates; a DataFrame: as read_force_plates returns it.
    """
    if force_plates is None or force_plates is False:
        return None
    if force_plates is True or (isinstance(force_plates, str) and force_plates == "file"):
        if not isinstance(dynamic, (str, os.PathLike)) or \
                not os.fspath(dynamic).lower().endswith(".c3d"):
            raise ValueError(f"force_plates={force_plates!r} reads the plates of the C3D file "
                             f"given as dynamic; got dynamic of type {type(dynamic).__name__}"
                             ": pass read_force_plates(path) (or the path) as force_plates")
        force_plates = dynamic
    if isinstance(force_plates, (str, os.PathLike)):
        with warnings.catch_warnings():   # an unzeroed plate: assign_plates removes its offset
            warnings.simplefilter("ignore", RuntimeWarning)
            return read_force_plates(force_plates, zero="none")
    if isinstance(force_plates, pd.DataFrame) and "plates" in force_plates.attrs:
        return force_plates
    raise ArgumentTypeError(f"force_plates must be None, True, 'file', a C3D path or the "
                            f"DataFrame read_force_plates returns; got "
                            f"{type(force_plates).__name__}")


def plate_reference_events(plates, trial, feet):
    """The heel strikes and toe-offs the plates time: ``{side: {event: times}}`` (s, on
    the trial's time axis, to the analog sample) for the sides of `feet` (side -> labels
    of the foot's markers). A contact loaded at the first (last) analog sample has no
    heel strike (toe-off); a contact no single foot stood on gives none (warned once by
    :func:`~bmc_functions.files.force_plates.assign_plates`)."""
    contacts = assign_plates(plates, trial, feet)
    last = (len(plates) - 1) / plates.attrs["rate"]
    events = {side: {event: [] for event in EVENTS} for side in feet}
    for row in contacts.itertuples():              # loop over contacts (a few), not frames
        if row.side is None or row.side not in events:
            continue
        if row.start > 0:
            events[row.side]["heel_strike"].append(row.start)
        if row.stop < last:
            events[row.side]["toe_off"].append(row.stop)
    return {side: {event: np.sort(np.asarray(times, dtype=float))
                   for event, times in found.items()} for side, found in events.items()}


def _matches(detected, reference, tolerance):
    """Pairs (i, j) of detected[i] and reference[j] within `tolerance`, one to one,
    nearest first."""
    if not detected.size or not reference.size:
        return []
    gap = np.abs(detected[:, None] - reference[None, :])
    order = np.argsort(gap, axis=None)
    pairs, used_i, used_j = [], set(), set()
    for flat in order[:np.count_nonzero(gap <= tolerance)]:   # loop over close pairs
        i, j = np.unravel_index(flat, gap.shape)
        if i not in used_i and j not in used_j:
            pairs.append((int(i), int(j)))
            used_i.add(i)
            used_j.add(j)
    return pairs


def calibrate_events(detected, reference, *, tolerance=MATCH_TOLERANCE):
    r"""Plate events first; the marker events the plates do not see, with the detector's
    offset on this trial removed.

    Parameters
    ----------
    detected : dict
        ``{side: {event: times}}`` from the markers (s).
    reference : dict
        ``{side: {event: times}}`` from the force plates (s), e.g.
        :func:`plate_reference_events`.
    tolerance : float, optional
        Largest time (s) between a marker event and the plate event that replaces it
        (default ``MATCH_TOLERANCE`` = 0.15 s, half the shortest stride).

    Returns
    -------
    events : dict
        ``{side: {event: times}}``, sorted: every plate event, and every marker event no
        plate event lies within `tolerance` of, minus the offset of its kind.
    source : dict
        ``{side: {event: array of str}}``, beside `events`: ``'force plate'`` or
        ``'markers'``.
    calibration : dict
        Per event kind: ``offset_ms`` (the median of marker minus plate time over the
        matched events of both sides, ms; 0.0 when none matched, and then nothing is
        corrected) and ``matched`` (how many).

    Notes
    -----
    A kinematic detector's timing error against a force plate is mostly a constant of the
    subject, the marker set and the method (the heel's forward maximum comes 35-95 ms
    before the plate's contact on the trials of tools/validate_gait_events.py, depending on
    the trial; Zeni et al., 2008, reported a consistent bias too). Measured on the
    trial's own plates, it is removed from the events the plates do not see: the
    median over both sides (robust to one mismatched event), per kind of event.
    Leave-one-out on the shared trials (each plate event hidden in turn, the offset
    measured on the others, the hidden one predicted): ``tools/validate_gait_events.py
    --calibration``.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.gait.plate_events import calibrate_events
    >>> markers = {"right": {"heel_strike": np.array([0.96, 2.07, 3.16]),
    ...                      "toe_off": np.array([])}}
    >>> plates = {"right": {"heel_strike": np.array([1.0, 2.1]), "toe_off": np.array([])}}
    >>> events, source, calibration = calibrate_events(markers, plates)
    >>> print(events["right"]["heel_strike"], source["right"]["heel_strike"])
    [1.   2.1  3.195] ['force plate' 'force plate' 'markers']
    >>> print(calibration["heel_strike"])
    {'offset_ms': -35.0, 'matched': 2}
    """
    tolerance = check_number(tolerance, "tolerance", positive=True)
    pairs = {event: {} for event in EVENTS}
    offsets = {event: [] for event in EVENTS}
    for side, found in detected.items():
        for event in EVENTS:
            mine = np.asarray(found.get(event, []), dtype=float)
            plate = np.asarray(reference.get(side, {}).get(event, []), dtype=float)
            pairs[event][side] = _matches(mine, plate, tolerance)
            offsets[event] += [mine[i] - plate[j] for i, j in pairs[event][side]]
    calibration = {event: {"offset_ms": round(1000 * float(np.median(offsets[event])), 1)
                           if offsets[event] else 0.0, "matched": len(offsets[event])}
                   for event in EVENTS}
    events, source = {}, {}
    for side in dict.fromkeys([*detected, *reference]):
        events[side], source[side] = {}, {}
        for event in EVENTS:
            mine = np.asarray(detected.get(side, {}).get(event, []), dtype=float)
            plate = np.asarray(reference.get(side, {}).get(event, []), dtype=float)
            near = (np.abs(mine[:, None] - plate[None, :]) <= tolerance).any(axis=1) \
                if plate.size else np.zeros(mine.shape, bool)
            alone = mine[~near] - calibration[event]["offset_ms"] / 1000.0
            times = np.concatenate([plate, alone])
            kinds = np.array(["force plate"] * plate.size + ["markers"] * alone.size)
            order = np.argsort(times, kind="stable")
            events[side][event], source[side][event] = times[order], kinds[order]
    return events, source, calibration
