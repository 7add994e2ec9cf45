r"""Plug-in Gait's lower body, step by step: pelvis, hip centre, femur, tibia, foot, angles.

Each step is a function of its own (arrays in, arrays out, frames on the first axis); the
list of steps and the references are in the package's docstring
(:mod:`bmc_functions.models.plug_in_gait`), the references cited here by number:

.. [1] Davis RB, Ounpuu S, Tyburski D, Gage JR (1991). A gait analysis data collection
   and reduction technique. Human Movement Science 10(5), 575-587.
.. [2] Kadaba MP, Ramakrishnan HK, Wootten ME (1990). Measurement of lower extremity
   kinematics during level walking. Journal of Orthopaedic Research 8(3), 383-392.
.. [3] Vicon Motion Systems (2010-2017). Plug-in Gait reference guide / Plug-in Gait
   product guide (Nexus 2): lower-body model, chord function, static processing.
.. [4] Baker R (2013). Measuring walking: a handbook of clinical gait analysis. Mac
   Keith Press. (The CGM's definitions and their criticism.)
"""

import numpy as np

from ..._checks import check_flag, check_vectors
from ...rigid_body.cardan import decompose, decompose_orthonormal
from ...rigid_body.frames import nearest_lab_axis
from ...rigid_body.rotations import (cross_rows, dot_rows, rot_x, rot_y, rot_z,
                                      vector_dot, vector_length)

#: Davis et al. (1991) hip-centre regression, as Plug-in Gait implements it [1, 3]:
#: C = 0.115 * leg length - 15.3 (mm), theta = 0.5 rad (28.4 deg) and beta = 0.314 rad
#: (18 deg). Plug-in Gait uses these two angles in radians exactly (its hip centres are
#: reproduced to 1e-3 mm with them, tests/test_plug_in_gait.py).
DAVIS_C_SLOPE = 0.115
DAVIS_C_INTERCEPT = -15.3
DAVIS_THETA = 0.5
DAVIS_BETA = 0.314

#: ASIS-trochanter distance when not measured, from the leg length (mm): Davis et al.
#: (1991) regression, written in Vicon's .vsk files as the expression
#: "( 0.1288 * LeftLegLength ) - 48.56".
ASIS_TROCHANTER_SLOPE = 0.1288
ASIS_TROCHANTER_INTERCEPT = -48.56

#: Plug-in Gait's marker names (lower body) and the segment each belongs to.
PELVIS_MARKERS = ("LASI", "RASI", "LPSI", "RPSI", "SACR")
LEG_MARKERS = ("THI", "KNE", "TIB", "ANK", "HEE", "TOE")

#: The angles returned, per joint, with the Vicon output they reproduce (X, Y, Z).
CGM_ANGLES = {"pelvis": ("tilt", "obliquity", "rotation"),
              "hip": ("flexion", "adduction", "rotation"),
              "knee": ("flexion", "adduction", "rotation"),
              "ankle": ("dorsiflexion", "inversion", "rotation"),
              "foot": ("progression",)}

#: Vicon's name of each lower-body output (the L or R prefix added), and the component used.
LOWER_BODY_OUTPUTS = {("pelvis", "tilt"): ("PelvisAngles", 0),
                      ("pelvis", "obliquity"): ("PelvisAngles", 1),
                      ("pelvis", "rotation"): ("PelvisAngles", 2),
                      ("hip", "flexion"): ("HipAngles", 0), ("hip", "adduction"): ("HipAngles", 1),
                      ("hip", "rotation"): ("HipAngles", 2),
                      ("knee", "flexion"): ("KneeAngles", 0),
                      ("knee", "adduction"): ("KneeAngles", 1),
                      ("knee", "rotation"): ("KneeAngles", 2),
                      ("ankle", "dorsiflexion"): ("AnkleAngles", 0),
                      ("ankle", "inversion"): ("AnkleAngles", 1),
                      ("ankle", "rotation"): ("AnkleAngles", 2),
                      ("foot", "progression"): ("FootProgressAngles", 2)}

#: Distance (mm) between the first and last positions of LASI above which the direction
#: of progression is taken from its path; at or below it (a static trial, a swing, a
#: throw: a trial that does not travel), from the pelvis's forward axis in the first frame.
#: Vicon's threshold: "If the distance between the first and last valid position of the
#: LASI marker is greater than a threshold of 800 mm ..." (Vicon FAQ, "What is the Plug-in
#: Gait 'Progression Frame' and how is it used?"; pyCGM2's PelvisProgressionFrameProcedure
#: uses the same 800 mm).
PROGRESSION_MIN_PATH = 800.0

