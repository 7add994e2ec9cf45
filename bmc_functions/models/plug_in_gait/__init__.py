r"""The Conventional Gait Model (Vicon Plug-in Gait, lower limb), step by step.

Most clinical gait laboratories place the Plug-in Gait markers (LASI/RASI, LPSI/RPSI or
SACR; on each side a thigh wand THI, the lateral knee KNE, a tibia wand TIB, the lateral
ankle ANK, HEE and TOE) and report the angles of the Conventional Gait Model (CGM:
Davis et al. 1991 [1]_; Kadaba et al. 1990 [2]_), as Vicon's Plug-in Gait computes them
[3]_. There are no medial markers: the knee and ankle centres are found from the lateral
marker, a wand marker and the measured joint width (the *chord function*), and the hip
centre from a regression on the leg length (Davis et al. 1991)::

    model = plug_in_gait("Static.c3d", "Subject.vsk")   # static trial, subject measurements
    angles = model.angles("Walk.c3d")                     # degrees, one row per frame
    angles["knee", "right", "flexion"]

The steps, each a function of its own (arrays in, arrays out, frames on the first axis):

1. :func:`cgm_pelvis_frame` - origin between the ASIS markers, y from RASI to LASI, x
   forward (towards the ASIS from the sacrum), z up.
2. :func:`davis_hip_centre` - the hip centre in the pelvis frame from the leg length,
   the ASIS-trochanter distance (:func:`asis_trochanter_distance`) and the inter-ASIS
   distance.
3. :func:`chord_joint_centre` - the knee centre from THI, the hip centre, KNE and the
   knee width; the ankle centre from TIB, the knee centre, ANK and the ankle width.
4. :func:`cgm_femur_frame`, :func:`cgm_tibia_frame` (with the tibial torsion),
   :func:`cgm_uncorrected_foot_frame` (ankle centre to TOE) and
   :func:`cgm_foot_frame` (the static offsets applied).
5. :func:`static_foot_offsets` - in the static trial, the plantar-flexion and rotation
   offsets between the uncorrected foot and the foot defined by HEE and TOE.
6. :func:`cgm_angles` - the Cardan angles (sequence y-x-z) with Vicon's signs, and the
   pelvis and foot-progression angles against the direction of progression
   (:func:`progression_frame`).

The modules, each read on its own:

- :mod:`~bmc_functions.models.plug_in_gait.subject` - the subject's measurements (a .vsk,
  a dict, a C3D's PROCESSING group), their names in any case, their checks and defaults.
- :mod:`~bmc_functions.models.plug_in_gait.labels` - a trial's marker labels (subject
  prefixes, renames, case), its units and the body's handedness checked.
- :mod:`~bmc_functions.models.plug_in_gait.checks` - what the model is told, checked
  against what a body allows: measurement ranges and units, measurements against the
  markers, leg markers swapped, misplaced or jumping, the lab's vertical.
- :mod:`~bmc_functions.models.plug_in_gait.upper_body_checks` - the same for the upper
  body: its measurements' ranges (the head offset in radians) and chords, its markers
  swapped (between the sides, along the trunk, along an arm) or far from the body.
- :mod:`~bmc_functions.models.plug_in_gait.lower_body` - the steps above, arrays in and
  arrays out.
- :mod:`~bmc_functions.models.plug_in_gait.upper_body` - the head, thorax and arms
  (Plug-in Gait FullBody), their joint centres and angles, arrays in and arrays out, and
  the ISB's thoracohumeral angles read from the same thorax and humerus
  (:func:`thoracohumeral_angles`, :meth:`PlugInGait.thoracohumeral_angles`).
- :mod:`~bmc_functions.models.plug_in_gait.model` - :func:`plug_in_gait` (the static
  processing) and :class:`PlugInGait` (a trial's centres, frames and angles).


Segment axes as in Plug-in Gait: x anterior, y to the subject's left (for the segments
of both sides), z proximal (up the segment); the foot's z points from the toe back
towards the ankle. Lengths in mm; angles in the subject measurements in radians (as
Vicon stores them); output angles in degrees.

References
----------
.. [1] Davis RB, Ounpuu S, Tyburski D, Gage JR (1991). A gait analysis data collection
   and reduction technique. Human Movement Science 10(5), 575-587.
.. [2] Kadaba MP, Ramakrishnan HK, Wootten ME (1990). Measurement of lower extremity
   kinematics during level walking. Journal of Orthopaedic Research 8(3), 383-392.
.. [3] Vicon Motion Systems (2010-2017). Plug-in Gait reference guide / Plug-in Gait
   product guide (Nexus 2): lower-body model, chord function, static processing.
.. [4] Baker R (2013). Measuring walking: a handbook of clinical gait analysis. Mac
   Keith Press. (The CGM's definitions and their criticism.)
.. [5] Baker R (2006). Gait analysis methods in rehabilitation. Journal of
   NeuroEngineering and Rehabilitation 3, 4.
"""

