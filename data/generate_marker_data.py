"""Generate the synthetic marker-based motion capture trials in data/markers/.

Both lower limbs (pelvis, thighs, shanks, feet) are posed by known joint angles; skin
markers are attached to each segment; a static calibration trial and a dynamic trial (one
walking stride) are written as TRC files (mm), together with the ground truth (segment
poses and joint angles) as CSV. See data/README.md, section "Marker-based motion capture
trials".

Run from the repository root::

    python data/generate_marker_data.py            # writes data/markers/
    python data/generate_marker_data.py OUTDIR     # writes elsewhere (used by the tests)

The ground truth is built here with scipy.spatial.transform.Rotation and plain numpy, not
with bmc_functions, so that the package can be tested against it independently.

Building other trials (e.g. several strides) from the same pieces::

    gen = load the module (tests/helpers.py: load_data_script("generate_marker_data"))
    s = time / stride_time                         # fraction of the right stride, any range
    legs = {"right": gen.leg_angles(s), "left": gen.leg_angles(s + 0.5)}
    poses = gen.segment_poses(gen.pelvis_angles(s), pelvis_origin, legs)
    points = gen.marker_positions(poses, gen.soft_tissue_artefact(rng, legs, reference))
    truth = gen.truth_table(time, poses)           # angles as bmc_functions reports them

Each function takes per-frame arrays (frames on the first axis), so the joint-angle
trajectories can be anything: other keypoints, stride-to-stride variability, a run.
"""

import pathlib
import sys

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation

SEED = 20021983          # Wu et al. 2002, Grood & Suntay 1983
RATE = 100.0             # Hz, both trials
STATIC_FRAMES = 50       # 0.5 s of quiet standing
STRIDE_TIME = 1.10       # s, one walking stride, right heel strike to right heel strike
WALK_SPEED = 1300.0      # mm/s
NOISE_SD = 0.5           # mm, white measurement noise on every coordinate
DECIMALS = 4             # mm, rounding of the coordinates written to the TRC files
SIDES = ("right", "left")

# --- The subject: landmarks and skin markers in each segment's anatomical frame (mm) -----
# Frames follow Wu et al. (2002): x anterior, y superior, z to the right. Leg markers are
# given for the right side; the left side is their mirror image (z negated, R -> L).
PELVIS_WIDTH = 240.0     # distance between the ASISs
PELVIS_DEPTH = 160.0     # distance from mid-ASIS to mid-PSIS
PELVIS_LANDMARKS = {     # pelvis frame: origin mid-ASIS
    "RASI": (0.0, 0.0, PELVIS_WIDTH / 2),
    "LASI": (0.0, 0.0, -PELVIS_WIDTH / 2),
    "RPSI": (-PELVIS_DEPTH, 0.0, 45.0),
    "LPSI": (-PELVIS_DEPTH, 0.0, -45.0),
}
# The synthetic hip joint centre sits exactly where the regression of Harrington et al.
# (2007) puts it, so the regression's own error (1-2 cm in real subjects) is absent here.
HIP_CENTRE = (-0.24 * PELVIS_DEPTH - 9.9, -0.30 * PELVIS_WIDTH - 10.9,
              0.33 * PELVIS_WIDTH + 7.3)   # right hip; the left one has z negated
