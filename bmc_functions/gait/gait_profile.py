r"""The lab's normative data and the Gait Profile Score against it (Baker et al. 2009).

What a clinical report adds to the cycles of :func:`~bmc_functions.gait.cycles.normalize_by_side`:

- :func:`normative_data`: mean and standard deviation per percent of the cycle of the lab's
  own control cycles (several subjects; left and right pooled), and
  :func:`write_normative_data` / :func:`read_normative_data` to keep them as a CSV file.
  The package ships no normative dataset: a reference curve belongs to the lab, its
  marker placement, its model and its population.
- :func:`gait_profile_score`: the Gait Variable Scores (GVS), the Movement Analysis Profile
  (MAP, the table of GVS) and the Gait Profile Score (GPS) of Baker et al. [1]_.

The nine variables (:data:`GPS_VARIABLES`) are named by the columns ``(joint, side, angle)``
that both kinematic models of the package return (the ISB lower-limb pipeline of
:func:`~bmc_functions.calibrate_lower_limb` and :func:`~bmc_functions.plug_in_gait`): Plug-in
Gait's ``LPelvisAngles`` X, Y, Z are ``('pelvis', 'left', 'tilt' / 'obliquity' /
'rotation')``, ``LHipAngles`` ``('hip', 'left', 'flexion' / 'adduction' / 'rotation')``,
``LKneeAngles`` X ``('knee', 'left', 'flexion')``, ``LAnkleAngles`` X ``('ankle', 'left',
'dorsiflexion')`` and ``LFootProgressAngles`` Z ``('foot', 'left', 'progression')``. The ISB
pipeline has no foot progression angle: its GPS is made of eight variables, and says so.

References
----------
.. [1] Baker R, McGinley JL, Schwartz MH, Beynon S, Rozumalski A, Graham HK, Tirosh O
   (2009). The Gait Profile Score and Movement Analysis Profile. Gait & Posture
   30(3):265-269. doi:10.1016/j.gaitpost.2009.05.020
"""

from collections import namedtuple
from collections.abc import Mapping

import numpy as np
import pandas as pd

from .._checks import (as_float_array, check_choice, check_finite_or_nan, check_output_path,
                       warn)
from ..models.plug_in_gait import VICON_OUTPUTS
from .events import SIDES

#: Baker et al. (2009)'s nine kinematic variables -> the ``(joint, angle)`` of the cycles'
#: columns (the side is the column's side). Hip abduction is the package's ``adduction``
#: column: a sign does not change a root-mean-square difference from a mean of the same sign.
GPS_VARIABLES = {
    "pelvic_tilt": ("pelvis", "tilt"),
    "pelvic_obliquity": ("pelvis", "obliquity"),
    "pelvic_rotation": ("pelvis", "rotation"),
    "hip_flexion": ("hip", "flexion"),
    "hip_abduction": ("hip", "adduction"),
    "hip_rotation": ("hip", "rotation"),
    "knee_flexion": ("knee", "flexion"),
    "ankle_dorsiflexion": ("ankle", "dorsiflexion"),
    "foot_progression": ("foot", "progression"),
}

#: The same nine variables in the model outputs Vicon Nexus stores for Plug-in Gait
#: (:func:`~bmc_functions.read_c3d_model_outputs`): ``(label without its side letter, X/Y/Z
#: component)``; ``'L'`` or ``'R'`` before the label gives the side. Taken from Plug-in
#: Gait's own table of Vicon's outputs (``models.plug_in_gait.VICON_OUTPUTS``), under whose
#: columns the package's Plug-in Gait returns the same values.
VICON_GPS_OUTPUTS = {name: (VICON_OUTPUTS[pair][0], "xyz"[VICON_OUTPUTS[pair][1]])
                     for name, pair in GPS_VARIABLES.items()}

#: The variables of the pelvis, one segment for both sides (counted once in the GPS).
PELVIS_VARIABLES = ("pelvic_tilt", "pelvic_obliquity", "pelvic_rotation")

#: The points of the cycle at which Baker et al. (2009) compare curves: every 2 % of the
#: cycle, 0 to 100 % (51 points).
GPS_PERCENT = np.linspace(0.0, 100.0, 51)

