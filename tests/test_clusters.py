"""Tests of bmc_functions.rigid_body.clusters: predicted orientation error of a marker cluster."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from bmc_functions import expected_orientation_error, orientation_error_covariance, svdt


def polygon(n, radius):
    t = 2 * np.pi * np.arange(n) / n
    return radius * np.stack([np.cos(t), np.sin(t), np.zeros(n)], axis=1)


TETRAHEDRON = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]]) / np.sqrt(3)


# --- hand-derived values ----------------------------------------------------------------

@pytest.mark.parametrize("n", [3, 4, 5, 8])
def test_regular_polygon_by_hand(n):
    # C = diag(n r^2/2, n r^2/2, 0) for any regular n-gon (n >= 3), so
    # K = tr(C) I - C = diag(n r^2/2, n r^2/2, n r^2) and cov = sigma^2 K^-1
    r, sigma = 40.0, 0.7
    expected = sigma**2 / (n * r**2) * np.diag([2.0, 2.0, 1.0])
    np.testing.assert_allclose(orientation_error_covariance(polygon(n, r), sigma), expected,
                               rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(expected_orientation_error(polygon(n, r), sigma),
                               np.sqrt(5) * sigma / (np.sqrt(n) * r), rtol=1e-12)


def test_tetrahedron_by_hand():
    # vertices at distance d from the centre: C = (4 d^2/3) I, K = (8 d^2/3) I
    d, sigma = 50.0, 0.5
    cov = orientation_error_covariance(d * TETRAHEDRON + [10, -20, 300], sigma)
    np.testing.assert_allclose(cov, 3 * sigma**2 / (8 * d**2) * np.eye(3), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(expected_orientation_error(d * TETRAHEDRON, sigma, degrees=True),
                               np.degrees(np.sqrt(9 / 8) * sigma / d), rtol=1e-12)


def test_elongated_rectangle_by_hand():
    # markers at (+-a, +-b, 0): C = diag(4a^2, 4b^2, 0), K = diag(4b^2, 4a^2, 4a^2 + 4b^2)
    a, b, sigma = 60.0, 10.0, 1.0
    rect = np.array([[a, b, 0], [-a, b, 0], [-a, -b, 0], [a, -b, 0]])
    expected = sigma**2 * np.diag([1 / (4 * b**2), 1 / (4 * a**2), 1 / (4 * a**2 + 4 * b**2)])
    np.testing.assert_allclose(orientation_error_covariance(rect, sigma), expected, rtol=1e-12)


def test_zero_noise_gives_zero_error():
    np.testing.assert_array_equal(expected_orientation_error(polygon(4, 30), 0.0), 0.0)


# --- properties -------------------------------------------------------------------------

clusters = st.integers(3, 8).flatmap(lambda n: st.lists(
    st.tuples(*[st.floats(-100, 100, allow_nan=False)] * 3), min_size=n, max_size=n)).map(
    np.array).filter(lambda m: np.linalg.svd(m - m.mean(0), compute_uv=False)[1] > 1.0)


@settings(max_examples=60, deadline=None)
@given(markers=clusters, seed=st.integers(0, 2**32 - 1),
       shift=st.tuples(*[st.floats(-1e3, 1e3)] * 3))
def test_rotating_the_cluster_rotates_the_covariance(markers, seed, shift):
    R = Rotation.random(random_state=seed).as_matrix()
    cov = orientation_error_covariance(markers, 1.0)
    moved = orientation_error_covariance(markers @ R.T + np.array(shift), 1.0)
    np.testing.assert_allclose(moved, R @ cov @ R.T, rtol=1e-6, atol=1e-9 * np.abs(cov).max())
    np.testing.assert_allclose(expected_orientation_error(markers @ R.T, 2.0),
                               2 * expected_orientation_error(markers, 1.0), rtol=1e-6)


@settings(max_examples=60, deadline=None)
@given(markers=clusters, seed=st.integers(0, 2**32 - 1))
def test_linear_response_matches_svdt(markers, seed):
    # a tiny perturbation eps of the markers tilts the svdt fit by dtheta = K^-1 sum a x eps,
    # so cov = sigma^2 K^-1; the test recovers K^-1 from cov and checks it against svdt
    rng = np.random.default_rng(seed)
    eps = 1e-6 * rng.standard_normal(markers.shape)
    R = svdt(markers, markers + eps, order="row")[0]
    dtheta = Rotation.from_matrix(R).as_rotvec()
    K_inv = orientation_error_covariance(markers, 1.0)
    centred = markers - markers.mean(0)
    predicted = K_inv @ np.cross(centred, eps).sum(0)
    np.testing.assert_allclose(dtheta, predicted, atol=1e-4 * np.abs(predicted).max() + 1e-14)


def test_monte_carlo_agrees_with_prediction():
    # independent check: the sample covariance of svdt's error over many noisy frames
    rng = np.random.default_rng(1993)
    markers = np.array([[40, 5, 0], [-10, 35, 8], [-30, -20, -4], [5, -25, 12], [0, 0, 30.0]])
    sigma, frames = 0.5, 20000
    R_true = Rotation.from_euler("zxy", [30, -20, 45], degrees=True).as_matrix()
    B = markers @ R_true.T + [500, 200, 900] + sigma * rng.standard_normal((frames, 5, 3))
    R_est = svdt(markers, B, order="row")[0]
    rotvec = Rotation.from_matrix(R_true.T @ R_est).as_rotvec()  # in the cluster frame
    predicted = orientation_error_covariance(markers, sigma)
    np.testing.assert_allclose(np.cov(rotvec.T), predicted, atol=0.03 * np.abs(predicted).max())
    rms = np.sqrt(np.mean(np.sum(rotvec**2, axis=1)))
    np.testing.assert_allclose(rms, expected_orientation_error(markers, sigma), rtol=0.02)


def test_vectorized_over_clusters_and_noise():
    stack = np.stack([polygon(4, 20), polygon(4, 40), 30 * TETRAHEDRON])
    sigma = np.array([1.0, 1.0, 0.5])
    error = expected_orientation_error(stack, sigma)
    assert error.shape == (3,)
    for k in range(3):
        assert error[k] == pytest.approx(float(expected_orientation_error(stack[k], sigma[k])))
    assert orientation_error_covariance(stack[None], 1.0).shape == (1, 3, 3, 3)
    assert error[0] == pytest.approx(2 * error[1])  # twice the size, half the error


# --- bad input --------------------------------------------------------------------------

def test_markers_wrong_shape():
    with pytest.raises(ValueError, match=r"markers must have shape \(\.\.\., n, 3\).*\(4, 2\)"):
        expected_orientation_error(np.zeros((4, 2)), 1.0)


def test_markers_one_dimensional():
    with pytest.raises(ValueError, match=r"markers must have shape.*\(12,\)"):
        expected_orientation_error(np.arange(12.0), 1.0)


def test_too_few_markers():
    with pytest.raises(ValueError, match="at least 3 markers.*2 marker"):
        expected_orientation_error([[0, 0, 0], [1, 0, 0]], 1.0)


def test_markers_not_numeric():
    with pytest.raises(ValueError, match="markers must be a numeric array"):
        expected_orientation_error([["a", "b", "c"]] * 3, 1.0)


def test_markers_with_nan():
    markers = polygon(4, 30)
    markers[1, 0] = np.nan
    with pytest.raises(ValueError, match="markers contains NaN"):
        expected_orientation_error(markers, 1.0)


def test_markers_with_inf():
    markers = polygon(4, 30)
    markers[1, 0] = np.inf
    with pytest.raises(ValueError, match="markers contains infinite"):
        expected_orientation_error(markers, 1.0)


def test_collinear_cluster():
    line = np.array([[0, 0, 0], [10, 0, 0], [25, 0, 0], [40, 0, 0.0]])
    with pytest.raises(ValueError, match="1 of 2 cluster.*collinear"):
        expected_orientation_error(np.stack([line, polygon(4, 30)]), 1.0)


def test_coincident_markers():
    with pytest.raises(ValueError, match="coincident or collinear"):
        orientation_error_covariance(np.ones((4, 3)), 1.0)


@pytest.mark.parametrize("noise_sd", [-0.5, np.nan, np.inf])
def test_bad_noise_sd(noise_sd):
    with pytest.raises(ValueError, match="noise_sd must be finite and >= 0"):
        expected_orientation_error(polygon(4, 30), noise_sd)


def test_noise_sd_wrong_shape():
    with pytest.raises(ValueError, match=r"noise_sd must .*broadcast.*\(2,\).*\(3,\)"):
        expected_orientation_error(np.stack([polygon(4, 30)] * 2), [1.0, 2.0, 3.0])
