r"""Plug-in Gait's kinetics: hip, knee and ankle forces, moments and powers as Vicon reports them.

The steps, each a function of its own (arrays in, arrays out, frames on the first axis):

1. :func:`plate_sides` - which force plate each foot stood on (:func:`~bmc_functions.
   assign_plates`, or the user's assignment), and the stances no plate measured.
2. :func:`ground_wrench` - each foot's ground load at the marker rate (Vicon's own
   resampling, :func:`~bmc_functions.resample_force_plates`): the force and its moment
   about the plate's centre, zero outside the foot's contacts. (The kinetics average
   each plate only in the frames of its contacts given to a foot: the same numbers.)
3. :func:`cgm_segments` - the foot, tibia and femur of one side: frames, proximal joint
   centres, masses, centres of mass and inertia tensors (:data:`PIG_SEGMENTS`).
4. :func:`cgm_joint_loads` - Newton-Euler from the foot up
   (:func:`~bmc_functions.dynamics.newton_euler.inverse_dynamics`), the results
   expressed in Vicon's components (:data:`VICON_COMPONENTS`) per kg of body mass;
   the powers from Plug-in Gait's own angular velocities (:func:`vicon_angular_velocity`).

What the shared trial (Vicon Nexus 2.6, ``data/real/plug_in_gait/Movement_trial.c3d``)
shows about Vicon's Plug-in Gait, each rule checked against its stored curves
(``tests/test_plug_in_gait_kinetics.py``):

- Segment masses are Dempster's fractions of the body mass (foot 0.0145, shank 0.0465,
  thigh 0.100; Winter 2009, Table 4.1); the shank's and thigh's centres of mass lie
  0.433 of the way from the proximal to the distal joint centre of each frame (knee to
  ankle, hip to knee). The foot's lies on the foot's long axis (:math:`-z`) half a foot
  length from the ankle centre, the foot length being the trial's mean HEE-TOE distance
  less one marker radius (:func:`foot_length`; Vicon draws the trial's foot axes that
  long: 229.0 and 236.4 mm here). A least-squares fit of the stored ankle force in swing
  gives a mass fraction of 0.01453 and the centre of mass 114.8 and 118.8 mm down the
  foot's z axis, within 0.4 mm of the axis (0.5 x 229.0 = 114.5, 0.5 x 236.4 = 118.2).
- The radii of gyration are Winter's numbers *about the proximal end* (foot 0.690,
  shank 0.528, thigh 0.540), used about the centre of mass and about both transverse
  axes, none about the long axis (as pyCGM2 also does); with Winter's radii about the
  centre of mass (0.475, 0.302, 0.323) the swing moments miss Vicon's by up to
  0.043 N m/kg instead of 0.004.
- Velocities and accelerations by central differences of the joint centres and segment
  frames, without filtering.
- The force and moment at each joint are those on the distal segment, expressed in the
  distal segment's frame: ankle in the foot (whose x and z Vicon reverses for the force:
  a turn of 180 degrees about y), knee in the tibia, hip in the femur. Vicon's X is the
  component about the medio-lateral axis (y), positive for an internal hip extensor,
  knee extensor and ankle plantarflexor moment; Y and Z (hip and knee: about x and z;
  ankle: about the foot's -z and x) change sign on the right side
  (:data:`VICON_COMPONENTS`).
- The power is the moment times the relative angular velocity of the two segments
  (the hip's against the pelvis), in W/kg, in the Z component; each segment's angular
  velocity is estimated as Plug-in Gait's BodyBuilder code does it
  (:func:`vicon_angular_velocity`): one off-diagonal element per axis of
  :math:`R_{k-2}^T R_{k+2}`, over two frames either side, not the skew-symmetric part of
  :math:`\dot R R^T` (:func:`~bmc_functions.angular_velocity`). Vicon's own moments times
  these velocities give its stored powers to within 4e-7 W/kg (the file's float32) in all
  315 frames of the six power curves; with :math:`\dot R R^T` they miss by up to 0.054 W/kg RMS
  in stance, with BodyBuilder's rule over one frame either side by 0.033.
- Ground reaction: the plates' loads as the file stores them (Vicon does not re-zero
  them), in the frames of each contact. Vicon's windows begin about 0.15 s before
  the foot loads the plate (the frame after the TOE marker passes the plate's front
  edge, on both plates it used); the few newtons of the unloaded plate in those frames
  are left out here. Nexus used plates 1 (left) and 4 (right) of the shared trial and
  not 2 and 3, although each foot stood on its plate alone with heel, ankle and toe
  markers placed alike on all four (the toe 13 to 37 mm past the front edge on each):
  a per-plate setting, given here by ``plates=``.

References
----------
.. [1] Vicon Motion Systems. Plug-in Gait reference guide: kinetic modelling (Dempster's
   segment parameters, moments on the distal segment in its own frame).
.. [2] Davis RB, Ounpuu S, Tyburski D, Gage JR (1991). A gait analysis data collection and
   reduction technique. Human Movement Science 10, 575-587.
.. [3] Winter DA (2009). Biomechanics and Motor Control of Human Movement, 4th ed.
   Wiley. Table 4.1 (Dempster's segment parameters).
.. [4] Leboeuf F, Baker R, Barré A, Reay J, Jones R, Sangeux M (2019). The conventional
   gait model, an open-source implementation that reproduces the past but prepares for
   the future. Gait & Posture 69, 126-129.
.. [5] pyCGM2, ``pyCGM2/Model/model.py``, ``Segment.getAngularVelocity(method="pig")``:
   Plug-in Gait's BodyBuilder angular velocity, quoted in its docstring as
   ``[dot(NextPosR(:,2), PrevPosR(:,3)); dot(NextPosR(:,3), PrevPosR(:,1));
   dot(NextPosR(:,1), PrevPosR(:,2))] ./ (2*SamplePeriod)``.
"""

from pathlib import Path

import numpy as np
import pandas as pd

from ..._checks import (ArgumentTypeError, check_rotation_matrix, check_scalar, runs_mask,
                        warn)
from ..._threads import one_blas_thread
from ...dynamics.newton_euler import (check_metres, inverse_dynamics,
                                      unchecked_inverse_dynamics)
