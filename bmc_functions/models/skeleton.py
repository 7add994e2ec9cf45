r"""Joint angles from 3D body poses: a T-pose skeleton, inverse and forward kinematics.

A markerless pose estimator gives, per frame, the 3D positions of a few keypoints (hips,
knees, ankles, shoulders, elbows, wrists). This module turns them into the rotation of each
joint relative to its parent segment (and Cardan angles of it), and back into positions on
any skeleton, which is how a pose is *retargeted* onto a standard body.

The skeleton (:class:`Skeleton`) is a tree of 14 joints. In the T-pose every local rotation
is the identity and each joint sits at its parent plus its *offset*, a vector given in the
parent's frame. Forward kinematics (:func:`angles_to_pose`) is the chain

.. math:: \mathbf p_{knee} = \mathbf p_{hip} + R_{root}\,R_{hip}\,\mathbf j_{knee},\qquad
          \mathbf p_{foot} = \mathbf p_{knee} + R_{root}\,R_{hip}\,R_{knee}\,\mathbf j_{foot},

and inverse kinematics (:func:`pose_to_angles`) solves it joint by joint from the root out.

What one bone vector cannot tell
--------------------------------
A limb joint's rotation is found with :func:`~bmc_functions.get_R`, the *minimal* rotation
that takes the T-pose offset of its child onto the measured bone. Any further rotation
about the bone itself (the axial rotation, or *twist*, of the thigh, upper arm, ...) leaves
the bone vector unchanged, so it cannot be recovered from keypoints and is set to zero.
The recovered rotations are the "swing" part of the true ones; angles of the next joint
down the chain are expressed in that twist-free frame. Every limb bone *direction*
(hip -> knee -> foot, shoulder -> elbow -> wrist) and the trunk are nevertheless
reproduced exactly by :func:`angles_to_pose`, and so are the hip and shoulder lines
when ``hips`` and ``neck`` are the mid-points (the default). The skeleton's hip and
shoulder lines are straight, so if ``hips`` or ``neck`` positions are given off the
mid-points, the right hip or right shoulder is not on its measured direction. Only the root and
neck frames, built from two non-parallel directions each, have a full three degrees of
freedom.
"""

import warnings
from dataclasses import dataclass

import numpy as np

from .._checks import (MAX_MAGNITUDE, ArgumentTypeError, as_float_array, check_finite_or_nan,
                       check_rotation_matrix, check_sequence, warn_frames)
from ..rigid_body.cardan import GIMBAL_TOL, compose, decompose
from ..rigid_body.frames import frame_from_axes
from ..rigid_body.rotations import get_R, rotation_angle

#: The joints, each listed after its parent.
JOINTS = ("hips", "lefthip", "leftknee", "leftfoot", "righthip", "rightknee", "rightfoot",
          "neck", "leftshoulder", "leftelbow", "leftwrist", "rightshoulder", "rightelbow",
          "rightwrist")

#: Parent of each joint (the root, ``hips``, has none).
PARENTS = {"hips": None, "lefthip": "hips", "leftknee": "lefthip", "leftfoot": "leftknee",
           "righthip": "hips", "rightknee": "righthip", "rightfoot": "rightknee",
           "neck": "hips", "leftshoulder": "neck", "leftelbow": "leftshoulder",
           "leftwrist": "leftelbow", "rightshoulder": "neck", "rightelbow": "rightshoulder",
           "rightwrist": "rightelbow"}

#: The 12 keypoints a pose must provide; ``hips`` and ``neck`` are mid-points if absent.
KEYPOINTS = tuple(j for j in JOINTS if j not in ("hips", "neck"))

#: Joints with a rotation: those with a child. Each limb joint has exactly one child.
ROTATING_JOINTS = tuple(j for j in JOINTS if j in PARENTS.values())

# The child of each limb joint, whose bone gives the joint's rotation.
_CHILD = {"lefthip": "leftknee", "leftknee": "leftfoot", "righthip": "rightknee",
          "rightknee": "rightfoot", "leftshoulder": "leftelbow", "leftelbow": "leftwrist",
          "rightshoulder": "rightelbow", "rightelbow": "rightwrist"}
# The hip offsets hang directly from the root frame; the trunk from the root frame rotated
# by rotations['hips'] (see Skeleton's Notes).
_HIP_JOINTS = ("lefthip", "righthip")

#: Largest ratio (either way) accepted between the keypoints' bones and the skeleton's in
#: :func:`pose_to_angles`: a child's bones are about 0.6 times the default adult's, a
#: tall adult's 1.15; a factor of 5 is a unit (1000 for mm against m, 100 for cm).
MAX_SCALE = 5.0

