"""bmc_functions: rigid-body kinematics for biomechanics.

The least-squares rigid-body fit of marker sets (:func:`svdt`), the rotation that takes
one vector onto another (:func:`get_R`), Cardan/Euler angles (:func:`decompose`,
:func:`compose`), elemental rotations and orthonormal segment frames; joint angles from 3D
body poses (:mod:`~bmc_functions.skeleton`) and from marker clusters
(:mod:`~bmc_functions.tracking`, :mod:`~bmc_functions.segments`,
:mod:`~bmc_functions.joints`); TRC/C3D marker files (:mod:`~bmc_functions.marker_io`)
and OpenSim .mot/.sto motion files (:mod:`~bmc_functions.opensim_io`).
Arrays in, arrays out; frames (instants) on the first axis; every function vectorized
over frames.
"""

from .angles import compose, decompose
from .c3d_parameters import read_c3d_model_outputs, read_c3d_parameters
from .clusters import expected_orientation_error, orientation_error_covariance
from .conventional_gait_model import PlugInGait, PlugInGaitTrack, plug_in_gait
from .frames import frame_from_axes, frame_from_points
from .functional_joints import (JointAxis, JointCentre, functional_axis,
                                functional_joint_centre, sphere_fit_centre)
from .filtering import (ResidualAnalysis, corrected_cutoff, derivative, lowpass,
                        residual_analysis)
from .gait_cycles import (ensemble, gait_events, normalize_by_side, spatiotemporal_parameters,
                          stride_table, time_normalize)
from .event_io import read_events, write_events
from .force_plates import compare_events, force_plate_events
from .gap_filling import fill_gaps_rigid
from .joints import ankle_angles, hip_angles, knee_angles, pelvis_angles
from .lower_limb import LowerLimbModel, calibrate_lower_limb, lower_limb_angles
from .marker_io import read_c3d, read_trc, write_trc
from .marker_roles import read_marker_mapping
from .motion import HelicalAxis, angular_velocity, helical_axes, helical_axis
from .opensim_io import align_times, opensim_coordinates, read_mot, write_mot
from .rigid_body import svdt
from .rotations import elemental_rotation, get_R, rot_x, rot_y, rot_z, rotation_angle
from .segments import foot_frame, hip_joint_centre, pelvis_frame, shank_frame, thigh_frame
from .skeleton import PoseAngles, Skeleton, angles_to_pose, pose_to_angles
from .tracking import calibrate_cluster, reconstruct_landmarks
from .vsk_io import read_vsk

__version__ = "0.3.0"

__all__ = [
    "align_times",
    "angles_to_pose",
    "angular_velocity",
    "ankle_angles",
    "calibrate_cluster",
    "calibrate_lower_limb",
    "compare_events",
    "compose",
    "corrected_cutoff",
    "decompose",
    "derivative",
    "elemental_rotation",
    "ensemble",
    "expected_orientation_error",
    "fill_gaps_rigid",
    "foot_frame",
    "force_plate_events",
    "frame_from_axes",
    "frame_from_points",
    "functional_axis",
    "functional_joint_centre",
    "gait_events",
    "get_R",
    "helical_axes",
    "helical_axis",
    "HelicalAxis",
    "hip_angles",
    "hip_joint_centre",
    "JointAxis",
    "JointCentre",
    "knee_angles",
    "lower_limb_angles",
    "lowpass",
    "LowerLimbModel",
    "normalize_by_side",
    "opensim_coordinates",
    "orientation_error_covariance",
    "pelvis_angles",
    "pelvis_frame",
    "plug_in_gait",
    "PlugInGait",
    "PlugInGaitTrack",
    "pose_to_angles",
    "PoseAngles",
    "read_c3d",
    "read_c3d_model_outputs",
    "read_c3d_parameters",
    "read_events",
    "read_marker_mapping",
    "read_mot",
    "read_trc",
    "read_vsk",
    "reconstruct_landmarks",
    "residual_analysis",
    "ResidualAnalysis",
    "rot_x",
    "rot_y",
    "rot_z",
    "rotation_angle",
    "shank_frame",
    "Skeleton",
    "spatiotemporal_parameters",
    "sphere_fit_centre",
    "stride_table",
    "svdt",
    "thigh_frame",
    "time_normalize",
    "write_events",
    "write_mot",
    "write_trc",
]
