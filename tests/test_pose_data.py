"""The committed data/poses/ files: reproducible from their generator, and self-consistent.

The generator (data/generate_pose_data.py) does not use bmc_functions, so recovering its
ground-truth angles from its true positions with pose_to_angles is an independent check.
"""


import numpy as np
import pandas as pd
import pytest

from bmc_functions import Skeleton, angles_to_pose, pose_to_angles
from bmc_functions.models.skeleton import JOINTS, KEYPOINTS, ROTATING_JOINTS

from helpers import ROOT, load_data_script

POSES = ROOT / "data" / "poses"
FILES = ["walking_keypoints.csv", "walking_skeleton.csv", "walking_true_angles.csv",
         "walking_true_positions.csv"]


@pytest.fixture(scope="module")
def generator():
    return load_data_script("generate_pose_data")


def read_xyz(name, joints):
    table = pd.read_csv(POSES / name)
    return table["time"].to_numpy(), {
        j: table[[f"{j}_x", f"{j}_y", f"{j}_z"]].to_numpy() for j in joints}


def true_skeleton():
    table = pd.read_csv(POSES / "walking_skeleton.csv", keep_default_na=False)
    return Skeleton({row.joint: [row.offset_x, row.offset_y, row.offset_z]
                     for row in table.itertuples() if row.joint != "hips"})


@pytest.mark.parametrize("name", FILES)
def test_generator_reproduces_the_committed_files(generator, tmp_path, name):
    written = generator.write(tmp_path)
    assert written == FILES
    fresh = (tmp_path / name).read_text().splitlines()
    committed = (POSES / name).read_text().splitlines()
    assert fresh[0] == committed[0]          # header
    assert len(fresh) == len(committed)
    if fresh == committed:
        return
    # Otherwise allow one unit in the last printed digit (libm differences across
    # platforms), with the same NaN pattern.
    a = pd.read_csv(tmp_path / name, keep_default_na=False, na_values=["nan"])
    b = pd.read_csv(POSES / name, keep_default_na=False, na_values=["nan"])
    num = a.select_dtypes("number").columns
    assert (a.drop(columns=num) == b.drop(columns=num)).all().all()
    np.testing.assert_array_equal(a[num].isna(), b[num].isna())
    np.testing.assert_allclose(a[num].to_numpy(), b[num].to_numpy(), atol=2e-6, rtol=0)


def test_files_are_small():
    assert sum((POSES / n).stat().st_size for n in FILES) < 1_000_000


def test_lost_keypoints_are_the_documented_runs(generator):
    _, kp = read_xyz("walking_keypoints.csv", KEYPOINTS)
    lost = {j: np.flatnonzero(np.isnan(kp[j]).any(axis=1)).tolist() for j in KEYPOINTS}
    expected = {j: [] for j in KEYPOINTS}
    for joint, first, last in generator.LOST:
        expected[joint] += list(range(first, last + 1))
    assert lost == expected
    assert sum(map(len, expected.values())) > 0
    for j in KEYPOINTS:  # a NaN keypoint is NaN in all three coordinates
        assert (np.isnan(kp[j]).any(axis=1) == np.isnan(kp[j]).all(axis=1)).all()


def test_true_angles_are_recovered_from_the_true_positions():
    t, pos = read_xyz("walking_true_positions.csv", JOINTS)
    angles = pd.read_csv(POSES / "walking_true_angles.csv")
    assert len(t) == 200 and np.allclose(np.diff(t), 0.02)
    result = pose_to_angles({j: pos[j] for j in KEYPOINTS}, true_skeleton())
    for joint in ROTATING_JOINTS + ("root",):
        truth = angles[[f"{joint}_z", f"{joint}_x", f"{joint}_y"]].to_numpy()
        found = result.root_angles if joint == "root" else result.angles[joint]
        # positions are stored to 1 micrometre: angles to about a thousandth of a degree
        np.testing.assert_allclose(np.rad2deg(found), truth, atol=5e-3, err_msg=joint)
    np.testing.assert_allclose(result.root_position, pos["hips"], atol=1e-6)


def test_true_positions_follow_the_true_skeleton():
    _, pos = read_xyz("walking_true_positions.csv", JOINTS)
    sk = true_skeleton()
    for joint in JOINTS[1:]:
        parent = Skeleton.parents[joint]
        length = np.linalg.norm(pos[joint] - pos[parent], axis=1)
        np.testing.assert_allclose(length, np.linalg.norm(sk.offsets[joint]), atol=3e-6)
    np.testing.assert_allclose(pos["hips"], 0.5 * (pos["lefthip"] + pos["righthip"]),
                               atol=2e-6)
    np.testing.assert_allclose(pos["neck"],
                               0.5 * (pos["leftshoulder"] + pos["rightshoulder"]), atol=2e-6)


def test_noisy_keypoints_give_angles_within_a_few_degrees():
    _, kp = read_xyz("walking_keypoints.csv", KEYPOINTS)
    angles = pd.read_csv(POSES / "walking_true_angles.csv")
    result = pose_to_angles(kp, Skeleton.from_positions(kp))
    for joint in ROTATING_JOINTS:
        truth = angles[[f"{joint}_z", f"{joint}_x", f"{joint}_y"]].to_numpy()
        error = np.rad2deg(result.angles[joint]) - truth
        rms = np.sqrt(np.nanmean(error ** 2))
        assert 0.1 < rms < 5, (joint, rms)  # noise is felt, but the angles are right
    Q = angles_to_pose(result, Skeleton.from_positions(kp))
    assert np.isnan(Q["leftwrist"][50:65]).all() and np.isfinite(Q["leftwrist"][:50]).all()
