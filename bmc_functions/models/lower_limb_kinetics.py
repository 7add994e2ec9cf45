r"""Joint moments, forces and powers of the lower-limb model (ISB frames) from ground loads.

:meth:`LowerLimbModel.kinetics <bmc_functions.LowerLimbModel.kinetics>` calls
:func:`model_kinetics`: the trial's markers (and the ground loads) are low-pass
filtered, the segments tracked as for the angles, each ground load assigned to the foot
that stands on it, and Newton-Euler's equations
(:func:`~bmc_functions.inverse_dynamics`) solved from each foot up to the hip.

Signs (the distal segment's frame; x anterior, y superior, z to the right, for both sides;
:math:`M` the moment on the distal segment, :math:`s` = +1 right, -1 left). Every
component is positive in the sense *opposite* to the joint angle of the same plane, so
that the sagittal one reads as Plug-in Gait's X:

- ``moment_x`` = :math:`-M_z` (hip), :math:`+M_z` (knee), :math:`-M_z` (ankle): an
  internal hip extensor, knee extensor, ankle plantarflexor moment is positive;
- ``moment_y`` = :math:`-s M_x`: an internal hip and knee abductor, ankle evertor moment
  is positive;
- ``moment_z`` = :math:`-s M_y`: an internal external-rotator moment is positive;
- ``force_x`` = :math:`s F_z` (lateral positive), ``force_y`` = :math:`F_x` (anterior
  positive), ``force_z`` = :math:`F_y` (proximal positive): the force on the distal
  segment; a standing foot is pressed down by the shank, ``force_z < 0`` at the ankle;
- ``power`` = :math:`M \cdot (\omega_{distal} - \omega_{proximal})`: positive when
  the joint's muscles generate energy.

Moments in N m/kg, forces in N/kg, powers in W/kg (per kg of body mass).
"""

import re
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from .._checks import (ArgumentTypeError, check_one_or_per_frame, check_scalar,
                       check_vectors, runs_mask, warn, warn_frames)
from .._threads import blas_single_thread, one_blas_thread
from ..dynamics.newton_euler import STANDARD_GRAVITY, unchecked_inverse_dynamics
from ..dynamics.segment_parameters import (check_body_mass, principal_moments,
                                           segment_parameters)
from ..files.force_plates import plate_columns, read_force_plates
from ..files.opensim import read_mot
from ..files.trial import MarkerTable, load_trial, mm_per_unit
from ..markers.filtering import lowpass
from ..markers.roles import SIDE_PREFIX
from ..rigid_body.motion import (MAX_FRAME_ROTATION, angular_velocity, consecutive_turns,
                                 matrix_rows, unchecked_angular_velocity, warn_fast_turns)
from ..rigid_body.rotations import vector_length
from ..rigid_body.svdt import svdt
from .lower_limb_checks import deforming_frames

#: Default cut-off (Hz) of the low-pass filter applied to the markers and to the ground
#: loads alike: the same cut-off for both, as Kristianslund et al. (2012) found necessary
#: (a force filtered higher than the markers gives spurious knee moments peaks at
#: impact); 10 Hz keeps a running stance's shape. ``cutoff=None`` filters nothing.
DEFAULT_CUTOFF = 10.0

#: A ground force whose vertical component is below this (N) counts as no load.
LOAD_THRESHOLD = 20.0

#: A load is assigned to a foot whose heel-toe line passes within this horizontal
#: distance (mm) of its centre of pressure, on median over the loaded frames.
MAX_COP_DISTANCE_MM = 150.0

#: A foot counts as on the ground in a frame where its lowest marker is within this
#: height (mm) of the floor (the 2nd percentile of both feet's lowest markers) and the
#: heel-toe midpoint moves slower than MAX_CONTACT_SPEED (mm/s); such frames for at
#: least MIN_STANCE_S seconds make a stance.
CONTACT_HEIGHT_MM = 40.0
MAX_CONTACT_SPEED = 1500.0
MIN_STANCE_S = 0.05
#: Contact runs of one foot less than this apart (s) are one stance (a foot that rolls
#: over or flickers above the limits in mid-stance); a foot's swing is longer.
STANCE_GAP_S = 0.15

JOINTS = ("hip", "knee", "ankle")
#: The segments of each leg's chain, distal first (as inverse_dynamics takes them).
SEGMENTS = ("foot", "shank", "thigh")
QUANTITIES = ("moment_x", "moment_y", "moment_z", "force_x", "force_y", "force_z", "power")
_FORCE = re.compile(r"^(.*)ground_force_v([xyz])$")


def _column_index():
    """(joint, side, quantity) in the order of JOINTS, sides, QUANTITIES, with levels in
    that order so that the columns are lexsorted (selecting one joint needs no sort)."""
    levels = [list(JOINTS), ["right", "left"], list(QUANTITIES)]
    codes = np.indices([len(level) for level in levels]).reshape(3, -1)
    return pd.MultiIndex(levels=levels, codes=codes, names=["joint", "side", "quantity"])


def _read_forces(forces):
    """The external-loads table: a DataFrame indexed by time (s)."""
    if isinstance(forces, (str, Path)):
        suffix = Path(forces).suffix.lower()
        if suffix == ".c3d":
            return plate_loads_table(read_force_plates(forces))
        if suffix not in (".mot", ".sto"):
            raise ValueError(f"forces must be an OpenSim external-loads .mot/.sto file or "
                             f"a DataFrame; got a {suffix or 'suffix-less'} path {forces!r}")
        return read_mot(forces)
    if not isinstance(forces, pd.DataFrame):
        raise ValueError(f"forces must be an OpenSim external-loads .mot path or a "
                         f"DataFrame; got {type(forces).__name__}")
    return forces


