"""Small matplotlib helpers shared by the notebooks: 3D frames, marker clusters, equal axes,
and the gait-cycle figure (mean +- SD per joint and plane)."""

import hashlib
import re
import warnings
from collections import namedtuple
from collections.abc import Mapping

import numpy as np
import pandas as pd

from ._checks import (ArgumentTypeError, as_float_array, check_choice, check_finite_or_nan,
                      check_flag, check_number, check_scalar, check_vectors, warn)
from .gait.cycles import ensemble
from .gait.gait_profile import check_normative
from .markers.filtering import ResidualAnalysis

_AXIS_COLORS = ("tab:red", "tab:green", "tab:blue")


def set_axes_equal(ax):
    """Give a 3D axes the same scale on x, y and z, so that right angles look right.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> from bmc_functions.plotting import set_axes_equal
    >>> ax = plt.figure().add_subplot(projection='3d')
    >>> set_axes_equal(ax)
    >>> plt.close('all')
    """
    limits = np.array([ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d()])
    centre = limits.mean(axis=1)
    radius = 0.5 * np.max(limits[:, 1] - limits[:, 0])
    ax.set_xlim3d(centre[0] - radius, centre[0] + radius)
    ax.set_ylim3d(centre[1] - radius, centre[1] + radius)
    ax.set_zlim3d(centre[2] - radius, centre[2] + radius)
    ax.set_box_aspect((1, 1, 1))


def draw_frame(ax, R=None, origin=(0, 0, 0), length=1.0, label="", linestyle="-", alpha=1.0):
    """Draw the x, y, z axes of a frame (columns of `R`) as red, green, blue arrows.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D
    R : array_like, shape (3, 3), optional
        Rotation matrix whose columns are the frame's axes; identity if omitted.
    origin : array_like, shape (3,)
    length : float
        Length of the drawn axes.
    label : str
        Text drawn at the tip of each axis as ``x_label`` etc. (mathtext subscript).
    linestyle : str
    alpha : float

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> from bmc_functions import rot_z
    >>> from bmc_functions.plotting import draw_frame
    >>> ax = plt.figure().add_subplot(projection='3d')
    >>> draw_frame(ax, rot_z(0.5), label="B")
    >>> plt.close('all')
    """
    R = np.eye(3) if R is None else as_float_array(R, "R")
    if R.shape != (3, 3):
        raise ValueError(f"R must have shape (3, 3); got shape {R.shape}")
    check_finite_or_nan(R, "R")
    length = check_number(length, "length", positive=True)
    alpha = check_number(alpha, "alpha")
    origin = check_vectors(origin, "origin")
    for n, (color, name) in enumerate(zip(_AXIS_COLORS, "xyz")):
        tip = origin + length * R[:, n]
        ax.plot(*np.stack([origin, tip], axis=1), color=color, linestyle=linestyle,
                alpha=alpha, linewidth=2)
        ax.scatter(*tip, color=color, marker=">", s=0, alpha=0)  # keeps tips in the limits
        if label:
            ax.text(*tip, f"${name}_{{{label}}}$", color=color)


def plot_markers(ax, markers, color="k", label=None, connect=True, marker="o", **kwargs):
    """Scatter a marker cluster in 3D, optionally joined as a closed polygon.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D
    markers : array_like, shape (n, 3)
        One marker per row.
    color, label, marker : passed to ``ax.scatter``.
    connect : bool
        Join consecutive markers (and the last to the first) with thin lines.
    **kwargs : passed to ``ax.scatter``.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> from bmc_functions.plotting import plot_markers
    >>> ax = plt.figure().add_subplot(projection='3d')
    >>> plot_markers(ax, [[0, 0, 0], [1, 0, 0], [0, 1, 0]], label="static")
    >>> plt.close('all')
    """
    connect = check_flag(connect, "connect")
    markers = check_vectors(markers, "markers")
    if markers.ndim != 2:
        raise ValueError(f"markers must have shape (n, 3); got shape {markers.shape}")
    ax.scatter(*markers.T, color=color, label=label, marker=marker, depthshade=False,
               **kwargs)
    if connect and len(markers) > 1:
        closed = np.vstack([markers, markers[:1]])
        ax.plot(*closed.T, color=color, linewidth=0.8, alpha=0.6)


def plot_frames_row(R, titles=None, length=1.0, label="", reference=True, figsize=None,
                    elev=20, azim=-60):
    """Draw several frames side by side, one 3D panel each, over the fixed global frame.

    Useful to follow a sequence of rotations step by step (each panel one intermediate
    frame) or to compare two results (for example two rotation orders).

    Parameters
    ----------
    R : array_like, shape (n, 3, 3)
        Rotation matrices; the columns of ``R[i]`` are the axes of the frame in panel i.
    titles : sequence of str, optional
        One title per panel.
    length : float
        Length of the drawn axes.
    label : str
        Subscript written at the tips of the axes (see :func:`draw_frame`).
    reference : bool
        Also draw the global frame, dashed and faint, in every panel.
    figsize : tuple of float, optional
        Figure size; default ``(3.2 * n, 3.4)``.
    elev, azim : float
        Viewing angles passed to ``ax.view_init``, the same for every panel.

    Returns
    -------
    fig : matplotlib.figure.Figure
    axes : list of mpl_toolkits.mplot3d.Axes3D

    Raises
    ------
    ValueError
        If `R` is not of shape (n, 3, 3) or `titles` does not have n items.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> from bmc_functions import rot_x, rot_z
    >>> from bmc_functions.plotting import plot_frames_row
    >>> fig, axes = plot_frames_row([rot_z(0.5), rot_z(0.5) @ rot_x(0.5)],
    ...                             titles=["after z", "after z, x"])
    >>> len(axes)
    2
    >>> plt.close('all')
    """
    import matplotlib.pyplot as plt  # imported here so the package works without a display

    R = as_float_array(R, "R")
    if R.ndim != 3 or R.shape[1:] != (3, 3):
        raise ValueError(f"R must have shape (n, 3, 3), one rotation matrix per panel; "
                         f"got shape {R.shape}")
    check_finite_or_nan(R, "R")
    reference = check_flag(reference, "reference")
    length = check_number(length, "length", positive=True)
    elev, azim = check_number(elev, "elev"), check_number(azim, "azim")
    n = R.shape[0]
    if titles is not None and (isinstance(titles, str) or not hasattr(titles, "__len__")):
        raise ValueError(f"titles must be a sequence of strings, one per panel; got "
                         f"{type(titles).__name__}")
    if titles is not None and len(titles) != n:
        raise ValueError(f"titles must have one item per panel ({n}); got {len(titles)}")
    fig = plt.figure(figsize=_check_figsize(figsize) or (3.2 * n, 3.4))
    axes = []
    for i in range(n):  # one panel per matrix (a handful), not a loop over frames of data
        ax = fig.add_subplot(1, n, i + 1, projection="3d")
        if reference:
            draw_frame(ax, np.eye(3), length=length, linestyle="--", alpha=0.35)
        draw_frame(ax, R[i], length=length, label=label)
        lim = 1.1 * length
        ax.set_xlim3d(-lim, lim)
        ax.set_ylim3d(-lim, lim)
        ax.set_zlim3d(-lim, lim)
        set_axes_equal(ax)
        ax.set_xlabel("X")
        ax.set_ylabel("Y")
        ax.set_zlabel("Z")
        ax.view_init(elev=elev, azim=azim)
        if titles is not None:
            ax.set_title(titles[i], fontsize=10)
        axes.append(ax)
    fig.tight_layout()
    return fig, axes


