"""Tests of svdt's closed-form (quaternion / QCP) path: agreement with the SVD, the
ill-conditioned frames that fall back to the SVD, blocks of frames, and Horn's matrix.

Oracles: a per-frame SVD written here from Kabsch (1976), scipy's Rotation
(align_vectors, as_matrix) and hand-derived identities. Timing is not tested here: see
benchmarks/bench_svdt.py.
"""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import bmc_functions.rigid_body.svdt as rigid_body
from bmc_functions import svdt
from bmc_functions.rigid_body.quaternion_fit import horn_matrix, quaternion_rotation
from bmc_functions.rigid_body.svdt import cross_covariance, rotation_from_covariance


def svd_per_frame(A, B):
    """Reference: one SVD per frame with the reflection fix, RMSE from the residuals."""
    A = np.asarray(A, float)
    out_R, out_L, out_rmse = [], [], []
    for Bf in np.asarray(B, float):
        a_mean, b_mean = A.mean(axis=0), Bf.mean(axis=0)
        U, _, Vt = np.linalg.svd((Bf - b_mean).T @ (A - a_mean))
        R = U @ np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt))]) @ Vt
        L = b_mean - R @ a_mean
        residual = A @ R.T + L - Bf
        out_R.append(R)
        out_L.append(L)
        out_rmse.append(np.sqrt(np.sum(residual**2) / A.size))
    return np.array(out_R), np.array(out_L), np.array(out_rmse)


def moving_cluster(rng, A, R, noise, offset=1000.0):
    """Markers A rotated by R (F, 3, 3), translated far from the origin, plus noise."""
    L = rng.normal(scale=offset, size=(len(R), 3))
    return np.einsum("fij,nj->fni", R, A) + L[:, None, :] + rng.normal(
        scale=noise, size=(len(R), len(A), 3))


def well_spread_cluster(rng, n, scale=50.0):
    """n markers whose centred second singular value is at least 20% of the first."""
    while True:
        A = rng.normal(scale=scale, size=(n, 3))
        sv = np.linalg.svd(A - A.mean(axis=0), compute_uv=False)
        if sv[1] >= 0.2 * sv[0]:
            return A


def assert_same_fit(fit, ref, atol_R=1e-10, rtol=1e-10, atol_rmse=1e-12):
    R, L, rmse = fit
    R_ref, L_ref, rmse_ref = ref
    np.testing.assert_allclose(R, R_ref, rtol=0, atol=atol_R)
    # L is in the units of the data (here ~1000 from the origin): compare relatively.
    np.testing.assert_allclose(L, L_ref, rtol=0, atol=rtol * (1 + np.abs(L_ref).max()))
    np.testing.assert_allclose(rmse, rmse_ref, rtol=1e-9, atol=atol_rmse)


# --- agreement with the SVD on well-conditioned frames ----------------------------------

@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 8),
       noise=st.sampled_from([0.0, 1e-6, 0.01, 0.5, 3.0]))
def test_property_matches_the_svd_path_within_1e_10(seed, n, noise):
    rng = np.random.default_rng(seed)
    A = well_spread_cluster(rng, n)
    R_true = Rotation.random(40, random_state=rng).as_matrix()
    B = moving_cluster(rng, A, R_true, noise)
    assert_same_fit(svdt(A, B, order="row"), svd_per_frame(A, B))


@settings(max_examples=50, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 8),
       offset=st.sampled_from([0.0, 1e3, 1e5]), missing=st.sampled_from([0.1, 0.3]))
def test_property_missing_markers_far_from_the_origin_match_the_svd(seed, n, offset,
                                                                    missing):
    # Both trials `offset` mm from the origin, markers missing at random: every frame
    # agrees with one SVD per frame on its visible markers, computed on the same data
    # moved back to the origin (x - offset is exact here), and the undetermined frames
    # are those with fewer than 3 visible markers or visible markers collinear in A.
    rng = np.random.default_rng(seed)
    A = well_spread_cluster(rng, n)
    R_true = Rotation.random(30, random_state=rng).as_matrix()
    B = moving_cluster(rng, A, R_true, 0.5, offset=0.0)
    B[rng.random(B.shape[:2]) < missing] = np.nan
    A_far, B_far = A + offset, B + offset
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        R, L, rmse = svdt(A_far, B_far, order="row")
    A_near, B_near = A_far - offset, B_far - offset
    for f in range(len(B)):  # the reference: one frame at a time
        seen = ~np.isnan(B_near[f, :, 0])
        sv = np.linalg.svd(A_near[seen] - A_near[seen].mean(axis=0), compute_uv=False
                           ) if seen.sum() >= 3 else np.zeros(3)
        if sv[1] <= rigid_body.COLLINEAR_RTOL * sv[0]:
            assert np.isnan(R[f]).all() and np.isnan(L[f]).all() and np.isnan(rmse[f])
            continue
        R_ref, L_ref, rmse_ref = svd_per_frame(A_near[seen], B_near[f, seen][None])
        np.testing.assert_allclose(R[f], R_ref[0], rtol=0, atol=1e-10)
        L_ref_far = L_ref[0] + offset - R_ref[0] @ np.full(3, offset)
        np.testing.assert_allclose(L[f], L_ref_far, rtol=0, atol=1e-9 * (1 + offset))
        assert rmse[f] == pytest.approx(rmse_ref[0], rel=1e-8, abs=1e-12)

