"""Issue 24, finding 5 (the parts in rigid_body and models): arguments checked through
bmc_functions._checks, with ArgumentTypeError (a TypeError and a ValueError) naming them."""

import warnings

import numpy as np
import pytest

from bmc_functions import angular_velocity, helical_axes, helical_axis, plug_in_gait, rot_z
from bmc_functions._checks import ArgumentTypeError, check_scalar
from bmc_functions.models.plug_in_gait import load_subject

R = rot_z(np.radians(np.arange(20.0)))
T = np.zeros((20, 3))


@pytest.mark.parametrize("call, message", [
    (lambda: load_subject(3.0), "subject must be a dict"),
    (lambda: plug_in_gait(None, {}, markers=["LASI"]), "markers must be a dict"),
    (lambda: plug_in_gait(None, {}, markers={"LASI": 1}), "markers must be a dict"),
    (lambda: plug_in_gait(3, {}), "static must be a path, a marker DataFrame or None"),
])
def test_plug_in_gait_wrong_types(call, message):
    # before: a plain TypeError, which `except ValueError` did not catch
    with pytest.raises(ArgumentTypeError, match=message):
        call()
    with pytest.raises(ValueError, match=message):
        call()


@pytest.mark.parametrize("value", [True, np.True_, "100", None, [100.0], 1j])
def test_rate_not_a_number(value):
    with pytest.raises(ArgumentTypeError, match=r"rate must be a positive, finite sampling rate "
                                         r"in Hz; got"):
        angular_velocity(R, value)


@pytest.mark.parametrize("value", [100, np.int32(100), np.float32(100.0), 100.0])
def test_rate_any_real_number(value):
    np.testing.assert_allclose(angular_velocity(R, value)[:, 2], np.radians(100.0),
                               rtol=1e-4)


@pytest.mark.parametrize("step, error", [(1, None), (np.int64(1), None), (1.0, TypeError),
                                         (True, TypeError), (np.True_, TypeError),
                                         (0, ValueError), (19, None), (20, ValueError)])
def test_step_integer_boundaries(step, error):
    if error is None:
        axes, frames = helical_axes(R, T, step=step, min_angle=0.0)
        assert len(frames) == 20 - step
    else:
        with pytest.raises(error, match="step must be"):
            helical_axes(R, T, step=step)


@pytest.mark.parametrize("angle, ok", [(0.0, True), (-1e-12, False), (np.pi, False),
                                       (np.nextafter(np.pi, 0), True), (False, False)])
def test_min_angle_range_boundaries(angle, ok):
    if ok:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # below min_angle: NaN axis
            helical_axis(np.eye(3), np.zeros(3), R[10], np.zeros(3), min_angle=angle)
    else:
        with pytest.raises(ValueError, match=r"min_angle must be a number of radians in "
                                             r"\[0, pi\)"):
            helical_axis(np.eye(3), np.zeros(3), R[10], np.zeros(3), min_angle=angle)


def test_check_scalar():
    assert check_scalar(np.float32(0.5), "x", "a number") == 0.5
    assert check_scalar(np.uint8(3), "n", "an integer", integer=True) == 3
    assert type(check_scalar(np.int64(3), "n", "an integer", integer=True)) is int
    with pytest.raises(ArgumentTypeError, match=r"n must be an integer; got 3.0 \(float\)"):
        check_scalar(3.0, "n", "an integer", integer=True)
    with pytest.raises(ArgumentTypeError, match=r"x must be a number; got 'a' \(str\)"):
        check_scalar("a", "x", "a number")
    with pytest.raises(ValueError, match=r"x must be a number > 0; got 0"):
        check_scalar(0.0, "x", "a number > 0", minimum=0, strict=True)
    assert check_scalar(0.0, "x", "a number >= 0", minimum=0) == 0.0
    with pytest.raises(ValueError, match=r"x must be a number <= 1; got 1.5"):
        check_scalar(1.5, "x", "a number <= 1", maximum=1)
    with pytest.raises(ValueError, match=r"x must be a number; got nan"):
        check_scalar(float("nan"), "x", "a number")
