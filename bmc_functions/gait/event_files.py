r"""Gait events stored beside a trial: the C3D EVENT group, and a CSV file.

Vicon Nexus, Qualisys, Motive and other capture programs write the foot strikes and foot
offs they (or the user) marked into the C3D file's EVENT group. :func:`read_events`
returns them in the structure :func:`gait_events` returns (:class:`GaitEvents`), so that
they can be compared with detected events (:func:`compare_events`), used to cut cycles
(:func:`normalize_by_side`) or kept; :func:`write_events` writes any such events to a
CSV file (one row per event: side, event, time), which :func:`read_events` reads back.
"""

import os
from pathlib import Path

import numpy as np
import pandas as pd

from .._checks import check_output_path, warn
from ..files._c3d_binary import read_checked
from .cycles import MAX_MEDIAN_STRIDE
from .events import EVENT_NAMES, SIDE_NAMES, GaitEvents, checked_event_times, event_key

#: C3D EVENT:CONTEXTS -> side, and EVENT:LABELS -> event (case, spaces, '_' and '-'
#: ignored); the CSV file's side and event columns are read with the same keys.
C3D_SIDES, C3D_EVENTS = SIDE_NAMES, EVENT_NAMES

#: The abbreviations of an event kind that a side's initial or name precedes or follows
#: in one text (Motion Analysis Cortex writes CONTEXTS ``LHS``, ``RTO`` and empty LABELS):
#: heel strike, foot strike, initial contact; toe off, foot off.
C3D_EVENT_ABBREVIATIONS = {"hs": "heel_strike", "fs": "heel_strike", "ic": "heel_strike",
                           "to": "toe_off", "fo": "toe_off"}

CSV_COLUMNS = ("side", "event", "time")


def _side_and_kind(text):
    """(side, event) that one C3D text names, None for a part it does not name; None
    for a text that is neither (``General``, ``Event``). Reads ``Right``, ``Foot Strike``
    and the combined forms ``RHS``, ``LTO``, ``Left Foot Off``, ``HS_R``."""
    key = event_key(text)
    if not key:
        return None, None
    if key in C3D_SIDES:
        return C3D_SIDES[key], None
    kinds = {**C3D_EVENTS, **C3D_EVENT_ABBREVIATIONS}
    if key in C3D_EVENTS:
        return None, C3D_EVENTS[key]
    for side in sorted(C3D_SIDES, key=len, reverse=True):     # 'left' before 'l'
        if key.startswith(side) and key[len(side):] in kinds:
            return C3D_SIDES[side], kinds[key[len(side):]]
        if key.endswith(side) and key[:-len(side)] in kinds:
            return C3D_SIDES[side], kinds[key[:-len(side)]]
    return None


def _c3d_event(path, context, label):
    """(side, event) of one C3D event from its context and label, None when the two do
    not make a right or left foot strike or foot off; ValueError when they contradict."""
    parts = [_side_and_kind(context), _side_and_kind(label)]
    if None in parts:
        return None
    found = []
    for index, what in enumerate(("side", "event")):
        named = {part[index] for part in parts} - {None}
        if len(named) > 1:
            raise ValueError(f"{path}: the EVENT group's event with context "
                             f"{context.strip()!r} and label {label.strip()!r} names two "
                             f"{what}s ({' and '.join(sorted(named))}); which one is "
                             f"meant is ambiguous: correct the file")
        found.append(named.pop() if named else None)
    return None if None in found else tuple(found)


