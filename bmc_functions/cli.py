r"""The command line: ``bmc-kinematics`` (or ``python -m bmc_functions``).

One command per folder of trials, as a lab runs it::

    bmc-kinematics angles --static static.trc --markers markers.toml walk*.trc -o results
    bmc-kinematics angles --model plug-in-gait --static Static.c3d --subject Subject.vsk \
        Walk*.c3d -o results
    bmc-kinematics angles --static static.trc --markers markers.toml walk*.trc \
        --kinetics --forces "{stem}_grf.mot" --body-mass 70 -o results
    bmc-kinematics events --markers markers.toml walk*.trc -o results
    bmc-kinematics events --model plug-in-gait Walk*.c3d -o results   # no mapping file
    bmc-kinematics cycles --model plug-in-gait --static Static.c3d --subject Subject.vsk \
        --events stored Walk*.c3d -o results          # the events stored with the trials
    bmc-kinematics cycles --static static.trc --markers markers.toml walk*.trc -o results
    bmc-kinematics cycles ... --normative normal.csv walk*.trc    # + the GPS, the band
    bmc-kinematics angles --model plug-in-gait ... --c3d Walk*.c3d  # + <stem>.c3d
    bmc-kinematics cycles --model plug-in-gait --static Static.c3d --subject Subject.vsk \
        --kinetics --normative normal.csv Walk*.c3d -o report   # + moments and powers
    bmc-kinematics convert trial.c3d                     # -> trial.trc
    bmc-kinematics convert results/walk1_angles.csv --to mot

Every trial is run on its own: an error names the file on stderr and the next trial goes
on; the exit status is 0 only if every trial succeeded (1 otherwise, 2 for a wrong
command line). Per trial the outputs sit in the output folder under the file's stem, with
a small JSON record of what was run (the command, the options, the marker mapping, the
subject's measurements from the static trial, the warnings, the package version): what a
methods appendix states. The static trial given as a trial too (the file of --static) has
no events (no event warning, no events file) and, with Plug-in Gait, Nexus's static foot.

A body model is one entry of :data:`MODELS` (``--model``): a function that takes the parsed
command line and returns the calibrated model, which has ``angles(trial)``, and the
subject's measurements. The ISB lower-limb pipeline (:func:`calibrate_lower_limb`) is
``isb``; Vicon's Plug-in Gait (:func:`plug_in_gait`, with the subject file of
``--subject``) is ``plug-in-gait``.
"""

import argparse
import glob
import json
import platform
import sys
import textwrap
import warnings
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import pandas as pd
from tqdm.auto import tqdm

# matplotlib is imported only where a figure is drawn or the backend chosen (in main,
# _save_figure): pyplot takes about a second to import, which `events` and `convert`,
# drawing nothing, need not pay. The package itself (and so every model) is loaded
# anyway by the time this module runs: its imports are at the top.
from . import __version__
from ._checks import warn
from .dynamics.segment_parameters import MAX_BODY_MASS
from .files.c3d import read_c3d
from .files.c3d_parameters import read_c3d_parameters
from .files.c3d_writer import write_c3d
from .files.opensim import read_mot, write_mot
from .files.trc import read_trc, write_trc
from .gait.cycles import ensemble, normalize_by_side, spatiotemporal_parameters
from .gait.event_files import read_events
from .gait.events import gait_events
from .gait.gait_profile import gait_profile_score, read_normative_data
from .markers.roles import read_marker_mapping
from .models.keypoint_sets import KEYPOINT_SETS
from .models.keypoints import keypoint_angles
from .models.lower_limb import calibrate_lower_limb
from .models.plug_in_gait import plug_in_gait
from .models.plug_in_gait.labels import trial_event_markers
from .plotting import plot_angles, plot_gait_cycles

EXAMPLE = """\
example (a subject's static trial, its walks, and the lab's marker names):

  markers.toml, one line per role (the roles: help(bmc_functions.calibrate_lower_limb)):
      RASIS = "R.ASIS"
      LASIS = "L.ASIS"
      SACRUM = "V.Sacral"
      RTHIGH = ["R.TH1", "R.TH2", "R.TH3"]
      RKNEE_LAT = "R.Knee"
      RKNEE_MED = "R.MKnee"
      ...                       (the same with an L for the left side; JSON or YAML too)

  bmc-kinematics angles --static static.trc --markers markers.toml "walk*.trc" -o results

  writes, for walk1.trc: results/walk1_angles.mot (OpenSim's coordinate names),
  results/walk1_angles.csv, results/walk1_events.csv, results/walk1_angles.png and
  results/walk1_angles.json (options, subject measurements, warnings, version).

  --kinetics --body-mass 70 adds results/walk1_kinetics.csv and _kinetics.png (hip, knee
  and ankle moments, forces and powers per kg). The ground loads of each trial: a C3D
  trial's own force plates, or --forces, an OpenSim external-loads .mot, in which {stem}
  stands for the trial's name (--forces "{stem}_grf.mot": walk1_grf.mot for walk1.trc).
  The record gains the loads used, the segment parameters and which load went to which
  foot.

example (Vicon's Plug-in Gait: the standard marker names, "Sub01:LASI" too; no mapping):

  bmc-kinematics angles --model plug-in-gait --static Static.c3d --subject Subject.vsk \
      "Walk*.c3d" -o results

  --subject: the .vsk, or a C3D processed by Nexus (its PROCESSING group), or a TOML/JSON
  file of Vicon's names (LeftLegLength = 877.0, LeftKneeWidth = 144.0, ...). Without
  --static the static offsets come from the subject, e.g. the trial itself:
  bmc-kinematics angles --model plug-in-gait --subject Walk1.c3d Walk1.c3d
  The record (.json) holds every measurement used and every value derived.

  --kinetics: Plug-in Gait's hip, knee and ankle moments, forces and powers (Vicon's
  components, per kg) from each C3D trial's own force plates, the body mass the subject's
  Bodymass (--body-mass overrides it); --plates 1,4 uses those plates only, as Nexus's
  force plate settings do (N=left or N=right gives a plate to a foot). A trial without
  plates is named and its kinetics skipped. cycles --kinetics adds the moments and powers
  to each trial's report figure (against the normal band where --normative has them) and
  writes <stem>_kinetics_cycles.csv; angles --kinetics --c3d writes them into the copy
  as Vicon's LKneeMoment (N·mm/kg), LKneeForce, LKneePower:

  bmc-kinematics cycles --model plug-in-gait --static Static.c3d --subject Subject.vsk \
      --kinetics --plates 1,4 --normative normal.csv "Walk*.c3d" -o report

example (video keypoints, e.g. Pose2Sim's TRC files; no mapping, no static needed):

  bmc-kinematics angles --keypoints body25b "trial*.trc" -o results

  --keypoints: body25b (Pose2Sim's default), halpe26, coco17 (no feet) or blazepose; the
  angles of keypoint_angles (pelvis, hip, knee, ankle, trunk, shoulder, elbow), written as
  for markers. With --static and --static-offset, relative to the standing trial.
"""


