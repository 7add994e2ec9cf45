r"""Clinical joint angles from the 3D keypoints of a markerless pose estimator.

Video keypoints (OpenPose, RTMPose, MediaPipe... triangulated by Pose2Sim or another tool)
are joint centres and a few foot points, not anatomical landmarks: no ASIS, no
epicondyles, no malleoli. :func:`keypoint_angles` builds the ISB segment frames of
:mod:`~bmc_functions.models.segments` from what they do give, and reads the angles with
the joint coordinate systems of :mod:`~bmc_functions.models.joints` — the names, signs and
Cardan sequences of the marker pipeline (:func:`~bmc_functions.calibrate_lower_limb`)::

    angles = keypoint_angles("trial.trc", keypoints="body25b")
    angles["knee", "right", "flexion"]              # degrees, indexed by time (s)

The keypoint sets are data (:mod:`~bmc_functions.models.keypoint_sets`); the estimator's
mistakes are found by :mod:`~bmc_functions.models.keypoint_checks`.
"""

from pathlib import Path

import numpy as np
import pandas as pd

from .._checks import ArgumentTypeError, check_flag, warn
from ..files.trial import MarkerTable, load_trial, mm_per_unit
from ..rigid_body.frames import frame_from_axes, nearest_lab_axis
from .joints import ankle_angles, hip_angles, knee_angles, pelvis_angles
from .keypoint_checks import (bone_lengths, bone_outliers, frame_ranges, jumps, side_swaps)
from .keypoint_sets import KEYPOINT_SETS, ROLES
from .lower_limb import JOINT_ANGLES
from .segments import foot_frame, shank_frame, thigh_frame

#: The joints and angles of :func:`keypoint_angles`: the lower-limb pipeline's, then the
#: trunk (relative to the pelvis), the shoulder (humerus relative to the trunk), the elbow.
KEYPOINT_JOINT_ANGLES = {**JOINT_ANGLES,
                         "trunk": ("flexion", "lateral_bending", "rotation"),
                         "shoulder": ("flexion", "abduction", "rotation"),
                         "elbow": ("flexion",)}

#: Angles no keypoint set defines (NaN in every frame): see :func:`keypoint_angles`.
UNDEFINED = (("knee", "adduction"), ("knee", "rotation"), ("ankle", "inversion"),
             ("trunk", "flexion"))

#: Below this angle between two bones (degrees of knee or elbow flexion) the plane of the
#: three keypoints (hip-knee-ankle, shoulder-elbow-wrist) is not used: its normal, which
#: gives the rotation about the proximal bone, is then dominated by the keypoints' noise
#: (1 cm of noise across a 40 cm bone is 1.4 degrees of direction; at 15 degrees of
#: flexion the ankle is 10 cm off the thigh's line, so the plane turns by about 6 degrees).
PLANE_MIN_DEG = 15.0

#: The same for the elbow, higher: the forearm of a straight arm deviates laterally from
#: the humerus by the carrying angle (about 10-15 degrees in adults; Paraskevas et al.
#: 2004), so the plane of shoulder, elbow and wrist is the carrying angle's, not the
#: flexion's, until the elbow bends well past it (on the shared static trial, at 16
#: degrees of flexion, it put the shoulder's rotation at -140 degrees).
ELBOW_PLANE_MIN_DEG = 30.0

#: Half the distance between the virtual epicondyles (and malleoli) placed on the knee's
#: flexion axis to build the ISB frames (mm; any length gives the same frames).
_HALF_WIDTH_MM = 50.0

#: Order of the angle names in the columns' third level, so that each joint's angles are
#: lexsorted in the order of KEYPOINT_JOINT_ANGLES.
_ANGLE_ORDER = ("tilt", "obliquity", "flexion", "adduction", "abduction", "lateral_bending",
                "dorsiflexion", "inversion", "rotation")


