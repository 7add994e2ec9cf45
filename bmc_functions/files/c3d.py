r"""Marker trajectories from C3D files (binary; needs the optional package ezc3d).

:func:`read_c3d` returns the marker table of :mod:`~bmc_functions.files.marker_table`.
:func:`load_c3d_points` is the one way the package loads a C3D file's points (the
structure checks of :mod:`~bmc_functions.files._c3d_binary`, the whole frames of a cut
file, ezc3d in an isolated child process, invalid points as NaN):
:func:`~bmc_functions.files.c3d_parameters.read_c3d_model_outputs` reads the model outputs
through it too.
"""

import os
import struct
import tempfile
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd

from .._checks import check_regular_file, warn
from ._c3d_binary import check_c3d, read_isolated, require_ezc3d
from .marker_table import COORDS, zero_points_to_gaps


def read_c3d(path, *, zeros_as_gaps=True):
    r"""Read marker trajectories from a C3D file (needs the optional package ezc3d).

    Parameters
    ----------
    path : str or path-like
        The ``.c3d`` file.
    zeros_as_gaps : bool, optional
        If True (default), a point whose x, y and z are all exactly 0 is a gap (NaN), as
        older Vicon systems and others write a marker not seen. False keeps them (a
        point with a negative residual is a gap either way: the C3D convention).

    Returns
    -------
    pandas.DataFrame
        The same shape as :func:`~bmc_functions.files.trc.read_trc`: columns ``(marker,
        coord)``, index the time in seconds from 0 at the first stored frame (named
        ``'time'``), NaN for invalid points. ``df.attrs`` holds ``'rate'`` (POINT:RATE, Hz),
        ``'units'`` (POINT:UNITS), ``'frames'`` (1-based frame numbers),
        ``'dropped_labels'``, ``'invalid_points'`` (how many points, frame x marker, had a
        negative residual) and ``'zero_points'`` (how many more were exactly (0, 0, 0) and
        became NaN).

    Raises
    ------
    ImportError
        If ezc3d is not installed; the message names the extra ``bmc_functions[c3d]``.
    ValueError
        If a point has an empty label, or two points have the same label; if `path` is
        a directory, a device or a pipe; if the file is damaged: not a C3D file (no key
        0x50), cut before its parameters or its data, a parameter record that runs
        outside the parameter section, POINT:USED, POINT:FRAMES or POINT:DATA_START
        disagreeing with the header, POINT:RATE not a positive number, POINT:SCALE (header
        or parameter) not a finite number, or ezc3d failing,
        crashing or not finishing on it. The message names the file and the problem.
    TypeError
        If `path` is not a file name.

    Warns
    -----
    UserWarning
        If the file is cut inside its data: the whole frames it holds are read, and the
        warning says how many of the announced frames that is. If points exactly at
        (0, 0, 0) were read as gaps: how many, in which markers.

    Notes
    -----
    Before ezc3d [2]_ sees the file, its header block and parameter section are
    checked against the file's length (:func:`bmc_functions.files._c3d_binary.check_c3d`): a
    damaged C3D file made ezc3d crash the Python process (a segmentation fault),
    allocate without bound, loop forever or return frames of zeros. ezc3d then reads
    the file in a forked child process with a time and memory limit (POSIX; on Windows
    in this process, after the same checks), so that a damage the checks do not catch
    ends the child with a ValueError here, never the user's session. The fork costs
    about 10-50 ms per file.

    Positions come from the POINT group. A point whose residual is negative is invalid
    (the C3D convention for a marker not seen) and becomes NaN. Labels come from
    POINT:LABELS (continued in LABELS2, LABELS3, ... for files with more than 255
    points). Points that Vicon-style files list under POINT:ANGLES, FORCES, MOMENTS,
    POWERS, REACTIONS or SCALARS are model outputs in other units, not markers: they are
    left out and named in ``df.attrs['dropped_labels']``.

    References
    ----------
    .. [1] C3D.org, "The C3D file format user guide", https://www.c3d.org
    .. [2] Michaud B, Begon M (2021). ezc3d: An easy C3D file I/O cross-platform solution
       for C++, Python and MATLAB. Journal of Open Source Software 6(58), 2911.

    Examples
    --------
    The example walking trial written to a C3D file with ezc3d, and read back:

    >>> import os, tempfile
    >>> import ezc3d, numpy as np
    >>> from bmc_functions import read_c3d, read_trc
    >>> from bmc_functions.examples import example_file
    >>> trc = read_trc(example_file("markers/walk.trc"))
    >>> labels = list(trc.columns.get_level_values(0).unique())
    >>> c3d = ezc3d.c3d()
    >>> c3d["parameters"]["POINT"]["RATE"]["value"] = [trc.attrs["rate"]]
    >>> c3d["parameters"]["POINT"]["LABELS"]["value"] = tuple(labels)
    >>> c3d["parameters"]["POINT"]["UNITS"]["value"] = [trc.attrs["units"]]
    >>> points = np.ones((4, len(labels), len(trc)))    # x, y, z, 1; markers; frames
    >>> points[:3] = trc.to_numpy().reshape(len(trc), len(labels), 3).T
    >>> c3d["data"]["points"] = points
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     c3d.write(os.path.join(folder, "walk.c3d"))
    ...     df = read_c3d(os.path.join(folder, "walk.c3d"))
    >>> df.shape, df.attrs["rate"], df.attrs["units"], list(df.columns[:2])
    ((111, 69), 100.0, 'mm', [('PEL1', 'x'), ('PEL1', 'y')])
    >>> print(np.nanmax(np.abs(df.to_numpy() - trc.to_numpy())) < 1e-3)  # C3D: float32
    True
    """
    points = load_c3d_points(path, "read_c3d")
    labels = points["labels"]
    non_markers = {label.strip() for group in points["non_markers"].values()
                   for label in group}
    keep = np.array([label not in non_markers for label in labels], dtype=bool)
    kept = [label for label, is_marker in zip(labels, keep) if is_marker]
    _check_marker_labels(path, labels, keep, kept)
    rate = points["rate"]
    if not (np.isfinite(rate) and rate > 0):
        raise ValueError(f"{path}: POINT:RATE is {rate:g}; a frame rate must be a positive "
                         "number (Hz)")
    xyz = points["xyz"]
    n_frames = xyz.shape[0]
    columns = pd.MultiIndex.from_product([kept, COORDS], names=["marker", "coord"])
    df = pd.DataFrame(xyz[:, keep, :].reshape(n_frames, 3 * len(kept)), columns=columns,
                      index=pd.Index(np.arange(n_frames) / rate, name="time"))
    df.attrs = {"rate": rate, "units": points["units"][0].strip() if points["units"] else "",
                "frames": points["frames"],
                "dropped_labels": [label for label, is_marker in zip(labels, keep)
                                   if not is_marker],
                "invalid_points": int(np.count_nonzero(points["invalid"][:, keep]))}
    messages = points["messages"]
    zero_points_to_gaps(df, zeros_as_gaps, messages)
    if messages:
        warn(f"{path}: " + "; ".join(messages), UserWarning)
    return df


