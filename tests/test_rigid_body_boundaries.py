"""Issue 24: documented boundaries of the rigid-body fit, the chord construction and the
pose checks, pinned by physical cases (not built from the constants under test)."""

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bmc_functions import compose, svdt
from bmc_functions.models.plug_in_gait import chord_joint_centre
from bmc_functions.models.skeleton import _flipped


def svd_rotations(A, B):
    out = []
    for frame in B:
        U, _, Vt = np.linalg.svd((frame - frame.mean(0)).T @ (A - A.mean(0)))
        out.append(U @ np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt))]) @ Vt)
    return np.array(out)


def markers_with_sv_ratio(ratio):
    """4 markers whose centred second singular value is `ratio` times the first."""
    A = np.array([[-1.0, 0, 0], [1.0, 0, 0], [0, 0, 0], [0, 0, 0]]) * 100.0
    A[2, 1], A[3, 1] = 100.0 * ratio, -100.0 * ratio
    A -= A.mean(axis=0)
    sv = np.linalg.svd(A, compute_uv=False)
    assert sv[1] / sv[0] == pytest.approx(ratio, rel=1e-9)
    return A


@pytest.mark.parametrize("ratio, accepted", [(2e-6, True), (1.5e-6, True), (0.5e-6, False)])
def test_collinear_reference_at_the_documented_tolerance(ratio, accepted):
    # documented: refused when the second singular value of the centred markers is at
    # most 1e-6 times the largest
    A = markers_with_sv_ratio(ratio)
    if accepted:
        R, _, _ = svdt(A, A, order="row")
        np.testing.assert_allclose(R, np.eye(3), atol=1e-6)
    else:
        with pytest.raises(ValueError, match="the markers of A are collinear"):
            svdt(A, A, order="row")


@pytest.mark.parametrize("width", [1e-1, 1e-2, 1e-3, 1e-4, 1e-5])
def test_thin_clusters_agree_with_the_svd_within_1e_10(width):
    # documented: the closed form agrees with the SVD within 1e-10; thin clusters are
    # where it is ill-conditioned and must hand its frames to the exact path
    rng = np.random.default_rng(7)
    A = np.array([[0.0, 0, 0], [100, 0, 0], [200, 100 * width, 0], [300, 0, 100 * width]])
    R_true = Rotation.random(200, random_state=1).as_matrix()
    B = np.einsum("fij,nj->fni", R_true, A) + 1000.0 + rng.normal(scale=1e-3 * width,
                                                                  size=(200, 4, 3))
    R, _, _ = svdt(A, B, order="row")
    assert np.abs(R - svd_rotations(A, B)).max() < 1e-10


@pytest.mark.parametrize("delta, defined", [(59.999999, True), (60.0, False), (60.5, False)])
def test_chord_needs_delta_shorter_than_the_marker_distance(delta, defined):
    # documented: NaN where delta is not shorter than |M - P| (no right triangle)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        centre = chord_joint_centre([100.0, 0, 300], [0.0, 0, 0], [60.0, 0, 0], delta)
    assert np.isfinite(centre).all() == defined


@pytest.mark.parametrize("jump, flagged", [(120.0, True), (170.0, True), (60.0, False)])
def test_pose_frame_jumps_beyond_90_degrees_are_flagged(jump, flagged):
    # documented: a root frame turning by more than 90 degrees between consecutive frames
    # is a left-right swap (a trunk turns by under 500 deg/s: 17 degrees per frame at 30
    # frames per second); 10 frames turning 1 degree per frame, with a jump in frames 4-5
    turn = np.arange(10.0)
    turn[4:7] += jump
    R = compose(np.stack([turn, np.zeros(10), np.zeros(10)], axis=1), "YXZ", degrees=True)
    expected = np.zeros(10, bool)
    expected[4:7] = flagged
    np.testing.assert_array_equal(_flipped(R), expected)
