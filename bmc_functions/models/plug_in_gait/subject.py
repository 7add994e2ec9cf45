"""Plug-in Gait's subject measurements: read from a .vsk, a dict, a C3D's PROCESSING group
or a table file, in whatever case the names were written, and checked.

Lengths in mm, angles in radians, as Vicon stores them; the names are Vicon's .vsk names
(``LeftLegLength``; a C3D's ``LLegLength`` or ``LLEGLENGTH`` is the same measurement).
"""

import json
import os
from pathlib import Path

import numpy as np

# Parsers of the subject tables (:func:`load_subject`): tomllib is in the standard library
# from Python 3.11 (tomli before, a dependency there); PyYAML is optional. A missing one
# is reported when a file needs it.
try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    try:
        import tomli as tomllib
    except ModuleNotFoundError:
        tomllib = None
try:
    import yaml
except ModuleNotFoundError:
    yaml = None
from ..._checks import ArgumentTypeError, warn
from ...files.c3d_parameters import (VICON_SUBJECT_NAMES, read_c3d_parameters,
                                     subject_parameters)
from ...files.vsk import read_vsk
from .lower_body import asis_trochanter_distance
from .upper_body import UPPER_BODY_DEFAULTS

#: Default marker diameter (mm) when the subject gives none: Plug-in Gait's default [3].
DEFAULT_MARKER_DIAMETER = 14.0

#: Measurements without which the model cannot be built (Plug-in Gait marks them REQUIRED).
REQUIRED = ("LeftLegLength", "RightLegLength", "LeftKneeWidth", "RightKneeWidth",
            "LeftAnkleWidth", "RightAnkleWidth")

#: Subject measurements this implementation would refuse when non-zero, rather than
#: ignore: none now (``AnkleAbAdd``, the KAD-med static's ankle abduction, is applied:
#: :mod:`~bmc_functions.models.plug_in_gait.knee_alignment`). Kept, empty, for code that
#: imported it.
NOT_APPLIED = ()

#: The sole thickness (heel minus toe, mm) of the static processing's foot-flat option:
#: used on the sides processed with ``foot_flat``; a non-zero value on another side is
#: refused when a static trial is processed here (Vicon uses it only with that option);
#: without a static trial it plays no part (the offsets come from the subject).
STATIC_ONLY_NOT_APPLIED = ("LeftSoleDelta", "RightSoleDelta")

#: Every measurement the model reads: the lower body's (as the C3D reader knows them) and
#: the upper body's (ShoulderOffset, ElbowWidth, WristWidth, HandThickness per side,
#: HeadOffset).
MEASUREMENT_NAMES = VICON_SUBJECT_NAMES + tuple(UPPER_BODY_DEFAULTS)

#: The upper body's lengths (mm), which must be positive when given.
UPPER_BODY_LENGTHS = tuple(name for name in UPPER_BODY_DEFAULTS if name != "HeadOffset")

#: Vicon's name of each measurement, keyed by the name in lower case, long ('leftleglength')
#: and short ('lleglength', as a C3D's PROCESSING group writes it): C3D parameter names
#: are case-insensitive, and subject files of other labs do not all keep Vicon's case
#: (LSHOULDEROFFSET, LShoulderOffset and leftshoulderoffset are LeftShoulderOffset).
_NAME_OF = {name.lower(): name for name in MEASUREMENT_NAMES}
_NAME_OF.update({short + name[len(long):].lower(): name for name in MEASUREMENT_NAMES
                 for short, long in (("l", "Left"), ("r", "Right")) if name.startswith(long)})


def _canonical(name):
    """Vicon's .vsk name for a PROCESSING (C3D) or .vsk name in any case:
    LLegLength, LEFTLEGLENGTH -> LeftLegLength; other names unchanged."""
    return _NAME_OF.get(name.lower(), name)


def _optional_parser(module, name):
    """`module` if it was imported, else the ModuleNotFoundError naming the package."""
    if module is None:
        raise ModuleNotFoundError(f"No module named {name!r}", name=name)
    return module