#: Bone lengths of :meth:`Skeleton.default` in metres (an adult of about 1.75 m).
DEFAULT_LENGTHS = {"hip": 0.10, "thigh": 0.42, "shank": 0.42, "trunk": 0.50,
                   "shoulder": 0.18, "upperarm": 0.30, "forearm": 0.26}

# Which length sets each offset, and the offset's T-pose direction.
_BONES = {"lefthip": ("hip", (1, 0, 0)), "righthip": ("hip", (-1, 0, 0)),
          "leftknee": ("thigh", (0, -1, 0)), "rightknee": ("thigh", (0, -1, 0)),
          "leftfoot": ("shank", (0, -1, 0)), "rightfoot": ("shank", (0, -1, 0)),
          "neck": ("trunk", (0, 1, 0)),
          "leftshoulder": ("shoulder", (1, 0, 0)), "rightshoulder": ("shoulder", (-1, 0, 0)),
          "leftelbow": ("upperarm", (1, 0, 0)), "rightelbow": ("upperarm", (-1, 0, 0)),
          "leftwrist": ("forearm", (1, 0, 0)), "rightwrist": ("forearm", (-1, 0, 0))}


def _check_names(names, expected, what, allow_missing=()):
    """ValueError for a name not in `expected`, or one of `expected` missing."""
    for name in names:
        if name not in expected:
            raise ValueError(f"unknown joint {name!r} in {what}; expected names from "
                             f"{', '.join(expected)}")
    for name in expected:
        if name not in names and name not in allow_missing:
            raise ValueError(f"{what} is missing joint {name!r}")