from ...dynamics.segment_parameters import (DEMPSTER, GYRATION_ABOUT_PROXIMAL, SegmentParameters,
                                            check_body_mass)
from ...files.force_plates import (MIN_CONTACT, assign_plates, loaded_runs,
                                   plate_loads_at_marker_rate, read_force_plates,
                                   resampling_ratio)
from ...rigid_body.motion import consecutive_turns, matrix_rows, warn_fast_turns
from ...rigid_body.rotations import dot_rows, vector_length

#: Acceleration of gravity (m/s²) in the lab: Vicon's labs are z up.
GRAVITY_Z_UP = (0.0, 0.0, -9.80665)

#: Plug-in Gait's segments: Dempster's mass and centre of mass (Winter 2009, Table 4.1,
#: :data:`~bmc_functions.dynamics.segment_parameters.DEMPSTER`) and Winter's radius of
#: gyration about the proximal end (:data:`~bmc_functions.dynamics.segment_parameters.
#: GYRATION_ABOUT_PROXIMAL`), about the segment's two transverse axes (x, y; z is the long
#: axis of every Plug-in Gait segment). The shared trial's stored moments need these radii.
PIG_SEGMENTS = {
    name: SegmentParameters(DEMPSTER[name].mass, DEMPSTER[name].com,
                            (GYRATION_ABOUT_PROXIMAL[name],) * 2 + (0.0,))
    for name in ("foot", "shank", "thigh")}

#: Joints, distal first, and the segment below each (whose frame expresses its loads).
PIG_JOINTS = ("ankle", "knee", "hip")

#: Speed (mm/s) of the midpoint of a foot's HEE and TOE markers under which the foot is
#: taken to stand (on a plate or not) when it stays so for ``MIN_CONTACT`` (0.08 s) or more:
#: in the shared stair descent a standing foot moves at 0-50 mm/s, a swinging one at
#: 1000-3000 mm/s.
STILL_SPEED = 150.0

#: The quantities of each joint and side, in the columns' order.
KINETIC_QUANTITIES = ("moment_x", "moment_y", "moment_z", "force_x", "force_y", "force_z",
                      "power")

#: Vicon's X, Y, Z from the components along the distal segment's x, y, z axes:
#: (indices, signs) per joint, for the left side; the right side's moment Y and Z
#: change sign (:func:`vicon_components`). Found on the shared trial (correlation 0.999
#: or more with every stored curve).
VICON_COMPONENTS = {
    "force": {"ankle": ((0, 1, 2), (-1, 1, -1)), "knee": ((0, 1, 2), (1, 1, 1)),
              "hip": ((0, 1, 2), (1, 1, 1))},
    "moment": {"ankle": ((1, 2, 0), (1, -1, 1)), "knee": ((1, 0, 2), (-1, 1, 1)),
               "hip": ((1, 0, 2), (1, 1, 1))},
}


#: Frames either side over which Plug-in Gait differentiates the segment frames for the
#: joint powers (:func:`vicon_angular_velocity`): the shared trial's powers (120 Hz) need
#: 2, i.e. :math:`R_{k-2}` and :math:`R_{k+2}` (1 or 3 miss them by 0.033 and 0.040 W/kg
#: RMS). Whether Vicon counts frames or time (1/60 s) one trial cannot tell.
VICON_OMEGA_SPAN = 2


def vicon_angular_velocity(R, rate, span=VICON_OMEGA_SPAN):
    r"""A segment's angular velocity (lab frame) as Plug-in Gait computes it for the powers.

    Parameters
    ----------
    R : array_like, shape (frames, 3, 3)
        The segment's frame in every frame (columns: its x, y, z axes in the lab). A
        matrix containing NaN is a missing frame.
    rate : float
        Marker rate (Hz).
    span : int, optional
        Frames either side (:data:`VICON_OMEGA_SPAN`).

    Returns
    -------
    ndarray, shape (frames, 3)
        rad/s, in the lab frame; NaN in the first and last `span` frames and where
        :math:`R_k`, :math:`R_{k-s}` or :math:`R_{k+s}` is missing.

    Raises
    ------
    ValueError
        If `R` is not of shape (frames, 3, 3) or holds a matrix that is not a rotation,
        if `rate` is not positive and finite, or `span` not an integer >= 1.

    Notes
    -----
    Plug-in Gait's BodyBuilder code [1]_ takes from :math:`A_k = R_{k-s}^T R_{k+s}`, the
    turn from frame :math:`k-s` to frame :math:`k+s` in the segment's own axes, one
    off-diagonal element per axis (:math:`y_{k+s}\cdot z_{k-s}`, :math:`z_{k+s}\cdot x_{k-s}`,
    :math:`x_{k+s}\cdot y_{k-s}`):

    .. math::

        \omega'_k = \frac{(A_{zy},\, A_{xz},\, A_{yx})}{2 s h}, \qquad
        \omega_k = R_k\, \omega'_k, \qquad h = 1/\text{rate}.

    For a turn :math:`\theta = 2 s h\, \omega'`, :math:`A = I + [\theta]_\times +
    \tfrac12 (\theta\theta^T - |\theta|^2 I) + O(\theta^3)`, so :math:`A_{zy} = \theta_x
    + \tfrac12\theta_y\theta_z + O(\theta^3)`: the estimate is

    .. math::

        \omega' + s h\, (\omega'_y\omega'_z,\; \omega'_z\omega'_x,\; \omega'_x\omega'_y)
        + O(h^2),

    a bias of first order in :math:`h` that the skew-symmetric part of :math:`A`
    (:func:`~bmc_functions.angular_velocity`) cancels. It depends on the segment's axes
    and reaches a few per cent of a stance power (shank about 2 rad/s about two of its
    axes at 120 Hz: 0.07 rad/s). Vicon's stored powers of the shared trial are its
    moments times these velocities (distal minus proximal) to within 4e-7 W/kg.

    References
    ----------
    .. [1] pyCGM2, ``pyCGM2/Model/model.py``, ``Segment.getAngularVelocity(method="pig")``,
       which quotes Plug-in Gait's BodyBuilder code (with :math:`s = 1`).

    Examples
    --------
    A turn about a fixed axis :math:`n` at :math:`w` rad/s gives
    :math:`A = \cos\varphi\, I + \sin\varphi\, [n]_\times + (1 - \cos\varphi)\, n n^T`,
    :math:`\varphi = 2 s h w`; at a frame where :math:`R_k = I`, :math:`\omega_x =
    (n_x \sin\varphi + n_y n_z (1 - \cos\varphi)) / (2 s h)`, not :math:`w n_x = 0`:

    >>> import numpy as np
    >>> from scipy.spatial.transform import Rotation
    >>> from bmc_functions.models.plug_in_gait.kinetics import vicon_angular_velocity
    >>> n, w, rate = np.array([0.0, 0.6, 0.8]), 3.0, 100.0
    >>> t = (np.arange(5) - 2) / rate                    # R = I at the middle frame
    >>> R = Rotation.from_rotvec(w * t[:, None] * n).as_matrix()
    >>> print(vicon_angular_velocity(R, rate)[2].round(4))
    [0.0863 1.7957 2.3942]
    >>> phi = 2 * 2 * w / rate
    >>> A = np.array([n[1] * n[2] * (1 - np.cos(phi)), n[1] * np.sin(phi), n[2] * np.sin(phi)])
    >>> print((A / (phi / w)).round(4))
    [0.0863 1.7957 2.3942]
    """
    R = check_rotation_matrix(R, "R")
    rate = check_scalar(rate, "rate", "a positive, finite marker rate in Hz", minimum=0,
                        strict=True)
    span = check_scalar(span, "span", "an integer >= 1 (frames either side)", minimum=1,
                        integer=True)
    if R.ndim != 3:
        raise ValueError(f"R must have shape (frames, 3, 3); got shape {R.shape}")
    return _vicon_omega(R, rate, span)