SIDES = ("right", "left")
SIDE_PREFIX = {"right": "R", "left": "L"}
SIDE_NAME = {"right": "Right", "left": "Left"}
#: +1 right, -1 left: Plug-in Gait reports the left side's out-of-plane angles with the
#: sign that makes adduction, internal rotation and inversion positive on both sides.
MIRROR = {"right": 1.0, "left": -1.0}


# --- the model's steps (arrays in, arrays out) ----------------------------------------

def _unit(v):
    return v / vector_length(v)[..., None]


def axes_zy(y=None, z=None):
    """Columns x, y, z from z (exact) and a direction y (made perpendicular to z).

    Gram-Schmidt as in :func:`~bmc_functions.rigid_body.frames.frame_from_axes` (axes 'zy'), written
    out here without its argument checks: this runs nine times per trial on every frame,
    on points already checked, and a missing marker must give NaN, not an error."""
    with np.errstate(invalid="ignore", divide="ignore"):
        z, y = np.asarray(z, dtype=float), np.asarray(y, dtype=float)
        shape = np.broadcast_shapes(y.shape, z.shape)
        # The arithmetic on contiguous component rows (3, ...) in place (each operation
        # and its order as ``_unit(y - vector_dot(y, z)[..., None] * z)`` and
        # numpy.cross compute it, bit for bit): about 1.5 times faster than on the
        # strided columns of (..., 3) arrays and their temporaries. columns[k] holds R's
        # column k so; R is one transposing copy of them at the end.
        columns = np.empty((3, 3) + shape[:-1])
        for rows, given in zip(columns[1:], (y, z)):
            np.copyto(rows, np.moveaxis(np.broadcast_to(given, shape), -1, 0))
        x, y, z = columns
        length, scratch = np.empty(shape[:-1]), np.empty(shape[:-1])
        z /= np.sqrt(dot_rows(z, z, length, scratch), out=length)
        _subtract_along(y, dot_rows(y, z, length, scratch), z, scratch)
        y /= np.sqrt(dot_rows(y, y, length, scratch), out=length)
        cross_rows(y, z, out=x, scratch=scratch)
        return np.ascontiguousarray(np.moveaxis(columns, (0, 1), (-1, -2)))


def _component_rows(v, shape):
    """A copy of `v` broadcast to `shape` (..., 3), as its rows x, y, z: shape (3, ...)."""
    return np.array(np.moveaxis(np.broadcast_to(v, shape), -1, 0), order="C")


def cgm_pelvis_frame(rasi, lasi, sacrum):
    r"""The CGM pelvis: origin between the ASIS markers, axes x forward, y left, z up.

    Parameters
    ----------
    rasi, lasi : array_like, shape (..., 3)
        Right and left anterior superior iliac spine markers (mm).
    sacrum : array_like, shape (..., 3)
        The SACR marker, or the midpoint of RPSI and LPSI.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
        Columns: the unit x (anterior), y (left), z (up) axes in the lab.
    origin : ndarray, shape (..., 3)
        The midpoint of the ASIS markers.

    Notes
    -----
    Kadaba et al. (1990) [2]_: :math:`\hat y = (L_{ASI} - R_{ASI})/|\cdot|`;
    :math:`\hat x` the part of :math:`O - S` (origin minus sacrum) perpendicular to
    :math:`\hat y`; :math:`\hat z = \hat x \times \hat y`. (Plug-in Gait draws its pelvis
    at the midpoint of the hip centres, ``PELO``; the axes are the same.)

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait import cgm_pelvis_frame
    >>> R, origin = cgm_pelvis_frame([100, -120, 900], [100, 120, 900], [-50, 0, 920])
    >>> print(R.round(3) + 0.0)
    [[ 0.991  0.     0.132]
     [ 0.     1.     0.   ]
     [-0.132  0.     0.991]]
    >>> print(origin)
    [100.   0. 900.]
    """
    rasi, lasi = check_vectors(rasi, "rasi"), check_vectors(lasi, "lasi")
    sacrum = check_vectors(sacrum, "sacrum")
    origin = (rasi + lasi) / 2.0
    R = axes_zy(y=lasi - rasi, z=np.cross(origin - sacrum, lasi - rasi))
    return R, origin


