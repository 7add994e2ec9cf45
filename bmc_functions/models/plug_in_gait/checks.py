r"""Checks of what Plug-in Gait is told: the subject's measurements and the leg markers.

Plug-in Gait takes every marker and measurement as given; a knee width in cm, a knee
marker swapped with its thigh wand, one pair of markers swapped between the sides for a
run of frames, all give plausible-looking curves tens of degrees off. These functions look
at the data for what a real body forbids (arrays and dicts in; flags, an error or one
warning out):

- :func:`check_measurement_ranges`: every measurement within what a human body (child to
  tall adult) allows, radians where radians belong.
- :func:`check_measurements_against_markers`: the inter-ASIS distance, the leg length and
  the widths agree with the trial's own markers.
- :func:`zero_points_as_missing`: (0, 0, 0) written for a missing point is a gap.
- :func:`check_leg_marker_order`: each wand lies between its joints (THI nearer the ASIS
  than KNE is, TIB nearer KNE than ANK is, ANK nearer KNE than TOE is), each lateral
  marker on its own side of the other leg's, the heel behind the toe.
- :func:`check_leg_distances`: the distances between a leg's markers stay constant over a
  trial (they sit on the same or adjacent rigid segments): frames where a marker jumps
  (a ghost, a swap for a run of frames) are flagged.
- :func:`check_toe_ahead_of_ankle` and :func:`check_thigh_wands`: with or without a
  static trial, the toe marker in front of the ankle marker and the thigh wand on the
  lateral side of the thigh (TOE and ANK swapped in every frame, a wand placed medially in
  the static trial and the walk alike: the comparison with the static cannot see them).

The bounds are wide, written as fractions of the data's own scale (the leg length, the
ASIS distance) or of the body's proportions: Winter (2009), *Biomechanics and Motor
Control of Human Movement*, 4th ed., Fig. 4.1 (Drillis and Contini's segment lengths as
fractions of the body height H: thigh 0.245 H, leg 0.246 H, foot 0.152 H, hip width
0.191 H, ankle height 0.039 H), over heights from 0.9 m (a 3-year-old) to 2.1 m.
"""

import numpy as np

from ..._checks import warn, warn_frames
from ...rigid_body.rotations import vector_length
from ..lower_limb_checks import report_flagged_frames
from .lower_body import cgm_pelvis_frame, davis_hip_centre

#: Measurement (mm or rad) -> (impossible below, doubtful below, doubtful above, impossible
#: above). Leg length (ASIS to medial malleolus) ~ 0.49 H (Winter's trochanter height
#: 0.53 H less the ankle height 0.039 H): 440-1030 mm for H = 0.9-2.1 m; a value in metres
#: (0.9) or x10 (8770) is impossible. Knee and ankle widths (the joint's medio-lateral
#: breadth): tens of mm to a few hundred at most; in cm (10.5) or x10 impossible. Inter-ASIS
#: distance ~ 0.13-0.16 H by the markers of the shipped subject (307 mm for H ~ 1.8 m) and
#: Winter's hip width 0.191 H is its upper bound. The marker diameter: Vicon sells 3-25 mm
#: markers; 14 mm is Plug-in Gait's default. Angles in radians: beyond pi they can only be
#: degrees; beyond 1 rad (57 deg) of tibial torsion or static foot offset is doubtful.
MEASUREMENT_RANGES = {
    "LegLength": (250.0, 400.0, 1200.0, 1500.0),
    "KneeWidth": (40.0, 60.0, 180.0, 300.0),
    "AnkleWidth": (25.0, 40.0, 130.0, 200.0),
    "InterAsisDistance": (80.0, 120.0, 400.0, 600.0),
    "MarkerDiameter": (2.0, 5.0, 30.0, 50.0),
    "TibialTorsion": (-np.pi, -1.0, 1.0, np.pi),
    # the malleoli's line beyond 90 degrees from the shank's transverse plane is not an
    # ankle (a value in degrees); beyond 0.6 rad (34 degrees) doubtful: the lateral
    # malleolus lies about 1 cm below the medial one over a 7 cm wide ankle (8 degrees)
    "AnkleAbAdd": (-np.pi / 2, -0.6, 0.6, np.pi / 2),
    "StaticPlantFlex": (-np.pi, -1.0, 1.0, np.pi),
    "StaticRotOff": (-np.pi, -1.0, 1.0, np.pi),
}

