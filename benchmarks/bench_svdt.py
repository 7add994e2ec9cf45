"""Benchmark of svdt against per-frame loops and the floor; and of the angle functions.

Run from the repository root:

    python benchmarks/bench_svdt.py            # N = 10^3 ... 10^6 (about 2 minutes)
    python benchmarks/bench_svdt.py --quick    # N = 10^3 ... 10^5, loops up to 10^4

For N frames of a 4-marker cluster (random orientations, a walking-like path, 0.5 mm
noise) it times, side by side, the median of several repeats of:

(a) a per-frame loop equivalent to the seed's svdt (one SVD per frame);
(b) scipy.spatial.transform.Rotation.align_vectors in a per-frame loop, with the
    centring and the translation done by hand;
(c) bmc_functions.svdt;
(d) the floor: the centroids and the per-frame cross-covariance matrices only
    (bmc_functions.rigid_body.cross_covariance), which every method has to compute,
    here as fast as NumPy allows: one BLAS matrix product over all frames;
(d0) the same quantities computed the straightforward NumPy way (means, centred copies,
    a batched matrix product): the floor a vectorized textbook implementation pays.

It prints the times, the ratios a/c, b/c and c/d, the time per frame of (c) (constant if
its time is linear in N) and the peak memory of each call (tracemalloc; the input is
not counted). The loops (a) and (b) run up to N = 10^5 (10^4 with --quick); beyond that
their cells are '-'. A second table compares decompose, compose and get_R on 10^6
rotations (10^5 with --quick) with SciPy computing the same results from the same input.
This is a benchmark to read, not a test: timings vary with the machine and its load.
"""

import argparse
import os
import platform
import sys
import time
import tracemalloc
import warnings

import numpy as np
import scipy
from scipy.spatial.transform import Rotation

from bmc_functions import compose, decompose, get_R, svdt
from bmc_functions.rigid_body import cross_covariance


# --- the methods ----------------------------------------------------------------------------

def loop_seed(A, B):
    """(a) One SVD per frame, as the seed's svdt does (reflection fix, RMSE per marker)."""
    F = len(B)
    R_all, L_all, rmse_all = np.empty((F, 3, 3)), np.empty((F, 3)), np.empty(F)
    a_mean = A.mean(axis=0)
    for f in range(F):
        b = B[f]
        b_mean = b.mean(axis=0)
        U, _, Vt = np.linalg.svd((b - b_mean).T @ (A - a_mean))
        R = U @ np.diag([1.0, 1.0, np.linalg.det(U @ Vt)]) @ Vt
        L = b_mean - R @ a_mean
        err = 0.0
        for i in range(len(A)):
            err += np.sum((R @ A[i] + L - b[i]) ** 2)
        R_all[f], L_all[f], rmse_all[f] = R, L, np.sqrt(err / A.size)
    return R_all, L_all, rmse_all


def loop_scipy(A, B):
    """(b) scipy's align_vectors per frame; centring, translation and RMSE by hand."""
    F = len(B)
    R_all, L_all, rmse_all = np.empty((F, 3, 3)), np.empty((F, 3)), np.empty(F)
    a_mean = A.mean(axis=0)
    A_centred = A - a_mean
    for f in range(F):
        b_mean = B[f].mean(axis=0)
        rotation, _ = Rotation.align_vectors(B[f] - b_mean, A_centred)
        R = rotation.as_matrix()
        L = b_mean - R @ a_mean
        residual = A @ R.T + L - B[f]
        R_all[f], L_all[f], rmse_all[f] = R, L, np.sqrt(np.sum(residual**2) / A.size)
    return R_all, L_all, rmse_all


def package_svdt(A, B):
    """(c)"""
    return svdt(A, B, order="row")


def floor(A, B, weights):
    """(d) centroids and cross-covariance matrices only."""
    return cross_covariance(A, B, weights)


def floor_textbook(A, B):
    """(d0) centroids and cross-covariance matrices, the straightforward NumPy way."""
    a_mean = A.mean(axis=0)
    b_mean = B.mean(axis=1)
    M = np.matmul(np.swapaxes(B - b_mean[:, None, :], 1, 2), A - a_mean)
    return a_mean, b_mean, M


