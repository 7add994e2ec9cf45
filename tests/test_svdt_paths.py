"""Issue 24, finding 1: svdt has two fitting paths, the closed form and one exact path
(an SVD on scaled markers) for every frame the closed form cannot fit."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bmc_functions.rigid_body.svdt as svdt_module
from bmc_functions import svdt


def svd_per_frame(A, B):
    """Reference: one SVD per frame with the reflection fix (the seed's method)."""
    out = []
    for frame in B:
        a_mean, b_mean = A.mean(axis=0), frame.mean(axis=0)
        U, _, Vt = np.linalg.svd((frame - b_mean).T @ (A - a_mean))
        R = U @ np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt))]) @ Vt
        L = b_mean - R @ a_mean
        out.append((R, L, np.sqrt(np.sum((A @ R.T + L - frame) ** 2) / A.size)))
    return [np.array(x) for x in zip(*out)]


@pytest.fixture
def exact_path(monkeypatch):
    """The number of frames sent to the exact path, per call of it."""
    sent = []
    original = svdt_module._fit_scaled

    def spy(A, B):
        sent.append(len(B))
        return original(A, B)

    monkeypatch.setattr(svdt_module, "_fit_scaled", spy)
    return sent


def test_ill_conditioned_frames_take_the_exact_path_whole(exact_path):
    # a nearly collinear cluster (width 1e-4 of its length: accepted by svdt) beside
    # frames of an ordinary one would need two fits; here every frame of the thin cluster
    # is ill-conditioned for the closed form, and R, L and RMSE all come from the exact
    # path, equal to one SVD per frame
    A = np.array([[0.0, 0, 0], [100, 0, 0], [200, 0.01, 0], [300, 0, 0.01]])
    R_true = Rotation.random(10, random_state=3).as_matrix()
    rng = np.random.default_rng(1)
    B = np.einsum("fij,nj->fni", R_true, A) + 1000.0 + rng.normal(scale=1e-6,
                                                                  size=(10, 4, 3))
    R, L, rmse = svdt(A, B, order="row")
    assert exact_path == [10]
    R_ref, L_ref, rmse_ref = svd_per_frame(A, B)
    np.testing.assert_allclose(R, R_ref, atol=1e-9)
    np.testing.assert_allclose(L, L_ref, atol=1e-6)
    np.testing.assert_allclose(rmse, rmse_ref, rtol=1e-6)


def test_well_conditioned_frames_stay_in_the_closed_form(exact_path):
    A = np.array([[0.0, 0, 0], [70, 5, 0], [10, 55, 5], [60, 50, 30]])
    R_true = Rotation.random(50, random_state=4).as_matrix()
    B = np.einsum("fij,nj->fni", R_true, A) + 500.0
    svdt(A, B, order="row")
    assert exact_path == []


@pytest.mark.parametrize("n, exact", [(svdt_module.MOMENT_MATRIX_MAX_MARKERS, False),
                                      (svdt_module.MOMENT_MATRIX_MAX_MARKERS + 1, True)])
def test_many_markers_boundary(exact_path, n, exact):
    # documented: "more than MOMENT_MATRIX_MAX_MARKERS = 128 markers" take the exact path
    assert svdt_module.MOMENT_MATRIX_MAX_MARKERS == 128
    rng = np.random.default_rng(n)
    A = rng.normal(scale=100.0, size=(n, 3))
    R_true = Rotation.random(3, random_state=5).as_matrix()
    B = np.einsum("fij,nj->fni", R_true, A) + rng.normal(scale=0.5, size=(3, n, 3))
    R, L, rmse = svdt(A, B, order="row")
    assert (exact_path == [3]) is exact
    R_ref, L_ref, rmse_ref = svd_per_frame(A, B)
    np.testing.assert_allclose(R, R_ref, atol=1e-12)
    np.testing.assert_allclose(rmse, rmse_ref, rtol=1e-10)
