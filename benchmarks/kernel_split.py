#!/usr/bin/env python
"""Where one ``subdivide`` call's time goes, kernel by kernel, on one thread.

usage: python benchmarks/kernel_split.py [--mesh armadillo] [--levels 3] [--calls 5]
                                         [--variants sqrt3 loop] [--threads 1]

Profiles ``--calls`` calls of ``subdivide`` per variant (after two untimed warm-up calls)
with cProfile on the process CPU clock, so that the time other processes hold the core is
left out (with one thread, the process's CPU time is the call's own), and prints a Markdown
table: each kernel's own time per call, and the rest (NumPy, Python between the kernels).
Numba's dispatchers report their calls to the profiler, so every kernel called from Python
has its row; kernels called from kernels are counted in their caller.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import sys
import time


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mesh", default="armadillo")
    ap.add_argument("--levels", type=int, default=3)
    ap.add_argument("--calls", type=int, default=5)
    ap.add_argument("--variants", nargs="+", default=["sqrt3", "loop"])
    ap.add_argument("--threads", type=int, default=1, help="NUMBA_NUM_THREADS (default 1)")
    ap.add_argument("--rows", type=int, default=7, help="kernels listed per variant (default 7)")
    args = ap.parse_args(argv)
    os.environ["NUMBA_NUM_THREADS"] = str(args.threads)  # before Numba starts

    from _bench import load, tags

    import hybridsub

    m = load(args.mesh)
    print(f"{args.mesh} × {args.levels}, NUMBA_NUM_THREADS={args.threads}, cProfile on process CPU time, "
          f"{args.calls} calls; ms per call\n")
    for variant in args.variants:
        edges, kw = tags(m, variant)

        def call():
            hybridsub.subdivide(m.V, m.F, edges, levels=args.levels, **kw)

        call(), call()
        prof = cProfile.Profile(time.process_time)
        prof.enable()
        for _ in range(args.calls):
            call()
        prof.disable()
        stats = pstats.Stats(prof).stats  # (file, line, name) -> (cc, nc, tottime, cumtime, callers)
        total = sum(v[2] for v in stats.values()) / args.calls
        me = os.path.abspath(__file__)
        own = sorted(((v[2] / args.calls, k) for k, v in stats.items() if os.path.abspath(k[0]) != me), reverse=True)
        own = own[:args.rows]
        print(f"| {variant} | ms per call | share |\n|---|---|---|")
        for t, (path, line, name) in own:
            where = os.path.splitext(os.path.basename(path))[0] + "." if path != "~" else ""
            print(f"| `{where}{name}` | {1e3 * t:.1f} | {t / total:.0%} |")
        rest = total - sum(t for t, _ in own)
        print(f"| the rest | {1e3 * rest:.1f} | {rest / total:.0%} |\n| **total** | **{1e3 * total:.1f}** | |\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
