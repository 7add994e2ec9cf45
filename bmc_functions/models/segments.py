r"""Anatomical frames of the pelvis, thigh, shank and foot from landmarks (ISB conventions).

Every frame has the axes of Wu et al. (2002): **x anterior, y superior (along the segment's
long axis), z to the subject's right**, for the left side as well as the right (the shank
frame takes its long axis exactly, as Grood & Suntay's knee needs: see
:func:`shank_frame`). Each function returns the rotation matrices (columns: the unit x, y,
z axes in lab coordinates) and the origins, vectorized over frames; a frame with a NaN
landmark gives NaN.

The lab frame of the data does not matter (the axes come from the landmarks), but the
landmarks must be those of the named side: for a right limb the lateral epicondyle lies
to the right of the medial one, for a left limb to the left.
"""

import numpy as np

from .._checks import check_choice, check_vectors
from ..rigid_body.frames import frame_from_axes
from ..rigid_body.rotations import cross_rows, vector_length

#: Two landmarks count as coincident when their distance is at most this fraction of the
#: largest absolute coordinate of the two (or of 1, if that is smaller).
COINCIDENT_RTOL = 1e-9

#: Harrington et al. (2007) hip joint centre regression in the pelvis frame (mm):
#: coefficient of pelvis depth, coefficient of pelvis width, constant.
HARRINGTON = {"x": (-0.24, 0.0, -9.9), "y": (0.0, -0.30, -10.9), "z": (0.0, 0.33, 7.3)}

#: Range of pelvis widths (distance between the ASISs) accepted by
#: :func:`hip_joint_centre`, in mm: wide enough for small children and for skin markers on
#: large adults, narrow enough to catch landmarks in metres (about 0.25) or cm (about 25).
PELVIS_WIDTH_RANGE_MM = (50.0, 600.0)


def _check_side(side):
    check_choice(side, "side", ("right", "left"))
    return 1.0 if side == "right" else -1.0


def _landmarks(**named):
    """Validate named landmark arrays of shape (..., 3) that broadcast together."""
    arrays = {name: check_vectors(value, name) for name, value in named.items()}
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrays.values()))
    except ValueError:
        shapes = ", ".join(f"{name} {a.shape}" for name, a in arrays.items())
        raise ValueError(f"landmark arrays must have the same shape (..., 3); got {shapes}") \
            from None
    return [np.broadcast_to(a, shape) for a in arrays.values()]


def _check_apart(a, b, name_a, name_b, difference=None):
    """Raise if two landmarks coincide in any frame (NaN frames are skipped).
    `difference`: a - b (or b - a: only its length is read) if the caller has it."""
    distance = vector_length(a - b if difference is None else difference)
    # The largest absolute coordinate, NaN ignored: the largest of the largest and of
    # minus the smallest coordinate (the same number, with no array of absolute values).
    scale = max(np.fmax.reduce(a, axis=None, initial=0.0),
                -np.fmin.reduce(a, axis=None, initial=0.0),
                np.fmax.reduce(b, axis=None, initial=0.0),
                -np.fmin.reduce(b, axis=None, initial=0.0))
    close = distance <= COINCIDENT_RTOL * max(scale, 1.0)
    if close.any():
        raise ValueError(f"{name_a} and {name_b} coincide in {int(close.sum())} of "
                         f"{close.size} frames; they must be distinct points")


def _frame(primary, secondary, axes, problem):
    """frame_from_axes, with its 'parallel' error restated in terms of the landmarks."""
    try:
        return frame_from_axes(primary, secondary, axes=axes)
    except ValueError as error:
        raise ValueError(f"{problem}: {error}") from None