def plate_loads_table(plates):
    """Force plates as an external-loads table: OpenSim's columns, in N, m and N m.

    Parameters
    ----------
    plates : pandas.DataFrame
        What :func:`~bmc_functions.read_force_plates` returns (mm, N, N mm, lab frame).

    Returns
    -------
    pandas.DataFrame
        The same time index; per plate ``<n>_ground_force_v[xyz]`` (N),
        ``<n>_ground_force_p[xyz]`` (m) and ``<n>_ground_torque_[xyz]`` (N m). Where the
        centre of pressure is undefined (a load under the reader's threshold), the point
        is the plate's centre and the torque the moment about it: the same load about the
        lab's origin, defined under any load.

    Raises
    ------
    TypeError
        If `plates` is not a DataFrame with the reader's ``attrs['plates']``.
    ValueError
        If a plate lacks a force, centre-of-pressure, free-moment or moment column
        (named).
    """
    if not isinstance(plates, pd.DataFrame) or "plates" not in plates.attrs:
        raise ArgumentTypeError(f"plates must be the DataFrame read_force_plates returns; "
                                f"got {type(plates).__name__}")
    columns, values = {}, plates.to_numpy(dtype=float)
    for number, setup in zip(plates.columns.unique(0), plates.attrs["plates"]):
        kinds = ("force", "cop", "free_moment", "moment")
        column = plate_columns(plates, number, kinds)        # a ValueError naming a gap
        force, cop, free, moment = (values[:, column[kind]] for kind in kinds)
        undefined = np.isnan(cop).any(axis=1, keepdims=True)
        centre = np.asarray(setup["corners"], dtype=float).mean(axis=0)
        point = np.where(undefined, centre, cop) / 1000.0
        torque = np.where(undefined, moment, free) / 1000.0
        for k, axis in enumerate("xyz"):
            columns[f"{number}_ground_force_v{axis}"] = force[:, k]
            columns[f"{number}_ground_force_p{axis}"] = point[:, k]
            columns[f"{number}_ground_torque_{axis}"] = torque[:, k]
    return pd.DataFrame(columns, index=plates.index)


def _load_groups(table):
    """Prefix -> (force, cop, free moment) arrays (samples, 3) of every load in `table`."""
    groups = {}
    for column in table.columns:
        match = _FORCE.match(str(column))
        if match:
            groups.setdefault(match.group(1), set()).add(match.group(2))
    loads = {}
    for prefix, axes in groups.items():
        names = [[f"{prefix}ground_force_{kind}{a}" for a in "xyz"] for kind in "vp"]
        names.append([f"{prefix}ground_torque_{a}" for a in "xyz"])
        missing = [n for block in names[:2] for n in block if n not in table.columns]
        if missing:
            raise ValueError(f"forces: the load {prefix or '(no prefix)'!r} lacks "
                             f"{', '.join(missing)}")
        arrays = [table[block].to_numpy(dtype=float) if block[0] in table.columns
                  else np.zeros((len(table), 3)) for block in names]
        loads[prefix] = arrays
    if not loads:
        raise ValueError(f"forces has no ground_force_v[xyz] columns (OpenSim external "
                         f"loads: [prefix]ground_force_vx, ..._px, ground_torque_x); got "
                         f"{list(table.columns)[:6]}")
    return loads


def _force_rate(time):
    step = np.diff(time)
    low = step.min() if len(step) else np.nan         # NaN time: NaN, refused as well
    median = np.median(step) if low > 0 else np.nan   # found once, used twice
    if not median > 0 or step.max() - low > 0.01 * median:    # numpy.ptp's max - min
        raise ValueError("forces must be sampled at a regular rate, its time increasing")
    return 1.0 / median


def _resampler(time, times):
    """A function ``(values, scale=1.0) -> resampled``: linear interpolation of (samples,
    k) `values` (times `scale`) at `times`; NaN outside: numpy.interp's formula,
    :math:`v_j + (v_{j+1} - v_j) / (t_{j+1} - t_j) (t - t_j)`, for every column at once
    (`time` increasing, 2 samples or more). Where each time falls is found once for all
    the signals resampled; the samples used are scaled, not the whole record (the same
    numbers)."""
    j = np.clip(np.searchsorted(time, times, side="right") - 1, 0, len(time) - 2)
    step, offset = time[j + 1] - time[j], times - time[j]
    last, outside = times == time[-1], (times < time[0]) | (times > time[-1])
    pairs = np.c_[j, j + 1]           # each pair of neighbours read together: one pass

    def resample(values, scale=1.0):
        rows = values.T               # (k, samples): each column's samples gathered at once
        gathered = rows[:, pairs]
        gathered *= scale
        low, high = gathered[..., 0], gathered[..., 1]
        result = high - low           # the formula in place: one temporary, not four
        result /= step
        result *= offset
        result += low
        result = result.T
        result[last] = values[-1] * scale
        result[outside] = np.nan
        return result
    return resample


def _run_edges(mask):
    """The starts and stops (arrays) of the runs of True in a boolean vector."""
    edges = np.diff(np.r_[0, mask.astype(np.int8), 0])
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)


def _runs(mask):
    """(start, stop) index pairs of the runs of True in a boolean vector."""
    return list(zip(*_run_edges(mask)))


