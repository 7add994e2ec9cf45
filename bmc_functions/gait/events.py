r"""Gait events: heel strike and toe-off of each side from the foot and pelvis markers.

The step of the applied path (files -> markers -> segments -> joints -> gait cycles) that
times the cycles:

- :class:`GaitEvents` holds a trial's events (``events[side][event]``, sorted times in
  s) and what the detection found: walking or running, the lab's vertical and direction
  of progression, the markers that timed each event;
- :func:`gait_events` finds them from the foot markers (heel, toe, MT5, lateral
  malleolus: those the foot has) and the pelvis, in walking and running, overground and
  on a treadmill. Its steps: the roles resolved (the pelvis of
  :func:`~bmc_functions.markers.roles.pelvis_roles`, the markers of each foot), the
  lab's vertical and direction of progression found from the data, Zeni et al.'s
  coordinate events refined by the foot markers' accelerations where the foot rests on
  a floor, and the checks of the trial (units, rate, direction of travel, sides, level
  ground, alternation of the feet, missing events).

:mod:`~bmc_functions.gait.cycles` cuts signals into the cycles these events bound;
:mod:`~bmc_functions.gait.force_plates` gives the force plates' events to judge them by,
:mod:`~bmc_functions.gait.event_files` reads and writes events stored beside a trial.

References (the full list, with what each method is used for, in :func:`gait_events`):
Zeni JA, Richards JG, Higginson JS (2008) Gait & Posture 27(4):710-714 (coordinate
events); Hreljac A, Marshall RN (2000) J Biomech 33(6):783-786 (walking);
Handsaker JC et al. (2016) J Biomech 49(16):4128-4133 (running); Cavagna GA, Heglund NC,
Taylor CR (1977) Am J Physiol 233(5):R243-R261 (walking or running); Novacheck TF (1998)
Gait & Posture 7(1):77-95 (floor contact); Winter DA (2009) Biomechanics and Motor
Control of Human Movement, 4th ed., ch. 4 (pelvis height).
"""

import warnings
from collections.abc import Mapping

import numpy as np
import pandas as pd
from scipy.optimize import linear_sum_assignment
from scipy.signal import butter, find_peaks

from .._checks import (ArgumentTypeError, as_float_array, check_choice, check_finite_or_nan,
                       check_flag, check_number, check_rate_attr, warn)
from ..files.marker_table import check_numeric_columns
from ..files.trial import load_trial, mm_per_unit
from ..markers.filtering import corrected_cutoff, filter_runs
from ..markers.roles import (check_known_roles, check_labels, check_shared_labels, describe,
                             pelvis_roles)
from .plate_events import calibrate_events, plate_reference_events, plates_of

SIDES = {"right": "R", "left": "L"}
EVENTS = ("heel_strike", "toe_off")

#: Largest share of the Nyquist frequency (half the rate) accepted as a cut-off: a rate
#: inferred from a time index rounded to the millisecond or carrying float rounding errors
#: can be that far above the true one, and a cut-off at the true Nyquist frequency gives
#: a degenerate filter (normalised frequency 1) that returns the noise unfiltered.
NYQUIST_SHARE = 0.99

#: Shortest stride accepted between two events of the same kind and side (s): a sprinter's
#: stride lasts about 0.45 s, so two heel strikes of one foot closer than this are noise.
MIN_STRIDE = 0.3

#: A touchdown or toe-off found in running must have a foot marker (the toe at toe-off)
#: within this height (mm) of its floor for that contact (its low level within
#: LANDING_TIME of a touchdown, over the stance a toe-off ends: on stairs each step has
#: its own): an acceleration or jerk peak with the foot high in the air (a toe-off before
#: the trial began) is not an event. A heel strike in the first frames needs a foot marker
#: within this height of its floor at the contact too (:func:`_lands_in_data`).
NEAR_FLOOR = 25.0

#: A heel strike (toe-off) must put the heel ahead of (the toe behind) the pelvis at least
#: this far (mm) beyond the signal's low level (its 5th percentile): a step moves the foot
#: 0.3 m or more relative to the pelvis even in slow gait, standing sway a few mm. Without
#: it, the noise of a standing trial gives "events" every MIN_STRIDE.
MIN_EXCURSION = 100.0

#: The distance between two markers of one foot (heel-toe, heel-MT5) changes by less than a
#: few mm from one frame to the next (4 mm at most in the trials of this project, foot
#: deformation included); a jump of more than this (mm) is a swapped or mislabelled marker.
FOOT_JUMP = 15.0

#: Low-pass cut-off (Hz) of the foot markers before they are differentiated: the
#: accelerations that time the events need it. The cut-off means what it means for
#: :func:`~bmc_functions.lowpass`: the whole zero-lag filter (both passes) attenuates it
#: by 3 dB. 12 Hz is where the former default (15 Hz per pass, before issue 31) put it
#: (12.2 Hz), so the validated events stay; the same value in the per-pass meaning moves
#: the walking toe-offs of the Codamotion walk 12 ms later (tools/validate_gait_events.py).
#: On that walk 10-15 Hz give the same heel strikes within a frame, 6 Hz delays them by
#: about 10 ms; 0.4 times the rate when that is lower.
CUTOFF = 12.0

#: Walking heel strike: the search window (ms before, after Zeni's heel strike). Zeni's
#: heel strike comes 55-95 ms before the force plate's on the real trials here (55-74 ms on
#: the level walk, 88-94 ms on the stair descent: tools/validate_gait_events.py; the heel's
#: forward maximum precedes contact, and on stairs the forefoot lands later still: 135 ms
#: after it at one contact). The far end is rounded outwards to a frame (at 50 Hz 150 ms
#: spans 8 frames, not 7, which cut that contact's acceleration peak); the near end to the
#: nearest frame (rounded outwards too, it moved five heel strikes of the walks without
#: heel markers at 50 Hz by 20-40 ms and dropped one).
STRIKE_WINDOW = (50.0, 150.0)

#: Walking toe-off: the search window (ms before, after Zeni's toe-off), which falls
#: within about 35 ms of the force plate's on the real trials here.
OFF_WINDOW = (100.0, 100.0)

#: Median speed (mm/s) against the way the body faces above which a trial walks backwards:
#: the slowest forward walking studied clinically is about 400 mm/s.
MIN_SPEED = 150.0

#: A foot marker whose median lateral offset from the pelvis centre lies this far (mm) on
#: the other side is on the wrong side: feet land 50-150 mm to their own side of the
#: midline in walking, near it in running (a crossover runner's foot rarely beyond 20 mm).
MIN_SIDE_OFFSET = 40.0

#: Longest heel-to-toe distance (mm) of one foot: a shoe of EU size 50 is about 330 mm.
MAX_FOOT = 350.0

#: Largest angle (degrees) between the mean foot-to-pelvis direction and the lab axis taken
#: as the vertical: the trunk leans by up to about 10-15 degrees in walking and running, so
#: a lab axis further off is no vertical (the direction itself is used, with a warning).
VERTICAL_TILT_DEG = 30.0

#: Angle (degrees) of the pelvis heading from its mean above which a frame counts as turning:
#: the pelvis rotates by about 10 degrees each way in straight walking.
TURN_DEG = 45.0

#: Largest difference (mm) between the heights at which the feet land in level gait: the
#: marker noise and the shoe's compression add up to some 10 mm; a stair riser is
#: 150-200 mm, a kerb 100 mm or more.
MAX_LEVEL_CHANGE = 60.0

#: After a heel strike, the foot's lowest marker reaches the floor within this time (s):
#: foot-flat comes 50-100 ms after a heel strike in walking.
LANDING_TIME = 0.15

#: Right and left heel strikes closer than this (s) land together (a jump): a sprinter's
#: step lasts about 0.2 s.
MIN_STEP = 0.08

#: A foot on the floor keeps one of its markers within FLOOR_BAND (mm) of that marker's own
#: low level (its 5th percentile: markers sit at different heights above the sole, and
#: the heel's is lowest at heel strike, the toe's at push-off) for at least MIN_FLOOR_TIME
#: of the frames: half the share of the stride a foot stands on the floor (Novacheck
#: 1998: stance 62 % of the stride in walking, 22 % in sprinting, the shortest of
#: running), as the markers roll off the band before the foot leaves the floor. The
#: trials of tools/validate_gait_events.py keep it 33-73 % of their frames (real walks
#: 35-73 %, the runs 33-39 %); feet posed by joint angles without a floor (the two-leg
#: synthetic trial) 28 %. The band: the marker noise and the shoe's compression.
FLOOR_BAND = 10.0
MIN_FLOOR_TIME = {"walking": 0.62 / 2, "running": 0.22 / 2}

#: Data (s of valid frames) needed to judge the floor contact: a walking stride.
MIN_FLOOR_DATA = 1.0

#: Foot roles the events use (prefix R/L): touchdown from whichever lands first, toe-off
#: from the toe (or MT5), Zeni's windows from the heel (else the lateral malleolus, else
#: the toe).
FOOT_ROLES = ("HEEL", "TOE", "MT5", "ANKLE_LAT")

#: Below this rate (Hz) the events are warned about: issue 20's target, met by
#: tools/validate_gait_events.py, is 50-250 Hz (45 leaves room for a 50 Hz file's jitter).
MIN_RATE = 45.0

#: Below this rate (Hz) a time index is taken for milliseconds or frame numbers, not s.
MIN_PLAUSIBLE_RATE = 10.0

#: Median height (mm) of the pelvis centre above the mean of the foot markers, range of a
#: person walking or running: about 0.5 of the body height (Winter 2009, ch. 4: the
#: greater trochanter at 0.530 H), so 300 mm for a small child to 1500 mm.
PELVIS_HEIGHT = (300.0, 1500.0)


