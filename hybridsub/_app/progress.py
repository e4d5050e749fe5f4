"""Refinement level by level, with a progress bar on stderr.

The file pipeline refines with :func:`hybridsub._refiner.subdivide_levels`, the fast path of
``subdivide`` (or, for a mesh with UVs, ``subdivide_face_varying_levels``),
which yields each level as it is done with its propagated tags: the bar moves per level,
only two levels are held at a time, and no matrix is formed.
"""

from __future__ import annotations

import shutil
import sys
import time
from dataclasses import dataclass

import numpy as np

from .._input import open_gate
from .._refiner import subdivide_face_varying_levels, subdivide_levels
from .._units import si


@dataclass
class LevelResult:
    X: np.ndarray  # (n_L, d) refined per-vertex data
    faces: np.ndarray
    sharp_edges: np.ndarray
    sharpness: np.ndarray
    sharp_faces: np.ndarray  # mask
    corners: np.ndarray
    face_parent: np.ndarray  # input face of each output face
    seconds: float
    uv: np.ndarray | None = None  # (t_L, e) refined face-varying data, with uv=
    face_uv: np.ndarray | None = None  # (m_L, 3) its index of each face corner
    corner_sharpness: np.ndarray | None = None  # the sharpness left to each of corners (None: all infinite)


def refine_by_level(X, F, levels: int, *, scheme="hybrid", sharp_edges=None, sharpness=None, sharp_faces=None,
                    corners=None, loop_weights="loop", on_level=None, max_memory=None, uv=None, face_uv=None,
                    uv_mode="linear", non_manifold="raise", corner_sharpness=None,
                    boundary="edge_only", holes=None) -> LevelResult:
    """Refine ``F`` and the per-vertex data ``X (n, d)`` level by level.

    ``on_level(done, levels, n_faces, seconds)`` is called after each level; ``max_memory``
    as in :func:`hybridsub.subdivide`. With ``uv (t, e)`` and ``face_uv (m, 3)`` the
    face-varying data is refined too (``uv_mode``), seams split as in
    :func:`hybridsub.subdivide_face_varying`. ``corner_sharpness``, ``boundary`` and ``holes``
    as in :func:`hybridsub.subdivide`: the faces descending from holes (and, with ``"none"``,
    from the faces at the boundary) are left out of the result (positions unchanged).
    """
    X = np.ascontiguousarray(X, dtype=np.float64)
    F = F0 = np.asarray(F, dtype=np.int64)
    n0 = len(X)
    parent = np.arange(len(F), dtype=np.int64)
    pairs, sharp = sharp_edges, sharpness
    mask = None
    total = 0.0
    tags = dict(sharpness=sharpness, sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights,
                max_memory=max_memory, non_manifold=non_manifold, corner_sharpness=corner_sharpness,
                boundary=boundary)
    if uv is not None:
        uv = np.ascontiguousarray(uv, dtype=np.float64)
        face_uv = np.asarray(face_uv, dtype=np.int64)
        mode = {"linear": "all", "smooth": "none"}.get(uv_mode, uv_mode)  # uv_mode or a uv_interpolation name
        run = subdivide_face_varying_levels(X, F, uv, face_uv, sharp_edges, levels, scheme=scheme,
                                            uv_interpolation=mode, **tags)
    else:
        run = subdivide_levels(X, F, sharp_edges, levels, scheme=scheme, holes=holes, **tags)
    t = time.perf_counter()
    for out in run:
        X, F, pairs, sharp, mask = out.X, out.faces, out.sharp_edges, out.sharpness, out.sharp_faces
        if uv is not None:
            uv, face_uv = out.UV, out.uv_faces
        parent = parent[out.face_parent]
        dt = time.perf_counter() - t
        total += dt
        if on_level is not None:
            on_level(out.step, levels, len(F), dt)
        t = time.perf_counter()
    if mask is None:  # no step ran: the input's tags
        mask = np.zeros(len(F), bool)
        if sharp_faces is not None:
            mask[np.asarray(sharp_faces)] = True
    if pairs is None:
        pairs, sharp = np.empty((0, 2), np.int64), np.empty(0)
    if sharp is None:
        sharp = np.full(len(pairs), np.inf)
    inp = open_gate(F0, sharp_edges, 0, n_vertices=n0, scheme=scheme, sharpness=sharpness, sharp_faces=sharp_faces,
                    corners=corners, loop_weights=loop_weights, non_manifold=non_manifold if levels else "raise",
                    corner_sharpness=corner_sharpness, boundary=boundary, holes=holes)
    # the cut's copies and edge_and_corner's vertices are corners too (input vertices keep their numbers);
    # semi-sharp corners spent by the last level are corners no more
    left = None if inp.corner_sharpness is None else inp.corner_sharpness - levels
    corners = np.flatnonzero(inp.corner if left is None else left > 0)
    left = None if left is None or not np.isfinite(left[corners]).any() else left[corners]
    mask = np.asarray(mask)
    if inp.hole is not None and levels:  # the faces of holes left out
        keep = ~inp.hole[parent]
        F, mask, parent = F[keep], mask[keep], parent[keep]
        face_uv = None if face_uv is None else face_uv[keep]
    return LevelResult(X, F, np.asarray(pairs), np.asarray(sharp), mask, corners, parent, total, uv,
                       face_uv, left)