def _distance_to_segment(point, a, b):
    """Distance (frames,) from points to the segments a-b, all (frames, 2)."""
    ab = b - a
    u = np.einsum("fi,fi->f", point - a, ab) / np.einsum("fi,fi->f", ab, ab)
    np.clip(u, 0, 1, out=u)
    offset = point - (a + u[:, None] * ab)
    offset *= offset           # numpy.linalg.norm's sum of squares, without its copies
    return np.sqrt(offset[:, 0] + offset[:, 1])                       # 2D points


def _feet(kin, model):
    """Side -> (heel, toe) in every frame, mm."""
    feet = {}
    for side in model.sides:
        foot = kin.landmarks.get(("foot", side))
        if foot is not None:
            p = SIDE_PREFIX[side]
            feet[side] = (foot[p + "HEEL"], foot[p + "TOE"])
    return feet


def _assign(loads, time, times, resample, feet, up, threshold):
    """Each loaded interval of each load -> the foot that stands on it (or None);
    `resample` from :func:`_resampler`."""
    horizontal = np.linalg.svd(np.eye(3) - np.outer(up, up))[0][:, :2]    # 2 axes
    lines = {side: (heel @ horizontal, toe @ horizontal)    # the same for every load
             for side, (heel, toe) in feet.items()}
    assignment = []
    for prefix, (force, cop, _) in loads.items():
        runs = np.c_[_run_edges(_loaded(force @ up, threshold))]
        spans = np.c_[np.searchsorted(times, time[runs[:, 0]], side="left"),
                      np.searchsorted(times, time[runs[:, 1] - 1], side="right")]
        keep = spans[:, 1] > spans[:, 0]            # not between two marker frames
        runs, spans = runs[keep], spans[keep]
        point = resample(cop, 1000.0) @ horizontal                    # mm, marker frames
        distances = {side: _span_medians(_distance_to_segment(point, *line), spans)
                     for side, line in lines.items()}
        # Python floats read once (tolist), not one NumPy scalar per run and side
        distances = {side: d.tolist() for side, d in distances.items()}
        starts, ends = time[runs[:, 0]].tolist(), time[runs[:, 1] - 1].tolist()
        for k, (start, end) in enumerate(zip(starts, ends)):
            near = [side for side, d in distances.items() if d[k] <= MAX_COP_DISTANCE_MM]
            assignment.append({"load": prefix, "start": start, "end": end,
                               "side": near[0] if len(near) == 1 else None,
                               "distance_mm": {side: round(d[k], 1)
                                               for side, d in distances.items()}})
    _warn_assignment(assignment)
    return assignment


def _loaded(vertical, threshold):
    """Whether each vertical force exceeds `threshold` (finite), a NaN one counted as 0:
    ``numpy.nan_to_num(vertical) > threshold``, whose infinities become the largest
    floats, on the same side of the threshold. The comparison alone (NaN is never above
    it), without that pass, which replaces the NaN first."""
    loaded = vertical > threshold
    if threshold < 0:                               # then a NaN, as 0, is above it
        loaded |= np.isnan(vertical)
    return loaded


def _median(values):
    """The median of the values that are not NaN (NaN if none)."""
    values = values[~np.isnan(values)]
    return float(np.median(values)) if values.size else np.nan


def _span_medians(values, spans):
    """The median of `values` (NaN ignored) over each [start, stop) of `spans`, at once."""
    if not len(spans):
        return np.zeros(0)
    length = spans[:, 1] - spans[:, 0]
    if length.max() <= 0:                           # only empty spans: no value
        return np.full(len(spans), np.nan)
    if len(spans) * length.max() > 10_000_000:     # one long span among many: one by one
        return np.array([_median(values[a:b]) for a, b in spans])
    offsets = np.arange(length.max())
    index = spans[:, :1] + offsets
    inside = offsets < length[:, None]
    table = np.where(inside, values[np.minimum(index, len(values) - 1)], np.nan)
    # numpy.nanmedian's numbers (the mean of the two middle values, or the middle one
    # twice, of the values not NaN) from one sort per table, without its masked
    # arrays: NaN sorts last. A span without a value: NaN.
    ordered = np.sort(table, axis=1)
    counts = (~np.isnan(table)).sum(axis=1, keepdims=True)
    high = counts // 2
    low = np.maximum(np.where(counts % 2 == 1, high, high - 1), 0)
    middle = np.take_along_axis(ordered, low, 1) + np.take_along_axis(ordered, high, 1)
    return np.where(counts[:, 0] > 0, middle[:, 0] / 2.0, np.nan)


def _warn_assignment(assignment):
    problems = []
    claims = {prefix: _claimed_side(prefix)          # each prefix read once
              for prefix in {item["load"] for item in assignment}}
    for item in assignment:
        claimed = claims[item["load"]]
        if item["side"] is not None and not (claimed and claimed != item["side"]):
            continue                                  # no problem: nothing to write
        name = item["load"] or "(no prefix)"
        span = f"{item['start']:.3f}-{item['end']:.3f} s"
        if item["side"] is None:
            problems.append(f"{name!r} at {span} stands under no foot alone (distance of "
                            f"its centre of pressure to each heel-toe line: "
                            f"{item['distance_mm']} mm; limit {MAX_COP_DISTANCE_MM:g}): "
                            f"not used")
        else:
            problems.append(f"{name!r} at {span} is under the {item['side']} foot, not "
                            f"the {claimed} one its prefix says: applied to the "
                            f"{item['side']} foot")
    if problems:
        warn("ground loads: " + "; ".join(problems), RuntimeWarning)


