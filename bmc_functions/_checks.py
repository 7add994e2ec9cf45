"""Input validation shared by the public functions.

One function per concept (a vector array, a rotation matrix, an angle sequence), called
at the boundary of every public function so that the checks are not scattered and every
message has the same form: what was received, and what was expected.
"""

import warnings

import numpy as np

#: Largest deviation of ``R @ R.T`` from the identity accepted for a rotation matrix.
ORTHONORMAL_ATOL = 1e-6


def as_float_array(value, name):
    """Return `value` as a float64 array, or raise ValueError naming `name`."""
    if np.iscomplexobj(value):
        raise ValueError(f"{name} must be real; got complex values")
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name} must be a numeric array; got {type(value).__name__} "
                         f"that cannot be converted to float ({error})") from None
    return array


def check_vectors(value, name, allow_nan=True):
    """Return `value` as a float array of shape (..., 3).

    Infinite coordinates are always an error; NaN coordinates are missing data and
    are accepted unless `allow_nan` is False.
    """
    array = as_float_array(value, name)
    if array.ndim == 0 or array.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (..., 3) (3D vectors on the last axis); "
                         f"got shape {array.shape}")
    check_finite_or_nan(array, name, allow_nan)
    return array


def check_finite_or_nan(array, name, allow_nan=True):
    """Raise ValueError if `array` has infinite values (or NaN, if not allowed)."""
    if np.isinf(array).any():
        raise ValueError(f"{name} contains infinite values; use NaN for missing data")
    if not allow_nan and np.isnan(array).any():
        raise ValueError(f"{name} contains NaN values, which are not allowed here")


def check_rotation_matrix(value, name="R", atol=ORTHONORMAL_ATOL):
    """Return `value` as a float array of rotation matrices, shape (..., 3, 3).

    Items that contain NaN are missing data and are not checked. Every other item
    must be orthonormal within `atol` and have determinant +1.
    """
    R = as_float_array(value, name)
    if R.ndim < 2 or R.shape[-2:] != (3, 3):
        raise ValueError(f"{name} must have shape (..., 3, 3); got shape {R.shape}")
    check_finite_or_nan(R, name)
    Rf = R.reshape(-1, 3, 3)
    if Rf.size:
        # R @ R.T and det(R) from the rows, element-wise over the matrices: the same
        # values as a batched matmul and LU determinant, several times faster. A NaN
        # anywhere in a matrix makes its deviation and determinant NaN, which no test
        # below flags: missing matrices are skipped without a separate pass.
        rows = Rf[:, 0], Rf[:, 1], Rf[:, 2]
        deviation = np.zeros(len(Rf))
        for i in range(3):
            for j in range(i, 3):
                dot = np.einsum("fk,fk->f", rows[i], rows[j])
                np.maximum(deviation, np.abs(dot - 1.0 if i == j else dot), out=deviation)
        bad = np.flatnonzero(deviation > atol)
        if bad.size:
            raise ValueError(
                f"{name} is not a rotation matrix: R @ R.T differs from the identity by "
                f"up to {np.nanmax(deviation):.3g} (tolerance {atol:g}) in {bad.size} of "
                f"{np.count_nonzero(~np.isnan(deviation))} matrices")
        det = np.einsum("fk,fk->f", rows[0], np.cross(rows[1], rows[2]))
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
        raise ValueError(f"sequence must be a string such as 'ZXY'; got {sequence!r}")
    seq = sequence.upper()
    valid = (len(seq) == 3 and set(seq) <= set("XYZ")
             and seq[0] != seq[1] and seq[1] != seq[2])
    if not valid:
        raise ValueError(
            f"unknown rotation sequence {sequence!r}: expected three axes from x, y, z with "
            "no axis repeated consecutively, e.g. 'ZXY' (Cardan) or 'ZXZ' (Euler)")
    return seq, seq[0] == seq[2]


def warn_frames(count, total, what, stacklevel=3):
    """Issue one RuntimeWarning summarizing `count` of `total` frames."""
    if count:
        warnings.warn(f"{count} of {total} frames {what}", RuntimeWarning,
                      stacklevel=stacklevel)


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
