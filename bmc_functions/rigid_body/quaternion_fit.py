r"""The optimal rotation from a cross-covariance matrix in closed form (the fast path of svdt).

Horn's (1987) quaternion method turns the best rotation for a cross-covariance matrix M
into the largest eigenvalue :math:`\lambda` of a symmetric 4x4 matrix built from M.
Theobald's (2005) QCP method finds :math:`\lambda` as the largest root of that
matrix's characteristic quartic by Newton's iteration. Here the rotation matrix is then
obtained without the eigenvector, from M, its cofactor matrix and :math:`\lambda`
(the polar-decomposition identity in :func:`quaternion_rotation`), so that it is
element-wise arithmetic over frames: no per-frame SVD or eigen-solver.

Frames where this closed form is ill-conditioned (the two largest eigenvalues nearly
equal: collinear or nearly collinear markers, or nearly mirrored data) are flagged so
that the caller can use the SVD instead (:func:`bmc_functions.rigid_body.svdt.svdt` does).
"""

import numpy as np

#: A frame is well-conditioned for the closed form when
#: :math:`D = (s_1+s_2)(s_1+s_3')(s_2+s_3')` is at least this fraction of
#: :math:`E_0^3` (E0: the starting upper bound of the largest eigenvalue); below it the
#: rounding error of the closed form could exceed about 1e-11 and the SVD is used.
CONDITION_RTOL = 1e-3

#: Newton's iteration stops when every step is at most this fraction of E0.
NEWTON_RTOL = 1e-10

#: Frames not converged after this many Newton steps are flagged (and go to the SVD).
NEWTON_MAX_ITER = 50


