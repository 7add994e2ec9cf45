r"""Lower-limb joint angles from a lab's own marker files: static calibration, then any trial.

The applied pipeline of :mod:`~bmc_functions.markers.tracking`,
:mod:`~bmc_functions.models.segments` and :mod:`~bmc_functions.models.joints` in one call: a
static trial calibrates the landmarks in each cluster's technical frame (Cappozzo et al.
1995); in a dynamic trial every cluster is tracked with :func:`svdt`, the landmarks are put
back, the ISB segment frames built and the pelvis, hip, knee and ankle angles of both sides
returned as one DataFrame::

    model = calibrate_lower_limb("static.trc", markers)   # markers: role -> your label
    angles = model.angles("walk.trc")
    angles["knee", "right", "flexion"]                     # degrees, indexed by time (s)

Where each landmark comes from in a dynamic trial:

- a segment with a technical cluster (roles ``PELVIS``, ``RTHIGH``, ``RSHANK``,
  ``RFOOT``, ...): all its landmarks are reconstructed from the cluster;
- a segment without one: its landmarks are taken as measured in the dynamic trial (they
  must be there), the hip centre is carried by the pelvis frame, and the foot's origin
  (and, without MT5, its medio-lateral direction) comes from the shank's malleoli.
"""

import functools
import os
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pandas as pd

from .._checks import check_choice, check_flag, check_rate_attr, missing_rows, warn
from .._threads import blas_single_thread
from ..batch import check_batch_options, map_trials
from ..files.trial import MarkerTable, load_trial, mm_per_unit
from ..markers.roles import (FOOT_FRAME_ROLES, SIDE_PREFIX, check_labels, check_mapping,
                             describe, is_cluster, pelvis_roles)
from ..markers.tracking import calibrate_cluster, reconstruct_landmarks
from ..rigid_body.frames import nearest_lab_axis
from ..rigid_body.svdt import COLLINEAR_RTOL, svdt
from .functional_joints import functional_axis, functional_joint_centre
from .joints import ankle_angles, hip_angles, knee_angles, pelvis_angles
from .lower_limb_kinetics import DEFAULT_CUTOFF, model_kinetics
from .lower_limb_checks import (COLLINEAR_WARN_RATIO, DEFORM_FACTOR, DEFORM_MM, UNITS_RATIO,
                                check_dynamic_units, check_sides, check_static_geometry,
                                check_still, check_units, segment_name, warn_dynamic)
from .segments import foot_frame, hip_joint_centre, pelvis_frame, shank_frame, thigh_frame

JOINT_ANGLES = {"pelvis": ("tilt", "obliquity", "rotation"),
                "hip": ("flexion", "adduction", "rotation"),
                "knee": ("flexion", "adduction", "rotation"),
                "ankle": ("dorsiflexion", "inversion", "rotation")}


#: Order of the angle names in the columns' third level: each joint's three angles come
#: in increasing order, so that the columns are lexsorted in the order of JOINT_ANGLES
#: (selecting ``angles['knee', 'right']`` then needs no sort and gives no warning).
_ANGLE_ORDER = ("tilt", "obliquity", "flexion", "adduction", "dorsiflexion", "inversion",
                "rotation")


def _column_index(columns):
    """MultiIndex (joint, side, angle) of `columns` that keeps their order, lexsorted."""
    levels = [list(JOINT_ANGLES), ["right", "left"], list(_ANGLE_ORDER)]
    codes = [[level.index(column[k]) for column in columns]
             for k, level in enumerate(levels)]
    return pd.MultiIndex(levels=levels, codes=codes, names=["joint", "side", "angle"])


# --- the model ---------------------------------------------------------------------------

class _Poses(NamedTuple):
    """What :meth:`LowerLimbModel.track` finds before the angles: as
    :class:`LowerLimbKinematics` (`rmse`, `frames`, `landmarks`, `lab_frame`), the frames
    check_sides flags (`mirrored`: every angle NaN; `crossed`: the legs'), the units of
    the trial's markers and their MarkerTable (the kinetics reads it again)."""

    rmse: pd.DataFrame
    frames: dict
    landmarks: dict
    lab_frame: np.ndarray
    mirrored: np.ndarray
    crossed: np.ndarray
    units: object
    table: object = None


@dataclass
class LowerLimbKinematics:
    """What one dynamic trial gives: angles and everything needed to check them.

    Attributes
    ----------
    angles : pandas.DataFrame
        As :meth:`LowerLimbModel.angles`.
    rmse : pandas.DataFrame
        svdt RMSE (mm, per coordinate: distance/sqrt(3) for isotropic residuals) of each
        cluster per frame, one column per cluster role, indexed by time.
    frames : dict
        (segment, side) -> (R, origin): rotation matrices (frames, 3, 3), columns the
        segment's x, y, z axes in the lab, and origins (frames, 3) in mm. The pelvis has
        side None.
    landmarks : dict
        (segment, side) -> {role: (frames, 3) positions in mm} as used for the frames.
    lab_frame : ndarray, shape (3, 3)
        Columns: the direction of progression, the vertical and the right-hand
        horizontal, in the lab's coordinates (for the pelvis angles).
    """

    angles: pd.DataFrame
    rmse: pd.DataFrame
    frames: dict
    landmarks: dict
    lab_frame: np.ndarray


