"""Regenerate the figures of docs/features.md, docs/limit.md, docs/analysis.md, docs/semisharp.md,
docs/face_varying.md, docs/adaptive.md and docs/usage.md.

usage: python docs/figures/make_figures.py [--out DIR] [--quick] [--only fig_options ...]

Headless (matplotlib's Agg backend). Run it from the repository root with hybridsub
importable (``pip install ".[plot]"``). ``--quick`` draws smaller versions (for the smoke test).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402

import hybridsub  # noqa: E402
from hybridsub import analysis  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
LIGHT = np.array([0.35, 0.45, 0.82])


def _view(azim, elev):
    """Rotation taking world coordinates to (right, up, towards the viewer)."""
    a, e = np.radians(azim), np.radians(elev)
    Rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    Rx = np.array([[1, 0, 0], [0, np.cos(e), -np.sin(e)], [0, np.sin(e), np.cos(e)]])
    return Rx @ Rz


def render(ax, V, F, *, azim=35, elev=-60, face_normals=None, colors=None, edges=None, edge_color="red",
           points=(), wire=0.0, window=None):
    """Orthographic, flat-shaded drawing of a mesh on ``ax``; feature edges and points are
    depth-sorted together with the faces (painter's algorithm), so hidden ones stay hidden.

    ``points``: sequence of (vertex indices, colour, label). ``window``: (x0, x1, y0, y1) as
    fractions of the projected bounding box, to zoom in.
    """
    R = _view(azim, elev)
    P = V @ R.T
    tri = P[F]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]) if face_normals is None else face_normals @ R.T
    n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    front = n[:, 2] > 0
    shade = 0.25 + 0.75 * np.clip(n @ (LIGHT / np.linalg.norm(LIGHT)), 0, 1)
    base = np.array([0.78, 0.80, 0.84]) if colors is None else colors
    col = np.c_[(np.broadcast_to(base, (len(F), 3)) * shade[:, None]).clip(0, 1), np.ones(len(F))]
    polys = list(tri[front][:, :, :2])
    depth = list(tri[front][:, :, 2].mean(axis=1))
    cols = list(col[front])
    size = np.ptp(P[:, :2], axis=0).max()
    eps = 0.004 * size
    if edges is not None and len(edges):
        a, b = P[edges[:, 0]], P[edges[:, 1]]
        d = (b - a)[:, :2]
        d = np.c_[-d[:, 1], d[:, 0]] / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)
        w = 0.5 * (0.0025 if window is None else 0.0012) * size * d
        quads = np.stack([a[:, :2] - w, b[:, :2] - w, b[:, :2] + w, a[:, :2] + w], axis=1)
        polys += list(quads)
        depth += list((a[:, 2] + b[:, 2]) / 2 + eps)
        cols += [matplotlib.colors.to_rgba(edge_color)] * len(edges)
    handles = []
    for idx, c, label in points:
        idx = np.asarray(idx, dtype=np.int64)
        if not len(idx):
            continue
        t = np.linspace(0, 2 * np.pi, 9)[:-1]
        r = (0.006 if window is None else 0.003) * size
        circ = P[idx, None, :2] + r * np.stack([np.cos(t), np.sin(t)], axis=1)[None]
        polys += list(circ)
        depth += list(P[idx, 2] + 3 * eps)
        cols += [matplotlib.colors.to_rgba(c)] * len(idx)
        handles.append(plt.Line2D([], [], marker="o", ls="", color=c, label=label))
    order = np.argsort(depth)
    pc = PolyCollection([polys[i] for i in order], facecolors=[cols[i] for i in order],
                        edgecolors="face" if not wire else None, linewidths=0.1)
    if wire:
        ec = np.array([cols[i] for i in order])
        ec[:, :3] *= 1 - wire
        pc.set_edgecolor(ec)
    ax.add_collection(pc)
    ax.set_aspect("equal")
    lo, hi = P[:, :2].min(axis=0), P[:, :2].max(axis=0)
    if window is not None:
        x0, x1, y0, y1 = window
        ax.set_xlim(lo[0] + x0 * (hi[0] - lo[0]), lo[0] + x1 * (hi[0] - lo[0]))
        ax.set_ylim(lo[1] + y0 * (hi[1] - lo[1]), lo[1] + y1 * (hi[1] - lo[1]))
    else:
        ax.set_xlim(lo[0] - 0.02 * size, hi[0] + 0.02 * size)
        ax.set_ylim(lo[1] - 0.02 * size, hi[1] + 0.02 * size)
    ax.axis("off")
    return handles


def _save(fig, path, dpi):
    """Save, then shrink to a 256-colour palette (the figures are flat-shaded drawings)."""
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    try:
        from PIL import Image
    except ImportError:  # pragma: no cover - matplotlib depends on pillow
        return
    Image.open(path).convert("RGB").quantize(colors=256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE).save(path, optimize=True)


def fig_features(out, quick):
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, angle=30)
    base = hybridsub.detect_features(V, F, angle=30, corner_angle=None)
    turning = np.setdiff1d(feat.corners, base.corners)
    c = np.bincount(feat.sharp_edges.ravel(), minlength=len(V))
    darts = np.flatnonzero(c == 1)
    fig, axs = plt.subplots(1, 2, figsize=(10, 5))
    pts = [(base.corners, "k", "corner: 3+ creases"), (turning, "tab:blue", "corner: crease turns > 45°"),
           (darts, "tab:green", "dart: a crease ends")]
    for ax, (az, el) in zip(axs, [(30, -110), (35, -60)]):
        h = render(ax, V, F, azim=az, elev=el, edges=feat.sharp_edges, points=pts)
    axs[0].legend(handles=h, loc="lower left", fontsize=8, frameon=False)
    fig.suptitle(f"detect_features(V, F, angle=30) on fandisk: {len(feat.sharp_edges)} sharp edges (red), "
                 f"{len(feat.corners)} corners, {len(darts)} darts", fontsize=10)
    fig.tight_layout()
    _save(fig, os.path.join(out, "features_fandisk.png"), 70 if quick else 100)


def _phong(V, F, N, m):
    """Split each face into m² flat pieces with positions and normals interpolated from its
    corners: shading that shows the per-corner normals (Phong)."""
    ij = [(i, j) for i in range(m + 1) for j in range(m + 1 - i)]
    idx = {p: t for t, p in enumerate(ij)}
    bary = np.array([[1 - (i + j) / m, i / m, j / m] for i, j in ij])
    sub = []
    for i in range(m):
        for j in range(m - i):
            sub.append((idx[(i, j)], idx[(i + 1, j)], idx[(i, j + 1)]))
            if i + j < m - 1:
                sub.append((idx[(i + 1, j)], idx[(i + 1, j + 1)], idx[(i, j + 1)]))
    sub = np.array(sub)
    Vs = np.einsum("kc,fcd->fkd", bary, V[F])  # (m_faces, nb, 3)
    Ns = np.einsum("kc,fcd->fkd", bary, N)
    nb = len(bary)
    Fs = (np.arange(len(F))[:, None, None] * nb + sub[None]).reshape(-1, 3)
    Vs = Vs.reshape(-1, 3)
    Ns = Ns.reshape(-1, 3)
    return Vs, Fs, Ns[Fs].mean(axis=1)


def fig_limit(out, quick):
    # A coarse model, where refinement and limit differ visibly: an octahedron with a crease
    # loop round its equator (the paper's Fig. 7: input, subdivided, limit).
    from hybridsub._io import read_off
    data = os.path.join(os.path.dirname(os.path.dirname(HERE)), "tests", "data")
    V, F = read_off(os.path.join(data, "octahedron.off"))
    V = V * np.array([1.0, 1.0, 2.0])
    eq = np.flatnonzero(np.abs(V[:, 2]) < 1e-9)
    E = np.array([[a, b] for a in eq for b in eq if a < b and np.linalg.norm(V[a] - V[b]) < 1.5])
    fig = plt.figure(figsize=(13, 3.6))
    az, el = 30, -70
    panels = [("(a) input, equator tagged", 0, False), ("(b) hybrid, 2 levels", 2, False),
              ("(c) hybrid, 5 levels", 3 if quick else 5, False), ("(d) 2 levels pushed to the limit,\nlimit normals (Phong)", 2, True)]
    for t, (title, L, lim) in enumerate(panels):
        ax = fig.add_subplot(1, 4, t + 1)
        r = hybridsub.refine(F, E, L)
        X = r.apply(V)
        if lim:
            P = hybridsub.limit_positions(V, F, E, levels=L)
            N = hybridsub.limit_normals(V, F, E, levels=L, per_face_corner=True)
            Vs, Fs, Ns = _phong(P, r.faces, N, 4 if quick else 8)
            render(ax, np.vstack([Vs, P]), Fs, azim=az, elev=el, face_normals=Ns, edges=r.sharp_edges + len(Vs))
        else:
            render(ax, X, r.faces, azim=az, elev=el, edges=r.sharp_edges if L else E, wire=0.4 if L < 4 else 0.0)
        ax.set_title(title + (f" ({len(r.faces)} faces)" if not lim else ""), fontsize=9)
    fig.tight_layout()
    _save(fig, os.path.join(out, "limit_octahedron.png"), 70 if quick else 100)

    # fandisk: how far the vertices of one hybrid level still move.
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, angle=30)
    tags = {"sharp_edges": feat.sharp_edges, "corners": feat.corners}
    r = hybridsub.refine(F, feat.sharp_edges, 1, corners=feat.corners)
    V1 = r.apply(V)
    P = hybridsub.limit_positions(V, F, levels=1, **tags)
    dist = np.linalg.norm(V1 - P, axis=1) / np.ptp(V, axis=0).max()
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.6), gridspec_kw={"width_ratios": [1, 1.15]})
    cmap = plt.get_cmap("viridis")
    d = dist[r.faces].mean(axis=1)
    top = np.quantile(d, 0.995)
    for ax, (az, el) in zip(axs, [(35, -60), (215, -60)]):
        render(ax, P, r.faces, azim=az, elev=el, colors=np.clip(cmap(d / top)[:, :3] * 1.3, 0, 1))
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(0, top))
    fig.colorbar(sm, ax=axs[1], fraction=0.04, label="|V₁ − limit_positions| / model size")
    fig.suptitle(f"fandisk, hybrid, 1 level ({len(r.faces)} faces): distance of each vertex to its limit position",
                 fontsize=10)
    fig.tight_layout()
    _save(fig, os.path.join(out, "limit_fandisk.png"), 70 if quick else 90)

    # Convergence: |S_L V − L V| over the input vertices, against the predicted rates.
    fig, ax = plt.subplots(figsize=(6.2, 4.2))
    cases = [("icosahedron", "sqrt3", {}, 2 / 3 - float(hybridsub._rules.step_rules.kobbelt_alpha(5))),
             ("icosahedron", "loop", {}, ((3 + 2 * np.cos(2 * np.pi / 5)) / 8) ** 2),
             ("cube-meshed", "hybrid", "features", None), ("cube-meshed", "loop", "features", None)]
    data = os.path.join(os.path.dirname(os.path.dirname(HERE)), "tests", "data")
    from hybridsub._io import read_off
    for name, scheme, tags, rate in cases:
        Vm, Fm = read_off(os.path.join(data, f"{name}.off"))
        kw = {}
        if tags == "features":
            f = hybridsub.detect_features(Vm, Fm)
            kw = {"sharp_edges": f.sharp_edges, "corners": f.corners}
        levels = (3 if quick else 6) if name == "icosahedron" else (2 if quick else 4)
        lim = hybridsub.limit_positions(Vm, Fm, scheme=scheme, **kw)
        rr = hybridsub.refine(Fm, kw.pop("sharp_edges", None), levels, scheme=scheme, **kw)
        X, err = Vm.copy(), [np.abs(Vm - lim).max()]
        for st in rr.steps:
            X = st.matrix @ X
            err.append(np.abs(X[: len(Vm)] - lim).max())
        line, = ax.semilogy(range(levels + 1), err, "o-", label=f"{name}, {scheme}")
        if rate:
            ax.semilogy(range(1, levels + 1), 0.5 * err[1] * rate ** np.arange(levels), ":", color=line.get_color(),
                        lw=1.2, label=f"  slope of the predicted rate {rate:.3f}/level (× 0.5)")
    ax.set_xlabel("level L")
    ax.set_ylabel("max |(S_L V)[:n] − limit_positions(V)|")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    _save(fig, os.path.join(out, "limit_convergence.png"), 100)


def fig_spectra(out, quick):
    ns = np.arange(3, 21 if not quick else 9)
    fig, axs = plt.subplots(1, 3, figsize=(13, 4))
    for ax, scheme in zip(axs[:2], ["sqrt3", "loop"]):
        ev = [np.sort(np.abs(analysis.eigenvalues(analysis.subdivision_matrix(
            int(n), scheme, steps=2 if scheme == "sqrt3" else 1))))[::-1] for n in ns]
        for j in range(1, 6):
            ax.plot(ns, [e[j] if j < len(e) else np.nan for e in ev], "o", ms=3, label=f"|λ{j + 1}|")
        cf = [analysis.closed_form_spectrum(int(n), scheme) for n in ns]
        if scheme == "sqrt3":
            a = hybridsub._rules.step_rules.kobbelt_alpha(ns)
            ax.plot(ns, (2 + 2 * np.cos(2 * np.pi / ns)) / 9, "k-", lw=0.8, label="eq. (7): (2+2cos 2π/n)/9")
            ax.plot(ns, (2 - 3 * a) ** 2 / 9, "k--", lw=0.8, label="eq. (7): (2−3α_n)²/9")
            ax.set_title("√3, two steps (aligned ring)", fontsize=10)
        else:
            ax.plot(ns, (3 + 2 * np.cos(2 * np.pi / ns)) / 8, "k-", lw=0.8, label="eq. (10): (3+2cos 2π/n)/8")
            ax.set_title("Loop, one step", fontsize=10)
        assert all(np.allclose(np.sort(np.abs(c))[::-1][:3], e[:3]) for c, e in zip(cf, ev))
        ax.set_xlabel("valence n")
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    ax = axs[2]
    ks = np.arange(1, 15 if not quick else 8)
    for scheme, style in (("loop", "-"), ("sqrt3", "--")):
        top = []
        for k in ks:
            e = analysis.eigenvalues(analysis.subdivision_matrix(int(k), scheme, steps=2 if scheme == "sqrt3" else 1,
                                                                 crease=True))
            t = 0.5 if scheme == "loop" else 1 / 3
            top.append([abs(e[1]) / t, abs(e[2]) / t])
        top = np.array(top)
        ax.plot(ks, top[:, 0], "o" + style, ms=3, label=f"{scheme}: λ₂ / crease tangent")
        ax.plot(ks, top[:, 1], "s" + style, ms=3, label=f"{scheme}: λ₃ / crease tangent")
    ax.axhline(1, color="k", lw=0.6)
    ax.axvline(5.5, color="gray", lw=0.6, ls=":")
    ax.set_xlabel("faces k in the sector")
    ax.set_title("crease sectors: the crease tangent must be λ₂ or λ₃", fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    _save(fig, os.path.join(out, "analysis_spectra.png"), 100)


def fig_charmaps(out, quick):
    cases = [(3, "sqrt3", False), (5, "sqrt3", False), (8, "sqrt3", False), (14, "sqrt3", False),
             (3, "loop", False), (5, "loop", False), (8, "loop", False), (14, "loop", False),
             (3, "loop", True), (5, "loop", True), (6, "loop", True), (8, "loop", True)]
    if quick:
        cases = cases[:2] + cases[8:9]
    cols = 4
    rows = (len(cases) + cols - 1) // cols
    fig, axs = plt.subplots(rows, cols, figsize=(3 * cols, 3 * rows))
    for ax, (n, scheme, crease) in zip(np.ravel(axs), cases):
        levels = (4 if scheme == "sqrt3" else 3) if not quick else 2
        P, F, lam = analysis.characteristic_map(n, scheme, levels=levels, crease=crease)
        E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
        ax.add_collection(LineCollection(P[E], lw=0.25, color="k"))
        ax.autoscale()
        ax.set_aspect("equal" if not crease else "auto")
        ax.set_xticks([])
        ax.set_yticks([])
        what = f"crease, {n} faces" if crease else f"n = {n}"
        ax.set_title(f"{'√3' if scheme == 'sqrt3' else 'Loop'}, {what}\nλ = {lam[0]:.3f}, {lam[1]:.3f}", fontsize=8)
    for ax in np.ravel(axs)[len(cases):]:
        ax.axis("off")
    fig.tight_layout()
    _save(fig, os.path.join(out, "analysis_charmaps.png"), 80)


def _box():
    """The 12-triangle cube (trimesh's box): coarse, so that every level shows."""
    import trimesh
    m = trimesh.creation.box()
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64)


def fig_semisharp(out, quick):
    # The same cube, its 12 edges creased with sharpness 0.5, 1, 2, 3 and inf: hybrid (top)
    # and Loop (bottom, OpenSubdiv's uniform creasing), 5 levels each.
    from PIL import Image

    from hybridsub._app.figure import Panel, render_figure

    V, F = _box()
    E = hybridsub.detect_features(V, F, angle=30).sharp_edges
    levels = 3 if quick else 5
    rows = []
    for scheme, name in (("hybrid", "hybrid √3–Loop"), ("loop", "Loop")):
        panels = []
        for s in (0.5, 1, 2, 3, np.inf):
            r = hybridsub.refine(F, E, levels, n_vertices=len(V), scheme=scheme, sharpness=np.full(len(E), s))
            panels.append(Panel(f"s = {s:g}" if np.isfinite(s) else "s = ∞ (sharp)", r.apply(V), r.faces,
                                f"{len(r.faces):,} faces"))
        path = os.path.join(out, f"_semisharp_{scheme}.png")
        w = 1000 if quick else 1500
        render_figure(panels, path, width=w, height=w * 33 // 100,
                      title=f"{name}, {levels} levels, the cube's 12 edges creased with sharpness s")
        rows.append(Image.open(path).convert("RGB"))
        os.remove(path)
    img = Image.new("RGB", (rows[0].width, sum(r.height for r in rows)), "white")
    img.paste(rows[0], (0, 0))
    img.paste(rows[1], (0, rows[0].height))
    img.quantize(colors=256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE).save(
        os.path.join(out, "semisharp_cube.png"), optimize=True)


def _strip(paths, out_path):
    """Stack PNGs (same width) into one, shrunk to a 256-colour palette; the parts removed."""
    from PIL import Image

    rows = [Image.open(p).convert("RGB") for p in paths]
    img = Image.new("RGB", (rows[0].width, sum(r.height for r in rows)), "white")
    y = 0
    for r, p in zip(rows, paths):
        img.paste(r, (0, y))
        y += r.height
        os.remove(p)
    img.quantize(colors=256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE).save(out_path, optimize=True)


def fig_options(out, quick):
    # docs/usage.md: the options that change the shape. Top: the cube's 8 vertices as corners
    # of sharpness 0 … ∞ (corner_sharpness=); bottom: holes= against deleting the faces.
    from hybridsub._app.figure import Panel, render_figure

    V, F = _box()
    levels = 3 if quick else 4
    w = 900 if quick else 1200
    corners = np.arange(len(V))
    panels = []
    for s in (0, 1, 2, 3, np.inf):
        X, G = hybridsub.subdivide(V, F, levels=levels, scheme="loop", corners=corners,
                                   corner_sharpness=np.full(len(V), float(s)))
        panels.append(Panel(f"corner_sharpness = {s:g}" if np.isfinite(s) else "corners (∞)", X, G,
                            f"{len(G):,} faces"))
    top = os.path.join(out, "_options_corners.png")
    render_figure(panels, top, width=w, height=w * 30 // 100, view=(35, 25),
                  title=f"Loop, {levels} levels: the cube's 8 vertices as corners of sharpness s")
    top_face = np.flatnonzero((V[F][:, :, 2] > 0).all(axis=1))  # the two triangles of the top side
    keep = np.setdiff1d(np.arange(len(F)), top_face)
    Vh, Fh = hybridsub.subdivide(V, F, levels=levels, scheme="loop", holes=top_face)
    Vd, Fd = hybridsub.subdivide(V, F[keep], levels=levels, scheme="loop")
    Vn, Fn = hybridsub.subdivide(V, F[keep], levels=levels, scheme="loop", boundary="none")
    panels = [Panel("holes = the top side", Vh, Fh, f"{len(Fh):,} faces: the closed surface, cut"),
              Panel("the top side deleted", Vd, Fd, f"{len(Fd):,} faces: its boundary a crease"),
              Panel('deleted, boundary="none"', Vn, Fn, f"{len(Fn):,} faces: the boundary faces left out")]
    bottom = os.path.join(out, "_options_holes.png")
    render_figure(panels, bottom, width=w, height=w * 30 // 100, view=(35, 40),
                  title=f"Loop, {levels} levels: a hole shapes its neighbours, a deleted face does not")
    _strip([top, bottom], os.path.join(out, "options_cube.png"))


def _checkerboard(squares):
    """A texture: ``squares`` × ``squares`` checkerboard over the unit UV square."""
    light, dark = np.array([0.95, 0.93, 0.88]), np.array([0.18, 0.33, 0.6])

    def image(uv):
        odd = (np.floor(uv[:, 0] * squares) + np.floor(uv[:, 1] * squares)) % 2 == 1
        return np.where(odd[:, None], dark, light)

    return image


def fig_textured(out, quick):
    """The textured bunny (OpenSubdiv's test scan, 1,289 UV seams), its texture drawn as a
    checkerboard from the UVs: input; two hybrid levels with linear and smooth UVs (welded,
    face-varying); two levels of the mesh as trimesh stores it (vertices split along the
    seams, not welded). Bottom row: a close-up of a seam on the back."""
    import trimesh

    from hybridsub._app import render as _render

    d = np.load(os.path.join(HERE, "..", "..", "tests", "data", "bunny10k_textured.fvar_linear.L1.npz"))
    V, F, UV, FUV = d["V_in"], d["F_in"], d["UV_in"], d["FUV_in"]
    n_seams = len(hybridsub.seam_edges(F, FUV))
    panels = [(f"input: {len(F):,} faces,\n{n_seams:,} UV seams", V, F, UV, FUV)]
    for mode in ("linear", "smooth"):
        V2, F2, UV2, FUV2 = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=2, uv_mode=mode)
        panels.append((f'hybrid, 2 levels, uv_mode="{mode}"\n{len(F2):,} faces', V2, F2, UV2, FUV2))
    vertex_of_uv = np.empty(len(UV), np.int64)
    vertex_of_uv[FUV.ravel()] = F.ravel()
    split = trimesh.Trimesh(V[vertex_of_uv], FUV, visual=trimesh.visual.TextureVisuals(uv=UV), process=False)
    apart = hybridsub.subdivide_mesh(split, 2, weld=False)
    panels.append(("not welded: seams refined as open\nboundaries (creases, cracks)", apart.vertices, apart.faces,
                   apart.visual.uv, apart.faces))
    size = 220 if quick else 330
    R = _render.view_rotation(0, 10)
    center = (V.min(axis=0) + V.max(axis=0)) / 2
    scale, mid, zspan = _render.fit(V - center, R, size, size)
    zoom, spot = 4.5, np.array([2.0, 0.6])  # the close-up: 4.5 times, on the seam across the back
    image = _checkerboard(24)
    fig, axs = plt.subplots(2, 4, figsize=(4 * size / 100, 2 * size / 100 + 0.75))
    for j, (title, A, B, U, T) in enumerate(panels):
        for i, frame in enumerate([(scale, mid, zspan), (scale * zoom, spot, zspan)]):
            axs[i, j].imshow(_render.render(A - center, B, R, size, size, frame=frame, texture=(U, T, image)))
            axs[i, j].set_axis_off()
        axs[0, j].set_title(title, fontsize=9)
        x = (spot[0] - mid[0]) * scale + size / 2
        y = size / 2 - (spot[1] - mid[1]) * scale
        h = size / zoom / 2
        axs[0, j].add_patch(plt.Rectangle((x - h, y - h), 2 * h, 2 * h, fill=False, color="tab:red", lw=1))
    fig.tight_layout(pad=0.3)
    _save(fig, os.path.join(out, "textured_bunny.png"), 100)


