r"""Marker trajectories in and out of TRC files (Motion Analysis Corp., text).

The TRC format is tab-separated text: three header lines (``PathFileType``; the keys
``DataRate CameraRate NumFrames NumMarkers Units OrigDataRate OrigDataStartFrame
OrigNumFrames``; their values), a labels line (``Frame#  Time  marker1 _ _ marker2 _ _
...``: each label is followed by two empty fields), a coordinate line (``X1 Y1 Z1 X2 Y2
Z2 ...``), usually a blank line, then one row per frame: frame number, time, and x, y, z
of every marker. :func:`read_trc` returns the marker table of
:mod:`~bmc_functions.files.marker_table`; the data rows are read by
:mod:`~bmc_functions.files.trc_rows`.
"""

import codecs
import io
import os
import re
import warnings
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd

from .._checks import (as_float_array, check_float_format, check_regular_file, check_scalar,
                       warn)
from .marker_table import COORDS, check_marker_frame, decode_text, zero_points_to_gaps
from .trc_rows import TrcError, read_rows, scan_rows

#: Keys of the second TRC header line, in the order the standard (and OpenSim) expects.
TRC_KEYS = ("DataRate", "CameraRate", "NumFrames", "NumMarkers", "Units",
            "OrigDataRate", "OrigDataStartFrame", "OrigNumFrames")

# A header line longer than this is not a TRC header (a binary file, /dev/zero copied...).
_HEADER_LINE_LIMIT = 1 << 24
# Bytes looked at before the scan for UTF-16 text or old Mac line ends (which change
# every line, so the whole file is normalized first).
_PEEK = 1 << 16


def _fields(line):
    """Fields of a tab-separated line with their padding spaces removed."""
    return [field.strip() for field in line.split("\t")]


def _nonempty(line):
    """The non-empty fields of a tab-separated line."""
    return [field for field in _fields(line) if field]


def _parse_count(text, key, error):
    """Parse a whole number from the header values line (line 3)."""
    try:
        value = float(text)
    except ValueError:
        value = np.nan
    if not (np.isfinite(value) and value == int(value) and value >= 0):
        raise error(3, f"{key} must be a whole number >= 0; got {text!r}")
    return int(value)


def _parse_rate(text, key, error):
    """Parse a positive rate (Hz) from the header values line (line 3)."""
    try:
        value = float(text)
    except ValueError:
        value = np.nan
    if not (np.isfinite(value) and value > 0):
        raise error(3, f"{key} must be a positive number (Hz); got {text!r}")
    return value


def _parse_header(lines, error):
    """Parse lines 1-3 into a dict of raw strings plus the checked numbers."""
    if len(lines) < 5:
        raise error(len(lines), f"the file ends after {len(lines)} line(s); a TRC file has "
                    "5 header lines (PathFileType, keys, values, labels, X1 Y1 Z1 ...) "
                    "before the data")
    # Only the first word of line 1 matters (as in OpenSim): writers separate the rest
    # by spaces or tabs, with or without a file name, sometimes with more text after it.
    first = lines[0].split(maxsplit=1)
    if not first or first[0].lower() != "pathfiletype":
        raise error(1, "expected the TRC header line 'PathFileType  4  (X/Y/Z)  <file>'; "
                    f"got {lines[0][:60]!r}")
    # Keys and values never contain spaces: split on tabs and spaces alike.
    keys, values = lines[1].split(), lines[2].split()
    lower = [key.lower() for key in keys]
    for required in ("DataRate", "NumFrames", "NumMarkers", "Units"):
        if required.lower() not in lower:
            raise error(2, f"the header keys line has no {required!r}; expected the keys "
                        f"{' '.join(TRC_KEYS)}; got {lines[1][:80]!r}")
    if len(values) != len(keys):
        raise error(3, f"{len(values)} header values for the {len(keys)} keys of line 2 "
                    f"({', '.join(keys)}); got {lines[2][:80]!r}")
    header = dict(zip(keys, values))
    by_lower = dict(zip(lower, values))
    parsed = {
        "rate": _parse_rate(by_lower["datarate"], "DataRate", error),
        "num_frames": _parse_count(by_lower["numframes"], "NumFrames", error),
        "num_markers": _parse_count(by_lower["nummarkers"], "NumMarkers", error),
        "units": by_lower["units"],
    }
    if "camerarate" in by_lower:
        parsed["camera_rate"] = _parse_rate(by_lower["camerarate"], "CameraRate", error)
    return header, parsed


