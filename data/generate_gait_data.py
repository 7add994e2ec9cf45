"""Generate the synthetic gait trials in data/gait/: several strides of both feet and the
pelvis, with stride-to-stride variability and the gait events known exactly.

Two trials, each a TRC file (mm) with an events table and a truth table beside it:

- ``walk``: overground walking, 100 Hz, progression along the lab's -X axis, Z up, a
  gap in the left heel marker over one left heel strike;
- ``run``: treadmill running, 150 Hz, progression along +X, Y up (OpenSim's axes), the
  pelvis staying over the belt.

The feet follow a simple sagittal model whose contact is exact by construction: at heel
strike the heel marker reaches the floor (rear-foot strike) and the foot rolls over the
heel to foot-flat, stays flat, rolls over the toe from heel-off, and leaves the floor at
toe-off (the toe marker stops being the pivot); in swing the heel moves forward with a
speed profile that rises from zero after toe-off and falls steeply before the next heel
strike, as measured feet do. On a treadmill everything moves back with the belt. The
pelvis rises to mid-stance in walking and sinks to mid-stance in running (Cavagna et al.,
1977), and yaws with the stride.

The truth table holds, per frame, hip and knee flexion and ankle dorsiflexion of both sides
built from typical curves (degrees) time-warped to each stride's events, with a per-stride
offset and gain: a per-frame signal whose cycles are known, to test the time
normalisation and to draw an ensemble against its truth. They are not computed from the
markers (the full leg comes with the lower-limb generator, data/generate_marker_data.py).

Run from the repository root::

    python data/generate_gait_data.py            # writes data/gait/
    python data/generate_gait_data.py OUTDIR     # writes elsewhere (used by the tests)

Built with numpy, scipy and pandas only (no bmc_functions apart from write_trc), so that
the package can be tested against it independently.
"""

import importlib.util
import pathlib
import sys

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

SEED = 20080408          # Zeni et al. 2008 (Gait & Posture 27:710)
NOISE_SD = 0.3           # mm, white measurement noise on every coordinate
DECIMALS = 3             # mm, rounding of the coordinates written to the TRC files

# --- the subject ------------------------------------------------------------------------------
FOOT = {                 # marker -> (forward, up, lateral) from the heel marker, mm, foot flat
    "HEE": (0.0, 0.0, 0.0),
    "TOE": (190.0, 5.0, 10.0),
    "MT5": (150.0, -5.0, 45.0),
}
HEEL_HEIGHT = 35.0       # mm, heel marker above the floor with the foot flat
STEP_WIDTH = 160.0       # mm, between the heel markers of the two feet
PELVIS = {               # marker -> (forward, up, right) from the pelvis centre, mm
    "RASI": (80.0, 15.0, 120.0),
    "LASI": (80.0, 15.0, -120.0),
    "RPSI": (-80.0, -15.0, 45.0),
    "LPSI": (-80.0, -15.0, -45.0),
}

# --- the trials -------------------------------------------------------------------------------
# Per gait: stride time (s) and its SD, stance (fraction of the stride) and SD, speed (mm/s),
# pelvis height and vertical amplitude (mm), yaw amplitude (deg), foot pitch at heel strike
# and toe-off (deg), foot-flat and heel-off (fractions of stance), swing clearance (mm), how
# far ahead of the pelvis centre the heel lands (mm).
GAITS = {
    "walk": dict(stride=1.10, stride_sd=0.03, stance=0.61, stance_sd=0.012, speed=1300.0,
                 height=950.0, bob=20.0, yaw=5.0, pitch_hs=20.0, pitch_to=-50.0,
                 foot_flat=0.18, heel_off=0.55, clearance=70.0, ahead=330.0),
    "run": dict(stride=0.72, stride_sd=0.015, stance=0.36, stance_sd=0.01, speed=3300.0,
                height=980.0, bob=35.0, yaw=7.0, pitch_hs=12.0, pitch_to=-55.0,
                foot_flat=0.15, heel_off=0.40, clearance=160.0, ahead=260.0),
}
# gap: (marker, which heel strike of its side in the trial, half width in s)
TRIALS = {
    "walk": dict(gait="walk", rate=100.0, duration=5.0, treadmill=False,
                 axes=("-x", "z", "y"), gap=("LHEE", 2, 0.08)),
    "run": dict(gait="run", rate=150.0, duration=3.0, treadmill=True,
                axes=("x", "y", "z"), gap=None),
}
# axes: where the model's forward, up and right axes go in the lab. A body is right-handed
# (forward x up = right, as x x y = z in the ISB axes): the three lab axes must form a proper
# rotation (det +1), or the trial is a mirror image (its right side drawn on its left).