def plot_residuals(ax, measured, fitted, scale=1.0, color="tab:red", label=None):
    """Draw each marker's residual as a segment from its fitted to its measured position.

    Marker residuals are usually millimetres on a cluster of centimetres, too small to
    see; `scale` magnifies them (the segment is drawn from the fitted position towards
    the measured one, `scale` times as long) so that their pattern becomes visible.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D
    measured, fitted : array_like, shape (n, 3)
        The same n markers, measured and as predicted by the fit (``R @ a + L``).
    scale : float
        Magnification of the residuals; 1 draws them true to size.
    color, label : passed to ``ax.plot`` (the label once, for a legend).

    Returns
    -------
    residuals : ndarray, shape (n, 3)
        ``measured - fitted``, unscaled.

    Raises
    ------
    ValueError
        If `measured` or `fitted` is not of shape (n, 3), or their shapes differ.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> from bmc_functions.plotting import plot_residuals
    >>> ax = plt.figure().add_subplot(projection='3d')
    >>> e = plot_residuals(ax, [[0, 0, 1], [1, 0, 0]], [[0, 0, 0], [1, 0, 0]], scale=10)
    >>> print(e)
    [[0. 0. 1.]
     [0. 0. 0.]]
    >>> plt.close('all')
    """
    measured = check_vectors(measured, "measured")
    fitted = check_vectors(fitted, "fitted")
    scale = check_number(scale, "scale")
    if measured.ndim != 2 or measured.shape != fitted.shape:
        raise ValueError(f"measured and fitted must have the same shape (n, 3); got "
                         f"{measured.shape} and {fitted.shape}")
    residuals = measured - fitted
    tips = fitted + scale * residuals
    # one polyline with NaN breaks: a single artist (and a single legend entry)
    segments = np.stack([fitted, tips, np.full_like(fitted, np.nan)], axis=1).reshape(-1, 3)
    ax.plot(*segments.T, color=color, linewidth=1.5, label=label)
    return residuals


def draw_vector(ax, v, origin=(0, 0, 0), color="k", label="", linestyle="-", alpha=1.0):
    """Draw a vector (a bone, a marker direction) as a 3D arrow from `origin`.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D
    v : array_like, shape (3,)
        The vector; the arrow ends at ``origin + v``.
    origin : array_like, shape (3,)
    color : str
    label : str
        Text (mathtext allowed) written just beyond the tip of the arrow.
    linestyle : str
    alpha : float

    Raises
    ------
    ValueError
        If `v` or `origin` is not a single 3-vector.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> from bmc_functions.plotting import draw_vector
    >>> ax = plt.figure().add_subplot(projection='3d')
    >>> draw_vector(ax, [1, 2, 0], label=r"$\\vec{A}$")
    >>> plt.close('all')
    """
    v = check_vectors(v, "v")
    origin = check_vectors(origin, "origin")
    alpha = check_number(alpha, "alpha")
    if v.shape != (3,) or origin.shape != (3,):
        raise ValueError(f"v and origin must each have shape (3,); got shapes {v.shape} "
                         f"and {origin.shape}")
    ax.quiver(*origin, *v, color=color, linestyle=linestyle, alpha=alpha, linewidth=2,
              arrow_length_ratio=0.12)
    tip = origin + v
    ax.scatter(*tip, s=0, alpha=0)  # keeps the tip inside the automatic limits
    if label:
        ax.text(*(origin + 1.08 * v), label, color=color)


#: Colours of the sides in gait figures: the convention of clinical gait reports (Vicon
#: Polygon and the Conventional Gait Model reports): right green, left red.
SIDE_COLORS = {"right": "tab:green", "left": "tab:red"}

#: Clinical sign labels (positive, negative) of each angle, for the y axes of gait figures;
#: ``(joint, angle)`` keys take precedence over ``angle`` keys.
SIGN_LABELS = {
    "flexion": ("Flex", "Ext"), "adduction": ("Add", "Abd"), "rotation": ("Int", "Ext"),
    "dorsiflexion": ("Dors", "Plan"), "inversion": ("Inv", "Ev"),
    "tilt": ("Ant", "Post"), "obliquity": ("Up", "Down"),
    ("pelvis", "rotation"): ("Fwd", "Bwd"),
    # keypoint_angles: the shoulder's abduction, the trunk relative to the pelvis
    "abduction": ("Abd", "Add"), "lateral_bending": ("To side", "Away"),
    ("trunk", "rotation"): ("Fwd", "Bwd"),
    # Plug-in Gait's FootProgressAngles: toe-in positive (Vicon's stored curve follows the
    # heel-to-toe line turned medially, r = 0.92 and 0.80 on data/real/plug_in_gait)
    ("foot", "progression"): ("Int", "Ext"),
    # kinetics (LowerLimbModel.kinetics, Plug-in Gait's): internal moments on the distal
    # segment, signs of bmc_functions.models.lower_limb_kinetics
    ("hip", "moment_x"): ("Ext", "Flex"), ("knee", "moment_x"): ("Ext", "Flex"),
    ("ankle", "moment_x"): ("Plan", "Dors"), "moment_y": ("Abd", "Add"),
    ("ankle", "moment_y"): ("Ev", "Inv"), "moment_z": ("Ext", "Int"),
    "force_x": ("Lat", "Med"), "force_y": ("Ant", "Post"), "force_z": ("Prox", "Dist"),
    "power": ("Gen", "Abs"),
}

#: Units of the y axis of a kinetics quantity (per kg of body mass), by its prefix; any
#: other column is an angle (deg).
KINETICS_UNITS = {"moment": "N·m/kg", "force": "N/kg", "power": "W/kg"}

#: Smallest y range of a kinetics panel (its units per kg), as MIN_RANGE is of an angle's.
MIN_KINETICS_RANGE = 1.0


#: Fixed y ranges of gait figures per ``(joint, angle)`` (deg; kinetics per kg of body
#: mass), those of clinical gait reports (Vicon Polygon's Plug-in Gait report and the
#: Conventional Gait Model's) for the angles, so that a curve is read against the same
#: scale in every report and a 0.25 degree wobble is not drawn as a signal; a curve or
#: band outside its range widens it. Angles not listed get :data:`MIN_RANGE` around their
#: data (kinetics :data:`MIN_KINETICS_RANGE`).
CLINICAL_RANGES = {
    ("pelvis", "tilt"): (-10.0, 40.0), ("pelvis", "obliquity"): (-20.0, 20.0),
    ("pelvis", "rotation"): (-30.0, 30.0),
    ("hip", "flexion"): (-20.0, 70.0), ("hip", "adduction"): (-30.0, 30.0),
    ("hip", "rotation"): (-30.0, 30.0),
    ("knee", "flexion"): (-15.0, 75.0), ("knee", "adduction"): (-30.0, 30.0),
    ("knee", "rotation"): (-30.0, 30.0),
    ("ankle", "dorsiflexion"): (-30.0, 30.0), ("ankle", "inversion"): (-30.0, 30.0),
    ("ankle", "rotation"): (-30.0, 30.0),
    ("foot", "progression"): (-30.0, 30.0),
    # kinetics (N·m/kg, W/kg): ranges that hold adult walking's normal curves (Winter
    # 2009, ch. 5: hip and ankle sagittal moments up to about 1 and 1.6 N·m/kg, ankle
    # power up to about 4 W/kg), so that a pathological curve is read on the same scale
    ("hip", "moment_x"): (-1.5, 2.0), ("knee", "moment_x"): (-1.0, 1.5),
    ("ankle", "moment_x"): (-0.5, 2.0),
    ("hip", "moment_y"): (-1.0, 1.5), ("knee", "moment_y"): (-1.0, 1.0),
    ("ankle", "moment_y"): (-0.5, 0.5),
    ("hip", "moment_z"): (-0.5, 0.5), ("knee", "moment_z"): (-0.5, 0.5),
    ("ankle", "moment_z"): (-0.5, 0.5),
    ("hip", "power"): (-2.0, 3.0), ("knee", "power"): (-3.0, 2.0),
    ("ankle", "power"): (-2.0, 5.0),
}

#: Smallest y range (deg) of a gait panel whose angle has no clinical range.
MIN_RANGE = 20.0

#: Colour of the normative band (mean +- 1 SD of the lab's controls) behind the curves.
NORMAL_COLOR = "0.82"


