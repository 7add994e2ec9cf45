"""The pose estimator's typical mistakes, found in the keypoints themselves.

Three kinds, each judged against the trial's own scale (its median bone lengths and the
keypoints' usual frame-to-frame behaviour), so that no threshold is fitted to one file:

- :func:`side_swaps`: a keypoint of one side exchanged with its partner of the other side
  for some frames (a knee and an ankle, an elbow and a wrist...);
- :func:`jumps`: a keypoint that leaves its path for a few frames and comes back;
- :func:`bone_outliers`: a bone whose length departs from its median by more than the
  triangulation's spread explains.

Each returns boolean masks (frames,) per role and text for the one summary warning that
:func:`~bmc_functions.keypoint_angles` issues; the frames found are set to NaN there.
"""

import numpy as np
import pandas as pd

#: A frame-to-frame step is a side swap when exchanging the two sides' keypoints makes the
#: step at most this fraction of the step as labelled. Legitimately moving limbs never
#: come close: the exchange would need each keypoint to cover the distance between the
#: left and right limbs (10 cm or more) in one frame while the other covers none.
SWAP_RATIO = 0.5

#: A jump lasts at most this many frames (the running median's half-width).
JUMP_FRAMES = 5

#: A keypoint is off its path when its distance from its running median (over
#: 2 * JUMP_FRAMES + 1 frames) exceeds both JUMP_SPREADS times that distance's median
#: over the trial (the keypoint's usual noise) and JUMP_BONE_FRACTION times the trial's
#: median thigh (or upper-arm) length. On the shared Pose2Sim trials the largest such
#: distances are 96 mm (raw keypoints, 60 Hz) and 58 mm (filtered at 6 Hz), below 0.3
#: times a 415 mm thigh (125 mm).
JUMP_SPREADS = 10.0
JUMP_BONE_FRACTION = 0.3

#: A bone's length is an outlier when it departs from its median by more than both
#: BONE_SPREADS robust standard deviations (1.4826 x MAD) and BONE_FRACTION of the
#: median. On the shared filtered trial the largest departure is 5.7 spreads and 20 % of
#: the median (the left upper arm); Pose2Sim's triangulated bones vary that much.
BONE_SPREADS = 6.0
BONE_FRACTION = 0.3

#: At most this many passes: the frames flagged in one pass are left out of the median
#: and spread of the next, so that a bone stretched in many frames does not widen its own
#: threshold (15 of 100 frames did, by a third).
BONE_PASSES = 5

#: Pairs of roles (without the side prefix) whose distance is a bone, and its name.
BONES = {("HIP", "KNEE"): "thigh", ("KNEE", "ANKLE"): "shank", ("HEEL", "TOE"): "foot",
         ("SHOULDER", "ELBOW"): "upper arm", ("ELBOW", "WRIST"): "forearm"}


def frame_ranges(mask, time):
    """'30-39 (0.517-0.667 s), 52' for the True runs of `mask` (row numbers from 0)."""
    rows = np.flatnonzero(mask)
    if not rows.size:
        return ""
    breaks = np.flatnonzero(np.diff(rows) > 1)
    starts = np.r_[rows[0], rows[breaks + 1]]
    ends = np.r_[rows[breaks], rows[-1]]
    parts = [f"{a}-{b} ({time[a]:.3f}-{time[b]:.3f} s)" if b > a else f"{a} ({time[a]:.3f} s)"
             for a, b in zip(starts, ends)]
    return ", ".join(parts)


def _distance(a, b):
    return np.linalg.norm(a - b, axis=-1)


