"""Benchmark of plug_in_gait on a 10-minute trial (both legs, 100 Hz, 60,000 frames).

Run from the repository root:

    python benchmarks/bench_plug_in_gait.py            # 60,000 frames, 7 repeats
    python benchmarks/bench_plug_in_gait.py --quick    # 6,000 frames, 3 repeats

The trial is made with the seeded generator data/generate_plug_in_gait_data.py (the
Plug-in Gait marker set, 16 markers, walking at 1.3 m/s). It times ``model.angles(trial)``
(pelvis, Davis hip centres, chord knee and ankle centres, 9 segment frames, 26 angles and
the DataFrame) and reports the median and minimum wall time of the repeats, the median
process (CPU) time and the time per frame. The static processing (once per subject) is
timed separately. A benchmark to read, not a test: timings vary with the machine's load.
"""

import argparse
import importlib.util
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))  # run from a checkout without installing

from bmc_functions import plug_in_gait  # noqa: E402


def load_generator():
    spec = importlib.util.spec_from_file_location(
        "generate_plug_in_gait_data", ROOT / "data" / "generate_plug_in_gait_data.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def bench_plug_in_gait(n_frames=60_000, repeats=7):
    """Time the static processing and ``model.angles`` on one generated trial; a dict."""
    gen = load_generator()
    static, _, _ = gen.make_trial(50, static=True)
    trial, _, _ = gen.make_trial(n_frames)
    subject = {k: v for k, v in gen.SUBJECT.items() if "Static" not in k}

    start = time.perf_counter()
    model = plug_in_gait(static, subject)
    calibration = time.perf_counter() - start

    model.angles(trial)                      # warm-up
    times, cpu = [], []
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
    n_frames, rate = result["frames"], result["rate"]
    print(f"plug_in_gait, {n_frames:,} frames ({n_frames / rate / 60:.1f} min at "
          f"{rate:g} Hz), both legs, {result['angles']} angles")
    print(f"  machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
          f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(f"  static processing (once per subject): {result['calibration_s'] * 1e3:.1f} ms")
    print(f"  model.angles: median {result['median_s']:.3f} s, min {result['min_s']:.3f} s "
          f"over {result['repeats']} repeats; "
          f"{result['median_s'] / n_frames * 1e6:.2f} us per frame")
    print(f"  process (CPU) time: median {result['cpu_median_s']:.3f} s")
    print(f"  target for 60,000 frames: under 1 s (median / target = "
          f"{result['median_s'] / 1.0 * 60_000 / n_frames:.2f}, scaled to 60,000 frames)")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="6,000 frames, 3 repeats")
    args = parser.parse_args(argv)
    n_frames, repeats = (6_000, 3) if args.quick else (60_000, 7)
    result = bench_plug_in_gait(n_frames, repeats)
    print_rows(result)
    return result


if __name__ == "__main__":
    main()