#: The statistics of a normative table and the columns of its CSV file.
STATISTICS = ("mean", "sd", "count")
CSV_COLUMNS = ["joint", "angle", "percent", "mean", "sd", "count"]

GaitProfile = namedtuple("GaitProfile", ["map", "gps", "per_cycle"])
GaitProfile.__doc__ = ("The Movement Analysis Profile (GVS per variable and side, deg), the "
                       "Gait Profile Score (left, right, overall, deg) and the GVS and GPS "
                       "of every cycle.")


def _check_cycles(cycles, name="cycles"):
    """A cycles DataFrame (or a list of them) checked: [(frame, side level)], one percent
    grid."""
    frames = [cycles] if isinstance(cycles, pd.DataFrame) else cycles
    if not isinstance(frames, (list, tuple)) or not frames or not all(
            isinstance(frame, pd.DataFrame) for frame in frames):
        raise TypeError(f"{name} must be a DataFrame of time-normalised cycles (as "
                        f"normalize_by_side returns) or a list of them; got "
                        f"{type(cycles).__name__}")
    percent = None
    for frame in frames:
        if (not isinstance(frame.index, pd.MultiIndex)
                or list(frame.index.names) != ["cycle", "percent"]):
            raise ValueError(f"{name} must be indexed by (cycle, percent), as "
                             f"normalize_by_side returns; got index names "
                             f"{list(frame.index.names)}")
        if (not isinstance(frame.columns, pd.MultiIndex) or frame.columns.nlevels != 3
                or not set(frame.columns.get_level_values(1)) & set(SIDES)):
            raise ValueError(f"{name} must have (joint, side, angle) columns with sides "
                             f"'right' and/or 'left', as normalize_by_side returns for the "
                             f"angles of the lower-limb pipeline or Plug-in Gait; got "
                             f"columns {list(frame.columns[:3])}")
        check_finite_or_nan(as_float_array(frame, name), name)
        points = np.unique(frame.index.get_level_values("percent").to_numpy(float))
        if percent is not None and not np.array_equal(points, percent):
            raise ValueError(f"{name}: every table must have the same points of the cycle; "
                             f"got {len(percent)} and {len(points)} points")
        percent = points
    return frames, percent


def _side_curves(frame, side, joint, angle):
    """(cycles, points) of one column of one side, the all-NaN (padding) cycles left out."""
    if (joint, side, angle) not in frame.columns:
        return None
    curves = frame[(joint, side, angle)].unstack("percent").to_numpy(float)
    return curves[~np.all(np.isnan(curves), axis=1)]


