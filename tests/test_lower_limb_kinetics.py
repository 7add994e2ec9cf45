"""LowerLimbModel.kinetics: signs on synthetic static postures (worked out by hand), the
assignment of ground loads to feet and its warnings, and the shared running trial against
OpenSim's inverse dynamics."""

import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import (calibrate_lower_limb, hip_joint_centre, pelvis_frame, read_mot,
                           read_trc)
from bmc_functions.dynamics.newton_euler import STANDARD_GRAVITY as G
from helpers import (ROOT, SHARED_DATA, needs_shared, synthetic_markers, two_leg_markers,
                     warning_messages)

RATE = 100.0
FRAMES = 100
BODY_MASS = 70.0
PELVIS = {"RASI": (120.0, 950.0, 125.0), "LASI": (120.0, 950.0, -125.0),
          "RPSI": (-40.0, 960.0, 45.0), "LPSI": (-40.0, 960.0, -45.0)}
MARKERS = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI"}
for _p in "RL":
    MARKERS.update({_p + "KNEE_LAT": _p + "LFC", _p + "KNEE_MED": _p + "MFC",
                    _p + "ANKLE_LAT": _p + "LMAL", _p + "ANKLE_MED": _p + "MMAL",
                    _p + "HEEL": _p + "HEE", _p + "TOE": _p + "TOE", _p + "MT5": _p + "MT5"})


def hip(side):
    return hip_joint_centre(*(np.array(PELVIS[k]) for k in ("RASI", "LASI", "RPSI", "LPSI")),
                            side=side)


def leg(side, raise_by=0.0):
    """A vertical leg under its hip centre (lab: x forwards, y up, z right; mm): knee
    centre at 500 mm, ankle centre at 90 mm, heel 60 mm behind and toe 160 mm in front
    of the ankle at 40 mm, MT5 lateral."""
    p, s = side[0].upper(), 1.0 if side == "right" else -1.0
    hx, _, hz = hip(side)
    points = {p + "LFC": (hx, 500, hz + s * 50), p + "MFC": (hx, 500, hz - s * 50),
              p + "LMAL": (hx, 90, hz + s * 35), p + "MMAL": (hx, 90, hz - s * 35),
              p + "HEE": (hx - 60, 40, hz), p + "TOE": (hx + 160, 40, hz),
              p + "MT5": (hx + 130, 40, hz + s * 35)}
    return {label: np.add(xyz, (0, raise_by, 0)) for label, xyz in points.items()}


def standing_trial(raise_left=0.0):
    points = {**PELVIS, **leg("right"), **leg("left", raise_left)}
    columns = pd.MultiIndex.from_product([list(points), ["x", "y", "z"]],
                                         names=["marker", "coord"])
    values = np.tile(np.concatenate([np.asarray(v, float) for v in points.values()]),
                     (FRAMES, 1))
    df = pd.DataFrame(values, columns=columns,
                      index=pd.Index(np.arange(FRAMES) / RATE, name="time"))
    df.attrs = {"rate": RATE, "units": "mm"}
    return df


def loads(**feet):
    """An external-loads table: prefix -> (force (3,), cop (3,) in m, torque (3,))."""
    table = {}
    for prefix, (force, cop, torque) in feet.items():
        prefix = "" if prefix == "none" else prefix
        for kind, value in (("ground_force_v", force), ("ground_force_p", cop),
                            ("ground_torque_", torque)):
            for axis, component in zip("xyz", value):
                table[f"{prefix}{kind}{axis}"] = np.full(2 * FRAMES + 20, float(component))
    return pd.DataFrame(table, index=pd.Index(np.arange(2 * FRAMES + 20) / (2 * RATE) - 0.05,
                                              name="time"))


def under(side, dx=0.0, dz=0.0):
    """A point on the floor dx (mm) in front of and dz (mm) lateral to an ankle, in m."""
    hx, _, hz = hip(side)
    s = 1.0 if side == "right" else -1.0
    return np.array([hx + dx, 0.0, hz + s * dz]) / 1000.0


@pytest.fixture(scope="module")
def model():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return calibrate_lower_limb(None, MARKERS)