#: Order of the rows (joints) and columns (planes) of gait figures: sagittal, frontal,
#: transverse, whatever the order of the DataFrame's columns.
JOINT_ORDER = ("pelvis", "hip", "knee", "ankle", "foot")
PLANE_ORDER = ("tilt", "flexion", "dorsiflexion", "obliquity", "adduction", "abduction",
               "lateral_bending", "inversion", "rotation", "moment_x", "moment_y",
               "moment_z", "power", "force_x", "force_y", "force_z")


def _check_figsize(figsize):
    """`figsize` as a (width, height) tuple of positive numbers (inches), or None."""
    if figsize is None:
        return None
    if isinstance(figsize, (str, bytes)) or np.ndim(figsize) != 1 or len(figsize) != 2:
        raise ArgumentTypeError(f"figsize must be (width, height) in inches, two positive "
                                f"numbers; got {figsize!r} ({type(figsize).__name__})")
    return tuple(check_scalar(value, "figsize", "a positive number (inches)", minimum=0,
                              strict=True) for value in figsize)


def _check_axes(ax, three_d=False):
    """Refuse an `ax` that is not None or a matplotlib Axes (a 3D one if `three_d`)."""
    from matplotlib.axes import Axes

    if ax is None:
        return
    if not isinstance(ax, Axes) or (three_d and not hasattr(ax, "zaxis")):
        kind = "a 3D matplotlib Axes (fig.add_subplot(projection='3d'))" if three_d else \
            "a matplotlib Axes"
        raise ArgumentTypeError(f"ax must be {kind} or None; got {ax!r} "
                                f"({type(ax).__name__})")


def _check_colors(colors):
    """`colors` as a list of matplotlib colours (one colour: a list of it), or None."""
    from matplotlib.colors import is_color_like

    if colors is None:
        return None
    if is_color_like(colors) and not isinstance(colors, (list, np.ndarray)):
        return [colors]              # one colour ('red', '#1f77b4', (0, 0, 1)) for all
    if isinstance(colors, (str, bytes)) or not hasattr(colors, "__iter__"):
        raise ArgumentTypeError(f"colors must be a list of matplotlib colours (or one "
                                f"colour); got {colors!r} ({type(colors).__name__})")
    colors = list(colors)
    bad = [color for color in colors if not is_color_like(color)]
    if bad or not colors:
        raise ValueError(f"colors must be a list of matplotlib colours ('red', '#1f77b4', "
                         f"(0, 0, 1)); got {bad[0]!r} in it" if bad else
                         "colors must list at least one colour; got an empty list")
    return colors


def _units(quantity):
    """The y axis' unit of a column's last level: a kinetics quantity's, else degrees."""
    return KINETICS_UNITS.get(str(quantity).split("_")[0], "deg")


def _clinical_order(names, order):
    """Unique `names`, those in `order` first and in its order, then the others as given."""
    names = list(dict.fromkeys(names))
    return sorted(names, key=lambda n: (order.index(n) if n in order else len(order),
                                        names.index(n)))


#: One panel of a gait figure: its axes, joint and angle, the sides that have a column
#: there (clinical order: right, left, others), whether it is on the last row, and whether
#: it is the lowest panel of its column (the panel below it, if any, is hidden).
_Panel = namedtuple("_Panel", "ax joint angle sides last_row lowest source")


def _joint_plane_panels(columns, row_height, figsize):
    """The figure of the gait plots: joints (rows) and their planes (columns) in clinical
    order, each drawn panel labelled (:func:`_label_panel`), the panels a joint lacks
    hidden. `columns`: one table's columns, or a tuple of several (the angles, then the
    kinetics), whose rows follow one another. Returns the figure, the axes (rows, planes)
    and the list of panels to draw in (:data:`_Panel`; ``source``: the table's position)."""
    import matplotlib.pyplot as plt

    sources = columns if isinstance(columns, tuple) else (columns,)
    rows = [(k, joint) for k, names in enumerate(sources)
            for joint in _clinical_order(names.get_level_values(0), JOINT_ORDER)]
    planes = [_clinical_order([c[2] for c in sources[k] if c[0] == joint], PLANE_ORDER)
              for k, joint in rows]
    n_planes = max(len(p) for p in planes)
    figsize = _check_figsize(figsize)
    fig, axes = plt.subplots(len(rows), n_planes, squeeze=False, sharex=True,
                             figsize=figsize or (3.3 * n_planes, row_height * len(rows)))
    panels = []
    for row, (k, joint) in enumerate(rows):          # a panel per joint and plane (a dozen)
        names = sources[k]
        sides = _clinical_order([c[1] for c in names if c[0] == joint], ("right", "left"))
        for col in range(n_planes):
            if col >= len(planes[row]):
                axes[row, col].set_visible(False)
                continue
            angle = planes[row][col]
            last_row = row == len(rows) - 1
            panels.append(_Panel(axes[row, col], joint, angle,
                                 [side for side in sides if (joint, side, angle) in names],
                                 last_row, last_row or col >= len(planes[row + 1]), k))
    return fig, axes, panels


def _label_panel(ax, joint, angle):
    """The zero line, the clinical sign labels of the y axis and the panel's title."""
    ax.axhline(0.0, color="0.6", linewidth=0.6)
    positive, negative = SIGN_LABELS.get((joint, angle), SIGN_LABELS.get(angle, ("+", "−")))
    ax.set_ylabel(f"{negative} − / {positive} + ({_units(angle)})", fontsize=8)
    ax.set_title(f"{joint} {angle}", fontsize=10)


