"""Input validation shared by the public functions.

One function per concept (a numeric array, a flag, a choice among strings, a vector
array, a rotation matrix, an angle sequence), called at the boundary of every public
function so that the checks are not scattered and every message has the same form: the
argument's name, what was received, and what was expected.

The rules every public function follows through these checks:

- Numbers only: booleans, strings, dates and times, complex numbers and None are refused
  with :class:`ArgumentTypeError` (a TypeError that is also a ValueError).
- Missing data is NaN. The masked entries of a masked array (``numpy.ma``) and the
  missing values of a pandas object (``pd.NA`` included) are read as NaN, never as the
  values hidden under them; where NaN is allowed they propagate per frame, where it is
  not (the reference markers of :func:`~bmc_functions.svdt`) they are refused.
- Flags (``degrees``, ``extrinsic``, ...) are ``True`` or ``False`` (Python or NumPy
  booleans); a string such as ``'False'`` or an array raises :class:`ArgumentTypeError`.
- Magnitudes: infinite values are refused, and so are values beyond
  :data:`MAX_MAGNITUDE` (1e100) where a quantity is squared (coordinates, angles):
  no unit makes such values physical, and refusing them keeps every result finite.
  Directions (:func:`~bmc_functions.get_R`, :func:`~bmc_functions.frame_from_axes`)
  accept any finite nonzero vector: they are scaled before their lengths are computed.
"""

import inspect
import numbers
import os
import re
import reprlib
import stat
import warnings

import numpy as np

#: Largest deviation of ``R @ R.T`` from the identity accepted for a rotation matrix.
ORTHONORMAL_ATOL = 1e-6


#: Largest magnitude accepted for a coordinate, angle or other quantity (in any unit).
#: Nothing measured in biomechanics comes near it (the Earth's radius is 6.4e9 mm), while
#: its square and the sums of squares a fit forms stay far inside the float64 range
#: (about 1.8e308): a larger value is a unit or data error, refused with a clear message
#: rather than overflowing into a NaN with a misleading explanation.
MAX_MAGNITUDE = 1e100


class ArgumentTypeError(TypeError, ValueError):
    """An argument of the wrong type: not a number, array of numbers or flag as expected.

    A TypeError, as a wrong type calls for; also a ValueError, so that code written for
    the earlier releases, which raised ValueError for these inputs, still catches it.
    """


def _describe(value):
    """A short description of `value` for a message: its type and a truncated repr."""
    text = reprlib.repr(value)  # bounded work, even for a list of a million items
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{text} ({type(value).__name__})"


def as_float_array(value, name):
    """Return `value` as a float64 array, or raise naming `name`.

    The one conversion of every numeric argument of the public API:

    - integers and floats of any precision are converted to float64; a pandas Series or
      DataFrame of numbers too, its missing values (``pd.NA`` included) becoming NaN;
    - a masked array (``numpy.ma``) has its masked entries replaced by NaN, the
      package's marker of missing data (they are never read as numbers);
    - booleans, strings, dates and times (datetime64, timedelta64), complex numbers,
      None and other objects raise :class:`ArgumentTypeError` (a TypeError that is also
      a ValueError), since they are not quantities;
    - a ragged nested sequence, or a Python integer too large for float64, raises
      ValueError.
    """
    if value is None or isinstance(value, (str, bytes, dict, set)):
        raise ArgumentTypeError(f"{name} must be a numeric array; got {_describe(value)}")
    value = _from_pandas(value)
    mask = np.ma.getmaskarray(value) if np.ma.isMaskedArray(value) else None
    try:
        array = np.asarray(np.ma.getdata(value) if mask is not None else value)
    except ValueError as error:
        if "inhomogeneous" in str(error) or "sequence" in str(error):
            raise ValueError(f"{name} must be a rectangular array of numbers (every row "
                             f"the same length); got a ragged nested sequence") from None
        raise ValueError(f"{name} must be a numeric array; got {_describe(value)} "
                         f"({error})") from None
    kind = array.dtype.kind
    if kind == "c":
        raise ArgumentTypeError(f"{name} must be real; got complex values")
    if kind == "b":
        raise ArgumentTypeError(f"{name} must be a numeric array; got booleans (dtype "
                                f"bool), which are not quantities")
    if kind in "mM":
        raise ArgumentTypeError(f"{name} must be a numeric array; got dates or times "
                                f"(dtype {array.dtype}); convert them to numbers first")
    if kind in "USV":
        raise ArgumentTypeError(f"{name} must be a numeric array; got dtype "
                                f"{array.dtype} (strings or records), not numbers")
    if kind == "O":
        flat = array.ravel()
        if any(isinstance(x, (str, bytes, bool, np.bool_, complex, np.complexfloating))
               or x is None for x in flat):
            raise ArgumentTypeError(f"{name} must be a numeric array; got a sequence with "
                                    f"items that are not real numbers (strings, booleans, "
                                    f"None or complex)")
    original = array
    try:
        with np.errstate(over="ignore"):  # long double beyond float64: reported below
            array = array.astype(float, copy=False)
    except OverflowError:
        raise ValueError(f"{name} has a value too large for a floating-point number "
                         f"(above 1.8e308); got {_describe(value)}") from None
    except (TypeError, ValueError) as error:
        raise ArgumentTypeError(f"{name} must be a numeric array; got {_describe(value)} "
                                f"that cannot be converted to float ({error})") from None
    if mask is not None and mask.any():
        array = np.where(np.broadcast_to(mask, array.shape), np.nan, array)
    if kind == "f" and original.dtype.itemsize > array.dtype.itemsize:
        # long double: values beyond the float64 range became inf in the conversion
        if (np.isinf(array) & ~np.isinf(original)).any():
            raise ValueError(f"{name} has a value too large for a float64 number (above "
                             f"1.8e308)")
    return array