def _claimed_side(prefix):
    """The side a load's prefix names ('R_', 'right_', 'l_', ...), or None ('', '1_')."""
    text = prefix.lower().rstrip("_ ")
    return {"r": "right", "right": "right", "l": "left", "left": "left"}.get(text)


#: Samples per block in which :func:`_assigned_wrenches` adds the loads (a block's arrays
#: fit in the cache).
_WRENCH_BLOCK = 16384


def _assigned_wrenches(loads, assignment, time, sides):
    """(6 per side, samples): each side's force (N) and moment about the lab origin (N m)
    of the loads assigned to it, summed in order, over the samples of their assigned
    spans; zero elsewhere. One row per component, its samples contiguous (the layout
    the filter runs along)."""
    both = np.zeros((6 * len(sides), len(time)))
    # A block of samples at a time, its moment in a workspace that stays in the cache:
    # the same operations, each sample's, but the record's arrays read once, not once per
    # step of the moment and per component added (these passes are memory-bound).
    work = np.empty((4, min(_WRENCH_BLOCK, len(time))))
    for prefix, (force, cop, free) in loads.items():
        masks = {}
        for k, side in enumerate(sides):
            spans = [(item["start"], item["end"]) for item in assignment
                     if item["load"] == prefix and item["side"] == side]
            if spans:
                masks[k] = _span_mask(time, *np.array(spans).T)
        for start in range(0, len(time), _WRENCH_BLOCK) if masks else ():
            block = slice(start, start + _WRENCH_BLOCK)
            q, f, torque = cop[block].T, force[block].T, free[block].T
            moment, product = work[:3, :q.shape[1]], work[3, :q.shape[1]]
            for m, (i, j) in enumerate(((1, 2), (2, 0), (0, 1))):    # q x F + T
                np.multiply(q[i], f[j], out=moment[m])
                np.multiply(q[j], f[i], out=product)
                moment[m] -= product
                moment[m] += torque[m]
            for k, inside in masks.items():
                for row, component in zip(both[6 * k:6 * k + 6, block], (*f, *moment)):
                    np.add(row, component, out=row, where=inside[block])   # 0 outside
    return both


def _span_mask(time, starts, ends):
    """Whether each sample of `time` lies in one of the spans [start, end] (times, any
    order, overlapping or not)."""
    return runs_mask(len(time), np.searchsorted(time, starts),
                     np.searchsorted(time, ends, side="right"))


def _external_wrenches(forces, times, feet, up, cutoff, threshold):
    """Side -> (force (N), moment about the lab origin (N m)) at the marker `times`, and
    the assignment. The one place that reads ground loads: a .mot/.sto path or a
    DataFrame, or a C3D file's force plates (plate_loads_table).

    The load is carried as a wrench about the lab origin, force :math:`F` and moment
    :math:`q \\times F + T`: filtering it is filtering the physical load, with no centre
    of pressure to divide out near zero force.
    """
    table = _read_forces(forces)
    time = np.asarray(table.index, dtype=float)
    rate = _force_rate(time)
    loads = _load_groups(table)
    resample = _resampler(time, times)
    assignment = _assign(loads, time, times, resample, feet, up, threshold)
    sides = list(feet)                       # both sides' wrenches side by side
    both = _assigned_wrenches(loads, assignment, time, sides).T    # (samples, 6 per side)
    covered = (times >= time[0]) & (times <= time[-1])
    if cutoff is not None and both.size:     # then filter and resample both sides at once
        both = lowpass(both, cutoff, rate=rate)
    # beyond the record: no load here (a stance there is NaN, see _unmeasured); a NaN
    # sample of a loaded interval stays NaN (missing data, per frame)
    both = np.where(covered[:, None], resample(both), 0.0)
    wrenches = {side: (both[:, 6 * k:6 * k + 3], both[:, 6 * k + 3:6 * k + 6])
                for k, side in enumerate(sides)}
    return wrenches, assignment, covered


def _floor(heights):
    """The floor's height (mm): the 2nd percentile of the lowest foot marker, both feet
    (`heights`: side -> the height of its foot's lowest marker, per frame)."""
    heights = list(heights.values())
    return np.nanpercentile(np.concatenate(heights), 2) if heights else np.nan


def _stances(height, heel, toe, rate, floor):
    """Runs (start, stop) of frames in which a foot is on the ground (see CONTACT_*);
    `height`: its lowest marker's, per frame."""
    middle = (heel + toe) / 2
    speed = vector_length(np.gradient(middle, 1 / rate, axis=0))
    with np.errstate(invalid="ignore"):
        low = height <= floor + CONTACT_HEIGHT_MM
        contact = low & (speed <= MAX_CONTACT_SPEED)
    starts, stops = _run_edges(contact)
    if not starts.size:
        return []
    # one stance, even if it flickers: a run begins one only after a gap of STANCE_GAP_S,
    # and the stance ends with the run before the next one that does
    first = np.r_[True, (starts[1:] - stops[:-1]) / rate >= STANCE_GAP_S]
    starts, stops = starts[first], stops[np.r_[first[1:], True]]
    keep = (stops - starts) / rate >= MIN_STANCE_S
    return list(zip(starts[keep].tolist(), stops[keep].tolist()))