def scipy_vector_rotation(a, b):
    """The rotation of get_R (about a x b by the angle between a and b) with scipy."""
    a = a / np.linalg.norm(a, axis=1, keepdims=True)
    b = b / np.linalg.norm(b, axis=1, keepdims=True)
    w = np.cross(a, b)
    sin = np.linalg.norm(w, axis=1)
    angle = np.arctan2(sin, np.sum(a * b, axis=1))
    return Rotation.from_rotvec(w * (angle / sin)[:, None]).as_matrix()


# --- data and measurement ----------------------------------------------------------------------

def make_trial(n_frames, rng):
    """A 4-marker cluster (about 60 mm across) moving along a walking-like path."""
    A = np.array([[0.0, 0.0, 0.0], [70.0, 5.0, 0.0], [10.0, 55.0, 5.0], [60.0, 50.0, 30.0]])
    R = Rotation.random(n_frames, random_state=rng).as_matrix()
    t = np.linspace(0.0, 1.0, n_frames)
    path = np.column_stack([5000.0 * t, 300.0 * np.sin(20 * t), 900.0 + 40.0 * np.sin(60 * t)])
    B = np.einsum("fij,nj->fni", R, A) + path[:, None, :]
    B += rng.normal(scale=0.5, size=B.shape)
    return A, B


