"""Tests of bmc_functions.models.lower_limb_checks at their thresholds (the messages themselves are
checked case by case in tests/test_lower_limb.py, through calibrate_lower_limb)."""

import warnings

import numpy as np
import pytest

from bmc_functions import calibrate_lower_limb, read_trc
from bmc_functions.models.lower_limb_checks import COLLINEAR_WARN_RATIO

from helpers import ROOT, load_data_script, synthetic_markers as markers, two_leg_markers
from helpers import warning_messages as _warnings

GEN = load_data_script("generate_marker_data")
MARKERS_DIR = ROOT / "data" / "markers"


@pytest.fixture(scope="module")
def clean():
    return GEN.make_trials(noise_sd=0.0, sta_scale=0.0, gaps=False)


@pytest.mark.parametrize("travel, warns", [(99.0, False), (101.0, True)])
def test_static_motion_boundary_is_100_mm(clean, travel, warns):
    # documented: a warning when a marker travels more than 100 mm from its median
    static = clean["static"].copy()
    ramp = np.zeros(len(static))
    ramp[-1] = travel                  # one frame away: the median stays where it was
    static[[c for c in static.columns if c[1] == "y"]] += ramp[:, None]
    messages = _warnings(calibrate_lower_limb, static, markers())
    assert any("is not static" in m for m in messages) == warns


@pytest.mark.parametrize("degrees, warns", [(9.0, False), (11.0, True)])
def test_static_rotation_boundary_is_10_degrees(clean, degrees, warns):
    # The last frame turned about the vertical through the pelvis: every group turns by
    # about 49/50 of that angle from the mean orientation (1 frame of 50 moves the mean);
    # documented: a warning above 10 degrees.
    static = clean["static"].copy()
    xyz = static.to_numpy().copy().reshape(len(static), -1, 3)
    a = np.deg2rad(degrees)
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


SHANK = ("RTB1", "RTB2", "RTB3")


def _scaled_shank(trial, rmse, frames=slice(None)):
    """`trial` with the shank cluster scaled about its centroid so that its svdt RMSE is
    `rmse` mm in `frames` (a scaled rigid shape is best fitted unrotated: its residuals
    are the scaling's, RMSE = |s - 1| * sqrt(sum |a_i|^2 / 3n), a_i from the centroid)."""
    out = trial.copy()
    points = np.stack([trial[label].to_numpy() for label in SHANK], axis=1)
    centroid = points.mean(axis=1, keepdims=True)
    size = np.sqrt(((points - centroid) ** 2).sum(axis=2).mean(axis=1) / 3)
    factor = 1.0 + np.asarray(rmse, float) / size
    scaled = centroid + factor[:, None, None] * (points - centroid)
    for k, label in enumerate(SHANK):
        out.loc[out.index[frames], label] = scaled[frames, k]
    return out


@pytest.mark.parametrize("rmse, warns", [(5.0, False), (5.9, False), (6.1, True),
                                         (7.0, True)])
def test_deformation_boundary_is_6_mm(clean, rmse, warns):
    # documented: a cluster deforms above 6 mm of svdt RMSE (clean static: 5 x its RMSE
    # is far below); fixed physical deformations, not built from the constant
    model = calibrate_lower_limb(clean["static"], markers())
    assert model.static_rmse["RSHANK"] < 0.1
    walk = _scaled_shank(clean["walk"], np.full(len(clean["walk"]), rmse))
    messages = _warnings(model.angles, walk)
    assert any("deforms" in m for m in messages) == warns
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        np.testing.assert_allclose(model.track(walk).rmse["RSHANK"], rmse, rtol=1e-6)