def _check_kept(events, path, span=None, slack=1e-9):
    """Leave out (with one warning) events outside the trial's `span` (start, stop) in s
    by more than `slack` (s; an event within it is put on the first or last frame) and
    events stored twice (same side and kind, within 1 ms); warn when the times look
    like ms (a median stride above MAX_MEDIAN_STRIDE s)."""
    outside, twice, strides = [], 0, []
    for side, found in events.items():
        for event, times in found.items():
            times = np.sort(np.asarray(times, dtype=float))
            if span is not None:
                out = (times < span[0] - slack) | (times > span[1] + slack)
                outside += [f"{side} {event} at {t:.4g} s" for t in times[out]]
                times = np.clip(times[~out], span[0], span[1])
            keep = np.r_[True, np.diff(times) > 1e-3][:times.size]
            twice += int((~keep).sum())
            found[event] = times[keep]
            if event == "heel_strike" and times[keep].size > 1:
                strides.append(np.diff(times[keep]))
    if outside:
        warn(f"{path}: {len(outside)} event(s) lie outside the trial "
             f"({span[0]:.4g} to {span[1]:.4g} s) and were left out: "
             f"{', '.join(outside[:6])}", UserWarning)
    if twice:
        warn(f"{path}: {twice} event(s) stored twice (same side and kind within "
             f"1 ms); each kept once", UserWarning)
    if strides and np.median(np.concatenate(strides)) > MAX_MEDIAN_STRIDE:
        warn(f"{path}: successive heel strikes of a side are "
             f"{np.median(np.concatenate(strides)):.4g} apart (median), but a "
             f"stride lasts 0.4-3 s: are the times in milliseconds or frames? "
             f"They should be in seconds", UserWarning)


def _extract_events(source):
    """Read the EVENT group and the timing of the first frame with ezc3d (plain objects)."""
    import ezc3d

    c3d = ezc3d.c3d(str(source))
    params = c3d["parameters"]
    group = params.get("EVENT", {})

    def value(name, default):
        return group[name]["value"] if name in group else default

    point = params["POINT"]
    return {
        "used": int(np.ravel(value("USED", [0]))[0]) if np.size(value("USED", [0])) else 0,
        "contexts": [str(v) for v in value("CONTEXTS", [])],
        "labels": [str(v) for v in value("LABELS", [])],
        "times": np.asarray(value("TIMES", np.zeros((2, 0))), dtype=float),
        "rate": float(np.ravel(point["RATE"]["value"])[0]) if "RATE" in point else np.nan,
        "first_frame": int(c3d["header"]["points"]["first_frame"]),
        "last_frame": int(c3d["header"]["points"]["last_frame"]),
        "has_group": "EVENT" in params,
    }


def _read_c3d_events(path):
    info = read_checked(path, _extract_events, "read_events")
    times = info["times"]
    if times.ndim != 2 or times.shape[0] != 2:
        raise ValueError(f"{path}: EVENT:TIMES must hold (minutes, seconds) per event, "
                         f"shape (2, n); got shape {times.shape}")
    n = min(len(info["contexts"]), len(info["labels"]), times.shape[1])
    if info["used"] and n < info["used"]:
        raise ValueError(f"{path}: EVENT:USED says {info['used']} events but CONTEXTS, "
                         f"LABELS and TIMES describe {n}; the EVENT group is damaged")
    n = info["used"] if info["used"] else n
    # event times count from the start of the capture (frame 1); read_c3d's time axis
    # from the first stored frame
    start = info["first_frame"] / info["rate"]
    events = {}
    other = []
    for context, label, (minutes, seconds) in zip(info["contexts"][:n], info["labels"][:n],
                                                  times[:, :n].T):
        found = _c3d_event(path, context, label)
        if found is None:
            other.append(f"{context.strip()}/{label.strip()}")
            continue
        side, event = found
        side_events = events.setdefault(side, {"heel_strike": [], "toe_off": []})
        side_events[event].append(60.0 * minutes + seconds - start)
    if other:
        warn(f"{path}: {len(other)} of {n} events of the EVENT group are not a "
             f"right or left foot strike or foot off and were left out "
             f"({', '.join(sorted(set(other)))})", UserWarning)
    span = (0.0, (info["last_frame"] - info["first_frame"]) / info["rate"])
    # EVENT:TIMES are float32 (7 digits): an event on the first or last stored frame
    # may land a rounding error outside the trial; half a frame is still that frame
    _check_kept(events, path, span if np.all(np.isfinite(span)) else None,
                slack=0.5 / info["rate"])
    return events, "the C3D file's EVENT group", info["has_group"]


