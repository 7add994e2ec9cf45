"""Generate synthetic Plug-in Gait trials with known joint centres and angles (seeded).

The Plug-in Gait marker set (LASI RASI LPSI RPSI; on each side THI KNE TIB ANK HEE TOE)
is placed on a subject whose joint angles are known: the pelvis, hip, knee and ankle
angles are chosen (smooth curves with seeded random harmonics), the segment frames are
composed from them with scipy.spatial.transform.Rotation, the joint centres follow from
the segment lengths and the Davis et al. (1991) hip regression, and every marker is put
where Plug-in Gait's construction (chord function, static offsets) recovers exactly those
centres and frames. Without noise, ``bmc_functions.plug_in_gait`` must return the known
angles to rounding (tests/test_plug_in_gait.py). With ``make_trial(..., upper_body=True)``
the FullBody markers are added the same way (head, thorax, SHO ELB WRA WRB FIN per side)
from known head, thorax, shoulder, elbow and wrist angles, each joint centre placed where
Vicon's upper-body definitions (chords, wrist bar) recover it
(tests/test_plug_in_gait_upper_body.py).

The conventions are Vicon's (Plug-in Gait reference guide): lab z up, walking along +x;
segment axes x anterior, y to the subject's left, z proximal (the foot's z from the toe
back to the ankle); angles as Vicon reports them, left and right with Vicon's signs.
The ground truth is built here with scipy and numpy, not with bmc_functions.

Run from the repository root::

    python data/generate_plug_in_gait_data.py OUTDIR   # writes static/walk TRC + truth CSV

or use :func:`make_trial` (frames on the first axis; any length, e.g. the benchmark's
60,000 frames).
"""

import pathlib
import sys

import numpy as np
import pandas as pd
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

SEED = 19910575          # Davis et al. 1991, Human Movement Science 10:575
RATE = 100.0             # Hz
STRIDE_TIME = 1.1        # s
WALK_SPEED = 1300.0      # mm/s along +x
MARKER_DIAMETER = 14.0   # mm

#: The subject's measurements, with Vicon's names (mm, radians).
SUBJECT = {"LeftLegLength": 905.0, "RightLegLength": 898.0, "LeftKneeWidth": 108.0,
           "RightKneeWidth": 111.0, "LeftAnkleWidth": 71.0, "RightAnkleWidth": 73.0,
           "InterAsisDistance": 248.0, "MarkerDiameter": MARKER_DIAMETER,
           "LeftTibialTorsion": 0.12, "RightTibialTorsion": -0.07,
           "LeftStaticPlantFlex": 0.21, "RightStaticPlantFlex": 0.16,
           "LeftStaticRotOff": -0.06, "RightStaticRotOff": 0.04,
           # the upper body (used by trials made with upper_body=True)
           "LeftShoulderOffset": 48.0, "RightShoulderOffset": 52.0, "LeftElbowWidth": 76.0,
           "RightElbowWidth": 79.0, "LeftWristWidth": 55.0, "RightWristWidth": 57.0,
           "LeftHandThickness": 28.0, "RightHandThickness": 31.0, "HeadOffset": 0.09}

#: Upper-body lengths (mm): shoulder to elbow centre, elbow to wrist centre, wrist centre to
#: the hand's chord point; the shoulder centre in the thorax frame (left side; y mirrored).
HUMERUS_LENGTH = {"left": 290.0, "right": 295.0}
FOREARM_LENGTH = {"left": 250.0, "right": 255.0}
HAND_LENGTH = {"left": 80.0, "right": 82.0}
SHOULDER_IN_THORAX = np.array([0.0, 175.0, -45.0])

FEMUR_LENGTH = {"left": 420.0, "right": 415.0}    # hip centre to knee centre, mm
TIBIA_LENGTH = {"left": 405.0, "right": 400.0}    # knee centre to ankle centre, mm
FOOT_LENGTH = {"left": 150.0, "right": 148.0}     # ankle centre to TOE, mm
HEEL_TOE = {"left": 190.0, "right": 185.0}        # TOE to HEE, mm
SACRUM_DEPTH = 150.0     # mm behind the ASIS midpoint
#: The knee alignment device's arm (mm): its markers are 5.66 in apart (Motion Lab Systems),
#: the arms orthogonal and equally long, so each is 5.66 in / sqrt(2).
KAD_ARM = 5.66 * 25.4 / np.sqrt(2.0)
SIDES = ("right", "left")
MIRROR = {"right": 1.0, "left": -1.0}

