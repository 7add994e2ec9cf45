"""Every argument of the public API, given a bad value of its kind, raises a ValueError
that names it (issue 24).

Built from :func:`inspect.signature`: each public callable has one valid call (``VALID``,
small seeded data or the package's example files); each of its parameters is classified
by kind from its name and default, and each bad value of that kind is substituted in the
valid call, one at a time:

- flags (``degrees``, ``extrinsic``, ... or a bool default): ``'False'``, ``1``, ``None``,
  ``np.array([True])``;
- choices (a str default): ``1``, ``'nonsense'``;
- numbers (an int or float default, or a named quantity): ``'a'``, ``True``, ``nan``, and
  ``-1`` where only positive values make sense;
- arrays (required numeric arguments): a string, a ragged nested list.

The expected outcome is a ValueError (:class:`~bmc_functions._checks.ArgumentTypeError`
is one) whose message names the parameter: never a bare TypeError, never numpy's or
pandas's own message, never a silent result. File paths, role mappings and event dicts
are not substituted here (their readers have tests of their own).

Written for issue 24, it found 43 cases across the package (among them
``hip_angles(I, R, degrees='False')`` returning degrees, ``side=1`` a plain ValueError for
some joints and an ArgumentTypeError for others, a bare TypeError from ``static_offset``);
each was fixed in the function's module, through ``bmc_functions._checks``.
"""

import inspect
import re
import warnings
from functools import lru_cache

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

import bmc_functions  # noqa: E402
from bmc_functions import plotting  # noqa: E402
from bmc_functions._checks import ArgumentTypeError  # noqa: E402
from bmc_functions.batch import map_trials  # noqa: E402
from bmc_functions.examples import example_file  # noqa: E402

# animate_trial's valid call is never rendered
pytestmark = pytest.mark.filterwarnings("ignore:Animation was deleted:UserWarning")

# --- small valid inputs ------------------------------------------------------------------

RNG = np.random.default_rng(24)
FRAMES = 6
A4 = np.array([[0.0, 0, 0], [100, 0, 0], [0, 60, 0], [20, 30, 80]])
R_SET = (bmc_functions.rot_z([0.0, 0.4, 0.0, -0.4, 0.0, 0.2])  # a star arc: two planes
         @ bmc_functions.rot_x([0.0, 0.0, 0.4, 0.0, -0.4, 0.3]))
T_SET = RNG.normal(0, 10, (FRAMES, 3))
CLUSTER_1 = np.broadcast_to(A4[:3], (FRAMES, 3, 3)) + RNG.normal(0, 0.01, (FRAMES, 3, 3))
CLUSTER_2 = np.einsum("fij,nj->fni", R_SET, A4[1:] + [0, -300, 0])
RASIS, LASIS = np.array([0.0, 1000, 120]), np.array([0.0, 1000, -120])
RPSIS, LPSIS = np.array([-160.0, 1000, 45]), np.array([-160.0, 1000, -45])
HIP = np.array([-50.0, 920, 85])
LAT_EP, MED_EP = np.array([0.0, 500, 130]), np.array([0.0, 500, 40])
LAT_MAL, MED_MAL = np.array([-10.0, 80, 120]), np.array([5.0, 90, 50])
HEEL, TOE = np.array([-60.0, 40, 85]), np.array([150.0, 20, 90])
SIGNAL_TIME = np.arange(0, 3.01, 0.01)
SIGNAL = np.sin(2 * np.pi * SIGNAL_TIME)
EVENTS = {"right": {"heel_strike": np.array([0.1, 1.1, 2.2]),
                    "toe_off": np.array([0.72, 1.76])}}
GAIT_ROLES = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
              "RHEEL": "RHEE", "RTOE": "RTOE", "LHEEL": "LHEE", "LTOE": "LTOE"}


