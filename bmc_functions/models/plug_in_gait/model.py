r"""The Plug-in Gait model of a subject: built from the static trial and the subject's
measurements (:func:`plug_in_gait`), then run on trials (:class:`PlugInGait`)."""

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..._checks import ArgumentTypeError, check_choice, missing_rows, warn, warn_frames
from ...files.opensim import opensim_coordinates
from ...files.trial import MarkerTable, load_trial, mm_per_unit
from ...rigid_body.rotations import rot_y
from ..lower_limb_checks import check_still
from . import checks, upper_body_checks
from .kinetics import plug_in_gait_kinetics
from .knee_alignment import (abadd_rotated_ankle_centre, ankle_abadd_offset, kad_knee_marker,
                             rotated_chord_joint_centre, tibial_torsion_offset, vicon_wand_offset,
                             wand_offset_from_vicon, wand_rotation_offset)
from .labels import check_handedness, check_markers, check_trial_units, resolve_labels
from .lower_body import (CGM_ANGLES, LEG_MARKERS, LOWER_BODY_OUTPUTS, PELVIS_MARKERS,
                         PROGRESSION_MIN_PATH, SIDE_NAME, SIDE_PREFIX, SIDES, cgm_angles,
                         cgm_femur_frame,
                         cgm_foot_frame, cgm_pelvis_frame, cgm_static_foot_frame,
                         cgm_tibia_frame, cgm_uncorrected_foot_frame, chord_joint_centre,
                         davis_hip_centre, progression_frame, static_foot_offsets)
from .subject import check_same_subject, check_subject, load_subject, subject_names
from .upper_body import (THORACOHUMERAL_ANGLES, THORAX_MARKERS, UPPER_BODY_ANGLES,
                         UPPER_BODY_CENTRES, UPPER_BODY_MARKERS, UPPER_BODY_OUTPUTS,
                         head_level_offset, thoracohumeral_angles, upper_body_angles,
                         upper_body_geometry)

#: The knee alignment device's markers (Vicon's names, without the side's L or R), read in
#: the static trial only.
KAD_MARKERS = ("KAX", "KD1", "KD2")
#: The KAD-med static's medial malleolus markers (after the side's L/R): ``LMED``, as
#: pyCGM2 reads it, or ``LMMA``; either one per side.
MEDIAL_ANKLE_MARKERS = ("MED", "MMA")

#: Every joint's angles, the lower body's then the upper body's, in the columns' order.
ALL_ANGLES = {**CGM_ANGLES, **UPPER_BODY_ANGLES}

#: Vicon's name of each output (the L or R prefix added) and the component used, for every
#: (joint, angle) of :meth:`PlugInGait.angles`: ``('knee', 'flexion')`` ->
#: ``('KneeAngles', 0)``, ``('shoulder', 'abduction')`` -> ``('ShoulderAngles', 1)``.
VICON_OUTPUTS = {**LOWER_BODY_OUTPUTS, **UPPER_BODY_OUTPUTS}

#: Order of the angle names in the columns' third level (each joint's in increasing order).
_ANGLE_ORDER = ("tilt", "obliquity", "flexion", "adduction", "lateral_flexion", "abduction",
                "ulnar_deviation", "dorsiflexion", "inversion", "rotation", "progression")

#: Angle (degrees) between the pelvis's path and the lab axis taken as the direction of
#: progression above which a trial warns (as the ISB pipeline,
#: :data:`bmc_functions.models.lower_limb.PROGRESSION_WARN_DEG`).
PROGRESSION_WARN_DEG = 20.0


def _warn_upper_body_defaults(derived, frames):
    """One warning when an arm segment of the trial rests on a measurement the subject did
    not give (Vicon's template default used instead)."""
    used = []
    for side in ("left", "right"):
        long = side.capitalize()
        if ("humerus", side) in frames:
            used += [long + name for name in ("ShoulderOffset", "ElbowWidth", "WristWidth")]
        if ("hand", side) in frames:
            used.append(long + "HandThickness")
    defaulted = [name for name in used if name in derived]
    if defaulted:
        values = ", ".join(f"{name} = {derived[name]:g} mm" for name in defaulted)
        warn(f"the subject gives no {', '.join(defaulted)}: the arms use the defaults of "
             f"Vicon's Plug-in Gait template ({values}); measure them for this subject "
             f"(the shoulder, elbow and wrist centres move with them)", RuntimeWarning)


def _warn_diagonal(pelvis_origin, R_progression, label):
    """One warning when the pelvis travels more than PROGRESSION_WARN_DEG from the lab
    axis taken as forward (a diagonal walkway): Plug-in Gait, Vicon's included, reports
    the pelvis and foot-progression angles against that axis."""
    valid = np.isfinite(pelvis_origin).all(axis=1)
    if not valid.any() or not np.isfinite(R_progression).all():
        return
    up, forward = R_progression[:, 2], R_progression[:, 0]
    path = pelvis_origin[valid][-1] - pelvis_origin[valid][0]
    path = path - (path @ up) * up
    if np.linalg.norm(path) <= PROGRESSION_MIN_PATH:
        return
    angle = float(np.degrees(np.arctan2(np.linalg.norm(np.cross(path, forward)),
                                        path @ forward)))
    if angle > PROGRESSION_WARN_DEG:
        warn(f"the pelvis in {label} travels {angle:.0f} degrees from the lab axis "
             f"taken as the direction of progression (the nearest one; warning "
             f"above {PROGRESSION_WARN_DEG:.0f} degrees): Plug-in Gait (Vicon's "
             f"too) reports the pelvis angles and foot progression against that "
             f"axis, so pelvis rotation and foot progression read about "
             f"{angle:.0f} degrees off. Rotate the marker coordinates so that the "
             f"walkway runs along a lab axis", RuntimeWarning)



@dataclass
class PlugInGaitTrack:
    """What :meth:`PlugInGait.track` returns for one trial.

    Attributes
    ----------
    centres : pandas.DataFrame
        Joint centres (mm, lab), columns ``(point, coord)`` like a marker DataFrame:
        ``LHJC``/``RHJC`` (hip), ``LKJC``/``RKJC`` (knee, Vicon's ``LFEO``),
        ``LAJC``/``RAJC`` (ankle, Vicon's ``LTIO``) and ``PELO`` (midpoint of the hip
        centres, Vicon's ``PELO``), indexed by time; with the upper body's markers also
        ``TRXO`` (thorax origin, Vicon's ``TRXO``), ``LSJC``/``RSJC`` (shoulder, Vicon's
        ``LCLO``), ``LEJC``/``REJC`` (elbow, ``LHUO``), ``LWJC``/``RWJC`` (wrist,
        ``LRAO``) and ``LHND``/``RHND`` (the hand's chord point; Vicon's ``LHNO`` is
        2 LHND - LWJC), each where its markers are in the trial
        (:func:`~bmc_functions.models.plug_in_gait.upper_body.upper_body_geometry`).
    frames : dict
        (segment, side) -> (R, origin): rotation matrices (frames, 3, 3), columns the
        segment's x, y, z axes (Vicon's ``...A``, ``...L``, ``...P`` directions), and
        origins (frames, 3) in mm. Segments: ``('pelvis', None)`` (origin PELO),
        ``('femur', side)`` (origin the knee centre), ``('tibia', side)`` (torsioned,
        origin the ankle centre), ``('tibia_untorsioned', side)``, ``('foot', side)``
        (origin the TOE marker), ``('foot_uncorrected', side)`` and, when HEE is
        there, ``('foot_static', side)`` (the heel-toe foot of the static processing).
        The axes of every segment are Vicon's (``...A``, ``...L``, ``...P`` minus
        ``...O``, normalized); Vicon's foot origin ``LFOO`` is not a CGM landmark (it
        stays 164 mm from the ankle centre in the shared trial, a length of Vicon's
        skeleton template), so only the foot's axes are comparable. The upper body:
        ``('head', None)`` (origin the front of the head; Vicon's ``HEDO`` is a mesh
        origin moved from it, its axes are these), ``('thorax', None)`` (origin TRXO; x
        forward, y left, z up: Vicon writes it turned 180° about x, ``TRXL`` to the
        right and ``TRXP`` down), and per side ``('clavicle', side)``, ``('humerus',
        side)``, ``('radius', side)`` and ``('hand', side)`` with Vicon's origins and
        axes (``LCLO``, ``LHUO``, ``LRAO``, ``LHNO``).
    progression : ndarray, shape (3, 3)
        :func:`progression_frame` of the trial.
    """

    centres: pd.DataFrame
    frames: dict
    progression: np.ndarray


