r"""Functional joint centres and axes: the point or line that two tracked segments share.

A functional trial moves a joint through its range; each segment's marker cluster is
tracked with :func:`~bmc_functions.rigid_body.svdt.svdt`, and the joint centre (a ball joint such
as the hip) or the joint axis (a hinge-like joint such as the knee) is the point or line that
stays fixed in both segments. Three estimators:

- :func:`functional_joint_centre`: the symmetrical centre of rotation estimation (SCoRE,
  Ehrig et al. 2006), one linear least-squares problem over all frames;
- :func:`functional_axis`: the symmetrical axis of rotation approach (SARA, Ehrig et al.
  2007), the null space of the same problem;
- :func:`sphere_fit_centre`: the classic one-sided method, the centre of the spheres on
  which segment 2's markers move in segment 1's frame, for comparison.

The segments' frames are their marker clusters in a reference frame of the trial (the first
frame in which all of a cluster's markers are visible), so the centre or axis found in one
trial can be carried into any other trial of the same clusters: see
:meth:`JointCentre.locate` and :meth:`JointAxis.locate`.
"""

import warnings

import numpy as np
from scipy.spatial.transform import Rotation

from .._checks import check_vectors, residual_outliers, warn, warn_frames
from ..rigid_body.svdt import rotation_from_covariance, svdt

#: Smallest range of motion (deg, peak to peak) that determines a centre or an axis: the
#: joint must turn through at least this much about its main axis (an axis), and about a
#: second, independent axis as well (a centre). Below it the least-squares problem is so
#: ill-conditioned that 0.5 mm of noise moves the estimate by centimetres.
MIN_RANGE_DEG = 5.0

#: Range of motion (deg) below which a result is computed but a warning says it may be off by
#: many millimetres: with 15 deg, 0.5 mm noise and a soft-tissue artefact, centre errors of
#: about 1 cm are usual (Ehrig et al. 2006; notebook 11, section 6).
RECOMMENDED_RANGE_DEG = 15.0

#: Range of motion (deg) about the main axis below which functional_axis computes the axis
#: but warns: with less flexion, secondary rotations of a few degrees and a soft-tissue
#: artefact tilt the axis by 5-20 deg (notebook 11, section 8: 9 deg at 15 deg of flexion
#: with 2 and 4 deg secondary rotations, 1.6 deg from 30 deg on).
RECOMMENDED_AXIS_RANGE_DEG = 30.0

#: functional_axis warns when the second range of motion is at least this fraction of the
#: first: the movement is then not dominated by one axis and the axis is poorly defined.
HINGE_RATIO = 0.5

#: functional_axis refuses a reference_direction whose mean cosine with the axis is at most
#: this (within 0.6 deg of perpendicular): it cannot choose the sign.
PERPENDICULAR_COS = 0.01


