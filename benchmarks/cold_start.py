"""The first call of a fresh install: each case in a fresh process with an empty Numba cache
(every kernel it needs compiled), then the same with the cache that run left (warm).

    python benchmarks/cold_start.py [--rounds 1] [--only NAME]

Prints wall time and the child's CPU time (user + system: what the compile costs, whatever
else the machine is doing), cold with the helpers that compile ahead (hybridsub/_compile_ahead.py;
their CPU time counted in) and without them (``HYBRIDSUB_COMPILE_AHEAD=0``), then warm. Targets (issue 31): a first ``subdivide(levels=1)`` ≤ 8 s, the
README's first snippet ≤ 20 s; warm, a tiny mesh through the CLI ≤ 0.8 s and ``import`` +
a small ``subdivide`` ≤ 1 s.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time

TET = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"

CASES = {
    "subdivide(levels=1)": [sys.executable, "-c",
                            "import hybridsub; V, F = hybridsub.load_example(); hybridsub.subdivide(V, F, levels=1)"],
    "README snippet": [sys.executable, "-c", """
import hybridsub
V, F = hybridsub.load_example()
feat = hybridsub.detect_features(V, F, angle=30)
V2, F2 = hybridsub.subdivide(V, F, feat.sharp_edges, levels=2, corners=feat.corners)
r = hybridsub.refine(F, feat.sharp_edges, levels=2, corners=feat.corners)
V2 = r.apply(V)
hybridsub.write_mesh("fandisk2.obj", V2, r.faces, sharp_edges=r.sharp_edges, corners=r.corners)
"""],
    "CLI: subdivide tet.off": ["hybridsub", "subdivide", "tet.off", "-o", "tet2.obj", "-q"],
    "LimitSurface.evaluate": [sys.executable, "-c", """
import numpy as np, hybridsub
V, F = hybridsub.load_example()
hybridsub.LimitSurface(V, F).evaluate(np.arange(100), np.full((100, 3), 1 / 3))
"""],
    "LimitSurface, creases, D": [sys.executable, "-c", """
import numpy as np, hybridsub
V, F = hybridsub.load_example()
feat = hybridsub.detect_features(V, F, angle=30)
s = hybridsub.LimitSurface(V, F, feat.sharp_edges, corners=feat.corners)
s.evaluate(np.arange(100), np.full((100, 3), 1 / 3), derivatives=True)
"""],
    "CLI: adaptive 0.1%": ["hybridsub", "subdivide", "fandisk.off", "--tolerance", "0.1%", "-o", "a.obj", "-q"],
}


def _example(path: str) -> None:
    import hybridsub

    hybridsub.write_mesh(path, *hybridsub.load_example())


def _run(cmd, cwd, cache, ahead: str = "1") -> tuple[float, float]:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, HYBRIDSUB_COMPILE_NOTICE="0", HYBRIDSUB_COMPILE_AHEAD=ahead)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run(cmd, cwd=cwd, env=env, check=True, capture_output=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--only", default="", help="the cases whose name contains this")
    args = ap.parse_args()
    print(f"{'case':26} {'cold wall':>10} {'cold CPU':>9} {'alone wall':>10} {'alone CPU':>9} "
          f"{'warm wall':>10} {'warm CPU':>9}")
    for name, cmd in CASES.items():
        if args.only not in name:
            continue
        for _ in range(args.rounds):
            with tempfile.TemporaryDirectory() as work:
                with open(os.path.join(work, "tet.off"), "w") as f:
                    f.write(TET)
                _example(os.path.join(work, "fandisk.off"))
                cold = _run(cmd, work, os.path.join(work, "cache-ahead"))
                cache = os.path.join(work, "numba-cache")
                alone = _run(cmd, work, cache, ahead="0")
                warm = _run(cmd, work, cache)
            print(f"{name:26} {cold[0]:9.2f}s {cold[1]:8.2f}s {alone[0]:9.2f}s {alone[1]:8.2f}s "
                  f"{warm[0]:9.2f}s {warm[1]:8.2f}s", flush=True)


if __name__ == "__main__":
    main()