def kinetics(model, trial, forces, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("error")            # a clean static case warns nothing
        return model.kinetics(trial, forces, body_mass=BODY_MASS, **options)


# Dempster's masses (kg) of a 70 kg subject, and the foot's centre of mass 80 mm in front
# of the ankle (half-way from the ankle centre to the toe, 160 mm ahead): worked by hand.
M_FOOT, M_SHANK, M_THIGH = 0.0145 * 70, 0.0465 * 70, 0.100 * 70
FOOT_COM_DX = 0.080


@pytest.mark.parametrize("dx", [100.0, -50.0])
def test_sagittal_signs_of_a_subject_standing_on_both_feet(model, dx):
    """Static: 350 N under each foot, dx mm in front of the ankle (the leg vertical, ankle,
    knee and hip on one vertical line). Moment of the ground force about each joint
    350 * dx; the foot's weight acts 80 mm in front. By hand (x: extensor/plantarflexor
    positive): ankle = (F dx - m_foot g 0.08) / 70, knee = -ankle, hip = ankle.
    Ahead of the ankle: plantarflexor, knee flexor, hip extensor; behind: the reverse."""
    F = 350.0
    trial = standing_trial()
    result = kinetics(model, trial, loads(R_=((0, F, 0), under("right", dx), (0, 0, 0)),
                                          L_=((0, F, 0), under("left", dx), (0, 0, 0))))
    ankle = (F * dx / 1000 - M_FOOT * G * FOOT_COM_DX) / BODY_MASS
    for side in ("right", "left"):
        assert result["ankle", side, "moment_x"].to_numpy() == pytest.approx(ankle, abs=1e-9)
        assert result["knee", side, "moment_x"].to_numpy() == pytest.approx(-ankle, abs=1e-9)
        assert result["hip", side, "moment_x"].to_numpy() == pytest.approx(ankle, abs=1e-9)
        assert np.sign(result["ankle", side, "moment_x"].iloc[0]) == np.sign(dx)
        # the shank presses the foot down: F - m_foot g down, per kg
        assert result["ankle", side, "force_z"].to_numpy() == pytest.approx(
            -(F - M_FOOT * G) / BODY_MASS, abs=1e-9)
        assert result["hip", side, "force_z"].to_numpy() == pytest.approx(
            -(F - (M_FOOT + M_SHANK + M_THIGH) * G) / BODY_MASS, abs=1e-9)
        powers = result.loc[:, (slice(None), side, "power")].to_numpy()
        assert powers == pytest.approx(0.0, abs=1e-9)
    assert result.index.equals(trial.index)
    assert [a["side"] for a in result.attrs["load_assignment"]] == ["right", "left"]


def test_frontal_and_transverse_signs_mirror_between_the_sides(model):
    """The load 30 mm lateral to each ankle, knee and hip (the leg vertical) lifts the
    lateral border of the foot: an external eversion and abduction (valgus) moment, held
    by an internal invertor and adductor moment: moment_y (abductor, evertor positive) is
    -F 0.03 at every joint of both sides, as when the ground force passes lateral to the
    knee. A free moment of +5 N m about the vertical (y up) turns the toes to the left:
    it rotates the right foot internally, held by an internal external-rotator moment
    (+z), and the left one externally (-z)."""
    F, T = 350.0, 5.0
    trial = standing_trial()
    result = kinetics(model, trial, loads(R_=((0, F, 0), under("right", 0, 30), (0, T, 0)),
                                          L_=((0, F, 0), under("left", 0, 30), (0, T, 0))))
    frontal = -F * 0.030 / BODY_MASS
    for side, turn in (("right", 1.0), ("left", -1.0)):
        for joint in ("ankle", "knee", "hip"):
            assert result[joint, side, "moment_y"].to_numpy() == pytest.approx(frontal,
                                                                              abs=1e-9)
            assert result[joint, side, "moment_z"].to_numpy() == pytest.approx(
                turn * T / BODY_MASS, abs=1e-9)


def test_a_hanging_foot_needs_a_dorsiflexor_and_a_standing_one_no_load_is_nan(model):
    """Left leg raised 150 mm, no load (swing, at rest): its foot's weight, 80 mm in front
    of the ankle, is held by a dorsiflexor moment (negative moment_x). The right foot
    stands with no load at all: NaN, and one warning names its stance."""
    trial = standing_trial(raise_left=150.0)
    forces = loads(R_=((0, 0, 0), under("right"), (0, 0, 0)))
    messages = warning_messages(model.kinetics, trial, forces, body_mass=BODY_MASS)
    assert len(messages) == 1
    assert "no ground load measured in the stance(s) right 0.000-0.990 s" in messages[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = model.kinetics(trial, forces, body_mass=BODY_MASS)
    assert result["ankle", "left", "moment_x"].to_numpy() == pytest.approx(
        -M_FOOT * G * FOOT_COM_DX / BODY_MASS, abs=1e-9)
    assert result["knee", "left", "force_z"].to_numpy() == pytest.approx(
        (M_FOOT + M_SHANK) * G / BODY_MASS, abs=1e-9)          # it holds the leg up
    assert result.loc[:, (slice(None), "right")].isna().all().all()


def test_loads_are_assigned_by_position_whatever_their_prefix(model):
    """A load named L_ under the right foot goes to the right foot, with a warning; an
    unprefixed load under neither foot is not used, with a warning."""
    trial = standing_trial()
    forces = loads(L_=((0, 350, 0), under("right", 50), (0, 0, 0)),
                   R_=((0, 350, 0), under("left", 50), (0, 0, 0)),
                   none=((0, 200, 0), under("right", 2000), (0, 0, 0)))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = model.kinetics(trial, forces, body_mass=BODY_MASS)
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1, messages
    assert "'L_' at -0.050-1.045 s is under the right foot, not the left one" in messages[0]
    assert "'(no prefix)' at -0.050-1.045 s stands under no foot alone" in messages[0]
    sides = {a["load"]: a["side"] for a in result.attrs["load_assignment"]}
    assert sides == {"L_": "right", "R_": "left", "": None}
    assert result["ankle", "right", "moment_x"].iloc[50] > 0        # 50 mm ahead


def test_frames_the_tracking_rejects_are_nan_and_not_differentiated_through(model):
    """The legs' labels swapped in frames 40-45: the tracking flags them (its warning, and
    NaN angles); the kinetics are NaN there, and the 180-degree turns of the swapped
    frames are not differentiated (no angular-velocity warning)."""
    trial = standing_trial()
    rows = trial.index[40:46]
    for label in ("LFC", "MFC", "LMAL", "MMAL", "HEE", "TOE", "MT5"):
        right = trial.loc[rows, "R" + label].to_numpy()
        left = trial.loc[rows, "L" + label].to_numpy()
        trial.loc[rows, "R" + label], trial.loc[rows, "L" + label] = left, right
    forces = loads(R_=((0, 350, 0), under("right", 50), (0, 0, 0)),
                   L_=((0, 350, 0), under("left", 50), (0, 0, 0)))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = model.kinetics(trial, forces, body_mass=BODY_MASS, cutoff=None,
                                force_cutoff=None)
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1 and "the legs' left and right labels are swapped" in messages[0]
    nan = result.isna().any(axis=1).to_numpy()
    assert np.flatnonzero(nan).tolist() == list(range(40, 46))
    assert result["ankle", "left", "moment_x"].iloc[0] == pytest.approx(
        (350 * 0.05 - M_FOOT * G * FOOT_COM_DX) / BODY_MASS)


def test_a_frame_in_which_a_segment_turns_too_far_is_nan_with_one_warning(model):
    """The right foot's markers turned 90 degrees about the vertical through the ankle in
    frame 50 only (no tracking check sees it: no cluster, no mirror): the pairs 49-50 and
    50-51 turn more than 30 degrees, so frames 49-51 of the right leg are NaN (not a
    spike of sin(90)/h); the left leg is untouched."""
    trial = standing_trial()
    row = trial.index[50]
    ankle = (trial.loc[row, "RLMAL"].to_numpy() + trial.loc[row, "RMMAL"].to_numpy()) / 2
    for label in ("RHEE", "RTOE", "RMT5"):
        d = trial.loc[row, label].to_numpy() - ankle
        trial.loc[row, label] = ankle + [d[2], d[1], -d[0]]          # 90 deg about y
    forces = loads(R_=((0, 350, 0), under("right", 50), (0, 0, 0)),
                   L_=((0, 350, 0), under("left", 50), (0, 0, 0)))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = model.kinetics(trial, forces, body_mass=BODY_MASS, cutoff=None,
                                force_cutoff=None)
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1 and "3 of 100 frames" in messages[0] \
        and "more than 30 degrees" in messages[0], messages
    right = result.xs("right", axis=1, level="side")
    assert np.flatnonzero(right.isna().any(axis=1)).tolist() == [49, 50, 51]
    assert not result.xs("left", axis=1, level="side").isna().any().any()
    clean = kinetics(model, standing_trial(), forces, cutoff=None, force_cutoff=None)
    np.testing.assert_allclose(result.drop(index=result.index[49:52]),
                               clean.drop(index=clean.index[49:52]), atol=1e-9)


def both_legs():
    """The roles of data/markers' trials, both legs."""
    markers = synthetic_markers()
    markers.update({"LTHIGH": ["LTH1", "LTH2", "LTH3", "LTH4"], "LSHANK": ["LTB1", "LTB2", "LTB3"],
                    "LKNEE_LAT": "LLFC", "LKNEE_MED": "LMFC", "LANKLE_LAT": "LLMAL",
                    "LANKLE_MED": "LMMAL", "LHEEL": "LHEEL", "LTOE": "LTOE", "LMT5": "LMT5"})
    return markers


def walk_loads(trial, stride_time=1.10):
    """700 N up under each foot's heel-toe midpoint in the first 60 % of its stride (the
    generator's right heel strike at phase 0, left at 0.5), at 1000 Hz, OpenSim's
    columns (m)."""
    time = np.arange(int(len(trial) * 10)) / 1000.0
    frame = np.minimum((time * 100).astype(int), len(trial) - 1)
    table = {}
    for p, phase in (("R", 0.0), ("L", 0.5)):
        down = (time / stride_time + phase) % 1.0 < 0.6
        cop = ((trial[p + "HEEL"].to_numpy() + trial[p + "TOE"].to_numpy()) / 2000.0)[frame]
        for k, axis in enumerate("xyz"):
            table[f"{p}_ground_force_v{axis}"] = 700.0 * down * (axis == "y")
            table[f"{p}_ground_force_p{axis}"] = cop[:, k] * (axis != "y")
            table[f"{p}_ground_torque_{axis}"] = np.zeros(len(time))
    return pd.DataFrame(table, index=pd.Index(time + trial.index[0], name="time"))


def test_a_marker_swapped_in_some_frames_makes_them_nan_a_slow_deformation_does_not():
    """The generated walk (data/markers): with two thigh markers swapped in frames 50-59
    (a jump of the cluster's RMSE), the right leg is NaN there and the left leg is
    unchanged; with a thigh marker sliding slowly, the tracking warns and nothing is
    NaN (the benchmark's ten-minute walk, its thighs deforming up to 9 mm with the
    soft-tissue artefact, gives no NaN either)."""
    static = read_trc(ROOT / "data" / "markers" / "static.trc")
    walk = read_trc(ROOT / "data" / "markers" / "walk.trc")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        walk_model = calibrate_lower_limb(static, both_legs())
        clean = walk_model.kinetics(walk, walk_loads(walk), body_mass=70.0)
    forces = walk_loads(walk)
    swapped = walk.copy()
    rows = walk.index[50:60]
    swapped.loc[rows, "RTH1"] = walk.loc[rows, "RTH2"].to_numpy()
    swapped.loc[rows, "RTH2"] = walk.loc[rows, "RTH1"].to_numpy()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = walk_model.kinetics(swapped, forces, body_mass=70.0)
    said = [str(w.message) for w in caught if "taken as missing" in str(w.message)]
    assert len(said) == 1 and "RTHIGH (RTH1, RTH2, RTH3, RTH4) in 10 of" in said[0]
    right = result.xs("right", axis=1, level="side")
    assert right.iloc[50:60].isna().all().all()
    assert clean.xs("right", axis=1, level="side").iloc[40:70].notna().all().all()
    np.testing.assert_allclose(result.xs("left", axis=1, level="side"),
                               clean.xs("left", axis=1, level="side"), atol=1e-9)
    # a marker sliding 40 mm over the skin and back, slowly (half a second): the cluster
    # deforms (the tracking warns) but no frame is taken as missing
    drifted = walk.copy()
    drifted["RTH1"] = walk["RTH1"].to_numpy() + np.c_[
        40.0 * np.sin(np.pi * np.clip((walk.index - 0.3) / 0.5, 0, 1)), 0 * walk.index,
        0 * walk.index]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = walk_model.kinetics(drifted, forces, body_mass=70.0)
    messages = [str(w.message) for w in caught]
    assert any("RTHIGH" in m and "deforms in" in m for m in messages), messages
    assert not any("taken as missing" in m for m in messages)
    assert result.isna().sum().sum() == clean.isna().sum().sum()


def test_a_z_up_lab_gives_the_same_kinetics(model):
    """The trial and its loads turned 90 degrees about x (y up becomes z up): gravity
    follows the lab's vertical, the moments are in the segments' frames: nothing
    changes."""
    turn = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])             # y -> z
    trial = standing_trial()
    turned = trial.copy()
    for label in trial.columns.get_level_values(0).unique():
        turned[label] = trial[label].to_numpy() @ turn.T
    forces = loads(R_=((10, 350, 5), under("right", 50, 10), (0, 2, 0)),
                   L_=((-5, 300, 0), under("left", -20), (0, -1, 0)))
    rotated = forces.copy()
    for prefix in ("R_", "L_"):
        for kind in ("ground_force_v", "ground_force_p", "ground_torque_"):
            names = [f"{prefix}{kind}{axis}" for axis in "xyz"]
            rotated[names] = forces[names].to_numpy() @ turn.T
    expected = kinetics(model, trial, forces)
    result = kinetics(model, turned, rotated)
    assert np.abs(result.to_numpy() - expected.to_numpy()).max() < 1e-9
    assert result.attrs["gravity"] == pytest.approx([0, 0, -G])
    # gravity given per frame: the same numbers as one vector for every frame
    per_frame = kinetics(model, turned, rotated, gravity=np.tile([0, 0, -G], (len(trial), 1)))
    assert np.array_equal(per_frame.to_numpy(),
                          kinetics(model, turned, rotated, gravity=[0, 0, -G]).to_numpy(),
                          equal_nan=True)


