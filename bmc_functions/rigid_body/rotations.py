"""Rotation matrices: elemental rotations and the rotation that takes one vector onto another.

Conventions used throughout the package:

- A rotation matrix ``R`` has shape ``(..., 3, 3)``; leading axes are frames (or any batch).
- ``R`` is *active*: ``R @ v`` rotates the vector ``v``. Equivalently, the columns of ``R``
  are the axes of a rotated frame expressed in the fixed (global) frame, so ``R @ p_local``
  gives the global coordinates of a point known in the rotated frame.
- Angles are in radians unless a function has ``degrees=True``.
"""

import numpy as np

from .._checks import (ArgumentTypeError, as_float_array, check_finite_or_nan, check_flag,
                       check_rotation_matrix, check_vectors)

_AXIS_INDEX = {"X": 0, "Y": 1, "Z": 2}


def axis_indices(first, second):
    """Indices i, j, k of two different axes (letters, any case) and the remaining one,
    and the parity e = +1 if (i, j, k) is a cyclic permutation of (0, 1, 2), else -1.

    Examples
    --------
    >>> from bmc_functions.rigid_body.rotations import axis_indices
    >>> axis_indices('z', 'x'), axis_indices('X', 'Z')
    ((2, 0, 1, 1.0), (0, 2, 1, -1.0))
    """
    i, j = _AXIS_INDEX[first.upper()], _AXIS_INDEX[second.upper()]
    return i, j, 3 - i - j, (1.0 if (j - i) % 3 == 1 else -1.0)


def elemental_rotation(axis, angle, degrees=False):
    r"""Rotation matrix about one coordinate axis.

    Parameters
    ----------
    axis : {'x', 'y', 'z'}
        The coordinate axis (case-insensitive).
    angle : array_like, shape (...)
        Rotation angle, positive counterclockwise when looking from the positive axis
        towards the origin (right-hand rule).
    degrees : bool, optional
        If True, `angle` is in degrees. Default False (radians).

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
        The rotation matrices, one per angle.

    Raises
    ------
    TypeError
        If `degrees` is not a boolean, `axis` is not a string, or `angle` is not numeric.
    ValueError
        If `axis` is not one of x, y, z, or `angle` is infinite or beyond
        ``MAX_MAGNITUDE = 1e100``. (A NaN angle gives NaN in the four entries that
        depend on it.)

    Notes
    -----
    .. math::

        R_x(\alpha) = \begin{bmatrix} 1 & 0 & 0 \\ 0 & \cos\alpha & -\sin\alpha \\
                      0 & \sin\alpha & \cos\alpha \end{bmatrix},\quad
        R_y(\beta) = \begin{bmatrix} \cos\beta & 0 & \sin\beta \\ 0 & 1 & 0 \\
                      -\sin\beta & 0 & \cos\beta \end{bmatrix},\quad
        R_z(\gamma) = \begin{bmatrix} \cos\gamma & -\sin\gamma & 0 \\
                      \sin\gamma & \cos\gamma & 0 \\ 0 & 0 & 1 \end{bmatrix}

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import elemental_rotation
    >>> elemental_rotation('z', 90, degrees=True).round(6) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    >>> elemental_rotation('x', [0.1, 0.2]).shape
    (2, 3, 3)
    """
    if not isinstance(axis, str):
        raise ArgumentTypeError(f"axis must be one of 'x', 'y', 'z'; got {axis!r} "
                                f"({type(axis).__name__})")
    if axis.upper() not in _AXIS_INDEX:
        raise ValueError(f"axis must be one of 'x', 'y', 'z'; got {axis!r}")
    degrees = check_flag(degrees, "degrees")
    angle = as_float_array(angle, "angle")
    check_finite_or_nan(angle, "angle")
    if degrees:
        angle = np.deg2rad(angle)
    i = _AXIS_INDEX[axis.upper()]
    j, k = (i + 1) % 3, (i + 2) % 3  # (i, j, k) is a cyclic permutation of (0, 1, 2)
    c, s = np.cos(angle), np.sin(angle)
    R = np.zeros(angle.shape + (3, 3))
    R[..., i, i] = 1.0
    R[..., j, j] = c
    R[..., k, k] = c
    R[..., j, k] = -s
    R[..., k, j] = s
    return R


def rot_x(angle, degrees=False):
    """Rotation matrix about the x axis; see :func:`elemental_rotation`.

    Examples
    --------
    >>> from bmc_functions import rot_x
    >>> rot_x(0.5).shape
    (3, 3)
    """
    return elemental_rotation("x", angle, degrees)