#: Mean and amplitude (degrees) of each right-side angle over a stride; the left side is
#: half a stride later. Ankle: dorsiflexion and rotation of the foot before the offsets.
CURVES = {"pelvis_tilt": (10.0, 2.0), "pelvis_obliquity": (0.0, 4.0),
          "pelvis_rotation": (0.0, 6.0), "hip_flexion": (15.0, 25.0),
          "hip_adduction": (2.0, 6.0), "hip_rotation": (3.0, 8.0),
          "knee_flexion": (25.0, 30.0), "knee_adduction": (1.0, 3.0),
          "knee_rotation": (-2.0, 8.0), "ankle_dorsiflexion": (0.0, 12.0),
          "ankle_rotation": (-5.0, 6.0)}


#: The upper body's curves (degrees), right side's conventions (Vicon's signs).
UPPER_CURVES = {"thorax_tilt": (4.0, 2.0), "thorax_obliquity": (0.0, 3.0),
                "thorax_rotation": (0.0, 8.0), "head_tilt": (-5.0, 4.0),
                "head_obliquity": (0.0, 3.0), "head_rotation": (0.0, 6.0),
                "shoulder_flexion": (0.0, 25.0), "shoulder_abduction": (12.0, 6.0),
                "shoulder_rotation": (10.0, 10.0), "elbow_flexion": (75.0, 25.0),
                "wrist_flexion": (5.0, 15.0), "wrist_ulnar_deviation": (3.0, 8.0),
                "wrist_rotation": (0.0, 10.0)}


def _curves(s, rng, table=None):
    """Smooth periodic curves (degrees) of the stride fraction s, seeded harmonics."""
    out = {}
    for name, (mean, amplitude) in (CURVES if table is None else table).items():
        phases = rng.uniform(0, 2 * np.pi, 3)
        weights = np.array([1.0, 0.35, 0.15]) * amplitude
        out[name] = mean + sum(w * np.sin(2 * np.pi * (k + 1) * s + p)
                               for k, (w, p) in enumerate(zip(weights, phases)))
    return out


def _yxz(a, b, c):
    """R = Ry(a) Rx(b) Rz(c), angles in degrees, frames on the first axis (scipy)."""
    return Rotation.from_euler("YXZ", np.column_stack([a, b, c]), degrees=True).as_matrix()


def _rot(axis, angle):
    return Rotation.from_euler(axis, angle).as_matrix()


def davis_hip_centres(subject):
    """The hip centres in the pelvis frame (mm), Davis et al. (1991) as Vicon uses it."""
    radius = subject["MarkerDiameter"] / 2.0
    leg = (subject["LeftLegLength"] + subject["RightLegLength"]) / 2.0
    C = 0.115 * leg - 15.3
    theta, beta = 0.5, 0.314
    out = {}
    for side in SIDES:
        long = "Left" if side == "left" else "Right"
        xdis = 0.1288 * subject[long + "LegLength"] - 48.56
        y = subject["InterAsisDistance"] / 2.0 - C * np.sin(theta)
        out[side] = np.array([C * np.cos(theta) * np.sin(beta) - (xdis + radius) * np.cos(beta),
                              y if side == "left" else -y,
                              -C * np.cos(theta) * np.cos(beta)
                              - (xdis + radius) * np.sin(beta)])
    return out


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _xyz(a, b, c):
    """R = Rx(a) Ry(b) Rz(c), degrees (scipy)."""
    return Rotation.from_euler("XYZ", np.column_stack([a, b, c]), degrees=True).as_matrix()


def _wrist_bar_middle(wjc, ejc, bar, delta, m):
    """The wrist bar's midpoint W with WJC = W + m delta unit((EJC - W) x bar): Vicon's
    wrist centre inverted by fixed-point iteration (a contraction: delta << forearm)."""
    offset = np.zeros_like(wjc)
    for _ in range(80):
        offset = -m * delta * _unit(np.cross(ejc - (wjc + offset), bar))
    return wjc + offset


