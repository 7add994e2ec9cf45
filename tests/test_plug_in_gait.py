"""plug_in_gait (Vicon Plug-in Gait / CGM lower body), its steps and readers.

Oracles: Vicon Nexus 2.6's own output stored in the shared Plug-in Gait trial (angles,
virtual points, PROCESSING parameters), ezc3d for the C3D parameters, the seeded
generator data/generate_plug_in_gait_data.py for known angles, and hand-derived values.
"""

import re
import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import (plug_in_gait, read_c3d, read_c3d_model_outputs,
                           read_c3d_parameters, read_vsk)
from bmc_functions.files.c3d_parameters import subject_parameters
from bmc_functions.models.plug_in_gait import (
    VICON_OUTPUTS, asis_trochanter_distance, cgm_angles, cgm_foot_frame, cgm_tibia_frame,
    chord_joint_centre, davis_hip_centre, load_subject, progression_frame,
    static_foot_offsets)
from bmc_functions.rigid_body.rotations import rot_x, rot_y, rot_z

from helpers import ROOT, SHARED_DATA, load_data_script

ezc3d = pytest.importorskip("ezc3d")

# The repository copy (MIT, data/real/plug_in_gait/LICENSE) first, else ../shared.
FOLDER = next((folder for folder in (ROOT / "data" / "real" / "plug_in_gait",
                                     SHARED_DATA / "plug_in_gait")
               if (folder / "Movement_trial.c3d").exists()), None)
needs_data = pytest.mark.skipif(FOLDER is None, reason="Plug-in Gait trial absent")
GEN = load_data_script("generate_plug_in_gait_data")

RMS_LIMIT = 0.1     # degrees, per curve (the criterion)
CENTRE_LIMIT = 0.5  # mm


def _side_prefix(side):
    return "L" if side == "left" else "R"


def rms_per_curve(angles, vicon):
    """(joint, side, angle) -> RMS difference (degrees) from Vicon's stored curve."""
    out = {}
    for joint, side, name in angles.columns:
        label, component = VICON_OUTPUTS[(joint, name)]
        reference = vicon[_side_prefix(side) + label].iloc[:, component].to_numpy()
        difference = angles[joint, side, name].to_numpy() - reference
        out[(joint, side, name)] = float(np.sqrt(np.nanmean(difference ** 2)))
    return out


@pytest.fixture(scope="module")
def vicon():
    if FOLDER is None:
        pytest.skip("Plug-in Gait trial absent")
    return {"dynamic": read_c3d_model_outputs(FOLDER / "Movement_trial.c3d"),
            "static": read_c3d_model_outputs(FOLDER / "Static_trial.c3d"),
            "dynamic_points": read_c3d(FOLDER / "Movement_trial.c3d"),
            "static_points": read_c3d(FOLDER / "Static_trial.c3d")}


def subject_as(source):
    if source == "vsk":
        return FOLDER / "Test.vsk"
    if source == "c3d":
        return FOLDER / "Movement_trial.c3d"
    subject = read_vsk(FOLDER / "Test.vsk")  # as a dict, Vicon's names
    return {name: value for name, value in subject.items() if name != "__model__"}


# --- against Vicon's own output --------------------------------------------------------

@needs_data
@pytest.mark.parametrize("with_static", [True, False])
@pytest.mark.parametrize("source", ["vsk", "c3d", "dict"])
def test_every_curve_matches_vicon(vicon, with_static, source):
    static = FOLDER / "Static_trial.c3d" if with_static else None
    model = plug_in_gait(static, subject_as(source))
    angles = model.angles(FOLDER / "Movement_trial.c3d")
    assert angles.shape == (323, 64)
    rms = rms_per_curve(angles, vicon["dynamic"])
    assert len(rms) == 64  # 13 lower-body and 19 upper-body curves per side
    worst = max(rms, key=rms.get)
    assert rms[worst] <= RMS_LIMIT, (worst, rms[worst])
    # what this implementation actually achieves (float32 storage in the C3D)
    assert rms[worst] < 1e-4, (worst, rms[worst])


@needs_data
def test_joint_centres_match_vicon_virtual_points(vicon):
    model = plug_in_gait(FOLDER / "Static_trial.c3d", FOLDER / "Test.vsk")
    for trial, points in (("Movement_trial.c3d", "dynamic_points"),
                          ("Static_trial.c3d", "static_points")):
        track = model.track(FOLDER / trial)
        stored = vicon[points]
        # Vicon: LFEO = knee centre, LTIO = ankle centre, LFEP = hip centre (the femur's
        # proximal end), PELO = midpoint of the hip centres
        for mine, theirs in (("LKJC", "LFEO"), ("RKJC", "RFEO"), ("LAJC", "LTIO"),
                             ("RAJC", "RTIO"), ("LHJC", "LFEP"), ("RHJC", "RFEP"),
                             ("PELO", "PELO")):
            distance = np.linalg.norm(track.centres[mine].to_numpy()
                                      - stored[theirs].to_numpy(), axis=1)
            assert distance.max() < CENTRE_LIMIT, (trial, mine, distance.max())
            assert distance.max() < 1e-3, (trial, mine, distance.max())