def _parse_labels(line, error):
    """Marker labels of line 4, in data-column order (marker k in fields 3k+3 to 3k+5)."""
    fields = _fields(line)
    tokens = [field for field in fields if field]
    if (len(tokens) < 2 or tokens[0].lower().replace(" ", "") != "frame#"
            or tokens[1].lower() != "time"):
        raise error(4, f"expected the labels line 'Frame#  Time  marker1 ...'; "
                    f"got {line[:60]!r}")
    rest = fields[2:]
    while rest and not rest[-1]:
        rest.pop()
    if not rest:
        raise error(4, "the labels line names no marker")
    # The standard layout: each label followed by two empty fields. If the file has it,
    # the positions are authoritative (an empty label slot is then an error); if not
    # (double tabs, missing padding), the labels are taken in order.
    standard = (fields[0] and fields[1]
                and all(not field for i, field in enumerate(rest) if i % 3))
    if not standard:
        return tokens[2:]
    labels = rest[0::3]
    if not all(labels):
        k = labels.index("")  # (0-based marker index)
        raise error(4, f"marker column {k + 1} (data fields {3 * k + 3}-{3 * k + 5}) has "
                    "no label")
    return labels


def normalized_copy(raw, error, remove_spaces):
    """The file as UTF-8 bytes with '\\n' line ends (and no spaces in the data rows, after
    checking that none is inside a field, if `remove_spaces`)."""
    if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        try:
            raw = raw.decode("utf-16").encode("utf-8")  # the BOM is dropped
        except UnicodeDecodeError as err:
            raise error(1, f"the file starts with a UTF-16 byte-order mark but is not "
                        f"valid UTF-16 text ({err.reason} at byte {err.start})") from None
    raw = raw.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    if not remove_spaces:
        return io.BytesIO(raw)
    pos = 0
    for _ in range(5):  # the data rows start after the five header lines
        end = raw.find(b"\n", pos)
        if end < 0:
            return io.BytesIO(raw)
        pos = end + 1
    data = raw[pos:]
    if b" " in data:
        # Spaces only pad numbers; one between two characters of a field is an error.
        match = re.search(rb"[^\t\n ] +[^\t\n ]", data)
        if match:
            line = 6 + data.count(b"\n", 0, match.start())
            raise error(line, f"a space inside a field: {match.group().decode('latin-1')!r}; "
                        "fields are separated by tabs")
        data = data.replace(b" ", b"")
    return io.BytesIO(raw[:pos] + data)


def _header_lines(source, error):
    """The five header lines (text, line ends removed) and the byte offset after them.

    As ``text.split('\\n')`` would give them: a file of three lines ending with a line
    break has four, the last empty.
    """
    raw = []
    for k in range(5):
        line = source.readline(_HEADER_LINE_LIMIT + 1)
        if len(line) > _HEADER_LINE_LIMIT:
            raise error(k + 1, f"the line is longer than {_HEADER_LINE_LIMIT} bytes; a TRC "
                        "file starts with five short text lines (is it a TRC file?)")
        if not line:
            break
        raw.append(line)
        if not line.endswith(b"\n"):
            break
    offset = source.tell()
    if len(raw) < 5 and (not raw or raw[-1].endswith(b"\n")):
        raw.append(b"")
    if raw:
        raw[0] = raw[0].removeprefix(codecs.BOM_UTF8)  # a byte-order mark is not text
    # each line on its own (a Latin-1 file name in line 1 leaves UTF-8 labels UTF-8)
    lines = [decode_text(line.removesuffix(b"\n")) for line in raw]
    return [line.removesuffix("\r") for line in lines], offset