@dataclass
class LowerLimbModel:
    """A calibrated lower-limb model: made by :func:`calibrate_lower_limb`.

    Attributes
    ----------
    markers : dict
        The checked role -> label(s) mapping.
    sides : tuple of str
        The sides computed.
    hip_centre : str
        The hip-centre method.
    knee_axis : str
        'epicondyles' or 'functional': where the thigh frame's medio-lateral axis comes
        from.
    static_offset : bool
        Whether :meth:`angles` subtracts the static angles (hip, knee, ankle).
    units : str or None
        Units of the static trial's file; lengths here are always in mm.
    landmarks : pandas.DataFrame
        Calibrated landmark positions in the static trial (mean over its frames), one row
        per role (hip centres included), columns x, y, z, in mm, lab coordinates. Empty
        when there is no static trial.
    clusters : dict
        Cluster role -> dict with 'labels', 'segment', 'local' (markers in the technical
        frame, mm), 'landmark_roles' and 'landmarks_local' (mm).
    static_rmse : dict
        Cluster role -> median svdt RMSE (mm) of the cluster over the static frames.
    static_frames : dict
        (segment, side) -> (R (3, 3), origin (3,)) in the static trial.
    static_angles : pandas.Series
        The angles of the static posture (degrees, same index as the columns of
        :meth:`angles`, without offset); empty without a static trial.
    options : dict
        What a functional method found, beyond the landmarks (empty for the
        regression and the markers). With the functional options, the fits to check:
        ``'functional_hip'``, side -> :class:`~bmc_functions.JointCentre` of the hip
        trial (its `rms_distance`, `range_of_motion`, `frames_used`), and
        ``'functional_knee'``, side -> :class:`~bmc_functions.JointAxis` of the knee
        trial.

    Examples
    --------
    The example trials shipped with the package (both legs; their mapping as a file):

    >>> import warnings
    >>> from bmc_functions import calibrate_lower_limb
    >>> from bmc_functions import read_marker_mapping
    >>> from bmc_functions.examples import example_file
    >>> markers = read_marker_mapping(example_file("markers/markers.toml"))
    >>> model = calibrate_lower_limb(example_file("markers/static.trc"), markers)
    >>> model.sides, model.hip_centre, model.units
    (('right', 'left'), 'harrington', 'mm')
    >>> print(model.landmarks.loc["RHJC"].round(1).to_dict())     # Harrington, mm
    {'x': 440.8, 'y': 864.7, 'z': 286.8}
    >>> print(round(model.static_rmse["RTHIGH"], 2))                 # mm
    0.34
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")          # the trial's two occlusion gaps
    ...     result = model.track(example_file("markers/walk.trc"))
    >>> result.angles.shape, list(result.rmse.columns[:3])
    ((111, 24), ['PELVIS', 'RTHIGH', 'RSHANK'])
    """

    markers: dict
    sides: tuple
    hip_centre: str = "harrington"
    knee_axis: str = "epicondyles"
    static_offset: bool = False
    units: object = None
    landmarks: pd.DataFrame = field(default_factory=pd.DataFrame)
    clusters: dict = field(default_factory=dict)
    static_rmse: dict = field(default_factory=dict)
    static_frames: dict = field(default_factory=dict)
    static_angles: pd.Series = field(default_factory=pd.Series)
    options: dict = field(default_factory=dict)

    # -- segments and their landmarks --

    def _segments(self):
        """(segment, side) -> (cluster role or None, landmark roles)."""
        segments = {("pelvis", None): ("PELVIS" if "PELVIS" in self.markers else None,
                                       pelvis_roles(self.markers))}
        for side in self.sides:
            p = SIDE_PREFIX[side]
            foot = [p + "HEEL", p + "TOE"] + ([p + "MT5"] if p + "MT5" in self.markers else [])
            if p + "FOOT" in self.markers:
                foot += [p + "ANKLE_LAT", p + "ANKLE_MED"]
            axis = ([p + "KNEE_AXIS_LAT", p + "KNEE_AXIS_MED"]
                    if self.knee_axis == "functional" else [])
            for segment, roles in (("thigh", [p + "HJC", p + "KNEE_LAT", p + "KNEE_MED"] + axis),
                                   ("shank", [p + "KNEE_LAT", p + "KNEE_MED",
                                              p + "ANKLE_LAT", p + "ANKLE_MED"]),
                                   ("foot", foot)):
                if segment == "foot" and not self.has_foot(side):
                    continue                # no foot frame: ankle angles NaN
                cluster = p + segment.upper()
                segments[(segment, side)] = (cluster if cluster in self.markers else None,
                                             roles)
        return segments

    def has_foot(self, side):
        """Whether `side` has the heel and toe roles that its foot frame needs (without
        them, its ankle angles are NaN)."""
        p = SIDE_PREFIX[side]
        return all(p + role in self.markers for role in FOOT_FRAME_ROLES)

    def _measured_roles(self, roles):
        """The `roles` measured in a trial (a hip centre is computed, bar 'marker')."""
        return [role for role in roles if role in self.markers
                and not (role.endswith("HJC") and self.hip_centre != "marker")]

    def _inversion_measured(self, side):
        p = SIDE_PREFIX[side]
        return p + "MT5" in self.markers or p + "FOOT" in self.markers

    # -- from landmarks to angles (shared by the static and every dynamic trial) --

    def _frames(self, landmarks, pelvis=None):
        """Segment frames from {(segment, side): {role: (F, 3)}}; `pelvis`: the pelvis
        frame if already made from them (:meth:`_landmarks_in`)."""
        frames = {("pelvis", None): (self._pelvis_frame(landmarks[("pelvis", None)])
                                     if pelvis is None else pelvis)}
        for side in self.sides:
            p = SIDE_PREFIX[side]
            thigh, shank, foot = (landmarks.get((segment, side))
                                  for segment in ("thigh", "shank", "foot"))
            ends = ("KNEE_AXIS_LAT", "KNEE_AXIS_MED") if self.knee_axis == "functional" \
                else ("KNEE_LAT", "KNEE_MED")
            frames[("thigh", side)] = thigh_frame(thigh[p + "HJC"], thigh[p + ends[0]],
                                                  thigh[p + ends[1]], side=side)
            frames[("shank", side)] = shank_frame(shank[p + "KNEE_LAT"],
                                                  shank[p + "KNEE_MED"],
                                                  shank[p + "ANKLE_LAT"],
                                                  shank[p + "ANKLE_MED"], side=side)
            if foot is None:                 # no heel or toe: no foot frame
                continue
            malleoli = foot if p + "ANKLE_LAT" in foot else shank
            frames[("foot", side)] = foot_frame(foot[p + "HEEL"], foot[p + "TOE"],
                                                malleoli[p + "ANKLE_LAT"],
                                                malleoli[p + "ANKLE_MED"],
                                                mt5=foot.get(p + "MT5"), side=side)
        return frames

    def _angles(self, frames, lab_frame):
        """(frames, columns) degrees, and the column tuples."""
        columns, blocks = [], []
        R_pelvis = frames[("pelvis", None)][0]
        for joint in JOINT_ANGLES:
            for side in self.sides:
                if joint == "pelvis":
                    block = pelvis_angles(R_pelvis, side, R_lab=lab_frame, degrees=True)
                elif joint == "hip":
                    block = hip_angles(R_pelvis, frames[("thigh", side)][0], side,
                                       degrees=True)
                elif joint == "knee":
                    block = knee_angles(frames[("thigh", side)][0],
                                        frames[("shank", side)][0], side, degrees=True)
                elif ("foot", side) not in frames:
                    block = np.full(R_pelvis.shape[:-2] + (3,), np.nan)   # no foot markers
                else:
                    block = ankle_angles(frames[("shank", side)][0],
                                         frames[("foot", side)][0], side, degrees=True)
                    if not self._inversion_measured(side):
                        block[..., 1] = np.nan
                blocks.append(block)
                columns += [(joint, side, name) for name in JOINT_ANGLES[joint]]
        return np.concatenate(blocks, axis=-1), columns

    # -- dynamic trials --

    def _pelvis_frame(self, pelvis):
        """The pelvis frame (R, origin) from its landmarks {role: (F, 3)}."""
        posterior = pelvis_roles(self.markers)[2:]
        return pelvis_frame(pelvis["RASIS"], pelvis["LASIS"], pelvis[posterior[0]],
                            pelvis[posterior[-1]])

    def _landmarks_in(self, table, scale, trial_name):
        """Landmarks of every segment in every frame of a dynamic trial, RMSEs, and the
        pelvis frame if made here (None if not: it carries the hip centres)."""
        labels = table.labels
        static = not self.landmarks.empty
        landmarks, rmse, undetermined, missing = {}, {}, {}, {}
        pose = None              # the pelvis frame: made once for both hips and _frames
        segments = self._segments()
        # The pelvis first: segments without a cluster carry the hip centre in it.
        for key, (cluster, roles) in segments.items():
            segment, side = key
            if cluster is not None and static:
                check_labels(self.markers, [cluster], labels, trial_name, table.dropped)
                info = self.clusters[cluster]
                points = table.stacked(info["labels"], scale)
                with warnings.catch_warnings():
                    warnings.filterwarnings("ignore", message=".*fewer than 3 non-collinear",
                                            category=RuntimeWarning)
                    rebuilt, error = reconstruct_landmarks(info["local"],
                                                           info["landmarks_local"], points)
                rmse[cluster] = error
                undetermined[cluster] = np.isnan(error)
                landmarks[key] = {role: rebuilt[:, k]
                                  for k, role in enumerate(info["landmark_roles"])}
                continue
            found = {}
            for role in roles:
                if role.endswith("HJC") and self.hip_centre != "marker":
                    if static and pose is None:
                        pose = self._pelvis_frame(landmarks[("pelvis", None)])
                    found[role] = self._carried_hip_centre(landmarks[("pelvis", None)],
                                                           side, pose)
                    continue
                label = self.markers[role]
                if not table.has_data(label):
                    how = (f"it has no cluster ({SIDE_PREFIX.get(side, '') + segment.upper()}"
                           if segment != "pelvis" else "it has no cluster (PELVIS")
                    raise ValueError(
                        f"markers[{role!r}] = {label!r} ({describe(role)}) is not in {trial_name} "
                        f"(or is empty in every frame), and the {segment}"
                        + (f" ({side})" if side else "") + f" cannot be rebuilt without it: "
                        f"{how} in the mapping). Give the cluster and a static trial, or a "
                        f"trial that has the landmark")
                found[role] = table.points(label, scale)
            landmarks[key] = found
            measured = self._measured_roles(roles)
            # Measured landmarks: a frame that lacks one leaves the segment undetermined.
            missing[key] = {role: missing_rows(found[role]) for role in measured}
            name = "PELVIS" if segment == "pelvis" else SIDE_PREFIX[side] + segment.upper()
            if static and len(measured) >= 3 and name in self.clusters:
                # No cluster: the segment's own markers must still move as a rigid body.
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", RuntimeWarning)
                    _, _, error = svdt(self.clusters[name]["local"],
                                       table.stacked([self.markers[r] for r in measured],
                                                     scale),           # found's values
                                       order="row")
                rmse[name] = error
        return landmarks, rmse, undetermined, missing, pose

    def _carried_hip_centre(self, pelvis, side, pose):
        """Hip centre in every frame from the pelvis landmarks (and, with a static
        trial, their frame `pose`: (R, origin))."""
        if self.landmarks.empty:
            posterior = pelvis_roles(self.markers)[2:]
            return hip_joint_centre(pelvis["RASIS"], pelvis["LASIS"], pelvis[posterior[0]],
                                    pelvis[posterior[-1]], side=side)
        R, origin = pose
        R0, o0 = self.static_frames[("pelvis", None)]
        local = R0.T @ (self.landmarks.loc[SIDE_PREFIX[side] + "HJC"].to_numpy() - o0)
        return np.einsum("fij,j->fi", R, local) + origin

    def track(self, dynamic):
        """Angles, cluster RMSEs, segment frames and landmarks of a dynamic trial.

        Parameters
        ----------
        dynamic : pandas.DataFrame or path
            A trial from :func:`read_trc`/:func:`read_c3d`, or a path to a .trc or .c3d
            file, in mm, cm or m (from ``df.attrs['units']``).

        Returns
        -------
        LowerLimbKinematics
        """
        df, trial_name = load_trial(dynamic, "dynamic")
        with blas_single_thread():  # see bmc_functions._threads
            return self._track(df, trial_name)

    def _track(self, df, trial_name):
        poses = self._poses(df, trial_name)
        values, columns = self._angles(poses.frames, poses.lab_frame)
        if self.static_offset and not self.static_angles.empty:
            offset = self.static_angles.reindex(_column_index(columns)).to_numpy()
            offset = np.where([c[0] == "pelvis" for c in columns], 0.0, offset)
            values = values - offset
        values[poses.mirrored] = np.nan                  # flagged frames: see check_sides
        legs = np.array([c[0] != "pelvis" for c in columns])
        values[np.ix_(poses.crossed, legs)] = np.nan
        angles = pd.DataFrame(values, index=poses.rmse.index, columns=_column_index(columns))
        angles.attrs = {"units": "deg", "marker_units": poses.units,
                        "hip_centre": self.hip_centre, "knee_axis": self.knee_axis,
                        "static_offset": self.static_offset,
                        "pelvis_sequence": "YXZ (rotation, obliquity, tilt) relative to "
                                           "lab_frame", "lab_frame": poses.lab_frame.tolist()}
        footless = [side for side in self.sides if not self.has_foot(side)]
        if footless:
            angles.attrs["notes"] = [_no_foot_note(self, footless)]
        return LowerLimbKinematics(angles, poses.rmse, poses.frames, poses.landmarks,
                                   poses.lab_frame)

    def _poses(self, df, trial_name):
        """:meth:`track` without the angles (and their gimbal-lock warning): a
        :class:`_Poses`, with every other warning of :meth:`track`."""
        scale, units = mm_per_unit(df, trial_name)
        time = df.index.to_numpy()
        if time.dtype.kind in "iuf" and np.isfinite(time).all():
            check_rate_attr(df, time.astype(float), trial_name)
        table = MarkerTable(df, trial_name)
        if self.landmarks.empty:
            roles = [role for role in self.markers
                     if not is_cluster(role) and (role[1:] != "HJC" or
                                                  self.hip_centre == "marker")]
            check_labels(self.markers, roles, table.labels, trial_name, table.dropped)
            points = _dynamic_posture(self, table, scale, trial_name)
            check_units(self.markers, points, units, trial_name)
            hips, _ = HIP_CENTRE_METHODS[self.hip_centre](self, points, {})
            check_static_geometry(self, points, hips)
        else:
            check_dynamic_units(self, table, scale, units, trial_name)
        landmarks, rmse, undetermined, missing, pelvis = self._landmarks_in(table, scale,
                                                                            trial_name)
        mirrored, crossed = check_sides(self, table, scale, landmarks, trial_name)
        frames = self._frames(landmarks, pelvis)
        lab, off_axis, (backwards, moving) = _lab_frame(frames, deviation=True)
        if backwards:
            warn(f"the pelvis of {trial_name} faces against its direction of travel in "
                 f"{backwards} of {moving} frames (its anterior axis, from the PSISs "
                 f"to the ASISs, points back along the path): the subject walks "
                 f"backwards, the trial is time-reversed, or the ASIS and PSIS "
                 f"labels are swapped. The pelvis angles are taken relative to where "
                 f"the pelvis faces (lab_frame's x), not to the direction of travel",
                 RuntimeWarning)
        if off_axis > PROGRESSION_WARN_DEG:
            axis = "+-"[int(lab[:, 0].sum() < 0)] + "xyz"[int(np.argmax(np.abs(lab[:, 0])))]
            warn(f"the direction of progression in {trial_name} is {off_axis:.0f} degrees "
                 f"from the lab axis {axis} that the pelvis angles take as forward "
                 f"(the nearest one; warning above {PROGRESSION_WARN_DEG:.0f} "
                 f"degrees): pelvis rotation reads about {off_axis:.0f} degrees "
                 f"off (tilt and obliquity are not affected: rotation comes first "
                 f"in the sequence). Rotate the marker coordinates so that the "
                 f"walkway runs along a lab axis",
                 RuntimeWarning)
        rmse_df = pd.DataFrame(rmse, index=df.index.copy(), dtype=float)
        warn_dynamic(self, rmse_df, undetermined, trial_name, missing)
        return _Poses(rmse_df, frames, landmarks, lab, mirrored, crossed, units, table)

    def _angle_gaps(self, poses, columns):
        """The frames (bool, (frames, len(columns))) in which the angles `columns`
        ((joint, side, angle) tuples) of :meth:`track` are NaN, found without computing
        them: a Cardan decomposition is finite wherever its two segment frames are (NaN
        exactly where one is, :func:`~bmc_functions.decompose_orthonormal`), so an angle
        is NaN where a frame of its joint is, a side without a foot frame (the ankle),
        the unmeasured inversion, the frames check_sides flags (every angle mirrored, the
        legs' crossed) and a NaN static offset."""
        segments = {"pelvis": ("pelvis",), "hip": ("pelvis", "thigh"),
                    "knee": ("thigh", "shank"), "ankle": ("shank", "foot")}
        used = {(segment, None if segment == "pelvis" else side)
                for joint, side, _ in columns for segment in segments[joint]}
        missing = {key: missing_rows(poses.frames[key][0].reshape(-1, 9))
                   for key in used if key in poses.frames}
        none = np.ones(len(poses.mirrored), dtype=bool)
        offset = (self.static_angles.reindex(pd.MultiIndex.from_tuples(columns)).to_numpy()
                  if self.static_offset and not self.static_angles.empty
                  else np.zeros(len(columns)))
        gaps = []
        for k, (joint, side, angle) in enumerate(columns):
            gap = poses.mirrored | np.isnan(poses.lab_frame).any()
            for segment in segments[joint]:
                gap |= missing.get((segment, None if segment == "pelvis" else side), none)
            if joint != "pelvis":
                gap |= poses.crossed | (np.isnan(offset[k]) & np.ones_like(gap))
            if joint == "ankle" and angle == "inversion" and not self._inversion_measured(side):
                gap |= none
            gaps.append(gap)
        return np.stack(gaps, axis=1)

    def angles(self, dynamic):
        """Pelvis, hip, knee and ankle angles of a dynamic trial (degrees).

        Parameters
        ----------
        dynamic : pandas.DataFrame or path
            As :meth:`track`.

        Returns
        -------
        pandas.DataFrame
            Indexed by the trial's time (s); columns ``(joint, side, angle)``:
            ``('pelvis', side, 'tilt' | 'obliquity' | 'rotation')`` relative to the lab,
            ``('hip', side, 'flexion' | 'adduction' | 'rotation')``,
            ``('knee', side, 'flexion' | 'adduction' | 'rotation')``,
            ``('ankle', side, 'dorsiflexion' | 'inversion' | 'rotation')``. Positive:
            anterior tilt, this side up, this side forwards; flexion, adduction, internal
            rotation; dorsiflexion, inversion, internal rotation; the same on both sides.
            ``attrs`` holds the units ('deg'), the marker units of the file, the hip-centre
            method, whether the static offset was subtracted, and the pelvis sequence.
        """
        return self.track(dynamic).angles

    def kinetics(self, dynamic, forces, *, body_mass, cutoff=DEFAULT_CUTOFF,
                 force_cutoff="cutoff", parameters=None, gravity=None):
        r"""Hip, knee and ankle moments, forces and powers of a dynamic trial.

        Parameters
        ----------
        dynamic : pandas.DataFrame or path
            As :meth:`track`; it needs its sampling rate (``attrs['rate']``).
        forces : path or pandas.DataFrame
            The ground loads: an OpenSim external-loads ``.mot`` (or the DataFrame
            :func:`~bmc_functions.read_mot` gives), with per foot or per plate the
            columns ``<prefix>ground_force_v[xyz]`` (N), ``<prefix>ground_force_p[xyz]``
            (centre of pressure, m) and optionally ``<prefix>ground_torque_[xyz]`` (free
            moment, N m), in the marker trial's lab frame, prefixes such as ``R_``/``L_``
            or ``''``/``1_``; or a ``.c3d`` path, whose force plates are read
            (:func:`~bmc_functions.read_force_plates`, one load per plate). Each loaded interval is assigned to the foot standing on it
            (its centre of pressure within 150 mm of that foot's heel-toe line, and of no
            other foot's), whatever the prefix says (a contradicted ``R_``/``L_`` is
            warned about).
        body_mass : float
            kg, from 0.2 to 650 (a mass in g, lb or tonnes is refused): the segment
            masses are Dempster's fractions of it, and the results are divided by it.
        cutoff : float or None, optional
            Low-pass cut-off (Hz) of the markers, before tracking
            (:func:`~bmc_functions.lowpass`, zero-lag Butterworth); default
            ``DEFAULT_CUTOFF`` = 10 Hz; None: no filtering.
        force_cutoff : float or None, optional
            Cut-off (Hz) of the ground loads; default: the same as `cutoff`
            (Kristianslund et al. 2012: a different cut-off for markers and forces makes
            spurious moment peaks at impact). None: not filtered.
        parameters : dict, optional
            Segment-parameter overrides (:func:`~bmc_functions.segment_parameters`).
        gravity : array_like, shape (3,) or (frames, 3), optional
            m/s² in the lab; default 9.80665 down the lab's vertical (``lab_frame``).

        Returns
        -------
        pandas.DataFrame
            Indexed like :meth:`angles`; columns ``(joint, side, quantity)``: joint
            'hip', 'knee', 'ankle'; side 'right', 'left'; quantity 'moment_x',
            'moment_y', 'moment_z' (N m/kg), 'force_x', 'force_y', 'force_z' (N/kg),
            'power' (W/kg). The internal moment and the joint reaction force on the
            distal segment, in the distal segment's frame: ``moment_x`` about the
            medio-lateral axis, positive for an internal hip extensor, knee extensor and
            ankle plantarflexor moment; ``moment_y`` about the anterior axis, positive
            for a hip or knee abductor and an ankle evertor moment; ``moment_z`` about
            the long axis, positive for an external-rotator moment; ``force_x`` lateral,
            ``force_y`` anterior, ``force_z`` proximal (a standing foot's ankle force is
            negative: the shank presses on it); ``power`` positive when generated.
            In a stance without a measured load the side is NaN (one warning names the
            stances); in swing the loads are the segments' own dynamics. ``attrs``:
            units, body mass, cut-offs, gravity, the segment parameters and the load
            assignment (load, interval, side, distances).

        Raises
        ------
        ValueError
            If `body_mass` is outside 0.2 to 650 kg, the trial has no rate, `forces` is neither a
            .mot/.sto path, a .c3d path nor a DataFrame, its columns are incomplete,
            or a C3D file's plates are damaged (:func:`~bmc_functions.read_force_plates`).

        Warns
        -----
        RuntimeWarning
            Once for loads that stand under no foot alone or under the foot their prefix
            does not name; once for stances with no measured load; once for the frames
            made NaN below (a cluster that deforms, a segment that turns too far).

            Frames that the tracking flags give no kinetics, in all that depends on them
            (and in the neighbours that differentiating them needs): those whose angles it
            leaves NaN (a gap, labels swapped between the legs); those in which a cluster
            deforms (its warning; found in the unfiltered markers, whose markers are then
            taken as missing there before filtering); and those next to a turn of the
            foot, shank or thigh by more than 30 degrees from one frame to the next
            (:data:`~bmc_functions.rigid_body.motion.MAX_FRAME_ROTATION`), which no
            difference can follow.

        Notes
        -----
        Segments (Dempster via Winter 2009, Table 4.1): the foot from the ankle centre
        (mid-malleoli) to the toe marker, the shank from the knee centre (mid-epicondyles)
        to the ankle centre, the thigh from the hip centre to the knee centre. The
        Newton-Euler recursion is :func:`~bmc_functions.inverse_dynamics`'s; the joint
        power of the hip uses the pelvis' angular velocity. The tracking is
        :meth:`track`'s without the angles themselves (only where they would be NaN), and
        the unfiltered markers are fitted (the deformation test) only in the frames where
        the filtered fit does not already bound their RMSE below the threshold: the same
        result, in less time (``benchmarks/bench_lower_limb.py --kinetics``).

        References
        ----------
        .. [1] Winter DA (2009) Biomechanics and Motor Control of Human Movement, 4th ed.
           Wiley, ch. 4-5.
        .. [2] Kristianslund E, Krosshaug T, van den Bogert AJ (2012) Effect of low pass
           filtering on joint moments from inverse dynamics: implications for injury
           prevention. J Biomech 45:666-671.

        Examples
        --------
        The example walk has no force plate: with an external-loads table that measures
        nothing, its stances are NaN (and a warning names them); the swings are the
        segments' own dynamics.

        >>> import warnings
        >>> import numpy as np
        >>> import pandas as pd
        >>> from bmc_functions import calibrate_lower_limb, read_marker_mapping
        >>> from bmc_functions.examples import example_file
        >>> markers = read_marker_mapping(example_file("markers/markers.toml"))
        >>> model = calibrate_lower_limb(example_file("markers/static.trc"), markers)
        >>> columns = [f"R_ground_{kind}{axis}" for kind in ("force_v", "force_p", "torque_")
        ...            for axis in "xyz"]
        >>> loads = pd.DataFrame(0.0, columns=columns, index=np.arange(0, 1.2, 0.001))
        >>> with warnings.catch_warnings():
        ...     warnings.simplefilter("ignore")
        ...     kin = model.kinetics(example_file("markers/walk.trc"), loads, body_mass=70)
        >>> kin.shape, kin.attrs["units"]["moment"]
        ((111, 42), 'N m/kg')
        >>> list(kin["knee", "right"].columns)
        ['moment_x', 'moment_y', 'moment_z', 'force_x', 'force_y', 'force_z', 'power']
        """
        return model_kinetics(self, dynamic, forces, body_mass=body_mass, cutoff=cutoff,
                              force_cutoff=force_cutoff, parameters=parameters,
                              gravity=gravity)


