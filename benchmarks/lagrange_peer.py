"""Adobe Lagrange (OpenSubdiv inside) as a peer of the vertex path: a mesh refined and put
on its limit surface with limit normals, in one task.

usage: python benchmarks/lagrange_peer.py [--levels L] [--repeat N]    (also a section of compare.py)

Task, fandisk with its 30° creases (Loop, 722 crease edges), ``L`` levels (3 by default):
* ours: ``limit_mesh(V, F, creases, levels=L, scheme="loop")`` (refined faces, limit positions
  and limit normals in one call; the same numbers as ``refine``, ``limit_positions`` and
  ``limit_normals`` separately, which are timed too);
* Lagrange: ``lagrange.subdivision.subdivide_mesh(mesh, num_levels=L, use_limit_surface=True,
  output_limit_normals=...)`` with the creases as an edge sharpness attribute of 1 (sharp).
Both single-threaded where the library lets us choose (ours: ``set_threads(1)``; Lagrange's
refinement is serial). The outputs are compared vertex by vertex (matched by position):
positions at every vertex (OpenSubdiv gives darts — vertices with one crease — the smooth
limit mask, which is not their limit; ``docs/limit.md``), normals at the vertices off creases
(on a crease Lagrange gives one side's normal, we the mean of the two).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from _bench import Timing, load, measure, tags  # noqa: E402

import hybridsub  # noqa: E402


def lagrange_mesh(V, F, creases):
    """A lagrange.SurfaceMesh of (V, F) and the id of its edge sharpness attribute (1 on ``creases``)."""
    import lagrange

    m = lagrange.SurfaceMesh()
    m.add_vertices(np.ascontiguousarray(V, np.float64))
    m.add_triangles(np.ascontiguousarray(F, np.uint32))
    m.initialize_edges()
    ends = np.array([m.get_edge_vertices(e) for e in range(m.num_edges)], np.int64)
    key = {(int(a), int(b)): e for e, (a, b) in enumerate(np.sort(ends, axis=1))}
    s = np.zeros(m.num_edges)
    for a, b in np.sort(np.asarray(creases, np.int64), axis=1):
        s[key[(int(a), int(b))]] = 1.0
    aid = m.create_attribute("sharpness", element=lagrange.AttributeElement.Edge,
                             usage=lagrange.AttributeUsage.Scalar, initial_values=s)
    return m, aid


def lagrange_task(levels: int):
    """``prepare``, ``run`` and the arrays (P, F, N) of a run's output, for :func:`_bench.measure`."""
    import lagrange

    fan = load("fandisk")
    creases, _ = tags(fan, "loop+creases")

    def run(mesh_and_attr):
        m, aid = mesh_and_attr
        return lagrange.subdivision.subdivide_mesh(m, num_levels=levels, scheme=lagrange.subdivision.SchemeType.Loop,
                                                   edge_sharpness_attr=aid, use_limit_surface=True,
                                                   output_limit_normals="limit_normal")

    def arrays(out):
        return (np.asarray(out.vertices, np.float64), np.asarray(out.facets, np.int64),
                np.asarray(out.attribute("limit_normal").data, np.float64))

    return (lambda: lagrange_mesh(fan.V, fan.F, creases)), run, arrays


def ours_task(levels: int):
    fan = load("fandisk")
    creases, _ = tags(fan, "loop+creases")

    def run(inp):
        V, F = inp
        m = hybridsub.limit_mesh(V, F, creases, levels=levels, scheme="loop")
        return m.vertices, m.faces, m.normals

    def run_separately(inp):
        V, F = inp
        F2 = hybridsub.refine(F, creases, levels, scheme="loop", n_vertices=len(V)).faces
        P = hybridsub.limit_positions(V, F, creases, levels=levels, scheme="loop")
        N = hybridsub.limit_normals(V, F, creases, levels=levels, scheme="loop")
        return P, F2, N

    return (lambda: (fan.V, fan.F)), run, run_separately, creases


