"""A mutation sample: small deliberate bugs, each of which the tests must catch.

    python tools/mutation_sample.py              # every mutation, in a scratch copy
    python tools/mutation_sample.py --list       # the mutations, without running them

Each mutation changes one comparison, constant, index or sign in the package (the kind of
slip a refactor makes) and runs the tests that should notice it. A mutation is *killed*
when those tests fail, and *survives* when they pass: a survivor is a behaviour no test
pins. The sample is run in a scratch copy of the repository (the working tree is never
touched) and prints a table and the score; the issue that asked for it (24) wants at least
90 % killed. tests/test_mutation_sample.py checks that every mutation still applies to
the current code (its original text is found exactly once), so the sample cannot silently
go stale.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class Mutation:
    file: str          # below bmc_functions/
    original: str      # text found exactly once in the file
    mutant: str        # what it becomes
    tests: tuple       # pytest arguments that should catch it
    what: str          # the slip it models


MUTATIONS = [
    # files: units, the TRC writer, OpenSim's pelvis
    Mutation("files/trial.py", '"m": 1000.0}', '"m": 100.0}',
             ("tests/test_lower_limb.py", "tests/test_gait_units_and_boundaries.py"),
             "metres read as 100 mm"),
    Mutation("files/trial.py", '"millimeters": "mm", ', "",
             ("tests/test_gait_units_and_boundaries.py", "tests/test_lower_limb.py"),
             "a spelled-out unit forgotten"),
    Mutation("files/trc.py", 'minimum=0, strict=True)', 'minimum=0)',
             ("tests/test_marker_io.py", "tests/test_documented_boundaries.py"),
             "write_trc accepts a rate of 0 Hz"),
    Mutation("files/opensim.py", "return np.stack([-tilt, -mirror * obliquity",
             "return np.stack([tilt, -mirror * obliquity",
             ("tests/test_plug_in_gait_variants.py", "tests/test_files_layer.py"),
             "Plug-in Gait's pelvis tilt written to OpenSim with the wrong sign"),
    Mutation("gait/event_files.py", "np.diff(times) > 1e-3", "np.diff(times) > 1e-2",
             ("tests/test_event_io.py", "tests/test_documented_boundaries.py"),
             "events 1-10 ms apart merged as duplicates"),
    # markers: the one pelvis resolver, the filter
    Mutation("markers/roles.py", 'if {"RPSIS", "LPSIS"} <= set(markers)',
             'if {"RPSIS", "LPSIS"} & set(markers)',
             ("tests/test_gait_units_and_boundaries.py", "tests/test_lower_limb.py",
              "tests/test_lower_limb_calibration_steps.py", "tests/test_documented_boundaries.py"),
             "one PSIS taken as both"),
    Mutation("markers/filtering.py", "(2.0 ** (1.0 / passes) - 1.0) ** (1.0 / (2 * order))",
             "(2.0 ** (1.0 / passes) - 1.0) ** (1.0 / order)",
             ("tests/test_filtering.py",), "the cut-off correction's exponent"),
    # the shared checks and the one warning mechanism
    Mutation("_checks.py", "while frame is not None and frame.f_code.co_filename.startswith",
             "while False and frame.f_code.co_filename.startswith",
             ("tests/test_lower_limb_calibration_steps.py", "tests/test_lower_limb.py"),
             "warnings attributed to the package's own line"),
    Mutation("_checks.py", "(number <= minimum if strict else number < minimum)",
             "(number < minimum if strict else number < minimum)",
             ("tests/test_argument_checks.py", "tests/test_public_arguments.py"),
             "a strict lower bound made inclusive"),
    Mutation("_checks.py", "    if isinstance(value, (bool, np.bool_)):\n        return bool(value)",
             "    if isinstance(value, (bool, np.bool_, str)):\n        return bool(value)",
             ("tests/test_joints.py", "tests/test_public_arguments.py"),
             "a flag given as the string 'False' read as True"),
    Mutation("batch.py", "if workers is not None and client is not None:",
             "if workers is not None and client is not None and False:",
             ("tests/test_batch.py",), "workers and a dask client both accepted"),
    # the rigid-body maths
    Mutation("rigid_body/rotations.py", "return np.arctan2(np.linalg.norm(r, axis=-1), trace - 1)",
             "return np.arctan2(np.linalg.norm(r, axis=-1), trace - 1.01)",
             ("tests/test_rotations.py",), "the rotation angle's trace term"),
    Mutation("rigid_body/motion.py", "zip(out, ((2, 1), (0, 2), (1, 0)))",
             "zip(out, ((1, 2), (0, 2), (1, 0)))",
             ("tests/test_motion.py",), "angular velocity's x component with the wrong sign"),
    Mutation("rigid_body/svdt.py", "if n > MOMENT_MATRIX_MAX_MARKERS:",
             "if n > 4 * MOMENT_MATRIX_MAX_MARKERS:",
             ("tests/test_rigid_body.py", "tests/test_rigid_body_fast.py",
              "tests/test_svdt_paths.py"),
             "the closed form used up to 512 markers (memory bound moved)"),
    Mutation("rigid_body/frames.py", "out[axis] = np.sign(vector[axis]) or 1.0",
             "out[axis] = 1.0",
             ("bmc_functions/rigid_body/frames.py", "tests/test_plug_in_gait.py"),
             "the nearest lab axis loses its sign"),
    # models: joint angles, the checks, Plug-in Gait
    Mutation("models/joints.py", '    degrees = check_flag(degrees, "degrees")\n    proximal',
             '    proximal', ("tests/test_joints.py", "tests/test_joint_argument_checks.py"),
             "degrees no longer checked in the joint angles"),
    Mutation("models/lower_limb_checks.py", "DEFORM_MM = 6.0", "DEFORM_MM = 12.0",
             ("tests/test_lower_limb_checks.py", "tests/test_lower_limb_calibration_steps.py"),
             "the deformation threshold doubled (a survivor of the first sample)"),
    Mutation("models/lower_limb_checks.py", "STATIC_ROTATION_DEG = 10.0",
             "STATIC_ROTATION_DEG = 15.0",
             ("tests/test_lower_limb_checks.py", "tests/test_lower_limb_calibration_steps.py"),
             "a static trial may turn by 15 degrees"),
    Mutation("models/lower_limb_checks.py", "LEGS_CROSSED = 0.25", "LEGS_CROSSED = 0.35",
             ("tests/test_lower_limb_checks.py", "tests/test_lower_limb_calibration_steps.py"),
             "the crossed-legs threshold"),
    Mutation("models/plug_in_gait/lower_body.py", "ASIS_TROCHANTER_SLOPE = 0.1288",
             "ASIS_TROCHANTER_SLOPE = 0.1388",
             ("tests/test_plug_in_gait.py",), "Davis's ASIS-trochanter regression slope"),
    # gait: cycles and events
    Mutation("gait/cycles.py", "if stop - start > max_gap_samples or start == 0",
             "if stop - start >= max_gap_samples or start == 0",
             ("tests/test_gait_units_and_boundaries.py", "tests/test_gait_cycles.py"),
             "a gap of exactly max_gap no longer bridged (a survivor of the first sample)"),
    Mutation("gait/cycles.py", "inside = (starts >= time[0] - tol) & (ends <= time[-1] + tol)",
             "inside = (starts >= time[0] - tol) & (ends <= time[-1])",
             ("tests/test_gait_units_and_boundaries.py", "tests/test_gait_cycles.py",
              "tests/test_documented_boundaries.py"),
             "the rounding tolerance at the trial's last frame dropped"),
    Mutation("gait/cycles.py", "int(np.floor(max_gap * rate + 1e-9))",
             "int(np.floor(max_gap * rate + 1e-9)) + 1",
             ("tests/test_gait_units_and_boundaries.py", "tests/test_gait_cycles.py"),
             "max_gap counted one frame long (off by one)"),
    Mutation("files/force_plates.py", "np.asarray(vertical) > threshold",
             "np.asarray(vertical) >= 2 * threshold",
             ("tests/test_event_io.py", "tests/test_gait_events.py",
              "tests/test_documented_boundaries.py"),
             "the force plates' contact threshold doubled"),
    # --- a blind sample: chosen from the package's code alone by a reviewer who did not
    # read the tests (its first run killed 15 of 24; the tests of
    # tests/test_documented_boundaries.py were added for the survivors)
    # files/
    Mutation("files/trial.py", '"cm": 10.0', '"cm": 1.0',
             ("tests/test_lower_limb.py", "tests/test_gait_units_and_boundaries.py", "tests/test_marker_io.py",
              "bmc_functions/files/trial.py"),
             "centimetres read as millimetres"),
    Mutation("files/trc.py", "max(0.02 * expected, 0.002)", "max(0.2 * expected, 0.002)",
             ("tests/test_marker_io.py", "tests/test_files_layer.py", "tests/test_marker_data.py",
              "bmc_functions/files/trc.py", "tests/test_documented_boundaries.py"),
             "DataRate-vs-Time tolerance 20 % instead of the documented 2 %"),
    Mutation("files/c3d.py", 'first = c3d["first_frame"] + 1', 'first = c3d["first_frame"]',
             ("tests/test_marker_io.py", "tests/test_files_layer.py", "tests/test_marker_data.py",
              "bmc_functions/files/c3d.py"),
             "C3D frame numbers counted from 0 (off by one)"),
    # markers/
    Mutation("markers/filtering.py", "jumps = np.flatnonzero(steps > 1.5 * median)",
             "jumps = np.flatnonzero(steps > 2.5 * median)",
             ("tests/test_filtering.py", "bmc_functions/markers/filtering.py", "tests/test_documented_boundaries.py"),
             "a time index with one dropped row (step 2x) no longer refused"),
    Mutation("markers/filtering.py", "MIN_SIGNAL = 1.2", "MIN_SIGNAL = 1.0",
             ("tests/test_filtering.py", "bmc_functions/markers/filtering.py"),
             "residual analysis finds a cut-off in white noise"),
    Mutation("markers/gap_filling.py", "if not -len(markers) <= reference < len(markers):",
             "if not -len(markers) <= reference <= len(markers):",
             ("tests/test_gap_filling.py", "tests/test_zero_gaps.py",
              "bmc_functions/markers/gap_filling.py"),
             "reference frame == len(markers) passes the range check (IndexError)"),
    # models/
    Mutation("models/segments.py", '"x": (-0.24, 0.0, -9.9)', '"x": (-0.24, 0.0, 9.9)',
             ("tests/test_segments.py", "bmc_functions/models/segments.py"),
             "Harrington's x constant with the wrong sign"),
    Mutation("models/joints.py", "R = R_lab.T @ R", "R = R_lab @ R",
             ("tests/test_joints.py", "tests/test_joint_argument_checks.py", "bmc_functions/models/joints.py"),
             "pelvis_angles: R_lab applied untransposed"),
    Mutation("models/lower_limb.py",
             "if angle > KNEE_AXIS_ANGLE_DEG or distance > KNEE_AXIS_DISTANCE_MM:",
             "if angle > KNEE_AXIS_ANGLE_DEG and distance > KNEE_AXIS_DISTANCE_MM:",
             ("tests/test_lower_limb_functional.py", "tests/test_lower_limb.py",
              "bmc_functions/models/lower_limb.py", "tests/test_documented_boundaries.py"),
             "functional knee axis warned only when both angle and distance are off"),
    Mutation("models/lower_limb_checks.py",
             "if ratios and all(not 1 / UNITS_RATIO <= r <= UNITS_RATIO for r, _ in ratios):",
             "if ratios and any(not 1 / UNITS_RATIO <= r <= UNITS_RATIO for r, _ in ratios):",
             ("tests/test_lower_limb_checks.py", "tests/test_lower_limb_calibration_steps.py",
              "bmc_functions/models/lower_limb_checks.py", "tests/test_documented_boundaries.py"),
             "one odd-sized cluster taken as wrong units"),
    Mutation("models/plug_in_gait/lower_body.py", "rot_z(-MIRROR[side] * torsion)",
             "rot_z(MIRROR[side] * torsion)",
             ("tests/test_plug_in_gait.py", "tests/test_plug_in_gait_variants.py",
              "tests/test_plug_in_gait_imports.py", "bmc_functions/models/plug_in_gait"),
             "tibial torsion applied with the wrong sign"),
    Mutation("models/skeleton.py", '"leftelbow": ("upperarm", (1, 0, 0))',
             '"leftelbow": ("forearm", (1, 0, 0))',
             ("tests/test_skeleton.py", "tests/test_pose_data.py", "bmc_functions/models/skeleton.py"),
             "left upper arm offset takes the forearm length"),
    # gait/
    Mutation("gait/events.py", "if lateral < -MIN_SIDE_OFFSET:", "if lateral < -4 * MIN_SIDE_OFFSET:",
             ("tests/test_gait_events.py", "tests/test_gait_data.py", "bmc_functions/gait/events.py"),
             "swapped foot labels tolerated up to 160 mm on the wrong side"),
    Mutation("gait/events.py", "MIN_STEP = 0.08", "MIN_STEP = 0.02",
             ("tests/test_gait_events.py", "tests/test_gait_data.py", "bmc_functions/gait/events.py"),
             "both-feet-together warning at 20 ms instead of the documented 80 ms"),
    Mutation("gait/cycles.py", '"stride_time_sd": np.std(stride, ddof=1)',
             '"stride_time_sd": np.std(stride)',
             ("tests/test_gait_cycles.py", "tests/test_gait_units_and_boundaries.py", "bmc_functions/gait/cycles.py"),
             "stride-time SD with ddof=0"),
    Mutation("gait/cycles.py", "double = count > 1", "double = count > 2",
             ("tests/test_gait_cycles.py", "tests/test_gait_units_and_boundaries.py", "bmc_functions/gait/cycles.py"),
             "a cycle holding two toe-offs (missed strike) kept"),
    Mutation("files/force_plates.py", "<= half_v + PLATE_MARGIN)", "<= half_u + PLATE_MARGIN)",
             ("tests/test_event_io.py", "tests/test_gait_events.py", "bmc_functions/gait/force_plates.py", "tests/test_documented_boundaries.py"),
             "plate's second half-width taken from the first edge (wrong axis)"),
    Mutation("gait/event_files.py", 'start = info["first_frame"] / info["rate"]',
             'start = (info["first_frame"] + 1) / info["rate"]',
             ("tests/test_event_io.py", "bmc_functions/gait/event_files.py"),
             "C3D event times shifted by one frame"),
    # rigid_body/
    Mutation("rigid_body/cardan.py", "np.where(x == -np.pi, np.pi, x) for x in (a, c)",
             "np.where(x == np.pi, -np.pi, x) for x in (a, c)",
             ("tests/test_angles.py", "tests/test_rotations.py", "bmc_functions/rigid_body/cardan.py", "tests/test_documented_boundaries.py"),
             "outer angles in [-pi, pi) instead of the documented (-pi, pi]"),
    Mutation("rigid_body/clusters.py", "collinear = eig[..., 1] <= COLLINEAR_RTOL**2 * eig[..., 2]",
             "collinear = eig[..., 1] <= COLLINEAR_RTOL * eig[..., 2]",
             ("tests/test_clusters.py", "bmc_functions/rigid_body/clusters.py", "tests/test_documented_boundaries.py"),
             "collinearity tolerance not squared (1e-3 on singular values)"),
    Mutation("rigid_body/motion.py", "MAX_FRAME_ROTATION = np.radians(30.0)",
             "MAX_FRAME_ROTATION = np.radians(45.0)",
             ("tests/test_motion.py", "bmc_functions/rigid_body/motion.py"),
             "angular-velocity warning at 45 deg per frame instead of the documented 30"),
    Mutation("rigid_body/svdt.py", "np.sqrt(E / (3.0 * count), out=RMSE)",
             "np.sqrt(E / count, out=RMSE)",
             ("tests/test_rigid_body.py", "tests/test_rigid_body_fast.py",
              "tests/test_svdt_paths.py", "bmc_functions/rigid_body/svdt.py"),
             "closed-form RMSE per marker instead of per coordinate"),
    # _checks.py / cli.py
    Mutation("_checks.py", "rate > 0 and min(abs(from_span / rate - 1),", "rate > 0 and max(abs(from_span / rate - 1),",
             ("tests/test_gait_cycles.py", "tests/test_lower_limb.py", "tests/test_gait_units_and_boundaries.py",
              "bmc_functions/_checks.py", "tests/test_documented_boundaries.py"),
             "rate warning when either span or step is off (documented: both)"),
    Mutation("cli.py", "if run.failed or missing:", "if run.failed:",
             ("tests/test_cli.py", "bmc_functions/cli.py", "tests/test_documented_boundaries.py"),
             "exit status 0 when a trial pattern matched no file"),
    # --- a second blind sample, by another reviewer who read the package's code alone
    # (its first run killed 16 of 24; tests/test_documented_boundaries.py has the
    # tests added for the survivors)
    # files/
    Mutation("files/opensim.py", "yxz = np.stack([sign * rotation, -sign * obliquity, -tilt]",
             "yxz = np.stack([sign * rotation, sign * obliquity, -tilt]",
             ("tests/test_opensim_io.py", "tests/test_files_layer.py", "tests/test_documented_boundaries.py",
              "bmc_functions/files/opensim.py"),
             "ISB pelvis obliquity rebuilt with the wrong sign for OpenSim"),
    Mutation("files/c3d.py", "invalid = residuals[0].T < 0", "invalid = residuals[0].T <= 0",
             ("tests/test_marker_io.py", "tests/test_files_layer.py", "tests/test_marker_data.py",
              "tests/test_zero_gaps.py", "tests/test_documented_boundaries.py", "bmc_functions/files/c3d.py"),
             "C3D points of residual 0 (valid, interpolated) read as gaps"),
    Mutation("files/marker_table.py",
             "zero[:, first:stop] = np.all(values.reshape(len(df), -1, 3) == 0, axis=2)",
             "zero[:, first:stop] = np.any(values.reshape(len(df), -1, 3) == 0, axis=2)",
             ("tests/test_zero_gaps.py", "tests/test_marker_io.py", "tests/test_documented_boundaries.py",
              "bmc_functions/files/marker_table.py"),
             "a point with one zero coordinate taken as a (0, 0, 0) gap"),
    # markers/
    Mutation("markers/tracking.py", "landmarks = (l_local @ R.reshape(-1, 3).T)",
             "landmarks = (l_local @ np.swapaxes(R, 1, 2).reshape(-1, 3).T)",
             ("tests/test_tracking.py", "tests/test_documented_boundaries.py", "bmc_functions/markers/tracking.py"),
             "reconstructed landmarks rotated by R transposed"),
    Mutation("markers/roles.py", "        if len(value) < 3:", "        if len(value) < 2:",
             ("tests/test_marker_roles.py", "tests/test_documented_boundaries.py", "bmc_functions/markers/roles.py"),
             "a cluster role of 2 labels accepted (documented: 3 or more)"),
    Mutation("markers/filtering.py", "long = runs.length >= order + 1",
             "long = runs.length > order + 1",
             ("tests/test_filtering.py", "tests/test_documented_boundaries.py", "bmc_functions/markers/filtering.py"),
             "derivative: runs of order+1 samples left NaN (off by one)"),
    # models/
    Mutation("models/joints.py", "sign = sign * np.array([1.0, -1.0, -1.0])",
             "sign = sign * np.array([1.0, -1.0, 1.0])",
             ("tests/test_joints.py", "tests/test_joint_argument_checks.py", "tests/test_documented_boundaries.py", "bmc_functions/models/joints.py"),
             "left joint rotation not mirrored"),
    Mutation("models/segments.py", "PELVIS_WIDTH_RANGE_MM = (50.0, 600.0)",
             "PELVIS_WIDTH_RANGE_MM = (5.0, 600.0)",
             ("tests/test_segments.py", "tests/test_documented_boundaries.py", "bmc_functions/models/segments.py"),
             "Harrington hip centre accepts a pelvis in cm"),
    Mutation("models/functional_joints.py", "\nHINGE_RATIO = 0.5\n", "\nHINGE_RATIO = 1.0\n",
             ("tests/test_functional_joints.py", "tests/test_documented_boundaries.py", "bmc_functions/models/functional_joints.py"),
             "functional_axis hinge warning at ratio 1 instead of the documented 0.5"),
    Mutation("models/plug_in_gait/subject.py", "DEFAULT_MARKER_DIAMETER = 14.0",
             "DEFAULT_MARKER_DIAMETER = 16.0",
             ("tests/test_plug_in_gait.py", "tests/test_plug_in_gait_variants.py",
              "tests/test_plug_in_gait_imports.py", "tests/test_documented_boundaries.py", "bmc_functions/models/plug_in_gait"),
             "Plug-in Gait's default marker diameter 16 mm instead of 14"),
    Mutation("models/lower_limb_checks.py", "ANKLE_WIDTH_MM = (40.0, 130.0)",
             "ANKLE_WIDTH_MM = (40.0, 230.0)",
             ("tests/test_lower_limb_checks.py", "tests/test_lower_limb_calibration_steps.py", "tests/test_documented_boundaries.py",
              "bmc_functions/models/lower_limb_checks.py"),
             "malleolus markers 130-230 mm apart accepted"),
    Mutation("models/lower_limb.py", "FUNCTIONAL_HIP_DISTANCE_MM = 50.0",
             "FUNCTIONAL_HIP_DISTANCE_MM = 80.0",
             ("tests/test_lower_limb_functional.py", "tests/test_lower_limb.py", "tests/test_documented_boundaries.py",
              "bmc_functions/models/lower_limb.py"),
             "functional-vs-Harrington hip warning at 80 mm instead of the documented 50"),
    Mutation("models/skeleton.py", "MAX_FRAME_TURN_DEG = 90.0", "MAX_FRAME_TURN_DEG = 150.0",
             ("tests/test_skeleton.py", "tests/test_pose_data.py", "tests/test_documented_boundaries.py", "bmc_functions/models/skeleton.py"),
             "root-frame jumps of 90-150 degrees not flagged"),
    # gait/
    Mutation("gait/events.py", "long = np.diff(kinds[kind]) >= 1.7 * stride",
             "long = np.diff(kinds[kind]) >= 2.7 * stride",
             ("tests/test_gait_events.py", "tests/test_gait_data.py", "tests/test_documented_boundaries.py", "bmc_functions/gait/events.py"),
             "a missing event (interval of 2 strides) no longer warned"),
    Mutation("gait/events.py", "MAX_FOOT = 350.0", "MAX_FOOT = 450.0",
             ("tests/test_gait_events.py", "tests/test_gait_data.py", "tests/test_documented_boundaries.py", "bmc_functions/gait/events.py"),
             "heel-toe distance up to 450 mm taken as one foot"),
    Mutation("gait/cycles.py", '- np.searchsorted(offs, start, side="right")) > 1',
             '- np.searchsorted(offs, start, side="right")) > 2',
             ("tests/test_gait_cycles.py", "tests/test_gait_units_and_boundaries.py", "tests/test_documented_boundaries.py", "bmc_functions/gait/cycles.py"),
             "spatiotemporal stride spanning two toe-offs (missed strike) kept"),
    Mutation("gait/force_plates.py", "if stop < forces.shape[2]:", "if stop <= forces.shape[2]:",
             ("tests/test_event_io.py", "tests/test_gait_events.py", "tests/test_documented_boundaries.py", "bmc_functions/gait/force_plates.py"),
             "a contact still loaded at the recording's end gives a toe-off"),
    Mutation("gait/event_files.py", 'n = info["used"] if info["used"] else n', "n = n",
             ("tests/test_event_io.py", "tests/test_documented_boundaries.py", "bmc_functions/gait/event_files.py"),
             "C3D EVENT:USED ignored (stale events beyond it read)"),
    # rigid_body/
    Mutation("rigid_body/motion.py", "MIN_HELICAL_ANGLE = np.radians(5.0)",
             "MIN_HELICAL_ANGLE = np.radians(2.0)",
             ("tests/test_motion.py", "tests/test_documented_boundaries.py", "bmc_functions/rigid_body/motion.py"),
             "helical axis default min_angle 2 deg instead of the documented 5"),
    Mutation("rigid_body/motion.py", "(1.0 / np.tan(0.5 * angle))[..., None] * np.cross(n, u))",
             "(1.0 / np.tan(0.5 * angle))[..., None] * np.cross(u, n))",
             ("tests/test_motion.py", "tests/test_documented_boundaries.py", "bmc_functions/rigid_body/motion.py"),
             "helical axis point: cross product reversed"),
    Mutation("rigid_body/frames.py",
             "cross_rows(*((u, v) if parity > 0 else (v, u)), out=entries[:, k], scratch=term)",
             "cross_rows(u, v, out=entries[:, k], scratch=term)",
             ("tests/test_frames.py", "tests/test_documented_boundaries.py", "bmc_functions/rigid_body/frames.py"),
             "frame_from_axes left-handed for odd axis orders ('yx', 'xz', ...)"),
    Mutation("rigid_body/svdt.py", "if sv[1] <= COLLINEAR_RTOL * sv[0]:",
             "if sv[1] <= COLLINEAR_RTOL**2 * sv[0]:",
             ("tests/test_rigid_body.py", "tests/test_rigid_body_fast.py",
              "tests/test_svdt_paths.py", "tests/test_documented_boundaries.py", "bmc_functions/rigid_body/svdt.py"),
             "svdt accepts a nearly collinear reference (1e-12 instead of 1e-6)"),
    # _checks.py / plotting.py
    Mutation("_checks.py", "if high > max_abs or low < -max_abs:", "if high > max_abs:",
             ("tests/test_argument_checks.py", "tests/test_public_arguments.py", "tests/test_documented_boundaries.py",
              "bmc_functions/_checks.py"),
             "huge negative values (-1e300) pass the magnitude check"),
    Mutation("plotting.py", "outside = (at < finite.min()) | (at > finite.max())",
             "outside = at > finite.max()",
             ("tests/test_plotting.py", "tests/test_documented_boundaries.py", "bmc_functions/plotting.py"),
             "events before the curves' start drawn silently (no warning)"),
    # --- a third blind sample, by a third reviewer who read the package's code alone
    # (its first run killed 18 of 24, one equivalent mutant replaced; the survivors'
    # tests are in tests/test_documented_boundaries.py)
    # files/
    Mutation("files/trc.py", "if count > 1)", "if count > 2)",
             ("tests/test_marker_io.py", "tests/test_files_layer.py", "tests/test_marker_data.py",
              "tests/test_documented_boundaries.py", "bmc_functions/files/trc.py"),
             "read_trc: a label used twice not refused as duplicate"),
    Mutation("files/trc.py", "if (steps <= 0).any():", "if (steps < 0).any():",
             ("tests/test_marker_io.py", "tests/test_files_layer.py", "tests/test_marker_data.py",
              "tests/test_documented_boundaries.py", "bmc_functions/files/trc.py"),
             "read_trc: a repeated time (step 0) not warned"),
    Mutation("files/trc.py", "if len(time) > 1 and (np.diff(time) <= 0).any():",
             "if len(time) > 1 and (np.diff(time) < 0).any():",
             ("tests/test_marker_io.py", "tests/test_files_layer.py", "tests/test_marker_data.py",
              "tests/test_documented_boundaries.py", "bmc_functions/files/trc.py"),
             "write_trc accepts a repeated time"),
    Mutation("files/trc_rows.py", "first_line = 6 + int(numbers[0])", "first_line = 7 + int(numbers[0])",
             ("tests/test_marker_io.py", "tests/test_files_layer.py", "tests/test_marker_data.py",
              "tests/test_documented_boundaries.py", "bmc_functions/files/trc_rows.py"),
             "TRC row errors name the line after the bad one (off by one)"),
    # markers/
    Mutation("markers/gap_filling.py", "        mask[gap_frames] = fill",
             "        mask[gap_frames] = missing[gap_frames]",
             ("tests/test_gap_filling.py", "tests/test_zero_gaps.py", "tests/test_lower_limb_gaps.py",
              "tests/test_documented_boundaries.py", "bmc_functions/markers/gap_filling.py"),
             "fill_gaps mask marks unfilled gaps as filled"),
    Mutation("markers/tracking.py", "return (cluster - centroid) @ R_T, (landmarks - centroid) @ R_T",
             "return (cluster - centroid) @ R_T, landmarks @ R_T",
             ("tests/test_tracking.py", "tests/test_documented_boundaries.py", "bmc_functions/markers/tracking.py"),
             "landmarks in the cluster frame not taken relative to the centroid"),
    Mutation("markers/filtering.py", "padlen = min(wanted, length - 1)", "padlen = min(wanted, length)",
             ("tests/test_filtering.py", "tests/test_documented_boundaries.py", "bmc_functions/markers/filtering.py"),
             "padding as long as a short run (sosfiltfilt refuses it; off by one)"),
    Mutation("markers/filtering.py",
             "np.divide(np.subtract(block[1], block[0], out=out[0]), step, out=out[0])",
             "out[0] = (-3 * block[0] + 4 * block[1] - block[2]) / (2 * step)",
             ("tests/test_filtering.py", "tests/test_documented_boundaries.py", "bmc_functions/markers/filtering.py"),
             "velocity at a run's first frame by second-order differences (fails on 2-frame "
             "runs)"),
    # models/
    Mutation("models/plug_in_gait/lower_body.py", "DAVIS_C_INTERCEPT = -15.3", "DAVIS_C_INTERCEPT = -13.5",
             ("tests/test_plug_in_gait.py", "tests/test_plug_in_gait_variants.py",
              "tests/test_plug_in_gait_imports.py", "tests/test_documented_boundaries.py",
              "bmc_functions/models/plug_in_gait"),
             "Davis's C intercept -13.5 instead of the documented -15.3 mm"),
    Mutation("models/functional_joints.py", "MIN_RANGE_DEG = 5.0", "MIN_RANGE_DEG = 2.0",
             ("tests/test_functional_joints.py", "tests/test_lower_limb_functional.py",
              "tests/test_documented_boundaries.py", "bmc_functions/models/functional_joints.py"),
             "functional joints accept 2 deg of motion (documented: 5)"),
    Mutation("models/lower_limb_checks.py", "KNEE_WIDTH_MM = (50.0, 170.0)", "KNEE_WIDTH_MM = (50.0, 270.0)",
             ("tests/test_lower_limb_checks.py", "tests/test_lower_limb_calibration_steps.py",
              "tests/test_documented_boundaries.py", "bmc_functions/models/lower_limb_checks.py"),
             "knee markers 170-270 mm apart accepted"),
    Mutation("models/lower_limb.py", "PROGRESSION_WARN_DEG = 20.0", "PROGRESSION_WARN_DEG = 30.0",
             ("tests/test_lower_limb.py", "tests/test_lower_limb_calibration_steps.py",
              "tests/test_documented_boundaries.py", "bmc_functions/models/lower_limb.py"),
             "progression off a lab axis warned at 30 deg instead of the documented 20"),
    # gait/
    Mutation("files/force_plates.py", "MAX_TRAVEL = 150.0", "MAX_TRAVEL = 250.0",
             ("tests/test_event_io.py", "tests/test_gait_events.py", "tests/test_documented_boundaries.py",
              "bmc_functions/gait/force_plates.py"),
             "foot on the plate may travel 250 mm (documented 150)"),
    Mutation("gait/events.py", "MIN_RATE = 45.0", "MIN_RATE = 25.0",
             ("tests/test_gait_events.py", "tests/test_gait_data.py", "tests/test_documented_boundaries.py",
              "bmc_functions/gait/events.py"),
             "low-rate warning below 25 Hz instead of the documented 45"),
    Mutation("gait/cycles.py", "MAX_MEDIAN_STRIDE = 10.0", "MAX_MEDIAN_STRIDE = 100.0",
             ("tests/test_event_io.py", "tests/test_documented_boundaries.py",
              "bmc_functions/gait/event_files.py"),
             "event files in frames/ms (median stride 10-100) read without a warning"),
    Mutation("gait/cycles.py", "\nMIN_CYCLE_FRAMES = 4\n", "\nMIN_CYCLE_FRAMES = 2\n",
             ("tests/test_gait_cycles.py", "tests/test_gait_units_and_boundaries.py",
              "tests/test_documented_boundaries.py", "bmc_functions/gait/cycles.py"),
             "cycles of 2-4 frames accepted (documented 4)"),
    # rigid_body/
    Mutation("rigid_body/rotations.py", "j = np.argmin(np.abs(np.nan_to_num(u)), axis=-1)",
             "j = np.argmax(np.abs(np.nan_to_num(u)), axis=-1)",
             ("tests/test_rotations.py", "tests/test_documented_boundaries.py",
              "bmc_functions/rigid_body/rotations.py"),
             "get_R of opposite vectors: perpendicular from the largest component (NaN along an axis)"),
    Mutation("rigid_body/cardan.py", "\nGIMBAL_TOL = 1e-12\n", "\nGIMBAL_TOL = 1e-6\n",
             ("tests/test_angles.py", "tests/test_rotations.py", "tests/test_one_rotation_angle.py",
              "tests/test_documented_boundaries.py", "bmc_functions/rigid_body/cardan.py"),
             "gimbal lock declared at 1e-6 instead of the documented 1e-12"),
    Mutation("rigid_body/frames.py", "\nPARALLEL_RTOL = 1e-8\n", "\nPARALLEL_RTOL = 1e-4\n",
             ("tests/test_frames.py", "tests/test_documented_boundaries.py", "bmc_functions/rigid_body/frames.py"),
             "axes 1e-8..1e-4 rad apart refused as parallel (documented 1e-8)"),
    Mutation("rigid_body/clusters.py", "(noise_sd < 0).any()", "(noise_sd <= 0).any()",
             ("tests/test_clusters.py", "tests/test_documented_boundaries.py", "bmc_functions/rigid_body/clusters.py"),
             "noise_sd = 0 refused (documented: only negative)"),
    # _checks.py / batch.py / plotting.py / cli.py
    Mutation("_checks.py", "ORTHONORMAL_ATOL = 1e-6", "ORTHONORMAL_ATOL = 1e-3",
             ("tests/test_argument_checks.py", "tests/test_public_arguments.py",
              "tests/test_documented_boundaries.py", "bmc_functions/_checks.py"),
             "rotation matrices off by 1e-3 accepted as orthonormal"),
    Mutation("batch.py", '"None or a positive integer", minimum=1, integer=True)',
             '"None or a positive integer", minimum=1)',
             ("tests/test_batch.py", "tests/test_documented_boundaries.py", "bmc_functions/batch.py"),
             "map_trials accepts workers=2.5"),
    Mutation("plotting.py", "tips = fitted + scale * residuals", "tips = fitted + residuals",
             ("tests/test_plotting.py", "tests/test_plotting_3d.py", "tests/test_documented_boundaries.py",
              "bmc_functions/plotting.py"),
             "plot_residuals ignores scale in the drawing"),
    Mutation("cli.py", "for stem, files in stems.items() if len(files) > 1}",
             "for stem, files in stems.items() if len(files) > 2}",
             ("tests/test_cli.py", "tests/test_documented_boundaries.py", "bmc_functions/cli.py"),
             "two trials of the same stem overwrite each other's outputs"),
    # --- a fourth blind sample, by a fourth reviewer who read the package's code alone
    # (its first run killed 15 of 24; the survivors' tests are in
    # tests/test_documented_boundaries.py)
    # files/
    Mutation("files/vsk.py", "if name in subject and subject[name] != number:",
             "if name in subject and subject[name] != subject[name]:",
             ("tests/test_files_layer.py", "tests/test_plug_in_gait_imports.py",
              "tests/test_documented_boundaries.py", "bmc_functions/files/vsk.py"),
             "a .vsk parameter given twice with different values: the last silently wins"),
    Mutation("files/_c3d_binary.py", 'PROCESSORS = {84: "<", 85: "<", 86: ">"}',
             'PROCESSORS = {84: "<", 85: ">", 86: ">"}',
             ("tests/test_files_layer.py", "tests/test_marker_io.py",
              "tests/test_documented_boundaries.py", "bmc_functions/files/_c3d_binary.py",
              "bmc_functions/files/c3d.py"),
             "DEC (processor 85) C3D integers read big-endian"),
    Mutation("files/c3d_parameters.py", "if count == 1 and len(dims) <= 1:",
             "if count == 1 and len(dims) < 1:",
             ("tests/test_files_layer.py", "tests/test_plug_in_gait_imports.py", "tests/test_marker_io.py",
              "tests/test_documented_boundaries.py", "bmc_functions/files/c3d_parameters.py"),
             "one-element C3D parameters (dims [1]) returned as arrays, not scalars"),
    Mutation("files/opensim.py", "\nMAX_TIME_STEP = 1.0\n", "\nMAX_TIME_STEP = 2.0\n",
             ("tests/test_opensim_io.py", "tests/test_files_layer.py",
              "tests/test_documented_boundaries.py", "bmc_functions/files/opensim.py"),
             "time columns in frames (steps 1-2) not recognised (documented 1 s)"),
    # markers/
    Mutation("markers/tracking.py", "if singular_values[1] <= COLLINEAR_RTOL * singular_values[0]:",
             "if singular_values[2] <= COLLINEAR_RTOL * singular_values[0]:",
             ("tests/test_tracking.py", "tests/test_documented_boundaries.py",
              "bmc_functions/markers/tracking.py"),
             "a coplanar cluster refused as collinear (wrong singular value)"),
    Mutation("markers/gap_filling.py", "R[outlier[gap_frames]] = np.nan",
             "R[outlier[gap_frames]] = R[outlier[gap_frames]]",
             ("tests/test_gap_filling.py", "tests/test_zero_gaps.py",
              "tests/test_documented_boundaries.py", "bmc_functions/markers/gap_filling.py"),
             "gaps filled from outlier (deformed-cluster) frames"),
    Mutation("markers/roles.py", "if len(set(value)) != len(value):",
             "if len(set(value)) != len(set(value)):",
             ("tests/test_marker_roles.py", "tests/test_documented_boundaries.py",
              "bmc_functions/markers/roles.py"),
             "a cluster naming the same marker twice accepted"),
    Mutation("markers/roles.py", "for label, roles in owners.items() if len(roles) > 1}",
             "for label, roles in owners.items() if len(roles) > 2}",
             ("tests/test_marker_roles.py", "tests/test_documented_boundaries.py",
              "bmc_functions/markers/roles.py"),
             "one label mapped to two roles accepted"),
    # models/
    Mutation("models/segments.py", "local[..., 2] *= sign", "local[..., 1] *= sign",
             ("tests/test_segments.py", "tests/test_lower_limb.py",
              "tests/test_documented_boundaries.py", "bmc_functions/models/segments.py"),
             "Harrington hip centre: left side mirrored on the wrong axis"),
    Mutation("models/segments.py", 'up = sign * cross_rows(np.moveaxis(points["mt5"] - heel, -1, 0),',
             'up = cross_rows(np.moveaxis(points["mt5"] - heel, -1, 0),',
             ("tests/test_segments.py", "tests/test_lower_limb.py",
              "tests/test_documented_boundaries.py", "bmc_functions/models/segments.py"),
             "foot frame from mt5: left foot not mirrored"),
    Mutation("models/plug_in_gait/lower_body.py", "DAVIS_BETA = 0.314", "DAVIS_BETA = 0.214",
             ("tests/test_plug_in_gait.py", "tests/test_plug_in_gait_variants.py",
              "tests/test_documented_boundaries.py", "bmc_functions/models/plug_in_gait"),
             "Davis hip-centre beta 0.214 rad instead of the documented 0.314 (18 deg)"),
    Mutation("models/lower_limb_checks.py", "JOINT_LINE_TILT_DEG = 35.0", "JOINT_LINE_TILT_DEG = 45.0",
             ("tests/test_lower_limb_checks.py", "tests/test_lower_limb.py",
              "tests/test_documented_boundaries.py", "bmc_functions/models/lower_limb_checks.py"),
             "joint-line tilt warning at 45 deg instead of the documented 35"),
    # gait/
    Mutation("gait/cycles.py", 'row["cadence"] = 120.0 / stride_time',
             'row["cadence"] = 60.0 / stride_time',
             ("tests/test_gait_cycles.py", "tests/test_gait_units_and_boundaries.py",
              "tests/test_documented_boundaries.py", "bmc_functions/gait/cycles.py"),
             "cadence in strides/min instead of steps/min"),
    Mutation("gait/cycles.py", 'else 100 - 100 * row["swing_time"] / stride_time)',
             'else 100 * row["swing_time"] / stride_time)',
             ("tests/test_gait_cycles.py", "tests/test_gait_units_and_boundaries.py",
              "tests/test_documented_boundaries.py", "bmc_functions/gait/cycles.py"),
             "stance % from swing time: the swing % reported as stance"),
    Mutation("gait/cycles.py", "steps = np.diff(merged)[mine[1:] & ~mine[:-1]]",
             "steps = np.diff(merged)[~mine[1:] & mine[:-1]]",
             ("tests/test_gait_cycles.py", "tests/test_gait_units_and_boundaries.py",
              "tests/test_documented_boundaries.py", "bmc_functions/gait/cycles.py"),
             "step time of one side measured to the other side's strike"),
    Mutation("gait/events.py", "VERTICAL_TILT_DEG = 30.0", "VERTICAL_TILT_DEG = 20.0",
             ("tests/test_gait_events.py", "tests/test_gait_data.py",
              "tests/test_documented_boundaries.py", "bmc_functions/gait/events.py"),
             "lab vertical snapped only within 20 deg (documented 30)"),
    Mutation("gait/events.py", "TURN_DEG = 45.0", "TURN_DEG = 60.0",
             ("tests/test_gait_events.py", "tests/test_gait_data.py",
              "tests/test_documented_boundaries.py", "bmc_functions/gait/events.py"),
             "turning-trial warning at 60 deg (documented 45)"),
    # rigid_body/
    Mutation("rigid_body/cardan.py",
             "a = np.where(locked, 0.0, np.arctan2(-e * R[..., j, k], R[..., k, k]))",
             "a = np.where(locked, 0.0, np.arctan2(e * R[..., j, k], R[..., k, k]))",
             ("tests/test_angles.py", "tests/test_rotations.py", "tests/test_one_rotation_angle.py",
              "tests/test_documented_boundaries.py", "bmc_functions/rigid_body/cardan.py"),
             "Cardan first angle sign flipped (zero-first branch: extrinsic)"),
    Mutation("rigid_body/rotations.py", "x[..., 1] * y[..., 1] + x[..., 2] * y[..., 2]",
             "x[..., 1] * y[..., 1] + x[..., 2] * y[..., 1]",
             ("tests/test_rotations.py", "tests/test_rigid_body.py",
              "tests/test_documented_boundaries.py", "bmc_functions/rigid_body/rotations.py"),
             "_dot uses the wrong z component"),
    Mutation("rigid_body/rotations.py", "np.abs(v[..., 1])), np.abs(v[..., 2]))",
             "np.abs(v[..., 1])), np.abs(v[..., 1]))",
             ("tests/test_rotations.py", "tests/test_rigid_body.py",
              "tests/test_documented_boundaries.py", "bmc_functions/rigid_body/rotations.py"),
             "unit_vectors scale ignores z: vectors along z refused as zero"),
    Mutation("rigid_body/motion.py", 'if frame == "lab":',
             'if frame == "local":',
             ("tests/test_motion.py", "tests/test_documented_boundaries.py",
              "bmc_functions/rigid_body/motion.py"),
             "angular velocity in the lab frame computed as the local one"),
    Mutation("rigid_body/motion.py", 's = s + np.einsum("...i,...i->...", point - s, n)[..., None] * n',
             's = s + np.einsum("...i,...i->...", s - point, n)[..., None] * n',
             ("tests/test_motion.py", "tests/test_documented_boundaries.py",
              "bmc_functions/rigid_body/motion.py"),
             "helical axis point: projection towards `point` with the wrong sign"),
    # _checks.py / cli.py
    Mutation("_checks.py", "number > maximum)", "number >= maximum)",
             ("tests/test_argument_checks.py", "tests/test_public_arguments.py",
              "tests/test_documented_boundaries.py", "bmc_functions/_checks.py"),
             "check_scalar's maximum becomes exclusive"),
    Mutation("cli.py", 'print("error: no trial to run", file=sys.stderr)\n        return 1',
             'print("error: no trial to run", file=sys.stderr)\n        return 0',
             ("tests/test_cli.py", "tests/test_documented_boundaries.py", "bmc_functions/cli.py"),
             "no trial to run exits with status 0"),
]


def apply(mutation, root):
    path = root / "bmc_functions" / mutation.file
    text = path.read_text(encoding="utf-8")
    count = text.count(mutation.original)
    if count != 1:
        raise ValueError(f"{mutation.file}: the original text of '{mutation.what}' is found "
                         f"{count} times; expected once: {mutation.original!r}")
    path.write_text(text.replace(mutation.original, mutation.mutant), encoding="utf-8")
    return path, text


def run(mutation, root):
    """True when the tests catch the mutation (they fail)."""
    path, text = apply(mutation, root)
    try:
        env = dict(os.environ, PYTHONPATH=str(root))
        result = subprocess.run(
            [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:randomly",
             "-o", "addopts=-p no:cacheprovider --doctest-modules", *mutation.tests],
            cwd=root, env=env, capture_output=True, text=True)
        return result.returncode != 0
    finally:
        path.write_text(text, encoding="utf-8")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--list", action="store_true", help="list the mutations only")
    args = parser.parse_args(argv)
    if args.list:
        for k, mutation in enumerate(MUTATIONS, 1):
            print(f"{k:2d}. {mutation.file}: {mutation.what}")
        return 0
    with tempfile.TemporaryDirectory() as scratch:
        root = Path(scratch) / "repo"
        shutil.copytree(ROOT, root, ignore=shutil.ignore_patterns(
            ".git", ".venv", "__pycache__", "_build", "*.egg-info", "node_modules"))
        for mutation in MUTATIONS:        # all must apply before any runs
            path, text = apply(mutation, root)
            path.write_text(text, encoding="utf-8")
        killed = 0
        print(f"{'':3} {'result':8} {'s':>5}  mutation")
        for k, mutation in enumerate(MUTATIONS, 1):
            start = time.perf_counter()
            caught = run(mutation, root)
            killed += caught
            print(f"{k:2d}. {'killed' if caught else 'SURVIVED':8} "
                  f"{time.perf_counter() - start:5.0f}  {mutation.file}: {mutation.what}",
                  flush=True)
    print(f"{killed} of {len(MUTATIONS)} mutations killed ({100 * killed / len(MUTATIONS):.0f} %)")
    return 0 if killed == len(MUTATIONS) else 1


if __name__ == "__main__":
    sys.exit(main())