@pytest.mark.parametrize("rmse, warns", [(9.5, False), (10.5, True)])
def test_deformation_boundary_is_5_times_the_static_rmse(clean, rmse, warns):
    # a static shank of 2 mm RMSE (every frame scaled by +-, the mean shape unchanged):
    # documented: the warning is then above 5 x 2 = 10 mm
    static = clean["static"]
    signs = np.where(np.arange(len(static)) % 2, -2.0, 2.0)
    model = calibrate_lower_limb(_scaled_shank(static, signs), markers())
    np.testing.assert_allclose(model.static_rmse["RSHANK"], 2.0, rtol=1e-3)
    walk = _scaled_shank(clean["walk"], np.full(len(clean["walk"]), rmse))
    messages = _warnings(model.angles, walk)
    assert any("RSHANK" in m and "deforms" in m for m in messages) == warns


# --- issue 21: mirrored, swapped, reversed and mislabelled trials ---------------------------

import pandas as pd  # noqa: E402

from bmc_functions.models.lower_limb_checks import LEGS_CROSSED  # noqa: E402


def both_markers():
    return two_leg_markers()


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


# --- boundaries of the static checks (issue 24): documented values, both sides ------------


from bmc_functions.models import lower_limb  # noqa: E402
from bmc_functions.models.lower_limb_checks import (check_static_geometry,  # noqa: E402
                                                    check_units)


@pytest.mark.parametrize("width, refused", [(79.5, True), (80.0, False), (600.0, False),
                                            (600.5, True)])
def test_pelvis_width_boundaries_are_80_and_600_mm_inclusive(width, refused):
    roles = {"RASIS": "RASI", "LASIS": "LASI"}
    points = {"RASI": np.array([width, 0.0, 0.0]), "LASI": np.zeros(3)}
    if refused:
        with pytest.raises(ValueError, match="a pelvis is 80 to 600 mm wide"):
            check_units(roles, points, "mm", "the trial")
    else:
        check_units(roles, points, "mm", "the trial")


@pytest.fixture(scope="module")
def posture(clean):
    model = calibrate_lower_limb(clean["static"], markers())
    loaded, _ = lower_limb._load(clean["static"], "static")
    points = lower_limb._static_points(model, loaded.table, loaded.scale, loaded.name)
    hips, _ = lower_limb.harrington_hip_centres(model, points, {})
    return model, points, hips


@pytest.mark.parametrize("along, refused", [(1.14, False), (1.16, True), (-0.14, False),
                                            (-0.16, True)])
def test_thigh_cluster_span_boundaries_are_documented_fractions(posture, along, refused):
    # documented: a cluster's centroid from -15 % to 115 % of its segment, distal to
    # proximal (SEGMENT_SPAN); the thigh cluster moved rigidly along the thigh's axis
    model, points, hips = posture
    knee = (points["RLFC"] + points["RMFC"]) / 2
    axis = hips["right"] - knee
    labels = model.markers["RTHIGH"]
    centroid = np.mean([points[label] for label in labels], axis=0)
    now = (centroid - knee) @ axis / (axis @ axis)
    moved = dict(points)
    for label in labels:
        moved[label] = points[label] + (along - now) * axis
    if refused:
        with pytest.raises(ValueError, match="right thigh cluster RTHIGH .* lies (above the "
                                             "hip|below the knee)"):
            check_static_geometry(model, moved, hips)
    else:
        check_static_geometry(model, moved, hips)


def test_static_offset_leaves_the_pelvis_relative_to_the_lab(trials):
    static, walk, model = trials
    offset = calibrate_lower_limb(static, both_markers(), static_offset=True)
    plain, relative = _quiet(model.angles, walk), _quiet(offset.angles, walk)
    pd.testing.assert_frame_equal(relative["pelvis"], plain["pelvis"])
    expected = plain["knee"] - model.static_angles["knee"]
    pd.testing.assert_frame_equal(relative["knee"], expected)