def _from_pandas(value):
    """A pandas Series or DataFrame of numbers as a float array, with its missing values
    (NaN, None, pd.NA in the nullable dtypes) as NaN; anything else unchanged."""
    if isinstance(value, np.ndarray) or not hasattr(value, "to_numpy"):
        return value
    dtypes = [value.dtype] if hasattr(value, "dtype") else list(getattr(value, "dtypes", []))
    if not dtypes or any(getattr(d, "kind", "O") not in "iuf" for d in dtypes):
        return value  # booleans, strings, dates...: refused, with their own message, below
    try:
        return value.to_numpy(dtype=float, na_value=np.nan)
    except (TypeError, ValueError):
        return value


def check_flag(value, name):
    """Return `value` as a bool if it is a Python or NumPy boolean; else raise.

    A string such as ``'False'`` is truthy and an array has no single truth value, so
    anything but a boolean raises :class:`ArgumentTypeError` naming `name`.
    """
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise ArgumentTypeError(f"{name} must be True or False; got {_describe(value)}")


def check_number(value, name, positive=False):
    """Return `value` as a Python float if it is one finite real number (positive, if
    asked); else raise naming `name`."""
    array = as_float_array(value, name)
    if array.shape != ():
        raise ValueError(f"{name} must be a single number; got shape {array.shape}")
    check_finite_or_nan(array, name, allow_nan=False)
    if positive and not array > 0:
        raise ValueError(f"{name} must be a positive number; got {float(array):g}")
    return float(array)


def check_choice(value, name, choices):
    """Return `value` if it is one of the strings `choices`; else raise naming `name`."""
    expected = " or ".join(repr(c) for c in choices)
    if not isinstance(value, str):
        raise ArgumentTypeError(f"{name} must be {expected}; got {_describe(value)}")
    if value not in choices:
        raise ValueError(f"{name} must be {expected}; got {value!r}")
    return value


def check_vectors(value, name, allow_nan=True, max_abs=MAX_MAGNITUDE):
    """Return `value` as a float array of shape (..., 3).

    Infinite coordinates are always an error; NaN coordinates are missing data and
    are accepted unless `allow_nan` is False. Magnitudes above `max_abs` are refused
    (None: any finite value, for directions whose length does not matter).
    """
    array = as_float_array(value, name)
    if array.ndim == 0 or array.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (..., 3) (3D vectors on the last axis); "
                         f"got shape {array.shape}")
    check_finite_or_nan(array, name, allow_nan, max_abs)
    return array


def check_one_or_per_frame(vectors, name, frames):
    """Return `vectors` ((..., 3), already checked) if they are one vector for every frame,
    (3,) or (1, 3), or one per frame, (frames, 3); a ValueError otherwise (a vector per
    frame of another trial is not stretched or cut to fit)."""
    if vectors.shape not in ((3,), (1, 3), (frames, 3)):
        raise ValueError(f"{name} must have shape (3,) (one for every frame) or "
                         f"(frames, 3) = {(frames, 3)}; got shape {vectors.shape}")
    return vectors