def _column_index():
    levels = [list(KEYPOINT_JOINT_ANGLES), ["right", "left"], list(_ANGLE_ORDER)]
    columns = [(joint, side, angle) for joint, angles in KEYPOINT_JOINT_ANGLES.items()
               for side in ("right", "left") for angle in angles]
    codes = [[level.index(column[k]) for column in columns] for k, level in enumerate(levels)]
    return pd.MultiIndex(levels=levels, codes=codes, names=["joint", "side", "angle"])


def keypoint_mapping(keypoints):
    """The checked role -> label mapping and its display name, from a set name or a dict.

    Parameters
    ----------
    keypoints : str or dict
        A name of :data:`KEYPOINT_SETS` ('body25b', 'halpe26', 'coco17', 'blazepose'), or
        a dict role -> label with roles from :data:`ROLES`.

    Returns
    -------
    mapping : dict
    name : str

    Examples
    --------
    >>> from bmc_functions.models.keypoints import keypoint_mapping
    >>> mapping, name = keypoint_mapping("coco17")
    >>> mapping["RKNEE"], "RHEEL" in mapping
    ('RKnee', False)
    """
    if isinstance(keypoints, str):
        if keypoints not in KEYPOINT_SETS:
            raise ValueError(f"keypoints must be one of {', '.join(map(repr, KEYPOINT_SETS))} "
                             f"or a dict role -> label; got {keypoints!r}")
        return dict(KEYPOINT_SETS[keypoints]), keypoints
    if not isinstance(keypoints, dict):
        raise ArgumentTypeError(f"keypoints must be a keypoint set's name (a str) or a dict "
                                f"role -> label; got {type(keypoints).__name__}")
    unknown = [role for role in keypoints if role not in ROLES]
    if unknown:
        raise ValueError(f"keypoints: unknown role(s) {unknown}; the roles are "
                         f"{', '.join(ROLES)}")
    bad = {role: label for role, label in keypoints.items() if not isinstance(label, str)}
    if bad:
        raise ValueError(f"keypoints: each label must be a str; got {bad}")
    labels = list(keypoints.values())
    twice = sorted({label for label in labels if labels.count(label) > 1})
    if twice:
        raise ValueError(f"keypoints: label(s) {twice} mapped to more than one role")
    return dict(keypoints), "custom"


def _points(table, mapping, scale, trial_name, set_name):
    """Role -> (F, 3) positions in mm for every role (NaN where the trial lacks it)."""
    frames = len(table.values)
    found = {role: label for role, label in mapping.items() if table.has_data(label)}
    if not found:
        raise ValueError(f"{trial_name} has none of the keypoints of keypoints={set_name!r} "
                         f"({', '.join(mapping.values())}); its labels are "
                         f"{', '.join(table.labels[:30])}. Give the set the estimator used, "
                         f"or a dict role -> label")
    absent = [label for role, label in mapping.items() if role not in found]
    if absent:
        warn(f"{trial_name} lacks keypoint(s) {', '.join(absent)} of keypoints={set_name!r} "
             f"(or they are empty): the angles that need them are NaN", UserWarning)
    nan = np.full((frames, 3), np.nan)
    return {role: table.points(found[role], scale) if role in found else nan
            for role in ROLES if not role.endswith("SMALL_TOE")}      # not used


