"""write_c3d (issue 30): a copy of the trial with the package's outputs and events, read
back by ezc3d and by the package (round trip)."""

import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import (gait_events, plug_in_gait, read_c3d, read_c3d_model_outputs,
                           read_events, write_c3d)
from bmc_functions.examples import example_file
from bmc_functions.files.c3d_writer import ANGLE_COMPONENTS, VICON_ANGLE_LABELS
from bmc_functions.models.plug_in_gait import VICON_OUTPUTS

ezc3d = pytest.importorskip("ezc3d")

TRIAL = example_file("plug_in_gait/Movement_trial.c3d")


@pytest.fixture(scope="module")
def processed():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = plug_in_gait(example_file("plug_in_gait/Static_trial.c3d"),
                             example_file("plug_in_gait/Test.vsk"))
        angles = model.angles(TRIAL)
        events = gait_events(TRIAL, model.event_markers())
    return angles, events


def test_the_nexus_trial_round_trips(processed, tmp_path):
    angles, events = processed
    vicon = read_c3d_model_outputs(TRIAL)
    kinetics = 2.0 * vicon[["LKneeMoment", "RHipPower"]]          # known, changed values
    kinetics.attrs = {"groups": {"LKneeMoment": "MOMENTS", "RHipPower": "POWERS"}}
    renamed = angles.copy()                        # a new label as well as Vicon's ones
    renamed[("trunk", "left", "flexion")] = 1.0 + angles[("hip", "left", "flexion")]
    path = write_c3d(tmp_path / "processed", TRIAL, angles=renamed, kinetics=kinetics,
                     events=events)
    assert path.name == "processed.c3d"
    # the markers and Vicon's other outputs are unchanged
    original = read_c3d(TRIAL)
    copy = read_c3d(path)
    np.testing.assert_array_equal(copy.to_numpy(), original.to_numpy())
    assert list(copy.columns) == list(original.columns)
    out = read_c3d_model_outputs(path)
    for column, (label, coord) in {("knee", "left", "flexion"): ("LKneeAngles", "x"),
                                   ("pelvis", "right", "obliquity"): ("RPelvisAngles", "y"),
                                   ("ankle", "left", "rotation"): ("LAnkleAngles", "z"),
                                   ("foot", "right", "progression"):
                                       ("RFootProgressAngles", "z")}.items():
        np.testing.assert_allclose(out[(label, coord)], angles[column], atol=1e-4)
    np.testing.assert_allclose(out["LTrunkAngles"]["x"],
                               1.0 + angles[("hip", "left", "flexion")], atol=1e-4)
    assert (out["RFootProgressAngles"][["x", "y"]].to_numpy() == 0).all()
    np.testing.assert_allclose(out["LKneeMoment"], kinetics["LKneeMoment"], rtol=1e-6)
    assert np.isnan(out["RHipPower"].to_numpy()).sum() == np.isnan(
        kinetics["RHipPower"].to_numpy()).sum()       # Vicon's invalid frames stay invalid
    untouched = vicon.drop(columns=["LKneeMoment", "RHipPower"], level=0)
    untouched = untouched.drop(columns=[c for c in untouched.columns.get_level_values(0)
                                        if c.endswith("Angles") and c[1:] in {
                                            "PelvisAngles", "HipAngles", "KneeAngles",
                                            "AnkleAngles", "FootProgressAngles",
                                            "HeadAngles", "ThoraxAngles", "NeckAngles",
                                            "SpineAngles", "ShoulderAngles", "ElbowAngles",
                                            "WristAngles"}], level=0)
    np.testing.assert_array_equal(out[untouched.columns].to_numpy(), untouched.to_numpy())
    assert out.attrs["groups"]["LTrunkAngles"] == "ANGLES"
    assert out.attrs["groups"]["RHipPower"] == "POWERS"
    back = read_events(path)
    for side in ("right", "left"):
        for event in ("heel_strike", "toe_off"):
            np.testing.assert_allclose(back[side][event], events[side][event], atol=1e-5)
    # ezc3d reads the file directly, with the analog channels of the original
    c3d = ezc3d.c3d(str(path))
    source = ezc3d.c3d(str(TRIAL))
    np.testing.assert_array_equal(c3d["data"]["analogs"], source["data"]["analogs"])
    assert "LTrunkAngles" in c3d["parameters"]["POINT"]["ANGLES"]["value"]
    assert c3d["parameters"]["EVENT"]["USED"]["value"][0] == sum(
        len(times) for found in events.values() for times in found.values())
    assert set(c3d["parameters"]["EVENT"]["CONTEXTS"]["value"]) == {"Right", "Left"}


def test_a_marker_table_is_written_as_a_new_c3d(tmp_path):
    trial = read_c3d(TRIAL)
    trial.iloc[5:8, :3] = np.nan                                  # a gap stays a gap
    index = trial.index[::2]
    angles = pd.DataFrame({("knee", "right", "flexion"): np.linspace(10, 50, len(index))},
                          index=index)
    path = write_c3d(tmp_path / "markers.c3d", trial, angles=angles)
    back = read_c3d(path)
    np.testing.assert_allclose(back.to_numpy(), trial.to_numpy(), atol=1e-3)  # float32
    out = read_c3d_model_outputs(path)
    np.testing.assert_allclose(out.loc[index, ("RKneeAngles", "x")], angles.iloc[:, 0],
                               atol=1e-5)
    assert out["RKneeAngles"].iloc[1::2].isna().all().all()   # frames without a row


@pytest.mark.parametrize("arguments, error, message", [
    (dict(angles=pd.DataFrame({("knee", "right", "bending"): [1.0]}, index=[0.0])),
     ValueError, "angles: column .*the angle one of tilt"),
    (dict(angles=pd.DataFrame({("knee", "right", "flexion"): [1.0]}, index=[0.004])),
     ValueError, "angles: the times of its rows must be the trial's frames"),
    (dict(kinetics=pd.DataFrame({"a": [1.0]})), ValueError, "kinetics must be a DataFrame"),
    (dict(events={"middle": {"heel_strike": [0.5]}}), ValueError, "sides must be"),
    (dict(trial=42), TypeError, "trial must be a C3D file's path or a marker DataFrame"),
])
def test_bad_arguments_are_named(tmp_path, arguments, error, message):
    call = dict(path=tmp_path / "x.c3d", trial=TRIAL)
    call.update(arguments)
    with pytest.raises(error, match=message):
        write_c3d(**call)


def test_a_missing_folder_is_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="path: the folder"):
        write_c3d(tmp_path / "nowhere" / "x.c3d", TRIAL)


def test_the_writer_names_angles_as_plug_in_gait_does():
    """write_c3d (files layer, below the models) names the angles by a rule of its own:
    it must agree with Plug-in Gait's table of Vicon's outputs."""
    for (joint, angle), (label, component) in VICON_OUTPUTS.items():
        assert VICON_ANGLE_LABELS[joint] == label and ANGLE_COMPONENTS[angle] == component
