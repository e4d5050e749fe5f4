"""Figures of docs/fitting.md: convergence of hybridsub.fit, a fit to a scanned CAD part, and a
multiresolution edit.

    python benchmarks/fit_figures.py        # writes docs/images/fit_convergence.png, fit_scan.png,
                                            # multires_edit.png
"""

import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import hybridsub  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests"))
from test_fit import CREASES, EDGE, FC, VC, _sample  # noqa: E402
from conftest import load_mesh  # noqa: E402
from _bench import frame_3d  # noqa: E402

OUT = os.path.join(HERE, "..", "docs", "images")


def convergence():
    rng = np.random.default_rng(2)
    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    for scheme in ("hybrid", "sqrt3", "loop"):
        sharp = None if scheme == "sqrt3" else CREASES
        r = hybridsub.refine(FC, sharp, levels=2, scheme=scheme)
        pts = _sample(r, VC, 20000, rng)
        diag = np.linalg.norm(pts.max(0) - pts.min(0))
        start = VC + 0.05 * EDGE * rng.normal(size=VC.shape) / np.sqrt(3)
        res = hybridsub.fit(FC, pts, sharp, scheme=scheme, V0=start, levels=2)
        ax.semilogy(res.history["rms"] / diag, "o-", label=f"{scheme}, exact data")
        print(scheme, res.iterations, np.abs(res.vertices - VC).max() / diag)
        if scheme == "hybrid":
            sigma = 1e-3 * diag
            res = hybridsub.fit(FC, pts + sigma * rng.normal(size=pts.shape), sharp, V0=start, levels=2,
                                max_iterations=12)
            ax.semilogy(res.history["rms"] / diag, "s--", label="hybrid, noise σ = 1e-3 diag")
            ax.axhline(sigma / diag, color="gray", lw=0.8)
    ax.set_xlabel("iteration")
    ax.set_ylabel("RMS distance / bounding-box diagonal")
    ax.set_title("fit to 20,000 points of a level-2 surface, start perturbed by 5% of an edge")
    ax.title.set_fontsize(9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "fit_convergence.png"), dpi=120)


def _scan(V, F, n, sigma, rng):
    """n points uniformly over the area of the mesh, with Gaussian noise of deviation sigma."""
    tri = V[F]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    f = rng.choice(len(F), n, p=area / area.sum())
    pts = np.einsum("mi,mij->mj", rng.dirichlet([1, 1, 1], n), tri[f])
    return pts + sigma * rng.normal(size=pts.shape)


def _error_map(ax, P, faces, pts, fp, diag, vmax, title):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    err = np.bincount(fp.face, fp.distance, len(faces)) / np.maximum(np.bincount(fp.face, minlength=len(faces)), 1)
    cmap = plt.get_cmap("viridis")
    poly = Poly3DCollection(P[faces], facecolors=cmap(np.clip(err / diag / vmax, 0, 1)), linewidths=0)
    ax.add_collection3d(poly)
    frame_3d(ax, P, title)