class GaitEvents(dict):
    """Events of a trial: ``events[side][event]`` is a sorted array of times (s).

    A dict ``{"right": {"heel_strike": ..., "toe_off": ...}, "left": {...}}`` (only the
    sides whose roles were given), with what the detection found about the trial as
    attributes:

    Attributes
    ----------
    gait : str or None
        ``'walking'`` or ``'running'`` (decided from the data unless given); None for
        events not detected from markers (read from a file, from force plates).
    method : str
        The method used for each event.
    progression : ndarray, shape (3,), or None
        Unit vector of the direction of progression in the lab frame.
    vertical : ndarray, shape (3,), or None
        Unit vector pointing up in the lab frame.
    markers : dict
        Per side, the labels of the markers the events were found from (empty when
        the events were not found from markers).
    source : str, dict or None
        Where the events come from: the file's path for events read from a file or its
        force plates; for :func:`gait_events`, per event, ``source[side][event]`` an array
        of ``'force plate'`` or ``'markers'`` beside the times.
    attrs : dict
        What else the detection measured: for :func:`gait_events` with force plates,
        ``attrs['calibration']``, per event kind the offset (ms) of the marker events
        against the plates of this trial that was removed from the events the plates
        do not see, and on how many events it was measured.
    """

    def __init__(self, events, gait=None, method="", progression=None, vertical=None, *,
                 markers=None, source=None):
        super().__init__(events)
        self.gait = gait
        self.method = method
        self.progression = progression
        self.vertical = vertical
        self.markers = {} if markers is None else dict(markers)
        self.source = source
        self.attrs = {}

    def __repr__(self):
        parts = ", ".join(f"{side}: {len(ev['heel_strike'])} heel strikes, "
                          f"{len(ev['toe_off'])} toe-offs" for side, ev in self.items())
        return f"GaitEvents({self.gait or self.method or 'events'}; {parts})"


# --- inputs -----------------------------------------------------------------------------------

def _as_trial(dynamic, name="dynamic"):
    """Return the marker DataFrame of `dynamic` (a DataFrame, or a .trc/.c3d path)."""
    df, trial_name = load_trial(dynamic, name)
    if not isinstance(df.columns, pd.MultiIndex) or df.columns.nlevels != 2:
        raise ValueError(f"{name} must have two-level (marker, coord) columns as returned "
                         f"by read_trc; got columns {list(df.columns[:6])}")
    return df, trial_name


def _trial_time(df, name):
    """Return the trial's time (s) from its index, checked to increase strictly."""
    time = as_float_array(df.index.to_numpy(), f"{name}.index (time)")
    if time.ndim != 1 or len(time) < 3:
        raise ValueError(f"{name} must hold at least 3 frames indexed by time (s); "
                         f"got {len(time)}")
    check_finite_or_nan(time, f"{name}.index (time)", allow_nan=False)
    if np.any(np.diff(time) <= 0):
        raise ValueError(f"{name}.index (time) must increase strictly from frame to frame; "
                         f"it does not at {np.count_nonzero(np.diff(time) <= 0)} frames")
    return time


def _label(markers, role, labels, trial_name, required=True):
    """The label of `role` in `markers`, checked against the trial's `labels`."""
    if role not in markers:
        if required:
            raise ValueError(f"markers: the role {role!r} ({describe(role)}) is missing from "
                             "the mapping; gait events need it")
        return None
    label = markers[role]
    if not isinstance(label, str):
        raise ValueError(f"markers[{role!r}] must be one marker label (the {describe(role)}); "
                         f"got {label!r}")
    check_labels(markers, [role], labels, trial_name)   # the lower-limb pipeline's message
    return label


def _positions(df, label):
    return as_float_array(df[label][["x", "y", "z"]].to_numpy(), f"marker {label!r}")


def _pelvis_landmarks_in(df, markers, labels):
    """Whether the pelvis landmark roles are mapped to labels with data in the trial."""
    return all(isinstance(markers.get(role), str) and markers[role] in labels
               and np.isfinite(df[markers[role]].to_numpy(dtype=float)).any()
               for role in pelvis_roles(markers))


def _pelvis(df, markers, labels, trial_name):
    """Pelvis centre (n, 3), forward direction (posterior to mid-ASIS, (n, 3)) and
    rightward direction (LASIS to RASIS, (n, 3)); both directions None when the centre
    comes from the 'PELVIS' cluster (landmarks in the static trial only).

    The posterior landmarks are those of :func:`~bmc_functions.markers.roles.pelvis_roles`
    (both PSIS when mapped, else the sacrum), the pelvis of the lower-limb pipeline.
    """
    cluster = markers.get("PELVIS")
    if (not _pelvis_landmarks_in(df, markers, labels) and cluster is not None
            and not isinstance(cluster, str) and all(label in labels for label in cluster)):
        # landmarks in the static trial only: the technical cluster gives the centre
        return np.mean([_positions(df, label) for label in cluster], axis=0), None, None
    roles = pelvis_roles(markers)
    absent = [role for role in ("RASIS", "LASIS") if role not in markers]
    if absent:
        raise ValueError(f"markers: the role {absent[0]!r} ({describe(absent[0])}) is "
                         f"missing: the pelvis needs the roles 'RASIS' and 'LASIS' (the "
                         f"anterior superior iliac spines); got no {' or '.join(absent)}")
    if not set(roles[2:]) <= set(markers):
        raise ValueError("markers: the pelvis needs either the role 'SACRUM' or both "
                         "'RPSIS' and 'LPSIS' (or a 'PELVIS' cluster when those are in "
                         "the static trial only); got "
                         + (" and ".join(repr(role) for role in ("RPSIS", "LPSIS")
                                         if role in markers) + " only"
                            if {"RPSIS", "LPSIS"} & set(markers) else "neither"))
    points = [_positions(df, _label(markers, role, labels, trial_name)) for role in roles]
    right_asis, left_asis, posterior = points[0], points[1], np.mean(points[2:], axis=0)
    front = 0.5 * (right_asis + left_asis)
    return 0.5 * (front + posterior), front - posterior, right_asis - left_asis


def _feet(df, markers, labels, trial_name):
    """The foot markers of each side given: ``{side: {role: (n, 3)}}`` and their labels
    ``{side: {role: label}}``; foot markers never seen in the trial are left out (warned
    once)."""
    feet, labels_used, unseen, footless = {}, {}, [], []
    for side, prefix in SIDES.items():
        present = [role for role in FOOT_ROLES if prefix + role in markers]
        if not set(present) & {"HEEL", "TOE", "MT5"}:
            continue                      # an ankle marker alone is no foot to time
        if "TOE" not in present and "MT5" not in present:
            raise ValueError(f"markers: side {side!r} has {prefix}HEEL but not {prefix}TOE "
                             f"(nor {prefix}MT5); the toe-off needs a forefoot marker")

        def in_trial(role):
            label = markers[prefix + role]
            return isinstance(label, str) and label in labels

        def seen(role):
            return in_trial(role) and np.isfinite(df[markers[prefix + role]]
                                                  .to_numpy(float)).any()
        # the lateral malleolus is often a static-only landmark: used when in this trial;
        # another foot marker never seen in this trial (every frame NaN) is left out, with
        # a warning: it would drop every event its windows touch (one not in the trial at
        # all is kept, for _label's message)
        unseen += [markers[prefix + role] for role in present
                   if role != "ANKLE_LAT" and in_trial(role) and not seen(role)]
        present = [role for role in present
                   if seen(role) or (role != "ANKLE_LAT" and not in_trial(role))]
        if not {"TOE", "MT5"} & set(present):
            footless.append(side)
            continue
        foot = {role: _label(markers, prefix + role, labels, trial_name)
                for role in present}
        labels_used[side] = foot
        feet[side] = {role: _positions(df, label) for role, label in foot.items()}
    if unseen:
        warn(f"{trial_name}: {', '.join(unseen)} never seen (every frame NaN): left out "
             "of the events" + (f"; the {' and '.join(footless)} side has no "
                                "forefoot marker left and gets no events"
                                if footless else ""), RuntimeWarning)
    if not feet:
        raise ValueError("markers: no side to detect events on; give 'RTOE' (with 'RHEEL' "
                         "or 'RANKLE_LAT') and/or 'LTOE' (with 'LHEEL' or 'LANKLE_LAT')"
                         + (f" with data in the trial ({', '.join(unseen)} never seen)"
                            if unseen else ""))
    return feet, labels_used


def _roles(df, markers, trial_name):
    """Pelvis centre (n, 3), forward and rightward directions (n, 3) or None (see
    :func:`_pelvis`), and the foot markers of each side given and their labels (see
    :func:`_feet`)."""
    if not isinstance(markers, Mapping):
        raise TypeError(f"markers must be a dict mapping roles to labels (as for "
                        f"calibrate_lower_limb); got {type(markers).__name__}")
    labels = list(dict.fromkeys(df.columns.get_level_values(0)))
    check_known_roles(markers)         # a misspelt role is named, not left out
    check_shared_labels(markers)       # one label for two landmarks: named, not "units"
    centre, forward, rightward = _pelvis(df, markers, labels, trial_name)
    feet, labels_used = _feet(df, markers, labels, trial_name)
    return centre, forward, rightward, feet, labels_used


def _check_feet(feet, labels_used, mm):
    """Warn (once) when the distance between two markers of a foot jumps between frames."""
    found, n = [], 0
    for side, foot in feet.items():
        base = next((role for role in ("HEEL", "ANKLE_LAT") if role in foot), None)
        if base is None:
            continue
        for role in ("TOE", "MT5"):
            if role not in foot:
                continue
            distance = np.linalg.norm(foot[role] - foot[base], axis=1) * mm
            n = len(distance)
            with np.errstate(invalid="ignore"):
                jumps = np.count_nonzero(np.abs(np.diff(distance)) > FOOT_JUMP)
            if jumps:
                found.append(f"{labels_used[side][base]}-{labels_used[side][role]} "
                             f"{jumps} times")
    if found:
        warn(f"foot marker distances jump by more than {FOOT_JUMP:g} mm between "
             f"consecutive frames ({'; '.join(found)}, in {n} frames): "
             "swapped or mislabelled foot markers? The events of that side may be "
             "wrong; check the labels", RuntimeWarning)


# --- signal helpers (loops over runs of valid frames, never over frames) ----------------------

def true_runs(mask):
    """Start and stop indices of the runs of True in a boolean array (the runs of valid
    frames here, the gaps' runs of missing frames in :mod:`~bmc_functions.gait.cycles`)."""
    edges = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)