PELVIS_CLUSTER = {       # a triad on a sacral plate
    "PEL1": (-PELVIS_DEPTH - 25.0, 45.0, 0.0),
    "PEL2": (-PELVIS_DEPTH - 35.0, -15.0, 40.0),
    "PEL3": (-PELVIS_DEPTH - 35.0, -15.0, -40.0),
}
THIGH_LENGTH = 420.0     # hip centre to knee centre (mid-epicondyles)
THIGH_LANDMARKS = {      # thigh frame: origin at the hip centre
    "RLFC": (0.0, -THIGH_LENGTH + 5.0, 47.0),    # lateral femoral epicondyle
    "RMFC": (0.0, -THIGH_LENGTH - 5.0, -47.0),   # medial femoral epicondyle
}
THIGH_CLUSTER = {        # four skin markers on the antero-lateral thigh
    "RTH1": (35.0, -140.0, 80.0),
    "RTH2": (55.0, -250.0, 60.0),
    "RTH3": (-5.0, -230.0, 78.0),
    "RTH4": (25.0, -330.0, 62.0),
}
SHANK_LENGTH = 400.0     # mid-malleoli to knee centre
SHANK_LANDMARKS = {      # shank frame: origin mid-malleoli
    "RLMAL": (0.0, -8.0, 35.0),
    "RMMAL": (0.0, 8.0, -35.0),
}
SHANK_CLUSTER = {        # three skin markers on the antero-lateral shank
    "RTB1": (40.0, 290.0, 40.0),
    "RTB2": (45.0, 170.0, 35.0),
    "RTB3": (10.0, 230.0, 55.0),
}
FOOT_MARKERS = {         # foot frame: origin mid-malleoli (the ankle is a spherical joint
    "RHEEL": (-55.0, -45.0, 0.0),   # there); heel and toe on the foot's x axis, MT5 in
    "RTOE": (150.0, -45.0, 0.0),    # the plane normal to its y axis, so that the foot
    "RMT5": (115.0, -45.0, 35.0),   # frame of bmc_functions.foot_frame is the true one
}
# Per segment of the right side: (technical cluster, anatomical landmarks).
LEG = {"thigh": (THIGH_CLUSTER, THIGH_LANDMARKS), "shank": (SHANK_CLUSTER, SHANK_LANDMARKS),
       "foot": ({}, FOOT_MARKERS)}

# --- Soft-tissue artefact: displacement of each skin marker relative to its bone ----------
# Linear in the joint angles that move the underlying muscle and skin (Leardini et al.
# 2005; Camomilla et al. 2017): mm of displacement per radian of hip and knee flexion (of
# the same side; the right side for the pelvis), drawn once per marker, zero in the static
# pose. Thigh largest, shank and pelvis smaller; the foot markers sit on bone (none).
STA_SD = {"pelvis": (2.0, 0.0), "thigh": (7.0, 9.0), "shank": (1.5, 4.0)}

# --- Occlusion gaps in the dynamic trial: (marker, first frame, last frame) inclusive ---
GAPS = (("RTH3", 30, 41),   # thigh keeps 3 markers: still tracked
        ("RTB2", 70, 77),   # shank down to 2 markers: knee and ankle angles undetermined
        ("PEL1", 90, 95))   # pelvis down to 2 markers: pelvis and hip angles undetermined

#: Mirror across the sagittal plane (z -> -z): right-side geometry -> left side.
MIRROR = np.diag([1.0, 1.0, -1.0])


def mirrored(points):
    """Left-side copy of right-side points: names R... -> L..., z negated."""
    return {"L" + name[1:]: (x, y, -z) for name, (x, y, z) in points.items()}


def leg_markers(side):
    """{segment: (cluster, landmarks)} of one side's leg, in the segment frames."""
    if side == "right":
        return LEG
    return {segment: (mirrored(cluster), mirrored(landmarks))
            for segment, (cluster, landmarks) in LEG.items()}


def _periodic(keypoints, s):
    """Periodic cubic spline through (fraction of the stride, value) keypoints."""
    x, y = np.array(keypoints, dtype=float).T
    x, y = np.append(x, 1.0), np.append(y, y[0])
    return CubicSpline(x, y, bc_type="periodic")(np.asarray(s) % 1.0)


