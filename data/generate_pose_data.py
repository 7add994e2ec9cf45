"""Generate data/poses/: a synthetic walking trial of 3D body keypoints with its ground truth.

Usage (from the repository root)::

    python data/generate_pose_data.py            # writes data/poses/*.csv
    python data/generate_pose_data.py OUTDIR     # writes OUTDIR/*.csv

Four seconds of walking at 50 Hz (200 frames), made by forward kinematics from known
joint-rotation trajectories on a subject's T-pose skeleton, then measurement noise and a
few lost keypoints, like the output of a markerless pose estimator. Deterministic: the
same files on every run (seeded noise, fixed float formatting). The format is described
in data/README.md.

The ground truth is written so that it *can* be recovered from keypoints: every limb
joint's rotation is the minimal (twist-free) rotation that takes its T-pose offset onto
the bone, built here directly from a rotation vector perpendicular to the bone, because
a rotation about a bone's own axis leaves the keypoints unchanged and no method could
find it. The root and neck rotations are general but respect the frame definitions of
bmc_functions.skeleton (see ``simulate``). This script does not use bmc_functions, so
the truth is independent of the code it tests: rotations and angles come from
scipy.spatial.transform.Rotation.
"""

import pathlib
import sys

import numpy as np
from scipy.spatial.transform import Rotation

SEED = 20210916
RATE = 50.0          # Hz
DURATION = 4.0       # s
STRIDE_FREQ = 0.9    # strides per second
SPEED = 1.2          # m/s, walking towards +z
NOISE_SD = 0.005     # m, per coordinate, Gaussian
# Lost keypoints: (joint, first frame, last frame inclusive) set to NaN in the keypoints.
LOST = (("leftwrist", 50, 64), ("rightknee", 120, 127), ("leftfoot", 160, 165))

JOINTS = ("hips", "lefthip", "leftknee", "leftfoot", "righthip", "rightknee", "rightfoot",
          "neck", "leftshoulder", "leftelbow", "leftwrist", "rightshoulder", "rightelbow",
          "rightwrist")
PARENTS = {"hips": "", "lefthip": "hips", "leftknee": "lefthip", "leftfoot": "leftknee",
           "righthip": "hips", "rightknee": "righthip", "rightfoot": "rightknee",
           "neck": "hips", "leftshoulder": "neck", "leftelbow": "leftshoulder",
           "leftwrist": "leftelbow", "rightshoulder": "neck", "rightelbow": "rightshoulder",
           "rightwrist": "rightelbow"}
KEYPOINTS = tuple(j for j in JOINTS if j not in ("hips", "neck"))
ROTATING = ("hips", "lefthip", "leftknee", "righthip", "rightknee", "neck",
            "leftshoulder", "leftelbow", "rightshoulder", "rightelbow")

# The subject's T-pose (x left, y up, z forward), metres: not the default skeleton's.
LENGTHS = {"hip": 0.09, "thigh": 0.44, "shank": 0.43, "trunk": 0.52, "shoulder": 0.19,
           "upperarm": 0.31, "forearm": 0.27}
OFFSETS = {
    "hips": (0, 0, 0),
    "lefthip": (LENGTHS["hip"], 0, 0), "righthip": (-LENGTHS["hip"], 0, 0),
    "leftknee": (0, -LENGTHS["thigh"], 0), "rightknee": (0, -LENGTHS["thigh"], 0),
    "leftfoot": (0, -LENGTHS["shank"], 0), "rightfoot": (0, -LENGTHS["shank"], 0),
    "neck": (0, LENGTHS["trunk"], 0),
    "leftshoulder": (LENGTHS["shoulder"], 0, 0), "rightshoulder": (-LENGTHS["shoulder"], 0, 0),
    "leftelbow": (LENGTHS["upperarm"], 0, 0), "rightelbow": (-LENGTHS["upperarm"], 0, 0),
    "leftwrist": (LENGTHS["forearm"], 0, 0), "rightwrist": (-LENGTHS["forearm"], 0, 0),
}