def pelvis_frame(rasis, lasis, rpsis, lpsis):
    r"""Pelvis anatomical frame from the anterior and posterior superior iliac spines.

    Parameters
    ----------
    rasis, lasis, rpsis, lpsis : array_like, shape (..., 3)
        Right and left ASIS and PSIS, frames on the leading axes.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
        Columns: unit x (anterior), y (superior), z (right) in lab coordinates.
    origin : ndarray, shape (..., 3)
        Midpoint of the two ASISs.

    Raises
    ------
    ValueError
        If a landmark is not of shape (..., 3) or contains inf, the shapes differ, the two
        ASISs coincide, or mid-PSIS lies on the line through the ASISs.

    Notes
    -----
    Wu et al. (2002): z runs from the left to the right ASIS; x lies in the plane of the
    ASISs and mid-PSIS, perpendicular to z, pointing anteriorly; :math:`y = z \times x`
    points superiorly. Wu et al. place the origin at the hip joint centre; here it is the
    mid-ASIS point, which does not change the orientation (see :func:`hip_joint_centre`).

    References
    ----------
    .. [1] Wu G et al. (2002) ISB recommendation on definitions of joint coordinate system
       of various joints for the reporting of human joint motion - part I: ankle, hip, and
       spine. J Biomech 35:543-548.

    Examples
    --------
    >>> from bmc_functions import pelvis_frame
    >>> R, origin = pelvis_frame([0, 0, 120], [0, 0, -120], [-160, 0, 45], [-160, 0, -45])
    >>> R.round(6) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    >>> origin + 0.0
    array([0., 0., 0.])
    """
    rasis, lasis, rpsis, lpsis = _landmarks(rasis=rasis, lasis=lasis, rpsis=rpsis,
                                            lpsis=lpsis)
    right = rasis - lasis            # each difference made once: checked, then the axes
    _check_apart(rasis, lasis, "rasis", "lasis", right)
    mid_asis = (rasis + lasis) / 2
    mid_psis = (rpsis + lpsis) / 2
    forward = mid_asis - mid_psis
    _check_apart(mid_asis, mid_psis, "mid-ASIS", "mid-PSIS", forward)
    R = _frame(right, forward, "zx", "mid-PSIS lies on the line through the ASISs")
    return R, mid_asis


def hip_joint_centre(rasis, lasis, rpsis, lpsis, side="right"):
    r"""Hip joint centre estimated from the pelvis landmarks (Harrington et al. 2007).

    Parameters
    ----------
    rasis, lasis, rpsis, lpsis : array_like, shape (..., 3)
        Right and left ASIS and PSIS, **in millimetres** (the regression has constants
        in mm).
    side : {'right', 'left'}, optional
        Which hip. Default 'right'.

    Returns
    -------
    centre : ndarray, shape (..., 3)
        Hip joint centre in lab coordinates (mm).

    Raises
    ------
    ValueError
        As :func:`pelvis_frame`; if `side` is not 'right' or 'left'; or if the median
        pelvis width is outside ``PELVIS_WIDTH_RANGE_MM = (50, 600)``, which means the
        landmarks are not in millimetres (the regression's constants would then be wrong
        by a factor of 10 or 1000).

    Notes
    -----
    With the pelvis frame of :func:`pelvis_frame` (origin mid-ASIS), pelvis width
    :math:`PW` (distance between the ASISs) and depth :math:`PD` (mid-ASIS to mid-PSIS),
    the centre is at

    .. math:: x = -0.24\,PD - 9.9, \quad y = -0.30\,PW - 10.9, \quad
              z = \pm(0.33\,PW + 7.3)

    (mm; + right, - left). Harrington et al. derived these equations from MRI of 8 adults
    and 24 children; in their data the older regressions (Bell et al. 1990, Davis et al.
    1991) erred by up to 31 mm, while the new ones predicted the centre within a few mm
    per axis in leave-one-out cross-validation. Applied with skin markers to other
    subjects the error is larger, about 1 cm (Mantovani et al. 2016 found 12 +/- 6 mm
    against CT). A functional (sphere-fit) centre or one given by the lab's software can
    be used instead: the thigh frame only needs a point.

    References
    ----------
    .. [1] Harrington ME, Zavatsky AB, Lawson SEM, Yuan Z, Theologis TN (2007)
       Prediction of the hip joint centre in adults, children, and patients with
       cerebral palsy based on magnetic resonance imaging. J Biomech 40:595-602.
    .. [2] Mantovani G, Ng KCG, Lamontagne M (2016) Regression models to predict hip
       joint centers in pathological hip population. Gait Posture 44:48-54.

    Examples
    --------
    >>> from bmc_functions import hip_joint_centre
    >>> c = hip_joint_centre([0, 0, 120], [0, 0, -120], [-160, 0, 45], [-160, 0, -45])
    >>> print(c.round(1) + 0.0)
    [-48.3 -82.9  86.5]
    """
    sign = _check_side(side)
    R, origin = pelvis_frame(rasis, lasis, rpsis, lpsis)
    rasis, lasis, rpsis, lpsis = _landmarks(rasis=rasis, lasis=lasis, rpsis=rpsis,
                                            lpsis=lpsis)
    width = vector_length(rasis - lasis)
    depth = vector_length(origin - (rpsis + lpsis) / 2)
    # The regression's constants are in mm: landmarks in m or cm would put the centre
    # metres away without any other sign of trouble.
    seen = width[np.isfinite(width)]
    low, high = PELVIS_WIDTH_RANGE_MM
    if seen.size and not low <= np.median(seen) <= high:
        raise ValueError(f"the pelvis width (distance between rasis and lasis) is "
                         f"{np.median(seen):.4g} (median); in millimetres it should lie "
                         f"between {low:g} and {high:g}: the landmarks must be in mm "
                         f"(multiply metres by 1000, centimetres by 10)")
    local = np.stack([a * depth + b * width + c for a, b, c in HARRINGTON.values()],
                     axis=-1)
    local[..., 2] *= sign
    return origin + np.einsum("...ij,...j->...i", R, local)


