"""Tests of bmc_functions.rigid_body.cardan: decompose and compose, with scipy as the oracle."""

import itertools
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from bmc_functions import compose, decompose, rot_x, rot_y, rot_z
from bmc_functions.rigid_body.cardan import decompose_orthonormal

CARDAN = ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"]
EULER = ["XYX", "XZX", "YXY", "YZY", "ZXZ", "ZYZ"]
SEQUENCES = CARDAN + EULER
CONVENTIONS = list(itertools.product(SEQUENCES, [False, True]))
ELEMENTAL = {"X": rot_x, "Y": rot_y, "Z": rot_z}


def scipy_seq(seq, extrinsic):
    """scipy's spelling: upper case intrinsic, lower case extrinsic."""
    return seq.lower() if extrinsic else seq.upper()


def random_rotations(seed, n):
    return Rotation.random(n, random_state=seed).as_matrix()


quaternions = st.lists(st.floats(-1, 1, allow_nan=False), min_size=4, max_size=4).filter(
    lambda q: np.linalg.norm(q) > 0.1)


# --- hand-derived values ---------------------------------------------------------------

def test_seed_zxy_formulas_by_hand():
    # R = Rz Rx Ry; the seed reads theta_z = atan2(-r01, r11), theta_y = atan2(-r20, r22),
    # theta_x = atan2(r21, sqrt(r20^2 + r22^2)).
    z, x, y = 0.7, -0.3, 1.1
    R = rot_z(z) @ rot_x(x) @ rot_y(y)
    expected = [np.arctan2(-R[0, 1], R[1, 1]),
                np.arctan2(R[2, 1], np.hypot(R[2, 0], R[2, 2])),
                np.arctan2(-R[2, 0], R[2, 2])]
    np.testing.assert_allclose(expected, [z, x, y], atol=1e-14)
    np.testing.assert_allclose(decompose(R, "ZXY"), [z, x, y], atol=1e-14)


@pytest.mark.parametrize("seq", SEQUENCES)
@pytest.mark.parametrize("extrinsic", [False, True])
def test_decompose_recovers_angles_of_elemental_product(seq, extrinsic):
    a, b, c = 0.4, (1.2 if seq[0] == seq[2] else -0.5), -2.3
    Ra, Rb, Rc = (ELEMENTAL[axis](angle) for axis, angle in zip(seq, (a, b, c)))
    R = Rc @ Rb @ Ra if extrinsic else Ra @ Rb @ Rc
    np.testing.assert_allclose(decompose(R, seq, extrinsic=extrinsic), [a, b, c],
                               atol=1e-13)
    np.testing.assert_allclose(compose([a, b, c], seq, extrinsic=extrinsic), R, atol=1e-15)


def test_degrees_and_letter_case():
    R = rot_z(30, degrees=True) @ rot_x(-20, degrees=True) @ rot_y(10, degrees=True)
    for seq in ("ZXY", "zxy", "Zxy", "zXy"):
        np.testing.assert_allclose(decompose(R, seq, degrees=True), [30, -20, 10],
                                   atol=1e-12)


def test_extrinsic_equals_reversed_intrinsic():
    R = random_rotations(0, 50)
    for seq in SEQUENCES:
        np.testing.assert_allclose(decompose(R, seq, extrinsic=True),
                                   decompose(R, seq[::-1])[..., ::-1], atol=1e-12)


# --- scipy as the oracle ---------------------------------------------------------------

@pytest.mark.parametrize("seq,extrinsic", CONVENTIONS)
def test_decompose_agrees_with_scipy_on_random_rotations(seq, extrinsic):
    R = random_rotations(42, 500)
    ours = decompose(R, seq, extrinsic=extrinsic)
    theirs = Rotation.from_matrix(R).as_euler(scipy_seq(seq, extrinsic))
    # the same angle modulo 2 pi (scipy may give -pi where we give +pi)
    np.testing.assert_allclose(np.angle(np.exp(1j * (ours - theirs))), 0, atol=1e-10)