# --- the models -----------------------------------------------------------------------------

def _isb_model(args, static):
    """The ISB lower-limb pipeline, calibrated on the static trial."""
    if args.markers is None:
        raise ValueError("--model isb needs --markers (the marker mapping file)")
    if getattr(args, "subject", None) is not None:
        raise ValueError("--subject belongs to --model plug-in-gait (the ISB model takes "
                         "its measurements from the static trial's markers)")
    markers = read_marker_mapping(args.markers)
    options = {"hip_centre": args.hip_centre, "static_offset": args.static_offset}
    if args.sides:
        options["sides"] = tuple(args.sides.split(","))
    model = calibrate_lower_limb(static, markers, **options)
    return model, markers, _isb_measurements(model)


def _isb_measurements(model):
    """Segment lengths and widths (mm) of the static trial's landmarks."""
    points = model.landmarks
    if points.empty:
        return {}

    def distance(a, b):
        if a in points.index and b in points.index:
            return round(float(np.linalg.norm(points.loc[a] - points.loc[b])), 1)
        return None

    def middle(a, b):
        return (points.loc[a] + points.loc[b]) / 2 if {a, b} <= set(points.index) else None

    out = {"units": "mm", "pelvis_width_asis": distance("RASIS", "LASIS")}
    for side in model.sides:
        prefix = side[0].upper()
        knee = middle(prefix + "KNEE_LAT", prefix + "KNEE_MED")
        ankle = middle(prefix + "ANKLE_LAT", prefix + "ANKLE_MED")
        hip = points.loc[prefix + "HJC"] if prefix + "HJC" in points.index else None
        out[side] = {
            "thigh_length": None if hip is None or knee is None
            else round(float(np.linalg.norm(hip - knee)), 1),
            "shank_length": None if knee is None or ankle is None
            else round(float(np.linalg.norm(knee - ankle)), 1),
            "knee_width": distance(prefix + "KNEE_LAT", prefix + "KNEE_MED"),
            "ankle_width": distance(prefix + "ANKLE_LAT", prefix + "ANKLE_MED"),
            "foot_length": distance(prefix + "HEEL", prefix + "TOE"),
        }
    out["static_angles_deg"] = {".".join(key): round(float(value), 2)
                                for key, value in model.static_angles.items()
                                if np.isfinite(value)}
    return out


def _plug_in_gait_model(args, static):
    """Vicon's Plug-in Gait (the Conventional Gait Model) of the subject of --subject."""
    if args.subject is None:
        raise ValueError("--model plug-in-gait needs --subject: the subject's .vsk, a C3D "
                         "whose PROCESSING group holds the measurements (a trial processed "
                         "by Nexus), or a TOML/JSON file of Vicon's names (LeftLegLength = "
                         "877.0, ...)")
    if args.hip_centre != "harrington" or args.static_offset or args.sides:
        raise ValueError("--hip-centre, --static-offset and --sides belong to --model isb; "
                         "Plug-in Gait has its own hip centre (Davis et al. 1991) and "
                         "computes both sides")
    markers = read_marker_mapping(args.markers) if args.markers else None
    model = plug_in_gait(static, args.subject, markers=markers)
    return model, markers or {}, dict(model.attrs)


class KeypointModel:
    """:func:`keypoint_angles` as a command-line model: ``angles(trial)`` of one keypoint
    set, relative to the static trial with --static-offset."""

    def __init__(self, keypoints, static, relative_to_static):
        self.keypoints, self.static = keypoints, static
        self.relative_to_static = relative_to_static

    #: Why there are no gait events (gait_events needs pelvis markers behind the hips).
    no_events = ("events not computed: gait_events needs the pelvis' posterior markers "
                 "(PSIS or sacrum), which keypoints do not have")

    def angles(self, trial):
        return keypoint_angles(trial, self.keypoints, static=self.static,
                               relative_to_static=self.relative_to_static)


def _keypoint_model(args, static):
    """keypoint_angles on the video keypoints of --keypoints (a keypoint set's name)."""
    if getattr(args, "keypoints", None) is None:
        raise ValueError("--model keypoints needs --keypoints: the keypoint set "
                         f"({', '.join(KEYPOINT_SETS)})")
    given = [option for option, value in (("--markers", args.markers),
                                          ("--subject", getattr(args, "subject", None)),
                                          ("--sides", args.sides)) if value]
    if args.hip_centre != "harrington":
        given.append("--hip-centre")
    if given:
        raise ValueError(f"{', '.join(given)} belong(s) to the marker models; keypoints "
                         "name their own joints (--keypoints)")
    if args.static_offset and static is None:
        raise ValueError("--static-offset needs --static (a standing trial of the same "
                         "keypoints)")
    model = KeypointModel(args.keypoints, static, args.static_offset)
    return model, {}, {"keypoints": args.keypoints}


#: --model name -> (help, function(args, static) -> (model, mapping, measurements)).
#: The model has ``angles(trial)`` returning the (joint, side, angle) DataFrame; a model
#: with ``event_markers()`` gives the mapping of gait_events for the trial just read, one
#: with ``opensim_coordinates(angles)`` the columns of its .mot.
MODELS = {
    "isb": ("ISB segment frames (calibrate_lower_limb); needs --markers", _isb_model),
    "plug-in-gait": ("Vicon's Plug-in Gait (plug_in_gait); needs --subject",
                     _plug_in_gait_model),
    "keypoints": ("video keypoints (keypoint_angles); needs --keypoints", _keypoint_model),
}


# --- one trial at a time --------------------------------------------------------------------