def test_a_one_legged_model_gives_the_other_side_nan():
    markers = {role: label for role, label in MARKERS.items()
               if not role.startswith("L") or role in ("LASIS", "LPSIS")}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        right_only = calibrate_lower_limb(None, markers)
    result = kinetics(right_only, standing_trial(),
                      loads(R_=((0, 350, 0), under("right", 50), (0, 0, 0))))
    assert result["ankle", "right", "moment_x"].to_numpy() == pytest.approx(
        (350 * 0.05 - M_FOOT * G * FOOT_COM_DX) / BODY_MASS)
    assert result.loc[:, (slice(None), "left")].isna().all().all()


def test_a_missing_load_sample_is_nan_in_its_frames_only(model):
    forces = loads(R_=((0, 350, 0), under("right", 50), (0, 0, 0)),
                   L_=((0, 350, 0), under("left", 50), (0, 0, 0)))
    forces.loc[forces.index[100:104], "R_ground_force_px"] = np.nan     # 0.45-0.465 s
    result = kinetics(model, standing_trial(), forces, cutoff=None, force_cutoff=None)
    nan = result["ankle", "right", "moment_x"].isna()
    frames = nan.index[nan]                 # those interpolated from a missing sample
    assert {0.45, 0.46} <= set(frames) and set(frames) <= {0.44, 0.45, 0.46, 0.47}
    assert not result["ankle", "left"].isna().any().any()