#: The ASIS-trochanter distance as a fraction of the leg length: Davis et al.'s regression
#: (0.1288 L - 48.56) gives 0.07 L for an adult; beyond 0.3 L the trochanter would sit a
#: third of the way down the thigh (impossible); beyond 0.2 L doubtful.
ASIS_TROCHANTER_MAX = (0.2, 0.3)

#: Ratio of a measurement to the markers' value beyond which they contradict each other:
#: (doubtful, impossible). A factor of 1.5 is far outside marker placement (a 14 mm marker
#: on skin over the ASIS) and a factor 3 is a unit error (cm/mm, x10).
AGREEMENT_RATIO = (1.5, 3.0)

#: A leg marker's distance to a marker of its leg may change over a trial by at most this
#: fraction of the leg length (0.1 L = 88 mm for the shipped subject, whose largest change
#: over the walk is 32 mm, THI to ASIS): beyond it the marker has jumped (a ghost, a swap).
DISTANCE_CHANGE_MAX = 0.1

#: A median distance between a leg's markers (:data:`LEG_PAIRS`) may differ from the static
#: trial's by at most this fraction of the leg length (0.05 L = 44 mm for the shipped
#: subject, whose medians agree within 11 mm between the static trial and the walk), and
#: the thigh wands' median separation along RASI - LASI likewise (414 mm standing, 410 mm
#: walking).
STATIC_CHANGE_MAX = 0.05

#: Pairs of a leg's markers whose distance stays near constant (same or adjacent segments,
#: joint axes near the lateral markers); the heel is left out (its distance to ANK changes by
#: 35 % in the shipped walk).
LEG_PAIRS = (("THI", "ASI"), ("THI", "KNE"), ("KNE", "ANK"), ("TIB", "KNE"), ("TIB", "ANK"),
             ("ANK", "TOE"))


def check_measurement_ranges(subject, source="subject", ranges=None):
    """Each Plug-in Gait measurement within what a body allows (mm, radians).

    Parameters
    ----------
    subject : dict
        Vicon's names -> values (``LeftLegLength``, ``InterAsisDistance``, ...); absent
        names are not checked.
    source : str, optional
        Where the measurements come from, for the messages.
    ranges : dict, optional
        Measurement (without its Left/Right prefix) -> (impossible below, doubtful
        below, doubtful above, impossible above); default :data:`MEASUREMENT_RANGES`
        (the model adds :data:`~bmc_functions.models.plug_in_gait.upper_body_checks.
        UPPER_BODY_RANGES`).

    Raises
    ------
    ValueError
        If a measurement is outside `ranges`' impossible bounds (a unit
        error: cm, m, x10, degrees), or an ASIS-trochanter distance is more than 0.3 of the
        leg length.

    Warns
    -----
    RuntimeWarning
        One warning naming the doubtful measurements.

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait.checks import check_measurement_ranges
    >>> check_measurement_ranges({"LeftKneeWidth": 105.0})
    >>> check_measurement_ranges({"LeftKneeWidth": 10.5})
    Traceback (most recent call last):
    ...
    ValueError: subject: LeftKneeWidth = 10.5 is impossible (expected 40 to 300 mm; a value in cm, m, x10 or degrees?)
    """
    ranges = MEASUREMENT_RANGES if ranges is None else ranges
    doubtful = []
    for name, value in subject.items():
        key = name[4:] if name.startswith("Left") else (
            name[5:] if name.startswith("Right") else name)
        if key not in ranges:
            continue
        low, doubt_low, doubt_high, high = ranges[key]
        unit = "rad" if low < 0 else "mm"
        if not low <= value <= high:
            raise ValueError(f"{source}: {name} = {value:g} is impossible (expected "
                             f"{low:.4g} to {high:.4g} {unit}; a value in cm, m, x10 or "
                             f"degrees?)")
        if not doubt_low <= value <= doubt_high:
            doubtful.append(f"{name} = {value:g} (usual {doubt_low:g} to {doubt_high:g} "
                            f"{unit})")
    for side in ("Left", "Right"):
        leg, asis = subject.get(side + "LegLength"), subject.get(side + "AsisTrocanterDistance")
        if leg is None or asis is None:
            continue
        if not 0 < asis <= ASIS_TROCHANTER_MAX[1] * leg:
            raise ValueError(f"{source}: {side}AsisTrocanterDistance = {asis:g} mm is "
                             f"impossible with {side}LegLength = {leg:g} mm (expected 0 to "
                             f"{ASIS_TROCHANTER_MAX[1]:g} of it; Davis's regression gives "
                             f"{0.1288 * leg - 48.56:.0f} mm)")
        if asis > ASIS_TROCHANTER_MAX[0] * leg:
            doubtful.append(f"{side}AsisTrocanterDistance = {asis:g} (more than "
                            f"{ASIS_TROCHANTER_MAX[0]:g} of the leg length)")
    if doubtful:
        warn(f"{source}: doubtful measurement(s) {'; '.join(doubtful)}: check their units "
             f"and values", RuntimeWarning)