def check_finite_or_nan(array, name, allow_nan=True, max_abs=MAX_MAGNITUDE):
    """Raise ValueError if `array` has infinite values, magnitudes above `max_abs` (None:
    no limit) or NaN (if not allowed); return whether it holds no NaN.

    One largest/smallest pass checks all three (reductions without temporaries, about the
    cost of ``np.isinf(array).any()``): infinite values are the largest or smallest, and
    exceed `max_abs`; NaN propagates through max (then the NaN-ignoring reductions are
    used), which also tells a caller whether the array has gaps.
    """
    nan_free = True
    if array.size:
        high, low = np.max(array), np.min(array)
        if np.isnan(high):  # NaN propagates through max: look again, ignoring NaN
            nan_free = False
            high, low = np.fmax.reduce(array, axis=None), np.fmin.reduce(array, axis=None)
        if max_abs is None:
            if high == np.inf or low == -np.inf:
                raise ValueError(f"{name} contains infinite values; use NaN for missing "
                                 f"data")
        elif high > max_abs or low < -max_abs:
            if np.isinf(array).any():
                raise ValueError(f"{name} contains infinite values; use NaN for missing "
                                 f"data")
            raise ValueError(f"{name} has values of magnitude up to "
                             f"{np.nanmax(np.abs(array)):.3g}; values beyond {max_abs:g} "
                             f"are not physical in any unit (and would overflow when "
                             f"squared): check the data and their units")
    if not allow_nan and not nan_free:
        raise ValueError(f"{name} contains NaN values, which are not allowed here")
    return nan_free


def check_rotation_matrix(value, name="R", atol=ORTHONORMAL_ATOL):
    """Return `value` as a float array of rotation matrices, shape (..., 3, 3).

    Items that contain NaN are missing data and are not checked. Every other item
    must be orthonormal within `atol` and have determinant +1.
    """
    R = as_float_array(value, name)
    if R.ndim < 2 or R.shape[-2:] != (3, 3):
        raise ValueError(f"{name} must have shape (..., 3, 3); got shape {R.shape}")
    check_finite_or_nan(R, name)
    if R.size:
        # R @ R.T and det(R) from the rows, element-wise over the matrices (the nine
        # entries as contiguous (9, matrices) rows): the same values as a batched matmul
        # and LU determinant, several times faster. A NaN anywhere in a matrix makes its
        # deviation and determinant NaN, which no test below flags: missing matrices are
        # skipped without a separate pass.
        e = np.ascontiguousarray(R.reshape(-1, 9).T)
        rows = e[0:3], e[3:6], e[6:9]
        deviation = np.zeros(e.shape[1])
        for i in range(3):
            for j in range(i, 3):
                a, b = rows[i], rows[j]
                dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
                np.maximum(deviation, np.abs(dot - 1.0 if i == j else dot), out=deviation)
        bad = np.flatnonzero(deviation > atol)
        if bad.size:
            raise ValueError(
                f"{name} is not a rotation matrix: R @ R.T differs from the identity by "
                f"up to {np.nanmax(deviation):.3g} (tolerance {atol:g}) in {bad.size} of "
                f"{np.count_nonzero(~np.isnan(deviation))} matrices")
        r0, r1, r2 = rows
        det = (r0[0] * (r1[1] * r2[2] - r1[2] * r2[1]) + r0[1] * (r1[2] * r2[0] - r1[0] * r2[2])
               + r0[2] * (r1[0] * r2[1] - r1[1] * r2[0]))
        bad = np.flatnonzero(det < 0)
        if bad.size:
            raise ValueError(
                f"{name} is not a rotation matrix: det(R) = {det[bad[0]]:.3g} (a reflection) "
                f"in {bad.size} of {np.count_nonzero(~np.isnan(deviation))} matrices; a "
                f"rotation has det(R) = +1")
    return R


