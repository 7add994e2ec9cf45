"""Tests of bmc_functions.rigid_body.svdt.svdt: the seed's examples, scipy as the oracle,
missing markers and bad input."""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from bmc_functions import rot_z, svdt


def seed_loop_svdt(A, B):
    """An independent per-frame reference written from the seed's description (one SVD
    per frame, reflection fix, RMSE over all markers), for comparison only."""
    A = np.asarray(A, float)
    R_all, L_all, rmse_all = [], [], []
    for Bf in np.asarray(B, float):
        Am, Bm = A.mean(0), Bf.mean(0)
        U, _, Vt = np.linalg.svd((Bf - Bm).T @ (A - Am))
        R = U @ np.diag([1, 1, np.linalg.det(U @ Vt)]) @ Vt
        L = Bm - R @ Am
        err = (A @ R.T + L) - Bf
        R_all.append(R), L_all.append(L), rmse_all.append(np.sqrt((err**2).sum() / A.size))
    return np.array(R_all), np.array(L_all), np.array(rmse_all)


def random_cluster(rng, n, frames, noise=0.0, scale=100.0):
    A = rng.normal(scale=scale, size=(n, 3))
    R = Rotation.random(frames, random_state=rng).as_matrix()
    L = rng.normal(scale=1000, size=(frames, 3))
    B = np.einsum("fij,nj->fni", R, A) + L[:, None, :] + rng.normal(scale=noise or 1e-300,
                                                                     size=(frames, n, 3))
    return A, B, R, L


# --- the seed's examples, as printed there ----------------------------------------------

ROT_90_Z = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])


def test_seed_example_col_order():
    A = np.array([0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0])
    B = np.array([0, 0, 0, 0, 1, 0, -1, 0, 0, -1, 1, 0])
    R, L, RMSE = svdt(A, B)
    np.testing.assert_array_equal(np.around(R, 4), ROT_90_Z)
    np.testing.assert_array_equal(np.around(L, 4), [0, 0, 0])
    assert np.around(RMSE, 4) == 0.0
    assert R.shape == (3, 3) and L.shape == (3,) and np.ndim(RMSE) == 0


def test_seed_example_row_order():
    A = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    B = np.array([[0, 0, 0], [0, 1, 0], [-1, 0, 0], [-1, 1, 0]])
    R, L, RMSE = svdt(A, B, order="row")
    np.testing.assert_array_equal(np.around(R, 4), ROT_90_Z)
    np.testing.assert_array_equal(np.around(L, 4), [0, 0, 0])
    assert np.around(RMSE, 4) == 0.0


def test_seed_example_two_instants():
    A = np.array([1, 0, 0, 0, 1, 0, 0, 0, 1])
    B = np.vstack([[0, 1, 0, -1, 0, 0, 0, 0, 1]] * 2)
    R, L, RMSE = svdt(A, B)
    assert R.shape == (2, 3, 3) and L.shape == (2, 3) and RMSE.shape == (2,)
    np.testing.assert_array_equal(np.around(R, 4), [ROT_90_Z, ROT_90_Z])
    np.testing.assert_array_equal(np.around(L, 4), np.zeros((2, 3)))
    np.testing.assert_array_equal(np.around(RMSE, 4), [0, 0])


def test_one_row_in_col_order_keeps_the_frame_axis():
    A = np.array([1, 0, 0, 0, 1, 0, 0, 0, 1])
    R, L, RMSE = svdt(A, A[None, :])
    assert R.shape == (1, 3, 3) and L.shape == (1, 3) and RMSE.shape == (1,)


# --- exact and noisy data against independent references --------------------------------

def test_recovers_known_transformation_exactly():
    rng = np.random.default_rng(0)
    A, B, R_true, L_true = random_cluster(rng, 5, 50)
    R, L, RMSE = svdt(A, B, order="row")
    np.testing.assert_allclose(R, R_true, atol=1e-12)
    np.testing.assert_allclose(L, L_true, atol=1e-9)
    np.testing.assert_allclose(RMSE, 0, atol=1e-9)
    # the col layout gives the same
    R2, L2, RMSE2 = svdt(A.ravel(), B.reshape(50, -1))
    np.testing.assert_allclose(R2, R, atol=1e-15)
    np.testing.assert_allclose(L2, L, atol=1e-12)


def test_matches_per_frame_reference_on_noisy_data():
    rng = np.random.default_rng(1)
    A, B, _, _ = random_cluster(rng, 4, 200, noise=2.0)
    R, L, RMSE = svdt(A, B, order="row")
    R_ref, L_ref, rmse_ref = seed_loop_svdt(A, B)
    np.testing.assert_allclose(R, R_ref, atol=1e-12)
    np.testing.assert_allclose(L, L_ref, atol=1e-9)
    np.testing.assert_allclose(RMSE, rmse_ref, rtol=1e-10)