@needs_data
def test_segment_axes_match_vicon_virtual_points(vicon):
    model = plug_in_gait(FOLDER / "Static_trial.c3d", FOLDER / "Test.vsk")
    track = model.track(FOLDER / "Movement_trial.c3d")
    stored = vicon["dynamic_points"]
    for segment, side, name in (("pelvis", None, "PEL"), ("femur", "left", "LFE"),
                                ("femur", "right", "RFE"), ("tibia", "left", "LTI"),
                                ("tibia", "right", "RTI"), ("foot", "left", "LFO"),
                                ("foot", "right", "RFO")):
        origin = stored[name + "O"].to_numpy()
        axes = [stored[name + k].to_numpy() - origin for k in "ALP"]
        vicon_R = np.stack([a / np.linalg.norm(a, axis=1, keepdims=True) for a in axes], -1)
        R = track.frames[(segment, side)][0]
        assert np.abs(R - vicon_R).max() < 1e-5, segment


@needs_data
def test_static_offsets_match_nexus():
    model = plug_in_gait(FOLDER / "Static_trial.c3d", FOLDER / "Test.vsk")
    nexus = read_vsk(FOLDER / "Test.vsk")
    for name, value in model.static_offsets.items():
        assert abs(np.degrees(value - nexus[name])) < 0.01, name
        assert abs(np.degrees(value - nexus[name])) < 1e-4, name
    assert set(model.static_offsets) == {"LeftStaticPlantFlex", "LeftStaticRotOff",
                                         "RightStaticPlantFlex", "RightStaticRotOff"}


@needs_data
def test_static_trial_pelvis_hip_knee_match_vicon(vicon):
    model = plug_in_gait(FOLDER / "Static_trial.c3d", FOLDER / "Test.vsk")
    angles = model.angles(FOLDER / "Static_trial.c3d")
    rms = rms_per_curve(angles, vicon["static"])
    for key, value in rms.items():
        if key[0] in ("pelvis", "hip", "knee"):
            assert value < 1e-4, (key, value)


@needs_data
def test_static_trial_foot_is_the_heel_toe_foot(vicon):
    """In its static trial Nexus reports the foot whose long axis is HEE-TOE."""
    model = plug_in_gait(FOLDER / "Static_trial.c3d", FOLDER / "Test.vsk")
    dynamic_foot = rms_per_curve(model.angles(FOLDER / "Static_trial.c3d"), vicon["static"])
    static_foot = rms_per_curve(model.angles(FOLDER / "Static_trial.c3d", foot="static"),
                                vicon["static"])
    assert max(static_foot.values()) < 1e-4
    # with the dynamic foot the inversion differs by the foot's roll in the static posture
    assert dynamic_foot[("ankle", "left", "inversion")] > 1.0


@needs_data
def test_attrs_record_the_model_and_every_measurement():
    model = plug_in_gait(FOLDER / "Static_trial.c3d", FOLDER / "Test.vsk")
    angles = model.angles(FOLDER / "Movement_trial.c3d")
    attrs = angles.attrs
    assert "Plug-in Gait" in attrs["model"]
    assert attrs["measurements"]["LeftKneeWidth"] == 144.0
    assert attrs["marker_diameter_mm"] == 14.0
    assert attrs["derived"]["MarkerDiameter"] == 14.0      # the default, stated
    assert "LeftStaticPlantFlex" in attrs["derived"]        # from the static trial
    assert attrs["measurements"]["LeftAsisTrocanterDistance"] == pytest.approx(64.3976, 1e-6)


# --- the readers -------------------------------------------------------------------------

@needs_data
def test_read_c3d_parameters_agrees_with_ezc3d():
    path = FOLDER / "Movement_trial.c3d"
    ours = read_c3d_parameters(path)
    theirs = ezc3d.c3d(str(path))["parameters"]
    assert ours["POINT"]["LABELS"] == [str(x).rstrip() for x in theirs["POINT"]["LABELS"]["value"]]
    for name, entry in theirs["PROCESSING"].items():
        if isinstance(entry, dict) and "value" in entry and entry["type"] == 4:
            assert ours["PROCESSING"][name.upper()] == pytest.approx(float(entry["value"][0]))
    assert ours["POINT"]["RATE"] == 120.0
    assert ours["POINT"]["UNITS"] == "mm"


