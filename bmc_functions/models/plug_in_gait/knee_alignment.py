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

What is NOT established: whether Vicon's stored ``LeftThighRotation`` /
``RightThighRotation`` (and ``ShankRotation``) number equals :math:`\beta`, its negative,
or :math:`\beta` on one side and :math:`-\beta` on the other (Plug-in Gait reports the
left side's transverse angles mirrored). The evidence found: pyCGM2's ``getThighOffset``
(``atan2(-thi.x, thi.y)`` on the left, ``atan2(-thi.x, -thi.y)`` on the right, with
``thi = THI - KJC`` in the femur's axes, x anterior, y left) is compared in pyCGM2's test
suite with the ``LThighRotation`` Nexus stored for a Vicon KAD-med static (to 0.1 deg);
in this module's terms it is :math:`-\beta` on the left and :math:`+\beta` on the right,
i.e. a positive value on either side is a wand turned posteriorly (externally) from the
plane of the knee axis. But pyCGM2's versions disagree on the sign with which a
subject's ``ThighRotation`` then enters its dynamic chord function (``= mp[...]`` in one,
``= -mp[...]`` in another), Vicon's reference guide (in the stored excerpts) does not
define it, and no KAD static processed by Nexus was at hand to check either. The
subject measurements ``LeftThighRotation`` etc. therefore stay refused when non-zero
(:mod:`~bmc_functions.models.plug_in_gait.subject`): a wrong sign would be a silent wrong
angle. The functions here are exact and self-consistent and are tested so
(tests/test_plug_in_gait_knee_alignment.py).

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
"""

import numpy as np

from ..._checks import check_vectors
from .lower_body import chord_joint_centre


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
    W, P = np.asarray(wand, dtype=float), np.asarray(proximal_centre, dtype=float)
    for _ in range(MAX_ITERATIONS):
        turned = rotate_wand(W, P, P + (P - J), offset)
        new = chord_joint_centre(turned, P, lateral_marker, delta)
        with np.errstate(invalid="ignore"):
            moved = np.nanmax(np.abs(new - J), initial=0.0)
        J = new
        if moved < ITERATION_TOLERANCE:
            break
    return J