def test_a_path_gives_the_same_as_its_dataframe(model, tmp_path):
    from bmc_functions import write_mot
    forces = loads(R_=((0, 350, 0), under("right", 50), (0, 0, 0)),
                   L_=((0, 350, 0), under("left", 50), (0, 0, 0)))
    write_mot(forces, tmp_path / "grf.mot", in_degrees=False)
    trial = standing_trial()
    pd.testing.assert_frame_equal(kinetics(model, trial, tmp_path / "grf.mot"),
                                  kinetics(model, trial, forces), check_like=True)


@pytest.mark.parametrize("forces, match", [
    ("grf.csv", r"forces must be an OpenSim external-loads .mot/.sto file or a DataFrame"),
    (3, r"forces must be an OpenSim external-loads .mot path or a DataFrame; got int"),
    (pd.DataFrame({"R_ground_force_vx": [0.0, 1.0]}, index=[0.0, 0.01]),
     r"forces: the load 'R_' lacks R_ground_force_vy"),
    (pd.DataFrame({"Fx": [0.0, 1.0]}, index=[0.0, 0.01]), r"forces has no ground_force_v"),
])
def test_bad_forces_are_refused(model, forces, match):
    with pytest.raises(ValueError, match=match):
        model.kinetics(standing_trial(), forces, body_mass=BODY_MASS)


@pytest.mark.parametrize("options, match", [
    ({"body_mass": 0}, r"body_mass must be a body mass in kg"),
    ({"body_mass": 70, "cutoff": -1}, r"cutoff must be a cut-off frequency in Hz"),
    ({"body_mass": 70, "parameters": {"thigh": {"mass": 2}}},
     r"parameters\['thigh'\]\['mass'\] must be a fraction"),
    ({"body_mass": 70, "gravity": np.zeros((7, 3))},
     r"gravity must have shape \(3,\) \(one for every frame\) or \(frames, 3\)"),
])
def test_bad_options_are_refused(model, options, match):
    forces = loads(R_=((0, 350, 0), under("right"), (0, 0, 0)))
    with pytest.raises(ValueError, match=match):
        model.kinetics(standing_trial(), forces, **options)


# --- the shared running trial against OpenSim's inverse dynamics -------------------------

RUN_MARKERS = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI"}
for _p in "RL":
    RUN_MARKERS.update({_p + "THIGH": [_p + "TH1", _p + "TH2", _p + "TH3"],
                        _p + "SHANK": [_p + "TB1", _p + "TB2", _p + "TB3"],
                        _p + "KNEE_LAT": _p + "LFC", _p + "KNEE_MED": _p + "MFC",
                        _p + "ANKLE_LAT": _p + "LMAL", _p + "ANKLE_MED": _p + "MMAL",
                        _p + "HEEL": _p + "CAL", _p + "TOE": _p + "TOE", _p + "MT5": _p + "MT5"})

#: OpenSim's generalized forces (Rajagopal model: hip flexion, knee flexion and ankle
#: dorsiflexion positive), negated to read as extensor / plantarflexor moments.
OPENSIM = {"hip": "hip_flexion_{}_moment", "knee": "knee_angle_{}_moment",
           "ankle": "ankle_angle_{}_moment"}


def unswapped_run():
    """motion_capture_run.trc with its known RTOE/RMT5 label swap undone (43 frames: the
    toe is the farther of the two from the heel), so that the right foot frame is right."""
    trc = read_trc(SHARED_DATA / "motion_capture_run.trc")
    heel, toe, mt5 = (trc[label].to_numpy() for label in ("RCAL", "RTOE", "RMT5"))
    swap = np.linalg.norm(toe - heel, axis=1) < np.linalg.norm(mt5 - heel, axis=1)
    assert swap.sum() == 43
    trc.loc[swap, "RTOE"], trc.loc[swap, "RMT5"] = mt5[swap], toe[swap]
    return trc


