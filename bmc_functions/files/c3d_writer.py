r"""Results written back into a C3D file, where a lab's tools read them.

:func:`write_c3d` writes a copy of a trial (a C3D file, or a marker table) with the model
outputs of the package (joint angles, kinetics) as points listed under POINT:ANGLES,
FORCES, MOMENTS, POWERS or SCALARS, the way Vicon Nexus stores Plug-in Gait's outputs, and
the gait events in the EVENT group, so that Nexus, Polygon, Mokka and the package itself
(:func:`~bmc_functions.read_c3d_model_outputs`, :func:`~bmc_functions.read_events`) read
them.
"""

import os
from pathlib import Path

import numpy as np
import pandas as pd

from .._checks import check_output_path, check_regular_file
from ._c3d_binary import check_c3d, require_ezc3d
from .marker_table import check_marker_frame

#: Vicon's label (without the side letter) of each joint's angles.
VICON_ANGLE_LABELS = {"pelvis": "PelvisAngles", "hip": "HipAngles", "knee": "KneeAngles",
                      "ankle": "AnkleAngles", "foot": "FootProgressAngles",
                      "head": "HeadAngles", "thorax": "ThoraxAngles", "neck": "NeckAngles",
                      "spine": "SpineAngles", "shoulder": "ShoulderAngles",
                      "elbow": "ElbowAngles", "wrist": "WristAngles"}

#: The component (x, y, z: 0, 1, 2) of a Vicon angle point that each angle name fills:
#: sagittal, frontal, transverse (Plug-in Gait's X, Y, Z).
ANGLE_COMPONENTS = {"tilt": 0, "flexion": 0, "dorsiflexion": 0, "obliquity": 1,
                    "adduction": 1, "inversion": 1, "abduction": 1, "lateral_flexion": 1,
                    "ulnar_deviation": 1, "rotation": 2, "progression": 2}

#: Vicon's point (label ending, component, group) and the factor from the package's
#: units of each quantity of a ``(joint, side, quantity)`` kinetics table
#: (:meth:`~bmc_functions.PlugInGait.kinetics`): Vicon stores the moments in N·mm per kg
#: of body mass (the package: N·m/kg), the forces in N/kg and the power in W/kg as the Z
#: component of ``<S><Joint>Power``.
KINETIC_POINTS = {
    **{f"moment_{axis}": ("Moment", k, "MOMENTS", 1000.0) for k, axis in enumerate("xyz")},
    **{f"force_{axis}": ("Force", k, "FORCES", 1.0) for k, axis in enumerate("xyz")},
    "power": ("Power", 2, "POWERS", 1.0)}

#: The group of an output label by its ending, when the table does not say it
#: (``attrs['groups']``, as read_c3d_model_outputs sets it).
GROUP_ENDINGS = (("Angles", "ANGLES"), ("Angle", "ANGLES"), ("Moment", "MOMENTS"),
                 ("Force", "FORCES"), ("GRF", "FORCES"), ("Power", "POWERS"))

#: The unit parameter of each group, and the unit written when the file has none.
GROUP_UNITS = {"ANGLES": ("ANGLE_UNITS", "deg"), "FORCES": ("FORCE_UNITS", "N"),
               "MOMENTS": ("MOMENT_UNITS", "Nmm"), "POWERS": ("POWER_UNITS", "W")}

#: C3D event contexts and labels of the package's events (Vicon's words).
EVENT_CONTEXTS = {"right": "Right", "left": "Left"}
EVENT_LABELS = {"heel_strike": "Foot Strike", "toe_off": "Foot Off"}