@pytest.mark.parametrize("fraction, refused", [(0.49, True), (0.51, False)])
def test_pelvis_cluster_must_be_half_way_up_from_the_knees(posture, fraction, refused):
    # documented by the check: the PELVIS cluster at least half-way from the knees to the
    # ASISs (along up); moved rigidly along up
    model, points, hips = posture
    mid_asis = (points["RASI"] + points["LASI"]) / 2
    knees = (points["RLFC"] + points["RMFC"]) / 2
    up = mid_asis - knees
    labels = model.markers["PELVIS"]
    height = (np.mean([points[label] for label in labels], axis=0) - knees) @ up / (up @ up)
    moved = dict(points)
    for label in labels:
        moved[label] = points[label] + (fraction - height) * up
    if refused:
        with pytest.raises(ValueError, match="pelvis cluster PELVIS .* too low"):
            check_static_geometry(model, moved, hips)
    else:
        check_static_geometry(model, moved, hips)


@pytest.mark.parametrize("tilt, refused", [(34.0, False), (36.0, True)])
def test_knee_line_tilt_boundary_is_35_degrees(posture, tilt, refused):
    # the knee markers turned about their midpoint in the plane of the thigh's axis, width
    # kept: documented limit 35 degrees from perpendicular to the thigh
    model, points, hips = posture
    lat, med = points["RLFC"], points["RMFC"]
    centre, half = (lat + med) / 2, np.linalg.norm(lat - med) / 2
    axis = hips["right"] - centre
    axis /= np.linalg.norm(axis)
    across = (lat - med) - ((lat - med) @ axis) * axis
    across /= np.linalg.norm(across)
    direction = np.cos(np.deg2rad(tilt)) * across + np.sin(np.deg2rad(tilt)) * axis
    moved = dict(points, RLFC=centre + half * direction, RMFC=centre - half * direction)
    if refused:
        with pytest.raises(ValueError, match="right knee: the line from .* 36 degrees"):
            check_static_geometry(model, moved, hips)
    else:
        check_static_geometry(model, moved, hips)


@pytest.mark.parametrize("along, refused", [(0.33, False), (0.37, True)])
def test_foot_cluster_boundary_is_35_percent_up_the_shank(posture, along, refused):
    # documented (FOOT_CLUSTER_SPAN): a foot cluster's centroid at most 35 % of the way
    # from the ankle to the knee
    model, points, hips = posture
    ankle = (points["RLMAL"] + points["RMMAL"]) / 2
    knee = (points["RLFC"] + points["RMFC"]) / 2
    shank = (knee - ankle) / np.linalg.norm(knee - ankle)
    lateral = points["RLMAL"] - points["RMMAL"]
    lateral -= (lateral @ shank) * shank               # across the shank: `along` kept
    centre = ankle + along * (knee - ankle) + 0.5 * lateral     # on the right side
    moved = dict(points)
    labels = ("F1", "F2", "F3")
    for k, label in enumerate(labels):
        moved[label] = centre + 10.0 * np.eye(3)[k] - 10.0 / 3
    with_foot = lower_limb.LowerLimbModel(markers=dict(model.markers, RFOOT=labels),
                                          sides=model.sides)
    if refused:
        with pytest.raises(ValueError, match="right foot cluster RFOOT .* is not on the"):
            check_static_geometry(with_foot, moved, hips)
    else:
        check_static_geometry(with_foot, moved, hips)


@pytest.mark.parametrize("apart, flagged", [(-0.24, False), (-0.26, True)])
def test_legs_crossed_boundary_is_a_quarter_of_the_asis_distance(trials, apart, flagged):
    # frames 40-59: the right thigh cluster moved along RASIS - LASIS
    # so that they lie `apart` ASIS distances to the right of the left thigh's
    static, walk, model = trials
    moved = walk.copy()
    pelvis = _quiet(model.track, walk).landmarks[("pelvis", None)]   # the walk has no ASIS
    right = pelvis["RASIS"] - pelvis["LASIS"]
    width = np.linalg.norm(right, axis=1, keepdims=True)
    unit = right / width
    thigh = {p: [p + n for n in ("TH1", "TH2", "TH3", "TH4")] for p in "RL"}
    centroid = {p: np.nanmean(np.stack([walk[label].to_numpy() for label in thigh[p]]),
                              axis=0) for p in "RL"}
    now = np.einsum("fi,fi->f", centroid["R"] - centroid["L"], unit)[:, None]
    shift = (apart * width - now) * unit
    rows = slice(40, 60)
    for label in thigh["R"]:
        moved.loc[moved.index[rows], label] = walk[label].to_numpy()[rows] + shift[rows]
    messages = _warnings(model.angles, moved)
    crossed = [m for m in messages if "right thigh's markers lie to the subject's left" in m]
    assert bool(crossed) == flagged
    if flagged:
        assert crossed[0].startswith("20 of ")


