r"""Plug-in Gait's wand-rotation offsets (knee alignment device), arrays in, arrays out.

The chord function (:func:`~bmc_functions.models.plug_in_gait.chord_joint_centre`) puts
the knee centre in the plane of the thigh wand (THI), the hip centre and KNE, so the knee
flexion axis is only as good as the wand's placement. A knee alignment device (KAD,
Motion Lab Systems [1]_) or a medial marker shows the true flexion axis in the static
trial; the angle, about the thigh's long axis, between the wand's plane and the plane of
that axis is stored and turns the wand's plane in every dynamic trial ("Thigh and Shank
Rotations ... are applied to all dynamic data within the session" [1]_; Vicon's subject
measurements ``LeftThighRotation``, ``LeftShankRotation`` [2]_). The same holds for the
shank wand (TIB), the knee centre and ANK.

This module gives the two halves with ONE definition, so that what the static trial
measures the dynamic trial undoes exactly:

- :func:`wand_rotation_offset` - the static half: with the joint centre known (from the
  KAD, or a medial marker), the angle in the segment's transverse plane from the wand to
  the lateral marker, seen from the joint centre about the segment's long axis.
- :func:`rotated_chord_joint_centre` - the dynamic half: the joint centre for which that
  angle equals the stored offset (for 0, exactly the chord function).

Definition: with :math:`J` the joint centre, :math:`\hat z = (P - J)/|P - J|` the
segment's long axis (towards the proximal joint centre :math:`P`), and :math:`\hat w`,
:math:`\hat m` the parts of :math:`W - J` (wand) and :math:`M - J` (lateral marker)
perpendicular to :math:`\hat z`, the offset :math:`\beta` is the right-handed angle about
:math:`\hat z` from :math:`\hat w` to :math:`\hat m`. This is the angle pyCGM2's
modified chord function (``chord(..., beta)``, Leboeuf et al.) solves for, and the
"relative transverse alignment" of the KAD's axis to the thigh's wand that Motion Lab
Systems describes [1]_. For the standard chord function (wand, proximal centre, lateral
marker and centre in one plane) it is 0.

Vicon's sign, established from sources (the subject measurements ``LeftThighRotation``,
``RightThighRotation``, ``LeftShankRotation``, ``RightShankRotation``, radians):

.. math:: \beta_{\mathrm{left}} = -\,\mathrm{LeftThighRotation}, \qquad
          \beta_{\mathrm{right}} = +\,\mathrm{RightThighRotation}

(the same for the shank), i.e. ``value = MIRROR[side] * beta`` with ``MIRROR`` = +1 right,
-1 left (:func:`vicon_wand_offset`, :func:`wand_offset_from_vicon`): on either side a
positive value is a wand turned posteriorly (externally) from the plane of the joint's
flexion axis. The evidence [4]_:

1. pyCGM2's dynamic processing places the knee centre, every frame, with
   ``VCMJointCentre(..., beta=-LeftThighRotation)`` on the left and ``beta=
   +RightThighRotation`` on the right (and the same for the ankle with ShankRotation):
   ``pyCGM2/Model/CGM2/cgm.py``, ``_left_thigh_motion`` / ``_right_thigh_motion`` /
   ``_left_shank_motion`` / ``_right_shank_motion``. The two pyCGM2 versions that looked
   contradictory (``mp_computed[...] = -mp[...]`` in one, ``= mp[...]`` in the other) move
   the minus sign between the stored value and the call (``chord(..., beta=offset)`` in
   the older, ``VCMJointCentre(..., beta=-offset)`` in the newer): both give the beta
   above.
2. ``VCMJointCentre`` (``pyCGM2/Model/modelDecorator.py``, "the Vicon Clinical Manager
   method") with ``beta = b`` degrees returns exactly :func:`rotated_chord_joint_centre`
   with ``offset = radians(b)`` (checked on random limbs to 1e-13 mm): its beta is this
   module's :math:`\beta`.
3. The static half: pyCGM2's ``getThighOffset`` / ``getShankOffsets`` compute
   ``atan2(-w.x, w.y)`` (left) and ``atan2(-w.x, -w.y)`` (right), ``w`` the wand minus the
   joint centre in the segment's axes (x anterior, y left): that is
   ``MIRROR[side] * beta``, and pyCGM2's test suite compares it with the
   ``LThighRotation``, ``RThighRotation``, ``LShankRotation``, ``RShankRotation`` that
   Nexus wrote for a KAD-med static to 1e-3 degrees (``test_CGM1.py``,
   ``Test_LowerBody.test_KadMed_options``) and then the dynamic knee and ankle angles
   with these offsets applied to Nexus's (numpy ``decimal=2``): the static value and the
   dynamic use are the two halves of one definition, as here. The formula is evaluated by
   hand on the seeded generator's KAD static in
   ``tests/test_plug_in_gait_knee_alignment.py`` and gives back the generator's values.
4. OpenMA, validated against Nexus, reports for one subject's KAD static a left thigh
   rotation of +8.9585 deg and a right one of -10.0483 deg (the magnitudes Nexus stores;
   ``modules/body/test/c++/plugingaitTest_calibration.cpp``, ``calibrateFullBodyFrameKAD``).

The knee alignment device (Vicon's markers ``KAX``, ``KD1``, ``KD2``): its three arms are
orthogonal and equally long (markers 5.66 in apart [1]_), so its origin, where the arms
meet on the lateral knee, is the apex of a trirectangular tetrahedron on the three markers
(:func:`kad_knee_marker`); Plug-in Gait's static processing takes it as KNE, and the knee
centre as the chord function's with ``KAX`` as the wand (so the flexion axis is the
device's) [4]_, the ankle centre likewise with ``KAX`` as the wand turned by the tibial
torsion (0 unless the subject gives one). That ankle centre is exact for a straight knee
(the device's static is taken standing).

**The KAD-med variant** adds a medial malleolus marker per side (``LMED``, ``RMED``, as
pyCGM2 reads them, or ``LMMA``, ``RMMA``) to the static trial. The ankle centre is then
midway between the malleoli markers (pyCGM2's ``AnkleCalibrationDecorator.midMaleolus``),
and the static processing measures, besides ``ShankRotation`` from that centre:

- ``LeftAnkleAbAdd`` / ``RightAnkleAbAdd`` (radians): :func:`ankle_abadd_offset`,
  :math:`\alpha = \operatorname{atan2}(-A\cdot\hat z, |A_\perp|)`, :math:`A` = ANK - centre,
  :math:`\hat z` the shank's long axis: how far ANK lies below the shank's transverse
  plane through the centre (positive: the lateral malleolus below the medial one), the
  same sign on both sides;
- ``LeftTibialTorsion`` / ``RightTibialTorsion`` (radians):
  :func:`tibial_torsion_offset`, the angle about the tibia's long axis between the knee
  flexion axis (the femur's y, from the device) and the ankle's (the tibia's y, towards
  ANK), signed as :func:`~bmc_functions.models.plug_in_gait.cgm_tibia_frame` applies it
  (an ankle axis turned externally is negative on both sides).

In every trial, the chord function's ankle centre :math:`J` (with ``ShankRotation``) is
then turned about ANK (:math:`M`) by ``AnkleAbAdd`` (:func:`abadd_rotated_ankle_centre`):
:math:`J' = M + R_{\hat a}(\alpha)(J - M)`, :math:`\hat a = \hat z\times\hat m`
(:math:`\hat z = (K - J)/|K - J|`, :math:`\hat m = (M - J)/|M - J|`), which puts ANK
:math:`\alpha` below the chord centre's transverse plane; the shank, the foot and all
angles and kinetics downstream use :math:`J'`. Evidence for this rule, its sign and unit
(pyCGM2 [4]_, ``pyCGM2/Model/CGM2/cgm.py``, the version whose code was read):

1. ``_left_shank_motion`` / ``_right_shank_motion``: ``VCMJointCentre(..., beta=...)``,
   then ``_rotateAjc(AJC, KJC, ANK, mp_computed["LeftAnkleAbAddOffset"])`` (the right
   side alike, with no sign change); ``_rotateAjc`` builds a frame at ANK with z =
   unit(KJC - AJC), x = unit(z x unit(ANK - AJC)) and returns
   ``R Rx(offset) R^T (AJC - ANK) + ANK``, the offset in degrees: the rotation above.
2. ``getAbdAddAnkleJointOffset`` (the static half): ``atan2(-z.A, y.A)`` on the left and
   ``atan2(-z.A, -y.A)`` on the right in the shank's axes (y to the left, in the plane of
   z and ANK): :math:`\alpha` on both sides, the value the dynamic half applies. The
   unit: pyCGM2's tests compare its ``getViconAnkleAbAddOffset`` (degrees) with
   ``np.rad2deg`` of the ``LAnkleAbAdd`` / ``RAnkleAbAdd`` that Nexus wrote in a KAD-med
   static's PROCESSING group (``advancedCGM1_kad_midMaleolus``, ``decimal=3``): Vicon
   stores radians.
3. The sign of Vicon's number against :math:`\alpha`: ``getViconAnkleAbAddOffset``
   itself was not in the stored source text. A value equal to :math:`\alpha` on both
   sides is what the rule above applies unchanged on both sides, and it gives the same
   sign to the same anatomy on both legs (the lateral malleolus lies distal to the
   medial one: positive). The OpenMA test ``calibrateFullBodyFrameKADMed`` said to hold
   Nexus's values for a KAD-med static (11.5186 and 8.70843 degrees, left and right, both
   positive; tibial torsions about -12.0 and -17.7 degrees) was not in the two stored
   versions of ``plugingaitTest_calibration.cpp``: those numbers are unverified here.
   Not checked on a Nexus file: none with KAD-med markers was at hand.

``AnkleAbAdd`` is an output of the static processing (Vicon's subject template marks it
read-only, as ``StaticPlantFlex``; pyCGM2 measures it in every static, 0 for the chord
function's centre): a static trial without a medial marker on a side gives 0 there, and
a subject's value is applied only without a static trial (``plug_in_gait(None, ...)``).

The two halves are Vicon's, and not exact inverses: on a static trial's own markers, the
dynamic rule finds the ankle centre within 0.1 mm of the malleoli's midpoint for about 10
degrees of abduction (the chord centre's long axis is not the midpoint's);
``tests/test_plug_in_gait_knee_alignment.py`` builds each half from its definition
(the seeded generator's KAD-med static and walk) and recovers the known offsets and
angles to 1e-9.

Not checked on a Nexus file processed with non-zero offsets: none was at hand; Vicon's
reference guide (in the stored excerpts) names the measurements but does not define
their sign.

References
----------
.. [1] Motion Lab Systems. Knee Alignment Device (motion-labs.com/prod_qa_kad.html):
   three markers at equal distances (5.66 in) on three orthogonal arms; the software
   "calculates the relative transverse alignment of this axis, to the transverse plane
   orientation of the thigh and shank, as calculated using the mid-thigh and mid-shank
   stick markers".
.. [2] Vicon Motion Systems (2010-2017). Plug-in Gait reference guide: subject
   measurements (ThighRotation, ShankRotation), the chord function.
.. [3] Davis RB, Ounpuu S, Tyburski D, Gage JR (1991). A gait analysis data collection
   and reduction technique. Human Movement Science 10(5), 575-587.
.. [4] Leboeuf F et al. (2019). pyCGM2 (github.com/pyCGM2/pyCGM2): ``Model/CGM2/cgm.py``
   (thigh and shank offsets, their use in the motion), ``Model/modelDecorator.py``
   (``VCMJointCentre``; ``Kad``: the device's origin and knee centre),
   ``Tests/.../test_CGM1.py`` (comparison with Nexus). Read for facts only.
"""