def _unmeasured(stances, force, up, times, covered):
    """Frames (boolean) of the stances with no measured load (or beyond the loads'
    record), and their descriptions."""
    frames, named = np.zeros(len(times), bool), []
    if not stances:
        return frames, named
    start, stop = np.array(stances).T          # loaded and uncovered frames per stance,
    loaded = np.r_[0, np.cumsum(np.abs(force @ up) > LOAD_THRESHOLD)]     # from sums
    outside = np.r_[0, np.cumsum(~covered)]
    unloaded = (loaded[stop] - loaded[start]) / (stop - start) < 0.5
    partly = ~unloaded & (outside[stop] > outside[start])
    reported = unloaded | partly                  # a loop over these stances only
    for a, b, none in zip(start[reported], stop[reported], unloaded[reported]):
        if none:
            frames[a:b] = True
            named.append(f"{times[a]:.3f}-{times[b - 1]:.3f} s")
        else:                                     # partly beyond the loads' record
            beyond = np.arange(a, b)[~covered[a:b]]
            frames[beyond] = True
            named.append(f"{times[beyond[0]]:.3f}-{times[beyond[-1]]:.3f} s (beyond the "
                         f"record of the loads)")
    return frames, named


#: Sign of each local component (x, y, z of the distal frame) in moment_x, _y, _z, for
#: the hip, knee and ankle of the right side (the left side: y and z components negated);
#: see the module's docstring.
_MOMENT_AXES = (2, 0, 1)
_MOMENT_SIGNS = {"hip": (-1.0, -1.0, -1.0), "knee": (1.0, -1.0, -1.0),
                 "ankle": (-1.0, -1.0, -1.0)}


def _metres(first, second=None):
    """`first` / 1000 or the midpoint (`first` + `second`) / 2000 of points in mm: in m,
    column-major from the start (each coordinate's frames contiguous, the layout in which
    Newton-Euler computes; what is made from them, centres of mass and their derivatives,
    keeps it), without a copy into that layout."""
    out = np.empty(first.shape, order="F")
    # column by column (each written contiguously): twice as fast as one pass that reads
    # the points row by row and writes the columns strided; the same operations
    for k in range(first.shape[1]):
        column = out[:, k]
        if second is None:
            np.divide(first[:, k], 1000.0, out=column)
        else:
            np.divide(np.add(first[:, k], second[:, k], out=column), 2000.0, out=column)
    return out


def _chain(kin, side, rows, flagged):
    """Foot, shank, thigh: rotation matrices as (9, frames) rows (`rows`: segment -> the
    tracked frames' matrix_rows, made NaN in the `flagged` frames in place), proximal and
    distal ends (m); NaN in the `flagged` frames."""
    p = SIDE_PREFIX[side]
    shank = kin.landmarks[("shank", side)]
    hip = _metres(kin.landmarks[("thigh", side)][p + "HJC"])
    knee = _metres(shank[p + "KNEE_LAT"], shank[p + "KNEE_MED"])
    ankle = _metres(shank[p + "ANKLE_LAT"], shank[p + "ANKLE_MED"])
    toe = _metres(kin.landmarks[("foot", side)][p + "TOE"])
    R = [rows[segment] for segment in SEGMENTS]
    if flagged.any():                       # _legs' rows, these points: NaN in place
        for array in R:
            array[:, flagged] = np.nan
        for point in (ankle, knee, hip, toe):
            point[flagged] = np.nan
    return R, [ankle, knee, hip], [toe, ankle, knee]


def _flagged(model, kin):
    """Frames whose pelvis tilt, and whose leg angles of each side, the tracking leaves
    NaN (a gap, or labels it rejected): (pelvis, side -> frames), both from one look at
    each segment's frames (the pelvis's serves them all)."""
    names = (("hip", "flexion"), ("knee", "flexion"), ("ankle", "dorsiflexion"))
    gaps = model._angle_gaps(kin, [("pelvis", model.sides[0], "tilt")]  # any side
                             + [(j, side, a) for side in model.sides for j, a in names])
    return gaps[:, 0], {side: gaps[:, 1 + 3 * k:4 + 3 * k].any(axis=1)
                        for k, side in enumerate(model.sides)}


def _turning(rows, rejected):
    """Frames on either side of a pair of consecutive frames in which the foot, shank or
    thigh (`rows`: segment -> its tracked frames' matrix_rows) turns by more than
    MAX_FRAME_ROTATION (30 degrees): a rotation no difference can follow
    (:func:`~bmc_functions.angular_velocity`), a label swap in a real trial. The frames
    `rejected` already are left out."""
    flagged = np.zeros(len(rejected), dtype=bool)
    kept = ~rejected[1:] & ~rejected[:-1]                # pairs of frames not rejected
    for segment in SEGMENTS:
        turn = consecutive_turns(rows[segment])
        with np.errstate(invalid="ignore"):
            fast = kept & (turn > MAX_FRAME_ROTATION)    # NaN next to a gap: not fast
        flagged[1:] |= fast
        flagged[:-1] |= fast
    return flagged


