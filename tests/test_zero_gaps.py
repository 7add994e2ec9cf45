"""Gaps written as zeros (issue 20, item 1): a marker not seen stored as exactly
(0, 0, 0), as older Vicon systems and others write it, is a gap, in C3D and TRC files,
and the whole chain (reader, pipeline, gait events) treats it so.

Oracle: the same trial without the zeros (written here with ezc3d / write_trc).
"""

import sys
import warnings

import numpy as np
import pytest

from bmc_functions import calibrate_lower_limb, gait_events, read_c3d, read_trc, write_trc

from helpers import ROOT, SHARED_DATA

sys.path.insert(0, str(ROOT / "tests"))
from test_gait_cycles import leg_roles  # noqa: E402

CODA = SHARED_DATA / "force_plates" / "codamotion_gaitwands_20150204.c3d"
CODA_ROLES = {"RASIS": "R.ASIS", "LASIS": "L.ASIS", "RPSIS": "R.PSIS", "LPSIS": "L.PSIS",
              "RHEEL": "R.Heel", "RTOE": "R.Toe", "LHEEL": "L.Heel", "LTOE": "L.Toe"}


def write_c3d(trial, path, zero_frames=0, negative=()):
    """`trial` (a marker DataFrame, mm) as a C3D file; every marker (0, 0, 0) with a
    residual of 0 (a valid point!) in the first `zero_frames` frames, and a residual of
    -1 at the (frame, marker index) pairs of `negative`."""
    ezc3d = pytest.importorskip("ezc3d")
    labels = list(dict.fromkeys(trial.columns.get_level_values(0)))
    xyz = np.nan_to_num(trial.to_numpy(float).reshape(len(trial), len(labels), 3))
    residual = np.where(np.isnan(trial.to_numpy(float).reshape(len(trial), len(labels), 3)
                                 ).any(axis=2), -1.0, 0.0)
    xyz[:zero_frames] = 0.0
    residual[:zero_frames] = 0.0
    for frame, marker in negative:
        residual[frame, marker] = -1.0
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [float(trial.attrs["rate"])]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = tuple(labels)
    c3d["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    points = np.ones((4, len(labels), len(trial)))
    points[:3] = xyz.transpose(2, 1, 0)
    c3d["data"]["points"] = points
    c3d["data"]["meta_points"]["residuals"] = residual.T[None]
    c3d.write(str(path))
    return path


def test_zeros_and_negative_residuals_are_gaps_in_a_c3d(tmp_path):
    trial = read_trc(ROOT / "data" / "gait" / "legs_static.trc")
    path = write_c3d(trial, tmp_path / "zeros.c3d", zero_frames=7, negative=[(20, 0)])
    n_markers = trial.shape[1] // 3
    with pytest.warns(UserWarning, match=rf"{7 * n_markers} points \(frame x marker\) were "
                                         rf"exactly \(0, 0, 0\).* in {n_markers} markers .*"
                                         r"read as gaps \(NaN\); zeros_as_gaps=False keeps"):
        read = read_c3d(path)
    assert read.iloc[:7].isna().all().all() and read.iloc[7:].notna().all().all() == False
    assert read.attrs["zero_points"] == 7 * n_markers
    assert read.attrs["invalid_points"] == 1
    assert np.isnan(read.iloc[20, :3]).all()
    np.testing.assert_allclose(read.iloc[7:20].to_numpy(), trial.iloc[7:20].to_numpy(),
                               atol=1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        kept = read_c3d(path, zeros_as_gaps=False)
    assert (kept.iloc[:7].to_numpy() == 0).all() and kept.attrs["zero_points"] == 0
    with pytest.raises(TypeError, match="zeros_as_gaps must be True or False"):
        read_c3d(path, zeros_as_gaps="no")


def test_zeros_are_gaps_in_a_trc(tmp_path):
    trial = read_trc(ROOT / "data" / "gait" / "walk.trc")
    zeroed = trial.copy()
    zeroed.iloc[:5] = 0.0
    zeroed.loc[zeroed.index[10], "RHEE"] = 0.0
    zeroed.loc[zeroed.index[11], ("RTOE", "x")] = 0.0         # one coordinate: a value
    write_trc(zeroed, tmp_path / "z.trc")
    with pytest.warns(UserWarning, match=r"were exactly \(0, 0, 0\)"):
        read = read_trc(tmp_path / "z.trc")
    n_markers = trial.shape[1] // 3
    assert read.attrs["zero_points"] == 5 * n_markers + 1
    assert read.iloc[:5].isna().all().all() and read["RHEE"].iloc[10].isna().all()
    assert read.loc[read.index[11], ("RTOE", "x")] == 0.0


def test_a_static_trial_with_zero_frames_calibrates_as_the_clean_one(tmp_path):
    # the pipeline read the zeros as positions: the static means were pulled towards
    # the lab origin, and the geometry checks blamed the labels
    static = read_trc(ROOT / "data" / "gait" / "legs_static.trc")
    walk = read_trc(ROOT / "data" / "gait" / "legs_walk.trc")
    clean = write_c3d(static, tmp_path / "clean.c3d")
    zeros = write_c3d(static, tmp_path / "zeros.c3d", zero_frames=len(static) // 3)
    # the oracle: the clean trial without the frames that the zeros hide
    reference = calibrate_lower_limb(read_c3d(clean).iloc[len(static) // 3:],
                                     leg_roles()).angles(walk)
    with pytest.warns(UserWarning, match="were exactly"):
        static_read = read_c3d(zeros)
    angles = calibrate_lower_limb(static_read, leg_roles()).angles(walk)
    np.testing.assert_allclose(angles.to_numpy(), reference.to_numpy(), atol=1e-6)
    # the zeros kept as positions: the markers "move" 1.1 m to the lab origin and back
    with pytest.warns(RuntimeWarning, match="the static trial is not static: marker 'RASI' "
                                            r"moves up to 1\d\d\d mm"):
        calibrate_lower_limb(read_c3d(zeros, zeros_as_gaps=False), leg_roles())


@pytest.mark.skipif(not CODA.exists(), reason="../shared/data absent")
def test_gait_events_of_a_real_walk_whose_first_frames_are_zeros(tmp_path):
    # as the real file of the issue: every marker (0, 0, 0) for its first 226 frames
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        trial = read_c3d(CODA)
    path = write_c3d(trial, tmp_path / "zeros.c3d", zero_frames=226)
    with pytest.warns(UserWarning, match="4 markers|points"):
        zeroed = read_c3d(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        clean = gait_events(trial, CODA_ROLES)
    events = gait_events(zeroed, CODA_ROLES)
    start = 226 / 200 + 0.2
    for side in clean:
        for event in ("heel_strike", "toe_off"):
            expected = clean[side][event][clean[side][event] > start]
            found = events[side][event][events[side][event] > start]
            np.testing.assert_allclose(found, expected)
            assert np.all(events[side][event] > 226 / 200)     # nothing in the zeros
