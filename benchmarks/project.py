"""Closest points on the limit surface: misses and points per second.

usage: python benchmarks/project.py [--points N] [--seed S] [--meshes M ...] [--schemes S ...]
                                    [--offsets F ...] [--again E ...] [--cache-mb MB]

Samples N random points ``y = evaluate(face, bary)`` of each mesh's limit surface (creases
detected at 30°, corners at 45°; ``"sqrt3"`` takes no tags), pushes them off along the normal by each offset × the
bounding-box diagonal (and N points at 10 diagonals from the box centre), projects them, and
prints per mesh, scheme and offset: the number of feet farther from the query than ``y``
(for the far points: than the nearest of the N samples) (by
more than 1e-12 × diagonal, a miss), the largest such excess in diagonals, and points per second
of ``project`` on a surface that has answered one earlier call (other points, the same
kinds): the certificate's level is built then (its time is printed), and the patch cache
holds what those points needed, as in a fit's later iterations. ``--again E ...`` then projects
each case's queries on an emptied patch cache (filling it) and once more, moved by E ×
diagonal in a random direction (0: the same queries), and prints the second call's points per
second, its speed-up over the first and the keys it added: what a fit's next update, whose
queries move a little, can expect of the cache. ``--cache-mb`` sets the size at which the
patch cache is emptied between chunks of points (default: the library's, 256 MB).
"""

from __future__ import annotations

import argparse
import pathlib
import time

import numpy as np
from scipy.spatial import cKDTree

import hybridsub
from hybridsub._surface import surface as surface_module

MESHES = pathlib.Path(__file__).resolve().parents[1] / "tests" / "data"


def load(name):
    if name == "fandisk":
        return hybridsub.load_example()
    m = hybridsub.read_mesh(MESHES / f"{name}.off")
    return np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--meshes", nargs="+", default=["cube-meshed", "fandisk", "mesh_with_border"])
    ap.add_argument("--schemes", nargs="+", default=["loop", "sqrt3", "hybrid"])
    ap.add_argument("--offsets", nargs="+", type=float, default=[1e-3, 1e-2])
    ap.add_argument("--again", nargs="*", type=float, default=[])
    ap.add_argument("--cache-mb", type=float, default=None)
    a = ap.parse_args()
    if a.cache_mb is not None:
        surface_module.CACHE_BYTES = int(a.cache_mb * 2**20)
    for name in a.meshes:
        V, F = load(name)
        feat = hybridsub.detect_features(V, F, angle=30)
        diag = float(np.linalg.norm(V.max(0) - V.min(0)))
        for scheme in a.schemes:
            tags = {} if scheme == "sqrt3" else dict(sharp_edges=feat.sharp_edges, corners=feat.corners)
            s = hybridsub.LimitSurface(V, F, scheme=scheme, **tags)
            rng = np.random.default_rng(a.seed)
            n = a.points
            face = rng.integers(0, len(F), n)
            bary = rng.dirichlet([1, 1, 1], n)
            t = time.perf_counter()
            Y = s.evaluate(face, bary)
            N = s.normals(face, bary)
            t_eval = time.perf_counter() - t
            cases = [(f"{off:g} diag", Y + off * diag * N * rng.choice([-1, 1], n)[:, None]) for off in a.offsets]
            far = rng.normal(size=(2 * n, 3))
            far *= 10 * diag / np.linalg.norm(far, axis=1, keepdims=True)
            far += 0.5 * (V.max(0) + V.min(0))
            cases.append(("far 10 diag", far[:n]))
            t = time.perf_counter()
            s.project(far[n:n + 1])
            print(f"{name:18s} {scheme:6s} first call (the certificate's level): {time.perf_counter() - t:.2f} s")
            f2, b2 = rng.integers(0, len(F), n), rng.dirichlet([1, 1, 1], n)
            warm = s.evaluate(f2, b2) + np.outer(rng.uniform(-1e-2, 1e-2, n) * diag, [1, 1, 1]) / 3**0.5
            s.project(np.r_[warm, far[n:]])
            tree = cKDTree(Y)
            for label, Q in cases:
                t = time.perf_counter()
                _, _, foot, _ = s.project(Q)
                dt = time.perf_counter() - t
                ref = np.linalg.norm(Q - Y, axis=1) if label != "far 10 diag" else tree.query(Q)[0]
                got = np.linalg.norm(Q - foot, axis=1)
                excess = (got - ref) / diag
                miss = excess > 1e-12
                print(f"{name:18s} {scheme:6s} {label:12s} misses {miss.sum():5d}/{n}  worst {max(excess.max(), 0):.2e}"
                      f"  {n / dt:8.0f} points/s  (evaluate+normals {n / t_eval:.0f}/s)", flush=True)
                for eps in a.again:
                    step = rng.normal(size=Q.shape)
                    step *= eps * diag / np.linalg.norm(step, axis=1, keepdims=True)
                    s._new_cache()
                    t = time.perf_counter()
                    s.project(Q)
                    t_fill, keys, table = time.perf_counter() - t, s._table.n_keys, s._table
                    t = time.perf_counter()
                    s.project(Q + step)
                    dt = time.perf_counter() - t
                    added = f"{(s._table.n_keys - keys) / n:5.1f}" if s._table is table else "(emptied)"
                    print(f"{name:18s} {scheme:6s} {label:12s}   again, moved {eps:g} diag: {n / dt:8.0f} points/s"
                          f" ({t_fill / dt:.1f}x the call that filled the cache with {keys / n:.1f} keys a query;"
                          f" {added} new keys a query)", flush=True)

if __name__ == "__main__":
    main()
