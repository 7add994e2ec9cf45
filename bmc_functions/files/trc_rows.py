r"""The data rows of a TRC file: scanned, checked and parsed into numbers.

The rows after the five header lines hold, per frame, the frame number, the time and x,
y, z of every marker, tab-separated (:mod:`~bmc_functions.files.trc` reads the header).
:func:`scan_rows` measures every line (its fields, its trailing empty fields) block by
block from the bytes, so that a damaged row is found and named before the numbers are
parsed; :func:`read_rows` then parses them with :func:`pandas.read_csv` (its C parser)
and checks them. The scan is what lets a 340 MB file be read in about the time and
memory of :func:`pandas.read_csv` alone (``benchmarks/bench_read_trc.py``).
"""

import csv
import io

import numpy as np
import pandas as pd

from .marker_table import COORDS

#: Field texts read as missing data besides the empty field (some tools write NaN).
NA_TEXTS = ["", "NaN", "nan", "NAN", "-NaN", "-nan"]

# Bytes of a TRC data block that end or pad fields.
_TAB, _LF, _CR = 9, 10, 13
# Steps of the vectorized walk back over the rows' trailing tabs; rows with more (rare:
# a writer padding every row to a fixed width) are finished one by one.
_TRAIL_STEPS = 64
# Bytes read at a time when scanning the data rows (the scan keeps one block, not the
# whole file: the benchmark's peak memory).
_CHUNK = 1 << 22


class TrcError:
    """Build ValueErrors that name the file and the (1-based) line number."""

    def __init__(self, path):
        self.path = path

    def __call__(self, line, message):
        return ValueError(f"{self.path}, line {line}: {message}")


def field_name(j, labels):
    """Describe 0-based data field `j` for a message."""
    if j == 0:
        return "Frame#"
    if j == 1:
        return "Time"
    marker, coord = divmod(j - 2, 3)
    label = labels[marker] if marker < len(labels) else f"unlabelled marker {marker + 1}"
    return f"{label!r} {COORDS[coord]}"


def needs_normalizing(data, end):
    """Whether ``data[:end]`` holds a space or a carriage return not followed by a line
    feed: the scan reads tabs and line feeds only, so such rows are read from a
    normalized copy (:func:`~bmc_functions.files.trc.normalized_copy`)."""
    if data.find(b" ", 0, end) >= 0:
        return True
    return (data.find(b"\r", 0, end) >= 0
            and data.count(b"\r", 0, end) != data.count(b"\r\n", 0, end))


def _line_stats(part, end, base, line0, max_line, error):
    """Statistics of the lines of ``part[:end]`` (ending with a line feed), blank ones left
    out; the block holds no space and no carriage return but before a line feed.

    Returns (numbers, starts, tabs, trailing, n_lines): each non-blank line's index (from
    the first line of the data block), the byte offset of its start, its number of tabs
    and the number of tabs in its trailing run of tabs; and the number of lines.
    """
    codes = np.frombuffer(part, dtype=np.uint8, count=end)
    ends = np.flatnonzero(codes == _LF)
    starts = np.empty_like(ends)
    starts[0] = 0
    starts[1:] = ends[:-1] + 1
    long_lines = np.flatnonzero(ends - starts > max_line)
    if long_lines.size:
        i = long_lines[0]
        raise error(6 + line0 + i, f"the line is {ends[i] - starts[i]} bytes long; no row "
                    f"of this file needs more than {max_line} (is it a TRC file?)")
    is_tab = codes == _TAB
    # (a 16-bit sum is exact for lines shorter than 2**16 bytes, and twice as fast)
    dtype = np.uint16 if (ends - starts).max() < 2**16 else np.uint32
    tabs = np.add.reduceat(is_tab.view(np.uint8), starts, dtype=dtype).astype(np.int64)
    trailing, last_text = _trailing_tabs(part, codes, starts, ends)
    keep = last_text >= starts  # a line of tabs only is blank
    numbers = line0 + np.flatnonzero(keep)
    return numbers, starts[keep] + base, tabs[keep], trailing[keep], ends.size