def expand(patterns):
    """File names from the command line; a pattern with * ? [ is expanded here too (the
    Windows shell does not), sorted; a pattern that matches nothing is an error."""
    files, missing = [], []
    for pattern in patterns:
        if any(c in pattern for c in "*?[") and not Path(pattern).exists():
            found = sorted(glob.glob(pattern, recursive=True))
            if not found:
                missing.append(pattern)
            files.extend(found)
        else:
            files.append(pattern)
    return files, missing


class Run:
    """The state of one command: output folder, record basics, failures."""

    def __init__(self, args, argv):
        self.args = args
        self.out = Path(args.out)
        self.failed = []
        self.command = ["bmc-kinematics", *argv]

    def record(self, trial, what, **entries):
        record = {
            "bmc_functions": __version__,
            "command": self.command,
            "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "python": platform.python_version(),
            "numpy": np.__version__, "pandas": pd.__version__,
            "trial": str(trial),
        }
        record.update(entries)
        path = self.out / f"{Path(trial).stem}_{what}.json"
        path.write_text(json.dumps(record, indent=2, default=_json_default) + "\n",
                        encoding="utf-8")
        return path


def _json_default(value):
    if isinstance(value, (np.integer, np.floating)):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    return str(value)


class SkipTrial(Exception):
    """Raised by a trial's work to skip it (named on stderr, not a failure): a trial
    without stored events under --events stored, a static trial under `cycles`."""


def _each_trial(run, trials, work, desc, what):
    """Run work(trial, notes) -> (result, record entries) for each trial, with a progress
    bar; write the trial's record; an error or a warning names the file on stderr; failed
    trials are collected in run.failed. Returns {trial: result} of the trials that worked."""
    results = {}
    bar = tqdm(trials, desc=desc, unit="trial", disable=True if run.args.quiet else None,
               file=sys.stderr)
    for trial in bar:
        notes, error = [], None
        with warnings.catch_warnings(record=True) as found:
            warnings.simplefilter("always")
            try:
                result, entries = work(trial, notes)
            except SkipTrial as skip:
                error = skip
            except Exception as err:  # one bad trial must not lose the others
                error = err
        messages = list(dict.fromkeys([str(w.message) for w in found] + notes))
        for message in messages:
            tqdm.write(f"warning: {trial}: {message}", file=sys.stderr)
        if isinstance(error, SkipTrial):
            tqdm.write(f"skipped: {trial}: {error}", file=sys.stderr)
            continue
        if error is not None:
            run.failed.append(trial)
            tqdm.write(f"error: {trial}: {_error_text(error)}", file=sys.stderr)
            continue
        run.record(trial, what, options=_options(run.args), **entries, warnings=messages)
        results[trial] = result
    return results


def _json_keys(value):
    """`value` with the tuple keys of its dicts joined by dots (('knee', 'right',
    'flexion') -> 'knee.right.flexion'): JSON keys are strings."""
    if isinstance(value, dict):
        return {".".join(map(str, key)) if isinstance(key, tuple) else key: _json_keys(item)
                for key, item in value.items()}
    return value


def _error_text(err):
    text = str(err) or type(err).__name__
    return text if isinstance(err, (ValueError, TypeError, OSError)) else \
        f"{type(err).__name__}: {text}"


def _flat_csv(df, path):
    """`df` as CSV with its column levels joined by dots (knee.right.flexion, RTH1.x), the
    layout of the repository's data/ files; the index as it is."""
    table = df.copy()
    table.columns = [".".join(map(str, column)) for column in df.columns]
    table.to_csv(path)


def _write_events_csv(events, path):
    rows = [(side, event, float(t)) for side in events for event in ("heel_strike", "toe_off")
            for t in np.asarray(events[side].get(event, []), dtype=float)]
    table = pd.DataFrame(rows, columns=["side", "event", "time"]).sort_values(
        ["time", "side"], kind="stable")
    table.to_csv(path, index=False)


def _load_static(args):
    if args.static is None:
        return None
    if not Path(args.static).is_file():
        raise ValueError(f"{args.static}: the static trial does not exist")
    return args.static


def _calibrate(run):
    """The model of --model, or None after printing why (the run fails as a whole)."""
    name = run.args.model
    if getattr(run.args, "keypoints", None) and name == "isb":    # the default
        name = run.args.model = "keypoints"
    try:
        return MODELS[name][1](run.args, _load_static(run.args))
    except Exception as err:
        where = (run.args.static or getattr(run.args, "subject", None) or run.args.markers
                 or name)
        print(f"error: {where}: calibration failed: {_error_text(err)}", file=sys.stderr)
        return None


def _options(args):
    keys = ("model", "static", "subject", "markers", "keypoints", "hip_centre",
            "static_offset", "sides", "gait", "events", "kinetics", "forces", "body_mass",
            "plates", "c3d", "normative")
    # each model's own options only (Plug-in Gait has no --hip-centre, ISB no --subject)
    skip = {"isb": ("subject", "keypoints"),
            "plug-in-gait": ("hip_centre", "static_offset", "sides", "keypoints"),
            "keypoints": ("subject", "markers", "hip_centre", "sides")}
    skip = skip.get(getattr(args, "model", None), ())
    return {key: getattr(args, key) for key in keys if hasattr(args, key) and key not in skip}


def _labels_used(model, mapping):
    """For the record: the trial's labels a model resolved itself (Plug-in Gait: standard
    name -> label, e.g. 'Sub01:LASI'), else the mapping file's roles."""
    if callable(getattr(model, "event_markers", None)):
        return dict(model.markers)
    return mapping


#: Why a static trial (the file of --static given as a trial too) has no events.
STATIC_TRIAL = "the static trial (--static): no gait events"


def _is_static(args, trial):
    return args.static is not None and Path(args.static).resolve() == Path(trial).resolve()


def _event_roles(model, mapping):
    """The mapping of gait_events for the trial the model read last: Plug-in Gait's own
    (its labels, prefixes, SACR or PSIS, heel or not), else the mapping file's."""
    if callable(getattr(model, "event_markers", None)):
        return model.event_markers()
    return mapping


def _has_events(events):
    return events is not None and any(np.size(times) for found in events.values()
                                      for times in found.values())