def _read_subject_table(path):
    """A TOML, JSON or YAML file of Vicon's measurement names -> numbers (a dict); the
    table may sit under a key ``subject``."""
    suffix = path.suffix.lower()
    try:
        text = path.read_bytes().decode("utf-8")
        if suffix == ".toml":
            data = _optional_parser(tomllib, "tomli").loads(text)
        elif suffix == ".json":
            data = json.loads(text)
        else:
            data = _optional_parser(yaml, "yaml").safe_load(text)
    except ModuleNotFoundError as err:
        raise ValueError(f"subject: reading {path.name} needs the package {err.name} (pip "
                         f"install {'pyyaml' if err.name == 'yaml' else err.name}); or "
                         f"write the measurements as JSON") from None
    except Exception as err:     # the parser's own message (a syntax error, bad UTF-8)
        raise ValueError(f"subject: {path} could not be read as {suffix[1:].upper()}: "
                         f"{err}") from None
    if isinstance(data, dict) and isinstance(data.get("subject"), dict):
        data = data["subject"]
    if not isinstance(data, dict):
        raise ValueError(f"subject: {path} must hold a table of Vicon's measurement names "
                         f"(LeftLegLength = 877.0, ...); got {type(data).__name__}")
    return data


def load_subject(subject):
    """The subject measurements as a dict with Vicon's .vsk names.

    Parameters
    ----------
    subject : dict, or str / path-like
        A dict of Vicon's names (``LeftLegLength`` or ``LLegLength``, ...), a ``.vsk``
        file, a ``.c3d`` file whose PROCESSING group holds them, or a ``.toml``,
        ``.json`` or ``.yaml`` file of Vicon's names and numbers (the table at the top
        level or under a key ``subject``).

    Returns
    -------
    dict
        Name -> float, with Vicon's names: the names of the model's measurements are
        recognised in any case and with 'L'/'R' for 'Left'/'Right' (``LLegLength``,
        ``LEFTLEGLENGTH`` -> ``LeftLegLength``). Other numeric entries are kept as given.

    Raises
    ------
    ValueError
        If a path is none of those kinds, if a value is not a number, or if one
        measurement is given twice with different values (``LLegLength`` and
        ``LeftLegLength``).
    FileNotFoundError
        If the file does not exist.
    TypeError
        If `subject` is not a dict or a path.

    Examples
    --------
    >>> from bmc_functions.models.plug_in_gait import load_subject
    >>> subject, source = load_subject({"LLEGLENGTH": 877.0, "rightKneeWidth": 139.0})
    >>> subject, source
    ({'LeftLegLength': 877.0, 'RightKneeWidth': 139.0}, 'subject')
    """
    if isinstance(subject, (str, Path)):
        path = Path(subject)
        suffix = path.suffix.lower()
        if suffix in (".vsk", ".c3d", ".toml", ".json", ".yaml", ".yml") \
                and not path.is_file():
            raise FileNotFoundError(f"subject: {path} does not exist")
        if suffix == ".vsk":
            raw = read_vsk(path)
        elif suffix == ".c3d":
            raw = subject_parameters(path)
        elif suffix in (".toml", ".json", ".yaml", ".yml"):
            raw = _read_subject_table(path)
        else:
            raise ValueError(f"subject: expected a dict, a .vsk, a .c3d, or a .toml, .json "
                             f"or .yaml file of Vicon's names; got {str(path)!r}")
        source = f"subject ({path.name})"
    elif isinstance(subject, dict):
        raw, source = subject, "subject"
    else:
        raise ArgumentTypeError(f"subject must be a dict of Vicon's measurement names, or a "
                                f".vsk or .c3d path; got {type(subject).__name__}")
    out = {}
    for name, value in raw.items():
        if name == "__model__":
            continue
        key = _canonical(str(name))
        if key in MEASUREMENT_NAMES:
            if isinstance(value, bool) or not isinstance(value, (int, float, np.number)) \
                    or not np.isfinite(value):
                raise ValueError(f"{source}: {name} must be a finite number; got "
                                 f"{value!r}")
        elif not isinstance(value, (int, float, np.number)):
            continue  # other entries (text, arrays) are not measurements of this model
        value = float(value)
        if key in out and out[key] != value:
            raise ValueError(f"{source}: {key} is given twice with different values "
                             f"({out[key]:g} and {value:g})")
        out[key] = value
    return out, source


