"""Tests of bmc_functions.rigid_body.frames: orthonormal frames from axes and from points."""

import itertools

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bmc_functions import frame_from_axes, frame_from_points

AXES_PAIRS = ["".join(p) for p in itertools.permutations("xyz", 2)]


@pytest.mark.parametrize("axes", AXES_PAIRS)
def test_recovers_a_known_frame(axes):
    R_true = Rotation.random(30, random_state=0).as_matrix()
    i, j = "xyz".index(axes[0]), "xyz".index(axes[1])
    rng = np.random.default_rng(1)
    primary = R_true[:, :, i] * rng.uniform(0.5, 3, (30, 1))
    # secondary: not perpendicular to primary, but on the positive side of axis j
    secondary = R_true[:, :, j] + rng.uniform(-2, 2, (30, 1)) * R_true[:, :, i]
    R = frame_from_axes(primary, secondary, axes)
    np.testing.assert_allclose(R, R_true, atol=1e-12)


def test_gram_schmidt_by_hand():
    R = frame_from_axes([0, 2, 0], [1, 1, 0], "yx")  # y up, x from (1, 1, 0)
    np.testing.assert_allclose(R, np.diag([1.0, 1.0, 1.0]), atol=1e-15)
    R = frame_from_axes([1, 0, 0], [1, 0, -1], "xz")  # z = -e_z -> y = z x x = -e_y
    np.testing.assert_allclose(R, np.diag([1.0, -1.0, -1.0]), atol=1e-15)


def test_always_proper_rotation():
    rng = np.random.default_rng(2)
    R = frame_from_axes(rng.normal(size=(100, 3)), rng.normal(size=(100, 3)), "zx")
    np.testing.assert_allclose(R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape),
                               atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(R), 1, atol=1e-14)


def test_frame_from_points():
    origin = np.array([[1.0, 2, 3], [0, 0, 0]])
    R = frame_from_points(origin, origin + [0, 0, 5], origin + [4, 0, 0], axes="zx")
    np.testing.assert_allclose(R, np.broadcast_to(np.eye(3), (2, 3, 3)), atol=1e-15)


def test_nan_gives_nan_for_that_item_only():
    p = np.array([[1.0, 0, 0], [np.nan, 0, 0]])
    R = frame_from_axes(p, [0, 1, 0])
    assert np.isfinite(R[0]).all() and np.isnan(R[1]).all()


def test_coincident_points_raise():
    with pytest.raises(ValueError, match=r"primary has zero length.*coincident"):
        frame_from_points([0, 0, 0], [0, 0, 0], [0, 1, 0])
    with pytest.raises(ValueError, match=r"secondary has zero length"):
        frame_from_points([1, 1, 1], [2, 1, 1], [1, 1, 1])


def test_collinear_points_raise():
    with pytest.raises(ValueError, match=r"parallel in 1 of 1 items \(collinear points\?\)"):
        frame_from_points([0, 0, 0], [1, 1, 1], [-2, -2, -2])


@pytest.mark.parametrize("axes", ["xx", "x", "xyz", "ab", 1])
def test_bad_axes_raise(axes):
    with pytest.raises(ValueError, match=r"axes must be two different letters"):
        frame_from_axes([1, 0, 0], [0, 1, 0], axes)


def test_bad_shapes_raise():
    with pytest.raises(ValueError, match=r"primary must have shape \(\.\.\., 3\)"):
        frame_from_axes([1, 0], [0, 1, 0])
    with pytest.raises(ValueError, match=r"must broadcast"):
        frame_from_axes(np.ones((3, 3)), np.ones((4, 3)))


def _frame_by_columns(primary, secondary, axes):
    """The documented construction written directly on (..., 3) columns, in the order
    of frame_from_axes' operations (scale, length, Gram-Schmidt, cross product)."""
    def unit(v):
        v = v / np.max(np.abs(v), axis=-1, keepdims=True)
        return v / np.sqrt(v[..., 0] * v[..., 0] + v[..., 1] * v[..., 1]
                           + v[..., 2] * v[..., 2])[..., None]
    u, s = unit(primary), unit(secondary)
    dot = s[..., 0] * u[..., 0] + s[..., 1] * u[..., 1] + s[..., 2] * u[..., 2]
    v = s - dot[..., None] * u
    v = v / np.sqrt(v[..., 0] * v[..., 0] + v[..., 1] * v[..., 1]
                    + v[..., 2] * v[..., 2])[..., None]
    i, j = "xyz".index(axes[0]), "xyz".index(axes[1])
    k = 3 - i - j
    w = np.cross(u, v) if (j - i) % 3 == 1 else np.cross(v, u)
    R = np.empty(u.shape[:-1] + (3, 3))
    R[..., i], R[..., j], R[..., k] = u, v, w
    return R


@pytest.mark.parametrize("axes", ["".join(pair) for pair in itertools.permutations("xyz", 2)])
def test_the_same_numbers_as_the_construction_on_columns(axes):
    # frame_from_axes works on component rows in arrays it writes in place and makes R
    # by one transposing copy: the numbers of the construction written on columns, bit
    # for bit, for one vector, a stack, several leading axes, broadcasting, and NaN items.
    rng = np.random.default_rng(7)
    primary = rng.normal(size=(4, 50, 3)) * 10.0 ** rng.uniform(-3, 3, size=(4, 50, 1))
    secondary = rng.normal(size=(4, 50, 3))
    primary[1, 3] = np.nan
    secondary[2, 5, 1] = np.nan
    for p, s in ((primary, secondary), (primary[0], secondary[0]),
                 (primary[0, 0], secondary[0, 0]),
                 (primary[:, 0], secondary[0, 0])):
        expected = _frame_by_columns(*np.broadcast_arrays(p, s), axes)
        R = frame_from_axes(p, s, axes=axes)
        assert R.shape == expected.shape and R.flags.c_contiguous
        assert np.array_equal(R, expected, equal_nan=True)
    assert np.isnan(frame_from_axes(primary, secondary, axes)[1, 3]).all()