from .labels import check_handedness
from .lower_body import (ASIS_TROCHANTER_INTERCEPT, ASIS_TROCHANTER_SLOPE, CGM_ANGLES,
                         DAVIS_BETA, DAVIS_C_INTERCEPT, DAVIS_C_SLOPE, DAVIS_THETA,
                         LEG_MARKERS, LOWER_BODY_OUTPUTS, PELVIS_MARKERS,
                         PROGRESSION_MIN_PATH, SIDES, asis_trochanter_distance, cgm_angles,
                         cgm_femur_frame, cgm_foot_frame, cgm_pelvis_frame,
                         cgm_static_foot_frame, cgm_tibia_frame, cgm_uncorrected_foot_frame,
                         chord_joint_centre, davis_hip_centre, progression_frame,
                         static_foot_offsets)
from .model import (PROGRESSION_WARN_DEG, VICON_OUTPUTS, PlugInGait, PlugInGaitTrack,
                    plug_in_gait)
from .subject import (DEFAULT_MARKER_DIAMETER, NOT_APPLIED, REQUIRED, STATIC_ONLY_NOT_APPLIED,
                      load_subject)
from .upper_body import (ARM_MARKERS, HEAD_MARKERS, THORAX_MARKERS, UPPER_BODY_ANGLES,
                         UPPER_BODY_DEFAULTS, UPPER_BODY_OUTPUTS, cgm_arm_angles,
                         cgm_clavicle_frame, cgm_hand_frame, cgm_head_frame,
                         cgm_humerus_frame, cgm_radius_frame, cgm_thorax_frame,
                         cgm_trunk_angles, elbow_joint_centre, hand_centre, head_level_offset,
                         shoulder_joint_centre, thoracohumeral_angles, upper_body_angles,
                         upper_body_geometry, wrist_joint_centre)

__all__ = [
    "ARM_MARKERS", "ASIS_TROCHANTER_INTERCEPT", "ASIS_TROCHANTER_SLOPE", "CGM_ANGLES",
    "DAVIS_BETA", "DAVIS_C_INTERCEPT", "DAVIS_C_SLOPE", "DAVIS_THETA",
    "DEFAULT_MARKER_DIAMETER", "HEAD_MARKERS", "LEG_MARKERS", "LOWER_BODY_OUTPUTS",
    "NOT_APPLIED", "PELVIS_MARKERS", "PROGRESSION_MIN_PATH", "PROGRESSION_WARN_DEG",
    "REQUIRED", "SIDES", "STATIC_ONLY_NOT_APPLIED", "THORAX_MARKERS", "UPPER_BODY_ANGLES",
    "UPPER_BODY_DEFAULTS", "UPPER_BODY_OUTPUTS", "VICON_OUTPUTS", "PlugInGait",
    "PlugInGaitTrack", "asis_trochanter_distance", "cgm_angles", "cgm_arm_angles",
    "cgm_clavicle_frame", "cgm_femur_frame", "cgm_foot_frame", "cgm_hand_frame",
    "cgm_head_frame", "cgm_humerus_frame", "cgm_pelvis_frame", "cgm_radius_frame",
    "cgm_static_foot_frame", "cgm_thorax_frame", "cgm_tibia_frame", "cgm_trunk_angles",
    "cgm_uncorrected_foot_frame", "check_handedness", "chord_joint_centre",
    "davis_hip_centre", "elbow_joint_centre", "hand_centre", "head_level_offset",
    "load_subject", "plug_in_gait", "progression_frame", "shoulder_joint_centre",
    "static_foot_offsets", "thoracohumeral_angles", "upper_body_angles",
    "upper_body_geometry", "wrist_joint_centre",
]