def normative_data(cycles):
    r"""Mean and SD per percent of the gait cycle of a lab's control cycles.

    Parameters
    ----------
    cycles : pandas.DataFrame or list of DataFrame
        The time-normalised cycles of the lab's control subjects (people without gait
        pathology), as :func:`~bmc_functions.normalize_by_side` returns them: indexed by
        ``(cycle, percent)``, columns ``(joint, side, angle)``. A list holds one table per
        trial or subject; all must have the same points of the cycle.

    Returns
    -------
    pandas.DataFrame
        Indexed by ``percent``, columns ``(statistic, joint, angle)`` with statistic
        ``'mean'``, ``'sd'`` (ddof=1) and ``'count'`` (the cycles at that point), the layout
        of :func:`~bmc_functions.ensemble`. Left and right cycles are pooled: a normative
        curve describes a limb, not a side (each side's cycle starts at its own heel
        strike, and the pelvis columns of the left side are already mirrored by the
        models). Every cycle weighs the same, so a subject with more cycles weighs more:
        pass each subject's mean cycle to weigh subjects equally.

    Raises
    ------
    TypeError, ValueError
        If `cycles` is not such a table, or the tables have different points.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> from bmc_functions import normative_data
    >>> index = pd.MultiIndex.from_product([[0, 1], [0.0, 50.0, 100.0]],
    ...                                    names=["cycle", "percent"])
    >>> columns = pd.MultiIndex.from_tuples([("knee", "right", "flexion"),
    ...                                      ("knee", "left", "flexion")])
    >>> cycles = pd.DataFrame([[5.0, 7], [60, 62], [5, 7], [3, 9], [58, 64], [3, 9]],
    ...                       index=index, columns=columns)
    >>> print(normative_data(cycles)["mean"])
    joint     knee
    angle  flexion
    percent
    0.0        6.0
    50.0      61.0
    100.0      6.0
    """
    frames, percent = _check_cycles(cycles)
    pairs = list(dict.fromkeys((joint, angle) for frame in frames
                               for joint, side, angle in frame.columns if side in SIDES))
    stats = {name: np.full((len(percent), len(pairs)), np.nan) for name in STATISTICS}
    for k, (joint, angle) in enumerate(pairs):            # a loop over columns
        curves = [_side_curves(frame, side, joint, angle)
                  for frame in frames for side in SIDES]
        curves = np.concatenate([c for c in curves if c is not None and len(c)]
                                + [np.empty((0, len(percent)))])
        count = np.count_nonzero(~np.isnan(curves), axis=0)
        stats["count"][:, k] = count
        with np.errstate(invalid="ignore", divide="ignore"):
            total = np.nansum(curves, axis=0)
            mean = np.where(count > 0, total / np.maximum(count, 1), np.nan)
            squares = np.nansum((curves - mean) ** 2, axis=0)
            stats["mean"][:, k] = mean
            stats["sd"][:, k] = np.where(count > 1, np.sqrt(squares / np.maximum(count - 1, 1)),
                                         np.nan)
    columns = pd.MultiIndex.from_tuples(pairs, names=["joint", "angle"])
    index = pd.Index(percent, name="percent")
    table = pd.concat({name: pd.DataFrame(stats[name], index=index, columns=columns)
                       for name in STATISTICS}, axis=1, names=["statistic"])
    table["count"] = table["count"].astype(int)
    return table


def write_normative_data(normative, path):
    """Write a normative table (:func:`normative_data`) to a CSV file.

    Parameters
    ----------
    normative : pandas.DataFrame
        As :func:`normative_data` returns.
    path : str or path-like
        The CSV file to write: one row per joint, angle and percent of the cycle, columns
        ``joint, angle, percent, mean, sd, count`` (degrees as the cycles were).

    Raises
    ------
    TypeError, ValueError
        If `normative` is not such a table, `path` not a file name.
    FileNotFoundError
        If the folder of `path` does not exist.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np, pandas as pd
    >>> from bmc_functions import normative_data, read_normative_data, write_normative_data
    >>> index = pd.MultiIndex.from_product([[0, 1], [0.0, 100.0]], names=["cycle", "percent"])
    >>> columns = pd.MultiIndex.from_tuples([("knee", "right", "flexion")])
    >>> normative = normative_data(pd.DataFrame([[5.0], [7], [3], [9]], index=index,
    ...                                         columns=columns))
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     write_normative_data(normative, os.path.join(folder, "normal.csv"))
    ...     back = read_normative_data(os.path.join(folder, "normal.csv"))
    >>> print(back.equals(normative))
    True
    """
    check_normative(normative, "normative")
    check_output_path(path)
    pairs = list(normative["mean"].columns)                 # the table's order, kept
    percent = normative.index.to_numpy(float)
    long = pd.DataFrame({
        "joint": np.repeat([joint for joint, _ in pairs], len(percent)),
        "angle": np.repeat([angle for _, angle in pairs], len(percent)),
        "percent": np.tile(percent, len(pairs)),
        **{name: normative[name].to_numpy().T.ravel() for name in STATISTICS}})
    long.to_csv(path, index=False)   # shortest repr: read back exactly


