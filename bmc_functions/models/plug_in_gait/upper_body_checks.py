r"""Checks of what Plug-in Gait's upper body is told: its measurements and markers.

The upper body takes every marker and measurement as given, as the lower body does
(:mod:`~bmc_functions.models.plug_in_gait.checks`): a shoulder offset in cm, the two
shoulder markers swapped, CLAV swapped with STRN, all give plausible-looking curves tens
of degrees off. These functions look at the data for what a real body forbids (arrays and
dicts in; flags, an error or one warning out):

- :data:`UPPER_BODY_RANGES`: every upper-body measurement within what a body allows, the
  head offset in radians (checked by
  :func:`~bmc_functions.models.plug_in_gait.checks.check_measurement_ranges`).
- :func:`check_upper_body_measurements`: each chord's offset (``ShoulderOffset``, half the
  ``ElbowWidth``, half the ``HandThickness``, plus the marker radius) shorter than the
  distance from its marker to the proximal joint centre, as the chord needs.
- :func:`check_upper_body_markers`: per frame, the thorax markers in their order along the
  trunk (CLAV above STRN, C7 above T10), the left markers of the shoulders, elbows and head
  to the subject's left of the right ones, and each arm's markers in their order along the
  arm (the wrist bar short beside the forearm, FIN beyond the wrist bar); and no marker
  farther from the pelvis than a body reaches. Flagged markers are NaN in those frames, so
  that only the angles that use them are NaN.

The geometry behind each test is derived in its docstring; the margins are set against
the shared Plug-in Gait FullBody subject (a T-pose static trial and a walk), whose values
are quoted next to each constant.
"""

import numpy as np

from ..._checks import warn, warn_frames
from ..lower_limb_checks import report_flagged_frames
from .upper_body import (THORAX_MARKERS, cgm_thorax_frame, elbow_joint_centre,
                         shoulder_joint_centre, wrist_joint_centre)

#: Upper-body measurement (mm or rad) -> (impossible below, doubtful below, doubtful above,
#: impossible above), as :data:`~bmc_functions.models.plug_in_gait.checks.
#: MEASUREMENT_RANGES`. Vicon's Plug-in Gait reference guide defines them: the shoulder
#: offset, the vertical distance from the acromion marker's base down to the glenohumeral
#: centre (the template's prior 50 mm; at least the humeral head's radius, 10 mm in a small
#: child to 25 mm in an adult, plus the acromion's thickness); the elbow width, across the
#: epicondyles (adults' elbow breadth is about 55-80 mm, the 5th percentile of women to
#: the 95th of men in the frame-size tables of Frisancho (1984), Am J Clin Nutr 40:808; the
#: shared subject's values, over soft tissue, 92-96 mm); the wrist width, the wrist's antero-posterior thickness where
#: the bar sits (adults about 35-65 mm; the shared subject 61-65 mm); the hand thickness,
#: dorsum to palm at the metacarpal heads (adults about 25-35 mm; the template's 30 mm).
#: The bounds are wide (a 3-year-old to a large adult, then a factor of about 2): a value
#: in cm (5 for 50) or x10 (960) is impossible. ``HeadOffset`` is an angle about the head's
#: lateral axis in radians: beyond pi/2 the head's forward axis would point down its back
#: (a value in degrees: 16 for 0.28 rad); beyond 0.7 rad (40 degrees) doubtful (the
#: shared subject's head-level offset is 0.28 rad).
UPPER_BODY_RANGES = {
    "ShoulderOffset": (10.0, 20.0, 120.0, 200.0),
    "ElbowWidth": (25.0, 40.0, 150.0, 250.0),
    "WristWidth": (15.0, 25.0, 110.0, 180.0),
    "HandThickness": (8.0, 15.0, 60.0, 100.0),
    "HeadOffset": (-np.pi / 2, -0.7, 0.7, np.pi / 2),
}

