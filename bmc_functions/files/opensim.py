r"""OpenSim motion and storage files (.mot, .sto) in and out.

OpenSim writes its results (inverse kinematics, inverse dynamics, ...) as text tables: a
header that ends with the line ``endheader``, a line of column labels (the first is
``time``), then one row of numbers per instant, fields separated by tabs::

    Coordinates
    version=1
    nRows=122
    nColumns=40
    inDegrees=yes
    endheader
    time	pelvis_tilt	pelvis_list	...
          0.00000000	    -18.41593820	...

:func:`read_mot` returns such a table as a :class:`pandas.DataFrame` indexed by time (s),
one column per label, with the header in ``df.attrs``; :func:`write_mot` writes one, so
that angles computed here can be opened in OpenSim (e.g. to animate a model, or to
compare with its inverse kinematics), and ``read_mot(write_mot(df))`` gives back `df`
exactly. :func:`opensim_coordinates` renames the lower-limb pipeline's angles to the
coordinate names of OpenSim's gait models (``hip_flexion_r``, ``knee_angle_r``, ...; what
:func:`write_mot` does with them), and :func:`align_times` puts one table on the times of
another when the two round their times differently (0.007 s against 0.0066667 s).
"""

import re
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd

from .._checks import (as_float_array, check_flag, check_float_format, check_regular_file,
                       check_rotation_matrix, check_scalar, warn)
from ..rigid_body.cardan import compose, decompose

# A header longer than this (lines, or bytes per line) has no 'endheader': not a .mot file.
_HEADER_LINES = 10_000
_LINE_LIMIT = 1 << 20
#: Blank lines allowed between 'endheader' and the column labels.
_BLANK_LINES = 10
# Field texts read as missing data besides the empty field.
_NA_TEXTS = ["", "NaN", "nan", "NAN", "-NaN", "-nan", "-NAN"]


def _error(path, line, message):
    return ValueError(f"{path}, line {line}: {message}")


def _parse_yes_no(text):
    value = text.strip().lower()
    if value in ("yes", "true", "1"):
        return True
    if value in ("no", "false", "0"):
        return False
    return None


def read_mot(path):
    r"""Read an OpenSim motion or storage file (.mot, .sto).

    Parameters
    ----------
    path : str or path-like
        The ``.mot`` or ``.sto`` file.

    Returns
    -------
    pandas.DataFrame
        One row per instant, indexed by the ``time`` column (seconds, index named
        ``'time'``); one float column per other label, in file order. ``df.attrs``
        holds ``'name'`` (the first header line, e.g. ``'Coordinates'``),
        ``'in_degrees'`` (True/False from ``inDegrees=yes/no``, None if the header does
        not say), ``'header'`` (every ``key=value`` header line, values as text) and
        ``'description'`` (the other header lines, a list of str).

    Raises
    ------
    ValueError
        With the file name and the line number: no ``endheader`` line within the first
        10,000 lines, no labels line, a first label other than ``time``, empty or
        duplicate labels, a row with more or fewer fields than labels, a field that is
        not a number (or is infinite), a time that is missing. Also if `path` is a
        directory, a device or a pipe.

    Warns
    -----
    UserWarning
        Once per file: ``nRows`` or ``nColumns`` disagree with the table (all rows are
        read); the time does not increase; the last line does not end with a line break
        (its last value may be cut short and is set to NaN; the row is left out if
        its time may be cut).

    Notes
    -----
    Rows are parsed with :func:`pandas.read_csv` (C engine). Fields are separated by
    tabs; a file without any tab in its labels line (older SIMM ``.mot`` files) is split
    on runs of spaces instead. Values may be padded with spaces, as OpenSim writes
    them; ``NaN`` (any case) is missing data.

    References
    ----------
    .. [1] OpenSim documentation, "Storage (.sto) files" and "Motion (.mot) files";
       the reader is ``STOFileAdapter`` in OpenSim/Common.

    Examples
    --------
    >>> import os, tempfile
    >>> from bmc_functions import read_mot
    >>> text = ("Coordinates\nversion=1\nnRows=2\nnColumns=3\ninDegrees=yes\n"
    ...         "endheader\n"
    ...         "time\tknee_angle_r\tankle_angle_r\n"
    ...         "      0.00000000\t     12.50000000\t     -3.25000000\n"
    ...         "      0.01000000\t     13.00000000\t     -3.00000000\n")
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "ik.mot")
    ...     with open(path, "w") as file:
    ...         _ = file.write(text)
    ...     df = read_mot(path)
    >>> print(df.attrs["name"], df.attrs["in_degrees"], list(df.columns))
    Coordinates True ['knee_angle_r', 'ankle_angle_r']
    >>> print(df["knee_angle_r"].to_numpy(), df.index.to_numpy())
    [12.5 13. ] [0.   0.01]
    """
    check_regular_file(path, ".mot/.sto")
    path = Path(path)
    with open(path, "rb") as file:
        header = _read_header(file, path)
        labels, tabbed, number = _read_labels(file, path, len(header) + 2)
        first_row = number + 1
        last_line = _last_line(file)
        values = _read_values(file, path, labels, tabbed, first_row)
    messages = []
    if last_line.strip() and not last_line.endswith(b"\r") and len(values):
        values, message = _drop_cut_values(values, last_line, labels, tabbed)
        if message:
            messages.append(message)
    time = values[:, 0]
    rows = np.flatnonzero(np.isnan(time))
    if rows.size:
        raise _error(path, first_row + rows[0], "no time value (a blank or short line?)")
    rows = np.flatnonzero(np.isinf(values).any(axis=1))
    if rows.size:
        raise _error(path, first_row + rows[0], "infinite value; missing data is NaN")
    name, meta, description = _parse_header(header)
    lower = {key.lower(): value for key, value in meta.items()}
    for key, count in (("nrows", len(values)), ("ncolumns", len(labels))):
        if key in lower and lower[key].strip() != str(count):
            messages.append(f"the header says {key[0]}{key[1:].capitalize()} = "
                            f"{lower[key]} but the table has {count}")
    if len(time) > 1 and (np.diff(time) <= 0).any():
        i = int(np.argmax(np.diff(time) <= 0))
        messages.append(f"the time does not increase at line {first_row + i + 1} "
                        f"({time[i]:g} then {time[i + 1]:g})")
    if messages:
        warn(f"{path}: " + "; ".join(messages), UserWarning)
    df = pd.DataFrame(values[:, 1:], columns=pd.Index(labels[1:]),
                      index=pd.Index(time.copy(), name="time"))
    df.attrs = {"name": name,
                "in_degrees": _parse_yes_no(lower["indegrees"]) if "indegrees" in lower
                else None,
                "header": meta, "description": description}
    return df