import numpy as np

from ..._checks import check_vectors
from .lower_body import MIRROR, chord_joint_centre


def _unit(v):
    with np.errstate(invalid="ignore", divide="ignore"):
        return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _perpendicular(v, e):
    """The part of `v` perpendicular to the unit vector `e` (both (..., 3))."""
    return v - np.sum(v * e, axis=-1, keepdims=True) * e


#: The dynamic half's fixed-point iteration: at most this many steps, stopped when the
#: joint centre moves less than ``ITERATION_TOLERANCE`` (mm) on every frame.
MAX_ITERATIONS = 100
ITERATION_TOLERANCE = 1e-10


def _signed_angle(a, b, axis):
    """Right-handed angle about the unit `axis` from `a` to `b` (their parts
    perpendicular to `axis`), radians in (-pi, pi]."""
    a, b = _perpendicular(a, axis), _perpendicular(b, axis)
    return np.arctan2(np.sum(axis * np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))


def wand_rotation_offset(wand, proximal_centre, lateral_marker, joint_centre):
    r"""The wand's transverse offset (radians) from a segment whose joint centre is known.

    Parameters
    ----------
    wand : array_like, shape (..., 3)
        THI (thigh) or TIB (shank), mm.
    proximal_centre : array_like, shape (..., 3)
        The hip centre (thigh) or the knee centre (shank).
    lateral_marker : array_like, shape (..., 3)
        KNE (thigh) or ANK (shank).
    joint_centre : array_like, shape (..., 3)
        The true knee (ankle) centre, on the flexion axis through the lateral marker
        (from the knee alignment device, or midway to a medial marker).

    Returns
    -------
    ndarray, shape (...)
        :math:`\beta` in :math:`(-\pi, \pi]` (the module's definition); NaN where a point
        is missing. For a static trial, average it over the frames.

    Notes
    -----
    :math:`\beta = \operatorname{atan2}\big(\hat z\cdot(\hat w\times\hat m),\;\hat w\cdot
    \hat m\big)`, :math:`\hat z = (P - J)/|P - J|`, :math:`\hat w, \hat m` the parts of
    :math:`W - J, M - J` perpendicular to :math:`\hat z`.

    Examples
    --------
    The knee centre at the origin, the hip above it (the long axis +z), KNE 60 mm along
    +y, and a thigh wand turned 10 degrees from +y towards +x (-10 degrees about +z): the
    offset, from the wand's direction to KNE's, is +10 degrees:

    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.knee_alignment import wand_rotation_offset
    >>> a = np.radians(10.0)
    >>> thi = [100 * np.sin(a), 100 * np.cos(a), 200.]
    >>> offset = wand_rotation_offset(thi, [0, 0, 400.], [0, 60, 0.], [0, 0, 0.])
    >>> round(float(np.degrees(offset)), 9)
    10.0
    """
    W = check_vectors(wand, "wand")
    P = check_vectors(proximal_centre, "proximal_centre")
    M = check_vectors(lateral_marker, "lateral_marker")
    J = check_vectors(joint_centre, "joint_centre")
    return _signed_angle(W - J, M - J, _unit(P - J))