def _read_csv_events(path):
    try:
        table = pd.read_csv(path)
    except pd.errors.EmptyDataError:
        raise ValueError(f"{path}: the events file is empty; it needs the columns side, "
                         f"event, time") from None
    table.columns = [event_key(c) for c in table.columns]        # 'Time', ' side' ...
    missing = [c for c in CSV_COLUMNS if c not in table.columns]
    if missing:
        raise ValueError(f"{path}: an events file needs the columns side, event, time; "
                         f"{', '.join(missing)} missing (columns: {list(table.columns)})")
    side_keys = table["side"].map(event_key).map(C3D_SIDES)
    kind_keys = table["event"].map(event_key).map(C3D_EVENTS)
    unknown = set(table["side"][side_keys.isna()]) | set(table["event"][kind_keys.isna()])
    if unknown:
        raise ValueError(f"{path}: side must be 'right' or 'left' and event "
                         f"'heel_strike' or 'toe_off'; got "
                         f"{sorted(map(str, unknown))}")
    table["side"], table["event"] = side_keys, kind_keys
    time = pd.to_numeric(table["time"], errors="coerce")
    if not np.all(np.isfinite(time)):
        raise ValueError(f"{path}: column time must hold finite times (s); rows "
                         f"{np.flatnonzero(~np.isfinite(time))[:5].tolist()} do not")
    events = {}
    for (side, event), part in time.groupby([table["side"], table["event"]]):
        events.setdefault(side, {"heel_strike": [], "toe_off": []})[event] = part.tolist()
    _check_kept(events, path)
    return events, "a CSV events file", True