# typical sagittal curves (percent of stride, degrees); heel strike at 0 and 100, toe-off at
# `toe_off` (the warp puts each stride's own toe-off there)
CURVES = {
    "walk": dict(toe_off=60.0,
                 hip=[(0, 30), (10, 28), (30, 12), (50, -8), (60, -2), (75, 22), (88, 33)],
                 knee=[(0, 5), (15, 18), (38, 6), (50, 10), (60, 38), (72, 60), (85, 32)],
                 ankle=[(0, 0), (8, -6), (30, 6), (48, 12), (62, -16), (75, -4), (90, 1)]),
    "run": dict(toe_off=36.0,
                hip=[(0, 35), (18, 15), (36, -8), (55, 10), (80, 45), (92, 40)],
                knee=[(0, 18), (14, 40), (36, 18), (65, 95), (85, 50), (95, 20)],
                ankle=[(0, 2), (14, 18), (36, -22), (60, 2), (85, 8)]),
}


def _periodic(keypoints, percent):
    """Periodic cubic spline through (percent, value) keypoints, evaluated at `percent`."""
    x, y = np.array(keypoints, float).T
    spline = CubicSpline(np.r_[x, 100.0], np.r_[y, y[0]], bc_type="periodic")
    return spline(np.mod(percent, 100.0))


def _ease(u):
    """Smooth step 0 -> 1 on [0, 1] (zero slope at both ends)."""
    u = np.clip(u, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(np.pi * u)


def _swing_progress(s):
    """Fraction of the swing distance covered at swing phase `s`: the speed rises from zero
    after toe-off and falls steeply to a small value before heel strike."""
    grid = np.linspace(0.0, 1.0, 2001)
    speed = grid ** 0.6 * (1.0 - grid) ** 0.3 + 0.02
    path = np.concatenate(([0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]))))
    return np.interp(s, grid, path / path[-1])


def make_events(rng, gait, duration):
    """Heel strikes and toe-offs of both sides (s), from before 0 to after `duration`."""
    g = GAITS[gait]
    count = int(duration / g["stride"]) + 4
    stride = g["stride"] + g["stride_sd"] * rng.standard_normal(count)
    right_hs = -g["stride"] * rng.uniform(0.6, 0.9) + np.concatenate(([0.0], np.cumsum(stride)))
    half = 0.5 + 0.01 * rng.standard_normal(count)
    left_hs = right_hs[:-1] + half * stride
    events = {}
    for side, strikes in (("right", right_hs), ("left", left_hs)):
        stance = g["stance"] + g["stance_sd"] * rng.standard_normal(len(strikes) - 1)
        offs = strikes[:-1] + stance * np.diff(strikes)
        events[side] = {"heel_strike": strikes, "toe_off": offs}
    return events