def compare_outputs(ours, theirs, creases, levels: int) -> str:
    """How far Lagrange's limit positions and normals are from ours, in words."""
    from scipy.spatial import cKDTree

    fan = load("fandisk")
    P, F2, N = ours
    Q, G, M = theirs
    if (len(P), len(F2)) != (len(Q), len(G)):
        return f"counts differ: {len(Q)}/{len(G)} vs ours {len(P)}/{len(F2)}"
    diag = float(np.linalg.norm(fan.V.max(0) - fan.V.min(0)))
    d, idx = cKDTree(P).query(Q)
    r = hybridsub.refine(fan.F, creases, levels, scheme="loop", n_vertices=len(fan.V))
    on_crease = np.zeros(len(P), bool)
    on_crease[np.asarray(r.sharp_edges).ravel()] = True
    off = ~on_crease[idx]
    cosang = np.clip(np.einsum("ij,ij->i", M[off] / np.linalg.norm(M[off], axis=1, keepdims=True), N[idx[off]]), -1, 1)
    ang = np.degrees(np.arccos(cosang))
    far = d > 1e-12 * diag
    return (f"positions: {int((~far).sum()):,} of {len(d):,} within 1e-12 × diagonal (max {d[~far].max() / diag:.1e}), "
            f"{int(far.sum())} off by up to {d.max() / diag:.1e} (darts: OpenSubdiv's smooth mask); normals off "
            f"creases: max {ang.max():.1e}°, median {np.median(ang):.1e}°")


def run_section(levels: int, repeat: int, budget: float) -> tuple[list, str]:
    """The Markdown lines of the section, and a reason if Lagrange was skipped ('' otherwise)."""
    try:
        import lagrange  # noqa: F401
    except Exception as e:  # noqa: BLE001  (a missing or broken wheel)
        return [], f"cannot import lagrange: {type(e).__name__}: {e}"
    from importlib.metadata import version

    hybridsub.set_threads(1)
    try:
        prep_o, run_o, run_s, creases = ours_task(levels)
        prep_l, run_l, arr_l = lagrange_task(levels)
        t_o: Timing = measure(prep_o, run_o, repeat=repeat, budget=budget)
        t_s: Timing = measure(prep_o, run_s, repeat=repeat, budget=budget)
        t_l: Timing = measure(prep_l, run_l, repeat=repeat, budget=budget)
        ours = run_o(prep_o())
        same = all(np.array_equal(a, b) for a, b in zip(ours, run_s(prep_o())))
        check = compare_outputs(ours, arr_l(run_l(prep_l())), creases, levels)
    finally:
        hybridsub.set_threads()  # the rest of compare.py runs on every thread again
    ratio = t_o.median / t_l.median
    lines = [f"## The vertex path against Adobe Lagrange {version('adobe-lagrange')} (OpenSubdiv inside), one thread", "",
             f"fandisk, Loop with its 722 creases, {levels} levels: refined faces, limit positions and limit normals "
             "(`benchmarks/lagrange_peer.py`).", "",
             "| work | ours median | ours min | Lagrange median | Lagrange min | ours / Lagrange | target | |",
             "|---|---|---|---|---|---|---|---|",
             f"| `limit_mesh` L{levels} | {t_o.median:.3f} s | {min(t_o.times):.3f} s | "
             f"{t_l.median:.3f} s | {min(t_l.times):.3f} s | {ratio:.2f} | ≤ 0.5 | {'pass' if ratio <= 0.5 else '**fail**'} |",
             f"| `refine` + `limit_positions` + `limit_normals` L{levels} | {t_s.median:.3f} s | {min(t_s.times):.3f} s | "
             f"{t_l.median:.3f} s | {min(t_l.times):.3f} s | {t_s.median / t_l.median:.2f} | | |",
             "", f"Check: {check}; `limit_mesh` and the three calls {'agree bit for bit' if same else '**differ**'}."]
    return lines, ""


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--levels", type=int, default=3)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--budget", type=float, default=60.0)
    args = ap.parse_args(argv)
    lines, skipped = run_section(args.levels, args.repeat, args.budget)
    print("\n".join(lines) if lines else f"skipped: {skipped}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