def _peaks(signal, height, distance, drop):
    """Indices of the local maxima of `signal` (n,) above `height`, NaN runs excluded.

    A maximum needs a valid sample on each side: an extremum at the edge of a gap or of
    the trial is not confirmed by the data and is left out. It also needs the signal to
    fall by `drop` or more within `distance` samples on at least one side (one side is
    enough, so that an event near the end of the data is kept): a wiggle of noise on a
    plateau is no event.
    """
    found = []
    for start, stop in zip(*true_runs(~np.isnan(signal))):
        if stop - start >= 3:
            run = signal[start:stop]
            peaks, _ = find_peaks(run, height=height, distance=distance)
            # loop over the peaks found (events), not over frames
            deepest = np.array([min(run[max(p - distance, 0):p + distance + 1])
                                for p in peaks]).reshape(-1)
            found.append(peaks[run[peaks] - deepest >= drop] + start)
    return np.concatenate(found) if found else np.array([], dtype=int)


def _extrema(signal, rate, min_excursion):
    """Maxima of `signal` in its upper part (Zeni et al.'s events), at least MIN_STRIDE
    apart, at least `min_excursion` above the signal's 5th percentile and above the
    lowest value within MIN_STRIDE on one side."""
    if np.count_nonzero(~np.isnan(signal)) < 3:
        return np.array([], dtype=int)
    height, distance = _upper_part(signal, rate, min_excursion)
    return _peaks(signal, height, distance, min_excursion)


def _upper_part(signal, rate, min_excursion):
    """The level above which a maximum of `signal` places a Zeni event (its upper 40 %, at
    least `min_excursion` above its 5th percentile) and MIN_STRIDE in frames."""
    low, high = np.nanpercentile(signal, [5, 95])
    return low + max(0.6 * (high - low), min_excursion), max(1, int(MIN_STRIDE * rate))


def _edge_maximum(signal, rate, min_excursion, found):
    """``[0]`` when the maximum :func:`_extrema` would take for a Zeni event lies at or
    before the recording's first frame, else ``[]``: the first frame is in the signal's
    upper part and the highest of the first MIN_STRIDE, the signal falls by
    `min_excursion` within them (the criterion of :func:`_peaks`, one-sided), and no
    extremum in `found` lies there. Its time is unknown (the maximum may come before the
    recording); :func:`_lands_in_data` decides whether the contact it announces is in
    the data."""
    if np.count_nonzero(~np.isnan(signal)) < 3 or np.isnan(signal[0]):
        return np.array([], dtype=int)
    height, distance = _upper_part(signal, rate, min_excursion)
    first = signal[:distance + 1]
    if (signal[0] >= height and signal[0] >= np.nanmax(first)
            and signal[0] - np.nanmin(first) >= min_excursion
            and not np.any(np.asarray(found) <= distance)):
        return np.array([0])
    return np.array([], dtype=int)


def _lands_in_data(heights, found, rate, band, near_floor):
    """Whether the contact at frame `found`, searched in a window the recording's start
    cut (:func:`_edge_maximum`), is the foot's touchdown inside the data. Each foot
    marker's height (`heights`, (m, n)) is taken above its floor for this contact: the
    lowest it reaches from `found` to LANDING_TIME after it (foot flat; on stairs each
    step has its own, where a trial's lowest level would call a landing on a higher step
    a foot in the air). In the first frame every marker lies more than `band` above its
    floor (none has touched down); the first to come within `band` of it does so at most
    one frame before `found` (the contact timed is the first touchdown, not the heel
    dropping after a forefoot landing on a stair); and at `found` one lies within
    `near_floor` of its floor."""
    stop = found + max(2, int(round(LANDING_TIME * rate))) + 1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)       # a marker in a gap: NaN
        above = heights[:, :stop] - np.nanmin(heights[:, found:stop], axis=1)[:, None]
        down = above <= band
        arrival = np.min(np.where(down.any(axis=1), np.argmax(down, axis=1), stop))
        return bool(np.all(above[:, 0] > band) and found <= arrival + 1
                    and np.nanmin(above[:, found]) <= near_floor)


def _derivative(signal, rate, order):
    for _ in range(order):
        signal = np.gradient(signal, 1.0 / rate) if len(signal) > 1 else signal * np.nan
    return signal


def _descent_end(speed, start, stop):
    """The frame in [start, stop) nearest to where the vertical `speed` (n,) of a marker
    comes back to zero after its fastest descent in the window; None when it does not
    descend or its descent does not end in the window, -1 when the window holds a gap."""
    start, stop = max(start, 0), min(stop, len(speed))
    window = speed[start:stop]
    if window.size < 3:
        return None
    if np.isnan(window).any():
        return -1
    fastest = int(np.argmin(window))
    rest = np.flatnonzero(window[fastest:] >= 0)
    if window[fastest] >= 0 or not rest.size:
        return None
    k = fastest + int(rest[0])
    return start + k - int(abs(window[k - 1]) < abs(window[k]))   # the frame nearer zero


def _frames(ms, rate):
    """The number of frames that spans at least `ms` (ms) at `rate` (Hz): a search window
    rounded outwards, so that at 50 Hz a 150 ms window spans 8 frames (160 ms), not 7."""
    return int(np.ceil(ms * rate / 1000.0 - 1e-9))


def _argmax_in(signal, start, stop):
    """Index of the largest value of `signal` in [start, stop).

    The window is clipped to the trial. -1 if it holds a missing sample (the data cannot
    tell), None if the largest value is on the (clipped) window's edge: no peak in it.
    """
    start, stop = max(start, 0), min(stop, len(signal))
    if stop - start < 3:
        return None
    window = signal[start:stop]
    if np.isnan(window).any():
        return -1
    best = int(np.argmax(window))
    if best in (0, len(window) - 1):
        return None
    return start + best


# --- gait events ------------------------------------------------------------------------------

