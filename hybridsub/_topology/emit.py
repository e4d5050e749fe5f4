"""Emission: the next level's faces, twins and tags, derived from a level and its plan
instead of searched again, and the tags handed back to the user (parent faces, creases as
vertex pairs).

>>> import numpy as np
>>> from hybridsub._topology.level import checked_level
>>> from hybridsub._topology.step_plan import plan_step
>>> level = checked_level(np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]), 4)
>>> faces, child, offsets = child_level(level, plan_step(level, np.zeros(4, bool), "sqrt3", 1, "loop"))
>>> faces.shape, child.n_vertices, face_parents(offsets)[:4].tolist()
((12, 3), 8, [0, 0, 0, 1])
"""

from __future__ import annotations

import numpy as np

from .._rules import step_rules as R
from . import _kernels as K
from .level import Level
from .step_plan import EMPTY_FLOAT, StepPlan


def child_level(level: Level, plan: StepPlan, want_topology: bool = True):
    """The next level (faces, twins, tags) and the parent face of each of its faces.

    Without ``want_topology`` only the faces are built (for the last step of a call), and the
    parents are not returned (None): nothing holds them while the data is refined.
    """
    m = level.n_faces
    face_sharp = level.face_sharp
    offsets = np.empty(m + 1, np.int64)
    first = np.empty(3 * m, np.int32)  # child face numbers: fewer than 4m (plan_step checks 2³¹)
    K.child_offsets(plan.hkind, face_sharp, offsets, first)
    total = int(offsets[m])
    has_tags = level.hsharp is not None and plan.scheme != "sqrt3"
    faces = np.empty((total, 3), np.int64)
    twin = np.empty(3 * total if want_topology else 0, np.int64)
    hsharp = np.zeros(3 * total if want_topology and has_tags else 0)
    child_sharp = np.zeros(total if want_topology else 0, bool)
    big = K.use_threads(m)
    (K.emit_faces if big else K.emit_faces_serial)(
        level.faces, level.twin, plan.hkind, plan.edge_point, plan.face_point, plan.trisected, face_sharp, first,
        faces)
    child = None
    if want_topology:
        (K.emit_topology if big else K.emit_topology_serial)(
            level.twin, level.hsharp if has_tags else EMPTY_FLOAT, has_tags, plan.hkind, plan.face_point,
            plan.trisected, face_sharp, first, twin, hsharp, child_sharp, level.far_apart)
        child = Level(faces, plan.n_new, twin, hsharp if has_tags else None, child_sharp)
    return faces, child, offsets if want_topology else None


def face_parents(offsets: np.ndarray) -> np.ndarray:
    """Parent face of each child face, from the child offsets of the parents."""
    return np.repeat(np.arange(len(offsets) - 1, dtype=np.int64), np.diff(offsets))


def child_creases(level: Level, plan: StepPlan):
    """Tagged creases of the next level as vertex pairs: children (u, m), (m, w) of each
    tagged crease with s > 1, in edge order and the owner's orientation, with s − 1.

    Boundary edges are creases implicitly: a tag on one is not carried on.
    """
    if level.hsharp is None or plan.scheme == "sqrt3":
        return np.empty((0, 2), np.int64), np.empty(0)
    owner = level.edge_owner
    s = level.hsharp[owner]
    keep = owner[(s > 1) & (level.twin[owner] >= 0) & (plan.hkind[owner] == R.EDGE_SPLIT)]
    F = level.faces
    f, i = keep // 3, keep % 3
    u, w = F[f, i], F[f, (i + 1) % 3]
    mid = plan.edge_point[keep].astype(np.int64)
    pairs = np.empty((2 * len(keep), 2), np.int64)
    pairs[0::2, 0] = u
    pairs[0::2, 1] = mid
    pairs[1::2, 0] = mid
    pairs[1::2, 1] = w
    return pairs, np.repeat(R.child_sharpness(level.hsharp[keep]), 2)


#: Offset of the crease labels :func:`child_labels` carries: above every sharpness, so that
#: the emission passes every label on (less one per level, as it does a sharpness).
LABEL_BASE = 2.0**40


def child_labels(level: Level, plan: StepPlan, labels: np.ndarray) -> np.ndarray:
    """A per-halfedge label carried from a level's creases onto their children.

    ``labels`` (3m,) float64 holds ``LABEL_BASE + j`` on the halfedges of the creases to
    follow (``j`` ≥ 0 an integer, e.g. the row of the caller's crease list) and 0 elsewhere;
    the result holds ``LABEL_BASE + j − 1`` on the next level's halfedges of their split
    children, 0 elsewhere: the emission (:func:`child_level`) of a level tagged with the
    labels as its sharpness. After ``k`` steps a label reads ``j = label − LABEL_BASE + k``.
    """
    tagged = Level(level.faces, level.n_vertices, level.twin, np.ascontiguousarray(labels, np.float64),
                   level.face_sharp, level._by_origin)
    return child_level(tagged, plan)[1].hsharp
