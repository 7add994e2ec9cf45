"""calibrate_lower_limb with the functional hip centre (SCoRE) and the functional knee axis
(SARA), on the synthetic functional trials of data/functional (known hip centre and knee
axis; see data/generate_functional_data.py)."""

import copy
import pickle

import numpy as np
import pandas as pd
import pytest

from bmc_functions import JointAxis, JointCentre, calibrate_lower_limb, lower_limb_angles

from helpers import FUNCTIONAL_MARKERS as MARKERS
from helpers import ROOT

FOLDER = ROOT / "data" / "functional"
STATIC = FOLDER / "static.trc"
HIP = FOLDER / "hip_star_arc.trc"
KNEE = FOLDER / "knee_flexion.trc"


def true_static_hip():
    return pd.read_csv(FOLDER / "static_truth.csv")[["hip_x", "hip_y", "hip_z"]].to_numpy()[0]


@pytest.fixture(scope="module")
def harrington():
    return calibrate_lower_limb(STATIC, MARKERS)


@pytest.fixture(scope="module")
def functional_hip():
    return calibrate_lower_limb(STATIC, MARKERS, hip_centre="functional",
                                functional_trial=HIP)


@pytest.fixture(scope="module")
def functional_knee():
    return calibrate_lower_limb(STATIC, MARKERS, knee_axis="functional",
                                knee_axis_trial=KNEE)


def test_functional_hip_centre_is_closer_than_harrington(harrington, functional_hip):
    truth = true_static_hip()
    regression = np.linalg.norm(harrington.landmarks.loc["RHJC"].to_numpy() - truth)
    functional = np.linalg.norm(functional_hip.landmarks.loc["RHJC"].to_numpy() - truth)
    assert regression == pytest.approx(15.7, abs=1.0)     # the generator's offset
    assert functional < 6.0
    fit = functional_hip.options["functional_hip"]["right"]
    assert isinstance(fit, JointCentre) and fit.frames_used == 1501
    assert fit.range_of_motion[1] > 30


def test_functional_hip_centre_is_carried_into_a_dynamic_trial(functional_hip, harrington):
    # the thigh cluster carries the calibrated centre into every frame of the star arc
    truth = pd.read_csv(FOLDER / "hip_star_arc_truth.csv")[["hip_x", "hip_y", "hip_z"]]
    errors = {}
    for name, model in (("functional", functional_hip), ("harrington", harrington)):
        kin = model.track(HIP)
        centre = kin.landmarks[("thigh", "right")]["RHJC"]
        errors[name] = np.sqrt(np.mean(np.sum((centre - truth.to_numpy()) ** 2, axis=1)))
        assert kin.angles.attrs["hip_centre"] == model.hip_centre
    assert errors["functional"] < 0.75 * errors["harrington"]


def test_functional_knee_axis_reduces_cross_talk(harrington, functional_knee):
    slopes = {}
    for name, model in (("epicondyles", harrington), ("functional", functional_knee)):
        angles = model.angles(KNEE)
        assert angles.attrs["knee_axis"] == model.knee_axis
        flexion = angles["knee", "right", "flexion"]
        slopes[name] = np.polyfit(flexion, angles["knee", "right", "adduction"], 1)[0]
        assert flexion.max() == pytest.approx(90, abs=6)
    # the epicondylar line is 5 deg off the true flexion axis: adduction follows flexion
    assert abs(slopes["epicondyles"]) > 0.07
    assert abs(slopes["functional"]) < 0.5 * abs(slopes["epicondyles"])
    fit = functional_knee.options["functional_knee"]["right"]
    assert isinstance(fit, JointAxis)
    # the thigh frame's z axis is the SARA axis in the static trial
    lat, med = (functional_knee.landmarks.loc[f"RKNEE_AXIS_{e}"].to_numpy()
                for e in ("LAT", "MED"))
    z = functional_knee.static_frames[("thigh", "right")][0][:, 2]
    axis = (lat - med) / np.linalg.norm(lat - med)
    y = functional_knee.static_frames[("thigh", "right")][0][:, 1]
    expected = axis - (axis @ y) * y
    np.testing.assert_allclose(z, expected / np.linalg.norm(expected), atol=1e-12)