def plot_gait_cycles(cycles, toe_off=None, *, reference=None, reference_label="truth",
                     sd=True, figsize=None, normative=None, clinical_ranges=True, title=None,
                     kinetics=None):
    """The usual gait figure: one panel per joint and plane, mean +- SD over cycles.

    Rows are joints (pelvis, hip, knee, ankle, then any other), columns the planes
    (sagittal, frontal, transverse; :data:`JOINT_ORDER`, :data:`PLANE_ORDER`); right and
    left in their clinical colours (:data:`SIDE_COLORS`: right green, left red), the
    toe-off of each side as a vertical dotted line, the x axis in % of the gait cycle
    (heel strike to heel strike of that side), the y axis in degrees (kinetics columns,
    ``moment_*``, ``force_*``, ``power``: N·m/kg, N/kg, W/kg, :data:`KINETICS_UNITS`)
    with the clinical meaning of each sign (:data:`SIGN_LABELS`; e.g. "Ext - / Flex +": flexion up), on
    the fixed range of clinical reports (:data:`CLINICAL_RANGES`), behind the curves the
    lab's normal band (mean +- 1 SD of its controls, grey) when `normative` is given, and
    the number of cycles of each side in the title. A side without any cycle (all NaN) is
    not drawn and not in the legend. With `kinetics`, a clinical report's two pages in one
    figure: the angles, then below them the kinetics (rows hip, knee, ankle; columns the
    moments and the power, as Vicon Nexus's kinetics page).

    Parameters
    ----------
    cycles : pandas.DataFrame
        Time-normalised cycles, indexed by ``(cycle, percent)`` with columns
        ``(joint, side, angle)``, as :func:`~bmc_functions.normalize_by_side` returns for
        the angles of :meth:`~bmc_functions.LowerLimbModel.angles` (or the kinetics of
        :meth:`~bmc_functions.LowerLimbModel.kinetics`: ``(joint, side, quantity)``).
    toe_off : dict or pandas.DataFrame, optional
        Side -> toe-off in % of the cycle, or the table of
        :func:`~bmc_functions.spatiotemporal_parameters` (its ``stance`` column).
    reference : pandas.DataFrame, optional
        Cycles of a reference (the truth, another method) with the same column layout:
        its mean is drawn dashed, in the side's colour.
    reference_label : str
        Legend label of the reference.
    sd : bool
        Draw the mean +- 1 SD band.
    figsize : tuple, optional
        Default ``(3.3 * planes, 2.3 * joints)``.
    normative : pandas.DataFrame, optional
        The lab's normative table (:func:`~bmc_functions.normative_data`,
        :func:`~bmc_functions.read_normative_data`): its mean +- SD of each joint and
        angle is drawn as a grey band behind both sides' curves.
    clinical_ranges : bool
        True (default): every panel on its clinical range (:data:`CLINICAL_RANGES`,
        widened to hold the curves and bands; at least :data:`MIN_RANGE` degrees for an
        angle not listed). False: matplotlib's automatic range.
    title : str, optional
        Put before the cycle counts in the figure's title.
    kinetics : pandas.DataFrame, optional
        Time-normalised kinetics of the same cycles (:func:`~bmc_functions.
        normalize_by_side` of :meth:`~bmc_functions.PlugInGait.kinetics` or
        :meth:`~bmc_functions.LowerLimbModel.kinetics` with the same events; select the
        quantities to show, e.g. the moments and the power), drawn in rows of their own
        below the angles' rows, against the normal band where `normative` has their
        columns (a normative table made from kinetics cycles).

    Returns
    -------
    fig : matplotlib.figure.Figure
        Its title says the cycles of each side (``'right 2 cycles, left 1 cycle'``).
    axes : ndarray of matplotlib.axes.Axes, shape (joints, planes)
        With `kinetics`, the rows of the angles' joints, then those of the kinetics'.

    Raises
    ------
    ValueError
        If `cycles` (or `kinetics`) is not indexed by ``(cycle, percent)``, its columns
        are not ``(joint, side, angle)``, it holds no complete cycle (no rows, or all NaN:
        a trial with fewer than two heel strikes of each side), or `toe_off` is a table
        without a ``stance`` column.
    TypeError
        If `toe_off` is not a dict, a DataFrame or None.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> import numpy as np, pandas as pd
    >>> from bmc_functions.plotting import plot_gait_cycles
    >>> index = pd.MultiIndex.from_product([range(3), np.linspace(0, 100, 101)],
    ...                                    names=["cycle", "percent"])
    >>> columns = pd.MultiIndex.from_product([["knee"], ["right", "left"],
    ...                                       ["flexion", "adduction", "rotation"]])
    >>> rng = np.random.default_rng(0)
    >>> cycles = pd.DataFrame(rng.normal(size=(303, 6)), index=index, columns=columns)
    >>> fig, axes = plot_gait_cycles(cycles, toe_off={"right": 61.0, "left": 60.0})
    >>> axes.shape
    (1, 3)
    >>> print(axes[0, 0].get_ylabel())
    Ext − / Flex + (deg)
    >>> print([float(y) for y in axes[0, 0].get_ylim()], fig._suptitle.get_text())
    [-15.0, 75.0] right 3 cycles, left 3 cycles
    >>> plt.close('all')
    """
    _check_cycle_table(cycles, "cycles")
    if kinetics is not None:
        _check_cycle_table(kinetics, "kinetics")
    if isinstance(toe_off, pd.DataFrame):
        if "stance" not in toe_off.columns:
            raise ValueError(f"toe_off: the table has no 'stance' column (its columns: "
                             f"{', '.join(map(str, toe_off.columns[:8]))}); give the "
                             "table of spatiotemporal_parameters or a dict side -> "
                             "toe-off in % of the cycle")
        toe_off = toe_off["stance"].to_dict()
    elif toe_off is not None and not isinstance(toe_off, Mapping):
        raise TypeError("toe_off must be a dict side -> % of the cycle, or the table of "
                        f"spatiotemporal_parameters; got {type(toe_off).__name__}")
    if toe_off is not None:
        numbers = {side: value for side, value in toe_off.items()
                   if isinstance(value, (int, float, np.integer, np.floating))
                   and not isinstance(value, (bool, np.bool_))}
        wrong = [side for side in toe_off if side not in numbers]
        if wrong:
            raise ArgumentTypeError(f"toe_off[{wrong[0]!r}] must be a number (% of the "
                                    f"cycle, NaN if unknown); got "
                                    f"{toe_off[wrong[0]]!r} ({type(toe_off[wrong[0]]).__name__})")
        toe_off = {side: float(value) for side, value in numbers.items()}
    sd = check_flag(sd, "sd")
    clinical_ranges = check_flag(clinical_ranges, "clinical_ranges")
    if normative is not None:
        check_normative(normative, "normative")

    tables = (cycles,) if kinetics is None else (cycles, kinetics)
    fig, axes, panels = _joint_plane_panels(tuple(t.columns for t in tables), 2.3, figsize)
    statistics = [ensemble(table) for table in tables]
    ref = ensemble(reference)["mean"] if reference is not None else None
    for panel in panels:
        ax, stats = panel.ax, statistics[panel.source]
        percent = stats.index.to_numpy()
        for side in panel.sides:
            column = (panel.joint, side, panel.angle)
            color = SIDE_COLORS.get(side, "k")
            mean = stats["mean"][column].to_numpy()
            if not np.isfinite(mean).any():           # no cycle of this side
                continue
            ax.plot(percent, mean, color=color, linewidth=1.6, label=side)
            if sd:
                spread = stats["sd"][column].to_numpy()
                ax.fill_between(percent, mean - spread, mean + spread, color=color,
                                alpha=0.2, linewidth=0)
            if ref is not None and column in ref.columns:
                ax.plot(ref.index, ref[column], color=color, linestyle="--", linewidth=1.0,
                        label=f"{side} {reference_label}")
            if toe_off is not None and np.isfinite(toe_off.get(side, np.nan)):
                ax.axvline(toe_off[side], color=color, linestyle=":", linewidth=1.0)
        _draw_normal(ax, normative, panel.joint, panel.angle)
        _label_panel(ax, panel.joint, panel.angle)
        ax.set_xlim(0, 100)
        if clinical_ranges:
            _clinical_range(ax, panel.joint, panel.angle)
        if panel.last_row:
            ax.set_xlabel("gait cycle (%)")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="lower center", fontsize=8, ncol=len(handles),
                   frameon=False)
    fig.suptitle(_cycle_counts(cycles, title), fontsize=11)
    fig.tight_layout(rect=(0, 0.035 if handles else 0, 1, 0.96))
    return fig, axes


def _check_cycle_table(cycles, name):
    """Refuse a `cycles` table (argument `name`) that normalize_by_side cannot have given,
    or that holds no complete cycle."""
    if not isinstance(cycles, pd.DataFrame) or not isinstance(cycles.index, pd.MultiIndex) \
            or "percent" not in cycles.index.names:
        raise ValueError(f"{name} must be a DataFrame indexed by (cycle, percent), as "
                         "returned by normalize_by_side")
    if not isinstance(cycles.columns, pd.MultiIndex) or cycles.columns.nlevels != 3:
        raise ValueError(f"{name} must have three-level (joint, side, angle) columns; got "
                         f"{list(cycles.columns[:3])}")
    if not np.isfinite(cycles.to_numpy(dtype=float)).any():
        raise ValueError(f"{name} holds no complete gait cycle ({cycles.shape[0]} rows, "
                         "every value NaN or none): a cycle runs from one heel strike to "
                         "the next of the same side, so the trial needs two heel strikes "
                         "of one side (normalize_by_side warned which side had fewer); "
                         "plot the curves over time with plot_angles instead")


def _draw_normal(ax, normative, joint, angle):
    """The normative mean +- 1 SD of (joint, angle), grey, behind the curves."""
    if normative is None or (joint, angle) not in normative["mean"].columns:
        return
    mean = normative["mean"][(joint, angle)].to_numpy(float)
    spread = (normative["sd"][(joint, angle)].to_numpy(float)
              if "sd" in normative.columns.get_level_values(0) else np.zeros_like(mean))
    ax.fill_between(normative.index.to_numpy(float), mean - spread, mean + spread,
                    color=NORMAL_COLOR, linewidth=0, zorder=0, label="normal")


def _clinical_range(ax, joint, angle):
    """Set the panel's y range: the clinical one, widened to hold what is drawn."""
    low, high = ax.dataLim.y0, ax.dataLim.y1               # curves and bands drawn
    if (joint, angle) in CLINICAL_RANGES:
        lower, upper = CLINICAL_RANGES[joint, angle]
    else:
        centre = 0.5 * (low + high) if np.isfinite(low + high) else 0.0
        least = MIN_RANGE if _units(angle) == "deg" else MIN_KINETICS_RANGE
        lower, upper = centre - least / 2, centre + least / 2
    if np.isfinite(low) and np.isfinite(high):
        margin = 0.05 * (upper - lower)
        lower, upper = min(lower, low - margin), max(upper, high + margin)
    ax.set_ylim(float(lower), float(upper))


