r"""Rigid-body motion beyond angles: angular velocity and finite helical (screw) axes.

Both are built from the poses of a segment, a rotation matrix ``R`` (columns = segment
axes in the lab, ``p_lab = R @ p_segment + t``) and an origin ``t`` per frame, as
:func:`~bmc_functions.svdt` returns them. Frames on the first axis.
"""

from typing import NamedTuple

import numpy as np

from .._checks import (as_float_array, check_choice, check_rotation_matrix, check_scalar,
                       check_vectors, warn_frames)
from .rotations import dot_rows, rotation_angle, unchecked_rotation_angle

#: Default smallest rotation angle (radians, 5 degrees) for which :func:`helical_axis`
#: reports a direction and a point. The direction error grows as 1/angle (see Notes).
MIN_HELICAL_ANGLE = np.radians(5.0)


#: Largest rotation (radians, 30 degrees) between consecutive frames for which
#: :func:`angular_velocity` does not warn: the difference estimate is sin(angle)/h, 4.5 %
#: low at 30 degrees per frame, and a turn of more than 90 degrees per frame cannot be
#: told from 180 degrees minus it (the same sine: aliasing). A human segment turning
#: 30 degrees per frame at 100 Hz turns at 3000 deg/s, beyond walking and running.
MAX_FRAME_ROTATION = np.radians(30.0)


def _vee_skew(W):
    """The vector w of the skew-symmetric part of W: (W - W^T) / 2 = [w]x."""
    return 0.5 * np.stack([W[..., 2, 1] - W[..., 1, 2], W[..., 0, 2] - W[..., 2, 0],
                           W[..., 1, 0] - W[..., 0, 1]], axis=-1)


def _check_rate(rate):
    return check_scalar(rate, "rate", "a positive, finite sampling rate in Hz", minimum=0,
                        strict=True)


def _check_angle(value, name, low, text):
    """A number of radians in [low, pi): TypeError if not a number, ValueError if outside."""
    value = check_scalar(value, name, f"a number of radians in {text}")
    if not low <= value < np.pi:
        raise ValueError(f"{name} must be a number of radians in {text}; got {value!r}")
    return value


def _check_trial(R, name="R", min_frames=2):
    """A (frames, 3, 3) stack of rotation matrices with at least `min_frames` frames."""
    R = as_float_array(R, name)
    if R.ndim != 3 or R.shape[1:] != (3, 3):
        raise ValueError(f"{name} must have shape (frames, 3, 3), one rotation matrix per "
                         f"frame; got shape {R.shape}")
    R = check_rotation_matrix(R, name)
    if R.shape[0] < min_frames:
        raise ValueError(f"{name} must have at least {min_frames} frames to differentiate "
                         f"or compare poses; got {R.shape[0]}")
    return R


def consecutive_turns(R):
    """Rotation angle (radians) from each frame to the next of a (frames, 3, 3) stack of
    rotation matrices (checked by the caller), or of their (9, frames)
    :func:`matrix_rows`: :func:`~bmc_functions.rotation_angle` of
    :math:`R_{k+1} R_k^T`, from the nine row products of the pair, without forming the
    product; shape (frames - 1,), NaN next to a missing frame.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import rot_z
    >>> from bmc_functions.rigid_body.motion import consecutive_turns
    >>> print(np.degrees(consecutive_turns(rot_z([0, 10, 30, 70], degrees=True))).round(6))
    [10. 20. 40.]
    """
    return _turns(R if R.ndim == 2 and len(R) == 9 else matrix_rows(R))


#: Frames per block of :func:`matrix_rows`' copy (288 kB of matrices: they stay in cache
#: while their nine entries are copied out).
_ROWS_BLOCK = 4096


