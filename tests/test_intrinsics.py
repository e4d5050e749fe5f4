"""The two LLVM intrinsics the kernels call: an atomic integer add (threads counting into
one array) and a prefetch hint (reads that hop through index arrays)."""

import numpy as np
import pytest
from numba import njit, prange

from hybridsub._atomic import atomic_add
from hybridsub._prefetch import prefetch


@njit(parallel=True)
def _histogram(keys, n, dtype_probe):
    counts = np.zeros(n, dtype_probe.dtype)
    for k in prange(keys.shape[0]):
        atomic_add(counts, keys[k], 1)
    return counts


@pytest.mark.parametrize("dtype", [np.int32, np.int64])
def test_atomic_add_loses_no_count_when_threads_share_the_targets(dtype):
    """Ten million increments onto 64 slots, on every thread: each slot's total is exact (a
    plain ``+=`` loses counts when two threads update one slot at once)."""
    keys = np.random.default_rng(0).integers(0, 64, 10_000_000)
    counts = _histogram(keys, 64, np.zeros(0, dtype))
    assert counts.dtype == dtype
    assert counts.tolist() == np.bincount(keys, minlength=64).tolist()


def test_atomic_add_adds_any_integer_to_the_given_element():
    @njit
    def add(x, i, v):
        atomic_add(x, i, v)

    x = np.array([5, 6, 7], np.int64)
    add(x, 2, -10)
    add(x, np.int32(0), np.int8(3))
    assert x.tolist() == [8, 6, -3]


def test_prefetch_is_emitted_and_changes_no_result():
    """The hint reaches the compiled code as ``llvm.prefetch`` (a compiler that dropped it
    would make the kernels slower, not wrong), and the loop around it computes what it
    would without it."""
    @njit
    def gather(x, idx, ahead):
        total = 0.0
        for i in range(idx.shape[0]):
            if i + ahead < idx.shape[0]:
                prefetch(x, idx[i + ahead])
            total += x[idx[i]]
        return total

    x = np.random.default_rng(1).random(100_000)
    idx = np.random.default_rng(2).integers(0, len(x), 50_000)
    assert gather(x, idx, 8) == sum(x[i] for i in idx.tolist())
    ir = next(iter(gather.inspect_llvm().values()))
    assert "llvm.prefetch" in ir



def test_prefetch_compiles_to_nothing_where_llvm_refuses_it(monkeypatch):
    """Where this LLVM does not take the intrinsic (``lowers()`` False), a kernel with the
    hint compiles and runs, without it."""
    from hybridsub import _prefetch

    assert _prefetch.lowers()  # on the LLVM the project is tested with, the hint is emitted
    monkeypatch.setattr(_prefetch, "lowers", lambda: False)

    @njit
    def first(x, idx):
        prefetch(x, idx[0])
        return x[idx[0]]

    assert first(np.arange(4.0), np.array([2])) == 2.0
    assert "llvm.prefetch" not in next(iter(first.inspect_llvm().values()))
