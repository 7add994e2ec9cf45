"""Issue 24, finding 2: svdt's BLAS limit (bmc_functions._threads) can be switched off."""

import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

import bmc_functions.rigid_body.svdt as svdt_module
from bmc_functions import svdt
from bmc_functions._threads import SWITCH, limit_enabled

A = np.array([[0.0, 0, 0], [100, 0, 0], [0, 80, 0], [30, 40, 60]])
B = np.tile(A, (5, 1, 1)) + [1.0, 2.0, 3.0]


def blas_threads():
    return sorted({lib["num_threads"] for lib in threadpool_info()
                   if lib["user_api"] == "blas"})


@pytest.fixture
def threads_inside_svdt(monkeypatch):
    """The BLAS thread counts seen inside svdt's fitting step, per call."""
    seen = []
    original = svdt_module._fit_block

    def spy(*args):
        seen.append(blas_threads())
        return original(*args)

    monkeypatch.setattr(svdt_module, "_fit_block", spy)
    return seen


def test_default_is_one_thread(threads_inside_svdt, monkeypatch):
    monkeypatch.delenv(SWITCH, raising=False)
    with threadpool_limits(limits=2, user_api="blas"):
        svdt(A, B, order="row")
    assert threads_inside_svdt == [[1]]


@pytest.mark.parametrize("value", ["1", "", " 1 "])
def test_switched_on(threads_inside_svdt, monkeypatch, value):
    monkeypatch.setenv(SWITCH, value)
    with threadpool_limits(limits=2, user_api="blas"):
        svdt(A, B, order="row")
    assert threads_inside_svdt == [[1]]


def test_switched_off_leaves_the_setting_alone(threads_inside_svdt, monkeypatch):
    monkeypatch.setenv(SWITCH, "0")
    with threadpool_limits(limits=2, user_api="blas"):
        svdt(A, B, order="row")
        assert blas_threads() == [2]
    assert threads_inside_svdt == [[2]]


def test_read_at_every_call(threads_inside_svdt, monkeypatch):
    with threadpool_limits(limits=2, user_api="blas"):
        monkeypatch.setenv(SWITCH, "0")
        svdt(A, B, order="row")
        monkeypatch.setenv(SWITCH, "1")
        svdt(A, B, order="row")
    assert threads_inside_svdt == [[2], [1]]


@pytest.mark.parametrize("value", ["off", "2", "yes", "false"])
def test_unknown_value_names_the_variable(monkeypatch, value):
    monkeypatch.setenv(SWITCH, value)
    with pytest.raises(ValueError, match=rf"{SWITCH} must be '0' .* or '1' .*got {value!r}"):
        limit_enabled()
    with pytest.raises(ValueError, match=SWITCH):
        svdt(A, B, order="row")


def test_the_same_result_either_way(monkeypatch):
    monkeypatch.setenv(SWITCH, "0")
    off = svdt(A, B, order="row")
    monkeypatch.setenv(SWITCH, "1")
    on = svdt(A, B, order="row")
    for x, y in zip(off, on):
        np.testing.assert_array_equal(x, y)