def matrix_rows(R):
    """The nine entries of (frames, 3, 3) matrices as contiguous (9, frames) rows,
    row-major (row i of the matrices at 3i:3i+3): each entry's frames side by side, the
    layout in which the differences and products below run fastest. A new array (never a
    view of `R`)."""
    entries = R.reshape(-1, 9)                  # one matrix per line
    rows = np.empty((9, len(entries)), dtype=entries.dtype)
    # copied a block of frames at a time (each block vectorized): one entry's frames lie
    # 72 bytes apart, and a whole long trial's matrices (4 MB at 60,000 frames) leave the
    # cache between one entry's pass and the next, a block's do not; twice as fast
    for start in range(0, len(entries), _ROWS_BLOCK):
        rows[:, start:start + _ROWS_BLOCK] = entries[start:start + _ROWS_BLOCK].T
    return rows


def _turns(e):
    """:func:`consecutive_turns` from the (9, frames) :func:`matrix_rows`, a block of
    :data:`_OMEGA_BLOCK` pairs of frames at a time (each pair on its own: the same
    numbers), into one block's scratch rows."""
    turn = np.empty(max(e.shape[1] - 1, 0), dtype=_float_type(e))
    work = np.empty((4, min(len(turn), _OMEGA_BLOCK)), dtype=turn.dtype)
    for start in range(0, len(turn), _OMEGA_BLOCK):
        stop = min(start + _OMEGA_BLOCK, len(turn))
        _block_turns(e[:, start + 1:stop + 1], e[:, start:stop], turn[start:stop],
                     work[:, :stop - start])
    return turn


def _float_type(e):
    """The type the work arrays of rows `e` are computed in: theirs if floating (float32
    rows stay float32, as numpy's arithmetic on them would), else float64."""
    return e.dtype if e.dtype.kind == "f" else np.dtype(float)


def _block_turns(now, before, out, work):
    """The rotation angle of :math:`R_{k+1} R_k^T` from the rows of R_{k+1} (`now`) and
    R_k (`before`) into `out`: arctan2(2 |vee of its skew part|, trace - 1), each sum
    in the order of the formula; `work`: (4, frames) scratch."""
    def entry(i, j, into):                    # (R_{k+1} R_k^T)_ij: row i . row j
        return dot_rows(now[3 * i:3 * i + 3], before[3 * j:3 * j + 3], into, work[3])

    sine, term = work[0], work[1]           # the squares of W_ij - W_ji summed, in order
    for k, (i, j) in enumerate(((2, 1), (0, 2), (1, 0))):
        difference = np.subtract(entry(i, j, sine if k == 0 else term),
                                 entry(j, i, work[2]), out=sine if k == 0 else term)
        np.square(difference, out=difference)
        if k:
            sine += term
    trace = entry(0, 0, term)
    trace += entry(1, 1, work[2])
    trace += entry(2, 2, work[2])
    trace -= 1
    return np.arctan2(np.sqrt(sine, out=sine), trace, out=out)


def _omega_rows(e, e_dot, frame, out, scratch):
    """The vector of the skew-symmetric part of :math:`\\dot R R^T` ('lab') or
    :math:`R^T \\dot R` ('local') as (3, frames) rows written into `out`, from the
    (9, frames) rows of R and of its derivative: only the six entries the vector needs,
    each a dot product of rows ('lab') or columns ('local'), summed in that order;
    `scratch`: (2, frames)."""
    if frame == "lab":                            # W_ij = (row i of R_dot) . (row j of R)
        def entry(i, j, into):
            return dot_rows(e_dot[3 * i:3 * i + 3], e[3 * j:3 * j + 3], into, scratch[1])
    else:                                         # W_ij = (column i of R) . (column j of R_dot)
        def entry(i, j, into):
            return dot_rows(e[i::3], e_dot[j::3], into, scratch[1])
    for row, (i, j) in zip(out, ((2, 1), (0, 2), (1, 0))):    # W_ij - W_ji, halved
        np.subtract(entry(i, j, row), entry(j, i, scratch[0]), out=row)
    out *= 0.5
    return out


#: Frames per block of :func:`_omega_of_rows` and of :func:`_turns`: the derivative's
#: rows and the products of one block (32 kB a row) stay in the cache from one step to
#: the next and are reused by the next block, where the rows of a long trial (480 kB
#: at 60,000 frames) would be read from memory again by each step, and each temporary
#: be fresh memory (page faults). Every step is per frame (the differences read the
#: block's neighbouring frames): the same numbers.
_OMEGA_BLOCK = 4096


