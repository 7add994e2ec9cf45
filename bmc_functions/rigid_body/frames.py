"""Orthonormal frames (segment, root or anatomical frames) from points and directions."""

import numpy as np

from .._checks import ArgumentTypeError, check_vectors
from .rotations import axis_indices, cross_rows, dot_rows

#: Sine of the angle between the two directions below which they count as parallel.
PARALLEL_RTOL = 1e-8


def frame_from_axes(primary, secondary, axes="xy"):
    r"""Right-handed orthonormal frame from a primary axis and a second direction.

    The primary direction gives the first named axis exactly; the second direction fixes
    the plane of the first two axes (Gram-Schmidt); the third axis completes a
    right-handed frame.

    Parameters
    ----------
    primary : array_like, shape (..., 3)
        Direction of the axis named by ``axes[0]``.
    secondary : array_like, shape (..., 3)
        A direction in the plane of the two named axes, on the positive side of
        ``axes[1]``. It need not be perpendicular to `primary`.
    axes : str, optional
        Two different letters from x, y, z (case-insensitive): the axes that `primary`
        and `secondary` define. Default 'xy'. For example ``'yz'`` builds y from
        `primary`, z from `secondary`, and x = y x z.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
        Rotation matrices whose columns are the unit x, y and z axes of the frame in the
        coordinates of the input vectors. Items with NaN give NaN.

    Raises
    ------
    TypeError
        If `primary` or `secondary` is not numeric, or `axes` is not a string.
    ValueError
        If a direction has zero length, the two directions are parallel (sine of the
        angle between them below ``PARALLEL_RTOL = 1e-8``), `axes` is not two different
        letters from x, y, z, or a shape is not (..., 3). Any finite nonzero lengths are
        accepted (each direction is scaled before its length is computed).

    Notes
    -----
    With :math:`p` the primary and :math:`s` the secondary direction,

    .. math:: \hat u = \frac{p}{|p|}, \quad
              \hat v = \frac{s - (s\cdot\hat u)\,\hat u}{|s - (s\cdot\hat u)\,\hat u|},
              \quad \hat w = \pm\, \hat u \times \hat v ,

    with the sign + when (primary, secondary, third) is a cyclic order of (x, y, z)
    (``'xy'``, ``'yz'``, ``'zx'``) and - otherwise, so that the frame is right-handed.
    Without the Gram-Schmidt step, a frame built from two non-perpendicular vectors is
    not orthonormal and its angles are wrong.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import frame_from_axes
    >>> frame_from_axes([2, 0, 0], [1, 1, 0]).round(6) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    >>> frame_from_axes([0, 0, 1], [1, 0, 0], axes='zx').round(6) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    if not isinstance(axes, str):
        raise ArgumentTypeError(f"axes must be two different letters from x, y, z such as "
                                f"'xy'; got {axes!r} ({type(axes).__name__})")
    if (len(axes) != 2 or not set(axes.upper()) <= set("XYZ")
            or axes[0].upper() == axes[1].upper()):
        raise ValueError(f"axes must be two different letters from x, y, z such as 'xy'; "
                         f"got {axes!r}")
    # Directions: any finite length will do (each is scaled before it is squared).
    p = check_vectors(primary, "primary", max_abs=None)
    s = check_vectors(secondary, "secondary", max_abs=None)
    try:
        p, s = np.broadcast_arrays(p, s)
    except ValueError:
        raise ValueError(f"primary and secondary must broadcast against each other; got "
                         f"shapes {p.shape} and {s.shape}") from None
    # On the components as rows (each one's items side by side: the strided columns of
    # (..., 3) arrays are several times slower), the same operations item by item, in
    # arrays made once and written in place (fresh temporaries of a long trial each cost
    # page faults). The axes are made in their places of `entries` (component, axis,
    # ...), which becomes R in one transposing copy: a third of the time of filling R's
    # three columns (each a pass over all of R).
    i, j, k, parity = axis_indices(axes[0], axes[1])
    shape = p.shape[:-1]
    entries = np.empty((3, 3) + shape)
    u, v, s_unit = entries[:, i], entries[:, j], np.empty((3,) + shape)
    length, term = np.empty(shape), np.empty(shape)
    for name, given, rows in (("primary", p, u), ("secondary", s, s_unit)):
        np.copyto(rows, np.moveaxis(given, -1, 0))
        # Divided by the largest component before the length is computed: the squares
        # of a huge (1e200) or tiny (1e-300) vector would overflow or underflow.
        absolute = np.abs(rows, out=v)                  # v: scratch until its turn
        scale = np.maximum(np.maximum(absolute[0], absolute[1], out=length), absolute[2],
                           out=length)
        zero = scale == 0
        if zero.any():
            raise ValueError(f"{name} has zero length in {zero.sum()} of {zero.size} items "
                             "(coincident points?)")
        rows /= scale
        rows /= _length(rows, length, term)
    # v = s_unit - (s_unit . u) u
    dot = dot_rows(s_unit, u, term, length)
    np.subtract(s_unit, np.multiply(dot, u, out=v), out=v)
    v_norm = _length(v, length, term)
    parallel = v_norm < PARALLEL_RTOL
    if parallel.any():
        raise ValueError(f"primary and secondary are parallel in {parallel.sum()} of "
                         f"{parallel.size} items (collinear points?); they must span a plane")
    v /= v_norm
    cross_rows(*((u, v) if parity > 0 else (v, u)), out=entries[:, k], scratch=term)
    R = np.empty(shape + (3, 3))
    np.copyto(R, np.moveaxis(entries, (0, 1), (-2, -1)))
    return R


def _length(v, out, scratch):
    """Lengths of (3, ...) rows of vectors into `out` (`scratch`: a work array of its
    shape): :func:`~bmc_functions.rigid_body.rotations.vector_length`'s sum, in its
    order, ``sqrt((v0 v0 + v1 v1) + v2 v2)``."""
    return np.sqrt(dot_rows(v, v, out, scratch), out=out)


def frame_from_points(origin, primary_point, secondary_point, axes="xy"):
    """Orthonormal frame from three points: the origin and two points that set its axes.

    Parameters
    ----------
    origin : array_like, shape (..., 3)
        The frame's origin (e.g. a joint centre). Frames on the leading axes.
    primary_point : array_like, shape (..., 3)
        The axis ``axes[0]`` points from `origin` towards this point.
    secondary_point : array_like, shape (..., 3)
        Together with `origin` and `primary_point`, fixes the plane of the first two
        axes; ``axes[1]`` points to its side.
    axes : str, optional
        As in :func:`frame_from_axes`. Default 'xy'.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
        Columns: the frame's unit x, y, z axes. See :func:`frame_from_axes`.

    Raises
    ------
    ValueError
        If points coincide or are collinear, shapes are wrong, or a coordinate is
        infinite or beyond ``MAX_MAGNITUDE = 1e100`` (the differences of the points must
        not overflow).

    Examples
    --------
    >>> from bmc_functions import frame_from_points
    >>> frame_from_points([1, 1, 1], [1, 1, 5], [3, 1, 1], axes='zx').round(6) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    origin = check_vectors(origin, "origin")
    primary = check_vectors(primary_point, "primary_point") - origin
    secondary = check_vectors(secondary_point, "secondary_point") - origin
    return frame_from_axes(primary, secondary, axes)


def nearest_lab_axis(vector, exclude=None):
    """The signed lab axis (a unit vector) closest to `vector`, skipping axis `exclude`.

    How the pipelines name a lab's axes (which one is up, which one forward) from a mean
    segment direction, whichever axis the lab chose for them.

    Parameters
    ----------
    vector : array_like, shape (3,)
    exclude : int, optional
        An axis already taken (0, 1 or 2).

    Returns
    -------
    axis_vector : ndarray, shape (3,)
        +/- the unit vector of the chosen axis (+ when `vector` has no component on it).
    axis : int

    Examples
    --------
    >>> from bmc_functions.rigid_body.frames import nearest_lab_axis
    >>> nearest_lab_axis([0.1, -0.9, 0.3])
    (array([ 0., -1.,  0.]), 1)
    >>> nearest_lab_axis([0.1, -0.9, 0.3], exclude=1)
    (array([0., 0., 1.]), 2)
    """
    vector = np.asarray(vector, dtype=float)
    scores = np.abs(vector).copy()
    if exclude is not None:
        scores[exclude] = -1.0
    axis = int(np.argmax(scores))
    out = np.zeros(3)
    out[axis] = np.sign(vector[axis]) or 1.0
    return out, axis
