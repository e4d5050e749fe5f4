"""Topology and tags of one level: halfedges, edges, incidences, and one step's classes.

This is the layer between the rules (``_rules``, pure weights) and the matrices
(``_stencils``): it knows connectivity and tags, never positions, never weights beyond
asking ``_rules`` for them by valence and region.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _kernels as K
from . import _rules as R
from ._errors import MeshError


@dataclass(frozen=True, eq=False)
class Level:
    """Connectivity of one level: faces plus the halfedge/edge tables derived from them."""

    faces: np.ndarray  # (m, 3) int64
    n_vertices: int
    twin: np.ndarray  # (3m,) halfedge across, −1 on the boundary
    by_origin: np.ndarray  # (3m,) halfedges grouped by origin vertex
    origin_start: np.ndarray  # (n + 1,) CSR offsets into by_origin
    edge_of: np.ndarray  # (3m,) edge of each halfedge
    edge_owner: np.ndarray  # (ne,) lower-numbered halfedge of each edge
    ve_start: np.ndarray  # (n + 1,) CSR offsets into ve_edges
    ve_edges: np.ndarray  # (2 ne,) incident edges of each vertex

    @property
    def n_faces(self) -> int:
        return self.faces.shape[0]

    @property
    def n_edges(self) -> int:
        return self.edge_owner.shape[0]

    @property
    def valence(self) -> np.ndarray:
        return np.diff(self.ve_start)

    @property
    def edge_vertices(self) -> np.ndarray:
        """(ne, 2) edges as vertex pairs in their owner halfedge's orientation."""
        h = self.edge_owner
        f, i = h // 3, h % 3
        return np.stack([self.faces[f, i], self.faces[f, (i + 1) % 3]], axis=1)

    @property
    def boundary_edge(self) -> np.ndarray:
        return self.twin[self.edge_owner] < 0

    def find_edges(self, pairs: np.ndarray) -> np.ndarray:
        """Edge index of each vertex pair, −1 where the mesh has no such edge."""
        pairs = np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2)
        return K.find_edges(pairs, self.faces, self.by_origin, self.origin_start, self.edge_of)


def build_level(faces: np.ndarray, n_vertices: int) -> Level:
    """Build the halfedge tables of a mesh, or raise MeshError naming the offending edge.

    ``faces`` must already be an (m, 3) int64 array with indices in range and no repeated
    vertex within a face.
    """
    F = np.ascontiguousarray(faces, dtype=np.int64)
    twin, by_origin, origin_start, err, h = K.halfedge_twins(F, n_vertices)
    if err != K.OK:
        raise _edge_error(F, int(h))
    edge_of, owner = K.number_edges(twin)
    ve_start, ve_edges = K.vertex_edges(F, owner, n_vertices)
    return Level(F, int(n_vertices), twin, by_origin, origin_start, edge_of, owner, ve_start, ve_edges)


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
    """Everything one step decides from topology and tags, before any weight is written."""

    scheme: str
    step: int  # 1-based within the call; only "sqrt3" cares (Kobbelt's odd/even boundary)
    esharp: np.ndarray  # (ne,) sharpness this step: 0 smooth, > 0 crease, inf for boundary
    kind: np.ndarray  # (ne,) int8 EDGE_* code
    edge_point: np.ndarray  # (ne,) index of the (first) new point on the edge, −1 if none
    face_point: np.ndarray  # (m,) index of the face point, −1 if none
    face_sharp: np.ndarray  # (m,) bool
    rule_parent: np.ndarray  # (n,) int8 vertex rule from edges with s > 0
    rule_child: np.ndarray  # (n,) int8 vertex rule from edges with s > 1
    blend: np.ndarray  # (n,) weight of the parent rule's mask where the two differ
    smooth_weight: np.ndarray  # (n,) per-neighbour weight of the region's smooth mask
    crease_mask: tuple  # (self, neighbour) weights of the crease vertex mask
    n_new: int
    bnext: np.ndarray  # (3m,) boundary links, only filled for Kobbelt's even steps
    bprev: np.ndarray


