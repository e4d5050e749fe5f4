"""The limit surface anywhere beside OpenSubdiv Bfr: accuracy and evaluations per second.

usage: python benchmarks/limit_surface.py [--points N] [--seed S] [--repeat R] [--schemes S ...]
                                         [--meshes M ...] [--reference tests/data/NAME.npz]

For each mesh (``cylinder``: a CAD part of 384 faces, a 24-sided cylinder split 1-to-4 once, its
two rims 96 crease edges at 90°; ``cube-meshed``: the shipped CAD cube, 1,728 faces; ``fandisk``:
12,946 faces), with the creases ``detect_features`` finds at 30°: N random points (face, bary)
evaluated with derivatives by ``hybridsub.LimitSurface`` (``"loop"``, ``"hybrid"``; ``"sqrt3"``
on the same points without the creases, which Kobbelt's scheme does not take) and by OpenSubdiv
Bfr (Loop, its default approximation levels, ``benchmarks/peers/osd_bfr``, built by
``benchmarks/peers/build.sh``; skipped with a note when it is not built). Prints per scheme:

- ``first``: the first ``evaluate`` of N points on a new surface (after a warm-up call on another
  surface that compiles the kernels): it fills the surface's patch cache;
- ``new``: then N *other* random points on the same surface (issue 30's measure: new points after
  a warm-up call);
- ``again``: the median of ``R`` more calls on those points (every patch known);

each in points per second and against Bfr's rate on the same N points, and for Loop the distance
between the two on Bfr's regular patches (where Bfr is exact) and elsewhere, in units of the
bounding-box diagonal. Run it with ``NUMBA_NUM_THREADS=1`` for the per-core comparison (Bfr runs on
one core). ``--reference`` writes the Bfr values of the first 64 fandisk points on regular patches,
for ``tests/test_limit_surface.py``.
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
import hybridsub._surface.surface as surface_module

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


def cylinder():
    """A CAD part of a few hundred faces: a 24-sided closed cylinder split 1-to-4 once (384 faces;
    its rims are 90° creases, the caps' centres valence 24)."""
    import trimesh

    m = trimesh.creation.cylinder(radius=1.0, height=2.0, sections=24).subdivide()
    return np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)


def mesh(name: str):
    if name == "fandisk":
        return hybridsub.load_example()
    if name == "cylinder":
        return cylinder()
    m = hybridsub.read_mesh(HERE.parent.parent / "shared" / "meshes" / f"{name}.off")
    return m.vertices, m.faces


def points(F, n: int, seed: int):
    rng = np.random.default_rng(seed)
    return np.sort(rng.integers(0, len(F), n)), rng.dirichlet([1, 1, 1], n)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--schemes", nargs="+", default=["loop", "sqrt3", "hybrid"])
    ap.add_argument("--meshes", nargs="+", default=["cylinder", "fandisk"])
    ap.add_argument("--reference", type=pathlib.Path)
    a = ap.parse_args()
    have_bfr = (HERE / "peers" / "bin" / "osd_bfr").exists()
    if not have_bfr:
        print("Bfr: benchmarks/peers/bin/osd_bfr not built (benchmarks/peers/build.sh); timing ours only")
    V0, F0 = hybridsub.load_example()
    for scheme in a.schemes:  # compile every kernel first, on another surface
        hybridsub.LimitSurface(V0, F0, scheme=scheme).evaluate(*points(F0, 64, 99), derivatives=True)
    for name in a.meshes:
        V, F = mesh(name)
        feat = hybridsub.detect_features(V, F, angle=30)
        diag = float(np.linalg.norm(V.max(0) - V.min(0)))
        face0, bary0 = points(F, a.points, a.seed + 1)  # the warm-up call's points
        face, bary = points(F, a.points, a.seed)  # the new points
        print(f"{name}: {len(F):,} faces, {len(feat.sharp_edges)} crease edges, {a.points:,} points")
        bfr_rate = None
        if have_bfr:
            with tempfile.TemporaryDirectory() as tmp:
                off = pathlib.Path(tmp) / f"{name}.off"
                hybridsub.write_mesh(off, V, F)
                info, regular, P_osd, Du_osd, Dv_osd = bfr(off, feat.sharp_edges, face, bary[:, 1:])
            bfr_rate = a.points / info["evaluate"]["min"]
            print(f"  Bfr: {bfr_rate:.3g} points/s, regular patches {regular.mean():.0%}")
        for scheme in a.schemes:
            edges = None if scheme == "sqrt3" else feat.sharp_edges  # Kobbelt's √3 has no feature tags
            surface_module._TABLES.clear()  # "first": a process's first surface of its kind
            t_setup, s = median_time(lambda: hybridsub.LimitSurface(V, F, edges, scheme=scheme), 1)
            t_first, _ = median_time(lambda: s.evaluate(face0, bary0, derivatives=True), 1)
            t_new, _ = median_time(lambda: s.evaluate(face, bary, derivatives=True), 1)
            t_again, (P, Du, Dv) = median_time(lambda: s.evaluate(face, bary, derivatives=True), a.repeat)
            cells = []
            for what, t in (("first", t_first), ("new", t_new), ("again", t_again)):
                rate = a.points / t
                cells.append(f"{what} {rate:.3g}/s" + (f" ({rate / bfr_rate:.2f}× Bfr)" if bfr_rate else ""))
            line = f"  {scheme}: setup {t_setup:.3f} s; " + ", ".join(cells)
            if scheme == "loop" and have_bfr:
                err = np.linalg.norm(P - P_osd, axis=1) / diag
                if regular.any():
                    line += f"; |ours − Bfr| / diagonal: regular patches max {err[regular].max():.2e}"
                if not regular.all():
                    line += f", elsewhere max {err[~regular].max():.2e}, median {np.median(err[~regular]):.2e}"
                if a.reference is not None and name == "fandisk":
                    pick = np.flatnonzero(regular)[:64]
                    np.savez_compressed(a.reference, face=face[pick], bary=bary[pick], P=P_osd[pick],
                                        Du=Du_osd[pick], Dv=Dv_osd[pick], sharp_edges=feat.sharp_edges)
            print(line, flush=True)


if __name__ == "__main__":
    main()
