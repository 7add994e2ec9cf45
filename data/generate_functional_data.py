"""Generate the synthetic functional trials in data/functional/.

A right lower limb (pelvis, thigh, shank) with a known hip joint centre and a known knee
flexion axis performs two functional movements, each written as a TRC file (mm) with its
ground truth as CSV:

- ``hip_star_arc.trc``: the star arc of Camomilla et al. (2006): the thigh swings from the
  neutral posture in five directions (flexion, flexion-abduction, abduction,
  extension-abduction, extension) and back, then circumducts, while the pelvis sways;
- ``knee_flexion.trc``: three knee flexion-extension cycles (5 to 90 deg) with small
  secondary rotations (ab/adduction 2 deg, internal/external rotation 4 deg, at other
  frequencies) about axes through the knee centre, while the thigh moves a little;
- ``static.trc``: a standing calibration trial with the anatomical landmarks.

Measurement noise (white, 0.5 mm SD) and a soft-tissue-like artefact (each skin marker moves
relative to its bone linearly with the joint angles, coefficients drawn from the seed) are
added. See data/README.md, section "Functional trials".

Run from the repository root::

    python data/generate_functional_data.py            # writes data/functional/
    python data/generate_functional_data.py OUTDIR     # writes elsewhere (used by the tests)

``hip_trial`` and ``knee_trial`` build trials in memory with another range of motion, noise
or artefact (the validation tests and notebook 11 use them). The ground truth is built with
scipy.spatial.transform.Rotation and numpy, not with bmc_functions.
"""

import pathlib
import sys

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

SEED = 20062007          # Ehrig et al. 2006 and 2007
RATE = 100.0             # Hz
NOISE_SD = 0.5           # mm, white measurement noise on every coordinate
DECIMALS = 2             # mm, rounding of the coordinates written to the TRC files
STATIC_FRAMES = 50
HIP_AMPLITUDE = 35.0     # deg, flexion and abduction of the star arc (extension is half)
KNEE_AMPLITUDE = 90.0    # deg, peak knee flexion

# --- The subject (mm), frames of Wu et al. (2002): x anterior, y superior, z right -------
PELVIS_WIDTH = 230.0     # distance between the ASISs
PELVIS_DEPTH = 155.0     # mid-ASIS to mid-PSIS
PELVIS_MARKERS = {       # pelvis frame, origin mid-ASIS; tracked in every trial
    "RASI": (0.0, 0.0, PELVIS_WIDTH / 2),
    "LASI": (0.0, 0.0, -PELVIS_WIDTH / 2),
    "RPSI": (-PELVIS_DEPTH, 0.0, 45.0),
    "LPSI": (-PELVIS_DEPTH, 0.0, -45.0),
}
#: Where the regression of Harrington et al. (2007) puts the right hip centre, from the
#: ASIS and PSIS markers above (pelvis frame).
HARRINGTON_CENTRE = (-0.24 * PELVIS_DEPTH - 9.9, -0.30 * PELVIS_WIDTH - 10.9,
                     0.33 * PELVIS_WIDTH + 7.3)
#: The true hip centre is this far from the regression's (mm, pelvis frame; 15.7 mm in
#: all): a typical error of the regression with skin markers (Mantovani et al. 2016:
#: 12 +/- 6 mm against CT; up to 3-4 cm on real trials of this project's users).
HARRINGTON_ERROR = (7.0, -9.0, 10.8)
HIP_CENTRE = tuple(np.add(HARRINGTON_CENTRE, HARRINGTON_ERROR))

THIGH_LENGTH = 425.0     # hip centre to knee centre
THIGH_CLUSTER = {        # thigh frame, origin at the hip centre: four antero-lateral markers
    "RTH1": (35.0, -140.0, 75.0),
    "RTH2": (55.0, -245.0, 58.0),
    "RTH3": (-5.0, -230.0, 76.0),
    "RTH4": (25.0, -330.0, 60.0),
}
THIGH_LANDMARKS = {      # femoral epicondyles (static trial only)
    "RLFC": (0.0, -THIGH_LENGTH + 4.0, 46.0),
    "RMFC": (0.0, -THIGH_LENGTH - 4.0, -46.0),
}
KNEE_CENTRE = (0.0, -THIGH_LENGTH, 0.0)    # on the flexion axis, mid-epicondyles
#: The knee's true flexion axis in the thigh frame: the epicondylar z axis turned by 4 deg
#: about x (the medial end lower) and 3 deg about y; functional and transepicondylar axes
#: differ by a few degrees in real knees (Churchill et al. 1998).
KNEE_AXIS = tuple(Rotation.from_euler("XY", [4.0, 3.0], degrees=True).apply([0.0, 0.0, 1.0]))