def _bump(phase, centre, width):
    """A periodic Gaussian bump over the gait cycle (phase in cycles)."""
    d = (phase - centre + 0.5) % 1.0 - 0.5
    return np.exp(-(d / width) ** 2)


def _minimal_rotation(a, b):
    """Matrices of the rotation by the angle between a and b about a x b (no twist).

    Written here from the rotation vector (angle times unit axis) so that the ground
    truth does not depend on bmc_functions.get_R. The vectors are never (anti)parallel
    in this trial.
    """
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    c = np.cross(a, b)
    s = np.linalg.norm(c, axis=-1, keepdims=True)
    angle = np.arctan2(s, np.sum(a * b, axis=-1, keepdims=True))
    return Rotation.from_rotvec(c * angle / s).as_matrix()


def _rotvec(x, y, z):
    return Rotation.from_rotvec(np.stack([x, y, z], axis=-1)).as_matrix()


def simulate():
    """The trial at full precision.

    Returns
    -------
    dict with keys
        ``time`` (F,); ``offsets`` (joint -> (3,)); ``root_position`` (F, 3);
        ``root_rotation`` (F, 3, 3); ``rotations`` (joint -> (F, 3, 3), local);
        ``positions`` (joint -> (F, 3), true, all 14 joints); ``keypoints`` (joint ->
        (F, 3), noisy with NaN runs, the 12 limb keypoints); ``angles`` (joint -> (F, 3)
        ZXY angles in degrees, unwrapped; key ``'root'`` for the root rotation).

    Notes
    -----
    Model (the same chain as bmc_functions.skeleton): the hip offsets hang from the root
    frame, the trunk from ``R_root @ R_hips``, every other joint from its parent's world
    rotation ``W``: ``p_joint = p_parent + W_parent @ offset``, ``W_joint = W_parent @
    R_joint``. Recoverable truth: ``R_hips`` is a rotation about the root's z axis (a
    lateral bend, so the trunk stays in the root frame's xy plane); ``R_neck = Ry @ Rz``
    (its z axis has no y component, so the trunk stays in the neck frame's xy plane);
    every limb rotation is a rotation vector perpendicular to the bone.
    """
    t = np.arange(int(round(DURATION * RATE))) / RATE
    n = len(t)
    deg = np.deg2rad
    phase = (STRIDE_FREQ * t) % 1.0     # 0 = left heel strike
    wave = 2 * np.pi * STRIDE_FREQ * t
    zero = np.zeros(n)

    root_position = np.stack([0.02 * np.sin(wave), 0.90 + 0.015 * np.cos(2 * wave),
                              SPEED * t], axis=-1)
    # Pelvis: yaw (about y), forward tilt of the hip-trunk frame (about x), obliquity (z).
    root_rotation = Rotation.from_euler(
        "YXZ", np.stack([deg(6) * np.sin(wave), deg(8) + deg(2) * np.cos(2 * wave),
                         deg(4) * np.sin(wave)], axis=-1)).as_matrix()

    R = {}
    R["hips"] = _rotvec(zero, zero, deg(3) * np.sin(wave))           # lateral bend
    R["neck"] = Rotation.from_euler(                                   # thorax counter-
        "YZ", np.stack([-deg(9) * np.sin(wave), deg(2) * np.sin(wave + 1.0)],  # rotation,
                       axis=-1)).as_matrix()                           # shoulder tilt
    for side, sign, shift in (("left", 1.0, 0.0), ("right", -1.0, 0.5)):
        p = (phase - shift) % 1.0
        hip_flexion = deg(10 + 20 * np.cos(2 * np.pi * p) + 4 * _bump(p, 0.85, 0.08))
        hip_abduction = deg(2 + 3 * np.sin(2 * np.pi * p))
        knee_flexion = deg(5 + 13 * _bump(p, 0.15, 0.07) + 55 * _bump(p, 0.72, 0.11))
        # Flexion moves the knee forward: a negative rotation about x; abduction moves
        # the left foot to +x (rotation about +z), the right foot to -x.
        R[side + "hip"] = _rotvec(-hip_flexion, zero, sign * hip_abduction)
        R[side + "knee"] = _rotvec(knee_flexion, zero, zero)

        # Arms hang 10 degrees abducted and swing opposite to the leg on the same side.
        swing = -deg(16) * np.cos(2 * np.pi * p)
        abduction = deg(10)
        upper = np.stack([sign * np.sin(abduction) + zero,
                          -np.cos(abduction) * np.cos(swing),
                          np.cos(abduction) * np.sin(swing)], axis=-1)
        x_axis = np.array([sign, 0.0, 0.0])
        R[side + "shoulder"] = _minimal_rotation(x_axis, upper)
        # Elbow flexion brings the forearm forward, more when the arm swings forward.
        elbow = deg(25) + 0.6 * swing
        forward = np.array([0.0, 0.0, 1.0]) - upper[:, 2:3] * upper
        forward /= np.linalg.norm(forward, axis=-1, keepdims=True)
        fore = np.cos(elbow)[:, None] * upper + np.sin(elbow)[:, None] * forward
        fore_local = np.einsum("fji,fj->fi", R[side + "shoulder"], fore)
        R[side + "elbow"] = _minimal_rotation(x_axis, fore_local)

    offsets = {j: np.array(v, dtype=float) for j, v in OFFSETS.items()}
    pos = {"hips": root_position}
    world = {"hips": root_rotation @ R["hips"]}
    for joint in JOINTS[1:]:
        parent = PARENTS[joint]
        W = root_rotation if joint in ("lefthip", "righthip") else world[parent]
        pos[joint] = pos[parent] + W @ offsets[joint]
        if joint in R:
            world[joint] = W @ R[joint]

    rng = np.random.default_rng(SEED)
    keypoints = {}
    for joint in KEYPOINTS:
        keypoints[joint] = pos[joint] + rng.normal(0.0, NOISE_SD, size=(n, 3))
    for joint, first, last in LOST:
        keypoints[joint][first:last + 1] = np.nan

    def zxy(matrices):
        return np.rad2deg(np.unwrap(Rotation.from_matrix(matrices).as_euler("ZXY"), axis=0))

    angles = {"root": zxy(root_rotation)}
    angles.update({joint: zxy(R[joint]) for joint in ROTATING})
    return {"time": t, "offsets": offsets, "root_position": root_position,
            "root_rotation": root_rotation, "rotations": R, "positions": pos,
            "keypoints": keypoints, "angles": angles}