def leg_angles(s):
    """Clinical joint angles (degrees) of one leg at fractions `s` of its stride.

    A dict of arrays shaped like `s`: hip and knee flexion, adduction, rotation; ankle
    dorsiflexion, inversion, rotation (flexion, adduction, dorsiflexion, inversion and
    internal rotation positive, the same for either side). s = 0 is heel strike.
    """
    return {
        "hip_flexion": _periodic([(0.0, 30.0), (0.5, -10.0), (0.62, 0.0), (0.85, 33.0)], s),
        "hip_adduction": _periodic([(0.0, 2.0), (0.2, 7.0), (0.55, -2.0), (0.75, -5.0)], s),
        "hip_rotation": _periodic([(0.0, 3.0), (0.3, 6.0), (0.7, -4.0)], s),
        "knee_flexion": _periodic([(0.0, 5.0), (0.15, 18.0), (0.40, 4.0), (0.60, 40.0),
                                   (0.73, 62.0), (0.87, 30.0)], s),
        "knee_adduction": _periodic([(0.0, 1.0), (0.2, 3.0), (0.5, 0.5), (0.75, -2.0)], s),
        "knee_rotation": _periodic([(0.0, -2.0), (0.15, 5.0), (0.5, 0.0), (0.73, 10.0)], s),
        "ankle_dorsiflexion": _periodic([(0.0, 0.0), (0.08, -6.0), (0.45, 10.0),
                                         (0.62, -18.0), (0.75, -4.0), (0.9, 2.0)], s),
        "ankle_inversion": _periodic([(0.0, 4.0), (0.15, -3.0), (0.5, 2.0), (0.7, 6.0)], s),
        "ankle_rotation": _periodic([(0.0, -3.0), (0.3, 2.0), (0.65, -6.0)], s),
    }


def pelvis_angles(s):
    """Pelvis angles driving the model (degrees) at fractions `s` of the right stride.

    Intrinsic ZXY Cardan angles of the pelvis in the lab: tilt about z (negative =
    anterior), obliquity about x, rotation about y. (bmc_functions reports the pelvis with
    Baker's sequence instead; :func:`truth_table` gives those.)
    """
    two_pi_s = 2 * np.pi * np.asarray(s)
    return {"tilt": -8.0 + 2.0 * np.sin(2 * two_pi_s),
            "obliquity": 4.0 * np.sin(two_pi_s),
            "rotation": 5.0 * np.cos(two_pi_s)}


def static_angles(frames):
    """Pelvis drive angles and both legs' angles (degrees) of the standing calibration
    pose, constant over `frames`: (pelvis dict, {side: leg dict})."""
    pelvis = {"tilt": -10.0, "obliquity": 1.0, "rotation": 2.0}
    right = {"hip_flexion": 3.0, "hip_adduction": 1.0, "hip_rotation": 2.0,
             "knee_flexion": 4.0, "knee_adduction": 1.5, "knee_rotation": -3.0,
             "ankle_dorsiflexion": 2.0, "ankle_inversion": 1.0, "ankle_rotation": -4.0}
    left = {"hip_flexion": 2.0, "hip_adduction": -1.0, "hip_rotation": 4.0,
            "knee_flexion": 5.0, "knee_adduction": 2.0, "knee_rotation": -5.0,
            "ankle_dorsiflexion": 3.0, "ankle_inversion": -1.0, "ankle_rotation": -6.0}
    full = lambda values: {key: np.full(frames, value) for key, value in values.items()}
    return full(pelvis), {"right": full(right), "left": full(left)}


def _zxy(a, b, c):
    """Intrinsic ZXY rotation matrices (scipy's upper case is intrinsic): Rz Rx Ry."""
    return Rotation.from_euler("ZXY", np.column_stack([a, b, c]), degrees=True).as_matrix()


