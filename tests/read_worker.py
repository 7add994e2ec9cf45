"""Read many files in a child process, with a time and memory limit per read (fuzz tests).

A damaged file must never crash, hang or exhaust the process that reads it; to test that
without risking the test process, the reads run in a child Python process: it reads the
files one by one, writing each outcome as it goes, under an address-space limit
(``resource.RLIMIT_AS``) and a per-read time limit (``faulthandler``'s watchdog, which
ends the process even if a C library never returns). The parent restarts the child after
the file that ended it, so that one run covers every file.
"""

import faulthandler
import json
import os
import pickle
import resource
import subprocess
import sys
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _child(reader, list_file, out_file, timeout, memory):
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    sys.path.insert(0, str(ROOT))
    import bmc_functions

    read = getattr(bmc_functions, reader)
    paths = json.loads(Path(list_file).read_text())
    with open(out_file, "ab") as out:
        for i, path in enumerate(paths):  # loop over files
            print(i, flush=True)
            faulthandler.dump_traceback_later(timeout, exit=True)
            try:
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    df = read(path)
                record = ("ok", df.index.to_numpy(), list(df.attrs.get("frames", [])),
                          df.to_numpy(), list(df.columns), [str(w.message) for w in caught])
            except Exception as err:  # the parent checks the type and the message
                record = (type(err).__name__, str(err))
            faulthandler.cancel_dump_traceback_later()
            pickle.dump((i, record), out)
            out.flush()


def read_in_child(reader, paths, *, timeout=10.0, memory=3 * 2**30, folder):
    """Read `paths` with ``bmc_functions.<reader>`` in child processes.

    Returns one outcome per path: ``('ok', time, frames, values, columns, warnings)``,
    ``(exception type name, message)``, ``('crash', returncode, stderr)`` or
    ``('hang', timeout, stderr)``.
    """
    outcomes = [None] * len(paths)
    start = 0
    run = 0
    while start < len(paths):  # one child per crash, usually one in all
        run += 1
        list_file = Path(folder) / f"paths{run}.json"
        out_file = Path(folder) / f"out{run}.pickle"
        list_file.write_text(json.dumps([str(p) for p in paths[start:]]))
        code = (f"import sys; sys.path.insert(0, {str(ROOT / 'tests')!r}); "
                f"import read_worker; read_worker._child({reader!r}, {str(list_file)!r}, "
                f"{str(out_file)!r}, {timeout!r}, {memory!r})")
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              env={**os.environ, "PYTHONFAULTHANDLER": ""})
        done = set()
        if out_file.exists():
            with open(out_file, "rb") as out:
                while True:
                    try:
                        i, record = pickle.load(out)
                    except EOFError:
                        break
                    outcomes[start + i] = record
                    done.add(i)
        if proc.returncode == 0:
            break
        started = [int(line) for line in proc.stdout.split()]
        last = started[-1] if started else 0
        kind = "hang" if "Timeout" in proc.stderr else "crash"
        outcomes[start + last] = (kind, proc.returncode, proc.stderr[-2000:])
        start += last + 1
    return outcomes
