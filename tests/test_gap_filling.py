"""Tests of bmc_functions.markers.gap_filling: filling marker gaps with the rigid-body model."""

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bmc_functions import fill_gaps_rigid, read_trc

from helpers import ROOT, SHARED_DATA, needs_shared

CLUSTER = np.array([[0.0, 0, 0], [120, 0, 0], [0, 90, 0], [60, 45, 70], [-30, 60, 40]])


def moving_cluster(frames=200, cluster=CLUSTER, seed=7):
    """A rigid cluster on a smooth random path (ground truth from scipy)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 2 * np.pi, frames)[:, None]
    rotvec = 0.8 * np.sin(t * rng.uniform(0.5, 2, 3) + rng.uniform(0, 6, 3))
    R = Rotation.from_rotvec(rotvec).as_matrix()
    L = 500 * np.sin(t * rng.uniform(0.5, 2, 3)) + [1000, 800, 600]
    return np.einsum("fij,nj->fni", R, cluster) + L[:, None, :]


def test_noise_free_gaps_are_filled_exactly_and_visible_markers_kept():
    truth = moving_cluster()
    markers = truth.copy()
    markers[20:80, 0] = np.nan                 # one marker for 60 frames
    markers[50:60, 3] = np.nan                 # two at once (3 visible) in 50-59
    markers[150, 4, 2] = np.nan                # one coordinate only: the marker is missing
    filled, mask = fill_gaps_rigid(markers, return_mask=True)
    assert filled.shape == markers.shape
    np.testing.assert_allclose(filled, truth, atol=1e-8)
    expected = np.zeros((200, 5), dtype=bool)
    expected[20:80, 0] = expected[50:60, 3] = expected[150, 4] = True
    np.testing.assert_array_equal(mask, expected)
    seen = ~np.isnan(markers).any(axis=2)
    np.testing.assert_array_equal(filled[seen], markers[seen])
    # the input is not modified
    assert np.isnan(markers[20:80, 0]).all()


def test_plain_call_returns_the_filled_array_only():
    markers = moving_cluster(50)
    markers[10:20, 1] = np.nan
    filled = fill_gaps_rigid(markers)
    assert isinstance(filled, np.ndarray) and filled.shape == (50, 5, 3)
    assert not np.isnan(filled).any()


def test_fewer_than_three_visible_stay_nan_with_one_warning():
    truth = moving_cluster(100)
    markers = truth.copy()
    markers[10:20, :3] = np.nan                # 2 visible: undetermined
    markers[40:45, 0] = np.nan                 # 4 visible: filled
    with pytest.warns(RuntimeWarning, match=r"^10 of 100 frames have a missing marker but "
                                            r"fewer than 3 non-collinear visible markers"):
        filled, mask = fill_gaps_rigid(markers, return_mask=True)
    assert np.isnan(filled[10:20, :3]).all() and not mask[10:20].any()
    np.testing.assert_array_equal(filled[10:20, 3:], truth[10:20, 3:])
    np.testing.assert_allclose(filled[40:45, 0], truth[40:45, 0], atol=1e-8)


def test_three_marker_cluster_cannot_fill_a_lost_marker():
    truth = moving_cluster(30, CLUSTER[:3])
    markers = truth.copy()
    markers[5:9, 2] = np.nan
    with pytest.warns(RuntimeWarning, match=r"^4 of 30 frames have a missing marker"):
        filled = fill_gaps_rigid(markers)
    assert np.isnan(filled[5:9, 2]).all()


def test_no_gap_returns_a_copy_without_warning():
    markers = moving_cluster(20)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        filled, mask = fill_gaps_rigid(markers, return_mask=True)
    np.testing.assert_array_equal(filled, markers)
    assert filled is not markers and not mask.any()


def test_reference_frame_index_and_static_array():
    truth = moving_cluster(60)
    markers = truth.copy()
    markers[:30, 2] = np.nan
    for reference in (45, -1, CLUSTER, np.stack([CLUSTER + 5, CLUSTER - 5])):
        np.testing.assert_allclose(fill_gaps_rigid(markers, reference), truth, atol=1e-8)


def test_needs_a_reference_when_no_frame_is_complete():
    truth = moving_cluster(40)
    markers = truth.copy()
    markers[:20, 0] = np.nan
    markers[20:, 1] = np.nan
    with pytest.raises(ValueError, match=r"markers: no frame has all 5 markers visible.*pass "
                                         r"reference="):
        fill_gaps_rigid(markers)
    np.testing.assert_allclose(fill_gaps_rigid(markers, reference=CLUSTER), truth, atol=1e-8)


def test_noisy_cluster_error_is_at_the_noise_level_whatever_the_gap_length():
    # noise 0.5 mm on every coordinate; the filled marker's error comes from the fit only
    rng = np.random.default_rng(11)
    truth = moving_cluster(400)
    markers = truth + rng.normal(0, 0.5, truth.shape)
    markers[50:350, 0] = np.nan
    filled = fill_gaps_rigid(markers)
    error = np.linalg.norm(filled[50:350, 0] - truth[50:350, 0], axis=1)
    rms = np.sqrt(np.mean(error**2))
    assert 0.3 < rms < 1.5                    # about the 0.87 mm of one noisy marker


def test_procrustes_mean_reference_averages_out_noise():
    rng = np.random.default_rng(12)
    truth = moving_cluster(300)
    markers = truth + rng.normal(0, 1.0, truth.shape)
    markers[100:110, 0] = np.nan
    filled_mean = fill_gaps_rigid(markers)
    filled_one = fill_gaps_rigid(markers, reference=0)
    err = [np.sqrt(np.mean(np.sum((f[100:110, 0] - truth[100:110, 0]) ** 2, axis=1)))
           for f in (filled_mean, filled_one)]
    assert err[0] < err[1]


@pytest.mark.parametrize("markers, message", [
    (np.zeros((10, 4)), r"markers must have shape \(\.\.\., 3\)"),
    (np.zeros((10, 3)), r"markers must have shape \(frames, n, 3\).*got shape \(10, 3\)"),
    (np.zeros((2, 10, 4, 3)), r"markers must have shape \(frames, n, 3\)"),
    (np.zeros((10, 2, 3)), r"a cluster needs at least 3 markers for a rigid-body fit; "
                           r"markers has 2 \(shape \(10, 2, 3\)\)"),
    (np.full((10, 4, 3), np.inf), r"markers contains infinite values"),
])
def test_bad_markers(markers, message):
    with pytest.raises(ValueError, match=message):
        fill_gaps_rigid(markers)


@pytest.mark.parametrize("flag", ["True", 1, None])
def test_return_mask_not_a_flag(flag):
    with pytest.raises(TypeError, match=r"return_mask must be True or False; got"):
        fill_gaps_rigid(moving_cluster(10), return_mask=flag)


def test_collinear_visible_markers_are_not_filled():
    # markers 0, 1, 2 on a line, 3 off it: without 3 the pose about the line is unknown
    cluster = np.array([[0.0, 0, 0], [50, 0, 0], [120, 0, 0], [40, 70, 30]])
    truth = moving_cluster(20, cluster)
    markers = truth.copy()
    markers[5:8, 3] = np.nan
    markers[12, 0] = np.nan                    # 3 non-collinear left: filled
    with pytest.warns(RuntimeWarning, match=r"^3 of 20 frames have a missing marker but fewer "
                                            r"than 3 non-collinear"):
        filled, mask = fill_gaps_rigid(markers, return_mask=True)
    assert np.isnan(filled[5:8, 3]).all() and not mask[5:8].any()
    np.testing.assert_allclose(filled[12, 0], truth[12, 0], atol=1e-8)


def test_bad_references():
    markers = moving_cluster(20)
    markers[3, 0] = np.nan
    with pytest.raises(ValueError, match=r"reference must have shape \(5, 3\) \(or "
                                         r"\(frames, 5, 3\)\).*got shape \(4, 3\)"):
        fill_gaps_rigid(markers, CLUSTER[:4])
    with pytest.raises(ValueError, match=r"reference: marker\(s\) \[0, 1, 2\] are missing \(NaN\) "
                                         r"in the static trial"):
        fill_gaps_rigid(markers, np.where(CLUSTER == 0, np.nan, CLUSTER))
    static = np.stack([CLUSTER, CLUSTER])
    static[:, 2] = np.nan
    with pytest.raises(ValueError, match=r"reference: marker\(s\) \[2\] are missing \(NaN\) "
                                         r"in every frame of the static trial"):
        fill_gaps_rigid(markers, static)
    with pytest.raises(ValueError, match=r"reference frame 3 has missing marker\(s\) \[0\]"):
        fill_gaps_rigid(markers, 3)
    with pytest.raises(ValueError, match=r"reference frame 20 is out of range for 20 frames"):
        fill_gaps_rigid(markers, 20)
    line = np.outer(np.arange(5.0), [1, 2, 3])
    with pytest.raises(ValueError, match=r"reference \(the cluster's shape\): the markers of "
                                         r"A are collinear"):
        fill_gaps_rigid(markers, line)


def test_static_reference_averages_each_marker_over_its_visible_frames():
    truth = moving_cluster(30)
    markers = truth.copy()
    markers[:10, 1] = np.nan
    static = np.stack([CLUSTER] * 3)           # a static trial: the cluster does not move
    static[0, 3] = np.nan                      # marker 3 seen in two static frames only
    np.testing.assert_allclose(fill_gaps_rigid(markers, static), truth, atol=1e-8)


THIGH = ["RTH1", "RTH2", "RTH3", "RTH4"]


def test_dataframe_in_dataframe_out_with_the_array_result():
    walk = read_trc(ROOT / "data" / "markers" / "walk.trc")
    thigh = walk[THIGH]
    array = np.stack([thigh[m].to_numpy() for m in THIGH], axis=1)
    filled, mask = fill_gaps_rigid(thigh, return_mask=True)
    assert list(filled.columns) == list(thigh.columns)
    assert filled.index.equals(thigh.index) and filled.attrs["rate"] == 100.0
    np.testing.assert_array_equal(filled.to_numpy().reshape(-1, 4, 3), fill_gaps_rigid(array))
    assert list(mask.columns) == THIGH and mask["RTH3"].sum() == 12   # the file's gap
    assert not mask.drop(columns="RTH3").to_numpy().any()
    assert not filled.isna().any().any()
    # the static trial (other markers ignored) as the reference
    static = read_trc(ROOT / "data" / "markers" / "static.trc")
    from_static = fill_gaps_rigid(thigh, reference=static)
    gap = mask["RTH3"].to_numpy()
    difference = from_static["RTH3"].to_numpy()[gap] - filled["RTH3"].to_numpy()[gap]
    assert np.abs(difference).max() < 10        # mm: two references, same cluster


def test_dataframe_bad_input():
    walk = read_trc(ROOT / "data" / "markers" / "walk.trc")
    with pytest.raises(ValueError, match=r"reference \(a DataFrame\) lacks the marker\(s\) "
                                         r"\['RTH4'\] of markers"):
        fill_gaps_rigid(walk[THIGH], reference=walk[THIGH[:3]])
    flat = walk[THIGH].copy()
    flat.columns = [f"{m}_{c}" for m, c in flat.columns]
    with pytest.raises(ValueError, match=r"markers must be a pandas DataFrame with \(marker, "
                                         r"coord\) columns|markers must have two-level"):
        fill_gaps_rigid(flat)


@needs_shared("motion_capture_run.trc")
def test_real_running_pelvis_rigid_fill_beats_interpolation_on_long_gaps():
    df = read_trc(SHARED_DATA / "motion_capture_run.trc")
    pelvis = np.stack([df[m].to_numpy() for m in ("RASI", "LASI", "RPSI", "LPSI")], axis=1)
    assert not np.isnan(pelvis).any()
    markers = pelvis.copy()
    gap = slice(20, 100)                      # 80 frames (0.53 s at 150 Hz)
    markers[gap, 3] = np.nan
    filled = fill_gaps_rigid(markers)
    frames = np.arange(len(markers))
    seen = ~np.isnan(markers[:, 3, 0])
    linear = np.stack([np.interp(frames, frames[seen], markers[seen, 3, k]) for k in range(3)],
                      axis=1)
    rms = [np.sqrt(np.mean(np.sum((x[gap] - pelvis[gap, 3]) ** 2, axis=1)))
           for x in (filled[:, 3], linear)]
    assert rms[0] < 15 and rms[0] < rms[1] / 3


# --- issue 21: a reference that does not fit the trial ---------------------------------------

@pytest.mark.parametrize("change", ["size", "order", "metres"])
def test_reference_of_another_size_or_order_is_not_used_to_fill(change):
    markers = moving_cluster()
    gappy = markers.copy()
    gappy[50:80, 2] = np.nan
    reference = markers[0] - markers[0].mean(axis=0)
    wrong = {"size": reference * 1.4, "order": reference[[1, 0, 2, 3, 4]],
             "metres": reference / 1000}[change]
    with pytest.warns(RuntimeWarning, match=r"200 of 200 frames of markers do not have the "
                                            r"cluster's shape.*not filled"):
        filled = fill_gaps_rigid(gappy, wrong)
    assert np.isnan(filled[50:80, 2]).all()
    np.testing.assert_array_equal(filled[:50], gappy[:50])       # visible markers kept


def test_markers_swapped_in_some_frames_are_not_filled_there():
    markers = moving_cluster()
    gappy = markers.copy()
    gappy[100:120, [0, 1]] = markers[100:120, [1, 0]]
    gappy[105:110, 3] = np.nan
    gappy[150:160, 3] = np.nan
    with pytest.warns(RuntimeWarning, match=r"20 of 200 frames of markers do not have"):
        filled = fill_gaps_rigid(gappy)
    assert np.isnan(filled[105:110, 3]).all()
    np.testing.assert_allclose(filled[150:160, 3], markers[150:160, 3], atol=1e-9)
