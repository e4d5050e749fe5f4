"""Figure of docs/limit.md: a CAD part's Loop limit surface on a fine parameter grid, with its
crease curves, and how far OpenSubdiv Bfr's default evaluation is from it.

    benchmarks/peers/build.sh && python benchmarks/limit_figure.py [--mesh cube-meshed] [--n 5]
                                                                    # writes docs/images/limit_bfr.png

Every input face is cut into an n × n triangular grid of parameters; ``LimitSurface`` (Loop,
the mesh's 30° creases from ``detect_features``) and Bfr (its default approximation levels,
``benchmarks/peers/osd_bfr``) evaluate every grid point. Left: our surface, the crease curves
evaluated along the crease edges in red. Right: the same grid coloured by the distance between
Bfr's value and ours, over the bounding-box diagonal (log scale; below 1e-15 drawn as 1e-15).
"""

from __future__ import annotations

import argparse
import os
import pathlib
import sys
import tempfile
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402

import hybridsub  # noqa: E402

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from limit_surface import bfr  # noqa: E402
from _bench import frame_3d  # noqa: E402

OUT = HERE.parent / "docs" / "images"


def face_grid(n: int):
    """Barycentric points (p, 3) of an n × n triangular grid of one face and its small
    triangles (t, 3) over those points."""
    ij = [(i, j) for i in range(n + 1) for j in range(n + 1 - i)]
    index = {p: k for k, p in enumerate(ij)}
    bary = np.array([(n - i - j, i, j) for i, j in ij], dtype=float) / n
    tris = [(index[i, j], index[i + 1, j], index[i, j + 1]) for i, j in ij if i + j < n]
    tris += [(index[i + 1, j], index[i + 1, j + 1], index[i, j + 1]) for i, j in ij if i + j < n - 1]
    return bary, np.array(tris)


def crease_points(F: np.ndarray, creases: np.ndarray, k: int):
    """(face, bary) of k + 1 points along each crease edge, on a face that holds the edge."""
    face, bary = [], []
    t = np.linspace(0.0, 1.0, k + 1)
    for a, b in creases:
        f = np.flatnonzero(((F == a) | (F == b)).sum(axis=1) == 2)[0]
        ia, ib = list(F[f]).index(a), list(F[f]).index(b)
        B = np.zeros((k + 1, 3))
        B[:, ia], B[:, ib] = 1 - t, t
        face.append(np.full(k + 1, f)), bary.append(B)
    return np.concatenate(face), np.concatenate(bary)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", default="cube-meshed", help="a mesh of ../shared/meshes or a path (default %(default)s)")
    ap.add_argument("--n", type=int, default=5, help="grid cuts per face edge (default %(default)s; not a power of two, or the points are vertices of a refined level, where Bfr is exact)")
    a = ap.parse_args()
    path = pathlib.Path(a.mesh)
    if not path.exists():
        path = HERE.parent.parent / "shared" / "meshes" / f"{a.mesh}.off"
    mesh = hybridsub.read_mesh(path)
    V, F = mesh.vertices, mesh.faces
    creases = np.asarray(hybridsub.detect_features(V, F, angle=30).sharp_edges).reshape(-1, 2)
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    bary1, tris1 = face_grid(a.n)
    face = np.repeat(np.arange(len(F)), len(bary1))
    bary = np.tile(bary1, (len(F), 1))
    s = hybridsub.LimitSurface(V, F, creases, scheme="loop")
    t = time.perf_counter()
    P = s.evaluate(face, bary)
    t_ours = time.perf_counter() - t
    cf, cb = crease_points(F, creases, 8)
    C = s.evaluate(cf, cb).reshape(len(creases), 9, 3)
    with tempfile.TemporaryDirectory() as tmp:
        off = pathlib.Path(tmp) / "part.off"
        hybridsub.write_mesh(off, V, F)
        info, regular, P_osd, _, _ = bfr(off, creases, face, bary[:, 1:])
    err = np.linalg.norm(P - P_osd, axis=1) / diag
    print(f"{path.name}: {len(F)} faces, {len(creases)} crease edges, {len(face)} points; ours {t_ours:.1f} s, "
          f"Bfr {info['evaluate']['min']:.3f} s; regular patches {regular.mean():.0%}: max |Bfr − ours| / diag "
          f"{err[regular].max():.1e}; elsewhere max {err[~regular].max():.1e}, median {np.median(err[~regular]):.1e}")
    tris = (tris1[None] + len(bary1) * np.arange(len(F))[:, None, None]).reshape(-1, 3)
    fig = plt.figure(figsize=(11, 5.2))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    ax.computed_zorder = False
    light = np.array([0.4, -0.5, 0.8]) / np.linalg.norm([0.4, -0.5, 0.8])
    N = np.cross(P[tris[:, 1]] - P[tris[:, 0]], P[tris[:, 2]] - P[tris[:, 0]])
    shade = 0.35 + 0.6 * np.abs(N @ light) / np.maximum(np.linalg.norm(N, axis=1), 1e-300)
    ax.add_collection3d(Poly3DCollection(P[tris], facecolors=plt.cm.gray(shade), linewidths=0, zorder=1))
    segs = np.concatenate([C[:, :-1, None], C[:, 1:, None]], axis=2).reshape(-1, 2, 3)
    ax.add_collection3d(Line3DCollection(segs, colors="crimson", linewidths=0.8, zorder=2))
    frame_3d(ax, P, f"Loop limit surface, {len(face):,} grid points,\ncrease curves in red", azim=-55)
    ax = fig.add_subplot(1, 2, 2, projection="3d")
    e = np.maximum(err[tris].max(axis=1), 1e-15)
    norm = LogNorm(1e-15, max(float(e.max()), 1e-14))
    ax.add_collection3d(Poly3DCollection(P[tris], facecolors=plt.cm.magma(norm(e)), linewidths=0))
    frame_3d(ax, P, f"|Bfr (default levels) − exact| / diagonal:\nmax {err.max():.1e}; exact (≤ 1e-15) on "
                    f"{(err <= 1e-15).mean():.0%} of the points", azim=-55)
    fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap="magma"), ax=ax, shrink=0.6)
    fig.tight_layout()
    os.makedirs(OUT, exist_ok=True)
    fig.savefig(OUT / "limit_bfr.png", dpi=110)


if __name__ == "__main__":
    main()
