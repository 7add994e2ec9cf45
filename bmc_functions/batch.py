"""Run one function over many trials: in this process, in parallel processes, or on a cluster.

A lab's archive is many trials processed the same way (calibrate once, then the angles of
every walking trial). Trials are independent, so they parallelize across processes
without any change to the per-trial code. :func:`map_trials` is the one place that does
it, for every pipeline of the package:

- ``workers=None`` (default): one trial after another in this process;
- ``workers=n``: ``n`` worker processes on this machine
  (:class:`concurrent.futures.ProcessPoolExecutor`, started from a clean 'forkserver'
  process where the platform has one, else by 'spawn'), each limited to one BLAS thread
  with threadpoolctl, so that ``n`` processes use ``n`` cores and do not oversubscribe
  the machine (see :mod:`bmc_functions._threads`);
- ``client=``: a dask.distributed ``Client`` (the optional ``dask`` extra), one task per
  trial, for more than one machine (or a ``LocalCluster``).

The results come back in the order of the items, whatever the order of completion, with
a tqdm progress bar that appears only when the work takes longer than a moment.

Warnings raised by the function in a worker process are recorded there and raised again
in this process as each item completes, so that they reach the user (a notebook does
not show a worker's output) and the user's warning filters apply to them as in a serial
run (``warnings.simplefilter("error")`` turns them into that item's error).
"""

import concurrent.futures
import functools
import multiprocessing
import os
import pickle
import reprlib
import sys
import warnings
from concurrent.futures.process import BrokenProcessPool

# the plain text bar: tqdm.auto would warn in a Jupyter kernel without ipywidgets
from tqdm import tqdm

from ._checks import ArgumentTypeError, check_choice, check_flag, check_scalar, warn

#: Seconds before the progress bar appears (tqdm's ``delay``): short runs stay silent.
PROGRESS_DELAY = 1.0


def _limit_worker_blas():
    """Initializer of each worker process: one BLAS thread for the process's lifetime."""
    from threadpoolctl import threadpool_limits

    global _worker_limits
    _worker_limits = threadpool_limits(limits=1, user_api="blas")  # kept alive


def _module_of(filename):
    """The name of the loaded module whose file is `filename` (for warning filters)."""
    for name, module in list(sys.modules.items()):
        if getattr(module, "__file__", None) == filename:
            return name
    return None


class _RecordWarnings:
    """Picklable wrapper run in a worker process: returns (result, the warnings raised)."""

    def __init__(self, function):
        self.function = function

    def __call__(self, item):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")  # the caller's filters decide, in the caller
            result = self.function(item)
        return result, [(str(w.message), w.category, w.filename, w.lineno,
                         _module_of(w.filename)) for w in caught]


def _replay(recorded):
    """Raise again, in this process, the warnings recorded in a worker; return its result."""
    result, caught = recorded
    for message, category, filename, lineno, module in caught:
        source = sys.modules.get(module) if module else None
        registry = (vars(source).setdefault("__warningregistry__", {})
                    if source is not None else None)
        warnings.warn_explicit(message, category, filename, lineno, module=module,
                               registry=registry)
    return result


def _process_context():
    """How worker processes start: 'forkserver' where there is one, else 'spawn'.

    Never a plain fork of this process: forking a process that holds threads (BLAS, tqdm's
    monitor, a notebook's kernel) can deadlock. 'spawn' starts a fresh interpreter per
    worker, which imports numpy, scipy, pandas and the package again: about a second per
    worker on every call. 'forkserver' (Linux, macOS) starts one clean server process
    once, which imports the package once (the preload below), and forks the workers of
    every later call from it: after the first call, a pool starts in tens of ms.
    """
    if "forkserver" in multiprocessing.get_all_start_methods():
        context = multiprocessing.get_context("forkserver")
        # only read when the server starts (the first pool of the session)
        context.set_forkserver_preload([__name__.rpartition(".")[0] or __name__])
        return context
    return multiprocessing.get_context("spawn")


def _check_workers(workers):
    if workers is None:
        return None
    return check_scalar(workers, "workers", "None or a positive integer", minimum=1, integer=True)


def _check_client(client):
    """A dask.distributed Client (anything with its map, submit and cancel), or None."""
    if client is None:
        return None
    if isinstance(client, (str, bytes, os.PathLike)) or not all(
            callable(getattr(client, name, None)) for name in ("map", "submit", "cancel")):
        raise ArgumentTypeError(
            f"client must be a dask.distributed.Client (for example "
            f"Client('tcp://host:8786'), or Client(LocalCluster())) or None; got "
            f"{repr(client)[:80]} ({type(client).__name__}), which has no "
            f"map/submit/cancel")
    return client


