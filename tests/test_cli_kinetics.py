"""The command line's kinetics with Plug-in Gait (issues 29 and 30), end to end in
subprocesses on the Nexus stair descent (Static_trial.c3d, Movement_trial.c3d, Test.vsk,
Bodymass 85 kg; shipped in bmc_functions/example_data, the copy of ../shared/data's):
what the command writes equals PlugInGait.kinetics called in this process, and matches
the moments Vicon Nexus stored in the same C3D (plates 1 and 4, as Nexus used them);
the --c3d copy reads back as Vicon's names and units; a trial without force plates is
named and its kinetics skipped; every new error of the options."""

import json
import os
import subprocess
import sys
import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import (gait_events, normative_data, plug_in_gait, read_c3d,
                           read_c3d_model_outputs, write_normative_data)
from bmc_functions.cli import _kinetics_cycles, main

from helpers import ROOT, write_c3d_points

PIG = ROOT / "bmc_functions" / "example_data" / "plug_in_gait"
STATIC, VSK, WALK = PIG / "Static_trial.c3d", PIG / "Test.vsk", PIG / "Movement_trial.c3d"
VICON_PLATES = {2: None, 3: None}     # Nexus used plates 1 (left) and 4 (right) only
MOMENT_RMS = 0.02                     # issue 29: N m/kg, in the plate stances


def cli(*args, cwd=None):
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    return subprocess.run([sys.executable, "-m", "bmc_functions", *map(str, args)],
                          capture_output=True, text=True, cwd=cwd, env=env, timeout=600)


def read_flat(path, index):
    table = pd.read_csv(path, index_col=index)
    table.columns = pd.MultiIndex.from_tuples([tuple(c.split(".")) for c in table.columns])
    return table


@pytest.fixture(scope="module")
def model():
    pytest.importorskip("ezc3d")
    return plug_in_gait(STATIC, VSK)


@pytest.fixture(scope="module")
def expected(model):
    """PlugInGait.kinetics with Nexus's plates, in this process: the oracle of the CLI."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return model.kinetics(WALK, plates=VICON_PLATES)


@pytest.fixture(scope="module")
def angles_run(tmp_path_factory, model):
    """One `angles --kinetics --plates 1,4 --c3d` run: the walk, the static trial, and a
    copy of the walk's markers without force plates."""
    folder = tmp_path_factory.mktemp("angles")
    markers = read_c3d(WALK)
    labels = list(dict.fromkeys(markers.columns.get_level_values(0)))
    write_c3d_points(folder / "NoPlates.c3d", markers.to_numpy().reshape(len(markers), -1, 3),
                     labels, rate=markers.attrs["rate"])
    run = cli("angles", "--model", "plug-in-gait", "--static", STATIC, "--subject", VSK,
              "--kinetics", "--plates", "1,4", "--c3d", WALK, STATIC,
              folder / "NoPlates.c3d", "-o", folder / "out", "-q")
    return run, folder


def test_angles_kinetics_are_plug_in_gait_kinetics_and_vicon_s(angles_run, expected):
    """<stem>_kinetics.csv = PlugInGait.kinetics(plates={2: None, 3: None}), and each
    moment within 0.02 N m/kg RMS of Vicon's stored curve in the stances on plates 1, 4."""
    run, folder = angles_run
    assert run.returncode == 0, run.stderr
    written = read_flat(folder / "out" / "Movement_trial_kinetics.csv", "time")
    assert written.shape == (323, 42)
    np.testing.assert_allclose(written.to_numpy(), expected.to_numpy(), rtol=1e-12,
                               atol=1e-12)
    vicon = read_c3d_model_outputs(WALK)
    time = written.index.to_numpy()
    worst = 0.0
    for side, p in (("right", "R"), ("left", "L")):
        stance = np.zeros(len(time), bool)
        for row in expected.attrs["plates"]:
            if row["side"] == side:
                stance |= (time >= row["start"] - 1e-9) & (time <= row["stop"] + 1e-9)
        assert stance.sum() > 60
        for joint in ("hip", "knee", "ankle"):
            for k, axis in enumerate("xyz"):
                ours = written[joint, side, f"moment_{axis}"].to_numpy()[stance]
                stored = vicon[f"{p}{joint.capitalize()}Moment"][axis].to_numpy()[stance]
                rms = np.sqrt(np.mean((ours - stored / 1000.0) ** 2))
                worst = max(worst, rms)
    assert worst < MOMENT_RMS      # 0.0024 N m/kg measured (hip, right)
    assert (folder / "out" / "Movement_trial_kinetics.png").stat().st_size > 10_000