@dataclass
class PlugInGait:
    """A Plug-in Gait (CGM) model of one subject: made by :func:`plug_in_gait`.

    Attributes
    ----------
    subject : dict
        Every subject measurement the model uses (Vicon's names; mm, radians), given or
        derived.
    derived : dict
        The measurements this model computed rather than took from the subject (the
        ASIS-trochanter distances, the default marker diameter, the inter-ASIS distance
        and static offsets from the static trial, ...).
    static_offsets : dict
        ``'LeftStaticPlantFlex'``, ``'LeftStaticRotOff'`` and the right ones (radians):
        from the static trial when one was given, else from `subject`.
    markers : dict
        Standard name -> the label used in the last trial read.
    rename : dict
        The `markers` mapping given to :func:`plug_in_gait` (standard name -> label).
    attrs : dict
        For a methods appendix: the model (``'Plug-in Gait (Conventional Gait Model 1.0;
        the upper body where its markers are)'``), the references, where the
        measurements came from, every measurement used, what was derived, the static
        offsets, the marker diameter, ``'head_level_offset'`` and ``'foot_flat'``.
    head_level_offset : float or None
        What Vicon's static processing would write as ``HeadOffset`` with its "head
        level" option (radians, :func:`~bmc_functions.models.plug_in_gait.upper_body.
        head_level_offset`), from the static trial's head; reported, not applied (the
        subject's ``HeadOffset`` is). None without a static trial or its head markers.
    calibration : dict
        The static trial's leg-marker geometry, for the checks of later trials.
    foot_flat : tuple
        The sides whose static foot was processed flat (``plug_in_gait(...,
        foot_flat=...)``).
    """

    subject: dict
    derived: dict
    static_offsets: dict
    markers: dict = field(default_factory=dict)
    rename: dict = field(default_factory=dict)
    attrs: dict = field(default_factory=dict)
    head_level_offset: float = None
    calibration: dict = field(default_factory=dict)
    foot_flat: tuple = ()

    # -- one trial's geometry --

    def _landmarks(self, trial, name):
        df, label = load_trial(trial, name)
        scale, _ = mm_per_unit(df, label)
        data = MarkerTable(df, label)
        resolved = resolve_labels(data, self.rename, label)
        posterior = check_markers(resolved, data, label)
        self.markers = resolved
        self._posterior = posterior
        self._trial = label
        points = data.points_of(resolved, scale)
        checks.zero_points_as_missing(points, label)
        check_trial_units(points, resolved, df.attrs.get("units"), label)
        points["SACRUM"] = ((points["LPSI"] + points["RPSI"]) / 2.0 if posterior != ["SACR"]
                            else points["SACR"])
        if posterior != ["SACR"] and "SACR" in points:   # both kinds: SACR fills PSI gaps
            fill = missing_rows(points["SACRUM"]) & ~missing_rows(points["SACR"])
            points["SACRUM"][fill] = points["SACR"][fill]
            warn_frames(int(fill.sum()), len(fill), f"of {label} lack LPSI or RPSI: the "
                        f"pelvis uses SACR there (elsewhere the midpoint of the PSIS "
                        f"markers)")
        mirrored, crossed = check_handedness(points, label)
        if mirrored.any() or crossed.any():  # flagged frames: NaN where the check says
            for key, values in points.items():
                values[mirrored | crossed if key[1:] in LEG_MARKERS else mirrored] = np.nan
        flagged = (mirrored | crossed | self._check_leg_markers(points, label, name)
                   | self._check_upper_body_markers(points, label))
        return df, points, flagged

    def _check_leg_markers(self, points, label, name):
        """The measurements against the markers, and the leg markers' order and distances
        (:mod:`~bmc_functions.models.plug_in_gait.checks`): flagged markers NaN."""
        checks.check_measurements_against_markers(points, self.subject, trial=label)
        checks.check_lab_vertical(points, label)
        legs = {p: self.subject[long + "LegLength"] for p, long in (("L", "Left"),
                                                                     ("R", "Right"))}
        flagged = (checks.check_leg_marker_order(points, label, static=name == "static")
                   | checks.check_leg_distances(points, legs, label))
        if self.calibration and name != "static":
            checks.check_against_static(points, self.calibration, legs, label)
        pelvis = checks.pelvis_axes(points)     # the two checks below change no marker
        checks.check_toe_ahead_of_ankle(points, label, pelvis)   # with or without a static
        checks.check_thigh_wands(points, self.subject, label, pelvis)
        return flagged

    def _check_upper_body_markers(self, points, label):
        """The upper-body markers' order and the chords' offsets against them
        (:mod:`~bmc_functions.models.plug_in_gait.upper_body_checks`): flagged markers NaN."""
        if not any(name in points for name in upper_body_checks.UPPER_BODY_CHECKED):
            return np.zeros(len(points["LASI"]), dtype=bool)
        leg = (self.subject["LeftLegLength"] + self.subject["RightLegLength"]) / 2.0
        flagged = upper_body_checks.check_upper_body_markers(
            points, leg, label, self.subject["MarkerDiameter"] / 2.0)
        upper_body_checks.check_upper_body_measurements(points, self.subject, label)
        return flagged

    def _geometry(self, points, offsets, with_static_foot=True, ankles=None,
                  upper_body=True):
        """Joint centres and segment frames (every frame at once; the upper body's when
        `upper_body` and its markers are there); `ankles`: side -> the ankle centre
        measured in a KAD-med static (midway between the malleoli), in place of the chord
        function's."""
        subject = self.subject
        R_pelvis, asis_mid = cgm_pelvis_frame(points["RASI"], points["LASI"],
                                              points["SACRUM"])
        radius = subject["MarkerDiameter"] / 2.0
        mean_leg = (subject["LeftLegLength"] + subject["RightLegLength"]) / 2.0
        centres, frames = {}, {}
        for side in SIDES:
            p, long = SIDE_PREFIX[side], SIDE_NAME[side]
            hip = davis_hip_centre(R_pelvis, asis_mid, mean_leg_length=mean_leg,
                                   asis_trochanter=subject[long + "AsisTrocanterDistance"],
                                   inter_asis_distance=subject["InterAsisDistance"],
                                   marker_radius=radius, side=side)
            # the chord function, the wand turned by the knee alignment offsets (0: the
            # chord function itself, bit for bit): knee_alignment's module docstring
            knee = rotated_chord_joint_centre(
                points[p + "THI"], hip, points[p + "KNE"],
                subject[long + "KneeWidth"] / 2.0 + radius,
                wand_offset_from_vicon(subject.get(long + "ThighRotation", 0.0), side))
            ankle = rotated_chord_joint_centre(
                points[p + "TIB"], knee, points[p + "ANK"],
                subject[long + "AnkleWidth"] / 2.0 + radius,
                wand_offset_from_vicon(subject.get(long + "ShankRotation", 0.0), side))
            # then turned about ANK by the static ankle abduction (KAD-med; 0: unchanged)
            ankle = abadd_rotated_ankle_centre(ankle, knee, points[p + "ANK"],
                                               subject.get(long + "AnkleAbAdd", 0.0))
            if ankles and side in ankles:
                ankle = ankles[side]
            R_femur = cgm_femur_frame(hip, knee, points[p + "KNE"], side)
            R_tibia, R_untorsioned = cgm_tibia_frame(knee, ankle, points[p + "ANK"], side,
                                                     subject[long + "TibialTorsion"])
            R_uncorrected = cgm_uncorrected_foot_frame(ankle, points[p + "TOE"], R_tibia)
            centres[p + "HJC"], centres[p + "KJC"], centres[p + "AJC"] = hip, knee, ankle
            frames[("femur", side)] = (R_femur, knee)
            frames[("tibia", side)] = (R_tibia, ankle)
            frames[("tibia_untorsioned", side)] = (R_untorsioned, ankle)
            frames[("foot_uncorrected", side)] = (R_uncorrected, points[p + "TOE"])
            if with_static_foot and np.isfinite(points.get(p + "HEE", np.nan)).any():
                frames[("foot_static", side)] = (cgm_static_foot_frame(
                    points[p + "HEE"], points[p + "TOE"], R_tibia), points[p + "TOE"])
            if offsets is not None:
                frames[("foot", side)] = (cgm_foot_frame(
                    R_uncorrected, offsets[long + "StaticPlantFlex"],
                    offsets[long + "StaticRotOff"], side), points[p + "TOE"])
        centres["PELO"] = (centres["LHJC"] + centres["RHJC"]) / 2.0
        frames[("pelvis", None)] = (R_pelvis, centres["PELO"])
        if upper_body:
            upper_centres, upper_frames = upper_body_geometry(points, subject)
            centres.update(upper_centres)
            frames.update(upper_frames)
        return centres, frames

    def track(self, dynamic):
        """Joint centres and segment frames of a trial.

        Parameters
        ----------
        dynamic : str, path-like or pandas.DataFrame
            A .c3d or .trc file, or a marker DataFrame from :func:`read_c3d` /
            :func:`read_trc` (its ``attrs['units']`` set).

        Returns
        -------
        PlugInGaitTrack
            Centres (comparable with Vicon's ``LFEO`` = knee centre, ``LTIO`` = ankle
            centre, ``PELO``), frames and the direction of progression.

        Raises
        ------
        ValueError
            If a marker the model needs is missing (or in no frame), a label is
            ambiguous (two subject prefixes), the units are unknown or wrong (the ASIS
            distance is not a pelvis's), the body is mirrored in every frame
            (:func:`check_handedness`), a leg marker is swapped or misplaced in every
            frame, or placed elsewhere than in the static trial, a TOE lies behind its
            ANK or a thigh wand medial to the thigh (in the median frame), or a
            measurement contradicts the markers 3-fold
            (:mod:`~bmc_functions.models.plug_in_gait.checks`), an upper-body marker
            is swapped in every frame (between the sides, CLAV and STRN, C7 and T10,
            along an arm) or far from the pelvis in every frame, or an arm measurement
            leaves its chord without solution
            (:mod:`~bmc_functions.models.plug_in_gait.upper_body_checks`).

        Warns
        -----
        RuntimeWarning
            Once per cause: frames with undefined segments (a marker missing there:
            their angles NaN), frames mirrored or with the legs' labels swapped (NaN
            there), a walkway more than ``PROGRESSION_WARN_DEG`` (20) degrees from the
            nearest lab axis; frames where a leg marker is on the wrong side, out of
            order or has jumped (that marker NaN there), points at (0, 0, 0) (gaps), a
            body's vertical more than 30 degrees from every lab axis
            (:mod:`~bmc_functions.models.plug_in_gait.checks`); frames where an
            upper-body marker is swapped or far from the body (those markers NaN
            there, and the angles that use them), doubtful arm measurements
            (:mod:`~bmc_functions.models.plug_in_gait.upper_body_checks`).
        UserWarning
            "another subject's trial?" when the trial's subject name differs from the
            static trial's or the subject file's, or its ASIS markers or its legs
            (ASI-KNE-ANK) contradict the subject's InterAsisDistance or LegLength
            (:func:`~bmc_functions.models.plug_in_gait.subject.check_same_subject`).
        """
        return self._track(dynamic, with_static_foot=True)

    def _track(self, dynamic, with_static_foot):
        df, points, flagged = self._landmarks(dynamic, "dynamic")
        check_same_subject(getattr(self, "subject_names", {}), self.subject, dynamic,
                           np.linalg.norm(points["LASI"] - points["RASI"], axis=-1),
                           self._trial, legs={
                               side: tuple(points[p + m] for m in ("ASI", "KNE", "ANK"))
                               for side, p in (("Left", "L"), ("Right", "R"))})
        centres, frames = self._geometry(points, self.static_offsets, with_static_foot)
        self._report_undefined(points, frames, flagged)
        _warn_upper_body_defaults(self.derived, frames)
        R_pelvis = frames[("pelvis", None)][0]
        progression = progression_frame(points["LASI"], R_pelvis)
        _warn_diagonal(centres["PELO"], progression, self._trial)
        names = ["PELO", "LHJC", "RHJC", "LKJC", "RKJC", "LAJC", "RAJC"] + [
            name for name in UPPER_BODY_CENTRES if name in centres]
        columns = pd.MultiIndex.from_product([names, ["x", "y", "z"]],
                                             names=["point", "coord"])
        table = pd.DataFrame(np.concatenate([centres[n] for n in names], axis=1),
                             index=df.index.copy(), columns=columns)
        table.attrs = {"units": "mm", "rate": df.attrs.get("rate")}
        return PlugInGaitTrack(table, frames, progression)

    def _report_undefined(self, points, frames, flagged):
        """One warning for the frames in which a segment of the trial is undefined (a
        marker missing there, or a chord without solution): their angles are NaN."""
        used = [name for name in self.markers if not name.endswith("HEE")
                and (name not in PELVIS_MARKERS[2:] or name in self._posterior)
                and (name not in UPPER_BODY_MARKERS or np.isfinite(points[name]).any())]
        # frames flagged by check_handedness were warned about there: not counted again
        gaps = {name: int((missing_rows(points[name]) & ~flagged).sum())
                for name in used}
        gaps = {name: count for name, count in gaps.items() if count}
        undefined = np.zeros(len(flagged), dtype=bool)
        for key, (R, _) in frames.items():
            if key[0] not in ("foot_uncorrected", "foot_static", "tibia_untorsioned"):
                undefined |= missing_rows(R.reshape(*R.shape[:-2], 9))
        undefined = int((undefined & ~flagged).sum())
        if undefined:
            cause = (", ".join(f"{name} missing in {count}" for name, count in gaps.items())
                     if gaps else "a chord without solution: a joint width wider than the "
                     "marker's distance to the proximal joint centre")
            warn_frames(undefined, len(flagged), f"have undefined segments ({cause}); their "
                        f"angles are NaN")

    def event_markers(self):
        """The mapping :func:`~bmc_functions.gait_events` takes, for the last trial read.

        Returns
        -------
        dict
            The package's roles -> the labels of the trial (``'RASIS'`` -> ``'RASI'``,
            ``'RPSIS'``/``'LPSIS'`` or ``'SACRUM'``, and per side ``'HEEL'`` (HEE),
            ``'TOE'``, ``'ANKLE_LAT'`` (ANK)), subject prefixes and `markers` renames
            included.

        Examples
        --------
        >>> from bmc_functions import gait_events, plug_in_gait
        >>> from bmc_functions.examples import example_file
        >>> trial = example_file("plug_in_gait/Movement_trial.c3d")
        >>> model = plug_in_gait(None, trial)
        >>> angles = model.angles(trial)
        >>> model.event_markers()["RHEEL"], model.event_markers()["LTOE"]
        ('RHEE', 'LTOE')
        """
        roles = {"RASI": "RASIS", "LASI": "LASIS", "RPSI": "RPSIS", "LPSI": "LPSIS",
                 "SACR": "SACRUM"}
        for p in "LR":
            roles.update({p + "HEE": p + "HEEL", p + "TOE": p + "TOE",
                          p + "ANK": p + "ANKLE_LAT"})
        posterior = getattr(self, "_posterior", ["LPSI", "RPSI"])
        return {roles[name]: label for name, label in self.markers.items()
                if name in roles and (name not in PELVIS_MARKERS[2:] or name in posterior)}

    def opensim_coordinates(self, angles):
        """:func:`~bmc_functions.opensim_coordinates` of this model's `angles` (for
        ``write_mot``): the pelvis renamed in OpenSim's order, tilt-obliquity-rotation,
        even when `angles` lost the ``attrs['model']`` that says so."""
        if isinstance(angles, pd.DataFrame) and not str(
                angles.attrs.get("model", "")).startswith("Plug-in Gait"):
            angles = angles.copy(deep=False)
            angles.attrs = {**angles.attrs, "model": "Plug-in Gait (Vicon)"}
        return opensim_coordinates(angles)

    def angles(self, dynamic, *, foot="dynamic"):
        """Plug-in Gait's angles of a trial (degrees), one row per frame.

        Parameters
        ----------
        dynamic : str, path-like or pandas.DataFrame
            As :meth:`track`.
        foot : {'dynamic', 'static'}, keyword-only
            'dynamic' (default): the foot of every Plug-in Gait trial, the ankle centre
            to TOE line turned by the static offsets. 'static': the foot Nexus's static
            processing reports in the static trial itself, whose long axis is the HEE-TOE
            line (the trial needs HEE); only the ankle and foot angles change.

        Returns
        -------
        pandas.DataFrame
            Columns ``(joint, side, angle)``: ``('pelvis', side, 'tilt' | 'obliquity' |
            'rotation')`` = Vicon's LPelvisAngles / RPelvisAngles X, Y, Z; ``('hip' |
            'knee', side, 'flexion' | 'adduction' | 'rotation')`` = HipAngles /
            KneeAngles X, Y, Z; ``('ankle', side, 'dorsiflexion' | 'inversion' |
            'rotation')`` = AnkleAngles X, Y, Z; ``('foot', side, 'progression')`` =
            FootProgressAngles Z. With Plug-in Gait's upper-body markers (FullBody),
            also ``('head' | 'thorax', side, 'tilt' | 'obliquity' | 'rotation')``,
            ``('neck' | 'spine', side, 'flexion' | 'lateral_flexion' | 'rotation')``,
            ``('shoulder', side, 'flexion' | 'abduction' | 'rotation')``, ``('elbow',
            side, 'flexion')`` and ``('wrist', side, 'flexion' | 'ulnar_deviation' |
            'rotation')`` = Vicon's HeadAngles ... WristAngles X, Y, Z (head, thorax,
            neck and spine once per side, as Vicon writes them): an upper-body angle is
            left out when a marker it needs is not in the trial (a trial without RFIN
            has everything but the right wrist). Indexed as the trial (time in s). NaN
            where a marker a segment needs is missing in a frame. ``attrs``: the
            model's :attr:`attrs` and the trial's ``'rate'`` (Hz).

        Raises
        ------
        ValueError
            As :meth:`track`.

        Notes
        -----
        See :func:`cgm_angles` for the decomposition and signs,
        :func:`~bmc_functions.models.plug_in_gait.upper_body.cgm_trunk_angles` and
        :func:`~bmc_functions.models.plug_in_gait.upper_body.cgm_arm_angles` for the
        upper body's.
        """
        check_choice(foot, "foot", ("dynamic", "static"))
        result = self._track(dynamic, with_static_foot=foot == "static")
        if foot == "static":
            missing = [side for side in SIDES if ("foot_static", side) not in result.frames]
            if missing:
                raise ValueError(f"foot='static' needs the HEE markers; the trial has none "
                                 f"on the {' and '.join(missing)} side")
            for side in SIDES:
                result.frames[("foot", side)] = result.frames[("foot_static", side)]
        table = self._angle_table(result.frames, result.progression, result.centres.index)
        table.attrs["rate"] = result.centres.attrs.get("rate")
        return table

    def thoracohumeral_angles(self, dynamic):
        """The ISB's thoracohumeral angles (Y-X-Y) of a trial's arms (degrees).

        Not Vicon's output: Wu et al.'s (2005) plane of elevation, elevation and axial
        rotation, read from Plug-in Gait's thorax and humerus with their axes renamed
        as the ISB's. :func:`~bmc_functions.models.plug_in_gait.thoracohumeral_angles`
        says how, and what that approximates: T10 for T8, STRN for PX, the chord elbow
        centre and the offset shoulder centre for the glenohumeral
        centre, no scapula; the left arm mirrored onto a right one.

        Parameters
        ----------
        dynamic : str, path-like or pandas.DataFrame
            As :meth:`track`; it needs the thorax markers and, per side, SHO, ELB, WRA and
            WRB.

        Returns
        -------
        pandas.DataFrame
            Columns ``(side, angle)``: ``side`` 'right' and/or 'left' (a side without
            its arm markers is left out), ``angle`` 'plane_of_elevation', 'elevation'
            (negative, the ISB's sign: -90 with the arm horizontal), 'axial_rotation'.
            Indexed as :meth:`angles`; NaN where a marker is missing in a frame.
            ``attrs``: the model's :attr:`attrs` and the trial's ``'rate'`` (Hz).

        Raises
        ------
        ValueError
            As :meth:`track`, and if the trial has no thorax or no arm.

        Examples
        --------
        The shipped stair descent, the arms hanging about 30° from the trunk, somewhat
        behind the frontal plane:

        >>> from bmc_functions import plug_in_gait
        >>> from bmc_functions.examples import example_file
        >>> model = plug_in_gait(example_file("plug_in_gait/Static_trial.c3d"),
        ...                      example_file("plug_in_gait/Test.vsk"))
        >>> arms = model.thoracohumeral_angles(example_file("plug_in_gait/Movement_trial.c3d"))
        >>> print(arms.mean().round(1).unstack().to_string())
        angle  axial_rotation  elevation  plane_of_elevation
        side
        left             51.6      -18.9               -43.6
        right            48.0      -30.2               -45.0
        """
        result = self._track(dynamic, with_static_foot=False)
        sides = [side for side in SIDES if ("humerus", side) in result.frames]
        if ("thorax", None) not in result.frames or not sides:
            lacking = "thorax" if ("thorax", None) not in result.frames else "arm"
            raise ValueError(f"dynamic: the thoracohumeral angles need the thorax markers "
                             f"({', '.join(THORAX_MARKERS)}) and one arm's (SHO, ELB, WRA, "
                             f"WRB with an L or R prefix); the trial has no {lacking}")
        R_thorax = result.frames[("thorax", None)][0]
        blocks = [thoracohumeral_angles(R_thorax, result.frames[("humerus", side)][0], side)
                  for side in sides]
        columns = pd.MultiIndex.from_product([sides, list(THORACOHUMERAL_ANGLES)],
                                             names=["side", "angle"])
        table = pd.DataFrame(np.concatenate(blocks, axis=1),
                             index=result.centres.index.copy(), columns=columns)
        table.attrs = {**self.attrs, "rate": result.centres.attrs.get("rate")}
        return table

    def kinetics(self, dynamic, *, force_plates=None, plates=None, body_mass=None):
        """Plug-in Gait's hip, knee and ankle forces, moments and powers, as Vicon's.

        Parameters
        ----------
        dynamic : str, path-like or pandas.DataFrame
            As :meth:`track`; a C3D path's force plates are read from it.
        force_plates : pandas.DataFrame, optional
            :func:`~bmc_functions.read_force_plates` of the trial (or
            :func:`~bmc_functions.resample_force_plates` of it); required when `dynamic`
            is a DataFrame.
        plates : dict, optional
            Plate number (from 1) -> 'right', 'left' or None (not used), as Vicon
            Nexus's force-plate settings assign them; plates not named keep the
            automatic assignment (:func:`~bmc_functions.assign_plates`: the foot that
            stands on the plate alone).
        body_mass : float, optional
            kg, from 0.2 to 650 (a mass in g, lb or tonnes is refused); default the
            subject's ``Bodymass``.

        Returns
        -------
        pandas.DataFrame
            Indexed as :meth:`angles`; columns ``(joint, side, quantity)``: joint
            ``'hip'``, ``'knee'``, ``'ankle'``; side ``'right'``, ``'left'``;
            quantity ``moment_x``, ``moment_y``, ``moment_z`` (N m/kg, Vicon's
            ``<S><Joint>Moment`` X, Y, Z / 1000), ``force_x``, ``force_y``, ``force_z``
            (N/kg, ``<S><Joint>Force``) and ``power`` (W/kg, ``<S><Joint>Power`` Z: the
            moment times the relative angular velocity as Plug-in Gait estimates it,
            :func:`~bmc_functions.models.plug_in_gait.kinetics.vicon_angular_velocity`;
            NaN in the first and last two frames).
            The loads on the distal segment in its frame, Vicon's components and signs
            (X positive for an internal hip extensor, knee extensor and ankle
            plantarflexor moment; :mod:`~bmc_functions.models.plug_in_gait.kinetics`).
            In swing, the segments' own gravity and inertia. ``attrs``: the model's,
            ``'body_mass_kg'``, ``'segments'`` (Dempster's fractions),
            ``'foot_length_m'``, ``'plates'`` (every contact: plate, side used, foot
            found, start, stop), ``'options'``.

        Raises
        ------
        ValueError
            If the subject has no ``Bodymass`` and `body_mass` is not given (or it is
            outside 0.2 to 650 kg: a mass in g, lb or tonnes), a DataFrame trial comes
            without `force_plates`, the plates' frames differ from the trial's, or
            `plates` names an unknown plate or side; as :meth:`track`.

        Warns
        -----
        RuntimeWarning
            Once, naming the stances on a plate not used for that foot (NaN there); the
            contacts :func:`~bmc_functions.assign_plates` leaves unassigned; as
            :meth:`track`.
        UserWarning
            If `body_mass` differs from the subject's ``Bodymass`` by more than 10 %
            (:data:`~bmc_functions.models.plug_in_gait.kinetics.BODY_MASS_AGREEMENT`).

        Examples
        --------
        >>> import warnings
        >>> from bmc_functions import plug_in_gait
        >>> from bmc_functions.examples import example_file
        >>> model = plug_in_gait(example_file("plug_in_gait/Static_trial.c3d"),
        ...                      example_file("plug_in_gait/Test.vsk"))
        >>> with warnings.catch_warnings():
        ...     warnings.simplefilter("ignore")
        ...     kin = model.kinetics(example_file("plug_in_gait/Movement_trial.c3d"),
        ...                          plates={2: None, 3: None})
        >>> kin.shape
        (323, 42)
        >>> print(round(kin["knee", "left", "moment_x"].max(), 2))
        0.57
        """
        return plug_in_gait_kinetics(self, dynamic, force_plates=force_plates,
                                     plates=plates, body_mass=body_mass)

    def _angle_table(self, frames, progression, index):
        per_side = {}
        # the segment frames are the model's own, orthonormal by construction: not re-tested
        upper = upper_body_angles(frames, progression, check=False)
        for side in SIDES:
            per_side[side] = cgm_angles(progression, frames[("pelvis", None)][0],
                                        frames[("femur", side)][0],
                                        frames[("tibia_untorsioned", side)][0],
                                        frames[("tibia", side)][0],
                                        frames[("foot", side)][0], side, check=False)
            per_side[side].update(upper[side])
        columns, blocks = [], []
        for joint, names in ALL_ANGLES.items():
            for side in SIDES:
                for name in names:
                    if (joint, name) in per_side[side]:
                        columns.append((joint, side, name))
                        blocks.append(per_side[side][(joint, name)])
        # levels in the columns' own order, so that the columns are lexsorted and
        # angles['knee', 'right'] selects without a sort or a PerformanceWarning
        levels = [[joint for joint in ALL_ANGLES if any(c[0] == joint for c in columns)],
                  list(SIDES),
                  [name for name in _ANGLE_ORDER if any(c[2] == name for c in columns)]]
        codes = [[level.index(column[k]) for column in columns]
                 for k, level in enumerate(levels)]
        table = pd.DataFrame(np.column_stack(blocks), index=index.copy(),
                             columns=pd.MultiIndex(levels=levels, codes=codes,
                                                   names=["joint", "side", "angle"]))
        table.attrs = dict(self.attrs)
        return table


