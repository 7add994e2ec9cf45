"""The committed functional trials in data/functional/ are what
data/generate_functional_data.py writes, and they hold what data/README.md promises."""

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from bmc_functions import read_trc

from helpers import ROOT, load_data_script

FOLDER = ROOT / "data" / "functional"
TRIALS = ["static", "hip_star_arc", "knee_flexion"]
FILES = [f"{name}{suffix}" for name in TRIALS for suffix in (".trc", "_truth.csv")]

GEN = load_data_script("generate_functional_data")


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory):
    folder = tmp_path_factory.mktemp("functional")
    GEN.write_trials(folder)
    return folder


@pytest.mark.parametrize("name", FILES)
def test_generator_reproduces_the_committed_files(regenerated, name):
    committed = (FOLDER / name).read_bytes()
    fresh = (regenerated / name).read_bytes()
    assert fresh == committed, (f"data/functional/{name} differs from what the generator "
                                "writes: run python data/generate_functional_data.py")


def test_files_are_small():
    assert sum((FOLDER / name).stat().st_size for name in FILES) < 2_000_000


def test_trials_hold_what_the_readme_says():
    static = read_trc(FOLDER / "static.trc")
    hip = read_trc(FOLDER / "hip_star_arc.trc")
    knee = read_trc(FOLDER / "knee_flexion.trc")
    for trial in (static, hip, knee):
        assert trial.attrs["units"] == "mm" and trial.attrs["rate"] == 100.0
        assert not trial.isna().any().any()
    names = lambda df: list(dict.fromkeys(df.columns.get_level_values(0)))  # noqa: E731
    pelvis, thigh, shank = (list(GEN.PELVIS_MARKERS), list(GEN.THIGH_CLUSTER),
                            list(GEN.SHANK_CLUSTER))
    foot = list(GEN.FOOT_MARKERS)
    assert names(hip) == pelvis + thigh + shank + foot
    assert names(knee) == pelvis + thigh + shank + foot
    assert set(names(static)) == set(pelvis + thigh + shank + foot
                                     + list(GEN.THIGH_LANDMARKS) + list(GEN.SHANK_LANDMARKS))
    assert len(static) == 50 and len(hip) == 1501 and len(knee) == 1001


def _pose(table, segment):
    R = table[[f"{segment}_R{i}{j}" for i in range(3) for j in range(3)]].to_numpy()
    origin = table[[f"{segment}_o{c}" for c in "xyz"]].to_numpy()
    return R.reshape(-1, 3, 3), origin


def test_truth_is_consistent_with_the_model():
    hip = pd.read_csv(FOLDER / "hip_star_arc_truth.csv")
    R_p, o_p = _pose(hip, "pelvis")
    R_t, o_t = _pose(hip, "thigh")
    centre = hip[["hip_x", "hip_y", "hip_z"]].to_numpy()
    # the hip centre is fixed in the pelvis and is the thigh's origin
    np.testing.assert_allclose(np.einsum("fji,fj->fi", R_p, centre - o_p),
                               np.broadcast_to(GEN.HIP_CENTRE, centre.shape), atol=1e-5)
    np.testing.assert_allclose(o_t, centre, atol=1e-6)
    # the true centre lies 15.7 mm from Harrington's regression, as the README says
    assert np.linalg.norm(GEN.HARRINGTON_ERROR) == pytest.approx(15.7, abs=0.05)
    knee = pd.read_csv(FOLDER / "knee_flexion_truth.csv")
    R_t, o_t = _pose(knee, "thigh")
    direction = knee[[f"axis_direction_{c}" for c in "xyz"]].to_numpy()
    np.testing.assert_allclose(np.linalg.norm(direction, axis=1), 1.0, atol=1e-8)
    np.testing.assert_allclose(np.einsum("fji,fj->fi", R_t, direction),
                               np.broadcast_to(GEN.KNEE_AXIS, direction.shape), atol=1e-7)
    # the axis is 5.0 deg from the epicondylar z axis
    angle = np.degrees(np.arccos(GEN.KNEE_AXIS[2]))
    assert angle == pytest.approx(5.0, abs=0.01)
    # without secondary rotations the shank turns about the axis only: knee angles from
    # the truth poses (scipy) give the flexion back
    R_s, _ = _pose(knee, "shank")
    rel = Rotation.from_matrix(np.swapaxes(R_t, 1, 2) @ R_s)
    flexion = -np.degrees(rel.as_rotvec() @ np.array(GEN.KNEE_AXIS))
    assert np.corrcoef(flexion, knee["knee_flexion"])[0, 1] > 0.999
    assert knee["knee_flexion"].min() == pytest.approx(5.0, abs=1e-6)
    assert knee["knee_flexion"].max() == pytest.approx(90.0, abs=0.01)
