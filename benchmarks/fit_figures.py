"""Figures of docs/fitting.md: convergence of hybridsub.fit, and a multiresolution edit.

    python benchmarks/fit_figures.py        # writes docs/images/fit_convergence.png, multires_edit.png
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


def multires_edit():
    V, F = load_mesh("cube-meshed")
    feat = hybridsub.detect_features(V, F, angle=30)
    r = hybridsub.refine(F, feat.sharp_edges, levels=2, corners=feat.corners)
    P = r.apply(V)
    rng = np.random.default_rng(0)
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
    multires_edit()
    convergence()
