"""Gait events from markers against force-plate events, on the shared real trials.

Prints, for every shared trial with force plates (../shared/data: the Codamotion walks of
2015 and 1997, newwalk.c3d and Walk1.c3d of Motion Analysis, gait_with_emg.c3d, the Plug-in
Gait stair descent, and the treadmill run against grf_run.mot's vertical force; sample14.c3d,
damaged on purpose, is refused by the plate reader and listed so), at its own rate and
resampled to 50-250 Hz, with and without the refinement (``refine=``): per trial and
event, both sides pooled, the reference count, found % (within 100 ms walking, 60 ms
running), median and max |error| and the median (``bias_ms``) and mean signed error (ms,
negative = early). Then the leave-one-out of the calibration on the plates
(``gait_events(force_plates=...)``), and the synthetic trials of data/gait/.

newwalk.c3d and Walk1.c3d repeat labels (RANK, RKNE, LANK, LKNE, virtual points) with
different data in each copy, which read_c3d refuses: here the first copy keeps the label
and later ones become ``LABEL#2`` (:func:`read_markers`); the roles use the heel and toe.

Run from the repository root:  python tools/validate_gait_events.py [--all] [--write]

``--write`` stores the table of the Codamotion walk (whose file may not be copied into the
repository) as data/real/gait_events_vs_force_plates.csv, for notebook 10; the tests
recompute it from ../shared when that is present and check it equals the stored file.
"""

import sys
import warnings
from pathlib import Path

import pandas as pd

from bmc_functions import compare_events, force_plate_events, gait_events, read_c3d, read_trc

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "data"

#: The stored table of the Codamotion walk (written by --write, shown by notebook 10).
STORED = ROOT / "data" / "real" / "gait_events_vs_force_plates.csv"

#: trial name -> (file, roles, gait, tolerance in s)
TRIALS = {
    "codamotion walk": (
        SHARED / "force_plates" / "codamotion_gaitwands_20150204.c3d",
        {"RASIS": "R.ASIS", "LASIS": "L.ASIS", "RPSIS": "R.PSIS", "LPSIS": "L.PSIS",
         "RHEEL": "R.Heel", "RTOE": "R.Toe", "RANKLE_LAT": "R.Ankle",
         "LHEEL": "L.Heel", "LTOE": "L.Toe", "LANKLE_LAT": "L.Ankle"}, 0.1),
    "PiG stair descent": (
        SHARED / "plug_in_gait" / "Movement_trial.c3d",
        {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
         "RHEEL": "RHEE", "RTOE": "RTOE", "RANKLE_LAT": "RANK",
         "LTOE": "LTOE", "LANKLE_LAT": "LANK"}, 0.1),
}


def event_table(trials=TRIALS, steps=(1, 2, 4), heel=(True, False), detector=gait_events):
    """The comparison table of `detector` against the force plates, every trial, every
    decimation step (1 = the file's rate) and with / without the heel markers."""
    tables = []
    for name, (path, roles, tolerance) in trials.items():
        if not path.exists():
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            trial = read_c3d(path)
            reference = force_plate_events(path, roles, trial=trial)
        rate = trial.attrs["rate"]
        for step in steps:
            if rate / step < 45:
                continue
            part = trial.iloc[::step].copy()
            part.attrs["rate"] = rate / step    # the rate of the decimated trial
            for with_heel in heel:
                use = roles if with_heel else {k: v for k, v in roles.items()
                                               if not k.endswith("HEEL")}
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    try:
                        detected = detector(part, use)
                        note = ""
                    except ValueError as err:
                        detected, note = {}, f"error: {str(err)[:60]}"
                note = note or "; ".join(sorted({str(w.message)[:60] for w in caught}))
                table = compare_events(detected, reference, tolerance=tolerance)
                table.insert(0, "heel", "yes" if with_heel else "no")
                table.insert(0, "rate", round(rate / step))
                table.insert(0, "trial", name)
                table["warning"] = note
                tables.append(table)
    return pd.concat(tables, ignore_index=True) if tables else pd.DataFrame()


def zeni_alone(trial, roles):
    """Zeni et al.'s (2008) coordinate events alone, without the refinement: the events
    `gait_events` gives for a foot that never rests on a floor, here asked for every side
    (``refine=False``), so that they come from the package's own code."""
    return gait_events(trial, roles, gait="walking", refine=False)


def stored_table():
    """The table stored for notebook 10: the Codamotion walk (200 Hz, decimated to 100 and
    50 Hz, with and without its heel markers), gait_events and Zeni's events alone against
    its force plates; every side. Empty when ../shared is absent."""
    coda = {"codamotion walk": TRIALS["codamotion walk"]}
    tables = []
    for method, detector in (("gait_events", gait_events), ("Zeni alone", zeni_alone)):
        table = event_table(coda, detector=detector)
        if table.empty:
            return table
        table.insert(1, "method", method)
        tables.append(table)
    table = pd.concat(tables, ignore_index=True)
    return table.drop(columns="trial").rename(columns={"found_%": "found_percent"})