def test_angles_kinetics_record_holds_the_plates_and_segments(angles_run):
    run, folder = angles_run
    record = json.loads((folder / "out" / "Movement_trial_angles.json").read_text())
    assert record["options"]["kinetics"] is True
    assert record["options"]["plates"] == [[1, None], [4, None]]
    attrs = record["kinetics"]["attrs"]
    assert attrs["body_mass_kg"] == 85.0                 # Test.vsk's Bodymass
    assert attrs["segments"]["thigh"]["mass"] == 0.1
    assert [row["side"] for row in attrs["plates"]] == ["left", None, None, "right"]
    assert attrs["options"]["plates"] == {"2": None, "3": None}
    assert "measurements" not in attrs                  # in the record's subject already
    assert record["kinetics"]["forces"].endswith("(its force plates)")
    assert any(name.endswith("Movement_trial_kinetics.csv") for name in record["outputs"])


def test_a_trial_without_plates_is_named_and_its_kinetics_skipped(angles_run):
    run, folder = angles_run
    trial = folder / "NoPlates.c3d"
    assert f"warning: {trial}: kinetics skipped: {trial} has no force plates" in run.stderr
    assert (folder / "out" / "NoPlates_angles.csv").exists()
    assert not (folder / "out" / "NoPlates_kinetics.csv").exists()
    record = json.loads((folder / "out" / "NoPlates_angles.json").read_text())
    assert record["kinetics"]["skipped"].startswith("kinetics skipped")
    # the static trial: no kinetics, said in its record
    assert not (folder / "out" / "Static_trial_kinetics.csv").exists()
    static = json.loads((folder / "out" / "Static_trial_angles.json").read_text())
    assert static["kinetics"] == {"skipped": "the static trial (--static)"}


def test_the_c3d_copy_holds_vicon_s_kinetic_points(angles_run, expected):
    """--c3d with --kinetics: LKneeMoment (N mm/kg), RAnklePower Z (W/kg), LHipForce
    (N/kg) read back by read_c3d_model_outputs as the table computed; NaN stays a gap."""
    _, folder = angles_run
    copy = read_c3d_model_outputs(folder / "out" / "Movement_trial.c3d")
    for (joint, side, quantity), (label, coord, factor) in {
            ("knee", "left", "moment_x"): ("LKneeMoment", "x", 1000.0),
            ("hip", "right", "moment_y"): ("RHipMoment", "y", 1000.0),
            ("ankle", "right", "power"): ("RAnklePower", "z", 1.0),
            ("hip", "left", "force_z"): ("LHipForce", "z", 1.0)}.items():
        ours = expected[joint, side, quantity].to_numpy()
        np.testing.assert_allclose(copy[label][coord].to_numpy() / factor, ours,
                                   rtol=1e-6, atol=1e-6, equal_nan=True)
        assert np.isnan(ours).sum() > 20           # the unmeasured stances: gaps
    assert copy.attrs["groups"]["LKneeMoment"] == "MOMENTS"
    assert copy.attrs["groups"]["RAnklePower"] == "POWERS"


@pytest.fixture(scope="module")
def cycles_run(tmp_path_factory, model):
    """`cycles --kinetics --body-mass 90 --normative` with a normative file that holds
    angles and kinetics (the trial's own cycles, shifted)."""
    folder = tmp_path_factory.mktemp("cycles")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        angles = model.angles(WALK)
        kinetics = model.kinetics(WALK, body_mass=90.0)
        events = gait_events(WALK, model.event_markers())
        from bmc_functions import normalize_by_side

        cycles = normalize_by_side(angles, events)
        loads = _kinetics_cycles(kinetics, events)
        write_normative_data(normative_data(pd.concat([cycles + 3.0, loads], axis=1)),
                             folder / "normal.csv")
    run = cli("cycles", "--model", "plug-in-gait", "--static", STATIC, "--subject", VSK,
              "--kinetics", "--body-mass", "90", "--normative", folder / "normal.csv",
              WALK, "-o", folder / "out", "-q")
    return run, folder, loads


def test_cycles_kinetics_in_the_report(cycles_run):
    """<stem>_kinetics_cycles.csv: the kinetics of --body-mass 90 on the detected cycles;
    the report figure taller than the angles alone (the moments and powers rows); the
    ensemble holds the kinetics columns; the record says the body mass used."""
    run, folder, loads = cycles_run
    assert run.returncode == 0, run.stderr
    out = folder / "out"
    written = read_flat(out / "Movement_trial_kinetics_cycles.csv", ["cycle", "percent"])
    np.testing.assert_allclose(written.to_numpy(), loads.to_numpy(), rtol=1e-12,
                               atol=1e-12, equal_nan=True)
    # every cycle keeps its measured stance and swing (normalize_by_side alone: all NaN)
    right = written["knee", "right", "moment_x"].unstack(0)
    assert np.isfinite(right.iloc[:60, 0]).all()
    record = json.loads((out / "Movement_trial_cycles.json").read_text())
    assert record["kinetics"]["attrs"]["body_mass_kg"] == 90.0
    assert "gps_deg" in record
    import matplotlib.image

    height = matplotlib.image.imread(out / "Movement_trial_cycles.png").shape[0]
    assert height == pytest.approx(100 * 2.3 * (12 + 3), abs=2)   # 12 angle rows + 3
    ensemble = pd.read_csv(out / "ensemble.csv", index_col=0)
    assert "mean:ankle.right.power" in ensemble.columns


