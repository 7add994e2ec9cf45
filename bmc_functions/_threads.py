"""One BLAS thread inside the package's heavy calls.

The matrix products in svdt (and in the functions built on it) are small enough that one
core computes them at full speed, but large enough that OpenBLAS spreads them over every
core. On an idle machine that gains little (about 5 % here); on a busy one it loses a lot:
when another process holds a core, OpenBLAS's threads wait for each other, and svdt on
10^6 frames went from about 0.11 s to 0.3-2.9 s in measurements on a 2-core machine
(benchmarks/bench_svdt.py has the row). Limiting BLAS to one thread for the duration of
the call makes the time independent of such contention, and lets a lab run one process per
core over an archive of trials (:func:`bmc_functions.batch.map_trials`) without
oversubscription.

threadpoolctl [1]_ does the limiting; its controller is built once, on first use, and
entering or leaving the limit costs microseconds. The user's own setting is restored
when the call returns.

The limit is process-wide while the call runs (BLAS has one thread setting per process),
and it applies only in the main thread (see :func:`blas_single_thread`). To switch it
off, e.g. to give svdt every core on an idle machine or to keep a setting of one's own
during the call, set the environment variable ``BMC_FUNCTIONS_ONE_BLAS_THREAD=0``
(``1``, or unset, restores the default). It is read at every call, so it can be set or
changed in a running session (``os.environ[...] = "0"``)::

    BMC_FUNCTIONS_ONE_BLAS_THREAD=0 python my_analysis.py

References
----------
.. [1] threadpoolctl: Python helpers to limit the number of threads used in native
   libraries. https://github.com/joblib/threadpoolctl
"""

import contextlib
import functools
import os
import threading

from threadpoolctl import ThreadpoolController

_controller = None

#: The environment variable that switches the limit off ("0") or on ("1", the default).
SWITCH = "BMC_FUNCTIONS_ONE_BLAS_THREAD"


def _blas_controller():
    global _controller
    if _controller is None:  # built on first use, when numpy's BLAS is loaded
        _controller = ThreadpoolController()
    return _controller


def limit_enabled():
    """Whether the BLAS limit is on: the environment variable ``SWITCH``, read now.

    Unset, empty or ``'1'``: on; ``'0'``: off; anything else raises ValueError naming
    the variable (a typo must not silently keep or drop the limit).
    """
    value = os.environ.get(SWITCH, "1").strip()
    if value not in ("", "0", "1"):
        raise ValueError(f"the environment variable {SWITCH} must be '0' (BLAS threads "
                         f"left as they are) or '1' (one BLAS thread inside svdt, the "
                         f"default); got {value!r}")
    return value != "0"


def blas_single_thread():
    """Context manager: the BLAS libraries limited to one thread inside the block.

    Only in the main thread. BLAS's thread count is one setting for the whole process:
    calls from several threads at once (a threaded dask worker, a user's thread pool) would
    each save and restore it in an interleaved order and could leave it changed after they
    return. In another thread the block runs with the process's setting unchanged (those
    threads already share the cores among themselves).

    Switched off (the process's setting unchanged) by ``BMC_FUNCTIONS_ONE_BLAS_THREAD=0``
    (:func:`limit_enabled`).
    """
    if not limit_enabled() or threading.current_thread() is not threading.main_thread():
        return contextlib.nullcontext()
    return _blas_controller().limit(limits=1, user_api="blas")


def one_blas_thread(function):
    """Decorator: run `function` with the BLAS libraries limited to one thread."""

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with blas_single_thread():
            return function(*args, **kwargs)

    return wrapper