def rot_y(angle, degrees=False):
    """Rotation matrix about the y axis; see :func:`elemental_rotation`.

    Examples
    --------
    >>> from bmc_functions import rot_y
    >>> rot_y(90, degrees=True).round(6) + 0.0
    array([[ 0.,  0.,  1.],
           [ 0.,  1.,  0.],
           [-1.,  0.,  0.]])
    """
    return elemental_rotation("y", angle, degrees)


def rot_z(angle, degrees=False):
    """Rotation matrix about the z axis; see :func:`elemental_rotation`.

    Examples
    --------
    >>> from bmc_functions import rot_z
    >>> rot_z([0.0, 0.1, 0.2]).shape
    (3, 3, 3)
    """
    return elemental_rotation("z", angle, degrees)


def skew(v):
    r"""Skew-symmetric (cross-product) matrix of vectors: ``skew(a) @ b == cross(a, b)``.

    Parameters
    ----------
    v : array_like, shape (..., 3)

    Returns
    -------
    S : ndarray, shape (..., 3, 3)

    Raises
    ------
    ValueError
        If `v` is not numeric, not of shape (..., 3), or contains infinite values.

    Notes
    -----
    .. math:: [\mathbf{v}]_\times = \begin{bmatrix} 0 & -v_z & v_y \\ v_z & 0 & -v_x \\
              -v_y & v_x & 0 \end{bmatrix}

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.rigid_body.rotations import skew
    >>> skew([1, 2, 3]) @ np.array([4, 5, 6]) - np.cross([1, 2, 3], [4, 5, 6])
    array([0., 0., 0.])
    """
    v = check_vectors(v, "v")
    S = np.zeros(v.shape + (3,))
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    S[..., 0, 1], S[..., 0, 2] = -z, y
    S[..., 1, 0], S[..., 1, 2] = z, -x
    S[..., 2, 0], S[..., 2, 1] = -y, x
    return S


def unit_vectors(v, name="v"):
    """Divide vectors by their length; ValueError for zero length, NaN stays NaN.

    Parameters
    ----------
    v : array_like, shape (..., 3)
    name : str
        Name of the argument, used in error messages.

    Returns
    -------
    u : ndarray, shape (..., 3)

    Raises
    ------
    ValueError
        If any vector (without NaN) has zero length, or `v` has the wrong shape.

    Notes
    -----
    Each vector is divided by its largest absolute component before its length is
    computed, so that any finite nonzero vector (1e-300 or 1e300) has a direction.

    Examples
    --------
    >>> from bmc_functions.rigid_body.rotations import unit_vectors
    >>> unit_vectors([3, 0, 4])
    array([0.6, 0. , 0.8])
    """
    v = check_vectors(v, name, max_abs=None)
    # Scaled by the largest component first, so that the squares in the length neither
    # overflow (1e155) nor underflow (1e-300): any finite nonzero vector has a direction.
    scale = np.maximum(np.maximum(np.abs(v[..., 0]), np.abs(v[..., 1])), np.abs(v[..., 2]))
    zero = scale == 0
    if zero.any():
        where = np.argwhere(zero)
        first = f" (first at index {tuple(int(i) for i in where[0])})" if v.ndim > 1 else ""
        raise ValueError(f"{name} has zero length in {zero.sum()} of {zero.size} vectors"
                         f"{first}; a direction needs a nonzero vector")
    v = v / scale[..., None]
    return v / _norm(v)[..., None]


def vector_dot(x, y):
    """Dot products of 3D vectors over the last axis, shape (...): the same values, bit
    for bit, as ``np.sum(x * y, axis=-1)`` (summed in the same order), written out
    because a reduction over an axis of length 3 is slow. No argument check.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.rigid_body.rotations import vector_dot
    >>> print(vector_dot(np.array([[1.0, 2.0, 3.0]]), np.array([[4.0, 5.0, 6.0]])))
    [32.]
    """
    return x[..., 0] * y[..., 0] + x[..., 1] * y[..., 1] + x[..., 2] * y[..., 2]


_dot = vector_dot


def dot_rows(a, b, out, scratch):
    """``a[0] * b[0] + a[1] * b[1] + a[2] * b[2]``, added in that order (vector_dot's), into
    `out`, the second and third products made in `scratch`: dot products of vectors given
    as their component rows (shape (3, ...)), or any three such terms (the rows of
    matrices times components), without temporaries (a loop reusing its arrays). `out`
    and `scratch` have the products' shape and overlap neither `a` nor `b`. No argument
    check.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.rigid_body.rotations import dot_rows
    >>> a, b = np.array([[1.0, 0.0], [2.0, 1.0], [3.0, 0.0]]), np.full((3, 2), 2.0)
    >>> print(dot_rows(a, b, np.empty(2), np.empty(2)))
    [12.  2.]
    """
    np.multiply(a[0], b[0], out=out)
    out += np.multiply(a[1], b[1], out=scratch)
    out += np.multiply(a[2], b[2], out=scratch)
    return out


