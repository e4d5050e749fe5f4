"""refine (topology and step matrices, no positions), the composite matrix, and applying it.

The animation use: refine once, then ``r.apply(V)`` per frame. Compared here with SciPy's
``S @ V`` (the floor of a sparse product); compare.py sets it against re-running subdivide.
"""

import numpy as np
import pytest
from _bench import load, run_warm, tags

import hybridsub

CASES = [("fandisk", "hybrid"), ("fandisk", "loop+creases"), ("armadillo", "sqrt3"), ("armadillo", "loop")]
LEVELS = 3


def ids(case):
    return "-".join(case)


@pytest.mark.parametrize("case", CASES, ids=ids)
def test_refine(benchmark, case):
    m = load(case[0])
    edges, kw = tags(m, case[1])
    benchmark.group = f"refine {ids(case)} L{LEVELS}"
    run_warm(benchmark, lambda: hybridsub.refine(m.F, edges, LEVELS, **kw))


@pytest.mark.parametrize("case", CASES, ids=ids)
def test_composite_matrix(benchmark, case):
    """Forming S = S_L ⋯ S_1 from the steps (refine's own time excluded)."""
    m = load(case[0])
    edges, kw = tags(m, case[1])
    benchmark.group = f"refine {ids(case)} L{LEVELS}"

    # a fresh Refinement each round (not timed): its matrix is cached after the first access
    run_warm(benchmark, lambda r: r.matrix, prepare=lambda: (hybridsub.refine(m.F, edges, LEVELS, **kw),))


@pytest.mark.parametrize("frames", [1, 100], ids=lambda k: f"{k}frames")
@pytest.mark.parametrize("case", CASES, ids=ids)
def test_apply(benchmark, case, frames):
    """``r.apply(X)`` with the composite formed; X is (n, 3 × frames)."""
    m = load(case[0])
    edges, kw = tags(m, case[1])
    r = hybridsub.refine(m.F, edges, LEVELS, **kw)
    r.matrix
    X = m.V if frames == 1 else np.hstack([m.V + 1e-3 * k for k in range(frames)])
    benchmark.group = f"apply {ids(case)} L{LEVELS} {frames} frames"
    run_warm(benchmark, lambda: r.apply(X))


@pytest.mark.parametrize("frames", [1, 100], ids=lambda k: f"{k}frames")
@pytest.mark.parametrize("case", CASES, ids=ids)
def test_scipy_floor(benchmark, case, frames):
    """``S @ X`` in SciPy: the floor r.apply is measured against."""
    m = load(case[0])
    edges, kw = tags(m, case[1])
    S = hybridsub.refine(m.F, edges, LEVELS, **kw).matrix
    X = m.V if frames == 1 else np.hstack([m.V + 1e-3 * k for k in range(frames)])
    benchmark.group = f"apply {ids(case)} L{LEVELS} {frames} frames"
    run_warm(benchmark, lambda: S @ X)