def against_opensim(kin):
    """(joint, side) -> (correlation, RMS in N m/kg, our peak, OpenSim's peak) in the
    stance of that side (vertical ground force above 20 N)."""
    grf = read_mot(SHARED_DATA / "grf_run.mot")
    reference = read_mot(SHARED_DATA / "id_output_run.sto")
    t = reference.index.to_numpy()
    ours_t = np.arange(len(kin)) / 150.0             # the TRC's times, unrounded
    result = {}
    for side, s in (("right", "r"), ("left", "l")):
        loaded = grf.index[grf[s.upper() + "_ground_force_vy"] > 20]
        stance = (t >= loaded.min()) & (t <= loaded.max())
        for joint, column in OPENSIM.items():
            theirs = -reference[column.format(s)].to_numpy()[stance] / 70.0
            ours = np.interp(t[stance], ours_t, kin[joint, side, "moment_x"].to_numpy())
            result[joint, side] = (np.corrcoef(ours, theirs)[0, 1],
                                   np.sqrt(np.mean((ours - theirs) ** 2)),
                                   np.abs(ours).max(), np.abs(theirs).max())
    return result


@pytest.fixture(scope="module")
def run_model():
    if not (SHARED_DATA / "static_run.trc").exists():
        pytest.skip("shared data absent")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return calibrate_lower_limb(SHARED_DATA / "static_run.trc", RUN_MARKERS)


#: Measured on this trial (correlation, RMS N m/kg; right, left) with OpenSim's own
#: processing (markers at 6 Hz, ground forces unfiltered): hip 0.973, 0.983 (0.30, 0.36);
#: knee 0.997, 0.995 (0.11, 0.18); ankle 1.000, 0.998 (0.19, 0.19). The thresholds sit
#: just below. The RMS is model difference (OpenSim's scaled joints and segments, its hip
#: moment about the pelvis' flexion axis, ours about the thigh's), not noise.
OPENSIM_PROCESSING = {"hip": (0.96, 0.40), "knee": (0.99, 0.25), "ankle": (0.99, 0.25)}
#: With the default, markers and forces both at 10 Hz: hip 0.863, 0.826 (0.42, 0.52);
#: knee 0.991, 0.987 (0.14, 0.23); ankle 0.999, 0.995 (0.19, 0.20): OpenSim's hip has an
#: impact peak (about 1.5 N m/kg at 0.08 s) that appears only when the forces are filtered
#: higher than the markers (Kristianslund et al. 2012), and the default does not make it.
SAME_CUTOFF = {"hip": (0.80, 0.55), "knee": (0.98, 0.25), "ankle": (0.99, 0.25)}


@needs_shared("static_run.trc", "motion_capture_run.trc", "grf_run.mot", "id_output_run.sto")
@pytest.mark.parametrize("options, thresholds", [
    ({"cutoff": 6.0, "force_cutoff": None}, OPENSIM_PROCESSING),
    ({}, SAME_CUTOFF),
])
def test_running_trial_against_opensims_inverse_dynamics(run_model, options, thresholds):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        kin = run_model.kinetics(unswapped_run(), SHARED_DATA / "grf_run.mot",
                                 body_mass=70.0, **options)
    # the right foot lands again at the end, off the force plates: NaN, said once
    stances = [str(w.message) for w in caught if "no ground load" in str(w.message)]
    assert len(stances) == 1 and "right 0.727-0.813 s" in stances[0]
    assert kin.loc[0.74:, ("ankle", "right", "moment_x")].isna().all()
    sides = [(a["load"], a["side"]) for a in kin.attrs["load_assignment"]]
    assert sides == [("R_", "right"), ("L_", "left")]
    for (joint, side), (r, rms, ours, theirs) in against_opensim(kin).items():
        r_min, rms_max = thresholds[joint]
        assert r > r_min and rms < rms_max, (joint, side, r, rms)
        if joint != "hip":                            # peaks within 25 %
            assert abs(ours - theirs) < 0.25 * theirs, (joint, side, ours, theirs)