def _vicon_omega(R, rate, span=VICON_OMEGA_SPAN):
    """:func:`vicon_angular_velocity` of frames the model built (rotations by construction,
    the model's own segment and pelvis frames): its arithmetic without its checks."""
    return np.ascontiguousarray(_vicon_omega_rows(matrix_rows(R), rate, span).T)


#: The orders in which ``np.einsum`` added the three products of a dot product over
#: (frames, 3) arrays in the version these functions replaced (from +0, so that a zero sum
#: is +0): one after the other when the three entries are strided (``"fi,fi->f"`` of a
#: column of matrices), the third one added to the first before the second when they are
#: contiguous (``"fij,fj->fi"``: two SIMD lanes of numpy 2.4 on x86-64). Kept so that the
#: numbers did not change with the speed-up; they are fixed orders now, the same on every
#: machine and for every memory layout of R (einsum's order depended on both, so on
#: another machine or for a column-major R the previous version could differ by rounding).
_STRIDED, _CONTIGUOUS = (0, 1, 2), (0, 2, 1)


def _row_products(a, b, out, scratch, order):
    """The dot products of three rows `a` with three rows `b`, frame by frame, added in
    `order` (``_STRIDED`` or ``_CONTIGUOUS``), into `out`: the numbers of the
    ``np.einsum`` on (frames, 3) arrays that they replace (tested, zeros and NaN
    included), in one pass per row where einsum over short strided vectors is several
    times slower. `scratch`: a row."""
    with np.errstate(over="ignore", invalid="ignore"):    # silent, as einsum was
        dot_rows([a[k] for k in order], [b[k] for k in order], out, scratch)
    out += 0.0                                   # einsum's +0 start: -0 becomes +0
    return out


def _vicon_omega_rows(e, rate, span=VICON_OMEGA_SPAN):
    """:func:`vicon_angular_velocity` from the (9, frames) :func:`~bmc_functions.rigid_body.
    motion.matrix_rows` of the frames, as (3, frames) rows: the products of its rows, in
    the orders of the ``np.einsum`` it replaces (:func:`_row_products`)."""
    frames = e.shape[1]
    omega = np.full((3, frames), np.nan)
    if frames <= 2 * span:
        return omega
    before, after, middle = e[:, :-2 * span], e[:, 2 * span:], e[:, span:-span]
    local, scratch = np.empty((3, frames - 2 * span)), np.empty(frames - 2 * span)
    # A_zy = y_{k+s} . z_{k-s}, A_xz = z_{k+s} . x_{k-s}, A_yx = x_{k+s} . y_{k-s}: column
    # i of R is rows i, i + 3, i + 6
    for row, (i, j) in zip(local, ((1, 2), (2, 0), (0, 1))):
        _row_products(after[i::3], before[j::3], row, scratch, _STRIDED)
    for i, row in enumerate(omega[:, span:-span]):           # R_k local: row i of R_k
        _row_products(middle[3 * i:3 * i + 3], local, row, scratch, _CONTIGUOUS)
    omega[:, span:-span] *= rate / (2 * span)
    return omega


def vicon_components(local, quantity, joint, side):
    """Vicon's X, Y, Z of a force or moment given in the distal segment's frame.

    Parameters
    ----------
    local : array_like, shape (frames, 3)
        Components along the distal segment's x, y, z axes.
    quantity : {'force', 'moment'}
    joint : {'ankle', 'knee', 'hip'}
    side : {'right', 'left'}

    Returns
    -------
    ndarray, shape (frames, 3)

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.kinetics import vicon_components
    >>> print(vicon_components(np.array([[1.0, 2.0, 3.0]]), "moment", "knee", "right"))
    [[-2. -1. -3.]]
    """
    index, sign = VICON_COMPONENTS[quantity][joint]
    sign = np.array(sign, float)
    if quantity == "moment" and side == "right":
        sign = sign * np.array([1.0, -1.0, -1.0])
    return np.asarray(local, float)[:, list(index)] * sign


