"""The lab's normative data and the Gait Profile Score (issue 30; Baker et al. 2009).

Oracles: cycles built from the normative mean with a known constant offset (GVS = |c| in
that variable, 0 elsewhere, and the GPS that follows from the counting convention);
numpy's mean and SD over the pooled cycles; a hand computation, point by point in plain
Python, on the Plug-in Gait walk shipped with the package; Vicon Nexus's own angles of
that walk.
"""

import math
import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import (gait_events, gait_profile_score, normalize_by_side, normative_data,
                           plug_in_gait, read_c3d_model_outputs, read_normative_data,
                           write_normative_data)
from bmc_functions.examples import example_file
from bmc_functions.gait.gait_profile import (GPS_PERCENT, GPS_VARIABLES, PELVIS_VARIABLES,
                                             VICON_GPS_OUTPUTS)

PERCENT = np.linspace(0.0, 100.0, 101)
NINE = list(GPS_VARIABLES)
COLUMNS = pd.MultiIndex.from_tuples([(joint, side, angle) for side in ("right", "left")
                                     for joint, angle in GPS_VARIABLES.values()],
                                    names=["joint", "side", "angle"])


def cycles_table(values):
    """(cycles, 101 points, 18 columns) -> a normalize_by_side-like table."""
    values = np.asarray(values, float)
    index = pd.MultiIndex.from_product([range(values.shape[0]), PERCENT],
                                       names=["cycle", "percent"])
    return pd.DataFrame(values.reshape(-1, values.shape[2]), index=index, columns=COLUMNS)


def control_cycles(seed, n_cycles=4):
    """Smooth random curves (a few harmonics per column) for several control subjects."""
    rng = np.random.default_rng(seed)
    phase = 2 * np.pi * PERCENT / 100
    coefficients = rng.normal(0, 10, (n_cycles, 1, len(COLUMNS), 3))
    harmonics = np.stack([np.ones_like(phase), np.sin(phase), np.cos(2 * phase)], axis=-1)
    return cycles_table(np.einsum("pk,cnk->cpn", harmonics, coefficients[:, 0]))


@pytest.fixture(scope="module")
def normative():
    return normative_data([control_cycles(1), control_cycles(2, 3), control_cycles(3, 5)])


def subject_at_mean(normative, n_cycles=3):
    """Cycles equal to the normative mean in every column."""
    mean = np.stack([normative["mean"][(joint, angle)].to_numpy()
                     for joint, side, angle in COLUMNS], axis=1)
    return cycles_table(np.repeat(mean[None], n_cycles, axis=0))


# --- normative data --------------------------------------------------------------------

def test_normative_data_pools_the_cycles_of_every_table_and_both_sides():
    tables = [control_cycles(1), control_cycles(2, 3)]
    tables[1].loc[2, :] = np.nan                       # a padding cycle: not counted
    normative = normative_data(tables)
    for joint, angle in [("knee", "flexion"), ("pelvis", "obliquity")]:
        pooled = np.concatenate([t[(joint, side, angle)].unstack("percent").to_numpy()
                                 for t in tables for side in ("right", "left")])
        pooled = pooled[~np.isnan(pooled).all(axis=1)]
        assert len(pooled) == 2 * (4 + 2)
        np.testing.assert_allclose(normative["mean"][(joint, angle)], pooled.mean(axis=0))
        np.testing.assert_allclose(normative["sd"][(joint, angle)], pooled.std(axis=0, ddof=1))
        assert (normative["count"][(joint, angle)] == 12).all()
    assert normative.shape == (101, 3 * 9)
    np.testing.assert_array_equal(normative.index, PERCENT)


def test_normative_csv_round_trip_is_exact(normative, tmp_path):
    path = tmp_path / "normal.csv"
    write_normative_data(normative, path)
    back = read_normative_data(path)
    pd.testing.assert_frame_equal(back, normative)
    text = path.read_text().splitlines()
    assert text[0] == "joint,angle,percent,mean,sd,count" and len(text) == 1 + 9 * 101


def test_tables_of_different_points_are_refused():
    at_51 = control_cycles(2).loc[(slice(None), GPS_PERCENT), :]
    with pytest.raises(ValueError, match="every table must have the same points of the "
                                         "cycle; got 101 and 51 points"):
        normative_data([control_cycles(1), at_51])


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.drop(columns="sd"), "missing sd"),
    (lambda t: pd.concat([t, t.iloc[:1]]), "given twice"),
    (lambda t: t.assign(count=["x"] + list(t["count"].iloc[1:])), "'count' holds a value"),
    (lambda t: t.iloc[1:], "same points of the cycle"),
])
def test_a_damaged_normative_csv_is_refused(normative, tmp_path, edit, message):
    path = tmp_path / "normal.csv"
    write_normative_data(normative, path)
    edit(pd.read_csv(path)).to_csv(path, index=False)
    with pytest.raises(ValueError, match=message):
        read_normative_data(path)


