r"""Each stride's phases and distances: what Vicon Nexus reports in a C3D file's ANALYSIS group.

:func:`stride_phases` times, within each stride (heel strike to heel strike of one side),
the other foot's toe-off and heel strike and this foot's toe-off, and the single and
double support they bound; :func:`stride_distances` measures the stride and step lengths
and the walking speed from a foot marker at the heel strikes.
:func:`~bmc_functions.gait.cycles.spatiotemporal_parameters` reports their means per side.

The definitions are those of Vicon Nexus's *Generate Gait Cycle Parameters* and Polygon
[1]_ (Vicon's glossary [2]_ for the lengths): distances between the positions of a foot
marker at foot contacts (Nexus's default: the toe marker), measured along the direction of
progression.

References
----------
.. [1] Vicon Motion Systems, "How does Nexus (Plug-in Gait) and Polygon calculate Gait
   Cycle Parameters (Spatial and Temporal)?", Vicon support FAQ.
.. [2] Vicon Motion Systems, Vicon MX Hardware System Reference, Glossary: "Step length",
   "Stride length".
"""

import warnings
from collections.abc import Mapping

import numpy as np

from .._checks import as_float_array, warn
from ..files.trial import load_trial, mm_per_unit
from ..markers.roles import check_known_roles, check_labels

#: The foot markers a stride is measured with, in the order they are preferred: the toe
#: (Vicon Nexus's default), else the heel, else the lateral malleolus.
DISTANCE_ROLES = ("TOE", "HEEL", "ANKLE_LAT")

#: The pelvis markers that, above the feet, give the lab's vertical.
PELVIS_ROLES = ("RASIS", "LASIS", "RPSIS", "LPSIS", "SACRUM")

OPPOSITE = {"right": "left", "left": "right"}


def _first_in(times, starts, ends):
    """For each (start, end): the first of the sorted `times` strictly inside, else NaN."""
    if not len(times):
        return np.full(len(starts), np.nan)
    index = np.searchsorted(times, starts, side="right")
    found = times[np.minimum(index, len(times) - 1)]
    return np.where((index < len(times)) & (found < ends), found, np.nan)


def stride_phases(events, strides):
    """The events inside each stride and the supports they bound.

    Parameters
    ----------
    events : dict
        ``{side: {'heel_strike': times, 'toe_off': times}}`` (s), checked.
    strides : pandas.DataFrame
        :func:`~bmc_functions.stride_table`'s strides (``side``, ``start``, ``end``).

    Returns
    -------
    pandas.DataFrame
        `strides` with the times (s) ``foot_off_time``, ``opposite_foot_off_time``,
        ``opposite_foot_contact_time`` (the first of each strictly inside the stride, NaN
        if none), the same as % of the stride (``foot_off``, ``opposite_foot_off``,
        ``opposite_foot_contact``), ``single_support`` (s, opposite foot off to opposite
        foot contact) and ``double_support`` (s, heel strike to opposite foot off plus
        opposite foot contact to foot off).
    """
    table = strides.copy()
    for column in ("foot_off_time", "opposite_foot_off_time", "opposite_foot_contact_time"):
        table[column] = np.nan
    for side in dict.fromkeys(table["side"]):                   # a loop over the sides
        rows = (table["side"] == side).to_numpy()
        start, end = table.loc[rows, "start"].to_numpy(), table.loc[rows, "end"].to_numpy()
        other = events.get(OPPOSITE.get(side), {})
        table.loc[rows, "foot_off_time"] = _first_in(events[side]["toe_off"], start, end)
        table.loc[rows, "opposite_foot_off_time"] = _first_in(
            np.asarray(other.get("toe_off", []), float), start, end)
        table.loc[rows, "opposite_foot_contact_time"] = _first_in(
            np.asarray(other.get("heel_strike", []), float), start, end)
    duration = table["end"] - table["start"]
    for name in ("foot_off", "opposite_foot_off", "opposite_foot_contact"):
        table[name] = 100.0 * (table[name + "_time"] - table["start"]) / duration
    ordered = ((table["opposite_foot_off_time"] < table["opposite_foot_contact_time"])
               & (table["opposite_foot_contact_time"] < table["foot_off_time"]))
    table["single_support"] = (table["opposite_foot_contact_time"]
                               - table["opposite_foot_off_time"]).where(ordered)
    table["double_support"] = ((table["opposite_foot_off_time"] - table["start"])
                               + (table["foot_off_time"]
                                  - table["opposite_foot_contact_time"])).where(ordered)
    return table