def _stored_events(trial):
    """The events stored with `trial` (--events stored): its C3D EVENT group, else
    ``<stem>_events.csv`` beside it; SkipTrial when neither holds a foot event."""
    path, found = Path(trial), None
    if path.suffix.lower() == ".c3d":
        with warnings.catch_warnings():     # said once below, with the CSV looked for
            warnings.filterwarnings("ignore", message=r".*no (EVENT group|foot event) in")
            found = read_events(path)
    beside = path.with_name(f"{path.stem}_events.csv")
    if not _has_events(found) and beside.is_file():
        found = read_events(beside)
    if not _has_events(found):
        raise SkipTrial(f"no stored events (--events stored): no foot event in "
                        f"{'its EVENT group nor in ' if path.suffix.lower() == '.c3d' else ''}"
                        f"{beside.name} beside it")
    return found


def _parameters(events, trial, roles):
    """spatiotemporal_parameters with the trial's markers (lengths, speed, Vicon's
    percentages), or from the events alone (one warning) when the markers do not allow."""
    try:
        return spatiotemporal_parameters(events, trial=trial, markers=roles)
    except (ValueError, KeyError) as err:
        warn(f"spatiotemporal parameters from the events only (no lengths, speed or "
             f"support times): {_error_text(err)}", UserWarning)
        return spatiotemporal_parameters(events)


def _static_angles(model, trial, notes):
    """A static trial's angles: with Nexus's static foot (HEE-TOE) for Plug-in Gait."""
    if not callable(getattr(model, "event_markers", None)):
        return model.angles(trial)
    try:
        return model.angles(trial, foot="static")
    except ValueError as err:
        notes.append(f"the dynamic foot shown: {_error_text(err)}")
        return model.angles(trial)


def _angles_of(model, trial, events_markers, notes, args):
    """Angles and (when the mapping has the feet) events of one trial: detected, or the
    stored ones with --events stored; none for the static trial itself."""
    static = _is_static(args, trial)
    angles = _static_angles(model, trial, notes) if static else model.angles(trial)
    if getattr(model, "no_events", None):
        notes.append(model.no_events)
        return angles, None, model.no_events
    if static:
        return angles, None, STATIC_TRIAL
    if args.events == "stored":
        return angles, _stored_events(trial), None
    events_markers = _event_roles(model, events_markers)   # this trial's labels
    events, note = None, None
    try:
        events = gait_events(trial, events_markers, gait=args.gait)
    except Exception as err:  # no feet in the mapping, a standing trial...
        note = f"events not computed: {_error_text(err)}"
        notes.append(note)
    return angles, events, note


# --- the subcommands ------------------------------------------------------------------------

def _save_figure(fig, path, title=None):
    """Write `fig` as a PNG (100 dpi), with `title` as its suptitle if given, and close it."""
    import matplotlib.pyplot as plt

    if title is not None:
        fig.suptitle(title, fontsize=11)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _each_trial_of_the_model(run, per_trial, what):
    """For `angles` and `cycles`: the model of --model, calibrated once, then for each
    trial its angles and events (:func:`_angles_of`) and, with --kinetics, its kinetics
    (:func:`_kinetics_of_model`; None when skipped) handed to ``per_trial(model, trial,
    stem, angles, events, note, kinetics)`` -> (result, record entries). Returns the exit
    status (1 if the calibration failed) and {trial: result} of the trials that worked."""
    calibrated = _calibrate(run)
    if calibrated is None:
        return 1, {}
    model, mapping, subject = calibrated
    run.mapping = mapping
    kinetics = getattr(run.args, "kinetics", False)
    if kinetics and run.args.model == "plug-in-gait" and run.args.body_mass is None \
            and model.subject.get("Bodymass") is None:
        raise ValueError(f"--kinetics: the subject ({run.args.subject}) gives no Bodymass: "
                         "give --body-mass (kg)")

    def work(trial, notes):
        angles, events, note = _angles_of(model, trial, mapping, notes, run.args)
        loads, record = (_kinetics_of_model(run.args, model, trial, notes) if kinetics
                         else (None, None))
        result, entries = per_trial(model, trial, run.out / Path(trial).stem, angles,
                                    events, note, loads)
        if record is not None:
            entries["kinetics"] = record
        return result, dict(markers=_labels_used(model, mapping), subject=subject,
                            **entries)

    return 0, _each_trial(run, run.trials, work, what, what)


def cmd_angles(run):
    _check_kinetics_options(run.args)

    def per_trial(model, trial, stem, angles, events, note, kinetics):
        outputs = [f"{stem}_angles.mot", f"{stem}_angles.csv"]
        coordinates = getattr(model, "opensim_coordinates", None)
        write_mot(angles if coordinates is None else coordinates(angles), outputs[0],
                  name=Path(trial).stem)
        _flat_csv(angles, outputs[1])
        if _has_events(events):         # a standing trial: no empty file
            _write_events_csv(events, f"{stem}_events.csv")
            outputs.append(f"{stem}_events.csv")
        _save_figure(plot_angles(angles, events, title=Path(trial).name)[0],
                     f"{stem}_angles.png")
        outputs.append(f"{stem}_angles.png")
        entries = dict(frames=len(angles), angles_attrs=_json_keys(dict(angles.attrs)),
                       gait=getattr(events, "gait", None), outputs=outputs)
        if kinetics is not None:
            _flat_csv(kinetics, f"{stem}_kinetics.csv")
            _save_figure(plot_angles(kinetics, events,
                                     title=f"{Path(trial).name}: kinetics")[0],
                         f"{stem}_kinetics.png")
            outputs += [f"{stem}_kinetics.csv", f"{stem}_kinetics.png"]
        if run.args.c3d:
            outputs.append(str(_write_c3d_copy(run.args, trial, stem, angles, events,
                                               kinetics)))
        return angles, entries

    status, _ = _each_trial_of_the_model(run, per_trial, "angles")
    return status