def plug_in_gait(static, subject, *, markers=None, foot_flat=False):
    r"""Build Vicon's Plug-in Gait (the Conventional Gait Model) for a subject.

    Parameters
    ----------
    static : str, path-like, pandas.DataFrame or None
        The static trial (.c3d or .trc, or a marker DataFrame from :func:`read_c3d`). Its
        static processing computes the foot's static offsets (``StaticPlantFlex``,
        ``StaticRotOff``) and, when the subject does not give it, the inter-ASIS
        distance; with the knee alignment device on (markers ``LKAX``, ``LKD1``,
        ``LKD2`` and the right ones; KNE may be absent: the device's origin is taken as
        KNE), the wand offsets ``ThighRotation`` and ``ShankRotation`` of that side
        (replacing the subject's), and without it, when the subject gives a non-zero
        ``ThighRotation``, that side's ``ShankRotation`` (Vicon's "manual thigh
        offset" case); with a medial malleolus marker (the KAD-med static: ``LMED`` or
        ``LMMA``, and the right ones), the ankle centre midway between the malleoli and,
        measured from it, that side's ``ShankRotation``, ``AnkleAbAdd`` and
        ``TibialTorsion`` (replacing the subject's; without it that side's
        ``AnkleAbAdd`` is 0, as Vicon's static processing gives it, replacing a
        subject's non-zero value with a warning;
        :mod:`~bmc_functions.models.plug_in_gait.knee_alignment`). None: take them from
        `subject` (a .vsk or a dynamic C3D processed by Nexus holds them).
    subject : dict, str or path-like
        The subject measurements: a dict with Vicon's names, a ``.vsk`` subject file, or
        a ``.c3d`` file whose PROCESSING group holds them (Nexus writes them there).
        Lengths in mm, angles in radians, as Vicon stores them. Required:
        ``LeftLegLength``, ``RightLegLength`` (ASIS to medial malleolus),
        ``LeftKneeWidth``, ``RightKneeWidth``, ``LeftAnkleWidth``, ``RightAnkleWidth``
        (the C3D's ``LLegLength``, ``RKneeWidth``, ... are accepted). Optional:
        ``MarkerDiameter`` (default 14 mm), ``InterAsisDistance`` (default: from the
        static trial), ``Bodymass`` (kg; needed by :meth:`PlugInGait.kinetics`),
        ``LeftAsisTrocanterDistance`` (default
        :math:`0.1288\,L - 48.56`), ``LeftTibialTorsion`` (default 0),
        ``LeftThighRotation`` and ``LeftShankRotation`` (the knee alignment device's wand
        offsets, radians with Vicon's signs, applied to the chord function in every trial;
        default 0 or from the static trial's device), ``LeftAnkleAbAdd`` (the KAD-med
        static's ankle abduction, radians, the same sign on both sides, positive with the
        lateral malleolus below the medial: the ankle centre is turned about ANK by it in
        every trial; default 0 or from the static's medial markers), and, without a
        static trial, ``LeftStaticPlantFlex`` and ``LeftStaticRotOff`` (required then).
        The upper body (used when a trial has its markers): ``LeftShoulderOffset``,
        ``LeftElbowWidth``, ``LeftWristWidth``, ``LeftHandThickness`` and the right ones
        (mm; Vicon's template defaults 50, 80, 40 and 30 mm when absent, with a warning),
        ``HeadOffset`` (radians about the head's y axis, default 0); any case and
        ``L``/``R`` short forms are accepted (``LSHOULDEROFFSET``).
    markers : dict, optional
        Standard Plug-in Gait name -> the label in your files (``{'LASI': 'L.ASIS'}``).
        Without it a label equal to the standard name is used, or ``'Prefix:LASI'`` when
        the files carry one subject prefix, or else the one label that differs from it
        only in case (``'lasi'``). The pelvis needs LPSI and RPSI, or SACR (the midpoint
        of LPSI and RPSI is used when both are there, SACR in the frames where one of
        them is missing). The upper body's names (LFHD RFHD LBHD RBHD, C7 T10 CLAV STRN,
        L/R + SHO ELB WRA WRB FIN) are optional and renamed the same way, as are the
        knee alignment device's (L/R + KAX KD1 KD2, read in the static trial).
    foot_flat : bool or {'left', 'right'}, optional
        Vicon's static processing option "foot flat" (True: both feet; or one side): the
        static trial's heel is taken at the toe's height plus ``LeftSoleDelta``
        (``RightSoleDelta``; mm, heel minus toe sole thickness, default 0) along the lab
        vertical before the foot's static offsets are computed (the heel-toe line then
        horizontal, or inclined by the sole). Default False (the heel as recorded).

    Returns
    -------
    PlugInGait
        ``model.angles(dynamic)`` gives the angles, ``model.track(dynamic)`` the joint
        centres and segment frames; ``model.subject``, ``model.derived``,
        ``model.static_offsets`` and ``model.attrs`` record every value used.

    Raises
    ------
    ValueError
        If a required measurement is missing (each one named), a measurement is not a
        positive number, with a static trial ``SoleDelta`` is non-zero without the
        foot-flat option (Vicon applies it only with it), ``AnkleAbAdd`` lies beyond pi/2
        (degrees), a medial ankle marker lies lateral to ANK or 3 times too far from or
        too near it (``AnkleWidth`` + ``MarkerDiameter``), or both ``LMED`` and ``LMMA``
        are given,
        a marker is missing or its label ambiguous, the static trial leaves the static
        offsets undefined, a trial's declared units are wrong (its ASIS distance is not a
        pelvis's), every frame of a trial is mirrored (a lab axis reversed, left and
        right labels swapped: :func:`check_handedness`), a measurement is impossible (a
        unit error) or contradicts the markers 3-fold, the static trial's leg markers
        are swapped (heel and toe, the heels, the knees), or a toe marker lies behind its
        ankle marker or a thigh wand medial to the thigh: see
        :mod:`~bmc_functions.models.plug_in_gait.checks`; an upper-body measurement is
        impossible (``HeadOffset`` beyond pi/2: degrees), or a chord's offset is longer
        than its marker's distance to the proximal joint centre, or the static trial's
        upper-body markers are swapped in every frame: see
        :mod:`~bmc_functions.models.plug_in_gait.upper_body_checks`.
    TypeError
        If `subject` is not a dict or a path, or `markers` is not a dict.

    Warns
    -----
    RuntimeWarning
        If the static trial is not static (a marker travels more than 100 mm, or the
        pelvis turns more than 10 degrees: its offsets are means over the frames), or
        some of its frames are mirrored (:func:`check_handedness`; left out); a medial
        ankle marker 1.5 times too far from or too near ANK, or in no frame (not used);
        an ``AnkleAbAdd`` beyond 0.6 rad (given or measured), or a subject's non-zero
        ``AnkleAbAdd`` replaced by 0 (a static trial without medial ankle markers).

    Notes
    -----
    The steps and their sources are in the module's docstring
    (:mod:`bmc_functions.models.plug_in_gait`): Davis et al. (1991) hip centre,
    Kadaba et al. (1990) segment definitions, Vicon's Plug-in Gait guide for the chord
    function, tibial torsion, the foot's static offsets and the pelvis and foot
    progression angles. On the shared Plug-in Gait trial processed by Vicon Nexus 2.6
    (``data/real/plug_in_gait``) every angle curve agrees with Vicon's within 1e-4°
    RMS and the joint centres within 1e-3 mm (``tests/test_plug_in_gait.py``).

    Examples
    --------
    >>> from bmc_functions import plug_in_gait
    >>> from bmc_functions.examples import example_file   # data/real/plug_in_gait, shipped
    >>> model = plug_in_gait(example_file("plug_in_gait/Static_trial.c3d"),
    ...                      example_file("plug_in_gait/Test.vsk"))
    >>> round(model.static_offsets["LeftStaticPlantFlex"], 4)
    0.2527
    >>> angles = model.angles(example_file("plug_in_gait/Movement_trial.c3d"))
    >>> angles.shape   # the lower body's 26 curves and the upper body's 38 (FullBody markers)
    (323, 64)
    >>> print(angles["knee", "right", "flexion"].iloc[:3].round(2).to_list())
    [86.97, 86.52, 85.82]
    """
    if markers is None:
        markers = {}
    if not isinstance(markers, dict) or not all(isinstance(v, str) for v in markers.values()):
        raise ArgumentTypeError(f"markers must be a dict of standard name -> your label (a "
                                f"str); got {markers!r:.80}")
    unknown = [name for name in markers if name not in PELVIS_MARKERS
               and name[1:] not in LEG_MARKERS + KAD_MARKERS + MEDIAL_ANKLE_MARKERS
               and name not in UPPER_BODY_MARKERS]
    if unknown:
        raise ValueError(f"markers: unknown Plug-in Gait name(s) {', '.join(map(str, unknown))};"
                         f" expected names from LASI RASI LPSI RPSI SACR and L/R + THI KNE "
                         f"TIB ANK HEE TOE (KAX KD1 KD2: the knee alignment device; MED or "
                         f"MMA: the medial malleolus, KAD-med), or of the "
                         f"upper body LFHD RFHD LBHD RBHD C7 T10 CLAV STRN and L/R + SHO ELB "
                         f"WRA WRB FIN")
    if static is not None and not isinstance(static, (str, Path, pd.DataFrame)):
        raise ArgumentTypeError(f"static must be a path, a marker DataFrame or None; got "
                                f"{type(static).__name__}")
    if not (foot_flat is True or foot_flat is False
            or (isinstance(foot_flat, str) and foot_flat in ("left", "right"))):
        raise ArgumentTypeError(f"foot_flat must be True, False, 'left' or 'right'; got "
                                f"{foot_flat!r:.60}")
    flat_sides = (("left", "right") if foot_flat is True else () if foot_flat is False
                  else (foot_flat,))
    raw, source = load_subject(subject)
    used, derived = check_subject(raw, source, static is not None, flat_sides)
    checks.check_measurement_ranges(used, source, ranges={
        **checks.MEASUREMENT_RANGES, **upper_body_checks.UPPER_BODY_RANGES})
    used.update({"Bodymass": float(value) for name, value in raw.items()
                 if name.lower() == "bodymass"})     # for kinetics
    model = PlugInGait(subject=used, derived=derived, static_offsets={},
                       rename=dict(markers))
    model.subject_names = subject_names(static, subject)   # for check_same_subject
    model.foot_flat = flat_sides if static is not None else ()
    if static is not None:
        _static_processing(model, static)
    else:
        model.static_offsets = {side + what: used[side + what] for side in ("Left", "Right")
                                for what in ("StaticPlantFlex", "StaticRotOff")}
    model.attrs = {
        "model": "Plug-in Gait (Conventional Gait Model 1.0; the upper body where its "
                 "markers are)",
        "references": ["Davis et al. 1991, Hum Mov Sci 10:575 (hip centre)",
                       "Kadaba et al. 1990, J Orthop Res 8:383 (segments)",
                       "Vicon Plug-in Gait reference guide (chord function, offsets, "
                       "upper body kinematics)"],
        "subject_source": source,
        "static": "static trial" if static is not None else "offsets from the subject",
        "measurements": dict(model.subject),
        "derived": dict(model.derived),
        "static_offsets": dict(model.static_offsets),
        "marker_diameter_mm": model.subject["MarkerDiameter"],
        "head_level_offset": model.head_level_offset,
        "foot_flat": list(model.foot_flat),
        "units": "degrees (angles); mm and radians (measurements)",
    }
    return model


