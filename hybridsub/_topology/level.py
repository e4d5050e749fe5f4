"""Topology and tags of one level, and one step's classes.

This is the layer between the rules (``_rules``: weights from neighbourhood numbers) and
the matrices (``_stencils``): it knows connectivity and tags, never positions. A
:class:`Level` is a mesh's faces with its halfedge twins and tags; :func:`plan_step`
classifies one step (edge kinds, vertex masks, the layout of the new points);
:func:`child_level` builds the next level from the plan, deriving its twins and tags
instead of searching for them again.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from . import _kernels as K
from .._rules import refinement as R
from .._errors import MeshError


class Level:
    """Connectivity and tags of one level.

    Attributes
    ----------
    faces : (m, 3) int64
    n_vertices : int
    twin : (3m,) int64
        Halfedge across each halfedge ``3f + i`` (−1 on the boundary).
    hsharp : (3m,) float64 or None
        Tagged sharpness of each halfedge's edge (0 untagged, inf infinitely sharp); None
        when nothing is tagged.
    face_sharp : (m,) bool
        Sharp faces (refined 1-to-4).
    """

    def __init__(self, faces, n_vertices, twin, hsharp=None, face_sharp=None, by_origin=None):
        self.faces = faces
        self.n_vertices = int(n_vertices)
        self.twin = twin
        self.hsharp = hsharp
        self.face_sharp = np.zeros(len(faces), dtype=bool) if face_sharp is None else face_sharp
        self._by_origin = by_origin

    @property
    def n_faces(self) -> int:
        return self.faces.shape[0]

    @cached_property
    def _edges(self):
        return K.number_edges(self.twin)

    @property
    def edge_of(self) -> np.ndarray:
        """(3m,) edge of each halfedge, edges numbered in order of first appearance."""
        return self._edges[0]

    @property
    def edge_owner(self) -> np.ndarray:
        """(ne,) lower-numbered halfedge of each edge."""
        return self._edges[1]

    @property
    def n_edges(self) -> int:
        return self.edge_owner.shape[0]

    @property
    def edge_vertices(self) -> np.ndarray:
        """(ne, 2) edges as vertex pairs in their owner halfedge's orientation."""
        h = self.edge_owner
        f, i = h // 3, h % 3
        return np.stack([self.faces[f, i], self.faces[f, (i + 1) % 3]], axis=1)

    @property
    def boundary_edge(self) -> np.ndarray:
        return self.twin[self.edge_owner] < 0

    @property
    def valence(self) -> np.ndarray:
        """(n,) number of distinct neighbours of each vertex."""
        return np.bincount(self.edge_vertices.ravel(), minlength=self.n_vertices)

    @property
    def by_origin(self) -> np.ndarray:
        """(3m,) halfedges grouped by origin vertex (see ``origin_start``)."""
        return self._origin_groups()[0]

    @property
    def origin_start(self) -> np.ndarray:
        """(n + 1,) ``by_origin[origin_start[v]:origin_start[v+1]]`` leave vertex v."""
        return self._origin_groups()[1]

    def _origin_groups(self):
        if self._by_origin is None:
            self._by_origin = K.group_by_origin(self.faces, self.n_vertices)
        return self._by_origin

    def find_halfedges(self, pairs: np.ndarray) -> np.ndarray:
        """A halfedge of each vertex pair's edge, −1 where the mesh has no such edge."""
        pairs = np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2)
        return K.find_halfedges(pairs, self.faces, self.by_origin, self.origin_start)

    def find_edges(self, pairs: np.ndarray) -> np.ndarray:
        """Edge index of each vertex pair, −1 where the mesh has no such edge."""
        h = self.find_halfedges(pairs)
        return np.where(h >= 0, self.edge_of[np.maximum(h, 0)], -1)

    def tag(self, pairs: np.ndarray, sharpness: np.ndarray, face_sharp: np.ndarray) -> "Level":
        """This level with creases (vertex pairs, sharpness > 0) and sharp faces tagged.

        Raises MeshError naming the first pair that is not an edge; a pair listed twice keeps
        its largest sharpness.
        """
        hsharp = None
        if len(pairs):
            h = self.find_halfedges(pairs)
            if (h < 0).any():
                j = int(np.flatnonzero(h < 0)[0])
                raise MeshError(f"sharp edge {j} = {pairs[j].tolist()} is not an edge of the mesh")
            hsharp = np.zeros(3 * self.n_faces)
            np.maximum.at(hsharp, h, sharpness)
            t = self.twin[h]
            inner = t >= 0
            np.maximum.at(hsharp, t[inner], sharpness[inner])
        return Level(self.faces, self.n_vertices, self.twin, hsharp, face_sharp, self._by_origin)


