"""Benchmark of Plug-in Gait's marker checks on a 10-minute FullBody trial (60,000 frames).

Run from the repository root:

    python benchmarks/bench_plug_in_gait_checks.py            # 60,000 frames, 7 repeats
    python benchmarks/bench_plug_in_gait_checks.py --quick    # 6,000 frames, 3 repeats

Times, on the same points, the upper-body checks (``upper_body_checks``: the marker order,
far and jumping markers, the chords' offsets), the leg checks (``checks``) and the whole
``model.angles(trial)`` call, and reports each check's share of the call: a ratio, which a
loaded machine changes less than the times. The trial is made with the seeded generator
data/generate_plug_in_gait_data.py (``upper_body=True``). A benchmark to read, not a test.
"""

import time
import warnings

import numpy as np
from _timing import load_generator, machine_line, trial_size

from bmc_functions import plug_in_gait


def bench_checks(n_frames=60_000, repeats=7):
    """Median wall times (s) of the upper-body checks, the leg checks and the angles."""
    gen = load_generator("generate_plug_in_gait_data")
    static, _, _ = gen.make_trial(50, static=True, upper_body=True)
    trial, _, _ = gen.make_trial(n_frames, upper_body=True)
    subject = {k: v for k, v in gen.SUBJECT.items() if "Static" not in k}
    model = plug_in_gait(static, subject)
    times = {"upper": [], "legs": [], "angles": []}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _, points, _ = model._landmarks(trial, "dynamic")
        for _ in range(repeats):
            copy = {k: v.copy() for k, v in points.items()}
            start = time.perf_counter()
            model._check_upper_body_markers(copy, "trial")
            times["upper"].append(time.perf_counter() - start)
            copy = {k: v.copy() for k, v in points.items()}
            start = time.perf_counter()
            model._check_leg_markers(copy, "trial", "dynamic")
            times["legs"].append(time.perf_counter() - start)
            start = time.perf_counter()
            model.angles(trial)
            times["angles"].append(time.perf_counter() - start)
    return {key: float(np.median(value)) for key, value in times.items()}


def main(argv=None):
    n_frames, repeats = trial_size(__doc__.splitlines()[0], argv)
    result = bench_checks(n_frames, repeats)
    print(f"Plug-in Gait checks, {n_frames:,} frames (FullBody), medians of {repeats}")
    print(machine_line())
    for key, what in (("upper", "upper-body checks"), ("legs", "leg checks")):
        print(f"  {what}: {result[key]:.3f} s, {result[key] / result['angles']:.1%} of "
              f"model.angles ({result['angles']:.3f} s)")
    return result


if __name__ == "__main__":
    main()