def _check_still(model, df):
    """One warning if the static trial is not static (a marker travels more than 100 mm
    from its median position, or the pelvis markers turn by more than 10 degrees): the
    static offsets are means over its frames. The ISB pipeline's check
    (:func:`~bmc_functions.models.lower_limb_checks.check_still`), on the Plug-in Gait labels."""
    # check_still finds the pelvis by the lower-limb roles (pelvis_roles): Plug-in Gait's
    # pelvis markers are given those roles beside their own names
    posterior = ({"SACRUM": "SACR"} if model._posterior == ["SACR"]
                 else {"RPSIS": "RPSI", "LPSIS": "LPSI"})
    roles = {"RASIS": "RASI", "LASIS": "LASI", **posterior}
    markers = {**model.markers, **{role: model.markers[name] for role, name in roles.items()}}
    scale, _ = mm_per_unit(df, model._trial)
    check_still(markers, MarkerTable(df, model._trial), scale, model._trial)


def _find_label(df, name, rename):
    """The label of an optional marker `name` (renamed, exact, 'Prefix:NAME' or another
    case), or None when absent or ambiguous."""
    labels = list(dict.fromkeys(df.columns.get_level_values(0)))
    if name in rename:
        return rename[name] if rename[name] in labels else None
    if name in labels:
        return name
    found = [label for label in labels if label.rsplit(":", 1)[-1].upper() == name]
    return found[0] if len(found) == 1 else None


