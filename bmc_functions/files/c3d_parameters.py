r"""What a C3D file holds besides its markers: its parameters and the model outputs.

:func:`~bmc_functions.files.c3d.read_c3d` returns the marker trajectories. A C3D file
written by a motion-capture system holds more:

* **parameters** (groups of named values): POINT:RATE and the labels, but also, in a
  file processed by Vicon Nexus, the subject's measurements in the PROCESSING group
  (leg lengths, knee and ankle widths, the static offsets of Plug-in Gait, angles in
  radians) - :func:`read_c3d_parameters`;
* **model outputs**: points that are not markers but results, listed under POINT:ANGLES,
  FORCES, MOMENTS, POWERS, REACTIONS or SCALARS (Vicon's ``LKneeAngles``, ...), which
  ``read_c3d`` leaves out (``attrs['dropped_labels']``) - :func:`read_c3d_model_outputs`.
  The virtual points of a model (Plug-in Gait's joint centres and segment axes, ``PELO``,
  ``LFEO``, ...) are ordinary points: ``read_c3d`` returns them with the markers.

The parameter section is parsed here without a C3D library, after the structure checks
of :func:`bmc_functions.files._c3d_binary.check_c3d` (every record checked to lie inside the
section), so that a damaged file is refused with a message rather than read as
plausible numbers.
"""

import struct

import numpy as np
import pandas as pd

from .._checks import check_regular_file, warn
from ._c3d_binary import (NON_MARKER_GROUPS, PROCESSORS, check_c3d, read_float,
                          read_parameter_section, refuse_damaged, walk_parameters)
from .c3d import load_c3d_points
from .marker_table import COORDS, decode_text, zero_points_to_gaps

#: The subject measurements Vicon (Plug-in Gait) names, in the case its .vsk files write
#: them; a C3D file's PROCESSING group writes ``Left``/``Right`` as ``L``/``R``
#: (``LLegLength``). The file format's vocabulary: the models take their names from here.
VICON_SUBJECT_NAMES = ("Bodymass", "Height", "MarkerDiameter", "InterAsisDistance",
                       "LeftLegLength", "RightLegLength",
                       "LeftAsisTrocanterDistance", "RightAsisTrocanterDistance",
                       "LeftKneeWidth", "RightKneeWidth", "LeftAnkleWidth",
                       "RightAnkleWidth", "LeftTibialTorsion", "RightTibialTorsion",
                       "LeftSoleDelta", "RightSoleDelta",
                       "LeftThighRotation", "RightThighRotation",
                       "LeftShankRotation", "RightShankRotation",
                       "LeftStaticPlantFlex", "RightStaticPlantFlex",
                       "LeftStaticRotOff", "RightStaticRotOff",
                       "LeftAnkleAbAdd", "RightAnkleAbAdd")


def read_c3d_parameters(path):
    r"""Read every parameter of a C3D file: ``{GROUP: {NAME: value}}``.

    Parameters
    ----------
    path : str or path-like
        The ``.c3d`` file.

    Returns
    -------
    dict
        Group name -> {parameter name -> value}, names upper-case as the C3D format
        stores them (``params['PROCESSING']['LLEGLENGTH']``). Values: a float or int for
        a single number, a str for a single string, a list of str for an array of
        strings (trailing blanks removed), a NumPy array (C3D dimension order reversed,
        so that ``POINT:DESCRIPTIONS``-like tables read row by row) for an array of
        numbers. :func:`subject_parameters` maps the PROCESSING names back to the case
        Vicon writes (``LLegLength``).

    Raises
    ------
    ValueError
        If `path` is not a C3D file (no key 0x50), or its parameter section is cut or
        holds a record that runs outside it; the message names the file and the problem.
    FileNotFoundError, TypeError
        As :func:`~bmc_functions.files.c3d.read_c3d`.

    Notes
    -----
    C3D.org user guide [1]_: the parameter section starts in the block named by the
    header's first byte; after 4 bytes (the number of blocks, the processor type) come
    group records (negative id) and parameter records (positive id: the group's), each
    with a name, an offset to the next record, a data type (-1 char, 1 byte, 2 int16,
    4 float) and dimensions. Numbers are stored in the file's processor format (Intel,
    DEC or MIPS), which is honoured here.

    References
    ----------
    .. [1] C3D.org, "The C3D file format user guide", https://www.c3d.org

    Examples
    --------
    >>> from bmc_functions import read_c3d_parameters
    >>> from bmc_functions.examples import example_file   # the Plug-in Gait subject, shipped
    >>> params = read_c3d_parameters(example_file("plug_in_gait/Movement_trial.c3d"))
    >>> params["POINT"]["RATE"], params["PROCESSING"]["LLEGLENGTH"]
    (120.0, 877.0)
    """
    check_regular_file(path, "C3D")
    check_c3d(path)  # the header and every record checked before anything is decoded
    _, section, processor, _ = read_parameter_section(path)
    records = walk_parameters(section, 0, len(section), processor, refuse_damaged(path))
    groups = {}
    for (group, name), (kind, dims, at) in records.items():
        groups.setdefault(group, {})[name] = _decode(section, kind, dims, at, processor)
    return groups