def _elbow_marker(sjc, ejc, wrist_middle, R_humerus, delta, m):
    """ELB, `delta` from the elbow centre perpendicular to the humerus, placed so that the
    plane of the chord (through SJC and ELB, normal to the plane of SJC, ELB and the wrist
    bar's midpoint) holds the elbow centre: with v = W - EJC in the humerus frame and
    e = (cos psi, sin psi, 0), v . e = delta (1 - v_z / |SJC - EJC|); of the two roots the
    lateral one (closer to m y)."""
    length = np.linalg.norm(sjc - ejc, axis=1)
    v = np.einsum("fji,fj->fi", R_humerus, wrist_middle - ejc)
    k = delta * (1.0 - v[:, 2] / length)
    phi = np.arctan2(v[:, 1], v[:, 0])
    spread = np.arccos(k / np.hypot(v[:, 0], v[:, 1]))
    best = None
    for psi in (phi + spread, phi - spread):
        e = (np.cos(psi)[:, None] * R_humerus[:, :, 0]
             + np.sin(psi)[:, None] * R_humerus[:, :, 1])
        score = m * np.sin(psi)
        best = (e, score) if best is None else (np.where((score > best[1])[:, None], e,
                                                         best[0]), np.maximum(score, best[1]))
    return ejc + delta * best[0]


def _upper_body(points, truth, centres, origin, R_pelvis, s, seed, subject):
    """The head, thorax and arms on the trunk (see make_trial): markers placed so that
    Vicon's definitions (upper body kinematics) recover the known frames."""
    up = _curves(s, np.random.default_rng(seed + 1), UPPER_CURVES)
    radius = subject["MarkerDiameter"] / 2.0
    R_thorax = _yxz(up["thorax_tilt"], -up["thorax_obliquity"], up["thorax_rotation"])
    trxo = origin + np.array([-20.0, 0.0, 430.0])
    thorax_local = {"CLAV": [radius, 0, 0], "C7": [-140.0, 0, 40], "STRN": [20.0, 0, -170],
                    "T10": [-153.0, 0, -190]}
    for name, local in thorax_local.items():
        points[name] = trxo + R_thorax @ np.array(local, dtype=float)
    R_head = _yxz(-up["head_tilt"], -up["head_obliquity"], up["head_rotation"])
    R_markers = R_head @ _rot("y", -subject["HeadOffset"])   # the offset turns them back
    front = trxo + R_thorax @ np.array([40.0, 0.0, 230.0])
    for name, local in (("LFHD", [0, 70, 0]), ("RFHD", [0, -70, 0]),
                        ("LBHD", [-180, 65, 0]), ("RBHD", [-180, -65, 0])):
        points[name] = front + R_markers @ np.array(local, dtype=float)
    trunk = {"head": R_head, "thorax": R_thorax,             # against progression (+x)
             "neck": np.swapaxes(R_head, 1, 2) @ R_thorax,
             "spine": np.swapaxes(R_thorax, 1, 2) @ R_pelvis}
    names = {"head": ("tilt", "obliquity", "rotation"),
             "thorax": ("tilt", "obliquity", "rotation"),
             "neck": ("flexion", "lateral_flexion", "rotation"),
             "spine": ("flexion", "lateral_flexion", "rotation")}
    for joint, R in trunk.items():
        a, b, c = Rotation.from_matrix(R).as_euler("YXZ", degrees=True).T
        right = ((a if joint == "thorax" else -a), -b, c)
        for k, name in enumerate(names[joint]):
            truth[(joint, "right", name)] = right[k]
            truth[(joint, "left", name)] = right[k] if k == 0 else -right[k]
    centres["TRXO"] = trxo
    for side in SIDES:
        _arm(points, truth, centres, side, up, R_thorax, trxo, subject)