def _write_c3d_copy(args, trial, stem, angles, events, kinetics):
    """--c3d: <stem>.c3d, a copy of the C3D trial with the angles (Vicon's points under
    POINT:ANGLES), Plug-in Gait's kinetics (Vicon's <S><Joint>Moment, Force, Power, in
    Vicon's units) and the events (its EVENT group) added. The ISB model's kinetics are not
    written: their components are about its own segment axes, which Vicon's names would
    misstate."""
    source, target = Path(trial), Path(f"{stem}.c3d")
    if source.suffix.lower() != ".c3d":
        raise ValueError(f"--c3d copies a C3D trial with the angles added; {trial} is a "
                         f"{source.suffix or 'file without suffix'} (run it without --c3d)")
    if target.resolve() == source.resolve():
        raise ValueError(f"--c3d would overwrite the trial {trial}: give another --out "
                         "folder")
    return write_c3d(target, source, angles=angles,
                     kinetics=kinetics if args.model == "plug-in-gait" else None,
                     events=events if _has_events(events) else None)


def forces_of(trial, forces):
    """The ground loads of a trial for ``--kinetics``: `forces` (``--forces``) with
    ``{stem}`` replaced by the trial's file name without its suffix, or, without
    ``--forces``, the trial itself, which must then be a C3D file (its own force plates)."""
    if forces is None:
        if Path(trial).suffix.lower() != ".c3d":
            raise ValueError(f"--kinetics needs the ground loads of {trial}: a C3D trial "
                             f"carries its force plates; for a .trc give --forces, an "
                             f"OpenSim external-loads .mot (e.g. --forces "
                             f"'{{stem}}_grf.mot', {{stem}} being the trial's name)")
        return trial
    return forces.replace("{stem}", Path(trial).stem)


def _plate_list(text):
    """--plates: '1,4' -> [(1, None), (4, None)]; '1=left,4=right' names the foot."""
    plates = []
    for item in text.split(","):
        number, _, side = item.strip().partition("=")
        if not number.strip().isdigit() or int(number) < 1 or \
                side.strip() not in ("", "left", "right"):
            raise argparse.ArgumentTypeError(
                f"expected plate numbers from 1, separated by commas, each optionally "
                f"=left or =right (e.g. 1,4 or 1=left,4=right); got {text!r}")
        plates.append((int(number), side.strip() or None))
    return plates


def _check_kinetics_options(args):
    """--forces, --body-mass and --plates: refused without --kinetics, or for the model
    that does not take them; a body mass out of range, or none for Plug-in Gait's subject
    that has none, is refused before any trial runs (in :func:`_kinetics_of_model`)."""
    given = [option for option, value in (("--forces", args.forces),
                                          ("--body-mass", args.body_mass),
                                          ("--plates", args.plates)) if value is not None]
    if given and not args.kinetics:
        raise ValueError(f"{', '.join(given)} belong(s) to --kinetics, which was not given")
    if not args.kinetics:
        return
    if args.model == "keypoints" or getattr(args, "keypoints", None):
        raise ValueError("--kinetics needs a marker model (--model isb or plug-in-gait): "
                         "keypoints have no segment frames for inverse dynamics")
    if args.model == "isb" and args.plates is not None:
        raise ValueError("--plates belongs to --model plug-in-gait (the ISB model assigns "
                         "each load to the foot standing on it)")
    if args.model == "plug-in-gait" and args.forces is not None:
        raise ValueError("--forces belongs to --model isb: Plug-in Gait reads the force "
                         "plates of each C3D trial")
    if args.body_mass is not None and not 0 < args.body_mass <= MAX_BODY_MASS:
        raise ValueError(f"--body-mass: expected the subject's mass in kg, in (0, "
                         f"{MAX_BODY_MASS:g}]; got {args.body_mass:g}")
    if args.model == "isb" and args.body_mass is None:
        raise ValueError("--kinetics needs --body-mass (the subject's mass in kg)")


def _plates_of(args, trial):
    """Plug-in Gait's `plates` for one trial: None (every plate assigned automatically),
    or with --plates the plates not listed left out (Nexus's 'Invalid') and those listed
    with =left or =right given to that foot; SkipKinetics when the trial has no plate."""
    if Path(trial).suffix.lower() != ".c3d":
        raise SkipKinetics(f"kinetics skipped: {trial} is not a C3D file (Plug-in Gait "
                           f"reads the force plates of a C3D trial)")
    group = read_c3d_parameters(trial).get("FORCE_PLATFORM", {})
    used = np.ravel(group.get("USED", 0))
    count = int(used[0]) if used.size else 0
    if count < 1:
        raise SkipKinetics(f"kinetics skipped: {trial} has no force plates "
                           f"(FORCE_PLATFORM:USED is {count if 'USED' in group else 'missing'})")
    if args.plates is None:
        return None
    unknown = [number for number, _ in args.plates if number > count]
    if unknown:
        raise ValueError(f"--plates {unknown[0]}: {trial} has {count} force plate(s)")
    listed = dict(args.plates)      # number -> None (the automatic foot) or a side
    return {number: listed.get(number) for number in range(1, count + 1)
            if number not in listed or listed[number] is not None}


class SkipKinetics(Exception):
    """A trial whose kinetics cannot be computed (no force plates): named in a note, its
    angles and events written as without --kinetics."""


def _kinetics_of_model(args, model, trial, notes):
    """--kinetics for one trial: (the kinetics table, the record's entry), or (None, the
    entry saying why) for the static trial or a trial without force plates (a note)."""
    if _is_static(args, trial):
        return None, {"skipped": "the static trial (--static)"}
    try:
        if args.model == "plug-in-gait":
            plates = _plates_of(args, trial)
            kinetics = model.kinetics(trial, plates=plates, body_mass=args.body_mass)
            forces = f"{trial} (its force plates)"
        else:
            forces = forces_of(trial, args.forces)
            kinetics = model.kinetics(trial, forces, body_mass=args.body_mass)
    except SkipKinetics as skip:
        notes.append(str(skip))
        return None, {"skipped": str(skip)}
    own = getattr(model, "attrs", {})     # Plug-in Gait's: already in the record's subject
    attrs = {key: value for key, value in kinetics.attrs.items()
             if key not in own or own[key] is not value}
    return kinetics, dict(forces=str(forces), attrs=_json_keys(attrs))


