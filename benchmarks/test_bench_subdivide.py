"""subdivide: scheme × mesh × levels, and the copy floor of the outputs.

Run: ``pytest benchmarks/test_bench_subdivide.py --benchmark-only``. Groups are one mesh at
one level, so each table compares the schemes (and the floor) on the same input.
"""

import pytest
from _bench import MESHES, VARIANTS, load, run_warm, tags

import hybridsub

SIZES = ["icosahedron", "fandisk", "armadillo"]  # 20, 12,946 and 52,000 faces


@pytest.mark.parametrize("levels", [1, 2, 3], ids=lambda n: f"L{n}")
@pytest.mark.parametrize("mesh", SIZES)
@pytest.mark.parametrize("variant", list(VARIANTS))
def test_subdivide(benchmark, variant, mesh, levels):
    m = load(mesh)
    edges, kw = tags(m, variant)
    benchmark.group = f"subdivide {mesh} L{levels}"
    run_warm(benchmark, lambda: hybridsub.subdivide(m.V, m.F, edges, levels=levels, **kw))


@pytest.mark.parametrize("mesh", SIZES)
@pytest.mark.parametrize("variant", list(VARIANTS))
def test_copy_floor(benchmark, variant, mesh):
    """``V2.copy(); F2.copy()`` of the L3 output: what any implementation pays to produce it."""
    m = load(mesh)
    edges, kw = tags(m, variant)
    V2, F2 = hybridsub.subdivide(m.V, m.F, edges, levels=3, **kw)
    benchmark.group = f"subdivide {mesh} L3"
    run_warm(benchmark, lambda: (V2.copy(), F2.copy()))


assert set(SIZES) <= set(MESHES)
