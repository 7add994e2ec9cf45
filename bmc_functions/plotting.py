"""Small matplotlib helpers shared by the notebooks: 3D frames, marker clusters, equal axes."""

import numpy as np

from ._checks import (as_float_array, check_finite_or_nan, check_flag, check_number,
                      check_vectors)

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
    length = check_number(length, "length")
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
    length = check_number(length, "length")
    n = R.shape[0]
    if titles is not None and (isinstance(titles, str) or not hasattr(titles, "__len__")):
        raise ValueError(f"titles must be a sequence of strings, one per panel; got "
                         f"{type(titles).__name__}")
    if titles is not None and len(titles) != n:
        raise ValueError(f"titles must have one item per panel ({n}); got {len(titles)}")
    fig = plt.figure(figsize=figsize or (3.2 * n, 3.4))
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
    if v.shape != (3,) or origin.shape != (3,):
        raise ValueError(f"v and origin must each have shape (3,); got shapes {v.shape} "
                         f"and {origin.shape}")
    ax.quiver(*origin, *v, color=color, linestyle=linestyle, alpha=alpha, linewidth=2,
              arrow_length_ratio=0.12)
    tip = origin + v
    ax.scatter(*tip, s=0, alpha=0)  # keeps the tip inside the automatic limits
    if label:
        ax.text(*(origin + 1.08 * v), label, color=color)
