"""bmc_functions: rigid-body kinematics for biomechanics.

The least-squares rigid-body fit of marker sets (:func:`svdt`), the rotation that takes
one vector onto another (:func:`get_R`), Cardan/Euler angles (:func:`decompose`,
:func:`compose`), elemental rotations and orthonormal segment frames; joint angles from 3D
body poses and from marker clusters; TRC, C3D and OpenSim files; gait events and cycles.
Arrays in, arrays out; frames (instants) on the first axis; every function vectorized
over frames. Every public name is imported from here: ``from bmc_functions import svdt``.

The package's folders are the path a lab's data takes, each layer using only the ones
before it and the rigid-body maths under all of them::

    files/  ->  markers/  ->  models/  ->  gait/
    TRC, C3D,   which is      segment      events,
    OpenSim,    which, gaps,  frames,      cycles,
    .vsk; one   filtering,    joint        ensembles
    trial in    cluster       centres,
    mm          tracking      joint angles
    ---------------------------------------------------------------
    rigid_body/: rotations, Cardan angles, frames, svdt, motion

- :mod:`bmc_functions.files`: the file formats, and :mod:`~bmc_functions.files.trial`,
  the one trial loader with units.
- :mod:`bmc_functions.markers`: marker roles, gap filling, filtering, cluster tracking.
- :mod:`bmc_functions.models`: the lower-limb pipeline, Plug-in Gait, poses, and the
  segment frames, joint centres and joint angles they are made of.
- :mod:`bmc_functions.gait`: gait events from markers, event files and force plates,
  time normalisation, ensembles, spatio-temporal parameters.
- :mod:`bmc_functions.rigid_body`: the mathematics.
- Beside them: ``cli`` (the ``bmc-kinematics`` command), ``batch`` (many trials in
  parallel), :mod:`bmc_functions.plotting` (figures), :mod:`bmc_functions.examples`
  (the example trials), ``_checks`` (argument checks and the one warning mechanism) and
  ``_threads`` (BLAS threads).

Paths below the package are internal, except :mod:`bmc_functions.plotting`,
:mod:`bmc_functions.examples` and the few the notebooks import to teach (such as
``bmc_functions.rigid_body.rotations.skew``). tests/test_architecture.py checks the rules.
"""

from .dynamics.newton_euler import (JointLoads, SegmentMotion, inverse_dynamics,
                                    segment_motion)
from .dynamics.segment_parameters import (SegmentParameters, segment_inertia,
                                          segment_parameters)
from .files.c3d import read_c3d
from .files.c3d_parameters import read_c3d_model_outputs, read_c3d_parameters
from .files.force_plates import assign_plates, read_force_plates, resample_force_plates
from .files.c3d_writer import write_c3d
from .files.opensim import align_times, opensim_coordinates, read_mot, write_mot
from .files.trc import read_trc, write_trc
from .files.vsk import read_vsk
from .gait.cycles import (ensemble, normalize_by_side, spatiotemporal_parameters, stride_table,
                          time_normalize)
from .gait.event_files import read_events, write_events
from .gait.events import gait_events
from .gait.force_plates import compare_events, force_plate_events
from .gait.gait_profile import (GaitProfile, gait_profile_score, normative_data,
                                read_normative_data, write_normative_data)
from .markers.filtering import (ResidualAnalysis, corrected_cutoff, derivative, lowpass,
                                residual_analysis)
from .markers.gap_filling import fill_gaps_rigid
from .markers.roles import read_marker_mapping
from .markers.tracking import calibrate_cluster, reconstruct_landmarks
from .models.functional_joints import (JointAxis, JointCentre, functional_axis,
                                       functional_joint_centre, sphere_fit_centre)
from .models.joints import ankle_angles, hip_angles, knee_angles, pelvis_angles
from .models.keypoints import keypoint_angles
from .models.lower_limb import (LowerLimbModel, calibrate_lower_limb, lower_limb_angles,
                                 lower_limb_kinetics)
from .models.plug_in_gait import PlugInGait, PlugInGaitTrack, plug_in_gait
from .models.segments import (foot_frame, hip_joint_centre, pelvis_frame, shank_frame,
                              thigh_frame)
from .models.skeleton import PoseAngles, Skeleton, angles_to_pose, pose_to_angles
from .rigid_body.cardan import compose, decompose
from .rigid_body.clusters import expected_orientation_error, orientation_error_covariance
from .rigid_body.frames import frame_from_axes, frame_from_points
from .rigid_body.motion import HelicalAxis, angular_velocity, helical_axes, helical_axis
from .rigid_body.rotations import (elemental_rotation, get_R, rot_x, rot_y, rot_z,
                                   rotation_angle)
from .rigid_body.svdt import svdt

__version__ = "0.3.0"

__all__ = [
    "align_times",
    "angles_to_pose",
    "angular_velocity",
    "ankle_angles",
    "assign_plates",
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
    "gait_profile_score",
    "GaitProfile",
    "get_R",
    "helical_axes",
    "helical_axis",
    "HelicalAxis",
    "hip_angles",
    "hip_joint_centre",
    "inverse_dynamics",
    "keypoint_angles",
    "JointAxis",
    "JointCentre",
    "JointLoads",
    "knee_angles",
    "lower_limb_angles",
    "lower_limb_kinetics",
    "lowpass",
    "LowerLimbModel",
    "normalize_by_side",
    "normative_data",
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
    "read_force_plates",
    "read_marker_mapping",
    "read_mot",
    "read_normative_data",
    "read_trc",
    "read_vsk",
    "reconstruct_landmarks",
    "resample_force_plates",
    "residual_analysis",
    "ResidualAnalysis",
    "rot_x",
    "rot_y",
    "rot_z",
    "rotation_angle",
    "segment_inertia",
    "segment_motion",
    "segment_parameters",
    "SegmentMotion",
    "SegmentParameters",
    "shank_frame",
    "Skeleton",
    "spatiotemporal_parameters",
    "sphere_fit_centre",
    "stride_table",
    "svdt",
    "thigh_frame",
    "time_normalize",
    "write_c3d",
    "write_events",
    "write_mot",
    "write_normative_data",
    "write_trc",
]