def check_batch_options(workers, client, progress, errors):
    """The options of :func:`map_trials`, validated: (workers, client, progress, errors).

    For a pipeline that takes them and passes them on, to refuse a bad one at once, also
    when it runs a single trial in this process without calling :func:`map_trials`.
    """
    workers = _check_workers(workers)
    if workers is not None and client is not None:
        raise ValueError("give workers (processes on this machine) or client (a dask "
                         "cluster), not both")
    return (workers, _check_client(client), check_flag(progress, "progress"),
            check_choice(errors, "errors", ("raise", "warn")))


class WorkerDiedError(RuntimeError):
    """The worker process running one item died (killed, out of memory, or a crash in
    native code such as a file reader's segfault)."""


def _run_alone(context, function, item):
    """Run one item in a fresh one-worker pool: (result, warnings) or WorkerDiedError."""
    with concurrent.futures.ProcessPoolExecutor(max_workers=1, mp_context=context,
                                                initializer=_limit_worker_blas) as pool:
        try:
            return pool.submit(_RecordWarnings(function), item).result()
        except BrokenProcessPool:
            raise WorkerDiedError(
                "the worker process died while processing this item (killed, out of "
                "memory, or a crash in native code, e.g. a file reader); the other items "
                "were not affected") from None


def _item_text(item):
    text = os.fspath(item) if isinstance(item, (str, os.PathLike)) else repr(item)
    return text if len(text) <= 80 else text[:77] + "..."


def _map_on_dask(client, function, items, record):
    """One task per item on the dask cluster of `client`; record(index, get) as each
    completes."""
    from dask.distributed import as_completed  # dask is an optional extra

    futures = client.map(function, items, pure=False)
    index_of = {future.key: i for i, future in enumerate(futures)}
    try:
        for future in as_completed(futures):
            record(index_of[future.key], future.result)
    finally:
        client.cancel(futures)


def _map_in_processes(workers, function, items, record):
    """The items in a pool of `workers` processes (one BLAS thread each); record(index,
    get) as each completes, the worker's warnings raised again here."""
    context = _process_context()
    with concurrent.futures.ProcessPoolExecutor(
            max_workers=min(workers, max(len(items), 1)), mp_context=context,
            initializer=_limit_worker_blas) as pool:
        recorded = _RecordWarnings(function)
        futures = {pool.submit(recorded, item): i for i, item in enumerate(items)}
        broken = []   # items lost when a worker died (with it, the whole pool)
        try:
            for future in concurrent.futures.as_completed(futures):
                if isinstance(future.exception(), BrokenProcessPool):
                    broken.append(futures[future])
                    continue
                record(futures[future], lambda future=future: _replay(future.result()))
        except BaseException:
            for future in futures:
                future.cancel()
            raise
    # A dead worker breaks the pool and fails every item still pending in it: run each of
    # those alone in a fresh process, so that only the item that kills its process is
    # lost (and named), and the healthy ones are computed.
    for index in sorted(broken):
        record(index, lambda item=items[index]: _replay(_run_alone(context, function, item)))


def _checked_items(items):
    """`items` as a list; refused (naming `items`) when it is not an iterable of trials."""
    if items is None or isinstance(items, (str, bytes)) or not hasattr(items, "__iter__"):
        raise ArgumentTypeError(f"items must be an iterable of trials (e.g. a list of "
                                f"paths); got {reprlib.repr(items)} "
                                f"({type(items).__name__})")
    return list(items)


def _check_picklable(function):
    """Refuse, before any worker starts, a function that cannot be sent to a worker
    process (a lambda, a function defined in a notebook cell or inside another)."""
    inner = function
    while isinstance(inner, functools.partial):
        inner = inner.func
    why = None
    main_file = getattr(sys.modules.get("__main__"), "__file__", None)
    if getattr(inner, "__module__", None) == "__main__" and not (
            main_file and os.path.isfile(main_file)):
        # pickled by name, but a worker cannot import an interactive session's __main__
        why = "it is defined in an interactive session (a notebook cell), which worker " \
              "processes cannot import"
    else:
        try:
            pickle.dumps(function)
        except Exception as error:  # noqa: BLE001 (pickle raises several kinds)
            why = f"pickle: {error}"
    if why:
        raise ValueError(f"function {getattr(inner, '__qualname__', inner)!r} cannot be "
                         f"sent to worker processes ({why}); with workers=n it must be "
                         "defined at module level of an importable file (not a lambda, "
                         "nor in a notebook cell or another function), or a "
                         "functools.partial of one; or run with workers=None")


