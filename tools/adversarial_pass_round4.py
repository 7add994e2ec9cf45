"""An adversarial pass, round 4: the public functions of this round (kinetics, the upper
body, the clinical layer).

Run from the repository root (the runner, the classes and their meaning are those of
``tools/adversarial_pass.py``; ``--list`` prints every case that is not fine)::

    python tools/adversarial_pass_round4.py
    python tools/adversarial_pass_round4.py --list

Areas: force plates (read_force_plates, resample_force_plates, assign_plates); dynamics
(inverse_dynamics, segment_inertia, segment_parameters); Plug-in Gait (angles with the
upper-body markers missing, swapped or zeroed and its measurements in the wrong unit;
PlugInGait.kinetics with a body mass in grams or pounds, plates of another trial, a trial
whose attrs were lost); clinical (spatiotemporal_parameters with the trial, normative_data,
gait_profile_score, gait_events with force_plates); files (write_c3d,
read_c3d_model_outputs); keypoint_angles. Only the trials shipped with the package are
used (bmc_functions/example_data), so it runs in any clone.

Counts on the integration branch at cca6c02 and after this pass's fixes (99 cases;
crash/hang, silent wrong, unclear, false alarm, fine)::

    before:  0  32  5  0  62
    after:   0  24  3  0  72

Issue 32's upper-body checks (bmc_functions/models/plug_in_gait/upper_body_checks.py): at
bfda3ec the 26 Plug-in Gait cases were 0 13 2 0 11 (whole table 0 21 3 0 75); with them
all 26 are fine (whole table 0 8 1 0 90), and the five cases added with them (swaps in a
run of frames, a ghost finger marker, a doubtful shoulder offset) too: 104 cases,
0 8 1 0 95. The swaps in every frame and the impossible measurements are now errors, as
expected here.

The silent cases left are listed by ``--list``.

Issue 32's second pass added 21 cases (120; the area "plug-in gait lower": TOE and ANK
swapped in every frame, a thigh wand placed medially, with and without a static trial;
body masses in tonnes and at the 0.2 kg and 10 % boundaries; positions in mm given to
inverse_dynamics; a normative table in radians; an event after the trial) and turned
"write_c3d angles of another length" into a check of the documented behaviour (rows at
the trial's frames, gaps elsewhere). Counts on main at bfda3ec and after its fixes::

    before:  0  32  5  0  83
    after:   0  13  2  0  105

The 13 silent and 2 unclear left were all Plug-in Gait's upper body. With both passes
merged (125 cases: the 99, the 5 of the upper body and the 21 of the second pass)::

    bfda3ec:  0  39  2  0  84   (the 125 cases against main before this round's fixes)
    merged:   0   0  0  0 125

Expected numbers are the clean call's own results (an edit that changes nothing the
model sees must change nothing) or hand-derived values (a segment at rest held by m g).
"""

import argparse
import os
import re
import shutil
import sys
import tempfile
import warnings
import atexit
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.append(str(ROOT))
sys.path.append(str(ROOT / "tools"))

import adversarial_pass as ap  # noqa: E402  (the runner and the trial edits)
import bmc_functions as bf  # noqa: E402
from bmc_functions.examples import example_file  # noqa: E402

TMP = Path(tempfile.mkdtemp(prefix="adversarial4_"))
atexit.register(shutil.rmtree, TMP, ignore_errors=True)

STATIC = example_file("plug_in_gait/Static_trial.c3d")
VSK = example_file("plug_in_gait/Test.vsk")
WALK_PATH = example_file("plug_in_gait/Movement_trial.c3d")
VICON_PLATES = {2: None, 3: None}
FEET = {"right": ["RHEE", "RTOE"], "left": ["LHEE", "LTOE"]}
copy = ap.copy


