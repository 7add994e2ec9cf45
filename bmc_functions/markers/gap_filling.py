r"""Filling marker gaps with the rigid-body model of a cluster.

A marker of a cluster that is lost for some frames is where the cluster's other markers
say it is: fit the cluster's rigid-body pose to the markers that are seen
(:func:`~bmc_functions.svdt`) and put the lost marker where that pose carries it.
"""

import warnings

import numpy as np
import pandas as pd

from .._checks import (check_flag, check_vectors, mean_static, residual_outliers, warn,
                       warn_frames)
from ..files.marker_table import COORDS, check_marker_frame
from ..rigid_body.svdt import svdt


#: Largest relative difference between the marker distances of a given reference and
#: those of the trial (median over the marker pairs): skin markers of a cluster move
#: relative to one another by a few mm over a trial (soft-tissue artefact), a few % of
#: the distances; another subject's reference (25 % larger) is beyond it.
SIZE_TOLERANCE = 0.15

#: A marker whose position on the cluster (in the frame of its other markers) differs
#: across a gap by more than this share of the cluster's size (RMS distance of its
#: markers from their centroid) slipped during it: the gap is not filled. The soft
#: tissue moves a marker on its cluster by up to 0.3 of the size across a gap of 50
#: frames (0.29 on the real running pelvis of notebook 12, 35 of 123 mm; 0.27 on the
#: synthetic thigh with its artefact); 0.4 leaves a margin, and still catches a 40 mm
#: slip on a cluster of up to 100 mm.
SLIP_FACTOR = 0.4


def _reference_shape(markers, reference):
    """The cluster's shape (n, 3) from `reference` (None, a frame index or an array)."""
    n = markers.shape[1]
    complete = ~np.isnan(markers).any(axis=(1, 2))
    if reference is None:
        full = np.flatnonzero(complete)
        if not full.size:
            raise ValueError(f"markers: no frame has all {n} markers visible, so the "
                             "cluster's shape is unknown; pass reference= (a static "
                             "trial, shape (n, 3), or the index of a complete frame)")
        # Generalized Procrustes mean: fit every complete frame to the first one, take
        # each back to the cluster frame and average; once more against that mean.
        shape = markers[full[0]]
        if full.size > 1:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # complete frames: none
                for _ in range(2):
                    R, L, _ = svdt(shape, markers[full], order="row")
                    local = np.einsum("fji,fnj->fni", R, markers[full] - L[:, None, :])
                    shape = local.mean(axis=0)
        return shape
    if isinstance(reference, (int, np.integer)) and not isinstance(reference, bool):
        if not -len(markers) <= reference < len(markers):
            raise ValueError(f"reference frame {reference} is out of range for "
                             f"{len(markers)} frames")
        if not complete[reference]:
            missing = np.flatnonzero(np.isnan(markers[reference]).any(axis=1)).tolist()
            raise ValueError(f"reference frame {reference} has missing marker(s) {missing}; "
                             "the reference needs all markers of the cluster")
        return markers[reference]
    shape = mean_static(reference, "reference")   # a static trial: averaged over frames
    if shape.shape != (n, 3):
        raise ValueError(f"reference must have shape ({n}, 3) (or (frames, {n}, 3)), the "
                         f"same {n} markers as markers; got shape {np.shape(reference)}")
    return shape


