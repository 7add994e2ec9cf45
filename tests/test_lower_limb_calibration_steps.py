"""Tests of the issue-24 refactor of the lower-limb model and its checks:
one pelvis role resolver, one body for angles and track, warnings at the user's line,
pure calibration steps, and the physical boundaries of the checks."""

import warnings
from types import SimpleNamespace

import numpy as np
import pytest

from bmc_functions import calibrate_lower_limb, lower_limb_angles
from bmc_functions.files.trial import MarkerTable
from bmc_functions.models import lower_limb, lower_limb_checks
from bmc_functions.models.lower_limb_checks import check_still

from helpers import (FUNCTIONAL_MARKERS, ROOT, load_data_script,
                     synthetic_markers as markers, warning_messages as _messages)

GEN = load_data_script("generate_marker_data")


@pytest.fixture(scope="module")
def clean():
    return GEN.make_trials(noise_sd=0.0, sta_scale=0.0, gaps=False)


def _turned(static, degrees, labels):
    """`static` with its last frame's `labels` turned by `degrees` about the vertical
    through RASI."""
    out = static.copy()
    a = np.deg2rad(degrees)
    R = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    centre = static["RASI"].to_numpy()[-1]
    for label in labels:
        xyz = static[label].to_numpy()[-1]
        out.loc[out.index[-1], label] = (xyz - centre) @ R.T + centre
    return out


# --- finding 3: one pelvis role resolver, no private model method ------------------------

def test_model_has_no_private_pelvis_roles(clean):
    model = calibrate_lower_limb(clean["static"], markers())
    assert not hasattr(model, "_pelvis_roles")
    for wrapper in ("_labels", "_points", "_has_data"):
        assert not hasattr(lower_limb, wrapper)


def test_check_still_needs_only_the_role_mapping(clean):
    # the pelvis markers (no cluster among them) turned by 20 degrees in one frame: the
    # rigid group is found from the mapping alone (pelvis_roles), as for any caller
    pelvis = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI"}
    static = _turned(clean["static"], 20.0, ["RASI", "LASI", "RPSI", "LPSI"])
    messages = _messages(check_still, pelvis, MarkerTable(static, "the static trial"), 1.0,
                         "the static trial")
    assert any("the pelvis markers (RASI, LASI, RPSI, LPSI) turn by up to 20 degrees" in m
               for m in messages)


# --- finding 4: one rotation angle; the static-rotation boundary (documented: 10 degrees)

def test_check_still_measures_turns_with_rotation_angle(clean, monkeypatch):
    # rotation_angle (atan2, accurate at small angles), not arccos of the trace
    original, calls = lower_limb_checks.rotation_angle, []

    def spy(R):
        calls.append(np.shape(R))
        return original(R)

    monkeypatch.setattr(lower_limb_checks, "rotation_angle", spy)
    _messages(calibrate_lower_limb, clean["static"], markers())
    assert calls and all(shape[-2:] == (3, 3) for shape in calls)


# --- finding 2: angles is track's body; every warning points at the user's line ---------

def _gap_walk(clean):
    walk = clean["walk"].copy()
    walk.iloc[10:20, walk.columns.get_loc(("RTH1", "x"))] = np.nan   # a gap of 10 frames
    walk.iloc[10:20, walk.columns.get_loc(("RTH2", "x"))] = np.nan   # 2 of 4 markers: NaN
    return walk


def test_warnings_of_model_angles_point_at_the_callers_line(clean):
    model = calibrate_lower_limb(clean["static"], markers())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model.angles(_gap_walk(clean))
    assert caught and all(w.filename == __file__ for w in caught)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model.track(_gap_walk(clean))
    assert caught and all(w.filename == __file__ for w in caught)


def test_warnings_of_lower_limb_angles_point_at_the_callers_line(clean):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lower_limb_angles(clean["static"], _gap_walk(clean), markers())
    assert caught and all(w.filename == __file__ for w in caught)


def test_angles_are_the_angles_of_track(clean):
    model = calibrate_lower_limb(clean["static"], markers())
    angles = model.angles(clean["walk"])
    assert angles.equals(model.track(clean["walk"]).angles)
    assert angles.attrs == model.track(clean["walk"]).angles.attrs


def test_angles_calls_track(clean, monkeypatch):
    # one body: a change to track (a new check, a new attrs entry) reaches angles
    model = calibrate_lower_limb(clean["static"], markers())
    monkeypatch.setattr(type(model), "track",
                        lambda self, dynamic: SimpleNamespace(angles=("tracked", dynamic)))
    assert model.angles("walk") == ("tracked", "walk")


# --- finding 1: calibration in pure named steps, the model assembled once ---------------

FUNCTIONAL = ROOT / "data" / "functional"


def _static_points_of(model, trial):
    loaded, _ = lower_limb._load(trial, "static")
    points = lower_limb._static_points(model, loaded.table, loaded.scale, loaded.name)
    return loaded, points


def test_hip_centre_methods_are_a_plain_table_of_pure_functions(clean):
    assert set(lower_limb.HIP_CENTRE_METHODS) == {"harrington", "marker", "functional"}
    assert not hasattr(lower_limb, "_hip_centre_method")
    model = calibrate_lower_limb(clean["static"], markers())
    _, points = _static_points_of(model, clean["static"])
    before = dict(model.options)
    centres, fits = lower_limb.HIP_CENTRE_METHODS["harrington"](model, points, {})
    assert fits == {} and model.options == before
    np.testing.assert_allclose(centres["right"], model.landmarks.loc["RHJC"].to_numpy())