def asis_trochanter_distance(leg_length):
    """The ASIS-trochanter distance (mm) Plug-in Gait derives from the leg length.

    Parameters
    ----------
    leg_length : float or array_like
        Leg length (mm, ASIS to medial malleolus).

    Returns
    -------
    float or ndarray
        :math:`0.1288\\,L - 48.56` (Davis et al. 1991 [1]_; Vicon's .vsk expression).

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait import asis_trochanter_distance
    >>> round(float(asis_trochanter_distance(877.0)), 4)
    64.3976
    """
    return ASIS_TROCHANTER_SLOPE * np.asarray(leg_length, dtype=float) \
        + ASIS_TROCHANTER_INTERCEPT


def davis_hip_centre(R_pelvis, origin, *, mean_leg_length, asis_trochanter,
                     inter_asis_distance, marker_radius, side):
    r"""Hip joint centre from the Davis et al. (1991) regression, in the lab.

    Parameters
    ----------
    R_pelvis : array_like, shape (..., 3, 3)
        The CGM pelvis axes (columns x forward, y left, z up), :func:`cgm_pelvis_frame`.
    origin : array_like, shape (..., 3)
        The midpoint of the ASIS markers (mm).
    mean_leg_length : float
        Mean of the left and right leg lengths (mm).
    asis_trochanter : float
        The side's ASIS-trochanter distance (mm), :func:`asis_trochanter_distance`.
    inter_asis_distance : float
        Distance between the ASIS (mm).
    marker_radius : float
        Half the marker diameter (mm): the ASIS markers sit that far off the bone.
    side : {'right', 'left'}

    Returns
    -------
    ndarray, shape (..., 3)
        The hip centre (mm, lab).

    Notes
    -----
    With :math:`C = 0.115\,L_{mean} - 15.3`, :math:`\theta = 0.5` rad,
    :math:`\beta = 0.314` rad, :math:`X_{dis}` the ASIS-trochanter distance, :math:`r`
    the marker radius and :math:`a` half the inter-ASIS distance, the centre in the
    pelvis frame is (Davis et al. 1991 [1]_; Vicon [3]_)

    .. math::
        x &= C\cos\theta\sin\beta - (X_{dis} + r)\cos\beta \\
        y &= \pm\,(a - C\sin\theta) \quad (+ \text{ left}, - \text{ right}) \\
        z &= -C\cos\theta\cos\beta - (X_{dis} + r)\sin\beta

    The regression came from 25 hip radiographs (Davis et al. 1991); its error is about
    1-2 cm in an adult (Baker 2013 [4]_).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait import davis_hip_centre
    >>> hjc = davis_hip_centre(np.eye(3), np.zeros(3), mean_leg_length=871.5,
    ...                        asis_trochanter=64.4, inter_asis_distance=306.0,
    ...                        marker_radius=7.0, side="left")
    >>> hjc.round(2) + 0.0
    array([-44.89, 112.29, -92.94])
    """
    C = DAVIS_C_SLOPE * mean_leg_length + DAVIS_C_INTERCEPT
    theta, beta = DAVIS_THETA, DAVIS_BETA
    lateral = inter_asis_distance / 2.0 - C * np.sin(theta)
    local = np.array([C * np.cos(theta) * np.sin(beta)
                      - (asis_trochanter + marker_radius) * np.cos(beta),
                      lateral if side == "left" else -lateral,
                      -C * np.cos(theta) * np.cos(beta)
                      - (asis_trochanter + marker_radius) * np.sin(beta)])
    R = np.asarray(R_pelvis, dtype=float)
    return np.asarray(origin, dtype=float) + R @ local