def _read_header(file, path):
    """The header lines before 'endheader' (text, line ends removed); the file is left
    after 'endheader'. Bounded: a file without 'endheader' is refused."""
    header = []
    while True:
        line = file.readline(_LINE_LIMIT + 1)
        number = len(header) + 1
        if not line:
            raise _error(path, number, "the file ends before the line 'endheader' "
                         "that closes an OpenSim header")
        if len(line) > _LINE_LIMIT or number > _HEADER_LINES:
            raise _error(path, number, f"no line 'endheader' in the first "
                         f"{_HEADER_LINES} lines (is it an OpenSim .mot/.sto file?)")
        text = line.decode("utf-8", errors="replace").strip("\r\n")
        if text.strip().lower() == "endheader":
            return header
        header.append(text)


def _read_labels(file, path, number):
    """(labels, whether the fields are tab-separated, its line number) of the labels line,
    the first line from `number` on that is not blank (OpenSim's own external-loads files
    have a blank line after 'endheader'); the file is left at the first row."""
    labels_line = file.readline(_LINE_LIMIT + 1).decode("utf-8", errors="replace")
    for _ in range(_BLANK_LINES):
        if labels_line.strip() or not labels_line:
            break
        number += 1
        labels_line = file.readline(_LINE_LIMIT + 1).decode("utf-8", errors="replace")
    if not labels_line.strip():
        raise _error(path, number, "expected the column labels ('time' then one label "
                     "per column) after 'endheader'")
    if not labels_line.endswith("\n"):  # a label may be cut short
        raise _error(path, number, "the file ends in the column labels line (is it cut?)")
    labels_line = labels_line.rstrip("\r\n")
    tabbed = "\t" in labels_line
    labels = [label.strip() for label in
              (labels_line.split("\t") if tabbed else labels_line.split())]
    while tabbed and len(labels) > 1 and not labels[-1]:  # trailing tabs
        labels.pop()
    if labels[0].lower() != "time":
        raise _error(path, number, f"the first column label must be 'time'; got "
                     f"{labels[0]!r}")
    if not all(labels):
        raise _error(path, number, f"column {labels.index('') + 1} has no label")
    duplicates = sorted(label for label, count in Counter(labels).items() if count > 1)
    if duplicates:
        raise _error(path, number, f"duplicate column labels: {', '.join(duplicates)}")
    return labels, tabbed, number


def _last_line(file):
    """The end of the file after its last line break (empty if it ends with one), read
    from the end (at most a line's limit); the file position is kept."""
    data_offset = file.tell()
    size = file.seek(0, 2)
    last_line = b""
    if size > data_offset:
        file.seek(max(data_offset, size - _LINE_LIMIT))
        last_line = file.read().rsplit(b"\n", 1)[-1]
    file.seek(data_offset)
    return last_line


def _read_values(file, path, labels, tabbed, first_row):
    """The rows from the file's position as a (rows, labels) float array; refuse rows
    with fewer or more fields than labels, or fields that are not numbers."""
    width = len(labels)
    data_offset = file.tell()
    options = dict(header=None, sep="\t" if tabbed else r"\s+", skipinitialspace=True,
                   keep_default_na=False, na_values=_NA_TEXTS, skip_blank_lines=True,
                   engine="c")
    try:
        table = pd.read_csv(file, dtype=np.float64, **options)
    except pd.errors.EmptyDataError:
        table = pd.DataFrame(np.empty((0, width)))
    except ValueError as err:  # (pandas' ParserError is a ValueError)
        file.seek(data_offset)
        raise _locate_problem(path, file, labels, first_row, options, err) from None
    file.seek(data_offset)
    short = _first_short_row(file.read(), width, tabbed)
    if short is not None:  # pandas pads a short row with NaN: the values would shift
        line, count = short
        raise _error(path, first_row + line, f"the row has {count} fields for the {width} "
                     "column labels (a value left out? missing data is written NaN)")
    if table.shape[1] > width:  # trailing tabs, or fields without a label
        extra = table.iloc[:, width:].notna().any(axis=1).to_numpy()
        if extra.any():
            raise _error(path, first_row + int(np.argmax(extra)), f"the row has more fields "
                         f"than the {width} column labels")
        table = table.iloc[:, :width]
    values = table.to_numpy()
    if values.shape[1] < width:  # only a last line cut short (the check above): NaN
        values = np.hstack([values, np.full((len(values), width - values.shape[1]), np.nan)])
    return values


