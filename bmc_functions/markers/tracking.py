r"""Cluster tracking: landmarks calibrated in a static trial, reconstructed in a dynamic one.

The calibrated anatomical system technique (Cappozzo et al. 1995): a cluster of at least
three skin markers on a segment defines a *technical frame*; in a static (calibration)
trial, anatomical landmarks palpated or marked on the same segment are expressed in that
frame; in every frame of the dynamic trial the cluster's pose is found with the
least-squares fit :func:`svdt`, and the landmarks, which are no longer marked, are put
back where the fit says they are.
"""

import numpy as np

from .._checks import check_vectors, mean_static
from ..rigid_body.frames import frame_from_points
from ..rigid_body.svdt import COLLINEAR_RTOL, svdt


def calibrate_cluster(cluster_static, landmarks_static):
    r"""Cluster markers and landmarks in the cluster's technical frame, from a static trial.

    Parameters
    ----------
    cluster_static : array_like, shape (n, 3) or (frames, n, 3)
        The n >= 3 cluster markers in the static trial (lab coordinates). With several
        frames, each marker is averaged over the frames in which it is visible, which
        also averages out measurement noise.
    landmarks_static : array_like, shape (m, 3) or (frames, m, 3)
        The m anatomical landmarks of the same segment in the same trial.

    Returns
    -------
    cluster_local : ndarray, shape (n, 3)
        Cluster markers in the technical frame.
    landmarks_local : ndarray, shape (m, 3)
        Landmarks in the technical frame.

    Raises
    ------
    ValueError
        If a shape is wrong, there are fewer than 3 cluster markers, a marker or landmark
        is missing (NaN) in every static frame, a value is infinite, or the cluster
        markers are collinear.

    Notes
    -----
    The technical frame has its origin at the cluster's centroid :math:`\bar c` and axes
    from the first three markers (x towards marker 2 from marker 1, y in the plane of the
    three, :func:`frame_from_points`); any frame fixed to the cluster would do, as only
    the landmarks' positions relative to the cluster matter. A point :math:`p` in the lab
    has technical coordinates :math:`p_{local} = R_T^T (p - \bar c)`, and in a dynamic
    frame where :func:`svdt` gives :math:`(R, L)` it is back at :math:`R\,p_{local} + L`.

    References
    ----------
    .. [1] Cappozzo A, Catani F, Della Croce U, Leardini A (1995) Position and
       orientation in space of bones during movement: anatomical frame definition and
       determination. Clin Biomech 10:171-178.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import calibrate_cluster
    >>> cluster = [[10, 0, 0], [20, 0, 0], [10, 10, 0], [20, 10, 5]]
    >>> c_local, l_local = calibrate_cluster(cluster, [[15, 5, -100]])
    >>> print(np.round(c_local.mean(axis=0), 6) + 0.0)   # origin at the centroid
    [0. 0. 0.]
    >>> print(np.round(l_local, 2) + 0.0)
    [[   0.      0.   -101.25]]
    """
    cluster = mean_static(cluster_static, "cluster_static")
    landmarks = mean_static(landmarks_static, "landmarks_static")
    if cluster.shape[0] < 3:
        raise ValueError(f"a cluster needs at least 3 markers; cluster_static has "
                         f"{cluster.shape[0]}")
    centroid = cluster.mean(axis=0)
    singular_values = np.linalg.svd(cluster - centroid, compute_uv=False)
    if singular_values[1] <= COLLINEAR_RTOL * singular_values[0]:
        raise ValueError("the markers of cluster_static are collinear (or coincident): "
                         "the rotation about their line is undetermined")
    # The first three markers may be collinear even if the cluster is not: use the
    # first triple that spans a plane.
    # scaled: the products below cannot underflow
    unit = (cluster - centroid) / singular_values[0]
    for i, j, k in _triples(cluster.shape[0]):
        side_1, side_2 = unit[j] - unit[i], unit[k] - unit[i]
        if np.linalg.norm(np.cross(side_1, side_2)) > (
                COLLINEAR_RTOL * np.linalg.norm(side_1) * np.linalg.norm(side_2)):
            break
    R_T = frame_from_points(cluster[i], cluster[j], cluster[k])
    return (cluster - centroid) @ R_T, (landmarks - centroid) @ R_T


def _triples(n):
    return ((i, j, k) for i in range(n) for j in range(i + 1, n) for k in range(j + 1, n))


