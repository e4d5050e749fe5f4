"""The accuracy tables of docs/limit.md ("Accuracy"): LimitSurface.evaluate against deeper walks.

1. Random points: 300 random points of fandisk (creases at 30°; "sqrt3" without tags), at
   ``depth=`` 16, the default and 24, against the same points at depth 32: the largest
   position error over the diagonal and ``Du`` error over the largest |Du|.
2. Points next to irregular vertices and creases: 3000 points per case on the faces that get
   deeper walks (towards a corner or an edge at distances 10⁻¹² … 1, log-uniform, or anywhere),
   at a fixed default depth (the per-point rule switched off) and with the rule, against the
   same points at depth 56.

    python benchmarks/limit_accuracy.py
"""

from __future__ import annotations

import os
import sys

import numpy as np

from _bench import ROOT

import hybridsub

sys.path.insert(0, os.path.join(ROOT, "tests"))
from test_limit_surface import _near_features as near_features  # noqa: E402  (the tests' sampler, not a copy)

MESH_WITH_BORDER = os.path.join(ROOT, "tests", "data", "mesh_with_border.off")


def diag(V):
    return float(np.linalg.norm(V.max(0) - V.min(0)))


def random_points():
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, 30)
    rng = np.random.default_rng(0)
    face, bary = rng.integers(0, len(F), 300), rng.dirichlet([1, 1, 1], 300)
    print("| scheme | `depth=` | position error / diagonal | `Du` error / max \\|Du\\| |")
    print("|---|---|---|---|")
    for scheme, tags, depths in (("hybrid", dict(sharp_edges=feat.sharp_edges), (16, 18, 24)),
                                 ("sqrt3", {}, (16, 18, 24)), ("loop", dict(sharp_edges=feat.sharp_edges), (12, 14))):
        ref, dref, _ = hybridsub.LimitSurface(V, F, scheme=scheme, depth=32, **tags).evaluate(face, bary, True)
        for d in depths:
            P, Du, _ = hybridsub.LimitSurface(V, F, scheme=scheme, depth=d, **tags).evaluate(face, bary, True)
            e = np.linalg.norm(P - ref, axis=1).max() / diag(V)
            ed = np.linalg.norm(Du - dref, axis=1).max() / np.linalg.norm(dref, axis=1).max()
            print(f"| `\"{scheme}\"` | {d} | {e:.1e} | {ed:.1e} |")


def near_points():
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, 30)
    m = hybridsub.read_mesh(MESH_WITH_BORDER)
    half = np.arange(len(F)) < len(F) // 2
    cases = [("`\"hybrid\"`, creases at 30°", V, F, dict(sharp_edges=feat.sharp_edges, corners=feat.corners)),
             ("`\"hybrid\"`, half the faces sharp", V, F, dict(sharp_faces=half)),
             ("`\"hybrid\"`, open patch (`mesh_with_border`)", m.vertices, m.faces, {}),
             ("`\"sqrt3\"`, closed", V, F, dict(scheme="sqrt3")),
             ("`\"sqrt3\"`, open patch (Kobbelt's boundary)", m.vertices, m.faces, dict(scheme="sqrt3")),
             ("`\"loop\"`, creases", V, F, dict(scheme="loop", sharp_edges=feat.sharp_edges))]
    print("| case (fandisk unless said) | fixed default depth | per-point depth |")
    print("|---|---|---|")
    for label, X, T, kw in cases:
        s = hybridsub.LimitSurface(X, T, **kw)
        face, bary = near_features(s, 3000, seed=3)
        Q = hybridsub.LimitSurface(X, T, depth=56, **kw).evaluate(face, bary)
        P = s.evaluate(face, bary)
        fixed = hybridsub.LimitSurface(X, T, **kw)
        fixed._depths = lambda f, b, depth, rule_depth=None, _d=fixed.depth: np.full(len(f), _d)
        F0 = fixed.evaluate(face, bary)
        e_rule = np.linalg.norm(P - Q, axis=1).max() / diag(X)
        e_fixed = np.linalg.norm(F0 - Q, axis=1).max() / diag(X)
        print(f"| {label} | {e_fixed:.1e} | {e_rule:.1e} |")


if __name__ == "__main__":
    random_points()
    print()
    near_points()
