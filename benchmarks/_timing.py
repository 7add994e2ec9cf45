"""What the model benchmarks share (bench_lower_limb.py, bench_plug_in_gait.py,
bench_functional_joints.py, bench_archive.py): the repository on the import path, the
seeded data generators of data/, the timing of ``model.angles`` and the report lines.

Imported by the scripts of this folder as ``_timing`` (Python puts a script's folder on
the import path).
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


def load_generator(name):
    """The seeded data generator ``data/<name>.py`` as a module."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "data" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def trial_size(description, argv=None, kinetics=False):
    """(frames, repeats) from the command line: 60,000 and 7, or 6,000 and 3 with
    ``--quick``; with `kinetics`, (frames, repeats, only the kinetics row) and a
    ``--kinetics`` option."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--quick", action="store_true", help="6,000 frames, 3 repeats")
    if kinetics:
        parser.add_argument("--kinetics", action="store_true", help="the kinetics row only")
    args = parser.parse_args(argv)
    size = (6_000, 3) if args.quick else (60_000, 7)
    return (*size, args.kinetics) if kinetics else size


def time_angles(model, trial, repeats):
    """Time ``model.angles(trial)`` after one warm-up call: (wall times, process times,
    the angles of the last call)."""
    model.angles(trial)                      # warm-up
    times, cpu = [], []
    for _ in range(repeats):
        start, start_cpu = time.perf_counter(), time.process_time()
        angles = model.angles(trial)
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return times, cpu, angles


def angles_result(n_frames, rate, calibration, times, cpu, angles):
    """The result dict of a model benchmark: 'frames', 'rate', 'angles' (number of angle
    columns), 'repeats', 'calibration_s', 'median_s', 'min_s' (wall time of the repeats)
    and 'cpu_median_s' (process time)."""
    return {"frames": n_frames, "rate": rate, "angles": angles.shape[1],
            "repeats": len(times), "calibration_s": calibration,
            "median_s": float(np.median(times)), "min_s": float(np.min(times)),
            "cpu_median_s": float(np.median(cpu))}


def machine_line():
    """The processor, the number of CPUs and the load average (a loaded machine is slow)."""
    return (f"  machine: {platform.processor() or platform.machine()}, {os.cpu_count()} "
            f"CPUs, load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


def angles_line(result):
    """The line of the median and minimum time of ``model.angles`` and the time per frame."""
    return (f"  model.angles: median {result['median_s']:.3f} s, min {result['min_s']:.3f} s "
            f"over {result['repeats']} repeats; "
            f"{result['median_s'] / result['frames'] * 1e6:.2f} us per frame")
