"""Tests of bmc_functions.models.plug_in_gait.lower_body's arithmetic written for speed:
the same numbers, bit for bit, as the plain numpy formulas it replaces."""

import numpy as np
import pytest

from bmc_functions.models.plug_in_gait.lower_body import axes_zy


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
