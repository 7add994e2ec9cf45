"""One trial, whichever file it came from: a marker table in known units.

Every layer above the files (the lower-limb pipeline, Plug-in Gait, the gait events) loads
its trials here, so that a file accepted by one is accepted by all, with the same units:

- :func:`load_trial`: a marker DataFrame, or a .trc/.c3d path read into one.
- :func:`mm_per_unit`: the millimetres per unit of the trial's coordinates, from
  ``attrs['units']`` (as :func:`~bmc_functions.read_trc` and
  :func:`~bmc_functions.read_c3d` set it), spelled-out units included.
- :class:`MarkerTable`: the trial's coordinates as one float array, checked once.
"""

from pathlib import Path

import numpy as np
import pandas as pd

from .._checks import ArgumentTypeError
from .c3d import read_c3d
from .trc import read_trc

#: Millimetres per unit for the units a marker file may declare.
UNIT_SCALE = {"mm": 1.0, "cm": 10.0, "m": 1000.0}

#: Spelled-out units some writers put in their files, and the unit they mean.
UNIT_ALIASES = {"millimeter": "mm", "millimeters": "mm", "millimetre": "mm",
                "millimetres": "mm", "centimeter": "cm", "centimeters": "cm",
                "centimetre": "cm", "centimetres": "cm", "meter": "m", "meters": "m",
                "metre": "m", "metres": "m"}


def load_trial(trial, name):
    """A marker DataFrame from a DataFrame or a .trc/.c3d path, and its display name.

    Parameters
    ----------
    trial : pandas.DataFrame or str or pathlib.Path
        A marker table as :func:`~bmc_functions.read_trc` returns, or the path of a .trc or
        .c3d file.
    name : str
        What the trial is for ('static', 'dynamic'): the display name says it.

    Returns
    -------
    markers : pandas.DataFrame
    display : str
        'the static trial (walk.trc)': how messages name the trial.

    Examples
    --------
    >>> import pandas as pd
    >>> from bmc_functions.files.trial import load_trial
    >>> load_trial(pd.DataFrame(), 'static')[1]
    'the static trial'
    """
    if isinstance(trial, pd.DataFrame):
        return trial, f"the {name} trial"
    if isinstance(trial, (str, Path)):
        path = Path(trial)
        suffix = path.suffix.lower()
        if suffix == ".trc":
            return read_trc(path), f"the {name} trial ({path.name})"
        if suffix == ".c3d":
            return read_c3d(path), f"the {name} trial ({path.name})"
        raise ValueError(f"{name}: expected a .trc or .c3d file; got {str(path)!r}")
    raise TypeError(f"{name} must be a DataFrame from read_trc/read_c3d or a path to a .trc "
                    f"or .c3d file; got {type(trial).__name__}")


def mm_per_unit(markers, trial):
    """Millimetres per unit of a marker table's coordinates, and the unit's short name.

    Parameters
    ----------
    markers : pandas.DataFrame
        With ``attrs['units']``: 'mm', 'cm' or 'm', in any letter case, or spelled out
        ('millimeters', 'metres', ...).
    trial : str
        The trial's display name, for the messages.

    Returns
    -------
    scale : float
    unit : {'mm', 'cm', 'm'}

    Raises
    ------
    ValueError
        If the table has no frames, no units or units not listed above: a coordinate
        without a unit cannot be compared with the model's thresholds in millimetres.

    Examples
    --------
    >>> import pandas as pd
    >>> from bmc_functions.files.trial import mm_per_unit
    >>> table = pd.DataFrame({('A', 'x'): [1.0]})
    >>> table.attrs['units'] = 'Meters'
    >>> mm_per_unit(table, 'the trial')
    (1000.0, 'm')
    """
    if len(markers) == 0:
        raise ValueError(f"{trial} has no frames")
    units = markers.attrs.get("units")
    if units is None:
        raise ValueError(f"{trial} has no units: set df.attrs['units'] to 'mm' or 'm' "
                         "(read_trc and read_c3d set it from the file)")
    key = str(units).strip().lower()
    key = UNIT_ALIASES.get(key, key)
    if key not in UNIT_SCALE:
        raise ValueError(f"{trial}: units {units!r} are not supported; expected one of "
                         f"{', '.join(UNIT_SCALE)}")
    return UNIT_SCALE[key], key