def _decode(section, kind, dims, at, processor):
    """One parameter's value from its type, dimensions and offset in the section."""
    count = int(np.prod(dims, dtype=np.int64)) if dims else 1
    raw = section[at:at + abs(kind) * count]
    if kind == -1:  # characters: the first dimension is the length of each string
        if not dims:
            return decode_text(raw).rstrip()
        width = dims[0]
        texts = [decode_text(raw[k:k + width]).rstrip()
                 for k in range(0, len(raw), width)] if width else []
        if len(dims) == 1:
            return texts[0] if texts else ""
        return texts
    if kind == 4:
        values = np.array([read_float(raw[k:k + 4], processor)
                           for k in range(0, len(raw), 4)])
    else:
        code = {1: "b", 2: "h"}[kind]
        values = np.array(struct.unpack(PROCESSORS[processor] + code * count, raw))
    if count == 1 and len(dims) <= 1:
        return values[0].item()
    return values.reshape(tuple(reversed(dims))) if dims else values


def read_c3d_model_outputs(path, *, zeros_as_gaps=True):
    r"""Read the model outputs a C3D file carries (angles, forces, moments, powers, ...).

    Parameters
    ----------
    path : str or path-like
        The ``.c3d`` file (needs the optional package ezc3d).
    zeros_as_gaps : bool, optional
        If True (default), an output whose three components are all exactly 0 in a frame
        is a gap (NaN): Vicon Nexus writes (0, 0, 0) where it could not compute an output
        (a joint angle in frames where a marker it needs is missing), and such zeros
        overlaid with real curves pull means and peaks towards 0. False keeps them (a
        point with a negative residual is a gap either way: the C3D convention).

    Returns
    -------
    pandas.DataFrame
        The same layout as :func:`~bmc_functions.files.c3d.read_c3d`: columns
        ``(label, coord)`` with coords ``'x', 'y', 'z'`` (Vicon's X, Y, Z components, e.g.
        flexion, adduction, rotation of ``LKneeAngles``), index the time in seconds. Only
        the points listed under POINT:ANGLES, FORCES, MOMENTS, POWERS, REACTIONS or
        SCALARS; NaN where a point is invalid (negative residual) or, with `zeros_as_gaps`,
        exactly (0, 0, 0). ``attrs``: ``'rate'``, ``'frames'``, ``'groups'`` (label ->
        its group, e.g. ``'ANGLES'``), ``'units'`` (group -> the unit the file states,
        e.g. ``{'ANGLES': 'deg'}`` from POINT:ANGLE_UNITS, or ``''``),
        ``'invalid_points'`` (how many points, frame x output, had a negative residual)
        and ``'zero_points'`` (how many more were exactly (0, 0, 0) and became NaN), as
        :func:`~bmc_functions.files.c3d.read_c3d` counts them for markers.

    Raises
    ------
    ImportError, ValueError, TypeError
        As :func:`~bmc_functions.files.c3d.read_c3d` (a damaged file is refused).

    Warns
    -----
    UserWarning
        If the file is cut inside its data (the whole frames present are read); if
        outputs exactly at (0, 0, 0) were read as gaps: how many, in which outputs (one
        warning for both).

    Examples
    --------
    >>> from bmc_functions import read_c3d_model_outputs
    >>> from bmc_functions.examples import example_file   # the Plug-in Gait subject, shipped
    >>> out = read_c3d_model_outputs(example_file("plug_in_gait/Movement_trial.c3d"))
    >>> print(out["LKneeAngles"].iloc[0].round(2).to_dict())
    {'x': 26.41, 'y': 18.5, 'z': 2.84}
    >>> out.attrs["units"]["ANGLES"]
    'deg'
    """
    points = load_c3d_points(path, "read_c3d_model_outputs")
    group_of = {}
    for group in NON_MARKER_GROUPS:
        for label in points["non_markers"].get(group, []):
            group_of.setdefault(label.strip(), group)
    index = [k for k, label in enumerate(points["labels"]) if label in group_of]
    kept = [points["labels"][k] for k in index]
    xyz = points["xyz"][:, index, :]
    n_frames = xyz.shape[0]
    columns = pd.MultiIndex.from_product([kept, COORDS], names=["label", "coord"])
    df = pd.DataFrame(xyz.reshape(n_frames, 3 * len(kept)), columns=columns,
                      index=pd.Index(np.arange(n_frames) / points["rate"], name="time"))
    df.attrs = {"rate": points["rate"], "frames": points["frames"],
                "groups": {label: group_of[label] for label in kept},
                "units": _group_units(path, group_of),
                "invalid_points": int(np.count_nonzero(points["invalid"][:, index]))}
    messages = points["messages"]
    zero_points_to_gaps(df, zeros_as_gaps, messages, what="output",
                        why="the way Vicon Nexus fills an output it could not compute")
    if messages:
        warn(f"{path}: " + "; ".join(messages), UserWarning)
    return df


