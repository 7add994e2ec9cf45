"""Tests of bmc_functions.rigid_body.rotations: elemental rotations, get_R, rotation_angle."""

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from bmc_functions import elemental_rotation, get_R, rot_x, rot_y, rot_z, rotation_angle
from bmc_functions.rigid_body.rotations import skew, unit_vectors, vector_dot, vector_length

coordinate = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)
vectors = st.tuples(coordinate, coordinate, coordinate).map(np.array).filter(
    lambda v: np.linalg.norm(v) > 1e-3)


def assert_proper_rotation(R, atol=1e-12):
    np.testing.assert_allclose(R @ np.swapaxes(R, -1, -2), np.broadcast_to(np.eye(3), R.shape),
                               atol=atol)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=atol)


# --- elemental rotations ----------------------------------------------------------------

@pytest.mark.parametrize("axis", "xyz")
def test_elemental_rotation_agrees_with_scipy(axis):
    angles = np.linspace(-4, 4, 17)
    expected = Rotation.from_euler(axis, angles[:, None]).as_matrix()
    np.testing.assert_allclose(elemental_rotation(axis, angles), expected, atol=1e-15)
    np.testing.assert_allclose(elemental_rotation(axis.upper(), np.rad2deg(angles),
                                                  degrees=True), expected, atol=1e-14)


