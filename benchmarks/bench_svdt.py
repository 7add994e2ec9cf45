"""Benchmark of svdt against per-frame loops and the floor; and of the angle functions.

Run from the repository root:

    python benchmarks/bench_svdt.py            # N = 10^3 ... 10^6 and every row (minutes)
    python benchmarks/bench_svdt.py --quick    # N = 10^3 ... 10^5, loops up to 10^4 (~1 min)

For N frames of a 4-marker cluster (random orientations, a walking-like path, 0.5 mm
noise) it times, side by side, the median of several repeats of:

(a) a per-frame loop equivalent to the seed's svdt (one SVD per frame);
(b) scipy.spatial.transform.Rotation.align_vectors in a per-frame loop, with the
    centring and the translation done by hand;
(c) bmc_functions.svdt;
(d) the floor: the centroids and the per-frame cross-covariance matrices only
    (bmc_functions.rigid_body.svdt.cross_covariance), which every method has to compute,
    here as fast as NumPy allows: one BLAS matrix product over all frames;
(d0) the same quantities computed the straightforward NumPy way (means, centred copies,
    a batched matrix product): the floor a vectorized textbook implementation pays.

It prints the times, the ratios a/c, b/c and c/d, the time per frame of (c) (constant if
its time is linear in N) and the peak memory of each call (tracemalloc; the input is
not counted). The loops (a) and (b) run up to N = 10^5 (10^4 with --quick); beyond that
their cells are '-'. A second table compares decompose, compose and get_R on 10^6
rotations (10^5 with --quick) with SciPy computing the same results from the same input.
Then svdt idle and under a competing process, svdt's two fitting paths (the closed form
and the exact SVD path, also from 16 to 512 markers), roma (if installed), and the rows of the
other benchmarks beside this file: read_trc against pandas.read_csv on a 342 MB TRC file
(bench_read_trc.py; 34 MB with --quick), the lower-limb pipeline on a 10-minute trial
(bench_lower_limb.py) and an archive of 200 trials of 5 s, serial, in 2 processes and on
a dask LocalCluster (bench_archive.py; 40 trials of 2 s with --quick).
Every table times its methods in interleaved rounds (each round runs every method once), so
that a change of load during the run affects all of them alike; it reports the median and the
min. The machine, its load average and the BLAS thread settings are printed first: read the
ratios from a run on an idle machine (load average close to 0).
This is a benchmark to read, not a test: timings vary with the machine and its load.
"""

import argparse
import os
import platform
import subprocess
import sys
import time
import tracemalloc
import warnings
from pathlib import Path

import numpy as np
import scipy
from scipy.spatial.transform import Rotation
from threadpoolctl import ThreadpoolController, threadpool_info

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))  # run from a checkout without installing

from bmc_functions import compose, decompose, get_R, svdt  # noqa: E402
from bmc_functions.rigid_body import svdt as svdt_module  # noqa: E402
from bmc_functions.rigid_body.svdt import cross_covariance  # noqa: E402


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


def rounds(methods, repeats):
    """Time several methods interleaved: each round runs every method once, in turn.

    Interleaving spreads any change in the machine's load over all methods alike, so their
    ratios stay fair even when the absolute times drift. Returns {name: (median, min)}.
    """
    times = {name: [] for name in methods}
    for _ in range(repeats):
        for name, function in methods.items():
            start = time.perf_counter()
            function()
            times[name].append(time.perf_counter() - start)
    return {name: (float(np.median(t)), float(np.min(t))) for name, t in times.items()}


def median_time(function, *args, repeats):
    return rounds({"f": lambda: function(*args)}, repeats)["f"][0]


def peak_memory_mb(function, *args):
    tracemalloc.start()
    try:
        function(*args)
        return tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()


class CompetingProcess:
    """A second Python process spinning on one core while the block runs."""

    def __enter__(self):
        self.process = subprocess.Popen([sys.executable, "-c", "while True: pass"])
        time.sleep(0.5)  # let it start spinning
        return self

    def __exit__(self, *exc):
        self.process.kill()
        self.process.wait()


