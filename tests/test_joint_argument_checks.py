"""Issue 24, finding 4: every joint-angle function validates `side` and `degrees` alike."""

import numpy as np
import pytest

from bmc_functions import ankle_angles, compose, hip_angles, knee_angles, pelvis_angles
from bmc_functions._checks import ArgumentTypeError

R = compose([30.0, 5.0, 10.0], "ZXY", degrees=True)
I = np.eye(3)

CALLS = {
    "knee_angles": lambda **kw: knee_angles(I, R, **kw),
    "hip_angles": lambda **kw: hip_angles(I, R, **kw),
    "ankle_angles": lambda **kw: ankle_angles(I, R, **kw),
    "pelvis_angles": lambda **kw: pelvis_angles(R, **kw),
}


@pytest.mark.parametrize("name", CALLS)
@pytest.mark.parametrize("flag", ["False", "True", 0, 1, None, np.array([True])])
def test_degrees_must_be_a_boolean(name, flag):
    # before: hip_angles(I, R, degrees='False') returned degrees (a truthy string)
    with pytest.raises(ArgumentTypeError, match="degrees must be True or False"):
        CALLS[name](degrees=flag)


@pytest.mark.parametrize("name", CALLS)
def test_numpy_booleans_are_flags(name):
    np.testing.assert_array_equal(CALLS[name](degrees=np.True_), CALLS[name](degrees=True))
    np.testing.assert_array_equal(CALLS[name](degrees=np.False_),
                                  np.deg2rad(CALLS[name](degrees=True)))


@pytest.mark.parametrize("name", CALLS)
@pytest.mark.parametrize("side", [1, None, b"right"])
def test_side_of_the_wrong_type(name, side):
    # before: a plain ValueError for hip, ankle and pelvis, ArgumentTypeError for the knee
    with pytest.raises(ArgumentTypeError, match="side must be 'right' or 'left'"):
        CALLS[name](side=side)


@pytest.mark.parametrize("name", CALLS)
@pytest.mark.parametrize("side", ["Right", "l", ""])
def test_unknown_side(name, side):
    with pytest.raises(ValueError, match=f"side must be 'right' or 'left'; got {side!r}"):
        CALLS[name](side=side)


def test_knee_angles_read_flexion_as_minus_the_first_angle():
    # the knee shares the ZXY body of hip and ankle: flexion is -alpha on both sides
    shank = compose([-30.0, 5.0, 10.0], "ZXY", degrees=True)
    np.testing.assert_allclose(knee_angles(I, shank, degrees=True), [30.0, 5.0, 10.0])
    mirror = np.diag([1.0, 1.0, -1.0])
    np.testing.assert_allclose(knee_angles(I, mirror @ shank @ mirror, "left", degrees=True),
                               [30.0, 5.0, 10.0])
