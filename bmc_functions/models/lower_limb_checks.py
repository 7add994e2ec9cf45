r"""Checks of the lower-limb pipeline: the static posture and every dynamic trial.

What a mislabelled marker or a bad trial does to joint angles is a plausible-looking but
wrong curve; these checks turn each such case into an error or a warning that names the
side and the markers (used by :func:`~bmc_functions.calibrate_lower_limb`):

- the static posture's geometry (:func:`check_static_geometry`): left and right, lateral
  and medial, and each cluster on its own segment;
- a static trial that is not static (:func:`check_still`);
- in each dynamic trial (:func:`warn_dynamic`): frames where a cluster has fewer than 3
  visible markers, and clusters that deform (svdt residual far above its static value).
"""

import warnings

import numpy as np

from .._checks import warn, warn_frames
from ..markers.roles import SIDE_PREFIX, pelvis_roles
from ..rigid_body.rotations import rotation_angle, vector_length
from ..rigid_body.svdt import COLLINEAR_RTOL, svdt

#: Largest distance (mm) a marker may travel from its median position in a static trial
#: before a warning: quiet standing moves markers by up to about 40 mm.
STATIC_MOTION_MM = 100.0

#: Largest rotation (degrees) of a segment's markers from their mean orientation in a static
#: trial before a warning: in quiet standing the pelvis, thigh and shank turn by well under
#: 1 degree (0.5 in the shared running subject's static trial); a subject who turns or
#: walks turns them by tens of degrees, and the mean posture then has no meaning.
STATIC_ROTATION_DEG = 10.0

#: A cluster counts as nearly collinear when the second singular value of its centred
#: static markers is below this fraction of the first.
COLLINEAR_WARN_RATIO = 0.15

#: A cluster deforms in a dynamic frame when its svdt RMSE exceeds both this many mm and
#: DEFORM_FACTOR times its static RMSE (real soft-tissue artefact stays below ~4 mm).
DEFORM_MM = 6.0
DEFORM_FACTOR = 5.0

#: Where a cluster's centroid may lie along its segment (0 distal end, 1 proximal end)
#: before "cluster on the wrong segment" is reported.
SEGMENT_SPAN = (-0.15, 1.15)

#: Farthest a foot cluster's centroid may lie up the shank (0 ankle, 1 knee): a foot
#: cluster sits on the foot, below the ankle or just above it.
FOOT_CLUSTER_SPAN = 0.35


#: Range of the distance (mm) between the lateral and medial knee markers. The femur's
#: bicondylar width is 88.6 +- 4.2 mm in men and 78.5 +- 3.0 mm in women (Terzidis et al.
#: 2012, Anat Res Int 2012:679658, 360 dried femora), 64.5 +- 3.1 mm in Malay women
#: (Hussain et al. 2013, Biomed Res Int 2013:175056); the markers add their radius (about
#: 7 mm) and the soft tissue over the epicondyles on each side, and a child's knee is
#: smaller. A distance outside the range is not a knee: a marker is mapped to the wrong
#: label (e.g. a thigh-cluster marker).
#: The real walk of ../shared/data (an adult, markers on the skin) has its knee markers
#: 131-145 mm apart: the upper end leaves room for a larger knee. A thigh-cluster marker
#: mapped as a knee marker is caught by the tilt below even when its distance is human.
KNEE_WIDTH_MM = (50.0, 170.0)

#: Range of the distance (mm) between the lateral and medial malleolus markers (the
#: bimalleolar width is about 60-80 mm in adults, plus the markers and the skin).
ANKLE_WIDTH_MM = (40.0, 130.0)

#: Largest angle (degrees) between the line through a joint's lateral and medial markers
#: and the perpendicular to its segment's long axis: the epicondylar line is within a few
#: degrees of perpendicular to the femur's mechanical axis (the knee joint line is about
#: 3 degrees off it), the malleoli within about 10-20 degrees of the tibia's; 35 degrees
#: leaves 15 degrees of room for marker placement. Beyond it, one of the two markers is not
#: where its role says (a thigh marker mapped as a knee marker lies far up the thigh).
JOINT_LINE_TILT_DEG = 35.0


def segment_name(key):
    """'pelvis' or e.g. 'right thigh' for a (segment, side) key."""
    segment, side = key
    return segment if side is None else f"{side} {segment}"


def _static_groups(markers):
    """Marker groups that move as one rigid body in a static trial: each cluster, and the
    pelvis landmarks (name -> tuple of labels)."""
    groups = {role: value for role, value in markers.items() if isinstance(value, tuple)}
    pelvis = pelvis_roles(markers)
    if all(role in markers for role in pelvis):
        groups["pelvis markers"] = tuple(markers[role] for role in pelvis)
    return groups