def reconstruct_landmarks(cluster_local, landmarks_local, cluster_dynamic):
    r"""Landmark positions in every dynamic frame from the tracked cluster.

    Parameters
    ----------
    cluster_local : array_like, shape (n, 3)
        Cluster markers in the technical frame (from :func:`calibrate_cluster`).
    landmarks_local : array_like, shape (m, 3)
        Landmarks in the technical frame (from :func:`calibrate_cluster`).
    cluster_dynamic : array_like, shape (frames, n, 3)
        The same cluster markers, in the same order, in every frame of the dynamic
        trial. NaN marks an occluded marker.

    Returns
    -------
    landmarks : ndarray, shape (frames, m, 3)
        Reconstructed landmarks in lab coordinates; NaN in frames where fewer than 3
        non-collinear markers of the cluster are visible.
    rmse : ndarray, shape (frames,)
        Root-mean-square residual of the cluster fit (see :func:`svdt`): the part of
        the soft-tissue artefact and noise that deforms the cluster. NaN where
        undetermined.

    Raises
    ------
    ValueError
        If a shape is wrong, `cluster_dynamic` has a different number of markers than
        `cluster_local`, `cluster_local` or `landmarks_local` contains NaN, a value is
        infinite, or the cluster is collinear.

    Warns
    -----
    RuntimeWarning
        Once per call (from :func:`svdt`) with the number of frames that could not be
        fitted.

    Notes
    -----
    :func:`svdt` with ``A = cluster_local`` and ``B`` each dynamic frame gives the
    technical frame's pose :math:`(R_f, L_f)`; each landmark is
    :math:`p_f = R_f\, p_{local} + L_f`. A marker that is missing in a frame is left out
    of that frame's fit only, so a 4-marker cluster survives one occlusion; a 3-marker
    cluster does not. What does not fit a rigid body (the deformation part of the
    soft-tissue artefact) shows up in `rmse`; the rigid part, a common displacement of
    the whole cluster relative to the bone, does not, and goes straight into the
    landmarks (Cappozzo et al. 1997; Leardini et al. 2005).

    References
    ----------
    .. [1] Cappozzo A, Cappello A, Della Croce U, Pensalfini F (1997) Surface-marker
       cluster design criteria for 3-D bone movement reconstruction. IEEE Trans Biomed
       Eng 44:1165-1174.
    .. [2] Leardini A, Chiari L, Della Croce U, Cappozzo A (2005) Human movement
       analysis using stereophotogrammetry. Part 3. Soft tissue artifact assessment and
       compensation. Gait Posture 21:212-225.

    Examples
    --------
    The cluster of :func:`calibrate_cluster` shifted by 100 along x, then turned by 90
    degrees about z:

    >>> import numpy as np
    >>> from bmc_functions import calibrate_cluster, reconstruct_landmarks, rot_z
    >>> cluster = np.array([[10, 0, 0], [20, 0, 0], [10, 10, 0], [20, 10, 5]], float)
    >>> c_local, l_local = calibrate_cluster(cluster, [[15, 5, -100]])
    >>> moved = np.stack([cluster + [100, 0, 0], cluster @ rot_z(90, degrees=True).T])
    >>> landmarks, rmse = reconstruct_landmarks(c_local, l_local, moved)
    >>> print(np.round(landmarks, 4) + 0.0)
    [[[ 115.    5. -100.]]
    <BLANKLINE>
     [[  -5.   15. -100.]]]
    >>> print(np.round(rmse, 6) + 0.0)
    [0. 0.]
    """
    c_local = check_vectors(cluster_local, "cluster_local", allow_nan=False)
    l_local = check_vectors(landmarks_local, "landmarks_local", allow_nan=False)
    dynamic = check_vectors(cluster_dynamic, "cluster_dynamic")
    if c_local.ndim != 2:
        raise ValueError(f"cluster_local must have shape (n, 3); got shape {c_local.shape}")
    if l_local.ndim != 2:
        raise ValueError(f"landmarks_local must have shape (m, 3); got shape "
                         f"{l_local.shape}")
    if dynamic.ndim != 3:
        raise ValueError(f"cluster_dynamic must have shape (frames, n, 3); got shape "
                         f"{dynamic.shape}")
    if dynamic.shape[1] != c_local.shape[0]:
        raise ValueError(f"cluster_dynamic has {dynamic.shape[1]} markers per frame but "
                         f"cluster_local has {c_local.shape[0]}; they must be the same "
                         "markers in the same order")
    R, L, rmse = svdt(c_local, dynamic, order="row")
    # R_f p_local for every frame and landmark as one matrix product, (m, 3) @ (3, 3
    # frames), rather than a batched einsum (several times slower on long trials): each
    # landmark's (frames, 3) positions come out contiguous, which the segment frames
    # built from them read several times, and L is added to them in place.
    landmarks = (l_local @ R.reshape(-1, 3).T).reshape(len(l_local), len(R), 3)
    landmarks += L                                    # 0 frames allowed
    return landmarks.transpose(1, 0, 2), rmse