class Skeleton:
    r"""A T-pose skeleton: joint names, the parent of each joint and T-pose offsets.

    Parameters
    ----------
    offsets : dict
        Joint name -> offset, shape (3,): the vector from the parent to the joint in the
        T-pose, in the parent's frame (direction times bone length, in metres). Every
        joint of :data:`JOINTS` except the root ``hips`` must be present.

    Attributes
    ----------
    joints : tuple of str
        The 14 joint names, each after its parent (:data:`JOINTS`).
    parents : dict
        Joint -> parent joint (``None`` for the root ``hips``).
    offsets : dict
        Joint -> offset (3,) float array; ``offsets['hips']`` is zero.

    Raises
    ------
    ValueError
        If a joint is unknown or missing, an offset is not 3 finite numbers or has zero
        length, or ``lefthip`` and ``neck`` (or ``leftshoulder`` and ``neck``) offsets are
        parallel, so that the root (neck) frame cannot be built.

    Notes
    -----
    The layout is that of a markerless pose: the root ``hips`` is the mid-point of the
    hips, with children ``lefthip``, ``righthip`` and ``neck`` (the mid-point of the
    shoulders); each leg is hip -> knee -> foot (ankle), each arm shoulder -> elbow ->
    wrist. The names and parents are fixed (this is the tree :func:`pose_to_angles`
    solves); the offsets may be any nonzero vectors, for example arms hanging down instead
    of out. Every angle is measured from the pose the offsets describe, so angles computed
    against different reference poses are not comparable.

    Axis convention of :meth:`default` (right-handed, the subject facing +z): **x to the
    subject's left, y up, z forward**. The left hip, shoulder and arm lie along +x, the
    right ones along -x, the legs along -y and the trunk along +y: a T-pose.

    Every joint with a child has a local rotation, and every joint hangs from its
    parent's world rotation (the world rotation of ``hips`` being the root frame times
    ``rotations['hips']``), with one exception: the two hip offsets hang from the root
    frame itself. So ``rotations['hips']`` moves only the trunk: it is the trunk's
    lateral bend within the root frame, not a rotation of the pelvis. It is needed
    because an orthonormal root frame cannot make the hip line and the trunk both exact
    when the angle between them changes (lateral bending).

    Examples
    --------
    >>> from bmc_functions import Skeleton
    >>> sk = Skeleton.default()
    >>> print(sk.parents['leftknee'], sk.offsets['leftknee'])
    lefthip [ 0.   -0.42  0.  ]
    >>> print(round(sk.lengths['forearm'], 3))
    0.26
    """

    joints = JOINTS
    parents = PARENTS

    def __init__(self, offsets):
        if not hasattr(offsets, "keys"):
            raise ArgumentTypeError(f"offsets must be a dict joint name -> (3,) offset; got "
                             f"{type(offsets).__name__}")
        _check_names(list(offsets), JOINTS, "offsets", allow_missing=("hips",))
        checked = {"hips": np.zeros(3)}
        for joint in JOINTS[1:]:
            value = as_float_array(offsets[joint], f"offsets[{joint!r}]")
            if value.shape != (3,) or not (np.abs(value) <= MAX_MAGNITUDE).all():
                raise ValueError(f"offsets[{joint!r}] must be 3 finite numbers (magnitude "
                                 f"at most {MAX_MAGNITUDE:g}); got "
                                 f"{value.tolist() if value.size <= 6 else value.shape}")
            if not value.any():
                raise ValueError(f"offsets[{joint!r}] has zero length; a bone needs a "
                                 "nonzero offset")
            checked[joint] = value
        if "hips" in offsets and np.any(as_float_array(offsets["hips"], "offsets['hips']")):
            raise ValueError("offsets['hips'] must be zero: the root has no parent")
        for joint in ("lefthip", "leftshoulder"):
            # scaled to a largest component of 1, so that tiny offsets do not underflow
            a, b = (checked[name] / np.abs(checked[name]).max() for name in (joint, "neck"))
            if np.linalg.norm(np.cross(a, b)) < 1e-8 * np.linalg.norm(a) * np.linalg.norm(b):
                raise ValueError(f"offsets[{joint!r}] and offsets['neck'] are parallel; "
                                 "they must span a plane to define a frame")
        self.offsets = checked

    @classmethod
    def default(cls, lengths=None):
        """The seed's T-pose layout with adult bone lengths (x left, y up, z forward).

        Parameters
        ----------
        lengths : dict, optional
            Bone lengths in metres, keys among ``hip`` (half the hip width), ``thigh``,
            ``shank``, ``trunk`` (hips to neck), ``shoulder`` (half the shoulder width),
            ``upperarm``, ``forearm``. Missing keys take :data:`DEFAULT_LENGTHS`.

        Returns
        -------
        Skeleton

        Raises
        ------
        ValueError
            If a bone name is unknown or a length is not a positive finite number.

        Examples
        --------
        >>> from bmc_functions import Skeleton
        >>> print(Skeleton.default().offsets['rightelbow'] + 0.0)
        [-0.3  0.   0. ]
        """
        if lengths is None:
            lengths = {}
        elif not hasattr(lengths, "keys"):
            raise ArgumentTypeError(f"lengths must be a dict bone name -> length in "
                                    f"metres, e.g. {{'thigh': 0.45}}; got "
                                    f"{type(lengths).__name__}")
        lengths = {**DEFAULT_LENGTHS, **lengths}
        unknown = set(lengths) - set(DEFAULT_LENGTHS)
        if unknown:
            raise ValueError(f"unknown bone length {sorted(map(repr, unknown))[0]}; expected "
                             f"names "
                             f"from {', '.join(DEFAULT_LENGTHS)}")
        for bone, value in lengths.items():
            # A negative length would silently turn the bone round (legs pointing up).
            length = as_float_array(value, f"lengths[{bone!r}]")
            if length.shape != () or not 0 < length <= MAX_MAGNITUDE:
                raise ValueError(f"lengths[{bone!r}] must be a positive number of metres "
                                 f"(at most {MAX_MAGNITUDE:g}); "
                                 f"got {value!r}")
        return cls({joint: float(lengths[bone]) * np.array(direction, dtype=float)
                    for joint, (bone, direction) in _BONES.items()})

    @classmethod
    def from_positions(cls, positions):
        """The default layout with bone lengths measured from a pose sequence.

        Each length is the median over frames (NaN frames ignored), with the left and
        right sides averaged, so the skeleton is symmetric.

        Parameters
        ----------
        positions : dict
            Joint name -> (F, 3) positions, as for :func:`pose_to_angles`.

        Returns
        -------
        Skeleton

        Raises
        ------
        ValueError
            As :func:`pose_to_angles` for bad `positions`, or if a bone has no frame
            without NaN.

        Examples
        --------
        >>> from bmc_functions import Skeleton
        >>> tpose = Skeleton.default().tpose()
        >>> sk = Skeleton.from_positions(tpose)
        >>> print(round(sk.lengths['thigh'], 6))
        0.42
        """
        xyz = _check_positions(positions)
        medians = {}  # bone name -> median length of each side
        for joint, (bone, _) in _BONES.items():
            length = np.linalg.norm(xyz[joint] - xyz[PARENTS[joint]], axis=-1)
            if np.isnan(length).all():
                raise ValueError(f"bone {PARENTS[joint]}->{joint} has NaN in every frame; "
                                 "its length is unknown")
            medians.setdefault(bone, []).append(np.nanmedian(length))
        median = {bone: float(np.mean(lengths)) for bone, lengths in medians.items()}
        return cls.default(median)

    @property
    def lengths(self):
        """Bone lengths by name (``hip``, ``thigh``, ...), left and right averaged."""
        out = {}
        for joint, (bone, _) in _BONES.items():
            offset = self.offsets[joint]
            scale = np.abs(offset).max()  # scaled first: tiny offsets would underflow
            out.setdefault(bone, []).append(float(scale * np.linalg.norm(offset / scale)))
        return {bone: float(np.mean(v)) for bone, v in out.items()}

    def tpose(self, root_position=(0.0, 0.0, 0.0)):
        """World positions of the T-pose, dict joint -> (1, 3), the root at `root_position`.

        Examples
        --------
        >>> from bmc_functions import Skeleton
        >>> print(Skeleton.default().tpose()['leftwrist'].round(3) + 0.0)
        [[0.74 0.5  0.  ]]
        """
        root = as_float_array(root_position, "root_position")
        if root.shape != (3,) or not (np.abs(root) <= MAX_MAGNITUDE).all():
            raise ValueError(f"root_position must be 3 finite numbers (x, y, z); got "
                             f"{root.tolist() if root.size <= 6 else root.shape}")
        eye = np.eye(3)[None]
        result = PoseAngles(root_position=root[None].copy(),
                            root_rotation=eye.copy(),
                            rotations={j: eye.copy() for j in ROTATING_JOINTS})
        return angles_to_pose(result, self)

    def __repr__(self):
        lengths = ", ".join(f"{k}={v:.3f}" for k, v in self.lengths.items())
        return f"Skeleton({lengths})"