def foot_length(heel, toe, marker_diameter):
    """Plug-in Gait's foot length (m): the trial's mean heel-to-toe marker distance less
    one marker radius.

    Vicon Nexus draws each trial's foot axes this long (``LFOA - LFOO``) and puts the
    foot's centre of mass half of it from the ankle centre: 229.0 and 236.4 mm in the
    shared walk, 236.0 and 239.0 mm in its static trial, each equal to this rule within
    0.05 mm.

    Parameters
    ----------
    heel, toe : array_like, shape (frames, 3)
        HEE and TOE markers (mm).
    marker_diameter : float
        mm.

    Returns
    -------
    float
        m; NaN when HEE is missing in every frame.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.kinetics import foot_length
    >>> print(round(foot_length(np.zeros((2, 3)), [[250.0, 0, 0], [240, 0, 0]], 14.0), 4))
    0.238
    """
    distance = vector_length(np.asarray(toe, float) - np.asarray(heel, float))
    if not np.isfinite(distance).any():
        return np.nan
    return float(np.nanmean(distance) - marker_diameter / 2.0) / 1000.0


def cgm_segments(frames, centres, side, body_mass, *, foot, parameters=None):
    """Foot, tibia and femur of one side for :func:`inverse_dynamics` (SI units).

    Parameters
    ----------
    frames : dict
        :attr:`PlugInGaitTrack.frames` (mm).
    centres : dict
        Joint centre name -> (frames, 3) in mm: ``'LHJC'``, ``'LKJC'``, ``'LAJC'``
        and the right ones.
    side : {'right', 'left'}
    body_mass : float
        kg.
    foot : float
        The foot's length (m, :func:`foot_length`).
    parameters : dict, optional
        Segment ('foot', 'shank', 'thigh') -> :class:`SegmentParameters`; default
        :data:`PIG_SEGMENTS`.

    Returns
    -------
    dict
        ``'R'``, ``'com'`` (m), ``'joint'`` (m), ``'mass'`` (kg), ``'inertia'`` (kg m²,
        about the centre of mass in the segment's frame), ``'length'`` (m, per frame):
        lists, foot first. The shank and thigh are the knee-ankle and hip-knee lines
        of each frame (the centre of mass on it, the length for the inertia); the
        foot's centre of mass is on its long axis (-z) half a foot from the ankle.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.kinetics import cgm_segments
    >>> I = np.repeat(np.eye(3)[None], 2, axis=0)
    >>> frames = {("foot", "left"): (I, None), ("tibia", "left"): (I, None),
    ...           ("femur", "left"): (I, None)}
    >>> centres = {"LHJC": np.tile([0.0, 0, 800], (2, 1)),
    ...            "LKJC": np.tile([0.0, 0, 400], (2, 1)), "LAJC": np.zeros((2, 3))}
    >>> seg = cgm_segments(frames, centres, "left", 80.0, foot=0.2)
    >>> print(seg["com"][0][0], seg["com"][2][0], round(seg["mass"][2], 3))
    [ 0.   0.  -0.1] [0.     0.     0.6268] 8.0
    """
    return _with_tensors(_segment_parts(frames, centres, side, body_mass, foot, parameters))


def _with_tensors(segments):
    """:func:`_segment_parts`' segments as :func:`cgm_segments` gives them: each
    ``'principal'`` (3, frames) as ``'inertia'`` (frames, 3, 3), row i of the identity
    times the principal moment :math:`I_i` (0 off the diagonal, NaN where :math:`I_i` is:
    the numbers of ``m l**2 diag(k**2)``)."""
    # cgm_segments' keys in their order, its arrays row-major (_segment_parts lays out
    # the centres as Newton-Euler's rows)
    out = {key: [np.ascontiguousarray(v) for v in segments[key]] if key in ("joint", "com")
           else segments[key] for key in ("R", "joint", "com", "mass")}
    out["inertia"] = [np.ascontiguousarray(np.moveaxis(principal, 0, -1)[..., None]
                                           * np.eye(3)) for principal in segments["principal"]]
    out["length"] = segments["length"]
    return out


def _segment_parts(frames, centres, side, body_mass, foot, parameters=None):
    """:func:`cgm_segments` with ``'principal'`` in place of ``'inertia'``: each tensor's
    principal moments (diagonal in the segment's frame) as (3, frames) rows,
    :math:`m l^2 k_i^2`, the form Newton-Euler takes them in (the tensors are 5 MB each
    in a 10-minute trial, written and read again for their diagonal otherwise)."""
    table = PIG_SEGMENTS if parameters is None else {**PIG_SEGMENTS, **parameters}
    p = side[0].upper()
    # the joint centres and centres of mass are the (frames, 3) transposes of (3, frames)
    # rows, the layout Newton-Euler computes in (no copy into rows there; elementwise
    # operations, the same numbers in any layout): the centres divided as they are read
    hip, knee, ankle = (np.divide(centres[p + name].T, 1000.0,
                                  out=np.empty((3, len(centres[p + name])))).T
                        for name in ("HJC", "KJC", "AJC"))
    R_foot = frames[("foot", side)][0]
    out = {"R": [R_foot, frames[("tibia", side)][0], frames[("femur", side)][0]],
           "joint": [ankle, knee, hip], "com": [], "mass": [], "principal": [],
           "length": []}
    for name, proximal, distal in (("foot", ankle, None), ("shank", knee, ankle),
                                   ("thigh", hip, knee)):
        seg = table[name]
        if distal is None:     # the foot's centre of mass on its long axis (-z, to the toe)
            length = np.full(len(ankle), float(foot))
            com = np.subtract(proximal, seg.com * length[:, None] * R_foot[..., 2],
                              out=np.empty((3, len(ankle))).T)
        else:
            length = vector_length(distal - proximal)
            com = proximal + seg.com * (distal - proximal)
        mass = seg.mass * body_mass
        out["com"].append(com)
        out["mass"].append(mass)
        out["length"].append(length)
        # (m l^2) k_i^2 (k_i^2 (m l^2): the same product), the tensor's diagonal
        out["principal"].append(np.multiply.outer(np.square(seg.gyration),
                                                  mass * length ** 2))
    return out


