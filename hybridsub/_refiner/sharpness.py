"""The derivative of a refinement in its creases' sharpness: the step matrices of one call,
and for each step the derivative of its matrix in each given crease's sharpness.

Within one step a crease of sharpness ``0 < s <= 1`` (one that decays this step) enters two
kinds of rows, both affine in ``s`` (:mod:`hybridsub._rules.step_rules`): its edge point,
``s`` of the midpoint and ``1 − s`` of Loop's R4 point, and the masks of its two ends, which
blend their parent and child rules with ``w``, the mean sharpness of their decaying creases.
Creases with ``s > 1`` and the rest of the step do not depend on ``s``; which rule applies
where (the topology and which creases decay) is fixed by the integer parts. A crease given
with sharpness ``s`` has ``s − k`` at step ``k + 1``, so it decays at exactly one step (the
``⌈s⌉``-th), and the refined data is affine in each crease's sharpness between integers: the
derivative here is exact, that of the affine piece ``(⌈s⌉ − 1, ⌈s⌉]`` holding ``s`` (so at
an integer, the derivative from below); zero for ``s > levels`` and for infinite creases.

>>> import numpy as np
>>> from hybridsub._input import open_gate
>>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
>>> steps = sharpness_steps(open_gate(F, [[0, 1]], 1, scheme="loop", sharpness=[0.5]), np.array([[0, 1]]),
...                         np.array([0.5]))
>>> len(steps.matrices), steps.slopes[0].edge.tolist()[:4]
(1, [0, 0, 0, 0])
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .._input import RefineInput
from .._topology import LABEL_BASE, Level, StepPlan, blend_slopes, child_labels, face_parents
from .budget import Budget
from .loop import walk
from .stencils import step_matrix

#: The edge point's weights' derivative in its edge's sharpness: each end, each opposite vertex.
EDGE_SLOPE = (0.125, -0.125)


@dataclass(frozen=True, eq=False)
class Slopes:
    """The derivative of one step's matrix in the given creases' sharpness, as entries:
    ``d S[row, col] / d s[edge] += value`` (an entry may repeat)."""

    row: np.ndarray  # int64
    col: np.ndarray  # int64
    value: np.ndarray  # float64
    edge: np.ndarray  # int64, the row of the caller's crease list


@dataclass(frozen=True, eq=False)
class SharpnessSteps:
    """One call's step matrices, finest faces and each step's :class:`Slopes`."""

    matrices: list  # scipy.sparse.csr_matrix per step
    faces: np.ndarray
    slopes: list  # Slopes per step
    hole: np.ndarray | None = None  # (m,) the finest faces descending from a hole (None: no holes)


def sharpness_steps(inp: RefineInput, pairs: np.ndarray, sharpness: np.ndarray,
                    slopes: bool = True) -> SharpnessSteps:
    """Walk ``inp`` (no cut, no UVs) and differentiate each step in ``sharpness``.

    ``pairs`` (k, 2) and ``sharpness`` (k,) are the caller's creases as ``inp`` was opened
    with (checked by the gate, ``sharpness`` normalised: ``inf`` for ``>= 10``); slopes are
    reported against their rows. A crease listed twice takes the larger sharpness, and its
    derivative goes to the first row holding it. Without ``slopes`` only the matrices and
    faces (``slopes`` then empty).
    """
    if inp.cut is not None or inp.uv is not None:
        raise ValueError("sharpness derivatives are not available with non_manifold='cut' or uv_faces")
    if slopes and inp.corner_sharpness is not None and (np.isfinite(inp.corner_sharpness) & (inp.corner_sharpness > 0)).any():
        raise ValueError("sharpness derivatives are not available with semi-sharp corners (finite corner_sharpness): "
                         "give the corners infinite sharpness, or take no derivative in the creases' sharpness")
    labels = _first_labels(inp.level, pairs, sharpness)
    want = slopes
    matrices, slopes = [], []
    faces = inp.faces.copy()
    hole = inp.hole
    n0 = inp.n_vertices
    for s in walk(inp, Budget(inp.levels, inp.scheme, inp.max_memory)):  # refused before step 1 if too large
        matrices.append(step_matrix(s.level, s.plan))
        if hole is not None:
            hole = hole[face_parents(s.offsets)]
        if not want:
            faces = s.faces
            continue
        corner = np.zeros(s.level.n_vertices, bool)
        corner[:n0] = inp.corner
        slopes.append(_step_slopes(s.level, s.plan, corner, inp.loop_weights, labels, s.step - 1))
        if s.step < inp.levels:
            labels = child_labels(s.level, s.plan, labels)
        faces = s.faces
    return SharpnessSteps(matrices, faces, slopes, hole)


def _first_labels(level: Level, pairs: np.ndarray, sharpness: np.ndarray) -> np.ndarray:
    """Level 0's crease labels: ``LABEL_BASE + j`` on both halfedges of the edge of row ``j``
    with finite positive sharpness (an edge listed twice: its largest sharpness's first row)."""
    labels = np.zeros(3 * level.n_faces)
    live = np.flatnonzero((sharpness > 0) & np.isfinite(sharpness))
    if not len(live):
        return labels
    order = np.lexsort((live, -sharpness[live]))  # descending sharpness, then ascending row
    rows = live[order]
    h = level.find_halfedges(pairs[rows])
    for half in (h, level.twin[h]):
        keep = half >= 0
        first, at = np.unique(half[keep], return_index=True)
        labels[first] = LABEL_BASE + rows[keep][at]
    return labels


def _step_slopes(level: Level, plan: StepPlan, corner: np.ndarray, loop_weights: str, labels: np.ndarray,
                 k: int) -> Slopes:
    """The :class:`Slopes` of one step (level ``k`` → ``k + 1``)."""
    empty = Slopes(*(np.empty(0, dt) for dt in (np.int64, np.int64, np.float64, np.int64)))
    if level.hsharp is None or plan.scheme == "sqrt3":
        return empty
    owner = level.edge_owner
    t = level.twin[owner]
    s = level.hsharp[owner]
    live = (labels[owner] > 0) & (t >= 0) & (s > 0) & (s <= 1)
    h, t = owner[live], t[live]
    if not len(h):
        return empty
    edge = (labels[h] - LABEL_BASE + k).astype(np.int64)
    F = level.faces
    f, i = h // 3, h % 3
    u, w, a = F[f, i], F[f, (i + 1) % 3], F[f, (i + 2) % 3]
    b = F[t // 3, (t % 3 + 2) % 3]
    r = plan.edge_point[h].astype(np.int64)
    e_end, e_opp = EDGE_SLOPE
    rows = [np.repeat(r, 4)]
    cols = [np.stack([u, w, a, b], axis=1).ravel()]
    vals = [np.tile([e_end, e_end, e_opp, e_opp], len(h))]
    edges = [np.repeat(edge, 4)]
    dcoef, decaying = blend_slopes(level, corner, plan.scheme, plan.step, loop_weights)
    moving = np.flatnonzero(np.any(dcoef != 0, axis=0))
    if len(moving):
        # the vertex rows with the slopes for coefficients: rows are linear in them
        D = step_matrix(level, _with_coefficients(plan, dcoef))[:level.n_vertices]
        ends = np.concatenate([u, w])
        end_edge = np.concatenate([edge, edge])
        keep = np.any(dcoef[:, ends] != 0, axis=0)
        ends, end_edge = ends[keep], end_edge[keep]
        Dv = sp.csr_matrix(D[ends])
        Dv.eliminate_zeros()
        sizes = np.diff(Dv.indptr)
        rows.append(np.repeat(ends, sizes))
        cols.append(Dv.indices.astype(np.int64))
        vals.append(Dv.data / np.repeat(decaying[ends], sizes))
        edges.append(np.repeat(end_edge, sizes))
    return Slopes(*(np.concatenate(x) for x in (rows, cols, vals, edges)))


def _with_coefficients(plan: StepPlan, coefficients: np.ndarray) -> StepPlan:
    return dataclasses.replace(plan, coefficients=np.ascontiguousarray(coefficients))
