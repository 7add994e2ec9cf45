"""Tests of the command line (bmc_functions.cli): end to end in a subprocess on the
repository's trials and on the real trials of ../shared/data, the outputs read back and
compared with the package's own functions called directly; errors and exit status."""

import json
import os
import shutil
import subprocess
import sys
import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import (calibrate_lower_limb, gait_events, read_mot, read_trc,
                           opensim_coordinates)
from bmc_functions import read_marker_mapping as read_mapping
from bmc_functions.cli import main

from helpers import ROOT, SHARED_DATA, needs_shared, write_c3d_points

MARKERS = ROOT / "data" / "markers"

#: The marker names of data/markers (generate_marker_data.py): both legs, with feet.
REPO_MAPPING = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
                "PELVIS": ["PEL1", "PEL2", "PEL3"]}
for _p in "RL":
    REPO_MAPPING.update({_p + "THIGH": [_p + "TH1", _p + "TH2", _p + "TH3", _p + "TH4"],
                         _p + "SHANK": [_p + "TB1", _p + "TB2", _p + "TB3"],
                         _p + "KNEE_LAT": _p + "LFC", _p + "KNEE_MED": _p + "MFC",
                         _p + "ANKLE_LAT": _p + "LMAL", _p + "ANKLE_MED": _p + "MMAL",
                         _p + "HEEL": _p + "HEEL", _p + "TOE": _p + "TOE",
                         _p + "MT5": _p + "MT5"})

RUN_TOML = """\
# the running trials of ../shared/data (a Cortex marker set)
RASIS = "RASI"
LASIS = "LASI"
RPSIS = "RPSI"
LPSIS = "LPSI"
""" + "".join(f"""{p}THIGH = ["{p}TH1", "{p}TH2", "{p}TH3"]
{p}SHANK = ["{p}TB1", "{p}TB2", "{p}TB3"]
{p}KNEE_LAT = "{p}LFC"
{p}KNEE_MED = "{p}MFC"
{p}ANKLE_LAT = "{p}LMAL"
{p}ANKLE_MED = "{p}MMAL"
{p}HEEL = "{p}CAL"
{p}TOE = "{p}TOE"
{p}MT5 = "{p}MT5"
""" for p in "RL")


