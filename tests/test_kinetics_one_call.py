"""lower_limb_kinetics (the one-call kinetics beside lower_limb_angles), write_c3d's
(joint, side, quantity) kinetics and plot_gait_cycles(kinetics=): the numbers are those
of the model's own kinetics, called directly."""

import warnings

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

from bmc_functions import (calibrate_lower_limb, lower_limb_kinetics, normative_data,  # noqa: E402
                           read_c3d_model_outputs, read_marker_mapping, write_c3d)
from bmc_functions.plotting import CLINICAL_RANGES, NORMAL_COLOR, plot_gait_cycles  # noqa: E402

from helpers import ROOT  # noqa: E402

REAL = ROOT / "data" / "real"
RUN_ROLES = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI"}
for _p in "RL":
    RUN_ROLES.update({_p + "THIGH": [_p + "TH1", _p + "TH2", _p + "TH3"],
                      _p + "SHANK": [_p + "TB1", _p + "TB2", _p + "TB3"],
                      _p + "KNEE_LAT": _p + "LFC", _p + "KNEE_MED": _p + "MFC",
                      _p + "ANKLE_LAT": _p + "LMAL", _p + "ANKLE_MED": _p + "MMAL",
                      _p + "HEEL": _p + "CAL", _p + "TOE": _p + "TOE", _p + "MT5": _p + "MT5"})


