"""Tests of bmc_functions.models.lower_limb_checks at their thresholds (the messages themselves are
checked case by case in tests/test_lower_limb.py, through calibrate_lower_limb)."""

import warnings

import numpy as np
import pytest

from bmc_functions import calibrate_lower_limb, read_trc
from bmc_functions.models.lower_limb_checks import (COLLINEAR_WARN_RATIO, DEFORM_FACTOR, DEFORM_MM,
                                             STATIC_MOTION_MM, STATIC_ROTATION_DEG)

from helpers import ROOT, load_data_script

GEN = load_data_script("generate_marker_data")
MARKERS_DIR = ROOT / "data" / "markers"


def markers():
    roles = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
             "PELVIS": ["PEL1", "PEL2", "PEL3"]}
    roles.update({"RTHIGH": ["RTH1", "RTH2", "RTH3", "RTH4"], "RSHANK": ["RTB1", "RTB2", "RTB3"],
                  "RKNEE_LAT": "RLFC", "RKNEE_MED": "RMFC", "RANKLE_LAT": "RLMAL",
                  "RANKLE_MED": "RMMAL", "RHEEL": "RHEEL", "RTOE": "RTOE", "RMT5": "RMT5"})
    return roles


@pytest.fixture(scope="module")
def clean():
    return GEN.make_trials(noise_sd=0.0, sta_scale=0.0, gaps=False)


