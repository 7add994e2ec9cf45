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

This module gives the two halves with ONE convention, so that what the static trial
measures the dynamic trial undoes exactly:

- :func:`wand_rotation_offset` - the static half: the offset (radians) from the wand's
  plane to the plane that holds the known flexion axis.
- :func:`rotated_chord_joint_centre` - the dynamic half: the chord function with the
  wand's plane turned by that offset.

Convention (this module's): the offset is the right-handed rotation about the unit axis
:math:`\hat e_1` from the proximal joint centre to the lateral marker (hip centre to KNE
for the thigh: pointing down the thigh) that carries the wand's direction (perpendicular
to :math:`\hat e_1`) onto the direction opposite the flexion axis' medial direction.
Positive is counter-clockwise seen from the lateral marker looking up at the proximal
centre.

What is NOT established: whether Vicon's stored ``ThighRotation`` number equals this
offset, its negative, or its mirror on the left side. pyCGM2's versions disagree on the
sign with which a subject's ``ThighRotation`` enters its chord function, and neither
Vicon's reference guide (as far as the stored excerpts go) nor a KAD static processed by
Nexus was at hand to decide it. The subject measurements ``LeftThighRotation`` etc.
therefore stay refused when non-zero (:mod:`~bmc_functions.models.plug_in_gait.subject`):
a wrong sign would be a silent wrong angle. The functions here are exact and
self-consistent and are tested so (tests/test_plug_in_gait_knee_alignment.py).

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


def wand_rotation_offset(wand, proximal_centre, lateral_marker, axis_point):
    r"""The rotation (radians) of the wand's plane onto the plane of a known flexion axis.

    Parameters
    ----------
    wand : array_like, shape (..., 3)
        THI (thigh) or TIB (shank), mm.
    proximal_centre : array_like, shape (..., 3)
        The hip centre (thigh) or the knee centre (shank).
    lateral_marker : array_like, shape (..., 3)
        KNE (thigh) or ANK (shank): a point of the flexion axis, lateral.
    axis_point : array_like, shape (..., 3)
        Another point of the same flexion axis, medial to `lateral_marker` (the joint
        centre, a medial marker, or the KAD's axis point).

    Returns
    -------
    ndarray, shape (...)
        The offset :math:`\theta` in :math:`(-\pi, \pi]`; NaN where a point is missing.

    Notes
    -----
    With :math:`\hat e_1 = (M - P)/|M - P|`, :math:`\hat w` the unit part of :math:`W -
    P` perpendicular to :math:`\hat e_1` (the chord function's :math:`\hat e_2`) and
    :math:`\hat t` the unit part of :math:`M - A` perpendicular to :math:`\hat e_1` (the
    chord function places the centre on the side opposite its :math:`\hat e_2`, so the
    wand's direction that yields this axis is lateral, from the medial point to M),

    .. math:: \theta = \operatorname{atan2}\big(\hat e_1\cdot(\hat w\times\hat t),\;
              \hat w\cdot\hat t\big),

    the right-handed angle about :math:`\hat e_1` from :math:`\hat w` to :math:`\hat t`.
    For a static trial, average the per-frame offsets over its frames.

    Examples
    --------
    A thigh along the lab's z axis (the hip straight above KNE), its knee axis along y,
    and a wand turned 10 degrees from y towards x, out of that axis' plane: that is +10
    degrees about the axis from the hip to KNE (-z), so the offset that turns the wand
    back is -10:

    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.knee_alignment import wand_rotation_offset
    >>> hip, kne, medial = [0, 60, 400.], [0, 60, 0.], [0, -40, 0.]
    >>> a = np.radians(10.0)
    >>> thi = [200 * np.sin(a), 60 + 200 * np.cos(a), 200.]
    >>> round(float(np.degrees(wand_rotation_offset(thi, hip, kne, medial))), 9)
    -10.0
    """
    W = check_vectors(wand, "wand")
    P = check_vectors(proximal_centre, "proximal_centre")
    M = check_vectors(lateral_marker, "lateral_marker")
    A = check_vectors(axis_point, "axis_point")
    e1 = _unit(M - P)
    w = _unit(_perpendicular(W - P, e1))
    t = _unit(_perpendicular(M - A, e1))
    return np.arctan2(np.sum(e1 * np.cross(w, t), axis=-1), np.sum(w * t, axis=-1))


def rotate_wand(wand, proximal_centre, lateral_marker, offset):
    r"""The wand turned by `offset` (radians) about the line from the proximal centre to
    the lateral marker (right-handed about :math:`\hat e_1 = (M - P)/|M - P|`).

    Parameters
    ----------
    wand, proximal_centre, lateral_marker : array_like, shape (..., 3)
        As for :func:`wand_rotation_offset`.
    offset : float or array_like, shape (...)
        Radians, :func:`wand_rotation_offset`'s convention.

    Returns
    -------
    ndarray, shape (..., 3)
        The turned wand (Rodrigues' formula); `wand` itself (a copy) where the offset is 0.

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait.knee_alignment import rotate_wand
    >>> rotate_wand([0, 100, 200.], [0, 0, 400.], [0, 0, 0.], np.pi / 2).round(9) + 0.0
    array([100.,   0., 200.])
    """
    W = check_vectors(wand, "wand")
    P = check_vectors(proximal_centre, "proximal_centre")
    M = check_vectors(lateral_marker, "lateral_marker")
    theta = np.asarray(offset, dtype=float)[..., None]
    k = _unit(M - P)
    v = W - P
    turned = v * np.cos(theta) + np.cross(k, v) * np.sin(theta) \
        + k * np.sum(k * v, axis=-1, keepdims=True) * (1.0 - np.cos(theta))
    return P + turned


def rotated_chord_joint_centre(wand, proximal_centre, lateral_marker, delta, offset):
    r"""The chord function with the wand's plane turned by a static offset.

    Parameters
    ----------
    wand, proximal_centre, lateral_marker : array_like, shape (..., 3)
        As for :func:`~bmc_functions.models.plug_in_gait.chord_joint_centre`.
    delta : float
        Joint width / 2 + marker radius (mm).
    offset : float
        Radians, from :func:`wand_rotation_offset` in the static trial.

    Returns
    -------
    ndarray, shape (..., 3)
        The joint centre. With ``offset == 0`` this is exactly
        :func:`~bmc_functions.models.plug_in_gait.chord_joint_centre` (the same call).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.knee_alignment import (
    ...     rotated_chord_joint_centre, wand_rotation_offset)
    >>> hip, kne, centre = np.array([0, 0, 400.]), np.array([0, 60, 0.]), np.zeros(3)
    >>> a = np.radians(10.0)
    >>> thi = np.array([200 * np.sin(a), 200 * np.cos(a), 200.])
    >>> offset = wand_rotation_offset(thi, hip, kne, centre)
    >>> J = rotated_chord_joint_centre(thi, hip, kne, 60.0, offset)
    >>> print(np.abs(J - centre).max() < 1e-9)
    True
    """
    if np.all(np.asarray(offset, dtype=float) == 0.0):
        return chord_joint_centre(wand, proximal_centre, lateral_marker, delta)
    turned = rotate_wand(wand, proximal_centre, lateral_marker, offset)
    return chord_joint_centre(turned, proximal_centre, lateral_marker, delta)
