"""The synthetic gait trials of data/gait/ are bodies, not mirror images of bodies."""

import numpy as np
import pytest

from bmc_functions import read_trc
from helpers import ROOT


@pytest.mark.parametrize("name", ["walk", "run"])
def test_synthetic_trials_are_right_handed(name):
    # forward (from the posterior markers to the ASISs) x up must point to the subject's
    # right (from LASI to RASI), in every frame: x x y = z in the ISB axes
    trial = read_trc(ROOT / "data" / "gait" / f"{name}.trc")
    p = {m: trial[m].to_numpy() for m in ("RASI", "LASI", "RPSI", "LPSI")}
    forward = (p["RASI"] + p["LASI"] - p["RPSI"] - p["LPSI"]) / 2
    right = p["RASI"] - p["LASI"]
    up = np.cross(right, forward)             # right x forward = up for a right-handed body
    heel_to_hip = p["RASI"] - trial["RHEE"].to_numpy()
    ok = np.isfinite(up).all(axis=1) & np.isfinite(heel_to_hip).all(axis=1)
    assert ok.sum() > 100
    assert np.all(np.einsum("fi,fi->f", up[ok], heel_to_hip[ok]) > 0), \
        f"{name}.trc is a mirror image: the pelvis's 'up' points to the floor"
