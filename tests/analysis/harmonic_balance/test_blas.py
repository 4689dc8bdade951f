"""One BLAS thread for harmonic balance (qzs.analysis.harmonic_balance.blas): the count is one
inside and restored after, also after an error; where numpy's OpenBLAS is not reached, the
context does nothing."""
import numpy as np
import pytest

from qzs.analysis.harmonic_balance import blas
from qzs.analysis.harmonic_balance.blas import _blas_thread_control, _single_threaded_blas


def test_one_thread_inside_and_the_count_restored_after():
    setter, getter = _blas_thread_control()
    if setter is None:
        pytest.skip("numpy's OpenBLAS exposes no thread control here")
    before = getter()
    setter(2)
    try:
        with _single_threaded_blas():
            assert getter() == 1
            np.linalg.eigvals(np.eye(3))
        assert getter() == 2
        with pytest.raises(ZeroDivisionError), _single_threaded_blas():
            assert getter() == 1
            1 / 0
        assert getter() == 2
    finally:
        setter(before)


def test_without_thread_control_it_only_runs_the_block(monkeypatch):
    monkeypatch.setattr(blas, "_BLAS_CONTROL", [(None, None)])
    ran = []
    with _single_threaded_blas():
        ran.append(True)
    assert ran == [True]
    assert _blas_thread_control() == (None, None)
