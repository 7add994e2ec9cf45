"""Cardan (Tait-Bryan) and Euler angles: decompose a rotation matrix, and compose one.

**Intrinsic or extrinsic is chosen only by the keyword ``extrinsic``, never by the case
of the letters.** ``'zxy'``, ``'ZXY'`` and ``'Zxy'`` are the same sequence here. (SciPy
uses upper case for intrinsic and lower case for extrinsic; mixing up the two conventions
is a common source of wrong angles, so this package does not follow it.)

- Intrinsic (default), sequence ``'ijk'``: rotate about the moving axes, first about
  ``i``, then about the new ``j``, then about the newest ``k``:
  ``R = R_i(a) @ R_j(b) @ R_k(c)``.
- Extrinsic (``extrinsic=True``), sequence ``'ijk'``: rotate about the fixed axes, first
  about ``i``, then ``j``, then ``k``: ``R = R_k(c) @ R_j(b) @ R_i(a)``.

Angles are returned in sequence order, ``(a, b, c)``.
"""

import numpy as np

from .._checks import (as_float_array, check_finite_or_nan, check_flag, check_rotation_matrix,
                       check_sequence, warn_frames)
from .rotations import axis_indices, elemental_rotation

#: |cos(b)| (Cardan) or |sin(b)| (Euler) below which the middle angle is taken as gimbal
#: lock: the first and third axes are then aligned and only their sum (or difference) is
#: defined, so the third angle is set to zero. Setting it to zero changes the composed
#: matrix by at most pi * GIMBAL_TOL, so the tolerance is kept near rounding level.
GIMBAL_TOL = 1e-12


