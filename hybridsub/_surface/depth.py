"""How deep each point is followed: deeper the closer it lies to where the surface is not a
polynomial of the chart at any scale.

The descent ends with a quadratic interpolation on a face 3^(−depth/2) (√3 faces) or
2^(−depth) (Loop faces) of the input face's size. That is exact to rounding wherever the
limit surface is smooth over a few such faces, and is not in two places, at any depth:

* **round an irregular vertex** (valence other than 6, a boundary, a tag, faces of both
  types): the surface is a function of the distance r to the vertex that is homogeneous but
  not linear in the chart (the characteristic map), so while a point is in the vertex's
  one-ring the interpolation is off by a fixed fraction of r (up to 3e-7 of the diagonal at
  r = 1e-5 next to a valence-9 vertex, for both Loop and √3). A point is exact a few levels
  after it leaves the ring: ``4 + log₂(1/r)`` levels on Loop faces (then it reaches a
  regular patch), ``12 + 2 log₃(1/r)`` on √3 faces.
* **along a split edge beside a √3 face** (a crease or boundary of the hybrid, an edge
  between a sharp and a smooth face, Kobbelt's boundary in ``"sqrt3"``): the edge is halved
  (trisected) every step while the √3 faces along it shrink by √3, so the faces beside it
  flatten level after level; a point at distance δ from it needs ``16 + 2 log₃(1/δ)`` levels,
  and next to a vertex on such an edge (where a crease sector gains a face every level)
  ``22 + 2 log₃(1/r)``.

Measured on fandisk (creases, a sharp/smooth interface, vertices of valence 3 to 9) and an
open patch (Kobbelt's boundary), against the same points at depth 56, points at distances
10⁻¹ … 10⁻¹² (``docs/limit.md``, "Accuracy"). Points closer than ``AT_VERTEX`` to a vertex
take its limit position, exactly; points exactly on a split edge converge along it.
"""

from __future__ import annotations

import numpy as np

from .._input import RefineInput
from ._walk_kernels import AT_VERTEX

#: Levels past the one where the faces' size equals the distance (see the module docstring).
EDGE_LEVELS = 16
GRADED_VERTEX_LEVELS = 22
SQRT3_VERTEX_LEVELS = 12
LOOP_VERTEX_LEVELS = 4
#: Depth of a point exactly on a split edge beside a √3 face: it stays in the faces along the
#: edge, which converge (measured: between a sharp and a smooth face 2e-11 of the diagonal at
#: 24 levels, 5e-12 at 26, 3e-14 at 32; on a boundary 8.5e-13 from 18 to 36, 4e-14 at 40).
ON_EDGE_DEPTH = 40
#: No point goes deeper than this (unless ``depth`` itself is deeper): √3 faces are then
#: 3^(−28) ≈ 4e-14 of the input face's size, about where the chart's rounding starts to show.
MAX_DEPTH = 56

_CORNER = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3.0) / 2]])
_HEIGHT = np.sqrt(3.0) / 2


