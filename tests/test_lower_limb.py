"""calibrate_lower_limb / lower_limb_angles: synthetic truth, real data, every listed error."""

import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import calibrate_lower_limb, lower_limb_angles, read_trc
from bmc_functions.lower_limb import LowerLimbKinematics

from helpers import ROOT, SHARED_DATA

MARKERS_DIR = ROOT / "data" / "markers"


def right_markers(**extra):
    markers = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
               "PELVIS": ["PEL1", "PEL2", "PEL3"],
               "RTHIGH": ["RTH1", "RTH2", "RTH3", "RTH4"], "RSHANK": ["RTB1", "RTB2", "RTB3"],
               "RKNEE_LAT": "RLFC", "RKNEE_MED": "RMFC", "RANKLE_LAT": "RLMAL",
               "RANKLE_MED": "RMMAL", "RHEEL": "RHEEL", "RTOE": "RTOE", "RMT5": "RMT5"}
    markers.update(extra)
    return markers


def _with_foot(df, truth):
    """Add heel, toe and MT5 markers fixed to the true shank (ankle angles are then 0)."""
    R = truth[[f"shank_R{i}{j}" for i in range(3) for j in range(3)]].to_numpy().reshape(-1, 3, 3)
    origin = truth[["shank_ox", "shank_oy", "shank_oz"]].to_numpy()
    out = df.copy()
    for name, local in (("RHEEL", (-55.0, -45.0, 0.0)), ("RTOE", (150.0, -45.0, 0.0)),
                        ("RMT5", (115.0, -45.0, 35.0))):
        xyz = np.einsum("fij,j->fi", R, local) + origin
        for k, c in enumerate("xyz"):
            out[(name, c)] = xyz[:, k]
    return out


@pytest.fixture(scope="module")
def synthetic():
    static = read_trc(MARKERS_DIR / "static.trc")
    walk = read_trc(MARKERS_DIR / "walk.trc")
    truth_static = pd.read_csv(MARKERS_DIR / "static_truth.csv")
    truth_walk = pd.read_csv(MARKERS_DIR / "walk_truth.csv")
    static = _with_foot(static, truth_static)
    walk = _with_foot(walk, truth_walk)
    for df in (static, walk):
        df.attrs["units"] = "mm"
    return static, walk, truth_walk