def _drop_cut_values(values, last_line, labels, tabbed):
    """`values` without what may be cut short in a last line without a line break
    (31.25 written, 3 left: never read it as 3), and the message saying so (or '')."""
    fields = last_line.split(b"\t") if tabbed else last_line.split()
    complete = len(fields) - 1 if last_line[-1:] not in (b"\t", b" ") else len(fields)
    if complete < 1:  # the time itself may be cut
        return values[:-1], ("the last line does not end with a line break (is the file "
                             "cut?) and stops in its time: the row was left out")
    cut = [label for label, value in zip(labels[complete:], values[-1, complete:])
           if not np.isnan(value)]
    values[-1, complete:] = np.nan
    if not cut:
        return values, ""
    return values, ("the last line does not end with a line break (is the file cut?): "
                    "its last value may be cut short, so these columns of that row were "
                    f"set to NaN: {', '.join(cut)}")


def _parse_header(header):
    """(name, key=value lines as a dict, the other lines) of the header lines."""
    named = bool(header) and "=" not in header[0]
    meta, description = {}, []
    for line in header[1:] if named else header:
        key, sep, value = line.partition("=")
        if sep and key.strip() and " " not in key.strip():
            meta[key.strip()] = value.strip()
        elif line.strip():
            description.append(line.strip())
    return (header[0].strip() if named else ""), meta, description


def _first_short_row(data, width, tabbed):
    """(line, fields) of the first non-blank row with fewer than `width` fields, counted
    from the first data line; None if there is none. A last line without a line break
    is left to the check for a file cut short. Vectorized over the bytes of the rows."""
    codes = np.frombuffer(data, dtype=np.uint8)
    ends = np.flatnonzero(codes == 10)            # the line breaks of complete lines
    if not ends.size:
        return None
    starts = np.r_[0, ends[:-1] + 1]
    space = np.isin(codes, np.frombuffer(b" \t\r\n\v\f", dtype=np.uint8))
    if tabbed:       # a field per tab, plus one (an empty field is NaN, still a field)
        marks = codes == 9
        extra = 1
    else:            # runs of spaces: count where a word starts
        marks = ~space & np.r_[True, space[:-1]]
        extra = 0
    count = np.r_[0, np.cumsum(marks)]
    filled = np.r_[0, np.cumsum(~space)]
    fields = count[ends] - count[starts] + extra
    blank = filled[ends] == filled[starts]
    short = np.flatnonzero((fields < width) & ~blank)
    if not short.size:
        return None
    return int(short[0]), int(fields[short[0]])


def _locate_problem(path, file, labels, first_row, options, err):
    """The ValueError to raise when pandas could not parse the rows as numbers."""
    match = re.search(r"Expected (\d+) fields in line (\d+), saw (\d+)", str(err))
    if match:  # a row longer than the first one
        expected, line, saw = (int(group) for group in match.groups())
        return _error(path, first_row + line - 1, f"the row has {saw} fields where the "
                      f"rows before have {expected} (for {len(labels)} column labels)")
    text = pd.read_csv(file, dtype=str, **options)
    missing = [text.lower() for text in _NA_TEXTS]
    for j in range(min(len(labels), text.shape[1])):  # loop over columns, not rows
        column = text.iloc[:, j].fillna("").str.strip()
        empty = column.str.lower().isin(missing)
        numbers = pd.to_numeric(column.where(~empty), errors="coerce")
        bad = np.flatnonzero(numbers.isna().to_numpy() & ~empty.to_numpy())
        if bad.size:
            i = int(bad[0])
            return _error(path, first_row + i, f"column {j + 1} ({labels[j]!r}) is not a "
                          f"number: {column.iloc[i]!r}")
    return ValueError(f"{path}: the rows could not be read as numbers ({err})")