def screen_keypoints(points, time, trial_name, labels=None):
    """The estimator's mistakes set to NaN, with one warning naming keypoints and frames.

    Parameters
    ----------
    points : dict
        Role -> (F, 3) positions (mm); not modified.
    time : ndarray, shape (F,)
    trial_name : str
    labels : dict, optional
        Role -> label, to name the keypoints as the file does (default: the roles).

    Returns
    -------
    dict
        The same roles, with NaN in the flagged frames.
    """
    points = {role: value.copy() for role, value in points.items()}
    name = {role: (labels or {}).get(role, role) for role in points}
    found = []
    for role, mask in side_swaps(points).items():
        for p in "RL":
            points[p + role][mask] = np.nan
        found.append(f"{name['R' + role]} and {name['L' + role]} swapped between sides in "
                     f"rows {frame_ranges(mask, time)}")
    lengths = bone_lengths(points)
    thighs = [np.nanmedian(v) for (bone, _, _), v in lengths.items()
              if ("thigh" in bone or "upper arm" in bone) and np.isfinite(v).any()]
    masks, limits = jumps(points, max(thighs) if thighs else 0.0)
    for role, mask in masks.items():
        points[role][mask] = np.nan
        found.append(f"{name[role]} off its path by more than {limits[role]:.0f} mm in rows "
                     f"{frame_ranges(mask, time)}")
    for (bone, a, b), (mask, median, limit) in bone_outliers(bone_lengths(points)).items():
        points[a][mask] = np.nan
        points[b][mask] = np.nan
        found.append(f"the {bone} ({name[a]}-{name[b]}) off its median length {median:.0f} "
                     f"mm by more than {limit:.0f} mm in rows {frame_ranges(mask, time)}")
    if found:
        flagged = np.zeros(len(time), bool)
        for role, value in points.items():
            flagged |= np.isnan(value).any(axis=1)
        warn(f"keypoint_angles: the pose estimator's mistakes in {trial_name} (rows counted "
             f"from 0): " + "; ".join(found) + ". Those keypoints are NaN in those rows, and "
             "the angles that use them", RuntimeWarning)
    return points


def _unit(v):
    with np.errstate(invalid="ignore", divide="ignore"):
        return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _bend(proximal, joint, distal):
    """Angle (degrees) between the bones joint->proximal continued and joint->distal."""
    cosine = np.einsum("fi,fi->f", _unit(joint - proximal), _unit(distal - joint))
    return np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))


def plane_axis(proximal, joint, distal, fallback, flip=1.0, min_deg=PLANE_MIN_DEG):
    """The flexion axis of a hinge-like joint from three keypoints, with its validity.

    Parameters
    ----------
    proximal, joint, distal : ndarray, shape (F, 3)
        E.g. hip, knee, ankle.
    fallback : ndarray, shape (F, 3)
        The direction used where the bones are within `min_deg` of straight.
    flip : float
        -1 to turn the normal around (the elbow bends the other way from the knee).
    min_deg : float
        The flexion below which the plane is not used.

    Returns
    -------
    axis : ndarray, shape (F, 3)
        Unit normal of the plane of the three points, pointing to the subject's right
        when the joint is flexed ((proximal - joint) x (distal - joint) for the knee);
        the fallback where the joint is nearly straight.
    defined : ndarray of bool, shape (F,)
        Where the plane was used.
    """
    normal = flip * np.cross(proximal - joint, distal - joint)
    with np.errstate(invalid="ignore"):
        defined = _bend(proximal, joint, distal) >= min_deg
    axis = np.where(defined[:, None], _unit(normal), _unit(fallback))
    # a fallback along the bone (a limb held out sideways) gives no frame: NaN
    along = np.abs(np.einsum("fi,fi->f", axis, _unit(proximal - joint)))
    with np.errstate(invalid="ignore"):
        axis[along > 0.999] = np.nan
    return axis, defined


def _frame(primary, secondary, axes):
    """frame_from_axes with NaN (not an error) where a direction is zero or they align."""
    primary, secondary = _unit(primary), _unit(secondary)
    with np.errstate(invalid="ignore"):
        bad = np.linalg.norm(np.cross(primary, secondary), axis=-1) < 1e-6
    primary = np.where(bad[:, None], np.nan, primary)
    return frame_from_axes(primary, secondary, axes=axes)


def _trunk_top(points):
    """The neck keypoint where it is seen, else the mid-point of the shoulders."""
    mid_shoulders = (points["RSHOULDER"] + points["LSHOULDER"]) / 2
    return np.where(np.isfinite(points["NECK"]), points["NECK"], mid_shoulders)