def quiet(function, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return function(*args, **kwargs)


# --- the interface ------------------------------------------------------------------------

def test_columns_index_and_attrs(synthetic):
    static, walk, _ = synthetic
    model = calibrate_lower_limb(static, right_markers())
    angles = quiet(model.angles, walk)
    assert angles.index.equals(walk.index)
    assert angles.columns.names == ["joint", "side", "angle"]
    assert list(angles.columns) == [
        ("pelvis", "right", "tilt"), ("pelvis", "right", "obliquity"),
        ("pelvis", "right", "rotation"), ("hip", "right", "flexion"),
        ("hip", "right", "adduction"), ("hip", "right", "rotation"),
        ("knee", "right", "flexion"), ("knee", "right", "adduction"),
        ("knee", "right", "rotation"), ("ankle", "right", "dorsiflexion"),
        ("ankle", "right", "inversion"), ("ankle", "right", "rotation")]
    assert angles.attrs["units"] == "deg" and angles.attrs["marker_units"] == "mm"


def test_knee_angles_follow_the_truth_and_ankle_is_zero(synthetic):
    static, walk, truth = synthetic
    result = quiet(calibrate_lower_limb(static, right_markers()).track, walk)
    assert isinstance(result, LowerLimbKinematics)
    knee = result.angles["knee"]["right"].to_numpy()
    true = truth[["knee_flexion", "knee_adduction", "knee_internal_rotation"]].to_numpy()
    ok = np.isfinite(knee[:, 0])
    # the artefact and noise of the files: same bounds as notebook 07 found
    assert np.abs(knee[ok, 0] - true[ok, 0]).max() < 5
    assert np.corrcoef(knee[ok, 0], true[ok, 0])[0, 1] > 0.99
    ankle = result.angles["ankle"]["right"].to_numpy()
    # foot fixed to the true shank: only the shank's tracking error remains
    assert np.nanmax(np.abs(ankle)) < 20


def test_path_and_dataframe_give_the_same(synthetic, tmp_path):
    static = read_trc(MARKERS_DIR / "static.trc")
    markers = right_markers()
    for role in ("RHEEL", "RTOE", "RMT5"):
        del markers[role]
    markers.update(RHEEL="RLMAL", RTOE="RTB1", RMT5="RLFC")   # any markers: same both ways
    with pytest.raises(ValueError):   # RLFC etc. are landmarks missing in the dynamic trial
        quiet(lower_limb_angles, MARKERS_DIR / "static.trc", MARKERS_DIR / "walk.trc", markers)


def test_gap_gives_nan_only_where_the_cluster_is_needed(synthetic):
    static, walk, _ = synthetic
    model = calibrate_lower_limb(static, right_markers())
    with pytest.warns(RuntimeWarning, match=r"8 of 111 frames .* RSHANK .*knee and ankle"):
        angles = model.angles(walk)
    shank_gap = np.arange(70, 78)
    assert angles["knee"].iloc[shank_gap].isna().all().all()
    assert angles["ankle"].iloc[shank_gap].isna().all().all()
    assert angles["hip"].iloc[shank_gap].notna().all().all()
    pelvis_gap = np.arange(90, 96)
    assert angles["hip"].iloc[pelvis_gap].isna().all().all()
    assert angles["pelvis"].iloc[pelvis_gap].isna().all().all()
    assert angles["knee"].iloc[pelvis_gap].notna().all().all()
    others = np.setdiff1d(np.arange(len(walk)), np.r_[shank_gap, pelvis_gap])
    assert angles.iloc[others].notna().all().all()


# --- errors and warnings ------------------------------------------------------------------

def test_missing_role(synthetic):
    static, _, _ = synthetic
    markers = right_markers()
    markers["RKNEE_MEDIAL"] = markers.pop("RKNEE_MED")
    with pytest.raises(ValueError, match=r"unknown role 'RKNEE_MEDIAL'.*'RKNEE_MED'"):
        calibrate_lower_limb(static, markers)
    del markers["RKNEE_MEDIAL"]
    with pytest.raises(ValueError, match=r"role 'RKNEE_MED' \(right medial femoral "
                                         r"epicondyle\) is missing"):
        calibrate_lower_limb(static, markers)


def test_missing_label_names_close_labels(synthetic):
    static, _, _ = synthetic
    with pytest.raises(ValueError, match=r"markers\['RKNEE_MED'\] = 'R.MFC'.*look close: "
                                         r"'RMFC'"):
        calibrate_lower_limb(static, right_markers(RKNEE_MED="R.MFC"))


def test_cluster_needs_three_labels(synthetic):
    static, _, _ = synthetic
    with pytest.raises(ValueError, match=r"RSHANK.*3 or more labels"):
        calibrate_lower_limb(static, right_markers(RSHANK=["RTB1", "RTB2"]))
    with pytest.raises(ValueError, match=r"RSHANK.*list of 3 or more"):
        calibrate_lower_limb(static, right_markers(RSHANK="RTB1"))


def test_wrong_types(synthetic):
    static, _, _ = synthetic
    with pytest.raises(TypeError, match="markers must be a dict"):
        calibrate_lower_limb(static, [("RASIS", "RASI")])
    with pytest.raises(TypeError, match="static must be a DataFrame"):
        calibrate_lower_limb(42, right_markers())
    with pytest.raises(ValueError, match="hip_centre must be one of"):
        calibrate_lower_limb(static, right_markers(), hip_centre="sphere")


def test_lateral_medial_knee_swapped(synthetic):
    static, _, _ = synthetic
    with pytest.raises(ValueError, match=r"right knee: RKNEE_LAT \('RMFC'\) lies medial to "
                                         r"RKNEE_MED \('RLFC'\).*swapped"):
        calibrate_lower_limb(static, right_markers(RKNEE_LAT="RMFC", RKNEE_MED="RLFC"))


def test_lateral_medial_ankle_swapped(synthetic):
    static, _, _ = synthetic
    with pytest.raises(ValueError, match=r"right ankle: RANKLE_LAT \('RMMAL'\).*swapped"):
        calibrate_lower_limb(static, right_markers(RANKLE_LAT="RMMAL", RANKLE_MED="RLMAL"))


def test_left_right_pelvis_swapped(synthetic):
    static, _, _ = synthetic
    with pytest.raises(ValueError, match=r"RASIS \('LASI'\) lies to the subject's left.*"
                                         r"swapped"):
        calibrate_lower_limb(static, right_markers(RASIS="LASI", LASIS="RASI",
                                                   RPSIS="LPSI", LPSIS="RPSI"))


def test_leg_on_the_wrong_side(synthetic):
    static, _, _ = synthetic
    mirrored = static.copy()
    z = [c for c in mirrored.columns if c[1] == "z"]
    mirrored[z] = -mirrored[z]          # the leg is now a left leg, still called R...
    mirrored = mirrored.rename(columns={"RASI": "LASI", "LASI": "RASI",
                                        "RPSI": "LPSI", "LPSI": "RPSI"}, level=0)
    with pytest.raises(ValueError, match=r"right knee markers \('RLFC', 'RMFC'\) lie on "
                                         r"the subject's left side"):
        calibrate_lower_limb(mirrored, right_markers())


def test_cluster_on_the_wrong_segment(synthetic):
    static, _, _ = synthetic
    with pytest.raises(ValueError, match=r"right shank cluster RSHANK \(RTH1, RTH2, RTH3\) "
                                         r"lies above the knee"):
        calibrate_lower_limb(static, right_markers(RSHANK=["RTH1", "RTH2", "RTH3"]))
    with pytest.raises(ValueError, match=r"right thigh cluster RTHIGH \(RTB1, RTB2, RTB3\) "
                                         r"lies below the knee"):
        calibrate_lower_limb(static, right_markers(RTHIGH=["RTB1", "RTB2", "RTB3"]))


def test_static_that_moves(synthetic):
    static, walk, _ = synthetic
    moving = walk.copy()
    for name in ("RASI", "LASI", "RPSI", "LPSI", "RLFC", "RMFC", "RLMAL", "RMMAL"):
        for c in "xyz":                      # the landmarks of the static, carried along
            moving[(name, c)] = static[(name, c)].iloc[0] + (
                walk[("PEL2", c)] - walk[("PEL2", c)].iloc[0]).to_numpy()
    with pytest.warns(RuntimeWarning, match=r"is not static: marker '\w+' moves up to "
                                            r"1[0-9]{3} mm.*about 40 mm"):
        quiet_other = calibrate_lower_limb
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=".*collinear")
            try:
                quiet_other(moving.ffill().bfill(), right_markers())
            except ValueError:
                pass