def read_events(path):
    r"""Gait events stored with a trial: a C3D file's EVENT group, or a CSV file.

    Parameters
    ----------
    path : str or path-like
        A ``.c3d`` file (its EVENT group: contexts ``Right``/``Left``, labels ``Foot
        Strike``/``Foot Off``) or a ``.csv`` file with columns ``side`` (``right``,
        ``left``), ``event`` (``heel_strike``, ``toe_off``) and ``time`` (s), as written
        by :func:`write_events` (other columns are ignored).

    Returns
    -------
    GaitEvents
        ``events[side][event]`` sorted arrays of times (s) on the time axis of
        :func:`read_c3d` (0 at the first stored frame) for a C3D file, as stored for a
        CSV file; both sides always present (empty arrays when the file has none).
        ``gait`` is None; ``method`` and ``source`` say where the events come from.

    Raises
    ------
    ValueError
        If the file is not a readable C3D file, its EVENT group is damaged or names two
        sides or kinds for one event, or the CSV
        file lacks a column or holds an unknown side, event or a non-numeric time.
    ImportError
        For a C3D file, if ezc3d is not installed.

    Warns
    -----
    UserWarning
        Once, naming the events of the EVENT group that are not a right or left foot
        strike or foot off (``General`` events, other labels): they are left out; and
        when a C3D file has no EVENT group or no foot event at all; once, naming the
        events outside the C3D trial's frames (left out); once for events stored twice
        (same side and kind within 1 ms: kept once); when a side's heel strikes are more
        than ``MAX_MEDIAN_STRIDE`` (10 s) apart (times in ms or frames?).

    Notes
    -----
    Contexts and labels, and the CSV file's column names, sides and events, are matched
    ignoring case, spaces, ``_`` and ``-`` (``Right``, ``R``, ``Foot_Strike``,
    ``Heel Strike``, ``Time`` are all read). A C3D event may also name side and kind in
    one text, in its context or its label, the other left empty or agreeing (Motion
    Analysis Cortex writes contexts ``LHS``, ``RHS``, ``LTO``, ``RTO`` and empty labels):
    a side (``R``, ``Right``) before or after ``HS``, ``FS``, ``IC`` (foot strike) or
    ``TO``, ``FO`` (foot off) or the full names. A context and a label that name two
    different sides or kinds (``Right`` with ``LHS``, ``RHS`` with ``Foot Off``) are
    ambiguous and raise a ValueError.


    A C3D event time is given as minutes and seconds (EVENT:TIMES, two rows) from the
    start of the capture, where frame 1 is at time 0; :func:`read_c3d` counts time from
    the first stored frame (POINT first frame :math:`f_0`, 1-based), so the stored time
    :math:`t_\mathrm{C3D}` becomes :math:`t = 60\,m + s - (f_0 - 1)/f_s` [1]_.

    References
    ----------
    .. [1] C3D.org, "The C3D file format user guide", chapter on the EVENT group,
       https://www.c3d.org

    Examples
    --------
    >>> import tempfile, os, numpy as np
    >>> from bmc_functions import read_events, write_events
    >>> events = {"right": {"heel_strike": np.array([0.5, 1.6]), "toe_off": np.array([1.2])},
    ...           "left": {"heel_strike": np.array([1.05]), "toe_off": np.array([0.65])}}
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "walk_events.csv")
    ...     table = write_events(events, path)
    ...     back = read_events(path)
    >>> print(table)
        side        event  time
    0  right  heel_strike  0.50
    1   left      toe_off  0.65
    2   left  heel_strike  1.05
    3  right      toe_off  1.20
    4  right  heel_strike  1.60
    >>> print(back.method, "|", back.gait)
    a CSV events file | None
    >>> print(back["right"]["heel_strike"])
    [0.5 1.6]
    """
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name (str or path-like); got "
                        f"{type(path).__name__}")
    suffix = Path(path).suffix.lower()
    if suffix == ".c3d":
        events, origin, has_group = _read_c3d_events(path)
        if not has_group or not events:
            warn(f"{path}: {'no EVENT group' if not has_group else 'no foot event'}"
                 " in the file: no stored events", UserWarning)
    elif suffix in (".csv", ".txt"):
        events, origin, _ = _read_csv_events(path)
    else:
        raise ValueError(f"path must be a .c3d or .csv file; got {os.fspath(path)!r}")
    result = {side: {event: np.sort(np.asarray(events.get(side, {}).get(event, []),
                                               dtype=float))
                     for event in ("heel_strike", "toe_off")}
              for side in ("right", "left")}
    return GaitEvents(result, gait=None, method=origin, source=os.fspath(path))


def write_events(events, path):
    """Write gait events to a CSV file (columns side, event, time), sorted by time.

    Parameters
    ----------
    events : dict
        ``events[side][event]`` arrays of times (s), as returned by :func:`gait_events`,
        :func:`force_plate_events` or :func:`read_events`.
    path : str or path-like
        The ``.csv`` file to write (e.g. beside the angles: ``walk_angles.csv`` and
        ``walk_events.csv``).

    Returns
    -------
    pandas.DataFrame
        The table written.

    Raises
    ------
    ValueError
        If a side is not ``'right'``/``'left'``, an event not ``'heel_strike'`` /
        ``'toe_off'``, or a time not finite.
    TypeError
        If `events` is not a dict of dicts, or `path` not a file name.
    FileNotFoundError
        If the folder of `path` does not exist.

    Examples
    --------
    See :func:`read_events`.
    """
    events = checked_event_times(events, "events")
    check_output_path(path)
    rows = []
    for side, found in events.items():
        if side not in ("right", "left"):
            raise ValueError(f"events: side must be 'right' or 'left'; got {side!r}")
        for event, times in found.items():
            if event not in ("heel_strike", "toe_off"):
                raise ValueError(f"events[{side!r}]: event must be 'heel_strike' or "
                                 f"'toe_off'; got {event!r}")
            rows += [(side, event, t) for t in times]
    table = pd.DataFrame(rows, columns=list(CSV_COLUMNS))
    table = table.sort_values(["time", "side", "event"], kind="stable", ignore_index=True)
    table.to_csv(path, index=False, float_format="%.6f")
    return table