@pytest.mark.parametrize("ahead, refused", [(1.0, False), (-1.0, True)])
def test_toe_must_lie_ahead_of_the_heel(trials, ahead, refused):
    # the right toe moved to `ahead` mm in front of the heel along the pelvis's forward
    # direction (documented: anterior made horizontal); MT5 not mapped (its own check)
    static, walk, model = trials
    mapping = {role: label for role, label in both_markers().items() if role[1:] != "MT5"}
    no_mt5 = calibrate_lower_limb(static, mapping)
    loaded, _ = lower_limb._load(static, "static")
    points = lower_limb._static_points(no_mt5, loaded.table, loaded.scale, loaded.name)
    hips, _ = lower_limb.harrington_hip_centres(no_mt5, points, {})
    mid_asis = (points["RASI"] + points["LASI"]) / 2
    anterior = mid_asis - (points["RPSI"] + points["LPSI"]) / 2
    up = mid_asis - (points["RLFC"] + points["RMFC"] + points["LLFC"] + points["LMFC"]) / 4
    up /= np.linalg.norm(up)
    forward = anterior - (anterior @ up) * up
    forward /= np.linalg.norm(forward)
    toe = points["RTOE"] - points["RHEEL"]
    moved = dict(points, RTOE=points["RHEEL"] + toe - (toe @ forward - ahead) * forward)
    if refused:
        with pytest.raises(ValueError, match=r"RTOE .* lies 1 mm behind RHEEL"):
            check_static_geometry(no_mt5, moved, hips)
    else:
        check_static_geometry(no_mt5, moved, hips)


def test_visible_centroid_of_part_of_a_stack_is_that_of_its_copy():
    # The thigh's markers are read in place from a C-ordered stack of the leg's markers:
    # the same sums, bit for bit, as from a C-ordered copy (and from numpy.sum over the
    # markers), with and without missing markers; other layouts are copied first.
    from bmc_functions.models.lower_limb_checks import visible_centroid
    rng = np.random.default_rng(3)
    leg = rng.normal(scale=300.0, size=(400, 7, 3)) + 1000.0
    planes = np.stack([np.asfortranarray(leg[:, k]) for k in range(4)], axis=1)
    for part in (leg[:, :4], leg[:, 2:6], planes):       # planes: x, y, z apart
        copy = np.ascontiguousarray(part)
        assert np.array_equal(visible_centroid(part), visible_centroid(copy))
        assert np.array_equal(visible_centroid(part), copy.sum(axis=1) / 4)
    leg[10, 1] = np.nan                                   # one marker missing: 3 seen
    leg[11, :4] = np.nan                                  # none seen: NaN
    centroid = visible_centroid(leg[:, :4])
    assert np.array_equal(centroid, visible_centroid(np.ascontiguousarray(leg[:, :4])),
                          equal_nan=True)
    assert np.array_equal(centroid[10], (leg[10, 0] + leg[10, 2] + leg[10, 3]) / 3)
    assert np.isnan(centroid[11]).all()


