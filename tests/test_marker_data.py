"""The committed marker trials in data/markers/ are what data/generate_marker_data.py
writes, and they have the properties data/README.md promises."""


import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from bmc_functions import read_trc
from bmc_functions._checks import check_rotation_matrix

from helpers import ROOT, load_data_script

MARKERS = ROOT / "data" / "markers"
FILES = ["static.trc", "walk.trc", "static_truth.csv", "walk_truth.csv"]


GEN = load_data_script("generate_marker_data")


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory):
    folder = tmp_path_factory.mktemp("markers")
    GEN.write_trials(folder)
    return folder


@pytest.mark.parametrize("name", FILES)
def test_generator_reproduces_the_committed_files(regenerated, name):
    committed = (MARKERS / name).read_bytes()
    fresh = (regenerated / name).read_bytes()
    assert fresh == committed, (f"data/markers/{name} differs from what the generator "
                                "writes: run python data/generate_marker_data.py")


def test_files_are_small():
    assert sum((MARKERS / name).stat().st_size for name in FILES) < 2_000_000


def test_trials_hold_what_the_readme_says():
    static = read_trc(MARKERS / "static.trc")
    walk = read_trc(MARKERS / "walk.trc")
    assert static.attrs["units"] == walk.attrs["units"] == "mm"
    assert static.attrs["rate"] == walk.attrs["rate"] == 100.0
    clusters = [name for cluster in GEN.CLUSTERS.values() for name in cluster]
    landmarks = [name for group in GEN.LANDMARKS.values() for name in group]
    static_names = list(dict.fromkeys(static.columns.get_level_values(0)))
    walk_names = list(dict.fromkeys(walk.columns.get_level_values(0)))
    assert static_names == clusters + landmarks          # landmarks in the static trial only
    assert walk_names == clusters
    assert not static.isna().any().any()
    # the gaps are NaN runs exactly where listed, nothing else is missing
    missing = walk.isna()
    expected = np.zeros(missing.shape, bool)
    for name, first, last in GEN.GAPS:
        expected[first:last + 1, list(missing.columns.get_level_values(0)).index(name)
                 + np.arange(3)] = True
    assert np.array_equal(missing.to_numpy(), expected)


@pytest.mark.parametrize("name", ["static_truth.csv", "walk_truth.csv"])
def test_truth_poses_are_rotations_and_knee_angles_match_them(name):
    truth = pd.read_csv(MARKERS / name)
    R = {seg: truth[[f"{seg}_R{i}{j}" for i in range(3) for j in range(3)]]
         .to_numpy().reshape(-1, 3, 3) for seg in ("pelvis", "thigh", "shank")}
    for seg, Rs in R.items():
        # stored with 9 decimals: orthonormal well within the package's 1e-6 tolerance
        check_rotation_matrix(Rs, seg)
        np.testing.assert_allclose(Rs @ np.swapaxes(Rs, 1, 2),
                                   np.broadcast_to(np.eye(3), Rs.shape), atol=1e-8)
    # The knee angles are the intrinsic ZXY angles of thigh^T shank with flexion negated.
    relative = np.swapaxes(R["thigh"], 1, 2) @ R["shank"]
    zxy = Rotation.from_matrix(relative).as_euler("ZXY", degrees=True)
    angles = truth[["knee_flexion", "knee_adduction", "knee_internal_rotation"]].to_numpy()
    np.testing.assert_allclose(zxy * [-1, 1, 1], angles, atol=1e-5)
    if name == "walk_truth.csv":
        # a walking stride: knee flexion from near extension to 55-70 deg in swing
        assert angles[:, 0].min() < 10 and 55 < angles[:, 0].max() < 70


def test_soft_tissue_artefact_has_the_documented_size():
    clean = GEN.make_trials(noise_sd=0.0, sta_scale=0.0, gaps=False)["walk"]
    sta = GEN.make_trials(noise_sd=0.0, gaps=False)["walk"]
    shift = np.linalg.norm((sta - clean).to_numpy().reshape(len(sta), -1, 3), axis=2).max(0)
    names = list(dict.fromkeys(sta.columns.get_level_values(0)))
    largest = {seg: max(shift[names.index(n)] for n in cluster)
               for seg, cluster in GEN.CLUSTERS.items()}
    assert 8 < largest["thigh"] < 20            # up to 1-2 cm on the thigh
    assert 2 < largest["shank"] < largest["thigh"]
    assert largest["pelvis"] < largest["shank"]
    # smooth: frame-to-frame change far below the amplitude
    step = np.abs(np.diff((sta - clean).to_numpy(), axis=0)).max()
    assert step < 0.15 * largest["thigh"]