def read_normative_data(path):
    """Read a normative table written by :func:`write_normative_data` (or by hand).

    Parameters
    ----------
    path : str or path-like
        A CSV file with the columns ``joint, angle, percent, mean, sd, count`` (one row per
        joint, angle and percent of the cycle; an empty ``mean`` or ``sd`` is NaN).

    Returns
    -------
    pandas.DataFrame
        As :func:`normative_data` returns: indexed by ``percent``, columns
        ``(statistic, joint, angle)``.

    Raises
    ------
    ValueError
        If a column is missing, a number unreadable, or the joints do not share the same
        points of the cycle; the message names the file.

    Examples
    --------
    See :func:`write_normative_data`.
    """
    table = pd.read_csv(path, dtype={"joint": str, "angle": str})
    missing = [name for name in CSV_COLUMNS if name not in table.columns]
    if missing:
        raise ValueError(f"{path}: a normative CSV file needs the columns "
                         f"{', '.join(CSV_COLUMNS)}; missing {', '.join(missing)}")
    for name in ("percent", "mean", "sd", "count"):
        numbers = pd.to_numeric(table[name], errors="coerce")
        bad = numbers.isna() & table[name].notna() | (
            numbers.isna() if name in ("percent", "count") else False)
        if bad.any():
            raise ValueError(f"{path}: column {name!r} holds a value that is not a number "
                             f"(line {int(np.flatnonzero(bad)[0]) + 2})")
        table[name] = numbers.astype(float)
    keys = ["joint", "angle", "percent"]
    if table.duplicated(keys).any():
        row = table[table.duplicated(keys)].iloc[0]
        raise ValueError(f"{path}: {row['joint']} {row['angle']} at {row['percent']:g} % is "
                         f"given twice")
    order = list(dict.fromkeys(zip(table["joint"], table["angle"])))
    wide = table.set_index(keys)[list(STATISTICS)].unstack(["joint", "angle"])
    wide.columns = wide.columns.set_names(["statistic", "joint", "angle"])
    wide = wide.reindex(columns=pd.MultiIndex.from_tuples(
        [(s, j, a) for s in STATISTICS for j, a in order],
        names=["statistic", "joint", "angle"])).sort_index()
    if wide["count"].isna().any().any():
        raise ValueError(f"{path}: every joint and angle must be given at the same points "
                         f"of the cycle")
    wide["count"] = wide["count"].astype(int)
    wide.index = pd.Index(wide.index.to_numpy(float), name="percent")
    return wide


def check_normative(normative, name):
    """Refuse what is not a normative table (statistic, joint, angle) x percent."""
    if (not isinstance(normative, pd.DataFrame)
            or not isinstance(normative.columns, pd.MultiIndex)
            or normative.columns.nlevels != 3
            or list(normative.columns.names) != ["statistic", "joint", "angle"]
            or "mean" not in normative.columns.get_level_values(0)
            or normative.index.name != "percent"):
        raise ValueError(f"{name} must be the table normative_data or read_normative_data "
                         f"returns (indexed by percent, columns (statistic, joint, angle)); "
                         f"got {type(normative).__name__}"
                         + (f" with columns {list(normative.columns[:3])}"
                            if isinstance(normative, pd.DataFrame) else ""))


def _check_variables(variables):
    """The variable -> (joint, angle) mapping, checked (GPS_VARIABLES by default)."""
    if variables is None:
        return dict(GPS_VARIABLES)
    if not isinstance(variables, Mapping) or not variables or not all(
            isinstance(name, str) and isinstance(pair, tuple) and len(pair) == 2
            and all(isinstance(part, str) for part in pair)
            for name, pair in variables.items()):
        raise ValueError(f"variables must be a dict of variable name -> (joint, angle) "
                         f"strings, like GPS_VARIABLES ({{'knee_flexion': ('knee', "
                         f"'flexion'), ...}}); got {variables!r}"[:300])
    return dict(variables)


def _at_gps_points(curves, percent):
    """Curves (..., points) at `percent` linearly interpolated to GPS_PERCENT."""
    if curves.shape[-1] == len(GPS_PERCENT) and np.allclose(percent, GPS_PERCENT):
        return curves
    right = np.clip(np.searchsorted(percent, GPS_PERCENT, side="right"), 1, len(percent) - 1)
    weight = (GPS_PERCENT - percent[right - 1]) / (percent[right] - percent[right - 1])
    return curves[..., right - 1] * (1 - weight) + curves[..., right] * weight


#: Largest |angle| (degrees) of a table's variables below which, with the other table's
#: reaching :data:`UNIT_RATIO` times as far, the table is taken to be in radians: no
#: angle in radians exceeds pi; in degrees the nine GPS variables reach 30 to 70 over a
#: normal cycle (knee flexion about 60).
RADIAN_MAX = np.pi