def quiet(function, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return function(*args, **kwargs)


SUBJECT = dict(bf.read_vsk(VSK))
MODEL = quiet(bf.plug_in_gait, STATIC, VSK)
WALK = bf.read_c3d(WALK_PATH)
PLATES = bf.read_force_plates(WALK_PATH)
ANGLES = quiet(MODEL.angles, WALK)
KINETICS = quiet(MODEL.kinetics, WALK_PATH, plates=VICON_PLATES)
UPPER = ["head", "thorax", "neck", "spine", "shoulder", "elbow", "wrist"]
#: the clean trial's own warnings, allowed in every case
with warnings.catch_warnings(record=True) as _seen:
    warnings.simplefilter("always")
    MODEL.angles(WALK)
    MODEL.kinetics(WALK_PATH, plates=VICON_PLATES)
KNOWN = "|".join(re.escape(str(w.message)[:40]) for w in _seen) or None


def case(name, call, expect="ok", keywords=(), allow=None, **options):
    allow = f"{allow}|{KNOWN}" if allow and KNOWN else (allow or KNOWN)
    ap.case(name, call, expect, keywords, allow, **options)


def same_angles(joints, tol=1.0):
    """The result's angles of `joints` within `tol` degrees of the clean trial's."""
    def check(result):
        a = result.loc[:, result.columns.get_level_values(0).isin(joints)]
        b = ANGLES.loc[:, a.columns]
        return a.shape[1] > 0 and bool((np.abs(a - b).max().max() < tol)
                                       or np.allclose(a, b, atol=tol, equal_nan=True))
    return check


def nan_or_same(joints):
    def check(result):
        cols = result.columns.get_level_values(0).isin(joints)
        a = result.loc[:, cols]
        return a.shape[1] == 0 or a.isna().all().all() or same_angles(joints)(result)
    return check


def nan_or_same_outside(joints, rows):
    """Outside `rows`, the angles of `joints` equal the clean trial's; inside, each is
    either NaN or within 1 degree of it."""
    def check(result):
        a = result.loc[:, result.columns.get_level_values(0).isin(joints)]
        b = ANGLES.loc[:, a.columns]
        inside = np.zeros(len(a), dtype=bool)
        inside[rows] = True
        outside_same = np.allclose(a[~inside], b[~inside], atol=1e-9, equal_nan=True)
        near = (a[inside] - b[inside]).abs() < 1.0
        return outside_same and bool((a[inside].isna() | near).all().all())
    return check


def subject(**changes):
    out = dict(SUBJECT)
    out.update(changes)
    return out


def swapped(a, b):
    return ap.swap_markers(WALK, a, b)


def zeroed(label):
    out = copy(WALK)
    out.loc[:, label] = 0.0
    return out


def dropped(labels):
    out = WALK.drop(columns=labels, level=0)
    out.attrs = dict(WALK.attrs)
    return out


def same_kinetics(tol=0.05):
    return lambda r: np.allclose(r.to_numpy(), KINETICS.loc[:, r.columns].to_numpy(),
                                 atol=tol, equal_nan=True)


# --- Plug-in Gait: upper body -------------------------------------------------------------

def pig_cases():
    area = "plug-in gait"
    case("clean walk", lambda: MODEL.angles(WALK), area=area, check=same_angles(UPPER, 1e-9))
    for key, value in (("LeftShoulderOffset", 5.0), ("RightShoulderOffset", 5.0),
                       ("LeftElbowWidth", 960.0), ("RightElbowWidth", 9.2),
                       ("LeftWristWidth", 610.0), ("LeftHandThickness", 300.0)):
        case(f"{key}={value} (wrong unit)",
             lambda k=key, v=value: quiet(bf.plug_in_gait, STATIC, subject(**{k: v})).angles(
                 WALK), "error", [key], area=area)
    case("HeadOffset=15 (degrees where radians belong)",
         lambda: quiet(bf.plug_in_gait, STATIC, subject(HeadOffset=15.0)).angles(WALK),
         "error", ["HeadOffset"], area=area)
    case("RightShoulderOffset=110 (in range, 0.6 of SHO's distance to the thorax)",
         lambda: quiet(bf.plug_in_gait, STATIC, subject(RightShoulderOffset=110.0)).angles(
             WALK), "warn", ["RightShoulderOffset"], area=area)
    for a, b in (("LSHO", "RSHO"), ("LELB", "RELB"), ("LWRA", "RWRA"), ("LFHD", "RFHD"),
                 ("LELB", "LWRA"), ("CLAV", "STRN"), ("C7", "T10"), ("LFIN", "LWRB")):
        case(f"{a} and {b} swapped in every frame", lambda a=a, b=b: MODEL.angles(
            swapped(a, b)), "error", [f"{a}|{b}|swap"], area=area)
    for a, b in (("LSHO", "RSHO"), ("C7", "T10"), ("RFIN", "RWRA")):
        case(f"{a} and {b} swapped in frames 100-129", lambda a=a, b=b: MODEL.angles(
            ap.swap_markers(WALK, a, b, slice(100, 130))), "warn", [f"{a}|{b}", "30 of"],
            area=area, check=nan_or_same_outside(UPPER, slice(100, 130)))
    ghost = copy(WALK)
    ghost.loc[ghost.index[50:60], "RFIN"] = ghost.loc[ghost.index[50:60], "RFIN"] + 5000.0
    case("RFIN a ghost 5 m away in 10 frames", lambda: MODEL.angles(ghost), "warn",
         ["RFIN", "10 of"], area=area, check=lambda r: same_angles(
             [j for j in UPPER if j != "wrist"], 1e-9)(r)
         and r["wrist", "right"].iloc[50:60].isna().all().all())
    for label in ("CLAV", "LSHO", "RFHD", "LWRB"):
        case(f"{label} zeroed (0, 0, 0) in every frame",
             lambda label=label: MODEL.angles(zeroed(label)), "warn", [label], area=area,
             check=nan_or_same(UPPER))
    case("upper-body markers absent", lambda: MODEL.angles(dropped(
        ["LSHO", "RSHO", "LELB", "RELB", "LWRA", "RWRA", "LWRB", "RWRB", "LFIN", "RFIN",
         "LUPA", "RUPA", "LFRM", "RFRM"])), area=area,
        check=lambda r: same_angles(["hip", "knee", "ankle"], 1e-9)(r) and nan_or_same(
            ["shoulder", "elbow", "wrist"])(r), allow="missing|absent|shoulder|arm")
    case("head markers absent", lambda: MODEL.angles(dropped(["LFHD", "RFHD", "LBHD",
                                                               "RBHD"])), area=area,
         check=nan_or_same(["head"]), allow="missing|absent|head")
    case("trial in metres, attrs units='m'", lambda: MODEL.angles(
        ap.scaled(WALK, 0.001).pipe(lambda d: (d.attrs.update(units="m"), d)[1])),
        area=area, check=same_angles(UPPER + ["hip", "knee"]))
    case("trial in metres, attrs still 'mm'", lambda: MODEL.angles(ap.scaled(WALK, 0.001)),
         "error", [r"unit|metre|mm"], area=area)
    case("trial whose attrs were lost", lambda: MODEL.angles(
        WALK.pipe(lambda d: (setattr(d, "attrs", {}), d)[1] if False else
                  pd.DataFrame(d.to_numpy(), index=d.index, columns=d.columns))),
        "warn", ["unit"], area=area, check=same_angles(UPPER))
    case("duplicated marker label", lambda: MODEL.angles(pd.concat(
        [WALK, WALK[["LSHO"]]], axis=1).pipe(lambda d: (d.attrs.update(WALK.attrs), d)[1])),
        "error", ["LSHO", r"duplicat|twice"], area=area)


# --- Plug-in Gait: lower body, with and without the static trial --------------------------

LOWER = ["pelvis", "hip", "knee", "ankle", "foot"]


def medial(df, wand):
    """`wand` moved 120 mm towards the other side (along LASI - RASI or back)."""
    return shifted_wand(df, wand, 120.0)


def pig_lower_cases():
    area = "plug-in gait lower"
    no_static = quiet(bf.plug_in_gait, None, subject(**MODEL.static_offsets))
    static = bf.read_c3d(STATIC)
    case("no static trial: clean walk", lambda: no_static.angles(WALK), area=area,
         check=same_angles(LOWER, 1e-6))
    for p in "LR":
        case(f"{p}TOE and {p}ANK swapped in every frame (static given)",
             lambda p=p: MODEL.angles(swapped(p + "TOE", p + "ANK")), "error",
             [f"{p}TOE", f"{p}ANK", "swap"], area=area)
        case(f"{p}TOE and {p}ANK swapped in every frame (no static)",
             lambda p=p: no_static.angles(swapped(p + "TOE", p + "ANK")), "error",
             [f"{p}TOE", f"{p}ANK", "swap"], area=area)
        case(f"{p}THI placed medially (no static)",
             lambda p=p: no_static.angles(medial(WALK, p + "THI")), "error",
             [f"{p}THI", "medial"], area=area)
        case(f"{p}THI placed medially in the static and the walk",
             lambda p=p: quiet(bf.plug_in_gait, medial(static, p + "THI"), VSK).angles(
                 medial(WALK, p + "THI")), "error", [f"{p}THI", "medial"], area=area)
        case(f"{p}THI moved 20 mm medially (still lateral; no static)",
             lambda p=p: no_static.angles(shifted_wand(WALK, p + "THI", 20.0)), area=area,
             allow=".",
             check=lambda r: r.shape == ANGLES.shape)


def shifted_wand(df, wand, mm):
    out = copy(df)
    p = wand[0]
    inward = df["LASI" if p == "R" else "RASI"].to_numpy() - df[p + "ASI"].to_numpy()
    out.loc[:, wand] = (df[wand].to_numpy()
                        + mm * inward / np.linalg.norm(inward, axis=1, keepdims=True))
    return out


# --- Plug-in Gait: kinetics -----------------------------------------------------------------

def kinetics_cases():
    area = "kinetics"
    run = MODEL.kinetics
    case("clean: equals the path's", lambda: run(WALK, force_plates=PLATES,
                                                 plates=VICON_PLATES), area=area,
         allow=r"stance\(s\) that no plate",
         check=same_kinetics(1e-9))
    for value, keys in ((85000.0, ["body_mass"]), (0.085, ["body_mass"]), (np.nan, ["body_mass"]),
                        ("85", ["body_mass"]), (-85, ["body_mass"]), (np.inf, ["body_mass"])):
        case(f"body_mass={value!r}", lambda v=value: run(WALK_PATH, plates=VICON_PLATES,
                                                        body_mass=v), "error", keys, area=area)
    case("body_mass=0.2 (the smallest accepted) runs", lambda: quiet(
        run, WALK_PATH, plates=VICON_PLATES, body_mass=0.2), area=area,
        check=lambda r: r.attrs["body_mass_kg"] == 0.2)
    case("body_mass=90 against the subject's 85 kg (within 10 %)", lambda: run(
        WALK_PATH, plates=VICON_PLATES, body_mass=90), area=area,
        check=lambda r: r.attrs["body_mass_kg"] == 90)
    case("body_mass=187 (pounds) against the subject's 85 kg",
         lambda: run(WALK_PATH, plates=VICON_PLATES, body_mass=187), "warn",
         [r"body_mass|Bodymass"], area=area)
    shifted = copy(PLATES)
    shifted.index = shifted.index + 100.0
    case("force plates of another time base (no overlap)",
         lambda: run(WALK, force_plates=shifted, plates=VICON_PLATES), "error",
         [r"time|overlap"], area=area)
    lost = pd.DataFrame(PLATES.to_numpy(), index=PLATES.index, columns=PLATES.columns)
    case("force plates whose attrs were lost", lambda: run(WALK, force_plates=lost,
                                                           plates=VICON_PLATES),
         "error", ["force_plates"], area=area)
    trial_lost = pd.DataFrame(WALK.to_numpy(), index=WALK.index, columns=WALK.columns)
    case("trial whose attrs were lost", lambda: run(trial_lost, force_plates=PLATES,
                                                    plates=VICON_PLATES),
         "warn", [r"unit|rate|attrs"], area=area, check=same_kinetics())
    metres = copy(PLATES)
    cop = [c for c in metres.columns if c[1].startswith("cop")]
    metres[cop] = metres[cop] / 1000.0
    case("plate COP in metres, attrs still 'mm'", lambda: run(
        WALK, force_plates=metres, plates=VICON_PLATES), "warn",
        [r"cop|centre of pressure|unit|plate"], area=area, check=same_kinetics())
    other = bf.read_c3d(STATIC)
    case("trial of another recording (the static) with these plates",
         lambda: run(other, force_plates=PLATES), "error", [r"time|overlap|force_plates"],
         area=area)
    case("one-frame trial", lambda: run(WALK.iloc[:1].pipe(copy), force_plates=PLATES),
         "error", [r"frame|short"], area=area)
    case("empty trial", lambda: run(WALK.iloc[:0].pipe(copy), force_plates=PLATES),
         "error", [r"frame|empty|dynamic"], area=area)
    case("plates={9: None} (no such plate)", lambda: run(WALK_PATH, plates={9: None}),
         "error", ["plates", "9"], area=area)
    case("plates=[2, 3] (a list)", lambda: run(WALK_PATH, plates=[2, 3]), "error",
         ["plates"], area=area)
    nan_plates = copy(PLATES)
    nan_plates.iloc[1000:1100, :] = np.nan
    case("NaN in 100 plate samples", lambda: run(WALK, force_plates=nan_plates,
                                                 plates=VICON_PLATES),
         "warn", [r"NaN|missing|gap"], area=area,
         check=lambda r: r.isna().any().any())
    case("LowerLimbModel.kinetics body_mass=0.07 (tonnes)", lambda: quiet(
        bf.calibrate_lower_limb, ap.STATIC, ap.walk_markers()).kinetics(
            ap.WALK, pd.DataFrame(), body_mass=0.07), "error", ["body_mass", "0.07"],
        area=area)
    case("LowerLimbModel.kinetics body_mass=85000 (grams)", lambda: quiet(
        bf.calibrate_lower_limb, ap.STATIC, ap.walk_markers()).kinetics(
            ap.WALK, pd.DataFrame(), body_mass=85000), "error", ["body_mass"], area=area)


# --- force plates -------------------------------------------------------------------------

def plate_cases():
    area = "force plates"
    case("read_force_plates of a missing file", lambda: bf.read_force_plates(
        TMP / "none.c3d"), "error", ["none.c3d"], area=area)
    case("read_force_plates of a TRC", lambda: bf.read_force_plates(
        example_file("gait/walk.trc")), "error", [r"c3d|walk.trc"], area=area)
    case("read_force_plates of the static (no plates?)", lambda: bf.read_force_plates(
        STATIC), area=area, allow=".", check=lambda r: r is not None)
    for value in ("bogus", None, 3):
        case(f"read_force_plates zero={value!r}", lambda v=value: bf.read_force_plates(
            WALK_PATH, zero=v), "error", ["zero"], area=area)
    for value in (-1.0, np.nan, "20"):
        case(f"read_force_plates cop_threshold={value!r}",
             lambda v=value: bf.read_force_plates(WALK_PATH, cop_threshold=v), "error",
             ["cop_threshold"], area=area)
    case("resample_force_plates: frames match the trial's",
         lambda: bf.resample_force_plates(PLATES), area=area,
         check=lambda r: len(r) == len(WALK) and np.allclose(r.index, WALK.index, atol=1e-6))
    case("resample_force_plates with attrs lost", lambda: bf.resample_force_plates(
        pd.DataFrame(PLATES.to_numpy(), index=PLATES.index, columns=PLATES.columns)),
        "error", [r"plates|rate|attrs"], area=area)
    case("resample_force_plates of an array", lambda: bf.resample_force_plates(
        PLATES.to_numpy()), "error", ["plates"], area=area)
    clean = quiet(bf.assign_plates, PLATES, WALK, FEET)
    case("assign_plates misspelt foot label", lambda: bf.assign_plates(
        PLATES, WALK, {"right": ["RHEEX", "RTOE"], "left": ["LHEE", "LTOE"]}), "error",
        ["RHEEX"], area=area)
    case("assign_plates trial in metres (units 'm')", lambda: bf.assign_plates(
        PLATES, ap.scaled(WALK, 0.001).pipe(lambda d: (d.attrs.update(units="m"), d)[1]),
        FEET), area=area, allow=".", check=lambda r: r["side"].tolist() == clean["side"].tolist())
    case("assign_plates trial in metres, attrs 'mm'", lambda: bf.assign_plates(
        PLATES, ap.scaled(WALK, 0.001), FEET), "warn", [r"unit|metre|mm|far|outside"],
        area=area, check=lambda r: r["side"].tolist() == clean["side"].tolist())
    shifted = copy(WALK)
    shifted.index = shifted.index + 100.0
    case("assign_plates trial of another time base", lambda: bf.assign_plates(
        PLATES, shifted, FEET), "error", [r"time|overlap"], area=area)
    case("assign_plates threshold=-5", lambda: bf.assign_plates(PLATES, WALK, FEET,
                                                                threshold=-5),
         "error", ["threshold"], area=area)
    case("assign_plates feet as a list", lambda: bf.assign_plates(PLATES, WALK,
                                                                  ["RHEE", "LHEE"]),
         "error", ["feet"], area=area)


# --- dynamics -----------------------------------------------------------------------------

def dynamics_cases():
    area = "dynamics"
    R = np.repeat(np.eye(3)[None], 5, axis=0)
    com = np.tile([0.1, 0, 0], (5, 1))
    joint = np.zeros((5, 3))
    I = np.zeros((3, 3))

    def solve(**kw):
        args = dict(R=[R], com=[com], joint=[joint], mass=[1.0], inertia=[I], rate=100)
        args.update(kw)
        return bf.inverse_dynamics(args.pop("R"), args.pop("com"), args.pop("joint"),
                                   args.pop("mass"), args.pop("inertia"), **args)
    case("segment at rest: m g up, m g d moment", lambda: solve(), area=area,
         check=lambda r: np.allclose(r.force[0, 2], [0, 9.80665, 0])
         and np.allclose(r.moment[0, 2], [0, 0, 0.980665]))
    for name, kw, keys in (
            ("mass=-1", dict(mass=[-1.0]), ["mass"]),
            ("mass=nan", dict(mass=[np.nan]), ["mass"]),
            ("inertia not symmetric", dict(inertia=[np.triu(np.ones((3, 3)))]), ["inertia"]),
            ("R scaled by 2 (not a rotation)", dict(R=[2 * R]), ["R"]),
            ("no rate", dict(rate=None), ["rate"]),
            ("rate=0", dict(rate=0), ["rate"]),
            ("com of 4 frames, R of 5", dict(com=[com[:4]]), ["com"]),
            ("one frame", dict(R=[R[:1]], com=[com[:1]], joint=[joint[:1]]),
             [r"frame|short"])):
        case(f"inverse_dynamics {name}", lambda kw=kw: solve(**kw), "error", keys,
             area=area)
    case("inverse_dynamics com and joint in mm (a 100 mm lever)", lambda: solve(
        com=[com * 1000], joint=[joint + [0, 3000.0, 0]]), "error", ["com", r"mm|metre"],
        area=area)
    case("inverse_dynamics cop in mm, the rest in m", lambda: solve(
        force=np.tile([0, 700.0, 0], (5, 1)), cop=np.tile([100.0, 0, 50.0], (5, 1))),
        "error", ["cop", r"mm|metre"], area=area)
    case("inverse_dynamics cop 0.15 m from the ankle (metres)", lambda: solve(
        force=np.tile([0, 700.0, 0], (5, 1)), cop=np.tile([0.1, 0, 0.05], (5, 1))),
        area=area, check=lambda r: np.isfinite(r.moment).all())
    gap = np.tile([0.1, 0, 0], (9, 1))
    gap[4] = np.nan                         # 9 frames: runs of 4 either side
    case("inverse_dynamics NaN com in a frame -> NaN there", lambda: solve(
        R=[np.repeat(np.eye(3)[None], 9, axis=0)], com=[gap], joint=[np.zeros((9, 3))]),
        area=area, allow=".", check=lambda r: np.isnan(r.force[0, 4]).all()
        and np.isfinite(r.force[0, [0, 8]]).all())
    case("segment_inertia known shank", lambda: bf.segment_inertia(
        [[0, 0.5, 0]], [[0, 0.1, 0]], 70, "shank"), area=area,
        check=lambda r: abs(r[0] - 3.255) < 1e-9 and np.allclose(r[1], [[0, 0.3268, 0]],
                                                                  atol=1e-4))
    for name, args, keys in (
            ("body_mass=70000 (grams)", ([[0, 0.5, 0]], [[0, 0.1, 0]], 70000, "shank"),
             ["body_mass"]),
            ("body_mass=nan", ([[0, 0.5, 0]], [[0, 0.1, 0]], np.nan, "shank"),
             ["body_mass"]),
            ("segment='femur'", ([[0, 0.5, 0]], [[0, 0.1, 0]], 70, "femur"), ["segment"]),
            ("proximal == distal", ([[0, 0.5, 0]], [[0, 0.5, 0]], 70, "shank"),
             [r"length|proximal|distal"]),
            ("segment in mm (400 mm shank)", ([[0, 500, 0]], [[0, 100, 0]], 70, "shank"),
             [r"metre|unit|length|mm"])):
        case(f"segment_inertia {name}", lambda a=args: bf.segment_inertia(*a),
             "warn" if "mm" in name else "error", keys, area=area)
    case("segment_inertia proximal == distal in 2 of 5 frames -> NaN inertia there",
         lambda: bf.segment_inertia([[0, 0.5, 0]] * 5, [[0, 0.5, 0]] * 2 + [[0, 0.1, 0]] * 3,
                                    70, "shank"), "warn", ["2 of 5", "shank"], area=area,
         check_always=True, check=lambda r: np.isnan(r[2][:2]).all()
         and np.isfinite(r[2][2:]).all())
    case("segment_parameters('bogus')", lambda: bf.segment_parameters("bogus"), "error",
         ["parameters"], area=area)


# --- clinical layer and files ---------------------------------------------------------------

def clinical_cases():
    area = "clinical"
    roles = MODEL.event_markers()
    events = quiet(bf.gait_events, WALK, roles)
    spt = quiet(bf.spatiotemporal_parameters, events, WALK, roles)
    case("spatiotemporal_parameters trial in metres (units 'm')",
         lambda: bf.spatiotemporal_parameters(events, ap.scaled(WALK, 0.001).pipe(
             lambda d: (d.attrs.update(units="m"), d)[1]), roles), area=area, allow=".",
         check=lambda r: np.allclose(r.select_dtypes("number").to_numpy(),
                                     spt.select_dtypes("number").to_numpy(), equal_nan=True,
                                     rtol=1e-6))
    case("spatiotemporal_parameters misspelt marker", lambda: bf.spatiotemporal_parameters(
        events, WALK, dict(roles, RHEEL="RHEEX")), "error",
        ["RHEEX"], area=area)
    shifted = copy(WALK)
    shifted.index = shifted.index + 100.0
    case("spatiotemporal_parameters events outside the trial's time",
         lambda: bf.spatiotemporal_parameters(events, shifted, roles), "error",
         [r"time|outside|overlap"], area=area)
    late = {side: {key: np.r_[times, 9.0 + 0.5 * (side == "left")]
                   for key, times in found.items()} for side, found in events.items()}
    case("spatiotemporal_parameters with one heel strike after the trial",
         lambda: bf.spatiotemporal_parameters(late, WALK, roles), "warn",
         [r"outside the trial", "9 s"], area=area)
    case("gait_events force_plates of another time base", lambda: bf.gait_events(
        WALK, roles, force_plates=PLATES.set_axis(PLATES.index + 100.0).pipe(
            lambda d: (d.attrs.update(PLATES.attrs), d)[1])), "error",
        [r"time|overlap|force_plates"], area=area)
    case("gait_events force_plates a numpy array", lambda: bf.gait_events(
        WALK, roles, force_plates=PLATES.to_numpy()), "error", ["force_plates"], area=area)
    cycles = quiet(bf.normalize_by_side, ANGLES, events)
    case("normative_data of an empty list", lambda: bf.normative_data([]), "error",
         ["cycles"], area=area)
    case("normative_data of a dict", lambda: bf.normative_data({"a": cycles}), "error",
         ["cycles"], area=area)
    norm = quiet(bf.normative_data, [cycles])
    case("gait_profile_score against itself: GVS and GPS >= 0, finite", lambda:
         bf.gait_profile_score(cycles, norm), area=area, allow=".",
         check=lambda r: np.isfinite(np.asarray(r.gps, float)).all())
    radians = cycles * np.pi / 180
    case("gait_profile_score of cycles in radians", lambda: bf.gait_profile_score(
        radians, norm), "error", [r"radian|degree|unit"], area=area)
    case("gait_profile_score of a normative in radians", lambda: bf.gait_profile_score(
        cycles, norm * np.pi / 180), "error", ["normative", r"radian"], area=area)
    case("gait_profile_score: one variable moving 1/20 as much as the normal (degrees)",
         lambda: bf.gait_profile_score(cycles.loc[:, [("knee", s, "flexion") for s in
                                                       ("left", "right")]] / 20 + 1.0,
                                       norm, variables={"knee_flexion": ("knee", "flexion")}),
         area=area, allow=".", check=lambda r: np.isfinite(float(r.gps["overall"])))
    case("gait_profile_score pelvis='middle'", lambda: bf.gait_profile_score(
        cycles, norm, pelvis="middle"), "error", ["pelvis"], area=area)
    case("gait_profile_score normative of a dict", lambda: bf.gait_profile_score(
        cycles, {"a": 1}), "error", ["normative"], area=area)

    def round_trip(trial):
        path = TMP / "out.c3d"
        bf.write_c3d(path, trial)
        return bf.read_c3d(path)
    case("write_c3d round trip", lambda: round_trip(WALK), area=area, allow=".",
         check=lambda r: np.allclose(r[["LASI", "RSHO"]].to_numpy(),
                                     WALK[["LASI", "RSHO"]].to_numpy(), atol=1e-2,
                                     equal_nan=True))
    case("write_c3d of a trial whose attrs were lost", lambda: round_trip(pd.DataFrame(
        WALK.to_numpy(), index=WALK.index, columns=WALK.columns)), "warn",
        [r"unit|attrs|rate"], area=area, check=lambda r: r.attrs.get("rate") == 120.0
        and r.attrs.get("units") == "mm")
    case("write_c3d into a missing folder", lambda: bf.write_c3d(TMP / "no" / "x.c3d",
                                                                  WALK), "error",
         ["no"], area=area)
    # documented: rows at the trial's frames are written there, frames without a row are
    # gaps (written every other frame, or one cycle, on purpose); the times say where
    case("write_c3d angles of 10 rows (the trial's first frames)",
         lambda: bf.read_c3d_model_outputs(bf.write_c3d(TMP / "y.c3d", WALK,
                                                        angles=ANGLES.iloc[:10])),
         area=area, allow=".",
        check=lambda r: np.allclose(r[("LKneeAngles", "x")].iloc[:10],
                                    ANGLES[("knee", "left", "flexion")].iloc[:10], atol=1e-3)
        and r[("LKneeAngles", "x")].iloc[10:].isna().all())
    case("read_c3d_model_outputs of a TRC", lambda: bf.read_c3d_model_outputs(
        example_file("gait/walk.trc")), "error", [r"c3d|walk.trc"], area=area)
    case("keypoint_angles of an array", lambda: bf.keypoint_angles(np.zeros((5, 75))),
         "error", ["trial"], area=area)
    case("keypoint_angles keypoints='bogus'", lambda: bf.keypoint_angles(WALK,
                                                                         keypoints="bogus"),
         "error", ["keypoints"], area=area)
    case("keypoint_angles of a Plug-in Gait trial (no keypoint labels)",
         lambda: bf.keypoint_angles(WALK), "error", [r"keypoint|label|missing"], area=area)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", action="store_true", help="print every case not fine")
    parser.add_argument("--only", default=None, help="regular expression on the area")
    args = parser.parse_args(argv)
    for make in (pig_cases, pig_lower_cases, kinetics_cases, plate_cases, dynamics_cases,
                 clinical_cases):
        make()
    counts, by_area = {}, {}
    for c in ap.CASES:
        if args.only and not re.search(args.only, c["area"]):
            continue
        kind, detail = ap.run_case(c)
        counts[kind] = counts.get(kind, 0) + 1
        by_area.setdefault(c["area"], {}).setdefault(kind, 0)
        by_area[c["area"]][kind] += 1
        if args.list and kind != "fine":
            print(f"[{kind}] {c['area']}: {c['name']}: {detail[:240]}", flush=True)
    classes = ["crash/hang", "silent wrong", "unclear", "false alarm", "fine"]
    print(f"{sum(counts.values())} cases, package at {Path(bf.__file__).parent}")
    print("area".ljust(22) + "".join(k.rjust(14) for k in classes))
    for area, found in by_area.items():
        print(area.ljust(22) + "".join(str(found.get(k, 0)).rjust(14) for k in classes))
    print("total".ljust(22) + "".join(str(counts.get(k, 0)).rjust(14) for k in classes))


if __name__ == "__main__":
    os.environ.setdefault("MPLBACKEND", "Agg")
    main()