def map_trials(function, items, *, workers=None, client=None, progress=True, desc=None,
               errors="raise"):
    """Apply `function` to every item (one trial each) and return the results in order.

    Parameters
    ----------
    function : callable
        Called as ``function(item)`` for each item. With ``workers`` or ``client`` it runs
        in another process, so it must be picklable: a function defined at module level
        (not a lambda or a function defined in a notebook cell), or a
        :func:`functools.partial` of one.
    items : iterable
        The trials, e.g. a list of paths.
    workers : int or None, optional
        None (default): run in this process, one item after another. An integer n >= 1:
        n worker processes on this machine, each limited to one BLAS thread (a good
        choice is the number of cores, ``os.cpu_count()``). The workers start in about
        a second the first time in a session, then in tens of milliseconds. In a script,
        call it under ``if __name__ == "__main__":`` (the workers import the script).
    client : dask.distributed.Client, optional
        Run one task per item on this dask cluster instead (needs the ``dask`` extra).
        Not together with `workers`. The workers' warnings stay in their logs (a
        ``LocalCluster(processes=False)`` runs the tasks in threads of this process, whose
        warnings are shown here).
    progress : bool, optional
        Show a tqdm progress bar when the run takes longer than ``PROGRESS_DELAY``
        seconds (default True).
    desc : str, optional
        The progress bar's label.
    errors : {'raise', 'warn'}, optional
        'raise' (default): the first failing item stops the run with its exception, with
        the item named in a note. 'warn': a failing item's result is None, and one
        RuntimeWarning at the end names the failed items and their errors, so one broken
        file does not lose the rest of an archive. An item whose worker process dies
        (a crash in native code) fails with :class:`WorkerDiedError`; the items that
        were pending in the broken pool are rerun, each in a fresh process.

    Returns
    -------
    list
        ``[function(item) for item in items]``, in the order of `items`.

    Raises
    ------
    TypeError
        If `function` is not callable, `items` is not an iterable (None, a string),
        `workers` is not None or an integer, `client` is
        not None or a dask ``Client``, or `progress` is not True or False (an
        :class:`~bmc_functions._checks.ArgumentTypeError`, also a ValueError).
    ValueError
        If `workers` is below 1, both `workers` and `client` are given, `errors` is not
        'raise' or 'warn', or `function` cannot be pickled while `workers` is given
        (checked before any worker starts).

    Examples
    --------
    >>> from bmc_functions.batch import map_trials
    >>> map_trials(abs, [-1, 2, -3])
    [1, 2, 3]
    >>> import operator, functools
    >>> map_trials(functools.partial(operator.mul, 10), [1, 2, 3], workers=2)
    [10, 20, 30]
    """
    if not callable(function):
        raise ArgumentTypeError(f"function must be callable; got {type(function).__name__}")
    workers, client, progress, errors = check_batch_options(workers, client, progress,
                                                            errors)
    items = _checked_items(items)
    if workers is not None:
        _check_picklable(function)
    bar = tqdm(total=len(items), desc=desc, disable=not progress or not items,
               delay=PROGRESS_DELAY)
    results = [None] * len(items)
    failures = []

    def record(index, get):
        try:
            results[index] = get()
        except Exception as error:  # noqa: BLE001 (reported below, per item)
            if errors == "raise":
                if hasattr(error, "add_note"):  # Python >= 3.11: say which trial failed
                    error.add_note(f"while processing item {index}: {_item_text(items[index])}")
                raise
            failures.append((index, error))
        finally:
            bar.update(1)

    try:
        if client is not None:
            _map_on_dask(client, function, items, record)
        elif workers is not None:
            _map_in_processes(workers, function, items, record)
        else:
            for i, item in enumerate(items):
                record(i, lambda item=item: function(item))
    finally:
        bar.close()

    if failures:
        listed = "; ".join(f"{_item_text(items[i])}: {type(e).__name__}: {e}"
                           for i, e in sorted(failures, key=lambda f: f[0]))
        warn(f"{len(failures)} of {len(items)} items failed and gave None: {listed}",
             RuntimeWarning)
    return results