def test_rmse_definition_by_hand():
    # a unit square scaled by s about its centre: M = s * (scatter of A) is symmetric
    # positive semidefinite, so the best rotation is the identity and every marker is off
    # by (s - 1) times its distance from the centre, sqrt(0.5):
    # RMSE = sqrt(4 * (s - 1)**2 * 0.5 / (3 * 4)) = |s - 1| / sqrt(6)
    A = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    s = 1.3
    B = (A - 0.5 * np.array([1, 1, 0])) * s + [0.5, 0.5, 0] + [2, 3, 4]
    R, L, RMSE = svdt(A, B, order="row")
    np.testing.assert_allclose(R, np.eye(3), atol=1e-14)
    np.testing.assert_allclose(L, [2, 3, 4], atol=1e-14)
    assert RMSE == pytest.approx(0.3 / np.sqrt(6), rel=1e-12)


def test_always_a_proper_rotation_even_for_mirrored_markers():
    rng = np.random.default_rng(2)
    A = rng.normal(size=(6, 3))
    B = A * [1, 1, -1]  # a mirror image: the unconstrained optimum is a reflection
    R, _, _ = svdt(A, B, order="row")
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 8),
       noise=st.sampled_from([0.0, 0.01, 1.0]))
def test_agrees_with_scipy_align_vectors(seed, n, noise):
    rng = np.random.default_rng(seed)
    A, B, _, _ = random_cluster(rng, n, 1, noise=noise)
    R, L, RMSE = svdt(A, B[0], order="row")
    Ac, Bc = A - A.mean(0), B[0] - B[0].mean(0)
    expected = Rotation.align_vectors(Bc, Ac)[0].as_matrix()
    np.testing.assert_allclose(R, expected, atol=1e-10)
    np.testing.assert_allclose(L, B[0].mean(0) - expected @ A.mean(0), atol=1e-7)
    residual = A @ R.T + L - B[0]
    assert RMSE == pytest.approx(np.sqrt((residual**2).mean()), rel=1e-9, abs=1e-12)



@pytest.mark.parametrize("offset", [1e4, 1e6])
def test_static_and_dynamic_trials_far_from_the_origin(offset):
    # Lab coordinates: both trials 10 m (or 1 km) from the origin, a 50 mm cluster, no
    # noise. The inputs are exact to offset * 1e-16, so R must be exact to ~1e-12 and the
    # markers reconstructed to ~1e-10 mm; summing b_i (a_i - a_mean) without centring B
    # multiplies the rounding error of the centred A (offset * 1e-16) by the offset.
    rng = np.random.default_rng(21)
    A = rng.normal(scale=50.0, size=(3, 3))
    R_true = Rotation.random(200, random_state=rng).as_matrix()
    B = np.einsum("fij,nj->fni", R_true, A) + offset
    R, L, RMSE = svdt(A + offset, B, order="row")
    np.testing.assert_allclose(R, R_true, rtol=0, atol=1e-10)
    np.testing.assert_allclose(L, offset - R_true @ np.full(3, offset), rtol=0,
                               atol=1e-9 * offset)
    assert RMSE.max() < 1e-8
    # the same with one marker missing in a frame (the weighted path)
    A4 = np.vstack((A, A.mean(axis=0) + [0.0, 0.0, 60.0]))
    B4 = np.einsum("fij,nj->fni", R_true, A4) + offset
    B4[::2, 3] = np.nan
    R4, _, RMSE4 = svdt(A4 + offset, B4, order="row")
    np.testing.assert_allclose(R4, R_true, rtol=0, atol=1e-10)
    assert RMSE4.max() < 1e-8


def test_missing_markers_far_from_the_origin_match_a_per_frame_fit():
    # the frames with missing markers are fitted with weighted sums: they too must not
    # lose digits to the distance from the origin (1 km here, 0.5 mm noise)
    rng = np.random.default_rng(22)
    offset = 1e6
    A = rng.normal(scale=50.0, size=(8, 3))
    R_true = Rotation.random(300, random_state=rng).as_matrix()
    B = np.einsum("fij,nj->fni", R_true, A) + rng.normal(scale=0.5, size=(300, 8, 3))
    B[rng.random((300, 8)) < 0.2] = np.nan
    A_far, B_far = A + offset, B + offset
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a few frames with < 3 markers
        R, _, RMSE = svdt(A_far, B_far, order="row")
    # the same data moved back to the origin exactly (x - 1e6 is exact here)
    A_near, B_near = A_far - offset, B_far - offset
    for f in range(300):
        seen = ~np.isnan(B_near[f, :, 0])
        if seen.sum() < 3:
            assert np.isnan(R[f]).all()
            continue
        R_ref, _, rmse_ref = seed_loop_svdt(A_near[seen], B_near[f, seen][None])
        np.testing.assert_allclose(R[f], R_ref[0], rtol=0, atol=1e-10)
        assert RMSE[f] == pytest.approx(rmse_ref[0], rel=1e-8)