@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), noise=st.floats(0.0, 5.0))
def test_property_quaternion_rotation_matches_scipy_align_vectors(seed, noise):
    rng = np.random.default_rng(seed)
    A = well_spread_cluster(rng, 5)
    A = A - A.mean(axis=0)
    R_true = Rotation.random(1, random_state=rng).as_matrix()
    B = moving_cluster(rng, A, R_true, noise, offset=0.0)[0]
    B = B - B.mean(axis=0)
    R, lam, ok = quaternion_rotation((B.T @ A)[None])
    expected, _ = Rotation.align_vectors(B, A)
    assert ok[0]
    np.testing.assert_allclose(R[0], expected.as_matrix(), atol=1e-10)
    # lam is the maximum of tr(R^T M) = sum_i b_i . R a_i
    assert lam[0] == pytest.approx(np.sum(B * (A @ R[0].T)), rel=1e-12)


def test_planar_cluster_uses_the_closed_form_and_matches():
    # Four markers in a plane: M has rank 2, but the optimal rotation is unique and the
    # closed form stays well-conditioned (D = (s1 + s2) s1 s2 > 0).
    rng = np.random.default_rng(11)
    A = np.array([[0.0, 0, 0], [80, 0, 0], [0, 40, 0], [80, 40, 0]])
    R_true = Rotation.random(200, random_state=rng).as_matrix()
    B = moving_cluster(rng, A, R_true, 0.2)
    _, _, M = cross_covariance(A, B, np.ones(B.shape[:2]))
    assert quaternion_rotation(M)[2].all()
    assert_same_fit(svdt(A, B, order="row"), svd_per_frame(A, B))