def _with_kad_knees(model, static):
    """The static trial with KNE set to the knee alignment device's origin on each side
    whose device markers (KAX, KD1, KD2) are there (:func:`kad_knee_marker`), and the
    sides found; the trial itself when there is no device."""
    with warnings.catch_warnings():      # read again, and warned about, by _landmarks
        warnings.simplefilter("ignore")
        df, _ = load_trial(static, "static")
    found = {}
    for side in SIDES:
        p = SIDE_PREFIX[side]
        labels = [_find_label(df, p + name, model.rename) for name in KAD_MARKERS]
        if all(labels):
            found[side] = labels
    if not found:
        return static, {}
    df = df.copy()
    for side, labels in found.items():
        xyz = [df[label][["x", "y", "z"]].to_numpy(dtype=float) for label in labels]
        knee = kad_knee_marker(*xyz, side)
        label = (model.rename.get(SIDE_PREFIX[side] + "KNE")
                 or labels[0][:len(labels[0]) - 3] + "KNE")      # the device's prefix
        for k, coord in enumerate("xyz"):
            df[(label, coord)] = knee[:, k]
    return df, found


def _medial_ankle_markers(model, df, points):
    """The medial malleolus markers of the KAD-med static (``MED``, as pyCGM2 names them,
    or ``MMA``; renamed with `markers=` as the others), side -> (frames, 3) mm, checked
    against ANK (:func:`_check_medial_ankle`); a side without one is left out."""
    scale, _ = mm_per_unit(df, model._trial)
    found = {}
    for side in SIDES:
        p = SIDE_PREFIX[side]
        labels = [label for label in (_find_label(df, p + name, model.rename)
                                      for name in MEDIAL_ANKLE_MARKERS) if label]
        if not labels:
            continue
        if len(labels) > 1:
            raise ValueError(f"static: both {' and '.join(labels)} found: give one medial "
                             f"ankle marker per side (or name it with markers=)")
        medial = MarkerTable(df, model._trial).points(labels[0], scale)
        if not np.isfinite(medial).all(axis=1).any():
            warn(f"static: {labels[0]} (the medial ankle marker) is in no frame: "
                 f"{SIDE_NAME[side]}AnkleAbAdd and the tibial torsion are not measured",
                 RuntimeWarning)
            continue
        _check_medial_ankle(points, medial, model.subject, side, labels[0])
        found[side] = medial
    return found


