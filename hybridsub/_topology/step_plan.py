"""One step's plan: every decision a step makes from topology and tags (edge kinds, the
layout of the new points, every vertex mask as four coefficients), before any weight is
applied to data.

>>> import numpy as np
>>> from hybridsub._topology.level import checked_level
>>> level = checked_level(np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]), 4)
>>> plan = plan_step(level, np.zeros(4, bool), "sqrt3", 1, "loop")
>>> plan.n_new      # four old vertices and one face point per face
8
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numba
import numpy as np

from .._rules import step_rules as R
from . import _classify_kernels as C
from . import _kernels as K
from .level import Level

#: Most vertices a level may have: a step plan numbers its new points in int32 (half the
#: memory of int64; 2³¹ vertices would take 50 GB for their positions alone).
INDEX_LIMIT = 2**31 - 1


#: Empty arrays handed to kernels in place of an absent input.
EMPTY_FLOAT = np.empty(0, np.float64)
EMPTY_INT = np.empty(0, np.int64)
EMPTY_BOOL = np.empty(0, np.bool_)


@dataclass(frozen=True, eq=False)
class StepPlan:
    """Everything one step decides from topology and tags, before any weight is applied."""

    scheme: str
    step: int  # 1-based within the call; only "sqrt3" cares (Kobbelt's odd/even boundary)
    hkind: np.ndarray  # (3m,) int8 EDGE_* code of each halfedge's edge
    edge_point: np.ndarray  # (3m,) int32 index of the (first) new point on each halfedge's edge, −1 if none
    face_point: np.ndarray  # (m,) int32 index of the face point, −1 if none
    trisected: np.ndarray  # (m,) int8 local index of the trisected boundary halfedge, −1 if none
    coefficients: np.ndarray  # (4, n): every vertex mask, see _rules.vertex_mask
    n_new: int
    bnext: np.ndarray  # (3m,) boundary links, only for Kobbelt's even steps with edges to trisect (else empty)
    bprev: np.ndarray


def plan_step(level: Level, corner: np.ndarray, scheme: str, step: int, loop_weights: str,
              force_split: np.ndarray | None = None) -> StepPlan:
    """Classify edges and vertices of one step and lay out the new points.

    ``force_split`` (3m,) bool marks halfedges whose edges are split even between smooth
    faces (UV seams: R4 points, no flip); both halfedges of an edge must agree.

    Tags come from the level (``hsharp``, ``face_sharp``: all sharp for ``"loop"``, none for
    ``"sqrt3"``); ``corner`` (n,) is the corner mask, or each
    vertex's sharpness (float64: inf a corner, finite a semi-sharp corner, 0 none).
    """
    c = _classified(level, scheme, step, force_split)
    coefficients = _coefficients(level, c, corner, scheme, step, loop_weights, c.s_frac)
    if scheme == "sqrt3" and step % 2 == 0 and c.trisected.max(initial=-1) >= 0:  # boundary edges to trisect
        bnext, bprev = K.boundary_links(level.faces, level.twin)
    else:
        bnext = bprev = EMPTY_INT
    return StepPlan(scheme, step, c.hkind, c.edge_point, c.face_point, c.trisected, coefficients, c.n_new, bnext,
                    bprev)


def step_arguments(level: Level, plan: StepPlan) -> tuple:
    """The arguments the stencil kernels share, in their order."""
    has_tags = level.hsharp is not None and plan.scheme != "sqrt3"
    return (level.faces, level.twin, level.hsharp if has_tags else EMPTY_FLOAT, has_tags, plan.hkind,
            plan.edge_point, plan.face_point, plan.coefficients, plan.bnext, plan.bprev)


class _Classified(NamedTuple):
    """A step's classification: what :func:`plan_step` and :func:`blend_slopes` share."""

    hkind: np.ndarray
    edge_point: np.ndarray
    face_point: np.ndarray
    trisected: np.ndarray
    counts: np.ndarray  # (6, n), see _classify_kernels.classify_step
    s_frac: np.ndarray  # (n,) sum of the sharpness of each vertex's creases with 0 < s <= 1
    n_new: int
    region_of_all: int


