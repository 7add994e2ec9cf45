"""Least-squares rigid-body transformation between two marker sets (the SVD method).

svdt computes the SVD method's rotation in closed form for speed (Horn's quaternion
method, :mod:`bmc_functions.rigid_body.quaternion_fit`), and with the SVD itself (on
scaled markers) in the frames the closed form cannot fit: ill-conditioned or tiny ones,
and every frame of a set of more than ``MOMENT_MATRIX_MAX_MARKERS`` markers.
"""

import numpy as np

from .._checks import as_float_array, check_choice, check_finite_or_nan, warn_frames
from .._threads import one_blas_thread
from .quaternion_fit import rotation_rows

#: Relative tolerance for a degenerate (coincident or collinear) marker set: the second
#: singular value of the centred markers at most this fraction of the largest.
COLLINEAR_RTOL = 1e-6

#: Below this bound of the cross-covariance, :math:`\sqrt{G_A G_B}`, a frame is fitted
#: again with its markers scaled (their products would lose digits to underflow).
SMALL_BOUND = 1e-150

#: Above this number of markers, :func:`svdt` fits each frame by an SVD on blocks of
#: frames instead of through the moment matrix, whose (3n)^2 entries would take
#: gigabytes for thousands of markers. Memory, not speed, sets it: with 2^20 marker
#: positions per call the closed form was still 2.8 times faster at 256 markers and 1.5
#: times at 512 (one run on a loaded 2-core machine), but its work space for a block of
#: CHUNK_FRAMES frames, (12 + 6n) values per frame, is 50 MB at 128 markers and 200 MB
#: at 512, against a few MB for the SVD path.
MOMENT_MATRIX_MAX_MARKERS = 128

#: Frames fitted per block in :func:`svdt` (a block's temporaries fit in the cache).
CHUNK_FRAMES = 8192