#: A chord's offset (measurement plus marker radius) beyond this fraction of the median
#: distance from its marker to the proximal joint centre is doubtful (the chord's joint
#: centre would sit more than 30 degrees off the segment's axis as seen from the proximal
#: centre); at 1 the chord has no solution. The shared subject: shoulder 0.30-0.34
#: (57 mm against 167-199 mm), elbow 0.18, hand 0.27.
CHORD_DOUBT = 0.5

#: The wrist bar (WRA to WRB) is shorter than this fraction of the distance from ELB to
#: either bar marker: it spans the wrist's breadth (60-70 mm in the shared subject), the
#: forearm its length (230-250 mm): 0.25-0.30 in both shared trials, and no more in a
#: child (bar about 40 mm, forearm 150 mm). A bar marker swapped with ELB, or with the
#: other arm's (the wrists farther apart than 0.6 forearm lengths), breaks it.
WRIST_BAR_MAX = 0.6

#: Pairs of upper-body markers whose distance stays constant over a trial -> the largest
#: change allowed from the trial's median, as a fraction of the leg length. On one rigid
#: body, 0.025 (22 mm for the shared subject): the head's four markers (one band; 5 mm at
#: most in the shared trials), the sternum (CLAV-STRN, 1 mm) and the wrist bar (4 mm).
#: Nearly rigid, 0.05 (44 mm): the upper and lower rings of the thorax (CLAV-C7, STRN-T10:
#: breathing, 3 mm), ELB to each bar marker (ELB lies near the forearm's pronation axis;
#: 8 mm) and FIN to each bar marker (across the wrist, whose flexion moves FIN by a few cm;
#: 6 mm in the walk). Beyond them a marker has jumped (a ghost, a swap in a run of frames).
UPPER_PAIRS = {**{pair: 0.025 for pair in (("LFHD", "RFHD"), ("LBHD", "RBHD"),
                                           ("LFHD", "LBHD"), ("RFHD", "RBHD"),
                                           ("LFHD", "RBHD"), ("RFHD", "LBHD"),
                                           ("CLAV", "STRN"), ("LWRA", "LWRB"),
                                           ("RWRA", "RWRB"))},
               **{pair: 0.05 for pair in (("CLAV", "C7"), ("STRN", "T10")) + tuple(
                   (p + a, p + b) for p in "LR" for a, b in (
                       ("ELB", "WRA"), ("ELB", "WRB"), ("WRA", "FIN"), ("WRB", "FIN")))}}

#: An upper-body marker farther from the midpoint of the ASIS markers than this many leg
#: lengths is no part of the body (a ghost, a point left at a lab default): a fingertip
#: held overhead is about 0.72 body heights (1.5 leg lengths) away.
FAR_FROM_PELVIS = 2.0


def _unit(v):
    with np.errstate(invalid="ignore", divide="ignore"):
        return v / _norm(v)[:, None]


def _norm(v):
    """Row norms of (frames, 3) (einsum: a third of numpy.linalg.norm's time)."""
    with np.errstate(invalid="ignore"):
        return np.sqrt(np.einsum("fi,fi->f", v, v))


def _has(points, *names):
    return all(name in points for name in names)


def _up(points):
    """The trunk's up direction per frame: from the ASIS midpoint to the thorax markers'
    centroid (NaN without them)."""
    if not _has(points, *THORAX_MARKERS):
        return np.full(points["LASI"].shape, np.nan)
    centroid = sum(points[name] for name in THORAX_MARKERS) / 4.0
    return _unit(centroid - (points["LASI"] + points["RASI"]) / 2.0)


def _left(points, radius):
    """The subject's left per frame: the thorax's y axis, else LASI - RASI."""
    left = _unit(points["LASI"] - points["RASI"])
    if _has(points, *THORAX_MARKERS):
        R, _ = cgm_thorax_frame(points["CLAV"], points["C7"], points["STRN"],
                                points["T10"], radius)
        usable = np.isfinite(R[..., :, 1]).all(axis=1)
        left[usable] = R[usable, :, 1]
    return left