def test_elemental_rotations_by_hand():
    # where the unit vectors go under a quarter turn (right-hand rule)
    np.testing.assert_allclose(rot_z(np.pi / 2) @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(rot_x(np.pi / 2) @ [0, 1, 0], [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(rot_y(np.pi / 2) @ [0, 0, 1], [1, 0, 0], atol=1e-15)


def test_elemental_rotation_bad_axis():
    with pytest.raises(ValueError, match=r"axis must be one of 'x', 'y', 'z'; got 'w'"):
        elemental_rotation("w", 0.1)


def test_skew_is_cross_product():
    a, b = np.random.default_rng(0).normal(size=(2, 5, 3))
    np.testing.assert_allclose(np.einsum("nij,nj->ni", skew(a), b), np.cross(a, b),
                               atol=1e-14)


# --- get_R: hand-derived and special cases ----------------------------------------------

def test_get_R_quarter_turn_by_hand():
    R = get_R([2, 0, 0], [0, 0, 5])  # x onto z: -90 degrees about y
    np.testing.assert_allclose(R, rot_y(-np.pi / 2), atol=1e-15)


def test_get_R_parallel_is_identity_exactly():
    R = get_R([1.0, 2.0, 3.0], [2.0, 4.0, 6.0])
    np.testing.assert_allclose(R, np.eye(3), atol=1e-15)
    assert np.isfinite(R).all()


@pytest.mark.parametrize("a,axis", [([1, 0, 0], [0, 0, 1]), ([0, 1, 0], [0, 0, -1]),
                                    ([0, 0, 2], [0, 1, 0]),
                                    ([1, 1, 0], [2**-0.5, -(2**-0.5), 0])])
def test_get_R_antiparallel_documented_rule(a, axis):
    # pi about  a_hat x e_j, with e_j the axis of a's smallest |component| (lowest index)
    a = np.asarray(a, float)
    R = get_R(a, -3 * a)
    k = np.asarray(axis, float)
    np.testing.assert_allclose(R, 2 * np.outer(k, k) - np.eye(3), atol=1e-15)
    np.testing.assert_allclose(R @ a, -a, atol=1e-14)
    assert_proper_rotation(R)


@pytest.mark.parametrize("epsilon", [1e-4, 1e-8, 1e-12, 1e-15, 0.0])
@pytest.mark.parametrize("antiparallel", [False, True])
def test_get_R_nearly_parallel_or_antiparallel_is_exact(epsilon, antiparallel):
    rng = np.random.default_rng(11)
    a = rng.normal(size=(20, 3))
    perturbation = np.cross(a, rng.normal(size=(20, 3)))
    b = (-a if antiparallel else a) + epsilon * perturbation
    R = get_R(a, b)
    assert np.isfinite(R).all()
    assert_proper_rotation(R)
    a_hat = a / np.linalg.norm(a, axis=1, keepdims=True)
    b_hat = b / np.linalg.norm(b, axis=1, keepdims=True)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", R, a_hat), b_hat, atol=1e-14)


def test_get_R_broadcasts():
    assert get_R(np.ones((4, 1, 3)), np.eye(3)).shape == (4, 3, 3, 3)
    assert get_R([1, 0, 0], [0, 1, 0]).shape == (3, 3)


def test_get_R_nan_only_in_that_item():
    A = np.array([[1.0, 0, 0], [np.nan, 0, 0], [0, 1, 0]])
    B = np.array([[0.0, 1, 0], [0, 1, 0], [0, 1, np.nan]])
    R = get_R(A, B)
    assert np.isfinite(R[0]).all()
    assert np.isnan(R[1]).all() and np.isnan(R[2]).all()


@pytest.mark.parametrize("A,B,name", [([0, 0, 0], [1, 0, 0], "A"), ([1, 0, 0], [0, 0, 0], "B")])
def test_get_R_zero_length_raises(A, B, name):
    with pytest.raises(ValueError, match=rf"{name} has zero length"):
        get_R(A, B)


def test_get_R_zero_length_reports_index():
    A = np.ones((5, 3))
    A[3] = 0
    with pytest.raises(ValueError, match=r"1 of 5 vectors \(first at index \(3,\)\)"):
        get_R(A, np.ones(3))


def test_get_R_bad_shapes_raise():
    with pytest.raises(ValueError, match=r"A must have shape \(\.\.\., 3\)"):
        get_R([1, 0], [0, 1, 0])
    with pytest.raises(ValueError, match=r"must broadcast"):
        get_R(np.ones((4, 3)), np.ones((5, 3)))
    with pytest.raises(ValueError, match=r"B contains infinite values"):
        get_R([1, 0, 0], [np.inf, 0, 0])


# --- get_R: properties, scipy as the oracle --------------------------------------------

@settings(max_examples=200, deadline=None)
@given(a=vectors, b=vectors)
def test_get_R_properties(a, b):
    R = get_R(a, b)
    a_hat, b_hat = a / np.linalg.norm(a), b / np.linalg.norm(b)
    assert_proper_rotation(R)
    np.testing.assert_allclose(R @ a_hat, b_hat, atol=1e-12)
    angle_between = np.arctan2(np.linalg.norm(np.cross(a_hat, b_hat)), a_hat @ b_hat)
    np.testing.assert_allclose(rotation_angle(R), angle_between, atol=1e-9)
    # minimal: the rotation axis is perpendicular to both vectors
    rotvec = Rotation.from_matrix(R).as_rotvec()
    if np.linalg.norm(rotvec) > 1e-6 and np.linalg.norm(np.cross(a_hat, b_hat)) > 1e-6:
        np.testing.assert_allclose(rotvec @ a_hat, 0, atol=1e-8)
        np.testing.assert_allclose(rotvec @ b_hat, 0, atol=1e-8)


@settings(max_examples=200, deadline=None)
@given(a=vectors, b=vectors)
def test_get_R_agrees_with_scipy_align_vectors(a, b):
    a_hat, b_hat = a / np.linalg.norm(a), b / np.linalg.norm(b)
    assume(np.linalg.norm(np.cross(a_hat, b_hat)) > 1e-6)  # scipy's axis is arbitrary when (anti)parallel
    # align_vectors(b, a) finds the rotation C minimizing |b - C a|; for one pair, the minimal one
    expected = Rotation.align_vectors(b_hat[None], a_hat[None])[0].as_matrix()
    np.testing.assert_allclose(get_R(a, b), expected, atol=1e-9)


# --- rotation_angle, unit_vectors -------------------------------------------------------

def test_rotation_angle_matches_scipy():
    rotations = Rotation.random(100, random_state=3)
    np.testing.assert_allclose(rotation_angle(rotations.as_matrix()), rotations.magnitude(),
                               atol=1e-12)
    np.testing.assert_allclose(rotation_angle(rot_x(1e-9)), 1e-9, rtol=1e-6)


def test_rotation_angle_bad_shape():
    with pytest.raises(ValueError, match=r"R must have shape \(\.\.\., 3, 3\)"):
        rotation_angle(np.eye(2))


@pytest.mark.parametrize("R,problem", [(np.diag([1.0, 1.0, -1.0]), r"det\(R\) = -1"),
                                       (2 * np.eye(3), r"R @ R.T differs")])
def test_rotation_angle_refuses_non_rotations(R, problem):
    # both would give an angle of 0, silently
    with pytest.raises(ValueError, match=rf"not a rotation matrix.*{problem}"):
        rotation_angle(R)


def test_rotation_angle_nan_item():
    R = np.stack([rot_x(0.3), np.full((3, 3), np.nan)])
    angle = rotation_angle(R)
    assert angle[0] == pytest.approx(0.3) and np.isnan(angle[1])


def test_elemental_rotation_refuses_infinite_angles():
    with pytest.raises(ValueError, match=r"angle contains infinite values"):
        rot_x(np.inf)
    # a NaN angle leaves only the entries that depend on it undetermined
    R = rot_y([0.0, np.nan])[1]
    np.testing.assert_array_equal(np.isnan(R), [[1, 0, 1], [0, 0, 0], [1, 0, 1]])


def test_unit_vectors():
    np.testing.assert_allclose(unit_vectors([[3, 0, 4], [0, 2, 0]]), [[0.6, 0, 0.8], [0, 1, 0]])
    with pytest.raises(ValueError, match=r"v has zero length"):
        unit_vectors([0, 0, 0])


def test_vector_length_and_dot_are_numpys_values_bit_for_bit():
    """The written-out lengths and dot products of the model's hot paths give exactly
    np.linalg.norm's and np.sum's values (same order of summation), NaN included."""
    from bmc_functions.rigid_body.rotations import vector_dot, vector_length
    rng = np.random.default_rng(7)
    a, b = rng.normal(scale=500.0, size=(2, 4, 1000, 3))
    a[1, 3] = np.nan
    assert np.array_equal(vector_length(a), np.linalg.norm(a, axis=-1), equal_nan=True)
    assert np.array_equal(vector_dot(a, b), np.sum(a * b, axis=-1), equal_nan=True)