def fill_gaps_rigid(markers, reference=None, *, return_mask=False):
    r"""Fill the gaps of a marker cluster with its rigid-body model.

    Parameters
    ----------
    markers : array_like, shape (frames, n, 3), or pandas.DataFrame
        The n >= 3 markers of one cluster (markers on one rigid segment), frames on the
        first axis. A marker with any NaN coordinate in a frame is missing there. Or a
        DataFrame with (marker, coord) columns as :func:`~bmc_functions.read_trc` returns
        it, holding only the cluster's markers (e.g. ``df[['RASI', 'LASI', 'RPSI',
        'LPSI']]``).
    reference : None, int, array_like or pandas.DataFrame, optional
        The cluster's shape (its markers in any one pose):

        - None (default): the average shape over the frames in which all n markers are
          visible, after fitting each of them onto the first (a Procrustes mean);
        - an int: that frame of `markers` (all n markers must be visible);
        - an array of shape (n, 3), or (frames, n, 3): e.g. the same markers in a
          static trial, each averaged over the frames in which it is visible;
        - with a DataFrame `markers`, a DataFrame of a static trial (read_trc) that
          contains the same marker labels (other markers are ignored).
    return_mask : bool, keyword-only
        Also return which markers were filled. Default False.

    Returns
    -------
    filled : ndarray, shape (frames, n, 3), or pandas.DataFrame
        A copy of `markers` with every missing marker filled in each frame where at
        least 3 non-collinear markers are visible; frames with fewer stay NaN.
        Visible markers are never changed. A DataFrame (same index, columns and
        ``attrs``) if `markers` is one.
    mask : ndarray of bool, shape (frames, n), or pandas.DataFrame
        Only with ``return_mask=True``: True where a marker was filled (a DataFrame
        with one column per marker if `markers` is a DataFrame).

    Raises
    ------
    TypeError
        If `return_mask` is not True or False.
    ValueError
        If `markers` is not of shape (frames, n, 3) with n >= 3, contains infinite
        values; if no frame is complete and `reference` is None; if `reference` has
        the wrong shape, misses a marker in every frame, is a frame out of range or with
        missing markers, or its markers are collinear; if a DataFrame has columns other
        than (marker, x/y/z) or the reference DataFrame lacks one of the markers.

    Warns
    -----
    RuntimeWarning
        Once per call, with the number of frames that have a missing marker but fewer
        than 3 non-collinear visible markers (left unfilled); and once with the frames
        whose markers do not have the reference's shape (svdt residual above
        :func:`~bmc_functions._checks.residual_outliers`' threshold: a reference of another
        size, marker order or units, or markers swapped there): gaps there are not
        filled.

    Notes
    -----
    In each frame with a missing marker, :func:`~bmc_functions.svdt` fits the rigid
    transformation :math:`(R, \mathbf L)` that takes the visible markers of the
    reference shape :math:`\mathbf a_i` onto their measured positions
    :math:`\mathbf b_i`; a missing marker :math:`j` is put at
    :math:`R\,\mathbf a_j + \mathbf L`. Three non-collinear markers determine the
    pose, so a cluster of 3 cannot fill a lost marker (two are left); a cluster of 4
    or more can fill any one lost marker, of 5 or more any two.

    The error of a filled marker has two parts: the pose error of the fit (marker noise
    and how well the visible markers are spread, see
    :func:`~bmc_functions.expected_orientation_error`), multiplied by the distance of
    the filled marker from the visible ones; and the deformation of the cluster (soft
    tissue artefact), which a rigid model cannot know. Unlike interpolation, it does
    not depend on the length of the gap.

    References
    ----------
    .. [1] Söderkvist I, Wedin PA (1993) Determining the movements of the skeleton using
       well-configured markers. J Biomech 26:1473-1477.
    .. [2] Gower JC (1975) Generalized Procrustes analysis. Psychometrika 40:33-51.

    Examples
    --------
    Four markers translating along x; the fourth is lost in frame 1:

    >>> import numpy as np
    >>> from bmc_functions import fill_gaps_rigid
    >>> cluster = np.array([[0, 0, 0], [100, 0, 0], [0, 80, 0], [50, 40, 60]], float)
    >>> markers = cluster + np.array([0, 10, 20])[:, None, None] * [1, 0, 0]
    >>> markers[1, 3] = np.nan
    >>> filled, mask = fill_gaps_rigid(markers, return_mask=True)
    >>> print(filled[1, 3].round(6) + 0.0, mask[1].tolist())
    [60. 40. 60.] [False, False, False, True]
    """
    return_mask = check_flag(return_mask, "return_mask")
    df = markers if isinstance(markers, pd.DataFrame) else None
    if df is not None:
        names, markers, reference = _from_frame(df, reference)
    markers = check_vectors(markers, "markers")
    if markers.ndim != 3:
        raise ValueError(f"markers must have shape (frames, n, 3), one cluster's n markers "
                         f"in every frame; got shape {markers.shape}")
    n_markers = markers.shape[1]
    if n_markers < 3:
        raise ValueError(f"a cluster needs at least 3 markers for a rigid-body fit; "
                         f"markers has {n_markers} (shape {markers.shape})")
    try:
        shape = _reference_shape(markers, reference)
        # svdt's own checks of the shape (>= 3 markers, not collinear), named here
        svdt(shape, shape, order="row")
    except ValueError as error:
        if str(error).startswith(("markers", "reference")):
            raise
        raise ValueError(f"reference (the cluster's shape): {error}") from None
    missing = np.isnan(markers).any(axis=2)                   # (frames, n)
    filled = markers.copy()
    filled[missing] = np.nan                                  # partly missing: all NaN
    gap_frames = np.flatnonzero(missing.any(axis=1))
    mask = np.zeros_like(missing)
    if gap_frames.size:
        # svdt fits every frame (its own warning is replaced by one about filling): the
        # residuals of all frames tell whether the markers have the reference's shape,
        # and a gap frame whose visible markers do not is not filled.
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            R_all, L_all, rmse = svdt(shape, filled, order="row")
        outlier = residual_outliers(rmse, shape, "markers", "gaps in those frames are "
                                    "not filled")
        if reference is not None and not isinstance(reference, (int, np.integer)) and \
                not outlier.any() and _other_size(markers, shape):
            outlier[:] = True                  # warned: no gap is filled
        R, L = R_all[gap_frames], L_all[gap_frames]
        R[outlier[gap_frames]] = np.nan
        fitted = ~np.isnan(R).any(axis=(1, 2))
        predicted = np.einsum("fij,nj->fni", R, shape) + L[:, None, :]
        fill = missing[gap_frames] & fitted[:, None]
        block = filled[gap_frames]
        block[fill] = predicted[fill]
        filled[gap_frames] = block
        mask[gap_frames] = fill
        _unfill_slipped(filled, mask, markers, missing, shape)
        warn_frames(int(np.count_nonzero(~fitted & ~outlier[gap_frames])), len(markers),
                    "have a missing marker but fewer than 3 non-collinear visible markers "
                    "of the cluster; they were not filled")
    if df is not None:
        filled = pd.DataFrame(filled.reshape(len(df), -1), index=df.index,
                              columns=pd.MultiIndex.from_product([names, COORDS]))
        filled.attrs = dict(df.attrs)
        mask = pd.DataFrame(mask, index=df.index, columns=names)
    if return_mask:
        return filled, mask
    return filled