def check_subject(subject, source, static_given, foot_flat=()):
    """The measurements the model uses, required ones checked and optional ones derived;
    `foot_flat`: the sides ('left', 'right') whose static foot is processed flat.

    Returns (measurements, derived): both dicts name -> float; `derived` names the values
    this function computed (the static ones are added by the static processing)."""
    missing = [name for name in REQUIRED if name not in subject]
    if not static_given:
        missing += [name for name in ("InterAsisDistance", "LeftStaticPlantFlex",
                                      "RightStaticPlantFlex", "LeftStaticRotOff",
                                      "RightStaticRotOff") if name not in subject]
    if missing:
        static_only = [name for name in missing if name not in REQUIRED]
        why = "" if not static_only else (
            f"; without a static trial {' and '.join(static_only)} must come from the "
            f"subject: give the static trial (plug_in_gait(static, ...); --static on the "
            f"command line), from which Plug-in Gait's static processing computes them, or "
            f"a subject file that holds them (the .vsk Nexus saved after the static "
            f"processing, or a C3D it processed)")
        raise ValueError(f"{source}: missing subject measurement(s) {', '.join(missing)}"
                         f"{why}")
    for name in REQUIRED + ("InterAsisDistance", "MarkerDiameter"):
        if name in subject and not subject[name] > 0:
            raise ValueError(f"{source}: {name} must be a positive length (mm); got "
                             f"{subject[name]:g}")
    flat_soles = tuple(side.capitalize() + "SoleDelta" for side in foot_flat)
    for name in NOT_APPLIED + (STATIC_ONLY_NOT_APPLIED if static_given else ()):
        if subject.get(name, 0.0) != 0.0 and name not in flat_soles:
            raise ValueError(f"{source}: {name} = {subject[name]:g}; this Plug-in Gait "
                             f"implementation applies the sole-thickness offset only with "
                             f"the foot-flat option (plug_in_gait(..., foot_flat=True) if "
                             f"Nexus processed the static trial with it); else set it to 0 "
                             f"or process the trial in Nexus")
    used, derived = {}, {}
    used["MarkerDiameter"] = subject.get("MarkerDiameter", DEFAULT_MARKER_DIAMETER)
    if "MarkerDiameter" not in subject:
        derived["MarkerDiameter"] = used["MarkerDiameter"]
    for name in REQUIRED:
        used[name] = subject[name]
    if "InterAsisDistance" in subject:
        used["InterAsisDistance"] = subject["InterAsisDistance"]
    for side in ("Left", "Right"):
        name = side + "AsisTrocanterDistance"
        if name in subject:
            used[name] = subject[name]
        else:
            used[name] = derived[name] = float(asis_trochanter_distance(
                subject[side + "LegLength"]))
        name = side + "TibialTorsion"
        used[name] = subject.get(name, 0.0)
        if name not in subject:
            derived[name] = 0.0
        for name in (side + "ThighRotation", side + "ShankRotation", side + "AnkleAbAdd"):
            if name in subject:     # else 0, or from a static trial with the device
                used[name] = subject[name]
        if side.lower() in foot_flat:
            used[side + "SoleDelta"] = subject.get(side + "SoleDelta", 0.0)
        if not static_given:
            for what in ("StaticPlantFlex", "StaticRotOff"):
                used[side + what] = subject[side + what]
    upper, upper_derived = _upper_body_measurements(subject, source)
    used.update(upper)
    derived.update(upper_derived)
    return used, derived


def _upper_body_measurements(subject, source):
    """The upper body's measurements: given ones checked (lengths positive), missing ones
    Vicon's template defaults (:data:`~bmc_functions.models.plug_in_gait.upper_body.
    UPPER_BODY_DEFAULTS`), returned as (used, derived)."""
    for name in UPPER_BODY_LENGTHS:
        if name in subject and not subject[name] > 0:
            raise ValueError(f"{source}: {name} must be a positive length (mm); got "
                             f"{subject[name]:g}")
    used = {name: subject.get(name, default) for name, default in UPPER_BODY_DEFAULTS.items()}
    derived = {name: default for name, default in UPPER_BODY_DEFAULTS.items()
               if name not in subject}
    return used, derived


#: How far (mm) the median distance between a trial's ASIS markers may lie from the
#: subject's InterAsisDistance before :func:`check_same_subject` suspects another subject.
#: Vicon's InterAsisDistance is that of the ASIS markers (the static trial's, when not
#: measured); marker placement between sessions and skin motion in walking move it by a
#: few mm (the shipped trials: 306 mm in Test.vsk, 307 mm in the static, 311 mm in the
#: walk), while adults' inter-ASIS distances spread over about 200-300 mm: 30 mm is ten
#: times the first and a tenth of the second.
INTER_ASIS_TOLERANCE = 30.0