def cli(*args, cwd=None):
    """`python -m bmc_functions ...` in a fresh process using this checkout."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    return subprocess.run([sys.executable, "-m", "bmc_functions", *map(str, args)],
                          capture_output=True, text=True, cwd=cwd, env=env, timeout=300)


def quiet_angles(static, trial, mapping):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = calibrate_lower_limb(static, mapping)
        return model, model.angles(trial)


def test_help_shows_a_worked_example():
    run = cli("--help")
    assert run.returncode == 0
    assert "bmc-kinematics angles --static static.trc --markers markers.toml" in run.stdout
    assert 'RTHIGH = ["R.TH1", "R.TH2", "R.TH3"]' in run.stdout
    for command in ("angles", "events", "cycles", "convert"):
        assert command in run.stdout
    assert "bmc-kinematics angles" in cli("angles", "--help").stdout


def test_angles_end_to_end_on_the_repository_trials(tmp_path):
    mapping = tmp_path / "markers.json"
    mapping.write_text(json.dumps(REPO_MAPPING))
    run = cli("angles", "--static", MARKERS / "static.trc", "--markers", mapping,
              MARKERS / "walk.trc", "-o", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    out = tmp_path / "out"
    # the same numbers as the package called directly
    model, angles = quiet_angles(MARKERS / "static.trc", MARKERS / "walk.trc", REPO_MAPPING)
    mot = read_mot(out / "walk_angles.mot")
    expected = opensim_coordinates(angles)
    assert list(mot.columns) == list(expected.columns)
    np.testing.assert_array_equal(mot.to_numpy(), expected.to_numpy())   # exact precision
    csv = pd.read_csv(out / "walk_angles.csv", index_col="time")
    assert "knee.right.flexion" in csv.columns
    np.testing.assert_array_equal(csv["knee.right.flexion"],
                                  angles["knee", "right", "flexion"])
    events = pd.read_csv(out / "walk_events.csv")
    with warnings.catch_warnings():   # the synthetic feet never rest on a floor (07 says why)
        warnings.filterwarnings("ignore", ".*never rest on a floor", RuntimeWarning)
        truth = gait_events(MARKERS / "walk.trc", REPO_MAPPING)
    np.testing.assert_array_equal(
        events.query("side == 'right' and event == 'heel_strike'")["time"],
        truth["right"]["heel_strike"])
    assert (out / "walk_angles.png").stat().st_size > 10_000
    record = json.loads((out / "walk_angles.json").read_text())
    from bmc_functions import __version__
    assert record["bmc_functions"] == __version__
    assert record["options"]["hip_centre"] == "harrington"
    assert record["markers"]["RTHIGH"] == REPO_MAPPING["RTHIGH"]
    knee_width = np.linalg.norm(model.landmarks.loc["RKNEE_LAT"] -
                                model.landmarks.loc["RKNEE_MED"])
    assert record["subject"]["right"]["knee_width"] == round(knee_width, 1)
    assert record["frames"] == len(angles)
    # the occlusion gaps of this trial are reported, with the file's name, on stderr
    assert all(line.startswith(("warning: ", "error: ")) or not line.strip()
               for line in run.stderr.splitlines())
    assert record["warnings"] and all(f"warning: {MARKERS / 'walk.trc'}: " in run.stderr
                                      for _ in record["warnings"])


def test_one_bad_trial_does_not_stop_the_others(tmp_path):
    mapping = tmp_path / "markers.toml"
    mapping.write_text("\n".join(f"{k} = {json.dumps(v)}" for k, v in REPO_MAPPING.items()))
    broken = tmp_path / "broken.trc"
    broken.write_text("PathFileType\t4\t(X/Y/Z)\tbroken.trc\nnot a trc file\n")
    run = cli("angles", "--static", MARKERS / "static.trc", "--markers", mapping,
              broken, MARKERS / "walk.trc", tmp_path / "absent*.trc", "-o", tmp_path)
    assert run.returncode == 1
    assert f"error: {broken}: " in run.stderr
    assert f"error: {tmp_path / 'absent*.trc'}: no file matches" in run.stderr
    assert "1 of 2 trial(s) done; failed:" in run.stderr
    assert (tmp_path / "walk_angles.mot").exists()
    assert not (tmp_path / "broken_angles.mot").exists()


def test_events_and_cycles_on_a_pattern(tmp_path):
    mapping = tmp_path / "markers.json"
    mapping.write_text(json.dumps(REPO_MAPPING))
    gait = ROOT / "data" / "gait"
    run = cli("events", "--markers", mapping, MARKERS / "w*.trc", "-o", tmp_path, "-q")
    assert run.returncode == 0, run.stderr
    parameters = pd.read_csv(tmp_path / "walk_parameters.csv", index_col="side")
    assert {"cadence", "stance"} <= set(parameters.columns)
    run = cli("cycles", "--static", gait / "legs_static.trc", "--markers", mapping,
              gait / "legs_walk.trc", "-o", tmp_path, "-q")
    assert run.returncode == 0, run.stderr
    cycles = pd.read_csv(tmp_path / "legs_walk_cycles.csv", index_col=["cycle", "percent"])
    assert cycles.index.get_level_values("percent").nunique() == 101
    stats = pd.read_csv(tmp_path / "ensemble.csv", index_col=0)
    assert "mean:knee.right.flexion" in stats.columns
    assert (tmp_path / "ensemble.png").exists() and (tmp_path / "legs_walk_cycles.png").exists()


def test_convert_angles_csv_to_mot_and_mot_to_csv(tmp_path):
    _, angles = quiet_angles(MARKERS / "static.trc", MARKERS / "walk.trc", REPO_MAPPING)
    table = angles.copy()
    table.columns = [".".join(c) for c in angles.columns]
    table.to_csv(tmp_path / "walk_angles.csv")
    assert main(["convert", str(tmp_path / "walk_angles.csv"), "-o", str(tmp_path / "o"),
                 "-q"]) == 0
    mot = read_mot(tmp_path / "o" / "walk_angles.mot")
    np.testing.assert_array_equal(mot["knee_angle_r"], angles["knee", "right", "flexion"])
    assert main(["convert", str(tmp_path / "o" / "walk_angles.mot"), "--to", "csv", "-o",
                 str(tmp_path / "p"), "-q"]) == 0
    back = pd.read_csv(tmp_path / "p" / "walk_angles.csv", index_col="time")
    np.testing.assert_array_equal(back["knee_angle_r"], angles["knee", "right", "flexion"])


def test_convert_refuses_what_it_cannot_convert(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("x")
    assert main(["convert", str(tmp_path / "notes.txt"), "-o", str(tmp_path), "-q"]) == 1
    assert f"error: {tmp_path / 'notes.txt'}: cannot convert a .txt" in capsys.readouterr().err


def test_two_trials_with_the_same_name_are_refused(tmp_path):
    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "walk.trc").write_text("x")
    with pytest.raises(SystemExit) as info:
        main(["events", "--markers", "m.json", str(tmp_path / "a" / "walk.trc"),
              str(tmp_path / "b" / "walk.trc")])
    assert info.value.code == 2


def test_a_calibration_failure_names_the_static_trial(tmp_path, capsys):
    mapping = tmp_path / "m.json"
    mapping.write_text(json.dumps({**REPO_MAPPING, "RKNEE_LAT": "NOPE"}))
    status = main(["angles", "--static", str(MARKERS / "static.trc"), "--markers",
                   str(mapping), str(MARKERS / "walk.trc"), "-o", str(tmp_path), "-q"])
    assert status == 1
    err = capsys.readouterr().err
    assert f"error: {MARKERS / 'static.trc'}: calibration failed:" in err and "NOPE" in err


# --- the mapping file --------------------------------------------------------------------------

@pytest.mark.parametrize("suffix, text", [
    (".toml", 'RASIS = "RASI"\nRTHIGH = ["A", "B", "C"]\n'),
    (".json", '{"markers": {"RASIS": "RASI", "RTHIGH": ["A", "B", "C"]}}'),
    (".yaml", "RASIS: RASI\nRTHIGH: [A, B, C]\n"),
])
def test_mapping_in_toml_json_or_yaml(tmp_path, suffix, text):
    if suffix == ".yaml":
        pytest.importorskip("yaml")
    path = tmp_path / f"markers{suffix}"
    path.write_text(text)
    assert read_mapping(path) == {"RASIS": "RASI", "RTHIGH": ["A", "B", "C"]}


def test_the_shipped_example_mapping_is_that_of_the_example_trials():
    from bmc_functions.examples import example_file

    assert read_mapping(example_file("markers/markers.toml")) == REPO_MAPPING


def test_yaml_without_pyyaml_says_what_to_do(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "yaml", None)      # as if PyYAML were not installed
    path = tmp_path / "markers.yml"
    path.write_text("RASIS: RASI\n")
    with pytest.raises(ValueError, match=r"markers.yml: reading YAML needs the package "
                                         r"PyYAML \(pip install pyyaml\)"):
        read_mapping(path)


@pytest.mark.parametrize("name, text, match", [
    ("m.toml", "RASIS = \n", r"m.toml: could not be read as TOML"),
    ("m.json", '{"RASIS": 3}', r"m.json: RASIS must be a label or a list of labels; got 3"),
    ("m.json", "[1, 2]", r"m.json: expected a table role = label"),
    ("m.txt", "RASIS = 1", r"m.txt: a marker mapping is a .toml, .json, .yaml or .yml"),
])
def test_mapping_errors_name_the_file(tmp_path, name, text, match):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(ValueError, match=match):
        read_mapping(path)


# --- the real trials of ../shared/data -----------------------------------------------------------

@needs_shared("static_run.trc", "motion_capture_run.trc", "ik_output_run.mot")
def test_angles_on_the_real_running_trial(tmp_path):
    (tmp_path / "run.toml").write_text(RUN_TOML)
    run = cli("angles", "--static", SHARED_DATA / "static_run.trc", "--markers", "run.toml",
              SHARED_DATA / "motion_capture_run.trc", "-o", "out", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    # the known RTOE/RMT5 swap of this file is reported, naming the file
    assert f"warning: {SHARED_DATA / 'motion_capture_run.trc'}: " in run.stderr
    assert "RTOE" in run.stderr
    ours = read_mot(tmp_path / "out" / "motion_capture_run_angles.mot")
    ik = read_mot(SHARED_DATA / "ik_output_run.mot")
    from bmc_functions import align_times
    ours = align_times(ours, ik)
    for name in ("hip_flexion_r", "knee_angle_r", "knee_angle_l", "ankle_angle_l"):
        assert np.corrcoef(ours[name], ik[name])[0, 1] > 0.98, name
    events = pd.read_csv(tmp_path / "out" / "motion_capture_run_events.csv")
    assert events.query("side == 'right' and event == 'toe_off'")["time"].tolist() == \
        pytest.approx([0.26], abs=0.014)
    record = json.loads((tmp_path / "out" / "motion_capture_run_angles.json").read_text())
    assert record["gait"] == "running"
    assert 150 < record["subject"]["pelvis_width_asis"] < 350


@needs_shared("plug_in_gait/Static_trial.c3d")
def test_convert_c3d_to_trc(tmp_path):
    pytest.importorskip("ezc3d")
    from bmc_functions import read_c3d

    source = SHARED_DATA / "plug_in_gait" / "Static_trial.c3d"
    run = cli("convert", source, "-o", tmp_path, "-q")
    assert run.returncode == 0, run.stderr
    trc = read_trc(tmp_path / "Static_trial.trc")
    c3d = read_c3d(source)
    assert list(trc.columns) == list(c3d.columns)
    np.testing.assert_allclose(trc.to_numpy(), c3d.to_numpy(), atol=5e-7, equal_nan=True)
    assert trc.attrs["rate"] == c3d.attrs["rate"]


WALK_YAML = """\
# ../shared/data/walk.trc: no clusters, every landmark in every frame (no static trial)
RASIS: R.ASIS
LASIS: L.ASIS
RPSIS: R.PSIS
LPSIS: L.PSIS
""" + "".join(f"""{p}KNEE_LAT: {p}.Knee
{p}KNEE_MED: {p}.Knee.Medial
{p}ANKLE_LAT: {p}.Ankle
{p}ANKLE_MED: {p}.Ankle.Medial
{p}HEEL: {p}.Heel
{p}TOE: {p}.MT2
{p}MT5: {p}.MT5
""" for p in "RL")


@needs_shared("walk.trc")
def test_angles_without_a_static_trial_and_a_trial_without_a_cycle(tmp_path):
    pytest.importorskip("yaml")
    (tmp_path / "walk.yaml").write_text(WALK_YAML)
    run = cli("angles", "--markers", "walk.yaml", SHARED_DATA / "walk.trc", "-o", "out",
              "-q", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    angles = pd.read_csv(tmp_path / "out" / "walk_angles.csv", index_col="time")
    from bmc_functions import lower_limb_angles
    expected = lower_limb_angles(None, SHARED_DATA / "walk.trc",
                                 read_mapping(tmp_path / "walk.yaml"))
    np.testing.assert_array_equal(angles["knee.right.flexion"],
                                  expected["knee", "right", "flexion"])
    # one heel strike per side: no cycle to normalise, and the command says so
    run = cli("cycles", "--markers", "walk.yaml", SHARED_DATA / "walk.trc", "-o", "out",
              "-q", cwd=tmp_path)
    assert run.returncode == 1
    assert f"error: {SHARED_DATA / 'walk.trc'}: cycles holds no complete gait cycle" \
        in run.stderr


# --- Plug-in Gait --------------------------------------------------------------------------

PIG = ROOT / "data" / "real" / "plug_in_gait"


def test_help_shows_a_worked_plug_in_gait_example():
    run = cli("angles", "--help")
    assert "bmc-kinematics angles --model plug-in-gait --static Static.c3d --subject " \
           "Subject.vsk" in run.stdout
    assert "--subject" in run.stdout and "PROCESSING" in run.stdout


def test_plug_in_gait_end_to_end_matches_vicon(tmp_path):
    """The command line's Plug-in Gait on the repository's Nexus trial: the written knee
    flexion against the curve Vicon Nexus stored in the same C3D (the oracle)."""
    pytest.importorskip("ezc3d")
    from bmc_functions import plug_in_gait, read_c3d_model_outputs
    from bmc_functions import opensim_coordinates

    trial = PIG / "Movement_trial.c3d"
    run = cli("angles", "--model", "plug-in-gait", "--static", PIG / "Static_trial.c3d",
              "--subject", PIG / "Test.vsk", trial, "-o", tmp_path, "-q")
    assert run.returncode == 0, run.stderr
    csv = pd.read_csv(tmp_path / "Movement_trial_angles.csv", index_col="time")
    assert csv.shape == (323, 64)     # the lower body's 26 curves, the upper body's 38
    vicon = read_c3d_model_outputs(trial)
    for side, p in (("right", "R"), ("left", "L")):
        difference = csv[f"knee.{side}.flexion"] - vicon[p + "KneeAngles"]["x"].to_numpy()
        assert np.sqrt(np.mean(difference ** 2)) < 0.1
    # .mot: OpenSim's names; the pelvis renamed exactly (the same sequence as OpenSim's)
    mot = read_mot(tmp_path / "Movement_trial_angles.mot")
    assert {"pelvis_tilt", "hip_flexion_r", "knee_angle_l", "ankle_angle_r",
            "foot_progression_r"} <= set(mot.columns)
    np.testing.assert_allclose(mot["pelvis_tilt"], -csv["pelvis.right.tilt"], atol=1e-12)
    np.testing.assert_allclose(mot["pelvis_list"], -csv["pelvis.right.obliquity"],
                               atol=1e-12)
    np.testing.assert_allclose(mot["knee_angle_r"], csv["knee.right.flexion"], atol=1e-12)
    # the record: every measurement used and derived, the static offsets, the version
    record = json.loads((tmp_path / "Movement_trial_angles.json").read_text())
    from bmc_functions import __version__
    assert record["bmc_functions"] == __version__
    model = plug_in_gait(PIG / "Static_trial.c3d", PIG / "Test.vsk")
    assert record["subject"]["measurements"] == model.attrs["measurements"]
    assert record["subject"]["derived"] == model.attrs["derived"]
    assert record["subject"]["static_offsets"]["LeftStaticPlantFlex"] == pytest.approx(
        model.static_offsets["LeftStaticPlantFlex"])
    assert record["options"]["model"] == "plug-in-gait"
    assert record["markers"]["LASI"] == "LASI" and record["markers"]["RTOE"] == "RTOE"
    assert "hip_centre" not in record["options"]
    assert (tmp_path / "Movement_trial_events.csv").exists()
    assert (tmp_path / "Movement_trial_angles.png").stat().st_size > 10_000
    direct = opensim_coordinates(model.angles(trial))
    np.testing.assert_array_equal(mot.to_numpy(), direct.to_numpy())


@pytest.mark.parametrize("kind", ["c3d", "toml", "json"])
def test_plug_in_gait_without_static_from_the_c3d_or_a_subject_file(tmp_path, kind):
    pytest.importorskip("ezc3d")
    from bmc_functions import read_c3d_model_outputs
    from bmc_functions.files.c3d_parameters import subject_parameters

    trial = PIG / "Movement_trial.c3d"
    subject = trial
    if kind != "c3d":       # Vicon's names and numbers, written by a lab by hand
        values = {k: v for k, v in subject_parameters(trial).items() if k[:1] in "LRI"
                  and not k.isupper()}
        subject = tmp_path / f"subject.{kind}"
        subject.write_text(json.dumps(values) if kind == "json" else
                           "\n".join(f"{k} = {v!r}" for k, v in values.items()))
    run = cli("angles", "--model", "plug-in-gait", "--subject", subject, trial,
              "-o", tmp_path / "out", "-q")
    assert run.returncode == 0, run.stderr
    csv = pd.read_csv(tmp_path / "out" / "Movement_trial_angles.csv", index_col="time")
    vicon = read_c3d_model_outputs(trial)
    difference = csv["knee.left.flexion"] - vicon["LKneeAngles"]["x"].to_numpy()
    assert np.sqrt(np.mean(difference ** 2)) < 0.1
    record = json.loads((tmp_path / "out" / "Movement_trial_angles.json").read_text())
    assert record["subject"]["static"] == "offsets from the subject"


def test_plug_in_gait_without_subject_says_what_to_give(tmp_path, capsys):
    status = main(["angles", "--model", "plug-in-gait", str(PIG / "Movement_trial.c3d"),
                   "-o", str(tmp_path), "-q"])
    assert status == 1
    assert "--model plug-in-gait needs --subject" in capsys.readouterr().err


def test_plug_in_gait_refuses_the_isb_options(tmp_path, capsys):
    status = main(["angles", "--model", "plug-in-gait", "--subject", str(PIG / "Test.vsk"),
                   "--hip-centre", "marker", str(PIG / "Movement_trial.c3d"), "-o",
                   str(tmp_path), "-q"])
    assert status == 1
    assert "belong to --model isb" in capsys.readouterr().err


def test_isb_refuses_a_subject_file(tmp_path, capsys):
    mapping = tmp_path / "m.json"
    mapping.write_text(json.dumps(REPO_MAPPING))
    status = main(["angles", "--static", str(MARKERS / "static.trc"), "--markers",
                   str(mapping), "--subject", str(PIG / "Test.vsk"),
                   str(MARKERS / "walk.trc"), "-o", str(tmp_path), "-q"])
    assert status == 1
    assert "--subject belongs to --model plug-in-gait" in capsys.readouterr().err


def test_plug_in_gait_missing_offsets_name_the_subject_file(tmp_path, capsys):
    subject = tmp_path / "subject.json"
    subject.write_text(json.dumps({"LeftLegLength": 877.0, "RightLegLength": 866.0,
                                   "LeftKneeWidth": 144.0, "RightKneeWidth": 139.0,
                                   "LeftAnkleWidth": 85.0, "RightAnkleWidth": 89.0,
                                   "InterAsisDistance": 306.0}))
    status = main(["angles", "--model", "plug-in-gait", "--subject", str(subject),
                   str(PIG / "Movement_trial.c3d"), "-o", str(tmp_path), "-q"])
    assert status == 1
    err = capsys.readouterr().err
    assert f"error: {subject}: calibration failed" in err
    assert "LeftStaticPlantFlex" in err and "give the static trial" in err


def test_plug_in_gait_cycles_and_a_prefixed_trial(tmp_path):
    """`cycles` with Plug-in Gait; the events of a trial whose labels carry a subject
    prefix come from the model's own labels (Sub01:RHEE ...), as without the prefix."""
    pytest.importorskip("ezc3d")
    from bmc_functions import read_c3d

    trial = read_c3d(PIG / "Movement_trial.c3d")
    labels = ["LASI", "RASI", "LPSI", "RPSI"] + [p + m for p in "LR" for m in (
        "THI", "KNE", "TIB", "ANK", "HEE", "TOE")]
    xyz = np.stack([trial[label].to_numpy() for label in labels], axis=1)
    prefixed = write_c3d_points(tmp_path / "prefixed.c3d", xyz,
                                ["Sub01:" + label for label in labels])
    run = cli("cycles", "--model", "plug-in-gait", "--subject", PIG / "Movement_trial.c3d",
              PIG / "Movement_trial.c3d", prefixed, "-o", tmp_path / "out", "-q")
    assert run.returncode == 0, run.stderr
    out = tmp_path / "out"
    plain = pd.read_csv(out / "Movement_trial_cycles.csv")
    assert "foot.right.progression" in plain.columns
    prefixed_cycles = pd.read_csv(out / "prefixed_cycles.csv")   # lower-body markers only
    np.testing.assert_allclose(prefixed_cycles.to_numpy(float),
                               plain[prefixed_cycles.columns].to_numpy(float), atol=1e-6)
    assert (out / "ensemble.png").exists()