def _foot_marker(markers, side, labels, data):
    """The label of the first of DISTANCE_ROLES mapped for `side` with data in the trial."""
    prefix = "R" if side == "right" else "L"
    for role in DISTANCE_ROLES:
        label = markers.get(prefix + role)
        if isinstance(label, str) and label in labels and np.isfinite(data(label)).any():
            return label
    return None


def _vertical(markers, labels, data, feet):
    """The lab axis nearest the mean direction from the feet to the pelvis markers."""
    pelvis = [data(markers[role]) for role in PELVIS_ROLES
              if isinstance(markers.get(role), str) and markers[role] in labels]
    if not pelvis or not feet:
        raise ValueError("markers: the stride and step lengths need the pelvis markers "
                         "('RASIS' and 'LASIS', as gait_events takes them) to find the "
                         "vertical, and a foot marker ('RTOE', 'RHEEL' or 'RANKLE_LAT', and "
                         "the L ones) in the trial; got roles " + ", ".join(sorted(markers)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)      # frames without data: NaN
        up = np.nanmean(np.nanmean(pelvis, axis=0) - np.nanmean(list(feet.values()), axis=0),
                        axis=0)
    if not np.all(np.isfinite(up)):
        raise ValueError("trial: no frame has both the pelvis and the foot markers: the "
                         "vertical cannot be found")
    axis = int(np.argmax(np.abs(up)))
    return np.sign(up[axis]) * np.eye(3)[axis]


def _at(points, time, when):
    """Positions (k, 3) of `points` (n, 3) at the times `when` (k,), linearly interpolated
    between frames (exact at a frame's time; NaN next to a missing frame or outside)."""
    out = np.full((len(when), 3), np.nan)
    inside = np.isfinite(when) & (when >= time[0]) & (when <= time[-1])
    for k in range(3):                                        # a loop over coordinates
        out[inside, k] = np.interp(when[inside], time, points[:, k])
    return out


def _check_mapped_labels(markers, labels, name, dropped=()):
    """The pelvis and foot roles `markers` maps: known roles, labels in the trial."""
    check_known_roles(markers)
    used = [role for role in markers if role in PELVIS_ROLES
            or (role[:1] in "RL" and role[1:] in DISTANCE_ROLES)]
    check_labels(markers, used, labels, name, dropped)


def _check_event_times(phases, time, name):
    """A ValueError when no event of the strides lies within the trial's time (events of
    another trial, or a time base shifted); one warning naming the events outside it."""
    columns = ["start", "end", "opposite_foot_contact_time"]
    when = phases[[c for c in columns if c in phases]].to_numpy(float).ravel()
    when = np.unique(when[np.isfinite(when)])
    step = np.median(np.diff(time)) if len(time) > 1 else 0.0
    outside = when[(when < time[0] - step / 2) | (when > time[-1] + step / 2)]
    if not outside.size:
        return
    if outside.size == when.size:
        raise ValueError(f"events must lie within the trial's time, {time[0]:g} to "
                         f"{time[-1]:g} s{name.removeprefix('the trial trial')}; got every "
                         f"event outside it "
                         f"({when.min():g} to {when.max():g} s): the events of another "
                         f"trial, or times from another origin?")
    warn(f"spatiotemporal_parameters: {outside.size} event(s) outside the trial's time "
         f"({time[0]:g} to {time[-1]:g} s): {', '.join(f'{t:g} s' for t in outside[:6])}"
         f"{' ...' if outside.size > 6 else ''}; the strides they bound have no length",
         RuntimeWarning)


def stride_distances(phases, trial, markers, vertical=None, progression=None):
    """Stride length, step length and speed of each stride, from a foot marker.

    Parameters
    ----------
    phases : pandas.DataFrame
        :func:`stride_phases`' table.
    trial : pandas.DataFrame or path
        The marker trial the events were found in (a .trc or .c3d path, or the DataFrame
        of :func:`~bmc_functions.read_trc` / :func:`~bmc_functions.read_c3d`).
    markers : dict
        Role -> label, as :func:`~bmc_functions.gait_events` takes it.
    vertical, progression : array_like (3,), optional
        The lab's up and the direction of progression (unit vectors), as
        :func:`~bmc_functions.gait_events` finds them; found from the trial if None.

    Returns
    -------
    table : pandas.DataFrame
        `phases` with ``stride_length``, ``step_length`` (m) and ``speed`` (m/s).
    used : dict
        Side -> the label of the marker measured.

    Raises
    ------
    ValueError
        If `markers` names an unknown role, or maps a pelvis or foot role to a label the
        trial lacks (a misspelling: the message names the labels that look close); if
        every event of the strides lies outside the trial's time (more than half a
        frame before its first frame or after its last).

    Warns
    -----
    RuntimeWarning
        Naming the events outside the trial's time when only some are: the strides they
        bound have no length.
    """
    df, name = load_trial(trial, "trial")
    if not isinstance(markers, Mapping):
        raise TypeError(f"markers must be a dict mapping roles to labels (as gait_events "
                        f"takes it); got {type(markers).__name__}")
    mm, _ = mm_per_unit(df, name)
    time = as_float_array(df.index.to_numpy(), "trial.index (time)")
    labels = list(dict.fromkeys(df.columns.get_level_values(0)))
    _check_mapped_labels(markers, labels, name, df.attrs.get("dropped_labels", ()))
    _check_event_times(phases, time, name)
    labels = set(labels)

    def data(label):
        return df[label][["x", "y", "z"]].to_numpy(float) * mm

    used = {side: _foot_marker(markers, side, labels, data) for side in OPPOSITE}
    used = {side: label for side, label in used.items() if label is not None}
    feet = {side: data(label) for side, label in used.items()}
    up = (_vertical(markers, labels, data, feet) if vertical is None
          else np.asarray(vertical, float))
    table = phases.copy()
    start, end, contact = {}, {}, {}
    for side in OPPOSITE:                                    # a loop over the sides
        rows = (table["side"] == side).to_numpy()
        own = feet.get(side)
        other = feet.get(OPPOSITE[side])
        nan = np.full((np.count_nonzero(rows), 3), np.nan)
        start[side] = nan if own is None else _at(own, time,
                                                  table.loc[rows, "start"].to_numpy())
        end[side] = nan if own is None else _at(own, time, table.loc[rows, "end"].to_numpy())
        contact[side] = nan if other is None else _at(
            other, time, table.loc[rows, "opposite_foot_contact_time"].to_numpy())
    strides = np.concatenate([end[s] - start[s] for s in OPPOSITE])
    forward = _forward(strides, up, progression)
    for side in OPPOSITE:
        rows = (table["side"] == side).to_numpy()
        table.loc[rows, "stride_length"] = (end[side] - start[side]) @ forward / 1000.0
        table.loc[rows, "step_length"] = (end[side] - contact[side]) @ forward / 1000.0
    table["speed"] = table["stride_length"] / table["stride_time"]
    return table, used


def _forward(strides, up, progression):
    """The horizontal direction of progression: `progression` without its vertical part,
    or the mean horizontal stride; warns when the strides point elsewhere."""
    horizontal = strides - np.outer(strides @ up, up)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        mean = np.nanmean(horizontal, axis=0) if len(horizontal) else np.full(3, np.nan)
    forward = mean if progression is None else np.asarray(progression, float)
    forward = forward - (forward @ up) * up
    norm = np.linalg.norm(forward)
    if not np.isfinite(norm) or norm == 0:
        return np.full(3, np.nan)
    forward /= norm
    with np.errstate(invalid="ignore", divide="ignore"):
        cosine = (horizontal @ forward) / np.linalg.norm(horizontal, axis=1)
    off = np.count_nonzero(cosine < np.cos(np.radians(20.0)))
    if off:
        warn(f"{off} of {len(strides)} strides point more than 20 degrees away from the "
             f"direction of progression: the trial turns, and the lengths along it are "
             f"shorter than the strides", RuntimeWarning)
    return forward


def side_means(table, columns):
    """Per side, the mean of `columns` over the strides that have them (NaN if none)."""
    return table.groupby("side", sort=False)[columns].mean()