def write_mot(df, path, *, in_degrees=None, name=None, float_format=None):
    r"""Write a table indexed by time to an OpenSim motion file (.mot / .sto).

    Parameters
    ----------
    df : pandas.DataFrame
        One row per instant, indexed by time in seconds (increasing). Either the joint
        angles of the lower-limb pipeline as they come (:meth:`LowerLimbModel.angles`:
        columns ``(joint, side, angle)``, ``attrs['units']`` 'deg'), written under
        OpenSim's coordinate names by :func:`opensim_coordinates`; or one numeric column
        per coordinate, labels non-empty strings without tabs or line breaks (e.g.
        ``'knee_angle_r'``). NaN is written as ``NaN``.
    path : str or path-like
        The file to write (overwritten if it exists).
    in_degrees : bool, optional
        Whether angles are in degrees (``inDegrees=yes``); default
        ``df.attrs['in_degrees']``, else ``df.attrs['units']`` ('deg' or 'rad').
        Required one way or the other: OpenSim converts the angles with it.
    name : str, optional
        The first header line; default ``df.attrs['name']``, else the file's stem.
    float_format : str, optional
        printf-style floating-point format of the values, e.g. ``'%.8f'`` (OpenSim's
        own); default None writes the shortest text that reads back to the same float
        (the data's full precision: an exact round trip). The time is written with it
        only when that keeps every time within 0.5 us, otherwise exactly.

    Raises
    ------
    ValueError
        If the labels are not unique non-empty strings without tabs or line breaks (or
        one is ``time``), the columns have two levels or more than three, the rows have
        several index levels (several trials: write one trial per file), a value or a
        time is not a finite number (NaN values are allowed), the time does not
        increase, the name or the file name contains a line break, or `float_format` is
        not one floating-point conversion (``'%d'`` would truncate every value).
    TypeError
        If `df` is not a DataFrame, holds booleans, or `in_degrees` is not a bool.

    Notes
    -----
    The layout is OpenSim's (``STOFileAdapter``): the name, ``version=1``,
    ``nRows=<n>``, ``nColumns=<columns + 1>``, ``inDegrees=yes|no``, ``endheader``, the
    labels ``time`` then the columns, then one tab-separated row per instant.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np, pandas as pd
    >>> from bmc_functions import read_mot, write_mot
    >>> df = pd.DataFrame({"knee_angle_r": [12.5, 13.0, np.nan],
    ...                    "hip_flexion_r": [30.25, 31.0, 31.5]},
    ...                   index=pd.Index([0.0, 0.01, 0.02], name="time"))
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "angles.mot")
    ...     write_mot(df, path, in_degrees=True, name="Coordinates")
    ...     with open(path) as file:
    ...         lines = file.read().splitlines()
    ...     back = read_mot(path)
    >>> print(lines[:7])
    ['Coordinates', 'version=1', 'nRows=3', 'nColumns=3', 'inDegrees=yes', 'endheader',
     'time\tknee_angle_r\thip_flexion_r']
    >>> print(back.equals(df), back.attrs["in_degrees"])
    True True

    The pipeline's angles as they come (here two frames of a right leg):

    >>> columns = pd.MultiIndex.from_tuples([("hip", "right", "flexion"),
    ...                                      ("knee", "right", "flexion"),
    ...                                      ("ankle", "right", "dorsiflexion")])
    >>> angles = pd.DataFrame([[30.0, 5.0, 2.0], [31.0, 6.5, 1.0]], columns=columns,
    ...                       index=pd.Index([0.0, 0.01], name="time"))
    >>> angles.attrs["units"] = "deg"
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     write_mot(angles, os.path.join(folder, "walk.mot"))
    ...     back = read_mot(os.path.join(folder, "walk.mot"))
    >>> print(list(back.columns), back.attrs["in_degrees"])
    ['hip_flexion_r', 'knee_angle_r', 'ankle_angle_r'] True
    """
    if not isinstance(df, pd.DataFrame):
        raise TypeError(f"df must be a pandas DataFrame indexed by time; got "
                        f"{type(df).__name__}")
    if df.index.nlevels != 1:
        raise ValueError(f"df has {df.index.nlevels} row index levels "
                         f"{list(df.index.names)}; a .mot file holds one trial indexed by "
                         "time: write one file per trial, e.g. df.loc['walk1']")
    if df.columns.nlevels == 3:
        df = opensim_coordinates(df)
    labels = _column_labels(df)
    if any(dtype.kind == "b" for dtype in df.dtypes):
        raise TypeError("df must hold numbers; got boolean columns")
    values = as_float_array(df.to_numpy(), "df")
    if np.isinf(values).any():
        raise ValueError("df contains infinite values; use NaN for missing data")
    time = _check_time_index(df, "df")
    if len(time) > 2 and np.median(np.diff(time)) >= MAX_TIME_STEP:
        warn(f"df.index (time) steps by {np.median(np.diff(time)):.4g} (median), "
             f"{1 / np.median(np.diff(time)):.3g} Hz if in seconds: is it in ms or "
             f"frame numbers? OpenSim reads the time column in seconds",
             RuntimeWarning)
    in_degrees = _in_degrees(in_degrees, df.attrs)
    file_name = str(path)
    if re.search(r"[\r\n]", file_name):
        raise ValueError(f"path: the file name must not contain a line break; got "
                         f"{file_name!r}")
    if name is None:
        name = df.attrs.get("name") or Path(file_name).stem
    if not isinstance(name, str) or re.search(r"[\r\n]", name) or "=" in name:
        raise ValueError(f"name must be one line of text without '='; got {name!r}")
    head = [name, "version=1", f"nRows={len(time)}", f"nColumns={len(labels) + 1}",
            f"inDegrees={'yes' if in_degrees else 'no'}", "endheader",
            "\t".join(["time", *labels])]
    table = pd.DataFrame(values, columns=range(len(labels)))
    table.insert(0, "time", _time_column(time, float_format))
    body = table.to_csv(sep="\t", header=False, index=False, na_rep="NaN",
                        float_format=float_format, lineterminator="\n")
    with open(path, "w", encoding="utf-8", newline="\n") as file:
        file.write("\n".join(head) + "\n" + body)


def _column_labels(df):
    """The labels of `df`'s one column level: unique non-empty strings without tabs,
    line breaks or padding, other than 'time'."""
    if df.columns.nlevels != 1:
        raise ValueError(f"df has {df.columns.nlevels} column levels; a .mot file has one "
                         "label per column: flatten them first, e.g. df.columns = "
                         "['_'.join(c) for c in df.columns] (or give the pipeline's "
                         "(joint, side, angle) columns as they come)")
    labels = list(df.columns)
    for label in labels:  # loop over columns, not rows
        if (not isinstance(label, str) or not label.strip() or label != label.strip()
                or re.search(r"[\t\n\r]", label) or label.lower() == "time"):
            raise ValueError(f"df: column label {label!r} must be a non-empty string "
                             "without tabs, line breaks or padding spaces, other than "
                             "'time'")
    duplicates = sorted(label for label, count in Counter(labels).items() if count > 1)
    if duplicates:
        raise ValueError(f"df: duplicate column labels: {', '.join(duplicates)}")
    return labels


