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
exactly.
"""

import re
import warnings
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd

from ._checks import as_float_array
from .marker_io import _check_regular_file

# A header longer than this (lines, or bytes per line) has no 'endheader': not a .mot file.
_HEADER_LINES = 10_000
_LINE_LIMIT = 1 << 20
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
    _check_regular_file(path, ".mot/.sto")
    path = Path(path)
    with open(path, "rb") as file:
        header = []
        while True:  # the header, bounded: a file without 'endheader' is refused
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
                break
            header.append(text)
        labels_line = file.readline(_LINE_LIMIT + 1).decode("utf-8", errors="replace")
        labels_number = len(header) + 2
        if not labels_line.strip():
            raise _error(path, labels_number, "expected the column labels ('time' then "
                         "one label per column) after 'endheader'")
        if not labels_line.endswith("\n"):  # a label may be cut short
            raise _error(path, labels_number, "the file ends in the column labels line "
                         "(is it cut?)")
        data_offset = file.tell()
        file.seek(0, 2)
        size = file.tell()
        last_line = b""
        if size > data_offset:  # the end of the last line, for a file cut short
            file.seek(max(data_offset, size - _LINE_LIMIT))
            last_line = file.read().rsplit(b"\n", 1)[-1]

        labels_line = labels_line.rstrip("\r\n")
        tabbed = "\t" in labels_line
        labels = [label.strip() for label in
                  (labels_line.split("\t") if tabbed else labels_line.split())]
        while tabbed and len(labels) > 1 and not labels[-1]:  # trailing tabs
            labels.pop()
        if labels[0].lower() != "time":
            raise _error(path, labels_number, f"the first column label must be 'time'; "
                         f"got {labels[0]!r}")
        if not all(labels):
            k = labels.index("")
            raise _error(path, labels_number, f"column {k + 1} has no label")
        duplicates = sorted(label for label, n in Counter(labels).items() if n > 1)
        if duplicates:
            raise _error(path, labels_number, f"duplicate column labels: "
                         f"{', '.join(duplicates)}")

        width = len(labels)
        first_row = labels_number + 1
        file.seek(data_offset)
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
    if table.shape[1] > width:  # trailing tabs, or fields without a label
        extra = table.iloc[:, width:].notna().any(axis=1).to_numpy()
        if extra.any():
            raise _error(path, first_row + int(np.argmax(extra)), f"the row has more fields "
                         f"than the {width} column labels")
        table = table.iloc[:, :width]
    elif table.shape[1] < width and len(table):
        raise _error(path, first_row, f"the row has {table.shape[1]} fields for the "
                     f"{width} column labels")
    values = table.to_numpy()
    messages = []
    if last_line.strip() and not last_line.endswith(b"\r") and len(values):
        # no line break at the end: the last value may be cut short (31.25 written, 3
        # left): never read it as 3
        fields = last_line.split(b"\t") if tabbed else last_line.split()
        complete = len(fields) - 1 if last_line[-1:] not in (b"\t", b" ") else len(fields)
        if complete < 1:  # the time itself may be cut
            values = values[:-1]
            messages.append("the last line does not end with a line break (is the file "
                            "cut?) and stops in its time: the row was left out")
        else:
            cut = [label for label, value in zip(labels[complete:], values[-1, complete:])
                   if not np.isnan(value)]
            values[-1, complete:] = np.nan
            if cut:
                messages.append("the last line does not end with a line break (is the file "
                                "cut?): its last value may be cut short, so these columns "
                                f"of that row were set to NaN: {', '.join(cut)}")
    time = values[:, 0]
    rows = np.flatnonzero(np.isnan(time))
    if rows.size:
        raise _error(path, first_row + rows[0], "no time value (a blank or short line?)")
    rows = np.flatnonzero(np.isinf(values).any(axis=1))
    if rows.size:
        raise _error(path, first_row + rows[0], "infinite value; missing data is NaN")
    meta, description = {}, []
    for line in header[1:] if header and "=" not in header[0] else header:
        key, sep, value = line.partition("=")
        if sep and key.strip() and " " not in key.strip():
            meta[key.strip()] = value.strip()
        elif line.strip():
            description.append(line.strip())
    name = header[0].strip() if header and "=" not in header[0] else ""
    lower = {key.lower(): value for key, value in meta.items()}
    for key, count in (("nrows", len(values)), ("ncolumns", width)):
        if key in lower and lower[key].strip() != str(count):
            messages.append(f"the header says {key[0]}{key[1:].capitalize()} = "
                            f"{lower[key]} but the table has {count}")
    if len(time) > 1 and (np.diff(time) <= 0).any():
        i = int(np.argmax(np.diff(time) <= 0))
        messages.append(f"the time does not increase at line {first_row + i + 1} "
                        f"({time[i]:g} then {time[i + 1]:g})")
    if messages:
        warnings.warn(f"{path}: " + "; ".join(messages), UserWarning, stacklevel=2)
    df = pd.DataFrame(values[:, 1:], columns=pd.Index(labels[1:]),
                      index=pd.Index(time.copy(), name="time"))
    df.attrs = {"name": name,
                "in_degrees": _parse_yes_no(lower["indegrees"]) if "indegrees" in lower
                else None,
                "header": meta, "description": description}
    return df


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
        One row per instant, indexed by time in seconds (increasing); one numeric
        column per coordinate, labels non-empty strings without tabs or line breaks
        (OpenSim's coordinate names, e.g. ``'knee_angle_r'``). NaN is written as
        ``NaN``. For multi-level columns (e.g. joint angles ``(joint, side, angle)``),
        flatten them first, e.g. ``df.columns = ['_'.join(c) for c in df.columns]``.
    path : str or path-like
        The file to write (overwritten if it exists).
    in_degrees : bool, optional
        Whether angles are in degrees (``inDegrees=yes``); default
        ``df.attrs['in_degrees']``. Required one way or the other: OpenSim converts
        the angles with it.
    name : str, optional
        The first header line; default ``df.attrs['name']``, else the file's stem.
    float_format : str, optional
        printf-style format of the numbers, e.g. ``'%.8f'`` (OpenSim's own); default
        None writes the shortest text that reads back to the same float (exact
        round trip).

    Raises
    ------
    ValueError
        If the labels are not unique non-empty strings without tabs or line breaks (or
        one is ``time``), the columns have several levels, a value or a time is not a
        finite number (NaN values are allowed), the time does not increase, the name or
        the file name contains a line break, or `float_format` does not write a number.
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
    """
    if not isinstance(df, pd.DataFrame):
        raise TypeError(f"df must be a pandas DataFrame indexed by time; got "
                        f"{type(df).__name__}")
    if df.columns.nlevels != 1:
        raise ValueError(f"df has {df.columns.nlevels} column levels; a .mot file has one "
                         "label per column: flatten them first, e.g. df.columns = "
                         "['_'.join(c) for c in df.columns]")
    labels = list(df.columns)
    for label in labels:  # loop over columns, not rows
        if (not isinstance(label, str) or not label.strip() or label != label.strip()
                or re.search(r"[\t\n\r]", label) or label.lower() == "time"):
            raise ValueError(f"df: column label {label!r} must be a non-empty string "
                             "without tabs, line breaks or padding spaces, other than "
                             "'time'")
    duplicates = sorted(label for label, n in Counter(labels).items() if n > 1)
    if duplicates:
        raise ValueError(f"df: duplicate column labels: {', '.join(duplicates)}")
    if any(dtype.kind == "b" for dtype in df.dtypes):
        raise TypeError("df must hold numbers; got boolean columns")
    values = as_float_array(df.to_numpy(), "df")
    if np.isinf(values).any():
        raise ValueError("df contains infinite values; use NaN for missing data")
    if df.index.dtype.kind in "mM":
        raise ValueError(f"df.index (time) must hold the time in seconds as numbers; got "
                         f"dtype {df.index.dtype}")
    time = as_float_array(df.index.to_numpy(), "df.index (time)")
    if not np.isfinite(time).all():
        raise ValueError("df.index (time) must hold finite times in seconds")
    if len(time) > 1 and (np.diff(time) <= 0).any():
        i = int(np.argmax(np.diff(time) <= 0))
        raise ValueError(f"df.index (time) must increase; got {time[i]:g} then "
                         f"{time[i + 1]:g} at rows {i} and {i + 1}")
    if in_degrees is None:
        in_degrees = df.attrs.get("in_degrees")
        if in_degrees is None:
            raise ValueError("in_degrees: df.attrs has no 'in_degrees'; pass "
                             "in_degrees=True (angles in degrees) or False (radians)")
    if not isinstance(in_degrees, (bool, np.bool_)):
        raise TypeError(f"in_degrees must be True or False; got {in_degrees!r}")
    file_name = str(path)
    if re.search(r"[\r\n]", file_name):
        raise ValueError(f"path: the file name must not contain a line break; got "
                         f"{file_name!r}")
    if name is None:
        name = df.attrs.get("name") or Path(file_name).stem
    if not isinstance(name, str) or re.search(r"[\r\n]", name) or "=" in name:
        raise ValueError(f"name must be one line of text without '='; got {name!r}")
    if float_format is not None:
        from .marker_io import _check_float_format

        _check_float_format(float_format)
    head = [name, "version=1", f"nRows={len(time)}", f"nColumns={len(labels) + 1}",
            f"inDegrees={'yes' if in_degrees else 'no'}", "endheader",
            "\t".join(["time", *labels])]
    table = pd.DataFrame(values, columns=range(len(labels)))
    table.insert(0, "time", time)
    body = table.to_csv(sep="\t", header=False, index=False, na_rep="NaN",
                        float_format=float_format, lineterminator="\n")
    with open(path, "w", encoding="utf-8", newline="\n") as file:
        file.write("\n".join(head) + "\n" + body)
