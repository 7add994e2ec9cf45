r"""Marker trajectories in and out of files: TRC (text) and C3D (binary, optional).

Every reader returns the same shape of data, a :class:`pandas.DataFrame` with

* one row per frame, indexed by the time in seconds (index named ``'time'``);
* columns a two-level :class:`pandas.MultiIndex` ``(marker, coord)`` with coords
  ``'x'``, ``'y'``, ``'z'``, so that ``df['RTH1']`` is the (n_frames, 3) trajectory of
  marker RTH1 and ``df['RTH1'].to_numpy()`` is ready for :func:`svdt`;
* NaN where a marker was not seen (an empty field in a TRC file, an invalid point in a
  C3D file);
* ``df.attrs`` holding the file's metadata: ``'rate'`` (Hz, float), ``'units'`` (e.g.
  ``'mm'``), ``'frames'`` (the frame numbers, a list of int, one per row) and more (see
  :func:`read_trc`).

``df.attrs`` travels with the DataFrame through pandas operations unchanged, so after
slicing rows (``df.iloc[10:20]``) ``attrs['frames']`` still describes the whole file;
:func:`write_trc` then numbers the frames 1, 2, ... (see its Notes).

The TRC format (Motion Analysis Corp.) is tab-separated text: three header lines
(``PathFileType``; the keys ``DataRate CameraRate NumFrames NumMarkers Units
OrigDataRate OrigDataStartFrame OrigNumFrames``; their values), a labels line
(``Frame#  Time  marker1 _ _ marker2 _ _ ...``: each label is followed by two empty
fields), a coordinate line (``X1 Y1 Z1 X2 Y2 Z2 ...``), usually a blank line, then one row
per frame: frame number, time, and x, y, z of every marker.
"""

import codecs
import csv
import io
import os
import re
import stat
import struct
import tempfile
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd

from .._checks import as_float_array, check_finite_or_nan, check_flag, warn
from ._c3d_binary import check_c3d, read_isolated

#: Names of the coordinate level of the columns.
COORDS = ("x", "y", "z")

#: Keys of the second TRC header line, in the order the standard (and OpenSim) expects.
TRC_KEYS = ("DataRate", "CameraRate", "NumFrames", "NumMarkers", "Units",
            "OrigDataRate", "OrigDataStartFrame", "OrigNumFrames")

# Field texts read as missing data besides the empty field (some tools write NaN).
_NA_TEXTS = ["", "NaN", "nan", "NAN", "-NaN", "-nan"]



class _TrcError:
    """Build ValueErrors that name the file and the (1-based) line number."""

    def __init__(self, path):
        self.path = path

    def __call__(self, line, message):
        return ValueError(f"{self.path}, line {line}: {message}")


def _fields(line):
    """Fields of a tab-separated line with their padding spaces removed."""
    return [field.strip() for field in line.split("\t")]


def _nonempty(line):
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
        k = labels.index("")
        raise error(4, f"marker column {k + 1} (data fields {3 * k + 3}-{3 * k + 5}) has "
                    "no label")
    return labels


def _field_name(j, labels):
    """Describe 0-based data field `j` for a message."""
    if j == 0:
        return "Frame#"
    if j == 1:
        return "Time"
    k, c = divmod(j - 2, 3)
    label = labels[k] if k < len(labels) else f"unlabelled marker {k + 1}"
    return f"{label!r} {COORDS[c]}"


# Bytes of a TRC data block that end or pad fields.
_TAB, _LF, _CR = 9, 10, 13
# Bytes read at a time when scanning the data rows (the scan keeps one block, not the file).
_CHUNK = 1 << 24
# A header line longer than this is not a TRC header (a binary file, /dev/zero copied...).
_HEADER_LINE_LIMIT = 1 << 24
# Steps of the vectorized walk back over a row's trailing tabs before finishing by hand.
_TRAIL_STEPS = 64


class _Normalize(Exception):
    """The data rows hold spaces or lone carriage returns: read a normalized copy."""