class JointCentre(np.ndarray):
    r"""The joint centre in the lab in every frame, shape (frames, 3), with the fit's details.

    It is a NumPy array and behaves as one: indexing, arithmetic, reductions and NumPy
    functions (``np.mean``, ``np.sort``, ``np.concatenate``, ...) give plain ``ndarray``
    results, since the details describe the fit, not a derived array; an in-place
    operation (``centre += 1``) changes the values and leaves the details as they were.
    ``copy()``, ``copy.deepcopy`` and pickling keep the details (so do views made by array
    methods such as ``.T`` or ``.reshape``; use ``np.asarray(centre)`` for a plain array).
    ``pandas.DataFrame(centre, columns=list('xyz'))`` makes a plain table. The details are
    attributes:

    Attributes
    ----------
    local_1, local_2 : ndarray, shape (3,)
        The centre in each segment's frame: in the coordinates of `reference_1` and
        `reference_2` (the lab coordinates of the clusters in their reference frame).
    reference_1, reference_2 : ndarray, shape (n1, 3) and (n2, 3)
        Each cluster's markers in its reference frame (the first frame in which all of the
        cluster's markers are visible), which defines the segment's frame.
    distance : ndarray, shape (frames,)
        Distance between the two segments' estimates of the centre in each frame
        (:math:`\|R_1 c_1 + t_1 - R_2 c_2 - t_2\|`); NaN where a cluster is missing.
    rms_distance : float
        Root-mean-square of `distance` over the frames used: how well the two segments
        agree on one point (noise, soft-tissue artefact, a joint that is not a ball joint).
    frames_used : int
        Number of frames in the fit (both clusters with at least 3 visible markers).
    range_of_motion : ndarray, shape (3,)
        Peak-to-peak range (deg) of the relative rotation of segment 2 in segment 1 about
        its three principal axes, largest first (see Notes of
        :func:`functional_joint_centre`).
    method : str
        'SCoRE' or 'sphere fit'.

    Examples
    --------
    What :func:`functional_joint_centre` returns for a pelvis cluster fixed in the lab and
    a thigh cluster turning about the hip at (10, -80, 90) mm; then the same hip centre in
    another trial, found from the pelvis cluster alone (there 5 mm further along x):

    >>> import numpy as np
    >>> from bmc_functions import functional_joint_centre, rot_x, rot_z
    >>> hip = np.array([10.0, -80.0, 90.0])
    >>> pelvis = np.array([[0, 0, 0], [100, 0, 0], [0, 100, 0], [0, 0, 100]], float)
    >>> thigh = hip + np.array([[0, -100, 40], [30, -250, 50], [-20, -300, 60]], float)
    >>> a = np.arange(31.0)
    >>> R = np.concatenate([rot_x(a, degrees=True), rot_z(a, degrees=True)])
    >>> centre = functional_joint_centre(np.broadcast_to(pelvis, (62, 4, 3)),
    ...                                  np.einsum("fij,nj->fni", R, thigh - hip) + hip)
    >>> isinstance(centre, np.ndarray), centre.shape, centre.method, centre.frames_used
    (True, (62, 3), 'SCoRE', 62)
    >>> print(np.round(centre.local_1, 6) + 0.0)       # in the pelvis cluster's frame
    [ 10. -80.  90.]
    >>> print(np.round(centre.locate(pelvis + [5.0, 0, 0]), 6) + 0.0)
    [ 15. -80.  90.]
    """

    _details = ("local_1", "local_2", "reference_1", "reference_2", "distance",
                "rms_distance", "frames_used", "range_of_motion", "method")

    def __new__(cls, centre, **details):
        obj = np.asarray(centre, dtype=float).view(cls)
        for name in cls._details:
            setattr(obj, name, details.get(name))
        return obj

    def __array_finalize__(self, obj):
        for name in self._details:
            setattr(self, name, getattr(obj, name, None))

    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        inputs = tuple(np.asarray(x) if isinstance(x, JointCentre) else x for x in inputs)
        out = kwargs.get("out")
        if out is not None:
            kwargs["out"] = tuple(np.asarray(x) if isinstance(x, JointCentre) else x
                                  for x in out)
        result = getattr(ufunc, method)(*inputs, **kwargs)
        if out is not None:
            # in place (centre += 1): the caller's own array back, as NumPy does
            return out[0] if len(out) == 1 else out
        return result

    def __array_function__(self, func, types, args, kwargs):
        # NumPy functions (np.sort, np.concatenate, np.nan_to_num, ...) see plain arrays
        return func(*_plain(args), **_plain(kwargs))

    def __getitem__(self, key):
        return np.asarray(self)[key]

    def __reduce__(self):
        # pickle and deepcopy (also across processes) keep the details
        return (_rebuild_centre, (np.asarray(self).copy(),
                                  {name: getattr(self, name) for name in self._details}))

    def locate(self, markers, segment=1):
        """The centre in the lab in every frame of another trial, from one segment's cluster.

        Parameters
        ----------
        markers : array_like, shape (frames, n, 3) or (n, 3)
            The same cluster markers, in the same order, as `markers_1` (``segment=1``) or
            `markers_2` (``segment=2``) of the functional trial; NaN for a missing marker.
        segment : {1, 2}, optional
            Which segment's cluster `markers` holds. Default 1.

        Returns
        -------
        centre : ndarray, shape (frames, 3) or (3,)
            :math:`R c + t`, with (R, t) from :func:`svdt` of the reference cluster to
            `markers`; NaN where fewer than 3 markers are visible.
        """
        R, t, single = _pose_in(self, markers, segment)
        centre = np.einsum("fij,j->fi", R, self.local_1 if segment == 1 else self.local_2) + t
        return centre[0] if single else centre


def _rebuild_centre(array, details):
    return JointCentre(array, **details)


def _plain(value):
    """`value` with every JointCentre in it (also inside lists, tuples and dicts) viewed
    as a plain ndarray."""
    if isinstance(value, JointCentre):
        return value.view(np.ndarray)
    if isinstance(value, (list, tuple)):
        return type(value)(_plain(x) for x in value)
    if isinstance(value, dict):
        return {key: _plain(x) for key, x in value.items()}
    return value


class JointAxis(tuple):
    r"""``(points, directions)`` of a functional axis, with the fit's details as attributes.

    Unpacks as ``points, directions = functional_axis(...)``, each of shape (frames, 3).

    Attributes
    ----------
    points, directions : ndarray, shape (frames, 3)
        A point on the axis and its unit direction in the lab in every frame.
    point_1, direction_1, point_2, direction_2 : ndarray, shape (3,)
        The axis in each segment's frame (coordinates of `reference_1` and `reference_2`);
        the points are the point of the axis nearest to the clusters' centroids.
    reference_1, reference_2 : ndarray, shape (n1, 3) and (n2, 3)
        Each cluster's markers in its reference frame (see :class:`JointCentre`).
    distance : ndarray, shape (frames,)
        Distance between the two segments' estimates of the point in each frame.
    rms_distance : float
        Root-mean-square of `distance` over the frames used.
    frames_used : int
        Number of frames in the fit.
    range_of_motion : ndarray, shape (3,)
        Peak-to-peak range (deg) of the relative rotation about its principal axes.

    Examples
    --------
    What :func:`functional_axis` returns for a thigh cluster fixed in the lab and a shank
    cluster flexing 90 deg about the line through (0, -400, 0) along z; then the axis in
    another trial from the thigh cluster alone (there 10 mm further along z):

    >>> import numpy as np
    >>> from bmc_functions import functional_axis, rot_z
    >>> thigh = np.array([[30, -150, 60], [50, -250, 70], [0, -300, 80]], float)
    >>> knee = np.array([0.0, -400.0, 0.0])
    >>> shank = knee + np.array([[40, -100, 40], [45, -250, 35], [10, -200, 55]], float)
    >>> R = rot_z(-np.linspace(0, 90, 91), degrees=True)
    >>> axis = functional_axis(np.broadcast_to(thigh, (91, 3, 3)),
    ...                        np.einsum("fij,nj->fni", R, shank - knee) + knee)
    >>> points, directions = axis                     # a tuple of two (frames, 3) arrays
    >>> print(np.round(axis.direction_1, 6) + 0.0, axis.frames_used)
    [0. 0. 1.] 91
    >>> point, direction = axis.locate(thigh + [0, 0, 10.0])
    >>> print(np.round(point[:2], 6) + 0.0, np.round(direction, 6) + 0.0)
    [   0. -400.] [0. 0. 1.]
    """

    def __new__(cls, points, directions, **details):
        obj = super().__new__(cls, (points, directions))
        obj.__dict__.update(details)
        return obj

    def __reduce__(self):
        # pickle, copy and deepcopy: rebuilt from (points, directions) and the details
        return (_rebuild_axis, (self[0], self[1], dict(self.__dict__)))

    @property
    def points(self):
        return self[0]

    @property
    def directions(self):
        return self[1]

    def locate(self, markers, segment=1):
        """The axis in the lab in every frame of another trial, from one segment's cluster.

        Parameters
        ----------
        markers : array_like, shape (frames, n, 3) or (n, 3)
            As :meth:`JointCentre.locate`.
        segment : {1, 2}, optional
            Which segment's cluster `markers` holds. Default 1.

        Returns
        -------
        points, directions : ndarray, shape (frames, 3) or (3,)
            :math:`R p + t` and :math:`R n` with the axis :math:`(p, n)` in that segment's
            frame; NaN where fewer than 3 markers are visible.
        """
        R, t, single = _pose_in(self, markers, segment)
        point, direction = ((self.point_1, self.direction_1) if segment == 1
                            else (self.point_2, self.direction_2))
        points = np.einsum("fij,j->fi", R, point) + t
        directions = np.einsum("fij,j->fi", R, direction)
        return (points[0], directions[0]) if single else (points, directions)