def resample(trial, rate):
    """The trial sampled at `rate` (Hz) by linear interpolation of each coordinate (NaN
    where a neighbour is NaN): a recording of the same motion at another rate."""
    import numpy as np
    old = trial.index.to_numpy(float)
    new = np.arange(old[0], old[-1] + 1e-9, 1.0 / rate)
    values = trial.to_numpy(float)
    out = np.empty((len(new), values.shape[1]))
    for k in range(values.shape[1]):        # columns, not frames
        column = values[:, k]
        out[:, k] = np.interp(new, old, column)
        missing = np.interp(new, old, np.isnan(column).astype(float)) > 0
        out[missing, k] = np.nan
    result = pd.DataFrame(out, index=pd.Index(new, name=trial.index.name),
                          columns=trial.columns)
    result.attrs = dict(trial.attrs, rate=float(rate))
    return result


def synthetic_table(rates=(50, 60, 100, 150, 250), heel=(True, False), margin=0.1,
                    detector=gait_events):
    """Detected events against the exact events of the synthetic trials of data/gait/
    (walking 100 Hz overground, running 150 Hz on a treadmill) resampled to `rates`;
    true events within `margin` s of the trial's ends (which no data can confirm) and in
    a marker gap are left out."""
    root = Path(__file__).resolve().parents[1] / "data" / "gait"
    roles = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
             "RHEEL": "RHEE", "RTOE": "RTOE", "RMT5": "RMT5",
             "LHEEL": "LHEE", "LTOE": "LTOE", "LMT5": "LMT5"}
    tables = []
    for name, tolerance in (("walk", 0.1), ("run", 0.06)):
        trial = read_trc(root / f"{name}.trc")
        truth = pd.read_csv(root / f"{name}_events.csv")
        t0, t1 = trial.index[0] + margin, trial.index[-1] - margin
        truth = truth[(truth.time > t0) & (truth.time < t1) & ~truth.in_gap]
        reference = {side: {event: part.loc[part.event == event, "time"].to_numpy()
                            for event in ("heel_strike", "toe_off")}
                     for side, part in truth.groupby("side")}
        for rate in rates:
            part = resample(trial, rate)
            for with_heel in heel:
                use = roles if with_heel else {k: v for k, v in roles.items()
                                               if not k.endswith("HEEL")}
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    try:
                        detected = detector(part, use)
                    except ValueError as err:
                        detected = {}
                        caught.append(warnings.WarningMessage(f"error: {err}", UserWarning,
                                                              "", 0))
                table = compare_events(detected, reference, tolerance=tolerance)
                table.insert(0, "heel", "yes" if with_heel else "no")
                table.insert(0, "rate", rate)
                table.insert(0, "trial", f"synthetic {name}")
                table["warning"] = "; ".join(sorted({str(w.message)[:60] for w in caught}))
                tables.append(table)
    return pd.concat(tables, ignore_index=True)


# --- every shared trial with plates (issue 31) ---------------------------------------------------

def _c3d_roles(heel, toe, ankle, pelvis):
    roles = dict(pelvis)
    for side in "RL":
        roles.update({f"{side}HEEL": side + heel, f"{side}TOE": side + toe,
                      f"{side}ANKLE_LAT": side + ankle})
    return roles


_HH_PELVIS = {"RASIS": "RASI", "LASIS": "LASI", "SACRUM": "VSAC"}

#: trial name -> (file, roles, tolerance (s)): every shared trial whose force plates give the
#: reference events (sample14.c3d, damaged on purpose, is refused by the plate reader and
#: listed as such). The running trial's reference is grf_run.mot's vertical force.
SHARED_TRIALS = {
    "codamotion walk 2015": TRIALS["codamotion walk"][:2] + (0.1,),
    "PiG stair descent": TRIALS["PiG stair descent"][:2] + (0.1,),
    "codamotion walk 1997": (
        SHARED / "walks_with_plates" / "codamotion_gaitwands_19970212.c3d",
        TRIALS["codamotion walk"][1], 0.1),
    "newwalk (MAC 2003)": (
        SHARED / "walks_with_plates" / "newwalk.c3d",
        _c3d_roles("HEE", "TOE", "ANK", _HH_PELVIS), 0.1),
    "Walk1 (MAC 2019)": (
        SHARED / "walks_with_plates" / "Walk1.c3d",
        _c3d_roles("HEE", ".TO", "ANK", _HH_PELVIS), 0.1),
    "gait_with_emg (IST 2019)": (
        SHARED / "walks_with_plates" / "gait_with_emg.c3d",
        _c3d_roles("CAL", "TOE", "LMA", {"RASIS": "RASI", "LASIS": "LASI",
                                         "RPSIS": "RPSI", "LPSIS": "LPSI"}), 0.1),
    "sample14 (damaged)": (
        SHARED / "walks_with_plates" / "sample14.c3d",
        {"RASIS": "RASI", "LASIS": "LASI", "SACRUM": "SACR", "RHEEL": "RHEE",
         "RTOE": "RTOE", "RANKLE_LAT": "RANK", "LTOE": "LTOE", "LANKLE_LAT": "LANK"}, 0.1),
    "treadmill run": (
        SHARED / "motion_capture_run.trc",
        {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
         "RHEEL": "RCAL", "RTOE": "RTOE", "RMT5": "RMT5",
         "LHEEL": "LCAL", "LTOE": "LTOE", "LMT5": "LMT5"}, 0.06),
}


