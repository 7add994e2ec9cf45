r"""The marker table every marker reader returns and every marker writer takes.

Every reader returns the same shape of data, a :class:`pandas.DataFrame` with

* one row per frame, indexed by the time in seconds (index named ``'time'``);
* columns a two-level :class:`pandas.MultiIndex` ``(marker, coord)`` with coords
  ``'x'``, ``'y'``, ``'z'``, so that ``df['RTH1']`` is the (n_frames, 3) trajectory of
  marker RTH1 and ``df['RTH1'].to_numpy()`` is ready for :func:`~bmc_functions.svdt`;
* NaN where a marker was not seen (an empty field in a TRC file, an invalid point in a
  C3D file);
* ``df.attrs`` holding the file's metadata: ``'rate'`` (Hz, float), ``'units'`` (e.g.
  ``'mm'``), ``'frames'`` (the frame numbers, a list of int, one per row) and more (see
  :func:`~bmc_functions.files.trc.read_trc`).

``df.attrs`` travels with the DataFrame through pandas operations unchanged, so after
slicing rows (``df.iloc[10:20]``) ``attrs['frames']`` still describes the whole file;
:func:`~bmc_functions.files.trc.write_trc` then numbers the frames 1, 2, ... (see its Notes).

The readers are :func:`~bmc_functions.files.trc.read_trc` and
:func:`~bmc_functions.files.c3d.read_c3d`; the writer
:func:`~bmc_functions.files.trc.write_trc`.
"""

import re

import numpy as np
import pandas as pd

from .._checks import ArgumentTypeError, as_float_array, check_finite_or_nan, check_flag

#: Names of the coordinate level of the columns.
COORDS = ("x", "y", "z")


def check_marker_frame(df, name="df"):
    """Return (markers, values (n, 3 * n_markers) in x, y, z order) of a marker DataFrame."""
    if not isinstance(df, pd.DataFrame):
        raise ValueError(f"{name} must be a pandas DataFrame with (marker, coord) columns; "
                         f"got {type(df).__name__}")
    columns = df.columns
    if not isinstance(columns, pd.MultiIndex) or columns.nlevels != 2:
        raise ValueError(f"{name} must have two-level (marker, coord) columns as returned by "
                         f"read_trc; got columns {list(columns[:6])}")
    coords_of = {}
    for marker, coord in columns:  # one pass over the columns (linear in their number)
        coords_of.setdefault(marker, []).append(coord)
    markers = list(coords_of)
    for marker in markers:  # loop over markers, not frames
        # (readers strip the padding of fields, so ' A' would come back as 'A')
        if (not isinstance(marker, str) or not marker.strip() or marker != marker.strip()
                or re.search(r"[\t\n\r]", marker)):
            raise ValueError(f"{name}: marker label {marker!r} must be a non-empty string "
                             "without tabs, line breaks or leading or trailing spaces")
        coords = sorted(coords_of[marker], key=str)
        if coords != list(COORDS):
            raise ValueError(f"{name}: marker {marker!r} must have exactly the coords "
                             f"'x', 'y', 'z'; got {coords}")
    check_numeric_columns(df, name)
    ordered = pd.MultiIndex.from_product([markers, COORDS])
    values = as_float_array(df.reindex(columns=ordered).to_numpy(), name)
    check_finite_or_nan(values, name)
    return markers, values


def check_numeric_columns(df, name="df"):
    """Raise ArgumentTypeError naming the first column of `df` that does not hold numbers
    (booleans, text, dates) and, for text, its first value that is not a number; only
    the columns of other dtypes than integers and floats are looked at."""
    for column, dtype in df.dtypes.items():   # loop over columns, not frames
        if dtype.kind in "iuf":
            continue
        if dtype.kind == "b":
            what = "boolean columns (True/False)"
        elif dtype.kind in "mM":
            what = f"dates or times (dtype {dtype})"
        else:
            values = df[column]
            numbers = pd.to_numeric(values, errors="coerce")
            text = values[numbers.isna() & values.notna()]
            if text.empty:
                continue                    # numbers stored as objects: converted later
            what = (f"text ({text.iloc[0]!r} at time {text.index[0]} is not a number; "
                    f"{text.size} such value(s))")
        raise ArgumentTypeError(f"{name} must hold coordinates (numbers); got {what} in "
                                f"column {column!r}")


#: Bytes of coordinates :func:`zero_points_to_gaps` looks at in one step.
_ZERO_BLOCK = 1 << 23


def zero_points_to_gaps(df, enabled, messages, what="marker",
                        why="the way some systems write a marker not seen"):
    """Set to NaN (in place) the points of `df` exactly at (0, 0, 0) when `enabled`;
    count them in ``df.attrs['zero_points']`` and say so in `messages`, naming the
    columns' kind (`what`: ``'marker'``, ``'output'``) and why zeros mean a gap (`why`)."""
    enabled = check_flag(enabled, "zeros_as_gaps")
    n_markers = df.shape[1] // 3
    zero = np.zeros((len(df), n_markers), dtype=bool)      # (frames, markers)
    attrs, df.attrs = df.attrs, {}   # (pandas copies attrs into every column selected)
    try:
        if enabled and zero.size:
            # a few markers at a time (about _ZERO_BLOCK bytes): no copy of the whole
            # table, which would double a big trial's memory
            step = max(1, _ZERO_BLOCK // (24 * max(len(df), 1)))
            for first in range(0, n_markers, step):       # loop over blocks of markers
                stop = min(first + step, n_markers)
                values = df.iloc[:, 3 * first:3 * stop].to_numpy(dtype=float)
                zero[:, first:stop] = np.all(values.reshape(len(df), -1, 3) == 0, axis=2)
        for marker in np.flatnonzero(zero.any(axis=0)):    # the markers with zeros only
            for k in range(3 * marker, 3 * marker + 3):
                column = df.iloc[:, k].to_numpy(dtype=float, copy=True)
                column[zero[:, marker]] = np.nan
                df.isetitem(k, column)
    finally:
        df.attrs = attrs
    count = int(np.count_nonzero(zero))
    df.attrs["zero_points"] = count
    if count:
        markers = df.columns.get_level_values(0)[::3]
        hit = [str(marker) for marker, has_zero in zip(markers, zero.any(axis=0)) if has_zero]
        messages.append(f"{count} points (frame x {what}) were exactly (0, 0, 0), {why}, "
                        f"in {len(hit)} {what}s ({', '.join(hit[:6])}"
                        f"{' ...' if len(hit) > 6 else ''}): read as gaps (NaN); "
                        "zeros_as_gaps=False keeps them")


def decode_text(raw):
    """The text of the bytes `raw` of a C3D or TRC file: UTF-8 where they are valid
    UTF-8, else Latin-1 (every byte a character), with no byte lost or replaced.

    The one decoding rule of the package's readers for labels, units and descriptions,
    so that a label such as 'Kné' (one byte 0xE9 in Latin-1, two bytes in UTF-8) comes
    back the same from :func:`~bmc_functions.files.c3d.read_c3d`,
    :func:`~bmc_functions.files.c3d_parameters.read_c3d_parameters` and
    :func:`~bmc_functions.files.trc.read_trc`.
    """
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        return raw.decode("latin-1")
