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

from ._checks import warn_frames
from .marker_roles import SIDE_PREFIX

#: Largest distance (mm) a marker may travel from its median position in a static trial
#: before a warning: quiet standing moves markers by up to about 40 mm.
STATIC_MOTION_MM = 100.0

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


def segment_name(key):
    """'pelvis' or e.g. 'right thigh' for a (segment, side) key."""
    segment, side = key
    return segment if side is None else f"{side} {segment}"


def check_still(model, df, scale, trial):
    """Warn if a marker of the static trial travels more than STATIC_MOTION_MM."""
    worst, worst_label = 0.0, None
    for label in {l for v in model.markers.values()
                  for l in (v if isinstance(v, tuple) else (v,))}:
        xyz = df.points(label, scale)
        if np.isnan(xyz).all():
            continue
        travel = float(np.nanmax(np.linalg.norm(xyz - np.nanmedian(xyz, axis=0), axis=1)))
        if travel > worst:
            worst, worst_label = travel, label
    if worst > STATIC_MOTION_MM:
        warnings.warn(f"{trial} is not static: marker {worst_label!r} moves up to "
                      f"{worst:.0f} mm from its median position (quiet standing moves markers "
                      f"by up to about 40 mm; warning above {STATIC_MOTION_MM:.0f} mm). The "
                      "landmarks are calibrated from the mean posture: check that this is the "
                      "standing calibration trial", RuntimeWarning, stacklevel=4)


def check_static_geometry(model, points, hips):
    """Left/right, lateral/medial and cluster placement from the static posture."""
    def P(role):
        return points.get(model.markers[role]) if role in model.markers else None

    rasis, lasis = P("RASIS"), P("LASIS")
    posterior = model._pelvis_roles()[2:]
    mid_asis = (rasis + lasis) / 2
    mid_psis = np.mean([P(r) for r in posterior], axis=0)
    knees = [(P(SIDE_PREFIX[s] + "KNEE_LAT") + P(SIDE_PREFIX[s] + "KNEE_MED")) / 2
             for s in model.sides]
    anterior = mid_asis - mid_psis
    up = mid_asis - np.mean(knees, axis=0)
    right = np.cross(anterior, up)
    right /= np.linalg.norm(right)
    up_unit = up / np.linalg.norm(up)
    if (rasis - lasis) @ right <= 0:
        raise ValueError(
            f"RASIS ({model.markers['RASIS']!r}) lies to the subject's left of LASIS "
            f"({model.markers['LASIS']!r}) in the static posture (judged with anterior = "
            "from the posterior markers to the ASISs and up = from the knees to the pelvis): "
            "left and right are swapped in the mapping or in the labels")
    # From here on, 'right' is the pelvis's own medio-lateral axis (now checked).
    right = (rasis - lasis) / np.linalg.norm(rasis - lasis)
    for side in model.sides:
        p, sign = SIDE_PREFIX[side], 1.0 if side == "right" else -1.0
        for joint, lat, med in (("knee", "KNEE_LAT", "KNEE_MED"),
                                ("ankle", "ANKLE_LAT", "ANKLE_MED")):
            a, b = P(p + lat), P(p + med)
            centre = (a + b) / 2
            if sign * ((centre - mid_asis) @ right) <= 0:
                raise ValueError(
                    f"the {side} {joint} markers ({model.markers[p + lat]!r}, "
                    f"{model.markers[p + med]!r}) lie on the subject's "
                    f"{'left' if side == 'right' else 'right'} side of the pelvis: left and "
                    f"right legs are swapped in the mapping or in the labels")
            if sign * ((a - b) @ right) <= 0:
                raise ValueError(
                    f"{side} {joint}: {p + lat} ({model.markers[p + lat]!r}) lies medial to "
                    f"{p + med} ({model.markers[p + med]!r}) in the static posture: the "
                    f"lateral and medial markers are swapped")
        hip = hips[side]
        knee = (P(p + "KNEE_LAT") + P(p + "KNEE_MED")) / 2
        ankle = (P(p + "ANKLE_LAT") + P(p + "ANKLE_MED")) / 2
        spans = {"THIGH": ("thigh", knee, hip), "SHANK": ("shank", ankle, knee)}
        for cluster, (segment, distal, proximal) in spans.items():
            if p + cluster not in model.markers:
                continue
            labels = model.markers[p + cluster]
            if not all(label in points for label in labels):
                continue                       # no static trial: the cluster is not used
            centroid = np.mean([points[label] for label in labels], axis=0)
            axis = proximal - distal
            t = (centroid - distal) @ axis / (axis @ axis)
            if not SEGMENT_SPAN[0] <= t <= SEGMENT_SPAN[1]:
                where = "above the hip" if segment == "thigh" and t > 1 else (
                    "below the knee" if segment == "thigh" else
                    "above the knee" if t > 1 else "below the ankle")
                raise ValueError(
                    f"the {side} {segment} cluster {p + cluster} ({', '.join(labels)}) lies "
                    f"{where} ({t:.0%} of the way from the {segment}'s distal to its "
                    f"proximal end) in the static posture: it is not on the {side} "
                    f"{segment}; check the cluster labels")
            if sign * ((centroid - mid_asis) @ right) <= 0:
                raise ValueError(
                    f"the {side} {segment} cluster {p + cluster} ({', '.join(labels)}) lies "
                    f"on the subject's {'left' if side == 'right' else 'right'} side: it is "
                    f"on the other leg; check the cluster labels")
        if p + "FOOT" in model.markers and all(label in points
                                               for label in model.markers[p + "FOOT"]):
            labels = model.markers[p + "FOOT"]
            centroid = np.mean([points[label] for label in labels], axis=0)
            t = (centroid - ankle) @ (knee - ankle) / ((knee - ankle) @ (knee - ankle))
            if t > 0.35 or sign * ((centroid - mid_asis) @ right) <= 0:
                raise ValueError(
                    f"the {side} foot cluster {p}FOOT ({', '.join(labels)}) is not on the "
                    f"{side} foot in the static posture ({t:.0%} of the way from the ankle "
                    f"to the knee); check the cluster labels")
    if "PELVIS" in model.markers and all(label in points for label in model.markers["PELVIS"]):
        labels = model.markers["PELVIS"]
        centroid = np.mean([points[label] for label in labels], axis=0)
        height = (centroid - np.mean(knees, axis=0)) @ up_unit
        if height < 0.5 * (up @ up_unit):
            raise ValueError(f"the pelvis cluster PELVIS ({', '.join(labels)}) lies "
                             f"{height:.0f} mm above the knees, too low for the pelvis "
                             "in the static posture; check the cluster labels")


