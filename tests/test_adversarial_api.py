"""Bad and edge inputs across the public API outside the file readers (issue 10).

Each case is one call, as a hostile or careless user would write it, with what must happen:
either a clear error (its type, and a message that names the argument and the problem)
or the correct result, checked against an independent oracle (scipy, a per-frame SVD, or
the same call on well-scaled data). Cases marked heavy run in a subprocess with a time
limit, so that a hang or a crash fails the test instead of stopping the suite.

The first group reproduces the classes of issue 10 one by one; the second is the wider
adversarial pass (``CASES``), whose classification before and after the fix is in the
notes of the change.
"""

import subprocess
import sys
import textwrap
import warnings
from dataclasses import dataclass
from decimal import Decimal
from fractions import Fraction
from typing import Callable

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from bmc_functions.rigid_body import svdt as rigid_body
from bmc_functions import (PoseAngles, Skeleton, angles_to_pose, calibrate_cluster, compose,
                           decompose, elemental_rotation, expected_orientation_error,
                           frame_from_axes, frame_from_points, get_R, hip_joint_centre,
                           knee_angles, orientation_error_covariance, pelvis_frame,
                           pose_to_angles, reconstruct_landmarks, rot_x, rot_y, rot_z,
                           rotation_angle, shank_frame, svdt, thigh_frame)
from bmc_functions._checks import MAX_MAGNITUDE, ArgumentTypeError
from bmc_functions.models.skeleton import ROTATING_JOINTS as _ROTATING
from bmc_functions.plotting import draw_frame, plot_frames_row, plot_markers, plot_residuals
from helpers import ROOT

# --- data and oracles --------------------------------------------------------------------

A4 = np.array([[0.0, 0, 0], [100, 0, 0], [0, 60, 0], [20, 30, 80]])  # 4 markers, mm
R_TRUE = Rotation.from_euler("zxy", [30, -20, 50], degrees=True).as_matrix()
L_TRUE = np.array([500.0, -200, 900])
B4 = A4 @ R_TRUE.T + L_TRUE
R_GOOD = rot_z(0.3) @ rot_x(-0.4) @ rot_y(1.1)

# Landmarks of a right leg (mm), ISB axes: x anterior, y up, z right.
RASIS, LASIS = np.array([0.0, 1000, 120]), np.array([0.0, 1000, -120])
RPSIS, LPSIS = np.array([-160.0, 1000, 45]), np.array([-160.0, 1000, -45])
HIP = np.array([-50.0, 920, 85])
LAT_EP, MED_EP = np.array([0.0, 500, 130]), np.array([0.0, 500, 40])
LAT_MAL, MED_MAL = np.array([-10.0, 80, 120]), np.array([5.0, 90, 50])


def svd_fit(A, B):
    """Independent reference: one SVD per call, with the reflection fix."""
    Am, Bm = A.mean(0), B.mean(0)
    U, _, Vt = np.linalg.svd((B - Bm).T @ (A - Am))
    R = U @ np.diag([1, 1, np.linalg.det(U @ Vt)]) @ Vt
    return R, Bm - R @ Am


def close(expected, atol=1e-9):
    def check(out):
        np.testing.assert_allclose(out, expected, atol=atol, rtol=1e-9)
    return check


def svdt_matches(A, B, atol=1e-9):
    """svdt(A, B, 'row') output agrees with the SVD of the markers seen (no NaN)."""
    seen = ~np.isnan(B).any(axis=1)
    R_ref, L_ref = svd_fit(A[seen], B[seen])

    def check(out):
        R, L, _ = out
        np.testing.assert_allclose(R, R_ref, atol=atol)
        np.testing.assert_allclose(L, L_ref, atol=atol * max(1.0, np.abs(L_ref).max()))
    return check


def all_nan(out):
    for item in out if isinstance(out, tuple) else (out,):
        assert np.isnan(item).all()


# --- the classes of issue 10, one test each ----------------------------------------------

def test_masked_entries_are_missing_data_in_svdt():
    # issue 10 reproducer: the hidden value of a masked marker was used (R off by 1.0)
    B = np.ma.masked_array(B4.copy(), mask=False)
    B[2] = np.ma.masked
    B.data[2] = [9e3, -7e3, 5e3]  # what hides under the mask must not matter
    R, L, rmse = svdt(A4, B, order="row")
    B_nan = B4.copy()
    B_nan[2] = np.nan
    R_nan, L_nan, rmse_nan = svdt(A4, B_nan, order="row")
    np.testing.assert_array_equal(R, R_nan)
    np.testing.assert_allclose(R, R_TRUE, atol=1e-12)
    np.testing.assert_allclose(L, L_TRUE, atol=1e-9)
    assert rmse < 1e-9 and rmse == rmse_nan


def test_masked_entries_are_missing_data_in_get_r_and_decompose():
    A = np.ma.masked_array([[1.0, 0, 0], [1, 0, 0]], mask=[[0, 0, 0], [0, 1, 0]])
    R = get_R(A, [0, 1, 0])
    np.testing.assert_allclose(R[0], rot_z(np.pi / 2), atol=1e-15)
    assert np.isnan(R[1]).all()
    Rm = np.ma.masked_array(np.stack([R_GOOD, R_GOOD]))
    Rm[1, 0, 0] = np.ma.masked
    angles = decompose(Rm, "ZXY")
    np.testing.assert_allclose(angles[0], [0.3, -0.4, 1.1], atol=1e-12)
    assert np.isnan(angles[1]).all()


def test_masked_reference_markers_are_refused_like_nan():
    A = np.ma.masked_array(A4, mask=False)
    A[1, 0] = np.ma.masked
    with pytest.raises(ValueError, match=r"A contains NaN"):
        svdt(A, B4, order="row")


@pytest.mark.parametrize("call, name", [
    (lambda v: decompose(R_GOOD, degrees=v), "degrees"),
    (lambda v: decompose(R_GOOD, extrinsic=v), "extrinsic"),
    (lambda v: compose([0.1, 0.2, 0.3], degrees=v), "degrees"),
    (lambda v: compose([0.1, 0.2, 0.3], extrinsic=v), "extrinsic"),
    (lambda v: elemental_rotation("x", 30, degrees=v), "degrees"),
    (lambda v: rot_z(30, degrees=v), "degrees"),
    (lambda v: knee_angles(np.eye(3), R_GOOD, degrees=v), "degrees"),
    (lambda v: expected_orientation_error(A4, 0.5, degrees=v), "degrees"),
])
@pytest.mark.parametrize("value", ["False", "True", 0, 1, None, np.array([True]),
                                   np.array([True, False])])
def test_flags_accept_booleans_only(call, name, value):
    # 'False' used to select degrees (a non-empty string is truthy); an array flag gave
    # numpy's "truth value of an array is ambiguous"
    with pytest.raises(TypeError, match=rf"{name} must be True or False; got"):
        call(value)


def test_numpy_booleans_are_flags():
    np.testing.assert_allclose(decompose(R_GOOD, degrees=np.True_),
                               np.degrees([0.3, -0.4, 1.1]), atol=1e-10)
    np.testing.assert_allclose(compose([0.3, -0.4, 1.1], extrinsic=np.False_), R_GOOD,
                               atol=1e-15)


def test_get_r_of_huge_and_tiny_vectors_is_the_rotation_of_their_directions():
    # issue 10: [1e155, 1e155, 0] overflowed when squared (all NaN); [1e-300, 0, 0]
    # underflowed (said "zero length")
    np.testing.assert_allclose(get_R([1e155, 1e155, 0], [0, 1, 0]),
                               get_R([1, 1, 0], [0, 1, 0]), atol=1e-15)
    np.testing.assert_allclose(get_R([1e-300, 0, 0], [0, 1, 0]), rot_z(np.pi / 2),
                               atol=1e-15)
    np.testing.assert_allclose(get_R([1e308, -1e308, 1e308], [5e-324, 0, 0]),
                               get_R([1, -1, 1], [1, 0, 0]), atol=1e-15)


