"""The vertex limit functions timed: ``limit_matrix``, ``limit_positions``, ``limit_normals``
and ``limit_mesh`` on fandisk, per scheme and tag set (the table of docs/limit.md).

usage: python benchmarks/vertex_limits.py [--repeat N] [--threads T]

Best of ``N`` after one warm-up call (compilation), ``T`` threads (1 by default).
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from _bench import load  # noqa: E402

import hybridsub  # noqa: E402


def cases(V, F):
    f = hybridsub.detect_features(V, F)
    tags = dict(sharp_edges=f.sharp_edges, corners=f.corners)
    x = V[F].mean(axis=1)[:, 0]
    half = dict(sharp_faces=x < np.median(x))  # one side sharp: mixed vertices along a curve
    semi = dict(sharp_edges=f.sharp_edges,
                sharpness=np.linspace(0.2, 4.0, len(f.sharp_edges)))
    return [('`"hybrid"`', "hybrid", tags, 0), ('`"loop"`', "loop", tags, 0), ('`"sqrt3"`', "sqrt3", {}, 0),
            ('`"hybrid"`, the faces on one side sharp (mixed vertices between)', "hybrid", half, 0),
            ('`"loop"`, semi-sharp creases 0.2 … 4', "loop", semi, 0),
            ('`"hybrid"`, `levels=2`', "hybrid", tags, 2), ('`"loop"`, `levels=3`', "loop", tags, 3)]


def best(fn, repeat):
    fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args(argv)
    hybridsub.set_threads(args.threads)
    fan = load("fandisk")
    V, F = fan.V, fan.F
    print(f"fandisk ({len(V)} vertices, {len(F)} faces), best of {args.repeat}, {args.threads} thread(s)\n")
    print("| case | `limit_matrix` | `limit_positions` | `limit_normals` | `limit_mesh` (positions, normals, faces) |")
    print("|---|---:|---:|---:|---:|")
    for label, scheme, tags, levels in cases(V, F):
        kw = dict(scheme=scheme, levels=levels, **tags)
        tm = best(lambda: hybridsub.limit_matrix(F, n_vertices=len(V), **kw), args.repeat) if levels < 3 else None
        tp = best(lambda: hybridsub.limit_positions(V, F, **kw), args.repeat)
        tn = best(lambda: hybridsub.limit_normals(V, F, **kw), args.repeat)
        tl = best(lambda: hybridsub.limit_mesh(V, F, **kw), args.repeat)
        cell = "" if tm is None else f"{tm:.3f} s"
        print(f"| {label} | {cell} | {tp:.3f} s | {tn:.3f} s | {tl:.3f} s |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