def _rate_rows(e, out, start, rate, forward, backward):
    """The derivative of :func:`_omega_of_rows` (its differences) of the frames from
    `start` on, as many as `out` (9, n) holds, written into `out`."""
    frames, stop = e.shape[1], start + out.shape[1]
    low, high = max(start, 1), min(stop, frames - 1)    # central: both neighbours exist
    central = out[:, low - start:high - start]
    np.multiply(np.subtract(e[:, low + 1:high + 1], e[:, low - 1:high - 1], out=central),
                0.5 * rate, out=central)
    if start == 0:
        out[:, 0] = np.nan
    if stop == frames:
        out[:, -1] = np.nan
    # the few one-sided frames (ends, gap edges) of this block, if it has any (`forward`
    # and `backward` are sorted): (R[k+1] - R[k]) / h and (R[k] - R[k-1]) / h
    for index, ahead in ((forward, 1), (backward, 0)):
        here = index[np.searchsorted(index, start):np.searchsorted(index, stop)]
        if here.size:
            out[:, here - start] = (e[:, here + ahead] - e[:, here + ahead - 1]) * rate
    return out


def angular_velocity(R, rate, frame="lab"):
    r"""Angular velocity of a segment from its rotation matrices.

    Parameters
    ----------
    R : array_like, shape (frames, 3, 3)
        The segment's rotation matrix in every frame (at least 2), e.g. from
        :func:`~bmc_functions.svdt`. A matrix containing NaN is a missing frame.
    rate : float
        Sampling rate in Hz (frames per second), > 0.
    frame : {'lab', 'local'}, optional
        Express the angular velocity in the lab (fixed) frame, from :math:`\dot R R^T`
        (default), or in the segment's own (moving) frame, from :math:`R^T \dot R`.

    Returns
    -------
    omega : ndarray, shape (frames, 3)
        Angular velocity in rad/s. NaN in a missing frame, and in a frame whose two
        neighbours are both missing (or absent); see Notes.

    Raises
    ------
    TypeError
        If `rate` is not a number, or `frame` is not a string.
    ValueError
        If `R` is not of shape (frames, 3, 3), has fewer than 2 frames, contains
        infinite values or a matrix that is not a rotation (orthonormal within
        ``ORTHONORMAL_ATOL = 1e-6``, det = +1); if `rate` is not positive and finite;
        if `frame` is not 'lab' or 'local'.

    Warns
    -----
    RuntimeWarning
        Once per call, when consecutive frames turn by more than
        ``MAX_FRAME_ROTATION`` (30 degrees): the estimate, sin(angle) * rate, is 4.5 % or
        more low, and above 90 degrees per frame a turn cannot be told from 180 degrees
        minus it (aliasing: 150 degrees per frame at 100 Hz, 262 rad/s, reads as
        50 rad/s).

    Notes
    -----
    Differentiating :math:`R R^T = I` gives :math:`\dot R R^T + R \dot R^T = 0`: the
    matrix :math:`\Omega = \dot R R^T` is skew-symmetric, :math:`\Omega = [\omega]_\times`,
    and :math:`\omega` is the angular velocity in the lab frame; in the segment's frame it
    is :math:`\omega' = R^T \omega`, with :math:`[\omega']_\times = R^T \dot R`.

    :math:`\dot R` is estimated by central differences, :math:`(R_{k+1} - R_{k-1})/(2h)`
    with :math:`h = 1/\text{rate}`, and by one-sided differences
    (:math:`(R_{k+1} - R_k)/h` or :math:`(R_k - R_{k-1})/h`) at the first and last frames
    and next to a missing frame. The estimated :math:`\dot R R^T` is not exactly
    skew-symmetric; :math:`\omega` is taken from its skew-symmetric part.

    *Accuracy.* For a rotation about a fixed axis at a constant rate :math:`\omega`,
    both differences give exactly :math:`\sin(\omega h)/h`: a relative error of
    :math:`(\omega h)^2/6` (0.17 % at 10 rad/s sampled at 100 Hz). In general the
    central difference has an error of order :math:`h^2` and the one-sided difference
    an error of order :math:`h` (about :math:`h\,\dot\omega/2` for a fixed axis). Noise
    in R is amplified by about :math:`\text{rate}/\sqrt 2`: filter the markers (or R)
    before differentiating real data.

    References
    ----------
    .. [1] Zatsiorsky VM (1998) Kinematics of Human Motion. Human Kinetics, ch. 1.
    .. [2] Murray RM, Li Z, Sastry SS (1994) A Mathematical Introduction to Robotic
       Manipulation. CRC Press, ch. 2.

    Examples
    --------
    A rotation about z at 2 rad/s, sampled at 100 Hz:

    >>> import numpy as np
    >>> from bmc_functions import angular_velocity, rot_z
    >>> R = rot_z(2.0 * np.arange(5) / 100)
    >>> print(np.round(angular_velocity(R, 100), 4) + 0.0)
    [[0.     0.     1.9999]
     [0.     0.     1.9999]
     [0.     0.     1.9999]
     [0.     0.     1.9999]
     [0.     0.     1.9999]]
    """
    R = _check_trial(R)
    rate = _check_rate(rate)
    check_choice(frame, "frame", ("lab", "local"))
    e = matrix_rows(R)                            # (9, frames): one pass per entry
    omega = _omega_of_rows(e, rate, frame)
    warn_fast_turns(_turns(e))                                   # NaN next to a gap
    return omega