def blas_threads():
    return ", ".join(f"{lib['internal_api']} {lib['num_threads']} threads"
                     for lib in threadpool_info() if lib["user_api"] == "blas") or "none found"


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
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "?"
    lines = [
        f"machine: {platform.platform()}; {cpu}; {os.cpu_count()} logical CPUs",
        f"load average (1, 5, 15 min) at start: {load}  (an idle machine reads close to 0)",
        f"BLAS: {blas_threads()} by default; svdt limits itself to 1 (threadpoolctl); "
        "OMP_NUM_THREADS=" + os.environ.get("OMP_NUM_THREADS", "unset") +
        ", OPENBLAS_NUM_THREADS=" + os.environ.get("OPENBLAS_NUM_THREADS", "unset"),
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


# --- the tables -------------------------------------------------------------------------------

def svdt_table(sizes, loop_limit, rng):
    print("\nsvdt: N frames x 4 markers; median (min) of interleaved rounds; peak memory (MB) "
          "in brackets")
    header = (f"{'N':>9} | {'(a) seed loop':>27} | {'(b) scipy loop':>27} | {'(c) svdt':>27} | "
              f"{'(d) floor':>27} | {'(d1) floor, 1 thr':>27} | {'(d0) textbook':>27} | "
              f"{'a/c':>5} | {'b/c':>5} | {'c/d':>5} | {'c/d1':>5} | {'c/d0':>5} | {'c ns/fr':>7}")
    print(header)
    print("-" * len(header))
    controller = ThreadpoolController()
    for n_frames in sizes:
        A, B = make_trial(n_frames, rng)
        weights = np.ones(B.shape[:2])

        def floor_one_thread():
            with controller.limit(limits=1, user_api="blas"):
                floor(A, B, weights)

        methods = {
            "c": lambda: package_svdt(A, B),
            "d": lambda: floor(A, B, weights),
            "d1": floor_one_thread,
            "d0": lambda: floor_textbook(A, B),
        }
        if n_frames <= loop_limit:
            methods["a"] = lambda: loop_seed(A, B)
            methods["b"] = lambda: loop_scipy(A, B)
        repeats = 7 if n_frames <= 10_000 else (5 if n_frames <= 100_000 else 3)
        if n_frames > 10_000 and n_frames <= loop_limit:
            repeats = 3  # the loops take seconds each
        t = rounds(methods, repeats)
        # the methods agree (a check, not a timing)
        _, _, M_d0 = floor_textbook(A, B)
        assert np.allclose(M_d0, floor(A, B, weights)[2], rtol=1e-9, atol=1e-6)
        check = min(n_frames, 10_000)
        R_a, _, rmse_a = loop_seed(A, B[:check])
        R_c, _, rmse_c = package_svdt(A, B[:check])
        assert np.abs(R_a - R_c).max() < 1e-9 and np.abs(rmse_a - rmse_c).max() < 1e-9
        m = {"c": peak_memory_mb(package_svdt, A, B), "d": peak_memory_mb(floor, A, B, weights)}
        if n_frames <= 10_000:  # tracemalloc slows a Python loop down a lot
            m["a"] = peak_memory_mb(loop_seed, A, B)
            m["b"] = peak_memory_mb(loop_scipy, A, B)

        def cell(key):
            if key not in t:
                return "-"
            text = f"{fmt_time(t[key][0])} ({fmt_time(t[key][1])})"
            return text + (f" [{m[key]:.3g}]" if key in m else "")

        def ratio(key, spec="5.0f"):
            return fmt(t[key][0] / t["c"][0], spec) if key in t else "-"

        tc = t["c"][0]
        print(f"{n_frames:>9,} | {cell('a'):>27} | {cell('b'):>27} | {cell('c'):>27} | "
              f"{cell('d'):>27} | {cell('d1'):>27} | {cell('d0'):>27} | "
              f"{ratio('a'):>5} | {ratio('b'):>5} | {tc / t['d'][0]:5.1f} | "
              f"{tc / t['d1'][0]:5.1f} | {tc / t['d0'][0]:5.1f} | {tc / n_frames * 1e9:7.0f}")
    print("a/c, b/c: how many times faster svdt is than the loops; c/d, c/d1, c/d0: svdt / "
          "the floor (BLAS with its default threads, BLAS with one thread, textbook NumPy).")


def contention_table(n_frames, rng, repeats):
    """svdt idle and with another process spinning on one core; before (BLAS threads as the
    library chooses) and now (the package's one BLAS thread)."""
    print(f"\nsvdt on {n_frames:,} frames x 4 markers, idle and with a competing process "
          "spinning on one core; median (min) of interleaved rounds")
    A, B = make_trial(n_frames, rng)
    controller = ThreadpoolController()
    cores = os.cpu_count() or 1

    def all_threads():  # svdt as it was: the BLAS products spread over every core
        with controller.limit(limits=cores, user_api="blas"):
            svdt.__wrapped__(A, B, order="row")

    methods = {"one BLAS thread (svdt now)": lambda: package_svdt(A, B),
               f"{cores} BLAS threads (before)": all_threads}
    idle = rounds(methods, repeats)
    with CompetingProcess():
        busy = rounds(methods, repeats)
    print(f"{'':>28} | {'idle':>19} | {'competing process':>19} | {'busy/idle':>9}")
    for name in methods:
        print(f"{name:>28} | {fmt_time(idle[name][0]):>9} ({fmt_time(idle[name][1]):>7}) | "
              f"{fmt_time(busy[name][0]):>9} ({fmt_time(busy[name][1]):>7}) | "
              f"{busy[name][0] / idle[name][0]:9.2f}")
    print("target: svdt now within 1.3x of its idle time under the competing process")


def paths_table(n_frames, rng, repeats):
    """svdt's two fitting paths on the same frames: the closed form (every frame of a
    4-marker cluster takes it) and the exact path (an SVD per frame on scaled markers,
    forced here by setting MOMENT_MATRIX_MAX_MARKERS to 0); then both at 16 to 512
    markers with 2^20 marker positions per call, against the closed form's work space.
    Keeps the two paths honest: the closed form must stay clearly faster, and the marker
    threshold is set by memory."""
    def run(A, B, threshold):
        saved = svdt_module.MOMENT_MATRIX_MAX_MARKERS
        svdt_module.MOMENT_MATRIX_MAX_MARKERS = threshold
        try:
            svdt(A, B, order="row")
        finally:
            svdt_module.MOMENT_MATRIX_MAX_MARKERS = saved

    print(f"\nsvdt's paths: closed form vs exact path (SVD on scaled markers); min of "
          f"{repeats} interleaved rounds")
    A, B = make_trial(n_frames, rng)
    t = rounds({"closed": lambda: run(A, B, 10**9), "exact": lambda: run(A, B, 0)}, repeats)
    print(f"{n_frames:,} frames x 4 markers: closed form {fmt_time(t['closed'][1])}, exact "
          f"path {fmt_time(t['exact'][1])}, exact/closed = {t['exact'][1] / t['closed'][1]:.1f}")
    for n in (16, 64, 128, 256, 512):
        frames = 2**20 // n
        A = rng.normal(scale=100.0, size=(n, 3))
        B = A[None] + rng.normal(size=(frames, n, 3))
        t = rounds({"closed": lambda: run(A, B, 10**9), "exact": lambda: run(A, B, 0)},
                   max(2, repeats // 2))
        workspace = (12 + 6 * n) * svdt_module.CHUNK_FRAMES * 8 / 1e6  # a long trial's
        print(f"{n:>4} markers x {frames:>6,} frames: closed {fmt_time(t['closed'][1])}, "
              f"exact {fmt_time(t['exact'][1])}, exact/closed "
              f"{t['exact'][1] / t['closed'][1]:.2f}; closed form's work space per block "
              f"of {svdt_module.CHUNK_FRAMES} frames {workspace:.0f} MB")
    print(f"svdt takes the exact path above MOMENT_MATRIX_MAX_MARKERS = "
          f"{svdt_module.MOMENT_MATRIX_MAX_MARKERS} markers")


def roma_row(n_frames, rng, repeats):
    """roma (PyTorch) rigid registration, when installed: another batched peer."""
    try:
        import roma
        import torch
    except ImportError:
        print("\nroma: not installed (pip install roma torch to add its row)")
        return
    A, B = make_trial(n_frames, rng)
    x = torch.from_numpy(np.broadcast_to(A, B.shape).copy())
    y = torch.from_numpy(B)
    t = rounds({"svdt": lambda: package_svdt(A, B),
                "roma": lambda: roma.rigid_points_registration(x, y)}, repeats)
    print(f"\nroma {roma.__version__} (torch {torch.__version__}) rigid_points_registration on "
          f"{n_frames:,} frames: {fmt_time(t['roma'][0])}; svdt {fmt_time(t['svdt'][0])}; "
          f"roma/svdt = {t['roma'][0] / t['svdt'][0]:.1f}")


def angles_table(n, rng):
    print(f"\nAngle functions on {n:,} rotations, against SciPy computing the same result "
          "from the same input (median (min) of 5 interleaved rounds)")
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
    print(f"{'bmc_functions':>24} | {'time':>17} | {'scipy':>38} | {'time':>17} | "
          f"{'ratio':>5} | {'max diff':>8}")
    for name, ours, scipy_name, theirs in rows:
        t = rounds({"ours": ours, "theirs": theirs}, 5)
        diff = np.abs(ours() - theirs()).max()
        print(f"{name:>24} | {fmt_time(t['ours'][0]):>8} ({fmt_time(t['ours'][1]):>6}) | "
              f"{scipy_name:>38} | {fmt_time(t['theirs'][0]):>8} "
              f"({fmt_time(t['theirs'][1]):>6}) | {t['ours'][0] / t['theirs'][0]:5.2f} | "
              f"{diff:8.1e}")
    t_euler_only = median_time(lambda: rotation.as_euler("ZXY"), repeats=3)
    print(f"(for reference: scipy's as_euler alone, from its stored quaternions: "
          f"{fmt_time(t_euler_only)})")
    print("ratio: bmc_functions time / scipy time (target: at most 2).")


def _benchmark_module(name):
    """Import benchmarks/<name>.py (beside this file), or None when it is absent."""
    import importlib
    here = str(Path(__file__).resolve().parent)
    if here not in sys.path:
        sys.path.insert(0, here)
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as error:
        if error.name != name:
            raise
        return None


def read_trc_rows(n_frames, rounds):
    """read_trc against pandas.read_csv on a generated 100-marker TRC file, each read in a
    fresh process for its peak memory (benchmarks/bench_read_trc.py)."""
    print(f"\nread_trc vs pandas.read_csv: 100 markers x {n_frames:,} frames, 0.5 % gaps; "
          f"each read in its own process, interleaved in {rounds} rounds")
    module = _benchmark_module("bench_read_trc")
    if module is None:
        print("  benchmarks/bench_read_trc.py not found: row left out")
        return
    module.print_rows(module.bench_read_trc(n_markers=100, n_frames=n_frames, rounds=rounds))
    print("  target: read_trc within 1.5x of read_csv's time and 2x its peak memory")


def lower_limb_rows(n_frames, repeats):
    """The lower-limb pipeline on one long trial (benchmarks/bench_lower_limb.py)."""
    print()
    module = _benchmark_module("bench_lower_limb")
    module.print_rows(module.bench_lower_limb(n_frames, repeats))


def archive_rows(n_trials, seconds, rounds):
    """An archive of trials: serial, processes, dask (benchmarks/bench_archive.py)."""
    module = _benchmark_module("bench_archive")
    module.print_rows(module.bench_archive(n_trials, seconds, rounds))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="N up to 10^5, loops up to 10^4, angle table on 10^5, a smaller "
                             "TRC file and archive, fewer repeats")
    args = parser.parse_args(argv)
    rng = np.random.default_rng(2024)
    print(machine_description())
    warnings.simplefilter("error", RuntimeWarning)  # no frame of these trials may fail
    if args.quick:
        svdt_table([1_000, 10_000, 100_000], 10_000, rng)
        contention_table(100_000, rng, 5)
        paths_table(100_000, rng, 3)
        roma_row(100_000, rng, 3)
        angles_table(100_000, rng)
        read_trc_rows(10_000, 2)
        lower_limb_rows(60_000, 3)
        archive_rows(40, 2.0, 2)
    else:
        svdt_table([1_000, 10_000, 100_000, 1_000_000], 100_000, rng)
        contention_table(1_000_000, rng, 7)
        paths_table(1_000_000, rng, 5)
        roma_row(1_000_000, rng, 3)
        angles_table(1_000_000, rng)
        read_trc_rows(100_000, 3)
        lower_limb_rows(60_000, 7)
        archive_rows(200, 5.0, 3)
    print(f"\nload average (1, 5, 15 min) at the end: "
          f"{', '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    sys.exit(main())
