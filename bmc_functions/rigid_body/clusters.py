r"""Marker-cluster design: how precisely a cluster's geometry determines its orientation.

With isotropic marker noise, the orientation error of the least-squares fit (:func:`svdt`)
depends on the cluster only through the spread of its markers about their centroid
(Söderkvist & Wedin 1993; Cappozzo et al. 1997). The functions here predict that error
from the geometry alone, so that a cluster can be judged before any data are recorded.
"""

import numpy as np

from .._checks import as_float_array, check_finite_or_nan, check_flag
from .svdt import COLLINEAR_RTOL


def _cluster_stiffness(markers):
    """Validate `markers` (..., n, 3); return K = tr(C) I - C, with C the scatter matrix
    of the markers divided by a scale s (shape (...)), and s.

    Scaled so that C stays well inside the float range for any accepted coordinates
    (squares of 1e200 overflow, of 1e-200 underflow); K of the markers is s**2 times K.
    """
    markers = as_float_array(markers, "markers")
    if markers.ndim < 2 or markers.shape[-1] != 3:
        raise ValueError(f"markers must have shape (..., n, 3), one marker per row; got "
                         f"shape {markers.shape}")
    n = markers.shape[-2]
    if n < 3:
        raise ValueError(f"at least 3 markers are needed to determine an orientation; "
                         f"markers has {n} marker(s) per cluster (shape {markers.shape})")
    check_finite_or_nan(markers, "markers", allow_nan=False)
    centred = markers - markers.mean(axis=-2, keepdims=True)
    scale = np.max(np.abs(centred), axis=(-2, -1), keepdims=True)
    scale[scale == 0] = 1.0  # all markers coincide: caught as collinear below
    centred = centred / scale
    # scatter matrix C = sum_i a_i a_i^T; its eigenvalues are the squared singular values
    scatter = np.swapaxes(centred, -1, -2) @ centred
    eig = np.linalg.eigvalsh(scatter)  # ascending: eig[..., 2] is the largest
    collinear = eig[..., 1] <= COLLINEAR_RTOL**2 * eig[..., 2]
    if collinear.any():
        raise ValueError(f"markers: {int(collinear.sum())} of {collinear.size} cluster(s) are "
                         f"coincident or collinear, so the rotation about their line is "
                         f"undetermined (infinite error); at least 3 non-collinear markers "
                         f"are needed")
    trace = np.trace(scatter, axis1=-2, axis2=-1)
    return trace[..., None, None] * np.eye(3) - scatter, scale[..., 0, 0]


def _relative_noise(noise_sd, shape, scale):
    """Validate `noise_sd`; return it divided by the clusters' `scale`."""
    noise_sd = as_float_array(noise_sd, "noise_sd")
    if not np.isfinite(noise_sd).all() or (noise_sd < 0).any():
        raise ValueError(f"noise_sd must be finite and >= 0 (a standard deviation); got "
                         f"{np.array2string(noise_sd.ravel()[:5], precision=3)}")
    try:
        np.broadcast_shapes(noise_sd.shape, shape)
    except ValueError:
        raise ValueError(f"noise_sd must be a scalar or broadcast to the clusters' shape "
                         f"{shape}; got shape {noise_sd.shape}") from None
    check_finite_or_nan(noise_sd, "noise_sd")
    return noise_sd / scale