def gait_events(dynamic, markers, *, gait="auto", cutoff=None, refine=True,
                force_plates=None):
    r"""Heel strikes and toe-offs of each side from the foot and pelvis markers.

    Parameters
    ----------
    dynamic : pandas.DataFrame or path
        The walking or running trial: a DataFrame as returned by :func:`read_trc`
        (index time in s, columns ``(marker, coord)``), or a path to a ``.trc`` or
        ``.c3d`` file.
    markers : dict
        Role -> label in the file, the same mapping as for the lower-limb pipeline. Used
        here: ``'RASIS'``, ``'LASIS'`` and both ``'RPSIS'`` and ``'LPSIS'`` or else
        ``'SACRUM'`` (the pelvis of the lower-limb pipeline: the PSIS when both are
        mapped, whether or not a sacrum is; or the ``'PELVIS'`` cluster when those
        landmarks are not in this trial); per side (prefix ``R``/``L``) ``'TOE'``
        (or ``'MT5'`` in its place) and whichever of ``'HEEL'``, ``'MT5'`` and
        ``'ANKLE_LAT'`` (the lateral malleolus, used when it is in this trial) the foot
        has. A side without
        ``'HEEL'``, ``'TOE'`` or ``'MT5'`` is left out; other roles (clusters,
        epicondyles...) are ignored.
    gait : {'auto', 'walking', 'running'}, optional
        ``'auto'`` (default) decides from the pelvis's vertical motion (see Notes).
    cutoff : float, optional
        Low-pass cut-off (Hz) of the foot markers before they are differentiated.
        As for :func:`lowpass`: the frequency the whole zero-lag filter (both passes)
        attenuates by 3 dB (the design cut-off is raised by :func:`corrected_cutoff`).
        Default: ``CUTOFF`` (12 Hz), or 0.4 times the sampling rate if lower.
    refine : bool, optional
        True (default): Zeni's coordinate events are refined by the foot markers'
        accelerations (see Notes). False: Zeni et al.'s (2008) events alone on every
        side, as given for a foot that never rests on a floor: the baseline a
        validation compares the refinement with (``tools/validate_gait_events.py``).
    force_plates : None, True, 'file', path or pandas.DataFrame, optional
        Force plates of the same recording: ``True`` or ``'file'`` (the plates of
        `dynamic`, a ``.c3d`` path), a ``.c3d`` path, or the DataFrame
        :func:`read_force_plates` returns (its marker rate must be the trial's, its time
        axis :func:`read_c3d`'s). Where a foot stands on a plate alone, its heel strike
        and toe-off are the plate's (first and last loaded analog sample); the other
        events, from the markers, have the detector's offset on this trial's plates
        removed (see Notes). None (default): the markers alone.

    Returns
    -------
    GaitEvents
        A dict: ``events[side]["heel_strike"]`` and ``events[side]["toe_off"]`` are sorted
        1-D arrays of times (s, taken from the trial's index), for ``side`` in
        ``'right'``, ``'left'``. A side may have no events (empty arrays). Attributes
        ``gait``, ``method``, ``progression`` and ``vertical`` say what was found,
        ``markers[side][event]`` the labels of the markers that timed the events,
        ``source[side][event]`` per event ``'force plate'`` or ``'markers'``, and with
        force plates ``attrs['calibration']`` the offset removed.

    Raises
    ------
    TypeError
        If `dynamic` is not a DataFrame or a path, or `markers` is not a mapping; if
        `gait` is not a string or `refine` not a boolean (ArgumentTypeError, also a
        ValueError).
    ValueError
        If a role is missing, a label is not in the file (the message lists close
        labels), a side has a heel but no forefoot marker, no side has a foot, the time
        does not increase, `gait` is unknown, the trial has no units or units other
        than mm, cm or m (``attrs['units']``, spelled out or not: as
        :func:`calibrate_lower_limb`), the vertical or the direction of progression
        cannot be found; if the body travels against the way it faces
        (walking backwards, a trial reversed in time: the events would come out as
        their opposites); if foot markers lie on the wrong side of the pelvis (right
        and left foot labels swapped); if the pelvis's height above the feet is not a
        person's in the stated units (``PELVIS_HEIGHT``: metres labelled mm); if the
        time index steps slower than ``MIN_PLAUSIBLE_RATE`` (10 Hz: ms or frame numbers);
        if a foot's toe lies behind its heel in the direction of progression (the heel
        and toe roles swapped); if `cutoff` is not below ``NYQUIST_SHARE`` (99 %) of half
        the rate the time index steps at; if a role is unknown (a misspelling: the
        message names the roles that look close) or one label is mapped to two roles;
        if a coordinate column holds booleans or text (the column is named);
        if ``force_plates=True`` (or ``'file'``) and `dynamic` is not a ``.c3d`` path, if
        the plates' marker rate is not the trial's, or :func:`read_force_plates` refuses
        the file's plates (damaged analog data, unknown plate types). `force_plates` of
        another type raises a TypeError (ArgumentTypeError).

    Warns
    -----
    RuntimeWarning
        When the distance between two markers of a foot jumps by more than
        ``FOOT_JUMP`` (15 mm) between consecutive frames, or exceeds ``MAX_FOOT``
        (swapped labels); when a side has no event at all (a standing trial: its arrays
        are empty); when the walking/running decision rests on fewer than two stances;
        when the heading of the pelvis changes by more than 45 degrees (a turn); when
        the feet land at heights more than ``MAX_LEVEL_CHANGE`` (60 mm) apart (stairs, a
        slope); when right and left heel strikes come within ``MIN_STEP`` (80 ms: a
        jump); when a foot never rests on a floor (Zeni's events are then given for
        it); when a side has no heel or lateral malleolus (its heel strikes are timed by
        the forefoot); when the rate is below ``MIN_RATE`` (45 Hz); when events seem
        missing (a side's heel strikes and toe-offs differ in number by 2 or more, or
        an interval between them is 1.7 strides or longer: gaps drop events); when
        `gait` is given and the pelvis's vertical motion says the other; when
        ``attrs['rate']`` contradicts the time index by more than 2 % (the index is
        used: after ``df.iloc[::k]``, divide the rate by k).

    Notes
    -----
    **Lab axes are not assumed.** The vertical :math:`\hat v` is the lab axis nearest to
    the mean direction from the feet to the pelvis, with that direction's sign (every lab
    calibrates one axis to gravity; which one and which way is found from the data; the
    mean direction itself leans by some degrees because the feet spend longer behind the
    pelvis than ahead of it). If no axis lies within 30 degrees, the mean direction is
    used, with a warning. The direction of progression :math:`\hat d` is the mean
    horizontal direction from the posterior pelvis (sacrum or mid-PSIS) to mid-ASIS; it
    is the same overground and on a treadmill, where the pelvis does not travel. When the
    pelvis landmarks are not in the trial (static-only landmarks) and a ``'PELVIS'``
    cluster is mapped, the pelvis centre is the cluster's centroid and the direction of
    progression the mean horizontal direction from heel to toe.

    **Windows: Zeni et al. (2008)** [1]_. With the pelvis centre :math:`p` (between
    mid-ASIS and the posterior pelvis), each maximum of the heel's position ahead of the
    pelvis, :math:`(h - p)\cdot\hat d`, and each minimum of the toe's,
    :math:`(t - p)\cdot\hat d`, places one heel strike and one toe-off (the lateral
    malleolus, else the toe, stands in for a missing heel). Only maxima in the upper
    40 % of the signal's range, at least ``MIN_EXCURSION`` (100 mm) above its low level
    (a standing trial has no events) and at least ``MIN_STRIDE`` (0.3 s) apart count.
    These coordinate events are robust but not timed by the contact: against the force
    plates of the real trials here Zeni's heel strike comes 30-95 ms early (the heel's
    forward maximum precedes contact) and his toe-off is not found in running.

    **Walking: Hreljac & Marshall (2000)** [2]_, with the touchdown of Handsaker et al.
    [3]_. The foot markers are low-pass filtered (``CUTOFF``). Heel strike is the
    earliest of the peaks of the foot markers' vertical acceleration (the impact stops
    the marker's descent), each searched from 50 ms before to 150 ms after Zeni's heel
    strike (``STRIKE_WINDOW``, its far end rounded outwards to a frame): the heel's for
    a heel strike, the forefoot's for a landing on the forefoot (stairs), the lateral
    malleolus's when there is no heel marker (it lands with the heel, 5-10 ms later
    here). A marker whose acceleration has
    no peak inside the window (its largest value on the window's edge: the impact
    smoothed out, as at 50-60 Hz) lands where its vertical speed comes back to zero from
    its fastest descent (the floor stops it); without that, a forefoot's later peak (foot
    flat) was taken for the heel strike, 50-100 ms late. Toe-off is the peak of the
    toe's forward acceleration within 100 ms of Zeni's toe-off (``OFF_WINDOW``).
    Why these: on the five level walks over force plates the project's tests use (three
    systems, 1997-2019, recorded at 60-200 Hz, each also resampled to 50-250 Hz) every
    plate event is found, heel strikes with a median error of 0-14 ms, toe-offs 2-44 ms
    (late: the toe's forward acceleration peaks after it leaves the floor), against
    30-65 ms early for Zeni's heel strike (``tools/validate_gait_events.py``). Velocity
    thresholds depend on the marker and the speed: Ghoussayni et al.'s 50 mm/s on the
    heel's sagittal speed [4]_ is crossed 85-105 ms after the plates' contact on that walk (the heel still
    moves at 200-350 mm/s when it lands), so Bruening & Ridge [5]_ tuned the
    threshold to the walking speed; O'Connor et al.'s foot-velocity algorithm [6]_
    needs a foot centre from heel and toe markers, which clinical walks without a
    heel marker lack. The table is printed by ``tools/validate_gait_events.py``.

    **Running: Handsaker et al. (2016)** [3]_, in windows placed by Zeni's events:
    touchdown is the first peak of the vertical acceleration of the foot markers
    (whichever comes first) within -50/+100 ms of Zeni's heel strike; toe-off is the
    peak of the toe's vertical jerk from 35 % of the way between touchdown and Zeni's
    toe-off (200 ms before Zeni's toe-off when the touchdown is not in the data) to 30 ms
    after it, among the frames with the toe within ``NEAR_FLOOR`` of the floor of the
    stance it ends (a larger peak with the toe in the air is no toe-off). On the shared
    treadmill run (150 Hz, resampled to 50-250 Hz) every event the force plate records
    is found, toe-offs 5-30 ms early (median), touchdowns 10-15 ms late.
    Handsaker et al. took touchdown from the heel and first-metatarsal markers
    and toe-off from the hallux marker, and placed their search windows their own way;
    here the heel, ``TOE``, ``MT5`` and ``ANKLE_LAT`` roles play those parts. A
    touchdown needs a foot marker, a toe-off the toe, within ``NEAR_FLOOR`` (25 mm) of
    the marker's floor for that contact: its low level (5th percentile) within
    ``LANDING_TIME`` (150 ms) either side of the touchdown, or from the touchdown of the
    stance a toe-off ends (the trial's when that touchdown is not in the data). A peak
    with the foot in the air (a marker rising after a toe-off) is no event, and on
    stairs each step is its own floor, where the trial's lowest level would call every
    landing above the lowest step a foot in the air.

    **Walking or running** (``gait='auto'``): at mid-stance the body's centre of mass is
    highest in walking (inverted pendulum) and lowest in running (spring-mass; Cavagna
    et al., 1977 [7]_). The pelvis height in the middle of each stance (Zeni's heel
    strike to toe-off) and each swing (toe-off to heel strike: the middle of the other
    foot's stance) is compared with its mean height at the interval's two ends: higher
    on average means walking. A trial of one step per side has two such intervals.

    **Trials that are not level forward gait.** The travel is the pelvis's velocity
    relative to the supporting foot (the lower one in each frame): relative to the floor
    overground, to the belt on a treadmill. A median travel of more than ``MIN_SPEED``
    (150 mm/s) against the pelvis's facing is refused. A foot marker whose median
    lateral offset from the pelvis centre lies more than ``MIN_SIDE_OFFSET`` (40 mm) on
    the other side (the pelvis's right from LASIS to RASIS) is refused, and so is a body
    that is the mirror image of one (the pelvis's right crossed with its forward direction
    pointing towards the feet: every R/L label swapped, or a lab axis reversed). A foot none
    of whose markers stays within ``FLOOR_BAND`` (10 mm) of its own low level in
    ``MIN_FLOOR_TIME`` of the frames (half the stance share: 31 % walking, 11 %
    running; Novacheck 1998) never rests on a floor (feet posed by joint
    angles): no contact can be timed, and Zeni's events are given, with a warning.

    **Force plates first** (``force_plates=``). Where a foot stands on a plate alone
    (:func:`assign_plates`: the foot's markers over the plate, one foot, one plate), its
    heel strike and toe-off are the first and last analog samples of the contact
    (vertical force above 20 N), and ``source`` says ``'force plate'``. The marker
    detector's offset on this trial (median of marker minus plate, per kind of event,
    both sides) is removed from the events the plates do not see
    (``attrs['calibration']``; :func:`~bmc_functions.gait.plate_events.calibrate_events`).
    Left out one at a time on the shared trials, the calibration brings the mean signed
    error of the hidden events from up to 31 ms (toe-off) to within 2 ms on every trial
    with two or more plate events of that kind; with two events only, the median
    absolute error may grow (one event's noise becomes the offset).

    **Gaps.** Extrema are searched only inside runs of valid frames and need a valid
    frame on either side; a refinement window that holds a missing frame drops its
    event. Events are never interpolated across gaps. Events of a partial stride at the
    start or end of the trial are kept when the extremum lies inside the data.

    **A heel strike in the first frames.** When the recording starts after the heel's
    forward maximum (Zeni's heel strike comes 30-95 ms before contact), the first frame
    is the highest of the first ``MIN_STRIDE`` in the upper part of the signal and the
    signal falls by ``MIN_EXCURSION`` from it: the criterion of the other extrema, on
    one side. Its window (cut by the recording's start) is searched as any other, and
    the contact found kept when the data show the foot landing: in the first frame every
    foot marker lies more than ``FLOOR_BAND`` above its floor for this contact (the
    lowest it reaches in the ``LANDING_TIME`` after the contact: each stair has its own),
    one lies within ``NEAR_FLOOR`` of its floor at the contact, and the contact timed is
    the foot's first touchdown (at most a frame after the first marker comes within
    ``FLOOR_BAND`` of its floor: not the heel dropping after a forefoot landing on a
    stair). A recording that starts with the foot on the floor gets no heel strike for
    it; ``refine=False`` (Zeni's events alone) none either, as the maximum's time is not
    in the data. On the shared run this finds the right heel strike 57 ms after the
    first frame at 50-60 Hz (missed before); cut one frame after each plate heel strike,
    the stair descent and the walks get none.

    **Accuracy** (``tools/validate_gait_events.py``, ``gait_events(trial, markers)``
    without plates, against the force plates of every shared trial at its own rate and
    resampled to 50, 60, 100 and 250 Hz; per trial and event, both sides pooled; all
    plate events found within 100 ms, 60 ms running, at every rate; median absolute
    error, range over the rates, ms; bias: median signed error, + late; plates: heel
    strikes + toe-offs the plates time):

    ======================= ====== =========== ======== ======= =========
    trial (system, rate)    plates heel strike bias     toe-off bias
    ======================= ====== =========== ======== ======= =========
    Codamotion 2015, 200 Hz 4+4    2-7         -3 to 4  11-23   11 to 23
    stair descent, 120 Hz   4+3    2-6         -4 to 1  7-14    7 to 14
    Codamotion 1997, 200 Hz 1+1    0-10        0 to 10  30-37   30 to 37
    newwalk (MAC), 60 Hz    2+2    2-10        0 to 10  4-9     4 to 9
    Walk1 (MAC), 60 Hz      2+2    2-14        2 to 14  35-40   35 to 40
    gait_with_emg, 60 Hz    2+2    6-12        6 to 12  32-44   32 to 44
    treadmill run, 150 Hz   2+2    10-15       10 to 15 8-30    -30 to -5
    ======================= ====== =========== ======== ======= =========

    Every set meets issue 31's target (85 % found, median within 3 frames or 45 ms). The
    walking toe-offs are late (the toe's forward acceleration peaks after it leaves the
    floor): 30-44 ms on three trials. Tried on these trials and not kept, as none is
    nearer on every trial: the toe's forward jerk peak (16-43 ms early on three), its
    vertical acceleration peak (no peak in the window for 15 of 64), its vertical jerk
    peak, Zeni's toe-off alone (nearer on five walks, 31-36 ms early on the stairs); a
    speed threshold would need a fraction fitted to the trials (the toe's forward speed
    at the plates' toe-off is 16-41 % of its swing peak, by trial).

    Times are those of frames (no sub-frame interpolation): the resolution is one frame.

    References
    ----------
    .. [1] Zeni JA, Richards JG, Higginson JS (2008) Two simple methods for determining
       gait events during treadmill and overground walking using kinematic data. Gait &
       Posture 27(4):710-714.
    .. [2] Hreljac A, Marshall RN (2000) Algorithms to determine event timing during
       normal walking using kinematic data. Journal of Biomechanics 33(6):783-786.
    .. [3] Handsaker JC, Forrester SE, Folland JP, Black MI, Allen SJ (2016) A kinematic
       algorithm to identify gait events during running at different speeds and with
       different footstrike types. Journal of Biomechanics 49(16):4128-4133.
    .. [4] Ghoussayni S, Stevens C, Durham S, Ewins D (2004) Assessment and validation
       of a simple automated method for the detection of gait events and intervals.
       Gait & Posture 20(3):266-272.
    .. [5] Bruening DA, Ridge ST (2014) Automated event detection algorithms in
       pathological gait. Gait & Posture 39(1):472-477.
    .. [6] O'Connor CM, Thorpe SK, O'Malley MJ, Vaughan CL (2007) Automatic detection
       of gait events using kinematic data. Gait & Posture 25(3):469-474.
    .. [7] Cavagna GA, Heglund NC, Taylor CR (1977) Mechanical work in terrestrial
       locomotion: two basic mechanisms for minimizing energy expenditure. American
       Journal of Physiology 233(5):R243-R261.

    Examples
    --------
    The synthetic walker of data/gait/ (true right heel strikes at 0.341, 1.439, 2.566,
    3.658 and 4.780 s; a gap hides the left heel over its third heel strike):

    >>> from bmc_functions import gait_events, read_trc
    >>> from bmc_functions.examples import example_file    # data/gait, shipped too
    >>> trial = read_trc(example_file("gait/walk.trc"))
    >>> roles = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
    ...          "RHEEL": "RHEE", "RTOE": "RTOE", "LHEEL": "LHEE", "LTOE": "LTOE"}
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     events = gait_events(trial, roles)
    >>> events
    GaitEvents(walking; right: 5 heel strikes, 4 toe-offs, left: 3 heel strikes, 5 toe-offs)
    >>> print(str(caught[0].message).split(",")[0])   # a left heel strike is in a gap
    events seem missing: left heel strikes (3 against 5 toe offs
    >>> print(events["right"]["heel_strike"])
    [0.34 1.44 2.57 3.66 4.78]
    >>> print(events.markers["right"])
    {'heel_strike': ['RHEE'], 'toe_off': ['RTOE']}
    >>> print(events.progression.round(3) + 0.0, events.vertical)
    [-1.    -0.006  0.   ] [0. 0. 1.]
    """
    check_choice(gait, "gait", ("auto", "walking", "running"))
    refine = check_flag(refine, "refine")
    df, trial_name, time, rate = _dynamic_trial(dynamic)
    if cutoff is not None:
        cutoff = check_number(cutoff, "cutoff", positive=True)
    pelvis, forward, rightward, feet, labels_used = _roles(df, markers, trial_name)
    mm, units = mm_per_unit(df, trial_name)
    cutoff = _check_cutoff(cutoff, rate, time)
    up, heading = _lab_directions(pelvis, forward, rightward, feet, labels_used, rate, mm,
                                  units)
    zeni, edges = _zeni_events(feet, pelvis, heading, rate, mm)
    gait = _decide_gait(gait, zeni, pelvis @ up)
    if refine:
        level = _landing_range(zeni, feet, up, rate, mm) <= MAX_LEVEL_CHANGE
        floorless = _floorless(feet, up, mm, rate, gait) if level else []
        why = "no floor contact in the data"
    else:
        floorless, why = list(feet), "refine=False"
    events, used = _zeni_alone(zeni, feet, time, labels_used, floorless)
    refined, refined_used, method = _refined_events(
        gait, zeni, {side: foot for side, foot in feet.items() if side not in floorless},
        heading, up, rate, time, mm, cutoff, labels_used, edges)
    events.update(refined)
    used.update(refined_used)
    if floorless:
        method = (method + "; " if refine else "") + (
            "Zeni et al. (2008) alone on the " + " and ".join(floorless) + f" side ({why})")
    _check_level(events, feet, up, time, rate, mm)
    _check_alternation(events)
    _check_missing_events(events)
    return _with_plates(GaitEvents(events, gait, method, heading, up, markers=used),
                        plates_of(force_plates, dynamic), df, labels_used)