def warn_fast_turns(turn):
    """The warning of :func:`angular_velocity` for the `turn` (radians, NaN ignored) of
    :func:`consecutive_turns` above :data:`MAX_FRAME_ROTATION`; nothing if there is none.
    For a caller of :func:`unchecked_angular_velocity` that warns rather than flags."""
    fast = turn > MAX_FRAME_ROTATION
    shortfall = 100 * (1 - np.sin(MAX_FRAME_ROTATION) / MAX_FRAME_ROTATION)
    warn_frames(int(np.count_nonzero(fast)), turn.size,
                f"(pairs of consecutive frames) rotate by more than "
                f"{np.degrees(MAX_FRAME_ROTATION):.0f} degrees (up to "
                f"{np.degrees(np.nanmax(turn)) if fast.any() else 0:.0f}): the difference "
                f"estimate gives sin(angle) * rate, {shortfall:.0f}% or more below the true "
                f"speed, and above 90 degrees per frame the rotation is aliased (its true "
                f"size cannot be known). Sample faster")


def _omega_of_rows(e, rate, frame, axis=-1):
    """:func:`angular_velocity` (frames, 3) from the (9, frames) :func:`matrix_rows` of R
    and the rate, both valid: its differences, without its checks and warning. With
    ``axis=0`` its (3, frames) rows, returned as their (frames, 3) transpose (a view).
    Central differences everywhere, one-sided ones at the ends and gap edges; computed
    a block of :data:`_OMEGA_BLOCK` frames at a time."""
    valid = ~np.isnan(e.sum(axis=0))        # a NaN entry (rotations have no infinity)
    has_prev = np.zeros_like(valid)
    has_next = np.zeros_like(valid)
    has_prev[1:] = valid[:-1]
    has_next[:-1] = valid[1:]
    one_sided = ~(has_prev & has_next)
    forward = np.flatnonzero(one_sided & has_next)
    backward = np.flatnonzero(one_sided & ~has_next & has_prev)
    frames = e.shape[1]
    omega = np.empty((3, frames), dtype=_float_type(e))
    work = np.empty((11, min(frames, _OMEGA_BLOCK)), dtype=omega.dtype)   # a block's R_dot, scratch
    for start in range(0, frames, _OMEGA_BLOCK):
        block = slice(start, start + _OMEGA_BLOCK)
        w = work[:, :len(omega[0, block])]
        _omega_rows(e[:, block], _rate_rows(e, w[:9], start, rate, forward, backward),
                    frame, omega[:, block], w[9:])
    omega[:, ~valid | ~(has_prev | has_next)] = np.nan
    return omega.T if axis == 0 else np.ascontiguousarray(omega.T)


