"""map_trials: the same results in order in this process, in worker processes and on a dask
LocalCluster; one BLAS thread in the workers; errors per item; bad arguments."""

import functools
import operator
import os
import warnings

import numpy as np
import pytest

from bmc_functions import svdt
from bmc_functions.batch import map_trials


def fit_trial(seed):
    """A small trial: a 4-marker cluster in 200 frames; returns (seed, max |R - truth|)."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(seed)
    A = rng.normal(size=(4, 3)) * 50
    truth = Rotation.random(200, random_state=seed).as_matrix()
    B = np.einsum("fij,nj->fni", truth, A) + rng.normal(size=(200, 1, 3))
    R, _, _ = svdt(A, B, order="row")
    return seed, float(np.abs(R - truth).max())


def blas_threads(_):
    from threadpoolctl import threadpool_info

    return sorted({lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"})


def warn_on_odd(x):
    if x % 2:
        warnings.warn(f"odd item {x} is doubtful", RuntimeWarning)
    return x


def fail_on_odd(x):
    if x % 2:
        raise ValueError(f"odd item {x}")
    return x


def test_serial_results_in_order():
    assert map_trials(abs, [-3, 2, -1]) == [3, 2, 1]
    assert map_trials(abs, []) == []


def test_processes_give_the_serial_results_in_order():
    seeds = list(range(6))
    serial = map_trials(fit_trial, seeds)
    parallel = map_trials(fit_trial, seeds, workers=2, progress=False)
    assert parallel == serial
    assert [s for s, _ in parallel] == seeds
    assert max(err for _, err in parallel) < 1e-6   # the fits themselves are right


def test_workers_use_one_blas_thread_each():
    assert map_trials(blas_threads, [0, 1], workers=2, progress=False) == [[1], [1]]


def test_dask_local_cluster_gives_the_serial_results():
    distributed = pytest.importorskip("dask.distributed")
    seeds = list(range(5))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=":0") as cluster, \
            distributed.Client(cluster) as client:
        result = map_trials(fit_trial, seeds, client=client, progress=False)
    assert result == map_trials(fit_trial, seeds)


def test_error_names_the_item():
    with pytest.raises(ValueError, match="odd item 1") as info:
        map_trials(fail_on_odd, [0, 1, 2])
    if hasattr(info.value, "__notes__"):
        assert "item 1" in info.value.__notes__[0]


def test_errors_warn_keeps_the_other_items():
    with pytest.warns(RuntimeWarning, match=r"2 of 4 items failed.*odd item 1.*odd item 3"):
        result = map_trials(fail_on_odd, [0, 1, 2, 3], workers=2, errors="warn",
                            progress=False)
    assert result == [0, None, 2, None]


@pytest.mark.parametrize("kwargs, error, message", [
    (dict(workers=0), ValueError, "workers must be None or a positive integer; got 0"),
    (dict(workers=-2), ValueError, "got -2"),
    (dict(workers=2.5), TypeError, "workers must be None or a positive integer"),
    (dict(workers=True), TypeError, "got True"),
    (dict(workers=2, client=object()), ValueError, "not both"),
    (dict(errors="ignore"), ValueError, "errors must be 'raise' or 'warn'"),
])
def test_bad_arguments(kwargs, error, message):
    with pytest.raises(error, match=message):
        map_trials(abs, [1], **kwargs)


def test_function_must_be_callable():
    with pytest.raises(TypeError, match="function must be callable; got int"):
        map_trials(3, [1])


def test_svdt_leaves_the_callers_blas_setting_unchanged():
    from threadpoolctl import threadpool_info

    before = [lib["num_threads"] for lib in threadpool_info()]
    fit_trial(0)
    assert [lib["num_threads"] for lib in threadpool_info()] == before


def test_svdt_runs_with_one_blas_thread(monkeypatch):
    from threadpoolctl import threadpool_info

    import bmc_functions.rigid_body.svdt as rigid_body

    seen = []
    original = rigid_body._fit_block

    def spy(*args):
        seen.append(sorted({lib["num_threads"] for lib in threadpool_info()
                            if lib["user_api"] == "blas"}))
        return original(*args)

    monkeypatch.setattr(rigid_body, "_fit_block", spy)
    fit_trial(1)
    assert seen and all(s == [1] for s in seen)


def test_warnings_of_worker_processes_reach_the_caller():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = map_trials(warn_on_odd, [0, 1, 2, 3], workers=2, progress=False)
    assert result == [0, 1, 2, 3]
    messages = sorted(str(w.message) for w in caught)
    assert messages == ["odd item 1 is doubtful", "odd item 3 is doubtful"]
    assert all(w.category is RuntimeWarning and w.filename == __file__ for w in caught)


@pytest.mark.parametrize("workers", [None, 2])
def test_the_callers_warning_filters_apply_as_in_a_serial_run(workers):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("ignore")
        assert map_trials(warn_on_odd, [1, 2], workers=workers, progress=False) == [1, 2]
    assert caught == []
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)   # a warning becomes the item's error
        with pytest.raises(RuntimeWarning, match="odd item 1 is doubtful"):
            map_trials(warn_on_odd, [0, 1, 2], workers=workers, progress=False)


def test_svdt_in_several_threads_leaves_the_blas_setting_unchanged():
    from concurrent.futures import ThreadPoolExecutor

    from threadpoolctl import threadpool_info

    before = [lib["num_threads"] for lib in threadpool_info()]
    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(fit_trial, range(8)))
    assert max(err for _, err in results) < 1e-6
    fit_trial(0)   # and once more in the main thread
    assert [lib["num_threads"] for lib in threadpool_info()] == before


# --- issue 21: a worker that dies, and a client that is not one ------------------------------

def die_on_three(x):
    """As a reader's segfault: item 3 kills its worker process (after 0.2 s, so that
    other items are pending in the pool when it dies)."""
    import time
    time.sleep(0.2)
    if x == 3:
        os._exit(1)
    return x * 10


def test_a_worker_that_dies_loses_only_its_own_item():
    from bmc_functions.batch import WorkerDiedError
    with pytest.warns(RuntimeWarning, match=r"^1 of 8 items failed and gave None: 3: "
                                            r"WorkerDiedError: the worker process died"):
        results = map_trials(die_on_three, range(8), workers=2, errors="warn",
                             progress=False)
    assert results == [0, 10, 20, None, 40, 50, 60, 70]
    with pytest.raises(WorkerDiedError, match=r"worker process died while processing this "
                                              r"item"):
        map_trials(die_on_three, range(5), workers=2, progress=False)


@pytest.mark.parametrize("client", ["localhost", object(), 8786])
def test_client_that_is_not_a_dask_client_is_refused(client):
    with pytest.raises(TypeError, match=r"client must be a dask.distributed.Client .*got "):
        map_trials(abs, [1, 2], client=client)


def test_lower_limb_angles_checks_client_and_workers_for_one_trial_too():
    from bmc_functions import lower_limb_angles
    with pytest.raises(TypeError, match=r"client must be a dask.distributed.Client"):
        lower_limb_angles(None, "walk.trc", {}, client=object())
    with pytest.raises(ValueError, match=r"workers must be None or a positive integer"):
        lower_limb_angles(None, "walk.trc", {}, workers=0)