def scan_fit():
    """Fandisk as a scanned CAD part: 500,000 noisy points on its facets; the control mesh is
    fandisk decimated to 1,500 faces (trimesh's quadric decimation), its creases and corners
    from detect_features; its level-2 hybrid surface is fitted to the scan."""
    import trimesh
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    from hybridsub._surface.mesh_closest import closest_points

    V, F = hybridsub.load_example()
    rng = np.random.default_rng(3)
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    pts = _scan(V, F, 500_000, 2e-4 * diag, rng)
    coarse = trimesh.Trimesh(V, F, process=False).simplify_quadric_decimation(face_count=1500)
    VC0, FC0 = np.asarray(coarse.vertices, dtype=float), np.asarray(coarse.faces, dtype=np.int64)
    feat = hybridsub.detect_features(VC0, FC0, angle=30)
    print("control:", len(FC0), "faces,", len(np.asarray(feat.sharp_edges).reshape(-1, 2)), "crease edges")
    res = hybridsub.fit(FC0, pts, feat.sharp_edges, corners=feat.corners, V0=VC0, levels=2, max_iterations=8)
    print("scan fit:", res.iterations, "updates, rms/diag", res.rms / diag, "max/diag", res.max_error / diag,
          "seconds", res.history["seconds"][-1], "rms per update / diag", res.history["rms"] / diag)
    r = hybridsub.refine(FC0, feat.sharp_edges, levels=2, corners=feat.corners)
    before, after = r.apply(VC0), r.apply(res.vertices)
    fb, fa = closest_points(before, r.faces, pts), closest_points(after, r.faces, pts)
    vmax = float(np.quantile(fb.distance, 0.98)) / diag
    fig = plt.figure(figsize=(10, 8.4))
    ax = fig.add_subplot(2, 2, 1, projection="3d")
    few = pts[rng.choice(len(pts), 40_000, replace=False)]
    ax.scatter(few[:, 0], few[:, 1], few[:, 2], s=0.05, c="0.3", depthshade=False)
    frame_3d(ax, V, "the scan: 500,000 points on fandisk's facets,\nnoise σ = 2e-4 × diagonal (4e4 drawn)")
    ax = fig.add_subplot(2, 2, 2, projection="3d")
    ax.computed_zorder = False  # the creases over the faces
    ax.add_collection3d(Poly3DCollection(res.vertices[FC0], facecolors="0.88", edgecolors="0.45", linewidths=0.15,
                                         zorder=1))
    crease = np.asarray(feat.sharp_edges).reshape(-1, 2)
    ax.add_collection3d(Line3DCollection(res.vertices[crease], colors="crimson", linewidths=0.9, zorder=2))
    frame_3d(ax, V, f"the fitted control mesh ({len(FC0):,} faces, decimated),\nits creases in red")
    _error_map(fig.add_subplot(2, 2, 3, projection="3d"), before, r.faces, pts, fb, diag, vmax,
               f"before: the decimated mesh's own surface,\nRMS {np.sqrt(np.mean(fb.distance ** 2)) / diag:.1e} × diagonal")
    _error_map(fig.add_subplot(2, 2, 4, projection="3d"), after, r.faces, pts, fa, diag, vmax,
               f"fitted (level 2, {res.iterations} updates, {res.history['seconds'][-1]:.0f} s):\n"
               f"RMS {res.rms / diag:.1e} × diagonal")
    sm = plt.cm.ScalarMappable(cmap="viridis", norm=plt.Normalize(0, vmax))
    fig.subplots_adjust(left=0.0, right=0.9, top=0.95, bottom=0.02, wspace=0.0, hspace=0.08)
    fig.colorbar(sm, cax=fig.add_axes([0.9, 0.08, 0.015, 0.36]), label="a face's points: mean distance / diagonal")
    fig.savefig(os.path.join(OUT, "fit_scan.png"), dpi=100)


def multires_edit():
    V, F = load_mesh("cube-meshed")
    feat = hybridsub.detect_features(V, F, angle=30)
    r = hybridsub.refine(F, feat.sharp_edges, levels=2, corners=feat.corners)
    P = r.apply(V)
    bumps = 0.08 * np.sin(6 * P[:, 0]) * np.sin(6 * P[:, 1]) * np.sin(6 * P[:, 2])
    N = P / np.linalg.norm(P, axis=1)[:, None]
    X = P + bumps[:, None] * N                                            # fine detail on the rounded cube
    coarse, details = r.decompose(X)
    edited = coarse.copy()
    top = coarse[:, 2] > 0.5
    edited[top] = edited[top] @ np.array([[np.cos(0.6), -np.sin(0.6), 0], [np.sin(0.6), np.cos(0.6), 0], [0, 0, 1]]).T
    edited[top, 2] += 0.6                                                 # twist and lift the top
    X2 = r.reconstruct(edited, details)
    fig = plt.figure(figsize=(10, 3.6))
    for i, (Y, title) in enumerate([(X, "fine data (level 2)"), (r.apply(edited), "coarse edit, no details"),
                                    (X2, "coarse edit, details carried")]):
        ax = fig.add_subplot(1, 3, i + 1, projection="3d")
        ax.plot_trisurf(Y[:, 0], Y[:, 1], Y[:, 2], triangles=r.faces, color="0.8", edgecolor="none",
                        shade=True, linewidth=0)
        ax.set_title(title, fontsize=9)
        ax.set_axis_off()
        ax.view_init(20, 35)
        ax.set_box_aspect(np.ptp(Y, axis=0))
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "multires_edit.png"), dpi=110)


if __name__ == "__main__":
    which = sys.argv[1:] or ["multires_edit", "convergence", "scan_fit"]
    for name in which:
        globals()[name]()
