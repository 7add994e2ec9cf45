"""Small matplotlib helpers shared by the notebooks: 3D frames, marker clusters, equal axes."""

import numpy as np

from ._checks import as_float_array, check_vectors

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
    markers = check_vectors(markers, "markers")
    if markers.ndim != 2:
        raise ValueError(f"markers must have shape (n, 3); got shape {markers.shape}")
    ax.scatter(*markers.T, color=color, label=label, marker=marker, depthshade=False,
               **kwargs)
    if connect and len(markers) > 1:
        closed = np.vstack([markers, markers[:1]])
        ax.plot(*closed.T, color=color, linewidth=0.8, alpha=0.6)