def _with_plates(events, plates, trial, labels_used):
    """`events` from the markers, with ``source`` per event; with `plates`, the plates'
    events first and the others calibrated on them (:func:`calibrate_events`)."""
    if plates is None:
        events.source = {side: {key: np.full(len(times), "markers")
                                for key, times in found.items()}
                         for side, found in events.items()}
        return events
    reference = plate_reference_events(
        plates, trial, {side: list(dict.fromkeys(labels.values()))
                        for side, labels in labels_used.items()})
    calibrated, source, calibration = calibrate_events(events, reference)
    result = GaitEvents(calibrated, events.gait, events.method + "; force plates first, "
                        "the other events calibrated on them", events.progression,
                        events.vertical, markers=events.markers, source=source)
    result.attrs["calibration"] = calibration
    return result


def _dynamic_trial(dynamic):
    """The marker DataFrame of `dynamic`, its display name, its time (s) and rate (Hz),
    checked: no label twice, some data, a plausible rate."""
    df, trial_name = _as_trial(dynamic)
    time = _trial_time(df, "dynamic")
    twice = list(dict.fromkeys(label for label, _ in df.columns[df.columns.duplicated()]))
    if twice:
        raise ValueError(f"dynamic: the label(s) {', '.join(map(str, twice))} appear more "
                         f"than once in {trial_name}; which copy is the marker is "
                         f"ambiguous: rename or drop one")
    check_numeric_columns(df, "dynamic")
    if not np.isfinite(df.to_numpy(dtype=float)).any():
        raise ValueError(f"dynamic: every coordinate of {trial_name} is NaN (no marker "
                         f"seen in any frame): no events can be found")
    rate = _trial_rate(time)
    check_rate_attr(df, time, "dynamic")  # the index is the time (df.iloc[::k] keeps it)
    return df, trial_name, time, rate


def _check_cutoff(cutoff, rate, time):
    """The low-pass cut-off (Hz): `cutoff`, or CUTOFF (0.4 times the rate if lower);
    refused at or above NYQUIST_SHARE of half the rate, the rate being the lower of the
    median step's and the whole span's (frames - 1 over the duration), so that a rate
    inferred a rounding error above the true one does not let a cut-off at the Nyquist
    frequency through."""
    span_rate = (len(time) - 1) / (time[-1] - time[0])
    nyquist = 0.5 * min(rate, span_rate)
    cutoff = min(CUTOFF, 0.4 * rate) if cutoff is None else cutoff
    if not 0 < cutoff < NYQUIST_SHARE * nyquist:
        raise ValueError(f"cutoff must be between 0 and half the sampling rate "
                         f"({nyquist:.6g} Hz); got {cutoff!r} (it must lie at least 1 % "
                         f"below half the rate the time index steps at)")
    return cutoff


def _lab_directions(pelvis, forward, rightward, feet, labels_used, rate, mm, units):
    """The vertical and the direction of progression (unit vectors, (3,)), after the
    checks of units, feet, travel, handedness and sides that they make possible."""
    up = _vertical(pelvis, feet)
    _check_units(pelvis, feet, up, mm, units)   # before any mm limit
    _check_feet(feet, labels_used, mm)
    from_pelvis = forward is not None
    if forward is None:                                 # from the feet: heel (ankle) to toe
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # frames without a foot: NaN
            forward = np.nanmean([foot[_toe(foot)] - foot[_rear(foot)]
                                  for foot in feet.values()], axis=0)
    heading = _heading(forward, up, len(pelvis))
    _check_direction(pelvis, feet, heading, up, rate, mm, from_pelvis)
    if from_pelvis:
        _check_handedness(forward, rightward, up)
        _check_heel_before_toe(feet, labels_used, heading, mm)
    _check_sides(pelvis, feet, labels_used, heading, rightward, up, mm)
    return up, heading