def read_trc(path, *, zeros_as_gaps=True):
    r"""Read marker trajectories from a TRC file.

    Parameters
    ----------
    path : str or path-like
        The ``.trc`` file.
    zeros_as_gaps : bool, optional
        If True (default), a marker whose x, y and z are all exactly 0 in a frame is a
        gap (NaN): the way several systems write a marker not seen. False keeps them.

    Returns
    -------
    pandas.DataFrame
        One row per frame, indexed by the file's Time column (seconds, index named
        ``'time'``); columns a MultiIndex ``(marker, coord)`` with coords ``'x'``,
        ``'y'``, ``'z'``, markers in file order; empty fields are NaN. ``df.attrs``
        holds:

        - ``'rate'``: DataRate (Hz, float);
        - ``'units'``: Units as written (e.g. ``'mm'``, ``'m'``);
        - ``'frames'``: the Frame# column (list of int, one per row);
        - ``'camera_rate'``: CameraRate (Hz, float; absent if the header lacks it);
        - ``'header'``: every key of header line 2 with its value (strings);
        - ``'dropped_labels'``: labels beyond NumMarkers whose columns were entirely
          empty and were not kept (see Notes);
        - ``'zero_points'``: how many points (frame, marker) were exactly (0, 0, 0) and
          became NaN (0 with ``zeros_as_gaps=False``).

    Raises
    ------
    ValueError
        If the file is malformed, with the file name and the line number in the
        message: a missing or garbled header line (PathFileType, keys, values, labels,
        coordinate line), a header value that is not a number (DataRate, NumFrames,
        NumMarkers, CameraRate), a label slot without a name, duplicate labels, a data
        row with more fields than the labels define, that stops inside a marker or whose
        number of fields differs from most rows' by other than whole markers (a lost or
        stray tab), a field that is not a number (or is infinite), a row without frame
        number or time, a frame number that is not a whole number below 2**53. Also if
        `path` is a directory, a device (``/dev/zero``), a named pipe or a socket: these
        are refused before anything is read.
    FileNotFoundError
        If there is no file at `path`.

    Warns
    -----
    UserWarning
        Once per file, when the header disagrees with the data but the data can still
        be read unambiguously: NumFrames differs from the number of data rows;
        NumMarkers is smaller than the number of labels and some of the extra labels
        hold data (they are kept); NumMarkers is larger than the number of labels; the
        time does not increase from row to row; the last line does not end with a line
        break (a file cut while it was copied or written): a value there may be cut
        short (``31.25`` cut to ``3``), so every marker of that row whose x, y, z may be
        incomplete is NaN, and the row is left out if its frame number or time may be
        cut; when points exactly (0, 0, 0) were read as gaps (how many, in which
        markers).

    Notes
    -----
    Data columns are assigned to labels by position, as in the standard: marker
    :math:`k` (0-based) occupies fields :math:`3k+3` to :math:`3k+5` (1-based) of every
    row, after Frame# and Time. The label of marker :math:`k` is field :math:`3k+3` of the
    labels line; when that line does not follow the standard spacing (double tabs), the
    labels are taken in order instead. Columns are never re-aligned by guessing.

    Tolerated quirks of real files: a first line whose fields are separated by spaces or
    tabs, with or without a file name after ``(X/Y/Z)`` and with any text after it (only
    its first word ``PathFileType`` is read, as in OpenSim), header keys and values
    separated by tabs or spaces, trailing tabs on any line, header lines padded with
    tabs or spaces (``'       123'``), double tabs between header keys, zero or more
    blank (or tab-only) lines before the data, Windows line ends, a UTF-8 or UTF-16
    byte-order mark (UTF-8, else Latin-1, without one), rows whose trailing
    empty fields are omitted (when they stop at a marker boundary), the text ``NaN`` for
    a missing value.

    Labels beyond NumMarkers (some systems list labels of virtual markers they never
    wrote): if their columns are empty in every row they are dropped, so that the
    DataFrame has the NumMarkers markers the header announces, and their names are kept
    in ``df.attrs['dropped_labels']``; if any of them holds data it is kept (with a
    warning), because discarding measured data silently would be worse. A marker within
    the first NumMarkers that is empty in every row (e.g. a static-trial landmark in a
    dynamic trial) is kept as an all-NaN column: it is part of the marker set.

    The time index is the Time column as written (often rounded to 1 ms); the exact
    sample times are ``(frames - frames[0]) / rate`` plus the first time.

    The file is read block by block: each line's tabs are counted with NumPy (for the
    checks above), then pandas' C parser reads the rows straight from the file, so a
    big file costs about what :func:`pandas.read_csv` costs (time and memory) and no
    whole-file text copy is made (files with spaces in the rows, old Mac line ends or
    UTF-16 text are first normalized in memory). Work is bounded by the header: a data
    line longer than :math:`2^{22} + 256\,w` bytes (:math:`w` the fields per row the
    labels define) is refused at once.

    References
    ----------
    .. [1] Motion Analysis Corporation, "Track Row Column (TRC) file format",
       appendix of the EVaRT/Cortex user manual.
    .. [2] OpenSim User's Guide, "Marker (.trc) Files"; the reader and writer are
       ``TRCFileAdapter`` in OpenSim/Common.

    Examples
    --------
    >>> import os, tempfile
    >>> from bmc_functions import read_trc
    >>> text = ("PathFileType\t4\t(X/Y/Z)\tdemo.trc\n"
    ...         "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\t"
    ...         "OrigDataStartFrame\tOrigNumFrames\n"
    ...         "100\t100\t2\t2\tmm\t100\t1\t2\n"
    ...         "Frame#\tTime\tRTH1\t\t\tRTH2\t\t\t\n"
    ...         "\t\tX1\tY1\tZ1\tX2\tY2\tZ2\t\n"
    ...         "\n"
    ...         "1\t0.00\t10.0\t20.0\t30.0\t\t\t\t\n"
    ...         "2\t0.01\t11.0\t21.0\t31.0\t40.0\t50.0\t60.0\t\n")
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "demo.trc")
    ...     with open(path, "w") as file:
    ...         _ = file.write(text)
    ...     df = read_trc(path)
    >>> print(df.attrs["rate"], df.attrs["units"], df.attrs["frames"])
    100.0 mm [1, 2]
    >>> print(list(df.columns.get_level_values("marker").unique()))
    ['RTH1', 'RTH2']
    >>> print(df["RTH2"].to_numpy())
    [[nan nan nan]
     [40. 50. 60.]]
    """
    check_regular_file(path, "TRC")
    path = Path(path)
    error = TrcError(path)
    with open(path, "rb") as file:
        source = file
        peek = file.read(_PEEK)
        if (peek[:2] in (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)
                or re.search(rb"\r[^\n]", peek)):
            file.seek(0)
            source = normalized_copy(file.read(), error, remove_spaces=False)
        layout, scan = _scan_file(source, error)
        if scan is None:  # spaces or lone carriage returns in the data rows
            file.seek(0)
            source = normalized_copy(file.read(), error, remove_spaces=True)
            layout, scan = _scan_file(source, error)
        parsed, first_line, messages = read_rows(source, scan, layout["width"],
                                                 layout["labels"], error)
    df = _marker_table(parsed, first_line, layout, messages, error)
    zero_points_to_gaps(df, zeros_as_gaps, messages)
    if messages:
        warn(f"{path}: " + "; ".join(messages), UserWarning)
    return df