def _arm(points, truth, centres, side, up, R_thorax, trxo, subject):
    m, p = MIRROR[side], side[0].upper()
    long = "Left" if side == "left" else "Right"
    radius = subject["MarkerDiameter"] / 2.0
    sjc_local = SHOULDER_IN_THORAX * [1.0, -m, 1.0]
    sjc = trxo + R_thorax @ sjc_local
    # SHO: in the thorax's y-z plane, delta from the centre, the line to it perpendicular
    # to the line from the thorax origin (the chord), above
    u = _unit(-sjc_local)
    d = np.array([0.0, -u[2], u[1]])
    d = d if d[2] > 0 else -d
    points[p + "SHO"] = sjc + R_thorax @ ((subject[long + "ShoulderOffset"] + radius) * d)
    R_humerus = R_thorax @ _xyz(-m * up["shoulder_abduction"], -up["shoulder_flexion"],
                                m * (up["shoulder_rotation"] - 180.0))
    ejc = sjc - HUMERUS_LENGTH[side] * R_humerus[:, :, 2]
    R_radius = R_humerus @ _rot("y", np.radians(up["elbow_flexion"])[:, None])
    wjc = ejc - FOREARM_LENGTH[side] * R_radius[:, :, 2]
    R_hand = R_radius @ _yxz(up["wrist_flexion"], m * up["wrist_ulnar_deviation"],
                             m * up["wrist_rotation"])
    hand = wjc - HAND_LENGTH[side] * R_hand[:, :, 2]
    bar = m * R_hand[:, :, 1]                                  # WRA - WRB
    middle = _wrist_bar_middle(wjc, ejc, bar, subject[long + "WristWidth"] / 2 + radius, m)
    points[p + "WRA"], points[p + "WRB"] = middle + 25.0 * bar, middle - 25.0 * bar
    away = middle - wjc
    away = away - np.sum(away * R_hand[:, :, 2], axis=1, keepdims=True) * R_hand[:, :, 2]
    # FIN on the bar's (dorsal) side of the hand's long axis: the chord puts the hand's
    # centre on the side away from the wand (the bar's midpoint)
    points[p + "FIN"] = hand + (subject[long + "HandThickness"] / 2 + radius) * _unit(away)
    points[p + "ELB"] = _elbow_marker(sjc, ejc, middle, R_humerus,
                                      subject[long + "ElbowWidth"] / 2 + radius, m)
    for joint, names in (("shoulder", ("flexion", "abduction", "rotation")),
                         ("elbow", ("flexion",)),
                         ("wrist", ("flexion", "ulnar_deviation", "rotation"))):
        for name in names:
            truth[(joint, side, name)] = up[f"{joint}_{name}"]
    centres[p + "SJC"], centres[p + "EJC"], centres[p + "WJC"] = sjc, ejc, wjc
    centres[p + "HND"] = hand


def _turn(v, axis, angle):
    """Rodrigues: the vectors v (n, 3) turned by angle (radians) about the unit axes (n, 3)."""
    return (v * np.cos(angle) + np.cross(axis, v) * np.sin(angle)
            + axis * np.sum(axis * v, axis=-1, keepdims=True) * (1.0 - np.cos(angle)))


def _kad(knee_marker, lateral, up, side):
    """The knee alignment device's markers KAX, KD1, KD2 with its origin on the KNE marker:
    three orthogonal arms of KAD_ARM, equally inclined (1/sqrt 3) to the lateral axis, KAX
    in the plane of the lateral and long axes (so the chord through KAX finds the knee
    centre on the flexion axis); the right device is the left one's mirror image."""
    arm = lateral / np.sqrt(3.0) + np.sqrt(2.0 / 3.0) * up
    turns = (2.0 * np.pi / 3.0, 4.0 * np.pi / 3.0)
    if side == "right":
        turns = turns[::-1]
    return {"KAX": knee_marker + KAD_ARM * arm,
            "KD1": knee_marker + KAD_ARM * _turn(arm, lateral, turns[0]),
            "KD2": knee_marker + KAD_ARM * _turn(arm, lateral, turns[1])}