def _check_medial_ankle(points, medial, subject, side, label):
    """A ValueError if the medial ankle marker lies lateral to ANK (along the pelvis's
    left-right axis, in the median frame: swapped with ANK, or the other side's), or its
    distance to ANK contradicts AnkleWidth + MarkerDiameter 3-fold; a warning beyond 1.5
    (:data:`~bmc_functions.models.plug_in_gait.checks.AGREEMENT_RATIO`)."""
    p, long = SIDE_PREFIX[side], SIDE_NAME[side]
    lateral = (points["LASI"] - points["RASI"]) * (1.0 if side == "left" else -1.0)
    with np.errstate(invalid="ignore"):
        across = np.nanmedian(np.sum((medial - points[p + "ANK"]) * lateral, axis=1)
                              / np.linalg.norm(lateral, axis=1))
        distance = np.nanmedian(np.linalg.norm(medial - points[p + "ANK"], axis=1))
    if across > 0:
        raise ValueError(f"static: {label} lies {across:.0f} mm lateral to {p}ANK (median "
                         f"frame, along RASI-LASI): a medial ankle marker must be medial; "
                         f"swapped with {p}ANK, or the other side's?")
    expected = subject[long + "AnkleWidth"] + subject["MarkerDiameter"]
    ratio = max(distance / expected, expected / distance)
    what = (f"static: {label} is {distance:.0f} mm from {p}ANK (median frame), "
            f"{long}AnkleWidth + MarkerDiameter = {expected:.0f} mm")
    if ratio > checks.AGREEMENT_RATIO[1]:
        raise ValueError(f"{what}: {ratio:.1f} times off (a unit error, or another "
                         f"marker labelled {label}?)")
    if ratio > checks.AGREEMENT_RATIO[0]:
        warn(f"{what}: {ratio:.1f} times off; the ankle centre is taken midway between "
             f"them", RuntimeWarning)


