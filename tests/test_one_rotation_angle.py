"""Issue 24, finding 3: one rotation angle (rotations.rotation_angle), used by motion,
skeleton and the fits rather than rewritten."""

import re
from pathlib import Path

import numpy as np
import pytest

import bmc_functions
from bmc_functions import helical_axes, helical_axis, rot_x, rot_z, rotation_angle
from bmc_functions.rigid_body.rotations import unchecked_rotation_angle

PACKAGE = Path(bmc_functions.__file__).parent
OWN = ["rigid_body/motion.py", "rigid_body/svdt.py", "rigid_body/quaternion_fit.py",
       "rigid_body/clusters.py", "models/skeleton.py", "models/functional_joints.py",
       "models/joints.py", "models/segments.py"] + sorted(
    str(path.relative_to(PACKAGE)) for path in (PACKAGE / "models" / "plug_in_gait").glob("*.py"))


@pytest.mark.parametrize("module", OWN)
def test_the_angle_is_not_rewritten_from_the_trace(module):
    code = re.sub(r'(?s)""".*?"""', "", (PACKAGE / module).read_text())   # docstrings out
    assert not re.search(r"arccos\([^)]*trace|arctan2\([^)]*norm\(r", code)


def test_helical_axis_angle_is_rotation_angle():
    rng = np.random.default_rng(24)
    angles = rng.uniform(-np.pi, np.pi, (50, 2))
    R1 = rot_x(angles[:, 0]) @ rot_z(angles[:, 1])
    R2 = rot_z(angles[:, 1]) @ rot_x(angles[:, 0])
    t = rng.normal(size=(50, 3))
    axis = helical_axis(R1, t, R2, -t, min_angle=0.0)
    np.testing.assert_array_equal(axis.angle, rotation_angle(R2 @ np.swapaxes(R1, 1, 2)))


@pytest.mark.parametrize("angle", [1e-9, 1e-4, 0.3, np.pi / 2, 3.0, np.pi - 1e-7])
def test_angle_of_known_rotations(angle):
    # atan2 form: exact to rounding at small angles, where arccos of the trace loses
    # half the digits (arccos(1 - 5e-19) is 0 in float64)
    R = rot_x(angle)
    assert unchecked_rotation_angle(R) == pytest.approx(angle, rel=1e-12)
    assert rotation_angle(R) == unchecked_rotation_angle(R)


def test_helical_axes_angle_step_boundary_uses_the_same_angle():
    # a segment turning by 1 degree per frame: with angle_step = 10 degrees, each pair
    # spans the first frame whose rotation_angle reaches the step
    R = rot_z(np.radians(np.arange(40.0)))
    t = np.zeros((40, 3))
    axes, frames = helical_axes(R, t, angle_step=np.radians(10.0) - 1e-9)
    assert frames[0].tolist() == [0, 10]
    np.testing.assert_allclose(np.degrees(axes.angle), 10.0)
