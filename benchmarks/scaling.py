#!/usr/bin/env python
"""How hybridsub's time grows with the output: subdivide over levels, meshes and schemes.

usage: python benchmarks/scaling.py [--levels L ...] [--repeat N] [--max-faces M]
                                    [--out docs/images/scaling.png] [--csv OUT.csv]

Times ``subdivide`` (median of warm runs, measured as compare.py measures) on icosahedron,
fandisk and armadillo at each level for each variant (sqrt3, loop, loop with 30° creases,
hybrid), and plots time against output faces, log-log, with a line of slope 1 (linear time)
for reference. Needs matplotlib (the ``plot`` extra).
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import time

from _bench import ROOT, VARIANTS, cpu_name, load, measure, tags

import hybridsub

MESHES = ["icosahedron", "fandisk", "armadillo"]
DEFAULT_LEVELS = {"icosahedron": [1, 2, 3, 4, 5, 6, 7]}  # up to 327k faces: meets fandisk's sizes; others 1–4
MARKERS = {"icosahedron": "^", "fandisk": "s", "armadillo": "o"}


def predicted_faces(n_faces: int, variant: str, levels: int) -> int:
    """Output size of sqrt3 (×3) and loop (×4) per level; hybrid lies between (at most ×4)."""
    return n_faces * (3 if VARIANTS[variant]["scheme"] == "sqrt3" else 4) ** levels


def run(levels, repeat, max_faces, log=print) -> list:
    rows = []
    for name in MESHES:
        m = load(name)
        for variant in VARIANTS:
            edges, kw = tags(m, variant)
            for L in levels or DEFAULT_LEVELS.get(name, [1, 2, 3, 4]):
                if predicted_faces(len(m.F), variant, L) > max_faces:
                    continue
                t = measure(lambda: (m.V, m.F), lambda inp: hybridsub.subdivide(inp[0], inp[1], edges, levels=L, **kw),
                            repeat=repeat, budget=30.0, counts=lambda out: (len(out[0]), len(out[1])))
                rows.append(dict(mesh=name, variant=variant, levels=L, vertices=t.counts[0], faces=t.counts[1],
                                 median_s=t.median, min_s=t.min, runs=t.runs))
                log(f"{name:12s} {variant:13s} L{L}  {t.counts[1]:>11,} faces  {t.median * 1e3:9.2f} ms"
                    f"  {t.counts[1] / t.median / 1e6:6.2f} M faces/s")
    return rows


def plot(rows, path: str, machine: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.5))
    colors = dict(zip(VARIANTS, plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    for variant in VARIANTS:
        for name in MESHES:
            pts = sorted((r["faces"], r["median_s"]) for r in rows if r["variant"] == variant and r["mesh"] == name)
            if not pts:
                continue
            f, t = zip(*pts)
            label = variant if name == MESHES[-1] else None
            ax.plot(f, t, marker=MARKERS[name], color=colors[variant], label=label, alpha=0.85)
            bx.plot(f, [x / y / 1e6 for x, y in pts], marker=MARKERS[name], color=colors[variant], alpha=0.85)
    if rows:  # slope 1 through the largest output
        big = max(rows, key=lambda r: r["faces"])
        lo = min(r["faces"] for r in rows)
        ax.plot([lo, big["faces"]], [big["median_s"] * lo / big["faces"], big["median_s"]], "k:", lw=1,
                label="linear time")
    for name, mk in MARKERS.items():
        ax.plot([], [], mk, color="gray", label=name)
    ax.set(xscale="log", yscale="log", xlabel="output faces", ylabel="subdivide, median (s)",
           title="time against output size")
    bx.set(xscale="log", xlabel="output faces", ylabel="million output faces per second", title="throughput")
    ax.legend(fontsize=8)
    for a in (ax, bx):
        a.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"hybridsub {hybridsub.__version__}: subdivide, warm, median of runs — {machine}", fontsize=9)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=120)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--levels", type=int, nargs="+", help="default: 1-4 (icosahedron 1-7)")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--max-faces", type=int, default=15_000_000, help="skip outputs larger than this")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "images", "scaling.png"))
    ap.add_argument("--csv", help="also write the numbers here")
    args = ap.parse_args(argv)
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        print("scaling.py needs matplotlib: pip install matplotlib (or the project's plot extra)", file=sys.stderr)
        return 2
    load_start = os.getloadavg()[0]
    rows = run(args.levels, args.repeat, args.max_faces)
    plot(rows, args.out, f"{cpu_name()}, {os.cpu_count()} CPUs, {time.strftime('%Y-%m-%d')}, "
                         f"load {load_start:.1f} → {os.getloadavg()[0]:.1f}")
    print(f"wrote {args.out}")
    if args.csv:
        with open(args.csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
