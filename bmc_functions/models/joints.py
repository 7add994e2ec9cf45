r"""Joint angles from the anatomical frames of two adjacent segments.

The knee angles follow the joint coordinate system of Grood & Suntay (1983) written as a
Cardan sequence of the rotation of the shank relative to the thigh, with the ISB segment
frames of :mod:`bmc_functions.models.segments` (x anterior, y superior, z right).
"""

import numpy as np

from .._checks import check_choice, check_flag, check_rotation_matrix
from ..rigid_body.cardan import decompose_orthonormal


def knee_angles(R_thigh, R_shank, side="right", *, degrees=False):
    r"""Knee flexion, adduction and internal rotation (Grood & Suntay's JCS).

    Parameters
    ----------
    R_thigh, R_shank : array_like, shape (..., 3, 3)
        Anatomical frames of the thigh and the shank in the lab (columns: unit x anterior,
        y superior, z right), e.g. from :func:`thigh_frame` and :func:`shank_frame`.
        Frames on the leading axes; a frame containing NaN gives NaN angles.
    side : {'right', 'left'}, optional
        Which knee: the signs of adduction and rotation are flipped for the left side so
        that both sides read the same clinically. Default 'right'.
    degrees : bool, keyword-only
        Return degrees instead of radians. Default False.

    Returns
    -------
    angles : ndarray, shape (..., 3)
        Flexion (+) / extension (-), adduction (+, varus) / abduction (-, valgus), and
        internal (+) / external (-) rotation of the shank relative to the thigh.

    Raises
    ------
    TypeError
        If `degrees` is not a boolean, `side` is not a string, or a matrix is not numeric.
    ValueError
        If a matrix is not of shape (..., 3, 3), is not a rotation matrix (tolerance
        ``ORTHONORMAL_ATOL = 1e-6``, det = +1), the two shapes differ, or `side` is
        unknown.

    Warns
    -----
    RuntimeWarning
        Once per call, from :func:`decompose`, for frames in gimbal lock (adduction of
        +/-90 degrees: not a knee).

    Notes
    -----
    The rotation of the shank relative to the thigh, :math:`R = R_{thigh}^T R_{shank}`,
    is decomposed as the intrinsic sequence ZXY:
    :math:`R = R_z(\alpha)\, R_x(\beta)\, R_y(\gamma)`. Its three axes are those of Grood
    & Suntay's joint coordinate system: first the femoral medio-lateral axis
    :math:`e_1 = z_{thigh}`, last the tibial long axis :math:`e_3 = y_{shank}`, and in
    between the floating axis :math:`x'`, which equals
    :math:`e_2 = e_3 \times e_1 / |e_3 \times e_1|` (because
    :math:`e_3 \times e_1 = \cos\beta\; x'`).

    Signs, for a right knee (z to the right = lateral):

    - :math:`\alpha > 0` turns the shank's long axis :math:`y` towards :math:`-x`, so the
      ankle moves anteriorly: extension. Hence **flexion** :math:`= -\alpha`.
    - :math:`\beta > 0` turns :math:`y` towards :math:`+z`, so the ankle moves medially
      (to the left): **adduction** (varus) :math:`= \beta`.
    - :math:`\gamma > 0` turns the shank's anterior axis :math:`x` towards :math:`-z`
      (medially): **internal rotation** :math:`= \gamma`.

    For a left knee z still points to the right, now medially: flexion is again
    :math:`-\alpha`, while adduction :math:`= -\beta` and internal rotation
    :math:`= -\gamma`.

    References
    ----------
    .. [1] Grood ES, Suntay WJ (1983) A joint coordinate system for the clinical
       description of three-dimensional motions: application to the knee. J Biomech Eng
       105:136-144.
    .. [2] Wu G et al. (2002) ISB recommendation on definitions of joint coordinate
       system of various joints for the reporting of human joint motion - part I.
       J Biomech 35:543-548.

    Examples
    --------
    A shank flexed by 30 degrees (rotated by -30 degrees about the lateral z axis), then
    adducted by 5 and internally rotated by 10 degrees:

    >>> import numpy as np
    >>> from bmc_functions import compose, knee_angles
    >>> R_thigh = np.eye(3)
    >>> R_shank = compose([-30, 5, 10], 'ZXY', degrees=True)
    >>> print(knee_angles(R_thigh, R_shank, degrees=True).round(6) + 0.0)
    [30.  5. 10.]

    The mirror image of that pose on a left knee reads the same:

    >>> M = np.diag([1.0, 1.0, -1.0])          # mirror across the sagittal plane
    >>> L_shank = M @ R_shank @ M               # still a rotation, z still to the right
    >>> print(knee_angles(R_thigh, L_shank, 'left', degrees=True).round(6) + 0.0)
    [30.  5. 10.]
    """
    return _relative_zxy(R_thigh, R_shank, side, ("R_thigh", "R_shank"), (-1.0, 1.0, 1.0),
                         degrees)


