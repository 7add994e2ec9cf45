"""Gait events from markers against force-plate events, on the shared real trials.

Prints the table (trial, rate, heel marker, side, event, found %, median and max |error|
in ms) for every trial and rate: the trials of ../shared/data/ that have force plates
(a 200 Hz walk over four plates; a Plug-in Gait stair descent at 120 Hz), each also
decimated (every 2nd / 4th frame) and with its heel markers left out of the roles.

Run from the repository root:  python tools/validate_gait_events.py
"""

import sys
import warnings
from pathlib import Path

import pandas as pd

from bmc_functions import compare_events, force_plate_events, gait_events, read_c3d

SHARED = Path(__file__).resolve().parents[1].parent / "shared" / "data"

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
            part = trial.iloc[::step]
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


if __name__ == "__main__":
    pd.set_option("display.width", 200, "display.max_columns", 20, "display.max_colwidth", 60)
    table = event_table()
    show = table if "--all" in sys.argv else table[table.side == "both"]
    print(show.drop(columns=["bias_ms"] if "--bias" not in sys.argv else []).to_string(
        index=False))
