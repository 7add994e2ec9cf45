"""Benchmark of the lower-limb pipeline on a 10-minute trial (both legs, 100 Hz).

Run from the repository root:

    python benchmarks/bench_lower_limb.py            # 60,000 frames, 7 repeats
    python benchmarks/bench_lower_limb.py --quick    # 6,000 frames, 3 repeats

The trial is made with the seeded generator of data/ (data/generate_marker_data.py): ten
minutes of walking, both legs, with the soft-tissue artefact and 0.5 mm noise, 23 markers
(pelvis, thigh and shank clusters, heel, toe and MT5 of both feet) tracked with the
static trial of data/markers/. It times ``model.angles(trial)`` (svdt for 5 clusters,
landmarks, 7 segment frames, 24 angles, the checks and the DataFrame) and reports the
median and the minimum of the repeats (wall time) and the median process (CPU) time, the
time per frame, the load average and the BLAS
thread settings. Calibration (once per subject) is timed separately. This is a benchmark
to read, not a test: timings vary with the machine and its load.
"""

import argparse
import os
import platform
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))  # run from a checkout without installing

from bmc_functions import calibrate_lower_limb  # noqa: E402
from bmc_functions.files.trc import read_trc  # noqa: E402


def load_generator():
    import importlib.util
    spec = importlib.util.spec_from_file_location(
        "generate_marker_data", ROOT / "data" / "generate_marker_data.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def markers_of_the_synthetic_subject():
    markers = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
               "PELVIS": ["PEL1", "PEL2", "PEL3"]}
    for p in "RL":
        markers.update({p + "THIGH": [p + "TH1", p + "TH2", p + "TH3", p + "TH4"],
                        p + "SHANK": [p + "TB1", p + "TB2", p + "TB3"],
                        p + "KNEE_LAT": p + "LFC", p + "KNEE_MED": p + "MFC",
                        p + "ANKLE_LAT": p + "LMAL", p + "ANKLE_MED": p + "MMAL",
                        p + "HEEL": p + "HEEL", p + "TOE": p + "TOE", p + "MT5": p + "MT5"})
    return markers


def long_trial(gen, n_frames, seed=1):
    """A walking trial of n_frames at gen.RATE with both legs, artefact and noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n_frames) / gen.RATE
    s = t / gen.STRIDE_TIME
    legs = {"right": gen.leg_angles(s), "left": gen.leg_angles(s + 0.5)}
    # a treadmill: the pelvis stays near the origin
    origin = np.column_stack([np.zeros_like(t), 930.0 - 12.0 * np.cos(4 * np.pi * s),
                              10.0 * np.sin(2 * np.pi * s)])
    _, reference = gen.static_angles(1)
    poses = gen.segment_poses(gen.pelvis_angles(s), origin, legs)
    points = gen.marker_positions(poses, gen.soft_tissue_artefact(rng, legs, reference))
    clusters, _, feet = gen.marker_names()
    for name in clusters + feet:
        points[name] = points[name] + rng.normal(0.0, gen.NOISE_SD, points[name].shape)
    return gen._to_frame(points, clusters + feet, t)


def bench_lower_limb(n_frames=60_000, repeats=7):
    """Time calibration and ``model.angles`` on one long generated trial; return a dict.

    Keys: 'frames', 'rate', 'angles' (number of angle columns), 'calibration_s',
    'median_s', 'min_s' (wall time of the repeats) and 'cpu_median_s' (process time).
    """
    gen = load_generator()
    static = read_trc(ROOT / "data" / "markers" / "static.trc")
    trial = long_trial(gen, n_frames)
    markers = markers_of_the_synthetic_subject()

    start = time.perf_counter()
    model = calibrate_lower_limb(static, markers)
    calibration = time.perf_counter() - start

    times, cpu = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        model.angles(trial)                      # warm-up
        for _ in range(repeats):
            start, start_cpu = time.perf_counter(), time.process_time()
            angles = model.angles(trial)
            times.append(time.perf_counter() - start)
            cpu.append(time.process_time() - start_cpu)
    return {"frames": n_frames, "rate": gen.RATE, "angles": angles.shape[1],
            "repeats": repeats, "calibration_s": calibration,
            "median_s": float(np.median(times)), "min_s": float(np.min(times)),
            "cpu_median_s": float(np.median(cpu))}


def print_rows(result):
    """Print the lines of :func:`bench_lower_limb`'s result."""
    n_frames, rate = result["frames"], result["rate"]
    print(f"lower-limb pipeline, {n_frames:,} frames ({n_frames / rate / 60:.1f} min at "
          f"{rate:g} Hz), both legs, {result['angles']} angles")
    print(f"  machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
          f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    try:
        from threadpoolctl import threadpool_info
        blas = [f"{i['internal_api']} {i['num_threads']} threads" for i in threadpool_info()]
        print(f"  BLAS: {', '.join(blas) or 'none found'} (model.angles limits itself to 1)")
    except ImportError:
        print("  BLAS: threadpoolctl not installed")
    print(f"  calibration (static trial, once per subject): "
          f"{result['calibration_s'] * 1e3:.1f} ms")
    print(f"  model.angles: median {result['median_s']:.3f} s, min {result['min_s']:.3f} s "
          f"over {result['repeats']} repeats; "
          f"{result['median_s'] / n_frames * 1e6:.2f} us per frame")
    print(f"  process (CPU) time: median {result['cpu_median_s']:.3f} s (wall time above it "
          f"means the process waited for a core: the machine is loaded)")
    print("  target for 60,000 frames: under 1 s")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="6,000 frames, 3 repeats")
    args = parser.parse_args(argv)
    n_frames, repeats = (6_000, 3) if args.quick else (60_000, 7)
    result = bench_lower_limb(n_frames, repeats)
    print_rows(result)
    return result


if __name__ == "__main__":
    main()
