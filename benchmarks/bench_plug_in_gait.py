"""Benchmark of plug_in_gait on a 10-minute trial (both legs, 100 Hz, 60,000 frames).

Run from the repository root:

    python benchmarks/bench_plug_in_gait.py            # 60,000 frames, 7 repeats
    python benchmarks/bench_plug_in_gait.py --quick    # 6,000 frames, 3 repeats
    python benchmarks/bench_plug_in_gait.py --kinetics # the kinetics row only

A second row times the same trial with Plug-in Gait FullBody's markers (the generator's
``upper_body=True``: 64 angles).

The trial is made with the seeded generator data/generate_plug_in_gait_data.py (the
Plug-in Gait marker set, 16 markers, walking at 1.3 m/s). It times ``model.angles(trial)``
(pelvis, Davis hip centres, chord knee and ankle centres, 9 segment frames, 26 angles and
the DataFrame) and reports the median and minimum wall time of the repeats, the median
process (CPU) time and the time per frame. The static processing (once per subject) is
timed separately. A benchmark to read, not a test: timings vary with the machine's load.

The kinetics row times ``model.kinetics(trial, force_plates=plates)`` (plate assignment,
resampling, Newton-Euler of both legs, Vicon's powers) on the same duration of a real
trial: the package's example stair descent (Vicon Nexus, 2.7 s at 120 Hz, four plates at
1080 Hz) played forwards and backwards, copy after copy, markers and plates alike
(continuous, about three plate contacts a second, as on an instrumented treadmill).
"""

import time
import warnings

import numpy as np
import pandas as pd
from _timing import (angles_line, angles_result, load_generator, machine_line,
                     time_angles, trial_size)

from bmc_functions import plug_in_gait, read_c3d, read_force_plates
from bmc_functions.examples import example_file


def bench_plug_in_gait(n_frames=60_000, repeats=7, upper_body=False):
    """Time the static processing and ``model.angles`` on one generated trial (with the
    FullBody markers when `upper_body`); a dict (see ``_timing.angles_result``)."""
    gen = load_generator("generate_plug_in_gait_data")
    static, _, _ = gen.make_trial(50, static=True, upper_body=upper_body)
    trial, _, _ = gen.make_trial(n_frames, upper_body=upper_body)
    subject = {k: v for k, v in gen.SUBJECT.items() if "Static" not in k}

    start = time.perf_counter()
    model = plug_in_gait(static, subject)
    calibration = time.perf_counter() - start
    return angles_result(n_frames, gen.RATE, calibration, *time_angles(model, trial, repeats))


def print_rows(result, what="both legs"):
    n_frames, rate = result["frames"], result["rate"]
    print(f"plug_in_gait, {n_frames:,} frames ({n_frames / rate / 60:.1f} min at "
          f"{rate:g} Hz), {what}, {result['angles']} angles")
    print(machine_line())
    print(f"  static processing (once per subject): {result['calibration_s'] * 1e3:.1f} ms")
    print(angles_line(result))
    print(f"  process (CPU) time: median {result['cpu_median_s']:.3f} s")
    print(f"  target for 60,000 frames: under 1 s (process time median / target = "
          f"{result['cpu_median_s'] / 1.0 * 60_000 / n_frames:.2f}, scaled to 60,000 "
          f"frames)")


def back_and_forth(table, copies, rate):
    """`table` played forwards, backwards, forwards... `copies` times, on a new time axis
    at `rate` (Hz), with its attrs."""
    values = table.to_numpy()
    longer = pd.DataFrame(np.concatenate([values[::(-1) ** k] for k in range(copies)]),
                          columns=table.columns)
    longer.index = pd.Index(np.arange(len(longer)) / rate, name="time")
    longer.attrs = dict(table.attrs)
    return longer


def bench_kinetics(minutes=10.0, repeats=7):
    """Time ``model.kinetics`` on the example stair descent made `minutes` long; a dict
    like :func:`bench_plug_in_gait`'s, with 'contacts' (plate contacts in the trial)."""
    path = example_file("plug_in_gait/Movement_trial.c3d")
    model = plug_in_gait(example_file("plug_in_gait/Static_trial.c3d"),
                         example_file("plug_in_gait/Test.vsk"))
    markers, plates = read_c3d(path), read_force_plates(path)
    rate = markers.attrs["rate"]
    copies = int(np.ceil(minutes * 60.0 * rate / len(markers)))
    trial = back_and_forth(markers, copies, rate)
    plates = back_and_forth(plates, copies, plates.attrs["rate"])
    times, cpu = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        model.kinetics(trial, force_plates=plates)                        # warm-up
        for _ in range(repeats):
            start, start_cpu = time.perf_counter(), time.process_time()
            kinetics = model.kinetics(trial, force_plates=plates)
            times.append(time.perf_counter() - start)
            cpu.append(time.process_time() - start_cpu)
    return {"frames": len(trial), "rate": rate, "repeats": repeats,
            "contacts": len(kinetics.attrs["plates"]),
            "median_s": float(np.median(times)), "min_s": float(np.min(times)),
            "cpu_median_s": float(np.median(cpu))}


def print_kinetics(result):
    n_frames, rate = result["frames"], result["rate"]
    print(f"plug_in_gait kinetics, {n_frames:,} frames ({n_frames / rate / 60:.1f} min at "
          f"{rate:g} Hz), both legs, four plates at 1080 Hz ({result['contacts']} contacts)")
    print(machine_line())
    print(f"  model.kinetics: median {result['median_s']:.3f} s, min {result['min_s']:.3f} s "
          f"over {result['repeats']} repeats; process (CPU) time median "
          f"{result['cpu_median_s']:.3f} s")
    print("  target for a 10-minute trial: under 1 s")


def main(argv=None):
    n_frames, repeats, only_kinetics = trial_size(__doc__.splitlines()[0], argv,
                                                  kinetics=True)
    result = {}
    if not only_kinetics:
        result = bench_plug_in_gait(n_frames, repeats)
        print_rows(result)
        full = bench_plug_in_gait(n_frames, repeats, upper_body=True)
        print_rows(full, "full body (FullBody markers: legs, trunk, head, arms)")
        print(f"  full body / lower body, process (CPU) time medians: "
              f"{full['cpu_median_s'] / result['cpu_median_s']:.2f}")
        result["full_body"] = full
    # 60,000 frames stand for 10 minutes (at 100 Hz), --quick's 6,000 for one
    result["kinetics"] = bench_kinetics(n_frames / 6000.0, repeats)
    print_kinetics(result["kinetics"])
    if not only_kinetics:
        print(f"  kinetics / full-body angles, process (CPU) time medians: "
              f"{result['kinetics']['cpu_median_s'] / full['cpu_median_s']:.2f}")
    return result


if __name__ == "__main__":
    main()