def _scan_file(source, error):
    """The header (dict: ``header``, ``values``, ``labels``, ``width``, ``offset``) and
    the scan of the data rows (:func:`~bmc_functions.files.trc_rows.scan_rows`; None if
    they need a normalized copy) of a TRC file open in binary mode."""
    source.seek(0)
    lines, offset = _header_lines(source, error)
    header, header_values = _parse_header(lines, error)
    labels = _parse_labels(lines[3], error)
    coord_tokens = _nonempty(lines[4])
    if not coord_tokens or not re.fullmatch(r"[XYZxyz]\d+", coord_tokens[0]):
        raise error(5, f"expected the coordinate line 'X1  Y1  Z1  X2 ...'; got "
                    f"{lines[4][:60]!r}")
    width = 2 + 3 * len(labels)
    layout = {"header": header, "values": header_values, "labels": labels,
              "width": width, "offset": offset}
    max_line = (1 << 22) + 256 * width
    return layout, scan_rows(source, offset, max_line, error)


def _marker_table(parsed, first_line, layout, messages, error):
    """The marker DataFrame of the parsed rows, with the header's metadata in ``attrs``;
    what disagrees between header and rows is appended to `messages`."""
    header_values, labels = layout["values"], layout["labels"]
    n_rows = len(parsed)
    if header_values["num_frames"] != n_rows:
        messages.append(f"the header says NumFrames = {header_values['num_frames']} but the "
                        f"file holds {n_rows} data rows; all {n_rows} rows were read")
    keep, dropped = _markers_to_keep(parsed, labels, header_values["num_markers"], messages)
    kept = [label for label, is_kept in zip(labels, keep) if is_kept]
    duplicates = sorted(label for label, count in Counter(kept).items() if count > 1)
    if duplicates:
        raise error(4, f"duplicate marker labels: {', '.join(duplicates)}")
    time = parsed.column(1).copy()
    steps = np.diff(time)
    if (steps <= 0).any():
        i = int(np.argmax(steps <= 0))
        messages.append(f"the time does not increase at line {first_line + i + 1} "
                        f"({time[i]:g} then {time[i + 1]:g})")
    rate_message = _rate_against_time(header_values["rate"], time,
                                      parsed.column(0) if n_rows else time)
    if rate_message:
        messages.append(rate_message)
    # the parsed columns become the DataFrame's: no second copy of the data
    df = parsed.markers(keep)
    df.columns = pd.MultiIndex.from_product([kept, COORDS], names=["marker", "coord"])
    df.index = pd.Index(time, name="time")
    df.attrs = {"rate": header_values["rate"], "units": header_values["units"],
                "frames": parsed.column(0).astype(np.int64).tolist()}
    if "camera_rate" in header_values:
        df.attrs["camera_rate"] = header_values["camera_rate"]
    df.attrs["header"] = layout["header"]
    df.attrs["dropped_labels"] = dropped
    return df