#: Ratio of the two tables' largest |angle| beyond which one is in radians and the other in
#: degrees: half of 180/pi (57.3), so that a knee or pelvis that moves a third as much as
#: the normal one is still compared.
UNIT_RATIO = 90.0 / np.pi


def _check_same_units(frames, normal, variables):
    """A ValueError when `cycles` and `normative` are in different angle units: one's
    largest |angle| over the variables within pi (radians), the other's more than
    :data:`UNIT_RATIO` times larger."""
    largest = {}
    for name, tables in (("cycles", [frame.loc[:, [c for c in frame.columns
                                                    if (c[0], c[2]) in variables.values()]]
                                      for frame in frames]),
                         ("normative", [normal.loc[:, [c for c in normal.columns
                                                        if c in variables.values()]]])):
        values = np.concatenate([np.abs(t.to_numpy(float)).ravel() for t in tables])
        largest[name] = np.nanmax(values, initial=0.0) if values.size else 0.0
    for small, large in (("cycles", "normative"), ("normative", "cycles")):
        if 0 < largest[small] <= RADIAN_MAX and largest[large] > UNIT_RATIO * largest[small]:
            raise ValueError(f"{small} and {large} must be in the same unit, degrees; got "
                             f"{small}' angles within {largest[small]:.3g} and {large}' up "
                             f"to {largest[large]:.3g}: {small} in radians? "
                             f"(numpy.degrees converts them)")


def _counted(pelvis):
    """{side: set of the variables its GPS counts} for the pelvis convention."""
    counted = {side: set(GPS_VARIABLES) for side in SIDES}
    if pelvis != "each":
        other = "right" if pelvis == "left" else "left"
        counted[other] -= set(PELVIS_VARIABLES)
    return counted


def _side_scores(frame, side, reference, variables, percent):
    """Per-cycle GVS of one side of one cycles table: DataFrame (cycle x variable), the
    cycles with no value in any variable of that side (padding) left out."""
    columns = {}
    for name, (joint, angle) in variables.items():           # a loop over variables
        if (joint, side, angle) in frame.columns and name in reference:
            curves = frame[(joint, side, angle)].unstack("percent")
            differences = _at_gps_points(curves.to_numpy(float), percent) - reference[name]
            columns[name] = pd.Series(np.sqrt(np.mean(differences ** 2, axis=1)),
                                      index=curves.index)   # NaN where a point is NaN
    values = frame.loc[:, frame.columns.get_level_values(1) == side]
    present = values.notna().any(axis=1).groupby(level="cycle").any()
    table = pd.DataFrame(columns, columns=list(variables), dtype=float)
    return table.loc[present[present].index.intersection(table.index)]


