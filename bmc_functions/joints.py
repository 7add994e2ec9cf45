r"""Joint angles from the anatomical frames of two adjacent segments.

The knee angles follow the joint coordinate system of Grood & Suntay (1983) written as a
Cardan sequence of the rotation of the shank relative to the thigh, with the ISB segment
frames of :mod:`bmc_functions.segments` (x anterior, y superior, z right).
"""

import numpy as np

from ._checks import check_choice, check_flag, check_rotation_matrix
from .angles import decompose


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

    For a left knee z still points to the right, now laterally: flexion is again
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
    check_choice(side, "side", ("right", "left"))
    degrees = check_flag(degrees, "degrees")
    R_thigh = check_rotation_matrix(R_thigh, "R_thigh")
    R_shank = check_rotation_matrix(R_shank, "R_shank")
    if R_thigh.shape != R_shank.shape:
        raise ValueError(f"R_thigh and R_shank must have the same shape; got "
                         f"{R_thigh.shape} and {R_shank.shape}")
    relative = np.swapaxes(R_thigh, -1, -2) @ R_shank
    angles = decompose(relative, "ZXY")
    sign = np.array([-1.0, 1.0, 1.0]) if side == "right" else np.array([-1.0, -1.0, -1.0])
    angles = angles * sign
    return np.rad2deg(angles) if degrees else angles