def test_functional_steps_return_their_fits_and_write_nothing():
    model = calibrate_lower_limb(FUNCTIONAL / "static.trc", FUNCTIONAL_MARKERS,
                                 hip_centre="functional",
                                 functional_trial=FUNCTIONAL / "hip_star_arc.trc",
                                 knee_axis="functional",
                                 knee_axis_trial=FUNCTIONAL / "knee_flexion.trc")
    assert list(model.options) == ["functional_hip", "functional_knee"]
    hip_fit, knee_fit = (model.options[key]["right"]
                         for key in ("functional_hip", "functional_knee"))
    static, points = _static_points_of(model, FUNCTIONAL / "static.trc")
    trials = {"static": static,
              "functional_trial": lower_limb._load(FUNCTIONAL / "hip_star_arc.trc", "hip")[0],
              "knee_axis_trial": lower_limb._load(FUNCTIONAL / "knee_flexion.trc", "knee")[0]}
    centres, fits = lower_limb.functional_hip_centres(model, points, trials)
    rows, axes = lower_limb.functional_knee_axes(model, points, trials)
    np.testing.assert_allclose(centres["right"], model.landmarks.loc["RHJC"].to_numpy())
    np.testing.assert_allclose(rows["RKNEE_AXIS_LAT"],
                               model.landmarks.loc["RKNEE_AXIS_LAT"].to_numpy())
    assert fits["right"].rms_distance == model.options["functional_hip"]["right"].rms_distance
    np.testing.assert_allclose(axes["right"].locate(
        np.stack([points[label] for label in FUNCTIONAL_MARKERS["RTHIGH"]]))[1],
        model.options["functional_knee"]["right"].locate(
            np.stack([points[label] for label in FUNCTIONAL_MARKERS["RTHIGH"]]))[1])
    assert list(model.options) == ["functional_hip", "functional_knee"]   # nothing written
    assert model.options["functional_hip"]["right"] is hip_fit
    assert model.options["functional_knee"]["right"] is knee_fit


def test_cluster_and_posture_steps_rebuild_the_calibration(clean):
    model = calibrate_lower_limb(clean["static"], markers())
    static, points = _static_points_of(model, clean["static"])
    clusters, static_rmse = lower_limb.calibrate_clusters(model, static, points,
                                                          model.landmarks)
    assert list(clusters) == list(model.clusters) and static_rmse == model.static_rmse
    for name, entry in clusters.items():
        np.testing.assert_array_equal(entry["local"], model.clusters[name]["local"])
    frames, angles = lower_limb.static_posture(model, model.landmarks)
    assert angles.equals(model.static_angles)
    np.testing.assert_array_equal(frames[("pelvis", None)][0],
                                  model.static_frames[("pelvis", None)][0])


def test_calibration_does_not_write_into_the_model_it_is_given(clean, monkeypatch):
    # the configured model is handed to the steps; the calibrated one is a new object
    seen = []
    original = lower_limb.check_static_geometry

    def spy(model, points, hips):
        seen.append(model)
        return original(model, points, hips)

    monkeypatch.setattr(lower_limb, "check_static_geometry", spy)
    model = calibrate_lower_limb(clean["static"], markers())
    configured = seen[0]
    assert configured is not model
    assert configured.landmarks.empty and configured.clusters == {}
    assert configured.static_rmse == {} and configured.options == {}
    assert configured.units is None and not model.landmarks.empty


# --- finding 6: no function body (docstring aside) longer than about 80 lines ------------

import ast  # noqa: E402


MODULES = ["bmc_functions/models/lower_limb.py", "bmc_functions/models/lower_limb_checks.py",
           "bmc_functions/markers/roles.py", "bmc_functions/markers/tracking.py"]


def _body_lengths(path):
    for node in ast.walk(ast.parse((ROOT / path).read_text())):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                body = body[1:]                      # the docstring
            if body:
                yield node.name, body[-1].end_lineno - body[0].lineno + 1


@pytest.mark.parametrize("path", MODULES)
def test_no_function_body_is_longer_than_80_lines(path):
    long = {name: length for name, length in _body_lengths(path) if length > 80}
    assert not long


# --- finding 5: names that explain themselves ----------------------------------------------

MISLEADING = {"dead", "few", "flat", "m", "P", "th", "sh", "ft", "pel", "lm", "sv", "frame",
              "df_f", "trial_f"}


def _bound_names(path):
    for node in ast.walk(ast.parse((ROOT / path).read_text())):
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            yield node.id
        elif isinstance(node, ast.arg):
            yield node.arg
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield node.name


@pytest.mark.parametrize("path", MODULES)
def test_no_misleading_names(path):
    assert not MISLEADING & set(_bound_names(path))


@pytest.mark.parametrize("distance, warns", [(49.0, False), (51.0, True)])
def test_functional_hip_centre_warns_beyond_50_mm_from_harrington(monkeypatch, distance,
                                                                  warns):
    # the regression replaced by the functional centre moved `distance` mm: documented
    # warning above 50 mm (FUNCTIONAL_HIP_DISTANCE_MM)
    model = calibrate_lower_limb(FUNCTIONAL / "static.trc", FUNCTIONAL_MARKERS,
                                 hip_centre="functional",
                                 functional_trial=FUNCTIONAL / "hip_star_arc.trc")
    static, points = _static_points_of(model, FUNCTIONAL / "static.trc")
    trials = {"static": static,
              "functional_trial": lower_limb._load(FUNCTIONAL / "hip_star_arc.trc", "hip")[0]}
    found = model.landmarks.loc["RHJC"].to_numpy()
    moved = {"right": found + distance * np.array([0.0, 0.6, 0.8])}
    monkeypatch.setattr(lower_limb, "harrington_hip_centres",
                        lambda model, points, trials: (moved, {}))
    messages = _messages(lower_limb.functional_hip_centres, model, points, trials)
    assert any("lies" in m and "from Harrington's regression" in m for m in messages) == warns
