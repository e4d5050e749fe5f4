"""Compile time, on its own: the first call in a fresh process with an empty Numba cache.

Beside it, the same code with a warm cache (``cache=True``): the start-up a user sees.
Each round is one ``python -c CODE`` subprocess, timed as a whole (interpreter start,
import, loading or compiling the kernels, the call).
"""

import os
import subprocess
import sys
import tempfile

import pytest
from _bench import ROOT

CODE = {
    "hybrid": "V, F = hybridsub.load_example(); f = hybridsub.detect_features(V, F)\n"
              "hybridsub.subdivide(V, F, f.sharp_edges, levels=1, corners=f.corners)",
    "every-scheme": "V, F = hybridsub.load_example(); f = hybridsub.detect_features(V, F)\n"
                    "hybridsub.subdivide(V, F, f.sharp_edges, levels=1, corners=f.corners)\n"
                    "hybridsub.subdivide(V, F, levels=1, scheme='sqrt3')\n"
                    "hybridsub.subdivide(V, F, f.sharp_edges, levels=1, scheme='loop')",
}


def fresh_process(code: str, cache_dir: str) -> None:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir,
               PYTHONPATH=os.pathsep.join(filter(None, [ROOT, os.environ.get("PYTHONPATH")])))
    subprocess.run([sys.executable, "-c", "import hybridsub\n" + code], env=env, check=True)


@pytest.mark.parametrize("what", list(CODE))
def test_cold_compile(benchmark, what, tmp_path):
    """Empty NUMBA_CACHE_DIR: every kernel the code uses is compiled (and written to the cache)."""
    benchmark.group = f"first call: {what}"
    dirs = iter(tempfile.mkdtemp(dir=tmp_path) for _ in range(10))
    benchmark.pedantic(lambda d: fresh_process(CODE[what], d), setup=lambda: ((next(dirs),), {}), rounds=1,
                       iterations=1)


@pytest.mark.parametrize("what", list(CODE))
def test_warm_cache(benchmark, what, tmp_path):
    """The cache filled by one earlier run: loading, not compiling."""
    benchmark.group = f"first call: {what}"
    fresh_process(CODE[what], str(tmp_path))
    benchmark.pedantic(fresh_process, args=(CODE[what], str(tmp_path)), rounds=3, iterations=1)