def ground_wrench(plates, contacts, side):
    """One foot's ground load at the marker rate, from the plates assigned to it.

    Parameters
    ----------
    plates : pandas.DataFrame
        :func:`~bmc_functions.resample_force_plates` (force N, moment N mm about the
        plate's centre, lab frame; ``attrs['plates']`` with each plate's corners).
    contacts : pandas.DataFrame
        Rows ``plate``, ``side``, ``start``, ``stop`` (s), as
        :func:`~bmc_functions.assign_plates` returns.
    side : {'right', 'left'}

    Returns
    -------
    force : ndarray, shape (frames, 3)
        N, lab; zero outside the foot's contacts.
    point : ndarray, shape (frames, 3)
        The point the moment is about (the loaded plate's centre, m); zero elsewhere.
    moment : ndarray, shape (frames, 3)
        N m about `point`.
    stance : ndarray of bool, shape (frames,)
        The frames of the foot's contacts.

    Examples
    --------
    >>> import warnings
    >>> from bmc_functions import (read_c3d, read_force_plates, resample_force_plates,
    ...                            assign_plates)
    >>> from bmc_functions.examples import example_file
    >>> from bmc_functions.models.plug_in_gait.kinetics import ground_wrench
    >>> path = example_file("plug_in_gait/Movement_trial.c3d")
    >>> raw = read_force_plates(path)
    >>> feet = {"right": ["RHEE", "RTOE"], "left": ["LHEE", "LTOE"]}
    >>> contacts = assign_plates(raw, read_c3d(path), feet)
    >>> force, point, moment, stance = ground_wrench(resample_force_plates(raw),
    ...                                              contacts, "right")
    >>> print(int(stance.sum()), round(float(force[:, 2].max())))
    168 1153
    """
    rows = contacts[contacts["side"] == side]
    loads = plate_loads_at_marker_rate(plates, 1, np.unique(rows["plate"].astype(int)))
    return foot_wrench(plates.index.to_numpy(float), loads, plates.attrs["plates"],
                       contacts, side)


def foot_wrench(time, loads, plates, contacts, side):
    """:func:`ground_wrench` from the plates' loads at the marker rate: `time` (s), `loads`
    plate number -> (force N, moment N mm; (frames, 3) each, lab), `plates` the
    ``attrs['plates']`` of :func:`~bmc_functions.read_force_plates`."""
    force, point, moment = (np.zeros((len(time), 3)) for _ in range(3))
    stance = np.zeros(len(time), dtype=bool)
    rows = contacts[contacts["side"] == side]
    centres = {plate: np.mean(np.asarray(plates[plate - 1]["corners"], float), axis=0) / 1000.0
               for plate in loads}
    # contact by contact, in the order listed: a later contact wins where two overlap
    for plate, first, stop in zip(rows["plate"].to_numpy(int).tolist(),
                                  *_contact_frames(time, rows["start"], rows["stop"])):
        force[first:stop] = loads[plate][0][first:stop]
        moment[first:stop] = loads[plate][1][first:stop] / 1000.0
        point[first:stop] = centres[plate]
        stance[first:stop] = True
    return force, point, moment, stance


def _contact_frames(time, starts, stops):
    """The frames [first, stop) of contacts from `starts` to `stops` (s, both included, to
    1e-9 s) in the ascending `time` (s): ``time[first:stop]`` is each contact."""
    first = np.searchsorted(time, np.asarray(starts, float) - 1e-9, side="left")
    stop = np.searchsorted(time, np.asarray(stops, float) + 1e-9, side="right")
    return first, stop


def _plate_frames(time, contacts):
    """Plate number -> the ascending frames of `time` in its contacts given to a foot."""
    rows = contacts[contacts["side"].notna()]
    first, stop = _contact_frames(time, rows["start"], rows["stop"])
    plates = rows["plate"].to_numpy(int)
    return {plate: np.flatnonzero(runs_mask(len(time), first[plates == plate],
                                            stop[plates == plate]))
            for plate in dict.fromkeys(plates.tolist())}     # in the contacts' order


def _in_contacts(time, starts, stops):
    """Boolean mask of the frames of `time` inside any contact (:func:`_contact_frames`)."""
    return runs_mask(len(time), *_contact_frames(time, starts, stops))


def cgm_joint_loads(segments, wrench, rate, body_mass, side, pelvis_R):
    """Newton-Euler up one leg, in Vicon's components per kg of body mass.

    Parameters
    ----------
    segments : dict
        :func:`cgm_segments`.
    wrench : tuple
        ``(force, point, moment)`` of :func:`ground_wrench` (N, m, N m; lab).
    rate : float
        Marker rate (Hz).
    body_mass : float
        kg.
    side : {'right', 'left'}
    pelvis_R : ndarray, shape (frames, 3, 3)
        The pelvis frame (the hip power is against the pelvis's angular velocity).

    Returns
    -------
    dict
        ``(joint, quantity)`` -> (frames,) array: quantity ``force_x`` ... ``force_z``
        (N/kg), ``moment_x`` ... ``moment_z`` (N m/kg), ``power`` (W/kg), joint
        ``'ankle'``, ``'knee'``, ``'hip'``. The power is the moment on the distal
        segment (lab) dotted with the distal minus the proximal segment's
        :func:`vicon_angular_velocity`: NaN in the first and last
        :data:`VICON_OMEGA_SPAN` frames.

    Examples
    --------
    A leg at rest, its segments vertical (x forward, y left, z up) with no ground load:
    the hip holds the leg's weight, 11 kg of the body's 70, i.e. 1.54 N/kg; the foot's
    centre of mass 0.1 m in front of the ankle pulls it into dorsiflexion (moment X < 0).

    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.kinetics import cgm_joint_loads
    >>> I = np.repeat(np.eye(3)[None], 5, axis=0)
    >>> foot = I @ np.array([[0, 0, -1], [0, 1, 0], [1, 0, 0.0]])   # z backwards
    >>> seg = {"R": [foot, I, I], "mass": [1.0, 3.0, 7.0],
    ...        "joint": [np.tile([0, 0, z], (5, 1)) for z in (0.1, 0.5, 0.9)],
    ...        "com": [np.tile([0.1, 0, 0.05], (5, 1)), np.tile([0, 0, 0.3], (5, 1)),
    ...                np.tile([0, 0, 0.7], (5, 1))],
    ...        "inertia": [np.zeros((3, 3))] * 3}
    >>> zero = np.zeros((5, 3))
    >>> out = cgm_joint_loads(seg, (zero, zero, zero), 100, 70.0, "left", I)
    >>> print(round(out["hip", "force_z"][2], 4), round(out["ankle", "moment_x"][2], 4))
    1.5411 -0.014
    """
    force, point, moment = wrench
    loads = inverse_dynamics(segments["R"], segments["com"], segments["joint"],
                             segments["mass"], segments["inertia"], rate=rate,
                             force=force, cop=point, free_moment=moment,
                             gravity=GRAVITY_Z_UP)
    omegas = [vicon_angular_velocity(R, rate).T for R in [*segments["R"], pelvis_R]]
    return _in_vicon_components(loads, omegas, body_mass, side)