def _markers_to_keep(parsed, labels, num_markers, messages):
    """Which labelled markers to keep (bool per label) and the labels dropped: labels
    beyond NumMarkers whose columns are empty in every row."""
    n_labels = len(labels)
    keep = np.ones(n_labels, dtype=bool)
    dropped = []
    if n_labels > num_markers:
        extra = np.arange(num_markers, n_labels)
        holds_data = np.array([any(not np.isnan(parsed.column(field)).all()
                                   for field in range(2 + 3 * marker, 5 + 3 * marker))
                               for marker in extra], dtype=bool)
        keep[extra[~holds_data]] = False
        dropped = [labels[marker] for marker in extra[~holds_data]]
        if holds_data.any():
            names = ", ".join(labels[marker] for marker in extra[holds_data])
            messages.append(f"the header says NumMarkers = {num_markers} but "
                            f"{holds_data.sum()} of the {extra.size} labels beyond it hold "
                            f"data and were kept: {names}")
    elif n_labels < num_markers:
        messages.append(f"the header says NumMarkers = {num_markers} but the labels line "
                        f"names {n_labels} markers; {n_labels} were read")
    return keep, dropped


def _rate_against_time(rate, time, frames):
    """A message if the DataRate contradicts the Time column, else None.

    The span of the Time column is compared with the span the frame numbers and the rate
    give, ``(frames[-1] - frames[0]) / rate``: frames that a writer skipped count, and the
    Time column's rounding (often to 1 ms) averages out over the trial. Allowed: 2 % or
    2 ms, whichever is larger.
    """
    finite = np.isfinite(time) & np.isfinite(frames)
    if finite.sum() < 3:
        return None
    time, frames = time[finite], frames[finite]
    span, count = time[-1] - time[0], frames[-1] - frames[0]
    if span <= 0 or count <= 0:
        return None            # a time that does not increase is reported on its own
    expected = count / rate
    if abs(span - expected) <= max(0.02 * expected, 0.002):
        return None
    return (f"the header says DataRate = {rate:g} Hz, but the Time column steps at "
            f"{count / span:.4g} Hz ({count:.0f} frame steps over {span:.4g} s; at {rate:g} Hz "
            f"they would span {expected:.4g} s): the index is the Time column as written, "
            f"df.attrs['rate'] the DataRate; check which one is right")