def _flag(bad, judged, names, points, trial, what):
    """Report `bad` frames (an error if all judged frames are), NaN the named markers."""
    report_flagged_frames(bad, judged, trial, what,
                          f"{' and '.join(names)} are NaN (the angles that use them too)")
    for name in names:
        points[name][bad] = np.nan
    return bad


def _order(points, first, second, axis, trial, what):
    """Frames where `first` - `second` points against `axis` (judged where finite)."""
    with np.errstate(invalid="ignore"):
        along = np.einsum("fi,fi->f", points[first] - points[second], axis)
    judged = np.isfinite(along)
    return _flag(judged & (along < 0), judged, (first, second), points, trial, what)


def _nearer(points, near, far, ref, ratio, trial, what):
    """Frames where `near` is not nearer `ref` than `ratio` times `far` is."""
    a, b = _norm(points[near] - points[ref]), _norm(points[far] - points[ref])
    judged = np.isfinite(a) & np.isfinite(b)
    return _flag(judged & (a >= ratio * b), judged, (near, far), points, trial, what)


def _finger_beyond(points, p, trial):
    """Frames where a bar marker is at least as far from ELB as FIN is and farther than
    the other bar marker: that marker and FIN blamed (swapped, or FIN misplaced)."""
    d = {name: _norm(points[p + name] - points[p + "ELB"]) for name in ("WRA", "WRB", "FIN")}
    judged = np.isfinite(d["WRA"]) & np.isfinite(d["WRB"]) & np.isfinite(d["FIN"])
    flagged = np.zeros(len(judged), dtype=bool)
    for bar, other in (("WRA", "WRB"), ("WRB", "WRA")):
        with np.errstate(invalid="ignore"):
            bad = judged & (d[bar] >= d["FIN"]) & (d[bar] >= d[other]) & ~flagged
        flagged |= _flag(bad, judged, (p + bar, p + "FIN"), points, trial,
                         f"{p}{bar} is at least as far from {p}ELB as {p}FIN is (FIN lies "
                         f"beyond the wrist bar): {p}FIN and {p}{bar} swapped, or misplaced")
    return flagged


def _check_jumps(points, leg_length, trial):
    """Frames where an upper-body marker's distances to its partners of
    :data:`UPPER_PAIRS` leave their medians by more than their tolerance (fractions of
    `leg_length`): in all its pairs (two of three or more): that marker NaN there."""
    frames = len(points["LASI"])
    sample = np.unique(np.round(np.linspace(0, frames - 1, min(frames, MEDIAN_FRAMES)))
                       .astype(int))
    off = {}
    for (a, b), fraction in UPPER_PAIRS.items():
        if not _has(points, a, b):
            continue
        d = _norm(points[a] - points[b])
        if np.isfinite(d[sample]).any():
            with np.errstate(invalid="ignore"):
                off[a, b] = np.abs(d - np.nanmedian(d[sample])) > fraction * leg_length
    flagged = np.zeros(frames, dtype=bool)
    named = []
    for name in UPPER_BODY_CHECKED:
        mine = [off[pair] for pair in off if name in pair]
        if not mine:
            continue
        bad = np.sum(mine, axis=0) >= min(2, len(mine))
        if bad.any():
            named.append(f"{name} in {int(bad.sum())}")
            flagged |= bad
            points[name][bad] = np.nan
    if named:
        warn_frames(int(flagged.sum()), frames,
                    f"of {trial} have an upper-body marker that jumped (its distances to "
                    f"the markers on its segment change by more than "
                    f"{min(UPPER_PAIRS.values()) * leg_length:.0f}-"
                    f"{max(UPPER_PAIRS.values()) * leg_length:.0f} mm: a ghost marker or a "
                    f"swap): {', '.join(named)}; that marker is NaN there")
    return flagged


