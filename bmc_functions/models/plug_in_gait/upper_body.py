r"""Plug-in Gait's upper body: head, thorax, clavicles, humeri, radii, hands, and angles.

Vicon's Plug-in Gait FullBody [1]_ adds to the lower body a head (LFHD RFHD LBHD RBHD), a
thorax (C7 T10 CLAV STRN) and, per side, an arm (SHO on the acromio-clavicular joint, ELB on
the lateral epicondyle, a wrist bar WRA (thumb side) and WRB (little-finger side), FIN on
the second metacarpal head). As in the lower body, the joint centres come from markers
placed beside the joint, a measured width and the chord function
(:func:`~bmc_functions.models.plug_in_gait.lower_body.chord_joint_centre`):

1. :func:`cgm_head_frame` - x from the back to the front of the head, y from right to left,
   turned about y by the subject's ``HeadOffset``.
2. :func:`cgm_thorax_frame` - z up, from the midpoint of STRN and T10 to the midpoint of CLAV
   and C7; x forward, from the midpoint of C7 and T10 towards the midpoint of CLAV and STRN;
   origin CLAV moved back by the marker radius.
3. :func:`shoulder_joint_centre` - the chord from the thorax origin to SHO, with a virtual
   wand perpendicular to SHO and the thorax's forward axis, and ``ShoulderOffset`` plus the
   marker radius; :func:`cgm_clavicle_frame` from it.
4. :func:`elbow_joint_centre`, :func:`wrist_joint_centre`, :func:`hand_centre` - the elbow
   from the shoulder centre, ELB and the plane of the arm (``ElbowWidth``); the wrist from the
   wrist bar (``WristWidth``); the hand from the wrist centre and FIN (``HandThickness``).
5. :func:`cgm_humerus_frame`, :func:`cgm_radius_frame`, :func:`cgm_hand_frame`.
6. :func:`cgm_trunk_angles` (head, thorax, neck, spine) and :func:`cgm_arm_angles`
   (shoulder, elbow, wrist), with Vicon's sequences and signs.
7. :func:`thoracohumeral_angles` - not Vicon's: the ISB's thoracohumeral Y-X-Y angles [2]_
   read from the same thorax and humerus, with the approximations that implies.

Every joint centre and segment axis reproduces the virtual points Nexus 2.6 wrote in the
shared FullBody trials (``TRXO``, ``LCLO``, ``LHUO``, ``LRAO``, ``LHNO`` ... and their
``A``, ``L``, ``P`` points) within 1e-3 mm and 1e-4 degrees, and every angle Vicon's
``<S><Joint>Angles`` within 1e-4 degrees RMS (tests/test_plug_in_gait_upper_body.py). Where
Vicon's guide [1]_ does not say a sign or a sequence, these virtual points and angles
decided it; each such choice is stated where it is made.

References
----------
.. [1] Vicon Motion Systems (2016-2021). Plug-in Gait reference guide, "Upper body
   kinematics" (Nexus 2.12 documentation): fixed values, head, thorax, clavicle, humerus,
   radius and hand definitions, the head offset of the static processing.
.. [2] Wu G et al. (2005). ISB recommendation on definitions of joint coordinate systems of
   various joints for the reporting of human joint motion - Part II: shoulder, elbow, wrist
   and hand. Journal of Biomechanics 38(5), 981-992. (What the ISB recommends instead.)
"""

import numpy as np

from ..._checks import check_choice, check_flag, check_rotation_matrix
from ...rigid_body.cardan import decompose, decompose_orthonormal
from ...rigid_body.rotations import rot_y, vector_dot, vector_length
from .lower_body import (MIRROR, SIDE_NAME, SIDE_PREFIX, SIDES, chord_joint_centre,
                         wrap_degrees, yxz_angles)

#: Plug-in Gait's upper-body markers: head, thorax, and per side (L or R prefix) the arm.
#: RBAK (an asymmetry marker on the right scapula) and the UPA and FRM wand markers only
#: help Nexus label the trial; the model does not use them.
HEAD_MARKERS = ("LFHD", "RFHD", "LBHD", "RBHD")
THORAX_MARKERS = ("C7", "T10", "CLAV", "STRN")
ARM_MARKERS = ("SHO", "ELB", "WRA", "WRB", "FIN")
UPPER_BODY_MARKERS = HEAD_MARKERS + THORAX_MARKERS + tuple(p + m for p in "LR"
                                                           for m in ARM_MARKERS)

#: The upper-body angles returned, per joint: Vicon's ``<S><Joint>Angles`` X, Y, Z (the
#: elbow: X only; Vicon writes 0 in its Y and Z).
UPPER_BODY_ANGLES = {"head": ("tilt", "obliquity", "rotation"),
                     "thorax": ("tilt", "obliquity", "rotation"),
                     "neck": ("flexion", "lateral_flexion", "rotation"),
                     "spine": ("flexion", "lateral_flexion", "rotation"),
                     "shoulder": ("flexion", "abduction", "rotation"),
                     "elbow": ("flexion",),
                     "wrist": ("flexion", "ulnar_deviation", "rotation")}

#: Vicon's output of each upper-body angle (the L or R prefix added) and its component.
UPPER_BODY_OUTPUTS = {(joint, name): (joint.capitalize() + "Angles", k)
                      for joint, names in UPPER_BODY_ANGLES.items()
                      for k, name in enumerate(names)}