def _side_kinetics(kin, side, rows, wrench, flagged, out, body_mass, table, rate, gravity,
                   base_omega):
    """(joints, quantities, frames): hip, knee, ankle x QUANTITIES of one side, per kg,
    written into `out`; NaN in the `flagged` frames. `rows`: segment -> its tracked
    frames' matrix_rows, which are made NaN in the `flagged` frames in place (the
    caller's turn check has read them already)."""
    R, proximal, distal = _chain(kin, side, rows, flagged)
    masses, coms, inertias = [], [], []
    for segment, start, end in zip(SEGMENTS, proximal, distal):
        mass, com, moments = principal_moments(start, end, body_mass, segment,
                                               parameters=table)
        masses.append(mass)
        coms.append(com)
        inertias.append(moments)
    # tracked frames (rotations; _legs has made NaN those that turn too fast), masses and
    # the principal moments of segment_inertia's diagonal tensors, positions in m:
    # nothing inverse_dynamics checks
    loads = unchecked_inverse_dynamics(R, coms, proximal, masses, inertias, rate, *wrench,
                                       gravity, base_omega)
    sign = 1.0 if side == "right" else -1.0
    # (x s) / body_mass as x / (s body_mass) in one pass: the same value bit for bit, as
    # s is +1 or -1 (a sign change is exact, and rounding is symmetric about zero)
    for k, joint in zip((2, 1, 0), JOINTS):                  # thigh, shank, foot
        rows = out[JOINTS.index(joint)]                      # one row per quantity
        signs = np.multiply(_MOMENT_SIGNS[joint], (1.0, sign, sign))
        for q, (axis, s) in enumerate(zip(_MOMENT_AXES, signs)):
            np.divide(loads.moment_local[k][:, axis], s * body_mass, out=rows[q])
        for q, (axis, s) in enumerate(zip((2, 0, 1), (sign, 1.0, 1.0)), start=3):
            np.divide(loads.force_local[k][:, axis], s * body_mass, out=rows[q])
        np.divide(loads.power[k], body_mass, out=rows[6])
    return out


def _filtered_markers(df, cutoff):
    if cutoff is None:
        return df
    cutoff = check_scalar(cutoff, "cutoff", "a cut-off frequency in Hz, > 0", minimum=0,
                          strict=True)
    return lowpass(df, cutoff)


def _raw_rmse(model, table, scale, frames=None):
    """Each cluster's svdt RMSE (mm) in the unfiltered markers (a MarkerTable, its
    `scale` to mm), where filtering has not smeared a swapped frame over its neighbours;
    only in `frames` (cluster -> frames (bool), NaN elsewhere) if given."""
    rmse = {}
    for cluster, info in model.clusters.items():
        if frames is not None and cluster not in frames:
            continue
        if all(label in table.columns for label in info["labels"]):
            rows = (np.ones(len(table.values), bool) if frames is None
                    else frames[cluster])
            rmse[cluster] = np.full(len(table.values), np.nan)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)    # the tracking says it
                if rows.any():
                    points = _stacked_rows(table, info["labels"], scale, rows)
                    rmse[cluster][rows] = svdt(info["local"], points, order="row")[2]
    return pd.DataFrame(rmse, index=pd.RangeIndex(len(table.values)), dtype=float)


def _stacked_rows(table, labels, scale, rows):
    """``table.stacked(labels, scale)[rows]`` (`rows`: frames, bool), its values and its
    memory layout (which sets the order of svdt's sums over a frame's markers), from
    the coordinates of those frames only: not every frame stacked first and the rows
    copied out of it (the candidates are a few of the frames)."""
    values = table.values
    if rows.all() or not values.flags.f_contiguous or values.flags.c_contiguous:
        return table.stacked(labels, scale)[rows]
    # a column-major table: stacked's x, y and z planes, whose rows the boolean index
    # copies keeping that order, each frame's x of every label, then y, then z
    columns = [table.columns[label][axis] for axis in "xyz" for label in labels]
    points = values[np.flatnonzero(rows)[:, None], columns]        # (frames, 3 n)
    if scale != 1.0:
        points *= scale                          # as stacked: each coordinate times scale
    return points.reshape(len(points), 3, len(labels)).transpose(0, 2, 1)


def _sudden(high, rmse, threshold):
    """The runs of `high` frames entered or left by a jump of the RMSE of more than half
    `threshold` in one frame (a marker swapped or lost), not a slow deformation (the
    soft tissue's, which the angles only warn about)."""
    runs = np.array(_runs(high), dtype=int).reshape(-1, 2)
    before = np.r_[np.nan, rmse][runs[:, 0]]              # the frame before each run
    after = np.r_[rmse, np.nan][runs[:, 1]]               # and after it
    with np.errstate(invalid="ignore"):
        jump = ((rmse[runs[:, 0]] - before > threshold / 2)
                | (rmse[runs[:, 1] - 1] - after > threshold / 2))
    return runs_mask(len(rmse), runs[jump, 0], runs[jump, 1])


def _poses(model, df):
    """``model.track(df)`` but its angles, which the kinetics does not use (only where
    they are NaN: ``model._angle_gaps``)."""
    df, trial_name = load_trial(df, "dynamic")
    with blas_single_thread():  # see bmc_functions._threads
        return model._poses(df, trial_name)


