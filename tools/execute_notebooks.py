"""Run notebooks top to bottom and store their outputs, as nbval will compare them.

Usage (from the repository root)::

    python tools/execute_notebooks.py notebooks/01_rotation_matrices.ipynb [...]
    python tools/execute_notebooks.py            # every notebook in notebooks/

Each notebook runs in a fresh kernel of the current environment with the working
directory set to notebooks/, exactly as nbval runs it, and is saved in place.
"""

import pathlib
import sys
import time

import nbclient
import nbformat

ROOT = pathlib.Path(__file__).resolve().parents[1]


def execute(path):
    path = pathlib.Path(path).resolve()
    nb = nbformat.read(path, as_version=4)
    start = time.perf_counter()
    client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(path.parent)}})
    client.execute()
    nbformat.write(nb, path)
    print(f"{path.relative_to(ROOT)}: {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    paths = sys.argv[1:] or sorted((ROOT / "notebooks").glob("*.ipynb"))
    for p in paths:
        execute(p)