def gait_profile_score(cycles, normative, *, variables=None, pelvis="left"):
    r"""Gait Variable Scores, Movement Analysis Profile and Gait Profile Score.

    Parameters
    ----------
    cycles : pandas.DataFrame or list of DataFrame
        One subject's time-normalised cycles, as :func:`~bmc_functions.normalize_by_side`
        returns them (columns ``(joint, side, angle)``, degrees); a list holds one table
        per trial.
    normative : pandas.DataFrame
        The lab's normative table (:func:`normative_data`, :func:`read_normative_data`),
        made by the same model as `cycles`; its ``'mean'`` is the reference curve.
    variables : dict, optional
        Variable name -> ``(joint, angle)`` of the columns. Default
        :data:`GPS_VARIABLES`, Baker et al.'s nine (both models of the package name their
        columns so). Override it for other column names, or to leave a variable out.
    pelvis : {'left', 'right', 'each'}, optional
        Which side's cycles the pelvis variables are counted in (see Notes). Default
        ``'left'``, the convention of Baker et al.

    Returns
    -------
    GaitProfile
        Named tuple:

        - ``map``: the Movement Analysis Profile, a DataFrame indexed by variable,
          columns ``'left'``, ``'right'``: each side's GVS (deg), the mean over that
          side's cycles of the GVS of each cycle. The pelvis GVS of the side that does not
          count them are shown too (they are scores of that side's cycles);
        - ``gps``: a Series ``'left'``, ``'right'``, ``'overall'`` (deg), the RMS of the
          GVS of ``map`` that count (see Notes);
        - ``per_cycle``: the GVS of every cycle, and its GPS (column ``'gps'``), indexed by
          ``(side, trial, cycle)``.

        ``map.attrs['counted']`` lists the ``(variable, side)`` pairs the overall GPS
        counts; ``map.attrs['cycles']`` the cycles per side.

    Raises
    ------
    TypeError, ValueError
        If `cycles` or `normative` is not such a table (or `cycles` holds no cycle, or
        either does not span 0 to 100 % of the cycle, or one is in radians and the other
        in degrees: one's angles all within pi, the other's :data:`UNIT_RATIO` times
        larger), `variables` not such a dict, `pelvis` none of the three.

    Warns
    -----
    UserWarning
        One warning: the variables missing from `cycles` or `normative` (the ISB
        pipeline has no foot progression: its GPS counts 8 variables) and the cycles left
        out of a variable because a point of theirs is missing.

    Notes
    -----
    Baker et al. [1]_ compare each kinematic variable :math:`x_i` of a cycle with the mean
    :math:`\bar x_i` of people without gait pathology at :math:`T = 51` points (every 2 %
    of the cycle, :data:`GPS_PERCENT`; curves given at other points are linearly
    interpolated there):

    .. math::

        \mathrm{GVS}_i = \sqrt{\frac{1}{T} \sum_{t=1}^{T} (x_{i,t} - \bar x_{i,t})^2},
        \qquad \mathrm{GPS} = \sqrt{\frac{1}{N} \sum_{i=1}^{N} \mathrm{GVS}_i^2}.

    The pelvis is one segment, its motion the same whichever foot starts the cycle: its
    three variables are counted once, in the left side's GPS, by the convention the
    authors recommend (as C-Motion's documentation of the paper's method states it [2]_,
    and as pyCGM2 implements it [3]_). So the left GPS holds 9 GVS, the right GPS the 6
    of the hip, knee, ankle and foot, and the overall GPS the 15 (GDI and GPS were
    designed on the same 15 features). The right side's pelvis GVS are in the MAP all the
    same (they score the right cycles), not in the GPS. ``pelvis='right'`` moves the
    pelvis to the right side; ``pelvis='each'`` counts it in both sides' GPS (9 and 9)
    and 18 GVS in the overall one, for comparison with tools that do so. A subject's GVS
    is the mean over their cycles of each cycle's GVS, and the GPS comes from those
    means, so that the MAP and the GPS agree (the GPS of each cycle is in
    ``per_cycle``). The GPS is in degrees, the units of the curves.

    References
    ----------
    .. [1] Baker R et al. (2009). The Gait Profile Score and Movement Analysis Profile.
       Gait & Posture 30(3):265-269.
    .. [2] HAS-Motion (C-Motion), "Gait Profile Score", Sift and Visual3D documentation
       (wiki.has-motion.com), with the equations of Baker et al. (2009, 2012).
    .. [3] pyCGM2, ``pyCGM2.Processing.Scores.scoreProcedures.CGM1_GPS``.

    Examples
    --------
    Three variables for brevity: control cycles 1 degree either side of a normal curve,
    and a subject 5 degrees above it in knee flexion, normal elsewhere:

    >>> import numpy as np, pandas as pd
    >>> from bmc_functions import gait_profile_score, normative_data
    >>> three = {"pelvic_tilt": ("pelvis", "tilt"), "hip_flexion": ("hip", "flexion"),
    ...          "knee_flexion": ("knee", "flexion")}
    >>> percent = np.linspace(0, 100, 101)
    >>> normal = 30 * np.sin(np.pi * percent / 100)
    >>> columns = pd.MultiIndex.from_tuples(
    ...     [(joint, side, angle) for side in ("left", "right")
    ...      for joint, angle in three.values()])
    >>> def cycles(*curves):
    ...     index = pd.MultiIndex.from_product([range(len(curves)), percent],
    ...                                        names=["cycle", "percent"])
    ...     return pd.DataFrame(np.concatenate([np.tile(c, (6, 1)).T for c in curves]),
    ...                         index=index, columns=columns)
    >>> normative = normative_data(cycles(normal - 1, normal + 1))
    >>> subject = cycles(normal)
    >>> subject.loc[:, ("knee", slice(None), "flexion")] += 5
    >>> profile = gait_profile_score(subject, normative, variables=three)
    >>> print(profile.map.round(3))
    side          left  right
    variable
    pelvic_tilt    0.0    0.0
    hip_flexion    0.0    0.0
    knee_flexion   5.0    5.0
    >>> print(profile.gps.round(3).to_dict())  # sqrt(25/3), sqrt(25/2), sqrt(50/5)
    {'left': 2.887, 'right': 3.536, 'overall': 3.162}
    """
    frames, percent = _check_cycles(cycles)
    check_normative(normative, "normative")
    variables = _check_variables(variables)
    check_choice(pelvis, "pelvis", ("left", "right", "each"))
    normal = normative["mean"]
    normal_percent = normal.index.to_numpy(float)
    for name, points in (("cycles", percent), ("normative", normal_percent)):
        if len(points) < 2 or points[0] != 0 or points[-1] != 100:
            raise ValueError(f"{name} must cover the whole cycle, 0 to 100 %; got points "
                             f"from {points[0]:g} to {points[-1]:g} %")
    _check_same_units(frames, normal, variables)
    reference = {name: _at_gps_points(normal[pair].to_numpy(float), normal_percent)
                 for name, pair in variables.items() if pair in normal.columns}
    parts = {(side, trial): _side_scores(frame, side, reference, variables, percent)
             for side in SIDES for trial, frame in enumerate(frames)}
    per_cycle = pd.concat(parts, names=["side", "trial", "cycle"])
    if per_cycle.empty:
        raise ValueError("cycles holds no gait cycle (every value NaN, or no row): a cycle "
                         "runs from one heel strike to the next of the same side")
    counted = {side: [name for name in variables
                      if name in _counted(pelvis)[side] or name not in GPS_VARIABLES]
               for side in SIDES}
    _warn_missing(per_cycle, variables, reference, counted)
    table = per_cycle.groupby(level="side", sort=False).mean().reindex(list(SIDES)).T
    table = table.reindex(columns=["left", "right"])
    table.index.name = "variable"
    pairs = [(name, side) for side in ("left", "right") for name in counted[side]
             if np.isfinite(table.loc[name, side])]
    gps = {side: _rms([table.loc[name, s] for name, s in pairs if s == side])
           for side in ("left", "right")}
    gps["overall"] = _rms([table.loc[name, side] for name, side in pairs])
    per_cycle["gps"] = [_rms([row[name] for name in counted[side] if np.isfinite(row[name])])
                        for (side, _, _), row in per_cycle.iterrows()]   # a loop over cycles
    table.attrs = {"counted": pairs,
                   "cycles": per_cycle.groupby(level="side").size().to_dict()}
    return GaitProfile(table, pd.Series(gps, name="gps"), per_cycle)


def _rms(values):
    """Root mean square of a list of numbers, NaN for none."""
    values = np.asarray(values, float)
    return float(np.sqrt(np.mean(values ** 2))) if values.size else np.nan


def _warn_missing(per_cycle, variables, reference, counted):
    """One warning naming the variables with no data and the cycles left out for gaps."""
    messages = []
    absent = [name for name in variables
              if name not in reference or per_cycle[name].isna().all()]
    if absent:
        messages.append(f"no {', '.join(absent)} in the cycles or the normative data: "
                        f"the GPS counts {len(variables) - len(absent)} of the "
                        f"{len(variables)} variables and is not comparable with a "
                        f"{len(variables)}-variable GPS")
    partial = per_cycle.drop(columns=absent).isna().sum()
    partial = partial[partial > 0]
    if len(partial):
        messages.append("cycles left out for a missing point: " + ", ".join(
            f"{name} {count} of {len(per_cycle)}" for name, count in partial.items()))
    if messages:
        warn("gait_profile_score: " + "; ".join(messages), UserWarning)