def _median_distance(a, b):
    with np.errstate(invalid="ignore"):
        d = vector_length(a - b)
    return float(np.nanmedian(d)) if np.isfinite(d).any() else np.nan


def _compare(measured, value, name, what, source, doubtful):
    """An error if `value` and `measured` differ by AGREEMENT_RATIO[1]; doubtful beyond [0]."""
    if not (np.isfinite(measured) and measured > 0):
        return
    ratio = max(value / measured, measured / value)
    if ratio > AGREEMENT_RATIO[1]:
        raise ValueError(f"{source}: {name} = {value:g} mm contradicts the markers ({what} "
                         f"= {measured:.0f} mm, {ratio:.1f} times apart): a unit error?")
    if ratio > AGREEMENT_RATIO[0]:
        doubtful.append(f"{name} = {value:g} mm ({what} {measured:.0f} mm)")


def check_measurements_against_markers(points, subject, source="subject", trial="the trial"):
    """The measurements agree with the trial's markers within :data:`AGREEMENT_RATIO`.

    The inter-ASIS distance against the median LASI-RASI distance; each leg length
    (ASIS to medial malleolus) against the median distance from the ASIS to the lateral
    malleolus marker (ANK), which differ by the half ankle width and the marker's radius
    (a few % of the leg). The widths are checked by :func:`check_measurement_ranges`.

    Parameters
    ----------
    points : dict
        Standard names -> (frames, 3) positions in mm (``LASI``, ``RASI``, ``LANK``, ...).
    subject : dict
        The measurements (Vicon's names, mm).
    source, trial : str, optional
        Names for the messages.

    Raises
    ------
    ValueError
        If a measurement and the markers are more than ``AGREEMENT_RATIO[1]`` (3) times
        apart.

    Warns
    -----
    RuntimeWarning
        One warning naming the measurements more than 1.5 times off.
    """
    doubtful = []
    if "InterAsisDistance" in subject:
        _compare(_median_distance(points["LASI"], points["RASI"]),
                 subject["InterAsisDistance"], "InterAsisDistance",
                 f"LASI-RASI in {trial}", source, doubtful)
    for side, p in (("Left", "L"), ("Right", "R")):
        leg = _median_distance(points[p + "ASI"], points[p + "ANK"])
        _compare(leg, subject[side + "LegLength"], side + "LegLength",
                 f"{p}ASI-{p}ANK in {trial}", source, doubtful)
    if doubtful:
        warn(f"{source}: measurement(s) {'; '.join(doubtful)} disagree with the markers "
             f"of {trial}: check their units and values", RuntimeWarning)