# --- missing markers ---------------------------------------------------------------------

def test_missing_marker_is_dropped_for_that_frame_only():
    rng = np.random.default_rng(3)
    A, B, R_true, L_true = random_cluster(rng, 5, 10, noise=0.5)
    B[4, 2, :] = np.nan   # marker 2 occluded in frame 4
    B[6, 0, 1] = np.nan   # a single NaN coordinate hides the whole marker
    R, L, RMSE = svdt(A, B, order="row")
    assert np.isfinite(R).all() and np.isfinite(L).all() and np.isfinite(RMSE).all()
    for frame, marker in [(4, 2), (6, 0)]:
        keep = np.arange(5) != marker
        R_ref, L_ref, rmse_ref = seed_loop_svdt(A[keep], B[frame:frame + 1, keep])
        np.testing.assert_allclose(R[frame], R_ref[0], atol=1e-12)
        np.testing.assert_allclose(L[frame], L_ref[0], atol=1e-9)
        assert RMSE[frame] == pytest.approx(rmse_ref[0], rel=1e-10)
    R_ref, _, _ = seed_loop_svdt(A, B[[0, 1, 2, 3, 5, 7, 8, 9]])
    np.testing.assert_allclose(R[[0, 1, 2, 3, 5, 7, 8, 9]], R_ref, atol=1e-12)


def test_too_few_markers_in_a_frame_gives_nan_and_one_warning():
    rng = np.random.default_rng(4)
    A, B, _, _ = random_cluster(rng, 4, 6)
    B[1, :2] = np.nan    # two of four visible
    B[3, :] = np.nan     # none visible
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        R, L, RMSE = svdt(A, B, order="row")
    assert len(caught) == 1
    assert issubclass(caught[0].category, RuntimeWarning)
    assert "2 of 6 frames" in str(caught[0].message)
    assert np.isnan(R[[1, 3]]).all() and np.isnan(L[[1, 3]]).all()
    assert np.isnan(RMSE[[1, 3]]).all()
    assert np.isfinite(R[[0, 2, 4, 5]]).all() and np.isfinite(RMSE[[0, 2, 4, 5]]).all()


def test_visible_markers_collinear_in_a_frame_gives_nan():
    A = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]])  # first three collinear
    B = np.stack([A, A])
    B[1, 3] = np.nan
    with pytest.warns(RuntimeWarning, match=r"1 of 2 frames have fewer than 3 non-collinear"):
        R, L, RMSE = svdt(A, B, order="row")
    assert np.isnan(R[1]).all() and np.isfinite(R[0]).all()


def test_visible_markers_nearly_collinear_in_a_with_noisy_b_gives_nan():
    # Markers 1-3 of A are collinear by the rule svdt applies to A itself (second
    # singular value 6e-9 of the first): svdt(A[:3], ...) raises. With marker 4 hidden
    # the rotation about their line is undetermined; noise in B must not decide it.
    rng = np.random.default_rng(6)
    A = np.array([[0.0, 0, 0], [50, 0, 0], [100, 1e-6, 0], [50, 40, 0]])
    with pytest.raises(ValueError, match=r"collinear"):
        svdt(A[:3], A[:3], order="row")
    R_true = Rotation.random(20, random_state=rng).as_matrix()
    B = np.einsum("fij,nj->fni", R_true, A) + rng.normal(scale=0.3, size=(20, 4, 3))
    B[::2, 3] = np.nan
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        R, L, RMSE = svdt(A, B, order="row")
    assert [str(w.message)[:16] for w in caught] == ["10 of 20 frames "]
    assert np.isnan(R[::2]).all() and np.isnan(L[::2]).all() and np.isnan(RMSE[::2]).all()
    assert np.isfinite(R[1::2]).all()
    # the frames with all four markers are still fitted well (0.3 mm noise, 40 mm cluster)
    error = Rotation.from_matrix(np.swapaxes(R_true[1::2], 1, 2) @ R[1::2]).magnitude()
    assert np.degrees(error).max() < 2.0

def test_degenerate_frame_of_b_gives_nan():
    # a system that writes zeros instead of NaN for lost markers: all markers coincide
    A = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    B = np.stack([A + 5, np.zeros_like(A)])
    with pytest.warns(RuntimeWarning, match=r"1 of 2 frames"):
        R, _, _ = svdt(A, B, order="row")
    assert np.isnan(R[1]).all()
    np.testing.assert_allclose(R[0], np.eye(3), atol=1e-12)


