"""Gait events from markers against force-plate events, on the shared real trials.

Prints the table (trial, rate, heel marker, side, event, found %, median and max |error|
in ms) for every trial and rate: the trials of ../shared/data/ that have force plates
(a 200 Hz walk over four plates; a Plug-in Gait stair descent at 120 Hz), each also
decimated (every 2nd / 4th frame) and with its heel markers left out of the roles.

Run from the repository root:  python tools/validate_gait_events.py

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


if __name__ == "__main__":
    pd.set_option("display.width", 200, "display.max_columns", 20, "display.max_colwidth", 60)
    if "--write" in sys.argv:
        table = stored_table()
        if table.empty:
            sys.exit(f"{SHARED} not found: the Codamotion walk is needed for --write")
        table.to_csv(STORED, index=False)
        print(f"wrote {STORED.relative_to(ROOT)} ({len(table)} rows)")
    for table in (event_table(), synthetic_table()):
        show = table if "--all" in sys.argv else table[table.side == "both"]
        print(show.drop(columns=["bias_ms"] if "--bias" not in sys.argv else []).to_string(
            index=False))