def _rigid_bound(model, raw, smooth, scale, kin):
    """An upper bound of each cluster's :func:`_raw_rmse` (mm), from the fit of its
    filtered markers: svdt makes the RMSE the least over every pose, and about the pose
    fitted to the filtered markers the RMSE of the unfiltered ones is at most that fit's
    RMSE plus the RMS distance from the unfiltered to the filtered markers (Minkowski's
    inequality). NaN where fewer than 3 of its markers are seen (no fit, no RMSE);
    infinite where they are but the filtered fit is missing (no bound). `raw` and
    `smooth`: MarkerTables of the unfiltered and filtered markers, `scale` to mm."""
    bound = {}
    for cluster, info in model.clusters.items():
        if all(label in raw.columns for label in info["labels"]):
            # Summed label by label, seen ones only, in place (an unseen one adds nothing:
            # the sums of the squares seen, the same numbers as adding zeros for it).
            total, count = np.zeros(len(raw.values)), np.zeros(len(raw.values), int)
            for label in info["labels"]:
                squares = _squared_distance(raw, smooth, label, scale)   # NaN: not seen
                seen = ~np.isnan(squares)
                np.add(total, squares, out=total, where=seen)
                count += seen
            fit = (kin.rmse[cluster].to_numpy() if cluster in kin.rmse
                   else np.full(len(count), np.nan))
            with np.errstate(invalid="ignore", divide="ignore"):
                values = fit + np.sqrt(total / (3.0 * count))
            values[np.isnan(values)] = np.inf                 # seen, but no fit
            values[count < 3] = np.nan
            bound[cluster] = values
    return pd.DataFrame(bound, dtype=float)


def _squared_distance(raw, smooth, label, scale):
    """Per frame, the squared distance (mm²) between a label's points in two MarkerTables,
    from their coordinate columns in place (no copy of the points): the sum of the
    squared differences of x, y and z, in that order (as numpy.sum adds three terms)."""
    first, second = raw.columns[label], smooth.columns[label]
    total = None
    for axis in "xyz":
        a, b = raw.values[:, first[axis]], smooth.values[:, second[axis]]
        if scale != 1.0:            # times 1.0 is the same number: skipped in mm
            a, b = a * scale, b * scale
        square = a - b
        square *= square                              # in place, as every step here
        if total is None:
            total = square                            # (0 plus the first square)
        else:
            total += square
    return total


def _candidates(model, raw, smooth, scale, kin):
    """Cluster -> the frames (bool) in which it may deform beyond its threshold
    (deforming_frames) in the unfiltered markers, and the frames next to them (the jump
    test of :func:`_sudden` reads them): those where its :func:`_rigid_bound` is not
    below the threshold (by a margin of 1e-6 for rounding). Elsewhere its svdt RMSE is
    below the threshold too, and :func:`_raw_rmse` need not fit them. Clusters without
    such frames are left out."""
    bound = _rigid_bound(model, raw, smooth, scale, kin) * (1 + 1e-6)
    candidates = {}
    for cluster, (high, _) in deforming_frames(model, bound).items():
        if high.any():
            candidates[cluster] = high | np.r_[high[1:], False] | np.r_[False, high[:-1]]
    return candidates


def _tracked(model, df, cutoff, trial_name):
    """The trial tracked from its filtered markers. A cluster that deforms suddenly (its
    RMSE above the tracking's threshold, entered or left by a jump: a marker swapped,
    mislabelled or lost, as in the unfiltered markers) has its markers taken as missing
    in those frames before filtering, so that no segment frame, and no kinetics, is made
    from them (the angles only warn). The unfiltered markers are fitted (svdt) only in
    the frames where the filtered fit does not already show the cluster rigid enough in
    them (:func:`_candidates`), and in every frame for the warning when one deforms."""
    if not model.clusters:
        return _poses(model, _filtered_markers(df, cutoff))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        filtered = _filtered_markers(df, cutoff)
        kin = _poses(model, filtered)
    scale, _ = mm_per_unit(df, trial_name)
    raw = MarkerTable(df, trial_name)
    candidates = _candidates(model, raw, kin.table, scale, kin)       # filtered markers
    deforming = {}
    if candidates:                        # the raw fit in those frames only
        rmse = _raw_rmse(model, raw, scale, candidates)
        for cluster, (high, threshold) in deforming_frames(model, rmse).items():
            frames = _sudden(high, rmse[cluster].to_numpy(), threshold)
            if frames.any():
                deforming[cluster] = frames
    if deforming:
        cleaned = df.copy()
        for cluster, frames in deforming.items():
            for label in model.clusters[cluster]["labels"]:
                cleaned.loc[frames, label] = np.nan
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            kin = _poses(model, _filtered_markers(cleaned, cutoff))
    _rewarn(model, caught, deforming)
    if not deforming:
        return kin
    largest = np.nanmax(_raw_rmse(model, raw, scale).to_numpy())       # of every frame
    which = ", ".join(f"{cluster} ({', '.join(model.clusters[cluster]['labels'])}) in "
                      f"{int(frames.sum())} of {len(frames)} frames"
                      for cluster, frames in deforming.items())
    warn(f"{trial_name}, kinetics: the markers of {which} are taken as missing: the "
         f"cluster deforms there by a jump (svdt RMSE up to {largest:.1f}"
         f" mm), a marker swapped, mislabelled or lost; the segments they make, and the "
         f"moments, forces and powers that use them, are NaN there", RuntimeWarning)
    return kin


def _rewarn(model, caught, deforming):
    """The tracking's warnings, each once, but those about the gaps made here (said by
    the caller)."""
    made = [*deforming, *(label for cluster in deforming
                          for label in model.clusters[cluster]["labels"])]
    for message, category in dict.fromkeys((str(w.message), w.category) for w in caught):
        if not (deforming and ("too short for the filter" in message
                               or any(name in message for name in made))):
            warn(message, category)