def _in_degrees(in_degrees, attrs):
    """`in_degrees`, else what ``attrs`` says ('in_degrees', else 'units'); refuse a
    contradiction between the two, or neither."""
    if in_degrees is not None:
        in_degrees = check_flag(in_degrees, "in_degrees")
    stated = attrs.get("in_degrees")
    if stated is None:
        stated = _UNIT_DEGREES.get(str(attrs.get("units")).strip().lower())
    if in_degrees is not None and stated is not None and in_degrees != bool(stated):
        raise ValueError(f"in_degrees={in_degrees} contradicts df.attrs (units "
                         f"{attrs.get('units', attrs.get('in_degrees'))!r}: in "
                         f"{'degrees' if stated else 'radians'}); convert the angles or "
                         f"leave in_degrees out")
    if in_degrees is None:
        in_degrees = stated
        if in_degrees is None:
            raise ValueError("in_degrees: df.attrs has no 'in_degrees' and no 'units' "
                             "('deg' or 'rad'); pass in_degrees=True (angles in degrees) "
                             "or False (radians)")
    return bool(in_degrees)


def _time_column(time, float_format):
    """The time column: `time` itself (written exactly) when `float_format` is None or
    keeps every time within 0.5 us, else the shortest exact text of each time ('%.2f'
    would merge the times of neighbouring frames at 200 Hz)."""
    if float_format is None:
        return time
    check_float_format(float_format)
    text = np.char.mod(float_format, time)
    if len(time) and np.abs(text.astype(float) - time).max() > 5e-7 * (1 + 1e-9):
        text = np.array([repr(float(t)) for t in time])  # the shortest exact text
    return text


_UNIT_DEGREES = {"deg": True, "degree": True, "degrees": True, "rad": False,
                 "radian": False, "radians": False}


#: A median time step (s) from which write_mot warns that the index is not in seconds
#: (a 1 Hz motion file is no motion capture; ms or frame numbers are).
MAX_TIME_STEP = 1.0


def _check_time_index(df, name):
    """The time index of `df` as floats: numbers, finite, increasing."""
    if df.index.dtype.kind in "mM":
        raise ValueError(f"{name}.index (time) must hold the time in seconds as numbers; "
                         f"got dtype {df.index.dtype}")
    time = as_float_array(df.index.to_numpy(), f"{name}.index (time)")
    if not np.isfinite(time).all():
        raise ValueError(f"{name}.index (time) must hold finite times in seconds")
    if len(time) > 1 and (np.diff(time) <= 0).any():
        i = int(np.argmax(np.diff(time) <= 0))
        raise ValueError(f"{name}.index (time) must increase; got {time[i]:g} then "
                         f"{time[i + 1]:g} at rows {i} and {i + 1}")
    return time


# The pipeline's angles -> the coordinates of OpenSim's gait models (gait2392, Rajagopal
# 2015 [1]_ of opensim_coordinates), where the two mean the same rotation with the same sign.
_OPENSIM_NAMES = {
    ("hip", "flexion"): "hip_flexion", ("hip", "adduction"): "hip_adduction",
    ("hip", "rotation"): "hip_rotation", ("knee", "flexion"): "knee_angle",
    ("ankle", "dorsiflexion"): "ankle_angle",
}
_PELVIS = ("tilt", "obliquity", "rotation")


