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
    clusters, landmarks, feet = GEN.marker_names()
    static_names = list(dict.fromkeys(static.columns.get_level_values(0)))
    walk_names = list(dict.fromkeys(walk.columns.get_level_values(0)))
    assert static_names == clusters + landmarks + feet   # landmarks in the static trial only
    assert walk_names == clusters + feet
    assert len(static_names) == 35 and len(walk_names) == 23
    assert not static.isna().any().any()
    # the gaps are NaN runs exactly where listed, nothing else is missing
    missing = walk.isna()
    expected = np.zeros(missing.shape, bool)
    for name, first, last in GEN.GAPS:
        expected[first:last + 1, list(missing.columns.get_level_values(0)).index(name)
                 + np.arange(3)] = True
    assert np.array_equal(missing.to_numpy(), expected)


SEGMENTS = ["pelvis"] + [f"{side}_{segment}" for side in ("right", "left")
                         for segment in ("thigh", "shank", "foot")]


def _matrices(truth, segment):
    return truth[[f"{segment}_R{i}{j}" for i in range(3) for j in range(3)]] \
        .to_numpy().reshape(-1, 3, 3)


@pytest.mark.parametrize("name", ["static_truth.csv", "walk_truth.csv"])
def test_truth_poses_are_rotations_and_angles_match_them(name):
    truth = pd.read_csv(MARKERS / name)
    R = {seg: _matrices(truth, seg) for seg in SEGMENTS}
    for seg, Rs in R.items():
        # stored with 9 decimals: orthonormal well within the package's 1e-6 tolerance
        check_rotation_matrix(Rs, seg)
        np.testing.assert_allclose(Rs @ np.swapaxes(Rs, 1, 2),
                                   np.broadcast_to(np.eye(3), Rs.shape), atol=1e-8)
    mirror = np.diag([1.0, 1.0, -1.0])
    for side in ("right", "left"):
        for joint, prox, dist, signs, angles in (
                ("hip", "pelvis", f"{side}_thigh", [1, 1, 1], ("flexion", "adduction",
                                                               "rotation")),
                ("knee", f"{side}_thigh", f"{side}_shank", [-1, 1, 1],
                 ("flexion", "adduction", "rotation")),
                ("ankle", f"{side}_shank", f"{side}_foot", [1, 1, 1],
                 ("dorsiflexion", "inversion", "rotation"))):
            # intrinsic ZXY of proximal^T distal, of its mirror image on the left side
            relative = np.swapaxes(R[prox], 1, 2) @ R[dist]
            if side == "left":
                relative = mirror @ relative @ mirror
            zxy = Rotation.from_matrix(relative).as_euler("ZXY", degrees=True) * signs
            columns = [f"{side}_{joint}_{a}" for a in angles]
            np.testing.assert_allclose(zxy, truth[columns].to_numpy(), atol=1e-5)
    # pelvis: Baker's rotation-obliquity-tilt (intrinsic YXZ) in the lab
    yxz = Rotation.from_matrix(R["pelvis"]).as_euler("YXZ", degrees=True)
    np.testing.assert_allclose(yxz * [1, -1, -1], truth[["pelvis_rotation", "pelvis_obliquity",
                                                         "pelvis_tilt"]].to_numpy(), atol=1e-5)
    if name == "walk_truth.csv":
        for side in ("right", "left"):
            # a walking stride: knee flexion from near extension to 55-70 deg in swing,
            # ankle plantarflexion at push-off
            knee = truth[f"{side}_knee_flexion"]
            assert knee.min() < 10 and 55 < knee.max() < 70
            assert truth[f"{side}_ankle_dorsiflexion"].min() < -10
        # the left leg is half a stride behind the right
        assert abs(truth["left_knee_flexion"].idxmax() - truth["right_knee_flexion"].idxmax()
                   - 55) < 3 or abs(truth["right_knee_flexion"].idxmax()
                                    - truth["left_knee_flexion"].idxmax() - 55) < 3


def test_functions_are_reusable_for_other_trials():
    # several strides from the same pieces: periodic, both legs, same truth conventions
    time = np.arange(0, 3.3, 0.01)
    s = time / GEN.STRIDE_TIME
    legs = {"right": GEN.leg_angles(s), "left": GEN.leg_angles(s + 0.5)}
    origin = np.column_stack([1300.0 * time, np.full_like(time, 930.0), np.zeros_like(time)])
    poses = GEN.segment_poses(GEN.pelvis_angles(s), origin, legs)
    points = GEN.marker_positions(poses)
    truth = GEN.truth_table(time, poses)
    stride = int(round(GEN.STRIDE_TIME * 100))
    np.testing.assert_allclose(truth["left_knee_flexion"].to_numpy()[:-stride],
                               truth["left_knee_flexion"].to_numpy()[stride:], atol=1e-9)
    np.testing.assert_allclose(truth["right_knee_flexion"], legs["right"]["knee_flexion"],
                               atol=1e-9)
    assert set(points) == set(sum(GEN.marker_names(), []))


def test_soft_tissue_artefact_has_the_documented_size():
    clean = GEN.make_trials(noise_sd=0.0, sta_scale=0.0, gaps=False)["walk"]
    sta = GEN.make_trials(noise_sd=0.0, gaps=False)["walk"]
    shift = np.linalg.norm((sta - clean).to_numpy().reshape(len(sta), -1, 3), axis=2).max(0)
    names = list(dict.fromkeys(sta.columns.get_level_values(0)))
    clusters = {"pelvis": GEN.PELVIS_CLUSTER, "thigh": GEN.THIGH_CLUSTER,
                "shank": GEN.SHANK_CLUSTER}
    largest = {seg: max(shift[names.index(n)] for n in cluster)
               for seg, cluster in clusters.items()}
    assert 8 < largest["thigh"] < 20            # up to 1-2 cm on the thigh
    assert 2 < largest["shank"] < largest["thigh"]
    assert largest["pelvis"] < largest["shank"]
    # smooth: frame-to-frame change far below the amplitude
    step = np.abs(np.diff((sta - clean).to_numpy(), axis=0)).max()
    assert step < 0.15 * largest["thigh"]


def test_pelvis_is_lowest_in_double_support_as_in_walking():
    truth = pd.read_csv(MARKERS / "walk_truth.csv")
    s = truth["time"].to_numpy() / GEN.STRIDE_TIME
    height = truth["pelvis_oy"].to_numpy()
    lowest, highest = s[np.argmin(height)], s[np.argmax(height)]
    assert min(abs(lowest - 0.0), abs(lowest - 0.5), abs(lowest - 1.0)) < 0.02
    assert min(abs(highest - 0.25), abs(highest - 0.75)) < 0.02