#: Frames per block in which :meth:`MarkerTable.stacked` copies a C-ordered stack.
_STACK_BLOCK = 2048


def _has_infinity(values):
    """Whether a (frames, columns) array holds an infinity, tested a few columns at a
    time into one small boolean array: ``np.isinf(values).any()`` would make a fresh
    boolean array as large as the table (a whole C3D's, model outputs included) for one
    answer, and fault in its pages."""
    block = 8
    found = np.empty((len(values), min(block, values.shape[1])), dtype=bool,
                     order="F" if values.flags.f_contiguous else "C")
    for start in range(0, values.shape[1], block):     # a loop over columns, not frames
        part = values[:, start:start + block]
        if np.isinf(part, out=found[:, :part.shape[1]]).any():
            return True
    return False


class MarkerTable:
    """A marker DataFrame as one float array, with each label's three columns.

    Selecting columns of the DataFrame itself copies its attrs every time (slow on long
    trials); the table is checked once here (two-level columns, numbers, no label twice,
    x, y, z for each, nothing infinite) and then read by label.
    """

    def __init__(self, df, trial="the trial"):
        if not isinstance(df.columns, pd.MultiIndex) or df.columns.nlevels != 2:
            raise ValueError(f"{trial} must have two-level (marker, coord) columns, as "
                             f"read_trc and read_c3d return; got columns "
                             f"{list(df.columns[:6])}")
        not_numbers = [(column, dtype) for column, dtype in df.dtypes.items()
                       if dtype.kind in "bmM"]   # True/False would read as 1/0 mm
        if not_numbers:
            (label, coord), dtype = not_numbers[0]
            raise ArgumentTypeError(
                f"{trial}: marker {label!r}, coordinate {coord!r} holds "
                f"{'booleans (True/False)' if dtype.kind == 'b' else f'dates ({dtype})'}"
                f", not coordinates ({len(not_numbers)} such column(s)); expected numbers, "
                f"with NaN for missing data")
        try:
            self.values = df.to_numpy(dtype=float)
        except (TypeError, ValueError) as error:
            for k, column in enumerate(df.columns):      # a loop over columns: the culprit
                try:
                    df.iloc[:, k].to_numpy(dtype=float)
                except (TypeError, ValueError):
                    values = df.iloc[:, k]
                    bad = pd.to_numeric(values, errors="coerce").isna() & values.notna()
                    where = int(np.argmax(bad.to_numpy())) if bad.any() else 0
                    raise ValueError(
                        f"{trial}: marker {column[0]!r}, coordinate {column[1]!r} holds "
                        f"{values.iloc[where]!r} at frame {where} (index "
                        f"{df.index[where]}), which is not a number; expected numbers, "
                        f"with NaN for missing data") from None
            raise ValueError(f"{trial} holds values that are not numbers: {error}") from None
        self.dropped = tuple(df.attrs.get("dropped_labels") or ())
        self.labels = list(dict.fromkeys(df.columns.get_level_values(0)))
        self.columns = {}
        for k, (label, coord) in enumerate(df.columns):
            if coord in self.columns.setdefault(label, {}):
                raise ValueError(f"{trial}: marker {label!r} appears twice (two {coord!r} "
                                 f"columns, {self.columns[label][coord]} and {k}): which "
                                 f"copy is meant is ambiguous; rename or drop one")
            self.columns[label][coord] = k
        for label, coords in self.columns.items():     # a loop over labels, not frames
            if sorted(coords) != ["x", "y", "z"]:
                raise ValueError(f"{trial}: marker {label!r} must have the coords 'x', 'y', "
                                 f"'z' (as read_trc returns); got {list(coords)}")
        if _has_infinity(self.values):
            infinite = np.isinf(self.values)
            frames, column = np.nonzero(infinite)
            label = df.columns[column[0]][0]
            raise ValueError(f"{trial}: marker {label!r} has an infinite coordinate (first "
                             f"at frame {frames[0]}; {infinite.any(axis=1).sum()} frames in "
                             f"all); use NaN for missing data")

    def points(self, label, scale):
        """(frames, 3) coordinates of one label in mm."""
        where = self.columns[label]
        points = self.values[:, [where["x"], where["y"], where["z"]]]      # a copy
        return points if scale == 1.0 else points * scale

    def points_of(self, labels, scale):
        """Name -> (frames, 3) coordinates (mm) for each name -> label of `labels`: the
        arrays ``{name: self.points(label, scale) ...}`` (the same values and memory
        layout, copies of the table's; from a column-major table, views of one new array
        that do not overlap, so each can be written to apart from the others, and one
        kept keeps that array).

        A column-major table's copies are made as rows of one array (each its own three
        rows): one allocation in place of one per label, whose fresh pages the kernel
        would fault in and zero one array at a time (about three times slower).
        """
        if not self.values.flags.f_contiguous or self.values.flags.c_contiguous:
            return {name: self.points(label, scale) for name, label in labels.items()}
        rows = np.empty((3 * len(labels), len(self.values)))
        for k, label in enumerate(labels.values()):   # a loop over labels, not frames
            for axis, row in zip("xyz", rows[3 * k:3 * k + 3]):
                row[...] = self.values[:, self.columns[label][axis]]
        if scale != 1.0:
            rows *= scale                # as points(): each coordinate times the scale
        # (frames, 3) views, column-major as points() returns them from such a table
        return {name: rows[3 * k:3 * k + 3].T for k, name in enumerate(labels)}

    def stacked(self, labels, scale, contiguous=False):
        """(frames, n, 3) coordinates (mm) of the n `labels`: the array
        ``np.stack([self.points(label, scale) for label in labels], axis=1)``, its values
        and its memory layout (which sets the order of the sums that svdt, for one,
        makes over a frame's markers); C-ordered with `contiguous`.

        A DataFrame's table is column-major (and so is each label's points), and
        np.stack then lays the points out as three (frames, n) planes, x, y and z: each
        plane is filled here column by column (each read in place), several times
        faster than copying each label's points and stacking the copies.
        """
        frames = len(self.values)
        if contiguous:
            # Blocks of frames (a block's rows stay in the cache while they are written):
            # a transposing copy of the whole columns at once is about twice as slow.
            columns = [self.columns[label][axis] for label in labels for axis in "xyz"]
            stacked = np.empty((frames, len(columns)))
            for start in range(0, frames, _STACK_BLOCK):
                block = slice(start, start + _STACK_BLOCK)
                stacked[block] = self.values[block, columns]
            if scale != 1.0:
                stacked *= scale
            return stacked.reshape(frames, len(labels), 3)
        if not self.values.flags.f_contiguous or self.values.flags.c_contiguous:
            return np.stack([self.points(label, scale) for label in labels], axis=1)
        planes = np.empty((3, frames, len(labels)))
        for plane, axis in zip(planes, "xyz"):
            for k, label in enumerate(labels):
                plane[:, k] = self.values[:, self.columns[label][axis]]
        if scale != 1.0:
            planes *= scale              # as points(): each coordinate times the scale
        return planes.transpose(1, 2, 0)

    def has_data(self, label):
        """Whether `label` is in the table with a coordinate in at least one frame."""
        # its three columns read in place (no copy of the points)
        return label in self.columns and any(
            bool(np.isfinite(self.values[:, column]).any())
            for column in self.columns[label].values())