def horn_matrix(M):
    r"""Horn's symmetric 4x4 matrix N of cross-covariance matrices M.

    Parameters
    ----------
    M : array_like, shape (..., 3, 3)
        :math:`M = \sum_i (b_i - \bar b)(a_i - \bar a)^T`, as in :func:`svdt`.

    Returns
    -------
    N : ndarray, shape (..., 4, 4)
        Symmetric, traceless, with :math:`q^T N q = \operatorname{tr}(R(q)^T M)` for a
        unit quaternion :math:`q = (w, x, y, z)` and its rotation matrix :math:`R(q)`.

    Notes
    -----
    With :math:`S = M^T` (so :math:`S_{xy} = \sum_i (a_{ix} - \bar a_x)(b_{iy} - \bar b_y)`,
    Horn's notation):

    .. math::

        N = \begin{bmatrix}
        S_{xx}+S_{yy}+S_{zz} & S_{yz}-S_{zy} & S_{zx}-S_{xz} & S_{xy}-S_{yx} \\
        S_{yz}-S_{zy} & S_{xx}-S_{yy}-S_{zz} & S_{xy}+S_{yx} & S_{zx}+S_{xz} \\
        S_{zx}-S_{xz} & S_{xy}+S_{yx} & -S_{xx}+S_{yy}-S_{zz} & S_{yz}+S_{zy} \\
        S_{xy}-S_{yx} & S_{zx}+S_{xz} & S_{yz}+S_{zy} & -S_{xx}-S_{yy}+S_{zz}
        \end{bmatrix}

    References
    ----------
    .. [1] Horn BKP (1987) Closed-form solution of absolute orientation using unit
       quaternions. J Opt Soc Am A 4:629-642.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.rigid_body.quaternion_fit import horn_matrix
    >>> horn_matrix(np.eye(3)) + 0.0
    array([[ 3.,  0.,  0.,  0.],
           [ 0., -1.,  0.,  0.],
           [ 0.,  0., -1.,  0.],
           [ 0.,  0.,  0., -1.]])
    """
    M = np.asarray(M, dtype=float)
    S = np.swapaxes(M, -1, -2)
    (xx, xy, xz), (yx, yy, yz), (zx, zy, zz) = (
        (S[..., i, 0], S[..., i, 1], S[..., i, 2]) for i in range(3))
    rows = [[xx + yy + zz, yz - zy, zx - xz, xy - yx],
            [yz - zy, xx - yy - zz, xy + yx, zx + xz],
            [zx - xz, xy + yx, -xx + yy - zz, yz + zy],
            [xy - yx, zx + xz, yz + zy, -xx - yy + zz]]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def quaternion_rotation(M):
    r"""Proper rotations R maximizing tr(R^T M), in closed form (Horn's quaternion method).

    Parameters
    ----------
    M : array_like, shape (F, 3, 3)
        Cross-covariance matrices, one per frame, finite.

    Returns
    -------
    R : ndarray, shape (F, 3, 3)
        The optimal proper rotations; where `well_conditioned` is False they are not
        reliable (use the SVD there).
    lam : ndarray, shape (F,)
        The largest eigenvalue of Horn's matrix :func:`horn_matrix`, which equals the
        maximum of :math:`\operatorname{tr}(R^T M)`.
    well_conditioned : ndarray of bool, shape (F,)
        False where the two largest eigenvalues are too close for the closed form
        (see ``CONDITION_RTOL``) or Newton's iteration did not converge.

    Notes
    -----
    The characteristic polynomial of Horn's matrix N is (Theobald 2005)

    .. math:: P(\lambda) = \lambda^4 - 2u\,\lambda^2 - 8w\,\lambda + (u^2 - 4v),

    with :math:`u = \|M\|_F^2`, :math:`w = \det M` and :math:`v = \|\operatorname{cof}
    M\|_F^2` (the sum of the squared 2x2 minors of M). Its largest root :math:`\lambda`
    is found by Newton's iteration from an upper bound (here
    :math:`\sqrt{3}\,\|M\|_F`; :func:`svdt` uses :math:`\sqrt{G_A G_B}`, with
    :math:`G_A = \sum_i \|a_i - \bar a\|^2` and :math:`G_B` likewise, which is close to
    :math:`\lambda` for a nearly rigid cluster), from which Newton's steps decrease
    monotonically.

    The optimal rotation is the rotation factor of :math:`M = R H`, H symmetric with
    eigenvalues :math:`s_1, s_2, s_3' = \pm s_3` (the singular values of M, the last
    with the sign of det M) and :math:`\operatorname{tr} H = \lambda`. The
    Cayley-Hamilton theorem for H, with :math:`H^2 = M^T M` and
    :math:`\operatorname{cof} M = R \operatorname{adj} H`, gives

    .. math:: R = \frac{\lambda \operatorname{cof} M + h M - M M^T M}{D},\quad
              h = \frac{\lambda^2 + u}{2},\quad
              D = \lambda \frac{\lambda^2 - u}{2} - w = (s_1+s_2)(s_1+s_3')(s_2+s_3').

    D vanishes exactly when the optimal rotation is not unique (the two largest
    eigenvalues of N coincide, :math:`\lambda_1 - \lambda_2 = 2(s_2 + s_3')`); a small
    D marks the ill-conditioned frames.

    References
    ----------
    .. [1] Horn BKP (1987) Closed-form solution of absolute orientation using unit
       quaternions. J Opt Soc Am A 4:629-642.
    .. [2] Theobald DL (2005) Rapid calculation of RMSDs using a quaternion-based
       characteristic polynomial. Acta Crystallogr A 61:478-480.
    .. [3] Liu P, Agrafiotis DK, Theobald DL (2010) Fast determination of the optimal
       rotational matrix for macromolecular superpositions. J Comput Chem 31:1561-1563.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import rot_z
    >>> from bmc_functions.rigid_body.quaternion_fit import quaternion_rotation
    >>> M = rot_z(90, degrees=True) @ np.diag([3.0, 2.0, 1.0])
    >>> R, lam, ok = quaternion_rotation(M[None])
    >>> R[0].round(6) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    >>> print(round(float(lam[0]), 6), bool(ok[0]))
    6.0 True
    """
    M = np.asarray(M, dtype=float)
    if M.ndim != 3 or M.shape[1:] != (3, 3):
        raise ValueError(f"M must have shape (F, 3, 3); got shape {M.shape}")
    m = np.ascontiguousarray(M.reshape(-1, 9).T)
    R = np.empty((M.shape[0], 3, 3))
    lam, ok = rotation_rows(m, None, R.reshape(-1, 9).T)
    return R, lam, ok