# --- static trial ------------------------------------------------------------------------

def _static_points(model, table, scale, trial_name, median=False):
    """Mean (or median) position (mm) of every mapped label over the static trial."""
    out = {}
    for role, value in model.markers.items():
        for label in (value if isinstance(value, tuple) else (value,)):
            if label in out or (median and label not in table.columns):
                continue      # without a static trial, clusters are not needed
            xyz = table.points(label, scale)
            if np.isnan(xyz).any(axis=1).all():
                if median:
                    continue
                raise ValueError(f"markers[{role!r}] = {label!r} ({describe(role)}) is "
                                 f"missing (NaN) in every frame of {trial_name}")
            out[label] = np.nanmedian(xyz, axis=0) if median else np.nanmean(xyz, axis=0)
    return out


def _side_of(role):
    """'right', 'left' or None (pelvis) for a role."""
    return None if role in ("RASIS", "LASIS", "RPSIS", "LPSIS", "SACRUM", "PELVIS") \
        else {"R": "right", "L": "left"}[role[0]]


def _dynamic_posture(model, table, scale, trial_name):
    """Without a static trial, the posture the geometry checks judge: from the frames in
    which the markers it combines are seen together.

    Every mapped label with data is seen together in some frames: its median over those
    frames. Otherwise per side: the pelvis markers with one side's markers (the checks
    relate each side to the pelvis) are seen together in some frames; that side's markers
    are taken relative to the pelvis frame in those frames (median), and placed on the
    pelvis's median posture (pelvis markers seen together). A median over all frames of
    each marker apart would mix frames: the subject walks a metre between them, and a
    knee from one frame beside a pelvis from another looks like a swapped leg.
    """
    points = _static_points(model, table, scale, trial_name, median=True)
    labels = list(points)
    xyz = {label: table.points(label, scale) for label in labels}
    seen = np.stack([np.isfinite(xyz[label]).all(axis=1) for label in labels], axis=1)
    together = seen.all(axis=1)
    if together.any():
        return {label: np.median(xyz[label][together], axis=0) for label in labels}
    pelvis_labels = [model.markers[r] for r in pelvis_roles(model.markers)]
    if not all(label in points for label in pelvis_labels):
        return points                  # a pelvis landmark missing: reported downstream
    groups = {None: [], "right": [], "left": []}
    for role, value in model.markers.items():
        for label in (value if isinstance(value, tuple) else (value,)):
            if label in points and label not in pelvis_labels:
                groups[_side_of(role)].append(label)
    pelvis_seen = np.all([np.isfinite(xyz[label]).all(axis=1)
                          for label in pelvis_labels + groups[None]], axis=0)
    if not pelvis_seen.any():
        raise ValueError(f"{trial_name} (no static trial): no frame has the pelvis markers "
                         f"({', '.join(pelvis_labels + groups[None])}) all seen together; "
                         "the posture that the checks judge needs them. Give a static trial")
    out = {label: np.median(xyz[label][pelvis_seen], axis=0)
           for label in pelvis_labels + groups[None]}
    pelvis = [out[label] for label in pelvis_labels] + ([out[pelvis_labels[-1]]]
                                                        if len(pelvis_labels) == 3 else [])
    R0, o0 = pelvis_frame(*pelvis)
    for side in ("right", "left"):
        if not groups[side]:
            continue
        both = pelvis_seen & np.all([np.isfinite(xyz[label]).all(axis=1)
                                     for label in groups[side]], axis=0)
        if not both.any():
            raise ValueError(
                f"{trial_name} (no static trial): no frame has the pelvis markers and the "
                f"{side} side's markers ({', '.join(groups[side])}) all seen together; the "
                "posture that the checks judge needs them in one frame. Give a static "
                "trial, or fill the gaps first")
        frames = [xyz[label][both] for label in pelvis_labels]
        if len(frames) == 3:
            frames.append(frames[2])
        R, origin = pelvis_frame(*frames)
        for label in groups[side]:
            local = np.einsum("fji,fj->fi", R, xyz[label][both] - origin)
            out[label] = R0 @ np.median(local, axis=0) + o0
    return out