def check_still(markers, table, scale, trial_name):
    """Warn once if the static trial is not static.

    `markers` maps roles to labels (a label, or a tuple of labels for a cluster), as
    :func:`~bmc_functions.read_marker_mapping` returns; the pelvis is found by its roles
    (:func:`~bmc_functions.markers.roles.pelvis_roles`).

    Two measures, the worst of each reported: how far a marker travels from its median
    position (more than ``STATIC_MOTION_MM``), and how far a rigid group of markers (a
    cluster, or the pelvis markers) turns from its mean orientation (more than
    ``STATIC_ROTATION_DEG``; svdt of the mean shape to each frame). A subject who turns on
    the spot moves markers less than 100 mm from their median, yet the mean of turning
    markers is a shrunken shape; the rotation catches that, and a walk (the segments turn
    relative to each other).
    """
    worst, worst_label = 0.0, None
    for label in {label for value in markers.values()
                  for label in (value if isinstance(value, tuple) else (value,))}:
        xyz = table.points(label, scale)
        if np.isnan(xyz).all():
            continue
        travel = float(np.nanmax(np.linalg.norm(xyz - np.nanmedian(xyz, axis=0), axis=1)))
        if travel > worst:
            worst, worst_label = travel, label
    turn, turn_group = 0.0, None
    for name, labels in _static_groups(markers).items():
        if len(labels) < 3 or not all(label in table.columns for label in labels):
            continue
        points = np.stack([table.points(label, scale) for label in labels], axis=1)
        seen = np.isfinite(points).all(axis=(1, 2))
        if seen.sum() < 2:
            continue
        mean = points[seen].mean(axis=0)
        shape = mean - mean.mean(axis=0)
        singular_values = np.linalg.svd(shape, compute_uv=False)
        if singular_values[1] <= COLLINEAR_RTOL * singular_values[0]:
            continue                     # collinear (svdt's rule): reported by the calibration
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            R, _, _ = svdt(shape, points[seen], order="row")
        angle = float(np.degrees(rotation_angle(R)).max())
        if angle > turn:
            turn, turn_group = angle, (name, labels)
    found = []
    if worst > STATIC_MOTION_MM:
        found.append(f"marker {worst_label!r} moves up to {worst:.0f} mm from its median "
                     f"position (quiet standing moves markers by up to about 40 mm; warning "
                     f"above {STATIC_MOTION_MM:.0f} mm)")
    if turn > STATIC_ROTATION_DEG:
        name, labels = turn_group
        what, verb, its = (("pelvis markers", "turn", "their") if name == "pelvis markers"
                           else (f"cluster {name}", "turns", "its"))
        found.append(f"the {what} ({', '.join(labels)}) {verb} by up to {turn:.0f} degrees "
                     f"from {its} mean orientation (quiet standing: about 1 degree; warning "
                     f"above {STATIC_ROTATION_DEG:.0f} degrees)")
    if found:
        warn(f"{trial_name} is not static: " + "; ".join(found) + ". The landmarks are "
             "calibrated from the mean posture: check that this is the standing "
             "calibration trial", RuntimeWarning)


#: Range of the distance between the ASISs (mm) that a pelvis can have: outside it, the
#: file's declared units are wrong (coordinates in m labelled mm, or the reverse).
PELVIS_WIDTH_MM = (80.0, 600.0)

#: A dynamic trial whose clusters are all this many times larger or smaller than in the
#: static trial is in other units than it declares.
UNITS_RATIO = 2.0


def check_units(markers, points, units, trial_name):
    """Raise if the pelvis width shows that the file's declared units are wrong."""
    rasis, lasis = (points.get(markers[role]) for role in ("RASIS", "LASIS"))
    if rasis is None or lasis is None:
        return
    width = float(np.linalg.norm(rasis - lasis))
    low, high = PELVIS_WIDTH_MM
    if not low <= width <= high:
        raise ValueError(
            f"{trial_name} declares its units as {units!r}, but then the distance between RASIS "
            f"({markers['RASIS']!r}) and LASIS ({markers['LASIS']!r}) is "
            f"{width:.4g} mm, while a pelvis is {low:.0f} to {high:.0f} mm wide: the file's "
            f"units are wrong (set df.attrs['units'] to the units the coordinates are in)")


#: Frames (at most, evenly spread) from which check_dynamic_units takes a cluster's size.
UNITS_CHECK_FRAMES = 2000


