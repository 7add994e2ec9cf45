"""Benchmark of a lab's archive: lower-limb angles of many trials, serial and in parallel.

Run from the repository root:

    python benchmarks/bench_archive.py            # 200 trials of 5 s (500 frames), 3 rounds
    python benchmarks/bench_archive.py --quick    # 40 trials of 2 s, 2 rounds
    python benchmarks/bench_archive.py --trials 100 --seconds 10 --rounds 2

It writes an archive in a temporary folder (deleted at the end, never kept): the static
trial of data/markers/ and N walking trials made with the seeded generator of data/
(data/generate_marker_data.py, through benchmarks/bench_lower_limb.py's ``long_trial``:
both legs, 23 markers, soft-tissue artefact and noise; trial k has seed k, so every trial
differs), as TRC files at 100 Hz. Then it times the whole call a user makes,

    lower_limb_angles("static.trc", [paths...], markers, workers=..., client=...)

(read every file, calibrate once, track, angles, one long DataFrame) in three ways:

- serial: one trial after another in this process;
- 2 processes: ``workers=2`` (a process pool, one BLAS thread per worker, forked from
  a clean server process that imported the package once: the first call of a session
  pays about a second for it, which a warm-up run takes here; the pool's start-up,
  tens of ms, is part of every call);
- dask: ``client=`` a dask.distributed LocalCluster of 2 worker processes with one thread
  each (started once; its start-up time is printed apart).

Two phases, each timing its ways interleaved in rounds (a change of load hits both
alike): serial and 2 processes; then, with the cluster running, serial again and dask.
The cluster's scheduler runs in this process and its workers keep a heartbeat, which
slows everything a little, so each parallel way is compared with the serial run timed
beside it.

It checks that the three results are identical and prints, per way, the median and the
min of the rounds, trials per second and frames per second (from the median), and the
speed-up over serial. On a machine with 2 cores the ideal speed-up is 2; the load average
printed first says how much of the machine was free. This is a benchmark to read, not a
test: timings vary with the machine and its load.
"""

import argparse
import functools
import os
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from _timing import load_generator  # (puts the repository on the import path)
from bench_lower_limb import long_trial, markers_of_the_synthetic_subject

from bmc_functions import lower_limb_angles, write_trc


def write_archive(folder, n_trials, seconds):
    """Write static.trc and n_trials walking trials (walk_001.trc ...) into `folder`.

    Returns (static path, list of trial paths, total frames of the trials, frame rate).
    """
    gen = load_generator("generate_marker_data")
    folder = Path(folder)
    static = folder / "static.trc"
    write_trc(gen.make_trials()["static"], static)
    n_frames = int(round(seconds * gen.RATE))
    paths = []
    for k in range(1, n_trials + 1):
        path = folder / f"walk_{k:03d}.trc"
        write_trc(long_trial(gen, n_frames, seed=k), path, float_format="%.4f")
        paths.append(path)
    return static, paths, n_trials * n_frames, gen.RATE


def _blas_threads_of_workers(client):
    from threadpoolctl import threadpool_info

    def blas():
        return sorted({lib["num_threads"] for lib in threadpool_info()
                       if lib["user_api"] == "blas"})

    return sorted({tuple(threads) for threads in client.run(blas).values()})


def _interleaved(ways, rounds, reference):
    """Time each way once per round, in turn; every result must equal `reference`."""
    for way in ways.values():            # warm-up: imports, the process server
        pd.testing.assert_frame_equal(way(), reference)
    times = {name: [] for name in ways}
    for _ in range(rounds):
        for name, way in ways.items():
            start = time.perf_counter()
            out = way()
            times[name].append(time.perf_counter() - start)
            pd.testing.assert_frame_equal(out, reference)  # the same angles
    return {name: {"median_s": float(np.median(t)), "min_s": float(np.min(t))}
            for name, t in times.items()}


