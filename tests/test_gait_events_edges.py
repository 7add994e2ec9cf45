"""Gait events at the edges of a recording and on stairs.

Oracles: the exact events of the synthetic trials of data/gait (data/README.md), cut so
that a true heel strike falls in the first frames, and the same trials made into a stair
descent (each foot lowered by one riser per step during its swing, the pelvis with them),
whose contacts stand on floors 170 mm apart.
"""

import sys
import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import gait_events, read_trc

from helpers import ROOT, needs_shared

sys.path.insert(0, str(ROOT / "tools"))
import validate_gait_events as validation  # noqa: E402

# The synthetic walk hides one left heel strike in a gap of its heel marker on purpose
# (data/README.md); gait_events says so ("events seem missing").
pytestmark = pytest.mark.filterwarnings(
    "ignore:events seem missing. left heel strikes:RuntimeWarning")

ROLES = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
         "RHEEL": "RHEE", "RTOE": "RTOE", "RMT5": "RMT5",
         "LHEEL": "LHEE", "LTOE": "LTOE", "LMT5": "LMT5"}

#: A stair riser (mm): 150-200 mm in buildings.
RISER = 170.0


def resampled(name, rate):
    """The synthetic trial `name` sampled at `rate` (Hz) by linear interpolation."""
    trial = read_trc(ROOT / "data" / "gait" / f"{name}.trc")
    old = trial.index.to_numpy(float)
    new = np.arange(old[0], old[-1] + 1e-9, 1.0 / rate)
    values = np.column_stack([np.interp(new, old, column)
                              for column in trial.to_numpy(float).T])
    out = pd.DataFrame(values, index=pd.Index(new, name="time"), columns=trial.columns)
    out.attrs = dict(trial.attrs, rate=float(rate))
    return out


def truth(name, side, event="heel_strike", in_gap=False):
    """The exact times (s) of `event` of `side` (those hidden in a gap only if `in_gap`)."""
    table = pd.read_csv(ROOT / "data" / "gait" / f"{name}_events.csv")
    keep = (table.side == side) & (table.event == event) & (in_gap | ~table.in_gap)
    return table.loc[keep, "time"].to_numpy()


def starting(trial, time):
    """The frames of `trial` from `time` (s) on: a recording that starts there."""
    return trial[trial.index >= time - 1e-9]


