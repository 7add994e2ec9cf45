"""Least-squares rigid-body transformation between two marker sets (the SVD method)."""

import numpy as np

from ._checks import as_float_array, check_finite_or_nan, warn_frames

#: Relative tolerance for a degenerate (coincident or collinear) marker set: the second
#: singular value of the centred markers at most this fraction of the largest.
COLLINEAR_RTOL = 1e-6


def _as_marker_sets(A, B, order):
    """Validate and reshape to A (n, 3) and B (F, n, 3); also return whether B was one set."""
    if order not in ("col", "row"):
        raise ValueError(f"order must be 'col' or 'row'; got {order!r}")
    A = as_float_array(A, "A")
    B = as_float_array(B, "B")
    check_finite_or_nan(A, "A", allow_nan=False)
    check_finite_or_nan(B, "B")
    if order == "col":
        if A.ndim != 1 or A.size % 3:
            raise ValueError(f"with order='col', A must be 1D [x1, y1, z1, ..., xn, yn, zn] "
                             f"with a length that is a multiple of 3; got shape {A.shape}")
        if B.ndim not in (1, 2) or B.shape[-1] % 3:
            raise ValueError(f"with order='col', B must have shape (3n,) or (frames, 3n) with "
                             f"3n a multiple of 3; got shape {B.shape}")
        single = B.ndim == 1
        A = A.reshape(-1, 3)
        B = B.reshape(-1, B.shape[-1] // 3, 3)
    else:
        if A.ndim != 2 or A.shape[1] != 3:
            raise ValueError(f"with order='row', A must have shape (n, 3), one marker per "
                             f"row; got shape {A.shape}")
        if B.ndim not in (2, 3) or B.shape[-1] != 3:
            raise ValueError(f"with order='row', B must have shape (n, 3) or (frames, n, 3); "
                             f"got shape {B.shape}")
        single = B.ndim == 2
        B = B.reshape(-1, B.shape[-2], 3)
    n = A.shape[0]
    if n < 3:
        raise ValueError(f"at least 3 markers are needed to determine a 3D rigid-body "
                         f"transformation; A has {n} marker(s) (shape {A.shape})")
    if B.shape[1] != n:
        raise ValueError(f"B must have the same number of markers as A ({n}); got "
                         f"{B.shape[1]} markers")
    sv = np.linalg.svd(A - A.mean(axis=0), compute_uv=False)
    if sv[1] <= COLLINEAR_RTOL * sv[0]:
        kind = "coincident" if sv[0] == 0 else "collinear"
        raise ValueError(f"the markers of A are {kind}: the rotation about their line is "
                         f"undetermined; at least 3 non-collinear markers are needed "
                         f"(singular values of centred A: {np.array2string(sv, precision=3)})")
    return A, B, single


def cross_covariance(A, B, weights):
    """Centroids and cross-covariance matrices of weighted marker sets.

    Parameters
    ----------
    A : ndarray, shape (n, 3)
    B : ndarray, shape (F, n, 3)
        Without NaN (missing markers replaced by any finite value and given weight 0).
    weights : ndarray, shape (F, n)
        1 for a marker seen in that frame, 0 for a missing one.

    Returns
    -------
    A_mean, B_mean : ndarray, shape (F, 3)
        Centroids of the markers seen in each frame.
    M : ndarray, shape (F, 3, 3)
        :math:`M = \\sum_i w_i (b_i - \\bar b)(a_i - \\bar a)^T`.
    """
    count = weights.sum(axis=1)[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        A_mean = weights @ A / count
        B_mean = np.einsum("fn,fnj->fj", weights, B) / count
    # sum w b a^T - count * b_mean a_mean^T, written without forming centred copies
    M = np.einsum("fn,fni,nj->fij", weights, B, A) - count[:, :, None] * (
        B_mean[:, :, None] * A_mean[:, None, :])
    return A_mean, B_mean, M


def rotation_from_covariance(M):
    """The proper rotation R maximizing trace(R^T M), by SVD with the reflection fix.

    Parameters
    ----------
    M : ndarray, shape (F, 3, 3)

    Returns
    -------
    R : ndarray, shape (F, 3, 3)
    degenerate : ndarray of bool, shape (F,)
        True where M has rank < 2 (relative tolerance ``COLLINEAR_RTOL**2`` on its
        singular values), so that R is not unique.
    """
    U, S, Vt = np.linalg.svd(M)
    d = np.sign(np.linalg.det(U @ Vt))
    d[d == 0] = 1.0
    R = (U * np.stack([np.ones_like(d), np.ones_like(d), d], axis=-1)[:, None, :]) @ Vt
    degenerate = S[:, 1] <= COLLINEAR_RTOL**2 * S[:, 0]
    return R, degenerate


def svdt(A, B, order="col"):
    r"""Least-squares rigid-body transformation between two marker sets: B = R A + L.

    Finds the rotation matrix R and translation vector L that minimize the sum of squared
    distances between the markers of `B` and the transformed markers of `A` [1]_, [2]_.
    A typical use: `A` holds the markers of a static (calibration) trial, `B` the same
    markers in every frame of a dynamic trial; then ``R @ p + L`` takes a point ``p``
    known in the static trial to its position in each frame.

    Parameters
    ----------
    A : array_like
        Marker coordinates at the reference instant (at least 3 non-collinear markers;
        no NaN). ``order='col'``: shape (3n,) as ``[x1, y1, z1, ..., xn, yn, zn]``.
        ``order='row'``: shape (n, 3), one marker per row.
    B : array_like
        The same markers at one or more instants. ``order='col'``: shape (3n,) or
        (ni, 3n), one instant per row. ``order='row'``: shape (n, 3) or (ni, n, 3).
        NaN coordinates mark a marker missing (occluded) in that instant.
    order : {'col', 'row'}, optional
        Layout of `A` and `B` as above. Default 'col'.

    Returns
    -------
    R : ndarray, shape (3, 3) or (ni, 3, 3)
        Rotation matrices (orthonormal, determinant +1).
    L : ndarray, shape (3,) or (ni, 3)
        Translation vectors.
    RMSE : float or ndarray, shape (ni,)
        Root-mean-square residual, :math:`\sqrt{\sum_i \|e_i\|^2 / (3n)}` over the n
        markers used, in the units of the coordinates.

    Raises
    ------
    ValueError
        If `order` is unknown; a shape does not fit `order` (or a 'col' length is not a
        multiple of 3); there are fewer than 3 markers; `B` has a different number of
        markers than `A`; `A` contains NaN or either contains infinite values; or the
        markers of `A` are coincident or collinear (second singular value of the
        centred markers at most ``COLLINEAR_RTOL = 1e-6`` times the largest).

    Warns
    -----
    RuntimeWarning
        Once per call, with the number of instants that could not be fitted: fewer than
        3 visible markers, or visible markers collinear. Their R, L and RMSE are NaN.

    Notes
    -----
    The model is :math:`b_i = R a_i + L + e_i`. The least-squares translation makes the
    centroids coincide, :math:`L = \bar b - R \bar a`, which leaves the rotation that
    maximizes :math:`\operatorname{tr}(R^T M)` with the cross-covariance matrix
    :math:`M = \sum_i (b_i - \bar b)(a_i - \bar a)^T`. With the singular value
    decomposition :math:`M = U S V^T`,

    .. math:: R = U \operatorname{diag}(1, 1, \det(U V^T))\, V^T .

    Without the middle factor, :math:`U V^T` is a reflection (det = -1) when the data
    are mirrored or the markers nearly coplanar and noisy; flipping the direction of the
    smallest singular value gives the best proper rotation [3]_, [4]_.

    A marker whose coordinates contain NaN in an instant is left out of that instant's
    fit only (centroids, M and RMSE use the markers seen); the instant is fitted if at
    least 3 non-collinear markers remain.

    References
    ----------
    .. [1] Söderkvist I, Wedin PA (1993) Determining the movements of the skeleton using
       well-configured markers. J Biomech 26:1473-1477.
    .. [2] Challis JH (1995) A procedure for determining rigid body transformation
       parameters. J Biomech 28:733-737.
    .. [3] Kabsch W (1976) A solution for the best rotation to relate two sets of
       vectors. Acta Crystallogr A 32:922-923.
    .. [4] Umeyama S (1991) Least-squares estimation of transformation parameters
       between two point patterns. IEEE Trans Pattern Anal Mach Intell 13:376-380.

    Examples
    --------
    Four markers rotated by 90 degrees about z:

    >>> import numpy as np
    >>> from bmc_functions import svdt
    >>> A = np.array([0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0])
    >>> B = np.array([0, 0, 0, 0, 1, 0, -1, 0, 0, -1, 1, 0])
    >>> R, L, RMSE = svdt(A, B)
    >>> R.round(4) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    >>> L.round(4) + 0.0, round(float(RMSE), 4)
    (array([0., 0., 0.]), 0.0)

    The same with one marker per row, and for two instants at once:

    >>> R, L, RMSE = svdt(A.reshape(4, 3), B.reshape(4, 3), order='row')
    >>> R, L, RMSE = svdt(A, np.vstack((B, B)))
    >>> R.shape, L.shape, RMSE.shape
    ((2, 3, 3), (2, 3), (2,))
    """
    A, B, single = _as_marker_sets(A, B, order)
    seen = ~np.isnan(B).any(axis=2)
    weights = seen.astype(float)
    B_filled = np.where(seen[:, :, None], B, 0.0)

    A_mean, B_mean, M = cross_covariance(A, B_filled, weights)
    count = weights.sum(axis=1)
    undetermined = count < 3
    M[undetermined] = np.eye(3)  # placeholder, so that the SVD sees finite values
    R, degenerate = rotation_from_covariance(M)
    undetermined |= degenerate

    L = B_mean - np.einsum("fij,fj->fi", R, A_mean)
    residual = np.einsum("fij,nj->fni", R, A) + L[:, None, :] - B_filled
    with np.errstate(invalid="ignore", divide="ignore"):
        RMSE = np.sqrt(np.einsum("fn,fni,fni->f", weights, residual, residual) / (3 * count))

    R[undetermined] = np.nan
    L[undetermined] = np.nan
    RMSE[undetermined] = np.nan
    warn_frames(int(undetermined.sum()), undetermined.size,
                "have fewer than 3 non-collinear visible markers; their R, L and RMSE are NaN",
                stacklevel=3)
    if single:
        return R[0], L[0], RMSE[0]
    return R, L, RMSE
