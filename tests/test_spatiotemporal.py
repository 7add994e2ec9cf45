"""Vicon's gait cycle parameters from the events and a foot marker (issue 30):
spatiotemporal_parameters(events, trial, markers).

Oracles: a synthetic walk whose foot placements and events are known (lengths, supports
and percentages follow by hand), in metres, in a y-up lab, walking on a diagonal; the
shared Motion Analysis walk (Walk1.c3d: its 8 stored events) and the Plug-in Gait trial
shipped with the package, measured by hand from the marker coordinates at the event frames.
No shared C3D file holds Vicon's ANALYSIS values (the two Nexus files have an empty
ANALYSIS group), so none is compared value by value here.
"""

import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import gait_events, plug_in_gait, read_c3d_parameters, \
    spatiotemporal_parameters
from bmc_functions.examples import example_file

from helpers import SHARED_DATA, needs_shared

RATE = 100.0
SHIFT = 0.5          # the synthetic trial starts at 0 s; its first event is at 0.5 s
# along-progression knots (time, position in m) of each toe: flat in stance (heel strike
# to toe-off), moving in swing; left steps 0.8 m, right steps 0.6 m, strides 1.4 m
KNOTS = {"left": ([0.0, 0.62, 1.0, 1.62, 2.0], [0.0, 0.0, 1.4, 1.4, 2.8]),
         "right": ([-0.45, 0.1, 0.55, 1.1, 1.55, 2.1], [-0.8, -0.8, 0.6, 0.6, 2.0, 2.0])}
EVENTS = {"left": {"heel_strike": np.array([0.0, 1.0, 2.0]) + SHIFT,
                   "toe_off": np.array([0.62, 1.62]) + SHIFT},
          "right": {"heel_strike": np.array([0.55, 1.55]) + SHIFT,
                    "toe_off": np.array([0.1, 1.1, 2.1]) + SHIFT}}
ROLES = {"RASIS": "RASI", "LASIS": "LASI", "RTOE": "RTOE", "LTOE": "LTOE",
         "RHEEL": "RHEE", "LHEEL": "LHEE"}


def synthetic_walk():
    """A y-up lab in metres; progression 30 degrees from x in the floor (x-z) plane."""
    time = np.arange(0, 2.7, 1 / RATE)
    forward = np.array([np.cos(np.radians(30)), 0.0, np.sin(np.radians(30))])
    up = np.array([0.0, 1.0, 0.0])
    lateral = np.cross(forward, up)                       # to the right
    columns, data = [], []
    for side, sign in (("left", -1.0), ("right", 1.0)):
        knots_t, knots_x = KNOTS[side]
        along = np.interp(time - SHIFT, knots_t, knots_x)
        height = 0.03 + 0.05 * (np.gradient(along) > 0)     # lifted in swing
        toe = along[:, None] * forward + sign * 0.1 * lateral + height[:, None] * up
        heel = toe - 0.2 * forward
        prefix = side[0].upper()
        columns += [(prefix + "TOE", c) for c in "xyz"] + [(prefix + "HEE", c) for c in "xyz"]
        data += [toe, heel]
    pelvis = (1.4 * (time - SHIFT))[:, None] * forward + 0.9 * up
    for label, sign in (("RASI", 1.0), ("LASI", -1.0)):
        columns += [(label, c) for c in "xyz"]
        data.append(pelvis + sign * 0.12 * lateral)
    df = pd.DataFrame(np.hstack(data), columns=pd.MultiIndex.from_tuples(columns),
                      index=pd.Index(time, name="time"))
    df.attrs = {"rate": RATE, "units": "m"}
    return df


def test_a_synthetic_walk_gives_the_known_parameters():
    st = spatiotemporal_parameters(EVENTS, synthetic_walk(), ROLES)
    assert st.loc["left", "stride_length"] == pytest.approx(1.4, abs=1e-9)
    assert st.loc["right", "stride_length"] == pytest.approx(1.4, abs=1e-9)
    # a 3D distance would give sqrt(0.8^2 + 0.2^2) = 0.825: the feet are 0.2 m apart
    assert st.loc["left", "step_length"] == pytest.approx(0.8, abs=1e-9)
    assert st.loc["right", "step_length"] == pytest.approx(0.6, abs=1e-9)
    assert st.loc["left", "speed"] == pytest.approx(1.4, abs=1e-9)        # 1.4 m in 1 s
    expected = {"left": dict(opposite_foot_off=10.0, opposite_foot_contact=55.0,
                             foot_off=62.0, single_support=0.45, double_support=0.17),
                "right": dict(opposite_foot_off=7.0, opposite_foot_contact=45.0,
                              foot_off=55.0, single_support=0.38, double_support=0.17)}
    for side, values in expected.items():
        for name, value in values.items():
            assert st.loc[side, name] == pytest.approx(value, abs=1e-9), (side, name)
    strides = st.attrs["strides"]
    assert list(strides["side"]) == ["left", "left", "right"]
    assert st.attrs["markers"] == {"right": "RTOE", "left": "LTOE"}