def _cycle_counts(cycles, title):
    """'right 2 cycles, left 1 cycle': the cycles of each side with any value."""
    sides = cycles.columns.get_level_values(1)
    counts = []
    for side in _clinical_order(sides, ("right", "left")):       # a loop over sides
        values = cycles.loc[:, sides == side].to_numpy(float)
        has = np.isfinite(values).any(axis=1)
        n = len(set(cycles.index.get_level_values("cycle")[has])) if "cycle" in \
            cycles.index.names else int(has.any())
        counts.append(f"{side} {n} cycle{'' if n == 1 else 's'}")
    return (f"{title}: " if title else "") + ", ".join(counts)


def plot_angles(angles, events=None, *, title=None, figsize=None):
    """The joint angles of one trial over time: one panel per joint and plane.

    The figure to look at first, before any cycle is cut: rows are joints (pelvis, hip,
    knee, ankle, then any other), columns the planes (sagittal, frontal, transverse), as
    in :func:`plot_gait_cycles`; right and left in their clinical colours
    (:data:`SIDE_COLORS`), the y axis in degrees with the clinical meaning of each sign
    (:data:`SIGN_LABELS`). With `events`, each heel strike is a solid and each toe-off a
    dotted vertical line in the colour of its side, in every panel: a curve that jumps, a
    gap (NaN, an occluded marker) or an event in the wrong place shows at once.

    Parameters
    ----------
    angles : pandas.DataFrame
        One trial as :meth:`~bmc_functions.LowerLimbModel.angles` returns it: indexed by
        time (s), columns ``(joint, side, angle)``, degrees.
    events : dict, optional
        :func:`~bmc_functions.gait_events` of the trial, or any dict side -> {'heel_strike':
        times, 'toe_off': times} (s); a side or an event may be missing.
    title : str, optional
        The figure's title (e.g. the trial's name).
    figsize : tuple, optional
        Default ``(3.3 * planes, 2.1 * joints)``.

    Returns
    -------
    fig : matplotlib.figure.Figure
    axes : ndarray of matplotlib.axes.Axes, shape (joints, planes)

    Raises
    ------
    ValueError
        If `angles` is not indexed by time alone (several trials: plot one, e.g.
        ``angles.loc['walk1']``), its columns are not ``(joint, side, angle)``, it has
        no finite value, or an event time is not a finite number.
    TypeError
        If `angles` is not a DataFrame or `events` is not a dict of dicts.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> import numpy as np, pandas as pd
    >>> from bmc_functions.plotting import plot_angles
    >>> time = pd.Index(np.arange(0, 2, 0.01), name="time")
    >>> columns = pd.MultiIndex.from_product([["hip", "knee"], ["right", "left"],
    ...                                       ["flexion", "adduction"]])
    >>> phase = 2 * np.pi * time.to_numpy()[:, None] / 1.1
    >>> angles = pd.DataFrame(30 * np.sin(phase + np.arange(8)), index=time,
    ...                       columns=columns)
    >>> events = {"right": {"heel_strike": [0.1, 1.2], "toe_off": [0.75, 1.85]},
    ...           "left": {"heel_strike": [0.65], "toe_off": [0.2, 1.3]}}
    >>> fig, axes = plot_angles(angles, events, title="walk 1")
    >>> axes.shape
    (2, 2)
    >>> print(axes[1, 0].get_title(), "|", axes[1, 0].get_ylabel())
    knee flexion | Ext − / Flex + (deg)
    >>> plt.close('all')
    """
    from matplotlib.lines import Line2D

    if not isinstance(angles, pd.DataFrame):
        raise TypeError(f"angles must be a pandas DataFrame; got {type(angles).__name__}")
    if angles.index.nlevels != 1:
        raise ValueError(f"angles has {angles.index.nlevels} row index levels "
                         f"{list(angles.index.names)}; plot one trial, e.g. "
                         "angles.loc['walk1']")
    if not isinstance(angles.columns, pd.MultiIndex) or angles.columns.nlevels != 3:
        raise ValueError("angles must have three-level (joint, side, angle) columns, as "
                         "LowerLimbModel.angles returns; got "
                         f"{list(angles.columns[:3])}")
    time = as_float_array(angles.index.to_numpy(), "angles.index (time)")
    values = as_float_array(angles.to_numpy(), "angles")
    if not np.isfinite(values).any():
        raise ValueError(f"angles has no finite value ({angles.shape[0]} rows): nothing to "
                         "plot")
    marks = _event_times(events)
    _warn_events_outside(marks, time)
    fig, axes, panels = _joint_plane_panels(angles.columns, 2.1, figsize)
    sides_drawn = []
    for panel in panels:
        ax = panel.ax
        for side in panel.sides:
            curve = angles[panel.joint, side, panel.angle].to_numpy(dtype=float)
            if not np.isfinite(curve).any():
                continue
            ax.plot(time, curve, color=SIDE_COLORS.get(side, "k"), linewidth=1.3)
            sides_drawn.append(side)
        for side, event, at in marks:
            for t in at:
                ax.axvline(t, color=SIDE_COLORS.get(side, "k"), linewidth=0.8,
                           linestyle="-" if event == "heel_strike" else ":", alpha=0.7)
        _label_panel(ax, panel.joint, panel.angle)
        if panel.lowest:
            ax.set_xlabel("time (s)")
            ax.xaxis.set_tick_params(labelbottom=True)
    handles = [Line2D([], [], color=SIDE_COLORS.get(side, "k"), label=side)
               for side in dict.fromkeys(sides_drawn)]
    if marks:
        handles += [Line2D([], [], color="0.3", linestyle="-", linewidth=0.8,
                           label="heel strike"),
                    Line2D([], [], color="0.3", linestyle=":", linewidth=0.8,
                           label="toe-off")]
    fig.legend(handles=handles, loc="lower center", fontsize=8, ncol=len(handles),
               frameon=False)
    if title is not None:
        fig.suptitle(str(title), fontsize=11)
    fig.tight_layout(rect=(0, 0.035, 1, 0.96 if title is not None else 1))
    return fig, axes


def _event_times(events):
    """[(side, event, finite times)] from the events of gait_events (or a like dict)."""
    if events is None:
        return []
    if not isinstance(events, Mapping):
        raise TypeError("events must be the dict of gait_events (side -> {'heel_strike': "
                        f"times, 'toe_off': times}}); got {type(events).__name__}")
    marks = []
    for side, per_side in events.items():
        if not isinstance(per_side, Mapping):
            raise TypeError(f"events[{side!r}] must be a dict event -> times; got "
                            f"{type(per_side).__name__}")
        for event in ("heel_strike", "toe_off"):
            if event in per_side and per_side[event] is not None:
                at = as_float_array(np.atleast_1d(per_side[event]),
                                    f"events[{side!r}][{event!r}]")
                if at.ndim != 1 or not np.isfinite(at).all():
                    raise ValueError(f"events[{side!r}][{event!r}] must be finite times "
                                     f"(s); got {np.asarray(per_side[event])!r}")
                marks.append((side, event, at))
    return marks


def _warn_events_outside(marks, time):
    """One warning for the events outside the time span of the curves (another trial's
    events, or times in ms): they would not be drawn."""
    finite = time[np.isfinite(time)]
    if not marks or not finite.size:
        return
    at = np.concatenate([times for _, _, times in marks])
    outside = (at < finite.min()) | (at > finite.max())
    if outside.any():
        warn(f"events: {int(outside.sum())} of {at.size} event times lie outside "
             f"the curves' time ({finite.min():.4g} to {finite.max():.4g} s), e.g. "
             f"{at[outside][0]:.4g}: events of another trial, or in ms? They are "
             f"not drawn", RuntimeWarning)