def check_dynamic_units(model, table, scale, units, trial_name):
    """Raise if every cluster is UNITS_RATIO times larger or smaller than in the static."""
    ratios = []
    # the median size of a cluster over UNITS_CHECK_FRAMES frames spread over the trial is
    # the median over all of them for this purpose (a factor of UNITS_RATIO or more), at a
    # fixed cost: the check took a fifth of the time of a 10-minute trial
    every = slice(None, None, max(1, len(table.values) // UNITS_CHECK_FRAMES))
    sample = table.values[every]                     # those frames only, then the labels
    for cluster, info in model.clusters.items():
        if not all(label in table.columns for label in info["labels"]):
            continue
        points = np.stack([sample[:, [table.columns[label][a] for a in "xyz"]] * scale
                           for label in info["labels"]], axis=1)     # table.points' values
        seen = np.isfinite(points).all(axis=(1, 2))
        if not seen.any():
            continue
        points = points[seen]
        centred = points - points.mean(axis=1, keepdims=True)
        size = np.median(np.sqrt((centred ** 2).sum(axis=2).mean(axis=1)))
        static = np.sqrt((info["local"] ** 2).sum(axis=1).mean())
        if 1 / UNITS_RATIO <= size / static <= UNITS_RATIO:
            return      # it raises only if every cluster is off: the others need no size
        ratios.append((size / static, cluster))
    if ratios and all(not 1 / UNITS_RATIO <= r <= UNITS_RATIO for r, _ in ratios):
        ratio, cluster = ratios[0]
        raise ValueError(
            f"{trial_name} declares its units as {units!r}, but then its clusters are {ratio:.3g} "
            f"times their size in the static trial ({cluster}: a marker set does not change "
            f"size): the file's units are wrong (set df.attrs['units'] to the units the "
            f"coordinates are in)")


def _joint_centre(point, side, joint):
    """Midpoint of a joint's lateral and medial markers ('KNEE' or 'ANKLE')."""
    p = SIDE_PREFIX[side]
    return (point(p + joint + "_LAT") + point(p + joint + "_MED")) / 2


def _opposite(side):
    return "left" if side == "right" else "right"


def check_static_geometry(model, points, hips):
    """Left/right, lateral/medial and cluster placement from the static posture."""
    def point(role):
        """Static position of a role's label; None for a role not in the mapping."""
        return points.get(model.markers[role]) if role in model.markers else None

    rasis, lasis = point("RASIS"), point("LASIS")
    posterior = pelvis_roles(model.markers)[2:]
    mid_asis = (rasis + lasis) / 2
    mid_knees = np.mean([_joint_centre(point, side, "KNEE") for side in model.sides], axis=0)
    anterior = mid_asis - np.mean([point(role) for role in posterior], axis=0)
    up = mid_asis - mid_knees
    up_unit = up / np.linalg.norm(up)
    _check_pelvis_depth(model, point, anterior, posterior)
    _check_asis_sides(model, rasis - lasis, np.cross(anterior, up))
    # From here on, 'right' is the pelvis's own medio-lateral axis (now checked).
    right = (rasis - lasis) / np.linalg.norm(rasis - lasis)
    forward = anterior - (anterior @ up_unit) * up_unit
    forward /= np.linalg.norm(forward)
    ankles = {side: _joint_centre(point, side, "ANKLE") for side in model.sides}
    # The feet's markers are judged against the midline between the two ankles when both
    # legs are mapped (a subject may stand off the pelvis's midline), else the pelvis's.
    midline = (sum(ankles.values()) / 2 if len(ankles) == 2 else mid_asis)
    for side in model.sides:
        sign = 1.0 if side == "right" else -1.0
        lateral = sign * right      # this side's lateral direction
        _check_leg_markers_sides(model, point, side, mid_asis, lateral)
        if model.has_foot(side):        # a side without heel and toe has no foot
            _check_foot(model, point, side, sign, right, up_unit, forward, midline)
        _check_hip_side(model, side, hips[side], mid_asis, lateral)
        _check_joint_lines(model, point, side, hips[side])
        _check_leg_clusters(model, points, point, side, hips[side], mid_asis, lateral)
    _check_pelvis_cluster(model, points, mid_knees, up, up_unit)


def _check_asis_sides(model, asis_line, right):
    """RASIS must lie to the right of LASIS (right = anterior x up, from the markers)."""
    if asis_line @ right <= 0:
        raise ValueError(
            f"RASIS ({model.markers['RASIS']!r}) lies to the subject's left of LASIS "
            f"({model.markers['LASIS']!r}) in the static posture (judged with anterior = "
            "from the posterior markers to the ASISs and up = from the knees to the pelvis): "
            "left and right are swapped in the mapping or in the labels")


def _check_leg_markers_sides(model, point, side, mid_asis, lateral):
    """Each knee and ankle on its side of the pelvis, its lateral marker lateral."""
    p = SIDE_PREFIX[side]
    for joint, lat, med in (("knee", "KNEE_LAT", "KNEE_MED"),
                            ("ankle", "ANKLE_LAT", "ANKLE_MED")):
        lateral_point, medial_point = point(p + lat), point(p + med)
        centre = (lateral_point + medial_point) / 2
        if (centre - mid_asis) @ lateral <= 0:
            raise ValueError(
                f"the {side} {joint} markers ({model.markers[p + lat]!r}, "
                f"{model.markers[p + med]!r}) lie on the subject's "
                f"{_opposite(side)} side of the pelvis: left and "
                f"right legs are swapped in the mapping or in the labels")
        if (lateral_point - medial_point) @ lateral <= 0:
            raise ValueError(
                f"{side} {joint}: {p + lat} ({model.markers[p + lat]!r}) lies medial to "
                f"{p + med} ({model.markers[p + med]!r}) in the static posture: the "
                f"lateral and medial markers are swapped")


def _check_hip_side(model, side, hip, mid_asis, lateral):
    """The hip centre on its side of the pelvis (RHJC and LHJC swapped otherwise)."""
    if (hip - mid_asis) @ lateral <= 0:
        p = SIDE_PREFIX[side]
        source = (f"{p}HJC ({model.markers[p + 'HJC']!r})" if model.hip_centre == "marker"
                  else f"the {model.hip_centre} hip centre")
        raise ValueError(
            f"the {side} hip centre, {source}, lies on the subject's "
            f"{_opposite(side)} side of the pelvis in the static "
            f"posture: RHJC and LHJC are swapped in the mapping or in the labels")


def _check_leg_clusters(model, points, point, side, hip, mid_asis, lateral):
    """Thigh, shank and foot clusters: on their segment (SEGMENT_SPAN) and their side."""
    p = SIDE_PREFIX[side]
    knee, ankle = _joint_centre(point, side, "KNEE"), _joint_centre(point, side, "ANKLE")
    spans = {"THIGH": ("thigh", knee, hip), "SHANK": ("shank", ankle, knee)}
    for cluster, (segment, distal, proximal) in spans.items():
        if p + cluster not in model.markers:
            continue
        labels = model.markers[p + cluster]
        if not all(label in points for label in labels):
            continue                       # no static trial: the cluster is not used
        centroid = np.mean([points[label] for label in labels], axis=0)
        axis = proximal - distal
        along = (centroid - distal) @ axis / (axis @ axis)   # 0 distal end, 1 proximal
        if not SEGMENT_SPAN[0] <= along <= SEGMENT_SPAN[1]:
            where = "above the hip" if segment == "thigh" and along > 1 else (
                "below the knee" if segment == "thigh" else
                "above the knee" if along > 1 else "below the ankle")
            raise ValueError(
                f"the {side} {segment} cluster {p + cluster} ({', '.join(labels)}) lies "
                f"{where} ({along:.0%} of the way from the {segment}'s distal to its "
                f"proximal end) in the static posture: it is not on the {side} "
                f"{segment}; check the cluster labels")
        if (centroid - mid_asis) @ lateral <= 0:
            raise ValueError(
                f"the {side} {segment} cluster {p + cluster} ({', '.join(labels)}) lies "
                f"on the subject's {_opposite(side)} side: it is "
                f"on the other leg; check the cluster labels")
    if p + "FOOT" in model.markers and all(label in points
                                           for label in model.markers[p + "FOOT"]):
        labels = model.markers[p + "FOOT"]
        centroid = np.mean([points[label] for label in labels], axis=0)
        along = (centroid - ankle) @ (knee - ankle) / ((knee - ankle) @ (knee - ankle))
        if along > FOOT_CLUSTER_SPAN or (centroid - mid_asis) @ lateral <= 0:
            raise ValueError(
                f"the {side} foot cluster {p}FOOT ({', '.join(labels)}) is not on the "
                f"{side} foot in the static posture ({along:.0%} of the way from the ankle "
                f"to the knee); check the cluster labels")


def _check_pelvis_cluster(model, points, mid_knees, up, up_unit):
    """The PELVIS cluster at least half-way up from the knees to the ASISs."""
    if "PELVIS" in model.markers and all(label in points for label in model.markers["PELVIS"]):
        labels = model.markers["PELVIS"]
        centroid = np.mean([points[label] for label in labels], axis=0)
        height = (centroid - mid_knees) @ up_unit
        if height < 0.5 * (up @ up_unit):
            raise ValueError(f"the pelvis cluster PELVIS ({', '.join(labels)}) lies "
                             f"{height:.0f} mm above the knees, too low for the pelvis "
                             "in the static posture; check the cluster labels")


def _check_pelvis_depth(model, point, anterior, posterior):
    """The feet point forward from heel to toe: the ASISs must then be in front of the
    posterior markers, or ASIS and PSIS (or the sacral marker) are swapped."""
    # only the feet that have both markers (a side may have no foot markers: no ankle angles)
    ends = [(point(SIDE_PREFIX[side] + "HEEL"), point(SIDE_PREFIX[side] + "TOE"))
            for side in model.sides]
    toes = [toe - heel for heel, toe in ends if heel is not None and toe is not None]
    if not toes:
        return
    feet = np.mean(toes, axis=0)
    if feet @ anterior < 0 and all(t @ anterior < 0 for t in toes):
        names = ", ".join(f"{role} ({model.markers[role]!r})" for role in posterior)
        raise ValueError(
            f"the posterior pelvis markers {names} lie in front of RASIS "
            f"({model.markers['RASIS']!r}) and LASIS ({model.markers['LASIS']!r}) in the "
            f"static posture, judged by the feet (heel to toe points the other way, on "
            f"both feet): the ASIS and PSIS (or sacral) markers are swapped in the mapping "
            f"or in the labels")


def _check_joint_lines(model, point, side, hip):
    """Knee and ankle markers: a width a human joint can have, and a line roughly
    perpendicular to the segment (a marker of another role mapped there is not)."""
    p = SIDE_PREFIX[side]
    knee, ankle = _joint_centre(point, side, "KNEE"), _joint_centre(point, side, "ANKLE")
    for joint, (lat, med), axis, (low, high), segment in (
            ("knee", ("KNEE_LAT", "KNEE_MED"), hip - knee, KNEE_WIDTH_MM, "thigh"),
            ("ankle", ("ANKLE_LAT", "ANKLE_MED"), knee - ankle, ANKLE_WIDTH_MM, "shank")):
        line = point(p + lat) - point(p + med)
        width = float(np.linalg.norm(line))
        labels = f"{p + lat} ({model.markers[p + lat]!r}) and {p + med} " \
                 f"({model.markers[p + med]!r})"
        if not low <= width <= high:
            raise ValueError(
                f"{side} {joint}: {labels} are {width:.0f} mm apart in the static posture, "
                f"while a {joint}'s lateral and medial markers are {low:.0f} to {high:.0f} "
                f"mm apart: one of them is not on the {joint} (a marker of another role "
                f"mapped there, or the units are wrong)")
        tilt = 90.0 - np.degrees(np.arccos(min(1.0, abs(line @ axis) / (
            width * np.linalg.norm(axis)))))
        if tilt > JOINT_LINE_TILT_DEG:
            raise ValueError(
                f"{side} {joint}: the line from {labels} is {tilt:.0f} degrees from "
                f"perpendicular to the {segment}'s long axis in the static posture (at most "
                f"{JOINT_LINE_TILT_DEG:.0f} expected: the markers sit on either side of the "
                f"joint, at one level): one of them is not on the {joint} (a marker of "
                f"another role, e.g. of the {segment} cluster, mapped there?)")


def _check_foot(model, point, side, sign, right, up, forward, midline):
    """Heel, toe and MT5 of one foot: on its side, the toe ahead of the heel, MT5 lateral."""
    p = SIDE_PREFIX[side]
    other = "left" if side == "right" else "right"
    roles = [p + "HEEL", p + "TOE"] + ([p + "MT5"] if p + "MT5" in model.markers else [])
    for role in roles:
        if sign * ((point(role) - midline) @ right) <= 0:
            raise ValueError(
                f"the {side} foot marker {role} ({model.markers[role]!r}) lies on the "
                f"subject's {other} side in the static posture: it is on the {other} foot; "
                f"left and right are swapped in the mapping or in the labels")
    heel, toe = point(p + "HEEL"), point(p + "TOE")
    ahead = (toe - heel) @ forward
    if ahead <= 0:
        raise ValueError(
            f"{side} foot: {p}TOE ({model.markers[p + 'TOE']!r}) lies {-ahead:.0f} mm behind "
            f"{p}HEEL ({model.markers[p + 'HEEL']!r}) in the static posture (forward = the "
            f"pelvis's anterior direction): the heel and toe markers are swapped")
    if p + "MT5" in model.markers:
        mt5 = point(p + "MT5")
        if sign * np.cross(toe - heel, mt5 - heel) @ up >= 0:
            raise ValueError(
                f"{side} foot: {p}MT5 ({model.markers[p + 'MT5']!r}) lies medial to the line "
                f"from {p}HEEL to {p}TOE ({model.markers[p + 'HEEL']!r} to "
                f"{model.markers[p + 'TOE']!r}) in the static posture; the fifth metatarsal "
                f"head is lateral: MT5 and TOE are swapped, or MT5 is on the other foot")


#: In a dynamic frame, the two thighs are flagged as swapped when the right thigh's
#: markers lie this fraction of the ASIS distance or more to the subject's left of the
#: left thigh's (judged along the pelvis's RASIS - LASIS axis). Crossing the legs in
#: walking (a narrow base, a scissor gait) brings the thighs together; their markers
#: stay near the hips, which are about 0.7 ASIS distances apart, so that a crossing of
#: 0.25 is far beyond it, while swapped labels put them about -0.7 apart.
LEGS_CROSSED = 0.25


def visible_centroid(points):
    """Per-frame mean of the visible markers (frames, 3); NaN where none is visible."""
    with np.errstate(invalid="ignore", over="ignore"):
        everywhere = points.shape[1] > 0 and np.isfinite(points.sum())   # all seen
    if everywhere:                                        # no masked copy to make
        return _marker_sum(points) / points.shape[1]
    finite = np.isfinite(points)
    seen = finite[..., 0] & finite[..., 1] & finite[..., 2]              # all three
    count = np.count_nonzero(seen, axis=1)[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        return _marker_sum(np.where(seen[..., None], points, 0.0)) / count


def _marker_sum(points):
    """The sum over the markers (axis 1) of (frames, markers, 3) points, added marker
    after marker as numpy.sum(axis=1) adds them, by einsum: several times faster than
    a reduction over a middle axis. Each frame's (markers, 3) block must be contiguous
    for that order (a C-ordered copy is made if not): a part of a C-ordered stack of
    more markers is read as it is."""
    item = points.itemsize
    contiguous = points.strides[1:] == (3 * item, item)       # within each frame
    if not contiguous or points.strides[0] < 3 * item * points.shape[1]:
        points = np.ascontiguousarray(points)
    return np.einsum("fki->fi", points)


def _side_labels(model, side, roles):
    p = SIDE_PREFIX[side]
    labels = []
    for role in roles:
        value = model.markers.get(p + role)
        if value is not None:
            labels += list(value) if isinstance(value, tuple) else [value]
    return labels


def check_sides(model, table, scale, landmarks, trial_name):
    r"""Per-frame handedness of the body and the side of each thigh (vectorized).

    A trial whose left and right labels are all swapped, or that is mirrored (a lab axis
    reversed), fits every 3-marker cluster with an RMSE of zero; what changes is the
    handedness of the body: with ``right`` = RASIS - LASIS, ``anterior`` = from the
    posterior pelvis markers to the ASISs and ``up`` = from the legs' markers to the
    ASISs, :math:`\mathrm{right}\cdot(\mathrm{anterior}\times\mathrm{up}) > 0` in
    every posture of a real body, and < 0 in its mirror image. The legs' labels swapped
    (the pelvis's not) put the right thigh's markers to the left of the left thigh's.
    The trial's own markers are used (the reconstructed pelvis landmarks in frames
    where the pelvis markers are not seen).

    A 3-marker pelvis cluster fits its own mirror image turned round (an RMSE of zero
    again): the pelvis's anterior axis then points against the feet (heel to toe), which
    the mirror leaves pointing forward; more than 90 degrees between them is flagged.

    Returns
    -------
    mirrored, crossed : ndarray of bool, shape (frames,)
        Frames where the body is mirrored (or the pelvis faces against the feet), and
        where the thighs are swapped. Raises
        ValueError when every frame that can be judged is flagged (the whole trial);
        otherwise one warning per kind.
    """
    pelvis = _measured_or_rebuilt(model, table, scale, landmarks[("pelvis", None)],
                                  pelvis_roles(model.markers))
    posterior = pelvis_roles(model.markers)[2:]
    right = pelvis["RASIS"] - pelvis["LASIS"]
    mid_asis = (pelvis["RASIS"] + pelvis["LASIS"]) / 2
    anterior = mid_asis - (pelvis[posterior[0]] + pelvis[posterior[-1]]) / 2
    legs = {side: _leg_centroids(model, table, scale, side) for side in model.sides}
    with np.errstate(invalid="ignore", divide="ignore"):
        facing = np.einsum("fi,fi->f", anterior, _foot_direction(model, table, scale,
                                                                 landmarks, len(right)))
        facing /= vector_length(anterior)          # np.linalg.norm's values, faster
    judged = np.isfinite(facing)
    against = judged & (facing < 0)
    report_flagged_frames(
        against, judged, trial_name,
        "the pelvis faces against the feet: its anterior axis (from the posterior "
        "markers to the ASISs) points more than 90 degrees away from heel to toe. The "
        "trial is mirrored (a lab axis reversed) or its left and right labels are "
        "swapped (a pelvis cluster then fits turned round), or the ASIS and PSIS labels "
        "are swapped", "every angle is NaN")
    mirrored = _mirrored_frames(model, legs, right, mid_asis, anterior, against, trial_name)
    crossed = _crossed_frames(model, legs, right, mirrored, trial_name)
    return mirrored | against, crossed


def _measured_or_rebuilt(model, table, scale, rebuilt, roles):
    """{role: (frames, 3)} the trial's own markers, the rebuilt landmarks where a marker
    is not seen (or not in the trial)."""
    shape = rebuilt[roles[0]].shape
    out = {}
    for role in roles:
        fallback = np.broadcast_to(rebuilt[role], shape)
        label = model.markers[role]
        if label in table.columns:
            raw = table.points(label, scale)
            out[role] = np.where(np.isfinite(raw).all(axis=1, keepdims=True), raw, fallback)
        else:
            out[role] = fallback
    return out


def _leg_centroids(model, table, scale, side):
    """Per-frame centroids (frames, 3) of one leg's visible markers: of the thigh (its
    cluster and the knee markers) and of the whole leg below the hip; None without any."""
    thigh, shank = ([label for label in _side_labels(model, side, roles)
                     if label in table.columns]         # the labels the trial has
                    for roles in (("THIGH", "KNEE_LAT", "KNEE_MED"),
                                  ("SHANK", "ANKLE_LAT", "ANKLE_MED")))
    if not thigh + shank:
        return None, None
    # the leg's markers, the thigh's first, from the table's columns (no stack of them,
    # a copy of 11 markers of every frame on fresh pages each call)
    return coordinate_centroids(_table_coordinates(table, thigh + shank, scale), len(thigh))


def _table_coordinates(table, labels, scale):
    """The raw positions (mm) of the `labels` of a MarkerTable as
    :func:`coordinate_centroids` takes them: each label's x, y and z columns, read in
    place (times `scale`, as ``table.stacked``, unless it is 1)."""
    markers = [[table.values[:, table.columns[label][axis]] for axis in "xyz"]
               for label in labels]
    if scale != 1.0:
        markers = [[column * scale for column in marker] for marker in markers]
    return markers


def coordinate_centroids(markers, split=None):
    """:func:`visible_centroid` of the first `split` `markers` (None when `split` is None
    or 0) and of all of them, each marker given as its x, y and z coordinates (three
    (frames,) arrays: a table's columns, or the rows of a (frames, 3) array's transpose),
    without their (frames, markers, 3) stack (a copy on fresh pages, about twice as
    slow). The same numbers bit for bit, silent as visible_centroid: its sums start at 0
    and add the markers one after the other, the first `split` first; where a marker is
    not seen in some frame (or a sum overflows), every marker adds 0 in the frames where
    it is not seen and the frames' counts of those seen divide the sums. Each result is
    (frames, 3), C-ordered; with `split` ``len(markers)`` both are the same array."""
    sums = np.zeros((3, len(markers[0][0])))
    part, count = None, len(markers)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for k, marker in enumerate(markers):
            if k == split:
                part = _centroid(sums, split)
            for total, column in zip(sums, marker):
                total += column
        if not np.isfinite(sums).all():   # a marker not seen somewhere (or an overflow)
            sums[:] = 0.0
            count = np.zeros((sums.shape[1], 1), int)
            for k, marker in enumerate(markers):
                if k == split:
                    part = _centroid(sums, count)
                seen = np.isfinite(marker[0]) & np.isfinite(marker[1]) & np.isfinite(marker[2])
                count[:, 0] += seen
                for total, column in zip(sums, marker):
                    total += np.where(seen, column, 0.0)
        whole = _centroid(sums, count)
    return (whole if split == len(markers) else part if split else None), whole


def _centroid(sums, count):
    """(frames, 3) sums / count from (3, frames) sums, C-ordered (as visible_centroid's)."""
    return np.divide(sums.T, count, out=np.empty(sums.T.shape))


def _foot_direction(model, table, scale, landmarks, frames):
    """Per frame, the mean heel-to-toe unit vector of the feet (frames, 3): the trial's
    markers, the rebuilt ones where not seen; NaN where no foot is known."""
    feet = []
    for side in model.sides:
        if ("foot", side) not in landmarks:  # a side without foot markers (no ankle angles)
            continue
        p = SIDE_PREFIX[side]
        ends = landmarks[("foot", side)]
        if p + "FOOT" in model.markers and not model.landmarks.empty:   # rebuilt
            ends = _measured_or_rebuilt(model, table, scale, ends, [p + "TOE", p + "HEEL"])
        # (else the foot's landmarks are the trial's own markers, NaN where not seen: the
        # values that _measured_or_rebuilt would copy and select back, unchanged)
        heel_to_toe = ends[p + "TOE"] - ends[p + "HEEL"]
        length = vector_length(heel_to_toe)[:, None]   # np.linalg.norm's values
        with np.errstate(invalid="ignore", divide="ignore"):
            feet.append(heel_to_toe / length)
    if not feet:                   # no foot markers on either side: no frame is judged
        return np.full((frames, 3), np.nan)
    # Without a foot that is never seen (which only added zeros to the sums) the mean
    # takes visible_centroid's fast path in a trial without gaps: the same directions
    # (up to the sign of a zero component, which the test of their sign ignores).
    return visible_centroid(np.stack(feet, axis=1))


def _mirrored_frames(model, legs, right, mid_asis, anterior, against, trial_name):
    """Frames where the body's handedness is reversed, bar those flagged `against` the
    feet already (reported)."""
    lower = [below for _, below in legs.values() if below is not None]
    if not lower:
        return np.zeros(len(right), bool)
    up = mid_asis - visible_centroid(np.stack(lower, axis=1))
    volume = np.einsum("fi,fi->f", right, np.cross(anterior, up))
    judged = np.isfinite(volume)
    mirrored = judged & (volume < 0) & ~against
    report_flagged_frames(
        mirrored, judged, trial_name,
        f"the body is mirrored: RASIS ({model.markers['RASIS']!r}) lies to the "
        f"subject's left of LASIS ({model.markers['LASIS']!r}), judged with "
        f"anterior = from the posterior pelvis markers to the ASISs and up = from "
        f"the legs' markers to the ASISs (the handedness of the body, which no "
        f"posture changes). Left and right are swapped in the labels of this "
        f"trial, or the trial is mirrored (a lab axis reversed)",
        "every angle is NaN")
    return mirrored


def _crossed_frames(model, legs, right, mirrored, trial_name):
    """Frames where the right thigh lies LEGS_CROSSED ASIS distances or more to the left
    of the left thigh, bar the `mirrored` ones (reported)."""
    if len(model.sides) != 2 or any(thigh is None for thigh, _ in legs.values()):
        return np.zeros(len(right), bool)
    width = vector_length(right)                   # np.linalg.norm's values, faster
    with np.errstate(invalid="ignore", divide="ignore"):
        apart = np.einsum("fi,fi->f", legs["right"][0] - legs["left"][0], right) / width
    judged = np.isfinite(apart)
    crossed = judged & (apart < -LEGS_CROSSED * width) & ~mirrored
    report_flagged_frames(
        crossed, judged, trial_name,
        f"the right thigh's markers lie to the subject's left of the left thigh's "
        f"(by more than {LEGS_CROSSED:g} times the ASIS distance, along RASIS - "
        f"LASIS): the legs' left and right labels are swapped in this trial",
        "the hip, knee and ankle angles of both sides are NaN")
    return crossed


def report_flagged_frames(flagged, judged, trial_name, what, consequence):
    count, total = int(flagged.sum()), int(judged.sum())
    if not count:
        return
    if count == total:
        raise ValueError(f"in every frame of {trial_name} ({total}), {what}")
    warn_frames(count, total, f"of {trial_name} (of those that could be judged): {what}. In "
                f"those frames {consequence}")


_DEPENDS = {"PELVIS": "pelvis and hip", "THIGH": "hip and knee", "SHANK": "knee and ankle",
            "FOOT": "ankle"}


def deforming_frames(model, rmse):
    """Cluster -> (frames in which it deforms, the threshold in mm): its svdt RMSE above
    DEFORM_MM or DEFORM_FACTOR times its static RMSE, whichever is larger (the frames
    :func:`warn_dynamic` warns about)."""
    result = {}
    for cluster in rmse.columns:
        threshold = max(DEFORM_MM, DEFORM_FACTOR * model.static_rmse[cluster])
        with np.errstate(invalid="ignore"):
            result[cluster] = (rmse[cluster].to_numpy() > threshold, threshold)
    return result


def warn_dynamic(model, rmse, undetermined, trial_name, missing=None):
    """One warning per cluster with undetermined frames, per segment without a cluster
    whose measured landmarks are missing in some frames (`missing`: (segment, side) ->
    {role: frame mask}), and per deforming cluster."""
    for key, masks in (missing or {}).items():
        if not masks:
            continue
        gap = np.any(list(masks.values()), axis=0)
        if gap.any():
            which = ", ".join(f"{role} ({model.markers[role]!r}, {int(mask.sum())} frames)"
                              for role, mask in masks.items() if mask.any())
            warn_frames(int(gap.sum()), gap.size,
                        f"of {trial_name} lack a landmark of the {segment_name(key)}, which has "
                        f"no cluster to rebuild it: {which}. The {segment_name(key)} frame, "
                        f"and the angles that use it, are NaN there")
    for cluster, mask in undetermined.items():
        if mask.any():
            info = model.clusters[cluster]
            side = segment_name(info["segment"]).split()[0] if cluster != "PELVIS" else ""
            kind = "PELVIS" if cluster == "PELVIS" else cluster[1:]
            warn_frames(int(mask.sum()), mask.size,
                        f"of {trial_name} have fewer than 3 visible (non-collinear) markers of "
                        f"{cluster} ({', '.join(info['labels'])}): the {side + ' ' if side else ''}"
                        f"{_DEPENDS[kind]} angles are NaN there")
    for cluster, (high, threshold) in deforming_frames(model, rmse).items():
        values = rmse[cluster].to_numpy()
        if high.any():
            info = model.clusters[cluster]
            what = ("markers, used as its cluster," if info.get("measured") else "cluster")
            warn(
                f"the {segment_name(info['segment'])} {what} {cluster} "
                f"({', '.join(info['labels'])}) deforms in {int(high.sum())} of {high.size} "
                f"frames of {trial_name}: svdt RMSE up to {np.nanmax(values):.1f} mm (static "
                f"{model.static_rmse[cluster]:.2f} mm; warning above {threshold:.1f} mm). A "
                f"marker may have come loose, been swapped or mislabelled there; the angles "
                f"that use this segment are unreliable in those frames", RuntimeWarning)
