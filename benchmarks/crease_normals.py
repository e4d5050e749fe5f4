"""Normals of ``LimitSurface`` on the hybrid's split edges against the vertices' tangent masks.

    python benchmarks/crease_normals.py

The oracle is independent of the walk: the vertices of uniform refinement level 2 that lie inside
input edges split beside a √3 face (fandisk's creases at 30°; the boundary of the open patch
``mesh_with_border``; fandisk with half its faces sharp, whose sharp/smooth interface edges are
split without a tag), their sector normals on their input face's side from
``limit_normals(per_face_corner=True)`` (stationary tangent masks), beside
``LimitSurface.normals`` at the same points (``refine(...).vertex_origin``) at the default depth.
Prints the largest and median angle in degrees per case, and the time of the normals call.
"""

from __future__ import annotations

import pathlib
import time

import numpy as np

import hybridsub
from hybridsub._surface.edge_fit import on_split_edge

DATA = pathlib.Path(__file__).resolve().parent.parent / "tests" / "data"


def cases():
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, angle=30)
    yield "fandisk, creases at 30°", V, F, dict(scheme="hybrid", sharp_edges=feat.sharp_edges, corners=feat.corners)
    m = hybridsub.read_mesh(DATA / "mesh_with_border.off")
    yield "mesh_with_border, boundary", np.asarray(m.vertices, float), np.asarray(m.faces, np.int64), dict(scheme="hybrid")
    half = np.zeros(len(F), bool)
    half[: len(F) // 2] = True
    yield "fandisk, half the faces sharp", V, F, dict(scheme="hybrid", sharp_faces=half)


def main():
    for name, V, F, tags in cases():
        s = hybridsub.LimitSurface(V, F, **tags)
        r = hybridsub.refine(F, levels=2, **tags)
        f0, b0 = r.vertex_origin
        idx, _ = on_split_edge(s._depths, f0, b0)
        NC = hybridsub.limit_normals(V, F, levels=2, per_face_corner=True, **tags)
        fp = np.asarray(r.face_parent)
        ref = []
        for v in idx:
            rows, cols = np.nonzero(r.faces == v)
            side = np.flatnonzero(fp[rows] == f0[v])[0]
            ref.append(NC[rows[side], cols[side]])
        t = time.perf_counter()
        N = s.normals(f0[idx], b0[idx])
        dt = time.perf_counter() - t
        angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", N, np.array(ref)), -1, 1)))
        print(f"{name:32s} {len(idx):5d} points  max {angle.max():.3g}°  median {np.median(angle):.3g}°  ({dt:.2f} s)")


if __name__ == "__main__":
    main()