@needs_data
def test_read_c3d_parameters_arrays_read_row_by_row():
    path = FOLDER / "Movement_trial.c3d"
    ours = read_c3d_parameters(path)["FORCE_PLATFORM"]["CORNERS"]
    theirs = np.asarray(ezc3d.c3d(str(path))["parameters"]["FORCE_PLATFORM"]["CORNERS"]["value"])
    assert ours.shape == (4, 4, 3)          # plate, corner, coordinate
    np.testing.assert_allclose(ours, theirs.transpose(2, 1, 0))


@needs_data
def test_read_c3d_model_outputs_agrees_with_ezc3d():
    path = FOLDER / "Movement_trial.c3d"
    out = read_c3d_model_outputs(path)
    c3d = ezc3d.c3d(str(path))
    labels = [str(x).strip() for x in c3d["parameters"]["POINT"]["LABELS"]["value"]]
    k = labels.index("RKneeAngles")
    np.testing.assert_allclose(out["RKneeAngles"].to_numpy(),
                               c3d["data"]["points"][:3, k, :].T)
    assert out.attrs["groups"]["RKneeAngles"] == "ANGLES"
    assert out.attrs["units"]["ANGLES"] == "deg"
    assert "LFEO" not in out.columns.get_level_values(0)     # virtual points are markers
    assert "RKneeAngles" in read_c3d(path).attrs["dropped_labels"]


@needs_data
def test_subject_from_c3d_uses_vicon_names():
    subject = subject_parameters(FOLDER / "Movement_trial.c3d")
    assert subject["LLegLength"] == 877.0 and subject["InterAsisDistance"] == 306.0
    same, _ = load_subject(FOLDER / "Movement_trial.c3d")
    assert same["LeftLegLength"] == 877.0


def test_read_c3d_parameters_refuses_a_file_that_is_not_c3d(tmp_path):
    path = tmp_path / "not.c3d"
    path.write_bytes(b"\x02\x00" + b"x" * 600)
    with pytest.raises(ValueError, match="not a readable C3D file"):
        read_c3d_parameters(path)


@needs_data
def test_read_c3d_parameters_refuses_a_cut_parameter_section(tmp_path):
    data = (FOLDER / "Static_trial.c3d").read_bytes()
    path = tmp_path / "cut.c3d"
    path.write_bytes(data[:700])
    with pytest.raises(ValueError, match="not a readable C3D file"):
        read_c3d_parameters(path)


@needs_data
def test_subject_from_a_c3d_without_processing_is_refused(tmp_path):
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [100]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = ["A"]
    c3d["data"]["points"] = np.ones((4, 1, 3))
    path = tmp_path / "plain.c3d"
    c3d.write(str(path))
    with pytest.raises(ValueError, match="no PROCESSING parameter group"):
        plug_in_gait(None, path)


@pytest.mark.parametrize("text, message", [
    ("<KinematicModel", "the XML is broken"),
    ("<Skeleton></Skeleton>", "expected <KinematicModel>"),
    ("<KinematicModel></KinematicModel>", "no <Parameters>"),
    ('<KinematicModel><Parameters><StaticParameter NAME="LeftLegLength" VALUE="abc"/>'
     '</Parameters></KinematicModel>', "is not a number"),
    ('<KinematicModel><Parameters><StaticParameter NAME="LeftLegLength" VALUE="900"/>'
     '<Parameter NAME="LeftLegLength" VALUE="901"/></Parameters></KinematicModel>',
     "appears twice"),
])
def test_read_vsk_refuses_broken_files(tmp_path, text, message):
    path = tmp_path / "subject.vsk"
    path.write_text(text)
    with pytest.raises(ValueError, match=re.escape(message)):
        read_vsk(path)


def test_read_vsk_leaves_out_parameters_without_value(tmp_path):
    path = tmp_path / "subject.vsk"
    path.write_text('<KinematicModel MODEL="PlugInGait Lower Body Ai"><Parameters>'
                    '<StaticParameter NAME="LeftTibialTorsion" PRIOR="0"/>'
                    '<StaticParameter NAME="LeftLegLength" VALUE="900"/>'
                    '</Parameters></KinematicModel>')
    assert read_vsk(path) == {"LeftLegLength": 900.0,
                              "__model__": "PlugInGait Lower Body Ai"}


# --- the model's steps -------------------------------------------------------------------