def _no_medial_no_abadd(model, medial):
    """A side without a medial ankle marker: the static processing's ``AnkleAbAdd`` is 0,
    replacing a subject's non-zero value (with a warning). Vicon's subject template marks
    ``AnkleAbAdd`` read-only, as ``StaticPlantFlex``: an output of the static processing,
    not an input; pyCGM2 measures it in every static (``getAbdAddAnkleJointOffset``),
    which gives 0 for the chord function's ankle centre (ANK - centre perpendicular to
    the long axis)."""
    replaced = []
    for side in SIDES:
        name = SIDE_NAME[side] + "AnkleAbAdd"
        if side not in medial and model.subject.get(name, 0.0) != 0.0:
            replaced.append(f"{name} = {model.subject[name]:g}")
            model.subject[name] = model.derived[name] = 0.0
    if replaced:
        warn(f"static: the subject's {' and '.join(replaced)} replaced by 0: the static "
             f"trial has no medial ankle marker (LMED/LMMA, RMED/RMMA) on that side, and "
             f"Vicon's static processing computes AnkleAbAdd from it (0 without); give "
             f"static=None to apply the subject's value", RuntimeWarning)


def _static_knee(model, df, points, side, found, hip):
    """The static's knee centre and the shank's wand: with the device KAX (knee from the
    chord function through it), else KNE (knee with the subject's ThighRotation)."""
    p, long = SIDE_PREFIX[side], SIDE_NAME[side]
    delta = model.subject[long + "KneeWidth"] / 2.0 + model.subject["MarkerDiameter"] / 2.0
    if side in found:
        scale, _ = mm_per_unit(df, model._trial)
        wand = MarkerTable(df, model._trial).points(found[side][0], scale)   # KAX
        return chord_joint_centre(wand, hip, points[p + "KNE"], delta), wand
    thigh = model.subject.get(long + "ThighRotation", 0.0)
    return rotated_chord_joint_centre(points[p + "THI"], hip, points[p + "KNE"], delta,
                                      wand_offset_from_vicon(thigh, side)), points[p + "KNE"]


