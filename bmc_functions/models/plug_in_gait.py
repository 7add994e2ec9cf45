r"""The Conventional Gait Model (Vicon Plug-in Gait, lower limb), step by step.

Most clinical gait laboratories place the Plug-in Gait markers (LASI/RASI, LPSI/RPSI or
SACR; on each side a thigh wand THI, the lateral knee KNE, a tibia wand TIB, the lateral
ankle ANK, HEE and TOE) and report the angles of the Conventional Gait Model (CGM:
Davis et al. 1991 [1]_; Kadaba et al. 1990 [2]_), as Vicon's Plug-in Gait computes them
[3]_. There are no medial markers: the knee and ankle centres are found from the lateral
marker, a wand marker and the measured joint width (the *chord function*), and the hip
centre from a regression on the leg length (Davis et al. 1991)::

    model = plug_in_gait("Static.c3d", "Subject.vsk")   # static trial, subject measurements
    angles = model.angles("Walk.c3d")                     # degrees, one row per frame
    angles["knee", "right", "flexion"]

The steps, each a function of its own (arrays in, arrays out, frames on the first axis):

1. :func:`cgm_pelvis_frame` - origin between the ASIS markers, y from RASI to LASI, x
   forward (towards the ASIS from the sacrum), z up.
2. :func:`davis_hip_centre` - the hip centre in the pelvis frame from the leg length,
   the ASIS-trochanter distance (:func:`asis_trochanter_distance`) and the inter-ASIS
   distance.
3. :func:`chord_joint_centre` - the knee centre from THI, the hip centre, KNE and the
   knee width; the ankle centre from TIB, the knee centre, ANK and the ankle width.
4. :func:`cgm_femur_frame`, :func:`cgm_tibia_frame` (with the tibial torsion),
   :func:`cgm_uncorrected_foot_frame` (ankle centre to TOE) and
   :func:`cgm_foot_frame` (the static offsets applied).
5. :func:`static_foot_offsets` - in the static trial, the plantar-flexion and rotation
   offsets between the uncorrected foot and the foot defined by HEE and TOE.
6. :func:`cgm_angles` - the Cardan angles (sequence y-x-z) with Vicon's signs, and the
   pelvis and foot-progression angles against the direction of progression
   (:func:`progression_frame`).

Segment axes as in Plug-in Gait: x anterior, y to the subject's left (for the segments
of both sides), z proximal (up the segment); the foot's z points from the toe back
towards the ankle. Lengths in mm; angles in the subject measurements in radians (as
Vicon stores them); output angles in degrees.

References
----------
.. [1] Davis RB, Ounpuu S, Tyburski D, Gage JR (1991). A gait analysis data collection
   and reduction technique. Human Movement Science 10(5), 575-587.
.. [2] Kadaba MP, Ramakrishnan HK, Wootten ME (1990). Measurement of lower extremity
   kinematics during level walking. Journal of Orthopaedic Research 8(3), 383-392.
.. [3] Vicon Motion Systems (2010-2017). Plug-in Gait reference guide / Plug-in Gait
   product guide (Nexus 2): lower-body model, chord function, static processing.
.. [4] Baker R (2013). Measuring walking: a handbook of clinical gait analysis. Mac
   Keith Press. (The CGM's definitions and their criticism.)
.. [5] Baker R (2006). Gait analysis methods in rehabilitation. Journal of
   NeuroEngineering and Rehabilitation 3, 4.
"""

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

# Parsers of the subject tables (:func:`load_subject`): tomllib is in the standard library
# from Python 3.11 (tomli before, a dependency there); PyYAML is optional. A missing one
# is reported when a file needs it.
try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    try:
        import tomli as tomllib
    except ModuleNotFoundError:
        tomllib = None
try:
    import yaml
except ModuleNotFoundError:
    yaml = None

from .._checks import ArgumentTypeError, check_choice, check_vectors, warn, warn_frames
from ..files.c3d_parameters import VICON_SUBJECT_NAMES, subject_parameters
from ..files.opensim import opensim_coordinates
from ..files.trial import MarkerTable, load_trial, mm_per_unit
from ..files.vsk import read_vsk
from ..rigid_body.cardan import decompose
from ..rigid_body.frames import nearest_lab_axis
from ..rigid_body.rotations import rot_x, rot_y, rot_z
from .lower_limb_checks import (LEGS_CROSSED, check_still, check_units, report_flagged_frames,
                                visible_centroid)

#: Default marker diameter (mm) when the subject gives none: Plug-in Gait's default [3].
DEFAULT_MARKER_DIAMETER = 14.0

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

#: Measurements without which the model cannot be built (Plug-in Gait marks them REQUIRED).
REQUIRED = ("LeftLegLength", "RightLegLength", "LeftKneeWidth", "RightKneeWidth",
            "LeftAnkleWidth", "RightAnkleWidth")

#: Offsets of the knee alignment device and of the static ankle abduction: this
#: implementation does not apply them, so a non-zero value is refused (never ignored).
NOT_APPLIED = ("LeftThighRotation", "RightThighRotation", "LeftShankRotation",
               "RightShankRotation", "LeftAnkleAbAdd", "RightAnkleAbAdd")

#: The sole thickness of the static processing's flat-foot option (not implemented): a
#: non-zero value is refused when a static trial is processed here; without one it plays
#: no part (the offsets come from the subject).
STATIC_ONLY_NOT_APPLIED = ("LeftSoleDelta", "RightSoleDelta")

#: Plug-in Gait's marker names (lower body) and the segment each belongs to.
PELVIS_MARKERS = ("LASI", "RASI", "LPSI", "RPSI", "SACR")
LEG_MARKERS = ("THI", "KNE", "TIB", "ANK", "HEE", "TOE")

#: The angles returned, per joint, with the Vicon output they reproduce (X, Y, Z).
CGM_ANGLES = {"pelvis": ("tilt", "obliquity", "rotation"),
              "hip": ("flexion", "adduction", "rotation"),
              "knee": ("flexion", "adduction", "rotation"),
              "ankle": ("dorsiflexion", "inversion", "rotation"),
              "foot": ("progression",)}

#: Order of the angle names in the columns' third level (each joint's in increasing order).
_ANGLE_ORDER = ("tilt", "obliquity", "flexion", "adduction", "dorsiflexion", "inversion",
                "rotation", "progression")

