"""Adaptive refinement against uniform refinement (docs/adaptive.md): faces, time, error.

1. Tolerance: CAD parts with their 30° creases, each scheme, tolerance 2e-4 × the diagonal.
   The adaptive result's faces and time beside the coarsest uniform level that is as close
   (its error measured the same way: corners at the limit, edge midpoints and centroids on
   the limit surface, over the input faces where the adaptive refinement went deepest and
   a random 2 % of the others: the whole uniform level would take minutes to evaluate).
   Where a uniform level is already four times the adaptive face count and still not as close,
   the uniform levels above it are not measured (the ratio is then below adaptive / that
   level's faces, printed as "< x"; the time printed is then the next level's, a lower
   bound on the time of the level as close). "s" is a process's first call at that tolerance
   (kernels compiled, no patch built), "again" the call repeated (the limit surface's patches
   known: they are kept per kind of surface, docs/limit.md). The last column measures the adaptive output
   without the chart, both ways (the tests' oracle, ``tests/test_adaptive.py::_two_sided_error``,
   on 3,000 faces × 15 points projected onto the surface and 200,000 surface points).
2. Selective: a patch of 15 % of the faces refined 3 levels, against uniform level 3.
3. Throughput of the topology pass (refine_adaptive, one thread): output faces per second.
4. Face-varying data (one thread): the textured bunny of the tests (its UV seams), the 15 %
   patch to 3 levels and Loop to 0.1 % of the diagonal, with and without ``uv_faces=``.

The tolerance and selective parts run on the default threads, the throughput on one.

    python benchmarks/adaptive.py [--meshes fandisk,cube-meshed,mesh_with_border] [--quick]
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

from _bench import ROOT, cpu_name

import hybridsub
import hybridsub._surface.surface as surface_module
from hybridsub._surface.adaptive import adaptive_result, uniform_error

sys.path.insert(0, os.path.join(ROOT, "tests"))
from test_adaptive import _two_sided_error  # noqa: E402  (the tests' oracle, not a copy)

MESHES = {"fandisk": os.path.join(ROOT, "hybridsub", "data", "fandisk.off"),
          "cube-meshed": os.path.join(ROOT, "tests", "data", "cube-meshed.off"),
          "mesh_with_border": os.path.join(ROOT, "tests", "data", "mesh_with_border.off")}  # open: Kobbelt's boundary
SCHEMES = ("hybrid", "loop", "sqrt3")


def load(name):
    m = hybridsub.read_mesh(MESHES[name])
    V, F = m.vertices, m.faces
    feat = hybridsub.detect_features(V, F, 30)
    return V, F, feat


def tags_of(feat, scheme):
    return {} if scheme == "sqrt3" else dict(sharp_edges=feat.sharp_edges, corners=feat.corners)


def tolerance_row(name, scheme, rel, quick):
    V, F, feat = load(name)
    tags = tags_of(feat, scheme)
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    tol = rel * diag
    adaptive_result(V, F, tolerance=tol * 20, scheme=scheme, **tags)  # compile and warm up
    surface_module._TABLES.clear()  # the patches as a process's first call builds them
    t = time.perf_counter()
    res = adaptive_result(V, F, tolerance=tol, scheme=scheme, **tags)
    t_ad = time.perf_counter() - t
    t = time.perf_counter()
    adaptive_result(V, F, tolerance=tol, scheme=scheme, **tags)  # the patches known
    t_again = time.perf_counter() - t
    n_ad = len(res.refinement.faces)
    top = res.refinement.face_level.max()
    deep = np.unique(res.refinement.face_parent[res.refinement.face_level == top])
    rng = np.random.default_rng(0)
    probe = np.union1d(deep, np.flatnonzero(rng.random(len(F)) < 0.02))
    surface = hybridsub.LimitSurface(V, F, scheme=scheme, **tags)
    both = _two_sided_error(V, F, res.positions, res.refinement.faces, surface, faces=3000, points=200000)
    out = dict(mesh=name, scheme=scheme, tol=tol, faces=n_ad, seconds=t_ad, again=t_again, error=res.error,
               levels=np.bincount(res.refinement.face_level).tolist(), both=both)
    for L in range(0, 9):
        n_u = len(hybridsub.refine(F, levels=L, scheme=scheme, **tags).faces)
        if n_u > (3e6 if quick else 1.2e7):
            out["uniform"] = (f"> L{L - 1}", None, None, None)
            out["ratio"] = f"< {n_ad / n_u:.3f}"
            break
        err = uniform_error(V, F, L, only=probe, scheme=scheme, **tags)
        if err > tol and n_u >= 4 * n_ad:
            # The level as close is L + 1 or finer: its time is at least level L + 1's.
            hybridsub.subdivide(V, F, levels=L + 1, scheme=scheme, **tags)
            t = time.perf_counter()
            hybridsub.subdivide(V, F, levels=L + 1, scheme=scheme, **tags)
            out["uniform"] = (f"> L{L}", n_u, err, time.perf_counter() - t)
            out["ratio"] = f"< {n_ad / n_u:.3f}"
            break
        if err <= tol:
            hybridsub.subdivide(V, F, levels=L, scheme=scheme, **tags)
            t = time.perf_counter()
            hybridsub.subdivide(V, F, levels=L, scheme=scheme, **tags)
            t_u = time.perf_counter() - t
            out["uniform"] = (f"L{L}", n_u, err, t_u)
            out["ratio"] = f"{n_ad / n_u:.3f}"
            break
    return out


def selective_row(name, scheme):
    V, F, feat = load(name)
    tags = tags_of(feat, scheme)
    c = V[F].mean(axis=1)
    where = np.argsort(np.linalg.norm(c - c[0], axis=1))[: int(0.15 * len(F))]
    r = hybridsub.refine_adaptive(F, where=where, levels=3, scheme=scheme, **tags)
    u = hybridsub.refine(F, levels=3, scheme=scheme, **tags)
    return dict(mesh=name, scheme=scheme, faces=len(r.faces), uniform=len(u.faces), ratio=len(r.faces) / len(u.faces))


def throughput_row(name, scheme, levels):
    V, F, feat = load(name)
    tags = tags_of(feat, scheme)
    c = V[F].mean(axis=1)
    where = np.argsort(np.linalg.norm(c - c[0], axis=1))[: int(0.15 * len(F))]
    hybridsub.refine_adaptive(F, where=where, levels=1, scheme=scheme, **tags)
    best = np.inf
    for _ in range(3):
        t = time.perf_counter()
        r = hybridsub.refine_adaptive(F, where=where, levels=levels, scheme=scheme, **tags)
        best = min(best, time.perf_counter() - t)
    return dict(mesh=name, scheme=scheme, levels=levels, faces=len(r.faces), seconds=best,
                rate=len(r.faces) / best)


def uv_row(scheme):
    d = np.load(os.path.join(ROOT, "tests", "data", "bunny10k_textured.fvar_linear.L1.npz"))
    V, F, FUV = d["V_in"], d["F_in"], d["FUV_in"]
    c = V[F].mean(axis=1)
    where = np.argsort(np.linalg.norm(c - c[0], axis=1))[: int(0.15 * len(F))]
    calls = {"patch": dict(where=where, levels=3)}
    if scheme == "loop":
        calls["0.1%"] = dict(V=V, tolerance="0.1%")
    out = {}
    for what, kw in calls.items():
        for uv in (False, True):
            extra = dict(uv_faces=FUV) if uv else {}
            r = hybridsub.refine_adaptive(F, scheme=scheme, **kw, **extra)
            best = np.inf
            for _ in range(3):
                t = time.perf_counter()
                hybridsub.refine_adaptive(F, scheme=scheme, **kw, **extra)
                best = min(best, time.perf_counter() - t)
            out[what, uv] = (len(r.faces), best)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="fandisk,cube-meshed")
    ap.add_argument("--schemes", default=",".join(SCHEMES))
    ap.add_argument("--quick", action="store_true", help="uniform levels up to 3M faces only")
    ap.add_argument("--only", choices=("tolerance", "selective", "throughput", "uv"))
    a = ap.parse_args()
    names = a.meshes.split(",")
    print(f"# hybridsub {hybridsub.__version__}, {cpu_name()}, {os.cpu_count()} cores")
    if a.only in (None, "tolerance"):
        print("\n## tolerance 2e-4 × diagonal: adaptive against the coarsest uniform level as close")
        print(f"{'mesh':12} {'scheme':7} {'adaptive faces':>14} {'s':>6} {'again':>6} {'error/tol':>9}  levels (faces at 0, 1, …)"
              f"  | {'uniform':>7} {'faces':>10} {'error/tol':>9} {'s':>6} | faces ratio | both ways / tol")
        for name in names:
            for scheme in a.schemes.split(","):
                o = tolerance_row(name, scheme, 2e-4, a.quick)
                lev, n_u, e_u, t_u = o["uniform"]
                e_txt = "" if e_u is None else f"{e_u / o['tol']:.3f}"
                t_txt = "" if t_u is None else f"{t_u:.2f}"
                n_txt = f"{n_u:,}" if n_u else ""
                print(f"{name:12} {scheme:7} {o['faces']:>14,} {o['seconds']:>6.2f} {o['again']:>6.2f} {o['error'] / o['tol']:>9.3f}  "
                      f"{o['levels']}  | {lev:>7} {n_txt:>10} {e_txt:>9} {t_txt:>6} | {o['ratio']} | {o['both'] / o['tol']:.3f}",
                      flush=True)
    if a.only in (None, "selective"):
        print("\n## 15 % of the faces (a patch) to 3 levels, against uniform level 3")
        for name in names:
            for scheme in SCHEMES:
                o = selective_row(name, scheme)
                print(f"{name:12} {scheme:7} {o['faces']:>10,} of {o['uniform']:>10,}  ratio {o['ratio']:.3f}",
                      flush=True)
    if a.only in (None, "throughput"):
        hybridsub.set_threads(1)
        print("\n## topology pass (refine_adaptive, a 15 % patch), one thread")
        for scheme in SCHEMES:
            o = throughput_row("fandisk", scheme, 4 if scheme == "loop" else 5)
            print(f"fandisk      {scheme:7} L{o['levels']}: {o['faces']:>10,} faces in {o['seconds']:.3f} s = "
                  f"{o['rate'] / 1e6:.2f} M faces/s", flush=True)

    if a.only in (None, "uv"):
        hybridsub.set_threads(1)
        print("\n## with UVs (uv_faces=), the textured bunny (9,999 faces, 1,289 seams), one thread")
        for scheme in ("hybrid", "loop"):
            for (what, uv), (n, t) in uv_row(scheme).items():
                print(f"bunny        {scheme:7} {what:6} {'with UVs' if uv else 'no UVs':9} {n:>9,} faces "
                      f"{t * 1e3:8.1f} ms", flush=True)


if __name__ == "__main__":
    main()