SHANK_LENGTH = 405.0     # mid-malleoli to knee centre
SHANK_CLUSTER = {        # shank frame, origin mid-malleoli: four antero-lateral markers
    "RTB1": (40.0, 300.0, 42.0),
    "RTB2": (45.0, 170.0, 35.0),
    "RTB3": (10.0, 235.0, 55.0),
    "RTB4": (30.0, 120.0, 48.0),
}
SHANK_LANDMARKS = {      # malleoli (static trial only)
    "RLMAL": (0.0, -8.0, 35.0),
    "RMMAL": (0.0, 8.0, -35.0),
}
FOOT_MARKERS = {         # in every trial; the ankle stays neutral: shank frame coordinates
    "RHEEL": (-55.0, -45.0, 5.0),
    "RTOE": (150.0, -60.0, 10.0),
    "RMT5": (110.0, -55.0, 45.0),
}

# --- Soft-tissue artefact: mm of marker displacement per radian of joint angle ---------
# (Leardini et al. 2005; Camomilla et al. 2017): thigh largest, pelvis smallest.
STA_SD = {"pelvis": 1.5, "thigh": 4.0, "shank": 3.0}


def _rotation_matrices(rotvec_deg):
    return Rotation.from_rotvec(rotvec_deg, degrees=True).as_matrix()


def _place(points, R, origin, artefact=None):
    """Lab coordinates (F, 3) of each named point given in a segment's frame."""
    placed = {}
    for name, local in points.items():
        local = np.broadcast_to(np.asarray(local, dtype=float), origin.shape)
        if artefact is not None:
            local = local + artefact[name]
        placed[name] = np.einsum("fij,fj->fi", R, local) + origin
    return placed


def _artefact(rng, names, angles_rad, sd):
    """Displacement (F, 3) of each marker in its bone's frame: linear in the joint angles
    (columns of `angles_rad`, measured from the neutral posture), per-marker coefficients
    drawn from `rng`."""
    return {name: angles_rad @ rng.normal(0.0, sd, (angles_rad.shape[1], 3))
            for name in names}


def _noisy(rng, points, noise_sd):
    return {name: p + rng.normal(0.0, noise_sd, p.shape) for name, p in points.items()}


def _pose_columns(table, segment, R, origin):
    for i, axis in enumerate("xyz"):
        table[f"{segment}_o{axis}"] = origin[:, i]
    for i in range(3):
        for j in range(3):
            table[f"{segment}_R{i}{j}"] = R[:, i, j]


def _excursion(t, duration):
    """Out-and-back profile from 0 to 1 and back to 0 over `duration` (smooth)."""
    inside = (t >= 0) & (t <= duration)
    return np.where(inside, np.sin(np.pi * np.clip(t, 0, duration) / duration) ** 2, 0.0)


def star_arc(time, amplitude):
    """Hip angles of the star arc: flexion, abduction, internal rotation (deg), (F,) each.

    One second of neutral posture, then five out-and-back excursions of 2 s each at
    0, 45, 90, 135 and 180 deg in the flexion-abduction plane (extension reaching half the
    amplitude), then a 4 s circumduction at 60 % of the amplitude.
    """
    flexion = np.zeros_like(time)
    abduction = np.zeros_like(time)
    directions = [(0.0, 1.0), (45.0, 1.0), (90.0, 0.9), (135.0, 0.6), (180.0, 0.5)]
    for i, (psi, scale) in enumerate(directions):
        a = amplitude * scale * _excursion(time - 1.0 - 2.0 * i, 2.0)
        flexion += a * np.cos(np.radians(psi))
        abduction += a * np.sin(np.radians(psi))
    t_c = time - 11.0
    inside = (t_c >= 0) & (t_c <= 4.0)
    envelope = np.where(inside, np.sin(np.pi * np.clip(t_c, 0, 4.0) / 4.0), 0.0)
    psi = 2 * np.pi * t_c / 4.0
    flexion += 0.6 * amplitude * envelope * np.cos(psi) * (np.cos(psi) > 0) \
        + 0.3 * amplitude * envelope * np.cos(psi) * (np.cos(psi) <= 0)
    abduction += 0.6 * amplitude * envelope * np.sin(psi) * (np.sin(psi) > 0)
    rotation = 5.0 * np.sin(2 * np.pi * time / 3.0)
    return flexion, abduction, rotation