def test_one_call_form_passes_the_options():
    angles = lower_limb_angles(STATIC, KNEE, MARKERS, knee_axis="functional",
                               knee_axis_trial=KNEE, hip_centre="functional",
                               functional_trial=HIP)
    assert angles.attrs["hip_centre"] == "functional"
    assert angles.attrs["knee_axis"] == "functional"


def test_functional_needs_its_trial():
    with pytest.raises(ValueError, match=r"hip_centre='functional' needs functional_trial"):
        calibrate_lower_limb(STATIC, MARKERS, hip_centre="functional")
    with pytest.raises(ValueError, match=r"knee_axis='functional' needs knee_axis_trial"):
        calibrate_lower_limb(STATIC, MARKERS, knee_axis="functional")


def test_trial_without_its_option():
    with pytest.raises(ValueError, match=r"functional_trial is used only with "
                       r"hip_centre='functional'; got hip_centre='harrington'"):
        calibrate_lower_limb(STATIC, MARKERS, functional_trial=HIP)


def test_functional_needs_a_static_trial():
    with pytest.raises(ValueError, match=r"hip_centre='functional' needs a static trial"):
        calibrate_lower_limb(None, MARKERS, hip_centre="functional", functional_trial=HIP)


def test_unknown_knee_axis():
    with pytest.raises(ValueError, match=r"knee_axis must be 'epicondyles' or "
                       r"'functional'; got 'sara'"):
        calibrate_lower_limb(STATIC, MARKERS, knee_axis="sara")


def test_functional_needs_the_clusters():
    no_shank = {k: v for k, v in MARKERS.items() if k != "RSHANK"}
    # without a shank cluster the shank landmarks must be in every trial: the knee
    # trial has no malleoli, but the check for the cluster comes first
    with pytest.raises(ValueError, match=r"knee_axis='functional' needs a technical "
                       r"cluster .* no 'RSHANK'"):
        calibrate_lower_limb(STATIC, no_shank, knee_axis="functional",
                             knee_axis_trial=KNEE)


def test_functional_trial_without_movement_names_side_and_trial():
    with pytest.raises(ValueError, match=r"hip_centre='functional', right hip in the hip "
                       r"movement trial \(static.trc\): too little movement"):
        calibrate_lower_limb(STATIC, MARKERS, hip_centre="functional",
                             functional_trial=STATIC)
    with pytest.raises(ValueError, match=r"knee_axis='functional', right knee in the knee "
                       r"flexion trial \(static.trc\): too little movement"):
        calibrate_lower_limb(STATIC, MARKERS, knee_axis="functional",
                             knee_axis_trial=STATIC)


def swap_side(label):
    return {"R": "L", "L": "R"}.get(label[0], label[0]) + label[1:]


def mirrored(path):
    """The trial mirrored across the sagittal plane (z negated), with R and L labels
    swapped: the same movement of the left leg."""
    from bmc_functions import read_trc
    df = read_trc(path)
    out = df.copy()
    out.loc[:, (slice(None), "z")] = -out.loc[:, (slice(None), "z")]
    out.columns = pd.MultiIndex.from_tuples([(swap_side(m), c) for m, c in df.columns],
                                            names=df.columns.names)
    out.attrs = dict(df.attrs)
    return out


def test_left_side_gives_the_same_results():
    pelvis = ("RASIS", "LASIS", "RPSIS", "LPSIS")
    left = {role if role in pelvis else swap_side(role):
            value if role in pelvis else
            ([swap_side(v) for v in value] if isinstance(value, list) else swap_side(value))
            for role, value in MARKERS.items()}
    static, hip, knee = (mirrored(p) for p in (STATIC, HIP, KNEE))
    right = calibrate_lower_limb(STATIC, MARKERS, hip_centre="functional",
                                 functional_trial=HIP, knee_axis="functional",
                                 knee_axis_trial=KNEE)
    model = calibrate_lower_limb(static, left, hip_centre="functional",
                                 functional_trial=hip, knee_axis="functional",
                                 knee_axis_trial=knee)
    np.testing.assert_allclose(model.landmarks.loc["LHJC"].to_numpy(),
                               right.landmarks.loc["RHJC"].to_numpy() * [1, 1, -1], atol=1e-6)
    # the knee angles read the same clinically on both sides
    a_right = right.angles(KNEE)["knee", "right"]
    a_left = model.angles(knee)["knee", "left"]
    np.testing.assert_allclose(a_left.to_numpy(), a_right.to_numpy(), atol=1e-6)