def _foot(t, strikes, offs, g, lateral, rng, speed):
    """Positions (n, 3) of the foot markers (forward, up, right) of one side, overground."""
    n_steps = len(offs)
    # heel marker position at each heel strike: ahead of where the pelvis is then
    landing = speed * strikes + g["ahead"] + 10.0 * rng.standard_normal(len(strikes))
    pitch = np.full(len(t), np.nan)
    pivot = np.full(len(t), "", dtype=object)
    anchor = np.full(len(t), np.nan)                 # forward position of the pivot marker
    heel_x = np.full(len(t), np.nan)
    heel_y = np.full(len(t), np.nan)
    foot = np.array([FOOT[m] for m in FOOT])         # (markers, 3)
    toe_vec = foot[list(FOOT).index("TOE"), :2]

    def rotate(vec, angle):
        c, s = np.cos(np.radians(angle)), np.sin(np.radians(angle))
        return np.stack([vec[0] * c - vec[1] * s, vec[0] * s + vec[1] * c], axis=-1)

    for k in range(n_steps):                         # loop over strides (a few), not frames
        hs, to, next_hs = strikes[k], offs[k], strikes[k + 1]
        stance = (t >= hs) & (t < to)
        u = (t[stance] - hs) / (to - hs)
        angle = np.where(u < g["foot_flat"], g["pitch_hs"] * (1 - _ease(u / g["foot_flat"])),
                         np.where(u < g["heel_off"], 0.0,
                                  g["pitch_to"] * (1 - np.cos(0.5 * np.pi * (u - g["heel_off"])
                                                              / (1 - g["heel_off"])))))
        pitch[stance] = angle
        on_toe = u >= g["heel_off"]
        toe_down = np.array([landing[k], HEEL_HEIGHT]) + toe_vec
        rel = rotate(toe_vec, angle)
        heel_x[stance] = np.where(on_toe, toe_down[0] - rel[:, 0], landing[k])
        heel_y[stance] = np.where(on_toe, toe_down[1] - rel[:, 1], HEEL_HEIGHT)
        # swing: from the heel's position at toe-off to the next landing
        swing = (t >= to) & (t < next_hs)
        s = (t[swing] - to) / (next_hs - to)
        start = toe_down - rotate(toe_vec, g["pitch_to"])
        end = np.array([landing[k + 1], HEEL_HEIGHT])
        progress = _swing_progress(s)
        heel_x[swing] = start[0] + (end[0] - start[0]) * progress
        heel_y[swing] = (start[1] + (end[1] - start[1]) * _ease(s) ** 0.7
                         + g["clearance"] * np.sin(np.pi * s))
        pitch[swing] = g["pitch_to"] + (g["pitch_hs"] - g["pitch_to"]) * _ease(s / 0.8)
    out = {}
    for name, (fwd, up, side_offset) in FOOT.items():
        rel = rotate(np.array([fwd, up]), pitch)
        out[name] = np.stack([heel_x + rel[:, 0], heel_y + rel[:, 1],
                              np.full(len(t), lateral + np.sign(lateral) * side_offset)],
                             axis=1)
    return out


def _phase(t, strikes):
    """Stride phase (0 to 1) of each instant from the heel strikes around it."""
    k = np.clip(np.searchsorted(strikes, t, side="right") - 1, 0, len(strikes) - 2)
    return (t - strikes[k]) / (strikes[k + 1] - strikes[k]), k


def _angles(t, events, gait, rng):
    """Hip and knee flexion and ankle dorsiflexion (deg) of both sides, time-warped to each
    stride."""
    curves = CURVES[gait]
    table = {}
    for side in ("right", "left"):
        strikes, offs = events[side]["heel_strike"], events[side]["toe_off"]
        phase, k = _phase(t, strikes)
        stance = (offs[k] - strikes[k]) / (strikes[k + 1] - strikes[k])
        # piecewise-linear warp: the stride's toe-off goes to the curve's toe-off percent
        percent = np.where(phase < stance, phase / stance * curves["toe_off"],
                           curves["toe_off"] + (phase - stance) / (1 - stance)
                           * (100 - curves["toe_off"]))
        for joint in ("hip", "knee", "ankle"):
            gain = 1 + 0.04 * rng.standard_normal(len(strikes))
            offset = 1.5 * rng.standard_normal(len(strikes))
            angle = "dorsiflexion" if joint == "ankle" else "flexion"
            table[(joint, side, angle)] = gain[k] * _periodic(curves[joint], percent) + offset[k]
    return table