def test_chord_joint_centre_meets_its_three_conditions():
    rng = np.random.default_rng(3)
    proximal = rng.normal(0, 50, (200, 3)) + [0, 0, 800]
    marker = rng.normal(0, 50, (200, 3)) + [60, 0, 400]
    wand = marker + rng.normal(0, 40, (200, 3)) + [40, 0, 150]
    delta = 62.0
    J = chord_joint_centre(wand, proximal, marker, delta)
    np.testing.assert_allclose(np.linalg.norm(J - marker, axis=1), delta, rtol=1e-12)
    dots = np.sum((marker - J) * (proximal - J), axis=1)
    np.testing.assert_allclose(dots, 0.0, atol=1e-8)
    normal = np.cross(wand - marker, proximal - marker)
    np.testing.assert_allclose(np.sum(normal * (J - marker), axis=1), 0.0, atol=1e-6)
    # J is on the other side of the line proximal->marker than the wand
    axis = np.cross(marker - proximal, normal)
    assert (np.sign(np.sum(axis * (J - proximal), axis=1))
            != np.sign(np.sum(axis * (wand - proximal), axis=1))).all()


def test_chord_joint_centre_without_solution_is_nan():
    J = chord_joint_centre([100, 0, 300], [0, 0, 50], [30, 0, 0], 60.0)
    assert np.isnan(J).all()


def test_davis_hip_centre_by_hand():
    C = 0.115 * 900.0 - 15.3
    x = C * np.cos(0.5) * np.sin(0.314) - (70.0 + 7.0) * np.cos(0.314)
    y = 125.0 - C * np.sin(0.5)
    z = -C * np.cos(0.5) * np.cos(0.314) - (70.0 + 7.0) * np.sin(0.314)
    R = rot_z(0.3)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        hjc = davis_hip_centre(R, [1.0, 2.0, 3.0], mean_leg_length=900.0,
                               asis_trochanter=70.0, inter_asis_distance=250.0,
                               marker_radius=7.0, side=side)
        np.testing.assert_allclose(hjc, [1.0, 2.0, 3.0] + R @ [x, sign * y, z], rtol=1e-14)


def test_asis_trochanter_distance_is_vicons_expression():
    # the .vsk's own value of the shared subject
    assert asis_trochanter_distance(877.0) == pytest.approx(64.397598266601563, abs=1e-5)


def test_static_offsets_round_trip_through_the_foot_frame():
    rng = np.random.default_rng(8)
    R_u = np.stack([rot_z(a) @ rot_x(b) for a, b in rng.uniform(-1, 1, (20, 2))])
    for side in ("left", "right"):
        R_static = cgm_foot_frame(R_u, 0.23, -0.05, side)
        plantar, rotation = static_foot_offsets(R_u, R_static, side)
        assert plantar == pytest.approx(0.23, abs=1e-12)
        assert rotation == pytest.approx(-0.05, abs=1e-12)


def test_tibial_torsion_turns_the_knee_tibia_about_its_long_axis():
    torsioned, untorsioned = cgm_tibia_frame([0, 0, 400], [0, 0, 0], [0, -50, 0], "right",
                                             torsion=0.2)
    np.testing.assert_allclose(untorsioned, torsioned @ rot_z(-0.2), atol=1e-15)
    _, left = cgm_tibia_frame([0, 0, 400], [0, 0, 0], [0, 50, 0], "left", torsion=0.2)
    np.testing.assert_allclose(left[:, 2], [0, 0, 1], atol=1e-15)


@pytest.mark.parametrize("side", ["right", "left"])
def test_tibial_torsion_is_subtracted_from_knee_rotation(side):
    """Vicon's BodyLanguage: KneeAngles Z = rotation - TibialTorsion, on both sides."""
    rng = np.random.default_rng(5)
    femur = np.stack([rot_y(a) @ rot_x(b) for a, b in rng.uniform(-0.5, 0.5, (10, 2))])
    tibia = femur @ np.stack([rot_y(a) @ rot_z(c) for a, c in rng.uniform(-0.6, 0.6, (10, 2))])
    foot = tibia @ rot_y(-np.pi / 2)
    I = np.repeat(np.eye(3)[None], 10, axis=0)
    lateral = [0, -50, 0] if side == "right" else [0, 50, 0]
    torsioned, untorsioned = cgm_tibia_frame([0, 0, 400], [0, 0, 0], lateral, side, torsion=0.1)
    np.testing.assert_allclose(torsioned, np.eye(3), atol=1e-15)
    turn = untorsioned  # the turn about z that the torsion applies (torsioned = identity)
    plain = cgm_angles(np.eye(3), I, femur, tibia, tibia, foot, side)
    twisted = cgm_angles(np.eye(3), I, femur, tibia @ turn, tibia, foot, side)
    np.testing.assert_allclose(twisted[("knee", "rotation")],
                               plain[("knee", "rotation")] - np.degrees(0.1), atol=1e-9)
    np.testing.assert_allclose(twisted[("knee", "flexion")], plain[("knee", "flexion")],
                               atol=1e-9)