def chord_joint_centre(wand, proximal_centre, lateral_marker, delta):
    r"""The chord function: a joint centre from a wand, the proximal centre and a width.

    The distal joint centre :math:`J` of a segment is placed so that

    1. it lies in the plane of the wand marker :math:`W`, the proximal joint centre
       :math:`P` and the lateral marker :math:`M`;
    2. it is `delta` from :math:`M` (half the joint width plus the marker radius);
    3. the line :math:`M - J` (the joint's flexion axis) is perpendicular to the line
       :math:`P - J` (the segment's long axis).

    Parameters
    ----------
    wand : array_like, shape (..., 3)
        THI for the knee, TIB for the ankle (mm).
    proximal_centre : array_like, shape (..., 3)
        The hip centre for the knee, the knee centre for the ankle.
    lateral_marker : array_like, shape (..., 3)
        KNE for the knee, ANK for the ankle.
    delta : float
        Knee (ankle) width / 2 + marker diameter / 2 (mm).

    Returns
    -------
    ndarray, shape (..., 3)
        The joint centre (mm). NaN where a point is missing, or where `delta` is not
        shorter than :math:`|M - P|` (no such triangle).

    Notes
    -----
    By condition 3, :math:`J` lies on the circle with diameter :math:`PM` (Thales). With
    :math:`d = |M - P|`, the right triangle :math:`P J M` has hypotenuse :math:`d` and
    legs :math:`\delta` and :math:`\ell = \sqrt{d^2 - \delta^2}`; the angle at :math:`P`
    is :math:`\varphi` with :math:`\sin\varphi = \delta/d`. With :math:`\hat e_1 = (M -
    P)/d` and :math:`\hat e_2` the unit vector in the plane perpendicular to
    :math:`\hat e_1` on the wand's side,

    .. math:: J = P + \ell\cos\varphi\,\hat e_1 - \ell\sin\varphi\,\hat e_2
                = P + \frac{\ell^2}{d}\,\hat e_1 - \frac{\ell\,\delta}{d}\,\hat e_2 ,

    the solution on the side away from the wand (the joint is medial to the marker and
    the wand stands out laterally). This reproduces Vicon's knee and ankle centres to
    1e-4 mm on the shared trial (tests/test_plug_in_gait.py).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait import chord_joint_centre
    >>> J = chord_joint_centre([100, 0, 300], [0, 0, 400], [60, 0, 0], 60.0)
    >>> J.round(6) + 0.0
    array([0., 0., 0.])
    >>> float(np.linalg.norm(J - [60, 0, 0]))
    60.0
    """
    # W, P, M, d: the names of the Notes (the construction is read against them)
    W = check_vectors(wand, "wand")
    P = check_vectors(proximal_centre, "proximal_centre")
    M = check_vectors(lateral_marker, "lateral_marker")
    if _stacks_of_vectors(W, P, M) and np.ndim(delta) == 0:    # frames of a trial
        return _chord_rows(W, P, M, delta)
    v = M - P
    d = vector_length(v)[..., None]
    e1 = v / d
    w = W - P
    w = w - vector_dot(w, e1)[..., None] * e1
    e2 = _unit(w)
    with np.errstate(invalid="ignore"):
        legs = d ** 2 - delta ** 2
        legs = np.where(legs > 0, legs, np.nan)
        return P + legs / d * e1 - np.sqrt(legs) * delta / d * e2


def _subtract_along(v, amount, direction, scratch):
    """``v -= amount * direction`` for component rows (3, ...), row by row through
    `scratch` (no (3, ...) temporary on fresh pages); `amount` and `scratch` apart."""
    for k in range(3):            # v[k]: a row, or an item of a single vector, in place
        v[k] -= np.multiply(amount, direction[k], out=scratch)
    return v


def _stacks_of_vectors(*arrays):
    """Whether the arrays are (frames, 3) stacks of one shape, more than one frame, each
    contiguous by rows or by columns (any other layout, a view with steps or reversed,
    takes the plain formula): numpy's arithmetic on them returns a column-major array if
    all are column-major, a row-major one otherwise."""
    shape = arrays[0].shape
    return (len(shape) == 2 and shape[0] > 1
            and all(a.shape == shape and (a.flags.c_contiguous or a.flags.f_contiguous)
                    for a in arrays))


def _chord_rows(W, P, M, delta):
    """chord_joint_centre's construction on (frames, 3) stacks, bit for bit: each
    operation of the plain formula, in its order, on contiguous component rows in place
    (about 1.5 times faster than on the strided columns and their temporaries), the
    result laid out as the plain formula's (column-major if all three stacks are)."""
    shape = W.shape
    w, p, v = (_component_rows(a, shape) for a in (W, P, M))
    v -= p                                                       # v = M - P
    length, scratch = np.empty(shape[:-1]), np.empty(shape[:-1])
    d = np.sqrt(dot_rows(v, v, length, scratch))
    e1 = np.divide(v, d, out=v)
    w -= p                                                       # w = W - P
    _subtract_along(w, dot_rows(w, e1, length, scratch), e1, scratch)
    e2 = np.divide(w, np.sqrt(dot_rows(w, w, length, scratch), out=length), out=w)
    with np.errstate(invalid="ignore"):
        legs = d ** 2 - delta ** 2
        legs = np.where(legs > 0, legs, np.nan)
        # P + legs / d * e1 - np.sqrt(legs) * delta / d * e2, operation by operation
        # each product's operands in the formula's order (a NaN's sign is the first's)
        np.multiply(np.divide(legs, d, out=scratch), e1, out=e1)
        np.multiply(np.divide(np.multiply(np.sqrt(legs), delta, out=length), d, out=length),
                    e2, out=e2)
        p += e1
        p -= e2
    if all(a.flags.f_contiguous for a in (W, P, M)):
        return p.T                               # (frames, 3) column-major, as numpy's
    J = np.empty(shape)
    J.T[...] = p
    return J