def decompose(R, sequence="ZXY", *, extrinsic=False, degrees=False):
    r"""Cardan or Euler angles of rotation matrices.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Rotation matrices (orthonormal, determinant +1). Frames on the leading axes.
        Matrices containing NaN give NaN angles.
    sequence : str, optional
        Three axes from ``x, y, z``: a Cardan sequence (``'XYZ', 'XZY', 'YXZ', 'YZX',
        'ZXY', 'ZYX'``) or a proper Euler sequence (``'XYX', 'XZX', 'YXY', 'YZY', 'ZXZ',
        'ZYZ'``). Case-insensitive. Default ``'ZXY'``.
    extrinsic : bool, keyword-only
        False (default): intrinsic rotations, ``R = R_i(a) @ R_j(b) @ R_k(c)``.
        True: extrinsic rotations about the fixed axes in sequence order,
        ``R = R_k(c) @ R_j(b) @ R_i(a)``. The letter case never selects this.
    degrees : bool, keyword-only
        Return degrees instead of radians. Default False.

    Returns
    -------
    angles : ndarray, shape (..., 3)
        ``(a, b, c)``, the angles about the first, second and third axis of `sequence`.
        First and third angles in :math:`(-\pi, \pi]`; the middle angle in
        :math:`[-\pi/2, \pi/2]` for Cardan and :math:`[0, \pi]` for Euler sequences.

    Raises
    ------
    TypeError
        If `extrinsic` or `degrees` is not a boolean (``'False'`` is a string), `R` is
        not numeric, or `sequence` is not a string.
    ValueError
        If `R` is not of shape (..., 3, 3), contains infinite values, is not orthonormal
        (tolerance ``ORTHONORMAL_ATOL = 1e-6``), has determinant -1, or `sequence` is
        unknown.

    Warns
    -----
    RuntimeWarning
        Once per call, with the number of frames in gimbal lock (middle angle at
        :math:`\pm\pi/2` for Cardan, :math:`0` or :math:`\pi` for Euler, within
        ``GIMBAL_TOL = 1e-12``). There the first and third axes coincide, only their
        combined rotation is defined, and the third angle is set to 0. The angles still
        reproduce `R` (to within :math:`\pi \cdot 10^{-12}`). Close to, but not in, gimbal
        lock the first and third angles are individually ill-conditioned (small changes
        of `R` change them a lot), although together they reproduce `R`.

    Notes
    -----
    Rows and columns are numbered from 0 (:math:`x = 0, y = 1, z = 2`), as in NumPy.
    For an intrinsic Cardan sequence :math:`ijk` with parity :math:`e = +1` when
    :math:`(i, j, k)` is a cyclic permutation of :math:`(x, y, z)` and :math:`-1`
    otherwise, multiplying out :math:`R = R_i(a) R_j(b) R_k(c)` gives

    .. math::

        R_{ik} = e \sin b, \quad
        R_{ii} = \cos b \cos c, \quad R_{ij} = -e \cos b \sin c ,

    so :math:`b = \operatorname{atan2}(e R_{ik}, \sqrt{R_{ii}^2 + R_{ij}^2})` and
    :math:`c = \operatorname{atan2}(-e R_{ij}, R_{ii})`. For ZXY
    (:math:`R = R_z R_x R_y`) this is :math:`\theta_x = \operatorname{atan2}(R_{21},
    \sqrt{R_{20}^2 + R_{22}^2})`, :math:`\theta_y = \operatorname{atan2}(-R_{20}, R_{22})`.
    For a proper Euler sequence :math:`iji`, :math:`R_{ii} = \cos b`,
    :math:`R_{ij} = \sin b \sin c` and :math:`R_{ik} = e \sin b \cos c`.

    The first angle is then read from :math:`M = R\,R_k(c)^T = R_i(a) R_j(b)` (with
    :math:`R_i(c)^T` for Euler), whose column :math:`j` is
    :math:`R_i(a)\,e_j = (\cos a)\, e_j + e (\sin a)\, e_k`:
    :math:`a = \operatorname{atan2}(e M_{kj}, M_{jj})`. Computing `a` from the
    already-found `c` keeps the angles consistent near gimbal lock, so composing them
    reproduces `R` to rounding error even where `a` and `c` are individually
    ill-conditioned. arctan2 (not arctan) is used throughout so that every quadrant
    is recovered.

    An extrinsic sequence :math:`ijk` is the intrinsic sequence :math:`kji` with the
    angles in reverse order; in gimbal lock its third angle (that sequence's first) is
    set to 0 and the other outer angle computed from it in the same way. The same
    convention as ``scipy.spatial.transform.Rotation.as_euler``.

    References
    ----------
    .. [1] Diebel J (2006) Representing attitude: Euler angles, unit quaternions, and
       rotation vectors. Stanford University technical report.
    .. [2] Grood ES, Suntay WJ (1983) A joint coordinate system for the clinical
       description of three-dimensional motions: application to the knee. J Biomech Eng
       105:136-144.
    .. [3] Wu G et al. (2002) ISB recommendation on definitions of joint coordinate
       system of various joints for the reporting of human joint motion - part I.
       J Biomech 35:543-548.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import compose, decompose, rot_x, rot_y, rot_z
    >>> R = rot_z(30, degrees=True) @ rot_x(20, degrees=True) @ rot_y(10, degrees=True)
    >>> decompose(R, 'ZXY', degrees=True).round(6)
    array([30., 20., 10.])
    >>> decompose(R, 'zxy', degrees=True).round(6)  # letter case does not matter
    array([30., 20., 10.])
    >>> Re = rot_y(10, degrees=True) @ rot_x(20, degrees=True) @ rot_z(30, degrees=True)
    >>> decompose(Re, 'ZXY', extrinsic=True, degrees=True).round(6)
    array([30., 20., 10.])
    """
    seq, _ = check_sequence(sequence)
    extrinsic = check_flag(extrinsic, "extrinsic")
    degrees = check_flag(degrees, "degrees")
    return decompose_orthonormal(check_rotation_matrix(R), seq, extrinsic=extrinsic,
                                 degrees=degrees)