def _check_far(points, leg_length, trial):
    """Upper-body markers farther than FAR_FROM_PELVIS leg lengths from the ASIS midpoint:
    NaN there, one warning (an error for a marker far in every frame it has)."""
    asis = (points["LASI"] + points["RASI"]) / 2.0
    limit = FAR_FROM_PELVIS * leg_length
    flagged = np.zeros(len(asis), dtype=bool)
    named = []
    for name in UPPER_BODY_CHECKED:
        if name not in points:
            continue
        distance = _norm(points[name] - asis)
        with np.errstate(invalid="ignore"):
            far = distance > limit
        if far.any() and far.sum() == np.isfinite(distance).sum():
            raise ValueError(f"in every frame of {trial} ({int(far.sum())}), {name} is more "
                             f"than {limit:.0f} mm from the pelvis, where no body reaches "
                             f"(another subject's marker, a lab point, other units?)")
        if far.any():
            points[name][far] = np.nan
            flagged |= far
            named.append(f"{name} in {int(far.sum())}")
    if named:
        warn_frames(int(flagged.sum()), len(flagged),
                    f"of {trial} have an upper-body marker more than {limit:.0f} mm "
                    f"({FAR_FROM_PELVIS:g} leg lengths) from the pelvis, where no body "
                    f"reaches (a ghost, or a gap written as a lab point): {', '.join(named)}; "
                    f"that marker is NaN there")
    return flagged


#: The markers :func:`check_upper_body_markers` looks at.
UPPER_BODY_CHECKED = ("LFHD", "RFHD", "LBHD", "RBHD") + THORAX_MARKERS + tuple(
    p + m for p in "LR" for m in ("SHO", "ELB", "WRA", "WRB", "FIN"))


