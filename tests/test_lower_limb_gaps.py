"""The lower-limb pipeline on trials as clinical systems write them: no heel marker, and
no static trial with gaps in different frames (issue 20, items 2 and 3).

Oracle: the same trial without the defect (the angles of every frame whose markers are
all there do not change), on the real walk of ../shared/data and the synthetic legs.
"""

import sys
import warnings

import numpy as np
import pytest

from bmc_functions import calibrate_lower_limb, gait_events, lower_limb_angles, read_trc

from helpers import ROOT, SHARED_DATA

sys.path.insert(0, str(ROOT / "tests"))
from test_gait_cycles import leg_roles  # noqa: E402

WALK = SHARED_DATA / "walk.trc"
needs_shared = pytest.mark.skipif(not WALK.exists(), reason="../shared/data absent")


def walk_markers():
    markers = {"RASIS": "R.ASIS", "LASIS": "L.ASIS", "RPSIS": "R.PSIS", "LPSIS": "L.PSIS"}
    for p, side in (("R", "R."), ("L", "L.")):
        markers.update({p + "KNEE_LAT": side + "Knee", p + "KNEE_MED": side + "Knee.Medial",
                        p + "ANKLE_LAT": side + "Ankle", p + "ANKLE_MED": side + "Ankle.Medial",
                        p + "HEEL": side + "Heel", p + "TOE": side + "MT2",
                        p + "MT5": side + "MT5"})
    return markers


# --- item 2: no heel marker -----------------------------------------------------------------

def test_a_side_without_heel_gets_hip_and_knee_angles_and_nan_ankle():
    static, walk = read_trc(ROOT / "data" / "gait" / "legs_static.trc"), \
        read_trc(ROOT / "data" / "gait" / "legs_walk.trc")
    full = calibrate_lower_limb(static, leg_roles()).angles(walk)
    roles = {k: v for k, v in leg_roles().items() if k != "LHEEL"}
    with pytest.warns(UserWarning, match=r"the left side has no foot frame \(LHEEL not in "
                                         r"the mapping\): its hip and knee angles are "
                                         r"computed, its ankle angles are NaN"):
        model = calibrate_lower_limb(static, roles)
    angles = model.angles(walk)
    assert angles.attrs["notes"] == [
        "the left side has no foot frame (LHEEL not in the mapping): its hip and knee "
        "angles are computed, its ankle angles are NaN"]
    assert angles["ankle", "left"].isna().all().all()
    others = [c for c in angles.columns if c[:2] != ("ankle", "left")]
    np.testing.assert_array_equal(angles[others].to_numpy(), full[others].to_numpy())
    assert np.isnan(model.static_angles["ankle", "left"]).all()


@needs_shared
def test_the_real_walk_without_heel_markers():
    markers = {k: v for k, v in walk_markers().items() if not k.endswith("HEEL")}
    with pytest.warns(UserWarning, match="the right and left side has no foot frame"):
        angles = lower_limb_angles(None, WALK, markers)
    assert angles["ankle"].isna().all().all()
    assert angles[["pelvis", "hip", "knee"]].notna().all().all()
    # and the events come from what the feet have: the lateral malleolus and the toe
    events = gait_events(WALK, markers)
    assert events.markers["right"]["heel_strike"] == ["R.Ankle"]
    assert events.markers["right"]["toe_off"] == ["R.MT2"]


# --- item 3: no static trial, gaps in different frames -------------------------------------

def with_gaps(trial, gaps):
    out = trial.copy()
    for label, rows in gaps.items():
        out.loc[out.index[rows], label] = np.nan
    return out


@needs_shared
def test_without_static_the_posture_comes_from_frames_seen_together():
    # no frame has every marker (the right knee is hidden in every other block of 10
    # frames, the left medial ankle in the blocks between): each side is judged with the
    # pelvis in the frames where they are seen together; the angles of each frame are
    # those of the full trial
    walk = read_trc(WALK)
    blocks = (np.arange(len(walk)) // 10) % 2 == 0
    gappy = with_gaps(walk, {"R.Knee": np.flatnonzero(blocks),
                             "L.Ankle.Medial": np.flatnonzero(~blocks)})
    markers = walk_markers()
    full = lower_limb_angles(None, walk, markers)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)    # the gaps are reported
        angles = lower_limb_angles(None, gappy, markers)
    assert angles.notna().all(axis=1).sum() == 0           # no frame has every angle
    present = angles.notna().to_numpy()
    np.testing.assert_allclose(angles.to_numpy()[present], full.to_numpy()[present],
                               atol=1e-9)
    assert angles["knee", "right"].notna().all(axis=1).sum() == np.count_nonzero(~blocks)


@needs_shared
def test_without_static_and_no_frame_with_the_pelvis_and_a_side_is_an_error():
    walk = read_trc(WALK)
    n = len(walk)
    gappy = with_gaps(walk, {label: slice(n // 3, None) for label in
                             ("R.ASIS", "L.ASIS", "R.PSIS", "L.PSIS")})
    gappy = with_gaps(gappy, {"R.Knee": slice(0, n // 2)})
    with pytest.raises(ValueError, match=r"\(no static trial\): no frame has the pelvis "
                                         r"markers and the right side's markers \(.*R\.Knee"
                                         r".*\) all seen together"):
        lower_limb_angles(None, gappy, walk_markers())
    pelvis_never = with_gaps(walk, {"R.ASIS": slice(0, n // 2), "L.ASIS": slice(n // 2, None)})
    with pytest.raises(ValueError, match=r"no frame has the pelvis markers \(R\.ASIS, L\.ASIS"
                                         r", R\.PSIS, L\.PSIS\) all seen together"):
        lower_limb_angles(None, pelvis_never, walk_markers())