def opensim_coordinates(angles):
    r"""The lower-limb pipeline's angles under the coordinate names of OpenSim's models.

    Parameters
    ----------
    angles : pandas.DataFrame
        Joint angles in degrees as :meth:`LowerLimbModel.angles` returns them: indexed by
        time, columns ``(joint, side, angle)``, ``attrs['units']`` 'deg' (and
        ``attrs['lab_frame']`` for the pelvis, when present).

    Returns
    -------
    pandas.DataFrame
        Indexed by time; one column per coordinate (degrees), in the order of the table
        below, right side before left; ``attrs``: ``'in_degrees'`` True, ``'units'``
        'deg', ``'name'`` 'Coordinates', and ``'source_columns'`` (coordinate ->
        the pipeline's column).

    Raises
    ------
    ValueError
        If `angles` does not have three column levels, or ``attrs['units']`` says
        radians (convert with ``np.rad2deg`` first), or it has pelvis angles of an
        unknown sequence (see Notes: ``attrs['model']`` or ``attrs['pelvis_sequence']``
        says which).
    TypeError
        If `angles` is not a DataFrame.

    Notes
    -----
    The names, and what a positive value means in both (right and left alike):

    - pelvis (converted, see below): ``pelvis_tilt`` (**posterior** tilt),
      ``pelvis_list`` (right side **down**), ``pelvis_rotation`` (right side forwards);
    - ``(hip, side, flexion | adduction | rotation)``: ``hip_flexion_r``,
      ``hip_adduction_r``, ``hip_rotation_r`` (flexion, adduction, internal rotation;
      ``_l`` on the left);
    - ``(knee, side, flexion)``: ``knee_angle_r`` (flexion [1]_);
    - ``(ankle, side, dorsiflexion)``: ``ankle_angle_r`` (dorsiflexion);
    - no coordinate in OpenSim's gait models: ``knee_adduction_r``, ``knee_rotation_r``,
      ``ankle_inversion_r``, ``ankle_rotation_r`` (adduction, internal rotation,
      inversion, internal rotation).

    The hip, knee and ankle angles keep their values: OpenSim's hip is a ball joint
    turned by flexion (about the pelvis' z), adduction, then rotation (about the femur's
    y), the sequence of the joint coordinate system here, and its left-side coordinates
    carry the same clinical sign as the right ones. The knee and ankle of OpenSim's gait
    models have one degree of freedom each, so the knee's adduction and rotation and the
    ankle's inversion and rotation have no coordinate there: they are written under the
    names above, which OpenSim ignores (``subtalar_angle`` is a joint of the model, not
    the ankle complex's inversion here, so it is not used). Other columns are written as
    ``<joint>_<angle>_<r|l>``. Note that in gait2392 (OpenSim's older model) a flexed
    knee reads a **negative** ``knee_angle``; in Rajagopal 2015 (and in the real running
    trial's inverse kinematics in ``data/real/ik_output_run.mot``) it reads positive, as
    here.

    The pelvis is converted, not renamed: OpenSim turns it relative to the ground by
    ``pelvis_tilt`` about z, then ``pelvis_list`` about x, then ``pelvis_rotation``
    about y (intrinsic ZXY, right-hand signs), where the pipeline reports Baker's
    rotation-obliquity-tilt relative to the direction of progression
    (:func:`pelvis_angles`). So the pelvis orientation is rebuilt from the three angles
    of one side, :math:`R = R_{lab} R_y(\gamma) R_x(\beta) R_z(\alpha)` with
    :math:`\alpha = -\text{tilt}`, :math:`\beta = -\text{obliquity}_{right}`
    (:math:`+\text{obliquity}_{left}`), :math:`\gamma = \text{rotation}_{right}`
    (:math:`-\text{rotation}_{left}`) and :math:`R_{lab}` = ``attrs['lab_frame']`` (the
    identity when absent), and decomposed as :math:`R = R_z R_x R_y` — exact, where
    changing signs alone would leave the second-order difference between the sequences
    (up to 3.9 degrees on the real running trial). The right side's angles are used
    when present.

    Plug-in Gait's angles (``attrs['model']`` starting with ``'Plug-in Gait'``, as
    :meth:`PlugInGait.angles` sets it) turn the pelvis tilt-obliquity-rotation from the
    direction of progression, OpenSim's own order: they are renamed with the signs of
    OpenSim's axes, exactly, ``pelvis_tilt`` = -tilt, ``pelvis_list`` =
    -obliquity (right) = obliquity (left), ``pelvis_rotation`` = rotation (right) =
    -rotation (left). Which of the two sequences the pelvis angles follow is read from
    ``attrs`` (``'model'``; the ISB pipeline's ``'pelvis_sequence'`` or
    ``'lab_frame'``), else inferred from a foot progression angle (Plug-in Gait's only);
    without either (``attrs`` lost, e.g. by ``pd.concat``) the pelvis is refused.

    On a real running trial (``data/real/``) against OpenSim's inverse kinematics
    (Rajagopal 2015 model), the columns written here correlate with OpenSim's at
    r >= 0.98 for the hip flexion, knee and ankle angles (offsets of 0 to 6 degrees: the
    model's joints are not the ISB segment frames; tests/test_opensim_io.py).

    References
    ----------
    .. [1] Rajagopal A, Dembia CL, DeMers MS, Delp DD, Hicks JL, Delp SL (2016)
       Full-body musculoskeletal model for muscle-driven simulation of human gait. IEEE
       Trans Biomed Eng 63:2068-2079.
    .. [2] Delp SL et al. (2007) OpenSim: open-source software to create and analyze
       dynamic simulations of movement. IEEE Trans Biomed Eng 54:1940-1950.
    .. [3] Baker R (2001) Pelvic angles: a mathematically rigorous definition which is
       consistent with a conventional clinical understanding of the terms. Gait Posture
       13:1-6.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> from bmc_functions import opensim_coordinates
    >>> columns = pd.MultiIndex.from_tuples(
    ...     [("pelvis", "right", a) for a in ("tilt", "obliquity", "rotation")]
    ...     + [("knee", "right", "flexion"), ("knee", "right", "adduction")])
    >>> angles = pd.DataFrame([[12.0, 0.0, 0.0, 20.0, 1.5]], columns=columns,
    ...                       index=pd.Index([0.0], name="time"))
    >>> angles.attrs = {"units": "deg", "pelvis_sequence": "YXZ"}  # the ISB pipeline's
    >>> coordinates = opensim_coordinates(angles)
    >>> print(coordinates.round(6).iloc[0].to_dict())
    {'pelvis_tilt': -12.0, 'pelvis_list': 0.0, 'pelvis_rotation': 0.0, 'knee_angle_r': 20.0,
     'knee_adduction_r': 1.5}
    """
    if not isinstance(angles, pd.DataFrame):
        raise TypeError(f"angles must be a pandas DataFrame; got {type(angles).__name__}")
    if angles.columns.nlevels != 3:
        raise ValueError(f"angles must have the columns (joint, side, angle) of "
                         f"LowerLimbModel.angles; got {angles.columns.nlevels} level(s)")
    units = str(angles.attrs.get("units", "deg")).strip().lower()
    if _UNIT_DEGREES.get(units) is False:
        raise ValueError(f"angles.attrs['units'] is {angles.attrs['units']!r}; the "
                         "pipeline's angles are in degrees: convert them first "
                         "(np.rad2deg) and set attrs['units'] = 'deg'")
    columns = list(angles.columns)
    duplicates = sorted({str(column) for column in columns if columns.count(column) > 1})
    if duplicates:
        raise ValueError(f"angles has duplicate columns: {', '.join(duplicates)}")
    values = {column: as_float_array(angles[column].to_numpy(), f"angles[{column!r}]")
              for column in columns}
    out, source = {}, {}
    pelvis_sides = [side for side in ("right", "left")
                    if all(("pelvis", side, angle) in columns for angle in _PELVIS)]
    pelvis = [column for column in columns if column[0] == "pelvis"]
    # Plug-in Gait's pelvis turns tilt-obliquity-rotation, OpenSim's order: renamed,
    # not converted (the conversion is for the ISB pipeline's reverse sequence)
    in_opensim_order = (_pelvis_in_opensim_order(angles) if pelvis_sides else
                        str(angles.attrs.get("model", "")).startswith("Plug-in Gait"))
    if pelvis and not pelvis_sides:
        got = [column[1:] for column in pelvis]
        if in_opensim_order:
            raise ValueError(f"angles: the pelvis needs its tilt, obliquity and rotation "
                             f"of one side; got {got}")
        raise ValueError(f"angles: the pelvis is converted to OpenSim's sequence from its "
                         f"tilt, obliquity and rotation of one side; got only {got}")
    if pelvis_sides:
        side = pelvis_sides[0]
        tilt, obliquity, rotation = (values["pelvis", side, angle] for angle in _PELVIS)
        if in_opensim_order:
            pelvis_coordinates = _pelvis_renamed(tilt, obliquity, rotation, side)
        else:
            pelvis_coordinates = _pelvis_converted(tilt, obliquity, rotation, side,
                                                   angles.attrs.get("lab_frame"))
        for k, name in enumerate(("pelvis_tilt", "pelvis_list", "pelvis_rotation")):
            out[name] = pelvis_coordinates[:, k]
            source[name] = ("pelvis", side, _PELVIS[k])
    extras = [("knee", "adduction"), ("knee", "rotation"), ("ankle", "inversion"),
              ("ankle", "rotation")]
    order = list(_OPENSIM_NAMES) + extras
    for side in ("right", "left"):
        for joint, angle in order:
            if (joint, side, angle) in columns:
                name = _OPENSIM_NAMES.get((joint, angle), f"{joint}_{angle}")
                out[f"{name}_{side[0]}"] = values[joint, side, angle]
                source[f"{name}_{side[0]}"] = (joint, side, angle)
    for column in columns:   # anything else keeps a readable name
        joint, side, angle = (str(level) for level in column)
        if column in source.values() or joint == "pelvis" and pelvis_sides:
            continue
        name = f"{joint}_{angle}_{side[0]}" if side in ("right", "left") else \
            "_".join((joint, side, angle))
        out[name] = values[column]
        source[name] = column
    result = pd.DataFrame(out, index=angles.index.copy())
    result.attrs = {"name": "Coordinates", "in_degrees": True, "units": "deg",
                    "source_columns": source}
    return result