def _frame_numbers(frames, n_rows):
    """attrs['frames'] as int64 when it holds one whole number below 2**53 per row,
    otherwise 1, 2, ..., n_rows (e.g. after slicing rows, or for frame labels)."""
    default = np.arange(1, n_rows + 1, dtype=np.int64)
    if frames is None or isinstance(frames, (str, bytes)):
        return default
    try:
        array = np.asarray(frames)
    except (TypeError, ValueError, OverflowError):  # ragged, or ints beyond int64
        array = np.asarray(frames, dtype=object) if np.ndim(frames) == 1 else np.array([])
    if array.shape != (n_rows,):  # e.g. rows sliced after reading: attrs was not sliced
        return default
    usable = array.dtype.kind in "iuf"  # not bool, text or Python objects
    if usable:
        array = array.astype(float)
        usable = bool(np.isfinite(array).all() and (array == np.round(array)).all()
                      and (np.abs(array) < 2.0**53).all())
    if not usable:
        warn(f"df.attrs['frames'] does not hold whole numbers below 2**53 (got "
             f"{array[:3].tolist()}...): the frames were numbered 1 to {n_rows}",
             UserWarning)
        return default
    return array.astype(np.int64)


def write_trc(df, path, *, rate=None, units=None, float_format="%.6f"):
    r"""Write marker trajectories to a standard TRC file.

    Parameters
    ----------
    df : pandas.DataFrame
        Marker trajectories as returned by :func:`read_trc` or :func:`read_c3d`:
        columns a MultiIndex ``(marker, coord)`` with coords ``'x'``, ``'y'``, ``'z'``
        for every marker; index the time in seconds. NaN is missing data.
    path : str or path-like
        The file to write (overwritten if it exists).
    rate : float, optional
        DataRate in Hz; default ``df.attrs['rate']``.
    units : str, optional
        Units of the coordinates, e.g. ``'mm'``; default ``df.attrs['units']``.
    float_format : str, default ``'%.6f'``
        printf-style format of the coordinates and the time; the time is written with
        ``'%.6f'`` instead if this format would round it by more than 0.5 us (so that
        e.g. ``'%.2f'`` for coordinates in mm does not merge the times of neighbouring
        frames), and with 9, 12 or 15 decimals where times less than 1 us apart would
        otherwise be written as one.

    Raises
    ------
    ValueError
        If `df` does not have (marker, coord) columns with exactly x, y, z per marker, if
        a label is empty, contains a tab or has leading or trailing spaces, if a value is
        infinite, if the time index is not numbers (e.g. a TimedeltaIndex), not finite or
        not increasing, if the rate or the units are neither given nor in ``df.attrs``,
        if ``df.attrs['camera_rate']`` is not a positive number, if the file name
        contains a line break (it is written in header line 1), or if `float_format`
        does not write a number (``'abc'``, ``'%s %s'``).
    TypeError
        If `df` holds booleans, `rate` is a boolean, `float_format` is not a string, or
        `path` is not a file name.

    Warns
    -----
    UserWarning
        If ``df.attrs['frames']`` has one entry per row but not whole numbers below
        2**53 (frame labels, 10**400): the frames are then numbered 1, 2, ..., n. If a
        fixed-point `float_format` (``'%.6f'``) keeps fewer than 4 significant digits
        of the largest value (data in small units: 1e-7 would be written as 0).

    Notes
    -----
    The file follows the layout OpenSim writes and reads [1]_: the header line
    ``PathFileType 4 (X/Y/Z) <name>``; the eight keys ``DataRate CameraRate NumFrames
    NumMarkers Units OrigDataRate OrigDataStartFrame OrigNumFrames`` and their values;
    ``Frame# Time`` then each label followed by two empty fields; ``X1 Y1 Z1 ...``; a
    blank line; one row per frame with every field followed by a tab, NaN written as an
    empty field. CameraRate is ``df.attrs['camera_rate']`` if present, else the rate;
    OrigDataRate is the rate, OrigDataStartFrame the first frame number and OrigNumFrames
    the number of rows.

    The frame numbers are ``df.attrs['frames']`` when it has one whole number (below
    2**53) per row, otherwise 1, 2, ..., n (e.g. after the rows were sliced, since
    ``attrs`` is not sliced with them). Everything written reads back with
    :func:`read_trc`: the values as `float_format` prints them, the rest exactly.

    References
    ----------
    .. [1] OpenSim, ``TRCFileAdapter`` (OpenSim/Common/TRCFileAdapter.cpp).

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np, pandas as pd
    >>> from bmc_functions import read_trc, write_trc
    >>> columns = pd.MultiIndex.from_product([["RTH1", "RTH2"], ["x", "y", "z"]])
    >>> df = pd.DataFrame([[1.0, 2.0, 3.0, np.nan, np.nan, np.nan],
    ...                    [1.5, 2.5, 3.5, 4.0, 5.0, 6.0]],
    ...                   index=pd.Index([0.0, 0.01], name="time"), columns=columns)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "trial.trc")
    ...     write_trc(df, path, rate=100.0, units="mm")
    ...     with open(path) as file:
    ...         lines = file.read().splitlines()
    ...     back = read_trc(path)
    >>> print(lines[6].split("\t"))
    ['1', '0.000000', '1.000000', '2.000000', '3.000000', '', '', '', '']
    >>> print(back.attrs["rate"], back.attrs["units"], back.equals(df))
    100.0 mm True
    """
    name = os.fspath(path) if isinstance(path, (str, os.PathLike)) else None
    if not isinstance(name, str):
        raise TypeError(f"path must be a file name (str or path-like); got "
                        f"{type(path).__name__}")
    if re.search(r"[\r\n]", name):  # it would break header line 1
        raise ValueError(f"path: the file name must not contain a line break; got {name!r}")
    float_format = check_float_format(float_format)
    markers, values = check_marker_frame(df)
    n_rows = values.shape[0]
    rate = _rate_to_write(rate, df.attrs)
    units = _units_to_write(units, df.attrs)
    time = _time_to_write(df)
    frames = _frame_numbers(df.attrs.get("frames"), n_rows)
    camera_rate = _camera_rate_to_write(df.attrs.get("camera_rate", rate))

    def number(value):
        return f"{float(value):.15g}"

    n_markers = len(markers)
    head = [
        f"PathFileType\t4\t(X/Y/Z)\t{Path(path).name}",
        "\t".join(TRC_KEYS),
        "\t".join([number(rate), number(camera_rate), str(n_rows), str(n_markers),
                   units.strip(), number(rate), str(frames[0] if n_rows else 1),
                   str(n_rows)]),
        "Frame#\tTime\t" + "".join(f"{marker}\t\t\t" for marker in markers),
        "\t\t" + "".join(f"X{k}\tY{k}\tZ{k}\t" for k in range(1, n_markers + 1)),
        "",
    ]
    _warn_lost_digits(values, float_format)
    table = pd.DataFrame(values)
    table.insert(0, "time", _time_column(time, float_format))
    table.insert(0, "frame", frames)
    table["end"] = np.nan  # an empty last field: every field ends with a tab (OpenSim)
    body = table.to_csv(sep="\t", header=False, index=False, na_rep="",
                        float_format=float_format, lineterminator="\n")
    with open(path, "w", encoding="utf-8", newline="\n") as file:
        file.write("\n".join(head) + "\n" + body)