def _rebuild_axis(points, directions, details):
    return JointAxis(points, directions, **details)


#: Largest turn (degrees) of a cluster between consecutive frames taken as movement: 90
#: degrees in one frame is 9,000 deg/s at 100 Hz, beyond any limb's (a few hundred deg/s
#: in a functional trial); a cluster mirrored (its left and right labels exchanged) turns
#: by about 180 degrees at once. As the skeleton's MAX_FRAME_TURN_DEG.
MAX_FRAME_TURN_DEG = 90.0

#: The turns are judged only in a sampled movement, where the median turn between
#: consecutive frames is below this (degrees).
CONTINUOUS_TURN_DEG = 10.0


def _as_cluster(markers, name):
    """Validate a cluster trial: float array (frames, n, 3) with n >= 3."""
    array = check_vectors(markers, name)
    if array.ndim != 3:
        raise ValueError(f"{name} must have shape (frames, n, 3): n markers of one segment "
                         f"in every frame; got shape {array.shape}")
    if array.shape[1] < 3:
        raise ValueError(f"{name} has {array.shape[1]} marker(s); a segment's pose needs at "
                         "least 3 non-collinear markers")
    return array


def _track(markers, name):
    """Reference configuration (n, 3), its centroid, and the poses (R, t) of the centred
    reference in every frame (NaN where undetermined), without svdt's own warning."""
    complete = np.flatnonzero(~np.isnan(markers).any(axis=(1, 2)))
    if complete.size == 0:
        never = np.flatnonzero(np.isnan(markers).all(axis=(0, 2)))
        hint = (f" (marker(s) {', '.join(map(str, never))} missing in every frame: leave "
                f"them out of {name})" if never.size else "")
        raise ValueError(f"{name}: no frame has all {markers.shape[1]} markers visible; one "
                         f"such frame is needed as the segment's reference{hint}")
    reference = markers[complete[0]]
    centroid = reference.mean(axis=0)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            R, t, rmse = svdt(reference - centroid, markers, order="row")
    except ValueError as error:
        raise ValueError(f"{name} (reference frame {complete[0]}): {error}") from None
    bad = residual_outliers(rmse, reference, name, "those frames are left out of the fit")
    R[bad], t[bad] = np.nan, np.nan
    flipped = _flipped_frames(R)
    if flipped.any():
        warn_frames(int(flipped.sum()), len(R),
                    f"of {name} turn the cluster by more than {MAX_FRAME_TURN_DEG:g} degrees "
                    "from the frames around them, and back (its markers mirrored or "
                    "swapped there: left and right labels exchanged?): left out of the fit")
        R[flipped], t[flipped], bad = np.nan, np.nan, bad | flipped
    return reference, centroid, R, t, bad


def _flipped_frames(R):
    """Frames (F,) in the minority of two states separated by turns of more than
    MAX_FRAME_TURN_DEG between consecutive tracked frames, in a sampled movement (median
    turn below CONTINUOUS_TURN_DEG). A nearly planar cluster (the pelvis's ASIS and PSIS)
    mirrored fits as the cluster turned by 180 degrees, with no residual to show it."""
    valid = np.flatnonzero(np.isfinite(R).all(axis=(1, 2)))
    flagged = np.zeros(len(R), bool)
    if valid.size < 2:
        return flagged
    relative = R[valid[1:]] @ np.swapaxes(R[valid[:-1]], 1, 2)
    cos_turn = np.clip((np.trace(relative, axis1=1, axis2=2) - 1) / 2, -1, 1)
    turn = np.degrees(np.arccos(cos_turn))
    jumps = turn > MAX_FRAME_TURN_DEG
    if not jumps.any() or np.median(turn) > CONTINUOUS_TURN_DEG:
        return flagged
    state = np.r_[0, np.cumsum(jumps)] % 2
    minority = 1 if np.count_nonzero(state == 1) <= np.count_nonzero(state == 0) else 0
    flagged[valid[state == minority]] = True
    return flagged