def _leg_frames(points, side, R_pelvis):
    """Thigh, shank and foot frames of one side, and where the knee's plane is used."""
    p, sign = ("R", 1.0) if side == "right" else ("L", -1.0)
    hip, knee, ankle = points[p + "HIP"], points[p + "KNEE"], points[p + "ANKLE"]
    axis, defined = plane_axis(hip, knee, ankle, R_pelvis[:, :, 2])
    offset = sign * _HALF_WIDTH_MM * axis
    R_thigh, _ = thigh_frame(hip, knee + offset, knee - offset, side=side)
    R_shank, _ = shank_frame(knee + offset, knee - offset, ankle + offset, ankle - offset,
                             side=side)
    # No sole plane from the small toe: it lies a few cm off the heel-toe line, and the
    # plane through it flips with the keypoints' noise (on the shared Pose2Sim trial the
    # dorsiflexion then jumped by 100 degrees). The foot's roll follows the shank, as
    # without MT5 in the marker pipeline.
    toes = points[p + "TOE"]
    heel = points[p + "HEEL"]
    if np.isfinite(heel).any() and np.isfinite(toes).any():
        R_foot, _ = foot_frame(heel, toes, ankle + offset, ankle - offset, side=side)
    else:
        R_foot = np.full_like(R_thigh, np.nan)
    return R_thigh, R_shank, R_foot, defined


def segment_frames(points):
    """Every segment frame (F, 3, 3) of :func:`keypoint_angles` and the validity masks.

    Parameters
    ----------
    points : dict
        Role -> (F, 3) positions (every role of :data:`ROLES`; NaN where missing).

    Returns
    -------
    dict
        ``'pelvis'``, ``'trunk'``, and per side ``('thigh' | 'shank' | 'foot' |
        'humerus' | 'forearm', side)`` -> rotation matrices; ``('knee_plane', side)`` and
        ``('elbow_plane', side)`` -> (F,) masks of the frames where the joint's plane
        gives the rotation about the bone.
    """
    mid_hip = (points["RHIP"] + points["LHIP"]) / 2
    up = _trunk_top(points) - mid_hip
    frames = {"pelvis": _frame(points["RHIP"] - points["LHIP"], up, "zy"),
              "trunk": _frame(up, points["RSHOULDER"] - points["LSHOULDER"], "yz")}
    for side in ("right", "left"):
        p = "R" if side == "right" else "L"
        thigh, shank, foot, defined = _leg_frames(points, side, frames["pelvis"])
        frames.update({("thigh", side): thigh, ("shank", side): shank, ("foot", side): foot,
                       ("knee_plane", side): defined})
        shoulder, elbow, wrist = (points[p + k] for k in ("SHOULDER", "ELBOW", "WRIST"))
        axis, defined = plane_axis(shoulder, elbow, wrist, frames["trunk"][:, :, 2], -1.0,
                                   ELBOW_PLANE_MIN_DEG)
        frames[("humerus", side)] = _frame(shoulder - elbow, axis, "yz")
        frames[("forearm", side)] = _frame(elbow - wrist, axis, "yz")
        frames[("elbow_plane", side)] = defined
    return frames


def _lab_frame(R_pelvis, mid_hip):
    """Forward (x), vertical (y), right (z) as signed lab axes, from the pelvis frames: as
    the lower-limb pipeline does (the travel if over 250 mm, else the pelvis' heading)."""
    valid = np.isfinite(R_pelvis).all(axis=(1, 2)) & np.isfinite(mid_hip).all(axis=1)
    if not valid.any():
        return None
    y, y_axis = nearest_lab_axis(R_pelvis[valid][:, :, 1].mean(axis=0))
    path = mid_hip[valid][-1] - mid_hip[valid][0]
    path = path - (path @ y) * y
    heading = R_pelvis[valid][:, :, 0].mean(axis=0)
    forward = path if np.linalg.norm(path) > 250.0 and heading @ path > 0 else heading
    x, _ = nearest_lab_axis(forward, exclude=y_axis)
    return np.column_stack([x, y, np.cross(x, y)])