@pytest.mark.parametrize("angle_from_pi", [0.0, 1e-12, 1e-8, 1e-4])
def test_rotations_near_180_degrees(angle_from_pi):
    # Quaternion methods that read the rotation from the first component of the
    # eigenvector (w = cos(angle / 2)) fail here; the closed form used has no such step.
    rng = np.random.default_rng(5)
    A = well_spread_cluster(rng, 4)
    axes = rng.normal(size=(50, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    R_true = Rotation.from_rotvec((np.pi - angle_from_pi) * axes).as_matrix()
    B = moving_cluster(rng, A, R_true, 0.0)
    R, L, rmse = svdt(A, B, order="row")
    np.testing.assert_allclose(R, R_true, atol=1e-10)
    assert_same_fit((R, L, rmse), svd_per_frame(A, B))
    _, _, M = cross_covariance(A, B, np.ones(B.shape[:2]))
    assert quaternion_rotation(M)[2].all()


# --- ill-conditioned frames fall back to the SVD ------------------------------------------

def assert_falls_back_to_svd(A, B, monkeypatch):
    """Every frame is flagged ill-conditioned, svdt sends it to the SVD, and the result
    is an optimal proper rotation (in a tie, any member of the optimal family is)."""
    _, _, M = cross_covariance(A, B, np.ones(B.shape[:2]))
    R_fast, lam, ok = quaternion_rotation(M)
    assert not ok.any()
    sent = []

    def recording_svd(M_frames):
        sent.append(len(M_frames))
        return rotation_from_covariance(M_frames)

    monkeypatch.setattr(rigid_body, "rotation_from_covariance", recording_svd)
    R, _, _ = svdt(A, B, order="row")
    assert sum(sent) == len(B)
    np.testing.assert_allclose(R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape),
                               atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)
    # optimal: tr(R^T M) reaches the largest eigenvalue of Horn's matrix
    best = np.linalg.eigvalsh(horn_matrix(M))[:, -1]
    np.testing.assert_allclose(np.einsum("fij,fij->f", R, M), best, rtol=1e-12)


def test_nearly_equal_largest_eigenvalues_fall_back(monkeypatch):
    # Markers mirrored through a plane, with the two smaller principal moments of the
    # cluster equal: s2 = s3 and det(M) < 0, so the two largest eigenvalues of Horn's
    # matrix, s1 + s2 - s3 and s1 - s2 + s3, coincide and the best rotation is a
    # whole family. The SVD picks one; svdt must give the same.
    A = np.array([[100.0, 0, 0], [-100, 0, 0], [0, 30, 0], [0, -30, 0],
                  [0, 0, 30], [0, 0, -30]])
    mirror = np.diag([1.0, 1.0, -1.0])
    R_true = Rotation.random(20, random_state=1).as_matrix()
    B = np.einsum("fij,nj->fni", R_true, A @ mirror) + 500.0
    B += np.random.default_rng(2).normal(scale=1e-9, size=B.shape)
    assert_falls_back_to_svd(A, B, monkeypatch)


def test_nearly_collinear_cluster_falls_back(monkeypatch):
    # Width 1e-4 of the length: accepted by svdt (COLLINEAR_RTOL = 1e-6 on the singular
    # values of A), but the closed form loses about 1e-8 of accuracy there.
    A = np.array([[0.0, 0, 0], [100, 0, 0], [200, 0.01, 0], [300, 0, 0.01]])
    R_true = Rotation.random(10, random_state=3).as_matrix()
    B = np.einsum("fij,nj->fni", R_true, A) + 1000.0
    assert_falls_back_to_svd(A, B, monkeypatch)


def test_thin_cluster_just_above_the_conditioning_threshold_still_within_1e_10():
    # A 300 x 8 mm cluster: D / E0^3 is about 1e-3, the smallest ratio that svdt still
    # solves in closed form; its error there grows like 1/ratio^2, to about 1e-11 (and
    # that of the RMSE, in mm, to about 1e-11 x the cluster's length).
    rng = np.random.default_rng(12)
    A = np.array([[0.0, 0, 0], [100, 0, 0], [200, 8, 0], [300, 0, 8]])
    R_true = Rotation.random(300, random_state=rng).as_matrix()
    B = moving_cluster(rng, A, R_true, 0.01)
    assert_same_fit(svdt(A, B, order="row"), svd_per_frame(A, B), atol_rmse=1e-10)


def test_collinear_frame_of_b_is_nan_with_one_warning():
    rng = np.random.default_rng(4)
    A = well_spread_cluster(rng, 4)
    R_true = Rotation.random(30, random_state=rng).as_matrix()
    B = moving_cluster(rng, A, R_true, 0.1)
    B[7] = np.linspace(0, 1, 4)[:, None] * [10.0, 20.0, 30.0]  # collinear in frame 7
    B[8] = 5.0                                                  # coincident in frame 8
    with pytest.warns(RuntimeWarning, match="2 of 30 frames") as record:
        R, L, rmse = svdt(A, B, order="row")
    assert len(record) == 1
    bad = np.isnan(rmse)
    np.testing.assert_array_equal(np.flatnonzero(bad), [7, 8])
    assert np.isnan(R[bad]).all() and np.isnan(L[bad]).all()
    good = ~bad
    assert_same_fit((R[good], L[good], rmse[good]), svd_per_frame(A, B[good]))


def test_quaternion_rotation_flags_a_zero_matrix_without_error():
    R, lam, ok = quaternion_rotation(np.zeros((2, 3, 3)))
    assert not ok.any()


# --- blocks of frames, missing markers ----------------------------------------------------

def test_blocks_and_missing_markers_across_block_boundaries(monkeypatch):
    monkeypatch.setattr(rigid_body, "CHUNK_FRAMES", 7)  # many small blocks
    rng = np.random.default_rng(6)
    A = well_spread_cluster(rng, 5)
    R_true = Rotation.random(40, random_state=rng).as_matrix()
    B = moving_cluster(rng, A, R_true, 0.3)
    B[6, 1] = np.nan        # last frame of block 0
    B[7, 2, 0] = np.nan     # first frame of block 1
    B[20, :3] = np.nan      # only 2 markers left: undetermined
    B[33, [0, 4]] = np.nan  # 3 markers left
    with pytest.warns(RuntimeWarning, match="1 of 40 frames") as record:
        R, L, rmse = svdt(A, B, order="row")
    assert len(record) == 1
    assert np.isnan(R[20]).all() and np.isnan(L[20]).all() and np.isnan(rmse[20])
    for frame in range(40):
        if frame == 20:
            continue
        keep = ~np.isnan(B[frame]).any(axis=1)
        ref = svd_per_frame(A[keep], B[frame:frame + 1, keep])
        assert_same_fit((R[frame:frame + 1], L[frame:frame + 1], rmse[frame:frame + 1]), ref)


def test_no_warning_and_same_result_whatever_the_block_size(monkeypatch):
    rng = np.random.default_rng(7)
    A = well_spread_cluster(rng, 4)
    B = moving_cluster(rng, A, Rotation.random(50, random_state=rng).as_matrix(), 0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        whole = svdt(A, B, order="row")
        monkeypatch.setattr(rigid_body, "CHUNK_FRAMES", 3)
        blocks = svdt(A, B, order="row")
    for x, y in zip(whole, blocks):
        np.testing.assert_array_equal(x, y)


def test_infinite_value_in_a_late_frame_is_still_an_error():
    A = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    B = np.tile(A, (20, 1, 1))
    B[-1, 2, 1] = np.inf
    with pytest.raises(ValueError, match="B contains infinite values"):
        svdt(A, B, order="row")


# --- cross_covariance, the floor of every method ------------------------------------------

def test_cross_covariance_matches_its_definition_with_and_without_missing_markers():
    rng = np.random.default_rng(8)
    A = rng.normal(scale=50, size=(5, 3)) + 300.0
    B = rng.normal(scale=50, size=(6, 5, 3)) + 1000.0
    weights = np.ones((6, 5))
    weights[2, 1] = weights[4, [0, 3]] = 0.0
    for w in (np.ones((6, 5)), weights):
        A_mean, B_mean, M = cross_covariance(A, B, w)
        for f in range(6):
            seen = w[f] == 1
            a_bar, b_bar = A[seen].mean(axis=0), B[f, seen].mean(axis=0)
            np.testing.assert_allclose(A_mean[f], a_bar, rtol=1e-13)
            np.testing.assert_allclose(B_mean[f], b_bar, rtol=1e-13)
            expected = (B[f, seen] - b_bar).T @ (A[seen] - a_bar)
            np.testing.assert_allclose(M[f], expected, rtol=0, atol=1e-9)


# --- Horn's matrix --------------------------------------------------------------------------

def test_horn_matrix_quadratic_form_is_the_fit_objective():
    # q^T N q = tr(R(q)^T M) for any unit quaternion q (Horn 1987), checked with scipy's
    # quaternion-to-matrix conversion (scalar last there).
    rng = np.random.default_rng(9)
    M = rng.normal(size=(3, 3))
    N = horn_matrix(M)
    np.testing.assert_allclose(N, N.T, atol=0)
    q = rng.normal(size=(100, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    R = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()
    np.testing.assert_allclose(np.einsum("fi,ij,fj->f", q, N, q),
                               np.einsum("fij,ij->f", R, M), atol=1e-12)


def test_horn_matrix_eigenvalues_from_the_singular_values():
    # The eigenvalues of N are s1+s2+s3', s1-s2-s3', -s1+s2-s3', -s1-s2+s3', where
    # s3' = sign(det M) s3: the largest is the maximum of tr(R^T M) over rotations.
    rng = np.random.default_rng(10)
    for _ in range(5):
        M = rng.normal(size=(3, 3))
        s = np.linalg.svd(M, compute_uv=False)
        s3 = np.sign(np.linalg.det(M)) * s[2]
        expected = sorted([s[0] + s[1] + s3, s[0] - s[1] - s3, -s[0] + s[1] - s3,
                           -s[0] - s[1] + s3])
        np.testing.assert_allclose(np.linalg.eigvalsh(horn_matrix(M)), expected, atol=1e-12)
        lam = quaternion_rotation(M[None])[1][0]
        assert lam == pytest.approx(expected[-1], rel=1e-13)


def test_quaternion_rotation_wrong_shape():
    with pytest.raises(ValueError, match=r"M must have shape \(F, 3, 3\); got shape \(3, 3\)"):
        quaternion_rotation(np.eye(3))


@pytest.mark.parametrize("n", [4, 63, 64])
def test_collinear_subsets_for_small_and_large_marker_sets(n):
    # up to 62 markers the visibility patterns are coded as integers, beyond that not
    rng = np.random.default_rng(12)
    A = rng.normal(scale=50.0, size=(n, 3))
    A[:3] = [[0.0, 0, 0], [50, 0, 0], [100, 1e-6, 0]]  # collinear (rule for A: 1e-6)
    A[3] = [50, 40, 0]
    seen = np.ones((5, n), dtype=bool)
    seen[1, 3:] = False  # only the collinear three
    seen[2, 4:] = False  # the collinear three and marker 4
    seen[3, 2:] = False  # two markers
    seen[4, 0] = False  # markers 1, 2 of the line and marker 4
    expected = [False, True, False, True, False]
    assert rigid_body._collinear_subsets(A, seen).tolist() == expected