def quiet_events(trial, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return gait_events(trial, ROLES, **options)


def first_strikes(events, side, before):
    found = events[side]["heel_strike"]
    return found[found < before]


# --- a heel strike in the first frames ---------------------------------------------------

@pytest.mark.parametrize("name", ["walk", "run"])
@pytest.mark.parametrize("rate", [50.0, 100.0])
@pytest.mark.parametrize("side", ["right", "left"])
def test_a_heel_strike_in_the_first_two_frames_is_found(name, rate, side):
    # the recording starts two frames before a true heel strike: Zeni's maximum of the
    # heel ahead of the pelvis (35-95 ms before contact) lies before the first frame
    strike = truth(name, side)[1]
    events = quiet_events(starting(resampled(name, rate), strike - 2 / rate))
    found = first_strikes(events, side, strike + 0.1)
    assert found.size == 1, found
    assert abs(found[0] - strike) <= 2 / rate + 1e-9, (found, strike)


@pytest.mark.parametrize("name", ["walk", "run"])
@pytest.mark.parametrize("rate", [50.0, 100.0, 250.0])
@pytest.mark.parametrize("after", [0, 1, 3])
def test_a_recording_that_starts_after_the_heel_strike_gets_none_there(name, rate, after):
    # the foot is on the floor in the first frame: its heel strike came before the
    # recording, and no event is invented for it
    for side in ("right", "left"):
        strike = truth(name, side)[1]
        events = quiet_events(starting(resampled(name, rate), strike + after / rate))
        assert first_strikes(events, side, strike + 0.1).size == 0, (side, events[side])


# --- stairs: each contact has its own floor ----------------------------------------------

def stair_descent(trial, name):
    """`trial` made into a stair descent: each foot lowered by RISER during each of its
    swings (toe-off to 0.1 s before the next heel strike, linearly), so that every
    contact stands one riser below the foot's previous one; the pelvis follows the mean
    of the feet."""
    time = trial.index.to_numpy(float)
    drops = {}
    for side in ("right", "left"):
        offs = np.sort(truth(name, side, "toe_off", in_gap=True))
        strikes = np.sort(truth(name, side, "heel_strike", in_gap=True))
        drop = np.zeros_like(time)
        for off in offs:                                 # loop over swings, not frames
            land = strikes[strikes > off]
            end = (land[0] if land.size else off + 0.4) - 0.1
            drop += RISER * np.clip((time - off) / (end - off), 0.0, 1.0)
        drops[side] = drop
    up = quiet_events(trial).vertical                 # the lab's vertical: z or y up
    axis = "xyz"[int(np.argmax(np.abs(up)))]
    out = trial.copy()
    for label in dict.fromkeys(out.columns.get_level_values(0)):
        side = {"R": "right", "L": "left"}.get(label[0])
        drop = drops[side] if label[1:] in ("HEE", "TOE", "MT5") and side else \
            0.5 * (drops["right"] + drops["left"])
        out[(label, axis)] = out[(label, axis)] - np.sign(up.sum()) * drop
    return out


@pytest.mark.parametrize("name", ["walk", "run"])
@pytest.mark.parametrize("rate", [50.0, 100.0])
def test_a_heel_strike_in_the_first_frames_on_the_top_step_of_a_stair(name, rate):
    # the first contact stands one or more risers above the trial's lowest floor: judged
    # against its own floor (the lowest the foot reaches after it lands) it is a
    # landing; a trial-wide floor would call the foot in the air. (In the synthetic run
    # at 100 Hz the heel's forward maximum lies before the first frame, so the cut
    # window decides; the synthetic walk's maximum coincides with its contact.)
    strike = truth(name, "right")[1]
    trial = stair_descent(starting(resampled(name, rate), strike - 2 / rate), name)
    heel = trial["RHEE"].to_numpy() @ quiet_events(trial).vertical
    assert heel[0] - np.percentile(heel, 5) > RISER            # above the lowest floor
    with pytest.warns(RuntimeWarning, match="the feet land at heights"):
        events = gait_events(trial, ROLES)
    found = first_strikes(events, "right", strike + 0.1)
    assert found.size == 1 and abs(found[0] - strike) <= 2 / rate + 1e-9, found
    # and every later heel strike of the descent, each on its own step
    later = truth(name, "right")[2:]
    later = later[later < trial.index[-1] - 0.1]
    assert np.abs(events["right"]["heel_strike"][1:len(later) + 1] - later).max() \
        <= 2 / rate + 1e-9


# --- the real stair descent, cut so that a heel strike falls in its first frames ---------

@needs_shared("plug_in_gait/Movement_trial.c3d")
@pytest.mark.parametrize("rate", [50.0, 100.0, 120.0])
def test_a_stair_descent_cut_two_frames_before_each_plate_heel_strike(rate):
    # Movement_trial.c3d descends steps 195 mm apart: each contact stands on a floor of
    # its own, up to 4 risers above the trial's lowest. Cut two frames before each plate
    # heel strike, the trial starts with Zeni's maximum (about 90 ms before contact here)
    # already past: the heel strike is found (within 20 ms) against its own step's floor;
    # cut one frame after it, the foot is on its step in the first frame and none is given
    trial, reference = validation.plate_reference("PiG stair descent")
    if rate != trial.attrs["rate"]:
        trial = validation.resample(trial, rate)
    roles = validation.SHARED_TRIALS["PiG stair descent"][1]
    for side, found in reference.items():
        for strike in found["heel_strike"]:            # loop over the plate's events
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                early = gait_events(starting(trial, strike - 2 / rate), roles)
                late = gait_events(starting(trial, strike + 1 / rate), roles)
            first = first_strikes(early, side, strike + 0.1)
            assert first.size == 1 and abs(first[0] - strike) <= 0.02, (side, strike, first)
            assert first_strikes(late, side, strike + 0.1).size == 0, (side, strike)
