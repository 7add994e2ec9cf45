"""Generate the synthetic marker-based motion capture trials in data/markers/.

A right lower limb (pelvis, thigh, shank) is posed by known joint angles; skin markers are
attached to each segment; a static calibration trial and a dynamic trial (one walking
stride) are written as TRC files (mm), together with the ground truth (segment poses and
knee angles) as CSV. See data/README.md, section "Marker-based motion capture trials".

Run from the repository root::

    python data/generate_marker_data.py            # writes data/markers/
    python data/generate_marker_data.py OUTDIR     # writes elsewhere (used by the tests)

The ground truth is built here with scipy.spatial.transform.Rotation and plain numpy, not
with bmc_functions, so that the package can be tested against it independently.
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

# --- The subject: landmarks and skin markers in each segment's anatomical frame (mm) -----
# Frames follow Wu et al. (2002): x anterior, y superior, z to the right.
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
              0.33 * PELVIS_WIDTH + 7.3)
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
CLUSTERS = {"pelvis": PELVIS_CLUSTER, "thigh": THIGH_CLUSTER, "shank": SHANK_CLUSTER}
LANDMARKS = {"pelvis": PELVIS_LANDMARKS, "thigh": THIGH_LANDMARKS, "shank": SHANK_LANDMARKS}

# --- Soft-tissue artefact: displacement of each skin marker relative to its bone ----------
# Linear in the joint angles that move the underlying muscle and skin (Leardini et al.
# 2005; Camomilla et al. 2017): mm of displacement per radian of hip and knee flexion,
# drawn once per marker, zero in the static pose. Thigh largest, shank and pelvis smaller.
STA_SD = {"pelvis": (2.0, 0.0), "thigh": (7.0, 9.0), "shank": (1.5, 4.0)}

# --- Occlusion gaps in the dynamic trial: (marker, first frame, last frame) inclusive ---
GAPS = (("RTH3", 30, 41),   # thigh keeps 3 markers: still tracked
        ("RTB2", 70, 77),   # shank down to 2 markers: knee angles undetermined
        ("PEL1", 90, 95))   # pelvis down to 2 markers


def _periodic(keypoints, s):
    """Periodic cubic spline through (fraction of the stride, value) keypoints."""
    x, y = np.array(keypoints, dtype=float).T
    x, y = np.append(x, 1.0), np.append(y, y[0])
    return CubicSpline(x, y, bc_type="periodic")(s % 1.0)


def stride_angles(s):
    """Joint angles (degrees) at fractions `s` of the stride: a dict of (F,) arrays.

    Pelvis angles are its ZXY Cardan angles in the lab; hip and knee angles are the
    clinical angles (flexion, adduction, internal rotation positive).
    """
    two_pi_s = 2 * np.pi * s
    return {
        "pelvis_tilt": -8.0 + 2.0 * np.sin(2 * two_pi_s),      # about z: negative = anterior
        "pelvis_obliquity": 4.0 * np.sin(two_pi_s),
        "pelvis_rotation": 5.0 * np.cos(two_pi_s),
        "hip_flexion": _periodic([(0.0, 30.0), (0.5, -10.0), (0.62, 0.0), (0.85, 33.0)], s),
        "hip_adduction": _periodic([(0.0, 2.0), (0.2, 7.0), (0.55, -2.0), (0.75, -5.0)], s),
        "hip_internal_rotation": _periodic([(0.0, 3.0), (0.3, 6.0), (0.7, -4.0)], s),
        "knee_flexion": _periodic([(0.0, 5.0), (0.15, 18.0), (0.40, 4.0), (0.60, 40.0),
                                   (0.73, 62.0), (0.87, 30.0)], s),
        "knee_adduction": _periodic([(0.0, 1.0), (0.2, 3.0), (0.5, 0.5), (0.75, -2.0)], s),
        "knee_internal_rotation": _periodic([(0.0, -2.0), (0.15, 5.0), (0.5, 0.0),
                                             (0.73, 10.0)], s),
    }


def static_angles(frames):
    """Joint angles (degrees) of the standing calibration pose, constant over `frames`."""
    values = {"pelvis_tilt": -10.0, "pelvis_obliquity": 1.0, "pelvis_rotation": 2.0,
              "hip_flexion": 3.0, "hip_adduction": 1.0, "hip_internal_rotation": 2.0,
              "knee_flexion": 4.0, "knee_adduction": 1.5, "knee_internal_rotation": -3.0}
    return {key: np.full(frames, value) for key, value in values.items()}


def _poses(angles, pelvis_origin):
    """Segment orientations (F, 3, 3) and origins (F, 3) in the lab from joint angles.

    Each joint rotation (distal segment in the proximal frame) is intrinsic z-x-y about
    ISB axes (z to the right, x anterior, y superior) of the right side: hip flexion is
    positive about z, knee flexion negative about z (the shank swings backwards);
    adduction is positive about x and internal rotation positive about y.
    """
    R_pelvis = Rotation.from_euler(
        "ZXY", np.column_stack([angles["pelvis_tilt"], angles["pelvis_obliquity"],
                                angles["pelvis_rotation"]]), degrees=True).as_matrix()
    # Upper-case 'ZXY' in scipy is intrinsic: R = Rz @ Rx @ Ry.
    R_hip = Rotation.from_euler(
        "ZXY", np.column_stack([angles["hip_flexion"], angles["hip_adduction"],
                                angles["hip_internal_rotation"]]), degrees=True).as_matrix()
    R_knee = Rotation.from_euler(
        "ZXY", np.column_stack([-angles["knee_flexion"], angles["knee_adduction"],
                                angles["knee_internal_rotation"]]), degrees=True).as_matrix()
    R_thigh = R_pelvis @ R_hip
    R_shank = R_thigh @ R_knee
    hip = pelvis_origin + R_pelvis @ np.array(HIP_CENTRE)
    knee = hip + R_thigh @ np.array([0.0, -THIGH_LENGTH, 0.0])
    ankle = knee - R_shank @ np.array([0.0, SHANK_LENGTH, 0.0])
    return {"pelvis": (R_pelvis, pelvis_origin), "thigh": (R_thigh, hip),
            "shank": (R_shank, ankle)}


def _place(points, pose, artefact=None):
    """Lab coordinates (F, 3) of each named point given in the segment's frame."""
    R, origin = pose
    placed = {}
    for name, local in points.items():
        local = np.broadcast_to(np.asarray(local, dtype=float), origin.shape)
        if artefact is not None:
            local = local + artefact[name]
        placed[name] = np.einsum("fij,fj->fi", R, local) + origin
    return placed