def test_progression_frame_static_uses_the_pelvis_axis():
    R = np.repeat(rot_z(np.pi / 2)[None], 4, axis=0)          # facing +y, not moving
    lab = progression_frame(np.zeros((4, 3)), R)
    np.testing.assert_allclose(lab, rot_z(np.pi / 2), atol=1e-15)


def test_cgm_angles_of_known_rotations():
    I = np.eye(3)[None]
    foot = I @ rot_y(-np.pi / 2)                               # perpendicular to the tibia
    femur = I @ rot_y(-np.radians(30))                         # hip flexed 30 degrees
    angles = cgm_angles(np.eye(3), I, femur, femur, femur, femur @ foot, "left")
    assert angles[("hip", "flexion")][0] == pytest.approx(30.0)
    assert angles[("knee", "flexion")][0] == pytest.approx(0.0, abs=1e-12)
    assert angles[("ankle", "dorsiflexion")][0] == pytest.approx(0.0, abs=1e-12)


# --- synthetic truth ---------------------------------------------------------------------

@pytest.fixture(scope="module")
def synthetic():
    static, _, _ = GEN.make_trial(50, static=True)
    walk, truth, centres = GEN.make_trial(300)
    return static, walk, truth, centres


def test_synthetic_angles_recovered_exactly(synthetic):
    static, walk, truth, centres = synthetic
    subject = {k: v for k, v in GEN.SUBJECT.items() if "Static" not in k}
    model = plug_in_gait(static, subject)
    for name in ("LeftStaticPlantFlex", "RightStaticRotOff"):
        assert model.static_offsets[name] == pytest.approx(GEN.SUBJECT[name], abs=1e-12)
    angles = model.angles(walk)
    assert np.abs(angles[truth.columns].to_numpy() - truth.to_numpy()).max() < 1e-9
    track = model.track(walk)
    for name, xyz in centres.items():
        assert np.abs(track.centres[name].to_numpy() - xyz).max() < 1e-9


def test_synthetic_without_static_uses_the_subjects_offsets(synthetic):
    _, walk, truth, _ = synthetic
    angles = plug_in_gait(None, GEN.SUBJECT).angles(walk)
    assert np.abs(angles[truth.columns].to_numpy() - truth.to_numpy()).max() < 1e-9


def test_subject_prefix_is_recognised(synthetic):
    static, walk, truth, _ = synthetic
    prefixed = walk.rename(columns=lambda label: "Sub01:" + label, level=0)
    angles = plug_in_gait(None, GEN.SUBJECT).angles(prefixed)
    assert np.abs(angles[truth.columns].to_numpy() - truth.to_numpy()).max() < 1e-9


def test_two_subject_prefixes_are_ambiguous(synthetic):
    _, walk, _, _ = synthetic
    one = walk.rename(columns=lambda label: "A:" + label, level=0)
    two = walk[["LASI"]].rename(columns=lambda label: "B:" + label, level=0)
    both = pd.concat([one, two], axis=1)
    both.attrs = dict(walk.attrs)
    with pytest.raises(ValueError, match="several subject prefixes.*A:LASI, B:LASI"):
        plug_in_gait(None, GEN.SUBJECT).angles(both)


def test_markers_renames_labels(synthetic):
    _, walk, truth, _ = synthetic
    renamed = walk.rename(columns={"LASI": "L.ASIS", "RTOE": "R.Toe"}, level=0)
    model = plug_in_gait(None, GEN.SUBJECT, markers={"LASI": "L.ASIS", "RTOE": "R.Toe"})
    angles = model.angles(renamed)
    assert np.abs(angles[truth.columns].to_numpy() - truth.to_numpy()).max() < 1e-9
    assert model.markers["LASI"] == "L.ASIS"


def test_sacrum_marker_instead_of_psis(synthetic):
    _, walk, truth, _ = synthetic
    sacrum = (walk["LPSI"] + walk["RPSI"]) / 2.0
    trial = walk.drop(columns=["LPSI", "RPSI"], level=0)
    for coord in "xyz":
        trial[("SACR", coord)] = sacrum[coord]
    trial.attrs = dict(walk.attrs)
    angles = plug_in_gait(None, GEN.SUBJECT).angles(trial)
    assert np.abs(angles[truth.columns].to_numpy() - truth.to_numpy()).max() < 1e-9


