"""The limit surface anywhere beside OpenSubdiv Bfr: accuracy and evaluations per second.

usage: python benchmarks/limit_surface.py [--points N] [--seed S] [--repeat R] [--schemes S ...]
                                         [--reference tests/data/NAME.npz]

Samples N random points (face, bary) of fandisk with its detected creases (30°), evaluates
them with ``hybridsub.LimitSurface`` (``"loop"``, ``"hybrid"``; ``"sqrt3"`` on the same points
without the creases, which Kobbelt's scheme does not take) and with OpenSubdiv Bfr (Loop,
its default approximation levels, ``benchmarks/peers/osd_bfr``, built by
``benchmarks/peers/build.sh``; skipped with a note when it is not built), and prints: setup
time, the time of the first ``evaluate(..., derivatives=True)`` of the points (after a
warm-up call on another surface that compiles the kernels: this one fills the surface's patch
cache), the median time of ``R`` more runs (the cache filled), points per second, and the distance between the two
on Bfr's regular patches (where Bfr is exact) and elsewhere, in units of the bounding-box
diagonal. ``--reference`` writes the Bfr values
of the first 64 points on regular patches, for ``tests/test_limit_surface.py``.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import subprocess
import tempfile
import time

import numpy as np

import hybridsub

HERE = pathlib.Path(__file__).resolve().parent


def bfr(off: pathlib.Path, creases: np.ndarray, face: np.ndarray, uv: np.ndarray, extra=()):
    exe = HERE / "peers" / "bin" / "osd_bfr"
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        np.savetxt(tmp / "pts.txt", np.c_[face, uv], fmt=["%d", "%.17g", "%.17g"])
        np.savetxt(tmp / "creases.txt", creases, fmt="%d")
        out = subprocess.run([str(exe), str(off), str(tmp / "pts.txt"), "--creases", str(tmp / "creases.txt"),
                              "--out", str(tmp / "res.txt"), *extra], check=True, capture_output=True, text=True)
        res = np.loadtxt(tmp / "res.txt").reshape(-1, 10)
    return json.loads(out.stdout), res[:, 0].astype(bool), res[:, 1:4], res[:, 4:7], res[:, 7:10]


def median_time(fn, repeat=3):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times)), out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--schemes", nargs="+", default=["loop", "hybrid"])
    ap.add_argument("--reference", type=pathlib.Path)
    a = ap.parse_args()
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, angle=30)
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    rng = np.random.default_rng(a.seed)
    face = np.sort(rng.integers(0, len(F), a.points))
    bary = rng.dirichlet([1, 1, 1], a.points)
    have_bfr = (HERE / "peers" / "bin" / "osd_bfr").exists()
    if have_bfr:
        with tempfile.TemporaryDirectory() as tmp:
            off = pathlib.Path(tmp) / "fandisk.off"
            hybridsub.write_mesh(off, V, F)
            info, regular, P_osd, Du_osd, Dv_osd = bfr(off, feat.sharp_edges, face, bary[:, 1:])
        print(f"Bfr: setup {info['setup']['min']:.4f} s, evaluate {info['evaluate']['min']:.4f} s "
              f"({a.points / info['evaluate']['min']:.3g} points/s), regular patches {regular.mean():.0%}")
    else:
        print("Bfr: benchmarks/peers/bin/osd_bfr not built (benchmarks/peers/build.sh); timing ours only")
    for scheme in a.schemes:
        edges = None if scheme == "sqrt3" else feat.sharp_edges  # Kobbelt's √3 has no feature tags
        t_setup, s = median_time(lambda: hybridsub.LimitSurface(V, F, edges, scheme=scheme), 1)
        hybridsub.LimitSurface(V, F, edges, scheme=scheme).evaluate(face[:8], bary[:8], derivatives=True)  # compiles
        t_first, _ = median_time(lambda: s.evaluate(face, bary, derivatives=True), 1)
        t_eval, (P, Du, Dv) = median_time(lambda: s.evaluate(face, bary, derivatives=True), a.repeat)
        line = (f"{scheme}: setup {t_setup:.3f} s, first evaluate {t_first:.3f} s ({a.points / t_first:.3g} points/s, "
                f"fills the patch cache), again {t_eval:.3f} s ({a.points / t_eval:.3g} points/s)")
        if scheme == "loop" and have_bfr:
            err = np.linalg.norm(P - P_osd, axis=1) / diag
            line += (f"; |ours − Bfr| / diagonal: regular patches max {err[regular].max():.2e}, "
                     f"elsewhere max {err[~regular].max():.2e}, median {np.median(err[~regular]):.2e}")
            if a.reference is not None:
                pick = np.flatnonzero(regular)[:64]
                np.savez_compressed(a.reference, face=face[pick], bary=bary[pick], P=P_osd[pick], Du=Du_osd[pick],
                                    Dv=Dv_osd[pick], sharp_edges=feat.sharp_edges)
        print(line, flush=True)


if __name__ == "__main__":
    main()
