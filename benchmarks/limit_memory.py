"""Peak memory of ``LimitSurface.evaluate`` on many fresh points (issue 30: 10⁶ points ≤ 1 GB).

usage: python benchmarks/limit_memory.py [--points N] [--scheme S]

One process per call: fandisk with its 30° creases (``"sqrt3"`` without them), ``N`` random
points (1e6 by default) evaluated with derivatives on a new surface; prints the time and the
process's peak resident memory before and after (``ru_maxrss``).
"""

from __future__ import annotations

import argparse
import resource
import sys
import time

import numpy as np

from _bench import load  # noqa: E402

import hybridsub  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", type=float, default=1e6)
    ap.add_argument("--scheme", default="hybrid", choices=["hybrid", "loop", "sqrt3"])
    args = ap.parse_args(argv)
    fan = load("fandisk")
    tags = {} if args.scheme == "sqrt3" else dict(sharp_edges=fan.creases)
    n = int(args.points)
    rng = np.random.default_rng(1)
    face, bary = rng.integers(0, len(fan.F), n), rng.dirichlet([1, 1, 1], n)
    surface = hybridsub.LimitSurface(fan.V, fan.F, scheme=args.scheme, **tags)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    t = time.perf_counter()
    surface.evaluate(face, bary, derivatives=True)
    took = time.perf_counter() - t
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"{args.scheme}: {n:,} points in {took:.1f} s, peak {peak:.0f} MB (before the call {before:.0f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