def _rate_to_write(rate, attrs):
    """The DataRate: `rate`, else ``attrs['rate']``; a positive number (Hz)."""
    if rate is None:
        rate = attrs.get("rate")
        if rate is None:
            raise ValueError("rate: df.attrs has no 'rate'; pass rate= (Hz)")
    return check_scalar(rate, "rate", "a positive number (Hz)", minimum=0, strict=True)


def _units_to_write(units, attrs):
    """The Units: `units`, else ``attrs['units']``; one word."""
    if units is None:
        units = attrs.get("units")
        if units is None:
            raise ValueError("units: df.attrs has no 'units'; pass units= (e.g. 'mm')")
    if not isinstance(units, str) or not units.strip() or re.search(r"\s", units.strip()):
        raise ValueError(f"units must be a non-empty word such as 'mm' or 'm'; got {units!r}")
    return units


def _time_to_write(df):
    """The time index as floats: numbers in seconds, finite, increasing."""
    if df.index.dtype.kind in "mM":  # numpy would turn these into counts of ns or us
        raise ValueError(f"df.index (time) must hold the time in seconds as numbers; got "
                         f"dtype {df.index.dtype} (for a TimedeltaIndex, set "
                         "df.index = df.index.total_seconds())")
    time = as_float_array(df.index.to_numpy(), "df.index (time)")
    if time.ndim != 1 or not np.isfinite(time).all():
        raise ValueError("df.index (time) must hold finite times in seconds; got "
                         f"{df.index[:5].tolist()}...")
    if len(time) > 1 and (np.diff(time) <= 0).any():
        i = int(np.argmax(np.diff(time) <= 0))
        raise ValueError(f"df.index (time) must increase; got {time[i]:g} then "
                         f"{time[i + 1]:g} at rows {i} and {i + 1}")
    return time