def rotate_wand(wand, pivot, axis_point, offset):
    r"""The wand turned by `offset` (radians) about the line from `pivot` to `axis_point`
    (right-handed about :math:`(A - O)/|A - O|`).

    Parameters
    ----------
    wand, pivot, axis_point : array_like, shape (..., 3)
        The point to turn and two points of the axis (mm).
    offset : float or array_like, shape (...)
        Radians.

    Returns
    -------
    ndarray, shape (..., 3)
        The turned point (Rodrigues' formula).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.knee_alignment import rotate_wand
    >>> rotate_wand([0, 100, 200.], [0, 0, 0.], [0, 0, 400.], np.pi / 2).round(9) + 0.0
    array([-100.,    0.,  200.])
    """
    W = check_vectors(wand, "wand")
    O = check_vectors(pivot, "pivot")
    A = check_vectors(axis_point, "axis_point")
    theta = np.asarray(offset, dtype=float)[..., None]
    k = _unit(A - O)
    v = W - O
    turned = v * np.cos(theta) + np.cross(k, v) * np.sin(theta) \
        + k * np.sum(k * v, axis=-1, keepdims=True) * (1.0 - np.cos(theta))
    return O + turned


def rotated_chord_joint_centre(wand, proximal_centre, lateral_marker, delta, offset):
    r"""The chord function with a wand offset: the centre whose :math:`\beta` is `offset`.

    Parameters
    ----------
    wand, proximal_centre, lateral_marker : array_like, shape (..., 3)
        As for :func:`~bmc_functions.models.plug_in_gait.chord_joint_centre`.
    delta : float
        Joint width / 2 + marker radius (mm).
    offset : float
        Radians, :func:`wand_rotation_offset` averaged over the static trial.

    Returns
    -------
    ndarray, shape (..., 3)
        The joint centre: `delta` from the lateral marker, :math:`M - J \perp P - J`
        (the chord function's conditions 2 and 3), and the wand at `offset` from the
        lateral marker about the long axis (in place of condition 1). With ``offset ==
        0`` this is exactly :func:`~bmc_functions.models.plug_in_gait.chord_joint_centre`
        (the same call). NaN where a point is missing.

    Notes
    -----
    Turning the wand by :math:`\beta` about the long axis through :math:`P` puts it in
    the plane of :math:`J, P, M`, where the chord function finds :math:`J`; the axis
    depends on :math:`J`, so the two steps are iterated from the chord function's centre
    (a fixed point; every frame at once, at most ``MAX_ITERATIONS`` steps, until the
    centre moves less than ``ITERATION_TOLERANCE`` mm). pyCGM2 solves the same condition
    by a search along the circle of centres.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.knee_alignment import (
    ...     rotated_chord_joint_centre, wand_rotation_offset)
    >>> hip, kne, centre = np.array([0, 0, 400.]), np.array([0, 60, 0.]), np.zeros(3)
    >>> a = np.radians(10.0)
    >>> thi = np.array([100 * np.sin(a), 100 * np.cos(a), 200.])
    >>> offset = wand_rotation_offset(thi, hip, kne, centre)
    >>> J = rotated_chord_joint_centre(thi, hip, kne, 60.0, offset)
    >>> print(np.abs(J - centre).max() < 1e-9)
    True
    """
    J = chord_joint_centre(wand, proximal_centre, lateral_marker, delta)
    if np.all(np.asarray(offset, dtype=float) == 0.0):
        return J
    # relative to P: coordinates of a segment's size (a long walk's lab coordinates, 1e6
    # mm, would leave rounding above the tolerance)
    P = np.asarray(proximal_centre, dtype=float)
    W = np.asarray(wand, dtype=float) - P
    M = np.asarray(lateral_marker, dtype=float) - P
    J = J - P
    origin = np.zeros_like(P)
    for _ in range(MAX_ITERATIONS):
        turned = rotate_wand(W, origin, -J, offset)
        new = chord_joint_centre(turned, origin, M, delta)
        with np.errstate(invalid="ignore"):
            moved = np.nanmax(np.abs(new - J), initial=0.0)
        J = new
        if moved < ITERATION_TOLERANCE:
            break
    return P + J