def test_metres_are_scaled_to_millimetres(synthetic):
    _, walk, truth, _ = synthetic
    metres = walk / 1000.0
    metres.attrs = dict(walk.attrs, units="m")
    angles = plug_in_gait(None, GEN.SUBJECT).angles(metres)
    assert np.abs(angles[truth.columns].to_numpy() - truth.to_numpy()).max() < 1e-9


def test_missing_frames_give_nan_and_one_warning(synthetic):
    _, walk, _, _ = synthetic
    gappy = walk.copy()
    gappy.loc[gappy.index[10:22], ("LTHI", slice(None))] = np.nan
    with pytest.warns(RuntimeWarning, match=r"12 of 300 frames .*LTHI missing in 12"):
        angles = plug_in_gait(None, GEN.SUBJECT).angles(gappy)
    assert angles["knee", "left"].iloc[10:22].isna().all().all()
    assert angles["knee", "right"].notna().all().all()
    assert angles["pelvis"].notna().all().all()


# --- every listed error ------------------------------------------------------------------

def test_missing_required_measurements_are_each_named():
    subject = {k: v for k, v in GEN.SUBJECT.items()
               if k not in ("LeftKneeWidth", "RightAnkleWidth")}
    with pytest.raises(ValueError, match="missing subject measurement.*LeftKneeWidth, "
                                         "RightAnkleWidth"):
        plug_in_gait(None, subject)


def test_without_static_the_offsets_are_required():
    subject = {k: v for k, v in GEN.SUBJECT.items() if "Static" not in k}
    with pytest.raises(ValueError, match="LeftStaticPlantFlex.*without a static trial"):
        plug_in_gait(None, subject)


def test_without_static_the_inter_asis_distance_is_required():
    subject = {k: v for k, v in GEN.SUBJECT.items() if k != "InterAsisDistance"}
    with pytest.raises(ValueError, match="InterAsisDistance"):
        plug_in_gait(None, subject)


def test_inter_asis_distance_from_the_static_trial(synthetic):
    static, _, _, _ = synthetic
    subject = {k: v for k, v in GEN.SUBJECT.items() if k != "InterAsisDistance"}
    model = plug_in_gait(static, subject)
    assert model.derived["InterAsisDistance"] == pytest.approx(248.0, abs=1e-9)


def test_a_width_must_be_positive():
    with pytest.raises(ValueError, match="LeftKneeWidth must be a positive length"):
        plug_in_gait(None, dict(GEN.SUBJECT, LeftKneeWidth=0.0))


def test_a_measurement_must_be_a_number():
    with pytest.raises(ValueError, match="LeftLegLength must be a finite number"):
        plug_in_gait(None, dict(GEN.SUBJECT, LeftLegLength="900"))


def test_static_ankle_abduction_is_applied_not_refused():
    """AnkleAbAdd (KAD-med) is applied, not refused: it moves the ankle centre and only
    that side's ankle-dependent angles (the rule and its oracle:
    tests/test_plug_in_gait_knee_alignment.py)."""
    walk, _, _ = GEN.make_trial(20)
    model = plug_in_gait(None, dict(GEN.SUBJECT, LeftAnkleAbAdd=0.1))
    assert model.subject["LeftAnkleAbAdd"] == 0.1
    plain = plug_in_gait(None, GEN.SUBJECT)
    moved = model.track(walk).centres["LAJC"] - plain.track(walk).centres["LAJC"]
    assert np.all(np.linalg.norm(moved, axis=1) > 1.0)
    a, b = model.angles(walk), plain.angles(walk)
    assert np.array_equal(a["knee", "right"].to_numpy(), b["knee", "right"].to_numpy())
    assert not np.allclose(a["ankle", "left"].to_numpy(), b["ankle", "left"].to_numpy())


def test_sole_delta_is_refused_only_with_a_static_trial(synthetic):
    static, walk, truth, _ = synthetic
    with pytest.raises(ValueError, match="LeftSoleDelta = 5.*sole-thickness"):
        plug_in_gait(static, dict(GEN.SUBJECT, LeftSoleDelta=5.0))
    angles = plug_in_gait(None, dict(GEN.SUBJECT, LeftSoleDelta=5.0)).angles(walk)
    assert np.abs(angles[truth.columns].to_numpy() - truth.to_numpy()).max() < 1e-9


def test_conflicting_short_and_long_names_are_refused():
    with pytest.raises(ValueError, match="LeftLegLength is given twice"):
        plug_in_gait(None, dict(GEN.SUBJECT, LLegLength=850.0))