def segment_poses(pelvis, pelvis_origin, legs):
    """Segment orientations (F, 3, 3) and origins (F, 3) in the lab from joint angles.

    Parameters
    ----------
    pelvis : dict
        'tilt', 'obliquity', 'rotation' (F,) arrays, as :func:`pelvis_angles`.
    pelvis_origin : ndarray, shape (F, 3)
        Mid-ASIS in the lab (mm).
    legs : dict
        {'right': dict, 'left': dict} of clinical angles as :func:`leg_angles`; a side
        may be left out.

    Returns
    -------
    dict
        'pelvis' -> (R, origin); (segment, side) -> (R, origin) for 'thigh', 'shank',
        'foot' (origins: hip centre, mid-malleoli, mid-malleoli).

    Notes
    -----
    Each joint rotation (distal segment in the proximal frame) is intrinsic z-x-y about
    the ISB axes of the right side: hip flexion positive about z, knee flexion negative
    about z (the shank swings backwards), ankle dorsiflexion positive about z; adduction
    or inversion positive about x and internal rotation positive about y. A left joint
    is the mirror image of the right joint with the same clinical angles,
    ``MIRROR @ R @ MIRROR``.
    """
    R_pelvis = _zxy(pelvis["tilt"], pelvis["obliquity"], pelvis["rotation"])
    poses = {"pelvis": (R_pelvis, pelvis_origin)}
    for side, a in legs.items():
        R_hip = _zxy(a["hip_flexion"], a["hip_adduction"], a["hip_rotation"])
        R_knee = _zxy(-a["knee_flexion"], a["knee_adduction"], a["knee_rotation"])
        R_ankle = _zxy(a["ankle_dorsiflexion"], a["ankle_inversion"], a["ankle_rotation"])
        hip_local = np.array(HIP_CENTRE)
        if side == "left":
            R_hip, R_knee, R_ankle = (MIRROR @ R @ MIRROR for R in (R_hip, R_knee, R_ankle))
            hip_local = MIRROR @ hip_local
        R_thigh = R_pelvis @ R_hip
        R_shank = R_thigh @ R_knee
        R_foot = R_shank @ R_ankle
        hip = pelvis_origin + R_pelvis @ hip_local
        knee = hip + R_thigh @ np.array([0.0, -THIGH_LENGTH, 0.0])
        ankle = knee - R_shank @ np.array([0.0, SHANK_LENGTH, 0.0])
        poses[("thigh", side)] = (R_thigh, hip)
        poses[("shank", side)] = (R_shank, ankle)
        poses[("foot", side)] = (R_foot, ankle)
    return poses


def _place(points, pose, artefact=None):
    """Lab coordinates (F, 3) of each named point given in the segment's frame."""
    R, origin = pose
    placed = {}
    for name, local in points.items():
        local = np.broadcast_to(np.asarray(local, dtype=float), origin.shape)
        if artefact is not None and name in artefact:
            local = local + artefact[name]
        placed[name] = np.einsum("fij,fj->fi", R, local) + origin
    return placed


def marker_names(sides=SIDES):
    """(cluster marker names, landmark names, foot marker names) in file order."""
    clusters, landmarks, feet = list(PELVIS_CLUSTER), list(PELVIS_LANDMARKS), []
    for side in sides:
        leg = leg_markers(side)
        clusters += list(leg["thigh"][0]) + list(leg["shank"][0])
        landmarks += list(leg["thigh"][1]) + list(leg["shank"][1])
        feet += list(leg["foot"][1])
    return clusters, landmarks, feet


def marker_roles(sides=SIDES):
    """Role -> label of these trials' markers, the ``markers`` argument of
    ``bmc_functions.calibrate_lower_limb`` (pelvis landmarks and cluster, then each leg of
    `sides`); a new dict at each call, for callers that change it."""
    roles = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
             "PELVIS": list(PELVIS_CLUSTER)}
    for side in sides:
        leg, p = leg_markers(side), side[0].upper()
        knee, ankle, foot = list(leg["thigh"][1]), list(leg["shank"][1]), leg["foot"][1]
        roles.update({p + "THIGH": list(leg["thigh"][0]), p + "SHANK": list(leg["shank"][0]),
                      p + "KNEE_LAT": knee[0], p + "KNEE_MED": knee[1],
                      p + "ANKLE_LAT": ankle[0], p + "ANKLE_MED": ankle[1],
                      **{p + name[1:]: name for name in foot}})     # HEEL, TOE, MT5
    return roles


def marker_positions(poses, artefact=None):
    """Lab positions (F, 3) of every marker of the posed segments: a dict by name."""
    points = {}
    points.update(_place(PELVIS_CLUSTER, poses["pelvis"], artefact))
    points.update(_place(PELVIS_LANDMARKS, poses["pelvis"]))
    for side in SIDES:
        if ("thigh", side) not in poses:
            continue
        for segment, (cluster, landmarks) in leg_markers(side).items():
            points.update(_place(cluster, poses[(segment, side)], artefact))
            points.update(_place(landmarks, poses[(segment, side)]))
    return points