class LoadedTrial(NamedTuple):
    """A trial as the calibration steps use it: its markers, mm per unit, display name."""

    table: MarkerTable
    scale: float
    name: str


def _load(trial, what):
    """A LoadedTrial and the file's canonical units, from a DataFrame or a path."""
    df, name = load_trial(trial, what)
    scale, units = mm_per_unit(df, name)
    return LoadedTrial(MarkerTable(df, name), scale, name), units


def harrington_hip_centres(model, points, trials):
    """Harrington et al. (2007) from the static pelvis landmarks; a sacral marker stands
    for the midpoint of the PSISs (pelvis depth = mid-ASIS to the sacral marker).
    Returns ({side: (3,) mm}, fits): a regression has no fits ({})."""
    pelvis = [points[model.markers[role]] for role in pelvis_roles(model.markers)]
    if len(pelvis) == 3:
        pelvis.append(pelvis[2])
    return {side: hip_joint_centre(*pelvis, side=side) for side in model.sides}, {}


def marker_hip_centres(model, points, trials):
    """The lab's own hip-centre markers RHJC/LHJC; no fits ({})."""
    return {side: points[model.markers[SIDE_PREFIX[side] + "HJC"]]
            for side in model.sides}, {}


def _functional_clusters(model, roles, trials, what, points):
    """(frames, n, 3) arrays (mm) of cluster roles in the functional trial trials[what],
    and the trial's name; checked against the static `points` and trials['static']."""
    loaded = trials[what]
    labels = {role: (model.markers[role] if is_cluster(role) else (model.markers[role],))
              for role in roles}
    check_labels(model.markers, roles, loaded.table.labels, loaded.name, loaded.table.dropped)
    arrays = [np.stack([loaded.table.points(label, loaded.scale) for label in labels[role]],
                       axis=1)
              for role in roles]
    _check_functional_units(model, roles, labels, arrays, points, loaded.name)
    arrays = _drop_deformed(roles, labels, arrays, points, trials["static"], loaded.name)
    return arrays, loaded.name


def _drop_deformed(roles, labels, arrays, points, static, trial_name):
    """Leave out (NaN) the frames of a functional trial where a cluster does not have its
    static shape: the rule of the dynamic trials (svdt RMSE above DEFORM_MM and
    DEFORM_FACTOR times the static RMSE), one warning naming the clusters."""
    static_table, static_scale = static.table, static.scale
    bad = np.zeros(len(arrays[0]), bool)
    found = []
    for role, array in zip(roles, arrays):
        if len(labels[role]) < 3 or not all(label in points for label in labels[role]):
            continue
        shape = np.stack([points[label] for label in labels[role]])
        shape = shape - shape.mean(axis=0)
        frames = np.stack([static_table.points(label, static_scale)
                           for label in labels[role]], axis=1)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            _, _, static_rmse = svdt(shape, frames, order="row")
            _, _, rmse = svdt(shape, array, order="row")
        threshold = max(DEFORM_MM, DEFORM_FACTOR * float(np.nanmedian(static_rmse)))
        high = rmse > threshold
        if high.any():
            found.append(f"{role} ({', '.join(labels[role])}) in {int(high.sum())} frames, "
                         f"svdt RMSE up to {np.nanmax(rmse):.1f} mm (warning above "
                         f"{threshold:.1f} mm)")
            bad |= high
    if bad.any():
        warn(f"{int(bad.sum())} of {bad.size} frames of {trial_name} are left out of "
             f"the functional fit: a cluster does not have its static shape there ("
             + "; ".join(found) + "). A marker swapped, slid or mislabelled",
             RuntimeWarning)
        arrays = [np.where(bad[:, None, None], np.nan, array) for array in arrays]
    return arrays


def _fit(function, markers_1, markers_2):
    """A functional fit whose count of frames without 3 visible markers leaves out the
    frames that _drop_deformed left out (and reported) already."""
    dropped = int(np.isnan(markers_1).all(axis=(1, 2)).sum())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fit = function(markers_1, markers_2)
    for w in caught:
        message = str(w.message)
        if "fewer than 3 visible" in message and dropped:
            count, total = message.split(" of ")[0], message.split(" of ")[1].split()[0]
            if int(count) <= dropped:
                continue
            message = message.replace(f"{count} of {total}", f"{int(count) - dropped} "
                                      f"more of {total}", 1)
        warn(message, w.category)
    return fit


def _rms_size(points):
    """RMS distance of the markers from their centroid, per frame: (..., n, 3) -> (...)."""
    centred = points - points.mean(axis=-2, keepdims=True)
    return np.sqrt((centred ** 2).sum(axis=-1).mean(axis=-1))


def _check_functional_units(model, roles, labels, arrays, points, trial_name):
    """Refuse a functional trial whose marker groups are all UNITS_RATIO times larger or
    smaller than in the static trial (units other than declared), as for dynamic trials;
    the pelvis landmarks count as one group."""
    groups = [(role, labels[role], array) for role, array in zip(roles, arrays)
              if len(labels[role]) >= 3]
    singles = [(role, array) for role, array in zip(roles, arrays) if len(labels[role]) == 1]
    if len(singles) >= 3:
        groups.append((", ".join(role for role, _ in singles),
                       tuple(labels[role][0] for role, _ in singles),
                       np.concatenate([array for _, array in singles], axis=1)))
    ratios = []
    for name, group_labels, array in groups:
        seen = np.isfinite(array).all(axis=(1, 2))
        if not seen.any() or not all(label in points for label in group_labels):
            continue
        static = _rms_size(np.stack([points[label] for label in group_labels]))
        ratios.append((float(np.median(_rms_size(array[seen]))) / static, name))
    if ratios and all(not 1 / UNITS_RATIO <= r <= UNITS_RATIO for r, _ in ratios):
        ratio, name = ratios[0]
        raise ValueError(
            f"{trial_name}'s markers are {ratio:.3g} times their size in the static trial "
            f"({name}; a marker set does not change size): its units are not the ones it "
            f"declares (set df.attrs['units'] to the units the coordinates are in)")