#: Vicon's name of each output (the L or R prefix added), and the component used.
VICON_OUTPUTS = {("pelvis", "tilt"): ("PelvisAngles", 0),
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

#: Horizontal distance (mm) the pelvis must travel for the direction of progression to be
#: taken from its path; below it (a static trial), from the pelvis's forward axis.
PROGRESSION_MIN_PATH = 250.0

SIDES = ("right", "left")
_PREFIX = {"right": "R", "left": "L"}
_LONG = {"right": "Right", "left": "Left"}
#: +1 right, -1 left: Plug-in Gait reports the left side's out-of-plane angles with the
#: sign that makes adduction, internal rotation and inversion positive on both sides.
_MIRROR = {"right": 1.0, "left": -1.0}


# --- the model's steps (arrays in, arrays out) ----------------------------------------

def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _frame(y=None, z=None):
    """Columns x, y, z from z (exact) and a direction y (made perpendicular to z).

    Gram-Schmidt as in :func:`~bmc_functions.rigid_body.frames.frame_from_axes` (axes 'zy'), written
    out here without its argument checks: this runs nine times per trial on every frame,
    on points already checked, and a missing marker must give NaN, not an error."""
    with np.errstate(invalid="ignore", divide="ignore"):
        z = _unit(np.asarray(z, dtype=float))
        y = np.asarray(y, dtype=float)
        y = _unit(y - np.sum(y * z, axis=-1, keepdims=True) * z)
        x = np.cross(y, z)
    return np.stack([x, y, z], axis=-1)


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
    R = _frame(y=lasi - rasi, z=np.cross(origin - sacrum, lasi - rasi))
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
    v = M - P
    d = np.linalg.norm(v, axis=-1, keepdims=True)
    e1 = v / d
    w = W - P
    w = w - np.sum(w * e1, axis=-1, keepdims=True) * e1
    e2 = _unit(w)
    with np.errstate(invalid="ignore"):
        legs = d ** 2 - delta ** 2
        legs = np.where(legs > 0, legs, np.nan)
        return P + legs / d * e1 - np.sqrt(legs) * delta / d * e2


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
    return _frame(y=-_MIRROR[side] * lateral, z=hip - knee)


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
    torsioned = _frame(y=-_MIRROR[side] * lateral, z=knee - ankle)
    untorsioned = torsioned @ rot_z(-_MIRROR[side] * torsion) if torsion else torsioned
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
    return _frame(y=np.asarray(R_tibia, float)[..., :, 1], z=ankle - toe)


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
    return _frame(y=np.asarray(R_tibia, float)[..., :, 1],
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
    return float(-a), float(_MIRROR[side] * b)


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
    turn = rot_y(-plantar_flexion) @ rot_x(_MIRROR[side] * rotation)
    return np.asarray(R_uncorrected, float) @ turn


def progression_frame(pelvis_origin, R_pelvis):
    """The direction of progression, as a lab frame: x forward, y left, z up.

    Parameters
    ----------
    pelvis_origin : array_like, shape (frames, 3)
        A point of the pelvis (mm).
    R_pelvis : array_like, shape (frames, 3, 3)
        The CGM pelvis axes.

    Returns
    -------
    ndarray, shape (3, 3)
        Columns: forward, left and up, each a signed lab axis. Up: the lab axis closest to
        the pelvis's mean z axis. Forward: the horizontal lab axis closest to the pelvis's
        path from its first to its last defined frame, when that path is longer than
        ``PROGRESSION_MIN_PATH`` (250 mm); otherwise (a static trial) closest to the
        pelvis's mean forward axis. NaN when the pelvis is never defined.

    Notes
    -----
    Plug-in Gait reports the pelvis and foot-progression angles against the direction of
    progression, a lab axis chosen from the subject's motion [3]_; on a diagonal walkway
    the pelvis rotation is offset by the walkway's angle. Vicon's exact rule for a subject
    who hardly moves is not stated in the sources used here; this one (the same as
    :func:`~bmc_functions.calibrate_lower_limb`'s) reproduces the shared static and
    dynamic trials.

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
    path = path - (path @ up) * up
    forward = path if np.linalg.norm(path) > PROGRESSION_MIN_PATH \
        else R[valid][:, :, 0].mean(axis=0)
    x, _ = nearest_lab_axis(forward, exclude=up_axis)
    return np.column_stack([x, np.cross(up, x), up])


#: Angle (degrees) between the pelvis's path and the lab axis taken as the direction of
#: progression above which a trial warns (as the ISB pipeline,
#: :data:`bmc_functions.models.lower_limb.PROGRESSION_WARN_DEG`).
PROGRESSION_WARN_DEG = 20.0


def _warn_diagonal(pelvis_origin, R_progression, label):
    """One warning when the pelvis travels more than PROGRESSION_WARN_DEG from the lab
    axis taken as forward (a diagonal walkway): Plug-in Gait, Vicon's included, reports
    the pelvis and foot-progression angles against that axis."""
    valid = np.isfinite(pelvis_origin).all(axis=1)
    if not valid.any() or not np.isfinite(R_progression).all():
        return
    up, forward = R_progression[:, 2], R_progression[:, 0]
    path = pelvis_origin[valid][-1] - pelvis_origin[valid][0]
    path = path - (path @ up) * up
    if np.linalg.norm(path) <= PROGRESSION_MIN_PATH:
        return
    angle = float(np.degrees(np.arctan2(np.linalg.norm(np.cross(path, forward)),
                                        path @ forward)))
    if angle > PROGRESSION_WARN_DEG:
        warn(f"the pelvis in {label} travels {angle:.0f} degrees from the lab axis "
             f"taken as the direction of progression (the nearest one; warning "
             f"above {PROGRESSION_WARN_DEG:.0f} degrees): Plug-in Gait (Vicon's "
             f"too) reports the pelvis angles and foot progression against that "
             f"axis, so pelvis rotation and foot progression read about "
             f"{angle:.0f} degrees off. Rotate the marker coordinates so that the "
             f"walkway runs along a lab axis", RuntimeWarning)


def _yxz(R_proximal, R_distal):
    """Cardan y-x-z angles (degrees) of the distal frame relative to the proximal one."""
    relative = np.swapaxes(R_proximal, -1, -2) @ R_distal
    return decompose(relative, "YXZ", degrees=True)


def _wrap(angle):
    return (angle + 180.0) % 360.0 - 180.0


def cgm_angles(R_progression, R_pelvis, R_femur, R_tibia_knee, R_tibia_ankle, R_foot,
               side):
    r"""Plug-in Gait's angles of one side (degrees), with Vicon's components and signs.

    Parameters
    ----------
    R_progression : array_like, shape (3, 3)
        :func:`progression_frame`.
    R_pelvis, R_femur, R_tibia_knee, R_tibia_ankle, R_foot : array_like, (frames, 3, 3)
        The segment axes: pelvis, femur, untorsioned tibia (knee angles), torsioned tibia
        (ankle angles), foot.
    side : {'right', 'left'}

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
    s = _MIRROR[side]
    # the five relative rotations decomposed in one call
    proximal = np.stack(np.broadcast_arrays(R_progression, R_pelvis, R_femur, R_tibia_ankle,
                                            R_progression))
    distal = np.stack(np.broadcast_arrays(R_pelvis, R_femur, R_tibia_knee, R_foot, R_foot))
    pelvis, hip, knee, ankle, foot = _yxz(proximal, distal)
    return {("pelvis", "tilt"): pelvis[:, 0], ("pelvis", "obliquity"): -s * pelvis[:, 1],
            ("pelvis", "rotation"): s * pelvis[:, 2],
            ("hip", "flexion"): -hip[:, 0], ("hip", "adduction"): s * hip[:, 1],
            ("hip", "rotation"): s * hip[:, 2],
            ("knee", "flexion"): knee[:, 0], ("knee", "adduction"): s * knee[:, 1],
            ("knee", "rotation"): s * knee[:, 2],
            ("ankle", "dorsiflexion"): _wrap(-ankle[:, 0] - 90.0),
            ("ankle", "inversion"): s * ankle[:, 2], ("ankle", "rotation"): s * ankle[:, 1],
            ("foot", "progression"): s * foot[:, 1]}


# --- subject measurements ------------------------------------------------------------

#: Vicon's name of each measurement, keyed by the name in lower case, long ('leftleglength')
#: and short ('lleglength', as a C3D's PROCESSING group writes it): C3D parameter names
#: are case-insensitive, and subject files of other labs do not all keep Vicon's case.
_NAME_OF = {name.lower(): name for name in VICON_SUBJECT_NAMES}
_NAME_OF.update({short + name[len(long):].lower(): name for name in VICON_SUBJECT_NAMES
                 for short, long in (("l", "Left"), ("r", "Right")) if name.startswith(long)})


def _canonical(name):
    """Vicon's .vsk name for a PROCESSING (C3D) or .vsk name in any case:
    LLegLength, LEFTLEGLENGTH -> LeftLegLength; other names unchanged."""
    return _NAME_OF.get(name.lower(), name)


def _optional_parser(module, name):
    """`module` if it was imported, else the ModuleNotFoundError naming the package."""
    if module is None:
        raise ModuleNotFoundError(f"No module named {name!r}", name=name)
    return module


def _read_subject_table(path):
    """A TOML, JSON or YAML file of Vicon's measurement names -> numbers (a dict); the
    table may sit under a key ``subject``."""
    suffix = path.suffix.lower()
    try:
        text = path.read_bytes().decode("utf-8")
        if suffix == ".toml":
            data = _optional_parser(tomllib, "tomli").loads(text)
        elif suffix == ".json":
            data = json.loads(text)
        else:
            data = _optional_parser(yaml, "yaml").safe_load(text)
    except ModuleNotFoundError as err:
        raise ValueError(f"subject: reading {path.name} needs the package {err.name} (pip "
                         f"install {'pyyaml' if err.name == 'yaml' else err.name}); or "
                         f"write the measurements as JSON") from None
    except Exception as err:     # the parser's own message (a syntax error, bad UTF-8)
        raise ValueError(f"subject: {path} could not be read as {suffix[1:].upper()}: "
                         f"{err}") from None
    if isinstance(data, dict) and isinstance(data.get("subject"), dict):
        data = data["subject"]
    if not isinstance(data, dict):
        raise ValueError(f"subject: {path} must hold a table of Vicon's measurement names "
                         f"(LeftLegLength = 877.0, ...); got {type(data).__name__}")
    return data


def load_subject(subject):
    """The subject measurements as a dict with Vicon's .vsk names.

    Parameters
    ----------
    subject : dict, or str / path-like
        A dict of Vicon's names (``LeftLegLength`` or ``LLegLength``, ...), a ``.vsk``
        file, a ``.c3d`` file whose PROCESSING group holds them, or a ``.toml``,
        ``.json`` or ``.yaml`` file of Vicon's names and numbers (the table at the top
        level or under a key ``subject``).

    Returns
    -------
    dict
        Name -> float, with Vicon's names: the names of the model's measurements are
        recognised in any case and with 'L'/'R' for 'Left'/'Right' (``LLegLength``,
        ``LEFTLEGLENGTH`` -> ``LeftLegLength``). Other numeric entries are kept as given.

    Raises
    ------
    ValueError
        If a path is none of those kinds, if a value is not a number, or if one
        measurement is given twice with different values (``LLegLength`` and
        ``LeftLegLength``).
    FileNotFoundError
        If the file does not exist.
    TypeError
        If `subject` is not a dict or a path.

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait import load_subject
    >>> subject, source = load_subject({"LLEGLENGTH": 877.0, "rightKneeWidth": 139.0})
    >>> subject, source
    ({'LeftLegLength': 877.0, 'RightKneeWidth': 139.0}, 'subject')
    """
    if isinstance(subject, (str, Path)):
        path = Path(subject)
        suffix = path.suffix.lower()
        if suffix in (".vsk", ".c3d", ".toml", ".json", ".yaml", ".yml") \
                and not path.is_file():
            raise FileNotFoundError(f"subject: {path} does not exist")
        if suffix == ".vsk":
            raw = read_vsk(path)
        elif suffix == ".c3d":
            raw = subject_parameters(path)
        elif suffix in (".toml", ".json", ".yaml", ".yml"):
            raw = _read_subject_table(path)
        else:
            raise ValueError(f"subject: expected a dict, a .vsk, a .c3d, or a .toml, .json "
                             f"or .yaml file of Vicon's names; got {str(path)!r}")
        source = f"subject ({path.name})"
    elif isinstance(subject, dict):
        raw, source = subject, "subject"
    else:
        raise ArgumentTypeError(f"subject must be a dict of Vicon's measurement names, or a "
                                f".vsk or .c3d path; got {type(subject).__name__}")
    out = {}
    for name, value in raw.items():
        if name == "__model__":
            continue
        key = _canonical(str(name))
        if key in VICON_SUBJECT_NAMES:
            if isinstance(value, bool) or not isinstance(value, (int, float, np.number)) \
                    or not np.isfinite(value):
                raise ValueError(f"{source}: {name} must be a finite number; got "
                                 f"{value!r}")
        elif not isinstance(value, (int, float, np.number)):
            continue  # other entries (text, arrays) are not measurements of this model
        value = float(value)
        if key in out and out[key] != value:
            raise ValueError(f"{source}: {key} is given twice with different values "
                             f"({out[key]:g} and {value:g})")
        out[key] = value
    return out, source


def _check_subject(subject, source, static_given):
    """The measurements the model uses, required ones checked and optional ones derived.

    Returns (measurements, derived): both dicts name -> float; `derived` names the values
    this function computed (the static ones are added by the static processing)."""
    missing = [name for name in REQUIRED if name not in subject]
    if not static_given:
        missing += [name for name in ("InterAsisDistance", "LeftStaticPlantFlex",
                                      "RightStaticPlantFlex", "LeftStaticRotOff",
                                      "RightStaticRotOff") if name not in subject]
    if missing:
        static_only = [name for name in missing if name not in REQUIRED]
        why = "" if not static_only else (
            f"; without a static trial {' and '.join(static_only)} must come from the "
            f"subject: give the static trial (plug_in_gait(static, ...); --static on the "
            f"command line), from which Plug-in Gait's static processing computes them, or "
            f"a subject file that holds them (the .vsk Nexus saved after the static "
            f"processing, or a C3D it processed)")
        raise ValueError(f"{source}: missing subject measurement(s) {', '.join(missing)}"
                         f"{why}")
    for name in REQUIRED + ("InterAsisDistance", "MarkerDiameter"):
        if name in subject and not subject[name] > 0:
            raise ValueError(f"{source}: {name} must be a positive length (mm); got "
                             f"{subject[name]:g}")
    for name in NOT_APPLIED + (STATIC_ONLY_NOT_APPLIED if static_given else ()):
        if subject.get(name, 0.0) != 0.0:
            raise ValueError(f"{source}: {name} = {subject[name]:g}; this Plug-in Gait "
                             f"implementation does not apply the knee alignment device, "
                             f"ankle abduction or (in its static processing) sole-thickness "
                             f"offsets; set it to 0 or process the trial in Nexus")
    used, derived = {}, {}
    used["MarkerDiameter"] = subject.get("MarkerDiameter", DEFAULT_MARKER_DIAMETER)
    if "MarkerDiameter" not in subject:
        derived["MarkerDiameter"] = used["MarkerDiameter"]
    for name in REQUIRED:
        used[name] = subject[name]
    if "InterAsisDistance" in subject:
        used["InterAsisDistance"] = subject["InterAsisDistance"]
    for side in ("Left", "Right"):
        name = side + "AsisTrocanterDistance"
        if name in subject:
            used[name] = subject[name]
        else:
            used[name] = derived[name] = float(asis_trochanter_distance(
                subject[side + "LegLength"]))
        name = side + "TibialTorsion"
        used[name] = subject.get(name, 0.0)
        if name not in subject:
            derived[name] = 0.0
        if not static_given:
            for what in ("StaticPlantFlex", "StaticRotOff"):
                used[side + what] = subject[side + what]
    return used, derived


# --- labels ---------------------------------------------------------------------------

def _resolve_labels(data, markers, trial):
    """Standard name -> the trial's label, for the Plug-in Gait names present.

    `markers` renames (standard name -> label); otherwise a label equal to the standard
    name, or 'Prefix:NAME' with one prefix in the whole trial, or else the one label equal
    to it but for the case ('lasi', 'Sub01:Lasi')."""
    labels = data.labels
    present = set(labels)
    resolved = {}
    names = list(PELVIS_MARKERS) + [p + m for p in "LR" for m in LEG_MARKERS]
    prefixes = {label.rsplit(":", 1)[0] for label in labels if ":" in label
                and label.rsplit(":", 1)[1] in names}
    folded = {}
    for label in labels:
        folded.setdefault(label.rsplit(":", 1)[-1].upper(), []).append(label)
    for name in names:
        if name in markers:
            label = markers[name]
            if label not in present:
                raise ValueError(f"markers: {name} -> {label!r}, but {trial} has no label "
                                 f"{label!r}")
            resolved[name] = label
        elif name in present:
            resolved[name] = name
        else:
            found = [f"{prefix}:{name}" for prefix in prefixes
                     if f"{prefix}:{name}" in present]
            if len(found) > 1:
                first = sorted(found)[0].rsplit(":", 1)[0]
                raise ValueError(f"{trial}: the marker {name} appears with several subject "
                                 f"prefixes ({', '.join(sorted(found))}); choose one "
                                 f"subject's labels with markers=, e.g. markers={{name: "
                                 f"'{first}:' + name for name in ('LASI', 'RASI', 'LPSI', "
                                 f"'RPSI', 'LTHI', ...)}}")
            if found:
                resolved[name] = found[0]
            else:   # another case ('lasi', 'Sub01:LAsi'): when one label only is meant
                found = folded.get(name, [])
                if len(found) > 1:
                    raise ValueError(f"{trial}: the marker {name} matches several labels "
                                     f"in other cases ({', '.join(found)}); choose one "
                                     f"with markers={{'{name}': '...'}}")
                if found:
                    resolved[name] = found[0]
    return resolved


def _check_markers(resolved, data, trial):
    """Refuse a trial without the markers the model needs; return the posterior choice."""
    needed = ["LASI", "RASI"] + [p + m for p in "LR" for m in ("THI", "KNE", "TIB", "ANK",
                                                                 "TOE")]
    missing = [name for name in needed if name not in resolved
               or not data.has_data(resolved[name])]
    posterior = ["LPSI", "RPSI"] if all(name in resolved and data.has_data(resolved[name])
                                        for name in ("LPSI", "RPSI")) else ["SACR"]
    if posterior == ["SACR"] and not ("SACR" in resolved and data.has_data(resolved["SACR"])):
        missing.append("SACR or LPSI and RPSI")
    if missing:
        raise ValueError(f"{trial}: missing Plug-in Gait marker(s) {', '.join(missing)} "
                         f"(labels found: {', '.join(data.labels[:30])}"
                         f"{', ...' if len(data.labels) > 30 else ''}); rename with "
                         f"markers={{'LASI': 'your label', ...}}")
    return posterior


def _check_units(points, labels, units, trial):
    """Refuse a trial whose declared units are wrong (metres labelled mm, or the reverse):
    the ASIS distance (median over the frames) must be a pelvis's
    (:func:`~bmc_functions.models.lower_limb_checks.check_units`)."""
    with np.errstate(invalid="ignore"):
        width = np.linalg.norm(points["RASI"] - points["LASI"], axis=1)
    if not np.isfinite(width).any():
        return
    middle = np.nanmedian(width)
    roles = {"RASIS": labels["RASI"], "LASIS": labels["LASI"]}
    check_units(roles, {labels["RASI"]: np.array([middle, 0.0, 0.0]),
                        labels["LASI"]: np.zeros(3)}, units, trial)


# --- handedness -----------------------------------------------------------------------

def check_handedness(points, trial="the trial"):
    r"""Frames where the body is mirrored, or its legs' left and right labels swapped.

    A trial whose left and right labels are all swapped, or that is mirrored (a lab axis
    reversed, a left-handed lab frame), still gives Plug-in Gait plausible-looking curves
    (the chord function finds a knee centre on the "wrong" side of every marker). What
    changes is the handedness of the body: with :math:`\vec r` = RASI - LASI,
    :math:`\vec a` = from the sacrum (the midpoint of the PSIS markers, or SACR) to the
    midpoint of the ASIS markers and :math:`\vec u` = from the leg markers' centroid to
    that midpoint,

    .. math:: \vec r \cdot (\vec a \times \vec u) > 0

    in every posture of a real body (right, forward and up make a right-handed triad), and
    < 0 in its mirror image. The legs' labels alone swapped (the pelvis's not) put the
    right thigh (THI, KNE) to the subject's left of the left thigh, by more than
    ``LEGS_CROSSED`` (:mod:`~bmc_functions.models.lower_limb_checks`) times the ASIS distance
    along :math:`\vec r` (crossing the legs in walking brings the thighs together, not
    0.7 ASIS distances past each other). The same tests as
    :func:`~bmc_functions.models.lower_limb_checks.check_sides`, on the Plug-in Gait markers.

    Parameters
    ----------
    points : dict
        Standard name (``'LASI'``, ``'RTHI'``, ..., and ``'SACRUM'``) -> (frames, 3)
        positions (mm); NaN where missing (such frames are not judged).
    trial : str, optional
        The trial's name, for the messages.

    Returns
    -------
    mirrored, crossed : ndarray of bool, shape (frames,)
        The frames flagged: :meth:`PlugInGait.angles` makes every angle NaN in the
        mirrored frames and the hip, knee and ankle angles NaN in the crossed ones.

    Raises
    ------
    ValueError
        If every frame that can be judged is flagged (the whole trial is mirrored or
        swapped).

    Warns
    -----
    RuntimeWarning
        Once per kind, when some frames (not all) are flagged.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait import check_handedness
    >>> body = {"RASI": [[0, -120, 900]], "LASI": [[0, 120, 900]],
    ...         "SACRUM": [[-150, 0, 920]]}
    >>> for p, y in (("R", -100), ("L", 100)):
    ...     for name, z in (("THI", 650), ("KNE", 480), ("TIB", 300), ("ANK", 80)):
    ...         body[p + name] = [[0, y, z]]
    >>> body = {name: np.array(xyz, float) for name, xyz in body.items()}
    >>> mirrored, crossed = check_handedness(body)
    >>> print(mirrored, crossed)
    [False] [False]
    >>> flipped = {name: xyz * [1, -1, 1] for name, xyz in body.items()}
    >>> check_handedness(flipped)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: in every frame of the trial (1), the body is mirrored: ...
    """

    right = points["RASI"] - points["LASI"]
    middle = (points["RASI"] + points["LASI"]) / 2.0
    anterior = middle - points["SACRUM"]
    legs = visible_centroid(np.stack([points[p + name] for p in "LR"
                               for name in ("THI", "KNE", "TIB", "ANK")], axis=1))
    volume = np.einsum("fi,fi->f", right, np.cross(anterior, middle - legs))
    judged = np.isfinite(volume)
    mirrored = judged & (volume < 0)
    report_flagged_frames(
        mirrored, judged, trial,
        "the body is mirrored: RASI lies to the subject's left of LASI, judged with "
        "anterior = from the sacrum to the ASISs and up = from the legs' markers to the "
        "ASISs (the handedness of the body, which no posture changes). Left and right "
        "are swapped in the labels of this trial, or the trial is mirrored (a lab "
        "axis reversed), or the ASIS and PSIS labels are swapped", "every angle is NaN")
    thigh = {p: visible_centroid(np.stack([points[p + "THI"], points[p + "KNE"]], axis=1))
             for p in "LR"}
    width = np.linalg.norm(right, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        apart = np.einsum("fi,fi->f", thigh["R"] - thigh["L"], right) / width
    judged = np.isfinite(apart) & ~mirrored
    crossed = judged & (apart < -LEGS_CROSSED * width)
    report_flagged_frames(
        crossed, judged, trial,
        f"the right thigh's markers (RTHI, RKNE) lie to the subject's left of the left "
        f"thigh's (by more than {LEGS_CROSSED:g} times the ASIS distance, along RASI - "
        f"LASI): the legs' left and right labels are swapped in this trial",
        "the hip, knee and ankle angles of both sides are NaN")
    return mirrored, crossed


# --- the model ------------------------------------------------------------------------

@dataclass
class PlugInGaitTrack:
    """What :meth:`PlugInGait.track` returns for one trial.

    Attributes
    ----------
    centres : pandas.DataFrame
        Joint centres (mm, lab), columns ``(point, coord)`` like a marker DataFrame:
        ``LHJC``/``RHJC`` (hip), ``LKJC``/``RKJC`` (knee, Vicon's ``LFEO``),
        ``LAJC``/``RAJC`` (ankle, Vicon's ``LTIO``) and ``PELO`` (midpoint of the hip
        centres, Vicon's ``PELO``), indexed by time.
    frames : dict
        (segment, side) -> (R, origin): rotation matrices (frames, 3, 3), columns the
        segment's x, y, z axes (Vicon's ``...A``, ``...L``, ``...P`` directions), and
        origins (frames, 3) in mm. Segments: ``('pelvis', None)`` (origin PELO),
        ``('femur', side)`` (origin the knee centre), ``('tibia', side)`` (torsioned,
        origin the ankle centre), ``('tibia_untorsioned', side)``, ``('foot', side)``
        (origin the TOE marker), ``('foot_uncorrected', side)`` and, when HEE is
        there, ``('foot_static', side)`` (the heel-toe foot of the static processing).
        The axes of every segment are Vicon's (``...A``, ``...L``, ``...P`` minus
        ``...O``, normalized); Vicon's foot origin ``LFOO`` is not a CGM landmark (it
        stays 164 mm from the ankle centre in the shared trial, a length of Vicon's
        skeleton template), so only the foot's axes are comparable.
    progression : ndarray, shape (3, 3)
        :func:`progression_frame` of the trial.
    """

    centres: pd.DataFrame
    frames: dict
    progression: np.ndarray


@dataclass
class PlugInGait:
    """A Plug-in Gait (CGM) model of one subject: made by :func:`plug_in_gait`.

    Attributes
    ----------
    subject : dict
        Every subject measurement the model uses (Vicon's names; mm, radians), given or
        derived.
    derived : dict
        The measurements this model computed rather than took from the subject (the
        ASIS-trochanter distances, the default marker diameter, the inter-ASIS distance
        and static offsets from the static trial, ...).
    static_offsets : dict
        ``'LeftStaticPlantFlex'``, ``'LeftStaticRotOff'`` and the right ones (radians):
        from the static trial when one was given, else from `subject`.
    markers : dict
        Standard name -> the label used in the last trial read.
    rename : dict
        The `markers` mapping given to :func:`plug_in_gait` (standard name -> label).
    attrs : dict
        For a methods appendix: the model (``'Plug-in Gait lower body (Conventional
        Gait Model 1.0)'``), the references, where the measurements came from, every
        measurement used, what was derived, the static offsets and the marker
        diameter.
    """

    subject: dict
    derived: dict
    static_offsets: dict
    markers: dict = field(default_factory=dict)
    rename: dict = field(default_factory=dict)
    attrs: dict = field(default_factory=dict)

    # -- one trial's geometry --

    def _landmarks(self, trial, name):
        df, label = load_trial(trial, name)
        scale, _ = mm_per_unit(df, label)
        data = MarkerTable(df, label)
        resolved = _resolve_labels(data, self.rename, label)
        posterior = _check_markers(resolved, data, label)
        self.markers = resolved
        self._posterior = posterior
        self._trial = label
        points = {key: data.points(value, scale) for key, value in resolved.items()}
        _check_units(points, resolved, df.attrs.get("units"), label)
        points["SACRUM"] = ((points["LPSI"] + points["RPSI"]) / 2.0 if posterior != ["SACR"]
                            else points["SACR"])
        if posterior != ["SACR"] and "SACR" in points:   # both kinds: SACR fills PSI gaps
            fill = (np.isnan(points["SACRUM"]).any(axis=1)
                    & np.isfinite(points["SACR"]).all(axis=1))
            points["SACRUM"][fill] = points["SACR"][fill]
            warn_frames(int(fill.sum()), len(fill), f"of {label} lack LPSI or RPSI: the "
                        f"pelvis uses SACR there (elsewhere the midpoint of the PSIS "
                        f"markers)")
        mirrored, crossed = check_handedness(points, label)
        if mirrored.any() or crossed.any():  # flagged frames: NaN where the check says
            for key, values in points.items():
                values[mirrored | crossed if key[1:] in LEG_MARKERS else mirrored] = np.nan
        return df, points, mirrored | crossed

    def _geometry(self, points, offsets, with_static_foot=True):
        """Joint centres and segment frames (every frame at once)."""
        subject = self.subject
        R_pelvis, asis_mid = cgm_pelvis_frame(points["RASI"], points["LASI"],
                                              points["SACRUM"])
        radius = subject["MarkerDiameter"] / 2.0
        mean_leg = (subject["LeftLegLength"] + subject["RightLegLength"]) / 2.0
        centres, frames = {}, {}
        for side in SIDES:
            p, long = _PREFIX[side], _LONG[side]
            hip = davis_hip_centre(R_pelvis, asis_mid, mean_leg_length=mean_leg,
                                   asis_trochanter=subject[long + "AsisTrocanterDistance"],
                                   inter_asis_distance=subject["InterAsisDistance"],
                                   marker_radius=radius, side=side)
            knee = chord_joint_centre(points[p + "THI"], hip, points[p + "KNE"],
                                      subject[long + "KneeWidth"] / 2.0 + radius)
            ankle = chord_joint_centre(points[p + "TIB"], knee, points[p + "ANK"],
                                       subject[long + "AnkleWidth"] / 2.0 + radius)
            R_femur = cgm_femur_frame(hip, knee, points[p + "KNE"], side)
            R_tibia, R_untorsioned = cgm_tibia_frame(knee, ankle, points[p + "ANK"], side,
                                                     subject[long + "TibialTorsion"])
            R_uncorrected = cgm_uncorrected_foot_frame(ankle, points[p + "TOE"], R_tibia)
            centres[p + "HJC"], centres[p + "KJC"], centres[p + "AJC"] = hip, knee, ankle
            frames[("femur", side)] = (R_femur, knee)
            frames[("tibia", side)] = (R_tibia, ankle)
            frames[("tibia_untorsioned", side)] = (R_untorsioned, ankle)
            frames[("foot_uncorrected", side)] = (R_uncorrected, points[p + "TOE"])
            if with_static_foot and np.isfinite(points.get(p + "HEE", np.nan)).any():
                frames[("foot_static", side)] = (cgm_static_foot_frame(
                    points[p + "HEE"], points[p + "TOE"], R_tibia), points[p + "TOE"])
            if offsets is not None:
                frames[("foot", side)] = (cgm_foot_frame(
                    R_uncorrected, offsets[long + "StaticPlantFlex"],
                    offsets[long + "StaticRotOff"], side), points[p + "TOE"])
        centres["PELO"] = (centres["LHJC"] + centres["RHJC"]) / 2.0
        frames[("pelvis", None)] = (R_pelvis, centres["PELO"])
        return centres, frames

    def track(self, dynamic):
        """Joint centres and segment frames of a trial.

        Parameters
        ----------
        dynamic : str, path-like or pandas.DataFrame
            A .c3d or .trc file, or a marker DataFrame from :func:`read_c3d` /
            :func:`read_trc` (its ``attrs['units']`` set).

        Returns
        -------
        PlugInGaitTrack
            Centres (comparable with Vicon's ``LFEO`` = knee centre, ``LTIO`` = ankle
            centre, ``PELO``), frames and the direction of progression.

        Raises
        ------
        ValueError
            If a marker the model needs is missing (or in no frame), a label is
            ambiguous (two subject prefixes), the units are unknown or wrong (the ASIS
            distance is not a pelvis's), or the body is mirrored in every frame
            (:func:`check_handedness`).

        Warns
        -----
        RuntimeWarning
            Once per cause: frames with undefined segments (a marker missing there:
            their angles NaN), frames mirrored or with the legs' labels swapped (NaN
            there), a walkway more than ``PROGRESSION_WARN_DEG`` (20) degrees from the
            nearest lab axis.
        """
        return self._track(dynamic, with_static_foot=True)

    def _track(self, dynamic, with_static_foot):
        df, points, flagged = self._landmarks(dynamic, "dynamic")
        centres, frames = self._geometry(points, self.static_offsets, with_static_foot)
        needed = [name for name in self.markers if not name.endswith("HEE")
                  and (name not in PELVIS_MARKERS[2:] or name in self._posterior)]
        # frames flagged by check_handedness were warned about there: not counted again
        gaps = {name: int((np.isnan(points[name]).any(axis=1) & ~flagged).sum())
                for name in needed}
        gaps = {name: count for name, count in gaps.items() if count}
        undefined = np.isnan(frames[("pelvis", None)][0]).any(axis=(1, 2))
        for side in SIDES:
            undefined |= np.isnan(frames[("foot", side)][0]).any(axis=(1, 2))
        undefined = int((undefined & ~flagged).sum())
        if undefined:
            cause = (", ".join(f"{name} missing in {count}" for name, count in gaps.items())
                     if gaps else "a chord without solution: a joint width wider than the "
                     "marker's distance to the proximal joint centre")
            warn_frames(undefined, len(df), f"have undefined segments ({cause}); their "
                        f"angles are NaN")
        R_pelvis = frames[("pelvis", None)][0]
        progression = progression_frame(centres["PELO"], R_pelvis)
        _warn_diagonal(centres["PELO"], progression, self._trial)
        names = ["PELO", "LHJC", "RHJC", "LKJC", "RKJC", "LAJC", "RAJC"]
        columns = pd.MultiIndex.from_product([names, ["x", "y", "z"]],
                                             names=["point", "coord"])
        table = pd.DataFrame(np.concatenate([centres[n] for n in names], axis=1),
                             index=df.index.copy(), columns=columns)
        table.attrs = {"units": "mm", "rate": df.attrs.get("rate")}
        return PlugInGaitTrack(table, frames, progression)

    def event_markers(self):
        """The mapping :func:`~bmc_functions.gait_events` takes, for the last trial read.

        Returns
        -------
        dict
            The package's roles -> the labels of the trial (``'RASIS'`` -> ``'RASI'``,
            ``'RPSIS'``/``'LPSIS'`` or ``'SACRUM'``, and per side ``'HEEL'`` (HEE),
            ``'TOE'``, ``'ANKLE_LAT'`` (ANK)), subject prefixes and `markers` renames
            included.

        Examples
        --------
        >>> from bmc_functions import gait_events, plug_in_gait
        >>> from bmc_functions.examples import example_file
        >>> trial = example_file("plug_in_gait/Movement_trial.c3d")
        >>> model = plug_in_gait(None, trial)
        >>> angles = model.angles(trial)
        >>> model.event_markers()["RHEEL"], model.event_markers()["LTOE"]
        ('RHEE', 'LTOE')
        """
        roles = {"RASI": "RASIS", "LASI": "LASIS", "RPSI": "RPSIS", "LPSI": "LPSIS",
                 "SACR": "SACRUM"}
        for p in "LR":
            roles.update({p + "HEE": p + "HEEL", p + "TOE": p + "TOE",
                          p + "ANK": p + "ANKLE_LAT"})
        posterior = getattr(self, "_posterior", ["LPSI", "RPSI"])
        return {roles[name]: label for name, label in self.markers.items()
                if name in roles and (name not in PELVIS_MARKERS[2:] or name in posterior)}

    def opensim_coordinates(self, angles):
        """:func:`~bmc_functions.opensim_coordinates` of this model's `angles` (for
        ``write_mot``): the pelvis renamed in OpenSim's order, tilt-obliquity-rotation,
        even when `angles` lost the ``attrs['model']`` that says so."""
        if isinstance(angles, pd.DataFrame) and not str(
                angles.attrs.get("model", "")).startswith("Plug-in Gait"):
            angles = angles.copy(deep=False)
            angles.attrs = {**angles.attrs, "model": "Plug-in Gait (Vicon)"}
        return opensim_coordinates(angles)

    def angles(self, dynamic, *, foot="dynamic"):
        """Plug-in Gait's angles of a trial (degrees), one row per frame.

        Parameters
        ----------
        dynamic : str, path-like or pandas.DataFrame
            As :meth:`track`.
        foot : {'dynamic', 'static'}, keyword-only
            'dynamic' (default): the foot of every Plug-in Gait trial, the ankle centre
            to TOE line turned by the static offsets. 'static': the foot Nexus's static
            processing reports in the static trial itself, whose long axis is the HEE-TOE
            line (the trial needs HEE); only the ankle and foot angles change.

        Returns
        -------
        pandas.DataFrame
            Columns ``(joint, side, angle)``: ``('pelvis', side, 'tilt' | 'obliquity' |
            'rotation')`` = Vicon's LPelvisAngles / RPelvisAngles X, Y, Z; ``('hip' |
            'knee', side, 'flexion' | 'adduction' | 'rotation')`` = HipAngles /
            KneeAngles X, Y, Z; ``('ankle', side, 'dorsiflexion' | 'inversion' |
            'rotation')`` = AnkleAngles X, Y, Z; ``('foot', side, 'progression')`` =
            FootProgressAngles Z. Indexed as the trial (time in s). NaN where a marker a
            segment needs is missing. ``attrs``: the model's :attr:`attrs` and the
            trial's ``'rate'`` (Hz).

        Raises
        ------
        ValueError
            As :meth:`track`.

        Notes
        -----
        See :func:`cgm_angles` for the decomposition and signs.
        """
        check_choice(foot, "foot", ("dynamic", "static"))
        result = self._track(dynamic, with_static_foot=foot == "static")
        if foot == "static":
            missing = [side for side in SIDES if ("foot_static", side) not in result.frames]
            if missing:
                raise ValueError(f"foot='static' needs the HEE markers; the trial has none "
                                 f"on the {' and '.join(missing)} side")
            for side in SIDES:
                result.frames[("foot", side)] = result.frames[("foot_static", side)]
        table = self._angle_table(result.frames, result.progression, result.centres.index)
        table.attrs["rate"] = result.centres.attrs.get("rate")
        return table

    def _angle_table(self, frames, progression, index):
        columns, blocks = [], []
        per_side = {}
        for side in SIDES:
            per_side[side] = cgm_angles(progression, frames[("pelvis", None)][0],
                                        frames[("femur", side)][0],
                                        frames[("tibia_untorsioned", side)][0],
                                        frames[("tibia", side)][0],
                                        frames[("foot", side)][0], side)
        for joint, names in CGM_ANGLES.items():
            for side in SIDES:
                for name in names:
                    columns.append((joint, side, name))
                    blocks.append(per_side[side][(joint, name)])
        # levels in the columns' own order, so that the columns are lexsorted and
        # angles['knee', 'right'] selects without a sort or a PerformanceWarning
        levels = [list(CGM_ANGLES), list(SIDES), list(_ANGLE_ORDER)]
        codes = [[level.index(column[k]) for column in columns]
                 for k, level in enumerate(levels)]
        table = pd.DataFrame(np.column_stack(blocks), index=index.copy(),
                             columns=pd.MultiIndex(levels=levels, codes=codes,
                                                   names=["joint", "side", "angle"]))
        table.attrs = dict(self.attrs)
        return table


def plug_in_gait(static, subject, *, markers=None):
    r"""Build Vicon's Plug-in Gait (the Conventional Gait Model, lower body) for a subject.

    Parameters
    ----------
    static : str, path-like, pandas.DataFrame or None
        The static trial (.c3d or .trc, or a marker DataFrame from :func:`read_c3d`). Its
        static processing computes the foot's static offsets (``StaticPlantFlex``,
        ``StaticRotOff``) and, when the subject does not give it, the inter-ASIS
        distance. None: take them from `subject` (a .vsk or a dynamic C3D processed by
        Nexus holds them).
    subject : dict, str or path-like
        The subject measurements: a dict with Vicon's names, a ``.vsk`` subject file, or
        a ``.c3d`` file whose PROCESSING group holds them (Nexus writes them there).
        Lengths in mm, angles in radians, as Vicon stores them. Required:
        ``LeftLegLength``, ``RightLegLength`` (ASIS to medial malleolus),
        ``LeftKneeWidth``, ``RightKneeWidth``, ``LeftAnkleWidth``, ``RightAnkleWidth``
        (the C3D's ``LLegLength``, ``RKneeWidth``, ... are accepted). Optional:
        ``MarkerDiameter`` (default 14 mm), ``InterAsisDistance`` (default: from the
        static trial), ``LeftAsisTrocanterDistance`` (default
        :math:`0.1288\,L - 48.56`), ``LeftTibialTorsion`` (default 0), and, without a
        static trial, ``LeftStaticPlantFlex`` and ``LeftStaticRotOff`` (required then).
    markers : dict, optional
        Standard Plug-in Gait name -> the label in your files (``{'LASI': 'L.ASIS'}``).
        Without it a label equal to the standard name is used, or ``'Prefix:LASI'`` when
        the files carry one subject prefix, or else the one label that differs from it
        only in case (``'lasi'``). The pelvis needs LPSI and RPSI, or SACR (the midpoint
        of LPSI and RPSI is used when both are there, SACR in the frames where one of
        them is missing).

    Returns
    -------
    PlugInGait
        ``model.angles(dynamic)`` gives the angles, ``model.track(dynamic)`` the joint
        centres and segment frames; ``model.subject``, ``model.derived``,
        ``model.static_offsets`` and ``model.attrs`` record every value used.

    Raises
    ------
    ValueError
        If a required measurement is missing (each one named), a measurement is not a
        positive number, a knee-alignment-device offset is non-zero (not applied here),
        a marker is missing or its label ambiguous, the static trial leaves the static
        offsets undefined, a trial's declared units are wrong (its ASIS distance is not a
        pelvis's), or every frame of a trial is mirrored (a lab axis reversed, left and
        right labels swapped: :func:`check_handedness`).
    TypeError
        If `subject` is not a dict or a path, or `markers` is not a dict.

    Warns
    -----
    RuntimeWarning
        If the static trial is not static (a marker travels more than 100 mm, or the
        pelvis turns more than 10 degrees: its offsets are means over the frames), or
        some of its frames are mirrored (:func:`check_handedness`; left out).

    Notes
    -----
    The steps and their sources are in the module's docstring
    (:mod:`bmc_functions.models.plug_in_gait`): Davis et al. (1991) hip centre,
    Kadaba et al. (1990) segment definitions, Vicon's Plug-in Gait guide for the chord
    function, tibial torsion, the foot's static offsets and the pelvis and foot
    progression angles. On the shared Plug-in Gait trial processed by Vicon Nexus 2.6
    (``data/real/plug_in_gait``) every angle curve agrees with Vicon's within 1e-4°
    RMS and the joint centres within 1e-3 mm (``tests/test_plug_in_gait.py``).

    Examples
    --------
    >>> from bmc_functions import plug_in_gait
    >>> from bmc_functions.examples import example_file   # data/real/plug_in_gait, shipped
    >>> model = plug_in_gait(example_file("plug_in_gait/Static_trial.c3d"),
    ...                      example_file("plug_in_gait/Test.vsk"))
    >>> round(model.static_offsets["LeftStaticPlantFlex"], 4)
    0.2527
    >>> angles = model.angles(example_file("plug_in_gait/Movement_trial.c3d"))
    >>> angles.shape
    (323, 26)
    >>> print(angles["knee", "right", "flexion"].iloc[:3].round(2).to_list())
    [86.97, 86.52, 85.82]
    """
    if markers is None:
        markers = {}
    if not isinstance(markers, dict) or not all(isinstance(v, str) for v in markers.values()):
        raise ArgumentTypeError(f"markers must be a dict of standard name -> your label (a "
                                f"str); got {markers!r:.80}")
    unknown = [name for name in markers
               if name not in PELVIS_MARKERS and name[1:] not in LEG_MARKERS]
    if unknown:
        raise ValueError(f"markers: unknown Plug-in Gait name(s) {', '.join(map(str, unknown))};"
                         f" expected names from LASI RASI LPSI RPSI SACR and L/R + THI KNE "
                         f"TIB ANK HEE TOE")
    if static is not None and not isinstance(static, (str, Path, pd.DataFrame)):
        raise ArgumentTypeError(f"static must be a path, a marker DataFrame or None; got "
                                f"{type(static).__name__}")
    raw, source = load_subject(subject)
    used, derived = _check_subject(raw, source, static is not None)
    model = PlugInGait(subject=used, derived=derived, static_offsets={},
                       rename=dict(markers))
    if static is not None:
        _static_processing(model, static)
    else:
        model.static_offsets = {side + what: used[side + what] for side in ("Left", "Right")
                                for what in ("StaticPlantFlex", "StaticRotOff")}
    model.attrs = {
        "model": "Plug-in Gait lower body (Conventional Gait Model 1.0)",
        "references": ["Davis et al. 1991, Hum Mov Sci 10:575 (hip centre)",
                       "Kadaba et al. 1990, J Orthop Res 8:383 (segments)",
                       "Vicon Plug-in Gait reference guide (chord function, offsets)"],
        "subject_source": source,
        "static": "static trial" if static is not None else "offsets from the subject",
        "measurements": dict(model.subject),
        "derived": dict(model.derived),
        "static_offsets": dict(model.static_offsets),
        "marker_diameter_mm": model.subject["MarkerDiameter"],
        "units": "degrees (angles); mm and radians (measurements)",
    }
    return model


def _check_still(model, df):
    """One warning if the static trial is not static (a marker travels more than 100 mm
    from its median position, or the pelvis markers turn by more than 10 degrees): the
    static offsets are means over its frames. The ISB pipeline's check
    (:func:`~bmc_functions.models.lower_limb_checks.check_still`), on the Plug-in Gait labels."""
    # check_still finds the pelvis by the lower-limb roles (pelvis_roles): Plug-in Gait's
    # pelvis markers are given those roles beside their own names
    posterior = ({"SACRUM": "SACR"} if model._posterior == ["SACR"]
                 else {"RPSIS": "RPSI", "LPSIS": "LPSI"})
    roles = {"RASIS": "RASI", "LASIS": "LASI", **posterior}
    markers = {**model.markers, **{role: model.markers[name] for role, name in roles.items()}}
    scale, _ = mm_per_unit(df, model._trial)
    check_still(markers, MarkerTable(df, model._trial), scale, model._trial)


def _static_processing(model, static):
    """Plug-in Gait's static processing: inter-ASIS distance (if needed), foot offsets."""
    df, points, _ = model._landmarks(static, "static")
    _check_still(model, df)
    missing = [p + "HEE" for p in "LR" if not np.isfinite(points.get(p + "HEE", np.nan)).any()]
    if missing:
        raise ValueError(f"static: missing Plug-in Gait marker(s) {', '.join(missing)}: the "
                         f"static processing needs HEE for the foot's offsets; without "
                         f"them give static=None and a subject that holds the offsets (the "
                         f".vsk or a C3D Nexus processed), or rename the heel markers with "
                         f"markers={{'LHEE': ..., 'RHEE': ...}}")
    if "InterAsisDistance" not in model.subject:
        distance = np.linalg.norm(points["LASI"] - points["RASI"], axis=-1)
        model.subject["InterAsisDistance"] = float(np.nanmean(distance))
        model.derived["InterAsisDistance"] = model.subject["InterAsisDistance"]
    _, frames = model._geometry(points, None)
    offsets = {}
    for side in SIDES:
        long, p = _LONG[side], _PREFIX[side]
        R_tibia = frames[("tibia", side)][0]
        R_static = cgm_static_foot_frame(points[p + "HEE"], points[p + "TOE"], R_tibia)
        plantar, rotation = static_foot_offsets(frames[("foot_uncorrected", side)][0],
                                                R_static, side)
        offsets[long + "StaticPlantFlex"], offsets[long + "StaticRotOff"] = plantar, rotation
    model.static_offsets = offsets
    model.subject.update(offsets)
    model.derived.update(offsets)