def soft_tissue_artefact(rng, legs, reference, sta_scale=1.0):
    """Soft-tissue displacement (in the bone frame, mm) of every cluster marker, (F, 3).

    Linear in the hip and knee flexion of the marker's side (the right side for the
    pelvis), measured from the `reference` (static) angles; coefficients drawn from
    `rng` in a fixed order (pelvis, then each side's thigh and shank).
    """
    artefact = {}
    groups = [("pelvis", PELVIS_CLUSTER, "right")]
    for side in legs:
        leg = leg_markers(side)
        groups += [("thigh", leg["thigh"][0], side), ("shank", leg["shank"][0], side)]
    for segment, cluster, side in groups:
        hip = np.deg2rad(legs[side]["hip_flexion"] - reference[side]["hip_flexion"][0])
        knee = np.deg2rad(legs[side]["knee_flexion"] - reference[side]["knee_flexion"][0])
        sd_hip, sd_knee = STA_SD[segment]
        for name in cluster:
            per_hip = rng.normal(0.0, sd_hip, 3)
            per_knee = rng.normal(0.0, sd_knee, 3)
            artefact[name] = sta_scale * (hip[:, None] * per_hip + knee[:, None] * per_knee)
    return artefact


def _to_frame(points, names, time):
    """DataFrame in the layout of bmc_functions.files.marker_table: (marker, coord) columns."""
    columns = pd.MultiIndex.from_product([names, ["x", "y", "z"]], names=["marker", "coord"])
    data = np.concatenate([points[name] for name in names], axis=1)
    df = pd.DataFrame(data, index=pd.Index(time, name="time"), columns=columns)
    df.attrs["rate"] = RATE
    df.attrs["units"] = "mm"
    return df


def _joint_angles(R_proximal, R_distal, side, signs):
    """Clinical angles of a joint: ZXY of the relative rotation (mirrored for the left)."""
    relative = np.swapaxes(R_proximal, 1, 2) @ R_distal
    if side == "left":
        relative = MIRROR @ relative @ MIRROR
    return Rotation.from_matrix(relative).as_euler("ZXY", degrees=True) * signs


def truth_table(time, poses):
    """Ground truth per frame, as bmc_functions reports it, computed from the poses.

    Columns: ``time``; ``pelvis_tilt``, ``pelvis_obliquity``, ``pelvis_rotation``
    (relative to the lab, Baker's sequence rotation-obliquity-tilt = intrinsic YXZ,
    anterior tilt, right side up and right side forwards positive); for each side
    ``<side>_hip_flexion|adduction|rotation``, ``<side>_knee_flexion|adduction|rotation``,
    ``<side>_ankle_dorsiflexion|inversion|rotation`` (clinical signs, the same on both
    sides); then origin ``_ox _oy _oz`` (mm) and rotation matrix ``_R00 ... _R22``
    (row-major; columns are the segment axes in the lab) of ``pelvis`` and of
    ``<side>_thigh``, ``<side>_shank``, ``<side>_foot``.
    """
    R_pelvis = poses["pelvis"][0]
    yxz = Rotation.from_matrix(R_pelvis).as_euler("YXZ", degrees=True)
    table = {"time": time, "pelvis_tilt": -yxz[:, 2], "pelvis_obliquity": -yxz[:, 1],
             "pelvis_rotation": yxz[:, 0]}
    sides = [side for side in SIDES if ("thigh", side) in poses]
    for side in sides:
        R = {segment: poses[(segment, side)][0] for segment in ("thigh", "shank", "foot")}
        for joint, (prox, dist, signs, names) in {
                "hip": (R_pelvis, R["thigh"], [1, 1, 1], ("flexion", "adduction", "rotation")),
                "knee": (R["thigh"], R["shank"], [-1, 1, 1],
                         ("flexion", "adduction", "rotation")),
                "ankle": (R["shank"], R["foot"], [1, 1, 1],
                          ("dorsiflexion", "inversion", "rotation"))}.items():
            values = _joint_angles(prox, dist, side, np.array(signs, dtype=float))
            for k, name in enumerate(names):
                table[f"{side}_{joint}_{name}"] = values[:, k]
    segments = [("pelvis", poses["pelvis"])] + [
        (f"{side}_{segment}", poses[(segment, side)])
        for side in sides for segment in ("thigh", "shank", "foot")]
    for name, (R, origin) in segments:
        for i, axis in enumerate("xyz"):
            table[f"{name}_o{axis}"] = origin[:, i]
        for i in range(3):
            for j in range(3):
                table[f"{name}_R{i}{j}"] = R[:, i, j]
    return pd.DataFrame(table)