def _check_pair(markers_1, markers_2):
    m1 = _as_cluster(markers_1, "markers_1")
    m2 = _as_cluster(markers_2, "markers_2")
    if m1.shape[0] != m2.shape[0]:
        raise ValueError(f"markers_1 and markers_2 must have the same number of frames (the "
                         f"same trial); got {m1.shape[0]} and {m2.shape[0]}")
    return m1, m2


def _prepare(markers_1, markers_2):
    """Track both clusters; return their tracks, the mask of frames usable for the fit, and
    the range of motion (deg, (3,), largest first)."""
    m1, m2 = _check_pair(markers_1, markers_2)
    *track_1, bad_1 = _track(m1, "markers_1")
    *track_2, bad_2 = _track(m2, "markers_2")
    R1, R2 = track_1[2], track_2[2]
    valid = ~(np.isnan(R1).any(axis=(1, 2)) | np.isnan(R2).any(axis=(1, 2)))
    frames = valid.size
    warn_frames(int(np.count_nonzero(~valid & ~bad_1 & ~bad_2)), frames,
                "have fewer than 3 visible (non-collinear) markers in markers_1 or markers_2: "
                "left out of the fit, NaN in the per-frame output")
    if valid.sum() < 2:
        raise ValueError(f"only {int(valid.sum())} of {frames} frames have both clusters "
                         "tracked (3 or more visible markers each); a functional trial needs "
                         "many frames of movement")
    return track_1, track_2, valid, range_of_motion(R1[valid], R2[valid])


def range_of_motion(R1, R2):
    r"""Peak-to-peak range of the relative rotation of segment 2 in segment 1 (deg).

    Parameters
    ----------
    R1, R2 : array_like, shape (frames, 3, 3)
        Orientations of the two segments in the lab (no NaN).

    Returns
    -------
    ranges : ndarray, shape (3,)
        Ranges about the three principal axes of the movement, largest first.

    Notes
    -----
    The relative orientation :math:`Q_k = R_{1,k}^T R_{2,k}` is referred to its mean
    :math:`\bar Q` (the rotation nearest to the average of the :math:`Q_k`), and the
    rotation vectors of :math:`\bar Q^T Q_k` (axis times angle) are projected on their
    principal axes. For a hinge the second and third ranges are zero; for a star arc of
    the hip all three are tens of degrees.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions import rot_z
    >>> from bmc_functions.models.functional_joints import range_of_motion
    >>> R2 = rot_z(np.linspace(0, 60, 61), degrees=True)     # a hinge through 60 deg
    >>> print(range_of_motion(np.broadcast_to(np.eye(3), R2.shape), R2).round(3) + 0.0)
    [60.  0.  0.]
    """
    Q = np.swapaxes(np.asarray(R1, dtype=float), 1, 2) @ np.asarray(R2, dtype=float)
    Q_mean = rotation_from_covariance(Q.mean(axis=0)[None])[0][0]
    rotvec = Rotation.from_matrix(Q_mean.T @ Q).as_rotvec(degrees=True)
    centred = rotvec - rotvec.mean(axis=0)
    _, axes = np.linalg.eigh(centred.T @ centred)
    projected = rotvec @ axes[:, ::-1]
    return projected.max(axis=0) - projected.min(axis=0)


def _check_centre_range(ranges, name):
    first, second = ranges[0], ranges[1]
    if first < MIN_RANGE_DEG:
        raise ValueError(
            f"too little movement to determine the joint centre: the joint turned through "
            f"{first:.2f} deg (peak to peak, about its main axis); at least {MIN_RANGE_DEG:g} "
            f"deg about two different axes is needed, and {RECOMMENDED_RANGE_DEG:g} deg or more "
            f"for an accurate centre")
    if second < MIN_RANGE_DEG:
        raise ValueError(
            f"the movement is a rotation about one axis (a hinge): {first:.1f} deg about its "
            f"main axis but only {second:.2f} deg about any other (at least {MIN_RANGE_DEG:g} "
            f"deg needed), so the centre is undetermined along the axis; move the joint in "
            f"two planes (e.g. a star arc), or use functional_axis for a hinge-like joint")
    if second < RECOMMENDED_RANGE_DEG:
        warn(
            f"{name}: the joint turned through only {second:.1f} deg about its second axis "
            f"({first:.1f} deg about the first); below {RECOMMENDED_RANGE_DEG:g} deg the centre "
            f"can be off by a centimetre or more (more with noisy markers: check "
            f"rms_distance)", RuntimeWarning)


def _pose_points(R, t, local):
    return np.einsum("fij,j->fi", R, local) + t


def _finish_centre(track_1, track_2, valid, ranges, c1, c2, method):
    """Per-frame centres from the centred local centres c1, c2; the JointCentre result."""
    ref_1, o1, R1, t1 = track_1
    ref_2, o2, R2, t2 = track_2
    p1 = _pose_points(R1, t1, c1)
    p2 = _pose_points(R2, t2, c2)
    centre = (p1 + p2) / 2
    distance = np.linalg.norm(p1 - p2, axis=1)
    centre[~valid] = np.nan
    distance[~valid] = np.nan
    return JointCentre(centre, local_1=c1 + o1, local_2=c2 + o2, reference_1=ref_1,
                       reference_2=ref_2, distance=distance,
                       rms_distance=float(np.sqrt(np.mean(distance[valid] ** 2))),
                       frames_used=int(valid.sum()), range_of_motion=ranges, method=method)