def _write(path, header, columns):
    table = np.column_stack(columns)
    fmt = ["%.2f"] + ["%.6f"] * (table.shape[1] - 1)
    np.savetxt(path, table, fmt=fmt, delimiter=",", header=",".join(header), comments="")


def write(outdir):
    """Write the four CSV files of the trial into `outdir` (created if needed)."""
    outdir = pathlib.Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    trial = simulate()
    t = trial["time"]
    xyz = lambda joints: [f"{j}_{c}" for j in joints for c in "xyz"]  # noqa: E731

    _write(outdir / "walking_keypoints.csv", ["time"] + xyz(KEYPOINTS),
           [t] + [trial["keypoints"][j] for j in KEYPOINTS])
    _write(outdir / "walking_true_positions.csv", ["time"] + xyz(JOINTS),
           [t] + [trial["positions"][j] for j in JOINTS])
    names = ("root",) + ROTATING
    _write(outdir / "walking_true_angles.csv",
           ["time"] + [f"{j}_{c}" for j in names for c in "zxy"],
           [t] + [trial["angles"][j] for j in names])
    with open(outdir / "walking_skeleton.csv", "w", newline="\n") as f:
        f.write("joint,parent,offset_x,offset_y,offset_z\n")
        for joint in JOINTS:
            x, y, z = trial["offsets"][joint]
            f.write(f"{joint},{PARENTS[joint]},{x:.6f},{y:.6f},{z:.6f}\n")
    return sorted(p.name for p in outdir.glob("walking_*.csv"))


if __name__ == "__main__":
    here = pathlib.Path(__file__).resolve().parent
    target = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else here / "poses"
    for name in write(target):
        print(target / name)