def _side(side):
    if side not in MIRROR:
        raise ValueError(f"side must be 'left' or 'right'; got {side!r}")
    return MIRROR[side]


def wand_offset_from_vicon(value, side):
    r"""This module's :math:`\beta` (radians) from Vicon's ``ThighRotation`` /
    ``ShankRotation`` of one side: :math:`\beta = \pm` value (+ right, - left).

    Parameters
    ----------
    value : float or array_like
        Vicon's ``LeftThighRotation`` (etc.), radians.
    side : {'left', 'right'}

    Returns
    -------
    float or ndarray
        :math:`\beta` for :func:`rotated_chord_joint_centre`.

    Notes
    -----
    The sign and its sources are in the module's docstring.

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait.knee_alignment import wand_offset_from_vicon
    >>> wand_offset_from_vicon(0.1, "left"), wand_offset_from_vicon(0.1, "right")
    (-0.1, 0.1)
    """
    return _side(side) * value


def vicon_wand_offset(beta, side):
    r"""Vicon's ``ThighRotation`` / ``ShankRotation`` (radians) from :math:`\beta`: the
    inverse of :func:`wand_offset_from_vicon` (the same sign, :math:`\pm 1` being its own
    inverse).

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait.knee_alignment import vicon_wand_offset
    >>> vicon_wand_offset(-0.1, "left")
    0.1
    """
    return _side(side) * beta