def cgm_femur_frame(hip_centre, knee_centre, knee_marker, side):
    """The CGM femur: z from the knee centre to the hip centre, y along the knee's axis.

    Parameters
    ----------
    hip_centre, knee_centre, knee_marker : array_like, shape (..., 3)
        Hip centre, knee centre (:func:`chord_joint_centre`) and the KNE marker (mm).
    side : {'right', 'left'}

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Columns x (anterior), y (left), z (proximal). The y axis is the line from the
        knee centre to KNE (laterally on the left, medially on the right: y points to
        the subject's left on both sides, as in Plug-in Gait), made perpendicular to z.

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait import cgm_femur_frame
    >>> cgm_femur_frame([0, 0, 800], [0, 0, 400], [0, -60, 400], "right").round(3) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    hip, knee = np.asarray(hip_centre, float), np.asarray(knee_centre, float)
    lateral = np.asarray(knee_marker, float) - knee
    return axes_zy(y=-MIRROR[side] * lateral, z=hip - knee)


def cgm_tibia_frame(knee_centre, ankle_centre, ankle_marker, side, torsion=0.0):
    r"""The CGM tibia: z from the ankle centre to the knee centre, y along the ankle axis.

    Parameters
    ----------
    knee_centre, ankle_centre, ankle_marker : array_like, shape (..., 3)
        Knee centre, ankle centre and the ANK marker (mm).
    side : {'right', 'left'}
    torsion : float, optional
        Tibial torsion (radians, Vicon's ``LeftTibialTorsion``): the angle about the
        tibia's long axis from the knee flexion axis to the ankle flexion axis.

    Returns
    -------
    torsioned : ndarray, shape (..., 3, 3)
        The tibia whose y axis is the ankle flexion axis (centre to ANK): the proximal
        segment of the ankle angles (Vicon's ``LTIO`` axes).
    untorsioned : ndarray, shape (..., 3, 3)
        The same turned about z by the torsion, so that its y axis is the knee flexion
        axis: the distal segment of the knee angles.

    Notes
    -----
    Plug-in Gait [3]_ keeps two tibiae for this reason. Vicon's own definition of the
    knee angles (its BodyLanguage model, quoted in pyCGM2's source [6]_) subtracts the
    torsion from the knee rotation of the torsioned tibia: ``RKneeAngles`` Z = rotation
    :math:`- t_R`, ``LKneeAngles`` Z = (mirrored rotation) :math:`- t_L`. Turning the
    distal frame about its own z axis by :math:`\varphi` adds :math:`\varphi` to the third
    y-x-z angle and changes nothing else, so the untorsioned tibia is
    :math:`R\,R_z(\mp t)` (- right, + left: the left side's rotation is reported with the
    opposite sign). The shared Vicon trial has zero torsion, so this sign rests on that
    definition, not on a comparison with Vicon's output.

    References
    ----------
    .. [6] Leboeuf F et al. (2019). pyCGM2 (github.com/pyCGM2/pyCGM2), the knee-angle
       comments ``RKNA=<1(RKNA),2(RKNA),3(RKNA)-$RTibialTorsion>`` and
       ``LKNA=<1(LKNA),-2(LKNA),-3(LKNA)-$LTibialTorsion>``.

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait import cgm_tibia_frame
    >>> tors, untors = cgm_tibia_frame([0, 0, 400], [0, 0, 0], [0, -50, 0], "right")
    >>> tors.round(3) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    knee, ankle = np.asarray(knee_centre, float), np.asarray(ankle_centre, float)
    lateral = np.asarray(ankle_marker, float) - ankle
    torsioned = axes_zy(y=-MIRROR[side] * lateral, z=knee - ankle)
    untorsioned = torsioned @ rot_z(-MIRROR[side] * torsion) if torsion else torsioned
    return torsioned, untorsioned


def cgm_uncorrected_foot_frame(ankle_centre, toe, R_tibia):
    """The foot before the static offsets: z from TOE to the ankle centre, y the ankle axis.

    Parameters
    ----------
    ankle_centre, toe : array_like, shape (..., 3)
        Ankle centre and the TOE marker (mm).
    R_tibia : array_like, shape (..., 3, 3)
        The (torsioned) tibia, :func:`cgm_tibia_frame`: its y axis is the ankle's.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Columns x (up, out of the sole's plane), y (left), z (from the toe back to the
        ankle).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait import cgm_uncorrected_foot_frame
    >>> cgm_uncorrected_foot_frame([0, 0, 80], [150, 0, 80], np.eye(3)).round(3) + 0.0
    array([[ 0.,  0., -1.],
           [ 0.,  1.,  0.],
           [ 1.,  0.,  0.]])
    """
    ankle, toe = np.asarray(ankle_centre, float), np.asarray(toe, float)
    return axes_zy(y=np.asarray(R_tibia, float)[..., :, 1], z=ankle - toe)


def cgm_static_foot_frame(heel, toe, R_tibia):
    """The foot of the static trial: z from TOE to HEE, y the ankle axis.

    Parameters
    ----------
    heel, toe : array_like, shape (..., 3)
        HEE and TOE markers (mm).
    R_tibia : array_like, shape (..., 3, 3)
        The torsioned tibia.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        What Plug-in Gait's static processing writes as the foot (``LFOO`` axes in the
        static trial): the heel-toe line is the foot's long axis.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait import cgm_static_foot_frame
    >>> cgm_static_foot_frame([-50, 0, 30], [150, 0, 30], np.eye(3)).round(3) + 0.0
    array([[ 0.,  0., -1.],
           [ 0.,  1.,  0.],
           [ 1.,  0.,  0.]])
    """
    return axes_zy(y=np.asarray(R_tibia, float)[..., :, 1],
                  z=np.asarray(heel, float) - np.asarray(toe, float))


def static_foot_offsets(R_uncorrected, R_static_foot, side):
    r"""Plug-in Gait's static offsets of the foot: plantar flexion and rotation (radians).

    Parameters
    ----------
    R_uncorrected : array_like, shape (frames, 3, 3)
        :func:`cgm_uncorrected_foot_frame` in the static trial.
    R_static_foot : array_like, shape (frames, 3, 3)
        :func:`cgm_static_foot_frame` in the static trial.
    side : {'right', 'left'}

    Returns
    -------
    plantar_flexion, rotation : float
        Vicon's ``StaticPlantFlex`` and ``StaticRotOff`` (radians), the means over the
        frames where both feet are defined.

    Raises
    ------
    ValueError
        If no frame has both frames defined (a marker missing throughout).

    Notes
    -----
    The relative rotation :math:`R_u^T R_s` is decomposed in the Cardan sequence y-x-z,
    :math:`R_y(a) R_x(b) R_z(c)`: the heel-toe line is pitched by :math:`a` about the
    ankle axis and turned by :math:`b` about the axis normal to the sole. Then
    ``StaticPlantFlex`` :math:`= -a` and ``StaticRotOff`` :math:`= \pm b` (+ right,
    - left). The roll :math:`c` about the foot's long axis is not kept (the CGM has no
    sensor of it). These reproduce what Nexus wrote for the shared subject within
    1e-6 rad.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import rot_y
    >>> from bmc_functions.models.plug_in_gait import static_foot_offsets
    >>> Ru = np.eye(3)[None]
    >>> pf, rot = static_foot_offsets(Ru, Ru @ rot_y(-0.25), "right")
    >>> round(pf, 6), round(rot, 6) + 0.0
    (0.25, 0.0)
    """
    Ru, Rs = np.asarray(R_uncorrected, float), np.asarray(R_static_foot, float)
    relative = np.swapaxes(Ru, -1, -2) @ Rs
    valid = np.isfinite(relative).all(axis=(-1, -2))
    if not valid.any():
        raise ValueError("static: the foot is undefined in every frame of the static trial "
                         "(a marker of the foot or shank missing throughout)")
    a, b, _ = decompose(relative[valid], "YXZ").mean(axis=0)
    return float(-a), float(MIRROR[side] * b)


def cgm_foot_frame(R_uncorrected, plantar_flexion, rotation, side):
    r"""The CGM foot: the uncorrected foot turned by the static offsets.

    Parameters
    ----------
    R_uncorrected : array_like, shape (..., 3, 3)
        :func:`cgm_uncorrected_foot_frame`.
    plantar_flexion, rotation : float
        ``StaticPlantFlex`` and ``StaticRotOff`` (radians), :func:`static_foot_offsets`.
    side : {'right', 'left'}

    Returns
    -------
    ndarray, shape (..., 3, 3)
        :math:`R_u\,R_y(-p)\,R_x(\pm r)` (+ right, - left): in the static posture the
        foot's z axis is the heel-toe line (up to its roll), in every trial the foot
        moves with the toe marker and the ankle centre.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait import cgm_foot_frame
    >>> cgm_foot_frame(np.eye(3), 0.0, 0.0, "left").round(3) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    turn = rot_y(-plantar_flexion) @ rot_x(MIRROR[side] * rotation)
    return np.asarray(R_uncorrected, float) @ turn


def progression_frame(pelvis_origin, R_pelvis):
    """The direction of progression, as a lab frame: x forward, y left, z up.

    Parameters
    ----------
    pelvis_origin : array_like, shape (frames, 3)
        A point of the pelvis (mm): Plug-in Gait uses LASI.
    R_pelvis : array_like, shape (frames, 3, 3)
        The CGM pelvis axes.

    Returns
    -------
    ndarray, shape (3, 3)
        Columns: forward, left and up, each a signed lab axis. Up: the lab axis closest to
        the pelvis's mean z axis. Forward: the horizontal lab axis closest to the point's
        displacement from its first to its last defined frame, when that displacement is
        longer than ``PROGRESSION_MIN_PATH`` (800 mm, Vicon's threshold); otherwise (a
        trial that does not travel: a static trial, a swing, a throw) the horizontal lab
        axis closest to the pelvis's forward axis in the first frame in which the pelvis
        is defined. NaN when the pelvis is never defined.

    Notes
    -----
    Plug-in Gait reports the pelvis, thorax, head and foot-progression angles against the
    direction of progression, a lab axis chosen from the subject's motion [3]_; on a
    diagonal walkway the pelvis rotation is offset by the walkway's angle. For a trial
    that travels, Vicon compares the X and Y displacements of LASI between its first and
    last valid frames; below 800 mm, its FAQ describes the pelvis's facing direction
    (ASIS midpoint minus sacrum) averaged over 10% of the frames in the middle of the
    trial, pyCGM2 takes it in the first valid frame, and on a real swing processed by
    Nexus (issue 34) the first frame reproduces Vicon's pelvis, thorax and head angles
    where a mean over the whole trial is 90 degrees off: the first frame is used here.
    The pelvis's x axis is that facing direction made perpendicular to RASI-LASI, which
    points to the same lab axis.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait import progression_frame
    >>> path = np.column_stack([np.linspace(1000, -300, 5), np.zeros(5), np.full(5, 900.)])
    >>> progression_frame(path, np.repeat(np.eye(3)[None], 5, axis=0)) + 0.0
    array([[-1.,  0.,  0.],
           [ 0., -1.,  0.],
           [ 0.,  0.,  1.]])
    """
    origin, R = np.asarray(pelvis_origin, float), np.asarray(R_pelvis, float)
    valid = np.isfinite(R).all(axis=(1, 2)) & np.isfinite(origin).all(axis=1)
    if not valid.any():
        return np.full((3, 3), np.nan)
    up, up_axis = nearest_lab_axis(R[valid][:, :, 2].mean(axis=0))
    path = origin[valid][-1] - origin[valid][0]
    forward = path - (path @ up) * up if np.linalg.norm(path) > PROGRESSION_MIN_PATH \
        else R[valid][0][:, 0]
    x, _ = nearest_lab_axis(forward, exclude=up_axis)
    return np.column_stack([x, np.cross(up, x), up])


def yxz_angles(R_proximal, R_distal, check=True):
    """Cardan y-x-z angles (degrees) of the distal frame relative to the proximal one.

    With `check` False the relative rotations are not tested for orthonormality
    (:func:`~bmc_functions.rigid_body.cardan.decompose_orthonormal`): for segment axes the
    package built itself.
    """
    relative = np.swapaxes(R_proximal, -1, -2) @ R_distal
    return (decompose if check else decompose_orthonormal)(relative, "YXZ", degrees=True)


def wrap_degrees(angle):
    return (angle + 180.0) % 360.0 - 180.0


def cgm_angles(R_progression, R_pelvis, R_femur, R_tibia_knee, R_tibia_ankle, R_foot,
               side, *, check=True):
    r"""Plug-in Gait's angles of one side (degrees), with Vicon's components and signs.

    Parameters
    ----------
    R_progression : array_like, shape (3, 3)
        :func:`progression_frame`.
    R_pelvis, R_femur, R_tibia_knee, R_tibia_ankle, R_foot : array_like, (frames, 3, 3)
        The segment axes: pelvis, femur, untorsioned tibia (knee angles), torsioned tibia
        (ankle angles), foot.
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
        (joint, angle) -> (frames,) degrees, the keys of ``CGM_ANGLES``.

    Notes
    -----
    Every angle is a Cardan decomposition in the sequence y-x-z (flexion about the
    proximal y, then ab/adduction about the floating x, then rotation about the distal
    z, as Grood and Suntay's joint coordinate system), :math:`R_p^T R_d = R_y(a)
    R_x(b) R_z(c)`. With :math:`s = +1` on the right and :math:`-1` on the left:

    =========================== ======================================================
    pelvis (against progression) tilt :math:`a`, obliquity :math:`-s\,b`, rotation
                                :math:`s\,c`
    hip (pelvis to femur)        flexion :math:`-a`, adduction :math:`s\,b`, rotation
                                :math:`s\,c`
    knee (femur to tibia)        flexion :math:`a`, adduction :math:`s\,b`, rotation
                                :math:`s\,c`
    ankle (tibia to foot)        dorsiflexion :math:`-a - 90°`, inversion :math:`s\,c`,
                                rotation :math:`s\,b`
    foot (against progression)   progression :math:`s\,b`
    =========================== ======================================================

    The foot's z axis runs along the foot (toe to ankle), so the ankle's middle angle is
    a rotation about the axis normal to the sole and its third a roll about the foot's
    long axis; 90° is taken off the flexion because the foot is perpendicular to the
    tibia in the neutral posture. These signs reproduce Vicon's stored curves (knee
    flexion positive flexed, hip flexion positive flexed, dorsiflexion positive,
    adduction, internal rotation and inversion positive on both sides).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait import cgm_angles
    >>> I = np.eye(3)[None]
    >>> foot = I @ np.array([[0, 0, -1.], [0, 1, 0], [1, 0, 0]])   # z back along the foot
    >>> a = cgm_angles(np.eye(3), I, I, I, I, foot, "right")
    >>> {k: round(float(v[0]), 6) + 0.0 for k, v in a.items()}["ankle", "dorsiflexion"]
    0.0
    """
    s = MIRROR[side]
    check = check_flag(check, "check")
    # the five relative rotations, written into one array, decomposed in one call
    pairs = ((R_progression, R_pelvis), (R_pelvis, R_femur), (R_femur, R_tibia_knee),
             (R_tibia_ankle, R_foot), (R_progression, R_foot))
    shape = np.broadcast_shapes(*(np.shape(R) for pair in pairs for R in pair))
    relative = np.empty((len(pairs),) + shape)
    for k, (proximal, distal) in enumerate(pairs):
        np.matmul(np.swapaxes(np.asarray(proximal, float), -1, -2),
                  np.asarray(distal, float), out=relative[k])
    pelvis, hip, knee, ankle, foot = (decompose if check else decompose_orthonormal)(
        relative, "YXZ", degrees=True)                     # as yxz_angles does
    return {("pelvis", "tilt"): pelvis[:, 0], ("pelvis", "obliquity"): -s * pelvis[:, 1],
            ("pelvis", "rotation"): s * pelvis[:, 2],
            ("hip", "flexion"): -hip[:, 0], ("hip", "adduction"): s * hip[:, 1],
            ("hip", "rotation"): s * hip[:, 2],
            ("knee", "flexion"): knee[:, 0], ("knee", "adduction"): s * knee[:, 1],
            ("knee", "rotation"): s * knee[:, 2],
            ("ankle", "dorsiflexion"): wrap_degrees(-ankle[:, 0] - 90.0),
            ("ankle", "inversion"): s * ankle[:, 2], ("ankle", "rotation"): s * ankle[:, 1],
            ("foot", "progression"): s * foot[:, 1]}