def zero_points_as_missing(points, trial="the trial"):
    """Points exactly at (0, 0, 0), written by some tables for a gap, made NaN in place.

    Returns the number of (marker, frame) entries changed; one warning names the markers.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.checks import zero_points_as_missing
    >>> points = {"LKNE": np.array([[1.0, 2, 3], [0, 0, 0]])}
    >>> import warnings
    >>> with warnings.catch_warnings(record=True):
    ...     zero_points_as_missing(points)
    1
    >>> print(points["LKNE"][1])
    [nan nan nan]
    """
    counts = {}
    for name, values in points.items():
        # the three comparisons joined: the same booleans as (values == 0.0).all(axis=-1),
        # several times faster than a reduction over an axis of length 3
        zero = (values[..., 0] == 0.0) & (values[..., 1] == 0.0) & (values[..., 2] == 0.0)
        if zero.any():
            values[zero] = np.nan
            counts[name] = int(zero.sum())
    if counts:
        warn(f"{trial}: points at exactly (0, 0, 0) taken as missing (a gap written as "
             f"zeros): {', '.join(f'{n} in {c} frames' for n, c in counts.items())}",
             RuntimeWarning)
    return sum(counts.values())


def check_leg_marker_order(points, trial="the trial", static=False):
    """Frames whose leg markers are in an order no body takes; flagged markers made NaN.

    Per side and frame: THI nearer the ASIS than KNE is (the thigh wand lies between hip
    and knee), TIB nearer KNE than ANK is (a wand swapped with the joint marker beside
    it); and each lateral marker
    (THI, KNE, TIB, ANK) and TOE of the right leg to the subject's right of the left
    leg's, along RASI - LASI (one pair swapped between the sides: lateral markers sit
    outside both legs, so the swap puts them a leg's breadth on the wrong side; in the
    shipped walk the toes are never nearer than 100 mm, the lateral markers 198 mm; a
    walk whose feet cross, as on a tightrope, is flagged).

    Parameters
    ----------
    points : dict
        Standard names -> (frames, 3) positions (mm); changed in place: the markers of a
        flagged frame are NaN there.
    trial : str, optional
        The trial's name, for the messages.
    static : bool, optional
        A static trial: also ANK nearer KNE than TOE is (TOE and ANK swapped; in a
        walk a flexed knee and a plantar-flexed foot bring the toe nearer), HEE nearer
        ANK than TOE is (heel and toe swapped), and the
        right HEE and TOE to the subject's right of the left ones (standing, the feet
        are apart; in walking they may cross, so not checked there).

    Returns
    -------
    ndarray of bool, shape (frames,)
        The frames flagged.

    Raises
    ------
    ValueError
        If a check flags every frame that can be judged (the trial is labelled wrong).

    Warns
    -----
    RuntimeWarning
        One per check that flags some frames, naming the markers.
    """
    frames = len(points["LASI"])
    flagged = np.zeros(frames, dtype=bool)
    with np.errstate(invalid="ignore"):
        right = points["RASI"] - points["LASI"]
        right = right / vector_length(right)[:, None]
        for name in ("THI", "KNE", "TIB", "ANK", "TOE") + (("HEE",) if static else ()):
            if "R" + name not in points or "L" + name not in points:
                continue
            apart = np.einsum("fi,fi->f", points["R" + name] - points["L" + name], right)
            judged = np.isfinite(apart)
            bad = judged & (apart < 0)
            report_flagged_frames(
                bad, judged, trial,
                f"R{name} lies to the subject's left of L{name} (along RASI - LASI): the "
                f"pair is swapped between the sides", f"L{name} and R{name} are NaN")
            for p in "LR":
                points[p + name][bad] = np.nan
            flagged |= bad
        for p in "LR":
            for near, far, ref in (("THI", "KNE", "ASI"), ("TIB", "ANK", "KNE")) + (
                    (("ANK", "TOE", "KNE"), ("HEE", "TOE", "ANK")) if static else ()):
                if p + near not in points or p + far not in points:
                    continue
                a = vector_length(points[p + near] - points[p + ref])
                b = vector_length(points[p + far] - points[p + ref])
                judged = np.isfinite(a) & np.isfinite(b)
                bad = judged & (a >= b)
                report_flagged_frames(
                    bad, judged, trial,
                    f"{p}{near} is farther from {p}{ref} than {p}{far} is ({p}{near} and "
                    f"{p}{far} swapped, or misplaced)", f"{p}{near} and {p}{far} are NaN")
                for name in (near, far):
                    points[p + name][bad] = np.nan
                flagged |= bad
    return flagged