def cmd_events(run):
    pig = run.args.model == "plug-in-gait"
    if not pig and run.args.markers is None:
        raise ValueError("events needs --markers (the marker mapping file), or --model "
                         "plug-in-gait for Plug-in Gait's labels")
    mapping = read_marker_mapping(run.args.markers) if run.args.markers else None

    def work(trial, notes):
        # Plug-in Gait: the roles from this trial's labels (prefixes, SACR or PSIS, HEE)
        data, roles = trial_event_markers(trial, mapping) if pig else (trial, mapping)
        events = gait_events(data, roles, gait=run.args.gait)
        stem = run.out / Path(trial).stem
        _write_events_csv(events, f"{stem}_events.csv")
        _parameters(events, data, roles).to_csv(f"{stem}_parameters.csv",
                                                       index_label="side")
        return events, dict(markers=roles, gait=events.gait, method=events.method,
                            outputs=[f"{stem}_events.csv", f"{stem}_parameters.csv"])

    _each_trial(run, run.trials, work, "events", "events")
    return 0


def cmd_cycles(run):
    _check_kinetics_options(run.args)
    normative = _read_normative(run.args.normative)

    def per_trial(model, trial, stem, angles, events, note, kinetics):
        if events is None:
            raise (SkipTrial if note == STATIC_TRIAL else ValueError)(note)
        cycles = normalize_by_side(angles, events)
        params = _parameters(events, trial, _event_roles(model, run.mapping))
        outputs = [f"{stem}_cycles.csv", f"{stem}_cycles.png", f"{stem}_parameters.csv"]
        title, entries = Path(trial).name, {}
        if normative is not None:
            title, entries = _gait_profile(cycles, normative, f"{stem}_gps.csv", title)
            outputs.append(f"{stem}_gps.csv")
        loads = None if kinetics is None else _kinetics_cycles(kinetics, events)
        if loads is not None:
            _flat_csv(loads, f"{stem}_kinetics_cycles.csv")
            outputs.append(f"{stem}_kinetics_cycles.csv")
        # refuses a trial without a cycle; its title counts the cycles of each side
        fig, _ = plot_gait_cycles(cycles, params, title=title, normative=normative,
                                  kinetics=_report_kinetics(loads))
        _save_figure(fig, outputs[1])
        _flat_csv(cycles, outputs[0])
        params.to_csv(outputs[2], index_label="side")
        return (cycles, params, loads), dict(
            cycles=int(cycles.index.get_level_values(0).nunique()), **entries,
            outputs=outputs)

    status, results = _each_trial_of_the_model(run, per_trial, "cycles")
    if results:
        _write_ensemble(run.out, results, normative)
    return status


def _kinetics_cycles(kinetics, events):
    """The kinetics' cycles, NaN only at the points of a cycle nearer a frame of a long
    gap (a stance no plate measured) than a measured frame: ``long_gaps='points'``.
    With the default, every kinetics cycle would be NaN: each opens or closes on a stance
    no plate measures."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # said once, by the angles' normalisation
        return normalize_by_side(kinetics, events, long_gaps="points")


#: The kinetics of the report figure (Vicon Nexus's kinetics page): the moments in the
#: three planes and the power of each joint; the forces stay in the CSV files.
REPORT_KINETICS = ("moment_x", "moment_y", "moment_z", "power")


def _report_kinetics(cycles):
    """The kinetics cycles drawn in the report figure (:data:`REPORT_KINETICS`), or None
    when there are none or no cycle has a value (no stance on a plate in a whole cycle)."""
    if cycles is None:
        return None
    shown = cycles.loc[:, cycles.columns.get_level_values(2).isin(REPORT_KINETICS)]
    return shown if np.isfinite(shown.to_numpy(float)).any() else None


def _read_normative(path):
    """The normative table of --normative (read_normative_data), or None without it."""
    if path is None:
        return None
    try:
        return read_normative_data(path)
    except (ValueError, TypeError, OSError) as err:
        raise ValueError(f"--normative {path}: {_error_text(err)}") from err


def _gait_profile(cycles, normative, path, title):
    """--normative: the Gait Profile Score of `cycles` (one table, or a list of one per
    trial) against `normative`; writes the MAP (GVS per variable and side) and the GPS
    (last row; 'overall' column) to `path`; returns the figure's title with the overall GPS
    and the record's entries."""
    profile = gait_profile_score(cycles, normative)
    table = profile.map.copy()
    table["overall"] = np.nan
    table.loc["GPS"] = profile.gps.reindex(table.columns)
    table.to_csv(path, index_label="variable")
    overall = float(profile.gps["overall"])
    return f"{title}, GPS {overall:.2f}°", dict(
        gps_deg={side: float(value) for side, value in profile.gps.items()},
        map_deg={variable: {side: float(value) for side, value in row.items()}
                 for variable, row in profile.map.iterrows()})


def _pooled(tables):
    """{trial stem: cycles} pooled into one table, its cycles named 'stem:cycle'."""
    pooled = pd.concat(list(tables.values()), keys=list(tables), names=["trial"])
    pooled = pooled.reset_index(level=0)
    pooled.index = pd.MultiIndex.from_arrays(
        [pooled["trial"] + ":" + pooled.index.get_level_values(0).astype(str),
         pooled.index.get_level_values(1)], names=["cycle", "percent"])
    return pooled.drop(columns="trial", level=0)


def _write_ensemble(out, results, normative=None):
    """ensemble.csv and ensemble.png in `out`: every cycle of every trial that worked
    ({trial: (cycles, parameters, kinetics cycles or None)}), pooled, the kinetics of
    the trials that have them beside the angles; with `normative`, the normal band and
    the GPS of all the cycles (gps.csv)."""
    pooled = _pooled({Path(t).stem: cycles for t, (cycles, _, _) in results.items()})
    loads = {Path(t).stem: kinetic for t, (_, _, kinetic) in results.items()
             if kinetic is not None}
    loads = _pooled(loads) if loads else None
    # the stance alone: the tables' attrs (with the trial's markers) cannot be concatenated
    stance = pd.concat([pd.Series(params["stance"].to_numpy(), index=params.index)
                        for _, params, _ in results.values()])
    stats = ensemble(pooled if loads is None else pd.concat([pooled, loads], axis=1))
    stats.columns = [f"{stat}:{'.'.join(map(str, column))}"
                     for stat, *column in stats.columns]
    stats.to_csv(out / "ensemble.csv")
    title = f"{len(results)} trial(s), mean ± SD"
    if normative is not None:
        title, _ = _gait_profile([cycles for cycles, _, _ in results.values()], normative,
                                 out / "gps.csv", title)
    fig, _ = plot_gait_cycles(pooled, stance.groupby(level=0).mean().to_dict(),
                              title=title, normative=normative,
                              kinetics=_report_kinetics(loads))
    _save_figure(fig, out / "ensemble.png")     # the title counts the cycles per side