@needs_shared("static_run.trc", "motion_capture_run.trc", "grf_run.mot")
def test_the_runs_swapped_toe_labels_give_no_right_leg_kinetics(run_model):
    """motion_capture_run.trc as recorded: RTOE and RMT5 swapped in 43 of its 123 frames
    (every third one). The right foot's markers deform there by a jump of the RMSE (a
    soft tissue's slow deformation is not taken for it); they are taken as missing, and with a gap every third frame nothing of the right leg
    can be differentiated: all of it NaN (it held a -5.4 N m/kg ankle spike at 0.18 s).
    The left leg uses none of them: the same as with the swap undone."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        raw = run_model.kinetics(SHARED_DATA / "motion_capture_run.trc",
                                 SHARED_DATA / "grf_run.mot", body_mass=70.0)
    messages = [str(w.message) for w in caught]
    deform = [m for m in messages if "RFOOT" in m]
    assert len(deform) == 1 and "RFOOT (RCAL, RTOE, RMT5) in 43 of 123 frames are taken " \
        "as missing" in deform[0] and "by a jump" in deform[0], deform
    assert not any("rotate by more than" in m for m in messages)
    assert raw.xs("right", axis=1, level="side").isna().all().all()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fixed = run_model.kinetics(unswapped_run(), SHARED_DATA / "grf_run.mot",
                                   body_mass=70.0)
    left = raw.xs("left", axis=1, level="side")
    assert left.notna().to_numpy().mean() > 0.9
    np.testing.assert_allclose(left, fixed.xs("left", axis=1, level="side"), atol=1e-9)


def knee_peaks(kin):
    """Peak knee extensor moment (N m/kg) of each stance of the run, and the vertical
    ground force (N) at that instant."""
    grf = read_mot(SHARED_DATA / "grf_run.mot")
    peaks = {}
    for side in ("right", "left"):
        loaded = grf.index[grf[side[0].upper() + "_ground_force_vy"] > 20]
        stance = kin.loc[loaded.min():loaded.max(), ("knee", side, "moment_x")]
        force = np.interp(stance.idxmax(), grf.index, grf[side[0].upper() + "_ground_force_vy"])
        peaks[side] = (stance.max(), force)
    return peaks


@needs_shared("static_run.trc", "motion_capture_run.trc", "grf_run.mot")
def test_sensitivity_of_the_peak_knee_moment(run_model):
    """Kristianslund et al. (2012), measured on the run (default filtering, 10 Hz): moving
    the centre of pressure 1 cm forwards lowers the peak knee extensor moment by about
    F_vertical * 0.01 m (-0.23, -0.22 N m/kg); moving the knee centre 1 cm forwards (its
    epicondyles in the static trial) raises it by about as much (+0.20, +0.19); forces
    filtered at 50 Hz against markers at 6 Hz raise the hip's impact peak (first 60 ms of
    stance) by 0.16 and 0.46 N m/kg over both at 6 Hz."""
    trial = unswapped_run()
    grf = read_mot(SHARED_DATA / "grf_run.mot")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        base = knee_peaks(run_model.kinetics(trial, grf, body_mass=70.0))
        moved = grf.copy()
        moved[["R_ground_force_px", "L_ground_force_px"]] += 0.01     # x: forwards
        cop = knee_peaks(run_model.kinetics(trial, moved, body_mass=70.0))
        static = read_trc(SHARED_DATA / "static_run.trc")
        R, _ = pelvis_frame(*(static[label].to_numpy().mean(axis=0)
                              for label in ("RASI", "LASI", "RPSI", "LPSI")))
        for label in ("RLFC", "RMFC", "LLFC", "LMFC"):     # 10 mm along the pelvis' x
            static[label] = static[label].to_numpy() + 10.0 * R[:, 0]
        knee = knee_peaks(calibrate_lower_limb(static, RUN_MARKERS).kinetics(
            trial, grf, body_mass=70.0))
        impact = {cut: run_model.kinetics(trial, grf, body_mass=70.0, cutoff=6.0,
                                          force_cutoff=cut) for cut in (6.0, 50.0)}
    for side in ("right", "left"):
        lever = base[side][1] * 0.01 / 70.0                 # N m/kg per cm
        assert cop[side][0] - base[side][0] == pytest.approx(-lever, rel=0.15), side
        assert knee[side][0] - base[side][0] == pytest.approx(lever, rel=0.25), side
        start = grf.index[grf[side[0].upper() + "_ground_force_vy"] > 20].min()
        early = {cut: kin.loc[start:start + 0.06, ("hip", side, "moment_x")].max()
                 for cut, kin in impact.items()}
        assert early[50.0] - early[6.0] > 0.1, (side, early)


def test_c3d_plates_become_one_load_per_plate_about_the_same_origin():
    """A C3D path's plates (read_force_plates) as an external-loads table: where the
    centre of pressure is defined, point and torque are the centre of pressure and the
    free moment; elsewhere the plate's centre and the moment about it. Either way the
    moment about the lab's origin is the plate's own, q x F + T = c x F + M_c."""
    import numpy as np
    from bmc_functions import read_force_plates
    from bmc_functions.examples import example_file
    from bmc_functions.models.lower_limb_kinetics import _read_forces, plate_loads_table

    path = example_file("plug_in_gait/Movement_trial.c3d")
    plates = read_force_plates(path)
    table = _read_forces(path)
    pd.testing.assert_frame_equal(table, plate_loads_table(plates))
    assert len(table) == len(plates)
    for number, setup in zip(plates.columns.unique(0), plates.attrs["plates"]):
        force = table[[f"{number}_ground_force_v{a}" for a in "xyz"]].to_numpy()
        point = table[[f"{number}_ground_force_p{a}" for a in "xyz"]].to_numpy() * 1000
        torque = table[[f"{number}_ground_torque_{a}" for a in "xyz"]].to_numpy() * 1000
        centre = np.asarray(setup["corners"]).mean(axis=0)
        expected = np.cross(centre, force) + plates[number][
            [f"moment_{a}" for a in "xyz"]].to_numpy()
        np.testing.assert_allclose(np.cross(point, force) + torque, expected,
                                   atol=1e-6 * np.abs(expected).max())
        loaded = plates[number]["force_z"].abs() > 100
        np.testing.assert_allclose(point[loaded], plates[number][["cop_x", "cop_y", "cop_z"]]
                                   .to_numpy()[loaded])
        assert np.isfinite(table.to_numpy()).all()
    cut = plates.drop(columns=[(2, "free_moment_z")])
    cut.attrs = plates.attrs
    with pytest.raises(ValueError, match=r"plate 2 of attrs\['plates'\] has no column "
                                         r"\(2, 'free_moment_z'\)"):
        plate_loads_table(cut)
    with pytest.raises(TypeError, match="plates must be the DataFrame read_force_plates"):
        plate_loads_table(pd.DataFrame(plates.to_numpy()))


def _walk_variants():
    """The shipped walk (two occlusion gaps) and copies with frames the tracking flags:
    a lab axis reversed in some frames (mirrored), the right thigh cluster moved to the
    left of the left one (crossed legs), a cluster marker missing."""
    walk = read_trc(ROOT / "data" / "markers" / "walk.trc")
    mirrored = walk.copy()
    mirrored.iloc[30:45, 2::3] *= -1                        # z of every marker
    crossed = walk.copy()
    shift = (crossed["LTH1"].to_numpy() - crossed["RTH1"].to_numpy())[40:60] * 1.6
    for label in ("RTH1", "RTH2", "RTH3", "RTH4"):
        crossed.loc[crossed.index[40:60], label] = crossed[label].to_numpy()[40:60] + shift
    lost = walk.copy()
    lost.loc[lost.index[10:20], ["LTB1", "LTB2"]] = np.nan
    return {"walk": walk, "mirrored": mirrored, "crossed": crossed, "lost": lost}


@pytest.mark.parametrize("variant", ["walk", "mirrored", "crossed", "lost"])
@pytest.mark.parametrize("options", [{}, {"static_offset": True}, {"without": "LMT5"},
                                     {"without": "LTOE"}])
def test_the_kinetics_rejects_the_frames_whose_angles_are_nan(variant, options):
    """The kinetics skips the angles and finds where they would be NaN from the segment
    frames and the tracking's flags (model._angle_gaps): the same frames as the angles'
    NaN, column by column (gaps, mirrored and crossed frames, a static offset, a side
    without MT5 (no inversion) or without a foot frame)."""
    static = read_trc(ROOT / "data" / "markers" / "static.trc")
    roles = two_leg_markers()
    without = options.get("without")
    if without:
        roles = {role: label for role, label in roles.items() if label != without}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = calibrate_lower_limb(static, roles,
                                     static_offset=options.get("static_offset", False))
        trial = _walk_variants()[variant]
        angles = model.angles(trial)
        poses = model._poses(trial, "the trial")
    gaps = model._angle_gaps(poses, list(angles.columns))
    expected = angles.isna().to_numpy()
    assert expected.any() and not expected.all()
    np.testing.assert_array_equal(gaps, expected)


@needs_shared("static_run.trc", "motion_capture_run.trc")
@pytest.mark.parametrize("trial", ["generated", "run"])
def test_the_unfiltered_markers_are_fitted_only_where_a_cluster_may_deform(trial):
    """The kinetics fits the unfiltered markers (svdt) only in the frames where the fit
    of the filtered ones does not already bound the RMSE below the threshold (and next
    to them): everywhere else the RMSE of a full fit is below it, and in those frames the
    fit is the full one. On a generated walk whose thigh clusters deform slowly beyond
    the threshold, and on the run whose RTOE and RMT5 are swapped every third frame."""
    from bmc_functions.files.trial import MarkerTable, mm_per_unit
    from bmc_functions.models.lower_limb_checks import deforming_frames
    from bmc_functions.models.lower_limb_kinetics import (_candidates, _filtered_markers,
                                                          _poses, _raw_rmse)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if trial == "generated":
            import sys
            sys.path.insert(0, str(ROOT / "benchmarks"))
            import bench_lower_limb as bench
            gen = bench.load_generator("generate_marker_data")
            df = bench.long_trial(gen, 3000)
            model = calibrate_lower_limb(read_trc(ROOT / "data" / "markers" / "static.trc"),
                                         bench.markers_of_the_synthetic_subject())
        else:
            df = read_trc(SHARED_DATA / "motion_capture_run.trc")
            model = calibrate_lower_limb(SHARED_DATA / "static_run.trc", RUN_MARKERS)
        filtered = _filtered_markers(df, 10.0)
        kin = _poses(model, filtered)
        raw, scale = MarkerTable(df), mm_per_unit(df, "the trial")[0]
        candidates = _candidates(model, raw, MarkerTable(filtered), scale, kin)
        full = _raw_rmse(model, raw, scale)
        some = _raw_rmse(model, raw, scale, candidates)
    assert candidates                             # the test reaches the fits it checks
    for cluster, (high, threshold) in deforming_frames(model, full).items():
        frames = candidates.get(cluster, np.zeros(len(df), bool))
        assert not (high & ~frames).any(), cluster           # nothing high is left out
        if cluster != "RFOOT" or trial == "generated":   # the run's swapped foot: all
            assert frames.mean() < 0.5, (cluster, frames.mean())  # most is left out
        if frames.any():
            np.testing.assert_allclose(some[cluster][frames], full[cluster][frames],
                                       rtol=1e-12, atol=1e-12)


def test_the_span_mask_is_every_sample_within_a_span():
    """_span_mask merges the spans (any order, overlapping, touching, of one sample,
    beyond the record) before marking them: each sample whose time is in some
    [start, end], as a direct comparison with every span says."""
    from bmc_functions.models.lower_limb_kinetics import _span_mask
    rng = np.random.default_rng(29)
    for _ in range(300):
        time = np.arange(rng.integers(2, 60)) * 0.001
        starts = rng.choice(time, rng.integers(1, 8)) + rng.choice([0, 0.0004, -0.5], 1)
        ends = starts + rng.integers(0, 15, starts.size) * 0.001
        expected = ((time[:, None] >= starts) & (time[:, None] <= ends)).any(axis=1)
        assert np.array_equal(_span_mask(time, starts, ends), expected), (starts, ends)


def test_span_medians_are_numpys_nanmedian_of_each_span():
    """_span_medians (one sort for every span at once) gives numpy.nanmedian of each
    span to the last bit: odd and even counts, NaN inside, a span of NaN only (NaN),
    spans long enough for nanmedian's other algorithm (600 values or more)."""
    from bmc_functions.models.lower_limb_kinetics import _span_medians
    rng = np.random.default_rng(7)
    for size in (40, 2000):
        values = np.round(rng.normal(size=size) * 100, rng.integers(0, 3))
        values[rng.random(size) < 0.2] = np.nan
        values[5:9] = np.nan
        starts = np.r_[5, rng.integers(0, size - 1, 30)]
        spans = np.c_[starts, np.r_[9, starts[1:] + rng.integers(1, size, 30)]]
        spans[:, 1] = np.minimum(spans[:, 1], size)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            expected = [np.nanmedian(values[a:b]) for a, b in spans]
        got = _span_medians(values, spans)
        assert np.isnan(got[0])
        assert np.array_equal(got, expected, equal_nan=True)