def _stacked_svd(track_1, track_2, valid):
    """SVD of the stacked system [R1, -R2] x = t2 - t1 over the valid frames."""
    R1, t1 = track_1[2][valid], track_1[3][valid]
    R2, t2 = track_2[2][valid], track_2[3][valid]
    A = np.concatenate([R1, -R2], axis=2).reshape(-1, 6)
    b = (t2 - t1).reshape(-1)
    # QR of [A | b] first: A = Q R with Q^T b in R's last column, so that the SVD (and
    # every product with U) is of a 6 x 6 matrix; the same U^T b, s and V as the SVD of
    # the tall A, several times faster, without squaring A's condition number
    R = np.linalg.qr(np.column_stack([A, b]), mode="r")
    U, s, Vt = np.linalg.svd(R[:6, :6])
    return U.T @ R[:6, 6], s, Vt


def functional_joint_centre(markers_1, markers_2):
    r"""Joint centre from the movement of two segments (SCoRE, Ehrig et al. 2006).

    Parameters
    ----------
    markers_1, markers_2 : array_like, shape (frames, n1, 3) and (frames, n2, 3)
        The marker clusters of the two segments (e.g. pelvis and thigh) in every frame of a
        functional trial, in the lab; n1, n2 >= 3 markers each. NaN marks a missing marker;
        a frame where a cluster has fewer than 3 visible markers is left out of the fit.

    Returns
    -------
    centre : JointCentre, shape (frames, 3)
        The joint centre in the lab in every frame: the mean of the two segments' estimates
        (NaN in frames left out). A NumPy array that also carries the centre in each
        segment's frame, the RMS distance between the two estimates, the number of frames
        used and the range of motion (see :class:`JointCentre`).

    Raises
    ------
    ValueError
        If a cluster is not of shape (frames, n, 3), has fewer than 3 markers, contains
        infinite values, has no frame with all its markers visible, or its markers are
        collinear; if the clusters have different numbers of frames; if fewer than 2 frames
        have both clusters tracked; if the joint moved too little (less than
        ``MIN_RANGE_DEG = 5`` deg peak to peak); or if it moved about one axis only (a
        hinge: the centre is undetermined along the axis; use :func:`functional_axis`).

    Warns
    -----
    RuntimeWarning
        Once per call, with the number of frames left out; and when the range of motion
        about the second axis is below ``RECOMMENDED_RANGE_DEG = 15`` deg. Frames where a
        cluster does not have the shape of its reference frame (svdt residual far above
        the trial's usual, and above 0.2 of the cluster's size: a marker swapped, slid
        or mislabelled) are left out, with one warning per cluster; so are the frames in
        which a cluster turns by more than ``MAX_FRAME_TURN_DEG = 90`` degrees at once
        and back (the minority: a nearly planar cluster such as the pelvis's, mirrored
        by exchanged left and right labels, fits as turned by 180 degrees), and the
        frames of :meth:`JointCentre.locate` whose markers do not fit the reference (NaN).

    Notes
    -----
    Each cluster is tracked with :func:`svdt` from its own reference frame (any frame
    would do; the first with all its markers visible is used), which gives the pose
    :math:`(R_{1,k}, \mathbf t_{1,k})` and :math:`(R_{2,k}, \mathbf t_{2,k})` of the
    segments in frame :math:`k`. A joint centre is a point fixed in both segments: with
    :math:`\mathbf c_1` in segment 1's frame and :math:`\mathbf c_2` in segment 2's,

    .. math:: R_{1,k}\,\mathbf c_1 + \mathbf t_{1,k} = R_{2,k}\,\mathbf c_2 + \mathbf t_{2,k}
              \quad\text{in every frame } k.

    These are three linear equations per frame in the six unknowns; stacked over the
    frames,

    .. math:: \begin{bmatrix} R_{1,1} & -R_{2,1}\\ \vdots & \vdots\\ R_{1,K} & -R_{2,K}
              \end{bmatrix}
              \begin{bmatrix}\mathbf c_1\\ \mathbf c_2\end{bmatrix} =
              \begin{bmatrix}\mathbf t_{2,1}-\mathbf t_{1,1}\\ \vdots\\
              \mathbf t_{2,K}-\mathbf t_{1,K}\end{bmatrix},

    solved in the least-squares sense (by the SVD of the :math:`3K \times 6` matrix,
    computed from its QR decomposition). Both
    segments may move in the lab: only their relative motion matters, and neither segment
    is treated as fixed, hence "symmetrical". The lab centre in frame :math:`k` is the
    mean of :math:`R_{1,k}\mathbf c_1 + \mathbf t_{1,k}` and
    :math:`R_{2,k}\mathbf c_2 + \mathbf t_{2,k}`.

    The problem is well posed only if the joint turns about two independent axes. Its
    conditioning is judged from the range of motion: the rotation vectors of the relative
    orientation :math:`R_1^T R_2` about its mean, projected on their principal axes
    (:func:`range_of_motion`). If only the first range is large the movement is a hinge and
    the centre can slide along the axis (one singular value of the stacked matrix is
    zero); if all are small, noise dominates.

    References
    ----------
    .. [1] Ehrig RM, Taylor WR, Duda GN, Heller MO (2006) A survey of formal methods for
       determining the centre of rotation of ball joints. J Biomech 39:2798-2809.
    .. [2] Cappozzo A (1984) Gait analysis methodology. Hum Mov Sci 3:27-50.
    .. [3] Leardini A, Cappozzo A, Catani F, et al. (1999) Validation of a functional
       method for the estimation of hip joint centre location. J Biomech 32:99-103.

    Examples
    --------
    A pelvis cluster fixed in the lab and a thigh cluster turning about the point
    (10, -80, 90) mm through 30 deg about x and then 30 deg about z:

    >>> import numpy as np
    >>> from bmc_functions import functional_joint_centre, rot_x, rot_z
    >>> hip = np.array([10.0, -80.0, 90.0])
    >>> pelvis = np.array([[0, 0, 0], [100, 0, 0], [0, 100, 0], [0, 0, 100]], float)
    >>> thigh = hip + np.array([[0, -100, 40], [30, -250, 50], [-20, -300, 60]], float)
    >>> angles = np.linspace(0, 30, 31)
    >>> R = np.concatenate([rot_x(angles, degrees=True), rot_z(angles, degrees=True)])
    >>> thigh_moving = np.einsum("fij,nj->fni", R, thigh - hip) + hip
    >>> pelvis_still = np.broadcast_to(pelvis, (len(R), 4, 3))
    >>> centre = functional_joint_centre(pelvis_still, thigh_moving)
    >>> print(centre.shape, np.round(centre[0], 6) + 0.0)
    (62, 3) [ 10. -80.  90.]
    >>> print(centre.frames_used, round(centre.rms_distance, 9))
    62 0.0
    >>> print(centre.range_of_motion.round(1) + 0.0)   # deg, about two axes only
    [42.2 21.3  0. ]
    """
    track_1, track_2, valid, ranges = _prepare(markers_1, markers_2)
    _check_centre_range(ranges, "functional_joint_centre")
    Ub, s, Vt = _stacked_svd(track_1, track_2, valid)
    x = Vt.T @ (Ub / s)
    return _finish_centre(track_1, track_2, valid, ranges, x[:3], x[3:], "SCoRE")