def thigh_frame(hip_centre, lateral_epicondyle, medial_epicondyle, side="right"):
    r"""Thigh (femur) anatomical frame from the hip centre and the femoral epicondyles.

    Parameters
    ----------
    hip_centre, lateral_epicondyle, medial_epicondyle : array_like, shape (..., 3)
        Landmarks, frames on the leading axes.
    side : {'right', 'left'}, optional
        Which limb: decides whether the lateral epicondyle is to the right (right limb)
        or to the left (left limb) of the medial one. Default 'right'.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
        Columns: unit x (anterior), y (superior), z (right) in lab coordinates.
    origin : ndarray, shape (..., 3)
        The hip centre.

    Raises
    ------
    ValueError
        If a landmark is not of shape (..., 3) or contains inf, the shapes differ, `side`
        is unknown, two landmarks coincide, or the hip centre lies on the epicondylar line.

    Notes
    -----
    Wu et al. (2002): with the knee centre :math:`K` midway between the epicondyles,
    :math:`y` runs from :math:`K` to the hip centre; :math:`z` is perpendicular to
    :math:`y` in the plane of the hip centre and the epicondyles, pointing to the right
    (from the medial to the lateral epicondyle on a right limb); :math:`x = y \times z`
    points anteriorly. :math:`z` is Grood & Suntay's (1983) femoral flexion axis.

    References
    ----------
    .. [1] Wu G et al. (2002) J Biomech 35:543-548 (see :func:`pelvis_frame`).
    .. [2] Grood ES, Suntay WJ (1983) A joint coordinate system for the clinical
       description of three-dimensional motions: application to the knee. J Biomech Eng
       105:136-144.

    Examples
    --------
    >>> from bmc_functions import thigh_frame
    >>> R, origin = thigh_frame([0, 420, 0], [0, 0, 45], [0, 0, -45])
    >>> R.round(6) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    >>> R, origin = thigh_frame([0, 420, 0], [0, 0, -45], [0, 0, 45], side='left')
    >>> print(R[:, 2].round(6) + 0.0)  # z still points to the right
    [0. 0. 1.]
    """
    sign = _check_side(side)
    hip, lateral, medial = _landmarks(hip_centre=hip_centre,
                                      lateral_epicondyle=lateral_epicondyle,
                                      medial_epicondyle=medial_epicondyle)
    across = lateral - medial        # each difference made once: checked, then the axes
    _check_apart(lateral, medial, "lateral_epicondyle", "medial_epicondyle", across)
    knee = (lateral + medial) / 2
    along = hip - knee
    _check_apart(hip, knee, "hip_centre", "mid-epicondyles", along)
    R = _frame(along, sign * across, "yz",
               "hip_centre lies on the line through the epicondyles")
    return R, hip