def plan_step(
    level: Level,
    edge_sharpness: np.ndarray,
    face_sharp: np.ndarray,
    corner: np.ndarray,
    scheme: str,
    step: int,
    loop_weights: str,
    force_split: np.ndarray | None = None,
) -> StepPlan:
    """Classify edges and vertices of one step and lay out the new points.

    ``edge_sharpness`` (ne,) holds the tagged sharpness per edge (0 = untagged), ``face_sharp``
    (m,) the sharp-face mask, ``corner`` (n,) the corner mask. ``force_split`` (ne,) bool,
    optional, marks edges that must be split although they would be flipped (UV seams, see
    ``_facevarying``): they get an R4 edge point like a split-smooth edge and are not creases,
    so vertex rules are unchanged. ``"hybrid"`` and ``"loop"`` only.
    """
    n, m = level.n_vertices, level.n_faces
    boundary = level.boundary_edge
    ev = level.edge_vertices
    owner = level.edge_owner
    twin = level.twin
    empty = np.empty(0, np.int64)
    bnext = bprev = empty

    if scheme == "sqrt3":
        if force_split is not None and np.any(force_split):
            raise ValueError('forced splits need scheme="hybrid" or "loop"; Kobbelt\'s √3 has no split edges')
        odd = step % 2 == 1
        face_sharp = np.zeros(m, dtype=bool)
        esharp = np.where(boundary, np.inf, 0.0)
        kind = np.where(boundary, R.EDGE_KEEP if odd else R.EDGE_TRISECT, R.EDGE_FLIP).astype(np.int8)
        crease_mask = R.KOBBELT_BOUNDARY_MASK
        if odd:
            has_fp = np.ones(m, dtype=bool)
        else:
            has_fp = ~(twin.reshape(m, 3) < 0).any(axis=1)
            bnext, bprev = K.boundary_links(level.faces, twin)
    else:
        if scheme == "loop":
            face_sharp = np.ones(m, dtype=bool)
        esharp = np.where(boundary, np.inf, edge_sharpness)
        f0 = owner // 3
        t = twin[owner]
        sharp_side = face_sharp[f0] | np.where(t >= 0, face_sharp[np.maximum(t, 0) // 3], False)
        split = (esharp > 0) | sharp_side
        if force_split is not None:
            split |= force_split
        kind = np.where(split, R.EDGE_SPLIT, R.EDGE_FLIP).astype(np.int8)
        crease_mask = R.CREASE_MASK
        has_fp = ~face_sharp

    # Vertex rules from incident crease counts (OpenSubdiv's parent and child rules).
    ends = ev.ravel()
    s2 = np.repeat(esharp, 2)
    c_parent = np.bincount(ends, weights=s2 > 0, minlength=n)
    c_child = np.bincount(ends, weights=s2 > 1, minlength=n)
    rule_parent = R.vertex_rule(c_parent, corner)
    rule_child = R.vertex_rule(c_child, corner)
    if scheme == "sqrt3" and step % 2 == 1:
        rule_parent = rule_child = np.where(rule_parent != R.SMOOTH, R.CORNER, R.SMOOTH).astype(np.int8)
    fractional = (s2 > 0) & (s2 <= 1)
    n_frac = np.bincount(ends, weights=fractional, minlength=n)
    s_frac = np.bincount(ends, weights=np.where(fractional, s2, 0.0), minlength=n)
    blend = np.divide(s_frac, n_frac, out=np.zeros(n), where=n_frac > 0)

    # Region of each vertex: are its faces sharp (Loop), smooth (sqrt3) or both?
    corners_of = level.faces.ravel()
    n_faces_at = np.bincount(corners_of, minlength=n)
    n_sharp_at = np.bincount(corners_of, weights=np.repeat(face_sharp, 3), minlength=n)
    region = np.where(
        n_sharp_at == 0, R.REGION_SQRT3, np.where(n_sharp_at == n_faces_at, R.REGION_LOOP, R.REGION_MIXED)
    )
    smooth_weight = R.smooth_neighbour_weight(level.valence, region, loop_weights)

    # Layout: old vertices, edge points in edge order, face points in face order.
    n_pts = (kind == R.EDGE_SPLIT).astype(np.int64) + 2 * (kind == R.EDGE_TRISECT)
    first = n + np.cumsum(n_pts) - n_pts
    edge_point = np.where(n_pts > 0, first, -1)
    n_edge_pts = int(n_pts.sum())
    face_point = np.where(has_fp, n + n_edge_pts + np.cumsum(has_fp) - 1, -1)
    n_new = n + n_edge_pts + int(has_fp.sum())

    return StepPlan(
        scheme, step, esharp, kind, edge_point.astype(np.int64), face_point.astype(np.int64),
        np.ascontiguousarray(face_sharp, dtype=bool), rule_parent, rule_child, blend,
        np.ascontiguousarray(smooth_weight, dtype=np.float64), crease_mask, n_new, bnext, bprev,
    )


def child_faces(level: Level, plan: StepPlan):
    """Faces of the next level and the parent (in this level) of each."""
    F = level.faces
    counts = K.child_face_counts(F, level.edge_of, plan.kind, plan.face_sharp)
    offsets = np.zeros(len(counts) + 1, np.int64)
    np.cumsum(counts, out=offsets[1:])
    faces, parent = K.emit_faces(
        F, level.twin, level.edge_of, plan.kind, plan.edge_point, plan.face_point, plan.face_sharp, offsets
    )
    return faces, parent


def child_creases(level: Level, plan: StepPlan, tagged: np.ndarray):
    """Tagged creases of the next level: children (u, m), (m, w) with sharpness s − 1.

    ``tagged`` (ne,) is the user-tagged sharpness per edge. Boundary edges are creases
    implicitly: a tag on one is not carried on.
    """
    keep = np.flatnonzero((tagged > 1) & (plan.kind == R.EDGE_SPLIT) & ~level.boundary_edge)
    ev = level.edge_vertices[keep]
    mid = plan.edge_point[keep]
    pairs = np.empty((2 * len(keep), 2), np.int64)
    pairs[0::2, 0] = ev[:, 0]
    pairs[0::2, 1] = mid
    pairs[1::2, 0] = mid
    pairs[1::2, 1] = ev[:, 1]
    return pairs, np.repeat(R.child_sharpness(tagged[keep]), 2)