def check_sequence(sequence):
    """Return the upper-case axis sequence and whether it is a proper Euler sequence.

    Accepts the 6 Cardan (Tait-Bryan) sequences, with three different axes, and the 6
    proper Euler sequences, whose first and third axes are the same. Letter case does
    not matter (it never selects intrinsic or extrinsic rotations).
    """
    if not isinstance(sequence, str):
        raise ArgumentTypeError(f"sequence must be a string such as 'ZXY'; got "
                                f"{_describe(sequence)}")
    seq = sequence.upper()
    valid = (len(seq) == 3 and set(seq) <= set("XYZ")
             and seq[0] != seq[1] and seq[1] != seq[2])
    if not valid:
        raise ValueError(
            f"unknown rotation sequence {sequence!r}: expected three axes from x, y, z with "
            "no axis repeated consecutively, e.g. 'ZXY' (Cardan) or 'ZXZ' (Euler)")
    return seq, seq[0] == seq[2]


#: The package's folder: a warning is attributed to the first frame outside it.
_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def warn(message, category=UserWarning):
    """Issue a warning attributed to the user's line: the first caller outside the package.

    Every warning of the package goes through here, so that it points at the line that
    called the package (a script's, a notebook cell's, a test's), however deep inside the
    package it was found: a fixed ``stacklevel`` would point inside the package whenever a
    public function is reached through another (``lower_limb_angles`` calls
    ``LowerLimbModel.angles``, which calls the checks). Python 3.12's
    ``warnings.warn(skip_file_prefixes=...)`` does the same; this package supports 3.10.
    """
    level, frame = 1, inspect.currentframe()
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE):
        frame, level = frame.f_back, level + 1
    warnings.warn(message, category, stacklevel=level)


def warn_frames(count, total, what):
    """Issue one RuntimeWarning summarizing `count` of `total` frames."""
    if count:
        warn(f"{count} of {total} frames {what}", RuntimeWarning)


def missing_rows(values):
    """True where an item of `values` (its entries on the last axis: a point's x, y, z, a
    matrix's nine entries) has a NaN entry, shape ``values.shape[:-1]``; for data that
    holds no infinity (a trial's markers, which MarkerTable refuses, and what is built
    from them): the sum of the entries is NaN exactly then, several times faster than
    ``np.isnan(values).any(axis=-1)`` over a short axis."""
    return np.isnan(np.einsum("...i->...", values))


def runs_mask(length, first, stop):
    """Whether each of `length` items lies in one of the runs ``[first, stop)`` (index
    arrays of the same length, each 0 to `length`; any order, overlapping, touching or
    empty, a run with `stop` <= `first` empty): the runs merged, then one stretch of True
    per merged run, written at once (no pass over the items but the writing of the mask).

    Examples
    --------
    >>> from bmc_functions._checks import runs_mask
    >>> runs_mask(8, [5, 1, 2], [7, 3, 2]).astype(int)
    array([0, 1, 1, 0, 0, 1, 1, 0])
    """
    first, stop = np.asarray(first, dtype=np.intp), np.asarray(stop, dtype=np.intp)
    if not first.size:
        return np.zeros(length, dtype=bool)
    stop = np.maximum(stop, first)                   # an empty run reaches nothing
    order = np.argsort(first, kind="stable")
    first, stop = first[order], np.maximum.accumulate(stop[order])   # reach so far
    opens = np.r_[True, first[1:] > stop[:-1]]       # a run that starts a merged one
    closes = np.r_[opens[1:], True]                  # ... and the one that ends it
    bounds = np.r_[0, np.c_[first[opens], stop[closes]].ravel(), length]
    return np.repeat(np.arange(len(bounds) - 1) % 2 == 1, np.diff(bounds))


def mean_static(value, name):
    """Average a static trial, (n, 3) or (frames, n, 3), to (n, 3): each marker over the
    frames in which it is visible (shared by tracking and gap_filling)."""
    array = check_vectors(value, name)
    if array.ndim == 3:
        missing = np.isnan(array).any(axis=2).all(axis=0)
        if missing.any():
            raise ValueError(f"{name}: marker(s) {np.flatnonzero(missing).tolist()} are "
                             "missing (NaN) in every frame of the static trial")
        present = ~np.isnan(array).any(axis=2, keepdims=True)
        array = np.where(present, array, 0.0).sum(axis=0) / present.sum(axis=0)
    elif array.ndim == 2:
        missing = np.isnan(array).any(axis=1)
        if missing.any():
            raise ValueError(f"{name}: marker(s) {np.flatnonzero(missing).tolist()} are "
                             "missing (NaN) in the static trial")
    else:
        raise ValueError(f"{name} must have shape (n, 3) or (frames, n, 3); got shape "
                         f"{array.shape}")
    return array