def sphere_fit_centre(markers_1, markers_2):
    r"""Joint centre by the classic one-sided sphere fit (for comparison with SCoRE).

    Segment 1 is held fixed: segment 2's markers, expressed in segment 1's frame, move on
    spheres about the joint centre, and the centre common to those spheres is fitted.

    Parameters
    ----------
    markers_1, markers_2 : array_like, shape (frames, n1, 3) and (frames, n2, 3)
        As :func:`functional_joint_centre`; segment 1 is the one held fixed (the pelvis for
        the hip).

    Returns
    -------
    centre : JointCentre, shape (frames, 3)
        As :func:`functional_joint_centre`, with ``method='sphere fit'``. The centre in
        segment 2's frame is the mean of the fitted centre seen from segment 2.

    Raises
    ------
    ValueError
        As :func:`functional_joint_centre`.

    Warns
    -----
    RuntimeWarning
        As :func:`functional_joint_centre`.

    Notes
    -----
    Each marker :math:`j` of segment 2, in segment 1's frame,
    :math:`\mathbf p_{jk} = R_{1,k}^T(\mathbf m_{jk} - \mathbf t_{1,k})`, lies on a sphere
    :math:`\|\mathbf p_{jk} - \mathbf c\|^2 = r_j^2`. Expanding, :math:`2\,\mathbf
    p_{jk}\cdot\mathbf c + (r_j^2 - \|\mathbf c\|^2) = \|\mathbf p_{jk}\|^2` is linear in
    :math:`\mathbf c` and one constant per marker; subtracting each marker's mean over the
    frames eliminates the constants:

    .. math:: 2\,(\mathbf p_{jk} - \bar{\mathbf p}_j)\cdot\mathbf c =
              \|\mathbf p_{jk}\|^2 - \overline{\|\mathbf p_j\|^2},

    solved by linear least squares over all markers and frames (the algebraic sphere fit;
    it is biased by noise and by the soft-tissue artefact of the moving markers, which
    is one reason why Ehrig et al. 2006 found SCoRE more accurate).

    References
    ----------
    .. [1] Ehrig RM, Taylor WR, Duda GN, Heller MO (2006) J Biomech 39:2798-2809.
    .. [2] Leardini A et al. (1999) J Biomech 32:99-103.
    .. [3] Gamage SSHU, Lasenby J (2002) New least squares solutions for estimating the
       average centre of rotation and the axis of rotation. J Biomech 35:87-93.

    Examples
    --------
    The trial of :func:`functional_joint_centre`'s example gives the same centre without
    noise:

    >>> import numpy as np
    >>> from bmc_functions import rot_x, rot_z
    >>> from bmc_functions.models.functional_joints import sphere_fit_centre
    >>> hip = np.array([10.0, -80.0, 90.0])
    >>> pelvis = np.array([[0, 0, 0], [100, 0, 0], [0, 100, 0], [0, 0, 100]], float)
    >>> thigh = hip + np.array([[0, -100, 40], [30, -250, 50], [-20, -300, 60]], float)
    >>> angles = np.linspace(0, 30, 31)
    >>> R = np.concatenate([rot_x(angles, degrees=True), rot_z(angles, degrees=True)])
    >>> thigh_moving = np.einsum("fij,nj->fni", R, thigh - hip) + hip
    >>> centre = sphere_fit_centre(np.broadcast_to(pelvis, (62, 4, 3)), thigh_moving)
    >>> print(np.round(centre.local_1, 6) + 0.0)
    [ 10. -80.  90.]
    """
    track_1, track_2, valid, ranges = _prepare(markers_1, markers_2)
    _check_centre_range(ranges, "sphere_fit_centre")
    _, o1, R1, t1 = track_1
    m2 = np.asarray(markers_2, dtype=float)[valid]
    p = np.einsum("fji,fnj->fni", R1[valid], m2 - t1[valid][:, None, :])  # (F, n2, 3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)    # a marker missing in every frame
        p_mean = np.nanmean(p, axis=0)
        sq = np.sum(p**2, axis=2)
        sq_mean = np.nanmean(sq, axis=0)
    A = 2 * (p - p_mean).reshape(-1, 3)
    b = (sq - sq_mean).reshape(-1)
    seen = ~np.isnan(b)
    c1 = np.linalg.lstsq(A[seen], b[seen], rcond=None)[0]
    _, o2, R2, t2 = track_2
    # the same point seen from segment 2, averaged over the frames
    c2 = np.einsum("fji,fj->fi", R2[valid], _pose_points(R1, t1, c1)[valid] - t2[valid]
                   ).mean(axis=0)
    return _finish_centre(track_1, track_2, valid, ranges, c1, c2, "sphere fit")


