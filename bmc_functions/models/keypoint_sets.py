"""Keypoint sets of markerless pose estimators, as data: role -> the label in the file.

A role names what a keypoint stands for in :func:`~bmc_functions.keypoint_angles`:
``RHIP``, ``RKNEE``, ``RANKLE``, ``RHEEL``, ``RTOE`` (the big toe, or the tip of the foot),
``RSMALL_TOE`` (not used for angles), ``RSHOULDER``, ``RELBOW``, ``RWRIST`` (``L`` for the
left side), and ``NECK``. The labels are those Pose2Sim writes in its TRC files for each 2D
estimator's skeleton (Pagnon et al. 2022; ``Pose2Sim/skeletons.py``); a label a set lacks
leaves its role out of the mapping, and the angles that need it are NaN.

- ``body25b``: OpenPose's BODY_25B, Pose2Sim's default (21 keypoints written).
- ``halpe26``: AlphaPose's/RTMPose's HALPE_26: the same labels, plus a mid-hip ``Hip``,
  eyes and ears (not used).
- ``coco17``: COCO's 17 keypoints: **no feet and no neck** (no ankle angles; the trunk's
  top is the mid-point of the shoulders).
- ``blazepose``: MediaPipe's BlazePose (33 keypoints): heel and ``foot_index`` (the tip of
  the foot, used as the toe), no small toe and no neck.

References
----------
.. [1] Pagnon D, Domalain M, Reveret L (2022) Pose2Sim: an open-source Python package for
   multiview markerless kinematics. J Open Source Softw 7:4362.
"""

#: The roles of one side, without the side's prefix ('R' or 'L').
SIDE_ROLES = ("HIP", "KNEE", "ANKLE", "HEEL", "TOE", "SMALL_TOE", "SHOULDER", "ELBOW",
              "WRIST")

#: Every role a keypoint mapping may use.
ROLES = tuple(p + role for p in "RL" for role in SIDE_ROLES) + ("NECK",)

_BODY25B = {"HIP": "Hip", "KNEE": "Knee", "ANKLE": "Ankle", "HEEL": "Heel", "TOE": "BigToe",
            "SMALL_TOE": "SmallToe", "SHOULDER": "Shoulder", "ELBOW": "Elbow",
            "WRIST": "Wrist"}
_BLAZEPOSE = {"HIP": "hip", "KNEE": "knee", "ANKLE": "ankle", "HEEL": "heel",
              "TOE": "foot_index", "SHOULDER": "shoulder", "ELBOW": "elbow", "WRIST": "wrist"}
_COCO = ("HIP", "KNEE", "ANKLE", "SHOULDER", "ELBOW", "WRIST")


def _camel(roles, neck):
    mapping = {p + role: p + label for p in "RL" for role, label in _BODY25B.items()
               if role in roles}
    if neck:
        mapping["NECK"] = "Neck"
    return mapping


#: Named keypoint sets: role -> label, as Pose2Sim writes them.
KEYPOINT_SETS = {
    "body25b": _camel(SIDE_ROLES, neck=True),
    "halpe26": _camel(SIDE_ROLES, neck=True),
    "coco17": _camel(_COCO, neck=False),
    "blazepose": {p + role: side + "_" + label for p, side in (("R", "right"), ("L", "left"))
                  for role, label in _BLAZEPOSE.items()},
}