def kad_knee_marker(kax, kd1, kd2, side):
    r"""The knee alignment device's origin (the virtual KNE marker) from its three markers.

    Parameters
    ----------
    kax, kd1, kd2 : array_like, shape (..., 3)
        The device's markers ``KAX``, ``KD1``, ``KD2`` (mm), each on one of its three
        orthogonal, equally long arms.
    side : {'left', 'right'}

    Returns
    -------
    ndarray, shape (..., 3)
        The point where the arms meet (mm); NaN where a marker is missing.

    Notes
    -----
    The markers are equally far apart (:math:`a\sqrt 2`, :math:`a` the arm, 5.66 in on
    Motion Lab Systems' device [1]_), so the origin :math:`O` is the apex of a
    trirectangular tetrahedron on them: above the triangle's centroid :math:`C` by
    :math:`a/\sqrt 3`, along the normal :math:`\hat n = (K_2 - K_1)\times(A - K_1)/|\cdot|`
    (:math:`A` = KAX, :math:`K_1` = KD1, :math:`K_2` = KD2): :math:`O = C - \hat n\,a/\sqrt 3`
    on the left, :math:`O = C + \hat n\,a/\sqrt 3` on the right (the right device is the
    left one's mirror image) [4]_. :math:`a` is the mean of the three distances over
    :math:`\sqrt 2`.

    Examples
    --------
    Arms of 100 mm along +x, +y, +z from the origin (a left device):

    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.knee_alignment import kad_knee_marker
    >>> kad_knee_marker([100, 0, 0.], [0, 100, 0.], [0, 0, 100.], "left").round(9) + 0.0
    array([0., 0., 0.])
    """
    A = check_vectors(kax, "kax")
    K1 = check_vectors(kd1, "kd1")
    K2 = check_vectors(kd2, "kd2")
    sign = _side(side)        # -1 left: O = C - n h; +1 right: O = C + n h
    arm = (np.linalg.norm(A - K1, axis=-1) + np.linalg.norm(A - K2, axis=-1)
           + np.linalg.norm(K1 - K2, axis=-1))[..., None] / (3.0 * np.sqrt(2.0))
    normal = _unit(np.cross(K2 - K1, A - K1))
    return (A + K1 + K2) / 3.0 + sign * normal * arm / np.sqrt(3.0)