def test_the_resampler_is_numpys_interp_and_the_distance_a_hand_derived_one():
    """_resampler (one gather for every column, the formula in place) gives numpy.interp
    of each scaled column to the last bit, NaN outside the record; _distance_to_segment
    the distance to the nearer end beyond the segment, the perpendicular one beside it."""
    from bmc_functions.models.lower_limb_kinetics import _distance_to_segment, _resampler
    rng = np.random.default_rng(3)
    time = np.arange(1000) * 0.001 + 0.3
    times = np.r_[0.2, np.arange(90) * 0.0113 + 0.3, time[-1], 1.4]
    values = rng.normal(size=(1000, 3)) * 100
    values[500] = np.nan
    expected = np.stack([np.interp(times, time, values[:, k] * 1000.0, left=np.nan,
                                   right=np.nan) for k in range(3)], axis=1)
    assert np.array_equal(_resampler(time, times)(values, 1000.0), expected, equal_nan=True)
    a, b = np.zeros((4, 2)), np.tile([10.0, 0.0], (4, 1))
    point = np.array([[-3.0, 4.0], [5.0, -2.0], [16.0, 8.0], [np.nan, 0.0]])
    np.testing.assert_array_equal(_distance_to_segment(point, a, b), [5.0, 2.0, 10.0, np.nan])