def _as_marker_sets(A, B, order):
    """Validate and reshape to A (n, 3) and B (F, n, 3); also return whether B was one set."""
    check_choice(order, "order", ("col", "row"))
    A = as_float_array(A, "A")
    B = as_float_array(B, "B")
    check_finite_or_nan(A, "A", allow_nan=False)
    check_finite_or_nan(B, "B")
    if order == "col":
        if A.ndim != 1 or A.size % 3:
            hint = ("; for one marker per row, pass order='row'"
                    if A.ndim == 2 and A.shape[1] == 3 else "")
            raise ValueError(f"with order='col', A must be 1D [x1, y1, z1, ..., xn, yn, zn] "
                             f"with a length that is a multiple of 3; got shape {A.shape}"
                             + hint)
        if B.ndim not in (1, 2) or B.shape[-1] % 3:
            raise ValueError(f"with order='col', B must have shape (3n,) or (frames, 3n) with "
                             f"3n a multiple of 3; got shape {B.shape}")
        single = B.ndim == 1
        A = A.reshape(-1, 3)
        # explicit frame count: reshape(-1, 0, 3) fails for a B without markers
        B = B.reshape(1 if single else B.shape[0], B.shape[-1] // 3, 3)
    else:
        if A.ndim != 2 or A.shape[1] != 3:
            raise ValueError(f"with order='row', A must have shape (n, 3), one marker per "
                             f"row; got shape {A.shape}")
        if B.ndim not in (2, 3) or B.shape[-1] != 3:
            raise ValueError(f"with order='row', B must have shape (n, 3) or (frames, n, 3); "
                             f"got shape {B.shape}")
        single = B.ndim == 2
        B = B.reshape(1 if single else B.shape[0], B.shape[-2], 3)
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


def _moment_matrix(A):
    """The matrix W that gives, for one frame's markers ``b`` (shape (n, 3)) flattened,
    ``b.ravel() @ W`` = [M (9 entries, row-major), centroid (3), centred b (3n)].

    With A centred, :math:`M = \\sum_i b_i (a_i - \\bar a)^T` needs no centred copy of
    B (the centred ``a_i`` sum to zero), so that every frame's moments are one matrix
    product over all frames: the cheapest way to compute them with NumPy (BLAS).
    """
    n = A.shape[0]
    A_centred = A - A.mean(axis=0)
    # Centre twice: after one pass the centred markers of a cluster far from the origin
    # sum to ~ |A| * 1e-16, not 0, and that error would be multiplied by |B| in M (at
    # 1e6 mm, 1e-7 in R). After the second pass the sum is ~ 1e-16 times the cluster size.
    A_centred -= A_centred.mean(axis=0)
    W = np.zeros((3 * n, 12 + 3 * n))
    for i in range(3):
        W[i::3, 3 * i:3 * i + 3] = A_centred  # M[i, j] = sum_k b[k, i] * a_centred[k, j]
        W[i::3, 9 + i] = 1.0 / n
    W[:, 12:] = np.eye(3 * n) - np.kron(np.full((n, n), 1.0 / n), np.eye(3))
    return W


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

    Notes
    -----
    When every marker is seen (all weights 1) this is one matrix product of the
    flattened frames with a fixed matrix built from A (see ``_moment_matrix``); the
    general case uses weighted sums of the centred markers of each frame (centring avoids
    cancellation for markers far from the origin).
    """
    F, n = B.shape[:2]
    if np.all(weights == 1):
        X = B.reshape(F, 3 * n) @ _moment_matrix(A)[:, :12]
        A_mean = np.broadcast_to(A.mean(axis=0), (F, 3)).copy()
        return A_mean, X[:, 9:12], X[:, :9].reshape(F, 3, 3)
    A_origin = A.mean(axis=0)
    A_centred = A - A_origin
    count = weights.sum(axis=1)[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        A_mean = weights @ A_centred / count
        B_mean = np.einsum("fn,fnj->fj", weights, B) / count
    # With centred copies: the shortcut sum w b a^T - count b_mean a_mean^T cancels
    # digits when the markers are far from the origin.
    M = np.einsum("fn,fni,fnj->fij", weights, B - B_mean[:, None, :],
                  A_centred - A_mean[:, None, :])
    return A_mean + A_origin, B_mean, M


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


@one_blas_thread
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
        NaN coordinates (or masked entries of a masked array) mark a marker missing
        (occluded) in that instant.
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
    TypeError
        If `A` or `B` is not numeric (None, booleans, strings, dates, complex) or `order`
        is not a string (:class:`~bmc_functions._checks.ArgumentTypeError`, also a
        ValueError).
    ValueError
        If `order` is unknown; a shape does not fit `order` (or a 'col' length is not a
        multiple of 3) or a nested list is ragged; there are fewer than 3 markers; `B`
        has a different number of markers than `A`; `A` contains NaN (or masked
        entries) or either contains infinite values or values beyond
        ``MAX_MAGNITUDE = 1e100``; or the markers of `A` are coincident or collinear
        (second singular value of the centred markers at most ``COLLINEAR_RTOL = 1e-6``
        times the largest).

    Warns
    -----
    RuntimeWarning
        Once per call, with the number of instants that could not be fitted and why:
        fewer than 3 non-collinear visible markers, or visible markers of `B` that
        coincide or are collinear. Their R, L and RMSE are NaN.

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
    least 3 markers remain that are not collinear in `A` (by the ``COLLINEAR_RTOL``
    test applied to `A`).

    *How it is computed.* The result is the one defined above, but for speed over many
    frames the rotation is computed in closed form rather than by one SVD per frame:
    the maximum of :math:`\operatorname{tr}(R^T M)` is the largest eigenvalue
    :math:`\lambda` of Horn's symmetric 4x4 matrix built from M [5]_, found by Newton's
    iteration on its characteristic polynomial [6]_, and R follows from M and
    :math:`\lambda` (see :mod:`bmc_functions.rigid_body.quaternion_fit`), element-wise over blocks
    of frames. It agrees with the SVD within 1e-10 (typically 1e-13). M is divided by
    :math:`\sqrt{G_A}\sqrt{G_B}` (the sums of squares of the centred markers, a bound of
    the largest eigenvalue) first: R does not depend on the scale of M, and the
    quartic's coefficients, of degree 4 in M, then neither overflow nor underflow at any
    accepted scale of the coordinates. The frames the closed form cannot fit take one
    slower, exact path, the SVD above on each frame's markers divided by their largest
    centred coordinate (vectorized over blocks of frames), whose singular values decide
    which frames are undetermined: frames where the closed form is ill-conditioned (two
    nearly equal largest eigenvalues: nearly collinear markers, or nearly mirrored data
    with a tie), frames whose bound is below ``SMALL_BOUND = 1e-150`` (coordinates so
    small that their products underflow, or the markers of B coinciding), and every
    frame when there are more than ``MOMENT_MATRIX_MAX_MARKERS = 128`` markers (the
    closed form's moment matrix has :math:`(3n)^2` entries and its work space grows as
    :math:`6n` values per frame: 50 MB for blocks of 8192 frames at 128 markers). In
    ``benchmarks/bench_svdt.py``'s trial (4 markers) the closed form is 12 to 17 times
    faster than the exact path on :math:`10^5` to :math:`10^6` frames.

    *Threads.* While it runs, svdt limits the BLAS library (NumPy's matrix products) to
    one thread, for the whole process, and restores the previous setting when it
    returns: its products are too small to gain from several cores, and under
    contention (another process holding a core) BLAS's threads wait for each other
    (:math:`10^6` frames: 0.11 s idle, 0.3 to 2.9 s so;
    :mod:`bmc_functions._threads`). The limit applies in the main thread only; set the
    environment variable ``BMC_FUNCTIONS_ONE_BLAS_THREAD=0`` (read at every call) to
    switch it off.

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
    .. [5] Horn BKP (1987) Closed-form solution of absolute orientation using unit
       quaternions. J Opt Soc Am A 4:629-642.
    .. [6] Theobald DL (2005) Rapid calculation of RMSDs using a quaternion-based
       characteristic polynomial. Acta Crystallogr A 61:478-480.

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
    F, n = B.shape[:2]
    R = np.empty((F, 3, 3))
    L = np.empty((F, 3))
    RMSE = np.empty(F)
    too_few = np.empty(F, dtype=bool)  # fewer than 3 non-collinear visible markers
    degenerate_B = np.empty(F, dtype=bool)  # visible markers of B coincident or collinear
    if n > MOMENT_MATRIX_MAX_MARKERS:
        # The moment matrix has (3n)^2 entries: for many markers, the per-frame SVD on
        # blocks of about 2^16 markers keeps the memory bounded.
        step = max(1, 2**16 // n)
        for start in range(0, F, step):
            block = slice(start, min(start + step, F))
            too_few[block], degenerate_B[block] = _fit_block_direct(
                A, B[block], R[block], L[block], RMSE[block])
    else:
        W = _moment_matrix(A)
        # Blocks of frames: the temporaries of one block stay in the processor's cache
        # and the memory used beyond the outputs does not grow with the number of
        # frames. The two largest temporaries are allocated once (fresh memory for
        # every block costs page faults).
        workspace = np.empty((W.shape[1] + W.shape[0]) * min(F, CHUNK_FRAMES))
        for start in range(0, F, CHUNK_FRAMES):
            block = slice(start, min(start + CHUNK_FRAMES, F))
            too_few[block], degenerate_B[block] = _fit_block(
                A, W, B[block], R[block], L[block], RMSE[block], workspace)

    undetermined = too_few | degenerate_B
    R[undetermined] = np.nan
    L[undetermined] = np.nan
    RMSE[undetermined] = np.nan
    n_too_few, n_degenerate_B = int(too_few.sum()), int(degenerate_B.sum())
    if not n_degenerate_B:
        why = "have fewer than 3 non-collinear visible markers"
    elif not n_too_few:
        why = ("have visible markers of B that coincide or are collinear (the rotation "
               "about their line is undetermined)")
    else:
        why = (f"cannot be fitted ({n_too_few} with fewer than 3 non-collinear visible "
               f"markers, {n_degenerate_B} with visible markers of B that coincide or are "
               f"collinear)")
    warn_frames(n_too_few + n_degenerate_B, F, why + "; their R, L and RMSE are NaN")
    if single:
        return R[0], L[0], RMSE[0]
    return R, L, RMSE


def _fit_block(A, W, B, R, L, RMSE, workspace):
    """Fit the frames of one block, writing into R, L and RMSE; return the masks of the
    frames with fewer than 3 non-collinear visible markers and of the other undetermined
    frames (visible markers of B coincident or collinear).

    Every frame's moments come from one matrix product (see ``_moment_matrix``); frames
    with missing markers are recomputed with weights. The rotation comes from the closed
    form (:func:`~bmc_functions.rigid_body.quaternion_fit.rotation_rows`); the frames
    where it is ill-conditioned or the moments underflow are fitted again by
    :func:`_fit_scaled`.
    """
    n_frames, n = B.shape[:2]
    size = W.shape[1] * n_frames
    X = workspace[:size].reshape(W.shape[1], n_frames)  # (12 + 3n, frames): a frame per column
    np.matmul(W.T, B.reshape(n_frames, 3 * n).T, out=X)
    moments, B_mean, B_centred = X[:9], X[9:12], X[12:]
    A_origin = A.mean(axis=0)
    G_A = np.full(n_frames, np.sum((A - A_origin) ** 2))
    G_B = np.einsum("ij,ij->j", B_centred, B_centred)
    count = np.full(n_frames, float(n))
    missing = np.flatnonzero(np.isnan(G_B))  # a NaN coordinate in the frame (no inf here)
    too_few = np.zeros(n_frames, dtype=bool)
    if missing.size:
        B_miss = B[missing]
        a_mean, b_mean, M, count[missing], G_A[missing], G_B[missing], too_few[missing] = \
            _moments_with_gaps(A, B_miss)
        B_mean[:, missing] = b_mean.T
        moments[:, missing] = M.reshape(-1, 9).T
        # Placeholders (M = I: a well-conditioned problem) so that the arithmetic stays
        # finite; these frames are set to NaN by the caller.
        moments[:, too_few] = np.eye(3).reshape(9, 1)
        G_A[too_few] = G_B[too_few] = 3.0

    # sqrt(G_A G_B) bounds the largest eigenvalue from above (Cauchy-Schwarz). M is
    # divided by it (R does not depend on the scale of M) so that the quartic's
    # coefficients, of degree 4 in M, neither overflow for coordinates up to
    # MAX_MAGNITUDE nor underflow for tiny ones; the bound of the scaled M is then 1.
    # Frames with a bound below SMALL_BOUND (tiny coordinates, or the markers of B
    # coinciding) get the placeholder too, and are fitted at the end with scaled markers.
    bound = np.sqrt(G_A) * np.sqrt(G_B)
    small = (bound < SMALL_BOUND) & ~too_few
    if small.any():
        moments[:, small] = np.eye(3).reshape(9, 1)
        bound[small] = 3.0
    moments /= bound
    _, ok = rotation_rows(moments, np.ones(n_frames), R.reshape(n_frames, 9).T)

    # L = centroid of B - R @ centroid of A
    L[:] = B_mean.T
    L -= (R.reshape(3 * n_frames, 3) @ A_origin).reshape(n_frames, 3)
    if missing.size:
        L[missing] = b_mean - np.einsum("fij,fj->fi", R[missing], a_mean)

    # Sum of squared residuals, from the centred coordinates (one more matrix product):
    # R (a_k - a_mean) - (b_k - b_mean) for every marker k. (The shortcut
    # G_A + G_B - 2 lam loses digits when the fit is nearly perfect.)
    residual = workspace[size:size + 3 * n * n_frames].reshape(3 * n, n_frames)
    np.matmul(W[:, :9], R.reshape(n_frames, 9).T, out=residual)
    residual -= B_centred
    E = np.einsum("ij,ij->j", residual, residual)
    if missing.size:
        E[missing] = _residual_sum_squares(A, B_miss, R[missing], L[missing])
    with np.errstate(invalid="ignore", divide="ignore"):
        np.sqrt(E / (3.0 * count), out=RMSE)

    # The frames the closed form cannot fit are fitted again by the exact path, an SVD
    # on each frame's markers scaled (rare): where it is ill-conditioned (nearly
    # collinear markers, nearly mirrored data with a tie) and where the products in M
    # and the squares in the RMSE reach the underflow range (both marker sets spanning
    # less than about 1e-75, or B's markers coinciding). Its singular values decide
    # which of them are undetermined.
    refit = (small | ~ok) & ~too_few
    degenerate = np.zeros(n_frames, dtype=bool)
    if refit.any():
        R[refit], L[refit], RMSE[refit], degenerate[refit] = _fit_scaled(A, B[refit])
    return too_few, degenerate


def _moments_with_gaps(A, B):
    """The moments of frames B (F, n, 3) with missing markers (NaN), from the markers
    seen in each frame: centroids of A and B, M, the number of markers seen, the sums of
    squares G_A and G_B of the centred markers, and whether the markers seen are fewer
    than 3 or collinear in A (by the rule applied to A itself: M alone cannot tell, as
    noise in B gives it rank 2)."""
    seen = ~np.isnan(B).any(axis=2)
    weights = seen.astype(float)
    B_filled = np.where(seen[:, :, None], B, 0.0)
    a_mean, b_mean, M = cross_covariance(A, B_filled, weights)
    G_A = np.einsum("fn,fni->f", weights, (A - a_mean[:, None, :]) ** 2)
    G_B = np.einsum("fn,fni->f", weights, (B_filled - b_mean[:, None, :]) ** 2)
    return (a_mean, b_mean, M, weights.sum(axis=1), G_A, G_B,
            _collinear_subsets(A, seen))


def _fit_block_direct(A, B, R, L, RMSE):
    """As :func:`_fit_block`, for many markers: every frame by :func:`_fit_scaled`."""
    seen = ~np.isnan(B).any(axis=2)
    too_few = np.zeros(len(B), dtype=bool)
    partial = np.flatnonzero(~seen.all(axis=1))
    if partial.size:
        too_few[partial] = _collinear_subsets(A, seen[partial])
    fit = np.flatnonzero(~too_few)
    degenerate = np.zeros(len(B), dtype=bool)
    R[fit], L[fit], RMSE[fit], degenerate[fit] = _fit_scaled(A, B[fit])
    return too_few, degenerate & ~too_few


def _fit_scaled(A, B):
    """R, L, RMSE and the degenerate mask of frames B (F, n, 3; NaN = missing), with the
    centred markers of A and of each frame of B divided by their largest absolute
    coordinate before any product: nothing underflows, whatever their scale.

    The slow, exact path (an SVD per frame, vectorized) for the frames the closed form
    cannot fit (ill-conditioned, or moments that would underflow) and for many markers.
    """
    seen = ~np.isnan(B).any(axis=2)
    weights = seen.astype(float)
    count = weights.sum(axis=1)
    B_filled = np.where(seen[:, :, None], B, 0.0)
    A_origin = A.mean(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        a_mean = weights @ (A - A_origin) / count[:, None] + A_origin
        b_mean = np.einsum("fn,fnj->fj", weights, B_filled) / count[:, None]
    a_c = (A[None] - a_mean[:, None, :]) * weights[:, :, None]
    b_c = (B_filled - b_mean[:, None, :]) * weights[:, :, None]

    def scaled(x):
        scale = np.max(np.abs(x), axis=(1, 2))
        scale[~(scale > 0)] = 1.0
        return x / scale[:, None, None], scale

    a_s, _ = scaled(a_c)
    b_s, _ = scaled(b_c)
    R, degenerate = rotation_from_covariance(np.einsum("fni,fnj->fij", b_s, a_s))
    L = b_mean - np.einsum("fij,fj->fi", R, a_mean)
    r, r_scale = scaled(np.einsum("fij,fnj->fni", R, a_c) - b_c)
    with np.errstate(invalid="ignore", divide="ignore"):
        RMSE = r_scale * np.sqrt(np.einsum("fni,fni->f", r, r) / (3.0 * count))
    return R, L, RMSE, degenerate


def _collinear_subsets(A, seen):
    """For each row of `seen` (F, n) bool: are the markers of A it selects fewer than 3,
    coincident or collinear, with the tolerance used for A (``COLLINEAR_RTOL``)?

    Computed once per distinct pattern of visible markers (batched over patterns): the
    eigenvalues of the scatter matrix of the selected markers are the squares of the
    singular values of the centred markers.
    """
    n = seen.shape[1]
    if n <= 62:  # one integer per pattern: np.unique on integers is ~50x faster
        codes, inverse = np.unique(seen @ (np.int64(1) << np.arange(n, dtype=np.int64)),
                                   return_inverse=True)
        patterns = (codes[:, None] >> np.arange(n)) & 1
    else:
        patterns, inverse = np.unique(seen, axis=0, return_inverse=True)
    weights = patterns.astype(float)
    count = weights.sum(axis=1)
    A_centred = A - A.mean(axis=0)
    A_centred /= np.abs(A_centred).max()  # scaled: tiny markers must not underflow below
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = weights @ A_centred / count[:, None]
    D = (A_centred[None] - np.nan_to_num(mean)[:, None, :]) * weights[:, :, None]
    lam = np.linalg.eigvalsh(np.einsum("pni,pnj->pij", D, D))  # ascending
    collinear = (count < 3) | ~(lam[:, 1] > COLLINEAR_RTOL**2 * lam[:, 2])
    return collinear[inverse.reshape(-1)]


def _residual_sum_squares(A, B, R, L):
    """Sum over the visible markers of |R a + L - b|^2, per frame."""
    residual = np.einsum("fij,nj->fni", R, A) + L[:, None, :] - B
    residual = np.where(np.isnan(B).any(axis=2)[:, :, None], 0.0, residual)
    return np.einsum("fni,fni->f", residual, residual)