def _blame(off):
    """The leg markers to blame, from which pairs of :data:`LEG_PAIRS` are off (pair ->
    bool or array of bool): a marker with one pair (TOE) when it is off and ANK is not
    blamed, with two (THI, TIB) when both are, with three (KNE, ANK) when two are (a
    misplaced knee marker moves along the shank, nearly keeping its distance to TIB)."""
    blamed = {}
    for name in ("THI", "KNE", "TIB", "ANK", "TOE"):
        mine = [off[pair] for pair in off if name in pair]
        if mine:
            blamed[name] = np.sum(mine, axis=0) >= min(2, len(mine))
    if "TOE" in blamed and "ANK" in blamed:
        blamed["TOE"] = blamed["TOE"] & ~blamed["ANK"]
    return blamed


def check_leg_distances(points, leg_length, trial="the trial"):
    """Frames in which a leg marker has jumped: its distances to the other markers of its
    leg (:data:`LEG_PAIRS`; all of them, or two of three for KNE and ANK) differ from their medians over the trial by more than
    ``DISTANCE_CHANGE_MAX`` (0.1) times the leg length. The flagged marker is NaN there.

    Parameters
    ----------
    points : dict
        Standard names -> (frames, 3) positions (mm); changed in place.
    leg_length : dict
        ``'L'`` and ``'R'`` -> the leg length (mm).
    trial : str, optional
        The trial's name, for the messages.

    Returns
    -------
    ndarray of bool, shape (frames,)
        The frames flagged (any marker of either leg).

    Warns
    -----
    RuntimeWarning
        One warning naming the markers and their frame counts.
    """
    frames = len(points["LASI"])
    flagged = np.zeros(frames, dtype=bool)
    jumped = {}
    for p in "LR":
        tolerance = DISTANCE_CHANGE_MAX * leg_length[p]
        off = {}
        with np.errstate(invalid="ignore"):
            for a, b in LEG_PAIRS:
                d = vector_length(points[p + a] - points[p + b])
                if not np.isfinite(d).any():
                    continue
                off[a, b] = np.abs(d - np.nanmedian(d)) > tolerance
        if off:
            jumped[p] = _blame(off)
        for name, bad in jumped.get(p, {}).items():
            points[p + name][bad] = np.nan
            flagged |= bad
    named = [f"{p}{name} in {int(bad.sum())}" for p in jumped
             for name, bad in jumped[p].items() if bad.any()]
    if named:
        warn_frames(int(flagged.sum()), frames,
                    f"of {trial} have a leg marker that jumped (its distances to the "
                    f"other markers of its leg change by more than {DISTANCE_CHANGE_MAX:g} "
                    f"of the leg length: a ghost marker or a swap): {', '.join(named)}; "
                    f"that marker is NaN there")
    return flagged


def leg_calibration(points):
    """The static trial's reference geometry for :func:`check_against_static`: per side
    the median distance of each pair of :data:`LEG_PAIRS` (``('L', 'KNE', 'ANK')`` ->
    mm) and the median separation of the thigh wands along RASI - LASI (``'THI'``)."""
    reference = {(p, a, b): _median_distance(points[p + a], points[p + b])
                 for p in "LR" for a, b in LEG_PAIRS}
    right = points["RASI"] - points["LASI"]
    with np.errstate(invalid="ignore"):
        right = right / vector_length(right)[:, None]
        apart = np.einsum("fi,fi->f", points["RTHI"] - points["LTHI"], right)
    reference["THI"] = float(np.nanmedian(apart)) if np.isfinite(apart).any() else np.nan
    return reference