def side_swaps(points):
    """Frames in which a keypoint is exchanged with its other-side partner.

    Parameters
    ----------
    points : dict
        Role -> (F, 3) positions.

    Returns
    -------
    dict
        Side role without prefix (e.g. 'KNEE') -> (F,) mask of the frames in the minority
        labelling (the swapped frames), for the pairs with any.

    Notes
    -----
    Between two frames, the step as labelled is :math:`|R_f - R_{f-1}| + |L_f - L_{f-1}|`
    and the step with the sides exchanged :math:`|R_f - L_{f-1}| + |L_f - R_{f-1}|`; a
    step whose exchange is shorter than ``SWAP_RATIO`` times the labelled one is a
    change of labelling. Counting the changes from the first frame splits the trial into
    two labellings; the one that holds fewer frames is the swapped one.
    """
    found = {}
    for role in sorted({r[1:] for r in points if r[0] in "RL"}):
        right, left = points.get("R" + role), points.get("L" + role)
        if right is None or left is None or len(right) < 2:
            continue
        straight = _distance(right[1:], right[:-1]) + _distance(left[1:], left[:-1])
        crossed = _distance(right[1:], left[:-1]) + _distance(left[1:], right[:-1])
        with np.errstate(invalid="ignore"):
            change = crossed < SWAP_RATIO * straight
        state = np.r_[0, np.cumsum(change) % 2].astype(bool)
        seen = np.isfinite(right).all(axis=1) & np.isfinite(left).all(axis=1)
        swapped = state if np.count_nonzero(state & seen) <= np.count_nonzero(~state & seen) \
            else ~state
        swapped &= seen
        if swapped.any():
            found[role] = swapped
    return found


def jumps(points, scale):
    """Frames in which a keypoint leaves its path for at most ``JUMP_FRAMES`` frames.

    Judged where the 2 * JUMP_FRAMES + 1 frames around a frame all have the keypoint (not
    within JUMP_FRAMES of a gap or of the trial's ends).

    Parameters
    ----------
    points : dict
        Role -> (F, 3) positions.
    scale : float
        The trial's median thigh (or upper-arm) length, same units.

    Returns
    -------
    masks : dict
        Role -> (F,) mask, for the roles with any.
    threshold : dict
        Role -> the distance from the running median above which it was flagged.
    """
    roles = list(points)
    stacked = np.concatenate([points[role] for role in roles], axis=1)
    window = 2 * JUMP_FRAMES + 1
    # only a complete window is judged: beside a gap (or the trial's ends) a median of one
    # side's frames lags behind a moving keypoint (a walking foot by 13 cm at 50 Hz)
    median = pd.DataFrame(stacked).rolling(window, center=True, min_periods=window).median()
    off = np.linalg.norm((stacked - median.to_numpy()).reshape(len(stacked), -1, 3), axis=2)
    usual = np.zeros(len(roles))
    seen = np.isfinite(off).any(axis=0)            # a role absent from the trial: all NaN
    usual[seen] = np.nanmedian(off[:, seen], axis=0)
    limit = np.maximum(JUMP_SPREADS * np.nan_to_num(usual), JUMP_BONE_FRACTION * scale)
    with np.errstate(invalid="ignore"):
        flagged = off > limit
    masks = {role: flagged[:, k] for k, role in enumerate(roles) if flagged[:, k].any()}
    return masks, {role: float(limit[k]) for k, role in enumerate(roles)}


def bone_lengths(points):
    """(bone name, proximal role, distal role) -> (F,) lengths, for the bones present."""
    out = {}
    for p, side in (("R", "right"), ("L", "left")):
        for (a, b), name in BONES.items():
            if p + a in points and p + b in points:
                out[(f"{side} {name}", p + a, p + b)] = _distance(points[p + a], points[p + b])
    return out


def bone_outliers(lengths):
    """Frames in which a bone's length departs from its median beyond its spread.

    Parameters
    ----------
    lengths : dict
        As :func:`bone_lengths` returns.

    Returns
    -------
    dict
        Same keys -> (mask (F,), median, threshold), for the bones with any outlier.
    """
    found = {}
    for key, length in lengths.items():
        mask = np.zeros(length.shape, bool)
        for _ in range(BONE_PASSES):      # the outliers found leave the median and spread
            kept = length[~mask & np.isfinite(length)]
            if not kept.size:
                break
            median = np.median(kept)
            spread = 1.4826 * np.median(np.abs(kept - median))
            limit = max(BONE_SPREADS * spread, BONE_FRACTION * median)
            with np.errstate(invalid="ignore"):
                new = np.abs(length - median) > limit
            if np.array_equal(new, mask):
                break
            mask = new
        if mask.any():
            found[key] = (mask, float(median), float(limit))
    return found