class _StatusLine:
    """One tqdm line on a stream (stderr), redrawn in place: a label, a bar, a percentage and
    text. tqdm sizes it to the terminal; it is imported only when the line is enabled."""

    _STEPS = 1000  # the bar's resolution

    def __init__(self, label: str, enabled: bool, stream=None):
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled
        self.label = label
        self.bar = None

    def draw(self, frac: float, info: str) -> None:
        if self.bar is None:
            from tqdm import tqdm

            label = self.label.replace("{", "{{").replace("}", "}}")
            self.bar = tqdm(total=self._STEPS, file=self.stream, leave=True, mininterval=0,
                            ncols=shutil.get_terminal_size((80, 20)).columns - 1, nrows=20,
                            bar_format=label + " [{bar:20}] {percentage:3.0f}%  {desc}", ascii=" #")
        self.bar.n = int(round(min(max(frac, 0.0), 1.0) * self._STEPS))
        self.bar.set_description_str(info, refresh=False)
        self.bar.refresh()

    def close(self) -> None:
        if self.enabled and self.bar is not None:
            self.bar.close()
            self.bar = None


class ProgressBar(_StatusLine):
    """One line on stderr, redrawn after each level: bar (weighted by the predicted faces of
    each level, since a level's cost is proportional to the faces it makes), level, faces,
    faces per second. Silent unless enabled (the command line enables it when stderr is a
    terminal and ``--quiet`` is not given)."""

    def __init__(self, predicted_faces: list[int], label: str, enabled: bool, stream=None):
        super().__init__(label, enabled, stream)
        self.cum = np.cumsum([0] + list(predicted_faces), dtype=np.float64)
        self.levels = len(predicted_faces)
        if enabled:
            self._draw(0, "starting")

    def update(self, done: int, levels: int, n_faces: int, seconds: float) -> None:
        if not self.enabled:
            return
        rate = n_faces / seconds if seconds > 0 else float("inf")
        info = f"level {done}/{levels}: {n_faces:,} faces, {si(rate)} faces/s"
        if done < levels:
            nxt = int(self.cum[min(done + 1, self.levels)] - self.cum[done])
            info += f"; next {nxt:,}"
        self._draw(done, info)

    def _draw(self, done: int, info: str) -> None:
        self.draw(self.cum[done] / self.cum[-1] if self.cum[-1] > 0 else 1.0, info)


class BatchProgress(_StatusLine):
    """One line on stderr for ``hybridsub batch``, redrawn as meshes finish (at most ten times a
    second): bar and count of meshes finished (done or skipped) out of those found so far
    (``+`` while the inputs are still being walked), failures, output faces per second of wall
    time. Silent unless enabled."""

    def __init__(self, total: int, enabled: bool, stream=None):
        super().__init__("batch", enabled, stream)
        self.total = total
        self.last = -1.0

    def update(self, finished: int, failed: int, faces: int, seconds: float, total: int | None = None,
               planning: bool = False) -> None:
        if total is not None:
            self.total = total
        if not self.enabled:
            return
        now = time.perf_counter()
        if (planning or finished + failed < self.total) and now - self.last < 0.1:
            return
        self.last = now
        info = f"{finished + failed:,}/{self.total:,}{'+' if planning else ''} meshes"
        if failed:
            info += f" ({failed:,} failed)"
        if seconds > 0:
            info += f", {si(faces / seconds)} faces/s"
        self.draw((finished + failed) / self.total if self.total else 1.0, info)