def unchecked_angular_velocity(rows, rate):
    """:func:`angular_velocity` in the lab frame of rotation matrices given as their
    (9, frames) :func:`matrix_rows` (``rows[3 * i + j]`` = :math:`R_{ij}`; 2 frames or
    more) and a rate that the caller has checked, and whose consecutive frames
    it knows to turn by at most :data:`MAX_FRAME_ROTATION` (or has flagged those that
    do): the same values, without the checks and the warning; (frames, 3), column-major
    (each component's frames contiguous, as :func:`matrix_rows` has them)."""
    return _omega_of_rows(rows, rate, "lab", axis=0)


class HelicalAxis(NamedTuple):
    """A finite helical (screw) axis: a rotation by `angle` about the line through
    `point` with direction `direction`, and a translation `translation` along it.

    Returned by :func:`helical_axis` and :func:`helical_axes`; a named tuple, so it
    unpacks as ``direction, point, angle, translation = axis``.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import helical_axis, rot_x
    >>> R2 = rot_x(40, degrees=True)                  # 40 deg about x, 3 along x
    >>> axis = helical_axis(np.eye(3), np.zeros(3), R2, np.array([3.0, 0, 0]))
    >>> direction, point, angle, translation = axis
    >>> print(direction.round(6) + 0.0, round(float(np.degrees(angle)), 6),
    ...       round(float(translation), 6))
    [1. 0. 0.] 40.0 3.0
    """

    direction: np.ndarray
    """Unit direction n, shape (..., 3); the rotation is positive (right hand) about n."""
    point: np.ndarray
    """A point s on the axis, shape (..., 3), in the coordinates of t1 and t2."""
    angle: np.ndarray
    """Rotation angle phi about the axis, radians in [0, pi], shape (...)."""
    translation: np.ndarray
    """Translation along the axis, n . d, in the units of t, shape (...)."""