def keypoint_trial():
    """Four frames of a standing body25b pose (m, y up): a valid keypoint_angles trial."""
    pose = {"RHip": (-0.1, 0.9, 0), "LHip": (0.1, 0.9, 0), "Neck": (0, 1.45, 0),
            "RKnee": (-0.1, 0.5, 0.08), "RAnkle": (-0.1, 0.1, 0), "LKnee": (0.1, 0.5, 0.05),
            "LAnkle": (0.1, 0.1, 0), "RShoulder": (-0.18, 1.4, 0), "LShoulder": (0.18, 1.4, 0),
            "RElbow": (-0.2, 1.12, 0), "RWrist": (-0.2, 1.0, 0.2)}
    values = np.ravel(list(pose.values())) + RNG.normal(0, 1e-3, (4, 3 * len(pose)))
    df = pd.DataFrame(values, index=np.arange(4) / 60.0,
                      columns=pd.MultiIndex.from_product([pose, ["x", "y", "z"]]))
    df.attrs["units"] = "m"
    return df


def quiet(call, /, *args, **kwargs):
    """Call `call` with its warnings silenced (the valid inputs are small and rough)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return call(*args, **kwargs)


@lru_cache(maxsize=None)
def marker_roles():
    return bmc_functions.read_marker_mapping(example_file("markers/markers.toml"))


@lru_cache(maxsize=None)
def lower_limb_model():
    return quiet(bmc_functions.calibrate_lower_limb, example_file("markers/static.trc"),
                 marker_roles())


@lru_cache(maxsize=None)
def plug_in_gait_model():
    return quiet(bmc_functions.plug_in_gait, example_file("plug_in_gait/Static_trial.c3d"),
                 example_file("plug_in_gait/Test.vsk"))


@lru_cache(maxsize=None)
def gait_trial():
    return bmc_functions.read_trc(example_file("gait/walk.trc"))


@lru_cache(maxsize=None)
def angles_table():
    """A pipeline angles DataFrame (deg, MultiIndex columns) of the example walk."""
    return quiet(lower_limb_model().angles, example_file("markers/walk.trc"))


@lru_cache(maxsize=None)
def residuals():
    return bmc_functions.residual_analysis(100 * SIGNAL + RNG.normal(0, 2, SIGNAL.size),
                                           rate=100)


def skeleton():
    return bmc_functions.Skeleton.default()


def tpose_angles():
    return bmc_functions.pose_to_angles(skeleton().tpose(), skeleton())


def marker_frame():
    """A TRC-like DataFrame of two markers over three frames."""
    columns = pd.MultiIndex.from_product([["RTH1", "RTH2"], ["x", "y", "z"]])
    return pd.DataFrame(RNG.normal(0, 100, (3, 6)), columns=columns,
                        index=pd.Index([0.0, 0.01, 0.02], name="time"))


def figure_3d():
    return plt.figure().add_subplot(projection="3d")


def zero_loads():
    """An external-loads table with one unloaded foot over 2 s (valid: nothing to assign)."""
    columns = [f"R_ground_{kind}{axis}" for kind in ("force_v", "force_p", "torque_")
               for axis in "xyz"]
    return pd.DataFrame(0.0, columns=columns, index=pd.Index(np.arange(200) / 100, name="time"))


def chain_arrays():
    """A two-segment chain at rest for inverse_dynamics: R, com, joint, mass, inertia."""
    R = np.repeat(np.eye(3)[None], FRAMES, axis=0)
    return dict(R=[R, R], com=[np.zeros((FRAMES, 3))] * 2, joint=[np.ones((FRAMES, 3))] * 2,
                mass=[1.0, 2.0], inertia=[np.eye(3) * 0.01] * 2)


def cycles_table():
    """Time-normalised cycles as plot_gait_cycles takes them (joint, side, angle)."""
    return bmc_functions.normalize_by_side(angles_table(), {"right": {"heel_strike": np.array(
        [0.0, 1.0])}, "left": {"heel_strike": np.array([0.0, 1.0])}}, n_points=11)


# name -> (callable, keyword arguments of one valid call). Methods are looked up on the
# object the valid call builds.
VALID = {
    "align_times": lambda: (bmc_functions.align_times, dict(
        df=pd.DataFrame({"a": [1.0, 2, 3]}, index=[0.0, 0.007, 0.013]),
        times=pd.DataFrame({"a": [1.0, 2, 3]}, index=np.arange(3) / 150),
        tolerance=0.005)),
    "angles_to_pose": lambda: (bmc_functions.angles_to_pose,
                               dict(result=tpose_angles(), skeleton=skeleton())),
    "angular_velocity": lambda: (bmc_functions.angular_velocity, dict(R=R_SET, rate=100.0)),
    "ankle_angles": lambda: (bmc_functions.ankle_angles,
                             dict(R_shank=R_SET, R_foot=R_SET[::-1])),
    "calibrate_cluster": lambda: (bmc_functions.calibrate_cluster,
                                  dict(cluster_static=A4, landmarks_static=[[15, 5, -100]])),
    "calibrate_lower_limb": lambda: (bmc_functions.calibrate_lower_limb, dict(
        static=example_file("markers/static.trc"), markers=marker_roles())),
    "compare_events": lambda: (bmc_functions.compare_events, dict(
        detected=EVENTS, reference=EVENTS)),
    "compose": lambda: (bmc_functions.compose, dict(angles=[[0.1, 0.2, 0.3]])),
    "corrected_cutoff": lambda: (bmc_functions.corrected_cutoff, dict(cutoff=6.0, rate=150.0)),
    "decompose": lambda: (bmc_functions.decompose, dict(R=R_SET)),
    "derivative": lambda: (bmc_functions.derivative, dict(data=SIGNAL, rate=100.0)),
    "elemental_rotation": lambda: (bmc_functions.elemental_rotation,
                                   dict(axis="x", angle=[0.1, 0.2])),
    "inverse_dynamics": lambda: (bmc_functions.inverse_dynamics,
                                 dict(chain_arrays(), rate=100.0)),
    "segment_inertia": lambda: (bmc_functions.segment_inertia, dict(
        proximal=T_SET, distal=T_SET + [0, -400, 0], body_mass=70.0, segment="shank")),
    "segment_motion": lambda: (bmc_functions.segment_motion,
                               dict(R=R_SET, com=T_SET, rate=100.0)),
    "segment_parameters": lambda: (bmc_functions.segment_parameters,
                                   dict(parameters={"thigh": {"mass": 0.1}})),
    "ensemble": lambda: (bmc_functions.ensemble, dict(cycles=[[0.0, 1.0], [2.0, 3.0]])),
    "expected_orientation_error": lambda: (bmc_functions.expected_orientation_error,
                                           dict(markers=A4, noise_sd=0.5)),
    "fill_gaps_rigid": lambda: (bmc_functions.fill_gaps_rigid, dict(markers=CLUSTER_2)),
    "foot_frame": lambda: (bmc_functions.foot_frame, dict(
        heel=HEEL, toe=TOE, lateral_malleolus=LAT_MAL, medial_malleolus=MED_MAL)),
    "read_force_plates": lambda: (bmc_functions.read_force_plates, dict(
        path=example_file("plug_in_gait/Movement_trial.c3d"))),
    "resample_force_plates": lambda: (bmc_functions.resample_force_plates, dict(
        plates=bmc_functions.read_force_plates(
            example_file("plug_in_gait/Movement_trial.c3d")))),
    "assign_plates": lambda: (bmc_functions.assign_plates, dict(
        plates=bmc_functions.read_force_plates(example_file("plug_in_gait/Movement_trial.c3d")),
        trial=bmc_functions.read_c3d(example_file("plug_in_gait/Movement_trial.c3d")),
        feet={"right": ["RHEE", "RTOE"], "left": ["LHEE", "LTOE"]})),
    "force_plate_events": lambda: (bmc_functions.force_plate_events, dict(
        path=example_file("plug_in_gait/Movement_trial.c3d"),
        markers={"RHEEL": "RHEE", "RTOE": "RTOE", "LHEEL": "LHEE", "LTOE": "LTOE"})),
    "frame_from_axes": lambda: (bmc_functions.frame_from_axes,
                                dict(primary=[1.0, 0, 0], secondary=[0.0, 1, 0.1])),
    "frame_from_points": lambda: (bmc_functions.frame_from_points, dict(
        origin=[0.0, 0, 0], primary_point=[1.0, 0, 0], secondary_point=[0.0, 1, 0.1])),
    "functional_axis": lambda: (bmc_functions.functional_axis,
                                dict(markers_1=CLUSTER_1, markers_2=CLUSTER_2)),
    "functional_joint_centre": lambda: (bmc_functions.functional_joint_centre,
                                        dict(markers_1=CLUSTER_1, markers_2=CLUSTER_2)),
    "gait_profile_score": lambda: (bmc_functions.gait_profile_score, dict(
        cycles=cycles_table(), normative=bmc_functions.normative_data(cycles_table()))),
    "gait_events": lambda: (bmc_functions.gait_events,
                            dict(dynamic=gait_trial(), markers=GAIT_ROLES)),
    "get_R": lambda: (bmc_functions.get_R, dict(A=[1.0, 0, 0], B=[0.0, 1, 0])),
    "helical_axes": lambda: (bmc_functions.helical_axes, dict(R=R_SET, t=T_SET, step=2)),
    "helical_axis": lambda: (bmc_functions.helical_axis, dict(
        R1=R_SET[0], t1=T_SET[0], R2=R_SET[-1], t2=T_SET[-1])),
    "hip_angles": lambda: (bmc_functions.hip_angles,
                           dict(R_pelvis=R_SET, R_thigh=R_SET[::-1])),
    "hip_joint_centre": lambda: (bmc_functions.hip_joint_centre, dict(
        rasis=RASIS, lasis=LASIS, rpsis=RPSIS, lpsis=LPSIS)),
    "keypoint_angles": lambda: (bmc_functions.keypoint_angles,
                                dict(trial=keypoint_trial(), keypoints="body25b")),
    "knee_angles": lambda: (bmc_functions.knee_angles,
                            dict(R_thigh=R_SET, R_shank=R_SET[::-1])),
    "lower_limb_angles": lambda: (bmc_functions.lower_limb_angles, dict(
        static=example_file("markers/static.trc"),
        dynamic=example_file("markers/walk.trc"), markers=marker_roles(),
        progress=False)),
    "lower_limb_kinetics": lambda: (bmc_functions.lower_limb_kinetics, dict(
        static=example_file("markers/static.trc"),
        dynamic=example_file("markers/walk.trc"), markers=marker_roles(),
        forces=zero_loads(), body_mass=70.0, progress=False)),
    "lowpass": lambda: (bmc_functions.lowpass, dict(data=SIGNAL, cutoff=6.0, rate=100.0)),
    "normalize_by_side": lambda: (bmc_functions.normalize_by_side, dict(
        signal=angles_table(), events={side: {"heel_strike": np.array([0.0, 1.0])}
                                       for side in ("right", "left")})),
    "normative_data": lambda: (bmc_functions.normative_data, dict(cycles=cycles_table())),
    "opensim_coordinates": lambda: (bmc_functions.opensim_coordinates,
                                    dict(angles=angles_table())),
    "orientation_error_covariance": lambda: (bmc_functions.orientation_error_covariance,
                                             dict(markers=A4, noise_sd=0.5)),
    "pelvis_angles": lambda: (bmc_functions.pelvis_angles, dict(R_pelvis=R_SET)),
    "pelvis_frame": lambda: (bmc_functions.pelvis_frame, dict(
        rasis=RASIS, lasis=LASIS, rpsis=RPSIS, lpsis=LPSIS)),
    "plug_in_gait": lambda: (bmc_functions.plug_in_gait, dict(
        static=example_file("plug_in_gait/Static_trial.c3d"),
        subject=example_file("plug_in_gait/Test.vsk"))),
    "pose_to_angles": lambda: (bmc_functions.pose_to_angles,
                               dict(positions=skeleton().tpose(), skeleton=skeleton())),
    "reconstruct_landmarks": lambda: (bmc_functions.reconstruct_landmarks, dict(
        cluster_local=A4 - A4.mean(axis=0), landmarks_local=[[0.0, 0, -100]],
        cluster_dynamic=[A4 + 5.0])),
    "residual_analysis": lambda: (bmc_functions.residual_analysis,
                                  dict(data=SIGNAL, rate=100.0)),
    "rot_x": lambda: (bmc_functions.rot_x, dict(angle=0.3)),
    "rot_y": lambda: (bmc_functions.rot_y, dict(angle=0.3)),
    "rot_z": lambda: (bmc_functions.rot_z, dict(angle=0.3)),
    "rotation_angle": lambda: (bmc_functions.rotation_angle, dict(R=R_SET)),
    "shank_frame": lambda: (bmc_functions.shank_frame, dict(
        lateral_epicondyle=LAT_EP, medial_epicondyle=MED_EP, lateral_malleolus=LAT_MAL,
        medial_malleolus=MED_MAL)),
    "spatiotemporal_parameters": lambda: (bmc_functions.spatiotemporal_parameters,
                                          dict(events=EVENTS)),
    "sphere_fit_centre": lambda: (bmc_functions.sphere_fit_centre,
                                  dict(markers_1=CLUSTER_1, markers_2=CLUSTER_2)),
    "stride_table": lambda: (bmc_functions.stride_table, dict(events=EVENTS)),
    "svdt": lambda: (bmc_functions.svdt, dict(A=A4, B=A4 + 1.0, order="row")),
    "thigh_frame": lambda: (bmc_functions.thigh_frame, dict(
        hip_centre=HIP, lateral_epicondyle=LAT_EP, medial_epicondyle=MED_EP)),
    "time_normalize": lambda: (bmc_functions.time_normalize, dict(
        signal=SIGNAL, heel_strikes=[0.5, 1.5, 2.5], time=SIGNAL_TIME, n_points=5)),
    "write_c3d": lambda: (bmc_functions.write_c3d, dict(
        trial=example_file("plug_in_gait/Movement_trial.c3d"))),
    "write_mot": lambda: (bmc_functions.write_mot, dict(df=angles_table().iloc[:3])),
    "write_normative_data": lambda: (bmc_functions.write_normative_data, dict(
        normative=bmc_functions.normative_data(cycles_table()))),
    "write_trc": lambda: (bmc_functions.write_trc, dict(df=marker_frame(), rate=100.0,
                                                        units="mm")),
    # methods of the public classes
    "PlugInGait.angles": lambda: (plug_in_gait_model().angles, dict(
        dynamic=example_file("plug_in_gait/Movement_trial.c3d"))),
    "PlugInGait.kinetics": lambda: (plug_in_gait_model().kinetics, dict(
        dynamic=example_file("plug_in_gait/Movement_trial.c3d"))),
    "PlugInGait.thoracohumeral_angles": lambda: (plug_in_gait_model().thoracohumeral_angles,
                                                 dict(dynamic=example_file(
                                                     "plug_in_gait/Movement_trial.c3d"))),
    "LowerLimbModel.kinetics": lambda: (lower_limb_model().kinetics, dict(
        dynamic=example_file("markers/walk.trc"), forces=zero_loads(), body_mass=70.0)),
    "Skeleton.tpose": lambda: (skeleton().tpose, dict()),
    "JointCentre.locate": lambda: (bmc_functions.functional_joint_centre(
        CLUSTER_1, CLUSTER_2).locate, dict(markers=CLUSTER_1)),
    # plotting (bmc_functions.plotting)
    "plotting.plot_angles": lambda: (plotting.plot_angles, dict(angles=angles_table())),
    "plotting.plot_gait_cycles": lambda: (plotting.plot_gait_cycles,
                                          dict(cycles=cycles_table())),
    "plotting.plot_frames_row": lambda: (plotting.plot_frames_row, dict(R=R_SET[:2])),
    "plotting.draw_frame": lambda: (plotting.draw_frame, dict(ax=figure_3d())),
    "plotting.draw_vector": lambda: (plotting.draw_vector, dict(ax=figure_3d(),
                                                                v=[1.0, 0, 0])),
    "plotting.plot_trial_3d": lambda: (plotting.plot_trial_3d,
                                       dict(markers=marker_frame())),
    "plotting.animate_trial": lambda: (plotting.animate_trial, dict(markers=marker_frame())),
    "plotting.set_lab_view": lambda: (plotting.set_lab_view, dict(ax=figure_3d())),
    "plotting.plot_residual_analysis": lambda: (plotting.plot_residual_analysis,
                                                dict(result=residuals())),
    # the batch runner of the pipelines (bmc_functions.batch, documented)
    "batch.map_trials": lambda: (map_trials, dict(function=abs, items=[-1, 2])),
}

#: Public names with no argument of the kinds tested here: result containers built by the
#: package (their fields are not user input), file readers and writers of paths, and
#: callables whose only arguments are mappings or files.
NOT_SUBSTITUTED = {
    "GaitProfile", "HelicalAxis", "JointAxis", "JointCentre", "JointLoads", "LowerLimbModel",
    "PlugInGait", "SegmentMotion", "SegmentParameters",
    "PlugInGaitTrack", "PoseAngles", "ResidualAnalysis", "Skeleton", "read_c3d",
    "read_c3d_model_outputs", "read_c3d_parameters", "read_events", "read_marker_mapping",
    "read_mot", "read_normative_data", "read_trc", "read_vsk", "write_events",
}

# --- kinds of parameters -----------------------------------------------------------------

FLAGS = {"degrees", "extrinsic", "return_mask", "static_offset", "zeros_as_gaps",
         "progress", "in_degrees", "sd", "reference", "equal", "connect"}
#: Quantities that must be positive (-1 is refused too).
POSITIVE = {"rate", "cutoff", "noise_sd", "tolerance", "threshold", "min_contact",
            "n_points", "max_gap", "step", "angle_step", "min_angle", "axis_length",
            "length", "passes", "order", "workers", "interval"}
NUMBERS = POSITIVE | {"elev", "azim", "alpha", "scale"}
#: Parameters that are not substituted: paths, mappings, objects, free text, matplotlib
#: styles, and keyword catch-alls.
OTHER = {"path", "markers", "events", "detected", "reference_events", "static", "dynamic",
         "subject", "skeleton", "result", "ax", "df", "times", "signal", "angles_df",
         "label", "title", "titles", "labels", "name", "figsize", "color", "colors",
         "linestyle", "marker", "reference_label", "float_format", "units", "columns",
         "client", "functional_trial", "knee_axis_trial", "sides", "trial", "frames",
         "time", "toe_offs", "toe_off", "point", "R_lab", "reference_direction",
         "view_from", "origin", "root_position", "options", "details", "kwargs",
         "cycles", "axis", "lengths", "segment", "fit_from", "cutoffs", "function",
         "items", "desc"}
#: Per callable: parameter -> kind, where the name alone misleads.
KIND_OVERRIDES = {
    ("svdt", "order"): "choice",
    ("compare_events", "reference"): "other",
    ("gait_profile_score", "normative"): "other",
    ("write_normative_data", "normative"): "other",
    ("plotting.plot_gait_cycles", "reference"): "other",
    ("plotting.plot_gait_cycles", "cycles"): "other",
    ("plotting.plot_frames_row", "R"): "array",
    ("plotting.plot_angles", "angles"): "other",
    ("opensim_coordinates", "angles"): "other",
    ("elemental_rotation", "axis"): "choice",
    ("ensemble", "cycles"): "array",
    ("time_normalize", "time"): "array",
    ("time_normalize", "signal"): "array",
    ("time_normalize", "toe_offs"): "array",
    ("align_times", "tolerance"): "number",
    ("LowerLimbModel.kinetics", "forces"): "other",          # a path or a table: tested
    ("LowerLimbModel.kinetics", "force_cutoff"): "number",   # in test_lower_limb_kinetics
    ("lower_limb_kinetics", "forces"): "other",
    ("lower_limb_kinetics", "force_cutoff"): "number",
    **{(callable_name, name): "array" for callable_name, name in [
        ("fill_gaps_rigid", "reference"), ("fill_gaps_rigid", "markers"),
        ("expected_orientation_error", "markers"), ("orientation_error_covariance", "markers"),
        ("foot_frame", "mt5"), ("frame_from_points", "origin"),
        ("functional_axis", "reference_direction"), ("helical_axes", "point"),
        ("helical_axis", "point"), ("pelvis_angles", "R_lab"),
        ("Skeleton.tpose", "root_position"), ("JointCentre.locate", "markers"),
        ("residual_analysis", "cutoffs"), ("plotting.draw_frame", "R"),
        ("plotting.draw_frame", "origin"), ("plotting.draw_vector", "origin"),
        ("plotting.set_lab_view", "view_from")]},
}

#: Bad values of each kind, with the error expected: a value of the wrong type raises
#: ArgumentTypeError (a TypeError that is also a ValueError), as the validators of
#: bmc_functions._checks do; a value of the right type but out of range, ValueError.
BAD = {
    "flag": [("False", ArgumentTypeError), (1, ArgumentTypeError), (None, ArgumentTypeError),
             (np.array([True]), ArgumentTypeError)],
    "choice": [(1, ArgumentTypeError), ("nonsense", ValueError)],
    "number": [("a", ArgumentTypeError), (True, ArgumentTypeError), (np.nan, ValueError)],
    "array": [("abc", ArgumentTypeError), ([[1.0, 2.0], [3.0]], ValueError)],
}


def kind_of(callable_name, parameter):
    """The kind of `parameter` (an inspect.Parameter) of the public callable."""
    name, default = parameter.name, parameter.default
    if (callable_name, name) in KIND_OVERRIDES:
        return KIND_OVERRIDES[callable_name, name]
    if parameter.kind in (parameter.VAR_KEYWORD, parameter.VAR_POSITIONAL) or name in OTHER:
        return "other"
    if name in FLAGS or isinstance(default, (bool, np.bool_)):
        return "flag"
    if name in NUMBERS:
        return "number"
    if isinstance(default, str):
        return "choice"
    if isinstance(default, (int, float)):
        return "number"
    if default is parameter.empty:
        return "array"
    return "other"


def bad_values(parameter, kind):
    """The bad values of `kind` for `parameter`, each with the error it must raise."""
    values = [(value, error) for value, error in BAD.get(kind, [])
              if not (value is None and parameter.default is None)]  # None: the default
    if kind == "number" and parameter.name in POSITIVE:
        values.append((-1, ValueError))
    return values


def _cases():
    cases = []
    for callable_name, make in VALID.items():
        function, _ = make()
        for parameter in inspect.signature(function).parameters.values():
            kind = kind_of(callable_name, parameter)
            for value, error in bad_values(parameter, kind):
                cases.append(pytest.param(callable_name, parameter.name, value, error,
                                          id=f"{callable_name}-{parameter.name}-{value!r}"))
        plt.close("all")
    return cases


# --- the tests ---------------------------------------------------------------------------

def test_every_public_callable_is_in_the_table():
    """A new public name must be given a valid call (or be listed as not substituted)."""
    names = set(bmc_functions.__all__)
    covered = {name for name in VALID if "." not in name} | NOT_SUBSTITUTED
    assert names - covered == set()
    functions = {name for name, value in vars(plotting).items()
                 if inspect.isfunction(value) and not name.startswith("_")
                 and value.__module__ == plotting.__name__}
    untested = {"animation_html", "plot_markers", "plot_residuals", "set_axes_equal"}
    assert functions - untested == {name.split(".")[1] for name in VALID
                                    if name.startswith("plotting.")}


@pytest.mark.parametrize("callable_name", sorted(VALID))
def test_the_valid_call_runs(callable_name, tmp_path):
    function, arguments = VALID[callable_name]()
    arguments = _with_path(function, arguments, tmp_path)
    quiet(function, **arguments)
    plt.close("all")


def _with_path(function, arguments, tmp_path):
    """Writers take a `path`: one in the test's temporary folder."""
    if "path" in inspect.signature(function).parameters and "path" not in arguments:
        arguments = dict(arguments, path=tmp_path / "out")
    return arguments


@pytest.mark.parametrize("callable_name, name, value, error", _cases())
def test_a_bad_argument_raises_a_value_error_naming_it(callable_name, name, value, error,
                                                       tmp_path):
    function, arguments = VALID[callable_name]()
    arguments = _with_path(function, dict(arguments, **{name: value}), tmp_path)
    try:
        with pytest.raises(error, match=rf"\b{re.escape(name)}\b"):
            quiet(function, **arguments)
    finally:
        plt.close("all")