def test_svdt_refuses_non_physical_magnitudes_with_the_true_reason():
    # issue 10: one marker at 1e300 gave NaN with "fewer than 3 non-collinear visible
    # markers", which was false
    B = B4.copy()
    B[1] = [1e300, 0, 0]
    with pytest.raises(ValueError, match=r"B has values of magnitude up to 1e\+300; "
                                         r"values beyond 1e\+100 are not physical"):
        svdt(A4, B, order="row")
    with pytest.raises(ValueError, match=r"A has values of magnitude up to 1e\+200"):
        svdt(A4 * 1e198, B4, order="row")


def _noisy_frames_with_missing_markers():
    rng = np.random.default_rng(10)
    B = B4 + rng.normal(scale=0.5, size=(5, 4, 3))
    B[1, 2] = np.nan
    B[3, 0, 1] = np.nan
    return B


@pytest.mark.parametrize("scale", [1e-300, 1e-200, 1e-160, 1e-75, 1e-20, 1e20, 1e60, 1e97])
def test_svdt_is_right_at_any_accepted_scale(scale):
    # Every product is formed from scaled markers: the same R at every scale, L and RMSE
    # scaled with the data, no warning (tiny markers used to underflow: NaN with a false
    # "collinear", or an RMSE of 0; huge ones to overflow)
    B = _noisy_frames_with_missing_markers()
    R_ref, L_ref, rmse_ref = svdt(A4, B, order="row")
    for f in range(len(B)):  # the unit-scale fit itself against the SVD oracle
        svdt_matches(A4, B[f])((R_ref[f], L_ref[f], rmse_ref[f]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        R, L, rmse = svdt(A4 * scale, B * scale, order="row")
    np.testing.assert_allclose(R, R_ref, atol=1e-12)
    np.testing.assert_allclose(L / scale, L_ref, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(rmse / scale, rmse_ref, rtol=1e-9)


@pytest.mark.parametrize("scale_a, scale_b", [(1.0, 1e-300), (1e-300, 1.0), (1e-200, 1e-90)])
def test_svdt_is_right_when_the_two_marker_sets_have_very_different_scales(scale_a, scale_b):
    # R maximizes tr(R^T M) whatever positive factor scales M: the oracle's R
    B = _noisy_frames_with_missing_markers() - B4.mean(axis=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        R, _, _ = svdt(A4 * scale_a, B * scale_b, order="row")
    for f in range(len(B)):
        seen = ~np.isnan(B[f]).any(axis=1)
        np.testing.assert_allclose(R[f], svd_fit(A4[seen], B[f][seen])[0], atol=1e-12)


def test_svdt_path_for_many_markers_agrees_with_the_moment_matrix_path(monkeypatch):
    # the moment matrix has (3n)^2 entries (6000 markers: a raw MemoryError for 2.4 GiB);
    # above MOMENT_MATRIX_MAX_MARKERS each frame is fitted by an SVD instead: same
    # results, same undetermined frames, same warning
    rng = np.random.default_rng(11)
    A = rng.normal(size=(7, 3)) * 100
    R_true = Rotation.random(40, random_state=rng).as_matrix()
    B = np.einsum("fij,nj->fni", R_true, A) + rng.normal(scale=0.5, size=(40, 7, 3))
    B[rng.random(B.shape[:2]) < 0.3] = np.nan
    B[5] = 3.0          # coincident markers
    B[6, :5] = np.nan   # two markers left
    with pytest.warns(RuntimeWarning) as fast_warning:
        fast = svdt(A, B, order="row")
    monkeypatch.setattr(rigid_body, "MOMENT_MATRIX_MAX_MARKERS", 3)
    with pytest.warns(RuntimeWarning) as direct_warning:
        direct = svdt(A, B, order="row")
    assert [str(w.message) for w in fast_warning] == [str(w.message) for w in direct_warning]
    for x, y in zip(fast, direct):
        np.testing.assert_array_equal(np.isnan(x), np.isnan(y))
        np.testing.assert_allclose(x, y, atol=1e-10)


def test_svdt_frames_whose_b_markers_coincide_are_named_as_such():
    B = np.stack([B4, np.full_like(B4, 3.0)])
    with pytest.warns(RuntimeWarning, match=r"1 of 2 frames have visible markers of B "
                                            r"that coincide or are collinear"):
        R, L, rmse = svdt(A4, B, order="row")
    assert np.isnan(R[1]).all() and np.isfinite(R[0]).all()


def test_skeleton_lengths_refuse_booleans_and_non_dicts():
    with pytest.raises(TypeError, match=r"lengths\['thigh'\] must be a numeric array; got "
                                        r"booleans"):
        Skeleton.default({"thigh": True})  # used to give a 1 m thigh
    with pytest.raises(TypeError, match=r"lengths must be a dict bone name -> length"):
        Skeleton.default([0.1])  # raw TypeError from dict()
    with pytest.raises(TypeError, match=r"lengths must be a dict.*got ndarray"):
        Skeleton.default(np.array([0.1, 0.2]))  # "truth value of an array is ambiguous"


def test_dates_are_not_coordinates():
    dates = np.array(["2024-01-01"] * 12, dtype="datetime64[D]").reshape(4, 3)
    with pytest.raises(TypeError, match=r"A must be a numeric array; got dates or times"):
        svdt(dates, B4, order="row")
    with pytest.raises(TypeError, match=r"B must be a numeric array; got dates or times"):
        svdt(A4, np.arange(12).reshape(4, 3).astype("timedelta64[s]"), order="row")


def test_python_integers_beyond_float_range_are_named():
    A = A4.astype(int).tolist()
    A[0][0] = 10**400
    with pytest.raises(ValueError, match=r"A has a value too large for a floating-point "
                                         r"number"):
        svdt(A, B4, order="row")


def test_ragged_nested_sequence_names_the_argument():
    with pytest.raises(ValueError, match=r"A must be a rectangular array of numbers.*ragged"):
        svdt([[0, 0, 0], [1, 0], [0, 1, 0]], B4[:3], order="row")


def test_array_as_order_or_side_is_a_clear_type_error():
    with pytest.raises(TypeError, match=r"order must be 'col' or 'row'; got array"):
        svdt(A4, B4, order=np.array(["row", "col"]))
    with pytest.raises(TypeError, match=r"side must be 'right' or 'left'; got array"):
        knee_angles(np.eye(3), np.eye(3), side=np.array(["right", "left"]))


def test_huge_coordinates_give_no_linalg_error():
    # issue 10: "SVD did not converge" / "Eigenvalues did not converge"
    with pytest.raises(ValueError, match=r"markers has values of magnitude up to 1e\+202"):
        expected_orientation_error(A4 * 1e200, 0.5)
    with pytest.raises(ValueError, match=r"B has values of magnitude"):
        svdt(A4, B4 * 1e250, order="row")
    # and at the largest accepted scale the error is the scaled one (sigma/d invariant)
    np.testing.assert_allclose(expected_orientation_error(A4 * 1e95, 0.5e95),
                               expected_orientation_error(A4, 0.5), rtol=1e-12)
    np.testing.assert_allclose(expected_orientation_error(A4 * 1e-150, 0.5e-150),
                               expected_orientation_error(A4, 0.5), rtol=1e-12)


def test_none_is_named_as_none_not_as_nan():
    with pytest.raises(TypeError, match=r"A must be a numeric array; got None"):
        svdt(None, B4, order="row")


def test_huge_directions_are_not_called_parallel():
    np.testing.assert_allclose(frame_from_axes([1e200, 0, 0], [0, 1e200, 0]), np.eye(3),
                               atol=1e-15)
    np.testing.assert_allclose(frame_from_axes([1e-300, 0, 0], [1e-300, 1e-300, 0]),
                               np.eye(3), atol=1e-15)


def test_argument_type_error_is_also_a_value_error():
    # earlier releases raised ValueError for these inputs: code catching it still works
    assert issubclass(ArgumentTypeError, TypeError) and issubclass(ArgumentTypeError,
                                                                   ValueError)
    with pytest.raises(ValueError):
        svdt(None, B4, order="row")


# --- the adversarial pass ----------------------------------------------------------------

@dataclass
class Case:
    id: str
    call: Callable
    error: type = None      # expected exception type, or None for a result
    match: str = None       # regex the message must match (names argument and problem)
    check: Callable = None  # for a result: asserts it against the oracle


def err(id, call, error, match):
    return Case(id, call, error=error, match=match)


def ok(id, call, check):
    return Case(id, call, check=check)


T = ArgumentTypeError  # wrong type: a TypeError that is also a ValueError
V = ValueError
NAN3 = np.full(3, np.nan)
B2 = np.stack([B4, B4])
TILT = get_R([0, 0, 1], [0, 1, 1])


def _nan_marker(B, frame=None, marker=1):
    B = B.copy()
    if frame is None:
        B[marker] = np.nan
    else:
        B[frame, marker] = np.nan
    return B


def _nullable_with_na(B):
    """B as a pandas DataFrame of the nullable Float64 dtype, marker 1 missing (pd.NA)."""
    frame = pd.DataFrame(B).astype("Float64")
    frame.iloc[1, :] = pd.NA
    return frame


def _pose(sk=None):
    return (sk or Skeleton.default()).tpose()


def _skeleton_roundtrip(out):
    pose = _pose()
    for joint, value in out.items():
        np.testing.assert_allclose(value, pose[joint], atol=1e-12)


CASES = [
    # svdt: types
    err("svdt-A-None", lambda: svdt(None, B4, order="row"), T, r"A must be a numeric array; got None"),
    err("svdt-B-None", lambda: svdt(A4, None, order="row"), T, r"B must be a numeric array; got None"),
    err("svdt-A-str", lambda: svdt("0 0 0 1 0 0 0 1 0", B4.ravel()), T, r"A must be a numeric array"),
    err("svdt-A-str-list", lambda: svdt([str(x) for x in A4.ravel()], B4.ravel()), T, r"A must be a numeric array; got dtype <U"),
    err("svdt-A-bool", lambda: svdt(A4 > 10, B4, order="row"), T, r"A must be a numeric array; got booleans"),
    err("svdt-B-bool", lambda: svdt(A4, B4 > 10, order="row"), T, r"B must be a numeric array; got booleans"),
    err("svdt-A-complex", lambda: svdt(A4 + 0j, B4, order="row"), T, r"A must be real; got complex"),
    err("svdt-B-object-None", lambda: svdt(A4, [[0, 0, 0], [1, 0, None], [0, 1, 0], [1, 1, 1]], order="row"), T, r"B must be a numeric array; got a sequence with items"),
    err("svdt-B-dict", lambda: svdt(A4, {"a": 1}, order="row"), T, r"B must be a numeric array; got \{'a': 1\} \(dict\)"),
    err("svdt-A-datetime", lambda: svdt(np.zeros((4, 3), "datetime64[s]"), B4, order="row"), T, r"A must be a numeric array; got dates"),
    err("svdt-A-int-400", lambda: svdt([[10**400, 0, 0], [1, 0, 0], [0, 1, 0]], B4[:3], order="row"), V, r"A has a value too large"),
    err("svdt-A-ragged", lambda: svdt([[0, 0, 0], [1, 0], [0, 1, 0]], B4[:3], order="row"), V, r"A must be a rectangular array"),
    err("svdt-B-ragged", lambda: svdt(A4, [B4, B4[:3]], order="row"), V, r"B must be a rectangular array"),
    err("svdt-order-int", lambda: svdt(A4, B4, order=1), T, r"order must be 'col' or 'row'; got 1"),
    err("svdt-order-array", lambda: svdt(A4, B4, order=np.array("row ")), T, r"order must be 'col' or 'row'"),
    err("svdt-order-upper", lambda: svdt(A4, B4, order="ROW"), V, r"order must be 'col' or 'row'; got 'ROW'"),
    ok("svdt-int-input", lambda: svdt(A4.astype(int), np.round(B4).astype(np.int32), order="row"), svdt_matches(A4, np.round(B4))),
    ok("svdt-float32", lambda: svdt(A4.astype(np.float32), B4.astype(np.float32), order="row"), svdt_matches(A4.astype(np.float32).astype(float), B4.astype(np.float32).astype(float))),
    ok("svdt-list-input", lambda: svdt(A4.tolist(), B4.tolist(), order="row"), svdt_matches(A4, B4)),
    ok("svdt-python-bigint", lambda: svdt([[10**20, 0, 0], [0, 10**20, 0], [0, 0, 10**20]], [[10**20, 0, 0], [0, 10**20, 0], [0, 0, 10**20]], order="row"), lambda out: np.testing.assert_allclose(out[0], np.eye(3), atol=1e-12)),
    ok("svdt-masked-B-frames", lambda: svdt(A4, np.ma.masked_invalid(_nan_marker(B2, 0)), order="row"), lambda out: np.testing.assert_allclose(out[0], [R_TRUE, R_TRUE], atol=1e-12)),
    ok("svdt-masked-nomask", lambda: svdt(A4, np.ma.masked_array(B4), order="row"), svdt_matches(A4, B4)),
    ok("svdt-pandas", lambda: svdt(pd.DataFrame(A4, columns=list("xyz")), pd.DataFrame(B4), order="row"), svdt_matches(A4, B4)),
    ok("svdt-pandas-NA", lambda: svdt(A4, _nullable_with_na(B4), order="row"), svdt_matches(A4, _nan_marker(B4))),
    ok("svdt-pandas-Int64", lambda: svdt(A4, pd.DataFrame(np.round(B4)).astype("Int64"), order="row"), svdt_matches(A4, np.round(B4))),
    err("getR-pandas-bool", lambda: get_R(pd.Series([True, False, False]), [0, 1, 0]), T, r"A must be a numeric array; got booleans"),
    err("getR-pandas-dates", lambda: get_R(pd.Series(pd.to_datetime(["2020", "2021", "2022"])), [0, 1, 0]), T, r"A must be a numeric array; got dates"),
    err("getR-pandas-strings", lambda: get_R(pd.Series(["1", "0", "0"]), [0, 1, 0]), T, r"A must be a numeric array"),
    err("getR-longdouble-1e400", lambda: get_R(np.array([np.longdouble("1e400"), 0, 0]), [0, 1, 0]), V, r"A has a value too large for a float64"),
    ok("getR-decimal-fraction", lambda: get_R([Decimal("1.5"), 0, 0], [0, Fraction(1, 3), 0]), close(rot_z(np.pi / 2), 1e-15)),
    ok("getR-uint64-max", lambda: get_R(np.array([2**64 - 1, 0, 0], np.uint64), [0, 1, 0]), close(rot_z(np.pi / 2), 1e-15)),
    # svdt: shapes and sizes
    err("svdt-0-markers", lambda: svdt(np.zeros((0, 3)), np.zeros((0, 3)), order="row"), V, r"at least 3 markers.*A has 0"),
    err("svdt-2-markers", lambda: svdt(A4[:2], B4[:2], order="row"), V, r"at least 3 markers"),
    err("svdt-A-scalar", lambda: svdt(5.0, B4, order="row"), V, r"A must have shape \(n, 3\)"),
    err("svdt-B-scalar", lambda: svdt(A4, 5.0, order="row"), V, r"B must have shape"),
    err("svdt-marker-count", lambda: svdt(A4, B4[:3], order="row"), V, r"B must have the same number of markers as A \(4\)"),
    err("svdt-B-4d", lambda: svdt(A4, B2[None], order="row"), V, r"B must have shape \(n, 3\) or \(frames, n, 3\)"),
    err("svdt-col-len", lambda: svdt(np.arange(10.0), np.arange(10.0)), V, r"multiple of 3"),
    ok("svdt-0-frames", lambda: svdt(A4, np.zeros((0, 4, 3)), order="row"), lambda out: [np.testing.assert_equal(x.shape, s) for x, s in zip(out, [(0, 3, 3), (0, 3), (0,)])]),
    ok("svdt-0-frames-col", lambda: svdt(A4.ravel(), np.zeros((0, 12))), lambda out: np.testing.assert_equal(out[0].shape, (0, 3, 3))),
    # svdt: values
    err("svdt-A-nan", lambda: svdt(_nan_marker(A4), B4, order="row"), V, r"A contains NaN"),
    err("svdt-A-inf", lambda: svdt(A4 + [np.inf, 0, 0], B4, order="row"), V, r"A contains infinite values"),
    err("svdt-B-inf", lambda: svdt(A4, B4 + [0, -np.inf, 0], order="row"), V, r"B contains infinite values"),
    err("svdt-B-1e300", lambda: svdt(A4, np.where(np.arange(4)[:, None] == 1, 1e300, B4), order="row"), V, r"B has values of magnitude up to 1e\+300"),
    err("svdt-A-collinear", lambda: svdt(np.outer(np.arange(4.0), [1, 2, 3]), B4, order="row"), V, r"markers of A are collinear"),
    err("svdt-A-coincident", lambda: svdt(np.ones((4, 3)), B4, order="row"), V, r"markers of A are coincident"),
    ok("svdt-B-all-nan", lambda: svdt(A4, np.full((2, 4, 3), np.nan), order="row"), all_nan),
    ok("svdt-B-one-missing", lambda: svdt(A4, _nan_marker(B4), order="row"), svdt_matches(A4, _nan_marker(B4))),
    ok("svdt-B-half-coordinate-nan", lambda: svdt(A4, np.where([[0, 0, 0], [0, 1, 0], [0, 0, 0], [0, 0, 0]], np.nan, B4), order="row"), svdt_matches(A4, _nan_marker(B4))),
    ok("svdt-two-missing", lambda: svdt(A4, _nan_marker(_nan_marker(B4, marker=0)), order="row"), all_nan),
    ok("svdt-mirror", lambda: svdt(A4, A4 * [1, 1, -1], order="row")[0], lambda R: (np.testing.assert_allclose(np.linalg.det(R), 1.0), np.testing.assert_allclose(R, svd_fit(A4, A4 * [1, 1, -1])[0], atol=1e-9))),
    ok("svdt-B-planar-A-3d", lambda: svdt(A4, A4 * [1, 1, 0], order="row")[0], lambda R: np.testing.assert_allclose(R, svd_fit(A4, A4 * [1, 1, 0])[0], atol=1e-9)),
    ok("svdt-far-from-origin", lambda: svdt(A4 + 1e7, B4 + 1e7, order="row"), svdt_matches(A4 + 1e7, B4 + 1e7, atol=1e-7)),
    ok("svdt-both-1e-300-missing", lambda: svdt(A4 * 1e-300, _nan_marker(B4 - B4.mean(0)) * 1e-300, order="row")[0], close(R_TRUE, 1e-12)),
    ok("svdt-A-1e-250-missing", lambda: svdt(A4 * 1e-250, _nan_marker(B4), order="row")[0], close(R_TRUE, 1e-12)),
    ok("svdt-1e-160-rmse", lambda: svdt(A4 * 1e-160, (A4 + [[0, 0, 1], [0, 0, -1], [0, 0, 1], [0, 0, -1]]) * 1e-160, order="row")[2] / 1e-160, close(svdt(A4, A4 + [[0, 0, 1], [0, 0, -1], [0, 0, 1], [0, 0, -1]], order="row")[2], 1e-12)),
    ok("svdt-scale-1e-150", lambda: svdt(A4 * 1e-150, B4 * 1e-150, order="row")[0], close(R_TRUE, 1e-12)),
    ok("svdt-scale-1e95", lambda: svdt(A4 * 1e95, B4 * 1e95, order="row")[0], close(R_TRUE, 1e-12)),
    ok("svdt-B-scaled-1e6", lambda: svdt(A4, B4 * 1e6, order="row")[0], close(svd_fit(A4, B4 * 1e6)[0], 1e-9)),
    ok("svdt-B-coincident", lambda: svdt(A4, np.full((4, 3), 2.0), order="row"), all_nan),
    ok("svdt-subnormal-noise", lambda: svdt(A4, B4 + 5e-324, order="row"), svdt_matches(A4, B4)),
    ok("svdt-180-deg", lambda: svdt(A4, A4 @ rot_x(np.pi).T, order="row")[0], close(rot_x(np.pi), 1e-12)),
    # get_R
    err("getR-None", lambda: get_R(None, [0, 1, 0]), T, r"A must be a numeric array; got None"),
    err("getR-zero", lambda: get_R([0, 0, 0], [0, 1, 0]), V, r"A has zero length"),
    err("getR-inf", lambda: get_R([np.inf, 0, 0], [0, 1, 0]), V, r"A contains infinite"),
    err("getR-shape", lambda: get_R([1, 0], [0, 1, 0]), V, r"A must have shape \(\.\.\., 3\)"),
    err("getR-broadcast", lambda: get_R(np.ones((2, 3)), np.ones((3, 3))), V, r"A and B must broadcast"),
    err("getR-bool", lambda: get_R([True, False, False], [0, 1, 0]), T, r"A must be a numeric array; got booleans"),
    err("getR-str", lambda: get_R("x", [0, 1, 0]), T, r"A must be a numeric array"),
    err("getR-complex", lambda: get_R([1j, 0, 0], [0, 1, 0]), T, r"A must be real"),
    ok("getR-huge", lambda: get_R([1e155, 1e155, 0], [0, 1, 0]), close(get_R([1, 1, 0], [0, 1, 0]), 1e-15)),
    ok("getR-tiny", lambda: get_R([1e-300, 0, 0], [0, 1, 0]), close(rot_z(np.pi / 2), 1e-15)),
    ok("getR-subnormal", lambda: get_R([5e-324, 0, 0], [0, 0, 3e-320]), close(rot_y(-np.pi / 2), 1e-15)),
    ok("getR-max-float", lambda: get_R([1.7e308, 0, 0], [0, -1.7e308, 0]), close(rot_z(-np.pi / 2), 1e-15)),
    ok("getR-antiparallel", lambda: get_R([0, 0, 2], [0, 0, -5]) @ [0, 0, 1], close([0, 0, -1], 1e-15)),
    ok("getR-nan", lambda: get_R([np.nan, 0, 0], [0, 1, 0]), all_nan),
    ok("getR-empty", lambda: get_R(np.zeros((0, 3)), [0, 1, 0]).shape, lambda s: np.testing.assert_equal(s, (0, 3, 3))),
    ok("getR-nearly-antiparallel", lambda: get_R([1, 0, 0], [-1, 1e-17, 0]) @ [1, 0, 0], close([-1, 0, 0], 1e-15)),
    # decompose / compose
    err("decompose-reflection", lambda: decompose(np.diag([1.0, 1, -1])), V, r"R is not a rotation matrix.*reflection"),
    err("decompose-scaled", lambda: decompose(2 * np.eye(3)), V, r"R is not a rotation matrix"),
    err("decompose-shape", lambda: decompose(np.eye(4)), V, r"R must have shape \(\.\.\., 3, 3\)"),
    err("decompose-bool", lambda: decompose(np.eye(3, dtype=bool)), T, r"R must be a numeric array; got booleans"),
    err("decompose-None", lambda: decompose(None), T, r"R must be a numeric array; got None"),
    err("decompose-seq-int", lambda: decompose(R_GOOD, 123), T, r"sequence must be a string"),
    err("decompose-seq-xxy", lambda: decompose(R_GOOD, "XXY"), V, r"unknown rotation sequence 'XXY'"),
    err("decompose-seq-long", lambda: decompose(R_GOOD, "ZXYZ"), V, r"unknown rotation sequence"),
    err("decompose-degrees-str", lambda: decompose(R_GOOD, degrees="False"), T, r"degrees must be True or False"),
    err("decompose-extrinsic-str", lambda: decompose(R_GOOD, extrinsic="False"), T, r"extrinsic must be True or False"),
    err("decompose-degrees-int", lambda: decompose(R_GOOD, degrees=1), T, r"degrees must be True or False"),
    err("decompose-1e200", lambda: decompose(np.eye(3) * 1e200), V, r"R has values of magnitude"),
    ok("decompose-nan", lambda: decompose(np.full((3, 3), np.nan)), all_nan),
    ok("decompose-empty", lambda: decompose(np.zeros((0, 3, 3))).shape, lambda s: np.testing.assert_equal(s, (0, 3))),
    ok("decompose-identity", lambda: decompose(np.eye(3)), close([0, 0, 0], 1e-15)),
    ok("decompose-masked", lambda: decompose(np.ma.masked_array(R_GOOD, mask=np.eye(3, dtype=bool))), all_nan),
    ok("decompose-near-gimbal", lambda: compose(decompose(compose([0.3, np.pi / 2 - 1e-9, 0.2])), "ZXY"), close(compose([0.3, np.pi / 2 - 1e-9, 0.2]), 1e-9)),
    ok("decompose-gimbal-warns", lambda: _warns(lambda: decompose(compose([0.3, np.pi / 2, 0.2]))), lambda out: np.testing.assert_allclose(compose(out), compose([0.3, np.pi / 2, 0.2]), atol=1e-11)),
    ok("decompose-vs-scipy", lambda: decompose(R_GOOD, "XYZ", extrinsic=True), close(Rotation.from_matrix(R_GOOD).as_euler("xyz"), 1e-12)),
    ok("decompose-float32", lambda: decompose(R_GOOD.astype(np.float32)), close([0.3, -0.4, 1.1], 1e-6)),
    ok("decompose-euler-near-gimbal", lambda: compose(decompose(compose([0.4, 1e-9, -0.7], "ZXZ"), "ZXZ"), "ZXZ"), close(compose([0.4, 1e-9, -0.7], "ZXZ"), 1e-12)),
    ok("decompose-euler-vs-scipy", lambda: decompose(R_GOOD, "YXY"), close(Rotation.from_matrix(R_GOOD).as_euler("YXY"), 1e-12)),
    ok("decompose-within-tolerance", lambda: decompose(R_GOOD + 1e-8), close([0.3, -0.4, 1.1], 1e-7)),
    err("decompose-seq-bytes", lambda: decompose(R_GOOD, b"ZXY"), T, r"sequence must be a string"),
    err("compose-shape", lambda: compose([0.1, 0.2]), V, r"angles must have shape \(\.\.\., 3\)"),
    err("compose-None", lambda: compose(None), T, r"angles must be a numeric array; got None"),
    err("compose-bool", lambda: compose([True, False, True]), T, r"angles must be a numeric array; got booleans"),
    err("compose-inf", lambda: compose([0, np.inf, 0]), V, r"angles contains infinite"),
    err("compose-1e300", lambda: compose([0, 1e300, 0]), V, r"angles has values of magnitude"),
    err("compose-str-angles", lambda: compose(["0.1", "0.2", "0.3"]), T, r"angles must be a numeric array"),
    err("compose-extrinsic-None", lambda: compose([0, 0, 0], extrinsic=None), T, r"extrinsic must be True or False"),
    # NaN first angle (about z): rows x and y unknown, row z still determined
    ok("compose-nan", lambda: compose([np.nan, 0.2, 0.3]), lambda R: (all_nan(R[:2]), np.testing.assert_allclose(R[2], (rot_x(0.2) @ rot_y(0.3))[2], atol=1e-15))),
    ok("compose-empty", lambda: compose(np.zeros((0, 3))).shape, lambda s: np.testing.assert_equal(s, (0, 3, 3))),
    ok("compose-vs-scipy", lambda: compose([10, 20, 30], "ZYZ", extrinsic=True, degrees=True), close(Rotation.from_euler("zyz", [10, 20, 30], degrees=True).as_matrix(), 1e-14)),
    ok("compose-large-angle", lambda: compose([1e6, 0, 0]), close(rot_z(1e6), 1e-15)),
    # elemental rotations, rotation_angle
    err("elemental-axis-w", lambda: elemental_rotation("w", 1.0), V, r"axis must be one of 'x', 'y', 'z'; got 'w'"),
    err("elemental-axis-int", lambda: elemental_rotation(0, 1.0), T, r"axis must be one of"),
    err("elemental-degrees-str", lambda: elemental_rotation("x", 30, degrees="yes"), T, r"degrees must be True or False"),
    err("rotx-None", lambda: rot_x(None), T, r"angle must be a numeric array; got None"),
    err("rotx-inf", lambda: rot_x(np.inf), V, r"angle contains infinite"),
    err("roty-str", lambda: rot_y("30"), T, r"angle must be a numeric array"),
    err("rotz-bool", lambda: rot_z(True), T, r"angle must be a numeric array; got booleans"),
    ok("rotz-nan", lambda: rot_z(np.nan)[:2, :2], all_nan),
    ok("rotz-masked", lambda: rot_z(np.ma.masked_array([0.5, 1.0], mask=[0, 1]))[1, :2, :2], all_nan),
    ok("rotx-empty", lambda: rot_x([]).shape, lambda s: np.testing.assert_equal(s, (0, 3, 3))),
    err("angle-not-rotation", lambda: rotation_angle(np.ones((3, 3))), V, r"R is not a rotation matrix"),
    err("angle-shape", lambda: rotation_angle(np.eye(2)), V, r"R must have shape"),
    ok("angle-pi", lambda: rotation_angle(rot_x(np.pi)), close(np.pi, 1e-15)),
    ok("angle-tiny", lambda: rotation_angle(rot_y(1e-12)), close(1e-12, 1e-24)),
    ok("angle-near-pi", lambda: rotation_angle(Rotation.from_rotvec([np.pi - 1e-7, 0, 0]).as_matrix()), close(np.pi - 1e-7, 1e-12)),
    ok("angle-vs-scipy", lambda: rotation_angle(R_GOOD), close(Rotation.from_matrix(R_GOOD).magnitude(), 1e-14)),
    ok("angle-nan", lambda: rotation_angle(np.full((2, 3, 3), np.nan)), all_nan),
    # frames
    err("frame-zero-primary", lambda: frame_from_axes([0, 0, 0], [0, 1, 0]), V, r"primary has zero length"),
    err("frame-parallel", lambda: frame_from_axes([1, 0, 0], [-3, 0, 0]), V, r"primary and secondary are parallel"),
    err("frame-axes-int", lambda: frame_from_axes([1, 0, 0], [0, 1, 0], axes=1), T, r"axes must be two different letters"),
    err("frame-axes-xx", lambda: frame_from_axes([1, 0, 0], [0, 1, 0], axes="xx"), V, r"axes must be two different letters"),
    err("frame-None", lambda: frame_from_axes(None, [0, 1, 0]), T, r"primary must be a numeric array; got None"),
    err("frame-inf", lambda: frame_from_axes([np.inf, 0, 0], [0, 1, 0]), V, r"primary contains infinite"),
    ok("frame-huge", lambda: frame_from_axes([1e200, 0, 0], [0, 1e200, 0]), close(np.eye(3), 1e-15)),
    ok("frame-tiny", lambda: frame_from_axes([1e-300, 0, 0], [1e-300, 1e-300, 0]), close(np.eye(3), 1e-15)),
    ok("frame-mixed-scale", lambda: frame_from_axes([1e200, 0, 0], [0, 1e-200, 0]), close(np.eye(3), 1e-15)),
    ok("frame-nan", lambda: frame_from_axes([np.nan, 0, 0], [0, 1, 0]), all_nan),
    err("frame-points-huge", lambda: frame_from_points([-1e300, 0, 0], [1e300, 0, 0], [0, 1, 0]), V, r"origin has values of magnitude"),
    err("frame-points-collinear", lambda: frame_from_points([0, 0, 0], [1, 0, 0], [2, 0, 0]), V, r"parallel"),
    ok("frame-points-vs-oracle", lambda: frame_from_points([1, 1, 1], [1, 1, 5], [3, 1, 1], axes="zx"), close(np.eye(3), 1e-15)),
    # knee angles
    err("knee-side-int", lambda: knee_angles(np.eye(3), np.eye(3), side=1), T, r"side must be 'right' or 'left'"),
    err("knee-side-upper", lambda: knee_angles(np.eye(3), np.eye(3), side="Right"), V, r"side must be 'right' or 'left'; got 'Right'"),
    err("knee-degrees-str", lambda: knee_angles(np.eye(3), np.eye(3), degrees="False"), T, r"degrees must be True or False"),
    err("knee-shapes", lambda: knee_angles(np.eye(3), np.stack([np.eye(3)] * 2)), V, r"R_thigh and R_shank must have the same shape"),
    err("knee-reflection", lambda: knee_angles(np.eye(3), np.diag([1.0, -1, 1])), V, r"R_shank is not a rotation matrix"),
    err("knee-None", lambda: knee_angles(None, np.eye(3)), T, r"R_thigh must be a numeric array; got None"),
    ok("knee-nan", lambda: knee_angles(np.full((3, 3), np.nan), np.eye(3)), all_nan),
    ok("knee-oracle", lambda: knee_angles(np.eye(3), compose([-30, 5, 10], degrees=True), degrees=True), close([30, 5, 10], 1e-12)),
    ok("knee-thigh-tilted", lambda: knee_angles(TILT, TILT @ compose([-30, 5, 10], degrees=True), degrees=True), close([30, 5, 10], 1e-12)),
    # segments
    err("pelvis-coincident", lambda: pelvis_frame(RASIS, RASIS, RPSIS, LPSIS), V, r"rasis and lasis coincide"),
    err("pelvis-None", lambda: pelvis_frame(None, LASIS, RPSIS, LPSIS), T, r"rasis must be a numeric array; got None"),
    err("pelvis-shape", lambda: pelvis_frame(RASIS[:2], LASIS, RPSIS, LPSIS), V, r"rasis must have shape"),
    err("pelvis-huge", lambda: pelvis_frame(RASIS * 1e200, LASIS, RPSIS, LPSIS), V, r"rasis has values of magnitude"),
    err("pelvis-bool", lambda: pelvis_frame(RASIS > 0, LASIS, RPSIS, LPSIS), T, r"rasis must be a numeric array; got booleans"),
    err("pelvis-collinear", lambda: pelvis_frame(RASIS, LASIS, [0, 1000, 300], [0, 1000, -300]), V, r"mid-ASIS and mid-PSIS coincide"),
    ok("pelvis-oracle", lambda: pelvis_frame(RASIS, LASIS, RPSIS, LPSIS)[0], close(np.eye(3), 1e-15)),
    ok("pelvis-nan-frame", lambda: pelvis_frame(np.stack([RASIS, NAN3]), LASIS, RPSIS, LPSIS)[0][1], all_nan),
    ok("pelvis-0-frames", lambda: pelvis_frame(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)))[0].shape, lambda s: np.testing.assert_equal(s, (0, 3, 3))),
    err("hjc-metres", lambda: hip_joint_centre(RASIS / 1000, LASIS / 1000, RPSIS / 1000, LPSIS / 1000), V, r"pelvis width.*must be in mm"),
    err("hjc-side", lambda: hip_joint_centre(RASIS, LASIS, RPSIS, LPSIS, side=None), T, r"side must be 'right' or 'left'; got None"),
    ok("hjc-oracle", lambda: hip_joint_centre([0, 0, 120], [0, 0, -120], [-160, 0, 45], [-160, 0, -45]), close([-0.24 * 160 - 9.9, -0.30 * 240 - 10.9, 0.33 * 240 + 7.3], 1e-12)),
    err("thigh-side-bool", lambda: thigh_frame(HIP, LAT_EP, MED_EP, side=True), T, r"side must be 'right' or 'left'; got True"),
    err("thigh-coincident", lambda: thigh_frame(HIP, LAT_EP, LAT_EP), V, r"lateral_epicondyle and medial_epicondyle coincide"),
    err("thigh-on-line", lambda: thigh_frame([0, 500, 500], [0, 500, 130], [0, 500, 40]), V, r"hip_centre lies on the line through the epicondyles"),
    ok("thigh-oracle", lambda: thigh_frame([0, 420, 0], [0, 0, 45], [0, 0, -45])[0], close(np.eye(3), 1e-15)),
    # distances below 1e-9 (in the data's unit) count as coincident, as documented
    err("thigh-tiny-units", lambda: thigh_frame(np.array([0, 420, 0]) * 1e-200, np.array([0, 0, 45]) * 1e-200, np.array([0, 0, -45]) * 1e-200), V, r"lateral_epicondyle and medial_epicondyle coincide"),
    ok("thigh-far-from-origin", lambda: thigh_frame(np.array([0, 420, 0]) + 1e9, np.array([0, 0, 45]) + 1e9, np.array([0, 0, -45]) + 1e9)[0], close(np.eye(3), 1e-6)),
    err("shank-str", lambda: shank_frame("a", MED_EP, LAT_MAL, MED_MAL), T, r"lateral_epicondyle must be a numeric array"),
    err("shank-broadcast", lambda: shank_frame(np.zeros((2, 3)) + LAT_EP, np.zeros((3, 3)) + MED_EP, LAT_MAL, MED_MAL), V, r"landmark arrays must have the same shape"),
    ok("shank-oracle", lambda: shank_frame([0, 400, 45], [0, 400, -45], [0, 0, 35], [0, 0, -35])[0], close(np.eye(3), 1e-15)),
    # tracking
    err("calibrate-2-markers", lambda: calibrate_cluster(A4[:2], [[0, 0, 0]]), V, r"a cluster needs at least 3 markers"),
    err("calibrate-collinear", lambda: calibrate_cluster(np.outer(np.arange(4.0), [1, 0, 0]), [[0, 0, 0]]), V, r"collinear"),
    err("calibrate-None", lambda: calibrate_cluster(None, [[0, 0, 0]]), T, r"cluster_static must be a numeric array; got None"),
    err("calibrate-nan-marker", lambda: calibrate_cluster(_nan_marker(A4), [[0, 0, 0]]), V, r"marker\(s\) \[1\] are missing"),
    err("calibrate-huge", lambda: calibrate_cluster(A4 * 1e200, [[0, 0, 0]]), V, r"cluster_static has values of magnitude"),
    err("calibrate-4d", lambda: calibrate_cluster(A4[None, None], [[0, 0, 0]]), V, r"cluster_static must have shape"),
    ok("calibrate-tiny", lambda: _calibrate_roundtrip(1e-200), close(np.zeros(3), 1e-12)),
    ok("calibrate-first-three-collinear", lambda: calibrate_cluster([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]], [[0, 0, 5]])[1], lambda l: np.testing.assert_allclose(np.linalg.norm(l), np.linalg.norm(np.array([0, 0, 5]) - [0.75, 0.25, 0]), rtol=1e-12)),
    ok("calibrate-static-frames-partly-nan", lambda: calibrate_cluster(np.stack([A4, _nan_marker(A4), A4 + 0.0]), [[0, 0, 0]])[0], close(calibrate_cluster(A4, [[0, 0, 0]])[0], 1e-12)),
    err("calibrate-landmarks-inf", lambda: calibrate_cluster(A4, [[np.inf, 0, 0]]), V, r"landmarks_static contains infinite"),
    err("cluster-noise-broadcast", lambda: orientation_error_covariance(np.stack([A4, A4]), [0.1, 0.2, 0.3]), V, r"noise_sd must be a scalar or broadcast"),
    err("reconstruct-marker-count", lambda: reconstruct_landmarks(A4, [[0, 0, 0]], B2[:, :3]), V, r"cluster_dynamic has 3 markers per frame but cluster_local has 4"),
    err("reconstruct-2d-dynamic", lambda: reconstruct_landmarks(A4, [[0, 0, 0]], B4), V, r"cluster_dynamic must have shape \(frames, n, 3\)"),
    err("reconstruct-nan-local", lambda: reconstruct_landmarks(_nan_marker(A4), [[0, 0, 0]], B2), V, r"cluster_local contains NaN"),
    ok("reconstruct-oracle", lambda: reconstruct_landmarks(A4, [[10, 20, 30]], B2)[0][:, 0], close([R_TRUE @ [10, 20, 30] + L_TRUE] * 2, 1e-9)),
    ok("reconstruct-masked", lambda: reconstruct_landmarks(A4, [[10, 20, 30]], np.ma.masked_invalid(_nan_marker(B2, 1)))[0][:, 0], close([R_TRUE @ [10, 20, 30] + L_TRUE] * 2, 1e-9)),
    ok("reconstruct-0-frames", lambda: reconstruct_landmarks(A4, [[0, 0, 0]], np.zeros((0, 4, 3)))[0].shape, lambda s: np.testing.assert_equal(s, (0, 1, 3))),
    # clusters
    err("cluster-noise-negative", lambda: expected_orientation_error(A4, -1.0), V, r"noise_sd must be finite and >= 0"),
    err("cluster-noise-str", lambda: expected_orientation_error(A4, "0.5"), T, r"noise_sd must be a numeric array"),
    err("cluster-noise-huge", lambda: expected_orientation_error(A4, 1e200), V, r"noise_sd has values of magnitude"),
    err("cluster-nan", lambda: orientation_error_covariance(_nan_marker(A4), 0.5), V, r"markers contains NaN"),
    err("cluster-collinear", lambda: orientation_error_covariance(np.outer(np.arange(4.0), [1, 1, 0]), 0.5), V, r"coincident or collinear"),
    err("cluster-coincident", lambda: expected_orientation_error(np.ones((4, 3)), 0.5), V, r"coincident or collinear"),
    err("cluster-huge", lambda: expected_orientation_error(A4 * 1e200, 0.5), V, r"markers has values of magnitude"),
    err("cluster-degrees-str", lambda: expected_orientation_error(A4, 0.5, degrees="True"), T, r"degrees must be True or False"),
    ok("cluster-tiny", lambda: expected_orientation_error(A4 * 1e-160, 0.5e-160), close(expected_orientation_error(A4, 0.5), 1e-15)),
    ok("cluster-zero-noise", lambda: expected_orientation_error(A4, 0.0), close(0.0, 0)),
    ok("cluster-cov-oracle", lambda: orientation_error_covariance([[50, 0, 0], [0, 50, 0], [-50, 0, 0], [0, -50, 0]], 0.5), close(np.diag([0.25 / 5000, 0.25 / 5000, 0.25 / 10000]), 1e-18)),
    # skeleton
    err("skeleton-length-bool", lambda: Skeleton.default({"thigh": True}), T, r"lengths\['thigh'\] must be a numeric array; got booleans"),
    err("skeleton-lengths-list", lambda: Skeleton.default([0.1]), T, r"lengths must be a dict"),
    err("skeleton-lengths-array", lambda: Skeleton.default(np.array([0.4])), T, r"lengths must be a dict"),
    err("skeleton-lengths-intkey", lambda: Skeleton.default({1: 0.4}), V, r"unknown bone length 1"),
    err("skeleton-length-huge", lambda: Skeleton.default({"thigh": 1e200}), V, r"lengths\['thigh'\] must be a positive number"),
    err("skeleton-length-inf", lambda: Skeleton.default({"thigh": np.inf}), V, r"lengths\['thigh'\] must be a positive number"),
    err("skeleton-offsets-list", lambda: Skeleton([1, 2, 3]), T, r"offsets must be a dict"),
    err("skeleton-offset-bool", lambda: Skeleton({**Skeleton.default().offsets, "leftknee": [False, True, False]}), T, r"offsets\['leftknee'\] must be a numeric array; got booleans"),
    ok("skeleton-tiny-offsets", lambda: Skeleton({j: v * 1e-200 for j, v in Skeleton.default().offsets.items()}).lengths["thigh"], close(0.42e-200, 1e-212)),
    ok("skeleton-length-int", lambda: Skeleton.default({"thigh": 1}).lengths["thigh"], close(1.0, 0)),
    err("tpose-root-str", lambda: Skeleton.default().tpose("abc"), T, r"root_position must be a numeric array"),
    err("tpose-root-huge", lambda: Skeleton.default().tpose([1e200, 0, 0]), V, r"root_position must be 3 finite numbers"),
    err("pose-positions-list", lambda: pose_to_angles([1, 2], Skeleton.default()), T, r"positions must be a dict"),
    err("pose-skeleton-None", lambda: pose_to_angles(_pose(), None), V, r"skeleton must be a Skeleton"),
    err("pose-huge", lambda: pose_to_angles({**_pose(), "leftknee": np.array([[1e300, 0, 0]])}, Skeleton.default()), V, r"positions\['leftknee'\] has values of magnitude"),
    err("pose-bool", lambda: pose_to_angles({**_pose(), "leftknee": np.array([[True, False, True]])}, Skeleton.default()), T, r"positions\['leftknee'\] must be a numeric array; got booleans"),
    err("pose-ragged-frames", lambda: pose_to_angles({**_pose(), "leftknee": np.zeros((2, 3))}, Skeleton.default()), V, r"positions\['leftknee'\] has 2 frames"),
    err("pose-sequence", lambda: pose_to_angles(_pose(), Skeleton.default(), sequence=None), T, r"sequence must be a string"),
    ok("pose-tpose-zero", lambda: pose_to_angles(_pose(), Skeleton.default()).angles["leftknee"], close(np.zeros((1, 3)), 1e-15)),
    ok("pose-masked", lambda: pose_to_angles({**_pose(), "leftfoot": np.ma.masked_array(_pose()["leftfoot"], mask=True)}, Skeleton.default()).angles["leftknee"], all_nan),
    ok("pose-roundtrip", lambda: angles_to_pose(pose_to_angles(_pose(), Skeleton.default()), Skeleton.default()), _skeleton_roundtrip),
    err("a2p-rotations-list", lambda: angles_to_pose(PoseAngles(np.zeros((1, 3)), np.eye(3)[None], rotations=[1, 2]), Skeleton.default()), T, r"result.rotations must be a dict"),
    err("a2p-angles-bool", lambda: angles_to_pose(PoseAngles(np.zeros((1, 3)), np.eye(3)[None], angles={j: np.zeros((1, 3), bool) for j in _ROTATING}), Skeleton.default()), T, r"result.angles\['hips'\] must be a numeric array; got booleans"),
    err("a2p-root-None", lambda: angles_to_pose(PoseAngles(None, np.eye(3)[None], rotations={}), Skeleton.default()), T, r"result.root_position must be a numeric array; got None"),
    ok("pose-0-frames", lambda: pose_to_angles({k: np.zeros((0, 3)) for k in _pose()}, Skeleton.default()).angles["leftknee"].shape, lambda s: np.testing.assert_equal(s, (0, 3))),
    ok("a2p-nan-rotation", lambda: angles_to_pose(PoseAngles(np.zeros((1, 3)), np.full((1, 3, 3), np.nan), rotations={j: np.eye(3)[None] for j in _ROTATING}), Skeleton.default())["leftfoot"], all_nan),
    err("a2p-result-dict", lambda: angles_to_pose({}, Skeleton.default()), V, r"result must be a PoseAngles"),
    err("a2p-reflection", lambda: angles_to_pose(PoseAngles(np.zeros((1, 3)), np.diag([1.0, 1, -1])[None], rotations={}), Skeleton.default()), V, r"result.root_rotation is not a rotation matrix"),
    # plotting helpers (Agg backend)
    err("plot-draw-frame-inf", lambda: _plot(lambda ax: draw_frame(ax, np.full((3, 3), np.inf))), V, r"R contains infinite"),
    err("plot-draw-frame-length", lambda: _plot(lambda ax: draw_frame(ax, length="1")), T, r"length must be a numeric array"),
    err("plot-markers-connect", lambda: _plot(lambda ax: plot_markers(ax, A4, connect="no")), T, r"connect must be True or False"),
    err("plot-markers-shape", lambda: _plot(lambda ax: plot_markers(ax, B2)), V, r"markers must have shape \(n, 3\)"),
    err("plot-residuals-scale", lambda: _plot(lambda ax: plot_residuals(ax, A4, A4, scale=[1, 2])), V, r"scale must be a single number"),
    err("plot-row-titles", lambda: _close(plot_frames_row(np.stack([R_GOOD] * 2), titles=5)), V, r"titles must be a sequence"),
    err("plot-row-reference", lambda: _close(plot_frames_row(np.stack([R_GOOD] * 2), reference="no")), T, r"reference must be True or False"),
    ok("plot-residuals-oracle", lambda: _plot(lambda ax: plot_residuals(ax, A4 + 1, A4)), close(np.ones((4, 3)), 0)),
]


def _warns(call):
    with pytest.warns(RuntimeWarning, match="gimbal lock"):
        return call()


def _calibrate_roundtrip(scale):
    """Landmark at the cluster's centroid: at the origin of the technical frame."""
    cluster = A4 * scale
    return calibrate_cluster(cluster, cluster.mean(axis=0, keepdims=True))[1][0] / scale


def _plot(draw):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    try:
        return draw(plt.figure().add_subplot(projection="3d"))
    finally:
        plt.close("all")


def _close(result):
    import matplotlib.pyplot as plt
    plt.close("all")
    return result


def run_case(case):
    """Run one case and assert its expectation (used by the test and by the classifier)."""
    if case.error is not None:
        with pytest.raises(case.error, match=case.match):
            case.call()
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            out = case.call()
        case.check(out)


def test_case_ids_are_unique():
    ids = [case.id for case in CASES]
    assert len(ids) == len(set(ids))
    assert len(ids) >= 100


@pytest.mark.parametrize("case", CASES, ids=[case.id for case in CASES])
def test_adversarial_case(case):
    run_case(case)


# --- heavy inputs, each in a subprocess with a time limit --------------------------------

HEAVY = {
    # 200,000 frames with every marker missing: NaN out, one warning, no per-frame loop
    "svdt-many-nan-frames": """
        import warnings
        import numpy as np
        from bmc_functions import svdt
        A = np.array([[0.0, 0, 0], [100, 0, 0], [0, 60, 0], [20, 30, 80]])
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            R, L, rmse = svdt(A, np.full((200_000, 4, 3), np.nan), order="row")
        assert np.isnan(rmse).all() and len(caught) == 1, caught
    """,
    # 200 markers, each frame missing a different random subset
    "svdt-200-markers-random-occlusion": """
        import warnings
        import numpy as np
        from bmc_functions import svdt
        rng = np.random.default_rng(3)
        A = rng.normal(size=(200, 3)) * 100
        B = np.broadcast_to(A, (2000, 200, 3)).copy()
        B[rng.random((2000, 200)) < 0.5] = np.nan
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            R, L, rmse = svdt(A, B, order="row")
        np.testing.assert_allclose(R, np.broadcast_to(np.eye(3), R.shape), atol=1e-9)
    """,
    # 20,000 markers in 2 GB of address space: the moment matrix alone would need 29 GB
    "svdt-20000-markers-bounded-memory": """
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (2 * 2**30, 2 * 2**30))
        import numpy as np
        from bmc_functions import svdt, rot_z
        rng = np.random.default_rng(5)
        A = rng.normal(size=(20_000, 3)) * 100
        B = np.stack([A @ rot_z(0.1 * k).T for k in range(5)])
        R, L, rmse = svdt(A, B, order="row")
        assert np.allclose(R, np.stack([rot_z(0.1 * k) for k in range(5)]), atol=1e-12)
        assert np.all(rmse < 1e-10)
    """,
    # an object array of 20,000 frames of Python ints
    "svdt-object-ints": """
        import numpy as np
        from bmc_functions import svdt
        A = np.array([[0, 0, 0], [100, 0, 0], [0, 60, 0], [20, 30, 80]])
        B = np.empty((20_000, 4, 3), dtype=object)
        B[:] = A.astype(object)
        R, L, rmse = svdt(A, B, order="row")
        assert np.allclose(R, np.eye(3)) and np.allclose(rmse, 0)
    """,
    # decompose of 200,000 matrices at gimbal lock: one warning, angles reproduce R
    "decompose-many-gimbal": """
        import warnings
        import numpy as np
        from bmc_functions import compose, decompose
        R = np.broadcast_to(compose([0.3, np.pi / 2, 0.2]), (200_000, 3, 3))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            angles = decompose(R)
        assert len(caught) == 1
        assert np.allclose(compose(angles[:10]), R[:10], atol=1e-11)
    """,
}


@pytest.mark.parametrize("name", sorted(HEAVY))
def test_heavy_case_in_a_subprocess(name):
    code = textwrap.dedent(HEAVY[name])
    try:
        proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                              text=True, timeout=120,
                              env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin",
                                   "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"})
    except subprocess.TimeoutExpired:
        pytest.fail(f"{name} did not finish within 120 s (a hang?)")
    assert proc.returncode == 0, f"{name}: exit code {proc.returncode}\n{proc.stderr[-2000:]}"


def test_max_magnitude_is_far_beyond_any_measurement_and_far_below_overflow():
    assert 1e20 < MAX_MAGNITUDE and MAX_MAGNITUDE**2 * 1e6 < np.finfo(float).max