def test_short_names_are_accepted(synthetic):
    _, walk, truth, _ = synthetic
    subject = {("L" + k[4:] if k.startswith("Left") else
                "R" + k[5:] if k.startswith("Right") else k): v
               for k, v in GEN.SUBJECT.items()}
    angles = plug_in_gait(None, subject).angles(walk)
    assert np.abs(angles[truth.columns].to_numpy() - truth.to_numpy()).max() < 1e-9


def test_subject_of_the_wrong_type():
    with pytest.raises(TypeError, match="subject must be a dict"):
        plug_in_gait(None, [900.0])


def test_subject_file_of_the_wrong_kind(tmp_path):
    with pytest.raises(ValueError, match="expected a dict, a .vsk, a .c3d, or a .toml"):
        plug_in_gait(None, tmp_path / "subject.txt")


def test_markers_must_be_a_dict_of_labels():
    with pytest.raises(TypeError, match="markers must be a dict"):
        plug_in_gait(None, GEN.SUBJECT, markers=["LASI"])
    with pytest.raises(TypeError, match="markers must be a dict"):
        plug_in_gait(None, GEN.SUBJECT, markers={"LASI": ["a", "b"]})


def test_markers_with_an_unknown_name():
    with pytest.raises(ValueError, match="unknown Plug-in Gait name.*LKNEE"):
        plug_in_gait(None, GEN.SUBJECT, markers={"LKNEE": "LKNE"})


def test_markers_renamed_to_a_label_the_trial_lacks(synthetic):
    _, walk, _, _ = synthetic
    model = plug_in_gait(None, GEN.SUBJECT, markers={"LASI": "L.ASIS"})
    with pytest.raises(ValueError, match="LASI -> 'L.ASIS'.*has no label"):
        model.angles(walk)


def test_a_missing_marker_is_named(synthetic):
    _, walk, _, _ = synthetic
    with pytest.raises(ValueError, match="missing Plug-in Gait marker.*RTIB"):
        plug_in_gait(None, GEN.SUBJECT).angles(walk.drop(columns="RTIB", level=0))


def test_no_posterior_pelvis_marker(synthetic):
    _, walk, _, _ = synthetic
    with pytest.raises(ValueError, match="SACR or LPSI and RPSI"):
        plug_in_gait(None, GEN.SUBJECT).angles(walk.drop(columns="LPSI", level=0))


def test_static_trial_without_heel_markers(synthetic):
    static, _, _, _ = synthetic
    with pytest.raises(ValueError, match="needs HEE"):
        plug_in_gait(static.drop(columns=["LHEE"], level=0), GEN.SUBJECT)


def test_static_of_the_wrong_type():
    with pytest.raises(TypeError, match="static must be a path"):
        plug_in_gait(3.0, GEN.SUBJECT)


def test_foot_option_is_checked(synthetic):
    _, walk, _, _ = synthetic
    model = plug_in_gait(None, GEN.SUBJECT)
    with pytest.raises(ValueError, match="foot must be 'dynamic' or 'static'"):
        model.angles(walk, foot="heel")
    with pytest.raises(ValueError, match="foot='static' needs the HEE"):
        model.angles(walk.drop(columns=["LHEE"], level=0), foot="static")


def test_trial_without_units(synthetic):
    _, walk, _, _ = synthetic
    bare = walk.copy()
    bare.attrs = {}
    with pytest.raises(ValueError, match="has no units"):
        plug_in_gait(None, GEN.SUBJECT).angles(bare)


@needs_data
def test_the_repository_copy_is_unchanged():
    shared = SHARED_DATA / "plug_in_gait"
    if not shared.exists() or FOLDER == shared:
        pytest.skip("no second copy to compare")
    for name in ("Static_trial.c3d", "Movement_trial.c3d", "Test.vsk"):
        assert (FOLDER / name).read_bytes() == (shared / name).read_bytes()
    assert "MIT" in (FOLDER / "LICENSE").read_text()