def _classified(level: Level, scheme: str, step: int, force_split: np.ndarray | None) -> _Classified:
    """Edge kinds, the new points' layout and the per-vertex numbers the rules need."""
    F, twin = level.faces, level.twin
    m, n = level.n_faces, level.n_vertices
    odd = step % 2 == 1
    sqrt3 = scheme == "sqrt3"
    has_tags = level.hsharp is not None and not sqrt3
    if n + 4 * m > INDEX_LIMIT:  # new points: at most two per edge (≤ 3m/2 edges) and one per face
        raise MemoryError(f"a step of {m:,} faces and {n:,} vertices could make more than {INDEX_LIMIT:,} vertices, "
                          "more than the int32 indices of a step plan hold")
    hkind = np.empty(3 * m, np.int8)
    edge_point = np.empty(3 * m, np.int32)
    face_point = np.empty(m, np.int32)
    trisected = np.empty(m, np.int8)
    counts = np.zeros((6, n), np.int64)
    s_frac = np.zeros(n, np.float64)
    if force_split is not None and sqrt3:
        raise ValueError('scheme="sqrt3" flips every interior edge; forced splits need "hybrid" or "loop"')
    force = EMPTY_BOOL if force_split is None else np.ascontiguousarray(force_split, dtype=bool)
    n_sharp = int(np.count_nonzero(level.face_sharp))
    mixed = 0 < n_sharp < m
    region_of_all = -1 if mixed else (R.REGION_LOOP if n_sharp else R.REGION_SQRT3)
    args = (F, twin, level.hsharp if has_tags else EMPTY_FLOAT, has_tags, level.face_sharp, mixed, force,
            R.SCHEME_CODES[scheme], odd, hkind, edge_point, face_point, trisected, counts, s_frac)
    n_new = C.classify_step_chunks(*args, numba.get_num_threads()) if K.use_threads(m) else C.classify_step(*args)
    return _Classified(hkind, edge_point, face_point, trisected, counts, s_frac, int(n_new), region_of_all)


def _coefficients(level: Level, c: _Classified, corner: np.ndarray, scheme: str, step: int, loop_weights: str,
                  s_frac: np.ndarray) -> np.ndarray:
    """Every vertex mask as four coefficients, the semi-sharp blends from ``s_frac``."""
    n = level.n_vertices
    sqrt3 = scheme == "sqrt3"
    table = R.smooth_weight_table(int(c.counts[0].max()) if n else 0, loop_weights)
    cs, cn = R.KOBBELT_BOUNDARY_MASK if sqrt3 else R.CREASE_MASK
    coefficients = np.empty((4, n), np.float64)
    corner = np.ascontiguousarray(corner if corner.dtype == np.float64 else np.where(corner, np.inf, 0.0))
    (C.vertex_coefficients if K.use_threads(level.n_faces) else C.vertex_coefficients_serial)(
        c.counts, s_frac, corner, c.region_of_all, table, cs, cn, sqrt3 and step % 2 == 1, coefficients)
    return coefficients


def blend_slopes(level: Level, corner: np.ndarray, scheme: str, step: int,
                 loop_weights: str) -> tuple[np.ndarray, np.ndarray]:
    """How each vertex mask of a step moves with its semi-sharp blend ``w``.

    A vertex whose creases decay this step (``0 < s <= 1``) takes ``w · parent + (1 − w) ·
    child`` (:func:`hybridsub._rules.step_rules.vertex_mask`), ``w`` the mean sharpness of
    those creases: its four coefficients are affine in ``w``. Returns ``(slopes, decaying)``:
    ``slopes`` (4, n) the coefficients' derivative in ``w`` (the masks at ``w = 1`` less those
    at ``w = 0``; zero where nothing decays or both rules agree) and ``decaying`` (n,) the
    number of each vertex's decaying creases, so that a vertex's mask moves by ``slopes /
    decaying`` per unit of one of them.
    """
    c = _classified(level, scheme, step, None)
    decaying = c.counts[3].copy()
    at_one = _coefficients(level, c, corner, scheme, step, loop_weights, decaying.astype(np.float64))
    at_zero = _coefficients(level, c, corner, scheme, step, loop_weights, np.zeros(level.n_vertices))
    return at_one - at_zero, decaying