def _side_angles(frames, side, lab):
    """(F, 13) degrees of one side, in the order of KEYPOINT_JOINT_ANGLES."""
    R_pelvis, R_trunk = frames["pelvis"], frames["trunk"]
    count = len(R_pelvis)
    pelvis = (pelvis_angles(R_pelvis, side, R_lab=lab, degrees=True) if lab is not None
              else np.full((count, 3), np.nan))
    hip = hip_angles(R_pelvis, frames[("thigh", side)], side, degrees=True)
    knee = knee_angles(frames[("thigh", side)], frames[("shank", side)], side, degrees=True)
    ankle = ankle_angles(frames[("shank", side)], frames[("foot", side)], side, degrees=True)
    trunk = hip_angles(R_pelvis, R_trunk, side, degrees=True)
    shoulder = hip_angles(R_trunk, frames[("humerus", side)], side, degrees=True)
    shoulder[:, 1] *= -1.0                                   # abduction = -adduction
    elbow = -knee_angles(frames[("humerus", side)], frames[("forearm", side)], side,
                         degrees=True)[:, :1]                # the elbow bends forwards
    straight_knee = ~frames[("knee_plane", side)]
    hip[straight_knee, 2] = np.nan
    ankle[straight_knee, 2] = np.nan
    shoulder[~frames[("elbow_plane", side)], 2] = np.nan
    knee[:, 1:] = np.nan
    ankle[:, 1] = np.nan
    trunk[:, 0] = np.nan
    return np.concatenate([pelvis, hip, knee, ankle, trunk, shoulder, elbow], axis=1)


def _angles_of(trial, mapping, set_name, what):
    """Angles (F, 26) in degrees of one trial, its time index, units and lab frame."""
    keypoints, trial_name = load_trial(trial, what)
    scale, units = mm_per_unit(keypoints, trial_name)
    table = MarkerTable(keypoints, trial_name)
    time = keypoints.index.to_numpy()
    points = _points(table, mapping, scale, trial_name, set_name)
    points = screen_keypoints(points, np.asarray(time, float) if time.dtype.kind in "iuf"
                              else np.arange(len(time), dtype=float), trial_name, mapping)
    frames = segment_frames(points)
    lab = _lab_frame(frames["pelvis"], (points["RHIP"] + points["LHIP"]) / 2)
    values = np.concatenate([_side_angles(frames, side, lab) for side in ("right", "left")],
                            axis=1)
    order = [(joint, side, angle) for side in ("right", "left")
             for joint, angles in KEYPOINT_JOINT_ANGLES.items() for angle in angles]
    columns = list(_column_index())
    values = values[:, [order.index(column) for column in columns]]
    return values, keypoints.index.copy(), units, lab


def _column_median(values):
    """Median of each column over the rows that have a value (NaN for an empty column)."""
    seen = np.isfinite(values).any(axis=0)
    out = np.full(values.shape[1], np.nan)
    out[seen] = np.nanmedian(values[:, seen], axis=0)
    return out