def test_the_heel_is_measured_when_the_toe_is_not_mapped():
    roles = {role: label for role, label in ROLES.items() if "TOE" not in role}
    st = spatiotemporal_parameters(EVENTS, synthetic_walk(), roles)
    assert st.attrs["markers"] == {"right": "RHEE", "left": "LHEE"}
    assert st.loc["left", "stride_length"] == pytest.approx(1.4, abs=1e-9)
    assert st.loc["right", "step_length"] == pytest.approx(0.6, abs=1e-9)


def test_without_the_trial_the_table_is_as_before():
    st = spatiotemporal_parameters(EVENTS)
    assert "stride_length" not in st.columns and "strides" not in st.attrs
    full = spatiotemporal_parameters(EVENTS, synthetic_walk(), ROLES, cycles="mean")
    pd.testing.assert_frame_equal(full[st.columns], st)


def test_with_the_trial_each_side_is_its_first_complete_cycle():
    """Vicon Nexus reports the first cycle of each side in which every event is found.
    The left side's first stride (0.5-1.5 s) here lacks the right toe-off that the
    events below drop, so its second stride (1.5-2.5 s) is the one reported."""
    events = {"left": EVENTS["left"],
              "right": {"heel_strike": EVENTS["right"]["heel_strike"],
                        "toe_off": EVENTS["right"]["toe_off"][1:]}}   # 0.6 s dropped
    st = spatiotemporal_parameters(events, synthetic_walk(), ROLES)
    assert st.attrs["cycle"] == {"left": (1.5, 2.5), "right": (1.05, 2.05)}
    # left, 1.5-2.5 s: foot off 2.12, opposite foot off 1.6, opposite contact 2.05
    by_hand = {"stride_time": 1.0, "cadence": 120.0, "stance_time": 0.62,
               "swing_time": 0.38, "step_time": 0.45, "stance": 62.0,
               "opposite_foot_off": 10.0, "opposite_foot_contact": 55.0,
               "single_support": 0.45, "double_support": 0.1 + 0.07,
               "stride_length": 1.4, "step_length": 0.8, "speed": 1.4}
    for name, value in by_hand.items():
        assert st.loc["left", name] == pytest.approx(value, abs=1e-9), name
    # right, 1.05-2.05 s: opposite foot off 1.12, opposite contact 1.5, foot off 1.6
    assert st.loc["right", "step_time"] == pytest.approx(0.55, abs=1e-9)
    assert st.loc["right", "stance"] == pytest.approx(55.0, abs=1e-9)
    assert st.loc["left", "stride_from"] == "first cycle"
    assert st.loc["left", "strides"] == 2                     # still every stride counted
    mean = spatiotemporal_parameters(events, synthetic_walk(), ROLES, cycles="mean")
    assert mean.loc["left", "stance_time"] == pytest.approx(0.62, abs=1e-9)
    assert mean.loc["left", "single_support"] == pytest.approx(0.45, abs=1e-9)  # one has it
    first = spatiotemporal_parameters(events, cycles="first")    # events alone
    assert first.loc["left", "stance_time"] == pytest.approx(0.62, abs=1e-9)
    assert first.attrs["cycle"]["left"] == (1.5, 2.5)


def test_cycles_must_be_first_or_mean():
    with pytest.raises(ValueError, match="cycles must be 'first'.*got 'last'"):
        spatiotemporal_parameters(EVENTS, cycles="last")


@pytest.mark.parametrize("arguments, message", [
    (dict(trial=None), "trial and markers go together"),
    (dict(markers=None), "trial and markers go together"),
    (dict(markers={"RTOE": "RTOE", "LTOE": "LTOE"}), r"need the pelvis markers \('RASIS'"),
])
def test_missing_inputs_are_named(arguments, message):
    call = dict(events=EVENTS, trial=synthetic_walk(), markers=ROLES)
    call.update(arguments)
    with pytest.raises(ValueError, match=message):
        spatiotemporal_parameters(**call)


# --- real trials, by hand ----------------------------------------------------------------