def _abadd_plane(delta, length, abadd):
    """Where ANK and the chord function's centre lie, for a known AnkleAbAdd `abadd`
    (radians), in the plane of the shank's long axis and its lateral direction: 2D
    coordinates (lateral, proximal) with the true ankle centre at the origin and the knee
    centre at (0, length). Returns (ank, chord_centre), each (2,).

    Vicon's dynamic rule (pyCGM2's ``_rotateAjc``) takes the chord function's centre P
    (|ANK - P| = delta, ANK - P perpendicular to KJC - P) and turns it about ANK by
    `abadd` towards the knee; ANK is found here so that the turned centre is the origin:
    the angle at ANK from (origin - ANK) to (KJC - ANK) must equal phi - abadd, phi =
    arccos(delta / |KJC - ANK|) the chord centre's angle (a right triangle). Solved for
    ANK's angle psi below the lateral axis with scipy's brentq (no package code)."""
    knee = np.array([0.0, length])

    def ank(psi):
        return delta * np.array([np.cos(psi), -np.sin(psi)])

    def mismatch(psi):
        d_a, to_knee = -ank(psi) / delta, knee - ank(psi)
        angle = -np.arctan2(d_a[0] * to_knee[1] - d_a[1] * to_knee[0], d_a @ to_knee)
        return angle - (np.arccos(delta / np.linalg.norm(to_knee)) - abadd)

    psi = brentq(mismatch, -1.2, 1.2, xtol=1e-15)
    d_a = -ank(psi) / delta
    c, s_ = np.cos(abadd), np.sin(abadd)          # turn back by abadd, away from the knee
    d_p = np.array([c * d_a[0] - s_ * d_a[1], s_ * d_a[0] + c * d_a[1]])
    return ank(psi), ank(psi) + delta * d_p


