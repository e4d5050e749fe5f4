"""The comparison figure of the paper (figs. 4–6): input with its sharp edges, √3, hybrid, Loop.

Panels are rendered by ``_render`` (z-buffer, off-screen) and laid out with matplotlib's Agg
canvas, which needs no display. matplotlib is an optional dependency (``hybridsub[plot]``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import render as _render
from .pipeline import SCHEME_NAMES
from .._input import count_of
from .._refiner import refine
from .._topology import undirected_edges

@dataclass
class Panel:
    title: str
    V: np.ndarray
    F: np.ndarray
    caption: str
    lines: np.ndarray | None = None
    semi: np.ndarray | None = None


def compare_panels(V, F, levels: int, *, sharp_edges=None, sharpness=None, sharp_faces=None, corners=None,
                   loop_weights="loop") -> list[Panel]:
    """Subdivide with the three schemes; the input panel shows creases (red: infinitely
    sharp, orange: semi-sharp) and boundary edges."""
    E = np.empty((0, 2), np.int64) if sharp_edges is None else np.asarray(sharp_edges, dtype=np.int64).reshape(-1, 2)
    s = np.full(len(E), np.inf) if sharpness is None else np.asarray(sharpness, dtype=np.float64)
    pairs, _, cnt = undirected_edges(np.asarray(F, dtype=np.int64), len(V))
    boundary = pairs[cnt == 1]
    n_sharp = len(E)
    caption = f"{len(F):,} faces · {n_sharp:,} sharp edges"
    if len(boundary):
        caption += f" · {len(boundary):,} boundary"
    panels = [Panel("input", V, F, caption, np.vstack([E[np.isinf(s)], boundary]), E[~np.isinf(s)])]
    for scheme in ("sqrt3", "hybrid", "loop"):
        tags = {} if scheme == "sqrt3" else dict(sharpness=sharpness, sharp_faces=sharp_faces, corners=corners)
        r = refine(F, None if scheme == "sqrt3" else sharp_edges, levels, n_vertices=len(V), scheme=scheme,
                   loop_weights=loop_weights, **tags)
        panels.append(Panel(f"{SCHEME_NAMES[scheme]}, {count_of(levels, 'level')}",
                            r.apply(V), r.faces, f"{len(r.faces):,} faces"))
    return panels


def render_figure(panels: list[Panel], path: str, *, width: int = 1600, height: int = 520,
                  view: tuple[float, float] | None = None, title: str | None = None) -> tuple[float, float]:
    """Render the panels side by side into a ``width`` × ``height`` PNG; returns the view used.

    All panels share one scale and view (chosen on the first panel unless ``view`` is given),
    fitted so that every panel shows whole."""
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError:
        raise ImportError("the figure needs matplotlib: python -m pip install 'hybridsub[plot]' "
                          "(or python -m pip install matplotlib)") from None
    ref = panels[0]
    allV = np.vstack([p.V for p in panels])  # one frame for all panels, big enough for each
    center = (allV.min(axis=0) + allV.max(axis=0)) / 2
    if view is None:
        view = _render.choose_view(ref.V, ref.F, ref.lines)
    R = _render.view_rotation(*view)
    k = len(panels)
    top = 34 if title else 0
    label = 64
    pw, ph = width // k, height - label - top
    if pw < 16 or ph < 16:
        raise ValueError(f"a {width}x{height} figure leaves no room for {k} panels")
    frame = _render.fit(allV - center, R, pw, ph)
    dpi = 100
    fig = Figure(figsize=(width / dpi, height / dpi), dpi=dpi, facecolor="white")
    FigureCanvasAgg(fig)
    if title:
        fig.text(0.5, 1 - 17 / height, title, ha="center", va="center", fontsize=13)
    for i, p in enumerate(panels):
        lines = [(p.lines, (0.85, 0.05, 0.05)), (p.semi, (0.95, 0.55, 0.0))]
        img = _render.render(p.V - center, p.F, R, pw, ph, frame=frame, lines=lines)
        x0 = (i * width / k + (width / k - pw) / 2) / width
        ax = fig.add_axes((x0, label / height, pw / width, ph / height))
        ax.imshow(img, interpolation="nearest")
        ax.set_axis_off()
        fig.text(x0 + pw / width / 2, (label - 20) / height, p.title, ha="center", va="center", fontsize=12,
                 weight="bold")
        fig.text(x0 + pw / width / 2, (label - 44) / height, p.caption, ha="center", va="center", fontsize=11,
                 color="0.25")
    fig.savefig(path, dpi=dpi, facecolor="white", format="png")
    return view

