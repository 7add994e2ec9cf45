"""Benchmark of the lower-limb pipeline on a 10-minute trial (both legs, 100 Hz).

Run from the repository root:

    python benchmarks/bench_lower_limb.py            # 60,000 frames, 7 repeats
    python benchmarks/bench_lower_limb.py --quick    # 6,000 frames, 3 repeats
    python benchmarks/bench_lower_limb.py --kinetics # the kinetics row only

The trial is made with the seeded generator of data/ (data/generate_marker_data.py): ten
minutes of walking, both legs, with the soft-tissue artefact and 0.5 mm noise, 23 markers
(pelvis, thigh and shank clusters, heel, toe and MT5 of both feet) tracked with the
static trial of data/markers/. It times ``model.angles(trial)`` (svdt for 5 clusters,
landmarks, 7 segment frames, 24 angles, the checks and the DataFrame) and reports the
median and the minimum of the repeats (wall time) and the median process (CPU) time, the
time per frame, the load average and the BLAS
thread settings. Calibration (once per subject) is timed separately. The kinetics row
times ``model.kinetics(trial, loads, body_mass=70)`` on the same trial with ground loads at
1000 Hz (one per foot, an OpenSim external-loads table: 700 N under the heel-toe midpoint
in the first 60 % of each stride): marker and load filtering, tracking, load assignment, two
three-segment Newton-Euler chains and the DataFrame. This is a benchmark to read, not a
test: timings vary with the machine and its load.
"""

import time
import warnings

import numpy as np
import pandas as pd
from _timing import (ROOT, angles_line, angles_result, load_generator, machine_line,
                     time_angles, trial_size)

from bmc_functions import calibrate_lower_limb
from bmc_functions.files.trc import read_trc


def markers_of_the_synthetic_subject():
    """Role -> label of the generated two-leg trials (data/generate_marker_data.py)."""
    return load_generator("generate_marker_data").marker_roles()


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
    """Time calibration and ``model.angles`` on one long generated trial; a dict (see
    ``_timing.angles_result``)."""
    gen = load_generator("generate_marker_data")
    static = read_trc(ROOT / "data" / "markers" / "static.trc")
    trial = long_trial(gen, n_frames)
    markers = markers_of_the_synthetic_subject()

    start = time.perf_counter()
    model = calibrate_lower_limb(static, markers)
    calibration = time.perf_counter() - start
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        timed = time_angles(model, trial, repeats)
    return angles_result(n_frames, gen.RATE, calibration, *timed)


def ground_loads(gen, trial, force_rate=1000.0):
    """An external-loads table (OpenSim columns, N and m, y up) for the generated walk:
    per foot 700 N up at the heel-toe midpoint on the floor during its stance (the first
    60 % of its stride, right heel strike at the generator's phase 0, left at 0.5)."""
    rate = trial.attrs["rate"]
    time = np.arange(int(len(trial) * force_rate / rate)) / force_rate
    frame = np.minimum((time * rate).astype(int), len(trial) - 1)
    table = {}
    for p, phase in (("R", 0.0), ("L", 0.5)):
        heel, toe = trial[p + "HEEL"].to_numpy(), trial[p + "TOE"].to_numpy()
        down = (time / gen.STRIDE_TIME + phase) % 1.0 < 0.6
        cop = ((heel + toe) / 2000.0)[frame] * [1, 0, 1]
        for k, axis in enumerate("xyz"):
            table[f"{p}_ground_force_v{axis}"] = 700.0 * down * (axis == "y")
            table[f"{p}_ground_force_p{axis}"] = cop[:, k]
            table[f"{p}_ground_torque_{axis}"] = np.zeros(len(time))
    return pd.DataFrame(table, index=pd.Index(time + trial.index[0], name="time"))


def bench_kinetics(n_frames=60_000, repeats=7):
    """Time ``model.kinetics`` on the long generated trial; a dict like
    :func:`bench_lower_limb`'s."""
    gen = load_generator("generate_marker_data")
    static = read_trc(ROOT / "data" / "markers" / "static.trc")
    trial = long_trial(gen, n_frames)
    model = calibrate_lower_limb(static, markers_of_the_synthetic_subject())
    loads = ground_loads(gen, trial)
    times, cpu = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        model.kinetics(trial, loads, body_mass=70.0)                  # warm-up
        for _ in range(repeats):
            start, start_cpu = time.perf_counter(), time.process_time()
            kinetics = model.kinetics(trial, loads, body_mass=70.0)
            times.append(time.perf_counter() - start)
            cpu.append(time.process_time() - start_cpu)
    assigned = sum(a["side"] is not None for a in kinetics.attrs["load_assignment"])
    return {"frames": n_frames, "rate": gen.RATE, "repeats": repeats, "assigned": assigned,
            "nan": float(kinetics.isna().to_numpy().mean()),
            "median_s": float(np.median(times)), "min_s": float(np.min(times)),
            "cpu_median_s": float(np.median(cpu))}


def print_kinetics(result):
    n_frames = result["frames"]
    print(f"lower-limb kinetics, {n_frames:,} frames ({n_frames / result['rate'] / 60:.1f} "
          f"min), both legs, ground loads at 1000 Hz ({result['assigned']} stances "
          f"assigned, {100 * result['nan']:.1f} % NaN)")
    print(machine_line())
    print(f"  model.kinetics: median {result['median_s']:.3f} s, min {result['min_s']:.3f} s "
          f"over {result['repeats']} repeats; process (CPU) time median "
          f"{result['cpu_median_s']:.3f} s; {result['median_s'] / n_frames * 1e6:.2f} us "
          f"per frame")
    print("  target for 60,000 frames: under 1 s")


def print_rows(result):
    """Print the lines of :func:`bench_lower_limb`'s result."""
    n_frames, rate = result["frames"], result["rate"]
    print(f"lower-limb pipeline, {n_frames:,} frames ({n_frames / rate / 60:.1f} min at "
          f"{rate:g} Hz), both legs, {result['angles']} angles")
    print(machine_line())
    try:
        from threadpoolctl import threadpool_info
        blas = [f"{i['internal_api']} {i['num_threads']} threads" for i in threadpool_info()]
        print(f"  BLAS: {', '.join(blas) or 'none found'} (model.angles limits itself to 1)")
    except ImportError:
        print("  BLAS: threadpoolctl not installed")
    print(f"  calibration (static trial, once per subject): "
          f"{result['calibration_s'] * 1e3:.1f} ms")
    print(angles_line(result))
    print(f"  process (CPU) time: median {result['cpu_median_s']:.3f} s (wall time above it "
          f"means the process waited for a core: the machine is loaded)")
    print("  target for 60,000 frames: under 1 s")


def main(argv=None):
    n_frames, repeats, only_kinetics = trial_size(__doc__.splitlines()[0], argv,
                                                  kinetics=True)
    result = {}
    if not only_kinetics:
        result = bench_lower_limb(n_frames, repeats)
        print_rows(result)
    result["kinetics"] = bench_kinetics(n_frames, repeats)
    print_kinetics(result["kinetics"])
    if not only_kinetics:                     # the two rows of this run side by side
        print(f"  kinetics / angles, process (CPU) time medians: "
              f"{result['kinetics']['cpu_median_s'] / result['cpu_median_s']:.2f}")
    return result


if __name__ == "__main__":
    main()