def write_c3d(path, trial, *, angles=None, kinetics=None, events=None):
    r"""Write a copy of a trial with model outputs and gait events added (needs ezc3d).

    Parameters
    ----------
    path : str or path-like
        The C3D file to write (``.c3d`` is added if missing; its folder must exist).
    trial : str or path-like or pandas.DataFrame
        The trial: a C3D file, copied whole (markers, analog channels, force plates,
        parameters), or a marker table (:func:`~bmc_functions.read_trc`,
        :func:`~bmc_functions.read_c3d`; ``attrs['rate']`` and ``attrs['units']``).
    angles : pandas.DataFrame, optional
        Joint angles (degrees) indexed by time (s, from the trial's first frame): the
        ``(joint, side, angle)`` columns of the package's models, written as Vicon's
        points (``('knee', 'left', 'flexion')`` as ``LKneeAngles`` X; X, Y, Z the
        sagittal, frontal and transverse angles, :data:`ANGLE_COMPONENTS`; a component
        the table lacks, such as ``LFootProgressAngles`` X and Y, is written 0), or
        ``(label, coord)`` columns as :func:`~bmc_functions.read_c3d_model_outputs`
        returns them.
    kinetics : pandas.DataFrame, optional
        The ``(joint, side, quantity)`` table of :meth:`~bmc_functions.PlugInGait.kinetics`
        (or :meth:`~bmc_functions.LowerLimbModel.kinetics`, whose components are about its
        own segment axes), written as Vicon's points in Vicon's units
        (:data:`KINETIC_POINTS`: ``('knee', 'left', 'moment_x')`` as ``LKneeMoment`` X in
        N·mm/kg, ``force_*`` as ``LKneeForce`` in N/kg, ``power`` as ``LKneePower`` Z in
        W/kg); or ``(label, coord)`` columns indexed by time (``LKneeMoment``,
        ``LHipPower`` ...), each label under the group ``attrs['groups']`` names, else the
        one its ending names (:data:`GROUP_ENDINGS`: Moment, Force, Power; else SCALARS),
        written as they are.
    events : dict, optional
        ``{side: {'heel_strike': times, 'toe_off': times}}`` (s from the trial's first
        frame), as :func:`~bmc_functions.gait_events` or
        :func:`~bmc_functions.read_events` return them: written as Vicon's
        ``Right``/``Left`` ``Foot Strike``/``Foot Off`` events, replacing the foot events
        the trial held (its other events are kept).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    ValueError
        If a table's times do not fall on the trial's frames, an angle name is not one
        of :data:`ANGLE_COMPONENTS` (a kinetics quantity one of :data:`KINETIC_POINTS`),
        a table has other columns, or the trial is damaged
        (as :func:`~bmc_functions.read_c3d`); the message names the argument.
    FileNotFoundError
        If the folder of `path` or the trial does not exist.
    ImportError
        If ezc3d is not installed.

    Notes
    -----
    An output point with a label the trial already has (Vicon's own ``LKneeAngles``, say)
    is overwritten. A frame an output lacks (NaN, or no row) is written with residual -1,
    the C3D convention for an invalid point. A point whose three components are exactly 0
    (a lone component of 0.0 with the two not given) reads back as a gap, as Vicon's
    zero-filled outputs do (:func:`~bmc_functions.read_c3d_model_outputs`). Event times
    are stored as minutes and seconds from the start of the capture (frame 1 at 0 s), so
    the trial's first frame :math:`f_0` adds :math:`(f_0 - 1)/f_s`, as
    :func:`~bmc_functions.read_events` subtracts it. The trial is read by ezc3d in this
    process, after the structure checks of :func:`~bmc_functions.read_c3d`.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np, pandas as pd
    >>> from bmc_functions import read_c3d_model_outputs, read_events, read_trc, write_c3d
    >>> from bmc_functions.examples import example_file
    >>> trial = read_trc(example_file("markers/walk.trc"))
    >>> columns = pd.MultiIndex.from_tuples([("knee", "left", "flexion")])
    >>> angles = pd.DataFrame(np.linspace(5, 60, len(trial)), index=trial.index,
    ...                       columns=columns)
    >>> events = {"left": {"heel_strike": np.array([0.2]), "toe_off": np.array([0.8])}}
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = write_c3d(os.path.join(folder, "walk"), trial, angles=angles,
    ...                      events=events)
    ...     outputs = read_c3d_model_outputs(path)
    ...     back = read_events(path)
    >>> print(path.name, outputs["LKneeAngles"].iloc[-1].to_dict())
    walk.c3d {'x': 60.0, 'y': 0.0, 'z': 0.0}
    >>> print(back["left"]["heel_strike"].round(4), outputs.attrs["groups"])
    [0.2] {'LKneeAngles': 'ANGLES'}
    """
    require_ezc3d("write_c3d")
    target = Path(check_output_path(path))
    if target.suffix.lower() != ".c3d":
        target = target.with_name(target.name + ".c3d")
    c3d = _source(trial)
    rate = float(np.ravel(c3d["parameters"]["POINT"]["RATE"]["value"])[0])
    n_frames = c3d["data"]["points"].shape[2]
    for name, table in (("angles", angles), ("kinetics", kinetics)):
        if table is not None:
            _add_points(c3d, _outputs(table, name, rate, n_frames))
    if events is not None:
        _set_events(c3d, events, c3d["header"]["points"]["first_frame"] / rate)
    c3d.write(os.fspath(target))
    return target