def _trial_scene(markers, frames):
    """(time, xyz (F, M, 3), labels, [(name, R (F, 3, 3), origin (F, 3))]) of a trial."""
    if not isinstance(markers, pd.DataFrame) or markers.columns.nlevels != 2:
        raise ValueError("markers must be a DataFrame with (marker, coord) columns, as "
                         "read_trc and read_c3d return")
    labels = list(dict.fromkeys(markers.columns.get_level_values(0)))
    try:
        xyz = markers[[(label, c) for label in labels for c in "xyz"]].to_numpy(dtype=float)
    except KeyError:
        raise ValueError("markers must have the coordinates 'x', 'y', 'z' for every "
                         "marker") from None
    time = as_float_array(markers.index.to_numpy(), "markers.index (time)")
    xyz = xyz.reshape(len(markers), len(labels), 3)
    if len(time) and np.isnan(xyz).all():
        raise ValueError("markers: every coordinate is NaN (no marker seen in any frame): "
                         "nothing to draw")
    items = []
    if frames is not None:
        if not isinstance(frames, Mapping):
            raise TypeError("frames must be a dict name -> (R, origin), e.g. "
                            f"model.track(trial).frames; got {type(frames).__name__}")
        for name, value in frames.items():
            if not isinstance(value, (tuple, list)) or len(value) != 2:
                raise ValueError(f"frames[{name!r}] must be a pair (R, origin); got "
                                 f"{type(value).__name__}")
            R, origin = (as_float_array(v, f"frames[{name!r}]") for v in value)
            if R.shape != (len(time), 3, 3) or origin.shape != (len(time), 3):
                raise ValueError(f"frames[{name!r}] must be (R, origin) of shapes "
                                 f"({len(time)}, 3, 3) and ({len(time)}, 3), one per "
                                 f"frame of markers; got {R.shape} and {origin.shape}")
            label = " ".join(str(part) for part in
                             (name if isinstance(name, tuple) else (name,)) if part)
            items.append((label, R, origin))
    return time, xyz, labels, items


def _trial_axes(ax, vertical_axis, elev, azim):
    """A 3D axes for the trial: lab x, y, z as matplotlib's X, Y, Z (right-handed), the
    camera turned so that `vertical_axis` points up (:func:`_set_view`, as
    :func:`set_lab_view`), the three axes in a cube."""
    import matplotlib.pyplot as plt

    vertical_axis = check_choice(vertical_axis, "vertical_axis", ("x", "y", "z"))
    elev, azim = check_number(elev, "elev"), check_number(azim, "azim")
    _check_axes(ax, three_d=True)
    if ax is None:
        fig = plt.figure(figsize=(6, 6))
        ax = fig.add_subplot(projection="3d")
    ax.set_box_aspect((1, 1, 1))
    return _set_view(ax, elev, azim, vertical_axis, ("x", "y", "z"))


def _set_view(ax, elev, azim, vertical, labels):
    """The camera of every lab figure: the lab's x, y, z drawn on the axes' X, Y, Z (so
    right-handed), the view turned so that the lab axis `vertical` points up, from
    elevation `elev` and azimuth `azim` (degrees, matplotlib's); the axes labelled."""
    ax.view_init(elev=elev, azim=azim, vertical_axis=vertical)
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.set_zlabel(labels[2])
    return ax