def helical_axis(R1, t1, R2, t2, *, point=None, min_angle=MIN_HELICAL_ANGLE):
    r"""Finite helical axis of the displacement of a segment from one pose to another.

    Parameters
    ----------
    R1, t1 : array_like, shapes (..., 3, 3) and (..., 3)
        The first pose: ``p = R1 @ p_segment + t1``.
    R2, t2 : array_like, shapes (..., 3, 3) and (..., 3)
        The second pose. Leading axes of the four arguments broadcast (pairs of frames).
        For the motion of one segment relative to another (the shank in the thigh's
        frame), pass the relative poses ``R_thigh.T @ R_shank`` and
        ``R_thigh.T @ (t_shank - t_thigh)``.
    point : array_like, shape (..., 3), optional
        Return the point of the axis nearest this point. Default: nearest the origin.
    min_angle : float, keyword-only
        Smallest rotation angle (radians, >= 0) for which the axis is reported; below
        it `direction`, `point` and `translation` are NaN. Default
        ``MIN_HELICAL_ANGLE`` = 5 degrees. Use 0 only for noise-free data.

    Returns
    -------
    HelicalAxis
        Named tuple ``(direction, point, angle, translation)``: unit direction
        :math:`\mathbf n` (..., 3), point :math:`\mathbf s` (..., 3), rotation angle
        :math:`\varphi` (...) in :math:`[0, \pi]`, translation along the axis
        :math:`\tau` (...). NaN where an input contains NaN.

    Raises
    ------
    TypeError
        If `min_angle` is not a number.
    ValueError
        If a shape is wrong or the shapes do not broadcast, a value is infinite, a
        matrix is not a rotation, or `min_angle` is not in :math:`[0, \pi)`.

    Warns
    -----
    RuntimeWarning
        Once per call, with the number of pairs that rotate less than `min_angle`.

    Notes
    -----
    Chasles' theorem: every rigid displacement is a screw motion, a rotation
    :math:`\varphi` about a line (direction :math:`\mathbf n` through :math:`\mathbf s`)
    and a translation :math:`\tau` along it. The displacement takes a point from
    :math:`\mathbf p_1` to :math:`\mathbf p_2 = R\mathbf p_1 + \mathbf d` with
    :math:`R = R_2 R_1^T` and :math:`\mathbf d = \mathbf t_2 - R\,\mathbf t_1`. From
    :math:`R` (Spoor & Veldpaus 1980): :math:`2\sin\varphi\,\mathbf n` is the vector of
    :math:`R - R^T` and :math:`2\cos\varphi = \operatorname{tr}R - 1`; above 90 degrees
    :math:`\mathbf n` is taken from the symmetric part,
    :math:`R + R^T + (1 - \operatorname{tr}R) I = 2(1-\cos\varphi)\,\mathbf n\mathbf n^T`,
    which stays accurate up to 180 degrees. Then :math:`\tau = \mathbf n\cdot\mathbf d`
    and, with :math:`\mathbf u = \mathbf d - \tau\mathbf n`, the point of the axis nearest
    the origin solves :math:`(I - R)\mathbf s = \mathbf u`, :math:`\mathbf s\perp\mathbf n`:

    .. math:: \mathbf s = \tfrac12\left(\mathbf u
              + \cot\tfrac{\varphi}{2}\;\mathbf n\times\mathbf u\right).

    *Why a minimum angle.* An orientation error :math:`\delta\theta` in the poses tilts
    the axis by about :math:`\delta\theta/\varphi` (it is a small rotation added to a
    rotation of size :math:`\varphi`), and :math:`\cot(\varphi/2) \approx 2/\varphi`
    multiplies the errors of :math:`\mathbf d` in :math:`\mathbf s`: noise is amplified
    as :math:`1/\varphi` (Woltring et al. 1985). At :math:`\varphi = 0` the axis does not
    exist. With a typical cluster's orientation error of 0.3-0.5 degrees per pose, 5
    degrees keeps the direction error below about 10 degrees; below `min_angle` NaN is
    returned rather than a wild axis.

    References
    ----------
    .. [1] Spoor CW, Veldpaus FE (1980) Rigid body motion calculated from spatial
       co-ordinates of markers. J Biomech 13:391-393.
    .. [2] Woltring HJ, Huiskes R, de Lange A, Veldpaus FE (1985) Finite centroid and
       helical axis estimation from noisy landmark measurements in the study of human
       joint kinematics. J Biomech 18:379-389.

    Examples
    --------
    A rotation by 90 degrees about the vertical line through (1, 0, 0), with a
    translation of 2 along it:

    >>> import numpy as np
    >>> from bmc_functions import helical_axis, rot_z
    >>> R2 = rot_z(90, degrees=True)
    >>> t2 = np.array([1.0, 0, 0]) - R2 @ [1.0, 0, 0] + [0, 0, 2]
    >>> axis = helical_axis(np.eye(3), np.zeros(3), R2, t2)
    >>> print(axis.direction.round(6) + 0.0, axis.point.round(6) + 0.0)
    [0. 0. 1.] [1. 0. 0.]
    >>> print(round(float(np.degrees(axis.angle)), 6), round(float(axis.translation), 6))
    90.0 2.0
    """
    R1 = check_rotation_matrix(R1, "R1")
    R2 = check_rotation_matrix(R2, "R2")
    t1 = check_vectors(t1, "t1")
    t2 = check_vectors(t2, "t2")
    if point is not None:
        point = check_vectors(point, "point")
    min_angle = _check_angle(min_angle, "min_angle", 0.0, "[0, pi)")
    try:
        shape = np.broadcast_shapes(R1.shape[:-2], t1.shape[:-1], R2.shape[:-2],
                                    t2.shape[:-1],
                                    () if point is None else point.shape[:-1])
    except ValueError:
        raise ValueError(f"the leading axes of R1, t1, R2, t2 (and point) must broadcast; "
                         f"got shapes {R1.shape}, {t1.shape}, {R2.shape}, {t2.shape}"
                         + ("" if point is None else f", {point.shape}")) from None
    return _screw(R1, t1, R2, t2, point, min_angle, shape)


