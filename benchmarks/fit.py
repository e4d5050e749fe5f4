"""Fit time against the number of points and the control mesh's size (hybridsub.fit, levels=L).

    python benchmarks/fit.py                         # a small table (fandisk-derived controls)
    python benchmarks/fit.py --points 1e6 --faces 12946 --iterations 10
    python benchmarks/fit.py --limit hybrid --points 3000 --iterations 4   # the limit surface (levels=None)

The control meshes are fandisk (12,946 faces) and its first √3 level's coarser cousins made
by refining the icosahedron; the points are sampled on the control's own level-L surface
with Gaussian noise (σ = 1e-4 × diagonal), the start is the control's own positions
perturbed by 0.1% of the diagonal. Times are wall-clock, after a warm-up (Numba compiled,
SciPy loaded), per call of ``fit`` with ``max_iterations`` updates.

``--limit SCHEME`` fits the limit surface instead (``levels=None``): the control is the CAD
cube (``tests/data/cube-meshed.off``, 1,728 faces, creases at 30° and their corners), the
points exact samples of its limit surface at random parameters, the start its positions
perturbed by 2% of the mean edge; after a warm-up fit of 50 points, printed per update: the RMS and largest distance (in
diagonals) and the time so far.
"""

import argparse
import pathlib
import time
import warnings

import numpy as np

import hybridsub


def controls():
    V, F = hybridsub.load_example()
    yield "fandisk", V, F, hybridsub.detect_features(V, F, angle=30)
    for lv in (2, 3):
        Vi = np.array([[0.0, 0, 1], [0, 0, -1], [1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0]])
        Fi = np.array([[0, 2, 4], [0, 4, 3], [0, 3, 5], [0, 5, 2], [1, 4, 2], [1, 3, 4], [1, 5, 3], [1, 2, 5]])
        r = hybridsub.refine(Fi, levels=lv + 1, scheme="loop")
        P = r.apply(Vi)
        yield f"sphere{len(r.faces)}", P / np.linalg.norm(P, axis=1)[:, None], r.faces, None


def case(name, V, F, feat, n_points, levels, iterations, rng):
    tags = dict(sharp_edges=feat.sharp_edges, corners=feat.corners) if feat is not None else {}
    r = hybridsub.refine(F, levels=levels, **tags)
    P = r.apply(V)
    f = rng.integers(0, len(r.faces), n_points)
    pts = np.einsum("mi,mij->mj", rng.dirichlet([1, 1, 1], n_points), P[r.faces[f]])
    diag = np.linalg.norm(pts.max(0) - pts.min(0))
    pts += 1e-4 * diag * rng.normal(size=pts.shape)
    start = V + 0.001 * diag * rng.normal(size=V.shape) / np.sqrt(3)
    t = time.perf_counter()
    res = hybridsub.fit(F, pts, tags.get("sharp_edges"), corners=tags.get("corners"), V0=start, levels=levels,
                        max_iterations=iterations)
    dt = time.perf_counter() - t
    print(f"{name:14s} {len(F):7,d} faces  level {levels}  {n_points:9,d} points  {res.iterations:2d} updates  "
          f"{dt:7.2f} s  rms/diag {res.rms / diag:.2e}", flush=True)


def limit_case(scheme, n_points, iterations, rng):
    m = hybridsub.read_mesh(pathlib.Path(__file__).resolve().parents[1] / "tests" / "data" / "cube-meshed.off")
    V, F = np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)
    feat = hybridsub.detect_features(V, F, angle=30)
    tags = {} if scheme == "sqrt3" else dict(sharp_edges=feat.sharp_edges, corners=feat.corners)
    s = hybridsub.LimitSurface(V, F, scheme=scheme, **tags)
    pts = s.evaluate(rng.integers(0, len(F), n_points), rng.dirichlet([1, 1, 1], n_points))
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    edge = float(np.linalg.norm(V[F[:, 0]] - V[F[:, 1]], axis=1).mean())
    start = V + 0.02 * edge * rng.normal(size=V.shape)
    with warnings.catch_warnings():   # warm-up (Numba compiled, SciPy loaded): 50 points underdetermine it
        warnings.simplefilter("ignore")
        hybridsub.fit(F, pts[:50], tags.get("sharp_edges"), corners=tags.get("corners"), V0=start, scheme=scheme,
                      max_iterations=1)
    t = time.perf_counter()
    res = hybridsub.fit(F, pts, tags.get("sharp_edges"), corners=tags.get("corners"), V0=start, scheme=scheme,
                        max_iterations=iterations)
    dt = time.perf_counter() - t
    print(f"cube-meshed {len(F):,d} faces  {scheme} limit surface  {n_points:,d} points  {res.iterations} updates  "
          f"{dt:.1f} s", flush=True)
    for i, (rms, largest, _, at) in enumerate(res.history):
        print(f"  {i}: rms {rms / diag:.1e}  largest {largest / diag:.1e} diag  at {at:.1f} s")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--points", type=float, nargs="*", default=[1e4, 1e5])
    ap.add_argument("--levels", type=int, default=1)
    ap.add_argument("--iterations", type=int, default=5)
    ap.add_argument("--faces", type=int, default=None, help="only the control with this many faces")
    ap.add_argument("--limit", default=None, help="fit the limit surface of this scheme (levels=None)")
    a = ap.parse_args()
    rng = np.random.default_rng(0)
    if a.limit:
        for n in a.points:
            limit_case(a.limit, int(n), a.iterations, rng)
        return
    items = [c for c in controls() if a.faces is None or len(c[2]) == a.faces]
    case(*items[-1][:4], 1000, a.levels, 1, rng)   # warm-up
    for name, V, F, feat in items:
        for n in a.points:
            case(name, V, F, feat, int(n), a.levels, a.iterations, rng)


if __name__ == "__main__":
    main()