def cmd_convert(run):
    target = run.args.to

    def work(trial, notes):
        source = Path(trial)
        suffix = source.suffix.lower()
        to = target or {".c3d": "trc", ".csv": "mot", ".mot": "csv", ".sto": "csv"}.get(suffix)
        if to is None:
            raise ValueError(f"cannot convert a {suffix or 'file without suffix'}: give a "
                             ".c3d (to .trc), an angles .csv (to .mot) or a .mot (to .csv)")
        out = run.out / f"{source.stem}.{to}"
        if out.resolve() == source.resolve():
            raise ValueError(f"the output would overwrite the input ({out})")
        if suffix in (".c3d", ".trc") and to in ("trc", "csv"):
            markers = read_c3d(source) if suffix == ".c3d" else read_trc(source)
            if to == "trc":
                write_trc(markers, out)
            else:
                _flat_csv(markers, out)
        elif suffix == ".csv" and to == "mot":
            write_mot(_read_angles_csv(source, run.args.model), out, name=source.stem)
        elif suffix in (".mot", ".sto") and to == "csv":
            read_mot(source).to_csv(out)
        else:
            raise ValueError(f"cannot convert {suffix} to .{to}")
        return out, dict(outputs=[str(out)])

    _each_trial(run, run.trials, work, "convert", "convert")
    return 0


def _read_angles_csv(path, model=None):
    """The angles .csv written by `angles` (columns joint.side.angle, index time), with
    the attrs that say its model's pelvis sequence: `model` ('isb' or 'plug-in-gait'),
    else Plug-in Gait's when it has a foot progression angle (which `angles` writes for
    Plug-in Gait only), else the ISB pipeline's."""
    table = pd.read_csv(path, index_col=0)
    parts = [str(column).split(".") for column in table.columns]
    if not parts or any(len(p) != 3 for p in parts):
        raise ValueError(f"{path}: expected the columns joint.side.angle of the angles "
                         f"written by 'bmc-kinematics angles'; got {list(table.columns[:3])}")
    table.columns = pd.MultiIndex.from_tuples([tuple(p) for p in parts])
    table.index.name = "time"
    progression = any(p[0] == "foot" and p[2] == "progression" for p in parts)
    if model == "isb" and progression:
        raise ValueError(f"{path}: --model isb, but the file has a foot progression angle, "
                         "which only Plug-in Gait's angles have: give --model plug-in-gait")
    if model == "plug-in-gait" or (model is None and progression):
        table.attrs = {"units": "deg", "model": "Plug-in Gait"}
    else:
        table.attrs = {"units": "deg", "pelvis_sequence": "YXZ"}
    return table


# --- the parser -----------------------------------------------------------------------------

def _para(text):
    """A description wrapped once here (the epilogs' examples must keep their lines)."""
    return textwrap.fill(text, 88)


def _kinetics_options(sub):
    """--kinetics, --forces, --body-mass and --plates of `angles` and `cycles`."""
    sub.add_argument("--kinetics", action="store_true", help="also hip, knee and ankle "
                     "moments, forces and powers per kg of body mass: angles: "
                     "<stem>_kinetics.csv and .png; cycles: <stem>_kinetics_cycles.csv and "
                     "the moments and powers in the cycle figure. A trial without force "
                     "plates is named and its kinetics skipped")
    sub.add_argument("--forces", help="--kinetics, --model isb: the ground loads, an "
                     "OpenSim external-loads .mot; '{stem}' stands for the trial's name "
                     "(e.g. '{stem}_grf.mot'). Default: a C3D trial's own force plates "
                     "(plug-in-gait: always)")
    sub.add_argument("--body-mass", type=float, help="--kinetics: the subject's mass (kg); "
                     "plug-in-gait: default the subject's Bodymass (.vsk, PROCESSING)")
    sub.add_argument("--plates", type=_plate_list, metavar="N,N", help="--kinetics, "
                     "plug-in-gait: the force plates used, the others left out (Nexus's "
                     "force plate settings, 'Invalid'), e.g. 1,4; N=left or N=right gives "
                     "plate N to that foot. Default: each plate to the foot that stands "
                     "on it alone")


def _c3d_option(sub):
    """--c3d of `angles`."""
    sub.add_argument("--c3d", action="store_true", help="also <stem>.c3d: a copy of the C3D "
                     "trial with the angles (Vicon's points: LKneeAngles ...), the events "
                     "and, with --kinetics and --model plug-in-gait, the kinetics "
                     "(LKneeMoment in N·mm/kg, LKneeForce, LKneePower, as Vicon stores "
                     "them) added, for Nexus, Polygon or Mokka. A .trc trial is refused")


def _normative_option(sub):
    """--normative of the cycles subcommand."""
    sub.add_argument("--normative", metavar="FILE", help="the lab's normative data (a CSV "
                     "as write_normative_data writes it, of the same model): its normal "
                     "band on the cycle figures, the Gait Profile Score in their titles, and "
                     "the GPS and MAP (deg) in <stem>_gps.csv, gps.csv (all the trials) and "
                     "the record")