def cross_rows(a, b, out=None, scratch=None):
    """Cross products of 3D vectors given as their component rows, ``a[0], a[1], a[2]``
    (shape (3, ...); each component's items side by side), shape (3, ...): each component
    as ``numpy.cross`` computes it (the same values, bit for bit), several times faster
    than ``numpy.cross`` or the same products on the strided columns of (..., 3) arrays.
    No argument check. With `out` (shape (3, ...), overlapping neither `a` nor `b`) the
    products are written into it, and with `scratch` (shape (...)) the second product of
    each component too: the same numbers without temporaries (a loop reusing its arrays).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.rigid_body.rotations import cross_rows
    >>> print(cross_rows(np.array([[1.0], [0.0], [0.0]]), np.array([[0.0], [1.0], [0.0]]))[:, 0])
    [0. 0. 1.]
    """
    if out is None:
        out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    for i, (j, k) in enumerate(((1, 2), (2, 0), (0, 1))):    # a_j b_k - a_k b_j
        component = out[i, ...]                  # a view, 0-d for a single vector
        np.multiply(a[j], b[k], out=component)
        component -= np.multiply(a[k], b[j], out=scratch)
    return out


def vector_length(v):
    """Lengths of 3D vectors on the last axis, shape (...): the same values, bit for bit,
    as ``np.linalg.norm(v, axis=-1)`` (the squares summed in the same order), several
    times faster on long stacks of vectors, where a reduction over an axis of length 3 is
    slow. NaN propagates; no argument check (for arrays the caller has checked).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.rigid_body.rotations import vector_length
    >>> print(vector_length(np.array([[3.0, 4.0, 0.0], [1.0, 2.0, 2.0]])))
    [5. 3.]
    """
    return np.sqrt(_dot(v, v))


def _norm(x):
    """Lengths of vectors on the last axis (the same values as np.linalg.norm)."""
    return vector_length(x)


def _perpendicular(u):
    """A deterministic unit vector perpendicular to each unit vector in `u`.

    The rule: ``u x e_j`` normalized, where ``e_j`` is the coordinate axis along which
    ``u`` has its smallest absolute component (the lowest index on ties), so that the
    cross product is never small.
    """
    j = np.argmin(np.abs(np.nan_to_num(u)), axis=-1)
    e = np.eye(3)[j]
    p = np.cross(u, e)
    return p / np.linalg.norm(p, axis=-1, keepdims=True)


