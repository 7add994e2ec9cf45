"""Model outputs Vicon zero-filled are gaps (issue 30): read_c3d_model_outputs turns a
point exactly at (0, 0, 0), or with a negative residual, into NaN and counts it in
``attrs``, as read_c3d does for markers.

Oracles: the original file read with ezc3d (the frames left alone must come back
unchanged), and C3D files written here with ezc3d whose zeros are known.
"""

import warnings

import numpy as np
import pytest

from bmc_functions import read_c3d, read_c3d_model_outputs
from bmc_functions.examples import example_file

from helpers import SHARED_DATA, needs_shared

ezc3d = pytest.importorskip("ezc3d")

MOVEMENT = example_file("plug_in_gait/Movement_trial.c3d")


def labels_of(c3d):
    return [str(label).strip() for label in c3d["parameters"]["POINT"]["LABELS"]["value"]]


def test_zero_filled_vicon_angles_become_gaps(tmp_path):
    """The shipped Nexus trial with RKneeAngles set to (0, 0, 0), residual 0 (a valid
    point), in frames 10-40 and LHipAngles' x alone set to 0 in frame 50 (a value)."""
    c3d = ezc3d.c3d(str(MOVEMENT))
    labels = labels_of(c3d)
    knee, hip = labels.index("RKneeAngles"), labels.index("LHipAngles")
    original = read_c3d_model_outputs(MOVEMENT)
    points = c3d["data"]["points"]
    points[:3, knee, 10:41] = 0.0
    points[0, hip, 50] = 0.0
    c3d["data"]["points"] = points
    residuals = c3d["data"]["meta_points"]["residuals"]
    residuals[0, knee, 10:41] = 0.0
    c3d["data"]["meta_points"]["residuals"] = residuals
    path = tmp_path / "zeros.c3d"
    c3d.write(str(path))
    with pytest.warns(UserWarning, match=r"31 points \(frame x output\) were exactly "
                                         r"\(0, 0, 0\), the way Vicon Nexus fills an output "
                                         r"it could not compute, in 1 outputs "
                                         r"\(RKneeAngles\): read as gaps \(NaN\)"):
        out = read_c3d_model_outputs(path)
    assert out.attrs["zero_points"] == 31
    assert out.attrs["invalid_points"] == original.attrs["invalid_points"] > 0
    assert out["RKneeAngles"].iloc[10:41].isna().all().all()
    np.testing.assert_array_equal(out["RKneeAngles"].iloc[:10], original["RKneeAngles"].iloc[:10])
    np.testing.assert_array_equal(out["RKneeAngles"].iloc[41:], original["RKneeAngles"].iloc[41:])
    assert out.loc[out.index[50], ("LHipAngles", "x")] == 0.0    # one component: a value
    untouched = out.drop(columns=["RKneeAngles", "LHipAngles"], level=0)
    np.testing.assert_array_equal(untouched.to_numpy(),
                                  original.drop(columns=["RKneeAngles", "LHipAngles"],
                                                level=0).to_numpy())
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        kept = read_c3d_model_outputs(path, zeros_as_gaps=False)
    assert (kept["RKneeAngles"].iloc[10:41].to_numpy() == 0).all()
    assert kept.attrs["zero_points"] == 0
    with pytest.raises(TypeError, match="zeros_as_gaps must be True or False"):
        read_c3d_model_outputs(path, zeros_as_gaps="no")


def test_a_synthetic_c3d_with_an_angles_group(tmp_path):
    """A C3D written from scratch: two markers and two angle outputs listed in
    POINT:ANGLES, zeros and a negative residual where known."""
    rng = np.random.default_rng(30)
    labels = ["RHEE", "RTOE", "LKneeAngles", "RKneeAngles"]
    n = 20
    xyz = rng.normal(10, 5, (3, len(labels), n))
    xyz[:3, 2, 3:6] = 0.0          # LKneeAngles zero-filled in frames 3-5
    xyz[:3, 0, 7] = 0.0            # a marker at the origin: not an output, not counted
    residuals = np.zeros((1, len(labels), n))
    residuals[0, 3, 12] = -1.0     # RKneeAngles invalid in frame 12
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [100.0]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = tuple(labels)
    c3d["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    c3d.add_parameter("POINT", "ANGLES", ["LKneeAngles", "RKneeAngles"])
    c3d.add_parameter("POINT", "ANGLE_UNITS", ["deg"])
    points = np.ones((4, len(labels), n))
    points[:3] = xyz
    c3d["data"]["points"] = points
    c3d["data"]["meta_points"]["residuals"] = residuals
    path = tmp_path / "synthetic.c3d"
    c3d.write(str(path))
    with pytest.warns(UserWarning, match=r"3 points \(frame x output\).*\(LKneeAngles\)"):
        out = read_c3d_model_outputs(path)
    assert list(out.columns.get_level_values(0).unique()) == ["LKneeAngles", "RKneeAngles"]
    assert out.attrs["zero_points"] == 3 and out.attrs["invalid_points"] == 1
    expected = xyz[:, 2:].transpose(2, 1, 0).copy()       # frames, outputs, xyz
    expected[3:6, 0] = np.nan
    expected[12, 1] = np.nan
    np.testing.assert_allclose(out.to_numpy().reshape(n, 2, 3), expected, rtol=1e-6)
    assert out.attrs["units"] == {"ANGLES": "deg"}
    markers = read_c3d(path, zeros_as_gaps=False)          # the markers are read_c3d's
    assert markers.attrs["dropped_labels"] == ["LKneeAngles", "RKneeAngles"]


@needs_shared("plug_in_gait/Movement_trial.c3d", "plug_in_gait/Static_trial.c3d")
@pytest.mark.parametrize("name, invalid", [("Movement_trial", 1680), ("Static_trial", 0)])
def test_the_shared_nexus_files_have_no_zero_filled_outputs(name, invalid):
    """Nexus 2.6.1 marked the outputs it could not compute with a negative residual in
    these files (the first frames' powers and forces, the ground reaction away from a
    plate), never with zeros: nothing is taken away from them, and every NaN is one
    ezc3d reads with a negative residual."""
    path = SHARED_DATA / "plug_in_gait" / f"{name}.c3d"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = read_c3d_model_outputs(path)
    assert out.attrs["zero_points"] == 0 and out.attrs["invalid_points"] == invalid
    c3d = ezc3d.c3d(str(path))
    labels = labels_of(c3d)
    index = [labels.index(label) for label in out.columns.get_level_values(0)[::3]]
    negative = c3d["data"]["meta_points"]["residuals"][0, index].T < 0
    values = out.to_numpy().reshape(len(out), -1, 3)
    np.testing.assert_array_equal(np.isnan(values).all(axis=2), negative)
    np.testing.assert_array_equal(values[~negative],
                                  c3d["data"]["points"][:3, index].transpose(2, 1, 0)[~negative])