# --- the KAD-med variant: medial malleolus markers, AnkleAbAdd, tibial torsion ---------------

def ankle_abadd_offset(knee_centre, ankle_centre, ankle_marker):
    r"""Vicon's ``AnkleAbAdd`` (radians) from an ankle centre known in a static trial.

    Parameters
    ----------
    knee_centre, ankle_centre, ankle_marker : array_like, shape (..., 3)
        The knee centre, the true ankle centre (midway between the malleoli markers in a
        KAD-med static) and ANK (mm).

    Returns
    -------
    ndarray, shape (...)
        :math:`\alpha = \operatorname{atan2}(-A\cdot\hat z,\ |A - (A\cdot\hat z)\hat z|)`,
        :math:`A` = ANK - ankle centre, :math:`\hat z` = (knee - ankle centre)/|.|: the
        angle, in the plane of the shank's long axis and ANK, by which ANK lies distal to
        the shank's transverse plane through the ankle centre (positive: the lateral
        malleolus below the medial one), the same number on both sides. NaN where a point
        is missing; average it over the static's frames.

    Notes
    -----
    pyCGM2's ``getAbdAddAnkleJointOffset`` (``Model/CGM2/cgm.py``) computes
    ``atan2(-z.A, y.A)`` on the left and ``atan2(-z.A, -y.A)`` on the right in the shank's
    axes (y to the left, i.e. lateral on the left and medial on the right, in the plane of
    z and ANK): that is :math:`\alpha` on both sides. Sign and unit: module docstring.

    Examples
    --------
    ANK 40 mm lateral and 5 mm below the ankle centre, the knee straight above:

    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.knee_alignment import ankle_abadd_offset
    >>> a = ankle_abadd_offset([0, 0, 400.], [0, 0, 0.], [0, 40, -5.])
    >>> round(float(np.degrees(a)), 6), round(float(np.degrees(np.arctan2(5, 40))), 6)
    (7.125016, 7.125016)
    """
    K = check_vectors(knee_centre, "knee_centre")
    J = check_vectors(ankle_centre, "ankle_centre")
    A = check_vectors(ankle_marker, "ankle_marker") - J
    z = _unit(K - J)
    along = np.sum(A * z, axis=-1)
    return np.arctan2(-along, np.linalg.norm(A - along[..., None] * z, axis=-1))