def check_against_static(points, reference, leg_length, trial="the trial"):
    """The leg markers sit where the static trial calibrated them.

    A marker placed elsewhere in the trial than in the static trial (a knee marker on the
    shank or at the wand, a toe marker at the heel) changes its distances to the other
    markers of its leg in every frame: a marker whose pairs' median distances
    (:data:`LEG_PAIRS`; all of them, or two of three for KNE and ANK) differ from the
    static trial's by more than ``STATIC_CHANGE_MAX`` (0.05) of the leg length is misplaced. A thigh wand placed
    medially brings the thigh wands closer along RASI - LASI by as much (their separation
    is set by the pelvis, not the stance: 414 mm standing, 410 mm walking, in the shipped
    trials).

    Parameters
    ----------
    points : dict
        Standard names -> (frames, 3) positions (mm).
    reference : dict
        :func:`leg_calibration` of the static trial.
    leg_length : dict
        ``'L'`` and ``'R'`` -> the leg length (mm).
    trial : str, optional
        The trial's name, for the messages.

    Raises
    ------
    ValueError
        Naming the misplaced marker(s) and their distances here and in the static trial.
    """
    now = leg_calibration(points)
    wrong = []
    for p in "LR":
        tolerance = STATIC_CHANGE_MAX * leg_length[p]
        off = {(a, b): abs(now[p, a, b] - reference[p, a, b]) > tolerance
               for a, b in LEG_PAIRS if np.isfinite(now[p, a, b] - reference[p, a, b])}
        for name, bad in _blame(off).items():
            mine = [pair for pair in off if name in pair]
            if bad:
                wrong.append(f"{p}{name} (" + ", ".join(
                    f"{p}{a}-{p}{b} {now[p, a, b]:.0f} mm here, {reference[p, a, b]:.0f} in "
                    f"the static trial" for a, b in mine) + ")")
    closer = reference["THI"] - now["THI"]
    if closer > STATIC_CHANGE_MAX * min(leg_length.values()):
        wrong.append(f"LTHI or RTHI (the thigh wands {now['THI']:.0f} mm apart here, "
                     f"{reference['THI']:.0f} in the static trial: one placed medially?)")
    if wrong:
        raise ValueError(f"{trial}: marker(s) placed elsewhere than in the static trial: "
                         f"{'; '.join(wrong)}. Plug-in Gait's offsets are calibrated on "
                         f"the static trial's markers: check the labels and the placement")


#: Angle (degrees) between the body's mean vertical in a trial and the nearest lab axis
#: above which the lab's vertical is doubtful: gait_events' threshold
#: (:data:`bmc_functions.gait.events.VERTICAL_TILT_DEG`, 30). The body's vertical (from the
#: midpoint of the ANK markers to that of the ASIS markers, averaged over the trial) lies
#: 8-13 degrees from the lab's z axis in the shipped static trial and walk and in the
#: walks over force plates the project's tests use (the ASISs sit ahead of the ankles).
VERTICAL_TILT_DEG = 30.0