def walk1_trial():
    """Walk1.c3d's markers (ezc3d; its duplicated labels' second copies dropped, which
    read_c3d refuses) and its 8 stored events (Motion Analysis writes the event kind in
    EVENT:CONTEXTS: LHS, RHS, LTO, RTO)."""
    ezc3d = pytest.importorskip("ezc3d")
    path = SHARED_DATA / "walks_with_plates" / "Walk1.c3d"
    c3d = ezc3d.c3d(str(path))
    labels = c3d["parameters"]["POINT"]["LABELS"]["value"]
    points = c3d["data"]["points"]
    keep = [k for k, label in enumerate(labels) if labels.index(label) == k]
    rate = c3d["parameters"]["POINT"]["RATE"]["value"][0]
    columns = pd.MultiIndex.from_product([[labels[k] for k in keep], ["x", "y", "z"]])
    df = pd.DataFrame(points[:3, keep].transpose(2, 1, 0).reshape(points.shape[2], -1),
                      columns=columns, index=pd.Index(np.arange(points.shape[2]) / rate))
    df.attrs = {"rate": rate, "units": "mm"}
    event = read_c3d_parameters(path)["EVENT"]
    times = {kind: np.sort([t for context, t in zip(event["CONTEXTS"], event["TIMES"][:, 1])
                            if context == kind]) for kind in ("LHS", "RHS", "LTO", "RTO")}
    events = {side: {"heel_strike": times[side[0].upper() + "HS"],
                     "toe_off": times[side[0].upper() + "TO"]} for side in ("left", "right")}
    return df, events, rate, points, labels


@needs_shared("walks_with_plates/Walk1.c3d")
def test_walk1_by_hand():
    df, events, rate, points, labels = walk1_trial()
    roles = {"RASIS": "RASI", "LASIS": "LASI", "SACRUM": "VSAC", "RHEEL": "RHEE",
             "RTOE": "R.TO", "LHEEL": "LHEE", "LTOE": "L.TO"}
    st = spatiotemporal_parameters(events, df, roles)

    def x_of(label, time):                     # the lab's X (the walk goes along +X), m
        return points[0, labels.index(label), int(round(time * rate))] / 1000.0

    left_start, left_end = events["left"]["heel_strike"]          # 0.567, 1.75 s
    right_start, right_end = events["right"]["heel_strike"]       # 1.15, 2.317 s
    by_hand = {
        ("left", "stride_length"): x_of("L.TO", left_end) - x_of("L.TO", left_start),
        ("right", "stride_length"): x_of("R.TO", right_end) - x_of("R.TO", right_start),
        ("left", "step_length"): x_of("L.TO", left_end) - x_of("R.TO", right_start),
        ("right", "step_length"): x_of("R.TO", right_end) - x_of("L.TO", left_end)}
    for (side, name), value in by_hand.items():
        assert st.loc[side, name] == pytest.approx(value, abs=0.01), (side, name)  # 1 cm
    assert st.loc["left", "speed"] == pytest.approx(
        by_hand["left", "stride_length"] / (left_end - left_start), abs=0.01)
    stride = left_end - left_start
    assert st.loc["left", "opposite_foot_off"] == pytest.approx(
        100 * (events["right"]["toe_off"][0] - left_start) / stride)
    assert st.loc["left", "opposite_foot_contact"] == pytest.approx(
        100 * (right_start - left_start) / stride)
    assert st.loc["left", "foot_off"] == pytest.approx(
        100 * (events["left"]["toe_off"][0] - left_start) / stride)
    assert st.loc["left", "single_support"] == pytest.approx(
        right_start - events["right"]["toe_off"][0])
    assert st.loc["right", "double_support"] == pytest.approx(
        (events["left"]["toe_off"][0] - right_start)
        + (events["right"]["toe_off"][1] - left_end))
    print(st[["stride_length", "step_length", "speed", "single_support",
              "double_support"]].round(3).to_string())