_DEPENDS = {"PELVIS": "pelvis and hip", "THIGH": "hip and knee", "SHANK": "knee and ankle",
            "FOOT": "ankle"}


def warn_dynamic(model, rmse, dead, trial):
    """One warning per cluster with undetermined frames, and per deforming cluster."""
    for cluster, mask in dead.items():
        if mask.any():
            info = model.clusters[cluster]
            side = segment_name(info["segment"]).split()[0] if cluster != "PELVIS" else ""
            kind = "PELVIS" if cluster == "PELVIS" else cluster[1:]
            warn_frames(int(mask.sum()), mask.size,
                        f"of {trial} have fewer than 3 visible (non-collinear) markers of "
                        f"{cluster} ({', '.join(info['labels'])}): the {side + ' ' if side else ''}"
                        f"{_DEPENDS[kind]} angles are NaN there", stacklevel=4)
    for cluster in rmse.columns:
        values = rmse[cluster].to_numpy()
        threshold = max(DEFORM_MM, DEFORM_FACTOR * model.static_rmse[cluster])
        high = values > threshold
        if high.any():
            info = model.clusters[cluster]
            what = ("markers, used as its cluster," if info.get("measured") else "cluster")
            warnings.warn(
                f"the {segment_name(info['segment'])} {what} {cluster} "
                f"({', '.join(info['labels'])}) deforms in {int(high.sum())} of {high.size} "
                f"frames of {trial}: svdt RMSE up to {np.nanmax(values):.1f} mm (static "
                f"{model.static_rmse[cluster]:.2f} mm; warning above {threshold:.1f} mm). A "
                f"marker may have come loose, been swapped or mislabelled there; the angles "
                f"that use this segment are unreliable in those frames", RuntimeWarning,
                stacklevel=4)