def fig_adaptive(out, quick):
    """Fandisk refined to a tolerance, faces coloured by level, beside the coarsest uniform
    level that is as close (its error measured the same way)."""
    from hybridsub._surface.adaptive import adaptive_result, uniform_error

    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, angle=30)
    tags = dict(sharp_edges=feat.sharp_edges, corners=feat.corners)
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    rel = 5e-3 if quick else 2e-4
    res = adaptive_result(V, F, tolerance=rel * diag, **tags)
    r = res.refinement
    L = 0
    while uniform_error(V, F, L, **tags) > res.tolerance and L < (1 if quick else 4):
        L += 1
    U = hybridsub.refine(F, levels=L, **tags)
    PU = hybridsub.limit_positions(V, F, levels=L, **tags)
    top = int(r.face_level.max())
    cmap = plt.get_cmap("YlOrRd")
    shade = (lambda j: cmap(0.12 + 0.78 * np.asarray(j) / max(top, 1)))
    fig, axs = plt.subplots(1, 2, figsize=(12, 6.0))
    az, el = 35, -60
    render(axs[0], res.positions, r.faces, azim=az, elev=el, colors=shade(r.face_level)[:, :3], wire=0.3)
    render(axs[1], PU, U.faces, azim=az, elev=el, wire=0.3)
    counts = np.bincount(r.face_level, minlength=top + 1)
    axs[0].set_title(f"adaptive, tolerance {rel:g} × diagonal: {len(r.faces):,} faces\n"
                     + ", ".join(f"{c:,} at level {j}" for j, c in enumerate(counts)), fontsize=10)
    axs[1].set_title(f"uniform level {L}: {len(U.faces):,} faces", fontsize=10)
    handles = [plt.Line2D([], [], marker="s", ls="", color=shade(j), label=f"level {j}") for j in range(top + 1)]
    axs[0].legend(handles=handles, loc="lower left", fontsize=8, frameon=False)
    fig.subplots_adjust(left=0.01, right=0.99, bottom=0.01, top=0.88, wspace=0.02)
    _save(fig, os.path.join(out, "adaptive_fandisk.png"), 90 if quick else 112)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=HERE)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--only", nargs="+", metavar="NAME", help="only these figures (e.g. fig_options)")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    figures = {f.__name__: f for f in (fig_features, fig_limit, fig_spectra, fig_charmaps, fig_semisharp,
                                       fig_textured, fig_adaptive, fig_options)}
    for f in (figures[n] for n in (args.only or figures)):
        t = time.time()
        f(args.out, args.quick)
        print(f"{f.__name__}: {time.time() - t:.1f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