def _camera_rate_to_write(camera_rate):
    """``attrs['camera_rate']`` (default the rate) as a positive float (Hz)."""
    if not isinstance(camera_rate, (bool, np.bool_)):
        try:
            camera_rate = float(camera_rate)
        except (TypeError, ValueError, OverflowError):
            pass  # refused below, as given
    if not (isinstance(camera_rate, float) and np.isfinite(camera_rate) and camera_rate > 0):
        raise ValueError("df.attrs['camera_rate'] must be a positive number (Hz); got "
                         f"{camera_rate!r}")
    return camera_rate


def _time_column(time, float_format):
    """The Time column: `time` printed with `float_format` when that keeps every time
    within 0.5 us ('%.2f' would write 200 Hz as 0.00, 0.01, 0.01, ...), else '%.6f';
    with more decimals (9, 12, 15) where those would write two times as one (times less
    than 1 us apart): every time written is read back distinct and increasing."""
    if not len(time):
        return time
    text = np.char.mod(float_format, time)
    try:
        exact = np.abs(text.astype(float) - time).max() <= 5e-7 * (1 + 1e-9)
    except ValueError:  # a format that does not print a number
        exact = False
    text = text if exact else np.char.mod("%.6f", time)
    for decimals in (9, 12, 15):
        if len(time) < 2 or (np.diff(text.astype(float)) > 0).all():
            break
        text = np.char.mod(f"%.{decimals}f", time)
    return text


def _warn_lost_digits(values, float_format):
    """Warn once when a fixed-point `float_format` ('%.6f') keeps fewer than 4
    significant digits of the data's largest value (data in small units: '%.6f' writes
    1e-7 as 0.000000). A value tiny beside the others (a 1e-16 from a rotation) is
    written as 0 without a word; other formats are the caller's choice."""
    match = re.fullmatch(r"%\.(\d+)f", float_format)
    if match is None or not values.size:
        return
    resolution = 10.0 ** -int(match.group(1))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)   # every value NaN: no largest
        largest = max(float(np.nanmax(values)), -float(np.nanmin(values)))  # no copy
    if 0 < largest < 1000 * resolution:
        magnitude = np.abs(values)
        zeroed = int(np.count_nonzero((magnitude < 0.5 * resolution) & (magnitude > 0)))
        warn(f"write_trc: float_format {float_format!r} writes the coordinates to "
             f"{resolution:g}, but the largest is {largest:.3g}: fewer than 4 significant "
             f"digits are kept ({zeroed} nonzero value(s) written as 0); give a "
             f"float_format with more digits (e.g. '%.10g') or the data in a smaller unit",
             UserWarning)