def _check_regular_file(path, what):
    """Refuse directories, devices and pipes at once (reading them would never end)."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name (str or path-like); got "
                        f"{type(path).__name__}")
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise FileNotFoundError(f"path: no such file: {path}") from None
    if stat.S_ISDIR(mode):
        raise ValueError(f"path: {path} is a directory; expected a {what} file")
    if not stat.S_ISREG(mode):
        raise ValueError(f"path: {path} is not a regular file (a device, pipe or socket); "
                         f"expected a {what} file")


def _normalized_copy(raw, error, remove_spaces):
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
    text = b"".join(raw)
    try:
        text = text.decode("utf-8-sig")  # -sig: a byte-order mark is not part of line 1
    except UnicodeDecodeError:  # e.g. a Latin-1 file name in line 1
        text = text.removeprefix(codecs.BOM_UTF8).decode("latin-1")
    lines = text.split("\n")[:len(raw)]
    return [line.removesuffix("\r") for line in lines], offset


def _line_stats(part, end, base, line0, max_line, error):
    """Statistics of the lines of ``part[:end]`` (ending with a line feed), blank ones left
    out.

    Returns (numbers, starts, tabs, trailing, n_lines): each non-blank line's index (from
    the first line of the data block), the byte offset of its start, its number of tabs
    and the number of tabs in its trailing run of tabs (and carriage returns); and the
    number of lines.
    """
    if part.find(b" ", 0, end) >= 0 or (part.find(b"\r", 0, end) >= 0 and part.count(
            b"\r", 0, end) != part.count(b"\r\n", 0, end)):
        raise _Normalize
    a = np.frombuffer(part, dtype=np.uint8, count=end)
    ends = np.flatnonzero(a == _LF)
    starts = np.empty_like(ends)
    starts[0] = 0
    starts[1:] = ends[:-1] + 1
    long_lines = np.flatnonzero(ends - starts > max_line)
    if long_lines.size:
        i = long_lines[0]
        raise error(6 + line0 + i, f"the line is {ends[i] - starts[i]} bytes long; no row "
                    f"of this file needs more than {max_line} (is it a TRC file?)")
    # (a 16-bit sum is exact for lines shorter than 2**16 bytes, and twice as fast)
    dtype = np.uint16 if (ends - starts).max() < 2**16 else np.uint32
    tabs = np.add.reduceat((a == _TAB).view(np.uint8), starts, dtype=dtype).astype(np.int64)
    # Walk back from each line end over tabs and carriage returns, all lines at once.
    pos = ends - 1
    trailing = np.zeros(ends.size, dtype=np.int64)
    active = np.arange(ends.size)
    for _ in range(_TRAIL_STEPS):  # loop over trailing bytes, not over lines
        active = active[pos[active] >= starts[active]]
        if not active.size:
            break
        byte = a[pos[active]]
        padding = (byte == _TAB) | (byte == _CR)
        active = active[padding]
        trailing[active] += byte[padding] == _TAB
        pos[active] -= 1
    else:
        for i in active[pos[active] >= starts[active]]:  # rows with > 64 trailing tabs
            row = part[starts[i]:pos[i] + 1]
            kept = row.rstrip(b"\t\r")
            trailing[i] += row.count(b"\t", len(kept))
            pos[i] = starts[i] + len(kept) - 1
    keep = pos >= starts
    numbers = line0 + np.flatnonzero(keep)
    return numbers, starts[keep] + base, tabs[keep], trailing[keep], ends.size


def _scan_rows(source, offset, max_line, error):
    """Per-line statistics of the data block (from byte `offset` to the end of the file).

    Reads the file block by block (no copy of the whole file is kept); returns the
    concatenated arrays of :func:`_line_stats`, the number of lines, and whether the last
    line ends with a line break.
    """
    size = source.seek(0, io.SEEK_END)
    source.seek(offset)
    pieces = []
    # (the unfinished last line of each block stays at the front of the buffer)
    buffer = bytearray(max(1, min(_CHUNK, size - offset)))
    have = 0
    base, line0 = offset, 0
    while True:
        if have == len(buffer):  # one line longer than the buffer (up to max_line)
            buffer.extend(bytes(len(buffer)))
        with memoryview(buffer) as view:
            n_read = source.readinto(view[have:])
        if not n_read:
            break
        have += n_read
        last = buffer.rfind(b"\n", 0, have)
        if last < 0:
            if have > max_line:
                raise error(6 + line0, f"the line is longer than {max_line} bytes; no row "
                            "of this file needs as many (is it a TRC file?)")
            continue
        *stats, n_lines = _line_stats(buffer, last + 1, base, line0, max_line, error)
        pieces.append(stats)
        base += last + 1
        line0 += n_lines
        rest = have - last - 1
        buffer[:rest] = buffer[last + 1:have]
        have = rest
    carry = bytes(buffer[:have])
    terminated = not carry or carry.endswith(b"\r")  # (cut between CR and LF: whole)
    if carry:
        if len(carry) > max_line:
            raise error(6 + line0, f"the line is longer than {max_line} bytes; no row of "
                        "this file needs as many (is it a TRC file?)")
        carry += b"\n"
        *stats, n_lines = _line_stats(carry, len(carry), base, line0, max_line, error)
        pieces.append(stats)
        line0 += n_lines
    if not pieces:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, empty, empty, 0, True
    numbers, starts, tabs, trailing = (np.concatenate(column) for column in zip(*pieces))
    return numbers, starts, tabs, trailing, line0, terminated


def _parse_cut_row(line, width, labels, line_number, error):
    """Values of a last row cut short (no line break): NaN where a field may be cut.

    Returns (values (width,), names of the markers set to NaN), or (None, []) when the
    frame number or the time may be cut (the row is then dropped).
    """
    fields = line.rstrip(b"\r").split(b"\t")
    complete = len(fields) - 1  # the last field is cut (or empty, after a final tab)
    if complete < 2:
        return None, []
    values = np.full(width, np.nan)
    for j, field in enumerate(fields[:min(complete, width)]):  # one row, by field
        text = field.decode("latin-1").strip()
        if text in _NA_TEXTS:
            continue
        try:
            values[j] = float(text)
        except ValueError:
            raise error(line_number, f"field {j + 1} ({_field_name(j, labels)}) is not a "
                        f"number: {text!r}") from None
    n_markers = (width - 2) // 3
    complete_markers = max(0, (complete - 2) // 3)
    values[2 + 3 * complete_markers:] = np.nan
    cut = [labels[k] for k in range(complete_markers, n_markers)
           if any(field.strip() for field in fields[2 + 3 * k:5 + 3 * k])]
    return values, cut


def _csv_options(width, longest):
    """pandas.read_csv options for the data rows (the fast C parser, no quoting).

    `longest` is the most fields of a row: fields beyond `width` (empty, as checked
    before) are skipped with ``usecols``, which pandas refuses when no row has them.
    """
    return dict(sep="\t", header=None, names=range(width),
                usecols=range(width) if longest > width else None,
                keep_default_na=False, na_values=_NA_TEXTS, skip_blank_lines=False,
                quoting=csv.QUOTE_NONE, engine="c")


def _locate_bad_value(source, offset, n_rows, width, longest):
    """Find the first non-numeric field of the data rows and return the ValueError to raise.

    Reads the rows as text in blocks of rows (only after the fast parse failed).
    """
    source.seek(offset)
    reader = pd.read_csv(source, dtype=str, nrows=n_rows, chunksize=4096,
                         encoding="utf-8", encoding_errors="replace",
                         **_csv_options(width, longest))
    first = 0
    for text in reader:  # loop over blocks of rows
        for j in range(width):  # loop over columns, not frames
            column = text[j].fillna("")
            numbers = pd.to_numeric(column.where(~column.isin(_NA_TEXTS)), errors="coerce")
            bad = np.flatnonzero(numbers.isna() & ~column.isin(_NA_TEXTS))
            if bad.size:
                i = bad[0]
                return first + i, j, column.iloc[i]
        first += len(text)
    return None


# Above this many fields per row the rows are parsed as one array (pandas' cost per column
# would dominate: 100,000 markers in one row took seconds); below, by pandas.read_csv.
_WIDE = 20_000


def _parse_wide(block, width, labels, first_line, error):
    """Parse rows of very many fields (few rows) into a (n_rows, width) array."""
    rows = block.split(b"\n")
    values = np.full((len(rows), width), np.nan)
    na = [text.encode() for text in _NA_TEXTS]
    for i, row in enumerate(rows):  # only for files of > 20,000 fields per row
        fields = np.array(row.rstrip(b"\r").split(b"\t")[:width])
        missing = np.isin(fields, na)
        try:
            values[i, :fields.size][~missing] = fields[~missing].astype(np.float64)
        except ValueError:
            for j in np.flatnonzero(~missing):  # find the field, for the message
                try:
                    float(fields[j])
                except ValueError:
                    text = fields[j].decode("utf-8", errors="replace")
                    raise error(first_line + i, f"field {j + 1} ({_field_name(j, labels)})"
                                f" is not a number: {text!r}") from None
            raise  # pragma: no cover - numpy failed for another reason
    return values


class _Rows:
    """The parsed rows: a DataFrame of one column per field (pandas' output, not
    copied), or for very wide files one array; the checks read it column by column."""

    def __init__(self, table=None, array=None):
        self.table, self.array = table, array

    def __len__(self):
        return len(self.table) if self.array is None else self.array.shape[0]

    def column(self, j):
        return self.table[j].to_numpy() if self.array is None else self.array[:, j]

    def any_in_row(self, test):
        """Boolean per row: test(values) is true in some field of the row."""
        if self.array is not None:
            return test(self.array).any(axis=1)
        hit = np.zeros(len(self.table), dtype=bool)
        for _, column in self.table.items():  # loop over columns, not frames
            hit |= test(column.to_numpy())
        return hit

    def append(self, row):
        if self.array is not None:
            self.array = np.vstack([self.array, row])
        else:
            extra = pd.DataFrame(row[None, :], columns=self.table.columns)
            self.table = extra if not len(self.table) else pd.concat(
                [self.table, extra], ignore_index=True)

    def markers(self, keep):
        """The marker columns (fields 2 onwards) of the kept markers, as a DataFrame."""
        if self.array is not None:
            data = self.array[:, 2:]
            if not keep.all():
                data = data[:, np.repeat(keep, 3)]
            return pd.DataFrame(data, copy=False)
        if keep.all():
            return self.table.iloc[:, 2:]
        return self.table.iloc[:, 2 + np.flatnonzero(np.repeat(keep, 3))]


def _read_rows(source, offset, width, labels, error):
    """Parse the data rows; return (_Rows, first line number, messages)."""
    max_line = (1 << 22) + 256 * width
    numbers, starts, tabs, trailing, n_lines, terminated = _scan_rows(source, offset,
                                                                      max_line, error)
    if not numbers.size:
        return _Rows(array=np.empty((0, width))), 6, []
    first_line = 6 + int(numbers[0])  # 1-based line number of the first row
    gaps = np.flatnonzero(np.diff(numbers) != 1)
    n_raw = tabs + 1
    used = n_raw - trailing  # fields up to the last non-empty one
    cut = not terminated and numbers[-1] == n_lines - 1
    messages = []

    rows = np.flatnonzero(used > width)
    if rows.size:
        i = rows[0]
        raise error(6 + int(numbers[i]), f"the row has {used[i]} fields but the labels "
                    f"line defines {width} (Frame#, Time, then x, y, z for each of "
                    f"{len(labels)} markers)")
    if gaps.size:
        raise error(6 + int(numbers[gaps[0]]) + 1, "no frame number (a blank or truncated "
                    "line inside the data?)")
    n_rows = numbers.size
    n_full = n_rows - 1 if cut else n_rows
    if not n_full:
        parsed = _Rows(array=np.empty((0, width)))
    elif width > _WIDE:
        source.seek(int(starts[0]))
        end = int(starts[n_full]) if n_full < n_rows else None
        block = source.read(end - int(starts[0]) if end else -1).rstrip(b"\r\n\t")
        block = b"\n".join(block.split(b"\n")[:n_full])
        parsed = _Rows(array=_parse_wide(block, width, labels, first_line, error))
    else:
        longest = int(n_raw[:n_full].max())
        source.seek(int(starts[0]))
        try:
            table = pd.read_csv(source, dtype=np.float64, nrows=n_full,
                                **_csv_options(width, longest))
        except ValueError:
            located = _locate_bad_value(source, int(starts[0]), n_full, width, longest)
            if located is None:  # pragma: no cover - pandas failed for another reason
                raise
            i, j, text = located
            raise error(first_line + i, f"field {j + 1} ({_field_name(j, labels)}) is not "
                        f"a number: {text!r}") from None
        parsed = _Rows(table=table)
    if len(parsed) != n_full:  # pragma: no cover - guards the line numbering
        raise RuntimeError(f"parsed {len(parsed)} rows from {n_full} lines")
    if cut:
        source.seek(int(starts[-1]))
        last_line = first_line + n_rows - 1
        row, nan_markers = _parse_cut_row(source.read(), width, labels, last_line, error)
        if row is None:
            messages.append(f"line {last_line}, the last line, does not end with a line "
                            "break and stops before its first marker (is the file cut?); "
                            "the row was left out")
        else:
            parsed.append(row)
            if nan_markers:
                messages.append(f"line {last_line}, the last line, does not end with a line "
                                "break (is the file cut?): its last value may be cut short, "
                                "so these markers of that row were set to NaN: "
                                f"{', '.join(nan_markers)}")
    n_raw, used = n_raw[:n_full], used[:n_full]

    frames, time = parsed.column(0), parsed.column(1)
    rows = np.flatnonzero(np.isnan(frames))
    if rows.size:
        raise error(first_line + rows[0], "no frame number (a blank or truncated line "
                    "inside the data?)")
    rows = np.flatnonzero(np.isnan(time))
    if rows.size:
        raise error(first_line + rows[0], "no time value in the Time column")
    # A row shorter than the layout is fine if it stops at a marker boundary (the
    # missing markers at the end are then NaN); stopping inside a marker is a truncated
    # row or a lost tab, which would shift every later column.
    boundary = 2 + 3 * ((n_raw - 2) // 3)
    rows = np.flatnonzero((n_raw < width) & (boundary < used))
    if rows.size:
        i = rows[0]
        k = (n_raw[i] - 2) // 3
        raise error(first_line + i, f"the row stops after {n_raw[i]} fields, inside "
                    f"marker {labels[k]!r}; expected {width} fields (Frame#, Time, then x, "
                    "y, z per marker): is a value or a tab missing?")
    # Likewise, a row with fewer or more fields than most rows of the file must differ
    # by whole markers; one field fewer in a file whose rows end with a tab is a lost
    # field, one more a stray tab (both shift every later column).
    if n_raw.size:
        counts, occurrences = np.unique(n_raw, return_counts=True)
        common = int(counts[np.argmax(occurrences)])
        rows = np.flatnonzero((n_raw - common) % 3 != 0)
        if rows.size:
            i = rows[0]
            raise error(first_line + i, f"the row has {n_raw[i]} fields where most "
                        f"rows have {common}: a lost or extra field would shift the columns")
    # (beyond 2**53 a float cannot tell neighbouring frames apart)
    rows = np.flatnonzero((frames != np.round(frames)) | (np.abs(frames) >= 2.0**53))
    if rows.size:
        raise error(first_line + rows[0], f"the frame number {frames[rows[0]]} is not "
                    "a whole number below 2**53")
    rows = np.flatnonzero(parsed.any_in_row(np.isinf))
    if rows.size:
        raise error(first_line + rows[0], "infinite value; missing data is an empty field")
    return parsed, first_line, messages


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
    _check_regular_file(path, "TRC")
    path = Path(path)
    error = _TrcError(path)
    with open(path, "rb") as file:
        peek = file.read(1 << 16)
        source = file
        # UTF-16 text, or old Mac line ends (a carriage return alone): normalize first
        if (peek[:2] in (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)
                or re.search(rb"\r[^\n]", peek)):
            file.seek(0)
            source = _normalized_copy(file.read(), error, remove_spaces=False)
        try:
            result = _read_trc_source(source, error)
        except _Normalize:  # spaces or lone carriage returns in the data rows
            file.seek(0)
            source = _normalized_copy(file.read(), error, remove_spaces=True)
            result = _read_trc_source(source, error)
    df, messages = result
    _zeros_as_gaps(df, zeros_as_gaps, messages)
    if messages:
        warn(f"{path}: " + "; ".join(messages), UserWarning)
    return df


def _zeros_as_gaps(df, enabled, messages):
    """Set to NaN (in place) the points of `df` exactly at (0, 0, 0) when `enabled`;
    count them in ``df.attrs['zero_points']`` and say so in `messages`."""
    check_flag(enabled, "zeros_as_gaps")
    values = df.to_numpy().reshape(len(df), df.shape[1] // 3, 3)
    zero = np.all(values == 0, axis=2)                     # (frames, markers)
    count = int(np.count_nonzero(zero)) if enabled else 0
    df.attrs["zero_points"] = count
    if count:
        values = values.copy()
        values[zero] = np.nan
        df.iloc[:, :] = values.reshape(len(df), df.shape[1])
        markers = df.columns.get_level_values(0)[::3]
        hit = [str(m) for m, z in zip(markers, zero.any(axis=0)) if z]
        messages.append(f"{count} points (frame x marker) were exactly (0, 0, 0), the way "
                        f"some systems write a marker not seen, in {len(hit)} markers "
                        f"({', '.join(hit[:6])}{' ...' if len(hit) > 6 else ''}): read as "
                        "gaps (NaN); zeros_as_gaps=False keeps them")


def _read_trc_source(source, error):
    """Read a TRC file from a binary file object; return (DataFrame, warning messages)."""
    source.seek(0)
    lines, offset = _header_lines(source, error)
    header, header_values = _parse_header(lines, error)
    labels = _parse_labels(lines[3], error)
    coord_tokens = _nonempty(lines[4])
    if not coord_tokens or not re.fullmatch(r"[XYZxyz]\d+", coord_tokens[0]):
        raise error(5, f"expected the coordinate line 'X1  Y1  Z1  X2 ...'; got "
                    f"{lines[4][:60]!r}")
    width = 2 + 3 * len(labels)
    parsed, start, messages = _read_rows(source, offset, width, labels, error)
    n_rows = len(parsed)

    num_markers, n_labels = header_values["num_markers"], len(labels)
    if header_values["num_frames"] != n_rows:
        messages.append(f"the header says NumFrames = {header_values['num_frames']} but the "
                        f"file holds {n_rows} data rows; all {n_rows} rows were read")
    keep = np.ones(n_labels, dtype=bool)
    dropped = []
    if n_labels > num_markers:
        extra = np.arange(num_markers, n_labels)
        holds_data = np.array([any(not np.isnan(parsed.column(2 + 3 * k + c)).all()
                                   for c in range(3)) for k in extra], dtype=bool)
        keep[extra[~holds_data]] = False
        dropped = [labels[k] for k in extra[~holds_data]]
        if holds_data.any():
            names = ", ".join(labels[k] for k in extra[holds_data])
            messages.append(f"the header says NumMarkers = {num_markers} but "
                            f"{holds_data.sum()} of the {extra.size} labels beyond it hold "
                            f"data and were kept: {names}")
    elif n_labels < num_markers:
        messages.append(f"the header says NumMarkers = {num_markers} but the labels line "
                        f"names {n_labels} markers; {n_labels} were read")
    kept = [label for label, k in zip(labels, keep) if k]
    duplicates = sorted(label for label, count in Counter(kept).items() if count > 1)
    if duplicates:
        raise error(4, f"duplicate marker labels: {', '.join(duplicates)}")
    time = parsed.column(1).copy()
    steps = np.diff(time)
    if (steps <= 0).any():
        i = int(np.argmax(steps <= 0))
        messages.append(f"the time does not increase at line {start + i + 1} "
                        f"({time[i]:g} then {time[i + 1]:g})")

    rate_message = _rate_against_time(header_values["rate"], time,
                                      parsed.column(0) if n_rows else time)
    if rate_message:
        messages.append(rate_message)

    columns = pd.MultiIndex.from_product([kept, COORDS], names=["marker", "coord"])
    # the parsed columns become the DataFrame's: no second copy of the data
    df = parsed.markers(keep)
    df.columns = columns
    df.index = pd.Index(time, name="time")
    df.attrs = {"rate": header_values["rate"], "units": header_values["units"],
                "frames": parsed.column(0).astype(np.int64).tolist()}
    if "camera_rate" in header_values:
        df.attrs["camera_rate"] = header_values["camera_rate"]
    df.attrs["header"] = header
    df.attrs["dropped_labels"] = dropped
    return df, messages


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


def _check_marker_frame(df, name="df"):
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
    kinds = {dtype.kind for dtype in df.dtypes}
    if "b" in kinds:  # True/False would be written as 1/0 coordinates
        raise TypeError(f"{name} must hold coordinates (numbers); got boolean columns")
    ordered = pd.MultiIndex.from_product([markers, COORDS])
    values = as_float_array(df.reindex(columns=ordered).to_numpy(), name)
    check_finite_or_nan(values, name)
    return markers, values


def _check_float_format(float_format):
    """Check a printf-style format writes numbers that read back; return it."""
    if not isinstance(float_format, str):
        raise TypeError(f"float_format must be a printf-style format string such as "
                        f"'%.6f'; got {type(float_format).__name__}")
    conversion = re.fullmatch(r"%[-+ #0]*\d*(?:\.\d*)?([a-zA-Z])", float_format)
    if conversion is not None and conversion.group(1) not in "eEfFgGrs":
        # '%d' or '%x' would truncate every value to a whole number without a word
        integer = conversion.group(1) in "diuoxXc"
        raise ValueError(f"float_format must be one floating-point conversion (%f, %e or "
                         f"%g), like '%.6f' or '%.8g'; got {float_format!r}, which "
                         + ("truncates the values (write '%.0f' to round to whole numbers)"
                            if integer else "is no conversion of a number"))
    try:
        samples = [float_format % value for value in (1.25, -1234.5, 1e-7, 3e12)]
        ok = all(not re.search(r"\s", text) and np.isfinite(float(text)) for text in samples)
        ok = ok and abs(float(samples[1]) + 1234.5) <= 1.0  # the number, not a constant
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok:
        raise ValueError(f"float_format must format one number as a number, like '%.6f', "
                         f"'%.3f' or '%.8g'; got {float_format!r}")
    if re.fullmatch(r"%[-+ #0]*\d*(?:\.\d*)?[eEfFgGrs]", float_format) is None:
        raise ValueError(f"float_format must be one floating-point conversion (%f, %e or "
                         f"%g), like '%.6f' or '%.8g'; got {float_format!r}")
    return float_format


def _frame_numbers(frames, n):
    """attrs['frames'] as int64 when it holds one whole number below 2**53 per row,
    otherwise 1, 2, ..., n (e.g. after slicing rows, or for frame labels)."""
    default = np.arange(1, n + 1, dtype=np.int64)
    if frames is None or isinstance(frames, (str, bytes)):
        return default
    try:
        array = np.asarray(frames)
    except (TypeError, ValueError, OverflowError):  # ragged, or ints beyond int64
        array = np.asarray(frames, dtype=object) if np.ndim(frames) == 1 else np.array([])
    if array.shape != (n,):  # e.g. rows sliced after reading: attrs was not sliced
        return default
    usable = array.dtype.kind in "iuf"  # not bool, text or Python objects
    if usable:
        array = array.astype(float)
        usable = bool(np.isfinite(array).all() and (array == np.round(array)).all()
                      and (np.abs(array) < 2.0**53).all())
    if not usable:
        warn(f"df.attrs['frames'] does not hold whole numbers below 2**53 (got "
             f"{array[:3].tolist()}...): the frames were numbered 1 to {n}",
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
        frames).

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
        2**53 (frame labels, 10**400): the frames are then numbered 1, 2, ..., n.

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
    float_format = _check_float_format(float_format)
    markers, values = _check_marker_frame(df)
    n = values.shape[0]
    attrs = df.attrs
    if rate is None:
        rate = attrs.get("rate")
        if rate is None:
            raise ValueError("rate: df.attrs has no 'rate'; pass rate= (Hz)")
    if isinstance(rate, (bool, np.bool_)):
        raise TypeError(f"rate must be a number (Hz); got {bool(rate)}")
    try:
        rate = float(rate)
    except (TypeError, ValueError, OverflowError):
        rate = np.nan
    if not (np.isfinite(rate) and rate > 0):
        raise ValueError(f"rate must be a positive number (Hz); got {rate!r}")
    if units is None:
        units = attrs.get("units")
        if units is None:
            raise ValueError("units: df.attrs has no 'units'; pass units= (e.g. 'mm')")
    if not isinstance(units, str) or not units.strip() or re.search(r"\s", units.strip()):
        raise ValueError(f"units must be a non-empty word such as 'mm' or 'm'; got {units!r}")
    if df.index.dtype.kind in "mM":  # numpy would turn these into counts of ns or us
        raise ValueError(f"df.index (time) must hold the time in seconds as numbers; got "
                         f"dtype {df.index.dtype} (for a TimedeltaIndex, set "
                         "df.index = df.index.total_seconds())")
    time = as_float_array(df.index.to_numpy(), "df.index (time)")
    if time.ndim != 1 or not np.isfinite(time).all():
        raise ValueError("df.index (time) must hold finite times in seconds; got "
                         f"{df.index[:5].tolist()}...")
    if n > 1 and (np.diff(time) <= 0).any():
        i = int(np.argmax(np.diff(time) <= 0))
        raise ValueError(f"df.index (time) must increase; got {time[i]:g} then "
                         f"{time[i + 1]:g} at rows {i} and {i + 1}")
    frames = _frame_numbers(attrs.get("frames"), n)
    camera_rate = attrs.get("camera_rate", rate)
    try:
        if not isinstance(camera_rate, (bool, np.bool_)):
            camera_rate = float(camera_rate)
    except (TypeError, ValueError, OverflowError):
        pass
    if not (isinstance(camera_rate, float) and np.isfinite(camera_rate) and camera_rate > 0):
        raise ValueError("df.attrs['camera_rate'] must be a positive number (Hz); got "
                         f"{camera_rate!r}")
    time_column = time
    if n:
        # The time keeps at least 1 us even if float_format rounds the coordinates
        # coarsely ('%.2f' would write 200 Hz as 0.00, 0.01, 0.01, ...).
        text = np.char.mod(float_format, time)
        try:
            exact = np.abs(text.astype(float) - time).max() <= 5e-7 * (1 + 1e-9)
        except ValueError:  # a format that does not print a number
            exact = False
        time_column = text if exact else np.char.mod("%.6f", time)

    def number(value):
        return f"{float(value):.15g}"

    m = len(markers)
    head = [
        f"PathFileType\t4\t(X/Y/Z)\t{Path(path).name}",
        "\t".join(TRC_KEYS),
        "\t".join([number(rate), number(camera_rate), str(n), str(m), units.strip(),
                   number(rate), str(frames[0] if n else 1), str(n)]),
        "Frame#\tTime\t" + "".join(f"{marker}\t\t\t" for marker in markers),
        "\t\t" + "".join(f"X{k}\tY{k}\tZ{k}\t" for k in range(1, m + 1)),
        "",
    ]
    table = pd.DataFrame(values)
    table.insert(0, "time", time_column)
    table.insert(0, "frame", frames)
    table["end"] = np.nan  # an empty last field: every field ends with a tab (OpenSim)
    body = table.to_csv(sep="\t", header=False, index=False, na_rep="",
                        float_format=float_format, lineterminator="\n")
    with open(path, "w", encoding="utf-8", newline="\n") as file:
        file.write("\n".join(head) + "\n" + body)


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
        The same shape as :func:`read_trc`: columns ``(marker, coord)``, index the time
        in seconds from 0 at the first stored frame (named ``'time'``), NaN for invalid
        points. ``df.attrs`` holds ``'rate'`` (POINT:RATE, Hz), ``'units'``
        (POINT:UNITS), ``'frames'`` (1-based frame numbers), ``'dropped_labels'``,
        ``'invalid_points'`` (how many points, frame x marker, had a negative residual)
        and ``'zero_points'`` (how many more were exactly (0, 0, 0) and became NaN).

    Raises
    ------
    ImportError
        If ezc3d is not installed; the message names the extra ``bmc_functions[c3d]``.
    ValueError
        If a point has an empty label, or two points have the same label; if `path` is
        a directory, a device or a pipe; if the file is damaged: not a C3D file (no key
        0x50), cut before its parameters or its data, a parameter record that runs
        outside the parameter section, POINT:USED, POINT:FRAMES or POINT:DATA_START
        disagreeing with the header, POINT:RATE not a positive number, or ezc3d failing,
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
    try:
        import ezc3d  # noqa: F401 (read in a child process)
    except ImportError as err:
        raise ImportError("read_c3d needs the optional package ezc3d; install it with "
                          "pip install 'bmc_functions[c3d]' (or pip install ezc3d)") from err
    _check_regular_file(path, "C3D")
    info = check_c3d(path)
    messages = []
    with tempfile.TemporaryDirectory() as folder:
        source = path
        if info["frames_present"] < info["frames"]:
            source = _complete_frames_copy(path, info, Path(folder) / "complete.c3d")
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
    negative = np.zeros(xyz.shape[:2], dtype=bool)       # (frames, points)
    if residuals is not None and np.size(residuals):
        negative = residuals[0].T < 0
        xyz[negative] = np.nan

    non_markers = {label.strip() for group in c3d["non_markers"].values() for label in group}
    keep = np.array([label not in non_markers for label in labels], dtype=bool)
    kept = [label for label, k in zip(labels, keep) if k]
    blank = [str(k + 1) for k, label in enumerate(labels) if keep[k] and not label]
    if blank:
        raise ValueError(f"{path}: POINT:LABELS: points {', '.join(blank)} (of {n_points}) "
                         "have an empty label; name them (e.g. in the capture software) "
                         "before reading")
    duplicates = sorted(label for label, count in Counter(kept).items() if count > 1)
    if duplicates:
        raise ValueError(f"{path}: duplicate marker labels in POINT:LABELS: "
                         f"{', '.join(duplicates)}")
    rate = c3d["rate"]
    if not (np.isfinite(rate) and rate > 0):
        raise ValueError(f"{path}: POINT:RATE is {rate:g}; a frame rate must be a positive "
                         "number (Hz)")
    units = c3d["units"][0].strip() if c3d["units"] else ""
    first = c3d["first_frame"] + 1  # ezc3d counts from 0
    columns = pd.MultiIndex.from_product([kept, COORDS], names=["marker", "coord"])
    df = pd.DataFrame(xyz[:, keep, :].reshape(n_frames, 3 * len(kept)), columns=columns,
                      index=pd.Index(np.arange(n_frames) / rate, name="time"))
    df.attrs = {"rate": rate, "units": units,
                "frames": list(range(first, first + n_frames)),
                "dropped_labels": [label for label, k in zip(labels, keep) if not k],
                "invalid_points": int(np.count_nonzero(negative[:, keep]))}
    _zeros_as_gaps(df, zeros_as_gaps, messages)
    if messages:
        warn(f"{path}: " + "; ".join(messages), UserWarning)
    return df


def _complete_frames_copy(path, info, target):
    """Copy the whole frames of a cut C3D file, its header saying how many there are."""
    n = info["frames_present"]
    with open(path, "rb") as file:
        data = bytearray(file.read(info["data_offset"] + n * info["frame_bytes"]))
    order = info["order"]
    struct.pack_into(order + "H", data, 8, info["first_frame"] + n - 1)  # last frame
    if info["frames_param_offset"] is not None:
        struct.pack_into(order + "H", data, info["frames_param_offset"], n)
    Path(target).write_bytes(data)
    return target