def _trailing_tabs(part, codes, starts, ends):
    """The number of tabs in each line's trailing run of tabs (and the CR of a CR LF),
    and the offset of each line's last other byte (below its start for a line of tabs).

    Walks back from every line end at once, one byte per step: a row of a real file
    ends with a few tabs, so this takes a few steps over the line ends only (three times
    faster than locating every field's end, benchmarks/bench_read_trc.py).
    """
    pos = ends - 1
    trailing = np.zeros(ends.size, dtype=np.int64)
    active = np.arange(ends.size)
    for _ in range(_TRAIL_STEPS):  # loop over trailing bytes, not over lines
        active = active[pos[active] >= starts[active]]
        if not active.size:
            return trailing, pos
        byte = codes[pos[active]]
        padding = (byte == _TAB) | (byte == _CR)
        active = active[padding]
        trailing[active] += byte[padding] == _TAB
        pos[active] -= 1
    for i in active[pos[active] >= starts[active]]:  # rows with more trailing tabs
        row = part[starts[i]:pos[i] + 1]
        kept = row.rstrip(b"\t\r")
        trailing[i] += row.count(b"\t", len(kept))
        pos[i] = starts[i] + len(kept) - 1
    return trailing, pos


def scan_rows(source, offset, max_line, error):
    """Per-line statistics of the data block (from byte `offset` to the end of the file).

    Reads the file block by block (no copy of the whole file is kept); returns a dict of
    the concatenated arrays of :func:`_line_stats` (``numbers``, ``starts``, ``tabs``,
    ``trailing``), ``n_lines`` and ``terminated`` (whether the last line ends with a line
    break); or None when a block holds spaces or lone carriage returns
    (:func:`needs_normalizing`): the caller then reads a normalized copy.
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
        if needs_normalizing(buffer, last + 1):
            return None
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
        if needs_normalizing(carry, len(carry)):
            return None
        *stats, n_lines = _line_stats(carry, len(carry), base, line0, max_line, error)
        pieces.append(stats)
        line0 += n_lines
    names = ("numbers", "starts", "tabs", "trailing")
    if pieces:
        scan = {name: np.concatenate(column) for name, column in zip(names, zip(*pieces))}
    else:
        scan = {name: np.zeros(0, dtype=np.int64) for name in names}
    scan.update(n_lines=line0, terminated=terminated)
    return scan


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
        if text in NA_TEXTS:
            continue
        try:
            values[j] = float(text)
        except ValueError:
            raise error(line_number, f"field {j + 1} ({field_name(j, labels)}) is not a "
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
                keep_default_na=False, na_values=NA_TEXTS, skip_blank_lines=False,
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
            numbers = pd.to_numeric(column.where(~column.isin(NA_TEXTS)), errors="coerce")
            bad = np.flatnonzero(numbers.isna() & ~column.isin(NA_TEXTS))
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
    na = [text.encode() for text in NA_TEXTS]
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
                    raise error(first_line + i, f"field {j + 1} ({field_name(j, labels)})"
                                f" is not a number: {text!r}") from None
            raise  # pragma: no cover - numpy failed for another reason
    return values


class Rows:
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




def read_rows(source, scan, width, labels, error):
    """Parse and check the data rows measured by :func:`scan_rows`; return (:class:`Rows`,
    the line number of the first row, warning messages)."""
    numbers = scan["numbers"]
    if not numbers.size:
        return Rows(array=np.empty((0, width))), 6, []
    first_line = 6 + int(numbers[0])  # 1-based line number of the first row
    n_fields = scan["tabs"] + 1
    used = n_fields - scan["trailing"]  # fields up to the last non-empty one
    _check_row_lengths(numbers, used, width, labels, error)
    cut = not scan["terminated"] and numbers[-1] == scan["n_lines"] - 1
    n_whole = numbers.size - 1 if cut else numbers.size
    parsed = _parse_whole_rows(source, scan["starts"], n_whole, n_fields, width, labels,
                               first_line, error)
    messages = []
    if cut:
        last_line = first_line + numbers.size - 1
        source.seek(int(scan["starts"][-1]))
        messages = _append_cut_row(parsed, source.read(), width, labels, last_line, error)
    _check_parsed_rows(parsed, n_fields[:n_whole], used[:n_whole], width, labels,
                       first_line, error)
    return parsed, first_line, messages


def _check_row_lengths(numbers, used, width, labels, error):
    """Refuse a row with more fields than the labels define, or a blank line between
    rows (line numbers are those of the file)."""
    rows = np.flatnonzero(used > width)
    if rows.size:
        i = rows[0]
        raise error(6 + int(numbers[i]), f"the row has {used[i]} fields but the labels "
                    f"line defines {width} (Frame#, Time, then x, y, z for each of "
                    f"{len(labels)} markers)")
    gaps = np.flatnonzero(np.diff(numbers) != 1)
    if gaps.size:
        raise error(6 + int(numbers[gaps[0]]) + 1, "no frame number (a blank or truncated "
                    "line inside the data?)")


def _parse_whole_rows(source, starts, n_whole, n_fields, width, labels, first_line,
                      error):
    """The first `n_whole` rows (those ending with a line break) as :class:`Rows`."""
    if not n_whole:
        return Rows(array=np.empty((0, width)))
    source.seek(int(starts[0]))
    if width > _WIDE:
        end = int(starts[n_whole]) if n_whole < starts.size else None
        block = source.read(end - int(starts[0]) if end else -1).rstrip(b"\r\n\t")
        block = b"\n".join(block.split(b"\n")[:n_whole])
        return Rows(array=_parse_wide(block, width, labels, first_line, error))
    longest = int(n_fields[:n_whole].max())
    try:
        table = pd.read_csv(source, dtype=np.float64, nrows=n_whole,
                            **_csv_options(width, longest))
    except ValueError:
        located = _locate_bad_value(source, int(starts[0]), n_whole, width, longest)
        if located is None:  # pragma: no cover - pandas failed for another reason
            raise
        i, j, text = located
        raise error(first_line + i, f"field {j + 1} ({field_name(j, labels)}) is not "
                    f"a number: {text!r}") from None
    if len(table) != n_whole:  # pragma: no cover - guards the line numbering
        raise RuntimeError(f"parsed {len(table)} rows from {n_whole} lines")
    return Rows(table=table)


def _append_cut_row(parsed, line, width, labels, line_number, error):
    """Append to `parsed` what can be trusted of the last line, which has no line break;
    return the warning messages."""
    row, nan_markers = _parse_cut_row(line, width, labels, line_number, error)
    if row is None:
        return [f"line {line_number}, the last line, does not end with a line break and "
                "stops before its first marker (is the file cut?); the row was left out"]
    parsed.append(row)
    if not nan_markers:
        return []
    return [f"line {line_number}, the last line, does not end with a line break (is the "
            "file cut?): its last value may be cut short, so these markers of that row "
            f"were set to NaN: {', '.join(nan_markers)}"]


def _check_parsed_rows(parsed, n_fields, used, width, labels, first_line, error):
    """Refuse rows without frame number or time, rows whose fields would shift the
    columns, frame numbers that are not whole, and infinite values."""
    frames, time = parsed.column(0), parsed.column(1)
    rows = np.flatnonzero(np.isnan(frames))
    if rows.size:
        raise error(first_line + rows[0], "no frame number (a blank or truncated line "
                    "inside the data?)")
    rows = np.flatnonzero(np.isnan(time))
    if rows.size:
        raise error(first_line + rows[0], "no time value in the Time column")
    _check_field_counts(n_fields, used, width, labels, first_line, error)
    # (beyond 2**53 a float cannot tell neighbouring frames apart)
    rows = np.flatnonzero((frames != np.round(frames)) | (np.abs(frames) >= 2.0**53))
    if rows.size:
        raise error(first_line + rows[0], f"the frame number {frames[rows[0]]} is not "
                    "a whole number below 2**53")
    rows = np.flatnonzero(parsed.any_in_row(np.isinf))
    if rows.size:
        raise error(first_line + rows[0], "infinite value; missing data is an empty field")


def _check_field_counts(n_fields, used, width, labels, first_line, error):
    """Refuse a row whose number of fields would shift the later columns."""
    # A row shorter than the layout is fine if it stops at a marker boundary (the
    # missing markers at the end are then NaN); stopping inside a marker is a truncated
    # row or a lost tab, which would shift every later column.
    boundary = 2 + 3 * ((n_fields - 2) // 3)
    rows = np.flatnonzero((n_fields < width) & (boundary < used))
    if rows.size:
        i = rows[0]
        marker = (n_fields[i] - 2) // 3
        raise error(first_line + i, f"the row stops after {n_fields[i]} fields, inside "
                    f"marker {labels[marker]!r}; expected {width} fields (Frame#, Time, "
                    "then x, y, z per marker): is a value or a tab missing?")
    # Likewise, a row with fewer or more fields than most rows of the file must differ
    # by whole markers; one field fewer in a file whose rows end with a tab is a lost
    # field, one more a stray tab (both shift every later column).
    if n_fields.size:
        counts, occurrences = np.unique(n_fields, return_counts=True)
        common = int(counts[np.argmax(occurrences)])
        rows = np.flatnonzero((n_fields - common) % 3 != 0)
        if rows.size:
            i = rows[0]
            raise error(first_line + i, f"the row has {n_fields[i]} fields where most "
                        f"rows have {common}: a lost or extra field would shift the columns")