@settings(max_examples=100, deadline=None)
@given(q=quaternions, convention=st.sampled_from(CONVENTIONS))
def test_decompose_agrees_with_scipy_and_compose_inverts_it_property(q, convention):
    seq, extrinsic = convention
    R = Rotation.from_quat(q).as_matrix()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # hypothesis finds gimbal lock
        ours = decompose(R, seq, extrinsic=extrinsic)
    np.testing.assert_allclose(compose(ours, seq, extrinsic=extrinsic), R, atol=1e-12)
    middle = ours[1] if seq[0] == seq[2] else ours[1] - np.pi / 2
    if abs(np.sin(middle)) > 1e-6 and abs(np.cos(ours[1])) > 1e-6:  # away from gimbal lock
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            theirs = Rotation.from_matrix(R).as_euler(scipy_seq(seq, extrinsic))
        np.testing.assert_allclose(np.angle(np.exp(1j * (ours - theirs))), 0, atol=1e-8)


@pytest.mark.parametrize("seq,extrinsic", CONVENTIONS)
def test_compose_agrees_with_scipy(seq, extrinsic):
    angles = np.random.default_rng(1).uniform(-np.pi, np.pi, (200, 3))
    expected = Rotation.from_euler(scipy_seq(seq, extrinsic), angles).as_matrix()
    np.testing.assert_allclose(compose(angles, seq, extrinsic=extrinsic), expected,
                               atol=1e-14)
    np.testing.assert_allclose(
        compose(np.rad2deg(angles), seq, extrinsic=extrinsic, degrees=True), expected,
        atol=1e-13)


@pytest.mark.parametrize("seq,extrinsic", CONVENTIONS)
def test_angle_ranges(seq, extrinsic):
    angles = decompose(random_rotations(7, 2000), seq, extrinsic=extrinsic)
    assert np.all(angles[:, [0, 2]] > -np.pi) and np.all(angles[:, [0, 2]] <= np.pi)
    if seq[0] == seq[2]:
        assert np.all(angles[:, 1] >= 0) and np.all(angles[:, 1] <= np.pi)
    else:
        assert np.all(np.abs(angles[:, 1]) <= np.pi / 2)


# --- gimbal lock ------------------------------------------------------------------------

@pytest.mark.parametrize("seq,extrinsic", CONVENTIONS)
@pytest.mark.parametrize("lock", ["low", "high"])
def test_gimbal_lock_reproduces_matrix_third_angle_zero(seq, extrinsic, lock):
    euler = seq[0] == seq[2]
    middle = {("low", True): 0.0, ("high", True): np.pi,
              ("low", False): -np.pi / 2, ("high", False): np.pi / 2}[lock, euler]
    rng = np.random.default_rng(3)
    n = 20
    angles = np.column_stack([rng.uniform(-3, 3, n), np.full(n, middle), rng.uniform(-3, 3, n)])
    R = compose(angles, seq, extrinsic=extrinsic)
    with pytest.warns(RuntimeWarning, match=rf"{n} of {n} frames are in gimbal lock"):
        found = decompose(R, seq, extrinsic=extrinsic)
    assert np.isfinite(found).all()
    np.testing.assert_array_equal(found[:, 2], 0.0)
    np.testing.assert_allclose(np.abs(found[:, 1]), abs(middle), atol=1e-7)
    np.testing.assert_allclose(compose(found, seq, extrinsic=extrinsic), R, atol=1e-12)


def test_gimbal_lock_two_angle_sets_one_matrix_and_one_warning_per_call():
    R1 = compose([0.5, np.pi / 2, 0.2])  # ZXY: only z + y is defined in lock
    R2 = compose([0.7, np.pi / 2, 0.0])
    np.testing.assert_allclose(R1, R2, atol=1e-15)
    R = np.stack([R1, compose([0.1, 0.2, 0.3]), R2])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        angles = decompose(R)
    assert len(caught) == 1 and "2 of 3 frames" in str(caught[0].message)
    np.testing.assert_allclose(angles[0], [0.7, np.pi / 2, 0], atol=1e-12)
    np.testing.assert_allclose(angles[1], [0.1, 0.2, 0.3], atol=1e-14)


@pytest.mark.parametrize("seq,extrinsic", CONVENTIONS)
def test_near_gimbal_lock_still_reproduces_matrix(seq, extrinsic):
    euler = seq[0] == seq[2]
    rng = np.random.default_rng(5)
    offsets = np.array([1e-15, 1e-13, 1e-11, 1e-9, 1e-7, 1e-5])
    middle = offsets if euler else np.pi / 2 - offsets
    angles = np.column_stack([rng.uniform(-3, 3, 6), middle, rng.uniform(-3, 3, 6)])
    R = compose(angles, seq, extrinsic=extrinsic)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        found = decompose(R, seq, extrinsic=extrinsic)
    # setting the third angle to 0 within GIMBAL_TOL = 1e-12 costs at most pi * 1e-12
    np.testing.assert_allclose(compose(found, seq, extrinsic=extrinsic), R, atol=4e-12)


