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
import sys
import time

import numpy as np

import hybridsub

DATA = pathlib.Path(__file__).resolve().parent.parent / "tests" / "data"
sys.path.insert(0, str(DATA.parent))
from test_limit_surface import split_edge_vertices  # noqa: E402  (the test's oracle, the same points)


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
        s, face, bary, ref = split_edge_vertices(tags, V, F)
        t = time.perf_counter()
        N = s.normals(face, bary)
        dt = time.perf_counter() - t
        angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", N, ref), -1, 1)))
        print(f"{name:32s} {len(face):5d} points  max {angle.max():.3g}°  median {np.median(angle):.3g}°  ({dt:.2f} s)")


if __name__ == "__main__":
    main()
