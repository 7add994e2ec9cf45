"""Body models: segment frames from markers, joint centres, joint angles, and their checks.

- :mod:`.segments`: pelvis, thigh, shank and foot frames from landmarks (ISB).
- :mod:`.joints`: joint angles from two adjacent segments' frames.
- :mod:`.functional_joints`: joint centres and axes found from motion.
- :mod:`.lower_limb`: the lower-limb pipeline (static calibration, then any trial), with
  :mod:`.lower_limb_checks` the checks of its postures and trials.
- :mod:`.plug_in_gait`: the Conventional Gait Model (Vicon Plug-in Gait), a subpackage:
  subject measurements, marker labels, lower body, the model.
- :mod:`.skeleton`: joint angles from 3D body poses (keypoints).
"""