#: A cluster's fit in a frame is an outlier when its RMS marker distance (svdt's RMSE,
#: which is per coordinate, times sqrt(3)) exceeds RESIDUAL_FACTOR times the trial's
#: lower quartile (the cluster's usual noise and soft-tissue artefact), clipped to between
#: RESIDUAL_FLOOR and RESIDUAL_CEILING times the cluster's size (the RMS distance of its
#: markers from their centroid). Soft-tissue artefact deforms a cluster by up to about
#: 0.13-0.16 of its size relative to its first frame in the synthetic knee trials of
#: notebook 11 at 120 degrees of flexion (0.12 at 90 degrees: 8.5 mm for the 70 mm shank
#: cluster of data/functional), while a marker swapped or mislabelled, or a reference of
#: another cluster, size (30 % or more), marker order or units, misplaces the markers by
#: a good part of the cluster's size. The ceiling catches a reference that fits no frame
#: (then the quartile itself is large).
RESIDUAL_FACTOR = 5.0
RESIDUAL_FLOOR = 0.2
RESIDUAL_CEILING = 0.25


def residual_outliers(rmse, shape, name, consequence):
    """Frames whose svdt RMSE shows markers not shaped as `shape`; one warning.

    `rmse` (frames,) from svdt of `shape` (n, 3) to the frames (NaN where undetermined).
    Returns a boolean mask of the outlier frames.
    """
    distance = np.sqrt(3.0) * np.asarray(rmse, dtype=float)
    seen = np.isfinite(distance)
    if not seen.any():
        return np.zeros(distance.shape, bool)
    shape = np.asarray(shape, dtype=float)
    radius = float(np.sqrt(((shape - shape.mean(axis=0)) ** 2).sum(axis=1).mean()))
    threshold = float(np.clip(RESIDUAL_FACTOR * np.quantile(distance[seen], 0.25),
                              RESIDUAL_FLOOR * radius, RESIDUAL_CEILING * radius))
    bad = seen & (distance > threshold)
    if bad.any():
        warn(
            f"{int(bad.sum())} of {int(seen.sum())} frames of {name} do not have the "
            f"cluster's shape: RMS marker distance from the fitted shape up to "
            f"{np.nanmax(distance):.3g} (warning above {threshold:.3g}: {RESIDUAL_FACTOR:g} "
            f"times the trial's lower quartile, within {RESIDUAL_FLOOR:g} to "
            f"{RESIDUAL_CEILING:g} times the cluster's size, {radius:.3g}). A marker "
            f"swapped, slid or mislabelled there, or a reference of another cluster, size, "
            f"marker order or units; {consequence}", RuntimeWarning)
    return bad


def check_rate_attr(frame, time, name, *, error=False):
    """Warn (raise ValueError if `error`) if ``attrs['rate']`` contradicts the time index.

    Both the span (frames - 1 over the time from first to last, which averages out a
    time rounded to 1 ms) and the median step (which frames skipped by a writer do not
    change) must be more than 2 % off the rate.
    """
    rate = frame.attrs.get("rate") if hasattr(frame, "attrs") else None
    if rate is None or len(time) < 3 or not time[-1] > time[0]:
        return
    try:
        rate = float(rate)
    except (TypeError, ValueError):
        return
    from_span = (len(time) - 1) / (time[-1] - time[0])
    step = float(np.median(np.diff(time)))
    from_step = 1.0 / step if step > 0 else np.inf
    if np.isfinite(rate) and rate > 0 and min(abs(from_span / rate - 1),
                                              abs(from_step / rate - 1)) > 0.02:
        message = (f"{name}: attrs['rate'] = {rate:g} Hz, but its time index steps at "
                   f"{from_span:.4g} Hz ({len(time)} frames from {time[0]:.4g} to "
                   f"{time[-1]:.4g})")
        if error:
            raise ValueError(message + ": the times found would not be the trial's; "
                             "correct attrs['rate'] or the index (an index in frame "
                             "numbers or ms is not a time in s; after df.iloc[::k], "
                             "divide attrs['rate'] by k)")
        warn(message + ": the index is used as the time; check which one is right (an "
             "index in frame numbers or ms is not a time in s)", RuntimeWarning)


# --- files: paths and number formats

