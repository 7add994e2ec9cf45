"""Tests of the centroid of the visible markers that check_handedness (Plug-in Gait's
labels) sums without a stack: the same numbers, bit for bit, as visible_centroid of the
stack."""

import warnings

import numpy as np
import pytest

from bmc_functions.models.lower_limb_checks import coordinate_centroids, visible_centroid


@pytest.mark.parametrize("case", ["seen", "gaps", "overflow", "negative zeros"])
@pytest.mark.parametrize("count", [1, 2, 8])
def test_visible_centroid_without_a_stack_is_visible_centroid(case, count):
    """Column-major (frames, 3) markers like a trial's points, with large and small
    magnitudes: every bit, NaN and zero sign as visible_centroid(np.stack(...)), in
    every frame, also where no marker or one coordinate is seen; C-ordered."""
    rng = np.random.default_rng(3)
    markers = [np.asfortranarray(rng.normal(size=(400, 3))
                                 * 10.0 ** rng.integers(-6, 7, size=(400, 3)))
               for _ in range(count)]
    if case == "gaps":
        markers[0][5:9] = np.nan
        markers[-1][7, 2] = np.nan                    # one coordinate: not seen
        for marker in markers:
            marker[20] = np.nan                       # no marker seen
    elif case == "overflow":
        for marker in markers:
            marker[11] = 1e308
    elif case == "negative zeros":
        for marker in markers:
            marker[30:33] = -0.0
        markers[0][31, 0] = np.nan
    expected = visible_centroid(np.stack(markers, axis=1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")            # no warning visible_centroid does not give
        centroid = coordinate_centroids([marker.T for marker in markers])[1]
    assert centroid.flags.c_contiguous and centroid.shape == expected.shape
    assert np.array_equal(centroid, expected, equal_nan=True)
    assert np.array_equal(np.signbit(centroid), np.signbit(expected))
