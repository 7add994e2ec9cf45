"""A trial's Plug-in Gait markers: their labels found (prefixes, renames, case), the
units and the body's handedness checked."""

import numpy as np

from ...files.trial import MarkerTable, load_trial
from ...rigid_body.rotations import vector_length
from ..lower_limb_checks import (LEGS_CROSSED, check_units, coordinate_centroids,
                                 report_flagged_frames)
from .lower_body import LEG_MARKERS, PELVIS_MARKERS
from .upper_body import UPPER_BODY_MARKERS


def resolve_labels(data, markers, trial):
    """Standard name -> the trial's label, for the Plug-in Gait names present.

    `markers` renames (standard name -> label); otherwise a label equal to the standard
    name, or 'Prefix:NAME' with one prefix in the whole trial, or else the one label equal
    to it but for the case ('lasi', 'Sub01:Lasi'). The upper body's names are looked up
    the same way; none of them is required."""
    labels = data.labels
    present = set(labels)
    resolved = {}
    names = (list(PELVIS_MARKERS) + [p + m for p in "LR" for m in LEG_MARKERS]
             + list(UPPER_BODY_MARKERS))
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


def check_markers(resolved, data, trial):
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


def check_trial_units(points, labels, units, trial):
    """Refuse a trial whose declared units are wrong (metres labelled mm, or the reverse):
    the ASIS distance (median over the frames) must be a pelvis's
    (:func:`~bmc_functions.models.lower_limb_checks.check_units`)."""
    with np.errstate(invalid="ignore"):
        width = vector_length(points["RASI"] - points["LASI"])
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
    # visible_centroid of the leg markers, summed without their stack
    legs = coordinate_centroids([points[p + name].T for p in "LR"
                                 for name in ("THI", "KNE", "TIB", "ANK")])[1]
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
    thigh = {p: coordinate_centroids([points[p + "THI"].T, points[p + "KNE"].T])[1]
             for p in "LR"}
    width = vector_length(right)
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


#: Plug-in Gait's marker names -> the roles of :func:`~bmc_functions.gait_events`.
EVENT_ROLES = {"RASI": "RASIS", "LASI": "LASIS", "RPSI": "RPSIS", "LPSI": "LPSIS",
               "SACR": "SACRUM", **{p + m: p + role for p in "LR" for m, role in
                                    (("HEE", "HEEL"), ("TOE", "TOE"), ("ANK", "ANKLE_LAT"))}}


def trial_event_markers(trial, markers=None):
    """The mapping :func:`~bmc_functions.gait_events` takes, from a Plug-in Gait trial's
    own labels, without a model: its labels found as :func:`resolve_labels` finds them
    (subject prefixes ``'Sub01:LASI'``, renames `markers`, case), the PSIS markers when
    both hold data, else SACR; HEE where the trial has it.

    Returns
    -------
    (pandas.DataFrame, dict)
        The trial read, and role -> label (``'RASIS'`` -> ``'RASI'``, ``'RHEEL'`` ->
        ``'RHEE'``, ...), as ``PlugInGait.event_markers()`` gives them after a trial.

    Examples
    --------
    >>> from bmc_functions.examples import example_file
    >>> from bmc_functions.models.plug_in_gait.labels import trial_event_markers
    >>> _, roles = trial_event_markers(example_file("plug_in_gait/Movement_trial.c3d"))
    >>> roles["RHEEL"], roles["LTOE"], "SACRUM" in roles
    ('RHEE', 'LTOE', False)
    """
    df, label = load_trial(trial, "trial")
    data = MarkerTable(df, label)
    resolved = resolve_labels(data, markers or {}, label)
    resolved = {name: value for name, value in resolved.items() if data.has_data(value)}
    psis = all(name in resolved for name in ("LPSI", "RPSI"))
    roles = {EVENT_ROLES[name]: value for name, value in resolved.items()
             if name in EVENT_ROLES and (name not in ("LPSI", "RPSI", "SACR")
                                         or (name == "SACR") != psis)}
    missing = [name for name in ("RASI", "LASI", "RTOE", "LTOE") if name not in resolved]
    if not (psis or "SACR" in resolved):
        missing.append("SACR or LPSI and RPSI")
    if missing:
        raise ValueError(f"{label}: missing Plug-in Gait marker(s) {', '.join(missing)} "
                         f"that gait events need (labels found: "
                         f"{', '.join(data.labels[:30])}); rename with markers=")
    return df, roles