def check_output_path(path):
    """Refuse a path to write to that is not a file name, or whose folder does not exist
    (a writer would otherwise fail half-way, or create nothing where the user looks).
    Raises TypeError or FileNotFoundError naming `path`; returns it unchanged."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name (str or path-like); got "
                        f"{type(path).__name__}")
    folder = os.path.dirname(os.fspath(path)) or "."
    if not os.path.isdir(folder):
        raise FileNotFoundError(f"path: the folder {folder!r} of {os.fspath(path)!r} does "
                                f"not exist")
    return path


def check_regular_file(path, what):
    """Refuse a path that is not a regular file before it is opened.

    A directory, a device (``/dev/zero``), a pipe or a socket would make a reader fail
    obscurely or never finish; `what` names the format expected (``'TRC'``, ``'C3D'``).
    Raises TypeError if `path` is not a file name, FileNotFoundError if nothing is there.
    """
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


# One printf floating-point conversion: flags, width, precision, then the letter.
_FLOAT_CONVERSION = r"%[-+ #0]*\d*(?:\.\d*)?"


def check_float_format(float_format):
    """Check a printf-style format writes numbers that read back; return it.

    ``'%d'`` or ``'%x'`` would truncate every value without a word, ``'abc'`` or
    ``'%s %s'`` would not write a number at all: each is a ValueError naming the format;
    a format that is not a string is a TypeError.
    """
    if not isinstance(float_format, str):
        raise TypeError(f"float_format must be a printf-style format string such as "
                        f"'%.6f'; got {type(float_format).__name__}")
    conversion = re.fullmatch(_FLOAT_CONVERSION + "([a-zA-Z])", float_format)
    if conversion is not None and conversion.group(1) not in "eEfFgGrs":
        integer = conversion.group(1) in "diuoxXc"
        raise ValueError(f"float_format must be one floating-point conversion (%f, %e or "
                         f"%g), like '%.6f' or '%.8g'; got {float_format!r}, which "
                         + ("truncates the values (write '%.0f' to round to whole numbers)"
                            if integer else "is no conversion of a number"))
    if not _formats_numbers(float_format):
        raise ValueError(f"float_format must format one number as a number, like '%.6f', "
                         f"'%.3f' or '%.8g'; got {float_format!r}")
    if re.fullmatch(_FLOAT_CONVERSION + "[eEfFgGrs]", float_format) is None:
        raise ValueError(f"float_format must be one floating-point conversion (%f, %e or "
                         f"%g), like '%.6f' or '%.8g'; got {float_format!r}")
    return float_format


def _formats_numbers(float_format):
    """Whether `float_format` prints sample values as texts that read back as them."""
    try:
        samples = [float_format % value for value in (1.25, -1234.5, 1e-7, 3e12)]
    except (TypeError, ValueError, OverflowError):
        return False
    for text in samples:
        if re.search(r"\s", text):
            return False
        try:
            number = float(text)
        except ValueError:
            return False
        if not np.isfinite(number):
            return False
    return abs(float(samples[1]) + 1234.5) <= 1.0  # the number, not a constant text

# --- numbers given as arguments

def check_scalar(value, name, expected, *, minimum=None, maximum=None, strict=False,
                 integer=False):
    """Return `value` as one finite number within its bounds; else raise naming `name`.

    The message is always ``"{name} must be {expected}; got {value}"``: `expected` says
    what the argument is and its range in the caller's words (``'a time (s) >= 0'``,
    ``'an integer >= 2'``). A value that is no number (a string, a boolean, None, an
    array, NaN or infinity) raises :class:`ArgumentTypeError` or ValueError; one out of
    ``[minimum, maximum]`` (``minimum`` excluded if `strict`) raises ValueError.
    With `integer`, only Python or NumPy integers are accepted (not ``2.0``), returned
    as int; else a float.
    """
    refused = f"{name} must be {expected}; got {_describe(value)}"
    several = isinstance(value, (list, tuple, dict, set)) or (
        isinstance(value, np.ndarray) and value.ndim > 0)
    if several:                                     # several numbers, not one
        raise ArgumentTypeError(refused)
    if integer:
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
            raise ArgumentTypeError(refused)
        number = int(value)
    else:
        try:
            number = check_number(value, name)
        except ArgumentTypeError:
            raise ArgumentTypeError(refused) from None
        except ValueError:
            raise ValueError(refused) from None
    below = minimum is not None and (number <= minimum if strict else number < minimum)
    if below or (maximum is not None and number > maximum):
        raise ValueError(f"{name} must be {expected}; got "
                         f"{number if integer else format(number, '.6g')}")
    return number