def _check_functional_sides(model, pelvis, thigh, side, trial_name):
    """Frames of a hip trial where the body is mirrored (see check_sides), judged from
    the ASIS and posterior markers and the thigh cluster; NaN there, a whole trial
    refused."""
    if pelvis.shape[1] < 3 or "PELVIS" in model.markers:
        return pelvis, thigh
    rasis, lasis = pelvis[:, 0], pelvis[:, 1]
    mid_asis = (rasis + lasis) / 2
    anterior = mid_asis - pelvis[:, 2:].mean(axis=1)
    up = mid_asis - thigh.mean(axis=1)
    volume = np.einsum("fi,fi->f", rasis - lasis, np.cross(anterior, up))
    judged = np.isfinite(volume)
    flagged = judged & (volume < 0)
    if flagged.any():
        what = (f"the body is mirrored: RASIS ({model.markers['RASIS']!r}) lies to the "
                f"subject's left of LASIS ({model.markers['LASIS']!r}), judged with "
                f"anterior = from the posterior pelvis markers to the ASISs and up = from "
                f"the {side} thigh cluster to the ASISs. Left and right are swapped in the "
                f"labels of this trial, or it is mirrored (a lab axis reversed)")
        if flagged.sum() == judged.sum():
            raise ValueError(f"in every frame of {trial_name} ({int(judged.sum())}), {what}")
        warn(f"{int(flagged.sum())} of {int(judged.sum())} frames of {trial_name}: "
             f"{what}; those frames are left out of the {side} hip fit",
             RuntimeWarning)
        pelvis, thigh = pelvis.copy(), thigh.copy()
        pelvis[flagged], thigh[flagged] = np.nan, np.nan
    return pelvis, thigh


#: A functional hip centre farther than this (mm) from Harrington's regression in the
#: static posture gets a warning: the regression's errors against imaging are of the
#: order of a centimetre (Harrington et al. 2007), a functional centre's on a good trial
#: too (Ehrig et al. 2006; notebook 11), so that 50 mm is several times what the two
#: methods disagree by in a typical hip; beyond it, check the functional trial (a
#: dysplastic hip may differ for real, hence a warning, not an error).
FUNCTIONAL_HIP_DISTANCE_MM = 50.0


def _pelvis_markers(model):
    """The pelvis roles a functional hip fit tracks: the PELVIS cluster, or the landmarks."""
    return ["PELVIS"] if "PELVIS" in model.markers else pelvis_roles(model.markers)


def _require_cluster(model, role, option):
    if role not in model.markers:
        raise ValueError(f"{option} needs a technical cluster on every thigh (and, for the "
                         f"knee, shank) of the sides computed; the mapping has no {role!r} "
                         f"({describe(role)})")


def functional_hip_centres(model, points, trials):
    """SCoRE (functional_joint_centre) on the hip trial trials['functional_trial'] between
    the pelvis markers and the thigh cluster, carried into the static trial by the pelvis
    markers. Returns ({side: (3,) mm}, {side: JointCentre})."""
    pelvis_group = _pelvis_markers(model)
    pelvis_labels = [label for role in pelvis_group
                     for label in (model.markers[role] if role == "PELVIS"
                                   else (model.markers[role],))]
    centres, fits = {}, {}
    for side in model.sides:
        thigh = SIDE_PREFIX[side] + "THIGH"
        _require_cluster(model, thigh, "hip_centre='functional'")
        arrays, trial_name = _functional_clusters(model, pelvis_group + [thigh], trials,
                                                  "functional_trial", points)
        pelvis, thigh_markers = _check_functional_sides(
            model, np.concatenate(arrays[:-1], axis=1), arrays[-1], side, trial_name)
        try:
            fit = _fit(functional_joint_centre, pelvis, thigh_markers)
        except ValueError as error:
            raise ValueError(f"hip_centre='functional', {side} hip in {trial_name}: {error}") \
                from None
        centres[side] = fit.locate(np.stack([points[label] for label in pelvis_labels]))
        fits[side] = fit
        regression = harrington_hip_centres(model, points, trials)[0][side]
        distance = float(np.linalg.norm(centres[side] - regression))
        if distance > FUNCTIONAL_HIP_DISTANCE_MM:
            warn(
                f"the functional {side} hip centre from {trial_name} lies {distance:.0f} mm from "
                f"Harrington's regression in the static posture (warning above "
                f"{FUNCTIONAL_HIP_DISTANCE_MM:.0f} mm; the two usually agree within 10-30 "
                f"mm): check the functional trial (swapped or sliding markers, a mirrored "
                f"or mislabelled trial) and the fit's rms_distance "
                f"({fit.rms_distance:.1f} mm)", RuntimeWarning)
    return centres, fits


#: Hip-centre methods: name -> function(model, static points, trials) -> (centres
#: {side: (3,) mm, lab}, fits {side: JointCentre}, empty for a regression). A new
#: method is one more entry here.
HIP_CENTRE_METHODS = {"harrington": harrington_hip_centres,
                      "marker": marker_hip_centres,
                      "functional": functional_hip_centres}


#: A functional knee axis more than this many degrees from the epicondylar line, or
#: passing farther than KNEE_AXIS_DISTANCE_MM from mid-epicondyles, in the static posture,
#: gets a warning: the transepicondylar axis approximates the knee's flexion axis within
#: a few degrees (Churchill et al. 1998, Clin Orthop 356:111-118); on the synthetic knee
#: of data/functional (5 degrees off, with soft-tissue artefact) SARA's axis is 8 degrees
#: and 6 mm from the epicondyles', from the same trial mirrored 29 degrees and 26 mm. A
#: larger difference is a functional trial gone wrong (swapped, sliding or mirrored
#: markers) or an epicondyle marker misplaced: worth a look, hence a warning.
KNEE_AXIS_ANGLE_DEG = 20.0
KNEE_AXIS_DISTANCE_MM = 20.0


def _check_knee_axis(model, points, side, point, direction, trial_name):
    p = SIDE_PREFIX[side]
    lat, med = (points[model.markers[p + role]] for role in ("KNEE_LAT", "KNEE_MED"))
    line = (lat - med) / np.linalg.norm(lat - med)
    angle = float(np.degrees(np.arccos(min(1.0, abs(line @ direction)))))
    offset = (lat + med) / 2 - point
    distance = float(np.linalg.norm(offset - (offset @ direction) * direction))
    if angle > KNEE_AXIS_ANGLE_DEG or distance > KNEE_AXIS_DISTANCE_MM:
        warn(
            f"the functional {side} knee axis from {trial_name} is {angle:.0f} degrees from the "
            f"epicondylar line ({p}KNEE_LAT to {p}KNEE_MED) and passes {distance:.0f} mm "
            f"from mid-epicondyles in the static posture (warning above "
            f"{KNEE_AXIS_ANGLE_DEG:.0f} degrees or {KNEE_AXIS_DISTANCE_MM:.0f} mm; the two "
            f"usually agree within a few degrees): check the knee trial (swapped, sliding "
            f"or mirrored markers) and the epicondyle markers", RuntimeWarning)


def functional_knee_axes(model, points, trials):
    """SARA (functional_axis) on the knee trial trials['knee_axis_trial'] between the
    thigh and shank clusters; the axis is carried into the static trial by the thigh
    cluster and represented by the points of the axis nearest to the two epicondyles.
    Returns ({role KNEE_AXIS_LAT/MED: (3,) mm}, {side: JointAxis})."""
    rows, fits = {}, {}
    for side in model.sides:
        p = SIDE_PREFIX[side]
        for role in (p + "THIGH", p + "SHANK"):
            _require_cluster(model, role, "knee_axis='functional'")
        (thigh, shank), trial_name = _functional_clusters(
            model, [p + "THIGH", p + "SHANK"], trials, "knee_axis_trial", points)
        try:
            fit = _fit(functional_axis, thigh, shank)
        except ValueError as error:
            raise ValueError(f"knee_axis='functional', {side} knee in {trial_name}: {error}") \
                from None
        point, direction = fit.locate(np.stack([points[label]
                                                for label in model.markers[p + "THIGH"]]))
        for end in ("LAT", "MED"):
            q = points[model.markers[p + "KNEE_" + end]]
            rows[p + "KNEE_AXIS_" + end] = point + ((q - point) @ direction) * direction
        _check_knee_axis(model, points, side, point, direction, trial_name)
        fits[side] = fit
    return rows, fits


def static_landmarks(model, points, hips, knee_axis_points):
    """Landmark positions (mm, lab) of the static posture: one row per landmark role of
    the mapping, then the hip centres, then the functional knee axis's points."""
    rows = {role: points[label] for role, label in model.markers.items()
            if not is_cluster(role)}
    for side, centre in hips.items():
        rows[SIDE_PREFIX[side] + "HJC"] = centre
    rows.update(knee_axis_points)
    return pd.DataFrame(rows, index=["x", "y", "z"]).T