def _graded_halfedges(inp: RefineInput) -> np.ndarray:
    """(m, 3) bool: halfedge ``3f + i`` lies on a split edge with a √3 face on a side."""
    lvl, m = inp.level, inp.n_faces
    if inp.scheme == "loop":
        return np.zeros((m, 3), bool)
    twin = np.asarray(lvl.twin, np.int64)
    boundary = twin < 0
    if inp.scheme == "sqrt3":
        return boundary.reshape(m, 3)
    sharp = np.asarray(lvl.face_sharp, bool)
    smooth = ~np.repeat(sharp, 3)
    smooth_twin = np.where(boundary, False, ~sharp[np.where(boundary, 0, twin) // 3])
    crease = boundary if lvl.hsharp is None else boundary | (np.asarray(lvl.hsharp) > 0)
    split = crease | ~smooth | (~boundary & ~smooth_twin)
    return (split & (smooth | smooth_twin)).reshape(m, 3)


def _irregular_vertices(inp: RefineInput) -> np.ndarray:
    """(n,) bool: not an untagged interior vertex of valence 6 with faces of one type."""
    lvl, n = inp.level, inp.n_vertices
    F = np.asarray(inp.faces, np.int64)
    valence = np.bincount(F.ravel(), minlength=n)
    odd = (valence != 6) | inp.corner
    ends = np.stack([F, np.roll(F, -1, axis=1)], -1).reshape(-1, 2)  # halfedge 3f + i: F[f, i] → F[f, i + 1]
    tagged = np.asarray(lvl.twin) < 0
    if lvl.hsharp is not None:
        tagged |= np.asarray(lvl.hsharp) > 0
    odd[ends[tagged].ravel()] = True
    sharp = np.repeat(np.asarray(inp.face_sharp, bool), 3)
    some = np.bincount(F.ravel(), weights=sharp, minlength=n)
    odd |= (some > 0) & (some < valence)
    return odd


class PointDepths:
    """The depth each point of a surface is followed to (see the module docstring)."""

    def __init__(self, inp: RefineInput, default: int):
        self.default = default
        self.sqrt3 = inp.scheme == "sqrt3"
        F = np.asarray(inp.faces, np.int64)
        self.edge = _graded_halfedges(inp)
        graded = np.zeros(inp.n_vertices, bool)
        graded[F[self.edge]] = True
        graded[np.roll(F, -1, axis=1)[self.edge]] = True
        loop_face = np.asarray(inp.face_sharp, bool)
        # Per face corner, the levels past the faces' size reaching r (none: −inf).
        levels = np.where(loop_face, LOOP_VERTEX_LEVELS, SQRT3_VERTEX_LEVELS)[:, None].astype(float)
        self.vertex = np.where(graded[F], float(GRADED_VERTEX_LEVELS),
                               np.where(_irregular_vertices(inp)[F], levels, -np.inf))
        self.halving = loop_face  # a level halves the face (Loop) instead of dividing it by √3
        self.any = self.edge.any(axis=1) | np.isfinite(self.vertex).any(axis=1)
        # Beyond these distances no rule asks for more than the default (the loosest face type).
        self._per_level = np.log(2.0) if loop_face.size and loop_face.all() else np.log(3.0) / 2
        self._vmax = self.vertex.max() if np.isfinite(self.vertex).any() else -np.inf

    def _reach(self, base: int) -> tuple[float, float]:
        """The distances to an irregular vertex and to a split edge beyond which no rule asks for
        more than ``base`` levels."""
        vertex = float(np.exp(-(base - self._vmax) * self._per_level))
        edge = float(np.exp(-(base - EDGE_LEVELS) * self._per_level)) if self.edge.any() else 0.0
        return vertex, edge

    def __call__(self, f: np.ndarray, b: np.ndarray, depth: int, rule_depth: int | None = None) -> np.ndarray:
        """Depth of each point (face ``f``, bary ``b``) for a surface of depth ``depth``: the
        rule's depth shifted by ``depth`` − the scheme's default, between ``depth`` and
        ``max(depth, MAX_DEPTH)``. With ``rule_depth`` (deeper than ``depth``: the surface's
        own depth), the rule is that of ``rule_depth``: points it takes deeper than ``depth``
        keep their depth there, so a shallow evaluation (``project``'s first iterations) is off
        by no more next to irregular vertices and split edges than elsewhere."""
        out = np.full(len(f), depth, np.int64)
        if depth >= MAX_DEPTH:
            return out
        shift = max(depth, rule_depth if rule_depth is not None else depth) - self.default
        reach_vertex, reach_edge = self._reach(depth - shift)
        # |p − corner i| ≥ (1 − b_i) × height and the distance to edge i is b_(i+2) × height.
        b0, b1, b2 = b[:, 0], b[:, 1], b[:, 2]
        close = np.maximum(np.maximum(b0, b1), b2) > 1 - reach_vertex / _HEIGHT
        if reach_edge > 0:
            close |= np.minimum(np.minimum(b0, b1), b2) < reach_edge / _HEIGHT
        near = np.flatnonzero(close & self.any[f])
        if not len(near):
            return out
        fn, bn = f[near], b[near]
        per_level = np.where(self.halving[fn], np.log(2.0), np.log(3.0) / 2)  # log of 1 / the level's shrink
        need = np.zeros(len(near))
        on_edge = np.zeros(len(near), bool)
        p = bn @ _CORNER
        with np.errstate(divide="ignore", invalid="ignore"):  # log(0): the terms np.where drops
            for i in range(3):
                delta = bn[:, (i + 2) % 3] * _HEIGHT
                graded = self.edge[fn, i]
                need = np.where(graded & (delta > 0), np.maximum(need, EDGE_LEVELS - np.log(delta) / per_level), need)
                on_edge |= graded & (delta == 0)
                r = np.linalg.norm(p - _CORNER[i], axis=1)
                near_vertex = np.isfinite(self.vertex[fn, i]) & (r > 0)
                need = np.where(near_vertex, np.maximum(need, self.vertex[fn, i] - np.log(r) / per_level), need)
        need = np.where(on_edge, np.maximum(np.minimum(need, MAX_DEPTH), ON_EDGE_DEPTH),
                        np.minimum(need, MAX_DEPTH))
        d = np.clip(np.ceil(need).astype(np.int64) + shift, depth, MAX_DEPTH)
        d[bn.max(axis=1) >= 1 - AT_VERTEX] = depth  # the last level's vertex: its limit position, exactly
        if self.sqrt3:
            d += d % 2  # Kobbelt's boundary: even levels
        out[near] = d
        return out
