"""Benchmark of plug_in_gait on a 10-minute trial (both legs, 100 Hz, 60,000 frames).

Run from the repository root:

    python benchmarks/bench_plug_in_gait.py            # 60,000 frames, 7 repeats
    python benchmarks/bench_plug_in_gait.py --quick    # 6,000 frames, 3 repeats

A second row times the same trial with Plug-in Gait FullBody's markers (the generator's
``upper_body=True``: 64 angles).

The trial is made with the seeded generator data/generate_plug_in_gait_data.py (the
Plug-in Gait marker set, 16 markers, walking at 1.3 m/s). It times ``model.angles(trial)``
(pelvis, Davis hip centres, chord knee and ankle centres, 9 segment frames, 26 angles and
the DataFrame) and reports the median and minimum wall time of the repeats, the median
process (CPU) time and the time per frame. The static processing (once per subject) is
timed separately. A benchmark to read, not a test: timings vary with the machine's load.
"""

import time

from _timing import (angles_line, angles_result, load_generator, machine_line,
                     time_angles, trial_size)

from bmc_functions import plug_in_gait


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


def main(argv=None):
    n_frames, repeats = trial_size(__doc__.splitlines()[0], argv)
    result = bench_plug_in_gait(n_frames, repeats)
    print_rows(result)
    full = bench_plug_in_gait(n_frames, repeats, upper_body=True)
    print_rows(full, "full body (FullBody markers: legs, trunk, head, arms)")
    print(f"  full body / lower body, process (CPU) time medians: "
          f"{full['cpu_median_s'] / result['cpu_median_s']:.2f}")
    result["full_body"] = full
    return result


if __name__ == "__main__":
    main()