# --- shapes, NaN ------------------------------------------------------------------------

def test_shapes_broadcast_over_leading_axes():
    R = random_rotations(2, 24).reshape(2, 3, 4, 3, 3)
    angles = decompose(R, "XYZ")
    assert angles.shape == (2, 3, 4, 3)
    assert compose(angles, "XYZ").shape == (2, 3, 4, 3, 3)
    assert decompose(np.eye(3)).shape == (3,)


def test_nan_matrix_gives_nan_angles_for_that_frame_only():
    R = random_rotations(4, 3)
    R[1, 0, 0] = np.nan
    angles = decompose(R, "ZXY")
    assert np.isnan(angles[1]).all()
    assert np.isfinite(angles[[0, 2]]).all()
    assert np.isnan(compose(angles, "ZXY")[1]).all()


# --- bad input --------------------------------------------------------------------------

def test_not_orthonormal_raises():
    R = np.eye(3)
    R[0, 1] = 0.01
    with pytest.raises(ValueError, match=r"not a rotation matrix.*R @ R.T differs"):
        decompose(R)


def test_reflection_raises():
    with pytest.raises(ValueError, match=r"det\(R\) = -1.*reflection"):
        decompose(np.diag([1.0, 1.0, -1.0]))


@pytest.mark.parametrize("shape", [(3,), (3, 4), (2, 2, 2)])
def test_wrong_shape_raises(shape):
    with pytest.raises(ValueError, match=r"R must have shape \(\.\.\., 3, 3\); got shape"):
        decompose(np.zeros(shape))


@pytest.mark.parametrize("seq", ["XXY", "XYY", "XY", "XYZX", "ABC", "", 3])
def test_unknown_sequence_raises(seq):
    with pytest.raises(ValueError, match=r"sequence"):
        decompose(np.eye(3), seq)
    with pytest.raises(ValueError, match=r"sequence"):
        compose([0, 0, 0], seq)


def test_compose_bad_angles_raise():
    with pytest.raises(ValueError, match=r"angles must have shape \(\.\.\., 3\)"):
        compose([0.1, 0.2])
    with pytest.raises(ValueError, match=r"angles contains infinite values"):
        compose([0.1, np.inf, 0.2])
    with pytest.raises(ValueError, match=r"angles must be a numeric array"):
        compose(["a", "b", "c"])


def test_complex_input_raises():
    with pytest.raises(ValueError, match=r"R must be real; got complex"):
        decompose(np.eye(3) + 0j)
    with pytest.raises(ValueError, match=r"angles must be real"):
        compose([1j, 0, 0])


def test_extrinsic_and_degrees_are_keyword_only():
    with pytest.raises(TypeError):
        decompose(np.eye(3), "ZXY", True)
    with pytest.raises(TypeError):
        compose([0, 0, 0], "ZXY", True)


# --- decompose_orthonormal: decompose without the rotation test (issue 34) ----------------

@pytest.mark.parametrize("seq, extrinsic", CONVENTIONS)
def test_decompose_orthonormal_is_decompose_bit_for_bit(seq, extrinsic):
    R = Rotation.random(200, random_state=7).as_matrix()
    R[3] = np.nan                                             # a missing frame
    R[5] = rot_x(0.4) @ rot_y(0.3)                            # exact, no rounding noise
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        checked = decompose(R, seq, extrinsic=extrinsic, degrees=True)
        unchecked = decompose_orthonormal(R, seq, extrinsic=extrinsic, degrees=True)
    np.testing.assert_array_equal(unchecked, checked)
    assert np.isnan(unchecked[3]).all() and np.isfinite(np.delete(unchecked, 3, 0)).all()


def test_decompose_orthonormal_skips_only_the_rotation_test():
    scaled = 2.0 * np.eye(3)                                  # not a rotation
    with pytest.raises(ValueError, match="not a rotation matrix"):
        decompose(scaled)
    assert decompose_orthonormal(scaled).shape == (3,)        # no test, by design
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 3, 3\)"):
        decompose_orthonormal(np.eye(2))
    with pytest.raises(ValueError, match="sequence"):
        decompose_orthonormal(np.eye(3), "XXY")
    with pytest.warns(RuntimeWarning, match="1 of 1 frames are in gimbal lock"):
        decompose_orthonormal(rot_x(np.pi / 2), "YXZ")
