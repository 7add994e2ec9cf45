"""Tests of bmc_functions.lower_limb_checks at their thresholds (the messages themselves are
checked case by case in tests/test_lower_limb.py, through calibrate_lower_limb)."""

import warnings

import numpy as np
import pytest

from bmc_functions import calibrate_lower_limb, read_trc
from bmc_functions.lower_limb_checks import (COLLINEAR_WARN_RATIO, DEFORM_FACTOR, DEFORM_MM,
                                             STATIC_MOTION_MM, STATIC_ROTATION_DEG)

from helpers import ROOT, load_data_script

GEN = load_data_script("generate_marker_data")
MARKERS_DIR = ROOT / "data" / "markers"


def markers():
    roles = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
             "PELVIS": ["PEL1", "PEL2", "PEL3"]}
    roles.update({"RTHIGH": ["RTH1", "RTH2", "RTH3", "RTH4"], "RSHANK": ["RTB1", "RTB2", "RTB3"],
                  "RKNEE_LAT": "RLFC", "RKNEE_MED": "RMFC", "RANKLE_LAT": "RLMAL",
                  "RANKLE_MED": "RMMAL", "RHEEL": "RHEEL", "RTOE": "RTOE", "RMT5": "RMT5"})
    return roles


@pytest.fixture(scope="module")
def clean():
    return GEN.make_trials(noise_sd=0.0, sta_scale=0.0, gaps=False)


def _warnings(function, *args, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        function(*args, **kwargs)
    return [str(w.message) for w in caught]


@pytest.mark.parametrize("travel, warns", [(0.9 * STATIC_MOTION_MM, False),
                                           (1.1 * STATIC_MOTION_MM, True)])
def test_static_motion_threshold(clean, travel, warns):
    static = clean["static"].copy()
    ramp = np.zeros(len(static))
    ramp[-1] = travel                  # one frame away: the median stays where it was
    static[[c for c in static.columns if c[1] == "y"]] += ramp[:, None]
    messages = _warnings(calibrate_lower_limb, static, markers())
    assert any("is not static" in m for m in messages) == warns


@pytest.mark.parametrize("factor, warns", [(0.8, False), (1.2, True)])
def test_static_rotation_threshold(clean, factor, warns):
    # The last frame turned about the vertical through the pelvis: every group turns by
    # about that angle from the mean orientation (the mean barely moves: 1 frame of 50).
    static = clean["static"].copy()
    xyz = static.to_numpy().copy().reshape(len(static), -1, 3)
    a = np.deg2rad(factor * STATIC_ROTATION_DEG)
    R = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    centre = static["RASI"].to_numpy()[-1]
    xyz[-1] = (xyz[-1] - centre) @ R.T + centre
    static.iloc[:, :] = xyz.reshape(len(static), -1)
    messages = _warnings(calibrate_lower_limb, static, markers())
    assert not any("moves up to" in m for m in messages)      # travel stays below its limit
    assert any("from its mean orientation" in m or "from their mean orientation" in m
               for m in messages) == warns


def test_collinear_threshold_is_a_ratio_of_singular_values(clean):
    static = clean["static"].copy()
    a, b = static["RTB1"].to_numpy(), static["RTB3"].to_numpy()
    direction = (a - b) / np.linalg.norm(a - b, axis=1, keepdims=True)
    normal = np.cross(direction, [0.0, 0.0, 1.0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    for offset, warns in ((5.0, True), (60.0, False)):
        s = static.copy()
        s[[("RTB2", c) for c in "xyz"]] = (a + b) / 2 + offset * normal
        cluster = np.stack([s[n].to_numpy()[0] for n in ("RTB1", "RTB2", "RTB3")])
        sv = np.linalg.svd(cluster - cluster.mean(axis=0), compute_uv=False)
        assert (sv[1] < COLLINEAR_WARN_RATIO * sv[0]) == warns
        messages = _warnings(calibrate_lower_limb, s, markers())
        assert any("nearly collinear" in m for m in messages) == warns


@pytest.mark.parametrize("shift, warns", [(0.8 * DEFORM_MM, False), (4 * DEFORM_MM, True)])
def test_deformation_threshold(clean, shift, warns):
    model = calibrate_lower_limb(clean["static"], markers())
    walk = clean["walk"].copy()
    walk[("RTB1", "x")] += shift            # RMSE of 3 markers with one moved by d: < d
    messages = _warnings(model.angles, walk)
    assert any("deforms" in m for m in messages) == warns
    assert DEFORM_FACTOR * max(model.static_rmse.values()) < DEFORM_MM   # clean: floor rules