def hip_trial(rng, amplitude=HIP_AMPLITUDE, noise_sd=NOISE_SD, sta_scale=1.0):
    """A star-arc hip trial in memory.

    Parameters
    ----------
    rng : numpy.random.Generator
        Draws the artefact coefficients, then the noise.
    amplitude : float
        Peak hip flexion and abduction (deg); extension reaches half of it.
    noise_sd : float
        White noise on every coordinate (mm).
    sta_scale : float
        Multiplies the soft-tissue artefact (0 switches it off).

    Returns
    -------
    dict with 'markers' (DataFrame, (marker, coord) columns, mm), 'pelvis' and 'thigh'
    (name -> (F, 3) marker arrays of each cluster), 'truth' (DataFrame: hip angles, hip
    centre in the lab, segment poses), 'centre' ((F, 3) true centre in the lab).
    """
    time = np.arange(int(round(15.0 * RATE)) + 1) / RATE
    flexion, abduction, rotation = star_arc(time, amplitude)
    slow = 2 * np.pi * time
    R_pelvis = Rotation.from_euler(
        "ZXY", np.column_stack([-8.0 + 3.0 * np.sin(0.13 * slow), 3.0 * np.sin(0.21 * slow),
                                4.0 * np.sin(0.17 * slow)]), degrees=True).as_matrix()
    o_pelvis = np.column_stack([300.0 + 15.0 * np.sin(0.11 * slow),
                                920.0 + 6.0 * np.sin(0.23 * slow),
                                150.0 + 12.0 * np.sin(0.19 * slow + 1.0)])
    # hip rotation in the pelvis frame (right hip): flexion about +z, abduction about -x,
    # then internal rotation about the thigh's long axis (+y)
    swing = _rotation_matrices(np.column_stack([-abduction, np.zeros_like(time), flexion]))
    R_hip = swing @ Rotation.from_euler("Y", rotation[:, None], degrees=True).as_matrix()
    R_thigh = R_pelvis @ R_hip
    centre = o_pelvis + R_pelvis @ np.array(HIP_CENTRE)
    angles = np.radians(np.column_stack([flexion, abduction, rotation]))
    art_pelvis = _artefact(rng, PELVIS_MARKERS, angles, sta_scale * STA_SD["pelvis"])
    art_thigh = _artefact(rng, THIGH_CLUSTER, angles, sta_scale * STA_SD["thigh"])
    pelvis = _noisy(rng, _place(PELVIS_MARKERS, R_pelvis, o_pelvis, art_pelvis), noise_sd)
    thigh = _noisy(rng, _place(THIGH_CLUSTER, R_thigh, centre, art_thigh), noise_sd)
    # the knee stays extended (the knee angles of the static posture) and the ankle neutral
    o_shank = centre + R_thigh @ np.array(KNEE_CENTRE) - R_thigh @ np.array([0, SHANK_LENGTH, 0])
    art_shank = _artefact(rng, SHANK_CLUSTER, angles, sta_scale * STA_SD["shank"] / 2)
    shank = _noisy(rng, {**_place(SHANK_CLUSTER, R_thigh, o_shank, art_shank),
                         **_place(FOOT_MARKERS, R_thigh, o_shank)}, noise_sd)
    truth = {"time": time, "hip_flexion": flexion, "hip_abduction": abduction,
             "hip_internal_rotation": rotation, "hip_x": centre[:, 0],
             "hip_y": centre[:, 1], "hip_z": centre[:, 2]}
    _pose_columns(truth, "pelvis", R_pelvis, o_pelvis)
    _pose_columns(truth, "thigh", R_thigh, centre)
    return {"markers": _to_frame({**pelvis, **thigh, **shank}, time), "pelvis": pelvis,
            "thigh": thigh, "truth": pd.DataFrame(truth), "centre": centre}