def _relative_zxy(R_proximal, R_distal, side, names, signs_right, degrees):
    """Shared body of the joint-angle functions: ZXY angles of R_proximal.T @ R_distal.

    `signs_right` multiplies the three angles on the right side; on the left side the
    last two are negated as well (adduction/inversion and rotation mirror).
    """
    check_choice(side, "side", ("right", "left"))
    degrees = check_flag(degrees, "degrees")
    proximal = check_rotation_matrix(R_proximal, names[0])
    distal = check_rotation_matrix(R_distal, names[1])
    if proximal.shape != distal.shape:
        raise ValueError(f"{names[0]} and {names[1]} must have the same shape; got "
                         f"{proximal.shape} and {distal.shape}")
    # a product of two checked rotations: not re-checked (their deviations add up)
    angles = decompose_orthonormal(np.swapaxes(proximal, -1, -2) @ distal, "ZXY")
    sign = np.asarray(signs_right, dtype=float)
    if side == "left":
        sign = sign * np.array([1.0, -1.0, -1.0])
    angles = angles * sign
    return np.rad2deg(angles) if degrees else angles


def hip_angles(R_pelvis, R_thigh, side="right", *, degrees=False):
    r"""Hip flexion, adduction and internal rotation (joint coordinate system of Wu et al. 2002).

    Parameters
    ----------
    R_pelvis, R_thigh : array_like, shape (..., 3, 3)
        Anatomical frames of the pelvis and the thigh in the lab (columns: unit x
        anterior, y superior, z right), e.g. from :func:`pelvis_frame` and
        :func:`thigh_frame`. A frame containing NaN gives NaN angles.
    side : {'right', 'left'}, optional
        Which hip; the left side's adduction and rotation are negated so that both sides
        read the same clinically. Default 'right'.
    degrees : bool, keyword-only
        Return degrees instead of radians. Default False.

    Returns
    -------
    angles : ndarray, shape (..., 3)
        Flexion (+) / extension (-), adduction (+) / abduction (-), internal (+) /
        external (-) rotation of the thigh relative to the pelvis.

    Raises
    ------
    TypeError, ValueError
        As :func:`knee_angles`.

    Notes
    -----
    :math:`R = R_{pelvis}^T R_{thigh} = R_z(\alpha) R_x(\beta) R_y(\gamma)` (intrinsic
    ZXY): the first axis is the pelvis's medio-lateral :math:`z`, the last the femur's
    long axis :math:`y`, the middle one the floating axis, as in Wu et al.'s hip joint
    coordinate system. For a right hip, :math:`\alpha > 0` tilts the femur's long axis
    (knee to hip) backwards at the top, i.e. the knee moves forwards: **flexion**
    :math:`= \alpha`; :math:`\beta > 0` moves the knee medially: **adduction**
    :math:`= \beta`; :math:`\gamma > 0` turns the femur's anterior axis medially:
    **internal rotation** :math:`= \gamma`. For a left hip (z still to the right, now
    medial) adduction :math:`= -\beta` and internal rotation :math:`= -\gamma`.

    References
    ----------
    .. [1] Wu G et al. (2002) ISB recommendation on definitions of joint coordinate
       system of various joints for the reporting of human joint motion - part I: ankle,
       hip, and spine. J Biomech 35:543-548.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import compose, hip_angles
    >>> R_thigh = compose([30, 5, 10], 'ZXY', degrees=True)   # flexed, adducted, internal
    >>> print(hip_angles(np.eye(3), R_thigh, degrees=True).round(6) + 0.0)
    [30.  5. 10.]
    >>> M = np.diag([1.0, 1.0, -1.0])                           # the mirror image, left hip
    >>> print(hip_angles(np.eye(3), M @ R_thigh @ M, 'left', degrees=True).round(6) + 0.0)
    [30.  5. 10.]
    """
    return _relative_zxy(R_pelvis, R_thigh, side, ("R_pelvis", "R_thigh"), (1.0, 1.0, 1.0),
                         degrees)