def test_no_warning_without_missing_data():
    rng = np.random.default_rng(5)
    A, B, _, _ = random_cluster(rng, 4, 20, noise=0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        svdt(A, B, order="row")


# --- bad input: each with its own message -----------------------------------------------

def test_fewer_than_three_markers():
    with pytest.raises(ValueError, match=r"at least 3 markers.*A has 2 marker"):
        svdt([0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0])


def test_coincident_markers():
    with pytest.raises(ValueError, match=r"markers of A are coincident"):
        svdt(np.ones(9), np.arange(9.0))


def test_collinear_markers():
    A = np.array([[0.0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]])
    with pytest.raises(ValueError, match=r"markers of A are collinear"):
        svdt(A, A, order="row")


def test_nearly_collinear_within_tolerance():
    A = np.array([[0.0, 0, 0], [100, 0, 0], [200, 1e-5, 0]])
    with pytest.raises(ValueError, match=r"collinear"):
        svdt(A, A, order="row")
    A[2, 1] = 1e-2  # well above the relative tolerance: accepted
    R, _, _ = svdt(A, A, order="row")
    np.testing.assert_allclose(R, np.eye(3), atol=1e-9)


def test_nan_in_a():
    A = np.array([0, 0, 0, 1, 0, 0, 0, 1, np.nan])
    with pytest.raises(ValueError, match=r"A contains NaN"):
        svdt(A, np.arange(9.0))


def test_infinite_values():
    A = np.array([0, 0, 0, 1, 0, 0, 0, 1, 0.0])
    with pytest.raises(ValueError, match=r"B contains infinite values"):
        svdt(A, np.array([0, 0, 0, 1, 0, 0, 0, 1, np.inf]))


def test_marker_count_mismatch():
    A = np.array([0, 0, 0, 1, 0, 0, 0, 1, 0.0])
    with pytest.raises(ValueError, match=r"same number of markers as A \(3\); got 4"):
        svdt(A, np.zeros((5, 12)))
    with pytest.raises(ValueError, match=r"same number of markers as A \(3\); got 4"):
        svdt(A.reshape(3, 3), np.zeros((4, 3)), order="row")


@pytest.mark.parametrize("B,order", [(np.empty(0), "col"), (np.empty((5, 0)), "col"),
                                     (np.empty((5, 0, 3)), "row")])
def test_b_without_markers(B, order):
    # not numpy's "cannot reshape array of size 0" but the marker count
    A = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    with pytest.raises(ValueError, match=r"same number of markers as A \(3\); got 0"):
        svdt(A.ravel() if order == "col" else A, B, order=order)

@pytest.mark.parametrize("A,B", [(np.zeros(10), np.zeros(10)),
                                 (np.arange(9.0), np.zeros(10))])
def test_length_not_multiple_of_three(A, B):
    with pytest.raises(ValueError, match=r"multiple of 3.*got shape"):
        svdt(A, B)


@pytest.mark.parametrize("order", ["column", "rows", None, "COL"])
def test_unknown_order(order):
    with pytest.raises(ValueError, match=r"order must be 'col' or 'row'; got"):
        svdt(np.arange(9.0), np.arange(9.0), order=order)


def test_row_order_wrong_shapes():
    with pytest.raises(ValueError, match=r"order='row', A must have shape \(n, 3\)"):
        svdt(np.arange(9.0), np.arange(9.0), order="row")
    with pytest.raises(ValueError, match=r"order='row', B must have shape"):
        svdt(np.eye(3), np.ones((2, 3, 4)), order="row")


def test_col_order_wrong_shapes():
    with pytest.raises(ValueError, match=r"order='col', A must be 1D"):
        svdt(np.eye(3), np.arange(9.0))
    with pytest.raises(ValueError, match=r"order='col', B must have shape"):
        svdt(np.arange(9.0), np.ones((2, 2, 9)))


def test_row_shaped_markers_with_the_default_order_name_order_row():
    # the most common slip: (n, 3) arrays without order='row'
    A = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    with pytest.raises(ValueError, match=r"A must be 1D.*got shape \(4, 3\); for one "
                                         r"marker per row, pass order='row'"):
        svdt(A, A)

def test_non_numeric_input():
    with pytest.raises(ValueError, match=r"A must be a numeric array"):
        svdt(["a"] * 9, np.arange(9.0))


def test_rotation_about_z_by_hand_with_translation():
    A = np.array([[0.0, 0, 0], [1, 0, 0], [0, 2, 0], [0, 0, 3]])
    R_true = rot_z(0.3)
    B = A @ R_true.T + [10, -5, 2]
    R, L, RMSE = svdt(A, B, order="row")
    np.testing.assert_allclose(R, R_true, atol=1e-14)
    np.testing.assert_allclose(L, [10, -5, 2], atol=1e-13)