def decompose_orthonormal(R, sequence="ZXY", *, extrinsic=False, degrees=False):
    """:func:`decompose` without the rotation-matrix check, for matrices known orthonormal.

    For code that built `R` itself from orthonormal frames (products of segment axes
    made by cross products and normalisation, as the Plug-in Gait model does on every
    frame of a trial): the orthonormality and determinant test of :func:`decompose`
    then costs as much as the decomposition and can never fail. The angles are the
    same, bit for bit, as those of :func:`decompose`, and so are the NaN and gimbal-lock
    rules. Matrices from outside (files, users) go through :func:`decompose`: here a
    matrix that is not a rotation gives meaningless angles without an error.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Rotation matrices, orthonormal with determinant +1 by construction; NaN for
        missing frames. Not checked.
    sequence, extrinsic, degrees
        As in :func:`decompose`.

    Returns
    -------
    angles : ndarray, shape (..., 3)
        As :func:`decompose`.

    Raises
    ------
    TypeError
        If `extrinsic` or `degrees` is not a boolean or `sequence` is not a string.
    ValueError
        If `R` is not of shape (..., 3, 3) or `sequence` is unknown.

    Examples
    --------
    >>> from bmc_functions import rot_x, rot_y, rot_z
    >>> from bmc_functions.rigid_body.cardan import decompose_orthonormal
    >>> R = rot_z(30, degrees=True) @ rot_x(20, degrees=True) @ rot_y(10, degrees=True)
    >>> decompose_orthonormal(R, 'ZXY', degrees=True).round(6)
    array([30., 20., 10.])
    """
    seq, euler = check_sequence(sequence)
    extrinsic = check_flag(extrinsic, "extrinsic")
    degrees = check_flag(degrees, "degrees")
    R = np.asarray(R, dtype=float)
    if R.ndim < 2 or R.shape[-2:] != (3, 3):
        raise ValueError(f"R must have shape (..., 3, 3); got shape {R.shape}")
    if extrinsic:
        # Extrinsic ijk is intrinsic kji with the angles reversed; the angle to set to 0
        # in gimbal lock (our third) is then that sequence's first.
        angles, locked = _intrinsic_angles(R, seq[::-1], euler, zero_in_lock="first")
        angles = angles[..., ::-1]
    else:
        angles, locked = _intrinsic_angles(R, seq, euler, zero_in_lock="third")
    # A matrix with any NaN entry is missing data: all three angles are unknown. (Its
    # entries summed are NaN exactly then, for the finite-or-NaN matrices of this
    # function and of decompose, which refuses infinite ones: faster than any() over
    # the two small trailing axes.)
    angles[np.isnan(np.einsum("...ij->...", R))] = np.nan
    warn_frames(int(np.count_nonzero(locked)), locked.size,
                f"are in gimbal lock for sequence {seq} (middle angle "
                f"{'0 or 180' if euler else '+/-90'} degrees); their third angle was set to 0")
    return np.rad2deg(angles) if degrees else angles