def make_trial(name, seed=SEED, noise_sd=NOISE_SD):
    """Markers (DataFrame as from read_trc), events (DataFrame) and truth angles of a trial."""
    spec = TRIALS[name]
    g = GAITS[spec["gait"]]
    rng = np.random.default_rng([seed, list(TRIALS).index(name)])
    rate = spec["rate"]
    t = np.arange(int(round(spec["duration"] * rate))) / rate
    events = make_events(rng, spec["gait"], spec["duration"])
    points = {}
    for side, sign in (("right", 1.0), ("left", -1.0)):
        foot = _foot(t, events[side]["heel_strike"], events[side]["toe_off"], g,
                     sign * STEP_WIDTH / 2, rng, g["speed"])
        for marker, xyz in foot.items():
            points[side[0].upper() + marker] = xyz
    # pelvis: forward at the walking speed, vertical bob, lateral sway and yaw
    phase, _ = _phase(t, events["right"]["heel_strike"])
    mid = 0.5 * g["stance"]
    bob = g["bob"] * np.cos(4 * np.pi * (phase - mid))
    height = g["height"] + (bob if spec["gait"] == "walk" else -bob)
    sway = 15.0 * np.sin(2 * np.pi * (phase - mid))
    yaw = np.radians(g["yaw"]) * np.cos(2 * np.pi * phase)
    centre = np.stack([g["speed"] * t, height, sway], axis=1)
    for marker, (fwd, up, right) in PELVIS.items():
        c, s = np.cos(yaw), np.sin(yaw)                # yaw about the vertical (up) axis
        points[marker] = centre + np.stack([fwd * c + right * s, np.full(len(t), up),
                                            -fwd * s + right * c], axis=1)
    if spec["treadmill"]:                             # the belt carries everything back
        for marker in points:
            points[marker][:, 0] -= g["speed"] * t
    # lab axes, noise, a gap
    axes = np.zeros((3, 3))
    for model_axis, lab in enumerate(spec["axes"]):
        axes["xyz".index(lab[-1]), model_axis] = -1.0 if lab[0] == "-" else 1.0
    names = ["RASI", "LASI", "RPSI", "LPSI", "RHEE", "RTOE", "RMT5", "LHEE", "LTOE", "LMT5"]
    values = np.stack([points[m] @ axes.T for m in names], axis=1)        # (n, markers, 3)
    values = values + noise_sd * rng.standard_normal(values.shape)
    values = np.round(values, DECIMALS)
    gap_frames = np.zeros(len(t), bool)
    if spec["gap"] is not None:
        marker, which, half_width = spec["gap"]
        side = "left" if marker[0] == "L" else "right"
        strikes = events[side]["heel_strike"]
        centre_time = strikes[strikes > 0][which]
        gap_frames = np.abs(t - centre_time) <= half_width
        values[gap_frames, names.index(marker)] = np.nan
    columns = pd.MultiIndex.from_product([names, ["x", "y", "z"]], names=["marker", "coord"])
    markers = pd.DataFrame(values.reshape(len(t), -1), index=pd.Index(t, name="time"),
                           columns=columns)
    markers.attrs.update(rate=rate, units="mm")
    # events inside the trial, and whether a gap hides them
    rows = []
    for side in ("right", "left"):
        for event in ("heel_strike", "toe_off"):
            for time in events[side][event]:
                if 0.0 <= time <= t[-1]:
                    frame = int(np.clip(np.rint(time * rate), 0, len(t) - 1))
                    hidden = bool(spec["gap"] is not None and spec["gap"][0][0] == side[0].upper()
                                  and gap_frames[max(frame - 2, 0):frame + 3].any())
                    rows.append((side, event, round(float(time), 6), hidden))
    table = pd.DataFrame(rows, columns=["side", "event", "time", "in_gap"])
    table = table.sort_values(["side", "event", "time"], ignore_index=True)
    angles = pd.DataFrame(_angles(t, events, spec["gait"], rng), index=pd.Index(t, name="time"))
    angles.columns = pd.MultiIndex.from_tuples(angles.columns, names=["joint", "side", "angle"])
    return markers, table, angles