@dataclass
class PoseAngles:
    """Result of :func:`pose_to_angles`; input of :func:`angles_to_pose`.

    Attributes
    ----------
    root_position : ndarray, shape (F, 3)
        Position of the root (``hips``) in the world frame.
    root_rotation : ndarray, shape (F, 3, 3)
        Orientation of the root frame in the world frame (orthonormal, columns = axes).
    rotations : dict
        Joint -> (F, 3, 3) local rotation, for each joint with a child
        (:data:`ROTATING_JOINTS`). May be None in :func:`angles_to_pose` if `angles` is
        given.
    angles : dict
        Joint -> (F, 3) Cardan angles of `rotations` in radians, in `sequence` order,
        unwrapped over frames (continuous rather than jumping by 2 pi at +/-pi). Near
        gimbal lock (middle angle near +/-pi/2 for Cardan sequences) the first and third
        angles can still jump: that is the angle set changing branch, not a wrap.
    sequence : str
        The intrinsic angle sequence of `angles`, e.g. 'ZXY'.
    root_angles : ndarray, shape (F, 3)
        Angles of `root_rotation` in the same sequence, unwrapped.

    Examples
    --------
    A T-pose with the left knee bent by 30 degrees, to angles and back to positions:

    >>> import numpy as np
    >>> from bmc_functions import Skeleton, angles_to_pose, pose_to_angles, rot_x
    >>> skeleton = Skeleton.default()
    >>> pose = skeleton.tpose()
    >>> shank = rot_x(30, degrees=True) @ skeleton.offsets["leftfoot"]
    >>> pose["leftfoot"] = pose["leftknee"] + shank
    >>> result = pose_to_angles(pose, skeleton)
    >>> result.sequence, result.root_position.shape, result.rotations["leftknee"].shape
    ('ZXY', (1, 3), (1, 3, 3))
    >>> print(np.rad2deg(result.angles["leftknee"]).round(6) + 0.0)   # Z, X, Y
    [[ 0. 30.  0.]]
    >>> back = angles_to_pose(result, skeleton)
    >>> print(np.abs(back["leftfoot"] - pose["leftfoot"]).max() < 1e-9)
    True
    """

    root_position: np.ndarray
    root_rotation: np.ndarray
    rotations: dict = None
    angles: dict = None
    sequence: str = "ZXY"
    root_angles: np.ndarray = None


def _check_positions(positions):
    """Validate a pose dict; return joint -> (F, 3) float arrays with hips and neck."""
    if not hasattr(positions, "keys"):
        raise ArgumentTypeError(f"positions must be a dict joint name -> (F, 3) array; got "
                         f"{type(positions).__name__}")
    _check_names(list(positions), JOINTS, "positions", allow_missing=("hips", "neck"))
    xyz, frames = {}, None
    for joint in JOINTS:
        if joint not in positions:
            continue
        values = as_float_array(positions[joint], f"positions[{joint!r}]")
        if values.ndim != 2 or values.shape[1] != 3:
            raise ValueError(f"positions[{joint!r}] must have shape (F, 3) (frames, xyz); "
                             f"got shape {values.shape}")
        check_finite_or_nan(values, f"positions[{joint!r}]")
        if frames is None:
            frames = (joint, len(values))
        elif len(values) != frames[1]:
            raise ValueError(f"positions[{joint!r}] has {len(values)} frames but "
                             f"positions[{frames[0]!r}] has {frames[1]}")
        xyz[joint] = values
    if "hips" not in xyz:
        xyz["hips"] = 0.5 * (xyz["lefthip"] + xyz["righthip"])
    if "neck" not in xyz:
        xyz["neck"] = 0.5 * (xyz["leftshoulder"] + xyz["rightshoulder"])
    return xyz