def orientation_error_covariance(markers, noise_sd):
    r"""Predicted covariance of the orientation error of a marker cluster fitted with svdt.

    First-order (small-noise) prediction for independent, isotropic marker noise with
    standard deviation `noise_sd` on every coordinate [1]_, [2]_.

    Parameters
    ----------
    markers : array_like, shape (..., n, 3)
        Marker coordinates of one or more clusters (one marker per row, n >= 3, not
        collinear), e.g. the static trial. Only their positions relative to the centroid
        matter.
    noise_sd : float or array_like broadcastable to shape (...)
        Standard deviation of the marker noise per coordinate, in the units of `markers`.

    Returns
    -------
    cov : ndarray, shape (..., 3, 3)
        Covariance, in rad², of the small rotation vector :math:`\delta\boldsymbol\theta`
        with :math:`R_{est} = R_{true}\exp([\delta\boldsymbol\theta]_\times)`, expressed in
        the cluster's frame (the frame of `markers`).

    Raises
    ------
    ValueError
        If `markers` does not have shape (..., n, 3) with n >= 3, contains NaN or infinite
        values, or a cluster is collinear or coincident (relative tolerance
        ``COLLINEAR_RTOL`` as in :func:`svdt`), or has values beyond
        ``MAX_MAGNITUDE = 1e100``; if `noise_sd` is negative, not finite, beyond
        ``MAX_MAGNITUDE``, or does not broadcast to the clusters' shape.

    See Also
    --------
    expected_orientation_error : the root-mean-square error angle.
    bmc_functions.svdt : the least-squares fit whose error this predicts.

    Notes
    -----
    With centred markers :math:`\mathbf a_i` (:math:`\sum_i \mathbf a_i = 0`), noise
    :math:`\boldsymbol\varepsilon_i` in the cluster frame and a small error
    :math:`\delta\boldsymbol\theta`, the least-squares fit minimizes
    :math:`\sum_i \|\boldsymbol\varepsilon_i - \bar{\boldsymbol\varepsilon}
    - \delta\boldsymbol\theta\times\mathbf a_i\|^2`, whose solution is

    .. math:: \delta\boldsymbol\theta = K^{-1}\sum_i \mathbf a_i\times\boldsymbol\varepsilon_i,
       \qquad K = \sum_i [\mathbf a_i]_\times^T[\mathbf a_i]_\times
       = \operatorname{tr}(C)\,I - C,\quad C = \sum_i \mathbf a_i\mathbf a_i^T .

    With :math:`\operatorname{Cov}(\boldsymbol\varepsilon_i) = \sigma^2 I`, the covariance
    is :math:`\sigma^2 K^{-1}`. K is the inertia tensor of unit masses at the markers; its
    eigenvalues are :math:`\lambda_j + \lambda_k` for the eigenvalues
    :math:`\lambda_1, \lambda_2, \lambda_3` of C (the squared singular values of the
    centred markers), so a nearly collinear cluster (two small :math:`\lambda`) has a
    large error about its line.

    If the reference (static) markers are noisy too, with standard deviation
    :math:`\sigma_A`, use :math:`\sqrt{\sigma^2 + \sigma_A^2}` (the two errors add, to
    first order). The prediction holds while the error angles are small (a few degrees).

    The markers of each cluster are divided by their largest centred coordinate before
    the scatter matrix is formed, and the result scaled back: the squares of very large
    or very small coordinates would overflow or underflow.

    References
    ----------
    .. [1] Söderkvist I, Wedin PA (1993) Determining the movements of the skeleton using
       well-configured markers. J Biomech 26:1473-1477.
    .. [2] Cappozzo A, Cappello A, Della Croce U, Pensalfini F (1997) Surface-marker
       cluster design criteria for 3-D bone movement reconstruction. IEEE Trans Biomed
       Eng 44:1165-1174.

    Examples
    --------
    A square of 4 markers, 50 mm from its centre, 0.5 mm noise: the error about the
    normal (z) has half the variance of the in-plane errors.

    >>> import numpy as np
    >>> from bmc_functions import orientation_error_covariance
    >>> square = np.array([[50, 0, 0], [0, 50, 0], [-50, 0, 0], [0, -50, 0]])
    >>> cov = orientation_error_covariance(square, 0.5)
    >>> print(np.round(np.sqrt(np.diag(cov)) * 1e3, 3))  # standard deviations, mrad
    [7.071 7.071 5.   ]
    """
    K, scale = _cluster_stiffness(markers)
    relative = _relative_noise(noise_sd, K.shape[:-2], scale)
    return (relative**2)[..., None, None] * np.linalg.inv(K)


def expected_orientation_error(markers, noise_sd, *, degrees=False):
    r"""Predicted root-mean-square orientation error of a marker cluster fitted with svdt.

    Parameters
    ----------
    markers : array_like, shape (..., n, 3)
        Marker coordinates of one or more clusters (n >= 3, not collinear).
    noise_sd : float or array_like broadcastable to shape (...)
        Standard deviation of the marker noise per coordinate, in the units of `markers`.
    degrees : bool, keyword-only
        Return degrees instead of radians (a boolean; anything else raises TypeError).

    Returns
    -------
    error : ndarray, shape (...)
        :math:`\sqrt{E[\theta^2]}`, where :math:`\theta` is the angle of
        :math:`R_{est}^T R_{true}` (as computed by
        ``rotation_angle(R_est.T @ R_true)``).

    Raises
    ------
    ValueError
        As :func:`orientation_error_covariance`.

    Notes
    -----
    :math:`E[\theta^2] = \operatorname{tr}(\sigma^2 K^{-1})
    = \sigma^2\sum_{j<k} 1/(\lambda_j + \lambda_k)` (see
    :func:`orientation_error_covariance`). For n markers at a root-mean-square distance
    d from their centroid, :math:`\sum_j\lambda_j = n d^2`; in a quasi-isotropic layout
    this gives :math:`E[\theta^2] = c\,\sigma^2/(n d^2)` with :math:`c = 9/2` for a 3D
    layout (:math:`\lambda_j = n d^2/3`) and :math:`c = 5` for a planar one
    (:math:`\lambda = n d^2/2, n d^2/2, 0`).

    Examples
    --------
    Markers on a regular planar polygon of radius d: :math:`\sqrt{5}\,\sigma/(\sqrt n\, d)`.

    >>> import numpy as np
    >>> from bmc_functions import expected_orientation_error
    >>> t = 2 * np.pi * np.arange(6) / 6
    >>> hexagon = 60 * np.stack([np.cos(t), np.sin(t), 0 * t], axis=1)
    >>> print(round(float(expected_orientation_error(hexagon, 1.0, degrees=True)), 4))
    0.8717
    >>> print(round(float(np.degrees(np.sqrt(5) * 1.0 / (np.sqrt(6) * 60))), 4))
    0.8717
    """
    degrees = check_flag(degrees, "degrees")
    K, scale = _cluster_stiffness(markers)
    relative = _relative_noise(noise_sd, K.shape[:-2], scale)
    # sigma * sqrt(tr(K^-1)), without forming sigma**2 (which could overflow)
    error = relative * np.sqrt(np.trace(np.linalg.inv(K), axis1=-2, axis2=-1))
    return np.degrees(error) if degrees else error