def check_lab_vertical(points, trial="the trial"):
    """One warning when no lab axis is within ``VERTICAL_TILT_DEG`` of the body's vertical.

    Plug-in Gait takes the lab axis nearest to the pelvis's up axis as the vertical of
    its pelvis and foot progression angles: a lab tilted by 40 degrees (a trial exported
    in another frame, a calibration L-frame on a slope) moves them by as much, without
    changing the joint angles.

    Parameters
    ----------
    points : dict
        Standard names -> (frames, 3) positions (``LASI``, ``RASI``, ``LANK``, ``RANK``).
    trial : str, optional
        The trial's name, for the message.

    Returns
    -------
    float
        The angle (degrees) from the body's vertical to the nearest lab axis; NaN when it
        cannot be judged.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.checks import check_lab_vertical
    >>> body = {"LASI": [[0, 120, 900]], "RASI": [[0, -120, 900]],
    ...         "LANK": [[-100, 100, 80]], "RANK": [[-100, -100, 80]]}
    >>> round(check_lab_vertical({k: np.array(v, float) for k, v in body.items()}), 1)
    7.0
    """
    up = (points["LASI"] + points["RASI"] - points["LANK"] - points["RANK"]) / 2.0
    up = up[np.isfinite(up).all(axis=1)]
    if not len(up):
        return np.nan
    mean = up.mean(axis=0)
    cosine = np.abs(mean).max() / np.linalg.norm(mean)
    angle = float(np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0))))
    if angle > VERTICAL_TILT_DEG:
        axis = "xyz"[int(np.abs(mean).argmax())]
        warn(f"{trial}: the body's vertical (from the ANK markers to the ASIS markers) is "
             f"{angle:.0f} degrees from the nearest lab axis ({axis}): the lab's vertical is "
             f"not where the trial says, and the pelvis and foot progression angles are "
             f"relative to that axis; rotate the trial so that a lab axis is vertical",
             RuntimeWarning)
    return angle


#: The thigh wand's distance medial to the line from the hip centre to KNE (along the
#: pelvis's lateral axis, median over the trial), as a fraction of the leg length, beyond
#: which it is placed medially: 0.03 L = 26 mm for the shipped subject. The wands of the
#: shared trials lie 54 to 96 mm lateral of that line (median; the Plug-in Gait subject
#: 59 to 64, sample14 and newwalk 76 to 96), Walk1's (placed at the front of the thigh)
#: 6 mm medial to 2 mm lateral; a wand moved to the medial thigh lies 60 mm or more medial.
THIGH_WAND_MEDIAL_MAX = 0.03


def pelvis_axes(points, pelvis=None):
    """The CGM pelvis frame (columns x anterior, y left, z up) and its origin, per frame:
    `pelvis` when the caller has them already (:func:`cgm_pelvis_frame` of these points)."""
    if pelvis is not None:
        return pelvis
    return cgm_pelvis_frame(points["RASI"], points["LASI"], points["SACRUM"])


def check_toe_ahead_of_ankle(points, trial="the trial", pelvis=None):
    """A ValueError when a leg's TOE lies behind its ANK along the pelvis's anterior axis
    in the median frame (TOE and ANK swapped in every frame, or a toe marker at the heel).

    The toe marker (on the second metatarsal head) lies in front of the lateral malleolus
    whatever the foot does: 139 to 182 mm in the median frame of the shipped trials, 75
    to 146 mm in the shared walks (sample14, newwalk, Walk1, the Codamotion walks, whose
    turns put it behind in 6 to 13 % of the frames). A swap in a run of frames is left
    to :func:`check_leg_distances`.

    Parameters
    ----------
    points : dict
        Standard names -> (frames, 3) positions (mm), with ``'SACRUM'``.
    trial : str, optional
        The trial's name, for the message.
    pelvis : tuple, optional
        ``(R, origin)`` of :func:`cgm_pelvis_frame` of these points, when the caller has
        them (computed here otherwise).

    Returns
    -------
    dict
        ``'L'``, ``'R'`` -> the median distance (mm) of TOE ahead of ANK (NaN if no frame
        has both).

    Examples
    --------
    Each TOE is (150, -+20, -40) mm from its ANK, the pelvis's anterior axis
    (160, 0, -20)/161.2 (the ASIS midpoint less the sacrum): 153.8 mm ahead.

    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.checks import check_toe_ahead_of_ankle
    >>> body = {"LASI": [100, 120, 900], "RASI": [100, -120, 900], "SACRUM": [-60, 0, 920],
    ...         "LANK": [0, 100, 80], "LTOE": [150, 80, 40], "RANK": [0, -100, 80],
    ...         "RTOE": [150, -80, 40]}
    >>> ahead = check_toe_ahead_of_ankle({k: np.array([v], float) for k, v in body.items()})
    >>> print({side: round(value) for side, value in ahead.items()})
    {'L': 154, 'R': 154}
    """
    R_pelvis, _ = pelvis_axes(points, pelvis)
    ahead = {}
    for p in "LR":
        if p + "TOE" not in points or p + "ANK" not in points:
            continue
        along = np.einsum("fi,fi->f", points[p + "TOE"] - points[p + "ANK"], R_pelvis[:, :, 0])
        along = along[np.isfinite(along)]
        ahead[p] = float(np.median(along)) if along.size else np.nan
    behind = [p for p, value in ahead.items() if value < 0]
    if behind:
        raise ValueError(f"{trial}: " + "; ".join(
            f"{p}TOE lies {-ahead[p]:.0f} mm behind {p}ANK along the pelvis's anterior axis "
            f"(median frame)" for p in behind) + ": the toe marker is in front of the "
            "ankle marker in a foot; TOE and ANK swapped (or the toe marker at the heel)? "
            "Check the labels")
    return ahead


