"""An adversarial pass over the newer public functions: the mistakes a lab makes.

Run from the repository root (it imports the package found first on sys.path, so the same
script can judge an older checkout: ``PYTHONPATH=/path/to/old python tools/...``)::

    python tools/adversarial_pass.py            # counts by class
    python tools/adversarial_pass.py --list     # and every case that is not fine

Each case is a call and what a user should get from it:

- ``ok``: a result, with no warning other than those the case allows (no false alarm);
- ``error``: a TypeError or ValueError (a FileNotFoundError for a missing file) whose
  message holds every keyword of the case (names the argument, the marker, the cause);
- ``warn``: a result and a warning whose message holds the keywords; an error naming
  them is accepted too (a value the data cannot support is not returned);
- a function of the result (``check=``) for what the result must be; in a ``warn`` case,
  no warning is fine when the result passes it (a reordered cluster that is symmetric
  gives the right answer).

A case is then classed as *fine*, *crash/hang* (any other exception, or more than
TIME_LIMIT seconds), *silent wrong* (an error or warning was due and none came, or the
result is wrong), *unclear* (the error or warning came but does not name the keywords)
or *false alarm* (an ``ok`` case that warned or raised).

The cases cover the lower-limb pipeline (calibrate_lower_limb, lower_limb_angles), gait
cycles (time_normalize, normalize_by_side, ensemble, stride_table,
spatiotemporal_parameters; not gait_events), functional joints, motion, gap filling,
batch (map_trials), poses (pose_to_angles) and the TRC reader's DataRate. Issue 21's own
examples are in the tests (tests/test_adversarial_api.py and the modules' tests): these
are other cases of the same classes.
"""

import argparse
import os
import re
import signal
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.append(str(ROOT))            # after PYTHONPATH: an older checkout can be judged
sys.path.append(str(ROOT / "tools"))
sys.path.append(str(ROOT / "tests"))     # helpers: the generated trials' marker roles

import bmc_functions as bf  # noqa: E402
from bmc_functions import (Skeleton, angular_velocity, calibrate_lower_limb,  # noqa: E402
                           ensemble, fill_gaps_rigid, functional_axis,
                           functional_joint_centre, helical_axes, helical_axis,
                           lower_limb_angles, normalize_by_side, pose_to_angles, read_trc,
                           rot_x, rot_y, rot_z, spatiotemporal_parameters, sphere_fit_centre,
                           stride_table, time_normalize)
from bmc_functions.batch import map_trials  # noqa: E402

from _adversarial_worker import die_on_three  # noqa: E402  (importable by the workers)
from helpers import FUNCTIONAL_MARKERS, two_leg_markers as walk_markers  # noqa: E402

#: Seconds after which a case counts as a hang.
TIME_LIMIT = 20

DATA = ROOT / "data"
MARKERS_DIR = DATA / "markers"
FUNCTIONAL_DIR = DATA / "functional"

#: Warnings of the committed synthetic walk (two occlusion gaps), allowed in 'ok' cases.
KNOWN = r"fewer than 3 visible|lack a landmark"