def median_time(function, *args, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function(*args)
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def peak_memory_mb(function, *args):
    tracemalloc.start()
    try:
        function(*args)
        return tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()


def machine_description():
    try:
        blas = np.show_config(mode="dicts")["Build Dependencies"]["blas"]
        blas = f"{blas.get('name')} {blas.get('version')}"
    except Exception:  # the layout of numpy's build information changes across versions
        blas = "unknown"
    cpu = platform.processor() or "unknown"
    try:
        with open("/proc/cpuinfo") as info:
            cpu = next(line.split(":", 1)[1].strip() for line in info
                       if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    coretype = os.environ.get("OPENBLAS_CORETYPE")
    lines = [
        f"machine: {platform.platform()}; {cpu}; {os.cpu_count()} logical CPUs",
        f"python {platform.python_version()}, numpy {np.__version__} (BLAS: {blas}), "
        f"scipy {scipy.__version__}",
        "OPENBLAS_CORETYPE: " + (f"{coretype} (set: it selects an older OpenBLAS kernel, "
                                 "which slows numpy; times are with it)"
                                 if coretype else "not set"),
    ]
    return "\n".join(lines)


def fmt_time(seconds):
    if seconds is None:
        return "-"
    return f"{seconds * 1e3:.3g} ms" if seconds < 1 else f"{seconds:.3g} s"


def fmt(value, spec):
    return "-" if value is None else format(value, spec)


# --- the tables ------------------------------------------------------------------------------------

def svdt_table(sizes, loop_limit, rng):
    print("\nsvdt: N frames x 4 markers; median time of repeats (peak memory, MB)")
    header = (f"{'N':>9} | {'(a) seed loop':>16} | {'(b) scipy loop':>16} | {'(c) svdt':>16} | "
              f"{'(d) floor':>16} | {'(d0) textbook':>14} | {'a/c':>6} | {'b/c':>6} | "
              f"{'c/d':>5} | {'c/d0':>5} | {'c ns/frame':>10}")
    print(header)
    print("-" * len(header))
    for n_frames in sizes:
        A, B = make_trial(n_frames, rng)
        weights = np.ones(B.shape[:2])
        fast_repeats = 7 if n_frames <= 100_000 else 5
        loop_repeats = 3 if n_frames <= 10_000 else 2
        t_c = median_time(package_svdt, A, B, repeats=fast_repeats)
        t_d = median_time(floor, A, B, weights, repeats=fast_repeats)
        t_d0 = median_time(floor_textbook, A, B, repeats=fast_repeats)
        _, _, M_d0 = floor_textbook(A, B)
        assert np.allclose(M_d0, floor(A, B, weights)[2], rtol=1e-9, atol=1e-6)
        m_c = peak_memory_mb(package_svdt, A, B)
        m_d = peak_memory_mb(floor, A, B, weights)
        t_a = t_b = m_a = m_b = None
        if n_frames <= loop_limit:
            t_a = median_time(loop_seed, A, B, repeats=loop_repeats)
            t_b = median_time(loop_scipy, A, B, repeats=loop_repeats)
            if n_frames <= 10_000:  # tracemalloc slows a Python loop down a lot
                m_a = peak_memory_mb(loop_seed, A, B)
                m_b = peak_memory_mb(loop_scipy, A, B)
            # the methods agree (a check, not a timing)
            R_a, L_a, rmse_a = loop_seed(A, B) if n_frames <= 10_000 else loop_seed(
                A, B[:10_000])
            R_c, L_c, rmse_c = package_svdt(A, B[:len(R_a)])
            assert np.abs(R_a - R_c).max() < 1e-9 and np.abs(rmse_a - rmse_c).max() < 1e-9

        def cell(t, m):
            return f"{fmt_time(t)} ({fmt(m, '.3g')})" if t is not None else "-"

        print(f"{n_frames:>9,} | {cell(t_a, m_a):>16} | {cell(t_b, m_b):>16} | "
              f"{cell(t_c, m_c):>16} | {cell(t_d, m_d):>16} | {fmt_time(t_d0):>14} | "
              f"{fmt(t_a and t_a / t_c, '6.0f'):>6} | {fmt(t_b and t_b / t_c, '6.0f'):>6} | "
              f"{t_c / t_d:5.1f} | {t_c / t_d0:5.1f} | {t_c / n_frames * 1e9:10.0f}")
    print("a/c, b/c: how many times faster svdt is than the loops; c/d, c/d0: svdt / the "
          "floor (BLAS, textbook).")


def angles_table(n, rng):
    print(f"\nAngle functions on {n:,} rotations, against SciPy computing the same result "
          "from the same input (median of 3)")
    R = Rotation.random(n, random_state=rng).as_matrix()
    angles = rng.uniform(-1.5, 1.5, size=(n, 3))
    a, b = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    rotation = Rotation.from_matrix(R)
    rows = [
        ("decompose(R, 'ZXY')", lambda: decompose(R, "ZXY"),
         "from_matrix(R).as_euler('ZXY')", lambda: Rotation.from_matrix(R).as_euler("ZXY")),
        ("compose(angles, 'ZXY')", lambda: compose(angles, "ZXY"),
         "from_euler('ZXY', angles).as_matrix()",
         lambda: Rotation.from_euler("ZXY", angles).as_matrix()),
        ("get_R(a, b)", lambda: get_R(a, b),
         "from_rotvec(axis * angle).as_matrix()", lambda: scipy_vector_rotation(a, b)),
    ]
    print(f"{'bmc_functions':>24} | {'time':>9} | {'scipy':>38} | {'time':>9} | "
          f"{'ratio':>5} | {'max diff':>8}")
    for name, ours, scipy_name, theirs in rows:
        t_ours = median_time(ours, repeats=3)
        t_theirs = median_time(theirs, repeats=3)
        diff = np.abs(ours() - theirs()).max()
        print(f"{name:>24} | {fmt_time(t_ours):>9} | {scipy_name:>38} | "
              f"{fmt_time(t_theirs):>9} | {t_ours / t_theirs:5.2f} | {diff:8.1e}")
    t_euler_only = median_time(lambda: rotation.as_euler("ZXY"), repeats=3)
    print(f"(for reference: scipy's as_euler alone, from its stored quaternions: "
          f"{fmt_time(t_euler_only)})")
    print("ratio: bmc_functions time / scipy time (target: at most 2).")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="N up to 10^5, loops up to 10^4, angle table on 10^5")
    args = parser.parse_args(argv)
    rng = np.random.default_rng(2024)
    print(machine_description())
    warnings.simplefilter("error", RuntimeWarning)  # no frame of these trials may fail
    if args.quick:
        svdt_table([1_000, 10_000, 100_000], 10_000, rng)
        angles_table(100_000, rng)
    else:
        svdt_table([1_000, 10_000, 100_000, 1_000_000], 100_000, rng)
        angles_table(1_000_000, rng)


if __name__ == "__main__":
    sys.exit(main())