@pytest.mark.parametrize("seed", range(4))
def test_leg_centroids_from_the_columns_equal_visible_centroid_of_the_stack(seed):
    # check_sides' leg centroids are summed from the table's columns in place: the same
    # numbers, bit for bit (signs of zero included), as visible_centroid of the stack of
    # the leg's markers, for both layouts of the table, units, missing markers, a marker
    # never seen, sums that overflow, and a thigh part of none, some or all markers.
    from bmc_functions.files.trial import MarkerTable
    from bmc_functions.models.lower_limb_checks import (_table_coordinates,
                                                        coordinate_centroids,
                                                        visible_centroid)
    rng = np.random.default_rng(seed)
    for _ in range(60):
        frames, count = int(rng.integers(1, 40)), int(rng.integers(1, 12))
        labels = [f"M{k}" for k in range(count)]
        values = rng.normal(size=(frames, 3 * count)) * 10.0 ** rng.uniform(-3, 3)
        kind = rng.integers(0, 5)
        if kind == 1:
            values[rng.random(values.shape) < rng.uniform(0.0, 0.3)] = np.nan
        elif kind == 2:
            values[:, :3] = np.nan                        # one marker never seen
        elif kind == 3:
            values[:] = -0.0
        elif kind == 4:
            values[rng.random(values.shape) < 0.3] = 1.5e308      # sums overflow
        columns = pd.MultiIndex.from_tuples([(label, axis) for label in labels
                                             for axis in "xyz"])
        layout = np.asfortranarray if rng.random() < 0.5 else np.ascontiguousarray
        table = MarkerTable(pd.DataFrame(layout(values), columns=columns))
        scale = float(rng.choice([1.0, 10.0, 0.001, 25.4]))
        split = int(rng.integers(0, count + 1))
        with np.errstate(all="ignore"):
            stack = table.stacked(labels, scale, contiguous=True)
            expected = (visible_centroid(stack[:, :split]) if split else None,
                        visible_centroid(stack))
            found = coordinate_centroids(_table_coordinates(table, labels, scale), split)
        assert (found[0] is None) == (expected[0] is None)
        for a, b in zip(found, expected):
            if b is not None:
                assert a.flags.c_contiguous and a.shape == b.shape
                assert np.array_equal(a, b, equal_nan=True)
                assert np.array_equal(np.signbit(a), np.signbit(b))


def test_foot_direction_of_measured_feet_reads_their_landmarks_as_they_are():
    # A foot without a cluster has the trial's own markers as its landmarks: the feet's
    # direction read from them directly is that of the markers taken where seen and the
    # landmarks elsewhere (_measured_or_rebuilt), bit for bit, gaps included.
    from bmc_functions.examples import example_file
    from bmc_functions.files.trial import MarkerTable, load_trial
    from bmc_functions.models import lower_limb_checks as checks
    from bmc_functions import read_marker_mapping
    markers = read_marker_mapping(example_file("markers/markers.toml"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = calibrate_lower_limb(example_file("markers/static.trc"), markers)
        df, _ = load_trial(example_file("markers/walk.trc"), "dynamic")
        df = df.copy()
        df.loc[df.index[20:30], markers["RTOE"]] = np.nan
        kin = model.track(df)
    assert "RFOOT" not in model.markers and not model.landmarks.empty
    table = MarkerTable(df)
    found = checks._foot_direction(model, table, 1.0, kin.landmarks, len(df))
    feet = []
    for side, p in (("right", "R"), ("left", "L")):
        ends = checks._measured_or_rebuilt(model, table, 1.0, kin.landmarks[("foot", side)],
                                           [p + "TOE", p + "HEEL"])
        heel_to_toe = ends[p + "TOE"] - ends[p + "HEEL"]
        feet.append(heel_to_toe / np.linalg.norm(heel_to_toe, axis=1, keepdims=True))
    expected = checks.visible_centroid(np.stack(feet, axis=1))
    assert np.isnan(feet[0][20:30]).all() and not np.isnan(found).any()   # the left's
    assert np.array_equal(found, expected, equal_nan=True)