def _model_joint_loads(segments, wrench, rate, body_mass, side, pelvis_R):
    """:func:`cgm_joint_loads` of the segments :func:`_segment_parts` built from the
    model's own frames (rotations by construction, metres, masses > 0, the inertia's
    principal moments in each segment's frame): the same recursion and numbers without
    re-checking them
    (:func:`~bmc_functions.dynamics.newton_euler.unchecked_inverse_dynamics`); the
    ground load's point is checked as there (it depends on the plates), and a segment
    turning too fast between frames gets the same warning."""
    if len(pelvis_R) < 3:                  # too short to differentiate: its usual error
        return cgm_joint_loads(_with_tensors(segments), wrench, rate, body_mass, side,
                               pelvis_R)
    force, point, moment = wrench
    # where the load acts depends on the plates (their corners, plates=), not on the model
    check_metres(segments["com"], segments["joint"], force, point)
    rows = [matrix_rows(R) for R in segments["R"]]
    for e in rows:
        warn_fast_turns(consecutive_turns(e))
    loads = unchecked_inverse_dynamics(
        rows, segments["com"], segments["joint"], segments["mass"], segments["principal"],
        rate, force,
        _about_origin(point, force, moment), np.asarray(GRAVITY_Z_UP),
        np.zeros(3))       # base: the loads' own powers go unused (Vicon's, below)
    omegas = [_vicon_omega_rows(e, rate) for e in [*rows, matrix_rows(pelvis_R)]]
    return _in_vicon_components(loads, omegas, body_mass, side)


def _about_origin(point, force, moment):
    """The moment about the lab's origin, point x force + moment, of (frames, 3) arrays:
    numpy.cross's products and differences (a1 b2 - a2 b1, ...), one column at a time
    into the result (numpy.cross's temporaries take three times as long): the same
    numbers."""
    out, scratch = np.empty(np.shape(force)), np.empty(len(force))
    for i, (j, k) in enumerate(((1, 2), (2, 0), (0, 1))):
        np.multiply(point[:, j], force[:, k], out=out[:, i])
        out[:, i] -= np.multiply(point[:, k], force[:, j], out=scratch)
    out += moment
    return out


def _in_vicon_components(loads, omegas, body_mass, side):
    """The :class:`~bmc_functions.dynamics.newton_euler.JointLoads` of one leg as
    :func:`cgm_joint_loads` returns them; `omegas`: Vicon's angular velocities of the
    foot, tibia, femur and pelvis as (3, frames) rows. :func:`vicon_components` and the
    power's dot product computed on the loads' own rows (each component's frames
    contiguous), one array per column: the same products, in the same order."""
    out = {}
    scratch = np.empty(loads.power.shape[-1])
    for j, joint in enumerate(PIG_JOINTS):
        for quantity, local in (("force", loads.force_local[j]),
                                ("moment", loads.moment_local[j])):
            index, sign = VICON_COMPONENTS[quantity][joint]
            if quantity == "moment" and side == "right":       # as vicon_components
                sign = np.multiply(sign, (1.0, -1.0, -1.0))
            for k, axis in enumerate("xyz"):
                # (x sign) / mass as x / (sign mass): a sign of +-1 is exact and a
                # quotient's rounding symmetric, the same number in one pass
                out[joint, f"{quantity}_{axis}"] = np.divide(local.T[index[k]],
                                                             float(sign[k]) * body_mass)
        # the recursion's moments are the transposes of (3, frames) rows: einsum summed
        # their strided (frames, 3) entries one after the other (_STRIDED)
        power = _row_products(loads.moment[j].T, np.subtract(omegas[j], omegas[j + 1]),
                              np.empty_like(scratch), scratch, _STRIDED)
        power /= body_mass
        out[joint, "power"] = power
    return out


#: Relative difference between a `body_mass` given to :meth:`PlugInGait.kinetics` and the
#: subject's ``Bodymass`` beyond which they contradict each other (one warning naming
#: both): a body's mass changes by a few percent between sessions, a mass in pounds by
#: 120 %.
BODY_MASS_AGREEMENT = 0.1

#: Kilograms per pound (avoirdupois; exact by the 1959 international yard and pound).
KG_PER_POUND = 0.45359237


def body_mass_of(subject, body_mass):
    """The body mass (kg) to use: `body_mass` if given, else the subject's ``Bodymass``;
    one warning when both are given and differ by more than :data:`BODY_MASS_AGREEMENT`."""
    bodymass = subject.get("Bodymass")
    if body_mass is None:
        if bodymass is None:
            raise ValueError("the subject gives no Bodymass (kg; a .vsk parameter, the C3D's "
                             "PROCESSING:Bodymass or a dict entry): give it to plug_in_gait "
                             "or pass body_mass= to kinetics")
        return check_body_mass(bodymass, "Bodymass")
    body_mass = check_body_mass(body_mass)
    if bodymass is not None and abs(body_mass - bodymass) > BODY_MASS_AGREEMENT * bodymass:
        pounds = abs(body_mass * KG_PER_POUND - bodymass) <= BODY_MASS_AGREEMENT * bodymass
        warn(f"body_mass={body_mass:g} kg contradicts the subject's Bodymass={bodymass:g} kg "
             f"(they differ by more than {100 * BODY_MASS_AGREEMENT:g} %"
             + ("; body_mass looks like pounds: " + f"{body_mass * KG_PER_POUND:.1f} kg"
                if pounds else "") + "): the kinetics use body_mass; check which is right",
             UserWarning)
    return body_mass