def bench_archive(n_trials=200, seconds=5.0, rounds=3, workers=2, folder=None):
    """Time lower_limb_angles over a generated archive: serial, processes, dask.

    Two phases, each interleaving its ways in `rounds` rounds: serial and `workers`
    processes; then, with a dask LocalCluster running, serial again and dask (the
    cluster's scheduler runs in this process and its workers keep a heartbeat, which
    slows everything a little: each parallel way is compared with the serial run timed
    beside it). Returns a dict: 'trials', 'frames' (total), 'rate', 'file_mb',
    'cluster_start_s', 'worker_blas' (the BLAS thread counts in the dask workers),
    'rows' (a list of (way, {'median_s', 'min_s'}, serial median beside it)).
    """
    markers = markers_of_the_synthetic_subject()
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        Client = LocalCluster = None
    with tempfile.TemporaryDirectory(dir=folder) as tmp, warnings.catch_warnings():
        # the artefact makes the thigh clusters deform in some frames: warnings expected
        warnings.simplefilter("ignore", RuntimeWarning)
        static, paths, frames, rate = write_archive(tmp, n_trials, seconds)
        file_mb = sum(p.stat().st_size for p in paths) / 2**20

        def run(**how):
            return lower_limb_angles(static, paths, markers, progress=False, **how)

        result = {"trials": n_trials, "frames": frames, "seconds_per_trial": seconds,
                  "rate": rate, "file_mb": file_mb, "workers": workers,
                  "cluster_start_s": None, "worker_blas": None, "rows": []}
        reference = run()
        local = f"{workers} processes"
        t = _interleaved({"serial": run, local: lambda: run(workers=workers)}, rounds,
                         reference)
        result["rows"] += [("serial", t["serial"], t["serial"]["median_s"]),
                           (local, t[local], t["serial"]["median_s"])]
        if LocalCluster is None:
            return result
        start = time.perf_counter()
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          dashboard_address=None, silence_logs=50) as cluster, \
                Client(cluster) as client:
            # the workers' own warnings (the same artefact) are switched off there too
            client.run(functools.partial(warnings.filterwarnings, "ignore",
                                         category=RuntimeWarning))
            result["cluster_start_s"] = time.perf_counter() - start
            result["worker_blas"] = _blas_threads_of_workers(client)
            name = f"dask LocalCluster ({workers}x1)"
            t = _interleaved({"serial, cluster up": run, name: lambda: run(client=client)},
                             rounds, reference)
        result["rows"] += [("serial, cluster up", t["serial, cluster up"],
                            t["serial, cluster up"]["median_s"]),
                           (name, t[name], t["serial, cluster up"]["median_s"])]
    return result


def print_rows(result):
    """Print the archive table from :func:`bench_archive`'s result."""
    n, frames = result["trials"], result["frames"]
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "?"
    print(f"\nArchive: lower_limb_angles over {n} trials of {result['seconds_per_trial']:g} s "
          f"({frames:,} frames at {result['rate']:g} Hz, both legs, "
          f"{result['file_mb']:.0f} MB of TRC); {os.cpu_count()} CPUs, load average now {load}")
    if result["cluster_start_s"] is not None:
        print(f"  dask LocalCluster ({result['workers']} worker processes x 1 thread) started "
              f"in {result['cluster_start_s']:.1f} s; BLAS threads in its workers: "
              f"{', '.join(str(list(t)) for t in result['worker_blas'])}")
    else:
        print("  dask.distributed not installed (pip install 'bmc_functions[dask]' for its row)")
    print(f"{'':>24} | {'median (min)':>19} | {'trials/s':>8} | {'frames/s':>9} | "
          f"{'speed-up':>8}")
    for name, t, serial in result["rows"]:
        median, low = t["median_s"], t["min_s"]
        print(f"{name:>24} | {median:7.2f} s ({low:5.2f} s) | {n / median:8.1f} | "
              f"{frames / median:9,.0f} | {serial / median:7.2f}x")
    print("every way gave the same DataFrame; speed-up: median of the serial run timed beside "
          "it / median (ideal: the number of free cores)")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="40 trials of 2 s, 2 rounds")
    parser.add_argument("--trials", type=int, help="number of trials (default 200)")
    parser.add_argument("--seconds", type=float, help="length of each trial (default 5 s)")
    parser.add_argument("--rounds", type=int, help="interleaved rounds (default 3)")
    parser.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    args = parser.parse_args(argv)
    trials, seconds, rounds = (40, 2.0, 2) if args.quick else (200, 5.0, 3)
    result = bench_archive(args.trials or trials, args.seconds or seconds,
                           args.rounds or rounds, args.workers)
    print_rows(result)
    return result


if __name__ == "__main__":
    main()