def _apply_T(R, v):
    """R^T @ v for stacks: (F, 3, 3), (F, 3) -> (F, 3)."""
    return np.einsum("fji,fj->fi", R, v)


def _apply(R, v):
    """R @ v for stacks: (F, 3, 3) or (3, 3), (3,) or (F, 3) -> (F, 3)."""
    return np.einsum("...ij,...j->...i", R, v)


def _frame(primary, secondary, what):
    """frame_from_axes with an error message that names the joints involved."""
    try:
        return frame_from_axes(primary, secondary, "xy")
    except ValueError as error:
        raise ValueError(f"cannot build the {what}: {error}") from None


def _swing(offset, bone, joint, child):
    """get_R with an error message that names the bone."""
    try:
        return get_R(offset, bone)
    except ValueError as error:
        raise ValueError(f"cannot find the rotation of {joint!r} from the bone "
                         f"{joint}->{child}: {error}") from None


def _unwrap(angles):
    """np.unwrap over frames (axis 0) that skips NaN frames instead of spreading NaN."""
    valid = ~np.isnan(angles)
    if valid.all():
        return np.unwrap(angles, axis=0)
    n = np.arange(len(angles))[:, None]
    # Index of the last valid frame at or before each frame (the first valid for a
    # leading gap): a NaN gap is bridged by repeating the value before it.
    last = np.maximum.accumulate(np.where(valid, n, -1), axis=0)
    first = np.argmax(valid, axis=0)
    last = np.where(last < 0, first, last)
    filled = np.take_along_axis(angles, last, axis=0)
    out = np.unwrap(filled, axis=0)
    out[~valid] = np.nan
    return out


#: Largest turn (degrees) of the root or neck frame between consecutive frames that is
#: taken as movement: 90 degrees in one frame is 2,700 deg/s at 30 frames per second, far
#: beyond a trunk's turn (under about 500 deg/s even in sport); a keypoint detector that
#: swaps left and right turns the frame by about 180 degrees at once.
MAX_FRAME_TURN_DEG = 90.0


#: The jumps are judged only in a sampled movement, where the median turn between
#: consecutive frames is below this (degrees); poses given frame by frame without
#: continuity (unrelated poses) are not judged.
CONTINUOUS_TURN_DEG = 10.0


def _flipped(R):
    """Frames (F,) in the minority of two states separated by jumps of more than
    MAX_FRAME_TURN_DEG between consecutive valid frames (left and right swapped there)."""
    valid = np.flatnonzero(np.isfinite(R).all(axis=(1, 2)))
    flagged = np.zeros(len(R), bool)
    if valid.size < 2:
        return flagged
    turn = np.degrees(rotation_angle(R[valid[1:]] @ np.swapaxes(R[valid[:-1]], 1, 2)))
    jumps = turn > MAX_FRAME_TURN_DEG
    if not jumps.any() or np.median(turn) > CONTINUOUS_TURN_DEG:
        return flagged          # no jump, or not a sampled movement (unrelated poses)
    state = np.r_[0, np.cumsum(jumps)] % 2
    minority = 1 if np.count_nonzero(state == 1) <= np.count_nonzero(state == 0) else 0
    flagged[valid[state == minority]] = True
    return flagged