def test_runs_mask_is_every_index_within_a_run():
    """runs_mask (shared by the loads' spans, the sudden deformations and Plug-in Gait's
    contacts) merges the runs before marking them: any order, overlapping, touching,
    empty and reversed runs (empty), none at all; as a direct comparison says."""
    from bmc_functions._checks import runs_mask
    rng = np.random.default_rng(40)
    for _ in range(300):
        length = int(rng.integers(0, 40))
        count = int(rng.integers(0, 8))
        first = rng.integers(0, length + 1, count)
        stop = rng.integers(0, length + 1, count)
        index = np.arange(length)[:, None]
        expected = ((index >= first) & (index < stop)).any(axis=1)
        assert np.array_equal(runs_mask(length, first, stop), expected), (first, stop)


@pytest.mark.parametrize("scale", [1.0, 10.0])
@pytest.mark.parametrize("row_major", [False, True])
def test_the_candidate_frames_are_stacked_as_stacked_then_selected(scale, row_major):
    """_stacked_rows (only the coordinates of the candidate frames read) gives
    MarkerTable.stacked(...)[rows]: its values, NaN included, and its memory layout (which
    sets the order of svdt's sums), for a column-major table (read_trc's) and a row-major
    one, some frames, one frame or all of them."""
    from bmc_functions.files.trial import MarkerTable
    from bmc_functions.models.lower_limb_kinetics import _stacked_rows
    df = read_trc(ROOT / "data" / "markers" / "walk.trc")
    df.loc[df.index[20:24], "RTH1"] = np.nan
    table = MarkerTable(df)
    if row_major:
        table.values = np.ascontiguousarray(table.values)
    rng = np.random.default_rng(11)
    labels = ["RTH3", "LTOE", "RTH1", "RTH2"]
    for rows in (rng.random(len(df)) < 0.3, np.arange(len(df)) == 22,
                 np.ones(len(df), bool)):
        expected = table.stacked(labels, scale)[rows]
        got = _stacked_rows(table, labels, scale, rows)
        assert np.array_equal(got, expected, equal_nan=True)
        assert got.shape == expected.shape and got.strides == expected.strides


def test_a_load_is_on_where_nan_to_num_of_its_vertical_force_exceeds_the_threshold():
    """_loaded (the comparison alone) is numpy.nan_to_num(vertical) > threshold: a NaN
    sample counts as 0 (on only below a negative threshold), infinities as the largest
    floats of their sign."""
    from bmc_functions.models.lower_limb_kinetics import _loaded
    rng = np.random.default_rng(5)
    vertical = rng.normal(size=500) * 40
    vertical[rng.random(500) < 0.1] = np.nan
    vertical[[3, 7]] = np.inf, -np.inf
    for threshold in (20.0, 0.0, -5.0, -np.finfo(float).max / 2):
        with warnings.catch_warnings():
            warnings.simplefilter("error")                     # nothing to say
            got = _loaded(vertical, threshold)
        assert np.array_equal(got, np.nan_to_num(vertical) > threshold), threshold


def test_the_resampler_at_scale_one_is_numpys_interp():
    """_resampler without a scale (the multiplication by 1.0 skipped) gives numpy.interp
    of each column to the last bit, NaN included."""
    from bmc_functions.models.lower_limb_kinetics import _resampler
    rng = np.random.default_rng(4)
    time = np.arange(1000) * 0.001 + 0.3
    times = np.r_[0.2, np.arange(90) * 0.0113 + 0.3, time[-1], 1.4]
    values = rng.normal(size=(1000, 3)) * 100
    values[500, 1] = np.nan
    expected = np.stack([np.interp(times, time, values[:, k], left=np.nan, right=np.nan)
                         for k in range(3)], axis=1)
    assert np.array_equal(_resampler(time, times)(values), expected, equal_nan=True)


def test_the_assigned_wrenches_are_added_block_by_block_as_at_once(monkeypatch):
    """_assigned_wrenches (a block of samples at a time) gives each side's sum, in
    order, of the forces and moments about the origin (q x F + T) of the loads assigned
    to it, in their spans only, zero elsewhere: as the whole record at once says, to the
    last bit (NaN centres of pressure, spans across blocks, a load on both sides)."""
    from bmc_functions.models import lower_limb_kinetics as kinetics
    monkeypatch.setattr(kinetics, "_WRENCH_BLOCK", 7)
    rng = np.random.default_rng(8)
    time = np.arange(50) * 0.001
    loads = {p: [rng.normal(size=(50, 3)) * s for s in (300.0, 0.5, 2.0)] for p in "AB"}
    loads["A"][1][[3, 20]] = np.nan
    assignment = [{"load": "A", "start": 0.002, "end": 0.030, "side": "right"},
                  {"load": "A", "start": 0.035, "end": 0.049, "side": "left"},
                  {"load": "B", "start": 0.010, "end": 0.040, "side": "right"},
                  {"load": "B", "start": 0.041, "end": 0.045, "side": None}]
    expected = np.zeros((12, 50))
    for item in assignment:
        if item["side"] is None:
            continue
        force, cop, free = loads[item["load"]]
        moment = [cop[:, i] * force[:, j] - cop[:, j] * force[:, i] + free[:, m]
                  for m, (i, j) in enumerate(((1, 2), (2, 0), (0, 1)))]
        inside = (time >= item["start"]) & (time <= item["end"])
        rows = slice(0, 6) if item["side"] == "right" else slice(6, 12)
        expected[rows] = np.where(inside, expected[rows] + np.r_[force.T, moment],
                                  expected[rows])
    got = kinetics._assigned_wrenches(loads, assignment, time, ["right", "left"])
    assert np.array_equal(got, expected, equal_nan=True)