def _zeni_events(feet, pelvis, heading, rate, mm):
    """Zeni et al.'s (2008) events, frame indices ``{side: {event: (k,)}}``: extrema of
    the rear foot's and the toe's coordinates along the progression relative to the
    pelvis; warns about a side without any. Also, per side, ``[0]`` when a heel strike's
    maximum lies at or before the first frame (:func:`_edge_maximum`), else ``[]``."""
    zeni, edges, excursion = {}, {}, MIN_EXCURSION / mm
    for side, foot in feet.items():
        rear = (foot[_rear(foot)] - pelvis) @ heading
        toe = (foot[_toe(foot)] - pelvis) @ heading
        zeni[side] = {"heel_strike": _extrema(rear, rate, excursion),
                      "toe_off": _extrema(-toe, rate, excursion)}
        edges[side] = _edge_maximum(rear, rate, excursion, zeni[side]["heel_strike"])
    still = [side for side, found in zeni.items() if not any(map(len, found.values()))]
    if still:
        warn(f"no heel strike or toe-off found on the {' and '.join(still)} side: "
             f"the foot never moves {MIN_EXCURSION:g} mm ahead of or behind its usual "
             "place relative to the pelvis (a standing trial, or a foot lost in "
             "gaps); its event arrays are empty", RuntimeWarning)
    return zeni, edges


def _decide_gait(gait, zeni, pelvis_height):
    """'walking' or 'running': `gait` if given (warned when the pelvis says the other),
    else from the pelvis's height at mid-stance and mid-swing."""
    if gait == "auto":
        return _walking_or_running(zeni, pelvis_height)
    with warnings.catch_warnings(record=True) as doubt:
        warnings.simplefilter("always")
        judged = _walking_or_running(zeni, pelvis_height)
    if not doubt and judged != gait:
        warn(f"gait={gait!r} was given, but the pelvis's vertical motion says "
             f"{judged} (highest at mid-stance: walking; lowest: running); "
             f"the {gait} detector may miss or misplace events",
             RuntimeWarning)
    return gait


def _zeni_alone(zeni, feet, time, labels_used, sides):
    """The events (times) and markers of Zeni's events of `sides`, not refined."""
    events = {side: {key: time[np.sort(zeni[side][key])] for key in EVENTS}
              for side in sides}
    used = {side: {"heel_strike": [labels_used[side][_rear(feet[side])]],
                   "toe_off": [labels_used[side][_toe(feet[side])]]} for side in sides}
    return events, used


def _refined_events(gait, zeni, feet, heading, up, rate, time, mm, cutoff, labels_used,
                    edges):
    """Zeni's events of each side of `feet` refined by the filtered foot markers:
    (events, markers used, method); warns about a side timed by its forefoot. A heel
    strike whose Zeni maximum lies at or before the first frame (`edges`) is kept when
    the foot lands inside the data (:func:`_lands_in_data`)."""
    forefoot = [side for side, foot in feet.items() if not {"HEEL", "ANKLE_LAT"} & set(foot)]
    if forefoot:
        warn(f"no heel or lateral malleolus marker on the {' and '.join(forefoot)} "
             "side: its heel strikes are timed by the forefoot markers, which "
             "land 30-100 ms after the heel of a rear-foot striker (on time for a "
             "fore-foot striker)", RuntimeWarning)
    filtered = {side: {role: _lowpass_points(point, rate, cutoff)
                       for role, point in foot.items()}
                for side, foot in feet.items()}
    events, used = {}, {}
    if gait == "walking":
        method = ("Hreljac & Marshall (2000) in windows placed by Zeni et al. (2008): "
                  "heel strike at the first vertical-acceleration peak of the foot markers, "
                  "toe-off at the toe's forward-acceleration peak")
        for side, foot in filtered.items():
            events[side], used[side] = _walking_events(
                zeni[side], foot, heading, up, rate, time, labels_used[side],
                (edges[side], mm))
    else:
        method = ("Handsaker et al. (2016) in windows placed by Zeni et al. (2008): "
                  "touchdown at the first vertical-acceleration peak of the foot markers, "
                  "toe-off at the toe's vertical-jerk peak")
        for side, foot in filtered.items():
            height = {role: point @ up for role, point in foot.items()}
            events[side], used[side] = _running_events(
                zeni[side], height, rate, time, NEAR_FLOOR / mm, labels_used[side],
                (edges[side], mm))
    return events, used, method


def _floorless(feet, up, mm, rate, gait):
    """The sides whose feet never rest on a floor (warned once): no marker stays within
    FLOOR_BAND of its own low level in MIN_FLOOR_TIME[gait] of the frames (judged on a
    stride or more of data: MIN_FLOOR_DATA)."""
    found, shares = [], []
    for side, foot in feet.items():
        height = np.array([foot[role] @ up for role in foot]) * mm
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)   # a marker never seen: NaN
            low = np.nanmin(height - np.nanpercentile(height, 5, axis=1)[:, None], axis=0)
        valid = np.isfinite(low)
        if np.count_nonzero(valid) < MIN_FLOOR_DATA * rate:
            continue
        share = np.mean(low[valid] < FLOOR_BAND)
        if share < MIN_FLOOR_TIME[gait]:
            found.append(side)
            shares.append(f"{100 * share:.0f} %")
    if found:
        feet_word = "foot never rests" if len(found) == 1 else "feet never rest"
        warn(f"the {' and '.join(found)} {feet_word} on a floor (no foot marker "
             f"stays within {FLOOR_BAND:g} mm of its own low level in more than "
             f"{' and '.join(shares)} of the frames; a foot stands on the floor "
             f"{100 * 2 * MIN_FLOOR_TIME[gait]:.0f} % of a stride or more in {gait}): no "
             "contact to time; Zeni et al.'s coordinate events are given instead, which "
             "came 35-95 ms early at heel strike on the force-plate trials this package "
             "was checked on", RuntimeWarning)
    return found


def _rear(foot):
    """The rearmost foot role present: heel, else lateral malleolus, else the toe."""
    return next(role for role in ("HEEL", "ANKLE_LAT", "TOE", "MT5") if role in foot)



def _toe(foot):
    return "TOE" if "TOE" in foot else "MT5"


def _lowpass_points(points, rate, cutoff):
    """Zero-lag 2nd-order Butterworth low-pass of each coordinate of `points` (n, 3), run
    by run of valid frames, with :func:`~bmc_functions.lowpass`'s meaning of `cutoff`:
    the two passes together attenuate `cutoff` by 3 dB (the design cut-off raised by
    :func:`~bmc_functions.corrected_cutoff`: 12 Hz at 200 Hz is designed at 15.0 Hz), and
    each run is padded by two periods of the cut-off (runs of 9 frames or fewer are NaN).
    """
    sos = butter(2, corrected_cutoff(cutoff, rate), fs=rate, output="sos")
    filtered, done = filter_runs(points, sos, padlen=int(np.ceil(2 * rate / cutoff)))
    return np.where(done, filtered, np.nan)


def _vertical(pelvis, feet):
    """The lab's vertical axis (sign from the data): nearest to the mean foot-to-pelvis
    direction."""
    foot_points = np.stack([point for foot in feet.values() for point in foot.values()])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)     # no valid frame: raised below
        up = np.nanmean(pelvis - np.nanmean(foot_points, axis=0), axis=0)
    if not np.all(np.isfinite(up)) or np.linalg.norm(up) == 0:
        raise ValueError("dynamic: cannot find the vertical: no frame has both the pelvis "
                         "and the foot markers")
    up /= np.linalg.norm(up)
    axis = int(np.argmax(np.abs(up)))
    if abs(up[axis]) >= np.cos(np.radians(VERTICAL_TILT_DEG)):   # sign from the data
        return np.sign(up[axis]) * np.eye(3)[axis]
    warn(f"no lab axis lies within {VERTICAL_TILT_DEG:.0f} degrees of the mean foot-to-pelvis "
         f"direction {np.round(up, 3).tolist()}; it is used as the vertical",
         RuntimeWarning)
    return up


def _heading(forward, up, n):
    """Mean horizontal direction of `forward` (n, 3); warns when the trial turns."""
    forward = forward - (forward @ up)[:, None] * up
    heading = np.nanmean(forward, axis=0)
    if not np.all(np.isfinite(heading)) or np.linalg.norm(heading) == 0:
        raise ValueError("dynamic: cannot find the direction of progression: no frame has "
                         "all the pelvis markers")
    heading /= np.linalg.norm(heading)
    with np.errstate(invalid="ignore"):
        cos_turn = (forward @ heading) / np.linalg.norm(forward, axis=1)
    turned = np.count_nonzero(cos_turn < np.cos(np.radians(TURN_DEG)))
    if turned:
        warn(f"{turned} of {n} frames have the pelvis heading more than "
             f"{TURN_DEG:.0f} degrees away from its mean: the trial turns, and the events "
             "assume a straight path", RuntimeWarning)
    return heading


def _check_direction(pelvis, feet, heading, up, rate, mm, from_pelvis):
    """Refuse a trial that travels against the way the body faces (walking backwards, or
    a trial reversed in time): the events would come out as their opposites.

    The travel is the pelvis's velocity relative to the supporting foot (the lower foot
    in each frame): relative to the floor overground, relative to the belt on a
    treadmill.
    """
    velocity = np.gradient(pelvis, 1.0 / rate, axis=0) if len(pelvis) > 1 else pelvis * 0
    heights, speeds = [], []
    for foot in feet.values():
        centre = np.mean([foot[role] for role in foot], axis=0)
        heights.append(np.min([foot[role] @ up for role in foot], axis=0))
        speeds.append(np.gradient(centre, 1.0 / rate, axis=0))
    heights, speeds = np.array(heights), np.array(speeds)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        lower = np.nanargmin(np.where(np.isnan(heights), np.inf, heights), axis=0)
    support = speeds[lower, np.arange(len(pelvis))]
    travel = (velocity - support) @ heading * mm       # mm/s, + = the way the body faces
    travel = travel[np.isfinite(travel)]
    if travel.size and np.median(travel) < -MIN_SPEED:
        facing = "the pelvis (mid-PSIS to mid-ASIS)" if from_pelvis else "the feet (heel to toe)"
        raise ValueError(f"dynamic: the body travels backwards relative to the supporting "
                         f"foot (median {-np.median(travel):.0f} mm/s against the way "
                         f"{facing} faces): walking backwards, a trial reversed in time, or "
                         "the front and back pelvis markers swapped? The event methods "
                         "need forward gait; they would return foot offs as foot strikes")