def test_nearly_collinear_cluster(synthetic):
    static, _, _ = synthetic
    s = static.copy()
    a, b = s["RTB1"].to_numpy(), s["RTB2"].to_numpy()
    s[[("RTB3", c) for c in "xyz"]] = (a + b) / 2 + 0.5 * (a - b)[:, [1, 2, 0]] / 100
    with pytest.warns(RuntimeWarning, match=r"right shank cluster RSHANK \(RTB1, RTB2, "
                                            r"RTB3\) is nearly collinear"):
        calibrate_lower_limb(s, right_markers())


def test_deforming_cluster(synthetic):
    static, walk, _ = synthetic
    model = calibrate_lower_limb(static, right_markers())
    bad = walk.copy()
    bad.loc[bad.index[10:20], ("RTH2", "x")] += 60.0           # a loose marker
    with pytest.warns(RuntimeWarning, match=r"right thigh cluster RTHIGH \(RTH1, RTH2, RTH3, "
                                            r"RTH4\) deforms in 10 of 111 frames"):
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=".*fewer than 3")
            model.angles(bad)


def test_metres_and_millimetres_agree(synthetic):
    static, walk, _ = synthetic
    in_m = [df / 1000 for df in (static, walk)]
    for df in in_m:
        df.attrs["units"] = "m"
    a_mm = quiet(lower_limb_angles, static, walk, right_markers())
    a_m = quiet(lower_limb_angles, in_m[0], in_m[1], right_markers())
    assert a_m.attrs["marker_units"] == "m"
    np.testing.assert_allclose(a_m.to_numpy(), a_mm.to_numpy(), atol=1e-9)


def test_units_missing_or_unknown(synthetic):
    static, _, _ = synthetic
    s = static.copy()
    s.attrs = {}
    with pytest.raises(ValueError, match=r"has no units: set df.attrs\['units'\]"):
        calibrate_lower_limb(s, right_markers())
    s.attrs["units"] = "in"
    with pytest.raises(ValueError, match=r"units 'in' are not supported"):
        calibrate_lower_limb(s, right_markers())