def _view_box(xyz):
    """Per frame, the centre of the markers' extent (F, 3), and one half-width for the
    whole trial: a box that holds the body in every frame and follows it as it walks."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)     # frames without any marker
        low, high = np.nanmin(xyz, axis=1), np.nanmax(xyz, axis=1)
    centre = (low + high) / 2
    centre = pd.DataFrame(centre).ffill().bfill().to_numpy()
    radius = 0.55 * np.nanmax(high - low)
    return centre, (radius if np.isfinite(radius) and radius > 0 else 1.0)


def _set_box(ax, centre, radius):
    ax.set_xlim3d(centre[0] - radius, centre[0] + radius)
    ax.set_ylim3d(centre[1] - radius, centre[1] + radius)
    ax.set_zlim3d(centre[2] - radius, centre[2] + radius)


def _frame_lines(ax, items, length):
    """One Line3D per segment axis (x red, y green, z blue), updated by _draw_instant."""
    return [[ax.plot([], [], [], color=_AXIS_COLORS[k], linewidth=2)[0] for k in range(3)]
            for _ in items]


def _draw_instant(k, xyz, items, dots, lines, length, stamp, time, box):
    visible = ~np.isnan(xyz[k]).any(axis=1)
    dots.set_data_3d(*xyz[k, visible].T)
    for (_, R, origin), axes in zip(items, lines):
        for j, line in enumerate(axes):
            tip = origin[k] + length * R[k, :, j]
            line.set_data_3d(*np.stack([origin[k], tip], axis=1))
    _set_box(dots.axes, box[0][k], box[1])          # the view follows the subject
    stamp.set_text(f"t = {time[k]:.3f} s")
    return [dots, stamp, *[line for axes in lines for line in axes]]


def plot_trial_3d(markers, frames=None, *, time=None, ax=None, vertical_axis="y",
                  axis_length=100.0, elev=15.0, azim=-60.0):
    """One instant of a trial in 3D: the markers and the segment frames (a still, to print).

    The lab's x, y, z are matplotlib's X, Y, Z (a right-handed view: a right knee is drawn
    as a right knee) and the camera is turned with ``ax.view_init(vertical_axis=...)`` so
    that the lab's vertical points up; the three axes have one scale, in a box that holds
    the body in every frame, centred on the markers at that instant. Each
    segment frame is drawn as its x, y, z axes in red, green and blue from its origin.
    :func:`animate_trial` plays the whole trial.

    Parameters
    ----------
    markers : pandas.DataFrame
        A trial as :func:`~bmc_functions.read_trc` or :func:`~bmc_functions.read_c3d`
        returns it (columns ``(marker, coord)``, indexed by time); NaN markers are not drawn.
    frames : dict, optional
        Name -> ``(R, origin)`` with R of shape (frames, 3, 3) (columns the segment's axes
        in the lab) and origin (frames, 3), one per row of `markers`: e.g.
        ``model.track(trial).frames`` of the lower-limb pipeline.
    time : float, optional
        The instant to draw (s); the nearest row is used. Default: the first row.
    ax : mpl_toolkits.mplot3d.Axes3D, optional
        Axes to draw in; default a new 6 x 6 inch figure.
    vertical_axis : {'y', 'z', 'x'}
        The lab's vertical axis (default 'y', as in OpenSim and the ISB frames; 'z' for a
        z-up lab).
    axis_length : float
        Length of the drawn segment axes, in the units of `markers` (default 100: mm).
    elev, azim : float
        Camera elevation and azimuth (degrees), as in ``ax.view_init``.

    Returns
    -------
    ax : mpl_toolkits.mplot3d.Axes3D

    Raises
    ------
    ValueError
        If `markers` does not have ``(marker, coord)`` columns with x, y, z for every
        marker, `frames` do not have one pose per row, or `vertical_axis` is unknown.
    TypeError
        If `frames` is not a dict.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> import warnings
    >>> from bmc_functions import calibrate_lower_limb, read_trc
    >>> from bmc_functions import read_marker_mapping
    >>> from bmc_functions.examples import example_file
    >>> from bmc_functions.plotting import plot_trial_3d
    >>> markers = read_marker_mapping(example_file("markers/markers.toml"))
    >>> walk = read_trc(example_file("markers/walk.trc"))
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")                 # the trial's occlusion gaps
    ...     model = calibrate_lower_limb(example_file("markers/static.trc"), markers)
    ...     frames = model.track(walk).frames
    >>> ax = plot_trial_3d(walk, frames, time=0.5)
    >>> print(ax.get_title(), len(ax.lines))        # markers + 3 axes of 7 segments
    t = 0.500 s 22
    >>> plt.close('all')
    """
    times, xyz, _, items = _trial_scene(markers, frames)
    if not len(times):
        raise ValueError("markers has no rows: nothing to draw")
    if time is not None and (isinstance(time, (bool, np.bool_)) or not np.isscalar(time)
                             or not np.isfinite(as_float_array(time, "time"))):
        raise ValueError(f"time must be a finite number of seconds; got {time!r}")
    axis_length = check_number(axis_length, "axis_length", positive=True)
    if time is not None:
        step = float(np.median(np.diff(times))) if len(times) > 1 else 0.0
        if not times[0] - step <= float(time) <= times[-1] + step:
            raise ValueError(f"time must lie within the trial ({times[0]:.4g} to "
                             f"{times[-1]:.4g} s); got {float(time):g}")
    k = 0 if time is None else int(np.argmin(np.abs(times - float(time))))
    if np.isnan(xyz[k]).all():
        warn(f"no marker is visible at t = {times[k]:.4g} s (every coordinate NaN): "
             f"the figure shows no markers; choose another time", RuntimeWarning)
    ax = _trial_axes(ax, vertical_axis, elev, azim)
    dots = ax.plot([], [], [], "o", color="0.25", markersize=3, linestyle="none")[0]
    lines = _frame_lines(ax, items, axis_length)
    stamp = ax.set_title("", fontsize=10)
    _draw_instant(k, xyz, items, dots, lines, axis_length, stamp, times, _view_box(xyz))
    return ax


def animate_trial(markers, frames=None, *, step=1, vertical_axis="y", axis_length=100.0,
                  elev=15.0, azim=-60.0, interval=None):
    """The trial in 3D, animated: markers and segment frames frame by frame.

    The view and the drawing are those of :func:`plot_trial_3d`. In a notebook, and in
    the book built from it (it plays offline: the frames are embedded in the page), show it
    with ``IPython.display.HTML(animation.to_jshtml())``; save it with
    ``animation.save("trial.gif", writer="pillow")``; for print, use
    :func:`plot_trial_3d` at the instant that matters.

    Parameters
    ----------
    markers, frames, vertical_axis, axis_length, elev, azim
        As :func:`plot_trial_3d`.
    step : int
        Draw every `step`-th frame (default 1: all of them); a long trial embedded with
        ``to_jshtml`` grows by one image per drawn frame.
    interval : float, optional
        Milliseconds between drawn frames; default real time (``1000 * step / rate``, the
        rate from the time index).

    Returns
    -------
    matplotlib.animation.FuncAnimation
        Keep a reference to it until it is shown or saved.

    Raises
    ------
    ValueError, TypeError
        As :func:`plot_trial_3d`; `step` not a positive whole number.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> from bmc_functions import read_trc
    >>> from bmc_functions.examples import example_file
    >>> from bmc_functions.plotting import animate_trial
    >>> walk = read_trc(example_file("markers/walk.trc"))
    >>> animation = animate_trial(walk, step=10)
    >>> html = animation.to_jshtml()          # a self-contained player for the page
    >>> print(html.count("data:image/png"))   # one image per drawn frame
    12
    >>> plt.close('all')
    """
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation

    step = check_scalar(step, "step", "a positive whole number", minimum=1, integer=True)
    axis_length = check_number(axis_length, "axis_length", positive=True)
    if interval is not None:
        interval = check_number(interval, "interval", positive=True)
    times, xyz, _, items = _trial_scene(markers, frames)
    if not len(times):
        raise ValueError("markers has no rows: nothing to animate")
    fig = plt.figure(figsize=(6, 6))
    ax = _trial_axes(fig.add_subplot(projection="3d"), vertical_axis, elev, azim)
    dots = ax.plot([], [], [], "o", color="0.25", markersize=3, linestyle="none")[0]
    lines = _frame_lines(ax, items, axis_length)
    stamp = ax.set_title("", fontsize=10)
    if interval is None:
        rate = 1.0 / np.median(np.diff(times)) if len(times) > 1 else 1.0
        interval = 1000.0 * step / rate
    return FuncAnimation(fig, _draw_instant, frames=range(0, len(times), step),
                         fargs=(xyz, items, dots, lines, axis_length, stamp, times,
                                _view_box(xyz)),
                         interval=interval, blit=False)


#: The player's buttons without the icon font matplotlib fetches from a CDN.
_PLAYER_SYMBOLS = {"fa-minus": "&minus;", "fa-fast-backward": "&laquo;",
                   "fa-step-backward": "&lsaquo;", "fa-play fa-flip-horizontal": "&#9664;",
                   "fa-pause": "&#10074;&#10074;", "fa-play": "&#9654;",
                   "fa-step-forward": "&rsaquo;", "fa-fast-forward": "&raquo;",
                   "fa-plus": "+", "fa-repeat": "&#8635;"}


#: Most frames :func:`animation_html` embeds: about 70 kB each (a 6 x 6 in figure), so
#: 250 stay under matplotlib's default embed limit (``rcParams['animation.embed_limit']``,
#: 20 MB), beyond which the player would stop part-way.
MAX_HTML_FRAMES = 250


def animation_html(animation):
    """An animation as a self-contained HTML player that works offline and is the same on
    every run: what a notebook should display, and what the book built from it plays.

    ``animation.to_jshtml()`` embeds every frame as an image, but its buttons use an icon
    font loaded from a CDN (no icons without a network; the book refuses pages that load
    from the network) and its element ids are random (a notebook's stored output would
    change at every run, and nbval compares it). Here the font's link is removed, the
    icons are plain text symbols, and the id is derived from the content.

    Parameters
    ----------
    animation : matplotlib.animation.Animation
        E.g. from :func:`animate_trial`.

    Returns
    -------
    str
        The HTML; in a notebook: ``IPython.display.HTML(animation_html(animation))``.

    Raises
    ------
    TypeError
        If `animation` is not a matplotlib animation.
    ValueError
        If it has more than :data:`MAX_HTML_FRAMES` frames to draw (the page would hold
        tens of MB, take minutes to build and be cut at matplotlib's embed limit).

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> from bmc_functions import read_trc
    >>> from bmc_functions.examples import example_file
    >>> from bmc_functions.plotting import animate_trial, animation_html
    >>> walk = read_trc(example_file("markers/walk.trc"))
    >>> html = animation_html(animate_trial(walk, step=20))
    >>> "http" in html, html.count("data:image/png"), "&#9654;" in html
    (False, 6, True)
    >>> plt.close('all')
    """
    from matplotlib.animation import Animation

    if not isinstance(animation, Animation):
        raise TypeError(f"animation must be a matplotlib animation (e.g. from "
                        f"animate_trial); got {type(animation).__name__}")
    drawn = getattr(animation, "_save_count", None)       # frames FuncAnimation will draw
    if isinstance(drawn, int) and drawn > MAX_HTML_FRAMES:
        raise ValueError(f"animation: {drawn} frames to embed, more than {MAX_HTML_FRAMES}: "
                         f"each is an image of about 70 kB that takes about 0.1 s to draw, "
                         f"and matplotlib stops at its embed limit (20 MB) with the player "
                         f"cut short; animate every "
                         f"{int(np.ceil(drawn / MAX_HTML_FRAMES))}-times-larger step "
                         f"(animate_trial(..., step=...))")
    html = animation.to_jshtml()
    html = re.sub(r"<link[^>]*font-awesome[^>]*>", "", html)
    for icon, symbol in sorted(_PLAYER_SYMBOLS.items(), key=lambda item: -len(item[0])):
        html = html.replace(f'<i class="fa {icon}"></i>', symbol)
    found = re.search(r"anim([0-9a-f]{32})", html)
    if found:
        stable = hashlib.sha1(html.replace(found.group(1), "").encode()).hexdigest()[:32]
        html = html.replace(found.group(1), stable)
    return html


def set_lab_view(ax, view_from=(1.0, 1.0, 1.0), vertical="y", labels=None, equal=True):
    """Show a 3D axes as the lab is: its vertical axis up, seen from a lab direction.

    Plot the lab's coordinates as they are, x, y, z on the axes' x, y, z, and call this
    after plotting (and after any ``set_xlim``...). Matplotlib's 3D axes are
    right-handed, so the figure is too. Never plot the lab's (x, z, y) on the axes to make
    a y-up lab stand upright: swapping two axes is a reflection that no camera angle
    undoes (a right knee is drawn as a left knee). This function turns the camera instead
    (``ax.view_init(..., vertical_axis=vertical)``).

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D
    view_from : array_like, shape (3,)
        Direction from the centre of the plot towards the camera, in lab coordinates
        (its length does not matter). For a lab with x forwards, y up and z to the
        right, ``(1, 0.3, 0)`` looks at the subject from the front and a little from
        above, ``(0.5, 0.3, 1)`` from the subject's right and a little from the front.
    vertical : {'x', 'y', 'z'}
        The lab axis drawn upwards on the screen ('y' in the ISB and most lab frames).
    labels : sequence of 3 str, optional
        Labels of the lab's x, y and z axes, e.g. ``("x forwards (mm)", "y up (mm)",
        "z right (mm)")``; default "x", "y", "z".
    equal : bool
        Give the three axes the same scale (``ax.set_aspect('equal')``: the box takes
        the proportions of the current limits), so that right angles look right.

    Returns
    -------
    ax : mpl_toolkits.mplot3d.Axes3D
        The same axes.

    Raises
    ------
    ValueError
        If `view_from` is not one finite nonzero 3-vector, `vertical` is not 'x', 'y'
        or 'z', or `labels` does not hold three strings.

    Notes
    -----
    Matplotlib places the camera at elevation `elev` above the horizontal plane and
    azimuth `azim` within it, measured in the axes' own order with the vertical axis
    last: with ``vertical_axis='y'`` the camera direction is
    :math:`(\\cos e \\sin a,\\ \\sin e,\\ \\cos e \\cos a)` in (x, y, z). This function
    inverts that relation, so that the view is given by what a reader can picture: where
    the camera stands in the lab.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> from bmc_functions.plotting import draw_frame, set_lab_view
    >>> ax = plt.figure().add_subplot(projection='3d')
    >>> draw_frame(ax, label="lab")
    >>> ax = set_lab_view(ax, view_from=(1, 0.5, 1), labels=("x forwards", "y up", "z right"))
    >>> print(round(ax.elev, 2), round(ax.azim, 2))
    19.47 45.0
    >>> plt.close('all')
    """
    vertical = check_choice(vertical, "vertical", ("x", "y", "z"))
    direction = check_vectors(view_from, "view_from", allow_nan=False, max_abs=None)
    if direction.shape != (3,) or not np.any(direction):
        raise ValueError(f"view_from must be one nonzero 3-vector (a direction in lab "
                         f"coordinates); got {np.array2string(direction)}")
    equal = check_flag(equal, "equal")
    if labels is None:
        labels = ("x", "y", "z")
    if isinstance(labels, str) or len(labels) != 3 or not all(isinstance(s, str) for s in labels):
        raise ValueError(f"labels must be three strings, for the lab's x, y and z axes; got "
                         f"{labels!r}")
    # matplotlib's camera direction is np.roll((cos e cos a, cos e sin a, sin e), v - 2)
    # in data order, v the index of the vertical axis: roll it back and read e and a off it
    v = "xyz".index(vertical)
    p = np.roll(direction / np.linalg.norm(direction), 2 - v)
    elev = np.degrees(np.arctan2(p[2], np.hypot(p[0], p[1])))
    azim = np.degrees(np.arctan2(p[1], p[0]))
    _set_view(ax, elev, azim, vertical, labels)
    if equal:
        ax.set_aspect("equal")
    return ax


def plot_residual_analysis(result, columns=None, *, ax=None, colors=None):
    """The residual-analysis figure (Winter 2009): residual against cut-off, the noise
    line fitted at high cut-offs, and the cut-off where the curve meets its intercept.

    Parameters
    ----------
    result : ResidualAnalysis
        From :func:`~bmc_functions.residual_analysis` on a DataFrame or an array.
    columns : list, optional
        The columns (or markers) to draw; default all (keep it to a few).
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new figure.
    colors : list of str, optional
        One colour per column; default matplotlib's cycle.

    Returns
    -------
    matplotlib.axes.Axes

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use('Agg')
    >>> import matplotlib.pyplot as plt
    >>> import numpy as np
    >>> from bmc_functions import residual_analysis
    >>> from bmc_functions.plotting import plot_residual_analysis
    >>> rng = np.random.default_rng(0)
    >>> t = np.arange(400) / 100
    >>> x = np.c_[np.sin(2 * np.pi * t), np.cos(2 * np.pi * t)] + rng.normal(0, 0.02, (400, 2))
    >>> ax = plot_residual_analysis(residual_analysis(x, rate=100))
    >>> print(len(ax.lines))     # per column: curve, noise line, intercept, cut-off
    8
    >>> plt.close('all')
    """
    import matplotlib.pyplot as plt

    if not isinstance(result, ResidualAnalysis):
        raise TypeError(f"result must be what residual_analysis returns (a "
                        f"ResidualAnalysis); got {type(result).__name__}")
    cutoffs = np.asarray(result.cutoffs, dtype=float)
    curves, chosen, noise, slope, labels = _residual_curves(result, columns)
    _check_axes(ax)
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 3.6))
    cycle = _check_colors(colors) or plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (curve, cutoff, level, rise, label) in enumerate(zip(curves, chosen, noise,
                                                                slope, labels)):
        color = cycle[i % len(cycle)]
        ax.plot(cutoffs, curve, color=color, linewidth=1.6, label=label)
        line = np.array([0.0, cutoffs[-1]])   # the noise line: level + rise * cut-off
        ax.plot(line, level + rise * line, color=color, linestyle="--", linewidth=0.9)
        if np.isfinite(cutoff):
            ax.plot([0.0, cutoff], [level, level], color=color, linestyle=":", linewidth=0.9)
            ax.plot([cutoff], [level], "o", color=color, markersize=5)
    ax.axvspan(result.fit_from, cutoffs[-1], color="0.9", zorder=0)
    ax.set_xlim(0, cutoffs[-1])
    ax.set_ylim(bottom=0)
    ax.set_xlabel("cut-off frequency (Hz)")
    ax.set_ylabel("RMS residual")
    ax.set_title("residual analysis (grey: cut-offs the noise line is fitted to)",
                 fontsize=9)
    ax.legend(fontsize=8)
    return ax


def _residual_curves(result, columns):
    """The residual curves of `columns` of a ResidualAnalysis, with their chosen cut-offs,
    noise levels, slopes of the noise line and legend labels (five lists)."""
    residuals = result.residuals
    if isinstance(residuals, pd.DataFrame):
        names = list(residuals.columns) if columns is None else list(columns)
        missing = [name for name in names if name not in residuals.columns]
        if missing:
            raise ValueError(f"columns: {missing} are not in the result; it has "
                             f"{list(residuals.columns)[:6]}...")
        return ([residuals[name].to_numpy() for name in names],
                [result.cutoff[name] for name in names],
                [result.noise[name] for name in names],
                [result.slope[name] for name in names],
                ["".join(map(str, name)) if isinstance(name, tuple) else str(name)
                 for name in names])
    by_column = np.asarray(residuals, dtype=float)
    by_column = by_column.reshape(len(by_column), -1)
    picked = range(by_column.shape[1]) if columns is None else (
        [columns] if isinstance(columns, (str, int, np.integer)) else list(columns))
    unknown = [j for j in picked if isinstance(j, (bool, np.bool_)) or not isinstance(
        j, (int, np.integer)) or not 0 <= j < by_column.shape[1]]
    if unknown:
        raise ValueError(f"columns: {unknown} are not column numbers of the result; it has "
                         f"{by_column.shape[1]} (0 to {by_column.shape[1] - 1})")
    return ([by_column[:, j] for j in picked],
            [np.ravel(result.cutoff)[j] for j in picked],
            [np.ravel(result.noise)[j] for j in picked],
            [np.ravel(result.slope)[j] for j in picked],
            [f"column {j}" for j in picked])
