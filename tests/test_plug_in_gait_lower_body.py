"""Tests of bmc_functions.models.plug_in_gait.lower_body's arithmetic written for speed:
the same numbers, bit for bit, as the plain numpy formulas it replaces."""

import warnings

import numpy as np
import pytest

from bmc_functions.models.plug_in_gait.lower_body import axes_zy, chord_joint_centre


def _plain_axes_zy(y, z):
    """Gram-Schmidt 'zy' in plain numpy: z unit, y made perpendicular and unit, x = y x z."""
    z = np.asarray(z, dtype=float)
    z = z / np.linalg.norm(z, axis=-1, keepdims=True)
    y = np.asarray(y, dtype=float)
    y = y - np.sum(y * z, axis=-1, keepdims=True) * z
    y = y / np.linalg.norm(y, axis=-1, keepdims=True)
    return np.stack(np.broadcast_arrays(np.cross(y, z), y, z), axis=-1)


@pytest.mark.parametrize("y_shape, z_shape", [((500, 3), (500, 3)), ((3,), (3,)),
                                              ((500, 3), (3,)), ((3,), (500, 3)),
                                              ((4, 6, 3), (6, 3)), ((0, 3), (3,))])
@pytest.mark.parametrize("fortran", [False, True])
def test_axes_zy_is_plain_gram_schmidt_bit_for_bit(y_shape, z_shape, fortran):
    """Random directions (some NaN, one zero, large and small magnitudes), C- or
    column-major like a trial's points, broadcast: every bit as the plain formula, the
    same shape and a C-ordered result; the inputs untouched."""
    rng = np.random.default_rng(7)
    y = rng.normal(size=y_shape) * 10.0 ** rng.integers(-3, 4, size=y_shape)
    z = rng.normal(size=z_shape) * 10.0 ** rng.integers(-3, 4, size=z_shape)
    if y.ndim == 2 and len(y) > 10:
        y[3] = np.nan
        y[7, 1] = np.nan
        y[9] = 0.0
    if fortran:
        y, z = np.asfortranarray(y), np.asfortranarray(z)
    y_before, z_before = y.copy(), z.copy()
    with np.errstate(invalid="ignore", divide="ignore"):
        expected = _plain_axes_zy(y, z)
    R = axes_zy(y=y, z=z)
    assert R.shape == expected.shape and R.flags.c_contiguous
    assert np.array_equal(R, expected, equal_nan=True)
    assert np.array_equal(y, y_before, equal_nan=True) and np.array_equal(z, z_before)


def _plain_chord(W, P, M, delta):
    """The chord construction in plain numpy, as chord_joint_centre's Notes write it."""
    v = M - P
    d = np.linalg.norm(v, axis=-1, keepdims=True)
    e1 = v / d
    w = W - P
    w = w - np.sum(w * e1, axis=-1, keepdims=True) * e1
    e2 = w / np.linalg.norm(w, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore"):
        legs = d ** 2 - delta ** 2
        legs = np.where(legs > 0, legs, np.nan)
        return P + legs / d * e1 - np.sqrt(legs) * delta / d * e2


def _laid_out(points, layout):
    """The same (frames, 3) values, row- or column-major, or a strided view of either."""
    if layout == "C":
        return np.ascontiguousarray(points)
    if layout == "F":
        return np.asfortranarray(points)
    if layout == "column of a stack":                       # like R[..., 1]: rows strided
        stack = np.full(points.shape + (3,), np.nan)
        stack[..., 1] = points
        return stack[..., 1]
    if layout == "reversed":                                # frames backwards: steps < 0
        return np.ascontiguousarray(points[::-1])[::-1]
    if layout == "reversed F":
        return np.asfortranarray(points[::-1])[::-1]
    every_other = np.full((2 * len(points), 3), np.nan, order="F")
    every_other[::2] = points
    return every_other[::2]                                 # column-major, strided


@pytest.mark.parametrize("layouts", [("F", "C", "F"), ("F", "F", "F"), ("C", "C", "C"),
                                     ("C", "F", "F"), ("F", "column of a stack", "F"),
                                     ("every other", "every other", "every other"),
                                     ("every other", "C", "F"),
                                     ("reversed F", "reversed F", "reversed F"),
                                     ("reversed", "F", "C")])
def test_chord_joint_centre_is_the_plain_construction_bit_for_bit(layouts):
    """A knee-like geometry with noise, missing markers, a lateral marker nearer than
    delta (no triangle) and one on the proximal centre: every bit, NaN, the memory
    layout and the warnings of the plain formula, whatever the stacks' layouts."""
    rng = np.random.default_rng(11)
    frames = 300
    P = np.array([0.0, 0.0, 400.0]) + rng.normal(size=(frames, 3)) * 30.0
    M = np.array([0.0, -60.0, 0.0]) + rng.normal(size=(frames, 3)) * 10.0 ** rng.integers(
        -2, 3, size=(frames, 3))
    W = np.array([100.0, 0.0, 300.0]) + rng.normal(size=(frames, 3)) * 20.0
    W[4] = np.nan
    M[6, 2] = np.nan
    M[8] = P[8] + [1.0, 0.0, 0.0]                          # |M - P| < delta
    M[9] = P[9]                                             # 0 / 0
    W, P, M = (_laid_out(a, layout) for a, layout in zip((W, P, M), layouts))
    with warnings.catch_warnings(record=True) as plain_warnings:
        warnings.simplefilter("always")
        expected = _plain_chord(W, P, M, 60.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        J = chord_joint_centre(W, P, M, 60.0)
    assert np.array_equal(J, expected, equal_nan=True)
    assert np.array_equal(np.signbit(J), np.signbit(expected))     # a NaN's sign too
    assert J.strides == expected.strides
    assert ([str(w.message) for w in caught] == [str(w.message) for w in plain_warnings]
            and caught)