def read_markers(path):
    """The markers of a shared trial. A C3D file whose labels repeat (newwalk.c3d and
    Walk1.c3d: RANK, RKNE, LANK, LKNE and virtual points twice, the copies holding
    different data) is read point by point with ezc3d, the first copy keeping the label
    and later copies renamed ``LABEL#2``, ``LABEL#3`` (POINT:LABELS order: the marker
    set's own copy comes first; the roles use no repeated label but the ankles, which
    the heel makes unnecessary)."""
    path = Path(path)
    if path.suffix.lower() == ".trc":
        return read_trc(path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return read_c3d(path)
    except ValueError as err:
        if "duplicate marker labels" not in str(err):
            raise
    import ezc3d
    import numpy as np
    c3d = ezc3d.c3d(str(path), extract_forceplat_data=False)
    point = c3d["parameters"]["POINT"]
    labels, seen = [], {}
    for label in point["LABELS"]["value"]:
        seen[label] = seen.get(label, 0) + 1
        labels.append(label if seen[label] == 1 else f"{label}#{seen[label]}")
    data = c3d["data"]["points"]                      # (4, n_points, n_frames)
    xyz = data[:3].transpose(2, 1, 0).astype(float)   # frames, points, 3
    gaps = (data[3].T < 0) | np.all(xyz == 0, axis=2)
    xyz[gaps] = np.nan
    rate = float(point["RATE"]["value"][0])
    columns = pd.MultiIndex.from_product([labels, ["x", "y", "z"]])
    df = pd.DataFrame(xyz.reshape(len(xyz), -1), columns=columns,
                      index=pd.Index(np.arange(len(xyz)) / rate, name="time"))
    df.attrs = {"rate": rate, "units": point["UNITS"]["value"][0]}
    return df


def run_reference(threshold=20.0):
    """The running trial's events from grf_run.mot (300 Hz): where each foot's vertical
    force (``R_ground_force_vy``, ``L_``) rises above / falls below `threshold` N."""
    import numpy as np
    from bmc_functions.files.force_plates import loaded_runs
    path = SHARED / "grf_run.mot"
    text = path.read_text().splitlines()
    start = next(k for k, line in enumerate(text) if line.strip() == "endheader") + 1
    grf = pd.read_csv(path, sep=r"\s+", skiprows=start)
    time = grf["time"].to_numpy()
    rate = 1.0 / np.median(np.diff(time))
    events = {}
    for side, prefix in (("right", "R"), ("left", "L")):
        force = grf[f"{prefix}_ground_force_vy"].to_numpy()
        starts, stops = loaded_runs(force, rate, threshold, 0.05)
        events[side] = {
            "heel_strike": time[[s for s in starts if s > 0]],
            "toe_off": time[[s - 1 for s in stops if s < len(force)]]}
    return events


def plate_reference(name):
    """(markers, reference events) of a shared trial; ValueError when its plates are
    refused (sample14.c3d)."""
    path, roles, _ = SHARED_TRIALS[name]
    trial = read_markers(path)
    if path.suffix.lower() == ".trc":
        return trial, run_reference()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reference = force_plate_events(path, roles, trial=trial)
    return trial, reference


def _signed_mean(detected, reference, tolerance):
    """Mean signed error (ms) of the reference events found, per (side, event) and
    'both' (the nearest detected event of the same side and kind, within tolerance)."""
    import numpy as np
    out, pooled = {}, {}
    for side, found in reference.items():
        for event, times in found.items():
            mine = np.asarray(detected.get(side, {}).get(event, []), float)
            times = np.asarray(times, float)
            if not mine.size or not times.size:
                continue
            error = mine[np.argmin(np.abs(mine[None] - times[:, None]), axis=1)] - times
            error = error[np.abs(error) <= tolerance]
            out[(side, event)] = error
            pooled.setdefault(event, []).append(error)
    means = {key: (round(1000 * float(np.mean(e)), 1) if e.size else float("nan"))
             for key, e in out.items()}
    for event, parts in pooled.items():
        e = np.concatenate(parts)
        means[("both", event)] = round(1000 * float(np.mean(e)), 1) if e.size else float("nan")
    return means


def shared_table(names=None, rates=(None,), refine=(True, False), detector=gait_events,
                 **options):
    """Every shared trial (or `names`) at its own rate (None) and resampled to `rates`,
    with and without the refinement: found %, median, max, median signed (bias) and
    mean signed error (ms) per side and event against its plates. A trial whose plates are
    refused gets one row with the error."""
    tables = []
    for name in names or SHARED_TRIALS:
        path, roles, tolerance = SHARED_TRIALS[name]
        if not path.exists():
            continue
        try:
            trial, reference = plate_reference(name)
        except ValueError as err:
            tables.append(pd.DataFrame([{"trial": name, "warning": f"refused: {err}"[:90]}]))
            continue
        for rate in rates:
            part = trial if rate is None else resample(trial, rate)
            for flag in refine:
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    try:
                        detected = detector(part, roles, refine=flag, **options)
                        note = ""
                    except ValueError as err:
                        detected, note = {}, f"error: {str(err)[:60]}"
                note = note or "; ".join(sorted({str(w.message)[:60] for w in caught}))
                table = compare_events(detected, reference, tolerance=tolerance)
                means = _signed_mean(detected, reference, tolerance)
                table["mean_ms"] = [means.get((s, e), float("nan"))
                                    for s, e in zip(table.side, table.event)]
                table.insert(0, "refine", flag)
                table.insert(0, "rate", round(part.attrs["rate"]))
                table.insert(0, "trial", name)
                table["warning"] = note
                tables.append(table)
    return pd.concat(tables, ignore_index=True) if tables else pd.DataFrame()


def calibration_table(names=None, detector=gait_events):
    """Leave-one-out of the calibration on the plates (gait_events(force_plates=...)):
    each plate event of each trial hidden in turn, the marker detector's offset measured
    on the trial's other plate events, and the hidden event predicted by the marker event
    with that offset removed. Per trial and event: how many, the mean signed and median
    absolute error (ms) of the marker events alone and calibrated."""
    import numpy as np
    from bmc_functions.gait.plate_events import calibrate_events
    rows = []
    for name in names or SHARED_TRIALS:
        path, roles, tolerance = SHARED_TRIALS[name]
        if not path.exists():
            continue
        try:
            trial, reference = plate_reference(name)
        except ValueError:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            detected = detector(trial, roles)
        errors = {}
        for side, found in reference.items():
            for event, times in found.items():
                for k, hidden in enumerate(times):       # each plate event in turn
                    rest = {s: {e: (np.delete(t, k) if (s, e) == (side, event) else t)
                                for e, t in f.items()} for s, f in reference.items()}
                    events, source, _ = calibrate_events(detected, rest)
                    mine = events[side][event][source[side][event] == "markers"]
                    raw = np.asarray(detected[side][event], float)
                    if not mine.size or not raw.size:
                        continue
                    before = raw[np.argmin(np.abs(raw - hidden))] - hidden
                    after = mine[np.argmin(np.abs(mine - hidden))] - hidden
                    if abs(before) <= tolerance:
                        errors.setdefault(event, []).append((before, after))
        for event, pairs in errors.items():
            ms = 1000 * np.array(pairs)
            rows.append({"trial": name, "event": event, "n": len(ms),
                         "mean_ms_markers": round(float(ms[:, 0].mean()), 1),
                         "mean_ms_calibrated": round(float(ms[:, 1].mean()), 1),
                         "median_abs_ms_markers": round(float(np.median(abs(ms[:, 0]))), 1),
                         "median_abs_ms_calibrated": round(float(np.median(abs(ms[:, 1]))), 1)})
    return pd.DataFrame(rows)


if __name__ == "__main__":
    pd.set_option("display.width", 200, "display.max_columns", 20, "display.max_colwidth", 60)
    if "--write" in sys.argv:
        table = stored_table()
        if table.empty:
            sys.exit(f"{SHARED} not found: the Codamotion walk is needed for --write")
        table.to_csv(STORED, index=False)
        print(f"wrote {STORED.relative_to(ROOT)} ({len(table)} rows)")
    table = shared_table(rates=(None, 50, 60, 100, 250))
    show = table if "--all" in sys.argv else table[table.side.isin(["both"])
                                                   | table.side.isna()]
    print(show.to_string(index=False))
    print()
    print(calibration_table().to_string(index=False))
    print()
    table = synthetic_table()
    show = table if "--all" in sys.argv else table[table.side == "both"]
    print(show.to_string(index=False))