# --- a full two-leg trial, built on data/generate_marker_data.py's functions ---------------
LEGS_TRIAL = dict(rate=100.0, duration=4.4, static_frames=50, noise_sd=0.5)
#: Fraction of the stride at which the curves of generate_marker_data.leg_angles put
#: toe-off (the ankle's push-off peak): each stride's own toe-off is warped there.
CURVE_TOE_OFF = 0.62
ANGLE_GAIN_SD = 0.05     # per stride and angle: gain (fraction) ...
ANGLE_OFFSET_SD = 1.0    # ... and offset (deg) of the generator's curves


def marker_generator():
    """data/generate_marker_data.py as a module (its functions pose a two-leg model)."""
    path = pathlib.Path(__file__).with_name("generate_marker_data.py")
    spec = importlib.util.spec_from_file_location("generate_marker_data", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _warped_phase(t, strikes, offs):
    """Cumulative stride phase (stride k: k to k + 1) with each stride's toe-off at
    CURVE_TOE_OFF of the way, and the stride index of each instant."""
    phase, k = _phase(t, strikes)
    stance = (offs[k] - strikes[k]) / (strikes[k + 1] - strikes[k])
    warped = np.where(phase < stance, phase / stance * CURVE_TOE_OFF,
                      CURVE_TOE_OFF + (phase - stance) / (1 - stance) * (1 - CURVE_TOE_OFF))
    return k + warped, k


def make_leg_trial(seed=SEED):
    """A static trial and several walking strides of a two-leg model (clusters, landmarks,
    feet), with stride-to-stride variability: (static, walk, events, truth angles).

    The joint angles are generate_marker_data.leg_angles's curves, time-warped to each
    stride's heel strikes and toe-off and given a gain and an offset per stride; the pelvis
    advances at the speed that keeps the stance heel still on average, so the feet slide
    little. Heel strike and toe-off are known by construction of the angle curves (stride
    fraction 0 and CURVE_TOE_OFF); the feet are posed by the joint angles, not by a floor.
    """
    gen = marker_generator()
    spec = LEGS_TRIAL
    rng = np.random.default_rng([seed, len(TRIALS)])
    rate = spec["rate"]
    t = np.arange(int(round(spec["duration"] * rate))) / rate
    events = make_events(rng, "walk", spec["duration"])
    phases, legs = {}, {}
    for side in ("right", "left"):
        s, k = _warped_phase(t, events[side]["heel_strike"], events[side]["toe_off"])
        angles = gen.leg_angles(s)
        for name in angles:                          # a gain and an offset per stride
            gain = 1 + ANGLE_GAIN_SD * rng.standard_normal(len(events[side]["toe_off"]))
            offset = ANGLE_OFFSET_SD * rng.standard_normal(len(events[side]["toe_off"]))
            angles[name] = angles[name] * gain[k] + offset[k]
        phases[side], legs[side] = s, angles
    # speed: the pelvis travels over the stance foot as far as the heel moves back relative
    # to it between heel strike and toe-off (nominal stride, no variability)
    nominal = np.array([0.0, CURVE_TOE_OFF])
    still = gen.segment_poses(gen.pelvis_angles(nominal), np.zeros((2, 3)),
                              {"right": gen.leg_angles(nominal)})
    heel = gen.marker_positions(still)["RHEEL"][:, 0]
    speed = (heel[0] - heel[1]) / (CURVE_TOE_OFF * GAITS["walk"]["stride"])
    s_right = phases["right"]
    # the pelvis is highest at mid-stance of either leg, lowest in double support
    origin = np.column_stack([200.0 + speed * t, 930.0 - 12.0 * np.cos(4 * np.pi * s_right),
                              200.0 + 10.0 * np.sin(2 * np.pi * s_right)])
    poses = gen.segment_poses(gen.pelvis_angles(s_right), origin, legs)
    frames = spec["static_frames"]
    pelvis_static, legs_static = gen.static_angles(frames)
    static_poses = gen.segment_poses(pelvis_static, np.tile([500.0, 940.0, 200.0], (frames, 1)),
                                     legs_static)
    artefact = gen.soft_tissue_artefact(rng, legs, legs_static)
    clusters, landmarks, feet = gen.marker_names()
    static_points = gen.marker_positions(static_poses)
    walk_points = gen.marker_positions(poses, artefact)
    out = []
    for points, names, time in ((static_points, clusters + landmarks + feet,
                                 np.arange(frames) / rate),
                                (walk_points, clusters + feet, t)):
        values = np.stack([points[name] for name in names], axis=1)
        values = np.round(values + spec["noise_sd"] * rng.standard_normal(values.shape),
                          DECIMALS)
        columns = pd.MultiIndex.from_product([names, ["x", "y", "z"]],
                                             names=["marker", "coord"])
        df = pd.DataFrame(values.reshape(len(time), -1), index=pd.Index(time, name="time"),
                          columns=columns)
        df.attrs.update(rate=rate, units="mm")
        out.append(df)
    rows = [(side, event, round(float(time), 6), False)
            for side in ("right", "left") for event in ("heel_strike", "toe_off")
            for time in events[side][event] if 0.0 <= time <= t[-1]]
    table = pd.DataFrame(rows, columns=["side", "event", "time", "in_gap"])
    table = table.sort_values(["side", "event", "time"], ignore_index=True)
    truth = gen.truth_table(t, poses).set_index("time")
    wanted = [c for c in truth.columns if c.split("_")[0] in ("pelvis", "right", "left")
              and c.split("_")[-1] in ("flexion", "adduction", "rotation", "dorsiflexion",
                                       "inversion", "tilt", "obliquity")]
    truth = truth[wanted]
    names = []
    for column in wanted:
        part = column.split("_")
        if part[0] == "pelvis":
            names.append(("pelvis", "right", part[1]))    # the right side's reading
        else:
            names.append((part[1], part[0], part[2]))
    truth.columns = pd.MultiIndex.from_tuples(names, names=["joint", "side", "angle"])
    return out[0], out[1], table, truth


def write_trials(outdir):
    """Write every trial of TRIALS into `outdir`."""
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
    from bmc_functions.files.trc import write_trc

    outdir = pathlib.Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    for name in TRIALS:
        markers, events, angles = make_trial(name)
        write_trc(markers, outdir / f"{name}.trc", float_format=f"%.{DECIMALS}f")
        events.to_csv(outdir / f"{name}_events.csv", index=False, lineterminator="\n")
        flat = angles.copy()
        flat.columns = [".".join(col) for col in flat.columns]
        flat.round(4).to_csv(outdir / f"{name}_angles.csv", float_format="%.4f",
                             lineterminator="\n")
    static, walk, events, truth = make_leg_trial()
    write_trc(static, outdir / "legs_static.trc", float_format=f"%.{DECIMALS}f")
    write_trc(walk, outdir / "legs_walk.trc", float_format=f"%.{DECIMALS}f")
    events.to_csv(outdir / "legs_walk_events.csv", index=False, lineterminator="\n")
    truth.columns = [".".join(col) for col in truth.columns]
    (truth.round(4) + 0.0).to_csv(outdir / "legs_walk_angles.csv", float_format="%.4f",
                                  lineterminator="\n")


if __name__ == "__main__":
    write_trials(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent / "gait")