def _screw(R1, t1, R2, t2, point, min_angle, shape, what="pairs of poses"):
    """The helical axis of (R1, t1) -> (R2, t2), inputs already checked."""
    R = R2 @ np.swapaxes(R1, -1, -2)
    d = t2 - np.einsum("...ij,...j->...i", R, t1)
    R = np.broadcast_to(R, shape + (3, 3))
    d = np.broadcast_to(d, shape + (3,))
    r = _vee_skew(R)                                     # sin(phi) n
    trace = R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2]
    angle = unchecked_rotation_angle(R)
    with np.errstate(invalid="ignore", divide="ignore"):
        n = r / np.linalg.norm(r, axis=-1, keepdims=True)
        large = angle > 0.5 * np.pi
        if large.any():
            # 2 (1 - cos phi) n n^T: its column with the largest diagonal entry is the
            # best-conditioned multiple of n; its sign is that of sin(phi) n.
            B = R[large] + np.swapaxes(R[large], -1, -2)
            B = B + (1.0 - trace[large])[:, None, None] * np.eye(3)
            j = np.argmax(np.diagonal(B, axis1=-2, axis2=-1), axis=-1)
            col = np.take_along_axis(B, j[:, None, None], axis=-1)[..., 0]
            col /= np.linalg.norm(col, axis=-1, keepdims=True)
            sign = np.where(np.einsum("fi,fi->f", col, r[large]) < 0, -1.0, 1.0)
            n[large] = sign[:, None] * col
        tau = np.einsum("...i,...i->...", n, d)
        u = d - tau[..., None] * n
        s = 0.5 * (u + (1.0 / np.tan(0.5 * angle))[..., None] * np.cross(n, u))
    if point is not None:
        s = s + np.einsum("...i,...i->...", point - s, n)[..., None] * n
    small = angle < min_angle
    n = np.where(small[..., None], np.nan, n)
    s = np.where(small[..., None], np.nan, s)
    tau = np.where(small, np.nan, tau)
    warn_frames(int(np.count_nonzero(small)), small.size,
                f"({what}) rotate less than min_angle = {np.degrees(min_angle):.3g} "
                "degrees; their helical axis (direction, point, translation) is NaN")
    return HelicalAxis(n, s, angle, tau)