def functional_axis(markers_1, markers_2, reference_direction=None):
    r"""Joint axis from the movement of two segments (SARA, Ehrig et al. 2007).

    Parameters
    ----------
    markers_1, markers_2 : array_like, shape (frames, n1, 3) and (frames, n2, 3)
        The marker clusters of the two segments (e.g. thigh and shank) in every frame of a
        functional trial (e.g. knee flexion-extension), as in
        :func:`functional_joint_centre`.
    reference_direction : array_like, shape (3,) or (frames, 3), optional
        A direction in the lab that the axis should point along (e.g. the lateral minus
        the medial epicondyle of a right knee, or the lab's axis to the subject's right).
        Default: the rule in Notes.

    Returns
    -------
    result : JointAxis
        Unpacks as ``points, directions``: a point on the axis and the unit direction of
        the axis in the lab in every frame, shape (frames, 3) each, NaN in frames left out.
        Also carries the axis in each segment's frame, the RMS distance between the two
        segments' points, the frames used and the range of motion (see
        :class:`JointAxis`).

    Raises
    ------
    ValueError
        As :func:`functional_joint_centre` for the inputs; if the joint turned through less
        than ``MIN_RANGE_DEG = 5`` deg; if `reference_direction` is not of shape (3,) or
        (frames, 3), or is perpendicular to the axis (mean cosine at most
        ``PERPENDICULAR_COS = 0.01``).

    Warns
    -----
    RuntimeWarning
        Once per call with the number of frames left out; when the joint turned through
        less than ``RECOMMENDED_AXIS_RANGE_DEG = 30`` deg about its main axis; when the
        second range of motion is at least ``HINGE_RATIO = 0.5`` times the first (the
        movement is not dominated by one axis, and the axis is poorly defined).

    Notes
    -----
    A hinge has a line of points fixed in both segments, so the stacked system of
    :func:`functional_joint_centre`, :math:`A\mathbf x = \mathbf b` with
    :math:`\mathbf x = (\mathbf c_1, \mathbf c_2)`, has a null space: if
    :math:`\mathbf n_1` and :math:`\mathbf n_2` are the axis direction in the two frames,
    :math:`R_{1,k}\mathbf n_1 = R_{2,k}\mathbf n_2` in every frame and
    :math:`A\,(\mathbf n_1, \mathbf n_2) = \mathbf 0`. With measured data the null space is
    the right singular vector :math:`\mathbf v_6` of the smallest singular value of
    :math:`A`; the point is the least-squares solution with that singular value left out,

    .. math:: \mathbf x = \sum_{i=1}^{5} \frac{\mathbf u_i\cdot\mathbf b}{s_i}\,\mathbf v_i,

    which is the point of the axis nearest to the two clusters' centroids (the frames'
    origins). The lab direction in frame :math:`k` is the normalized mean of
    :math:`R_{1,k}\mathbf n_1` and :math:`R_{2,k}\mathbf n_2`; the lab point is the mean
    of :math:`R_{1,k}\mathbf c_1 + \mathbf t_{1,k}` and
    :math:`R_{2,k}\mathbf c_2 + \mathbf t_{2,k}`.

    *Sign rule.* The direction of a null vector is arbitrary. With `reference_direction`
    it is chosen so that its mean dot product with that direction is positive. Without,
    it is chosen by the right-hand rule so that, seen from the axis, segment 2's cluster
    centroid lies at a positive angle from segment 1's in most frames (positive mean sine
    of the angle). For a knee given as (thigh, shank), which flexes posteriorly, this
    points to the subject's right on either side once the knee flexes by more than about
    10-20 deg (depending on the clusters' placement); for an elbow (upper arm, forearm),
    which flexes anteriorly, to the left. Pass `reference_direction` when it matters.

    References
    ----------
    .. [1] Ehrig RM, Taylor WR, Duda GN, Heller MO (2007) A survey of formal methods for
       determining functional joint axes. J Biomech 40:2150-2157.
    .. [2] Ehrig RM, Taylor WR, Duda GN, Heller MO (2006) J Biomech 39:2798-2809.

    Examples
    --------
    A thigh cluster fixed in the lab, a shank cluster turning through 90 deg about the
    line through (0, -400, 0) along z:

    >>> import numpy as np
    >>> from bmc_functions import functional_axis, rot_z
    >>> thigh = np.array([[30, -150, 60], [50, -250, 70], [0, -300, 80]], float)
    >>> knee = np.array([0.0, -400.0, 0.0])
    >>> shank = knee + np.array([[40, -100, 40], [45, -250, 35], [10, -200, 55]], float)
    >>> R = rot_z(-np.linspace(0, 90, 91), degrees=True)            # flexion
    >>> shank_moving = np.einsum("fij,nj->fni", R, shank - knee) + knee
    >>> points, directions = functional_axis(np.broadcast_to(thigh, (91, 3, 3)), shank_moving)
    >>> print(np.round(directions[0], 6) + 0.0)
    [0. 0. 1.]
    >>> print(np.round(points[0, :2], 6) + 0.0)
    [   0. -400.]
    """
    track_1, track_2, valid, ranges = _prepare(markers_1, markers_2)
    first, second = ranges[0], ranges[1]
    if first < MIN_RANGE_DEG:
        raise ValueError(
            f"too little movement to determine the joint axis: the joint turned through "
            f"{first:.2f} deg (peak to peak); at least {MIN_RANGE_DEG:g} deg is needed, and "
            f"{RECOMMENDED_AXIS_RANGE_DEG:g} deg or more for an accurate axis")
    if first < RECOMMENDED_AXIS_RANGE_DEG:
        warn(
            f"functional_axis: the joint turned through only {first:.1f} deg about its main "
            f"axis; below {RECOMMENDED_AXIS_RANGE_DEG:g} deg, secondary rotations of a few "
            f"degrees and the soft-tissue artefact can tilt the axis by 5-20 deg",
            RuntimeWarning)
    if second >= HINGE_RATIO * first:
        warn(
            f"functional_axis: the movement is not dominated by one axis ({first:.1f} deg "
            f"about the first, {second:.1f} deg about the second); the axis is poorly "
            f"defined (for a ball joint, use functional_joint_centre)", RuntimeWarning)
    Ub, s, Vt = _stacked_svd(track_1, track_2, valid)
    x = Vt[:5].T @ (Ub[:5] / s[:5])
    null = Vt[5]
    n1 = null[:3] / np.linalg.norm(null[:3])
    n2 = null[3:] / np.linalg.norm(null[3:])
    ref_1, o1, R1, t1 = track_1
    ref_2, o2, R2, t2 = track_2
    d = np.einsum("fij,j->fi", R1, n1) + np.einsum("fij,j->fi", R2, n2)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    p1 = _pose_points(R1, t1, x[:3])
    p2 = _pose_points(R2, t2, x[3:])
    points = (p1 + p2) / 2
    if reference_direction is None:
        u = _pose_points(R1, t1, np.zeros(3)) - points       # axis point -> centroid 1
        v = _pose_points(R2, t2, np.zeros(3)) - points
        sense = np.einsum("fi,fi->f", d, np.cross(u, v)) / (
            np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
    else:
        ref = check_vectors(reference_direction, "reference_direction")
        if ref.shape not in ((3,), (valid.size, 3)):
            raise ValueError(f"reference_direction must have shape (3,) or (frames, 3) = "
                             f"({valid.size}, 3); got shape {ref.shape}")
        with np.errstate(invalid="ignore", divide="ignore"):
            unit = ref / np.linalg.norm(ref, axis=-1, keepdims=True)
        sense = np.einsum("fi,fi->f", d, np.broadcast_to(unit, d.shape))
    seen = np.isfinite(sense) & valid
    mean_sense = np.mean(sense[seen]) if seen.any() else np.nan
    if reference_direction is not None and not abs(mean_sense) > PERPENDICULAR_COS:
        raise ValueError(f"reference_direction is perpendicular to the axis (mean cosine "
                         f"{mean_sense:.2g}; zero or missing in every frame if nan): it "
                         f"cannot choose the axis's sign")
    if mean_sense < 0:
        d, n1, n2 = -d, -n1, -n2
    distance = np.linalg.norm(p1 - p2, axis=1)
    for array in (points, d, distance):
        array[~valid] = np.nan
    return JointAxis(points, d, point_1=x[:3] + o1, direction_1=n1, point_2=x[3:] + o2,
                     direction_2=n2, reference_1=ref_1, reference_2=ref_2,
                     distance=distance,
                     rms_distance=float(np.sqrt(np.mean(distance[valid] ** 2))),
                     frames_used=int(valid.sum()), range_of_motion=ranges)


def _pose_in(result, markers, segment):
    """svdt poses (R, t) of a segment's reference cluster in `markers`, and whether
    `markers` was one frame."""
    if segment not in (1, 2):
        raise ValueError(f"segment must be 1 or 2; got {segment!r}")
    reference = result.reference_1 if segment == 1 else result.reference_2
    array = check_vectors(markers, "markers")
    single = array.ndim == 2
    if array.ndim not in (2, 3) or array.shape[-2] != reference.shape[0]:
        raise ValueError(f"markers must have shape (frames, {reference.shape[0]}, 3) or "
                         f"({reference.shape[0]}, 3): the cluster of segment {segment}; got "
                         f"shape {array.shape}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)   # fewer than 3 markers: NaN
        R, t, rmse = svdt(reference, array.reshape(-1, *reference.shape), order="row")
    bad = residual_outliers(rmse, reference, "markers",
                            f"the {'centre' if isinstance(result, JointCentre) else 'axis'} "
                            f"is NaN there")
    R[bad], t[bad] = np.nan, np.nan
    return R, t, single