def test_models_with_functional_fits_pickle_and_copy(functional_hip, functional_knee):
    # the fits kept in model.options (a JointCentre, a JointAxis) survive pickling (worker
    # processes, saving a calibration) and deepcopy; the restored model gives the same angles
    for model in (functional_hip, functional_knee):
        for restored in (pickle.loads(pickle.dumps(model)), copy.deepcopy(model)):
            np.testing.assert_array_equal(restored.angles(KNEE).to_numpy(),
                                          model.angles(KNEE).to_numpy())
    fit = pickle.loads(pickle.dumps(functional_knee)).options["functional_knee"]["right"]
    assert isinstance(fit, JointAxis) and fit.frames_used == 1001


# --- issue 21: functional trials checked like dynamic ones ---------------------------------

import warnings  # noqa: E402

from bmc_functions import read_trc  # noqa: E402


def _hip_error(trial):
    model = calibrate_lower_limb(STATIC, MARKERS, hip_centre="functional",
                                 functional_trial=trial)
    return float(np.linalg.norm(model.landmarks.loc["RHJC"].to_numpy() - true_static_hip()))


def _recorded(function, *args):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = function(*args)
    return result, [str(w.message) for w in caught]


def test_functional_trial_in_metres_labelled_mm_is_refused():
    trial = read_trc(HIP)
    trial.iloc[:, :] = trial.to_numpy() / 1000
    with pytest.raises(ValueError, match=r"hip movement trial's markers are 0.001 times "
                                         r"their size in the static trial .*units"):
        _hip_error(trial)


def test_mirrored_star_arc_is_refused():
    trial = read_trc(HIP)
    trial.loc[:, (slice(None), "z")] *= -1
    with pytest.raises(ValueError, match=r"in every frame of the hip movement trial .*the "
                                         r"body is mirrored"):
        _hip_error(trial)


def test_thigh_labels_swapped_half_way_are_left_out_of_the_fit():
    trial = read_trc(HIP)
    rows = trial.index[len(trial) // 2:]
    first = trial.loc[rows, "RTH1"].to_numpy()
    trial.loc[rows, "RTH1"] = trial.loc[rows, "RTH2"].to_numpy()
    trial.loc[rows, "RTH2"] = first
    error, messages = _recorded(_hip_error, trial)
    assert any(m.startswith("751 of 1501 frames of the hip movement trial are left out of "
                            "the functional fit") and "RTHIGH" in m for m in messages)
    assert not any("fewer than 3 visible" in m for m in messages)   # not counted twice
    assert error < 5.0          # 24 mm off when the swapped frames were used


def test_sliding_thigh_marker_is_left_out_where_it_slid():
    trial = read_trc(HIP)
    trial[("RTH3", "x")] += np.linspace(0, 40, len(trial))
    error, messages = _recorded(_hip_error, trial)
    assert any("left out of the functional fit" in m and "RTHIGH" in m for m in messages)
    assert error < 12.0          # 24 mm with every frame


def test_clean_functional_trials_raise_no_new_warning():
    _, messages = _recorded(_hip_error, HIP)
    assert messages == []
    _, messages = _recorded(lambda: calibrate_lower_limb(
        STATIC, MARKERS, knee_axis="functional", knee_axis_trial=KNEE))
    assert messages == []


def test_mirrored_knee_trial_gives_an_axis_far_from_the_epicondyles_and_warns():
    # a hinge mirrored across the sagittal plane is still a medio-lateral hinge, and a
    # nearly planar thigh cluster fits its mirror image: only the anatomy tells
    trial = read_trc(KNEE)
    trial.loc[:, (slice(None), "z")] *= -1
    with pytest.warns(RuntimeWarning, match=r"functional right knee axis from the knee "
                                            r"flexion trial is 2\d degrees from the "
                                            r"epicondylar line .* passes 2\d mm"):
        calibrate_lower_limb(STATIC, MARKERS, knee_axis="functional", knee_axis_trial=trial)
