"""Topology and tags (OpenSubdiv's Vtr): halfedges, levels, step plans, emission of the next
level, the non-manifold cut and the face-varying (UV) index mesh. Knows connectivity and
tags, never positions. Other layers import from here, never from the modules inside."""

from ._halfedge_kernels import (dest, edge_sharpness, far_twins, next_in_face, opposite, origin, owned_edge,
                                owned_ends_in, prev_in_face)
from ._kernels import group_by_origin, step_counts, use_threads
from .cut import Cut, cut_non_manifold, map_sharp_edges
from .edges import (EdgeGroups, UndirectedEdges, edge_keys, group_halfedges, halfedge_ends, next_halfedge,
                    prev_halfedge, undirected_edges)
from .emit import LABEL_BASE, child_creases, child_labels, child_level, face_parents
from .errors import duplicate_faces_error, not_an_edge_error, topology_error
from .level import Level, build_level, checked_level
from .step_plan import StepPlan, blend_slopes, plan_step, step_arguments
from .sectors import Sectors, vertex_sectors
from .uv import linear_rows, seam_halfedges, uv_start

__all__ = ["LABEL_BASE", "blend_slopes", "child_labels", "Cut", "EdgeGroups", "Level", "Sectors", "StepPlan", "UndirectedEdges", "build_level", "checked_level",
           "child_creases", "child_level", "cut_non_manifold", "dest", "duplicate_faces_error", "edge_keys",
           "edge_sharpness", "face_parents", "far_twins", "group_by_origin", "group_halfedges", "halfedge_ends", "linear_rows", "map_sharp_edges",
           "next_halfedge", "next_in_face", "not_an_edge_error", "opposite", "origin", "owned_edge", "owned_ends_in", "plan_step", "prev_halfedge",
           "prev_in_face", "seam_halfedges", "step_arguments", "step_counts", "topology_error", "undirected_edges", "use_threads",
           "uv_start", "vertex_sectors"]