#: How far (mm) a trial's leg, measured along its markers (ASI to KNE to ANK, the 95th
#: percentile over frames: the leg at its straightest, since hip flexion shortens ASI-KNE),
#: may lie from the subject's LegLength (ASIS to medial malleolus via the knee, Vicon's
#: definition) before :func:`check_same_subject` suspects another subject. The two differ
#: by what the markers add or miss: two marker radii (7 mm each), the lateral against the
#: medial malleolus (about 15 mm), and the knee marker's skin motion (about 20 mm): about
#: 50 mm, rounded up. The shipped subject's legs: 871-879 mm in the walk, 876-881 mm in the
#: static trial, against LegLengths of 866 and 877 mm.
LEG_LENGTH_TOLERANCE = 60.0


def file_subject_name(source):
    """The subject's name a file gives: a C3D's SUBJECTS:NAMES (when it names one subject),
    a .vsk's file name (Nexus names the .vsk after the subject); None for a DataFrame, a
    dict, another file or a C3D without one name.

    Examples
    --------
    >>> from bmc_functions.examples import example_file
    >>> from bmc_functions.models.plug_in_gait.subject import file_subject_name
    >>> file_subject_name(example_file("plug_in_gait/Static_trial.c3d"))
    'Test'
    >>> file_subject_name(example_file("plug_in_gait/Test.vsk")), file_subject_name({})
    ('Test', None)
    """
    if not isinstance(source, (str, os.PathLike)):
        return None
    path = Path(source)
    if path.suffix.lower() == ".vsk":
        return path.stem
    if path.suffix.lower() != ".c3d" or not path.is_file():
        return None
    names = read_c3d_parameters(path).get("SUBJECTS", {}).get("NAMES", [])
    names = [str(name).strip() for name in ([names] if isinstance(names, str) else names)]
    names = [name for name in names if name]
    return names[0] if len(names) == 1 else None


def subject_names(static, subject):
    """{'the static trial': name, 'the subject file': name}, the names that were found."""
    found = (("the static trial", file_subject_name(static)),
             ("the subject file", file_subject_name(subject)))
    return {what: name for what, name in found if name}


def check_same_subject(names, measurements, trial, asis_distance, label, legs=None):
    """One warning (it says "subject") when the trial seems another subject's than the
    model's: its subject name (:func:`file_subject_name`) differs from one of `names`
    (:func:`subject_names` of the static trial and subject file, case ignored), or the
    median distance of its ASIS markers (`asis_distance`, mm per frame) lies more than
    :data:`INTER_ASIS_TOLERANCE` from the measurements' InterAsisDistance, or a leg
    (`legs`: ``{'Left': (ASI, KNE, ANK), ...}``, positions (frames, 3) in mm) measures
    more than :data:`LEG_LENGTH_TOLERANCE` from its LegLength. Knee and ankle widths are
    not compared: Plug-in Gait has no medial marker to measure them between."""
    causes = []
    name = file_subject_name(trial)
    if name:
        causes += [f"its subject is {name!r}, that of {what} {other!r}"
                   for what, other in names.items() if other.casefold() != name.casefold()]
    expected = measurements.get("InterAsisDistance")
    seen = np.isfinite(asis_distance)
    measured = float(np.median(asis_distance[seen])) if seen.any() else np.nan
    if expected and abs(measured - expected) > INTER_ASIS_TOLERANCE:
        causes.append(f"its ASIS markers are {measured:.0f} mm apart (median), the "
                      f"subject's InterAsisDistance is {expected:.0f} mm (more than "
                      f"{INTER_ASIS_TOLERANCE:g} mm off)")
    causes += _leg_length_causes(measurements, legs or {})
    if causes:
        warn(f"{label}: another subject's trial? {'; '.join(causes)}: the model's "
             f"measurements may not be this subject's", UserWarning)


def _leg_length_causes(measurements, legs):
    """What :func:`check_same_subject` says of each leg whose markers' length lies more than
    LEG_LENGTH_TOLERANCE from the subject's LegLength."""
    causes = []
    for side, (asis, knee, ankle) in legs.items():
        expected = measurements.get(side + "LegLength")
        with np.errstate(invalid="ignore"):
            chain = (np.linalg.norm(asis - knee, axis=-1)
                     + np.linalg.norm(knee - ankle, axis=-1))
        seen = np.isfinite(chain)
        if not expected or not seen.any():
            continue
        measured = float(np.percentile(chain[seen], 95))
        if abs(measured - expected) > LEG_LENGTH_TOLERANCE:
            causes.append(f"its {side.lower()} leg markers (ASI-KNE-ANK, at the leg's "
                          f"straightest) measure {measured:.0f} mm, the subject's "
                          f"{side}LegLength is {expected:.0f} mm (more than "
                          f"{LEG_LENGTH_TOLERANCE:g} mm off)")
    return causes