def _check_heel_before_toe(feet, labels_used, heading, mm):
    """Refuse a foot whose toe (or MT5) lies behind its heel in the direction of
    progression (the pelvis's, mid-PSIS to mid-ASIS) in most frames: the heel and toe
    roles are swapped. A shod foot's toe marker lies 150-250 mm ahead of its heel marker
    in standing and stays ahead through the stride (the heel rises at push-off, the toe
    never passes behind it); MIN_SIDE_OFFSET (40 mm) behind is beyond any foot posture."""
    swapped = []
    for side, foot in feet.items():
        if "HEEL" not in foot:
            continue
        toe = _toe(foot)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)   # frames without the foot
            ahead = np.nanmedian((foot[toe] - foot["HEEL"]) @ heading) * mm
        if ahead < -MIN_SIDE_OFFSET:
            swapped.append(f"{labels_used[side][toe]} (given as the "
                           f"{describe(SIDES[side] + toe)}) lies {-ahead:.0f} mm behind "
                           f"{labels_used[side]['HEEL']} "
                           f"(given as the {describe(SIDES[side] + 'HEEL')})")
    if swapped:
        raise ValueError("markers: the toe lies behind the heel in the direction of "
                         "progression (median over the frames): " + "; ".join(swapped)
                         + ". The heel and toe roles are swapped? Map each role to its "
                         "marker")


def _check_handedness(forward, rightward, up):
    """Refuse a body that is a mirror image of a body.

    In a right-handed body frame (ISB: x forwards, y up, z to the right) z x x = y: the
    pelvis's right (LASIS to RASIS) crossed with its forward direction (mid-PSIS to
    mid-ASIS) points up, away from the feet. In a mirror image it points down. The file
    cannot tell which of two mistakes made it (every right and left label swapped, or one
    lab axis reversed: a left-handed file), but either gives each foot's events to the
    other side. Run after :func:`_check_direction`, which names the other cause of a
    reversed forward direction (ASIS and PSIS swapped).
    """
    if rightward is None:
        return
    with np.errstate(invalid="ignore", divide="ignore"):
        turn = np.cross(rightward, forward) @ up / (
            np.linalg.norm(rightward, axis=1) * np.linalg.norm(forward, axis=1))
    turn = turn[np.isfinite(turn)]
    if turn.size and np.median(turn) < 0:
        raise ValueError(
            f"dynamic: the body is a mirror image: the pelvis's right (LASIS to RASIS) "
            f"crossed with its forward direction (mid-PSIS to mid-ASIS) points towards the "
            f"feet in {np.mean(turn < 0):.0%} of the frames, where a body's points up (z x "
            f"x = y). Every right and left label is swapped, or one lab axis is reversed (a "
            f"left-handed file); the events would be given to the wrong side")


def _check_sides(pelvis, feet, labels_used, heading, rightward, up, mm):
    """Refuse feet whose markers lie on the wrong side of the pelvis (the R and L foot
    labels swapped), warn about a foot whose markers are too far apart (markers of the
    two feet mixed).

    The pelvis's right is the direction from LASIS to RASIS (so that a trial mirrored as
    a whole, pelvis included, is left to the pelvis checks of the lower-limb pipeline);
    without those landmarks in the trial the sides are not judged (the right of the
    direction of progression would blame the labels for a mirrored lab frame).
    """
    right = None
    if rightward is not None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            right = np.nanmean(rightward, axis=0)
        right = right - (right @ up) * up
        norm = np.linalg.norm(right)
        right = right / norm if np.isfinite(norm) and norm > 0 else None
    wrong, mixed = [], []
    for side, foot in feet.items():
        sign = 1.0 if side == "right" else -1.0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            for role, point in foot.items():
                if right is None:
                    break
                lateral = np.nanmedian((point - pelvis) @ right) * mm * sign
                if lateral < -MIN_SIDE_OFFSET:
                    wrong.append(f"{labels_used[side][role]} ({describe(SIDES[side] + role)}) "
                                 f"lies {-lateral:.0f} mm to the subject's "
                                 f"{'left' if side == 'right' else 'right'}")
            rear, toe = _rear(foot), _toe(foot)
            if rear != toe:
                length = np.nanmedian(np.linalg.norm(foot[toe] - foot[rear], axis=1)) * mm
                if length > MAX_FOOT:
                    mixed.append(f"{labels_used[side][rear]}-{labels_used[side][toe]} "
                                 f"{length:.0f} mm")
    if wrong:
        raise ValueError("markers: foot markers on the wrong side of the pelvis: "
                         + "; ".join(wrong) + ". The right and left foot labels are "
                         "swapped (or the pelvis's right and left)? Events would be "
                         "given to the wrong side")
    if mixed:
        warn(f"foot markers too far apart for one foot ({'; '.join(mixed)}; a foot "
             f"is shorter than {MAX_FOOT:g} mm): markers of the two feet mixed? The "
             "events of that side may be wrong", RuntimeWarning)


def _landing_range(strikes, feet, up, rate, mm):
    """Range (mm) of the heights at which the feet land: the lowest foot marker in the
    LANDING_TIME after each heel strike (frame indices `strikes[side]['heel_strike']`)."""
    heights = []
    span = max(2, int(round(LANDING_TIME * rate)))
    for side, found in strikes.items():
        foot = feet[side]
        low = np.min([foot[role] @ up for role in foot], axis=0) * mm
        for strike in found["heel_strike"]:      # loop over events (a few), not frames
            window = low[strike:strike + span]
            if np.isfinite(window).any():
                heights.append(np.nanmin(window))
    return np.ptp(heights) if len(heights) >= 2 else 0.0


def _check_level(events, feet, up, time, rate, mm):
    """Warn when the feet land at heights that differ (stairs, a slope, a step)."""
    strikes = {side: {"heel_strike": np.searchsorted(time, found["heel_strike"])}
               for side, found in events.items()}
    spread = _landing_range(strikes, feet, up, rate, mm)
    if spread > MAX_LEVEL_CHANGE:
        warn(f"the feet land at heights {spread:.0f} mm apart (lowest foot marker "
             "after each heel strike): stairs, a slope or a step? The event "
             "methods assume level walking or running; check these events",
             RuntimeWarning)


def _trial_rate(time):
    """The trial's rate from its time index (s), refused when too slow for marker data
    (an index in ms or frame numbers) and warned below MIN_RATE."""
    step = float(np.median(np.diff(time)))
    rate = 1.0 / step
    if rate < MIN_PLAUSIBLE_RATE:
        raise ValueError(f"dynamic.index (time) steps by {step:.4g}: {rate:.3g} Hz if in "
                         f"seconds, too slow for marker data (at least "
                         f"{MIN_PLAUSIBLE_RATE:g} Hz); the index must be time in seconds "
                         f"(is it in ms or frame numbers?)")
    if rate < MIN_RATE:
        warn(f"the trial is sampled at {rate:.3g} Hz, below the {MIN_RATE:g} Hz "
             f"from which the events are validated (tools/validate_gait_events.py):"
             f" one frame is {1000 * step:.0f} ms, and the filtered accelerations "
             f"that time the contacts are unreliable; check the events",
             RuntimeWarning)
    return rate


def _check_units(pelvis, feet, up, mm, units):
    """Refuse a pelvis whose median height above the feet is not a human's in the
    trial's stated units (metres labelled mm, mm labelled m)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)       # frames without data: NaN
        feet_mean = np.nanmean([point for foot in feet.values() for point in foot.values()],
                               axis=0)
        height = float(np.nanmedian((pelvis - feet_mean) @ up)) * mm
    if np.isfinite(height) and not PELVIS_HEIGHT[0] <= height <= PELVIS_HEIGHT[1]:
        raise ValueError(f"dynamic: the pelvis lies {height:.4g} mm above the feet (median) "
                         f"if the coordinates are in {units!r} (attrs['units']), but a "
                         f"person's lies {PELVIS_HEIGHT[0]:g}-{PELVIS_HEIGHT[1]:g} mm above "
                         f"them: are the units right (metres or cm labelled mm?)")


def _check_missing_events(events):
    """Warn once when a side's events leave out some: one list holds 2 or more events
    fewer than the other, or an interval between successive events is 1.7 times the
    side's usual stride or longer (gaps in the foot markers drop events)."""
    found = []
    for side, kinds in events.items():
        counts = {kind: len(kinds[kind]) for kind in EVENTS}
        intervals = np.concatenate([np.diff(kinds[kind]) for kind in EVENTS])
        stride = float(np.median(intervals)) if intervals.size else np.nan
        for kind in EVENTS:
            other = counts[EVENTS[1 - EVENTS.index(kind)]]
            long = np.diff(kinds[kind]) >= 1.7 * stride
            if other - counts[kind] >= 2 or long.any():
                found.append(f"{side} {kind.replace('_', ' ')}s ({counts[kind]} against "
                             f"{other} {EVENTS[1 - EVENTS.index(kind)].replace('_', ' ')}s"
                             + (f", {int(long.sum())} interval(s) of 1.7 strides or more"
                                if long.any() else "") + ")")
    if found:
        warn("events seem missing: " + "; ".join(found) + ". Gaps in the foot "
             "markers around an event drop it (never interpolated); fill the gaps "
             "or check these events", RuntimeWarning)


def _check_alternation(events):
    """Warn when right and left heel strikes come together (jumping, hopping)."""
    if len(events) < 2:
        return
    strikes = [events[side]["heel_strike"] for side in ("right", "left")]
    if not all(len(s) for s in strikes):
        return
    gap = np.min(np.abs(strikes[0][:, None] - strikes[1][None, :]), axis=1)
    together = np.count_nonzero(gap < MIN_STEP)
    if together:
        warn(f"{together} of {len(strikes[0])} right heel strikes come within "
             f"{1000 * MIN_STEP:g} ms of a left one: both feet land together "
             "(jumping, hopping?), which is not walking or running; check these "
             "events", RuntimeWarning)


