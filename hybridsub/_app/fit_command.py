"""``hybridsub fit`` and ``hybridsub decompose``: files in, files out, progress on stderr.

The command line (``cli.py``) only parses; the work is here. ``fit`` reads a control mesh
with its tags and a target (a mesh, whose vertices are the points, or a point file: ``.xyz``
/ ``.txt`` / ``.csv`` with three numbers a line, or ``.npy``), fits the control positions and
writes the control mesh with its tags. ``decompose`` refines a coarse mesh with its tags,
takes a fine mesh with the same vertex numbering as that refinement, and writes the coarse
positions of its reverse subdivision, with the details in an ``.npz`` beside it.
"""

from __future__ import annotations

import os
import sys

import numpy as np

from .. import _io
from .._fit import fit
from .._refiner import refine

POINT_FILES = (".xyz", ".txt", ".csv", ".npy")


def read_points(path: str) -> np.ndarray:
    """(p, 3) target points from a point file or a mesh file's vertices."""
    ext = os.path.splitext(path)[1].lower()
    if ext == ".npy":
        return np.load(path)
    if ext in POINT_FILES:
        delim = "," if ext == ".csv" else None
        P = np.loadtxt(path, delimiter=delim, ndmin=2, comments="#")
        if P.shape[1] < 3:
            raise ValueError(f"{path}: a point file needs three numbers a line, got {P.shape[1]}")
        return P[:, :3]
    return _io.read_mesh(path).vertices


def fit_file(control: str, target: str, output: str, *, levels=None, scheme="hybrid", smoothness=0.0,
             max_iterations=50, tol=1e-12, quiet=False) -> int:
    """Fit ``control``'s positions to ``target`` and write the fitted control mesh to ``output``."""
    mesh = _io.read_mesh(control)
    pts = read_points(target)
    say = (lambda *m: None) if quiet else (lambda *m: print(*m, file=sys.stderr, flush=True))
    what = "the limit surface" if levels is None else f"level {levels}"
    say(f"fitting {what} of {control} ({len(mesh.faces):,} faces, {scheme}) to {len(pts):,} points of {target}")
    res = fit(mesh.faces, pts, scheme=scheme, V0=mesh.vertices, levels=levels, smoothness=smoothness,
              max_iterations=max_iterations, tol=tol, **mesh.tag_arrays(),
              callback=lambda i, rms, mx: say(f"  iteration {i:3d}: rms {rms:.6g}, max {mx:.6g}"))
    _io.write_mesh(output, res.vertices, mesh.faces, **mesh.tag_arrays())
    state = "converged" if res.converged else "stopped (max iterations)"
    say(f"{state} after {res.iterations} updates: rms {res.rms:.6g}, max {res.max_error:.6g}; wrote {output}")
    return 0


def decompose_file(coarse: str, fine: str, output: str, *, levels: int, scheme="hybrid", quiet=False) -> int:
    """Reverse-subdivide ``fine`` (level ``levels`` of ``coarse``'s refinement) into ``output``
    (the coarse mesh, new positions, tags kept) and ``output``'s stem + ``.details.npz``."""
    cm = _io.read_mesh(coarse)
    fm = _io.read_mesh(fine)
    r = refine(cm.faces, levels=levels, n_vertices=len(cm.vertices), scheme=scheme, **cm.tag_arrays())
    if len(fm.vertices) != r.n_vertices:
        raise ValueError(f"{fine}: has {len(fm.vertices):,} vertices, level {levels} of {coarse} has "
                         f"{r.n_vertices:,}: the fine mesh must be that refinement (same numbering)")
    c, details = r.decompose(fm.vertices)
    _io.write_mesh(output, c, cm.faces, **cm.tag_arrays())
    side = os.path.splitext(output)[0] + ".details.npz"
    np.savez_compressed(side, **{f"level{k + 1}": d for k, d in enumerate(details)},
                        local_frames=details.local_frames)
    if not quiet:
        norms = ", ".join(f"{x:.4g}" for x in details.norms())
        print(f"decomposed {fine} into {output} ({len(c):,} vertices) and {side} (largest detail per level: "
              f"{norms})", file=sys.stderr)
    return 0