def test_many_trials_one_long_frame(synthetic):
    static, walk, _ = synthetic
    out = quiet(lower_limb_angles, static, [walk, walk.iloc[:50]], right_markers(),
                progress=False)
    assert out.index.names == ["trial", "time"]
    assert list(out.index.get_level_values(0).unique()) == ["0", "1"]
    assert len(out.loc["1"]) == 50
    np.testing.assert_allclose(out.loc["1"].to_numpy(), out.loc["0"].iloc[:50].to_numpy(),
                               atol=1e-9)


def test_static_offset_zeroes_the_static_posture(synthetic):
    static, _, _ = synthetic
    model = calibrate_lower_limb(static, right_markers(), static_offset=True)
    angles = quiet(model.angles, static)
    joints = angles.drop(columns="pelvis", level=0)
    assert np.abs(joints.mean().to_numpy()).max() < 0.5


# --- real data ----------------------------------------------------------------------------

needs_shared = pytest.mark.skipif(not SHARED_DATA.exists(), reason="../shared/data absent")


def run_markers():
    markers = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI"}
    for p in "RL":
        markers.update({p + "THIGH": [p + "TH1", p + "TH2", p + "TH3"],
                        p + "SHANK": [p + "TB1", p + "TB2", p + "TB3"],
                        p + "KNEE_LAT": p + "LFC", p + "KNEE_MED": p + "MFC",
                        p + "ANKLE_LAT": p + "LMAL", p + "ANKLE_MED": p + "MMAL",
                        p + "HEEL": p + "CAL", p + "TOE": p + "TOE", p + "MT5": p + "MT5"})
    return markers


def _read_mot(path):
    """A small reader for OpenSim .mot files (header through 'endheader')."""
    with open(path) as file:
        lines = file.read().splitlines()
    start = next(k for k, line in enumerate(lines) if line.strip() == "endheader")
    return pd.read_csv(path, sep=r"\s+", skiprows=start + 1)


@needs_shared
@pytest.mark.parametrize("joint, angle, column, r_min", [
    ("hip", "flexion", "hip_flexion", 0.97), ("knee", "flexion", "knee_angle", 0.97)])
@pytest.mark.parametrize("side", ["right", "left"])
def test_running_trial_against_opensim(joint, angle, column, r_min, side):
    model = calibrate_lower_limb(SHARED_DATA / "static_run.trc", run_markers())
    angles = quiet(model.angles, SHARED_DATA / "motion_capture_run.trc")
    mot = _read_mot(SHARED_DATA / "ik_output_run.mot")
    ours = np.interp(mot["time"], angles.index, angles[joint, side, angle])
    theirs = mot[f"{column}_{side[0]}"].to_numpy()
    r = np.corrcoef(ours, theirs)[0, 1]
    assert r >= r_min
    assert abs(np.mean(ours - theirs)) < 10       # model joints vs segment frames


@needs_shared
def test_running_trial_flags_the_swapped_foot_labels():
    model = calibrate_lower_limb(SHARED_DATA / "static_run.trc", run_markers())
    with pytest.warns(RuntimeWarning, match=r"right foot markers, used as its cluster, RFOOT "
                                            r"\(RCAL, RTOE, RMT5\) deforms in \d+ of 123"):
        model.angles(SHARED_DATA / "motion_capture_run.trc")


@needs_shared
def test_walk_trc_without_static():
    markers = {"RASIS": "R.ASIS", "LASIS": "L.ASIS", "RPSIS": "R.PSIS", "LPSIS": "L.PSIS"}
    for p, side in (("R", "R."), ("L", "L.")):
        markers.update({p + "KNEE_LAT": side + "Knee", p + "KNEE_MED": side + "Knee.Medial",
                        p + "ANKLE_LAT": side + "Ankle", p + "ANKLE_MED": side + "Ankle.Medial",
                        p + "HEEL": side + "Heel", p + "TOE": side + "MT2",
                        p + "MT5": side + "MT5"})
    angles = lower_limb_angles(None, SHARED_DATA / "walk.trc", markers)
    assert angles.notna().all().all()
    knee = angles["knee"]
    assert 50 < knee["right", "flexion"].max() < 80     # swing peak of walking
    assert 50 < knee["left", "flexion"].max() < 80
