"""Benchmark of the functional joint centre and axis on 60-second trials at 100 Hz.

Run from the repository root:

    python benchmarks/bench_functional_joints.py            # 60 s trials, 7 repeats
    python benchmarks/bench_functional_joints.py --quick    # 15 s trials, 3 repeats

The trials come from the seeded generator of data/ (data/generate_functional_data.py):
four star arcs of the hip (6004 frames, 4 pelvis and 4 thigh markers) and six knee
flexion trials (6006 frames, 4 thigh and 4 shank markers), with soft-tissue artefact and
0.5 mm noise. It times functional_joint_centre, sphere_fit_centre and functional_axis
(svdt of both clusters, the range of motion, the least-squares fit, the per-frame output)
and reports the median and minimum wall time of the repeats and the load average. This is
a benchmark to read, not a test: timings vary with the machine and its load.
"""

import argparse
import os
import statistics
import time
import warnings

import numpy as np
from _timing import load_generator

from bmc_functions import functional_axis, functional_joint_centre, sphere_fit_centre


def concatenated(trials, *names):
    return [np.concatenate([np.stack(list(t[name].values()), axis=1) for t in trials])
            for name in names]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="15 s trials, 3 repeats")
    args = parser.parse_args()
    copies, repeats = (1, 3) if args.quick else ((4, 6), 7)
    hips, knees = (copies, copies) if isinstance(copies, int) else copies
    gen = load_generator("generate_functional_data")
    rng = np.random.default_rng(1)
    pelvis, thigh = concatenated([gen.hip_trial(rng) for _ in range(hips)], "pelvis", "thigh")
    thigh_k, shank = concatenated([gen.knee_trial(rng) for _ in range(knees)], "thigh",
                                  "shank")
    cases = [("functional_joint_centre", functional_joint_centre, pelvis, thigh),
             ("sphere_fit_centre", sphere_fit_centre, pelvis, thigh),
             ("functional_axis", functional_axis, thigh_k, shank)]
    print(f"load average: {os.getloadavg()[0]:.2f}")
    for name, function, m1, m2 in cases:
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                function(m1, m2)
            times.append(time.perf_counter() - start)
        print(f"{name:24s} {len(m1):6d} frames: median {statistics.median(times) * 1e3:7.1f} ms, "
              f"min {min(times) * 1e3:7.1f} ms")


if __name__ == "__main__":
    main()