def _pair_distances(points):
    """Distances between every pair of the n markers of `points` (..., n, 3): (..., pairs)."""
    i, j = np.triu_indices(points.shape[-2], k=1)
    return np.linalg.norm(points[..., i, :] - points[..., j, :], axis=-1)


def _other_size(markers, shape):
    """Whether the reference `shape`'s markers lie further apart (or closer) than the
    trial's by SIZE_TOLERANCE or more, median over the marker pairs, with one warning:
    another subject's or another cluster's reference (a 25 % larger one puts every filled
    marker off by a quarter of the cluster's size, within the fit residual's ceiling)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)   # a pair never seen together
        trial = np.nanmedian(_pair_distances(markers), axis=0)
    ratio = _pair_distances(shape) / trial
    ratio = ratio[np.isfinite(ratio)]
    if not ratio.size or abs(np.log(np.median(ratio))) <= np.log(1 + SIZE_TOLERANCE):
        return False
    warn(f"reference: its markers lie {np.median(ratio):.3g} times as far apart as in "
         f"markers (median over {ratio.size} marker pairs; a cluster's skin deformation "
         f"explains up to {SIZE_TOLERANCE:.0%}): a reference of another subject, cluster or "
         "unit? No gap is filled; give this subject's static trial, or reference=None "
         "(the shape of the trial's complete frames)", RuntimeWarning)
    return True


def _unfill_slipped(filled, mask, markers, missing, shape):
    """Undo (NaN) the filling of a gap across which the marker moved on the cluster: its
    position in the frame of the cluster's other markers (fitted without it) at the last
    frame seen before the gap and the first after differs by more than SLIP_FACTOR times
    the cluster's size (a marker that slipped, was knocked or re-stuck during the gap:
    the rigid fill would put it where it was, then jump). One warning names them."""
    radius = float(np.sqrt(((shape - shape.mean(axis=0)) ** 2).sum(axis=1).mean()))
    slipped = []
    for k in range(markers.shape[1]):          # loop over the cluster's markers (a few)
        edges = np.diff(missing[:, k].astype(np.int8))
        starts, ends = np.flatnonzero(edges == 1) + 1, np.flatnonzero(edges == -1) + 1
        if missing[0, k]:
            ends = ends[1:]                   # a gap at the start: no frame before it
        starts = starts[:ends.size]
        if not starts.size:
            continue
        others = np.arange(markers.shape[1]) != k
        if others.sum() < 3:
            continue
        edge_frames = np.r_[starts - 1, ends]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # fewer than 3 others: NaN
            try:
                R, L, _ = svdt(shape[others], markers[edge_frames][:, others], order="row")
            except ValueError:                 # the others collinear: nothing to judge by
                continue
        local = np.einsum("fji,fj->fi", R, markers[edge_frames, k] - L)
        shift = np.linalg.norm(local[starts.size:] - local[:starts.size], axis=1)
        moved = shift > SLIP_FACTOR * radius     # NaN (undetermined): not flagged
        for first, stop, distance in zip(starts[moved], ends[moved], shift[moved]):
            filled[first:stop, k] = np.nan
            mask[first:stop, k] = False
            slipped.append((k, first, stop, distance))
    if slipped:
        listed = "; ".join(f"marker {k} in frames {first}-{stop - 1} (moved {distance:.3g})"
                           for k, first, stop, distance in slipped[:6])
        warn(f"{len(slipped)} gap(s) left unfilled: the marker lies elsewhere on the "
             f"cluster after the gap than before it (by more than {SLIP_FACTOR:g} times the "
             f"cluster's size, {radius:.3g}): {listed}. It slipped or was re-stuck during "
             "the gap, so where it was is not known", RuntimeWarning)


def _from_frame(df, reference):
    """Marker names, (frames, n, 3) values and the reference of a DataFrame input."""
    names, values = check_marker_frame(df, "markers")
    if isinstance(reference, pd.DataFrame):
        ref_names = set(reference.columns.get_level_values(0))
        absent = [name for name in names if name not in ref_names]
        if absent:
            raise ValueError(f"reference (a DataFrame) lacks the marker(s) {absent} of "
                             "markers")
        _, ref_values = check_marker_frame(reference[names], "reference")
        reference = ref_values.reshape(len(reference), len(names), 3)
    return names, values.reshape(len(df), len(names), 3), reference
