"""The figure and the numbers of docs/differentiable.md: a control mesh fitted by gradient
descent through ``hybridsub.torch.Subdivide``, and crease sharpness learned from a target
shape through ``hybridsub.torch.subdivide``.

usage: python docs/figures/differentiable.py [--out DIR] [--quick]

Headless (matplotlib's Agg backend); needs PyTorch (``pip install ".[torch,plot]"``). Prints
the numbers the page quotes; ``--quick`` runs fewer iterations (for the smoke test).
"""

from __future__ import annotations

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import torch  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(os.path.dirname(HERE)))  # the checkout's hybridsub

import hybridsub  # noqa: E402
import hybridsub.torch as ht  # noqa: E402
from hybridsub._io import read_off  # noqa: E402


def fit_sphere(steps: int):
    """The icosahedron's control points moved so that its Loop surface (3 levels) lies on the
    unit sphere: loss = mean (|p| − 1)² over the refined vertices."""
    V, F = read_off(os.path.join(HERE, "..", "..", "tests", "data", "icosahedron.off"))
    V = V / np.linalg.norm(V, axis=1, keepdims=True)
    sub = ht.Subdivide(hybridsub.refine(F, levels=3, scheme="loop"))
    X = torch.tensor(V, requires_grad=True)
    opt = torch.optim.Adam([X], lr=0.01)
    worst = []
    for _ in range(steps):
        opt.zero_grad()
        radius = sub(X).norm(dim=1)
        loss = ((radius - 1) ** 2).mean()
        loss.backward()
        opt.step()
        worst.append(float((radius.detach() - 1).abs().max()))
    return worst


def learn_sharpness(steps: int, seed: int = 0):
    """The creases of a meshed cube (dihedral angle > 30°), each with its own sharpness, learned
    from a target refined with other sharpness values: loss = mean squared distance between the
    refined vertices (Loop, 3 levels; the same topology for any sharpness)."""
    V, F = read_off(os.path.join(HERE, "..", "..", "tests", "data", "cube-meshed.off"))
    V = V / np.abs(V).max()
    E = hybridsub.detect_features(V, F, angle=30).sharp_edges
    rng = np.random.default_rng(seed)
    true = rng.uniform(0.2, 2.8, len(E))
    target = torch.tensor(hybridsub.subdivide(V, F, E, sharpness=true, levels=3, scheme="loop")[0])
    s = torch.full((len(E),), 1.5, dtype=torch.float64, requires_grad=True)
    X = torch.tensor(V)
    opt = torch.optim.Adam([s], lr=0.05)
    losses = []
    for _ in range(steps):
        opt.zero_grad()
        V2, _ = ht.subdivide(X, F, E, sharpness=s, levels=3, scheme="loop")
        loss = ((V2 - target) ** 2).sum(dim=1).mean()
        loss.backward()
        opt.step()
        with torch.no_grad():
            s.clamp_(min=1e-3)  # sharpness 0 is no crease: stay positive
        losses.append(float(loss.detach()))
    return true, s.detach().numpy(), losses, len(E)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=HERE)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    n_fit, n_sharp = (20, 10) if args.quick else (300, 300)
    worst = fit_sphere(n_fit)
    print(f"sphere: |p| - 1 at most {worst[0]:.4f} before, {worst[-1]:.2e} after {n_fit} Adam steps")
    true, learned, losses, k = learn_sharpness(n_sharp)
    err = np.abs(learned - true)
    print(f"sharpness: {k} creases, loss {losses[0]:.2e} -> {losses[-1]:.2e} after {n_sharp} Adam steps; "
          f"|s - s*| median {np.median(err):.3f}, max {err.max():.3f}")
    fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
    ax[0].semilogy(worst)
    ax[0].set(title="control mesh fitted to the unit sphere", xlabel="Adam step", ylabel="max | |p| − 1 |")
    ax[1].semilogy(losses)
    ax[1].set(title="sharpness learned from a target shape", xlabel="Adam step", ylabel="mean squared distance")
    ax[2].plot([0, 3], [0, 3], color="0.7", lw=1)
    ax[2].scatter(true, learned, s=12)
    ax[2].set(title=f"learned against true sharpness ({k} creases)", xlabel="true s*", ylabel="learned s",
              xlim=(0, 3), ylim=(0, 3))
    fig.tight_layout()
    path = os.path.join(args.out, "differentiable.png")
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