def test_a_turning_static_trial_is_flagged_by_its_pelvis_markers(vicon):
    """The static check finds Plug-in Gait's pelvis by the lower-limb roles: the pelvis
    markers turned by 20 degrees about the vertical through RASI in the last frame (each
    moved by less than 100 mm, the travel limit) must warn that they turn. In the middle
    of the issue 24 refactor this check was silently skipped for Plug-in Gait."""
    static = vicon["static_points"].copy()
    labels = ["RASI", "LASI", "RPSI", "LPSI"]
    angle = np.deg2rad(20.0)
    up = np.array([0.0, 0.0, 1.0])                # the Nexus lab: z up
    centre = static["RASI"].to_numpy()[-1]
    for label in labels:
        offset = static[label].to_numpy()[-1] - centre
        turned = (offset * np.cos(angle) + np.cross(up, offset) * np.sin(angle)
                  + up * (up @ offset) * (1 - np.cos(angle)))
        static.loc[static.index[-1], label] = centre + turned
    with pytest.warns(RuntimeWarning, match=r"pelvis markers \(RASI, LASI, RPSI, LPSI\) "
                                            r"turn by up to 20 degrees"):
        plug_in_gait(static, FOLDER / "Test.vsk")


# --- issue 30: a trial of another subject ---------------------------------------------------

def _subject_warnings(call):
    with warnings.catch_warnings(record=True) as found:
        warnings.simplefilter("always")
        call()
    return [str(w.message) for w in found if "subject" in str(w.message)]


@needs_data
@pytest.mark.parametrize("static, subject", [("Static_trial.c3d", "Test.vsk"),
                                             (None, "Test.vsk"),
                                             (None, "Movement_trial.c3d")])
def test_the_same_subjects_files_raise_no_subject_warning(static, subject):
    """The shipped trials are all of subject 'Test' (SUBJECTS:NAMES, Test.vsk), ASIS
    markers 307-311 mm apart against the .vsk's InterAsisDistance of 306 mm."""
    model = plug_in_gait(None if static is None else FOLDER / static, FOLDER / subject)
    assert _subject_warnings(lambda: model.angles(FOLDER / "Movement_trial.c3d")) == []


@needs_data
def test_another_subjects_name_or_pelvis_is_warned_about(tmp_path):
    from bmc_functions.models.plug_in_gait.subject import INTER_ASIS_TOLERANCE

    trial = FOLDER / "Movement_trial.c3d"
    other = tmp_path / "Other.vsk"                     # Nexus names a .vsk after the subject
    other.write_bytes((FOLDER / "Test.vsk").read_bytes())
    found = _subject_warnings(lambda: plug_in_gait(FOLDER / "Static_trial.c3d",
                                                   other).angles(trial))
    assert len(found) == 1
    assert "its subject is 'Test', that of the subject file 'Other'" in found[0]
    assert "static trial" not in found[0] and "ASIS" not in found[0]
    # a subject whose pelvis is 40 mm narrower than the trial's ASIS markers (median 311 mm)
    subject, _ = load_subject(FOLDER / "Test.vsk")
    narrow = dict(subject, InterAsisDistance=subject["InterAsisDistance"] - 35.0)
    assert 311 - narrow["InterAsisDistance"] > INTER_ASIS_TOLERANCE
    found = _subject_warnings(lambda: plug_in_gait(None, narrow).angles(trial))
    assert len(found) == 1
    assert re.search(r"ASIS markers are 311 mm apart \(median\), the subject's "
                     r"InterAsisDistance is 271 mm \(more than 30 mm off\)", found[0])
    # within the tolerance: no warning
    close = dict(subject, InterAsisDistance=subject["InterAsisDistance"] - 15.0)
    assert _subject_warnings(lambda: plug_in_gait(None, close).angles(trial)) == []


@needs_data
def test_a_subject_whose_legs_the_markers_contradict_is_warned_about():
    """The walk's legs measure 879 mm (left) and 871 mm (right) along ASI-KNE-ANK at their
    straightest, against the subject's LegLengths of 877 and 866 mm: a subject 70 mm
    longer on the left is another subject; 50 mm is within LEG_LENGTH_TOLERANCE."""
    from bmc_functions.models.plug_in_gait.subject import LEG_LENGTH_TOLERANCE

    trial = FOLDER / "Movement_trial.c3d"
    subject, _ = load_subject(FOLDER / "Test.vsk")
    longer = dict(subject, LeftLegLength=subject["LeftLegLength"] + 70.0)
    found = _subject_warnings(lambda: plug_in_gait(None, longer).angles(trial))
    assert len(found) == 1
    assert re.search(r"its left leg markers \(ASI-KNE-ANK, at the leg's straightest\) "
                     r"measure 879 mm, the subject's LeftLegLength is 947 mm \(more than "
                     r"60 mm off\)", found[0]), found[0]
    assert "right leg" not in found[0] and "ASIS markers" not in found[0]
    assert 947 - 879 > LEG_LENGTH_TOLERANCE > 50
    close = dict(subject, LeftLegLength=subject["LeftLegLength"] + 50.0)
    assert _subject_warnings(lambda: plug_in_gait(None, close).angles(trial)) == []