def _intrinsic_angles(R, seq, euler, zero_in_lock):
    """Angles (a, b, c) of R = R_i(a) R_j(b) R_k(c) (R_i(c) for Euler) and the lock mask.

    In gimbal lock the angle named by `zero_in_lock` ('first' or 'third') is set to 0;
    the other outer angle is always computed from the one already known (see the Notes
    of decompose), so that the three angles reproduce R.
    """
    i, j, k, e = axis_indices(seq[0], seq[1])
    if euler:
        sin_b = np.hypot(R[..., i, j], R[..., i, k])
        b = np.arctan2(sin_b, R[..., i, i])
        locked = sin_b < GIMBAL_TOL
    else:
        cos_b = np.hypot(R[..., i, i], R[..., i, j])
        b = np.arctan2(e * R[..., i, k], cos_b)
        locked = cos_b < GIMBAL_TOL

    # (only the two entries of a column or row that the next angle needs are formed)
    if zero_in_lock == "third":
        if euler:
            c = np.where(locked, 0.0, np.arctan2(R[..., i, j], e * R[..., i, k]))
            # column j of R @ R_i(c).T = R_i(a) @ R_j(b): cos(c) R[:, j] - e sin(c) R[:, k]
            cos_c, sin_c, other = np.cos(c), e * np.sin(c), k
            col_j = cos_c * R[..., j, j] - sin_c * R[..., j, other]
            col_k = cos_c * R[..., k, j] - sin_c * R[..., k, other]
        else:
            c = np.where(locked, 0.0, np.arctan2(-e * R[..., i, j], R[..., i, i]))
            # column j of R @ R_k(c).T = R_i(a) @ R_j(b): cos(c) R[:, j] + e sin(c) R[:, i]
            cos_c, sin_c, other = np.cos(c), e * np.sin(c), i
            col_j = cos_c * R[..., j, j] + sin_c * R[..., j, other]
            col_k = cos_c * R[..., k, j] + sin_c * R[..., k, other]
        # that column is R_i(a) e_j = cos(a) e_j + e sin(a) e_k
        a = np.arctan2(e * col_k, col_j)
    else:
        if euler:
            a = np.where(locked, 0.0, np.arctan2(R[..., j, i], -e * R[..., k, i]))
        else:
            a = np.where(locked, 0.0, np.arctan2(-e * R[..., j, k], R[..., k, k]))
        # row j of R_i(a).T @ R = R_j(b) @ R_(k or i)(c): cos(a) R[j] + e sin(a) R[k]
        cos_a, sin_a = np.cos(a), e * np.sin(a)
        last = k if euler else i
        row_j = cos_a * R[..., j, j] + sin_a * R[..., k, j]
        row_last = cos_a * R[..., j, last] + sin_a * R[..., k, last]
        if euler:  # row j of R_i(c) = cos(c) e_j - e sin(c) e_k
            c = np.arctan2(-e * row_last, row_j)
        else:  # row j of R_k(c) = cos(c) e_j + e sin(c) e_i
            c = np.arctan2(e * row_last, row_j)

    # Report +pi rather than -pi for the first and third angles: ranges (-pi, pi].
    a, c = (np.where(x == -np.pi, np.pi, x) for x in (a, c))
    return np.stack([a, b, c], axis=-1), locked


def compose(angles, sequence="ZXY", *, extrinsic=False, degrees=False):
    r"""Rotation matrices from Cardan or Euler angles; the inverse of :func:`decompose`.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        ``(a, b, c)``, the angles about the first, second and third axis of `sequence`.
    sequence : str, optional
        As in :func:`decompose`. Case-insensitive. Default ``'ZXY'``.
    extrinsic : bool, keyword-only
        False (default): ``R = R_i(a) @ R_j(b) @ R_k(c)`` (intrinsic). True:
        ``R = R_k(c) @ R_j(b) @ R_i(a)`` (rotations about the fixed axes).
    degrees : bool, keyword-only
        Angles in degrees. Default False.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)

    Raises
    ------
    TypeError
        If `extrinsic` or `degrees` is not a boolean, `angles` is not numeric, or
        `sequence` is not a string.
    ValueError
        If `angles` is not of shape (..., 3), has infinite values or values beyond
        ``MAX_MAGNITUDE = 1e100``, or `sequence` is unknown.

    Notes
    -----
    The product of three elemental rotations (see :func:`elemental_rotation`). NaN
    angles give NaN matrices.

    Examples
    --------
    >>> from bmc_functions import compose, rot_x, rot_y, rot_z
    >>> import numpy as np
    >>> R = compose([30, 20, 10], 'ZXY', degrees=True)
    >>> bool(np.allclose(R, rot_z(30, degrees=True) @ rot_x(20, degrees=True)
    ...                     @ rot_y(10, degrees=True)))
    True
    >>> compose(np.zeros((5, 3))).shape
    (5, 3, 3)
    """
    seq, _ = check_sequence(sequence)
    extrinsic = check_flag(extrinsic, "extrinsic")
    degrees = check_flag(degrees, "degrees")
    angles = as_float_array(angles, "angles")
    if angles.ndim == 0 or angles.shape[-1] != 3:
        raise ValueError(f"angles must have shape (..., 3), one angle per axis of the "
                         f"sequence; got shape {angles.shape}")
    check_finite_or_nan(angles, "angles")
    Ra, Rb, Rc = (elemental_rotation(axis, angles[..., n], degrees)
                  for n, axis in enumerate(seq))
    return Rc @ Rb @ Ra if extrinsic else Ra @ Rb @ Rc