def keypoint_angles(trial, keypoints="body25b", *, static=None, relative_to_static=False):
    r"""Clinical joint angles from a trial of 3D keypoints (markerless motion capture).

    Parameters
    ----------
    trial : pandas.DataFrame or path
        The keypoints: a DataFrame from :func:`read_trc` (e.g. a Pose2Sim TRC), or a path
        to a .trc or .c3d file; in mm, cm or m (``attrs['units']``), any lab axes (the
        vertical and forward axes are found from the body, as the marker pipeline does).
        Use the filtered keypoints where there are both (Pose2Sim filters at 6 Hz).
    keypoints : str or dict, optional
        The keypoint set: ``'body25b'`` (default; Pose2Sim's), ``'halpe26'``,
        ``'coco17'`` (no feet: no ankle angles; no neck) or ``'blazepose'``, see
        :mod:`~bmc_functions.models.keypoint_sets`; or a dict role -> label with the
        roles ``RHIP RKNEE RANKLE RHEEL RTOE RSHOULDER RELBOW RWRIST`` (``L`` for the
        left), ``NECK`` and ``RSMALL_TOE``/``LSMALL_TOE`` (accepted, not used). Labels of the trial
        not in the mapping are ignored; a role that is missing leaves out only the angles
        that need it (NaN).
    static : pandas.DataFrame or path, keyword-only, optional
        A standing trial of the same keypoints, screened and computed the same way. Its
        angles (median over its frames) are kept in ``attrs['static_angles']``.
    relative_to_static : bool, keyword-only
        Subtract the static trial's angles from every angle except the pelvis' (which
        stays relative to the lab), as ``static_offset`` does in
        :func:`calibrate_lower_limb`. An angle the standing posture leaves undefined
        (hip, ankle or shoulder rotation about a straight knee or elbow) keeps its
        absolute value, and ``attrs['notes']`` names it. Default False.

    Returns
    -------
    pandas.DataFrame
        Degrees, indexed by the trial's time; columns ``(joint, side, angle)``, the same
        names and signs as :meth:`LowerLimbModel.angles` for the lower limb:

        - ``pelvis``: ``tilt`` (anterior +), ``obliquity`` (this side up +), ``rotation``
          (this side forwards +), relative to the lab (Baker's rotation-obliquity-tilt);
        - ``hip``: ``flexion``, ``adduction``, ``rotation`` (internal +);
        - ``knee``: ``flexion``; ``adduction`` and ``rotation`` NaN (see Notes);
        - ``ankle``: ``dorsiflexion``, ``rotation`` (internal +); ``inversion`` NaN;
        - ``trunk`` relative to the pelvis: ``flexion`` NaN (see Notes),
          ``lateral_bending`` (towards this side +), ``rotation`` (this side's shoulder
          forwards +);
        - ``shoulder`` (humerus relative to the trunk): ``flexion``, ``abduction``,
          ``rotation`` (internal +);
        - ``elbow``: ``flexion``.

        ``attrs``: ``'units'`` 'deg', ``'keypoint_units'``, ``'keypoints'`` (the set's
        name or 'custom'), ``'lab_frame'``, ``'relative_to_static'``,
        ``'static_angles'`` (a dict column -> degrees, with `static`) and ``'notes'``.

    Raises
    ------
    ValueError
        An unknown keypoint set or role, a label that is not a str or is given to two
        roles; a trial with none of the set's keypoints (the message lists its labels);
        units missing or unknown; ``relative_to_static=True`` without `static`.
    TypeError
        `trial` or `static` of another type than a DataFrame or a path; `keypoints`
        neither a str nor a dict (an ArgumentTypeError, also a ValueError);
        `relative_to_static` not a bool.

    Warns
    -----
    UserWarning
        Keypoints of the set that the trial lacks (the angles that need them are NaN).
    RuntimeWarning
        Once per trial, the pose estimator's mistakes found in the keypoints (see
        Notes), naming the keypoints and the rows: they are set to NaN there, and so are
        the angles that use them.

    Notes
    -----
    *Segment frames* (ISB axes: x anterior, y superior, z to the right, both sides):

    - pelvis: z from the left to the right hip keypoint, y towards the neck keypoint (the
      mid-point of the shoulders without one) made perpendicular to z. **The keypoints
      have no point of the pelvis but the hip centres**, so the pelvis' tilt cannot be
      told from the lumbar spine's flexion: here the pelvis and the trunk lean together,
      ``pelvis tilt`` is the forward lean of the hips-to-neck line from the vertical
      (-3 degrees on the shared static trial, where the marker pipeline's ASIS-PSIS
      pelvis on Pose2Sim's LSTM markers tilts 11 degrees anteriorly), obliquity and
      rotation are those of the hip line; the hip flexion is then the thigh relative to
      that line (a spine that flexes shows as hip flexion). ``relative_to_static``
      removes the standing offsets.
    - thigh and shank: the long axes from hip to knee and knee to ankle; their
      medio-lateral axis is the knee's flexion axis, the normal to the plane of hip, knee
      and ankle (:func:`plane_axis`), in place of the epicondylar line of
      :func:`thigh_frame` and :func:`shank_frame` (which build the frames here from
      virtual epicondyles and malleoli on that axis). Where the knee is within
      ``PLANE_MIN_DEG = 15`` degrees of straight the plane is undefined (its normal is
      noise): the pelvis' z is used instead and **hip rotation is NaN there** (and ankle
      rotation, which needs the shank's orientation about its axis). A knee hyperextended
      by more than that angle reads as flexed, and its hip rotation 180 degrees off (the
      plane's normal turns to the left, and the frames with it; hip flexion and adduction
      are unaffected): a hip rotation near +-180 degrees means genu recurvatum.
    - foot (:func:`foot_frame` without MT5): x from the heel to the toe keypoint (the big
      toe, or the tip of the foot); its roll follows the shank, so **ankle inversion is
      NaN**, as in the marker pipeline without MT5. The small toe is not used: it lies a
      few cm off the heel-toe line and the sole's plane through it flips with the
      keypoints' noise (on the shared Pose2Sim trial the dorsiflexion then jumped by 100
      degrees).
    - trunk: y from the mid-hips to the neck keypoint, z along the shoulder line.
    - humerus and forearm: the long axes, and the elbow's flexion axis (the normal to the
      plane of shoulder, elbow and wrist) as z; the trunk's z where the elbow is within
      ``ELBOW_PLANE_MIN_DEG = 30`` degrees of straight (the carrying angle), where
      **shoulder rotation is NaN**.

    *Angles*: pelvis :func:`pelvis_angles`, hip :func:`hip_angles`, knee
    :func:`knee_angles`, ankle :func:`ankle_angles`; the trunk relative to the pelvis and
    the humerus relative to the trunk with the hip's ZXY sequence (flexion about the
    proximal z, ab/adduction about the floating axis, rotation about the distal long
    axis, the left side's second and third angles negated); the shoulder's abduction is
    minus that adduction. The shoulder's ZXY (flexion first) is the hip's sequence, read
    as clinicians describe arm movements in the sagittal plane; ISB's humerus-thorax
    sequence YXY (plane of elevation, elevation, axial rotation; Wu et al. 2005) is
    singular with the arm at the side, where arms are in gait and balance, while ZXY is
    singular at 90 degrees of abduction (a warning says so). The elbow's flexion is the
    angle between humerus and forearm.

    *Not defined by keypoints* (NaN in every frame, never zeros): the knee's adduction
    and rotation (thigh and shank share the knee's flexion axis by construction, so both
    would read zero); the ankle's inversion (see the foot); the trunk's flexion relative
    to the pelvis (the pelvis frame takes its anterior axis from the trunk). Where a
    joint is nearly straight, the rotation about the proximal bone (hip, shoulder) and
    the ankle's rotation (see above).

    *The estimator's mistakes* (:mod:`~bmc_functions.models.keypoint_checks`), judged
    from the trial's own scale: a keypoint exchanged with its other-side partner (a knee,
    an ankle, an elbow...) in some frames, found from the frame-to-frame steps
    (``SWAP_RATIO``); a keypoint off its path for up to ``JUMP_FRAMES = 5`` frames, by
    more than ten times its usual distance from its running median and 0.3 times the
    trial's median thigh length; a bone (thigh, shank, foot, upper arm, forearm) whose
    length departs from its median by more than 6 robust standard deviations and 30 %.

    *Against OpenSim* (Pose2Sim's demo balancing trial, ``data/real/markerless``, filtered
    keypoints, against OpenSim's inverse kinematics of Pose2Sim's LSTM markers; the full
    table in notebook 06, the limits in tests/test_keypoint_angles.py): r = 0.92-0.98 and
    3-6 degrees RMS about the mean offset for pelvis tilt, hip flexion and adduction, knee
    and ankle flexion; 0.93 for the shoulder's elevation; elbow flexion 0.95 (right) and
    0.80 (left, a small, noisy range); pelvis obliquity 0.90, rotation 0.79; hip rotation
    0.92 on the left and only 0.39 on the right, whose knee is often nearly straight. The
    offsets reach 25 degrees (the elbow): the models' zeros differ.

    References
    ----------
    .. [1] Wu G et al. (2002) ISB recommendation on definitions of joint coordinate
       system of various joints for the reporting of human joint motion - part I: ankle,
       hip, and spine. J Biomech 35:543-548.
    .. [2] Wu G et al. (2005) ISB recommendation ... part II: shoulder, elbow, wrist and
       hand. J Biomech 38:981-992.
    .. [3] Grood ES, Suntay WJ (1983) J Biomech Eng 105:136-144.
    .. [4] Baker R (2001) Pelvic angles. Gait Posture 13:1-6.
    .. [5] Paraskevas G, Papadopoulos A, Papaziogas B et al. (2004) Study of the carrying
       angle of the human elbow joint in full extension: a morphometric analysis. Surg
       Radiol Anat 26:19-23.
    .. [6] Pagnon D, Domalain M, Reveret L (2022) Pose2Sim: an open-source Python package
       for multiview markerless kinematics. J Open Source Softw 7:4362.

    Examples
    --------
    A standing pose made by hand (metres, y up, facing +z; body25b labels):

    >>> import numpy as np, pandas as pd
    >>> from bmc_functions import keypoint_angles
    >>> pose = {"RHip": (-0.1, 0.9, 0), "LHip": (0.1, 0.9, 0), "Neck": (0, 1.45, 0),
    ...         "RKnee": (-0.1, 0.5, 0.08), "RAnkle": (-0.1, 0.1, 0)}
    >>> df = pd.DataFrame([np.ravel(list(pose.values()))] * 2, index=[0.0, 0.01],
    ...                   columns=pd.MultiIndex.from_product([pose, ["x", "y", "z"]]))
    >>> df.attrs["units"] = "m"
    >>> import warnings
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")     # the keypoints this pose lacks
    ...     angles = keypoint_angles(df, "body25b")
    >>> print(angles["knee", "right", "flexion"].round(1).tolist())
    [22.6, 22.6]
    >>> print(angles["hip", "right"].iloc[0].round(1).to_dict())
    {'flexion': 11.3, 'adduction': 0.0, 'rotation': 0.0}
    """
    mapping, set_name = keypoint_mapping(keypoints)
    relative_to_static = check_flag(relative_to_static, "relative_to_static")
    if relative_to_static and static is None:
        raise ValueError("relative_to_static=True needs a static trial (static=...); got "
                         "static=None")
    if not isinstance(trial, (pd.DataFrame, str, Path)):
        raise ArgumentTypeError(f"trial must be a DataFrame from read_trc/read_c3d or a path "
                                f"to a .trc or .c3d file; got {type(trial).__name__}")
    values, index, units, lab = _angles_of(trial, mapping, set_name, "keypoint")
    columns = _column_index()
    attrs = {"units": "deg", "keypoint_units": units, "keypoints": set_name,
             "lab_frame": None if lab is None else lab.tolist(),
             "relative_to_static": relative_to_static,
             "notes": [f"not defined by keypoints, NaN: "
                       f"{', '.join(' '.join(u) for u in UNDEFINED)}; hip and ankle rotation "
                       f"are NaN where the knee is within {PLANE_MIN_DEG:g} degrees of "
                       f"straight, shoulder rotation where the elbow is within "
                       f"{ELBOW_PLANE_MIN_DEG:g}"]}
    if static is not None:
        static_values = _angles_of(static, mapping, set_name, "static")[0]
        offset = _column_median(static_values)
        attrs["static_angles"] = {column: float(v) for column, v in zip(columns, offset)}
        if relative_to_static:
            pelvis = np.array([column[0] == "pelvis" for column in columns])
            # an angle the standing posture leaves undefined (a rotation about a straight
            # limb) keeps its absolute value, and the notes say so
            unset = np.isnan(offset) & np.isfinite(values).any(axis=0) & ~pelvis
            if unset.any():
                attrs["notes"].append(
                    "not relative to the static trial (undefined there, e.g. a rotation "
                    "about a straight knee or elbow): " + ", ".join(
                        " ".join(column) for column, u in zip(columns, unset) if u))
            values = values - np.where(pelvis | unset, 0.0, offset)
    if not any(role.endswith("HEEL") for role in mapping):
        attrs["notes"].append(f"keypoints={set_name!r} has no heel: the ankle angles are NaN")
    angles = pd.DataFrame(values, index=index, columns=columns)
    angles.attrs = attrs
    return angles