def make_trial(n_frames, *, static=False, seed=SEED, subject=SUBJECT, upper_body=False,
               wand_offsets=None, kad=False, straight_knees=False, ankle_abadd=None,
               medial_ankles=False):
    """Markers, known angles and known joint centres of one trial.

    Returns (markers, angles, centres): markers a DataFrame with columns (marker, coord)
    in mm (attrs 'units' 'mm', 'rate'); angles a DataFrame with columns (joint, side,
    angle) in degrees, Vicon's components and signs; centres a dict name -> (frames, 3)
    (LHJC, RHJC, LKJC, ...). A static trial holds one posture, standing still. With
    `upper_body`, also the head, thorax and arm markers of Plug-in Gait FullBody (LFHD ...
    STRN, L/R SHO ELB WRA WRB FIN), their known angles (head, thorax, neck, spine,
    shoulder, elbow, wrist) and centres (TRXO, LSJC, LEJC, LWJC, LHND).

    `wand_offsets` (Vicon's ``LeftThighRotation``, ``RightShankRotation``, ... in radians)
    turns THI and TIB about the segment's long axis off the plane of the flexion axis, by
    Vicon's convention (``beta = -value`` on the left, ``+value`` on the right, beta the
    right-handed angle about the long axis from the wand to the lateral marker; sources in
    bmc_functions/models/plug_in_gait/knee_alignment.py). `kad` puts the knee alignment
    device on (KAX, KD1, KD2 per side; KNE taken off, the device's origin where it was);
    `straight_knees` sets the knee angles to 0 (a KAD static: the device's ankle centre is
    exact for a straight knee only).

    `ankle_abadd` (Vicon's ``LeftAnkleAbAdd``, ``RightAnkleAbAdd``, radians) places ANK
    off the shank's transverse plane through the ankle centre: with `medial_ankles` (a
    KAD-med static, medial malleolus markers LMED, RMED) ANK lies `abadd` below the
    lateral axis, at the ankle width + marker diameter / 2 from the centre, and MED
    opposite, so that the centre is midway (the static's definition, pyCGM2's
    ``getAbdAddAnkleJointOffset``); without, ANK and TIB are placed where Vicon's dynamic
    rule (the chord function with the ShankRotation, then the centre turned about ANK by
    `abadd`, pyCGM2's ``_rotateAjc``) finds the true ankle centre (:func:`_abadd_plane`).
    The ankle flexion axis (the tibia's y) stays the true one in both.
    """
    rng = np.random.default_rng(seed)
    t = np.arange(n_frames) / RATE
    s = np.zeros_like(t) + 0.13 if static else t / STRIDE_TIME
    right = _curves(s, rng)
    rng_left = np.random.default_rng(seed)          # the same curves, half a stride later
    left = _curves(s + (0.0 if static else 0.5), rng_left)
    origin = np.column_stack([(0.0 if static else WALK_SPEED) * t, 15.0 * np.sin(4 * np.pi * s),
                              950.0 + 10.0 * np.cos(4 * np.pi * s)])
    # pelvis against the direction of progression (+x): Vicon's right-side angles
    R_pelvis = _yxz(right["pelvis_tilt"], -right["pelvis_obliquity"], right["pelvis_rotation"])
    x, y = R_pelvis[:, :, 0], R_pelvis[:, :, 1]
    half = subject["InterAsisDistance"] / 2.0
    points = {"LASI": origin + half * y, "RASI": origin - half * y}
    sacrum = origin - SACRUM_DEPTH * x
    points["LPSI"], points["RPSI"] = sacrum + 45.0 * y, sacrum - 45.0 * y
    truth, centres = {}, {}
    truth[("pelvis", "right", "tilt")] = right["pelvis_tilt"]
    truth[("pelvis", "right", "obliquity")] = right["pelvis_obliquity"]
    truth[("pelvis", "right", "rotation")] = right["pelvis_rotation"]
    truth[("pelvis", "left", "tilt")] = right["pelvis_tilt"]
    truth[("pelvis", "left", "obliquity")] = -right["pelvis_obliquity"]
    truth[("pelvis", "left", "rotation")] = -right["pelvis_rotation"]
    hips = davis_hip_centres(subject)
    radius = subject["MarkerDiameter"] / 2.0
    wand_offsets = wand_offsets or {}
    for side, curves in (("right", right), ("left", left)):
        m, p = MIRROR[side], side[0].upper()
        if straight_knees:
            for name in ("knee_flexion", "knee_adduction", "knee_rotation"):
                curves[name] = np.zeros_like(t)
        long = "Left" if side == "left" else "Right"
        hip = origin + R_pelvis @ hips[side]
        R_femur = R_pelvis @ _yxz(-curves["hip_flexion"], m * curves["hip_adduction"],
                                  m * curves["hip_rotation"])
        R_knee_tibia = R_femur @ _yxz(curves["knee_flexion"], m * curves["knee_adduction"],
                                      m * curves["knee_rotation"])
        # Vicon: knee rotation = rotation of the (torsioned) tibia - torsion
        R_tibia = R_knee_tibia @ _rot("z", m * subject[long + "TibialTorsion"])
        knee = hip - FEMUR_LENGTH[side] * R_femur[:, :, 2]
        ankle = knee - TIBIA_LENGTH[side] * R_tibia[:, :, 2]
        delta_knee = subject[long + "KneeWidth"] / 2.0 + radius
        delta_ankle = subject[long + "AnkleWidth"] / 2.0 + radius
        lateral_femur, lateral_tibia = -m * R_femur[:, :, 1], -m * R_tibia[:, :, 1]
        points[p + "KNE"] = knee + delta_knee * lateral_femur
        # the wands, turned by -beta about the long axis (beta = m * Vicon's value)
        thigh_beta = m * wand_offsets.get(long + "ThighRotation", 0.0)
        shank_beta = m * wand_offsets.get(long + "ShankRotation", 0.0)
        points[p + "THI"] = (knee + 0.6 * FEMUR_LENGTH[side] * R_femur[:, :, 2]
                             + (delta_knee + 30.0) * _turn(lateral_femur, R_femur[:, :, 2],
                                                           -thigh_beta))
        abadd = (ankle_abadd or {}).get(long + "AnkleAbAdd", 0.0)
        up_tibia = R_tibia[:, :, 2]
        if medial_ankles or abadd == 0.0:
            points[p + "ANK"] = ankle + delta_ankle * (np.cos(abadd) * lateral_tibia
                                                       - np.sin(abadd) * up_tibia)
            points[p + "TIB"] = (ankle + 0.6 * TIBIA_LENGTH[side] * up_tibia
                                 + (delta_ankle + 30.0) * _turn(lateral_tibia, up_tibia,
                                                                -shank_beta))
            if medial_ankles:
                points[p + "MED"] = 2.0 * ankle - points[p + "ANK"]
        else:      # the dynamic rule: ANK and the chord centre P from _abadd_plane
            ank, chord = _abadd_plane(delta_ankle, TIBIA_LENGTH[side], abadd)
            points[p + "ANK"] = ankle + ank[0] * lateral_tibia + ank[1] * up_tibia
            centre = ankle + chord[0] * lateral_tibia + chord[1] * up_tibia
            lateral_c = (points[p + "ANK"] - centre) / delta_ankle
            up_c = _unit(knee - centre)
            points[p + "TIB"] = (centre + 0.6 * TIBIA_LENGTH[side] * up_c
                                 + (delta_ankle + 30.0) * _turn(lateral_c, up_c, -shank_beta))
        if kad:
            device = _kad(points[p + "KNE"], lateral_femur, R_femur[:, :, 2], side)
            points.update({p + name: xyz for name, xyz in device.items()})
            del points[p + "KNE"]
        # the foot before the offsets: its roll is the tibia's (no roll sensor in the CGM)
        R_uncorrected = R_tibia @ _yxz(-90.0 - curves["ankle_dorsiflexion"],
                                       curves["ankle_rotation"], np.zeros_like(t))
        R_foot = (R_uncorrected @ _rot("y", -subject[long + "StaticPlantFlex"])
                  @ _rot("x", m * subject[long + "StaticRotOff"]))
        points[p + "TOE"] = ankle - FOOT_LENGTH[side] * R_uncorrected[:, :, 2]
        points[p + "HEE"] = points[p + "TOE"] + HEEL_TOE[side] * R_foot[:, :, 2]
        truth[("hip", side, "flexion")] = curves["hip_flexion"]
        truth[("hip", side, "adduction")] = curves["hip_adduction"]
        truth[("hip", side, "rotation")] = curves["hip_rotation"]
        truth[("knee", side, "flexion")] = curves["knee_flexion"]
        truth[("knee", side, "adduction")] = curves["knee_adduction"]
        truth[("knee", side, "rotation")] = curves["knee_rotation"]
        # ankle and foot progression of the corrected foot, decomposed with scipy
        relative = np.swapaxes(R_tibia, 1, 2) @ R_foot
        a, b, c = Rotation.from_matrix(relative).as_euler("YXZ", degrees=True).T
        truth[("ankle", side, "dorsiflexion")] = (-a - 90.0 + 180.0) % 360.0 - 180.0
        truth[("ankle", side, "inversion")] = m * c
        truth[("ankle", side, "rotation")] = m * b
        _, b, _ = Rotation.from_matrix(R_foot).as_euler("YXZ", degrees=True).T
        truth[("foot", side, "progression")] = m * b
        centres[p + "HJC"], centres[p + "KJC"], centres[p + "AJC"] = hip, knee, ankle
    names = ["LASI", "RASI", "LPSI", "RPSI"] + [p + m for p in "LR"
                                                for m in ("THI", "KNE", "TIB", "ANK", "HEE",
                                                          "TOE", "KAX", "KD1", "KD2", "MED")
                                                if p + m in points]
    if upper_body:
        _upper_body(points, truth, centres, origin, R_pelvis, s, seed, subject)
        names += ["LFHD", "RFHD", "LBHD", "RBHD", "C7", "T10", "CLAV", "STRN"] + [
            p + m for p in "LR" for m in ("SHO", "ELB", "WRA", "WRB", "FIN")]
    columns = pd.MultiIndex.from_product([names, ["x", "y", "z"]], names=["marker", "coord"])
    index = pd.Index(t, name="time")
    markers = pd.DataFrame(np.concatenate([points[n] for n in names], axis=1),
                           index=index, columns=columns)
    markers.attrs = {"units": "mm", "rate": RATE, "frames": list(range(1, n_frames + 1))}
    angles = pd.DataFrame(truth, index=index)
    angles.columns.names = ["joint", "side", "angle"]
    return markers, angles, centres


def write_trials(outdir):
    """Write pig_static.trc (50 frames), pig_walk.trc (one stride) and the truth CSV."""
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
    from bmc_functions import write_trc

    outdir = pathlib.Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    static, _, _ = make_trial(50, static=True)
    walk, truth, _ = make_trial(int(round(STRIDE_TIME * RATE)))
    write_trc(static, outdir / "pig_static.trc", rate=RATE, units="mm")
    write_trc(walk, outdir / "pig_walk.trc", rate=RATE, units="mm")
    truth.to_csv(outdir / "pig_walk_truth.csv", float_format="%.9f")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python data/generate_plug_in_gait_data.py OUTDIR")
    write_trials(sys.argv[1])