def shank_frame(lateral_epicondyle, medial_epicondyle, lateral_malleolus,
                medial_malleolus, side="right"):
    r"""Shank (tibia/fibula) anatomical frame from the epicondyles and the malleoli.

    Parameters
    ----------
    lateral_epicondyle, medial_epicondyle : array_like, shape (..., 3)
        Femoral epicondyles: their midpoint is taken as the knee joint centre.
    lateral_malleolus, medial_malleolus : array_like, shape (..., 3)
        Malleoli. Frames on the leading axes.
    side : {'right', 'left'}, optional
        Which limb (see :func:`thigh_frame`). Default 'right'.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
        Columns: unit x (anterior), y (superior), z (right) in lab coordinates.
    origin : ndarray, shape (..., 3)
        The midpoint of the malleoli.

    Raises
    ------
    ValueError
        If a landmark is not of shape (..., 3) or contains inf, the shapes differ, `side`
        is unknown, two landmarks coincide, or the knee centre lies on the malleolar line.

    Notes
    -----
    :math:`y` runs from the intermalleolar midpoint to the knee centre (the tibial long
    axis, Grood & Suntay's rotation axis); :math:`z` is perpendicular to :math:`y` in the
    plane of the malleoli and the knee centre, pointing to the right;
    :math:`x = y \times z`, normal to that plane, points anteriorly. The knee centre
    stands in for the intercondylar point of the tibial plateau, which a marker set
    rarely has. The torsion of the tibia (the malleolar line turned outwards relative to
    the knee) is therefore part of the frame: knee rotation is measured from this
    anatomical definition.

    *Difference from Wu et al. (2002).* Their tibia/fibula frame (XYZ, made for the ankle)
    has the same origin and the same :math:`x` (normal to the "torsional plane" of the
    intercondylar point and the malleoli), but takes :math:`z` exactly along the
    malleolar line and :math:`y = z \times x`, which is then only close to the long axis.
    The two frames differ by a rotation about :math:`x` by the angle between the
    malleolar line and the perpendicular to the long axis: the lateral malleolus lies
    lower than the medial one, typically by several degrees (13 degrees in this
    project's synthetic data), and with Wu's frame that angle would go straight into
    knee ab/adduction. Here the long axis is exact, as Grood & Suntay's joint coordinate
    system requires.

    References
    ----------
    .. [1] Wu G et al. (2002) J Biomech 35:543-548 (see :func:`pelvis_frame`).
    .. [2] Grood ES, Suntay WJ (1983) J Biomech Eng 105:136-144.

    Examples
    --------
    >>> from bmc_functions import shank_frame
    >>> R, origin = shank_frame([0, 400, 45], [0, 400, -45], [0, 0, 35], [0, 0, -35])
    >>> R.round(6) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    sign = _check_side(side)
    lat_ep, med_ep, lat_mal, med_mal = _landmarks(lateral_epicondyle=lateral_epicondyle,
                                                  medial_epicondyle=medial_epicondyle,
                                                  lateral_malleolus=lateral_malleolus,
                                                  medial_malleolus=medial_malleolus)
    across = lat_mal - med_mal       # each difference made once: checked, then the axes
    _check_apart(lat_mal, med_mal, "lateral_malleolus", "medial_malleolus", across)
    knee = (lat_ep + med_ep) / 2
    ankle = (lat_mal + med_mal) / 2
    along = knee - ankle
    _check_apart(knee, ankle, "mid-epicondyles", "mid-malleoli", along)
    R = _frame(along, sign * across, "yz",
               "the knee centre lies on the line through the malleoli")
    return R, ankle


def foot_frame(heel, toe, lateral_malleolus, medial_malleolus, mt5=None, side="right"):
    r"""Foot anatomical frame from the heel, the toe, the malleoli and (optionally) MT5.

    Parameters
    ----------
    heel, toe : array_like, shape (..., 3)
        Markers on the posterior calcaneus and on the forefoot (second metatarsal head
        or toe), frames on the leading axes.
    lateral_malleolus, medial_malleolus : array_like, shape (..., 3)
        The malleoli: their midpoint (the ankle centre) is the origin; without `mt5`
        they also give the medio-lateral direction.
    mt5 : array_like, shape (..., 3), optional
        Fifth metatarsal head. With it, the plane of heel, toe and MT5 (the sole) gives
        the superior axis, and the foot's roll about its long axis is measured.
    side : {'right', 'left'}, optional
        Which foot (see :func:`thigh_frame`). Default 'right'.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
        Columns: unit x (anterior), y (superior), z (right) in lab coordinates.
    origin : ndarray, shape (..., 3)
        The midpoint of the malleoli.

    Raises
    ------
    ValueError
        If a landmark is not of shape (..., 3) or contains inf, the shapes differ, `side`
        is unknown, heel and toe coincide, or the heel-toe line is parallel to the
        second direction (MT5 on that line, or the malleolar line along the foot).

    Notes
    -----
    :math:`x` runs from the heel to the toe (the foot's long axis). With MT5,
    :math:`y` is normal to the plane of heel, toe and MT5,
    :math:`y \propto \pm(MT5 - heel) \times (toe - heel)` (+ right, - left, so that it
    points upwards), made normal to :math:`x`, and :math:`z = x \times y`. Without MT5,
    :math:`z` is the malleolar line (lateral minus medial on the right) made normal to
    :math:`x`, and :math:`y = z \times x`. The axes follow Wu et al. (2002) for the
    calcaneus (x anterior, y superior, z right); Wu et al. make the calcaneus frame
    coincide with the tibia's in the neutral posture, which a marker-defined foot does
    only approximately (the heel and toe markers are rarely at the same height above the
    sole): the static trial's ankle angles show the difference, and the static offset of
    :func:`calibrate_lower_limb` removes it.

    *Without MT5 the foot's roll is not measured*: the malleoli belong to the shank, so
    the frame's rotation about the heel-toe line then follows the shank, and ankle
    inversion is undetermined (:func:`calibrate_lower_limb` returns NaN for it).

    References
    ----------
    .. [1] Wu G et al. (2002) ISB recommendation on definitions of joint coordinate
       system of various joints for the reporting of human joint motion - part I: ankle,
       hip, and spine. J Biomech 35:543-548.

    Examples
    --------
    >>> from bmc_functions import foot_frame
    >>> R, origin = foot_frame([-50, -40, 0], [150, -40, 0], [0, -8, 35], [0, 8, -35],
    ...                        mt5=[110, -40, 35])
    >>> R.round(6) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    >>> print(origin + 0.0)
    [0. 0. 0.]
    """
    sign = _check_side(side)
    named = {"heel": heel, "toe": toe, "lateral_malleolus": lateral_malleolus,
             "medial_malleolus": medial_malleolus}
    if mt5 is not None:
        named["mt5"] = mt5
    points = dict(zip(named, _landmarks(**named)))
    heel, toe = points["heel"], points["toe"]
    forward = toe - heel             # each difference made once: checked, then the axes
    _check_apart(heel, toe, "heel", "toe", forward)
    origin = (points["lateral_malleolus"] + points["medial_malleolus"]) / 2
    if mt5 is not None:
        # The normal made on the components as rows (numpy.cross's numbers, bit for bit)
        # and passed on as such (frame_from_axes reads rows): no transposing copies.
        up = sign * cross_rows(np.moveaxis(points["mt5"] - heel, -1, 0),
                               np.moveaxis(forward, -1, 0))
        R = _frame(forward, np.moveaxis(up, 0, -1), "xy",
                   "mt5 lies on the line through heel and toe")
    else:
        across = points["lateral_malleolus"] - points["medial_malleolus"]
        _check_apart(points["lateral_malleolus"], points["medial_malleolus"],
                     "lateral_malleolus", "medial_malleolus", across)
        R = _frame(forward, sign * across, "xz",
                   "the malleolar line is parallel to heel-toe")
    return R, origin