def test_kinetics_cycles_keep_the_measured_points():
    """_kinetics_cycles: NaN only where the kinetics are missing, each point with the
    value normalize_by_side gives where nothing is missing (a synthetic signal)."""
    from bmc_functions import normalize_by_side

    time = np.arange(0, 3.0, 0.01)
    columns = pd.MultiIndex.from_tuples([("knee", "right", "moment_x")])
    full = pd.DataFrame(np.sin(time), index=time, columns=columns)
    holed = full.copy()
    holed[(time > 1.5) & (time < 2.0)] = np.nan           # the second cycle's middle
    events = {"right": {"heel_strike": np.array([0.5, 1.3, 2.2])}}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = normalize_by_side(full, events)
    cycles = _kinetics_cycles(holed, events)
    second = cycles.loc[1, ("knee", "right", "moment_x")].to_numpy()
    percent = cycles.loc[1].index.to_numpy()
    t = 1.3 + percent / 100 * 0.9
    assert np.isnan(second[(t > 1.52) & (t < 1.98)]).all()
    keep = (t < 1.48) | (t > 2.02)
    np.testing.assert_allclose(second[keep], plain.loc[1].to_numpy()[keep, 0], atol=1e-3)
    np.testing.assert_allclose(cycles.loc[0].to_numpy(), plain.loc[0].to_numpy(),
                               atol=1e-12)


# --- errors of the options (in this process: they stop before any trial) ---------------------

def pig(*more):
    return ["--model", "plug-in-gait", "--static", str(STATIC), "--subject", str(VSK), *more]


@pytest.mark.parametrize("argv, message", [
    (["angles", *pig("--plates", "1,4"), str(WALK)], "--plates belong(s) to --kinetics"),
    (["angles", *pig("--kinetics", "--forces", "x.mot"), str(WALK)],
     "--forces belongs to --model isb"),
    (["angles", *pig("--kinetics", "--body-mass", "-5"), str(WALK)],
     "--body-mass: expected the subject's mass in kg"),
    (["cycles", "--markers", "m.toml", "--kinetics", "--plates", "1", "--body-mass", "70",
      str(WALK)], "--plates belongs to --model plug-in-gait"),
    (["angles", "--keypoints", "body25b", "--kinetics", str(WALK)],
     "--kinetics needs a marker model"),
])
def test_option_errors(tmp_path, capsys, argv, message):
    assert main([*argv, "-o", str(tmp_path), "-q"]) == 1
    assert message in capsys.readouterr().err


def test_a_bad_plate_list_is_a_usage_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["angles", *pig("--kinetics", "--plates", "1,x"), str(WALK), "-o",
              str(tmp_path)])
    assert stop.value.code == 2
    assert "argument --plates: expected plate numbers from 1" in capsys.readouterr().err


def test_a_plate_the_trial_lacks_fails_the_trial(tmp_path, capsys):
    pytest.importorskip("ezc3d")
    assert main(["angles", *pig("--kinetics", "--plates", "1,7"), str(WALK), "-o",
                 str(tmp_path), "-q"]) == 1
    err = capsys.readouterr().err
    assert f"error: {WALK}: --plates 7: {WALK} has 4 force plate(s)" in err


def test_a_subject_without_bodymass_needs_body_mass(tmp_path, capsys):
    pytest.importorskip("ezc3d")
    from bmc_functions import read_vsk

    values = {k: v for k, v in read_vsk(VSK).items()
              if k != "Bodymass" and isinstance(v, (int, float))}
    (tmp_path / "subject.toml").write_text("".join(f"{k} = {float(v)!r}\n"
                                                   for k, v in values.items()))
    argv = ["angles", "--model", "plug-in-gait", "--static", str(STATIC), "--subject",
            str(tmp_path / "subject.toml"), "--kinetics", str(WALK), "-o",
            str(tmp_path / "out"), "-q"]
    assert main(argv) == 1
    assert f"--kinetics: the subject ({tmp_path / 'subject.toml'}) gives no Bodymass: " \
           "give --body-mass (kg)" in capsys.readouterr().err
    assert not (tmp_path / "out" / "Movement_trial_angles.csv").exists()