def quiet(call, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return call(*args, **kwargs)


@pytest.fixture(scope="module")
def run_kinetics():
    """The repository's running trial with its ground loads (70 kg), through the model."""
    model = quiet(calibrate_lower_limb, REAL / "static_run.trc", RUN_ROLES)
    return quiet(model.kinetics, REAL / "motion_capture_run.trc", REAL / "grf_run.mot",
                 body_mass=70.0)


def test_one_trial_is_the_model_s_kinetics(run_kinetics):
    one = quiet(lower_limb_kinetics, REAL / "static_run.trc", REAL / "motion_capture_run.trc",
                RUN_ROLES, body_mass=70.0, forces=REAL / "grf_run.mot")
    pd.testing.assert_frame_equal(one, run_kinetics)
    assert one.attrs["body_mass"] == 70.0
    assert np.isfinite(one["knee", "left", "moment_x"]).sum() > 50   # the right: labels swapped


def test_a_list_of_trials_stacks_them_as_lower_limb_angles(run_kinetics):
    trial, loads = REAL / "motion_capture_run.trc", REAL / "grf_run.mot"
    many = quiet(lower_limb_kinetics, REAL / "static_run.trc", [trial, str(trial)],
                 RUN_ROLES, body_mass=70.0, forces=[loads, loads], progress=False)
    assert list(many.index.names) == ["trial", "time"]
    for name in many.index.get_level_values("trial").unique():
        np.testing.assert_array_equal(many.loc[name].to_numpy(), run_kinetics.to_numpy())


@pytest.mark.parametrize("dynamic, forces, match", [
    ("trial", None, "forces: None reads the force plates of each C3D trial; .*motion_"
                    "capture_run.trc is not a C3D path"),
    ("list", REAL / "grf_run.mot", "forces: for a list of 2 trials give a list of as many"),
    ("list", [REAL / "grf_run.mot"], "forces: .* got a list of 1"),
])
def test_forces_that_do_not_fit_the_trials_are_refused(dynamic, forces, match):
    trial = REAL / "motion_capture_run.trc"
    with pytest.raises(ValueError, match=match):
        lower_limb_kinetics(REAL / "static_run.trc",
                            trial if dynamic == "trial" else [trial, trial],
                            RUN_ROLES, body_mass=70.0, forces=forces, progress=False)


def test_an_empty_list_is_refused():
    with pytest.raises(ValueError, match="dynamic is an empty list"):
        lower_limb_kinetics(REAL / "static_run.trc", [], RUN_ROLES, body_mass=70.0)


# --- write_c3d with the (joint, side, quantity) table --------------------------------------

def test_write_c3d_names_and_units_of_a_kinetics_table(tmp_path):
    """Each quantity as Vicon's point and unit: moment_x of the left knee as LKneeMoment X
    times 1000 (N mm/kg), power as the Z of <S><Joint>Power, the forces unchanged; the
    components not given are 0, a NaN frame is a gap."""
    pytest.importorskip("ezc3d")
    from bmc_functions import read_trc

    trial = read_trc(ROOT / "bmc_functions" / "example_data" / "markers" / "walk.trc")
    n = len(trial)
    columns = pd.MultiIndex.from_tuples([("knee", "left", "moment_x"),
                                         ("knee", "left", "moment_y"),
                                         ("ankle", "right", "power"),
                                         ("hip", "right", "force_z")],
                                        names=["joint", "side", "quantity"])
    values = np.column_stack([np.linspace(-0.5, 1.0, n), np.full(n, 0.25),
                              np.linspace(-2, 3, n) + 1e-3, np.full(n, 9.5)])
    values[3, 0] = np.nan      # (a power of exactly 0 would read back as Vicon's gap)
    table = pd.DataFrame(values, index=trial.index, columns=columns)
    path = write_c3d(tmp_path / "kin", trial, kinetics=table)
    back = read_c3d_model_outputs(path)
    np.testing.assert_allclose(back["LKneeMoment"]["x"], values[:, 0] * 1000.0, rtol=1e-6,
                               equal_nan=True)
    np.testing.assert_allclose(back["LKneeMoment"]["y"].drop(back.index[3]), 250.0,
                               rtol=1e-6)
    assert np.isnan(back["LKneeMoment"].iloc[3]).all()        # the whole point is a gap
    np.testing.assert_allclose(back["RAnklePower"]["z"], values[:, 2], rtol=1e-6,
                               atol=1e-6)
    assert (back["RAnklePower"][["x", "y"]].to_numpy() == 0).all()
    np.testing.assert_allclose(back["RHipForce"]["z"], 9.5, rtol=1e-6)
    assert back.attrs["groups"] == {"LKneeMoment": "MOMENTS", "RAnklePower": "POWERS",
                                    "RHipForce": "FORCES"}


def test_write_c3d_refuses_an_unknown_kinetic_quantity(tmp_path):
    pytest.importorskip("ezc3d")
    from bmc_functions import read_trc

    trial = read_trc(ROOT / "bmc_functions" / "example_data" / "markers" / "walk.trc")
    table = pd.DataFrame(0.0, index=trial.index, columns=pd.MultiIndex.from_tuples(
        [("knee", "left", "torque")]))
    with pytest.raises(ValueError, match=r"kinetics: column \('knee', 'left', 'torque'\): "
                                         r"the side must be 'right' or 'left' and the "
                                         r"quantity one of moment_x"):
        write_c3d(tmp_path / "bad", trial, kinetics=table)


# --- plot_gait_cycles(kinetics=) -----------------------------------------------------------

def cycles_of(columns, rng, scale):
    index = pd.MultiIndex.from_product([range(2), np.linspace(0, 100, 101)],
                                       names=["cycle", "percent"])
    return pd.DataFrame(rng.normal(0, scale, (202, len(columns))), index=index,
                        columns=pd.MultiIndex.from_tuples(columns))


def test_plot_gait_cycles_draws_the_kinetics_rows_below_the_angles():
    """Rows: the angles' joints, then the kinetics' (hip, knee, ankle); the kinetics
    panels on their clinical ranges, the normal band where the normative has them."""
    rng = np.random.default_rng(29)
    angles = cycles_of([(j, s, a) for j in ("pelvis", "hip", "knee", "ankle")
                        for s in ("right", "left")
                        for a in ("flexion", "adduction", "rotation")], rng, 5.0)
    kinetics = cycles_of([(j, s, q) for j in ("hip", "knee", "ankle")
                          for s in ("right", "left")
                          for q in ("moment_x", "moment_y", "moment_z", "power")], rng, 0.05)
    normative = normative_data(pd.concat([angles, kinetics.filter(like="moment_x")], axis=1))
    fig, axes = plot_gait_cycles(angles, kinetics=kinetics, normative=normative)
    assert axes.shape == (7, 4)
    assert not axes[0, 3].get_visible() and axes[4, 3].get_visible()
    assert [axes[4 + k, 0].get_title() for k in range(3)] == [
        "hip moment_x", "knee moment_x", "ankle moment_x"]
    assert axes[6, 3].get_title() == "ankle power"
    assert axes[6, 3].get_ylim() == CLINICAL_RANGES["ankle", "power"]
    assert axes[5, 0].get_ylabel() == "Flex − / Ext + (N·m/kg)"
    grey = matplotlib.colors.to_rgba(NORMAL_COLOR)

    def banded(ax):
        return any(np.allclose(c.get_facecolor()[0], grey) for c in ax.collections)

    assert banded(axes[4, 0]) and not banded(axes[4, 1])   # moment_x only in the normative
    plt.close(fig)


def test_plot_gait_cycles_refuses_kinetics_without_a_cycle():
    rng = np.random.default_rng(30)
    angles = cycles_of([("knee", "right", "flexion")], rng, 5.0)
    empty = cycles_of([("knee", "right", "moment_x")], rng, 1.0) * np.nan
    with pytest.raises(ValueError, match="kinetics holds no complete gait cycle"):
        plot_gait_cycles(angles, kinetics=empty)
    plt.close("all")