def _static_wand_offsets(model, df, points, found, medial):
    """Vicon's static processing of the knee alignment offsets (radians, Vicon's signs),
    per side, replacing the subject's values (as Nexus does); returns the ankle centres
    measured (side -> (frames, 3)) for the static's own geometry:

    - with the knee alignment device (`found`: side -> its labels): the knee centre is
      the chord function's with KAX as the wand; ``ThighRotation`` is measured;
    - without it but with a non-zero ``ThighRotation`` from the subject (Plug-in Gait's
      "manual thigh offset"): the knee centre with that offset;
    - with a medial ankle marker (`medial`, KAD-med): the ankle centre midway between
      the malleoli markers; ``AnkleAbAdd`` (:func:`ankle_abadd_offset`) and
      ``TibialTorsion`` (:func:`tibial_torsion_offset`, femur against tibia) measured;
      without it (device or manual thigh offset) the ankle centre is the chord function's
      with the shank's wand (KAX, or KNE) turned by the tibial torsion;
    - then ``ShankRotation`` is measured from that ankle centre; with none of the three,
      nothing (the subject's values, or 0).

    Sources: pyCGM2's ``Kad``, ``Cgm1ManualOffsets`` and ``AnkleCalibrationDecorator.
    midMaleolus`` decorators and ``getAbdAddAnkleJointOffset`` / ``getTibialTorsionOffset``
    (:mod:`~bmc_functions.models.plug_in_gait.knee_alignment`)."""
    centres, ankles = None, {}
    radius = model.subject["MarkerDiameter"] / 2.0
    for side in SIDES:
        p, long = SIDE_PREFIX[side], SIDE_NAME[side]
        thigh = model.subject.get(long + "ThighRotation", 0.0)
        if side not in found and side not in medial and thigh == 0.0:
            continue
        if centres is None:
            centres, _ = model._geometry(points, None)
        hip, ank = centres[p + "HJC"], points[p + "ANK"]
        knee, wand = _static_knee(model, df, points, side, found, hip)
        measured = {}
        if side in found:
            measured[long + "ThighRotation"] = vicon_wand_offset(wand_rotation_offset(
                points[p + "THI"], hip, points[p + "KNE"], knee), side)
        if side in medial:
            ankle = ankles[side] = (ank + medial[side]) / 2.0
            R_femur = cgm_femur_frame(hip, knee, points[p + "KNE"], side)
            R_tibia = cgm_tibia_frame(knee, ankle, ank, side)[0]
            measured[long + "AnkleAbAdd"] = ankle_abadd_offset(knee, ankle, ank)
            measured[long + "TibialTorsion"] = tibial_torsion_offset(R_femur, R_tibia, side)
        else:
            ankle = rotated_chord_joint_centre(
                wand, knee, ank, model.subject[long + "AnkleWidth"] / 2.0 + radius,
                wand_offset_from_vicon(model.subject[long + "TibialTorsion"], side))
        measured[long + "ShankRotation"] = vicon_wand_offset(wand_rotation_offset(
            points[p + "TIB"], knee, ank, ankle), side)
        for name, value in measured.items():
            model.subject[name] = model.derived[name] = float(np.nanmean(value))
        checks.check_measurement_ranges({name: model.subject[name] for name in measured},
                                        "static")
    return ankles


def _static_processing(model, static):
    """Plug-in Gait's static processing: inter-ASIS distance (if needed), the knee
    alignment device's offsets (when its markers are there), foot offsets."""
    static, kad = _with_kad_knees(model, static)
    df, points, _ = model._landmarks(static, "static")
    _check_still(model, df)
    missing = [p + "HEE" for p in "LR" if not np.isfinite(points.get(p + "HEE", np.nan)).any()]
    if missing:
        raise ValueError(f"static: missing Plug-in Gait marker(s) {', '.join(missing)}: the "
                         f"static processing needs HEE for the foot's offsets; without "
                         f"them give static=None and a subject that holds the offsets (the "
                         f".vsk or a C3D Nexus processed), or rename the heel markers with "
                         f"markers={{'LHEE': ..., 'RHEE': ...}}")
    if "InterAsisDistance" not in model.subject:
        distance = np.linalg.norm(points["LASI"] - points["RASI"], axis=-1)
        model.subject["InterAsisDistance"] = float(np.nanmean(distance))
        model.derived["InterAsisDistance"] = model.subject["InterAsisDistance"]
    medial = _medial_ankle_markers(model, df, points)
    _no_medial_no_abadd(model, medial)
    ankles = _static_wand_offsets(model, df, points, kad, medial)
    _, frames = model._geometry(points, None, ankles=ankles)
    if ("head", None) in frames:   # what Vicon's "head level" option would compute
        R_head = frames[("head", None)][0] @ rot_y(-model.subject["HeadOffset"])
        model.head_level_offset = head_level_offset(
            R_head, progression_frame(points["LASI"], frames[("pelvis", None)][0]))
    offsets = {}
    for side in SIDES:
        long, p = SIDE_NAME[side], SIDE_PREFIX[side]
        R_tibia = frames[("tibia", side)][0]
        heel = points[p + "HEE"]
        if side in model.foot_flat:   # the heel at the toe's height + the sole's delta
            up = progression_frame(points["LASI"], frames[("pelvis", None)][0])[:, 2]
            rise = (points[p + "TOE"] - heel) @ up + model.subject[long + "SoleDelta"]
            heel = heel + rise[:, None] * up
        R_static = cgm_static_foot_frame(heel, points[p + "TOE"], R_tibia)
        plantar, rotation = static_foot_offsets(frames[("foot_uncorrected", side)][0],
                                                R_static, side)
        offsets[long + "StaticPlantFlex"], offsets[long + "StaticRotOff"] = plantar, rotation
    checks.check_measurement_ranges(offsets, "static")
    model.calibration = checks.leg_calibration(points)
    model.static_offsets = offsets
    model.subject.update(offsets)
    model.derived.update(offsets)
