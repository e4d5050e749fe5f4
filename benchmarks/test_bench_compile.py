"""Compile time, on its own: the first call in a fresh process with an empty Numba cache.

Beside it, the same code with a warm cache (``cache=True``): the start-up a user sees.
Each round is one ``python -c CODE`` subprocess, timed as a whole (interpreter start,
import, loading or compiling the kernels, the call).
"""

import tempfile

import pytest
from _bench import FIRST_CALL, fresh_process


@pytest.mark.parametrize("what", list(FIRST_CALL))
def test_cold_compile(benchmark, what, tmp_path):
    """Empty NUMBA_CACHE_DIR: every kernel the code uses is compiled (and written to the cache)."""
    benchmark.group = f"first call: {what}"
    benchmark.pedantic(fresh_process, setup=lambda: ((FIRST_CALL[what], tempfile.mkdtemp(dir=tmp_path)), {}),
                       rounds=1, iterations=1)


@pytest.mark.parametrize("what", list(FIRST_CALL))
def test_warm_cache(benchmark, what, tmp_path):
    """The cache filled by one earlier run: loading, not compiling."""
    benchmark.group = f"first call: {what}"
    fresh_process(FIRST_CALL[what], str(tmp_path))
    benchmark.pedantic(fresh_process, args=(FIRST_CALL[what], str(tmp_path)), rounds=3, iterations=1)