def _warnings(function, *args, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        function(*args, **kwargs)
    return [str(w.message) for w in caught]


@pytest.mark.parametrize("travel, warns", [(0.9 * STATIC_MOTION_MM, False),
                                           (1.1 * STATIC_MOTION_MM, True)])
def test_static_motion_threshold(clean, travel, warns):
    static = clean["static"].copy()
    ramp = np.zeros(len(static))
    ramp[-1] = travel                  # one frame away: the median stays where it was
    static[[c for c in static.columns if c[1] == "y"]] += ramp[:, None]
    messages = _warnings(calibrate_lower_limb, static, markers())
    assert any("is not static" in m for m in messages) == warns


@pytest.mark.parametrize("factor, warns", [(0.8, False), (1.2, True)])
def test_static_rotation_threshold(clean, factor, warns):
    # The last frame turned about the vertical through the pelvis: every group turns by
    # about that angle from the mean orientation (the mean barely moves: 1 frame of 50).
    static = clean["static"].copy()
    xyz = static.to_numpy().copy().reshape(len(static), -1, 3)
    a = np.deg2rad(factor * STATIC_ROTATION_DEG)
    R = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    centre = static["RASI"].to_numpy()[-1]
    xyz[-1] = (xyz[-1] - centre) @ R.T + centre
    static.iloc[:, :] = xyz.reshape(len(static), -1)
    messages = _warnings(calibrate_lower_limb, static, markers())
    assert not any("moves up to" in m for m in messages)      # travel stays below its limit
    assert any("from its mean orientation" in m or "from their mean orientation" in m
               for m in messages) == warns


def test_collinear_threshold_is_a_ratio_of_singular_values(clean):
    static = clean["static"].copy()
    a, b = static["RTB1"].to_numpy(), static["RTB3"].to_numpy()
    direction = (a - b) / np.linalg.norm(a - b, axis=1, keepdims=True)
    normal = np.cross(direction, [0.0, 0.0, 1.0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    for offset, warns in ((5.0, True), (60.0, False)):
        s = static.copy()
        s[[("RTB2", c) for c in "xyz"]] = (a + b) / 2 + offset * normal
        cluster = np.stack([s[n].to_numpy()[0] for n in ("RTB1", "RTB2", "RTB3")])
        sv = np.linalg.svd(cluster - cluster.mean(axis=0), compute_uv=False)
        assert (sv[1] < COLLINEAR_WARN_RATIO * sv[0]) == warns
        messages = _warnings(calibrate_lower_limb, s, markers())
        assert any("nearly collinear" in m for m in messages) == warns


@pytest.mark.parametrize("shift, warns", [(0.8 * DEFORM_MM, False), (4 * DEFORM_MM, True)])
def test_deformation_threshold(clean, shift, warns):
    model = calibrate_lower_limb(clean["static"], markers())
    walk = clean["walk"].copy()
    walk[("RTB1", "x")] += shift            # RMSE of 3 markers with one moved by d: < d
    messages = _warnings(model.angles, walk)
    assert any("deforms" in m for m in messages) == warns
    assert DEFORM_FACTOR * max(model.static_rmse.values()) < DEFORM_MM   # clean: floor rules


# --- issue 21: mirrored, swapped, reversed and mislabelled trials ---------------------------

import pandas as pd  # noqa: E402

from bmc_functions.models.lower_limb_checks import LEGS_CROSSED  # noqa: E402


def both_markers():
    roles = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
             "PELVIS": ["PEL1", "PEL2", "PEL3"]}
    for p in "RL":
        roles.update({p + "THIGH": [p + "TH1", p + "TH2", p + "TH3", p + "TH4"],
                      p + "SHANK": [p + "TB1", p + "TB2", p + "TB3"],
                      p + "KNEE_LAT": p + "LFC", p + "KNEE_MED": p + "MFC",
                      p + "ANKLE_LAT": p + "LMAL", p + "ANKLE_MED": p + "MMAL",
                      p + "HEEL": p + "HEEL", p + "TOE": p + "TOE", p + "MT5": p + "MT5"})
    return roles


@pytest.fixture(scope="module")
def trials():
    static = read_trc(MARKERS_DIR / "static.trc")
    walk = read_trc(MARKERS_DIR / "walk.trc")
    return static, walk, calibrate_lower_limb(static, both_markers())


def _relabel(df, rename):
    out = df.copy()
    out.columns = pd.MultiIndex.from_tuples([(rename(m), c) for m, c in df.columns],
                                            names=df.columns.names)
    out.attrs = dict(df.attrs)
    return out


def _swap_lr(label):
    return {"R": "L", "L": "R"}.get(label[0], label[0]) + label[1:]


def _quiet(function, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return function(*args, **kwargs)


def test_every_label_swapped_in_a_dynamic_trial_is_refused(trials):
    static, walk, model = trials
    with pytest.raises(ValueError, match=r"in every frame of the dynamic trial .*right "
                                         r"thigh's markers lie to the subject's left .*"
                                         r"swapped"):
        model.angles(_relabel(walk, _swap_lr))


def test_trial_mirrored_across_the_sagittal_plane_is_refused(trials):
    # labels kept: a 3-marker pelvis cluster fits its mirror image with an RMSE of zero,
    # turned round; the pelvis then faces against the feet
    static, walk, model = trials
    mirrored = walk.copy()
    mirrored.loc[:, (slice(None), "z")] *= -1
    with pytest.raises(ValueError, match=r"in every frame .*the pelvis faces against the "
                                         r"feet.*mirrored"):
        model.angles(mirrored)


def test_mirrored_body_is_judged_from_the_raw_pelvis_markers_too(trials):
    # a static trial used as a dynamic one, its ASIS markers measured: mirror it
    static, walk, model = trials
    mirrored = static.copy()
    mirrored.loc[:, (slice(None), "z")] *= -1
    with pytest.raises(ValueError, match=r"in every frame"):
        _quiet(model.angles, mirrored)


def test_labels_swapped_in_some_frames_flag_those_frames_only(trials):
    static, walk, model = trials
    mixed = walk.copy()
    swapped = _relabel(walk, _swap_lr)[walk.columns]
    mixed.iloc[40:60] = swapped.iloc[40:60].to_numpy()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        angles = model.angles(mixed)
    clean = _quiet(model.angles, walk)
    messages = [str(w.message) for w in caught]
    assert sum("right thigh's markers lie to the subject's left" in m for m in messages) == 1
    assert any(m.startswith("20 of 105 frames") for m in messages)
    legs = angles.drop(columns="pelvis", level="joint")
    assert legs.iloc[40:60].isna().all().all()
    # the other frames are untouched, and so are the pelvis angles
    pd.testing.assert_frame_equal(angles.iloc[:40], clean.iloc[:40])
    pd.testing.assert_frame_equal(angles["pelvis"], clean["pelvis"])


def test_legs_crossing_in_walking_is_not_flagged(trials):
    # a narrow base: both thighs moved 40 % of the ASIS distance toward the midline
    static, walk, model = trials
    narrow = walk.copy()
    width = np.linalg.norm(static["RASI"].to_numpy()[0] - static["LASI"].to_numpy()[0])
    shift = 0.4 * width * (1 - LEGS_CROSSED)
    for label in [m for m in walk.columns.get_level_values(0).unique() if m[:2] == "RT"]:
        narrow[(label, "z")] -= shift / 2
    for label in [m for m in walk.columns.get_level_values(0).unique() if m[:2] == "LT"]:
        narrow[(label, "z")] += shift / 2
    messages = _warnings(model.angles, narrow)
    assert not any("lie to the subject's left" in m for m in messages)


def test_time_reversed_walk_warns_and_keeps_pelvis_rotation_small(trials):
    static, walk, model = trials
    reversed_walk = walk.copy()
    reversed_walk.iloc[:, :] = walk.to_numpy()[::-1]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        angles = model.angles(reversed_walk)
    assert any("faces against its direction of travel in 105 of 105 frames" in str(w.message)
               for w in caught)
    truth = _quiet(model.angles, walk)["pelvis", "right", "rotation"].abs().max()
    assert angles["pelvis", "right", "rotation"].abs().max() < truth + 1.0   # not 180


def test_walking_backwards_keeps_pelvis_angles_relative_to_its_heading(trials):
    # the same walk, the subject turned round (180 deg about the vertical) and moving
    # backwards along the original path: the pelvis faces against its travel
    static, walk, model = trials
    values = walk.to_numpy().reshape(len(walk), -1, 3)
    centre = np.nanmean(values, axis=(0, 1))
    turned = (values - centre) * [-1, 1, -1] + centre          # 180 deg about y
    path = np.nanmean(values[:, :4], axis=1)                   # pelvis markers' travel
    backwards = turned + (path - path[::-1])[:, None, :] * [1, 0, 0]
    trial = walk.copy()
    trial.iloc[:, :] = backwards.reshape(len(walk), -1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        angles = model.angles(trial)
    assert any("walks backwards" in str(w.message) for w in caught)
    assert angles["pelvis", "right", "rotation"].abs().max() < 15


def test_knee_marker_mapped_to_a_thigh_cluster_marker_is_refused(trials):
    static, walk, model = trials
    with pytest.raises(ValueError, match=r"right knee: RKNEE_LAT \('RTH1'\) and RKNEE_MED "
                                         r"\('RMFC'\) .*not on the knee"):
        calibrate_lower_limb(static, dict(both_markers(), RKNEE_LAT="RTH1"))


def test_knee_width_outside_the_human_range_is_refused(trials):
    static, walk, model = trials
    wide = static.copy()
    lat, med = static["RLFC"].to_numpy(), static["RMFC"].to_numpy()
    unit = (lat - med) / np.linalg.norm(lat - med, axis=1, keepdims=True)
    wide.loc[:, "RLFC"] = med + unit * 200.0   # no human knee is 20 cm wide
    with pytest.raises(ValueError, match=r"right knee: .* are 200 mm apart .*50 to 170 mm"):
        calibrate_lower_limb(wide, both_markers())


def test_hip_centre_markers_swapped_are_refused(trials):
    static, walk, model = trials
    with_hjc = static.copy()
    for side, source in (("R", "L"), ("L", "R")):
        centre = model.landmarks.loc[source + "HJC"].to_numpy()
        for k, c in enumerate("xyz"):
            with_hjc[(side + "HJC", c)] = centre[k]
    mapping = dict(both_markers(), RHJC="RHJC", LHJC="LHJC")
    with pytest.raises(ValueError, match=r"right hip centre, RHJC \('RHJC'\), lies on the "
                                         r"subject's left .*RHJC and LHJC are swapped"):
        calibrate_lower_limb(with_hjc, mapping, hip_centre="marker")


def test_asis_and_psis_swapped_are_named_not_left_and_right(trials):
    static, walk, model = trials
    swapped = dict(both_markers(), RASIS="RPSI", RPSIS="RASI", LASIS="LPSI", LPSIS="LASI")
    with pytest.raises(ValueError, match=r"posterior pelvis markers .* lie in front of RASIS "
                                         r".*ASIS and PSIS .* are swapped"):
        calibrate_lower_limb(static, swapped)


def test_a_label_twice_in_a_trial_is_refused(trials):
    static, walk, model = trials
    doubled = pd.concat([walk, walk[["RTH1"]] + 10.0], axis=1)
    doubled.attrs = dict(walk.attrs)
    with pytest.raises(ValueError, match=r"marker 'RTH1' appears twice"):
        model.angles(doubled)


def test_the_same_label_mapped_to_two_roles_is_named_as_such(trials):
    static, walk, model = trials
    with pytest.raises(ValueError, match=r"maps the label 'RLFC' to 2 roles: RKNEE_LAT .*"
                                         r"RKNEE_MED"):
        calibrate_lower_limb(static, dict(both_markers(), RKNEE_MED="RLFC"))


def test_text_in_a_dynamic_trial_names_the_marker(trials):
    static, walk, model = trials
    text = walk.astype(object)
    text.loc[text.index[5], ("RTH2", "y")] = "n/a"
    with pytest.raises(ValueError, match=r"marker 'RTH2', coordinate 'y' holds 'n/a' at "
                                         r"frame 5"):
        model.angles(text)


def test_rate_attribute_contradicting_the_index_warns(trials):
    static, walk, model = trials
    walk = walk.copy()
    walk.attrs["rate"] = 200.0
    messages = _warnings(model.angles, walk)
    assert any("attrs['rate'] = 200 Hz, but its time index steps at 100 Hz" in m
               for m in messages)