def get_R(A, B):
    r"""The minimal rotation that takes the direction of vector `A` onto that of `B`.

    Parameters
    ----------
    A, B : array_like, shape (..., 3)
        Vectors (any nonzero length). Leading axes broadcast against each other.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
        Proper rotation matrices with ``R @ A / |A| == B / |B|``, rotating about the axis
        ``A x B`` by the angle between the vectors. Items with NaN give NaN.

    Raises
    ------
    TypeError
        If `A` or `B` is not numeric (None, booleans, strings, complex).
    ValueError
        If a vector (without NaN) has zero length (all three components exactly 0), a
        component is infinite, or the shapes are not (..., 3) or do not broadcast.

    Notes
    -----
    With the unit vectors :math:`\hat a = A/|A|` and :math:`\hat b = B/|B|`, the rotation
    angle :math:`\theta` has :math:`\cos\theta = \hat a\cdot\hat b` and
    :math:`\sin\theta = |\hat a\times\hat b|`, and the unit axis is
    :math:`\hat k = \hat a\times\hat b / |\hat a\times\hat b|`. Rodrigues' formula gives

    .. math:: R = \cos\theta\, I + \sin\theta\, [\hat k]_\times
              + (1-\cos\theta)\, \hat k \hat k^T ,

    the same matrix as the change of basis to :math:`(\hat a, \hat b_\perp, \hat k)`,
    a rotation about the third axis, and the change back.

    Special cases, both exact: parallel vectors give the identity; antiparallel vectors
    give a rotation by :math:`\pi` about a deterministic axis perpendicular to `A`,
    :math:`\hat a \times e_j` normalized, where :math:`e_j` is the coordinate axis along
    which :math:`\hat a` has its smallest absolute component (lowest index on ties).
    For nearly (anti)parallel vectors the axis is made exactly perpendicular to
    :math:`\hat a`, which keeps ``R @ a_hat == b_hat`` to rounding error.

    Any finite nonzero vector has a direction: each is divided by its largest absolute
    component before its length is computed, so that neither 1e-300 nor 1e300 loses it
    to underflow or overflow. Masked entries of a masked array count as NaN.

    The rotation is not the only one taking `A` onto `B`: any rotation about `B`
    applied afterwards also does. A single vector cannot reveal the twist about itself.

    References
    ----------
    .. [1] Rodrigues O (1840) Des lois géométriques qui régissent les déplacements d'un
       système solide dans l'espace. J Math Pures Appl 5:380-440.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import get_R
    >>> R = get_R([1, 0, 0], [0, 2, 0])
    >>> R.round(6) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    >>> get_R([1, 0, 0], [-1, 0, 0]).round(6) + 0.0  # antiparallel: pi about z
    array([[-1.,  0.,  0.],
           [ 0., -1.,  0.],
           [ 0.,  0.,  1.]])
    >>> get_R(np.ones((10, 3)), [[0, 0, 1]]).shape
    (10, 3, 3)
    """
    a = unit_vectors(A, "A")
    b = unit_vectors(B, "B")
    try:
        a, b = np.broadcast_arrays(a, b)
    except ValueError:
        raise ValueError(f"A and B must broadcast against each other; got shapes "
                         f"{np.shape(A)} and {np.shape(B)}") from None
    w = np.cross(a, b)
    cos = _dot(a, b)
    sin = _norm(w)
    scale = np.hypot(cos, sin)  # removes the rounding in cos**2 + sin**2 = 1
    cos, sin = cos / scale, sin / scale
    # Axis: a x b, or for exactly (anti)parallel vectors the deterministic perpendicular
    # (computed only where needed: it is rare and costs more than the rest).
    axis = w.copy()
    parallel = ~(sin > 0)
    if parallel.any():
        axis[parallel] = _perpendicular(a[parallel])
    # Made exactly perpendicular to a, so that R @ a == b even when a x b is tiny and its
    # direction inexact: that direction error is multiplied by sin in R @ a.
    axis = axis - _dot(axis, a)[..., None] * a
    axis = axis / _norm(axis)[..., None]
    # Rodrigues: cos I + sin [axis]x + (1 - cos) axis axis^T, assembled in place.
    R = ((1 - cos)[..., None] * axis)[..., :, None] * axis[..., None, :]
    for i in range(3):
        R[..., i, i] += cos
    s_axis = sin[..., None] * axis
    x, y, z = s_axis[..., 0], s_axis[..., 1], s_axis[..., 2]
    R[..., 0, 1] -= z
    R[..., 0, 2] += y
    R[..., 1, 0] += z
    R[..., 1, 2] -= x
    R[..., 2, 0] -= y
    R[..., 2, 1] += x
    return R


def rotation_angle(R):
    r"""Angle of rotation of rotation matrices, in radians, in [0, pi].

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)

    Returns
    -------
    angle : ndarray, shape (...)
        NaN for matrices containing NaN.

    Raises
    ------
    ValueError
        If `R` is not numeric, not of shape (..., 3, 3), contains infinite values, or
        is not a rotation matrix (orthonormal within ``ORTHONORMAL_ATOL = 1e-6``,
        det = +1): for a reflection or a scaled matrix an angle would be meaningless.

    Notes
    -----
    Computed as :math:`\operatorname{atan2}(|\mathbf{r}|, \operatorname{tr}R - 1)` with
    :math:`\mathbf{r} = (R_{21}-R_{12},\ R_{02}-R_{20},\ R_{10}-R_{01})` (rows and
    columns numbered from 0), which is :math:`2\sin\theta\,\hat k`, while
    :math:`\operatorname{tr}R - 1 = 2\cos\theta`; this is accurate for small angles,
    unlike :math:`\arccos((\operatorname{tr}R-1)/2)`. Near :math:`\pi` it is as
    accurate as the matrix.

    Examples
    --------
    >>> from bmc_functions import rot_z, rotation_angle
    >>> print(round(float(rotation_angle(rot_z(30, degrees=True))), 6))
    0.523599
    """
    return unchecked_rotation_angle(check_rotation_matrix(R))


def unchecked_rotation_angle(R):
    """:func:`rotation_angle` of matrices already known to be rotations (no check).

    For the package's own products of checked rotations (:mod:`.motion`), whose
    deviation from orthonormality can add up to more than the tolerance of one matrix.
    """
    r = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                  R[..., 1, 0] - R[..., 0, 1]], axis=-1)
    trace = R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2]
    return np.arctan2(np.linalg.norm(r, axis=-1), trace - 1)