def _pelvis_omega(R, gaps, rate):
    """The pelvis's angular velocity (lab, rad/s), NaN in the `gaps` frames, and the
    warning of :func:`~bmc_functions.angular_velocity`; without its checks (rotations
    by construction of the pelvis frame, a rate model_kinetics has checked) once the trial has the 2 frames it needs
    (else its error)."""
    if len(R) < 2:
        return angular_velocity(np.where(gaps[:, None, None], np.nan, R), rate)
    rows = matrix_rows(R)                   # a new array: its gaps made NaN in place
    rows[:, gaps] = np.nan
    warn_fast_turns(consecutive_turns(rows))
    return unchecked_angular_velocity(rows, rate)


def _legs(model, kin, feet, wrenches, covered, times, up, flagged, constants):
    """(joints, sides, quantities, frames) of both legs (each column's frames contiguous,
    as the DataFrame stores them), and the unmeasured stances; `flagged`: side -> the
    frames _flagged rejects; `constants` are _side_kinetics' body_mass, table, rate,
    gravity, base_omega."""
    values = np.full((len(JOINTS), 2, len(QUANTITIES), len(times)), np.nan)
    missing, turning = [], np.zeros(len(times), dtype=bool)
    heights = {side: np.fmin(heel @ up, toe @ up) for side, (heel, toe) in feet.items()}
    floor = _floor(heights)                               # the same for both sides
    for k, side in enumerate(("right", "left")):
        if side not in feet:
            continue
        force, moment = wrenches[side]
        frames, named = _unmeasured(_stances(heights[side], *feet[side], constants[2], floor),
                                    force, up, times, covered)
        if frames.any():                 # else the load as it is (no copy)
            force = np.where(frames[:, None], np.nan, force)
        rejected = flagged[side]
        rows = {segment: matrix_rows(kin.frames[(segment, side)][0]) for segment in SEGMENTS}
        turned = _turning(rows, rejected) & ~rejected
        turning |= turned
        _side_kinetics(kin, side, rows, (force, moment), rejected | turned, values[:, k],
                       *constants)
        missing += [f"{side} {span}" for span in named]
        del rows, force     # freed before the next side makes its own (reused memory)
    return values, missing, turning


@one_blas_thread   # as track and angles: see bmc_functions._threads
def model_kinetics(model, dynamic, forces, *, body_mass, cutoff=DEFAULT_CUTOFF,
                   force_cutoff="cutoff", parameters=None, gravity=None):
    """Hip, knee and ankle moments, forces and powers: see :meth:`LowerLimbModel.kinetics`."""
    body_mass = check_body_mass(body_mass)
    if isinstance(force_cutoff, str) and force_cutoff == "cutoff":
        force_cutoff = cutoff
    elif force_cutoff is not None:
        force_cutoff = check_scalar(force_cutoff, "force_cutoff", "a cut-off frequency in "
                                    "Hz, > 0, 'cutoff' or None", minimum=0, strict=True)
    table = segment_parameters(parameters)
    df, trial_name = load_trial(dynamic, "dynamic")
    rate = float(df.attrs.get("rate", np.nan))
    if not np.isfinite(rate) or rate <= 0:
        raise ValueError(f"{trial_name} has no sampling rate (attrs['rate']); kinetics "
                         f"needs it to differentiate")
    kin = _tracked(model, df, cutoff, trial_name)
    up = kin.lab_frame[:, 1]
    gravity = -STANDARD_GRAVITY * up if gravity is None else gravity
    index = np.asarray(df.index, dtype=float)
    times = index[0] + np.arange(len(index)) / rate
    if np.abs(times - index).max() > 0.5 / rate:       # an irregular index: keep it
        times = index
    feet = _feet(kin, model)
    wrenches, assignment, covered = _external_wrenches(forces, times, feet, up,
                                                       force_cutoff, LOAD_THRESHOLD)
    gaps, flagged = _flagged(model, kin)
    gravity = check_one_or_per_frame(check_vectors(gravity, "gravity", allow_nan=False),
                                     "gravity", len(times))        # as inverse_dynamics
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        base_omega = _pelvis_omega(kin.frames[("pelvis", None)][0], gaps, rate)
        values, missing, turning = _legs(model, kin, feet, wrenches, covered, times, up,
                                         flagged, (body_mass, table, rate, gravity, base_omega))
    for message, category in dict.fromkeys((str(w.message), w.category) for w in caught):
        warn(f"{trial_name}, kinetics: {message}", category)          # each once
    warn_frames(int(turning.sum()), len(times),
                f"of {trial_name} are next to a turn of a leg segment by more than "
                f"{np.degrees(MAX_FRAME_ROTATION):.0f} degrees from one frame to the next "
                f"(a label swap, or a rate too low for the motion): that leg's moments, "
                f"forces and powers are NaN there")
    if missing:
        warn(f"{trial_name}: no ground load measured in the stance(s) {', '.join(missing)} "
             f"(the foot is on the ground, no load is assigned to it): that side's "
             f"moments, forces and powers are NaN there", RuntimeWarning)
    # values is this call's own array: wrapped, not copied (pandas copies an array by
    # default)
    result = pd.DataFrame(values.reshape(-1, len(times)).T, index=df.index.copy(),
                          columns=_column_index(), copy=False)
    result.attrs = {
        "units": {"moment": "N m/kg", "force": "N/kg", "power": "W/kg"},
        "frames": "moments and forces on the distal segment, in its ISB frame; signs: "
                  "bmc_functions.models.lower_limb_kinetics",
        "body_mass": body_mass, "cutoff": cutoff, "force_cutoff": force_cutoff,
        "gravity": np.asarray(gravity, dtype=float).tolist(),
        "segment_parameters": {name: p._asdict() for name, p in table.items()},
        "load_assignment": assignment}
    return result
