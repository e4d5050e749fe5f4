"""How much what a ``LimitSurface`` evaluated before moves its next answers.

usage: python benchmarks/cache_history.py [--points N] [--meshes M ...] [--schemes S ...]

A key's representative is the first patch met with it (docs/limit.md, "The patch cache");
patches of one key are the same tagged mesh with the same shapes, so the answers should not
move. N random points are evaluated with
derivatives on a fresh surface and on one that has answered N other points first; printed per
mesh and scheme: the share of points whose bits differ, the largest position difference (in
bounding-box diagonals) and the largest relative difference of ``Du``, ``Dv``. Creases at 30°
and their corners (``"sqrt3"``: none).
"""

from __future__ import annotations

import argparse

import numpy as np

from _bench import load  # noqa: E402

import hybridsub  # noqa: E402
import hybridsub._surface.surface as surface_module  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=20000)
    ap.add_argument("--meshes", nargs="+", default=["fandisk", "mesh_with_border"])
    ap.add_argument("--schemes", nargs="+", default=["loop", "sqrt3", "hybrid"])
    a = ap.parse_args()
    for name in a.meshes:
        m = load(name)
        diag = float(np.linalg.norm(m.V.max(0) - m.V.min(0)))
        rng = np.random.default_rng(0)
        n = a.points
        face, bary = rng.integers(0, len(m.F), n), rng.dirichlet([1, 1, 1], n)
        other = rng.integers(0, len(m.F), n), rng.dirichlet([1, 1, 1], n)
        for scheme in a.schemes:
            tags = {} if scheme == "sqrt3" else dict(sharp_edges=m.creases, corners=m.corners)
            surface_module._TABLES.clear()  # a fresh process's patch table
            fresh = hybridsub.LimitSurface(m.V, m.F, scheme=scheme, **tags).evaluate(face, bary, derivatives=True)
            surface_module._TABLES.clear()
            s = hybridsub.LimitSurface(m.V, m.F, scheme=scheme, **tags)
            s.evaluate(*other, derivatives=True)
            warm = s.evaluate(face, bary, derivatives=True)
            differ = np.zeros(n, bool)
            for x, y in zip(fresh, warm):
                differ |= (x != y).any(axis=1)
            dp = np.linalg.norm(fresh[0] - warm[0], axis=1).max() / diag
            dd = max((np.linalg.norm(x - y, axis=1) / np.linalg.norm(x, axis=1)).max()
                     for x, y in zip(fresh[1:], warm[1:]))
            print(f"{name:18s} {scheme:6s} points differing {differ.mean():6.1%}  position {dp:.1e} diag  "
                  f"derivatives {dd:.1e} relative", flush=True)


if __name__ == "__main__":
    main()