def knee_trial(rng, amplitude=KNEE_AMPLITUDE, noise_sd=NOISE_SD, sta_scale=1.0,
               secondary=1.0):
    """A knee flexion-extension trial in memory.

    Parameters
    ----------
    rng : numpy.random.Generator
    amplitude : float
        Peak knee flexion (deg); each of the three cycles starts and ends at 5 deg.
    noise_sd, sta_scale : float
        As :func:`hip_trial`.
    secondary : float
        Multiplies the secondary rotations (2 deg ab/adduction, 4 deg internal/external
        rotation; 0 gives a pure hinge).

    Returns
    -------
    dict with 'markers', 'thigh', 'shank' (as :func:`hip_trial`), 'truth' (DataFrame: knee
    angles, axis point and direction in the lab, segment poses), 'point' and 'direction'
    ((F, 3) the true axis in the lab).
    """
    time = np.arange(int(round(10.0 * RATE)) + 1) / RATE
    flexion = 5.0 + (amplitude - 5.0) * np.sin(np.pi * time / (10.0 / 3)) ** 2
    adduction = secondary * 2.0 * np.sin(2 * np.pi * 0.9 * time)
    internal = secondary * 4.0 * np.sin(2 * np.pi * 1.3 * time + 1.0)
    slow = 2 * np.pi * time
    # seated on a high stool: the thigh flexed about 80 deg at the hip, moving a little
    R_thigh = Rotation.from_euler(
        "ZXY", np.column_stack([80.0 + 4.0 * np.sin(0.2 * slow), 3.0 * np.sin(0.15 * slow),
                                5.0 * np.sin(0.1 * slow)]), degrees=True).as_matrix()
    o_thigh = np.column_stack([200.0 + 8.0 * np.sin(0.12 * slow),
                               600.0 + 5.0 * np.sin(0.25 * slow),
                               150.0 + 6.0 * np.sin(0.18 * slow)])
    axis = np.array(KNEE_AXIS)
    R_knee = (_rotation_matrices(-flexion[:, None] * axis)
              @ Rotation.from_euler("XY", np.column_stack([adduction, internal]),
                                    degrees=True).as_matrix())
    R_shank = R_thigh @ R_knee
    knee = o_thigh + R_thigh @ np.array(KNEE_CENTRE)
    o_shank = knee - R_shank @ np.array([0.0, SHANK_LENGTH, 0.0])
    angles = np.radians(np.column_stack([flexion - 5.0, adduction, internal]))
    art_thigh = _artefact(rng, THIGH_CLUSTER, angles, sta_scale * STA_SD["thigh"] / 2)
    art_shank = _artefact(rng, SHANK_CLUSTER, angles, sta_scale * STA_SD["shank"])
    thigh = _noisy(rng, _place(THIGH_CLUSTER, R_thigh, o_thigh, art_thigh), noise_sd)
    shank = _noisy(rng, _place(SHANK_CLUSTER, R_shank, o_shank, art_shank), noise_sd)
    # seated upright: the pelvis (carrying the hip centre, the thigh's origin) sways a little
    R_pelvis = Rotation.from_euler(
        "ZXY", np.column_stack([-5.0 + 2.0 * np.sin(0.1 * slow), 2.0 * np.sin(0.13 * slow),
                                3.0 * np.sin(0.07 * slow)]), degrees=True).as_matrix()
    o_pelvis = o_thigh - R_pelvis @ np.array(HIP_CENTRE)
    pelvis = _noisy(rng, _place(PELVIS_MARKERS, R_pelvis, o_pelvis), noise_sd)
    foot = _noisy(rng, _place(FOOT_MARKERS, R_shank, o_shank), noise_sd)
    direction = R_thigh @ axis
    truth = {"time": time, "knee_flexion": flexion, "knee_adduction": adduction,
             "knee_internal_rotation": internal}
    for i, c in enumerate("xyz"):
        truth[f"axis_point_{c}"] = knee[:, i]
    for i, c in enumerate("xyz"):
        truth[f"axis_direction_{c}"] = direction[:, i]
    _pose_columns(truth, "thigh", R_thigh, o_thigh)
    _pose_columns(truth, "shank", R_shank, o_shank)
    return {"markers": _to_frame({**pelvis, **thigh, **shank, **foot}, time), "thigh": thigh,
            "shank": shank, "truth": pd.DataFrame(truth), "point": knee,
            "direction": direction}


