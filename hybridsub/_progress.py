"""Refinement level by level, with a progress bar on stderr.

``refine`` runs all its levels in one call and keeps every step's matrix. The command line
instead refines one level at a time, applies that step to the positions (and colours, UVs)
at once and drops it, so it can report each level as it finishes and never holds more than
two levels. Calling ``refine(levels=1)`` repeatedly, carrying the propagated tags, is the
same computation as one call with ``"hybrid"`` and ``"loop"`` (a step depends only on the
level's faces and tags) and with ``"sqrt3"`` on closed meshes. Kobbelt's boundary rule counts
odd and even steps within a call, so on open meshes ``"sqrt3"`` goes two levels per call
(odd, even), which keeps the parity. ``tests/test_cli.py`` checks all of this against single
calls.
"""

from __future__ import annotations

import shutil
import sys
import time
from dataclasses import dataclass

import numpy as np

from ._meshinfo import _edges
from ._refine import refine


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


def refine_by_level(X, F, levels: int, *, scheme="hybrid", sharp_edges=None, sharpness=None, sharp_faces=None,
                    corners=None, loop_weights="loop", on_level=None, max_memory=None) -> LevelResult:
    """Refine ``F`` and the per-vertex data ``X (n, d)`` level by level.

    ``on_level(done, levels, n_faces, seconds)`` is called after each call to ``refine`` (one
    level, or two for ``"sqrt3"`` on an open mesh). ``max_memory`` goes to every ``refine``.
    """
    X = np.asarray(X, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    n = len(X)
    chunk = 1
    if scheme == "sqrt3" and levels > 1 and len(F) and (_edges(F, n)[2] == 1).any():
        chunk = 2
    if sharp_faces is not None:
        mask = np.zeros(len(F), bool)
        mask[np.asarray(sharp_faces)] = True
        sharp_faces = mask
    parent = np.arange(len(F), dtype=np.int64)
    done, total = 0, 0.0
    while done < levels:
        k = min(chunk, levels - done)
        t = time.perf_counter()
        r = refine(F, sharp_edges, k, n_vertices=n, scheme=scheme, sharpness=sharpness, sharp_faces=sharp_faces,
                   corners=corners, loop_weights=loop_weights, max_memory=max_memory)
        X = r.apply(X)
        F, sharp_edges, sharpness, sharp_faces, corners = r.faces, r.sharp_edges, r.sharpness, r.sharp_faces, r.corners
        parent = parent[r.face_parent]
        n = r.n_vertices
        del r
        dt = time.perf_counter() - t
        total += dt
        done += k
        if on_level is not None:
            on_level(done, levels, len(F), dt)
    if sharp_faces is None:
        sharp_faces = np.zeros(len(F), bool)
    if sharp_edges is None:
        sharp_edges, sharpness = np.empty((0, 2), np.int64), np.empty(0)
    corners = np.empty(0, np.int64) if corners is None else np.asarray(corners, dtype=np.int64)
    if sharpness is None:
        sharpness = np.full(len(sharp_edges), np.inf)
    return LevelResult(X, F, np.asarray(sharp_edges), np.asarray(sharpness), np.asarray(sharp_faces), corners,
                       parent, total)


def _si(x: float) -> str:
    for unit, div in (("G", 1e9), ("M", 1e6), ("k", 1e3)):
        if x >= div:
            return f"{x / div:.1f} {unit}"
    return f"{x:.0f}"


class ProgressBar:
    """One line on stderr, redrawn after each level: bar (weighted by the predicted faces of
    each level, since a level's cost is proportional to the faces it makes), level, faces,
    faces per second. Silent unless enabled (the command line enables it when stderr is a
    terminal and ``--quiet`` is not given)."""

    def __init__(self, predicted_faces: list[int], label: str, enabled: bool, stream=None):
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled
        self.label = label
        self.cum = np.cumsum([0] + list(predicted_faces), dtype=np.float64)
        self.levels = len(predicted_faces)
        self.shown = False
        if enabled:
            self._draw(0, "starting")

    def update(self, done: int, levels: int, n_faces: int, seconds: float) -> None:
        if not self.enabled:
            return
        rate = n_faces / seconds if seconds > 0 else float("inf")
        info = f"level {done}/{levels}: {n_faces:,} faces, {_si(rate)} faces/s"
        if done < levels:
            nxt = int(self.cum[min(done + 1, self.levels)] - self.cum[done])
            info += f"; next {nxt:,}"
        self._draw(done, info)

    def _draw(self, done: int, info: str) -> None:
        width = shutil.get_terminal_size((80, 20)).columns
        frac = self.cum[done] / self.cum[-1] if self.cum[-1] > 0 else 1.0
        bar_w = 20 if width >= 100 else 10
        full = int(round(frac * bar_w))
        line = f"{self.label} [{'#' * full}{'.' * (bar_w - full)}] {frac * 100:3.0f}%  {info}"
        self.stream.write("\r" + line[:width - 1].ljust(width - 1))
        self.stream.flush()
        self.shown = True

    def close(self) -> None:
        if self.enabled and self.shown:
            self.stream.write("\n")
            self.stream.flush()
            self.shown = False
