"""bmc_functions: rigid-body kinematics for biomechanics.

The least-squares rigid-body fit of marker sets (:func:`svdt`), the rotation that takes
one vector onto another (:func:`get_R`), Cardan/Euler angles (:func:`decompose`,
:func:`compose`), elemental rotations and orthonormal segment frames. Arrays in, arrays
out; frames (instants) on the first axis; every function vectorized over frames.
"""

from .angles import compose, decompose
from .frames import frame_from_axes, frame_from_points
from .rigid_body import svdt
from .rotations import elemental_rotation, get_R, rot_x, rot_y, rot_z, rotation_angle

__version__ = "0.1.0"

__all__ = [
    "compose",
    "decompose",
    "elemental_rotation",
    "frame_from_axes",
    "frame_from_points",
    "get_R",
    "rot_x",
    "rot_y",
    "rot_z",
    "rotation_angle",
    "svdt",
]