def check_thigh_wands(points, subject, trial="the trial", pelvis=None):
    """A ValueError when a thigh wand lies medial to the line from the hip centre to KNE
    by more than :data:`THIGH_WAND_MEDIAL_MAX` of the leg length (median frame): a wand
    placed on the medial thigh turns the femur's frame by about 180 degrees about its
    long axis, in the static trial as in the walk, so comparing the two cannot see it.

    The hip centre is Davis et al.'s (:func:`davis_hip_centre`, the subject's
    measurements; the markers' inter-ASIS distance when the subject gives none yet); the
    offset is measured along the pelvis's lateral axis.

    Parameters
    ----------
    points : dict
        Standard names -> (frames, 3) positions (mm), with ``'SACRUM'``.
    subject : dict
        The model's measurements (leg lengths, ASIS-trochanter distances, marker
        diameter, inter-ASIS distance).
    trial : str, optional
        The trial's name, for the message.
    pelvis : tuple, optional
        As for :func:`check_toe_ahead_of_ankle`.

    Returns
    -------
    dict
        ``'L'``, ``'R'`` -> the wand's median lateral offset (mm; negative: medial).
    """
    R_pelvis, origin = pelvis_axes(points, pelvis)
    iad = subject.get("InterAsisDistance")
    if iad is None:
        with np.errstate(invalid="ignore"):
            iad = float(np.nanmedian(np.linalg.norm(points["LASI"] - points["RASI"],
                                                    axis=-1)))
    mean_leg = (subject["LeftLegLength"] + subject["RightLegLength"]) / 2.0
    offsets, medial = {}, []
    for p, long, side in (("L", "Left", "left"), ("R", "Right", "right")):
        hip = davis_hip_centre(R_pelvis, origin, mean_leg_length=mean_leg,
                               asis_trochanter=subject[long + "AsisTrocanterDistance"],
                               inter_asis_distance=iad,
                               marker_radius=subject["MarkerDiameter"] / 2.0, side=side)
        with np.errstate(invalid="ignore"):
            axis = points[p + "KNE"] - hip
            axis /= vector_length(axis)[:, None]
            wand = points[p + "THI"] - hip
            wand -= np.einsum("fi,fi->f", wand, axis)[:, None] * axis
            lateral = R_pelvis[:, :, 1] * (1.0 if p == "L" else -1.0)
            offset = np.einsum("fi,fi->f", wand, lateral)
        offset = offset[np.isfinite(offset)]
        offsets[p] = float(np.median(offset)) if offset.size else np.nan
        if offsets[p] < -THIGH_WAND_MEDIAL_MAX * subject[long + "LegLength"]:
            medial.append(p)
    if medial:
        raise ValueError(f"{trial}: " + "; ".join(
            f"{p}THI lies {-offsets[p]:.0f} mm medial to the line from the hip centre to "
            f"{p}KNE (median frame)" for p in medial) + ": the thigh wand belongs on the "
            f"lateral thigh (a medial wand turns the femur's frame by about 180 degrees); "
            f"check its placement and label")
    return offsets