def _group_units(path, group_of):
    """Group -> the unit POINT:<GROUP>_UNITS states (ANGLES -> ANGLE_UNITS), or ''."""
    parameters = read_c3d_parameters(path)["POINT"]
    units = {}
    for group in sorted(set(group_of.values())):
        value = parameters.get(group.rstrip("S") + "_UNITS", "")
        units[group] = value if isinstance(value, str) else " ".join(value)
    return units


def subject_parameters(path):
    """The PROCESSING parameters of a C3D file (subject measurements), Vicon's names.

    Parameters
    ----------
    path : str or path-like
        A C3D file processed by Vicon Nexus (or any file with a PROCESSING group).

    Returns
    -------
    dict
        Name -> float, with the case Vicon writes (``'LLegLength'``,
        ``'InterAsisDistance'``: C3D parameter names are case-insensitive and
        :func:`read_c3d_parameters` returns them upper-case; the case of Vicon's
        measurement names, :data:`VICON_SUBJECT_NAMES`, is restored, other names stay
        upper-case). Lengths in mm, angles in radians, as
        Vicon stores them. Only single numbers are returned.

    Raises
    ------
    ValueError
        If the file has no PROCESSING group, or as :func:`read_c3d_parameters`.

    Examples
    --------
    >>> from bmc_functions.files.c3d_parameters import subject_parameters
    >>> from bmc_functions.examples import example_file   # the Plug-in Gait subject, shipped
    >>> subject = subject_parameters(example_file("plug_in_gait/Movement_trial.c3d"))
    >>> subject["LKneeWidth"], round(subject["LStaticPlantFlex"], 4)
    (144.0, 0.2527)
    """
    groups = read_c3d_parameters(path)
    if "PROCESSING" not in groups:
        raise ValueError(f"{path}: the C3D file has no PROCESSING parameter group (where "
                         f"Vicon Nexus writes the subject measurements); groups found: "
                         f"{', '.join(sorted(groups))}")
    known = {name.upper(): name for name in VICON_SUBJECT_NAMES}
    known.update({("L" + name[4:]).upper(): "L" + name[4:] for name in VICON_SUBJECT_NAMES
                  if name.startswith("Left")})
    known.update({("R" + name[5:]).upper(): "R" + name[5:] for name in VICON_SUBJECT_NAMES
                  if name.startswith("Right")})
    subject = {}
    for name, value in groups["PROCESSING"].items():
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            subject[known.get(name, name)] = float(value)
        elif isinstance(value, np.ndarray) and value.size == 1:
            subject[known.get(name, name)] = float(value.ravel()[0])
    return subject
