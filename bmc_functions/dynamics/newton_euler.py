r"""Newton-Euler inverse dynamics of a chain of segments, from the distal end up.

Arrays in, arrays out, SI units (m, kg, s; N, N m, W), frames on the first axis,
vectorized over frames (a loop over the few segments of the chain only). The joint
reaction force and the net joint moment are those *acting on the distal segment* of each
joint, from the proximal one (Winter 2009; OpenSim's inverse dynamics reports the same,
as generalized forces): an "internal" moment, the one the muscles and ligaments about
the joint exert on the distal segment.
"""

from typing import NamedTuple

import numpy as np

from .._checks import (ArgumentTypeError, as_float_array, check_one_or_per_frame,
                       check_rotation_matrix, check_vectors)
from ..markers.filtering import derivative
from ..rigid_body.motion import angular_velocity, unchecked_angular_velocity
from ..rigid_body.rotations import cross_rows, dot_rows
from .segment_parameters import MAX_SEGMENT_LENGTH

#: Standard acceleration of gravity (m/s²; CGPM 1901), OpenSim's default magnitude.
STANDARD_GRAVITY = 9.80665

#: Default gravity vector: the ISB global frame has its y axis vertical, upwards (Wu &
#: Cavanagh 1995), as the package's TRC trials do. Give ``gravity=`` for a z-up lab.
GRAVITY_Y_UP = (0.0, -STANDARD_GRAVITY, 0.0)


class SegmentMotion(NamedTuple):
    """A segment's motion in the lab: angular velocity (rad/s) and acceleration (rad/s²),
    acceleration of its centre of mass (m/s²); each (frames, 3)."""

    omega: np.ndarray
    alpha: np.ndarray
    acceleration: np.ndarray


class JointLoads(NamedTuple):
    """What :func:`inverse_dynamics` returns, one row per joint (the proximal joint of
    each segment of the chain, distal first)."""

    force: np.ndarray
    """Joint reaction force (N) on the distal segment, in the lab frame; shape
    (joints, frames, 3)."""
    moment: np.ndarray
    """Net joint moment (N m) on the distal segment about the joint centre, in the lab
    frame; shape (joints, frames, 3)."""
    force_local: np.ndarray
    """The force expressed in the frame given by `express_in` (by default the distal
    segment's own frame): components along that frame's x, y, z axes."""
    moment_local: np.ndarray
    """The moment expressed in the same frame as `force_local`."""
    power: np.ndarray
    """Joint power (W): moment . (omega_distal - omega_proximal); shape (joints, frames)."""


def segment_motion(R, com, rate):
    r"""Angular velocity, angular acceleration and centre-of-mass acceleration of a segment.

    Parameters
    ----------
    R : array_like, shape (frames, 3, 3)
        Segment frame in every frame (at least 3).
    com : array_like, shape (frames, 3)
        Centre of mass in the lab (m).
    rate : float
        Sampling rate (Hz).

    Returns
    -------
    SegmentMotion
        In the lab frame. NaN where `R` or `com` is NaN (and next to it, as the differences
        need).

    Notes
    -----
    :math:`\omega` from :math:`\dot R R^T` (:func:`~bmc_functions.angular_velocity`,
    central differences of :math:`R`), :math:`\alpha = \dot\omega` and
    :math:`a = \ddot c` by central differences (:func:`~bmc_functions.derivative`), each
    with an error of order :math:`h^2`. Differences amplify noise: filter the markers
    first.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import rot_z, segment_motion
    >>> t = np.arange(5) / 100
    >>> motion = segment_motion(rot_z(2 * t), np.c_[t ** 2, 0 * t, 0 * t], 100)
    >>> print(motion.omega[2].round(4) + 0.0, motion.acceleration[2] + 0.0)
    [0.     0.     1.9999] [2. 0. 0.]
    """
    omega = angular_velocity(R, rate)
    com = check_vectors(com, "com")
    if com.shape != (len(omega), 3):
        raise ValueError(f"com must have shape (frames, 3) = {(len(omega), 3)}, one point "
                         f"per frame of R; got {com.shape}")
    return SegmentMotion(omega, derivative(omega, rate),
                         derivative(com, rate, order=2))