def test_angles_with_kinetics_writes_the_moments_and_records_the_loads(tmp_path):
    """--kinetics on the repository's running trial, its loads found by --forces with
    {stem}: <stem>_kinetics.csv holds what LowerLimbModel.kinetics returns, a figure is
    written, the record names the loads, the segment parameters and the assignment; a
    .trc without --forces, and no --body-mass, are refused naming the trial."""
    real = ROOT / "data" / "real"
    (tmp_path / "run.toml").write_text(RUN_TOML)
    shutil.copy(real / "motion_capture_run.trc", tmp_path / "run1.trc")
    shutil.copy(real / "grf_run.mot", tmp_path / "run1_grf.mot")
    run = cli("angles", "--static", real / "static_run.trc", "--markers", "run.toml",
              "run1.trc", "-o", "out", "-q", "--kinetics", "--forces", "{stem}_grf.mot",
              "--body-mass", "70", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert "RFOOT (RCAL, RTOE, RMT5) in 43 of 123 frames are taken as missing" in run.stderr
    written = pd.read_csv(tmp_path / "out" / "run1_kinetics.csv", index_col=0)
    assert (tmp_path / "out" / "run1_kinetics.png").stat().st_size > 10_000
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = calibrate_lower_limb(real / "static_run.trc",
                                     read_mapping(tmp_path / "run.toml"))
        expected = model.kinetics(tmp_path / "run1.trc", tmp_path / "run1_grf.mot",
                                  body_mass=70.0)
    assert written.shape == (123, 42)
    knee = written.filter(like="knee").filter(like="left").filter(like="moment_x")
    np.testing.assert_allclose(knee.to_numpy()[:, 0],
                               expected["knee", "left", "moment_x"].to_numpy(), atol=1e-6)
    record = json.loads((tmp_path / "out" / "run1_angles.json").read_text())
    assert record["options"]["body_mass"] == 70.0 and record["options"]["kinetics"]
    assert record["kinetics"]["forces"] == "run1_grf.mot"
    attrs = record["kinetics"]["attrs"]
    assert attrs["segment_parameters"]["thigh"]["mass"] == pytest.approx(0.100)
    assert [(a["load"], a["side"]) for a in attrs["load_assignment"]] == \
        [("R_", "right"), ("L_", "left")]
    refused = cli("angles", "--static", real / "static_run.trc", "--markers", "run.toml",
                  "run1.trc", "-o", "out2", "-q", "--kinetics", "--body-mass", "70",
                  cwd=tmp_path)
    assert refused.returncode != 0 and "error: run1.trc: --kinetics needs the ground " \
        "loads of run1.trc: a C3D trial carries its force plates" in refused.stderr
    no_mass = cli("angles", "--static", real / "static_run.trc", "--markers", "run.toml",
                  "run1.trc", "-o", "out3", "-q", "--kinetics", "--forces", "{stem}_grf.mot",
                  cwd=tmp_path)
    assert no_mass.returncode != 0 and "--kinetics needs --body-mass" in no_mass.stderr
# --- issue 30: Plug-in Gait's labels without a mapping, stored events, the static trial -------

def _pig_copy(path, trial, *, prefix="", sacrum=False, heel=True):
    """A copy of the Nexus walk's lower-body markers with a subject prefix, the sacrum
    (the PSIS midpoint) instead of the PSIS markers, with or without HEE."""
    posterior = ["SACR"] if sacrum else ["LPSI", "RPSI"]
    legs = [p + m for p in "LR" for m in ("THI", "KNE", "TIB", "ANK", "TOE")
            + (("HEE",) if heel else ())]
    xyz = [trial[label].to_numpy() for label in ["LASI", "RASI"] + legs] + (
        [(trial["LPSI"].to_numpy() + trial["RPSI"].to_numpy()) / 2] if sacrum
        else [trial["LPSI"].to_numpy(), trial["RPSI"].to_numpy()])
    labels = [prefix + label for label in ["LASI", "RASI"] + legs + posterior]
    return write_c3d_points(path, np.stack(xyz, axis=1), labels)


def test_events_with_plug_in_gait_labels_prefixes_sacrum_and_no_heel(tmp_path):
    """`events --model plug-in-gait` without a mapping file: the events and parameters
    of the package's functions called with the roles written out by hand."""
    pytest.importorskip("ezc3d")
    from bmc_functions import read_c3d, spatiotemporal_parameters

    trial = read_c3d(PIG / "Movement_trial.c3d")
    copy = _pig_copy(tmp_path / "sub01.c3d", trial, prefix="Sub01:", sacrum=True,
                     heel=False)
    run = cli("events", "--model", "plug-in-gait", PIG / "Movement_trial.c3d", copy,
              "-o", tmp_path / "out", "-q")
    assert run.returncode == 0, run.stderr
    out = tmp_path / "out"
    by_hand = {"Movement_trial": (PIG / "Movement_trial.c3d", {
        "RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
        **{p + role: p + name for p in "RL" for role, name in (
            ("HEEL", "HEE"), ("TOE", "TOE"), ("ANKLE_LAT", "ANK"))}}),
        "sub01": (copy, {"RASIS": "Sub01:RASI", "LASIS": "Sub01:LASI",
                         "SACRUM": "Sub01:SACR",
                         **{p + role: f"Sub01:{p}{name}" for p in "RL" for role, name in (
                             ("TOE", "TOE"), ("ANKLE_LAT", "ANK"))}})}
    for stem, (path, roles) in by_hand.items():
        record = json.loads((out / f"{stem}_events.json").read_text())
        assert record["markers"] == roles
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            events = gait_events(path, roles)
            direct = spatiotemporal_parameters(events, trial=path, markers=roles)
        written = pd.read_csv(out / f"{stem}_events.csv")
        for side in ("right", "left"):
            for kind in ("heel_strike", "toe_off"):
                times = written.query("side == @side and event == @kind")["time"]
                np.testing.assert_allclose(times, events[side][kind], atol=1e-9)
        table = pd.read_csv(out / f"{stem}_parameters.csv", index_col="side")
        assert {"stride_length", "step_length", "speed", "double_support"} <= set(
            table.columns)
        numbers = direct.select_dtypes("number").columns
        np.testing.assert_allclose(table[numbers].to_numpy(float),
                                   direct[numbers].to_numpy(float))
    assert 0.3 < table.loc["right", "stride_length"] < 2.0     # metres


def test_events_without_markers_or_model_says_what_to_give(tmp_path):
    run = cli("events", PIG / "Movement_trial.c3d", "-o", tmp_path, "-q")
    assert run.returncode == 1
    assert "--markers" in run.stderr and "--model plug-in-gait" in run.stderr


def test_cycles_with_stored_events_from_a_csv_or_the_event_group(tmp_path):
    """--events stored: the events beside the trial (CSV) or in its EVENT group, one
    right stride fewer than detected, give one right cycle fewer; a trial without
    stored events is named on stderr and skipped (not a failure)."""
    ezc3d = pytest.importorskip("ezc3d")
    from bmc_functions import read_c3d, write_events

    trial = read_c3d(PIG / "Movement_trial.c3d")
    folder = tmp_path / "trials"
    folder.mkdir()
    with_csv = _pig_copy(folder / "walk_csv.c3d", trial)
    with_group = _pig_copy(folder / "walk_group.c3d", trial)
    without = _pig_copy(folder / "walk_none.c3d", trial)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        detected = gait_events(with_csv, {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI",
                                          "LPSIS": "LPSI", "RHEEL": "RHEE", "LHEEL": "LHEE",
                                          "RTOE": "RTOE", "LTOE": "LTOE"})
    stored = {side: {kind: np.asarray(times) for kind, times in found.items()}
              for side, found in detected.items()}
    stored["right"]["heel_strike"] = stored["right"]["heel_strike"][1:]
    assert stored["right"]["heel_strike"].size >= 2
    write_events(stored, folder / "walk_csv_events.csv")
    c3d = ezc3d.c3d(str(with_group))
    pairs = [(f"{side[0].upper()}{'HS' if kind == 'heel_strike' else 'TO'}", t)
             for side, found in stored.items() for kind, times in found.items()
             for t in times]
    c3d.add_parameter("EVENT", "USED", [len(pairs)])
    c3d.add_parameter("EVENT", "CONTEXTS", [context for context, _ in pairs])
    c3d.add_parameter("EVENT", "LABELS", [""] * len(pairs))
    c3d.add_parameter("EVENT", "TIMES", np.array([np.zeros(len(pairs)),
                                                  [t for _, t in pairs]]))
    c3d.write(str(with_group))     # first frame 1: the times as read_c3d's
    run = cli("cycles", "--model", "plug-in-gait", "--subject", PIG / "Movement_trial.c3d",
              "--events", "stored", with_csv, with_group, without, "-o", tmp_path / "out",
              "-q")
    assert run.returncode == 0, run.stderr
    assert "skipped: " in run.stderr and "walk_none.c3d: no stored events" in run.stderr
    out = tmp_path / "out"
    assert not (out / "walk_none_cycles.csv").exists()
    right = stored["right"]["heel_strike"].size - 1
    for stem in ("walk_csv", "walk_group"):
        cycles = pd.read_csv(out / f"{stem}_cycles.csv", index_col=[0, 1])
        assert cycles["knee.right.flexion"].dropna().index.get_level_values(0).nunique() \
            == right
        record = json.loads((out / f"{stem}_cycles.json").read_text())
        assert record["options"]["events"] == "stored"
    np.testing.assert_allclose(pd.read_csv(out / "walk_csv_cycles.csv").to_numpy(float),
                               pd.read_csv(out / "walk_group_cycles.csv").to_numpy(float),
                               atol=1e-3)     # EVENT:TIMES are float32: ~1e-7 s apart


def test_the_static_trial_has_no_events_and_nexus_static_foot(tmp_path):
    """The static trial given as a trial too: no event warning, no events file, and the
    ankle of Nexus's static processing (HEE-TOE foot), stored in the same C3D."""
    pytest.importorskip("ezc3d")
    from bmc_functions import read_c3d_model_outputs

    static = PIG / "Static_trial.c3d"
    run = cli("angles", "--model", "plug-in-gait", "--static", static, "--subject",
              PIG / "Test.vsk", static, "-o", tmp_path, "-q")
    assert run.returncode == 0, run.stderr
    assert "event" not in run.stderr and "heel strike" not in run.stderr
    assert not (tmp_path / "Static_trial_events.csv").exists()
    angles = pd.read_csv(tmp_path / "Static_trial_angles.csv", index_col="time")
    vicon = read_c3d_model_outputs(static)
    for side, p in (("right", "R"), ("left", "L")):
        for angle, axis in (("dorsiflexion", "x"), ("inversion", "y"), ("rotation", "z")):
            np.testing.assert_allclose(angles[f"ankle.{side}.{angle}"],
                                       vicon[p + "AnkleAngles"][axis], atol=1e-3)


def test_the_ensemble_title_counts_the_cycles_of_each_side(tmp_path, monkeypatch):
    """The titles are plot_gait_cycles' own: right and left counted apart."""
    pytest.importorskip("ezc3d")
    from bmc_functions import cli as cli_module

    titles = {}

    def save(fig, path, title=None):
        titles[os.path.basename(str(path))] = fig._suptitle.get_text()
        import matplotlib.pyplot as plt
        plt.close(fig)

    monkeypatch.setattr(cli_module, "_save_figure", save)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        status = main(["cycles", "--model", "plug-in-gait", "--subject",
                       str(PIG / "Movement_trial.c3d"), str(PIG / "Movement_trial.c3d"),
                       "-o", str(tmp_path), "-q"])
    assert status == 0
    cycles = pd.read_csv(tmp_path / "Movement_trial_cycles.csv", index_col=[0, 1])
    counts = {side: cycles[f"knee.{side}.flexion"].dropna().index.get_level_values(0)
              .nunique() for side in ("right", "left")}
    for name in ("Movement_trial_cycles.png", "ensemble.png"):
        for side, count in counts.items():
            assert f"{side} {count} cycle" in titles[name], titles[name]
    assert titles["Movement_trial_cycles.png"].startswith("Movement_trial.c3d")


# --- --normative (the Gait Profile Score) and --c3d ------------------------------------------

EXAMPLE_PIG = ROOT / "bmc_functions" / "example_data" / "plug_in_gait"


def _pig_args(*more):
    return ("--model", "plug-in-gait", "--static", EXAMPLE_PIG / "Static_trial.c3d",
            "--subject", EXAMPLE_PIG / "Test.vsk", *more, EXAMPLE_PIG / "Movement_trial.c3d")


def test_cycles_with_normative_data_write_the_gait_profile_score(tmp_path):
    """--normative: a normative CSV made from the trial's own cycles shifted by 4 degrees
    (write_normative_data); <stem>_gps.csv, gps.csv and the record hold the MAP and GPS
    that gait_profile_score gives in this process for the same cycles; a bad file is an
    error naming it; without --normative no GPS file."""
    pytest.importorskip("ezc3d")
    from bmc_functions import gait_profile_score, normative_data, write_normative_data

    first = cli("cycles", *_pig_args(), "-o", tmp_path / "plain", "-q")
    assert first.returncode == 0, first.stderr
    # the trial's cycles as the command wrote them (detected events)
    cycles = pd.read_csv(tmp_path / "plain" / "Movement_trial_cycles.csv",
                         index_col=["cycle", "percent"])
    cycles.columns = pd.MultiIndex.from_tuples([tuple(c.split(".")) for c in cycles])
    assert cycles.index.get_level_values("cycle").nunique() >= 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        normative = normative_data(cycles + 4.0)
        write_normative_data(normative, tmp_path / "normal.csv")
        expected = gait_profile_score(cycles, normative)
    assert not list((tmp_path / "plain").glob("*gps.csv"))
    run = cli("cycles", *_pig_args("--normative", tmp_path / "normal.csv"), "-o",
              tmp_path / "out", "-q")
    assert run.returncode == 0, run.stderr
    out = tmp_path / "out"
    for name in ("Movement_trial_gps.csv", "gps.csv"):     # one trial: the same cycles
        table = pd.read_csv(out / name, index_col="variable")
        np.testing.assert_allclose(table.loc["GPS", ["left", "right", "overall"]],
                                   expected.gps[["left", "right", "overall"]], rtol=1e-9)
        np.testing.assert_allclose(table.loc[expected.map.index, ["left", "right"]],
                                   expected.map[["left", "right"]], rtol=1e-9)
    # the normal mean (both sides pooled, normative_data) 4 degrees above: a few degrees
    assert 2.0 < expected.gps["overall"] < 10.0
    record = json.loads((out / "Movement_trial_cycles.json").read_text())
    assert record["gps_deg"]["overall"] == pytest.approx(expected.gps["overall"])
    assert record["map_deg"]["knee_flexion"]["right"] == pytest.approx(
        expected.map.loc["knee_flexion", "right"])
    assert record["options"]["normative"] == str(tmp_path / "normal.csv")
    assert (out / "Movement_trial_cycles.png").stat().st_size > 10_000
    (tmp_path / "bad.csv").write_text("joint,angle\nknee,flexion\n")
    bad = cli("cycles", *_pig_args("--normative", tmp_path / "bad.csv"), "-o",
              tmp_path / "bad", "-q")
    assert bad.returncode == 1 and f"--normative {tmp_path / 'bad.csv'}" in bad.stderr


def test_angles_c3d_writes_a_copy_that_reads_back(tmp_path):
    """--c3d: <stem>.c3d holds the angles written (read_c3d_model_outputs, to the C3D's
    float32) and the events of <stem>_events.csv (read_events); a .trc trial is refused
    naming it, and a --c3d that would overwrite its trial too."""
    pytest.importorskip("ezc3d")
    from bmc_functions import read_c3d_model_outputs, read_events

    run = cli("angles", *_pig_args("--c3d"), "-o", tmp_path, "-q")
    assert run.returncode == 0, run.stderr
    written = tmp_path / "Movement_trial.c3d"
    csv = pd.read_csv(tmp_path / "Movement_trial_angles.csv", index_col="time")
    outputs = read_c3d_model_outputs(written)
    for column, (label, coord) in {"knee.left.flexion": ("LKneeAngles", "x"),
                                   "hip.right.adduction": ("RHipAngles", "y"),
                                   "pelvis.left.rotation": ("LPelvisAngles", "z"),
                                   "foot.right.progression": ("RFootProgressAngles", "z")
                                   }.items():
        np.testing.assert_allclose(outputs[label][coord].to_numpy(), csv[column],
                                   atol=1e-3, equal_nan=True)
    events = pd.read_csv(tmp_path / "Movement_trial_events.csv")
    back = read_events(written)
    for side in ("left", "right"):
        for event in ("heel_strike", "toe_off"):
            mine = events.query("side == @side and event == @event")["time"].to_numpy()
            np.testing.assert_allclose(back[side][event], mine, atol=1e-4)
    record = json.loads((tmp_path / "Movement_trial_angles.json").read_text())
    assert str(written) in record["outputs"] and record["options"]["c3d"] is True
    # a .trc: refused, naming the trial; writing over the trial itself: refused
    trc = tmp_path / "walk.trc"
    from bmc_functions import read_c3d, write_trc

    write_trc(read_c3d(EXAMPLE_PIG / "Movement_trial.c3d"), trc)
    refused = cli("angles", *_pig_args("--c3d")[:-1], trc, "-o", tmp_path / "trc", "-q")
    assert refused.returncode == 1
    assert f"error: {trc}: --c3d copies a C3D trial" in refused.stderr
    shutil.copy(EXAMPLE_PIG / "Movement_trial.c3d", tmp_path / "here.c3d")
    over = cli("angles", *_pig_args("--c3d")[:-1], "here.c3d", "-q", cwd=tmp_path)
    assert over.returncode == 1 and "would overwrite the trial here.c3d" in over.stderr