def check_upper_body_markers(points, leg_length, trial="the trial", marker_radius=7.0):
    r"""Frames whose upper-body markers are in an order no body takes; those markers NaN.

    Per frame, with *up* the direction from the midpoint of the ASIS markers to the
    centroid of the thorax markers and *left* the thorax's y axis (from
    :func:`~bmc_functions.models.plug_in_gait.upper_body.cgm_thorax_frame`; LASI - RASI
    where the thorax is undefined):

    - CLAV above STRN and C7 above T10 along *up*: both pairs run along the trunk, and the
      trunk does not flex 90 degrees on the pelvis (CLAV - STRN 162 mm, C7 - T10 252 mm
      up in the shared trials). A pair swapped reverses its own sign; *up* (the centroid)
      does not change;
    - LSHO, LELB, LFHD, LBHD to the subject's left of RSHO, RELB, RFHD, RBHD along
      *left* (the thorax checked first): shoulders and elbows do not cross the midline
      (286 mm and 580 mm apart at least in the shared trials), and the head turns less
      than 90 degrees on the thorax (the head's markers 83 mm apart at least). A pair
      swapped between the sides puts each a body's breadth on the wrong side. The wrists
      and fingers may cross (arms folded): they are not compared across the sides;
    - per arm, WRA and WRB each nearer the other than ``WRIST_BAR_MAX`` (0.6) times
      ELB's distance to it (the bar spans the wrist, the forearm is 3-4 times longer;
      0.30 at most in the shared trials): a bar marker swapped with ELB, or with the other
      arm's bar, breaks it; and FIN farther from ELB than WRA and WRB are (FIN lies beyond
      the wrist: ratio 1.25 at least in the shared trials; it fails only with the wrist
      flexed past about 100 degrees): FIN swapped with a bar marker puts that marker
      farthest, and it and FIN are blamed;
    - every upper-body marker within ``FAR_FROM_PELVIS`` (2) leg lengths of the ASIS
      midpoint (a ghost or a lab default elsewhere; exact zeros are taken as gaps before,
      by :func:`~bmc_functions.models.plug_in_gait.checks.zero_points_as_missing`);
    - then, in the frames left, each distance of :data:`UPPER_PAIRS` (markers on one
      rigid segment, or nearly) within 0.025 or 0.05 leg lengths of its median over the
      trial: a marker off in all its pairs (two of three or more) has jumped there (a
      ghost for a few frames).

    Parameters
    ----------
    points : dict
        Standard names -> (frames, 3) positions (mm), with ``LASI`` and ``RASI``; changed
        in place: the markers a test blames are NaN in its flagged frames. Absent markers
        are not checked.
    leg_length : float
        The mean leg length (mm).
    trial : str, optional
        The trial's name, for the messages.
    marker_radius : float, optional
        Half the marker diameter (mm), for the thorax frame.

    Returns
    -------
    ndarray of bool, shape (frames,)
        The frames flagged (any test).

    Raises
    ------
    ValueError
        If a test flags every frame it can judge (the trial is labelled wrong), naming
        the markers.

    Warns
    -----
    RuntimeWarning
        One per test that flags some frames, naming the markers and the frame count.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.models.plug_in_gait.upper_body_checks import (
    ...     check_upper_body_markers)
    >>> body = {"LASI": [[0, 120, 900.]], "RASI": [[0, -120, 900.]],
    ...         "CLAV": [[100, 0, 1400.]], "C7": [[-100, 0, 1450.]],
    ...         "STRN": [[100, 0, 1250.]], "T10": [[-100, 0, 1200.]]}
    >>> points = {k: np.array(v) for k, v in body.items()}
    >>> check_upper_body_markers(points, 880.0)
    array([False])
    >>> points["CLAV"], points["STRN"] = points["STRN"], points["CLAV"]
    >>> check_upper_body_markers(points, 880.0)
    Traceback (most recent call last):
    ...
    ValueError: in every frame of the trial (1), CLAV lies below STRN along the trunk (CLAV and STRN swapped?)
    """
    flagged = _check_far(points, leg_length, trial)
    up = _up(points)
    for top, bottom in (("CLAV", "STRN"), ("C7", "T10")):
        if _has(points, top, bottom):
            flagged |= _order(points, top, bottom, up, trial,
                              f"{top} lies below {bottom} along the trunk ({top} and "
                              f"{bottom} swapped?)")
    left = _left(points, marker_radius)   # the thorax's, once its markers are checked
    for name in ("SHO", "ELB", "FHD", "BHD"):
        if _has(points, "L" + name, "R" + name):
            flagged |= _order(points, "L" + name, "R" + name, left, trial,
                              f"R{name} lies to the subject's left of L{name} (along the "
                              f"thorax's lateral axis): the pair is swapped between the sides")
    for p in "LR":
        for near, other in (("WRA", "WRB"), ("WRB", "WRA")):
            if _has(points, p + near, p + "ELB", p + other):
                flagged |= _nearer(points, p + near, p + "ELB", p + other, WRIST_BAR_MAX,
                                   trial, f"{p}{near} is not beside {p}{other} (the wrist bar "
                                   f"longer than {WRIST_BAR_MAX:g} of its distance to "
                                   f"{p}ELB): {p}{near} swapped with {p}ELB or with the "
                                   f"other arm's, or misplaced")
        if _has(points, p + "WRA", p + "WRB", p + "FIN", p + "ELB"):
            flagged |= _finger_beyond(points, p, trial)
    flagged |= _check_jumps(points, leg_length, trial)
    return flagged