def ankle_angles(R_shank, R_foot, side="right", *, degrees=False):
    r"""Ankle dorsiflexion, inversion and internal rotation (Wu et al. 2002).

    Parameters
    ----------
    R_shank, R_foot : array_like, shape (..., 3, 3)
        Anatomical frames of the shank and the foot in the lab (columns: unit x
        anterior, y superior, z right), e.g. from :func:`shank_frame` and
        :func:`foot_frame`. A frame containing NaN gives NaN angles.
    side : {'right', 'left'}, optional
        Which ankle; the left side's inversion and rotation are negated so that both
        sides read the same clinically. Default 'right'.
    degrees : bool, keyword-only
        Return degrees instead of radians. Default False.

    Returns
    -------
    angles : ndarray, shape (..., 3)
        Dorsiflexion (+) / plantarflexion (-), inversion (+) / eversion (-), internal
        (+) / external (-) rotation of the foot relative to the shank.

    Raises
    ------
    TypeError, ValueError
        As :func:`knee_angles`.

    Notes
    -----
    Wu et al.'s ankle joint coordinate system: :math:`e_1` the tibia's medio-lateral
    axis (dorsi-/plantarflexion), :math:`e_3` the foot's (calcaneus's) superior axis
    (internal/external rotation), :math:`e_2` floating (inversion/eversion). With
    :math:`R = R_{shank}^T R_{foot} = R_z(\alpha) R_x(\beta) R_y(\gamma)`:
    :math:`\alpha > 0` turns the foot's anterior axis upwards: **dorsiflexion**
    :math:`= \alpha`; on a right foot :math:`\beta > 0` tilts the foot's superior axis
    laterally, so the sole faces medially: **inversion** :math:`= \beta`;
    :math:`\gamma > 0` turns the toes medially: **internal rotation** :math:`= \gamma`.
    Left foot: inversion :math:`= -\beta`, internal rotation :math:`= -\gamma`. The foot
    frame coincides with the shank frame in the neutral posture, so the angles are zero
    there; with a marker-defined foot frame that is true only after a static offset
    (see :func:`calibrate_lower_limb`).

    References
    ----------
    .. [1] Wu G et al. (2002) J Biomech 35:543-548 (see :func:`hip_angles`).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import ankle_angles, compose
    >>> R_foot = compose([10, 4, -6], 'ZXY', degrees=True)   # dorsiflexed, inverted, external
    >>> print(ankle_angles(np.eye(3), R_foot, degrees=True).round(6) + 0.0)
    [10.  4. -6.]
    """
    return _relative_zxy(R_shank, R_foot, side, ("R_shank", "R_foot"), (1.0, 1.0, 1.0),
                         degrees)