def _chain(name, values, count, *shapes):
    """`values` as a list of `count` float arrays, each of one of `shapes`."""
    if isinstance(values, (str, bytes, dict)) or not hasattr(values, "__len__"):
        raise ArgumentTypeError(f"{name} must be a sequence of arrays, one per segment; "
                                f"got {type(values).__name__}")
    if len(values) != count:
        raise ValueError(f"{name} must give one entry per segment ({count}, distal "
                         f"first, as R); got {values!r:.80}")
    arrays = [as_float_array(v, f"{name}[{k}]") for k, v in enumerate(values)]
    for k, array in enumerate(arrays):
        if array.shape not in shapes:
            raise ValueError(f"{name}[{k}] must have shape "
                             f"{' or '.join(map(str, shapes))}; got {array.shape}")
    return arrays


def _cross(a, b):
    """a x b of (..., 3) arrays, component by component (numpy.cross is several times
    slower on long stacks of vectors)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))       # written in place: no stack
    np.subtract(a1 * b2, a2 * b1, out=out[..., 0])
    np.subtract(a2 * b0, a0 * b2, out=out[..., 1])
    np.subtract(a0 * b1, a1 * b0, out=out[..., 2])
    return out


def _external(force, cop, free_moment, frames):
    """The distal load as a wrench about the lab origin: force (F, 3), moment (F, 3)."""
    if force is None:
        return np.zeros((frames, 3)), np.zeros((frames, 3))
    force = check_vectors(force, "force")
    cop = np.zeros(3) if cop is None else check_vectors(cop, "cop")
    free = np.zeros(3) if free_moment is None else check_vectors(free_moment, "free_moment")
    for name, array in (("force", force), ("cop", cop), ("free_moment", free)):
        if array.shape not in ((frames, 3), (3,)):
            raise ValueError(f"{name} must have shape (frames, 3) = {(frames, 3)}; got "
                             f"{array.shape}")
    return _wrench(force, cop, free, frames)


def _wrench(force, cop, free, frames):
    """(force, moment about the lab origin) of a load at `cop`, broadcast to frames."""
    force = np.broadcast_to(force, (frames, 3))
    return force, _cross(cop, force) + free


def _check_mass_inertia(mass, inertia):
    """Each mass finite and > 0 (kg); each inertia tensor symmetric where it is finite."""
    bad = [k for k, m in enumerate(mass) if not np.isfinite(m) or m <= 0]
    if bad:
        raise ValueError(f"mass must hold finite masses > 0 (kg); got "
                         f"{[mass[k] for k in bad]} at segment(s) {bad}")
    for k, tensor in enumerate(inertia):
        # the three pairs of off-diagonal terms (the diagonal is symmetric by itself)
        asymmetry = np.maximum.reduce([np.abs(tensor[..., i, j] - tensor[..., j, i])
                                       for i, j in ((0, 1), (0, 2), (1, 2))])
        scale = np.maximum.reduce([np.abs(tensor[..., i, j]) for i in range(3)
                                   for j in range(3)])          # NaN if any entry is
        if np.nanmax(asymmetry - 1e-9 * scale - 1e-12, initial=0.0) > 0:
            raise ValueError(f"inertia[{k}] must be symmetric (an inertia tensor); got "
                             f"{np.nanmax(asymmetry):.3g} between off-diagonal terms")


def check_metres(com, joint, force, cop):
    """A ValueError when a segment's centre of mass lies farther from its joint, or the
    ground load's point of application from the distal joint, than any body's segment is
    long (median over frames; :data:`~bmc_functions.dynamics.segment_parameters.
    MAX_SEGMENT_LENGTH`, 2.72 m): positions in mm where metres belong, or a load on a
    plate that is not under the foot. `com`, `joint`: lists of (frames, 3) arrays, distal
    first; `force`, `cop`: (frames, 3) or (3,), or None (no load to check)."""
    pairs = [(f"com[{k}]", f"joint[{k}]", c, j, None)
             for k, (c, j) in enumerate(zip(com, joint))]
    if force is not None and cop is not None:
        force = np.broadcast_to(force, joint[0].shape)
        # |F| > 0 exactly where the sum of its squares is, in any order (squares >= 0)
        loaded = (_squares(force) if force.ndim == 2 else np.linalg.norm(force, axis=-1)) > 0
        pairs.append(("cop", "joint[0]", cop, joint[0], loaded))
    for a, b, first, second, frames in pairs:
        with np.errstate(over="ignore", invalid="ignore"):    # the exact test warns, once
            difference = np.subtract(first, second)           # (in its frames), as it did
        if not _within(difference, frames):
            _check_median(a, b, np.broadcast_to(first, second.shape), second, frames)


def _squares(v):
    """The sum of the squares of the (frames, 3) vectors `v`, column by column."""
    total = np.square(v[:, 0])
    total += np.square(v[:, 1])
    total += np.square(v[:, 2])
    return total


def _within(difference, frames):
    """True if the median length of the finite (frames, 3) `difference` vectors of the
    `frames` (a mask, or None: all) cannot exceed MAX_SEGMENT_LENGTH: more than half of
    them are shorter than it by a margin (1e-9 of it) far above the rounding of their
    squares, and none overflows (their norms finite exactly where these squares are).
    Counting them is several times faster than the median of the norms (a partition
    of every frame), which :func:`_check_median` takes otherwise (and for anything but
    (frames, 3) float64 differences: its own arithmetic)."""
    if difference.ndim != 2 or difference.shape[1] != 3 or difference.dtype != np.float64:
        return False
    with np.errstate(over="ignore"):     # an overflow warns in the exact test, as it did
        squares = _squares(difference)
    if frames is not None:
        squares[~frames] = np.nan
    finite = np.count_nonzero(squares < 1e300)
    if finite + np.count_nonzero(np.isnan(squares)) != len(squares):
        return False                     # an infinite or huge vector: the exact test
    short = np.count_nonzero(squares < (MAX_SEGMENT_LENGTH * (1 - 1e-9)) ** 2)
    # the median is the middle one of the sorted lengths (or the mean of the middle
    # two): at most (finite - 1) // 2 of them longer, it is not longer (none: no median)
    return finite == 0 or finite - short <= (finite - 1) // 2


def _check_median(a, b, first, second, frames):
    """:func:`check_metres`' test of one pair: the median of the finite distances between
    `first` and `second` in `frames` (a mask, or None: all)."""
    if frames is not None:
        first, second = first[frames], second[frames]
    distance = np.linalg.norm(first - second, axis=-1)
    distance = distance[np.isfinite(distance)]
    if distance.size and np.median(distance) > MAX_SEGMENT_LENGTH:
        raise ValueError(f"{a} must be within a segment's length of {b}, in metres "
                         f"(no body's segment is longer than {MAX_SEGMENT_LENGTH:g} m); "
                         f"got {np.median(distance):.4g} apart (median over frames): "
                         f"positions in mm?")


def inverse_dynamics(R, com, joint, mass, inertia, *, rate=None, motion=None, force=None,
                     cop=None, free_moment=None, gravity=GRAVITY_Y_UP, base_omega=None,
                     express_in=None):
    r"""Joint forces, moments and powers of a chain of segments (Newton-Euler, bottom-up).

    Parameters
    ----------
    R : sequence of array_like, shape (frames, 3, 3)
        Each segment's frame (columns: its axes in the lab), the most distal segment first
        (foot, shank, thigh).
    com : sequence of array_like, shape (frames, 3)
        Each segment's centre of mass in the lab (m).
    joint : sequence of array_like, shape (frames, 3)
        Each segment's proximal joint centre in the lab (m): where its joint's force acts
        and about which its moment is taken (ankle, knee, hip).
    mass : sequence of float
        Segment masses (kg).
    inertia : sequence of array_like, shape (3, 3) or (frames, 3, 3)
        Inertia tensors about the centre of mass, in the segment's frame (kg m²).
    rate : float, optional
        Sampling rate (Hz): the motion is then found by differentiation
        (:func:`segment_motion`). Give either `rate` or `motion`.
    motion : sequence of SegmentMotion, optional
        Each segment's motion, if known (a simulation, a filtered estimate).
    force, cop, free_moment : array_like, shape (frames, 3), optional
        The external load on the most distal segment: the force (N) the ground exerts,
        its point of application (centre of pressure, m) and the free moment (N m), all
        in the lab frame. None: no external load (swing). A NaN frame gives NaN joint
        loads in that frame. With `force` given and ``cop=None`` the force acts at the
        lab's origin: `free_moment` is then the load's whole moment about the origin,
        :math:`q \times F + T` (a wrench about the origin, as
        :meth:`LowerLimbModel.kinetics <bmc_functions.LowerLimbModel.kinetics>` passes
        the filtered ground load), and the result is the same as with `cop` = :math:`q`
        and `free_moment` = :math:`T`.
    gravity : array_like, shape (3,) or (frames, 3), optional
        Acceleration of gravity in the lab (m/s²); default (0, -9.80665, 0): y up.
    base_omega : array_like, shape (frames, 3) or (3,), optional
        Angular velocity (lab, rad/s) of the body above the chain (the pelvis), for the
        power of the top joint; default: a fixed base (zero).
    express_in : sequence of array_like, shape (frames, 3, 3), optional
        A frame per joint in which `force_local` and `moment_local` are expressed;
        default: each joint's distal segment (`R`).

    Returns
    -------
    JointLoads
        Forces and moments on the distal segment of each joint, lab and local, and powers.

    Raises
    ------
    ValueError
        If the sequences do not give one entry per segment, a shape disagrees, a matrix
        is not a rotation, neither (or both) of `rate` and `motion` is given, or a
        centre of mass lies farther from its joint (or `cop` from the distal joint, where
        `force` is not zero) than 2.72 m, the height of the tallest person recorded
        (median over frames; positions in mm).

    Notes
    -----
    Segment :math:`i` (mass :math:`m_i`, centre of mass :math:`c_i`, inertia
    :math:`I_i = R_i I_i' R_i^T` in the lab, proximal joint centre :math:`p_i`) carries
    at its distal end the load of the segment below, a force :math:`f_d` and a moment
    :math:`n_d` about the lab origin: for the foot the ground's,
    :math:`f_d = F`, :math:`n_d = q \times F + T` (centre of pressure :math:`q`, free
    moment :math:`T`); for the others the reaction to the joint load below,
    :math:`f_d = -f_{i-1}`, :math:`n_d = -(m_{i-1} + p_{i-1} \times f_{i-1})`. Newton's
    and Euler's equations (the latter about the centre of mass) give the unknown force
    :math:`f_i` and moment :math:`m_i` that the proximal segment exerts at :math:`p_i`:

    .. math::

        m_i a_i &= f_i + f_d + m_i g
        \;\Rightarrow\; f_i = m_i (a_i - g) - f_d, \\
        I_i \alpha_i + \omega_i \times I_i \omega_i &= m_i + (p_i - c_i) \times f_i
            + n_d - c_i \times f_d \\
        \Rightarrow\; m_i &= I_i \alpha_i + \omega_i \times I_i \omega_i
            - (p_i - c_i) \times f_i - n_d + c_i \times f_d,

    with :math:`n_d - c_i \times f_d` the distal load's moment about :math:`c_i`. The
    proximal segment receives :math:`-f_i, -m_i` (Newton's third law), so the joint power,
    the rate of work of the joint moment on the two segments, is
    :math:`P_i = m_i \cdot \omega_i - m_i \cdot \omega_{i+1}
    = m_i \cdot (\omega_i - \omega_{i+1})`: positive when the muscles generate energy
    (concentric), negative when they absorb it. The force's power is left out: the joint
    centres of the two segments are taken to coincide.

    References
    ----------
    .. [1] Winter DA (2009) Biomechanics and Motor Control of Human Movement, 4th ed.
       Wiley, ch. 5 (kinetics: forces and moments of force; link-segment model).
    .. [2] Dumas R, Aissaoui R, de Guise JA (2004) A 3D generic inverse dynamic method
       using wrench notation and quaternion algebra. Comput Methods Biomech Biomed Engin
       7:159-166.

    Examples
    --------
    A 1 kg foot at rest, its centre of mass 0.1 m in front of the ankle, no ground load:
    the ankle holds it with 9.81 N upwards and a moment of 0.98 N m about +z (y up):

    >>> import numpy as np
    >>> from bmc_functions import inverse_dynamics
    >>> R = np.repeat(np.eye(3)[None], 5, axis=0)
    >>> loads = inverse_dynamics([R], [np.tile([0.1, 0, 0], (5, 1))], [np.zeros((5, 3))],
    ...                          [1.0], [np.zeros((3, 3))], rate=100)
    >>> print(loads.force[0, 2].round(4) + 0.0, loads.moment[0, 2].round(4) + 0.0)
    [0.     9.8066 0.    ] [0.     0.     0.9807]
    """
    count = len(R)
    R = [as_float_array(r, f"R[{k}]") for k, r in enumerate(R)]
    if motion is not None:                  # else angular_velocity checks them
        R = [check_rotation_matrix(r, f"R[{k}]") for k, r in enumerate(R)]
    frames = len(R[0]) if count and R[0].ndim == 3 else 0
    if count == 0 or any(r.shape != (frames, 3, 3) for r in R):
        raise ValueError(f"R must be a non-empty sequence of (frames, 3, 3) arrays of the "
                         f"same shape; got {[np.shape(r) for r in R]}")
    com = _chain("com", com, count, (frames, 3))
    joint = _chain("joint", joint, count, (frames, 3))
    inertia = _chain("inertia", inertia, count, (frames, 3, 3), (3, 3))
    mass = [float(m) for m in _chain("mass", mass, count, ())]
    _check_mass_inertia(mass, inertia)
    if (rate is None) == (motion is None):
        raise ValueError("give either rate (the motion is differentiated) or motion; got "
                         + ("neither" if rate is None else "both"))
    if motion is None:
        motion = [segment_motion(r, c, rate) for r, c in zip(R, com)]
    gravity = check_one_or_per_frame(check_vectors(gravity, "gravity", allow_nan=False),
                                     "gravity", frames)
    f_d, n_d = _external(force, cop, free_moment, frames)
    check_metres(com, joint, None if force is None else check_vectors(force, "force"),
                  None if cop is None else check_vectors(cop, "cop"))
    checked = []
    for k in range(count):
        omega, alpha, acceleration = (check_vectors(v, f"motion[{k}]") for v in motion[k])
        if not omega.shape == alpha.shape == acceleration.shape == (frames, 3):
            raise ValueError(f"motion[{k}] must hold three (frames, 3) = {(frames, 3)} "
                             f"arrays; got {omega.shape}, {alpha.shape}, "
                             f"{acceleration.shape}")
        checked.append((omega, alpha, acceleration))
    base_omega = (np.zeros((frames, 3)) if base_omega is None else check_one_or_per_frame(
        check_vectors(base_omega, "base_omega"), "base_omega", frames))
    express = None if express_in is None else _chain("express_in", express_in, count,
                                                      (frames, 3, 3))
    f_d, n_d = _rows(f_d), _rows(n_d)

    def load(block):
        return _part(f_d, block), _part(n_d, block)
    return _solve(R, com, joint, mass, [_tensor_product(i) for i in inertia],
                  checked.__getitem__,          # k -> segment k's checked motion
                  load, gravity, base_omega, express)


def _rows(v, matrices=False):
    """(..., 3) vectors, or (..., 3, 3) `matrices`, as contiguous rows over the frames:
    (3, ...) or (9, ...) (``[3 * i + j]`` = entry ij), with an axis of length 1 for a
    single one (it broadcasts over the frames)."""
    v = np.asarray(v, dtype=float)
    rows = np.ascontiguousarray(np.moveaxis(v.reshape(*v.shape[:-2], 9) if matrices
                                            else v, -1, 0))
    return rows[:, None] if rows.ndim == 1 else rows


def _transposed(e, v, out, scratch):
    """:math:`R^T v` from the (9, frames) rows of R (e[3i + j] = R_ij) and (3, frames) v:
    the three components at once, column j of R times v_j, into `out`; `scratch`: a
    (3, frames) array for the products (no temporaries)."""
    return dot_rows((e[0:3], e[3:6], e[6:9]), v, out, scratch)


def _applied(e, v, out, scratch):
    """:math:`R v` from the (9, frames) rows of R and (3, frames) v, into `out`
    (`scratch` as for :func:`_transposed`)."""
    return dot_rows((e[0::3], e[1::3], e[2::3]), v, out, scratch)


def _tensor_product(inertia):
    """An inertia tensor (3, 3) or (frames, 3, 3) as the (9, 1) or (9, frames) rows
    :func:`_inertia_applied` takes."""
    return _rows(inertia, matrices=True)


def _principal_product(moments):
    """A tensor diagonal in the segment's frame given by its (3, frames) principal
    moments, as :func:`_inertia_applied` takes it: those rows themselves."""
    return moments


def _inertia_applied(inertia, v, out, scratch):
    """I v on (3, frames) rows into `out` (not `v`), for the rows of
    :func:`_tensor_product` (9 rows: nine products) or :func:`_principal_product` (3 rows:
    three products, the zeros off the diagonal add nothing)."""
    if len(inertia) == 3:
        return np.multiply(inertia, v, out=out)
    return _applied(inertia, v, out, scratch)


def _part(rows, block):
    """The frames `block` (a slice) of (k, frames) rows; rows of one frame, (k, 1), as
    they are (they broadcast over the frames)."""
    return rows if rows.shape[-1] == 1 else rows[:, block]


#: Frames per block of :func:`_solve`. Every step of the recursion is per frame, so it runs
#: a block of frames at a time: a block's rows (32 kB each) stay in the cache from one
#: step to the next and one block's scratch rows serve every step, where the rows of a
#: long trial (480 kB at 60,000 frames) would be read from memory again by every step and
#: each temporary be fresh memory (page faults). The same operations on every frame: the
#: same numbers.
_BLOCK = 4096


def _solve(R, com, joint, mass, inertia, motion, load, gravity, base_omega, express):
    """The recursion of :func:`inverse_dynamics` on valid float arrays (its Notes), from
    the distal load up: :class:`JointLoads`. Computed on rows (each vector component,
    each matrix entry a contiguous row over the frames), a segment after the other, a
    block of frames at a time (:data:`_BLOCK`). `R`: (frames, 3, 3) matrices or their
    (9, frames) rows; `inertia`: each segment's rows for :func:`_inertia_applied`;
    `motion`: a function of a segment's index that returns its :class:`SegmentMotion`
    (the unchecked path makes it when the segment's turn comes, and it is dropped after
    it: one segment's motion held at a time, not the chain's); `load`: a function of a block (a slice of frames) that
    returns the distal load there, force and moment about the lab origin as (3, block)
    rows; `express`: None for `R`."""
    g = _rows(gravity)
    R = [r if r.ndim == 2 else _rows(r, matrices=True) for r in R]
    express = R if express is None else [_rows(r, matrices=True) for r in express]
    com, joint = [_rows(c) for c in com], [_rows(p) for p in joint]
    frames = R[0].shape[1]
    loads = np.empty((4, len(R), 3, frames))     # force, moment, local ones: rows
    power = np.empty((len(R), frames))
    work = np.empty((7, 3, min(frames, _BLOCK)))     # one block's scratch rows, reused
    below = None                                     # the omega of the segment below
    for k, e in enumerate(R):
        omega, alpha, acceleration = (_rows(v) for v in motion(k))
        for start in range(0, frames, _BLOCK):
            block = slice(start, start + _BLOCK)
            w = work[..., :min(_BLOCK, frames - start)]      # the block's frames
            f, m = loads[0, k, :, block], loads[1, k, :, block]
            # the distal load: the ground's, or the reaction to the joint load below,
            # -f and -(m + p x f) of the segment below
            distal = load(block) if k == 0 else _reaction(
                loads[0, k - 1, :, block], loads[1, k - 1, :, block],
                joint[k - 1][:, block], w)
            _segment_loads(e[:, block], _part(inertia[k], block),
                           (omega[:, block], alpha[:, block], acceleration[:, block]),
                           com[k][:, block], joint[k][:, block], mass[k], _part(g, block),
                           distal, (f, m), w)
            _transposed(express[k][:, block], f, loads[2, k, :, block], w[0])
            _transposed(express[k][:, block], m, loads[3, k, :, block], w[0])
            if k:                                     # the power of the joint below
                _power(loads[1, k - 1, :, block], below[:, block], omega[:, block],
                       power[k - 1, block], w[1])
        below = omega
        del alpha, acceleration       # made for this segment (unchecked path): freed now
    top = _rows(base_omega)
    for start in range(0, frames, _BLOCK):
        block = slice(start, start + _BLOCK)
        _power(loads[1, -1, :, block], below[:, block], _part(top, block), power[-1, block],
               work[1, :, :min(_BLOCK, frames - start)])
    return JointLoads(*np.swapaxes(loads, 2, 3), power)  # (joints, frames, 3)


def _reaction(f, m, p, work):
    """The load a joint's force `f` and moment `m` (about the lab origin: m + p x f, `p`
    the joint) put on the segment above, -f and -(m + p x f), written into work[5] and
    work[6] (rows (3, block); work[1] and work[0][0] scratch)."""
    np.negative(f, out=work[5])
    np.negative(np.add(m, cross_rows(p, f, work[1], work[0][0]), out=work[6]), out=work[6])
    return work[5], work[6]


def _power(m, omega, omega_above, out, scratch):
    """The joint power m . (omega - omega_above) into `out` (`scratch` (3, block))."""
    np.einsum("if,if->f", m, np.subtract(omega, omega_above, out=scratch), out=out)


def _segment_loads(e, inertia, motion, c, p, mass, g, load, out, work):
    """One segment's joint force f and moment m over a block of frames (the Notes of
    :func:`inverse_dynamics`), written into `out` (f, m), from its rows (`e` its
    matrix's, `motion` omega, alpha, acceleration, `c`, `p` its centre of mass and
    joint) and the distal `load` (f_d, n_d; may be work[5] and work[6]). `work`:
    (7, 3, block) scratch, its first five rows used. Each operation that of the formula
    written with temporaries, in its order: the same numbers."""
    omega, alpha, acceleration = motion
    f_d, n_d = load
    f, m = out
    scratch, u, I_omega, rate_of_momentum, v = work[:5]
    np.multiply(mass, np.subtract(acceleration, g, out=f), out=f)  # f = mass (a - g) - f_d
    f -= f_d
    # I_lab = R I R^T applied as R (I (R^T v)): matrix-vector products only
    _transposed(e, omega, u, scratch)
    _applied(e, _inertia_applied(inertia, u, v, scratch), I_omega, scratch)
    _transposed(e, alpha, u, scratch)
    _applied(e, _inertia_applied(inertia, u, v, scratch), rate_of_momentum, scratch)
    rate_of_momentum += cross_rows(omega, I_omega, u, scratch[0])
    # m = rate_of_momentum - (p - c) x f - n_d + c x f_d
    np.subtract(rate_of_momentum, cross_rows(np.subtract(p, c, out=v), f, u, scratch[0]),
                out=m)
    m -= n_d
    m += cross_rows(c, f_d, u, scratch[0])


def unchecked_inverse_dynamics(R, com, joint, mass, inertia, rate, force, moment, gravity,
                               base_omega):
    """:func:`inverse_dynamics` with `rate`, `force`, ``free_moment=moment`` (the load's
    moment about the lab origin, no `cop`), `gravity` and `base_omega` (all given), for a
    caller whose arguments are already what that function checks: lists of float arrays
    of its shapes (3 frames or more), rotation matrices whose consecutive frames turn
    by at most :data:`~bmc_functions.rigid_body.motion.MAX_FRAME_ROTATION` (or are NaN),
    given as their (9, frames) :func:`~bmc_functions.rigid_body.motion.matrix_rows`,
    masses > 0, inertia tensors diagonal in the segment's frame given as their (3, frames)
    principal moments (:func:`~bmc_functions.dynamics.segment_parameters.principal_moments`),
    metres; `force` and `moment` (frames, 3), or one load for every frame (3,). The same results, without the checks
    and without warnings (:meth:`LowerLimbModel.kinetics
    <bmc_functions.LowerLimbModel.kinetics>` checks its trial once, not per segment)."""
    # each centre of mass as (3, frames) rows once: differentiated as their (frames, 3)
    # transpose (derivative keeps the layout: its acceleration is rows too, not copied
    # into rows by _solve) and handed so to _solve (rows of it again without a copy)
    com = [_rows(c).T for c in com]

    def motion(k):                           # made when _solve comes to the segment
        omega = unchecked_angular_velocity(R[k], rate)
        return SegmentMotion(omega, derivative(omega, rate),
                             derivative(com[k], rate, order=2))
    frames = len(com[0])                     # one load for every frame stretched, as there
    force = np.broadcast_to(force, (frames, 3))
    moment = np.broadcast_to(moment, (frames, 3))

    def load(block):        # _wrench's load, a block at a time: the same products (0 x F:
        f = force[block].T  # NaN where F is, as there) on the block's rows
        return f, np.add(cross_rows(np.zeros((3, 1)), f), moment[block].T)
    return _solve(R, com, joint, mass, [_principal_product(i) for i in inertia], motion,
                  load, gravity, base_omega, None)