def abadd_rotated_ankle_centre(ankle_centre, knee_centre, ankle_marker, offset):
    r"""The ankle centre turned about ANK by Vicon's ``AnkleAbAdd`` (the dynamic half).

    Parameters
    ----------
    ankle_centre : array_like, shape (..., 3)
        The chord function's ankle centre (with the ShankRotation offset applied).
    knee_centre, ankle_marker : array_like, shape (..., 3)
        The knee centre and ANK (mm).
    offset : float
        ``LeftAnkleAbAdd`` / ``RightAnkleAbAdd`` (radians, the same sign on both sides).

    Returns
    -------
    ndarray, shape (..., 3)
        :math:`J' = M + R_{\hat a}(\alpha)\,(J - M)`: the centre turned right-handedly by
        :math:`\alpha` about the axis through ANK (:math:`M`) along
        :math:`\hat a = \hat z\times\hat m`, :math:`\hat z = (K - J)/|K - J|`,
        :math:`\hat m = (M - J)/|M - J|` (perpendicular to the plane of the long axis and
        ANK): ANK then lies :math:`\alpha` below the chord centre's transverse plane. With
        ``offset == 0`` the input itself. NaN where a point is missing.

    Notes
    -----
    pyCGM2's ``_rotateAjc`` (``Model/CGM2/cgm.py``, called in ``_left_shank_motion`` and
    ``_right_shank_motion`` after ``VCMJointCentre``, the same offset on both sides): a
    frame at ANK with z = :math:`\hat z`, x = :math:`\hat a`, and
    ``R Rx(offset) R^T (AJC - ANK)``. Written here with Rodrigues' formula
    (:func:`rotate_wand`).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.knee_alignment import (
    ...     abadd_rotated_ankle_centre, ankle_abadd_offset)
    >>> knee, ank = np.array([0, 0, 400.]), np.array([0, 40, 0.])
    >>> J = abadd_rotated_ankle_centre([0, 0, 0.], knee, ank, np.radians(10.0))
    >>> J.round(6) + 0.0
    array([0.      , 0.60769 , 6.945927])
    >>> # measured from the chord centre's long axis, ANK is 10 degrees below
    >>> round(float(np.degrees(np.arctan2(-(ank - J)[2], (ank - J)[1]))), 9)
    10.0
    """
    J = check_vectors(ankle_centre, "ankle_centre")
    if np.all(np.asarray(offset, dtype=float) == 0.0):
        return J
    K = check_vectors(knee_centre, "knee_centre")
    M = check_vectors(ankle_marker, "ankle_marker")
    axis = np.cross(_unit(K - J), _unit(M - J))
    return rotate_wand(J, M, M + axis, offset)


def tibial_torsion_offset(R_femur, R_tibia, side):
    r"""Vicon's ``TibialTorsion`` (radians) from the knee and ankle flexion axes of a static.

    Parameters
    ----------
    R_femur : array_like, shape (..., 3, 3)
        The femur (its y axis the knee flexion axis, from the knee alignment device).
    R_tibia : array_like, shape (..., 3, 3)
        The torsioned tibia (its y axis the ankle flexion axis, through the malleoli).
    side : {'left', 'right'}

    Returns
    -------
    ndarray, shape (...)
        :math:`t = \mp\varphi` (- right, + left), :math:`\varphi` the right-handed angle
        about the tibia's z from its y axis to the femur's (projected): the inverse of
        :func:`~bmc_functions.models.plug_in_gait.cgm_tibia_frame`, whose untorsioned
        tibia :math:`R\,R_z(\mp t)` then has the femur's flexion axis. An ankle axis turned
        externally from the knee's gives a negative value on either side.

    Notes
    -----
    pyCGM2's ``getTibialTorsionOffset`` (``Model/CGM2/cgm.py``): ``atan2(k.y, k.x) -
    atan2(a.y, a.x)`` on the left and its negative on the right, ``k``, ``a`` the knee and
    ankle flexion axes in the shank's axes: the same :math:`t`.

    Examples
    --------
    A right leg whose ankle axis is turned 15 degrees externally (clockwise seen from
    above) from its knee axis:

    >>> import numpy as np
    >>> from bmc_functions.rigid_body.rotations import rot_z
    >>> from bmc_functions.models.plug_in_gait.knee_alignment import tibial_torsion_offset
    >>> t = tibial_torsion_offset(np.eye(3), rot_z(-np.radians(15.0)), "right")
    >>> round(float(np.degrees(t)), 9)
    -15.0
    """
    mirror = _side(side)
    R_f = np.asarray(R_femur, dtype=float)
    R_t = np.asarray(R_tibia, dtype=float)
    return -mirror * _signed_angle(R_t[..., :, 1], R_f[..., :, 1], R_t[..., :, 2])