def plate_sides(force_plates, markers, labels, plates=None):
    """The plates' contacts, each with the foot it is used for and the foot that stood on it.

    Parameters
    ----------
    force_plates : pandas.DataFrame
        :func:`~bmc_functions.read_force_plates` (analog rate) or its resampled table.
    markers : pandas.DataFrame
        The trial's markers (:func:`~bmc_functions.read_c3d`).
    labels : dict
        Standard Plug-in Gait name -> the trial's label (HEE and TOE of each side).
    plates : dict, optional
        Plate number (from 1) -> 'right', 'left' or None: the foot each plate is used
        for, as Vicon Nexus's force-plate settings say (None: not used). Plates not
        named keep the automatic assignment (:func:`~bmc_functions.assign_plates`).

    Returns
    -------
    pandas.DataFrame
        :func:`~bmc_functions.assign_plates`' rows with ``side`` the foot used and
        ``foot`` the one :func:`~bmc_functions.assign_plates` found on the plate.

    Raises
    ------
    ValueError
        If `plates` names a plate the file does not have or a side not 'right', 'left' or
        None.
    """
    feet = {side: [labels[p + name] for name in ("HEE", "TOE") if p + name in labels]
            for side, p in (("right", "R"), ("left", "L"))}
    contacts = assign_plates(force_plates, markers, feet).copy()
    contacts["foot"] = contacts["side"]
    if plates is None:
        return contacts
    if not isinstance(plates, dict):
        raise ArgumentTypeError(f"plates must be a dict of plate number -> 'right', 'left' "
                                f"or None; got {type(plates).__name__}")
    count = len(force_plates.attrs["plates"])
    for plate, side in plates.items():
        if plate not in range(1, count + 1) or side not in ("right", "left", None):
            raise ValueError(f"plates: {plate!r} -> {side!r}; expected a plate number "
                             f"from 1 to {count} -> 'right', 'left' or None")
    contacts["side"] = [plates.get(plate, side) if plate in plates else side
                        for plate, side in zip(contacts["plate"], contacts["side"])]
    return contacts


def _unmeasured(contacts, side, time):
    """Frames of the stances of `side` on a plate not used for it, and their text."""
    # the columns as arrays: pandas' row selection and itertuples take milliseconds
    pick = (contacts["foot"].to_numpy() == side) & (contacts["side"].to_numpy() != side)
    plate, start, stop = (contacts[name].to_numpy()[pick]
                          for name in ("plate", "start", "stop"))
    mask = _in_contacts(time, start, stop)
    return mask, [f"{side} foot on plate {p} at {a:.2f}-{b:.2f} s"
                  for p, a, b in zip(plate.tolist(), start.tolist(), stop.tolist())]


def floor_stances(heel, toe, rate, contacts, side, time):
    """Frames in which a foot stands still on no plate contact (the floor, a step).

    Parameters
    ----------
    heel, toe : ndarray, shape (frames, 3)
        HEE and TOE markers (mm; without HEE, TOE alone).
    rate : float
        Marker rate (Hz).
    contacts : pandas.DataFrame
        :func:`plate_sides`.
    side : {'right', 'left'}
    time : ndarray, shape (frames,)
        The trial's time (s).

    Returns
    -------
    mask : ndarray of bool, shape (frames,)
    text : list of str
        One description per stance.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> from bmc_functions.models.plug_in_gait.kinetics import floor_stances
    >>> x = np.r_[np.zeros(30), np.arange(1, 31) * 20.0]       # 30 frames still, then 2.4 m/s
    >>> foot = np.c_[x, 0 * x, 0 * x]
    >>> none = pd.DataFrame(columns=["plate", "side", "foot", "start", "stop"])
    >>> mask, text = floor_stances(foot, foot, 120.0, none, "left", np.arange(60) / 120)
    >>> print(int(mask.sum()), text)    # frame 29's central difference already moves
    29 ['left foot on no plate at 0.00-0.23 s']
    """
    middle = toe if not np.isfinite(heel).any() else (heel + toe) / 2.0
    speed = vector_length(np.gradient(middle, axis=0)) * rate
    starts, stops = loaded_runs(-np.nan_to_num(speed, nan=np.inf), rate, -STILL_SPEED,
                                MIN_CONTACT)
    foot = contacts["foot"].to_numpy() == side
    on_plate = _in_contacts(time, contacts["start"].to_numpy()[foot],
                            contacts["stop"].to_numpy()[foot])
    # the stances with no frame on a plate: the frames on a plate counted up to each
    # stance's start and stop (a loop over hundreds of stances took milliseconds)
    counts = np.concatenate([[0], np.cumsum(on_plate)])
    free = counts[stops] == counts[starts]
    starts, stops = starts[free], stops[free]
    return runs_mask(len(time), starts, stops), [
        f"{side} foot on no plate at {time[start]:.2f}-{time[stop - 1]:.2f} s"
        for start, stop in zip(starts.tolist(), stops.tolist())]


def _records(table):
    """The rows of `table` as dicts of Python values, None where a value is missing: what
    ``table.astype(object).where(table.notna(), None).to_dict("records")`` gives, from
    each column's ``tolist`` (Python's own values) and ``isna`` (hundreds of contacts:
    a third of pandas' time)."""
    if not table.columns.is_unique:        # pandas' own way: its warning, one of each name
        return table.astype(object).where(table.notna(), None).to_dict("records")
    names = list(table.columns)
    # a NumPy scalar kept in an object column: its Python value, as pandas gives it
    columns = [[None if missing else value.item() if isinstance(value, np.generic) else value
                for value, missing in zip(table[name].tolist(), table[name].isna().tolist())]
               for name in names]
    return [dict(zip(names, row)) for row in zip(*columns)]


#: kinetics_table's column levels, and its columns (joint, side, quantity) in their order.
_TABLE_LEVELS = (("hip", "knee", "ankle"), ("right", "left"), KINETIC_QUANTITIES)
_TABLE_KEYS = [(j, s, q) for j in _TABLE_LEVELS[0] for s in _TABLE_LEVELS[1]
               for q in _TABLE_LEVELS[2]]