def _walking_or_running(zeni, pelvis_height):
    """'walking' if the pelvis is higher in the middle of stances and swings than at their
    ends, else 'running'."""
    rise = []
    for found in zeni.values():
        for first, second in (("heel_strike", "toe_off"), ("toe_off", "heel_strike")):
            starts, ends = found[first], found[second]
            for start in starts:                      # loop over events (a few), not frames
                after = ends[ends > start]
                again = starts[starts > start]
                if after.size and (not again.size or after[0] < again[0]):
                    ends_mean = 0.5 * (pelvis_height[start] + pelvis_height[after[0]])
                    rise.append(pelvis_height[(start + after[0]) // 2] - ends_mean)
    rise = np.asarray(rise)
    rise = rise[~np.isnan(rise)]
    if rise.size < 2:
        warn(f"gait='auto' decided from {rise.size} stance or swing interval(s) "
             "only (the trial is short or has gaps); pass gait='walking' or "
             "'running' to be sure", RuntimeWarning)
    if rise.size == 0:
        return "walking"
    return "walking" if np.mean(rise) > 0 else "running"


def _first_peak(signals, start, stop, speeds=None):
    """Earliest of the maxima of several signals within [start, stop); None if none has a
    peak there, -1 if a signal with a peak elsewhere has a gap in the window.

    With `speeds` (the markers' vertical speeds), a marker whose acceleration has no peak
    inside the window (its largest value on the window's edge: its impact is smoothed
    out, as at 50-60 Hz) lands where its speed comes back to zero from its fastest
    descent in the window (:func:`_descent_end`): the floor stops it.
    """
    peaks = {role: _argmax_in(signal, start, stop) for role, signal in signals.items()}
    if speeds is not None:
        peaks.update({role: _descent_end(speeds[role], start, stop)
                      for role, p in peaks.items() if p is None})
    found = {role: p for role, p in peaks.items() if p is not None}
    if found.get("ANKLE_LAT") == -1 and found.get("HEEL", -1) != -1:
        del found["ANKLE_LAT"]      # the malleolus lands with the heel or after: not needed
    if not found or -1 in found.values():          # a marker in a gap: the data cannot tell
        return None, None
    role = min(found, key=found.get)
    return found[role], role


def _walking_events(zeni, foot, heading, up, rate, time, labels, edge=((), 1.0)):
    """Refine Zeni's events of one side for walking (Hreljac & Marshall, 2000); `edge`:
    (``[0]`` for a heel strike whose window the recording's start cuts, else ``[]``; mm
    per unit)."""
    strike_window = [int(round(STRIKE_WINDOW[0] * rate / 1000)),   # the far end outwards
                     _frames(STRIKE_WINDOW[1], rate)]
    off_window = [_frames(ms, rate) for ms in OFF_WINDOW]
    speed = {role: _derivative(point @ up, rate, 1) for role, point in foot.items()}
    vertical = {role: _derivative(v, rate, 1) for role, v in speed.items()}
    forward = _derivative(foot[_toe(foot)] @ heading, rate, 2)
    heights = np.array([point @ up for point in foot.values()])
    strikes, strike_roles = [], set()
    for guess in np.union1d(zeni["heel_strike"], edge[0]).astype(int):
        found, role = _first_peak(vertical, guess - strike_window[0],
                                  guess + strike_window[1] + 1, speed)
        if found is not None and (guess not in edge[0] or _lands_in_data(
                heights, found, rate, FLOOR_BAND / edge[1], NEAR_FLOOR / edge[1])):
            strikes.append(found)
            strike_roles.add(role)
    offs = []
    for guess in zeni["toe_off"]:
        found = _argmax_in(forward, guess - off_window[0], guess + off_window[1] + 1)
        if found is not None and found != -1:
            offs.append(found)
    used = {"heel_strike": sorted(labels[role] for role in strike_roles),
            "toe_off": [labels[_toe(foot)]] if offs else []}
    return ({"heel_strike": time[np.unique(np.array(strikes, dtype=int))],
             "toe_off": time[np.unique(np.array(offs, dtype=int))]}, used)


def _running_events(zeni, height, rate, time, near_floor, labels, edge=((), 1.0)):
    """Refine Zeni's events of one side for running (Handsaker et al., 2016); `edge` as
    for :func:`_walking_events`."""
    frames_per_ms = rate / 1000.0
    landing = max(2, int(round(LANDING_TIME * rate)))
    accel = {role: _derivative(h, rate, 2) for role, h in height.items()}
    toe = "TOE" if "TOE" in height else "MT5"
    jerk = _derivative(height[toe], rate, 3)
    strikes, strike_roles = [], set()
    for guess in np.union1d(zeni["heel_strike"], edge[0]).astype(int):
        first, role = _first_peak(accel, guess - int(round(50 * frames_per_ms)),
                                  guess + int(round(100 * frames_per_ms)))
        if first is not None and guess in edge[0] and not _lands_in_data(
                np.array(list(height.values())), first, rate, FLOOR_BAND / edge[1],
                near_floor):
            continue
        # a foot marker near this contact's floor: its low level within LANDING_TIME
        # either side (foot flat after a touchdown; the stance before a marker that
        # rises after a toe-off, which is no touchdown)
        if first is not None and min(h[first] - _floor(h, first - landing, first + landing)
                                     for h in height.values()) <= near_floor:
            strikes.append(first)
            strike_roles.add(role)
    strikes = np.array(strikes, dtype=int)
    offs = []
    for guess in zeni["toe_off"]:
        before = strikes[strikes < guess]
        # the toe leaves the floor from the floor of the stance it ends: its low level
        # from that stance's touchdown on (the trial's when the touchdown is not in the
        # data); its jerk peak is searched among the frames with the toe within
        # near_floor of it (a larger peak in early swing is no toe-off)
        if before.size and guess - before[-1] < 500 * frames_per_ms:
            start = before[-1] + int(round(0.35 * (guess - before[-1])))
            floor = _floor(height[toe], before[-1], guess + 1)
        else:
            start = guess - int(round(200 * frames_per_ms))
            floor = _floor(height[toe], 0, len(time))
        with np.errstate(invalid="ignore"):
            grounded = np.where(height[toe] - floor > near_floor, -np.inf, jerk)
        found = _argmax_in(grounded, start, guess + int(round(30 * frames_per_ms)) + 1)
        if found is not None and found != -1:
            offs.append(found)
    offs = np.array(offs, dtype=int)
    used = {"heel_strike": sorted(labels[role] for role in strike_roles),
            "toe_off": [labels[toe]] if offs.size else []}
    return {"heel_strike": time[np.unique(strikes)], "toe_off": time[np.unique(offs)]}, used


def _floor(height, start, stop):
    """A marker's floor level over frames [start, stop) (clipped to the trial): the 5th
    percentile of its height (NaN-aware), so that each contact of a stair has its own
    (over the whole trial it would be the lowest step's)."""
    part = height[max(start, 0):max(stop, 1)]
    if not np.isfinite(part).any():
        return np.nan
    return float(np.nanpercentile(part, 5))


#: Side and event names accepted for ``events[side][event]`` (case, spaces, '_' and '-'
#: ignored, see :func:`event_key`): the C3D EVENT group's contexts and labels (Vicon's
#: 'Right', 'Foot Strike') and the package's own ('right', 'heel_strike').
SIDE_NAMES = {"right": "right", "left": "left", "r": "right", "l": "left"}
EVENT_NAMES = {"footstrike": "heel_strike", "footoff": "toe_off",
               "heelstrike": "heel_strike", "toeoff": "toe_off"}


def event_key(text):
    """`text` with case, spaces, '_' and '-' ignored: 'Heel Strike', 'heel_strike' and
    'heel-strike' give the same key ('heelstrike')."""
    return "".join(str(text).replace("_", " ").replace("-", " ").split()).casefold()


def checked_event_times(events, name):
    """`events` (side -> event -> times) checked: a dict of dicts of finite times (s), each
    as a 1-D float array (what write_events and compare_events take), with the sides and
    events named as the package names them ('Right' -> 'right', 'Foot Strike' or
    'heel strike' -> 'heel_strike', see :data:`SIDE_NAMES`, :data:`EVENT_NAMES`)."""
    if not isinstance(events, Mapping):
        raise ArgumentTypeError(f"{name} must be a dict side -> {{event: times}} as "
                                f"returned by gait_events or force_plate_events; got "
                                f"{type(events).__name__}")
    out = {}
    for side, found in events.items():
        if not isinstance(found, Mapping):
            raise ArgumentTypeError(f"{name}[{side!r}] must be a dict event -> times "
                                    f"(e.g. {{'heel_strike': [...], 'toe_off': [...]}}); "
                                    f"got a {type(found).__name__}")
        side_name = _event_name(side, SIDE_NAMES, name, "side", out)
        out[side_name] = {}
        for event, times in found.items():
            event_name = _event_name(event, EVENT_NAMES, f"{name}[{side!r}]", "event",
                                     out[side_name])
            try:
                times = as_float_array(times, "times").ravel()
            except ValueError as error:
                raise ArgumentTypeError(f"{name}[{side!r}][{event!r}] must hold times (s); "
                                        f"got {times!r} ({error})") from None
            if not np.all(np.isfinite(times)):
                raise ValueError(f"{name}[{side!r}][{event!r}] must hold finite times (s); "
                                 f"got {np.count_nonzero(~np.isfinite(times))} NaN or inf")
            out[side_name][event_name] = times
    return out


def _event_name(key, names, name, what, taken):
    """The package's name of the side or event `key`; raise if unknown or given twice."""
    known = names.get(event_key(key))
    if known is None:
        expected = " or ".join(repr(v) for v in dict.fromkeys(names.values()))
        raise ValueError(f"{name}: {what} must be {expected}; got {key!r} (C3D spellings "
                         "such as 'Right' or 'Foot Strike' are accepted: case, spaces and "
                         "'_' ignored)")
    if known in taken:
        raise ValueError(f"{name}: the {what} {known!r} is given twice (as {key!r} and "
                         "another spelling)")
    return known


def match_events(detected, reference, tolerance):
    """Each reference time's signed error (detected minus reference), one-to-one.

    Every detected event is matched to at most one reference event and the reverse: the
    assignment that pairs the most events within `tolerance` (s) and, among those, has
    the smallest summed absolute error (scipy's ``linear_sum_assignment``). Reference
    events left unpaired get an error of inf.
    """
    reference = np.asarray(reference, dtype=float)
    detected = np.asarray(detected, dtype=float)
    error = np.full(reference.shape, np.inf)
    if not (reference.size and detected.size):
        return error
    gap = detected[None, :] - reference[:, None]
    near = np.abs(gap) <= tolerance
    # a pair beyond the tolerance costs more than every pair within it together
    cost = np.where(near, np.abs(gap), (min(gap.shape) + 1) * (tolerance + 1.0))
    rows, cols = linear_sum_assignment(cost)
    keep = near[rows, cols]
    error[rows[keep]] = gap[rows[keep], cols[keep]]
    return error