def pelvis_angles(R_pelvis, side="right", *, R_lab=None, degrees=False):
    r"""Pelvis tilt, obliquity and rotation relative to the lab (rotation-obliquity-tilt).

    Parameters
    ----------
    R_pelvis : array_like, shape (..., 3, 3)
        Pelvis anatomical frame in the lab (columns: unit x anterior, y superior, z
        right), e.g. from :func:`pelvis_frame`.
    side : {'right', 'left'}, optional
        Which side the obliquity and rotation are read for (as gait reports do: "up" and
        "forward" refer to that side). Default 'right'.
    R_lab : array_like, shape (3, 3), optional
        The reference frame in the lab's coordinates: columns x along the direction of
        progression, y vertical upwards, z to the right. Default: the lab's own axes
        (identity), i.e. a lab with x forwards, y up and z to the right.
    degrees : bool, keyword-only
        Return degrees instead of radians. Default False.

    Returns
    -------
    angles : ndarray, shape (..., 3)
        Anterior (+) / posterior (-) tilt; obliquity, + when this side is up; rotation,
        + when this side is forwards.

    Raises
    ------
    TypeError
        If `degrees` is not a boolean, `side` is not a string, or a matrix is not numeric.
    ValueError
        If a matrix is not a rotation matrix of shape (..., 3, 3) (`R_lab`: (3, 3)) or
        `side` is unknown.

    Notes
    -----
    Baker (2001) recommends the sequence rotation - obliquity - tilt for the pelvis,
    because its angles then read as a clinician describes the pelvis (rotation in the
    transverse plane as seen from above, obliquity as seen from the front after that
    rotation). So :math:`R_{lab}^T R_{pelvis} = R_y(\gamma) R_x(\beta) R_z(\alpha)`
    (intrinsic YXZ), and with the ISB axes: tilt :math:`= -\alpha` (a positive rotation
    about the right-pointing z lifts the anterior axis: posterior tilt); obliquity
    :math:`= -\beta` on the right (a positive rotation about x lowers the right side)
    and :math:`+\beta` on the left; rotation :math:`= \gamma` on the right (a positive
    rotation about y turns the front to the left, bringing the right side forwards) and
    :math:`-\gamma` on the left. OpenSim's pelvis coordinates use the other order
    (tilt - list - rotation, ZXY): the two differ by second-order terms that grow with
    the product of the angles; on the same pelvis frames, at most 0.8 degrees (obliquity)
    on this project's synthetic walking stride and 3.9 degrees on a real running trial
    (a recording the project's tests use, not shipped with it). Signs against OpenSim's
    models (e.g. Rajagopal et al. 2016): a positive ``pelvis_tilt`` is a posterior tilt
    (the opposite of tilt here) and a positive
    ``pelvis_list`` lowers the right side (the opposite of the right obliquity here);
    ``pelvis_rotation`` has the same sign as the rotation here. On the real running trial,
    after those sign changes: r = 0.96 (tilt), 0.92 (obliquity), 0.99 (rotation).

    References
    ----------
    .. [1] Baker R (2001) Pelvic angles: a mathematically rigorous definition which is
       consistent with a conventional clinical understanding of the terms. Gait Posture
       13:1-6.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import compose, pelvis_angles
    >>> R = compose([5, 3, -10], 'YXZ', degrees=True)    # rotation, obliquity, about z
    >>> print(pelvis_angles(R, degrees=True).round(6) + 0.0)
    [10. -3.  5.]
    >>> print(pelvis_angles(R, 'left', degrees=True).round(6) + 0.0)
    [10.  3. -5.]
    """
    check_choice(side, "side", ("right", "left"))
    degrees = check_flag(degrees, "degrees")
    R = check_rotation_matrix(R_pelvis, "R_pelvis")
    if R_lab is not None:
        R_lab = check_rotation_matrix(R_lab, "R_lab")
        if R_lab.shape != (3, 3):
            raise ValueError(f"R_lab must have shape (3, 3); got shape {R_lab.shape}")
        R = R_lab.T @ R
    yxz = decompose_orthonormal(R, "YXZ")     # R (R_lab.T @ R) checked above
    sign = np.array([-1.0, -1.0, 1.0]) if side == "right" else np.array([-1.0, 1.0, -1.0])
    angles = yxz[..., ::-1] * sign
    return np.rad2deg(angles) if degrees else angles