def rotation_rows(m, bound, out):
    """Kernel of :func:`quaternion_rotation` on the row layout used by svdt.

    Parameters
    ----------
    m : ndarray, shape (9, F)
        The entries of M, row-major (M00, M01, ..., M22), one frame per column.
    bound : ndarray, shape (F,), or None
        An upper bound of the largest eigenvalue, where Newton's iteration starts, and
        the scale of the conditioning test. None: :math:`\\sqrt{3}\\,\\|M\\|_F`.
    out : ndarray, shape (9, F)
        Receives the rotation matrices, row-major (may be a strided view).

    Returns
    -------
    lam, well_conditioned : ndarray, shape (F,)
    """
    m00, m01, m02, m10, m11, m12, m20, m21, m22 = m
    # Cofactor matrix of M (det(M) M^-T), row-major.
    cof = np.empty_like(m)
    for row, (a, b, c, d) in enumerate((
            (m11, m22, m12, m21), (m12, m20, m10, m22), (m10, m21, m11, m20),
            (m02, m21, m01, m22), (m00, m22, m02, m20), (m01, m20, m00, m21),
            (m01, m12, m02, m11), (m02, m10, m00, m12), (m00, m11, m01, m10))):
        np.multiply(a, b, out=cof[row])
        cof[row] -= c * d
    det = m00 * cof[0] + m01 * cof[1] + m02 * cof[2]
    u = np.einsum("ij,ij->j", m, m)
    v = np.einsum("ij,ij->j", cof, cof)
    # Characteristic quartic of Horn's matrix: lam^4 + c2 lam^2 + c1 lam + c0.
    c2 = -2.0 * u
    c1 = -8.0 * det
    c0 = u * u - 4.0 * v
    if bound is None:
        bound = np.sqrt(3.0 * u)
    lam = bound.copy()
    two_c2 = 2.0 * c2
    threshold = NEWTON_RTOL * bound
    # The iteration's arrays made once and written in place (the same operations).
    lam2, p, dp, step = (np.empty_like(lam) for _ in range(4))
    pending = np.empty(lam.shape, dtype=bool)
    for iteration in range(NEWTON_MAX_ITER):
        np.multiply(lam, lam, out=lam2)
        np.add(lam2, c2, out=p)                 # p = ((lam2 + c2) lam + c1) lam + c0
        p *= lam
        p += c1
        p *= lam
        p += c0
        np.multiply(4.0, lam2, out=dp)          # dp = (4 lam2 + 2 c2) lam + c1
        dp += two_c2
        dp *= lam
        dp += c1
        with np.errstate(invalid="ignore", divide="ignore"):
            np.divide(p, dp, out=step)
        lam -= step
        # |step| (in p's place) > threshold: False for NaN, a frame that cannot converge
        np.greater(np.abs(step, out=p), threshold, out=pending)
        if not pending.any():
            break
        if iteration >= 4:
            # Slow (linear) convergence means a nearly double root: a frame that the
            # conditioning test below will send to the SVD anyway. D grows with lam
            # above the root, so D at the current lam already tells.
            lp = lam[pending]
            D_pending = 0.5 * lp * (lp * lp - u[pending]) - det[pending]
            if np.all(D_pending <= CONDITION_RTOL * bound[pending] ** 3):
                break
    converged = np.abs(step) <= threshold  # False for NaN
    lam2 = lam * lam
    h = 0.5 * (lam2 + u)
    D = 0.5 * lam * (lam2 - u) - det
    ok = converged & (D > CONDITION_RTOL * bound**3)
    # S = (M^T M - h I) / D (symmetric), then R = (lam / D) cof(M) - M S.
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = 1.0 / D
    s00 = m00 * m00 + m10 * m10 + m20 * m20 - h
    s11 = m01 * m01 + m11 * m11 + m21 * m21 - h
    s22 = m02 * m02 + m12 * m12 + m22 * m22 - h
    s01 = m00 * m01 + m10 * m11 + m20 * m21
    s02 = m00 * m02 + m10 * m12 + m20 * m22
    s12 = m01 * m02 + m11 * m12 + m21 * m22
    for s_ij in (s00, s11, s22, s01, s02, s12):
        s_ij *= scale
    lam_scale = lam * scale
    S = ((s00, s01, s02), (s01, s11, s12), (s02, s12, s22))
    # R is made in cof's contiguous rows (cof is not read again) and copied to `out` in
    # one pass: svdt's `out` is a strided view, where 18 element-wise passes cost more.
    for i, (a0, a1, a2) in enumerate(((m00, m01, m02), (m10, m11, m12), (m20, m21, m22))):
        for j in range(3):
            ms = a0 * S[0][j]
            ms += a1 * S[1][j]
            ms += a2 * S[2][j]
            cof[3 * i + j] *= lam_scale
            cof[3 * i + j] -= ms
    out[...] = cof
    return lam, ok