#: The subject measurements of the upper body, and the values used when the subject does
#: not give them: the PRIOR values of Vicon's Plug-in Gait FullBody template, as Nexus
#: writes them in a subject's .vsk (the shared Test.vsk: ShoulderOffset 50, ElbowWidth 80,
#: WristWidth 40, HandThickness 30 mm, HeadOffset 0 rad). Lengths in mm, HeadOffset in
#: radians.
UPPER_BODY_DEFAULTS = {"LeftShoulderOffset": 50.0, "RightShoulderOffset": 50.0,
                       "LeftElbowWidth": 80.0, "RightElbowWidth": 80.0,
                       "LeftWristWidth": 40.0, "RightWristWidth": 40.0,
                       "LeftHandThickness": 30.0, "RightHandThickness": 30.0,
                       "HeadOffset": 0.0}

#: The upper body's points in :attr:`PlugInGaitTrack.centres`, in their order: the thorax
#: origin, then per side the shoulder, elbow and wrist centres and the hand's chord point.
UPPER_BODY_CENTRES = ("TRXO", "LSJC", "RSJC", "LEJC", "REJC", "LWJC", "RWJC", "LHND", "RHND")

#: The markers each arm angle needs (per side: prefix added).
ARM_NEEDS = {"shoulder": ("SHO", "ELB", "WRA", "WRB"), "elbow": ("SHO", "ELB", "WRA", "WRB"),
             "wrist": ARM_MARKERS}

#: The distance (mm) from the elbow marker at which the virtual wand of the elbow's chord
#: is placed, along the normal of the arm's plane (any length works: only its direction
#: matters to the chord).
ELBOW_WAND_MM = 500.0

_CYCLIC = {"xy": 2, "yz": 0, "zx": 1}
_INDEX = {"x": 0, "y": 1, "z": 2}


def _unit(v):
    with np.errstate(invalid="ignore", divide="ignore"):
        return v / vector_length(v)[..., None]