def test_the_plug_in_gait_walk_by_hand():
    """The stair descent shipped with the package, events from its markers: lengths
    along the progression gait_events finds (the lab's -X), by hand from RTOE and LTOE."""
    path = example_file("plug_in_gait/Movement_trial.c3d")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = plug_in_gait(example_file("plug_in_gait/Static_trial.c3d"),
                             example_file("plug_in_gait/Test.vsk"))
        events = gait_events(path, model.event_markers())
    st = spatiotemporal_parameters(events, path, model.event_markers())
    assert np.allclose(events.progression, [-1, 0, 0], atol=0.02)
    ezc3d = pytest.importorskip("ezc3d")
    c3d = ezc3d.c3d(str(path))
    labels = [label.strip() for label in c3d["parameters"]["POINT"]["LABELS"]["value"]]
    points = c3d["data"]["points"]
    rate = c3d["parameters"]["POINT"]["RATE"]["value"][0]

    def back_x(label, time):                   # along -X, m (events fall on frames)
        return -points[0, labels.index(label), int(round(time * rate))] / 1000.0

    def inside(times, start, end):
        return [t for t in times if start < t < end]

    def first_complete(side, other):             # Vicon Nexus's cycle, by hand
        strikes = events[side]["heel_strike"]
        for start, end in zip(strikes[:-1], strikes[1:]):
            if (inside(events[side]["toe_off"], start, end)
                    and inside(events[other]["toe_off"], start, end)
                    and inside(events[other]["heel_strike"], start, end)):
                return start, end, inside(events[other]["heel_strike"], start, end)[0]
        raise AssertionError(side)

    start, end, _ = first_complete("right", "left")
    assert st.attrs["cycle"]["right"] == pytest.approx((start, end))
    assert st.loc["right", "stride_length"] == pytest.approx(
        back_x("RTOE", end) - back_x("RTOE", start), abs=0.01)
    strides = [back_x("RTOE", b) - back_x("RTOE", a) for a, b in zip(
        events["right"]["heel_strike"][:-1], events["right"]["heel_strike"][1:])]
    mean = spatiotemporal_parameters(events, path, model.event_markers(), cycles="mean")
    assert mean.loc["right", "stride_length"] == pytest.approx(np.mean(strides), abs=0.01)
    start, end, contact = first_complete("left", "right")
    assert st.loc["left", "step_length"] == pytest.approx(
        back_x("LTOE", end) - back_x("RTOE", contact), abs=0.01)
    assert st.loc["left", "step_time"] == pytest.approx(end - contact, abs=1e-9)
    assert st.attrs["markers"] == {"right": "RTOE", "left": "LTOE"}


@needs_shared("plug_in_gait/Movement_trial.c3d", "walks_with_plates/Walk1.c3d")
def test_no_shared_file_holds_vicons_analysis_values():
    """Should a shared file gain Vicon's ANALYSIS values, compare them here."""
    for path in sorted(SHARED_DATA.glob("*/*.c3d")):
        analysis = read_c3d_parameters(path).get("ANALYSIS", {})
        assert analysis.get("USED", 0) == 0, path


def test_running_strides_have_lengths_but_no_supports():
    """In running the other foot leaves the ground after it lands (no double support):
    the supports are NaN, the lengths and percentages are still measured."""
    running = {"right": {"heel_strike": np.array([0.6, 1.3]), "toe_off": np.array([0.85])},
               "left": {"heel_strike": np.array([0.95]), "toe_off": np.array([0.5, 1.2])}}
    st = spatiotemporal_parameters(running, synthetic_walk(), ROLES)
    assert np.isnan(st.loc["right", ["single_support", "double_support"]].astype(float)).all()
    assert np.isfinite(st.loc["right", ["stride_length", "step_length", "speed"]]
                       .astype(float)).all()
    assert st.loc["right", "opposite_foot_contact"] == pytest.approx(50.0)


@needs_shared("force_plates/codamotion_gaitwands_20150204.c3d")
def test_a_real_walk_is_consistent_with_itself():
    """Codamotion's walk (4 strides a side, events from its markers): every stride's
    supports follow from its percentages, the two steps add up to a stride, and the
    numbers are an adult's (opposite foot contact near 50 %, foot off near 60 %)."""
    path = SHARED_DATA / "force_plates" / "codamotion_gaitwands_20150204.c3d"
    roles = {"RASIS": "R.ASIS", "LASIS": "L.ASIS", "RPSIS": "R.PSIS", "LPSIS": "L.PSIS",
             "RHEEL": "R.Heel", "RTOE": "R.Toe", "LHEEL": "L.Heel", "LTOE": "L.Toe"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        events = gait_events(path, roles)
    st = spatiotemporal_parameters(events, path, roles, cycles="mean")
    strides = st.attrs["strides"]
    np.testing.assert_allclose(
        strides["single_support"],
        (strides["opposite_foot_contact"] - strides["opposite_foot_off"]) / 100
        * strides["stride_time"], atol=1e-12)
    np.testing.assert_allclose(
        strides["double_support"],
        (strides["opposite_foot_off"] + strides["foot_off"]
         - strides["opposite_foot_contact"]) / 100 * strides["stride_time"], atol=1e-12)
    steps = st["step_length"].sum()
    assert steps == pytest.approx(st["stride_length"].mean(), abs=0.02)
    assert (abs(st["opposite_foot_contact"] - 50) < 3).all()
    assert ((st["foot_off"] > 55) & (st["foot_off"] < 67)).all()
    assert ((st["speed"] > 1.0) & (st["speed"] < 1.6)).all()