def _artefact(rng, angles, reference, sta_scale):
    """Soft-tissue displacement (in the bone frame, mm) of every cluster marker, (F, 3)."""
    hip = np.deg2rad(angles["hip_flexion"] - reference["hip_flexion"][0])[:, None]
    knee = np.deg2rad(angles["knee_flexion"] - reference["knee_flexion"][0])[:, None]
    artefact = {}
    for segment, cluster in CLUSTERS.items():
        sd_hip, sd_knee = STA_SD[segment]
        for name in cluster:
            per_hip = rng.normal(0.0, sd_hip, 3)
            per_knee = rng.normal(0.0, sd_knee, 3)
            artefact[name] = sta_scale * (hip * per_hip + knee * per_knee)
    return artefact


def _to_frame(points, names, time):
    """DataFrame in the layout of bmc_functions.marker_io: (marker, coord) columns."""
    columns = pd.MultiIndex.from_product([names, ["x", "y", "z"]], names=["marker", "coord"])
    data = np.concatenate([points[name] for name in names], axis=1)
    df = pd.DataFrame(data, index=pd.Index(time, name="time"), columns=columns)
    df.attrs["rate"] = RATE
    df.attrs["units"] = "mm"
    return df


def _truth_table(time, angles, poses):
    """Ground truth per frame: knee angles (deg), then origin and R of each segment."""
    table = {"time": time,
             "knee_flexion": angles["knee_flexion"],
             "knee_adduction": angles["knee_adduction"],
             "knee_internal_rotation": angles["knee_internal_rotation"]}
    for segment, (R, origin) in poses.items():
        for i, axis in enumerate("xyz"):
            table[f"{segment}_o{axis}"] = origin[:, i]
        for i in range(3):
            for j in range(3):
                table[f"{segment}_R{i}{j}"] = R[:, i, j]
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

    a_static = static_angles(STATIC_FRAMES)
    a_walk = stride_angles(s)
    static_origin = np.tile([500.0, 940.0, 200.0], (STATIC_FRAMES, 1))
    walk_origin = np.column_stack([200.0 + WALK_SPEED * walk_time,
                                   930.0 + 12.0 * np.cos(4 * np.pi * s),
                                   200.0 + 10.0 * np.sin(2 * np.pi * s)])
    p_static = _poses(a_static, static_origin)
    p_walk = _poses(a_walk, walk_origin)

    artefact = _artefact(rng, a_walk, a_static, sta_scale)
    static_pts, walk_pts = {}, {}
    for segment in CLUSTERS:
        static_pts.update(_place(CLUSTERS[segment], p_static[segment]))
        static_pts.update(_place(LANDMARKS[segment], p_static[segment]))
        walk_pts.update(_place(CLUSTERS[segment], p_walk[segment], artefact))
    cluster_names = [name for cluster in CLUSTERS.values() for name in cluster]
    landmark_names = [name for group in LANDMARKS.values() for name in group]
    static_names = cluster_names + landmark_names
    for name in static_names:
        static_pts[name] = static_pts[name] + rng.normal(0.0, noise_sd, (STATIC_FRAMES, 3))
    for name in cluster_names:
        walk_pts[name] = walk_pts[name] + rng.normal(0.0, noise_sd, (n_walk, 3))
    if gaps:
        for name, first, last in GAPS:
            walk_pts[name][first:last + 1] = np.nan

    return {"static": _to_frame(static_pts, static_names, static_time),
            "walk": _to_frame(walk_pts, cluster_names, walk_time),
            "static_truth": _truth_table(static_time, a_static, p_static),
            "walk_truth": _truth_table(walk_time, a_walk, p_walk)}


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
    from bmc_functions.marker_io import write_trc
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