def _measured_shape(model, key, roles, static, points):
    """A segment without a cluster measures its landmarks in every trial: their static
    shape (centred), to check in each dynamic frame that they still move as one rigid
    body. (cluster name, cluster entry, static RMSE), or None with fewer than 3 measured
    landmarks or collinear ones."""
    measured = model._measured_roles(roles)
    if len(measured) < 3:
        return None
    name = "PELVIS" if key[0] == "pelvis" else SIDE_PREFIX[key[1]] + key[0].upper()
    shape = np.stack([points[model.markers[role]] for role in measured])
    shape = shape - shape.mean(axis=0)
    singular_values = np.linalg.svd(shape, compute_uv=False)
    if singular_values[1] <= COLLINEAR_RTOL * singular_values[0]:   # svdt's rule
        return None
    entry = {"labels": tuple(model.markers[role] for role in measured), "segment": key,
             "local": shape, "landmark_roles": [], "landmarks_local": np.zeros((0, 3)),
             "measured": True}
    frames = np.stack([static.table.points(model.markers[role], static.scale)
                       for role in measured], axis=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        _, _, error = svdt(shape, frames, order="row")
    return name, entry, float(np.nanmedian(error))


def _warn_nearly_collinear(key, cluster, labels, mean, trial_name):
    """One warning if a cluster's static markers lie close to a line (COLLINEAR_WARN_RATIO)."""
    singular_values = np.linalg.svd(mean - mean.mean(axis=0), compute_uv=False)
    spread, width = singular_values[:2]
    if width < COLLINEAR_WARN_RATIO * spread:
        n = len(labels)
        warn(
            f"the {segment_name(key)} cluster {cluster} ({', '.join(labels)}) is nearly "
            f"collinear in {trial_name}: its markers lie within {width / np.sqrt(n):.1f} mm "
            f"(RMS) of a line, across a spread of {spread / np.sqrt(n):.0f} mm (singular "
            f"value ratio {width / spread:.3f} < {COLLINEAR_WARN_RATIO}); the rotation "
            f"about that line, and the angles that use this segment, are poorly "
            f"determined", RuntimeWarning)


def _calibrated_cluster(key, cluster, labels, roles, static, points, landmarks):
    """A cluster's markers and its segment's landmarks in its technical frame (the
    model's cluster entry), and its median svdt RMSE over the static frames."""
    mean = np.stack([points[label] for label in labels])
    _warn_nearly_collinear(key, cluster, labels, mean, static.name)
    roles = list(dict.fromkeys(roles))
    try:
        local, landmarks_local = calibrate_cluster(
            mean, np.stack([landmarks.loc[role].to_numpy() for role in roles]))
    except ValueError as error:
        raise ValueError(f"{cluster} ({', '.join(labels)}): {error}") from None
    entry = {"labels": labels, "segment": key, "local": local, "landmark_roles": roles,
             "landmarks_local": landmarks_local}
    cluster_static = np.stack([static.table.points(label, static.scale) for label in labels],
                              axis=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        _, rmse = reconstruct_landmarks(local, landmarks_local, cluster_static)
    return entry, float(np.nanmedian(rmse))


def calibrate_clusters(model, static, points, landmarks):
    """Every cluster calibrated on the static trial, and each one's static RMSE (mm):
    ({cluster role: entry}, {cluster role: median svdt RMSE}), in the segments' order.
    A segment without a cluster but with 3 or more measured landmarks gets an entry of
    their static shape ('measured': True)."""
    clusters, static_rmse = {}, {}
    for key, (cluster, roles) in model._segments().items():
        if cluster is None:
            shape = _measured_shape(model, key, roles, static, points)
            if shape is not None:
                name, clusters[name], static_rmse[name] = shape
            continue
        clusters[cluster], static_rmse[cluster] = _calibrated_cluster(
            key, cluster, model.markers[cluster], roles, static, points, landmarks)
    return clusters, static_rmse


def static_posture(model, landmarks):
    """Segment frames {(segment, side): (R (3, 3), origin (3,))} and joint angles
    (degrees, a Series indexed as the angles' columns) of the static posture."""
    segment_landmarks = {key: {role: landmarks.loc[role].to_numpy()[None] for role in roles}
                         for key, (_, roles) in model._segments().items()}
    static_frames = {key: (R[0], origin[0])
                     for key, (R, origin) in model._frames(segment_landmarks).items()}
    frames = {key: (R[None], origin[None]) for key, (R, origin) in static_frames.items()}
    values, columns = model._angles(frames, _lab_frame(frames))
    return static_frames, pd.Series(values[0], index=_column_index(columns))


def _calibration(model, trials, units):
    """The calibrated attributes of `model` from trials['static'] (and the functional
    trials), step by step: static means, their checks, hip centres, geometry checks,
    functional knee axes, landmarks, clusters, static posture. A dict for
    dataclasses.replace; nothing is written into `model`."""
    static = trials["static"]
    points = _static_points(model, static.table, static.scale, static.name)
    check_units(model.markers, points, units, static.name)
    check_still(model.markers, static.table, static.scale, static.name)
    hips, hip_fits = HIP_CENTRE_METHODS[model.hip_centre](model, points, trials)
    check_static_geometry(model, points, hips)
    options = {"functional_hip": hip_fits} if model.hip_centre == "functional" else {}
    knee_axis_points = {}
    if model.knee_axis == "functional":
        knee_axis_points, options["functional_knee"] = functional_knee_axes(model, points,
                                                                            trials)
    landmarks = static_landmarks(model, points, hips, knee_axis_points)
    clusters, static_rmse = calibrate_clusters(model, static, points, landmarks)
    static_frames, static_angles = static_posture(model, landmarks)
    return {"landmarks": landmarks, "clusters": clusters, "static_rmse": static_rmse,
            "static_frames": static_frames, "static_angles": static_angles,
            "options": options}


# --- lab frame and per-trial warnings ----------------------------------------------------

#: Angle (degrees) between the direction of progression and the lab axis taken as forward
#: above which a dynamic trial warns (a diagonal walkway: pelvis rotation is then offset).
PROGRESSION_WARN_DEG = 20.0


def _lab_frame(frames, deviation=False):
    """Progression (x), vertical (y), right (z) as signed lab axes, from the pelvis; with
    `deviation`, also the angle (degrees) between the horizontal direction of progression
    and that x axis."""
    R, origin = frames[("pelvis", None)]
    valid = ~missing_rows(R.reshape(len(R), 9))     # rotations: finite or NaN, never inf
    if not valid.any():
        lab = np.full((3, 3), np.nan)
        return (lab, 0.0, (0, 0)) if deviation else lab
    R = R if valid.all() else R[valid]             # the valid frames, copied once if any
    first, last = np.flatnonzero(valid)[[0, -1]]
    y, y_axis = nearest_lab_axis(R[:, :, 1].mean(axis=0))
    path = origin[last] - origin[first]
    path = path - (path @ y) * y
    heading = R[:, :, 0].mean(axis=0)
    forward = path if np.linalg.norm(path) > 250.0 else heading
    backwards = 0
    if forward is path and heading @ path < 0:
        # The pelvis faces against its travel (walking backwards, a time-reversed trial):
        # the angles are relative to where the pelvis faces, not where it goes, or pelvis
        # rotation would read about 180 degrees. Frames facing backwards are counted.
        backwards = int(np.count_nonzero(R[:, :, 0] @ path < 0))
        forward = heading
    x, _ = nearest_lab_axis(forward, exclude=y_axis)
    lab = np.column_stack([x, y, np.cross(x, y)])
    if not deviation:
        return lab
    horizontal = forward - (forward @ y) * y
    angle = np.degrees(np.arctan2(np.linalg.norm(np.cross(horizontal, x)), horizontal @ x))
    return lab, float(angle), (backwards, int(valid.sum()))


# --- public functions --------------------------------------------------------------------

def calibrate_lower_limb(static, markers, *, sides=None, hip_centre="harrington",
                         static_offset=False, functional_trial=None, knee_axis="epicondyles",
                         knee_axis_trial=None):
    r"""Calibrate a lower-limb model from a static trial (pelvis, hip, knee, ankle).

    Parameters
    ----------
    static : pandas.DataFrame, path or None
        The standing calibration trial: a DataFrame from :func:`read_trc` or
        :func:`read_c3d`, or a path to a .trc or .c3d file; in mm, cm or m (from
        ``attrs['units']``). None when every landmark is in every frame of the dynamic
        trials (then no cluster is needed, and each frame's landmarks are used as
        measured).
    markers : dict
        Role -> the label in this lab's files; a list of 3 or more labels for a cluster
        role. Roles: ``RASIS``, ``LASIS``, and either ``RPSIS`` + ``LPSIS`` or
        ``SACRUM``; optional ``PELVIS`` (cluster). Per side (prefix ``R`` or ``L``):
        ``KNEE_LAT``, ``KNEE_MED``, ``ANKLE_LAT``, ``ANKLE_MED``, ``HEEL``, ``TOE``
        (a side without ``HEEL`` or ``TOE`` has no foot frame: its ankle angles are NaN,
        with a warning and a note in the angles' ``attrs['notes']``);
        optional ``THIGH``, ``SHANK``, ``FOOT`` (clusters), ``MT5``, and ``HJC`` (needed
        with ``hip_centre='marker'``).
    sides : None, 'right', 'left' or a list of them, keyword-only
        The sides to compute. Default: every side that has a role in `markers`.
    hip_centre : {'harrington', 'marker', 'functional'}, keyword-only
        'harrington' (default): the regression of Harrington et al. (2007) on the static
        pelvis landmarks; with a sacral marker instead of two PSIS markers, the sacral
        marker stands for the midpoint of the PSISs (pelvis depth from mid-ASIS to it).
        'marker': the ``RHJC``/``LHJC`` markers the lab computed. 'functional': SCoRE
        (:func:`functional_joint_centre`) on `functional_trial`, between the pelvis
        markers (the ``PELVIS`` cluster, or else the ASIS and PSIS/sacral markers) and
        each side's ``THIGH`` cluster.
    functional_trial : pandas.DataFrame or path, keyword-only
        With ``hip_centre='functional'``: a hip-movement trial (e.g. a star arc: flexion,
        abduction, extension and circumduction of each hip, 30 deg or more) with the
        same marker set, in any units that :func:`read_trc` reports.
    knee_axis : {'epicondyles', 'functional'}, keyword-only
        The thigh frame's medio-lateral (flexion) axis: 'epicondyles' (default), the
        line through the femoral epicondyles; 'functional': the knee's flexion axis
        from SARA (:func:`functional_axis`) on `knee_axis_trial`, between each side's
        ``THIGH`` and ``SHANK`` clusters. See Notes.
    knee_axis_trial : pandas.DataFrame or path, keyword-only
        With ``knee_axis='functional'``: a knee flexion-extension trial (several cycles,
        60 deg or more) with the same marker set.
    static_offset : bool, keyword-only
        If True, :meth:`~LowerLimbModel.angles` subtracts the static trial's hip, knee
        and ankle angles (angles relative to the standing posture); the pelvis stays
        relative to the lab. Default False (angles relative to the anatomical frames).

    Returns
    -------
    LowerLimbModel
        Call ``.angles(dynamic)`` for the angles, ``.track(dynamic)`` for the angles
        with the cluster RMSEs, segment frames and landmarks; ``.landmarks``,
        ``.static_angles``, ``.static_frames``, ``.static_rmse`` hold the calibration.

    Raises
    ------
    TypeError
        If `static` or `markers` has a wrong type.
    ValueError
        A role missing from the mapping or unknown, or a label missing from the file (with
        the close labels the file has); a landmark missing in every static frame; units
        other than mm, cm, m, or declared units that the data contradict (a pelvis width
        outside 80-600 mm; in a dynamic trial, clusters twice or half their static size or
        more: coordinates in m labelled mm); lateral and medial markers swapped, left and
        right swapped (pelvis, knees, ankles, feet), heel and toe swapped, MT5 medial to the
        heel-toe line, or a cluster on the wrong segment (judged from the static posture);
        the ASIS and PSIS markers swapped (judged by the feet), a hip centre on the other
        side (RHJC/LHJC swapped), knee or ankle markers of a width or tilt no joint has (a
        marker of another role mapped there: ``KNEE_WIDTH_MM``, ``ANKLE_WIDTH_MM``,
        ``JOINT_LINE_TILT_DEG``); one label mapped to two roles, or a label twice in a
        trial; a functional trial in other units than the static, or mirrored in every
        frame; in :meth:`~LowerLimbModel.angles`, a trial whose every frame is mirrored or
        has its left and right labels swapped (see Warns); an unknown `hip_centre` or
        `knee_axis`; ``static_offset=True`` without a static trial; a functional option
        without its trial (or without a static trial), or a trial given without its option;
        a functional fit that fails (too little movement, a hinge movement for the hip
        centre, a cluster missing), with the side and the trial named.

    Warns
    -----
    RuntimeWarning
        A static trial that is not static (markers moving more than
        ``STATIC_MOTION_MM = 100`` mm from their median position, or a cluster or the
        pelvis markers turning more than ``STATIC_ROTATION_DEG = 10`` degrees from their
        mean orientation: a subject who turns or walks); a cluster nearly collinear in
        the static trial. In :meth:`~LowerLimbModel.angles`: a cluster that deforms
        (svdt RMSE above ``max(DEFORM_MM, DEFORM_FACTOR * static RMSE)``), frames where a
        cluster has fewer than 3 visible markers, or where a segment without a cluster
        lacks one of its measured landmarks (the angles that use that segment are NaN
        there, the others are kept); a direction of progression more than
        ``PROGRESSION_WARN_DEG = 20`` degrees from the nearest lab axis (a diagonal
        walkway: pelvis rotation is offset by that angle); frames where the body is
        mirrored (RASIS to the left of LASIS, judged with the legs below the pelvis and
        anterior from the PSISs to the ASISs), the pelvis faces against the feet (heel to
        toe), or the thighs are swapped (the angles are NaN there; every frame: an
        error); a pelvis facing against its direction of travel (walking backwards, a
        time-reversed trial: the pelvis angles are then relative to its heading); an
        ``attrs['rate']`` that contradicts the time index. In a functional trial: frames
        where a cluster lost its static shape (left out of the fit), a functional hip
        centre more than ``FUNCTIONAL_HIP_DISTANCE_MM = 50`` mm from Harrington's, and a
        functional knee axis more than ``KNEE_AXIS_ANGLE_DEG = 20`` degrees from the
        epicondylar line or ``KNEE_AXIS_DISTANCE_MM = 20`` mm from mid-epicondyles. Each
        once per call.

    Notes
    -----
    *Static trial.* Each label is averaged over the static frames. The hip centres
    come from the pelvis landmarks. Each cluster's landmarks are expressed in its
    technical frame (:func:`calibrate_cluster`): the pelvis cluster carries the ASIS and
    PSIS (or sacral) markers; the thigh cluster the hip centre and the epicondyles; the
    shank cluster the epicondyles and the malleoli; the foot cluster the heel, toe, MT5
    and malleoli.

    *Dynamic trial.* Each cluster is fitted with :func:`svdt` and its landmarks put back
    (:func:`reconstruct_landmarks`); a segment without a cluster uses its landmarks as
    measured, and its hip centre is carried by the pelvis frame. Segment frames: pelvis
    :func:`pelvis_frame`, thigh :func:`thigh_frame`, shank :func:`shank_frame`, foot
    :func:`foot_frame` (from heel, toe, MT5 and the malleoli). Angles: pelvis relative
    to the lab frame with the sequence rotation - obliquity - tilt (Baker 2001,
    :func:`pelvis_angles`), the lab frame's axes being the lab axes closest to the
    direction of progression (the pelvis's travel, or its mean anterior axis on a
    treadmill), to the vertical (the pelvis's mean superior axis) and to the right;
    hip :func:`hip_angles`, knee :func:`knee_angles` (Grood & Suntay 1983), ankle
    :func:`ankle_angles` (Wu et al. 2002). Without MT5 and without a foot cluster the
    foot's roll about the heel-toe line is not measured, and ankle inversion is NaN.

    *Functional hip centre.* The centre is found in the pelvis markers' frame from the
    hip trial, placed in the static trial through the same markers, and from there
    carried like any landmark (the thigh cluster carries it into every dynamic trial).
    The fits are in ``model.options['functional_hip']``: check their `rms_distance`
    and `range_of_motion`.

    *Functional knee axis and cross-talk.* Knee ab/adduction and rotation are measured
    about axes perpendicular to the thigh's medio-lateral axis; if that axis is off the
    joint's real flexion axis, part of the flexion appears as ab/adduction and rotation
    ("cross-talk", proportional to the flexion). With ``knee_axis='functional'`` the
    thigh's medio-lateral axis is the SARA axis: the epicondyles are replaced, for the
    thigh frame only, by the points of the axis nearest to them (roles
    ``RKNEE_AXIS_LAT``/``MED``), so the knee centre is the point of the axis nearest to
    mid-epicondyles; the shank frame is unchanged. On the synthetic trials of
    data/functional (a flexion axis 5 deg off the epicondylar line, soft-tissue artefact
    and 0.5 mm noise), the slope of knee adduction against flexion over 5-90 deg fell
    from -0.090 to -0.034 deg per deg (the adduction's range from 12.9 to 9.5 deg; the
    true secondary adduction spans 4 deg), while rotation's slope stayed as small
    (-0.034 to +0.030; tests/test_lower_limb_functional.py). The gain depends on how far
    the palpated axis is off and on the artefact, which biases SARA by a few degrees too.

    References
    ----------
    .. [1] Cappozzo A, Catani F, Della Croce U, Leardini A (1995) Position and
       orientation in space of bones during movement: anatomical frame definition and
       determination. Clin Biomech 10:171-178.
    .. [2] Wu G et al. (2002) ISB recommendation on definitions of joint coordinate
       system of various joints for the reporting of human joint motion - part I: ankle,
       hip, and spine. J Biomech 35:543-548.
    .. [3] Grood ES, Suntay WJ (1983) J Biomech Eng 105:136-144.
    .. [4] Baker R (2001) Pelvic angles: a mathematically rigorous definition which is
       consistent with a conventional clinical understanding of the terms. Gait Posture
       13:1-6.
    .. [5] Harrington ME et al. (2007) J Biomech 40:595-602.

    Examples
    --------
    The synthetic trials of the repository (both legs, with feet; see data/README.md):

    >>> import warnings
    >>> from bmc_functions import calibrate_lower_limb
    >>> from bmc_functions.examples import example_file  # data/markers, shipped too
    >>> markers = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
    ...            "PELVIS": ["PEL1", "PEL2", "PEL3"]}
    >>> for p in "RL":
    ...     markers.update({p + "THIGH": [p + "TH1", p + "TH2", p + "TH3", p + "TH4"],
    ...                     p + "SHANK": [p + "TB1", p + "TB2", p + "TB3"],
    ...                     p + "KNEE_LAT": p + "LFC", p + "KNEE_MED": p + "MFC",
    ...                     p + "ANKLE_LAT": p + "LMAL", p + "ANKLE_MED": p + "MMAL",
    ...                     p + "HEEL": p + "HEEL", p + "TOE": p + "TOE", p + "MT5": p + "MT5"})
    >>> model = calibrate_lower_limb(example_file("markers/static.trc"), markers)
    >>> print(model.static_angles["knee", "right"].round(1).to_dict())
    {'flexion': 4.0, 'adduction': 1.5, 'rotation': -3.0}
    >>> with warnings.catch_warnings():       # two occlusion gaps, reported once each
    ...     warnings.simplefilter("ignore")
    ...     angles = model.angles(example_file("markers/walk.trc"))
    >>> angles.shape
    (111, 24)
    >>> print(round(angles["knee", "right", "flexion"].max(), 1))
    66.0

    With the functional hip centre and knee axis (a star arc and a knee flexion trial of
    the same marker set; see data/functional and notebook 11):

    >>> model = calibrate_lower_limb("static.trc", markers, hip_centre="functional",
    ...                              functional_trial="star_arc.trc",
    ...                              knee_axis="functional",
    ...                              knee_axis_trial="knee_flexion.trc")  # doctest: +SKIP
    >>> model.options["functional_hip"]["right"].rms_distance           # doctest: +SKIP
    """
    check_choice(hip_centre, "hip_centre", tuple(HIP_CENTRE_METHODS))
    check_choice(knee_axis, "knee_axis", ("epicondyles", "functional"))
    static_offset = check_flag(static_offset, "static_offset")
    for option, value, trial_name, given in (
            ("hip_centre", hip_centre, "functional_trial", functional_trial),
            ("knee_axis", knee_axis, "knee_axis_trial", knee_axis_trial)):
        if value == "functional" and given is None:
            raise ValueError(f"{option}='functional' needs {trial_name}: the trial in which "
                             f"the joint moves (a DataFrame or a .trc/.c3d path)")
        if value != "functional" and given is not None:
            raise ValueError(f"{trial_name} is used only with {option}='functional'; got "
                             f"{option}={value!r}")
        if value == "functional" and static is None:
            raise ValueError(f"{option}='functional' needs a static trial: the functional "
                             f"result is placed in the static posture through the clusters")
    if static is None and static_offset:
        raise ValueError("static_offset=True needs a static trial (the offset is the static "
                         "posture's angles); got static=None")
    mapping, sides = check_mapping(markers, sides, hip_centre)
    model = LowerLimbModel(markers=mapping, sides=sides, hip_centre=hip_centre,
                           knee_axis=knee_axis, static_offset=static_offset)
    footless = [side for side in sides if not model.has_foot(side)]
    if footless:
        warn(_no_foot_note(model, footless), UserWarning)
    trials = {name: _load(given, what)[0]
              for name, given, what in (("functional_trial", functional_trial, "hip movement"),
                                        ("knee_axis_trial", knee_axis_trial, "knee flexion"))
              if given is not None}
    if static is None:
        return model
    trials["static"], units = _load(static, "static")
    roles = [role for role in mapping if role[1:] != "HJC" or hip_centre == "marker"]
    check_labels(mapping, roles, trials["static"].table.labels, trials["static"].name,
                 trials["static"].table.dropped)
    with blas_single_thread():  # see bmc_functions._threads
        calibration = _calibration(model, trials, units)
    return replace(model, units=units, **calibration)   # the model, assembled once


def _no_foot_note(model, sides):
    """What a side without heel or toe roles gets: hip and knee angles, NaN ankle."""
    roles = ", ".join(SIDE_PREFIX[side] + role for side in sides for role in FOOT_FRAME_ROLES
                      if SIDE_PREFIX[side] + role not in model.markers)
    return (f"the {' and '.join(sides)} side has no foot frame ({roles} not in the "
            f"mapping): its hip and knee angles are computed, its ankle angles are NaN")


def _trial_names(trials):
    names = [Path(t).stem if isinstance(t, (str, Path)) else str(k)
             for k, t in enumerate(trials)]
    if len(set(names)) < len(names):
        names = [str(t) if isinstance(t, (str, Path)) else str(k)
                 for k, t in enumerate(trials)]
    if len(set(names)) < len(names):
        names = [str(k) for k in range(len(trials))]
    return names


def lower_limb_angles(static, dynamic, markers, *, workers=None, client=None, progress=True,
                      errors="raise", **options):
    r"""Lower-limb angles in one call: calibrate on `static`, then angles of `dynamic`.

    Parameters
    ----------
    static : pandas.DataFrame, path or None
        As :func:`calibrate_lower_limb`.
    dynamic : pandas.DataFrame, path, or a list of them
        One trial, or many trials of the same subject and marker set (one static).
    markers : dict
        Role -> label(s), as :func:`calibrate_lower_limb`.
    workers, client : optional, keyword-only
        Passed to the batch runner for a list of trials (processes or a dask client).
    progress : bool, keyword-only
        Show a progress bar over a list of trials when it takes more than a moment.
        Default True.
    errors : {'raise', 'warn'}, keyword-only
        For a list of trials. 'raise' (default): the first trial that fails stops the run
        with its error, which names the trial. 'warn': a trial that fails (a broken file,
        a missing label) is left out of the result, and one RuntimeWarning names every
        failed trial and its error, so that one bad file does not lose an archive. If
        every trial fails, a ValueError says so.
    **options
        Keyword arguments of :func:`calibrate_lower_limb` (`sides`, `hip_centre`,
        `static_offset`, `functional_trial`, `knee_axis`, `knee_axis_trial`).

    Returns
    -------
    pandas.DataFrame
        For one trial, as :meth:`LowerLimbModel.angles`. For a list, the trials one
        below the other, with a two-level row index ``(trial, time)``: the trial is the
        file's stem (or its position in the list for DataFrames). ``attrs`` as for one
        trial; where the trials differ in ``'marker_units'`` or ``'lab_frame'`` (e.g. a
        file in m among files in mm, or walks in both directions), that entry is a dict
        trial -> value.

    Raises
    ------
    TypeError, ValueError
        As :func:`calibrate_lower_limb` and :meth:`LowerLimbModel.angles`; an empty list;
        every trial failed with ``errors='warn'``.

    Examples
    --------
    Two trials of one subject (here the same synthetic stride twice, with the markers of
    :func:`calibrate_lower_limb`'s example):

    >>> import warnings
    >>> from bmc_functions import lower_limb_angles
    >>> from bmc_functions.examples import example_file
    >>> markers = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
    ...            "PELVIS": ["PEL1", "PEL2", "PEL3"], "RTHIGH": ["RTH1", "RTH2", "RTH3"],
    ...            "RSHANK": ["RTB1", "RTB2", "RTB3"], "RKNEE_LAT": "RLFC",
    ...            "RKNEE_MED": "RMFC", "RANKLE_LAT": "RLMAL", "RANKLE_MED": "RMMAL",
    ...            "RHEEL": "RHEEL", "RTOE": "RTOE", "RMT5": "RMT5"}
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")
    ...     static, walk = example_file("markers/static.trc"), example_file("markers/walk.trc")
    ...     many = lower_limb_angles(static, [walk, str(walk)], markers)
    >>> list(many.index.names), many.shape
    (['trial', 'time'], (222, 12))
    >>> list(many.index.get_level_values("trial").unique())
    ['0', '1']
    """
    # at once, also for one trial (which runs here, without map_trials)
    workers, client, progress, errors = check_batch_options(workers, client, progress, errors)
    model = calibrate_lower_limb(static, markers, **options)
    if not isinstance(dynamic, (list, tuple)):
        return model.angles(dynamic)
    if not dynamic:
        raise ValueError("dynamic is an empty list: give at least one trial")
    return _stacked(model.angles, dynamic, dynamic, workers=workers, client=client,
                    progress=progress, errors=errors, desc="lower-limb angles")


def _stacked(function, items, dynamic, **batch):
    """map_trials(function, items) (one item per trial of the list `dynamic`), the
    results one below the other with a (trial, time) index (see lower_limb_angles)."""
    results = map_trials(function, items, **batch)
    kept = [(name, result) for name, result in zip(_trial_names(dynamic), results)
            if result is not None]   # errors='warn': the failed trials were named
    if not kept:
        raise ValueError(f"all {len(dynamic)} trials failed (errors='warn'; the warning "
                         "names each trial and its error)")
    names = [name for name, _ in kept]
    results = [result for _, result in kept]
    out = pd.concat(results, keys=names, names=["trial", "time"])
    out.attrs = dict(results[0].attrs)
    for key in ("marker_units", "lab_frame"):   # per trial, when the trials differ
        values = [result.attrs.get(key) for result in results]     # kinetics: none
        if any(value != values[0] for value in values):
            out.attrs[key] = dict(zip(names, values))
    return out


def _trial_kinetics(model, options, item):
    """LowerLimbModel.kinetics of one (trial, forces) pair (picklable for the workers)."""
    trial, forces = item
    return model.kinetics(trial, forces, **options)


def _forces_per_trial(dynamic, forces):
    """The ground loads of each trial of `dynamic` (a list): `forces` (a list of the same
    length), or with None each C3D trial's own force plates."""
    if forces is None:
        other = [trial for trial in dynamic if not isinstance(trial, (str, os.PathLike))
                 or Path(trial).suffix.lower() != ".c3d"]
        if other:
            raise ValueError(f"forces: None reads the force plates of each C3D trial; "
                             f"{_trial_text(other[0])} is not a C3D path: give forces, an "
                             f"external-loads .mot (or its table) per trial")
        return list(dynamic)
    if not isinstance(forces, (list, tuple)) or len(forces) != len(dynamic):
        got = (f"a list of {len(forces)}" if isinstance(forces, (list, tuple))
               else _trial_text(forces))
        raise ValueError(f"forces: for a list of {len(dynamic)} trials give a list of as "
                         f"many ground loads (one per trial, in the same order) or None "
                         f"(each C3D trial's own plates); got {got}")
    return list(forces)


def _trial_text(value):
    text = str(value) if isinstance(value, (str, os.PathLike)) else type(value).__name__
    return text if len(text) <= 80 else text[:77] + "..."


def lower_limb_kinetics(static, dynamic, markers, *, body_mass, forces=None,
                        cutoff=DEFAULT_CUTOFF, force_cutoff="cutoff", parameters=None,
                        gravity=None, workers=None, client=None, progress=True,
                        errors="raise", **options):
    r"""Lower-limb moments, forces and powers in one call: calibrate on `static`, then the
    kinetics of `dynamic`, as :func:`lower_limb_angles` gives the angles.

    The sibling of :func:`lower_limb_angles` rather than an option of it: the kinetics
    are a table of their own (``(joint, side, quantity)``, per kg of body mass, their own
    ``attrs``), and they need what the angles do not (the body mass, the ground loads).
    The numbers are those of ``calibrate_lower_limb(static, markers, **options)
    .kinetics(trial, forces, body_mass=...)``.

    Parameters
    ----------
    static, markers, **options
        As :func:`lower_limb_angles` (:func:`calibrate_lower_limb`'s).
    dynamic : pandas.DataFrame, path, or a list of them
        One trial, or many trials of the same subject (one static).
    body_mass : float, keyword-only
        kg, as :meth:`LowerLimbModel.kinetics`.
    forces : path, pandas.DataFrame, list or None, keyword-only
        The ground loads, as :meth:`LowerLimbModel.kinetics` takes them (an OpenSim
        external-loads ``.mot``, its table, or a ``.c3d`` path). None (default): each
        trial's own force plates, every trial then a C3D path. For a list of trials: a
        list of as many loads, in the same order, or None.
    cutoff, force_cutoff, parameters, gravity : keyword-only
        As :meth:`LowerLimbModel.kinetics`.
    workers, client, progress, errors : keyword-only
        As :func:`lower_limb_angles`, for a list of trials.

    Returns
    -------
    pandas.DataFrame
        For one trial, :meth:`LowerLimbModel.kinetics`'s table. For a list, the trials one
        below the other, indexed by ``(trial, time)`` as :func:`lower_limb_angles`;
        ``attrs`` those of the first trial.

    Raises
    ------
    TypeError, ValueError
        As :func:`calibrate_lower_limb` and :meth:`LowerLimbModel.kinetics`; `forces`
        None with a trial that is not a C3D path; for a list of trials, `forces` not None
        nor a list of the same length; an empty list.

    Examples
    --------
    The example walk has no force plate: an external-loads table that measures nothing
    (its stances NaN, a warning names them), twice:

    >>> import warnings
    >>> import numpy as np, pandas as pd
    >>> from bmc_functions import lower_limb_kinetics, read_marker_mapping
    >>> from bmc_functions.examples import example_file
    >>> markers = read_marker_mapping(example_file("markers/markers.toml"))
    >>> columns = [f"R_ground_{kind}{axis}" for kind in ("force_v", "force_p", "torque_")
    ...            for axis in "xyz"]
    >>> loads = pd.DataFrame(0.0, columns=columns, index=np.arange(0, 1.2, 0.001))
    >>> walk = example_file("markers/walk.trc")
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")
    ...     kin = lower_limb_kinetics(example_file("markers/static.trc"), [walk, walk],
    ...                               markers, body_mass=70, forces=[loads, loads],
    ...                               progress=False)
    >>> list(kin.index.names), kin.shape
    (['trial', 'time'], (222, 42))
    """
    batch = check_batch_options(workers, client, progress, errors)
    kinetic = dict(body_mass=body_mass, cutoff=cutoff, force_cutoff=force_cutoff,
                   parameters=parameters, gravity=gravity)
    if not isinstance(dynamic, (list, tuple)):
        loads = _forces_per_trial([dynamic], None)[0] if forces is None else forces
        return _trial_kinetics(calibrate_lower_limb(static, markers, **options), kinetic,
                               (dynamic, loads))
    if not dynamic:
        raise ValueError("dynamic is an empty list: give at least one trial")
    items = list(zip(dynamic, _forces_per_trial(dynamic, forces)))
    model = calibrate_lower_limb(static, markers, **options)
    return _stacked(functools.partial(_trial_kinetics, model, kinetic), items, dynamic,
                    workers=batch[0], client=batch[1], progress=batch[2], errors=batch[3],
                    desc="lower-limb kinetics")