def _source(trial):
    """The ezc3d object of the trial: the C3D file read (after the checks), or a new one
    holding the marker table."""
    import ezc3d  # optional dependency, imported where a C3D file is written

    if isinstance(trial, pd.DataFrame):
        markers, values = check_marker_frame(trial, "trial")
        rate = trial.attrs.get("rate")
        if not isinstance(rate, (int, float)) or not np.isfinite(rate) or rate <= 0:
            raise ValueError(f"trial: attrs['rate'] must be the frame rate (Hz), as "
                             f"read_trc sets it; got {rate!r}")
        c3d = ezc3d.c3d()
        c3d["parameters"]["POINT"]["RATE"]["value"] = [float(rate)]
        c3d["parameters"]["POINT"]["LABELS"]["value"] = tuple(markers)
        c3d["parameters"]["POINT"]["UNITS"]["value"] = [str(trial.attrs.get("units", "mm"))]
        xyz = values.reshape(len(trial), len(markers), 3)
        points = np.ones((4, len(markers), len(trial)))
        points[:3] = np.nan_to_num(xyz).transpose(2, 1, 0)
        c3d["data"]["points"] = points
        c3d["data"]["meta_points"]["residuals"] = np.where(
            np.isnan(xyz).any(axis=2), -1.0, 0.0).T[None]
        return c3d
    if not isinstance(trial, (str, os.PathLike)):
        raise TypeError(f"trial must be a C3D file's path or a marker DataFrame; got "
                        f"{type(trial).__name__}")
    check_regular_file(trial, "C3D")
    check_c3d(trial)              # a damaged file is refused before ezc3d reads it
    return ezc3d.c3d(os.fspath(trial))


def _outputs(table, name, rate, n_frames):
    """{label: (group, (n_frames, 3) values with NaN where missing)} of an outputs table."""
    if not isinstance(table, pd.DataFrame) or not isinstance(table.columns, pd.MultiIndex) \
            or table.columns.nlevels not in (2, 3):
        raise ValueError(f"{name} must be a DataFrame indexed by time with (joint, side, "
                         f"angle) or (label, coord) columns; got "
                         f"{type(table).__name__}")
    time = np.asarray(table.index, dtype=float)
    frames = np.rint(time * rate)
    if np.any(np.abs(time * rate - frames) > 0.01) or np.any(frames < 0) \
            or np.any(frames >= n_frames):
        raise ValueError(f"{name}: the times of its rows must be the trial's frames (s from "
                         f"the first frame, {n_frames} frames at {rate:g} Hz); got "
                         f"{time.min():g} to {time.max():g} s")
    frames = frames.astype(int)
    points, given = {}, {}
    for column in table.columns:                    # a loop over columns, not frames
        label, component, group, scale = _point_of(column, name,
                                                   table.attrs.get("groups", {}))
        values = points.setdefault(label, (group, np.full((n_frames, 3), np.nan)))[1]
        values[frames, component] = table[column].to_numpy(float) * scale
        given.setdefault(label, set()).add(component)
    for label, (group, values) in points.items():   # components not given: 0
        seen = np.isfinite(values).any(axis=1)
        for component in set(range(3)) - given[label]:
            values[seen, component] = 0.0
    return points


def _point_of(column, name, groups):
    """(label, component, group, factor to Vicon's unit) of one output column."""
    if len(column) == 3 and name == "kinetics":           # (joint, side, quantity)
        joint, side, quantity = column
        if side not in EVENT_CONTEXTS or quantity not in KINETIC_POINTS:
            raise ValueError(f"{name}: column {column!r}: the side must be 'right' or "
                             f"'left' and the quantity one of {', '.join(KINETIC_POINTS)}")
        ending, component, group, scale = KINETIC_POINTS[quantity]
        return side[0].upper() + str(joint).capitalize() + ending, component, group, scale
    if len(column) == 3:                                  # (joint, side, angle)
        joint, side, angle = column
        if side not in EVENT_CONTEXTS or angle not in ANGLE_COMPONENTS:
            raise ValueError(f"{name}: column {column!r}: the side must be 'right' or "
                             f"'left' and the angle one of {', '.join(ANGLE_COMPONENTS)}")
        stem = VICON_ANGLE_LABELS.get(joint, str(joint).capitalize() + "Angles")
        return side[0].upper() + stem, ANGLE_COMPONENTS[angle], "ANGLES", 1.0
    label, coord = column
    if coord not in ("x", "y", "z"):
        raise ValueError(f"{name}: column {column!r}: the coordinate must be 'x', 'y' or "
                         f"'z'")
    group = groups.get(label) or next((g for ending, g in GROUP_ENDINGS
                                       if str(label).endswith(ending)), "SCALARS")
    return str(label), "xyz".index(coord), group, 1.0