# --- GVS, GPS, MAP: constant offsets ---------------------------------------------------

@pytest.mark.parametrize("variable", NINE)
def test_a_constant_offset_gives_its_gvs_and_nothing_elsewhere(normative, variable):
    c = -3.7
    joint, angle = GPS_VARIABLES[variable]
    subject = subject_at_mean(normative)
    subject.loc[:, (joint, slice(None), angle)] += c
    profile = gait_profile_score(subject, normative)
    expected = pd.DataFrame(0.0, index=NINE, columns=["left", "right"])
    expected.loc[variable] = abs(c)
    np.testing.assert_allclose(profile.map.to_numpy(), expected.to_numpy(), atol=1e-12)
    pelvis = variable in PELVIS_VARIABLES
    # the pelvis counted once, in the left GPS: 9 GVS left, 6 right, 15 overall
    assert profile.gps["left"] == pytest.approx(abs(c) / 3)
    assert profile.gps["right"] == pytest.approx(0.0 if pelvis else abs(c) / math.sqrt(6),
                                                 abs=1e-12)
    assert profile.gps["overall"] == pytest.approx(
        abs(c) * math.sqrt((1 if pelvis else 2) / 15))
    each = gait_profile_score(subject, normative, pelvis="each")
    assert each.gps["right"] == pytest.approx(abs(c) / 3)
    assert each.gps["overall"] == pytest.approx(abs(c) * math.sqrt(2 / 18))


def test_one_side_offset_and_the_map_is_the_gvs_table(normative):
    subject = subject_at_mean(normative, n_cycles=2)
    subject.loc[:, ("knee", "left", "flexion")] += 6.0
    subject.loc[(1, slice(None)), ("hip", "right", "rotation")] += 4.0   # one cycle of two
    profile = gait_profile_score(subject, normative)
    assert profile.map.loc["knee_flexion", "left"] == pytest.approx(6.0)
    assert profile.map.loc["knee_flexion", "right"] == pytest.approx(0.0, abs=1e-12)
    assert profile.map.loc["hip_rotation", "right"] == pytest.approx(2.0)   # mean of 0 and 4
    per_cycle = profile.per_cycle
    np.testing.assert_allclose(per_cycle.loc[("right", 0, 1), "hip_rotation"], 4.0)
    np.testing.assert_allclose(per_cycle.drop(columns="gps").groupby(level="side").mean()
                               .T[["left", "right"]].to_numpy(), profile.map.to_numpy())
    counted = profile.map.attrs["counted"]
    assert len(counted) == 15 and ("pelvic_tilt", "right") not in counted
    gvs = np.array([profile.map.loc[name, side] for name, side in counted])
    assert profile.gps["overall"] == pytest.approx(np.sqrt(np.mean(gvs ** 2)))
    assert profile.gps["left"] == pytest.approx(6.0 / 3)
    assert profile.gps["right"] == pytest.approx(2.0 / math.sqrt(6))
    assert per_cycle.loc[("right", 0, 1), "gps"] == pytest.approx(4.0 / math.sqrt(6))
    assert profile.map.attrs["cycles"] == {"left": 2, "right": 2}


def test_51_points_whatever_the_cycles_resolution(normative):
    """Cycles at 101 points are compared at every other point (0, 2, ..., 100 %): the
    same cycles given at those 51 points alone score the same."""
    rng = np.random.default_rng(5)
    subject = subject_at_mean(normative) + rng.normal(0, 2, (3 * 101, 18))
    at_51 = subject.loc[(slice(None), GPS_PERCENT), :]
    assert len(at_51) == 3 * 51
    full = gait_profile_score(subject, normative)
    pd.testing.assert_frame_equal(full.map, gait_profile_score(at_51, normative).map)


# --- a real walk, by hand --------------------------------------------------------------

