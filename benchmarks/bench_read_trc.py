"""Benchmark: read_trc against pandas.read_csv on a big TRC file (time and peak memory).

Generates a TRC file (default 100 markers x 100,000 frames, 0.5 % of the marker samples
missing, about 340 MB) in a temporary folder, then times

* ``read_trc(path)``, and
* ``pandas.read_csv`` on the same data rows (C engine, ``skiprows=6``, tab-separated),
  the floor: what parsing the numbers alone costs,

each in a fresh Python process (so that peak memory is that of one read), interleaved
in rounds. Peak memory is the child's maximum resident set size minus its resident set
size after the imports (what the read itself added). Prints one line per method
(median and min of the rounds) and the ratios. Run from the repository root::

    python benchmarks/bench_read_trc.py            # the 342 MB file, 3 rounds
    python benchmarks/bench_read_trc.py --frames 10000 --rounds 5

The lead's main benchmark calls :func:`bench_read_trc` and prints its rows.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))  # run from a checkout without installing

_CHILD = r"""
import json, sys, time
import numpy as np, pandas as pd
sys.path.insert(0, {root!r})
from bmc_functions import read_trc

def status_mb(key):  # VmRSS now, VmHWM the peak (both reset by exec, unlike ru_maxrss)
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1]) / 1024

method, path = sys.argv[1], sys.argv[2]
before = status_mb("VmRSS")
start = time.perf_counter()
if method == "read_trc":
    df = read_trc(path)
else:
    df = pd.read_csv(path, sep="\t", header=None, skiprows=6, dtype=np.float64)
elapsed = time.perf_counter() - start
peak = status_mb("VmHWM")
print(json.dumps({{"seconds": elapsed, "peak_mb": peak, "base_mb": before,
                  "shape": list(df.shape)}}))
"""


def write_big_trc(path, n_markers=100, n_frames=100_000, gap_fraction=0.005, seed=0):
    """Write a TRC file of random marker trajectories (mm) with missing samples."""
    from bmc_functions import write_trc

    rng = np.random.default_rng(seed)
    values = rng.uniform(-1500.0, 1500.0, (n_frames, n_markers, 3))
    gaps = rng.random((n_frames, n_markers)) < gap_fraction
    values[gaps] = np.nan
    columns = pd.MultiIndex.from_product([[f"M{k:03d}" for k in range(n_markers)],
                                          ["x", "y", "z"]], names=["marker", "coord"])
    df = pd.DataFrame(values.reshape(n_frames, 3 * n_markers), columns=columns,
                      index=pd.Index(np.arange(n_frames) / 100.0, name="time"))
    write_trc(df, path, rate=100.0, units="mm", float_format="%.6f")
    return path


def _run(method, path):
    child = _CHILD.format(root=str(ROOT))
    out = subprocess.run([sys.executable, "-c", child, method, str(path)],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def bench_read_trc(n_markers=100, n_frames=100_000, gap_fraction=0.005, rounds=3,
                   folder=None):
    """Time read_trc and pandas.read_csv on a generated TRC file; return a dict of rows.

    Each read runs in its own Python process; the methods alternate in `rounds` rounds.
    Returns ``{'file_mb': ..., 'read_trc': {...}, 'pandas.read_csv': {...}}`` where each
    method has ``median_s``, ``min_s``, ``peak_mb`` (max RSS of the child, MB) and
    ``added_mb`` (peak minus the RSS after the imports, the memory the read needed).
    """
    with tempfile.TemporaryDirectory(dir=folder) as tmp:
        path = write_big_trc(Path(tmp) / "big.trc", n_markers, n_frames, gap_fraction)
        size = os.path.getsize(path) / 2**20
        runs = {"read_trc": [], "pandas.read_csv": []}
        for _ in range(rounds):  # interleaved: a change of load hits both methods
            for method in runs:
                runs[method].append(_run(method, path))
    result = {"file_mb": size, "frames": n_frames, "markers": n_markers}
    for method, rows in runs.items():
        seconds = [row["seconds"] for row in rows]
        result[method] = {"median_s": float(np.median(seconds)), "min_s": min(seconds),
                          "peak_mb": max(row["peak_mb"] for row in rows),
                          "added_mb": max(row["peak_mb"] - row["base_mb"] for row in rows)}
    return result


def print_rows(result):
    print(f"TRC file: {result['markers']} markers x {result['frames']} frames, "
          f"{result['file_mb']:.0f} MB; load average {os.getloadavg()[0]:.2f}")
    for method in ("read_trc", "pandas.read_csv"):
        row = result[method]
        print(f"  {method:16s} median {row['median_s']:.2f} s  min {row['min_s']:.2f} s  "
              f"peak RSS {row['peak_mb']:.0f} MB (+{row['added_mb']:.0f} MB for the read)")
    a, b = result["read_trc"], result["pandas.read_csv"]
    print(f"  ratio read_trc / read_csv: time {a['median_s'] / b['median_s']:.2f}x "
          f"(min {a['min_s'] / b['min_s']:.2f}x), memory added "
          f"{a['added_mb'] / b['added_mb']:.2f}x, "
          f"peak RSS {a['peak_mb'] / b['peak_mb']:.2f}x")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markers", type=int, default=100)
    parser.add_argument("--frames", type=int, default=100_000)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    print_rows(bench_read_trc(args.markers, args.frames, rounds=args.rounds))