def kinetics_table(columns, index):
    """A DataFrame of ``(joint, side, quantity)`` columns in the order hip, knee, ankle;
    right, left; :data:`KINETIC_QUANTITIES` (lexsorted by its levels' own order)."""
    return _kinetics_frame(np.stack([columns[key] for key in _TABLE_KEYS]), index)


def _kinetics_frame(values, index):
    """:func:`kinetics_table` of its columns' values given as (columns, frames) rows in
    the order of ``_TABLE_KEYS``: one row per column, handed to pandas as its block
    without a copy."""
    levels = [list(level) for level in _TABLE_LEVELS]
    codes = [[level.index(key[k]) for key in _TABLE_KEYS] for k, level in enumerate(levels)]
    return pd.DataFrame(values.T, index=index, copy=False,
                        columns=pd.MultiIndex(levels=levels, codes=codes,
                                              names=["joint", "side", "quantity"]))


def _marker_rate_time(force_plates, rate, frames):
    """The time (s) of the plates' frames at the marker `rate` (Hz) and the analog samples
    per frame (1: already at it), as :func:`~bmc_functions.resample_force_plates` gives
    them; a ValueError unless `frames` frames (those of the trial)."""
    if np.isclose(force_plates.attrs["rate"], rate):
        ratio, time = 1, force_plates.index.to_numpy(float)
    else:
        ratio = resampling_ratio(force_plates)
        time = np.arange(-(-len(force_plates) // ratio)) * ratio / force_plates.attrs["rate"]
    if len(time) != frames:
        raise ValueError(f"force_plates: {len(time)} frames at the marker rate, the "
                         f"trial {frames}: give the plates of the same trial")
    return time, ratio


@one_blas_thread   # as the ISB kinetics: see bmc_functions._threads
def plug_in_gait_kinetics(model, dynamic, *, force_plates=None, plates=None,
                          body_mass=None):
    """:meth:`PlugInGait.kinetics` (see there); `model` a :class:`PlugInGait`."""
    mass = body_mass_of(model.subject, body_mass)
    if force_plates is None:
        if not isinstance(dynamic, (str, Path)):
            raise ValueError("force_plates: a marker DataFrame trial needs its plates, "
                             "force_plates=read_force_plates(path); got None")
        force_plates = read_force_plates(dynamic)
    if not isinstance(force_plates, pd.DataFrame) or "plates" not in force_plates.attrs:
        raise ArgumentTypeError(f"force_plates must be the DataFrame read_force_plates "
                                f"returns; got {type(force_plates).__name__}")
    markers, points, flagged = model._landmarks(dynamic, "dynamic")
    # the legs and the pelvis only: the kinetics need no upper-body frame
    centres, frames = model._geometry(points, model.static_offsets, False, upper_body=False)
    model._report_undefined(points, frames, flagged)
    rate = float(markers.attrs["rate"])
    time, ratio = _marker_rate_time(force_plates, rate, len(markers))
    contacts = plate_sides(force_plates, markers, model.markers, plates)
    frames_of = _plate_frames(time, contacts)      # averaged once, where a foot uses them
    ground = plate_loads_at_marker_rate(force_plates, ratio, sorted(frames_of), frames_of)
    # the table's block, (columns, frames), each column written into its row (no
    # stack of the columns into it: 24 MB fewer written in a 10-minute trial)
    values, lengths, unmeasured = np.empty((len(_TABLE_KEYS), len(time))), {}, []
    for side in ("right", "left"):
        p = side[0].upper()
        # no heel marker: NaN (made only then: get's default is built at every call)
        heel = points[p + "HEE"] if p + "HEE" in points else np.full((len(time), 3), np.nan)
        foot = foot_length(heel, points[p + "TOE"], model.subject["MarkerDiameter"])
        if not np.isfinite(foot):     # no heel marker: the ankle centre to TOE instead
            foot = float(np.nanmean(np.linalg.norm(points[p + "TOE"] - centres[p + "AJC"],
                                                   axis=-1))) / 1000.0
            warn(f"{model._trial} has no {p}HEE: the {side} foot's length is the mean "
                 f"ankle centre to {p}TOE distance ({foot * 1000:.0f} mm), not Vicon's "
                 f"heel-to-toe length", RuntimeWarning)
        segments = _segment_parts(frames, centres, side, mass, foot)
        lengths[side] = foot
        wrench = foot_wrench(time, ground, force_plates.attrs["plates"], contacts, side)
        loads = _model_joint_loads(segments, wrench[:3], rate, mass, side,
                                   frames[("pelvis", None)][0])
        missing, text = _unmeasured(contacts, side, time)
        floor, on_floor = floor_stances(heel, points[p + "TOE"], rate, contacts, side, time)
        missing |= floor
        unmeasured += text + on_floor
        for (joint, quantity), column in loads.items():
            row = values[_TABLE_KEYS.index((joint, side, quantity))]
            np.copyto(row, column)
            row[missing] = np.nan        # np.where(missing, nan, column), in place
    if unmeasured:
        warn(f"{model._trial}: {len(unmeasured)} stance(s) that no plate used measured "
             f"({'; '.join(unmeasured)}): that side's forces, moments and powers are NaN "
             f"there (Vicon reports the segments' gravity and inertia only)",
             RuntimeWarning)
    table = _kinetics_frame(values, markers.index.copy())
    table.attrs = {**model.attrs, "rate": rate, "body_mass_kg": mass,
                   "units": "N m/kg (moments), N/kg (forces), W/kg (powers)",
                   "segments": {name: dict(value._asdict())
                                for name, value in PIG_SEGMENTS.items()},
                   "foot_length_m": lengths,
                   "plates": _records(contacts),
                   "options": {"plates": plates, "body_mass": body_mass,
                               "derivatives": "central differences, no filtering",
                               "power": f"moment . relative angular velocity, Plug-in "
                                        f"Gait's estimate over +-{VICON_OMEGA_SPAN} frames",
                               "frames": "distal segment (Vicon's components)"}}
    return table