@pytest.fixture(scope="module")
def walk_cycles():
    """The package's Plug-in Gait angles of the shipped Nexus walk, between the heel
    strikes found from its markers (right 2 cycles, left 1), and Vicon's own angles."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = plug_in_gait(example_file("plug_in_gait/Static_trial.c3d"),
                             example_file("plug_in_gait/Test.vsk"))
        trial = example_file("plug_in_gait/Movement_trial.c3d")
        angles = model.angles(trial)
        events = gait_events(trial, model.event_markers())
    vicon = read_c3d_model_outputs(trial)
    columns = {(GPS_VARIABLES[name][0], side, GPS_VARIABLES[name][1]):
               vicon[(side[0].upper() + label, component)]
               for side in ("right", "left") for name, (label, component)
               in VICON_GPS_OUTPUTS.items()}
    vicon_angles = pd.DataFrame(columns, index=angles.index)
    vicon_angles.columns.names = ["joint", "side", "angle"]
    return normalize_by_side(angles, events), normalize_by_side(vicon_angles, events)


def test_gvs_by_hand_on_the_plug_in_gait_walk(walk_cycles):
    ours, _ = walk_cycles
    normative = normative_data(ours)          # three cycles, both sides pooled
    left = ours.loc[(0, slice(None)), ("knee", "left", "flexion")].to_numpy()
    right = [ours.loc[(k, slice(None)), ("knee", "right", "flexion")].to_numpy()
             for k in (0, 1)]
    total = 0.0
    for point in range(0, 101, 2):            # every 2 % of the cycle, in plain Python
        mean = (left[point] + right[0][point] + right[1][point]) / 3
        total += (left[point] - mean) ** 2
    by_hand = math.sqrt(total / 51)
    profile = gait_profile_score(ours, normative)
    assert profile.map.loc["knee_flexion", "left"] == pytest.approx(by_hand, rel=1e-12)
    assert 1.0 < by_hand < 20.0               # a stair descent's cycles differ
    print(f"left knee flexion GVS {by_hand:.4f} deg; GPS {profile.gps.round(3).to_dict()}")


def test_the_package_scores_vicons_angles_as_its_own(walk_cycles):
    """Against a normative table of Vicon's own angles of the same cycles, the package's
    Plug-in Gait angles score what Vicon's angles score (they agree to 0.001 deg)."""
    ours, vicon = walk_cycles
    normative = normative_data(vicon)
    mine, theirs = gait_profile_score(ours, normative), gait_profile_score(vicon, normative)
    np.testing.assert_allclose(mine.map.to_numpy(), theirs.map.to_numpy(), atol=2e-3)
    np.testing.assert_allclose(mine.gps.to_numpy(), theirs.gps.to_numpy(), atol=2e-3)


# --- missing data and bad arguments ----------------------------------------------------

def test_a_missing_variable_and_a_gap_are_named_once(normative):
    subject = subject_at_mean(normative).drop(columns="foot", level=0)
    subject.loc[(1, 50.0), ("knee", "left", "flexion")] = np.nan
    subject.loc[:, ("knee", "left", "flexion")] += 2.0
    with pytest.warns(UserWarning) as caught:
        profile = gait_profile_score(subject, normative)
    assert len(caught) == 1
    message = str(caught[0].message)
    assert "no foot_progression" in message and "counts 8 of the 9" in message
    assert "knee_flexion 1 of 6" in message
    assert np.isnan(profile.per_cycle.loc[("left", 0, 1), "knee_flexion"])
    assert profile.map.loc["knee_flexion", "left"] == pytest.approx(2.0)  # the other two
    assert np.isnan(profile.map.loc["foot_progression"]).all()
    assert profile.gps["left"] == pytest.approx(2.0 / math.sqrt(8))


@pytest.mark.parametrize("arguments, error, message", [
    (dict(pelvis="both"), ValueError, "pelvis must be 'left' or 'right' or 'each'"),
    (dict(pelvis=1), TypeError, "pelvis must be"),
    (dict(variables={"knee": "flexion"}), ValueError, "variables must be a dict"),
    (dict(normative=pd.DataFrame({"a": [1.0]})), ValueError, "normative must be the table"),
    (dict(cycles=pd.DataFrame({"a": [1.0]})), ValueError, r"cycles must be indexed by "
                                                          r"\(cycle, percent\)"),
    (dict(cycles="walk.c3d"), TypeError, "cycles must be a DataFrame"),
    (dict(cycles=cycles_table(np.full((2, 101, 18), np.nan))), ValueError,
     "cycles holds no gait cycle"),
    (dict(normative=normative_data(cycles_table(np.zeros((1, 101, 18)))).iloc[:50]),
     ValueError, "normative must cover the whole cycle, 0 to 100 %; got points from 0 to 49"),
])
def test_bad_arguments_are_named(normative, arguments, error, message):
    call = dict(cycles=subject_at_mean(normative), normative=normative)
    call.update(arguments)
    with pytest.raises(error, match=message):
        gait_profile_score(**call)