def helical_axes(R, t, *, step=None, angle_step=None, point=None,
                 min_angle=MIN_HELICAL_ANGLE):
    r"""The finite helical axes of a trial, at a fixed frame step or angle increment.

    Parameters
    ----------
    R : array_like, shape (frames, 3, 3)
        The segment's rotation matrices (or the relative rotations of a joint, e.g.
        ``R_thigh.T @ R_shank``), at least 2 frames. NaN marks a missing frame.
    t : array_like, shape (frames, 3)
        The matching origins (relative positions for a joint).
    step : int, keyword-only
        Pair every frame k with frame k + step (a sliding window: one axis per frame;
        ``[::step]`` of the result gives non-overlapping steps).
    angle_step : float, keyword-only
        Instead of `step`: start at the first frame, pair it with the first later frame
        that has rotated by at least `angle_step` radians from it, continue from there:
        the sequence of axes, each for a rotation of about `angle_step`.
    point : array_like, shape (3,), optional
        Points on the axes nearest this point (default the origin), see
        :func:`helical_axis`.
    min_angle : float, keyword-only
        As in :func:`helical_axis`; `angle_step` must be at least `min_angle`.

    Returns
    -------
    axes : HelicalAxis
        Fields of shape (m, 3) or (m,), one per pair.
    frames : ndarray of int, shape (m, 2)
        The frame indices (from 0) of each pair.

    Raises
    ------
    TypeError
        If `step` is not an integer, or `angle_step` or `min_angle` is not a number.
    ValueError
        If `R` or `t` has a wrong shape or fewer than 2 frames, their frame counts
        differ, a matrix is not a rotation, a value is infinite; if not exactly one of
        `step` and `angle_step` is given, `step` is not in [1, frames - 1], or
        `angle_step` is not in [`min_angle`, pi).

    Warns
    -----
    RuntimeWarning
        With `step`: once per call, the number of pairs that rotate less than
        `min_angle` (their axes are NaN).

    Notes
    -----
    With `angle_step` the search loops over the axes found, not over frames: from each
    start frame, the angles to the following frames are computed in windows that double
    until one reaches `angle_step`, so each frame is compared a bounded number of times
    and the time is linear in the number of frames. Frames with NaN are skipped.

    Examples
    --------
    A knee-like rotation about a fixed axis (x, through (0, 0, -50)) by 2 degrees per
    frame:

    >>> import numpy as np
    >>> from bmc_functions import helical_axes, rot_x
    >>> R = rot_x(np.radians(2.0 * np.arange(30)))
    >>> c = np.array([0.0, 0, -50])
    >>> t = c - R @ c
    >>> axes, frames = helical_axes(R, t, angle_step=np.radians(9.9))
    >>> print(frames.tolist())
    [[0, 5], [5, 10], [10, 15], [15, 20], [20, 25]]
    >>> print(np.round(axes.direction[0], 6) + 0.0, np.round(axes.point[0], 6) + 0.0)
    [1. 0. 0.] [  0.   0. -50.]
    """
    R = _check_trial(R)
    t = check_vectors(t, "t")
    if t.ndim != 2 or t.shape[0] != R.shape[0]:
        raise ValueError(f"t must have shape (frames, 3) with the frames of R "
                         f"({R.shape[0]}); got shape {t.shape}")
    if point is not None:
        point = check_vectors(point, "point", allow_nan=False)
        if point.shape != (3,):
            raise ValueError(f"point must have shape (3,); got shape {point.shape}")
    min_angle = _check_angle(min_angle, "min_angle", 0.0, "[0, pi)")
    F = R.shape[0]
    if angle_step is not None:      # its type first: 'a' is no sign of a missing step
        angle_step = _check_angle(angle_step, "angle_step", min_angle,
                                  f"[min_angle, pi) = [{min_angle:.4g}, {np.pi:.4g})")
    if (step is None) == (angle_step is None):
        raise ValueError("give exactly one of step (frames between the two poses) and "
                         f"angle_step (radians); got step={step!r}, angle_step={angle_step!r}")
    if step is not None:
        step = check_scalar(step, "step", "an integer number of frames", integer=True)
        if not 1 <= step <= F - 1:
            raise ValueError(f"step must be between 1 and frames - 1 = {F - 1}; got {step}")
        first = np.arange(F - step)
        frames = np.stack([first, first + step], axis=1)
        axes = _screw(R[frames[:, 0]], t[frames[:, 0]], R[frames[:, 1]], t[frames[:, 1]],
                      point, min_angle, (len(frames),))
        return axes, frames
    valid = np.flatnonzero(~np.isnan(R).any(axis=(1, 2)) & ~np.isnan(t).any(axis=1))
    pairs = []
    k = 0                       # position of the current start frame in `valid`
    width = 8                   # frames searched at once; grows with the steps found
    while k < valid.size - 1:   # one iteration per axis found (or window), not per frame
        i = valid[k]
        # the first later frame that has turned by angle_step, searched in windows that
        # double until it is found: each frame is looked at a bounded number of times,
        # so the search is linear in the number of frames (not quadratic)
        stop = k + 1
        found = None
        while stop < valid.size:
            start, stop = stop, min(valid.size, stop + width)
            angle = rotation_angle(R[valid[start:stop]] @ R[i].T)
            reached = np.flatnonzero(angle >= angle_step)
            if reached.size:
                found = start + reached[0]
                break
            width *= 2
        if found is None:
            break
        pairs.append((i, valid[found]))
        width = max(8, 2 * (found - k))
        k = found
    frames = np.array(pairs, dtype=int).reshape(-1, 2)
    axes = _screw(R[frames[:, 0]], t[frames[:, 0]], R[frames[:, 1]], t[frames[:, 1]],
                  point, min_angle, (len(frames),))
    return axes, frames