def _angles(R, seq):
    """Unwrapped angles of (F, 3, 3) R, and the number of frames in gimbal lock."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # summarized once by the caller
        angles = decompose(R, seq)
    b = angles[:, 1]
    locked = (np.abs(np.sin(b)) if seq[0] == seq[2] else np.abs(np.cos(b))) < GIMBAL_TOL
    return _unwrap(angles), locked


def pose_to_angles(positions, skeleton, sequence="ZXY"):
    r"""Joint rotations and angles of a skeleton from 3D keypoint positions.

    Parameters
    ----------
    positions : dict
        Joint name -> (F, 3) world positions (frames on the first axis) of the 12 limb
        keypoints ``lefthip, leftknee, leftfoot, righthip, rightknee, rightfoot,
        leftshoulder, leftelbow, leftwrist, rightshoulder, rightelbow, rightwrist``, and
        optionally ``hips`` and ``neck`` (otherwise the mid-points of the hips and of the
        shoulders). NaN marks a lost keypoint.
    skeleton : Skeleton
        The T-pose whose offsets define zero rotation. Only the offset *directions*
        matter here; lengths matter in :func:`angles_to_pose`.
    sequence : str, optional
        Intrinsic Cardan/Euler sequence of the angles (see
        :func:`~bmc_functions.decompose`). Default ``'ZXY'``.

    Returns
    -------
    PoseAngles
        ``root_position`` (F, 3), ``root_rotation`` (F, 3, 3), ``rotations`` (joint ->
        (F, 3, 3) local rotation of each joint with a child), ``angles`` (joint -> (F, 3),
        radians, in sequence order, unwrapped over frames), ``sequence`` and
        ``root_angles`` (F, 3).

    Raises
    ------
    ValueError
        If a joint name is unknown or missing, an array is not (F, 3), the arrays have
        different numbers of frames, `skeleton` is not a Skeleton, `sequence` is unknown,
        or a bone has zero length or a frame's two directions are parallel, or the
        keypoints' bones are :data:`MAX_SCALE` (5) times the skeleton's or more, or as
        much shorter (positions and skeleton in different units: mm against m).

    Warns
    -----
    RuntimeWarning
        Once per call, with the number of frames in gimbal lock and the joints affected.
        In a sampled movement (median turn between frames below 10 degrees), frames
        whose root (or neck) frame turns by more than ``MAX_FRAME_TURN_DEG = 90``
        degrees at once, and back: left and right keypoints swapped there; the
        rotations that depend on that frame are NaN there.

    See Also
    --------
    keypoint_angles : clinical joint angles (ISB) from keypoints.

    Notes
    -----
    *Root frame.* With :math:`\hat u` the unit vector hips -> lefthip and :math:`\mathbf t`
    the trunk hips -> neck, Gram-Schmidt gives an orthonormal frame

    .. math:: F = [\hat u,\ \hat v,\ \hat u\times\hat v],\qquad
              \hat v = \frac{\mathbf t - (\mathbf t\cdot\hat u)\hat u}
                            {|\mathbf t - (\mathbf t\cdot\hat u)\hat u|},

    and :math:`R_{root} = F\,F_0^T`, with :math:`F_0` the same frame built from the
    T-pose offsets (the identity for :meth:`Skeleton.default`). Without Gram-Schmidt,
    :math:`[\hat u, \hat t, \hat u\times\hat t]` is not orthonormal whenever the trunk is
    not perpendicular to the hip line, and its "angles" are wrong.

    *Trunk and neck.* ``rotations['hips']`` is
    :math:`\operatorname{get\_R}(\mathbf j_{neck}, R_{root}^T\mathbf t)`, a lateral bend
    within the root frame, so that the trunk is reproduced exactly. The neck's world
    frame is built like the root frame from the shoulder line and the trunk, and
    ``rotations['neck']`` is it relative to :math:`R_{root}R_{hips}`.

    *Limbs.* Joint by joint from the root out, with :math:`W` the world rotation of the
    frame the joint hangs from (e.g. :math:`R_{root}` for a hip) and :math:`\mathbf b`
    the measured bone to its child,

    .. math:: R_{joint}\,\mathbf j_{child} \parallel W^T\mathbf b
              \quad\Rightarrow\quad
              R_{joint} = \operatorname{get\_R}(\mathbf j_{child},\ W^T\mathbf b),

    the minimal rotation: the twist about the bone is unknowable from one vector and set
    to zero (see the module docstring). Parallel and antiparallel bones are exact.

    *NaN.* A lost keypoint makes NaN exactly the rotations that depend on it: a lost
    wrist only the elbow; a lost knee the hip and the knee; a lost hip or shoulder (of
    either side, since ``hips`` and ``neck`` are their mid-points, and the root frame
    uses the trunk) the root frame, and so every rotation; a lost hip also the root
    position.

    *What these numbers are, and what they are not.* Each joint's angles are the Cardan
    angles (in `sequence`) of its twist-free rotation from the T-pose, in radians, about
    the axes of the T-pose's own frame (x left, y up, z forward for
    :meth:`Skeleton.default`): a motion description that reproduces the pose exactly
    (:func:`angles_to_pose`), not clinical angles. There is no axial rotation of a bone
    (no hip or shoulder rotation); a knee flexed with its thigh turned shows part of its
    flexion in another component; the elbow's flexion is spread over components; the
    signs and zero are the T-pose's, not the ISB's. For clinical angles (flexion,
    adduction, rotation in ISB segment frames and joint coordinate systems, in degrees,
    with the estimator's mistakes screened), use :func:`keypoint_angles`, which reads a
    Pose2Sim TRC file or a :func:`read_trc` DataFrame directly.

    References
    ----------
    .. [1] Rodrigues O (1840) Des lois géométriques qui régissent les déplacements d'un
       système solide dans l'espace. J Math Pures Appl 5:380-440.
    .. [2] Craig JJ (2005) Introduction to Robotics: Mechanics and Control, 3rd ed.
       Pearson. Chapter 3 (forward kinematics of a chain).
    .. [3] Wu G et al. (2005) ISB recommendation on definitions of joint coordinate
       systems of various joints for the reporting of human joint motion - part II:
       shoulder, elbow, wrist and hand. J Biomech 38:981-992.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import Skeleton, pose_to_angles, rot_x
    >>> sk = Skeleton.default()
    >>> pose = sk.tpose()
    >>> # bend the left knee by 30 degrees: the foot moves backwards (-z)
    >>> shank = rot_x(30, degrees=True) @ sk.offsets['leftfoot']
    >>> pose['leftfoot'] = pose['leftknee'] + shank
    >>> result = pose_to_angles(pose, sk)
    >>> print(np.rad2deg(result.angles['leftknee']).round(6) + 0.0)  # Z, X, Y
    [[ 0. 30.  0.]]
    >>> print(np.rad2deg(result.angles['lefthip']).round(6) + 0.0)
    [[0. 0. 0.]]
    """
    if not isinstance(skeleton, Skeleton):
        raise ValueError(f"skeleton must be a Skeleton (e.g. Skeleton.default() or "
                         f"Skeleton.from_positions(positions)); got "
                         f"{type(skeleton).__name__}")
    seq, _ = check_sequence(sequence)
    xyz = _check_positions(positions)
    offsets = skeleton.offsets
    _check_same_units(xyz, offsets)

    trunk = xyz["neck"] - xyz["hips"]
    F0 = frame_from_axes(offsets["lefthip"], offsets["neck"])
    R_root = _frame(xyz["lefthip"] - xyz["hips"], trunk,
                    "root frame from hips, lefthip and neck") @ F0.T

    rotations, world = {}, {}
    # Trunk: the lateral bend that makes the root frame's trunk offset exact.
    rotations["hips"] = _swing(offsets["neck"], _apply_T(R_root, trunk), "hips", "neck")
    world["hips"] = R_root @ rotations["hips"]
    # Neck: a full frame from the shoulder line and the trunk.
    N0 = frame_from_axes(offsets["leftshoulder"], offsets["neck"])
    N = _frame(xyz["leftshoulder"] - xyz["neck"], trunk,
               "neck frame from neck, leftshoulder and hips") @ N0.T
    rotations["neck"] = np.swapaxes(world["hips"], -1, -2) @ N
    world["neck"] = N
    # Limbs, from the root out (JOINTS lists every parent before its children).
    for joint in JOINTS:
        if joint not in _CHILD:
            continue
        child = _CHILD[joint]
        W = R_root if joint in _HIP_JOINTS else world[PARENTS[joint]]
        bone = _apply_T(W, xyz[child] - xyz[joint])
        rotations[joint] = _swing(offsets[child], bone, joint, child)
        world[joint] = W @ rotations[joint]

    # Left and right keypoints swapped in some frames turn the root (hips swapped) or the
    # neck frame (shoulders swapped) by about 180 degrees at once: NaN in those frames in
    # every rotation that depends on that frame, one warning.
    flipped_root, flipped_neck = _flipped(R_root), _flipped(N)
    flipped_neck &= ~flipped_root
    arms = ("neck", "leftshoulder", "leftelbow", "rightshoulder", "rightelbow")
    for mask, names, pair in ((flipped_root, list(rotations), "lefthip and righthip"),
                              (flipped_neck, arms, "leftshoulder and rightshoulder")):
        if mask.any():
            for name in names:
                rotations[name] = np.where(mask[:, None, None], np.nan, rotations[name])
            if mask is flipped_root:
                R_root = np.where(mask[:, None, None], np.nan, R_root)
            warn_frames(int(mask.sum()), len(mask),
                        f"turn by more than {MAX_FRAME_TURN_DEG:.0f} degrees from the frame "
                        f"before or after them (the keypoints {pair} swapped there, or "
                        f"misdetected): the rotations that depend on them are NaN there")
    angles, locked_joints, locked_any = {}, [], np.zeros(len(R_root), bool)
    for joint in ROTATING_JOINTS:
        angles[joint], locked = _angles(rotations[joint], seq)
        if locked.any():
            locked_joints.append(joint)
            locked_any |= locked
    root_angles, locked = _angles(R_root, seq)
    if locked.any():
        locked_joints.append("root")
        locked_any |= locked
    warn_frames(int(locked_any.sum()), len(locked_any),
                f"are in gimbal lock for sequence {seq} in joint(s) "
                f"{', '.join(locked_joints)}; the third angle there was set to 0")
    return PoseAngles(root_position=xyz["hips"].copy(), root_rotation=R_root,
                      rotations=rotations, angles=angles, sequence=seq,
                      root_angles=root_angles)


def _check_same_units(xyz, offsets):
    """Refuse keypoints whose bones are MAX_SCALE times the skeleton's or more (or as
    much shorter): positions in mm on a skeleton in metres would give angles (only the
    directions count) but a pose of bones in metres placed at positions in mm."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)   # a keypoint lost in every frame
        ratios = [np.nanmedian(np.linalg.norm(xyz[joint] - xyz[PARENTS[joint]], axis=1))
                  / np.linalg.norm(offsets[joint]) for joint in _BONES]
        ratio = float(np.nanmedian(ratios))
    if np.isfinite(ratio) and not 1 / MAX_SCALE < ratio < MAX_SCALE:
        raise ValueError(f"positions: the bones are {ratio:.4g} times the skeleton's "
                         f"(median over the {len(ratios)} bones): the positions and the "
                         "skeleton are in different units (mm against m?); convert one, "
                         "or build the skeleton from these positions "
                         "(Skeleton.from_positions)")