def _pelvis_in_opensim_order(angles):
    """Whether the pelvis angles of `angles` are Plug-in Gait's (tilt-obliquity-rotation,
    OpenSim's order) rather than the ISB pipeline's (rotation-obliquity-tilt).

    Said by ``attrs['model']`` (Plug-in Gait's) or ``attrs['pelvis_sequence']`` /
    ``attrs['lab_frame']`` (the ISB pipeline's); else inferred from a foot progression
    angle, which Plug-in Gait has and the ISB pipeline has not. Without any of these (the
    attrs lost, e.g. by pd.concat of tables whose attrs differ) the two sequences, 3 degrees
    apart in walking, cannot be told apart: refused.
    """
    attrs = angles.attrs
    if str(attrs.get("model", "")).startswith("Plug-in Gait"):
        return True
    if str(attrs.get("pelvis_sequence", "")).upper().startswith("YXZ") or \
            attrs.get("lab_frame") is not None:
        return False
    if any(column[0] == "foot" and column[2] == "progression" for column in angles.columns):
        return True
    raise ValueError("angles: the pelvis angles' sequence is unknown: angles.attrs has no "
                     "'model' (Plug-in Gait: tilt, obliquity, rotation) and no "
                     "'pelvis_sequence' (the ISB pipeline: 'YXZ', rotation, obliquity, "
                     "tilt), as after pd.concat, which drops attrs; say which: "
                     "angles.attrs['model'] = 'Plug-in Gait' or "
                     "angles.attrs['pelvis_sequence'] = 'YXZ'")


def _pelvis_converted(tilt, obliquity, rotation, side, lab_frame):
    """OpenSim's (pelvis_tilt, pelvis_list, pelvis_rotation), shape (n, 3), of the ISB
    pipeline's pelvis angles of `side`: the orientation rebuilt and decomposed Z-X-Y
    (see :func:`opensim_coordinates`); NaN where an angle is NaN."""
    sign = 1.0 if side == "right" else -1.0
    yxz = np.stack([sign * rotation, -sign * obliquity, -tilt], axis=-1)
    orientation = compose(np.nan_to_num(yxz), "YXZ", degrees=True)
    if lab_frame is not None:
        lab_frame = check_rotation_matrix(lab_frame, "angles.attrs['lab_frame']")
        if lab_frame.shape != (3, 3):
            raise ValueError(f"angles.attrs['lab_frame'] must be one 3 x 3 rotation "
                             f"matrix; got shape {lab_frame.shape}")
        orientation = lab_frame @ orientation
    zxy = decompose(orientation, "ZXY", degrees=True)
    zxy[np.isnan(yxz).any(axis=-1)] = np.nan
    return zxy