def make_trials(seed=SEED, noise_sd=NOISE_SD, sta_scale=1.0, gaps=True):
    """Build both trials in memory.

    Parameters
    ----------
    seed : int
        Seed of the random generator (artefact coefficients, then noise).
    noise_sd : float
        Standard deviation of the white noise added to every coordinate (mm).
    sta_scale : float
        Multiplies the soft-tissue artefact (0 switches it off).
    gaps : bool
        Whether to blank the occlusion gaps listed in GAPS in the dynamic trial.

    Returns
    -------
    dict with DataFrames 'static' and 'walk' (markers, mm, unrounded) and
    'static_truth' and 'walk_truth' (ground truth per frame).
    """
    rng = np.random.default_rng(seed)
    static_time = np.arange(STATIC_FRAMES) / RATE
    n_walk = int(round(STRIDE_TIME * RATE)) + 1
    walk_time = np.arange(n_walk) / RATE
    s = walk_time / STRIDE_TIME

    pelvis_static, legs_static = static_angles(STATIC_FRAMES)
    legs_walk = {"right": leg_angles(s), "left": leg_angles(s + 0.5)}
    static_origin = np.tile([500.0, 940.0, 200.0], (STATIC_FRAMES, 1))
    # The pelvis is lowest in double support (heel strikes at s = 0 and 0.5) and highest
    # in mid-stance, as in walking (running is the other way round).
    walk_origin = np.column_stack([200.0 + WALK_SPEED * walk_time,
                                   930.0 - 12.0 * np.cos(4 * np.pi * s),
                                   200.0 + 10.0 * np.sin(2 * np.pi * s)])
    p_static = segment_poses(pelvis_static, static_origin, legs_static)
    p_walk = segment_poses(pelvis_angles(s), walk_origin, legs_walk)

    artefact = soft_tissue_artefact(rng, legs_walk, legs_static, sta_scale)
    static_pts = marker_positions(p_static)
    walk_pts = marker_positions(p_walk, artefact)
    clusters, landmarks, feet = marker_names()
    static_names = clusters + landmarks + feet
    walk_names = clusters + feet
    for name in static_names:
        static_pts[name] = static_pts[name] + rng.normal(0.0, noise_sd, (STATIC_FRAMES, 3))
    for name in walk_names:
        walk_pts[name] = walk_pts[name] + rng.normal(0.0, noise_sd, (n_walk, 3))
    if gaps:
        for name, first, last in GAPS:
            walk_pts[name][first:last + 1] = np.nan

    return {"static": _to_frame(static_pts, static_names, static_time),
            "walk": _to_frame(walk_pts, walk_names, walk_time),
            "static_truth": truth_table(static_time, p_static),
            "walk_truth": truth_table(walk_time, p_walk)}


def _format_truth(table):
    """Truth table as strings: 9 decimals for rotation matrix entries (so that the read-back
    matrices are orthonormal to 1e-9), 6 for times, angles (deg) and origins (mm). Far
    above the last digit of double precision, so the files do not change with the platform.
    Adding 0.0 after rounding turns -0.0 into 0.0.
    """
    out = pd.DataFrame(index=table.index)
    for column in table.columns:
        decimals = 9 if "_R" in column else 6
        values = table[column].to_numpy().round(decimals) + 0.0
        out[column] = [f"{value:.{decimals}f}" for value in values]
    return out


def write_trials(outdir):
    """Write static.trc, walk.trc, static_truth.csv and walk_truth.csv into `outdir`."""
    from bmc_functions.files.trc import write_trc
    outdir = pathlib.Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    trials = make_trials()
    for name in ("static", "walk"):
        write_trc(trials[name], outdir / f"{name}.trc", float_format=f"%.{DECIMALS}f")
    for name in ("static_truth", "walk_truth"):
        _format_truth(trials[name]).to_csv(outdir / f"{name}.csv", index=False,
                                           lineterminator="\n")
    return trials


if __name__ == "__main__":
    here = pathlib.Path(__file__).resolve().parent
    write_trials(sys.argv[1] if len(sys.argv) > 1 else here / "markers")