def _add_points(c3d, points):
    """Write `points` ({label: (group, (n_frames, 3))}) into `c3d`: overwritten where the
    label exists, appended otherwise; each label listed under its group."""
    point = c3d["parameters"]["POINT"]
    labels = [str(label).strip() for label in point["LABELS"]["value"]]
    data, residuals = c3d["data"]["points"], c3d["data"]["meta_points"]["residuals"]
    new = [label for label in points if label not in labels]
    if new:
        n_frames = data.shape[2]
        data = np.concatenate([data, np.zeros((4, len(new), n_frames))], axis=1)
        residuals = np.concatenate([residuals.reshape(1, -1, n_frames),
                                    np.zeros((1, len(new), n_frames))], axis=1)
        descriptions = list(point.get("DESCRIPTIONS", {}).get("value", []))
        if len(descriptions) == len(labels):
            c3d.add_parameter("POINT", "DESCRIPTIONS", descriptions + [""] * len(new))
        labels += new
        c3d.add_parameter("POINT", "LABELS", labels)
        c3d["data"]["meta_points"].pop("camera_masks", None)   # rebuilt by ezc3d
    for label, (group, values) in points.items():
        k = labels.index(label)
        missing = ~np.isfinite(values).all(axis=1)
        data[:3, k, :] = np.where(missing[:, None], 0.0, values).T
        data[3, k, :] = 1.0
        residuals[0, k, :] = np.where(missing, -1.0, 0.0)
        listed = [str(v).strip() for v in point.get(group, {}).get("value", [])]
        if label not in listed:
            c3d.add_parameter("POINT", group, listed + [label])
        unit = GROUP_UNITS.get(group)
        if unit and unit[0] not in c3d["parameters"]["POINT"]:
            c3d.add_parameter("POINT", unit[0], [unit[1]])
    c3d["data"]["points"] = data
    c3d["data"]["meta_points"]["residuals"] = residuals


def _set_events(c3d, events, start):
    """The EVENT group: the trial's events other than foot strikes and offs, then `events`
    (s from the first frame; `start` s after the capture's start)."""
    group = c3d["parameters"].get("EVENT", {})

    def value(name, default):
        return list(np.ravel(group[name]["value"])) if name in group else default

    kept = [row for row in zip(value("CONTEXTS", []), value("LABELS", []),
                               np.asarray(group["TIMES"]["value"]).T.tolist()
                               if "TIMES" in group else [],
                               value("DESCRIPTIONS", []), value("SUBJECTS", []))
            if not (str(row[0]).strip() in EVENT_CONTEXTS.values()
                    and str(row[1]).strip() in EVENT_LABELS.values())]
    if not isinstance(events, dict):
        raise TypeError(f"events must be a dict side -> {{'heel_strike': times, "
                        f"'toe_off': times}}; got {type(events).__name__}")
    subject = value("SUBJECTS", [""])[0] if value("SUBJECTS", []) else ""
    for side, found in events.items():                    # sides and kinds: a few rows
        for event, times in (found.items() if isinstance(found, dict) else ()):
            if side not in EVENT_CONTEXTS or event not in EVENT_LABELS:
                raise ValueError(f"events[{side!r}][{event!r}]: the sides must be 'right' "
                                 f"or 'left', the events 'heel_strike' or 'toe_off'")
            for time in np.sort(np.asarray(times, dtype=float)):
                total = time + start
                kept.append((EVENT_CONTEXTS[side], EVENT_LABELS[event],
                             [float(total // 60), float(total % 60)], "", subject))
    c3d.add_parameter("EVENT", "USED", len(kept))
    c3d.add_parameter("EVENT", "CONTEXTS", [row[0] for row in kept])
    c3d.add_parameter("EVENT", "LABELS", [row[1] for row in kept])
    c3d.add_parameter("EVENT", "TIMES", np.array([row[2] for row in kept]).reshape(-1, 2).T)
    c3d.add_parameter("EVENT", "DESCRIPTIONS", [row[3] for row in kept])
    c3d.add_parameter("EVENT", "SUBJECTS", [row[4] for row in kept])
    c3d.add_parameter("EVENT", "ICON_IDS", [0] * len(kept))
    c3d.add_parameter("EVENT", "GENERIC_FLAGS", [0] * len(kept))