def static_trial(rng, noise_sd=NOISE_SD):
    """A standing calibration trial: every marker and landmark, neutral joints."""
    time = np.arange(STATIC_FRAMES) / RATE
    F = time.size
    R_pelvis = np.broadcast_to(Rotation.from_euler("ZXY", [-8.0, 1.0, 2.0], degrees=True)
                               .as_matrix(), (F, 3, 3))
    o_pelvis = np.tile([500.0, 930.0, 200.0], (F, 1))
    centre = o_pelvis + R_pelvis @ np.array(HIP_CENTRE)
    R_thigh = R_pelvis
    knee = centre + R_thigh @ np.array(KNEE_CENTRE)
    o_shank = knee - R_thigh @ np.array([0.0, SHANK_LENGTH, 0.0])
    points = {**_place(PELVIS_MARKERS, R_pelvis, o_pelvis),
              **_place(THIGH_CLUSTER, R_thigh, centre),
              **_place(THIGH_LANDMARKS, R_thigh, centre),
              **_place(SHANK_CLUSTER, R_thigh, o_shank),
              **_place(SHANK_LANDMARKS, R_thigh, o_shank),
              **_place(FOOT_MARKERS, R_thigh, o_shank)}
    truth = {"time": time, "hip_x": centre[:, 0], "hip_y": centre[:, 1],
             "hip_z": centre[:, 2]}
    _pose_columns(truth, "pelvis", R_pelvis, o_pelvis)
    _pose_columns(truth, "thigh", R_thigh, centre)
    _pose_columns(truth, "shank", R_thigh, o_shank)
    return {"markers": _to_frame(_noisy(rng, points, noise_sd), time),
            "truth": pd.DataFrame(truth)}


def _to_frame(points, time):
    """DataFrame in the layout of bmc_functions.files.marker_table: (marker, coord) columns."""
    names = list(points)
    columns = pd.MultiIndex.from_product([names, ["x", "y", "z"]], names=["marker", "coord"])
    data = np.concatenate([points[name] for name in names], axis=1)
    df = pd.DataFrame(data, index=pd.Index(time, name="time"), columns=columns)
    df.attrs["rate"] = RATE
    df.attrs["units"] = "mm"
    return df


def _format_truth(table):
    """Truth as strings: 9 decimals for rotation-matrix entries and axis directions, 6 for
    the rest; adding 0.0 after rounding turns -0.0 into 0.0."""
    out = pd.DataFrame(index=table.index)
    for column in table.columns:
        decimals = 9 if ("_R" in column or "direction" in column) else 6
        values = table[column].to_numpy().round(decimals) + 0.0
        out[column] = [f"{value:.{decimals}f}" for value in values]
    return out


def make_trials(seed=SEED):
    """The three trials of data/functional/, in memory (one generator, in this order)."""
    rng = np.random.default_rng(seed)
    return {"static": static_trial(rng), "hip_star_arc": hip_trial(rng),
            "knee_flexion": knee_trial(rng)}


def write_trials(outdir):
    """Write the TRC and truth CSV files of the three trials into `outdir`."""
    from bmc_functions.files.trc import write_trc
    outdir = pathlib.Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    trials = make_trials()
    for name, trial in trials.items():
        write_trc(trial["markers"], outdir / f"{name}.trc", float_format=f"%.{DECIMALS}f")
        _format_truth(trial["truth"]).to_csv(outdir / f"{name}_truth.csv", index=False,
                                             lineterminator="\n")
    return trials


if __name__ == "__main__":
    here = pathlib.Path(__file__).resolve().parent
    write_trials(sys.argv[1] if len(sys.argv) > 1 else here / "functional")