def _check_rotation_stack(value, name, frames):
    """(frames, 3, 3) rotation matrices (NaN allowed), or ValueError naming `name`."""
    R = as_float_array(value, name)
    if R.ndim != 3 or R.shape[1:] != (3, 3) or (frames is not None and len(R) != frames):
        expected = f"({frames}, 3, 3)" if frames is not None else "(F, 3, 3)"
        raise ValueError(f"{name} must have shape {expected}; got shape {R.shape}")
    # A matrix that is not a rotation would silently stretch or mirror the bones.
    return check_rotation_matrix(R, name)


def angles_to_pose(result, skeleton):
    r"""World positions of every joint from root pose and local rotations (forward kinematics).

    Parameters
    ----------
    result : PoseAngles
        Usually the output of :func:`pose_to_angles`. Uses ``root_position``,
        ``root_rotation`` and ``rotations``; if ``rotations`` is None, they are composed
        from ``angles`` in ``sequence``.
    skeleton : Skeleton
        The skeleton to pose. Another skeleton than the one the angles came from
        *retargets* the motion: same bone directions, this skeleton's bone lengths.

    Returns
    -------
    positions : dict
        Joint name -> (F, 3) world positions, all 14 joints.

    Raises
    ------
    ValueError
        If `result` or `skeleton` has the wrong type, a rotation (or angle) of a joint is
        missing or unknown, shapes do not match, or a matrix of ``root_rotation`` or
        ``rotations`` is not a rotation (not orthonormal, or a reflection); the message
        names the joint.

    Notes
    -----
    From the root out, with :math:`W_{parent}` the world rotation of the parent
    (:math:`R_{root}` for the hips, :math:`R_{root}R_{hips}` for the neck),

    .. math:: \mathbf p_{joint} = \mathbf p_{parent} + W_{parent}\,\mathbf j_{joint},
              \qquad W_{joint} = W_{parent}\,R_{joint}.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import Skeleton, angles_to_pose, pose_to_angles
    >>> sk = Skeleton.default()
    >>> result = pose_to_angles(sk.tpose(), sk)
    >>> tall = Skeleton.default({'thigh': 0.5})
    >>> print(angles_to_pose(result, tall)['leftfoot'].round(3) + 0.0)
    [[ 0.1  -0.92  0.  ]]
    """
    if not isinstance(result, PoseAngles):
        raise ValueError(f"result must be a PoseAngles (the output of pose_to_angles); "
                         f"got {type(result).__name__}")
    if not isinstance(skeleton, Skeleton):
        raise ValueError(f"skeleton must be a Skeleton; got {type(skeleton).__name__}")
    root = as_float_array(result.root_position, "result.root_position")
    if root.ndim != 2 or root.shape[1] != 3:
        raise ValueError(f"result.root_position must have shape (F, 3); got shape "
                         f"{root.shape}")
    frames = len(root)
    R_root = _check_rotation_stack(result.root_rotation, "result.root_rotation", frames)
    if result.rotations is not None:
        source, what = result.rotations, "result.rotations"
    elif result.angles is not None:
        source, what = result.angles, "result.angles"
    else:
        raise ValueError("result has neither rotations nor angles")
    if not hasattr(source, "keys"):
        raise ArgumentTypeError(f"{what} must be a dict joint name -> array; got "
                                f"{type(source).__name__}")
    _check_names(list(source), ROTATING_JOINTS, what)
    rotations = {}
    for joint in ROTATING_JOINTS:
        if result.rotations is not None:
            rotations[joint] = _check_rotation_stack(source[joint], f"{what}[{joint!r}]",
                                                     frames)
        else:
            values = as_float_array(source[joint], f"{what}[{joint!r}]")
            if values.shape != (frames, 3):
                raise ValueError(f"{what}[{joint!r}] must have shape ({frames}, 3); got "
                                 f"shape {values.shape}")
            rotations[joint] = compose(values, result.sequence)

    offsets = skeleton.offsets
    xyz = {"hips": root.copy()}
    world = {"hips": R_root @ rotations["hips"]}
    for joint in JOINTS[1:]:
        parent = PARENTS[joint]
        W = R_root if joint in _HIP_JOINTS else world[parent]
        xyz[joint] = xyz[parent] + _apply(W, offsets[joint])
        if joint in rotations:
            world[joint] = W @ rotations[joint]
    return xyz