def segment_axes(first, second, axes):
    """Orthonormal columns x, y, z from a first axis (exact) and a second one.

    Parameters
    ----------
    first, second : array_like, shape (..., 3)
        The directions of the two axes named by `axes`; `second` is made perpendicular
        to `first` (Gram-Schmidt).
    axes : str
        Their names, e.g. ``'xy'``, ``'zx'``, ``'zy'``, ``'yz'``.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Columns x, y, z; the third axis by the right-hand rule. NaN where a direction is
        missing (no argument checks: the callers pass points already checked).

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait.upper_body import segment_axes
    >>> segment_axes([0, 0, 2.0], [1, 0, 0.5], "zx").round(3) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    e1 = _unit(np.asarray(first, dtype=float))
    second = np.asarray(second, dtype=float)
    e2 = _unit(second - vector_dot(second, e1)[..., None] * e1)
    e3 = np.cross(e1, e2) if axes in _CYCLIC else np.cross(e2, e1)
    columns = [None, None, None]
    columns[_INDEX[axes[0]]], columns[_INDEX[axes[1]]] = e1, e2
    columns[3 - _INDEX[axes[0]] - _INDEX[axes[1]]] = e3
    return np.stack(np.broadcast_arrays(*columns), axis=-1)


def cgm_head_frame(lfhd, rfhd, lbhd, rbhd, head_offset=0.0):
    r"""The Plug-in Gait head: x forward, y to the left, turned about y by the head offset.

    Parameters
    ----------
    lfhd, rfhd, lbhd, rbhd : array_like, shape (..., 3)
        The four head markers (mm).
    head_offset : float, optional
        Vicon's ``HeadOffset`` (radians).

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
        Columns x, y, z. x (exact): from the back (midpoint of LBHD and RBHD) to the front
        (midpoint of LFHD and RFHD); y: from the right side (midpoint of RFHD and RBHD) to
        the left one, made perpendicular; z = x × y; then :math:`R\,R_y(\theta)` with
        :math:`\theta` the head offset.
    origin : ndarray, shape (..., 3)
        The front of the head (midpoint of LFHD and RFHD). Vicon's ``HEDO`` virtual point
        is a mesh origin moved from it (by ``(-0.84, 0, -0.3)`` times a head scale), not a
        landmark; its axes (``HEDA`` ...) are these.

    Notes
    -----
    Vicon's guide [1]_ states the axes, and that the offset is applied "around the Y axis of
    the defined head segment". The direction of the turn, :math:`R\,R_y(+\theta)`, is the one
    that levels the head when :math:`\theta` is what the static processing's "head level"
    option computes (:func:`head_level_offset`); the shared subject has a zero offset, so
    Vicon's output does not test it.

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait.upper_body import cgm_head_frame
    >>> R, origin = cgm_head_frame([80, 70, 1700], [80, -70, 1700], [-100, 70, 1700],
    ...                            [-100, -70, 1700])
    >>> print(R.round(3) + 0.0, origin)
    [[1. 0. 0.]
     [0. 1. 0.]
     [0. 0. 1.]] [  80.    0. 1700.]
    """
    lfhd, rfhd, lbhd, rbhd = (np.asarray(p, dtype=float) for p in (lfhd, rfhd, lbhd, rbhd))
    front, back = (lfhd + rfhd) / 2.0, (lbhd + rbhd) / 2.0
    R = segment_axes(front - back, (lfhd + lbhd) / 2.0 - (rfhd + rbhd) / 2.0, "xy")
    if head_offset:
        R = R @ rot_y(head_offset)
    return R, front


def head_level_offset(R_head, R_progression):
    r"""The head offset (radians) Vicon's static processing computes with "head level".

    Parameters
    ----------
    R_head : array_like, shape (frames, 3, 3)
        :func:`cgm_head_frame` of the static trial, without offset.
    R_progression : array_like, shape (3, 3)
        The direction of progression (:func:`~bmc_functions.models.plug_in_gait.
        lower_body.progression_frame`).

    Returns
    -------
    float
        The mean over the frames of the first (y) angle of the y-x-z Cardan decomposition
        of the lab axes in the head frame, :math:`R_h^T R_{prog}` (Vicon's guide [1]_: "the
        YXZ Euler angles representing the rotation from the head segment to the lab axes
        ... The Y rotation is taken as the head Offset angle, and the mean of this taken
        across the trial"). NaN when the head is never defined.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import rot_y
    >>> from bmc_functions.models.plug_in_gait.upper_body import head_level_offset
    >>> round(head_level_offset(rot_y(-0.3)[None], np.eye(3)), 6)
    0.3
    """
    relative = np.swapaxes(np.asarray(R_head, float), -1, -2) @ np.asarray(R_progression)
    valid = np.isfinite(relative).all(axis=(-1, -2))
    if not valid.any():
        return float("nan")
    return float(decompose(relative[valid], "YXZ")[:, 0].mean())


def cgm_thorax_frame(clav, c7, strn, t10, marker_radius):
    """The Plug-in Gait thorax: z up along the trunk, x forward, origin behind CLAV.

    Parameters
    ----------
    clav, c7, strn, t10 : array_like, shape (..., 3)
        The thorax markers (mm).
    marker_radius : float
        Half the marker diameter (mm).

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
        Columns x (forward), y (left), z (up). z (exact): from the midpoint of STRN and T10
        to the midpoint of CLAV and C7; x: from the midpoint of C7 and T10 to the midpoint
        of CLAV and STRN, made perpendicular (Vicon's guide [1]_).
    origin : ndarray, shape (..., 3)
        CLAV moved back along x by the marker radius (Vicon's ``TRXO``).

    Notes
    -----
    Vicon's virtual points ``TRXL`` and ``TRXP`` point to the right and down: Nexus writes
    this frame turned 180° about x (the axes x, -y, -z). The angles are the same either way
    (each sign below is fitted to Vicon's output); this frame keeps every segment's axes x
    forward, y left, z up.

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait.upper_body import cgm_thorax_frame
    >>> R, origin = cgm_thorax_frame([100, 0, 1400], [-100, 0, 1400], [100, 0, 1200],
    ...                              [-100, 0, 1200], 7.0)
    >>> print(R.round(3) + 0.0, origin)
    [[1. 0. 0.]
     [0. 1. 0.]
     [0. 0. 1.]] [  93.    0. 1400.]
    """
    clav, c7, strn, t10 = (np.asarray(p, dtype=float) for p in (clav, c7, strn, t10))
    R = segment_axes((clav + c7) / 2.0 - (strn + t10) / 2.0,
                     (clav + strn) / 2.0 - (c7 + t10) / 2.0, "zx")
    return R, clav - marker_radius * R[..., :, 0]


def shoulder_joint_centre(R_thorax, thorax_origin, shoulder_marker, delta, side):
    r"""The shoulder joint centre: a chord from the thorax origin to SHO.

    Parameters
    ----------
    R_thorax : array_like, shape (..., 3, 3)
        :func:`cgm_thorax_frame`.
    thorax_origin : array_like, shape (..., 3)
        Its origin (mm).
    shoulder_marker : array_like, shape (..., 3)
        SHO (mm).
    delta : float
        ``ShoulderOffset`` plus the marker radius (mm).
    side : {'right', 'left'}

    Returns
    -------
    ndarray, shape (..., 3)
        The shoulder centre (Vicon's ``LCLO``/``RCLO``): in the plane of the thorax origin
        :math:`O`, SHO and the virtual wand :math:`O \mp \hat x \times (SHO - O)` (- right,
        + left; :math:`\hat x` the thorax's forward axis: the wand points up on both
        sides), `delta` from SHO, the line from
        SHO to it perpendicular to the line from it to :math:`O`, on the side away from
        the wand (below SHO): :func:`~bmc_functions.models.plug_in_gait.lower_body.
        chord_joint_centre`.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.upper_body import shoulder_joint_centre
    >>> sjc = shoulder_joint_centre(np.eye(3), [0, 0, 0], [0, 200, 0], 57.0, "left")
    >>> print(sjc.round(2) + 0.0)
    [  0.   183.76 -54.64]
    """
    origin = np.asarray(thorax_origin, dtype=float)
    up = -MIRROR[side] * np.cross(np.asarray(R_thorax, dtype=float)[..., :, 0],
                                  np.asarray(shoulder_marker, dtype=float) - origin)
    return chord_joint_centre(origin + _unit(up), origin, shoulder_marker, delta)


def cgm_clavicle_frame(R_thorax, thorax_origin, shoulder_marker, shoulder_centre):
    """The clavicle: z from the shoulder centre to the thorax origin, y the wand's line.

    Parameters
    ----------
    R_thorax, thorax_origin, shoulder_marker, shoulder_centre : array_like
        :func:`cgm_thorax_frame`, SHO and :func:`shoulder_joint_centre` (mm).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Columns x, y, z (Vicon's ``LCLA``, ``LCLL``, ``LCLP`` directions from ``LCLO``): z
        exact, y along :math:`\\hat x_{thorax} \\times (SHO - O)` (up on the left, down on
        the right) made perpendicular, x = y × z (forward on both sides).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.upper_body import cgm_clavicle_frame
    >>> R = cgm_clavicle_frame(np.eye(3), [0, 0, 0], [0, 200, 0], [0, 200, -57])
    >>> print(R[:, 2].round(3) + 0.0)
    [ 0.    -0.962  0.274]
    """
    origin = np.asarray(thorax_origin, dtype=float)
    up = np.cross(np.asarray(R_thorax, dtype=float)[..., :, 0],
                  np.asarray(shoulder_marker, dtype=float) - origin)
    return segment_axes(origin - np.asarray(shoulder_centre, dtype=float), up, "zy")


def elbow_joint_centre(shoulder_centre, elbow_marker, wra, wrb, delta, side):
    r"""The elbow joint centre: a chord from the shoulder centre to ELB, in the arm's plane.

    Parameters
    ----------
    shoulder_centre, elbow_marker, wra, wrb : array_like, shape (..., 3)
        :func:`shoulder_joint_centre`, ELB and the wrist bar's markers (mm).
    delta : float
        ``ElbowWidth`` / 2 plus the marker radius (mm).
    side : {'right', 'left'}

    Returns
    -------
    ndarray, shape (..., 3)
        Vicon's ``LHUO``/``RHUO``. With :math:`\hat n` the unit normal of the plane of the
        shoulder centre, ELB and the wrist bar's midpoint (:math:`(S - E) \times (W - E)`),
        the chord's wand is :math:`E \mp 500\,\hat n` (- right, + left: lateral to the
        arm), and the centre lies `delta` from ELB on the medial side.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.upper_body import elbow_joint_centre
    >>> ejc = elbow_joint_centre([0, 0, 300], [0, 60, 0], [250, 40, 0], [250, 80, 0], 60.0,
    ...                          "left")   # elbow flexed 90 degrees: the centre 60 mm medial
    >>> print(ejc.round(6) + 0.0)
    [0. 0. 0.]
    """
    elbow = np.asarray(elbow_marker, dtype=float)
    shoulder = np.asarray(shoulder_centre, dtype=float)
    wrist = (np.asarray(wra, dtype=float) + np.asarray(wrb, dtype=float)) / 2.0
    normal = _unit(np.cross(_unit(shoulder - elbow), _unit(wrist - elbow)))
    wand = elbow - MIRROR[side] * ELBOW_WAND_MM * normal
    return chord_joint_centre(wand, shoulder, elbow, delta)


def wrist_joint_centre(elbow_centre, wra, wrb, delta, side):
    r"""The wrist joint centre: from the wrist bar's midpoint towards the palm.

    Parameters
    ----------
    elbow_centre, wra, wrb : array_like, shape (..., 3)
        :func:`elbow_joint_centre`, WRA (thumb side) and WRB (little-finger side) (mm).
    delta : float
        ``WristWidth`` / 2 plus the marker radius (mm).
    side : {'right', 'left'}

    Returns
    -------
    ndarray, shape (..., 3)
        Vicon's ``LRAO``/``RRAO``: :math:`W + \pm\delta\,\hat v` (+ right, - left) with
        :math:`W` the midpoint of WRA and WRB and :math:`\hat v = (E - W) \times (WRA -
        WRB)` normalised: perpendicular to the forearm and to the wrist bar.

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait.upper_body import wrist_joint_centre
    >>> print(wrist_joint_centre([0, 250, 1100], [0, 270, 850], [0, 230, 850], 37.5,
    ...                          "left").round(2) + 0.0)
    [ 37.5 250.  850. ]
    """
    wra, wrb = np.asarray(wra, dtype=float), np.asarray(wrb, dtype=float)
    middle = (wra + wrb) / 2.0
    across = _unit(np.cross(_unit(np.asarray(elbow_centre, dtype=float) - middle),
                            _unit(wra - wrb)))
    return middle + MIRROR[side] * delta * across


def hand_centre(wrist_centre, wra, wrb, finger_marker, delta):
    """The hand's centre: a chord from the wrist centre to FIN, the wrist bar as wand.

    Parameters
    ----------
    wrist_centre, wra, wrb, finger_marker : array_like, shape (..., 3)
        :func:`wrist_joint_centre`, the wrist bar's markers and FIN (mm).
    delta : float
        ``HandThickness`` / 2 plus the marker radius (mm).

    Returns
    -------
    ndarray, shape (..., 3)
        The point `delta` from FIN, in the plane of the wrist centre, FIN and the wrist
        bar's midpoint, on the side away from the bar. Vicon's hand origin ``LHNO`` lies
        twice as far from the wrist centre on the same line: :math:`2H - W`.

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait.upper_body import hand_centre
    >>> print(hand_centre([0, 0, 0], [-40, 20, 0], [-40, -20, 0], [-22, 0, -80],
    ...                   22.0).round(6) + 0.0)
    [  0.   0. -80.]
    """
    middle = (np.asarray(wra, dtype=float) + np.asarray(wrb, dtype=float)) / 2.0
    return chord_joint_centre(middle, wrist_centre, finger_marker, delta)


def cgm_humerus_frame(shoulder_centre, elbow_centre, wrist_centre):
    """The humerus: z from the elbow centre to the shoulder centre, y normal to the arm.

    Parameters
    ----------
    shoulder_centre, elbow_centre, wrist_centre : array_like, shape (..., 3)
        :func:`shoulder_joint_centre`, :func:`elbow_joint_centre`,
        :func:`wrist_joint_centre` (mm).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        z exact; x opposite to the forearm (from the wrist centre to the elbow centre)
        made perpendicular; y = z × x (the elbow's flexion axis). Vicon's ``LHUA``,
        ``LHUL``, ``LHUP`` directions from ``LHUO`` (the elbow centre).

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait.upper_body import cgm_humerus_frame
    >>> cgm_humerus_frame([0, 0, 300], [0, 0, 0], [-250, 0, 0]).round(3) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    elbow = np.asarray(elbow_centre, dtype=float)
    return segment_axes(np.asarray(shoulder_centre, dtype=float) - elbow,
                        elbow - np.asarray(wrist_centre, dtype=float), "zx")


def cgm_radius_frame(elbow_centre, wrist_centre, R_humerus):
    """The radius (forearm): y the humerus's y (the elbow is a hinge), z towards the elbow.

    Parameters
    ----------
    elbow_centre, wrist_centre : array_like, shape (..., 3)
        :func:`elbow_joint_centre`, :func:`wrist_joint_centre` (mm).
    R_humerus : array_like, shape (..., 3, 3)
        :func:`cgm_humerus_frame`.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        y exact (the humerus's y axis), z from the wrist centre to the elbow centre made
        perpendicular, x = y × z. Vicon's ``LRAA``, ``LRAL``, ``LRAP`` directions from
        ``LRAO`` (the wrist centre).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.upper_body import cgm_radius_frame
    >>> cgm_radius_frame([0, 0, 250], [0, 0, 0], np.eye(3)).round(3) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    return segment_axes(np.asarray(R_humerus, dtype=float)[..., :, 1],
                        np.asarray(elbow_centre, dtype=float)
                        - np.asarray(wrist_centre, dtype=float), "yz")


def cgm_hand_frame(wrist_centre, hand_point, wra, wrb, side):
    """The hand: z from the hand's centre to the wrist centre, y across the wrist bar.

    Parameters
    ----------
    wrist_centre, hand_point : array_like, shape (..., 3)
        :func:`wrist_joint_centre` and :func:`hand_centre` (mm).
    wra, wrb : array_like, shape (..., 3)
        The wrist bar's markers (mm).
    side : {'right', 'left'}

    Returns
    -------
    ndarray, shape (..., 3, 3)
        z exact; y along WRA - WRB on the right and WRB - WRA on the left (towards the
        little finger's side on the left hand, the thumb's on the right: the same
        direction, to the subject's right, in the anatomical posture), made
        perpendicular; x = y × z. Vicon's ``LHNA``, ``LHNL``, ``LHNP`` directions.

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait.upper_body import cgm_hand_frame
    >>> cgm_hand_frame([0, 0, 850], [0, 0, 760], [0, 20, 850], [0, -20, 850],
    ...                "left").round(3) + 0.0
    array([[-1.,  0.,  0.],
           [ 0., -1.,  0.],
           [ 0.,  0.,  1.]])
    """
    wra, wrb = np.asarray(wra, dtype=float), np.asarray(wrb, dtype=float)
    return segment_axes(np.asarray(wrist_centre, dtype=float)
                        - np.asarray(hand_point, dtype=float),
                        MIRROR[side] * (wra - wrb), "zy")


def cgm_trunk_angles(R_progression, R_pelvis, R_head, R_thorax, side, *, check=True):
    r"""Plug-in Gait's head, thorax, neck and spine angles of one side (degrees).

    Parameters
    ----------
    R_progression : array_like, shape (3, 3)
        The direction of progression.
    R_pelvis, R_head, R_thorax : array_like, shape (frames, 3, 3) or None
        :func:`~bmc_functions.models.plug_in_gait.lower_body.cgm_pelvis_frame`,
        :func:`cgm_head_frame`, :func:`cgm_thorax_frame`; None for a segment the trial
        lacks (the angles that need it are left out).
    side : {'right', 'left'}
        Vicon writes these angles once per side (``LHeadAngles``, ``RHeadAngles``, ...),
        the side setting the signs of the out-of-plane angles.
    check : bool, keyword-only
        Test that the segment axes are rotation matrices (default True), as
        :func:`~bmc_functions.rigid_body.cardan.decompose` does. False skips the test for
        axes orthonormal by construction (the model's own segment frames), through
        :func:`~bmc_functions.rigid_body.cardan.decompose_orthonormal`: the same angles,
        faster; axes that are not rotations then give meaningless angles, not an error.

    Returns
    -------
    dict
        (joint, angle) -> (frames,) degrees, for the joints whose segments are given.

    Notes
    -----
    Each is a Cardan y-x-z decomposition :math:`R_p^T R_d = R_y(a) R_x(b) R_z(c)`, with
    :math:`s = +1` on the right and :math:`-1` on the left:

    ==================================== =================================================
    head (:math:`R_p` progression)        tilt :math:`-a`, obliquity :math:`-s\,b`,
                                         rotation :math:`s\,c`
    thorax (:math:`R_p` progression)      tilt :math:`a`, obliquity :math:`-s\,b`, rotation
                                         :math:`s\,c` (the pelvis's signs)
    neck (:math:`R_p` head, :math:`R_d`   flexion :math:`-a`, lateral flexion :math:`-s\,b`,
    thorax)                              rotation :math:`s\,c`
    spine (:math:`R_p` thorax,            flexion :math:`-a`, lateral flexion :math:`-s\,b`,
    :math:`R_d` pelvis)                  rotation :math:`s\,c`
    ==================================== =================================================

    Vicon's guide [1]_ names the neck "the head relative to the thorax" and the spine
    "the thorax relative to the pelvis"; its output is the decomposition of the proximal
    segment in the distal one's frame (the thorax in the head's, the pelvis in the
    thorax's), which these formulas follow: they reproduce Vicon's curves of both sides in
    both shared trials within 1e-4 degrees RMS.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import rot_y
    >>> from bmc_functions.models.plug_in_gait.upper_body import cgm_trunk_angles
    >>> I = np.eye(3)[None]
    >>> a = cgm_trunk_angles(np.eye(3), I, rot_y(np.radians(10))[None], I, "right")
    >>> for joint in ("head", "thorax", "neck", "spine"):   # the head pitched nose-down
    ...     print(joint, [round(float(v[0]), 6) + 0.0 for k, v in a.items() if k[0] == joint])
    head [-10.0, 0.0, 0.0]
    thorax [0.0, 0.0, 0.0]
    neck [10.0, 0.0, 0.0]
    spine [0.0, 0.0, 0.0]
    """
    s = MIRROR[side]
    check = check_flag(check, "check")
    pairs = {"head": (R_progression, R_head), "thorax": (R_progression, R_thorax),
             "neck": (R_head, R_thorax), "spine": (R_thorax, R_pelvis)}
    signs = {"head": (-1, -s, s), "thorax": (1, -s, s), "neck": (-1, -s, s),
             "spine": (-1, -s, s)}
    out = {}
    for joint, (proximal, distal) in pairs.items():
        if proximal is None or distal is None:
            continue
        angles = yxz_angles(np.asarray(proximal, float), np.asarray(distal, float), check)
        for k, name in enumerate(UPPER_BODY_ANGLES[joint]):
            out[(joint, name)] = signs[joint][k] * angles[..., k]
    return out


def cgm_arm_angles(R_thorax, R_humerus, R_radius, R_hand, side, *, check=True):
    r"""Plug-in Gait's shoulder, elbow and wrist angles of one side (degrees).

    Parameters
    ----------
    R_thorax, R_humerus, R_radius : array_like, shape (frames, 3, 3)
        :func:`cgm_thorax_frame`, :func:`cgm_humerus_frame`, :func:`cgm_radius_frame`.
    R_hand : array_like, shape (frames, 3, 3) or None
        :func:`cgm_hand_frame`; None without FIN (the wrist angles are left out).
    side : {'right', 'left'}
    check : bool, keyword-only
        Test that the segment axes are rotation matrices (default True), as
        :func:`~bmc_functions.rigid_body.cardan.decompose` does. False skips the test for
        axes orthonormal by construction (the model's own segment frames), through
        :func:`~bmc_functions.rigid_body.cardan.decompose_orthonormal`: the same angles,
        faster; axes that are not rotations then give meaningless angles, not an error.

    Returns
    -------
    dict
        (joint, angle) -> (frames,) degrees.

    Notes
    -----
    With :math:`s = +1` on the right and :math:`-1` on the left:

    - shoulder: the Cardan x-y-z decomposition of the humerus in the thorax,
      :math:`R_t^T R_h = R_x(a) R_y(b) R_z(c)`: flexion :math:`-b`, abduction :math:`-s\,a`,
      rotation :math:`s\,c + 180°` (wrapped to ±180°; the humerus's x axis points back,
      away from the forearm). Abduction first, about the thorax's forward axis, then
      flexion about the floating axis: near 90° of flexion the abduction and rotation are
      indistinguishable (gimbal lock);
    - elbow: y-x-z of the radius in the humerus, flexion :math:`a` (the radius shares the
      humerus's y axis, so this is the whole rotation);
    - wrist: y-x-z of the hand in the radius: flexion :math:`a`, ulnar deviation
      :math:`s\,b`, rotation :math:`s\,c`.

    The sequences and signs are those that reproduce Vicon's ``ShoulderAngles``,
    ``ElbowAngles`` and ``WristAngles`` (within 1e-4 degrees RMS in both shared trials,
    one of them with the arms abducted 70-80 degrees). The ISB recommends y-x-y for the
    thoracohumeral joint instead [2]_.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import rot_x
    >>> from bmc_functions.models.plug_in_gait.upper_body import cgm_arm_angles
    >>> I = np.eye(3)[None]
    >>> humerus = rot_x(np.radians(-30))[None] @ np.diag([-1.0, -1, 1])   # x back
    >>> a = cgm_arm_angles(I, humerus, humerus, None, "right")
    >>> for (joint, name), value in a.items():
    ...     print(joint, name, round(float(value[0]), 6) + 0.0)
    shoulder flexion 0.0
    shoulder abduction 30.0
    shoulder rotation 0.0
    elbow flexion 0.0
    """
    s = MIRROR[side]
    R_thorax, R_humerus = np.asarray(R_thorax, float), np.asarray(R_humerus, float)
    check = check_flag(check, "check")
    shoulder = (decompose if check else decompose_orthonormal)(
        np.swapaxes(R_thorax, -1, -2) @ R_humerus, "XYZ", degrees=True)
    out = {("shoulder", "flexion"): -shoulder[..., 1],
           ("shoulder", "abduction"): -s * shoulder[..., 0],
           ("shoulder", "rotation"): wrap_degrees(s * shoulder[..., 2] + 180.0),
           ("elbow", "flexion"): yxz_angles(R_humerus, np.asarray(R_radius, float), check)[..., 0]}
    if R_hand is not None:
        wrist = yxz_angles(np.asarray(R_radius, float), np.asarray(R_hand, float), check)
        out.update({("wrist", "flexion"): wrist[..., 0],
                    ("wrist", "ulnar_deviation"): s * wrist[..., 1],
                    ("wrist", "rotation"): s * wrist[..., 2]})
    return out


#: Plug-in Gait's thorax axes renamed as the ISB's (columns: X = x forward, Y = z up,
#: Z = -y to the right) and the right humerus's (X = -x towards the forearm, Y = z
#: towards the shoulder, Z = y). Both have determinant +1: a renaming, not a reflection.
ISB_THORAX_AXES = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
ISB_HUMERUS_AXES = np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]])

#: The ISB's thoracohumeral angles, in the order of the Y-X-Y sequence.
THORACOHUMERAL_ANGLES = ("plane_of_elevation", "elevation", "axial_rotation")


def thoracohumeral_angles(R_thorax, R_humerus, side):
    r"""The ISB's thoracohumeral angles (Y-X-Y) from Plug-in Gait's thorax and humerus.

    Parameters
    ----------
    R_thorax, R_humerus : array_like, shape (..., 3, 3)
        :func:`cgm_thorax_frame` and :func:`cgm_humerus_frame` of the same `side`
        (Plug-in Gait's axes: x forward, y to the subject's left, z up the segment), in
        the lab. A matrix with NaN gives NaN angles in that frame.
    side : {'right', 'left'}

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Plane of elevation, elevation, axial rotation (degrees), as Wu et al. (2005) [2]_
        define them: the plane of elevation and the axial rotation in [-180, 180), the
        elevation in [-180, 0] (**negative**, the ISB's sign: a rotation about the
        floating axis X, which points forward when the arm is raised to the side).

    Raises
    ------
    ValueError
        If a matrix is not a rotation matrix of shape (..., 3, 3), or `side` is not
        'right' or 'left'.

    Warns
    -----
    RuntimeWarning
        Once per call, with the number of frames in gimbal lock (the arm exactly along
        the trunk), from :func:`~bmc_functions.decompose`.

    Notes
    -----
    The ISB's thorax has X forward, Y up and Z to the right; its humerus Y from the elbow
    to the glenohumeral centre, X forward (towards the forearm when the elbow is bent)
    and Z = X x Y. Plug-in Gait's axes, renamed: :math:`R^{ISB} = R\,Q` with
    :math:`Q_t = [e_x\;\; e_z\;\; -e_y]` and :math:`Q_h = [-e_x\;\; e_z\;\; e_y]`
    (:data:`ISB_THORAX_AXES`, :data:`ISB_HUMERUS_AXES`; Plug-in Gait's humerus x points
    away from the forearm). The humerus in the thorax is decomposed in the proper Euler
    sequence

    .. math:: Q_t^T R_t^T R_h Q_h = R_Y(\alpha)\,R_X(\beta)\,R_Y(\gamma), \qquad
              \beta \le 0,

    plane of elevation :math:`\alpha`, elevation :math:`\beta`, axial rotation
    :math:`\gamma`. A decomposition returns the middle angle of a proper Euler sequence
    in [0°, 180°]; the ISB's negative one is reached by decomposing
    :math:`D\,(Q_t^T R_t^T R_h Q_h)\,D` with :math:`D = R_Y(180°) = \mathrm{diag}(-1, 1,
    -1)`, since :math:`D\,R_Y(\alpha) R_X(\beta) R_Y(\gamma)\,D = R_Y(\alpha)
    R_X(-\beta) R_Y(\gamma)`. (Decomposing without :math:`D` gives :math:`(a, b, c) =
    (\alpha + 180°, -\beta, \gamma + 180°)`, the route notebook 16 takes.) The
    elevation is minus the angle between the thorax's and the humerus's long axes,
    :math:`\cos\beta = \hat Y_t \cdot \hat Y_h`: 0 with the arm along the trunk,
    -90° with the arm horizontal. The plane of elevation is 0° for an arm raised in the
    frontal plane (abduction) and 90° for one raised forward (flexion); the axial rotation
    is positive inwards (internal rotation). The sequence locks with the arm at the side
    (:math:`\beta = 0`), where the plane of elevation and the axial rotation are not
    defined apart, only their sum: there the axial rotation is set to 0 and the plane
    of elevation is the sum (with one warning). Near the lock the plane of elevation
    magnifies the arm's sideways movement by :math:`1 / |\sin\beta|`.

    **The left side** is mirrored onto a right side (the ISB defines its axes for the
    right): the humerus in the thorax, :math:`M = R_t^T R_h` in Plug-in Gait's thorax
    axes, is replaced by :math:`S M S` with :math:`S = \mathrm{diag}(1, -1, 1)`, the
    reflection in the thorax's sagittal plane (the two reflections keep it a rotation).
    A left arm that mirrors a right arm gets the right arm's angles.

    **Approximations** (these are not the ISB's frames, only its axes and sequence):

    - thorax: built from CLAV (for the ISB's IJ), STRN (for PX, which it is not
      always near), C7 and **T10** (for T8), and its second axis from the forward
      direction rather than the normal of the IJ-C7-midpoint plane: a small,
      subject-dependent tilt of the whole thorax;
    - humerus: its long axis runs from a chord-function elbow centre
      (:func:`elbow_joint_centre`) to a shoulder centre a fixed ``ShoulderOffset`` below
      the acromion marker (:func:`shoulder_joint_centre`), which moves with the scapula
      and clavicle, not to a regressed or functional glenohumeral centre; its second
      axis comes from the forearm (the ISB's second option), so the axial rotation is
      unreliable with the elbow straight;
    - no scapula: the glenohumeral and scapulothoracic angles the ISB also defines
      cannot be read from Plug-in Gait's markers.

    Examples
    --------
    An arm raised 90° to the side (the humerus's z, elbow to shoulder, points
    medially; the forearm points forward), and one raised 90° forward (z points back;
    x, away from the forearm, up: the forearm hangs down), the thorax aligned with the
    lab (Plug-in Gait's axes). The second arm's axial rotation of 90° belongs to the
    sequence as much as to the arm: the first rotation, 90° about the common Y axis,
    turned the humerus about its own long axis too, and the third turns it back.

    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.upper_body import thoracohumeral_angles
    >>> thorax = np.eye(3)
    >>> abducted = np.array([[-1.0, 0, 0], [0, 0, 1], [0, 1, 0]])   # columns x, y, z
    >>> flexed = np.array([[0.0, 0, -1], [0, 1, 0], [1, 0, 0]])   # z back, x up
    >>> print(thoracohumeral_angles(thorax, np.stack([abducted, flexed]), "right")
    ...       .round(6) + 0.0)
    [[  0. -90.   0.]
     [ 90. -90.  90.]]
    """
    check_choice(side, "side", SIDES)
    R_thorax = check_rotation_matrix(R_thorax, "R_thorax")
    R_humerus = check_rotation_matrix(R_humerus, "R_humerus")
    M = np.swapaxes(R_thorax, -1, -2) @ R_humerus
    if side == "left":
        M = M * np.array([1.0, -1.0, 1.0])[:, None] * np.array([1.0, -1.0, 1.0])
    D = np.diag([-1.0, 1.0, -1.0])
    yxy = decompose(D @ ISB_THORAX_AXES.T @ M @ ISB_HUMERUS_AXES @ D, "YXY", degrees=True)
    return np.stack([wrap_degrees(yxy[..., 0]), -yxy[..., 1], wrap_degrees(yxy[..., 2])],
                    axis=-1)


# --- a trial's upper body -----------------------------------------------------------------

def upper_body_geometry(points, subject):
    """The upper body's joint centres and segment frames in a trial, from the markers it has.

    Parameters
    ----------
    points : dict
        Standard marker name (``'CLAV'``, ``'LSHO'``, ...) -> (frames, 3) positions (mm);
        a marker absent, or NaN in every frame, leaves out the segments that need it.
    subject : dict
        The measurements (Vicon's names): ``MarkerDiameter``, ``HeadOffset`` and per side
        ``ShoulderOffset``, ``ElbowWidth``, ``WristWidth``, ``HandThickness``.

    Returns
    -------
    centres : dict
        ``'TRXO'`` (thorax origin) and per side ``'LSJC'`` (shoulder), ``'LEJC'``
        (elbow), ``'LWJC'`` (wrist), ``'LHND'`` (the hand's chord point): (frames, 3).
    frames : dict
        (segment, side) -> (R, origin): ``('head', None)``, ``('thorax', None)`` and per
        side ``('clavicle', side)`` (origin the shoulder centre), ``('humerus', side)``
        (the elbow centre), ``('radius', side)`` (the wrist centre), ``('hand', side)``
        (Vicon's hand origin, :math:`2H - W`). The head needs its four markers; the
        thorax its four; an arm the thorax and SHO, ELB, WRA, WRB; the hand also FIN.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.upper_body import upper_body_geometry
    >>> points = {"CLAV": [[100., 0, 1400]], "C7": [[-100., 0, 1400]],
    ...           "STRN": [[100., 0, 1200]], "T10": [[-100., 0, 1200]]}
    >>> centres, frames = upper_body_geometry({k: np.array(v) for k, v in points.items()},
    ...                                       {"MarkerDiameter": 14.0, "HeadOffset": 0.0})
    >>> sorted(frames), centres["TRXO"]
    ([('thorax', None)], array([[  93.,    0., 1400.]]))
    """
    present = {name for name, xyz in points.items() if np.isfinite(xyz).any()}
    radius = subject["MarkerDiameter"] / 2.0
    centres, frames = {}, {}
    if present.issuperset(HEAD_MARKERS):
        frames[("head", None)] = cgm_head_frame(*(points[m] for m in HEAD_MARKERS),
                                                head_offset=subject["HeadOffset"])
    if not present.issuperset(THORAX_MARKERS):
        return centres, frames
    R_thorax, origin = cgm_thorax_frame(points["CLAV"], points["C7"], points["STRN"],
                                        points["T10"], radius)
    frames[("thorax", None)], centres["TRXO"] = (R_thorax, origin), origin
    for side in SIDES:
        p, long = SIDE_PREFIX[side], SIDE_NAME[side]
        if not present.issuperset(p + m for m in ARM_NEEDS["shoulder"]):
            continue
        sho, elb, wra, wrb = (points[p + m] for m in ARM_NEEDS["shoulder"])
        sjc = shoulder_joint_centre(R_thorax, origin, sho,
                                    subject[long + "ShoulderOffset"] + radius, side)
        ejc = elbow_joint_centre(sjc, elb, wra, wrb,
                                 subject[long + "ElbowWidth"] / 2.0 + radius, side)
        wjc = wrist_joint_centre(ejc, wra, wrb, subject[long + "WristWidth"] / 2.0 + radius,
                                 side)
        R_humerus = cgm_humerus_frame(sjc, ejc, wjc)
        frames[("clavicle", side)] = (cgm_clavicle_frame(R_thorax, origin, sho, sjc), sjc)
        frames[("humerus", side)] = (R_humerus, ejc)
        frames[("radius", side)] = (cgm_radius_frame(ejc, wjc, R_humerus), wjc)
        centres[p + "SJC"], centres[p + "EJC"], centres[p + "WJC"] = sjc, ejc, wjc
        if p + "FIN" in present:
            hand = hand_centre(wjc, wra, wrb, points[p + "FIN"],
                               subject[long + "HandThickness"] / 2.0 + radius)
            frames[("hand", side)] = (cgm_hand_frame(wjc, hand, wra, wrb, side),
                                      2.0 * hand - wjc)
            centres[p + "HND"] = hand
    return centres, frames


def upper_body_angles(frames, R_progression, *, check=True):
    """The upper-body angles of both sides that the trial's segments allow (degrees).

    Parameters
    ----------
    frames : dict
        (segment, side) -> (R, origin), as :func:`upper_body_geometry` returns them, with
        the pelvis (``('pelvis', None)``) for the spine.
    R_progression : array_like, shape (3, 3)
        The direction of progression.
    check : bool, keyword-only
        Test that the segment axes are rotation matrices (default True); see
        :func:`cgm_trunk_angles`.

    Returns
    -------
    dict
        side -> {(joint, angle) -> (frames,) degrees}: :func:`cgm_trunk_angles` and, with
        an arm's segments, :func:`cgm_arm_angles`. The trunk's curves are decomposed once:
        the left side's are the right side's with the second and third angles negated
        (Vicon's sign per side, :func:`cgm_trunk_angles`).
    """
    check = check_flag(check, "check")
    R = {key: value[0] for key, value in frames.items()}
    right = cgm_trunk_angles(R_progression, R.get(("pelvis", None)), R.get(("head", None)),
                             R.get(("thorax", None)), "right", check=check)
    left = {(joint, name): value if name == UPPER_BODY_ANGLES[joint][0] else -value
            for (joint, name), value in right.items()}
    out = {"right": right, "left": left}
    for side in SIDES:
        if ("humerus", side) in R:
            out[side].update(cgm_arm_angles(R[("thorax", None)], R[("humerus", side)],
                                            R[("radius", side)], R.get(("hand", side)), side,
                                            check=check))
    return out