def quiet(function, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return function(*args, **kwargs)


STATIC = read_trc(MARKERS_DIR / "static.trc")
WALK = read_trc(MARKERS_DIR / "walk.trc")
F_STATIC = read_trc(FUNCTIONAL_DIR / "static.trc")
HIP = read_trc(FUNCTIONAL_DIR / "hip_star_arc.trc")
KNEE = read_trc(FUNCTIONAL_DIR / "knee_flexion.trc")
MODEL = quiet(calibrate_lower_limb, STATIC, walk_markers())


# --- trial edits ----------------------------------------------------------------------------

def copy(df):
    out = df.copy()
    out.attrs = dict(df.attrs)
    return out


def relabel(df, rename):
    out = copy(df)
    out.columns = pd.MultiIndex.from_tuples([(rename(m), c) for m, c in df.columns],
                                            names=df.columns.names)
    return out


def swap_lr(label):
    return {"R": "L", "L": "R"}.get(label[:1], label[:1]) + label[1:]


def swap_sides(df, labels=None):
    return relabel(df, lambda m: swap_lr(m) if labels is None or m in labels else m)


def scaled(df, factor):
    out = copy(df)
    out.iloc[:, :] = df.to_numpy() * factor
    return out


def mirrored(df, axis):
    out = copy(df)
    out.loc[:, (slice(None), axis)] = -out.loc[:, (slice(None), axis)]
    return out


def rotated(df, degrees):
    """About the vertical (y) axis."""
    out = copy(df)
    R = rot_y(degrees, degrees=True)
    values = df.to_numpy().reshape(len(df), -1, 3) @ R.T
    out.iloc[:, :] = values.reshape(len(df), -1)
    return out


def reversed_time(df):
    out = copy(df)
    out.iloc[:, :] = df.to_numpy()[::-1]
    return out


def swap_markers(df, a, b, frames=slice(None)):
    out = copy(df)
    rows = df.index[frames]
    out.loc[rows, a] = df.loc[rows, b].to_numpy()
    out.loc[rows, b] = df.loc[rows, a].to_numpy()
    return out


def with_hip_markers(df, model, swap=False):
    out = copy(df)
    for side in ("R", "L"):
        other = {"R": "L", "L": "R"}[side] if swap else side
        centre = model.landmarks.loc[other + "HJC"].to_numpy()
        for k, c in enumerate("xyz"):
            out[(side + "HJC", c)] = centre[k]
    out.attrs = dict(df.attrs)
    return out


def clusters(df, labels):
    return np.stack([df[label].to_numpy() for label in labels], axis=1)


# --- cases ----------------------------------------------------------------------------------

CASES = []


def case(name, call, expect="ok", keywords=(), allow=None, check=None, area="",
         check_always=False):
    CASES.append(dict(name=name, call=call, expect=expect, keywords=keywords, allow=allow,
                      check=check, area=area, check_always=check_always))


def pipeline_cases():
    m = walk_markers()
    area = "lower-limb pipeline"
    case("clean walk", lambda: MODEL.angles(WALK), allow=KNOWN, area=area)
    for axis in "xyz":
        case(f"walk mirrored across the {axis} axis",
             lambda axis=axis: MODEL.angles(mirrored(WALK, axis)), "warn",
             [r"mirror|swapped|faces against|upside|backwards"], allow=KNOWN, area=area)
    case("every R/L label swapped", lambda: MODEL.angles(swap_sides(WALK)), "warn",
         ["swapped"], allow=KNOWN, area=area)
    legs = [label for label in WALK.columns.get_level_values(0).unique()
            if label[0] in "RL" and label not in ("RASI", "LASI", "RPSI", "LPSI")]
    case("legs' labels swapped", lambda: MODEL.angles(swap_sides(WALK, legs)), "warn",
         ["swapped"], allow=KNOWN, area=area)
    for start, stop in ((10, 20), (50, 53), (0, 40)):
        def partial(start=start, stop=stop):
            mix = copy(WALK)
            mix.iloc[start:stop] = swap_sides(WALK)[WALK.columns].iloc[start:stop].to_numpy()
            return MODEL.angles(mix)
        case(f"R/L labels swapped in frames {start}-{stop}", partial, "warn",
             ["swapped", f"{stop - start} of"], allow=KNOWN, area=area)
    case("time-reversed walk", lambda: MODEL.angles(reversed_time(WALK)), "warn",
         [r"backwards|reversed"], allow=KNOWN, area=area)
    for degrees in (90, 180, -90):
        case(f"walk along another lab axis ({degrees} deg)",
             lambda d=degrees: MODEL.angles(rotated(WALK, d)), allow=KNOWN, area=area,
             check=lambda r: abs(r["pelvis", "right", "rotation"]).max() < 20)
    case("diagonal walkway (40 deg)", lambda: MODEL.angles(rotated(WALK, 40)), "warn",
         ["direction of progression"], allow=KNOWN, area=area)
    case("walk in m labelled mm", lambda: MODEL.angles(scaled(WALK, 0.001)), "error",
         ["units"], area=area)
    case("walk in cm labelled mm", lambda: MODEL.angles(scaled(WALK, 0.1)), "error",
         ["units"], area=area)
    case("walk in mm labelled m", lambda: MODEL.angles(
        copy(WALK).pipe(lambda d: d.attrs.update(units="m") or d)), "error", ["units"],
        area=area)
    case("static in m labelled mm",
         lambda: calibrate_lower_limb(scaled(STATIC, 0.001), m), "error", ["units"],
         area=area)

    def asis_psis():
        swapped = dict(m, RASIS="RPSI", RPSIS="RASI", LASIS="LPSI", LPSIS="LASI")
        return calibrate_lower_limb(STATIC, swapped)
    case("ASIS and PSIS swapped in the mapping", asis_psis, "error",
         [r"ASIS and PSIS|swapped"], area=area)
    case("ASIS and PSIS labels swapped in the static", lambda: calibrate_lower_limb(
        swap_markers(swap_markers(STATIC, "RASI", "RPSI"), "LASI", "LPSI"), m), "error",
        [r"ASIS and PSIS"], area=area)
    case("RASIS/LASIS swapped in the static", lambda: calibrate_lower_limb(
        swap_markers(STATIC, "RASI", "LASI"), m), "error", ["swapped"], area=area)
    for role, label, joint in (("RKNEE_LAT", "RTH1", "knee"), ("RKNEE_MED", "RTH3", "knee"),
                               ("LKNEE_LAT", "LTH2", "knee"), ("RANKLE_MED", "RTB2", "ankle"),
                               ("LANKLE_LAT", "LTB1", "ankle")):
        case(f"{role} mapped to a cluster marker ({label})",
             lambda role=role, label=label: calibrate_lower_limb(STATIC, dict(m, **{role: label})),
             "error", [joint, role], area=area)
    case("knee markers of the two sides swapped", lambda: calibrate_lower_limb(
        STATIC, dict(m, RKNEE_LAT="LLFC", LKNEE_LAT="RLFC")), "error", ["knee"], area=area)

    def hjc(swap):
        static = with_hip_markers(STATIC, MODEL, swap)
        return calibrate_lower_limb(static, dict(m, RHJC="RHJC", LHJC="LHJC"),
                                    hip_centre="marker")
    case("RHJC/LHJC markers", lambda: hjc(False), area=area)
    case("RHJC/LHJC swapped", lambda: hjc(True), "error", ["HJC", "swapped"], area=area)
    case("one label mapped to two roles", lambda: calibrate_lower_limb(
        STATIC, dict(m, RKNEE_MED="RLFC")), "error", ["RKNEE_LAT", "RKNEE_MED", "RLFC"],
        area=area)
    case("one label mapped to heel and toe", lambda: calibrate_lower_limb(
        STATIC, dict(m, LTOE="LHEEL")), "error", ["LHEEL", "LTOE"], area=area)

    def duplicated():
        df = pd.concat([WALK, WALK[["RTH1"]]], axis=1)
        df.attrs = dict(WALK.attrs)
        return MODEL.angles(df)
    case("a label twice in the trial", duplicated, "error", ["RTH1", "twice"], area=area)

    def text_value():
        df = copy(WALK).astype(object)
        df.iloc[5, 7] = "n/a"
        return MODEL.angles(df)
    case("'n/a' in a coordinate", text_value, "error", [repr(WALK.columns[7][0]), "n/a"],
         area=area)
    case("inf in a coordinate", lambda: MODEL.angles(
        copy(WALK).pipe(lambda d: d.iloc.__setitem__((3, 4), np.inf) or d)), "error",
        ["infinite"], area=area)
    case("no units", lambda: MODEL.angles(
        copy(WALK).pipe(lambda d: d.attrs.pop("units") and d)), "error", ["units"],
        area=area)
    case("units 'inches'", lambda: MODEL.angles(
        copy(WALK).pipe(lambda d: d.attrs.update(units="inches") or d)), "error",
        ["inches"], area=area)
    case("attrs['rate'] twice the index's", lambda: MODEL.angles(
        copy(WALK).pipe(lambda d: d.attrs.update(rate=200.0) or d)), "warn", ["rate"],
        allow=KNOWN, area=area)
    frames = copy(WALK)
    frames.index = pd.RangeIndex(len(WALK))
    case("walk indexed by frame numbers", lambda: MODEL.angles(frames), "warn",
         ["rate"], allow=KNOWN, area=area)
    case("empty trial", lambda: MODEL.angles(WALK.iloc[:0]), "error", ["no frames"],
         area=area)
    case("one frame", lambda: MODEL.angles(WALK.iloc[20:21]), allow=KNOWN, area=area)
    case("dynamic is a number", lambda: MODEL.angles(123), "error", ["dynamic"], area=area)
    case("dynamic is a .txt path", lambda: MODEL.angles("walk.txt"), "error", [".trc"],
         area=area)
    case("static path that does not exist", lambda: calibrate_lower_limb(
        "no_such_static.trc", m), "error", ["no_such_static"], area=area)
    case("cluster marker lost for the whole trial", lambda: MODEL.angles(
        copy(WALK).pipe(lambda d: d.loc.__setitem__((slice(None), "RTH1"), np.nan) or d)),
        allow=KNOWN, area=area)
    case("two thigh markers swapped for 20 frames", lambda: MODEL.angles(
        swap_markers(WALK, "RTH1", "RTH3", slice(30, 50))), "warn", ["RTHIGH", "deforms"],
        allow=KNOWN, area=area)
    case("walk as the static trial", lambda: calibrate_lower_limb(WALK.dropna(), m),
         "error", [], area=area)   # not static: an error (it lacks landmarks) or a warning
    case("static_offset='yes'", lambda: calibrate_lower_limb(STATIC, m, static_offset="yes"),
         "error", ["static_offset"], area=area)
    case("hip_centre='Harrington'", lambda: calibrate_lower_limb(
        STATIC, m, hip_centre="Harrington"), "error", ["hip_centre", "harrington"], area=area)
    case("sides='both'", lambda: calibrate_lower_limb(STATIC, m, sides="both"), "error",
         ["sides", "both"], area=area)
    case("markers is a list", lambda: calibrate_lower_limb(STATIC, list(m)), "error",
         ["markers"], area=area)
    case("a landmark given as a list", lambda: calibrate_lower_limb(
        STATIC, dict(m, RTOE=["RTOE"])), "error", ["RTOE"], area=area)
    case("a label that is a number", lambda: calibrate_lower_limb(
        STATIC, dict(m, RTOE=5)), "error", ["RTOE"], area=area)
    case("client=object()", lambda: lower_limb_angles(STATIC, WALK, m, client=object()),
         "error", ["client"], area=area)
    case("client='localhost', two trials", lambda: lower_limb_angles(
        STATIC, [WALK, WALK], m, client="localhost"), "error", ["client"], area=area)
    case("workers=0", lambda: lower_limb_angles(STATIC, WALK, m, workers=0), "error",
         ["workers"], area=area)
    case("workers='2'", lambda: lower_limb_angles(STATIC, [WALK], m, workers="2"), "error",
         ["workers"], area=area)
    case("errors='ignore'", lambda: lower_limb_angles(STATIC, [WALK], m, errors="ignore"),
         "error", ["errors"], area=area)
    case("empty list of trials", lambda: lower_limb_angles(STATIC, [], m), "error",
         ["empty"], area=area)
    case("one broken trial of three, errors='warn'", lambda: lower_limb_angles(
        STATIC, [WALK, "missing.trc", WALK], m, errors="warn", progress=False), "warn",
        ["missing.trc"], allow=KNOWN, area=area)

    # functional trials
    def hip_fit(trial, **options):
        return calibrate_lower_limb(F_STATIC, FUNCTIONAL_MARKERS, hip_centre="functional",
                                    functional_trial=trial, **options)
    truth = pd.read_csv(FUNCTIONAL_DIR / "static_truth.csv")[
        ["hip_x", "hip_y", "hip_z"]].to_numpy()[0]

    def within(mm):
        return lambda model: np.linalg.norm(
            model.landmarks.loc["RHJC"].to_numpy() - truth) < mm
    case("functional hip, clean", lambda: hip_fit(HIP), check=within(5), area=area)
    for axis in "xz":
        case(f"functional hip trial mirrored across {axis}",
             lambda axis=axis: hip_fit(mirrored(HIP, axis)), "warn",
             [r"mirror|swapped"], area=area)
    case("functional hip trial in m labelled mm", lambda: hip_fit(scaled(HIP, 0.001)),
         "error", ["units"], area=area)
    case("functional hip trial in cm labelled mm", lambda: hip_fit(scaled(HIP, 0.1)),
         "error", ["units"], area=area)
    n = len(HIP) // 2
    case("thigh labels swapped half-way through the hip trial", lambda: hip_fit(
        swap_markers(HIP, "RTH1", "RTH2", slice(n, None))), "warn", ["RTHIGH"], area=area)
    case("pelvis labels swapped for 300 frames", lambda: hip_fit(
        swap_markers(HIP, "RPSI", "LPSI", slice(200, 500))), "warn",
         [r"left out|swapped"], area=area)

    def sliding(mm):
        df = copy(HIP)
        df[("RTH3", "x")] = df[("RTH3", "x")] + np.linspace(0, mm, len(df))
        return df
    case("thigh marker sliding 40 mm in the hip trial", lambda: hip_fit(sliding(40)),
         "warn", ["RTH"], area=area)
    case("thigh marker sliding 3 mm (artefact)", lambda: hip_fit(sliding(3)),
         check=within(6), area=area)
    case("knee axis trial in m labelled mm", lambda: calibrate_lower_limb(
        F_STATIC, FUNCTIONAL_MARKERS, knee_axis="functional",
        knee_axis_trial=scaled(KNEE, 0.001)), "error", ["units"], area=area)
    case("knee axis trial mirrored across z", lambda: calibrate_lower_limb(
        F_STATIC, FUNCTIONAL_MARKERS, knee_axis="functional",
        knee_axis_trial=mirrored(KNEE, "z")), "warn", ["knee axis"], area=area)
    case("knee axis trial, shank labels swapped half-way", lambda: calibrate_lower_limb(
        F_STATIC, FUNCTIONAL_MARKERS, knee_axis="functional",
        knee_axis_trial=swap_markers(KNEE, "RTB1", "RTB2", slice(len(KNEE) // 2, None))),
        "warn", ["RSHANK"], area=area)


def gait_cycle_cases():
    area = "gait cycles"
    t = np.arange(0, 5.001, 0.01)
    y = np.sin(2 * np.pi * t)
    hs = np.array([0.5, 1.5, 2.5, 3.5])
    series = pd.Series(y, index=t)
    case("time_normalize clean", lambda: time_normalize(series, hs), area=area)
    case("n_points=10**9", lambda: time_normalize(series, hs, n_points=10**9), "error",
         ["n_points"], area=area)
    case("n_points=1.5", lambda: time_normalize(series, hs, n_points=1.5), "error",
         ["n_points"], area=area)
    case("n_points=np.int64(51)", lambda: time_normalize(series, hs, n_points=np.int64(51)),
         area=area)
    case("Series indexed by frame numbers", lambda: time_normalize(
        pd.Series(y), hs), "error", [r"frame numbers|milliseconds|ms"], area=area)
    case("Series indexed by ms, events in s", lambda: time_normalize(
        pd.Series(y, index=t * 1000), hs), "error", [r"ms|milliseconds"], area=area)
    case("signal and events in ms", lambda: time_normalize(
        pd.Series(y, index=t * 1000), hs * 1000), "warn", [r"milliseconds"], area=area)
    case("events in ms, signal in s", lambda: time_normalize(series, hs * 1000), "error",
         [r"ms|units"], area=area)
    case("array signal, time in frames", lambda: time_normalize(
        y, hs, time=np.arange(len(y))), "error", [r"frame"], area=area)
    case("unsorted heel strikes", lambda: time_normalize(series, hs[::-1]), "error",
         ["heel_strikes", "sorted"], area=area)
    case("NaN heel strike", lambda: time_normalize(series, np.r_[hs, np.nan]), "error",
         ["heel_strikes", "NaN"], area=area)
    case("2-D heel strikes", lambda: time_normalize(series, hs[None]), "error",
         ["heel_strikes", "1-D"], area=area)
    case("heel strikes as strings", lambda: time_normalize(series, ["0.5", "1.5"]),
         "error", ["heel_strikes"], area=area)
    case("inf in the signal", lambda: time_normalize(
        pd.Series(np.r_[y[:-1], np.inf], index=t), hs), "error", ["infinite"], area=area)
    case("max_gap=None", lambda: time_normalize(series, hs, max_gap=None), "error",
         ["max_gap"], area=area)
    case("max_gap='0.1'", lambda: time_normalize(series, hs, max_gap="0.1"), "error",
         ["max_gap"], area=area)
    case("max_gap=-1", lambda: time_normalize(series, hs, max_gap=-1), "error",
         ["max_gap"], area=area)
    case("repeated times", lambda: time_normalize(
        pd.Series(y, index=np.r_[t[:10], t[9:-1]]), hs), "error", ["time"], area=area)
    case("a string column", lambda: time_normalize(
        pd.DataFrame({"a": y, "b": "x"}, index=t), hs), "error", ["signal"], area=area)
    case("one heel strike", lambda: time_normalize(series, [1.0]), "warn",
         ["no complete cycle"], area=area)
    case("toe-offs unsorted", lambda: time_normalize(series, hs, toe_offs=[2.1, 1.1]),
         "error", ["toe_offs"], area=area)
    case("attrs['rate'] against the index", lambda: time_normalize(
        series.to_frame().pipe(lambda d: d.attrs.update(rate=50.0) or d), hs), "warn",
         ["rate"], area=area)
    cols = pd.MultiIndex.from_tuples([("knee", "right", "flexion"),
                                      ("knee", "left", "flexion")])
    angles = pd.DataFrame(np.c_[y, y], index=t, columns=cols)
    events = {"right": {"heel_strike": hs, "toe_off": hs + 0.6},
              "left": {"heel_strike": hs + 0.5, "toe_off": hs + 1.1}}
    case("normalize_by_side clean", lambda: normalize_by_side(angles, events), area=area)
    case("events without heel_strike", lambda: normalize_by_side(
        angles, {"right": {"toe_off": hs}, "left": {"toe_off": hs}}), "error",
        ["heel_strike"], area=area)
    case("events as arrays", lambda: normalize_by_side(
        angles, {"right": hs, "left": hs}), "error", ["events", "heel_strike"], area=area)
    case("events as a list", lambda: normalize_by_side(angles, [hs, hs]), "error",
         ["events"], area=area)
    case("signal without a side level", lambda: normalize_by_side(
        pd.DataFrame({"a": y}, index=t), events), "error", ["side"], area=area)
    case("signal as a Series", lambda: normalize_by_side(series, events), "error",
         ["signal"], area=area)
    case("events missing the left side", lambda: normalize_by_side(
        angles, {"right": events["right"]}), "error", ["left"], area=area)
    cycles = time_normalize(series, hs)
    case("ensemble clean", lambda: ensemble(cycles), area=area)
    case("ensemble of cycles of different lengths (list)", lambda: ensemble(
        [y[50:150], y[150:260], y[260:350]]), "error", [r"lengths|time-normalise"],
        area=area)

    def unnormalised():
        parts = {k: pd.Series(y[a:b], index=pd.Index(t[a:b] - t[a], name="percent"))
                 for k, (a, b) in enumerate([(50, 150), (150, 260)])}
        return ensemble(pd.concat(parts, names=["cycle", "percent"]).to_frame())
    case("ensemble of un-normalised cycles (DataFrame)", unnormalised, "error",
         [r"time-normalise|same points"], area=area)
    case("ensemble with inf", lambda: ensemble(np.array([[0.0, 1.0], [np.inf, 2.0]])),
         "error", ["infinite"], area=area)
    case("ensemble DataFrame with inf", lambda: ensemble(
        cycles.pipe(lambda d: d.iloc.__setitem__((3, 0), np.inf) or d)), "error",
        ["infinite"], area=area)
    case("ensemble of a 1-D array", lambda: ensemble(y), "error", ["cycles"], area=area)
    case("ensemble without a percent level", lambda: ensemble(angles), "error",
         ["percent"], area=area)
    case("ensemble of NaN cycles", lambda: ensemble(np.full((3, 5), np.nan)), area=area)
    case("stride_table clean", lambda: stride_table(events), area=area)
    case("stride_table, events in ms", lambda: stride_table(
        {"right": {"heel_strike": hs * 1000, "toe_off": hs * 1000 + 600}}), "warn",
        [r"milliseconds"], area=area)
    case("stride_table, events in frame numbers", lambda: stride_table(
        {"right": {"heel_strike": hs * 100, "toe_off": hs * 100 + 60}}), "warn",
        [r"frame numbers"], area=area)
    case("stride_table, unsorted", lambda: stride_table(
        {"right": {"heel_strike": hs[::-1]}}), "error", ["heel_strike", "sorted"],
        area=area)
    case("stride_table, a list", lambda: stride_table([hs]), "error", ["events"], area=area)
    case("stride_table, side as an array", lambda: stride_table({"right": hs}), "error",
         ["events['right']"], area=area)
    case("stride_table without toe-offs", lambda: stride_table(
        {"right": {"heel_strike": hs}}), area=area)
    case("spatiotemporal_parameters, events in ms", lambda: spatiotemporal_parameters(
        {"right": {"heel_strike": hs * 1000, "toe_off": hs * 1000 + 600}}), "warn",
        [r"milliseconds"], area=area)
    case("spatiotemporal_parameters, no events", lambda: spatiotemporal_parameters({}),
         area=area)
    case("spatiotemporal_parameters, arrays", lambda: spatiotemporal_parameters(
        {"right": hs}), "error", ["events['right']"], area=area)


def functional_cases():
    area = "functional joints"
    pelvis = clusters(HIP, ["RASI", "LASI", "RPSI", "LPSI"])
    thigh = clusters(HIP, ["RTH1", "RTH2", "RTH3", "RTH4"])
    k_thigh = clusters(KNEE, ["RTH1", "RTH2", "RTH3", "RTH4"])
    k_shank = clusters(KNEE, ["RTB1", "RTB2", "RTB3", "RTB4"])
    case("SCoRE clean", lambda: functional_joint_centre(pelvis, thigh), area=area)
    half = len(thigh) // 2
    swapped = thigh.copy()
    swapped[half:, [0, 1]] = thigh[half:, [1, 0]]
    case("SCoRE, thigh markers swapped half-way", lambda: functional_joint_centre(
        pelvis, swapped), "warn", ["markers_2", "shape"], area=area)
    jumped = thigh.copy()
    jumped[400:460, 2] += [60.0, 0, 0]
    case("SCoRE, a thigh marker off by 60 mm for 60 frames", lambda: functional_joint_centre(
        pelvis, jumped), "warn", ["markers_2", "60 of"], area=area)
    case("SCoRE, different frame counts", lambda: functional_joint_centre(
        pelvis, thigh[:-1]), "error", ["same number of frames"], area=area)
    case("SCoRE, 2 markers", lambda: functional_joint_centre(pelvis, thigh[:, :2]), "error",
         ["markers_2", "3"], area=area)
    case("SCoRE, 2-D markers", lambda: functional_joint_centre(pelvis[0], thigh), "error",
         ["markers_1", "shape"], area=area)
    case("SCoRE, inf", lambda: functional_joint_centre(
        np.where(np.arange(len(pelvis))[:, None, None] == 3, np.inf, pelvis), thigh),
        "error", ["markers_1", "infinite"], area=area)
    case("SCoRE, strings", lambda: functional_joint_centre("pelvis", thigh), "error",
         ["markers_1"], area=area)
    case("SCoRE, all NaN", lambda: functional_joint_centre(pelvis * np.nan, thigh),
         "error", ["markers_1"], area=area)
    case("SCoRE on a knee trial (14 deg about a second axis)", lambda:
         functional_joint_centre(k_thigh, k_shank), "warn", ["second axis"], area=area)
    hinge = np.einsum("fij,nj->fni", rot_z(np.linspace(0, 1.2, 200)), k_shank[0])
    case("SCoRE on a pure hinge", lambda: functional_joint_centre(
        np.broadcast_to(k_thigh[0], (200, 4, 3)), hinge), "error", ["hinge"], area=area)
    case("SCoRE with no movement", lambda: functional_joint_centre(
        pelvis[:50], np.broadcast_to(thigh[0], (50, 4, 3))), "warn", ["movement"],
        area=area)
    case("sphere fit clean", lambda: sphere_fit_centre(pelvis, thigh), area=area)
    centre = quiet(functional_joint_centre, pelvis, thigh)
    static_pelvis = clusters(F_STATIC, ["RASI", "LASI", "RPSI", "LPSI"]).mean(axis=0)
    case("locate clean", lambda: centre.locate(static_pelvis), area=area)
    case("locate with markers in another order", lambda: centre.locate(
        static_pelvis[[1, 0, 2, 3]]), "warn", ["shape"], area=area)
    case("locate with a cluster 1.4 times larger", lambda: centre.locate(
        static_pelvis * 1.4), "warn", ["shape"], area=area)
    case("locate in metres", lambda: centre.locate(static_pelvis / 1000), "warn",
         ["shape"], area=area)
    case("locate with 3 of 4 markers", lambda: centre.locate(static_pelvis[:3]), "error",
         ["markers", "shape"], area=area)
    case("locate segment=3", lambda: centre.locate(static_pelvis, segment=3), "error",
         ["segment"], area=area)
    case("SARA clean", lambda: functional_axis(k_thigh, k_shank), area=area)
    along = np.nanmean(quiet(functional_axis, k_thigh, k_shank)[1], axis=0)
    case("SARA, perpendicular reference", lambda: functional_axis(
        k_thigh, k_shank, reference_direction=np.cross(along, [0, 1.0, 0])), "error",
        ["reference_direction", "perpendicular"], area=area)
    case("SARA, reference of wrong shape", lambda: functional_axis(
        k_thigh, k_shank, reference_direction=[1.0, 0]), "error", ["reference_direction"],
        area=area)
    s_half = len(k_shank) // 2
    k_swapped = k_shank.copy()
    k_swapped[s_half:, [0, 2]] = k_shank[s_half:, [2, 0]]
    case("SARA, shank markers swapped half-way", lambda: functional_axis(
        k_thigh, k_swapped), "warn", ["markers_2"], area=area)
    axis = quiet(functional_axis, k_thigh, k_shank)
    right = axis.locate(k_thigh[0])
    case("axis locate, markers reversed", lambda: axis.locate(
        k_thigh[0, ::-1]), "warn", ["shape"], area=area,
         check=lambda r: np.linalg.norm(r[0] - right[0]) < 5 and r[1] @ right[1] > 0.998)


def motion_cases():
    area = "motion"
    R = rot_z(np.radians(2.0 * np.arange(50)))
    t = np.zeros((50, 3))
    case("angular_velocity clean", lambda: angular_velocity(R, 100), area=area)
    for step in (100, 150, 200, 250):
        case(f"angular_velocity at {step} deg per frame", lambda step=step: angular_velocity(
            rot_z(np.radians(step * np.arange(10))), 100), "warn", ["degrees", "alias"],
            area=area)
    case("angular_velocity rate=0", lambda: angular_velocity(R, 0), "error", ["rate"],
         area=area)
    case("angular_velocity rate='100'", lambda: angular_velocity(R, "100"), "error",
         ["rate"], area=area)
    case("angular_velocity rate=True", lambda: angular_velocity(R, True), "error",
         ["rate"], area=area)
    case("angular_velocity one frame", lambda: angular_velocity(R[:1], 100), "error",
         ["2 frames"], area=area)
    case("angular_velocity frame='world'", lambda: angular_velocity(R, 100, "world"),
         "error", ["frame"], area=area)
    case("angular_velocity of a reflection", lambda: angular_velocity(
        R * np.array([1, 1, -1.0])[:, None], 100), "error", ["det"], area=area)
    case("angular_velocity with NaN frames", lambda: angular_velocity(
        np.where(np.arange(50)[:, None, None] % 7 == 0, np.nan, R), 100), area=area)
    big = rot_x(np.radians(0.01 * np.arange(200_000)))
    case("helical_axes(angle_step) on 200,000 frames", lambda: helical_axes(
        big, np.zeros((len(big), 3)), angle_step=np.radians(10)), area=area,
        check=lambda r: len(r[1]) == 199)
    many = rot_x(np.radians(np.arange(100_000) % 360.0))
    case("helical_axes(angle_step), 16,666 axes in 100,000 frames", lambda: helical_axes(
        many, np.zeros((len(many), 3)), angle_step=np.radians(5.5)), area=area,
        check=lambda r: len(r[1]) == 16_666)
    slow = rot_x(np.radians(0.0001 * np.arange(100_000)))
    case("helical_axes(angle_step) never reached, 100,000 frames", lambda: helical_axes(
        slow, np.zeros((len(slow), 3)), angle_step=np.radians(30)), area=area,
        check=lambda r: len(r[1]) == 0)
    case("helical_axes step=0", lambda: helical_axes(R, t, step=0), "error", ["step"],
         area=area)
    case("helical_axes step=1.5", lambda: helical_axes(R, t, step=1.5), "error", ["step"],
         area=area)
    case("helical_axes both steps", lambda: helical_axes(R, t, step=1, angle_step=0.2),
         "error", ["exactly one"], area=area)
    case("helical_axes angle_step=4", lambda: helical_axes(R, t, angle_step=4.0), "error",
         ["angle_step"], area=area)
    case("helical_axes all NaN", lambda: helical_axes(R * np.nan, t, angle_step=0.2),
         area=area, check=lambda r: len(r[1]) == 0)
    case("helical_axes t of wrong shape", lambda: helical_axes(R, t[:, :2], step=1),
         "error", ["t", "shape"], area=area)
    case("helical_axis tiny rotation", lambda: helical_axis(
        np.eye(3), np.zeros(3), rot_x(0.001), np.zeros(3)), "warn", ["min_angle"],
        area=area)


def gap_cases():
    area = "gap filling"
    labels = ["RTH1", "RTH2", "RTH3", "RTH4"]
    markers = clusters(WALK, labels)
    reference = clusters(STATIC, labels).mean(axis=0)
    gappy = markers.copy()
    gappy[10:30, 2] = np.nan

    def close(limit):
        return lambda r: np.nanmax(np.abs(r[10:30, 2] - markers[10:30, 2])) < limit
    case("fill clean", lambda: fill_gaps_rigid(gappy, reference), area=area,
         check=close(6))
    case("fill, own shape", lambda: fill_gaps_rigid(gappy), area=area, check=close(6))
    centre = reference.mean(axis=0)
    for factor in (1.3, 0.7, 2.0):
        case(f"fill, reference {factor} times the size", lambda factor=factor:
             fill_gaps_rigid(gappy, (reference - centre) * factor + centre), "warn",
             ["shape"], area=area)
    for order in ([1, 0, 2, 3], [0, 1, 3, 2], [3, 2, 1, 0]):
        case(f"fill, reference in order {order}", lambda order=order: fill_gaps_rigid(
            gappy, reference[order]), "warn", ["shape"], area=area, check=close(6))
    case("fill, reference in metres", lambda: fill_gaps_rigid(gappy, reference / 1000),
         "warn", ["shape"], area=area)
    case("fill, reference of another cluster", lambda: fill_gaps_rigid(
        gappy, clusters(STATIC, ["LTH1", "LTH2", "LTH3", "LTH4"]).mean(axis=0)[[2, 0, 1, 3]]),
        "warn", ["shape"], area=area)
    swapped = gappy.copy()
    swapped[50:70, [0, 1]] = gappy[50:70, [1, 0]]
    swapped[55:60, 3] = np.nan
    case("fill, two markers swapped around a gap", lambda: fill_gaps_rigid(
        swapped, reference), "warn", ["shape"], area=area)
    case("fill, reference frame out of range", lambda: fill_gaps_rigid(gappy, 500),
         "error", ["reference", "500"], area=area)
    case("fill, return_mask='yes'", lambda: fill_gaps_rigid(gappy, return_mask="yes"),
         "error", ["return_mask"], area=area)
    case("fill, 2 markers", lambda: fill_gaps_rigid(gappy[:, :2]), "error", ["3"],
         area=area)
    case("fill, collinear reference", lambda: fill_gaps_rigid(
        gappy, np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0.0]])), "error",
        ["reference"], area=area)
    case("fill, inf", lambda: fill_gaps_rigid(np.where(np.isnan(gappy), np.inf, gappy)),
         "error", ["infinite"], area=area)
    frame = WALK[labels]
    case("fill, DataFrame with a reference lacking a marker", lambda: fill_gaps_rigid(
        frame, STATIC[labels[:3]]), "error", ["RTH4"], area=area)


def batch_cases():
    area = "batch"
    import operator
    import functools
    case("map_trials in processes", lambda: map_trials(
        functools.partial(operator.mul, 2), [1, 2, 3], workers=2, progress=False),
        area=area, check=lambda r: r == [2, 4, 6])
    case("map_trials, one item kills its worker", lambda: map_trials(
        die_on_three, range(8), workers=2, errors="warn", progress=False), "warn",
        [r"^1 of 8 items failed and gave None: 3: |$^"], area=area, check_always=True,
        check=lambda r: r == [0, 10, 20, None, 40, 50, 60, 70])
    case("map_trials, the dying item with errors='raise'", lambda: map_trials(
        die_on_three, range(5), workers=2, progress=False), "error", [],
        area=area)
    case("map_trials(function=5)", lambda: map_trials(5, [1]), "error", ["function"],
         area=area)
    case("map_trials(client='localhost')", lambda: map_trials(abs, [1], client="localhost"),
         "error", ["client"], area=area)
    case("map_trials(client=object())", lambda: map_trials(abs, [1], client=object()),
         "error", ["client"], area=area)
    case("map_trials(workers=True)", lambda: map_trials(abs, [1], workers=True), "error",
         ["workers"], area=area)
    case("map_trials(errors='skip')", lambda: map_trials(abs, [1], errors="skip"), "error",
         ["errors"], area=area)
    case("map_trials over a generator", lambda: map_trials(abs, (x for x in [-1, 2])),
         area=area, check=lambda r: r == [1, 2])


def pose_cases():
    area = "poses"
    sk = Skeleton.default()
    pose = sk.tpose()
    frames = 120
    turn = rot_y(np.linspace(0, 90, frames), degrees=True)
    moving = {k: np.einsum("fij,j->fi", turn, v[0]) + [0, 1.0, 0] for k, v in pose.items()}
    keys = [k for k in moving if k not in ("hips", "neck")]
    case("pose_to_angles clean", lambda: pose_to_angles(
        {k: moving[k] for k in keys}, sk), area=area)
    for a, b, (start, stop) in (("lefthip", "righthip", (40, 45)),
                                ("lefthip", "righthip", (0, 3)),
                                ("leftshoulder", "rightshoulder", (70, 72)),
                                ("lefthip", "righthip", (100, 120))):
        def swapped(a=a, b=b, start=start, stop=stop):
            p = {k: moving[k].copy() for k in keys}
            p[a][start:stop], p[b][start:stop] = moving[b][start:stop], moving[a][start:stop]
            return pose_to_angles(p, sk)
        case(f"{a}/{b} swapped in frames {start}-{stop}", swapped, "warn",
             [f"{stop - start} of", "swapped"], area=area)
    case("a keypoint missing", lambda: pose_to_angles(
        {k: moving[k] for k in keys[1:]}, sk), "error", [keys[0]], area=area)
    case("positions of wrong shape", lambda: pose_to_angles(
        {k: moving[k][:, :2] for k in keys}, sk), "error", ["shape"], area=area)
    case("skeleton=None", lambda: pose_to_angles({k: moving[k] for k in keys}, None),
         "error", ["skeleton"], area=area)
    case("sequence='ABC'", lambda: pose_to_angles({k: moving[k] for k in keys}, sk, "ABC"),
         "error", ["ABC"], area=area)
    case("a keypoint as strings", lambda: pose_to_angles(
        dict({k: moving[k] for k in keys}, leftknee="knee"), sk), "error", ["leftknee"],
        area=area)
    case("keypoints of different lengths", lambda: pose_to_angles(
        dict({k: moving[k] for k in keys}, leftknee=moving["leftknee"][:-1]), sk),
        "error", ["frames"], area=area)
    case("a keypoint lost for 10 frames", lambda: pose_to_angles(
        dict({k: moving[k] for k in keys},
             leftwrist=np.where(np.arange(frames)[:, None] < 10, np.nan,
                                moving["leftwrist"])), sk), area=area)


def trc_cases():
    area = "TRC reader"

    def trc(rate, times):
        header = ("PathFileType\t4\t(X/Y/Z)\tt.trc\n"
                  "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\t"
                  "OrigDataStartFrame\tOrigNumFrames\n"
                  f"{rate}\t{rate}\t{len(times)}\t1\tmm\t{rate}\t1\t{len(times)}\n"
                  "Frame#\tTime\tM\t\t\n\t\tX1\tY1\tZ1\n")
        # x = frame number (from 1: a point at exactly (0, 0, 0) would be read as a gap)
        rows = "".join(f"{k + 1}\t{t:.3f}\t{k + 1}\t0\t0\n" for k, t in enumerate(times))
        handle, path = tempfile.mkstemp(suffix=".trc")
        with os.fdopen(handle, "w") as file:
            file.write(header + rows)
        return path

    for rate, step, expect in ((100, 0.02, "warn"), (100, 0.001, "warn"), (50, 0.01, "warn"),
                               (100, 0.01, "ok"), (120, 1 / 120, "ok"), (250, 0.004, "ok")):
        path = trc(rate, np.arange(200) * step)
        case(f"TRC DataRate {rate} Hz, Time column steps {step:.4g} s",
             lambda path=path: read_trc(path), expect,
             ["DataRate", "Time"] if expect == "warn" else (), area=area)


# --- the runner -----------------------------------------------------------------------------

def _passes(check, result):
    try:
        return bool(check(result))
    except Exception:  # noqa: BLE001
        return False


class Timeout(Exception):
    pass


def _alarm(signum, frame):
    raise Timeout


def run_case(c):
    signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(TIME_LIMIT)
    start = time.perf_counter()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = c["call"]()
        error = None
    except Timeout:
        return "crash/hang", f"more than {TIME_LIMIT} s"
    except BaseException as exc:  # noqa: BLE001 (classified below)
        result, error, caught = None, exc, []
    finally:
        signal.alarm(0)
    elapsed = time.perf_counter() - start
    texts = [str(w.message) for w in caught]
    keywords = c["keywords"]

    def names(text):
        return all(re.search(k, text, re.IGNORECASE) if "|" in k
                   else k.lower() in text.lower() for k in keywords)
    if error is not None:
        acceptable = isinstance(error, (TypeError, ValueError)) or (
            isinstance(error, FileNotFoundError))
        if c["expect"] == "error" and not keywords and (
                acceptable or "WorkerDied" in type(error).__name__):
            return "fine", f"{type(error).__name__}: {error}"
        if not acceptable:
            return "crash/hang", f"{type(error).__name__}: {error}"
        if c["expect"] == "ok":
            return "false alarm", f"{type(error).__name__}: {error}"
        if names(str(error)):
            return "fine", str(error)
        return "unclear", f"{type(error).__name__}: {error}"
    if c["expect"] == "error":
        return "silent wrong", "no error" + (f"; warned: {texts}" if texts else "")
    unexpected = [t for t in texts if not (c["allow"] and re.search(c["allow"], t))]
    if c["expect"] == "warn":
        relevant = [t for t in unexpected if names(t)]
        if not unexpected:
            if c["check"] is not None and _passes(c["check"], result):
                return "fine", "no warning, and the result is right"
            return "silent wrong", "no warning"
        if c["check_always"] and not _passes(c["check"], result):
            return "silent wrong", f"wrong result; warned: {unexpected}"
        if not relevant:
            return "unclear", f"warned without naming {keywords}: {unexpected}"
        return "fine", relevant[0]
    elif unexpected:
        return "false alarm", f"warned: {unexpected}"
    if c["check"] is not None:
        try:
            good = c["check"](result)
        except Exception as exc:  # noqa: BLE001
            return "silent wrong", f"check failed: {type(exc).__name__}: {exc}"
        if not good:
            return "silent wrong", "wrong result"
    return "fine", f"{elapsed:.2f} s"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", action="store_true", help="print every case not fine")
    parser.add_argument("--skip", default=None, help="regular expression: skip the cases "
                        "whose name matches (e.g. 'n_points' on a release that would try "
                        "to allocate the memory)")
    args = parser.parse_args(argv)
    for make in (pipeline_cases, gait_cycle_cases, functional_cases, motion_cases,
                 gap_cases, batch_cases, pose_cases, trc_cases):
        make()
    counts, by_area = {}, {}
    for c in CASES:
        if args.skip and re.search(args.skip, c["name"]):
            kind, detail = "skipped", "--skip"
            print(f"[skipped] {c['area']}: {c['name']}")
            continue
        kind, detail = run_case(c)
        counts[kind] = counts.get(kind, 0) + 1
        by_area.setdefault(c["area"], {}).setdefault(kind, 0)
        by_area[c["area"]][kind] += 1
        if args.list and kind != "fine":
            print(f"[{kind}] {c['area']}: {c['name']}: {detail[:300]}")
    classes = ["crash/hang", "silent wrong", "unclear", "false alarm", "fine"]
    print(f"{len(CASES)} cases, package at {Path(bf.__file__).parent}")
    print("area".ljust(22) + "".join(k.rjust(14) for k in classes))
    for area, found in by_area.items():
        print(area.ljust(22) + "".join(str(found.get(k, 0)).rjust(14) for k in classes))
    print("total".ljust(22) + "".join(str(counts.get(k, 0)).rjust(14) for k in classes))


if __name__ == "__main__":
    main()