def _pelvis_renamed(tilt, obliquity, rotation, side):
    """OpenSim's (pelvis_tilt, pelvis_list, pelvis_rotation), shape (n, 3), of pelvis
    angles that turn tilt-obliquity-rotation (Plug-in Gait's, OpenSim's order) from
    x forward, y left, z up: the angles with the signs of OpenSim's axes (X forward,
    Y up, Z right), exactly; the left side's obliquity and rotation are mirrored."""
    mirror = 1.0 if side == "right" else -1.0
    return np.stack([-tilt, -mirror * obliquity, mirror * rotation], axis=-1)


def align_times(df, times, *, tolerance=None):
    r"""The rows of `df` at the times of another table, matched to the nearest time.

    Two tables of the same trial often round their times differently: a TRC file at
    150 Hz stores 0.007 s where OpenSim writes 0.00666667 s, so an exact join of the two
    finds almost no common time. This takes, for each of `times`, the row of `df`
    whose time is nearest, if it is within `tolerance`.

    Parameters
    ----------
    df : pandas.DataFrame
        Indexed by increasing time (s), e.g. :func:`opensim_coordinates` of the angles.
    times : array_like, pandas.Index or pandas.DataFrame
        The times wanted (s); a DataFrame stands for its index (e.g. :func:`read_mot` of
        OpenSim's result).
    tolerance : float, optional, keyword-only
        The largest time difference accepted (s). Default: a quarter of the median
        sample interval of `df` (rounding to the millisecond at 150 Hz moves a time
        by 0.33 ms, a quarter interval is 1.7 ms).

    Returns
    -------
    pandas.DataFrame
        One row per time of `times` (the index, named ``'time'``), `df`'s columns and
        ``attrs``; NaN where no row of `df` is within `tolerance`.

    Raises
    ------
    ValueError
        If a time index is not finite or not increasing, `df` has fewer than two rows
        and no `tolerance` is given, or `tolerance` is not a positive number.
    TypeError
        If `df` is not a DataFrame.

    Warns
    -----
    UserWarning
        Once per call, when some of `times` have no row of `df` within `tolerance`
        (e.g. they lie outside the trial): "3 of 122 times ...".

    Examples
    --------
    Our angles at the TRC's times (rounded to the millisecond) against OpenSim's at its
    own (1/150 s):

    >>> import numpy as np, pandas as pd
    >>> from bmc_functions import align_times
    >>> ours = pd.DataFrame({"knee_angle_r": [10.0, 11.0, 12.0, 13.0]},
    ...                     index=pd.Index([0.0, 0.007, 0.013, 0.02], name="time"))
    >>> opensim = pd.DataFrame({"knee_angle_r": [10.5, 11.5, 12.5, 13.5]},
    ...                        index=pd.Index(np.arange(4) / 150, name="time"))
    >>> ours.index.intersection(opensim.index).size     # an exact join: 2 of 4 times
    2
    >>> difference = align_times(ours, opensim) - opensim
    >>> print(difference["knee_angle_r"].to_numpy())
    [-0.5 -0.5 -0.5 -0.5]
    """
    if not isinstance(df, pd.DataFrame):
        raise TypeError(f"df must be a pandas DataFrame indexed by time; got "
                        f"{type(df).__name__}")
    if df.index.nlevels != 1:
        raise ValueError(f"df has {df.index.nlevels} row index levels; give one trial "
                         "indexed by time, e.g. df.loc['walk1']")
    own = _check_time_index(df, "df")
    wanted = times.index if isinstance(times, pd.DataFrame) else times
    wanted = as_float_array(np.asarray(wanted), "times")
    if wanted.ndim != 1 or not np.isfinite(wanted).all():
        raise ValueError(f"times must be a 1-D sequence of finite times (s); got shape "
                         f"{wanted.shape}")
    if tolerance is None:
        if len(own) < 2:
            raise ValueError("tolerance: df has fewer than two rows, so no sample interval "
                             "to take a quarter of; pass tolerance= (s)")
        tolerance = 0.25 * float(np.median(np.diff(own)))
    tolerance = check_scalar(tolerance, "tolerance", "a positive number of seconds",
                             minimum=0, strict=True)
    source = pd.DataFrame(df.to_numpy(), index=pd.Index(own), columns=df.columns)
    out = source.reindex(pd.Index(wanted), method="nearest", tolerance=float(tolerance))
    out.index = pd.Index(wanted, name="time")
    if len(own):
        nearest = own[np.clip(np.searchsorted(own, wanted), 1, len(own) - 1) - 1]
        upper = own[np.clip(np.searchsorted(own, wanted), 0, len(own) - 1)]
        matched = np.minimum(np.abs(nearest - wanted), np.abs(upper - wanted)) <= tolerance
    else:
        matched = np.zeros(len(wanted), dtype=bool)
    if (~matched).any():
        warn(f"align_times: {int((~matched).sum())} of {len(wanted)} times have no "
             f"row of df within {float(tolerance):.3g} s (e.g. {wanted[~matched][0]:g}"
             f" s; df spans {own[0] if len(own) else np.nan:g} to "
             f"{own[-1] if len(own) else np.nan:g} s): their rows are NaN"
             + ("; the times reach 100 times beyond df's: are they in ms or "
                "frames, not seconds?" if len(own) and own[-1] > 0
                and wanted.max() > 100 * own[-1] else ""),
             UserWarning)
    out.attrs = dict(df.attrs)
    return out