def build_level(faces: np.ndarray, n_vertices: int) -> Level:
    """Build the halfedge twins of a mesh, or raise MeshError naming the offending edge.

    ``faces`` must already be an (m, 3) int64 array with indices in range and no repeated
    vertex within a face.
    """
    F = np.ascontiguousarray(faces, dtype=np.int64)
    twin, by_origin, origin_start, err, h = K.halfedge_twins(F, n_vertices)
    if err != K.OK:
        raise _edge_error(F, int(h))
    return Level(F, n_vertices, twin, by_origin=(by_origin, origin_start))


def _edge_error(F: np.ndarray, h: int) -> MeshError:
    u, w = int(F[h // 3, h % 3]), int(F[h // 3, (h % 3 + 1) % 3])
    he = np.stack([F, np.roll(F, -1, axis=1)], axis=2).reshape(-1, 2)
    same = np.flatnonzero((he[:, 0] == u) & (he[:, 1] == w)) // 3
    other = np.flatnonzero((he[:, 0] == w) & (he[:, 1] == u)) // 3
    faces = sorted(set(same.tolist()) | set(other.tolist()))
    if len(faces) > 2:
        return MeshError(
            f"edge ({min(u, w)}, {max(u, w)}) is shared by {len(faces)} faces {faces}: the mesh is not "
            "edge-manifold (every edge must lie in one or two faces)"
        )
    return MeshError(
        f"faces {int(same[0])} and {int(same[1])} both run along edge {u}->{w} in the same direction: "
        "the mesh is not consistently oriented (fix the winding, e.g. trimesh.repair.fix_winding(mesh) "
        "or igl.bfs_orient)"
    )


@dataclass(frozen=True, eq=False)
class StepPlan:
    """Everything one step decides from topology and tags, before any weight is applied."""

    scheme: str
    step: int  # 1-based within the call; only "sqrt3" cares (Kobbelt's odd/even boundary)
    hkind: np.ndarray  # (3m,) int8 EDGE_* code of each halfedge's edge
    edge_point: np.ndarray  # (3m,) index of the (first) new point on each halfedge's edge, −1 if none
    face_point: np.ndarray  # (m,) index of the face point, −1 if none
    trisected: np.ndarray  # (m,) int8 local index of the trisected boundary halfedge, −1 if none
    coefficients: np.ndarray  # (4, n): every vertex mask, see _rules.vertex_mask
    n_new: int
    bnext: np.ndarray  # (3m,) boundary links, only filled for Kobbelt's even steps
    bprev: np.ndarray


def plan_step(level: Level, corner: np.ndarray, scheme: str, step: int, loop_weights: str,
              force_split: np.ndarray | None = None) -> StepPlan:
    """Classify edges and vertices of one step and lay out the new points.

    ``force_split`` (3m,) bool marks halfedges whose edges are split even between smooth
    faces (UV seams: R4 points, no flip); both halfedges of an edge must agree.

    Tags come from the level (``hsharp``, ``face_sharp``: all sharp for ``"loop"``, none for
    ``"sqrt3"``); ``corner`` (n,) is the corner mask.
    """
    F, twin = level.faces, level.twin
    m, n = level.n_faces, level.n_vertices
    odd = step % 2 == 1
    sqrt3 = scheme == "sqrt3"
    has_tags = level.hsharp is not None and not sqrt3
    hkind = np.empty(3 * m, np.int8)
    edge_point = np.empty(3 * m, np.int64)
    face_point = np.empty(m, np.int64)
    trisected = np.empty(m, np.int8)
    counts = np.zeros((6, n), np.int64)
    s_frac = np.zeros(n, np.float64)
    if force_split is not None and sqrt3:
        raise ValueError('scheme="sqrt3" flips every interior edge; forced splits need "hybrid" or "loop"')
    force = _EMPTY_B if force_split is None else np.ascontiguousarray(force_split, dtype=bool)
    n_sharp = int(np.count_nonzero(level.face_sharp))
    mixed = 0 < n_sharp < m
    region_of_all = -1 if mixed else (R.REGION_LOOP if n_sharp else R.REGION_SQRT3)
    n_new = K.classify_step(F, twin, level.hsharp if has_tags else _EMPTY_F, has_tags, level.face_sharp, mixed,
                            force, R.SCHEME_CODES[scheme], odd, hkind, edge_point, face_point, trisected, counts,
                            s_frac)
    table = R.smooth_weight_table(int(counts[0].max()) if n else 0, loop_weights)
    cs, cn = R.KOBBELT_BOUNDARY_MASK if sqrt3 else R.CREASE_MASK
    coefficients = np.empty((4, n), np.float64)
    K.vertex_coefficients(counts, s_frac, corner, region_of_all, table, cs, cn, sqrt3 and odd, coefficients)
    if sqrt3 and not odd:
        bnext, bprev = K.boundary_links(F, twin)
    else:
        bnext = bprev = _EMPTY_I
    return StepPlan(scheme, step, hkind, edge_point, face_point, trisected, coefficients, int(n_new), bnext,
                    bprev)


_EMPTY_F = np.empty(0, np.float64)
_EMPTY_I = np.empty(0, np.int64)
_EMPTY_B = np.empty(0, np.bool_)


def step_arguments(level: Level, plan: StepPlan) -> tuple:
    """The arguments the stencil kernels share, in their order."""
    has_tags = level.hsharp is not None and plan.scheme != "sqrt3"
    return (level.faces, level.twin, level.hsharp if has_tags else _EMPTY_F, has_tags, plan.hkind,
            plan.edge_point, plan.face_point, plan.coefficients, plan.bnext, plan.bprev)


def child_level(level: Level, plan: StepPlan, want_topology: bool = True):
    """The next level (faces, twins, tags) and the parent face of each of its faces.

    Without ``want_topology`` only the faces are built (for the last step of a call).
    """
    m = level.n_faces
    face_sharp = level.face_sharp
    offsets = np.empty(m + 1, np.int64)
    first = np.empty(3 * m, np.int64)
    K.child_offsets(plan.hkind, face_sharp, offsets, first)
    total = int(offsets[m])
    has_tags = level.hsharp is not None and plan.scheme != "sqrt3"
    faces = np.empty((total, 3), np.int64)
    twin = np.empty(3 * total if want_topology else 0, np.int64)
    hsharp = np.zeros(3 * total if want_topology and has_tags else 0)
    child_sharp = np.zeros(total if want_topology else 0, bool)
    big = m >= K.PARALLEL_MIN
    (K.emit_faces if big else K.emit_faces_serial)(
        level.faces, level.twin, plan.hkind, plan.edge_point, plan.face_point, plan.trisected, face_sharp, first,
        faces)
    child = None
    if want_topology:
        (K.emit_topology if big else K.emit_topology_serial)(
            level.twin, level.hsharp if has_tags else _EMPTY_F, has_tags, plan.hkind, plan.face_point,
            plan.trisected, face_sharp, first, twin, hsharp, child_sharp)
        child = Level(faces, plan.n_new, twin, hsharp if has_tags else None, child_sharp)
    return faces, child, offsets


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
    mid = plan.edge_point[keep]
    pairs = np.empty((2 * len(keep), 2), np.int64)
    pairs[0::2, 0] = u
    pairs[0::2, 1] = mid
    pairs[1::2, 0] = mid
    pairs[1::2, 1] = w
    return pairs, np.repeat(R.child_sharpness(level.hsharp[keep]), 2)