def _events_parser(commands, common):
    """The `events` subcommand: a mapping file, or Plug-in Gait's own labels."""
    sub = commands.add_parser(
        "events", help="heel strikes, toe-offs and spatio-temporal parameters",
        description="Events per trial: <stem>_events.csv, _parameters.csv and "
                    "_events.json.",
        epilog="example:\n  bmc-kinematics events --markers markers.toml walk1.trc walk2.trc"
               "\n  bmc-kinematics events --model plug-in-gait 'Walk*.c3d' -o results",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    common(sub, "dynamic trials")
    sub.add_argument("--markers", help="marker mapping (feet and pelvis); plug-in-gait: "
                     "optional, Plug-in Gait name = your label")
    sub.add_argument("--model", default="isb", choices=["isb", "plug-in-gait"],
                     help="plug-in-gait: Plug-in Gait's labels (subject prefixes, SACR or "
                     "PSIS, HEE or not), no mapping file")
    sub.add_argument("--gait", default="auto", choices=["auto", "walking", "running"])
    sub.set_defaults(handler=cmd_events)


def build_parser():
    parser = argparse.ArgumentParser(
        prog="bmc-kinematics",
        description=_para("Joint angles, gait events and gait cycles from marker files "
                          "(TRC or C3D), one command per folder of trials."),
        epilog=EXAMPLE, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=_version())
    commands = parser.add_subparsers(dest="command", metavar="command", required=True)

    def common(sub, trials_help):
        sub.add_argument("trials", nargs="+", metavar="TRIAL",
                         help=trials_help + " (files or patterns such as 'walk*.trc')")
        sub.add_argument("-o", "--out", default=".", help="output folder (created; "
                         "default: the current folder)")
        sub.add_argument("-q", "--quiet", action="store_true", help="no progress bar")

    def model_options(sub):
        sub.add_argument("--static", help="the subject's static calibration trial")
        sub.add_argument("--markers", help="marker mapping: role = label, in TOML, JSON "
                         "or YAML (plug-in-gait: optional, Plug-in Gait name = your label)")
        sub.add_argument("--model", default="isb", choices=sorted(MODELS),
                         help="body model (default: isb); plug-in-gait: Vicon's Plug-in "
                         "Gait with --subject")
        sub.add_argument("--subject", help="plug-in-gait: the subject's measurements, a "
                         "Vicon .vsk, a C3D with a PROCESSING group (a trial processed by "
                         "Nexus) or a TOML/JSON file of Vicon's names (LeftLegLength = 877)")
        sub.add_argument("--keypoints", choices=sorted(KEYPOINT_SETS), help="video keypoints "
                         "(e.g. Pose2Sim's TRC): their set; means --model keypoints")
        sub.add_argument("--hip-centre", default="harrington",
                         choices=["harrington", "marker"], help="hip centre (default: "
                         "harrington)")
        sub.add_argument("--static-offset", action="store_true",
                         help="angles relative to the standing posture (keypoints: "
                         "relative to --static)")
        sub.add_argument("--sides", help="e.g. 'right' (default: the sides mapped)")
        sub.add_argument("--gait", default="auto", choices=["auto", "walking", "running"],
                         help="event detection method (default: decided from the data)")
        sub.add_argument("--events", default="detected", choices=["detected", "stored"],
                         help="stored: the events stored with each trial (a C3D's EVENT "
                         "group, or <stem>_events.csv beside it) instead of detected ones; "
                         "a trial without is skipped")

    sub = commands.add_parser(
        "angles", help="pelvis, hip, knee and ankle angles of each trial",
        description=_para("Angles per trial: <stem>_angles.mot (OpenSim's coordinate "
                          "names), _angles.csv, _events.csv (when the feet are mapped), "
                          "_angles.png and _angles.json (the record)."),
        epilog=EXAMPLE, formatter_class=argparse.RawDescriptionHelpFormatter)
    common(sub, "dynamic trials")
    model_options(sub)
    _kinetics_options(sub)
    _c3d_option(sub)
    sub.set_defaults(handler=cmd_angles)

    _events_parser(commands, common)

    sub = commands.add_parser(
        "cycles", help="time-normalised gait cycles and the ensemble figure",
        description=_para("Cycles per trial: <stem>_cycles.csv (101 points per cycle), "
                          "_cycles.png, _parameters.csv, _cycles.json; for all trials "
                          "together: ensemble.csv (mean, sd, count) and ensemble.png."),
        epilog="example:\n  bmc-kinematics cycles --static static.trc --markers markers.toml "
               "'walk*.trc' -o results", formatter_class=argparse.RawDescriptionHelpFormatter)
    common(sub, "dynamic trials")
    model_options(sub)
    _kinetics_options(sub)
    _normative_option(sub)
    sub.set_defaults(handler=cmd_cycles)

    sub = commands.add_parser(
        "convert", help="C3D -> TRC; angles .csv -> .mot; .mot -> .csv",
        description=_para("Convert files: a .c3d to .trc (or --to csv), an angles .csv "
                          "written by 'angles' to an OpenSim .mot, a .mot to .csv."),
        epilog="example:\n  bmc-kinematics convert 'session/*.c3d' -o trc",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    common(sub, "files to convert")
    _convert_options(sub)
    return parser


def _convert_options(sub):
    """The options of `convert`: --to and the model of an angles .csv (--model)."""
    sub.add_argument("--to", choices=["trc", "mot", "csv"], help="output format (default: "
                     "from the input's suffix)")
    sub.add_argument("--model", choices=sorted(MODELS), default=None,
                     help="the model of an angles .csv (its pelvis sequence differs: "
                          "plug-in-gait tilt-obliquity-rotation, isb rotation-obliquity-"
                          "tilt); default: plug-in-gait if the file has a foot progression "
                          "angle, else isb")
    sub.set_defaults(handler=cmd_convert)


def _version():
    return f"bmc-kinematics (bmc_functions {__version__})"


def main(argv=None):
    """Run the command line; returns the exit status (0: every trial succeeded)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    args = parser.parse_args(argv)
    import matplotlib

    if "matplotlib.pyplot" not in sys.modules:
        matplotlib.use("Agg")       # files only: no window, works without a display
    trials, missing = expand(args.trials)
    for pattern in missing:
        print(f"error: {pattern}: no file matches", file=sys.stderr)
    stems = {}
    for trial in trials:
        stems.setdefault(Path(trial).stem, []).append(trial)
    clashes = {stem: files for stem, files in stems.items() if len(files) > 1}
    if clashes:
        stem, files = next(iter(clashes.items()))
        parser.error(f"two trials would write the same outputs ({stem}): "
                     f"{', '.join(files)}; run them into different --out folders")
    if not trials:
        print("error: no trial to run", file=sys.stderr)
        return 1
    run = Run(args, argv)
    run.trials = trials
    try:
        run.out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        print(f"error: {run.out}: cannot create the output folder ({err})", file=sys.stderr)
        return 1
    try:
        status = args.handler(run)
    except ValueError as err:       # e.g. the mapping file of `events`
        print(f"error: {err}", file=sys.stderr)
        return 1
    done = len(trials) - len(run.failed)
    if run.failed or missing:
        print(f"{done} of {len(trials)} trial(s) done; failed: "
              f"{', '.join(map(str, run.failed + missing))}", file=sys.stderr)
        return 1
    return status


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