def _chord_distances(points, subject, radius):
    """Per chord (measurement name -> (offset, median distance, marker, centre)): the
    distance from its marker to the proximal joint centre, where the markers allow."""
    out = {}
    if not _has(points, *THORAX_MARKERS):
        return out
    R, origin = cgm_thorax_frame(points["CLAV"], points["C7"], points["STRN"],
                                 points["T10"], radius)
    for side, p, long in (("left", "L", "Left"), ("right", "R", "Right")):
        if not _has(points, p + "SHO"):
            continue
        delta = subject[long + "ShoulderOffset"] + radius
        out[long + "ShoulderOffset"] = (delta, _median(points[p + "SHO"] - origin),
                                        p + "SHO", "the thorax origin")
        if not _has(points, p + "ELB", p + "WRA", p + "WRB"):
            continue
        sjc = shoulder_joint_centre(R, origin, points[p + "SHO"], delta, side)
        delta = subject[long + "ElbowWidth"] / 2.0 + radius
        out[long + "ElbowWidth"] = (delta, _median(points[p + "ELB"] - sjc), p + "ELB",
                                    "the shoulder centre")
        if not _has(points, p + "FIN"):
            continue
        ejc = elbow_joint_centre(sjc, points[p + "ELB"], points[p + "WRA"],
                                 points[p + "WRB"], delta, side)
        wjc = wrist_joint_centre(ejc, points[p + "WRA"], points[p + "WRB"],
                                 subject[long + "WristWidth"] / 2.0 + radius, side)
        out[long + "HandThickness"] = (subject[long + "HandThickness"] / 2.0 + radius,
                                       _median(points[p + "FIN"] - wjc), p + "FIN",
                                       "the wrist centre")
    return out


#: The median distances of :func:`check_upper_body_measurements` are taken over at most
#: this many frames, evenly spaced (a median over 2000 frames of a trial moves by less
#: than a millimetre; the check then costs the same for a 10-minute trial as a 20-s one).
MEDIAN_FRAMES = 2000


def _median(difference):
    d = _norm(difference)
    return float(np.nanmedian(d)) if np.isfinite(d).any() else np.nan


def check_upper_body_measurements(points, subject, trial="the trial", source="subject"):
    r"""Each upper-body chord's offset shorter than its marker's distance to the proximal
    joint centre.

    The chord function places a joint centre :math:`C` at the offset :math:`\delta` from
    its marker :math:`M`, with :math:`M - C` perpendicular to :math:`C - P` (:math:`P` the
    proximal joint centre), so :math:`|M - P|^2 = \delta^2 + |C - P|^2`: it needs
    :math:`\delta < |M - P|`. The offsets are ``ShoulderOffset`` (SHO from the thorax
    origin), ``ElbowWidth`` / 2 (ELB from the shoulder centre) and ``HandThickness`` / 2
    (FIN from the wrist centre), each plus the marker radius. Beyond
    ``CHORD_DOUBT`` (0.5) of the median distance the centre sits more than 30 degrees
    off the line from :math:`P` to :math:`M`, a doubt. The medians are taken over at most
    ``MEDIAN_FRAMES`` (2000) frames, evenly spaced.

    Parameters
    ----------
    points : dict
        Standard names -> (frames, 3) positions (mm); absent markers leave their chords
        out.
    subject : dict
        The measurements (Vicon's names, mm), with ``MarkerDiameter``.
    trial, source : str, optional
        Names for the messages.

    Raises
    ------
    ValueError
        If an offset is at least the median distance (no joint centre exists in most
        frames), naming the measurement, its value and the distance.

    Warns
    -----
    RuntimeWarning
        One warning naming the doubtful measurements.
    """
    radius = subject["MarkerDiameter"] / 2.0
    frames = max((len(values) for values in points.values()), default=0)
    sample = np.unique(np.round(np.linspace(0, frames - 1, min(frames, MEDIAN_FRAMES)))
                       .astype(int))
    doubtful = []
    for name, (delta, distance, marker, centre) in _chord_distances(
            {k: v[sample] for k, v in points.items()}, subject, radius).items():
        if not np.isfinite(distance):
            continue
        said = (f"{name} = {subject[name]:g} mm (the chord's offset {delta:.0f} mm against "
                f"{marker}'s median distance {distance:.0f} mm to {centre} in {trial})")
        if delta >= distance:
            raise ValueError(f"{source}: {said}: no joint centre exists at that offset; "
                             f"check the measurement's unit and value")
        if delta > CHORD_DOUBT * distance:
            doubtful.append(said)
    if doubtful:
        warn(f"{source}: doubtful measurement(s) {'; '.join(doubtful)}: an offset beyond "
             f"{CHORD_DOUBT:g} of the distance; check their units and values",
             RuntimeWarning)
