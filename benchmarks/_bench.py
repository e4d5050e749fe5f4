"""What the benchmark scripts and suites share: the meshes, the variants, the timing loop."""

from __future__ import annotations

import gc
import os
import platform
import subprocess
import sys
import time
from dataclasses import dataclass, field

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DATA = os.path.join(HERE, "data")
if os.path.isdir(os.path.join(ROOT, "hybridsub")) and ROOT not in sys.path:
    sys.path.insert(0, ROOT)  # benchmark the checkout this folder lives in, not an installed copy

import hybridsub  # noqa: E402
from hybridsub._io import example_path, read_off  # noqa: E402

MESHES = {
    "icosahedron": os.path.join(DATA, "icosahedron.off"),
    "fandisk": example_path("fandisk"),
    "armadillo": os.path.join(DATA, "armadillo.off"),
    "mesh_with_border": os.path.join(DATA, "mesh_with_border.off"),
}


@dataclass(frozen=True)
class Mesh:
    name: str
    path: str
    V: np.ndarray
    F: np.ndarray
    creases: np.ndarray  # edges with a dihedral angle above 30°
    corners: np.ndarray


_cache: dict = {}


def load(name: str) -> Mesh:
    if name not in _cache:
        V, F = read_off(MESHES[name])
        feat = hybridsub.detect_features(V, F, angle=30)
        _cache[name] = Mesh(name, MESHES[name], V, F, feat.sharp_edges, feat.corners)
    return _cache[name]


# The schemes benchmarked: hybridsub's three, Loop both plain and with the 30° creases.
VARIANTS = {
    "sqrt3": dict(scheme="sqrt3"),
    "loop": dict(scheme="loop"),
    "loop+creases": dict(scheme="loop", tagged=True),
    "hybrid": dict(scheme="hybrid", tagged=True),
}


def tags(mesh: Mesh, variant: str) -> tuple:
    """(sharp_edges, keyword arguments) of a variant on a mesh."""
    v = VARIANTS[variant]
    if not v.get("tagged"):
        return None, dict(scheme=v["scheme"])
    kw = dict(scheme=v["scheme"])
    if v["scheme"] == "hybrid":
        kw["corners"] = mesh.corners
    return mesh.creases, kw


# The first call a user makes, for the fresh-process timings (compare.py, test_bench_compile.py).
FIRST_CALL = {
    "hybrid": "import hybridsub\n"
              "V, F = hybridsub.load_example(); feat = hybridsub.detect_features(V, F, angle=30)\n"
              "hybridsub.subdivide(V, F, feat.sharp_edges, levels=1, corners=feat.corners)\n",
    "every-scheme": "import hybridsub\n"
                    "V, F = hybridsub.load_example(); feat = hybridsub.detect_features(V, F, angle=30)\n"
                    "hybridsub.subdivide(V, F, feat.sharp_edges, levels=1, corners=feat.corners)\n"
                    "hybridsub.subdivide(V, F, levels=1, scheme='sqrt3')\n"
                    "hybridsub.subdivide(V, F, feat.sharp_edges, levels=1, scheme='loop')\n",
}


def child_env(**extra) -> dict:
    """The environment of a child Python: this checkout (and benchmarks/) first on its path."""
    path = [ROOT, HERE] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    return dict(os.environ, PYTHONPATH=os.pathsep.join(path), **extra)


def fresh_process(code: str, cache_dir: str) -> float:
    """Wall time of ``python -c CODE`` with NUMBA_CACHE_DIR=cache_dir, interpreter start included."""
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-c", code], env=child_env(NUMBA_CACHE_DIR=cache_dir), capture_output=True,
                       text=True)
    dt = time.perf_counter() - t0
    if r.returncode:
        raise RuntimeError(f"python -c failed:\n{code}\n{r.stderr[-1000:]}")
    return dt


def cpu_name() -> str:
    """The CPU's model name (Linux), else what platform knows."""
    try:
        with open("/proc/cpuinfo") as fh:
            return next((ln.split(":", 1)[1].strip() for ln in fh if ln.startswith("model name")), "?")
    except OSError:
        return platform.processor() or platform.machine()


@dataclass
class Timing:
    """Times of the timed runs (seconds) and what the result looked like."""

    times: list
    counts: tuple | None = None  # (n_vertices, n_faces) of the result
    extra: dict = field(default_factory=dict)

    @property
    def median(self) -> float:
        return float(np.median(self.times))

    @property
    def min(self) -> float:
        return float(np.min(self.times))

    @property
    def runs(self) -> int:
        return len(self.times)


def measure(prepare, run, *, repeat: int, budget: float, counts=None) -> Timing:
    """Median-of-runs timing, the same for every contender.

    ``prepare()`` builds the input outside the timed region; ``run(inp)`` is timed alone with
    the garbage collector off. One untimed warm-up run comes first (JIT compilation, lazy
    imports, first use of a library). If the warm-up shows that ``repeat`` runs would take
    longer than ``budget`` seconds, fewer runs are made (at least one); the report shows how
    many. Results are deleted before the next run.
    """
    inp = prepare()
    gc.collect()
    t0 = time.perf_counter()
    out = run(inp)
    warm = time.perf_counter() - t0
    cnt = counts(out) if counts else None
    del out, inp
    n = repeat if warm * repeat <= budget else max(1, min(repeat, int(budget // max(warm, 1e-9))))
    times = []
    for _ in range(n):
        inp = prepare()
        gc.collect()
        gc.disable()
        try:
            t0 = time.perf_counter()
            out = run(inp)
            t1 = time.perf_counter()
        finally:
            gc.enable()
        del out, inp
        times.append(t1 - t0)
    return Timing(times, cnt)


def run_warm(benchmark, fn, *, prepare=None, budget: float = 2.0, min_rounds: int = 3, max_rounds: int = 20) -> None:
    """Benchmark ``fn(*prepare())`` (``fn()`` without prepare) the way compare.py times it.

    One untimed warm-up call (JIT compilation or cache load, first use), then rounds of one
    call each; ``prepare`` runs before each round, untimed, and the round's result is deleted
    in the (untimed) teardown, so at most one is alive. The number of rounds fits ``budget``
    seconds, within [min_rounds, max_rounds]. If ``fn`` returns ``(V, F)``, their sizes go
    into ``benchmark.extra_info``.
    """
    args = prepare() if prepare else ()
    t0 = time.perf_counter()
    out = fn(*args)
    warm = time.perf_counter() - t0
    if isinstance(out, tuple) and len(out) == 2 and all(isinstance(a, np.ndarray) for a in out):
        benchmark.extra_info.update(vertices=len(out[0]), faces=len(out[1]), output_bytes=out[0].nbytes + out[1].nbytes)
    del out, args
    rounds = int(min(max_rounds, max(min_rounds, budget // max(warm, 1e-9))))
    box = []

    def setup():
        gc.collect()
        return (prepare(), {}) if prepare else None

    def target(*args):
        box.append(fn(*args))

    def teardown(*args):
        box.clear()

    benchmark.pedantic(target, setup=setup, teardown=teardown, rounds=rounds, iterations=1, warmup_rounds=0)


def frame_3d(ax, P, title: str, azim: float = -60):
    """A figure panel's 3-D axes fitted to the points ``P``, seen from ``azim``, untitled axes."""
    lo, hi = P.min(0), P.max(0)
    ax.set_xlim(lo[0], hi[0]), ax.set_ylim(lo[1], hi[1]), ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)
    ax.view_init(25, azim)
    ax.set_axis_off()
    ax.set_title(title, fontsize=9)