def _check_marker_labels(path, labels, keep, kept):
    """Refuse markers without a label or with the same label (their columns would merge)."""
    blank = [str(k + 1) for k, label in enumerate(labels) if keep[k] and not label]
    if blank:
        raise ValueError(f"{path}: POINT:LABELS: points {', '.join(blank)} (of "
                         f"{len(labels)}) have an empty label; name them (e.g. in the "
                         "capture software) before reading")
    duplicates = sorted(label for label, count in Counter(kept).items() if count > 1)
    if duplicates:
        raise ValueError(f"{path}: duplicate marker labels in POINT:LABELS: "
                         f"{', '.join(duplicates)}")


def load_c3d_points(path, caller):
    """Every point of the C3D file `path`, checked, read in isolation, invalid ones NaN.

    `caller` names the public function for the ImportError when ezc3d is missing.
    Returns a dict: ``'xyz'`` (frames, points, 3) float with NaN where the residual is
    negative (the C3D convention for a point not seen), ``'invalid'`` (frames, points)
    bool, ``'labels'`` (stripped, one per point), ``'non_markers'`` (group -> labels, as
    :func:`~bmc_functions.files._c3d_binary.extract_points`), ``'rate'``, ``'units'``,
    ``'frames'`` (1-based frame numbers) and ``'messages'`` (what to warn about: the
    frames a cut file lacks). Raises as :func:`read_c3d`.
    """
    require_ezc3d(caller)
    check_regular_file(path, "C3D")
    info = check_c3d(path)
    messages = []
    with tempfile.TemporaryDirectory() as folder:
        source = path
        if info["frames_present"] < info["frames"]:
            source = complete_frames_copy(path, info, Path(folder) / "complete.c3d")
            messages.append(f"the header announces {info['frames']} frames but the file "
                            f"holds {info['frames_present']} whole frames (is it cut?); "
                            f"the first {info['frames_present']} were read")
        c3d = read_isolated(source, path, os.path.getsize(source))
    points = c3d["points"]
    if points.ndim != 3 or points.shape[0] < 3:
        raise ValueError(f"{path}: not a readable C3D file: ezc3d returned points of shape "
                         f"{points.shape}")
    n_points, n_frames = points.shape[1], points.shape[2]
    labels = [label.strip() for label in c3d["labels"][:n_points]]
    if len(labels) < n_points:
        raise ValueError(f"{path}: POINT:LABELS names {len(labels)} of the {n_points} points")
    xyz = points[:3].transpose(2, 1, 0).copy()  # (n_frames, n_points, 3)
    residuals = c3d["residuals"]
    invalid = np.zeros(xyz.shape[:2], dtype=bool)
    if residuals is not None and np.size(residuals):
        invalid = residuals[0].T < 0
        xyz[invalid] = np.nan
    first = c3d["first_frame"] + 1  # ezc3d counts from 0
    return {"xyz": xyz, "invalid": invalid, "labels": labels,
            "non_markers": c3d["non_markers"], "rate": c3d["rate"], "units": c3d["units"],
            "frames": list(range(first, first + n_frames)), "messages": messages}


def complete_frames_copy(path, info, target):
    """Write to `target` the whole frames of the cut C3D file `path`, its header saying
    how many there are (`info` from :func:`~bmc_functions.files._c3d_binary.check_c3d`);
    return `target`."""
    n_present = info["frames_present"]
    with open(path, "rb") as file:
        data = bytearray(file.read(info["data_offset"] + n_present * info["frame_bytes"]))
    order = info["order"]
    struct.pack_into(order + "H", data, 8, info["first_frame"] + n_present - 1)  # last frame
    if info["frames_param_offset"] is not None:
        struct.pack_into(order + "H", data, info["frames_param_offset"], n_present)
    Path(target).write_bytes(data)
    return target
